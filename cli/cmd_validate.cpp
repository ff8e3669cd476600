// conus validate: every violated rule of spec/conus-format.md, exit 0 only for a valid file.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "commands.h"
#include "conus/core/atomic_file.h"
#include "conus/format/container.h"
#include "conus/format/reflection_asset.h"
#include "progress.h"

namespace conus::cli {

Command addValidateCommand(CLI::App& root) {
    auto input = std::make_shared<std::string>();
    auto headersOnly = std::make_shared<bool>(false);
    CLI::App* command = root.add_subcommand(
        "validate", "Check a file against every rule of the CoNUS spec; exit 0 only if valid");
    command->add_option("input", *input, "file to check")->required();
    command->add_flag("--headers-only", *headersOnly,
                      "check headers, the map and the chunk tables without decompressing the pixel data (faster; a "
                      "file this passes may still fail to decode)");
    addQuietOption(*command);
    setExamples(*command, {"conus validate photo.exr            # exit 0: valid; 1: every broken rule listed, one a line",
                       "conus validate photo.exr >/dev/null && echo ok",
                       "conus validate asset.exr            # a reflection asset: each face, then the cube's frame"});
    return {command, [input, headersOnly] {
                checkInputPath(*input, false);  // "no such file", not a broken rule
                const format::ValidationReport report = format::validateConusFile(*input, {}, !*headersOnly);
                if (report.ok()) {
                    if (!quiet())
                        std::printf("%s: valid CoNUS %s (format version %d)\n", input->c_str(),
                                    format::isReflectionAsset(*input) ? "reflection asset, six faces" : "file", format::kFormatVersion);
                    return 0;
                }
                for (const auto& issue : report.issues)
                    std::printf("%s: %s: %s\n", input->c_str(), format::label(issue.rule).c_str(), issue.message.c_str());
                const long long problems = report.problemCount();
                std::fprintf(stderr, "conus validate: %s: not a valid CoNUS file (%lld problem%s)\n", input->c_str(),
                             problems, problems == 1 ? "" : "s");
                return 1;
            }};
}

}  // namespace conus::cli
