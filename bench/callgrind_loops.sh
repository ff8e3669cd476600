#!/bin/bash
# Instructions per iteration of Google Benchmark loops, by callgrind: the figure to compare two
# builds on a shared machine, where wall clocks are noise (bench/README.md, "Comparing two builds").
#   bench/callgrind_loops.sh BINARY NAME...      NAME: a benchmark's full name, e.g. BM_Distort or
#                                                BM_DecodeConusView/zoom:0/real_time
# Each benchmark runs alone under callgrind, 3 repetitions of one iteration each; a profile is
# dumped at the start and the end of each timed loop (State::StartKeepRunning / FinishKeepRunning),
# so it holds the loop alone, every thread included. The first repetition is left out (static
# images, lazy indices, symbol binding); the two others must agree.
set -euo pipefail
bin=$1
shift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
printf '%-45s %15s %15s\n' benchmark "instr/iter" "rep 2 vs 3"
for name in "$@"; do
    valgrind --tool=callgrind --callgrind-out-file="$work/cg" \
        --dump-after='*StartKeepRunning*' --dump-before='*FinishKeepRunning*' \
        "$bin" --benchmark_filter="^${name}\$" --benchmark_repetitions=3 --benchmark_min_time=0 \
        --benchmark_format=json >"$work/json" 2>"$work/log" || { echo "$name: failed (see valgrind's log)" >&2; cat "$work/log" >&2; exit 1; }
    python3 - "$work" "$name" <<'PY'
import glob, json, sys
work, name = sys.argv[1], sys.argv[2]
text = open(work + "/json").read()
runs = [b for b in json.loads(text)["benchmarks"] if b.get("run_type") == "iteration"] if text.strip() else []
if not runs:
    sys.exit(f"{name}: no such benchmark")
loops = []
for f in sorted(glob.glob(work + "/cg.*"), key=lambda f: int(f.rsplit(".", 1)[1])):
    trigger = total = None
    for line in open(f):
        if line.startswith("desc: Trigger:"):
            trigger = line
        elif line.startswith(("summary:", "totals:")):
            total = int(line.split()[1])
    if trigger and "FinishKeepRunning" in trigger:
        loops.append(total)
if len(loops) < 3:
    sys.exit(f"{name}: {len(loops)} timed loops seen, expected 3")
per = [x / runs[-1]["iterations"] for x in loops[-2:]]
print(f"{name:45s} {per[-1]:15.0f} {per[0] / per[1]:15.5f}")
PY
    rm -f "$work"/cg*
done
