// meshOverdraw: the surfaces a mesh stacks over a region, whatever the view, against what
// geometry says of simple meshes (a square stack, a box, a sphere, a height field), and the
// refusal of overlapping copies however they are placed in a larger scene.
#include "conus/codec/mesh/overdraw.h"

#include <gtest/gtest.h>

#include "codec/mesh/mesh_test_scenes.h"
#include "conus/core/error.h"
#include "conus/core/limits.h"

namespace conus::codec::test {
namespace {

// `copies` squares of side `side` at (x, y), stacked `gap` apart along z.
void addSquares(Mesh& m, int copies, float side, float x, float y, float gap) {
    for (int i = 0; i < copies; ++i) {
        const float z = -gap * float(i);
        const auto first = static_cast<std::uint32_t>(m.positions.size());
        for (const glm::vec3 p : {glm::vec3(x, y, z), glm::vec3(x + side, y, z), glm::vec3(x + side, y + side, z), glm::vec3(x, y + side, z)})
            m.positions.push_back(p);
        for (const std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(first + k);
    }
}

Mesh squares(int copies, float gap) {
    Mesh m;
    addSquares(m, copies, 2.0f, -1.0f, -1.0f, gap);
    return m;
}

// A w x h grid of unit cells, two triangles each, its heights a gentle asymmetric bump.
Mesh heightField(int w, int h) {
    Mesh m;
    for (int j = 0; j <= h; ++j)
        for (int i = 0; i <= w; ++i)
            m.positions.emplace_back(float(i), 0.3f * std::sin(0.21f * float(i)) * std::cos(0.13f * float(j)), float(j));
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const auto at = [&](int a, int b) { return std::uint32_t(b * (w + 1) + a); };
            for (const std::uint32_t k : {at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)})
                m.indices.push_back(k);
        }
    return m;
}

TEST(MeshOverdraw, CountsTheSurfacesStackedAlongTheWorstDirection) {
    // Squares stacked along z: each covers the whole shadow once, however far apart they lie
    // (a rasterizer pays for each wherever it is along the view).
    EXPECT_NEAR(meshOverdraw(squares(1, 0.01f)), 1.0, 1e-9);
    EXPECT_NEAR(meshOverdraw(squares(40, 0.01f)), 40.0, 1e-9);
    EXPECT_NEAR(meshOverdraw(squares(40, 1.0f)), 40.0, 1e-9);
    // A cube: two faces over each point of its shadow along an axis.
    EXPECT_NEAR(meshOverdraw(sharedBox({-1, -1, -1}, {1, 1, 1})), 2.0, 1e-9);
    // A closed sphere: about two surfaces wherever it is seen, however finely tessellated.
    const double coarse = meshOverdraw(uvSphere({0.3f, -0.2f, 1}, 1.5f, 24, 48));
    const double fine = meshOverdraw(uvSphere({0.3f, -0.2f, 1}, 1.5f, 96, 192));
    EXPECT_GT(fine, 1.5);
    EXPECT_LT(fine, 3.0);
    EXPECT_NEAR(fine, coarse, 0.5);
    // A height field is one surface from above, but seen level along x a line through it
    // crosses each bump of sin(0.21 x) twice: 2 x 200 x 0.21 / (2 pi) = 13.4 surfaces.
    EXPECT_NEAR(meshOverdraw(heightField(200, 120)), 2 * 200 * 0.21 / (2 * 3.14159265), 1.5);
}

TEST(MeshOverdraw, OverlappingCopiesAreRefusedWhereverTheyLieInTheScene) {
    const std::string what = "test render";
    EXPECT_NO_THROW(checkMeshOverdraw(squares(kMaxMeshOverlap / 2, 0.01f), what));
    try {
        checkMeshOverdraw(squares(2 * kMaxMeshOverlap, 0.01f), what);
        ADD_FAILURE() << "not refused";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
        EXPECT_NE(std::string(e.what()).find("test render: "), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("limit meshOverlap"), std::string::npos) << e.what();
    }
    // A stack of small copies in a large scene (a height field 100 times its size around it),
    // spread along the view by more than their size: counted on the grid of their own size.
    Mesh scene = heightField(200, 200);
    addSquares(scene, 2 * kMaxMeshOverlap, 0.5f, 37.3f, 5.0f, 0.7f);
    EXPECT_NEAR(meshOverdraw(scene), 2.0 * kMaxMeshOverlap, 1.0);
    EXPECT_THROW(checkMeshOverdraw(scene, what), Error);
    // Copies of a triangle that faces none of the 13 directions: seen along the nearest, each
    // still fills about half its box, and they stack.
    Mesh tilted;
    for (int i = 0; i < 4 * kMaxMeshOverlap; ++i) {
        const auto first = static_cast<std::uint32_t>(tilted.positions.size());
        const float e = 1e-5f * float(i);
        for (const glm::vec3 p : {glm::vec3(e, 0, 0), glm::vec3(1 + e, 0.3f, 0.1f), glm::vec3(0.2f + e, 1, -0.4f)}) tilted.positions.push_back(p);
        for (const std::uint32_t k : {0u, 1u, 2u}) tilted.indices.push_back(first + k);
    }
    EXPECT_GT(meshOverdraw(tilted), 0.4 * 4 * kMaxMeshOverlap);
    EXPECT_THROW(checkMeshOverdraw(tilted, what), Error);
    // One of them: half a surface (a triangle fills half its box).
    Mesh once = tilted;
    once.indices.resize(3);
    EXPECT_LE(meshOverdraw(once), 0.5 + 1e-9);
    EXPECT_GT(meshOverdraw(once), 0.4);
}

}  // namespace
}  // namespace conus::codec::test
