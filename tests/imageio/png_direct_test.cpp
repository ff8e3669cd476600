// The libpng reader (imageio/src/png_direct_pvt.h) against the OpenImageIO path it stands in for: the
// same pixels, channel names and encoding on the PNGs it takes, and the OpenImageIO path (same
// result as before) for every PNG it must not take.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "../../imageio/src/oiio_module_pvt.h"
#include "../../imageio/src/png_direct_pvt.h"
#include "conus/core/error.h"
#include "conus/imageio/image_file.h"
#include "test_dir.h"

using namespace conus;

namespace {

class PngDirectTest : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return m_folder.file(name); }
    test::TestDir m_folder{"conus-png-direct"};
};

// A width x height PNG of `channels` samples of `type`, every sample value of the type present
// (8 bits: all 256 in each channel; 16 bits: 0, 65535 and random ones), written by OpenImageIO.
void writePng(const std::string& file, int width, int height, int channels, OIIO::TypeDesc type,
              const std::vector<std::pair<std::string, std::string>>& text = {}) {
    std::mt19937 random(static_cast<unsigned>(width * 131 + height * 7 + channels));
    const std::size_t n = static_cast<std::size_t>(width) * height * channels;
    auto output = OIIO::ImageOutput::create(file);
    ASSERT_TRUE(output);
    OIIO::ImageSpec spec(width, height, channels, type);
    for (const auto& [name, value] : text) spec.attribute(name, value);
    ASSERT_TRUE(output->open(file, spec)) << output->geterror();
    if (type == OIIO::TypeDesc::UINT8) {
        std::vector<unsigned char> s(n);
        for (std::size_t i = 0; i < n; ++i) s[i] = static_cast<unsigned char>((i / channels * 7 + i % channels * 85) % 256);
        ASSERT_TRUE(output->write_image(type, s.data()));
    } else {
        std::vector<std::uint16_t> s(n);
        for (std::size_t i = 0; i < n; ++i) s[i] = static_cast<std::uint16_t>(random());
        s[0] = 0;
        s[n - 1] = 65535;
        ASSERT_TRUE(output->write_image(type, s.data()));
    }
    ASSERT_TRUE(output->close());
}

// OpenImageIO's sRGB curve is a fast float approximation (1.4e-5 relative at worst, measured);
// ours is the standard's formula in double, rounded once. Both are far inside what the stored
// half keeps (4.9e-4) and what one 8-bit code step spans (0.5% or more).
constexpr double kSrgbTolerance = 2e-5;

// The largest difference between the two reads' pixels, relative to max(1e-3, |reference|).
double largestRelativeDifference(const Image& a, const Image& reference) {
    double worst = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
        worst = std::max(worst, std::abs(double(a.pixels[i]) - reference.pixels[i]) /
                                    std::max(1e-3, std::abs(double(reference.pixels[i]))));
    return worst;
}

void expectSameRead(const std::string& file, const imageio::ReadOptions& options, double tolerance) {
    SCOPED_TRACE(file);
    const std::optional<imageio::ImageFile> direct = imageio::readPngDirect(file, options);
    ASSERT_TRUE(direct) << "the libpng reader did not take a plain PNG";
    const imageio::ImageFile reference = imageio::oiioFunctions().readImageFile(file, options);
    EXPECT_EQ(direct->info.format, reference.info.format);
    EXPECT_EQ(direct->info.encoding, reference.info.encoding);
    EXPECT_EQ(direct->info.parts, reference.info.parts);
    EXPECT_EQ(direct->info.orientation, reference.info.orientation);
    EXPECT_EQ(direct->info.oriented, reference.info.oriented);
    EXPECT_EQ(direct->info.nonFinite, reference.info.nonFinite);
    ASSERT_EQ(direct->image.width, reference.image.width);
    ASSERT_EQ(direct->image.height, reference.image.height);
    ASSERT_EQ(direct->image.channels, reference.image.channels);
    ASSERT_EQ(direct->image.pixels.size(), reference.image.pixels.size());
    const double worst = largestRelativeDifference(direct->image, reference.image);
    EXPECT_LE(worst, tolerance);
    ::testing::Test::RecordProperty("largest_relative_difference", std::to_string(worst));
}

}  // namespace

TEST_F(PngDirectTest, TakesPlainPngsAndReadsWhatOpenImageIoReads) {
    // Asymmetric sizes, grey and RGB, 8 and 16 bits; 8-bit 37x23 holds every value in each channel.
    struct Case {
        const char* name;
        int width, height, channels;
        OIIO::TypeDesc type;
        std::vector<std::pair<std::string, std::string>> text;
    };
    const Case cases[] = {
        {"rgb8.png", 37, 23, 3, OIIO::TypeDesc::UINT8, {{"Software", "conus test"}}},
        {"grey8.png", 29, 41, 1, OIIO::TypeDesc::UINT8, {}},
        {"rgb16.png", 53, 17, 3, OIIO::TypeDesc::UINT16, {}},
        {"grey16.png", 19, 61, 1, OIIO::TypeDesc::UINT16, {}},
        // Carried metadata (tEXt and tIME chunks), in an order of its own.
        {"tagged.png", 31, 11, 3, OIIO::TypeDesc::UINT8,
         {{"Exif:ImageHistory", "made for a test"}, {"Artist", "A. Tester"}, {"ImageDescription", "a caption"},
          {"Comment", "not carried"}, {"DateTime", "2026:11:24 05:30:00"}, {"Copyright", "none"}}},
        // Tagged linear: read without the sRGB curve by both paths.
        {"linear16.png", 23, 13, 1, OIIO::TypeDesc::UINT16, {{"oiio:ColorSpace", "linear"}}},
    };
    for (const Case& c : cases) {
        const std::string file = path(c.name);
        ASSERT_NO_FATAL_FAILURE(writePng(file, c.width, c.height, c.channels, c.type, c.text));
        imageio::ReadOptions options;  // as the file says: sRGB (converted to linear light) or linear
        expectSameRead(file, options, kSrgbTolerance);
        options.colorspace = Transfer::Linear;  // integer values as they are, exactly
        expectSameRead(file, options, 0);
        options.colorspace = Transfer::Raw;
        expectSameRead(file, options, 0);
    }
    const imageio::ImageFile tagged = imageio::readImageFile(path("tagged.png"));
    EXPECT_EQ(tagged.info.encoding.metadata.size(), 5u);  // all but the comment
    EXPECT_EQ(imageio::readImageFile(path("linear16.png")).info.encoding.transfer, Transfer::Linear);
}

// keepCodes: a plain 8-bit sRGB PNG read as its codes, whose values through the sRGB curve (computed
// as the float read computes it) are that read's pixels exactly; any other file reads as floats.
TEST_F(PngDirectTest, KeepsTheCodesOfAn8BitSrgbPng) {
    ASSERT_NO_FATAL_FAILURE(writePng(path("codes8.png"), 37, 23, 3, OIIO::TypeDesc::UINT8, {}));
    ASSERT_NO_FATAL_FAILURE(writePng(path("codes16.png"), 19, 11, 3, OIIO::TypeDesc::UINT16, {}));
    imageio::ReadOptions options;
    const imageio::ImageFile floats = imageio::readImageFile(path("codes8.png"), options);
    options.keepCodes = true;
    const imageio::ImageFile codes = imageio::readImageFile(path("codes8.png"), options);
    EXPECT_TRUE(codes.image.pixels.empty());
    EXPECT_EQ(codes.image.width, 37);
    EXPECT_EQ(codes.image.height, 23);
    EXPECT_EQ(codes.image.channels, floats.image.channels);
    EXPECT_EQ(codes.info.encoding, floats.info.encoding);
    ASSERT_EQ(codes.codes.size(), floats.image.pixels.size());
    for (std::size_t i = 0; i < codes.codes.size(); ++i)
        ASSERT_EQ(imageio::srgbToLinear(static_cast<float>(codes.codes[i]) * (1.0f / 255.0f)), floats.image.pixels[i]) << i;
    const imageio::ImageFile wide = imageio::readImageFile(path("codes16.png"), options);
    EXPECT_TRUE(wide.codes.empty());
    EXPECT_EQ(wide.image.pixels.size(), std::size_t{19} * 11 * 3);
    options.colorspace = Transfer::Linear;  // not sRGB: floats
    EXPECT_TRUE(imageio::readImageFile(path("codes8.png"), options).codes.empty());
}

// A real photograph as a camera pipeline leaves it: an ICC profile (iCCP), gAMA, cHRM, pHYs and
// text chunks (scikit-image's astronaut, from the Debian package the benchmarks use).
TEST_F(PngDirectTest, ReadsAPhotographWithItsProfileAsOpenImageIoDoes) {
    const std::string photo = "/usr/lib/python3/dist-packages/skimage/data/astronaut.png";
    ASSERT_TRUE(std::filesystem::exists(photo)) << photo << " is missing (Debian python3-skimage, scripts/packages.txt)";
    expectSameRead(photo, {}, kSrgbTolerance);
    const imageio::ImageFile read = imageio::readImageFile(photo);
    EXPECT_FALSE(read.info.encoding.iccProfile.empty());
}

TEST_F(PngDirectTest, LeavesEveryOtherPngToOpenImageIo) {
    const std::string xmp = path("xmp.png");
    ASSERT_NO_FATAL_FAILURE(writePng(xmp, 16, 12, 3, OIIO::TypeDesc::UINT8, {{"XML:com.adobe.xmp", "<x:xmpmeta/>"}}));
    const std::string alpha = path("alpha.png");
    ASSERT_NO_FATAL_FAILURE(writePng(alpha, 16, 12, 4, OIIO::TypeDesc::UINT8));
    const std::string greyAlpha = path("grey-alpha.png");
    ASSERT_NO_FATAL_FAILURE(writePng(greyAlpha, 16, 12, 2, OIIO::TypeDesc::UINT16));
    const std::string plain = path("plain.png");
    ASSERT_NO_FATAL_FAILURE(writePng(plain, 16, 12, 3, OIIO::TypeDesc::UINT8));
    EXPECT_TRUE(imageio::readPngDirect(plain, {}));
    // XMP decodes into many attributes; alpha is associated in linear light: OpenImageIO's path.
    EXPECT_FALSE(imageio::readPngDirect(xmp, {}));
    EXPECT_FALSE(imageio::readPngDirect(alpha, {}));
    EXPECT_FALSE(imageio::readPngDirect(greyAlpha, {}));
    EXPECT_EQ(imageio::readImageFile(xmp).image.channelCount(), 3);
    EXPECT_EQ(imageio::readImageFile(alpha).image.channelCount(), 4);
    EXPECT_EQ(imageio::readImageFile(greyAlpha).image.channels, (std::vector<std::string>{"Y", "A"}));
    // A part other than the first: the OpenImageIO path words that.
    imageio::ReadOptions part;
    part.part = "1";
    EXPECT_FALSE(imageio::readPngDirect(plain, part));
    EXPECT_THROW(imageio::readImageFile(plain, part), Error);

    // Limits: past them the OpenImageIO path refuses with its own words.
    imageio::ReadOptions small;
    small.limits.maxPixels = 100;
    EXPECT_FALSE(imageio::readPngDirect(plain, small));
    EXPECT_THROW(imageio::readImageFile(plain, small), Error);
}

TEST_F(PngDirectTest, ADamagedPngIsAnErrorNotACrash) {
    const std::string plain = path("plain.png");
    ASSERT_NO_FATAL_FAILURE(writePng(plain, 64, 48, 3, OIIO::TypeDesc::UINT16));  // random: ~18 KB
    std::ifstream in(plain, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 200u);
    // Cut short inside the image data, and a flipped byte inside it (its CRC no longer holds).
    const std::string cut = path("cut.png");
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() - 60);
    std::string flipped = bytes;
    flipped[flipped.size() - 40] = static_cast<char>(flipped[flipped.size() - 40] ^ 0x5A);
    const std::string bad = path("bad.png");
    std::ofstream(bad, std::ios::binary) << flipped;
    for (const std::string& file : {cut, bad}) {
        SCOPED_TRACE(file);
        EXPECT_FALSE(imageio::readPngDirect(file, {}));
        try {
            imageio::readImageFile(file);
            ADD_FAILURE() << "a damaged PNG was read";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::Io) << e.what();
        }
    }
}

TEST(PngDirect, SrgbCurveMeetsItsDefinition) {
    EXPECT_EQ(imageio::srgbToLinear(0.0), 0.0f);
    EXPECT_EQ(imageio::srgbToLinear(1.0), 1.0f);
    EXPECT_FLOAT_EQ(imageio::srgbToLinear(0.04045), static_cast<float>(0.04045 / 12.92));
    EXPECT_NEAR(imageio::srgbToLinear(0.5), 0.214041, 1e-6);  // ((0.5 + 0.055) / 1.055)^2.4
    // Continuous at the junction of its two pieces, and increasing.
    EXPECT_NEAR(imageio::srgbToLinear(0.04045 + 1e-9), imageio::srgbToLinear(0.04045), 1e-7);
    for (int v = 1; v < 256; ++v) EXPECT_LT(imageio::srgbToLinear((v - 1) / 255.0), imageio::srgbToLinear(v / 255.0));
}
