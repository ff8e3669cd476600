// The viewer's GPU drawing on the headless context (EGL or OSMesa): what --screenshot renders.
#include "conus/renderers/view_renderer.h"

#include <gtest/gtest.h>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/renderers/backend.h"
#include "viewer_test_util.h"

namespace conus::viewer {
namespace {

using renderers::ViewMode;
using renderers::ViewOptions;

struct Fixture {
    format::ConusFile file = test::conusFile();
    codec::SamplingMap map = codec::SamplingMap::fromGrid(file.map);
    renderers::ViewRenderer renderer{test::context()};
    Fixture() { renderer.setImage(file); }
};

Fixture& fixture() {
    static Fixture* f = new Fixture;
    return *f;
}

ViewOptions linear(ViewMode mode = ViewMode::Reconstructed) {
    ViewOptions o;
    o.mode = mode;
    o.gamma = 1.0;
    return o;
}

float channelDiff(const Image& a, const Image& b, int x, int y, int c) {
    return std::abs(a.at(x, y, c) - b.at(x, y, c));
}

double psnrRgb(const Image& a, const Image& b) {
    double se = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) se += std::pow(double(a.at(x, y, c)) - b.at(x, y, c), 2);
    const double mse = se / (3.0 * a.width * a.height);
    return 10 * std::log10(1.0 / std::max(mse, 1e-20));
}

TEST(ViewRenderer, ReconstructedMatchesTheCpuDecoder) {
    Fixture& f = fixture();
    const codec::View view{0.1, 0.15, 0.9, 0.8};
    const Image gpu = f.renderer.renderToImage(view, 256, 208, linear());
    codec::DecodeOptions options;
    options.view = view;
    options.width = 256;
    options.height = 208;
    // The viewer decodes zoomed-out pixels from the CoNUS image's mip chain.
    const codec::ImagePyramid pyramid = codec::buildPyramid(f.file.image);
    options.pyramid = &pyramid;
    const Image cpu = codec::decodeImage(f.file.image, f.map, options);
    EXPECT_GT(psnrRgb(gpu, cpu), 50.0);
    // Zoomed far in: still decoded from the CoNUS data (a zoom on the focus).
    const codec::View close{0.6, 0.5, 0.7, 0.6};
    options.view = close;
    EXPECT_GT(psnrRgb(f.renderer.renderToImage(close, 256, 208, linear()), codec::decodeImage(f.file.image, f.map, options)), 50.0);
}

// The software-GL path (codec::decodeImage per frame, uploaded, overlays blended over it) and the
// shader give the same frame, zoomed out (multi-tap), zoomed in, past the edge, with exposure, gamma
// and overlays.
TEST(ViewRenderer, CpuDecodeMatchesTheShader) {
    Fixture& f = fixture();
    for (const codec::View& view : {codec::View{0.1, 0.15, 0.9, 0.8}, codec::View{0.6, 0.5, 0.7, 0.6},
                                    codec::View{-0.2, -0.1, 1.1, 1.2}, codec::View{}}) {
        for (const bool overlays : {false, true}) {
            ViewOptions o;
            o.exposure = 0.5;
            o.grid = overlays;
            o.gridEvery = 5;
            o.outlines = overlays;
            o.decode = renderers::DecodePath::Gpu;
            EXPECT_FALSE(f.renderer.decodesOnCpu(o, view, 240));
            const Image gpu = f.renderer.renderToImage(view, 240, 180, o);
            o.decode = renderers::DecodePath::Cpu;
            EXPECT_TRUE(f.renderer.decodesOnCpu(o, view, 240));
            const Image cpu = f.renderer.renderToImage(view, 240, 180, o);
            EXPECT_GT(psnrRgb(gpu, cpu), overlays ? 40.0 : 50.0) << view.u0 << "," << view.v0 << " overlays " << overlays;
            // Same background outside [0,1]^2, same alpha.
            EXPECT_EQ(gpu.at(0, 0, 3), cpu.at(0, 0, 3));
            if (view.u0 < 0) {
                EXPECT_FLOAT_EQ(cpu.at(1, 1, 0), renderers::kViewBackground);
            }
        }
    }
    // Other modes never decode on the CPU.
    ViewOptions raw = linear(ViewMode::Raw);
    raw.decode = renderers::DecodePath::Cpu;
    EXPECT_FALSE(f.renderer.decodesOnCpu(raw, codec::View{}, 240));
}

// Auto on a software rasterizer: the CPU decoder where the view is magnified or 1:1, the shader's
// one trilinear tap where it is minified (measured faster there on llvmpipe); elsewhere the shader.
TEST(ViewRenderer, AutoDecodeFollowsTheRasterizerAndTheZoom) {
    Fixture& f = fixture();
    ViewOptions o;
    o.decode = renderers::DecodePath::Auto;
    const int across = f.file.image.width;  // target pixels across the whole image: 1:1
    const bool software = renderers::prefersCpu(test::context());
    EXPECT_EQ(f.renderer.decodesOnCpu(o, codec::View{}, across), software);
    EXPECT_EQ(f.renderer.decodesOnCpu(o, codec::View{0.2, 0.2, 0.4, 0.4}, across), software);  // magnified
    EXPECT_FALSE(f.renderer.decodesOnCpu(o, codec::View{}, across / 2));                      // minified
    EXPECT_FALSE(f.renderer.decodesOnCpu(o, codec::View{-0.5, 0, 1.5, 1}, across));           // minified
}

TEST(ViewRenderer, RawShowsTheCoNUSImageItself) {
    Fixture& f = fixture();
    const Image raw = f.renderer.renderToImage({}, test::kConusWidth, test::kConusHeight, linear(ViewMode::Raw));
    for (int y = 0; y < raw.height; y += 7)
        for (int x = 0; x < raw.width; x += 5)
            for (int c = 0; c < 3; ++c) ASSERT_LT(channelDiff(raw, f.file.image, x, y, c), 1e-4) << x << "," << y;
}

TEST(ViewRenderer, UniformImageHasTheSamePixelCountAndLooksLikeTheSource) {
    Fixture& f = fixture();
    const Image& uniform = f.renderer.uniformImage();
    EXPECT_EQ(uniform.width, test::kConusWidth);
    EXPECT_EQ(uniform.height, test::kConusHeight);
    const Image reference = codec::areaDownsample(test::sourceImage(), test::kConusWidth, test::kConusHeight);
    EXPECT_GT(psnrRgb(uniform, reference), 28.0);
    // Uniform mode at the uniform image's own size shows it pixel for pixel.
    const Image shown = f.renderer.renderToImage({}, uniform.width, uniform.height, linear(ViewMode::Uniform));
    EXPECT_GT(psnrRgb(shown, uniform), 60.0);
}

TEST(ViewRenderer, WipeSplitsReconstructedAndUniform) {
    Fixture& f = fixture();
    ViewOptions wipe = linear(ViewMode::Wipe);
    wipe.wipeX = 0.5;
    const Image w = f.renderer.renderToImage({}, 200, 150, wipe);
    ViewOptions shader = linear();
    shader.decode = renderers::DecodePath::Gpu;  // the wipe is drawn by the shader (pixel for pixel; the CPU path is within 50 dB)
    const Image r = f.renderer.renderToImage({}, 200, 150, shader);
    const Image u = f.renderer.renderToImage({}, 200, 150, linear(ViewMode::Uniform));
    for (int y = 0; y < 150; y += 3) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(w.at(40, y, c), r.at(40, y, c));
            EXPECT_EQ(w.at(160, y, c), u.at(160, y, c));
            EXPECT_EQ(w.at(100, y, c), 1.0f);  // the split line
        }
    }
}

TEST(ViewRenderer, GridLinesAreWhereEquationOnePutsThem) {
    Fixture& f = fixture();
    const int width = 400, height = 300, every = 5;
    const codec::View view{0.0, 0.0, 1.0, 1.0};
    ViewOptions options = linear();
    const Image plain = f.renderer.renderToImage(view, width, height, options);
    options.grid = true;
    options.gridEvery = every;
    const Image grid = f.renderer.renderToImage(view, width, height, options);
    const double lx = double(test::kConusWidth) / every, ly = double(test::kConusHeight) / every;
    const auto distorted = [&](int x, int y) {
        return f.map.distort({(x + 0.5) / width, (y + 0.5) / height});
    };
    int predicted = 0, brighter = 0, quiet = 0, unchanged = 0;
    for (int y = 1; y + 2 < height; ++y)
        for (int x = 1; x + 2 < width; ++x) {
            const glm::dvec2 d = distorted(x, y), r = distorted(x + 1, y), b = distorted(x, y + 1);
            const bool edge = std::floor(d.x * lx) != std::floor(r.x * lx) || std::floor(d.y * ly) != std::floor(b.y * ly);
            // Far from any line (its neighbours are not on one either): the overlay leaves it alone.
            const glm::dvec2 l = distorted(x - 1, y), a = distorted(x, y - 1), rr = distorted(x + 2, y), bb = distorted(x, y + 2);
            const bool nearEdge = std::floor(l.x * lx) != std::floor(rr.x * lx) || std::floor(a.y * ly) != std::floor(bb.y * ly);
            const float gain = grid.at(x, y, 1) - plain.at(x, y, 1);
            if (edge) {
                ++predicted;
                brighter += gain > 0.2f;
            } else if (!nearEdge) {
                ++quiet;
                unchanged += gain == 0.0f;
            }
        }
    ASSERT_GT(predicted, 3000);
    EXPECT_GT(brighter, 0.97 * predicted) << brighter << " of " << predicted;
    EXPECT_GT(unchanged, 0.999 * quiet) << unchanged << " of " << quiet;
}

TEST(ViewRenderer, DensityIsBrightAtTheFocus) {
    Fixture& f = fixture();
    const Image d = f.renderer.renderToImage({}, 160, 120, linear(ViewMode::Density));
    const auto brightness = [&](double u, double v) {
        const int x = int(u * 160), y = int(v * 120);
        return d.at(x, y, 0) + d.at(x, y, 1) + d.at(x, y, 2);
    };
    EXPECT_GT(brightness(test::kFocusU, test::kFocusV), 2.0f);
    EXPECT_LT(brightness(0.05, 0.05), 1.0f);
    EXPECT_GT(brightness(test::kFocusU, test::kFocusV), brightness(0.05, 0.05) + 1.0f);
}

TEST(ViewRenderer, OutlinesCircleTheFocus) {
    Fixture& f = fixture();
    ViewOptions o = linear();
    o.outlines = true;
    const int width = test::kSourceWidth, height = test::kSourceHeight;
    const Image im = f.renderer.renderToImage({}, width, height, o);
    // r = 0.1 of the width: 32 pixels right of the centre.
    const int x = int(test::kFocusU * width + 0.1 * width), y = int(test::kFocusV * height);
    EXPECT_FLOAT_EQ(im.at(x, y, 1), 1.0f);
    EXPECT_FLOAT_EQ(im.at(x, y, 0), 0.2f);
    EXPECT_NE(im.at(int(test::kFocusU * width), y, 1), 1.0f);
}

TEST(ViewRenderer, ExposureAndGamma) {
    Fixture& f = fixture();
    ViewOptions o = linear();
    const Image base = f.renderer.renderToImage({}, 64, 48, o);
    o.exposure = 1.0;
    const Image brighter = f.renderer.renderToImage({}, 64, 48, o);
    o.exposure = 0.0;
    o.gamma = 2.0;
    const Image gamma = f.renderer.renderToImage({}, 64, 48, o);
    for (int x = 0; x < 64; x += 9) {
        EXPECT_NEAR(brighter.at(x, 20, 0), 2 * base.at(x, 20, 0), 1e-5);
        EXPECT_NEAR(gamma.at(x, 20, 0), std::sqrt(base.at(x, 20, 0)), 1e-5);
    }
}

TEST(ViewRenderer, SrgbCurveAndToneMapsAgreeWithCoreOnBothPaths) {
    Fixture& f = fixture();
    const Image base = f.renderer.renderToImage({}, 64, 48, linear());
    for (ToneMap toneMap : {ToneMap::None, ToneMap::Reinhard, ToneMap::Aces}) {
        ViewOptions o;  // gamma 0: the sRGB curve
        o.exposure = 2.0;  // pushes the bright parts above 1
        o.toneMap = toneMap;
        for (renderers::DecodePath path : {renderers::DecodePath::Gpu, renderers::DecodePath::Cpu}) {
            o.decode = path;
            const Image shown = f.renderer.renderToImage({}, 64, 48, o);
            for (int x = 0; x < 64; x += 7)
                for (int c = 0; c < 3; ++c) {
                    const float want = linearToSrgbDisplay(exposeAndToneMap(base.at(x, 20, c), 4.0f, toneMap));
                    EXPECT_NEAR(shown.at(x, 20, c), want, 2e-3) << enumName(toneMap) << (path == renderers::DecodePath::Cpu ? " cpu" : " gpu");
                }
        }
    }
}

// The shader's texture is half floats up to +12 stops and float above: a dim image brightened by
// its exposure shows on the GPU what the CPU decode (float throughout) shows. With the half
// texture at +20 stops the dim values (2^-20..2^-21, half's subnormals: steps of 2^-24) would
// keep 3-4 bits and fall far below 50 dB.
TEST(ViewRenderer, DimImagesAtHighExposureMatchTheCpuDecode) {
    for (const int stops : {12, 20}) {
        format::ConusFile file = test::conusFile();
        for (float& x : file.image.pixels) x = std::ldexp(x, -stops);
        renderers::ViewRenderer renderer{test::context()};
        renderer.setImage(file);
        ViewOptions o = linear();
        o.exposure = stops;
        for (const codec::View& view : {codec::View{}, codec::View{0.1, 0.15, 0.9, 0.8}}) {
            o.decode = renderers::DecodePath::Gpu;
            const Image gpu = renderer.renderToImage(view, 160, 120, o);
            o.decode = renderers::DecodePath::Cpu;
            const Image cpu = renderer.renderToImage(view, 160, 120, o);
            EXPECT_GT(psnrRgb(gpu, cpu), 50.0) << stops << " stops";
            EXPECT_GT(gpu.at(80, 60, 0) + gpu.at(80, 60, 1), 0.05f) << "the picture, not black";
        }
    }
}

TEST(ViewRenderer, OutsideTheImageIsBackground) {
    Fixture& f = fixture();
    const Image im = f.renderer.renderToImage({-1.0, -1.0, 2.0, 2.0}, 90, 90, linear());
    EXPECT_NEAR(im.at(5, 5, 0), renderers::kViewBackground, 1e-6);
    EXPECT_NE(im.at(45, 45, 0), renderers::kViewBackground);
}

TEST(ViewRenderer, OverlayBlendsOverTheFrameInItsRectangleOnly) {
    Fixture& f = fixture();
    // A 40x20 overlay: left half opaque white, right half black at alpha 0.5.
    Image overlay = makeImage(40, 20, {"R", "G", "B", "A"});
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 40; ++x) {
            const float v = x < 20 ? 1.0f : 0.0f;
            for (int c = 0; c < 3; ++c) overlay.at(x, y, c) = v;
            overlay.at(x, y, 3) = x < 20 ? 1.0f : 0.5f;
        }
    const int slot = 3;
    f.renderer.setOverlay(slot, overlay);
    ASSERT_TRUE(f.renderer.hasOverlay(slot));
    const codec::View view{0.0, 0.0, 1.0, 1.0};
    const Image plain = f.renderer.renderToImage(view, 160, 120, linear());
    const Image over = f.renderer.renderToImage(view, 160, 120, linear(), {{slot, 30, 50}});
    for (int y = 0; y < 120; ++y)
        for (int x = 0; x < 160; ++x) {
            const bool inside = x >= 30 && x < 70 && y >= 50 && y < 70;
            for (int c = 0; c < 3; ++c) {
                const float expected = !inside ? plain.at(x, y, c) : x < 50 ? 1.0f : 0.5f * plain.at(x, y, c);
                ASSERT_NEAR(over.at(x, y, c), expected, 1e-4) << x << "," << y << " c" << c;
            }
        }
    // Clipped at the edges, and an empty image empties the slot.
    const Image corner = f.renderer.renderToImage(view, 160, 120, linear(), {{slot, 150, -10}});
    EXPECT_NEAR(corner.at(155, 5, 0), 1.0f, 1e-4);
    EXPECT_NEAR(corner.at(140, 5, 0), plain.at(140, 5, 0), 1e-4);
    f.renderer.setOverlay(slot, Image{});
    EXPECT_FALSE(f.renderer.hasOverlay(slot));
    const Image none = f.renderer.renderToImage(view, 160, 120, linear(), {{slot, 30, 50}});
    EXPECT_NEAR(none.at(40, 60, 1), plain.at(40, 60, 1), 1e-6);
}

}  // namespace
}  // namespace conus::viewer
