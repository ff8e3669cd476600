// Helpers shared by the format tests: a valid ConusFile, temporary folders, shared-data lookup.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "conus/core/error.h"
#include "conus/format/container.h"

namespace conus::format::testing {

// The conus::Error that `action` throws; when it throws none, a failure of the calling test (and
// an Error that says so).
template <class Action>
Error errorFrom(Action&& action) {
    try {
        action();
    } catch (const Error& e) {
        return e;
    }
    ADD_FAILURE() << "expected conus::Error";
    return Error(ErrorCode::Io, "no conus::Error was thrown");
}

inline GridNodes identityGrid(int columns, int rows) {
    GridNodes g;
    g.columns = columns;
    g.rows = rows;
    g.xy.resize(std::size_t{2} * columns * rows);
    for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < columns; ++i) {
            const std::size_t k = std::size_t(j) * columns + i;
            g.xy[2 * k] = float(i) / float(columns - 1);
            g.xy[2 * k + 1] = float(j) / float(rows - 1);
        }
    }
    return g;
}

// A small valid file: RGBA with values that are not representable in half, a gently distorted map.
inline ConusFile validFile(PixelType type = PixelType::Float) {
    ConusFile f;
    f.image = makeImage(8, 6, {"A", "B", "G", "R"});
    for (std::size_t i = 0; i < f.image.pixels.size(); ++i) f.image.pixels[i] = 0.1f + 0.0137f * float(i) + 1e-7f * float(i % 7);
    f.pixelType = type;
    f.compression = Compression::Zip;
    f.sourceWidth = 16;
    f.sourceHeight = 12;
    f.map = identityGrid(5, 4);
    f.map.xy[2 * (1 * 5 + 2)] += 0.05f;  // interior node (2,1) moves right
    return f;
}

// A fresh folder under the system temp directory, removed at the end of the test.
class TempDir {
public:
    TempDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_path = std::filesystem::temp_directory_path() /
                 ("conus-format-" + std::to_string(::getpid()) + "-" + info->test_suite_name() + "-" + info->name());
        std::filesystem::remove_all(m_path);
        std::filesystem::create_directories(m_path);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::permissions(m_path, std::filesystem::perms::owner_all, ec);
        std::filesystem::remove_all(m_path, ec);
    }
    std::string file(const std::string& name) const { return (m_path / name).string(); }
    const std::filesystem::path& path() const { return m_path; }

private:
    std::filesystem::path m_path;
};

inline std::filesystem::path sharedData() { return std::filesystem::path(CONUS_SHARED_DATA); }

#define CONUS_REQUIRE_SHARED_DATA()                                                                 \
    do {                                                                                            \
        if (!std::filesystem::is_directory(::conus::format::testing::sharedData() / "exr"))         \
            GTEST_SKIP() << "shared data not found at " << ::conus::format::testing::sharedData(); \
    } while (0)

}  // namespace conus::format::testing
