#include "encoding.h"

#include <CLI/CLI.hpp>

#include <algorithm>

#include "conus/codec/encode.h"
#include "progress.h"

namespace conus::cli {

void addStorageOptions(CLI::App& command, StorageOptions& options) {
    command.add_option("--size", options.sizeText, "CoNUS image size WxH (default: a quarter of each source side)");
    auto* half = command.add_flag("--half", options.half, "store colour channels as 16-bit half (default)");
    command.add_flag("--float", options.full, "store colour channels as 32-bit float")->excludes(half);
    command.add_option("--compression", options.compression, "zip | piz | dwaa | none")
        ->default_val("zip")
        ->check(CLI::IsMember({"zip", "piz", "dwaa", "none"}));
    addBackendOption(command, options.backend);
}

Size conusSize(const StorageOptions& options, const format::Image& source) {
    if (!options.sizeText.empty()) return parseSize(options.sizeText);
    return {std::max(1, (source.width + 2) / 4), std::max(1, (source.height + 2) / 4)};
}

void applyStorage(const StorageOptions& options, format::ConusFile& file) {
    file.pixelType = options.full ? format::PixelType::Float : format::PixelType::Half;
    file.compression = parseCompression(options.compression);
}

format::ConusFile encodeToConus(Renderer& renderer, const format::Image& source, const codec::SamplingMap& map,
                                Size size, std::optional<format::AnalyticMap> analytic, bool quiet) {
    Progress progress("encode " + std::to_string(source.width) + "x" + std::to_string(source.height) + " -> " +
                          std::to_string(size.width) + "x" + std::to_string(size.height),
                      quiet);
    format::ConusFile file;
    file.image = renderer.encode(source, map, {size.width, size.height, 0, progress.callback()});
    progress.done();
    file.sourceWidth = source.width;
    file.sourceHeight = source.height;
    file.map = map.toGrid();
    file.analytic = std::move(analytic);
    if (file.image.channelIndex("Z") >= 0) {
        file.depth.kind = format::DepthKind::CameraDepth;
        file.depth.near = 0;
        file.depth.far = 1;
    }
    return file;
}

}  // namespace conus::cli
