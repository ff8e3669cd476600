// conus-view: a small, pleasant viewer for CoNUS files (and the map editor of paper Figure 8).
#include "app.h"
#include "options.h"
#include "screenshot.h"

int main(int argc, char** argv) {
    int exitCode = 0;
    const auto options = conus::viewer::parseOptions(argc, argv, &exitCode);
    if (!options) return exitCode;
    if (!options->screenshot.empty()) return conus::viewer::runScreenshot(*options);
    return conus::viewer::runWindow(*options);
}
