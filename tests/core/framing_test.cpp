// Bounding boxes and framing a box with a camera (bounds.h, camera.h): what the mesh and volume
// commands, the reflection bake and the viewer frame a scene with.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "conus/core/bounds.h"
#include "conus/core/camera.h"
#include "conus/core/error.h"
#include "conus/core/mesh.h"

namespace conus {
namespace {

TEST(Bounds, TheBoxHoldsEveryPointAndNothingMore) {
    Mesh mesh;
    mesh.positions = {{1.5f, -2.0f, 0.25f}, {-0.5f, 3.0f, 0.75f}, {0.0f, 0.0f, -4.0f}};
    const AxisBox box = boundsOf(mesh);
    EXPECT_EQ(box.lo, glm::dvec3(-0.5, -2.0, -4.0));
    EXPECT_EQ(box.hi, glm::dvec3(1.5, 3.0, 0.75));
    EXPECT_EQ(box.centre(), glm::dvec3(0.5, 0.5, -1.625));
    const std::vector<glm::dvec3> points(mesh.positions.begin(), mesh.positions.end());
    const AxisBox same = boundsOf(std::span<const glm::dvec3>(points));
    EXPECT_EQ(same.lo, box.lo);
    EXPECT_EQ(same.hi, box.hi);
    // Corner bits pick hi per axis: 0 is lo, 7 is hi, 5 is (hi.x, lo.y, hi.z).
    EXPECT_EQ(box.corner(0), box.lo);
    EXPECT_EQ(box.corner(7), box.hi);
    EXPECT_EQ(box.corner(5), glm::dvec3(1.5, -2.0, 0.75));
    // No points: a box that holds nothing.
    const AxisBox empty = boundsOf(std::span<const glm::vec3>());
    EXPECT_GT(empty.lo.x, empty.hi.x);
}

TEST(Framing, TheClipRangeBracketsTheBoxAlongTheViewAxis) {
    // A box 2..6 deep in front of an eye at the origin looking along +z, and off to one side.
    const AxisBox box{{1.0, -1.0, 2.0}, {3.0, 0.5, 6.0}};
    const std::optional<ClipRange> clip = clipRangeFor(box, {0, 0, 0}, {0, 0, 1});
    ASSERT_TRUE(clip);
    EXPECT_DOUBLE_EQ(clip->far, 6.0 * 1.02 + 1e-6);
    EXPECT_DOUBLE_EQ(clip->near, 2.0 * 0.98);
    // Straddling the eye: near falls back to far / 10^4, never 0 or negative.
    const std::optional<ClipRange> around = clipRangeFor(box, {2.0, 0.0, 4.0}, {0, 0, 1});
    ASSERT_TRUE(around);
    EXPECT_DOUBLE_EQ(around->far, 2.0 * 1.02 + 1e-6);
    EXPECT_DOUBLE_EQ(around->near, around->far * 1e-4);
    // Looking away: nothing to frame.
    EXPECT_FALSE(clipRangeFor(box, {0, 0, 0}, {0, 0, -1}));
}

TEST(Framing, TheDefaultViewLooksAtTheCentreAndFillsTheFrame) {
    const AxisBox box{{-2.0, 0.0, -1.0}, {4.0, 1.0, 0.5}};  // wide, flat and off the origin
    for (double aspect : {1.0, 2.0, 0.5}) {
        const Camera camera = framingCamera(box, {0.55, 0.45, 1.0}, {0, 1, 0}, aspect);
        double extent = 0;
        for (int corner = 0; corner < 8; ++corner) {
            const glm::dvec3 p = camera.project(box.corner(corner));
            EXPECT_GT(p.z, camera.near()) << "corner " << corner << " at aspect " << aspect;
            EXPECT_LT(p.z, camera.far()) << "corner " << corner << " at aspect " << aspect;
            extent = std::max({extent, std::abs(p.x - 0.5), std::abs(p.y - 0.5)});
        }
        // The corners span about 90% of the frame; the steps closer take the box's image to scale
        // as 1 / distance, which its nearest corners outgrow, so one may end a little past the edge
        // (here 3.6% of the width at aspect 2).
        EXPECT_GT(extent, 0.4) << "aspect " << aspect;
        EXPECT_LT(extent, 0.55) << "aspect " << aspect;
        // It looks at the centre from the side `direction` names.
        const glm::dvec3 centre = camera.project(box.centre());
        EXPECT_NEAR(centre.x, 0.5, 1e-9);
        EXPECT_NEAR(centre.y, 0.5, 1e-9);
        EXPECT_GT(camera.eye().x, box.centre().x);
        EXPECT_GT(camera.eye().z, box.hi.z);
    }
}

// A user's eye and look-at point: the camera looks where asked, its clip range holds the box, and
// the eye on the target, a view along up and a box behind the eye are refused with one line each.
TEST(Framing, AGivenViewIsClippedToTheBoxOrRefused) {
    const AxisBox box{{1.0, -1.0, 2.0}, {3.0, 0.5, 6.0}};
    const Camera camera = lookingAtBox(box, {0.5, 0.2, -1.0}, {2.0, -0.25, 4.0}, {0, 1, 0}, 35.0, 1.5, "the model");
    const std::optional<ClipRange> clip = clipRangeFor(box, {0.5, 0.2, -1.0}, glm::normalize(glm::dvec3(1.5, -0.45, 5.0)));
    ASSERT_TRUE(clip);
    EXPECT_DOUBLE_EQ(camera.near(), clip->near);
    EXPECT_DOUBLE_EQ(camera.far(), clip->far);
    const glm::dvec3 target = camera.project({2.0, -0.25, 4.0});
    EXPECT_NEAR(target.x, 0.5, 1e-9);
    EXPECT_NEAR(target.y, 0.5, 1e-9);
    for (int corner = 0; corner < 8; ++corner) {
        const double depth = camera.project(box.corner(corner)).z;
        EXPECT_GE(depth, camera.near());
        EXPECT_LE(depth, camera.far());
    }
    const auto message = [&](glm::dvec3 eye, glm::dvec3 at, glm::dvec3 up) -> std::string {
        try {
            lookingAtBox(box, eye, at, up, 35.0, 1.5, "the volume");
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
            return e.what();
        }
        return "accepted";
    };
    EXPECT_NE(message({1, 1, 1}, {1, 1, 1}, {0, 1, 0}).find("must differ"), std::string::npos);
    EXPECT_NE(message({1, -3, 4}, {1, 3, 4}, {0, 1, 0}).find("along the up vector"), std::string::npos);
    EXPECT_EQ(message({0, 0, 10}, {0, 0, 20}, {0, 1, 0}), "the volume lies entirely behind the camera");
}

}  // namespace
}  // namespace conus
