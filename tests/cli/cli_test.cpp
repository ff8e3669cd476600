// The `conus` command as a user runs it: exit codes, messages and outputs, through the real binary.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/metrics.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/map_measures.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"
#include "cli_fixture.h"

namespace fs = std::filesystem;

using namespace conus::test;

namespace {

TEST_F(Cli, NoArgumentsIsAnErrorWithUsage) {
    const Result r = run("");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("conus"), std::string::npos) << r.err;
}

TEST_F(Cli, HelpListsEverySubcommand) {
    const Result r = run("--help");
    EXPECT_EQ(r.exitCode, 0);
    for (const char* name : {"encode", "decode", "uniform", "info", "validate", "demo"})
        EXPECT_NE(r.out.find(name), std::string::npos) << name;
}

TEST_F(Cli, EncodeWithFociThenValidateInfoDecode) {
    const std::string in = makePicture(400, 300);
    // --exact-k: the file records the foci as given (the budget's own k: budget_test.cpp).
    Result r = run("encode " + in + " -o " + path("a.exr") + " --size 100x75 --focus 0.3,0.4,0.1,4 --focus 0.7,0.6,0.08,3 --exact-k");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("100x75"), std::string::npos) << r.out;

    r = run("validate " + path("a.exr"));
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("valid CoNUS file"), std::string::npos);

    r = run("info " + path("a.exr") + " --json --density " + path("density.png"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["image"]["width"], 100);
    EXPECT_EQ(j["image"]["height"], 75);
    EXPECT_EQ(j["source"]["width"], 400);
    EXPECT_EQ(j["analyticMap"]["kind"], "foci");
    ASSERT_EQ(j["analyticMap"]["foci"].size(), 2u);
    EXPECT_NEAR(j["analyticMap"]["foci"][0]["k"].get<double>(), 4.0, 1e-6);
    // Two foci magnify: the map is not uniform.
    EXPECT_GT(j["samplingMap"]["densityMax"].get<double>(), 2.0 * j["samplingMap"]["densityMin"].get<double>());
    EXPECT_EQ(imageSize(path("density.png")).first, 400);

    r = run("decode " + path("a.exr") + " -o " + path("frame.png"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(imageSize(path("frame.png")), std::make_pair(400, 300));

    r = run("decode " + path("a.exr") + " -o " + path("zoom.png") + " --view 0.2,0.3,0.4,0.5 --size 320x240");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(imageSize(path("zoom.png")), std::make_pair(320, 240));

    r = run("decode " + path("a.exr") + " -o " + path("zoom2.exr") + " --view 0.2,0.3,0.4,0.5");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(imageSize(path("zoom2.exr")), std::make_pair(80, 60));  // the view at source resolution
    EXPECT_TRUE(leftovers().empty());
}

// A zoomed-out view goes through the image's pyramid (one trilinear tap per pixel), a magnified
// one through the plain bilinear tap: the same floats as the codec's decoder each way.
TEST_F(Cli, DecodeTakesThePyramidForAZoomedOutView) {
    const std::string in = makePicture(320, 240);
    ASSERT_EQ(run("encode " + in + " -o " + path("a.exr") + " --size 160x120 --focus 0.4,0.5,0.12,4 --float").exitCode, 0);
    const auto file = conus::format::readConusFile(path("a.exr"));
    const auto map = conus::codec::SamplingMap::fromGrid(file.map);
    const conus::codec::ImagePyramid pyramid = conus::codec::buildPyramid(file.image);
    const auto decoded = [&](const std::string& name) {
        const ExrRead r = readExr(path(name));
        std::vector<float> values;
        for (std::size_t p = 0; p < static_cast<std::size_t>(r.width) * r.height; ++p)
            for (const std::string& c : file.image.channels) values.push_back(r.channels.at(c).at(p));
        return values;
    };
    const auto maxDifference = [](const std::vector<float>& a, const std::vector<float>& b) {
        float worst = a.size() == b.size() ? 0.0f : INFINITY;
        for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
        return worst;
    };
    conus::codec::DecodeOptions o;
    o.width = 80;
    o.height = 60;
    Result r = run("decode " + path("a.exr") + " -o " + path("fit.exr") + " --size 80x60 --backend cpu");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::vector<float> fitted = decoded("fit.exr");
    const conus::Image taps = conus::codec::decodeImage(file.image, map, o);
    o.pyramid = &pyramid;
    const conus::Image trilinear = conus::codec::decodeImage(file.image, map, o);
    EXPECT_LT(maxDifference(fitted, trilinear.pixels), 1e-6f);
    EXPECT_GT(maxDifference(fitted, taps.pixels), 1e-3f);  // not the multi-tap average

    r = run("decode " + path("a.exr") + " -o " + path("zoom.exr") + " --view 0.1,0.1,0.3,0.3 --size 200x200 --backend cpu");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    o.view = {0.1, 0.1, 0.3, 0.3};
    o.width = o.height = 200;
    o.pyramid = nullptr;
    EXPECT_LT(maxDifference(decoded("zoom.exr"), conus::codec::decodeImage(file.image, map, o).pixels), 1e-6f);
}

TEST_F(Cli, UniformIsTheIdentityMap) {
    const std::string in = makePicture(256, 256);
    const Result r = run("uniform " + in + " -o " + path("u.exr") + " --size 64x64 --float");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto file = conus::format::readConusFile(path("u.exr"));
    EXPECT_EQ(file.pixelType, conus::format::PixelType::Float);
    const auto map = conus::codec::SamplingMap::fromGrid(file.map);
    EXPECT_NEAR(map.density({0.3, 0.7}), 1.0, 1e-9);
    EXPECT_EQ(file.image.width, 64);
}

// encode --fit and uniform --fit: the decoded view at the source's size, read back with
// OpenImageIO, comes closer to the (linear, float) source than without the fit.
TEST_F(Cli, FitRoundTripBeatsThePlainEncode) {
    constexpr int kW = 240, kH = 180;
    std::vector<float> source(std::size_t(kW) * kH * 3);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const double u = (x + 0.5) / kW, v = (y + 0.5) / kH;
            const double stripes = 0.5 + 0.4 * std::sin((x + 2 * y) * (0.08 + 0.3 * u));
            const bool disc = std::hypot(u - 0.35, v - 0.4) < 0.12;
            source[(y * kW + x) * 3 + 0] = float(disc ? 0.9 : 0.2 + 0.6 * stripes * v);
            source[(y * kW + x) * 3 + 1] = float(0.1 + 0.7 * u * u);
            source[(y * kW + x) * 3 + 2] = float(disc ? 0.1 : stripes);
        }
    const std::string in = path("in.exr");
    {
        auto output = OIIO::ImageOutput::create(in);
        OIIO::ImageSpec spec(kW, kH, 3, OIIO::TypeDesc::FLOAT);
        ASSERT_TRUE(output->open(in, spec));
        ASSERT_TRUE(output->write_image(OIIO::TypeDesc::FLOAT, source.data()));
        output->close();
    }
    const auto psnrOf = [&](const std::string& file) {
        const ExrRead view = readExr(file);
        EXPECT_EQ(view.width, kW);
        EXPECT_EQ(view.height, kH);
        double se = 0;
        int c = 0;
        for (const char* name : {"R", "G", "B"}) {
            const std::vector<float>& values = view.channels.at(name);
            for (std::size_t p = 0; p < values.size(); ++p) se += std::pow(values[p] - source[p * 3 + c], 2.0);
            ++c;
        }
        return 10 * std::log10(1.0 / (se / (3.0 * kW * kH)));
    };
    const std::string common = " --size 60x45 --float --backend cpu";
    const std::string foci = " --focus 0.35,0.4,0.1,4 --focus 0.75,0.65,0.07,3";
    double db[4];
    // encode fits by default (--fit says so); --fast is the filtered encode alone.
    const std::string variants[4] = {"encode " + in + " -o " + path("plain.exr") + foci + common + " --fast",
                                     "encode " + in + " -o " + path("fit.exr") + foci + common + " --fit",
                                     "uniform " + in + " -o " + path("uplain.exr") + common,
                                     "uniform " + in + " -o " + path("ufit.exr") + common + " --fit --fit-iterations 4"};
    const char* names[4] = {"plain", "fit", "uplain", "ufit"};
    for (int i = 0; i < 4; ++i) {
        Result r = run(variants[i]);
        ASSERT_EQ(r.exitCode, 0) << variants[i] << ": " << r.err;
        EXPECT_EQ(r.out.find("fitted to the decoder") != std::string::npos, i % 2 == 1) << r.out;
        r = run("decode " + path(std::string(names[i]) + ".exr") + " -o " + path(std::string(names[i]) + "-view.exr") +
                " --backend cpu");
        ASSERT_EQ(r.exitCode, 0) << r.err;
        db[i] = psnrOf(path(std::string(names[i]) + "-view.exr"));
    }
    EXPECT_GT(db[1], db[0] + 0.2) << "encode " << db[0] << " dB, encode --fit " << db[1] << " dB";
    EXPECT_GT(db[3], db[2] + 0.5) << "uniform " << db[2] << " dB, uniform --fit --fit-iterations 4 " << db[3] << " dB";
    // A count out of range is refused with a reason, and nothing is written.
    const Result bad = run("encode " + in + " -o " + path("bad.exr") + foci + " --fit --fit-iterations 0");
    EXPECT_NE(bad.exitCode, 0);
    EXPECT_NE(bad.err.find("--fit-iterations"), std::string::npos) << bad.err;
    EXPECT_FALSE(fs::exists(path("bad.exr")));
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(Cli, EncodeTakesTheMapOfAnotherFile) {
    const std::string in = makePicture(200, 200);
    ASSERT_EQ(run("encode " + in + " -o " + path("a.exr") + " --size 50x50 --focus 0.5,0.5,0.1,3").exitCode, 0);
    const Result r = run("encode " + in + " -o " + path("b.exr") + " --size 60x60 --map " + path("a.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto a = conus::format::readConusFile(path("a.exr"));
    const auto b = conus::format::readConusFile(path("b.exr"));
    EXPECT_EQ(a.map.xy, b.map.xy);
    EXPECT_EQ(b.image.width, 60);
}

TEST_F(Cli, BadArgumentsGiveOneLineReasons) {
    const std::string in = makePicture(64, 64);
    struct Case {
        std::string args, expected;
    };
    const Case cases[] = {
        {"encode " + in + " -o " + path("x.exr") + " --size 0x5", "size"},
        {"encode " + in + " -o " + path("x.exr") + " --size 12", "WxH"},
        {"encode " + in + " -o " + path("x.exr") + " --focus 0.5,0.5,0.1", "focus"},
        {"encode " + in + " -o " + path("x.exr") + " --focus 1.5,0.5,0.1,4", "focus"},
        {"encode " + in + " -o " + path("x.exr") + " --focus 0.5,0.5,0.1,nan", "focus"},
        {"encode " + path("missing.png") + " -o " + path("x.exr"), "missing.png"},
        {"encode " + in + " -o " + path("x.exr") + " --compression lzma", "compression"},
        {"decode " + path("missing.exr") + " -o " + path("x.png"), "missing.exr"},
        {"decode " + in + " -o " + path("x.png"), "in.png"},
        {"encode " + in, "output"},
        {"frobnicate", "frobnicate"},
    };
    for (const auto& c : cases) {
        const Result r = run(c.args);
        EXPECT_NE(r.exitCode, 0) << c.args;
        EXPECT_EQ(r.err.rfind("conus", 0), 0u) << c.args << "\n" << r.err;
        EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.args << "\n" << r.err;
        EXPECT_FALSE(fs::exists(path("x.exr"))) << c.args;
        EXPECT_FALSE(fs::exists(path("x.png"))) << c.args;
    }
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(Cli, DecodeViewMustNotBeEmpty) {
    ASSERT_NO_FATAL_FAILURE(makeUniformFile());
    const Result r = run("decode " + path("u.exr") + " -o " + path("v.png") + " --view 0.5,0.5,0.4,0.6");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("view"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("v.png")));
}

TEST_F(Cli, DecodeRefusesToOverwriteItsInputAndOversizedJpeg) {
    ASSERT_NO_FATAL_FAILURE(makeUniformFile());
    const std::string before = slurp(path("u.exr"));
    Result r = run("decode " + path("u.exr") + " -o " + path("u.exr"));
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("refusing to write " + path("u.exr") + ": it is the input file"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(path("u.exr")), before);
    // libjpeg would end the process on this size; the writer refuses it first.
    r = run("decode " + path("u.exr") + " -o " + path("wide.jpg") + " --size 65536x2");
    EXPECT_EQ(r.exitCode, 2);  // a size the format cannot hold: a usage error
    EXPECT_NE(r.err.find("conus decode: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("65500"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("wide.jpg")));
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(Cli, FailedWriteLeavesNoFile) {
    const std::string in = makePicture(64, 64);
    const Result r = run("encode " + in + " -o " + path("no/such/dir/x.exr") + " --size 16x16");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_FALSE(fs::exists(path("no")));
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(Cli, ExistingOutputIsUntouchedOnFailure) {
    ASSERT_NO_FATAL_FAILURE(makeUniformFile("keep.exr"));
    const std::string before = slurp(path("keep.exr"));
    EXPECT_NE(run("encode " + path("missing.png") + " -o " + path("keep.exr")).exitCode, 0);
    EXPECT_EQ(slurp(path("keep.exr")), before);
}

TEST_F(Cli, ValidateRejectsWhatIsNotCoNUS) {
    const std::string in = makePicture(32, 32);
    Result r = run("validate " + in);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("not a valid CoNUS file"), std::string::npos) << r.err;

    const fs::path beachball = fs::path(CONUS_SHARED_DATA) / "exr/Beachball_multipart.0001.exr";
    if (!fs::exists(beachball)) GTEST_SKIP() << "shared data not found at " << CONUS_SHARED_DATA;
    r = run("validate " + beachball.string());
    EXPECT_EQ(r.exitCode, 1);
    r = run("decode " + beachball.string() + " -o " + path("b.png"));
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("not a CoNUS file"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("b.png")));
}

TEST_F(Cli, InfoListsTheFoci) {
    const std::string in = makePicture(64, 64);
    ASSERT_EQ(run("encode " + in + " -o " + path("a.exr") + " --size 16x16 --focus 0.5,0.5,0.2,3 --exact-k").exitCode, 0);
    const Result r = run("info " + path("a.exr"));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("focus u=0.5 v=0.5 r=0.2 k=3"), std::string::npos) << r.out;
}

TEST_F(Cli, ValidateNamesTheRuleOfADamagedFile) {
    const fs::path damaged = fs::path(CONUS_SHARED_DATA) / "exr/damaged";
    if (!fs::exists(damaged)) GTEST_SKIP() << "shared data not found at " << CONUS_SHARED_DATA;
    int checked = 0;
    for (const auto& entry : fs::directory_iterator(damaged)) {
        if (entry.path().extension() == ".rst" || ++checked > 5) continue;
        const Result r = run("validate '" + entry.path().string() + "'");
        EXPECT_EQ(r.exitCode, 1) << entry.path();
        EXPECT_NE(r.out.find(": V"), std::string::npos) << entry.path() << "\n" << r.out;
    }
}

TEST_F(Cli, MapSubcommandsWriteValidMapsThatEncodeUses) {
    const std::string in = makePicture(200, 150);
    {
        std::ofstream strokes(path("strokes.json"));
        strokes << R"([{"u":0.4,"v":0.5,"radius":0.15,"strength":1.0,"duration":0.3}])";
    }
    const std::string maps[][2] = {
        {"foci", "map foci --focus 0.3,0.4,0.1,3 --focus 0.7,0.6,0.1,2 --aspect 1.333"},
        {"ground", "map ground --eye-height 1 --near 1 --far 20 --fov 60 --grid 33"},
        {"springs", "map springs --strokes " + path("strokes.json") + " --grid 33 --out-grid 17"},
        {"auto", "map auto --importance " + makeImportance(64, 48) + " --grid 33"},
    };
    for (const auto& [name, args] : maps) {
        const Result r = run(args + " -o " + path(name + ".exr") + " --preview " + path(name + ".png"));
        ASSERT_EQ(r.exitCode, 0) << args << "\n" << r.err;
        EXPECT_EQ(run("validate " + path(name + ".exr")).exitCode, 0) << name;
        EXPECT_GT(imageSize(path(name + ".png")).first, 0) << name;
        const Result e = run("encode " + in + " --map " + path(name + ".exr") + " -o " + path(name + "-enc.exr") +
                             " --size 50x40");
        ASSERT_EQ(e.exitCode, 0) << name << "\n" << e.err;
        const auto map = conus::codec::SamplingMap::fromGrid(conus::format::readConusFile(path(name + "-enc.exr")).map);
        // Every builder made a map that is not the identity somewhere.
        double spread = 0;
        for (double v = 0.05; v < 1; v += 0.1)
            for (double u = 0.05; u < 1; u += 0.1) spread = std::max(spread, std::abs(map.density({u, v}) - 1.0));
        EXPECT_GT(spread, 0.2) << name;
    }
    const Result c = run("map compose " + path("foci.exr") + " " + path("ground.exr") + " --translate 0.05,0 -o " +
                         path("sum.exr"));
    ASSERT_EQ(c.exitCode, 0) << c.err;
    EXPECT_EQ(run("validate " + path("sum.exr")).exitCode, 0);
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(Cli, MapErrorsAreOneLine) {
    {
        std::ofstream strokes(path("bad.json"));
        strokes << R"([{"u":0.4,"radius":0.15,"strength":1.0,"duration":0.3}])";
    }
    Result r = run("map springs --strokes " + path("bad.json") + " -o " + path("x.exr"));
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("conus map: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\"v\""), std::string::npos) << r.err;
    r = run("map auto --importance detail -o " + path("x.exr"));
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("needs an input image"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("x.exr")));
}

TEST_F(Cli, AnisotropyIsLimitedReportedAndDrawn) {
    // A wide focus: without a limit the footprints at its rim are > 3 times longer than wide;
    // with --max-anisotropy 3 the map says so, holds it, and info reports the same figure.
    const std::string foci = "map foci --focus 0.5,0.5,0.2,2 --aspect 1.7778";
    const Result free = run(foci + " -o " + path("free.exr"));
    ASSERT_EQ(free.exitCode, 0) << free.err;
    const Result r = run(foci + " --max-anisotropy 3 -o " + path("m.exr") + " --preview " + path("m.png"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    auto reported = [](const std::string& text) {
        const auto at = text.find("anisotropy up to ");
        return at == std::string::npos ? -1.0 : std::stod(text.substr(at + 17));
    };
    EXPECT_GT(reported(free.out), 3.0) << free.out;
    EXPECT_LE(reported(r.out), 3.0) << r.out;
    EXPECT_GT(reported(r.out), 1.5) << r.out;
    const auto map = conus::codec::SamplingMap::fromGrid(conus::format::readConusFile(path("m.exr")).map);
    EXPECT_LE(conus::codec::measureMap(map, 1.7778).maxAnisotropy, 3.0);
    const std::string in = makePicture(320, 180);
    ASSERT_EQ(run("encode " + in + " --map " + path("m.exr") + " -o " + path("e.exr") + " --size 80x45").exitCode, 0);
    const Result info = run("info " + path("e.exr") + " --json");
    ASSERT_EQ(info.exitCode, 0) << info.err;
    const auto json = nlohmann::json::parse(info.out);
    EXPECT_NEAR(json["samplingMap"]["maxAnisotropy"].get<double>(), conus::codec::measureMap(map, 320.0 / 180.0).maxAnisotropy, 1e-6);
    EXPECT_NE(run("info " + path("e.exr")).out.find("anisotropy    up to"), std::string::npos);
    EXPECT_GT(imageSize(path("m.png")).first, 0);
    // A limit below what a focus needs is held, not refused: the file records the k it leaves, and says so.
    const Result tight = run(foci + " --max-anisotropy 1.05 -o " + path("t.exr"));
    EXPECT_EQ(tight.exitCode, 0) << tight.err;
    EXPECT_NE(tight.err.find("under --max-anisotropy 1.05"), std::string::npos) << tight.err;
    const auto held = conus::format::readConusFile(path("t.exr"));
    ASSERT_TRUE(held.analytic.has_value());
    EXPECT_LT(held.analytic->foci[0].k, 1.5);
}

TEST_F(Cli, FocusFalloffIsBuiltRecordedAndChecked) {
    // `--falloff` builds the map the codec builds for that transition, and the file records it.
    const std::vector<conus::codec::Focus> foci{{0.45, 0.5, 0.1, 4}};
    const Result r = run("map foci --focus 0.45,0.5,0.1,4 --aspect 1.5 --falloff 1.5,logr -o " + path("m.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const conus::format::ConusFile file = conus::format::readConusFile(path("m.exr"));
    ASSERT_TRUE(file.analytic.has_value());
    conus::codec::FociOptions options;
    options.aspect = 1.5;
    options.falloff = {1.5, conus::codec::FociFalloffShape::LogRadius};
    conus::codec::FociReport report;
    const auto built = conus::codec::buildFociMap(foci, options, &report);
    // The file records the transition the map holds: 1.5 as asked, or what the anisotropy bound widened it to.
    ASSERT_EQ(report.transition.size(), 1u);
    EXPECT_NEAR(file.analytic->scalars.at("falloffWidth"), std::max(1.5, report.transition[0]), 1e-9);
    EXPECT_EQ(file.analytic->scalars.at("falloffShape"), 2.0);
    const auto read = conus::codec::SamplingMap::fromGrid(file.map);
    ASSERT_EQ(read.nodes().size(), built.nodes().size());
    double differs = 0, fromDefault = 0;
    conus::codec::FociOptions defaults;
    defaults.aspect = 1.5;
    const auto plain = conus::codec::buildFociMap(foci, defaults);
    for (std::size_t k = 0; k < built.nodes().size(); ++k) {
        differs = std::max(differs, double(glm::length(read.nodes()[k] - built.nodes()[k])));
        fromDefault = std::max(fromDefault, double(glm::length(read.nodes()[k] - plain.nodes()[k])));
    }
    EXPECT_LT(differs, 1e-6);
    EXPECT_GT(fromDefault, 1e-3);  // the option changed the map
    // encode --focus takes it too; the default (1.25) is recorded as well, and only the format's own
    // r..2r leaves no trace in the file.
    const std::string in = makePicture(240, 160);
    // Each records the transition its map holds: as asked, or the widest the encode said it widened to.
    const auto held = [](const Result& r, double asked) {
        double widest = asked;
        const std::string key = "transition widened from ";
        for (std::size_t at = r.out.find(key); at != std::string::npos; at = r.out.find(key, at + 1)) {
            const std::size_t to = r.out.find(" to ", at);
            widest = std::max(widest, std::stod(r.out.substr(to + 4)));
        }
        return widest;
    };
    const Result e = run("encode " + in + " --focus 0.45,0.5,0.1,4 --falloff 3 -o " + path("e.exr") + " --size 60x40");
    ASSERT_EQ(e.exitCode, 0);
    EXPECT_NEAR(conus::format::readConusFile(path("e.exr")).analytic->scalars.at("falloffWidth"), held(e, 3.0), 0.006) << e.out;
    const Result d = run("encode " + in + " --focus 0.45,0.5,0.1,4 -o " + path("d.exr") + " --size 60x40");
    ASSERT_EQ(d.exitCode, 0);
    EXPECT_NEAR(conus::format::readConusFile(path("d.exr")).analytic->scalars.at("falloffWidth"), held(d, 1.25), 0.006) << d.out;
    const Result f = run("encode " + in + " --focus 0.45,0.5,0.1,4 --falloff 2 -o " + path("f.exr") + " --size 60x40");
    ASSERT_EQ(f.exitCode, 0);
    if (held(f, 2.0) == 2.0) EXPECT_TRUE(conus::format::readConusFile(path("f.exr")).analytic->scalars.empty());
    // Bad falloffs: a usage error naming it, and no file.
    for (const char* bad : {"1", "9", "2,cubic", "x"}) {
        const Result b = run(std::string("map foci --focus 0.5,0.5,0.1,4 --falloff ") + bad + " -o " + path("b.exr"));
        EXPECT_EQ(b.exitCode, 2) << bad << ": " << b.err;
        EXPECT_NE(b.err.find("falloff"), std::string::npos) << b.err;
        EXPECT_FALSE(fs::exists(path("b.exr")));
    }
    // encode's --falloff shapes foci only: without --focus it is refused, not dropped.
    const Result alone = run("encode " + in + " --falloff 1.5 -o " + path("nofocus.exr") + " --size 60x40");
    EXPECT_EQ(alone.exitCode, 2) << alone.err;
    EXPECT_NE(alone.err.find("--focus"), std::string::npos) << alone.err;
    EXPECT_FALSE(fs::exists(path("nofocus.exr")));
}

TEST_F(Cli, DensityBoundsAreHeldOrRefused) {
    const std::string importance = makeImportance(160, 120);
    const Result held = run("map auto --importance " + importance + " --min-density 0.4 --max-density 9 -o " + path("a.exr"));
    ASSERT_EQ(held.exitCode, 0) << held.err;
    const auto map = conus::codec::SamplingMap::fromGrid(conus::format::readConusFile(path("a.exr")).map);
    const conus::codec::MapMeasures m = conus::codec::measureMap(map);
    EXPECT_GE(m.minCellDensity, 0.4 * 0.95);
    EXPECT_LE(m.maxCellDensity, 9 * 1.05);
    // Separable maps put bands through the hot spot: a floor of 0.6 cannot be held on them.
    const Result refused = run("map auto --importance " + importance + " --method separable --min-density 0.6 -o " + path("b.exr"));
    EXPECT_EQ(refused.exitCode, 2) << refused.out;
    EXPECT_NE(refused.err.find("the map reaches"), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(path("b.exr")));
}

TEST_F(Cli, FrameLossBudgetSaysWhatItAchieved) {
    const std::string picture = makePicture(256, 192), importance = makeImportance(64, 48);
    const std::string encode = "encode " + picture + " --importance " + importance + " --size 64x48 --frame-loss ";
    const Result tight = run(encode + "0.5 -o " + path("t.exr"));
    ASSERT_EQ(tight.exitCode, 0) << tight.err;
    EXPECT_NE(tight.out.find("budget: the whole frame within 0.5 dB and tiles outside the region within 4 dB"), std::string::npos) << tight.out;
    EXPECT_NE(tight.out.find(": context floor "), std::string::npos) << tight.out;
    EXPECT_NE(tight.out.find(": the whole frame "), std::string::npos) << tight.out;
    EXPECT_TRUE(fs::exists(path("t.exr")));
    // The budget stands in for the floor, and needs importance to spend.
    EXPECT_EQ(run(encode + "1 --min-density 0.3 -o " + path("x.exr")).exitCode, 2);
    EXPECT_EQ(run("encode " + picture + " --frame-loss 1 -o " + path("y.exr")).exitCode, 2);
    EXPECT_FALSE(fs::exists(path("x.exr")));
    EXPECT_FALSE(fs::exists(path("y.exr")));
}

TEST_F(Cli, FacesImportanceFindsTheAstronautsFace) {
    const std::string photo = "/usr/lib/python3/dist-packages/skimage/data/astronaut.png";
    if (!fs::exists(photo)) GTEST_SKIP() << "python3-skimage's photographs not installed (" << photo << ")";
    const Result r = run("encode " + photo + " --importance faces -o " + path("a.exr") + " --size 128x128");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto map = conus::codec::SamplingMap::fromGrid(conus::format::readConusFile(path("a.exr")).map);
    // The face is around (0.44, 0.23); the flag at the left edge and the suit are context.
    // (The context floor is the loss budget's: the face takes what the frame and its tiles can spare,
    // measured on 8-bit sRGB against `conus uniform`; 2.6 times the context's density here.)
    EXPECT_GT(map.density({0.44, 0.23}), 2.0);
    EXPECT_LT(map.density({0.1, 0.6}), map.density({0.44, 0.23}) / 2);
    EXPECT_LT(map.density({0.8, 0.85}), map.density({0.44, 0.23}) / 2);
}

TEST_F(Cli, FocusViewOfARealPhotoBeatsTheUniformImage) {
    const std::string photo = "/usr/lib/python3/dist-packages/skimage/data/astronaut.png";
    if (!fs::exists(photo)) GTEST_SKIP() << "python3-skimage's photographs not installed (" << photo << ")";
    const Result r = run("demo --input " + photo + " --focus 0.44,0.23,0.08,4 --out " + path("q"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    // The table's row "focus 1   31.30 dB   24.31 dB   +6.99" (the budget's block above it says
    // "  focus 1 at (u, v), r ...: k ...", indented).
    auto line = r.out.find("\nfocus 1 ");
    ASSERT_NE(line, std::string::npos) << r.out;
    ++line;
    double conusDb = 0, uniformDb = 0;
    ASSERT_EQ(std::sscanf(r.out.c_str() + line, "focus 1 %lf dB %lf dB", &conusDb, &uniformDb), 2) << r.out;
    EXPECT_GT(conusDb, uniformDb + 3.0) << r.out;
}

TEST_F(Cli, BackendsAgreeAndAreListed) {
    Result r = run("info --backends");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* name : {"egl", "osmesa", "cpu"}) EXPECT_NE(r.out.find(name), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("works"), std::string::npos);

    const std::string in = makePicture(256, 192);
    for (const char* backend : {"cpu", "egl", "osmesa"}) {
        r = run(std::string("encode ") + in + " -o " + path(std::string(backend) + ".exr") +
                " --size 64x48 --float --focus 0.4,0.5,0.12,3 --backend " + backend);
        ASSERT_EQ(r.exitCode, 0) << backend << "\n" << r.err;
        r = run("decode " + path(std::string(backend) + ".exr") + " -o " + path(std::string(backend) + "-view.exr") +
                " --view 0.3,0.4,0.5,0.6 --size 80x80 --backend " + backend);
        ASSERT_EQ(r.exitCode, 0) << backend << "\n" << r.err;
    }
    const auto cpu = conus::format::readConusFile(path("cpu.exr"));
    for (const char* backend : {"egl", "osmesa"}) {
        const auto gpu = conus::format::readConusFile(path(std::string(backend) + ".exr"));
        // The test picture's stripes reach 0.45 cycles per pixel, where the GPU's derivative-based
        // footprint and the CPU's Jacobian place taps slightly differently; on photographs the two
        // agree to >= 45 dB (renderers_tests). Here: the same pipeline, not another one.
        EXPECT_GT(conus::codec::psnr(cpu.image, gpu.image), 35.0) << backend;
    }
    r = run("encode " + in + " -o " + path("x.exr") + " --backend vulkan");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("backend"), std::string::npos) << r.err;
}

TEST_F(Cli, DemoRunsSmallAndPrintsPsnr) {
    const Result r = run("demo --size 512 --out " + path("demo"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* name : {"conus.exr", "uniform.exr", "conus.png", "uniform.png", "density.png",
                             "view-focus1.png", "view-focus2.png", "view-frame.png"})
        EXPECT_TRUE(fs::exists(path("demo") + "/" + name)) << name;
    EXPECT_NE(r.out.find("focus 1"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("dB"), std::string::npos) << r.out;
    EXPECT_EQ(run("validate " + path("demo") + "/conus.exr").exitCode, 0);
}

}  // namespace
