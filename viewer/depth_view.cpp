#include "depth_view.h"

#include <algorithm>
#include <cmath>

#include "conus/core/display.h"
#include "conus/core/error.h"

namespace conus::viewer {
namespace {

// The inverse of linearToSrgbDisplay: the ramp's display values as linear light.
float displayToLinear(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

glm::vec3 ramp(double t) {
    constexpr std::size_t n = kInfernoRamp.size();
    t = std::clamp(t, 0.0, 1.0) * double(n - 1);
    const std::size_t i = std::min(static_cast<std::size_t>(t), n - 2);
    const float f = static_cast<float>(t - double(i));
    glm::vec3 c;
    for (int k = 0; k < 3; ++k) c[k] = displayToLinear(kInfernoRamp[i][k] * (1 - f) + kInfernoRamp[i + 1][k] * f);
    return c;
}

}  // namespace

bool hasDepth(const format::ConusFile& file) { return file.image.channelIndex("Z") >= 0; }

bool validDepth(const format::ConusFile& file, int x, int y) {
    const Image& im = file.image;
    const int z = im.channelIndex("Z"), a = im.channelIndex("A");
    if (z < 0 || x < 0 || y < 0 || x >= im.width || y >= im.height) return false;
    const float depth = im.at(x, y, z);
    if (!std::isfinite(depth)) return false;
    if (a >= 0 && !(im.at(x, y, a) > 0.0f)) return false;
    const format::DepthInfo& d = file.depth;
    if (d.far > d.near && (depth < d.near || depth >= d.far)) return false;  // a miss is written as far
    return true;
}

DepthSpan depthSpan(const format::ConusFile& file) {
    DepthSpan span{HUGE_VAL, -HUGE_VAL};
    const int z = file.image.channelIndex("Z");
    for (int y = 0; y < file.image.height; ++y)
        for (int x = 0; x < file.image.width; ++x)
            if (validDepth(file, x, y)) {
                span.nearest = std::min(span.nearest, double(file.image.at(x, y, z)));
                span.farthest = std::max(span.farthest, double(file.image.at(x, y, z)));
            }
    return span;
}

format::ConusFile depthPicture(const format::ConusFile& file) {
    const int z = file.image.channelIndex("Z");
    if (z < 0) throw Error(ErrorCode::InvalidArgument, "the file has no Z channel");
    const DepthSpan span = depthSpan(file);
    const double extent = span.empty() ? 0.0 : span.farthest - span.nearest;
    format::ConusFile picture;
    picture.image = makeImage(file.image.width, file.image.height, {"R", "G", "B"});
    for (int y = 0; y < file.image.height; ++y)
        for (int x = 0; x < file.image.width; ++x) {
            glm::vec3 c(kDepthBackground[0], kDepthBackground[1], kDepthBackground[2]);
            if (validDepth(file, x, y)) {
                const double t = extent > 0 ? (file.image.at(x, y, z) - span.nearest) / extent : 0.0;
                c = ramp(1.0 - t);  // near bright, far dark
            }
            for (int k = 0; k < 3; ++k) picture.image.at(x, y, k) = c[k];
        }
    picture.pixelType = format::PixelType::Float;
    picture.sourceWidth = file.sourceWidth;
    picture.sourceHeight = file.sourceHeight;
    picture.dataKind = format::DataKind::Image;
    picture.map = file.map;
    picture.analytic = file.analytic;
    return picture;
}

std::optional<glm::dvec3> worldPoint(const format::ConusFile& file, const codec::SamplingMap& map, glm::ivec2 conusPixel) {
    if (!file.camera || file.depth.kind != format::DepthKind::CameraDepth) return std::nullopt;
    if (!validDepth(file, conusPixel.x, conusPixel.y)) return std::nullopt;
    const Camera camera = format::toCamera(*file.camera);
    const glm::dvec2 centre((conusPixel.x + 0.5) / file.image.width, (conusPixel.y + 0.5) / file.image.height);
    const glm::dvec2 uv = map.undistort(centre);  // the exact inverse of Equation 1
    // The camera's ray through uv, at the pixel's camera depth.
    return camera.unproject(uv, file.image.at(conusPixel.x, conusPixel.y, file.image.channelIndex("Z")));
}

}  // namespace conus::viewer
