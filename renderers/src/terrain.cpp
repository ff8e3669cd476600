// Height-field mesh rendering on a Context: one indexed draw into a (multisampled) RGBA32F + 32-bit
// float depth framebuffer, resolved and read back.
//
// Rows: the camera's v (down) becomes GL's y unflipped, so GL's window row 0 holds the top of the
// frame and the readback is already in the image-plane order (the winding flips too, which does
// not matter: no face culling, a height field is seen from both sides).
#include "conus/renderers/terrain.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>
#include <optional>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "context_pvt.h"
#include "embedded_shaders.h"
#include "frame_pvt.h"
#include "gl_objects_pvt.h"

namespace conus::renderers {
namespace {

constexpr const char* kWhat = "renderTerrain";
constexpr double kPi = 3.14159265358979323846;


}  // namespace

Camera viewerCamera(const codec::GroundParams& ground, double groundHeight, double aspect, double sideways,
                    double turnDegrees, double fovYDegrees) {
    const glm::dvec2 extent = codec::fieldExtent(ground);
    const glm::dvec3 eye{0.5 * extent.x + sideways, groundHeight + ground.eyeHeight, extent.y + ground.near};
    // Pitched so the field's near edge lands on the bottom row (the rows the ground map samples
    // most densely are then in view), unless that would lift the far edge out of the top half.
    const double halfFov = 0.5 * fovYDegrees * kPi / 180.0;
    const double pitch = std::min(std::atan2(ground.eyeHeight, ground.near) - halfFov,
                                  std::atan2(ground.eyeHeight, ground.far) + 0.5 * halfFov);
    const double turn = turnDegrees * kPi / 180.0;
    const glm::dvec3 direction(-std::sin(turn) * std::cos(pitch), -std::sin(pitch), -std::cos(turn) * std::cos(pitch));
    return Camera::perspective(eye, eye + direction * ground.far, {0, 1, 0}, fovYDegrees, aspect,
                               std::max(0.05, 0.02 * ground.eyeHeight), 4.0 * (ground.far + extent.x));
}

struct TerrainRenderer::Impl {
    Context& context;
    TerrainLook look;
    GlHandle vertexArray, vertexBuffer, indexBuffer;
    GLsizei indexCount = 0;
    // Framebuffers, kept between frames of one size.
    int width = 0, height = 0, samples = 1;
    std::optional<GlHandle> colour, depth, resolveTexture, drawFramebuffer, resolveFramebuffer;

    Impl(Context& c, const GladGLContext& gl, const TerrainLook& l)
        : context(c), look(l), vertexArray(makeVertexArray(gl)), vertexBuffer(makeBuffer(gl)),
          indexBuffer(makeBuffer(gl)) {}

    void ensureTargets(const GladGLContext& gl, int w, int h) {
        if (w == width && h == height && drawFramebuffer) return;
        drawFramebuffer.reset();
        resolveFramebuffer.reset();
        colour.reset();
        depth.reset();
        resolveTexture.reset();
        GLint maxSamples = 1;
        gl.GetIntegerv(GL_MAX_SAMPLES, &maxSamples);
        samples = std::clamp(look.samples, 1, std::max(1, static_cast<int>(maxSamples)));

        resolveTexture.emplace(gl.GenTextures, gl.DeleteTextures);
        gl.BindTexture(GL_TEXTURE_2D, resolveTexture->id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, w, h);
        resolveFramebuffer.emplace(gl.GenFramebuffers, gl.DeleteFramebuffers);
        gl.BindFramebuffer(GL_FRAMEBUFFER, resolveFramebuffer->id());
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, resolveTexture->id(), 0);

        colour.emplace(gl.GenRenderbuffers, gl.DeleteRenderbuffers);
        gl.BindRenderbuffer(GL_RENDERBUFFER, colour->id());
        gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? samples : 0, GL_RGBA32F, w, h);
        depth.emplace(gl.GenRenderbuffers, gl.DeleteRenderbuffers);
        gl.BindRenderbuffer(GL_RENDERBUFFER, depth->id());
        gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? samples : 0, GL_DEPTH_COMPONENT32F, w, h);
        drawFramebuffer.emplace(gl.GenFramebuffers, gl.DeleteFramebuffers);
        gl.BindFramebuffer(GL_FRAMEBUFFER, drawFramebuffer->id());
        gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour->id());
        gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth->id());
        checkGl(gl, kWhat);
        if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw Error(ErrorCode::Unsupported, std::string(kWhat) + ": the driver cannot render to a " +
                                                    std::to_string(w) + "x" + std::to_string(h) + " RGBA32F framebuffer with " +
                                                    std::to_string(samples) + " samples");
        width = w;
        height = h;
    }
};

TerrainRenderer::TerrainRenderer(Context& context, const Mesh& mesh, const TerrainLook& look) {
    const std::size_t n = mesh.positions.size();
    if (n == 0 || mesh.colours.size() != n || mesh.normals.size() != n || mesh.indices.empty() ||
        mesh.indices.size() % 3 != 0)
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": mesh with " + std::to_string(n) +
                                                    " positions, " + std::to_string(mesh.colours.size()) +
                                                    " colours, " + std::to_string(mesh.normals.size()) +
                                                    " normals and " + std::to_string(mesh.indices.size()) +
                                                    " indices is empty or inconsistent");
    if (*std::max_element(mesh.indices.begin(), mesh.indices.end()) >= n)
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": a mesh index is out of range");
    if (mesh.indices.size() > static_cast<std::size_t>(std::numeric_limits<GLsizei>::max()))
        throw Error(ErrorCode::LimitExceeded, std::string(kWhat) + ": too many indices for one draw");

    const GladGLContext& gl = makeCurrentGl(context);
    m_impl = std::make_unique<Impl>(context, gl, look);
    // Interleaved position, colour, normal: one buffer, one upload.
    std::vector<float> vertices(n * 9);
    for (std::size_t i = 0; i < n; ++i) {
        std::copy_n(glm::value_ptr(mesh.positions[i]), 3, &vertices[i * 9]);
        std::copy_n(glm::value_ptr(mesh.colours[i]), 3, &vertices[i * 9 + 3]);
        std::copy_n(glm::value_ptr(mesh.normals[i]), 3, &vertices[i * 9 + 6]);
    }
    uploadIndexedMesh(gl, m_impl->vertexArray.id(), m_impl->vertexBuffer.id(), m_impl->indexBuffer.id(), vertices,
                      mesh.indices);
    for (GLuint a = 0; a < 3; ++a) {
        gl.EnableVertexAttribArray(a);
        gl.VertexAttribPointer(a, 3, GL_FLOAT, GL_FALSE, 9 * sizeof(float),
                               reinterpret_cast<const void*>(static_cast<std::uintptr_t>(a * 3 * sizeof(float))));
    }
    gl.BindVertexArray(0);
    m_impl->indexCount = static_cast<GLsizei>(mesh.indices.size());
    checkGl(gl, kWhat);
}

TerrainRenderer::~TerrainRenderer() {
    // The GL objects are deleted in this context: make it current first.
    if (m_impl) makeCurrentGl(m_impl->context);
}

Image TerrainRenderer::render(const Camera& camera, int width, int height) {
    Context& context = m_impl->context;
    checkFrame(context, width, height, kWhat);
    const GladGLContext& gl = makeCurrentGl(context);
    const GLuint program = cachedProgram(context, "terrain", shaders::kShaderTerrainVert, shaders::kShaderTerrainFrag);
    m_impl->ensureTargets(gl, width, height);

    // The camera's NDC (u, v, z in [0,1]) to GL's clip space ([-1,1]^3). v stays the row index,
    // so GL's row 0 holds v = 0 and the readback comes out top row first (see the file comment).
    glm::dmat4 toClip(0.0);
    toClip[0][0] = toClip[1][1] = toClip[2][2] = 2.0;
    toClip[3] = glm::dvec4(-1.0, -1.0, -1.0, 1.0);
    const glm::mat4 viewProjection(toClip * camera.worldToNdcMatrix());
    const glm::vec3 towardSun = glm::normalize(m_impl->look.towardSun);

    gl.BindFramebuffer(GL_FRAMEBUFFER, m_impl->drawFramebuffer->id());
    gl.Viewport(0, 0, width, height);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.Disable(GL_CULL_FACE);
    if (m_impl->samples > 1) gl.Enable(GL_MULTISAMPLE);
    gl.ClearColor(m_impl->look.sky.r, m_impl->look.sky.g, m_impl->look.sky.b, 1.0f);
    gl.ClearDepth(1.0);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl.UseProgram(program);
    gl.UniformMatrix4fv(gl.GetUniformLocation(program, "uViewProjection"), 1, GL_FALSE, glm::value_ptr(viewProjection));
    gl.Uniform3f(gl.GetUniformLocation(program, "uTowardSun"), towardSun.x, towardSun.y, towardSun.z);
    gl.Uniform1f(gl.GetUniformLocation(program, "uAmbient"), m_impl->look.ambient);
    gl.BindVertexArray(m_impl->vertexArray.id());
    gl.DrawElements(GL_TRIANGLES, m_impl->indexCount, GL_UNSIGNED_INT, nullptr);
    gl.BindVertexArray(0);
    gl.Disable(GL_DEPTH_TEST);
    checkGl(gl, kWhat);

    // Resolve the samples (a plain copy without multisampling) and read back RGB floats.
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, m_impl->drawFramebuffer->id());
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, m_impl->resolveFramebuffer->id());
    gl.BlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    gl.BindFramebuffer(GL_FRAMEBUFFER, m_impl->resolveFramebuffer->id());
    Image frame = readRgbFrame(gl, width, height);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl(gl, kWhat);
    return frame;
}

Image renderTerrain(Context& context, const Mesh& mesh, const Camera& camera, int width,
                            int height, const TerrainLook& look) {
    TerrainRenderer renderer(context, mesh, look);
    return renderer.render(camera, width, height);
}

codec::GroundParams heightFieldGround(const format::ConusFile& file, const std::string& name) {
    if (file.dataKind != format::DataKind::HeightField || !file.analytic || file.analytic->kind != "ground")
        throw Error(ErrorCode::InvalidArgument, name + " is not a CoNUS height field with ground-map parameters");
    return codec::groundFromAnalytic(*file.analytic);
}

Camera heightFieldCamera(const format::ConusFile& file, double aspect, const std::optional<TerrainView>& view) {
    const Camera viewer = viewerCamera(heightFieldGround(file), codec::heightAt(file, {0.5, 1.0}), aspect);
    if (!view) return viewer;
    return Camera::perspective(view->eye, view->target, {0, 1, 0}, view->fovYDegrees, aspect, viewer.near(), viewer.far());
}

Image renderHeightFieldFrame(Context& context, const format::ConusFile& file, const Camera& camera, int width, int height) {
    const glm::dvec2 extent = codec::fieldExtent(heightFieldGround(file));
    return renderTerrain(context, codec::undistortHeightField(file, extent), camera, width, height);
}

}  // namespace conus::renderers
