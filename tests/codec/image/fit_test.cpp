// The encoder fitted to its decoder (fit.h): the operator it inverts is the decoder, its transpose
// is the true adjoint, and the fit lowers the decoded view's error step by step below the EWA
// encode's, on pictures with hard edges, texture and smooth shading through asymmetric foci.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "../../../codec/src/image/fit_pvt.h"
#include "../../../codec/src/image/resize_rows_pvt.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
#include "conus/codec/image/metrics.h"
#include "error_code.h"
#include "test_images.h"

namespace conus::codec {
namespace {

// Two foci of different size and strength, off centre, on a non-square frame.
SamplingMap twoFoci(double aspect) {
    FociOptions options;
    options.aspect = aspect;
    options.columns = options.rows = 65;
    const std::vector<Focus> foci = {{0.32, 0.4, 0.09, 4}, {0.71, 0.62, 0.06, 3}};
    return buildFociMap(foci, options);
}

double dot(const Image& a, const Image& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) sum += double(a.pixels[i]) * b.pixels[i];
    return sum;
}

// The decode of the whole frame at width x height; sourceView: at the source's size.
DecodeOptions viewOf(int width, int height) {
    DecodeOptions d;
    d.width = width;
    d.height = height;
    return d;
}
DecodeOptions sourceView(const Image& source) { return viewOf(source.width, source.height); }

// Magnified (the view finer than the CoNUS image everywhere) and minified in the foci (several
// taps per output pixel there): the CoNUS size against a 300x200 view.
struct Case {
    int conusWidth, conusHeight, channels;
};
const Case kCases[] = {{75, 50, 3}, {240, 170, 1}, {150, 100, 4}};

// Noise of the case's channel count (R, G, B, A in that order), w x h.
Image caseNoise(const Case& c, int w, int h, unsigned seed) {
    std::vector<std::string> names = {"R", "G", "B", "A"};
    names.resize(c.channels);
    return test::noise(w, h, names, seed);
}

TEST(Fit, ForwardIsTheDecoder) {
    const SamplingMap map = twoFoci(1.5);
    for (const Case& c : kCases) {
        const Image sized = caseNoise(c, c.conusWidth, c.conusHeight, 3);
        const DecodeOptions d = viewOf(300, 200);
        const Image decoded = decodeImage(sized, map, d);
        const Image forward = detail::fitForward(sized, map, 300, 200, 2);
        EXPECT_LT(test::maxAbsDifference(decoded, forward), 2e-5f) << c.conusWidth << "x" << c.conusHeight;
    }
}

TEST(Fit, AdjointIdentityThroughAFocusMap) {
    const SamplingMap map = twoFoci(1.5);
    for (const Case& c : kCases) {
        const Image x = caseNoise(c, c.conusWidth, c.conusHeight, 5);
        Image y = caseNoise(c, 300, 200, 6);
        for (float& v : y.pixels) v -= 0.5f;  // signed, so that no sum is dominated by a mean
        const Image dx = detail::fitForward(x, map, 300, 200, 3);
        const Image dty = detail::fitAdjoint(y, map, c.conusWidth, c.conusHeight, 3);
        const double lhs = dot(dx, y), rhs = dot(x, dty);
        EXPECT_NEAR(lhs, rhs, 1e-5 * (std::abs(lhs) + std::abs(rhs)) + 1e-6)
            << c.conusWidth << "x" << c.conusHeight << "x" << c.channels;
        // Not a trivial identity: the splat moved mass (its total is the view's weighted total).
        EXPECT_GT(std::abs(lhs), 1.0);
        // The same sums whatever the thread count (bands are fixed, their sums added in order).
        EXPECT_EQ(test::maxAbsDifference(dty, detail::fitAdjoint(y, map, c.conusWidth, c.conusHeight, 1)), 0.0f);
    }
}

// What the budget's confirmation measures without keeping a view at the source's size: the
// decoder's view of a band of rows (a view of those rows alone) is those rows of the whole view,
// and the uniform image's bilinear resize a row at a time is resizeBilinear's.
TEST(Fit, BandsOfTheViewAreTheWholeViewsRows) {
    const SamplingMap map = twoFoci(1.5);
    for (const Case& c : kCases) {
        const Image x = caseNoise(c, c.conusWidth, c.conusHeight, 9);
        const DecodeOptions d = viewOf(300, 200);
        const Image decoded = decodeImage(x, map, d), resized = resizeBilinear(x, View{}, 300, 200);
        Image bands = decoded, flat = resized;
        std::fill(bands.pixels.begin(), bands.pixels.end(), -1.0f);
        const detail::ResizedRows bilinear(x, 300, 200);
        const std::size_t row = std::size_t(300) * c.channels;
        for (int y0 = 0; y0 < 200; y0 += 37) {  // bands of 37 rows, the last one shorter
            DecodeOptions band = d;
            band.height = std::min(37, 200 - y0);
            band.view = {0.0, y0 / 200.0, 1.0, (y0 + band.height) / 200.0};
            const Image part = decodeImage(x, map, band);
            std::copy(part.pixels.begin(), part.pixels.end(), bands.pixels.begin() + std::ptrdiff_t(y0 * row));
        }
        for (int y = 0; y < 200; ++y) bilinear.row(y, flat.pixels.data() + std::size_t(y) * row);
        EXPECT_LT(test::maxAbsDifference(decoded, bands), 1e-5f) << c.conusWidth << "x" << c.conusHeight;
        EXPECT_EQ(test::maxAbsDifference(resized, flat), 0.0f) << c.conusWidth << "x" << c.conusHeight;
        EXPECT_GT(test::maxAbsDifference(decoded, resized), 0.05f);  // the two views differ: not one image twice
    }
}

// The normal equations' matrix, assembled as a stencil (and wide rows where the foci minify),
// is D^T D: A x against the adjoint of the forward view, on the magnified and the minified cases.
TEST(Fit, AssembledNormalEquationsAreDtD) {
    const SamplingMap map = twoFoci(1.5);
    std::size_t mostWide = 0;
    for (const Case& c : kCases) {
        const Image x = caseNoise(c, c.conusWidth, c.conusHeight, 7);
        std::size_t wide = 0;
        const Image ax = detail::fitNormalProduct(x, map, 300, 200, &wide, 2);
        const Image dtdx = detail::fitAdjoint(detail::fitForward(x, map, 300, 200, 2), map, c.conusWidth, c.conusHeight, 2);
        float largest = 0;
        for (const float v : dtdx.pixels) largest = std::max(largest, std::abs(v));
        EXPECT_GT(largest, 1.0f);
        EXPECT_LT(test::maxAbsDifference(ax, dtdx), 2e-5f * largest) << c.conusWidth << "x" << c.conusHeight;
        // The same whatever the thread count (the bands' sums in order).
        EXPECT_EQ(test::maxAbsDifference(ax, detail::fitNormalProduct(x, map, 300, 200, nullptr, 1)), 0.0f);
        mostWide = std::max(mostWide, wide);
    }
    // The 240x170 case minifies in the foci: some output pixels' taps reach past a 2x2 block.
    EXPECT_GT(mostWide, 0u);
}

// The fit of `encoded` as fitToDecoder chooses to make it, and as the forced walk of the taps.
struct FitBothWays {
    Image usualImage, walkedImage;
    FitResult usual, walked;
    FitBothWays(const Image& source, const SamplingMap& map, const Image& encoded, int iterations)
        : usualImage(encoded), walkedImage(encoded) {
        FitOptions f;
        f.iterations = iterations;
        usual = fitToDecoder(source, map, usualImage, f);
        detail::forceFitPasses(true);
        walked = fitToDecoder(source, map, walkedImage, f);
        detail::forceFitPasses(false);
    }
};

// A CoNUS image squeezed across (the view minifies it about 1.9x along x and magnifies it 2.2x
// along y): most output pixels' taps reach past a 2x2 block, several output rows a CoNUS row, more
// wide rows than the assembly keeps. The assembly is abandoned part way and the fit walks the taps
// instead, taking exactly the steps the forced walk takes.
TEST(Fit, AnAbandonedAssemblyWalksTheTaps) {
    const Image source = test::photoLike(300, 200, {"R", "G", "B"});
    const SamplingMap map = twoFoci(1.5);
    EncodeOptions e;
    e.width = 560;
    e.height = 90;
    const Image encoded = encodeImage(source, map, e);
    EXPECT_THROW(detail::fitNormalProduct(encoded, map, 300, 200), Error);
    const FitBothWays fits(source, map, encoded, 2);
    const FitResult &a = fits.usual, &w = fits.walked;
    ASSERT_EQ(a.steps.size(), w.steps.size());
    for (std::size_t i = 0; i < a.steps.size(); ++i) EXPECT_EQ(a.steps[i].psnr, w.steps[i].psnr) << i;
    EXPECT_EQ(test::maxAbsDifference(fits.usualImage, fits.walkedImage), 0.0f);
    EXPECT_GT(test::maxAbsDifference(fits.usualImage, encoded), 1e-3f);  // the fit moved the pixels
    EXPECT_GT(a.steps.back().psnr, a.steps[0].psnr);
}

// The assembled fit and the one that walks the taps every iteration take the same steps where the
// view magnifies, and the assembled ones are no worse where it minifies.
TEST(Fit, AssembledFitMatchesThePasses) {
    const Image source = test::photoLike(300, 200, {"R", "G", "B"});
    const SamplingMap map = twoFoci(1.5);
    for (const Case& c : {Case{75, 50, 3}, Case{240, 170, 3}}) {
        EncodeOptions e;
        e.width = c.conusWidth;
        e.height = c.conusHeight;
        const Image encoded = encodeImage(source, map, e);
        std::size_t wide = 0;
        detail::fitNormalProduct(encoded, map, 300, 200, &wide);  // throws where the fit would not assemble
        const FitBothWays fits(source, map, encoded, 3);
        const FitResult &a = fits.usual, &w = fits.walked;
        ASSERT_EQ(a.steps.size(), w.steps.size());
        EXPECT_NEAR(a.steps[0].psnr, w.steps[0].psnr, 1e-3);
        // Magnified, the two are the same iterations. Minified (wide rows), the walk's Jacobi
        // diagonal sums each corner's square apart where the assembly merges the corners that fall on
        // one CoNUS pixel first (the true diag(D^T D)): the assembly's steps are better there.
        for (std::size_t i = 1; i < a.steps.size(); ++i) {
            if (wide == 0) EXPECT_NEAR(a.steps[i].psnr, w.steps[i].psnr, 0.02) << i;
            else EXPECT_GT(a.steps[i].psnr, w.steps[i].psnr - 0.02) << i;
        }
        EXPECT_GT(a.steps.back().psnr, a.steps[0].psnr + 0.3);
        const double decoded = psnr(decodeImage(fits.usualImage, map, sourceView(source)), source);
        EXPECT_NEAR(decoded, a.steps.back().psnr, 0.01) << c.conusWidth << "x" << c.conusHeight;
        std::printf("[ info ] %dx%d (%zu wide rows): assembled %.3f dB, walked %.3f dB\n", c.conusWidth, c.conusHeight, wide,
                    a.steps.back().psnr, w.steps.back().psnr);
    }
}

// The encode hands the fit each CoNUS pixel's low-pass share (EncodeOptions::lowPassShare): the
// values the fit finds from the map, so a fit given them is the same fit, bit for bit. On a focus
// map the share is neither all 0 nor all 1 (the rims low-pass, the context keeps the box).
TEST(Fit, TheEncodesLowPassShareIsTheFitsOwn) {
    const Image source = test::photoLike(300, 200, {"R", "G", "B"});
    const SamplingMap map = twoFoci(1.5);
    for (const EncodeFilter filter : {EncodeFilter::Anisotropic, EncodeFilter::Ewa}) {
        std::vector<float> share = {7.0f};  // stale contents are replaced
        EncodeOptions e;
        e.width = 75;
        e.height = 50;
        e.filter = filter;
        e.lowPassShare = &share;
        const Image encoded = encodeImage(source, map, e);
        ASSERT_EQ(share.size(), 75u * 50u);
        EXPECT_GT(*std::max_element(share.begin(), share.end()), 0.1f);
        EXPECT_EQ(*std::min_element(share.begin(), share.end()), 0.0f);

        Image own = encoded, given = encoded;
        FitOptions f;
        f.iterations = 3;
        const FitResult a = fitToDecoder(source, map, own, f);
        f.lowPassShare = &share;
        const FitResult b = fitToDecoder(source, map, given, f);
        EXPECT_EQ(own.pixels, given.pixels);
        EXPECT_EQ(a.steps.back().psnr, b.steps.back().psnr);
        // The share is taken: another one of the right size gives another fit. One of another size
        // (another encode's) is not: the fit finds its own.
        const std::vector<float> ones(share.size(), 1.0f), wrong(10, 1.0f);
        Image held = encoded, other = encoded;
        f.lowPassShare = &ones;
        fitToDecoder(source, map, held, f);
        EXPECT_NE(own.pixels, held.pixels);
        f.lowPassShare = &wrong;
        fitToDecoder(source, map, other, f);
        EXPECT_EQ(own.pixels, other.pixels);
    }
}

TEST(Fit, ResidualFallsAndBeatsTheEwaEncode) {
    const Image source = test::photoLike(360, 240, {"R", "G", "B"});
    const SamplingMap map = twoFoci(1.5);
    EncodeOptions e;
    e.width = 90;
    e.height = 60;  // 1/16 of the pixels
    e.filter = EncodeFilter::Ewa;
    const Image ewa = encodeImage(source, map, e);
    const double before = psnr(decodeImage(ewa, map, sourceView(source)), source);

    // The plain least-squares fit: its residual falls at every iteration.
    Image fitted = ewa;
    FitOptions f;
    f.iterations = 10;
    f.holdLowPass = 0;
    const FitResult r = fitToDecoder(source, map, fitted, f);
    ASSERT_EQ(r.steps.size(), 11u);
    // Step 0 is the EWA image measured through the operator: the decoder's own PSNR.
    EXPECT_NEAR(r.steps[0].psnr, before, 0.01);
    for (std::size_t i = 1; i < r.steps.size(); ++i) {
        EXPECT_LE(r.steps[i].rms, r.steps[i - 1].rms * (1 + 1e-6)) << "iteration " << i;
        // Undamped, the objective is the residual's sum of squares.
        const double squares = r.steps[i].rms * r.steps[i].rms * 360 * 240 * 3;
        EXPECT_NEAR(r.steps[i].objective, squares, 1e-6 * squares);
        std::printf("[ info ] fit iteration %zu: decoded PSNR %.2f dB\n", i, r.steps[i].psnr);
    }
    const double after = psnr(decodeImage(fitted, map, sourceView(source)), source);
    EXPECT_NEAR(after, r.steps.back().psnr, 0.01);
    std::printf("[ info ] EWA encode %.2f dB, fitted %.2f dB; %lld values below 0 (min %.3f)\n", before, after,
                static_cast<long long>(r.negatives), r.minimum);
    EXPECT_GT(after, before + 0.6);

    // The default holds the long footprints toward the EWA image (and damping holds every pixel):
    // the damped objective falls at every iteration, and the result lands between the two.
    for (double damping : {0.0, 1.0}) {
        Image held = ewa;
        FitOptions d;
        d.iterations = 10;
        d.damping = damping;
        const FitResult rd = fitToDecoder(source, map, held, d);
        for (std::size_t i = 1; i < rd.steps.size(); ++i)
            EXPECT_LE(rd.steps[i].objective, rd.steps[i - 1].objective * (1 + 1e-6)) << "damped iteration " << i;
        const double between = psnr(decodeImage(held, map, sourceView(source)), source);
        std::printf("[ info ] damping %g with the hold: %.2f dB\n", damping, between);
        EXPECT_GT(between, before + 0.1);
        EXPECT_LT(between, after);
    }
}

TEST(Fit, UniformImageFittedToBilinear) {
    const Image source = test::photoLike(320, 200, {"R", "G", "B"});
    const SamplingMap identity = SamplingMap::identity(2, 2);
    const Image area = areaDownsample(source, 80, 50);
    Image fitted = area;
    fitToDecoder(source, identity, fitted);
    // The identity map's decoder is the bilinear resize the uniform baseline is shown with.
    const double before = psnr(resizeBilinear(area, View{}, 320, 200), source);
    const double after = psnr(resizeBilinear(fitted, View{}, 320, 200), source);
    std::printf("[ info ] uniform: area %.2f dB, fitted %.2f dB\n", before, after);
    EXPECT_GT(after, before + 0.5);
}

TEST(Fit, DepthStaysAndAlphaIsFitted) {
    const Image source = test::photoLike(240, 160, {"R", "G", "B", "A", "Z"});
    const SamplingMap map = twoFoci(1.5);
    EncodeOptions e;
    e.width = 60;
    e.height = 40;
    e.filter = EncodeFilter::Ewa;
    const Image ewa = encodeImage(source, map, e);
    for (const FitMethod method : {FitMethod::LeastSquares, FitMethod::Local}) {
        Image fitted = ewa;
        FitOptions f;
        f.method = method;
        fitToDecoder(source, map, fitted, f);
        const int a = fitted.channelIndex("A"), z = fitted.channelIndex("Z");
        double zChange = 0, aChange = 0;
        for (std::size_t p = 0; p < fitted.pixels.size() / 5; ++p) {
            zChange = std::max(zChange, double(std::abs(fitted.pixels[p * 5 + z] - ewa.pixels[p * 5 + z])));
            aChange = std::max(aChange, double(std::abs(fitted.pixels[p * 5 + a] - ewa.pixels[p * 5 + a])));
        }
        EXPECT_EQ(zChange, 0.0) << enumName(method);
        EXPECT_GT(aChange, 1e-3) << enumName(method);
    }
}

// The local fit under a uniform map at a ratio of 4 (the EWA encode is then the exact box): the
// decoded view of the fitted image re-encodes to the encode it started from (the consistent
// reconstruction), away from the borders where the decoder clamps; a constant stays constant;
// and the decoded view comes closer to the source than the encode's.
TEST(Fit, LocalFitReencodesToTheEncode) {
    const Image source = test::photoLike(320, 240, {"R", "G", "B"});
    const SamplingMap identity = SamplingMap::identity(5, 5);
    EncodeOptions e;
    e.width = 80;
    e.height = 60;
    e.filter = EncodeFilter::Ewa;
    const Image c0 = encodeImage(source, identity, e);
    Image fitted = c0;
    FitOptions f;
    f.method = FitMethod::Local;
    const FitResult r = fitToDecoder(source, identity, fitted, f);
    EXPECT_TRUE(r.steps.empty());
    const Image view = detail::fitForward(fitted, identity, 320, 240);
    const Image again = encodeImage(view, identity, e);
    double worst = 0, change = 0;
    for (int y = 6; y < 54; ++y)
        for (int x = 6; x < 74; ++x)
            for (int c = 0; c < 3; ++c) {
                worst = std::max(worst, double(std::abs(again.at(x, y, c) - c0.at(x, y, c))));
                change = std::max(change, double(std::abs(fitted.at(x, y, c) - c0.at(x, y, c))));
            }
    EXPECT_GT(change, 0.05) << "the fit should change the image";
    EXPECT_LT(worst, 2e-3) << "E D c should give back c0 (the kernel's inverse is cut at 1e-3)";
    EXPECT_GT(psnr(detail::fitForward(fitted, identity, 320, 240), source),
              psnr(detail::fitForward(c0, identity, 320, 240), source) + 0.3);

    Image flat = makeImage(80, 60, {"Y"});
    std::fill(flat.pixels.begin(), flat.pixels.end(), 0.375f);
    Image flatSource = makeImage(320, 240, {"Y"});
    fitToDecoder(flatSource, identity, flat, f);
    for (const float v : flat.pixels) ASSERT_NEAR(v, 0.375f, 1e-6f);

    FitOptions bad = f;
    bad.localSide = 0.25;
    Image any = c0;
    EXPECT_EQ(test::codeOf([&] { fitToDecoder(source, identity, any, bad); }), ErrorCode::InvalidArgument);
}

TEST(Fit, RefusesMismatchedInput) {
    const Image source = test::photoLike(120, 80, {"R", "G", "B"});
    const SamplingMap map = twoFoci(1.5);
    Image grey = test::noise(30, 20, {"Y"});
    EXPECT_EQ(test::codeOf([&] { fitToDecoder(source, map, grey); }), ErrorCode::InvalidArgument);
    Image rgb = test::noise(30, 20, {"R", "G", "B"});
    FitOptions f;
    f.iterations = -1;
    EXPECT_EQ(test::codeOf([&] { fitToDecoder(source, map, rgb, f); }), ErrorCode::InvalidArgument);
    f.iterations = 2;
    f.damping = std::nan("");
    EXPECT_EQ(test::codeOf([&] { fitToDecoder(source, map, rgb, f); }), ErrorCode::InvalidArgument);
}

}  // namespace
}  // namespace conus::codec
