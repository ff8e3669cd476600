#!/usr/bin/env bash
# Set-up command 2: install, build, and run the whole test suite (ctest). CI calls exactly this.
#
# scripts/run-tests.sh --sanitize: the same suite built with AddressSanitizer and
# UndefinedBehaviorSanitizer (g++) in build-asan/, every sanitizer finding fatal, leaks reported
# except Mesa's known ones (scripts/lsan.supp). Slower (about 3x); the nightly habit, not CI's.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--sanitize" ]; then
  scripts/setup.sh --packages-only
  launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
  # Not here: the Python module (an instrumented .so cannot load into an uninstrumented python3) and
  # the install test (its consumer is built without the sanitizers); the plain suite runs both.
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCONUS_BUILD_BENCH=OFF -DCONUS_BUILD_PYTHON=OFF \
    -DCONUS_TEST_INSTALL=OFF \
    -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
    "${launcher[@]}" >/dev/null
  cmake --build build-asan --parallel "${CONUS_JOBS:-$(nproc)}"
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=1:check_initialization_order=1"
  export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  ctest --test-dir build-asan --output-on-failure --parallel "${CONUS_JOBS:-$(nproc)}" --timeout 1800
  exit
fi
scripts/setup.sh
ctest --test-dir build --output-on-failure --parallel "$(nproc)" --timeout 900
