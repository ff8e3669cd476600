// What a newcomer reads: one clear line per problem with the right exit code (0 ok, 1 failure,
// 2 usage), checks made before the work, progress that can be silenced, help with examples.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "cli_fixture.h"

using namespace conus::test;

namespace {

// Lines of `text` that contain `needle`.
int countLines(const std::string& text, const std::string& needle) {
    int n = 0;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) n += line.find(needle) != std::string::npos;
    return n;
}

}  // namespace

TEST_F(Cli, EncodeToAPictureNameIsRefusedBeforeAnyWork) {
    const std::string in = makePicture(64, 48);
    const Result r = run("encode " + in + " -o " + path("x.png") + " --focus 0.5,0.5,0.1,2");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find(".exr"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("conus decode"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("done"), std::string::npos) << "no stage ran: " << r.err;
    EXPECT_FALSE(fs::exists(path("x.png")));
}

TEST_F(Cli, EncodeWithoutAMapSaysItIsTheUniformImage) {
    const Result r = run("encode " + makePicture(64, 48) + " -o " + path("x.exr"));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("conus uniform"), std::string::npos) << r.err;
}

TEST_F(Cli, DecodeChecksItsOutputBeforeTheWork) {
    ASSERT_EQ(run("uniform " + makePicture(64, 48) + " -o " + path("u.exr")).exitCode, 0);
    for (const std::string& bad : {path("x.xyz"), path("x.png") + " --bits float", path("x.jpg") + " --bits 16",
                                   path("missing-folder/x.png")}) {
        const Result r = run("decode " + path("u.exr") + " -o " + bad + " --size 4000x4000");
        EXPECT_EQ(r.exitCode, 2) << bad << ": " << r.err;
        EXPECT_EQ(countLines(r.err, "done"), 0) << "nothing decoded first: " << r.err;
        EXPECT_EQ(countLines(r.err, "conus decode: "), 1) << r.err;
    }
}

TEST_F(Cli, ProgressIsOneLinePerStageWithATotalAndQuietSilencesIt) {
    const std::string in = makePicture(64, 48);
    Result r = run("encode " + in + " -o " + path("a.exr") + " --focus 0.5,0.5,0.1,2");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(countLines(r.err, "conus encode: read "), 1) << r.err;
    EXPECT_EQ(countLines(r.err, "build sampling map (1 focus) done"), 1) << "one focus, not '1 foci': " << r.err;
    EXPECT_EQ(countLines(r.err, "conus encode: write "), 1) << r.err;
    EXPECT_EQ(countLines(r.err, "conus encode: done in "), 1) << r.err;
    r = run("encode " + in + " -o " + path("b.exr") + " --focus 0.5,0.5,0.1,2 --quiet");
    ASSERT_EQ(r.exitCode, 0);
    EXPECT_TRUE(r.err.empty()) << r.err;
    r = run("decode " + path("b.exr") + " -o " + path("b.xyz") + " -q");
    EXPECT_EQ(countLines(r.err, "conus decode: "), 1) << "errors still print: " << r.err;
}

// On a terminal (util-linux `script` gives the run one), the budget's map build shows each
// confirming encode's percentage on the stage's live line, up to 100%, then the stage's line; the
// same run to a file or a pipe prints the stage's line alone.
TEST_F(Cli, TheMapBuildShowsItsConfirmingEncodesOnATerminal) {
    const std::string in = makePicture(192, 128);
    const fs::path typed = fs::path(path("typescript.txt"));
    const std::string command = std::string(CONUS_BIN_DIR) + "/conus encode " + in + " -o " + path("t.exr") +
                                " --size 64x48 --focus 0.3,0.4,0.15,3";
    ASSERT_EQ(std::system(("script -qec '" + command + "' " + typed.string() + " >/dev/null 2>&1 </dev/null").c_str()), 0);
    const std::string shown = slurp(typed);
    EXPECT_NE(shown.find("build sampling map (1 focus): confirming encode 1   0%"), std::string::npos) << shown;
    EXPECT_NE(shown.find("build sampling map (1 focus): confirming encode 1 100%"), std::string::npos) << shown;
    EXPECT_NE(shown.find("build sampling map (1 focus) done"), std::string::npos) << shown;
    EXPECT_EQ(shown.find("confirming encode 0"), std::string::npos) << shown;
    const Result r = run("encode " + in + " -o " + path("u.exr") + " --size 64x48 --focus 0.3,0.4,0.15,3");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.err.find("confirming encode"), std::string::npos) << r.err;
    EXPECT_EQ(countLines(r.err, "build sampling map (1 focus) done"), 1) << r.err;
}

TEST_F(Cli, InfoOnAnInvalidFileIsOneLineAndVerboseListsEveryProblem) {
    ASSERT_EQ(run("uniform " + makePicture(64, 48) + " -o " + path("u.exr")).exitCode, 0);
    // Two broken rules, made by an ordinary EXR tool.
    ASSERT_EQ(std::system(("oiiotool " + path("u.exr") + " --attrib conus:dataKind bogus --attrib:type=int conus:version -3 -o " +
                           path("bad.exr") + " >/dev/null 2>&1").c_str()), 0);
    Result r = run("info " + path("bad.exr"));
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(countLines(r.err, ""), 1) << r.err;
    EXPECT_NE(r.err.find("V2: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("; V6: "), std::string::npos) << "both problems, on one line: " << r.err;
    r = run("info --verbose " + path("bad.exr"));
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(countLines(r.out, "V2:") + countLines(r.out, "V6:"), 2) << r.out;
    EXPECT_NE(r.err.find("(2 problems)"), std::string::npos) << r.err;
    r = run("validate " + path("bad.exr"));
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(countLines(r.out, path("bad.exr") + ": V"), 2) << r.out;
    EXPECT_NE(r.err.find("(2 problems)"), std::string::npos) << "the count matches the list: " << r.err;
}

TEST_F(Cli, InfoListsChannelsInDisplayOrderAndTheColour) {
    ASSERT_EQ(run("uniform " + makePicture(64, 48) + " -o " + path("u.exr")).exitCode, 0);
    const Result r = run("info " + path("u.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("channels R,G,B,"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("linear light"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("source srgb uint8"), std::string::npos) << r.out;
}

TEST_F(Cli, SpringStrokesInlineOrFromAFile) {
    const std::string strokes = R"([{"u":0.5,"v":0.4,"radius":0.15,"strength":1,"duration":0.3}])";
    Result r = run("map springs --grid 33 --out-grid 17 --strokes '" + strokes + "' -o " + path("inline.exr"));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    { std::ofstream(path("s.json")) << strokes; }
    r = run("map springs --grid 33 --out-grid 17 --strokes " + path("s.json") + " -o " + path("file.exr"));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(slurp(path("inline.exr")).size(), slurp(path("file.exr")).size());
}

TEST_F(Cli, UsageErrorsExitWithTwoBeforeAnyWork) {
    const std::string cases[] = {
        "heightfield encode procedural:64 -o " + path("t.exr") + " --compression foo",
        "render heightfield " + path("t.exr") + " -o " + path("f.png") + " --backend cpu",
        "decode " + path("t.exr") + " -o " + path("f.png") + " --tonemap sideways",
        "encode " + path("t.png") + " -o " + path("t.exr") + " --input-colorspace cmyk",
    };
    for (const std::string& args : cases) {
        const Result r = run(args);
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
        EXPECT_EQ(countLines(r.err, ""), 1) << args << "\n" << r.err;
    }
    // cpu is not offered where there is no CPU path.
    const Result help = run("render heightfield --help");
    EXPECT_EQ(help.out.find("cpu"), std::string::npos) << help.out;
}

TEST_F(Cli, EveryCommandsHelpHasExamplesAndTheExitCodesAreDocumented) {
    for (const char* command : {"encode", "uniform", "decode", "info", "validate", "demo", "map", "map springs",
                                "heightfield encode", "render heightfield"}) {
        const Result r = run(std::string(command) + " --help");
        EXPECT_EQ(r.exitCode, 0) << command;
        EXPECT_NE(r.out.find("Examples:"), std::string::npos) << command << "\n" << r.out;
    }
    const Result r = run("--help");
    EXPECT_NE(r.out.find("Exit codes: 0 success; 1 failure"), std::string::npos) << r.out;
}

TEST_F(Cli, MultiPartInputsSayWhichPartIsUsed) {
    // Two parts: a red one named "beauty", a blue one named "shadow".
    const std::string file = path("parts.exr");
    {
        auto out = OIIO::ImageOutput::create(file);
        OIIO::ImageSpec specs[2] = {OIIO::ImageSpec(32, 16, 3, OIIO::TypeDesc::HALF), OIIO::ImageSpec(32, 16, 3, OIIO::TypeDesc::HALF)};
        specs[0].attribute("oiio:subimagename", "beauty");
        specs[1].attribute("oiio:subimagename", "shadow");
        ASSERT_TRUE(out->open(file, 2, specs));
        std::vector<float> red(32 * 16 * 3, 0.0f), blue(32 * 16 * 3, 0.0f);
        for (int p = 0; p < 32 * 16; ++p) red[p * 3] = 1.0f, blue[p * 3 + 2] = 1.0f;
        out->write_image(OIIO::TypeDesc::FLOAT, red.data());
        out->open(file, specs[1], OIIO::ImageOutput::AppendSubimage);
        out->write_image(OIIO::TypeDesc::FLOAT, blue.data());
        out->close();
    }
    Result r = run("uniform " + file + " -o " + path("a.exr") + " --size 32x16");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("has 2 parts; using part 0 (beauty)"), std::string::npos) << r.err;
    r = run("uniform " + file + " -o " + path("b.exr") + " --size 32x16 --part shadow");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    ASSERT_EQ(run("decode " + path("b.exr") + " -o " + path("b.png")).exitCode, 0);
    auto in = OIIO::ImageInput::open(path("b.png"));
    ASSERT_TRUE(in);
    std::vector<float> px(32 * 16 * 3);
    in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data());
    EXPECT_GT(px[2], 0.9f) << "the blue part";
    EXPECT_LT(px[0], 0.1f);
    r = run("uniform " + file + " -o " + path("c.exr") + " --part nosuch");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("0 (beauty), 1 (shadow)"), std::string::npos) << r.err;
}

TEST_F(Cli, AViewPastTheImageShowsTheBackgroundNotSmearedEdges) {
    ASSERT_EQ(run("uniform " + makePicture(64, 48) + " -o " + path("u.exr") + " --size 64x48").exitCode, 0);
    ASSERT_EQ(run("decode " + path("u.exr") + " -o " + path("v.exr") + " --view -0.5,0,0.5,1 --size 64x48").exitCode, 0);
    auto in = OIIO::ImageInput::open(path("v.exr"));
    ASSERT_TRUE(in);
    std::vector<float> px(64 * 48 * 3);
    in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data());
    double left = 0, right = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 32; ++x) {
            for (int c = 0; c < 3; ++c) left += px[(y * 64 + x) * 3 + c], right += px[(y * 64 + x + 32) * 3 + c];
        }
    EXPECT_EQ(left, 0.0) << "outside the image: background";
    EXPECT_GT(right, 100.0) << "inside: the picture";
}

TEST_F(Cli, StandardInputIsAnInput) {
    const std::string in = makePicture(64, 48);
    // run() gives the command /dev/null as its input; the shell pipes the picture in instead.
    const int status = std::system((std::string(CONUS_BIN_DIR) + "/conus uniform - -o " + path("s.exr") + " -q < " + in).c_str());
    EXPECT_EQ(WEXITSTATUS(status), 0);
    ASSERT_EQ(run("info " + path("s.exr")).exitCode, 0);
    EXPECT_NE(run("info " + path("s.exr")).out.find("source        64 x 48"), std::string::npos);
}

// A name too long for the folder: it passes every check made before the work (the folder is
// there) and fails only when the file is created, after the command's other outputs were written.
std::string unwritableName(const std::string& extension) { return std::string(250, 'n') + extension; }

TEST_F(Cli, ACommandThatFailsLeavesNoneOfItsOutputs) {
    // A preview into a folder that is not there: refused before the work.
    Result r = run("map foci --focus 0.5,0.5,0.1,4 -o " + path("m.exr") + " --preview " + path("nodir/p.png"));
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_EQ(countLines(r.err, ""), 1) << r.err;
    EXPECT_NE(r.err.find("nodir"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("m.exr")));
    // A preview that fails once the map is written: the map goes too.
    r = run("map foci --focus 0.5,0.5,0.1,4 -o " + path("m.exr") + " --preview " + path(unwritableName(".png")) + " -q");
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_EQ(countLines(r.err, ""), 1) << r.err;
    EXPECT_FALSE(fs::exists(path("m.exr")));
    EXPECT_EQ(r.out.find("wrote"), std::string::npos) << "nothing said written: " << r.out;
    // A volume's picture, likewise.
    r = run("render volume procedural:shepp-logan:16 -o " + path("v.exr") + " --size 16x16 --uniform --picture " +
            path(unwritableName(".png")));
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_FALSE(fs::exists(path("v.exr")));
    // The demo: one of its pictures cannot be written (a folder has its name); none of them is
    // left, and the folder the demo made is gone.
    const std::string in = makePicture(64, 48);
    fs::create_directories(m_dir / "demo" / "view-frame.png");
    r = run("demo --input " + in + " --focus 0.5,0.5,0.1,2 --out " + path("demo") + " -q");
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("view-frame.png is a directory"), std::string::npos) << r.err;
    EXPECT_EQ(fs::directory_iterator(m_dir / "demo")->path().filename(), "view-frame.png");
    EXPECT_EQ(std::distance(fs::directory_iterator(m_dir / "demo"), fs::directory_iterator()), 1) << "only what was there";
    fs::remove(m_dir / "demo" / "view-frame.png");
    r = run("demo --input " + path("missing.png") + " --out " + path("demo/new"));
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_FALSE(fs::exists(path("demo/new")));
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(Cli, AViewWhollyOutsideThePictureIsRefusedBeforeAnyWork) {
    ASSERT_NO_FATAL_FAILURE(makeUniformFile());
    for (const char* view : {"1.2,0,1.5,0.5", "-0.5,0.2,0,0.4", "0.2,1,0.4,1.5"}) {
        const Result r = run("decode " + path("u.exr") + " -o " + path("x.png") + " --view " + view);
        EXPECT_EQ(r.exitCode, 2) << view << ": " << r.err;
        EXPECT_EQ(countLines(r.err, ""), 1) << r.err;
        EXPECT_NE(r.err.find("lies wholly outside the image"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("done"), std::string::npos) << "nothing read first: " << r.err;
        EXPECT_FALSE(fs::exists(path("x.png")));
    }
}

TEST_F(Cli, AMissingFileIsOnePlainLineNamingItOnce) {
    const std::string missing = path("missing.exr");
    for (const std::string& args : {"decode " + missing + " -o " + path("x.png"), "info " + missing,
                                    "map compose " + missing + " -o " + path("m.exr"), "validate " + missing}) {
        const Result r = run(args);
        EXPECT_EQ(r.exitCode, 1) << args << ": " << r.err;
        EXPECT_EQ(countLines(r.err, ""), 1) << args << ": " << r.err;
        EXPECT_EQ(countLines(r.err, "missing.exr"), 1) << args << ": " << r.err;
        EXPECT_NE(r.err.find("no such file"), std::string::npos) << args << ": " << r.err;
        EXPECT_EQ(r.err.find("missing.exr: missing.exr"), std::string::npos) << args << ": " << r.err;
        EXPECT_EQ(r.err.find("V1"), std::string::npos) << "no rule number for a file that is not there: " << r.err;
    }
    // The viewer says it before any window opens (no display needed), once.
    for (const std::string& args : {missing, missing + " --screenshot " + path("s.png"), "--edit " + path("missing.png")}) {
        const std::string command = std::string(CONUS_BIN_DIR) + "/conus-view " + args + " 2>" + path("view.txt") + " </dev/null";
        const int status = std::system(command.c_str());
        const std::string err = slurp(path("view.txt"));
        EXPECT_EQ(WEXITSTATUS(status), 1) << args << ": " << err;
        EXPECT_EQ(countLines(err, ""), 1) << args << ": " << err;
        EXPECT_EQ(err.find(".exr: " + missing), std::string::npos) << err;
        EXPECT_NE(err.find("no such file"), std::string::npos) << args << ": " << err;
    }
}

TEST_F(Cli, ASizeIsCheckedBeforeThePictureIsRead) {
    const std::string in = makePicture(64, 48);
    for (const std::string& command : {"uniform", "encode"}) {
        const Result r = run(command + " " + in + " -o " + path("u.exr") + " --size 0x0");
        EXPECT_EQ(r.exitCode, 2) << command << ": " << r.err;
        EXPECT_EQ(countLines(r.err, ""), 1) << command << ": " << r.err;
        EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("read "), std::string::npos) << "nothing read first: " << r.err;
    }
}

TEST_F(Cli, AMisspeltOptionIsNamedWithTheOneMeant) {
    const std::string in = makePicture(64, 48);
    Result r = run("encode " + in + " -o " + path("x.exr") + " --foccus 0.5,0.5,0.1,4");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(countLines(r.err, ""), 1) << r.err;
    EXPECT_NE(r.err.find("conus encode: unknown option --foccus; did you mean --focus?"), std::string::npos) << r.err;
    r = run("decode " + path("x.exr") + " -o " + path("x.png") + " --veiw=0,0,1,1");
    EXPECT_NE(r.err.find("unknown option --veiw; did you mean --view?"), std::string::npos) << r.err;
    r = run("map foci --focus 0.5,0.5,0.1,4 -o " + path("m.exr") + " --prevew " + path("m.png"));
    EXPECT_NE(r.err.find("unknown option --prevew; did you mean --preview?"), std::string::npos) << r.err;
    r = run("info " + path("x.exr") + " --nothing-like-it");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("unknown option --nothing-like-it (see --help)"), std::string::npos) << r.err;
    const std::string command = std::string(CONUS_BIN_DIR) + "/conus-view x.exr --screenshoot s.png 2>" + path("view.txt");
    EXPECT_EQ(WEXITSTATUS(std::system(command.c_str())), 2);
    EXPECT_NE(slurp(path("view.txt")).find("did you mean --screenshot?"), std::string::npos) << slurp(path("view.txt"));
    EXPECT_FALSE(fs::exists(path("x.exr")) || fs::exists(path("m.exr")));
}

// One word order for render: `conus render mesh|volume|heightfield`. The old order still runs the
// same command and says the new spelling on stderr; the new order says nothing of it.
TEST_F(Cli, TheOldRenderWordOrderIsAnAliasThatSaysTheNewOne) {
    const std::string common = " --size 24x16 --uniform --backend cpu -q";
    const Result old = run("volume render procedural:shepp-logan:16 -o " + path("old.exr") + common);
    ASSERT_EQ(old.exitCode, 0) << old.err;
    EXPECT_EQ(old.err, "conus: `conus volume render` is spelled `conus render volume` now\n");
    const Result now = run("render volume procedural:shepp-logan:16 -o " + path("new.exr") + common);
    ASSERT_EQ(now.exitCode, 0) << now.err;
    EXPECT_EQ(now.err, "");
    // The same command: the same pixels, read back with OpenImageIO.
    std::vector<float> a, b;
    for (const auto& [file, pixels] : {std::pair{path("old.exr"), &a}, std::pair{path("new.exr"), &b}}) {
        auto in = OIIO::ImageInput::open(file);
        ASSERT_TRUE(in) << file;
        const OIIO::ImageSpec& spec = in->spec();
        EXPECT_EQ(spec.width, 24);
        pixels->resize(std::size_t(spec.width) * spec.height * spec.nchannels);
        ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels->data()));
    }
    EXPECT_EQ(a, b);
    // Errors and help under the old order are the new command's; the groups' help names the new order.
    const Result bad = run("mesh render " + path("missing.obj") + " -o " + path("x.exr"));
    EXPECT_NE(bad.exitCode, 0);
    EXPECT_NE(bad.err.find("spelled `conus render mesh` now\nconus render: "), std::string::npos) << bad.err;
    const Result help = run("heightfield render --help");
    EXPECT_EQ(help.exitCode, 0) << help.err;
    EXPECT_NE(help.out.find("render heightfield"), std::string::npos) << help.out;
    EXPECT_NE(run("mesh --help").out.find("`conus render mesh`"), std::string::npos);
    EXPECT_NE(run("render --help").out.find("heightfield"), std::string::npos);
}
