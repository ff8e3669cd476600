// ConusFile -> HeaderModel: the header an in-memory file is written with (exr_io.cpp) and
// validated as (validate_file.cpp), built in this one place.
#include <algorithm>

#include "header_model_pvt.h"

namespace conus::format::detail {
namespace {

template <class T>
Attr<T> attr(T value) {
    Attr<T> a;
    a.present = a.typeOk = true;
    a.value = std::move(value);
    return a;
}

}  // namespace

std::string HeaderModel::partName(PartKind kind) const { return kParts[static_cast<std::size_t>(kind)].name + suffix; }

HeaderModel modelOf(const ConusFile& file, const std::string& suffix) {
    HeaderModel m;
    m.suffix = suffix;
    const Image& im = file.image;
    PartModel conus;
    conus.name = m.partName(PartKind::Conus);
    conus.type = "scanlineimage";
    conus.compression = file.compression;
    for (const std::string& name : im.channels) {
        conus.channels.push_back({name, isDepthChannel(name) || file.pixelType == PixelType::Float ? ChannelType::Float : ChannelType::Half, 1, 1});
    }
    // OpenEXR stores channels sorted by name; so does the model, so checks read the same.
    std::sort(conus.channels.begin(), conus.channels.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
    conus.dataWindow = conus.displayWindow = Box{0, 0, std::int64_t{im.width} - 1, std::int64_t{im.height} - 1};
    // Every part shares the displayWindow (OpenEXR requires it); the map's dataWindow is its grid.
    // The map is always stored losslessly (DWAA would quantize the node positions).
    PartModel map;
    map.name = m.partName(PartKind::SamplingMap);
    map.type = "scanlineimage";
    map.compression = file.compression == Compression::None ? Compression::None : Compression::Zip;
    map.channels = {{kMapChannelU, ChannelType::Float, 1, 1}, {kMapChannelV, ChannelType::Float, 1, 1}};
    map.displayWindow = conus.displayWindow;
    map.dataWindow = Box{0, 0, std::int64_t{file.map.columns} - 1, std::int64_t{file.map.rows} - 1};
    m.parts = {conus, map};
    m.slot(PartKind::Conus) = {0, 1};
    m.slot(PartKind::SamplingMap) = {1, 1};

    m.version = attr(kFormatVersion);
    m.sourceSize = attr(std::array<int, 2>{file.sourceWidth, file.sourceHeight});
    m.dataKind = attr(std::string(enumName(file.dataKind)));
    m.software = attr(file.software.empty() ? std::string(kSoftwareName) : file.software);
    if (file.analytic) {
        const AnalyticMap& a = *file.analytic;
        m.mapKind = attr(a.kind);
        if (a.is(MapKind::Foci) || !a.foci.empty()) {
            std::vector<float> f;
            for (const FocusParams& p : a.foci) {
                f.insert(f.end(), {float(p.u), float(p.v), float(p.r), float(p.k)});
            }
            m.foci = attr(std::move(f));
        }
        if (a.is(MapKind::Foci) || !a.composition.empty()) m.composition = attr(a.composition);
        if (!a.groundRows.empty()) m.groundRows = attr(a.groundRows);
        for (const auto& [name, value] : a.scalars) m.params[name] = attr(value);
    }
    if (file.camera) {
        m.worldToCamera = attr(file.camera->worldToCamera);
        m.worldToNDC = attr(file.camera->worldToNDC);
        m.projection = attr(file.camera->projection);
    }
    m.depthKind = attr(std::string(enumName(file.depth.kind)));
    if (file.depth.kind != DepthKind::None) m.depthRange = attr(std::array<float, 2>{file.depth.near, file.depth.far});
    if (!file.depth.units.empty()) m.depthUnits = attr(file.depth.units);
    const SourceEncoding& e = file.sourceEncoding;
    m.sourceTransfer = attr(std::string(enumName(e.transfer)));
    if (e.sampleType) m.sourceSampleType = attr(std::string(enumName(*e.sampleType)));
    if (e.chromaticities) m.chromaticities = attr(*e.chromaticities);
    if (!e.iccProfile.empty()) m.iccProfile = attr(base64Encode(e.iccProfile));
    return m;
}

}  // namespace conus::format::detail
