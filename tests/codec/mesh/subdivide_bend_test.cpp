// Subdivision where the map bends, on a map built by hand so that where it is affine is known: the
// left half of the frame is squeezed to 0.8 of its width (affine, not the identity), the right half
// stretched, and a bump around one node of the right half magnifies it. Seen by an orthographic
// camera, a world point (x, y, 0) lies at u = (x + 1) / 2, v = (1 - y) / 2.
#include <gtest/gtest.h>

#include <map>

#include "codec/mesh/mesh_test_scenes.h"
#include "conus/codec/mesh/subdivide.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

using namespace test;

constexpr int kSide = 17, kPixels = 256;
constexpr double kBound = 0.5;

// u of undistorted column position g (0..16): 0.8 g / 16 up to the middle column, then linear to 1.
double column(double g) { return g <= 8 ? 0.05 * g : 0.4 + 0.075 * (g - 8); }

// The 3 x 3 nodes around node (12, 12) move 0.3 of a cell toward it (the bump) when `bump`; columns
// follow column() when `squeeze`.
SamplingMap handMap(bool squeeze, bool bump) {
    std::vector<glm::vec2> nodes;
    for (int j = 0; j < kSide; ++j)
        for (int i = 0; i < kSide; ++i) {
            double gi = i, gj = j;
            if (bump && std::abs(i - 12) <= 1 && std::abs(j - 12) <= 1) gi += 0.3 * (12 - i), gj += 0.3 * (12 - j);
            nodes.emplace_back(squeeze ? column(gi) : gi / 16, gj / 16);
        }
    return SamplingMap(kSide, kSide, std::move(nodes));
}

Camera topCamera() { return Camera::orthographic({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 2.0, 1.0, 1.0, 10.0); }

glm::vec3 at(double u, double v) { return {float(2 * u - 1), float(1 - 2 * v), 0.0f}; }

// Two triangles over the image rectangle [u0, u1] x [v0, v1], sharing a diagonal.
Mesh quad(double u0, double v0, double u1, double v1) {
    Mesh m;
    m.positions = {at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1)};
    m.indices = {0, 3, 2, 0, 2, 1};
    return m;
}

// No T-junction: no vertex lies inside another triangle's edge (a split edge whose new vertex only
// one of its two triangles uses would leave one there).
int tJunctions(const Mesh& m) {
    int found = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) {
            const glm::dvec3 a = m.positions[m.indices[t + e]], b = m.positions[m.indices[t + (e + 1) % 3]];
            for (const glm::vec3& p : m.positions) {
                const glm::dvec3 q(p);
                const double s = glm::dot(q - a, b - a) / glm::dot(b - a, b - a);
                if (s > 1e-6 && s < 1 - 1e-6 && glm::length(a + s * (b - a) - q) < 1e-6 * glm::length(b - a)) ++found;
            }
        }
    return found;
}

TEST(SubdivideBend, AStraightEdgeWhereTheMapIsAffineIsNeverSplit) {
    const SamplingMap map = handMap(true, true);
    // The left half: columns 0..8, squeezed but affine; the quad's edges cross 7 columns and 13 rows of cells.
    const Mesh left = quad(0.03, 0.06, 0.47, 0.88);
    const BendMeasure bend = measureBend(left, topCamera(), map, kPixels, kPixels);
    EXPECT_LT(bend.largest(), 1e-4);  // the nodes are floats
    EXPECT_EQ(subdivideForBend(left, topCamera(), map, kPixels, kPixels, kBound).indices, left.indices);
    // The same quad over the middle column, where the squeeze turns into the stretch, bends.
    const Mesh across = quad(0.3, 0.06, 0.7, 0.3);
    const Mesh fine = subdivideForBend(across, topCamera(), map, kPixels, kPixels, kBound);
    EXPECT_GT(measureBend(across, topCamera(), map, kPixels, kPixels).edges, 1.0);
    EXPECT_GT(fine.triangleCount(), across.triangleCount());
    EXPECT_LE(measureBend(fine, topCamera(), map, kPixels, kPixels).largest(), kBound);
    EXPECT_EQ(tJunctions(fine), 0);
}

TEST(SubdivideBend, AnEdgeAcrossTheBumpsRimIsSplitUntilItFollowsTheMap) {
    const SamplingMap map = handMap(true, true);
    // The bump moves nodes by 0.3 cell on each axis: 0.3 * 0.075 * 256 * sqrt(2) = 8.15 pixels at most,
    // and the quad's corners lie where the map is affine.
    const Mesh rim = quad(0.6, 0.55, 0.95, 0.9);
    const BendMeasure before = measureBend(rim, topCamera(), map, kPixels, kPixels);
    EXPECT_GT(before.edges, 1.0);
    EXPECT_LT(before.largest(), 8.15);
    for (double bound : {2.0, kBound, 0.1}) {
        SCOPED_TRACE(bound);
        const Mesh fine = subdivideForBend(rim, topCamera(), map, kPixels, kPixels, bound);
        EXPECT_LE(measureBend(fine, topCamera(), map, kPixels, kPixels).largest(), bound);
        EXPECT_EQ(tJunctions(fine), 0);
    }
    // A finer bound takes more triangles.
    EXPECT_GT(subdivideForBend(rim, topCamera(), map, kPixels, kPixels, 0.1).triangleCount(),
              subdivideForBend(rim, topCamera(), map, kPixels, kPixels, 2.0).triangleCount());
}

TEST(SubdivideBend, AStraightTriangleAroundTheBumpIsSplitForItsInside) {
    const SamplingMap map = handMap(false, true);  // the identity but for the bump
    // Edges at u = 0.6, v = 0.6 and u + v = 1.8 (through (0.9, 0.9)) all miss the bump's cells
    // (0.625..0.875); two corners lie outside the frame, where the map continues by translation.
    Mesh around;
    around.positions = {at(0.6, 0.6), at(0.6, 1.2), at(1.2, 0.6)};
    around.indices = {0, 1, 2};
    const BendMeasure before = measureBend(around, topCamera(), map, kPixels, kPixels);
    EXPECT_LT(before.edges, 1e-4);
    EXPECT_GT(before.interiors, 4.0);  // the nodes next to the bump's centre moved 0.3 * 16 pixels
    const Mesh fine = subdivideForBend(around, topCamera(), map, kPixels, kPixels, kBound);
    EXPECT_GT(fine.triangleCount(), 4u);
    EXPECT_LE(measureBend(fine, topCamera(), map, kPixels, kPixels).largest(), kBound);
    EXPECT_EQ(tJunctions(fine), 0);
}

// A closed box under a strong focus stays closed: each directed edge has exactly one reverse.
TEST(SubdivideBend, AClosedBoxStaysClosed) {
    const Mesh box = sharedBox({-1, -0.5f, -0.7f}, {0.8f, 0.6f, 0.9f});
    const Camera camera = Camera::perspective({2.0, 1.5, 3.0}, {0, 0, 0}, {0, 1, 0}, 50, 1.5, 0.1, 100);
    const auto map = focusMap(0.45, 0.5, 0.15, 4, 1.5);
    const Mesh fine = subdivideForBend(box, camera, *map, 240, 160, kBound);
    EXPECT_GT(fine.triangleCount(), 4 * box.triangleCount());
    EXPECT_LE(measureBend(fine, camera, *map, 240, 160).largest(), kBound);
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (std::size_t t = 0; t < fine.indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) ++directed[{fine.indices[t + e], fine.indices[t + (e + 1) % 3]}];
    for (const auto& [edge, count] : directed) {
        EXPECT_EQ(count, 1);
        EXPECT_EQ(directed.count({edge.second, edge.first}), 1u) << edge.first << " -> " << edge.second;
    }
    EXPECT_THROW(subdivideForBend(box, camera, *map, 240, 160, 0.0), Error);
    EXPECT_THROW(subdivideForBend(box, camera, *map, 240, 160, std::nan("")), Error);
    SubdivideOptions few;
    few.maxTriangles = 50;
    EXPECT_THROW(subdivideForBend(box, camera, *map, 240, 160, 0.01, few), Error);
}

}  // namespace
}  // namespace conus::codec
