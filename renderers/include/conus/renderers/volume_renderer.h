// GPU CoNUS volume ray casting (paper section 3.2, "Volume data"), the GL twin of
// codec::renderVolumeReference and held to it (tests: PSNR >= 40 dB on every test volume).
//
// How a CoNUS pixel finds its ray: the exact inverse of the sampling map, evaluated per pixel by
// codec (Distortion::undistort, the one implementation of the inverse) and uploaded as an RG32F
// texture of undistorted positions, which one full-screen pass reads. The paper instead rasterizes
// the sampling mesh carrying undistorted coordinates; that interpolates the inverse linearly
// across sub-quads and would need a second, GLSL copy of the geometry to match the reference,
// while the table is exact, works for any Distortion (grid or analytic) and costs one O(1) lookup
// per pixel on the CPU (bench/README.md measures it against the ray casting). An identity FPC
// skips the table: each pixel's undistorted position is its centre.
//
// The pass then follows codec/volume/raycast.h's sampling exactly: the camera ray (from the
// camera's NDC-to-world matrix), clipped to the box and to near/far, steps from tEnter + jitter *
// step with pixelJitter's hash, trilinear samples from an R32F 3-D texture (GL_LINEAR, clamped),
// the transfer function's table as an RGBA32F 1-D texture (GL_LINEAR), the same opacity
// correction, early termination and Z rule. Output: an image with channels R, G, B, A, Z.
//
// Shared rules as gpu_image.h: the context is made current on the calling thread; a GL failure
// throws conus::Error(Unsupported), out of memory LimitExceeded; a volume past
// GL_MAX_3D_TEXTURE_SIZE or an output past the texture limit is LimitExceeded.
#pragma once

#include <memory>

#include "conus/codec/volume/raycast.h"
#include "conus/codec/volume/transfer_function.h"
#include "conus/core/fpc.h"
#include "conus/core/image.h"
#include "conus/core/volume.h"
#include "conus/renderers/backend.h"
#include "conus/renderers/context.h"
#include "conus/renderers/gpu_image.h"

namespace conus::renderers {

// A volume and a transfer function uploaded once, rendered any number of times (the viewer, the
// benchmarks, animations). Holds GL objects of `context`: destroy it before the context.
class VolumeRendererGpu {
public:
    VolumeRendererGpu(Context& context, const Volume& volume, const codec::TransferFunction& tf);
    ~VolumeRendererGpu();
    VolumeRendererGpu(const VolumeRendererGpu&) = delete;
    VolumeRendererGpu& operator=(const VolumeRendererGpu&) = delete;

    // Replaces the transfer function (a small upload).
    void setTransferFunction(const codec::TransferFunction& tf);
    Image render(const Fpc& fpc, int width, int height, const codec::VolumeRenderOptions& options,
                 GpuTimings* timings = nullptr);

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

// One render on a device: the GPU pass above, or codec's CPU reference.
Image renderVolume(const Device& device, const Volume& volume, const codec::TransferFunction& tf, const Fpc& fpc,
                   int width, int height, const codec::VolumeRenderOptions& options);

}  // namespace conus::renderers
