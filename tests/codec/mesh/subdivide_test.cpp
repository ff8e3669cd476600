// Edge subdivision: the longest projected edge ends at or under the bound, the surface is the same
// surface (closed stays closed: no cracks or T-junctions; same volume and area; same render),
// attributes interpolate linearly, and the caps hold.
#include "conus/codec/mesh/subdivide.h"

#include <gtest/gtest.h>

#include <map>

#include "codec/mesh/mesh_test_scenes.h"
#include "conus/codec/mesh/raycast.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"

namespace conus::codec {
namespace {

using namespace test;

Camera boxCamera() { return Camera::perspective({2.0, 1.5, 3.0}, {0, 0, 0}, {0, 1, 0}, 50, 1.5, 0.1, 100); }

// Each directed edge once, and its reverse once: a closed, consistently wound surface without
// cracks or T-junctions (a T-junction leaves a directed edge whose reverse is missing).
void expectClosed(const Mesh& mesh) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) ++directed[{mesh.indices[t + e], mesh.indices[t + (e + 1) % 3]}];
    int bad = 0;
    for (const auto& [edge, count] : directed) {
        const auto reverse = directed.find({edge.second, edge.first});
        if (count != 1 || reverse == directed.end() || reverse->second != 1) ++bad;
    }
    EXPECT_EQ(bad, 0) << "edges without exactly one opposite partner";
}

double signedVolume(const Mesh& m) {
    double v = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3)
        v += glm::dot(glm::dvec3(m.positions[m.indices[t]]),
                      glm::cross(glm::dvec3(m.positions[m.indices[t + 1]]), glm::dvec3(m.positions[m.indices[t + 2]]))) / 6;
    return v;
}

double area(const Mesh& m) {
    double a = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const glm::dvec3 p0 = m.positions[m.indices[t]], p1 = m.positions[m.indices[t + 1]], p2 = m.positions[m.indices[t + 2]];
        a += glm::length(glm::cross(p1 - p0, p2 - p0)) / 2;
    }
    return a;
}

TEST(Subdivide, ABoxUntilEveryEdgeIsShort) {
    const Mesh box = sharedBox({-1, -0.5f, -0.7f}, {0.8f, 0.6f, 0.9f});
    const SamplingMap map = SamplingMap::identity(map_rules::kDefaultSide, 33);  // wider than tall: not square
    const Camera camera = boxCamera();
    const double before = longestProjectedEdge(box, camera, map);
    EXPECT_GT(before, 10);
    for (double maxEdge : {4.0, 1.0, 0.5}) {
        SCOPED_TRACE(maxEdge);
        const Mesh fine = subdivideForMap(box, camera, map, maxEdge);
        EXPECT_LE(longestProjectedEdge(fine, camera, map), maxEdge);
        EXPECT_GT(fine.triangleCount(), box.triangleCount());
        expectClosed(fine);
        EXPECT_NEAR(signedVolume(fine), 1.8 * 1.1 * 1.6, 1e-4);
        EXPECT_NEAR(area(fine), area(box), 1e-4);
        ASSERT_EQ(fine.normals.size(), fine.positions.size());
        for (std::size_t i = 0; i < fine.positions.size(); ++i) {
            const glm::vec3 p = fine.positions[i];
            // On the box's surface: one coordinate on a face.
            const bool onFace = std::abs(p.x + 1) < 1e-6f || std::abs(p.x - 0.8f) < 1e-6f || std::abs(p.y + 0.5f) < 1e-6f ||
                                std::abs(p.y - 0.6f) < 1e-6f || std::abs(p.z + 0.7f) < 1e-6f || std::abs(p.z - 0.9f) < 1e-6f;
            EXPECT_TRUE(onFace) << i;
            EXPECT_NEAR(glm::length(fine.normals[i]), 1.0f, 1e-5f);
        }
    }
    // A finer bound takes more triangles.
    EXPECT_GT(subdivideForMap(box, camera, map, 0.5).triangleCount(), subdivideForMap(box, camera, map, 1.0).triangleCount());
    // Already short enough: unchanged.
    const Mesh same = subdivideForMap(box, camera, map, before + 1);
    EXPECT_EQ(same.indices, box.indices);
}

TEST(Subdivide, AttributesInterpolateLinearly) {
    Mesh sphere = uvSphere({0, 0, 0}, 1.0f, 8, 16);
    // Colours and UVs that are linear functions of position stay so at every new vertex.
    auto colourOf = [](glm::vec3 p) { return glm::vec3(0.5f) + 0.25f * p; };
    auto uvOf = [](glm::vec3 p) { return glm::vec2(0.3f * p.x + 0.5f, 0.2f * p.z - 0.1f * p.y + 0.5f); };
    for (const glm::vec3& p : sphere.positions) {
        sphere.colours.push_back(colourOf(p));
        sphere.uvs.push_back(uvOf(p));
    }
    const Camera camera = Camera::perspective({0, 0.5, 3}, {0, 0, 0}, {0, 1, 0}, 45, 1.0, 0.1, 10);
    const Mesh fine = subdivideForMap(sphere, camera, SamplingMap::identity(33, 33), 0.75);
    ASSERT_GT(fine.positions.size(), sphere.positions.size() * 3);
    ASSERT_EQ(fine.colours.size(), fine.positions.size());
    ASSERT_EQ(fine.uvs.size(), fine.positions.size());
    for (std::size_t i = 0; i < fine.positions.size(); ++i) {
        EXPECT_LT(glm::length(fine.colours[i] - colourOf(fine.positions[i])), 1e-5f) << i;
        EXPECT_LT(glm::length(fine.uvs[i] - uvOf(fine.positions[i])), 1e-5f) << i;
    }
    expectClosed(fine);
}

TEST(Subdivide, TheRenderIsTheSameSurface) {
    const Mesh box = flatBox({-1, -0.5f, -0.7f}, {0.8f, 0.6f, 0.9f});
    const Camera camera = boxCamera();
    const Fpc fpc(camera, focusMap(0.45, 0.5, 0.15, 3, 1.5));
    const auto& map = static_cast<const SamplingMap&>(*fpc.distortion());
    const Image coarse = renderMeshReference(MeshScene(box), fpc, 90, 60);
    const Image fine = renderMeshReference(MeshScene(subdivideForMap(box, camera, map, 0.5)), fpc, 90, 60);
    int differ = 0;
    for (std::size_t i = 0; i < coarse.pixels.size(); ++i)
        if (std::abs(coarse.pixels[i] - fine.pixels[i]) > 1e-4f * std::max(1.0f, std::abs(coarse.pixels[i]))) ++differ;
    EXPECT_LE(differ, 5) << "only rays through an edge may land on the other side";
}

TEST(Subdivide, EdgesBehindTheEyeAreNotMeasured) {
    // A long strip from in front of the eye to behind it.
    Mesh strip;
    strip.positions = {{-1, -1, -5}, {1, -1, -5}, {1, -1, 5}, {-1, -1, 5}};
    strip.indices = {0, 2, 1, 0, 3, 2};
    const Camera camera = Camera::perspective({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 60, 1.0, 0.1, 100);
    const SamplingMap map = SamplingMap::identity(17, 17);
    const double front = longestProjectedEdge(strip, camera, map);
    EXPECT_GT(front, 0);  // the edge across the far end is measured
    const Mesh fine = subdivideForMap(strip, camera, map, 0.5);
    EXPECT_LE(longestProjectedEdge(fine, camera, map), 0.5);
    EXPECT_GT(fine.triangleCount(), 2u);
}

TEST(Subdivide, CapsAndBadArguments) {
    const Mesh box = sharedBox({-1, -1, -1}, {1, 1, 1});
    const SamplingMap map = SamplingMap::identity(map_rules::kDefaultSide, map_rules::kDefaultSide);
    const Camera camera = boxCamera();
    SubdivideOptions few;
    few.maxTriangles = 100;
    try {
        subdivideForMap(box, camera, map, 0.1, few);
        FAIL() << "passed the cap";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << e.what();
    }
    for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) EXPECT_THROW(subdivideForMap(box, camera, map, bad), Error) << bad;
    EXPECT_THROW(subdivideForMap(Mesh{}, camera, map, 1.0), Error);
}

}  // namespace
}  // namespace conus::codec
