// conus uniform: the same pipeline with the identity map, i.e. the uniform image of the same pixel
// count: the baseline every CoNUS image is compared with.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "commands.h"
#include "encoding.h"
#include "image_io.h"

namespace conus::cli {

Command addUniformCommand(CLI::App& root) {
    struct Options {
        std::string input, output;
        StorageOptions storage;
    };
    auto options = std::make_shared<Options>();
    CLI::App* command = root.add_subcommand(
        "uniform", "Encode with the identity map: the uniform image of the same pixel count (the baseline)");
    command->add_option("input", options->input, "source image")->required();
    command->add_option("-o,--output", options->output, "output CoNUS file (.exr)")->required();
    addStorageOptions(*command, options->storage);
    return {command, [options] {
                const format::Image source = readImage(options->input);
                const Size size = conusSize(options->storage, source);
                Renderer renderer(options->storage.backend);
                format::ConusFile file =
                    encodeToConus(renderer, source, codec::SamplingMap::identity(2, 2), size, std::nullopt);
                applyStorage(options->storage, file);
                format::writeConusFile(options->output, file);
                std::printf("wrote %s: %dx%d uniform image of a %dx%d source\n", options->output.c_str(),
                            size.width, size.height, source.width, source.height);
                return 0;
            }};
}

}  // namespace conus::cli
