// Image files through OpenImageIO: channels by name, colour conversion, metadata, atomic writes.
// OpenImageIO reports failures through geterror(); they become conus::Error right where it is
// called, naming the user's path. Built into the module libconus_imageio_oiio (oiio_module.h):
// libconus_imageio forwards to it on first use.
#include "conus/imageio/image_file.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "conus/format/exr_check.h"
#include "oiio_module.h"

namespace conus::imageio::oiio {
namespace {

// ---- what a file format holds ------------------------------------------------------------------

struct FormatTraits {
    std::vector<SampleType> sampleTypes;  // the first is the natural one
    bool anyChannels = false;             // TIFF, EXR, DPX: any number of named channels
    bool alpha = false;
};

FormatTraits traitsOf(const std::string& formatName, const OIIO::ImageOutput& output) {
    FormatTraits t;
    t.anyChannels = output.supports("nchannels") != 0;
    t.alpha = output.supports("alpha") != 0;
    using enum SampleType;
    if (formatName == "png" || formatName == "pnm" || formatName == "jpeg2000" || formatName == "dpx")
        t.sampleTypes = {Uint8, Uint16};
    else if (formatName == "tiff")
        t.sampleTypes = {Uint16, Uint8, Float, Half};
    else if (formatName == "openexr")
        t.sampleTypes = {Half, Float};
    else if (formatName == "hdr")
        t.sampleTypes = {Float};
    else
        t.sampleTypes = {Uint8};
    return t;
}

bool isInteger(SampleType t) { return t == SampleType::Uint8 || t == SampleType::Uint16 || t == SampleType::Uint32; }

OIIO::TypeDesc typeDescOf(SampleType t) {
    switch (t) {
        case SampleType::Uint8: return OIIO::TypeDesc::UINT8;
        case SampleType::Uint16: return OIIO::TypeDesc::UINT16;
        case SampleType::Uint32: return OIIO::TypeDesc::UINT32;
        case SampleType::Half: return OIIO::TypeDesc::HALF;
        case SampleType::Float: return OIIO::TypeDesc::FLOAT;
    }
    return OIIO::TypeDesc::FLOAT;
}

std::optional<SampleType> sampleTypeOf(OIIO::TypeDesc type) {
    switch (type.basetype) {
        case OIIO::TypeDesc::UINT8:
        case OIIO::TypeDesc::INT8: return SampleType::Uint8;
        case OIIO::TypeDesc::UINT16:
        case OIIO::TypeDesc::INT16: return SampleType::Uint16;
        case OIIO::TypeDesc::UINT32:
        case OIIO::TypeDesc::INT32: return SampleType::Uint32;
        case OIIO::TypeDesc::HALF: return SampleType::Half;
        case OIIO::TypeDesc::FLOAT:
        case OIIO::TypeDesc::DOUBLE: return SampleType::Float;
        default: return std::nullopt;
    }
}

std::string joinTypes(const std::vector<SampleType>& types) {
    std::string s;
    for (std::size_t i = 0; i < types.size(); ++i)
        s += std::string(i == 0 ? "" : i + 1 == types.size() ? " or " : ", ") + enumName(types[i]);
    return s;
}

// ---- channels by name --------------------------------------------------------------------------

// The colour channels of an image in display order: R,G,B when all three are there, else Y, else
// (an image of other names) its first channel for a grey picture; A separately.
struct ChannelRoles {
    std::vector<int> colour;
    int alpha = -1;
};

ChannelRoles rolesOf(const Image& image) {
    ChannelRoles roles;
    const int r = image.channelIndex("R"), g = image.channelIndex("G"), b = image.channelIndex("B");
    const int y = image.channelIndex("Y");
    if (r >= 0 && g >= 0 && b >= 0) roles.colour = {r, g, b};
    else if (y >= 0) roles.colour = {y};
    roles.alpha = image.channelIndex("A");
    return roles;
}

// ---- colour ------------------------------------------------------------------------------------

// Converts the channels `colour` of an interleaved float buffer between OpenImageIO colour spaces
// ("sRGB", "linear"). OpenImageIO converts the first channels of a buffer (its colorconvert does
// not honour a channel range that starts past 0), so colour channels that do not lead the pixel
// are gathered into a buffer of their own first.
void convertColour(float* pixels, int width, int height, int channels, const std::vector<int>& colour,
                   const char* from, const char* to, const std::string& path) {
    if (colour.empty()) return;
    const auto count = static_cast<std::size_t>(width) * height;
    const int k = static_cast<int>(colour.size());
    bool leading = k == 1 || k == 3;
    for (int i = 0; i < k && leading; ++i) leading = colour[i] == i;
    auto run = [&](float* data, int nchannels, int chend) {
        OIIO::ImageBuf buffer(OIIO::ImageSpec(width, height, nchannels, OIIO::TypeDesc::FLOAT), data);
        OIIO::ROI roi = buffer.roi();
        roi.chend = chend;
        if (!OIIO::ImageBufAlgo::colorconvert(buffer, buffer, from, to, false, "", "", nullptr, roi))
            throw Error(ErrorCode::Io, path + ": colour conversion " + from + " -> " + to + " failed: " + buffer.geterror());
    };
    if (leading) {
        run(pixels, channels, k);
        return;
    }
    for (int c : colour) {  // one channel at a time: each is converted on its own
        std::vector<float> plane(count);
        for (std::size_t p = 0; p < count; ++p) plane[p] = pixels[p * channels + c];
        run(plane.data(), 1, 1);
        for (std::size_t p = 0; p < count; ++p) pixels[p * channels + c] = plane[p];
    }
}

// Multiplies (or divides) the colour channels by alpha, through OpenImageIO.
void premultiply(float* pixels, int width, int height, int channels, int alpha, bool associate) {
    OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::FLOAT);
    spec.alpha_channel = alpha;
    OIIO::ImageBuf buffer(spec, pixels);
    if (associate) OIIO::ImageBufAlgo::premult(buffer, buffer);
    else OIIO::ImageBufAlgo::unpremult(buffer, buffer);
}

// ---- metadata ----------------------------------------------------------------------------------

void collectMetadata(const OIIO::ImageSpec& spec, bool oriented, SourceEncoding& encoding) {
    for (const OIIO::ParamValue& pv : spec.extra_attribs) {
        const std::string name = pv.name().string();
        const OIIO::TypeDesc type = pv.type();
        if (name == "Orientation") {  // carried only when it was not applied
            if (!oriented && pv.get_int(1) != 1) encoding.metadata.push_back({name, pv.get_int(1)});
            continue;
        }
        if (!isCarriedMetadata(name) || type.arraylen != 0 || type.aggregate != OIIO::TypeDesc::SCALAR) continue;
        if (type == OIIO::TypeDesc::STRING) encoding.metadata.push_back({name, pv.get_string()});
        else if (type.basetype == OIIO::TypeDesc::FLOAT) encoding.metadata.push_back({name, pv.get_float()});
        else if (type.basetype == OIIO::TypeDesc::DOUBLE) encoding.metadata.push_back({name, double(pv.get_float())});
        else if (type.is_floating_point() || type == OIIO::TypeRational) encoding.metadata.push_back({name, pv.get_float()});
        else if (type.basetype >= OIIO::TypeDesc::UINT8 && type.basetype <= OIIO::TypeDesc::INT32)
            encoding.metadata.push_back({name, pv.get_int()});
    }
    if (const OIIO::ParamValue* icc = spec.find_attribute("ICCProfile");
        icc && icc->type().basetype == OIIO::TypeDesc::UINT8 && icc->datasize() > 0) {
        const auto* bytes = static_cast<const char*>(icc->data());
        encoding.iccProfile.assign(bytes, bytes + icc->datasize());
        if (!iccProfileProblem(encoding.iccProfile).empty()) encoding.iccProfile.clear();  // garbage is not carried
    }
}

void applyMetadata(const SourceEncoding& source, bool withIcc, OIIO::ImageSpec& spec) {
    for (const MetadataItem& item : source.metadata) {
        if (const auto* s = std::get_if<std::string>(&item.value)) spec.attribute(item.name, *s);
        else if (const auto* i = std::get_if<int>(&item.value)) spec.attribute(item.name, *i);
        else if (const auto* f = std::get_if<float>(&item.value)) spec.attribute(item.name, *f);
        else if (const auto* d = std::get_if<double>(&item.value)) spec.attribute(item.name, OIIO::TypeDesc::DOUBLE, d);
    }
    if (withIcc && !source.iccProfile.empty())
        spec.attribute("ICCProfile", OIIO::TypeDesc(OIIO::TypeDesc::UINT8, static_cast<int>(source.iccProfile.size())),
                       source.iccProfile.data());
}

// ---- reading -----------------------------------------------------------------------------------

// Standard input, read whole (bounded), with a name whose extension tells OpenImageIO the format.
struct StdinImage {
    std::vector<unsigned char> bytes;
    std::string name;
};

StdinImage readStdin() {
    constexpr std::size_t kMaxStdinBytes = std::size_t{4} << 30;
    StdinImage in;
    unsigned char chunk[1 << 16];
    std::size_t n;
    while ((n = std::fread(chunk, 1, sizeof chunk, stdin)) > 0) {
        in.bytes.insert(in.bytes.end(), chunk, chunk + n);
        if (in.bytes.size() > kMaxStdinBytes)
            throw Error(ErrorCode::LimitExceeded, "standard input holds more than 4 GiB; give a file instead");
    }
    if (in.bytes.empty()) throw Error(ErrorCode::Io, "standard input is empty");
    const auto starts = [&](const char* magic, std::size_t size) {
        return in.bytes.size() >= size && std::memcmp(in.bytes.data(), magic, size) == 0;
    };
    const char* ext = starts("\x89PNG", 4)               ? "png"
                      : starts("\xFF\xD8\xFF", 3)          ? "jpg"
                      : starts("II*\0", 4) || starts("MM\0*", 4) ? "tif"
                      : starts("\x76\x2f\x31\x01", 4)      ? "exr"
                      : starts("BM", 2)                    ? "bmp"
                      : starts("#?", 2)                    ? "hdr"
                      : starts("P", 1)                     ? "ppm"
                                                           : "";
    if (!*ext) throw Error(ErrorCode::Io, "standard input is not an image format CoNUS recognizes (PNG, JPEG, TIFF, EXR, BMP, HDR, PPM)");
    in.name = std::string("stdin.") + ext;
    return in;
}

bool isOpenExr(const unsigned char* bytes, std::size_t size) {
    return size >= 4 && std::memcmp(bytes, "\x76\x2f\x31\x01", 4) == 0;
}

// OpenEXR files are screened before OpenImageIO opens them (format/exr_check.h): it reads them with
// OpenEXR's C++ library, which allocates what a header declares (a 1.9 GB attribute in a 4 KB file
// cost 8 s and 2 GB; a 32768x32768 window in 5 KB, 73 s and 12.7 GB). Standard input is screened
// from a temporary copy, since the screen reads a file. Returns the file's size in bytes.
std::uintmax_t screenInput(const std::string& path, const StdinImage& stdinImage, const Limits& limits) {
    if (path == "-") {
        const std::vector<unsigned char>& bytes = stdinImage.bytes;
        if (isOpenExr(bytes.data(), bytes.size())) {
            const std::filesystem::path copy =
                std::filesystem::temp_directory_path() / ("conus-stdin-" + std::to_string(::getpid()) + ".exr");
            struct Remove {
                const std::filesystem::path& path;
                ~Remove() { std::error_code ec; std::filesystem::remove(path, ec); }
            } remove{copy};
            std::FILE* f = std::fopen(copy.c_str(), "wb");
            const bool written = f && std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
            if (f && std::fclose(f) != 0) throw Error(ErrorCode::Io, "cannot copy standard input to " + copy.string());
            if (!written) throw Error(ErrorCode::Io, "cannot copy standard input to " + copy.string());
            try {
                format::checkExrFile(copy.string(), limits);
            } catch (const Error& e) {
                const std::string what = e.what();
                throw Error(e.code(), "standard input" + what.substr(std::min(what.size(), copy.string().size())));
            }
        }
        return bytes.size();
    }
    unsigned char magic[4] = {};
    std::FILE* f = std::fopen(path.c_str(), "rb");
    const std::size_t n = f ? std::fread(magic, 1, sizeof magic, f) : 0;
    if (f) std::fclose(f);
    if (isOpenExr(magic, n)) format::checkExrFile(path, limits);
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    return ec ? 0 : size;
}

// Seeks to the part `wanted` (a name or an index; empty: the first) and says which it was.
void selectPart(OIIO::ImageInput& in, const std::string& path, const std::string& wanted, ImageFileInfo& info) {
    constexpr int kMaxParts = 10000;
    std::vector<std::string> names;
    for (int i = 0; i < kMaxParts && in.seek_subimage(i, 0); ++i)
        names.push_back(in.spec().get_string_attribute("oiio:subimagename"));
    info.parts = std::max(1, static_cast<int>(names.size()));
    int chosen = 0;
    if (!wanted.empty()) {
        chosen = -1;
        for (std::size_t i = 0; i < names.size(); ++i)
            if (names[i] == wanted) chosen = static_cast<int>(i);
        char* end = nullptr;
        const long index = std::strtol(wanted.c_str(), &end, 10);
        if (chosen < 0 && end && *end == '\0' && index >= 0 && index < static_cast<long>(names.size()))
            chosen = static_cast<int>(index);
        if (chosen < 0) {
            std::string list;
            for (std::size_t i = 0; i < names.size(); ++i)
                list += (i ? ", " : "") + std::to_string(i) + (names[i].empty() ? "" : " (" + names[i] + ")");
            throw Error(ErrorCode::InvalidArgument, path + " has no part '" + wanted + "'; its parts are " + list);
        }
    }
    if (!in.seek_subimage(chosen, 0)) throw Error(ErrorCode::Io, path + ": cannot read part " + std::to_string(chosen));
    info.part = chosen;
    info.partName = chosen < static_cast<int>(names.size()) ? names[chosen] : "";
}

// ---- integer samples through tables -------------------------------------------------------------

// An 8- or 16-bit image without alpha (a photograph) is read without a float copy to convert in
// place: its rows are decoded in strips of native samples, each sample becoming its float value
// through a table of every value the sample type has. The tables are made by the very calls the
// general path makes on each pixel (OpenImageIO's conversion to float, then convertColour), so
// the pixels come out the same to the bit, in one pass instead of three over 200 MB at 4096^2.
struct SampleTables {
    std::vector<float> plain;   // the sample as float, as read_image gives it
    std::vector<float> colour;  // the same, converted from sRGB to linear (empty: not asked)
};

bool readsThroughTables(const OIIO::ImageSpec& spec, const ChannelRoles& roles, Transfer transfer) {
    if (!spec.channelformats.empty() || (spec.format != OIIO::TypeDesc::UINT8 && spec.format != OIIO::TypeDesc::UINT16))
        return false;
    if (transfer == Transfer::Raw) return true;
    if (roles.alpha >= 0) return false;  // straight alpha, associated in linear light: the general path
    for (std::size_t i = 0; i < roles.colour.size(); ++i)
        if (roles.colour[i] != static_cast<int>(i)) return false;
    return true;
}

// nullopt when the colour conversion mixes channels (a table per channel cannot hold that).
std::optional<SampleTables> makeSampleTables(OIIO::TypeDesc type, const std::vector<int>& colour, bool srgb,
                                             const std::string& path) {
    const int values = type == OIIO::TypeDesc::UINT8 ? 256 : 65536;
    SampleTables t;
    t.plain.resize(values);
    if (type == OIIO::TypeDesc::UINT8) {
        std::vector<unsigned char> raw(values);
        for (int v = 0; v < values; ++v) raw[v] = static_cast<unsigned char>(v);
        OIIO::convert_pixel_values(type, raw.data(), OIIO::TypeDesc::FLOAT, t.plain.data(), values);
    } else {
        std::vector<unsigned short> raw(values);
        for (int v = 0; v < values; ++v) raw[v] = static_cast<unsigned short>(v);
        OIIO::convert_pixel_values(type, raw.data(), OIIO::TypeDesc::FLOAT, t.plain.data(), values);
    }
    if (!srgb || colour.empty()) return t;
    const int k = static_cast<int>(colour.size());
    std::vector<float> ramp(static_cast<std::size_t>(values) * k);
    for (int v = 0; v < values; ++v)
        for (int c = 0; c < k; ++c) ramp[static_cast<std::size_t>(v) * k + c] = t.plain[v];
    std::vector<int> leading(k);
    for (int c = 0; c < k; ++c) leading[c] = c;
    convertColour(ramp.data(), values, 1, k, leading, "sRGB", "linear", path);
    t.colour.resize(values);
    for (int v = 0; v < values; ++v) {
        t.colour[v] = ramp[static_cast<std::size_t>(v) * k];
        for (int c = 1; c < k; ++c)
            if (ramp[static_cast<std::size_t>(v) * k + c] != t.colour[v]) return std::nullopt;
    }
    return t;
}

template <typename Sample>
void convertRows(const Sample* samples, std::size_t count, int channels, const std::vector<const float*>& tables, float* out) {
    for (std::size_t i = 0; i < count; i += channels)
        for (int c = 0; c < channels; ++c) out[i + c] = tables[c][samples[i + c]];
}

// Fills `image` (already sized) from the current part of `in`; false when tables cannot reproduce
// the general path (then nothing was read).
bool readThroughTables(OIIO::ImageInput& in, int part, const OIIO::ImageSpec& spec, const ChannelRoles& roles,
                       Transfer transfer, Image& image, const std::string& shown) {
    const std::optional<SampleTables> tables =
        makeSampleTables(spec.format, roles.colour, transfer == Transfer::Srgb, shown);
    if (!tables) return false;
    const int channels = spec.nchannels;
    std::vector<const float*> perChannel(channels, tables->plain.data());
    if (!tables->colour.empty())
        for (int c : roles.colour) perChannel[c] = tables->colour.data();
    constexpr int kStripRows = 64;
    const std::size_t rowSamples = static_cast<std::size_t>(spec.width) * channels;
    std::vector<unsigned char> strip(kStripRows * rowSamples * spec.format.size());
    for (int y0 = 0; y0 < spec.height; y0 += kStripRows) {
        const int y1 = std::min(spec.height, y0 + kStripRows);
        if (!in.read_scanlines(part, 0, spec.y + y0, spec.y + y1, 0, 0, channels, spec.format, strip.data())) {
            std::string reason = in.geterror();
            if (reason.empty()) reason = "the file ends early or is damaged";
            throw Error(ErrorCode::Io, shown + ": cannot read pixels: " + reason);
        }
        const std::size_t count = static_cast<std::size_t>(y1 - y0) * rowSamples;
        float* out = image.pixels.data() + static_cast<std::size_t>(y0) * rowSamples;
        if (spec.format == OIIO::TypeDesc::UINT8) convertRows(strip.data(), count, channels, perChannel, out);
        else convertRows(reinterpret_cast<const unsigned short*>(strip.data()), count, channels, perChannel, out);
    }
    return true;
}

Transfer detectTransfer(const OIIO::ImageSpec& spec) {
    const OIIO::TypeDesc::BASETYPE base = static_cast<OIIO::TypeDesc::BASETYPE>(spec.format.basetype);
    if (base == OIIO::TypeDesc::HALF || base == OIIO::TypeDesc::FLOAT || base == OIIO::TypeDesc::DOUBLE)
        return Transfer::Linear;
    const std::string cs = spec.get_string_attribute("oiio:ColorSpace");
    if (OIIO::Strutil::iequals(cs, "linear") || OIIO::Strutil::iequals(cs, "scene_linear") ||
        OIIO::Strutil::iequals(cs, "lin_srgb") || OIIO::Strutil::iequals(cs, "Gamma1.0"))
        return Transfer::Linear;
    return Transfer::Srgb;  // sRGB, untagged, or a display gamma: sRGB is what such files hold
}

}  // namespace

ImageFile readImageFile(const std::string& path, const ReadOptions& options) {
    checkInputPath(path, /*allowStdin=*/true);
    StdinImage stdinImage;
    std::unique_ptr<OIIO::Filesystem::IOMemReader> memory;
    std::string openName = path;
    if (path == "-") {
        stdinImage = readStdin();
        memory = std::make_unique<OIIO::Filesystem::IOMemReader>(stdinImage.bytes.data(), stdinImage.bytes.size());
        openName = stdinImage.name;
    }
    const std::string shown = path == "-" ? std::string("standard input") : path;
    const std::uintmax_t fileSize = screenInput(path, stdinImage, options.limits);
    // Straight alpha as stored: colour is linearized first, then associated (in linear light).
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    // OpenImageIO 2.4 takes the proxy from the configuration once there is one (its pointer's value).
    void* proxy = memory.get();
    if (proxy) config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    auto in = OIIO::ImageInput::open(openName, &config, memory.get());
    if (!in) {
        std::string reason = OIIO::geterror();
        if (reason.empty()) reason = "not an image format OpenImageIO reads";
        throw Error(ErrorCode::Io, shown + ": cannot read image: " + reason);
    }
    ImageFile result;
    ImageFileInfo& info = result.info;
    info.format = in->format_name();
    selectPart(*in, shown, options.part, info);
    const OIIO::ImageSpec spec = in->spec();  // a copy: reading may change the input's
    const std::int64_t pixels = std::int64_t{spec.width} * spec.height;
    if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1)
        throw Error(ErrorCode::Io, shown + ": the image is empty (" + std::to_string(spec.width) + "x" +
                                       std::to_string(spec.height) + ", " + std::to_string(spec.nchannels) + " channels)");
    const Limits& limits = options.limits;
    if (spec.width > kMaxImageSide || spec.height > kMaxImageSide || pixels > limits.maxPixels ||
        spec.nchannels > limits.maxChannels)
        throw Error(ErrorCode::LimitExceeded,
                    shown + ": image of " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels and " +
                        std::to_string(spec.nchannels) + " channels is beyond the limits (sides up to " +
                        std::to_string(kMaxImageSide) + ", " + std::to_string(limits.maxPixels) +
                        " pixels, " + std::to_string(limits.maxChannels) + " channels)");

    // Memory for the pixels only once the file can hold them: within the decode memory limit, and
    // (for formats other than OpenEXR, whose chunk tables were checked) no more samples than the
    // file's bytes can expand to. kMaxExpansion is beyond what PNG's deflate (1032:1), TIFF's LZW
    // (~1300:1), JPEG (~500:1 for a flat colour) or any run-length coding reaches.
    constexpr std::uintmax_t kMaxExpansion = 4096;
    const std::int64_t floatBytes = pixels * spec.nchannels * std::int64_t(sizeof(float));
    if (floatBytes > limits.maxDecodeBytes)
        throw Error(ErrorCode::LimitExceeded, shown + ": image of " + std::to_string(spec.width) + "x" +
                                                  std::to_string(spec.height) + "x" + std::to_string(spec.nchannels) +
                                                  " floats takes " + std::to_string(floatBytes) +
                                                  " bytes, beyond the decode memory limit of " + std::to_string(limits.maxDecodeBytes));
    const std::uintmax_t fileBytes = std::uintmax_t(pixels) * std::uintmax_t(spec.nchannels) * spec.format.size();
    if (info.format != "openexr" && fileSize > 0 && fileBytes / kMaxExpansion > fileSize)
        throw Error(ErrorCode::Corrupt, shown + ": declares " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                            " pixels (" + std::to_string(fileBytes) + " bytes of samples) in a " +
                                            std::to_string(fileSize) + "-byte file; no image compression expands that far");

    std::vector<std::string> names;
    for (int c = 0; c < spec.nchannels; ++c) {
        char unnamed[16];  // a file without channel names: C0, C1, ...
        std::snprintf(unnamed, sizeof unnamed, "C%d", c);
        const std::string n = spec.channel_name(c);
        names.push_back(n.empty() ? std::string(unnamed) : n);
    }
    Image& image = result.image;
    image = makeImage(spec.width, spec.height, names);
    SourceEncoding& encoding = info.encoding;
    encoding.sampleType = sampleTypeOf(spec.format);
    encoding.transfer = options.colorspace.value_or(detectTransfer(spec));
    // Integer samples without alpha: straight to linear float through tables (same values).
    const bool tabled = readsThroughTables(spec, rolesOf(image), encoding.transfer) &&
                        readThroughTables(*in, info.part, spec, rolesOf(image), encoding.transfer, image, shown);
    if (!tabled && !in->read_image(info.part, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data())) {
        std::string reason = in->geterror();
        if (reason.empty()) reason = "the file ends early or is damaged";
        throw Error(ErrorCode::Io, shown + ": cannot read pixels: " + reason);
    }

    info.orientation = spec.get_int_attribute("Orientation", 1);
    info.oriented = options.autoOrient && info.orientation >= 2 && info.orientation <= 8;
    collectMetadata(spec, info.oriented, encoding);
    if (encoding.transfer != Transfer::Raw) {
        if (const OIIO::ParamValue* c = spec.find_attribute("chromaticities", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8))) {
            std::array<float, 8> xy{};
            std::memcpy(xy.data(), c->data(), sizeof xy);
            encoding.chromaticities = xy;
        } else if (encoding.iccProfile.empty() || encoding.iccProfile.find("sRGB") != std::string::npos) {
            // Untagged, or a profile that names itself sRGB (its description tag): sRGB's primaries.
            encoding.chromaticities = kRec709Chromaticities;
        }
    }

    info.nonFinite = tabled ? 0 : countNonFinite(image);  // every table value is finite
    if (info.nonFinite > 0) repairNonFinite(image, options.repair, shown);

    // Colour: linear light with associated alpha, as OpenEXR has it (the tables did it already).
    if (encoding.transfer != Transfer::Raw && !tabled) {
        const ChannelRoles roles = rolesOf(image);
        const bool straight = spec.get_int_attribute("oiio:UnassociatedAlpha", 0) != 0;
        const int c = image.channelCount();
        if (encoding.transfer == Transfer::Srgb) {
            if (roles.alpha >= 0 && !straight) premultiply(image.pixels.data(), image.width, image.height, c, roles.alpha, false);
            convertColour(image.pixels.data(), image.width, image.height, c, roles.colour, "sRGB", "linear", shown);
        }
        if (roles.alpha >= 0 && (straight || encoding.transfer == Transfer::Srgb))
            premultiply(image.pixels.data(), image.width, image.height, c, roles.alpha, true);
    }

    if (info.oriented) {
        OIIO::ImageSpec oriented(image.width, image.height, image.channelCount(), OIIO::TypeDesc::FLOAT);
        oriented.attribute("Orientation", info.orientation);
        OIIO::ImageBuf upright = OIIO::ImageBufAlgo::reorient(OIIO::ImageBuf(oriented, image.pixels.data()));
        if (upright.has_error()) throw Error(ErrorCode::Io, shown + ": cannot apply the EXIF orientation: " + upright.geterror());
        const OIIO::ROI roi = upright.roi();
        Image turned = makeImage(roi.width(), roi.height(), image.channels);
        upright.get_pixels(roi, OIIO::TypeDesc::FLOAT, turned.pixels.data());
        image = std::move(turned);
    }
    return result;
}

void linearize(Image& image) {
    checkImage(image, "linearize");
    const ChannelRoles roles = rolesOf(image);
    convertColour(image.pixels.data(), image.width, image.height, image.channelCount(), roles.colour, "sRGB", "linear",
                  "an image");
    if (roles.alpha >= 0) premultiply(image.pixels.data(), image.width, image.height, image.channelCount(), roles.alpha, true);
}

Image displayEncoded(const Image& image) {
    checkImage(image, "displayEncoded");
    Image out = image;
    for (float& v : out.pixels)
        if (!std::isfinite(v)) v = 0.0f;
    const ChannelRoles roles = rolesOf(out);
    if (roles.alpha >= 0) premultiply(out.pixels.data(), out.width, out.height, out.channelCount(), roles.alpha, false);
    std::vector<int> colour = roles.colour;
    if (colour.empty()) colour = {0};
    convertColour(out.pixels.data(), out.width, out.height, out.channelCount(), colour, "linear", "sRGB", "an image");
    for (std::size_t p = 0; p < out.pixels.size(); p += out.channels.size())
        for (int c : colour) out.pixels[p + c] = std::clamp(out.pixels[p + c], 0.0f, 1.0f);
    return out;
}

// ---- writing -----------------------------------------------------------------------------------

namespace {

// OpenImageIO's writers write through this proxy into an AtomicFile: every byte checked, and the
// file renamed into place only after the writer closed without error.
class AtomicProxy final : public OIIO::Filesystem::IOProxy {
public:
    explicit AtomicProxy(AtomicFile& file) : IOProxy(file.destination(), IOProxy::Write), m_file(file) {}
    const char* proxytype() const override { return "conus-atomic"; }
    size_t write(const void* buf, size_t size) override {
        const std::size_t n = pwrite(buf, size, m_pos);
        m_pos += static_cast<int64_t>(n);
        return n;
    }
    size_t pwrite(const void* buf, size_t size, int64_t offset) override {
        if (!m_error.empty()) return 0;
        try {
            if (static_cast<std::uint64_t>(offset) == m_file.size()) m_file.write(buf, size);
            else m_file.writeAt(static_cast<std::uint64_t>(offset), buf, size);
        } catch (const Error& e) {
            m_error = e.what();
            return 0;
        }
        return size;
    }
    size_t read(void* buf, size_t size) override {
        const std::size_t n = pread(buf, size, m_pos);
        m_pos += static_cast<int64_t>(n);
        return n;
    }
    size_t pread(void* buf, size_t size, int64_t offset) override {
        if (!m_error.empty()) return 0;
        try {
            return m_file.readAt(static_cast<std::uint64_t>(offset), buf, size);
        } catch (const Error& e) {
            m_error = e.what();
            return 0;
        }
    }
    bool seek(int64_t offset) override {
        m_pos = offset;
        return true;
    }
    size_t size() const override { return static_cast<size_t>(m_file.size()); }
    const std::string& failure() const { return m_error; }

private:
    AtomicFile& m_file;
};

struct Target {
    std::unique_ptr<OIIO::ImageOutput> output;
    std::string formatName;
    FormatTraits traits;
    SampleType sampleType = SampleType::Uint8;
};

Target targetFor(const std::string& path, const WriteOptions& options) {
    Target t;
    t.output = OIIO::ImageOutput::create(path);
    if (!t.output) {
        const std::string ext = std::filesystem::path(path).extension().string();
        (void)OIIO::geterror();
        throw Error(ErrorCode::InvalidArgument,
                    path + ": no image writer for " + (ext.empty() ? std::string("a name without an extension") : "'" + ext + "'") +
                        " (use .png, .jpg, .tif, .exr, .bmp, .hdr, ...)");
    }
    t.formatName = t.output->format_name();
    t.traits = traitsOf(t.formatName, *t.output);
    const auto holds = [&](SampleType s) {
        return std::find(t.traits.sampleTypes.begin(), t.traits.sampleTypes.end(), s) != t.traits.sampleTypes.end();
    };
    if (options.sampleType) {
        if (!holds(*options.sampleType))
            throw Error(ErrorCode::InvalidArgument, path + ": " + t.formatName + " holds " + joinTypes(t.traits.sampleTypes) +
                                                        " samples, not " + enumName(*options.sampleType));
        t.sampleType = *options.sampleType;
        return t;
    }
    t.sampleType = t.traits.sampleTypes.front();
    const std::optional<SampleType> source = options.source ? options.source->sampleType : std::nullopt;
    if (source && holds(*source)) t.sampleType = *source;
    else if (source && !isInteger(*source) && holds(SampleType::Float)) t.sampleType = SampleType::Float;  // linear stays float
    return t;
}

}  // namespace

void checkImageOutput(const std::string& path, const WriteOptions& options) {
    checkOutputPath(path);
    (void)targetFor(path, options);
}

std::string sampleTypesOf(const std::string& path) {
    auto output = OIIO::ImageOutput::create(path);
    if (!output) return "no";
    return joinTypes(traitsOf(output->format_name(), *output).sampleTypes);
}

void writeImageFile(const std::string& path, const Image& image, const WriteOptions& options) {
    checkImage(image, "writeImageFile");
    Target target = targetFor(path, options);
    const bool integer = isInteger(target.sampleType);

    // Channels by name: colour first in display order, then alpha, then (formats with named
    // channels only) the rest in the image's order.
    ChannelRoles roles = rolesOf(image);
    if (roles.colour.empty()) {  // no R,G,B or Y: show the first non-alpha channel as grey
        for (int c = 0; c < image.channelCount() && roles.colour.empty(); ++c)
            if (c != roles.alpha) roles.colour = {c};
        if (roles.colour.empty()) roles.colour = {0};
    }
    std::vector<int> order = roles.colour;
    int alpha = -1;
    if (roles.alpha >= 0 && target.traits.alpha && std::find(order.begin(), order.end(), roles.alpha) == order.end()) {
        alpha = static_cast<int>(order.size());
        order.push_back(roles.alpha);
    }
    if (target.traits.anyChannels)
        for (int c = 0; c < image.channelCount(); ++c)
            if (std::find(order.begin(), order.end(), c) == order.end()) order.push_back(c);
    const int channels = static_cast<int>(order.size());
    std::vector<int> colour(roles.colour.size());
    for (std::size_t i = 0; i < colour.size(); ++i) colour[i] = static_cast<int>(i);

    constexpr int kJpegMaxSide = 65500;  // libjpeg ends the process on larger images
    if (target.formatName == "jpeg" && (image.width > kJpegMaxSide || image.height > kJpegMaxSide))
        throw Error(ErrorCode::InvalidArgument, path + ": JPEG holds at most 65500 pixels a side, not " +
                                                    std::to_string(image.width) + "x" + std::to_string(image.height));

    const auto count = static_cast<std::size_t>(image.width) * image.height;
    std::vector<float> pixels(count * channels);
    for (std::size_t p = 0; p < count; ++p)
        for (int i = 0; i < channels; ++i) pixels[p * channels + i] = image.pixels[p * image.channelCount() + order[i]];

    // What the written values encode.
    const SourceEncoding* source = options.source;
    const bool raw = options.meaning == PixelMeaning::Raw || (source && source->transfer == Transfer::Raw);
    Transfer written = Transfer::Linear;
    if (raw) written = Transfer::Raw;
    else if (integer)
        written = source && source->transfer == Transfer::Linear && source->sampleType && isInteger(*source->sampleType)
                      ? Transfer::Linear
                      : Transfer::Srgb;

    if (!raw) {
        const float gain = static_cast<float>(std::exp2(options.display.exposure));
        const ToneMap toneMap = integer ? options.display.toneMap : ToneMap::None;
        if (options.meaning == PixelMeaning::Linear) {
            // Display formats store straight alpha; the colour is encoded from straight linear values.
            if (integer && alpha >= 0) premultiply(pixels.data(), image.width, image.height, channels, alpha, false);
            if (gain != 1.0f || toneMap != ToneMap::None)
                for (std::size_t p = 0; p < count; ++p)
                    for (int c : colour) pixels[p * channels + c] = exposeAndToneMap(pixels[p * channels + c], gain, toneMap);
            if (written == Transfer::Srgb)
                convertColour(pixels.data(), image.width, image.height, channels, colour, "linear", "sRGB", path);
        } else if (written != Transfer::Srgb) {  // display artwork into a linear format
            convertColour(pixels.data(), image.width, image.height, channels, colour, "sRGB", "linear", path);
        }
    }

    OIIO::ImageSpec spec(image.width, image.height, channels, typeDescOf(target.sampleType));
    spec.channelnames.clear();
    for (int c : order) spec.channelnames.push_back(image.channels[c]);
    spec.alpha_channel = alpha;
    spec.z_channel = -1;
    for (int i = 0; i < channels; ++i)
        if (spec.channelnames[i] == "Z") spec.z_channel = i;
    if (written == Transfer::Srgb) spec.attribute("oiio:ColorSpace", "sRGB");
    else if (written == Transfer::Linear) spec.attribute("oiio:ColorSpace", "Linear");
    if (integer && alpha >= 0) spec.attribute("oiio:UnassociatedAlpha", 1);
    if (target.formatName == "openexr") spec.attribute("compression", "zip");
    // zlib level 4, not OpenImageIO's 6: a 1920x1080 photo view (bench/notes/2026-11-24-decode-pyramid.md)
    // deflated at 6 took 0.6 s of CPU, a third of `conus decode`, for a file 4% smaller than at 4,
    // which takes 0.1 s; levels 1-3 save no more time and grow the file 6-11%.
    if (target.formatName == "png") spec.attribute("png:compressionLevel", 4);
    if (source) {
        applyMetadata(*source, written != Transfer::Raw, spec);
        if (!integer && source->chromaticities && !raw)
            spec.attribute("chromaticities", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8), source->chromaticities->data());
    }

    AtomicFile file(path);
    AtomicProxy proxy(file);
    // OpenImageIO 2.4.7 writes an unreadable TIFF through an IOProxy once it adds an EXIF
    // directory (measured: the header ends up pointing at the EXIF directory), so TIFF is written
    // by name into the temporary file and read back to check it.
    const bool proxied = target.formatName != "tiff" && target.output->supports("ioproxy") && target.output->set_ioproxy(&proxy);
    const std::string openPath = proxied ? path : file.temporaryPath();
    bool ok = target.output->open(openPath, spec);
    ok = ok && target.output->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
    ok = target.output->close() && ok;
    std::string reason = proxy.failure().empty() ? target.output->geterror() : proxy.failure();
    if (ok && proxy.failure().empty() && !proxied) {
        auto check = OIIO::ImageInput::open(openPath);
        if (!check || check->spec().width != spec.width || check->spec().height != spec.height) {
            ok = false;
            reason = "the finished file does not read back: " + (check ? std::string("wrong size") : OIIO::geterror());
        }
    }
    if (!ok || !proxy.failure().empty()) {
        if (reason.empty()) reason = "the " + target.formatName + " writer failed";
        for (std::size_t at; (at = reason.find(file.temporaryPath())) != std::string::npos;)
            reason.replace(at, file.temporaryPath().size(), path);  // the user's path, never the temporary one
        // A failure already worded for the destination is passed on as it is.
        throw Error(ErrorCode::Io, reason.rfind("cannot write " + path, 0) == 0 ? reason : "cannot write " + path + ": " + reason);
    }
    file.commit();
}

}  // namespace conus::imageio::oiio
