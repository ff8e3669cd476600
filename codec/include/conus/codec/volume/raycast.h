// The CPU reference of volume rendering through the FPC: CoNUS ray casting (paper section 3.2,
// "Volume data"). For every CoNUS pixel, its undistorted image position by the FPC's exact inverse
// (Fpc::ray), the camera's ray through it, clipped to the volume's box and to the camera's near
// and far depths, then front-to-back emission-absorption compositing of trilinear samples through
// the transfer function (transfer_function.h), stopping once the opacity reaches
// kTerminationOpacity. An identity Fpc (null distortion) renders the conventional image.
//
// The sampling both renderers share (renderers/volume.h is the GL twin and matches this):
// - world space: sample (i, j, k) sits at (i, j, k) * spacing; the box is [0, extent];
// - steps of `stepVoxels` times the smallest spacing along the unit ray direction, the first at
//   tEnter + jitter * step, jitter = pixelJitter(x, y) (a hash of the pixel: deterministic, the
//   same on both, and it turns wood-grain banding into fine noise), or 0.5 with jitter off;
// - values normalized to [0,1] over the options' range (the volume's min..max by default);
// - Z: the camera depth of the first sample at which the accumulated opacity reaches
//   `depthOpacity`, the camera's far where it never does.
// Output channels kVolumeChannels: R, G, B (premultiplied by A), A, Z.
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "conus/codec/volume/transfer_function.h"
#include "conus/core/error.h"
#include "conus/core/fpc.h"
#include "conus/core/image.h"
#include "conus/core/volume.h"

namespace conus::codec {

inline constexpr std::array<const char*, 5> kVolumeChannels = {"R", "G", "B", "A", "Z"};
inline constexpr float kTerminationOpacity = 0.99f;

struct VolumeRenderOptions {
    double stepVoxels = 0.5;   // step length in units of the smallest spacing, in (0, 16]
    float depthOpacity = 0.5f; // Z where the accumulated opacity first reaches this, in (0, 1)
    bool jitter = true;
    // The value range mapped to the transfer function's [0,1]; lo == hi: the volume's min..max.
    float rangeLo = 0, rangeHi = 0;
    int threads = 0;  // 0: all cores
    ProgressFn progress;
};

// The volume's smallest and largest sample.
glm::vec2 valueRange(const Volume& volume);
// The range a render uses: the options' when given, else valueRange (hi > lo always: a constant
// volume gets hi = lo + 1).
glm::vec2 renderRange(const Volume& volume, const VolumeRenderOptions& options);

// The per-pixel start offset in [0,1): a 32-bit integer hash of (x, y). The GLSL twin is
// pixelJitter in renderers/shaders/volume.frag.glsl.
float pixelJitter(int x, int y);

// Checks the output size and the options: conus::Error(InvalidArgument) otherwise. Every
// renderer calls it, after checkVolume (core/volume.h).
void checkVolumeRenderOptions(int width, int height, const VolumeRenderOptions& options);

// A ray's steps are bounded by the volume's size: at most kMaxRayStepsPerSample times
// width + height + depth across the box's diagonal. A step too small for that is refused with
// InvalidArgument (give a larger step); a spacing so uneven that a usual step exceeds it
// (the step follows the smallest spacing) with LimitExceeded. Every renderer calls it.
void checkRaySteps(const Volume& volume, double stepVoxels);

Image renderVolumeReference(const Volume& volume, const TransferFunction& tf, const Fpc& fpc, int width, int height,
                            const VolumeRenderOptions& options = {});

// One ray of `camera`'s through undistorted image position uv with start offset `jitter`:
// R, G, B, A, Z. `range` from renderRange. `steps`, when given, receives the samples taken (the
// ray's cost, for the benchmarks).
std::array<float, 5> castVolumeRay(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                                   glm::dvec2 uv, float jitter, glm::vec2 range, const VolumeRenderOptions& options,
                                   int* steps = nullptr);

// A perspective camera that frames the whole volume: looking at the box's centre from a fixed
// oblique direction (from the front, a little above and to the side), at the distance where the
// box's bounding sphere fills the vertical field of view; near and far bracket the sphere.
Camera defaultVolumeCamera(const Volume& volume, double aspect, double fovYDegrees = 30.0);

// The same view of what the transfer function shows (`render volume`'s default): the box of the
// samples whose opacity under `tf` (over `range`, renderRange's) is above 1/255 is looked at from
// where every such sample just fits the frame, so a head in a larger box fills it; the whole
// volume as above when no sample shows.
Camera defaultVolumeCamera(const Volume& volume, const TransferFunction& tf, glm::vec2 range, double aspect,
                           double fovYDegrees = 30.0);

}  // namespace conus::codec
