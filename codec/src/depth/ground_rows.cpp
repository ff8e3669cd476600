// The ground map's rows fitted to a terrain: each band of depth gets CoNUS rows in proportion to
// the screen rows it covers for the ground map's viewer, found by sweeping the horizon along rays
// across the field, within the DEM's own resolution and above a floor.
#include <algorithm>
#include <cmath>
#include <vector>

#include "conus/codec/depth/heightfield.h"

namespace conus::codec {
namespace {

constexpr double kHalfPi = 1.57079632679489661923;
constexpr int kColumns = 128;   // rays across the field of view
constexpr int kSegments = 256;  // the profile's pieces
constexpr double kFloor = 0.25;  // least row density, as a fraction of the uniform rate

// The DEM's height at field point (u, v) in [0,1]^2, bilinear between texel centres.
double heightAt(const Image& heights, int channel, double u, double v) {
    const double x = std::clamp(u * heights.width - 0.5, 0.0, heights.width - 1.0);
    const double y = std::clamp(v * heights.height - 0.5, 0.0, heights.height - 1.0);
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    const int x1 = std::min(x0 + 1, heights.width - 1), y1 = std::min(y0 + 1, heights.height - 1);
    const double fx = x - x0, fy = y - y0;
    const double top = heights.at(x0, y0, channel) * (1 - fx) + heights.at(x1, y0, channel) * fx;
    const double bottom = heights.at(x0, y1, channel) * (1 - fx) + heights.at(x1, y1, channel) * fx;
    return top * (1 - fy) + bottom * fy;
}

// Screen angle each depth bin brings into view (summed over the rays), nearest bin first: along a
// ray the terrain at depth z shows above what lies nearer only where its elevation angle exceeds
// the highest angle so far (the horizon sweep), and then by the difference.
std::vector<double> visibleAngle(const Image& heights, int channel, const GroundParams& ground, int bins) {
    const glm::dvec2 extent = fieldExtent(ground);
    const double eye = heightAt(heights, channel, 0.5, 1.0) + ground.eyeHeight;
    const double edge = 0.5 * extent.x / ground.far;  // tan of the half angle the far edge spans
    std::vector<double> angle(std::size_t(bins), 0.0);
    for (int c = 0; c < kColumns; ++c) {
        const double slope = edge * (2.0 * (c + 0.5) / kColumns - 1.0);
        double horizon = -kHalfPi;
        for (int k = 0; k < bins; ++k) {
            const double z = ground.near + (k + 0.5) / bins * (ground.far - ground.near);
            const double u = 0.5 + z * slope / extent.x;
            const double v = 1.0 - (k + 0.5) / bins;
            const double elevation = std::atan2(heightAt(heights, channel, u, v) - eye, z);
            if (k > 0 && elevation > horizon) angle[std::size_t(k)] += elevation - horizon;
            horizon = std::max(horizon, elevation);
        }
    }
    return angle;
}

}  // namespace

std::vector<double> groundRowsForTerrain(const Image& heights, const GroundParams& ground, int imageRows) {
    checkGroundParams(ground);
    if (heights.width < 1 || heights.height < 2 || imageRows < 1) return {};
    const int channel = heights.channelIndex("Z") >= 0 ? heights.channelIndex("Z") : 0;
    const int bins = std::clamp(heights.height, 64, 4096);
    std::vector<double> angle = visibleAngle(heights, channel, ground, bins);

    // Smoothed over a few bins: one ridge should not own a band of rows alone.
    const int radius = std::max(1, bins / 128);
    std::vector<double> smooth(angle.size(), 0.0);
    for (int k = 0; k < bins; ++k) {
        double sum = 0;
        int count = 0;
        for (int j = std::max(0, k - radius); j <= std::min(bins - 1, k + radius); ++j, ++count) sum += angle[std::size_t(j)];
        smooth[std::size_t(k)] = sum / count;
    }
    double total = 0;
    for (double a : smooth) total += a;
    if (!(total > 0) || !std::isfinite(total)) return {};

    // Row density (1: the uniform rate) clamped to [floor, cap], the cap the DEM's own row rate:
    // rows finer than the DEM's would sample the same texels again. The scale s makes the mean 1.
    const double cap = std::max(1.0, double(heights.height) / imageRows);
    const auto density = [&](double s, int k) { return std::clamp(s * smooth[std::size_t(k)] * bins / total, kFloor, cap); };
    const auto mean = [&](double s) {
        double sum = 0;
        for (int k = 0; k < bins; ++k) sum += density(s, k);
        return sum / bins;
    };
    double low = 1e-9, high = 1e9;
    for (int i = 0; i < 200 && high / low > 1 + 1e-12; ++i) {
        const double mid = std::sqrt(low * high);
        (mean(mid) < 1.0 ? low : high) = mid;
    }
    const double s = std::sqrt(low * high);

    // v runs from the far edge (0) to the near edge (1): bin k (nearest first) covers
    // v in [1 - (k + 1) / bins, 1 - k / bins]. The profile integrates the density over v.
    std::vector<double> cumulative(std::size_t(bins) + 1, 0.0);
    for (int i = 0; i < bins; ++i) cumulative[std::size_t(i) + 1] = cumulative[std::size_t(i)] + density(s, bins - 1 - i);
    std::vector<double> rows(kSegments + 1);
    for (int j = 0; j <= kSegments; ++j) {
        const double t = double(j) / kSegments * bins;
        const int i = std::min(static_cast<int>(t), bins - 1);
        const double value = cumulative[std::size_t(i)] + (t - i) * (cumulative[std::size_t(i) + 1] - cumulative[std::size_t(i)]);
        rows[std::size_t(j)] = double(float(value / cumulative.back()));  // as the file stores it
    }
    rows.front() = 0.0;
    rows.back() = 1.0;
    return rows;
}

}  // namespace conus::codec
