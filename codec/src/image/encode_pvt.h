// Private: the CPU encoder's erf and its choice of tap loop, shared with its test
// (tests/codec/image/encode_test.cpp).
#pragma once

#include "conus/codec/image/encode.h"

namespace conus::codec::detail {

// erf where the footprint filter needs it: the Gaussian is cut at kEncodeGaussianReach standard
// deviations, so its arguments never pass kEncodeGaussianReach / sqrt(2) (beyond, the value there).
// x * P(x^2), P of degree 9 fitted by least squares to the library's erf on that interval: within
// 1.3e-9 of it, where the table it replaces was within 1e-7 (linear between 2049 values). No table
// and no branch, so a row of taps' weights vectorizes; the library's erf took most of the encode.
inline double erfOnReach(double x) {
    constexpr double kMax = kEncodeGaussianReach / 1.4142135623730951;
    x = x < -kMax ? -kMax : x;  // (not std::min/max: those kept loops over taps from vectorizing)
    x = x > kMax ? kMax : x;
    const double t = x * x;
    double p = -4.0372232612551073e-08;
    p = p * t + 9.9982670243026206e-07;
    p = p * t - 1.2768009530393643e-05;
    p = p * t + 0.00011588722286987735;
    p = p * t - 0.00084828613557390038;
    p = p * t + 0.0052181384723283871;
    p = p * t - 0.026863017237900313;
    p = p * t + 0.11283697815173353;
    p = p * t - 0.37612626115271097;
    p = p * t + 1.1283791620114259;
    return x * p;
}

// erfOnReach in float, the same polynomial: within 4e-7 of erf (float rounding), for the
// anisotropic kernel's weights (normalized by their sum, where float is plenty), eight at a time
// in an AVX2 register where double took four.
inline float erfOnReachFloat(float x) {
    constexpr float kMax = static_cast<float>(kEncodeGaussianReach / 1.4142135623730951);
    x = x < -kMax ? -kMax : x;
    x = x > kMax ? kMax : x;
    const float t = x * x;
    float p = -4.0372232612551073e-08f;
    p = p * t + 9.9982670243026206e-07f;
    p = p * t - 1.2768009530393643e-05f;
    p = p * t + 0.00011588722286987735f;
    p = p * t - 0.00084828613557390038f;
    p = p * t + 0.0052181384723283871f;
    p = p * t - 0.026863017237900313f;
    p = p * t + 0.11283697815173353f;
    p = p * t - 0.37612626115271097f;
    p = p * t + 1.1283791620114259f;
    return x * p;
}

// Whether this processor runs the encoder's AVX2 tap loop (false where the build has none), and a
// switch to the baseline loop for every encode after it (tests compare the two).
bool encodeAvx2Available();
void forceBaselineEncode(bool baseline);

}  // namespace conus::codec::detail
