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

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

// A broken promise: say which and abort, so both libFuzzer and the replay test report it.
#define CONUS_FUZZ_CHECK(condition, what)                                                   \
    do {                                                                                    \
        if (!(condition)) {                                                                 \
            std::fprintf(stderr, "fuzz check failed: %s (%s:%d)\n", what, __FILE__, __LINE__); \
            std::abort();                                                                   \
        }                                                                                   \
    } while (0)
