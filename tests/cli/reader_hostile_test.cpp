// The readers against ../shared/data/hostile/round4 and variants of each class the tests make
// themselves: images that are not flat pictures (volume and cube DDS textures, DDS arrays), scene
// files nested past what a parser's recursion survives, instancing bombs, files named outside a
// model's folder (an OBJ's material library, an NRRD data file in any case and line ending), .npy
// headers that sent std::regex into deep recursion, and .npz archives with a large member nobody
// reads (JPEGs: reader_hostile_jpeg_test.cpp). Each goes through the real tools (`conus` commands,
// the viewer) and is refused in one line with exit 1, or read correctly, within a bounded peak memory.
#include <sys/stat.h>

#include <cstring>

#include <OpenImageIO/imageio.h>

#include "hostile_fixture.h"

namespace {

using namespace conus::hostile;

class ReaderHostile : public Hostile {
protected:
    static std::string round4(const std::string& name) { return hostileData(fs::path("round4") / name); }
    static std::string seed(const std::string& folder, const std::string& name) {
        return (fs::path(CONUS_FUZZ_CORPUS) / folder / name).string();
    }
    // `render mesh` (within 300 MB) and `bake reflection` of `scene` both refused for `reason`.
    void expectRenderAndBakeRefuse(const std::string& scene, const std::string& reason) {
        Outcome r = run({"render", "mesh", scene, "-o", path("x.exr"), "--size", "32x32"});
        expectRefused(r, "render", reason);
        expectMemory(r, 300);
        r = run({"bake", "reflection", scene, "--size", "8", "-o", path("a.exr")});
        expectRefused(r, "bake", reason);
    }
    // One refusal line holding `reason` and none of `secret` (a file's content).
    void expectRefusedQuietly(const Outcome& r, const std::string& command, const std::string& reason,
                              const std::string& secret = "") {
        expectRefused(r, command, reason);
        if (!secret.empty()) {
            EXPECT_FALSE(contains(r.err, secret) || contains(r.out, secret)) << r.err;
        }
    }
};

// ---- images --------------------------------------------------------------------------------------

void put32(std::string& s, std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) s[at + std::size_t(i)] = char((v >> (8 * i)) & 0xff);
}

// A DDS of 32-bit BGRA pixels: `depth` slices (a volume when > 1), six faces when `cube`, or a
// DX10 array of `layers` 2-D textures.
std::string dds(int width, int height, int depth, bool cube, int layers = 1) {
    std::string s(128, '\0');
    std::memcpy(s.data(), "DDS ", 4);
    put32(s, 4, 124);
    put32(s, 8, 0x1007 | (depth > 1 ? 0x800000 : 0));  // caps, height, width, pixel format (+ depth)
    put32(s, 12, std::uint32_t(height));
    put32(s, 16, std::uint32_t(width));
    put32(s, 20, std::uint32_t(width * 4));
    put32(s, 24, std::uint32_t(depth > 1 ? depth : 0));
    put32(s, 76, 32);  // the pixel format
    if (layers > 1) {
        put32(s, 80, 0x4);  // a FourCC: DX10
        std::memcpy(s.data() + 84, "DX10", 4);
    } else {
        put32(s, 80, 0x41);  // RGB with alpha
        put32(s, 88, 32);
        put32(s, 92, 0x00ff0000);
        put32(s, 96, 0x0000ff00);
        put32(s, 100, 0x000000ff);
        put32(s, 104, 0xff000000);
    }
    put32(s, 108, 0x1000 | (depth > 1 || cube ? 0x8 : 0));
    put32(s, 112, (depth > 1 ? 0x200000 : 0) | (cube ? 0x200 | 0xFC00 : 0));
    if (layers > 1) {
        std::string dx10(20, '\0');
        put32(dx10, 0, 28);  // R8G8B8A8_UNORM
        put32(dx10, 4, 3);   // a 2-D texture
        put32(dx10, 12, std::uint32_t(layers));
        s += dx10;
    }
    const int slices = depth * (cube ? 6 : 1) * layers;
    std::string pixels(std::size_t(width) * height * 4 * slices, '\0');
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = char(i * 7 + 3);
    return s + pixels;
}

TEST_F(ReaderHostile, VolumeAndCubeTexturesAreRefusedAsPictures) {
    write("vol4.dds", slurp(seed("image", "hostile-vol4-dds")).substr(1));  // the reproducer
    write("vol8.dds", dds(8, 8, 8, false));
    write("vol16.png", dds(16, 16, 3, false));  // a volume by any name
    write("cube.dds", dds(8, 8, 1, true));
    write("array.dds", dds(8, 8, 1, false, 2));
    write("depth_only.dds", slurp(seed("image", "found-dds-depth-without-volume-oiio-hang")).substr(1));
    const struct {
        const char* file;
        const char* reason;
    } cases[] = {{"vol4.dds", "a volume texture of 4x4x4 samples, not a picture"},
                 {"vol8.dds", "a volume texture of 8x8x8 samples"},
                 {"vol16.png", "a volume texture of 16x16x3 samples"},
                 {"cube.dds", "a cube map"},
                 {"array.dds", "an array of 2 textures, not a picture"},
                 // Depth declared without the volume flag: OpenImageIO's reader looped on it (found
                 // by the image harness); the header alone refuses it.
                 {"depth_only.dds", "a volume texture of 4x4x4 samples"}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.file);
        Outcome r = run({"uniform", path(c.file), "-o", path("x.exr")});
        expectRefused(r, "uniform", c.reason);
        expectMemory(r, 300);
        r = run({"encode", path(c.file), "-o", path("x.exr")});
        expectRefused(r, "encode", c.reason);
        r = run({"heightfield", "encode", path(c.file), "-o", path("t.exr"), "--size", "16x16"});
        expectRefused(r, "heightfield", c.reason);
        r = runTool("conus", {"uniform", "-", "-o", path("x.exr")}, path(c.file));  // standard input
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_EQ(errorLines(r.err).size(), 1u) << r.err;
        EXPECT_FALSE(fs::exists(path("x.exr")) || fs::exists(path("t.exr")));
    }
    // A flat DDS still reads, as a picture of its size.
    write("flat.dds", dds(8, 4, 1, false));
    const Outcome r = run({"uniform", path("flat.dds"), "-o", path("flat.exr")});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "of a 8x4 source")) << r.out;
}

// An uncompressed DDS whose pixel format gives a channel no bits (a zero mask): OpenImageIO's
// reader never finished it (found by the image harness: a 177-byte file held `conus uniform`
// past any limit); the header refuses it, for each channel, and a full set of masks still reads.
TEST_F(ReaderHostile, ADdsChannelWithoutBitsIsRefusedFromItsHeader) {
    write("found.dds", slurp(seed("image", "found-dds-zero-channel-mask-oiio-hang")).substr(1));
    const struct {
        std::size_t at;
        const char* channel;
    } masks[] = {{92, "red"}, {96, "green"}, {100, "blue"}, {104, "alpha"}};
    for (const auto& m : masks) {
        std::string bytes = dds(8, 4, 1, false);
        put32(bytes, m.at, 0);
        write(std::string("no_") + m.channel + ".dds", bytes);
    }
    for (const std::string file : {"found.dds", "no_red.dds", "no_green.dds", "no_blue.dds", "no_alpha.dds"}) {
        SCOPED_TRACE(file);
        const std::string channel = file == "found.dds" ? "green" : file.substr(3, file.size() - 7);
        Outcome r = run({"uniform", path(file), "-o", path("x.exr")});
        expectRefused(r, "uniform", "a DDS whose pixel format gives its " + channel + " channel no bits");
        EXPECT_LT(r.seconds, 5.0 * conus::testing::kTimeScale);
        expectMemory(r, 300);
        r = runTool("conus", {"uniform", "-", "-o", path("x.exr")}, path(file));  // standard input
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_FALSE(fs::exists(path("x.exr")));
    }
}

// An uncompressed DDS whose pixels take no bits, or bits that are no whole bytes, or a mask past
// them: OpenImageIO's reader never finished the first (found by the image harness: a 151-byte file
// with an alpha mask and 0 bits a pixel held `conus uniform` and oiiotool alike). The header
// refuses them; 16-bit 5:6:5 pixels still read.
TEST_F(ReaderHostile, ADdsPixelWithoutWholeBytesIsRefusedFromItsHeader) {
    write("found.dds", slurp(seed("image", "found-dds-zero-bits-oiio-hang")).substr(1));
    const struct {
        const char* file;
        std::uint32_t bits, alphaMask;
        const char* reason;
    } cases[] = {{"found.dds", 0, 0, "says 0 bits a pixel"},
                 {"bits0.dds", 0, 0xff000000, "says 0 bits a pixel"},
                 {"bits12.dds", 12, 0x00000f00, "says 12 bits a pixel"},
                 {"wide_alpha.dds", 16, 0xff000000, "alpha mask reaches past its 16 bits a pixel"}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.file);
        if (std::string(c.file) != "found.dds") {
            std::string bytes = dds(8, 4, 1, false);
            put32(bytes, 88, c.bits);
            put32(bytes, 92, 0xf800);
            put32(bytes, 96, 0x07e0);
            put32(bytes, 100, 0x001f);
            put32(bytes, 104, c.alphaMask);
            write(c.file, bytes);
        }
        Outcome r = run({"uniform", path(c.file), "-o", path("x.exr")});
        expectRefused(r, "uniform", c.reason);
        expectMemory(r, 300);
        r = runTool("conus", {"uniform", "-", "-o", path("x.exr")}, path(c.file));  // standard input
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_FALSE(fs::exists(path("x.exr")));
    }
    std::string rgb565 = dds(8, 4, 1, false);
    put32(rgb565, 80, 0x40);  // RGB, no alpha
    put32(rgb565, 88, 16);
    put32(rgb565, 92, 0xf800);
    put32(rgb565, 96, 0x07e0);
    put32(rgb565, 100, 0x001f);
    put32(rgb565, 104, 0);
    write("rgb565.dds", rgb565);
    const Outcome r = run({"uniform", path("rgb565.dds"), "-o", path("flat.exr")});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "of a 8x4 source")) << r.out;
}

// An uncompressed DDS whose pixel format names alpha beside no colour (the alpha-pixels flag
// without RGB or luminance), or no channel at all: OpenImageIO's reader never finished either
// (found by the image harness: a 161-byte file). The header refuses them; luminance with alpha,
// luminance alone and alpha alone still read.
TEST_F(ReaderHostile, ADdsAlphaBesideNoColourIsRefusedFromItsHeader) {
    write("found.dds", slurp(seed("image", "found-dds-alpha-beside-no-colour-oiio-hang")).substr(1));
    const auto format = [&](const char* file, std::uint32_t flags, std::uint32_t bits, std::uint32_t first, std::uint32_t alpha) {
        std::string bytes = dds(8, 4, 1, false);
        put32(bytes, 80, flags);
        put32(bytes, 88, bits);
        put32(bytes, 92, first);
        put32(bytes, 96, 0);
        put32(bytes, 100, 0);
        put32(bytes, 104, alpha);
        write(file, bytes);
    };
    format("alpha_beside.dds", 0x1, 32, 0, 0xff000000);
    format("alpha_both.dds", 0x3, 32, 0, 0xff000000);
    format("nothing.dds", 0x0, 32, 0, 0);
    for (const std::string file : {"found.dds", "alpha_beside.dds", "alpha_both.dds", "nothing.dds"}) {
        SCOPED_TRACE(file);
        Outcome r = run({"uniform", path(file), "-o", path("x.exr")});
        expectRefused(r, "uniform", file == "nothing.dds" ? "names no channels" : "has alpha beside no colour");
        expectMemory(r, 300);
        r = runTool("conus", {"uniform", "-", "-o", path("x.exr")}, path(file));  // standard input
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_FALSE(fs::exists(path("x.exr")));
    }
    format("luminance_alpha.dds", 0x20001, 16, 0x00ff, 0xff00);
    format("luminance.dds", 0x20000, 8, 0xff, 0);
    format("alpha.dds", 0x2, 8, 0, 0xff);
    for (const std::string file : {"luminance_alpha.dds", "luminance.dds", "alpha.dds"}) {
        const Outcome r = run({"uniform", path(file), "-o", path("flat.exr")});
        EXPECT_EQ(r.exitCode, 0) << file << ": " << r.err;
        EXPECT_TRUE(contains(r.out, "of a 8x4 source")) << r.out;
    }
}

// A model whose material names the volume texture: the mesh read refuses it, through render,
// bake and the viewer.
TEST_F(ReaderHostile, AVolumeTextureNamedByAMeshIsRefused) {
    write("m/vol.dds", dds(4, 4, 4, false));
    write("m/tex.mtl", "newmtl t\nKd 1 1 1\nmap_Kd vol.dds\n");
    write("m/tri.obj", "mtllib tex.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3\n");
    Outcome r = run({"render", "mesh", path("m/tri.obj"), "-o", path("x.exr"), "--size", "32x32"});
    expectRefused(r, "render", "a volume texture of 4x4x4 samples");
    expectMemory(r, 400);
    r = run({"bake", "reflection", path("m/tri.obj"), "--size", "8", "-o", path("a.exr")});
    expectRefused(r, "bake", "a volume texture");
    r = runTool("conus-view", {"--mesh", path("m/tri.obj"), "--screenshot", path("s.png"), "--size", "32x32"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    ASSERT_EQ(errorLines(r.err).size(), 1u) << r.err;
    EXPECT_TRUE(contains(r.err, "a volume texture")) << r.err;
    EXPECT_FALSE(fs::exists(path("x.exr")) || fs::exists(path("a.exr")) || fs::exists(path("s.png")));
}

// A progressive JPEG made by libjpeg (through OpenImageIO), then the same with its last scan
// repeated: each scan is a pass over the whole image, so scans are counted before decoding.
// ---- scene files ---------------------------------------------------------------------------------

// A glTF of one triangle under a chain of `depth` nodes (each the only child of the one before).
std::string chainGltf(int depth) {
    std::string nodes;
    for (int i = 0; i < depth; ++i)
        nodes += (i ? "," : "") + (i + 1 < depth ? "{\"children\": [" + std::to_string(i + 1) + "]}" : std::string("{\"mesh\": 0}"));
    return R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "scene": 0, "nodes": [)" + nodes + R"(],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
 "buffers": [{"uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA", "byteLength": 36}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]})";
}

// `levels` nodes, each naming the next twice: 2^levels instances of the triangle under the last.
std::string dagGltf(int levels) {
    std::string g = chainGltf(1);
    std::string nodes;
    for (int i = 0; i < levels; ++i)
        nodes += "{\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]},";
    nodes += "{\"mesh\": 0}";
    const std::size_t at = g.find("\"nodes\": [{\"mesh\": 0}]");
    return g.replace(at, std::strlen("\"nodes\": [{\"mesh\": 0}]"), "\"nodes\": [" + nodes + "]");
}

TEST_F(ReaderHostile, DeepAndInstancedGltfNodeTreesAreRefusedBeforeAssimp) {
    write("chain_at_limit.gltf", chainGltf(conus::kMaxSceneDepth));
    write("chain_past.gltf", chainGltf(conus::kMaxSceneDepth + 1));
    write("chain_20000.gltf", chainGltf(20000));
    write("dag_22.gltf", dagGltf(22));
    write("dag_12.gltf", dagGltf(12));
    // The DAG with a byte that is not UTF-8 in a key (found by the mesh harness): Assimp's JSON
    // reader took it and expanded 2^22 instances (9.7 GB) while the screen, unable to parse it, let it by.
    write("dag_22_not_utf8.gltf", [] {
        std::string g = dagGltf(22);
        g.insert(g.find("\"children\"") + 5, "\xff");
        return g;
    }());
    write("cycle.gltf", [] {
        std::string g = chainGltf(2);
        g.replace(g.find("{\"mesh\": 0}"), 11, "{\"mesh\": 0, \"children\": [0]}");
        return g;
    }());
    // JSON nested past the limit in a member Assimp parses but does not use.
    write("json_deep.gltf", [] {
        std::string g = chainGltf(1);
        g.insert(g.size() - 1, ", \"extras\": " + std::string(300000, '[') + std::string(300000, ']'));
        return g;
    }());
    Outcome r = run({"render", "mesh", path("chain_at_limit.gltf"), "-o", path("ok.exr"), "--size", "32x32"});
    EXPECT_EQ(r.exitCode, 0) << r.err;  // at the limit: Assimp's recursion is fine
    r = run({"render", "mesh", path("dag_12.gltf"), "-o", path("dag.exr"), "--size", "32x32"});
    EXPECT_EQ(r.exitCode, 0) << r.err;  // 4096 instances: within every cap
    const struct {
        const char* file;
        std::string reason;
    } cases[] = {
        {"chain_past.gltf", "its node tree is more than " + std::to_string(conus::kMaxSceneDepth) + " nodes deep"},
        {"chain_20000.gltf", "its node tree is more than"},
        {"dag_22.gltf", "its node tree expands to more than " + std::to_string(conus::kMaxSceneNodes) + " nodes"},
        {"cycle.gltf", "node 0 is its own ancestor"},
        {"dag_22_not_utf8.gltf", "its JSON does not parse as a glTF's"},
        {"json_deep.gltf", "its JSON nests more than " + std::to_string(conus::kMaxMarkupDepth) + " levels deep"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.file);
        expectRenderAndBakeRefuse(path(c.file), c.reason);
        r = runTool("conus-view", {"--mesh", path(c.file), "--screenshot", path("s.png"), "--size", "32x32"});
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_TRUE(errorLines(r.err).size() == 1u && contains(r.err, c.reason)) << r.err;
        EXPECT_FALSE(fs::exists(path("x.exr")) || fs::exists(path("a.exr")) || fs::exists(path("s.png")));
    }
    for (const char* name : {"mesh/deep_nodes_20000.gltf", "mesh/instance_dag_4M.gltf"}) {
        const std::string file = round4(name);
        CONUS_REQUIRE(file);
        r = run({"render", "mesh", file, "-o", path("x.exr"), "--size", "32x32"});
        expectRefused(r, "render", "its node tree");
        expectMemory(r, 300);
    }
}

// A glTF instancing a mesh of many triangles a few times: the count after instancing, against
// the triangle cap, before anything is expanded.
TEST_F(ReaderHostile, TrianglesAfterInstancingCountAgainstTheCap) {
    std::string g = dagGltf(10);  // 1024 instances of an accessor that claims 2^15 corners...
    g.replace(g.find("\"count\": 3"), 10, "\"count\": 98304");
    write("many.gltf", g);
    const Outcome r = run({"render", "mesh", path("many.gltf"), "-o", path("x.exr"), "--size", "32x32"});
    expectRefused(r, "render", "its nodes instance more than " + std::to_string(conus::kMaxMeshTriangles) + " triangles");
    expectMemory(r, 300);
}

// COLLADA and X3D: XML nested past the limit is refused before Assimp's recursive readers see it,
// and so is a COLLADA node graph deeper than the node limit or instancing past the caps (counted
// from the text, over the shared nodes).
TEST_F(ReaderHostile, DeepColladaAndX3dAreRefused) {
    const auto collada = [](int depth) {
        std::string nodes, ends;
        for (int i = 0; i < depth; ++i) {
            nodes += "<node id=\"n" + std::to_string(i) + "\">";
            ends += "</node>";
        }
        return std::string(R"(<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array>
<technique_common><accessor source="#pa" count="3" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s">)") +
               nodes + "<instance_geometry url=\"#g\"/>" + ends + R"(</visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#s"/></scene></COLLADA>
)";
    };
    const auto x3d = [](int depth) {
        std::string groups, ends;
        for (int i = 0; i < depth; ++i) {
            groups += "<Transform>";
            ends += "</Transform>";
        }
        return R"(<?xml version="1.0" encoding="UTF-8"?>
<X3D profile="Interchange" version="3.3"><Scene>)" +
               groups + R"(<Shape><IndexedFaceSet coordIndex="0 1 2 -1"><Coordinate point="0 0 0 1 0 0 0 1 0"/></IndexedFaceSet></Shape>)" +
               ends + "</Scene></X3D>\n";
    };
    // A DAG of library nodes, each instancing the next twice: 2^22 copies once Assimp expands it
    // (45 s and 9.9 GB before it was counted from the text).
    write("dag.dae", [&] {
        std::string library;
        for (int i = 0; i < 22; ++i)
            library += "<node id=\"d" + std::to_string(i) + "\"><instance_node url=\"#d" + std::to_string(i + 1) +
                       "\"/><instance_node url=\"#d" + std::to_string(i + 1) + "\"/></node>";
        library += "<node id=\"d22\"><instance_geometry url=\"#g\"/></node>";
        std::string file = collada(1);
        file.replace(file.find("<node id=\"n0\">"), std::strlen("<node id=\"n0\">"), "<node id=\"n0\"><instance_node url=\"#d0\"/>");
        file.replace(file.find("<library_visual_scenes>"), 0, "<library_nodes>" + library + "</library_nodes>");
        return file;
    }());
    write("shallow.dae", collada(4));
    write("nodes_300.dae", collada(300));
    write("xml_20000.dae", collada(20000));
    write("deep.x3d", x3d(20000));
    write("deep_comments.x3d", "<!-- <a><b><c> -->" + x3d(20000));
    Outcome r = run({"render", "mesh", path("shallow.dae"), "-o", path("ok.exr"), "--size", "32x32"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const struct {
        const char* file;
        std::string reason;
    } cases[] = {
        {"nodes_300.dae", "its node tree is more than " + std::to_string(conus::kMaxSceneDepth) + " nodes deep"},
        {"dag.dae", "its node tree expands to more than " + std::to_string(conus::kMaxSceneNodes) + " nodes"},
        {"xml_20000.dae", "its XML nests more than " + std::to_string(conus::kMaxMarkupDepth) + " levels deep"},
        {"deep.x3d", "its XML nests more than"},
        {"deep_comments.x3d", "its XML nests more than"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.file);
        expectRenderAndBakeRefuse(path(c.file), c.reason);
    }
}

// An OBJ's material library outside its folder is refused before it is opened, and no message
// shows a byte of it; nor of a library inside the folder that Assimp could not read.
TEST_F(ReaderHostile, AMaterialLibraryIsCheckedBeforeItIsOpened) {
    const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    write("secret/.env", "API_TOKEN=sk-live-0123456789abcdef\n");
    write("model/env.obj", "mtllib ../secret/.env\n" + triangle);
    write("model/passwd.obj", "mtllib ../../../../../../../../../etc/passwd\n" + triangle);
    write("model/early.mtl", "API_TOKEN=inside-the-folder\nnewmtl m\n");
    write("model/early.obj", "mtllib early.mtl\n" + triangle);
    ASSERT_EQ(::mkfifo(path("model/fifo.mtl").c_str(), 0600), 0);
    write("model/fifo.obj", "mtllib fifo.mtl\n" + triangle);
    const struct {
        const char* file;
        const char* reason;
        const char* secret;
    } cases[] = {{"model/env.obj", "outside its folder", "sk-live"},
                 {"model/passwd.obj", "outside its folder", "root:"},
                 {"model/early.obj", "has a statement before its first newmtl (non-empty line 1", "inside-the-folder"},
                 {"model/fifo.obj", "not a regular file", ""}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.file);
        Outcome r = run({"render", "mesh", path(c.file), "-o", path("x.exr"), "--size", "32x32"});
        expectRefusedQuietly(r, "render", c.reason, c.secret);
        expectMemory(r, 300);
        r = run({"bake", "reflection", path(c.file), "--size", "8", "-o", path("a.exr")});
        expectRefusedQuietly(r, "bake", c.reason, c.secret);
        r = runTool("conus-view", {"--mesh", path(c.file), "--screenshot", path("s.png"), "--size", "32x32"});
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_TRUE(contains(r.err, c.reason)) << r.err;
        EXPECT_FALSE(contains(r.err, c.secret) && *c.secret) << r.err;
    }
    const std::string shared = round4("mesh/model/mtllib_passwd.obj");
    CONUS_REQUIRE(shared);
    const Outcome r = run({"render", "mesh", shared, "-o", path("x.exr")});
    expectRefusedQuietly(r, "render", "outside its folder", "root:");
}

// An NRRD header's fields are found as teem finds them: in any case, at any line end (LF, CR LF,
// a lone CR). Each data file so named is checked by the policy before teem opens it.
TEST_F(ReaderHostile, NrrdDataFilesAreVettedInAnyCaseAndLineEnding) {
    std::string samples(64, '\0');
    for (int i = 0; i < 64; ++i) samples[std::size_t(i)] = char(i * 4);
    write("data/cube.raw", samples);
    ASSERT_EQ(::mkfifo(path("data/fifo.raw").c_str(), 0600), 0);
    const auto header = [](const std::string& field, const std::string& file, const std::string& eol) {
        return "NRRD0004" + eol + "type: uchar" + eol + "dimension: 3" + eol + "sizes: 4 4 4" + eol + "encoding: raw" + eol +
               field + ": " + file + eol;
    };
    const struct {
        std::string text;
        const char* reason;
    } cases[] = {
        {header("DATA FILE", "/etc/passwd", "\n"), "an absolute path"},
        {header("Data File", "/etc/passwd", "\r\n"), "an absolute path"},
        {header("DataFile", "/etc/passwd", "\n"), "an absolute path"},
        {header("data file", "/etc/passwd", "\r"), "an absolute path"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\rdata file: /etc/passwd\n", "an absolute path"},
        {header("DATA FILE", "../../../../../../../../etc/passwd", "\r"), "outside its folder"},
        {header("DATA FILE", "fifo.raw", "\n"), "not a regular file"},
        {header("data file", "-", "\n"), "standard input"},
        {header("Data File", "LIST", "\n") + "cube.raw\n/etc/passwd\n", "an absolute path"},
    };
    int n = 0;
    for (const auto& c : cases) {
        SCOPED_TRACE(c.text);
        const std::string name = "data/h" + std::to_string(n++) + ".nhdr";
        write(name, c.text);
        const Outcome r = run({"render", "volume", path(name), "-o", path("v.exr"), "--size", "16x16", "--backend", "cpu"});
        expectRefusedQuietly(r, "render", c.reason, "root:");
        expectMemory(r, 300);
        EXPECT_FALSE(fs::exists(path("v.exr")));
    }
    // Through the viewer too (it blocked forever on the FIFO).
    const Outcome v = runTool("conus-view", {"--volume", path("data/h6.nhdr"), "--screenshot", path("s.png"), "--size", "16x16"});
    EXPECT_EQ(v.exitCode, 1) << v.err;
    EXPECT_TRUE(contains(v.err, "not a regular file")) << v.err;
    // A data file beside the header reads whatever the line ends and the field's case.
    for (const std::string eol : {"\n", "\r\n", "\r"}) {
        write("data/ok.nhdr", header("DATA FILE", "cube.raw", eol));
        const Outcome r = run({"render", "volume", path("data/ok.nhdr"), "-o", path("ok.exr"), "--size", "16x16", "--backend", "cpu"});
        EXPECT_EQ(r.exitCode, 0) << r.err;
    }
    const std::string shared = round4("volume/model/nhdr_upper_passwd.nhdr");
    CONUS_REQUIRE(shared);
    const Outcome r = run({"render", "volume", shared, "-o", path("v.exr"), "--size", "32x32"});
    expectRefusedQuietly(r, "render", "an absolute path", "root:");
}

// ---- elevation models ----------------------------------------------------------------------------

std::string npy(const std::string& dict) {
    std::string header = dict;
    header.resize(((header.size() + 11) / 64 + 1) * 64 - 11, ' ');
    header += '\n';
    std::string out("\x93NUMPY\x01\x00", 8);
    out += char(header.size() & 0xff);
    out += char(header.size() >> 8);
    return out + header;
}

TEST_F(ReaderHostile, NpyHeadersAreParsedWithoutRecursionAndWithinLimits) {
    const std::string longShape = "(" + [] {
        std::string s;
        for (int i = 0; i < 10000; ++i) s += "1, ";
        return s;
    }() + ")";
    const struct {
        std::string dict;
        const char* reason;
    } cases[] = {
        {"{'descr': '<f4', 'fortran_order': False, 'shape': " + longShape + ", }", "shape is longer than 256 characters"},
        {"{'descr': '" + std::string(30000, '<') + "', 'fortran_order': False, 'shape': (4, 4), }", "longer than 32 characters"},
        {"{'descr': '<f4', 'fortran_order': False, 'shape': (4, 4)" + std::string(30000, ' '), "no ',' or '}'"},
        {"{'descr': '<f4', 'fortran_order': False, 'shape': ((((4, 4), }", "has a dimension"},
        {"{'descr': '<f4', 'fortran_order': True, 'shape': (4, 4), }", "Fortran-ordered"},
        {"{\"descr\": \"<f4\", \"shape\": (4, 4), 'x': " + std::string(40, 'A') + "}", "a word value is too long"},
    };
    int n = 0;
    for (const auto& c : cases) {
        SCOPED_TRACE(c.reason);
        const std::string name = "h" + std::to_string(n++) + ".npy";
        write(name, npy(c.dict) + std::string(64, '\0'));
        const Outcome r = run({"heightfield", "encode", path(name), "-o", path("t.exr"), "--size", "16x16"});
        expectRefused(r, "heightfield", c.reason);
        EXPECT_LT(r.err.size(), 600u) << "the message does not grow with the header";
        expectMemory(r, 300);
    }
    // Double quotes and no trailing comma, as other writers make them, read.
    std::string ok = npy("{\"descr\": \"<f4\", \"fortran_order\": False, \"shape\": (2, 2)}");
    const float heights[4] = {1, 2, 3, 4};
    write("ok.npy", ok + std::string(reinterpret_cast<const char*>(heights), sizeof heights));
    EXPECT_EQ(run({"heightfield", "encode", path("ok.npy"), "-o", path("ok.exr"), "--size", "16x16"}).exitCode, 0);
    const Outcome r = run({"heightfield", "encode", seed("dem", "hostile-regex_shape_30000.npy"), "-o", path("t.exr")});
    expectRefused(r, "heightfield", "is longer than");
    expectMemory(r, 300);
}

TEST_F(ReaderHostile, AnNpzMemberNobodyUsesIsNeverInflated) {
    const std::string file = round4("heightfield/junk_member.npz");
    CONUS_REQUIRE(file);
    const Outcome r = run({"heightfield", "encode", file, "-o", path("t.exr"), "--size", "64x64"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    expectMemory(r, 200);  // the 537 MB member stays compressed
}

// ---- work ----------------------------------------------------------------------------------------

// 2^17 overlapping near-copies of a triangle: each ray of a CPU render would test every copy (over
// a minute at 512x512); refused from a probe of the view before the render, by the render and the
// reflection bake alike. 64 copies render.
TEST_F(ReaderHostile, OverlappingCopiesOfATriangleAreRefusedBeforeTheRender) {
    writeNearCopies(m_dir / "near17.gltf", 1 << 17);
    writeNearCopies(m_dir / "near6.gltf", 64);
    const std::string reason = "deep along the average ray of this view";
    Outcome r = run({"render", "mesh", path("near17.gltf"), "-o", path("x.exr"), "--size", "512x512", "--backend", "cpu", "--uniform"});
    expectRefused(r, "render", reason);
    EXPECT_TRUE(contains(r.err, "limit meshOverlap")) << r.err;
    EXPECT_LT(r.seconds, 5.0 * conus::testing::kTimeScale);
    expectMemory(r, 500);
    r = run({"render", "mesh", path("near17.gltf"), "-o", path("x.exr"), "--size", "512x512", "--reference", "--uniform"});
    expectRefused(r, "render", reason);
    r = run({"bake", "reflection", path("near17.gltf"), "--size", "64", "-o", path("a.exr")});
    expectRefused(r, "bake", reason);
    expectMemory(r, 500);
    EXPECT_FALSE(fs::exists(path("x.exr")) || fs::exists(path("a.exr")));
    r = run({"render", "mesh", path("near6.gltf"), "-o", path("ok.exr"), "--size", "64x64", "--backend", "cpu", "--uniform"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    // Someone else's reader: the triangle covers part of the CoNUS image, not all of it.
    auto in = OIIO::ImageInput::open(path("ok.exr"));
    ASSERT_TRUE(in);
    const OIIO::ImageSpec spec = in->spec();
    const int alpha = spec.channelindex("A");
    ASSERT_GE(alpha, 0);
    std::vector<float> pixels(std::size_t(spec.image_pixels()) * spec.nchannels);
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
    int covered = 0;
    for (std::size_t p = 0; p < std::size_t(spec.image_pixels()); ++p) covered += pixels[p * spec.nchannels + alpha] > 0.5f;
    EXPECT_GT(covered, 0);
    EXPECT_LT(covered, spec.image_pixels());
}

}  // namespace
