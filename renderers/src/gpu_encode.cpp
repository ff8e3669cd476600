// GPU image encode (paper section 3.2) on a Context: the EWA encoder (the plan's mesh rasterized
// at the CoNUS resolution over the source's pyramid, whole or tile by tile), the choice between it
// and the mipmapped encoder (gpu_encode_mip.cpp), and the device dispatch of encodeImage.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "context_pvt.h"
#include "conus/renderers/gpu_image.h"
#include "embedded_shaders.h"
#include "gl_objects_pvt.h"
#include "gpu_encode_plan_pvt.h"
#include "gpu_encode_pvt.h"
#include "gpu_pass_pvt.h"

namespace conus::renderers {
namespace {

void setLinearClamp(const GladGLContext& gl) {
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

// Fills the atlas level by level, each from the one above (level 0 is `source`). Reading the atlas
// while drawing into another region of it is defined after glTextureBarrier.
void buildPyramid(Context& context, const GladGLContext& gl, const Pyramid& pyramid, GLuint source, GLuint atlas) {
    if (pyramid.rects.size() < 2) return;
    const GLuint program =
        cachedProgram(context, "pyramid", shaders::kShaderFullscreenVert, shaders::kShaderPyramidFrag);
    GlHandle framebuffer = makeFramebuffer(gl);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, atlas, 0);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error(ErrorCode::Unsupported, "encodeImageGpu: the driver cannot render into the RGBA32F pyramid");
    gl.UseProgram(program);
    gl.Uniform1i(gl.GetUniformLocation(program, "uSource"), 0);
    const GLint sourceRect = gl.GetUniformLocation(program, "uSourceRect");
    const GLint targetRect = gl.GetUniformLocation(program, "uTargetRect");
    gl.BindVertexArray(context.impl().emptyVertexArray);
    gl.ActiveTexture(GL_TEXTURE0);
    for (std::size_t level = 1; level < pyramid.rects.size(); ++level) {
        const auto& from = pyramid.rects[level - 1];
        const auto& to = pyramid.rects[level];
        gl.BindTexture(GL_TEXTURE_2D, level == 1 ? source : atlas);
        gl.Uniform4i(sourceRect, from[0], from[1], from[2], from[3]);
        gl.Uniform4i(targetRect, to[0], to[1], to[2], to[3]);
        gl.Viewport(to[0], to[1], to[2], to[3]);
        gl.TextureBarrier();
        gl.DrawArrays(GL_TRIANGLES, 0, 3);
    }
}

// Uploads the crop [x, x + width) x [y, y + height) of `pixels` (an image `rowLength` wide with
// `count` channels) into the bound texture at (atlasX, atlasY).
void uploadCrop(const GladGLContext& gl, const float* pixels, int rowLength, int count, const TileLevel& crop) {
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.PixelStorei(GL_UNPACK_ROW_LENGTH, rowLength);
    gl.PixelStorei(GL_UNPACK_SKIP_PIXELS, crop.x);
    gl.PixelStorei(GL_UNPACK_SKIP_ROWS, crop.y);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, crop.atlasX, crop.atlasY, crop.width, crop.height, pixelFormat(count), GL_FLOAT,
                     pixels);
    gl.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    gl.PixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
    gl.PixelStorei(GL_UNPACK_SKIP_ROWS, 0);
}

// One GPU encode: the program, the mesh uploaded once for every pass of four channels, the
// target, and (for sources past the texture limit) the tile plan with the CPU-built pyramid.
class GpuEncoder {
public:
    GpuEncoder(Context& context, const Image& source, const codec::SamplingMap& map, Image& out)
        : m_context(context), m_gl(makeCurrentGl(context)), m_source(source), m_out(out),
          m_pyramid(pyramidLayout(source.width, source.height)), m_mesh(buildMesh(map, out.width, out.height)),
          m_vertexArray(makeVertexArray(m_gl)), m_vertexBuffer(makeBuffer(m_gl)), m_indexBuffer(makeBuffer(m_gl)),
          m_target(m_gl, out.width, out.height, kWhat) {
        m_program = cachedProgram(context, "encode", shaders::kShaderEncodeVert, shaders::kShaderEncodeFrag);
        uploadMesh(m_gl, m_mesh, m_vertexArray.id(), m_vertexBuffer.id(), m_indexBuffer.id());
        const int limit = context.textureLimit();
        if (source.width > limit || source.height > limit || m_pyramid.atlasWidth > limit || m_pyramid.atlasHeight > limit)
            planTiling(limit);
    }

    // Channels [first, first + count) of the source into the same channels of the output.
    void pass(int first, int count, GpuTimings& t, Clock::time_point& start) {
        const PassPixels pixels(m_source, first, count);
        if (m_tiles.empty()) drawWhole(pixels, count, t, start);
        else drawTiles(pixels, first, count, t, start);
        m_gl.BindFramebuffer(GL_FRAMEBUFFER, m_target.framebuffer.id());
        readBack(m_gl, m_out, first, count);
        checkGl(m_gl, kWhat);
        t.readbackMs += millisecondsSince(start);
    }

    bool tiled() const { return !m_tiles.empty(); }

    ~GpuEncoder() {
        m_gl.BindVertexArray(0);
        m_gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    }

private:
    static constexpr const char* kWhat = "encodeImageGpu";

    double uniformSpacing() const {
        return codec::uniformSpacing(m_source.width, m_source.height, m_out.width, m_out.height);
    }
    static constexpr float kFar = std::numeric_limits<float>::max();

    // The plan, each tile's share of the mesh, and the pyramid's levels 1.. (built once on the
    // CPU with the reference's own area filter; the GPU then reads crops of them per tile).
    void planTiling(int limit) {
        m_tiles = planTiles(m_pyramid, tileMargin(m_mesh, m_source.width, m_source.height, uniformSpacing()), limit);
        m_levels.reserve(m_pyramid.rects.size());
        for (Tile& tile : m_tiles) tile.indices = tileIndices(m_mesh, tileCore(tile, m_source.width, m_source.height));
        for (std::size_t level = 1; level < m_pyramid.rects.size(); ++level)
            m_levels.push_back(codec::areaDownsample(level == 1 ? m_source : m_levels.back(), m_pyramid.rects[level][2],
                                                     m_pyramid.rects[level][3], 0));
    }

    void setDrawState(GLuint level0, GLuint atlas, const std::vector<std::array<int, 4>>& rects, const std::array<float, 4>& core) {
        const GladGLContext& gl = m_gl;
        gl.BindFramebuffer(GL_FRAMEBUFFER, m_target.framebuffer.id());
        gl.Viewport(0, 0, m_out.width, m_out.height);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, level0);
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_2D, atlas);
        gl.UseProgram(m_program);
        gl.Uniform1i(gl.GetUniformLocation(m_program, "uLevel0"), 0);
        gl.Uniform1i(gl.GetUniformLocation(m_program, "uPyramid"), 1);
        gl.Uniform1i(gl.GetUniformLocation(m_program, "uLevels"), static_cast<GLint>(rects.size()));
        gl.Uniform4iv(gl.GetUniformLocation(m_program, "uLevelRect"), static_cast<GLsizei>(rects.size()), rects[0].data());
        gl.Uniform4f(gl.GetUniformLocation(m_program, "uCore"), core[0], core[1], core[2], core[3]);
        gl.Uniform1f(gl.GetUniformLocation(m_program, "uUniform"), static_cast<float>(uniformSpacing()));
        gl.BindVertexArray(m_vertexArray.id());
    }

    // Upload the source as a float texture and build its area-averaged pyramid on the GPU, then
    // rasterize the whole mesh at the CoNUS resolution.
    void drawWhole(const PassPixels& pixels, int count, GpuTimings& t, Clock::time_point& start) {
        const GladGLContext& gl = m_gl;
        GlHandle texture = makeTexture(gl), atlas = makeTexture(gl);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, texture.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, internalFormat(count), m_source.width, m_source.height);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, m_source.width, m_source.height, pixelFormat(count), GL_FLOAT, pixels.data());
        setLinearClamp(gl);
        gl.BindTexture(GL_TEXTURE_2D, atlas.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, std::max(1, m_pyramid.atlasWidth), std::max(1, m_pyramid.atlasHeight));
        setLinearClamp(gl);
        buildPyramid(m_context, gl, m_pyramid, texture.id(), atlas.id());
        checkGl(gl, kWhat);
        gl.Finish();
        t.uploadMs += millisecondsSince(start);

        setDrawState(texture.id(), atlas.id(), m_pyramid.rects, {-kFar, -kFar, kFar, kFar});
        drawMeshTimed(gl, m_mesh, t, start);
    }

    // Per tile: upload the crops of every level around its core, draw its triangles; the shader
    // keeps the pixels of its core.
    void drawTiles(const PassPixels& pixels, int first, int count, GpuTimings& t, Clock::time_point& start) {
        const GladGLContext& gl = m_gl;
        gl.BindFramebuffer(GL_FRAMEBUFFER, m_target.framebuffer.id());
        gl.ClearColor(0, 0, 0, 0);
        gl.Clear(GL_COLOR_BUFFER_BIT);
        std::vector<PassPixels> levelPixels;
        levelPixels.reserve(m_levels.size());
        for (const Image& level : m_levels) levelPixels.emplace_back(level, first, count);
        for (const Tile& tile : m_tiles) {
            if (tile.indices.empty()) continue;
            GlHandle texture = makeTexture(gl), atlas = makeTexture(gl);
            const TileLevel& crop0 = tile.levels[0];
            gl.ActiveTexture(GL_TEXTURE0);
            gl.BindTexture(GL_TEXTURE_2D, texture.id());
            gl.TexStorage2D(GL_TEXTURE_2D, 1, internalFormat(count), crop0.width, crop0.height);
            uploadCrop(gl, pixels.data(), m_source.width, count, crop0);
            setLinearClamp(gl);
            gl.BindTexture(GL_TEXTURE_2D, atlas.id());
            gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, tile.atlasWidth, tile.atlasHeight);
            for (std::size_t level = 1; level < tile.levels.size(); ++level)
                uploadCrop(gl, levelPixels[level - 1].data(), m_pyramid.rects[level][2], count, tile.levels[level]);
            setLinearClamp(gl);
            std::vector<std::array<int, 4>> rects;
            for (std::size_t level = 0; level < tile.levels.size(); ++level) {
                const TileLevel& crop = tile.levels[level];
                rects.push_back({crop.atlasX - crop.x, crop.atlasY - crop.y, m_pyramid.rects[level][2], m_pyramid.rects[level][3]});
            }
            gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, m_indexBuffer.id());
            gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(tile.indices.size() * sizeof(GLuint)),
                          tile.indices.data(), GL_STREAM_DRAW);
            checkGl(gl, kWhat);
            gl.Finish();
            t.uploadMs += millisecondsSince(start);

            setDrawState(texture.id(), atlas.id(), rects, tileCore(tile, m_source.width, m_source.height));
            gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(tile.indices.size()), GL_UNSIGNED_INT, nullptr);
            checkGl(gl, kWhat);
            gl.Finish();
            t.drawMs += millisecondsSince(start);
        }
    }

    Context& m_context;
    const GladGLContext& m_gl;
    const Image& m_source;
    Image& m_out;
    const Pyramid m_pyramid;
    const Mesh m_mesh;
    GlHandle m_vertexArray, m_vertexBuffer, m_indexBuffer;
    FloatTarget m_target;
    GLuint m_program = 0;
    std::vector<Tile> m_tiles;  // empty: not tiled
    std::vector<Image> m_levels;
};

}  // namespace

void uploadMesh(const GladGLContext& gl, const Mesh& mesh, GLuint vertexArray, GLuint vertexBuffer, GLuint indexBuffer) {
    uploadIndexedMesh(gl, vertexArray, vertexBuffer, indexBuffer, mesh.vertices, mesh.indices);
    gl.EnableVertexAttribArray(0);
    constexpr GLsizei kStride = kVertexFloats * sizeof(float);
    gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, kStride, nullptr);
    gl.EnableVertexAttribArray(1);
    gl.VertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, kStride, reinterpret_cast<const void*>(2 * sizeof(float)));
    gl.EnableVertexAttribArray(2);
    gl.VertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, kStride, reinterpret_cast<const void*>(4 * sizeof(float)));
    checkGl(gl, "encodeImageGpu");
}

void drawMeshTimed(const GladGLContext& gl, const Mesh& mesh, GpuTimings& t, Clock::time_point& start) {
    gl.ClearColor(0, 0, 0, 0);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
    checkGl(gl, "encodeImageGpu");
    gl.Finish();
    t.drawMs += millisecondsSince(start);
}

Image encodeImageGpu(Context& context, const Image& source, const codec::SamplingMap& map,
                     const codec::EncodeOptions& options, GpuTimings* timings, const GpuEncodeOptions& gpu) {
    checkImage(source, "encodeImageGpu");
    if (options.lowPassShare) options.lowPassShare->clear();  // the CPU encoder's (encode.h): the fit finds its own
    Image out = makeImage(options.width, options.height, source.channels);
    checkTextureSize(context, out.width, out.height, "encodeImageGpu", "output");
    GpuTimings t;
    Clock::time_point start = Clock::now();
    const int limit = context.textureLimit();
    const bool fits = source.width <= limit && source.height <= limit;
    const bool mipmapped = gpu.kernel == GpuEncodeKernel::Mipmapped ||
                           (gpu.kernel == GpuEncodeKernel::Auto && options.filter == codec::EncodeFilter::Anisotropic &&
                            !codec::isUniformMap(map));
    if (mipmapped && fits) {
        encodeMipmapped(context, source, map, options, gpu, out, t, start);
    } else {
        GpuEncoder encoder(context, source, map, out);
        for (int first = 0; first < source.channelCount(); first += kChannelsPerPass)
            encoder.pass(first, std::min(kChannelsPerPass, source.channelCount() - first), t, start);
        t.path = encoder.tiled() ? "ewa, tiled" : "ewa";
    }
    if (timings) *timings = t;
    return out;
}

Image encodeImage(const Device& device, const Image& source, const codec::SamplingMap& map,
                          const codec::EncodeOptions& options) {
    codec::checkEncodeMemory(source, options.width, options.height);
    return device.run([&] { return codec::encodeImage(source, map, options); },
                      [&](Context& context) { return encodeImageGpu(context, source, map, options); });
}

}  // namespace conus::renderers
