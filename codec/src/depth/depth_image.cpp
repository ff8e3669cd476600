#include "conus/codec/depth/depth_image.h"

#include <algorithm>
#include <string>

#include "conus/core/error.h"
#include "conus/core/parallel.h"

namespace conus::codec {

Image decodeDepthNearest(const Image& conus, const SamplingMap& map, const DecodeOptions& options, float background) {
    checkImage(conus, "decodeDepthNearest");
    const int z = conus.channelIndex("Z");
    if (z < 0) throw Error(ErrorCode::InvalidArgument, "decodeDepthNearest: the CoNUS image has no Z channel");
    if (options.width < 1 || options.height < 1)
        throw Error(ErrorCode::InvalidArgument, "decodeDepthNearest: output " + std::to_string(options.width) + "x" +
                                                    std::to_string(options.height));
    checkDecodeMemory(conus, options.width, options.height);
    Image out = makeImage(options.width, options.height, {"Z"});
    const View& view = options.view;
    parallelRows(options.height, options.threads, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y) {
        const double v = view.v0 + (y + 0.5) / options.height * (view.v1 - view.v0);
        for (int x = 0; x < options.width; ++x) {
            const double u = view.u0 + (x + 0.5) / options.width * (view.u1 - view.u0);
            if (u < 0 || u > 1 || v < 0 || v > 1) {
                out.at(x, y) = background;
                continue;
            }
            const glm::dvec2 pd = map.distort({u, v});
            const int px = std::clamp(static_cast<int>(pd.x * conus.width), 0, conus.width - 1);
            const int py = std::clamp(static_cast<int>(pd.y * conus.height), 0, conus.height - 1);
            out.at(x, y) = conus.at(px, py, z);
        }
      }
    });
    return out;
}

}  // namespace conus::codec
