#include "conus/codec/map/pictures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "conus/codec/builders/map_measures.h"
#include "conus/core/display.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

// The density ramp (core/display.h), interpolated.
glm::vec3 heat(double t) {
    constexpr std::size_t n = kInfernoRamp.size();
    t = std::clamp(t, 0.0, 1.0) * (n - 1);
    const std::size_t i = std::min(static_cast<std::size_t>(t), n - 2);
    const float f = static_cast<float>(t - static_cast<double>(i));
    const glm::vec3 a(kInfernoRamp[i][0], kInfernoRamp[i][1], kInfernoRamp[i][2]);
    const glm::vec3 b(kInfernoRamp[i + 1][0], kInfernoRamp[i + 1][1], kInfernoRamp[i + 1][2]);
    return a * (1 - f) + b * f;
}

void blend(Image& image, int x, int y, glm::vec3 color, float alpha) {
    if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
    for (int c = 0; c < 3; ++c) image.at(x, y, c) = image.at(x, y, c) * (1 - alpha) + color[c] * alpha;
}

}  // namespace

DensityStats densityStats(const SamplingMap& map, int samples) {
    DensityStats stats{1e300, 0, 0};
    for (int j = 0; j < samples; ++j)
        for (int i = 0; i < samples; ++i) {
            const double d = map.density({(i + 0.5) / samples, (j + 0.5) / samples});
            stats.min = std::min(stats.min, d);
            stats.max = std::max(stats.max, d);
            stats.mean += d;
        }
    stats.mean /= double(samples) * samples;
    return stats;
}

Image densityPicture(const SamplingMap& map, int width, int height, int lines, const format::AnalyticMap* analytic, double aspect) {
    Image picture = makeImage(width, height, {"R", "G", "B"});
    std::vector<glm::dvec2> distorted(static_cast<std::size_t>(width) * height);
    std::vector<double> logDensity(distorted.size());
    double lo = 1e300, hi = -1e300;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const glm::dvec2 p{(x + 0.5) / width, (y + 0.5) / height};
            const std::size_t k = static_cast<std::size_t>(y) * width + x;
            distorted[k] = map.distort(p);
            logDensity[k] = std::log(std::max(map.density(p), 1e-12));
            lo = std::min(lo, logDensity[k]);
            hi = std::max(hi, logDensity[k]);
        }
    // A uniform map gets a mid-scale colour rather than a division by zero.
    const double range = hi - lo > 1e-9 ? hi - lo : 1.0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t k = static_cast<std::size_t>(y) * width + x;
            const glm::vec3 c = heat(hi - lo > 1e-9 ? (logDensity[k] - lo) / range : 0.5);
            for (int ch = 0; ch < 3; ++ch) picture.at(x, y, ch) = c[ch];
        }
    // Lines of the CoNUS pixel grid: where floor(u_d * lines) or floor(v_d * lines) changes.
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t k = static_cast<std::size_t>(y) * width + x;
            const glm::dvec2 d = distorted[k] * double(lines);
            bool edge = false;
            if (x + 1 < width) edge |= std::floor(d.x) != std::floor(distorted[k + 1].x * lines);
            if (y + 1 < height) edge |= std::floor(d.y) != std::floor(distorted[k + width].y * lines);
            if (edge) blend(picture, x, y, glm::vec3(1.0f), 0.55f);
        }
    // Anisotropy of each cell's mean Jacobian (map_measures.h): contours at the levels below, and a
    // cross at the most elongated cell.
    static constexpr double kAnisotropyLevels[] = {2.0, 4.0};
    std::vector<double> ratio(distorted.size());
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            ratio[static_cast<std::size_t>(y) * width + x] = anisotropy(cellJacobianAt(map, {(x + 0.5) / width, (y + 0.5) / height}), aspect);
    const glm::vec3 cyan(0.2f, 0.9f, 1.0f);
    for (int y = 0; y + 1 < height; ++y)
        for (int x = 0; x + 1 < width; ++x) {
            const std::size_t k = static_cast<std::size_t>(y) * width + x;
            for (double level : kAnisotropyLevels)
                if ((ratio[k] >= level) != (ratio[k + 1] >= level) || (ratio[k] >= level) != (ratio[k + width] >= level))
                    blend(picture, x, y, cyan, 0.9f);
        }
    const MapMeasures measures = measureMap(map, aspect);
    const int cx = static_cast<int>(measures.mostAnisotropic.x * width), cy = static_cast<int>(measures.mostAnisotropic.y * height);
    for (int d = -6; d <= 6; ++d) {
        blend(picture, cx + d, cy + d, cyan, 1.0f);
        blend(picture, cx + d, cy - d, cyan, 1.0f);
    }
    if (analytic && analytic->is(format::MapKind::Foci)) {
        for (const auto& f : analytic->foci) {
            // r is a fraction of the image width, circular in pixels.
            const double radius = f.r * width;
            const int steps = std::max(64, static_cast<int>(radius * 8));
            for (int s = 0; s < steps; ++s) {
                const double a = 2 * std::numbers::pi * s / steps;
                blend(picture, static_cast<int>(f.u * width + radius * std::cos(a)),
                      static_cast<int>(f.v * height + radius * std::sin(a)), {0.2f, 1.0f, 0.4f}, 1.0f);
            }
        }
    }
    return picture;
}

Image toRgb(const Image& image) {
    Image rgb = makeImage(image.width, image.height, {"R", "G", "B"});
    int source[3] = {image.channelIndex("R"), image.channelIndex("G"), image.channelIndex("B")};
    if (source[0] < 0 || source[1] < 0 || source[2] < 0) {
        int grey = image.channelIndex("Y");
        if (grey < 0) grey = 0;
        source[0] = source[1] = source[2] = grey;
    }
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = image.at(x, y, source[c]);
    return rgb;
}

Image sideBySide(std::span<const Image> images, int gap) {
    int width = gap, height = 0;
    for (const auto& image : images) {
        width += image.width + gap;
        height = std::max(height, image.height);
    }
    Image strip = makeImage(width, height + 2 * gap, {"R", "G", "B"});
    std::fill(strip.pixels.begin(), strip.pixels.end(), 0.12f);
    int x0 = gap;
    for (const auto& image : images) {
        const Image rgb = toRgb(image);
        for (int y = 0; y < rgb.height; ++y)
            for (int x = 0; x < rgb.width; ++x)
                for (int c = 0; c < 3; ++c) strip.at(x0 + x, gap + y, c) = rgb.at(x, y, c);
        x0 += image.width + gap;
    }
    return strip;
}

Image contactSheet(std::span<const Image> tiles, int columns) {
    if (tiles.empty() || columns < 1) throw Error(ErrorCode::InvalidArgument, "contactSheet: no tiles or no columns");
    const int tw = tiles.front().width, th = tiles.front().height, gap = 4;
    const int rows = (static_cast<int>(tiles.size()) + columns - 1) / columns;
    Image sheet = makeImage(columns * tw + (columns + 1) * gap, rows * th + (rows + 1) * gap, {"R", "G", "B"});
    for (std::size_t k = 0; k < tiles.size(); ++k) {
        const int x0 = gap + static_cast<int>(k % columns) * (tw + gap), y0 = gap + static_cast<int>(k / columns) * (th + gap);
        for (int y = 0; y < th; ++y)
            for (int x = 0; x < tw; ++x)
                for (int c = 0; c < 3; ++c) sheet.at(x0 + x, y0 + y, c) = tiles[k].at(x, y, c);
    }
    return sheet;
}

}  // namespace conus::codec
