#!/usr/bin/env python3
"""How much a CoNUS height field gains over a uniform one of the same sample count, and how the
gain falls as the camera leaves the ground map's viewer.

For each procedural seed, `conus heightfield encode` (the default terrain-fitted rows, and
`--rows planar` for the paper's flat ground plane), then `conus render heightfield --compare` from
the map's own viewer and from cameras moved back along the viewing direction, up, and sideways.
Wall clock does not matter here; each row is a PSNR difference (CoNUS - uniform, dB, the frame
against the full-resolution DEM's) measured in the same run. Writes build/bench-results/terrain.json
(stamped as bench/run_stamp.py stamps), a Markdown table on stdout (make_readme_tables.py terrain puts
it in bench/README.md), and the compare pictures of the viewer pose (full | CoNUS | uniform) next to
the JSON.

    bench/terrain_gain.py [--conus build/bin/conus] [--seeds 1,7,11] [--dem-size 1024] [--size 256x256]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

from run_stamp import run_stamp, stamp_line

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PSNR = re.compile(r"PSNR vs full resolution: CoNUS ([-0-9.]+) dB, uniform ([-0-9.]+) dB")
CAMERA = re.compile(r"^camera ([-0-9.,]+) ", re.M)
# Camera moves from the viewer, metres: (back along -forward, up, sideways).
POSES = [("viewer", 0, 0, 0), ("back 500 m", 500, 0, 0), ("back 1500 m", 1500, 0, 0), ("up 500 m", 0, 500, 0),
         ("sideways 1500 m", 0, 0, 1500)]


def run(args):
    done = subprocess.run(args, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"terrain_gain: {' '.join(args)} failed: {done.stderr.strip()}")
    return done.stdout


def moved(camera, back, up, sideways):
    eye, look, fov = camera[0:3], camera[3:6], camera[6]
    forward = [look[i] - eye[i] for i in range(3)]
    length = sum(f * f for f in forward) ** 0.5
    flat = [forward[0] / length, 0.0, forward[2] / length]
    delta = [-back * flat[0] + sideways * -flat[2], up, -back * flat[2] + sideways * flat[0]]
    return [eye[i] + delta[i] for i in range(3)] + [look[i] + delta[i] for i in range(3)] + [fov]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--conus", default=os.path.join(ROOT, "build", "bin", "conus"))
    parser.add_argument("--seeds", default="1,7,11")
    parser.add_argument("--dem-size", type=int, default=1024)
    parser.add_argument("--size", default="256x256", help="CoNUS (and uniform) height field size")
    parser.add_argument("--frame", default="640x360")
    parser.add_argument("--out", default=os.path.join(ROOT, "build", "bench-results"))
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    stamp, start = run_stamp(), time.time()
    rows = []
    for seed in [int(s) for s in args.seeds.split(",")]:
        dem = f"procedural:{args.dem_size}:{seed}"
        for kind in ("terrain", "planar"):
            exr = os.path.join(args.out, f"terrain-{seed}-{kind}.exr")
            run([args.conus, "heightfield", "encode", dem, "-o", exr, "--size", args.size, "--rows", kind, "-q"])
            viewer = None
            for name, back, up, sideways in POSES:
                pose = "viewer" if name == "viewer" else "moved"
                picture = os.path.join(args.out, f"terrain-{seed}-{kind}-{pose}.png")
                command = [args.conus, "render", "heightfield", exr, "--compare", dem, "--size", args.frame, "-o", picture]
                if viewer is not None:
                    command += ["--camera", ",".join(f"{x:.2f}" for x in moved(viewer, back, up, sideways))]
                out = run(command)
                if viewer is None:
                    viewer = [float(x) for x in CAMERA.search(out).group(1).split(",")]
                conus_db, uniform_db = (float(x) for x in PSNR.search(out).groups())
                rows.append({"seed": seed, "rows": kind, "pose": name, "conus_db": conus_db, "uniform_db": uniform_db,
                             "gain_db": round(conus_db - uniform_db, 2)})
                print(f"seed {seed} {kind:7s} {name:16s} CoNUS {conus_db:6.2f} dB  uniform {uniform_db:6.2f} dB  "
                      f"gain {conus_db - uniform_db:+.2f}", file=sys.stderr, flush=True)
    result = {"stamp": stamp, "seconds": time.time() - start, "seeds": args.seeds,
              "method": f"PSNR of a {args.frame} frame against the full-resolution DEM's, {args.dem_size}² procedural DEMs "
                        f"(seeds {args.seeds}), {args.size} height fields (deterministic)",
              "rows": rows}
    with open(os.path.join(args.out, "terrain.json"), "w") as f:
        json.dump(result, f, indent=1)
    print(table(result))


def table(result):
    """The README block: the stamp, then the gain (least .. most over the seeds) per pose."""
    poses = [p[0] for p in POSES]
    lines = [stamp_line(result["stamp"], result["method"]), "",
             "| gain over uniform, dB (least .. most) | " + " | ".join(poses) + " |", "|---|" + "---|" * len(poses)]
    for kind in ("terrain", "planar"):
        cells = []
        for pose in poses:
            gains = [r["gain_db"] for r in result["rows"] if r["rows"] == kind and r["pose"] == pose]
            cells.append(f"{min(gains):+.2f} .. {max(gains):+.2f}" if gains else "")
        label = "`--rows terrain` (default)" if kind == "terrain" else "`--rows planar` (the paper's ground plane)"
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
