// Files a model names on its own behalf (a glTF's buffer, an OBJ's material library and texture,
// an NRRD's data file, a raw volume's path inside its specification), through the real tools:
// never replaced by an output of the same run, whatever the output's path; and variants of the
// named-file policy the other suites do not write (tabs, several names on one line, backslashes,
// texture options, links to outside the folder). A file outside the model's folder is a FIFO
// here: opening it would block the tool until the 60 s timeout, so a refusal in seconds shows it
// was never opened; a secret's text never shows in a message.
#include <sys/stat.h>

#include <cstring>

#include "hostile_fixture.h"

namespace {

using namespace conus::hostile;

// One triangle as a glTF whose buffer is the file `buffer` beside it.
void writeTriangleGltf(const fs::path& gltf, const std::string& buffer) {
    const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::ofstream(gltf.parent_path() / buffer, std::ios::binary).write(reinterpret_cast<const char*>(xyz), sizeof xyz);
    std::ofstream(gltf) << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "buffers": [{"uri": ")"
                        << buffer << R"(", "byteLength": 36}], "bufferViews": [{"buffer": 0, "byteLength": 36}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]})";
}

class NamedHostile : public Hostile {
protected:
    // `output` was refused as an input of the run, in one line, and its bytes are as they were.
    void expectInputKept(const Outcome& r, const std::string& output, const std::string& bytes) {
        EXPECT_NE(r.exitCode, 0) << r.err;
        EXPECT_TRUE(contains(r.err, "refusing to write ") && contains(r.err, ": it is the input")) << r.err;
        EXPECT_EQ(errorLines(r.err).size(), 1u) << r.err;
        EXPECT_EQ(slurp(path(output)), bytes) << output << " was replaced";
    }
};

TEST_F(NamedHostile, AFileAModelNamesIsAnInputNoOutputReplaces) {
    fs::create_directories(m_dir / "m");
    writeTriangleGltf(m_dir / "m" / "tri.gltf", "b.exr");
    writeTriangleGltf(m_dir / "m" / "pic.gltf", "b.png");
    const std::string exrBuffer = slurp(path("m/b.exr")), pngBuffer = slurp(path("m/b.png"));
    // The buffer is named by the glTF only, never on the command line: refused when the write comes.
    expectInputKept(run({"render", "mesh", path("m/tri.gltf"), "-o", path("m/b.exr"), "--size", "16x16", "--backend", "cpu", "--uniform"}),
                    "m/b.exr", exrBuffer);
    fs::create_symlink("m/b.exr", m_dir / "alias.exr");
    expectInputKept(run({"render", "mesh", path("m/tri.gltf"), "-o", path("alias.exr"), "--size", "16x16", "--backend", "cpu", "--uniform"}),
                    "m/b.exr", exrBuffer);
    expectInputKept(run({"bake", "reflection", path("m/tri.gltf"), "--size", "8", "-o", path("m/b.exr")}), "m/b.exr", exrBuffer);
    expectInputKept(runTool("conus-view", {"--mesh", path("m/pic.gltf"), "--screenshot", path("m/b.png"), "--size", "16x16"}),
                    "m/b.png", pngBuffer);
    // Another output renders: the model reads.
    ASSERT_EQ(run({"render", "mesh", path("m/tri.gltf"), "-o", path("ok.exr"), "--size", "16x16", "--backend", "cpu", "--uniform"}).exitCode, 0);

    // An OBJ's material library and texture.
    write("o/t.mtl", "newmtl t\nKd 1 1 1\nmap_Kd tex.png\n");
    fs::copy_file(path("m/b.png"), path("o/tex.png"));  // not a PNG: the texture is dropped with a warning, still read
    write("o/tri.obj", "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3\n");
    const std::string mtl = slurp(path("o/t.mtl"));
    const Outcome obj = run({"render", "mesh", path("o/tri.obj"), "-o", path("o/t.mtl"), "--size", "16x16", "--backend", "cpu", "--uniform"});
    EXPECT_NE(obj.exitCode, 0);
    EXPECT_EQ(slurp(path("o/t.mtl")), mtl);

    // A raw volume's path is inside its specification: refused before any work, as a named input.
    std::string voxels(512, '\0');
    for (std::size_t i = 0; i < voxels.size(); ++i) voxels[i] = char(i * 7);
    write("v.exr", voxels);
    Outcome r = run({"render", "volume", "raw:8x8x8:uint8:" + path("v.exr"), "-o", path("v.exr"), "--size", "16x16", "--backend", "cpu", "--uniform"});
    expectInputKept(r, "v.exr", voxels);
    EXPECT_EQ(r.exitCode, 2) << "a usage error, found from the command line";
    // An NRRD header's data file.
    write("n/d.exr", voxels);
    write("n/h.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 8 8 8\nencoding: raw\ndata file: d.exr\n");
    expectInputKept(run({"render", "volume", path("n/h.nhdr"), "-o", path("n/d.exr"), "--size", "16x16", "--backend", "cpu", "--uniform"}),
                    "n/d.exr", voxels);
    write("v.png", voxels);
    r = runTool("conus-view", {"--volume", "raw:8x8x8:uint8:" + path("v.png"), "--screenshot", path("v.png"), "--size", "16x16"});
    expectInputKept(r, "v.png", voxels);
    ASSERT_EQ(run({"render", "volume", path("n/h.nhdr"), "-o", path("n/out.exr"), "--size", "16x16", "--backend", "cpu"}).exitCode, 0);
}

// Names outside the model's folder in the forms the policy's other tests do not write: each is
// refused in one line, in seconds (the outside file is a FIFO: an open would block), and the
// secret beside it never shows.
TEST_F(NamedHostile, NamesOutsideTheFolderInOtherSpellingsAreNeverOpened) {
    fs::create_directories(m_dir / "secret");
    ASSERT_EQ(::mkfifo(path("secret/fifo").c_str(), 0600), 0);
    write("secret/.env", "API_TOKEN=hunter2-not-for-you\n");
    fs::create_directories(m_dir / "model");
    fs::create_symlink(m_dir / "secret" / "fifo", m_dir / "model" / "link.mtl");
    fs::create_symlink(m_dir / "secret" / ".env", m_dir / "model" / "env.mtl");
    fs::create_symlink(m_dir / "secret" / "fifo", m_dir / "model" / "link.png");
    const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3\n";
    const std::vector<std::pair<std::string, std::string>> objs = {
        {"tab.obj", "mtllib\t../secret/fifo\n"},
        {"two.obj", "mtllib ok.mtl ../secret/fifo\n"},
        {"backslash.obj", "mtllib ..\\secret\\fifo\n"},
        {"link.obj", "mtllib link.mtl\n"},
        {"env.obj", "mtllib env.mtl\n"},
        {"crlf.obj", "mtllib ../secret/.env\r\n"},
        {"texopt.obj", "mtllib texopt.mtl\n"},
        {"texlink.obj", "mtllib texlink.mtl\n"},
        {"texabs.obj", "mtllib texabs.mtl\n"},
    };
    write("model/ok.mtl", "newmtl t\nKd 1 0.5 0.25\n");
    write("model/texopt.mtl", "newmtl t\nKd 1 1 1\nmap_Kd -s 1 1 1 -bm 0.5 ../secret/fifo\n");
    write("model/texlink.mtl", "newmtl t\nKd 1 1 1\nmap_Kd link.png\n");
    write("model/texabs.mtl", "newmtl t\nKd 1 1 1\nmap_Kd " + path("secret/fifo") + "\n");
    for (const auto& [name, head] : objs) {
        SCOPED_TRACE(name);
        write("model/" + name, head + triangle);
        const Outcome r = run({"render", "mesh", path("model/" + name), "-o", path("x.exr"), "--size", "16x16", "--backend", "cpu"});
        EXPECT_LT(r.seconds, 10.0 * conus::testing::kTimeScale) << "the FIFO was opened";
        EXPECT_NE(r.exitCode, 124) << "the FIFO was opened";
        EXPECT_FALSE(contains(r.err + r.out, "hunter2")) << r.err;
        EXPECT_LE(errorLines(r.err).size(), 2u) << r.err;  // a refusal, or a dropped texture's warning
        if (r.exitCode == 0) {
            EXPECT_TRUE(fs::exists(path("x.exr")));
        } else {
            EXPECT_EQ(r.exitCode, 1) << r.err;
            EXPECT_TRUE(contains(r.err, "outside its folder") || contains(r.err, "absolute path") ||
                        contains(r.err, "not a regular file") || contains(r.err, "cannot be opened"))
                << r.err;
        }
        fs::remove(path("x.exr"));
    }
    // NRRD data files: a tab after the colon, no space, a link in the folder to the FIFO outside.
    fs::create_symlink(m_dir / "secret" / "fifo", m_dir / "model" / "fifo.raw");
    const auto header = [](const std::string& field) {
        return "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n" + field + "\n";
    };
    for (const std::string& field : {std::string("data file:\t../secret/fifo"), std::string("data file:../secret/fifo"),
                                     std::string("DATA FILE: fifo.raw"), std::string("datafile: \t ../secret/fifo \t"),
                                     std::string("Data File: LIST\n../secret/fifo"), std::string("data file: ../secret/fifo\r")}) {
        SCOPED_TRACE(field);
        write("model/h.nhdr", header(field));
        const Outcome r = run({"render", "volume", path("model/h.nhdr"), "-o", path("v.exr"), "--size", "16x16", "--backend", "cpu"});
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_LT(r.seconds, 10.0 * conus::testing::kTimeScale) << "the FIFO was opened";
        EXPECT_EQ(errorLines(r.err).size(), 1u) << r.err;
        EXPECT_FALSE(fs::exists(path("v.exr")));
    }
}

}  // namespace
