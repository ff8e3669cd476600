// Writes that never lie or destroy, and inputs that cannot run forever: through the real binary.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include <OpenImageIO/imageio.h>

#include "cli_fixture.h"

using namespace conus::test;

TEST_F(Cli, EncodeAndUniformRefuseToOverwriteTheirInput) {
    ASSERT_EQ(run("uniform " + makePicture(64, 48) + " -o " + path("s.exr")).exitCode, 0);
    const std::string before = slurp(path("s.exr"));
    for (const char* command : {"encode", "uniform"}) {
        const Result r = run(std::string(command) + " " + path("s.exr") + " -o " + path("./s.exr"));
        EXPECT_EQ(r.exitCode, 2) << command;
        EXPECT_NE(r.err.find("refusing to write " + path("./s.exr") + ": it is the input " + path("s.exr")), std::string::npos) << r.err;
        EXPECT_EQ(slurp(path("s.exr")), before) << command;
    }
}

TEST_F(Cli, DevicesAndFifosAreNeitherOutputsNorInputs) {
    ASSERT_EQ(run("uniform " + makePicture(64, 48) + " -o " + path("s.exr")).exitCode, 0);
    // A picture name that leads to a device: refused, and the device stays a device.
    fs::create_symlink("/dev/null", path("null.png"));
    Result r = run("decode " + path("s.exr") + " -o " + path("null.png"));
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << r.err;
    ASSERT_EQ(::mkfifo(path("pipe.exr").c_str(), 0600), 0);
    r = run("encode " + path("s.exr") + " -o " + path("pipe.exr"));
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << r.err;
    struct stat st {};
    ASSERT_EQ(::stat(path("pipe.exr").c_str(), &st), 0);
    EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the FIFO is still a FIFO";
    // Inputs that would never end or would block: refused at once.
    const auto start = std::chrono::steady_clock::now();
    for (const std::string& input : {std::string("/dev/zero"), path("pipe.exr")}) {
        r = run("encode " + input + " -o " + path("z.exr"));
        EXPECT_EQ(r.exitCode, 1) << input;
        EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << r.err;
    }
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));
}

TEST_F(Cli, OutputsAreWrittenThroughSymlinks) {
    ASSERT_EQ(run("uniform " + makePicture(64, 48) + " -o " + path("s.exr")).exitCode, 0);
    { std::ofstream(path("real.png")) << "old"; }
    fs::create_symlink(path("real.png"), path("link.png"));
    ASSERT_EQ(run("decode " + path("s.exr") + " -o " + path("link.png")).exitCode, 0);
    EXPECT_TRUE(fs::is_symlink(path("link.png")));
    auto in = OIIO::ImageInput::open(path("real.png"));
    ASSERT_TRUE(in) << "the target now holds the picture";
    EXPECT_EQ(in->spec().width, 64);
}

TEST_F(Cli, AWriteCutShortByAFileSizeLimitIsAFailure) {
    ASSERT_EQ(run("uniform " + makePicture(256, 256) + " -o " + path("s.exr") + " --size 256x256").exitCode, 0);
    for (const char* ext : {"png", "exr", "tif", "jpg"}) {
        const std::string out = path(std::string("big.") + ext);
        const std::string command = "bash -c 'ulimit -f 50; " + std::string(CONUS_BIN_DIR) + "/conus decode " + path("s.exr") +
                                    " -o " + out + " --size 2048x2048 -q' 2>" + path("err.txt");
        const int status = std::system(command.c_str());
        EXPECT_EQ(WEXITSTATUS(status), 1) << ext << ": " << slurp(path("err.txt"));
        EXPECT_NE(slurp(path("err.txt")).find("cannot write " + out), std::string::npos) << slurp(path("err.txt"));
        EXPECT_EQ(slurp(path("err.txt")).find(".tmp-"), std::string::npos) << "the user's path, not the temporary";
        EXPECT_FALSE(fs::exists(out)) << ext;
    }
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(Cli, SigtermMidWriteLeavesNoTemporaryFile) {
    ASSERT_EQ(run("uniform " + makePicture(256, 256) + " -o " + path("s.exr") + " --size 256x256").exitCode, 0);
    const std::string out = path("huge.tif");
    const std::string command = std::string(CONUS_BIN_DIR) + "/conus decode " + path("s.exr") + " -o " + out +
                                " --size 6000x6000 --bits float -q & echo $! > " + path("pid.txt");
    ASSERT_EQ(std::system(command.c_str()), 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const pid_t pid = std::stoi(slurp(path("pid.txt")));
    // Wait until the temporary file exists (the write has begun), then stop the process.
    bool writing = false;
    for (int i = 0; i < 12000 && !writing; ++i) {  // up to two minutes on a loaded machine
        writing = !leftovers().empty();
        if (!writing) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ::kill(pid, SIGTERM);
    for (int i = 0; i < 200 && ::kill(pid, 0) == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_TRUE(writing) << "the write never started";
    EXPECT_TRUE(leftovers().empty());
    EXPECT_FALSE(fs::exists(out));
}

TEST_F(Cli, FloatFilesDecodeToFloatExr) {
    // 1e5 would be infinity as half.
    const std::string in = path("bright.exr");
    {
        auto out = OIIO::ImageOutput::create(in);
        ASSERT_TRUE(out->open(in, OIIO::ImageSpec(8, 8, 3, OIIO::TypeDesc::FLOAT)));
        std::vector<float> px(8 * 8 * 3, 1e5f);
        out->write_image(OIIO::TypeDesc::FLOAT, px.data());
        out->close();
    }
    ASSERT_EQ(run("uniform " + in + " -o " + path("f.exr") + " --size 8x8 --float").exitCode, 0);
    ASSERT_EQ(run("decode " + path("f.exr") + " -o " + path("d.exr")).exitCode, 0);
    auto back = OIIO::ImageInput::open(path("d.exr"));
    ASSERT_TRUE(back);
    EXPECT_EQ(back->spec().format, OIIO::TypeDesc::FLOAT);
    std::vector<float> px(8 * 8 * 3);
    back->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data());
    EXPECT_FLOAT_EQ(px[0], 1e5f);
}
