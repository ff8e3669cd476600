#!/usr/bin/env bash
# Builds the libFuzzer harnesses (tests/fuzz/fuzz_*.cpp) with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer into build-fuzz/ and runs each in turn for SECONDS (default 60), one
# process at a time, on its seeds (tests/fuzz/corpus/<harness>), the shared damaged and hostile
# files, and the dictionary (tests/fuzz/conus.dict), inputs of at most 16 KB (the seeds are a few
# KB; the large hostile maps are replayed by ctest). Inputs that reach new code are kept in
# build-fuzz/corpus/<harness>/ between runs. A crash, a leak, a timeout or a broken check stops
# that harness, leaves the input in build-fuzz/artifacts/ and makes the script fail; reproduce it
# with build-fuzz/bin/fuzz_<harness> <file>, then add the file to the harness's seeds.
# A unit slower than CONUS_FUZZ_TIMEOUT seconds (default 30) is a finding. Every input runs in well
# under a second on an idle core; a lower limit reports false timeouts when the machine is busy (a
# build beside a niced fuzzer starved it past 10 s while the same inputs replay in 0.8 s).
# CONUS_FUZZ_RUNS=N stops each harness after N executions instead (SECONDS still bounds it).
# CONUS_FUZZ_MAX_LEN=N caps the inputs at N bytes instead of 16384 (4096 suits the image harness,
# whose pictures past 4096 pixels are refused before decoding).
# CONUS_FUZZ_SANITIZERS=undefined builds into build-fuzz-undefined/ without AddressSanitizer: the
# harnesses then run several times faster where a reader allocates large buffers (Assimp's OBJ
# importer fills 16 MB per file, and ASan maps and faults those pages in afresh every time). The
# corpus, logs and findings stay in build-fuzz/, shared with the full build.
# CONUS_FUZZ_FORK=N runs N processes per harness (libFuzzer's -fork) on a machine with the cores.
# CONUS_FUZZ_BUILD=0 runs the harnesses already built, installing and building nothing (a copy of
# the build tree on a machine without the compilers).
# Usage: scripts/fuzz.sh [SECONDS] [HARNESS...]   e.g. scripts/fuzz.sh 1800 container
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift $(($# > 0 ? 1 : 0))

sanitizers="${CONUS_FUZZ_SANITIZERS:-address,undefined}"
build=build-fuzz
suffix=
if [ "$sanitizers" != "address,undefined" ]; then suffix="-${sanitizers//,/-}"; build="build-fuzz$suffix"; fi
harnesses=("$@")
if [ "${CONUS_FUZZ_BUILD:-1}" != 0 ]; then
  # clang and its sanitizer and libFuzzer runtimes: a fast no-op when present.
  scripts/install-packages.sh fuzz clang-14 libclang-rt-14-dev

  launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang-14 \
    -DCMAKE_CXX_COMPILER=clang++-14 -DCONUS_FUZZ=ON -DCONUS_FUZZ_SANITIZERS="$sanitizers" "${launcher[@]}" >/dev/null
  targets=()
  for name in "${harnesses[@]}"; do targets+=(--target "fuzz_$name"); done  # only the harnesses asked for
  cmake --build "$build" --parallel "${CONUS_FUZZ_JOBS:-$(nproc)}" "${targets[@]}"
fi
fork=()
if [ -n "${CONUS_FUZZ_FORK:-}" ]; then fork=(-fork="$CONUS_FUZZ_FORK"); fi

if ((${#harnesses[@]} == 0)); then
  for binary in "$build"/bin/fuzz_*; do harnesses+=("$(basename "$binary" | sed 's/^fuzz_//')"); done
fi
shared=../shared/data
mkdir -p build-fuzz/artifacts
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$PWD/scripts/lsan.supp:print_suppressions=0}"  # third-party leaks only
status=0
summary=()
total=0
for name in "${harnesses[@]}"; do
  mkdir -p "build-fuzz/corpus/$name"
  corpora=("build-fuzz/corpus/$name" "tests/fuzz/corpus/$name")
  for extra in "$shared/exr/damaged" "$shared/hostile"; do [ -d "$extra" ] && corpora+=("$extra"); done
  log="build-fuzz/$name$suffix.log"
  echo "fuzz: $name for ${seconds} s, -fsanitize=$sanitizers (log: $log)"
  set +e
  "$build/bin/fuzz_$name" -max_total_time="$seconds" -dict=tests/fuzz/conus.dict -timeout="${CONUS_FUZZ_TIMEOUT:-30}" -rss_limit_mb=2048 -max_len="${CONUS_FUZZ_MAX_LEN:-16384}" \
    -print_final_stats=1 -runs="${CONUS_FUZZ_RUNS:--1}" "${fork[@]}" -artifact_prefix="build-fuzz/artifacts/$name-" "${corpora[@]}" >"$log" 2>&1
  rc=$?
  set -e
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  if ((${#fork[@]})); then  # fork mode prints no final stats: its last status line counts them all
    last=$(grep -E '^#[0-9]+: cov:' "$log" | tail -1)
    execs=$(sed -n 's/^#\([0-9]*\):.*/\1/p' <<<"$last")
    secs=$(sed -n 's/.* time: \([0-9]*\)s.*/\1/p' <<<"$last")
    rate=$((${execs:-0} / (${secs:-0} > 0 ? ${secs:-1} : 1)))
  fi
  execs=${execs:-0}
  total=$((total + execs))
  if [ "$rc" -ne 0 ]; then
    status=1
    summary+=("$(printf '%-14s %12s execs %8s execs/s  FAILED (rc %d): %s' "$name" "$execs" "${rate:-?}" "$rc" \
      "$(grep -m1 -E 'ERROR|fuzz check failed|runtime error' "$log" || echo "see $log")")")
  else
    summary+=("$(printf '%-14s %12s execs %8s execs/s  ok' "$name" "$execs" "${rate:-?}")")
  fi
done
printf '%s\n' "${summary[@]}"
echo "fuzz: $total executions in all"
exit $status
