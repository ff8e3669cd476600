// Batch conversion through the real binary: several inputs, --out-dir, --name, --list, --jobs,
// --skip-existing, --fail-fast, the summary line and the exit code.
#include <gtest/gtest.h>

#include <fstream>

#include "cli_fixture.h"

namespace conus::test {
namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

class Batch : public Cli {};

TEST_F(Batch, EncodesEveryInputAndSaysHowItWent) {
    const std::string a = makePicture(120, 80, "a.png"), b = makePicture(90, 60, "b.png"), c = makePicture(64, 64, "c.png");
    std::ofstream(path("broken.png")) << "not a picture";
    const Result r = run("encode " + a + " " + b + " " + path("broken.png") + " " + c + " --out-dir " + path("out") +
                         " --jobs 2 --focus 0.5,0.5,0.1,3");
    EXPECT_EQ(r.exitCode, 1) << r.err;  // one failed
    EXPECT_TRUE(contains(r.out, "3 converted, 0 skipped (output exists), 1 failed in ")) << r.out;
    EXPECT_TRUE(contains(r.out, "  failed: " + path("broken.png") + ": ")) << r.out;
    EXPECT_TRUE(contains(r.err, "] failed: " + path("broken.png") + ": ")) << r.err;
    EXPECT_TRUE(contains(r.err, "/4] wrote " + path("out/")));  // a log line an item
    for (const char* name : {"a", "b", "c"}) {
        const Result v = run("validate " + path(std::string("out/") + name + ".exr"));
        EXPECT_EQ(v.exitCode, 0) << name << ": " << v.out << v.err;
    }
    const Result info = run("info " + path("out/b.exr") + " --json");
    EXPECT_TRUE(contains(info.out, "\"width\": 90")) << info.out;  // each input's own source
    EXPECT_FALSE(fs::exists(path("out/broken.exr")));
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(Batch, SkipsExistingOutputsAndReadsAList) {
    const std::string a = makePicture(80, 60, "a.png"), b = makePicture(80, 60, "b.png");
    ASSERT_EQ(run("encode " + a + " -o " + path("a.exr")).exitCode, 0);
    const auto before = fs::last_write_time(path("a.exr"));
    std::ofstream(path("list.txt")) << "# pictures\n" << a << "\n\n" << b << "\n";
    Result r = run("encode --list " + path("list.txt") + " --out-dir " + m_dir.string() + " --skip-existing");
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "1 converted, 1 skipped (output exists), 0 failed")) << r.out;
    EXPECT_EQ(fs::last_write_time(path("a.exr")), before);
    EXPECT_TRUE(fs::exists(path("b.exr")));
    // Decode them all, named by a pattern.
    r = run("decode " + path("a.exr") + " " + path("b.exr") + " --out-dir " + path("views") + " --name '{stem}-{index}.jpg' --size 40x30");
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "2 converted")) << r.out;
    EXPECT_EQ(imageSize(path("views/a-1.jpg")), std::make_pair(40, 30));
    EXPECT_EQ(imageSize(path("views/b-2.jpg")), std::make_pair(40, 30));
}

TEST_F(Batch, FailFastStopsAtTheFirstFailure) {
    std::ofstream(path("bad.png")) << "broken";
    const std::string good = makePicture(64, 48, "good.png");
    const Result r = run("encode " + path("bad.png") + " " + good + " --out-dir " + path("out") + " --fail-fast");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_TRUE(contains(r.out, "0 converted, 0 skipped (output exists), 1 failed, 1 not tried (--fail-fast)")) << r.out;
    EXPECT_FALSE(fs::exists(path("out/good.exr")));
}

TEST_F(Batch, MistakesAreUsageErrors) {
    const std::string a = makePicture(32, 32, "a.png"), b = makePicture(32, 32, "b.png");
    Result r = run("encode " + a + " " + b + " -o " + path("x.exr"));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_TRUE(contains(r.err, "-o names the output of one input; for 2 inputs give --out-dir")) << r.err;
    r = run("encode " + a + " " + b + " --out-dir " + path("o") + " --name same.exr");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_TRUE(contains(r.err, "gives every input the same output")) << r.err;
    fs::create_directories(m_dir / "sub");
    fs::copy_file(a, m_dir / "sub" / "a.png");
    r = run("encode " + a + " " + path("sub/a.png") + " --out-dir " + path("o"));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_TRUE(contains(r.err, "would both write")) << r.err;
    r = run("encode " + a);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_TRUE(contains(r.err, "-o,--output is required")) << r.err;
    EXPECT_FALSE(fs::exists(path("o")));
}

TEST_F(Batch, QuietSaysEachFailureOnceAndABatchThatWroteNothingLeavesNoFolder) {
    std::ofstream(path("bad.png")) << "broken";
    const std::string good = makePicture(48, 32, "good.png");
    Result r = run("encode " + path("bad.png") + " " + good + " --out-dir " + path("out") + " -q");
    EXPECT_EQ(r.exitCode, 1);
    const std::string both = r.out + r.err;
    std::size_t said = 0;
    for (std::size_t at = both.find("bad.png:"); at != std::string::npos; at = both.find("bad.png:", at + 1)) ++said;
    EXPECT_EQ(said, 1u) << "once, in the summary:\n" << r.out << "---\n" << r.err;
    EXPECT_TRUE(contains(r.out, "1 converted, 0 skipped (output exists), 1 failed")) << r.out;
    EXPECT_TRUE(fs::exists(path("out/good.exr")));
    // Every input failed: the folder the batch made is gone again.
    r = run("encode " + path("bad.png") + " " + path("missing.png") + " --out-dir " + path("none") + " -q");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_FALSE(fs::exists(path("none")));
}

}  // namespace
}  // namespace conus::test
