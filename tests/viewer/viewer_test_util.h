// Shared by the viewer tests: a small CoNUS file with a focus and one bright marker, the headless
// context, and running conus-view (under xvfb-run for window tests).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "conus/codec/image/encode.h"
#include "conus/codec/builders/foci.h"
#include "conus/format/container.h"
#include "conus/renderers/context.h"

namespace conus::viewer::test {

inline constexpr int kSourceWidth = 320, kSourceHeight = 240;
inline constexpr int kConusWidth = 200, kConusHeight = 150;
inline constexpr double kMarkerU = 0.3, kMarkerV = 0.4;   // a white disc on a dark picture
inline constexpr double kFocusU = 0.65, kFocusV = 0.55;

inline std::filesystem::path tempDir() {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("conus_viewer_tests_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    return dir;
}

// Dark smooth colours, a white disc of radius 5 source pixels at the marker.
inline Image sourceImage() {
    Image im = makeImage(kSourceWidth, kSourceHeight, {"R", "G", "B"});
    for (int y = 0; y < kSourceHeight; ++y)
        for (int x = 0; x < kSourceWidth; ++x) {
            const double u = (x + 0.5) / kSourceWidth, v = (y + 0.5) / kSourceHeight;
            const bool marker = std::hypot((u - kMarkerU) * kSourceWidth, (v - kMarkerV) * kSourceHeight) < 5.0;
            for (int c = 0; c < 3; ++c)
                im.at(x, y, c) = marker ? 1.0f : float(0.2 + 0.15 * std::sin(6 * u + 2 * c) * std::cos(5 * v));
        }
    return im;
}

inline format::ConusFile conusFile() {
    const codec::Focus focus{kFocusU, kFocusV, 0.1, 3.0};
    codec::FociOptions fo;
    fo.aspect = double(kSourceWidth) / kSourceHeight;
    const codec::SamplingMap map = codec::buildFociMap(std::span<const codec::Focus>(&focus, 1), fo);
    codec::EncodeOptions eo;
    eo.width = kConusWidth;
    eo.height = kConusHeight;
    format::ConusFile file;
    file.image = codec::encodeImage(sourceImage(), map, eo);
    file.pixelType = format::PixelType::Float;
    file.sourceWidth = kSourceWidth;
    file.sourceHeight = kSourceHeight;
    file.map = map.toGrid();
    format::AnalyticMap analytic;
    analytic.kind = "foci";
    analytic.composition = "density";
    analytic.foci.push_back({focus.u, focus.v, focus.r, focus.k});
    file.analytic = analytic;
    return file;
}

// Written once per process.
inline const std::string& conusPath() {
    static const std::string path = [] {
        const std::string p = (tempDir() / "test.exr").string();
        format::writeConusFile(p, conusFile());
        return p;
    }();
    return path;
}

inline renderers::Context& context() {
    // Never destroyed: Mesa's exit handlers may run before static destructors.
    static renderers::Context* c = renderers::Context::create().release();
    return *c;
}

inline std::string viewerBinary() { return std::string(CONUS_BIN_DIR) + "/conus-view"; }

inline bool haveXvfb() { return std::system("command -v xvfb-run > /dev/null 2>&1") == 0; }

// Runs a shell command, its output into `log`; returns the exit status. A command under
// xvfb-run that xvfb-run itself failed ("xvfb-run: error: ...": seen in parallel test runs as
// "problem while cleaning up temporary directory", exit 5, after the command had run; two `-a`
// servers starting at once race for a display) is run again, up to three times in all, unless
// the failed run's output holds a sanitizer's report; `log` gets every attempt's output.
inline int run(const std::string& command, std::string* log = nullptr) {
    const std::string logPath = (tempDir() / "run.log").string();
    int status = 0;
    std::string all;
    for (int attempt = 0; attempt < 3; ++attempt) {
        status = std::system((command + " > " + logPath + " 2>&1").c_str());
        std::ifstream in(logPath);
        const std::string text{std::istreambuf_iterator<char>(in), {}};
        all += text;
        const bool xvfbFailed = command.rfind("xvfb-run", 0) == 0 && text.find("xvfb-run: error:") != std::string::npos;
        const bool sanitizer = text.find("Sanitizer") != std::string::npos || text.find("runtime error:") != std::string::npos;
        if (!xvfbFailed || sanitizer) break;
        all += "\n[run again: xvfb-run failed]\n";
    }
    if (log) *log = all;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline void writeText(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

}  // namespace conus::viewer::test
