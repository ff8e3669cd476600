// Stands in for context_egl.cpp when CMake found no EGL library at configure time.
#include "context_pvt.h"

namespace conus::renderers {

std::unique_ptr<Platform> createEglPlatform(std::string& reason) {
    reason = "this build has no EGL (libEGL was not found when it was configured)";
    return nullptr;
}

}  // namespace conus::renderers
