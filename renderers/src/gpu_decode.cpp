// GPU image decode (paper section 4) on a Context: Equation 1 per output pixel in a full-screen
// pass, from the image (and, for a pyramid decode, its levels as the mip chain); and the device
// dispatch of decodeImage.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "context_pvt.h"
#include "conus/renderers/gpu_image.h"
#include "embedded_shaders.h"
#include "gl_objects_pvt.h"
#include "gpu_pass_pvt.h"

namespace conus::renderers {

Image decodeImageGpu(Context& context, const Image& conus, const codec::SamplingMap& map,
                             const codec::DecodeOptions& options, GpuTimings* timings) {
    constexpr const char* kWhat = "decodeImageGpu";
    checkImage(conus, kWhat);
    codec::checkDecodeMemory(conus, options.width, options.height, kMaxDecodeBytes, options.pyramid != nullptr);
    if (options.pyramid) codec::checkPyramid(conus, *options.pyramid);
    const codec::View& view = options.view;
    if (!std::isfinite(view.u0) || !std::isfinite(view.u1) || !std::isfinite(view.v0) || !std::isfinite(view.v1) ||
        view.u0 == view.u1 || view.v0 == view.v1 || std::abs(view.u1 - view.u0) > 1e6 ||
        std::abs(view.v1 - view.v0) > 1e6)
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": view (" + std::to_string(view.u0) + ", " +
                                                    std::to_string(view.v0) + ") - (" + std::to_string(view.u1) +
                                                    ", " + std::to_string(view.v1) + ") is empty or not finite");
    Image out = makeImage(options.width, options.height, conus.channels);
    checkTextureSize(context, conus.width, conus.height, kWhat, "CoNUS image");
    checkTextureSize(context, out.width, out.height, kWhat, "output");

    GpuTimings t;
    Clock::time_point start = Clock::now();
    const GladGLContext& gl = makeCurrentGl(context);
    const bool pyramid = options.pyramid != nullptr;
    std::string source = shaders::kShaderDecodeFrag;
    if (pyramid) source.insert(source.find('\n') + 1, "#define DECODE_PYRAMID 1\n");
    const GLuint program =
        cachedProgram(context, pyramid ? "decode/pyramid" : "decode", shaders::kShaderFullscreenVert, source.c_str());

    // The map's nodes, fetched exactly (texelFetch) by the shader.
    GlHandle mapTexture = uploadMapTexture(gl, GL_TEXTURE1, map.columns(), map.rows(), &map.nodes().front().x);
    FloatTarget target(gl, out.width, out.height, kWhat);
    checkGl(gl, kWhat);

    for (int first = 0; first < conus.channelCount(); first += kChannelsPerPass) {
        const int count = std::min(kChannelsPerPass, conus.channelCount() - first);
        GlHandle texture = makeTexture(gl);
        {
            // The image, then (pyramid decode) the pyramid's levels as its mip chain.
            std::vector<PassPixels> pixels;
            pixels.reserve(1 + (pyramid ? options.pyramid->levels.size() : 0));
            pixels.emplace_back(conus, first, count);
            if (pyramid)
                for (const Image& level : options.pyramid->levels) pixels.emplace_back(level, first, count);
            std::vector<TextureLevel> levels{{pixels[0].data(), conus.width, conus.height}};
            if (pyramid)
                for (std::size_t k = 0; k < options.pyramid->levels.size(); ++k)
                    levels.push_back({pixels[k + 1].data(), options.pyramid->levels[k].width,
                                      options.pyramid->levels[k].height});
            gl.ActiveTexture(GL_TEXTURE0);
            gl.BindTexture(GL_TEXTURE_2D, texture.id());
            storeLevels(gl, internalFormat(count), pixelFormat(count), levels);
            checkGl(gl, kWhat);
            gl.Finish();
        }
        t.uploadMs += millisecondsSince(start);

        gl.BindFramebuffer(GL_FRAMEBUFFER, target.framebuffer.id());
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_2D, mapTexture.id());
        gl.UseProgram(program);
        gl.Uniform1i(gl.GetUniformLocation(program, "uConus"), 0);
        gl.Uniform1i(gl.GetUniformLocation(program, "uMap"), 1);
        gl.Uniform4f(gl.GetUniformLocation(program, "uView"), float(view.u0), float(view.v0), float(view.u1),
                     float(view.v1));
        gl.Uniform2f(gl.GetUniformLocation(program, "uOutputSize"), float(out.width), float(out.height));
        gl.BindVertexArray(context.impl().emptyVertexArray);
        gl.DrawArrays(GL_TRIANGLES, 0, 3);
        checkGl(gl, kWhat);
        gl.Finish();
        t.drawMs += millisecondsSince(start);

        readBack(gl, out, first, count);
        checkGl(gl, kWhat);
        t.readbackMs += millisecondsSince(start);
    }
    gl.BindVertexArray(0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    if (timings) *timings = t;
    return out;
}

Image decodeImage(const Device& device, const Image& conus, const codec::SamplingMap& map,
                          const codec::DecodeOptions& options) {
    return device.run([&] { return codec::decodeImage(conus, map, options); },
                      [&](Context& context) { return decodeImageGpu(context, conus, map, options); });
}

}  // namespace conus::renderers
