// The radial comb: thin features crossing the ring just outside a focus came out as a
// starburst of streaks. Measured on a Siemens star: along any circle about its centre the star is a
// square wave of kSpokes periods, so its intensity there holds energy only at multiples of kSpokes
// cycles (and at 0). A low-pass filter of any width keeps it that way (it lowers the harmonics and
// keeps the mean of every period), so the energy a decoded view holds at 1 .. kSpokes/2 - 1 cycles
// along such a circle is aliasing: the comb. The focus is placed off the star's centre so that its
// ring crosses the spokes at every angle.
#include <cmath>
#include <complex>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"

namespace conus::codec {
namespace {

constexpr int kSource = 1024, kConus = 256, kSpokes = 48;
constexpr double kPi = 3.14159265358979323846;

// A size x size grey image whose pixel (x, y) is the mean of f over super x super sub-pixel
// centres (x + (i + 0.5) / super, y + (j + 0.5) / super), in pixels.
template <class F>
Image supersampled(int size, int super, F f) {
    Image im = makeImage(size, size, {"Y"});
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            double sum = 0;
            for (int j = 0; j < super; ++j)
                for (int i = 0; i < super; ++i) sum += f(x + (i + 0.5) / super, y + (j + 0.5) / super);
            im.at(x, y) = static_cast<float>(sum / (super * super));
        }
    return im;
}

// A 0.1 / 0.9 star of kSpokes dark and light pairs about the image centre, 4x4 supersampled.
Image siemensStar(int size) {
    return supersampled(size, 4, [size](double x, double y) {
        const double dx = x - 0.5 * size, dy = y - 0.5 * size;
        return std::sin(kSpokes * std::atan2(dy, dx)) > 0 ? 0.9 : 0.1;
    });
}

double bilinear(const Image& im, double x, double y) {
    x = std::clamp(x, 0.0, im.width - 1.001);
    y = std::clamp(y, 0.0, im.height - 1.001);
    const int xi = static_cast<int>(x), yi = static_cast<int>(y);
    const double fx = x - xi, fy = y - yi;
    return (1 - fy) * ((1 - fx) * im.at(xi, yi) + fx * im.at(xi + 1, yi)) +
           fy * ((1 - fx) * im.at(xi, yi + 1) + fx * im.at(xi + 1, yi + 1));
}

struct CircleSpectrum {
    double comb = 0;         // energy at 1 .. kSpokes/2 - 1 cycles: aliasing
    double fundamental = 0;  // energy at kSpokes cycles: the star itself
};

// The view's intensity along circles of the given radii (pixels) about the star's centre, as
// energy per frequency band, summed over the circles.
CircleSpectrum spectrum(const Image& view, const std::vector<double>& radii) {
    constexpr int kSamples = 4096;
    CircleSpectrum out;
    std::vector<double> s(kSamples);
    const double c = 0.5 * view.width;
    for (double r : radii) {
        for (int i = 0; i < kSamples; ++i) {
            const double t = 2 * kPi * i / kSamples;
            s[i] = bilinear(view, c + r * std::cos(t) - 0.5, c + r * std::sin(t) - 0.5);
        }
        const auto energy = [&](int k) {
            std::complex<double> sum = 0;
            for (int i = 0; i < kSamples; ++i) sum += s[i] * std::polar(1.0, -2 * kPi * k * i / kSamples);
            return 2 * std::norm(sum / double(kSamples));
        };
        for (int k = 1; k < kSpokes / 2; ++k) out.comb += energy(k);
        out.fundamental += energy(kSpokes);
    }
    return out;
}

// The old encoder's filter, exactly: the mean of the source over the CoNUS pixel's footprint (a
// 8x8 grid of sub-pixels, each undistorted exactly), no low-pass beyond the pixel's own box.
Image boxEncode(const Image& src, const SamplingMap& map, int size) {
    return supersampled(size, 8, [&](double x, double y) {
        const glm::dvec2 p = map.undistort({x / size, y / size});
        return bilinear(src, p.x * src.width - 0.5, p.y * src.height - 0.5);
    });
}

TEST(Comb, FocusRingOfASiemensStarAliasesNoMoreThanUniform) {
    const Image star = siemensStar(kSource);
    const std::vector<Focus> foci = {{0.5, 0.4, 0.1, 3}};  // the repro
    const Image uniform = resizeBilinear(areaDownsample(star, kConus, kConus), View{}, kSource, kSource);
    // Circles 200 .. 280 pixels from the star's centre cross the focus's ring (the focus spans
    // about 100 pixels about (512, 410)); the uniform image resolves the star there (a period of
    // 26 to 37 source pixels is 6.5 to 9 uniform pixels), so its comb is near its floor.
    const std::vector<double> radii = {200, 220, 240, 260, 280};
    const CircleSpectrum u = spectrum(uniform, radii);
    // The default focus (1.25), the files' old default (2), one between and a wide log-shaped one. With
    // maps whose anisotropy was unbounded, steeper rims combed more (1.25: +2.9 dB on this star,
    // bench/notes/2026-11-24-quality-ring-check.md); the bounded builder widens a rim too steep for
    // its bound, and the narrow default now combs least (bench/notes/2026-11-27-narrow-transitions.md).
    for (const FociFalloff& falloff : {FociFalloff{}, kFormatFalloff, FociFalloff{1.75, FociFalloffShape::Density},
                                       FociFalloff{3.0, FociFalloffShape::LogRadius}}) {
        FociOptions options;
        options.falloff = falloff;
        const SamplingMap map = buildFociMap(foci, options);
        EncodeOptions encode;
        encode.width = encode.height = kConus;
        DecodeOptions decode;
        decode.width = decode.height = kSource;

        const Image conus = decodeImage(encodeImage(star, map, encode), map, decode);
        const Image box = decodeImage(boxEncode(star, map, kConus), map, decode);
        const CircleSpectrum c = spectrum(conus, radii), b = spectrum(box, radii);
        const auto dB = [](double x, double y) { return 10 * std::log10(x / y); };
        std::printf("[ info ] falloff %s: comb energy in the focus ring: CoNUS %.3g (%+.2f dB vs uniform), plain box filter %.3g "
                    "(%+.2f dB), uniform %.3g; star fundamental: CoNUS %.3g, uniform %.3g\n",
                    falloffText(falloff).c_str(), c.comb, dB(c.comb, u.comb), b.comb, dB(b.comb, u.comb), u.comb, c.fundamental,
                    u.fundamental);
        // The target for the aliasing check in the ring: within 1 dB of uniform's.
        EXPECT_LT(dB(c.comb, u.comb), 1.0) << falloffText(falloff);
        // The measure sees the comb: the pixel's box alone (the old filter) is well above it (less
        // so since maps keep their anisotropy bounded: +2.9 dB with the widest ring).
        EXPECT_GT(dB(b.comb, u.comb), 2.5) << falloffText(falloff);
        // And the filter removes the comb, not the star: the spokes keep most of their contrast
        // (energy at the star's own frequency at least a quarter of the uniform image's).
        EXPECT_GT(c.fundamental, 0.25 * u.fundamental) << falloffText(falloff);
    }
}

// The encoder fitted to the decoder (fit.h). The least-squares fit is sharper than any prefilter
// and so keeps more of the star's harmonics above the rate, which alias: fitted without damping,
// the uniform image's comb rises by about 5 dB and CoNUS's by 13 dB (its ring's long footprints,
// which the EWA filter had low-passed). The fit therefore holds those pixels toward the EWA
// image (FitOptions::holdLowPass); the measure: the fitted CoNUS ring aliases no more than the
// uniform image fitted the same way, within the same 1 dB, and keeps the star.
TEST(Comb, FittedEncodeKeepsTheRingClean) {
    const Image star = siemensStar(kSource);
    const std::vector<Focus> foci = {{0.5, 0.4, 0.1, 3}};
    EncodeOptions encode;
    encode.width = encode.height = kConus;
    DecodeOptions decode;
    decode.width = decode.height = kSource;
    Image uniform = areaDownsample(star, kConus, kConus);
    const Image plainUniform = resizeBilinear(uniform, View{}, kSource, kSource);
    fitToDecoder(star, SamplingMap::identity(2, 2), uniform);
    const std::vector<double> radii = {200, 220, 240, 260, 280};
    const CircleSpectrum u = spectrum(plainUniform, radii);
    const CircleSpectrum fu = spectrum(resizeBilinear(uniform, View{}, kSource, kSource), radii);
    const auto dB = [](double x, double y) { return 10 * std::log10(x / y); };

    // The default focus (1.25), the files' old default (2) and one between.
    for (const FociFalloff& falloff : {FociFalloff{}, kFormatFalloff, FociFalloff{1.75, FociFalloffShape::Density}}) {
        FociOptions options;
        options.falloff = falloff;
        const SamplingMap map = buildFociMap(foci, options);
        Image conus = encodeImage(star, map, encode);
        const FitResult fit = fitToDecoder(star, map, conus);
        const CircleSpectrum c = spectrum(decodeImage(conus, map, decode), radii);
        std::printf("[ info ] falloff %s, comb energy in the focus ring, fitted: CoNUS %.3g (%+.2f dB vs uniform), fitted "
                    "uniform %.3g (%+.2f dB), CoNUS vs fitted uniform %+.2f dB; fundamental %.3g vs %.3g; decoded PSNR "
                    "%.2f -> %.2f dB\n",
                    falloffText(falloff).c_str(), c.comb, dB(c.comb, u.comb), fu.comb, dB(fu.comb, u.comb),
                    dB(c.comb, fu.comb), c.fundamental, u.fundamental, fit.steps.front().psnr, fit.steps.back().psnr);
        EXPECT_LT(dB(c.comb, fu.comb), 1.0) << falloffText(falloff);
        EXPECT_GT(c.fundamental, 0.25 * u.fundamental) << falloffText(falloff);
        EXPECT_GT(fit.steps.back().psnr, fit.steps.front().psnr + 1.0) << falloffText(falloff);
        if (falloff.width != FociFalloff{}.width) continue;
        // Without the hold the measure sees the comb come back.
        Image unheld = encodeImage(star, map, encode);
        FitOptions plain;
        plain.holdLowPass = 0;
        fitToDecoder(star, map, unheld, plain);
        const CircleSpectrum uc = spectrum(decodeImage(unheld, map, decode), radii);
        std::printf("[ info ] without the hold: CoNUS comb %.3g (%+.2f dB vs the fitted uniform image)\n", uc.comb,
                    dB(uc.comb, fu.comb));
        EXPECT_GT(dB(uc.comb, fu.comb), 3.0);
    }
}

}  // namespace
}  // namespace conus::codec
