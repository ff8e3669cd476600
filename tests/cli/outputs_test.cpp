// What a command writes, through the real binary: never a file it did not make (look-alike
// temporaries, links planted where it writes), never one of its inputs (by any path), never one
// file twice; and --tablet-size checked as it is read.
#include <gtest/gtest.h>

#include <unistd.h>

#include <map>
#include <string>
#include <vector>

#include "cli_fixture.h"

using namespace conus::test;

namespace {

// Every regular file under `folder` (recursively, links not followed) and its bytes.
std::map<std::string, std::string> snapshot(const fs::path& folder) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(folder))
        if (e.is_regular_file() && !e.is_symlink()) files[fs::relative(e.path(), folder).string()] = slurp(e.path());
    return files;
}

// The entries a user made that look like CoNUS temporaries, old naming and new, a folder among them.
void plantLookAlikes(const fs::path& folder) {
    fs::create_directories(folder / ".photos.tmp-999999-1");
    std::ofstream(folder / ".photos.tmp-999999-1" / "keep.txt") << "keep";
    std::ofstream(folder / ".notes.tmp-424242-7.txt") << "notes";
    std::ofstream(folder / ".x.tmp-1-0.exr") << "an old temporary's name, pid 1 (always running)";
    std::ofstream(folder / ".x.tmp-999997-0.exr") << "an old temporary's name, a pid that is not running";
    std::ofstream(folder / ".x.tmp-abcdefghijkl.exr") << "a new temporary's name";
}

}  // namespace

TEST_F(Cli, LookAlikeTemporariesSurviveEveryCommandThatWrites) {
    const std::string picture = makePicture(64, 48, "p.png");
    ASSERT_EQ(run("uniform " + picture + " -o " + path("s.exr") + " --size 16x12").exitCode, 0);
    plantLookAlikes(m_dir);
    fs::create_directories(m_dir / "batch");
    plantLookAlikes(m_dir / "batch");
    const auto before = snapshot(m_dir);
    const std::vector<std::string> commands = {
        "encode " + picture + " -o " + path("x.exr") + " --size 16x12 --fast",
        "uniform " + picture + " -o " + path("x.exr") + " --size 16x12",
        "decode " + path("s.exr") + " -o " + path("x.png"),
        "map foci --focus 0.5,0.5,0.1,3 -o " + path("m.exr") + " --preview " + path("m.png"),
        "bake relief tablet -o " + path("t.exr") + " --tablet-size 128x96 --size 32x24 --uniform",
        "encode " + picture + " " + makePicture(32, 24, "q.png") + " --out-dir " + path("batch") + " --size 16x12 --fast",
        "decode " + path("s.exr") + " " + path("x.exr") + " --out-dir " + path("batch") + " --name {stem}.png",
    };
    for (const std::string& command : commands) {
        const Result r = run(command);
        EXPECT_EQ(r.exitCode, 0) << command << ": " << r.err;
        const auto after = snapshot(m_dir);
        for (const auto& [name, bytes] : before) {
            const auto found = after.find(name);
            EXPECT_TRUE(found != after.end()) << command << " removed " << name;
            if (found != after.end() && name != "stdout.txt" && name != "stderr.txt")
                EXPECT_EQ(found->second, bytes) << command << " changed " << name;
        }
    }
    EXPECT_TRUE(fs::is_directory(m_dir / ".photos.tmp-999999-1"));
    EXPECT_TRUE(fs::is_directory(m_dir / "batch" / ".photos.tmp-999999-1"));
}

TEST_F(Cli, LinksPlantedWhereStandardInputWasCopiedAreNotFollowed) {
    ASSERT_EQ(run("uniform " + makePicture(64, 48) + " -o " + path("s.exr") + " --size 16x12").exitCode, 0);
    { std::ofstream(path("victim.txt")) << "precious"; }
    // `exec` keeps the shell's process id: the links wait at the names the process would have used
    // before (/tmp/conus-stdin-<pid>.exr, and its temporary beside the output).
    const std::string stdinLink = (fs::temp_directory_path() / "conus-stdin-$$.exr").string();
    const std::string script = "ln -s " + path("victim.txt") + " " + stdinLink + " && ln -s " + path("victim.txt") + " " +
                               path(".x.tmp-$$-0.exr") + " && echo $$ > " + path("pid.txt") + " && exec " +
                               std::string(CONUS_BIN_DIR) + "/conus encode - -o " + path("x.exr") + " --size 16x12 --fast < " +
                               path("s.exr") + " 2> " + path("err.txt");
    const int status = std::system(("bash -c '" + script + "'").c_str());
    const std::string planted = (fs::temp_directory_path() / ("conus-stdin-" + slurp(path("pid.txt")).substr(0, slurp(path("pid.txt")).size() - 1) + ".exr")).string();
    EXPECT_TRUE(fs::is_symlink(planted)) << "the link at the old standard-input name is left alone";
    std::error_code ec;
    fs::remove(planted, ec);
    EXPECT_EQ(WEXITSTATUS(status), 0) << slurp(path("err.txt"));
    EXPECT_EQ(slurp(path("victim.txt")), "precious");
    EXPECT_EQ(readExr(path("x.exr")).width, 16) << "the output was written all the same";
}

TEST_F(Cli, AnOutputThatIsAnInputIsRefusedByAnyPathAndTheInputIsUnchanged) {
    const std::string picture = makePicture(64, 48, "p.png");
    ASSERT_EQ(run("uniform " + picture + " -o " + path("a.exr") + " --size 16x12").exitCode, 0);
    ASSERT_EQ(run("bake relief tablet -o " + path("t.exr") + " --tablet-size 128x96 --size 32x24 --uniform").exitCode, 0);
    fs::create_symlink(path("a.exr"), path("soft.exr"));
    fs::create_hard_link(path("a.exr"), path("hard.exr"));
    fs::create_directories(m_dir / "in");
    fs::copy_file(path("a.exr"), path("in/b.exr"));
    fs::copy_file(picture, path("in/conus.png"));
    { std::ofstream(path("in/frame_0000.png"), std::ios::binary) << std::string(512, '\x40'); }  // 8x8x8 voxels
    fs::create_directories(m_dir / "sub");
    fs::create_symlink("../a.exr", path("sub/up.exr"));  // a relative link
    const std::string a = path("a.exr");
    const std::vector<std::string> commands = {
        "map compose " + a + " -o " + a,
        "map compose " + a + " -o " + path("soft.exr"),
        "map compose " + a + " -o " + path("hard.exr"),
        "map compose " + a + " -o " + path("sub/up.exr"),
        "encode " + picture + " --map " + a + " -o " + a,
        "encode " + picture + " --map " + path("hard.exr") + " -o " + path("soft.exr"),
        "encode " + a + " -o " + path("./a.exr"),
        "uniform " + a + " -o " + path("hard.exr"),
        "heightfield encode " + a + " -o " + a,
        "info " + a + " --density " + a,
        "info " + a + " --density " + path("soft.exr"),
        "decode " + a + " -o " + path("hard.exr"),
        "decode " + a + " -o " + path("sub/up.exr"),
        "render relief " + path("t.exr") + " -o " + path("t.exr"),
        "bake relief " + picture + " -o " + picture,
        "render volume procedural:shepp-logan:16 -o " + a + " --map " + a + " --size 16x16",
        // A batch whose --out-dir is the inputs' own folder.
        "encode " + path("in/b.exr") + " " + picture + " --out-dir " + path("in") + " --name {name} --size 16x12",
        "decode " + path("in/b.exr") + " --out-dir " + path("in") + " --name {name}",
        // A folder of outputs with fixed names, one of which is the input.
        "demo --input " + path("in/conus.png") + " --out " + path("in"),
        // The raw volume's path lies inside its specification; its frames are written beside it.
        "volume animate raw:8x8x8:uint8:" + path("in/frame_0000.png") + " --out-dir " + path("in") + " --frames 1 --size 16x16 -q",
    };
    const auto before = snapshot(m_dir);
    for (const std::string& command : commands) {
        const Result r = run(command);
        EXPECT_NE(r.exitCode, 0) << command;
        EXPECT_NE(r.err.find("refusing to write "), std::string::npos) << command << ": " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
        auto after = snapshot(m_dir);
        after.erase("stdout.txt"), after.erase("stderr.txt");
        auto expected = before;
        expected.erase("stdout.txt"), expected.erase("stderr.txt");
        EXPECT_EQ(after, expected) << command << ": every file as it was, nothing new";
    }
    EXPECT_TRUE(fs::is_symlink(path("soft.exr")));
}

TEST_F(Cli, TheViewersScreenshotNeverReplacesAFileItShows) {
    ASSERT_NO_FATAL_FAILURE(makeUniformFile());
    fs::create_symlink(path("u.exr"), path("alias.exr"));
    const std::string before = slurp(path("u.exr"));
    for (const std::string& shown : {path("u.exr"), path("alias.exr")}) {
        const std::string command = std::string(CONUS_BIN_DIR) + "/conus-view " + shown + " --screenshot " + path("u.exr") +
                                    " 2>" + path("err.txt");
        const int status = std::system(command.c_str());
        EXPECT_EQ(WEXITSTATUS(status), 2) << shown;
        EXPECT_NE(slurp(path("err.txt")).find("refusing to write " + path("u.exr") + ": it is the input"), std::string::npos)
            << slurp(path("err.txt"));
        EXPECT_EQ(slurp(path("u.exr")), before);
    }
}

TEST_F(Cli, TwoOutputsOfOneCommandThatAreOneFileAreRefused) {
    { std::ofstream(path("m.exr")) << "old"; }
    fs::create_symlink(path("m.exr"), path("alias.exr"));
    const std::vector<std::string> commands = {
        "map foci --focus 0.5,0.5,0.1,3 -o " + path("m.exr") + " --preview " + path("m.exr"),
        "map foci --focus 0.5,0.5,0.1,3 -o " + path("new.exr") + " --preview " + path("./new.exr"),
        "map foci --focus 0.5,0.5,0.1,3 -o " + path("m.exr") + " --preview " + path("alias.exr"),
        "render volume procedural:shepp-logan:16 -o " + path("v.exr") + " --picture " + path("v.exr") + " --size 16x16",
    };
    for (const std::string& command : commands) {
        const Result r = run(command);
        EXPECT_NE(r.exitCode, 0) << command;
        EXPECT_NE(r.err.find("refusing to write "), std::string::npos) << command << ": " << r.err;
        EXPECT_EQ(slurp(path("m.exr")), "old") << command;
        EXPECT_FALSE(fs::exists(path("new.exr"))) << command;
        EXPECT_FALSE(fs::exists(path("v.exr"))) << command;
    }
}

TEST_F(Cli, TabletSizesOutsideTheLimitsAreRefusedAsTheOptionIsRead) {
    for (const char* size : {"2x2", "3x3", "7x64", "65536x1", "32768x32768", "8192x8192", "8193x64", "0x0", "axb"}) {
        const Result r = run(std::string("bake relief tablet -o ") + path("t.exr") + " --tablet-size " + size + " --size 32x24");
        EXPECT_EQ(r.exitCode, 2) << size << ": " << r.err;
        EXPECT_NE(r.err.find(size), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
        EXPECT_FALSE(fs::exists(path("t.exr"))) << size;
    }
    const Result help = run("bake relief --help");
    EXPECT_NE(help.out.find("each side 8 to 8192"), std::string::npos) << "the limits are in the help";
    // The smallest tablet, and long thin ones, are made.
    for (const char* size : {"8x8", "2048x8", "64x2048"}) {
        const Result r = run(std::string("bake relief tablet -o ") + path("t.exr") + " --tablet-size " + size + " --size 8x8 --uniform");
        EXPECT_EQ(r.exitCode, 0) << size << ": " << r.err;
        EXPECT_EQ(readExr(path("t.exr")).width, 8) << size;
    }
    // More lines than the smallest tablet can hold: those that fall outside are not drawn.
    const Result r = run("bake relief tablet -o " + path("t.exr") + " --tablet-size 64x64 --size 32x24 --uniform --text "
                         "'A LINE FAR TOO LONG FOR SIXTY-FOUR PIXELS|B|C|D|E|F|G|H|I|J|K|L|M|N|O|P|Q|R|S|T'");
    EXPECT_EQ(r.exitCode, 0) << r.err;
}
