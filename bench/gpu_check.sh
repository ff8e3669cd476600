#!/usr/bin/env bash
# The GL checks and figures for a machine with a GPU, in one run: the renderers' tests (GL output
# against the CPU reference and analytic expectations), `conus demo` through EGL and through the CPU
# (the same pictures, the same PSNR), `conus encode` and `decode` of the demo's 4096x4096 picture
# timed on each backend, and renderers_bench's GPU / CPU pairs as JSON (medians of interleaved
# repetitions of at least a second each, so that the GPU's clocks have risen and every ratio is read
# off one run on one machine).
# CONUS_GPU_CHECK_ONLY=encode runs only the image encode's checks (a few minutes): the mipmapped GL
# encoder's tests, `conus encode --backend auto|egl|cpu` of the demo's 4096x4096 picture, and the
# 4096^2 -> 1024^2 encode rows from memory, GL beside CPU, with the issue's targets read off them
# (>= 200 encodes a second and >= 5x the CPU) in encode_summary.txt.
# Usage: bench/gpu_check.sh BIN_DIR OUT_DIR [REPETITIONS]
#   BIN_DIR holds renderers_tests, renderers_bench and conus (build/bin); OUT_DIR receives
#   machine.txt, renderers_tests.txt, cli.txt, demo-egl.png, renderers_bench.json (+ .err) and
#   reflection_quality.json. CONUS_GPU_CHECK_TESTS is a gtest filter for the tests (default all);
#   CONUS_GPU_CHECK_STAGE_SECONDS bounds each stage (default 900); CONUS_GPU_CHECK_MIN_TIME is each
#   benchmark repetition's least time in seconds (default 1).
# Figures from such runs: bench/notes/ (the GPU named in machine.txt).
set -uo pipefail
bin=${1:?usage: bench/gpu_check.sh BIN_DIR OUT_DIR [REPETITIONS]}
out=${2:?usage: bench/gpu_check.sh BIN_DIR OUT_DIR [REPETITIONS]}
repetitions=${3:-5}
limit=${CONUS_GPU_CHECK_STAGE_SECONDS:-900}  # each stage's wall-clock limit
mkdir -p "$out"
status=0

{
  date -u
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null || echo "no nvidia-smi"
  echo "cores: $(nproc)"
} >"$out/machine.txt"
cat "$out/machine.txt"

encode_check() {
  echo "== renderers_tests, the encoders"
  timeout "$limit" "$bin/renderers_tests" --gtest_brief=1 --gtest_filter='GpuEncodeMip*:EncodeDevice*:Backends/GpuImage.Encode*' \
    >"$out/renderers_tests_encode.txt" 2>&1 || status=1
  grep -E "dB|probe on|PASSED|FAILED" "$out/renderers_tests_encode.txt" | tail -40
  local demo
  demo=$(mktemp -d)
  timeout "$limit" "$bin/conus" demo --backend cpu --out "$demo/d" >/dev/null 2>&1 || status=1
  for backend in auto egl cpu auto egl cpu; do
    start=$(date +%s%N)
    timeout "$limit" "$bin/conus" encode "$demo/d/source.png" --focus 0.3,0.3,0.1,4 -o "$demo/t-$backend.exr" --backend "$backend" \
      >>"$out/cli_encode.txt" 2>&1 || status=1
    echo "time conus encode --backend $backend: $((($(date +%s%N) - start) / 1000000)) ms" | tee -a "$out/cli_encode.txt"
  done
  grep -oE "encode [0-9]+x[0-9]+ -> [0-9]+x[0-9]+( \([^)]*\))?" "$out/cli_encode.txt" | sort | uniq -c  # which device each took
  rm -rf "$demo"
  echo "== renderers_bench, encode rows ($repetitions repetitions)"
  timeout "$limit" "$bin/renderers_bench" --benchmark_filter='^BM_Encode(Cpu|Gpu|Cpu8Bit|Gpu8Bit/[14]|GpuEwa)/real_time$' \
    --benchmark_repetitions="$repetitions" --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true \
    --benchmark_min_time="${CONUS_GPU_CHECK_MIN_TIME:-1}" --benchmark_format=json >"$out/encode_bench.json" 2>"$out/encode_bench.err" || status=1
  python3 - "$out/encode_bench.json" <<'PY' | tee "$out/encode_summary.txt"
import json, sys
rows = {b["run_name"]: b for b in json.load(open(sys.argv[1]))["benchmarks"] if b.get("aggregate_name") == "median"}
ms = {name.replace("/real_time", ""): b["real_time"] for name, b in rows.items()}
for name, b in rows.items():
    print(f"{name}: {b['real_time']:.1f} ms  {b.get('label', '')}")
for gpu, cpu in (("BM_EncodeGpu8Bit/4", "BM_EncodeCpu8Bit"), ("BM_EncodeGpu8Bit/1", "BM_EncodeCpu8Bit"), ("BM_EncodeGpu", "BM_EncodeCpu")):
    if gpu in ms and cpu in ms:
        rate, speedup = 1000.0 / ms[gpu], ms[cpu] / ms[gpu]
        print(f"{gpu}: {rate:.1f} encodes/s (target >= 200), {speedup:.2f}x {cpu} (target >= 5x):",
              "met" if rate >= 200 and speedup >= 5 else "not met")
PY
}

if [ "${CONUS_GPU_CHECK_ONLY:-}" = encode ]; then
  encode_check
  exit $status
fi

echo "== renderers_tests"
timeout "$limit" "$bin/renderers_tests" --gtest_brief=1 --gtest_filter="${CONUS_GPU_CHECK_TESTS:-*}" >"$out/renderers_tests.txt" 2>&1 || status=1
tail -5 "$out/renderers_tests.txt"

demo=$(mktemp -d)
for backend in egl cpu; do
  echo "== conus demo --backend $backend" | tee -a "$out/cli.txt"
  timeout "$limit" "$bin/conus" demo --backend "$backend" --out "$demo/$backend" >>"$out/cli.txt" 2>&1 || status=1
  tail -4 "$out/cli.txt"
done
cp "$demo/egl/view-frame.png" "$out/demo-egl.png" 2>/dev/null
# The user's commands, wall clock: encode 4096x4096 -> 1024x1024 through a focus, decode a 2048x2048 frame.
for backend in egl cpu egl cpu; do
  for step in encode decode; do
    if [ $step = encode ]; then args=(encode "$demo/egl/source.png" --focus 0.3,0.3,0.1,4 -o "$demo/t-$backend.exr")
    else args=(decode "$demo/t-$backend.exr" --size 2048x2048 -o "$demo/t-$backend.png"); fi
    start=$(date +%s%N)
    timeout "$limit" "$bin/conus" "${args[@]}" --backend "$backend" -q >>"$out/cli.txt" 2>&1 || status=1
    echo "time conus $step --backend $backend: $((($(date +%s%N) - start) / 1000000)) ms" | tee -a "$out/cli.txt"
  done
done
rm -rf "$demo"

# Each GPU figure beside its baseline: conventional beside CoNUS, CPU beside GL.
pairs='BM_(Encode|Decode)(Gpu|Cpu)|BM_Encode(Cpu8Bit|Gpu8Bit/[14]|GpuEwa)|BM_Gpu(Conventional|Conus|ConusSubdivided)|BM_GpuConusOverConventionalPaired/.*'
pairs+='|BM_Volume(Gpu|Cpu)(Conventional|Conus)(Filled)?|BM_VolumeGpuConusOverConventionalPaired/.*'
pairs+='|BM_Intersect(Cpu|Glsl)/[01]|BM_ReflectionFrame(Gl)?/[01]|BM_ReliefFrame/[01]|BM_Render(Conus|Uniform)'
pairs+='|BM_GpuConusBend|BM_ReliefPaired/.*|BM_GpuBendOverAsBuiltPaired.*|BM_SubdivisionQuality.*'
echo "== renderers_bench ($repetitions repetitions)"
timeout "$limit" "$bin/renderers_bench" --benchmark_filter="^($pairs)(/real_time)?\$" --benchmark_repetitions="$repetitions" \
  --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true --benchmark_min_time="${CONUS_GPU_CHECK_MIN_TIME:-1}" \
  --benchmark_format=json >"$out/renderers_bench.json" 2>"$out/renderers_bench.err" || status=1
# The mirrors' quality against the traced reference (deterministic; on this GPU's GL).
timeout "$limit" "$bin/renderers_bench" --benchmark_filter='^BM_ReflectionSilhouettes/' --benchmark_format=json \
  >"$out/reflection_quality.json" 2>>"$out/renderers_bench.err" || status=1
tail -3 "$out/renderers_bench.err"
exit $status
