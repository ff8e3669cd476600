// The fixture of the hostile-input suites: the real `conus` binary run without a shell in a folder
// of its own, its wall time and peak memory measured (wait4), killed after 60 s so a hang fails;
// and the checks every refusal shares (one line `conus <cmd>: <reason>`, the exit code).
#pragma once

#include <gtest/gtest.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "conus/core/limits.h"
#include "sanitizers.h"

extern char** environ;

namespace fs = std::filesystem;

namespace conus::hostile {

struct Outcome {
    int exitCode = -1;
    std::string out, err;
    double seconds = 0;
    long peakKb = 0;  // the child's peak resident memory
};

inline std::string slurp(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// stderr's lines, without the progress lines commands print while they work.
inline std::vector<std::string> errorLines(const std::string& err) {
    std::vector<std::string> lines;
    std::stringstream in(err);
    for (std::string line; std::getline(in, line);)
        if (!line.empty() && !contains(line, " done (")) lines.push_back(line);
    return lines;
}

class Hostile : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() /
                ("conus-hostile-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "-" +
                 std::to_string(::getpid()));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }

    // Runs conus (or another of the built tools) with `args` (no shell), stdin from /dev/null,
    // measuring wall time and peak memory of that one child (wait4), killed after 60 s so a hang
    // fails instead of blocking the suite.
    Outcome run(const std::vector<std::string>& args) { return runTool("conus", args); }
    // `stdinFile` becomes the child's standard input (empty: /dev/null).
    Outcome runTool(const std::string& tool, const std::vector<std::string>& args, const std::string& stdinFile = "") {
        const std::string out = (m_dir / "stdout.txt").string(), err = (m_dir / "stderr.txt").string();
        std::vector<std::string> all{"timeout", "60", std::string(CONUS_BIN_DIR) + "/" + tool};
        all.insert(all.end(), args.begin(), args.end());
        std::vector<char*> argv;
        for (std::string& a : all) argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 0, stdinFile.empty() ? "/dev/null" : stdinFile.c_str(), O_RDONLY, 0);
        posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        Outcome r;
        const auto start = std::chrono::steady_clock::now();
        pid_t pid = 0;
        if (posix_spawnp(&pid, "timeout", &actions, nullptr, argv.data(), environ) != 0) {
            posix_spawn_file_actions_destroy(&actions);
            ADD_FAILURE() << "cannot start " << tool;
            return r;
        }
        int status = 0;
        rusage usage{};
        ::wait4(pid, &status, 0, &usage);
        posix_spawn_file_actions_destroy(&actions);
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        r.peakKb = usage.ru_maxrss;
        r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        r.out = slurp(out);
        r.err = slurp(err);
        return r;
    }

    std::string path(const std::string& name) const { return (m_dir / name).string(); }
    // `bytes` as the file `name` in the test's folder (its folders made).
    void write(const std::string& name, const std::string& bytes) const {
        fs::create_directories((m_dir / name).parent_path());
        std::ofstream(m_dir / name, std::ios::binary) << bytes;
    }

    // The file `relative` of the shared hostile files (shared/data/hostile).
    static std::string hostileData(const fs::path& relative) { return (fs::path(CONUS_SHARED_DATA) / "hostile" / relative).string(); }
    // A committed copy of a small reproducer, or the shared one.
    static std::string reproducer(const std::string& name) {
        const fs::path seed = fs::path(CONUS_FUZZ_CORPUS) / "container" / ("hostile-" + name);
        if (fs::exists(seed)) return seed.string();
        return hostileData(name);
    }

    // Refused: exit 1, the last stderr line is the one error line of `command`, holding `reason`.
    void expectRefused(const Outcome& r, const std::string& command, const std::string& reason, int exitCode = 1) {
        EXPECT_EQ(r.exitCode, exitCode) << r.err;
        const std::vector<std::string> lines = errorLines(r.err);
        ASSERT_FALSE(lines.empty()) << "no error line";
        EXPECT_EQ(lines.size(), 1u) << r.err;
        EXPECT_EQ(lines.back().rfind("conus " + command + ": ", 0), 0u) << lines.back();
        EXPECT_TRUE(contains(lines.back(), reason)) << lines.back();
    }

    // Handled within a second (plus the start) and with no more than `maxMb` of peak memory.
    static void expectBounded(const Outcome& r, long maxMb = 700) {
        EXPECT_LT(r.seconds, 2.0 * conus::testing::kTimeScale);
        EXPECT_LT(r.peakKb / 1024, maxMb * conus::testing::kMemoryScale);
    }

    // Peak memory only (time is not asserted; a hang is ended by the 60 s timeout and fails).
    static void expectMemory(const Outcome& r, long maxMb) { EXPECT_LT(r.peakKb / 1024, maxMb * conus::testing::kMemoryScale); }

    fs::path m_dir;
};

// `copies` near-copies of one triangle in one glTF mesh (its buffer a file beside it), copy i
// shifted by i millionths along (1, 0.5, 0.25): no two are the same (none is dropped as a
// duplicate), and every ray through the triangle crosses them all.
inline void writeNearCopies(const fs::path& gltf, int copies) {
    std::string bin;
    bin.reserve(std::size_t(copies) * 36);
    for (int i = 0; i < copies; ++i) {
        const float e = float(i) * 1e-6f;
        const float xyz[9] = {e, 0.5f * e, 0.25f * e, 1 + e, 0.5f * e, 0.25f * e, e, 1 + 0.5f * e, 0.25f * e};
        bin.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
    }
    const float spread = float(copies) * 1e-6f;
    std::ofstream(fs::path(gltf).replace_extension(".bin"), std::ios::binary) << bin;
    std::ofstream(gltf) << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
 "buffers": [{"uri": ")" << fs::path(gltf).replace_extension(".bin").filename().string() << R"(", "byteLength": )" << bin.size() << R"(}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": )" << bin.size() << R"(}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": )" << 3 * copies << R"(, "type": "VEC3", "min": [0, 0, 0], "max": [)"
                        << 1 + spread << ", " << 1 + spread << ", " << spread << "]}]}";
}

#define CONUS_REQUIRE(file)                                                                   \
    do {                                                                                      \
        if (!fs::exists(file)) GTEST_SKIP() << "shared data not found: " << (file);           \
    } while (0)

}  // namespace conus::hostile
