#include "conus/codec/image/encode.h"

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/foci_budget.h"
#include "conus/codec/builders/frame_budget.h"
#include "conus/codec/builders/importance.h"
#include "conus/codec/image/metrics.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "encode_cases.h"
#include "test_images.h"
#include "../../../codec/src/image/encode_pvt.h"

namespace conus::codec {
namespace {

using namespace conus::test;  // the shared test images, maxAbsDifference and encode cases

// Bilinear source sample at normalized (u,v), clamp to edge: the single-tap encoder.
float sampleBilinear(const Image& im, double u, double v) {
    const double x = std::clamp(u * im.width - 0.5, 0.0, im.width - 1.0);
    const double y = std::clamp(v * im.height - 0.5, 0.0, im.height - 1.0);
    const int x0 = std::min(static_cast<int>(x), im.width - 2), y0 = std::min(static_cast<int>(y), im.height - 2);
    const double fx = x - x0, fy = y - y0;
    return static_cast<float>((1 - fy) * ((1 - fx) * im.at(x0, y0) + fx * im.at(x0 + 1, y0)) +
                              fy * ((1 - fx) * im.at(x0, y0 + 1) + fx * im.at(x0 + 1, y0 + 1)));
}

TEST(EncodeAreaDownsample, MatchesExactAreaIntegralForAnyRatio) {
    const Image src = noise(10, 7, {"Y"});
    const Image out = areaDownsample(src, 3, 4);
    // Brute force: integrate the piecewise-constant source over each output pixel.
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 3; ++x) {
            const double x0 = x * 10.0 / 3, x1 = (x + 1) * 10.0 / 3, y0 = y * 7.0 / 4, y1 = (y + 1) * 7.0 / 4;
            double sum = 0;
            for (int j = 0; j < 7; ++j)
                for (int i = 0; i < 10; ++i) {
                    const double ox = std::max(0.0, std::min(x1, i + 1.0) - std::max(x0, double(i)));
                    const double oy = std::max(0.0, std::min(y1, j + 1.0) - std::max(y0, double(j)));
                    sum += ox * oy * src.at(i, j);
                }
            EXPECT_NEAR(out.at(x, y), sum / ((x1 - x0) * (y1 - y0)), 1e-6) << x << "," << y;
        }
}

TEST(EncodeAreaDownsample, KeepsChannelsAndRejectsGrowing) {
    const Image src = noise(40, 30, {"R", "G", "B", "A"});
    const Image same = areaDownsample(src, 40, 30);
    EXPECT_EQ(same.channels, src.channels);
    EXPECT_LT(maxAbsDifference(same, src), 1e-6f);
    EXPECT_THROW(areaDownsample(src, 41, 30), conus::Error);
    EXPECT_THROW(areaDownsample(src, 0, 30), conus::Error);
}

// The EWA filter's taps land on source pixel centres at every integer ratio (the anisotropic
// kernel's at powers of two: EncodeAnisotropic.UniformMapIsAnAreaDownsample).
TEST(Encode, IdentityMapEqualsAreaDownsampleAtIntegerRatios) {
    struct Case {
        int from, to;
        std::vector<std::string> channels;
        int mapSide;
    };
    const std::vector<Case> cases = {
        {512, 128, {"Y"}, 2},
        {512, 128, {"R", "G", "B"}, 17},
        {512, 128, {"R", "G", "B", "A"}, 33},
        {300, 100, {"R", "G", "B", "A"}, 9},
        {300, 100, {"R", "G", "B", "Z"}, map_rules::kDefaultSide},
        {300, 100, {"R", "G", "B", "A", "Z"}, 5},  // a channel count without a fixed kernel
        {300, 150, {"Y", "A"}, 3},                 // ratio 2
    };
    for (const Case& c : cases) {
        const Image src = noise(c.from, c.from, c.channels, c.from + c.to);
        const SamplingMap map = SamplingMap::identity(c.mapSide, c.mapSide);
        const Image enc = encodeImage(src, map, sized(c.to, c.to, 0, EncodeFilter::Ewa));
        const Image ref = areaDownsample(src, c.to, c.to);
        EXPECT_EQ(enc.channels, c.channels);
        EXPECT_LT(maxAbsDifference(enc, ref), 1e-5f) << c.from << "->" << c.to << " with " << c.channels.size()
                                                     << " channels";
    }
    // Different ratios per axis: 300x200 -> 100x100 (3 and 2).
    const Image src = noise(300, 200, {"R", "G", "B"}, 9);
    const Image enc = encodeImage(src, SamplingMap::identity(5, 5), sized(100, 100, 0, EncodeFilter::Ewa));
    EXPECT_LT(maxAbsDifference(enc, areaDownsample(src, 100, 100)), 1e-5f);
}

TEST(Encode, FootprintsBeyondTheTapCapUseThePyramid) {
    // A 64x ratio is four times the tap cap: the encoder reads a box-filtered mip level, which for
    // powers of two is still the exact area average.
    // (Both filters.)
    for (const EncodeFilter filter : kFilters) {
        const Image src = noise(1024, 1024, {"Y"}, 3);
        const Image enc = encodeImage(src, SamplingMap::identity(9, 9), sized(16, 16, 0, filter));
        EXPECT_LT(maxAbsDifference(enc, areaDownsample(src, 16, 16)), 1e-5f);
        // Non-power-of-two: close to the area average of a zone plate that reaches the output's
        // Nyquist rate at the sides (and passes it in the corners). The anisotropic kernel reads two
        // levels whose texels are a third and two thirds of the footprint, bilinear: it takes
        // more off the top frequencies than the box, which aliases them there.
        const Image zp = zonePlate(1000, 0.01);
        EXPECT_GT(psnr(encodeImage(zp, SamplingMap::identity(9, 9), sized(20, 20, 0, filter)), areaDownsample(zp, 20, 20)),
                  filter == EncodeFilter::Ewa ? 35.0 : 25.0);
    }
}

TEST(Encode, ConstantImageStaysConstantUnderAnyMapAndKeepsAlpha) {
    Image src = makeImage(256, 192, {"R", "G", "B", "A"});
    for (std::size_t i = 0; i < src.pixels.size(); i += 4) {
        src.pixels[i] = 0.25f;
        src.pixels[i + 1] = 0.5f;
        src.pixels[i + 2] = 0.75f;
        src.pixels[i + 3] = 0.4f;
    }
    for (const SamplingMap& map : {SamplingMap::identity(2, 2), twoFoci(256.0 / 192.0),
                                   twoFoci(256.0 / 192.0, FociComposition::Add)}) {
        const Image enc = encodeImage(src, map, sized(96, 64));
        ASSERT_EQ(enc.channels, src.channels);
        for (std::size_t i = 0; i < enc.pixels.size(); i += 4) {
            ASSERT_NEAR(enc.pixels[i], 0.25f, 1e-5f);
            ASSERT_NEAR(enc.pixels[i + 1], 0.5f, 1e-5f);
            ASSERT_NEAR(enc.pixels[i + 2], 0.75f, 1e-5f);
            ASSERT_NEAR(enc.pixels[i + 3], 0.4f, 1e-5f);
        }
    }
}

TEST(Encode, AlphaIsCarriedThroughTheMap) {
    // Alpha a ramp in u, colour noise: the encoded alpha must be the ramp at the undistorted u.
    Image src = noise(400, 400, {"R", "G", "B", "A"}, 5);
    for (int y = 0; y < 400; ++y)
        for (int x = 0; x < 400; ++x) src.at(x, y, 3) = (x + 0.5f) / 400;
    const SamplingMap map = twoFoci();
    const Image enc = encodeImage(src, map, sized(100, 100));
    for (int y = 0; y < 100; y += 7)
        for (int x = 0; x < 100; x += 7) {
            const glm::dvec2 p = map.undistort({(x + 0.5) / 100, (y + 0.5) / 100});
            // A linear ramp survives a symmetric box filter; clamping at the borders bends it.
            if (p.x > 0.05 && p.x < 0.95) {
                EXPECT_NEAR(enc.at(x, y, 3), p.x, 2e-3) << x << "," << y;
            }
        }
}

// Stripes of 64 source pixels: vertical ones in R, horizontal ones in G. Along each CoNUS row, the
// R edges must sit where Eq. 1 sends the source edges (and likewise G along columns).
TEST(Encode, EdgesLandWhereEquationOnePutsThem) {
    const int S = 1024, C = 256, period = 64;
    Image src = makeImage(S, S, {"R", "G"});
    for (int y = 0; y < S; ++y)
        for (int x = 0; x < S; ++x) {
            src.at(x, y, 0) = (x / period) % 2 ? 1.0f : 0.0f;
            src.at(x, y, 1) = (y / period) % 2 ? 1.0f : 0.0f;
        }
    const std::vector<Focus> foci = {{0.5, 0.45, 0.1, 4}};
    const SamplingMap map = buildFociMap(foci);
    const Image enc = encodeImage(src, map, sized(C, C));

    const int edges = S / period - 1;
    double maxShift = 0, maxError = 0;
    for (int axis = 0; axis < 2; ++axis) {
        for (int line = 8; line < C; line += 16) {
            int found = 0;
            for (int k = 0; k + 1 < C; ++k) {
                const float a = axis == 0 ? enc.at(k, line, 0) : enc.at(line, k, 1);
                const float b = axis == 0 ? enc.at(k + 1, line, 0) : enc.at(line, k + 1, 1);
                if ((a - 0.5f) * (b - 0.5f) >= 0) continue;
                ++found;
                const double crossing = k + (0.5 - a) / (b - a);  // CoNUS pixel coordinate
                const double along = (crossing + 0.5) / C, across = (line + 0.5) / C;
                const glm::dvec2 pd = axis == 0 ? glm::dvec2(along, across) : glm::dvec2(across, along);
                const glm::dvec2 p = map.undistort(pd);
                // The nearest source edge, moved by Eq. 1 at the same position across it.
                const double coord = axis == 0 ? p.x : p.y;
                const double edge = std::round(coord * S / period) * period / double(S);
                const glm::dvec2 q = map.distort(axis == 0 ? glm::dvec2(edge, p.y) : glm::dvec2(p.x, edge));
                const double expected = (axis == 0 ? q.x : q.y) * C - 0.5;
                maxError = std::max(maxError, std::abs(crossing - expected));
                maxShift = std::max(maxShift, std::abs(expected - (edge * C - 0.5)));
            }
            EXPECT_EQ(found, edges) << "axis " << axis << " line " << line;
        }
    }
    EXPECT_GT(maxShift, 5.0) << "the map should move edges by several CoNUS pixels";
    EXPECT_LT(maxError, 1.0) << "edges must sit where Eq. 1 puts them, within a CoNUS pixel";
}

// Where the map compresses, a fine zone plate must come out as its local average, not as aliased
// rings: compare with an exact supersampled reference, and with point sampling.
TEST(Encode, FootprintFilterPreventsAliasing) {
    const int S = 768, C = 160;
    const Image src = zonePlate(S, 0.45);
    const std::vector<Focus> foci = {{0.5, 0.5, 0.08, 3}};
    const SamplingMap map = buildFociMap(foci);
    const Image enc = encodeImage(src, map, sized(C, C));

    Image reference = makeImage(C, C, {"Y"}), pointSampled = makeImage(C, C, {"Y"});
    const int kSuper = 12;  // sub-pixels per axis per CoNUS pixel, each undistorted exactly
    for (int y = 0; y < C; ++y)
        for (int x = 0; x < C; ++x) {
            double sum = 0;
            for (int j = 0; j < kSuper; ++j)
                for (int i = 0; i < kSuper; ++i) {
                    const glm::dvec2 p = map.undistort({(x + (i + 0.5) / kSuper) / C, (y + (j + 0.5) / kSuper) / C});
                    sum += sampleBilinear(src, p.x, p.y);
                }
            reference.at(x, y) = static_cast<float>(sum / (kSuper * kSuper));
            const glm::dvec2 p = map.undistort({(x + 0.5) / C, (y + 0.5) / C});
            pointSampled.at(x, y) = sampleBilinear(src, p.x, p.y);
        }
    const double filtered = psnr(enc, reference), single = psnr(pointSampled, reference);
    RecordProperty("psnr_filtered_db", std::to_string(filtered));
    RecordProperty("psnr_point_sampled_db", std::to_string(single));
    std::printf("[ info ] vs 12x12 supersampled reference: footprint filter %.2f dB, point sampling %.2f dB\n",
                filtered, single);
    EXPECT_GT(filtered, 25.0);
    EXPECT_GT(filtered - single, 10.0) << "filtered " << filtered << " dB, point sampled " << single << " dB";
}

// The long-axis Gaussian (encode.h): none while the footprint is at most kEncodeBoxAnisotropy : 1
// or its major axis no longer than the uniform image's pixel; otherwise the filter's extent grows
// along the major axis only, by the smaller of the two ramps. Rotated, asymmetric footprints.
TEST(Encode, LongAxisLowPassOnlyWhereTheMajorAxisOutspansBothRules) {
    const double angle = 0.37;
    const glm::dvec2 along(std::cos(angle), std::sin(angle)), across(-along.y, along.x);
    // Edges a = major * along, b = minor * across: in (s,t) the major axis is s, the minor t.
    const auto plan = [&](double major, double minor, double uniform) {
        return planFootprint(major * along, minor * across, uniform);
    };
    const auto sigma = [](glm::dvec2 extent) { return (extent.x - 1.0) / (2.0 * kEncodeGaussianReach); };
    // Round enough: plain box, whatever the uniform pixel.
    EXPECT_DOUBLE_EQ(plan(2.9, 2.0, 1.0).extent.x, 1.0);
    EXPECT_DOUBLE_EQ(plan(2.9, 2.0, 1.0).extent.y, 1.0);
    // Long and thin, but finer than the uniform pixel along its length (a focus's inner ring): box.
    EXPECT_DOUBLE_EQ(plan(3.0, 0.5, 4.0).extent.x, 1.0);
    EXPECT_DOUBLE_EQ(plan(3.9, 0.4, 4.0).extent.y, 1.0);
    // Coarser than the uniform pixel: the anisotropy ramp where it is the smaller ...
    const double minorOverMajor = 1.0 / 6.0;
    const FootprintPlan a = plan(12.0, 2.0, 2.0);  // 1 - 1.5/6 = 0.75 < 1 - 2/12
    EXPECT_NEAR(sigma(a.extent), kEncodeAnisotropicSigma * (1.0 - kEncodeBoxAnisotropy * minorOverMajor), 1e-9);
    EXPECT_DOUBLE_EQ(a.extent.y, 1.0);
    // ... and the uniform ramp where that is: the same footprint against a wider uniform pixel.
    const FootprintPlan b = plan(12.0, 2.0, 6.0);  // 1 - 6/12 = 0.5 < 0.75
    EXPECT_NEAR(sigma(b.extent), kEncodeAnisotropicSigma * 0.5, 1e-9);
    EXPECT_LT(sigma(b.extent), sigma(a.extent));
    EXPECT_NEAR(uniformSpacing(1024, 768, 256, 192), 4.0, 1e-12);
}

TEST(Encode, ThreadCountDoesNotChangeTheResult) {
    const Image src = noise(512, 384, {"R", "G", "B", "A"}, 11);
    const SamplingMap map = twoFoci(512.0 / 384.0);
    const Image one = encodeImage(src, map, sized(160, 120, 1));
    const Image two = encodeImage(src, map, sized(160, 120, 2));
    EXPECT_EQ(one.pixels, two.pixels);
    const Image a1 = areaDownsample(src, 100, 70, 1), a2 = areaDownsample(src, 100, 70, 2);
    EXPECT_EQ(a1.pixels, a2.pixels);
}

// The encoder's erf (a polynomial, so that a row of taps vectorizes) against the library's, over
// the whole reach of the Gaussian and beyond it (held at the reach's value); non-decreasing,
// which the encoder relies on when it takes erf at a slab's ends from its rows' and columns'.
TEST(EncodeErf, MatchesTheLibraryOverTheReachAndNeverDecreases) {
    const double reach = kEncodeGaussianReach / std::sqrt(2.0);
    double worst = 0, previous = -2;
    for (int i = -200000; i <= 200000; ++i) {
        const double x = reach * i / 200000.0;
        const double e = detail::erfOnReach(x);
        worst = std::max(worst, std::abs(e - std::erf(x)));
        EXPECT_GE(e, previous) << "at " << x;
        previous = e;
    }
    EXPECT_LT(worst, 2e-9);
    // The float twin (the anisotropic kernel's weights): within float rounding of erf.
    double worstFloat = 0;
    for (int i = -200000; i <= 200000; ++i) {
        const double x = reach * i / 200000.0;
        worstFloat = std::max(worstFloat, std::abs(detail::erfOnReachFloat(static_cast<float>(x)) -
                                                   std::erf(double(static_cast<float>(x)))));
    }
    EXPECT_LT(worstFloat, 4e-7);
    EXPECT_FLOAT_EQ(detail::erfOnReachFloat(-3.0f), -detail::erfOnReachFloat(float(reach)));
    EXPECT_DOUBLE_EQ(detail::erfOnReach(3.0), detail::erfOnReach(reach));
    EXPECT_DOUBLE_EQ(detail::erfOnReach(-1e300), -detail::erfOnReach(reach));
}

// encode.h's rule evaluated the plain way, in double, tap by tap over the whole grid with
// clamp-to-edge bilinear reads and std::erf: what the encoder's row-at-a-time, vectorized path
// (and its fallback at the borders and for other channel counts) must reproduce. The major axis
// comes from the angle of [a b]'s right singular vector, the slabs from a direct intersection.
double bilinearAt(const Image& im, int c, double x, double y) {
    x = std::clamp(x, 0.0, im.width - 1.0);
    y = std::clamp(y, 0.0, im.height - 1.0);
    const int x0 = std::min(static_cast<int>(x), im.width - 2), y0 = std::min(static_cast<int>(y), im.height - 2);
    const double fx = x - x0, fy = y - y0;
    const auto v = [&](int i, int j) { return double(im.pixels[(std::size_t(j) * im.width + i) * im.channelCount() + c]); };
    return (1 - fy) * ((1 - fx) * v(x0, y0) + fx * v(x0 + 1, y0)) + fy * ((1 - fx) * v(x0, y0 + 1) + fx * v(x0 + 1, y0 + 1));
}

Image encodeByTheRule(const Image& src, const SamplingMap& map, int W, int H, int& gaussianPixels) {
    std::vector<Image> levels{src};
    while (levels.back().width > 1 || levels.back().height > 1)
        levels.push_back(areaDownsample(levels.back(), std::max(1, (levels.back().width + 1) / 2),
                                        std::max(1, (levels.back().height + 1) / 2), 1));
    const FootprintField field(map);
    const double uniform = uniformSpacing(src.width, src.height, W, H);
    const int channels = src.channelCount();
    Image out = makeImage(W, H, src.channels);
    gaussianPixels = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec2 p = map.undistort({(x + 0.5) / W, (y + 0.5) / H});
            const glm::dmat2 J = field.inverseJacobian(p);
            const glm::dvec2 a = J[0] / double(W) * glm::dvec2(src.width, src.height);
            const glm::dvec2 b = J[1] / double(H) * glm::dvec2(src.width, src.height);
            // [a b]^T [a b] = [[p q] [q r]]: its eigenvalues are the squared axes.
            const double pp = glm::dot(a, a), q = glm::dot(a, b), r = glm::dot(b, b);
            const double half = std::hypot(0.5 * (pp - r), q);
            const double major = std::sqrt(0.5 * (pp + r) + half), minor = std::sqrt(std::max(0.0, 0.5 * (pp + r) - half));
            const double angle = 0.5 * std::atan2(2 * q, pp - r);
            const glm::dvec2 m(std::cos(angle), std::sin(angle));
            const double ramp = major > 0 ? std::min(1 - kEncodeBoxAnisotropy * minor / major, 1 - uniform / major) : 0;
            const double sigma = kEncodeAnisotropicSigma * std::max(0.0, ramp), reach = kEncodeGaussianReach * sigma;
            const FootprintPlan plan = planFootprint(a, b, uniform);
            const int top = static_cast<int>(levels.size()) - 1;
            const int level = std::min(static_cast<int>(plan.level), top);
            const double blend = level < top ? plan.level - level : 0.0;
            if (sigma >= 1e-4) ++gaussianPixels;
            std::vector<double> value[2];
            for (int l = level; l <= std::min(level + 1, top); ++l) {
                const Image& im = levels[l];
                const glm::dvec2 scale(double(im.width) / src.width, double(im.height) / src.height);  // per axis
                const glm::dvec2 aL = a * scale, bL = b * scale;
                const int ns = std::clamp(static_cast<int>(std::ceil(glm::length(aL) * plan.extent.x - 1e-3)), 1, 128);
                const int nt = std::clamp(static_cast<int>(std::ceil(glm::length(bL) * plan.extent.y - 1e-3)), 1, 128);
                std::vector<double> sum(channels, 0.0);
                double total = 0;
                for (int j = 0; j < nt; ++j)
                    for (int i = 0; i < ns; ++i) {
                        const double s = (i + 0.5) * plan.extent.x / ns - 0.5 * plan.extent.x;
                        const double t = (j + 0.5) * plan.extent.y / nt - 0.5 * plan.extent.y;
                        double w = 1;
                        if (sigma >= 1e-4) {  // the Gaussian's mass over o with (s,t) - o m in the unit box
                            double lo = -reach, hi = reach;
                            for (const auto& [u, mu] : {std::pair{s, m.x}, std::pair{t, m.y}}) {
                                if (std::abs(mu) < 1e-9) {
                                    if (std::abs(u) > 0.5) hi = lo;
                                    continue;
                                }
                                lo = std::max(lo, std::min((u - 0.5) / mu, (u + 0.5) / mu));
                                hi = std::min(hi, std::max((u - 0.5) / mu, (u + 0.5) / mu));
                            }
                            w = hi > lo ? 0.5 * (std::erf(hi / (std::sqrt(2.0) * sigma)) - std::erf(lo / (std::sqrt(2.0) * sigma))) : 0;
                        }
                        const glm::dvec2 tap = p * glm::dvec2(im.width, im.height) - 0.5 + aL * s + bL * t;
                        for (int c = 0; c < channels; ++c) sum[c] += w * bilinearAt(im, c, tap.x, tap.y);
                        total += w;
                    }
                for (double& v : sum) v /= total;
                value[l - level] = sum;
                if (!(blend > 0)) break;
            }
            for (int c = 0; c < channels; ++c)
                out.pixels[(std::size_t(y) * W + x) * channels + c] = static_cast<float>(
                    blend > 0 ? value[0][c] + blend * (value[1][c] - value[0][c]) : value[0][c]);
        }
    return out;
}

TEST(Encode, MatchesAPlainEvaluationOfTheFootprintRule) {
    // A focus near the left edge (footprints clamped at the border) and one inside whose ring has
    // long thin footprints (the Gaussian); 1, 3 (the vector path) and 5 channels (the general one).
    const std::vector<Focus> foci = {{0.12, 0.45, 0.1, 4}, {0.62, 0.55, 0.12, 3}};
    FociOptions options;
    options.aspect = 330.0 / 250.0;
    const SamplingMap map = buildFociMap(foci, options);
    for (const auto& channels : {std::vector<std::string>{"Y"}, std::vector<std::string>{"R", "G", "B"},
                                 std::vector<std::string>{"R", "G", "B", "A", "Z"}}) {
        const Image src = noise(330, 250, channels, 5);
        const Image enc = encodeImage(src, map, sized(110, 84, 2, EncodeFilter::Ewa));
        int gaussian = 0;
        const Image reference = encodeByTheRule(src, map, 110, 84, gaussian);
        EXPECT_GT(gaussian, 110 * 84 / 20) << "too few long footprints to test the Gaussian";
        EXPECT_LT(maxAbsDifference(enc, reference), 2e-6f) << channels.size() << " channels";
    }
}

TEST(Encode, ReportsProgressUpToOne) {
    const Image src = noise(128, 128, {"Y"});
    std::vector<double> seen;
    EncodeOptions o = sized(64, 64, 2);
    o.progress = [&](double f) { seen.push_back(f); };
    encodeImage(src, SamplingMap::identity(3, 3), o);
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
    EXPECT_DOUBLE_EQ(seen.back(), 1.0);
}

TEST(Encode, RejectsBadArguments) {
    const Image src = noise(16, 16, {"Y"});
    const SamplingMap map = SamplingMap::identity(2, 2);
    auto code = [&](const Image& s, int w, int h) {
        try {
            encodeImage(s, map, sized(w, h));
        } catch (const conus::Error& e) {
            return static_cast<int>(e.code());
        }
        return -1;
    };
    EXPECT_EQ(code(src, 0, 8), static_cast<int>(ErrorCode::InvalidArgument));
    EXPECT_EQ(code(src, 8, -3), static_cast<int>(ErrorCode::InvalidArgument));
    EXPECT_EQ(code(src, kMaxImageSide + 1, 8), static_cast<int>(ErrorCode::LimitExceeded));
    EXPECT_EQ(code(src, kMaxImageSide, kMaxImageSide), static_cast<int>(ErrorCode::LimitExceeded));
    EXPECT_EQ(code(Image{}, 8, 8), static_cast<int>(ErrorCode::InvalidArgument));
    Image broken = src;
    broken.pixels.resize(10);
    EXPECT_EQ(code(broken, 8, 8), static_cast<int>(ErrorCode::InvalidArgument));
    EXPECT_THROW(areaDownsample(Image{}, 4, 4), conus::Error);
}


// ---- the anisotropic kernel (EncodeFilter::Anisotropic) against the EWA reference and analytic
// expectations ----

// Under a uniform map the encoder is the area average whichever filter is asked (encode.h: the
// uniform baseline stays exact). Away from a weak focus, where the map is near uniform at a ratio
// of 3, the anisotropic kernel is box-ish: the blend of two levels a little wider than the box.
TEST(EncodeAnisotropic, UniformMapIsAnAreaDownsample) {
    const Image src = noise(600, 600, {"R", "G", "B"}, 21);
    for (const auto& [w, h] : {std::pair{300, 300}, std::pair{150, 150}, std::pair{200, 200}, std::pair{200, 300}}) {
        const Image enc = encodeImage(src, SamplingMap::identity(9, 9), sized(w, h));
        EXPECT_LT(maxAbsDifference(enc, areaDownsample(src, w, h)), 1e-5f) << "600 -> " << w << "x" << h;
    }
    const Image smooth = texture(600, 4);
    const std::vector<Focus> weak = {{0.2, 0.2, 0.03, 1.2}};
    const SamplingMap map = buildFociMap(weak);
    const Image a = encodeImage(smooth, map, sized(200, 200));
    const Image e = encodeImage(smooth, map, sized(200, 200, 0, EncodeFilter::Ewa));
    const Image box = areaDownsample(smooth, 200, 200);
    // (The map there is not quite uniform: the context gives the focus its pixels, so the EWA's
    // box is not the area average either; the kernels are compared with each other and with it.)
    double worstA = 0, worstE = 0, squares = 0;
    int n = 0;
    for (int y = 100; y < 190; ++y)
        for (int x = 100; x < 190; ++x)
            for (int c = 0; c < 3; ++c, ++n) {
                worstA = std::max(worstA, double(std::abs(a.at(x, y, c) - box.at(x, y, c))));
                worstE = std::max(worstE, double(std::abs(e.at(x, y, c) - box.at(x, y, c))));
                squares += double(a.at(x, y, c) - e.at(x, y, c)) * (a.at(x, y, c) - e.at(x, y, c));
            }
    const double rms = std::sqrt(squares / n);
    std::printf("[ info ] far from a weak focus: largest difference from the area average: anisotropic %.4f, EWA %.4f; "
                "anisotropic against EWA %.4f rms\n", worstA, worstE, rms);
    EXPECT_LT(worstA, 1.5 * worstE);
    EXPECT_LT(rms, 0.015);  // 36 dB: a blur apart on 3x3-blurred noise
    EXPECT_GT(rms, 1e-4) << "the anisotropic kernel should have run (it is not the box at a ratio of 3)";
}

// A linear ramp (in x and y, not along an axis) stays that ramp under any map: each CoNUS pixel is
// the ramp at SM^-1 of its centre, since the kernel is symmetric about the centre and every box
// level of a ramp is the same ramp. Away from the borders, where the pyramid clamps.
TEST(EncodeAnisotropic, LinearRampStaysLinearUnderAFociMap) {
    const int S = 640, C = 160;
    Image src = makeImage(S, S, {"Y", "A"});
    const auto ramp = [](double u, double v) { return 0.2 + 0.5 * u + 0.25 * v; };
    for (int y = 0; y < S; ++y)
        for (int x = 0; x < S; ++x) {
            src.at(x, y, 0) = static_cast<float>(ramp((x + 0.5) / S, (y + 0.5) / S));
            src.at(x, y, 1) = static_cast<float>(1.0 - 0.6 * (y + 0.5) / S);
        }
    const SamplingMap map = twoFoci();
    const Image enc = encodeImage(src, map, sized(C, C));
    double worst = 0;
    int checked = 0;
    for (int y = 0; y < C; ++y)
        for (int x = 0; x < C; ++x) {
            const glm::dvec2 p = map.undistort({(x + 0.5) / C, (y + 0.5) / C});
            if (p.x < 0.15 || p.x > 0.85 || p.y < 0.15 || p.y > 0.85) continue;
            ++checked;
            worst = std::max(worst, std::abs(enc.at(x, y, 0) - ramp(p.x, p.y)));
            worst = std::max(worst, std::abs(enc.at(x, y, 1) - (1.0 - 0.6 * p.y)));
        }
    EXPECT_GT(checked, C * C / 3);
    EXPECT_LT(worst, 2e-4);
}

// Against the EWA filter on the same maps: the two kernels filter the same footprints and differ
// only in how they approximate the box across the minor axis, so photo-like content comes out
// the same to within a little blur; noise (all its energy at the top frequencies, where the two
// blurs differ most) still agrees to within a few percent of its range.
TEST(EncodeAnisotropic, AgreesWithTheEwaFilter) {
    const SamplingMap foci = twoFoci(400.0 / 300.0);
    const Image photo = photoLike(400, 300);
    const Image a = encodeImage(photo, foci, sized(200, 150));
    const Image e = encodeImage(photo, foci, sized(200, 150, 0, EncodeFilter::Ewa));
    const double db = psnr(a, e);
    std::printf("[ info ] anisotropic against EWA, photo-like 400x300 -> 200x150, two foci: %.2f dB\n", db);
    EXPECT_GT(db, 38.0);
    const Image n = noise(512, 512, {"Y"}, 5);
    const SamplingMap square = twoFoci();
    EXPECT_GT(psnr(encodeImage(n, square, sized(128, 128)), encodeImage(n, square, sized(128, 128, 0, EncodeFilter::Ewa))),
              24.0);
}

// The kernel's own properties under maps that stretch and rotate footprints: any channel count,
// alpha carried, a constant kept constant, the same result on any thread count.
TEST(EncodeAnisotropic, KeepsConstantsAndIsDeterministic) {
    const SamplingMap map = twoFoci(1.5, FociComposition::Add);
    Image flat = makeImage(180, 120, {"R", "G", "B", "A", "Z"});
    for (std::size_t i = 0; i < flat.pixels.size(); ++i) flat.pixels[i] = 0.1f + 0.2f * float(i % 5);
    const Image enc = encodeImage(flat, map, sized(90, 60));
    for (std::size_t i = 0; i < enc.pixels.size(); ++i) ASSERT_NEAR(enc.pixels[i], 0.1f + 0.2f * float(i % 5), 1e-5f) << i;
    const Image src = photoLike(300, 200, {"R", "G", "B", "A"});
    const Image one = encodeImage(src, map, sized(150, 100, 1)), two = encodeImage(src, map, sized(150, 100, 2));
    EXPECT_EQ(maxAbsDifference(one, two), 0.0f);
}

}  // namespace
}  // namespace conus::codec
