// Mass-spring brush system: convergence, determinism, magnification under a stroke, validity
// under adversarial strokes, resampling, stroke files.
#include "conus/codec/builders/springs.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <random>

#include "conus/codec/builders/compose.h"
#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "conus/core/error.h"
#include "codec/builders/valid_map.h"

namespace conus::codec {
namespace {

using test::expectValid;

void expectValidPositions(const SpringSystem& system) {
    const std::vector<glm::vec2> p = system.positions();
    ASSERT_TRUE(map_rules::isValidGrid(system.columns(), system.rows(), p));
    format::GridNodes grid{system.columns(), system.rows(), {}};
    for (const glm::vec2& q : p) grid.xy.insert(grid.xy.end(), {q.x, q.y});
    const format::ValidationReport report = format::validateGrid(grid);
    EXPECT_TRUE(report.ok()) << report.str();
}

TEST(Springs, IdentityIsAtRest) {
    SpringSystem system(33, 17);
    EXPECT_TRUE(system.stable());
    system.step(10);
    EXPECT_TRUE(system.stable());
    const SamplingMap map = system.toMap();
    const SamplingMap identity = SamplingMap::identity(33, 17);
    for (std::size_t k = 0; k < map.nodes().size(); ++k) {
        EXPECT_NEAR(map.nodes()[k].x, identity.nodes()[k].x, 1e-6);
        EXPECT_NEAR(map.nodes()[k].y, identity.nodes()[k].y, 1e-6);
    }
}

TEST(Springs, StrokeConvergesAndMagnifies) {
    SpringSystem system(129, 129);
    system.addStroke({0.5, 0.5, 0.2, 1.0, 0.5});
    EXPECT_FALSE(system.stable());
    const int steps = system.runUntilStable(20000);
    EXPECT_LT(steps, 20000);
    EXPECT_TRUE(system.stable());
    std::printf("129x129 one stroke: stable after %d steps (%.2f simulated s), %d held back\n", steps, system.time(),
                system.heldBack());
    const SamplingMap map = system.toMap();
    expectValid(map);
    EXPECT_GT(map.density({0.5, 0.5}), 1.5);
    EXPECT_LT(map.density({0.05, 0.05}), 1.0);  // paid for by the context
    // The centre of a centred stroke stays put by symmetry.
    EXPECT_NEAR(map.distort({0.5, 0.5}).x, 0.5, 1e-4);
    EXPECT_NEAR(map.distort({0.5, 0.5}).y, 0.5, 1e-4);
}

TEST(Springs, OffCentreStrokeMagnifiesItsCentre) {
    SpringSystem system(map_rules::kDefaultSide, map_rules::kDefaultSide);
    system.addStroke({0.3, 0.7, 0.15, 1.5, 0.2});
    system.runUntilStable(20000);
    const SamplingMap map = system.toMap();
    expectValid(map);
    EXPECT_GT(map.density({0.3, 0.7}), 1.5);
}

TEST(Springs, Deterministic) {
    auto run = [] {
        SpringSystem system(64, 48);
        system.addStroke({0.4, 0.5, 0.2, 2.0, 0.3});
        system.step(50);
        system.addStroke({0.7, 0.3, 0.1, 3.0, 0.1});
        system.runUntilStable(5000);
        return system.positions();
    };
    const auto a = run(), b = run();
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec2)));
}

TEST(Springs, AdversarialStrokesStayValid) {
    const std::vector<std::vector<Stroke>> cases{
        {{0.5, 0.5, 0.1, 1000.0, 0.0}},                             // huge, instant
        {{0.5, 0.5, 0.004, 1000.0, 0.1}},                           // tiny radius
        {{0.0, 0.0, 0.3, 500.0, 0.05}, {1.0, 1.0, 0.3, 500.0, 0.05}},  // corners
        {{0.5, 0.0, 0.2, 200.0, 0.05}, {0.0, 0.5, 0.2, 200.0, 0.05}, {1.0, 0.5, 0.05, 200.0, 0.0}},  // edges
        {{0.5, 0.5, 2.0, 1000.0, 0.0}},                             // covers everything
    };
    int guarded = 0;  // steps in which the guard held particles back
    for (const auto& strokes : cases) {
        SpringSystem system(48, 40);
        for (const Stroke& s : strokes) system.addStroke(s);
        for (int round = 0; round < 200; ++round) {
            system.step();
            guarded += system.heldBack() > 0;
            if (round % 25 == 0) expectValidPositions(system);
        }
        expectValid(system.toMap());
        expectValid(system.toMap(9, 7));
    }
    EXPECT_GT(guarded, 0);  // these strokes do try to fold cells
}

TEST(Springs, ManyOverlappingAndRandomStrokes) {
    for (unsigned seed : {1u, 2u, 3u}) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        SpringSystem system(40, 40);
        for (int s = 0; s < 30; ++s) {
            system.addStroke({unit(rng), unit(rng), 0.01 + 0.3 * unit(rng), 50.0 * unit(rng) * unit(rng), 0.2 * unit(rng)});
            if (s % 3 == 0) system.step(5);
        }
        for (int i = 0; i < 10; ++i) {
            system.step(30);
            expectValidPositions(system);
        }
        expectValid(system.toMap());
        expectValid(system.toMap(17, 11));
    }
    SpringSystem same(40, 40);
    for (int s = 0; s < 20; ++s) same.addStroke({0.5, 0.5, 0.1, 5.0, 0.1});
    same.runUntilStable(3000);
    expectValidPositions(same);
}

TEST(Springs, LowerResolutionMapIsValid) {
    SpringSystem system(map_rules::kDefaultSide, map_rules::kDefaultSide);
    system.addStroke({0.35, 0.4, 0.2, 2.0, 0.2});
    system.addStroke({0.7, 0.7, 0.1, 1.0, 0.2});
    system.runUntilStable(20000);
    const SamplingMap full = system.toMap();
    for (int side : {33, 17, 9, 2}) {
        double scale = 0;
        const SamplingMap coarse = system.toMap(side, side, &scale);
        expectValid(coarse);
        EXPECT_GT(scale, 0.0);
        if (side == 33) {
            EXPECT_EQ(scale, 1.0);
            // Every other particle: the same positions.
            EXPECT_EQ(coarse.node(10, 12), full.node(20, 24));
        }
    }
    // A finer grid than the particles is also fine.
    expectValid(system.toMap(100, 80));
}

TEST(Springs, RejectsBadInput) {
    EXPECT_THROW(SpringSystem(1, 10), Error);
    SpringOptions bad;
    bad.stiffness = -1;
    EXPECT_THROW(SpringSystem(10, 10, bad), Error);
    SpringSystem system(10, 10);
    EXPECT_THROW(system.addStroke({1.5, 0.5, 0.1, 1, 0.1}), Error);
    EXPECT_THROW(system.addStroke({0.5, 0.5, 0.0, 1, 0.1}), Error);
    EXPECT_THROW(system.addStroke({0.5, 0.5, 0.1, std::nan(""), 0.1}), Error);
    EXPECT_THROW(system.addStroke({0.5, 0.5, 0.1, 1, -1}), Error);
}

TEST(Springs, ParseStrokes) {
    const auto strokes = parseStrokes(R"([{"u":0.3,"v":0.4,"radius":0.1,"strength":1.0,"duration":0.5},
                                          {"u":1,"v":0,"radius":0.2,"strength":2}])");
    ASSERT_EQ(strokes.size(), 2u);
    EXPECT_DOUBLE_EQ(strokes[0].u, 0.3);
    EXPECT_DOUBLE_EQ(strokes[0].v, 0.4);
    EXPECT_DOUBLE_EQ(strokes[0].radius, 0.1);
    EXPECT_DOUBLE_EQ(strokes[0].strength, 1.0);
    EXPECT_DOUBLE_EQ(strokes[0].duration, 0.5);
    EXPECT_DOUBLE_EQ(strokes[1].duration, 0.5);  // default
    EXPECT_TRUE(parseStrokes("[]").empty());
}

void expectParseError(const std::string& text, const std::string& fragment) {
    try {
        parseStrokes(text);
        ADD_FAILURE() << "no error for " << text;
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(Springs, ParseStrokesErrors) {
    expectParseError("[{\"u\":0.3,", "bad JSON");
    expectParseError("{\"u\":0.3}", "expected a JSON list");
    expectParseError("[3]", "stroke 0: expected an object");
    expectParseError(R"([{"u":0.3,"v":0.4,"strength":1}])", "stroke 0: missing \"radius\"");
    expectParseError(R"([{"u":0.3,"v":0.4,"radius":0.1,"strength":1},{"u":"a","v":0.4,"radius":0.1,"strength":1}])",
                     "stroke 1: \"u\" must be a number");
    expectParseError(R"([{"u":0.3,"v":0.4,"radius":0.1,"strength":1,"strenght":2}])", "unknown key \"strenght\"");
    expectParseError(R"([{"u":1.3,"v":0.4,"radius":0.1,"strength":1}])", "stroke 0: u = 1.3 is outside [0, 1]");
    expectParseError(R"([{"u":0.3,"v":0.4,"radius":0.1,"strength":-1}])", "strength = -1");
    expectParseError(R"([{"u":0.3,"v":0.4,"radius":0.1,"strength":1,"duration":-2}])", "duration = -2");
}

}  // namespace
}  // namespace conus::codec

namespace conus::codec {
namespace {

// runUntilStable's coarse-to-fine warm start and longer relaxation steps reach the equilibrium of
// plain stepping (within a small fraction of a spacing), in far fewer steps, bit for bit the same
// every time, and through valid maps only.
TEST(Springs, MultilevelMatchesPlainStepping) {
    const std::vector<Stroke> strokes{{0.35, 0.4, 0.15, 1.5, 0.3}, {0.65, 0.6, 0.1, 1.0, 0.3}, {0.5, 0.8, 0.08, 2.0, 0.2}};
    auto run = [&](bool multilevel, int* steps, double* work) {
        SpringOptions o;
        o.multilevel = multilevel;
        SpringSystem system(129, 129, o);
        for (const Stroke& s : strokes) system.addStroke(s);
        *steps = system.runUntilStable(20000);
        *work = system.warmStartWork();
        EXPECT_TRUE(system.stable());
        expectValidPositions(system);
        return system.positions();
    };
    int plainSteps = 0, fastSteps = 0, againSteps = 0;
    double plainWork = 0, fastWork = 0, againWork = 0;
    const auto plain = run(false, &plainSteps, &plainWork);
    const auto fast = run(true, &fastSteps, &fastWork);
    const auto again = run(true, &againSteps, &againWork);
    double worst = 0;
    for (std::size_t k = 0; k < plain.size(); ++k) worst = std::max(worst, double(glm::length(plain[k] - fast[k])));
    worst *= 128.0;  // in spacings
    std::printf("129x129 three strokes: plain %d steps, multilevel %d + %.1f (warm start) steps, max difference %.4f spacings\n",
                plainSteps, fastSteps, fastWork, worst);
    EXPECT_EQ(plainWork, 0.0);
    EXPECT_LT(worst, 0.05);
    EXPECT_LT(fastSteps + fastWork, 0.5 * plainSteps);
    ASSERT_EQ(fast.size(), again.size());
    EXPECT_EQ(fastSteps, againSteps);
    EXPECT_EQ(0, std::memcmp(fast.data(), again.data(), fast.size() * sizeof(glm::vec2)));
}

// The viewer's use: strokes added between runs and steps; the warm start only happens once per
// new stroke, and stepping afterwards stays at the equilibrium.
TEST(Springs, MultilevelAfterSteppingAndNewStrokes) {
    SpringSystem system(96, 80);
    system.addStroke({0.4, 0.5, 0.2, 1.0, 0.3});
    system.step(10);
    system.runUntilStable(20000);
    EXPECT_TRUE(system.stable());
    const double work = system.warmStartWork();
    EXPECT_GT(work, 0.0);
    EXPECT_EQ(system.runUntilStable(20000), 0);  // already stable, no new warm start
    EXPECT_EQ(system.warmStartWork(), work);
    system.addStroke({0.7, 0.3, 0.1, 2.0, 0.1});
    system.runUntilStable(20000);
    EXPECT_TRUE(system.stable());
    EXPECT_GT(system.warmStartWork(), work);
    const auto before = system.positions();
    system.step(20);
    const auto after = system.positions();
    double moved = 0;
    for (std::size_t k = 0; k < before.size(); ++k) moved = std::max(moved, double(glm::length(before[k] - after[k])));
    EXPECT_LT(moved * 95.0, 0.01);
    expectValidPositions(system);
}

}  // namespace
}  // namespace conus::codec
