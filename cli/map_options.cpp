#include "map_options.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <string>

#include "conus/core/error.h"
#include "conus/core/map_rules.h"

#include "conus/renderers/mesh_sequence.h"
#include "progress.h"

namespace conus::cli {

codec::AutoMapOptions autoMapOptions(int grid, double minDensity, double maxDensity, double maxAnisotropy, const std::string& method) {
    codec::AutoMapOptions options;
    options.columns = options.rows = grid;
    options.minDensity = minDensity;
    options.maxDensity = maxDensity;
    options.maxAnisotropy = maxAnisotropy;
    options.method = method == "separable" ? codec::AutoMethod::Separable : codec::AutoMethod::Flow;
    return options;
}

std::vector<codec::Focus> parseFoci(const std::vector<std::string>& texts) {
    std::vector<codec::Focus> foci;
    for (const auto& text : texts) foci.push_back(codec::parseFocus(text));
    return foci;
}

codec::FociOptions frameFociOptions(int grid, const std::string& compose, double aspect) {
    codec::FociOptions options;
    options.columns = options.rows = grid;
    options.aspect = aspect;
    options.composition = compose == "add" ? codec::FociComposition::Add : codec::FociComposition::Density;
    return options;
}

FrameMap chooseFrameMap(bool uniform, const std::string& mapFile, const FociSource& fociSource,
                        const codec::FociOptions& options, const std::string& choices) {
    if (uniform) return {codec::SamplingMap::identity(2, 2), std::nullopt, true};
    if (!mapFile.empty()) {
        const format::ConusFile source = format::readConusFile(mapFile);
        return {codec::SamplingMap::fromGrid(source.map), source.analytic, false};
    }
    if (fociSource) {
        const std::vector<codec::Focus> foci = fociSource();
        Progress building("build sampling map (" + plural(foci.size(), "focus", "foci") + ")");
        FrameMap chosen{gl::frameMap(foci, options), std::nullopt, false};
        if (!foci.empty()) chosen.analytic = codec::toAnalytic(foci, options.composition);
        building.done();
        return chosen;
    }
    warn("no " + choices + ": rendering the uniform image of the same pixel count (what --uniform makes)");
    return {codec::SamplingMap::identity(2, 2), std::nullopt, true};
}

void addMaxAnisotropyOption(CLI::App& command, double& maxAnisotropy) {
    command.add_option("--max-anisotropy", maxAnisotropy,
                       "largest ratio of a CoNUS pixel's long to short side in the source (the Jacobian's singular "
                       "values; >= 1, default: no limit); a tight limit costs magnification")
        ->check(CLI::Range(1.0, 1e6));
}

CLI::Option* addFalloffOption(CLI::App& command, std::string& falloff) {
    return command.add_option("--falloff", falloff,
                       "how a focus's density falls to the context's: WIDTH[,SHAPE], from r to WIDTH r (in (1, 8]), "
                       "SHAPE density (smoothstep of the density, the default) | log (of its logarithm) | logr (of its "
                       "logarithm over log radius); default 2,density");
}

void addDensityBoundOptions(CLI::App& command, double& minDensity, double& maxDensity, const std::string& prefix) {
    command.add_option("--min-density", minDensity,
                       prefix + "density every map cell keeps (0..1, default 0.25), held to 5% or refused")
        ->check(CLI::Range(0.001, 0.999));
    command.add_option("--max-density", maxDensity,
                       prefix + "cap on every map cell's density (default 16: 4x the linear rate), held to 5% or refused")
        ->check(CLI::Range(1.001, 4096.0));
}

void checkGridForImage(int grid, int width, int height, int defaultGrid) {
    const int most = std::max(defaultGrid, 4 * std::max(width, height) + 1);
    if (grid > most)
        throw Error(ErrorCode::InvalidArgument, "--grid " + std::to_string(grid) + " is finer than a " + std::to_string(width) +
                                                    "x" + std::to_string(height) + " image can show; at most " +
                                                    std::to_string(most) + " nodes a side");
}

}  // namespace conus::cli
