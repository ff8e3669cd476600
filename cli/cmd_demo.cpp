// conus demo: the main job on a built-in input. Encodes a 4096^2 picture with two foci at 1/16 of
// its pixels, decodes zoomed views of each focus and the whole frame, writes PNGs side by side with
// the uniform image of the same pixel count, and prints the PSNR of every view for both.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "commands.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/builders/auto_map.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/foci_budget.h"
#include "conus/codec/builders/frame_budget.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/image/metrics.h"
#include "conus/codec/map/pictures.h"
#include "conus/core/atomic_file.h"
#include "conus/renderers/gpu_image.h"
#include "demo_picture.h"
#include "encoding.h"
#include "conus/imageio/image_file.h"
#include "image_files.h"
#include "map_options.h"
#include "conus/cli/option_checks.h"
#include "progress.h"

namespace conus::cli {
namespace {

struct DemoOptions {
    std::string out = "demo-out", input, importance, backend = enumName(renderers::Backend::Auto);
    std::vector<std::string> foci;
    int size = 4096;
    double k = 4;
};

// The picture the demo runs on, what it was, and the foci whose views it compares.
struct DemoSource {
    Image image;
    SourceEncoding encoding;
    std::vector<codec::Focus> foci;
};

DemoSource demoSource(const DemoOptions& o) {
    DemoSource s;
    if (!o.input.empty()) {
        imageio::ImageFile file = readSource(o.input, {});
        s.image = std::move(file.image);
        s.encoding = file.info.encoding;
        s.foci = parseFoci(o.foci);
        if (s.foci.empty()) s.foci.push_back({0.5, 0.5, 0.1, o.k});
        return s;
    }
    Progress picture("build the " + std::to_string(o.size) + "x" + std::to_string(o.size) + " demo picture");
    s.image = makeDemoPicture(o.size);
    // Drawn as an 8-bit sRGB picture would hold it; CoNUS works in linear light.
    imageio::linearize(s.image);
    s.encoding.transfer = Transfer::Srgb;
    s.encoding.sampleType = SampleType::Uint8;
    s.encoding.chromaticities = kRec709Chromaticities;
    picture.done();
    s.foci = {{0.28, 0.30, 0.07, o.k}, {0.70, 0.66, 0.07, o.k}};
    return s;
}

struct DemoMap {
    std::optional<codec::SamplingMap> map;
    std::optional<format::AnalyticMap> analytic;
};

// The demo encodes without the fit, and so do its budget's trials.
const codec::FrameModelOptions kDemoTrials{codec::ErrorSpace::Display, 0};

// From importance (its hottest region becomes the view when no focus names one), else the foci;
// under encode's default frame-loss budget, so the demo shows what `conus encode` gives.
DemoMap demoMap(const DemoOptions& o, DemoSource& source, const Size& size) {
    Progress building("build the sampling map");
    DemoMap m;
    const int w = source.image.width, h = source.image.height;
    std::string said;
    if (!o.importance.empty()) {
        const Image importance = importanceFrom(o.importance, source.image);
        const codec::FrameErrorModel model(source.image, size.width, size.height, importance, kDemoTrials);
        m.map = codec::buildAutoMapForFrameLoss(importance, model, codec::kDefaultFrameLoss, {}, codec::kDefaultTileLoss).map;
        if (o.foci.empty()) source.foci = {codec::hottestRegion(importance, w, h)};
    } else {
        // As `encode`: away from the foci the samples follow the picture's own detail.
        codec::FociMapRequest request;
        request.model = kDemoTrials;
        const Image detail = importanceFrom(enumName(codec::ImportanceRule::Detail), source.image);
        request.detail = &detail;
        codec::FociMap built = codec::budgetedFociMap(source.image, source.foci, size.width, size.height, request);
        said = describeFociBudget(built.budget, BudgetFrame{size.width, size.height, w, h}, false, request.options.columns);
        source.foci = built.budget.given;
        m.map = std::move(built.budget.map);
        m.analytic = std::move(built.analytic);
    }
    building.done();
    if (!said.empty() && !quiet()) std::printf("%s\n", said.c_str());
    return m;
}

struct ViewCase {
    std::string name, label;
    int x0, y0, width, height;  // source pixels
    int outWidth, outHeight;    // size of the picture written
};

// A view of each focus (its disc's bounding square, r a fraction of the width, kept inside the
// image) at source resolution, then the whole frame shrunk to at most `shrink`.
std::vector<ViewCase> demoViews(const DemoOptions& o, const std::vector<codec::Focus>& foci, int w, int h, double shrink) {
    std::vector<ViewCase> views;
    for (std::size_t i = 0; i < foci.size(); ++i) {
        const int half = std::max(1, static_cast<int>(std::lround(foci[i].r * w)));
        const int x0 = std::clamp(static_cast<int>(std::lround(foci[i].u * w)) - half, 0, std::max(0, w - 2 * half));
        const int y0 = std::clamp(static_cast<int>(std::lround(foci[i].v * h)) - half, 0, std::max(0, h - 2 * half));
        const int vw = std::min(w, 2 * half), vh = std::min(h, 2 * half);
        std::string label = "focus " + std::to_string(i + 1);
        if (o.input.empty()) label += i == 0 ? " (fine print)" : " (zone plate)";
        views.push_back({"focus" + std::to_string(i + 1), label, x0, y0, vw, vh, vw, vh});
    }
    views.push_back({"frame", "whole frame", 0, 0, w, h, std::max(1, int(w * shrink)), std::max(1, int(h * shrink))});
    return views;
}

// What one view gave: the PSNR of each file's decode against the source, and the picture of the
// three side by side.
struct ViewResult {
    double conus = 0, uniform = 0;
    Image strip;  // source | CoNUS | uniform
};

void writeConusStage(const std::string& path, const format::ConusFile& file) {
    Progress writing("write " + path);
    format::writeConusFile(path, file);
    writing.done();
}

int runDemo(const DemoOptions& o) {
    namespace fs = std::filesystem;
    const fs::path out(o.out);
    // Before any work: none of the files it always writes replaces the --input picture.
    for (const char* name : {"conus.exr", "uniform.exr", "source.png", "conus.png", "uniform.png", "density.png"})
        checkNotAnInput((out / name).string());
    AtomicOutputs outputs;  // everything the demo writes, or nothing
    outputs.makeFolder(o.out);
    DemoSource source = demoSource(o);
    const int w = source.image.width, h = source.image.height;
    const auto [conusWidth, conusHeight] = codec::defaultConusSize(w, h);  // 1/16 of the pixels
    const Size size{conusWidth, conusHeight};
    const DemoMap built = demoMap(o, source, size);
    const codec::SamplingMap& map = *built.map;

    const renderers::Device device = deviceFor(o.backend, renderers::CpuPath::Faster, "the demo");
    const codec::SamplingMap identity = codec::SamplingMap::identity(2, 2);
    const format::ConusFile conus =
        encodeToConus(device, source.image, source.encoding, map, size, built.analytic, {}, nullptr, "the CoNUS image");
    const format::ConusFile uniform = encodeToConus(device, source.image, source.encoding, identity, size, std::nullopt, {},
                                                    nullptr, "the uniform image (the identity map)");
    writeConusStage((out / "conus.exr").string(), conus);
    writeConusStage((out / "uniform.exr").string(), uniform);
    imageio::WriteOptions picture;
    picture.source = &source.encoding;
    if (o.input.empty()) writePicture((out / "source.png").string(), source.image, picture);  // to try the other commands on
    writePicture((out / "conus.png").string(), conus.image, picture);
    writePicture((out / "uniform.png").string(), uniform.image, picture);
    const double shrink = std::min(1.0, 1024.0 / std::max(w, h));
    const int pw = std::max(16, int(w * shrink)), ph = std::max(16, int(h * shrink));
    writeDrawing((out / "density.png").string(), codec::densityPicture(map, pw, ph, 32, built.analytic ? &*built.analytic : nullptr));

    const std::vector<ViewCase> views = demoViews(o, source.foci, w, h, shrink);
    std::vector<ViewResult> results;
    Progress comparing("decode " + plural(views.size(), "view", "views") + " from both files, PSNR against the source");
    for (const auto& v : views) {
        codec::DecodeOptions decode;
        decode.view = {double(v.x0) / w, double(v.y0) / h, double(v.x0 + v.width) / w, double(v.y0 + v.height) / h};
        decode.width = v.width;
        decode.height = v.height;
        const Image reference = codec::crop(source.image, v.x0, v.y0, v.width, v.height);
        const Image fromConus = renderers::decodeImage(device, conus.image, map, decode);
        const Image fromUniform = renderers::decodeImage(device, uniform.image, identity, decode);
        std::vector<Image> strip{reference, fromConus, fromUniform};
        if (v.outWidth != v.width)
            for (auto& image : strip) image = codec::areaDownsample(image, v.outWidth, v.outHeight);
        results.push_back({codec::psnr(reference, fromConus), codec::psnr(reference, fromUniform), codec::sideBySide(strip)});
    }
    comparing.done();
    for (std::size_t i = 0; i < views.size(); ++i)
        writePicture((out / ("view-" + views[i].name + ".png")).string(), results[i].strip, picture);
    outputs.commit();

    std::printf("\nCoNUS demo: %dx%d %s -> %dx%d (1/16 of the pixels), ", w, h,
                o.input.empty() ? "built-in picture" : o.input.c_str(), size.width, size.height);
    if (!o.importance.empty()) std::printf("map from '%s' importance", o.importance.c_str());
    else std::printf("%s", plural(source.foci.size(), "focus", "foci").c_str());
    for (const auto& f : source.foci) std::printf(" (%g,%g,r=%g,k=%g)", f.u, f.v, f.r, f.k);
    std::printf("\nuniform: the same %dx%d pixels spread evenly (the identity map, as `conus uniform` makes it)\n"
                "renderer: %s\n",
                size.width, size.height, device.describe().c_str());
    std::printf("%-22s %12s %14s %8s\n", "view", "CoNUS PSNR", "uniform PSNR", "gain");
    for (std::size_t i = 0; i < views.size(); ++i)
        std::printf("%-22s %9.2f dB %11.2f dB %+7.2f\n", views[i].label.c_str(), results[i].conus, results[i].uniform,
                    results[i].conus - results[i].uniform);
    std::string written;
    for (const auto& v : views) written += ", view-" + v.name + ".png";
    std::printf("\nwrote %s/: %sconus.exr, uniform.exr, conus.png, uniform.png, density.png%s\n"
                "  (each view-*.png: source | CoNUS | uniform)\n",
                o.out.c_str(), o.input.empty() ? "source.png, " : "", written.c_str());
    return 0;
}

CLI::App* declareDemo(CLI::App& root, DemoOptions& options) {
    CLI::App* command = addSubcommand(root, "demo", "The main job on a built-in picture: CoNUS vs uniform at 1/16 of the pixels, with PSNR",
        {"conus demo                                   # the built-in 4096x4096 picture, two foci",
         "conus demo --input photo.jpg --focus 0.42,0.31,0.08,4 --out my-demo",
         "conus demo --input portrait.jpg --importance faces"});
    command->add_option("--out", options.out, "folder for the pictures and files (default demo-out)");
    command->add_option("--size", options.size, "side of the built-in picture (default 4096)")
        ->check(CLI::Range(256, 8192));
    command->add_option("--k", options.k, "magnification of both foci (default 4)")->check(finiteRange(1.0, 8.0, true, true));
    command->add_option("--input", options.input,
                        "run the same comparison on your own picture instead of the built-in one");
    command->add_option("--focus", options.foci, "with --input: focus u,v,r,k (repeatable; default: the centre)");
    command->add_option("--importance", options.importance,
                        "with --input: build the map automatically from importance (a file, 'detail' or 'faces') "
                        "instead of foci; --focus then only names the views to compare");
    addBackendOption(*command, options.backend, renderers::CpuPath::Faster);
    return command;
}

}  // namespace

Command addDemoCommand(CLI::App& root) { return defineCommand(root, declareDemo, runDemo); }

}  // namespace conus::cli
