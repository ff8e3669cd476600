// Reading image files through OpenImageIO (oiio_module_pvt.h's readImageFile): standard input, the
// OpenEXR screen, the part, the limits before memory, integer samples through tables, colour to
// linear light with associated alpha, metadata, the EXIF orientation. OpenImageIO's failures
// become conus::Error right where it is called, naming the user's path.
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "conus/format/exr_check.h"
#include "image_colour_pvt.h"
#include "oiio_module_pvt.h"
#include "stdin_image_pvt.h"

namespace conus::imageio::oiio {
namespace {

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

// ---- reading -----------------------------------------------------------------------------------

bool isOpenExr(const unsigned char* bytes, std::size_t size) {
    return size >= 4 && std::memcmp(bytes, "\x76\x2f\x31\x01", 4) == 0;
}

// A JPEG's APP13 segment ("Photoshop 3.0": image resources, IPTC records among them) is screened
// as OpenImageIO 2.4 reads it before OpenImageIO opens the file: it looks only at the first
// resource, at fixed offsets ("8BIM", the id 0x0404, four bytes it skips, a 16-bit size), and walks
// the IPTC records from there trusting each record's 16-bit length, past the segment's end where
// a record says more than the segment holds (a heap over-read). Reading the resource the way the
// Photoshop format defines it (a name of any length) would screen other bytes than the ones
// OpenImageIO reads, so the screen reads it the same way and refuses what would take OpenImageIO
// past the segment.
void checkPhotoshopSegment(const std::vector<unsigned char>& segment, const std::string& shown) {
    static constexpr char kSignature[] = "Photoshop 3.0";  // and its terminating zero
    const std::size_t end = segment.size(), at = sizeof kSignature;
    if (end < at || std::memcmp(segment.data(), kSignature, sizeof kSignature) != 0) return;
    const auto refuse = [&](const char* what) {
        throw Error(ErrorCode::Io, shown + ": a JPEG whose Photoshop (APP13) segment is damaged: " + what);
    };
    if (end < at + 6 || std::memcmp(&segment[at], "8BIM", 4) != 0 || (segment[at + 4] << 8 | segment[at + 5]) != 0x0404) return;
    if (end < at + 12) refuse("its IPTC block is cut short");
    const std::size_t size = std::size_t{segment[at + 10]} << 8 | segment[at + 11];
    std::size_t r = at + 12;
    if (size > end - r) refuse("its IPTC block says more bytes than the segment holds");
    std::size_t left = size;
    while (left > 0 && r < end && segment[r] == 0x1C) {
        if (end - r < 5) refuse("an IPTC record runs past the segment");
        if (segment[r + 1] != 0x01 && segment[r + 1] != 0x02) return;  // where OpenImageIO stops
        const std::size_t length = std::size_t{segment[r + 3]} << 8 | segment[r + 4];
        if (length > end - (r + 5)) refuse("an IPTC record runs past the segment");
        const std::size_t step = 5 + length;
        if (step >= left) return;
        left -= step;
        r += step;
    }
}

// A progressive JPEG's decoder passes over every block of the image once per scan, and a scan
// may code nothing but an end-of-band run: 2,000 such scans in 592 KB cost libjpeg over a minute
// at 8192x8192. OpenImageIO sets no scan limit, so the scans are counted here, walking the
// markers (each segment's length, the entropy-coded data to its next marker), before it opens
// the file. `next` gives the file's bytes in order, -1 at the end.
template <class Next>
void checkJpegScans(Next next, const std::string& shown) {
    int scans = 0;
    int c = next();
    while (c >= 0) {
        if (c != 0xFF) {  // entropy-coded data (or garbage between segments): on to the next marker
            c = next();
            continue;
        }
        do c = next();
        while (c == 0xFF);  // fill bytes
        if (c < 0 || c == 0xD9) return;  // the end, or EOI
        if (c == 0x00 || (c >= 0xD0 && c <= 0xD8) || c == 0x01) {  // stuffed zero, RSTn, SOI, TEM: no length
            c = next();
            continue;
        }
        if (c == 0xDA && ++scans > kMaxJpegScans)
            throw Error(ErrorCode::LimitExceeded, shown + ": a JPEG of more than " + std::to_string(kMaxJpegScans) +
                                                      " scans, the limit (each scan is a pass over the whole image)");
        const int high = next(), low = next();
        if (high < 0 || low < 0) return;
        if (c == 0xED) {  // APP13: kept whole and screened (checkPhotoshopSegment)
            std::vector<unsigned char> segment;
            for (int left = (high << 8 | low) - 2; left > 0; --left) {
                const int b = next();
                if (b < 0) break;
                segment.push_back(static_cast<unsigned char>(b));
            }
            checkPhotoshopSegment(segment, shown);
        } else {
            for (int left = (high << 8 | low) - 2; left > 0 && c >= 0; --left) c = next();  // the segment
        }
        c = next();
    }
}

void checkJpegScans(const std::string& path, const std::string& shown) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return;  // OpenImageIO says why it cannot open it
    struct Close {
        std::FILE* f;
        ~Close() { std::fclose(f); }
    } close{f};
    checkJpegScans(
        [f] {
            const int c = getc_unlocked(f);
            return c == EOF ? -1 : c;
        },
        shown);
}

// A DDS header (the 4-byte magic, 124 bytes of header, and DX10's 20 more) is read before
// OpenImageIO opens the file: a volume, a cube map or an array is refused from what the header
// declares, whatever OpenImageIO would make of it (a header with a depth but no volume flag had its
// reader loop on slices its one-slice image does not have).
void checkDdsHeader(const unsigned char* bytes, std::size_t size, const std::string& shown) {
    if (size < 128 || std::memcmp(bytes, "DDS ", 4) != 0) return;  // OpenImageIO refuses what is short
    const auto u32 = [&](std::size_t at) {
        return std::uint32_t(bytes[at]) | std::uint32_t(bytes[at + 1]) << 8 | std::uint32_t(bytes[at + 2]) << 16 |
               std::uint32_t(bytes[at + 3]) << 24;
    };
    const std::uint32_t flags = u32(8), height = u32(12), width = u32(16), depth = u32(24), caps2 = u32(112);
    const bool dx10 = std::memcmp(bytes + 84, "DX10", 4) == 0 && size >= 148;
    const std::uint32_t dimension = dx10 ? u32(132) : 0, misc = dx10 ? u32(136) : 0, layers = dx10 ? u32(140) : 1;
    constexpr std::uint32_t kDepthFlag = 0x800000, kVolume = 0x200000, kCube = 0x200, kTexture3d = 4, kCubeMisc = 4;
    if ((flags & kDepthFlag) || depth > 1 || (caps2 & kVolume) || dimension == kTexture3d)
        throw Error(ErrorCode::Unsupported, shown + ": a volume texture of " + std::to_string(width) + "x" + std::to_string(height) +
                                                "x" + std::to_string(depth) + " samples, not a picture");
    if ((caps2 & kCube) || (misc & kCubeMisc)) throw Error(ErrorCode::Unsupported, shown + ": a cube map, not a picture");
    if (layers > 1)
        throw Error(ErrorCode::Unsupported, shown + ": an array of " + std::to_string(layers) + " textures, not a picture");
    // Uncompressed samples (no FourCC) are unpacked by each channel's bit mask; OpenImageIO's reader
    // never finishes a file whose pixel format gives a channel it names no bits (a zero mask).
    constexpr std::uint32_t kAlphaPixels = 0x1, kAlphaOnly = 0x2, kFourCc = 0x4, kRgb = 0x40, kLuminance = 0x20000;
    const std::uint32_t format = u32(80);
    if (!(format & kFourCc)) {
        const struct {
            bool used;
            std::uint32_t mask;
            const char* channel;
        } masks[] = {{(format & (kRgb | kLuminance)) != 0, u32(92), (format & kRgb) ? "red" : "luminance"},
                     {(format & kRgb) != 0, u32(96), "green"},
                     {(format & kRgb) != 0, u32(100), "blue"},
                     {(format & (kAlphaPixels | kAlphaOnly)) != 0, u32(104), "alpha"}};
        for (const auto& m : masks)
            if (m.used && m.mask == 0)
                throw Error(ErrorCode::Corrupt, shown + ": a DDS whose pixel format gives its " + m.channel + " channel no bits");
        // Nor one whose pixels take no bits (a 151-byte file with an alpha mask and 0 bits a pixel),
        // or a mask past the pixel's bits: whole bytes, 8 to 32 bits a pixel, are what the format has.
        const std::uint32_t bits = u32(88);
        if (bits == 0 || bits > 32 || bits % 8 != 0)
            throw Error(ErrorCode::Corrupt, shown + ": a DDS whose pixel format says " + std::to_string(bits) +
                                                " bits a pixel (8, 16, 24 or 32 are what it may hold)");
        for (const auto& m : masks)
            if (m.used && bits < 32 && (m.mask >> bits) != 0)
                throw Error(ErrorCode::Corrupt, shown + ": a DDS whose " + m.channel + " mask reaches past its " +
                                                    std::to_string(bits) + " bits a pixel");
        // Alpha beside colour that is not there (the alpha-pixels flag without RGB or luminance),
        // or no channel at all: OpenImageIO's reader never finished such a file (the image
        // harness's 161-byte DDS).
        if ((format & kAlphaPixels) && !(format & (kRgb | kLuminance)))
            throw Error(ErrorCode::Corrupt, shown + ": a DDS whose pixel format has alpha beside no colour (neither RGB nor luminance)");
        if (!(format & (kRgb | kLuminance | kAlphaOnly)))
            throw Error(ErrorCode::Corrupt, shown + ": a DDS whose pixel format names no channels (neither RGB, luminance nor alpha)");
    }
}

bool isJpeg(const unsigned char* bytes, std::size_t size) {
    return size >= 3 && std::memcmp(bytes, "\xFF\xD8\xFF", 3) == 0;
}

// OpenEXR files are screened before OpenImageIO opens them (format/exr_check.h): it reads them with
// OpenEXR's C++ library, which allocates what a header declares (a 1.9 GB attribute in a 4 KB file
// cost 8 s and 2 GB; a 32768x32768 window in 5 KB, 73 s and 12.7 GB). Standard input is screened
// from an anonymous copy (memfd_create: no name in any folder, so nothing to plant a link at and
// nothing left behind), read through /proc/self/fd, since the screen reads a file. Returns the
// file's size in bytes.
std::uintmax_t screenInput(const std::string& path, const StdinImage& stdinImage, const Limits& limits) {
    if (path == "-") {
        const std::span<const unsigned char> bytes = stdinImage.bytes.view();
        if (isOpenExr(bytes.data(), bytes.size())) {
            const int fd = ::memfd_create("conus-stdin", MFD_CLOEXEC);
            if (fd < 0) throw Error(ErrorCode::Io, "cannot screen standard input: " + std::string(std::strerror(errno)) + "; give a file instead");
            struct Close {
                int fd;
                ~Close() { ::close(fd); }
            } closer{fd};
            std::size_t done = 0;
            while (done < bytes.size()) {
                const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
                if (n < 0 && errno == EINTR) continue;
                if (n <= 0) throw Error(ErrorCode::Io, "cannot screen standard input: " + std::string(std::strerror(n < 0 ? errno : ENOSPC)));
                done += static_cast<std::size_t>(n);
            }
            const std::string copy = "/proc/self/fd/" + std::to_string(fd);
            try {
                format::checkExrFile(copy, limits);
            } catch (const Error& e) {
                const std::string what = e.what();
                throw Error(e.code(), "standard input" + what.substr(what.rfind(copy, 0) == 0 ? copy.size() : 0));
            }
        }
        checkDdsHeader(bytes.data(), bytes.size(), "standard input");
        if (isJpeg(bytes.data(), bytes.size())) {
            std::size_t at = 0;
            checkJpegScans([&] { return at < bytes.size() ? int(bytes[at++]) : -1; }, "standard input");
        }
        return bytes.size();
    }
    unsigned char magic[148] = {};  // a DDS header's length
    std::FILE* f = std::fopen(path.c_str(), "rb");
    const std::size_t n = f ? std::fread(magic, 1, sizeof magic, f) : 0;
    if (f) std::fclose(f);
    if (isOpenExr(magic, n)) format::checkExrFile(path, limits);
    checkDdsHeader(magic, n, path);
    if (isJpeg(magic, n)) checkJpegScans(path, path);
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

// Only a flat picture is read: one slice of one image, in scanlines or flat tiles. A volume
// texture (a DDS with depth, a 3-D TIFF), a cube map or a deep image is refused: OpenImageIO
// writes every slice (or face) of it into the buffer it is given, and the buffer holds one.
void checkPlainPicture(const OIIO::ImageSpec& spec, const std::string& shown) {
    const std::string layout = spec.get_string_attribute("textureformat");
    const auto has = [&](const char* word) { return layout.find(word) != std::string::npos; };
    if (spec.depth != 1 || spec.full_depth > 1 || spec.tile_depth > 1 || spec.z != 0 || has("Volume"))
        throw Error(ErrorCode::Unsupported, shown + ": a volume texture of " + std::to_string(spec.width) + "x" +
                                                std::to_string(spec.height) + "x" + std::to_string(spec.depth) +
                                                " samples, not a picture");
    if (has("CubeFace"))
        throw Error(ErrorCode::Unsupported, shown + ": a cube map (" + layout + "), not a picture");
    if (spec.deep) throw Error(ErrorCode::Unsupported, shown + ": a deep image (several samples a pixel), not a picture");
    if (spec.tile_width < 0 || spec.tile_height < 0)
        throw Error(ErrorCode::Corrupt, shown + ": declares tiles of " + std::to_string(spec.tile_width) + "x" +
                                            std::to_string(spec.tile_height) + " pixels");
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
    checkPlainPicture(spec, shown);
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
    // What OpenImageIO writes (every pixel of every slice, all channels, as float) is exactly
    // what was allocated: checked once more against the buffer itself before it writes.
    if (std::uint64_t(spec.image_pixels()) * std::uint64_t(spec.nchannels) != image.pixels.size() ||
        image.pixels.size() != std::uint64_t(pixels) * std::uint64_t(spec.nchannels))
        throw Error(ErrorCode::Corrupt, shown + ": OpenImageIO's description of the image does not match its " +
                                            std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels");
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

}  // namespace conus::imageio::oiio
