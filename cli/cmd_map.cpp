// conus map: build a sampling map (mass-spring strokes, composition of map files, the perspective
// ground plane, foci, importance) and write it as a CoNUS map file that `conus encode --map` reads.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "conus/codec/builders/auto_map.h"
#include "conus/codec/builders/compose.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/ground_map.h"
#include "conus/codec/builders/map_measures.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/builders/springs.h"
#include "conus/codec/map/pictures.h"
#include "conus/format/container.h"
#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/core/map_rules.h"
#include "conus/imageio/image_file.h"
#include "image_files.h"
#include "encoding.h"
#include "map_options.h"
#include "output_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

const std::string kGridHelp = "nodes per side (default " + std::to_string(map_rules::kDefaultSide) + ")";

constexpr int kPreviewSide = 512;

struct OutputOptions {
    std::string output, preview;
};

void addOutputOptions(CLI::App& command, OutputOptions& options) {
    writesFile(command.add_option("-o,--output", options.output, "output map file (.exr, a CoNUS file)"))->required();
    writesFile(command.add_option("--preview", options.preview,
                                  "also write a picture of the map (PNG, ...): density heat map with the distorted grid"));
}

// "a,b" -> two finite numbers.
std::pair<double, double> parsePair(const std::string& text, const char* what) {
    std::istringstream in(text);
    double a = 0, b = 0;
    char comma = 0;
    if (!(in >> a >> comma >> b) || comma != ',' || !in.eof() || !std::isfinite(a) || !std::isfinite(b)) {
        throw Error(ErrorCode::InvalidArgument, std::string(what) + " \"" + text + "\" is not two numbers \"a,b\"");
    }
    return {a, b};
}

// Checks before the work that the map file and its preview can be written (usage errors).
void checkOutputs(const OutputOptions& out) {
    checkConusOutput(out.output, "");
    if (!out.preview.empty()) checkPictureOutput(out.preview, {}, {out.output});
}

// Writes the map file (codec/conus_file.h) and its preview, both or neither, then reports them.
// `aspect` (width / height of the pictures it is meant for) makes the anisotropy one of pixels.
void writeMapFile(const codec::SamplingMap& map, std::optional<format::AnalyticMap> analytic, const OutputOptions& out,
                  double aspect = 1.0) {
    const format::ConusFile file = codec::makeMapFile(map, std::move(analytic));
    AtomicOutputs outputs;
    format::writeConusFile(out.output, file);
    if (!out.preview.empty())
        writeDrawing(out.preview,
                     codec::densityPicture(map, kPreviewSide, kPreviewSide, 32, file.analytic ? &*file.analytic : nullptr, aspect));
    outputs.commit();
    const codec::DensityStats stats = codec::densityStats(map);
    const codec::MapMeasures measures = codec::measureMap(map, aspect);
    if (quiet()) return;  // -q: silent on success
    std::printf("wrote %s: %dx%d sampling map, density %.3g .. %.3g, anisotropy up to %.3g\n", out.output.c_str(), map.columns(),
                map.rows(), stats.min, stats.max, measures.maxAnisotropy);
    if (!out.preview.empty()) std::printf("wrote %s\n", out.preview.c_str());
}

// The strokes as given: inline JSON (it starts with '[' or '{'), or the path of a JSON file.
std::string strokesText(const std::string& argument) {
    const auto first = argument.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && (argument[first] == '[' || argument[first] == '{')) return argument;
    const std::string& path = argument;
    checkInputPath(path);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::Io, "cannot open " + path);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// ---- springs ----

struct SpringsOptions {
    std::string strokes;
    int particles = 256, grid = 33, maxSteps = 20000;
    OutputOptions out;
};

CLI::App* addSprings(CLI::App& map, SpringsOptions& o) {
    CLI::App& command = *addSubcommand(map, "springs", "Mass-spring brush system (paper 3.1): paint strokes from a JSON list, solve until stable",
        {"conus map springs --strokes '[{\"u\":0.3,\"v\":0.4,\"radius\":0.1,\"strength\":1,\"duration\":0.5}]' -o m.exr",
         "conus map springs --strokes strokes.json -o m.exr --preview m.png"});
    command.add_option("--strokes", o.strokes,
                       "strokes as JSON, inline or a file: [{\"u\":0.3,\"v\":0.4,\"radius\":0.1,\"strength\":1.0,\"duration\":0.5}, ...]")
        ->required();
    command.add_option("--grid", o.particles, "particles per side (default 256)")->check(CLI::Range(kMinMapSide, kMaxMapSide));
    command.add_option("--out-grid", o.grid, "nodes per side of the written map (default 33)")->check(CLI::Range(kMinMapSide, kMaxMapSide));
    command.add_option("--max-steps", o.maxSteps, "give up waiting for the stable state after this many steps (default 20000)")
        ->check(CLI::Range(1, 10000000));
    addOutputOptions(command, o.out);
    return &command;
}

int runSprings(const SpringsOptions& o) {
    checkOutputs(o.out);
    const std::vector<codec::Stroke> strokes = codec::parseStrokes(strokesText(o.strokes));
    codec::SpringSystem system(o.particles, o.particles);
    for (const codec::Stroke& s : strokes) system.addStroke(s);
    Progress progress("solve " + std::to_string(o.particles) + "x" + std::to_string(o.particles) + " springs, " +
                      std::to_string(strokes.size()) + " strokes");
    const int steps = system.runUntilStable(o.maxSteps, progress.callback());
    progress.done();
    if (system.stable()) {
        std::printf("stable after %d steps (%.2f simulated s)\n", steps, system.time());
    } else {
        std::printf("not stable after %d steps; writing the current state\n", steps);
    }
    double scale = 1.0;
    const codec::SamplingMap map = system.toMap(o.grid, o.grid, &scale);
    if (scale < 1.0) std::printf("the %d-node grid folded; displacements scaled by %.4f\n", o.grid, scale);
    writeMapFile(map, std::nullopt, o.out);
    return 0;
}

// ---- compose ----

struct ComposeOptions {
    std::vector<std::string> inputs, translate, scale;
    std::vector<double> weights;
    int grid = 0;  // 0: the largest input's
    OutputOptions out;
};

CLI::App* addCompose(CLI::App& map, ComposeOptions& o) {
    CLI::App& command = *map.add_subcommand(
        "compose", "Add the displacement fields of map files (paper Fig. 9), each optionally translated and scaled");
    command.add_option("inputs", o.inputs, "map files (any CoNUS file)")->required()->expected(1, -1);
    command.add_option("--translate", o.translate, "dx,dy: move the k-th input's pattern (k-th use, k-th input)");
    command.add_option("--scale", o.scale, "s or s,cu,cv: scale the k-th input's pattern by s about (cu,cv), default centre 0.5,0.5");
    command.add_option("--weight", o.weights, "weight of the k-th input's displacement (default 1)");
    command.add_option("--grid", o.grid, "nodes per side of the result (default: the largest input's)")
        ->check(CLI::Range(kMinMapSide, kMaxMapSide));
    addOutputOptions(command, o.out);
    return &command;
}

// "s" or "s,cu,cv": a scale factor and its centre (default the middle).
struct ScaleText {
    double s = 0;
    glm::dvec2 centre{0.5, 0.5};
};

ScaleText parseScale(const std::string& text) {
    ScaleText r;
    std::istringstream in(text);
    char c1 = 0, c2 = 0;
    const bool ok = (in >> r.s) && (in.eof() || ((in >> c1 >> r.centre.x >> c2 >> r.centre.y) && c1 == ',' && c2 == ',' && in.eof()));
    if (!ok) throw Error(ErrorCode::InvalidArgument, "--scale \"" + text + "\" is not s or s,cu,cv");
    return r;
}

// The k-th input, moved and scaled as its --translate and --scale say; `aspect` its picture's.
codec::SamplingMap composeInput(const ComposeOptions& o, std::size_t k, codec::SamplingMap map, double aspect) {
    if (k < o.translate.size()) {
        const auto [dx, dy] = parsePair(o.translate[k], "--translate");
        codec::ComposeResult r = codec::translateMap(map, {dx, dy}, aspect);
        if (r.rebuilt) std::printf("%s: translated pattern built from its moved density\n", o.inputs[k].c_str());
        map = std::move(r.map);
    }
    if (k < o.scale.size()) {
        const ScaleText scale = parseScale(o.scale[k]);
        codec::ComposeResult r = codec::scaleMap(map, scale.s, scale.centre, aspect);
        if (r.rebuilt) std::printf("%s: scaled pattern built from its scaled density\n", o.inputs[k].c_str());
        map = std::move(r.map);
    }
    return map;
}

int runCompose(const ComposeOptions& o) {
    checkOutputs(o.out);
    if (o.translate.size() > o.inputs.size() || o.scale.size() > o.inputs.size() || o.weights.size() > o.inputs.size()) {
        throw Error(ErrorCode::InvalidArgument, "more --translate, --scale or --weight values than inputs");
    }
    std::vector<codec::SamplingMap> maps;
    int grid = o.grid;
    double aspect = 0;  // the first input's picture's, for the anisotropy bound
    for (std::size_t k = 0; k < o.inputs.size(); ++k) {
        const format::ConusFile file = format::readConusFile(o.inputs[k]);
        codec::SamplingMap map = codec::SamplingMap::fromGrid(file.map);
        if (o.grid == 0) grid = std::max({grid, map.columns(), map.rows()});
        if (aspect == 0) aspect = file.sourceWidth > 0 && file.sourceHeight > 0 ? double(file.sourceWidth) / file.sourceHeight : 1.0;
        maps.push_back(composeInput(o, k, std::move(map), aspect));
    }
    std::vector<double> weights;
    if (!o.weights.empty()) {
        weights.assign(maps.size(), 1.0);
        std::copy(o.weights.begin(), o.weights.end(), weights.begin());
    }
    const codec::ComposeResult sum = codec::addMaps(maps, grid, grid, weights, aspect);
    if (sum.rebuilt) {
        std::printf("added %zu maps; the plain sum folds or starves a cell, so built from their summed density "
                    "(anisotropy up to %.2f, bound %.2f)\n", maps.size(), sum.report.maxAnisotropy, sum.report.bound);
    } else {
        std::printf("added %zu maps\n", maps.size());
    }
    writeMapFile(sum.map, std::nullopt, o.out, aspect);
    return 0;
}

// ---- ground ----

struct GroundOptions {
    codec::GroundParams ground;
    int grid = map_rules::kDefaultSide;
    OutputOptions out;
};

CLI::App* addGround(CLI::App& map, GroundOptions& o) {
    CLI::App& command = *map.add_subcommand(
        "ground", "Perspective ground-plane map of a height field (paper section 4), viewer at the bottom edge's middle");
    command.add_option("--eye-height", o.ground.eyeHeight, "eye height above the ground (ground units)")->required();
    command.add_option("--near", o.ground.near, "ground distance of the bottom edge (v = 1)")->required();
    command.add_option("--far", o.ground.far, "ground distance of the top edge (v = 0)")->required();
    command.add_option("--fov", o.ground.fovDegrees, "horizontal field of view in degrees at the far edge (default 60)");
    command.add_option("--grid", o.grid, kGridHelp)->check(CLI::Range(kMinMapSide, kMaxMapSide));
    addOutputOptions(command, o.out);
    return &command;
}

int runGround(const GroundOptions& o) {
    checkOutputs(o.out);
    const codec::SamplingMap map = codec::buildGroundMap(o.ground, o.grid, o.grid);
    writeMapFile(map, codec::toAnalytic(o.ground), o.out);
    return 0;
}

// ---- foci ----

struct FociOptions {
    std::vector<std::string> foci;
    std::string composition = enumName(format::FociComposition::Density), falloff = defaultFalloffText();
    int grid = map_rules::kDefaultSide;
    double aspect = 1.0, maxAnisotropy = 0;
    bool exactK = false;
    OutputOptions out;
};

CLI::App* addFoci(CLI::App& map, FociOptions& o) {
    CLI::App& command = *map.add_subcommand("foci", "Circular foci u,v,r,k");
    addMaxAnisotropyOption(command, o.maxAnisotropy);
    command.add_option("--focus", o.foci, "focus u,v,r,k (repeat for several)")->required();
    addComposeOption(command, o.composition);
    addFalloffOption(command, o.falloff);
    command.add_option("--grid", o.grid, kGridHelp)->check(CLI::Range(kMinMapSide, kMaxMapSide));
    command.add_option("--aspect", o.aspect, "image width / height, so foci are circular in pixels (default 1)");
    addExactKOption(command, o.exactK);
    addOutputOptions(command, o.out);
    return &command;
}

int runFoci(const FociOptions& o) {
    checkOutputs(o.out);
    const std::vector<codec::Focus> list = parseFoci(o.foci);
    codec::FociOptions fo;
    fo.columns = fo.rows = o.grid;
    fo.aspect = o.aspect;
    fo.maxAnisotropy = o.maxAnisotropy;
    fo.composition = parseEnum<format::FociComposition>(o.composition);
    fo.falloff = codec::parseFalloff(o.falloff);
    Progress progress("build sampling map (" + plural(list.size(), "focus", "foci") + ")");
    // No picture to predict a loss on: the context keeps the default floor (foci_budget.h).
    const codec::FociBudget budget = codec::fociForContextFloor(list, fo, codec::kDefaultContextFloor, o.exactK);
    progress.done();
    const std::string said = describeFociBudget(budget, std::nullopt, o.exactK, o.grid, o.maxAnisotropy);
    if (!quiet()) std::printf("%s\n", said.c_str());
    std::optional<format::AnalyticMap> analytic = codec::toAnalytic(budget.given, fo.composition, codec::recordedFalloff(budget, fo.falloff));
    analytic->scalars["aspect"] = o.aspect;  // so an encode of a picture of another aspect can warn
    writeMapFile(budget.map, std::move(analytic), o.out, o.aspect);
    return 0;
}

// ---- auto ----

struct AutoOptions {
    std::string importance, image, method = enumName(codec::AutoMethod::Flow);
    double minDensity = 0.25, maxDensity = 16, maxAnisotropy = 0;
    int grid = map_rules::kDefaultSide;
    OutputOptions out;
};

CLI::App* addAuto(CLI::App& map, AutoOptions& o) {
    CLI::App& command = *map.add_subcommand(
        "auto", "Automatic map from importance: density follows the importance, with a floor for context");
    addMaxAnisotropyOption(command, o.maxAnisotropy);
    command.add_option("--importance", o.importance,
                       "importance image (one channel or RGB; higher = more samples), or 'detail' / 'faces' "
                       "computed from --image")
        ->required();
    command.add_option("--image", o.image, "the picture that 'detail' and 'faces' look at");
    addDensityBoundOptions(command, o.minDensity, o.maxDensity);
    command.add_option("--method", o.method, "how the map follows the importance: 2-D flow, or separable (the baseline)")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames<codec::AutoMethod>()));
    command.add_option("--grid", o.grid, kGridHelp)->check(CLI::Range(kMinMapSide, kMaxMapSide));
    addOutputOptions(command, o.out);
    return &command;
}

int runAuto(const AutoOptions& o) {
    checkOutputs(o.out);
    const Image picture = o.image.empty() ? Image{} : imageio::readImageFile(o.image).image;
    const Image importance = importanceFrom(o.importance, picture);
    const codec::AutoMapOptions options = autoMapOptions(o.grid, o.minDensity, o.maxDensity, o.maxAnisotropy, o.method);
    Progress progress("build sampling map from importance");
    const codec::SamplingMap map = codec::buildAutoMap(importance, options);
    progress.done();
    const codec::MapMeasures measures = codec::measureMap(map);
    std::printf("achieved density follows the target with correlation %.3f; cell density %.3g .. %.3g (asked: %.3g .. %.3g)\n",
                codec::densityCorrelation(map, codec::importanceToDensity(importance, options)), measures.minCellDensity,
                measures.maxCellDensity, o.minDensity, o.maxDensity);
    writeMapFile(map, std::nullopt, o.out, double(importance.width) / importance.height);
    return 0;
}

struct MapOptions {
    SpringsOptions springs;
    ComposeOptions compose;
    GroundOptions ground;
    FociOptions foci;
    AutoOptions automatic;
};

}  // namespace

Command addMapCommand(CLI::App& root) {
    Command map = addCommandGroup(root, "map", "Build a sampling map and write it as a map file for `conus encode --map`",
                                  {commandPart(addSprings, runSprings), commandPart(addCompose, runCompose),
                                   commandPart(addGround, runGround), commandPart(addFoci, runFoci), commandPart(addAuto, runAuto)});
    setExamples(*map.app, {"conus map foci --focus 0.3,0.4,0.08,4 --focus 0.7,0.6,0.05,3 --aspect 1.5 -o m.exr --preview m.png",
                           "conus map springs --strokes '[{\"u\":0.5,\"v\":0.4,\"radius\":0.1}]' -o m.exr",
                           "conus map auto --importance faces --image portrait.jpg -o m.exr"});
    return map;
}

}  // namespace conus::cli
