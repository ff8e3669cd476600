#!/usr/bin/env python3
"""Reflections of real models as a user makes them: through the `conus` binary, scored as codecs are.

    bench/mirrors_cli.py [--bin build/bin] [--backend egl|osmesa|cpu|auto] [--out DIR]

Each model (the Utah teapot, Cesium's milk truck and assimp-testmodels' spider, the held-out one)
beside a plane and a sphere mirror of radius 4, seen from (6, 3.5, 4) (the set-up of
bench/renderers/layered_reflection_bench.cpp, the spider brought to the truck's size there and
the set-up brought to the spider's own units here): `conus bake reflection` with `--view` and every
other option its default (CoNUS, then `--uniform`), `conus render reflection` at 256x256 (its
default 3x3 rays a pixel) and `render reflection --reference`. The score: 8-bit sRGB PSNR over the
mirror's pixels, leaving out those where the model itself stands in front of the mirror (its
coverage in `conus render mesh` from the same camera), and the whole frame's mean SSIM. Prints a
Markdown table; the frames stay in --out.
"""
import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image
from skimage.metrics import structural_similarity

ROOT = Path(__file__).resolve().parent.parent
MODELS = {
    "teapot": ROOT.parent / "shared" / "data" / "meshes" / "teapot.obj",
    "truck": Path("/usr/share/assimp/models/glTF/CesiumMilkTruck/CesiumMilkTruck.gltf"),
    "spider": Path("/usr/share/assimp/models/OBJ/spider.obj"),
}
FRAME = 256
EYE = np.array([6.0, 3.5, 4.0])
NORMAL = np.array([0.15, 0.0, 1.0]) / np.linalg.norm([0.15, 0.0, 1.0])


def placement(conus, name, model):
    """(scale, base): the bench's world point p is the model's own (p / scale + base). The
    spider is 193 units long about (-17, -2, -10); the bench makes its longer ground side 5 units,
    centred over the origin, on the ground (layered_reflection_bench.cpp's readModel), from its
    bounds as `conus info` gives them."""
    if name != "spider":
        return 1.0, np.zeros(3)
    info = json.loads(subprocess.run([conus, "info", str(model), "--json"], check=True, capture_output=True, text=True).stdout)
    lo, hi = np.array(info["bounds"]["min"]), np.array(info["bounds"]["max"])
    size = hi - lo
    return 5.0 / max(size[0], size[2]), np.array([(lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2])


def text(v):
    return ",".join(f"{x:.9g}" for x in v)


def mirror_mask(kind, eye, centre, radius, fov):
    """The frame's pixels whose centre ray meets the mirror (the renderers' camera: y up, rows down)."""
    forward = (centre - eye) / np.linalg.norm(centre - eye)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    t = np.tan(np.radians(fov) / 2)
    ys, xs = np.mgrid[0:FRAME, 0:FRAME] + 0.5
    d = forward + ((2 * xs / FRAME - 1) * t)[..., None] * right - ((2 * ys / FRAME - 1) * t)[..., None] * up
    if kind == "sphere":
        oc = eye - centre
        b, a, c = d @ oc, (d * d).sum(-1), oc @ oc - radius * radius
        return b * b - a * c > 0
    along = ((centre - eye) @ NORMAL) / (d @ NORMAL)
    q = eye + along[..., None] * d - centre
    s = np.cross([0.0, 1.0, 0.0], NORMAL)
    s /= np.linalg.norm(s)
    u = np.cross(NORMAL, s)
    return (along > 0) & (np.abs(q @ s) <= radius) & (np.abs(q @ u) <= radius)


def read(path):
    return np.asarray(Image.open(path).convert("RGB"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bin", default=str(ROOT / "build" / "bin"))
    parser.add_argument("--backend", default="auto")
    parser.add_argument("--out", default=str(ROOT / "build" / "mirrors-cli"))
    args = parser.parse_args()
    conus = str(Path(args.bin) / "conus")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    def run(*cmd):
        subprocess.run([conus, *map(str, cmd), "-q"], check=True, stdout=subprocess.DEVNULL)

    print("| model, mirror | mirror PSNR, CoNUS / uniform | SSIM, CoNUS / uniform |")
    print("|---|---|---|")
    for name, model in MODELS.items():
        if not model.exists():
            sys.exit(f"mirrors_cli.py: {model} is not installed (scripts/packages.txt)")
        scale, base = placement(conus, name, model)
        for kind in ("plane", "sphere"):
            centre = np.array([0.0, 1.5, -6.0 if kind == "plane" else -7.0]) / scale + base
            eye, radius, fov = EYE / scale + base, 4.0 / scale, 38.0 if kind == "plane" else 45.0
            camera = f"{text(eye)},{text(centre)},{fov:g}"
            mirror = ["--reflector", kind, f"--normal={text(NORMAL)}"]
            stem = out / f"{name}-{kind}"
            frames = {}
            for variant, extra in (("conus", []), ("uniform", ["--uniform"])):
                asset = f"{stem}-{variant}.exr"
                run("bake", "reflection", model, f"--center={text(centre)}", f"--view={text(eye)}", *mirror,
                    "--mirror-radius", radius, *extra, "-o", asset)
                frames[variant] = f"{stem}-{variant}.png"
                run("render", "reflection", asset, "--scene", model, f"--camera={camera}", f"--at={text(centre)}",
                    "--size", f"{FRAME}x{FRAME}", *mirror, "--radius", radius, "--backend", args.backend,
                    "-o", frames[variant])
            reference = f"{stem}-reference.png"
            run("render", "reflection", f"{stem}-conus.exr", "--scene", model, f"--camera={camera}",
                f"--at={text(centre)}", "--size", f"{FRAME}x{FRAME}", *mirror, "--radius", radius, "--reference",
                "-o", reference)
            run("render", "mesh", model, f"--camera={camera}", "--size", f"{FRAME}x{FRAME}", "--uniform",
                "-o", f"{stem}-direct.exr")
            coverage = read_alpha(f"{stem}-direct.exr")
            mask = mirror_mask(kind, eye, centre, radius, fov) & (coverage == 0)
            truth = read(reference).astype(float)
            psnr, ssim = [], []
            for variant in ("conus", "uniform"):
                frame = read(frames[variant])
                error = ((frame.astype(float) - truth) ** 2)[mask].mean()
                psnr.append(10 * np.log10(255.0 ** 2 / error))
                ssim.append(structural_similarity(frame, truth.astype(np.uint8), channel_axis=2))
            print(f"| {name}, {kind} | {psnr[0]:.2f} / {psnr[1]:.2f} dB | {ssim[0]:.4f} / {ssim[1]:.4f} |", flush=True)


def read_alpha(exr):
    """The A channel of a `render mesh` file, through oiiotool (PIL reads no OpenEXR)."""
    png = exr.replace(".exr", "-a.png")
    subprocess.run(["oiiotool", exr, "--ch", "A", "-d", "uint8", "-o", png], check=True)
    return np.asarray(Image.open(png))


if __name__ == "__main__":
    main()
