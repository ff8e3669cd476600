#include "map_options.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "conus/cli/option_checks.h"
#include "conus/codec/builders/mesh_sequence.h"
#include "conus/codec/conus_file.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "progress.h"

namespace conus::cli {

codec::AutoMapOptions autoMapOptions(int grid, double minDensity, double maxDensity, double maxAnisotropy, const std::string& method) {
    codec::AutoMapOptions options;
    options.columns = options.rows = grid;
    options.minDensity = minDensity;
    options.maxDensity = maxDensity;
    options.maxAnisotropy = maxAnisotropy;
    options.method = parseEnum<codec::AutoMethod>(method);
    return options;
}

std::vector<codec::Focus> parseFoci(const std::vector<std::string>& texts) {
    std::vector<codec::Focus> foci;
    for (const auto& text : texts) foci.push_back(codec::parseFocus(text));
    return foci;
}

codec::FociOptions fociMapOptions(int grid, const std::string& compose, const std::string& falloff, double maxAnisotropy) {
    codec::FociOptions options;
    options.columns = options.rows = grid;
    options.composition = parseEnum<format::FociComposition>(compose);
    options.falloff = codec::parseFalloff(falloff);
    options.maxAnisotropy = maxAnisotropy;
    return options;
}

codec::FociOptions frameFociOptions(int grid, const std::string& compose, double aspect) {
    codec::FociOptions options;
    options.columns = options.rows = grid;
    options.aspect = aspect;
    options.composition = parseEnum<format::FociComposition>(compose);
    // The rendered frames keep the r..2r ring: the narrow default was measured on photographs
    // (bench/notes/2026-11-27-narrow-transitions.md), not on renders, whose figures are the ring's.
    options.falloff = codec::kFormatFalloff;
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
        FrameMap chosen{codec::frameMap(foci, options), std::nullopt, false};
        if (!foci.empty()) chosen.analytic = codec::toAnalytic(foci, options.composition);
        building.done();
        return chosen;
    }
    warn("no " + choices + ": rendering the uniform image of the same pixel count (what --uniform makes)");
    return {codec::SamplingMap::identity(2, 2), std::nullopt, true};
}

CLI::Option* addFrameLossOption(CLI::App& command, double& frameLoss, const std::string& what) {
    return command
        .add_option("--frame-loss", frameLoss,
                    "whole-frame loss budget in dB against the uniform image of the same pixel count, predicted "
                    "before the work from the picture's detail at every scale and the map's density: " + what + " (default " +
                    numberText(codec::kDefaultFrameLoss) + ")")
        ->check(finiteRange(0.0, 60.0, true, true));
}

CLI::Option* addExactKOption(CLI::App& command, bool& exactK) {
    return command.add_flag("--exact-k", exactK,
                            "keep every focus's k as asked, even where the foci leave the context fewer samples than the "
                            "budget allows (the budget is then only reported)");
}

std::string fociKText(const std::vector<codec::Focus>& foci) {
    std::string out;
    for (const codec::Focus& f : foci) out += (out.empty() ? "" : ", ") + numberText(std::round(f.k * 100) / 100);
    return out;
}

namespace {

std::string percent(double share) { return numberText(std::round(share * 1000) / 10) + "%"; }

std::string oneIn(double downscale) { return "1/" + numberText(std::round(downscale * 10) / 10); }

// What a budget's losses are: the measure of the encode the file keeps (the budget's confirming
// encode of the map kept), or the model's prediction (`--fast`, a picture kept as 8-bit codes).
// Whether the losses printed are measured, and whether the file written is the encode measured
// (on the GL backend, and in demo and bake, the file is another encode of the same map).
std::string saidOf(bool measured, bool kept) {
    return !measured ? "predicted" : kept ? "measured by the encode kept" : "measured by an encode of this map";
}

// The region's gain, as measured or predicted by a confirmed model; a model no encode confirmed
// (`--fast`) overstates it (bench/budget_check.py --fast: by 1.7 to 14 dB on 20 of 21
// photographs), so it is not printed then. A negative gain is printed as a loss.
std::string gainText(const char* region, const char* gains, const char* loses, double db, bool confirmed) {
    if (!confirmed) return std::string(", ") + region + "'s gain is not predicted under --fast (the model alone overstates it)";
    return std::string(", ") + region + " " + lossText(-db, loses, gains, 1);
}

}  // namespace

std::string describeFloorBudget(const codec::BudgetResult& r, double frameLoss, const std::string& what, bool encodeKept, bool confirmed) {
    char floor[32];
    std::snprintf(floor, sizeof floor, "%.3g", r.minDensity);
    // Only a measure can say so: the model's choice is within the budget by construction.
    const bool over = r.encode != nullptr && (r.predicted.frameLoss > frameLoss ||
                                              r.predicted.tileLoss > codec::kDefaultTileLoss);
    return "budget: the whole frame within " + numberText(frameLoss) + " dB and tiles outside the region within " +
           numberText(codec::kDefaultTileLoss) + " dB (95th percentile), against `conus uniform` of the same pixel count on 8-bit sRGB "
           "(--frame-loss sets it)\n  " + what + ": context floor " + floor + ", density cap " + numberText(std::round(r.maxDensity * 10) / 10) +
           (r.budgetBinds ? "" : " (the budget does not bind: the lowest floor and the highest cap hold it)") +
           "\n  " + saidOf(r.encode != nullptr, encodeKept) + ": the whole frame " + lossText(r.predicted.frameLoss, "loses", "gains", 2) + ", tiles outside the region " +
           lossText(r.predicted.tileLoss, "lose", "gain", 1) + " at the 95th percentile" +
           gainText("the region", "gains", "loses", r.predicted.roiGain, confirmed || r.encode != nullptr) +
           (over ? "\n  over the budget: no map its encodes measured held it; this one is the nearest" : "");
}

std::string describeFociBudget(const codec::FociBudget& b, const std::optional<BudgetFrame>& frame, bool exactK, int grid,
                               double maxAnisotropy, bool encodeKept) {
    std::string text;
    const auto kOf = [](double k) { return numberText(std::round(k * 100) / 100); };
    if (frame) {
        // One short block: the budget, the k each focus got, what the frame holds, how to get the k asked.
        text = "budget: the whole frame within " + numberText(frame->frameLoss) + " dB and tiles outside the foci within " +
               numberText(codec::kDefaultTileLoss) + " dB (95th percentile)" +
               (std::isfinite(frame->restLoss) ? ", outside the foci " + numberText(frame->restLoss) + " dB" : "") +
               ", against `conus uniform` of the same pixel count on 8-bit sRGB (--frame-loss sets it)";
        for (std::size_t i = 0; i < b.given.size(); ++i) {
            char line[160];
            std::snprintf(line, sizeof line, "\n  focus %zu at (%.3g, %.3g), r %.3g: k %s (asked %s)", i + 1, b.given[i].u, b.given[i].v,
                          b.given[i].r, kOf(b.given[i].k).c_str(), kOf(b.asked[i].k).c_str());
            text += line;
        }
        text += "\n  " + saidOf(b.encode != nullptr, encodeKept) + ": the whole frame " + lossText(b.predicted.frameLoss, "loses", "gains", 2) + ", tiles outside the foci " +
                lossText(b.predicted.tileLoss, "lose", "gain", 1) + " at the 95th percentile" +
                gainText("the foci", "gain", "lose", b.predicted.roiGain, frame->confirmed || b.encode != nullptr);
        if (b.lowered)
            text += "\n  k as asked: --exact-k (predicted: the whole frame " + lossText(b.askedPredicted.frameLoss, "loses", "gains", 2) +
                    ", the tiles " + lossText(b.askedPredicted.tileLoss, "lose", "gain", 1) + ")";
        const double uniform = codec::contextDownscale({0, 1, 0}, frame->width, frame->height, frame->sourceWidth, frame->sourceHeight);
        text += "\n  the foci take " + percent(b.share.share) + " of the " + std::to_string(frame->width) + "x" +
                std::to_string(frame->height) + " pixels; the context is sampled like a " +
                oneIn(codec::contextDownscale(b.share, frame->width, frame->height, frame->sourceWidth, frame->sourceHeight)) +
                " downscale (the uniform image: " + oneIn(uniform) + ")";
        if (b.overBudget)
            warn("--exact-k: against the uniform image, the whole frame " + lossText(b.predicted.frameLoss, "loses", "gains", 1) +
                 ", the tiles outside the foci " + lossText(b.predicted.tileLoss, "lose", "gain", 1) + " (" + saidOf(b.encode != nullptr, encodeKept) +
                 "; the budget: " + numberText(frame->frameLoss) + " and " + numberText(codec::kDefaultTileLoss) + " dB)");
    } else {
        if (b.askedShare.ask > 1.0)
            text = "the foci ask " + numberText(std::round(b.askedShare.ask * 10) / 10) + "x the pixels there are at k " + fociKText(b.asked) + "; ";
        if (b.lowered)
            text += "the context floor (density " + numberText(codec::kDefaultContextFloor) + ") lowered k from " + fociKText(b.asked) +
                    " to " + fociKText(b.given) + " (--exact-k keeps k); ";
        text += "foci take " + percent(b.share.share) + " of the map's samples" + (b.lowered ? "" : " at k " + fociKText(b.given));
        text += "; the context keeps density " + numberText(std::round(b.share.contextDensity * 1000) / 1000) + " (" +
                numberText(std::round(std::sqrt(b.share.contextDensity) * 100) / 100) + "x the uniform image's linear rate)";
        if (exactK && b.share.contextDensity < codec::kDefaultContextFloor)
            warn("--exact-k: the foci leave the context density " + numberText(std::round(b.share.contextDensity * 1000) / 1000) +
                 ", under the default floor " + numberText(codec::kDefaultContextFloor));
    }
    if (b.gridLimited)
        warn("the map holds the foci only to k " + fociKText(b.given) + " (asked " + fociKText(b.asked) + ") on its " +
             std::to_string(grid) + "x" + std::to_string(grid) + " grid" +
             (maxAnisotropy > 0 ? " under --max-anisotropy " + numberText(maxAnisotropy) : std::string()) +
             ": recorded so (a finer --grid or a wider focus holds more)");
    for (const std::string& note : b.builderNotes) text += "\n" + std::string(frame ? "  " : "") + note;  // what the anisotropy bound cost
    return text;
}

void addMaxAnisotropyOption(CLI::App& command, double& maxAnisotropy) {
    command.add_option("--max-anisotropy", maxAnisotropy,
                       "largest ratio of a CoNUS pixel's long to short side in the source (the Jacobian's singular "
                       "values; >= 1, default: no limit); a tight limit costs magnification")
        ->check(finiteRange(1.0, 1e6, true, true));
}

std::string defaultFalloffText() { return codec::falloffText(codec::FociFalloff{}); }

CLI::Option* addFalloffOption(CLI::App& command, std::string& falloff) {
    return command.add_option("--falloff", falloff,
                       "how a focus's density falls to the context's: WIDTH[,SHAPE], from r to WIDTH r (in (1, 8]), "
                       "SHAPE one of " + enumChoices<format::FociFalloffShape>() + " (a smoothstep of the density, of its "
                       "logarithm, of its logarithm over log radius); default " + defaultFalloffText());
}

CLI::Option* addComposeOption(CLI::App& command, std::string& compose) {
    return command.add_option("--compose", compose, "how several foci combine")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames<format::FociComposition>()));
}

void addDensityBoundOptions(CLI::App& command, double& minDensity, double& maxDensity, const std::string& prefix) {
    command.add_option("--min-density", minDensity,
                       prefix + "density every map cell keeps (0..1, default 0.25), held to 5% or refused")
        ->check(finiteRange(0.001, 0.999, true, true));
    command.add_option("--max-density", maxDensity,
                       prefix + "cap on every map cell's density (default 16: 4x the linear rate), held to 5% or refused")
        ->check(finiteRange(1.001, 4096.0, true, true));
}

void checkGridForImage(int grid, int width, int height, int defaultGrid) { codec::checkGridForImage(grid, width, height, "--grid", defaultGrid); }

void checkMapForImage(const std::string& option, int columns, int rows, int width, int height) {
    const std::int64_t most = map_rules::maxSideForImage(width, height);
    if (std::max(columns, rows) > most)
        throw Error(ErrorCode::InvalidArgument, option + ": its " + std::to_string(columns) + "x" + std::to_string(rows) +
                                                    " sampling map is finer than a " + std::to_string(width) + "x" +
                                                    std::to_string(height) + " image can show; at most " +
                                                    std::to_string(most) + " nodes a side");
}

}  // namespace conus::cli
