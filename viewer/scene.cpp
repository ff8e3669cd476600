#include "scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "conus/codec/depth/intersect.h"
#include "conus/codec/depth/reflection.h"
#include "conus/codec/mesh/raycast.h"
#include "conus/codec/mesh/subdivide.h"
#include "conus/codec/volume/procedural.h"
#include "conus/codec/volume/raycast.h"
#include "conus/codec/volume/transfer_function.h"
#include "conus/core/error.h"
#include "conus/format/container.h"
#include "conus/renderers/mesh_render.h"
#include "conus/renderers/reflection.h"
#include "conus/renderers/relief.h"
#include "conus/renderers/volume_renderer.h"
#include "conus/sceneio/mesh_file.h"
#include "conus/sceneio/volume_file.h"
#include "scene_state.h"

namespace conus::viewer {
namespace {

// A mesh file, what readMesh dropped said on stderr as the viewer's other messages are; the files it
// names may lie in its folder or in --allow-dir's.
Mesh readMeshFile(const std::string& path, const std::vector<std::string>& allowDirs) {
    return sceneio::readMesh(path, {.warn = [](const std::string& text) {
                                        std::fprintf(stderr, "conus-view: warning: %s\n", text.c_str());
                                    },
                                    .allowedDirs = allowDirs});
}

// A volume file (or procedural: spec); an NRRD's data files may lie in its folder or in --allow-dir's.
Volume readVolumeFile(const Options& options) {
    if (options.scenePath.rfind("procedural:", 0) == 0) return codec::proceduralVolume(options.scenePath);
    sceneio::VolumeReadOptions read;
    read.allowedDirs = options.allowDirs;
    return sceneio::readVolume(options.scenePath, read);
}

std::string fileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

template <class Points>
BoundingSphere sphereAround(const Points& points) {
    return boundingSphere(std::vector<glm::dvec3>(points.begin(), points.end()));
}

// Only R, G, B of a frame with more channels (the reflection frame's M is a label, not a colour).
Image colourOf(const Image& frame) {
    Image rgb = makeImage(frame.width, frame.height, {"R", "G", "B"});
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x)
            for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = frame.at(x, y, c);
    return rgb;
}

class MeshView final : public Scene {
public:
    MeshView(renderers::Context& context, const std::string& path, const std::vector<std::string>& allowDirs, double maxEdge,
             double maxBend)
        : m_context(context), m_name(fileName(path) + " (mesh)"), m_mesh(readMeshFile(path, allowDirs)),
          m_bounds(sphereAround(m_mesh.positions)), m_maxEdge(maxEdge), m_renderer(context, m_mesh) {
        m_options.maxBend = maxBend;
    }
    std::string name() const override { return m_name; }
    glm::dvec3 centre() const override { return m_bounds.centre; }
    double radius() const override { return m_bounds.radius; }
    Image render(const Camera& camera, const codec::SamplingMap& map, bool conus, int width, int height) override {
        // --max-edge: this frame's subdivision (the camera and the map decide it), uploaded for this
        // frame and drawn as it is; otherwise the renderer splits where the map bends (tessellation).
        if (m_maxEdge > 0 && conus) {
            renderers::MeshRenderOptions asSplit;
            asSplit.maxBend = 0;
            return renderers::renderMeshGpu(m_context, codec::subdivideForMap(m_mesh, camera, map, m_maxEdge), camera, map,
                                            width, height, asSplit);
        }
        return m_renderer.render(camera, map, width, height, m_options);
    }

private:
    renderers::Context& m_context;
    std::string m_name;
    Mesh m_mesh;
    BoundingSphere m_bounds;
    double m_maxEdge;
    renderers::MeshRenderOptions m_options;
    renderers::MeshRenderer m_renderer;
};

class VolumeView final : public Scene {
public:
    VolumeView(renderers::Context& context, const Options& options)
        : m_name(fileName(options.scenePath) + " (volume)"),
          m_volume(readVolumeFile(options)),
          m_presets(codec::TransferFunction::presetNames()) {
        // The command line's default preset when none is named, so both show a volume alike.
        const std::string tf = options.transferFunction.empty() ? codec::TransferFunction::kDefaultPreset
                                                                : options.transferFunction;
        const auto preset = std::find(m_presets.begin(), m_presets.end(), tf);
        if (preset != m_presets.end()) m_preset = static_cast<int>(preset - m_presets.begin());
        else m_file = tf;  // a file: T cycles on through the presets
        m_renderer = std::make_unique<renderers::VolumeRendererGpu>(context, m_volume, transferFunction());
    }
    std::string name() const override { return m_name; }
    glm::dvec3 centre() const override { return 0.5 * m_volume.extent(); }
    double radius() const override { return std::max(1e-6, 0.5 * glm::length(m_volume.extent())); }
    Image render(const Camera& camera, const codec::SamplingMap& map, bool, int width, int height) override {
        codec::VolumeRenderOptions options;
        const Fpc fpc(camera, std::make_shared<codec::SamplingMap>(map));
        return m_renderer->render(fpc, width, height, options);
    }
    std::string nextLook() override {
        m_file.clear();
        m_preset = (m_preset + 1) % static_cast<int>(m_presets.size());
        m_renderer->setTransferFunction(transferFunction());
        return look();
    }
    std::string look() const override { return m_file.empty() ? "tf " + m_presets[m_preset] : "tf " + fileName(m_file); }

private:
    codec::TransferFunction transferFunction() const {
        return m_file.empty() ? codec::TransferFunction::preset(m_presets[m_preset]) : codec::TransferFunction::load(m_file);
    }
    std::string m_name;
    Volume m_volume;
    std::vector<std::string> m_presets;
    int m_preset = 0;
    std::string m_file;
    std::unique_ptr<renderers::VolumeRendererGpu> m_renderer;
};

// A baked relief asset and, when given, its conventional twin (--uniform).
class ReliefView final : public Scene {
public:
    ReliefView(renderers::Context& context, const Options& options) : m_name(fileName(options.scenePath) + " (relief)") {
        m_conus = open(context, options.scenePath);
        if (!options.uniform.empty()) m_uniform = open(context, options.uniform);
    }
    std::string name() const override { return m_name; }
    glm::dvec3 centre() const override { return m_bounds.centre; }
    double radius() const override { return m_bounds.radius; }
    bool throughMap() const override { return false; }
    // A tablet lies flat: seen from the front (+z) and well above.
    std::optional<Orbit> home() const override {
        Orbit orbit;
        orbit.target = m_bounds.centre;
        orbit.yawDegrees = 15;
        orbit.pitchDegrees = 50;
        orbit.distance = 1.15 * m_bounds.radius / std::sin(glm::radians(0.5 * orbit.fovYDegrees));
        return orbit;
    }
    Image render(const Camera& camera, const codec::SamplingMap&, bool conus, int width, int height) override {
        return (conus || !m_uniform ? *m_conus : *m_uniform).render(camera, width, height);
    }

private:
    std::unique_ptr<renderers::ReliefRenderer> open(renderers::Context& context, const std::string& path) {
        const format::ConusFile file = format::readConusFile(path);
        if (file.dataKind != format::DataKind::HeightField || file.depth.kind != format::DepthKind::Height)
            throw Error(ErrorCode::Unsupported, path + " is not a relief asset (make one with `conus bake relief`)");
        const codec::DepthImage asset = codec::DepthImage::fromFile(file);
        if (!m_bounded) {
            // The asset's box: its orthographic view's image corners at the nearest and farthest depth.
            std::vector<glm::dvec3> corners;
            for (int k = 0; k < 8; ++k)
                corners.push_back(asset.camera().unproject({double(k & 1), double((k >> 1) & 1)},
                                                           (k & 4) ? asset.maxDepth() : asset.minDepth()));
            m_bounds = sphereAround(corners);
            m_bounded = true;
        }
        return std::make_unique<renderers::ReliefRenderer>(context, asset, file.image);
    }
    std::string m_name;
    BoundingSphere m_bounds;
    bool m_bounded = false;
    std::unique_ptr<renderers::ReliefRenderer> m_conus, m_uniform;
};

// A baked reflection asset (six faces) and the scene it was baked from, drawn on the GPU
// (renderers::ReflectionRenderer, the GLSL twin of codec::renderReflectionFrame): a mirror sphere at the
// asset's centre whose reflected rays intersect the faces.
class ReflectionView final : public Scene {
public:
    ReflectionView(renderers::Context& context, const Options& options)
        : ReflectionView(context, options, readMeshFile(options.reflectionScene, options.allowDirs)) {}
    ReflectionView(renderers::Context& context, const Options& options, const Mesh& mesh)
        : m_name(fileName(options.scenePath) + " (reflection)"), m_bounds(sphereAround(mesh.positions)) {
        const std::vector<codec::ReflectionFace> conusFaces = codec::readReflectionFaces(options.scenePath);
        m_centre = conusFaces.front().depth.camera().eye();
        m_options.reflector.kind = codec::Reflector::Kind::Sphere;
        m_options.reflector.centre = m_centre;
        m_options.reflector.radius = options.reflectorRadius;
        m_conus = std::make_unique<renderers::ReflectionRenderer>(context, mesh, conusFaces, m_options);
        if (!options.uniform.empty())
            m_uniform = std::make_unique<renderers::ReflectionRenderer>(context, mesh, codec::readReflectionFaces(options.uniform), m_options);
    }
    std::string name() const override { return m_name; }
    glm::dvec3 centre() const override { return m_centre; }
    // The whole scene seen from the mirror's centre (the frame's near and far planes enclose it).
    double radius() const override {
        return std::max(glm::length(m_bounds.centre - m_centre) + m_bounds.radius, m_options.reflector.radius);
    }
    bool throughMap() const override { return false; }
    // Near the mirror, which fills about a third of the frame's height: the reflections are the subject.
    std::optional<Orbit> home() const override {
        Orbit orbit;
        orbit.target = m_centre;
        orbit.distance = 3.0 * m_options.reflector.radius / std::tan(glm::radians(0.5 * orbit.fovYDegrees));
        return orbit;
    }
    Image render(const Camera& camera, const codec::SamplingMap&, bool conus, int width, int height) override {
        return colourOf((conus || !m_uniform ? *m_conus : *m_uniform).render(camera, width, height));
    }

private:
    std::string m_name;
    BoundingSphere m_bounds;
    glm::dvec3 m_centre{0.0};
    codec::ReflectionFrameOptions m_options;
    std::unique_ptr<renderers::ReflectionRenderer> m_conus, m_uniform;
};

}  // namespace

std::unique_ptr<Scene> openScene(const Options& options, renderers::Context& context) {
    switch (options.sceneKind) {
    case SceneKind::Mesh: return std::make_unique<MeshView>(context, options.scenePath, options.allowDirs, options.maxEdge,
                                                                  options.maxBend);
    case SceneKind::Volume: return std::make_unique<VolumeView>(context, options);
    case SceneKind::Relief: return std::make_unique<ReliefView>(context, options);
    case SceneKind::Reflection: return std::make_unique<ReflectionView>(context, options);
    case SceneKind::None: break;
    }
    throw Error(ErrorCode::InvalidArgument, "no scene given (--mesh, --volume, --relief or --reflection)");
}

}  // namespace conus::viewer
