// Volume readers against files written here byte by byte (raw, .den, NRRD) or through OpenVDB's
// own writer, on asymmetric content (every sample distinct), plus the real MRI scan and hostile
// files: sizes that overflow, headers that lie about the payload, NaN samples.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "conus/core/error.h"
#include "conus/sceneio/volume_file.h"
#include "error_code.h"
#include "test_dir.h"

namespace conus::sceneio {
namespace {

using test::TestDir;

// A value no two samples share: x + 10 y + 100 z (+ 0.25 so floats are not whole).
float expected(int x, int y, int z) { return float(x + 10 * y + 100 * z) + 0.25f; }

void writeBytes(const std::string& path, const std::vector<unsigned char>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

template <class T>
void append(std::vector<unsigned char>& bytes, T value, bool big = false) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    if (big) std::reverse(b, b + sizeof(T));
    bytes.insert(bytes.end(), b, b + sizeof(T));
}

using test::codeOf;

// v is size.x x size.y x size.z voxels of `spacing`, holding value(x, y, z) at each. Wrap the call
// in ASSERT_NO_FATAL_FAILURE: a wrong size stops the test.
template <class Value>
void expectVolume(const Volume& v, glm::ivec3 size, glm::dvec3 spacing, Value value) {
    ASSERT_EQ(v.width, size.x);
    ASSERT_EQ(v.height, size.y);
    ASSERT_EQ(v.depth, size.z);
    EXPECT_EQ(v.spacing, spacing);
    for (int z = 0; z < size.z; ++z)
        for (int y = 0; y < size.y; ++y)
            for (int x = 0; x < size.x; ++x) EXPECT_EQ(v.at(x, y, z), value(x, y, z)) << x << "," << y << "," << z;
}

TEST(RawVolume, Float32LittleAndBigEndianWithSpacing) {
    TestDir dir("volume");
    for (bool big : {false, true}) {
        std::vector<unsigned char> bytes;
        for (int z = 0; z < 4; ++z)
            for (int y = 0; y < 3; ++y)
                for (int x = 0; x < 5; ++x) append(bytes, expected(x, y, z), big);
        const std::string path = dir.file(big ? "be.raw" : "le.raw");
        writeBytes(path, bytes);
        const Volume v = readVolume(std::string("raw:5x3x4:") + (big ? "float32-be" : "float32") + ":0.5,1,2:" + path);
        ASSERT_NO_FATAL_FAILURE(expectVolume(v, {5, 3, 4}, {0.5, 1, 2}, expected));
    }
}

TEST(RawVolume, Uint16AndUint8) {
    TestDir dir("volume");
    std::vector<unsigned char> bytes16, bytes8;
    for (int i = 0; i < 2 * 3 * 2; ++i) {
        append<std::uint16_t>(bytes16, static_cast<std::uint16_t>(1000 * i + 7));
        bytes8.push_back(static_cast<unsigned char>(20 * i + 3));
    }
    writeBytes(dir.file("a.raw"), bytes16);
    writeBytes(dir.file("b.raw"), bytes8);
    const Volume v16 = readVolume("raw:2x3x2:uint16:" + dir.file("a.raw"));
    const Volume v8 = readVolume("raw:2x3x2:uint8:3:" + dir.file("b.raw"));
    for (int i = 0; i < 12; ++i) {
        EXPECT_EQ(v16.values[i], float(1000 * i + 7));
        EXPECT_EQ(v8.values[i], float(20 * i + 3));
    }
    EXPECT_EQ(v8.spacing, glm::dvec3(3.0));
}

TEST(RawVolume, HostileInputs) {
    TestDir dir("volume");
    writeBytes(dir.file("short.raw"), std::vector<unsigned char>(100, 1));
    std::string message;
    // Payload size disagrees with the dimensions.
    EXPECT_EQ(codeOf([&] { readVolume("raw:5x5x5:uint8:" + dir.file("short.raw")); }, &message), ErrorCode::Corrupt);
    EXPECT_NE(message.find("100 bytes"), std::string::npos) << message;
    // Sizes whose product overflows 64 bits, one side past the cap, a zero side.
    EXPECT_EQ(codeOf([&] { readVolume("raw:4000000000x4000000000x4000000000:uint8:" + dir.file("short.raw")); }),
              ErrorCode::LimitExceeded);
    EXPECT_EQ(codeOf([&] { readVolume("raw:16384x16384x16384:float32:" + dir.file("short.raw")); }),
              ErrorCode::LimitExceeded);
    EXPECT_EQ(codeOf([&] { readVolume("raw:0x5x4:uint8:" + dir.file("short.raw")); }), ErrorCode::InvalidArgument);
    // Malformed specifications.
    EXPECT_EQ(codeOf([&] { readVolume("raw:5x5:uint8:" + dir.file("short.raw")); }), ErrorCode::InvalidArgument);
    EXPECT_EQ(codeOf([&] { readVolume("raw:5x5x4:int8:" + dir.file("short.raw")); }), ErrorCode::InvalidArgument);
    EXPECT_EQ(codeOf([&] { readVolume("raw:5x5x4:uint8:-1:" + dir.file("short.raw")); }), ErrorCode::InvalidArgument);
    EXPECT_EQ(codeOf([&] { readVolume("raw:5x5x4:uint8:" + dir.file("missing.raw")); }), ErrorCode::Io);
    // A NaN sample, named by its position.
    std::vector<unsigned char> bytes;
    for (int i = 0; i < 8; ++i) append(bytes, i == 5 ? std::numeric_limits<float>::quiet_NaN() : float(i));
    writeBytes(dir.file("nan.raw"), bytes);
    EXPECT_EQ(codeOf([&] { readVolume("raw:2x2x2:float32:" + dir.file("nan.raw")); }, &message), ErrorCode::Corrupt);
    EXPECT_NE(message.find("(1, 0, 1)"), std::string::npos) << message;
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("x.tiff")); }), ErrorCode::Unsupported);
}

std::vector<unsigned char> denFile(int w, int h, int d, std::uint32_t length, bool big, std::size_t payload) {
    std::vector<unsigned char> bytes;
    append<std::uint16_t>(bytes, 1, big);
    const int lens[3] = {w, h, d};
    for (int group = 0; group < 9; ++group)
        for (int a = 0; a < 3; ++a) {
            const int kind = group % 3;  // min, max, len
            append<std::uint16_t>(bytes, static_cast<std::uint16_t>(kind == 0 ? 0 : kind == 1 ? lens[a] - 1 : lens[a]), big);
        }
    append<std::uint16_t>(bytes, 3, big);
    append<std::uint32_t>(bytes, length, big);
    for (std::size_t i = 0; i < payload; ++i) bytes.push_back(static_cast<unsigned char>((i * 37) % 251));
    return bytes;
}

TEST(DenVolume, BothByteOrders) {
    TestDir dir("volume");
    for (bool big : {false, true}) {
        writeBytes(dir.file("v.den"), denFile(6, 4, 3, 72, big, 72));
        const Volume v = readVolume(dir.file("v.den"));
        ASSERT_EQ(v.width, 6);
        ASSERT_EQ(v.height, 4);
        ASSERT_EQ(v.depth, 3);
        for (std::size_t i = 0; i < 72; ++i) EXPECT_EQ(v.values[i], float((i * 37) % 251));
    }
}

TEST(DenVolume, HeadersThatLie) {
    TestDir dir("volume");
    writeBytes(dir.file("a.den"), denFile(6, 4, 3, 999, false, 72));  // length field disagrees
    writeBytes(dir.file("b.den"), denFile(6, 4, 3, 72, false, 50));   // truncated payload
    writeBytes(dir.file("c.den"), denFile(60000, 60000, 60000, 72, false, 72));
    writeBytes(dir.file("d.den"), std::vector<unsigned char>(30, 0));
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("a.den")); }), ErrorCode::Corrupt);
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("b.den")); }), ErrorCode::Corrupt);
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("c.den")); }), ErrorCode::LimitExceeded);  // a side past the cap
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("d.den")); }), ErrorCode::Corrupt);
}

TEST(DenVolume, TheRealMriScan) {
    const std::string path = std::string(CONUS_SHARED_DATA) + "/volumes/brainsmall.den";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data not present: " << path;
    const Volume v = readVolume(path);
    EXPECT_EQ(v.width, 128);
    EXPECT_EQ(v.height, 128);
    EXPECT_EQ(v.depth, 84);
    // A head in air: dark corners, bright matter in the middle.
    EXPECT_LT(v.at(0, 0, 0), 20.0f);
    float centre = 0;
    for (int z = 30; z < 54; ++z) centre = std::max(centre, v.at(64, 64, z));
    EXPECT_GT(centre, 60.0f);
}

// NRRD written by hand: a text header and raw little-endian data.
void writeNrrd(const std::string& path, const std::string& header, const std::vector<unsigned char>& data) {
    std::vector<unsigned char> bytes(header.begin(), header.end());
    bytes.insert(bytes.end(), data.begin(), data.end());
    writeBytes(path, bytes);
}

TEST(NrrdVolume, ShortSamplesAndSpacings) {
    TestDir dir("volume");
    std::vector<unsigned char> data;
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 5; ++x) append<std::int16_t>(data, static_cast<std::int16_t>(x - 10 * y + 100 * z));
    writeNrrd(dir.file("v.nrrd"),
              "NRRD0004\ntype: short\ndimension: 3\nsizes: 5 4 3\nspacings: 0.5 0.75 2\nendian: little\n"
              "encoding: raw\n\n",
              data);
    const Volume v = readVolume(dir.file("v.nrrd"));
    ASSERT_NO_FATAL_FAILURE(
        expectVolume(v, {5, 4, 3}, {0.5, 0.75, 2}, [](int x, int y, int z) { return float(x - 10 * y + 100 * z); }));
}

TEST(NrrdVolume, HostileHeaders) {
    TestDir dir("volume");
    const std::vector<unsigned char> data(60, 7);
    // Declares far more than it holds: refused by the cap before teem allocates.
    writeNrrd(dir.file("huge.nrrd"),
              "NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\nendian: little\n\n", data);
    // Declares a little more than it holds: teem reports the short payload.
    writeNrrd(dir.file("short.nrrd"), "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 4\nencoding: raw\n\n", data);
    writeNrrd(dir.file("2d.nrrd"), "NRRD0004\ntype: uchar\ndimension: 2\nsizes: 6 10\nencoding: raw\n\n", data);
    writeNrrd(dir.file("garbage.nrrd"), "not a nrrd at all\n", data);
    std::vector<unsigned char> nan;
    for (int i = 0; i < 8; ++i) append(nan, i == 3 ? std::numeric_limits<float>::infinity() : 1.0f);
    writeNrrd(dir.file("inf.nrrd"), "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nendian: little\nencoding: raw\n\n", nan);
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("huge.nrrd")); }), ErrorCode::LimitExceeded);
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("short.nrrd")); }), ErrorCode::Corrupt);
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("2d.nrrd")); }), ErrorCode::Unsupported);
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("garbage.nrrd")); }), ErrorCode::Corrupt);
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("inf.nrrd")); }), ErrorCode::Corrupt);
}

TEST(VdbVolume, SparseRoundTripOverTheActiveBox) {
    TestDir dir("volume");
    Volume v;
    v.width = 7;
    v.height = 5;
    v.depth = 4;
    v.spacing = glm::dvec3(0.25);
    v.values.resize(7 * 5 * 4);
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 7; ++x) v.values[v.index(x, y, z)] = expected(x, y, z);
    v.values[v.index(3, 2, 1)] = 0.0f;  // an inactive voxel inside the box reads the background
    writeVdbVolume(dir.file("v.vdb"), v);
    const Volume back = readVolume(dir.file("v.vdb"));
    ASSERT_EQ(back.width, 7);
    ASSERT_EQ(back.height, 5);
    ASSERT_EQ(back.depth, 4);
    EXPECT_NEAR(back.spacing.x, 0.25, 1e-12);
    EXPECT_EQ(back.values, v.values);
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"v.vdb"}) << "no temporary left";
}

TEST(VdbVolume, HostileFiles) {
    TestDir dir("volume");
    writeBytes(dir.file("bad.vdb"), std::vector<unsigned char>(200, 0x5a));
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("bad.vdb")); }), ErrorCode::Corrupt);
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("missing.vdb")); }), ErrorCode::Io);
    // A real file cut short.
    Volume v;
    v.width = v.height = v.depth = 16;
    v.values.assign(16 * 16 * 16, 1.5f);
    writeVdbVolume(dir.file("full.vdb"), v);
    std::ifstream in(dir.file("full.vdb"), std::ios::binary);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), {});
    bytes.resize(bytes.size() / 2);
    writeBytes(dir.file("cut.vdb"), bytes);
    std::string message;
    EXPECT_EQ(codeOf([&] { readVolume(dir.file("cut.vdb")); }, &message), ErrorCode::Corrupt) << message;
    // A sparse grid whose active box is past the cap: refused before densifying.
    Volume corners;
    corners.width = corners.height = corners.depth = 2;
    corners.values = {1, 0, 0, 0, 0, 0, 0, 1};
    writeVdbVolume(dir.file("small.vdb"), corners);
    VolumeReadOptions options;
    options.maxVoxels = 7;
    EXPECT_EQ(codeOf([&] { readVdbVolume(dir.file("small.vdb"), options); }), ErrorCode::LimitExceeded);
}

}  // namespace
}  // namespace conus::sceneio
