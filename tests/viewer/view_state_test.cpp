#include "view_state.h"

#include <gtest/gtest.h>

namespace conus::viewer {
namespace {

// The same point, in window or image coordinates, up to rounding.
void expectSamePoint(glm::dvec2 got, glm::dvec2 want) {
    EXPECT_NEAR(got.x, want.x, 1e-9);
    EXPECT_NEAR(got.y, want.y, 1e-9);
}

TEST(ViewState, FitShowsTheWholeImageCentred) {
    ViewState s(800, 600, 400, 100);  // wide image: width limits
    EXPECT_DOUBLE_EQ(s.zoom(), 2.0);
    const codec::View v = s.view();
    EXPECT_NEAR(v.u0, 0.0, 1e-12);
    EXPECT_NEAR(v.u1, 1.0, 1e-12);
    EXPECT_NEAR(0.5 * (v.v0 + v.v1), 0.5, 1e-12);
    EXPECT_NEAR(v.v1 - v.v0, 3.0, 1e-12);  // 600 px at 200 px per image height
}

TEST(ViewState, WindowAndImageCoordinatesInvert) {
    ViewState s(640, 480, 300, 200);
    s.zoomAbout(3.7, {100, 50});
    s.pan({-33, 12});
    for (glm::dvec2 w : {glm::dvec2(0, 0), glm::dvec2(640, 480), glm::dvec2(123.25, 401.5)}) {
        const glm::dvec2 back = s.imageToWindow(s.windowToImage(w));
        expectSamePoint(back, w);
    }
}

TEST(ViewState, ZoomAboutTheCursorKeepsItsPointFixed) {
    ViewState s(1280, 800, 2048, 2048);
    const glm::dvec2 cursor{913.5, 207.25};
    const glm::dvec2 before = s.windowToImage(cursor);
    for (int k = 0; k < 40; ++k) s.scroll(k < 25 ? 1.0 : -1.0, cursor);  // in and out, no drift
    s.zoomAbout(1.0 / 3.0, cursor);
    s.zoomAbout(7.5, cursor);
    const glm::dvec2 after = s.windowToImage(cursor);
    expectSamePoint(after, before);
}

TEST(ViewState, ZoomIsClampedAndStillAnchored) {
    ViewState s(100, 100, 100, 100);
    const glm::dvec2 cursor{20, 70};
    const glm::dvec2 before = s.windowToImage(cursor);
    s.zoomAbout(1e6, cursor);
    EXPECT_DOUBLE_EQ(s.zoom(), kMaxZoom);
    expectSamePoint(s.windowToImage(cursor), before);
    s.zoomAbout(1e-9, cursor);
    EXPECT_DOUBLE_EQ(s.zoom(), s.fitZoom() * kMinZoomOfFit);
    s.zoomAbout(0.0, cursor);  // ignored
    s.zoomAbout(std::nan(""), cursor);
    EXPECT_DOUBLE_EQ(s.zoom(), s.fitZoom() * kMinZoomOfFit);
}

TEST(ViewState, PanMovesTheContentWithTheMouse) {
    ViewState s(400, 400, 200, 200);
    s.zoomAbout(4.0, {200, 200});
    const glm::dvec2 grabbed = s.windowToImage({150, 220});
    s.pan({30, -10});
    const glm::dvec2 now = s.imageToWindow(grabbed);
    expectSamePoint(now, {180, 210});
}

TEST(ViewState, PanKeepsTheWindowCentreOverTheImage) {
    ViewState s(400, 300, 400, 300);
    s.pan({1e6, -1e6});
    EXPECT_DOUBLE_EQ(s.center().x, 0.0);
    EXPECT_DOUBLE_EQ(s.center().y, 1.0);
}

TEST(ViewState, SourceResolutionIsOneToOne) {
    ViewState s(1000, 700, 4000, 3000);
    s.sourceResolution();
    EXPECT_DOUBLE_EQ(s.zoom(), 1.0);
    // One window pixel spans one source pixel.
    const glm::dvec2 a = s.windowToImage({10, 10}), b = s.windowToImage({11, 11});
    EXPECT_NEAR((b.x - a.x) * 4000, 1.0, 1e-12);
    EXPECT_NEAR((b.y - a.y) * 3000, 1.0, 1e-12);
    s.fit();
    EXPECT_DOUBLE_EQ(s.zoom(), 0.23333333333333334);
}

TEST(ViewState, ShowViewFitsTheRectangle) {
    ViewState s(800, 400, 1000, 1000);
    s.showView({0.2, 0.3, 0.4, 0.4});  // 200 x 100 source pixels: zoom 4
    EXPECT_DOUBLE_EQ(s.zoom(), 4.0);
    const codec::View v = s.view();
    EXPECT_NEAR(v.u0, 0.2, 1e-12);
    EXPECT_NEAR(v.v1, 0.4, 1e-12);
}

TEST(ViewState, ResizeKeepsCentreAndZoom) {
    ViewState s(800, 600, 1000, 1000);
    s.zoomAbout(2.0, {100, 100});
    const glm::dvec2 c = s.center();
    const double z = s.zoom();
    s.setWindowSize(1024, 768);
    EXPECT_EQ(s.center(), c);
    EXPECT_DOUBLE_EQ(s.zoom(), z);
}

}  // namespace
}  // namespace conus::viewer
