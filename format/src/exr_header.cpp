// OpenEXR headers <-> HeaderModel (exr_header_pvt.h): each value type of kAttributes with its OpenEXR
// attribute class, a part's header both ways, and the model's fields as a ConusFile's.
#include "exr_header_pvt.h"

#include <ImfChannelList.h>
#include <ImfChromaticitiesAttribute.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfPartType.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfVecAttribute.h>

#include <cstring>
#include <type_traits>
#include <variant>

namespace conus::format::detail {
namespace {

Box boxOf(const Imath::Box2i& b) { return Box{b.min.x, b.min.y, b.max.x, b.max.y}; }

Imath::Box2i box2i(const Box& b) {
    return Imath::Box2i(Imath::V2i(int(b.minX), int(b.minY)), Imath::V2i(int(b.maxX), int(b.maxY)));
}

Compression compressionOf(Imf::Compression c) {
    switch (c) {
        case Imf::NO_COMPRESSION: return Compression::None;
        case Imf::PIZ_COMPRESSION: return Compression::Piz;
        case Imf::DWAA_COMPRESSION:
        case Imf::DWAB_COMPRESSION: return Compression::Dwaa;
        default: return Compression::Zip;  // other codecs (RLE, ZIPS, PXR24, B44) are read as-is
    }
}

Imf::Compression exrCompression(Compression c) {
    switch (c) {
        case Compression::None: return Imf::NO_COMPRESSION;
        case Compression::Zip: return Imf::ZIP_COMPRESSION;
        case Compression::Piz: return Imf::PIZ_COMPRESSION;
        case Compression::Dwaa: return Imf::DWAA_COMPRESSION;
    }
    return Imf::ZIP_COMPRESSION;
}

// Each value type of kAttributes with its OpenEXR attribute class, both ways.
template <class T>
struct ExrAttribute;
template <>
struct ExrAttribute<int> {
    using Type = Imf::IntAttribute;
    static int from(int v) { return v; }
    static Type to(int v) { return Type(v); }
};
template <>
struct ExrAttribute<double> {
    using Type = Imf::DoubleAttribute;
    static double from(double v) { return v; }
    static Type to(double v) { return Type(v); }
};
template <>
struct ExrAttribute<std::string> {
    using Type = Imf::StringAttribute;
    static std::string from(const std::string& v) { return v; }
    static Type to(const std::string& v) { return Type(v); }
};
template <>
struct ExrAttribute<std::array<int, 2>> {
    using Type = Imf::V2iAttribute;
    static std::array<int, 2> from(const Imath::V2i& v) { return {v.x, v.y}; }
    static Type to(const std::array<int, 2>& v) { return Type(Imath::V2i(v[0], v[1])); }
};
template <>
struct ExrAttribute<std::array<float, 2>> {
    using Type = Imf::V2fAttribute;
    static std::array<float, 2> from(const Imath::V2f& v) { return {v.x, v.y}; }
    static Type to(const std::array<float, 2>& v) { return Type(Imath::V2f(v[0], v[1])); }
};
template <>
struct ExrAttribute<std::vector<float>> {
    using Type = Imf::FloatVectorAttribute;
    static std::vector<float> from(const std::vector<float>& v) { return v; }
    static Type to(const std::vector<float>& v) { return Type(v); }
};
// A square matrix of side N, row-major as Imath stores one.
template <int N, class Matrix, class Attribute>
struct ExrMatrixAttribute {
    using Type = Attribute;
    static std::array<float, N * N> from(const Matrix& m) {
        std::array<float, N * N> a{};
        for (int r = 0; r < N; ++r)
            for (int c = 0; c < N; ++c) a[r * N + c] = m[r][c];
        return a;
    }
    static Type to(const std::array<float, N * N>& a) {
        Matrix m;
        for (int r = 0; r < N; ++r)
            for (int c = 0; c < N; ++c) m[r][c] = a[r * N + c];
        return Type(m);
    }
};
template <>
struct ExrAttribute<std::array<float, 16>> : ExrMatrixAttribute<4, Imath::M44f, Imf::M44fAttribute> {};
template <>
struct ExrAttribute<std::array<float, 8>> {  // red, green, blue, white: x, y each
    using Type = Imf::ChromaticitiesAttribute;
    static std::array<float, 8> from(const Imf::Chromaticities& c) {
        return {c.red.x, c.red.y, c.green.x, c.green.y, c.blue.x, c.blue.y, c.white.x, c.white.y};
    }
    static Type to(const std::array<float, 8>& c) {
        return Type(Imf::Chromaticities(Imath::V2f(c[0], c[1]), Imath::V2f(c[2], c[3]), Imath::V2f(c[4], c[5]),
                                        Imath::V2f(c[6], c[7])));
    }
};

template <>
struct ExrAttribute<std::array<float, 3>> {
    using Type = Imf::V3fAttribute;
    static std::array<float, 3> from(const Imath::V3f& v) { return {v.x, v.y, v.z}; }
    static Type to(const std::array<float, 3>& v) { return Type(Imath::V3f(v[0], v[1], v[2])); }
};
template <>
struct ExrAttribute<std::array<float, 9>> : ExrMatrixAttribute<3, Imath::M33f, Imf::M33fAttribute> {};

template <class T>
Attr<T> readAttr(const Imf::Attribute& attribute) {
    Attr<T> a;
    a.present = true;
    a.typeName = attribute.typeName();
    if (const auto* typed = dynamic_cast<const typename ExrAttribute<T>::Type*>(&attribute)) {
        a.typeOk = true;
        a.value = ExrAttribute<T>::from(typed->value());
    } else if constexpr (std::is_same_v<T, double>) {  // parameters may be stored as float
        if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&attribute)) {
            a.typeOk = true;
            a.value = f->value();
        }
    }
    return a;
}

template <class... F>
struct Overloaded : F... {
    using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

// Every attribute kAttributes places in `part`, from its header `h`.
void readAttributes(const Imf::Header& h, PartKind part, HeaderModel& m) {
    for (const AttributeSpec& spec : kAttributes) {
        if (spec.part != part) continue;
        std::visit(Overloaded{[&](ParamsMember family) {
                                  const std::size_t prefix = std::strlen(spec.name);
                                  for (auto it = h.begin(); it != h.end(); ++it) {
                                      if (std::strncmp(it.name(), spec.name, prefix) == 0)
                                          (m.*family)[it.name() + prefix] = readAttr<double>(it.attribute());
                                  }
                              },
                              [&](auto member) {
                                  using T = typename std::decay_t<decltype(m.*member)>::Value;
                                  if (auto it = h.find(spec.name); it != h.end()) m.*member = readAttr<T>(it.attribute());
                              }},
                   spec.field);
    }
}

PartModel partOf(const Imf::Header& h) {
    PartModel p;
    p.name = h.hasName() ? h.name() : std::string();
    p.type = h.hasType() ? h.type() : (h.hasTileDescription() ? Imf::TILEDIMAGE : Imf::SCANLINEIMAGE);
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        const Imf::Channel& c = it.channel();
        ChannelType t = c.type == Imf::HALF ? ChannelType::Half : c.type == Imf::FLOAT ? ChannelType::Float : ChannelType::Uint;
        p.channels.push_back({it.name(), t, c.xSampling, c.ySampling});
    }
    p.dataWindow = boxOf(h.dataWindow());
    p.displayWindow = boxOf(h.displayWindow());
    if (h.hasTileDescription()) {
        p.tileWidth = h.tileDescription().xSize;
        p.tileHeight = h.tileDescription().ySize;
    }
    p.compression = compressionOf(h.compression());
    return p;
}

}  // namespace

// Every attribute of `part` the model holds, into its header `h`.
void writeAttributes(const HeaderModel& m, PartKind part, Imf::Header& h) {
    for (const AttributeSpec& spec : kAttributes) {
        if (spec.part != part) continue;
        std::visit(Overloaded{[&](ParamsMember family) {
                                  for (const auto& [name, a] : m.*family)
                                      h.insert(spec.name + name, ExrAttribute<double>::to(a.value));
                              },
                              [&](auto member) {
                                  const auto& a = m.*member;
                                  using T = typename std::decay_t<decltype(a)>::Value;
                                  if (a.present) h.insert(spec.name, ExrAttribute<T>::to(a.value));
                              }},
                   spec.field);
    }
}

// The header of one part as the writer writes it (its attributes come separately).
Imf::Header exrHeader(const PartModel& p) {
    Imf::Header h(box2i(p.displayWindow), box2i(p.dataWindow));
    h.setName(p.name);
    h.setType(p.type);
    h.compression() = exrCompression(p.compression);
    for (const ChannelModel& c : p.channels)
        h.channels().insert(c.name, Imf::Channel(c.type == ChannelType::Half ? Imf::HALF : c.type == ChannelType::Float ? Imf::FLOAT : Imf::UINT));
    return h;
}

HeaderModel modelOf(const Imf::MultiPartInputFile& file, const std::string& suffix) {
    HeaderModel m;
    m.suffix = suffix;
    for (int i = 0; i < file.parts(); ++i) {
        m.parts.push_back(partOf(file.header(i)));
        for (const PartSpec& spec : kParts) {
            PartSlot& slot = m.slot(spec.kind);
            if (m.parts.back().name == m.partName(spec.kind) && slot.count++ == 0) slot.index = i;
        }
    }
    for (const PartSpec& spec : kParts) {
        if (const int index = m.slot(spec.kind).index; index >= 0) readAttributes(file.header(index), spec.kind, m);
    }
    return m;
}

void fillMetadata(const HeaderModel& m, const Imf::Header& h, ConusFile& out) {
    const PartModel& part = m.part(PartKind::Conus);
    out.pixelType = PixelType::Half;
    for (const ChannelModel& c : part.channels) {
        if (!isDepthChannel(c.name) && c.type == ChannelType::Float) out.pixelType = PixelType::Float;
    }
    out.compression = part.compression;
    out.sourceWidth = m.sourceSize.value[0];
    out.sourceHeight = m.sourceSize.value[1];
    out.dataKind = tryParseEnum<DataKind>(m.dataKind.value).value_or(DataKind::Image);
    if (m.mapKind.ok()) {
        AnalyticMap a;
        a.kind = m.mapKind.value;
        const std::vector<float>& f = m.foci.value;
        for (std::size_t i = 0; i + 3 < f.size(); i += 4) a.foci.push_back({f[i], f[i + 1], f[i + 2], f[i + 3]});
        a.composition = m.composition.value;
        a.groundRows = m.groundRows.value;
        for (const auto& [name, attr] : m.params) a.scalars[name] = attr.value;
        out.analytic = std::move(a);
    }
    if (m.projection.ok()) out.camera = CameraAttributes{m.projection.value, m.worldToCamera.value, m.worldToNDC.value};
    out.depth.kind = m.depthKind.ok() ? tryParseEnum<DepthKind>(m.depthKind.value).value_or(DepthKind::None) : DepthKind::None;
    if (out.depth.kind != DepthKind::None) {
        out.depth.near = m.depthRange.value[0];
        out.depth.far = m.depthRange.value[1];
    }
    out.depth.units = m.depthUnits.value;
    SourceEncoding& e = out.sourceEncoding;
    if (m.sourceTransfer.ok()) e.transfer = tryParseEnum<Transfer>(m.sourceTransfer.value).value_or(Transfer::Linear);
    if (m.sourceSampleType.ok()) e.sampleType = tryParseEnum<SampleType>(m.sourceSampleType.value);
    if (m.chromaticities.ok()) e.chromaticities = m.chromaticities.value;
    if (m.iccProfile.ok()) e.iccProfile = base64Decode(m.iccProfile.value).value_or(std::string());
    for (auto it = h.begin(); it != h.end(); ++it) {
        if (!isCarriedMetadata(it.name())) continue;
        const Imf::Attribute& a = it.attribute();
        if (const auto* v = dynamic_cast<const Imf::StringAttribute*>(&a)) e.metadata.push_back({it.name(), v->value()});
        else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a)) e.metadata.push_back({it.name(), i->value()});
        else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a)) e.metadata.push_back({it.name(), f->value()});
        else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a)) e.metadata.push_back({it.name(), d->value()});
    }
    if (m.software.ok()) out.software = m.software.value;
}

}  // namespace conus::format::detail
