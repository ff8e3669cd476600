#include "conus/codec/map_file.h"

namespace conus::codec {

format::ConusFile makeMapFile(const SamplingMap& map, std::optional<format::AnalyticMap> analytic) {
    format::ConusFile file;
    file.image = format::makeImage(map.columns(), map.rows(), {"Y"});
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
