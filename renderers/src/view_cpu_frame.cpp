// conus-view's CPU decode path: codec's decoder per frame at the target's resolution, turned into
// display values (through a table for 8-bit targets), uploaded and blitted into the framebuffer.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "conus/core/display.h"
#include "conus/core/parallel.h"
#include "conus/renderers/backend.h"
#include "shader_constants_pvt.h"
#include "view_renderer_pvt.h"

namespace conus::renderers {
namespace {


// An exposed linear value on the display, 0..255: tone map, then the sRGB curve or a gamma.
std::uint8_t displayByte(float exposed, float invGamma, ToneMap toneMap) {
    const float x = exposeAndToneMap(exposed, 1.0f, toneMap);
    const double v = invGamma == 0.0f ? linearToSrgbDisplay(x) : std::pow(static_cast<double>(std::max(x, 0.0f)), static_cast<double>(invGamma));
    return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}


// The 8-bit display table of the CPU path: a display value for every float in [2^-32, 1) by its
// top 12 mantissa bits (131072 buckets, relative width 2^-12); 0 below, 255 at 1 and above.
constexpr std::uint32_t kLutLowBits = 0x2f800000u;  // 2^-32
constexpr int kLutShift = 11;
constexpr std::size_t kLutSize = (0x3f800000u - kLutLowBits) >> kLutShift;

std::uint32_t floatBits(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, sizeof b);
    return b;
}

}  // namespace

float inverseGamma(const ViewOptions& options) {
    return options.gamma == 0.0 ? 0.0f : static_cast<float>(1.0 / std::max(options.gamma, 0.05));
}

bool ViewRenderer::Impl::cpuDecode(const ViewOptions& options, const codec::View& view, int width) const {
    if (options.mode != ViewMode::Reconstructed || !cpuMap) return false;
    switch (options.decode) {
    case DecodePath::Cpu: return true;
    case DecodePath::Gpu: return false;
    case DecodePath::Auto: break;
    }
    const bool minified = std::abs(view.u1 - view.u0) * conusWidth > width;
    return !minified && prefersCpu(context);
}

void ViewRenderer::Impl::buildLut(float exposure, float invGamma, ToneMap toneMap) {
    if (lut.size() == kLutSize && exposure == lutExposure && invGamma == lutInvGamma && toneMap == lutToneMap) return;
    lut.resize(kLutSize);
    for (std::size_t i = 0; i < kLutSize; ++i) {
        const std::uint32_t lo = kLutLowBits + (static_cast<std::uint32_t>(i) << kLutShift);
        const std::uint32_t mid = lo + (1u << (kLutShift - 1));
        float x;
        std::memcpy(&x, &mid, sizeof x);
        lut[i] = displayByte(x, invGamma, toneMap);  // indexed by the exposed value
    }
    lutExposure = exposure;
    lutInvGamma = invGamma;
    lutToneMap = toneMap;
}

void ViewRenderer::Impl::decodeFrame(const codec::View& view, int width, int height, const ViewOptions& options) {
    codec::DecodeOptions decode;
    decode.view = view;
    decode.width = width;
    decode.height = height;
    decode.pyramid = &rgbPyramid;
    const Image frame = codec::decodeImage(rgb, *cpuMap, decode);
    const float exposure = static_cast<float>(std::exp2(options.exposure));
    const float invGamma = inverseGamma(options);
    // Which columns / rows are inside [0,1]^2 at the pixel centres (gl_FragCoord in the shader).
    std::vector<std::uint8_t> colInside(width), rowInside(height);
    const double su = (view.u1 - view.u0) / width, sv = (view.v1 - view.v0) / height;
    for (int x = 0; x < width; ++x) {
        const double u = view.u0 + (x + 0.5) * su;
        colInside[x] = u >= 0.0 && u <= 1.0;
    }
    for (int y = 0; y < height; ++y) {
        const double v = view.v0 + (y + 0.5) * sv;
        rowInside[y] = v >= 0.0 && v <= 1.0;
    }
    const bool flip = options.bottomUp;
    const std::size_t count = static_cast<std::size_t>(width) * height * 4;
    if (floatTarget) {
        frameFloats.resize(count);
        parallelRows(height, 0, [&](int y0, int y1) {
            for (int y = y0; y < y1; ++y) {
                float* out = frameFloats.data() + static_cast<std::size_t>(flip ? height - 1 - y : y) * width * 4;
                const float* in = frame.pixels.data() + static_cast<std::size_t>(y) * width * 3;
                for (int x = 0; x < width; ++x, out += 4, in += 3) {
                    for (int c = 0; c < 3; ++c) {
                        const float t = exposeAndToneMap(in[c], exposure, options.toneMap);
                        out[c] = rowInside[y] && colInside[x]
                                     ? (invGamma == 0.0f ? linearToSrgbDisplay(t) : std::pow(std::max(t, 0.0f), invGamma))
                                     : kViewBackground;
                    }
                    out[3] = 1.0f;
                }
            }
        });
    } else {
        buildLut(exposure, invGamma, options.toneMap);
        frameBytes.resize(count);
        const std::uint8_t background = static_cast<std::uint8_t>(std::lround(kViewBackground * 255.0f));
        const std::uint8_t* table = lut.data();
        parallelRows(height, 0, [&](int y0, int y1) {
            for (int y = y0; y < y1; ++y) {
                std::uint8_t* out = frameBytes.data() + static_cast<std::size_t>(flip ? height - 1 - y : y) * width * 4;
                const float* in = frame.pixels.data() + static_cast<std::size_t>(y) * width * 3;
                for (int x = 0; x < width; ++x, out += 4, in += 3) {
                    if (!rowInside[y] || !colInside[x]) {
                        out[0] = out[1] = out[2] = background;
                    } else {
                        for (int c = 0; c < 3; ++c) {
                            const float f = in[c] * exposure;
                            const std::uint32_t b = floatBits(f);
                            // The table spans [2^-32, 1); above 1 only a tone map keeps values apart.
                            out[c] = !(f >= 0x1p-32f)                      ? 0
                                     : f < 1.0f                            ? table[(b - kLutLowBits) >> kLutShift]
                                     : options.toneMap == ToneMap::None    ? 255
                                                                           : displayByte(f, invGamma, options.toneMap);
                        }
                    }
                    out[3] = 255;
                }
            }
        });
    }

    const GladGLContext& gl = makeCurrentGl(context);
    const GLenum format = floatTarget ? GL_RGBA32F : GL_RGBA8;
    if (!frameTexture || frameWidth != width || frameHeight != height || frameFormat != format) {
        frameTexture = makeTexture(gl);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, frameTexture.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, format, width, height);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        if (!frameFramebuffer) frameFramebuffer = makeFramebuffer(gl);
        GLint readBinding = 0;
        gl.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readBinding);
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, frameFramebuffer.id());
        gl.FramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, frameTexture.id(), 0);
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(readBinding));
        frameWidth = width;
        frameHeight = height;
        frameFormat = format;
    }
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, frameTexture.id());
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    if (floatTarget) gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, frameFloats.data());
    else gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, frameBytes.data());
    // Copied into the bound draw framebuffer; the read binding is left as it was (the viewer
    // reads its back buffer for screenshots).
    GLint readBinding = 0;
    gl.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readBinding);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, frameFramebuffer.id());
    gl.BlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(readBinding));
    checkGl(gl, "ViewRenderer::draw (CPU decode)");
}

}  // namespace conus::renderers
