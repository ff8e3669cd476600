// Drawing a CoNUS file for a viewer: the conventional frame reconstructed from the CoNUS data
// (Equation 1 evaluated per pixel in the shader, never an upscaled cached frame) into the
// framebuffer bound in the current GL context, with the views a CoNUS viewer wants (raw image,
// the uniform image of the same pixel count, a wipe between the two, the sampling density) and
// overlays (the CoNUS pixel grid, focus outlines), exposure and gamma for HDR data.
//
// Shared rules: a ViewRenderer lives on one Context and is destroyed before it; every call makes
// that context current (a no-op for an adopted one, whose owner keeps it current). Image-plane
// coordinates follow spec/ (v down); the only flip is ViewOptions::bottomUp for a window's default
// framebuffer. GL failures throw conus::Error (Unsupported, LimitExceeded) as in gpu_image.h.
#pragma once

#include "conus/core/display.h"

#include <memory>
#include <utility>
#include <vector>

#include "conus/codec/image/decode.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"
#include "conus/core/enum_names.h"
#include "conus/core/image.h"
#include "conus/renderers/context.h"

namespace conus::renderers {

// The grey conus-view draws around the image, in every channel (its shader gets it as kBackground).
inline constexpr float kViewBackground = 0.11f;

enum class ViewMode {
    Reconstructed,  // the conventional frame decoded from the CoNUS image (default)
    Raw,            // the CoNUS image itself, stretched over the view's undistorted rectangle
    Uniform,        // the uniform image of the CoNUS image's pixel count, decoded the same way
    Wipe,           // Reconstructed left of ViewOptions::wipeX, Uniform right of it
    Density,        // heat map of log det J of the map (the sampling density), from the nodes
};

// Where ViewMode::Reconstructed is decoded; either way a zoomed-out pixel takes one trilinear tap
// from the CoNUS image's mip chain (codec::buildPyramid, built once in setImage), not up to 8x8
// taps. Gpu: view_frame.frag.glsl per pixel. Cpu: codec::decodeImage
// at the target's resolution every frame (still from the CoNUS data at every zoom, no cached frame),
// uploaded and copied into the target, overlays drawn over it by a second pass; on a software
// rasterizer (llvmpipe) the multithreaded incremental CPU decoder is several times faster than the
// shader at 1:1 and magnified. Auto: Gpu, except where the backend rule of backend.h
// (renderers::prefersCpu: GL_RENDERER names a software rasterizer) holds and the view is not minified
// (at most one CoNUS pixel across per target pixel, on average): a minified view takes one
// trilinear tap from the mip chain per pixel in the shader, which measured faster on llvmpipe than
// the CPU decoder (bench/README.md, Viewer). Other modes always use the GPU.
enum class DecodePath { Auto, Gpu, Cpu };

constexpr auto enumNameTable(ViewMode) {
    return makeEnumNameTable<ViewMode>("view mode", {{ViewMode::Reconstructed, "reconstructed"}, {ViewMode::Raw, "raw"}, {ViewMode::Uniform, "uniform"},
                                                     {ViewMode::Wipe, "wipe"}, {ViewMode::Density, "density"}});
}
constexpr auto enumNameTable(DecodePath) {
    return makeEnumNameTable<DecodePath>(
        "decode path", {{DecodePath::Auto, "auto"}, {DecodePath::Gpu, "gpu"}, {DecodePath::Cpu, "cpu"}});
}

struct ViewOptions {
    ViewMode mode = ViewMode::Reconstructed;
    bool grid = false;       // lines of the CoNUS pixel grid (where floor(u_d * W) changes)
    int gridEvery = 0;       // every n-th grid line; 0: automatic, lines at least ~6 pixels apart
    bool outlines = false;   // analytic focus circles (radius r and 2r)
    double exposure = 0.0;   // colour * 2^exposure
    ToneMap toneMap = ToneMap::None;  // after exposure, before the display curve (core/display.h)
    double gamma = 0.0;      // 0: the sRGB curve (data is linear light); else a display gamma (1: linear values)
    double wipeX = 0.5;      // Wipe: split position, a fraction of the viewport width
    bool bottomUp = true;    // the target's row 0 is the bottom (a window); false: top (readback)
    DecodePath decode = DecodePath::Auto;
};

// An overlay (ViewRenderer::setOverlay) drawn over a frame at (x, y): its top-left corner, in
// target pixels counted from the top-left of the target.
struct OverlayPlacement {
    int slot = 0;
    int x = 0, y = 0;
};

class ViewRenderer {
public:
    static constexpr int kOverlaySlots = 4;

    explicit ViewRenderer(Context& context);
    ~ViewRenderer();
    ViewRenderer(const ViewRenderer&) = delete;
    ViewRenderer& operator=(const ViewRenderer&) = delete;

    // Uploads the CoNUS image (display channels: R,G,B[,A], or Y, or the first), the map's nodes,
    // and computes the uniform image: a GPU decode of the whole frame at the CoNUS image's size,
    // whose footprint filter is an area downsample of the reconstructed frame. Throws
    // conus::Error(InvalidMap) for a bad map, LimitExceeded beyond GL_MAX_TEXTURE_SIZE.
    void setImage(const format::ConusFile& file);
    // Replaces the uniform image that U and W show with `image` (any size; its display channels,
    // as setImage takes them): the real baseline, what `conus uniform` made from the source, where
    // setImage's can only be resampled from the CoNUS data. Call after setImage.
    void setUniform(const Image& image);
    // Replaces the map alone (the map editor's live grid); the uniform image is not recomputed.
    void setMap(const codec::SamplingMap& map);
    bool hasImage() const;

    // Draws into the currently bound framebuffer, viewport (0,0,width,height).
    void draw(const codec::View& view, int viewportWidth, int viewportHeight, const ViewOptions& options);

    // Draws into an offscreen RGBA32F target and reads it back: RGBA, top row first, display
    // values (after exposure and gamma). options.bottomUp is ignored.
    // `overlays` are drawn over the frame (drawOverlay) before the read-back.
    Image renderToImage(const codec::View& view, int width, int height, ViewOptions options,
                                const std::vector<OverlayPlacement>& overlays = {});
    // Reads the currently bound read framebuffer (a window's back buffer before the swap) as
    // 8-bit-range RGBA floats in [0,1], top row first.
    Image readFramebuffer(int width, int height, bool bottomUp = true);
    // Clears the bound framebuffer to one colour (the viewer's "this file could not be opened").
    void clear(int width, int height, float red, float green, float blue);
    // Overlays (the viewer's help panel, error text, status bar): straight-alpha RGBA images (R,G,B,A,
    // top row first) uploaded once per slot (0 <= slot < kOverlaySlots) and drawn over the frame
    // by drawOverlay every redraw. An image of width or height 0 empties the slot. Throws
    // conus::Error(InvalidArgument) for a bad slot or an image that is not 4 channels,
    // LimitExceeded beyond GL_MAX_TEXTURE_SIZE.
    void setOverlay(int slot, const Image& rgba);
    bool hasOverlay(int slot) const;
    // Blends the slot's image (premultiplied "over") into the bound framebuffer, one texel per
    // pixel, its top-left at (x, y) counted from the top-left of the viewport (0,0,width,height);
    // clipped to the viewport. bottomUp as ViewOptions::bottomUp. Nothing for an empty slot.
    void drawOverlay(int slot, int x, int y, int viewportWidth, int viewportHeight, bool bottomUp = true);
    // Waits for the GPU (for timing).
    void finish();
    // Whether draw() of `view` at `width` pixels across with these options decodes on the CPU
    // (DecodePath resolved for this context and this zoom, see DecodePath).
    bool decodesOnCpu(const ViewOptions& options, const codec::View& view, int width) const;

    // The uniform image shown: setImage's, or the one setUniform gave (for tests and the inspector).
    const Image& uniformImage() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace conus::renderers
