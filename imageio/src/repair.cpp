// Repairing NaN and infinite values with OpenImageIO's fixNonFinite (oiiotool --fixnan): what
// reading a file with ReadOptions::repair does, and what callers holding pixels in memory ask for.
#include <OpenImageIO/imagebufalgo.h>

#include <cmath>

#include "conus/core/error.h"
#include "oiio_module_pvt.h"

namespace conus::imageio::oiio {

void repairNonFinite(Image& image, NonFiniteRepair repair, const std::string& shown) {
    if (repair == NonFiniteRepair::Keep || image.pixels.empty()) return;
    OIIO::ImageBuf buffer(OIIO::ImageSpec(image.width, image.height, image.channelCount(), OIIO::TypeDesc::FLOAT),
                          image.pixels.data());
    const auto mode = repair == NonFiniteRepair::Black ? OIIO::ImageBufAlgo::NONFINITE_BLACK : OIIO::ImageBufAlgo::NONFINITE_BOX3;
    if (!OIIO::ImageBufAlgo::fixNonFinite(buffer, buffer, mode))
        throw Error(ErrorCode::Io, shown + ": cannot repair non-finite values: " + buffer.geterror());
    // Box3 leaves a value whose 3x3 neighbourhood holds nothing finite; those become 0.
    for (float& v : image.pixels)
        if (!std::isfinite(v)) v = 0.0f;
}

}  // namespace conus::imageio::oiio
