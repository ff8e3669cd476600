// The hostile reproducers of ../shared/data/hostile (and other inputs that never end or lie)
// through the real `conus` binary: each is refused with one line `conus <cmd>: <reason>` naming
// the rule where one is broken, or handled, within a second (plus the ~0.5 s a start costs) and
// bounded memory. The small reproducers are committed as fuzz seeds, so most cases never skip.
#include "hostile_fixture.h"

#include "conus/codec/builders/foci.h"
#include "conus/codec/map/sampling_map.h"

namespace {

using namespace conus::hostile;

TEST_F(Hostile, HugeStringAttributeIsRefusedAtOnce) {
    const std::string file = reproducer("oom-string-attr-1.9GB.exr");
    Outcome r = run({"validate", file});
    expectRefused(r, "validate", "not a valid CoNUS file (1 problem)");
    EXPECT_TRUE(contains(r.out, ": V1: not a readable OpenEXR file: ") && contains(r.out, "declares 1929379846 bytes")) << r.out;
    expectBounded(r, 400);
    r = run({"info", file});
    expectRefused(r, "info", "V1: not a readable OpenEXR file");
    expectBounded(r, 400);
}

TEST_F(Hostile, DeclaredWindowWithoutDataIsRefusedBeforeAllocating) {
    const std::string file = reproducer("dw_32768x32768_rgb_dwab.exr");
    Outcome r = run({"info", file});
    expectRefused(r, "info", "V1: part 0 (`conus`) scanline 0: chunk declares 50331648 bytes of pixels in 144 bytes");
    expectBounded(r, 400);
    r = run({"decode", file, "-o", path("x.png"), "--size", "64x64"});
    expectRefused(r, "decode", "V4: image of 32768x32768x3 floats");
    expectBounded(r, 400);
    EXPECT_FALSE(fs::exists(path("x.png")));
}

TEST_F(Hostile, HugeTiledPartIsRefused) {
    const Outcome r = run({"info", reproducer("tiled_65536x16384_tile_4096_64ch.exr")});
    expectRefused(r, "info", "V1: part 0 (`conus`) tile (0, 0)");
    expectBounded(r, 400);
}

// The same EXRs given as pictures go through OpenImageIO, which reads them with OpenEXR's C++
// library: before the screen, `encode` spent 8 s and 2 GB on the first and 73 s and 12.7 GB on
// the second.
TEST_F(Hostile, HostileExrPicturesAreScreenedBeforeOpenImageIo) {
    const struct {
        const char* file;
        const char* reason;
    } cases[] = {
        {"oom-string-attr-1.9GB.exr", "not a readable OpenEXR file: part 0 header: attribute `conus:depthKind` (string) declares 1929379846 bytes"},
        {"dw_32768x32768_rgb_dwab.exr", "part 0 (`conus`) scanline 0: chunk declares 50331648 bytes of pixels in 144 bytes"},
        {"tiled_65536x16384_tile_4096_64ch.exr", "part 0 (`conus`) tile (0, 0): unreadable chunk"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.file);
        const std::string file = reproducer(c.file);
        const Outcome r = run({"encode", file, "-o", path("x.exr")});
        expectRefused(r, "encode", file + ": " + c.reason);
        expectBounded(r, 400);
        EXPECT_FALSE(fs::exists(path("x.exr")));
    }
}

// A 74-byte PNG that declares 16000x16000 RGB: refused before 3 GB of floats are committed.
TEST_F(Hostile, PictureDeclaringMoreThanItsBytesCanHoldIsRefused) {
    const std::string png = path("lying.png");
    {
        // Signature, IHDR (16000x16000, 8-bit RGB), an IDAT of 16 deflated zero bytes, IEND: a
        // well-formed PNG whose data falls 768 MB short.
        const unsigned char bytes[] = {
            0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a,                                   // signature
            0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 0, 0x3e, 0x80, 0, 0, 0x3e, 0x80, 8, 2, 0, 0, 0,  // 16000x16000 RGB8
            0xce, 0x1c, 0x48, 0x89,                                                         // CRC of IHDR
            0x00, 0x00, 0x00, 0x0b, 'I', 'D', 'A', 'T', 0x78, 0x9c, 0x63, 0x60, 0x40, 0x05, 0x00,  // 16 zero bytes
            0x00, 0x10, 0x00, 0x01, 0x39, 0xbd, 0x8f, 0x65,                                 // ... and the CRC
            0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};                        // IEND
        std::ofstream(png, std::ios::binary).write(reinterpret_cast<const char*>(bytes), sizeof bytes);
    }
    const Outcome r = run({"encode", png, "-o", path("x.exr")});
    expectRefused(r, "encode", png + ": declares 16000x16000 pixels (768000000 bytes of samples) in a 68-byte file");
    expectBounded(r, 400);
}

TEST_F(Hostile, SourceSizedDecodeBeyondTheMemoryLimitIsRefused) {
    const std::string file = reproducer("source_65536x16384.exr");
    Outcome r = run({"decode", file, "-o", path("x.png")});
    expectRefused(r, "decode", "beyond the decode memory limit of 8589934592; give a smaller --size");
    expectBounded(r, 400);
    r = run({"decode", file, "-o", path("y.png"), "--size", "64x16"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
}

// Maps far finer than their image: 900x900 nodes (SIGSEGV in the inverse's index once) and
// 257x257 (575 MB for a 300x200 view once) over a 24x16 image, and 4097x4097 over a 16x16 one
// (info 572 MB, decode 664 MB once). Readers take at most 4 nodes a pixel of the longer side (and
// 129 always): each is refused from its headers, before the map's pixels are read.
TEST_F(Hostile, MapsFinerThanTheirImageAreRefusedFromTheHeaders) {
    const struct {
        std::string file;
        const char* size;
    } cases[] = {{hostileData("samplingmap-index-uint32-overflow-n900.exr"), "900x900 nodes is finer than its 24x16 image"},
                 {hostileData("samplingmap-index-blowup-n257-575MB.exr"), "257x257 nodes is finer than its 24x16 image"},
                 {hostileData("round4/conus/map4097_img16.exr"), "4097x4097 nodes is finer than its 16x16 image"}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.file);
        CONUS_REQUIRE(c.file);
        Outcome r = run({"decode", c.file, "-o", path("view.png"), "--size", "64x64"});
        expectRefused(r, "decode", c.size);
        EXPECT_TRUE(contains(r.err, "readers take at most 129 nodes a side")) << r.err;
        expectMemory(r, 200);  // what loading OpenImageIO and GL costs any command: ~145 MB
        EXPECT_FALSE(fs::exists(path("view.png")));
        r = run({"info", c.file});
        expectRefused(r, "info", c.size);
        expectMemory(r, 200);
        r = run({"validate", c.file});
        expectRefused(r, "validate", "not a valid CoNUS file");
        EXPECT_TRUE(contains(r.out, c.size)) << r.out;
        // The file as a picture (its image part, with a warning naming the part) through a map of its own.
        r = run({"encode", c.file, "--map", c.file, "-o", path("again.exr"), "--size", "24x16", "--backend", "cpu"});
        EXPECT_EQ(r.exitCode, 1) << r.err;
        ASSERT_FALSE(errorLines(r.err).empty());
        EXPECT_TRUE(contains(errorLines(r.err).back(), c.size)) << r.err;
        expectMemory(r, 200);
        r = runTool("conus-view", {c.file, "--screenshot", path("s.png"), "--size", "32x32"});
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_TRUE(contains(r.err, c.size)) << r.err;
        expectMemory(r, 200);
    }
}

// The same limit for files the tools make: a map of 257 nodes a side is fine for a 64x64 image
// and, for a 16x16 one, refused as a usage error while the options are read (before the picture
// is: a missing picture is not what is said), or, without --size, once the picture's size is known.
TEST_F(Hostile, AMapIsNeverWrittenFinerThanItsImage) {
    std::string pgm = "P2\n16 16\n255\n";
    for (int i = 0; i < 256; ++i) pgm += std::to_string((i * 7) % 256) + " ";
    std::ofstream(path("p.pgm")) << pgm;
    Outcome r = run({"map", "foci", "--focus", "0.5,0.5,0.1,4", "--grid", "257", "-o", path("m.exr")});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = run({"encode", path("p.pgm"), "--map", path("m.exr"), "-o", path("big.exr"), "--size", "64x64"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(run({"info", path("big.exr")}).exitCode, 0);
    const std::string tooFine = "--map " + path("m.exr") + ": its 257x257 sampling map is finer than a ";
    r = run({"encode", path("p.pgm"), "--map", path("m.exr"), "-o", path("small.exr"), "--size", "16x16"});
    expectRefused(r, "encode", tooFine + "16x16 image can show; at most 129 nodes a side", 2);
    r = run({"encode", path("absent.pgm"), "--map", path("m.exr"), "-o", path("small.exr"), "--size", "16x16"});
    expectRefused(r, "encode", tooFine + "16x16 image can show", 2);
    // No --size: the CoNUS image is a quarter of the picture's side, 4x4, known once it is read.
    r = run({"encode", path("p.pgm"), "--map", path("m.exr"), "-o", path("small.exr")});
    expectRefused(r, "encode", tooFine + "4x4 image can show; at most 129 nodes a side", 2);
    EXPECT_FALSE(fs::exists(path("small.exr")));
}

TEST_F(Hostile, LyingNpzIsRefusedBeforeAllocating) {
    const std::string file = hostileData("npz-lying-size-4GB.npz");
    CONUS_REQUIRE(file);
    const Outcome r = run({"heightfield", "encode", file, "-o", path("t.exr"), "--size", "32x32"});
    expectRefused(r, "heightfield", "claims 4294967280 bytes from 73 compressed bytes");
    EXPECT_TRUE(contains(r.err, "deflate expands at most 1032 times")) << r.err;
    expectBounded(r, 400);
    EXPECT_FALSE(fs::exists(path("t.exr")));
}

TEST_F(Hostile, NpyShapesMustBePositiveWholeNumbers) {
    // "(-4, 4)" was read as 4x4; an overflowing dimension threw std::out_of_range.
    for (const char* shape : {"(-4, 4)", "(4, 99999999999999999999)", "(4.5, 4)"}) {
        std::string header = std::string("{'descr': '<f4', 'fortran_order': False, 'shape': ") + shape + ", }";
        header.resize(118, ' ');
        header += '\n';
        std::ofstream out(path("dem.npy"), std::ios::binary);
        out << "\x93NUMPY" << char(1) << char(0) << char(header.size() & 0xff) << char(header.size() >> 8) << header
            << std::string(64, '\0');
        out.close();
        const Outcome r = run({"heightfield", "encode", path("dem.npy"), "-o", path("t.exr"), "--size", "16x16"});
        expectRefused(r, "heightfield", "shape");
    }
}

TEST_F(Hostile, NonUtf8AttributesStillGiveJson) {
    const Outcome r = run({"info", "--json", reproducer("info-json-nonutf8-software.exr")});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(contains(j["software"].get<std::string>(), "\xEF\xBF\xBD")) << r.out;  // U+FFFD
}

TEST_F(Hostile, TwoBrokenRulesGiveOneErrorLine) {
    const std::string file = reproducer("multiline-error-two-rules.exr");
    Outcome r = run({"info", file});
    expectRefused(r, "info", "V5: source size 0x-1 outside [1, 65536]; V6: data kind `bogus`");
    // validate lists one problem a line on stdout, and ends with one line on stderr.
    r = run({"validate", file});
    expectRefused(r, "validate", "not a valid CoNUS file (2 problems)");
    EXPECT_TRUE(contains(r.out, file + ": V5: ") && contains(r.out, file + ": V6: ")) << r.out;
}

TEST_F(Hostile, InputsThatAreNotRegularFilesAreRefused) {
    ASSERT_EQ(::mkfifo(path("fifo.exr").c_str(), 0600), 0);
    ASSERT_EQ(::mkfifo(path("fifo.npy").c_str(), 0600), 0);
    for (const std::string& input : {path("fifo.exr"), std::string("/dev/zero")}) {
        Outcome r = run({"info", input});
        expectRefused(r, "info", "not a regular file");
        EXPECT_LT(r.seconds, 2.0 * conus::testing::kTimeScale);
        r = run({"decode", input, "-o", path("x.png")});
        expectRefused(r, "decode", "not a regular file");
        r = run({"validate", input});  // not a file at all: one line, as for a missing one, no rule listed
        expectRefused(r, "validate", "not a regular file");
        EXPECT_TRUE(r.out.empty()) << r.out;
    }
    for (const std::string& dem : {path("fifo.npy"), std::string("/dev/zero")}) {
        const Outcome r = run({"heightfield", "encode", dem, "-o", path("t.exr")});
        expectRefused(r, "heightfield", "not a regular file");
        EXPECT_LT(r.seconds, 2.0 * conus::testing::kTimeScale);
    }
}

TEST_F(Hostile, HeightFieldOptionsMustBeFiniteAndInRange) {
    // NaN and -10 fell back to the defaults silently.
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
        {{"--fov", "-10"}, "--fov: '-10' is not a finite number in (0, 170)"},
        {{"--fov", "nan"}, "--fov: 'nan' is not a finite number"},
        {{"--far", "nan"}, "--far: 'nan' is not a finite number"},
        {{"--near", "inf"}, "--near: 'inf' is not a finite number"},
        {{"--eye-height", "0"}, "--eye-height: '0' is not a finite number"},
        {{"--far", "100", "--near", "200"}, "--far: 100 is not beyond --near 200"},
    };
    for (const auto& [options, reason] : cases) {
        std::vector<std::string> args{"heightfield", "encode", "procedural:32", "-o", path("t.exr"), "--size", "16x16"};
        args.insert(args.end(), options.begin(), options.end());
        const Outcome r = run(args);
        expectRefused(r, "heightfield", reason, 2);
        EXPECT_FALSE(fs::exists(path("t.exr")));
    }
}

TEST_F(Hostile, AFocusTheGridCannotHoldGetsAFinerGrid) {
    // A 2x2 grid is always the identity: the builder refines it until the focus holds, instead of
    // refusing (or writing a file that records a focus its map ignores).
    const Outcome r = run({"map", "foci", "--focus", "0.5,0.5,0.1,4", "--grid", "2", "-o", path("m.exr")});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const auto map = conus::codec::SamplingMap::fromGrid(conus::format::readConusFile(path("m.exr")).map);
    EXPECT_GT(map.columns(), 2);
    const std::vector<conus::codec::Focus> focus{{0.5, 0.5, 0.1, 4}};
    EXPECT_GT(conus::codec::reachedMagnification(map, focus)[0], 3.25);
    EXPECT_NE(r.out.find("grid refined from 2x2 to "), std::string::npos) << r.out;
}

TEST_F(Hostile, InfoPrintsTheLimits) {
    Outcome r = run({"info", "--limits"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* name : {"imageSide", "imagePixels", "channels", "mapSide", "mapNodes", "attributeBytes", "headerBytes",
                             "indexBytes", "decodeBytes"})
        EXPECT_TRUE(contains(r.out, name)) << name;
    r = run({"info", "--limits", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["mapSide"]["value"], conus::kMaxMapSide);
    EXPECT_EQ(j["decodeBytes"]["unit"], "bytes");
}

}  // namespace
