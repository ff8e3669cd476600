// Files from the shared corpus: ordinary EXRs are NotConus; OpenEXR's damaged regression files are
// refused with conus::Error, without crashing or hanging.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>

#include "test_files.h"

namespace conus::format {
namespace {

using testing::sharedData;

TEST(Corpus, OrdinaryExrsAreNotConus) {
    CONUS_REQUIRE_SHARED_DATA();
    int seen = 0;
    for (const auto& entry : std::filesystem::directory_iterator(sharedData() / "exr")) {
        if (entry.path().extension() != ".exr") continue;
        ++seen;
        SCOPED_TRACE(entry.path().string());
        try {
            readConusFile(entry.path().string());
            ADD_FAILURE() << "read as a CoNUS file";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::NotConus) << e.what();
        }
        const ValidationReport r = validateConusFile(entry.path().string());
        EXPECT_TRUE(r.violates(Rule::V2)) << r.str();
    }
    EXPECT_GE(seen, 1);
}

TEST(Corpus, BeachballMultipartIsNotConus) {
    CONUS_REQUIRE_SHARED_DATA();
    const std::string path = (sharedData() / "exr" / "Beachball_multipart.0001.exr").string();
    try {
        readConusFile(path);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::NotConus);
        EXPECT_NE(std::string(e.what()).find("not a CoNUS file: no part named `conus`"), std::string::npos) << e.what();
    }
}

TEST(Corpus, DamagedFilesAreRejected) {
    CONUS_REQUIRE_SHARED_DATA();
    const auto folder = sharedData() / "exr" / "damaged";
    if (!std::filesystem::is_directory(folder)) GTEST_SKIP() << "shared data not found at " << folder;
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        if (entry.is_regular_file()) files.push_back(entry.path());  // README.rst too: not an EXR either
    }
    std::sort(files.begin(), files.end());
    EXPECT_EQ(files.size(), 186u);
    for (const auto& file : files) {
        // Printed first, so a crash or hang names the culprit in the log.
        std::printf("[ damaged  ] %s\n", file.filename().c_str());
        std::fflush(stdout);
        const auto start = std::chrono::steady_clock::now();
        try {
            readConusFile(file.string());
            ADD_FAILURE() << file << " was read as a valid CoNUS file";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()), "") << file;
        } catch (const std::exception& e) {
            ADD_FAILURE() << file << " threw a non-CoNUS exception: " << e.what();
        }
        EXPECT_FALSE(validateConusFile(file.string()).ok()) << file;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_LT(seconds, 10.0) << file << " took too long";
    }
}

}  // namespace
}  // namespace conus::format
