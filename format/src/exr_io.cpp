// All OpenEXR calls of conus_format. OpenEXR's exceptions (Iex::BaseExc derives from
// std::exception) are caught right where OpenEXR is called and turned into report issues or
// conus::Error, so nothing from OpenEXR escapes this file.
#include "exr_io.h"

#include "conus/core/parallel.h"

#include <ImfChannelList.h>
#include <ImfChromaticitiesAttribute.h>
#include <ImfIO.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfVecAttribute.h>
#include <ImfThreading.h>
#include <ImfTiledInputPart.h>
#include <openexr.h>
#include <half.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>
#include <type_traits>
#include <variant>

#include "header_model.h"
#include "header_scan.h"

namespace conus::format::detail {
namespace {

// ---- Before OpenEXR reads a header -------------------------------------------------------------
// Three readers look at each header, in this order, and the file reaches the next only if the one
// before accepts it:
// 1. scanHeaders (header_scan.cpp) walks the raw bytes: every attribute's size inside the file and
//    within the caps (limits.h), and the values whose C++ reader ignores the declared size
//    (chlist, preview, stringvector) exactly as long as declared. This is where the attribute
//    caps apply, before anything is allocated: OpenEXR 3.1's C core has no hook for a cap (its
//    context initializer offers read and size functions only, and a smaller size would break
//    chunk reads), and its C++ library allocates whatever a size says (a 1.9 GB string in a
//    4 KB file cost 13 s and 2 GB). A chlist one byte short of its terminator made the C core end
//    the header where the C++ library went on to read a 1.8 GB string the core never saw.
// 2. OpenEXR's C core parses defensively (validation.c checks every window, channel and
//    attribute against the file) and allocates no pixels; any error it reports refuses the file.
// 3. The C++ library, which trusts more, reads the headers the first two agree on.

void recordCoreError(exr_const_context_t ctx, exr_result_t code, const char* msg) {
    void* user = nullptr;
    if (exr_get_user_data(ctx, &user) == EXR_ERR_SUCCESS && user != nullptr) {
        auto* first = static_cast<std::string*>(user);
        if (first->empty()) *first = msg ? msg : exr_get_default_error_message(code);
    }
}

// An open C core context. The core reports some header errors (an attribute larger than the
// file, say) through the handler and still returns success, skipping the attribute; CoNUS refuses
// such a file, so `error` holds the first message the core reported, whatever it returned.
class CoreFile {
public:
    explicit CoreFile(const std::string& path) {
        exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
        init.error_handler_fn = &recordCoreError;
        init.user_data = &m_error;
        // A damaged offset table is refused, not rebuilt by scanning the file.
        init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
        const exr_result_t rv = exr_start_read(&m_ctx, path.c_str(), &init);
        if (rv != EXR_ERR_SUCCESS && m_error.empty()) m_error = exr_get_default_error_message(rv);
    }
    ~CoreFile() {
        if (m_ctx) exr_finish(&m_ctx);
    }
    CoreFile(const CoreFile&) = delete;
    CoreFile& operator=(const CoreFile&) = delete;

    exr_const_context_t ctx() const { return m_ctx; }
    const std::string& error() const { return m_error; }

private:
    exr_context_t m_ctx = nullptr;
    std::string m_error;
};

// A refusal: the rule it breaks and how readConusFile throws.
struct Problem {
    Rule rule = Rule::V1;
    ErrorCode code = ErrorCode::Corrupt;
    std::string message;  // empty: no problem
};

std::string partLabel(exr_const_context_t ctx, int p) {
    const char* name = nullptr;
    if (exr_get_name(ctx, p, &name) == EXR_ERR_SUCCESS && name) return "part " + std::to_string(p) + " (`" + name + "`)";
    return "part " + std::to_string(p);
}

// The header-level checks on the core's parse: display windows (V15), storage, chunk counts the
// file can hold.
Problem checkCoreHeaders(exr_const_context_t ctx, std::uintmax_t fileSize) {
    int parts = 0;
    if (exr_get_count(ctx, &parts) != EXR_ERR_SUCCESS || parts < 1) return {Rule::V1, ErrorCode::Corrupt, "no parts"};
    exr_attr_box2i_t firstDisplay{};
    for (int p = 0; p < parts; ++p) {
        exr_attr_box2i_t display{};
        if (exr_get_display_window(ctx, p, &display) == EXR_ERR_SUCCESS) {
            if (p == 0) firstDisplay = display;
            if (std::memcmp(&display, &firstDisplay, sizeof display) != 0) {
                // OpenEXR's C++ library refuses such a file with a vague message; name the rule.
                return {Rule::V15, ErrorCode::Corrupt,
                        "part " + std::to_string(p) + " displayWindow (" + std::to_string(display.min.x) + ", " +
                            std::to_string(display.min.y) + ") - (" + std::to_string(display.max.x) + ", " +
                            std::to_string(display.max.y) + ") differs from part 0's (" + std::to_string(firstDisplay.min.x) +
                            ", " + std::to_string(firstDisplay.min.y) + ") - (" + std::to_string(firstDisplay.max.x) + ", " +
                            std::to_string(firstDisplay.max.y) + ")"};
            }
        }
        int32_t chunks = 0;
        exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
        if (exr_get_storage(ctx, p, &storage) != EXR_ERR_SUCCESS) return {Rule::V1, ErrorCode::Corrupt, partLabel(ctx, p) + ": unknown storage"};
        if (exr_get_chunk_count(ctx, p, &chunks) != EXR_ERR_SUCCESS || chunks < 0)
            return {Rule::V1, ErrorCode::Corrupt, partLabel(ctx, p) + ": invalid chunk count"};
        // The C++ library reads every part's offset table (8 bytes a chunk) when it opens the file.
        if (std::uintmax_t(chunks) * 8 > fileSize) {
            return {Rule::V1, ErrorCode::Corrupt,
                    partLabel(ctx, p) + " needs " + std::to_string(chunks) + " chunk offsets, more than a " +
                        std::to_string(fileSize) + "-byte file can hold"};
        }
    }
    return {};
}

// ---- chunk table -------------------------------------------------------------------------------
// Before any pixel memory is committed, the chunk table and the file size must show that the data
// can be there: every chunk inside the file, the chunks together no larger than the file, and no
// chunk declaring more unpacked bytes than its packed bytes can expand to under its compression.

// The largest unpacked / packed ratio each compression can reach (so a declared size beyond it is
// a lie), rounded up generously:
// - RLE: a 2-byte run expands to at most 128 bytes (64).
// - ZIP, ZIPS: deflate expands at most 1032 times; PXR24 also drops float32 to 24 bits (1376).
// - PIZ: Huffman with run-length codes: 256 16-bit values in >= 10 bits (~410).
// - B44, B44A: a flat 4x4 block of halves (32 bytes) in 3 bytes (~11).
// - DWAA, DWAB: DC and RLE data are zlib-compressed after a 64:1 reduction (64 x 1032 = 66048).
std::uint64_t maxExpansion(exr_compression_t c) {
    switch (c) {
        case EXR_COMPRESSION_NONE: return 1;
        case EXR_COMPRESSION_RLE: return 128;
        case EXR_COMPRESSION_ZIPS:
        case EXR_COMPRESSION_ZIP:
        case EXR_COMPRESSION_PXR24: return 2048;
        case EXR_COMPRESSION_PIZ: return 1024;
        case EXR_COMPRESSION_B44:
        case EXR_COMPRESSION_B44A: return 16;
        case EXR_COMPRESSION_DWAA:
        case EXR_COMPRESSION_DWAB: return 131072;
        default: return 0;
    }
}

const char* compressionName(exr_compression_t c) {
    static const char* const kNames[] = {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"};
    return c >= 0 && c < EXR_COMPRESSION_LAST_TYPE ? kNames[c] : "unknown";
}

// Level 0 of part `p` (what CoNUS reads), chunk by chunk.
Problem checkChunks(exr_const_context_t ctx, int p, std::uintmax_t fileSize) {
    const std::string label = partLabel(ctx, p);
    exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
    exr_compression_t compression = EXR_COMPRESSION_LAST_TYPE;
    exr_attr_box2i_t dw{};
    if (exr_get_storage(ctx, p, &storage) != EXR_ERR_SUCCESS || exr_get_compression(ctx, p, &compression) != EXR_ERR_SUCCESS ||
        exr_get_data_window(ctx, p, &dw) != EXR_ERR_SUCCESS)
        return {Rule::V1, ErrorCode::Corrupt, label + ": unreadable storage, compression or data window"};
    const std::uint64_t ratio = maxExpansion(compression);
    if (ratio == 0) return {Rule::V1, ErrorCode::Corrupt, label + ": unknown compression"};
    const std::int64_t width = std::int64_t{dw.max.x} - dw.min.x + 1, height = std::int64_t{dw.max.y} - dw.min.y + 1;
    std::uint64_t packedTotal = 0;
    auto visit = [&](exr_result_t rv, const exr_chunk_info_t& c, const std::string& where) -> Problem {
        if (rv != EXR_ERR_SUCCESS) return {Rule::V1, ErrorCode::Corrupt, label + " " + where + ": unreadable chunk (" + exr_get_default_error_message(rv) + ")"};
        if (c.data_offset > fileSize || c.packed_size > fileSize - c.data_offset) {
            return {Rule::V1, ErrorCode::Corrupt,
                    label + " " + where + ": chunk of " + std::to_string(c.packed_size) + " bytes at offset " +
                        std::to_string(c.data_offset) + " runs past the end of the " + std::to_string(fileSize) + "-byte file"};
        }
        if (c.unpacked_size / ratio > c.packed_size) {
            return {Rule::V1, ErrorCode::Corrupt,
                    label + " " + where + ": chunk declares " + std::to_string(c.unpacked_size) + " bytes of pixels in " +
                        std::to_string(c.packed_size) + " bytes; " + compressionName(compression) + " expands at most " +
                        std::to_string(ratio) + " times"};
        }
        packedTotal += c.packed_size;
        return {};
    };
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 0;
        if (exr_get_scanlines_per_chunk(ctx, p, &lines) != EXR_ERR_SUCCESS || lines < 1)
            return {Rule::V1, ErrorCode::Corrupt, label + ": invalid scanlines per chunk"};
        for (std::int64_t y = dw.min.y; y <= dw.max.y; y += lines) {
            exr_chunk_info_t c{};
            const exr_result_t rv = exr_read_scanline_chunk_info(ctx, p, static_cast<int>(y), &c);
            if (Problem problem = visit(rv, c, "scanline " + std::to_string(y)); !problem.message.empty()) return problem;
        }
    } else if (storage == EXR_STORAGE_TILED) {
        uint32_t tw = 0, th = 0;
        exr_tile_level_mode_t level{};
        exr_tile_round_mode_t round{};
        if (exr_get_tile_descriptor(ctx, p, &tw, &th, &level, &round) != EXR_ERR_SUCCESS || tw < 1 || th < 1)
            return {Rule::V1, ErrorCode::Corrupt, label + ": invalid tile description"};
        const std::int64_t tilesX = (width + tw - 1) / tw, tilesY = (height + th - 1) / th;
        for (std::int64_t ty = 0; ty < tilesY; ++ty) {
            for (std::int64_t tx = 0; tx < tilesX; ++tx) {
                exr_chunk_info_t c{};
                const exr_result_t rv = exr_read_tile_chunk_info(ctx, p, int(tx), int(ty), 0, 0, &c);
                if (Problem problem = visit(rv, c, "tile (" + std::to_string(tx) + ", " + std::to_string(ty) + ")");
                    !problem.message.empty())
                    return problem;
            }
        }
    } else {
        return {};  // deep parts are never read; the header rules refuse them where they matter
    }
    // Chunks do not overlap: together they fit in the file.
    if (packedTotal > fileSize) {
        return {Rule::V1, ErrorCode::Corrupt,
                label + ": chunks hold " + std::to_string(packedTotal) + " bytes in all, more than the " +
                    std::to_string(fileSize) + "-byte file"};
    }
    return {};
}

// Readers 1 and 2 of the three above: the raw scan, then the C core's parse and its header-level
// checks. On success `core` holds the open context for the chunk checks.
Problem checkHeaders(const std::string& path, std::uintmax_t size, const Limits& limits, std::unique_ptr<CoreFile>& core) {
    if (const ScanResult scan = scanHeaders(path, size, limits); !scan.problem.empty())
        return {Rule::V1, scan.code, "not a readable OpenEXR file: " + scan.problem};
    core = std::make_unique<CoreFile>(path);
    if (!core->error().empty()) return {Rule::V1, ErrorCode::Corrupt, "not a readable OpenEXR file: " + core->error()};
    return checkCoreHeaders(core->ctx(), size);
}

// ---- headers <-> HeaderModel ------------------------------------------------------------------

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
template <>
struct ExrAttribute<std::array<float, 16>> {  // row-major, as Imath stores a matrix
    using Type = Imf::M44fAttribute;
    static std::array<float, 16> from(const Imath::M44f& m) {
        std::array<float, 16> a{};
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) a[r * 4 + c] = m[r][c];
        return a;
    }
    static Type to(const std::array<float, 16>& a) {
        Imath::M44f m;
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) m[r][c] = a[r * 4 + c];
        return Type(m);
    }
};
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

HeaderModel modelOf(const Imf::MultiPartInputFile& file) {
    HeaderModel m;
    for (int i = 0; i < file.parts(); ++i) {
        m.parts.push_back(partOf(file.header(i)));
        for (const PartSpec& spec : kParts) {
            PartSlot& slot = m.slot(spec.kind);
            if (m.parts.back().name == spec.name && slot.count++ == 0) slot.index = i;
        }
    }
    for (const PartSpec& spec : kParts) {
        if (const int index = m.slot(spec.kind).index; index >= 0) readAttributes(file.header(index), spec.kind, m);
    }
    return m;
}

// ---- HeaderModel -> ConusFile fields ----------------------------------------------------------

void fillMetadata(const HeaderModel& m, const Imf::Header& h, ConusFile& out) {
    const PartModel& part = m.part(PartKind::Conus);
    out.pixelType = PixelType::Half;
    for (const ChannelModel& c : part.channels) {
        if (c.name != "Z" && c.type == ChannelType::Float) out.pixelType = PixelType::Float;
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

// ---- writing through an AtomicFile ---------------------------------------------------------------

// OpenEXR writes through this stream into the AtomicFile, so every byte is checked. OpenEXR's
// destructors write the offset tables and swallow errors; a failure is therefore also remembered
// here and reported once the file object is gone.
class AtomicOStream final : public Imf::OStream {
public:
    explicit AtomicOStream(AtomicFile& file) : Imf::OStream(file.destination().c_str()), m_file(file) {}
    void write(const char c[], int n) override {
        try {
            if (m_pos == m_file.size()) m_file.write(c, static_cast<std::size_t>(n));
            else m_file.writeAt(m_pos, c, static_cast<std::size_t>(n));
        } catch (const Error& e) {
            if (m_failure.empty()) m_failure = e.what();
            throw;
        }
        m_pos += static_cast<std::uint64_t>(n);
    }
    std::uint64_t tellp() override { return m_pos; }
    void seekp(std::uint64_t pos) override { m_pos = pos; }
    const std::string& failure() const { return m_failure; }

private:
    AtomicFile& m_file;
    std::uint64_t m_pos = 0;
    std::string m_failure;
};

// ---- pixels ---------------------------------------------------------------------------------

void readImage(Imf::MultiPartInputFile& file, const HeaderModel& m, Image& image) {
    const int index = m.slot(PartKind::Conus).index;
    const PartModel& part = m.parts[index];
    std::vector<std::string> names;
    for (const ChannelModel& c : part.channels) names.push_back(c.name);
    image = makeImage(int(part.dataWindow.width()), int(part.dataWindow.height()), std::move(names));
    const std::size_t nc = image.channels.size();
    const std::size_t xStride = nc * sizeof(float);
    const std::size_t yStride = xStride * image.width;
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < nc; ++c) {
        // Fill 0 for nothing: every channel exists, so OpenEXR writes every value.
        fb.insert(image.channels[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(image.pixels.data() + c), xStride, yStride));
    }
    if (part.type == Imf::TILEDIMAGE) {
        Imf::TiledInputPart in(file, index);
        in.setFrameBuffer(fb);
        in.readTiles(0, in.numXTiles(0) - 1, 0, in.numYTiles(0) - 1, 0, 0);
    } else {
        Imf::InputPart in(file, index);
        in.setFrameBuffer(fb);
        in.readPixels(0, image.height - 1);
    }
}

// The map's nodes, interleaved (u, v) in GridNodes, as the part's two planes `ud` and `vd`.
Imf::FrameBuffer mapFrameBuffer(const GridNodes& grid) {
    Imf::FrameBuffer fb;
    char* base = const_cast<char*>(reinterpret_cast<const char*>(grid.xy.data()));
    const std::size_t xStride = 2 * sizeof(float);
    fb.insert(kMapChannelU, Imf::Slice(Imf::FLOAT, base, xStride, xStride * grid.columns));
    fb.insert(kMapChannelV, Imf::Slice(Imf::FLOAT, base + sizeof(float), xStride, xStride * grid.columns));
    return fb;
}

void readMap(Imf::MultiPartInputFile& file, const HeaderModel& m, GridNodes& grid) {
    const int index = m.slot(PartKind::SamplingMap).index;
    const PartModel& part = m.parts[index];
    grid.columns = int(part.dataWindow.width());
    grid.rows = int(part.dataWindow.height());
    grid.xy.assign(std::size_t{2} * grid.columns * grid.rows, 0.0f);
    Imf::InputPart in(file, index);
    in.setFrameBuffer(mapFrameBuffer(grid));
    in.readPixels(0, grid.rows - 1);
}

}  // namespace

void checkExr(const std::string& path, const Limits& limits) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) throw Error(ErrorCode::Io, "cannot read " + path + ": " + ec.message());
    std::unique_ptr<CoreFile> core;
    Problem problem = checkHeaders(path, size, limits, core);
    int parts = 0;
    if (problem.message.empty() && exr_get_count(core->ctx(), &parts) != EXR_ERR_SUCCESS)
        problem = {Rule::V1, ErrorCode::Corrupt, "not a readable OpenEXR file: no parts"};
    for (int p = 0; p < parts && problem.message.empty(); ++p) problem = checkChunks(core->ctx(), p, size);
    if (!problem.message.empty()) throw Error(problem.code, path + ": " + problem.message, {number(problem.rule)});
}

// OpenEXR (de)compresses the line blocks of one writePixels/readPixels call on its global thread
// pool, which is empty unless someone sizes it: one thread a core, once, unless the program set
// its own. A 1024^2 zip write was a serial tail of `conus encode` (bench/notes/2026-11-24-end-to-end.md).
static void useExrThreads() {
    static std::once_flag once;
    std::call_once(once, [] {
        if (Imf::globalThreadCount() == 0) Imf::setGlobalThreadCount(threadCount(0));
    });
}

LoadResult loadConusFile(const std::string& path, const Limits& limits, bool readPixels, ConusFile& out) {
    useExrThreads();
    LoadResult result;
    ValidationReport& r = result.report;
    auto refuse = [&](const Problem& problem) {
        r.add(problem.rule, problem.message);
        result.code = problem.code;
        return result;
    };
    // A FIFO never ends and a device may not either: only regular files are read.
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) {
        return refuse({Rule::V1, ErrorCode::Io, "cannot open " + path + ": " + (ec ? ec.message() : std::string("no such file"))});
    }
    if (!std::filesystem::is_regular_file(status)) return refuse({Rule::V1, ErrorCode::Io, "cannot read " + path + ": not a regular file"});
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec || !std::ifstream(path, std::ios::binary)) {
        return refuse({Rule::V1, ErrorCode::Io, "cannot open " + path + (ec ? ": " + ec.message() : std::string())});
    }
    std::unique_ptr<CoreFile> opened;
    if (Problem problem = checkHeaders(path, size, limits, opened); !problem.message.empty()) return refuse(problem);
    const CoreFile& core = *opened;
    try {
        Imf::MultiPartInputFile file(path.c_str());
        const HeaderModel model = modelOf(file);
        const HeaderCheck hc = checkHeaderRules(model, limits, r);
        if (!r.ok()) {
            result.code = hc.notConus ? ErrorCode::NotConus : hc.limitExceeded ? ErrorCode::LimitExceeded : ErrorCode::Corrupt;
            return result;
        }
        // Headers passed every rule, so every size below is within limits; the chunk tables must
        // still show that the pixels are in the file before memory is committed for them.
        const PartModel& part = model.part(PartKind::Conus);
        if (readPixels) {
            const std::int64_t bytes = part.dataWindow.width() * part.dataWindow.height() *
                                       std::int64_t(part.channels.size()) * std::int64_t(sizeof(float));
            if (bytes > limits.maxDecodeBytes) {
                return refuse({Rule::V4, ErrorCode::LimitExceeded,
                               "image of " + std::to_string(part.dataWindow.width()) + "x" + std::to_string(part.dataWindow.height()) +
                                   "x" + std::to_string(part.channels.size()) + " floats takes " + std::to_string(bytes) +
                                   " bytes, beyond the decode memory limit of " + std::to_string(limits.maxDecodeBytes)});
            }
        }
        for (const PartSpec& spec : kParts) {
            const int p = model.slot(spec.kind).index;
            if (Problem problem = checkChunks(core.ctx(), p, size); !problem.message.empty()) return refuse(problem);
        }
        ConusFile loaded;
        fillMetadata(model, file.header(model.slot(PartKind::Conus).index), loaded);
        if (readPixels) {
            readImage(file, model, loaded.image);
        } else {
            loaded.image.width = int(part.dataWindow.width());
            loaded.image.height = int(part.dataWindow.height());
            for (const ChannelModel& c : part.channels) loaded.image.channels.push_back(c.name);
        }
        readMap(file, model, loaded.map);
        const ValidationReport grid = validateGrid(loaded.map);
        r.issues.insert(r.issues.end(), grid.issues.begin(), grid.issues.end());
        if (!r.ok()) {
            result.code = ErrorCode::InvalidMap;
            return result;
        }
        out = std::move(loaded);
    } catch (const std::exception& e) {
        r.add(Rule::V1, std::string("damaged OpenEXR data: ") + e.what());
        result.code = ErrorCode::Corrupt;
    }
    return result;
}

void writeExrFile(AtomicFile& out, const ConusFile& file) {
    useExrThreads();
    const Image& im = file.image;
    const std::string& path = out.destination();
    AtomicOStream stream(out);
    try {
        // The parts and attributes the validator checked (header_model.cpp), then the source's
        // metadata, which only the `conus` part carries.
        const HeaderModel model = modelOf(file);
        std::vector<Imf::Header> headers;
        for (const PartModel& part : model.parts) headers.push_back(exrHeader(part));
        for (const PartSpec& spec : kParts) writeAttributes(model, spec.kind, headers[model.slot(spec.kind).index]);
        Imf::Header& conus = headers[model.slot(PartKind::Conus).index];
        for (const MetadataItem& item : file.sourceEncoding.metadata) {
            if (!isCarriedMetadata(item.name)) continue;  // never let an item overwrite a CoNUS attribute
            if (const auto* v = std::get_if<std::string>(&item.value)) conus.insert(item.name, Imf::StringAttribute(*v));
            else if (const auto* i = std::get_if<int>(&item.value)) conus.insert(item.name, Imf::IntAttribute(*i));
            else if (const auto* f = std::get_if<float>(&item.value)) conus.insert(item.name, Imf::FloatAttribute(*f));
            else if (const auto* d = std::get_if<double>(&item.value)) conus.insert(item.name, Imf::DoubleAttribute(*d));
        }
        Imf::MultiPartOutputFile exr(stream, headers.data(), int(headers.size()));
        {
            // OpenEXR converts types when reading but not when writing: HALF channels get their own
            // planar half buffers (rounded to nearest), FLOAT ones are written from the image.
            const std::size_t nc = im.channels.size();
            const std::size_t count = std::size_t(im.width) * im.height;
            std::vector<std::vector<Imath::half>> halves;
            Imf::FrameBuffer fb;
            for (std::size_t c = 0; c < nc; ++c) {
                if (im.channels[c] != "Z" && file.pixelType == PixelType::Half) {
                    std::vector<Imath::half>& h = halves.emplace_back(count);
                    for (std::size_t i = 0; i < count; ++i) h[i] = Imath::half(im.pixels[i * nc + c]);
                    fb.insert(im.channels[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(h.data()), sizeof(Imath::half),
                                                         sizeof(Imath::half) * im.width));
                } else {
                    fb.insert(im.channels[c], Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(im.pixels.data() + c)),
                                                         nc * sizeof(float), nc * sizeof(float) * im.width));
                }
            }
            Imf::OutputPart part(exr, model.slot(PartKind::Conus).index);
            part.setFrameBuffer(fb);
            part.writePixels(im.height);
        }
        {
            Imf::OutputPart part(exr, model.slot(PartKind::SamplingMap).index);
            part.setFrameBuffer(mapFrameBuffer(file.map));
            part.writePixels(file.map.rows);
        }
    } catch (const std::exception& e) {
        throw Error(ErrorCode::Io, stream.failure().empty() ? "cannot write " + path + ": " + e.what() : stream.failure());
    }
    if (!stream.failure().empty()) throw Error(ErrorCode::Io, stream.failure());
}

}  // namespace conus::format::detail
