// conus encode: a conventional image -> a CoNUS file, through foci, a map file, or the identity.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "commands.h"
#include "conus/codec/auto_map.h"
#include "conus/codec/foci.h"
#include "encoding.h"
#include "image_io.h"
#include "importance.h"
#include "progress.h"

namespace conus::cli {

Command addEncodeCommand(CLI::App& root) {
    struct Options {
        std::string input, output, mapFile, compose = "density", importance, method = "flow";
        double minDensity = 0.25, maxDensity = 16;
        std::vector<std::string> foci;
        int grid = 65;
        StorageOptions storage;
    };
    auto options = std::make_shared<Options>();
    CLI::App* command = root.add_subcommand(
        "encode", "Encode an image (PNG, JPEG, TIFF, EXR, ...) into a CoNUS file through a sampling map");
    command->add_option("input", options->input, "source image")->required();
    command->add_option("-o,--output", options->output, "output CoNUS file (.exr)")->required();
    command->add_option("--focus", options->foci,
                        "focus u,v,r,k: centre (u,v) in [0,1], radius r as a fraction of the width, linear "
                        "magnification k (repeat for several foci)");
    command->add_option("--map", options->mapFile, "take the sampling map from this CoNUS file")->excludes("--focus");
    command->add_option("--importance,--auto", options->importance,
                        "build the map automatically from importance: an image file (higher = more samples), "
                        "'detail' (the image's own edges) or 'faces' (faces found in it)")
        ->excludes("--focus")
        ->excludes("--map");
    command->add_option("--min-density", options->minDensity,
                        "with --importance: sampling density kept everywhere (0..1, default 0.25)")
        ->check(CLI::Range(0.001, 0.999));
    command->add_option("--max-density", options->maxDensity,
                        "with --importance: cap on the density (default 16, i.e. 4x the linear rate)")
        ->check(CLI::Range(1.001, 4096.0));
    command->add_option("--method", options->method, "with --importance: flow (default) | separable")
        ->check(CLI::IsMember({"flow", "separable"}));
    command->add_option("--compose", options->compose, "how several foci combine: density (default) | add")
        ->check(CLI::IsMember({"density", "add"}));
    command->add_option("--grid", options->grid, "sampling-map nodes per side for --focus and --importance (default 65)")
        ->check(CLI::Range(2, 1025));
    addStorageOptions(*command, options->storage);

    return {command, [options] {
                const format::Image source = readImage(options->input);
                const Size size = conusSize(options->storage, source);
                std::optional<format::AnalyticMap> analytic;
                std::unique_ptr<codec::SamplingMap> map;
                if (!options->mapFile.empty()) {
                    const format::ConusFile mapSource = format::readConusFile(options->mapFile);
                    map = std::make_unique<codec::SamplingMap>(codec::SamplingMap::fromGrid(mapSource.map));
                    analytic = mapSource.analytic;
                } else if (!options->importance.empty()) {
                    Progress progress("build sampling map from " + options->importance + " importance");
                    codec::AutoMapOptions autoOptions;
                    autoOptions.columns = autoOptions.rows = options->grid;
                    autoOptions.minDensity = options->minDensity;
                    autoOptions.maxDensity = options->maxDensity;
                    autoOptions.method =
                        options->method == "separable" ? codec::AutoMethod::Separable : codec::AutoMethod::Flow;
                    map = std::make_unique<codec::SamplingMap>(
                        codec::buildAutoMap(importanceFrom(options->importance, source), autoOptions));
                    progress.done();
                } else if (!options->foci.empty()) {
                    std::vector<codec::Focus> foci;
                    format::AnalyticMap params{"foci", {}, options->compose, {}};
                    for (const auto& text : options->foci) {
                        foci.push_back(codec::parseFocus(text));
                        params.foci.push_back({foci.back().u, foci.back().v, foci.back().r, foci.back().k});
                    }
                    codec::FociOptions fo;
                    fo.columns = fo.rows = options->grid;
                    fo.aspect = double(source.width) / source.height;
                    fo.composition = options->compose == "add" ? codec::FociComposition::Add
                                                               : codec::FociComposition::Density;
                    Progress progress("build sampling map (" + std::to_string(foci.size()) + " foci)");
                    map = std::make_unique<codec::SamplingMap>(codec::buildFociMap(foci, fo));
                    codec::checkFociHeld(*map, foci, fo);  // the file must not record a focus its map ignores
                    progress.done();
                    analytic = params;
                } else {
                    map = std::make_unique<codec::SamplingMap>(codec::SamplingMap::identity(2, 2));
                }
                Renderer renderer(options->storage.backend);
                format::ConusFile file = encodeToConus(renderer, source, *map, size, analytic);
                applyStorage(options->storage, file);
                format::writeConusFile(options->output, file);
                std::printf("wrote %s: %dx%d CoNUS image of a %dx%d source, %dx%d sampling map\n",
                            options->output.c_str(), size.width, size.height, source.width, source.height,
                            map->columns(), map->rows());
                return 0;
            }};
}

}  // namespace conus::cli
