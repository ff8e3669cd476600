// `conus bake relief` and `conus render relief` through the real binary.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cli/cli_fixture.h"
#include "conus/format/container.h"

namespace conus::test {
namespace {

using ReliefCli = Cli;

// The mean and spread of a picture's values, read by OpenImageIO.
std::pair<double, double> meanAndSpread(const std::string& path) {
    const OIIO::ImageBuf image(path);
    const auto stats = OIIO::ImageBufAlgo::computePixelStats(image);
    double mean = 0, spread = 0;
    for (std::size_t c = 0; c < stats.avg.size(); ++c) {
        mean += stats.avg[c];
        spread += stats.stddev[c];
    }
    return {mean / stats.avg.size(), spread / stats.avg.size()};
}

double meanDifference(const std::string& a, const std::string& b) {
    const OIIO::ImageBuf difference = OIIO::ImageBufAlgo::absdiff(OIIO::ImageBuf(a), OIIO::ImageBuf(b));
    const auto stats = OIIO::ImageBufAlgo::computePixelStats(difference);
    double sum = 0;
    for (const float v : stats.avg) sum += v;
    return sum / stats.avg.size();
}

TEST_F(ReliefCli, BakeValidatesAndRenders) {
    const std::string conus = path("tablet.exr"), uniform = path("uniform.exr");
    Result r = run("bake relief tablet --tablet-size 320x240 --size 80x60 --text 'AB|CD' -o " + conus);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("detail importance map"), std::string::npos) << r.out;
    r = run("bake relief tablet --tablet-size 320x240 --size 80x60 --text 'AB|CD' --uniform -o " + uniform);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(run("validate " + conus).exitCode, 0);
    EXPECT_EQ(run("validate " + uniform).exitCode, 0);

    const format::ConusFile baked = format::readConusFile(conus), flat = format::readConusFile(uniform);
    EXPECT_EQ(baked.dataKind, format::DataKind::HeightField);
    EXPECT_EQ(baked.depth.kind, format::DepthKind::Height);
    ASSERT_TRUE(baked.camera);
    EXPECT_EQ(baked.camera->projection, "orthographic");
    EXPECT_EQ(baked.image.width, 80);
    EXPECT_GT(baked.map.columns, 2);  // a real map
    EXPECT_EQ(flat.map.columns, 2);   // the identity
    EXPECT_EQ(flat.image.width * flat.image.height, baked.image.width * baked.image.height);

    const std::string frame = path("frame.png"), frameUniform = path("frame-uniform.png"), shadowed = path("shadows.png");
    r = run("render relief " + conus + " -o " + frame + " --size 160x120");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(imageSize(frame), std::make_pair(160, 120));
    const auto [mean, spread] = meanAndSpread(frame);
    EXPECT_GT(spread, 0.05);  // the tablet in front of the background, shaded
    EXPECT_GT(mean, 0.1);
    ASSERT_EQ(run("render relief " + uniform + " -o " + frameUniform + " --size 160x120").exitCode, 0);
    // A low light from +x: the frame and the strokes' walls cast shadows.
    const std::string lowLight = path("low.png");
    ASSERT_EQ(run("render relief " + conus + " -o " + lowLight + " --size 160x120 --light 1,0.3,0").exitCode, 0);
    ASSERT_EQ(run("render relief " + conus + " -o " + shadowed + " --size 160x120 --light 1,0.3,0 --shadows").exitCode, 0);
    // The same tablet from the same default view: close, but not the same samples; shadows darken.
    const double assets = meanDifference(frame, frameUniform);
    EXPECT_GT(assets, 0.0);
    EXPECT_LT(assets, 0.05);
    // Shadows only take light away: some pixels darker, none brighter.
    const auto darkening = OIIO::ImageBufAlgo::computePixelStats(
        OIIO::ImageBufAlgo::sub(OIIO::ImageBuf(lowLight), OIIO::ImageBuf(shadowed)));
    EXPECT_GT(*std::max_element(darkening.max.begin(), darkening.max.end()), 0.1f);
    EXPECT_GE(*std::min_element(darkening.min.begin(), darkening.min.end()), -0.01f);
    // A camera given: from straight above the centre, the field fills the frame; the line echoes
    // that camera as given.
    r = run("render relief " + conus + " -o " + path("above.png") + " --size 64x48 --camera 0.5,3,0.376,0.5,0,0.375,12");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("camera 0.5,3,0.376,0.5,0,0.375,12\n"), std::string::npos) << r.out;
    EXPECT_GT(meanAndSpread(path("above.png")).first, 0.25);
    // The default view's echo, given back, draws the same frame.
    r = run("render relief " + conus + " -o " + path("default.png") + " --size 64x48");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::size_t echoed = r.out.find("camera ");
    ASSERT_NE(echoed, std::string::npos) << r.out;
    const std::string camera = r.out.substr(echoed + 7, r.out.find('\n', echoed) - echoed - 7);
    ASSERT_EQ(run("render relief " + conus + " -o " + path("again.png") + " --size 64x48 --camera " + camera).exitCode, 0);
    EXPECT_LT(meanDifference(path("default.png"), path("again.png")), 2e-3) << camera;
    EXPECT_TRUE(leftovers().empty());
}

// --height-scale gives heights in world units: a float file's values times the scale, a 16-bit
// image's codes over 0..65535 first (code 65535 stands the scale high); the baked asset's heights
// (its Z channel, read back) say so, and the help says it in those words.
TEST_F(ReliefCli, HeightScaleIsWorldUnitsForFloatAndSixteenBitFiles) {
    const std::string png = path("dem.png"), exr = path("dem.exr");
    // Constant fields, so that resampling to the asset's texels changes nothing.
    OIIO::ImageBuf codes(OIIO::ImageSpec(24, 16, 1, OIIO::TypeDesc::UINT16));
    const float fraction = 40000.0f / 65535.0f;
    OIIO::ImageBufAlgo::fill(codes, {fraction});
    ASSERT_TRUE(codes.write(png));
    OIIO::ImageBuf metres(OIIO::ImageSpec(24, 16, 1, OIIO::TypeDesc::FLOAT));
    OIIO::ImageBufAlgo::fill(metres, {3.5f});
    ASSERT_TRUE(metres.write(exr));
    for (const auto& [source, expected] : {std::pair{png, 0.2 * 40000.0 / 65535.0}, std::pair{exr, 0.2 * 3.5}}) {
        const std::string out = source + "-relief.exr";
        const Result r = run("bake relief " + source + " --width 1 --height-scale 0.2 --uniform --size 12x8 -o " + out);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const format::ConusFile file = format::readConusFile(out);
        const int z = file.image.channelIndex("Z");
        ASSERT_GE(z, 0);
        for (int y = 0; y < file.image.height; ++y)
            for (int x = 0; x < file.image.width; ++x) ASSERT_NEAR(file.image.at(x, y, z), expected, 1e-4) << source;
    }
    const Result help = run("bake relief --help");
    EXPECT_NE(help.out.find("world units"), std::string::npos) << help.out;
}

// PSNR (dB) of picture a against the reference r, over the pixels whose (u, v) `in` accepts.
template <class Mask>
double psnrWhere(const std::string& a, const std::string& r, Mask in) {
    OIIO::ImageBuf x(a), y(r);
    EXPECT_TRUE(x.read(0, 0, true, OIIO::TypeDesc::FLOAT) && y.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << a << ", " << r;
    const OIIO::ROI roi = x.roi();
    double sum = 0, count = 0;
    for (OIIO::ImageBuf::ConstIterator<float> i(x), j(y); !i.done(); ++i, ++j) {
        if (!in((i.x() + 0.5) / roi.width(), (i.y() + 0.5) / roi.height())) continue;
        for (int c = 0; c < std::min(3, roi.nchannels()); ++c) sum += (i[c] - j[c]) * (i[c] - j[c]);
        count += std::min(3, roi.nchannels());
    }
    return 10 * std::log10(1.0 / std::max(sum / count, 1e-12));
}

// A focus on a relief: the budget lowers k so that the tablet outside the focus stays within 1 dB
// of the uniform asset (the target), says so, and the focus still gains.
TEST_F(ReliefCli, AFocusKeepsTheRestOfTheTablet) {
    const std::string args = " --tablet-size 512x384 --text 'CoNUS|RELIEF'";
    Result r = run("bake relief tablet" + args + " --size 128x96 --focus 0.5,0.3,0.12,3 -o " + path("f.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find(", outside the foci 0.6 dB, against"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("(asked 3)"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find(": k 3 (asked 3)"), std::string::npos) << r.out;  // lowered
    EXPECT_NE(r.out.find("k as asked: --exact-k"), std::string::npos) << r.out;
    ASSERT_EQ(run("bake relief tablet" + args + " --size 128x96 --uniform -o " + path("u.exr")).exitCode, 0);
    ASSERT_EQ(run("bake relief tablet" + args + " --uniform --size 512x384 -o " + path("ref.exr")).exitCode, 0);
    for (const char* name : {"f", "u", "ref"})
        ASSERT_EQ(run(std::string("decode ") + path(std::string(name) + ".exr") + " -o " + path(std::string(name) + ".png") + " --size 512x384 -q").exitCode, 0);
    const auto outside = [](double u, double v) { return std::hypot(u - 0.5, (v - 0.3) * 0.75) > 0.12; };
    const auto inside = [&](double u, double v) { return !outside(u, v); };
    const double rest = psnrWhere(path("f.png"), path("ref.png"), outside) - psnrWhere(path("u.png"), path("ref.png"), outside);
    const double focus = psnrWhere(path("f.png"), path("ref.png"), inside) - psnrWhere(path("u.png"), path("ref.png"), inside);
    std::printf("relief with a focus against the uniform asset: focus %+.2f dB, the rest %+.2f dB\n", focus, rest);
    EXPECT_GT(rest, -1.0);
    EXPECT_GT(focus, 1.0);
}

TEST_F(ReliefCli, BadInputFailsWithOneLine) {
    const std::string picture = makePicture(64, 48);
    const std::string plain = path("plain.exr");
    ASSERT_EQ(run("encode " + picture + " -o " + plain + " --focus 0.5,0.5,0.1,2").exitCode, 0);
    Result r = run("render relief " + plain + " -o " + path("f.png"));
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("conus render: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("not a relief asset"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    r = run("render relief " + path("missing.exr") + " -o " + path("f.png"));
    EXPECT_EQ(r.exitCode, 1);
    // Bad values are usage errors (2); a file that cannot serve is a failure (1).
    r = run("bake relief tablet --tablet-size 64x48 --size 128x96 -o " + path("t.exr"));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("larger than the height field"), std::string::npos) << r.err;
    EXPECT_EQ(run("bake relief tablet --text '' -o " + path("t.exr")).exitCode, 2);
    EXPECT_EQ(run("bake relief tablet --uniform --focus 0.5,0.5,0.1,2 -o " + path("t.exr")).exitCode, 2);
    EXPECT_EQ(run("render relief " + plain + " -o " + path("f.png") + " --step 0").exitCode, 2);
    EXPECT_EQ(run("render relief " + path("missing.exr") + " -o " + path("f.png") + " --camera 1,2,3").exitCode, 2);
    EXPECT_FALSE(fs::exists(path("t.exr")));
    EXPECT_FALSE(fs::exists(path("f.png")));
    EXPECT_TRUE(leftovers().empty());
}

}  // namespace
}  // namespace conus::test
