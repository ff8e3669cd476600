#!/usr/bin/env python3
"""Regenerates the tables of bench/README.md from a run of the suites.

    bench/make_readme_tables.py [--build DIR] [--repetitions N] [--instructions] [--from-results] SUITE...
    bench/make_readme_tables.py --plan [SUITE...]
    SUITE: codec, oiio, renderers, subdivision, reflections, terrain, end-to-end, viewer, web, quality-defaults,
           quality, or all

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

`web` runs bench/web_bench.py (build/bench-results/web.json): one CoNUS frame against a DZI pyramid
and the browser page's figures.

`all` is one run at one commit: it refuses a tree with changes (commit first, or --allow-modified),
so that every table names the same commit. Each suite's wall time is kept in
build/bench-results/durations.json; `--plan` lists what the suites would run and how long each
took when it last ran here, without running anything.

`subdivision`, `reflections`, `terrain`, `web` and `quality-defaults` write a result file first
(build/bench-results/subdivision.json and reflections.json: renderers_bench's JSON with the run's stamp;
build/bench-results/terrain.json from bench/terrain_gain.py; build/quality/targets.json from
`bench/quality.py --defaults-only`) and make the table from it; `--from-results` makes their tables
from the files of an earlier run without running anything.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import terrain_gain
from run_stamp import run_stamp, stamp_line

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
README = BENCH / "README.md"

# (what, benchmark, baseline, target): the target is the bound on benchmark / baseline, or "".
CODEC = [
    ("Eq. 1 lookup, two-focus 65x65 map (4096 points)", "BM_Distort", "BM_BaselineBilinear", ""),
    ("exact inverse, two-focus map", "BM_Undistort", "BM_BaselineBilinear", ""),
    ("encode 4096² -> 1024², two foci (anisotropic kernel)", "BM_EncodeConus/process_time/real_time",
     "BM_EncodeBaselineAreaDownsample/process_time/real_time", "3x"),
    ("decode 1920x1080 from 2048², zoom on a focus", "BM_DecodeConusView/zoom:1/real_time",
     "BM_DecodeBaselineBilinear/zoom:1/real_time", "1.2x"),
    ("decode, whole frame, pyramid (what `conus decode` takes)", "BM_DecodeConusPyramid/zoom:0/real_time",
     "BM_DecodeBaselineBilinear/zoom:0/real_time", "2x"),
    ("decode, whole frame, multi-tap reference", "BM_DecodeConusView/zoom:0/real_time",
     "BM_DecodeBaselineBilinear/zoom:0/real_time", ""),
    ("build the 2048² image's pyramid (once per image)", "BM_BuildPyramid/real_time",
     "BM_DecodeBaselineBilinear/zoom:0/real_time", ""),
    ("automatic map from 4096² importance, the default (bounded) builder", "BM_AutoMapFlow4096/real_time",
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


def stamp(method):
    return stamp_line(run_stamp(), method)


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
    run([str(BENCH / "quality.py"), "--out", str(out_dir)], env=env)
    report = (out_dir / "quality.md").read_text()
    plots = BENCH / "quality-plots"
    plots.mkdir(exist_ok=True)
    shutil.copy(out_dir / "quality.md", plots / "quality.md")
    for png in ("gain-loss.png", "rate-distortion.png"):
        if (out_dir / png).exists():
            shutil.copy(out_dir / png, plots / png)
    # The report's headlines: each rate, plain and then fitted to the decoder (the section that
    # follows the line starting "Fitted to the decoder").
    headline, fitted = [], False
    for line in report.splitlines():
        fitted = fitted or line.startswith("Fitted to the decoder")
        if line.startswith("- 1/"):
            headline.append(line.replace("- ", "- fitted to the decoder (`--fit 4` against `uniform --fit`), " if fitted else "- ", 1))
    return "\n".join([stamp("quality metrics (deterministic; load does not change them)"), ""] + headline +
                     ["", "The whole report: [quality-plots/quality.md](quality-plots/quality.md)."])


RESULTS = "bench-results"  # under the build folder

# renderers_bench's reflection benchmarks: the two mirrors' quality (deterministic, run once) and
# CoNUS / uniform cost pairs (medians of interleaved repetitions), each with its target.
MIRRORS = [("sphere", "BM_ReflectionSilhouettes/0"), ("plane", "BM_ReflectionSilhouettes/1")]
# The same gains over variants of the scene (a few outline pixels move one scene's figures by tenths).
VARIANTS = "BM_ReflectionSilhouetteVariants"
REFLECTION_COSTS = [
    ("intersection, CPU `codec::intersect` (relief asset)", "BM_IntersectCpu", ""),
    ("intersection, GLSL `renderers::intersectRays` (relief asset)", "BM_IntersectGlsl", ""),
    ("reflection frame, CPU `renderReflectionFrame`", "BM_ReflectionFrame", ""),
    ("reflection frame, GLSL `ReflectionRenderer::draw`", "BM_ReflectionFrameGl", ""),
]
# The same walks timed in interleaved pairs (BM_ReliefPaired/N: the median of per-pair ratios, what
# a loaded machine or a GPU's clocks disturb least): the intersection targets are judged on these.
RELIEF_PAIRS = [
    ("intersection, CPU, 320x240 rays", "BM_ReliefPaired/3", "1.05x"),
    ("intersection, GLSL, 320x240 rays (with upload and readback)", "BM_ReliefPaired/0", "1.05x"),
    ("intersection, GLSL, 1280x960 rays", "BM_ReliefPaired/1", "1.05x"),
    ("relief frame, GLSL, 640x480", "BM_ReliefPaired/2", ""),
]


def run_reflections(build, repetitions):
    """Runs the reflection benchmarks and writes build/bench-results/reflections.json."""
    binary = str(Path(build) / "bin" / "renderers_bench")
    stamp = run_stamp()
    quality = json.loads(run([binary, "--benchmark_filter=^BM_ReflectionSilhouette", "--benchmark_format=json"]))
    costs = "|".join(name for _, name, _ in REFLECTION_COSTS)
    cost = json.loads(run([binary, f"--benchmark_filter=^({costs})/[01](/|$)", f"--benchmark_repetitions={repetitions}",
                           "--benchmark_enable_random_interleaving=true", "--benchmark_report_aggregates_only=true",
                           "--benchmark_format=json"]))
    paired = json.loads(run([binary, "--benchmark_filter=^BM_ReliefPaired/", "--benchmark_format=json"]))
    result = {"stamp": stamp, "repetitions": repetitions, "quality": quality["benchmarks"], "cost": cost["benchmarks"],
              "paired": paired["benchmarks"]}
    path = Path(build) / RESULTS / "reflections.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=1))
    return result


def reflections_table(result):
    quality = {b["run_name"].split("/iterations")[0]: b for b in result["quality"]}
    lines = [stamp_line(result["stamp"], "PSNR against the traced reference (deterministic); cost: wall clock, medians "
                        f"of {result['repetitions']} interleaved repetitions"), "",
             "| mirror | whole mirror: CoNUS / uniform | ROI (box): CoNUS / uniform | rest: CoNUS / uniform | targets |",
             "|---|---|---|---|---|"]
    for mirror, name in MIRRORS:
        b = quality.get(name)
        if b is None:
            lines.append(f"| {mirror} | `{name}` not run | | | |")
            continue
        whole, roi, rest = ((b[f"{part}_conus_dB"], b[f"{part}_uniform_dB"]) for part in ("mirror", "roi", "rest"))
        met = [("mirror >= 30 dB", whole[0] >= 30), ("ROI >= +2 dB", roi[0] - roi[1] >= 2), ("rest >= uniform", rest[0] >= rest[1])]
        lines.append(f"| {mirror} | **{whole[0]:.1f} / {whole[1]:.1f} dB** | **{roi[0]:.1f} / {roi[1]:.1f} dB "
                     f"({roi[0] - roi[1]:+.1f})** | {rest[0]:.1f} / {rest[1]:.1f} dB ({rest[0] - rest[1]:+.1f}) | "
                     + ", ".join(f"{what} ({'met' if ok else '**not met**'})" for what, ok in met) + " |")
    variants = quality.get(VARIANTS)
    if variants is not None:
        lines += ["", f"| mirror | over {variants['variants']:.0f} variants of the scene: ROI, CoNUS - uniform, mean (lowest) "
                      "| rest, CoNUS - uniform, mean (lowest) | targets, on the mean |", "|---|---|---|---|"]
        for mirror, _ in MIRRORS:
            roi, rest = ((variants[f"{mirror}_{part}_gain_mean_dB"], variants[f"{mirror}_{part}_gain_lowest_dB"])
                         for part in ("roi", "rest"))
            met = [("ROI >= +2 dB", roi[0] >= 2), ("rest >= uniform", rest[0] >= 0)]
            lines.append(f"| {mirror} | **{roi[0]:+.1f} dB** ({roi[1]:+.1f}) | **{rest[0]:+.2f} dB** ({rest[1]:+.2f}) | "
                         + ", ".join(f"{what} ({'met' if ok else '**not met**'})" for what, ok in met) + " |")
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
    medians = {b["run_name"].replace("/real_time", ""): b["real_time"] * scale[b["time_unit"]] for b in result["cost"]
               if b.get("aggregate_name") == "median"}
    lines += ["", "| cost | CoNUS (`/1`) | uniform (`/0`, same run) | CoNUS / uniform | target |", "|---|---|---|---|---|"]
    for what, name, target in REFLECTION_COSTS:
        conus, uniform = medians.get(f"{name}/1"), medians.get(f"{name}/0")
        if conus is None or uniform is None:
            lines.append(f"| {what} | `{name}` not run | | | {target} |")
            continue
        ratio = conus / uniform
        mark = (" (met)" if ratio <= float(target.rstrip("x")) else " (**not met**)") if target else ""
        lines.append(f"| {what} | `{name}/1` {fmt_value(conus, False)} | `{name}/0` {fmt_value(uniform, False)} | "
                     f"**{ratio:.3g}x** | {target}{mark} |")
    paired = {b["run_name"].split("/iterations")[0]: b for b in result.get("paired", [])}
    if paired:
        lines += ["", "| cost, in interleaved pairs (same run) | benchmark | CoNUS / uniform, median of pairs (quartiles) "
                      "| target |", "|---|---|---|---|"]
        for what, name, target in RELIEF_PAIRS:
            b = paired.get(name)
            if b is None:
                lines.append(f"| {what} | `{name}` not run | | {target} |")
                continue
            ratio = b["ratio_median"]
            mark = (" (met)" if ratio <= float(target.rstrip("x")) else " (**not met**)") if target else ""
            lines.append(f"| {what} | `{name}` ({b['pairs']:.0f} pairs) | **{ratio:.3g}x** ({b['ratio_q1']:.3g}x-"
                         f"{b['ratio_q3']:.3g}x) | {target}{mark} |")
    return "\n".join(lines)


# The city's CoNUS render (renderers_bench, two tracked foci) as built, split where the map bends
# (the default: the tessellation stages) and everywhere on the CPU (--max-edge 0.5): (label, timed
# benchmark, counter suffix of BM_SubdivisionQuality).
SUBDIVISIONS = [("as built (`--max-bend 0`)", "BM_GpuConus/real_time", "none"),
                ("where the map bends, on the GPU (`--max-bend 0.5`, the default)", "BM_GpuConusBend/real_time", "bend"),
                ("everywhere, on the CPU (`--max-edge 0.5`)", "BM_GpuConusSubdivided/real_time", "edge")]


def run_subdivision(build, repetitions):
    """Times the three renders and scores them; writes build/bench-results/subdivision.json."""
    binary = str(Path(build) / "bin" / "renderers_bench")
    stamp = run_stamp()
    quality = json.loads(run([binary, "--benchmark_filter=^BM_SubdivisionQuality", "--benchmark_format=json"]))
    times = wall_medians(binary, [name for _, name, _ in SUBDIVISIONS], repetitions)
    paired = json.loads(run([binary, "--benchmark_filter=^BM_GpuBendOverAsBuiltPaired", "--benchmark_format=json"]))
    result = {"stamp": stamp, "repetitions": repetitions, "quality": quality["benchmarks"][0], "times": times,
              "paired": paired["benchmarks"][0]}
    path = Path(build) / RESULTS / "subdivision.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=1))
    return result


def subdivision_table(result):
    q, times = result["quality"], result["times"]
    base = {"triangles": q["triangles_none"], "time": times["BM_GpuConus/real_time"]}
    old = {"triangles": q["triangles_edge"], "time": times["BM_GpuConusSubdivided/real_time"]}
    lines = [stamp_line(result["stamp"], "triangles and PSNR (RGB) against the Embree reference (deterministic); frame "
                        f"time: wall clock, medians of {result['repetitions']} interleaved repetitions"), "",
             "| the city's CoNUS render, split | triangles uploaded (/ as built) | triangles drawn (/ everywhere) | "
             "frame time (/ as built, / everywhere) | PSNR against Embree | targets |", "|---|---|---|---|---|---|"]
    for label, name, key in SUBDIVISIONS:
        drawn, ms, psnr = q[f"triangles_{key}"], times[name], q[f"psnr_{key}"]
        uploaded = base["triangles"] if key == "bend" else drawn
        cells = [f"{uploaded:,.0f} ({uploaded / base['triangles']:.3g}x)",
                 f"{drawn:,.0f} ({drawn / old['triangles']:.3g}x)",
                 f"`{name.split('/')[0]}` {fmt_value(ms, False)} ({ms / base['time']:.3g}x, {ms / old['time']:.3g}x)",
                 f"**{psnr:.2f} dB**"]
        met = ""
        if key == "bend":
            gl = q.get("label", "").split(" (")[0] or "this GL"  # GL_RENDERER, without its version
            checks = [("uploaded <= 1.5x", uploaded / base["triangles"] <= 1.5),
                      (f"time <= 1.5x on {gl}", ms / base["time"] <= 1.5), (">= 40 dB", psnr >= 40)]
            met = ", ".join(f"{what} ({'met' if ok else '**not met**'})" for what, ok in checks)
        lines.append(f"| {label} | " + " | ".join(cells) + f" | {met} |")
    pair = result.get("paired")
    if pair:
        lines += ["", f"Paired (`BM_GpuBendOverAsBuiltPaired`, {pair['pairs']:.0f} interleaved pairs in the same run): "
                      f"the default frame takes **{pair['ratio_median']:.3g}x** the as-built one "
                      f"(quartiles {pair['ratio_q1']:.3g}x-{pair['ratio_q3']:.3g}x)."]
    return "\n".join(lines)


def run_quality_defaults(build):
    """Runs `bench/quality.py --defaults-only` (it writes build/quality/targets.json and the contact
    sheets); copies the 600 px wide sheet to bench/quality-plots/."""
    out_dir = Path(build) / "quality"
    env = dict(os.environ, PYTHONPATH=str(Path(build).resolve() / "python"))
    run([str(BENCH / "quality.py"), "--defaults-only", "--out", str(out_dir)], env=env)
    shutil.copy(out_dir / "contact-sheet-600.png", BENCH / "quality-plots" / "contact-sheet-defaults.png")
    return json.loads((out_dir / "targets.json").read_text())


# Targets of the defaults, per method of quality_targets.py: (mean ROI gain, worst ROI, frame loss
# on every photo, tile loss p95 on every photo); with no focus: (mean frame gain, tiles).
DEFAULT_TARGETS = {"foci": (7.0, 2.0, 2.0, 4.0), "importance": (8.0, 2.0, 2.0, 4.0)}
NO_FOCUS_TARGETS = (1.5, 3.0)
METHOD_LABELS = {"foci": "`--focus u,v,r,4` per region", "importance": "`--importance roi.png`",
                 "no focus": "nothing (the picture's own detail)", "detail": "`--importance detail`"}


def quality_defaults_table(result):
    results = result["results"]
    lines = [stamp_line(result["stamp"], f"`bench/quality.py --defaults-only` ({result['seconds'] / 60:.0f} min), "
                        f"{len(results)} photographs, 8-bit sRGB; against `conus uniform` and, in brackets, against "
                        "`uniform --fit` (deterministic)"), "",
             "| with the defaults | mean ROI gain (worst ROI) | whole-frame loss, mean (worst photo) "
             "| tile loss p95, worst photo | targets |", "|---|---|---|---|---|"]
    for method in next(iter(results.values())):
        rows = [r[method] for r in results.values() if "refused" not in r[method]]
        refused = len(results) - len(rows)
        label = METHOD_LABELS.get(method, method) + (f" (refused on {refused})" if refused else "")
        if not rows:
            lines.append(f"| {label} | | | | |")
            continue
        fit = [r["vs_fit"] for r in rows]
        mean = lambda rs, k: sum(r[k] for r in rs) / len(rs)
        gain, worst = mean(rows, "roi_gain"), min(r["worst_roi"] for r in rows)
        loss, loss_worst = mean(rows, "frame_loss"), max(r["frame_loss"] for r in rows)
        tiles = max(r["tile95"] for r in rows)
        frame = (f"{loss:+.2f} dB ({loss_worst:+.2f}) [{mean(fit, 'frame_loss'):+.2f} "
                 f"({max(r['frame_loss'] for r in fit):+.2f})]")
        tile_cell = f"{tiles:.2f} dB [{max(r['tile95'] for r in fit):.2f}]"
        if method in DEFAULT_TARGETS:
            g, w, l, tl = DEFAULT_TARGETS[method]
            met = [(f"ROI >= +{g:g}", gain >= g), (f"no ROI < +{w:g}", worst >= w), (f"loss <= {l:g}", loss_worst <= l),
                   (f"tiles <= {tl:g}", tiles <= tl)]
            roi = f"{gain:+.2f} dB ({worst:+.2f}) [{mean(fit, 'roi_gain'):+.2f}]"
        else:
            g, tl = NO_FOCUS_TARGETS
            met = [(f"gain >= +{g:g}", -loss >= g), (f"tiles <= {tl:g}", tiles <= tl)]
            roi = ""
        lines.append(f"| {label} | {roi} | {frame} | {tile_cell} | "
                     + ", ".join(f"{what} ({'met' if ok else '**not met**'})" for what, ok in met) + " |")
    lines += ["", "The rows per photograph: build/quality/targets.md; the contact sheet (source | default encode | "
              "uniform): [quality-plots/contact-sheet-defaults.png](quality-plots/contact-sheet-defaults.png)."]
    return "\n".join(lines)


def run_web(build):
    """Runs bench/web_bench.py, which writes build/bench-results/web.json."""
    saved = Path(build) / RESULTS / "web.json"
    run([sys.executable, str(BENCH / "web_bench.py"), "--bin", str(Path(build) / "bin"), "--out", str(saved)])
    result = json.loads(saved.read_text())
    result["stamp"] = run_stamp()
    saved.write_text(json.dumps(result, indent=1))
    return result


def rate_rows(gl, rates):
    """The drag's and the zoom's frames a second: shown (one an animation frame, what a user sees;
    the target's measure) and drawn (each frame waited for). An older web.json has one number."""
    if not isinstance(rates, dict):
        return [f"| pan/zoom at 1280x720, {gl} | {rates:.1f} frames/s | | | ≥ 30 frames/s "
                f"({'met' if rates >= 30 else '**not met**'}) |"]
    rows = []
    for kind, name in (("pan", "a drag"), ("zoom", "a zoom")):
        shown = rates[f"shown_{kind}"]
        rows.append(f"| {name} at 1280x720, {gl} | {shown:.1f} frames/s shown ({rates[kind]:.1f} drawn) | | | "
                    f"≥ 30 frames/s ({'met' if shown >= 30 else '**not met**'}) |")
    return rows


def web_table(result):
    c, d, dwaa = result["conus"], result["dzi"], result["conus_dwaa"]
    roi = result["roi_pixels"]
    # A result web_bench.py wrote by itself has no stamp: its own date and load, the commit unknown.
    stamp = result.get("stamp") or {"date": result["date"], "commit": "unknown",
                                     "machine": f"{result['cores']} cores, load {result['load']:.1f}"}
    lines = [stamp_line(stamp, "`bench/web_bench.py`, one run; headless Chromium"), "",
             "| measure | CoNUS | baseline (same run) | ratio | target |", "|---|---|---|---|---|",
             f"| whole frame 1024² + {roi}² region at full detail | 1 request, {c['bytes'] / 1024:.0f} KiB "
             f"({c['whole_db']:.1f} / {c['roi_db']:.1f} dB) | DZI Q {d['quality']}: {d['requests']} requests, "
             f"{d['bytes'] / 1024:.0f} KiB ({d['whole_db']:.1f} / {d['roi_db']:.1f} dB) | "
             f"{c['bytes'] / d['bytes']:.2f}x the bytes, 1/{d['requests']} the requests | |",
             f"| the same, CoNUS stored dwaa (not read by the page) | 1 request, {dwaa['bytes'] / 1024:.0f} KiB "
             f"({dwaa['whole_db']:.1f} / {dwaa['roi_db']:.1f} dB) | DZI Q {d['quality']} as above | "
             f"{dwaa['bytes'] / d['bytes']:.2f}x the bytes | |"]
    for gl, b in result["browser"].items():
        lines += [f"| first frame, 2048² CoNUS file at 1280x720, {gl} | {b['first_frame_ms']:.0f} ms | | | ≤ 1000 ms "
                  f"({'met' if b['first_frame_ms'] <= 1000 else '**not met**'}) |",
                  f"| first frame from `conus serve`, {gl} | {b['remote_first_frame_ms']:.0f} ms | | | |",
                  *rate_rows(gl, b["pan_zoom_fps"]),
                  f"| `conus serve`: 1024² frame of the 4096² picture, new focus ({gl} run) | {b['serve_frame_s']:.2f} s | | | "
                  f"≤ 0.5 s ({'met' if b['serve_frame_s'] <= 0.5 else '**not met**'}) |"]
    return "\n".join(lines)


# What each suite runs, for --plan.
PLAN = {"codec": "build/bin/codec_bench (wall medians; --instructions: callgrind)",
        "oiio": "build/bin/oiio_baseline_bench", "renderers": "build/bin/renderers_bench",
        "subdivision": "build/bin/renderers_bench: BM_SubdivisionQuality, BM_GpuBendOverAsBuiltPaired",
        "reflections": "build/bin/renderers_bench: BM_ReflectionSilhouette, its costs, BM_ReliefPaired",
        "terrain": "bench/terrain_gain.py",
        "end-to-end": "bench/end_to_end.sh", "viewer": "conus encode + conus-view --benchmark-frames under Xvfb",
        "web": "bench/web_bench.py (vips, Chromium)", "quality-defaults": "bench/quality.py --defaults-only",
        "quality": "bench/quality.py"}


def durations_path(build):
    return Path(build) / RESULTS / "durations.json"


def print_plan(build, suites):
    path = durations_path(build)
    known = json.loads(path.read_text()) if path.exists() else {}
    total, untimed = 0.0, []
    for suite in suites:
        last = known.get(suite)
        when = (f"{last['seconds'] / 60:.1f} min when it last ran ({last['stamp']['date']}, {last['stamp']['machine']})"
                if last else "not timed here yet")
        print(f"{suite:17} {PLAN[suite]}: {when}")
        if last:
            total += last["seconds"]
        else:
            untimed.append(suite)
    print(f"total: {total / 60:.0f} min" + (f" plus {', '.join(untimed)} (not timed)" if untimed else ""))


def record_duration(build, suite, seconds):
    path = durations_path(build)
    path.parent.mkdir(parents=True, exist_ok=True)
    known = json.loads(path.read_text()) if path.exists() else {}
    known[suite] = {"seconds": seconds, "stamp": run_stamp()}
    path.write_text(json.dumps(known, indent=1))


def replace_block(text, suite, body):
    pattern = re.compile(rf"(<!-- table:{re.escape(suite)} -->\n).*?(<!-- /table -->)", re.S)
    if not pattern.search(text):
        sys.exit(f"make_readme_tables.py: bench/README.md has no block <!-- table:{suite} -->")
    return pattern.sub(lambda m: m.group(1) + body + "\n" + m.group(2), text, count=1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    names = [*SUITES, "subdivision", "reflections", "terrain", "end-to-end", "viewer", "web", "quality-defaults", "quality"]
    parser.add_argument("suites", nargs="*", metavar="SUITE", help=", ".join([*names, "all"]))
    parser.add_argument("--plan", action="store_true", help="say what the suites run and how long each last took; run nothing")
    parser.add_argument("--allow-modified", action="store_true", help="all: run on a tree with uncommitted changes")
    parser.add_argument("--build", default=str(ROOT / "build"))
    parser.add_argument("--repetitions", type=int, default=7)
    parser.add_argument("--instructions", action="store_true", help="callgrind instruction counts (codec only)")
    parser.add_argument("--from-results", action="store_true",
                        help="subdivision, reflections, terrain, web, quality-defaults: the tables from the result files of an "
                        "earlier run")
    args = parser.parse_args()
    suites = names if "all" in args.suites or (args.plan and not args.suites) else args.suites
    if not suites or set(suites) - {*names, "all"}:
        parser.error(f"name suites among {', '.join(names)}, or all")
    if args.plan:
        print_plan(args.build, suites)
        return
    if "all" in args.suites and not args.allow_modified and "(modified)" in run_stamp()["commit"]:
        sys.exit("make_readme_tables.py: all: the tree has uncommitted changes; commit them first, so that every table "
                 "names one commit (or --allow-modified)")
    if args.instructions and set(suites) - {"codec"}:
        sys.exit("make_readme_tables.py: --instructions counts codec_bench only (valgrind stops at llvmpipe and libhwy)")
    if args.from_results and set(suites) - {"subdivision", "reflections", "terrain", "web", "quality-defaults"}:
        sys.exit("make_readme_tables.py: --from-results remakes the subdivision, reflections, terrain, web and "
                 "quality-defaults tables only")
    text = README.read_text()
    for suite in suites:
        started = time.monotonic()
        if suite in SUITES:
            body = benchmark_table(args.build, suite, args.repetitions, args.instructions)
        elif suite == "subdivision":
            saved = Path(args.build) / RESULTS / "subdivision.json"
            body = subdivision_table(json.loads(saved.read_text()) if args.from_results
                                     else run_subdivision(args.build, min(args.repetitions, 5)))
        elif suite == "reflections":
            saved = Path(args.build) / RESULTS / "reflections.json"
            body = reflections_table(json.loads(saved.read_text()) if args.from_results
                                     else run_reflections(args.build, min(args.repetitions, 5)))
        elif suite == "terrain":
            saved = Path(args.build) / RESULTS / "terrain.json"
            if not args.from_results:
                run([sys.executable, str(BENCH / "terrain_gain.py"), "--conus", str(Path(args.build) / "bin" / "conus"),
                     "--out", str(saved.parent)])
                shutil.copy(saved.parent / "terrain-7-terrain-viewer.png", BENCH / "img" / "terrain-compare.png")
            body = terrain_gain.table(json.loads(saved.read_text()))
        elif suite == "end-to-end":
            body = end_to_end_table(args.build, min(args.repetitions, 5))
        elif suite == "viewer":
            body = viewer_table(args.build)
        elif suite == "web":
            saved = Path(args.build) / RESULTS / "web.json"
            body = web_table(json.loads(saved.read_text()) if args.from_results else run_web(args.build))
        elif suite == "quality-defaults":
            saved = Path(args.build) / "quality" / "targets.json"
            body = quality_defaults_table(json.loads(saved.read_text()) if args.from_results
                                          else run_quality_defaults(args.build))
        else:
            body = quality_table(args.build)
        text = replace_block(text, suite, body)
        README.write_text(text)  # after each suite, so a later failure keeps the tables already made
        if not args.from_results:
            record_duration(args.build, suite, time.monotonic() - started)
    print(f"bench/README.md: {', '.join(suites)} rewritten")


if __name__ == "__main__":
    main()
