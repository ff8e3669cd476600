// conus render relief | reflection: frames of baked assets. Relief: each eye ray intersects the
// CoNUS height texture in a fragment shader (paper section 5); reflection: the reflected rays
// intersect the six faces of a reflection asset (GLSL, or the CPU reference with --backend cpu).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>

#include "arguments.h"
#include "backend.h"
#include "commands.h"
#include "conus/codec/depth/reflection.h"
#include "conus/codec/depth/relief.h"
#include "conus/core/error.h"
#include "conus/format/container.h"
#include "conus/renderers/reflection.h"
#include "conus/renderers/relief.h"
#include "conus/sceneio/mesh_file.h"
#include "image_files.h"
#include "output_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

struct RenderOptions {
    std::string input, output, cameraText, sizeText = "960x720", lightText = "-0.4,0.8,-0.45", backend = enumName(renderers::Backend::Auto);
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
    renderers::ReliefLook look;
    look.shadows = o.shadows;
    look.towardLight = glm::vec3(towardLight);
    look.intersect.stepTexels = o.step;
    const renderers::Device device = deviceFor(o.backend, renderers::CpuPath::None, "relief rendering");
    Progress progress("render " + std::to_string(size.width) + "x" + std::to_string(size.height));
    renderers::ReliefRenderer renderer(device.context(), asset, file.image, look);
    const Image frame = renderer.render(camera, size.width, size.height);
    progress.done();
    writePicture(o.output, frame, write);
    // The camera as --camera takes it: the one given, as given; else the default view's eye and a
    // point one unit along its view (the same camera when given back).
    const glm::dvec3 eye = given ? given->eye : camera.eye(), at = given ? given->target : eye + camera.forward();
    std::printf("wrote %s: %dx%d frame of a %dx%d relief asset (%s); camera %g,%g,%g,%g,%g,%g,%g\n",
                o.output.c_str(), size.width, size.height, file.image.width, file.image.height,
                device.context().renderer().c_str(), eye.x, eye.y, eye.z, at.x, at.y, at.z,
                given ? given->fovYDegrees : camera.verticalFovDegrees());
    return 0;
}

// --- reflection -------------------------------------------------------------------------------

// Rays a pixel a side when --samples is not given, for the reference and the asset's frame alike
// (scored against each other, they alias alike): one ray a pixel aliases a texture finer than the
// frame's pixels (the milk truck's 2048^2 on a truck a hundred pixels long), and 3x3 rays cost 9x
// the one-ray frame's rays and come within 47 dB of 8x8 (bench/notes/2026-12-07-mirrors-2.md).
constexpr int kFrameSamples = 3;

struct ReflectionRenderText {
    std::string asset, scene, output, cameraText, sizeText = "640x480", at, normal = "0,0,1", backend = enumName(renderers::Backend::Auto);
    std::string reflector = enumName(codec::Reflector::Kind::Sphere);
    std::vector<std::string> allowDirs;
    double radius = 0.5, step = 1.0;
    bool reference = false;
    int samples = kFrameSamples;
};

int runRenderReflection(const ReflectionRenderText& o) {
    const Size size = parseSize(o.sizeText);
    const imageio::WriteOptions write = writeOptionsOf({}, nullptr);
    checkPictureOutput(o.output, write, {o.scene, o.asset});
    if (o.cameraText.empty()) throw Error(ErrorCode::InvalidArgument, "--camera is required (x,y,z,lx,ly,lz,fovDeg)");
    const CameraText given = parseCamera(o.cameraText);
    codec::ReflectionFrameOptions options;
    options.reflector.kind = parseEnum<codec::Reflector::Kind>(o.reflector);
    options.reflector.radius = o.radius;
    options.reflector.normal = parseVector3(o.normal, "--normal");
    if (!(glm::length(options.reflector.normal) > 0)) throw Error(ErrorCode::InvalidArgument, "--normal is the zero vector");
    options.reflector.normal = glm::normalize(options.reflector.normal);
    options.intersect.stepTexels = o.step;
    options.samples = o.samples;
    const std::vector<codec::ReflectionFace> faces = codec::readReflectionFaces(o.asset);
    const glm::dvec3 centre = faces.front().depth.camera().eye();
    options.reflector.centre = o.at.empty() ? centre : parseVector3(o.at, "--at");
    const codec::MeshScene scene(readSceneMesh(o.scene, o.allowDirs));
    const double aspect = double(size.width) / size.height;
    const Camera camera = Camera::perspective(given.eye, given.target, {0, 1, 0}, given.fovYDegrees, aspect, 1e-3, 1e6);
    // The ground truth traces the mesh itself, on the CPU.
    const renderers::Device device =
        o.reference ? renderers::Device::cpu() : deviceFor(o.backend, renderers::CpuPath::Available, "reflection rendering");
    Progress rendering("render " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                       (o.reference ? " (reflections traced against the mesh)" : " (reflections from the faces)"));
    Image frame = o.reference
                      ? codec::renderReflectionFrame(scene, nullptr, centre, camera, size.width, size.height, options)
                      : renderers::renderReflection(device, scene, faces, camera, size.width, size.height, options);
    rendering.done();
    Image rgb{frame.width, frame.height, {"R", "G", "B"}, {}};
    rgb.pixels.reserve(static_cast<std::size_t>(frame.width) * frame.height * 3);
    for (std::size_t i = 0; i < frame.pixels.size(); i += 4) rgb.pixels.insert(rgb.pixels.end(), &frame.pixels[i], &frame.pixels[i + 3]);
    writePicture(o.output, rgb, write);
    std::printf("wrote %s: %dx%d frame, %dx%d ray%s a pixel, a %s reflector at %g,%g,%g (%s)\n", o.output.c_str(), size.width,
                size.height, options.samples, options.samples, options.samples > 1 ? "s" : "", o.reflector.c_str(),
                options.reflector.centre.x, options.reflector.centre.y, options.reflector.centre.z, device.describe().c_str());
    return 0;
}

CLI::App* addRenderReflection(CLI::App& command, ReflectionRenderText& o) {
    CLI::App* reflection = addSubcommand(
        command, "reflection", "A specular reflector whose reflected rays intersect a reflection asset's faces",
        {"conus render reflection asset.exr --scene scene.obj --camera 0,1,4,0,0,0,40 -o frame.png",
         "conus render reflection asset.exr --scene scene.obj --reflector plane --normal 0,0,1 --radius 2 --camera 0,1,4,0,0,0,40 -o frame.png"});
    reflection->add_option("asset", o.asset, "reflection asset (.exr, from `conus bake reflection`)")->required();
    reflection->add_option("--scene", o.scene, "the mesh file the asset was baked from (drawn behind)")->required();
    addAllowDirOption(*reflection, o.allowDirs);
    writesFile(reflection->add_option("-o,--output", o.output, "frame (.png, .exr, ...)"))->required();
    reflection->add_option("--camera", o.cameraText, "x,y,z,lx,ly,lz,fovDeg")->required();
    reflection->add_option("--size", o.sizeText, "frame size WxH")->capture_default_str();
    reflection->add_option("--reflector", o.reflector, "the mirror's shape")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames<codec::Reflector::Kind>()));
    reflection->add_option("--at", o.at, "the reflector's centre x,y,z (default: the asset's centre)");
    reflection->add_option("--radius", o.radius, "sphere radius, or half the plane mirror's side")
        ->capture_default_str()
        ->check(finiteRange(0, 1e9));
    reflection->add_option("--normal", o.normal, "plane: the mirror's facing direction x,y,z")->capture_default_str();
    reflection->add_option("--step", o.step, "linear-search step in CoNUS pixels")->capture_default_str()->check(finiteRange(0, 64));
    reflection->add_flag("--reference", o.reference,
                         "trace reflected rays against the mesh (Embree, CPU): the ground truth");
    reflection->add_option("--samples", o.samples,
                           "N: N x N rays a pixel, one in each cell of an N x N grid over it, averaged (1: one ray through the pixel's centre)")
        ->capture_default_str()
        ->check(CLI::Range(1, codec::kMaxFrameSamples));
    addBackendOption(*reflection, o.backend);
    return reflection;
}

CLI::App* addRenderRelief(CLI::App& command, RenderOptions& o) {
    CLI::App* relief = addSubcommand(command, "relief", "Relief texture mapping: eye rays against a relief asset",
                                     {"conus render relief tablet.exr -o frame.png",
                                      "conus render relief tablet.exr -o frame.png --shadows --size 1280x960",
                                      "conus render relief tablet.exr -o frame.png --camera 0.5,0.6,1.2,0.5,0,0.375,35"});
    relief->add_option("input", o.input, "relief asset (.exr, from `conus bake relief`)")->required();
    writesFile(relief->add_option("-o,--output", o.output, "frame (.png, .exr, ...)"))->required();
    relief->add_option("--camera", o.cameraText,
                       "x,y,z,lx,ly,lz,fovDeg: eye, look-at point (world: x right, y up, z toward the front "
                       "edge) and vertical fov (default: from the front, above)");
    relief->add_option("--size", o.sizeText, "frame size WxH")->capture_default_str();
    relief->add_option("--light", o.lightText, "direction toward the light x,y,z")->capture_default_str();
    relief->add_flag("--shadows", o.shadows, "self-shadowing: a second ray toward the light");
    relief->add_option("--step", o.step, "linear-search step in CoNUS pixels")
        ->capture_default_str()
        ->check(finiteRange(0, 64));
    addBackendOption(*relief, o.backend, renderers::CpuPath::None);
    return relief;
}

}  // namespace

Command addRenderCommand(CLI::App& root) {
    return addCommandGroup(root, "render",
                           "Render frames: of baked assets (relief, reflection), of meshes and volumes as CoNUS colour + depth "
                           "images (mesh, volume), of a CoNUS height field (heightfield)",
                           {commandPart(addRenderRelief, runRenderRelief), commandPart(addRenderReflection, runRenderReflection),
                            meshRenderPart(), volumeRenderPart(), heightFieldRenderPart()});
}

}  // namespace conus::cli
