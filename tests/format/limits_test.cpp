// The resource limits (limits.h) as the reader applies them, and the hostile reproducers of
// ../shared/data/hostile: each is refused quickly with a one-line, rule-numbered reason, or read
// within bounds. The small reproducers are also committed as fuzz seeds
// (tests/fuzz/corpus/container/hostile-*), so these tests never skip for them.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <set>
#include <vector>

#include <ImfFloatVectorAttribute.h>
#include <ImfPreviewImageAttribute.h>
#include <ImfStringVectorAttribute.h>

#include "raw_file.h"
#include "sanitizers.h"
#include "test_files.h"

namespace conus::format {
namespace {

using testing::TempDir;
using testing::validFile;
using testing::writeRaw;

// "Within a second", scaled for sanitizer builds.
constexpr double kSecond = 1.0 * conus::testing::kTimeScale;

std::string hostile(const std::string& name) {
    return std::string(CONUS_FUZZ_CORPUS) + "/container/hostile-" + name;
}

// The error readConusFile (or readConusHeader) throws, with its time.
struct Refusal {
    ErrorCode code = ErrorCode::Unsupported;
    std::string message;
    std::vector<int> rules;  // conus::Error::rules
    double seconds = 0;
};

template <class Read>
Refusal refusal(Read read) {
    Refusal r;
    const auto start = std::chrono::steady_clock::now();
    try {
        read();
        r.message = "(read without error)";
    } catch (const Error& e) {
        r.code = e.code();
        r.message = e.what();
        r.rules = e.rules();
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

::testing::AssertionResult oneLine(const std::string& s) {
    if (s.find('\n') == std::string::npos) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "spans lines: " << s;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(Limits, LimitsDefaultToTheStatedCapsAndTheTableListsEach) {
    const Limits limits;
    EXPECT_EQ(limits.maxPixels, kMaxImagePixels);
    EXPECT_EQ(limits.maxMapSide, kMaxMapSide);
    EXPECT_EQ(limits.maxChannels, kMaxChannels);
    EXPECT_EQ(limits.maxAttributeBytes, kMaxAttributeBytes);
    EXPECT_EQ(limits.maxHeaderBytes, kMaxHeaderBytes);
    EXPECT_EQ(limits.maxDecodeBytes, kMaxDecodeBytes);
    std::set<std::string> names;
    for (const LimitEntry& e : limitTable()) {
        EXPECT_TRUE(names.insert(e.name).second) << e.name;
        EXPECT_GT(e.value, 0) << e.name;
    }
    EXPECT_TRUE(names.count("attributeBytes") && names.count("indexBytes") && names.count("decodeBytes"));
}

TEST(Limits, TheSpecListsEveryLimit) {
    std::ifstream in(std::string(CONUS_SOURCE_DIR) + "/spec/conus-format.md");
    const std::string spec((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_FALSE(spec.empty());
    const auto section = spec.find("## Limits");
    ASSERT_NE(section, std::string::npos);
    for (const LimitEntry& e : limitTable())
        EXPECT_NE(spec.find("`" + std::string(e.name) + "`", section), std::string::npos) << e.name;
}

TEST(Limits, AnAttributeBeyondTheCapIsRefusedBeforeOpenExrReadsIt) {
    TempDir dir;
    writeRaw(dir.file("big.exr"), validFile(), [](Imf::Header& c, Imf::Header&) {
        c.insert("conus:note", Imf::StringAttribute(std::string(kMaxAttributeBytes + 1, 'x')));
    });
    const Refusal r = refusal([&] { readConusFile(dir.file("big.exr")); });
    EXPECT_EQ(r.code, ErrorCode::LimitExceeded) << r.message;
    EXPECT_TRUE(contains(r.message, "V1: ") && contains(r.message, "conus:note") &&
                contains(r.message, std::to_string(kMaxAttributeBytes + 1)))
        << r.message;
    EXPECT_TRUE(validateConusFile(dir.file("big.exr")).violates(Rule::V1));

    // At the cap it reads (the header's total stays below its own cap).
    writeRaw(dir.file("ok.exr"), validFile(), [](Imf::Header& c, Imf::Header&) {
        c.insert("conus:note", Imf::StringAttribute(std::string(kMaxAttributeBytes, 'x')));
    });
    EXPECT_NO_THROW(readConusFile(dir.file("ok.exr")));
}

TEST(Limits, SelfDelimitedAttributesOfTheRightLengthAreRead) {
    // The header walk checks chlist, preview and stringvector values against their declared size;
    // well-formed ones (as OpenEXR writes them) pass.
    TempDir dir;
    writeRaw(dir.file("a.exr"), validFile(), [](Imf::Header& c, Imf::Header&) {
        Imf::PreviewImage preview(3, 2);
        c.insert("preview", Imf::PreviewImageAttribute(preview));
        c.insert("conus:tags", Imf::StringVectorAttribute({"one", "", "three"}));
        c.insert("conus:values", Imf::FloatVectorAttribute({1.0f, 2.0f}));
    });
    EXPECT_NO_THROW(readConusFile(dir.file("a.exr")));
}

TEST(Limits, AHeaderBeyondTheCapIsRefused) {
    TempDir dir;
    writeRaw(dir.file("big.exr"), validFile(), [](Imf::Header& c, Imf::Header&) {
        for (int i = 0; i < 5; ++i)
            c.insert("conus:note" + std::to_string(i), Imf::StringAttribute(std::string(kMaxHeaderBytes / 5 + 1, 'x')));
    });
    const Refusal r = refusal([&] { readConusFile(dir.file("big.exr")); });
    EXPECT_EQ(r.code, ErrorCode::LimitExceeded) << r.message;
    EXPECT_TRUE(contains(r.message, "header holds")) << r.message;
}

TEST(Limits, ACallerMayTightenThem) {
    TempDir dir;
    writeConusFile(dir.file("a.exr"), validFile());  // 8x6, 4 float channels: 768 bytes of pixels
    Limits small;
    small.maxDecodeBytes = 700;
    Refusal r = refusal([&] { readConusFile(dir.file("a.exr"), small); });
    EXPECT_EQ(r.code, ErrorCode::LimitExceeded) << r.message;
    EXPECT_TRUE(contains(r.message, "V4: ") && contains(r.message, "decode memory limit")) << r.message;
    // The header and map alone need no pixel memory.
    EXPECT_NO_THROW(readConusHeader(dir.file("a.exr"), small));

    ConusFile f = validFile();
    f.software = std::string(200, 's');
    writeConusFile(dir.file("b.exr"), f);
    Limits attributes;
    attributes.maxAttributeBytes = 100;  // `software` holds 200, every other attribute less than 100
    r = refusal([&] { readConusFile(dir.file("b.exr"), attributes); });
    EXPECT_EQ(r.code, ErrorCode::LimitExceeded) << r.message;
    EXPECT_TRUE(contains(r.message, "software")) << r.message;
}

TEST(Limits, ReadConusHeaderHasTheImageShapeButNoPixels) {
    TempDir dir;
    const ConusFile f = validFile();
    writeConusFile(dir.file("a.exr"), f);
    const ConusFile h = readConusHeader(dir.file("a.exr"));
    EXPECT_EQ(h.image.width, 8);
    EXPECT_EQ(h.image.height, 6);
    EXPECT_EQ(h.image.channels, f.image.channels);
    EXPECT_TRUE(h.image.pixels.empty());
    EXPECT_EQ(h.map.xy, f.map.xy);
    EXPECT_EQ(h.sourceWidth, f.sourceWidth);
}

TEST(Limits, OnlyRegularFilesAreRead) {
    TempDir dir;
    ASSERT_EQ(::mkfifo(dir.file("fifo.exr").c_str(), 0600), 0);
    for (const std::string& path : {dir.file("fifo.exr"), dir.path().string(), std::string("/dev/zero")}) {
        const Refusal r = refusal([&] { readConusFile(path); });
        EXPECT_EQ(r.code, ErrorCode::Io) << path << ": " << r.message;
        EXPECT_LT(r.seconds, kSecond) << path;
        EXPECT_TRUE(validateConusFile(path).violates(Rule::V1)) << path;
    }
    EXPECT_TRUE(contains(refusal([&] { readConusHeader(dir.file("fifo.exr")); }).message, "not a regular file"));
}

// ---- the reproducers -----------------------------------------------------------------------

TEST(Hostile, AStringAttributeLargerThanTheFileIsRefusedAtOnce) {
    // Declares a 1.9 GB string in 3.9 KB: OpenEXR's C++ library spent 13 s and 2 GB on it.
    const Refusal r = refusal([] { readConusFile(hostile("oom-string-attr-1.9GB.exr")); });
    EXPECT_EQ(r.code, ErrorCode::Corrupt) << r.message;
    EXPECT_TRUE(contains(r.message, "V1: ") && contains(r.message, "`conus:depthKind` (string) declares 1929379846 bytes"))
        << r.message;
    EXPECT_TRUE(oneLine(r.message));
    EXPECT_LT(r.seconds, kSecond);
}

TEST(Hostile, AChannelListShortOfItsTerminatorIsRefused) {
    // Found by fuzzing: the C core ended the header at the declared end of the list, the C++
    // library read one byte further and then a 1.8 GB string attribute the core never saw.
    const std::string file = std::string(CONUS_FUZZ_CORPUS) + "/container/found-chlist-short-of-terminator-oom.exr";
    const Refusal r = refusal([&] { readConusFile(file); });
    EXPECT_EQ(r.code, ErrorCode::Corrupt) << r.message;
    EXPECT_TRUE(contains(r.message, "V1: ") && contains(r.message, "the channel list does not end exactly at its declared size"))
        << r.message;
    EXPECT_LT(r.seconds, kSecond);
}

TEST(Hostile, ADeclaredWindowWithoutItsDataIsRefusedBeforeAllocating) {
    // 32768x32768 RGB (DWAB) in 5 KB: the reader grew to 11 GB.
    for (bool pixels : {true, false}) {
        const Refusal r = refusal([&] {
            pixels ? readConusFile(hostile("dw_32768x32768_rgb_dwab.exr")) : readConusHeader(hostile("dw_32768x32768_rgb_dwab.exr"));
        });
        if (pixels) {
            // 12 GB as float: beyond the decode memory limit before the chunks are even looked at.
            EXPECT_EQ(r.code, ErrorCode::LimitExceeded) << r.message;
            EXPECT_TRUE(contains(r.message, "V4: ")) << r.message;
            EXPECT_EQ(r.rules, std::vector<int>{4});
        } else {
            EXPECT_EQ(r.code, ErrorCode::Corrupt) << r.message;
            EXPECT_TRUE(contains(r.message, "V1: ") && contains(r.message, "dwab expands at most")) << r.message;
            EXPECT_EQ(r.rules, std::vector<int>{1});
        }
        EXPECT_TRUE(oneLine(r.message));
        EXPECT_LT(r.seconds, kSecond);
    }
    Limits generous;  // the chunk table refuses it even when memory would allow it
    generous.maxDecodeBytes = std::int64_t{1} << 40;
    const Refusal r = refusal([&] { readConusFile(hostile("dw_32768x32768_rgb_dwab.exr"), generous); });
    EXPECT_TRUE(contains(r.message, "expands at most")) << r.message;
}

TEST(Hostile, AHugeTiledPartWithoutItsDataIsRefused) {
    // 65536x16384, 64 channels, 4096-pixel tiles, in 6 KB.
    Refusal r = refusal([] { readConusFile(hostile("tiled_65536x16384_tile_4096_64ch.exr")); });
    EXPECT_EQ(r.code, ErrorCode::LimitExceeded) << r.message;
    EXPECT_TRUE(contains(r.message, "V4: ")) << r.message;
    r = refusal([] { readConusHeader(hostile("tiled_65536x16384_tile_4096_64ch.exr")); });
    EXPECT_EQ(r.code, ErrorCode::Corrupt) << r.message;
    EXPECT_TRUE(contains(r.message, "V1: ") && contains(r.message, "tile (0, 0)")) << r.message;
    EXPECT_LT(r.seconds, kSecond);
}

TEST(Hostile, EveryFuzzFindingIsRefused) {
    // Inputs the fuzzer found (tests/fuzz/corpus/container/found-*): each is refused, on one line,
    // under V1, at once. A 2603220992x1093730560 preview in 8 bytes overflowed the walk's own
    // size arithmetic (UBSan).
    int seen = 0;
    for (const auto& entry : std::filesystem::directory_iterator(std::string(CONUS_FUZZ_CORPUS) + "/container")) {
        if (entry.path().filename().string().rfind("found-", 0) != 0) continue;
        ++seen;
        const Refusal r = refusal([&] { readConusFile(entry.path().string()); });
        EXPECT_TRUE(contains(r.message, "V1: ")) << entry.path() << ": " << r.message;
        EXPECT_TRUE(oneLine(r.message));
        EXPECT_LT(r.seconds, kSecond) << entry.path();
    }
    EXPECT_GE(seen, 2);
    EXPECT_TRUE(contains(refusal([] { readConusFile(std::string(CONUS_FUZZ_CORPUS) + "/container/found-preview-size-overflow.exr"); }).message,
                         "a 2603220992x1093730560 preview in 8 bytes"));
}

TEST(Hostile, AHugeSourceSizeIsReadAsDeclared) {
    // Valid: the limit applies to what a decode allocates (decode_test.cpp, cli hostile_test.cpp).
    const ConusFile f = readConusFile(hostile("source_65536x16384.exr"));
    EXPECT_EQ(f.sourceWidth, 65536);
    EXPECT_EQ(f.sourceHeight, 16384);
}

TEST(Hostile, NonUtf8TextIsKeptAsBytes) {
    const ConusFile f = readConusHeader(hostile("info-json-nonutf8-software.exr"));
    EXPECT_FALSE(f.software.empty());
}

TEST(Hostile, TwoBrokenRulesGiveOneLineNamingBoth) {
    const Refusal r = refusal([] { readConusFile(hostile("multiline-error-two-rules.exr")); });
    EXPECT_EQ(r.code, ErrorCode::Corrupt);
    EXPECT_TRUE(oneLine(r.message));
    EXPECT_TRUE(contains(r.message, "V5: source size 0x-1") && contains(r.message, "; V6: data kind `bogus`")) << r.message;
    EXPECT_EQ(r.rules, (std::vector<int>{5, 6}));  // what the bindings' exception carries
    const ValidationReport report = validateConusFile(hostile("multiline-error-two-rules.exr"));
    EXPECT_TRUE(report.violates(Rule::V5) && report.violates(Rule::V6)) << report.str();
}

TEST(Hostile, LargeMapsAreReadWithinBounds) {
    CONUS_REQUIRE_SHARED_DATA();
    const auto folder = testing::sharedData() / "hostile";
    if (!std::filesystem::is_directory(folder)) GTEST_SKIP() << "shared data not found at " << folder;
    // Valid maps far finer than their 24x16 images: refused from the headers (mapNodesPerPixel),
    // before the map's pixels are read.
    for (const char* name : {"samplingmap-index-uint32-overflow-n900.exr", "samplingmap-index-blowup-n257-575MB.exr"}) {
        for (const bool header : {false, true}) {
            const Refusal r = refusal([&] { header ? readConusHeader((folder / name).string()) : readConusFile((folder / name).string()); });
            EXPECT_EQ(r.code, ErrorCode::LimitExceeded) << name << ": " << r.message;
            EXPECT_NE(r.message.find("nodes is finer than its 24x16 image can show; readers take at most 129 nodes a side"),
                      std::string::npos)
                << r.message;
            EXPECT_LT(r.seconds, kSecond) << name;
        }
    }
    // At the limit a map reads and is written: 4 nodes a pixel of the longer side, plus one.
    const testing::TempDir dir;
    ConusFile fine = testing::validFile();
    fine.image = makeImage(40, 10, fine.image.channels);
    fine.map = testing::identityGrid(161, 9);
    writeConusFile(dir.file("fine.exr"), fine);
    EXPECT_EQ(readConusFile(dir.file("fine.exr")).map.columns, 161);
    fine.map = testing::identityGrid(162, 9);
    const Refusal past = refusal([&] { writeConusFile(dir.file("past.exr"), fine); });
    EXPECT_NE(past.message.find("162x9 nodes is finer than its 40x10 image can show; readers take at most 161"), std::string::npos)
        << past.message;
}

TEST(Hostile, EveryReproducerIsHandledWithinASecond) {
    CONUS_REQUIRE_SHARED_DATA();
    const auto folder = testing::sharedData() / "hostile";
    if (!std::filesystem::is_directory(folder)) GTEST_SKIP() << "shared data not found at " << folder;
    int seen = 0;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        if (entry.path().extension() != ".exr") continue;
        ++seen;
        const std::string path = entry.path().string();
        const Refusal read = refusal([&] { readConusFile(path); });
        const Refusal header = refusal([&] { readConusHeader(path); });
        EXPECT_TRUE(oneLine(read.message) && oneLine(header.message)) << path;
        EXPECT_LT(read.seconds, kSecond) << path;
        EXPECT_LT(header.seconds, kSecond) << path;
    }
    EXPECT_GE(seen, 8);
}

}  // namespace
}  // namespace conus::format
