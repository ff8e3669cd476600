#include "image_io.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <memory>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "conus/format/error.h"

namespace conus::cli {
namespace fs = std::filesystem;
namespace OIIO = OIIO_NAMESPACE;

format::Image readImage(const std::string& path) {
    if (!fs::exists(path)) throw Error(ErrorCode::Io, path + ": no such file");
    auto input = OIIO::ImageInput::open(path);
    if (!input) throw Error(ErrorCode::Io, path + ": cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = input->spec();
    if (spec.width < 1 || spec.height < 1 || spec.width > format::kMaxImageSide ||
        spec.height > format::kMaxImageSide || spec.nchannels < 1 || spec.nchannels > 64 ||
        std::int64_t{spec.width} * spec.height > format::kMaxImagePixels)
        throw Error(ErrorCode::LimitExceeded, path + ": image size " + std::to_string(spec.width) + "x" +
                                                  std::to_string(spec.height) + "x" +
                                                  std::to_string(spec.nchannels) + " is beyond the limits");
    std::vector<std::string> names;
    for (int c = 0; c < spec.nchannels; ++c) {
        std::string n = c < static_cast<int>(spec.channelnames.size()) ? spec.channelnames[c] : "";
        names.push_back(n.empty() ? "C" + std::to_string(c) : n);
    }
    format::Image image = format::makeImage(spec.width, spec.height, names);
    if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
        throw Error(ErrorCode::Io, path + ": cannot read pixels: " + input->geterror());
    return image;
}

namespace {

bool holdsOnlyDisplayChannels(const std::string& extension) {
    return extension != ".exr" && extension != ".tif" && extension != ".tiff";
}

}  // namespace

void writeImage(const std::string& path, const format::Image& source) {
    if (source.empty()) throw Error(ErrorCode::InvalidArgument, "nothing to write to " + path);
    fs::path target(path);
    std::string extension = target.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);

    // Keep the channels the target format can show: colour and alpha for PNG/JPEG.
    std::vector<int> keep;
    for (int c = 0; c < source.channelCount(); ++c) {
        const std::string& n = source.channels[c];
        if (holdsOnlyDisplayChannels(extension) && n != "R" && n != "G" && n != "B" && n != "A" && n != "Y")
            continue;
        keep.push_back(c);
    }
    if (keep.empty()) keep.push_back(0);
    if (holdsOnlyDisplayChannels(extension) && keep.size() > 4) keep.resize(4);

    // libjpeg ends the process (exit()) on a larger image instead of returning an error.
    constexpr int kJpegMaxSide = 65500;
    if ((extension == ".jpg" || extension == ".jpeg") && (source.width > kJpegMaxSide || source.height > kJpegMaxSide))
        throw Error(ErrorCode::InvalidArgument, path + ": JPEG holds at most 65500 pixels a side, not " +
                                                    std::to_string(source.width) + "x" + std::to_string(source.height));

    OIIO::TypeDesc type = OIIO::TypeDesc::UINT8;
    if (extension == ".exr") type = OIIO::TypeDesc::HALF;
    else if (extension == ".tif" || extension == ".tiff") type = OIIO::TypeDesc::UINT16;
    OIIO::ImageSpec spec(source.width, source.height, static_cast<int>(keep.size()), type);
    spec.channelnames.clear();
    for (int c : keep) spec.channelnames.push_back(source.channels[c]);
    spec.alpha_channel = -1;
    for (std::size_t i = 0; i < keep.size(); ++i)
        if (source.channels[keep[i]] == "A") spec.alpha_channel = static_cast<int>(i);

    std::vector<float> pixels(static_cast<std::size_t>(source.width) * source.height * keep.size());
    const std::size_t count = static_cast<std::size_t>(source.width) * source.height;
    for (std::size_t p = 0; p < count; ++p)
        for (std::size_t i = 0; i < keep.size(); ++i)
            pixels[p * keep.size() + i] = source.pixels[p * source.channels.size() + keep[i]];

    // Same folder (rename stays atomic), same extension (OpenImageIO picks the format from it).
    fs::path temp = target.parent_path() /
                    ("." + target.stem().string() + ".tmp-" + std::to_string(::getpid()) + target.extension().string());
    {
        auto output = OIIO::ImageOutput::create(path);
        if (!output) throw Error(ErrorCode::Io, path + ": no image writer for this extension");
        if (!output->open(temp.string(), spec)) {
            std::string reason = output->geterror();
            std::error_code ignored;
            fs::remove(temp, ignored);
            throw Error(ErrorCode::Io, path + ": cannot write: " + reason);
        }
        bool ok = output->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
        ok = output->close() && ok;
        if (!ok) {
            std::string reason = output->geterror();
            std::error_code ignored;
            fs::remove(temp, ignored);
            throw Error(ErrorCode::Io, path + ": cannot write: " + reason);
        }
    }
    std::error_code ec;
    fs::rename(temp, target, ec);
    if (ec) {
        fs::remove(temp, ec);
        throw Error(ErrorCode::Io, path + ": cannot rename the finished file into place");
    }
}

void drawText(format::Image& image, int x, int y, int size, const std::string& text, const float color[3]) {
    OIIO::ImageSpec spec(image.width, image.height, image.channelCount(), OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf buffer(spec, image.pixels.data());  // wraps our pixels: drawn in place
    const float rgba[4] = {color[0], color[1], color[2], 1.0f};
    OIIO::ImageBufAlgo::render_text(buffer, x, y, text, size, "DejaVuSans",
                                    OIIO::cspan<float>(rgba, std::min(4, image.channelCount())));
}

}  // namespace conus::cli
