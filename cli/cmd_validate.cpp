// conus validate: every violated rule of spec/conus-format.md, exit 0 only for a valid file.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>

#include "commands.h"
#include "conus/core/atomic_file.h"
#include "conus/format/container.h"
#include "conus/format/reflection_asset.h"
#include "progress.h"

namespace conus::cli {

namespace {

struct ValidateOptions {
    std::string input;
    bool headersOnly = false;
};

CLI::App* declareValidate(CLI::App& root, ValidateOptions& o) {
    CLI::App* command = addSubcommand(root, "validate", "Check a file against every rule of the CoNUS spec; exit 0 only if valid",
                                      {"conus validate photo.exr            # exit 0: valid; 1: every broken rule listed, one a line",
                                       "conus validate photo.exr >/dev/null && echo ok",
                                       "conus validate asset.exr            # a reflection asset: each face, then the cube's frame"});
    command->add_option("input", o.input, "file to check")->required();
    command->add_flag("--headers-only", o.headersOnly,
                      "check headers, the map and the chunk tables without decompressing the pixel data (faster; a "
                      "file this passes may still fail to decode)");
    return command;
}

int runValidate(const ValidateOptions& o) {
    checkInputPath(o.input, false);  // "no such file", not a broken rule
    const format::ValidationReport report = format::validateConusFile(o.input, {}, !o.headersOnly);
    if (report.ok()) {
        if (!quiet())
            std::printf("%s: valid CoNUS %s (format version %d)\n", o.input.c_str(),
                        format::isReflectionAsset(o.input) ? "reflection asset, six faces" : "file", format::kFormatVersion);
        return 0;
    }
    for (const auto& issue : report.issues)
        std::printf("%s: %s: %s\n", o.input.c_str(), format::label(issue.rule).c_str(), issue.message.c_str());
    const long long problems = report.problemCount();
    std::fprintf(stderr, "conus validate: %s: not a valid CoNUS file (%lld problem%s)\n", o.input.c_str(), problems,
                 problems == 1 ? "" : "s");
    return 1;
}

}  // namespace

Command addValidateCommand(CLI::App& root) { return defineCommand(root, declareValidate, runValidate); }

}  // namespace conus::cli
