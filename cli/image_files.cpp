#include "image_files.h"

#include <algorithm>
#include <cstddef>

#include <CLI/CLI.hpp>

#include "arguments.h"
#include "conus/codec/builders/importance.h"
#include "conus/core/atomic_file.h"
#include "progress.h"

namespace conus::cli {

void addSourceOptions(CLI::App& command, SourceOptions& options) {
    std::vector<std::string> colorspaces{kFromTheFile};
    for (const std::string& name : enumNames<Transfer>()) colorspaces.push_back(name);
    command.add_option("--input-colorspace", options.colorspace,
                       "what the input's values are; " + std::string(kFromTheFile) + ": 8/16-bit files " +
                           enumName(Transfer::Srgb) + ", float files " + enumName(Transfer::Linear) + "; " +
                           enumName(Transfer::Raw) + ": data, never converted")
        ->capture_default_str()
        ->check(CLI::IsMember(colorspaces));
    command.add_flag("--no-auto-orient", options.noAutoOrient,
                     "keep the stored frame instead of applying the EXIF orientation");
    command.add_option("--fix-nonfinite", options.fixNonFinite,
                       "NaN/Inf in the input: kept with a warning, made 0, or the mean of their finite neighbours")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames<imageio::NonFiniteRepair>()));
    command.add_option("--part", options.part, "the part of a multi-part input to read, by name or index (default: the first)");
}

imageio::ImageFile readSource(const std::string& path, const SourceOptions& options, bool keepCodes) {
    imageio::ReadOptions read;
    read.keepCodes = keepCodes;
    if (options.colorspace != kFromTheFile) read.colorspace = parseEnum<Transfer>(options.colorspace);
    read.autoOrient = !options.noAutoOrient;
    read.part = options.part;
    read.repair = parseEnum<imageio::NonFiniteRepair>(options.fixNonFinite);
    Progress progress("read " + path);
    imageio::ImageFile file = imageio::readImageFile(path, read);
    progress.done();
    const imageio::ImageFileInfo& info = file.info;
    if (info.parts > 1)
        warn(path + " has " + std::to_string(info.parts) + " parts; using part " + std::to_string(info.part) +
             (info.partName.empty() ? "" : " (" + info.partName + ")") + " (choose with --part NAME|N)");
    if (info.nonFinite > 0)
        warn(path + " holds " + plural(static_cast<std::size_t>(info.nonFinite), "NaN or infinite value", "NaN or infinite values") +
             (read.repair == imageio::NonFiniteRepair::Keep
                  ? "; filtering spreads them to their neighbours (repair with --fix-nonfinite " +
                        std::string(enumName(imageio::NonFiniteRepair::Box3)) + "|" + enumName(imageio::NonFiniteRepair::Black) + ")"
                  : "; repaired (--fix-nonfinite " + options.fixNonFinite + ")"));
    return file;
}

Image readData(const std::string& path) {
    imageio::ReadOptions read;
    read.colorspace = Transfer::Raw;
    return imageio::readImageFile(path, read).image;
}

namespace {

// The luminance of the picture as a display shows it (detailImportance's: the mean of R, G and B,
// else the grey channel Y, else the first), a band of rows display-encoded at a time: the same
// values as of displayEncoded(picture), without that copy of the picture (its size again, in
// fresh pages).
Image shownLuminance(const Image& picture) {
    constexpr int kBandRows = 128;
    const int r = picture.channelIndex("R"), g = picture.channelIndex("G"), b = picture.channelIndex("B");
    const int single = std::max(0, picture.channelIndex("Y"));
    const bool colour = r >= 0 && g >= 0 && b >= 0;
    const std::size_t channels = picture.channels.size(), row = std::size_t(picture.width) * channels;
    Image out = makeImage(picture.width, picture.height, {"Y"});
    Image band{picture.width, 0, picture.channels, {}};
    for (int y0 = 0; y0 < picture.height; y0 += kBandRows) {
        const int rows = std::min(kBandRows, picture.height - y0);
        band.height = rows;
        band.pixels.assign(picture.pixels.begin() + std::ptrdiff_t(y0 * row), picture.pixels.begin() + std::ptrdiff_t((y0 + rows) * row));
        const Image shown = imageio::displayEncoded(band);
        float* to = out.pixels.data() + std::size_t(y0) * picture.width;
        for (std::size_t p = 0; p < std::size_t(rows) * picture.width; ++p) {
            const float* px = &shown.pixels[p * channels];
            to[p] = colour ? (px[r] + px[g] + px[b]) / 3.0f : px[single];
        }
    }
    return out;
}

}  // namespace

Image importanceFrom(const std::string& source, const Image& picture) {
    const std::optional<codec::ImportanceRule> rule = tryParseEnum<codec::ImportanceRule>(source);
    if (!rule) return readData(source);
    if (picture.empty()) throw Error(ErrorCode::InvalidArgument, "'" + source + "' importance needs an input image");
    if (*rule == codec::ImportanceRule::Detail) return codec::detailImportanceOfLuminance(shownLuminance(picture));
    return codec::ruleImportance(*rule, imageio::displayEncoded(picture));
}

void addPictureOptions(CLI::App& command, PictureOptions& options) {
    std::string bits;
    for (const std::string& name : pictureBitsNames()) bits += (bits.empty() ? "" : ", ") + name;
    command.add_option("--bits", options.bits,
                       "sample type of the picture: one of " + bits + " (default: the source's where the format holds it)")
        ->check(CLI::IsMember(pictureBitsNames()));
    command.add_option("--exposure", options.exposure, "exposure in stops (multiplies colour by 2^EV)")
        ->check(finiteRange(-64.0, 64.0, true));
    command.add_option("--tonemap", options.toneMap,
                       "for 8/16-bit pictures of HDR data (" + std::string(enumName(ToneMap::None)) + ": values above 1 clip)")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames<ToneMap>()));
}

imageio::WriteOptions writeOptionsOf(const PictureOptions& options, const SourceEncoding* source) {
    imageio::WriteOptions write;
    write.source = source;
    write.display.exposure = options.exposure;
    write.display.toneMap = parseEnum<ToneMap>(options.toneMap);
    if (!options.bits.empty()) write.sampleType = parsePictureBits(options.bits);
    return write;
}

void checkPictureOutput(const std::string& path, const imageio::WriteOptions& options,
                        std::initializer_list<std::string> inputs) {
    const std::vector<std::string> list(inputs);
    checkOutputPath(path, list);
    imageio::checkImageOutput(path, options);
    if (options.display.toneMap != ToneMap::None && options.sampleType &&
        (*options.sampleType == SampleType::Half || *options.sampleType == SampleType::Float))
        throw Error(ErrorCode::InvalidArgument,
                    "--tonemap is for 8/16-bit pictures; a " + std::string(enumName(*options.sampleType)) +
                        " picture keeps the linear values (use --exposure alone)");
}

void writePicture(const std::string& path, const Image& image, const imageio::WriteOptions& options) {
    const std::int64_t nonFinite = imageio::countNonFinite(image);
    if (nonFinite > 0)
        warn(path + ": the picture holds " + plural(static_cast<std::size_t>(nonFinite), "NaN or infinite value", "NaN or infinite values") +
             " (from the input; repair them with --fix-nonfinite when encoding)");
    Progress progress("write " + path);
    imageio::writeImageFile(path, image, options);
    progress.done();
}

void writeDrawing(const std::string& path, const Image& image) {
    imageio::WriteOptions options;
    options.meaning = imageio::PixelMeaning::Display;
    imageio::writeImageFile(path, image, options);
}

}  // namespace conus::cli
