// conus-view as a user runs it: --screenshot headless, and the real window under Xvfb driven by
// --script (xvfb-run must be installed: package xvfb; these tests fail, not skip, without it, as
// CI installs it).
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "conus/codec/conus_file.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/format/container.h"
#include "sanitizers.h"
#include "view_state.h"
#include "oiio_picture.h"
#include "viewer_test_util.h"

namespace conus::viewer {
namespace {

namespace fs = std::filesystem;

// The files every test of this process wrote go when the process ends.
class RemoveTempDir : public ::testing::Environment {
public:
    void TearDown() override {
        std::error_code ignored;
        fs::remove_all(test::tempDir(), ignored);
    }
};
[[maybe_unused]] ::testing::Environment* const kRemoveTempDir = ::testing::AddGlobalTestEnvironment(new RemoveTempDir);

Image readPng(const fs::path& path) { return conus::test::readPictureWithOiio(path.string()); }

void writePng(const fs::path& path, const Image& im) {
    auto out = OIIO::ImageOutput::create(path.string());
    OIIO::ImageSpec spec(im.width, im.height, im.channelCount(), OIIO::TypeDesc::UINT8);
    out->open(path.string(), spec);
    out->write_image(OIIO::TypeDesc::FLOAT, im.pixels.data());
    out->close();
}

// Centroid and count of the pixels bright in every channel (the white marker).
glm::dvec3 marker(const Image& im) {
    glm::dvec3 sum{0.0};
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x)
            if (im.at(x, y, 0) > 0.85f && im.at(x, y, 1) > 0.85f && im.at(x, y, 2) > 0.85f) sum += glm::dvec3(x + 0.5, y + 0.5, 1);
    return sum.z > 0 ? glm::dvec3(sum.x / sum.z, sum.y / sum.z, sum.z) : sum;
}

// Pixels in [x0,x1)x[y0,y1) bright in every channel (white text).
int brightPixels(const Image& im, int x0, int y0, int x1, int y1) {
    int n = 0;
    for (int y = y0; y < std::min(y1, im.height); ++y)
        for (int x = x0; x < std::min(x1, im.width); ++x)
            n += im.at(x, y, 0) > 0.9f && im.at(x, y, 1) > 0.9f && im.at(x, y, 2) > 0.9f;
    return n;
}

// The rectangle [x0,x1)x[y0,y1) of the pixels that differ between a and b (x0 == x1 == 0: none).
struct Box { int x0 = 0, y0 = 0, x1 = 0, y1 = 0; };
Box changed(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height || a.channelCount() < 3 || b.channelCount() < 3) {
        ADD_FAILURE() << "pictures of different shapes: " << a.width << "x" << a.height << " vs " << b.width << "x" << b.height;
        return {0, 0, a.width, a.height};
    }
    Box box{a.width, a.height, 0, 0};
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c)
                if (std::abs(a.at(x, y, c) - b.at(x, y, c)) > 1.5f / 255) {
                    box = {std::min(box.x0, x), std::min(box.y0, y), std::max(box.x1, x + 1), std::max(box.y1, y + 1)};
                    break;
                }
    return box.x1 == 0 ? Box{} : box;
}

// A headless screenshot (no DISPLAY) of the test file's view [0.1,0.9]x[0.2,0.8] (256x144 source
// pixels) asked for at `size` (WxH), into `shot`.
void screenshotOfTheView(const std::string& size, Image& shot) {
    const fs::path out = test::tempDir() / ("view-" + size + ".png");
    std::string log;
    ASSERT_EQ(test::run("env -u DISPLAY " + test::viewerBinary() + " " + test::conusPath() + " --screenshot " + out.string() +
                            " --view 0.1,0.2,0.9,0.8 --size " + size + " --gamma 1", &log), 0) << log;
    shot = readPng(out);
}

// That view decoded on the CPU: what the screenshot shows.
Image cpuView() {
    const format::ConusFile file = format::readConusFile(test::conusPath());
    codec::DecodeOptions options;
    options.view = {0.1, 0.2, 0.9, 0.8};
    options.width = 256;
    options.height = 144;
    return codec::decodeImage(file.image, codec::SamplingMap::fromGrid(file.map), options);
}

// The largest difference between `expected` (channels R, G, B, clamped to [0,1]) and the 8-bit
// screenshot `shot` (R, G, B in that order, the picture starting at row `top`). A shot too small to
// hold the picture is a failure.
double worstDifference(const Image& shot, const Image& expected, int top = 0) {
    if (shot.width < expected.width || shot.height < top + expected.height || shot.channelCount() < 3) {
        ADD_FAILURE() << "a " << shot.width << "x" << shot.height << " shot cannot hold a " << expected.width << "x"
                      << expected.height << " picture at row " << top;
        return std::numeric_limits<double>::infinity();
    }
    // EXR stores channels sorted by name (B,G,R); the PNG is R,G,B.
    const int channel[3] = {expected.channelIndex("R"), expected.channelIndex("G"), expected.channelIndex("B")};
    double worst = 0;
    for (int y = 0; y < expected.height; ++y)
        for (int x = 0; x < expected.width; ++x)
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, double(std::abs(shot.at(x, top + y, c) - std::clamp(expected.at(x, y, channel[c]), 0.0f, 1.0f))));
    return worst;
}

std::string xvfb(const std::string& args) {
    return "xvfb-run -a -s '-screen 0 1024x768x24' " + conus::testing::glxLeakCheckPrefix() + test::viewerBinary() + " " + args;
}

TEST(ConusView, ScreenshotIsTheDecodedFrameWithoutADisplay) {
    Image shot;
    ASSERT_NO_FATAL_FAILURE(screenshotOfTheView("256x144", shot));
    ASSERT_EQ(shot.width, 256);
    // The view is 256x144 source pixels: the size's aspect, no letterbox.
    EXPECT_LT(worstDifference(shot, cpuView()), 3.0 / 255) << "8-bit rounding plus float differences";
}

// --uniform shows the real baseline (what `conus uniform` makes from the source) in U mode; without
// it the uniform image can only be resampled from the CoNUS data, which is not the same picture.
TEST(ConusView, UniformModeShowsTheGivenBaseline) {
    const Image uniform = codec::areaDownsample(test::sourceImage(), test::kConusWidth, test::kConusHeight);
    const fs::path uniformPath = test::tempDir() / "uniform.exr";
    format::writeConusFile(uniformPath.string(), codec::makeImageFile(uniform, codec::SamplingMap::identity(2, 2), test::kSourceWidth,
                                                                      test::kSourceHeight, {}));
    codec::DecodeOptions options;
    options.width = test::kSourceWidth;
    options.height = test::kSourceHeight;
    const Image expected = codec::decodeImage(uniform, codec::SamplingMap::identity(2, 2), options);
    const std::string size = " --size " + std::to_string(test::kSourceWidth) + "x" + std::to_string(test::kSourceHeight);
    const fs::path given = test::tempDir() / "given.png", resampled = test::tempDir() / "resampled.png";
    std::string log;
    ASSERT_EQ(test::run(test::viewerBinary() + " " + test::conusPath() + " --mode uniform --gamma 1 --uniform " + uniformPath.string() +
                            " --screenshot " + given.string() + size, &log), 0) << log;
    ASSERT_EQ(test::run(test::viewerBinary() + " " + test::conusPath() + " --mode uniform --gamma 1 --screenshot " + resampled.string() + size,
                        &log), 0) << log;
    const Image shotGiven = readPng(given), shotResampled = readPng(resampled);
    ASSERT_EQ(shotGiven.width, test::kSourceWidth);
    EXPECT_LT(worstDifference(shotGiven, expected), 3.0 / 255) << "8-bit rounding plus float differences";
    EXPECT_GT(worstDifference(shotResampled, expected), 6.0 / 255) << "the resampled uniform image is another picture";
    EXPECT_EQ(test::run(test::viewerBinary() + " --uniform " + uniformPath.string(), &log), 2) << log;
}

TEST(ConusView, ScreenshotLetterboxesLikeTheWindow) {
    // A 256x144-pixel view asked for at 256x256: shown whole at 256x144, centred, bands above and
    // below, not stretched to fill.
    Image shot;
    ASSERT_NO_FATAL_FAILURE(screenshotOfTheView("256x256", shot));
    ASSERT_EQ(shot.width, 256);
    ASSERT_EQ(shot.height, 256);
    const int top = (256 - 144) / 2;
    EXPECT_LT(worstDifference(shot, cpuView(), top), 3.0 / 255) << "the picture is the view, unstretched";
    // The bands show the background: one colour, unlike the picture.
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(shot.at(128, 5, c), shot.at(5, 5, c), 1e-6);
        EXPECT_NEAR(shot.at(128, 250, c), shot.at(5, 5, c), 1e-6);
    }
}

TEST(ConusView, ScreenshotModesAndGrid) {
    const fs::path dir = test::tempDir();
    for (const char* mode : {"raw", "uniform", "wipe", "density"}) {
        const fs::path out = dir / (std::string(mode) + ".png");
        std::string log;
        EXPECT_EQ(test::run(test::viewerBinary() + " " + test::conusPath() + " --screenshot " + out.string() + " --mode " +
                                mode + " --grid --outlines", &log), 0) << log;
        EXPECT_EQ(readPng(out).width, test::kSourceWidth) << mode;
    }
}

TEST(ConusView, ScreenshotOfAnInvalidFileFailsWithAReason) {
    const fs::path bad = test::tempDir() / "not_conus.exr";
    test::writeText(bad, "not an exr");
    std::string log;
    EXPECT_EQ(test::run(test::viewerBinary() + " " + bad.string() + " --screenshot " + (test::tempDir() / "x.png").string(), &log), 1);
    EXPECT_NE(log.find("not_conus.exr"), std::string::npos) << log;
    EXPECT_EQ(test::run(test::viewerBinary() + " --mode sideways " + test::conusPath(), &log), 2) << log;
}

TEST(ConusView, ScreenshotHelpOverlayDrawsTheKeyList) {
    const fs::path dir = test::tempDir();
    const std::string common = " " + test::conusPath() + " --size 800x640 --screenshot ";
    std::string log;
    ASSERT_EQ(test::run(test::viewerBinary() + common + (dir / "plain.png").string(), &log), 0) << log;
    ASSERT_EQ(test::run(test::viewerBinary() + common + (dir / "help.png").string() + " --help-overlay", &log), 0) << log;
    const Image plain = readPng(dir / "plain.png"), help = readPng(dir / "help.png");
    ASSERT_EQ(help.width, 800);
    ASSERT_EQ(help.height, 640);
    // The panel starts at the 16-pixel margin; everything outside it is the frame untouched.
    const Box box = changed(plain, help);
    EXPECT_EQ(box.x0, 16);
    EXPECT_EQ(box.y0, 16);
    EXPECT_GT(box.x1 - box.x0, 200) << "a panel wide enough for the key list";
    EXPECT_LT(box.x1, 800 - 16);
    EXPECT_GT(box.y1 - box.y0, 300) << "a line per key";
    EXPECT_LT(box.y1, 640);
    // White text inside the panel, on a darkened frame.
    EXPECT_GT(brightPixels(help, box.x0, box.y0, box.x1, box.y1), 10 * brightPixels(plain, box.x0, box.y0, box.x1, box.y1) + 500);
    double plainSum = 0, helpSum = 0;
    for (int y = box.y0; y < box.y1; ++y)
        for (int x = box.x0; x < box.x1; ++x)
            if (help.at(x, y, 0) < 0.5f) {
                plainSum += plain.at(x, y, 1);
                helpSum += help.at(x, y, 1);
            }
    EXPECT_LT(helpSum, 0.6 * plainSum) << "the panel darkens the frame behind the text";
}

TEST(ConusView, WindowHelpOverlayAndStatusBarToggle) {
    ASSERT_TRUE(test::haveXvfb());
    const fs::path dir = test::tempDir();
    test::writeText(dir / "help.txt", "screenshot " + (dir / "w0.png").string() + "\nkey H\nscreenshot " +
                                          (dir / "w1.png").string() + "\nkey H\nscreenshot " + (dir / "w2.png").string() +
                                          "\nkey B\nscreenshot " + (dir / "w3.png").string() + "\n");
    std::string log;
    ASSERT_EQ(test::run(xvfb(test::conusPath() + " --window 640x560 --script " + (dir / "help.txt").string()), &log), 0) << log;
    const Image w0 = readPng(dir / "w0.png"), w1 = readPng(dir / "w1.png"), w2 = readPng(dir / "w2.png"),
                        w3 = readPng(dir / "w3.png");
    ASSERT_EQ(w1.width, 640);
    const Box help = changed(w0, w1);
    EXPECT_EQ(help.x0, 16);
    EXPECT_EQ(help.y0, 16);
    EXPECT_GT(brightPixels(w1, help.x0, help.y0, help.x1, help.y1), 500) << "the key list in white";
    EXPECT_EQ(changed(w0, w2).x1, 0) << "H again closes the help";
    const Box status = changed(w0, w3);
    EXPECT_GT(status.y0, 500) << "the status bar is one line at the bottom";
    EXPECT_EQ(status.y1, 560);
    EXPECT_GT(brightPixels(w3, 0, status.y0, 640, 560), 50);
    EXPECT_NE(log.find("conus-view keys:"), std::string::npos) << "H still prints the keys too";
}

TEST(ConusView, WindowZoomKeepsTheFeatureUnderTheCursor) {
    ASSERT_TRUE(test::haveXvfb()) << "install xvfb (scripts/packages.txt)";
    const fs::path dir = test::tempDir();
    // Where the marker lands in a 400x300 window fitted to the 320x240 image.
    const ViewState state(400, 300, test::kSourceWidth, test::kSourceHeight);
    const glm::dvec2 at = state.imageToWindow({test::kMarkerU, test::kMarkerV});
    test::writeText(dir / "zoom.txt", "screenshot " + (dir / "before.png").string() + "\nzoom 3 at " + std::to_string(at.x) +
                                          " " + std::to_string(at.y) + "\nscreenshot " + (dir / "after.png").string() +
                                          "\nkey G\nkey D\nscreenshot " + (dir / "grid.png").string() +
                                          "\ninspect " + std::to_string(at.x) + " " + std::to_string(at.y) + "\n");
    std::string log;
    ASSERT_EQ(test::run(xvfb(test::conusPath() + " --window 400x300 --script " + (dir / "zoom.txt").string()), &log), 0) << log;
    const Image before = readPng(dir / "before.png"), after = readPng(dir / "after.png"), grid = readPng(dir / "grid.png");
    ASSERT_EQ(before.width, 400);
    ASSERT_EQ(after.height, 300);
    const glm::dvec3 a = marker(before), b = marker(after);
    ASSERT_GT(a.z, 10);
    EXPECT_NEAR(a.x, at.x, 1.5);
    EXPECT_NEAR(a.y, at.y, 1.5);
    EXPECT_NEAR(b.x, at.x, 1.5) << "the marker drifted away from the cursor";
    EXPECT_NEAR(b.y, at.y, 1.5);
    EXPECT_GT(b.z, 6 * a.z) << "3x zoom: about 9x the area";
    EXPECT_EQ(marker(grid).z, 0) << "density mode shows no picture";
    // The inspector line for the marker: the white disc, undistorted (u,v) at the marker.
    EXPECT_NE(log.find("u,v=(0.3000,0.4000)"), std::string::npos) << log;
    // The disc is white; the encoder's footprint filter (its anisotropic low-pass) blurs
    // its edge a little into the pixel at its centre, so near 1 rather than a fixed value (0.95:
    // the disc lies in the focus's widened transition, where footprints are 2.5 times longer than
    // wide).
    const std::size_t red = log.find("R=", log.find("u,v=(0.3000,0.4000)"));
    ASSERT_NE(red, std::string::npos) << log;
    EXPECT_GT(std::stod(log.substr(red + 2, 8)), 0.93) << log;
}

// The raw mode's grid in a 960x650 window: the automatic lines at least ~6 pixels apart everywhere,
// the focus included (spaced for density 1, they crowded together there into a moire).
TEST(ConusView, WindowRawGridIsThinnedToWhatTheScreenShows) {
    ASSERT_TRUE(test::haveXvfb()) << "install xvfb (scripts/packages.txt)";
    const fs::path dir = test::tempDir();
    test::writeText(dir / "raw.txt", "screenshot " + (dir / "raw.png").string() + "\nkey G\nscreenshot " +
                                         (dir / "raw-grid.png").string() + "\n");
    std::string log;
    ASSERT_EQ(test::run(xvfb(test::conusPath() + " --mode raw --window 960x650 --script " + (dir / "raw.txt").string()), &log), 0)
        << log;
    const Image plain = readPng(dir / "raw.png"), grid = readPng(dir / "raw-grid.png");
    ASSERT_EQ(plain.width, 960);
    ASSERT_EQ(grid.height, 650);
    constexpr int kTile = 48;
    int drawn = 0;
    double densest = 0;
    for (int y0 = 0; y0 + kTile <= 650; y0 += kTile)
        for (int x0 = 0; x0 + kTile <= 960; x0 += kTile) {
            int lines = 0;
            for (int y = y0; y < y0 + kTile; ++y)
                for (int x = x0; x < x0 + kTile; ++x)
                    lines += std::abs(plain.at(x, y, 1) - grid.at(x, y, 1)) > 1.5f / 255;
            const double share = double(lines) / (kTile * kTile);
            drawn += share > 0.05;
            densest = std::max(densest, share);
        }
    EXPECT_GT(drawn, 100) << "the grid covers the picture";
    EXPECT_LT(densest, 0.36) << "some tile is mostly grid lines";
}

TEST(ConusView, WindowShowsAnInvalidFileAsAnErrorWithoutCrashing) {
    ASSERT_TRUE(test::haveXvfb());
    const fs::path dir = test::tempDir();
    test::writeText(dir / "broken.exr", "garbage");
    test::writeText(dir / "bad.txt", "screenshot " + (dir / "bad.png").string() + "\nkey Tab\nscreenshot " +
                                         (dir / "good.png").string() + "\nkey ctrl+R\nkey Tab\ninspect 10 10\n");
    std::string log;
    EXPECT_EQ(test::run(xvfb((dir / "broken.exr").string() + " " + test::conusPath() + " --window 320x240 --script " +
                             (dir / "bad.txt").string()), &log), 1) << log;
    EXPECT_NE(log.find("broken.exr"), std::string::npos) << log;
    const Image bad = readPng(dir / "bad.png"), good = readPng(dir / "good.png");
    ASSERT_EQ(bad.width, 320);
    EXPECT_GT(bad.at(310, 230, 0), 0.3f);  // dark red (the bottom-right corner, clear of the text)
    EXPECT_LT(bad.at(310, 230, 1), 0.1f);
    // The error is written in the window: white text on a darkened panel at the top left.
    EXPECT_GT(brightPixels(bad, 0, 0, 320, 120), 100) << "no error text in the window";
    EXPECT_EQ(brightPixels(bad, 0, 0, 16, 240), 0) << "the panel keeps its margin";
    ASSERT_EQ(good.width, 320);
    EXPECT_GT(marker(good).z, 10) << "the second file is shown";
    EXPECT_NE(log.find("error:"), std::string::npos) << log;
}

TEST(ConusView, EditorPaintsSavesAndEncodes) {
    ASSERT_TRUE(test::haveXvfb());
    const fs::path dir = test::tempDir();
    writePng(dir / "photo.png", test::sourceImage());
    // The window fits the 320x240 image exactly: window pixel = source pixel.
    test::writeText(dir / "edit.txt", "drag 150 120 170 120\nwait 40\nkey S\nkey ctrl+S\nscreenshot " +
                                          (dir / "edit.png").string() + "\n");
    std::string log;
    ASSERT_EQ(test::run(xvfb("--edit " + (dir / "photo.png").string() + " -o " + (dir / "painted").string() +
                             " --size 160x120 --window 320x240 --script " + (dir / "edit.txt").string()), &log), 0) << log;
    const format::ConusFile map = format::readConusFile((dir / "painted.map.exr").string());
    const codec::SamplingMap sm = codec::SamplingMap::fromGrid(map.map);
    EXPECT_GT(sm.density({0.5, 0.5}), 1.2) << "the brush magnified the centre";
    const format::ConusFile encoded = format::readConusFile((dir / "painted.conus.exr").string());
    EXPECT_EQ(encoded.image.width, 160);
    EXPECT_EQ(encoded.sourceWidth, test::kSourceWidth);
    EXPECT_EQ(readPng(dir / "edit.png").width, 320);
}

// What a script's screenshot or the editor's save (S) writes never replaces a file the viewer
// reads, by any path (the picture being edited, the script itself, a link to either): each is
// refused in one line, the file unchanged, and the run fails; other names are written.
TEST(ConusView, ScriptScreenshotsAndEditorSavesNeverReplaceAnInput) {
    ASSERT_TRUE(test::haveXvfb());
    const fs::path dir = test::tempDir() / "inputs";
    fs::remove_all(dir);
    fs::create_directories(dir);
    writePng(dir / "photo.png", test::sourceImage());
    fs::create_symlink(dir / "photo.png", dir / "alias.map.exr");
    const auto bytes = [](const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string{std::istreambuf_iterator<char>(in), {}};
    };
    const std::string photo = bytes(dir / "photo.png");
    const fs::path script = dir / "script.png";  // text, named so that a screenshot could be written there
    test::writeText(script, "screenshot " + (dir / "photo.png").string() + "\nscreenshot " + script.string() + "\nkey S\nscreenshot " +
                                (dir / "fine.png").string() + "\n");
    const std::string scriptText = bytes(script);
    std::string log;
    const int status = test::run(xvfb("--edit " + (dir / "photo.png").string() + " -o " + (dir / "alias").string() +
                                      " --size 160x120 --window 320x240 --script " + script.string()), &log);
    EXPECT_NE(status, 0) << log;
    EXPECT_NE(log.find("refusing to write " + (dir / "photo.png").string() + ": it is the input"), std::string::npos) << log;
    EXPECT_NE(log.find("refusing to write " + script.string() + ": it is the input"), std::string::npos) << log;
    EXPECT_NE(log.find("refusing to write " + (dir / "alias.map.exr").string() + ": it is the input"), std::string::npos) << log;
    EXPECT_EQ(bytes(dir / "photo.png"), photo);
    EXPECT_EQ(bytes(script), scriptText);
    EXPECT_TRUE(fs::is_symlink(dir / "alias.map.exr"));
    EXPECT_EQ(readPng(dir / "fine.png").width, 320) << "another name is written";
}

// The window's fitted view shades only the image's box (rows counted from the bottom there) after
// a clear to the background: the same picture as the headless frame, which counts rows from the
// top, and the CPU decode's, bands included; and panned off centre, as the CPU decode shows it.
TEST(ConusView, WindowFittedViewMatchesTheHeadlessFrameAndTheCpuDecode) {
    ASSERT_TRUE(test::haveXvfb());
    const fs::path dir = test::tempDir();
    std::string log;
    const auto window = [&](const std::string& decode) {
        const fs::path shot = dir / ("fit-" + decode + ".png");
        test::writeText(dir / "fit.txt", "screenshot " + shot.string() + "\n");
        EXPECT_EQ(test::run(xvfb(test::conusPath() + " --window 610x300 --decode " + decode + " --script " + (dir / "fit.txt").string()), &log),
                  0) << log;
        return readPng(shot);
    };
    const Image gpu = window("gpu"), cpu = window("cpu");
    ASSERT_EQ(test::run("env -u DISPLAY " + test::viewerBinary() + " " + test::conusPath() + " --decode gpu --size 610x300 --screenshot " +
                            (dir / "fit-headless.png").string(), &log), 0) << log;
    const Image headless = readPng(dir / "fit-headless.png");
    ASSERT_EQ(gpu.width, 610);
    ASSERT_EQ(headless.height, 300);
    const Box none{};
    const Box a = changed(gpu, headless), b = changed(gpu, cpu);
    EXPECT_EQ(a.x1, none.x1) << "window vs headless differ in " << a.x0 << "," << a.y0 << " - " << a.x1 << "," << a.y1;
    EXPECT_EQ(b.x1, none.x1) << "shader vs CPU decode differ in " << b.x0 << "," << b.y0 << " - " << b.x1 << "," << b.y1;
    // Pillarboxed: background bands left and right, the picture between.
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(gpu.at(3, 150, c), 28.0f / 255, 0.5f / 255);
        EXPECT_NEAR(gpu.at(606, 20, c), 28.0f / 255, 0.5f / 255);
    }
    double spread = 0;
    for (int x = 250; x < 360; ++x) spread = std::max(spread, double(std::abs(gpu.at(x, 150, 0) - gpu.at(305, 150, 0))));
    EXPECT_GT(spread, 0.05) << "the middle shows the picture";

    // A tall window (bands above and below) panned down and right: the box is off centre.
    const auto tall = [&](const std::string& decode, const std::string& pan) {
        const fs::path shot = dir / ("tall-" + decode + (pan.empty() ? "" : "-panned") + ".png");
        test::writeText(dir / "tall.txt", pan + "screenshot " + shot.string() + "\n");
        EXPECT_EQ(test::run(xvfb(test::conusPath() + " --window 300x420 --decode " + decode + " --script " + (dir / "tall.txt").string()), &log),
                  0) << log;
        return readPng(shot);
    };
    const Image pannedGpu = tall("gpu", "pan 37 61\n"), pannedCpu = tall("cpu", "pan 37 61\n"), centred = tall("gpu", "");
    ASSERT_EQ(pannedGpu.height, 420);
    const Box c = changed(pannedGpu, pannedCpu);
    EXPECT_EQ(c.x1, none.x1) << "panned: shader vs CPU decode differ in " << c.x0 << "," << c.y0 << " - " << c.x1 << "," << c.y1;
    EXPECT_NE(changed(pannedGpu, centred).x1, none.x1) << "the pan moved the picture";
}

TEST(ConusView, BenchmarkPrintsFramesPerSecond) {
    ASSERT_TRUE(test::haveXvfb());
    std::string log;
    ASSERT_EQ(test::run(xvfb(test::conusPath() + " --window 320x240 --benchmark-frames 5"), &log), 0) << log;
    EXPECT_NE(log.find("frames/s"), std::string::npos) << log;
}

}  // namespace
}  // namespace conus::viewer
