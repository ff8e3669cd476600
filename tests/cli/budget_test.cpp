// What `conus encode` and `conus map foci` say about the pixel budget and the k each focus got,
// through the real binary: the line before the work, the k the file records, --exact-k, and the
// documented option combinations that once refused a grid as too coarse.
#include <algorithm>
#include <cmath>
#include <regex>
#include <utility>

#include <OpenImageIO/imagebuf.h>

#include "cli/cli_fixture.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"

namespace conus::test {
namespace {

using BudgetCli = Cli;

// The k of each focus the file records (conus:foci), read back by the format library.
std::vector<double> recordedK(const std::string& file) {
    const format::ConusFile f = format::readConusFile(file);
    std::vector<double> k;
    if (f.analytic)
        for (const auto& focus : f.analytic->foci) k.push_back(focus.k);
    return k;
}

// The numbers after `prefix` in `text` ("k 2.6, 2.6" -> {2.6, 2.6}).
std::vector<double> numbersAfter(const std::string& text, const std::string& prefix) {
    const std::size_t at = text.find(prefix);
    std::vector<double> out;
    if (at == std::string::npos) return out;
    const std::string rest = text.substr(at + prefix.size());
    const std::regex number(R"(^\s*,?\s*([0-9]+(\.[0-9]+)?))");
    std::smatch m;
    std::string tail = rest;
    while (std::regex_search(tail, m, number)) {
        out.push_back(std::stod(m[1]));
        tail = m.suffix();
    }
    return out;
}

// The k each focus got and the k asked, from the block `encode` prints ("focus 1 at (...): k 2.6 (asked 4)").
std::vector<std::pair<double, double>> printedK(const std::string& text) {
    const std::regex line(R"(focus [0-9]+ at \([^)]*\), r [0-9.e-]+: k ([0-9.]+) \(asked ([0-9.]+)\))");
    std::vector<std::pair<double, double>> out;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), line); it != std::sregex_iterator(); ++it)
        out.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
    return out;
}

// A printed loss: "loses 1.50 dB" as 1.5, "gains 0.44 dB" as -0.44, after `subject` ("the whole frame").
double printedLoss(const std::string& text, const std::string& subject) {
    const std::regex loss(subject + R"( (loses|gains|lose|gain) ([0-9.]+) dB)");
    std::smatch m;
    if (!std::regex_search(text, m, loss)) return std::nan("");
    return (m[1].str().rfind("gain", 0) == 0 ? -1.0 : 1.0) * std::stod(m[2]);
}

TEST_F(BudgetCli, TwoLargeFociAreLoweredAndSaySo) {
    const std::string picture = makePicture(360, 240);
    const std::string foci = " --focus 0.3,0.4,0.16,4 --focus 0.7,0.55,0.15,4 --size 90x60";
    const Result r = run("encode " + picture + foci + " -o " + path("held.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    // Before the work, on stdout: the budget, the k each focus got and was asked, what the frame
    // holds, how to get the k asked and what it costs, what the foci take.
    EXPECT_NE(r.out.find("budget: the whole frame within 1.5 dB and tiles outside the foci within 4 dB"), std::string::npos) << r.out;
    const std::vector<std::pair<double, double>> k = printedK(r.out);
    ASSERT_EQ(k.size(), 2u) << r.out;
    EXPECT_EQ(k[0].second, 4.0);
    EXPECT_GT(k[0].first, 1.0);
    EXPECT_LT(k[0].first, 4.0);
    EXPECT_NEAR(std::log(k[0].first), std::log(k[1].first), 0.02);  // every k lowered alike
    const double frame = printedLoss(r.out, ": the whole frame");
    EXPECT_LE(frame, 1.5 + 0.005) << r.out;
    EXPECT_LE(printedLoss(r.out, "tiles outside the foci"), 4.0 + 0.05) << r.out;
    EXPECT_NE(r.out.find("k as asked: --exact-k (predicted: the whole frame "), std::string::npos) << r.out;
    const double asked = printedLoss(r.out.substr(r.out.find("k as asked")), "the whole frame");
    EXPECT_GT(asked, frame) << r.out;
    EXPECT_NE(r.out.find("of the 90x60 pixels"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("the context is sampled like a 1/"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("(the uniform image: 1/4)"), std::string::npos) << r.out;
    // The file records the k printed, which the 'wrote' line repeats.
    const std::vector<double> recorded = recordedK(path("held.exr"));
    ASSERT_EQ(recorded.size(), 2u);
    EXPECT_NEAR(recorded[0], k[0].first, 0.006);
    EXPECT_NEAR(recorded[1], k[1].first, 0.006);
    EXPECT_NE(r.out.find("sampling map (k "), std::string::npos) << r.out;

    // --exact-k keeps k as asked and warns what the frame pays for it, as the block said it would.
    const Result exact = run("encode " + picture + foci + " --exact-k -o " + path("exact.exr"));
    ASSERT_EQ(exact.exitCode, 0) << exact.err;
    EXPECT_EQ(recordedK(path("exact.exr")), (std::vector<double>{4.0, 4.0}));
    EXPECT_EQ(exact.out.find("k as asked"), std::string::npos) << exact.out;
    // (Each run confirms its model by an encode of the map it chose: the --exact-k run on this very map.)
    EXPECT_NEAR(printedLoss(exact.out, ": the whole frame"), asked, 0.3) << exact.out;
    EXPECT_NE(exact.err.find("warning: --exact-k: against the uniform image, the whole frame "), std::string::npos) << exact.err;

    // A tighter whole-frame budget holds, as predicted, by lowering k.
    ASSERT_EQ(run("encode " + picture + foci + " --fast -o " + path("fast.exr")).exitCode, 0);
    const Result tight = run("encode " + picture + foci + " --fast --frame-loss 0.1 -o " + path("tight.exr"));
    ASSERT_EQ(tight.exitCode, 0) << tight.err;
    EXPECT_NE(tight.out.find("budget: the whole frame within 0.1 dB"), std::string::npos) << tight.out;
    EXPECT_LE(printedLoss(tight.out, ": the whole frame"), 0.1 + 0.005) << tight.out;
    EXPECT_LT(recordedK(path("tight.exr"))[0], 4.0 - 0.05);
    // The model alone (no encode confirms it under --fast) predicts the losses and says so; the
    // foci's gain, which it overstates, is not printed. With an encode to confirm it, it is.
    EXPECT_NE(tight.out.find("\n  predicted: the whole frame"), std::string::npos) << tight.out;
    EXPECT_NE(tight.out.find("the foci's gain is not predicted under --fast"), std::string::npos) << tight.out;
    EXPECT_EQ(tight.out.find("the foci gain "), std::string::npos) << tight.out;
    EXPECT_NE(r.out.find(" at the 95th percentile, the foci gain "), std::string::npos) << r.out;
}

// The 8-bit codes of a PNG, read by OpenImageIO.
std::vector<unsigned char> codesOf(const std::string& file, int width, int height) {
    const OIIO::ImageBuf image(file);
    std::vector<unsigned char> codes(std::size_t(width) * height * 3);
    EXPECT_TRUE(image.get_pixels(OIIO::ROI(0, width, 0, height, 0, 1, 0, 3), OIIO::TypeDesc::UINT8, codes.data()));
    return codes;
}

// What the block says the frame loses is the file's own loss, measured by someone else's reader:
// the encode and `conus uniform` of the same pixel count, each decoded to an 8-bit PNG at the
// source's size and read by OpenImageIO, their PSNR against the source's codes differ by what was
// printed (a focus the budget lowered: the file is the budget's measured encode).
TEST_F(BudgetCli, ThePrintedFrameLossIsTheFilesOwn) {
    const std::string picture = makePicture(360, 240);
    const Result r = run("encode " + picture + " --focus 0.3,0.4,0.16,4 --focus 0.7,0.55,0.15,4 --size 90x60 -o " + path("c.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    ASSERT_NE(r.out.find("measured by the encode kept: the whole frame "), std::string::npos) << r.out;
    ASSERT_EQ(run("uniform " + picture + " --size 90x60 -q -o " + path("u.exr")).exitCode, 0);
    for (const char* name : {"c", "u"})
        ASSERT_EQ(run(std::string("decode ") + path(std::string(name) + ".exr") + " --size 360x240 -q -o " + path(std::string(name) + ".png")).exitCode, 0);
    const std::vector<unsigned char> s = codesOf(picture, 360, 240), c = codesOf(path("c.png"), 360, 240), u = codesOf(path("u.png"), 360, 240);
    double ec = 0, eu = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        ec += (double(c[i]) - s[i]) * (double(c[i]) - s[i]);
        eu += (double(u[i]) - s[i]) * (double(u[i]) - s[i]);
    }
    const double measured = 10 * std::log10(ec / eu), printed = printedLoss(r.out, ": the whole frame");
    std::printf("frame loss printed %.2f dB, the files' PNGs %.3f dB\n", printed, measured);
    EXPECT_GT(std::abs(measured), 0.05);  // the map does change the frame's error
    EXPECT_NEAR(printed, measured, 0.05) << r.out;
}

TEST_F(BudgetCli, ASmallFocusKeepsItsK) {
    const std::string picture = makePicture(320, 240);
    const Result r = run("encode " + picture + " --focus 0.62,0.35,0.05,3 --size 80x60 --frame-loss 6 -o " + path("a.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out.find("k as asked"), std::string::npos) << r.out;
    EXPECT_EQ(printedK(r.out), (std::vector<std::pair<double, double>>{{3.0, 3.0}})) << r.out;
    EXPECT_NE(r.out.find("the foci take "), std::string::npos) << r.out;
    EXPECT_EQ(recordedK(path("a.exr")), std::vector<double>{3.0});
    // --exact-k is about foci only.
    EXPECT_EQ(run("encode " + picture + " --exact-k -o " + path("b.exr")).exitCode, 2);
    EXPECT_FALSE(fs::exists(path("b.exr")));
}

// --frame-loss is the budget of the detail map too: a looser one spends more on the detail (a lower
// context floor, or where the lowest floor holds the budget, a higher density cap), the prediction
// printed follows it, and the files differ.
TEST_F(BudgetCli, FrameLossSetsTheDetailMap) {
    const std::string picture = makePicture(320, 240);
    const Result tight = run("encode " + picture + " --importance detail --size 80x60 --frame-loss 0.2 -o " + path("t.exr"));
    const Result loose = run("encode " + picture + " --importance detail --size 80x60 --frame-loss 3 -o " + path("l.exr"));
    ASSERT_EQ(tight.exitCode, 0) << tight.err;
    ASSERT_EQ(loose.exitCode, 0) << loose.err;
    const auto floorAndCap = [](const std::string& text) {
        const std::vector<double> floor = numbersAfter(text, "context floor "), cap = numbersAfter(text, "density cap ");
        return std::make_pair(floor.empty() ? std::nan("") : floor[0], cap.empty() ? std::nan("") : cap[0]);
    };
    const auto [floorTight, capTight] = floorAndCap(tight.out);
    const auto [floorLoose, capLoose] = floorAndCap(loose.out);
    ASSERT_TRUE(std::isfinite(floorTight) && std::isfinite(capTight)) << tight.out;
    ASSERT_TRUE(std::isfinite(floorLoose) && std::isfinite(capLoose)) << loose.out;
    const double tightLoss = printedLoss(tight.out, ": the whole frame"), looseLoss = printedLoss(loose.out, ": the whole frame");
    EXPECT_LE(tightLoss, 0.2 + 0.005) << tight.out;
    EXPECT_LE(looseLoss, 3 + 0.005) << loose.out;
    // Where the budget binds, the looser one spends more on the detail; where even the lowest floor
    // and the highest cap hold it (a detail map that gains over the whole frame), the block says so.
    const bool binds = tight.out.find("does not bind") == std::string::npos;
    if (binds) {
        EXPECT_TRUE(floorLoose < floorTight - 0.01 || capLoose > capTight * 1.05) << tight.out << loose.out;
        EXPECT_GT(looseLoss, tightLoss + 0.3) << loose.out;
        EXPECT_NE(format::readConusFile(path("t.exr")).map.xy, format::readConusFile(path("l.exr")).map.xy);
    } else {
        EXPECT_NE(loose.out.find("does not bind"), std::string::npos) << loose.out;
        EXPECT_EQ(capTight, 256.0) << tight.out;
    }
}

// A region the map does worse on than the uniform image (a flat stretch of a smooth ramp, which the
// uniform image keeps as well as any, while the region's own map spends the fit elsewhere) is said
// to lose, never to "gain -3.9 dB".
TEST_F(BudgetCli, ARegionThatLosesIsSaidToLose) {
    const int w = 240, h = 160;
    const auto write = [&](const std::string& name, int channels, const std::vector<unsigned char>& pixels) {
        auto output = OIIO::ImageOutput::create(path(name));
        EXPECT_TRUE(output->open(path(name), OIIO::ImageSpec(w, h, channels, OIIO::TypeDesc::UINT8)));
        EXPECT_TRUE(output->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
        output->close();
        return path(name);
    };
    std::vector<unsigned char> ramp(std::size_t(w) * h * 3), roi(std::size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool red = x < 36 && y < 24;  // a red patch in the top-left corner
            const double rgb[3] = {red ? 1.0 : 0.1, red ? 0.0 : double(x) / (w - 1), red ? 0.0 : 0.2 + 0.1 * std::sin(y / 7.0)};
            for (int c = 0; c < 3; ++c) ramp[(std::size_t(y) * w + x) * 3 + c] = static_cast<unsigned char>(255 * std::pow(rgb[c], 1 / 2.2));
            roi[std::size_t(y) * w + x] = (y >= h / 4 && y < h / 2 && x >= w / 2 && x < 3 * w / 4) ? 255 : 0;
        }
    const Result r = run("encode " + write("ramp.png", 3, ramp) + " --importance " + write("roi.png", 1, roi) +
                         " --frame-loss 0.1 -o " + path("ramp.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("measured by the encode kept"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("the region loses "), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("gains -"), std::string::npos) << r.out;
    EXPECT_GT(printedLoss(r.out, "the region"), 0.5) << r.out;
}

TEST_F(BudgetCli, MapFociKeepsTheContextFloor) {
    // No picture: the context keeps at least a quarter of the uniform density.
    const std::string foci = " --focus 0.25,0.3,0.2,5 --focus 0.7,0.7,0.18,3";
    const Result r = run("map foci" + foci + " -o " + path("m.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("the context floor (density 0.25) lowered k from 5, 3 to "), std::string::npos) << r.out;
    const std::vector<double> k = recordedK(path("m.exr"));
    ASSERT_EQ(k.size(), 2u);
    EXPECT_LT(k[0], 5.0);
    EXPECT_LT(k[1], 3.0);
    EXPECT_NEAR(std::log(k[0]) / std::log(5.0), std::log(k[1]) / std::log(3.0), 0.01);  // the same power of each
    const std::vector<double> density = numbersAfter(r.out, "the context keeps density ");
    ASSERT_FALSE(density.empty()) << r.out;
    EXPECT_GE(density[0], 0.25);
    const Result exact = run("map foci" + foci + " --exact-k -o " + path("e.exr"));
    ASSERT_EQ(exact.exitCode, 0) << exact.err;
    EXPECT_EQ(recordedK(path("e.exr")), (std::vector<double>{5.0, 3.0}));
    EXPECT_NE(exact.err.find("under the default floor 0.25"), std::string::npos) << exact.err;
    // What the anisotropy bound cost the k = 5 focus is said, with numbers.
    EXPECT_NE(exact.out.find("focus 0.25,0.3,0.2,5: transition widened from 1.25 to "), std::string::npos) << exact.out;
    // And the file records the transition the map holds (the widest said), not the one asked.
    double widest = 0;
    for (std::size_t at = exact.out.find("transition widened from 1.25 to "); at != std::string::npos;
         at = exact.out.find("transition widened from 1.25 to ", at + 1))
        widest = std::max(widest, numbersAfter(exact.out.substr(at), "transition widened from 1.25 to ").at(0));
    const format::ConusFile e = format::readConusFile(path("e.exr"));
    ASSERT_TRUE(e.analytic);
    ASSERT_TRUE(e.analytic->scalars.count("falloffWidth")) << exact.out;
    EXPECT_NEAR(e.analytic->scalars.at("falloffWidth"), widest, 0.01) << exact.out;
}

TEST_F(BudgetCli, DocumentedCombinationsAreNotRefused) {
    // Each of these once ended in "grid too coarse" or an anisotropy refusal; now each encodes and
    // says what gave way.
    const std::string picture = makePicture(384, 256);
    const std::vector<std::string> combinations = {
        "--focus 0.55,0.62,0.08,4 --focus 0.72,0.31,0.05,4 --fit --falloff 1.75",
        "--focus 0.55,0.62,0.08,4 --focus 0.72,0.31,0.05,4 --falloff 1.5 --exact-k",
        "--focus 0.4,0.4,0.07,4 --max-anisotropy 4",
        "--focus 0.4,0.4,0.07,4 --max-anisotropy 8 --exact-k",
        "--focus 0.5,0.5,0.1,4 --grid 3",
        "--focus 0.1,0.9,0.06,6 --focus 0.92,0.08,0.05,6 --compose add",
    };
    int i = 0;
    for (const std::string& options : combinations) {
        const std::string out = path("c" + std::to_string(i++) + ".exr");
        const Result r = run("encode " + picture + " " + options + " --size 96x64 -o " + out);
        EXPECT_EQ(r.exitCode, 0) << options << ": " << r.err;
        EXPECT_TRUE(fs::exists(out)) << options;
        EXPECT_NE(r.out.find("foci take "), std::string::npos) << options << ": " << r.out;
    }
    // A grid too coarse to hold a focus is refined until it does, and the file records that k.
    const Result coarse = run("map foci --focus 0.5,0.5,0.1,4 --grid 2 -o " + path("g.exr"));
    ASSERT_EQ(coarse.exitCode, 0) << coarse.err;
    const std::vector<double> k = recordedK(path("g.exr"));
    ASSERT_EQ(k.size(), 1u);
    EXPECT_GT(k[0], 3.0);
}

// A textured picture, finer on the right than on the left (noise of two grain sizes over slanted
// waves) and flat in the bottom band: detail where a map can take samples from.
std::string texturedPicture(const std::string& file, int width, int height) {
    std::vector<unsigned char> pixels(static_cast<std::size_t>(width) * height * 3);
    unsigned state = 12345;
    const auto noise = [&state] {
        state = state * 1664525u + 1013904223u;
        return (state >> 8) / double(1u << 24);
    };
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c) {
                const bool flat = y > height * 3 / 4;
                const double wave = 0.5 + 0.3 * std::sin(0.3 * x + 0.2 * y + c) * (x > width / 2 ? 1.0 : 0.3);
                const double v = flat ? 0.4 + 0.1 * c : wave + (x > width / 2 ? 0.25 : 0.05) * (noise() - 0.5);
                pixels[(std::size_t(y) * width + x) * 3 + c] = static_cast<unsigned char>(std::clamp(v, 0.0, 1.0) * 255);
            }
    auto output = OIIO::ImageOutput::create(file);
    EXPECT_TRUE(output->open(file, OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::UINT8)));
    EXPECT_TRUE(output->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
    output->close();
    return file;
}

TEST_F(BudgetCli, NoFocusFollowsTheDetailAndBeatsUniform) {
    const std::string a = texturedPicture(path("a.png"), 320, 240), b = texturedPicture(path("b.png"), 240, 320);
    // A batch of two: the note about the default is said once, not per file.
    const Result batch = run("encode " + a + " " + b + " --out-dir " + path("out"));
    ASSERT_EQ(batch.exitCode, 0) << batch.err;
    std::size_t count = 0;
    for (std::size_t at = batch.err.find("no --focus"); at != std::string::npos; at = batch.err.find("no --focus", at + 1)) ++count;
    EXPECT_EQ(count, 1u) << batch.err;
    EXPECT_NE(batch.err.find("the samples follow the picture's own detail"), std::string::npos) << batch.err;
    ASSERT_EQ(run("uniform " + a + " -o " + path("u.exr")).exitCode, 0);
    // Against `conus uniform`, both decoded at the source's size to 8-bit PNGs (what a user looks at).
    ASSERT_EQ(run("decode " + path("out/a.exr") + " -o " + path("c.png") + " --backend cpu").exitCode, 0);
    ASSERT_EQ(run("decode " + path("u.exr") + " -o " + path("uv.png") + " --backend cpu").exitCode, 0);
    const ExrRead source = readExr(a), conus = readExr(path("c.png")), uniform = readExr(path("uv.png"));
    ASSERT_EQ(conus.width, 320);
    const auto psnr = [&source](const ExrRead& view) {
        double se = 0;
        std::size_t n = 0;
        for (const char* c : {"R", "G", "B"})
            for (std::size_t p = 0; p < source.channels.at(c).size(); ++p, ++n) se += std::pow(view.channels.at(c)[p] - source.channels.at(c)[p], 2);
        return 10.0 * std::log10(1.0 / std::max(se / double(n), 1e-12));
    };
    EXPECT_GT(psnr(conus), psnr(uniform) + 0.5) << "detail " << psnr(conus) << " dB, uniform " << psnr(uniform) << " dB";
    // The map is not the identity: it holds more samples on the fine right half than the flat band.
    const auto map = codec::SamplingMap::fromGrid(format::readConusFile(path("out/a.exr")).map);
    EXPECT_GT(map.density({0.75, 0.3}), 1.2 * map.density({0.25, 0.9}));
}

// The budget's confirming encode of the map it keeps is the file's encode (not made a second time):
// the file `encode --focus` writes holds the same pixels, read back by OIIO, as an encode through
// that file's own map (`--map`, no budget: a fresh encode and fit), and both say the same fit.
TEST_F(BudgetCli, TheConfirmingEncodeIsTheFilesEncode) {
    const std::string picture = texturedPicture(path("t.png"), 320, 240);
    for (const std::string k : {"", " --exact-k"}) {
        SCOPED_TRACE(k);
        const Result held = run("encode " + picture + " --focus 0.62,0.4,0.13,3" + k + " --size 80x60 --float -o " + path("held.exr"));
        ASSERT_EQ(held.exitCode, 0) << held.err;
        const Result again = run("encode " + picture + " --map " + path("held.exr") + " --size 80x60 --float -o " + path("again.exr"));
        ASSERT_EQ(again.exitCode, 0) << again.err;
        const ExrRead a = readExr(path("held.exr")), b = readExr(path("again.exr"));
        ASSERT_EQ(a.width, 80);
        ASSERT_EQ(b.width, 80);
        double worst = 0;
        for (const char* c : {"R", "G", "B"})
            for (std::size_t p = 0; p < a.channels.at(c).size(); ++p)
                worst = std::max(worst, double(std::abs(a.channels.at(c)[p] - b.channels.at(c)[p])));
        EXPECT_LT(worst, 1e-4);  // the map read back from the file is the map kept, to float precision
        const auto fitted = [](const std::string& text) { return numbersAfter(text, "decoded PSNR"); };
        ASSERT_FALSE(fitted(held.out + held.err).empty()) << held.out << held.err;
        ASSERT_FALSE(fitted(again.out + again.err).empty()) << again.out << again.err;
        EXPECT_NEAR(fitted(held.out + held.err)[0], fitted(again.out + again.err)[0], 0.01);
        EXPECT_NEAR(fitted(held.out + held.err).back(), fitted(again.out + again.err).back(), 0.01);
    }
}

}  // namespace
}  // namespace conus::test
