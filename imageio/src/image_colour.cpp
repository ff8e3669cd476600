// Colour by channel role through OpenImageIO (image_colour_pvt.h), and the module's linearize and
// displayEncoded built from it.
#include "image_colour_pvt.h"

#include <algorithm>
#include <cmath>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "conus/core/error.h"
#include "oiio_module_pvt.h"

namespace conus::imageio::oiio {

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

void premultiply(float* pixels, int width, int height, int channels, int alpha, bool associate) {
    OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::FLOAT);
    spec.alpha_channel = alpha;
    OIIO::ImageBuf buffer(spec, pixels);
    if (associate) OIIO::ImageBufAlgo::premult(buffer, buffer);
    else OIIO::ImageBufAlgo::unpremult(buffer, buffer);
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

}  // namespace conus::imageio::oiio
