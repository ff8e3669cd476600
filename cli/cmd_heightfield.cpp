// conus heightfield encode|render: CoNUS height fields (paper section 4, Figure 5). encode samples
// a DEM through the perspective ground map (the server); render undistorts the file into a mesh
// and renders a frame near the viewer (the client), optionally next to the full-resolution DEM and
// a uniform height field of the same sample count, with their PSNRs.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <regex>
#include <sstream>

#include "arguments.h"
#include "backend.h"
#include "commands.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/depth/heightfield.h"
#include "conus/codec/image/metrics.h"
#include "conus/codec/map/pictures.h"
#include "conus/format/container.h"
#include "conus/core/error.h"
#include "conus/renderers/terrain.h"
#include "conus/core/atomic_file.h"
#include "conus/imageio/image_file.h"
#include "encoding.h"
#include "image_files.h"
#include "map_options.h"
#include "output_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

// The camera as given, or the ground map's own viewer as a --camera value to start from.
void printCamera(const Camera& c, const std::string& given) {
    if (quiet()) return;
    if (!given.empty()) {
        std::printf("camera %s\n", given.c_str());
        return;
    }
    const glm::dvec3 eye = c.eye(), look = eye + c.forward() * 1000.0;
    std::printf("camera %.1f,%.1f,%.1f,%.1f,%.1f,%.1f,%.1f (the ground map's viewer; look-at 1000 ahead)\n", eye.x, eye.y,
                eye.z, look.x, look.y, look.z, c.verticalFovDegrees());
}

// The camera --camera names (empty: the ground map's own viewer).
std::optional<renderers::TerrainView> terrainView(const std::string& cameraText) {
    if (cameraText.empty()) return std::nullopt;
    const CameraText given = parseCamera(cameraText);
    return renderers::TerrainView{given.eye, given.target, given.fovYDegrees};
}

// A frame of the height field `file` (called `name` in messages) seen from `cameraText`.
struct Frame {
    Image image;
    Camera camera;
    glm::dvec2 extent;  // the field's size on the ground
};

Frame renderFrame(renderers::Context& context, const format::ConusFile& file, const std::string& name,
                  const std::string& cameraText, Size size, const std::string& stage) {
    const glm::dvec2 extent = codec::fieldExtent(renderers::heightFieldGround(file, name));
    const Camera camera = renderers::heightFieldCamera(file, double(size.width) / size.height, terrainView(cameraText));
    Progress progress(stage);
    Image image = renderers::renderHeightFieldFrame(context, file, camera, size.width, size.height);
    progress.done();
    printCamera(camera, cameraText);
    return {std::move(image), camera, extent};
}

// ---- encode ----

struct EncodeOptions {
    std::string dem, output, sizeText = "512x512", colour, compression = enumName(format::Compression::Zip),
                rows = enumName(codec::GroundRows::Terrain);
    codec::TerrainViewer viewer;  // --eye-height, --near, --far, --fov
    double heightScale = 1;
    int grid = 129;
};

CLI::App* addEncode(CLI::App& command, EncodeOptions& o) {
    CLI::App& encode = *command.add_subcommand("encode", "Sample a DEM through the perspective ground map");
    encode.add_option("dem", o.dem,
                      "DEM: 16-bit PNG/TIFF (read as [0,1]: give --height-scale), float EXR, .npy, .npz "
                      "(e.g. matplotlib's jacksboro_fault_dem.npz) or procedural[:SIZE[:SEED]]")
        ->required();
    writesFile(encode.add_option("-o,--output", o.output, "CoNUS file (.exr)"))->required();
    encode.add_option("--size", o.sizeText, "CoNUS image size WxH")->capture_default_str();
    // The ground map's own ranges (ground_map.h), checked here so a bad value is a usage error.
    encode.add_option("--eye-height", o.viewer.eyeHeight, "viewer's eye above the base plane, metres")
        ->capture_default_str()
        ->check(finiteRange(0, 1e9));
    encode.add_option("--near", o.viewer.near, "distance from the viewer to the field's near edge, metres")
        ->capture_default_str()
        ->check(finiteRange(0, 1e9, true));
    CLI::Option* far = encode.add_option("--far", o.viewer.far,
                                         "distance to the far edge, metres, beyond --near (default: near + the DEM's "
                                         "depth when the file gives its spacing, else 6000)")
                           ->check(finiteRange(0, 1e9));
    encode.add_option("--fov", o.viewer.fovDegrees,
                      "horizontal field of view at the far edge, degrees; sets the field's width (default: the "
                      "DEM's own width when known, else 60)")
        ->check(finiteRange(0, 170));
    encode.callback([&o, far] {
        if (far->count() > 0 && !(o.viewer.far > o.viewer.near)) {
            std::ostringstream why;
            why << o.viewer.far << " is not beyond --near " << o.viewer.near;
            throw CLI::ValidationError("--far", why.str());
        }
    });
    encode.add_option("--grid", o.grid, "sampling-map nodes per side stored in the file")->capture_default_str();
    encode.add_option("--rows", o.rows,
                      "how the map spends rows on depth: terrain (in proportion to the screen rows each band of the "
                      "terrain covers for the map's viewer, within the DEM's resolution) or planar (the paper's "
                      "perspective ground plane, which starves far mountains)")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames<codec::GroundRows>()));
    encode.add_option("--height-scale", o.heightScale, "multiplies the DEM's values (to metres)")
        ->capture_default_str();
    encode.add_option("--colour,--color", o.colour, "colour texture (default: a ramp by height and slope)");
    addCompressionOption(encode, o.compression);
    setExamples(encode, {"conus heightfield encode procedural -o terrain.exr",
                       "conus heightfield encode dem.tif --height-scale 800 -o terrain.exr --size 1024x1024 --eye-height 150",
                       "conus heightfield encode jacksboro_fault_dem.npz --colour ortho.png -o terrain.exr"});
    return &encode;
}

int runEncode(const EncodeOptions& o) {
    checkConusOutput(o.output, o.dem);
    Progress loading("read " + o.dem);
    const sceneio::Dem dem = demFrom(o.dem, o.heightScale);
    loading.done();
    codec::HeightFieldOptions options;
    options.ground = codec::groundForField(
        o.viewer, glm::dvec2(dem.cellMetres.x * dem.heights.width, dem.cellMetres.y * dem.heights.height));
    const Size size = parseSize(o.sizeText);
    checkGridForImage(o.grid, size.width, size.height, EncodeOptions{}.grid);
    options.width = size.width;
    options.height = size.height;
    options.mapGrid = o.grid;
    options.fitRows = parseEnum<codec::GroundRows>(o.rows) == codec::GroundRows::Terrain;
    const glm::dvec2 extent = codec::fieldExtent(options.ground);
    SourceEncoding encoding;
    const Image colour = demColour(dem, o.colour, extent, &encoding);
    Progress progress("encode height field " + o.sizeText);
    options.progress = progress.callback();
    format::ConusFile file = codec::encodeHeightField(dem.heights, colour, options);
    progress.done();
    file.compression = parseEnum<format::Compression>(o.compression);
    file.sourceEncoding = encoding;
    format::writeConusFile(o.output, file);
    const bool fitted = file.analytic && !file.analytic->groundRows.empty();
    std::printf("wrote %s: %dx%d CoNUS height field of %s; field %.0f x %.0f m (eye %g m, near %g m, "
                "far %g m, fov %.2f deg; %s rows); heights %.1f..%.1f m\n",
                o.output.c_str(), file.image.width, file.image.height, dem.description.c_str(), extent.x, extent.y,
                options.ground.eyeHeight, options.ground.near, options.ground.far, options.ground.fovDegrees,
                enumName(fitted ? codec::GroundRows::Terrain : codec::GroundRows::Planar), file.depth.near, file.depth.far);
    return 0;
}

// ---- render ----

struct RenderOptions {
    std::string input, frame, cameraText, frameSize = "960x540", compare, backend = enumName(renderers::Backend::Auto), colour;
    double heightScale = 1;
};

CLI::App* addRender(CLI::App& command, RenderOptions& o) {
    CLI::App& render = *command.add_subcommand("heightfield", "Undistort a CoNUS height field to a mesh and render a frame");
    render.add_option("input", o.input, "CoNUS height field (.exr)")->required();
    writesFile(render.add_option("-o,--output", o.frame, "frame (.png, .exr, ...)"))->required();
    render.add_option("--camera", o.cameraText,
                      "x,y,z,lx,ly,lz,fovDeg: eye, look-at point (world metres: x right, y up, z toward the "
                      "viewer) and vertical fov (default: the ground map's viewer)");
    render.add_option("--size", o.frameSize, "frame size WxH")->capture_default_str();
    render.add_option("--compare", o.compare,
                      "the DEM the file was made from: also render it at full resolution and a uniform height "
                      "field of the same sample count, side by side (full | CoNUS | uniform), with PSNRs");
    render.add_option("--height-scale", o.heightScale, "as given to encode (for --compare)")->capture_default_str();
    render.add_option("--colour,--color", o.colour, "as given to encode (for --compare)");
    addBackendOption(render, o.backend, renderers::CpuPath::None);
    setExamples(render, {"conus render heightfield terrain.exr -o frame.png",
                       "conus render heightfield terrain.exr -o frame.png --camera 0,150,0,0,0,-2000,50 --size 1280x720",
                       "conus render heightfield terrain.exr -o compare.png --compare procedural"});
    return &render;
}

// The DEM resampled uniformly to columns x rows, rendered as `frame` was.
Image renderUniform(renderers::Context& context, const sceneio::Dem& dem, const Image& colour, int columns, int rows,
                    const Frame& frame) {
    const format::ConusFile field = codec::uniformHeightField(dem.heights, colour, columns, rows);
    return renderers::renderTerrain(context, codec::undistortHeightField(field, frame.extent), frame.camera, frame.image.width,
                             frame.image.height);
}

// --compare: full resolution | CoNUS | uniform of the CoNUS image's sample count, with PSNRs.
void writeComparison(renderers::Context& context, const RenderOptions& o, const format::ConusFile& file, const Frame& frame) {
    Progress comparing("render full resolution and uniform");
    const sceneio::Dem dem = demFrom(o.compare, o.heightScale);
    const Image colour = demColour(dem, o.colour, frame.extent);
    const Image full = renderUniform(context, dem, colour, dem.heights.width, dem.heights.height, frame);
    const Image uniform = renderUniform(context, dem, colour, file.image.width, file.image.height, frame);
    comparing.done();
    const Image panels[] = {full, frame.image, uniform};
    writePicture(o.frame, codec::sideBySide(panels));
    std::printf("wrote %s: full resolution %dx%d | CoNUS %dx%d | uniform %dx%d (%s)\n", o.frame.c_str(), dem.heights.width,
                dem.heights.height, file.image.width, file.image.height, file.image.width, file.image.height,
                context.renderer().c_str());
    std::printf("PSNR vs full resolution: CoNUS %.2f dB, uniform %.2f dB\n", codec::psnr(frame.image, full),
                codec::psnr(uniform, full));
}

int runRender(const RenderOptions& o) {
    checkPictureOutput(o.frame, {}, {o.input});
    if (!o.compare.empty() && o.compare.rfind("procedural", 0) != 0) checkInputPath(o.compare);  // before the render
    const format::ConusFile file = format::readConusFile(o.input);
    const Size size = parseSize(o.frameSize);
    const renderers::Device device = deviceFor(o.backend, renderers::CpuPath::None, "terrain rendering");
    renderers::Context& context = device.context();
    const Frame frame = renderFrame(context, file, o.input, o.cameraText, size, "undistort and render");
    if (!o.compare.empty()) {
        writeComparison(context, o, file, frame);
        return 0;
    }
    writePicture(o.frame, frame.image);
    std::printf("wrote %s: %dx%d frame (%s)\n", o.frame.c_str(), frame.image.width, frame.image.height,
                context.renderer().c_str());
    return 0;
}

}  // namespace

Image heightFieldFrame(const format::ConusFile& file, const std::string& cameraText, int width, int height,
                       const std::string& backendName) {
    const renderers::Device device = deviceFor(backendName, renderers::CpuPath::None, "terrain rendering");
    return renderFrame(device.context(), file, "the file", cameraText, {width, height},
                       "undistort the height field and render " + std::to_string(width) + "x" + std::to_string(height))
        .image;
}

Command addHeightFieldCommand(CLI::App& root) {
    return addCommandGroup(root, "heightfield",
                           "CoNUS height fields: sample a DEM densely near a viewer (encode; a frame of it: `conus render heightfield`)",
                           {commandPart(addEncode, runEncode)});
}

CommandPart heightFieldRenderPart() { return commandPart(addRender, runRender); }

}  // namespace conus::cli
