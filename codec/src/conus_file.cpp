#include "conus/codec/conus_file.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "conus/core/error.h"

namespace conus::codec {

format::ConusFile makeImageFile(Image image, const SamplingMap& map, int sourceWidth, int sourceHeight,
                                SourceEncoding encoding, std::optional<format::AnalyticMap> analytic) {
    format::ConusFile file;
    file.image = std::move(image);
    file.sourceWidth = sourceWidth;
    file.sourceHeight = sourceHeight;
    file.dataKind = format::DataKind::Image;
    file.map = map.toGrid();
    file.analytic = std::move(analytic);
    file.sourceEncoding = std::move(encoding);
    if (file.image.channelIndex("Z") >= 0) {  // V14: a Z channel needs a depth kind
        file.depth.kind = format::DepthKind::CameraDepth;
        file.depth.near = 0;
        file.depth.far = 1;
    }
    return file;
}

format::ConusFile makeDepthImageFile(Image image, const SamplingMap& map, const Camera& camera, std::string units,
                                     std::optional<format::AnalyticMap> analytic) {
    if (image.channelIndex("Z") < 0)
        throw Error(ErrorCode::InvalidArgument, "makeDepthImageFile: the image has no Z channel");
    const int width = image.width, height = image.height;
    format::ConusFile file = makeImageFile(std::move(image), map, width, height, {}, std::move(analytic));
    file.dataKind = format::DataKind::DepthImage;
    file.pixelType = format::PixelType::Float;
    file.camera = format::toAttributes(camera);
    file.depth = {format::DepthKind::CameraDepth, std::move(units), static_cast<float>(camera.near()),
                  static_cast<float>(camera.far())};
    return file;
}

std::optional<double> madeForAspect(const format::ConusFile& file) {
    if (file.analytic)
        if (const auto aspect = file.analytic->scalars.find("aspect"); aspect != file.analytic->scalars.end()) return aspect->second;
    if (file.sourceWidth <= 0 || file.sourceHeight <= 0) return std::nullopt;
    // A map file's source size is its grid's: it says nothing of the pictures.
    if (file.sourceWidth == file.map.columns && file.sourceHeight == file.map.rows && file.image.width == file.map.columns)
        return std::nullopt;
    return double(file.sourceWidth) / file.sourceHeight;
}

bool aspectsDiffer(double madeFor, double aspect) { return std::abs(std::log(madeFor / aspect)) > 0.01; }

std::pair<int, int> defaultConusSize(int sourceWidth, int sourceHeight) {
    return {std::max(1, (sourceWidth + 2) / 4), std::max(1, (sourceHeight + 2) / 4)};
}

void checkGridForImage(int side, int width, int height, const std::string& what, int defaultSide) {
    const std::int64_t most = std::max<std::int64_t>(defaultSide, map_rules::maxSideForImage(width, height));
    if (side > most)
        throw Error(ErrorCode::InvalidArgument, what + " " + std::to_string(side) + " is finer than a " + std::to_string(width) + "x" +
                                                    std::to_string(height) + " image can show; at most " + std::to_string(most) +
                                                    " nodes a side");
}

format::ConusFile makeMapFile(const SamplingMap& map, std::optional<format::AnalyticMap> analytic) {
    format::ConusFile file;
    file.image = makeImage(map.columns(), map.rows(), {"Y"});
    for (int j = 0; j < map.rows(); ++j)
        for (int i = 0; i < map.columns(); ++i)
            file.image.at(i, j) =
                static_cast<float>(map.density({double(i) / (map.columns() - 1), double(j) / (map.rows() - 1)}));
    file.pixelType = format::PixelType::Float;
    file.sourceWidth = map.columns();
    file.sourceHeight = map.rows();
    file.dataKind = format::DataKind::Image;
    file.map = map.toGrid();
    file.analytic = std::move(analytic);
    return file;
}

}  // namespace conus::codec
