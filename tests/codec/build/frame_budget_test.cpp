// The frame-loss budget: its trial encodes against what an encode and decode measure, and a tighter
// budget giving a smaller measured loss.
#include "conus/codec/build/frame_budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/core/error.h"
#include "../../test_images.h"

namespace conus::codec {
namespace {

constexpr int kWidth = 384, kHeight = 256;

// Detail everywhere, finer on the right than on the left, and a few slanted waves: a frame whose
// context loses something at every floor, asymmetric so that a transposed map cannot pass.
Image picture() {
    const Image n = test::noise(kWidth, kHeight, {"R", "G", "B"}, 7);
    Image im = makeImage(kWidth, kHeight, {"R", "G", "B"});
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const int radius = x < kWidth / 3 ? 2 : 1;
            for (int c = 0; c < 3; ++c) {
                double sum = 0;
                int count = 0;
                for (int j = -radius; j <= radius; ++j)
                    for (int i = -radius; i <= radius; ++i, ++count)
                        sum += n.pixels[(std::size_t(std::clamp(y + j, 0, kHeight - 1)) * kWidth + std::clamp(x + i, 0, kWidth - 1)) * 3 + c];
                const double wave = 0.5 + 0.5 * std::sin(0.21 * x + 0.13 * y + c);
                im.pixels[(std::size_t(y) * kWidth + x) * 3 + c] = static_cast<float>(0.6 * sum / count + 0.4 * wave);
            }
        }
    return im;
}

// 1 on two boxes (the regions of interest), 0 elsewhere.
Image boxes() {
    Image im = makeImage(96, 64, {"Y"});
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 96; ++x) {
            const bool a = x >= 20 && x < 32 && y >= 14 && y < 26, b = x >= 62 && x < 70 && y >= 38 && y < 50;
            im.at(x, y) = (a || b) ? 1.0f : 0.0f;
        }
    return im;
}

double mse(const Image& a, const Image& b, const Image& importance, bool roiOnly) {
    double sum = 0;
    std::size_t count = 0;
    const std::size_t channels = a.channels.size();
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            if (roiOnly && importance.at(x * importance.width / a.width, y * importance.height / a.height) < 0.5f) continue;
            for (std::size_t c = 0; c < channels; ++c) {
                const double d = a.pixels[(std::size_t(y) * a.width + x) * channels + c] - b.pixels[(std::size_t(y) * a.width + x) * channels + c];
                sum += d * d;
            }
            ++count;
        }
    return sum / double(count * channels);
}

struct Measured {
    double frameLoss, roiGain;
};

// Encode to 1/16 of the pixels through `map`, decode at the source size; against the uniform image
// of the same pixel count (area downsample, bilinear up).
Measured measure(const Image& source, const SamplingMap& map, const Image& importance) {
    const int w = kWidth / 4, h = kHeight / 4;
    EncodeOptions e;
    e.width = w;
    e.height = h;
    DecodeOptions d;
    d.width = kWidth;
    d.height = kHeight;
    const Image view = decodeImage(encodeImage(source, map, e), map, d);
    const Image uniform = resizeBilinear(areaDownsample(source, w, h), {}, kWidth, kHeight);
    return {10 * std::log10(mse(view, source, importance, false) / mse(uniform, source, importance, false)),
            10 * std::log10(mse(uniform, source, importance, true) / mse(view, source, importance, true))};
}

// The trial of the identity map is the uniform image but for the encoder's filter: about no loss
// and no gain; fitted to the decoder (as `encode` does by default) it gains over the whole frame.
TEST(FrameBudget, IdentityPredictsAboutNoLossAndTheFitGains) {
    const Image source = picture();
    const FrameErrorModel plain(source, kWidth / 4, kHeight / 4, boxes(), {ErrorSpace::Display, 0});
    const FramePrediction p = plain.predict(SamplingMap::identity(9, 9));
    EXPECT_NEAR(p.frameLoss, 0.0, 0.5);
    EXPECT_NEAR(p.roiGain, 0.0, 0.5);
    EXPECT_NEAR(p.tileLoss, 0.0, 1.0);
    const FrameErrorModel fitted(source, kWidth / 4, kHeight / 4, boxes());
    const FramePrediction f = fitted.predict(SamplingMap::identity(9, 9));
    EXPECT_LT(f.frameLoss, p.frameLoss - 0.5);
    EXPECT_GT(f.roiGain, p.roiGain + 0.5);
}

// A map that magnifies the boxes: the trial's figures are those of the real encode and decode at
// the source's size (the picture is under the trial's 1024 px, so nothing is reduced), in linear
// light without the fit, as measure() takes them.
TEST(FrameBudget, TrialIsTheEncodeAndDecode) {
    const Image source = picture(), importance = boxes();
    AutoMapOptions options;
    options.maxDensity = 16;
    options.minDensity = 0.4;
    const SamplingMap map = buildAutoMap(importance, options);
    const FrameErrorModel model(source, kWidth / 4, kHeight / 4, importance, {ErrorSpace::Linear, 0});
    const FramePrediction p = model.predict(map);
    const Measured m = measure(source, map, importance);
    EXPECT_GT(m.roiGain, 1.0);  // the map does magnify them
    EXPECT_GT(m.frameLoss, 0.5);  // and the frame pays
    EXPECT_NEAR(p.frameLoss, m.frameLoss, 0.1);  // only the floor f differs
    EXPECT_NEAR(p.roiGain, m.roiGain, 1e-3);
}

TEST(FrameBudget, TighterBudgetGivesSmallerMeasuredLoss) {
    const Image source = picture(), importance = boxes();
    const FrameErrorModel model(source, kWidth / 4, kHeight / 4, importance, {ErrorSpace::Linear, 0});  // as measure() takes them
    AutoMapOptions options;
    options.maxDensity = 36;
    std::vector<Measured> measured;
    std::vector<double> floors;
    for (double budget : {0.5, 1.5, 3.0}) {
        SCOPED_TRACE(budget);
        const BudgetResult r = buildAutoMapForFrameLoss(importance, model, budget, options);
        // The floor is chosen on the target density; the built map predicts near the budget.
        EXPECT_TRUE(r.budgetBinds);
        EXPECT_LE(r.predicted.frameLoss, budget + 0.5);
        EXPECT_GT(r.predicted.roiGain, 0.0);
        measured.push_back(measure(source, r.map, importance));
        floors.push_back(r.minDensity);
        // The prediction is the real encode and decode (a trial of it): only the floor f differs.
        EXPECT_NEAR(measured.back().frameLoss, r.predicted.frameLoss, 0.1);
        EXPECT_NEAR(measured.back().roiGain, r.predicted.roiGain, 1e-3);
        std::printf("budget %.1f dB: floor %.3f, predicted loss %.2f gain %+.2f, measured loss %.2f gain %+.2f\n", budget,
                    r.minDensity, r.predicted.frameLoss, r.predicted.roiGain, measured.back().frameLoss,
                    measured.back().roiGain);
    }
    for (std::size_t i = 1; i < measured.size(); ++i) {
        EXPECT_LT(floors[i], floors[i - 1]);
        EXPECT_LT(measured[i - 1].frameLoss, measured[i].frameLoss);  // tighter: smaller loss
        EXPECT_LT(measured[i - 1].roiGain, measured[i].roiGain);      // and less gain
    }
    EXPECT_GT(measured.front().roiGain, 0.0);
}

TEST(FrameBudget, RejectsBadInput) {
    const Image source = picture();
    EXPECT_THROW(FrameErrorModel(Image{}, 4, 4, Image{}), Error);
    EXPECT_THROW(FrameErrorModel(source, kWidth + 1, 4, Image{}), Error);
    const FrameErrorModel model(source, kWidth / 4, kHeight / 4, Image{});
    EXPECT_THROW(buildAutoMapForFrameLoss(boxes(), model, -1.0), Error);
    EXPECT_THROW(buildAutoMapForFrameLoss(boxes(), model, std::nan("")), Error);
}

}  // namespace
}  // namespace conus::codec
