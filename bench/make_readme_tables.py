#!/usr/bin/env python3
"""Regenerates the tables of bench/README.md from a run of the suites.

    bench/make_readme_tables.py [--build DIR] [--repetitions N] [--instructions] SUITE...
    SUITE: codec, oiio, renderers, end-to-end, viewer, quality, or all

Each suite's table sits between `<!-- table:SUITE -->` and `<!-- /table -->` in bench/README.md;
this script rewrites that block only, stamped with the date, the commit, the machine and the
method. Every row is a benchmark beside the baseline measured in the same run, so the ratio is
the figure to read; absolute times are indicative on a shared machine.

Methods: wall clock (the default: medians of N interleaved repetitions of Google Benchmark's
real time), or `--instructions` (codec only: instructions per iteration under callgrind through
bench/callgrind_loops.sh, the same on a loaded machine as on an idle one). `end-to-end` runs
bench/end_to_end.sh and keeps its table; `viewer` times conus-view under Xvfb on a 2048² CoNUS
image of a photograph, both decode paths; `quality` runs bench/quality.py, keeps the headline of
its report and copies the report and its plots to bench/quality-plots/.
"""
import argparse
import datetime
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
README = BENCH / "README.md"

# (what, benchmark, baseline, target): the target is the bound on benchmark / baseline, or "".
CODEC = [
    ("Eq. 1 lookup, two-focus 65x65 map (4096 points)", "BM_Distort", "BM_BaselineBilinear", ""),
    ("exact inverse, two-focus map", "BM_Undistort", "BM_BaselineBilinear", ""),
    ("encode 4096² -> 1024², two foci (EWA footprint filter)", "BM_EncodeConus/real_time",
     "BM_EncodeBaselineAreaDownsample/real_time", ""),
    ("decode 1920x1080 from 2048², zoom on a focus", "BM_DecodeConusView/zoom:1/real_time",
     "BM_DecodeBaselineBilinear/zoom:1/real_time", "1.2x"),
    ("decode, whole frame, pyramid (what `conus decode` takes)", "BM_DecodeConusPyramid/zoom:0/real_time",
     "BM_DecodeBaselineBilinear/zoom:0/real_time", "2x"),
    ("decode, whole frame, multi-tap reference", "BM_DecodeConusView/zoom:0/real_time",
     "BM_DecodeBaselineBilinear/zoom:0/real_time", ""),
    ("build the 2048² image's pyramid (once per image)", "BM_BuildPyramid/real_time",
     "BM_DecodeBaselineBilinear/zoom:0/real_time", ""),
    ("automatic map from 4096² importance, flow", "BM_AutoMapFlow4096/real_time",
     "BM_AutoMapSeparable4096/real_time", ""),
    ("mass-spring 256², one step", "BM_SpringStep256", "BM_SpringBaselinePass256", ""),
    ("mass-spring 256², 3 strokes to the stable state", "BM_SpringTimeToStable256/1",
     "BM_SpringTimeToStable256/0", "1x"),
    ("per-frame map, 8 foci, closed form", "BM_FrameFociClosedForm/8", "BM_FrameFociDensityGridAdd/8", "1x"),
    ("Embree reference, CoNUS FPC, the city 480x320", "BM_MeshReferenceConus", "BM_MeshReferenceUniform", ""),
]
OIIO = [
    ("OpenImageIO resize, 1920x1080 from 2048², whole frame", "BM_DecodeBaselineOiio/zoom:0/real_time",
     "BM_DecodeBaselineBilinear/zoom:0/real_time", ""),
    ("OpenImageIO resize, zoom on a focus", "BM_DecodeBaselineOiio/zoom:1/real_time",
     "BM_DecodeBaselineBilinear/zoom:1/real_time", ""),
]
RENDERERS = [
    ("encode 4096² -> 1024², GPU", "BM_EncodeGpu/real_time", "BM_EncodeCpu/real_time", ""),
    ("decode 1920x1080 of 2048², GPU", "BM_DecodeGpu/real_time", "BM_DecodeCpu/real_time", ""),
    ("height field: server encode", "BM_EncodeConus/real_time", "BM_EncodeUniform/real_time", ""),
    ("height field: client undistort to a mesh", "BM_UndistortConus/real_time", "BM_UndistortUniform/real_time", ""),
    ("height field: client frame", "BM_RenderConus/real_time", "BM_RenderUniform/real_time", ""),
    ("mesh: CoNUS render, two tracked foci", "BM_GpuConus/real_time", "BM_GpuConventional/real_time", "1.02x"),
    ("mesh: CoNUS render subdivided for --max-edge 0.5", "BM_GpuConusSubdivided/real_time",
     "BM_GpuConventional/real_time", ""),
    ("volume: CoNUS ray casting, GPU", "BM_VolumeGpuConus/real_time", "BM_VolumeGpuConventional/real_time", ""),
    ("volume: CoNUS ray casting, CPU", "BM_VolumeCpuConus/real_time", "BM_VolumeCpuConventional/real_time", ""),
]
SUITES = {"codec": ("codec_bench", CODEC), "oiio": ("oiio_baseline_bench", OIIO),
          "renderers": ("renderers_bench", RENDERERS)}


def run(cmd, **kw):
    print("+", " ".join(map(str, cmd)), file=sys.stderr)
    result = subprocess.run(cmd, text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kw)
    sys.stderr.write(result.stderr)
    if result.returncode != 0:
        raise subprocess.CalledProcessError(result.returncode, cmd, result.stdout, result.stderr)
    return result.stdout


def machine():
    cpu = platform.processor() or platform.machine()
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    load = os.getloadavg()[0]
    return f"{cpu}, {os.cpu_count()} cores, load {load:.1f}"


def stamp(method):
    commit = run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"]).strip()
    # The tables and plots this script writes do not count as a modified tree.
    dirty = run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no", "--", ".",
                 ":!bench/README.md", ":!bench/quality-plots"]).strip()
    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return f"{when}, commit {commit}{' (modified)' if dirty else ''}, {machine()}; {method}."


def wall_medians(binary, names, repetitions):
    regex = "^(" + "|".join(re.escape(n) for n in names) + ")$"
    out = run([binary, f"--benchmark_filter={regex}", f"--benchmark_repetitions={repetitions}",
               "--benchmark_enable_random_interleaving=true", "--benchmark_report_aggregates_only=true",
               "--benchmark_format=json"])
    medians = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") == "median":
            scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
            medians[b["run_name"]] = b["real_time"] * scale
    return medians


def instructions(binary, names):
    out = run([str(BENCH / "callgrind_loops.sh"), binary, *names])
    counts = {}
    for line in out.splitlines()[1:]:
        name, per_iter, _ = line.split()
        counts[name] = float(per_iter)
    return counts


def fmt_value(v, instr):
    if instr:
        return f"{v / 1e6:.1f} M" if v >= 1e5 else f"{v:,.0f}"
    if v >= 1000:
        return f"{v / 1e3:.3g} s"
    return f"{v:.3g} ms" if v >= 0.01 else f"{v * 1e3:.3g} us"


def benchmark_table(build, suite, repetitions, instr):
    binary, rows = SUITES[suite]
    path = str(Path(build) / "bin" / binary)
    # One process per baseline and the benchmarks read against it (interleaved with it), so that a
    # benchmark that fails costs its own rows only.
    groups = {}
    for _, name, base, _ in rows:
        groups.setdefault(base, {base}).add(name)
    values, failed = {}, {}
    for names in groups.values():
        try:
            values.update(instructions(path, sorted(names)) if instr else wall_medians(path, sorted(names), repetitions))
        except subprocess.CalledProcessError as e:
            reason = ((e.stderr or "").strip().splitlines() or [f"exit {e.returncode}"])[-1]
            failed.update({n: reason for n in names})
    if instr:
        method = "instructions per iteration (callgrind, bench/callgrind_loops.sh)"
    else:
        method = f"wall clock, medians of {repetitions} interleaved repetitions"
    lines = [stamp(method), "",
             "| what | benchmark | baseline (same run) | benchmark / baseline | target |", "|---|---|---|---|---|"]
    for what, name, base, target in rows:
        if name not in values or base not in values:
            reason = failed.get(name) or failed.get(base) or "not run"
            lines.append(f"| {what} | `{name}`: failed ({reason[:120]}) | `{base}` | | {target} |")
            continue
        ratio = values[name] / values[base]
        mark = ""
        if target:
            mark = " (met)" if ratio <= float(target.rstrip("x")) else " (**not met**)"
        lines.append(f"| {what} | `{name}` {fmt_value(values[name], instr)} | `{base}` "
                     f"{fmt_value(values[base], instr)} | **{ratio:.3g}x** | {target}{mark} |")
    return "\n".join(lines)


def end_to_end_table(build, repetitions):
    out = run([str(BENCH / "end_to_end.sh"), build, str(repetitions)])
    table = [l for l in out.splitlines() if l.startswith("|")]
    threads = [l for l in out.splitlines() if l.startswith("threads")]
    return "\n".join([stamp(f"CPU seconds (user + sys), medians of {repetitions} runs of /usr/bin/time"), ""] +
                     table + [""] + threads)


PHOTO = "/usr/lib/python3/dist-packages/skimage/data/astronaut.png"  # Debian python3-skimage


def viewer_table(build, frames=20):
    bin_dir = Path(build) / "bin"
    with tempfile.TemporaryDirectory() as work:
        big, exr = f"{work}/photo4096.png", f"{work}/big.exr"
        run(["oiiotool", PHOTO, "--resize", "4096x4096", "-d", "uint8", "-o", big])
        run([str(bin_dir / "conus"), "encode", big, "-o", exr, "--size", "2048x2048", "--focus", "0.5,0.4,0.1,3", "-q"])
        rates = {}
        for decode in ("gpu", "cpu"):
            out = run(["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", str(bin_dir / "conus-view"), exr,
                       "--benchmark-frames", str(frames), "--window", "1920x1080", "--decode", decode])
            rates[decode] = float(re.findall(r"([0-9.]+) frames/s", out)[-1])
    return "\n".join([stamp(f"wall clock, {frames} frames under Xvfb"), "",
                      "| view | `--decode gpu` (Eq. 1 shader) | `--decode cpu` (decode + upload) | gpu / cpu | target |",
                      "|---|---|---|---|---|",
                      f"| fitted 1920x1080 of a 2048² image | {rates['gpu']:.1f} frames/s | {rates['cpu']:.1f} frames/s | "
                      f"{rates['gpu'] / rates['cpu']:.2f}x | 30 frames/s{' (met)' if max(rates.values()) >= 30 else ' (**not met**)'} |"])


def quality_table(build):
    out_dir = Path(build) / "quality"
    env = dict(os.environ, PYTHONPATH=str(Path(build).resolve() / "python"))
    run([sys.executable, str(BENCH / "quality.py"), "--out", str(out_dir)], env=env)
    report = (out_dir / "quality.md").read_text()
    plots = BENCH / "quality-plots"
    plots.mkdir(exist_ok=True)
    shutil.copy(out_dir / "quality.md", plots / "quality.md")
    for png in ("gain-loss.png", "rate-distortion.png"):
        if (out_dir / png).exists():
            shutil.copy(out_dir / png, plots / png)
    headline = [l for l in report.splitlines() if l.startswith("- 1/")]
    return "\n".join([stamp("quality metrics (deterministic; load does not change them)"), ""] + headline +
                     ["", "The whole report: [quality-plots/quality.md](quality-plots/quality.md)."])


def replace_block(text, suite, body):
    pattern = re.compile(rf"(<!-- table:{re.escape(suite)} -->\n).*?(<!-- /table -->)", re.S)
    if not pattern.search(text):
        sys.exit(f"make_readme_tables.py: bench/README.md has no block <!-- table:{suite} -->")
    return pattern.sub(lambda m: m.group(1) + body + "\n" + m.group(2), text, count=1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("suites", nargs="+", choices=[*SUITES, "end-to-end", "viewer", "quality", "all"])
    parser.add_argument("--build", default=str(ROOT / "build"))
    parser.add_argument("--repetitions", type=int, default=7)
    parser.add_argument("--instructions", action="store_true", help="callgrind instruction counts (codec only)")
    args = parser.parse_args()
    suites = [*SUITES, "end-to-end", "viewer", "quality"] if "all" in args.suites else args.suites
    if args.instructions and set(suites) - {"codec"}:
        sys.exit("make_readme_tables.py: --instructions counts codec_bench only (valgrind stops at llvmpipe and libhwy)")
    text = README.read_text()
    for suite in suites:
        if suite in SUITES:
            body = benchmark_table(args.build, suite, args.repetitions, args.instructions)
        elif suite == "end-to-end":
            body = end_to_end_table(args.build, min(args.repetitions, 5))
        elif suite == "viewer":
            body = viewer_table(args.build)
        else:
            body = quality_table(args.build)
        text = replace_block(text, suite, body)
        README.write_text(text)  # after each suite, so a later failure keeps the tables already made
    print(f"bench/README.md: {', '.join(suites)} rewritten")


if __name__ == "__main__":
    main()
