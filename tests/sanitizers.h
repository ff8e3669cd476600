// Tests that bound wall time or peak memory multiply the bound by kTimeScale or kMemoryScale.
// A time bound here is a hang detector, not a speed claim (speed is measured in bench/): the
// failures it guards took 13 s to minutes. Wall time on a shared 2-core machine running the suite
// two tests at a time drifts to 1.1-2.4x an idle run, so plain builds allow 3x; builds with
// AddressSanitizer (the nightly suite, scripts/run-tests.sh --sanitize) run about 3-5 times slower
// and hold more (shadow memory, redzones, the quarantine of freed blocks).
#pragma once

#include <string>

#if defined(__SANITIZE_ADDRESS__)
#define CONUS_TESTS_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CONUS_TESTS_SANITIZED 1
#endif
#endif

#ifdef CONUS_TESTS_SANITIZED
#include <dlfcn.h>
#include <sanitizer/asan_interface.h>

#include <filesystem>
#endif

namespace conus::testing {
#ifdef CONUS_TESTS_SANITIZED
inline constexpr double kTimeScale = 5.0;
inline constexpr long kMemoryScale = 2;
#else
inline constexpr double kTimeScale = 3.0;
inline constexpr long kMemoryScale = 1;
#endif

// What to put before a command that opens a GLX window, in a sanitized build: Mesa's GLX dlcloses
// its DRI driver at teardown, and LeakSanitizer then reports the blocks the driver's globals held
// as leaks of no module (so no suppression can name them). Preloading the driver, after the ASan
// runtime (which must come first), keeps it mapped. Empty in other builds.
inline std::string glxLeakCheckPrefix() {
#ifdef CONUS_TESTS_SANITIZED
    const char* driver = "/usr/lib/x86_64-linux-gnu/dri/swrast_dri.so";
    Dl_info info{};
    if (::dladdr(reinterpret_cast<void*>(&__asan_region_is_poisoned), &info) && info.dli_fname &&
        std::filesystem::exists(driver))
        return std::string("env LD_PRELOAD=") + info.dli_fname + ":" + driver + " ";
#endif
    return {};
}

}  // namespace conus::testing
