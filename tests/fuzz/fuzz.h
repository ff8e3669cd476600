// The libFuzzer entry point every harness in tests/fuzz defines (fuzz_<name>.cpp, one per input
// kind). The same file builds two ways: with clang and -fsanitize=fuzzer for fuzzing
// (scripts/fuzz.sh), and with the ordinary compiler and replay_main.cpp as a test that runs every
// file of the committed corpus through it (ctest: fuzz_replay.<name>). A harness returns 0 for any
// input and aborts (a finding) only when the library breaks a promise: a crash, an exception that
// is not conus::Error, a result that contradicts the input.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "conus/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

// A broken promise: say which and abort, so both libFuzzer and the replay test report it.
#define CONUS_FUZZ_CHECK(condition, what)                                                   \
    do {                                                                                    \
        if (!(condition)) {                                                                 \
            std::fprintf(stderr, "fuzz check failed: %s (%s:%d)\n", what, __FILE__, __LINE__); \
            std::abort();                                                                   \
        }                                                                                   \
    } while (0)

inline bool isOneLine(const std::string& s) { return s.find('\n') == std::string::npos && s.find('\r') == std::string::npos; }

// Runs `read` (a reader on one input and the checks of what it read): the reader may refuse the
// input with a one-line conus::Error and throws nothing else.
template <class Read>
int readOrRefuse(Read read) {
    try {
        read();
    } catch (const conus::Error& e) {
        CONUS_FUZZ_CHECK(isOneLine(e.what()), "an error is one line");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "non-CoNUS exception: %s\n", e.what());
        CONUS_FUZZ_CHECK(false, "the reader throws only conus::Error");
    }
    return 0;
}
