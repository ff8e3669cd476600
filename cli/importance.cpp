#include "importance.h"

#include <CLI/CLI.hpp>

#include "conus/codec/build/auto_map.h"
#include "conus/core/error.h"
#include "conus/core/plugin.h"
#include "conus/imageio/image_file.h"
#include "image_files.h"

namespace conus::cli {

Image faceImportance(const Image& image) {
    // CONUS_FACES_MODULE: the module's path relative to this program (cli/CMakeLists.txt).
    static const FaceImportanceFunction detect = reinterpret_cast<FaceImportanceFunction (*)()>(
        loadPluginSymbol(reinterpret_cast<const void*>(&faceImportance), CONUS_FACES_MODULE, "conusFaceImportance"))();
    return detect(image);
}

codec::AutoMapOptions autoMapOptions(int grid, double minDensity, double maxDensity, double maxAnisotropy, const std::string& method) {
    codec::AutoMapOptions options;
    options.columns = options.rows = grid;
    options.minDensity = minDensity;
    options.maxDensity = maxDensity;
    options.maxAnisotropy = maxAnisotropy;
    options.method = method == "separable" ? codec::AutoMethod::Separable : codec::AutoMethod::Flow;
    return options;
}

void addMaxAnisotropyOption(CLI::App& command, double& maxAnisotropy) {
    command.add_option("--max-anisotropy", maxAnisotropy,
                       "largest ratio of a CoNUS pixel's long to short side in the source (the Jacobian's singular "
                       "values; >= 1, default: no limit); a tight limit costs magnification")
        ->check(CLI::Range(1.0, 1e6));
}

void addDensityBoundOptions(CLI::App& command, double& minDensity, double& maxDensity, const std::string& prefix) {
    command.add_option("--min-density", minDensity,
                       prefix + "density every map cell keeps (0..1, default 0.25), held to 5% or refused")
        ->check(CLI::Range(0.001, 0.999));
    command.add_option("--max-density", maxDensity,
                       prefix + "cap on every map cell's density (default 16: 4x the linear rate), held to 5% or refused")
        ->check(CLI::Range(1.001, 4096.0));
}

Image importanceFrom(const std::string& source, const Image& image) {
    if (source == "detail") {
        if (image.empty()) throw Error(ErrorCode::InvalidArgument, "'detail' importance needs an input image");
        // Detail as people see it: on the display-encoded picture, where NaN cannot reach.
        return codec::detailImportance(imageio::displayEncoded(image));
    }
    if (source == "faces") {
        if (image.empty()) throw Error(ErrorCode::InvalidArgument, "'faces' importance needs an input image");
        return faceImportance(imageio::displayEncoded(image));
    }
    return readData(source);
}

}  // namespace conus::cli
