// The one call from a picture and its foci to an encode's map (budgetedFociMap): the same map as the
// steps it wraps taken by hand, the analytic form the file records, and the budget's findings as
// data (overBudget) for the callers to word.
#include "conus/codec/builders/foci_budget.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "conus/codec/builders/importance.h"
#include "../../test_images.h"

namespace conus::codec {
namespace {

constexpr int kWidth = 240, kHeight = 160;
// The model alone, no confirming encode: what is compared is the flow, not the encodes.
const FrameModelOptions kModel{ErrorSpace::Display, 0, kFitHoldLowPass, false};

// Noise on the left two thirds, flat on the right: the picture's own detail is not uniform.
Image picture() {
    Image im = test::noise(kWidth, kHeight, {"R", "G", "B"}, 5);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 2 * kWidth / 3; x < kWidth; ++x)
            for (int c = 0; c < 3; ++c) im.at(x, y, c) = 0.4f;
    return im;
}

void expectSameMap(const SamplingMap& a, const SamplingMap& b) {
    ASSERT_EQ(a.columns(), b.columns());
    ASSERT_EQ(a.rows(), b.rows());
    EXPECT_EQ(a.nodes(), b.nodes());
}

// On the picture's own detail: the map, the k given and the predictions are those of the steps
// `encode --focus` took by hand (one model of the picture, its context, the foci's region at 256).
TEST(BudgetedFociMap, IsTheFlowOnThePicturesOwnDetail) {
    const Image source = picture();
    const std::vector<Focus> foci{{0.3, 0.55, 0.09, 5.0}, {0.8, 0.3, 0.06, 3.0}};
    const Image detail = detailImportance(source);
    FociMapRequest request;
    request.model = kModel;
    request.detail = &detail;
    const FociMap built = budgetedFociMap(source, foci, kWidth / 4, kHeight / 4, request);

    const double aspect = double(kWidth) / kHeight;
    const FrameErrorModel own(source, kWidth / 4, kHeight / 4, detail, kModel);
    const DensityField context = ownDetailContext(own, detail, {});
    FociOptions options;
    options.aspect = aspect;
    options.context = &context;
    const FrameErrorModel model = own.withRegion(fociImportance(foci, aspect, 256, 170));
    const FociBudget byHand = fociForFrameLoss(foci, options, model);
    expectSameMap(built.budget.map, byHand.map);
    ASSERT_EQ(built.budget.given.size(), 2u);
    for (int i = 0; i < 2; ++i) EXPECT_EQ(built.budget.given[i].k, byHand.given[i].k);
    EXPECT_EQ(built.budget.predicted.frameLoss, byHand.predicted.frameLoss);
    EXPECT_FALSE(built.budget.overBudget);
    // The analytic form: the foci as given (k lowered or not), density composition, the falloff held.
    EXPECT_TRUE(built.analytic.is(format::MapKind::Foci));
    ASSERT_EQ(built.analytic.foci.size(), 2u);
    EXPECT_EQ(built.analytic.foci[1].u, 0.8);
    EXPECT_EQ(built.analytic.foci[0].k, built.budget.given[0].k);
    EXPECT_EQ(built.analytic.composition, enumName(FociComposition::Density));
}

// Without the detail the foci sit on a uniform context (`bake relief`), with the rest-loss budget.
TEST(BudgetedFociMap, WithoutTheDetailTheContextIsUniform) {
    const Image source = picture();
    const std::vector<Focus> foci{{0.45, 0.5, 0.1, 6.0}};
    FociMapRequest request;
    request.model = kModel;
    request.restLoss = 0.6;
    request.options.columns = request.options.rows = 33;
    const FociMap built = budgetedFociMap(source, foci, kWidth / 4, kHeight / 4, request);
    const double aspect = double(kWidth) / kHeight;
    FociOptions options;
    options.aspect = aspect;
    options.columns = options.rows = 33;
    const FrameErrorModel model(source, kWidth / 4, kHeight / 4, fociImportance(foci, aspect, 256, 170), kModel);
    const FociBudget byHand = fociForFrameLoss(foci, options, model, kDefaultFrameLoss, false, kDefaultTileLoss, 0.6);
    expectSameMap(built.budget.map, byHand.map);
    EXPECT_EQ(built.budget.given[0].k, byHand.given[0].k);
}

// k kept as asked past what the budget holds: the finding says so (the callers' warning); the
// budget's own choice holds it and says nothing.
TEST(BudgetedFociMap, AnExactKPastTheBudgetIsAFinding) {
    const Image source = picture();
    const std::vector<Focus> foci{{0.83, 0.5, 0.15, 5.0}};  // on the flat part, 2.6x the samples there are
    FociMapRequest request;
    request.model = kModel;
    request.frameLoss = 0.1;  // a tight budget: the focus as asked costs the frame more
    request.exactK = true;
    const FociMap exact = budgetedFociMap(source, foci, kWidth / 4, kHeight / 4, request);
    EXPECT_EQ(exact.budget.given[0].k, 5.0);
    EXPECT_TRUE(exact.budget.predicted.frameLoss > 0.1 || exact.budget.predicted.tileLoss > kDefaultTileLoss)
        << exact.budget.predicted.frameLoss << " " << exact.budget.predicted.tileLoss;
    EXPECT_TRUE(exact.budget.overBudget);
    request.exactK = false;
    const FociMap held = budgetedFociMap(source, foci, kWidth / 4, kHeight / 4, request);
    EXPECT_LT(held.budget.given[0].k, 5.0);
    EXPECT_LE(held.budget.predicted.frameLoss, 0.1 + 0.01);
    EXPECT_FALSE(held.budget.overBudget);
}

}  // namespace
}  // namespace conus::codec
