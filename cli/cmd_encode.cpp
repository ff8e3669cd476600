// conus encode: a conventional image -> a CoNUS file, through foci, a map file, or importance.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "batch.h"
#include "commands.h"
#include "conus/codec/build/auto_map.h"
#include "conus/codec/build/foci.h"
#include "conus/codec/build/frame_budget.h"
#include "conus/codec/image/encode.h"
#include "conus/core/limits.h"
#include "conus/core/map_rules.h"
#include "encoding.h"
#include "image_files.h"
#include "importance.h"
#include "map_options.h"
#include "progress.h"

namespace conus::cli {
namespace {

struct EncodeOptions {
    BatchOptions batch;
    std::string mapFile, compose = "density", importance, method = "flow", falloff = "2";
    double minDensity = 0.25, maxDensity = 16, maxAnisotropy = 0;
    double frameLoss = -1;  // dB; < 0: no budget (--min-density sets the floor)
    std::vector<std::string> foci;
    int grid = map_rules::kDefaultSide;
    FitSetting fit;  // --fit, --fit-iterations, --fit-hold
    SourceOptions source;
    StorageOptions storage;
};

struct BuiltMap {
    std::unique_ptr<codec::SamplingMap> map;
    std::optional<format::AnalyticMap> analytic;
};

BuiltMap mapFromFile(const std::string& path) {
    const format::ConusFile mapSource = format::readConusFile(path);
    return {std::make_unique<codec::SamplingMap>(codec::SamplingMap::fromGrid(mapSource.map)), mapSource.analytic};
}

BuiltMap mapFromImportance(const EncodeOptions& o, const Image& source, const Size& size) {
    Progress progress("build sampling map from " + o.importance + " importance");
    codec::AutoMapOptions autoOptions = autoMapOptions(o.grid, o.minDensity, o.maxDensity, o.maxAnisotropy, o.method);
    const Image importance = importanceFrom(o.importance, source);
    if (o.frameLoss < 0) {
        BuiltMap built{std::make_unique<codec::SamplingMap>(codec::buildAutoMap(importance, autoOptions)), std::nullopt};
        progress.done();
        return built;
    }
    // The budget chooses the context floor; say what it achieved.
    const codec::FrameErrorModel model(source, size.width, size.height, importance);
    codec::BudgetResult r = codec::buildAutoMapForFrameLoss(importance, model, o.frameLoss, autoOptions);
    progress.done();
    std::printf("frame-loss budget %.2f dB: context floor %.3g; predicted whole-frame loss %.2f dB, ROI gain %+.2f dB%s\n",
                o.frameLoss, r.minDensity, r.predicted.frameLoss, r.predicted.roiGain,
                r.budgetBinds ? "" : " (the lowest floor stays within the budget: raise --max-density for more)");
    return {std::make_unique<codec::SamplingMap>(std::move(r.map)), std::nullopt};
}

BuiltMap mapFromFoci(const EncodeOptions& o, const Image& source) {
    const std::vector<codec::Focus> foci = parseFoci(o.foci);
    codec::FociOptions fo;
    fo.columns = fo.rows = o.grid;
    fo.aspect = double(source.width) / source.height;
    fo.maxAnisotropy = o.maxAnisotropy;
    fo.composition = o.compose == "add" ? codec::FociComposition::Add : codec::FociComposition::Density;
    fo.falloff = codec::parseFalloff(o.falloff);
    Progress progress("build sampling map (" + plural(foci.size(), "focus", "foci") + ")");
    BuiltMap built{std::make_unique<codec::SamplingMap>(codec::buildFociMap(foci, fo)),
                   codec::toAnalytic(foci, fo.composition, fo.falloff)};
    codec::checkFociHeld(*built.map, foci, fo);  // the file must not record a focus its map ignores
    progress.done();
    return built;
}

// One input to one output; returns the line that says what was written.
std::string encodeOne(const EncodeOptions& o, const std::string& input, const std::string& output) {
    checkConusOutput(output, input);
    const imageio::ImageFile source = readSource(input, o.source);
    const Size size = conusSize(o.storage, source.image);
    codec::checkEncodeMemory(source.image, size.width, size.height);  // before a map is built for it
    if (!o.importance.empty() || !o.foci.empty()) checkGridForImage(o.grid, size.width, size.height);
    BuiltMap built;
    if (!o.mapFile.empty()) built = mapFromFile(o.mapFile);
    else if (!o.importance.empty()) built = mapFromImportance(o, source.image, size);
    else if (!o.foci.empty()) built = mapFromFoci(o, source.image);
    else {
        warn("no --focus, --map or --importance: writing the uniform image of the same pixel count (what `conus "
             "uniform` makes)");
        built.map = std::make_unique<codec::SamplingMap>(codec::SamplingMap::identity(2, 2));
    }
    const gl::Device device = deviceFor(o.storage.backend, gl::CpuPath::Available, "encoding");
    std::string fitNote;
    format::ConusFile file =
        encodeToConus(device, source.image, source.info.encoding, *built.map, size, built.analytic, o.fit, &fitNote);
    applyStorage(o.storage, file);
    Progress writing("write " + output);
    format::writeConusFile(output, file);
    writing.done();
    return "wrote " + output + ": " + std::to_string(size.width) + "x" + std::to_string(size.height) + " CoNUS image of a " +
           std::to_string(source.image.width) + "x" + std::to_string(source.image.height) + " source, " +
           std::to_string(built.map->columns()) + "x" + std::to_string(built.map->rows()) + " sampling map" +
           (fitNote.empty() ? "" : "; " + fitNote);
}

int runEncode(const EncodeOptions& o) {
    return runConversions(o.batch, [&o](const Job& job) { return encodeOne(o, job.input, job.output); });
}

}  // namespace

Command addEncodeCommand(CLI::App& root) {
    auto options = std::make_shared<EncodeOptions>();
    CLI::App* command = addSubcommand(root, "encode", "Encode an image (PNG, JPEG, TIFF, EXR, ...) into a CoNUS file through a sampling map",
        {"conus encode photo.jpg -o photo.exr --focus 0.42,0.31,0.08,4",
         "conus encode photo.jpg -o photo.exr --size 1024x768 --importance faces",
         "conus encode scan.tif -o scan.exr --map painted.exr --float",
         "conus encode photo.jpg -o photo.exr --focus 0.42,0.31,0.08,4 --fit   # fitted to the decoder: sharper, costs more CPU",
         "conus encode shots/*.jpg --out-dir exr/ --jobs 2 --skip-existing --focus 0.5,0.5,0.1,4"});
    addBatchOptions(*command, options->batch, "source image ('-' reads standard input)", "output CoNUS file (.exr)", "{stem}.exr");
    command->add_option("--focus", options->foci,
                        "focus u,v,r,k: centre (u,v) in [0,1], radius r as a fraction of the width, linear "
                        "magnification k (repeat for several foci)");
    command->add_option("--map", options->mapFile, "take the sampling map from this CoNUS file")->excludes("--focus");
    command->add_option("--importance,--auto", options->importance,
                        "build the map automatically from importance: an image file (higher = more samples), "
                        "'detail' (the image's own edges) or 'faces' (faces found in it)")
        ->excludes("--focus")
        ->excludes("--map");
    addDensityBoundOptions(*command, options->minDensity, options->maxDensity, "with --importance: ");
    command->add_option("--frame-loss", options->frameLoss,
                        "with --importance: whole-frame loss budget in dB against the uniform image; chooses the "
                        "lowest context floor whose predicted loss stays within it, and prints the predicted loss "
                        "and ROI gain")
        ->check(CLI::Range(0.0, 60.0))
        ->needs("--importance")
        ->excludes("--min-density");
    addMaxAnisotropyOption(*command, options->maxAnisotropy);
    command->add_option("--method", options->method, "with --importance: flow (default) | separable")
        ->check(CLI::IsMember({"flow", "separable"}));
    command->add_option("--compose", options->compose, "how several foci combine: density (default) | add")
        ->check(CLI::IsMember({"density", "add"}));
    addFalloffOption(*command, options->falloff)->needs("--focus");  // shapes foci only
    command->add_option("--grid", options->grid, "sampling-map nodes per side for --focus and --importance (default " + std::to_string(map_rules::kDefaultSide) + ")")
        ->check(CLI::Range(kMinMapSide, kMaxMapSide));
    addFitOption(*command, options->fit);
    addSourceOptions(*command, options->source);
    addStorageOptions(*command, options->storage);
    addQuietOption(*command);
    return {command, [options] { return runEncode(*options); }};
}

}  // namespace conus::cli
