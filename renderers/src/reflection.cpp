// Reflection frames on a Context (reflection.h): the scene behind from the mesh renderer (a pixel
// a ray), then one full-screen pass (reflection.frag.glsl) through intersect.inc.glsl. Window row 0
// is the frame's top row, as in the other renderers, so readbacks need no flip.
#include "conus/renderers/reflection.h"

#include <array>
#include <limits>
#include <optional>
#include <string>

#include <glm/gtc/type_ptr.hpp>

#include "conus/codec/mesh/shading.h"
#include "conus/renderers/mesh_render.h"
#include "context_pvt.h"
#include "depth_pvt.h"
#include "embedded_shaders.h"
#include "frame_pvt.h"
#include "gl_objects_pvt.h"

namespace conus::renderers {
namespace {

constexpr const char* kWhat = "reflection";
constexpr int kUnitsPerFace = 3;                               // depths, map nodes, colour
constexpr int kBehindUnit = codec::kCubeFaces * kUnitsPerFace;  // the scene behind
// What the scene behind stores as the depth of a pixel that sees nothing: beyond any mirror.
constexpr float kNothingBehind = std::numeric_limits<float>::max();

// A face's colour and coverage, R, G, B, A interleaved, from its mesh render.
std::vector<float> colourAndCoverage(const Image& image) {
    const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
    std::vector<float> out(pixels * 4);
    for (std::size_t p = 0; p < pixels; ++p)
        for (int k = 0; k < 4; ++k) out[p * 4 + k] = image.pixels[p * image.channels.size() + k];
    return out;
}

struct ReflectionScene : DepthFrameRenderer::Scene {
    codec::ReflectionFrameOptions options;
    MeshRenderer scene;
    std::vector<DepthTextures> depths;
    std::array<GlHandle, codec::kCubeFaces> colours;
    std::vector<codec::DepthImage> images;  // their cameras and depth ranges, for the uniforms
    int layers = 1;                         // each face's
    GlHandle behind;

    ReflectionScene(Context& c, const GladGLContext& gl, const Mesh& mesh, const std::vector<codec::ReflectionFace>& f,
                    const codec::ReflectionFrameOptions& o)
        : Scene(c, kWhat, {"R", "G", "B", "M"}), options(o), scene(c, mesh) {
        depths.reserve(codec::kCubeFaces);
        for (int k = 0; k < codec::kCubeFaces; ++k) {
            const codec::ReflectionFace& face = f[static_cast<std::size_t>(k)];
            images.push_back(face.depth);
            // The layers side by side (intersect.inc.glsl), in the depths and in the colours.
            std::vector<const codec::DepthImage*> layers;
            std::vector<std::vector<float>> rgba;
            for (int l = 0; l < face.layers(); ++l) {
                layers.push_back(&face.layerDepth(l));
                rgba.push_back(colourAndCoverage(face.layerImage(l)));
            }
            depths.emplace_back(c, gl, layers, kWhat, k * kUnitsPerFace);
            colours[static_cast<std::size_t>(k)] =
                floatTexture(gl, GL_TEXTURE0 + static_cast<GLenum>(k * kUnitsPerFace + 2), face.image.width * face.layers(),
                             face.image.height, 4, codec::sideBySide(rgba, face.image.width, face.image.height, 4).data());
        }
        layers = f.front().layers();
    }

    void drawFrame(const Camera& camera, int w, int h) override {
        checkFrame(context, w, h, kWhat);
        // The scene behind: R, G, B and camera depth (kNothingBehind where nothing was hit), one
        // pixel a ray: the frame's size times the rays a pixel a side, as the CPU shades each ray.
        const int n = options.samples;
        if (w > kMaxFrameSide / n || h > kMaxFrameSide / n)
            throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": " + std::to_string(n) + "x" + std::to_string(n) +
                                                        " rays a pixel over a " + std::to_string(w) + "x" + std::to_string(h) +
                                                        " frame need a scene frame of over " + std::to_string(kMaxFrameSide) + " a side");
        checkFrame(context, w * n, h * n, kWhat);
        MeshRenderOptions one;
        one.samples = 1;
        const Image mesh = scene.render(camera, codec::SamplingMap::identity(2, 2), w * n, h * n, one);
        std::vector<float> rgbz(static_cast<std::size_t>(w * n) * std::size_t(h * n) * 4);
        for (std::size_t p = 0; p < rgbz.size() / 4; ++p) {
            const float* m = &mesh.pixels[p * mesh.channels.size()];
            rgbz[p * 4] = m[codec::kMeshChannelR];
            rgbz[p * 4 + 1] = m[codec::kMeshChannelR + 1];
            rgbz[p * 4 + 2] = m[codec::kMeshChannelR + 2];
            rgbz[p * 4 + 3] = m[codec::kMeshChannelA] > 0.0f ? m[codec::kMeshChannelZ] : kNothingBehind;
        }
        const GladGLContext& gl = makeCurrentGl(context);
        behind = floatTexture(gl, GL_TEXTURE0 + kBehindUnit, w * n, h * n, 4, rgbz.data());

        const GLuint program =
            cachedProgram(context, "reflection", shaders::kShaderFullscreenVert, shaders::kShaderReflectionFrag);
        target.ensure(gl, w, h, GL_TEXTURE0 + kBehindUnit + 1, kWhat);
        gl.UseProgram(program);
        const auto at = [&](const std::string& name) { return gl.GetUniformLocation(program, name.c_str()); };
        for (int k = 0; k < codec::kCubeFaces; ++k) {
            const std::size_t f = static_cast<std::size_t>(k);
            const std::string index = "[" + std::to_string(k) + "]";
            depths[f].bind(gl);
            setDepthView(gl, program, images[f], depths[f], "uViews" + index, "uDepths" + index, "uMaps" + index);
            gl.ActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(k * kUnitsPerFace + 2));
            gl.BindTexture(GL_TEXTURE_2D, colours[f].id());
            gl.Uniform1i(at("uColours" + index), k * kUnitsPerFace + 2);
            gl.Uniform1f(at("uFar" + index), static_cast<float>(images[f].camera().far()));
        }
        gl.ActiveTexture(GL_TEXTURE0 + kBehindUnit);
        gl.BindTexture(GL_TEXTURE_2D, behind.id());
        gl.Uniform1i(at("uBehind"), kBehindUnit);
        gl.Uniform1i(at("uLayers"), layers);
        gl.Uniform1i(at("uSamples"), n);
        setIntersectOptions(gl, program, options.intersect);
        gl.Uniform1f(at("uTMax"), static_cast<float>(std::min(options.intersect.tMax, 1e30)));
        // Camera::ray as affine functions of uv (reflection.frag.glsl).
        const auto ray = [&](glm::dvec2 uv) { return camera.ray(uv); };
        const Ray r00 = ray({0, 0}), r10 = ray({1, 0}), r01 = ray({0, 1});
        // Perspective directions are affine in uv before normalization: at camera depth 1.
        const auto along = [&](const Ray& r) { return r.direction / glm::dot(r.direction, camera.forward()); };
        const auto set3 = [&](const char* name, glm::dvec3 v) {
            gl.Uniform3f(at(name), static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z));
        };
        set3("uRayO0", r00.origin);
        set3("uRayOU", r10.origin - r00.origin);
        set3("uRayOV", r01.origin - r00.origin);
        set3("uRayD0", along(r00));
        set3("uRayDU", along(r10) - along(r00));
        set3("uRayDV", along(r01) - along(r00));
        set3("uFrameEye", camera.eye());
        set3("uFrameForward", camera.forward());
        gl.Uniform2f(at("uFrameSize"), static_cast<float>(w), static_cast<float>(h));
        const codec::Reflector& r = options.reflector;
        const glm::vec3 centre(r.centre), normal(glm::normalize(r.normal));
        gl.Uniform1i(at("uReflectorKind"), r.kind == codec::Reflector::Kind::Sphere ? 0 : 1);
        gl.Uniform3f(at("uReflectorCentre"), centre.x, centre.y, centre.z);
        gl.Uniform1f(at("uReflectorRadius"), static_cast<float>(r.radius));
        gl.Uniform3f(at("uReflectorNormal"), normal.x, normal.y, normal.z);
        gl.Uniform3f(at("uSky"), codec::kReflectionSky[0], codec::kReflectionSky[1], codec::kReflectionSky[2]);
        drawFullscreen(context, gl, w, h, kWhat);
    }
};

std::unique_ptr<DepthFrameRenderer::Scene> reflectionScene(Context& context, const Mesh& scene,
                                                           const std::vector<codec::ReflectionFace>& faces,
                                                           const codec::ReflectionFrameOptions& options) {
    codec::checkIntersectOptions(options.intersect);
    if (options.samples < 1 || options.samples > codec::kMaxFrameSamples)
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": 1 to " + std::to_string(codec::kMaxFrameSamples) +
                                                    " rays a pixel a side, not " + std::to_string(options.samples));
    if (faces.size() != static_cast<std::size_t>(codec::kCubeFaces))
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": " + std::to_string(faces.size()) +
                                                    " faces; the GPU renderer draws a cube of " +
                                                    std::to_string(codec::kCubeFaces));
    for (const codec::ReflectionFace& face : faces) {
        if (face.layers() != faces.front().layers())
            throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": every face has one count of layers");
        for (int l = 0; l < face.layers(); ++l) {
            const Image& image = face.layerImage(l);
            const codec::DepthImage& depth = face.layerDepth(l);
            if (image.width != face.depth.width() || image.height != face.depth.height() || depth.width() != image.width ||
                depth.height() != image.height || image.channels.size() < 4)
                throw Error(ErrorCode::InvalidArgument,
                            std::string(kWhat) + ": a face's colour is not R, G, B, A of its depth image's size");
        }
    }
    const codec::Reflector& r = options.reflector;
    if (!(r.radius > 0.0) || !(glm::length(r.normal) > 0.0))
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": the reflector needs a radius > 0 and a normal");
    const GladGLContext& gl = makeCurrentGl(context);
    GLint units = 0;
    gl.GetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &units);
    if (units < kBehindUnit + 1)
        throw Error(ErrorCode::Unsupported, std::string(kWhat) + ": the driver has " + std::to_string(units) +
                                                " fragment texture units; the reflection pass needs " +
                                                std::to_string(kBehindUnit + 1));
    auto made = std::make_unique<ReflectionScene>(context, gl, scene, faces, options);
    checkGl(gl, kWhat);
    return made;
}

}  // namespace

ReflectionRenderer::ReflectionRenderer(Context& context, const Mesh& scene,
                                       const std::vector<codec::ReflectionFace>& faces,
                                       const codec::ReflectionFrameOptions& options)
    : DepthFrameRenderer(reflectionScene(context, scene, faces, options)) {}

Image renderReflection(const Device& device, const codec::MeshScene& scene,
                       const std::vector<codec::ReflectionFace>& faces, const Camera& camera, int width, int height,
                       const codec::ReflectionFrameOptions& options) {
    return device.run(
        [&] {
            const glm::dvec3 centre = faces.empty() ? options.reflector.centre : faces.front().depth.camera().eye();
            return codec::renderReflectionFrame(scene, &faces, centre, camera, width, height, options);
        },
        [&](Context& context) {
            return ReflectionRenderer(context, scene.mesh(), faces, options).render(camera, width, height);
        });
}

}  // namespace conus::renderers
