// Stands in for context_osmesa.cpp when CMake found no OSMesa library at configure time.
#include "context_pvt.h"

namespace conus::renderers {

std::unique_ptr<Platform> createOsMesaPlatform(std::string& reason) {
    reason = "this build has no OSMesa (libOSMesa was not found when it was configured)";
    return nullptr;
}

}  // namespace conus::renderers
