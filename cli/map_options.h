// The options that shape a built map, shared by `map foci`, `map auto` and `encode`, and the map a
// rendered frame (`render mesh`, `render volume`) is taken through.
#pragma once

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "conus/codec/builders/auto_map.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/foci_budget.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/map_rules.h"
#include "conus/format/container.h"

namespace CLI {
class App;
class Option;
}

namespace conus::cli {

// The options that shape a built map, for `map foci`, `map auto` and `encode`: --max-anisotropy
// (0: none), and --min-density / --max-density for automatic maps.
void addMaxAnisotropyOption(CLI::App& command, double& maxAnisotropy);
void addDensityBoundOptions(CLI::App& command, double& minDensity, double& maxDensity, const std::string& prefix = "");
// The transition foci get unless --falloff says otherwise (codec::parseFalloff's text of codec::FociFalloff{}).
std::string defaultFalloffText();
// --falloff WIDTH[,SHAPE] for `map foci`, `encode --focus` and `bake relief --focus`.
CLI::Option* addFalloffOption(CLI::App& command, std::string& falloff);
// --compose: how several foci combine (format::FociComposition's names), for `map foci`, `encode`,
// `mesh` and `render volume`.
CLI::Option* addComposeOption(CLI::App& command, std::string& compose);
// "4, 3.1": the foci's k, as the budget lines say them.
std::string fociKText(const std::vector<codec::Focus>& foci);

// The builder's options from what `map auto` and `encode --importance` are given (method: an
// AutoMethod's name).
codec::AutoMapOptions autoMapOptions(int grid, double minDensity, double maxDensity, double maxAnisotropy, const std::string& method);

// --frame-loss DB (the budget foci and importance maps hold by default) and --exact-k (foci keep
// the k asked). `frameLoss` keeps its value when the option is not given; the option is returned.
CLI::Option* addFrameLossOption(CLI::App& command, double& frameLoss, const std::string& what);
CLI::Option* addExactKOption(CLI::App& command, bool& exactK);

// The CoNUS and source sizes of an encode, for what a foci budget says (none for `map foci`).
struct BudgetFrame {
    int width = 0, height = 0, sourceWidth = 0, sourceHeight = 0;
    double frameLoss = codec::kDefaultFrameLoss;
    double restLoss = std::numeric_limits<double>::infinity();  // outside the foci (finite: said)
    // false: the budget's model was never confirmed by an encode (`--fast`): its frame and tile
    // losses are printed as predicted, its foci's gain not at all (the model alone overstates it).
    bool confirmed = true;
};
// What a foci budget did, in a line: the share of the pixels the foci take, what the context is
// sampled like, the k each focus got and, when the budget lowered k, why. Warns (even when quiet)
// where --exact-k left the context sparser than the budget, and where a grid held a focus only to
// a lower k (recorded so). `encodeKept`: the file written is the budget's confirming encode (else
// a measured loss is said to be of an encode of this map).
std::string describeFociBudget(const codec::FociBudget& budget, const std::optional<BudgetFrame>& frame, bool exactK, int grid,
                               double maxAnisotropy = 0, bool encodeKept = false);

// What the budget of an importance map did, in a short block: the budget, the context floor it
// chose, the predicted losses and the region's gain (`what`: the importance's name).
std::string describeFloorBudget(const codec::BudgetResult& r, double frameLoss, const std::string& what, bool encodeKept,
                                bool confirmed = true);

// --grid against the image it shapes (codec::checkGridForImage).
void checkGridForImage(int grid, int width, int height, int defaultGrid = map_rules::kDefaultSide);
// The same bound for a map taken from a file (`option` names it, e.g. "--map m.exr"): a map of
// columns x rows nodes is refused (InvalidArgument) past map_rules::maxSideForImage, which the
// writer would hold the file to after all the work.
void checkMapForImage(const std::string& option, int columns, int rows, int width, int height);

// The foci of repeated --focus u,v,r,k options, in order.
std::vector<codec::Focus> parseFoci(const std::vector<std::string>& texts);

// The foci builder's options from --grid, --compose (a FociComposition's name), --falloff and
// --max-anisotropy (0: the builder's default), for a picture's foci (encode, bake relief).
codec::FociOptions fociMapOptions(int grid, const std::string& compose, const std::string& falloff, double maxAnisotropy = 0);

// The foci builder's options for a rendered frame of `aspect` from --grid and --compose (a FociComposition's name),
// with the r..2r ring (codec::kFormatFalloff).
codec::FociOptions frameFociOptions(int grid, const std::string& compose, double aspect);

// The sampling map of a rendered CoNUS frame, and the analytic form written beside its grid.
struct FrameMap {
    codec::SamplingMap map;
    std::optional<format::AnalyticMap> analytic;
    bool identity = false;  // --uniform, or nothing asked for: the conventional frame
};

// The foci a frame asked for, made only when they are used (empty: none were asked for).
using FociSource = std::function<std::vector<codec::Focus>()>;

// In this order: --uniform: the identity; --map FILE: that file's map (and its analytic form);
// foci: the map built from them. With none of these, the identity and a warning that names the
// options that were not given (`choices`, e.g. "--focus or --map").
FrameMap chooseFrameMap(bool uniform, const std::string& mapFile, const FociSource& foci, const codec::FociOptions& options,
                        const std::string& choices);

}  // namespace conus::cli
