// imageio: channels placed by name in any order, colour converted through OpenImageIO, formats'
// limits said up front. Files are read back with OpenImageIO directly, never through imageio.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "test_dir.h"
#include "conus/core/error.h"
#include "conus/imageio/image_file.h"

namespace fs = std::filesystem;
using conus::Image;

namespace {

class ImageFileTest : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return m_folder.file(name); }
    conus::test::TestDir m_folder{"conus-imageio"};
    const fs::path& m_dir = m_folder.path();
};

struct Read {
    OIIO::ImageSpec spec;
    std::vector<float> pixels;
};

Read oiioRead(const std::string& path) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    Read r;
    if (!in) return r;
    r.spec = in->spec();
    r.pixels.resize(static_cast<std::size_t>(r.spec.width) * r.spec.height * r.spec.nchannels);
    in->read_image(0, 0, 0, r.spec.nchannels, OIIO::TypeDesc::FLOAT, r.pixels.data());
    return r;
}

// A 4x2 image whose channel c at pixel p holds (p + 1) / 16 + c / 64: every value tells where it came from.
Image tagged(const std::vector<std::string>& channels) {
    Image im = conus::makeImage(4, 2, channels);
    for (int p = 0; p < 8; ++p)
        for (int c = 0; c < im.channelCount(); ++c) im.pixels[p * im.channelCount() + c] = (p + 1) / 16.0f + c / 64.0f;
    return im;
}

}  // namespace

TEST_F(ImageFileTest, DisplayFormatsGetRgbaByNameWhateverTheOrder) {
    const std::vector<std::vector<std::string>> orders = {
        {"B", "G", "R"}, {"A", "B", "G", "R"}, {"Z", "G", "A", "R", "B"}, {"R", "G", "B", "A"}};
    for (const auto& order : orders) {
        const Image im = tagged(order);
        conus::imageio::WriteOptions raw;
        raw.meaning = conus::imageio::PixelMeaning::Raw;  // values as they are, to trace them
        conus::imageio::writeImageFile(path("out.png"), im, raw);
        const Read got = oiioRead(path("out.png"));
        const bool alpha = im.channelIndex("A") >= 0;
        ASSERT_EQ(got.spec.nchannels, alpha ? 4 : 3);
        const char* names[] = {"R", "G", "B", "A"};
        for (int p = 0; p < 8; ++p)
            for (int c = 0; c < got.spec.nchannels; ++c) {
                const float want = im.pixels[p * im.channelCount() + im.channelIndex(names[c])];
                EXPECT_NEAR(got.pixels[p * got.spec.nchannels + c], want, 1.0 / 255) << names[c] << " of order " << order[0];
            }
    }
}

TEST_F(ImageFileTest, GreyAndGreyAlphaAndNamelessChannels) {
    conus::imageio::WriteOptions raw;
    raw.meaning = conus::imageio::PixelMeaning::Raw;
    conus::imageio::writeImageFile(path("ya.png"), tagged({"A", "Y"}), raw);
    Read got = oiioRead(path("ya.png"));
    ASSERT_EQ(got.spec.nchannels, 2);
    EXPECT_EQ(got.spec.alpha_channel, 1);
    EXPECT_NEAR(got.pixels[0], 1 / 16.0f + 1 / 64.0f, 0.5 / 255) << "Y first";
    EXPECT_NEAR(got.pixels[1], 1 / 16.0f, 0.5 / 255) << "then A";
    // A sampling map's channels have no colour names: the first one is shown as grey.
    conus::imageio::writeImageFile(path("uv.png"), tagged({"ud", "vd"}), raw);
    got = oiioRead(path("uv.png"));
    ASSERT_EQ(got.spec.nchannels, 1);
    EXPECT_NEAR(got.pixels[0], 1 / 16.0f, 0.5 / 255);
}

TEST_F(ImageFileTest, SixtyFourChannelsSurviveExrAndTiff) {
    std::vector<std::string> names;
    for (int c = 0; c < 64; ++c) names.push_back(std::string(1, 'c').append(std::to_string(c)));
    const Image im = tagged(names);
    for (const char* ext : {"exr", "tif"}) {
        conus::imageio::WriteOptions options;
        options.meaning = conus::imageio::PixelMeaning::Raw;
        options.sampleType = conus::SampleType::Float;
        conus::imageio::writeImageFile(path(std::string("many.") + ext), im, options);
        const Read got = oiioRead(path(std::string("many.") + ext));
        ASSERT_EQ(got.spec.nchannels, 64) << ext;
        const conus::imageio::ImageFile back = conus::imageio::readImageFile(path(std::string("many.") + ext));
        ASSERT_EQ(back.image.channelCount(), 64);
        for (int c = 0; c < 64; ++c) {
            const int k = back.image.channelIndex(got.spec.channel_name(c));
            ASSERT_GE(k, 0) << got.spec.channel_name(c);
        }
    }
}

TEST_F(ImageFileTest, SrgbIsConvertedThroughOpenImageIoAndRawIsNot) {
    // An 8-bit file of code 128 everywhere, written by OpenImageIO.
    {
        auto out = OIIO::ImageOutput::create(path("mid.png"));
        OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::UINT8);
        std::vector<unsigned char> bytes(48, 128);
        ASSERT_TRUE(out->open(path("mid.png"), spec));
        out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
        out->close();
    }
    const conus::imageio::ImageFile srgb = conus::imageio::readImageFile(path("mid.png"));
    EXPECT_EQ(srgb.info.encoding.transfer, conus::Transfer::Srgb);
    EXPECT_EQ(srgb.info.encoding.sampleType, conus::SampleType::Uint8);
    EXPECT_NEAR(srgb.image.pixels[0], std::pow((128 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
    conus::imageio::ReadOptions raw;
    raw.colorspace = conus::Transfer::Raw;
    EXPECT_FLOAT_EQ(conus::imageio::readImageFile(path("mid.png"), raw).image.pixels[0], 128 / 255.0f);
    // linearize and displayEncoded undo each other.
    Image drawn = tagged({"R", "G", "B"});
    const Image before = drawn;
    conus::imageio::linearize(drawn);
    EXPECT_LT(drawn.pixels[0], before.pixels[0]);
    const Image shown = conus::imageio::displayEncoded(drawn);
    for (std::size_t i = 0; i < before.pixels.size(); ++i) EXPECT_NEAR(shown.pixels[i], before.pixels[i], 1e-5);
}

// 8- and 16-bit files without alpha are read through per-value tables (image_read.cpp) instead of
// converting a float copy in place: every pixel must equal what OpenImageIO's own float read and
// colour conversion give, to the bit, across several strips of rows and every sample value.
// TIFF: plain PNGs are read with libpng instead (png_direct_test.cpp compares those paths).
TEST_F(ImageFileTest, IntegerSamplesThroughTablesEqualOpenImageIoToTheBit) {
    struct Case {
        const char* name;
        int channels;
        OIIO::TypeDesc type;
        bool srgb;
    };
    for (const Case& k : {Case{"rgb8.tif", 3, OIIO::TypeDesc::UINT8, true}, Case{"grey16.tif", 1, OIIO::TypeDesc::UINT16, true},
                          Case{"rgb16raw.tif", 3, OIIO::TypeDesc::UINT16, false}}) {
        SCOPED_TRACE(k.name);
        const int w = 97, h = 150;  // 150 rows: three strips of 64, the last one short
        const int top = k.type == OIIO::TypeDesc::UINT8 ? 255 : 65535;
        std::vector<unsigned short> values(static_cast<std::size_t>(w) * h * k.channels);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < k.channels; ++c)  // every value, in no simple order
                    values[(static_cast<std::size_t>(y) * w + x) * k.channels + c] =
                        static_cast<unsigned short>((x * 7919L + y * 104729L + c * 31L + x * y) % (top + 1));
        {
            auto out = OIIO::ImageOutput::create(path(k.name));
            ASSERT_TRUE(out->open(path(k.name), OIIO::ImageSpec(w, h, k.channels, k.type)));
            ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT16, values.data()));
            ASSERT_TRUE(out->close());
        }
        conus::imageio::ReadOptions options;
        if (!k.srgb) options.colorspace = conus::Transfer::Raw;
        const conus::imageio::ImageFile read = conus::imageio::readImageFile(path(k.name), options);

        Read expected = oiioRead(path(k.name));
        ASSERT_EQ(expected.pixels.size(), read.image.pixels.size());
        if (k.srgb) {
            OIIO::ImageBuf buffer(OIIO::ImageSpec(w, h, k.channels, OIIO::TypeDesc::FLOAT), expected.pixels.data());
            ASSERT_TRUE(OIIO::ImageBufAlgo::colorconvert(buffer, buffer, "sRGB", "linear", false));
        }
        std::size_t differ = 0;
        for (std::size_t i = 0; i < expected.pixels.size(); ++i) differ += expected.pixels[i] != read.image.pixels[i];
        EXPECT_EQ(differ, 0u);
        EXPECT_EQ(read.info.nonFinite, 0);
        // Not a table of zeros or of the raw codes: dark stays dark, linear light is below the code.
        const std::size_t mid = (static_cast<std::size_t>(h / 2) * w + w / 3) * k.channels;
        const float code = float(values[mid]) / top;
        if (k.srgb && code > 0.1f) EXPECT_LT(read.image.pixels[mid], code);
        if (!k.srgb) EXPECT_FLOAT_EQ(read.image.pixels[mid], code);
    }
}

TEST_F(ImageFileTest, RequestsAFormatCannotHoldAreRefusedBeforeWriting) {
    conus::imageio::WriteOptions floatPng;
    floatPng.sampleType = conus::SampleType::Float;
    try {
        conus::imageio::checkImageOutput(path("x.png"), floatPng);
        FAIL();
    } catch (const conus::Error& e) {
        EXPECT_EQ(e.code(), conus::ErrorCode::InvalidArgument);
        EXPECT_NE(std::string(e.what()).find("uint8 or uint16"), std::string::npos) << e.what();
    }
    EXPECT_THROW(conus::imageio::checkImageOutput(path("x.xyz")), conus::Error);
    EXPECT_THROW(conus::imageio::checkImageOutput(path("noextension")), conus::Error);
    EXPECT_NO_THROW(conus::imageio::checkImageOutput(path("x.exr"), floatPng));
    EXPECT_TRUE(fs::is_empty(m_dir)) << "checks write nothing";
}

TEST_F(ImageFileTest, UnreadableFilesSayWhy) {
    { std::ofstream(path("bad.png")) << "not a png at all"; }
    try {
        conus::imageio::readImageFile(path("bad.png"));
        FAIL();
    } catch (const conus::Error& e) {
        EXPECT_NE(std::string(e.what()).find(path("bad.png")), std::string::npos) << e.what();
    }
    // A PPM that ends early: the reason is named, not left empty.
    { std::ofstream(path("short.ppm")) << "P6\n64 64\n255\n" << std::string(100, '\x7f'); }
    try {
        conus::imageio::readImageFile(path("short.ppm"));
        FAIL();
    } catch (const conus::Error& e) {
        const std::string what = e.what();
        EXPECT_GT(what.size(), what.find("cannot read pixels: ") + 20) << what;
    }
    EXPECT_THROW(conus::imageio::readImageFile("/dev/zero"), conus::Error);
}

namespace {

// A 3-channel picture of varied linear values: every octave from 1e-6 to 1 (dense near the sRGB
// curve's linear end), negatives, values past 1 and non-finite ones, each channel different.
Image variedLinear() {
    Image im;
    im.width = 997;
    im.height = 13;
    im.channels = {"G", "B", "R", "Z"};  // colour not leading, and one data channel
    im.pixels.resize(static_cast<std::size_t>(im.width) * im.height * 4);
    for (std::size_t i = 0; i < im.pixels.size(); ++i) {
        const double t = static_cast<double>((i * 7919) % 100003) / 100003.0;
        im.pixels[i] = static_cast<float>(std::pow(10.0, -6.0 + 6.2 * t));
    }
    const float odd[] = {-0.25f, 0.0f, 0.0031308f, 0.00313f, 1.0f, 1.5f, NAN, INFINITY, -INFINITY};
    for (std::size_t k = 0; k < std::size(odd); ++k)
        for (int c = 0; c < 4; ++c) im.pixels[(k * 5 + c) * 4 + c] = odd[k];
    return im;
}

}  // namespace

// Without alpha, displayEncoded takes the sRGB curve from its own table (no OpenImageIO): the
// same values, within 1e-6, as the exact curve in double and (within OpenImageIO's own
// approximation) as OpenImageIO's colorconvert; data channels are kept, non-finite values 0.
TEST(DisplayEncoded, OpaquePictureMatchesTheSrgbCurveAndOpenImageIO) {
    const Image linear = variedLinear();
    const Image shown = conus::imageio::displayEncoded(linear);
    ASSERT_EQ(shown.channels, linear.channels);
    ASSERT_EQ(shown.pixels.size(), linear.pixels.size());
    // OpenImageIO's conversion of the colour channels, gathered to lead the buffer (R, G, B).
    const std::size_t count = static_cast<std::size_t>(linear.width) * linear.height;
    std::vector<float> rgb(count * 3);
    const int order[3] = {2, 0, 1};
    for (std::size_t p = 0; p < count; ++p)
        for (int k = 0; k < 3; ++k) {
            const float v = linear.pixels[p * 4 + order[k]];
            rgb[p * 3 + k] = std::isfinite(v) ? v : 0.0f;
        }
    OIIO::ImageBuf buffer(OIIO::ImageSpec(linear.width, linear.height, 3, OIIO::TypeDesc::FLOAT), rgb.data());
    ASSERT_TRUE(OIIO::ImageBufAlgo::colorconvert(buffer, buffer, "linear", "sRGB"));
    double worstExact = 0, worstOiio = 0;
    for (std::size_t p = 0; p < count; ++p) {
        for (int k = 0; k < 3; ++k) {
            const float v = linear.pixels[p * 4 + order[k]];
            const double x = std::isfinite(v) ? v : 0.0;
            const double exact = std::clamp(x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055, 0.0, 1.0);
            const float got = shown.pixels[p * 4 + order[k]];
            worstExact = std::max(worstExact, std::abs(got - exact));
            worstOiio = std::max(worstOiio, std::abs(double(got) - std::clamp(rgb[p * 3 + k], 0.0f, 1.0f)));
        }
        const float z = linear.pixels[p * 4 + 3];
        EXPECT_EQ(shown.pixels[p * 4 + 3], std::isfinite(z) ? z : 0.0f) << p;
    }
    std::printf("[ info ] display encode against the exact sRGB curve: %.2g, against OpenImageIO: %.2g\n", worstExact,
                worstOiio);
    EXPECT_LT(worstExact, 1e-6);
    EXPECT_LT(worstOiio, 2e-5);
}
