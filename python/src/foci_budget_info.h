// What encode(foci=...)'s budget did (codec/builders/foci_budget.h), as File.budget shows it, and the
// warning it gives. Included by module.cpp only.
#pragma once

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <vector>

#include "conus/codec/builders/foci_budget.h"
#include "conus/core/error.h"
#include "arguments.h"

namespace conus::python {

// The dict of File.budget; warns (UserWarning) when k was lowered, when exact_k left the frame
// losing more than the budget (FociBudget::overBudget), and when the grid held a focus only to a lower k.
// `confirmed`: the budget's model was confirmed by an encode (fit > 0); the model alone (fit=0, as
// `--fast`) overstates the foci's gain, whose predicted_roi_gain is then None, as the CLI does not
// print it.
inline pybind11::dict budgetInfo(const codec::FociBudget& b, double frameLoss, int w, int h, int sourceW, int sourceH, bool confirmed) {
    std::vector<double> asked, given;
    for (const codec::Focus& f : b.asked) asked.push_back(f.k);
    for (const codec::Focus& f : b.given) given.push_back(f.k);
    pybind11::dict d;
    d["k_asked"] = asked;
    d["k_given"] = given;
    d["lowered"] = b.lowered;
    d["grid_limited"] = b.gridLimited;
    d["builder_notes"] = b.builderNotes;  // what the anisotropy bound cost (a transition widened, a grid refined)
    d["frame_loss"] = frameLoss;
    d["predicted_frame_loss"] = b.predicted.frameLoss;
    const bool measured = confirmed || b.encode != nullptr;
    d["confirmed"] = measured;
    d["predicted_roi_gain"] = measured ? pybind11::object(pybind11::float_(b.predicted.roiGain)) : pybind11::none();
    d["predicted_tile_loss"] = b.predicted.tileLoss;
    // What k as asked would hold (exact_k=True), predicted the same way.
    d["predicted_frame_loss_exact_k"] = b.askedPredicted.frameLoss;
    d["predicted_tile_loss_exact_k"] = b.askedPredicted.tileLoss;
    d["tile_loss"] = codec::kDefaultTileLoss;
    d["foci_share"] = b.share.share;
    d["ask"] = b.askedShare.ask;
    d["context_downscale"] = codec::contextDownscale(b.share, w, h, sourceW, sourceH);
    d["uniform_downscale"] = codec::contextDownscale({0, 1, 0}, w, h, sourceW, sourceH);
    const auto list = [](const std::vector<double>& k) {
        std::string out;
        for (double v : k) out += (out.empty() ? "" : ", ") + numberText(std::round(v * 100) / 100);
        return out;
    };
    std::string warning;
    if (b.lowered)
        warning = "conus.encode: the loss budget (whole frame " + numberText(frameLoss) + " dB, tiles " + numberText(codec::kDefaultTileLoss) +
                  " dB) lowered k from " + list(asked) + " to " +
                  list(given) + " (exact_k=True keeps k: predicted, the whole frame then " +
                  lossText(b.askedPredicted.frameLoss, "loses", "gains", 2) + ", the tiles " +
                  lossText(b.askedPredicted.tileLoss, "lose", "gain", 1) + ")";
    else if (b.overBudget)
        warning = std::string("conus.encode: exact_k: ") + (measured ? "measured by an encode" : "predicted") +
                  " against the uniform image, the whole frame " + lossText(b.predicted.frameLoss, "loses", "gains", 1) +
                  ", the tiles outside the foci " + lossText(b.predicted.tileLoss, "lose", "gain", 1) + " (the budget: " +
                  numberText(frameLoss) + " and " + numberText(codec::kDefaultTileLoss) + " dB)";
    if (b.gridLimited) warning += (warning.empty() ? "conus.encode: " : "; ") + std::string("the grid holds the foci only to k ") + list(given);
    if (!warning.empty()) warn(warning);
    return d;
}



}  // namespace conus::python
