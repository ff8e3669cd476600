// Plain PNG files through libpng, without OpenImageIO (png_direct_pvt.h says which files and why).
// What the file's chunks become follows OpenImageIO 2.4's PNG reader, as image_read.cpp then
// keeps it (tests/imageio/png_direct_test.cpp compares the two paths on the same files).
#include "png_direct_pvt.h"

#include <png.h>

#include <array>
#include <cctype>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string_view>
#include <vector>

namespace conus::imageio {

float srgbToLinear(double encoded) {
    const double linear = encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
    return static_cast<float>(linear);
}

namespace {

bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
    return true;
}

// libpng reports errors by calling back; the callback jumps back to the setjmp of the function
// that called libpng (a C library: no exception may cross it). Only plain data lives in those
// functions' frames.
struct Png {
    std::jmp_buf jump;
    png_structp png = nullptr;
    png_infop info = nullptr;
    ~Png() {
        if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
    }
};

[[noreturn]] void onError(png_structp png, png_const_charp) {
    std::longjmp(static_cast<Png*>(png_get_error_ptr(png))->jump, 1);
}
void onWarning(png_structp, png_const_charp) {}

// Reads the signature and the chunks before the image data. False: not a PNG, or damaged.
bool readHeader(std::FILE* f, Png& p) {
    unsigned char signature[8];
    if (std::fread(signature, 1, 8, f) != 8 || png_sig_cmp(signature, 0, 8) != 0) return false;
    p.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &p, onError, onWarning);
    if (!p.png) return false;
    p.info = png_create_info_struct(p.png);
    if (!p.info) return false;
    if (setjmp(p.jump)) return false;
    png_init_io(p.png, f);
    png_set_sig_bytes(p.png, 8);
    png_read_info(p.png, p.info);
    return true;
}

// Decodes the rows into `out` through one table for every sample; false when libpng found the
// data damaged.
bool readRows(Png& p, std::uint32_t width, std::uint32_t height, int channels, int depth, const float* table,
              unsigned char* row, float* out) {
    if (setjmp(p.jump)) return false;
    if (depth == 16) png_set_swap(p.png);  // big-endian samples to this machine's order
    png_read_update_info(p.png, p.info);
    const std::size_t rowSamples = std::size_t{width} * channels;
    for (std::uint32_t y = 0; y < height; ++y) {
        png_read_row(p.png, row, nullptr);
        float* o = out + y * rowSamples;
        if (depth == 8) {
            for (std::size_t i = 0; i < rowSamples; ++i) o[i] = table[row[i]];
        } else {
            const auto* s = reinterpret_cast<const std::uint16_t*>(row);
            for (std::size_t i = 0; i < rowSamples; ++i) o[i] = table[s[i]];
        }
    }
    png_read_end(p.png, nullptr);  // the trailing chunks' CRCs, as a complete read checks them
    return true;
}

// Decodes 8-bit rows into `out` as they are stored; false when libpng found the data damaged.
bool readCodes(Png& p, std::uint32_t width, std::uint32_t height, int channels, unsigned char* out) {
    if (setjmp(p.jump)) return false;
    png_read_update_info(p.png, p.info);
    for (std::uint32_t y = 0; y < height; ++y) png_read_row(p.png, out + std::size_t{y} * width * channels, nullptr);
    png_read_end(p.png, nullptr);
    return true;
}

// Metadata by name, in the order the attributes were first set, a later value replacing an
// earlier one in place (as OpenImageIO's ImageSpec::attribute does).
void setText(std::vector<MetadataItem>& items, const std::string& name, const std::string& value) {
    for (MetadataItem& item : items)
        if (item.name == name) {
            item.value = value;
            return;
        }
    items.push_back({name, value});
}

bool isLinearName(std::string_view cs) {
    return iequals(cs, "linear") || iequals(cs, "scene_linear") || iequals(cs, "lin_srgb") || iequals(cs, "Gamma1.0");
}

// What the chunks before the image data say: the transfer the file declares, its ICC profile,
// the metadata CoNUS carries. False when a chunk means something this reader does not reproduce
// (alpha, a palette, EXIF or XMP blocks, ...): the OpenImageIO path reads such files.
bool describe(const Png& p, Transfer& declared, SourceEncoding& encoding) {
    png_uint_32 width = 0, height = 0;
    int depth = 0, colourType = 0, interlace = 0;
    png_get_IHDR(p.png, p.info, &width, &height, &depth, &colourType, &interlace, nullptr, nullptr);
    if ((colourType != PNG_COLOR_TYPE_GRAY && colourType != PNG_COLOR_TYPE_RGB) || (depth != 8 && depth != 16) ||
        interlace != PNG_INTERLACE_NONE || png_get_valid(p.png, p.info, PNG_INFO_tRNS | PNG_INFO_eXIf | PNG_INFO_sBIT))
        return false;

    std::vector<MetadataItem> attributes;  // every attribute OpenImageIO would set, carried or not
    std::string colourSpace;
    int intent = 0;
    double gamma = 0;
    if (png_get_sRGB(p.png, p.info, &intent)) {
        colourSpace = "sRGB";
    } else if (png_get_gAMA(p.png, p.info, &gamma) && gamma > 0) {
        const float g = std::round(100.0f * static_cast<float>(1.0 / gamma)) / 100.0f;  // 2.2, not 2.19998
        colourSpace = g == 1.0f ? "linear" : "gamma";
    }
    png_charp profileName = nullptr;
    png_bytep profile = nullptr;
    png_uint_32 profileLength = 0;
    int compression = 0;
    if (png_get_iCCP(p.png, p.info, &profileName, &compression, &profile, &profileLength) && profile && profileLength)
        encoding.iccProfile.assign(reinterpret_cast<const char*>(profile), profileLength);
    if (!iccProfileProblem(encoding.iccProfile).empty()) encoding.iccProfile.clear();  // garbage is not carried
    png_timep time = nullptr;
    if (png_get_tIME(p.png, p.info, &time) && time) {
        char date[64];
        std::snprintf(date, sizeof date, "%4d:%02d:%02d %02d:%02d:%02d", time->year, time->month, time->day, time->hour,
                      time->minute, time->second);
        setText(attributes, "DateTime", date);
    }
    png_textp text = nullptr;
    const int texts = png_get_text(p.png, p.info, &text, nullptr);
    for (int i = 0; i < texts; ++i) {
        const std::string key = text[i].key ? text[i].key : "";
        const std::string value = text[i].text ? text[i].text : "";
        // Blocks OpenImageIO decodes into many attributes, and a textual orientation: its path.
        if (key.rfind("XML:", 0) == 0 || iequals(key.substr(0, 11), "Raw profile") || iequals(key, "Orientation") ||
            iequals(key, "ICCProfile"))
            return false;
        const std::string name = iequals(key, "Description") ? "ImageDescription"
                                 : iequals(key, "Author")    ? "Artist"
                                 : iequals(key, "Title")     ? "DocumentName"
                                                             : key;
        if (name == "oiio:ColorSpace") colourSpace = value;
        setText(attributes, name, value);
    }
    for (const MetadataItem& item : attributes)
        if (isCarriedMetadata(item.name)) encoding.metadata.push_back(item);
    declared = isLinearName(colourSpace) ? Transfer::Linear : Transfer::Srgb;
    return true;
}

}  // namespace

std::optional<ImageFile> readPngDirect(const std::string& path, const ReadOptions& options) {
    if (path == "-" || !(options.part.empty() || options.part == "0")) return std::nullopt;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
    const std::uintmax_t fileSize = std::filesystem::file_size(path, ec);
    if (ec) return std::nullopt;
    struct Close {
        void operator()(std::FILE* f) const { std::fclose(f); }
    };
    const std::unique_ptr<std::FILE, Close> f(std::fopen(path.c_str(), "rb"));
    if (!f) return std::nullopt;
    Png p;
    if (!readHeader(f.get(), p)) return std::nullopt;
    ImageFile result;
    ImageFileInfo& info = result.info;
    SourceEncoding& encoding = info.encoding;
    Transfer declared = Transfer::Srgb;
    if (!describe(p, declared, encoding)) return std::nullopt;
    const std::uint32_t width = png_get_image_width(p.png, p.info), height = png_get_image_height(p.png, p.info);
    const int depth = png_get_bit_depth(p.png, p.info), channels = png_get_channels(p.png, p.info);

    // The OpenImageIO path's limits (image_read.cpp); past any of them it words the refusal.
    const std::int64_t pixels = std::int64_t{width} * height;
    const Limits& limits = options.limits;
    constexpr std::uintmax_t kMaxExpansion = 4096;
    const std::uintmax_t sampleBytes = std::uintmax_t(pixels) * channels * (depth / 8);
    if (width < 1 || height < 1 || width > std::uint32_t(kMaxImageSide) || height > std::uint32_t(kMaxImageSide) ||
        pixels > limits.maxPixels || channels > limits.maxChannels ||
        pixels * channels * std::int64_t(sizeof(float)) > limits.maxDecodeBytes || sampleBytes / kMaxExpansion > fileSize)
        return std::nullopt;

    info.format = "png";
    encoding.sampleType = depth == 8 ? SampleType::Uint8 : SampleType::Uint16;
    encoding.transfer = options.colorspace.value_or(declared);
    if (encoding.transfer != Transfer::Raw && (encoding.iccProfile.empty() || encoding.iccProfile.find("sRGB") != std::string::npos))
        encoding.chromaticities = kRec709Chromaticities;  // untagged, or a profile that names itself sRGB

    // Every sample value's float (v / max, as OpenImageIO converts it), linearized for sRGB.
    const int values = depth == 8 ? 256 : 65536;
    const float scale = 1.0f / static_cast<float>(values - 1);
    std::vector<float> table(values);
    for (int v = 0; v < values; ++v) table[v] = static_cast<float>(v) * scale;
    if (encoding.transfer == Transfer::Srgb)
        for (float& t : table) t = srgbToLinear(t);

    Image& image = result.image;
    if (options.keepCodes && depth == 8 && encoding.transfer == Transfer::Srgb) {
        image.width = static_cast<int>(width);
        image.height = static_cast<int>(height);
        image.channels = channels == 1 ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"};
        result.codes.resize(std::size_t{width} * height * channels);
        if (!readCodes(p, width, height, channels, result.codes.data())) return std::nullopt;
        return result;
    }
    image = makeImage(static_cast<int>(width), static_cast<int>(height),
                      channels == 1 ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"});
    std::vector<unsigned char> row(std::size_t{width} * channels * (depth / 8));
    if (!readRows(p, width, height, channels, depth, table.data(), row.data(), image.pixels.data())) return std::nullopt;
    return result;
}

}  // namespace conus::imageio
