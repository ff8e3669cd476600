#include "image_io.h"

#include <algorithm>

#include <OpenImageIO/imageio.h>

#include "conus/format/error.h"

namespace conus::viewer {

format::Image readImage(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(ErrorCode::Io, "cannot read image " + path + ": " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.width > format::kMaxImageSide ||
        spec.height > format::kMaxImageSide ||
        std::int64_t(spec.width) * spec.height > format::kMaxImagePixels)
        throw Error(ErrorCode::LimitExceeded, path + ": image size " + std::to_string(spec.width) + "x" +
                                                  std::to_string(spec.height) + " is outside the supported range");
    std::vector<std::string> names;
    for (int c = 0; c < spec.nchannels; ++c) names.push_back(spec.channel_name(c));
    format::Image image = format::makeImage(spec.width, spec.height, names);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
        throw Error(ErrorCode::Io, "cannot read image " + path + ": " + in->geterror());
    return image;
}

void writeImage(const std::string& path, const format::Image& image) {
    const int channels = image.channelCount() >= 3 ? 3 : 1;
    std::vector<float> pixels(static_cast<std::size_t>(image.width) * image.height * channels);
    for (std::size_t i = 0; i < static_cast<std::size_t>(image.width) * image.height; ++i)
        for (int c = 0; c < channels; ++c) pixels[i * channels + c] = image.pixels[i * image.channels.size() + c];
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw Error(ErrorCode::Io, "cannot write " + path + ": " + OIIO::geterror());
    const std::string ext = path.substr(path.find_last_of('.') + 1);
    const bool eightBit = ext != "exr" && ext != "EXR" && ext != "tif" && ext != "tiff";
    OIIO::ImageSpec spec(image.width, image.height, channels, eightBit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    if (eightBit)
        for (float& v : pixels) v = std::clamp(v, 0.0f, 1.0f);
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !out->close())
        throw Error(ErrorCode::Io, "cannot write " + path + ": " + out->geterror());
}

}  // namespace conus::viewer
