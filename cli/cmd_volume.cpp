// conus render volume, conus volume animate: scalar volumes through the flexible pinhole camera (paper section 3.2,
// "Volume data"): one CoNUS ray per pixel through the undistorted image-plane point, composited
// front to back through a transfer function; written as a CoNUS depth image (R, G, B, A and the
// camera depth Z of the first sample past the opacity threshold, with its camera). animate slides
// one focus across the frame and writes each frame so.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "arguments.h"
#include "backend.h"
#include "commands.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/mesh_sequence.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/map/pictures.h"
#include "conus/codec/volume/procedural.h"
#include "conus/codec/volume/raycast.h"
#include "conus/codec/volume/transfer_function.h"
#include "conus/core/atomic_file.h"
#include "conus/core/camera.h"
#include "conus/core/error.h"
#include "conus/format/container.h"
#include "conus/renderers/volume_renderer.h"
#include "conus/sceneio/volume_file.h"
#include "encoding.h"
#include "image_files.h"
#include "map_options.h"
#include "output_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

struct VolumeOptions {
    std::string volume, output, picture, sizeText = "512x512", cameraText, upText = "0,-1,0", tf = codec::TransferFunction::kDefaultPreset,
                                         rangeText, backend = enumName(renderers::Backend::Auto), units = "voxel", mapFile;
    std::vector<std::string> foci, allowDirs;
    int grid = map_rules::kDefaultSide;
    std::string compose = enumName(format::FociComposition::Density);
    double step = 0.5, depthOpacity = 0.5;
    bool uniform = false, noJitter = false;
};

// procedural:... through codec, every file form through sceneio.
Volume loadVolume(const std::string& spec, const std::vector<std::string>& allowDirs) {
    if (spec.rfind("procedural:", 0) == 0) return codec::proceduralVolume(spec);
    sceneio::VolumeReadOptions read;
    read.allowedDirs = allowDirs;
    return sceneio::readVolume(spec, read);
}

// A preset's name, or the path of a transfer-function file (anything with a '/' or '.' or that exists).
codec::TransferFunction loadTransferFunction(const std::string& text) {
    std::error_code ec;
    if (text.find_first_of("/.") != std::string::npos || std::filesystem::exists(text, ec))
        return codec::TransferFunction::load(text);
    return codec::TransferFunction::preset(text);
}

codec::VolumeRenderOptions renderOptions(const VolumeOptions& o);

Camera volumeCamera(const VolumeOptions& o, const Volume& volume, const codec::TransferFunction& tf, double aspect) {
    // What the transfer function shows fills the frame (a head, not the box around it).
    if (o.cameraText.empty()) return codec::defaultVolumeCamera(volume, tf, codec::renderRange(volume, renderOptions(o)), aspect);
    // Near and far bracket the volume's box along the view axis.
    return givenCamera(parseCamera(o.cameraText), parseVector3(o.upText, "--up"), AxisBox{glm::dvec3(0.0), volume.extent()}, aspect,
                       "the volume");
}

// "a,b": two finite numbers.
glm::dvec2 parsePair(const std::string& text, const std::string& what) {
    const std::size_t comma = text.find(',');
    const std::string a = text.substr(0, comma), b = comma == std::string::npos ? "" : text.substr(comma + 1);
    char* endA = nullptr;
    char* endB = nullptr;
    const double x = std::strtod(a.c_str(), &endA), y = std::strtod(b.c_str(), &endB);
    if (a.empty() || b.empty() || *endA != '\0' || *endB != '\0' || !std::isfinite(x) || !std::isfinite(y))
        throw Error(ErrorCode::InvalidArgument, what + " '" + text + "' is not two numbers a,b");
    return {x, y};
}

// --camera and --up, checked before any work (the camera itself needs the volume's box).
void checkCameraOptions(const VolumeOptions& o) {
    if (o.cameraText.empty()) return;
    parseCamera(o.cameraText);
    parseVector3(o.upText, "--up");
}

codec::VolumeRenderOptions renderOptions(const VolumeOptions& o) {
    codec::VolumeRenderOptions options;
    options.stepVoxels = o.step;
    options.depthOpacity = float(o.depthOpacity);
    options.jitter = !o.noJitter;
    if (!o.rangeText.empty()) {
        const glm::dvec2 range = parsePair(o.rangeText, "--range");
        if (!(range.y > range.x) || std::abs(range.x) > 3e38 || std::abs(range.y) > 3e38)
            throw Error(ErrorCode::InvalidArgument, "--range '" + o.rangeText + "' is not lo,hi with lo < hi");
        options.rangeLo = float(range.x);
        options.rangeHi = float(range.y);
    }
    return options;
}

// The frame's size and the render options, every value of them checked before any work: --camera
// and --up, --size, --grid against that size, --range.
struct Frame {
    Size size;
    double aspect;
    codec::VolumeRenderOptions options;
};

Frame checkedFrame(const VolumeOptions& o) {
    checkCameraOptions(o);
    const Size size = parseSize(o.sizeText);
    checkGridForImage(o.grid, size.width, size.height);
    return {size, double(size.width) / size.height, renderOptions(o)};
}

// What render and animate read before rendering: the transfer function, the volume, the camera.
struct Scene {
    codec::TransferFunction tf;
    Volume volume;
    Camera camera;
};

Scene loadScene(const VolumeOptions& o, double aspect) {
    codec::TransferFunction tf = loadTransferFunction(o.tf);
    Progress loading("read " + o.volume);
    Volume volume = loadVolume(o.volume, o.allowDirs);
    loading.done();
    const Camera camera = volumeCamera(o, volume, tf, aspect);
    return {std::move(tf), std::move(volume), camera};
}

int runRender(const VolumeOptions& o) {
    checkConusOutput(o.output, o.volume);
    if (!o.picture.empty()) checkPictureOutput(o.picture, {}, {o.volume, o.output});
    auto [size, aspect, options] = checkedFrame(o);
    const Scene scene = loadScene(o, aspect);
    const Volume& volume = scene.volume;
    const Camera& camera = scene.camera;
    const codec::TransferFunction& tf = scene.tf;

    const FociSource foci = o.foci.empty() ? FociSource{} : [&o] { return parseFoci(o.foci); };
    const FrameMap chosen =
        chooseFrameMap(o.uniform, o.mapFile, foci, frameFociOptions(o.grid, o.compose, aspect), "--focus or --map");
    const codec::SamplingMap& map = chosen.map;
    const Fpc fpc(camera, chosen.identity ? nullptr : std::make_shared<codec::SamplingMap>(map));

    const renderers::Device device = deviceFor(o.backend, renderers::CpuPath::Available, "volume rendering");
    Progress rendering("render " + std::to_string(volume.width) + "x" + std::to_string(volume.height) + "x" +
                       std::to_string(volume.depth) + " volume at " + o.sizeText + " (" + device.describe() + ")");
    options.progress = rendering.callback();
    const Image image = renderers::renderVolume(device, volume, tf, fpc, size.width, size.height, options);
    rendering.done();
    Progress writing("write " + o.output);
    AtomicOutputs outputs;  // the file and its picture, both or neither
    format::writeConusFile(o.output, codec::makeDepthImageFile(image, map, camera, o.units, chosen.analytic));
    if (!o.picture.empty()) writePicture(o.picture, codec::toRgb(image));
    outputs.commit();
    writing.done();
    const glm::dvec3 eye = camera.eye(), look = eye + camera.forward();
    std::printf("camera %.4g,%.4g,%.4g,%.4g,%.4g,%.4g,%.4g (near %.4g, far %.4g)\n", eye.x, eye.y, eye.z, look.x, look.y,
                look.z, camera.verticalFovDegrees(), camera.near(), camera.far());
    std::printf("wrote %s: %dx%d CoNUS colour + depth image of %s (%dx%dx%d), %dx%d sampling map, %s\n", o.output.c_str(),
                size.width, size.height, o.volume.c_str(), volume.width, volume.height, volume.depth, map.columns(),
                map.rows(), device.describe().c_str());
    return 0;
}

// --- animate ----------------------------------------------------------------------------------

struct AnimateOptions {
    VolumeOptions volume;
    std::string outDir, from = "0.3,0.5", to = "0.7,0.5";
    int frames = 12;
    double radius = 0.1, k = 3;
};

glm::dvec2 parsePoint(const std::string& text, const std::string& what) {
    const glm::dvec2 p = parsePair(text, what);
    if (!(p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1))
        throw Error(ErrorCode::InvalidArgument, what + " '" + text + "' is not u,v in [0,1]");
    return p;
}

// The focus slides from --from to --to at constant speed; each frame's map is built from that one
// focus, so every node moves a bounded distance a frame (the map is a continuous function of the
// focus: tests/cli/volume_test.cpp bounds the step).
int runAnimate(const AnimateOptions& a) {
    const VolumeOptions& o = a.volume;
    const glm::dvec2 from = parsePoint(a.from, "--from"), to = parsePoint(a.to, "--to");
    auto [size, aspect, options] = checkedFrame(o);
    AtomicOutputs outputs;  // every frame or none
    outputs.makeFolder(a.outDir);
    const Scene scene = loadScene(o, aspect);
    const Volume& volume = scene.volume;
    const Camera& camera = scene.camera;
    const codec::TransferFunction& tf = scene.tf;
    const renderers::Device device = deviceFor(o.backend, renderers::CpuPath::Available, "volume rendering");
    const codec::FociOptions fo = frameFociOptions(o.grid, o.compose, aspect);
    // On a GL device the volume and transfer function go up once for all frames (a 3-D texture
    // upload per frame cost more than the frame itself on llvmpipe; bench/notes/2026-11-24-volumes.md).
    std::optional<renderers::VolumeRendererGpu> gpu;
    if (device.onGpu()) gpu.emplace(device.context(), volume, tf);
    std::optional<codec::SamplingMap> previous;
    double largest = 0;
    Progress rendering("render " + std::to_string(a.frames) + " frames at " + o.sizeText + " (" + device.describe() + ")");
    for (int f = 0; f < a.frames; ++f) {
        const double t = a.frames > 1 ? double(f) / (a.frames - 1) : 0.0;
        const glm::dvec2 centre = glm::mix(from, to, t);
        const std::vector<codec::Focus> foci{{centre.x, centre.y, a.radius, a.k}};
        codec::SamplingMap map = codec::frameMap(foci, fo);
        if (previous) largest = std::max(largest, codec::largestNodeStep(*previous, map));
        const Fpc fpc(camera, std::make_shared<codec::SamplingMap>(map));
        const Image image = gpu ? gpu->render(fpc, size.width, size.height, options)
                                : codec::renderVolumeReference(volume, tf, fpc, size.width, size.height, options);
        char name[32];
        std::snprintf(name, sizeof name, "frame_%04d", f);
        const std::filesystem::path base = std::filesystem::path(a.outDir) / name;
        format::writeConusFile(base.string() + ".exr",
                               codec::makeDepthImageFile(image, map, camera, o.units, codec::toAnalytic(foci, fo.composition)));
        writePicture(base.string() + ".png", codec::toRgb(image));
        previous = std::move(map);
        if (const ProgressFn report = rendering.callback()) report(double(f + 1) / a.frames);
    }
    rendering.done();
    outputs.commit();
    std::printf("wrote %d frames to %s; largest node step between frames %.4g (normalized units)\n", a.frames,
                a.outDir.c_str(), largest);
    return 0;
}


CLI::App* addRender(CLI::App& volume, VolumeOptions& options) {
    VolumeOptions* o = &options;
    CLI::App* render = addSubcommand(
        volume, "volume", "Render a volume as a CoNUS colour + depth image (R, G, B, A, Z and its camera)",
        {"conus render volume procedural:shepp-logan -o head.exr --focus 0.5,0.45,0.12,3 --picture head.png  # a phantom, a focus",
         "conus render volume brain.den -o brain.exr --tf bone --size 640x480 --uniform  # the uniform baseline",
         "conus render volume raw:256x256x128:uint16:0.8:ct.raw -o ct.exr --tf grey --range 0,4095  # a raw brick"});
    render->add_option("volume", o->volume,
                       "file.vdb | file.nrrd | file.nhdr | file.den | " + sceneio::rawVolumeForm() +
                           " | procedural:marschner-lobb[:n] | procedural:shepp-logan[:n]")
        ->required();
    writesFile(render->add_option("-o,--output", o->output, "the CoNUS file to write (.exr)"))->required();
    writesFile(render->add_option("--picture", o->picture, "also write the CoNUS image's colour as a picture (PNG)"));
    render->add_option("--size", o->sizeText, "CoNUS image size WxH")->capture_default_str();
    render->add_option("--camera", o->cameraText,
                       "ex,ey,ez,lx,ly,lz,fovDeg: eye, look-at point and vertical field of view, in the volume's world "
                       "units (sample (i,j,k) at (i,j,k) * spacing; default: one that frames the volume)");
    render->add_option("--up", o->upText, "the camera's up direction x,y,z (with --camera)")->capture_default_str();
    render->add_option("--tf", o->tf,
                       "transfer function: a preset (grey, bone, fire, shells) or a file of lines \"value r g b a\" "
                       "(numbers in [0,1], values increasing)")
        ->capture_default_str();
    render->add_option("--range", o->rangeText, "lo,hi: the sample values mapped to the transfer function's 0..1 "
                                                "(default: the volume's min..max)");
    render->add_option("--step", o->step, "ray step in voxels (the smallest spacing)")
        ->capture_default_str()
        ->check(finiteRange(0, 16));
    render->add_option("--depth-opacity", o->depthOpacity, "Z is where the accumulated opacity first reaches this")
        ->capture_default_str()
        ->check(finiteRange(0, 1));
    render->add_flag("--no-jitter", o->noJitter, "start every ray half a step in (banding) instead of a per-pixel jitter");
    render->add_option("--focus", o->foci, "u,v,r,k: a focus (centre, radius as a fraction of the width, magnification); repeatable");
    render->add_option("--map", o->mapFile, "take the sampling map from this CoNUS file");
    render->add_option("--grid", o->grid, "sampling-map nodes per side for --focus")
        ->capture_default_str()
        ->check(CLI::Range(kMinMapSide, kMaxMapSide));
    addComposeOption(*render, o->compose);
    render->add_flag("--uniform", o->uniform, "render the uniform image of the same pixel count (the baseline)");
    render->add_option("--units", o->units, "the volume's length unit, recorded as the depth's units")->capture_default_str();
    addBackendOption(*render, o->backend, renderers::CpuPath::Available);
    addAllowDirOption(*render, o->allowDirs);
    return render;
}

CLI::App* addAnimate(CLI::App& volume, AnimateOptions& animation) {
    AnimateOptions* a = &animation;
    CLI::App* animate = addSubcommand(
        volume, "animate", "Render a focus sliding across a volume: numbered CoNUS frames and pictures",
        {"conus volume animate procedural:shepp-logan --out-dir frames --from 0.3,0.45 --to 0.7,0.45 --frames 24"});
    animate->add_option("volume", a->volume.volume, "the volume, as for render")->required();
    animate->add_option("--out-dir", a->outDir, "folder for frame_NNNN.exr and frame_NNNN.png")->required();
    animate->add_option("--from", a->from, "u,v: the focus's first centre")->capture_default_str();
    animate->add_option("--to", a->to, "u,v: the focus's last centre")->capture_default_str();
    animate->add_option("--frames", a->frames, "number of frames")->capture_default_str()->check(CLI::Range(1, 100000));
    animate->add_option("--radius", a->radius, "the focus's radius, a fraction of the width")
        ->capture_default_str()
        ->check(finiteRange(0, 1));
    animate->add_option("--k", a->k, "the focus's magnification")->capture_default_str()->check(finiteRange(1, map_rules::kMaxMagnification, true));
    animate->add_option("--size", a->volume.sizeText, "CoNUS image size WxH")->capture_default_str();
    animate->add_option("--camera", a->volume.cameraText, "ex,ey,ez,lx,ly,lz,fovDeg (default: frames the volume)");
    animate->add_option("--tf", a->volume.tf, "transfer function: a preset or a file")->capture_default_str();
    animate->add_option("--grid", a->volume.grid, "sampling-map nodes per side")
        ->capture_default_str()
        ->check(CLI::Range(kMinMapSide, kMaxMapSide));
    addBackendOption(*animate, a->volume.backend, renderers::CpuPath::Available);
    addAllowDirOption(*animate, a->volume.allowDirs);
    return animate;
}

}  // namespace

Command addVolumeCommand(CLI::App& root) {
    return addCommandGroup(root, "volume",
                           "Scalar volumes through the flexible pinhole camera: a focus sliding across a volume (a frame: "
                           "`conus render volume`)",
                           {commandPart(addAnimate, runAnimate)});
}

CommandPart volumeRenderPart() { return commandPart(addRender, runRender); }

}  // namespace conus::cli
