// conus bake relief: a height field plus colour -> an orthographic CoNUS depth image (a relief
// asset, paper section 5) whose map gives the samples to what matters: --focus discs, an
// --importance image, or by default the source's own detail (the engraved text of a tablet).
// --uniform bakes the conventional asset of the same texel count, the baseline.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "arguments.h"
#include "commands.h"
#include "conus/codec/builders/auto_map.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/foci_budget.h"
#include "conus/codec/builders/frame_budget.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/depth/heightfield.h"
#include "conus/codec/depth/reflection.h"
#include "conus/codec/depth/relief.h"
#include "conus/codec/image/encode.h"
#include "conus/core/error.h"
#include "conus/format/reflection_asset.h"
#include "conus/imageio/image_file.h"
#include "conus/imageio/text.h"
#include "conus/sceneio/mesh_file.h"
#include "encoding.h"
#include "image_files.h"
#include "map_options.h"
#include "output_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

// The loss (dB) a relief asset's focus may cost the field outside it, against the uniform asset, as
// the budget measures it on the colour (encoded as `encode` does): the baked tablet of
// tests/cli/relief_test.cpp then loses 0.66 dB outside its focus on 8-bit sRGB, within the 1 dB a
// relief read all over can spare (bench/notes/2026-11-27-narrow-transitions.md). The budget's
// model, corrected by one confirming encode, is off by up to 0.3-0.5 dB there (its correction does
// not carry to maps a fraction of an octave of k away), so the bake confirms until the map kept is
// one its own encode measured within the budget: the colour at 1/16 of the pixels costs milliseconds
// an encode.
constexpr double kReliefRestLoss = 0.6;
constexpr int kReliefConfirmRounds = 6;

constexpr const char* kTabletSource = "tablet";
constexpr const char* kDefaultText = "CoNUS|FLEXIBLE PINHOLE|CAMERA";

// --tablet-size: below 8 pixels a side not one letter of the inscription (4 pixels at the least)
// shows, and 4096x4096 keeps the bake's working images (height, colour, ink and their
// filtered copies, 4 bytes a sample) under 0.8 GB (measured on a loaded 2-core machine: 752 MB
// peak, 13 s, for the default 1024x1024 bake of a 4096x4096 tablet).
constexpr int kTabletMinSide = 8;
constexpr int kTabletMaxSide = 8192;
constexpr std::int64_t kTabletMaxPixels = std::int64_t{4096} * 4096;

CLI::Validator tabletSizeCheck() {
    return sizeCheck([](const std::string& text, Size size) -> std::string {
        if (size.width < kTabletMinSide || size.height < kTabletMinSide || size.width > kTabletMaxSide ||
            size.height > kTabletMaxSide)
            return "tablet size '" + text + "': each side must lie in [" + std::to_string(kTabletMinSide) + ", " +
                   std::to_string(kTabletMaxSide) + "]";
        if (std::int64_t{size.width} * size.height > kTabletMaxPixels)
            return "tablet size '" + text + "' holds more than 4096x4096 pixels";
        return {};
    });
}

struct BakeOptions {
    std::string source, output, sizeText, colour, importance, text = kDefaultText, compression = enumName(format::Compression::Zip);
    std::string tabletSize = "1024x768";
    std::vector<std::string> foci;
    bool uniform = false, exactK = false;
    int grid = map_rules::kDefaultSide;
    double heightScale = 1.0, width = 1.0, minDensity = 0.7, maxDensity = 16.0;
};

struct Source {
    Image heights, colour;
    glm::dvec2 extent;
    std::string description;
};

Source readReliefSource(const BakeOptions& o) {
    if (o.source == kTabletSource) {
        const Size size = parseSize(o.tabletSize);
        codec::TabletOptions tablet;
        tablet.width = o.width;
        codec::Tablet made = codec::makeTablet(imageio::inscription(o.text, size.width, size.height), tablet);
        return {std::move(made.heights), std::move(made.colour), made.extent,
                "engraved tablet " + o.tabletSize + " \"" + o.text + "\""};
    }
    sceneio::Dem dem = demFrom(o.source, o.heightScale);
    const glm::dvec2 extent(o.width, o.width * dem.heights.height / dem.heights.width);
    Image colour = demColour(dem, o.colour, extent);
    return {std::move(dem.heights), std::move(colour), extent, dem.description};
}

int runBakeRelief(const BakeOptions& o) {
    checkConusOutput(o.output, o.source);
    Progress reading("make " + o.source);
    const Source source = readReliefSource(o);
    reading.done();
    Size size;
    if (o.sizeText.empty())
        std::tie(size.width, size.height) = codec::defaultConusSize(source.heights.width, source.heights.height);
    else
        size = parseSize(o.sizeText);
    checkGridForImage(o.grid, size.width, size.height);
    if (size.width > source.heights.width || size.height > source.heights.height)
        throw Error(ErrorCode::InvalidArgument, "--size " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                                                    " is larger than the height field (" +
                                                    std::to_string(source.heights.width) + "x" +
                                                    std::to_string(source.heights.height) + ")");

    std::optional<codec::SamplingMap> map;
    std::optional<format::AnalyticMap> analytic;
    std::string how = "conventional (identity map)";
    if (!o.uniform) {
        Progress building("build the sampling map");
        if (!o.foci.empty()) {
            const std::vector<codec::Focus> foci = parseFoci(o.foci);
            // The budget of `encode --focus`, on the asset's colour (on a uniform context: the rest of
            // the field keeps its samples), and the field outside the focus within kReliefRestLoss of
            // the uniform asset: a relief is read all over.
            codec::FociMapRequest request;
            request.options.columns = request.options.rows = o.grid;
            request.model = codec::FrameModelOptions{codec::ErrorSpace::Display, 0, codec::kFitHoldLowPass, true, kReliefConfirmRounds};
            request.exactK = o.exactK;
            request.restLoss = kReliefRestLoss;
            codec::FociMap built = codec::budgetedFociMap(source.colour, foci, size.width, size.height, request);
            const codec::FociBudget& budget = built.budget;
            const std::string said = describeFociBudget(
                budget, BudgetFrame{size.width, size.height, source.heights.width, source.heights.height, codec::kDefaultFrameLoss, kReliefRestLoss},
                o.exactK, o.grid);
            if (!quiet()) std::printf("%s\n", said.c_str());
            map = std::move(built.budget.map);
            analytic = std::move(built.analytic);
            how = plural(foci.size(), "focus", "foci") + " map (k " + fociKText(budget.given) + ")";
        } else {
            codec::AutoMapOptions ao;
            ao.columns = ao.rows = o.grid;
            ao.minDensity = o.minDensity;
            ao.maxDensity = o.maxDensity;
            const std::string importance = o.importance.empty() ? enumName(codec::ImportanceRule::Detail) : o.importance;
            map = codec::buildAutoMap(importanceFrom(importance, source.colour), ao);
            how = importance + " importance map";
        }
        building.done();
    }

    Progress baking("bake " + std::to_string(size.width) + "x" + std::to_string(size.height));
    codec::ReliefBakeOptions options;
    options.width = size.width;
    options.height = size.height;
    options.extent = source.extent;
    options.units = "";
    format::ConusFile file = codec::bakeRelief(source.heights, source.colour, map ? &*map : nullptr, options);
    baking.done();
    file.analytic = analytic;
    file.compression = parseEnum<format::Compression>(o.compression);
    Progress writing("write " + o.output);
    format::writeConusFile(o.output, file);
    writing.done();
    std::printf("wrote %s: %dx%d relief asset of %s (%dx%d), %s; field %g x %g, heights %g..%g\n", o.output.c_str(),
                size.width, size.height, source.description.c_str(), source.heights.width, source.heights.height,
                how.c_str(), source.extent.x, source.extent.y, file.depth.near, file.depth.far);
    return 0;
}

// --- reflection -------------------------------------------------------------------------------

struct ReflectionBakeText {
    std::string scene, output, centre = "0,0,0", roiMin, roiMax;
    std::vector<std::string> allowDirs;
    int size = 128;
    double magnification = codec::ReflectionBakeOptions{}.magnification;
    bool uniform = false;
    std::string layers = "auto";
    double mirrorRadius = 0.5;
    std::string view, reflector = "sphere", normal = "0,0,1";
};

// --layers: 1..kMaxReflectionLayers, or `auto` (0: as many as the scene needs).
int parseLayers(const std::string& text) {
    if (text == "auto") return 0;
    for (int k = 1; k <= codec::kMaxReflectionLayers; ++k)
        if (text == std::to_string(k)) return k;
    throw Error(ErrorCode::InvalidArgument, "--layers " + text + ": want 1 to " + std::to_string(codec::kMaxReflectionLayers) +
                                                " or auto");
}

int runBakeReflection(const ReflectionBakeText& o) {
    try {
        format::checkConusFileName(o.output);
    } catch (const Error&) {
        throw Error(ErrorCode::InvalidArgument,
                    "-o " + o.output + ": a reflection asset is one OpenEXR file; give a name ending in .exr (-o asset.exr)");
    }
    checkConusOutput(o.output, o.scene);
    codec::ReflectionBakeOptions options;
    options.centre = parseVector3(o.centre, "--center");
    options.size = o.size;
    options.uniform = o.uniform;
    options.magnification = o.magnification;
    options.layers = parseLayers(o.layers);
    if (o.roiMin.empty() != o.roiMax.empty())
        throw Error(ErrorCode::InvalidArgument, "--roi-min and --roi-max go together");
    if (!o.roiMin.empty()) {
        const glm::dvec3 lo = parseVector3(o.roiMin, "--roi-min"), hi = parseVector3(o.roiMax, "--roi-max");
        if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
            throw Error(ErrorCode::InvalidArgument, "--roi-min must lie below --roi-max on every axis");
        options.roi = codec::AxisBox{lo, hi};
    }
    const codec::MeshScene scene(readSceneMesh(o.scene, o.allowDirs));
    // --view: the faces' eye placed where the reflector's rays toward the viewpoint are best seen.
    std::optional<codec::EyePlacement> placed;
    codec::Reflector reflector;
    std::vector<Ray> viewRays;
    if (!o.view.empty()) {
        reflector.kind = parseEnum<codec::Reflector::Kind>(o.reflector);
        reflector.centre = options.centre;
        reflector.radius = o.mirrorRadius;
        reflector.normal = parseVector3(o.normal, "--normal");
        if (!(glm::length(reflector.normal) > 0)) throw Error(ErrorCode::InvalidArgument, "--normal is the zero vector");
        reflector.normal = glm::normalize(reflector.normal);
        if (!(o.mirrorRadius > 0)) throw Error(ErrorCode::InvalidArgument, "--view needs a mirror of --mirror-radius > 0");
        const glm::dvec3 viewpoint = parseVector3(o.view, "--view");
        Progress placing("place the eye for the view");
        placed = codec::placeReflectionEye(scene, reflector, viewpoint, options.layers);
        viewRays = codec::reflectedRays(reflector, viewpoint, codec::kViewRays);
        placing.done();
        options.centre = placed->eye;
        options.layers = placed->layers;  // auto: the layers the view needs there
    }
    Progress baking("bake six " + std::to_string(o.size) + "x" + std::to_string(o.size) + " faces (Embree)");
    const auto faces = codec::bakeReflection(scene, options);
    baking.done();
    // The report's rays are traced before the write, so that nothing fails after the asset is there.
    const int layers = faces.front().layers();
    const double one = placed ? codec::disocclusionFraction(scene, options.centre, viewRays, 1)
                              : codec::disocclusionFraction(scene, options.centre, o.mirrorRadius, 1);
    const double all = placed ? codec::disocclusionFraction(scene, options.centre, viewRays, layers)
                              : codec::disocclusionFraction(scene, options.centre, o.mirrorRadius, layers);
    // One file, written through a temporary and renamed: a failed bake leaves the earlier asset whole.
    Progress writing("write " + o.output);
    format::writeReflectionAsset(o.output, codec::reflectionAssetFile(faces));
    writing.done();
    std::printf("wrote %s: reflection asset of six %dx%d CoNUS colour + depth faces, %d layer%s, from %g,%g,%g (%s)\n",
                o.output.c_str(), o.size, o.size, layers, layers == 1 ? "" : "s", options.centre.x, options.centre.y,
                options.centre.z, o.uniform ? "uniform, the baseline" : "foci on the region of interest");
    if (placed) {
        std::printf("eye placed for the view: %g,%g,%g (render with --at %g,%g,%g, the reflector's centre)\n", options.centre.x,
                    options.centre.y, options.centre.z, reflector.centre.x, reflector.centre.y, reflector.centre.z);
        std::printf("rays the %s mirror reflects toward the view that land in a disocclusion: %.2f%% with 1 layer, %.2f%% with "
                    "%d (%.2f%% from the centre with %d)\n",
                    o.reflector.c_str(), 100.0 * one, 100.0 * all, layers, 100.0 * placed->centreDisoccluded,
                    parseLayers(o.layers) == 0 ? 1 : layers);
    } else {
        std::printf("mirror rays (radius %g) that land in a disocclusion: %.2f%% with 1 layer, %.2f%% with %d\n", o.mirrorRadius,
                    100.0 * one, 100.0 * all, layers);
    }
    return 0;
}

CLI::App* addBakeReflection(CLI::App& command, ReflectionBakeText& o) {
    CLI::App* reflection = addSubcommand(
        command, "reflection",
        "A mesh seen from a reflector's centre -> a reflection asset: one .exr of six CoNUS colour + depth faces",
        {"conus bake reflection scene.obj --center 0,0.5,0 -o asset.exr",
         "conus bake reflection scene.obj --uniform -o asset-uniform.exr"});
    reflection->add_option("scene", o.scene, "mesh file (.obj, .ply, .gltf, ...)")->required();
    writesFile(reflection->add_option("-o,--output", o.output, "reflection asset (.exr: the six faces and the cube's frame)"))->required();
    reflection->add_option("--center,--centre", o.centre, "the reflector's centre x,y,z")->capture_default_str();
    reflection->add_option("--size", o.size, "texels a face side")->capture_default_str()->check(CLI::Range(8, 4096));
    reflection->add_option("--magnification", o.magnification, "linear magnification of the region of interest")
        ->capture_default_str()
        ->check(finiteRange(1, 16, true));
    reflection->add_option("--roi-min", o.roiMin, "region of interest, lowest corner x,y,z (default: the whole scene)");
    reflection->add_option("--roi-max", o.roiMax, "region of interest, highest corner x,y,z");
    reflection->add_flag("--uniform", o.uniform, "identity maps: the conventional asset of the same texel count");
    reflection->add_option("--layers", o.layers,
                           "surfaces kept along each texel's ray, 1 to 4, or auto: until the next covers under 1% of the texels "
                           "(with --view: until under 1% of the rays toward the view land in a disocclusion)")
        ->capture_default_str();
    reflection->add_option("--mirror-radius", o.mirrorRadius,
                           "the reflector's radius, for the report of mirror rays that land in a disocclusion")
        ->capture_default_str()
        ->check(finiteRange(0, 1e6));
    reflection->add_option("--view", o.view,
                           "x,y,z the reflector is seen from: the faces' eye moves from --center toward the reflected "
                           "viewpoint, where the fewest reflected rays land in a disocclusion (--reflector, --normal, "
                           "--mirror-radius give the mirror)");
    reflection->add_option("--reflector", o.reflector, "with --view: the mirror's shape")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames<codec::Reflector::Kind>()));
    reflection->add_option("--normal", o.normal, "with --view, plane: the mirror's facing direction x,y,z")->capture_default_str();
    addAllowDirOption(*reflection, o.allowDirs);
    return reflection;
}

CLI::App* addBakeRelief(CLI::App& command, BakeOptions& o) {
    CLI::App* relief = addSubcommand(
        command, "relief", "A height field plus colour -> an orthographic CoNUS depth image (relief asset)",
        {"conus bake relief tablet -o tablet.exr --size 256x192",
         "conus bake relief tablet --text 'HELLO|WORLD' --uniform -o tablet-uniform.exr --size 256x192",
         "conus bake relief dem.tif --width 1 --height-scale 0.1 --colour ortho.png -o relief.exr --focus 0.5,0.5,0.1,4"});
    relief->add_option("source", o.source,
                       "'tablet' (the engraved tablet made in code) or a height field: 16-bit PNG/TIFF, float EXR, "
                       ".npy, .npz or procedural[:SIZE[:SEED]]")
        ->required();
    writesFile(relief->add_option("-o,--output", o.output, "relief asset (.exr)"))->required();
    relief->add_option("--size", o.sizeText, "CoNUS image size WxH (default: a quarter of each side)");
    relief->add_option("--focus", o.foci, "focus u,v,r,k (repeatable): magnify these discs");
    addExactKOption(*relief, o.exactK)->needs("--focus");
    relief->add_option("--importance", o.importance,
                       "detail (default) | faces | an importance image: where the samples go")
        ->excludes("--focus");
    relief->add_flag("--uniform", o.uniform, "bake the conventional asset (identity map), the baseline")
        ->excludes("--focus")
        ->excludes("--importance");
    relief->add_option("--grid", o.grid, "sampling-map nodes per side")->capture_default_str();
    relief->add_option("--min-density", o.minDensity,
                       "with importance: density kept everywhere (the tablet: 0.7 gains 3.5 dB on the text for "
                       "0.5 dB elsewhere, bench/notes/2026-11-24-relief.md)")
        ->capture_default_str()
        ->check(finiteRange(0, 1));
    relief->add_option("--max-density", o.maxDensity, "with importance: cap on the density")
        ->capture_default_str()
        ->check(finiteRange(1, 1e6));
    relief->add_option("--text", o.text, "tablet: the inscription, lines split at '|'")->capture_default_str();
    relief->add_option("--tablet-size", o.tabletSize,
                       "tablet: full-resolution height field WxH, each side " + std::to_string(kTabletMinSide) + " to " +
                           std::to_string(kTabletMaxSide) + ", at most " + std::to_string(kTabletMaxPixels / (1 << 20)) +
                           " Mi pixels (4096x4096)")
        ->capture_default_str()
        ->check(tabletSizeCheck());
    relief->add_option("--width", o.width, "the field's width in world units (its depth follows the aspect)")
        ->capture_default_str()
        ->check(finiteRange(0, 1e9));
    relief->add_option("--height-scale", o.heightScale,
                       "the heights in world units (those of --width): a float file's values times this; an 8- or "
                       "16-bit image's codes span 0..1 first (its largest code, 255 or 65535, becomes this)")
        ->capture_default_str()
        ->check(finiteRange(0, 1e9));
    relief->add_option("--colour,--color", o.colour, "colour image (default: a ramp by height and slope)");
    addCompressionOption(*relief, o.compression);
    return relief;
}

}  // namespace

Command addBakeCommand(CLI::App& root) {
    return addCommandGroup(root, "bake", "Bake assets for ray intersection (relief, reflection)",
                           {commandPart(addBakeRelief, runBakeRelief), commandPart(addBakeReflection, runBakeReflection)});
}

}  // namespace conus::cli
