// Relief assets and the engraved tablet (relief.h).
#include "conus/codec/depth/relief.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "conus/codec/depth/heightfield.h"
#include "conus/core/error.h"
#include "conus/core/parallel.h"

namespace conus::codec {
namespace {

// A 3x3 box blur of channel 0: the engraving's walls slope over a pixel instead of standing
// vertical (a V-cut chisel, and no wall steeper than the samples can hold).
Image softened(const Image& ink) {
    Image out = makeImage(ink.width, ink.height, {"Y"});
    for (int y = 0; y < ink.height; ++y)
        for (int x = 0; x < ink.width; ++x) {
            float sum = 0.0f;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    sum += std::clamp(ink.at(std::clamp(x + dx, 0, ink.width - 1), std::clamp(y + dy, 0, ink.height - 1)),
                                      0.0f, 1.0f);
            out.at(x, y) = sum / 9.0f;
        }
    return out;
}

}  // namespace

Tablet makeTablet(const Image& ink, const TabletOptions& o) {
    checkImage(ink, "makeTablet");
    if (!(o.width > 0 && o.slab > 0 && o.border >= 0 && o.border < 0.5 && o.frame >= 0 && o.bevel >= 0 &&
          o.engraving >= 0 && o.engraving < o.slab && std::isfinite(o.width + o.slab + o.frame + o.bevel)))
        throw Error(ErrorCode::InvalidArgument, "makeTablet: want width and slab > 0, border in [0, 0.5), frame, "
                                                "bevel and engraving >= 0, engraving < slab");
    const int w = ink.width, h = ink.height;
    Tablet tablet;
    tablet.extent = {o.width, o.width * h / w};
    tablet.heights = makeImage(w, h, {"Z"});
    tablet.colour = makeImage(w, h, {"R", "G", "B"});
    const Image strokes = softened(ink);
    const double frameWidth = o.border * std::min(tablet.extent.x, tablet.extent.y);
    const glm::dvec3 stone(0.56, 0.52, 0.46), paint(0.10, 0.09, 0.11), frameStone(0.63, 0.59, 0.52);
    parallelRows(h, 0, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                const double cx = (x + 0.5) / w * tablet.extent.x, cz = (y + 0.5) / h * tablet.extent.y;
                const double edge = std::min({cx, tablet.extent.x - cx, cz, tablet.extent.y - cz});
                double height = o.slab - std::max(0.0, o.bevel - edge);  // the outer chamfer, 45 degrees
                const double onFrame = o.bevel > 0 ? std::clamp((frameWidth - edge) / o.bevel, 0.0, 1.0)
                                                   : (edge < frameWidth ? 1.0 : 0.0);
                height += o.frame * onFrame;
                const double cut = strokes.at(x, y) * (1.0 - onFrame);
                height -= o.engraving * cut;
                tablet.heights.at(x, y) = static_cast<float>(height);
                // Mottled stone: a few incommensurate waves, different per channel.
                const double mottle = 0.05 * std::sin(23.0 * cx + 7.0 * cz) * std::cos(17.0 * cz - 5.0 * cx) +
                                      0.03 * std::sin(61.0 * cx * cz + 3.0 * cx);
                const glm::dvec3 base = glm::mix(stone, frameStone, onFrame) * (1.0 + mottle);
                const glm::dvec3 colour = glm::mix(base, paint, 0.85 * cut);
                for (int c = 0; c < 3; ++c) tablet.colour.at(x, y, c) = static_cast<float>(colour[c]);
            }
    });
    return tablet;
}

Camera reliefCamera(glm::dvec2 extent, double top) {
    const glm::dvec3 eye(0.5 * extent.x, top, 0.5 * extent.y);
    const double reach = std::max(extent.x, extent.y);
    // Up is -z so that v (down the image) runs along +z; far reaches well below the base plane.
    return Camera::orthographic(eye, eye - glm::dvec3(0.0, 1.0, 0.0), {0.0, 0.0, -1.0}, extent.y, extent.x / extent.y,
                                0.0, std::abs(top) + 2.0 * reach);
}

format::ConusFile bakeRelief(const Image& heights, const Image& colour, const SamplingMap* map,
                             const ReliefBakeOptions& options) {
    if (!(options.extent.x > 0 && options.extent.y > 0 && std::isfinite(options.extent.x) &&
          std::isfinite(options.extent.y)))
        throw Error(ErrorCode::InvalidArgument, "bakeRelief: extent " + std::to_string(options.extent.x) + " x " +
                                                    std::to_string(options.extent.y) + " is not positive");
    format::ConusFile file =
        map ? encodeHeightField(heights, colour, *map, options.width, options.height, options.units, options.threads)
            : uniformHeightField(heights, colour, options.width, options.height, options.units, options.threads);
    // The eye above the highest point by the field's size, so every height lies inside near..far.
    const double top = file.depth.far + std::max(options.extent.x, options.extent.y);
    if (!std::isfinite(top) || file.depth.near < -1e6)
        throw Error(ErrorCode::InvalidArgument, "bakeRelief: heights out of range");
    file.camera = format::toAttributes(reliefCamera(options.extent, top));
    return file;
}

Camera defaultReliefView(const DepthImage& asset, double aspect) {
    const Camera& top = asset.camera();
    const glm::dvec3 a = top.unproject({0.0, 0.0}, asset.maxDepth()), b = top.unproject({1.0, 1.0}, asset.minDepth());
    const glm::dvec3 centre = 0.5 * (a + b);
    const double reach = glm::length(b - a);
    const glm::dvec3 eye = centre + glm::dvec3(0.25, 0.75, 0.9) * reach;
    return Camera::perspective(eye, centre, {0, 1, 0}, 40.0, aspect, 0.01 * reach, 10.0 * reach);
}

double maskedPsnr(const Image& frame, const Image& reference, const Image& mask, bool inside) {
    checkImage(frame, "maskedPsnr");
    checkImage(reference, "maskedPsnr");
    checkImage(mask, "maskedPsnr");
    if (frame.width != reference.width || frame.height != reference.height || frame.channels != reference.channels ||
        mask.width != frame.width || mask.height != frame.height)
        throw Error(ErrorCode::InvalidArgument, "maskedPsnr: the frame, the reference and the mask differ in size or channels");
    double sum = 0.0;
    std::size_t count = 0;
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            if ((mask.at(x, y) > 0.5f) != inside) continue;
            for (int c = 0; c < frame.channelCount(); ++c) {
                const double d = double(frame.at(x, y, c)) - reference.at(x, y, c);
                sum += d * d;
            }
            count += static_cast<std::size_t>(frame.channelCount());
        }
    if (count == 0) throw Error(ErrorCode::InvalidArgument, "maskedPsnr: no pixel in the region");
    const double mse = sum / double(count);
    return mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : 99.0;
}

}  // namespace conus::codec
