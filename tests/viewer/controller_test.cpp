// The viewer's controller without a window: what keys, the wheel, drags and script commands do to
// the state a frame is drawn from.
#include <gtest/gtest.h>

#include <fstream>

#include "controller.h"
#include "viewer_test_util.h"

namespace conus::viewer {
namespace {

Options twoFiles() {
    Options o;
    const std::string bad = (test::tempDir() / "not-conus.exr").string();
    std::ofstream(bad) << "not an EXR";
    o.files = {test::conusPath(), bad};
    return o;
}

}  // namespace

TEST(Controller, WheelZoomsAboutTheCursorAndKeysChangeTheDisplay) {
    const Options options = twoFiles();
    Controller c(options);
    c.setWindowSize(640, 480);
    ASSERT_TRUE(c.load());
    EXPECT_EQ(c.exitCode(), 1) << "the second file is not a CoNUS file";
    ASSERT_TRUE(c.current()->ok());
    const glm::dvec2 at(200, 150);
    c.cursor(at);
    const glm::dvec2 before = c.state().windowToImage(at);
    c.scroll(3, false);
    EXPECT_GT(c.state().zoom(), 1.5 * 640.0 / test::kSourceWidth * 0.99);
    const glm::dvec2 after = c.state().windowToImage(at);
    EXPECT_NEAR(after.x, before.x, 1e-9);
    EXPECT_NEAR(after.y, before.y, 1e-9);
    c.key({"D"});
    EXPECT_EQ(c.display().mode, renderers::ViewMode::Density);
    c.key({"T"});
    EXPECT_EQ(c.display().toneMap, ToneMap::Reinhard);
    c.key({"E", true});
    EXPECT_EQ(c.display().exposure, -0.5);
    EXPECT_NE(c.title().find("reinhard"), std::string::npos) << c.title();
    EXPECT_NE(c.title().find("u,v="), std::string::npos) << "the pixel under the cursor: " << c.title();
}

TEST(Controller, TabShowsTheNextFileAndItsError) {
    const Options options = twoFiles();
    Controller c(options);
    c.setWindowSize(640, 480);
    ASSERT_TRUE(c.load());
    const int version = c.imageVersion();
    ASSERT_TRUE(c.shownFile().has_value());
    c.key({"Tab"});
    EXPECT_GT(c.imageVersion(), version) << "the drawing uploads again";
    EXPECT_FALSE(c.current()->ok());
    EXPECT_FALSE(c.shownFile().has_value());
    EXPECT_NE(c.title().find("ERROR"), std::string::npos) << c.title();
    c.key({"Tab"});
    EXPECT_TRUE(c.current()->ok());
    c.cannotDisplay("too large for the textures");
    EXPECT_NE(c.statusText().find("cannot display: too large"), std::string::npos) << c.statusText();
}

TEST(Controller, DragPansAndScriptsAskForScreenshotsAndQuit) {
    Options options;
    options.files = {test::conusPath()};
    Controller c(options);
    c.setWindowSize(640, 480);
    ASSERT_TRUE(c.load());
    const glm::dvec2 centre = c.state().center();
    c.run({"drag", {100, 100, 164, 100}, "", 1});
    EXPECT_LT(c.state().center().x, centre.x) << "the content follows the mouse right";
    c.run({"screenshot", {}, "/tmp/x.png", 2});
    EXPECT_EQ(c.takeScreenshotRequest(), "/tmp/x.png");
    EXPECT_EQ(c.takeScreenshotRequest(), "");
    c.run({"wait", {3}, "", 3});
    EXPECT_EQ(c.waitFrames(), 3);
    EXPECT_FALSE(c.quitRequested());
    c.run({"key", {}, "Q", 4});
    EXPECT_TRUE(c.quitRequested());
}

}  // namespace conus::viewer
