// conus uniform: the same pipeline with the identity map, i.e. the uniform image of the same pixel
// count: the baseline every CoNUS image is compared with.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "commands.h"
#include "encoding.h"
#include "image_files.h"
#include "output_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

struct UniformOptions {
    std::string input, output;
    SourceOptions source;
    StorageOptions storage;
    FitSetting fit;
};

int runUniform(const UniformOptions& o) {
    checkConusOutput(o.output, o.input);
    const imageio::ImageFile source = readSource(o.input, o.source);
    const Size size = conusSize(o.storage, source.image);
    const renderers::Device device = deviceFor(o.storage.backend, renderers::CpuPath::Faster, "encoding");
    std::string fitNote;
    format::ConusFile file = encodeToConus(device, source.image, source.info.encoding,
                                           codec::SamplingMap::identity(2, 2), size, std::nullopt, o.fit, &fitNote);
    applyStorage(o.storage, file);
    Progress writing("write " + o.output);
    format::writeConusFile(o.output, file);
    writing.done();
    if (!quiet())  // -q: silent on success
        std::printf("wrote %s: %dx%d uniform image of a %dx%d source%s%s\n", o.output.c_str(), size.width, size.height,
                source.image.width, source.image.height, fitNote.empty() ? "" : "; ", fitNote.c_str());
    return 0;
}

CLI::App* declareUniform(CLI::App& root, UniformOptions& options) {
    CLI::App* command = addSubcommand(root, "uniform", "Encode with the identity map: the uniform image of the same pixel count (the baseline)",
        {"conus uniform photo.jpg -o uniform.exr                 # 1/16 of the pixels, like encode's default",
         "conus uniform photo.jpg -o uniform.exr --size 512x384",
         "conus uniform photo.png -o same.exr --size 4000x3000   # at source size: an exact round trip",
         "conus uniform photo.jpg -o uniform.exr --fit           # fitted to its bilinear decode, like encode --fit"});
    command->add_option("input", options.input, "source image ('-' reads standard input)")->required();
    writesFile(command->add_option("-o,--output", options.output, "output CoNUS file (.exr)"))->required();
    addSourceOptions(*command, options.source);
    addStorageOptions(*command, options.storage);
    addFitOption(*command, options.fit);
    return command;
}

}  // namespace

Command addUniformCommand(CLI::App& root) { return defineCommand(root, declareUniform, runUniform); }

}  // namespace conus::cli
