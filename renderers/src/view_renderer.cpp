// conus-view's drawing: the uploads, one full-screen pass of view_frame.frag.glsl into the bound
// framebuffer (or, where the backend rule prefers the CPU, view_cpu_frame.cpp's frame), overlays.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <optional>

#include "context_pvt.h"
#include "conus/core/display.h"
#include "conus/core/parallel.h"
#include "conus/renderers/backend.h"
#include "conus/renderers/gpu_image.h"
#include "conus/renderers/view_renderer.h"
#include "embedded_shaders.h"
#include "gl_objects_pvt.h"
#include "shader_constants_pvt.h"
#include "view_renderer_pvt.h"

namespace conus::renderers {
namespace {

constexpr int kDensitySamples = 128;     // per side, for the heat map's log-density range
constexpr double kMinGridSpacing = 6.0;  // pixels between automatic grid lines (at density 1)

// The display channels as R,G,B (the shader writes alpha 1 whatever the image's alpha).
Image displayRgb(const Image& rgba) {
    Image out = makeImage(rgba.width, rgba.height, {"R", "G", "B"});
    const std::size_t pixels = static_cast<std::size_t>(rgba.width) * rgba.height;
    for (std::size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c) out.pixels[i * 3 + c] = rgba.pixels[i * 4 + c];
    return out;
}

// The display channels of a CoNUS image as RGBA: R,G,B(,A) when present, else Y (or the first
// channel) as grey. A depth-only image shows its Z as grey too, which is what one wants to see.
Image displayRgba(const Image& image) {
    Image out = makeImage(image.width, image.height, {"R", "G", "B", "A"});
    int source[4] = {image.channelIndex("R"), image.channelIndex("G"), image.channelIndex("B"), image.channelIndex("A")};
    if (source[0] < 0 || source[1] < 0 || source[2] < 0) {
        int grey = image.channelIndex("Y");
        if (grey < 0) grey = 0;
        source[0] = source[1] = source[2] = grey;
    }
    const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
    const std::size_t channels = image.channels.size();
    for (std::size_t i = 0; i < pixels; ++i) {
        for (int c = 0; c < 3; ++c) out.pixels[i * 4 + c] = image.pixels[i * channels + source[c]];
        out.pixels[i * 4 + 3] = source[3] >= 0 ? image.pixels[i * channels + source[3]] : 1.0f;
    }
    return out;
}

// The CoNUS image with codec::buildPyramid's levels as its mip chain, for one trilinear tap per
// zoomed-out pixel (view_frame.frag.glsl, as the CPU path's pyramid decode). `format` is the
// channels of the data (GL_RGBA, or GL_RGB: alpha 1; the shader shows rgb only).
GlHandle uploadMipmapped(const GladGLContext& gl, GLenum internalFormat, GLenum format, const Image& image,
                         const codec::ImagePyramid& pyramid) {
    GlHandle texture = makeTexture(gl);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, texture.id());
    std::vector<TextureLevel> levels{{image.pixels.data(), image.width, image.height}};
    for (const Image& level : pyramid.levels) levels.push_back({level.pixels.data(), level.width, level.height});
    storeLevels(gl, internalFormat, format, levels);
    return texture;
}

// The shader's CoNUS texture is RGBA16F where that shows what RGBA32F would on an 8-bit display:
// llvmpipe fetches a half texel in one load instead of four, and the fitted view's per-pixel-LOD
// trilinear tap is most of its frame (measured: bench/README.md, Viewer). Half's relative step
// (2^-11, rounding error 2^-12) is a tenth of the finest 8-bit sRGB step; below 2^-14 its absolute
// step 2^-24, scaled by an exposure of 2^12, is under half the darkest one (1 / (255 * 12.92) =
// 2^-11.7). Brighter exposures, and images with values past half's 65504, get RGBA32F.
constexpr double kHalfTextureMaxExposure = 12.0;  // stops
constexpr float kHalfMax = 65504.0f;

bool fitsHalf(const Image& image) {
    return std::all_of(image.pixels.begin(), image.pixels.end(), [](float x) { return std::abs(x) <= kHalfMax; });
}

GlHandle uploadRgba(const GladGLContext& gl, const Image& image) {
    GlHandle texture = makeTexture(gl);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, texture.id());
    gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, image.width, image.height);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.width, image.height, GL_RGBA, GL_FLOAT, image.pixels.data());
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return texture;
}

// The window pixels whose centres may fall inside [0,1]^2 for view_frame.frag.glsl's mapping
// (uv = view.xy + pixel * extent / size, rows flipped for a bottom-up target), one pixel wider on
// every side, clipped to the target: {x0, y0, x1, y1} in GL's framebuffer coordinates. Outside it
// every pixel is background (kBackground), so the frame shades only this box after a clear.
std::array<int, 4> imageBox(const codec::View& view, int width, int height, bool bottomUp) {
    // Pixel coordinate p (a centre is x + 0.5) where the view's coordinate from a to b reaches t.
    const auto span = [](double a, double b, int size) {
        const double p0 = (0.0 - a) / (b - a) * size, p1 = (1.0 - a) / (b - a) * size;
        const double lo = std::floor(std::min(p0, p1)) - 1.0, hi = std::ceil(std::max(p0, p1)) + 1.0;
        return std::pair<int, int>{static_cast<int>(std::clamp(lo, 0.0, double(size))),
                                   static_cast<int>(std::clamp(hi, 0.0, double(size)))};
    };
    const auto [x0, x1] = span(view.u0, view.u1, width);
    auto [r0, r1] = span(view.v0, view.v1, height);  // rows from the top
    if (bottomUp) std::tie(r0, r1) = std::pair<int, int>{height - r1, height - r0};
    return {x0, r0, x1, r1};
}

}  // namespace

GLuint ViewRenderer::Impl::conusTexture(const ViewOptions& options) {
    if (!conusHalf || (options.mode != ViewMode::Raw && options.exposure <= kHalfTextureMaxExposure)) return conus.id();
    if (!conusFloat) {
        const GladGLContext& gl = makeCurrentGl(context);
        conusFloat = uploadMipmapped(gl, GL_RGBA32F, GL_RGB, rgb, rgbPyramid);
        checkGl(gl, "ViewRenderer: float texture upload");
    }
    return conusFloat.id();
}

GLuint ViewRenderer::Impl::program(const ViewOptions& options, bool overlayOnly) {
    const int mode = static_cast<int>(options.mode);
    const std::string key = "view_frame/" + std::to_string(mode) + (options.grid ? "g" : "") + (options.outlines ? "o" : "") +
                            (overlayOnly ? "v" : "");
    std::string source = shaders::kShaderViewFrameFrag;
    const std::size_t eol = source.find('\n') + 1;
    source.insert(eol, "#define VIEW_MODE " + std::to_string(mode) + "\n#define VIEW_GRID " + (options.grid ? "1" : "0") +
                           "\n#define VIEW_OUTLINES " + (options.outlines ? "1" : "0") + "\n#define VIEW_OVERLAY " +
                           (overlayOnly ? "1" : "0") + "\n");
    return cachedProgram(context, key, shaders::kShaderFullscreenVert, source.c_str());
}

void ViewRenderer::Impl::uploadMap(const codec::SamplingMap& m) {
    const GladGLContext& gl = makeCurrentGl(context);
    map = uploadMapTexture(gl, GL_TEXTURE1, m.columns(), m.rows(), &m.nodes().front().x);
    checkGl(gl, "ViewRenderer: map upload");
    double lo = 1e300, hi = -1e300;
    for (int j = 0; j < kDensitySamples; ++j)
        for (int i = 0; i < kDensitySamples; ++i) {
            const double d = std::log(std::max(
                m.density({(i + 0.5) / kDensitySamples, (j + 0.5) / kDensitySamples}), 1e-12));
            lo = std::min(lo, d);
            hi = std::max(hi, d);
        }
    logDensityLo = static_cast<float>(lo);
    logDensityHi = static_cast<float>(hi);
}

ViewRenderer::ViewRenderer(Context& context) : m_impl(std::make_unique<Impl>(context)) {
    // Compile now, so a broken driver fails at start-up rather than at the first frame.
    makeCurrentGl(context);
    m_impl->program(ViewOptions{});
}

ViewRenderer::~ViewRenderer() = default;

bool ViewRenderer::hasImage() const { return static_cast<bool>(m_impl->conus); }
const Image& ViewRenderer::uniformImage() const { return m_impl->uniformImage; }

void ViewRenderer::setUniform(const Image& image) {
    Impl& d = *m_impl;
    if (!hasImage()) throw Error(ErrorCode::InvalidArgument, "ViewRenderer::setUniform before setImage");
    const Image rgba = displayRgba(image);
    const int limit = d.context.textureLimit();
    if (rgba.width > limit || rgba.height > limit)
        throw Error(ErrorCode::LimitExceeded, "ViewRenderer: uniform image " + std::to_string(rgba.width) + "x" +
                                                  std::to_string(rgba.height) + " exceeds the texture limit " +
                                                  std::to_string(limit));
    const GladGLContext& gl = makeCurrentGl(d.context);
    d.uniform = uploadRgba(gl, rgba);
    checkGl(gl, "ViewRenderer: uniform image upload");
    d.uniformImage = rgba;
}

void ViewRenderer::setImage(const format::ConusFile& file) {
    Impl& d = *m_impl;
    const codec::SamplingMap map = codec::SamplingMap::fromGrid(file.map);
    const Image rgba = displayRgba(file.image);
    const int limit = d.context.textureLimit();
    if (rgba.width > limit || rgba.height > limit)
        throw Error(ErrorCode::LimitExceeded, "ViewRenderer: CoNUS image " + std::to_string(rgba.width) + "x" +
                                                  std::to_string(rgba.height) + " exceeds the texture limit " +
                                                  std::to_string(limit));
    // The uniform image of the same pixel count: the whole frame decoded at the CoNUS image's size
    // on the GPU. The decoder averages taps over each output pixel's footprint, so this is the area
    // downsample of the reconstructed full frame in one pass (a CPU decode at source size plus
    // codec::areaDownsample takes seconds for a 2048^2 image; this takes a frame).
    codec::DecodeOptions options;
    options.width = rgba.width;
    options.height = rgba.height;
    d.uniformImage = decodeImageGpu(d.context, rgba, map, options);

    // One mip chain for both paths: the shader's texture levels and, without alpha, the CPU's.
    codec::ImagePyramid pyramid = codec::buildPyramid(rgba);
    const GladGLContext& gl = makeCurrentGl(d.context);
    d.conusHalf = fitsHalf(rgba);  // the levels are averages of level 0: within its range
    d.conus = uploadMipmapped(gl, d.conusHalf ? GL_RGBA16F : GL_RGBA32F, GL_RGBA, rgba, pyramid);
    d.conusFloat.reset();
    d.uniform = uploadRgba(gl, d.uniformImage);
    checkGl(gl, "ViewRenderer: image upload");
    d.uploadMap(map);
    d.rgb = displayRgb(rgba);
    for (Image& level : pyramid.levels) level = displayRgb(level);
    d.rgbPyramid = std::move(pyramid);
    d.cpuMap = map;
    d.conusWidth = rgba.width;
    d.conusHeight = rgba.height;
    d.sourceWidth = file.sourceWidth > 0 ? file.sourceWidth : rgba.width;
    d.sourceHeight = file.sourceHeight > 0 ? file.sourceHeight : rgba.height;
    d.foci.clear();
    if (file.analytic && file.analytic->is(format::MapKind::Foci))
        for (const auto& f : file.analytic->foci) {
            if (static_cast<int>(d.foci.size()) / 3 >= kViewMaxFoci) break;
            d.foci.insert(d.foci.end(), {float(f.u), float(f.v), float(f.r)});
        }
}

void ViewRenderer::setMap(const codec::SamplingMap& map) {
    m_impl->uploadMap(map);
    if (m_impl->cpuMap) m_impl->cpuMap = map;
}

bool ViewRenderer::decodesOnCpu(const ViewOptions& options, const codec::View& view, int width) const {
    return hasImage() && m_impl->cpuDecode(options, view, width);
}

void ViewRenderer::draw(const codec::View& view, int width, int height, const ViewOptions& options) {
    Impl& d = *m_impl;
    const GladGLContext& gl = makeCurrentGl(d.context);
    if (!hasImage()) {
        gl.Viewport(0, 0, width, height);
        gl.ClearColor(kViewBackground, kViewBackground, kViewBackground, 1.0f);
        gl.Clear(GL_COLOR_BUFFER_BIT);
        return;
    }
    const bool cpu = d.cpuDecode(options, view, width);
    if (cpu) {
        d.decodeFrame(view, width, height, options);
        if (!options.grid && !options.outlines) return;
    }
    // The whole frame, or (after a CPU decode) the overlays blended over it.
    const GLuint program = d.program(options, cpu);
    gl.Viewport(0, 0, width, height);
    gl.Disable(GL_DEPTH_TEST);
    if (cpu) {
        gl.Enable(GL_BLEND);
        gl.BlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    } else {
        gl.Disable(GL_BLEND);
    }
    gl.UseProgram(program);
    const GLuint textures[3] = {d.conusTexture(options), d.map.id(), d.uniform.id()};
    for (int unit = 0; unit < 3; ++unit) {
        gl.ActiveTexture(GL_TEXTURE0 + unit);
        gl.BindTexture(GL_TEXTURE_2D, textures[unit]);
    }
    const auto at = [&](const char* name) { return gl.GetUniformLocation(program, name); };
    gl.Uniform1i(at("uConus"), 0);
    gl.Uniform1i(at("uMap"), 1);
    gl.Uniform1i(at("uUniform"), 2);
    gl.Uniform4f(at("uView"), float(view.u0), float(view.v0), float(view.u1), float(view.v1));
    gl.Uniform2f(at("uOutputSize"), float(width), float(height));
    gl.Uniform1i(at("uBottomUp"), options.bottomUp ? 1 : 0);
    int every = options.gridEvery;
    if (every <= 0) {
        // Window pixels per CoNUS pixel where the density is 1, over the densest part's linear
        // magnification (the lines crowd together there); coarser lines until they are legible there.
        const double perPixel = width / (std::abs(view.u1 - view.u0) * d.conusWidth) / std::exp(0.5 * std::max(0.0f, d.logDensityHi));
        every = 1;
        while (every * perPixel < kMinGridSpacing && every < d.conusWidth) every *= 2;
    }
    gl.Uniform2f(at("uGridLines"), options.grid ? float(d.conusWidth) / every : 0.0f,
                 options.grid ? float(d.conusHeight) / every : 0.0f);
    gl.Uniform2f(at("uSourceSize"), float(d.sourceWidth), float(d.sourceHeight));
    const int foci = options.outlines ? static_cast<int>(d.foci.size() / 3) : 0;
    gl.Uniform1i(at("uFocusCount"), foci);
    if (foci > 0) gl.Uniform3fv(at("uFoci"), foci, d.foci.data());
    gl.Uniform1f(at("uExposure"), static_cast<float>(std::exp2(options.exposure)));
    gl.Uniform1f(at("uInvGamma"), inverseGamma(options));
    gl.Uniform1i(at("uToneMap"), static_cast<int>(options.toneMap));
    gl.Uniform1f(at("uWipeX"), static_cast<float>(options.wipeX * width));
    gl.Uniform2f(at("uLogDensity"), d.logDensityLo, d.logDensityHi);
    // Modes that paint nothing outside [0,1]^2 (no focus circles past its edge, no wipe line, not
    // the density's dimmed surround) shade only the image's box after a clear to the background:
    // a fitted square image leaves ~45% of a 16:9 window shaded for nothing on software GL.
    const bool boxed = !cpu && !options.outlines &&
                       (options.mode == ViewMode::Reconstructed || options.mode == ViewMode::Raw || options.mode == ViewMode::Uniform);
    if (boxed) {
        const std::array<int, 4> box = imageBox(view, width, height, options.bottomUp);
        if (box[0] > 0 || box[1] > 0 || box[2] < width || box[3] < height) {
            gl.ClearColor(kViewBackground, kViewBackground, kViewBackground, 1.0f);
            gl.Clear(GL_COLOR_BUFFER_BIT);
        }
        gl.Enable(GL_SCISSOR_TEST);
        gl.Scissor(box[0], box[1], box[2] - box[0], box[3] - box[1]);
    }
    gl.BindVertexArray(d.context.impl().emptyVertexArray);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);  // an empty box (the image out of view) draws nothing
    gl.BindVertexArray(0);
    gl.Disable(GL_SCISSOR_TEST);
    gl.Disable(GL_BLEND);
    checkGl(gl, "ViewRenderer::draw");
}

Image ViewRenderer::renderToImage(const codec::View& view, int width, int height, ViewOptions options,
                                          const std::vector<OverlayPlacement>& overlays) {
    constexpr const char* kWhat = "ViewRenderer::renderToImage";
    Image out = makeImage(width, height, {"R", "G", "B", "A"});
    const GladGLContext& gl = makeCurrentGl(m_impl->context);
    const FloatTarget target(gl, width, height, kWhat);
    options.bottomUp = false;  // read back top row first: no flip
    m_impl->floatTarget = true;  // a CPU decode keeps float values
    try {
        draw(view, width, height, options);
        for (const OverlayPlacement& o : overlays) drawOverlay(o.slot, o.x, o.y, width, height, false);
    } catch (...) {
        m_impl->floatTarget = false;
        throw;
    }
    m_impl->floatTarget = false;
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, out.pixels.data());
    checkGl(gl, kWhat);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    return out;
}

Image ViewRenderer::readFramebuffer(int width, int height, bool bottomUp) {
    const GladGLContext& gl = makeCurrentGl(m_impl->context);
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(width) * height * 4);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, bytes.data());
    checkGl(gl, "ViewRenderer::readFramebuffer");
    Image out = makeImage(width, height, {"R", "G", "B", "A"});
    for (int y = 0; y < height; ++y) {
        const int row = bottomUp ? height - 1 - y : y;
        for (int x = 0; x < width * 4; ++x)
            out.pixels[static_cast<std::size_t>(y) * width * 4 + x] =
                bytes[static_cast<std::size_t>(row) * width * 4 + x] / 255.0f;
    }
    return out;
}

void ViewRenderer::clear(int width, int height, float red, float green, float blue) {
    const GladGLContext& gl = makeCurrentGl(m_impl->context);
    gl.Viewport(0, 0, width, height);
    gl.ClearColor(red, green, blue, 1.0f);
    gl.Clear(GL_COLOR_BUFFER_BIT);
}

void ViewRenderer::setOverlay(int slot, const Image& rgba) {
    if (slot < 0 || slot >= kOverlaySlots)
        throw Error(ErrorCode::InvalidArgument, "ViewRenderer::setOverlay: slot " + std::to_string(slot) + " out of range");
    Impl& d = *m_impl;
    const GladGLContext& gl = makeCurrentGl(d.context);
    d.overlays[slot].reset();
    d.overlayWidth[slot] = d.overlayHeight[slot] = 0;
    if (rgba.width <= 0 || rgba.height <= 0) return;
    if (rgba.channelCount() != 4)
        throw Error(ErrorCode::InvalidArgument, "ViewRenderer::setOverlay: the overlay must be RGBA, not " +
                                                    std::to_string(rgba.channelCount()) + " channels");
    const int limit = d.context.maxTextureSize();
    if (rgba.width > limit || rgba.height > limit)
        throw Error(ErrorCode::LimitExceeded, "ViewRenderer::setOverlay: " + std::to_string(rgba.width) + "x" +
                                                  std::to_string(rgba.height) + " exceeds GL_MAX_TEXTURE_SIZE");
    d.overlays[slot] = uploadRgba(gl, rgba);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    checkGl(gl, "ViewRenderer::setOverlay");
    d.overlayWidth[slot] = rgba.width;
    d.overlayHeight[slot] = rgba.height;
}

bool ViewRenderer::hasOverlay(int slot) const {
    return slot >= 0 && slot < kOverlaySlots && static_cast<bool>(m_impl->overlays[slot]);
}

void ViewRenderer::drawOverlay(int slot, int x, int y, int width, int height, bool bottomUp) {
    if (!hasOverlay(slot) || width <= 0 || height <= 0) return;
    Impl& d = *m_impl;
    // The overlay's rectangle clipped to the viewport, as a scissor box (GL rows from the bottom).
    const int x0 = std::max(x, 0), x1 = std::min(x + d.overlayWidth[slot], width);
    const int y0 = std::max(y, 0), y1 = std::min(y + d.overlayHeight[slot], height);
    if (x0 >= x1 || y0 >= y1) return;
    const GladGLContext& gl = makeCurrentGl(d.context);
    const GLuint program = cachedProgram(d.context, "view_overlay", shaders::kShaderFullscreenVert, shaders::kShaderViewOverlayFrag);
    gl.Viewport(0, 0, width, height);
    gl.Disable(GL_DEPTH_TEST);
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(x0, bottomUp ? height - y1 : y0, x1 - x0, y1 - y0);
    gl.Enable(GL_BLEND);
    gl.BlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    gl.UseProgram(program);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, d.overlays[slot].id());
    gl.Uniform1i(gl.GetUniformLocation(program, "uOverlay"), 0);
    gl.Uniform2i(gl.GetUniformLocation(program, "uOrigin"), x, y);
    gl.Uniform1i(gl.GetUniformLocation(program, "uViewportHeight"), height);
    gl.Uniform1i(gl.GetUniformLocation(program, "uBottomUp"), bottomUp ? 1 : 0);
    gl.BindVertexArray(d.context.impl().emptyVertexArray);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.BindVertexArray(0);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_SCISSOR_TEST);
    checkGl(gl, "ViewRenderer::drawOverlay");
}

void ViewRenderer::finish() { makeCurrentGl(m_impl->context).Finish(); }

}  // namespace conus::renderers
