// The fixture of the CLI suites: the real `conus` binary run in a folder of its own per test, with
// pictures written by OpenImageIO and a check that no temporary file is left behind.
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "test_dir.h"

namespace conus::test {
namespace fs = std::filesystem;

struct Result {
    int exitCode = -1;
    std::string out, err;
};

// A picture's width and height as OpenImageIO reads them; (0, 0) when it cannot.
inline std::pair<int, int> imageSize(const std::string& path) {
    auto input = OIIO::ImageInput::open(path);
    if (!input) return {0, 0};
    return {input->spec().width, input->spec().height};
}

// An EXR's first part as OpenImageIO reads it: channels by name, and its string attributes.
struct ExrRead {
    int width = 0, height = 0;
    std::map<std::string, std::vector<float>> channels;  // name -> width * height values
    OIIO::ImageSpec spec;
};

inline ExrRead readExr(const std::string& path) {
    ExrRead r;
    auto input = OIIO::ImageInput::open(path);
    if (!input) return r;
    r.spec = input->spec();
    r.width = r.spec.width;
    r.height = r.spec.height;
    std::vector<float> all(static_cast<std::size_t>(r.width) * r.height * r.spec.nchannels);
    if (!input->read_image(0, 0, 0, r.spec.nchannels, OIIO::TypeDesc::FLOAT, all.data())) return r;
    for (int c = 0; c < r.spec.nchannels; ++c) {
        auto& values = r.channels[r.spec.channelnames[c]];
        for (std::size_t p = 0; p < static_cast<std::size_t>(r.width) * r.height; ++p)
            values.push_back(all[p * r.spec.nchannels + c]);
    }
    return r;
}

// A camera-depth image as `conus render mesh` and `conus render volume` write it: width x height,
// the channels R, G, B, A (coverage) and Z, the data kind and depth kind. Wrap the call in
// ASSERT_NO_FATAL_FAILURE: a wrong size or a missing channel stops the test.
inline void expectCameraDepthImage(const ExrRead& exr, int width, int height) {
    ASSERT_EQ(exr.width, width);
    ASSERT_EQ(exr.height, height);
    for (const char* c : {"R", "G", "B", "A", "Z"}) ASSERT_TRUE(exr.channels.count(c)) << c;
    EXPECT_EQ(exr.spec.get_string_attribute("conus:dataKind"), "depthimage");
    EXPECT_EQ(exr.spec.get_string_attribute("conus:depthKind"), "cameraDepth");
}

// PSNR of R, G, B, A between two renders of one size (peak 1).
inline double psnrRgb(const ExrRead& a, const ExrRead& b) {
    double se = 0;
    std::size_t n = 0;
    for (const char* c : {"R", "G", "B", "A"})
        for (std::size_t p = 0; p < a.channels.at(c).size(); ++p) {
            const double d = a.channels.at(c)[p] - b.channels.at(c)[p];
            se += d * d;
            ++n;
        }
    return 10.0 * std::log10(1.0 / std::max(se / n, 1e-12));
}

inline std::string slurp(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

class Cli : public ::testing::Test {
protected:
    Result run(const std::string& args) {
        const fs::path out = m_dir / "stdout.txt", err = m_dir / "stderr.txt";
        const std::string command = std::string(CONUS_BIN_DIR) + "/conus " + args + " >" + out.string() + " 2>" +
                                    err.string() + " </dev/null";
        const int status = std::system(command.c_str());
        Result r;
        r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        r.out = slurp(out);
        r.err = slurp(err);
        return r;
    }

    // A detailed RGB test picture (diagonal stripes of varying period plus a gradient), as PNG.
    std::string makePicture(int width, int height, const std::string& name = "in.png") {
        std::vector<unsigned char> pixels(static_cast<std::size_t>(width) * height * 3);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const double s = 0.5 + 0.5 * std::sin((x + y) * (0.05 + 0.4 * x / width));
                pixels[(y * width + x) * 3 + 0] = static_cast<unsigned char>(255 * s);
                pixels[(y * width + x) * 3 + 1] = static_cast<unsigned char>(255.0 * y / height);
                pixels[(y * width + x) * 3 + 2] = static_cast<unsigned char>(255 * (1 - s));
            }
        const std::string path = (m_dir / name).string();
        auto output = OIIO::ImageOutput::create(path);
        OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
        EXPECT_TRUE(output->open(path, spec));
        EXPECT_TRUE(output->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
        output->close();
        return path;
    }

    // path(name): the 16x16 uniform CoNUS file of a 64x64 picture that many tests decode. Call it
    // as ASSERT_NO_FATAL_FAILURE(makeUniformFile()), so a failed encode ends the test.
    void makeUniformFile(const std::string& name = "u.exr") {
        const std::string in = makePicture(64, 64);
        ASSERT_EQ(run("uniform " + in + " -o " + path(name) + " --size 16x16").exitCode, 0);
    }

    // A grey PNG that is bright in a disc around (0.3, 0.6) and dark elsewhere.
    std::string makeImportance(int width, int height) {
        std::vector<unsigned char> pixels(static_cast<std::size_t>(width) * height);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                pixels[y * width + x] = std::hypot((x + 0.5) / width - 0.3, (y + 0.5) / height - 0.6) < 0.15 ? 255 : 0;
        const std::string file = (m_dir / "importance.png").string();
        auto output = OIIO::ImageOutput::create(file);
        EXPECT_TRUE(output->open(file, OIIO::ImageSpec(width, height, 1, OIIO::TypeDesc::UINT8)));
        EXPECT_TRUE(output->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
        output->close();
        return file;
    }

    std::string path(const std::string& name) const { return (m_dir / name).string(); }

    // Nothing but the expected files: no temporaries left behind.
    std::vector<std::string> leftovers() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(m_dir)) {
            const std::string n = e.path().filename().string();
            if (n.find("tmp") != std::string::npos) names.push_back(n);
        }
        return names;
    }

    TestDir m_folder{"conus-cli"};
    const fs::path& m_dir = m_folder.path();
};

}  // namespace conus::test
