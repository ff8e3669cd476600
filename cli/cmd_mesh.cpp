// conus render mesh, conus mesh animate: triangle meshes through the flexible pinhole camera (paper sections
// 3.2 and 6). render writes one CoNUS colour + depth image (a `depthimage` file with its camera);
// animate renders the procedural city's focus-plus-context sequence, each frame's foci following
// chosen cars, as numbered CoNUS files and pictures, a contact sheet and (with ffmpeg) an MP4.
#include <CLI/CLI.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "arguments.h"
#include "backend.h"
#include "commands.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/mesh_sequence.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/map/pictures.h"
#include "conus/codec/mesh/city.h"
#include "conus/codec/mesh/subdivide.h"
#include "conus/core/atomic_file.h"
#include "conus/core/camera.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "conus/renderers/mesh_render.h"
#include "conus/sceneio/mesh_file.h"
#include "encoding.h"
#include "image_files.h"
#include "map_options.h"
#include "output_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

constexpr const char* kCity = "city";

// What render and animate share.
struct MeshOptions {
    std::string model, sizeText = "512x512", cameraText, upText = "0,1,0", backend = enumName(renderers::Backend::Auto), units = "m";
    double time = 0, maxEdge = 0, maxBend = renderers::kDefaultMaxBend;
    int samples = 4, grid = map_rules::kDefaultSide;
    std::vector<int> track;
    std::vector<std::string> allowDirs;
    double trackRadius = 0.05, trackK = 3;  // a car is small: a small, moderate focus keeps the context
    // animate: add, smooth from frame to frame (tests/codec/builders/mesh_sequence_test.cpp); render sets
    // density, as encode, volume and map compose foci.
    std::string compose = enumName(format::FociComposition::Add);
};

// --camera and --up as given (checked before any work).
struct CameraChoice {
    std::optional<CameraText> given;
    glm::dvec3 up{0, 1, 0};
};

CameraChoice parseCameraOptions(const MeshOptions& o) {
    CameraChoice choice;
    choice.up = parseVector3(o.upText, "--up");
    if (!(glm::length(choice.up) > 0)) throw Error(ErrorCode::InvalidArgument, "--up '" + o.upText + "' is the zero vector");
    if (!o.cameraText.empty()) choice.given = parseCamera(o.cameraText);
    return choice;
}

// --camera (with --up), or one that frames the model's bounding box from the front right and
// above (+x, +y, +z).
Camera meshCamera(const CameraChoice& choice, const AxisBox& b, double aspect) {
    if (!choice.given) return framingCamera(b, {0.55, 0.45, 1.0}, choice.up, aspect);
    return givenCamera(*choice.given, choice.up, b, aspect, "the model");
}

// The whole city from high above its front edge, steep enough that buildings hide few streets.
Camera cityCamera(const codec::CityScene& city, double aspect) {
    AxisBox b;
    b.lo = {-city.halfExtentX(), 0.0, -city.halfExtentZ()};
    b.hi = {city.halfExtentX(), city.maxHeight(), city.halfExtentZ()};
    return framingCamera(b, {0.15, 1.3, 1.0}, {0, 1, 0}, aspect);
}

void printCamera(const Camera& c) {
    const glm::dvec3 eye = c.eye(), look = eye + c.forward();
    std::printf("camera %.4g,%.4g,%.4g,%.4g,%.4g,%.4g,%.4g (near %.4g, far %.4g)\n", eye.x, eye.y, eye.z, look.x, look.y,
                look.z, c.verticalFovDegrees(), c.near(), c.far());
}

std::vector<glm::dvec3> carCentres(const codec::CityScene& city, const std::vector<int>& cars, double t) {
    std::vector<glm::dvec3> centres;
    for (int car : cars) {
        if (car < 0 || car >= city.carCount())
            throw Error(ErrorCode::InvalidArgument, "--track " + std::to_string(car) + ": the city has cars 0.." +
                                                        std::to_string(city.carCount() - 1));
        centres.push_back(city.carCentre(car, t));
    }
    return centres;
}

// Renders one frame on `device`. On a GPU the tessellation stages split triangles where the map
// bends them (--max-bend), unless --max-edge splits every triangle on the CPU first.
Image renderFrame(const renderers::Device& device, const Mesh& mesh, const Camera& camera, const codec::SamplingMap& map,
                  Size size, const MeshOptions& o, bool report) {
    renderers::MeshRenderOptions options;
    options.samples = o.samples;
    options.maxBend = o.maxEdge > 0 ? 0.0 : o.maxBend;
    if (!device.onGpu()) return renderers::renderMesh(device, mesh, camera, map, size.width, size.height, options);
    std::optional<Mesh> fine;
    if (o.maxEdge > 0) {
        const double before = codec::longestProjectedEdge(mesh, camera, map);
        fine = codec::subdivideForMap(mesh, camera, map, o.maxEdge);
        if (report)
            std::printf("subdivided %zu -> %zu triangles: longest projected edge %.3g -> %.3g map cells (--max-edge %g)\n",
                        mesh.triangleCount(), fine->triangleCount(), before,
                        codec::longestProjectedEdge(*fine, camera, map), o.maxEdge);
    }
    renderers::MeshRenderer renderer(device.context(), fine ? *fine : mesh);
    std::int64_t drawn = 0;
    Image image = renderer.render(camera, map, size.width, size.height, options, nullptr, report ? &drawn : nullptr);
    if (report && drawn > static_cast<std::int64_t>(mesh.triangleCount()))
        std::printf("drew %zu triangles as %lld, split on the GPU where the map bends them more than %g pixels (--max-bend)\n",
                    mesh.triangleCount(), static_cast<long long>(drawn), options.maxBend);
    return image;
}

renderers::Device meshDevice(const MeshOptions& o, bool reference) {
    if (reference) return renderers::Device::cpu();
    return deviceFor(o.backend, renderers::CpuPath::Available, "mesh rendering");
}

void addSharedOptions(CLI::App& command, MeshOptions& o, bool withCamera) {
    command.add_option("--size", o.sizeText, "CoNUS image size WxH")->capture_default_str();
    if (withCamera) {
        command.add_option("--camera", o.cameraText,
                           "ex,ey,ez,lx,ly,lz,fovDeg: eye, look-at point and vertical field of view (default: one that "
                           "frames the model's bounding box; the city: seen from above a corner)");
        command.add_option("--up", o.upText, "the camera's up direction x,y,z")->capture_default_str();
    }
    command.add_option("--time", o.time, "the city's time in seconds (cars move)")->capture_default_str()->check(finiteRange(-1e6, 1e6, true));
    command.add_option("--track-radius", o.trackRadius, "--track: each focus's radius, a fraction of the width")
        ->capture_default_str()
        ->check(finiteRange(0, 1));
    command.add_option("--track-k", o.trackK, "--track: each focus's magnification")
        ->capture_default_str()
        ->check(finiteRange(1, map_rules::kMaxMagnification, true));
    addComposeOption(command, o.compose);
    command.add_option("--grid", o.grid, "sampling-map nodes per side for --focus and --track")
        ->capture_default_str()
        ->check(CLI::Range(kMinMapSide, kMaxMapSide));
    command.add_option("--max-bend", o.maxBend,
                       "GPU: split triangles (tessellation shaders) where Equation 1 bends an edge or a triangle's inside "
                       "more than this many CoNUS pixels away from the straight lines the rasterizer draws (0: no split)")
        ->capture_default_str()
        ->check(finiteRange(0, 1e6, true));
    command.add_option("--max-edge", o.maxEdge,
                       "GPU: instead of --max-bend, split every triangle on the CPU until no projected edge spans more than "
                       "this many map cells (0: off)")
        ->capture_default_str()
        ->check(finiteRange(0, 1e6, true));
    command.add_option("--samples", o.samples, "samples a pixel (multisampling; the reference takes round(sqrt)^2 rays)")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    command.add_option("--units", o.units, "the model's length unit, recorded as the depth's units")->capture_default_str();
    addBackendOption(command, o.backend, renderers::CpuPath::Available);
}

// --- render -----------------------------------------------------------------------------------

struct RenderOptions {
    MeshOptions mesh;
    std::string output, mapFile;
    std::vector<std::string> foci;
    bool uniform = false, reference = false;
};

int runRender(const RenderOptions& r) {
    const MeshOptions& o = r.mesh;
    checkConusOutput(r.output, o.model);
    const Size size = parseSize(o.sizeText);
    checkGridForImage(o.grid, size.width, size.height);
    const CameraChoice cameraChoice = parseCameraOptions(o);
    if (!o.track.empty() && o.model != kCity)
        throw Error(ErrorCode::InvalidArgument, "--track follows the city's cars: give `city` as the model");
    const double aspect = double(size.width) / size.height;
    std::optional<codec::CityScene> city;
    Progress loading("read " + o.model);
    Mesh mesh;
    if (o.model == kCity) mesh = city.emplace().meshAt(o.time);
    else {
        sceneio::MeshReadOptions read;
        read.allowedDirs = o.allowDirs;
        read.warn = warn;
        sceneio::MeshReadReport report;
        mesh = sceneio::readMesh(o.model, read, &report);
        if (report.duplicateTriangles > 0)
            warn(o.model + ": dropped " + std::to_string(report.duplicateTriangles) +
                 " exact duplicate triangles (copies of another triangle's three corners)");
    }
    loading.done();
    const Camera camera =
        city && !cameraChoice.given ? cityCamera(*city, aspect) : meshCamera(cameraChoice, boundsOf(mesh), aspect);

    const FociSource foci = r.foci.empty() && o.track.empty() ? FociSource{} : [&] {
        std::vector<codec::Focus> given = parseFoci(r.foci);
        if (city) {
            const auto centres = carCentres(*city, o.track, o.time);
            const auto tracked = codec::trackedFoci(camera, centres, aspect, {o.trackRadius, o.trackK});
            given.insert(given.end(), tracked.begin(), tracked.end());
        }
        return given;
    };
    const FrameMap chosen = chooseFrameMap(r.uniform, r.mapFile, foci, frameFociOptions(o.grid, o.compose, aspect),
                                           "--focus, --map or --track");
    const codec::SamplingMap& map = chosen.map;

    const renderers::Device device = meshDevice(o, r.reference);
    Progress rendering("render " + std::to_string(mesh.triangleCount()) + " triangles at " + o.sizeText + " (" +
                       device.describe() + ")");
    const Image image = renderFrame(device, mesh, camera, map, size, o, !quiet());
    rendering.done();
    Progress writing("write " + r.output);
    format::writeConusFile(r.output, codec::makeDepthImageFile(image, map, camera, o.units, chosen.analytic));
    writing.done();
    printCamera(camera);
    std::printf("wrote %s: %dx%d CoNUS colour + depth image of %s (%zu triangles), %dx%d sampling map, %s\n",
                r.output.c_str(), size.width, size.height, o.model.c_str(), mesh.triangleCount(), map.columns(),
                map.rows(), device.describe().c_str());
    return 0;
}

// --- animate ----------------------------------------------------------------------------------

struct AnimateOptions {
    MeshOptions mesh;
    std::string outDir;
    int frames = 24;
    double fps = 12;
    bool video = true;
};

std::optional<std::string> findOnPath(const std::string& program) {
    const char* path = std::getenv("PATH");
    if (!path) return std::nullopt;
    std::string all = path;
    std::size_t start = 0;
    while (start <= all.size()) {
        const std::size_t end = std::min(all.find(':', start), all.size());
        const std::filesystem::path candidate = std::filesystem::path(all.substr(start, end - start)) / program;
        if (end > start && access(candidate.c_str(), X_OK) == 0) return candidate.string();
        start = end + 1;
    }
    return std::nullopt;
}

// Runs ffmpeg on the numbered PNGs into `output` (atomically); returns why it did not, or nothing.
std::optional<std::string> encodeVideo(const std::string& ffmpeg, const std::filesystem::path& dir, double fps,
                                       const std::string& output) {
    AtomicFile file(output);
    const std::string rate = std::to_string(fps), pattern = (dir / "frame_%04d.png").string();
    // Even sides (yuv420p needs them); no audio; overwrite the (empty) temporary file.
    std::vector<std::string> args = {ffmpeg, "-nostdin", "-loglevel", "error", "-y", "-framerate", rate, "-i", pattern,
                                     "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", "-f", "mp4",
                                     file.temporaryPath()};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::fflush(nullptr);
    const pid_t child = fork();
    if (child < 0) return "fork failed";
    if (child == 0) {
        execv(argv[0], argv.data());
        _exit(127);
    }
    int status = 0;
    if (waitpid(child, &status, 0) != child) return "waiting for ffmpeg failed";
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return "ffmpeg failed (exit status " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
    file.commit();
    return std::nullopt;
}

int runAnimate(const AnimateOptions& a) {
    const MeshOptions& o = a.mesh;
    if (o.model != kCity)
        throw Error(ErrorCode::InvalidArgument, "animate renders the procedural city: give `city` as the model, not '" + o.model + "'");
    if (o.track.empty()) warn("no --track: every frame is the uniform image (give --track 0,2 to follow cars)");
    const Size size = parseSize(o.sizeText);
    checkGridForImage(o.grid, size.width, size.height);
    const CameraChoice cameraChoice = parseCameraOptions(o);
    const double aspect = double(size.width) / size.height;
    const std::filesystem::path dir(a.outDir);
    // The frames and the contact sheet, all or none; the video (optional, ffmpeg reads the frames
    // from the folder) follows once they are in place.
    AtomicOutputs outputs;
    outputs.makeFolder(a.outDir);
    const codec::CityScene city;
    const Camera camera =
        cameraChoice.given ? meshCamera(cameraChoice, boundsOf(city.meshAt(o.time)), aspect) : cityCamera(city, aspect);
    const codec::FociOptions fo = frameFociOptions(o.grid, o.compose, aspect);
    const renderers::Device device = meshDevice(o, false);
    printCamera(camera);

    std::vector<Image> tiles;
    const int columns = std::min(a.frames, 6);
    const int tileWidth = std::max(16, std::min(size.width, 960 / columns));
    const int tileHeight = std::max(1, static_cast<int>(std::lround(tileWidth / aspect)));
    double largestStep = 0;
    std::optional<codec::SamplingMap> previous;
    Progress rendering("render " + std::to_string(a.frames) + " frames at " + o.sizeText + " (" + device.describe() + ")");
    for (int i = 0; i < a.frames; ++i) {
        const double t = o.time + i / a.fps;
        const auto foci = codec::trackedFoci(camera, carCentres(city, o.track, t), aspect, {o.trackRadius, o.trackK});
        codec::SamplingMap map = codec::frameMap(foci, fo);
        if (previous) largestStep = std::max(largestStep, codec::largestNodeStep(*previous, map));
        const Image image = renderFrame(device, city.meshAt(t), camera, map, size, o, false);
        char name[32];
        std::snprintf(name, sizeof name, "frame_%04d", i);
        format::writeConusFile((dir / (std::string(name) + ".exr")).string(),
                               codec::makeDepthImageFile(image, map, camera, o.units,
                                                         foci.empty() ? std::nullopt
                                                                      : std::optional(codec::toAnalytic(foci, fo.composition))));
        const Image rgb = codec::toRgb(image);
        setQuiet(true);
        writePicture((dir / (std::string(name) + ".png")).string(), rgb);
        setQuiet(false);
        tiles.push_back(codec::areaDownsample(rgb, tileWidth, tileHeight));
        liveLine("frame " + std::to_string(i + 1) + "/" + std::to_string(a.frames) + " (" +
                 plural(foci.size(), "focus", "foci") + ")");
        previous = std::move(map);
    }
    rendering.done();
    const std::string sheet = (dir / "contact_sheet.png").string();
    writePicture(sheet, codec::contactSheet(tiles, columns));
    outputs.commit();
    std::printf("wrote %d frames to %s (frame_0000.exr/.png ...), contact sheet %s; largest per-frame move of a map "
                "node %.4f (normalized)\n",
                a.frames, a.outDir.c_str(), sheet.c_str(), largestStep);
    if (!a.video) return 0;
    const auto ffmpeg = findOnPath("ffmpeg");
    if (!ffmpeg) {
        std::printf("no MP4: ffmpeg is not on PATH (Debian: apt-get install ffmpeg)\n");
        return 0;
    }
    const std::string video = (dir / "sequence.mp4").string();
    Progress encoding("encode " + video + " with ffmpeg");
    if (const auto why = encodeVideo(*ffmpeg, dir, a.fps, video)) {
        warn("no MP4: " + *why);
        return 0;
    }
    encoding.done();
    std::printf("wrote %s: %d frames at %g fps\n", video.c_str(), a.frames, a.fps);
    return 0;
}

CLI::App* addRender(CLI::App& command, RenderOptions& r) {
    CLI::App* render = addSubcommand(
        command, "mesh", "Render a mesh (OBJ, PLY, STL, glTF, ... or `city`) as a CoNUS colour + depth image",
        {"conus render mesh bunny.ply -o bunny.exr --focus 0.45,0.4,0.1,4",
         "conus render mesh model.obj -o model.exr --size 1024x1024 --camera 0,1,3,0,0,0,40 --max-bend 0.1",
         "conus render mesh city -o city.exr --track 0,2 --time 3.5 --reference"});
    render->add_option("model", r.mesh.model, "mesh file (anything Assimp reads) or `city` (the procedural city)")->required();
    writesFile(render->add_option("-o,--output", r.output, "CoNUS file (.exr): R, G, B, A (coverage), Z (camera depth)"))->required();
    render->add_option("--focus", r.foci, "focus u,v,r,k (repeatable): centre, radius (fraction of the width), magnification");
    render->add_option("--map", r.mapFile, "take the sampling map from this CoNUS file")->excludes("--focus");
    render->add_option("--track", r.mesh.track, "city: foci on these cars' projected centres (e.g. 0,2)")
        ->delimiter(',')
        ->excludes("--map");
    render->add_flag("--uniform", r.uniform, "the identity map: the conventional image of the same pixel count")
        ->excludes("--focus")
        ->excludes("--map")
        ->excludes("--track");
    render->add_flag("--reference", r.reference, "the exact CPU reference (Embree ray casting) instead of the GPU");
    r.mesh.compose = enumName(format::FociComposition::Density);
    addSharedOptions(*render, r.mesh, true);
    addAllowDirOption(*render, r.mesh.allowDirs);
    return render;
}

CLI::App* addAnimate(CLI::App& command, AnimateOptions& a) {
    CLI::App* animate = addSubcommand(
        command, "animate", "Render the city's focus-plus-context sequence: foci follow moving cars (paper section 6)",
        {"conus mesh animate city --frames 24 --out-dir frames --track 0,2",
         "conus mesh animate city --frames 48 --fps 24 --out-dir frames --track 1,3,4 --track-k 5 --size 640x360"});
    animate->add_option("model", a.mesh.model, "`city`")->required();
    animate->add_option("--frames", a.frames, "number of frames")->capture_default_str()->check(CLI::Range(1, 100000));
    animate->add_option("--fps", a.fps, "frames a second of city time (and of the MP4)")
        ->capture_default_str()
        ->check(finiteRange(0, 1000));
    animate->add_option("--out-dir", a.outDir, "folder for frame_NNNN.exr/.png, contact_sheet.png and sequence.mp4")->required();
    animate->add_option("--track", a.mesh.track, "cars whose projected centres carry the foci (e.g. 0,2)")->delimiter(',');
    animate->add_flag("!--no-video", a.video, "do not encode sequence.mp4 even when ffmpeg is on PATH");
    addSharedOptions(*animate, a.mesh, true);
    return animate;
}

}  // namespace

Command addMeshCommand(CLI::App& root) {
    return addCommandGroup(
        root, "mesh",
        "Triangle meshes through the flexible pinhole camera: focus-plus-context sequences (a frame: `conus render mesh`)",
        {commandPart(addAnimate, runAnimate)});
}

CommandPart meshRenderPart() { return commandPart(addRender, runRender); }

}  // namespace conus::cli
