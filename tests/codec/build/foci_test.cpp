// Foci: target density, single-focus magnification, both compositions, parsing.
#include "conus/codec/build/foci.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <utility>

#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

void expectValid(const SamplingMap& map) {
    const format::ValidationReport report = format::validateGrid(map.toGrid());
    EXPECT_TRUE(report.ok()) << report.str();
}

FociOptions options(double aspect, FociComposition composition = FociComposition::Density) {
    FociOptions o;
    o.aspect = aspect;
    o.composition = composition;
    return o;
}

TEST(Foci, DensityProfile) {
    const Focus f{0.4, 0.5, 0.1, 4};
    const std::vector<Focus> foci{f};
    for (double aspect : {1.0, 16.0 / 9.0, 0.5}) {
        EXPECT_DOUBLE_EQ(fociDensity(foci, aspect, 0.4, 0.5), 16.0);
        // The disc is circular in pixels: radius r in u, r * aspect in v.
        EXPECT_DOUBLE_EQ(fociDensity(foci, aspect, 0.4 + 0.1, 0.5), 16.0);
        EXPECT_NEAR(fociDensity(foci, aspect, 0.4, 0.5 + 0.1 * aspect), 16.0, 1e-9);
        EXPECT_NEAR(fociDensity(foci, aspect, 0.4, 0.5 + 0.2 * aspect), 1.0, 1e-9);
        EXPECT_DOUBLE_EQ(fociDensity(foci, aspect, 0.4 + 0.25, 0.5), 1.0);
        // Half way through the falloff the quintic smoothstep is 1/2.
        EXPECT_NEAR(fociDensity(foci, aspect, 0.4 + 0.15, 0.5), 1.0 + 15.0 * 0.5, 1e-9);
    }
    EXPECT_DOUBLE_EQ(fociDensity({}, 1.0, 0.3, 0.3), 1.0);
    // Several foci: the max of their densities.
    const std::vector<Focus> two{{0.3, 0.5, 0.1, 2}, {0.32, 0.5, 0.1, 3}};
    EXPECT_DOUBLE_EQ(fociDensity(two, 1.0, 0.31, 0.5), 9.0);
}

TEST(Foci, SingleFocusMagnification) {
    for (double k : {2.0, 4.0}) {
        for (double aspect : {1.0, 16.0 / 9.0}) {
            const Focus f{0.45, 0.55, 0.1, k};
            const SamplingMap map = buildFociMap(std::vector<Focus>{f}, options(aspect));
            expectValid(map);
            const double centre = map.density({f.u, f.v});
            const double far = map.density({0.95, 0.05});
            EXPECT_NEAR(centre / far, k * k, k * k * 0.15) << "k " << k << " aspect " << aspect;
        }
        // Circular in pixels: about the same linear magnification along u and along v (a small
        // focus, so the image border does not shape it).
        const Focus small{0.5, 0.5, 0.04, k};
        const SamplingMap map = buildFociMap(std::vector<Focus>{small}, options(16.0 / 9.0));
        const glm::dmat2 j = map.jacobian({small.u, small.v});
        EXPECT_NEAR(glm::length(j[0]), glm::length(j[1]), 0.06 * glm::length(j[0])) << "k " << k;
    }
}

TEST(Foci, NearbyFociKeepTheirMagnification) {
    // The context squeezed between two foci shears under Moser's flow and folds on a 65x65 grid.
    // Repairing the fold locally left steps (issue 10), so the builder tempers the density: the
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
    for (const auto& foci : cases) {
        for (auto composition : {FociComposition::Density, FociComposition::Add}) {
            for (double aspect : {1.0, 2.0}) {
                const SamplingMap map = buildFociMap(foci, options(aspect, composition));
                expectValid(map);
                EXPECT_EQ(map.columns(), map_rules::kDefaultSide);
                // Magnifies at the first focus.
                EXPECT_GT(map.density({foci[0].u, foci[0].v}), 1.0);
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
    EXPECT_EQ(code({0.5, 0.5, 0.1, 0.5}), ErrorCode::InvalidArgument);
    EXPECT_EQ(code({0.5, 0.5, 0.1, map_rules::kMaxMagnification + 1}), ErrorCode::InvalidArgument);
    EXPECT_EQ(code({0.5, std::nan(""), 0.1, 2}), ErrorCode::InvalidArgument);
    FociOptions o;
    o.aspect = 0;
    EXPECT_EQ(code({0.5, 0.5, 0.1, 2}, o), ErrorCode::InvalidArgument);
}

TEST(Foci, AGridTooCoarseForAFocusIsRefusedNamingOneThatHoldsIt) {
    const std::vector<Focus> foci{{0.5, 0.5, 0.1, 4}};
    FociOptions options;
    options.columns = options.rows = 2;  // always the identity: the focus would be recorded, not made
    const SamplingMap coarse = buildFociMap(foci, options);
    EXPECT_NEAR(reachedMagnification(coarse, foci)[0], 1.0, 1e-9);
    try {
        checkFociHeld(coarse, foci, options);
        FAIL() << "accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
        EXPECT_NE(std::string(e.what()).find("a 2x2 grid is too coarse for focus 0.5,0.5,0.1,4"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("5 nodes a side"), std::string::npos) << e.what();
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
