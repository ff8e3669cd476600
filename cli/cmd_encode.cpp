// conus encode: a conventional image -> a CoNUS file, through foci, a map file, or importance.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>

#include "arguments.h"
#include "batch.h"
#include "commands.h"
#include "conus/codec/builders/auto_map.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/foci_budget.h"
#include "conus/codec/builders/frame_budget.h"
#include "conus/codec/builders/importance.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/image/encode.h"
#include "conus/core/limits.h"
#include "conus/core/map_rules.h"
#include "conus/renderers/gpu_image.h"
#include "encoding.h"
#include "image_files.h"
#include "map_options.h"
#include "progress.h"

namespace conus::cli {
namespace {

struct EncodeOptions {
    BatchOptions batch;
    std::string mapFile, compose = enumName(format::FociComposition::Density), importance,
        method = enumName(codec::AutoMethod::Flow), falloff = defaultFalloffText();
    double minDensity = 0.25, maxDensity = 16, maxAnisotropy = 0;
    double frameLoss = codec::kDefaultFrameLoss;  // dB, predicted; --min-density instead sets an importance map's floor
    bool floorGiven = false;  // --min-density: no budget for importance maps
    bool frameLossGiven = false;
    bool exactK = false;      // --exact-k: foci keep k as asked
    bool fast = false;        // --fast: the filtered encode alone, no fit to the decoder
    std::vector<std::string> foci;
    std::vector<codec::Focus> parsedFoci;  // --focus, parsed once (runEncode)
    int grid = map_rules::kDefaultSide;
    FitSetting fit = defaultFit();  // fitted by default; --fast leaves it out
    SourceOptions source;
    StorageOptions storage;
};

// The picture: linear floats, or (`--fast`, a plain 8-bit sRGB file) its 8-bit codes, `image` then
// holding only their size and channels.
struct Picture {
    Picture(const Image& picture, const codec::EightBitImage* eightBit = nullptr) : image(picture), codes(eightBit) {}
    const Image& image;
    const codec::EightBitImage* codes;
};

struct BuiltMap {
    std::unique_ptr<codec::SamplingMap> map;
    std::optional<format::AnalyticMap> analytic;
    std::shared_ptr<const codec::ModelEncode> encoded{};  // the budget's confirming encode of `map`, kept
};

BuiltMap mapFromFile(const std::string& path, const Image& source, const Size& size) {
    const format::ConusFile mapSource = format::readConusFile(path);
    checkMapForImage("--map " + path, mapSource.map.columns, mapSource.map.rows, size.width, size.height);
    // Foci built for another aspect are ellipses on this picture.
    if (const std::optional<double> aspect = codec::madeForAspect(mapSource)) {
        const double here = double(source.width) / source.height;
        if (codec::aspectsDiffer(*aspect, here)) {
            char text[320];
            std::snprintf(text, sizeof text,
                          "the map %s was made for pictures of aspect %.3g (width / height) and this one's is %.3g: its "
                          "foci become ellipses (make it with `conus map foci --aspect %.3g`)",
                          path.c_str(), *aspect, here, here);
            warn(text);
        }
    }
    return {std::make_unique<codec::SamplingMap>(codec::SamplingMap::fromGrid(mapSource.map)), mapSource.analytic};
}

// The options of the map of the picture's own detail: what `encode` makes with no focus, and the
// context foci and importance maps sit on.
codec::AutoMapOptions ownDetailOptions(const EncodeOptions& o) { return autoMapOptions(o.grid, 0.25, o.maxDensity, o.maxAnisotropy, o.method); }

// The detail importance of a picture kept as 8-bit codes: each code's display value the one
// imageio::displayEncoded gives its linear value, so that it is the linear picture's detail exactly.
Image detailOfCodes(const codec::EightBitImage& codes) {
    Image linear = makeImage(256, 1, {"R", "G", "B"});
    for (int v = 0; v < 256; ++v)
        for (int c = 0; c < 3; ++c) linear.at(v, 0, c) = codec::srgbCodeToLinear()[v];
    const Image shown = imageio::displayEncoded(linear);
    float table[256];
    for (int v = 0; v < 256; ++v) table[v] = shown.at(v, 0, 0);
    return codec::detailImportance(codes, table);
}

// The picture's own detail (the importance `detail`), from its codes where it is kept as codes.
Image detailOf(const Picture& source) {
    return source.codes ? detailOfCodes(*source.codes) : importanceFrom(enumName(codec::ImportanceRule::Detail), source.image);
}

BuiltMap mapFromImportance(const EncodeOptions& o, const Image& source, const Size& size, const codec::FrameModelOptions& modelOptions,
                           bool encodeKept) {
    Progress progress("build sampling map from " + o.importance + " importance");
    codec::AutoMapOptions autoOptions = autoMapOptions(o.grid, o.minDensity, o.maxDensity, o.maxAnisotropy, o.method);
    const Image importance = importanceFrom(o.importance, source);
    if (o.floorGiven) {
        BuiltMap built{std::make_unique<codec::SamplingMap>(codec::buildAutoMap(importance, autoOptions)), std::nullopt};
        progress.done();
        return built;
    }
    // The budget chooses the context floor; say what it achieved. Apart from the importance the
    // samples follow the picture's own detail, as with no importance at all (`detail` is that already).
    codec::DensityField context;
    const bool notDetail = o.importance != enumName(codec::ImportanceRule::Detail);
    const Image detail = notDetail ? importanceFrom(enumName(codec::ImportanceRule::Detail), source) : Image{};
    // One model of the picture (its pyramid taken once), its region the detail's for the context.
    codec::FrameModelOptions confirming = modelOptions;
    confirming.confirmProgress = progress.steps("confirming encode");
    const codec::FrameErrorModel picture(source, size.width, size.height, notDetail ? detail : importance, confirming);
    if (notDetail) {
        context = codec::ownDetailContext(picture, detail, ownDetailOptions(o));
        autoOptions.context = &context;
    }
    const codec::FrameErrorModel model = notDetail ? picture.withRegion(importance) : picture;
    codec::BudgetResult r = codec::buildAutoMapForFrameLoss(importance, model, o.frameLoss, autoOptions, codec::kDefaultTileLoss);
    progress.done();
    if (!quiet())
        std::printf("%s\n", describeFloorBudget(r, o.frameLoss, o.importance + " importance", encodeKept, !o.fast).c_str());
    return {std::make_unique<codec::SamplingMap>(std::move(r.map)), std::nullopt, std::move(r.encode)};
}

// The foci's map under the frame-loss budget (foci_budget.h): says, before the work, what the foci
// take and the k each got; `given` receives that k for the line that says what was written.
BuiltMap mapFromFoci(const EncodeOptions& o, const Picture& source, const Size& size, const codec::FrameModelOptions& modelOptions, bool encodeKept,
                     std::string* given) {
    codec::FociMapRequest request;
    request.options = fociMapOptions(o.grid, o.compose, o.falloff, o.maxAnisotropy);
    request.model = modelOptions;
    request.frameLoss = o.frameLoss;
    request.exactK = o.exactK;
    // Away from the foci the samples follow the picture's own detail, as with no focus at all.
    const Image detail = detailOf(source);
    request.detail = &detail;
    request.contextOptions = ownDetailOptions(o);
    Progress progress("build sampling map (" + plural(o.parsedFoci.size(), "focus", "foci") + ")");
    request.model.confirmProgress = progress.steps("confirming encode");
    codec::FociMap built = source.codes ? codec::budgetedFociMap(*source.codes, o.parsedFoci, size.width, size.height, request)
                                        : codec::budgetedFociMap(source.image, o.parsedFoci, size.width, size.height, request);
    progress.done();
    const std::string said =
        describeFociBudget(built.budget,
                           BudgetFrame{size.width, size.height, source.image.width, source.image.height, o.frameLoss,
                                       std::numeric_limits<double>::infinity(), !o.fast},
                           o.exactK, o.grid,
                           o.maxAnisotropy, encodeKept);
    if (!quiet()) std::printf("%s\n", said.c_str());
    *given = "k " + fociKText(built.budget.given);
    return {std::make_unique<codec::SamplingMap>(std::move(built.budget.map)), std::move(built.analytic), std::move(built.budget.encode)};
}

// No focus, map or importance: the samples follow the picture's own detail, with the context floor
// the model predicts gains most over the whole frame (frame_budget.h), said once per batch.
BuiltMap mapFromOwnDetail(const EncodeOptions& o, const Picture& source, const Size& size, const codec::FrameModelOptions& modelOptions, std::string* given) {
    Progress progress("build sampling map from the picture's detail");
    codec::BudgetResult r =
        source.codes ? codec::buildOwnDetailMap(*source.codes, detailOfCodes(*source.codes), size.width, size.height, ownDetailOptions(o), modelOptions)
                     : codec::buildOwnDetailMap(source.image, detailOf(source), size.width, size.height, ownDetailOptions(o), modelOptions);
    progress.done();
    static std::once_flag once;  // once per batch, not per file
    std::call_once(once, [] {
        warn("no --focus, --map or --importance: the samples follow the picture's own detail (--importance detail, "
             "the context floor chosen for the whole frame); `conus uniform` writes the uniform image");
    });
    char text[160];
    std::snprintf(text, sizeof text, "detail, context floor %.2g, predicted: the whole frame %s", r.minDensity,
                  lossText(r.predicted.frameLoss, "loses", "gains", 1).c_str());
    *given = text;
    return {std::make_unique<codec::SamplingMap>(std::move(r.map)), std::nullopt};
}

// One input to one output; returns the line that says what was written.
std::string encodeOne(const EncodeOptions& o, const std::string& input, const std::string& output) {
    checkConusOutput(output, input);
    // `--fast` without an importance file reads a plain 8-bit sRGB picture as its codes: the budget's
    // model, the detail and the CPU encoder read them, and no float copy of the picture is made.
    imageio::ImageFile source = readSource(input, o.source, o.fast && o.importance.empty());
    codec::EightBitImage codes;
    if (!source.codes.empty()) codes = {source.image.width, source.image.height, source.image.channels, std::move(source.codes)};
    const Picture picture(source.image, codes.codes.empty() ? nullptr : &codes);
    const Size size = conusSize(o.storage, source.image);
    codec::checkEncodeMemory(source.image, size.width, size.height);  // before a map is built for it
    if (!o.importance.empty() || !o.foci.empty()) checkGridForImage(o.grid, size.width, size.height);
    BuiltMap built;
    std::string given;
    // The budgets' model predicts this encode (fitted or `--fast`) on what a user sees: colour
    // through the display's curve, raw data as stored; one real encode confirms it, but under `--fast`.
    codec::FrameModelOptions modelOptions{
        source.info.encoding.transfer == Transfer::Raw ? codec::ErrorSpace::Linear : codec::ErrorSpace::Display, o.fit.count(), o.fit.hold,
        !o.fast};
    modelOptions.filter = parseEnum<codec::EncodeFilter>(o.fit.filter);
    modelOptions.fitMethod = parseEnum<codec::FitMethod>(o.fit.method);
    // Chosen first, so that the budget can say whether the file is the encode it measured.
    const renderers::Device device = deviceFor(o.storage.backend, renderers::CpuPath::Measured, "encoding", renderers::encodeSpeedProbe());
    if (!o.mapFile.empty()) built = mapFromFile(o.mapFile, source.image, size);
    else if (!o.importance.empty()) built = mapFromImportance(o, source.image, size, modelOptions, !device.onGpu());
    else if (!o.foci.empty()) built = mapFromFoci(o, picture, size, modelOptions, !device.onGpu(), &given);
    else built = mapFromOwnDetail(o, picture, size, modelOptions, &given);
    std::string fitNote;
    // The budget's confirming encode is this encode on the CPU (same kernel, same fit): kept.
    format::ConusFile file =
        built.encoded && !device.onGpu()
            ? keptEncodeToConus(*built.encoded, source.info.encoding, *built.map, source.image.width, source.image.height,
                                built.analytic, &fitNote)
        : picture.codes ? encodeToConus(device, codes, source.info.encoding, *built.map, size, built.analytic, o.fit, &fitNote)
                        : encodeToConus(device, source.image, source.info.encoding, *built.map, size, built.analytic, o.fit, &fitNote);
    applyStorage(o.storage, file);
    Progress writing("write " + output);
    format::writeConusFile(output, file);
    writing.done();
    return "wrote " + output + ": " + std::to_string(size.width) + "x" + std::to_string(size.height) + " CoNUS image of a " +
           std::to_string(source.image.width) + "x" + std::to_string(source.image.height) + " source, " +
           std::to_string(built.map->columns()) + "x" + std::to_string(built.map->rows()) + " sampling map" +
           (given.empty() ? "" : " (" + given + ")") + (fitNote.empty() ? "" : "; " + fitNote);
}

int runEncode(const EncodeOptions& given) {
    EncodeOptions o = given;  // --fast turns the fit off below
    // Usage first, before any input is read.
    if (o.frameLossGiven && o.foci.empty() && o.importance.empty())
        throw Error(ErrorCode::InvalidArgument, "--frame-loss is the budget of --focus and --importance: give one of them");
    o.parsedFoci = parseFoci(o.foci);  // the --focus text, parsed once
    if (!o.storage.sizeText.empty()) {
        const Size size = parseSize(o.storage.sizeText);
        // A map file too fine for --size: refused before any picture is read (its header says).
        if (!o.mapFile.empty()) {
            const format::ConusFile map = format::readConusHeader(o.mapFile);
            checkMapForImage("--map " + o.mapFile, map.map.columns, map.map.rows, size.width, size.height);
        }
    }
    if (o.fast) o.fit.enabled = false;
    return runConversions(o.batch, [&o](const Job& job) { return encodeOne(o, job.input, job.output); });
}


CLI::App* declareEncode(CLI::App& root, EncodeOptions& o) {
    EncodeOptions* options = &o;  // lives as long as the command (defineCommand)
    CLI::App* command = addSubcommand(root, "encode", "Encode an image (PNG, JPEG, TIFF, EXR, ...) into a CoNUS file through a sampling map",
        {"conus encode photo.jpg -o photo.exr --focus 0.42,0.31,0.08,4",
         "conus encode photo.jpg -o photo.exr --size 1024x768 --importance faces",
         "conus encode scan.tif -o scan.exr --map painted.exr --float",
         "conus encode photo.jpg -o photo.exr --focus 0.42,0.31,0.08,4 --exact-k   # k as asked, whatever the frame loses",
         "conus encode photo.jpg -o photo.exr --focus 0.42,0.31,0.08,4 --fast      # not fitted to the decoder: faster, softer",
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
    command->get_option("--min-density")->each([options](const std::string&) { options->floorGiven = true; });
    addFrameLossOption(*command, options->frameLoss,
                       "foci get the largest k (every focus's lowered alike) and importance maps the lowest context "
                       "floor whose loss stays within it")
        ->excludes("--min-density")
        ->each([options](const std::string&) { options->frameLossGiven = true; });
    addExactKOption(*command, options->exactK)->needs("--focus");
    addMaxAnisotropyOption(*command, options->maxAnisotropy);
    command->add_option("--method", options->method, "with --importance: how the map follows it")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames<codec::AutoMethod>()));
    addComposeOption(*command, options->compose);
    addFalloffOption(*command, options->falloff)->needs("--focus");  // shapes foci only
    command->add_option("--grid", options->grid, "sampling-map nodes per side for --focus and --importance (default " + std::to_string(map_rules::kDefaultSide) + ")")
        ->check(CLI::Range(kMinMapSide, kMaxMapSide));
    addFitOption(*command, options->fit, true);
    command->add_flag("--fast", options->fast, "the filtered encode alone, not fitted to the decoder: faster, softer")
        ->excludes("--fit")
        ->excludes("--fit-iterations")
        ->excludes("--fit-method")
        ->excludes("--fit-hold");
    addSourceOptions(*command, options->source);
    addStorageOptions(*command, options->storage, renderers::CpuPath::Measured);
    return command;
}

}  // namespace

Command addEncodeCommand(CLI::App& root) { return defineCommand(root, declareEncode, runEncode); }

}  // namespace conus::cli
