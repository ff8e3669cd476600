// The user's path through real files: pictures made with OpenImageIO, converted by the real `conus`
// binary, written to disk and read back with OpenImageIO (never with CoNUS's own reader), then
// compared with the source. The inputs are asymmetric on purpose (a red, a green and a blue patch
// in known corners, text, partial alpha) so that swapped channels, flips, rotations, lost alpha,
// lost bits and colour-space mistakes each change a number these tests check.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "test_dir.h"

namespace fs = std::filesystem;

namespace {

constexpr int kW = 96, kH = 64;  // wider than tall: a rotation or transpose changes the shape

struct Picture {
    OIIO::ImageSpec spec;
    std::vector<float> pixels;  // as OpenImageIO reads them: float, [0,1] for integer files
    float at(int x, int y, int c) const { return pixels[(static_cast<std::size_t>(y) * spec.width + x) * spec.nchannels + c]; }
};

Picture readBack(const fs::path& path, bool unassociated = true) {
    OIIO::ImageSpec config;
    if (unassociated) config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path.string(), &config);
    EXPECT_TRUE(in) << path << ": " << OIIO::geterror();
    Picture p;
    if (!in) return p;
    p.spec = in->spec();
    p.pixels.resize(static_cast<std::size_t>(p.spec.width) * p.spec.height * p.spec.nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, p.spec.nchannels, OIIO::TypeDesc::FLOAT, p.pixels.data())) << in->geterror();
    return p;
}

// 8/16-bit code values of a float in [0,1].
int code(float v, int max) { return static_cast<int>(std::lround(v * max)); }

float srgbToLinear(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

class UserPath : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return m_dir.file(name); }

    // Runs the real binary; returns its exit code, stderr in `err`.
    int conus(const std::string& args, std::string* err = nullptr) {
        const std::string errFile = path("stderr.txt");
        const int status = std::system((std::string(CONUS_BIN_DIR) + "/conus " + args + " >/dev/null 2>" + errFile).c_str());
        std::ifstream in(errFile);
        std::stringstream s;
        s << in.rdbuf();
        if (err) *err = s.str();
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }

    // Writes an image with OpenImageIO from float values in [0,1] (integer types) or linear floats.
    std::string write(const std::string& name, OIIO::ImageSpec spec, const std::vector<float>& pixels) {
        const std::string p = path(name);
        auto out = OIIO::ImageOutput::create(p);
        EXPECT_TRUE(out);
        if (spec.alpha_channel >= 0 && spec.format != OIIO::TypeDesc::FLOAT) spec.attribute("oiio:UnassociatedAlpha", 1);
        EXPECT_TRUE(out->open(p, spec)) << out->geterror();
        EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) << out->geterror();
        out->close();
        return p;
    }

    // The asymmetric test picture: a dark grey field, a red patch top-left, green top-right, blue
    // bottom-left, a horizontal grey ramp across the middle, and white text bottom-right. With
    // alpha (4 channels): alpha ramps from 0 to 1 across the ramp rows and is partial on the text.
    std::vector<float> picture(int channels) const {
        std::vector<float> p(static_cast<std::size_t>(kW) * kH * channels);
        auto set = [&](int x, int y, std::array<float, 4> v) {
            for (int c = 0; c < channels; ++c) p[(static_cast<std::size_t>(y) * kW + x) * channels + c] = v[c];
        };
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                std::array<float, 4> v{40 / 255.f, 40 / 255.f, 40 / 255.f, 1.0f};
                if (x < 24 && y < 16) v = {1, 0, 0, 1};
                if (x >= kW - 24 && y < 16) v = {0, 1, 0, 1};
                if (x < 24 && y >= kH - 16) v = {0, 0, 1, 1};
                if (y >= 28 && y < 36) {
                    const float g = std::round(x * 255.0f / (kW - 1)) / 255.0f;
                    v = {g, g, g, std::round(x * 255.0f / (kW - 1)) / 255.0f};
                }
                if (channels <= 2) v[1] = v[3];  // grey (+ alpha): Y, A
                set(x, y, v);
            }
        // Text, drawn by OpenImageIO in white over the bottom-right corner.
        OIIO::ImageBuf buffer(OIIO::ImageSpec(kW, kH, channels, OIIO::TypeDesc::FLOAT), p.data());
        const float white[4] = {1, 1, 1, 0.6f};
        OIIO::ImageBufAlgo::render_text(buffer, 40, 58, "CoNUS", 14, "DejaVuSans", OIIO::cspan<float>(white, channels));
        buffer.get_pixels(buffer.roi(), OIIO::TypeDesc::FLOAT, p.data());
        // Quantize to 8 bits, as the file will hold them.
        for (float& v : p) v = std::round(std::clamp(v, 0.0f, 1.0f) * 255.0f) / 255.0f;
        if (channels == 4 || channels == 2)  // nothing under full transparency: associated alpha keeps no colour there
            for (std::size_t i = 0; i < p.size(); i += channels)
                if (p[i + channels - 1] == 0.0f)
                    for (int c = 0; c < channels - 1; ++c) p[i + c] = 0.0f;
        return p;
    }

    OIIO::ImageSpec spec(int channels, OIIO::TypeDesc type) const {
        OIIO::ImageSpec s(kW, kH, channels, type);
        if (channels == 2) {
            s.channelnames = {"Y", "A"};
            s.alpha_channel = 1;
        }
        if (channels == 1) s.channelnames = {"Y"};
        return s;
    }

    // Encodes with the identity map at the source's size, then decodes to `output`.
    void roundTrip(const std::string& input, const std::string& output, const std::string& decodeArgs = "") {
        std::string err;
        ASSERT_EQ(conus("uniform " + input + " -o " + path("u.exr") + " --size " + std::to_string(kW) + "x" +
                            std::to_string(kH), &err), 0) << err;
        ASSERT_EQ(conus("decode " + path("u.exr") + " -o " + output + " " + decodeArgs, &err), 0) << err;
    }

    conus::test::TestDir m_dir{"conus-user"};
};

// Expects `got` (read back) to hold `expected` (0..1 values, `channels` each) to within `codes`
// code values of `max`, channel by channel.
void expectCodes(const Picture& got, const std::vector<float>& expected, int channels, int max, int codes,
                 const std::string& what) {
    ASSERT_EQ(got.spec.width, kW) << what;
    ASSERT_EQ(got.spec.height, kH) << what;
    ASSERT_EQ(got.spec.nchannels, channels) << what;
    int worst = 0, wx = 0, wy = 0, wc = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int c = 0; c < channels; ++c) {
                const int d = std::abs(code(got.at(x, y, c), max) - code(expected[(static_cast<std::size_t>(y) * kW + x) * channels + c], max));
                if (d > worst) worst = d, wx = x, wy = y, wc = c;
            }
    EXPECT_LE(worst, codes) << what << ": worst at (" << wx << "," << wy << ") channel " << wc;
}

}  // namespace

TEST_F(UserPath, RgbPngRoundTripIsExactInEveryLosslessFormat) {
    const std::vector<float> src = picture(3);
    const std::string in = write("in.png", spec(3, OIIO::TypeDesc::UINT8), src);
    for (const char* ext : {"png", "bmp", "tif"}) {
        const std::string out = path(std::string("out.") + ext);
        roundTrip(in, out);
        const Picture got = readBack(out);
        EXPECT_EQ(got.spec.format, OIIO::TypeDesc::UINT8) << ext << ": an 8-bit source comes back as 8 bits";
        EXPECT_EQ(got.spec.channelnames, (std::vector<std::string>{"R", "G", "B"})) << ext;
        expectCodes(got, src, 3, 255, 0, ext);
        // The corners by name: what swapped channels or a flip would break first.
        EXPECT_EQ(code(got.at(2, 2, 0), 255), 255) << ext << ": red patch top-left";
        EXPECT_EQ(code(got.at(2, 2, 2), 255), 0) << ext;
        EXPECT_EQ(code(got.at(kW - 3, 2, 1), 255), 255) << ext << ": green patch top-right";
        EXPECT_EQ(code(got.at(2, kH - 3, 2), 255), 255) << ext << ": blue patch bottom-left";
    }
}

TEST_F(UserPath, JpegOutputKeepsChannelOrderAndCorners) {
    const std::string in = write("in.png", spec(3, OIIO::TypeDesc::UINT8), picture(3));
    const std::string out = path("out.jpg");
    roundTrip(in, out);
    const Picture got = readBack(out);
    ASSERT_EQ(got.spec.nchannels, 3);
    // Lossy, but a patch's colour survives: red is red, not blue.
    EXPECT_GT(got.at(6, 6, 0), 0.9f);
    EXPECT_LT(got.at(6, 6, 2), 0.1f);
    EXPECT_GT(got.at(kW - 7, 6, 1), 0.9f);
    EXPECT_GT(got.at(6, kH - 7, 2), 0.9f);
    EXPECT_LT(got.at(6, kH - 7, 0), 0.1f);
}

TEST_F(UserPath, RgbaPartialAlphaComesBackAsAlpha) {
    const std::vector<float> src = picture(4);
    const std::string in = write("in.png", spec(4, OIIO::TypeDesc::UINT8), src);
    for (const char* ext : {"png", "tif"}) {
        const std::string out = path(std::string("out.") + ext);
        roundTrip(in, out);
        const Picture got = readBack(out);
        ASSERT_EQ(got.spec.nchannels, 4) << ext;
        EXPECT_EQ(got.spec.alpha_channel, 3) << ext;
        EXPECT_EQ(got.spec.channelnames, (std::vector<std::string>{"R", "G", "B", "A"})) << ext;
        // Alpha is exact; colour is exact where opaque and within a code where alpha divides it.
        int alphaWorst = 0, opaqueWorst = 0, partialWorst = 0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const std::size_t k = (static_cast<std::size_t>(y) * kW + x) * 4;
                alphaWorst = std::max(alphaWorst, std::abs(code(got.at(x, y, 3), 255) - code(src[k + 3], 255)));
                if (src[k + 3] == 0.0f) continue;
                for (int c = 0; c < 3; ++c) {
                    const int d = std::abs(code(got.at(x, y, c), 255) - code(src[k + c], 255));
                    (src[k + 3] == 1.0f ? opaqueWorst : partialWorst) = std::max(src[k + 3] == 1.0f ? opaqueWorst : partialWorst, d);
                }
            }
        EXPECT_EQ(alphaWorst, 0) << ext;
        EXPECT_EQ(opaqueWorst, 0) << ext;
        EXPECT_LE(partialWorst, 1) << ext;
        // Opaque red stays opaque red (alpha used to receive the R values).
        EXPECT_EQ(code(got.at(2, 2, 3), 255), 255) << ext;
        EXPECT_EQ(code(got.at(2, 2, 0), 255), 255) << ext;
    }
}

TEST_F(UserPath, GreyAndGreyAlphaKeepTheirChannels) {
    for (int channels : {1, 2}) {
        const std::vector<float> src = picture(channels);
        const std::string in = write("grey.png", spec(channels, OIIO::TypeDesc::UINT8), src);
        const std::string out = path("grey-out.png");
        roundTrip(in, out);
        const Picture got = readBack(out);
        ASSERT_EQ(got.spec.nchannels, channels);
        if (channels == 2) {
            EXPECT_EQ(got.spec.alpha_channel, 1) << "Y then A, as the source had them";
            // Grey+alpha: exact where opaque; alpha exact everywhere.
            for (int y = 0; y < kH; ++y)
                for (int x = 0; x < kW; ++x) {
                    const std::size_t k = (static_cast<std::size_t>(y) * kW + x) * 2;
                    ASSERT_EQ(code(got.at(x, y, 1), 255), code(src[k + 1], 255)) << x << "," << y;
                    if (src[k + 1] == 1.0f) {
                        ASSERT_EQ(code(got.at(x, y, 0), 255), code(src[k], 255)) << x << "," << y;
                    }
                }
        } else {
            expectCodes(got, src, 1, 255, 0, "grey");
        }
    }
}

TEST_F(UserPath, SixteenBitStaysSixteenBitWithinOneCode) {
    // Fine 16-bit values that 8 bits (or half) could not hold.
    std::vector<float> src(static_cast<std::size_t>(kW) * kH * 3);
    for (std::size_t i = 0; i < src.size(); ++i) src[i] = static_cast<float>((i * 2654435761u) % 65536) / 65535.0f;
    const std::string in = write("in16.png", spec(3, OIIO::TypeDesc::UINT16), src);
    const std::string out = path("out16.png");
    roundTrip(in, out);
    const Picture got = readBack(out);
    EXPECT_EQ(got.spec.format, OIIO::TypeDesc::UINT16);
    expectCodes(got, src, 3, 65535, 1, "16-bit PNG");
    // --bits 8 asks for 8.
    ASSERT_EQ(conus("decode " + path("u.exr") + " -o " + path("out8.png") + " --bits 8"), 0);
    EXPECT_EQ(readBack(path("out8.png")).spec.format, OIIO::TypeDesc::UINT8);
    expectCodes(readBack(path("out8.png")), src, 3, 255, 1, "16-bit source to 8-bit PNG");
}

TEST_F(UserPath, ExrHoldsLinearLightTheSrgbDecodingOfTheJpegCodes) {
    // The JPEG's own codes as OpenImageIO decodes them, then the sRGB curve: what the EXR must hold.
    const std::string jpg = write("photo.jpg", spec(3, OIIO::TypeDesc::UINT8), picture(3));
    std::string err;
    ASSERT_EQ(conus("uniform " + jpg + " -o " + path("u.exr") + " --size 96x64", &err), 0) << err;
    const Picture codes = readBack(jpg);
    const Picture linear = readBack(path("u.exr"));  // part 0, `conus`, as any EXR reader sees it
    ASSERT_EQ(linear.spec.width, kW);
    EXPECT_EQ(linear.spec.get_string_attribute("oiio:ColorSpace"), "Linear");
    double worst = 0, sumExpected = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int c = 0; c < 3; ++c) {
                const int ch = linear.spec.channelindex(std::string(1, "RGB"[c]));
                const float expected = srgbToLinear(codes.at(x, y, c));
                worst = std::max(worst, double(std::abs(linear.at(x, y, ch) - expected)));
                sumExpected += expected;
            }
    EXPECT_LT(worst, 1e-3) << "half storage of the linear value";
    // oiiotool --printstats on the same file reports the same (linear) average.
    const std::string stats = path("stats.txt");
    ASSERT_EQ(std::system(("oiiotool --stats " + path("u.exr") + " > " + stats + " 2>&1").c_str()), 0);
    std::ifstream s(stats);
    std::string line, avgLine;
    while (std::getline(s, line))
        if (line.find("Stats Avg:") != std::string::npos) avgLine = line;
    std::istringstream fields(avgLine.substr(avgLine.find(':') + 1));
    double a = 0, sum = 0;
    for (int c = 0; c < 3 && fields >> a; ++c) sum += a;
    EXPECT_NEAR(sum / 3, sumExpected / (3.0 * kW * kH), 1e-3) << avgLine;
}

TEST_F(UserPath, HdrValuesAboveOneSurviveAndToneMapForDisplay) {
    std::vector<float> src(static_cast<std::size_t>(kW) * kH * 3);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int c = 0; c < 3; ++c) {
                float v = 0.02f * (x + 1) * (c + 1) + 0.01f * y;  // up to ~6
                if (x < 24 && y < 16) v = c == 0 ? 40.0f : 0.1f;   // a bright red patch top-left
                src[(static_cast<std::size_t>(y) * kW + x) * 3 + c] = v;
            }
    const std::string in = write("hdr.exr", spec(3, OIIO::TypeDesc::FLOAT), src);
    roundTrip(in, path("out.exr"));
    const Picture exr = readBack(path("out.exr"));
    EXPECT_EQ(exr.spec.format, OIIO::TypeDesc::FLOAT) << "a float source is stored and decoded as float";
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int c = 0; c < 3; ++c) {
                const int ch = exr.spec.channelindex(std::string(1, "RGB"[c]));
                ASSERT_NEAR(exr.at(x, y, ch), src[(static_cast<std::size_t>(y) * kW + x) * 3 + c], 1e-5f) << x << "," << y;
            }
    // To PNG: values above 1 clip as they are; with a tone map they keep their order below white.
    ASSERT_EQ(conus("decode " + path("u.exr") + " -o " + path("clip.png")), 0);
    ASSERT_EQ(conus("decode " + path("u.exr") + " -o " + path("tm.png") + " --tonemap reinhard --exposure -2"), 0);
    const Picture clip = readBack(path("clip.png")), tm = readBack(path("tm.png"));
    EXPECT_EQ(code(clip.at(80, 40, 0), 255), 255);
    EXPECT_EQ(code(clip.at(90, 40, 0), 255), 255) << "both clip";
    EXPECT_LT(tm.at(80, 40, 2), tm.at(90, 40, 2)) << "tone mapped: brighter stays brighter";
    EXPECT_LT(code(tm.at(90, 40, 2), 255), 255);
    EXPECT_GT(tm.at(2, 2, 0), tm.at(2, 2, 1)) << "the red patch stays red";
    // A tone map for a float picture is refused before any work.
    std::string err;
    EXPECT_EQ(conus("decode " + path("u.exr") + " -o " + path("t.exr") + " --bits float --tonemap aces", &err), 2) << err;
    EXPECT_FALSE(fs::exists(path("t.exr")));
}

TEST_F(UserPath, ExifOrientationIsAppliedSoFociReferToTheFrameUsersSee) {
    // Stored 96x64 with Orientation 6: viewers show it turned 90 degrees clockwise, 64x96, with
    // the stored top-left red patch at the top-right.
    OIIO::ImageSpec s = spec(3, OIIO::TypeDesc::UINT8);
    s.attribute("Orientation", 6);
    s.attribute("Make", "CoNUS Test Camera");
    s.attribute("Model", "Model 6");
    const std::string jpg = write("turned.jpg", s, picture(3));
    std::string err;
    ASSERT_EQ(conus("uniform " + jpg + " -o " + path("u.exr") + " --size 64x96", &err), 0) << err;
    ASSERT_EQ(conus("decode " + path("u.exr") + " -o " + path("out.png"), &err), 0) << err;
    const Picture got = readBack(path("out.png"));
    ASSERT_EQ(got.spec.width, 64);
    ASSERT_EQ(got.spec.height, 96);
    EXPECT_GT(got.at(64 - 7, 6, 0), 0.9f) << "red at the top-right, as a viewer shows the JPEG";
    EXPECT_LT(got.at(64 - 7, 6, 2), 0.1f);
    EXPECT_GT(got.at(6, 6, 2), 0.9f) << "blue (stored bottom-left) at the top-left";
    // OpenImageIO's own reorientation of the JPEG agrees pixel for pixel (within JPEG decode rounding).
    OIIO::ImageBuf upright = OIIO::ImageBufAlgo::reorient(OIIO::ImageBuf(jpg));
    ASSERT_EQ(upright.spec().width, 64);
    std::vector<float> want(64 * 96 * 3);
    upright.get_pixels(upright.roi(), OIIO::TypeDesc::FLOAT, want.data());
    int worst = 0;
    for (std::size_t i = 0; i < want.size(); ++i) worst = std::max(worst, std::abs(code(got.pixels[i], 255) - code(want[i], 255)));
    EXPECT_LE(worst, 1);
    // Make and Model travel into the EXR and back out to the JPEG.
    const Picture exr = readBack(path("u.exr"));
    EXPECT_EQ(exr.spec.get_string_attribute("Make"), "CoNUS Test Camera");
    ASSERT_EQ(conus("decode " + path("u.exr") + " -o " + path("out.jpg"), &err), 0) << err;
    const Picture back = readBack(path("out.jpg"));
    EXPECT_EQ(back.spec.get_string_attribute("Model"), "Model 6");
    EXPECT_EQ(back.spec.get_int_attribute("Orientation", 1), 1) << "already upright";
    // --no-auto-orient keeps the stored frame.
    ASSERT_EQ(conus("uniform " + jpg + " -o " + path("raw.exr") + " --size 96x64 --no-auto-orient", &err), 0) << err;
    const Picture raw = readBack(path("raw.exr"));
    EXPECT_EQ(raw.spec.width, 96);
}

TEST_F(UserPath, NonFiniteInputsAreReportedAndRepairedOnRequest) {
    std::vector<float> src(static_cast<std::size_t>(kW) * kH * 3, 0.5f);
    src[(10 * kW + 10) * 3 + 0] = std::nanf("");
    src[(20 * kW + 50) * 3 + 1] = INFINITY;
    const std::string in = write("nan.exr", spec(3, OIIO::TypeDesc::FLOAT), src);
    std::string err;
    ASSERT_EQ(conus("encode " + in + " -o " + path("kept.exr") + " --focus 0.5,0.5,0.2,2", &err), 0) << err;
    EXPECT_NE(err.find("2 NaN or infinite values"), std::string::npos) << err;
    EXPECT_NE(err.find("--fix-nonfinite"), std::string::npos) << err;
    ASSERT_EQ(conus("encode " + in + " -o " + path("fixed.exr") + " --focus 0.5,0.5,0.2,2 --fix-nonfinite box3", &err), 0) << err;
    const Picture fixed = readBack(path("fixed.exr"));
    for (float v : fixed.pixels) ASSERT_TRUE(std::isfinite(v));
    // The repaired values are their neighbours' (0.5), so the whole picture stays 0.5.
    for (float v : fixed.pixels) EXPECT_NEAR(v, 0.5f, 1e-3f);
    // Importance computed from the picture itself never fails on its NaN.
    ASSERT_EQ(conus("encode " + in + " -o " + path("auto.exr") + " --importance detail", &err), 0) << err;
}

TEST_F(UserPath, EveryOutputFormatIsReadableByOpenImageIo) {
    const std::string in = write("in.png", spec(4, OIIO::TypeDesc::UINT8), picture(4));
    std::string err;
    ASSERT_EQ(conus("encode " + in + " -o " + path("c.exr") + " --focus 0.3,0.3,0.1,3 --size 48x32", &err), 0) << err;
    for (const char* ext : {"png", "jpg", "bmp", "tif", "exr", "tga", "ppm", "hdr"}) {
        const std::string out = path(std::string("view.") + ext);
        ASSERT_EQ(conus("decode " + path("c.exr") + " -o " + out + " --view 0,0,0.5,0.5 --size 40x30", &err), 0) << ext << err;
        const Picture got = readBack(out);
        EXPECT_EQ(got.spec.width, 40) << ext;
        // The red patch sits at the top-left of this view in every format.
        const int r = got.spec.channelindex("R"), b = got.spec.channelindex("B");
        ASSERT_GE(r, 0) << ext;
        EXPECT_GT(got.at(3, 3, r), 0.8f) << ext;
        EXPECT_LT(got.at(3, 3, b), 0.2f) << ext;
    }
}

TEST_F(UserPath, ForeignToolsThatResizeEveryPartBreakTheFileAndValidateSaysSo) {
    const std::string in = write("in.png", spec(3, OIIO::TypeDesc::UINT8), picture(3));
    std::string err;
    ASSERT_EQ(conus("encode " + in + " -o " + path("c.exr") + " --focus 0.3,0.3,0.1,3 --size 48x32", &err), 0) << err;
    // oiiotool resizing every part (-a) shrinks the map to one node; without -a it drops the map.
    ASSERT_EQ(std::system(("oiiotool -a " + path("c.exr") + " --resize 50% -o " + path("all.exr") + " >/dev/null 2>&1").c_str()), 0);
    ASSERT_EQ(std::system(("oiiotool " + path("c.exr") + " --resize 50% -o " + path("first.exr") + " >/dev/null 2>&1").c_str()), 0);
    EXPECT_EQ(conus("validate " + path("all.exr"), &err), 1);
    EXPECT_NE(err.find("not a valid CoNUS file"), std::string::npos) << err;
    EXPECT_EQ(conus("validate " + path("first.exr"), &err), 1);
    EXPECT_EQ(conus("decode " + path("first.exr") + " -o " + path("x.png"), &err), 1);
    EXPECT_NE(err.find("V7"), std::string::npos) << err;
}
