// The scene readers and the budgets through the real `conus` binary: the reproducers of
// ../shared/data/hostile/scene (files a model names outside its folder, devices and FIFOs behind a
// name, lying lengths and compression bombs, work without end, files that validate but do not
// decode) and the smaller items found with them. Each is refused with one line and the right exit
// code (1 bad data, 2 usage), or done within a second and bounded memory.
#include <sys/stat.h>
#include <sys/wait.h>

#include "hostile_fixture.h"

namespace {

using namespace conus::hostile;

class SceneHostile : public Hostile {
protected:
    static std::string scene(const std::string& name) { return hostileData(fs::path("scene") / name); }
    // A glTF whose one buffer is `uri`: a triangle when the buffer holds three float32 corners.
    void writeGltf(const std::string& name, const std::string& uri) const {
        write(name, R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "scene": 0, "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "buffers": [{"uri": ")" + uri + R"(", "byteLength": 36}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]})");
    }
    void writeTriangleBuffer(const fs::path& file) const {
        const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(p), sizeof p);
    }
};

TEST_F(SceneHostile, AGltfNamingAFileOutsideItsFolderIsRefused) {
    const struct {
        const char* file;
        const char* reason;
    } cases[] = {{"gltf_passwd.gltf", "an absolute path"}, {"gltf_dotdot.gltf", "outside its folder"}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.file);
        const std::string file = scene(c.file);
        CONUS_REQUIRE(file);
        Outcome r = run({"render", "mesh", file, "-o", path("x.exr"), "--size", "32x32"});
        expectRefused(r, "render", c.reason);
        EXPECT_TRUE(contains(r.err, "/etc/passwd")) << r.err;
        expectBounded(r, 400);
        r = run({"bake", "reflection", file, "--size", "8", "-o", path("asset.exr")});
        expectRefused(r, "bake", c.reason);
        EXPECT_FALSE(fs::exists(path("x.exr")) || fs::exists(path("asset.exr")));
    }
}

TEST_F(SceneHostile, LinksFifosAndDevicesBehindAGltfNameAreRefused) {
    fs::create_directories(m_dir / "elsewhere");
    writeTriangleBuffer(m_dir / "elsewhere" / "tri.bin");
    fs::create_symlink("/etc/passwd", m_dir / "passwd.bin");
    ASSERT_EQ(::mkfifo(path("fifo.bin").c_str(), 0600), 0);
    const struct {
        const char* uri;
        const char* reason;
    } cases[] = {{"passwd.bin", "outside its folder"}, {"fifo.bin", "not a regular file"}, {"/dev/zero", "an absolute path"}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.uri);
        writeGltf("m.gltf", c.uri);
        const Outcome r = run({"render", "mesh", path("m.gltf"), "-o", path("x.exr"), "--size", "32x32"});
        expectRefused(r, "render", c.reason);
        expectBounded(r, 400);
    }
    // --allow-dir lets the same buffer read from the folder it names.
    writeGltf("far.gltf", "elsewhere/tri.bin");
    EXPECT_EQ(run({"render", "mesh", path("far.gltf"), "-o", path("x.exr"), "--size", "32x32"}).exitCode, 0);
    // A link out of the model's folder into another one the user allows.
    writeGltf("link.gltf", "link.bin");
    fs::create_directories(m_dir / "model");
    fs::rename(m_dir / "link.gltf", m_dir / "model" / "link.gltf");
    fs::create_symlink(m_dir / "elsewhere" / "tri.bin", m_dir / "model" / "link.bin");
    Outcome r = run({"render", "mesh", path("model/link.gltf"), "-o", path("y.exr"), "--size", "32x32"});
    expectRefused(r, "render", "outside its folder");
    r = run({"render", "mesh", path("model/link.gltf"), "-o", path("y.exr"), "--size", "32x32", "--allow-dir",
             path("elsewhere")});
    EXPECT_EQ(r.exitCode, 0) << r.err;
}

// conus-view reads scene files by the same policy, with the same --allow-dir.
TEST_F(SceneHostile, TheViewerKeepsAModelInsideItsFolderToo) {
    fs::create_directories(m_dir / "model");
    fs::create_directories(m_dir / "elsewhere");
    writeTriangleBuffer(m_dir / "elsewhere" / "tri.bin");
    writeGltf("model/far.gltf", "../elsewhere/tri.bin");
    const std::vector<std::string> view{"--mesh", path("model/far.gltf"), "--screenshot", path("far.png"), "--size", "32x32"};
    Outcome r = runTool("conus-view", view);
    EXPECT_EQ(r.exitCode, 1) << r.err;
    ASSERT_EQ(errorLines(r.err).size(), 1u) << r.err;
    EXPECT_TRUE(contains(r.err, "outside its folder")) << r.err;
    EXPECT_FALSE(fs::exists(path("far.png")));
    std::vector<std::string> allowed = view;
    allowed.insert(allowed.end(), {"--allow-dir", path("elsewhere")});
    r = runTool("conus-view", allowed);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("far.png")));
}

// A number option that is not a finite number in its range is a usage error in either tool: one
// line, exit 2 (CLI11's own range checks let NaN through).
TEST_F(SceneHostile, NotANumberIsAUsageErrorInEveryNumberOption) {
    write("a.pgm", "P2\n2 2\n255\n0 1 2 3\n");
    const std::vector<std::vector<std::string>> conusRuns{
        {"encode", path("a.pgm"), "-o", path("a.exr"), "--frame-loss", "nan"},
        {"encode", path("a.pgm"), "-o", path("a.exr"), "--focus", "0.5,0.5,0.1,4", "--max-anisotropy", "nan"},
        {"encode", path("a.pgm"), "-o", path("a.exr"), "--fit-hold", "inf"},
        {"render", "mesh", "city", "-o", path("c.exr"), "--max-bend", "nan"},
        {"demo", "--out", path("demo"), "--k", "nan"}};
    for (const auto& args : conusRuns) {
        SCOPED_TRACE(args[0] + " " + args[args.size() - 2]);
        const Outcome r = run(args);
        EXPECT_EQ(r.exitCode, 2) << r.err;
        EXPECT_EQ(errorLines(r.err).size(), 1u) << r.err;
        EXPECT_TRUE(contains(r.err, "not a finite number")) << r.err;
    }
    for (const auto& [option, value] : std::vector<std::pair<std::string, std::string>>{
             {"--exposure", "nan"}, {"--gamma", "nan"}, {"--max-edge", "-inf"}, {"--radius", "nan"}}) {
        SCOPED_TRACE(option);
        const Outcome r = runTool("conus-view", {"--volume", "procedural:shepp-logan:16", "--screenshot", path("v.png"), option, value});
        EXPECT_EQ(r.exitCode, 2) << r.err;
        EXPECT_EQ(errorLines(r.err).size(), 1u) << r.err;
        EXPECT_TRUE(contains(r.err, "conus-view: " + option)) << r.err;
    }
}

TEST_F(SceneHostile, AnNrrdDataFileOutsideItsFolderOrADeviceOrFifoIsRefused) {
    for (const char* name : {"det_passwd.nhdr", "det_devzero.nhdr"}) {
        SCOPED_TRACE(name);
        const std::string file = scene(name);
        CONUS_REQUIRE(file);
        const Outcome r = run({"render", "volume", file, "-o", path("v.exr"), "--size", "16x16", "--backend", "cpu"});
        expectRefused(r, "render", "an absolute path");
        expectBounded(r, 400);
    }
    ASSERT_EQ(::mkfifo(path("fifo.raw").c_str(), 0600), 0);
    write("fifo.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\ndata file: fifo.raw\n");
    Outcome r = run({"render", "volume", path("fifo.nhdr"), "-o", path("v.exr"), "--size", "16x16", "--backend", "cpu"});
    expectRefused(r, "render", "not a regular file");  // teem would block on it forever
    expectBounded(r, 400);
    // A data file in another folder reads once that folder is allowed.
    fs::create_directories(m_dir / "data");
    std::string samples(64, '\0');
    for (int i = 0; i < 64; ++i) samples[std::size_t(i)] = char(i * 4);
    std::ofstream(m_dir / "data" / "cube.raw", std::ios::binary) << samples;
    fs::create_directories(m_dir / "headers");
    write("headers/cube.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\ndata file: ../data/cube.raw\n");
    r = run({"render", "volume", path("headers/cube.nhdr"), "-o", path("v.exr"), "--size", "16x16", "--backend", "cpu"});
    expectRefused(r, "render", "outside its folder");
    r = run({"render", "volume", path("headers/cube.nhdr"), "-o", path("v.exr"), "--size", "16x16", "--backend", "cpu",
             "--allow-dir", path("data")});
    EXPECT_EQ(r.exitCode, 0) << r.err;
}

TEST_F(SceneHostile, AGlbChunkLengthPastTheFileIsRefusedAtOnce) {
    const std::string file = scene("glb_jsonlen.glb");
    CONUS_REQUIRE(file);
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"render", "mesh", file, "-o", path("x.exr"), "--size", "32x32"},
          std::vector<std::string>{"bake", "reflection", file, "--size", "8", "-o", path("asset.exr")}}) {
        const Outcome r = run(args);
        expectRefused(r, args[0], "its GLB header declares 4294967295 bytes in a file of 400");
        expectBounded(r, 400);
    }
}

// An OFF header's face count, which Assimp allocates by before reading a face (a fuzzer's 139-byte
// file asked for 61 GB), is checked against the file's size and the caps first.
TEST_F(SceneHostile, AnOffFaceCountPastTheFileIsRefusedAtOnce) {
    const std::string file = (fs::path(CONUS_FUZZ_CORPUS) / "mesh" / "found-off-face-count.off").string();
    Outcome r = run({"render", "mesh", file, "-o", path("x.exr"), "--size", "32x32"});
    expectRefused(r, "render", "its OFF header declares");
    expectBounded(r, 400);
    write("big.off", "OFF\n3 2000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    r = run({"render", "mesh", path("big.off"), "-o", path("x.exr"), "--size", "32x32"});
    expectRefused(r, "render", "faces in a file of");
    // The count as Assimp reads it: glued to the keyword, and wrapped to 32 bits (the fuzzer's 5 KB
    // file asked for 1.5 billion vertices: 44 s and 17.7 GB before Assimp gave up).
    const std::string glued = (fs::path(CONUS_FUZZ_CORPUS) / "mesh" / "found-off-count-glued-to-keyword.off").string();
    r = run({"info", glued});
    expectRefused(r, "info", "its OFF header declares 1504774368 vertices in a file of");
    expectBounded(r, 400);
    write("wrapped.off", "OFF 4294967299 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");  // 2^32 + 3: three
    r = run({"info", path("wrapped.off")});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "mesh, 1 triangles, 3 vertices")) << r.out;
}

// Assimp's OFF reader copies a line into 4096 characters and reads the rest of a longer line as
// the next ones: the fuzzer's 13 KB file (a vertex line that runs on) crashed `conus info` and
// every command that reads a mesh. Lines of 4096 characters or more are refused first; 4095 read.
TEST_F(SceneHostile, AnOffLineLongerThanAssimpsBufferIsRefused) {
    const std::string found = (fs::path(CONUS_FUZZ_CORPUS) / "mesh" / "found-off-long-line.off").string();
    write("runs-on.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0" + std::string(13000, 'x') + "\n3 0 1 2\n");
    write("at-4096.off", "OFF\n3 1 0\n0 0 0" + std::string(4096 - 5, ' ') + "\n1 0 0\n0 1 0\n3 0 1 2\n");
    for (const std::string& file : {found, path("runs-on.off"), path("at-4096.off")}) {
        SCOPED_TRACE(file);
        Outcome r = run({"info", file});
        expectRefused(r, "info", "characters an OFF line may have");
        EXPECT_TRUE(contains(r.err, "is not an OpenEXR file")) << r.err;
        r = run({"render", "mesh", file, "-o", path("x.exr"), "--size", "32x32"});
        expectRefused(r, "render", "characters an OFF line may have");
        expectBounded(r, 400);
        EXPECT_FALSE(fs::exists(path("x.exr")));
    }
    write("at-4095.off", "OFF\n3 1 0\n0 0 0" + std::string(4095 - 5, ' ') + "\n1 0 0\n0 1 0\n3 0 1 2\n");
    const Outcome r = run({"info", path("at-4095.off")});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "mesh, 1 triangles, 3 vertices")) << r.out;
}

// Assimp's COLLADA reader reads a primitive's index list (<p>) number by number and, at a character
// that is neither a digit nor a space, neither moves on nor stops: the fuzzer's 9.7 KB cube with
// "4meshng" in its list grew past 4.7 GB in 15 s. Such a list is refused before Assimp reads it
// (a CDATA section in one too); the same triangle with a clean list still reads.
TEST_F(SceneHostile, ACOLLADAIndexListWithALetterIsRefused) {
    const std::string found = (fs::path(CONUS_FUZZ_CORPUS) / "mesh" / "found-collada-index-list-letter.dae").string();
    const auto triangle = [](const std::string& list) {
        return std::string(
                   "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
                   "<library_geometries><geometry id=\"g\"><mesh>\n"
                   "<source id=\"p\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 1 0</float_array>\n"
                   "<technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\"><param name=\"X\" type=\"float\"/>"
                   "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"
                   "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>\n"
                   "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>") +
               list +
               "</p></triangles>\n</mesh></geometry></library_geometries>\n"
               "<library_visual_scenes><visual_scene id=\"s\"><node><instance_geometry url=\"#g\"/></node></visual_scene>"
               "</library_visual_scenes>\n<scene><instance_visual_scene url=\"#s\"/></scene>\n</COLLADA>\n";
    };
    write("letter.dae", triangle("0 1x 2"));
    write("cdata.dae", triangle("<![CDATA[0 1 2]]>"));
    for (const std::string& file : {found, path("letter.dae"), path("cdata.dae")}) {
        SCOPED_TRACE(file);
        Outcome r = run({"info", file});
        expectRefused(r, "info", "a COLLADA index list (<p>) holds a character that is neither a digit nor a space");
        r = run({"render", "mesh", file, "-o", path("x.exr"), "--size", "32x32"});
        expectRefused(r, "render", "a COLLADA index list");
        expectBounded(r, 400);
        EXPECT_FALSE(fs::exists(path("x.exr")));
    }
    write("clean.dae", triangle("\n 0\t1 2 \r\n"));
    const Outcome r = run({"info", path("clean.dae")});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "mesh, 1 triangles, 3 vertices")) << r.out;
}

// Assimp's OFF reader drops a face whose corner count is 0 or past 9 by lowering the mesh's face
// count; with every face dropped it read past its arrays (the fuzzer's 80-byte file). Such a file
// is refused, found where Assimp finds its faces (after comment lines and blank lines); cubes of
// four-corner faces, comments and COFF colours still read.
TEST_F(SceneHostile, AnOffFaceWithoutACornerCountIsRefused) {
    const std::string found = (fs::path(CONUS_FUZZ_CORPUS) / "mesh" / "found-off-no-faces.off").string();
    write("zero.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1 2\n");
    write("ten.off", "# comment\nOFF\n3 2 0\n\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n10 0 1 2 0 1 2 0 1 2 0\n");
    for (const std::string& file : {found, path("zero.off"), path("ten.off")}) {
        SCOPED_TRACE(file);
        const Outcome r = run({"render", "mesh", file, "-o", path("x.exr"), "--size", "32x32"});
        expectRefused(r, "render", "does not start with a corner count of 1 to 9");
        expectBounded(r, 400);
    }
    write("cube.off", "# a cube\nOFF\n# its counts\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                      "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
    write("coff.off", "COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n0 1 0 0 0 1 1\n3 0 1 2\n");
    for (const auto& [name, expected] : {std::pair{"cube.off", "mesh, 12 triangles, 8 vertices"},
                                         std::pair{"coff.off", "mesh, 1 triangles, 3 vertices, vertex colours"}}) {
        const Outcome r = run({"info", path(name)});
        EXPECT_EQ(r.exitCode, 0) << name << ": " << r.err;
        EXPECT_TRUE(contains(r.out, expected)) << r.out;
    }
}

TEST_F(SceneHostile, AnNpzBombIsRefusedBeforeInflating) {
    const std::string file = scene("npz_bomb_1GiB.npz");
    CONUS_REQUIRE(file);
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"heightfield", "encode", file, "-o", path("t.exr"), "--size", "32x32"},
          std::vector<std::string>{"bake", "relief", file, "-o", path("r.exr"), "--size", "32x32"}}) {
        const Outcome r = run(args);
        expectRefused(r, args[0], "the limit for " + std::to_string(conus::kMaxDemSamples) + " height samples");
        expectBounded(r, 400);
    }
}

TEST_F(SceneHostile, CoincidentTrianglesAreMergedSoARenderStaysFast) {
    const std::string file = scene("coincident_20k.obj");
    CONUS_REQUIRE(file);
    const Outcome r = run({"render", "mesh", file, "-o", path("x.exr"), "--size", "128x128"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "dropped 19999 exact duplicate triangles")) << r.err;
    expectBounded(r, 700);
}

TEST_F(SceneHostile, AVolumeRayTakesStepsBoundedByTheVolume) {
    Outcome r = run({"render", "volume", "procedural:shepp-logan:32", "-o", path("v.exr"), "--size", "16x16", "--backend",
                     "cpu", "--step", "1e-6", "--uniform"});
    expectRefused(r, "render", "give a larger step", 2);
    expectBounded(r, 400);
    r = run({"render", "volume", "procedural:shepp-logan:700", "-o", path("v.exr"), "--size", "16x16"});
    expectRefused(r, "render", "pass the limit of " + std::to_string(conus::kMaxVolumeVoxels), 2);
    expectBounded(r, 400);
}

TEST_F(SceneHostile, ListsThatAreNotRegularFilesAreRefused) {
    Outcome r = run({"encode", "--list", "/dev/zero", "--out-dir", path("out")});
    expectRefused(r, "encode", "not a regular file");
    expectBounded(r, 400);
    ASSERT_EQ(::mkfifo(path("list.fifo").c_str(), 0600), 0);
    r = run({"encode", "--list", path("list.fifo"), "--out-dir", path("out")});
    expectRefused(r, "encode", "not a regular file");
    expectBounded(r, 400);
}

TEST_F(SceneHostile, SizesAreCheckedBeforeAllocating) {
    write("small.ppm", "P3\n2 2\n255\n0 50 100 150 200 250\n10 20 30 40 50 60\n");
    Outcome r = run({"encode", path("small.ppm"), "-o", path("x.exr"), "--size", "32768x32768", "--focus", "0.5,0.5,0.1,2"});
    expectRefused(r, "encode", "beyond the encode memory limit of " + std::to_string(conus::kMaxEncodeBytes));
    expectBounded(r, 400);
    r = run({"heightfield", "encode", "procedural:20000", "-o", path("t.exr")});
    expectRefused(r, "heightfield", "more than the limit of " + std::to_string(conus::kMaxDemSamples), 2);
    expectBounded(r, 400);
    // A 4097-node map for a small image: a minute of building for nothing it can show.
    r = run({"heightfield", "encode", "procedural:64", "-o", path("t.exr"), "--size", "32x32", "--grid", "4097"});
    expectRefused(r, "heightfield", "--grid 4097 is finer than a 32x32 image can show; at most 129 nodes a side", 2);
    expectBounded(r, 400);
    r = run({"encode", path("small.ppm"), "-o", path("x.exr"), "--focus", "0.5,0.5,0.1,2", "--grid", "4097"});
    expectRefused(r, "encode", "--grid 4097 is finer", 2);
    expectBounded(r, 400);
}

TEST_F(SceneHostile, AFileThatValidatesAlsoDecodes) {
    // The source size alone makes the default frame pass the decode budget.
    const std::string big = scene("valid-sourceSize-32768x16000.exr");
    CONUS_REQUIRE(big);
    Outcome r = run({"decode", big, "-o", path("x.png")});
    expectRefused(r, "decode", "give a smaller --size");
    expectBounded(r, 400);
    EXPECT_FALSE(fs::exists(path("x.png")));
    r = run({"decode", big, "-o", path("x.png"), "--size", "64x32"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    // A garbage ICC profile: refused by validate (V16) and so by decode, one line each.
    const std::string icc = scene("valid-bad-icc-multiline.exr");
    r = run({"validate", icc});
    expectRefused(r, "validate", "not a valid CoNUS file");
    EXPECT_TRUE(contains(r.out, ": V16: ") && contains(r.out, "not an ICC profile")) << r.out;
    r = run({"decode", icc, "-o", path("y.png")});
    expectRefused(r, "decode", "V16");
}

TEST_F(SceneHostile, DamagedPixelDataFailsValidate) {
    // A zip-compressed file with one byte of its last image chunk flipped (its compressed pixels:
    // the chunks of a noisy 64x64 picture are several KB, the map's chunk after them a few dozen
    // bytes). The headers and chunk tables still pass; only a decompression sees the damage.
    std::string pgm = "P2\n64 64\n255\n";
    std::uint32_t state = 12345;
    for (int i = 0; i < 64 * 64; ++i) {
        state = state * 1664525u + 1013904223u;  // noise: chunks that do not compress
        pgm += std::to_string(state >> 24) + " ";
    }
    write("p.pgm", pgm);
    const Outcome made = run({"uniform", path("p.pgm"), "-o", path("u.exr"), "--size", "64x64", "--compression", "zip"});
    ASSERT_EQ(made.exitCode, 0) << made.err;
    std::ifstream in(m_dir / "u.exr", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 4000u);
    bytes[bytes.size() - 1000] = char(bytes[bytes.size() - 1000] ^ 0x5a);
    std::ofstream(m_dir / "damaged.exr", std::ios::binary) << bytes;
    Outcome r = run({"validate", path("damaged.exr"), "--headers-only"});
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    r = run({"validate", path("damaged.exr")});
    expectRefused(r, "validate", "not a valid CoNUS file");
    EXPECT_TRUE(contains(r.out, ": V1: damaged OpenEXR data")) << r.out;
    EXPECT_NE(run({"decode", path("damaged.exr"), "-o", path("d.png")}).exitCode, 0);
}

TEST_F(SceneHostile, SmallerItemsHaveTheirExitCodes) {
    Outcome r = run({"decode", "x.exr", "-o", path("x.png"), "--exposure", "nan"});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    write("a.pgm", "P2\n2 2\n255\n0 1 2 3\n");
    write("b.pgm", "P2\n2 2\n255\n3 2 1 0\n");
    r = run({"encode", path("a.pgm"), path("b.pgm"), "--out-dir", path("out"), "--name", "/tmp/escape-{stem}.exr"});
    expectRefused(r, "encode", "not a file name inside --out-dir", 2);
    r = run({"encode", path("a.pgm"), path("b.pgm"), "--out-dir", path("out"), "--name", "../{stem}.exr"});
    expectRefused(r, "encode", "not a file name inside --out-dir", 2);
    EXPECT_FALSE(fs::exists("/tmp/escape-a.exr") || fs::exists(path("a.exr")));
    // Bad data in a file is exit 1: NaN heights, absurd spacings, a zero-length NRRD direction.
    std::string npy("\x93NUMPY\x01\x00", 8);
    std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }";
    header.resize(118, ' ');
    header += '\n';
    npy += char(header.size() & 0xff);
    npy += char(header.size() >> 8);
    const float heights[6] = {1, 2, std::nanf(""), 4, 5, 6};
    npy += header + std::string(reinterpret_cast<const char*>(heights), sizeof heights);
    write("nan.npy", npy);
    r = run({"heightfield", "encode", path("nan.npy"), "-o", path("t.exr"), "--size", "16x16"});
    expectRefused(r, "heightfield", "every height must be finite");
    write("zero.nrrd", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\nspace dimension: 3\n"
                       "space directions: (0,0,0) (0,1,0) (0,0,1)\n\n" + std::string(64, '\1'));
    r = run({"render", "volume", path("zero.nrrd"), "-o", path("v.exr"), "--size", "16x16", "--backend", "cpu"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_EQ(errorLines(r.err).size(), 1u) << r.err;
}

// A reflection asset is one file written as a whole: a new bake replaces the earlier asset, a
// failed one leaves it as it was, and neither leaves a temporary file.
TEST_F(SceneHostile, AReflectionAssetIsWrittenAsAWhole) {
    write("scene.obj", "v -5 -1 -5\nv 5 -1 -5\nv 5 -1 5\nv -5 -1 5\nf 1 2 3 4\n");
    Outcome r = run({"bake", "reflection", path("scene.obj"), "--size", "8", "-o", path("asset.exr")});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = run({"bake", "reflection", path("scene.obj"), "--size", "16", "-o", path("asset.exr")});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto size = fs::file_size(m_dir / "asset.exr");
    r = run({"bake", "reflection", path("missing.obj"), "--size", "8", "-o", path("asset.exr")});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_EQ(fs::file_size(m_dir / "asset.exr"), size);
    EXPECT_EQ(run({"validate", path("asset.exr")}).exitCode, 0);
    for (const auto& e : fs::directory_iterator(m_dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

}  // namespace

namespace {

TEST_F(SceneHostile, InfoListsTheSceneLimits) {
    const conus::hostile::Outcome r = run({"info", "--limits", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    for (const conus::LimitEntry& e : conus::limitTable()) EXPECT_EQ(j[e.name]["value"], e.value) << e.name;
    EXPECT_EQ(j["demSamples"]["value"], conus::kMaxDemSamples);
    EXPECT_EQ(j["volumeReadBytes"]["unit"], "bytes");
    EXPECT_EQ(j["encodeBytes"]["value"], conus::kMaxEncodeBytes);
}

}  // namespace
