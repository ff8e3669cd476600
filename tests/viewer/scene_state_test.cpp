// The 3-D modes' interaction without a window: orbiting, dragging foci, toggling CoNUS, and the
// map and camera a frame is rendered with.
#include <gtest/gtest.h>

#include "conus/codec/builders/frame_foci.h"
#include "controller.h"
#include "scene_state.h"
#include "viewer_test_util.h"

namespace conus::viewer {
namespace {

constexpr int kW = 320, kH = 240;

Options sceneOptions() {
    Options o;
    o.sceneKind = SceneKind::Mesh;
    o.scenePath = "unused.obj";  // the controller never reads it: the window opens the scene
    o.foci = {{0.3, 0.4, 0.1, 3.0}};
    return o;
}

// The window pixel showing image point uv (the frame fills the window: same size).
glm::dvec2 windowOf(const Controller& c, glm::dvec2 uv) { return c.state().imageToWindow(uv); }

TEST(SceneState, OrbitKeepsTheDistanceAndLooksAtTheCentre) {
    SceneState s({1, 2, 3}, 0.5, {});
    const Camera before = s.camera(4.0 / 3);
    const double distance = glm::length(before.eye() - glm::dvec3(1, 2, 3));
    s.rotate(90, 30);
    const Camera after = s.camera(4.0 / 3);
    EXPECT_NEAR(glm::length(after.eye() - glm::dvec3(1, 2, 3)), distance, 1e-9);
    EXPECT_GT(glm::length(after.eye() - before.eye()), 0.5 * distance);
    // The centre projects to the image centre, in front, between near and far.
    const glm::dvec3 centre = after.project({1, 2, 3});
    EXPECT_NEAR(centre.x, 0.5, 1e-9);
    EXPECT_NEAR(centre.y, 0.5, 1e-9);
    EXPECT_GT(centre.z, after.near());
    EXPECT_LT(centre.z + 0.5, after.far());
    s.rotate(0, 500);
    EXPECT_LE(s.orbit().pitchDegrees, kMaxPitchDegrees) << "never over the pole";
    s.dolly(1e-6);
    EXPECT_GE(s.orbit().distance, 0.25 * 0.5);
    s.home();
    EXPECT_NEAR(glm::length(s.camera(1).eye() - before.eye()), 0, 1e-12);
}

TEST(SceneState, MapIsTheFociOrTheIdentity) {
    const codec::Focus focus{0.6, 0.4, 0.1, 4.0};
    SceneState s({0, 0, 0}, 1, {focus});
    const codec::SamplingMap map = s.map(1.5);
    codec::FociOptions options;
    options.aspect = 1.5;
    const codec::SamplingMap expected = codec::buildFrameFociMap(std::span<const codec::Focus>(&focus, 1), options);
    EXPECT_EQ(map.toGrid().xy, expected.toGrid().xy);
    EXPECT_GT(map.density({0.6, 0.4}), 4.0) << "magnified at the focus";
    const int version = s.version();
    s.toggleConus();
    EXPECT_NE(s.version(), version);
    EXPECT_NEAR(s.map(1.5).density({0.6, 0.4}), 1.0, 1e-9) << "conventional: the identity";
}

// A controller in mesh scene mode over a kW x kH window (the controller never opens the scene).
class SceneController : public ::testing::Test {
protected:
    void SetUp() override {
        c.setWindowSize(kW, kH);
        ASSERT_TRUE(c.load());
        c.startScene({0, 0, 0}, 1.0, "test (mesh)", true, "");
    }
    const Options options = sceneOptions();
    Controller c{options};
};

TEST_F(SceneController, DragOnAFocusMovesItElsewhereOrbits) {
    ASSERT_NE(c.scene(), nullptr);
    EXPECT_EQ(c.keyTable(), KeyTable::Scene);
    EXPECT_EQ(c.display().mode, renderers::ViewMode::Raw) << "the CoNUS image itself";
    EXPECT_EQ(c.sceneFrameSize(), glm::ivec2(kW, kH));

    // A drag from the focus takes it to where the drag ends; the camera stays.
    const Orbit orbit = c.scene()->orbit();
    const glm::dvec2 from = windowOf(c, {0.3, 0.4}), to = windowOf(c, {0.7, 0.6});
    c.run({"drag", {from.x, from.y, to.x, to.y}, "", 0});
    ASSERT_EQ(c.scene()->foci().size(), 1u);
    EXPECT_NEAR(c.scene()->foci()[0].u, 0.7, 0.01);
    EXPECT_NEAR(c.scene()->foci()[0].v, 0.6, 0.01);
    EXPECT_EQ(c.scene()->orbit().yawDegrees, orbit.yawDegrees);

    // A drag from empty image orbits: right turns the yaw down, the focus stays.
    const glm::dvec2 a = windowOf(c, {0.1, 0.9}), b = a + glm::dvec2(50, -20);
    c.run({"drag", {a.x, a.y, b.x, b.y}, "", 0});
    EXPECT_NEAR(c.scene()->orbit().yawDegrees, orbit.yawDegrees - 50 * kOrbitDegreesPerPixel, 1e-9);
    EXPECT_NEAR(c.scene()->orbit().pitchDegrees, orbit.pitchDegrees - 20 * kOrbitDegreesPerPixel, 1e-9);
    EXPECT_NEAR(c.scene()->foci()[0].u, 0.7, 0.01);

    // Keys: arrows orbit, + dollies, U toggles, N adds a focus at the cursor, X removes the nearest.
    const int version = c.sceneVersion();
    c.key({"Left"});
    EXPECT_NE(c.sceneVersion(), version);
    const double distance = c.scene()->orbit().distance;
    c.key({"+"});
    EXPECT_LT(c.scene()->orbit().distance, distance);
    c.scroll(2, false);
    EXPECT_LT(c.scene()->orbit().distance, distance / kDollyStep);
    c.key({"U"});
    EXPECT_FALSE(c.scene()->conus());
    c.key({"U"});
    c.cursor(windowOf(c, {0.2, 0.8}));
    c.key({"N"});
    ASSERT_EQ(c.scene()->foci().size(), 2u);
    EXPECT_NEAR(c.scene()->foci()[1].u, 0.2, 0.01);
    c.cursor(windowOf(c, {0.65, 0.6}));
    c.key({"X"});
    ASSERT_EQ(c.scene()->foci().size(), 1u);
    EXPECT_NEAR(c.scene()->foci()[0].u, 0.2, 0.01) << "the one near the cursor went";
    c.run({"orbit", {15, -5}, "", 0});
    c.key({"F"});
    EXPECT_EQ(c.scene()->orbit().yawDegrees, orbit.yawDegrees) << "F: the first camera";
    c.key({"T"});
    EXPECT_EQ(c.lookRequests(), 1);
}

// A frame handed back is what the window shows and what the inspector reads: a depth image with
// the camera, so the 3-D point under the cursor is the camera's.
TEST_F(SceneController, TheFrameIsShownAndInspected) {
    const double aspect = double(kW) / kH;
    const Camera camera = c.scene()->camera(aspect);
    const codec::SamplingMap map = c.scene()->map(aspect);
    // A frame of constant depth 2.5 (a screen facing the camera), colour = its distorted position.
    Image image = makeImage(kW, kH, {"R", "G", "B", "A", "Z"});
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            image.at(x, y, 0) = float((x + 0.5) / kW);
            image.at(x, y, 1) = float((y + 0.5) / kH);
            image.at(x, y, 3) = 1.0f;
            image.at(x, y, 4) = 2.5f;
        }
    const int before = c.imageVersion();
    c.setSceneFrame(sceneFrameFile(image, map, camera, c.scene()->foci()));
    EXPECT_NE(c.imageVersion(), before);
    const std::optional<format::ConusFile> shown = c.shownFile();
    ASSERT_TRUE(shown.has_value());
    EXPECT_EQ(shown->dataKind, format::DataKind::DepthImage);
    ASSERT_TRUE(shown->analytic.has_value());
    EXPECT_EQ(shown->analytic->foci.size(), 1u);
    // Raw display: the cursor over the CoNUS image at distorted (0.3, 0.4) -> the point the camera
    // sees there through the map's inverse, at depth 2.5.
    c.cursor(windowOf(c, {0.31, 0.41}));
    const std::string status = c.statusText();
    const std::size_t at = status.find("P=(");
    ASSERT_NE(at, std::string::npos) << status;
    glm::dvec3 p;
    ASSERT_EQ(std::sscanf(status.c_str() + at, "P=(%lf,%lf,%lf)", &p.x, &p.y, &p.z), 3) << status;
    const glm::dvec3 projected = camera.project(p);
    EXPECT_NEAR(projected.z, 2.5, 1e-4);
    const glm::dvec2 distorted = map.distort({projected.x, projected.y});
    EXPECT_NEAR(distorted.x, 0.31, 1.0 / kW);
    EXPECT_NEAR(distorted.y, 0.41, 1.0 / kH);
    // Z shows the frame's depth picture.
    c.key({"Z"});
    EXPECT_EQ(c.shownFile()->image.channels, (std::vector<std::string>{"R", "G", "B"}));
}

}  // namespace
}  // namespace conus::viewer
