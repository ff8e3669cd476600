// CLI11 checks that conus and conus-view share (header-only, so the viewer includes it without
// linking the tool): finite number ranges, the --allow-dir option of the scene readers, and the
// line that names an unknown option with the one it most likely misspells.
#pragma once

#include <algorithm>
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

// Edits (insertions, deletions, substitutions, swaps of neighbours) that turn `a` into `b`.
inline std::size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i)
        for (std::size_t j = 1; j <= b.size(); ++j) {
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1])});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}

// For CLI11's "argument was not expected": the first argument of argv that looks like an option
// and that neither `command` nor a command above it takes, as "unknown option --foccus", with
// "; did you mean --focus?" when one of their options is within two edits of it. Empty when no
// such argument (an extra positional value): CLI11's own words say it then.
inline std::string unknownOptionLine(const CLI::App* command, int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        const std::string argument = argv[i];
        if (argument == "--") break;
        if (argument.size() < 2 || argument[0] != '-' || std::isdigit(static_cast<unsigned char>(argument[1])) || argument[1] == '.')
            continue;  // a value ("-" is standard input; "-0.5" a number)
        const std::string name = argument.substr(0, argument.find('='));
        bool known = false;
        for (const CLI::App* c = command; c && !known; c = c->get_parent()) known = c->get_option_no_throw(name) != nullptr;
        if (known || (name.size() > 2 && name[1] != '-')) continue;  // known, or short flags run together ("-qv")
        std::string best;
        std::size_t bestDistance = 3;  // at most two edits
        for (const CLI::App* c = command; c; c = c->get_parent())
            for (const CLI::Option* option : c->get_options()) {
                std::vector<std::string> names;
                for (const std::string& l : option->get_lnames()) names.push_back("--" + l);
                for (const std::string& s : option->get_snames()) names.push_back("-" + s);
                for (const std::string& candidate : names)
                    if (const std::size_t d = editDistance(name, candidate); d < bestDistance && d < candidate.size() / 2)
                        bestDistance = d, best = candidate;
            }
        return "unknown option " + name + (best.empty() ? "" : "; did you mean " + best + "?");
    }
    return {};
}

}  // namespace conus::cli
