// conus render relief: a frame of a relief asset (`conus bake relief`) by relief texture mapping:
// each eye ray intersects the CoNUS height texture in a fragment shader (paper section 5).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>

#include "arguments.h"
#include "backend.h"
#include "commands.h"
#include "conus/codec/depth/relief.h"
#include "conus/core/error.h"
#include "conus/renderers/relief.h"
#include "image_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

struct RenderOptions {
    std::string input, output, cameraText, sizeText = "960x720", lightText = "-0.4,0.8,-0.45", backend = "auto";
    bool shadows = false;
    double step = 1.0;
};

glm::dvec3 parseDirection(const std::string& text) {
    const glm::dvec3 direction = parseVector3(text, "light");
    if (!(glm::length(direction) > 0.0))
        throw Error(ErrorCode::InvalidArgument, "light '" + text + "' has no direction");
    return direction;
}

int runRenderRelief(const RenderOptions& o) {
    const Size size = parseSize(o.sizeText);
    const imageio::WriteOptions write = writeOptionsOf({}, nullptr);
    checkPictureOutput(o.output, write, {o.input});
    // Values first, so that a bad one is a usage error before any work.
    const std::optional<CameraText> given = o.cameraText.empty() ? std::nullopt : std::optional(parseCamera(o.cameraText));
    const glm::dvec3 towardLight = parseDirection(o.lightText);
    const format::ConusFile file = format::readConusFile(o.input);
    if (file.dataKind != format::DataKind::HeightField || file.depth.kind != format::DepthKind::Height)
        throw Error(ErrorCode::Unsupported, o.input + " is not a relief asset (a height field with heights and a "
                                                          "camera; make one with `conus bake relief`)");
    const codec::DepthImage asset = codec::DepthImage::fromFile(file);
    const double aspect = double(size.width) / size.height;
    Camera camera = codec::defaultReliefView(asset, aspect);
    if (given)
        camera = Camera::perspective(given->eye, given->target, {0, 1, 0}, given->fovYDegrees, aspect, camera.near(),
                                     camera.far());
    gl::ReliefLook look;
    look.shadows = o.shadows;
    look.towardLight = glm::vec3(towardLight);
    look.intersect.stepTexels = o.step;
    const gl::Device device = deviceFor(o.backend, gl::CpuPath::None, "relief rendering");
    Progress progress("render " + std::to_string(size.width) + "x" + std::to_string(size.height));
    gl::ReliefRenderer renderer(device.context(), asset, file.image, look);
    const Image frame = renderer.render(camera, size.width, size.height);
    progress.done();
    writePicture(o.output, frame, write);
    const glm::dvec3 eye = camera.eye(), at = eye + camera.forward();
    std::printf("wrote %s: %dx%d frame of a %dx%d relief asset (%s); camera %.3g,%.3g,%.3g,%.3g,%.3g,%.3g,%.3g\n",
                o.output.c_str(), size.width, size.height, file.image.width, file.image.height,
                device.context().renderer().c_str(), eye.x, eye.y, eye.z, at.x, at.y, at.z, camera.verticalFovDegrees());
    return 0;
}

}  // namespace

Command addRenderCommand(CLI::App& root) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* command = root.add_subcommand("render", "Render frames of baked assets (relief)");
    command->require_subcommand(1);
    CLI::App* relief = addSubcommand(*command, "relief", "Relief texture mapping: eye rays against a relief asset",
                                     {"conus render relief tablet.exr -o frame.png",
                                      "conus render relief tablet.exr -o frame.png --shadows --size 1280x960",
                                      "conus render relief tablet.exr -o frame.png --camera 0.5,0.6,1.2,0.5,0,0.375,35"});
    relief->add_option("input", o->input, "relief asset (.exr, from `conus bake relief`)")->required();
    relief->add_option("-o,--output", o->output, "frame (.png, .exr, ...)")->required();
    relief->add_option("--camera", o->cameraText,
                       "x,y,z,lx,ly,lz,fovDeg: eye, look-at point (world: x right, y up, z toward the front "
                       "edge) and vertical fov (default: from the front, above)");
    relief->add_option("--size", o->sizeText, "frame size WxH")->capture_default_str();
    relief->add_option("--light", o->lightText, "direction toward the light x,y,z")->capture_default_str();
    relief->add_flag("--shadows", o->shadows, "self-shadowing: a second ray toward the light");
    relief->add_option("--step", o->step, "linear-search step in CoNUS pixels")
        ->capture_default_str()
        ->check(finiteRange(0, 64));
    addBackendOption(*relief, o->backend, gl::CpuPath::None);
    addQuietOption(*relief);
    return {command, [o] { return runRenderRelief(*o); }};
}

}  // namespace conus::cli
