// Private: the CPU encoder's erf and its choice of tap loop, shared with its test
// (tests/codec/image/encode_test.cpp).
#pragma once

#include "conus/codec/image/encode.h"

namespace conus::codec::detail {

// erf where the footprint filter needs it: the Gaussian is cut at kEncodeGaussianReach standard
// deviations, so its arguments never pass kEncodeGaussianReach / sqrt(2) (beyond, the value there).
// x * P(x^2), P of degree 9 fitted by least squares to the library's erf on that interval: within
// 1.3e-9 of it in double. No table and no branch, so a row of taps' weights vectorizes (the
// library's erf would take most of the encode). In float (the anisotropic kernel's weights, normalized by their sum, eight
// at a time in an AVX2 register where double takes four): within 4e-7 of erf.
template <typename T>
inline T erfOnReachIn(T x) {
    constexpr T kMax = static_cast<T>(kEncodeGaussianReach / 1.4142135623730951);
    x = x < -kMax ? -kMax : x;  // (not std::min/max: those kept loops over taps from vectorizing)
    x = x > kMax ? kMax : x;
    const T t = x * x;
    T p = static_cast<T>(-4.0372232612551073e-08);
    p = p * t + static_cast<T>(9.9982670243026206e-07);
    p = p * t - static_cast<T>(1.2768009530393643e-05);
    p = p * t + static_cast<T>(0.00011588722286987735);
    p = p * t - static_cast<T>(0.00084828613557390038);
    p = p * t + static_cast<T>(0.0052181384723283871);
    p = p * t - static_cast<T>(0.026863017237900313);
    p = p * t + static_cast<T>(0.11283697815173353);
    p = p * t - static_cast<T>(0.37612626115271097);
    p = p * t + static_cast<T>(1.1283791620114259);
    return x * p;
}
inline double erfOnReach(double x) { return erfOnReachIn(x); }
inline float erfOnReachFloat(float x) { return erfOnReachIn(x); }

// Whether this processor runs the encoder's AVX2 tap loop (false where the build has none), and a
// switch to the baseline loop for every encode after it (tests compare the two).
bool encodeAvx2Available();
void forceBaselineEncode(bool baseline);

}  // namespace conus::codec::detail
