// Writing and reading CoNUS files: round trips, atomic writes, error codes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>

#include "conus/core/map_rules.h"
#include "test_files.h"

namespace conus::format {
namespace {

using testing::TempDir;
using testing::errorFrom;
using testing::validFile;

std::uint32_t bits(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, sizeof b);
    return b;
}

void expectBitExact(const std::vector<float>& a, const std::vector<float>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(bits(a[i]), bits(b[i])) << "value " << i;
}

TEST(Container, FloatRoundTripIsBitExact) {
    TempDir dir;
    ConusFile f = validFile(PixelType::Float);
    f.image.pixels[3] = -0.0f;
    f.image.pixels[5] = 1e-30f;  // a float denormal-free tiny value, lost in half
    writeConusFile(dir.file("a.exr"), f);
    const ConusFile g = readConusFile(dir.file("a.exr"));
    EXPECT_EQ(g.image.width, 8);
    EXPECT_EQ(g.image.height, 6);
    EXPECT_EQ(g.image.channels, f.image.channels);
    expectBitExact(g.image.pixels, f.image.pixels);
    expectBitExact(g.map.xy, f.map.xy);
    EXPECT_EQ(g.map.columns, 5);
    EXPECT_EQ(g.map.rows, 4);
    EXPECT_EQ(g.pixelType, PixelType::Float);
    EXPECT_EQ(g.compression, Compression::Zip);
    EXPECT_EQ(g.sourceWidth, 16);
    EXPECT_EQ(g.sourceHeight, 12);
    EXPECT_EQ(g.dataKind, DataKind::Image);
    EXPECT_FALSE(g.analytic.has_value());
    EXPECT_FALSE(g.camera.has_value());
    EXPECT_EQ(g.depth.kind, DepthKind::None);
    EXPECT_EQ(g.software, format::kSoftwareName);
    EXPECT_TRUE(validateConusFile(dir.file("a.exr")).ok());
}

TEST(Container, HalfRoundTripWithinHalfPrecision) {
    TempDir dir;
    const ConusFile f = validFile(PixelType::Half);
    writeConusFile(dir.file("h.exr"), f);
    const ConusFile g = readConusFile(dir.file("h.exr"));
    EXPECT_EQ(g.pixelType, PixelType::Half);
    ASSERT_EQ(g.image.pixels.size(), f.image.pixels.size());
    for (std::size_t i = 0; i < f.image.pixels.size(); ++i) {
        EXPECT_NEAR(g.image.pixels[i], f.image.pixels[i], std::abs(f.image.pixels[i]) * 0.0005 + 1e-7) << i;
    }
    expectBitExact(g.map.xy, f.map.xy);  // the map is always FLOAT
}

TEST(Container, EverythingRoundTrips) {
    TempDir dir;
    ConusFile f = validFile(PixelType::Half);
    f.image = makeImage(7, 5, {"R", "G", "B", "Z"});  // sorted on disk: B, G, R, Z
    for (std::size_t i = 0; i < f.image.pixels.size(); ++i) f.image.pixels[i] = 0.3f + 1.0001f * float(i);
    f.dataKind = DataKind::DepthImage;
    f.depth = {DepthKind::CameraDepth, "m", 0.5f, 120.0f};
    f.analytic = AnalyticMap{"foci", {{0.42, 0.31, 0.08, 4}, {0.7, 0.6, 0.1, 2.5}}, "density", {}};
    // A real orthographic camera (V13 asks for invertible matrices that agree with the projection).
    const CameraAttributes cam =
        toAttributes(conus::Camera::orthographic({3, 9, -2}, {0.5, 0, 1}, {0, 1, 0}, 12.5, 1.6, -4, 80));
    f.camera = cam;
    f.software = "conus test";
    writeConusFile(dir.file("all.exr"), f);
    const ConusFile g = readConusFile(dir.file("all.exr"));
    EXPECT_EQ(g.image.channels, (std::vector<std::string>{"B", "G", "R", "Z"}));
    const int z = g.image.channelIndex("Z");
    for (int y = 0; y < 5; ++y) {
        for (int x = 0; x < 7; ++x) {
            EXPECT_EQ(bits(g.image.at(x, y, z)), bits(f.image.at(x, y, 3))) << "Z is always FLOAT";
            EXPECT_NEAR(g.image.at(x, y, g.image.channelIndex("G")), f.image.at(x, y, 1), std::abs(f.image.at(x, y, 1)) * 0.001);
        }
    }
    EXPECT_EQ(g.dataKind, DataKind::DepthImage);
    EXPECT_EQ(g.depth.kind, DepthKind::CameraDepth);
    EXPECT_EQ(g.depth.units, "m");
    EXPECT_EQ(g.depth.near, 0.5f);
    EXPECT_EQ(g.depth.far, 120.0f);
    ASSERT_TRUE(g.analytic.has_value());
    EXPECT_EQ(g.analytic->kind, "foci");
    EXPECT_EQ(g.analytic->composition, "density");
    ASSERT_EQ(g.analytic->foci.size(), 2u);
    EXPECT_EQ(g.analytic->foci[0].u, 0.42f);  // stored as float
    EXPECT_EQ(g.analytic->foci[1].k, 2.5);
    ASSERT_TRUE(g.camera.has_value());
    EXPECT_EQ(g.camera->projection, "orthographic");
    EXPECT_EQ(g.camera->worldToCamera, cam.worldToCamera);
    EXPECT_EQ(g.camera->worldToNDC, cam.worldToNDC);
    EXPECT_EQ(g.software, "conus test");
}

TEST(Container, GroundParametersRoundTrip) {
    TempDir dir;
    ConusFile f = validFile();
    f.dataKind = DataKind::HeightField;
    f.image = makeImage(8, 6, {"Z"});
    f.depth = {DepthKind::Height, "", -10.0f, 2500.0f};
    f.analytic = AnalyticMap{"ground", {}, "", {{"horizon", 0.25}, {"tilt", 1.0 / 3.0}}};
    writeConusFile(dir.file("g.exr"), f);
    const ConusFile g = readConusFile(dir.file("g.exr"));
    ASSERT_TRUE(g.analytic.has_value());
    EXPECT_EQ(g.analytic->kind, "ground");
    EXPECT_EQ(g.analytic->scalars.at("tilt"), 1.0 / 3.0);  // double, exact
    EXPECT_EQ(g.depth.kind, DepthKind::Height);
    EXPECT_EQ(g.dataKind, DataKind::HeightField);
}

TEST(Container, CompressionModes) {
    TempDir dir;
    for (Compression c : {Compression::None, Compression::Zip, Compression::Piz, Compression::Dwaa}) {
        for (PixelType t : {PixelType::Half, PixelType::Float}) {
            SCOPED_TRACE(std::string(enumName(c)) + " " + enumName(t));
            ConusFile f = validFile(t);
            f.compression = c;
            const std::string path = dir.file(std::string(enumName(c)) + enumName(t) + ".exr");
            writeConusFile(path, f);
            const ConusFile g = readConusFile(path);
            EXPECT_EQ(g.compression, c);
            expectBitExact(g.map.xy, f.map.xy);  // the map is stored losslessly in every mode
            const bool lossless = c != Compression::Dwaa;
            for (std::size_t i = 0; i < f.image.pixels.size(); ++i) {
                const float tol = t == PixelType::Float && lossless ? 0.0f
                                  : lossless                        ? std::abs(f.image.pixels[i]) * 0.0005f
                                                                    : std::abs(f.image.pixels[i]) * 0.05f + 0.01f;
                ASSERT_NEAR(g.image.pixels[i], f.image.pixels[i], tol) << i;
            }
        }
    }
}

TEST(Container, LargerImageRoundTrip) {
    TempDir dir;
    ConusFile f = validFile(PixelType::Float);
    f.image = makeImage(300, 200, {"Y"});
    for (std::size_t i = 0; i < f.image.pixels.size(); ++i) f.image.pixels[i] = std::sin(float(i) * 0.001f);
    f.map = testing::identityGrid(map_rules::kDefaultSide, 33);
    f.compression = Compression::Piz;
    writeConusFile(dir.file("big.exr"), f);
    const ConusFile g = readConusFile(dir.file("big.exr"));
    expectBitExact(g.image.pixels, f.image.pixels);
    expectBitExact(g.map.xy, f.map.xy);
}

TEST(Container, InvalidFileIsNotWritten) {
    TempDir dir;
    ConusFile f = validFile();
    f.sourceWidth = 0;
    const Error e = errorFrom([&] { writeConusFile(dir.file("bad.exr"), f); });
    EXPECT_EQ(e.code(), ErrorCode::Corrupt);
    EXPECT_NE(std::string(e.what()).find("V5"), std::string::npos) << e.what();
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(Container, InvalidMapIsNotWritten) {
    TempDir dir;
    ConusFile f = validFile();
    f.map.xy[2 * (1 * 5 + 2)] = 0.9f;  // folds
    const Error e = errorFrom([&] { writeConusFile(dir.file("bad.exr"), f); });
    EXPECT_EQ(e.code(), ErrorCode::InvalidMap);
    EXPECT_NE(std::string(e.what()).find("V11"), std::string::npos) << e.what();
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

std::string contents(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(Container, FailedWriteLeavesDestinationUntouched) {
    TempDir dir;
    const std::string path = dir.file("keep.exr");
    std::ofstream(path) << "precious";
    ConusFile f = validFile();
    f.map.xy[0] = std::nanf("");
    EXPECT_THROW(writeConusFile(path, f), Error);
    EXPECT_EQ(contents(path), "precious");
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(Container, UnwritableFolderLeavesNothing) {
    TempDir dir;
    const std::string missing = dir.file("no/such/folder/x.exr");
    const Error e = errorFrom([&] { writeConusFile(missing, validFile()); });
    EXPECT_EQ(e.code(), ErrorCode::Io) << e.what();
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));

    // A read-only folder (root ignores permissions, so only check when the write really fails).
    const std::filesystem::path ro = dir.path() / "ro";
    std::filesystem::create_directory(ro);
    std::filesystem::permissions(ro, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    bool threw = false;
    try {
        writeConusFile((ro / "x.exr").string(), validFile());
    } catch (const Error& e) {
        threw = true;
        EXPECT_EQ(e.code(), ErrorCode::Io);
    }
    std::filesystem::permissions(ro, std::filesystem::perms::owner_all);
    if (threw) {
        EXPECT_TRUE(std::filesystem::is_empty(ro));
    }
}

TEST(Container, OverwriteReplacesAtomically) {
    TempDir dir;
    const std::string path = dir.file("x.exr");
    ConusFile f = validFile();
    writeConusFile(path, f);
    f.sourceWidth = 99;
    writeConusFile(path, f);
    EXPECT_EQ(readConusFile(path).sourceWidth, 99);
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(Container, MissingFileIsIo) {
    TempDir dir;
    const Error e = errorFrom([&] { readConusFile(dir.file("nothing.exr")); });
    EXPECT_EQ(e.code(), ErrorCode::Io);
    EXPECT_FALSE(validateConusFile(dir.file("nothing.exr")).ok());
}

TEST(Container, LimitsAreEnforced) {
    TempDir dir;
    writeConusFile(dir.file("x.exr"), validFile());
    Limits small;
    small.maxPixels = 47;  // the image has 48
    const Error e = errorFrom([&] { readConusFile(dir.file("x.exr"), small); });
    EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << e.what();
    Limits mapLimit;
    mapLimit.maxMapSide = 4;
    EXPECT_TRUE(validateConusFile(dir.file("x.exr"), mapLimit).violates(Rule::V7));
    Limits channelLimit;
    channelLimit.maxChannels = 3;
    EXPECT_TRUE(validateConusFile(dir.file("x.exr"), channelLimit).violates(Rule::V3));
}

TEST(Container, TruncatedAndFlippedFilesNeverCrash) {
    // A poor man's fuzzer on our own files: every prefix length class and byte flips all over.
    TempDir dir;
    ConusFile f = validFile();
    f.compression = Compression::Piz;
    writeConusFile(dir.file("x.exr"), f);
    const std::string good = contents(dir.file("x.exr"));
    const std::string bad = dir.file("bad.exr");
    for (std::size_t len = 0; len < good.size(); len += 1 + len / 8) {
        std::ofstream(bad, std::ios::binary | std::ios::trunc).write(good.data(), std::streamsize(len));
        EXPECT_THROW(readConusFile(bad), Error) << "prefix of " << len << " bytes";
        EXPECT_FALSE(validateConusFile(bad).ok());
    }
    for (std::size_t pos = 0; pos < good.size(); pos += 3) {
        std::string s = good;
        s[pos] = char(s[pos] ^ 0x5a);
        std::ofstream(bad, std::ios::binary | std::ios::trunc).write(s.data(), std::streamsize(s.size()));
        try {
            readConusFile(bad);  // a flip in pixel data may still decode: that is fine
        } catch (const Error&) {
        }
    }
}

}  // namespace
}  // namespace conus::format
