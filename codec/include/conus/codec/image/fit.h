// An encoder fitted to its decoder: the CoNUS image whose decoded view is closest to the source.
//
// The CPU decoder's whole-image view at the source's size (decodeImage, no pyramid) is linear in
// the CoNUS pixels: view = D c, each output pixel one bilinear tap at Eq. 1 of its centre where
// the CoNUS image is magnified, the decoder's average of up to kDecodeMaxTaps^2 bilinear taps
// where it is minified (the same taps, exactly). fitToDecoder refines an encoded image c0 (the
// EWA encode, encodeImage) toward the least-squares fit
//     c* = argmin ||D c - s||^2 + sum_j h_j diag_j (c_j - c0_j)^2,   diag = diag(D^T D),
// h_j = damping + holdLowPass * (share of pixel j's footprint the encoder low-passed, below),
// by conjugate gradients on the normal equations (CGLS, Jacobi-preconditioned: a CoNUS pixel of
// the context covers up to ~100 source pixels, one in a focus about one). The undamped fit is the
// orthogonal projection of the source onto the decoder's reconstruction space: the L2-best image,
// but sharper than any prefilter, so it keeps harmonics above the local rate that alias; the
// damping per pixel (below) holds the ring's long footprints to their low-pass.
//
// Colour and alpha channels are fitted; a channel named "Z" (depth) is left as it was. Values are
// not clamped: a fit overshoots at hard edges like any L2 projection (FitResult counts the values
// below 0). CoNUS pixels no tap reaches keep their value. Cost: the normal equations D^T D c = D^T s
// are assembled on the CoNUS grid in one walk of Eq. 1 over the source's rows (D^T D is a 3x3
// stencil per CoNUS pixel where the view magnifies, plus the rows of D where it minifies), and the
// iterations run on them; where the view minifies most of the image, each iteration walks the
// source's rows twice instead. Memory: the CoNUS image some ten times over (no per-source-pixel
// storage). The same fit serves
// the uniform baseline (the identity map: D is then resizeBilinear to the source's size).
#pragma once

#include <cstdint>
#include <vector>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/enum_names.h"
#include "conus/core/error.h"
#include "conus/core/image.h"

namespace conus::codec {

// Default iterations: the decoded PSNR of astronaut and chelsea (two foci, 1/16) stops rising
// after 2-3 (bench/notes/2026-11-24-quality-fit-to-decoder.md: the PSNR per iteration). Damping
// (0: none where the encoder kept the box filter) and hold: where the encoder low-passed a long
// footprint axis (encode.h's rule against the radial comb), the damping grows by kFitHoldLowPass
// times the share of that low-pass (the Gaussian's extent beyond the box, at most 1). Without it
// the fit undoes that filter and the comb comes back (+13 dB in tests/codec/image/comb_test.cpp);
// with 3 the ring aliases as much as the uniform image fitted the same way.
inline constexpr int kFitIterations = 4;
// What `encode` (and conus.encode) runs by default: on the photographs of bench/quality.py the
// third and fourth iterations add 0.01-0.05 dB and cost half the fit's time.
inline constexpr int kDefaultEncodeFitIterations = 2;
inline constexpr double kFitDamping = 0.0;
inline constexpr double kFitHoldLowPass = 3.0;

// How the fit is found.
//  - LeastSquares: conjugate gradients on the normal equations through the decoder's taps at the
//    source's size, as above: one walk of every source pixel, then the iterations on the CoNUS grid.
//  - Local: one pass over the CoNUS image. Where the decoder magnifies (a CoNUS pixel covers a
//    source pixel or more), re-encoding the decoded view is a fixed convolution in CoNUS pixel units,
//    whatever the map: the encoder's unit box over the decoder's bilinear tent, [q, 1 - 2q, q] along
//    each axis (q = 1/8 for the exact box). The fit inverts it, c = K^-1 c0 (a separable filter,
//    q's geometric series cut where it falls below 1e-3): the CoNUS image whose decoded view
//    re-encodes to c0, the "consistent" reconstruction of sampling theory. The correction c - c0 is
//    scaled by 1 / (1 + hold) like the least squares' damping (holdLowPass times the low-pass share)
//    and fades where a CoNUS pixel's short axis covers less than a source pixel (there the decoder
//    minifies the CoNUS image and K no longer holds). No decoded view is made: FitResult::steps is empty.
enum class FitMethod { LeastSquares, Local };
constexpr auto enumNameTable(FitMethod) {
    return makeEnumNameTable<FitMethod>("fit method", {{FitMethod::LeastSquares, "least-squares"}, {FitMethod::Local, "local"}},
                                        true);
}
// q of the Local fit: the side weight of the encode-then-decode kernel along each axis. 1/8 is the
// exact box's; the anisotropic encoder's pyramid levels blur a little more.
inline constexpr double kFitLocalSide = 0.125;
// What `encode` fits with by default: the least squares. The local fit keeps most of the fit's gain
// inside the foci (0.2-0.6 dB below it on astronaut and the dogs) but a fifth of it over the whole
// frame, where the context holds detail above its sampling rate and only the least squares (the
// orthogonal projection) uses it (bench/notes/2026-12-06-encode-speed.md); it stays an option.
inline constexpr FitMethod kDefaultEncodeFitMethod = FitMethod::LeastSquares;

struct FitOptions {
    int iterations = kFitIterations;  // 0 measures only
    double damping = kFitDamping;     // >= 0, relative to each CoNUS pixel's own weight diag_j
    double holdLowPass = kFitHoldLowPass;  // >= 0, added where the encoder low-passed a long axis
    int threads = 0;
    ProgressFn progress;
    FitMethod method = FitMethod::LeastSquares;
    double localSide = kFitLocalSide;  // Local: q, in (0, 0.25)
    // The encode's low-pass share of each CoNUS pixel (EncodeOptions::lowPassShare), the same
    // values the least squares would find from the map; found from the map where this is null or
    // not one value a pixel of the CoNUS image.
    const std::vector<float>* lowPassShare = nullptr;
};

// The decoded view's error against the source over the fitted channels after `iteration`
// iterations (0: the image given), and the minimized objective (its sum of squares plus the
// damping term).
struct FitStep {
    int iteration = 0;
    double rms = 0, psnr = 0;  // PSNR for a peak of 1 (linear light)
    double objective = 0;
};

struct FitResult {
    std::vector<FitStep> steps;   // iterations 0 .. the last one run
    std::int64_t negatives = 0;   // fitted values below 0 in the result
    float minimum = 0, maximum = 0;  // over the fitted channels of the result
};

// Fits `conus` (in place; the encode of `source` through `map`, same channels in the same order)
// to the decoder's view at source.width x source.height. `conus` is read as the fit's starting
// point until the call returns (options.progress must not change it). Throws
// conus::Error(InvalidArgument) when the channels differ or options are out of range.
FitResult fitToDecoder(const Image& source, const SamplingMap& map, Image& conus, const FitOptions& options = {});

}  // namespace conus::codec
