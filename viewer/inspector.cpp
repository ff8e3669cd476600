#include "inspector.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "depth_view.h"

namespace conus::viewer {

Probe probe(const format::ConusFile& file, const codec::SamplingMap& map, glm::dvec2 uv) {
    Probe p;
    p.uv = uv;
    p.inside = uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1;
    const glm::dvec2 clamped = glm::clamp(uv, glm::dvec2(0.0), glm::dvec2(1.0));
    p.distorted = map.distort(clamped);
    p.density = map.density(clamped);
    const Image& image = file.image;
    const int sw = file.sourceWidth > 0 ? file.sourceWidth : image.width;
    const int sh = file.sourceHeight > 0 ? file.sourceHeight : image.height;
    p.sourcePixel = {std::min(sw - 1, int(clamped.x * sw)), std::min(sh - 1, int(clamped.y * sh))};
    p.conusPixel = {std::min(image.width - 1, int(p.distorted.x * image.width)),
                    std::min(image.height - 1, int(p.distorted.y * image.height))};
    p.channels = image.channels;
    // Bilinear between pixel centres ((x+0.5)/W), clamped to the edge, as the decoders sample.
    const double fx = std::clamp(p.distorted.x * image.width - 0.5, 0.0, double(image.width - 1));
    const double fy = std::clamp(p.distorted.y * image.height - 0.5, 0.0, double(image.height - 1));
    const int x0 = int(fx), y0 = int(fy);
    const int x1 = std::min(x0 + 1, image.width - 1), y1 = std::min(y0 + 1, image.height - 1);
    const double tx = fx - x0, ty = fy - y0;
    for (int c = 0; c < image.channelCount(); ++c) {
        const double top = image.at(x0, y0, c) * (1 - tx) + image.at(x1, y0, c) * tx;
        const double bottom = image.at(x0, y1, c) * (1 - tx) + image.at(x1, y1, c) * tx;
        p.values.push_back(static_cast<float>(top * (1 - ty) + bottom * ty));
    }
    p.depthImage = file.camera.has_value() && file.depth.kind == format::DepthKind::CameraDepth && hasDepth(file);
    if (p.depthImage) p.world = worldPoint(file, map, p.conusPixel);
    return p;
}

std::string formatProbe(const Probe& p) {
    char buffer[256];
    std::snprintf(buffer, sizeof buffer, "px (%d,%d) u,v=(%.4f,%.4f) ud,vd=(%.4f,%.4f) conus px (%d,%d) density %.3g (linear %.3g)%s",
                  p.sourcePixel.x, p.sourcePixel.y, p.uv.x, p.uv.y, p.distorted.x, p.distorted.y, p.conusPixel.x,
                  p.conusPixel.y, p.density, std::sqrt(std::max(p.density, 0.0)), p.inside ? "" : " (outside)");
    std::string text = buffer;
    // Channels in the order people read them (R,G,B,A), not OpenEXR's sorted one.
    for (const std::string& name : displayOrder(p.channels)) {
        const auto c = static_cast<std::size_t>(std::find(p.channels.begin(), p.channels.end(), name) - p.channels.begin());
        if (c >= p.values.size()) continue;
        std::snprintf(buffer, sizeof buffer, " %s=%.4g", name.c_str(), p.values[c]);
        text += buffer;
    }
    if (p.world) {
        std::snprintf(buffer, sizeof buffer, " P=(%.5g,%.5g,%.5g)", p.world->x, p.world->y, p.world->z);
        text += buffer;
    } else if (p.depthImage) {
        text += " P=background";
    }
    return text;
}

}  // namespace conus::viewer
