// Reading and writing a CoNUS file (one image, or a reflection asset's six) through OpenEXR: the
// screen before OpenEXR's C++ library reads (exr_screen_pvt.h), the header rules on the model of the
// headers (exr_header_pvt.h), then the parts' pixels (exr_parts_pvt.h). OpenEXR's exceptions (Iex::BaseExc
// derives from std::exception) are caught here and turned into report issues or conus::Error, so
// nothing from OpenEXR escapes format/.
#include "exr_io_pvt.h"

#include <ImfHeader.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfStringAttribute.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <span>
#include <system_error>
#include <variant>

#include "exr_header_pvt.h"
#include "exr_parts_pvt.h"
#include "exr_screen_pvt.h"
#include "header_model_pvt.h"

namespace conus::format::detail {
namespace {

enum class Layout { Image, ReflectionAsset };

LoadResult refusal(const Problem& problem) {
    LoadResult result;
    result.report.add(problem.rule, problem.message);
    result.code = problem.code;
    return result;
}

// A regular file (a FIFO never ends and a device may not either) that passes the screen
// (exr_screen_pvt.h); its size and the C core's context for the chunk checks.
Problem screen(const std::string& path, const Limits& limits, std::uintmax_t& size, std::unique_ptr<CoreFile>& core) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (status.type() == std::filesystem::file_type::not_found)
        return {Rule::V1, ErrorCode::Io, "cannot open " + path + ": no such file"};
    if (ec || !std::filesystem::exists(status)) return {Rule::V1, ErrorCode::Io, "cannot open " + path + ": " + ec.message()};
    if (!std::filesystem::is_regular_file(status)) return {Rule::V1, ErrorCode::Io, "cannot read " + path + ": not a regular file"};
    size = std::filesystem::file_size(path, ec);
    if (ec || !std::ifstream(path, std::ios::binary))
        return {Rule::V1, ErrorCode::Io, "cannot open " + path + (ec ? ": " + ec.message() : std::string())};
    return checkHeaders(path, size, limits, core);
}

bool hasPart(const HeaderModel& m, const std::string& name) {
    return std::any_of(m.parts.begin(), m.parts.end(), [&](const PartModel& p) { return p.name == name; });
}

// A file without a `conus` part whose parts include the first face's is a reflection asset.
Layout layoutOf(const HeaderModel& single) {
    return single.slot(PartKind::Conus).index < 0 && hasPart(single, kConusPartName + faceSuffix(0)) ? Layout::ReflectionAsset
                                                                                                   : Layout::Image;
}

ErrorCode codeOf(const HeaderCheck& hc) {
    return hc.notConus ? ErrorCode::NotConus : hc.limitExceeded ? ErrorCode::LimitExceeded : ErrorCode::Corrupt;
}

// The image's pixels as float, counted against the decode memory limit.
std::int64_t imageBytes(const HeaderModel& m) {
    const PartModel& part = m.part(PartKind::Conus);
    return part.dataWindow.width() * part.dataWindow.height() * std::int64_t(part.channels.size()) * std::int64_t(sizeof(float));
}

// After the header rules passed: the chunk tables of the image's two parts.
Problem checkImageChunks(const CoreFile& core, const HeaderModel& m, std::uintmax_t size) {
    for (const PartSpec& spec : kParts)
        if (Problem problem = checkChunks(core.ctx(), m.slot(spec.kind).index, size); !problem.message.empty()) return problem;
    return {};
}

// One image's metadata, map and (with `readPixels`) pixels; map rule issues land in `r`.
ConusFile readImage(Imf::MultiPartInputFile& file, const HeaderModel& m, bool readPixels, ValidationReport& r) {
    ConusFile loaded;
    const PartModel& part = m.part(PartKind::Conus);
    fillMetadata(m, file.header(m.slot(PartKind::Conus).index), loaded);
    if (readPixels) {
        readImagePart(file, m.slot(PartKind::Conus).index, part, loaded.image);
    } else {
        loaded.image.width = int(part.dataWindow.width());
        loaded.image.height = int(part.dataWindow.height());
        for (const ChannelModel& c : part.channels) loaded.image.channels.push_back(c.name);
    }
    readMapPart(file, m.slot(PartKind::SamplingMap).index, m.part(PartKind::SamplingMap), loaded.map);
    const ValidationReport grid = validateGrid(loaded.map);
    for (const Issue& issue : grid.issues)
        r.add(issue.rule, m.suffix.empty() ? issue.message : "face " + m.suffix.substr(1) + ": " + issue.message, issue.count);
    return loaded;
}

Problem decodeLimit(std::int64_t bytes, const std::string& what, const Limits& limits) {
    if (bytes <= limits.maxDecodeBytes) return {};
    return {Rule::V4, ErrorCode::LimitExceeded,
            what + " floats takes " + std::to_string(bytes) + " bytes, beyond the decode memory limit of " +
                std::to_string(limits.maxDecodeBytes)};
}

// Reads the file at `path` as `want` (either layout when empty) into `single` or `asset`.
LoadResult load(const std::string& path, const Limits& limits, bool readPixels, std::optional<Layout> want, ConusFile* single,
                ReflectionAssetFile* asset) {
    useExrThreads();
    std::uintmax_t size = 0;
    std::unique_ptr<CoreFile> core;
    if (Problem problem = screen(path, limits, size, core); !problem.message.empty()) return refusal(problem);
    LoadResult result;
    ValidationReport& r = result.report;
    try {
        Imf::MultiPartInputFile file(path.c_str());
        const HeaderModel model = modelOf(file);
        const Layout layout = layoutOf(model);
        if (want && *want != layout) {
            return refusal(layout == Layout::ReflectionAsset
                               ? Problem{Rule::V2, ErrorCode::NotConus,
                                         "a reflection asset (six cube faces), not one CoNUS image: `conus info`, `conus render "
                                         "reflection` and `conus-view --reflection` read it"}
                               : Problem{Rule::V18, ErrorCode::NotConus,
                                         "not a reflection asset (no part `" + std::string(kConusPartName) + faceSuffix(0) +
                                             "`); make one with `conus bake reflection SCENE -o asset.exr`"});
        }
        if (layout == Layout::Image) {
            const HeaderCheck hc = checkHeaderRules(model, limits, r);
            if (!r.ok()) {
                result.code = codeOf(hc);
                return result;
            }
            // Headers passed every rule, so every size below is within limits; the chunk tables must
            // still show that the pixels are in the file before memory is committed for them.
            const PartModel& part = model.part(PartKind::Conus);
            if (readPixels)
                if (Problem p = decodeLimit(imageBytes(model), "image of " + std::to_string(part.dataWindow.width()) + "x" +
                                                                   std::to_string(part.dataWindow.height()) + "x" +
                                                                   std::to_string(part.channels.size()),
                                            limits);
                    !p.message.empty())
                    return refusal(p);
            if (Problem p = checkImageChunks(*core, model, size); !p.message.empty()) return refusal(p);
            ConusFile loaded = readImage(file, model, readPixels, r);
            if (!r.ok()) {
                result.code = ErrorCode::InvalidMap;
                return result;
            }
            if (single) *single = std::move(loaded);
            return result;
        }
        AssetModel faces;
        for (int f = 0; f < kCubeFaceCount; ++f) faces[static_cast<std::size_t>(f)] = modelOf(file, faceSuffix(f));
        const HeaderCheck hc = checkAssetRules(faces, limits, r);
        if (!r.ok()) {
            result.code = codeOf(hc);
            return result;
        }
        if (readPixels) {
            std::int64_t bytes = 0;
            for (const HeaderModel& m : faces) bytes += imageBytes(m);
            if (Problem p = decodeLimit(bytes, "six faces of " + std::to_string(faces[0].part(PartKind::Conus).dataWindow.width()) + "x" +
                                                         std::to_string(faces[0].part(PartKind::Conus).dataWindow.height()) + "x" +
                                                         std::to_string(faces[0].part(PartKind::Conus).channels.size()),
                                        limits); !p.message.empty()) return refusal(p);
        }
        for (const HeaderModel& m : faces)
            if (Problem p = checkImageChunks(*core, m, size); !p.message.empty()) return refusal(p);
        ReflectionAssetFile loaded;
        for (std::size_t f = 0; f < faces.size(); ++f) loaded.faces[f] = readImage(file, faces[f], readPixels, r);
        if (!r.ok()) {
            result.code = ErrorCode::InvalidMap;
            return result;
        }
        loaded.frame = {faces[0].cubeCentre.value, faces[0].cubeAxes.value};
        if (asset) *asset = std::move(loaded);
    } catch (const std::exception& e) {
        r.add(Rule::V1, std::string("damaged OpenEXR data: ") + e.what());
        result.code = ErrorCode::Corrupt;
    }
    return result;
}

// The images of a file into `out`: image k's two parts after image k-1's, `models[k]` naming them.
void writeImages(AtomicFile& out, std::span<const HeaderModel> models, std::span<const ConusFile* const> files) {
    useExrThreads();
    const std::string& path = out.destination();
    AtomicOStream stream(out);
    try {
        // The parts and attributes the validator checked (header_model.cpp), then the source's
        // metadata, which only an image part carries.
        std::vector<Imf::Header> headers;
        for (std::size_t k = 0; k < models.size(); ++k) {
            const HeaderModel& model = models[k];
            const std::size_t first = headers.size();
            for (const PartModel& part : model.parts) headers.push_back(exrHeader(part));
            for (const PartSpec& spec : kParts) writeAttributes(model, spec.kind, headers[first + model.slot(spec.kind).index]);
            Imf::Header& conus = headers[first + model.slot(PartKind::Conus).index];
            for (const MetadataItem& item : files[k]->sourceEncoding.metadata) {
                if (!isCarriedMetadata(item.name)) continue;  // never let an item overwrite a CoNUS attribute
                if (const auto* v = std::get_if<std::string>(&item.value)) conus.insert(item.name, Imf::StringAttribute(*v));
                else if (const auto* i = std::get_if<int>(&item.value)) conus.insert(item.name, Imf::IntAttribute(*i));
                else if (const auto* f = std::get_if<float>(&item.value)) conus.insert(item.name, Imf::FloatAttribute(*f));
                else if (const auto* d = std::get_if<double>(&item.value)) conus.insert(item.name, Imf::DoubleAttribute(*d));
            }
        }
        Imf::MultiPartOutputFile exr(stream, headers.data(), int(headers.size()));
        int first = 0;
        for (std::size_t k = 0; k < models.size(); ++k) {
            writeImagePart(exr, first + models[k].slot(PartKind::Conus).index, files[k]->image, files[k]->pixelType);
            writeMapPart(exr, first + models[k].slot(PartKind::SamplingMap).index, files[k]->map);
            first += int(models[k].parts.size());
        }
    } catch (const std::exception& e) {
        throw Error(ErrorCode::Io, stream.failure().empty() ? "cannot write " + path + ": " + e.what() : stream.failure());
    }
    if (!stream.failure().empty()) throw Error(ErrorCode::Io, stream.failure());
}

}  // namespace

LoadResult loadConusFile(const std::string& path, const Limits& limits, bool readPixels, ConusFile& out) {
    return load(path, limits, readPixels, Layout::Image, &out, nullptr);
}

LoadResult loadReflectionAsset(const std::string& path, const Limits& limits, bool readPixels, ReflectionAssetFile& out) {
    return load(path, limits, readPixels, Layout::ReflectionAsset, nullptr, &out);
}

LoadResult validateFile(const std::string& path, const Limits& limits, bool readPixels) {
    return load(path, limits, readPixels, std::nullopt, nullptr, nullptr);
}

bool hasReflectionLayout(const std::string& path) {
    std::uintmax_t size = 0;
    std::unique_ptr<CoreFile> core;
    if (!screen(path, {}, size, core).message.empty()) return false;
    try {
        Imf::MultiPartInputFile file(path.c_str());
        return layoutOf(modelOf(file)) == Layout::ReflectionAsset;
    } catch (const std::exception&) {
        return false;
    }
}

void writeExrFile(AtomicFile& out, const ConusFile& file) {
    const HeaderModel model = modelOf(file);
    const ConusFile* files[] = {&file};
    writeImages(out, std::span(&model, 1), files);
}

void writeExrFile(AtomicFile& out, const ReflectionAssetFile& asset) {
    const AssetModel models = modelOf(asset);
    std::array<const ConusFile*, kCubeFaceCount> files{};
    for (std::size_t f = 0; f < files.size(); ++f) files[f] = &asset.faces[f];
    writeImages(out, models, files);
}

}  // namespace conus::format::detail
