// What the 3-D modes of conus-view render (scene_state.h holds how they are looked at): a scene is
// anything that makes a CoNUS image from a camera and a sampling map. One interface for the four
// kinds, each a thin wrapper over its renderer, its data uploaded once when the scene is opened:
//   --mesh FILE       renderers/mesh_render's GPU mesh encoder (Equation 1 in the vertex shader)
//   --volume SPEC     renderers/volume_renderer's GPU CoNUS ray casting; T cycles the presets
//   --relief ASSET    renderers/relief: relief texture mapping of a baked CoNUS height field
//   --reflection ASSET  the GLSL reflection renderer (renderers::ReflectionRenderer) over a baked asset
// Meshes and volumes are rendered through the map (the foci are live); relief and reflection assets
// hold their map already (baked), so their frames are conventional and C swaps the CoNUS asset for
// the conventional one (--uniform).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/renderers/context.h"
#include "options.h"
#include "scene_state.h"

namespace conus::viewer {

class Scene {
public:
    virtual ~Scene() = default;
    // Shown in the title and the status bar: "bunny.obj (mesh)".
    virtual std::string name() const = 0;
    // A sphere holding the content (the orbit turns about its centre).
    virtual glm::dvec3 centre() const = 0;
    virtual double radius() const = 0;
    // True when frames go through the map (the foci are live); false for baked assets.
    virtual bool throughMap() const { return true; }
    // The frame, width x height, float, top row first: R, G, B, and A and Z (camera depth) where the
    // renderer gives them. `conus` false: the conventional frame (a baked scene shows its
    // conventional asset; a live one gets the identity map anyway).
    virtual Image render(const Camera& camera, const codec::SamplingMap& map, bool conus, int width, int height) = 0;
    // T: the next look (a volume's next transfer function preset); its name, empty when the scene has one look.
    virtual std::string nextLook() { return {}; }
    virtual std::string look() const { return {}; }
    // The first camera, when the scene knows a better one than scene_state.h's default (a view
    // from the front right and a little above, framing the sphere).
    virtual std::optional<Orbit> home() const { return std::nullopt; }
};

// The scene Options ask for (options.sceneKind), its data read and uploaded to `context`. Throws
// conus::Error with the reason (an unreadable file, a bad asset).
std::unique_ptr<Scene> openScene(const Options& options, renderers::Context& context);

}  // namespace conus::viewer
