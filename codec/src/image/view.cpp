// What a view rectangle must be, for every caller (the CLI's --view, Python's view=).
#include <cmath>

#include "conus/codec/image/decode.h"
#include "conus/core/error.h"

namespace conus::codec {

void checkView(const View& view, const std::string& shown) {
    for (double value : {view.u0, view.v0, view.u1, view.v1})
        if (!std::isfinite(value)) throw Error(ErrorCode::InvalidArgument, "view " + shown + " holds a value that is not finite");
    if (!(view.u0 < view.u1) || !(view.v0 < view.v1))
        throw Error(ErrorCode::InvalidArgument, "view " + shown + " is empty or inverted: it needs u0 < u1 and v0 < v1");
    if (std::abs(view.u0) > 1e3 || std::abs(view.u1) > 1e3 || std::abs(view.v0) > 1e3 || std::abs(view.v1) > 1e3)
        throw Error(ErrorCode::InvalidArgument, "view " + shown + " is absurdly far from the image ([0,1] is the whole image)");
    // Partly outside shows the background there; wholly outside would be a frame of nothing but background.
    if (view.u1 <= 0 || view.u0 >= 1 || view.v1 <= 0 || view.v0 >= 1)
        throw Error(ErrorCode::InvalidArgument,
                    "view " + shown + " lies wholly outside the image (u and v run over [0, 1]: 0,0,1,1 is the whole image)");
}

}  // namespace conus::codec
