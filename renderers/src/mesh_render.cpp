// The GPU mesh encoder on a Context: one indexed draw into multisampled RGBA32F (colour, coverage)
// + R32F (camera depth) + 32-bit float depth targets, a resolve pass (mean colour, nearest depth),
// and a float readback. Rows: the camera's v (down) is GL's row index unflipped (mesh.vert.glsl), so
// the readback is top row first; no face culling (the shading is two-sided, open meshes shade).
#include "conus/renderers/mesh_render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "conus/codec/mesh/overdraw.h"
#include "conus/codec/mesh/raycast.h"
#include "context_pvt.h"
#include "embedded_shaders.h"
#include "frame_pvt.h"
#include "gl_objects_pvt.h"
#include "gpu_pass_pvt.h"
#include "shader_constants_pvt.h"

namespace conus::renderers {
namespace {

constexpr const char* kWhat = "renderMesh";
constexpr GLuint kAttributes = 4;     // position, normal, colour, uv
constexpr GLsizei kFloatsPerVertex = 11;
// A triangle patch at the largest level L (even) makes 3 (L/2) (L/2 + 1) + 1 vertices: 3169 at 64.
constexpr GLsizei kMaxPatchVertices = 3 * (kMeshMaxTessLevel / 2) * (kMeshMaxTessLevel / 2 + 1) + 1;
constexpr GLsizei kSoftwarePatchesPerDraw = 65535 / kMaxPatchVertices;
static_assert(kMeshMaxTessLevel % 2 == 0 && kSoftwarePatchesPerDraw >= 1);

enum class Albedo : GLint { VertexColour = 0, Texture = 1, Grey = 2 };

Albedo albedoOf(const Mesh& mesh) {
    if (!mesh.colours.empty()) return Albedo::VertexColour;
    if (mesh.texture && !mesh.texture->empty() && !mesh.uvs.empty()) return Albedo::Texture;
    return Albedo::Grey;
}

double elapsedMilliseconds(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// A 2-D texture (samples 1) or a multisampled one, with storage.
GlHandle makeTarget(const GladGLContext& gl, GLenum format, int samples, int width, int height) {
    GlHandle texture = makeTexture(gl);
    if (samples > 1) {
        gl.BindTexture(GL_TEXTURE_2D_MULTISAMPLE, texture.id());
        gl.TexStorage2DMultisample(GL_TEXTURE_2D_MULTISAMPLE, samples, format, width, height, GL_TRUE);
    } else {
        gl.BindTexture(GL_TEXTURE_2D, texture.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, format, width, height);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    return texture;
}

// Framebuffer with colour attachments 0 (RGBA32F) and 1 (R32F), and optionally a depth attachment.
GlHandle makeFramebufferOf(const GladGLContext& gl, GLenum textarget, GLuint colour, GLuint depth, GLuint zbuffer,
                           const std::string& what) {
    GlHandle framebuffer = makeFramebuffer(gl);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, textarget, colour, 0);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, textarget, depth, 0);
    if (zbuffer) gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, textarget, zbuffer, 0);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    gl.DrawBuffers(2, buffers);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error(ErrorCode::Unsupported, std::string(kWhat) + ": the driver cannot render to " + what);
    return framebuffer;
}

void checkOptions(const MeshRenderOptions& options) {
    if (options.samples < 1)
        throw Error(ErrorCode::InvalidArgument,
                    std::string(kWhat) + ": samples " + std::to_string(options.samples) + " is below 1");
    if (!(options.maxBend >= 0 && std::isfinite(options.maxBend)))
        throw Error(ErrorCode::InvalidArgument,
                    std::string(kWhat) + ": the largest bend " + std::to_string(options.maxBend) + " is not a finite pixel count >= 0");
}

// Whether Equation 1 is affine for `map` (every node where its corners' affine map puts it, as for
// the identity): straight edges stay straight and nothing needs splitting.
bool isAffine(const codec::SamplingMap& map) {
    const int columns = map.columns(), rows = map.rows();
    const auto node = [&](int i, int j) { return glm::dvec2(map.nodes()[static_cast<std::size_t>(j) * columns + i]); };
    const glm::dvec2 origin = node(0, 0), across = node(columns - 1, 0) - origin, down = node(0, rows - 1) - origin;
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i) {
            const glm::dvec2 affine = origin + across * (double(i) / (columns - 1)) + down * (double(j) / (rows - 1));
            if (glm::length(node(i, j) - affine) > 1e-7) return false;
        }
    return true;
}

}  // namespace

struct MeshRenderer::Impl {
    Context& context;
    GlHandle vertexArray, vertexBuffer, indexBuffer, texture, primitivesQuery;
    GLsizei indexCount = 0;
    Albedo albedo = Albedo::Grey;
    // Targets, kept between frames of one size and sample count.
    int width = 0, height = 0, samples = 0;
    std::optional<GlHandle> drawColour, drawDepth, zbuffer, drawFramebuffer;  // multisampled when samples > 1
    std::optional<GlHandle> colour, depth, resolveFramebuffer;               // samples > 1 only

    Impl(Context& c, const GladGLContext& gl)
        : context(c), vertexArray(makeVertexArray(gl)), vertexBuffer(makeBuffer(gl)), indexBuffer(makeBuffer(gl)),
          primitivesQuery(makeQuery(gl)) {}

    void ensureTargets(const GladGLContext& gl, int w, int h, int wantedSamples) {
        GLint maxSamples = 1;
        gl.GetIntegerv(GL_MAX_SAMPLES, &maxSamples);
        const int s = std::clamp(wantedSamples, 1, std::max(1, static_cast<int>(maxSamples)));
        if (w == width && h == height && s == samples && drawFramebuffer) return;
        drawFramebuffer.reset();
        resolveFramebuffer.reset();
        const std::string size = std::to_string(w) + "x" + std::to_string(h);
        const GLenum target = s > 1 ? GL_TEXTURE_2D_MULTISAMPLE : GL_TEXTURE_2D;
        drawColour = makeTarget(gl, GL_RGBA32F, s, w, h);
        drawDepth = makeTarget(gl, GL_R32F, s, w, h);
        zbuffer = makeTarget(gl, GL_DEPTH_COMPONENT32F, s, w, h);
        checkGl(gl, kWhat);
        drawFramebuffer = makeFramebufferOf(gl, target, drawColour->id(), drawDepth->id(), zbuffer->id(),
                                            size + " RGBA32F + R32F targets with " + std::to_string(s) + " samples");
        if (s > 1) {
            colour = makeTarget(gl, GL_RGBA32F, 1, w, h);
            depth = makeTarget(gl, GL_R32F, 1, w, h);
            resolveFramebuffer =
                makeFramebufferOf(gl, GL_TEXTURE_2D, colour->id(), depth->id(), 0, size + " RGBA32F + R32F targets");
        } else {
            colour.reset();
            depth.reset();
        }
        checkGl(gl, kWhat);
        width = w;
        height = h;
        samples = s;
    }
};

MeshRenderer::MeshRenderer(Context& context, const Mesh& given) {
    checkMesh(given, kWhat);
    codec::checkMeshOverdraw(given, kWhat);
    if (given.indices.size() > static_cast<std::size_t>(std::numeric_limits<GLsizei>::max()))
        throw Error(ErrorCode::LimitExceeded, std::string(kWhat) + ": too many indices for one draw");
    std::optional<Mesh> withNormals;
    if (given.normals.empty()) computeVertexNormals(withNormals.emplace(given));
    const Mesh& mesh = withNormals ? *withNormals : given;
    const GladGLContext& gl = makeCurrentGl(context);
    m_impl = std::make_unique<Impl>(context, gl);
    m_impl->albedo = albedoOf(mesh);
    // Interleaved position, normal, colour, uv: one buffer, one upload.
    const std::size_t n = mesh.positions.size();
    std::vector<float> vertices(n * kFloatsPerVertex, 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
        float* v = &vertices[i * kFloatsPerVertex];
        std::copy_n(glm::value_ptr(mesh.positions[i]), 3, v);
        std::copy_n(glm::value_ptr(mesh.normals[i]), 3, v + 3);
        if (!mesh.colours.empty()) std::copy_n(glm::value_ptr(mesh.colours[i]), 3, v + 6);
        if (!mesh.uvs.empty()) std::copy_n(glm::value_ptr(mesh.uvs[i]), 2, v + 9);
    }
    uploadIndexedMesh(gl, m_impl->vertexArray.id(), m_impl->vertexBuffer.id(), m_impl->indexBuffer.id(), vertices,
                      mesh.indices);
    const GLint sizes[kAttributes] = {3, 3, 3, 2};
    std::size_t offset = 0;
    for (GLuint a = 0; a < kAttributes; ++a) {
        gl.EnableVertexAttribArray(a);
        gl.VertexAttribPointer(a, sizes[a], GL_FLOAT, GL_FALSE, kFloatsPerVertex * sizeof(float),
                               reinterpret_cast<const void*>(static_cast<std::uintptr_t>(offset * sizeof(float))));
        offset += static_cast<std::size_t>(sizes[a]);
    }
    gl.BindVertexArray(0);
    m_impl->indexCount = static_cast<GLsizei>(mesh.indices.size());

    if (m_impl->albedo == Albedo::Texture) {
        const Image& image = *mesh.texture;
        checkImage(image, kWhat);
        if (image.width > context.textureLimit() || image.height > context.textureLimit())
            throw Error(ErrorCode::LimitExceeded, std::string(kWhat) + ": texture " + std::to_string(image.width) +
                                                      "x" + std::to_string(image.height) + " exceeds the GL texture limit " +
                                                      std::to_string(context.textureLimit()));
        // RGB by name (a grey texture repeats its one channel), rows top first as uv's (0,0) top-left.
        std::vector<float> rgb(static_cast<std::size_t>(image.width) * image.height * 3);
        const int r = image.channelIndex("R"), g = image.channelIndex("G"), b = image.channelIndex("B");
        const int y = image.channelIndex("Y") >= 0 ? image.channelIndex("Y") : 0;
        const int source[3] = {r >= 0 ? r : y, g >= 0 ? g : y, b >= 0 ? b : y};
        for (std::size_t p = 0; p < rgb.size() / 3; ++p)
            for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = image.pixels[p * image.channels.size() + source[c]];
        m_impl->texture = makeTexture(gl);
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_2D, m_impl->texture.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGB32F, image.width, image.height);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.width, image.height, GL_RGB, GL_FLOAT, rgb.data());
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
        gl.ActiveTexture(GL_TEXTURE0);
    }
    checkGl(gl, kWhat);
}

MeshRenderer::~MeshRenderer() {
    // The GL objects are deleted in this context: make it current first.
    if (m_impl) makeCurrentGl(m_impl->context);
}

Image MeshRenderer::render(const Camera& camera, const codec::SamplingMap& map, int width, int height,
                           const MeshRenderOptions& options, GpuTimings* timings, std::int64_t* trianglesDrawn) {
    return frame(camera, map, width, height, options, timings, trianglesDrawn, nullptr);
}

std::vector<Image> MeshRenderer::renderLayers(const Camera& camera, const codec::SamplingMap& map, int width,
                                              int height, int layers, const MeshRenderOptions& options) {
    if (layers < 1) throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": layers must be at least 1");
    MeshRenderOptions one = options;
    one.samples = 1;  // a previous layer's depth is one per pixel
    std::vector<Image> out;
    out.reserve(static_cast<std::size_t>(layers));
    for (int k = 0; k < layers; ++k)
        out.push_back(frame(camera, map, width, height, one, nullptr, nullptr, k == 0 ? nullptr : &out.back()));
    return out;
}

Image MeshRenderer::frame(const Camera& camera, const codec::SamplingMap& map, int width, int height,
                          const MeshRenderOptions& options, GpuTimings* timings, std::int64_t* trianglesDrawn,
                          const Image* behind) {
    Context& context = m_impl->context;
    checkFrame(context, width, height, kWhat);
    checkOptions(options);
    const GladGLContext& gl = makeCurrentGl(context);
    auto phase = std::chrono::steady_clock::now();
    const bool tessellate = options.maxBend > 0 && !isAffine(map);
    const GLuint program =
        tessellate ? cachedProgram(context, "mesh_tessellated",
                                   {{GL_VERTEX_SHADER, shaders::kShaderMeshPatchVert},
                                    {GL_TESS_CONTROL_SHADER, shaders::kShaderMeshTesc},
                                    {GL_TESS_EVALUATION_SHADER, shaders::kShaderMeshTese},
                                    {GL_FRAGMENT_SHADER, shaders::kShaderMeshFrag}})
                   : cachedProgram(context, "mesh", shaders::kShaderMeshVert, shaders::kShaderMeshFrag);
    m_impl->ensureTargets(gl, width, height, options.samples);
    Impl& impl = *m_impl;

    std::vector<float> nodes(map.nodes().size() * 2);
    for (std::size_t i = 0; i < map.nodes().size(); ++i) {
        nodes[2 * i] = map.nodes()[i].x;
        nodes[2 * i + 1] = map.nodes()[i].y;
    }
    const GlHandle mapTexture = uploadMapTexture(gl, GL_TEXTURE0, map.columns(), map.rows(), nodes.data());
    if (timings) {
        gl.Finish();
        timings->uploadMs = elapsedMilliseconds(phase);
        phase = std::chrono::steady_clock::now();
    }

    const glm::mat4 worldToNdc(camera.worldToNdcMatrix());
    // Row-vector matrices (OpenEXR's) are glm's column-major memory: depth is column 2 of the
    // row-vector matrix, i.e. elements 2, 6, 10, 14.
    const std::array<float, 16> w2c = camera.worldToCamera();
    const glm::vec4 depthRow(w2c[2], w2c[6], w2c[10], w2c[14]);
    const glm::vec3 eye(camera.eye()), forward(camera.forward());

    gl.BindFramebuffer(GL_FRAMEBUFFER, impl.drawFramebuffer->id());
    gl.Viewport(0, 0, width, height);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.Disable(GL_CULL_FACE);
    if (impl.samples > 1) gl.Enable(GL_MULTISAMPLE);
    const float clearColour[4] = {0, 0, 0, 0};
    const float clearDepth[4] = {static_cast<float>(camera.far()), 0, 0, 0};
    gl.ClearBufferfv(GL_COLOR, 0, clearColour);
    gl.ClearBufferfv(GL_COLOR, 1, clearDepth);
    gl.ClearDepth(1.0);
    gl.Clear(GL_DEPTH_BUFFER_BIT);
    gl.UseProgram(program);
    gl.UniformMatrix4fv(gl.GetUniformLocation(program, "uWorldToNdc"), 1, GL_FALSE, glm::value_ptr(worldToNdc));
    gl.Uniform4fv(gl.GetUniformLocation(program, "uDepthRow"), 1, glm::value_ptr(depthRow));
    gl.Uniform1i(gl.GetUniformLocation(program, "uMap"), 0);
    gl.Uniform1i(gl.GetUniformLocation(program, "uTexture"), 1);
    gl.Uniform1i(gl.GetUniformLocation(program, "uAlbedo"), static_cast<GLint>(impl.albedo));
    gl.Uniform1i(gl.GetUniformLocation(program, "uPerspective"), camera.projection() == Projection::Perspective);
    gl.Uniform3fv(gl.GetUniformLocation(program, "uEye"), 1, glm::value_ptr(eye));
    gl.Uniform3fv(gl.GetUniformLocation(program, "uForward"), 1, glm::value_ptr(forward));
    gl.Uniform2f(gl.GetUniformLocation(program, "uPixels"), static_cast<float>(width), static_cast<float>(height));
    // At least a millionth of a pixel: a bound that rounds to float 0 would make 0 / 0 levels.
    gl.Uniform1f(gl.GetUniformLocation(program, "uMaxBend"), static_cast<float>(std::max(options.maxBend, 1e-6)));
    if (impl.texture) {
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_2D, impl.texture.id());
        gl.ActiveTexture(GL_TEXTURE0);
    }
    // Peeling: the previous layer's camera depth a pixel, in the rows the readback gave them.
    std::optional<GlHandle> behindDepth;
    gl.Uniform1i(gl.GetUniformLocation(program, "uPeel"), behind != nullptr);
    gl.Uniform1i(gl.GetUniformLocation(program, "uBehind"), 4);
    if (behind) {
        std::vector<float> z(static_cast<std::size_t>(width) * height);
        for (std::size_t p = 0; p < z.size(); ++p) z[p] = behind->pixels[p * 5 + 4];
        behindDepth = makeTexture(gl);
        gl.ActiveTexture(GL_TEXTURE4);
        gl.BindTexture(GL_TEXTURE_2D, behindDepth->id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_R32F, width, height);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RED, GL_FLOAT, z.data());
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.Uniform1f(gl.GetUniformLocation(program, "uPeelGap"), static_cast<float>(codec::kPeelGap));
    }
    gl.BindVertexArray(impl.vertexArray.id());
    if (trianglesDrawn) gl.BeginQuery(GL_PRIMITIVES_GENERATED, impl.primitivesQuery.id());
    if (tessellate) {
        gl.PatchParameteri(GL_PATCH_VERTICES, 3);
        // Mesa's software rasterizers number the vertices of one draw in 16 bits, tessellated ones
        // included, so a draw there holds no more patches than can make 65535 vertices at the
        // largest level; elsewhere one draw holds them all.
        const GLsizei perDraw = isSoftwareRasterizer(context.renderer()) ? 3 * kSoftwarePatchesPerDraw : impl.indexCount;
        for (GLsizei first = 0; first < impl.indexCount; first += perDraw)
            gl.DrawElements(GL_PATCHES, std::min(perDraw, impl.indexCount - first), GL_UNSIGNED_INT,
                            reinterpret_cast<const void*>(static_cast<std::uintptr_t>(first) * sizeof(GLuint)));
    } else {
        gl.DrawElements(GL_TRIANGLES, impl.indexCount, GL_UNSIGNED_INT, nullptr);
    }
    if (trianglesDrawn) {
        gl.EndQuery(GL_PRIMITIVES_GENERATED);
        GLuint64 generated = 0;
        gl.GetQueryObjectui64v(impl.primitivesQuery.id(), GL_QUERY_RESULT, &generated);
        *trianglesDrawn = static_cast<std::int64_t>(generated);
    }
    gl.BindVertexArray(0);
    gl.Disable(GL_DEPTH_TEST);
    checkGl(gl, kWhat);

    GLuint readFramebuffer = impl.drawFramebuffer->id();
    if (impl.samples > 1) {
        // Mean colour, nearest depth (mesh_resolve.frag.glsl), into the single-sample targets.
        const GLuint resolve =
            cachedProgram(context, "mesh_resolve", shaders::kShaderFullscreenVert, shaders::kShaderMeshResolveFrag);
        gl.BindFramebuffer(GL_FRAMEBUFFER, impl.resolveFramebuffer->id());
        gl.UseProgram(resolve);
        gl.ActiveTexture(GL_TEXTURE2);
        gl.BindTexture(GL_TEXTURE_2D_MULTISAMPLE, impl.drawColour->id());
        gl.ActiveTexture(GL_TEXTURE3);
        gl.BindTexture(GL_TEXTURE_2D_MULTISAMPLE, impl.drawDepth->id());
        gl.ActiveTexture(GL_TEXTURE0);
        gl.Uniform1i(gl.GetUniformLocation(resolve, "uColour"), 2);
        gl.Uniform1i(gl.GetUniformLocation(resolve, "uDepth"), 3);
        gl.Uniform1i(gl.GetUniformLocation(resolve, "uSamples"), impl.samples);
        gl.BindVertexArray(context.impl().emptyVertexArray);
        gl.DrawArrays(GL_TRIANGLES, 0, 3);
        gl.BindVertexArray(0);
        checkGl(gl, kWhat);
        readFramebuffer = impl.resolveFramebuffer->id();
    }
    if (timings) {
        gl.Finish();
        timings->drawMs = elapsedMilliseconds(phase);
        phase = std::chrono::steady_clock::now();
    }

    gl.BindFramebuffer(GL_FRAMEBUFFER, readFramebuffer);
    Image frame = readColourAndDepth(gl, width, height);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl(gl, kWhat);
    if (timings) timings->readbackMs = elapsedMilliseconds(phase);
    return frame;
}

Image renderMeshGpu(Context& context, const Mesh& mesh, const Camera& camera, const codec::SamplingMap& map,
                    int width, int height, const MeshRenderOptions& options) {
    MeshRenderer renderer(context, mesh);
    return renderer.render(camera, map, width, height, options);
}

Image renderMesh(const Device& device, const Mesh& mesh, const Camera& camera, const codec::SamplingMap& map,
                 int width, int height, const MeshRenderOptions& options) {
    checkOptions(options);
    return device.run(
        [&] {
            codec::ReferenceOptions reference;
            const int side = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(options.samples)))));
            reference.samplesPerPixel = side * side;
            const codec::MeshScene scene(mesh);
            return codec::renderMeshReference(scene, Fpc(camera, std::make_shared<codec::SamplingMap>(map)), width,
                                              height, reference);
        },
        [&](Context& context) { return renderMeshGpu(context, mesh, camera, map, width, height, options); });
}

}  // namespace conus::renderers
