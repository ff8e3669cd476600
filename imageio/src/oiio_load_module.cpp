// Shared builds: OpenImageIO (and the ~260 libraries it links: OpenCV, GDAL, FFmpeg, ...) is
// loaded with its module the first time an image file is read or written, not at start-up.
#include "conus/core/plugin.h"
#include "oiio_module_pvt.h"

namespace conus::imageio {

const OiioFunctions& oiioFunctions() {
    // Beside this library in the build tree and when installed (imageio/CMakeLists.txt).
    static const OiioFunctions* functions = reinterpret_cast<decltype(&conusImageioOiio)>(loadPluginSymbol(
        reinterpret_cast<const void*>(&oiioFunctions), "libconus_imageio_oiio.so", "conusImageioOiio"))();
    return *functions;
}

}  // namespace conus::imageio
