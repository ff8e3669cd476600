#!/usr/bin/env python3
"""Photos an hour: CoNUS batch conversion on this machine, three ways, in one run.

Writes N photo-sized JPEGs (default 12 of 3000x2000: a textured scene with a red patch in one
corner and text-like bars), then times
  1. `conus encode` one photo at a time (the baseline: a shell loop),
  2. `conus encode ... --out-dir --jobs J` (the CLI's batch),
  3. conus.dask.encode_files on Dask's local threads,
each with one focus, at 1/16 of the pixels, and prints photos an hour and the ratio to the baseline.

    PYTHONPATH=build/python python3 bench/python/batch_throughput.py [--count 12] [--size 3000x2000] [--jobs 2]
"""
import argparse
import os
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import conus
import conus.dask


def photo(w, h, seed):
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    base = 0.35 + 0.25 * np.sin(x / (23 + seed)) * np.cos(y / 31.0) + 0.05 * rng.standard_normal((h, w), dtype=np.float32)
    img = np.stack([base, base * 0.8, base * 0.6], axis=-1)
    img[: h // 10, : w // 10] = (0.9, 0.05, 0.05)
    for i in range(0, w - 40, 60):
        img[h // 2:h // 2 + 12, i:i + 40] = 0.95
    return np.clip(img, 0, 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--count", type=int, default=12)
    parser.add_argument("--size", default="3000x2000")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--bin", default=str(pathlib.Path(__file__).resolve().parents[2] / "build" / "bin" / "conus"))
    args = parser.parse_args()
    w, h = map(int, args.size.split("x"))
    focus = "0.5,0.5,0.1,4"
    with tempfile.TemporaryDirectory(prefix="conus-throughput-") as work:
        work = pathlib.Path(work)
        inputs = []
        for i in range(args.count):
            path = work / f"photo{i:03d}.jpg"
            conus.write_image(str(path), conus.srgb_to_linear(photo(w, h, i)))
            inputs.append(str(path))
        results = []

        (work / "one").mkdir()
        start = time.perf_counter()
        for p in inputs:
            out = work / "one" / (pathlib.Path(p).stem + ".exr")
            subprocess.run([args.bin, "encode", p, "-o", str(out), "--focus", focus, "-q"], check=True, capture_output=True)
        results.append(("conus encode, one at a time", time.perf_counter() - start))

        start = time.perf_counter()
        subprocess.run([args.bin, "encode", *inputs, "--out-dir", str(work / "batch"), "--jobs", str(args.jobs), "--focus", focus, "-q"],
                       check=True, capture_output=True)
        results.append((f"conus encode --jobs {args.jobs}", time.perf_counter() - start))

        start = time.perf_counter()
        summary = conus.dask.encode_files(inputs, str(work / "dask"), foci=[tuple(map(float, focus.split(",")))], scheduler="threads")
        assert summary.count("converted") == args.count, summary.table()
        results.append(("conus.dask.encode_files (threads)", time.perf_counter() - start))

    base = results[0][1]
    print(f"{args.count} photos of {w}x{h} (JPEG), one focus, 1/16 of the pixels, {os.cpu_count()} cores")
    for name, seconds in results:
        print(f"  {name:<36} {seconds:7.1f} s  {3600 * args.count / seconds:7.0f} photos/hour  {base / seconds:5.2f}x")


if __name__ == "__main__":
    main()
