// Standard input as the tools read it, through the real binary: a picture piped in, and streams
// that never end or are no picture (/dev/zero, text, nothing), which must be refused in one line
// at once, not after reading gigabytes; a list of inputs read from standard input alike.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <fstream>

#include "hostile_fixture.h"

namespace {

using namespace conus::hostile;

using StdinHostile = Hostile;

TEST_F(StdinHostile, EndlessOrForeignStreamsAreRefusedAtOnce) {
    std::string text;
    while (text.size() < (4u << 20)) text += "hello, this is a log file and no picture at all\n";
    write("log.txt", text);
    const struct {
        std::string stdinFile;
        const char* reason;
    } cases[] = {
        {"/dev/zero", "standard input is not an image format"},
        {path("log.txt"), "standard input is not an image format"},
        {"/dev/null", "standard input is empty"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.stdinFile);
        for (const char* command : {"encode", "uniform"}) {
            const Outcome r = runTool("conus", {command, "-", "-o", path("x.exr"), "--size", "16x12"}, c.stdinFile);
            expectRefused(r, command, c.reason);
            expectBounded(r, 300);
            EXPECT_FALSE(fs::exists(path("x.exr")));
        }
    }
    // A list of inputs on standard input: /dev/zero has no line end, and is refused by its length.
    const Outcome r = runTool("conus", {"encode", "--list", "-", "--out-dir", path("out"), "--size", "16x12"}, "/dev/zero");
    expectRefused(r, "encode", "is longer than");
    expectMemory(r, 300);
    EXPECT_LT(r.seconds, 20.0 * conus::testing::kTimeScale);
    EXPECT_FALSE(fs::exists(path("out")) && !fs::is_empty(path("out")));
}

// A stream that starts like a picture and never ends (a header, then gigabytes of zeros: a sparse
// file here) is refused once it runs past what its header's picture can take, without keeping
// more; a picture of each kind piped in whole still reads. PNG, JPEG, BMP and PNM give their size
// in their first 200 bytes; a TIFF in its directory (after the pixels, as OpenImageIO writes it),
// OpenEXR and Radiance HDR in their headers: of those the whole picture comes before the zeros.
TEST_F(StdinHostile, APictureHeaderFollowedByEndlessBytesIsRefusedByWhatItDeclares) {
    std::vector<unsigned char> ramp(std::size_t(40) * 30 * 3);
    for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = static_cast<unsigned char>(i * 7 % 251);
    for (const std::string ext : {"png", "jpg", "bmp", "ppm", "tif", "exr", "hdr"}) {
        SCOPED_TRACE(ext);
        const std::string picture = path("ramp." + ext);
        {
            auto out = OIIO::ImageOutput::create(picture);
            ASSERT_TRUE(out);
            ASSERT_TRUE(out->open(picture, OIIO::ImageSpec(40, 30, 3, OIIO::TypeDesc::UINT8)));
            ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, ramp.data()));
            out->close();
        }
        Outcome r = runTool("conus", {"uniform", "-", "-o", path("piped.exr"), "--size", "20x15"}, picture);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        // The same file's header, then zeros up to 6 GiB, read by no disk.
        const bool headerFirst = ext == "png" || ext == "jpg" || ext == "bmp" || ext == "ppm";
        std::string head(headerFirst ? 200 : fs::file_size(picture), '\0');
        std::ifstream(picture, std::ios::binary).read(head.data(), std::streamsize(head.size()));
        const std::string endless = path("endless." + ext);
        std::ofstream(endless, std::ios::binary).write(head.data(), std::streamsize(head.size()));
        fs::resize_file(endless, std::uintmax_t{6} << 30);
        r = runTool("conus", {"encode", "-", "-o", path("x.exr"), "--size", "16x12"}, endless);
        expectRefused(r, "encode", "a 40x30");
        EXPECT_TRUE(contains(r.err, "can take")) << r.err;
        expectMemory(r, 400);
        EXPECT_FALSE(fs::exists(path("x.exr")));
    }
}

// Where the first bytes do not give the size (a BigTIFF, whose directory CoNUS does not walk) a
// stream is held to 256 MiB; a TIFF whose directory lies past that is refused at its first bytes,
// one whose directory holds no picture is refused there, and an OpenEXR header whose attribute
// declares more than a header may hold at once. A BigTIFF piped in whole still reads.
TEST_F(StdinHostile, AStreamWhoseHeaderGivesNoSizeIsHeldToAFewHundredMegabytes) {
    std::vector<unsigned char> ramp(std::size_t(40) * 30 * 3);
    for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = static_cast<unsigned char>(i * 5 % 253);
    const std::string big = path("big.tif");
    {
        auto out = OIIO::ImageOutput::create(big);
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(40, 30, 3, OIIO::TypeDesc::UINT8);
        spec.attribute("tiff:bigtiff", 1);
        ASSERT_TRUE(out->open(big, spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, ramp.data()));
        out->close();
    }
    ASSERT_EQ(slurp(big).substr(0, 4), std::string("II+\0", 4));
    Outcome r = runTool("conus", {"uniform", "-", "-o", path("piped.exr"), "--size", "20x15"}, big);
    EXPECT_EQ(r.exitCode, 0) << r.err;

    const auto endless = [&](const std::string& name, const std::string& head) {
        std::ofstream(path(name), std::ios::binary).write(head.data(), std::streamsize(head.size()));
        fs::resize_file(path(name), std::uintmax_t{6} << 30);
        return path(name);
    };
    // A TIFF's first directory is at the 32-bit offset after its byte order and 42.
    const auto tiffTo = [](std::uint32_t at) {
        std::string head("II*\0", 4);
        for (int i = 0; i < 4; ++i) head += static_cast<char>(at >> (8 * i) & 0xff);
        return head;
    };
    const struct {
        std::string stdinFile;
        const char* reason;
        long maxMb;
    } cases[] = {
        {endless("endless-big.tif", slurp(big).substr(0, 16)), "holds more than 256 MiB; give a file instead", 500},
        {endless("far.tif", tiffTo(0x7fff0000u)), "first directory is at byte 2147418112", 300},
        {endless("empty-directory.tif", tiffTo(64u << 20)), "gives no width or length", 400},
        // An OpenEXR header whose attribute declares 1 GiB (its name, type, then the size).
        {endless("huge-attribute.exr", std::string("\x76\x2f\x31\x01\x02\0\0\0comments\0string\0\0\0\0\x40", 28)),
         "has an attribute of 1073741824 bytes", 300},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.stdinFile);
        r = runTool("conus", {"encode", "-", "-o", path("x.exr"), "--size", "16x12"}, c.stdinFile);
        expectRefused(r, "encode", c.reason);
        expectMemory(r, c.maxMb);
        EXPECT_FALSE(fs::exists(path("x.exr")));
    }
}

TEST_F(StdinHostile, APicturePipedInIsReadAsFromItsFile) {
    // A 24x16 PNG of a horizontal ramp, written by OpenImageIO.
    const int w = 24, h = 16;
    std::vector<unsigned char> ramp(std::size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) ramp[(std::size_t(y) * w + x) * 3 + c] = static_cast<unsigned char>(x * 10 + c * 20 + y);
    {
        auto out = OIIO::ImageOutput::create(path("ramp.png"));
        ASSERT_TRUE(out);
        ASSERT_TRUE(out->open(path("ramp.png"), OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::UINT8)));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, ramp.data()));
        out->close();
    }
    Outcome r = runTool("conus", {"uniform", "-", "-o", path("piped.exr"), "--size", "12x8"}, path("ramp.png"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = run({"uniform", path("ramp.png"), "-o", path("named.exr"), "--size", "12x8"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto pixels = [](const std::string& file) {
        auto in = OIIO::ImageInput::open(file);
        std::vector<float> values;
        if (!in) return values;
        values.resize(std::size_t(in->spec().image_pixels()) * in->spec().nchannels);
        if (!in->read_image(0, 0, 0, in->spec().nchannels, OIIO::TypeDesc::FLOAT, values.data())) values.clear();
        return values;
    };
    const std::vector<float> piped = pixels(path("piped.exr")), named = pixels(path("named.exr"));
    ASSERT_FALSE(piped.empty());
    ASSERT_EQ(piped.size(), named.size());
    // A file goes to CoNUS's own PNG reader, standard input to OpenImageIO's: their sRGB curves
    // agree within 1e-5, which the half-float samples may round one step apart (2^-11 relative).
    for (std::size_t i = 0; i < piped.size(); ++i) EXPECT_NEAR(piped[i], named[i], 1e-3 * std::max(1.0f, named[i])) << i;
    EXPECT_NE(*std::min_element(piped.begin(), piped.end()), *std::max_element(piped.begin(), piped.end()));
}

}  // namespace
