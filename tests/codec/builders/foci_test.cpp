// Foci: target density, single-focus magnification, both compositions, parsing.
#include "conus/codec/builders/foci.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <utility>

#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "conus/core/error.h"
#include "codec/builders/valid_map.h"

namespace conus::codec {
namespace {

using test::expectValid;

FociOptions options(double aspect, FociComposition composition = FociComposition::Density) {
    FociOptions o;
    o.aspect = aspect;
    o.composition = composition;
    return o;
}

// The files' r..2r profile (kFormatFalloff); FalloffProfiles covers the others, the default among them.
TEST(Foci, DensityProfile) {
    const Focus f{0.4, 0.5, 0.1, 4};
    const std::vector<Focus> foci{f};
    for (double aspect : {1.0, 16.0 / 9.0, 0.5}) {
        EXPECT_DOUBLE_EQ(fociDensity(foci, aspect, 0.4, 0.5, kFormatFalloff), 16.0);
        // The disc is circular in pixels: radius r in u, r * aspect in v.
        EXPECT_DOUBLE_EQ(fociDensity(foci, aspect, 0.4 + 0.1, 0.5, kFormatFalloff), 16.0);
        EXPECT_NEAR(fociDensity(foci, aspect, 0.4, 0.5 + 0.1 * aspect, kFormatFalloff), 16.0, 1e-9);
        EXPECT_NEAR(fociDensity(foci, aspect, 0.4, 0.5 + 0.2 * aspect, kFormatFalloff), 1.0, 1e-9);
        EXPECT_DOUBLE_EQ(fociDensity(foci, aspect, 0.4 + 0.25, 0.5, kFormatFalloff), 1.0);
        // Half way through the falloff the quintic smoothstep is 1/2.
        EXPECT_NEAR(fociDensity(foci, aspect, 0.4 + 0.15, 0.5, kFormatFalloff), 1.0 + 15.0 * 0.5, 1e-9);
    }
    EXPECT_DOUBLE_EQ(fociDensity({}, 1.0, 0.3, 0.3), 1.0);
    // Several foci: the max of their densities.
    const std::vector<Focus> two{{0.3, 0.5, 0.1, 2}, {0.32, 0.5, 0.1, 3}};
    EXPECT_DOUBLE_EQ(fociDensity(two, 1.0, 0.31, 0.5), 9.0);
}

const FociFalloff kFalloffs[] = {{2.0, FociFalloffShape::Density},    {1.25, FociFalloffShape::Density},
                                  {1.5, FociFalloffShape::LogDensity},  {3.0, FociFalloffShape::Density},
                                  {2.0, FociFalloffShape::LogRadius},   {3.0, FociFalloffShape::LogRadius}};

TEST(Foci, FalloffProfiles) {
    const Focus f{0.4, 0.5, 0.1, 4};
    const std::vector<Focus> foci{f};
    const double aspect = 16.0 / 9.0;
    auto at = [&](double s, const FociFalloff& falloff) {  // along a diagonal, circular in pixels
        const double c = std::cos(0.6), sn = std::sin(0.6);
        return fociDensity(foci, aspect, f.u + s * f.r * c, f.v + s * f.r * sn * aspect, falloff);
    };
    for (const FociFalloff& falloff : kFalloffs) {
        const std::string name = falloffText(falloff);
        EXPECT_NEAR(at(0.999, falloff), 16.0, 1e-9) << name;
        EXPECT_NEAR(at(falloff.width + 1e-6, falloff), 1.0, 1e-9) << name;
        // Strictly falling through the transition, and continuous at both ends.
        double last = at(1.0, falloff);
        EXPECT_NEAR(last, 16.0, 1e-6) << name;
        for (double s = 1.0 + 1e-3; s < falloff.width; s += 1e-3) {
            const double d = at(s, falloff);
            EXPECT_LT(d, last + 1e-12) << name << " s " << s;
            EXPECT_LT(last - d, 0.5) << name << " s " << s;  // no jump
            last = d;
        }
        EXPECT_NEAR(at(falloff.width - 1e-6, falloff), 1.0, 1e-6) << name;
        // Half way: the density shape blends the density, the log shapes its logarithm (to k).
        const double s = falloff.shape == FociFalloffShape::LogRadius ? std::sqrt(falloff.width) : 0.5 * (1 + falloff.width);
        EXPECT_NEAR(at(s, falloff), falloff.shape == FociFalloffShape::Density ? 1 + 15.0 / 2 : 4.0, 1e-6) << name;
    }
    // At equal width a log blend is never denser than the density blend (k^(2t) <= 1 + (k^2-1) t).
    for (double s = 1.0; s < 2.0; s += 0.01)
        EXPECT_LE(at(s, {2.0, FociFalloffShape::LogDensity}), at(s, {2.0, FociFalloffShape::Density}) + 1e-12) << s;
    // The default is the width 1.25 density blend: the same as no falloff given.
    EXPECT_EQ(fociDensity(foci, aspect, 0.51, 0.52), fociDensity(foci, aspect, 0.51, 0.52, {1.25, FociFalloffShape::Density}));
    EXPECT_NE(fociDensity(foci, aspect, 0.51, 0.52), fociDensity(foci, aspect, 0.51, 0.52, kFormatFalloff));
}

// The share of all samples that a focus's transition ring (r..width r) holds, on the built map:
// the ring's area after distortion (the integral of the map's density over it), sampled finely.
// Against the same share of the target density (fociDensity), which the map follows.
TEST(Foci, FalloffSetsTheTransitionsShareOfSamples) {
    const std::vector<Focus> foci{{0.45, 0.55, 0.08, 4}};
    const double aspect = 1.5;
    constexpr int kSamples = 400;
    struct Share {
        double map, target;
    };
    auto ringShare = [&](const FociFalloff& falloff) {
        FociOptions options;
        options.aspect = aspect;
        options.falloff = falloff;
        const SamplingMap map = buildFociMap(foci, options);
        expectValid(map);
        double mapRing = 0, mapAll = 0, targetRing = 0, targetAll = 0;
        for (int j = 0; j < kSamples; ++j)
            for (int i = 0; i < kSamples; ++i) {
                const double u = (i + 0.5) / kSamples, v = (j + 0.5) / kSamples;
                const double du = u - foci[0].u, dv = (v - foci[0].v) / aspect;
                const double s = std::sqrt(du * du + dv * dv) / foci[0].r;
                const double d = map.density({u, v}), t = fociDensity(foci, aspect, u, v, falloff);
                mapAll += d;
                targetAll += t;
                if (s > 1.0 && s < falloff.width) {
                    mapRing += d;
                    targetRing += t;
                }
            }
        return Share{mapRing / mapAll, targetRing / targetAll};
    };
    std::vector<Share> shares;
    for (const FociFalloff& falloff : kFalloffs) {
        shares.push_back(ringShare(falloff));
        // The map spends on the ring what its target asks, within 15% (a 65-node grid over a ring
        // a few cells wide).
        EXPECT_NEAR(shares.back().map, shares.back().target, 0.15 * shares.back().target) << falloffText(falloff);
    }
    // Wider rings hold more of the samples, log blends fewer than the density blend of their width.
    const Share wide2 = shares[0], narrow = shares[1], log15 = shares[2], wide3 = shares[3], logr2 = shares[4], logr3 = shares[5];
    EXPECT_LT(narrow.map, log15.map);
    EXPECT_LT(log15.map, wide2.map);
    EXPECT_LT(wide2.map, wide3.map);
    EXPECT_LT(logr2.map, wide2.map);
    EXPECT_LT(logr3.map, wide3.map);
}

TEST(Foci, SingleFocusMagnification) {
    for (double k : {2.0, 4.0}) {
        for (double aspect : {1.0, 16.0 / 9.0}) {
            const Focus f{0.45, 0.55, 0.1, k};
            const SamplingMap map = buildFociMap(std::vector<Focus>{f}, options(aspect));
            expectValid(map);
            const double centre = map.density({f.u, f.v});
            const double far = map.density({0.95, 0.05});
            // The bounded builder trades a little magnification for the bound (its energy weighs
            // both): within 15% of k.
            EXPECT_NEAR(std::sqrt(centre / far), k, k * 0.15) << "k " << k << " aspect " << aspect;
        }
        // Circular in pixels: about the same linear magnification along u and along v (a small
        // focus, so the image border does not shape it). Moser's flow is exact here; the bounded
        // builder lets the frame's 16:9 shape shear a dense focus a little (the conformal weight,
        // growing with density, holds it to 30%).
        const Focus small{0.5, 0.5, 0.04, k};
        for (DensityBuilder builder : {DensityBuilder::Flow, DensityBuilder::Bounded}) {
            FociOptions o = options(16.0 / 9.0);
            o.builder = builder;
            const SamplingMap map = buildFociMap(std::vector<Focus>{small}, o);
            const glm::dmat2 j = map.jacobian({small.u, small.v});
            const double tolerance = builder == DensityBuilder::Flow ? 0.06 : 0.3;
            EXPECT_NEAR(glm::length(j[0]), glm::length(j[1]), tolerance * glm::length(j[0])) << "k " << k;
        }
    }
}

TEST(Foci, NearbyFociKeepTheirMagnification) {
    // The context squeezed between two foci shears under Moser's flow and folds on a 65x65 grid.
    // Repairing the fold locally left steps, so the builder tempers the density: the
    // foci keep most of their magnification, and more than half of their extra one.
    const std::vector<Focus> foci{{0.42, 0.31, 0.08, 4}, {0.7, 0.65, 0.1, 3}};
    const SamplingMap map = buildFociMap(foci, options(1.0));
    expectValid(map);
    const double far = map.density({0.05, 0.95});
    EXPECT_GT(map.density({0.42, 0.31}) / far, 0.6 * 16.0);
    EXPECT_GT(map.density({0.7, 0.65}) / far, 0.6 * 9.0);
    EXPECT_NO_THROW(checkFociHeld(map, foci, options(1.0)));
}

TEST(Foci, BothCompositionsValidForHardCases) {
    const std::vector<std::vector<Focus>> cases = {
        {{0.5, 0.5, 0.1, 4}, {0.56, 0.52, 0.08, 6}},           // overlapping
        {{0.0, 0.0, 0.1, 5}, {1.0, 1.0, 0.05, 8}},             // corners
        {{0.5, 0.0, 0.1, 4}, {0.0, 0.5, 0.2, 3}, {1, 0.4, 0.05, 16}},  // edges
        {{0.5, 0.5, 0.02, map_rules::kMaxMagnification}},                                // tiny and extreme
        {{0.3, 0.3, 0.3, 8}, {0.6, 0.6, 0.3, 8}, {0.4, 0.7, 0.25, 8}},  // large, overlapping
    };
    for (std::size_t c = 0; c < cases.size(); ++c) {
        const auto& foci = cases[c];
        for (auto composition : {FociComposition::Density, FociComposition::Add}) {
            for (double aspect : {1.0, 2.0}) {
                SCOPED_TRACE("case " + std::to_string(c) + ", " + enumName(composition) + ", aspect " + std::to_string(aspect));
                const SamplingMap map = buildFociMap(foci, options(aspect, composition));
                expectValid(map);
                // The bounded density composition refines the grid for a focus a few cells wide.
                if (composition == FociComposition::Add) {
                    EXPECT_EQ(map.columns(), map_rules::kDefaultSide);
                } else {
                    EXPECT_GE(map.columns(), map_rules::kDefaultSide);
                    EXPECT_LE(map.columns(), kMaxRefinedSide);
                }
                // Magnifies at the first focus; adding three large overlapping foci's maps (case 4)
                // can cancel one of them, which is what the density composition is for.
                if (composition == FociComposition::Density || c != 4) {
                    EXPECT_GT(map.density({foci[0].u, foci[0].v}), 1.0);
                }
            }
        }
    }
}

TEST(Foci, AddMatchesDensityForFarApartFoci) {
    const std::vector<Focus> foci{{0.25, 0.25, 0.06, 3}, {0.75, 0.75, 0.06, 3}};
    const SamplingMap add = buildFociMap(foci, options(1.0, FociComposition::Add));
    const SamplingMap joint = buildFociMap(foci, options(1.0, FociComposition::Density));
    for (const Focus& f : foci) {
        // The magnification at the focus agrees (the far context differs: Add squeezes it more)...
        EXPECT_NEAR(add.density({f.u, f.v}), joint.density({f.u, f.v}), 0.15 * joint.density({f.u, f.v}));
        // ... and so does the shape of the magnified disc, up to a translation.
        const glm::dvec2 ca = add.distort({f.u, f.v}), cj = joint.distort({f.u, f.v});
        for (int a = 0; a < 16; ++a) {
            const glm::dvec2 offset = 1.5 * f.r * glm::dvec2(std::cos(a * 0.3927), std::sin(a * 0.3927));
            const glm::dvec2 da = add.distort(glm::dvec2(f.u, f.v) + offset) - ca;
            const glm::dvec2 dj = joint.distort(glm::dvec2(f.u, f.v) + offset) - cj;
            EXPECT_LT(glm::length(da - dj), 0.2 * glm::length(dj));
        }
    }
}

TEST(Foci, Deterministic) {
    const std::vector<Focus> foci{{0.42, 0.31, 0.08, 4}, {0.7, 0.6, 0.12, 3}};
    for (auto composition : {FociComposition::Density, FociComposition::Add}) {
        const SamplingMap a = buildFociMap(foci, options(1.5, composition));
        const SamplingMap b = buildFociMap(foci, options(1.5, composition));
        ASSERT_EQ(a.nodes().size(), b.nodes().size());
        for (std::size_t k = 0; k < a.nodes().size(); ++k) {
            EXPECT_EQ(a.nodes()[k].x, b.nodes()[k].x);
            EXPECT_EQ(a.nodes()[k].y, b.nodes()[k].y);
        }
    }
}

TEST(Foci, NoFociIsIdentityAndGridSizeFollowsOptions) {
    FociOptions o;
    o.columns = 17;
    o.rows = 9;
    const SamplingMap map = buildFociMap({}, o);
    EXPECT_EQ(map.nodes(), SamplingMap::identity(17, 9).nodes());
    const SamplingMap one = buildFociMap(std::vector<Focus>{{0.5, 0.5, 0.2, 2}}, o);
    EXPECT_EQ(one.columns(), 17);
    EXPECT_EQ(one.rows(), 9);
}

TEST(Foci, RejectsBadFoci) {
    auto code = [](Focus f, FociOptions o = {}) {
        try {
            buildFociMap(std::vector<Focus>{f}, o);
        } catch (const Error& e) {
            return e.code();
        }
        return ErrorCode::Unsupported;  // "accepted"
    };
    EXPECT_EQ(code({1.2, 0.5, 0.1, 2}), ErrorCode::InvalidArgument);
    EXPECT_EQ(code({0.5, -0.1, 0.1, 2}), ErrorCode::InvalidArgument);
    EXPECT_EQ(code({0.5, 0.5, 0.0, 2}), ErrorCode::InvalidArgument);
    EXPECT_EQ(code({0.5, 0.5, 1.5, 2}), ErrorCode::InvalidArgument);
    EXPECT_EQ(code({0.5, 0.5, 1.0, 2}), ErrorCode::Unsupported);  // the widest focus: the image's width
    EXPECT_EQ(code({0.5, 0.5, 0.1, 0.5}), ErrorCode::InvalidArgument);
    EXPECT_EQ(code({0.5, 0.5, 0.1, map_rules::kMaxMagnification + 1}), ErrorCode::InvalidArgument);
    EXPECT_EQ(code({0.5, std::nan(""), 0.1, 2}), ErrorCode::InvalidArgument);
    FociOptions o;
    o.aspect = 0;
    EXPECT_EQ(code({0.5, 0.5, 0.1, 2}, o), ErrorCode::InvalidArgument);
    for (double width : {1.0, 0.5, 8.5, std::nan("")}) {
        FociOptions bad;
        bad.falloff.width = width;
        EXPECT_EQ(code({0.5, 0.5, 0.1, 2}, bad), ErrorCode::InvalidArgument) << width;
    }
}

TEST(Foci, ParseFalloffAndRecordIt) {
    EXPECT_EQ(parseFalloff("2").width, 2.0);
    EXPECT_EQ(parseFalloff("2").shape, FociFalloffShape::Density);
    EXPECT_EQ(parseFalloff("1.5,log").shape, FociFalloffShape::LogDensity);
    EXPECT_EQ(parseFalloff("3,logr").shape, FociFalloffShape::LogRadius);
    EXPECT_EQ(parseFalloff("3,logr").width, 3.0);
    for (const FociFalloff& f : kFalloffs) {
        EXPECT_EQ(parseFalloff(falloffText(f)).width, f.width);
        EXPECT_EQ(parseFalloff(falloffText(f)).shape, f.shape);
    }
    for (const char* text : {"", "x", "1", "9", "nan", "2,", "2,cubic", "2x", "1.5,log,3"}) {
        try {
            parseFalloff(text);
            ADD_FAILURE() << "accepted \"" << text << '"';
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
    }
    // The file records a falloff other than the format's r..2r (so the map can be rebuilt), and only
    // then: the default (1.25) is recorded.
    const std::vector<Focus> foci{{0.5, 0.5, 0.1, 3}};
    EXPECT_TRUE(toAnalytic(foci, FociComposition::Density, kFormatFalloff).scalars.empty());
    EXPECT_EQ(toAnalytic(foci, FociComposition::Density).scalars.at("falloffWidth"), 1.25);
    EXPECT_EQ(toAnalytic(foci, FociComposition::Density).scalars.at("falloffShape"), 0.0);
    const format::AnalyticMap a = toAnalytic(foci, FociComposition::Density, {1.5, FociFalloffShape::LogRadius});
    EXPECT_EQ(a.scalars.at("falloffWidth"), 1.5);
    EXPECT_EQ(a.scalars.at("falloffShape"), 2.0);
}

TEST(Foci, AGridTooCoarseForAFocusIsRefinedOrRefusedNamingOneThatHoldsIt) {
    const std::vector<Focus> foci{{0.5, 0.5, 0.1, 4}};
    FociOptions options;
    options.columns = options.rows = 2;  // always the identity: the focus would be recorded, not made
    // The default builder refines the grid itself, and says so.
    FociReport report;
    const SamplingMap refined = buildFociMap(foci, options, &report);
    EXPECT_GT(refined.columns(), 2);
    EXPECT_GT(reachedMagnification(refined, foci)[0], 3.25);
    ASSERT_FALSE(report.notes.empty());
    EXPECT_NE(report.notes.front().find("grid refined from 2x2 to"), std::string::npos) << report.notes.front();
    EXPECT_NO_THROW(checkFociHeld(refined, foci, options));
    // Moser's flow builds what it is asked for, so checkFociHeld refuses its coarse map.
    options.builder = DensityBuilder::Flow;
    const SamplingMap coarse = buildFociMap(foci, options);
    EXPECT_NEAR(reachedMagnification(coarse, foci)[0], 1.0, 1e-9);
    try {
        checkFociHeld(coarse, foci, options);
        FAIL() << "accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
        EXPECT_NE(std::string(e.what()).find("a 2x2 grid is too coarse for focus 0.5,0.5,0.1,4"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("9 nodes a side"), std::string::npos) << e.what();  // the narrow default ring
    }
    options.columns = options.rows = map_rules::kDefaultSide;
    const SamplingMap fine = buildFociMap(foci, options);
    EXPECT_GT(reachedMagnification(fine, foci)[0], 3.5);
    EXPECT_NO_THROW(checkFociHeld(fine, foci, options));
}

TEST(Foci, ParseFocus) {
    const Focus f = parseFocus("0.42,0.31,0.08,4");
    EXPECT_DOUBLE_EQ(f.u, 0.42);
    EXPECT_DOUBLE_EQ(f.v, 0.31);
    EXPECT_DOUBLE_EQ(f.r, 0.08);
    EXPECT_DOUBLE_EQ(f.k, 4);
    EXPECT_DOUBLE_EQ(parseFocus(" 0, 1 ,1, 64").k, 64);
    auto message = [](const std::string& text) -> std::string {
        try {
            parseFocus(text);
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
            return e.what();
        }
        return "accepted";
    };
    // Each refused text with what its message must say.
    const std::pair<const char*, const char*> refused[] = {
        {"0.4,0.3,0.1", "expected u,v,r,k"}, {"0.4,0.3,0.1,2,5", "has 5 values"}, {"", "values"},
        {"0.4,abc,0.1,2", "v = \"abc\""}, {"0.4,0.3,,2", "r = \"\""},
        {"0.4,0.3,0.1,2x", "not a finite number"}, {"0.4,0.3,0.1,nan", "not a finite number"},
        {"1.5,0.3,0.1,2", "outside [0,1]^2"}, {"0.5,0.3,0,2", "radius"}, {"0.5,0.3,1.5,2", "radius"},
        {"0.5,0.3,0.1,0.9", "magnification"}, {"0.5,0.3,0.1,100", "magnification"}};
    for (const auto& [text, says] : refused) EXPECT_NE(message(text).find(says), std::string::npos) << '"' << text << '"';
}

}  // namespace
}  // namespace conus::codec

namespace conus::codec {
namespace {

// The most important region: the square around what is at or above half the peak, measured in the
// pixels of the image it is for (here 2:1, the importance map 40x10), centred on that region.
TEST(Foci, TheHottestRegionIsTheSquareAroundHalfThePeak) {
    Image importance = makeImage(40, 10, {"Y"});
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 40; ++x) importance.at(x, y) = 0.1f;
    for (int y = 2; y < 6; ++y)
        for (int x = 24; x < 32; ++x) importance.at(x, y) = (x == 30 && y == 3) ? 2.0f : 1.2f;
    const Focus hot = hottestRegion(importance, 800, 400);
    EXPECT_DOUBLE_EQ(hot.u, 28.0 / 40);
    EXPECT_DOUBLE_EQ(hot.v, 4.0 / 10);
    // 8 of 40 columns of 800 px = 160 px wide, 4 of 10 rows of 400 px = 160 px tall: half 80 px.
    EXPECT_DOUBLE_EQ(hot.r, 80.0 / 800);
    EXPECT_EQ(hot.k, 1.0);
    // Nothing important: the centre; a single hot pixel: at least 8 pixels.
    const Focus none = hottestRegion(makeImage(4, 4, {"Y"}), 100, 100);
    EXPECT_EQ(none.u, 0.5);
    EXPECT_EQ(none.r, 0.1);
    Image dot = makeImage(100, 100, {"Y"});
    dot.at(10, 90) = 1.0f;
    EXPECT_DOUBLE_EQ(hottestRegion(dot, 100, 100).r, 8.0 / 100);
}

}  // namespace
}  // namespace conus::codec
