// conus-view: a small, pleasant viewer for CoNUS files (and the map editor of paper Figure 8).
#include <cstdio>
#include <string>
#include <vector>

#include "app.h"
#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "options.h"
#include "screenshot.h"

int main(int argc, char** argv) {
    int exitCode = 0;
    const auto options = conus::viewer::parseOptions(argc, argv, &exitCode);
    if (!options) return exitCode;
    // Files that are not there are said in one line before a window opens.
    std::vector<std::string> inputs = options->files;
    for (const std::string* path : {&options->uniform, &options->edit})
        if (!path->empty()) inputs.push_back(*path);
    for (const std::string& path : inputs) {
        try {
            conus::checkInputPath(path);
        } catch (const conus::Error& e) {
            std::fprintf(stderr, "conus-view: %s\n", e.what());
            return 1;
        }
    }
    if (!options->screenshot.empty()) return conus::viewer::runScreenshot(*options);
    return conus::viewer::runWindow(*options);
}
