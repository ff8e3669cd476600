// Tests that bound wall time or peak memory multiply the bound by kTimeScale or kMemoryScale:
// builds with AddressSanitizer (the nightly suite, scripts/run-tests.sh --sanitize) run about 3-5
// times slower and hold more (shadow memory, redzones, the quarantine of freed blocks).
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define CONUS_TESTS_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CONUS_TESTS_SANITIZED 1
#endif
#endif

namespace conus::testing {
#ifdef CONUS_TESTS_SANITIZED
inline constexpr double kTimeScale = 5.0;
inline constexpr long kMemoryScale = 2;
#else
inline constexpr double kTimeScale = 1.0;
inline constexpr long kMemoryScale = 1;
#endif
}  // namespace conus::testing
