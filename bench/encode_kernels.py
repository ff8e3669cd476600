#!/usr/bin/python3
"""The encode's filters and fits side by side on the photographs of bench/quality.py, through the
real binary: `bench/encode_kernels.py [build-dir] [--photos a,b] [--out DIR]`.

Each photograph is reduced to at most quality_targets.MAX_WIDTH px wide (oiiotool, 8-bit sRGB PNG)
and encoded at 1/16 of its pixels with one `--focus u,v,r,4` per region of quality_targets.py,
`--exact-k` (the budget's choice of k would otherwise differ from variant to variant and hide the
kernel's own effect), under each variant below; each file is decoded by `conus decode` to the
source's size as an 8-bit sRGB PNG and compared with the source: PSNR over the whole frame and
inside the regions, and the encode's own stage times (its stage lines). The table gives each
variant against the first (the EWA filter with the least-squares fit: the encode before the
anisotropic kernel and the local fit).
"""
import argparse
import pathlib
import re
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from quality_targets import ALL_PHOTOS, MAX_WIDTH, discs, psnr8, read_png  # noqa: E402

VARIANTS = [
    ("ewa + least-squares fit", ["--filter", "ewa", "--fit-method", "least-squares"]),
    ("anisotropic + least-squares fit (defaults)", []),
    ("ewa + local fit", ["--filter", "ewa", "--fit-method", "local"]),
    ("anisotropic + local fit", ["--fit-method", "local"]),
    ("ewa --fast", ["--filter", "ewa", "--fast"]),
    ("anisotropic --fast", ["--fast"]),
]
STAGE = re.compile(r"^conus encode: (\w+)[^\r\n]*? done \(([0-9.]+) s\)", re.M)


def run(args):
    r = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, args))}: {r.stderr.strip()}")
    return r.stderr.replace("\r", "\n")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("build", nargs="?", default="build")
    parser.add_argument("--photos", default="")
    parser.add_argument("--out", default="")
    parser.add_argument("--no-local", action="store_true", help="leave the local fit's rows out (a shorter run)")
    a = parser.parse_args()
    variants = [v for v in VARIANTS if not (a.no_local and "local" in v[0])]
    conus = pathlib.Path(a.build) / "bin" / "conus"
    photos = [p for p in ALL_PHOTOS if not a.photos or p[0] in a.photos.split(",")]
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        for name, path, regions in photos:
            src = work / f"{name}.png"
            run(["oiiotool", path, "--ch", "R,G,B", "--resize:filter=box", f"{MAX_WIDTH}x0", "-d", "uint8", "-o", src])
            source8 = read_png(src)
            h, w = source8.shape[:2]
            roi = discs(source8.shape, regions) > 0
            foci = [x for u, v, r in regions for x in ("--focus", f"{u},{v},{r},4")]
            for label, extra in variants:
                said = run([conus, "encode", src, "-o", work / "c.exr", "--exact-k", *foci, *extra])
                stages = {m.group(1): float(m.group(2)) for m in STAGE.finditer(said)}
                run([conus, "decode", work / "c.exr", "-o", work / "v.png", "--size", f"{w}x{h}", "-q"])
                view8 = read_png(work / "v.png")[..., :3]
                rows.setdefault(name, {})[label] = (psnr8(view8, source8), psnr8(view8, source8, roi),
                                                    stages.get("encode", 0.0), stages.get("fit", 0.0))
            base = rows[name][VARIANTS[0][0]]
            print(name, " ".join(f"[{lb}: {r[0] - base[0]:+.3f} / {r[1] - base[1]:+.3f} dB]" for lb, r in rows[name].items()),
                  flush=True)
    lines = [f"| variant | whole frame dB vs `{VARIANTS[0][0]}`: mean (worst) | ROI dB: mean (worst) | encode s | fit s |",
             "|---|---|---|---|---|"]
    for label, _ in variants:
        d = np.array([[rows[n][label][0] - rows[n][VARIANTS[0][0]][0], rows[n][label][1] - rows[n][VARIANTS[0][0]][1]]
                      for n in rows])
        t = np.array([rows[n][label][2:] for n in rows]).sum(axis=0)
        lines.append(f"| {label} | {d[:, 0].mean():+.3f} ({d[:, 0].min():+.3f}) | {d[:, 1].mean():+.3f} ({d[:, 1].min():+.3f}) "
                     f"| {t[0]:.2f} | {t[1]:.2f} |")
    lines.append("")
    lines.append("| photo | " + " | ".join(lb for lb, _ in variants) + " |")
    lines.append("|---|" + "---|" * len(variants))
    for n, r in rows.items():
        lines.append(f"| {n} | " + " | ".join(f"{r[lb][0]:.2f} / {r[lb][1]:.2f}" for lb, _ in variants) + " |")
    text = "\n".join(lines) + "\n(whole frame / ROI PSNR, 8-bit sRGB, dB; times summed over the photographs)\n"
    print(text)
    if a.out:
        pathlib.Path(a.out).write_text(text)


if __name__ == "__main__":
    main()
