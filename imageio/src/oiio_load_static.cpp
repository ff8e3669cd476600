// Static builds (the fuzz harnesses): the OpenImageIO half is linked in, nothing to load.
#include "oiio_module_pvt.h"

namespace conus::imageio {

const OiioFunctions& oiioFunctions() { return *conusImageioOiio(); }

}  // namespace conus::imageio
