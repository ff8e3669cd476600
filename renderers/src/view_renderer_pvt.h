// Private: a ViewRenderer's state (its Impl), shared by view_renderer.cpp (uploads, the shader
// frame, overlays) and view_cpu_frame.cpp (the CPU decode path and its 8-bit display table).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glad/gl.h>

#include "context_pvt.h"
#include "conus/renderers/view_renderer.h"
#include "gl_objects_pvt.h"

namespace conus::renderers {

// 0 selects the sRGB curve (ViewOptions::gamma 0); a gamma below 0.05 is held there.
float inverseGamma(const ViewOptions& options);

struct ViewRenderer::Impl {
    Context& context;
    GlHandle conus, map, uniform;
    bool conusHalf = false;  // conus is RGBA16F; conusFloat, its RGBA32F twin, made when first needed
    GlHandle conusFloat;
    // The CPU decode path: the display channels and the map on the CPU, the frame texture (RGBA8
    // for a window, RGBA32F when rendering to a float target) and a framebuffer to blit it from.
    Image rgb;
    codec::ImagePyramid rgbPyramid;  // rgb's mip chain: zoomed-out pixels take one trilinear tap
    std::optional<codec::SamplingMap> cpuMap;
    GlHandle frameTexture, frameFramebuffer;
    int frameWidth = 0, frameHeight = 0;
    GLenum frameFormat = 0;
    bool floatTarget = false;  // renderToImage: exact float values, no 8-bit rounding
    std::vector<std::uint8_t> frameBytes;
    std::vector<float> frameFloats;
    std::vector<std::uint8_t> lut;
    float lutExposure = -1, lutInvGamma = -1;
    ToneMap lutToneMap = ToneMap::None;
    int conusWidth = 0, conusHeight = 0;
    double sourceWidth = 1, sourceHeight = 1;
    std::vector<float> foci;  // u, v, r per focus
    float logDensityLo = 0, logDensityHi = 0;
    Image uniformImage;
    GlHandle overlays[ViewRenderer::kOverlaySlots];
    int overlayWidth[ViewRenderer::kOverlaySlots] = {}, overlayHeight[ViewRenderer::kOverlaySlots] = {};

    explicit Impl(Context& c) : context(c) {}
    // The handles delete their objects after this body, with the context current.
    ~Impl() { makeCurrentGl(context); }

    // Whether draw() decodes on the CPU: DecodePath resolved for this context and zoom.
    bool cpuDecode(const ViewOptions& options, const codec::View& view, int width) const;
    // The CPU path's display table for these settings; kept while they stay the same.
    void buildLut(float exposure, float invGamma, ToneMap toneMap);
    // The frame decoded by codec::decodeImage into the frame texture, top row first (or bottom row
    // first for a window), display values, background outside [0,1]^2 as the shader has it.
    void decodeFrame(const codec::View& view, int width, int height, const ViewOptions& options);
    // The CoNUS texture for these options: the half one for the decoded frame unless the exposure
    // needs float; the raw mode shows the CoNUS image's own values, so float.
    GLuint conusTexture(const ViewOptions& options);
    // The program for a mode and overlays: view_frame.frag.glsl with its VIEW_* switches defined
    // after the #version line (compiled once per combination, cached by the context).
    // overlayOnly: the overlays alone, premultiplied, to blend over a frame already drawn.
    GLuint program(const ViewOptions& options, bool overlayOnly = false);
    // The map's texture and the log-density range of the heat map.
    void uploadMap(const codec::SamplingMap& m);
};

}  // namespace conus::renderers
