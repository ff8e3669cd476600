// CLI11 checks that conus and conus-view share (header-only, so the viewer includes it without
// linking the tool): finite number ranges and the --allow-dir option of the scene readers.
#pragma once

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace conus::cli {

// A number option's check: finite, above `low` (or equal to it when `lowIncluded`) and below
// `high` (or equal to it when `highIncluded`). CLI::Range and CLI::PositiveNumber let NaN through (every comparison with NaN is false);
// this does not, so a bad value is a usage error (exit 2) instead of a silent fallback.
inline CLI::Validator finiteRange(double low, double high, bool lowIncluded = false, bool highIncluded = false) {
    std::ostringstream range;
    range << (lowIncluded ? "[" : "(") << low << ", " << high << (highIncluded ? "]" : ")");
    const std::string description = "a finite number in " + range.str();
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            const bool aboveLow = lowIncluded ? value >= low : value > low;
            const bool belowHigh = highIncluded ? value <= high : value < high;
            if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(value) || !aboveLow || !belowHigh)
                return "'" + text + "' is not " + description;
            return {};
        },
        description);
}

// --allow-dir DIR (repeatable): a folder, besides a scene file's own, that the files it names
// (glTF buffers, material libraries, NRRD data files) may lie in (sceneio/named_files.h).
inline void addAllowDirOption(CLI::App& command, std::vector<std::string>& dirs) {
    command.add_option("--allow-dir", dirs,
                       "a folder the files a scene file names (buffers, material libraries, data files) may also lie in; "
                       "by default only the scene file's own folder (repeatable)")
        ->check(CLI::ExistingDirectory);
}

}  // namespace conus::cli
