// Replays files through a harness's LLVMFuzzerTestOneInput without libFuzzer: what ctest runs on
// every build (the committed seed corpus, the shared damaged and hostile files), so CI keeps the
// corpus passing without fuzzing. Arguments are files or folders (read one level deep); a folder
// that does not exist is reported as skipped, not failed (the shared data may be absent).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
    std::vector<fs::path> files;
    for (int i = 1; i < argc; ++i) {
        const fs::path arg(argv[i]);
        std::error_code ec;
        if (fs::is_regular_file(arg, ec)) {
            files.push_back(arg);
        } else if (fs::is_directory(arg, ec)) {
            for (const auto& entry : fs::directory_iterator(arg))
                if (entry.is_regular_file()) files.push_back(entry.path());
        } else {
            std::printf("[ skipped  ] %s: not found\n", arg.c_str());
        }
    }
    std::sort(files.begin(), files.end());
    const auto start = std::chrono::steady_clock::now();
    for (const fs::path& file : files) {
        // Printed first, so a crash names its input.
        std::printf("[ replay   ] %s\n", file.c_str());
        std::fflush(stdout);
        std::ifstream in(file, std::ios::binary);
        const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("[ passed   ] %zu inputs in %.2f s\n", files.size(), seconds);
    return files.empty() ? 1 : 0;
}
