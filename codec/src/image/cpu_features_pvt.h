// Private: the processor features the decoder's AVX2 copies need, asked once. An AVX2 copy is a
// function compiled with CONUS_TARGET_AVX2 (x86-64-v3: AVX2, FMA, BMI2) beside its baseline twin;
// CONUS_HAVE_AVX2_COPY says whether this compiler builds such copies at all.
#pragma once

namespace conus::codec::detail {

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define CONUS_HAVE_AVX2_COPY 1
#define CONUS_TARGET_AVX2 [[gnu::target("avx2,fma,bmi,bmi2")]]
#else
#define CONUS_HAVE_AVX2_COPY 0
#define CONUS_TARGET_AVX2
#endif

// Whether this processor runs the AVX2 copies (false where this build has none).
inline bool cpuHasAvx2() {
#if CONUS_HAVE_AVX2_COPY
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2");
#else
    return false;
#endif
}

}  // namespace conus::codec::detail
