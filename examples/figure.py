#!/usr/bin/env python3
"""source | CoNUS | uniform: what CoNUS does, in one figure (matplotlib).

A built-in test picture (fine stripes, text-like bars, a radial target) is encoded with a focus on
its centre at 1/16 of the pixels, then shown three ways, zoomed on the focus: the source, the
CoNUS image decoded, and the uniform image of the same pixel count resized. PSNR in each title.

    python3 figure.py -o figure.png [--input photo.jpg --focus u,v,r,k]

Installed with the package in PREFIX/share/doc/conus/examples/; `import conus` needs the package on
PYTHONPATH (PREFIX/lib/python3/dist-packages, or build/python in a build tree).
"""
import argparse

import matplotlib.pyplot as plt
import numpy as np

import conus


def test_picture(w=960, h=640):
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    r = np.hypot(x - w / 2, y - h / 2)
    theta = np.arctan2(y - h / 2, x - w / 2)
    star = 0.5 + 0.5 * np.sign(np.sin(36 * theta))
    base = 0.25 + 0.2 * np.sin(x / 40.0) * np.cos(y / 55.0)
    img = np.stack([base, base * 0.9, base * 0.7], axis=-1)
    inner = r < 120
    img[inner] = star[inner, None] * np.array([1.0, 0.85, 0.3], np.float32)
    img[40:60, 40:300, :] = (0.9, 0.1, 0.1)  # a red bar, top-left
    return conus.srgb_to_linear(img)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("-o", "--output", default="figure.png")
    parser.add_argument("--input", help="a picture instead of the built-in one")
    parser.add_argument("--focus", default="0.5,0.5,0.125,4", help="u,v,r,k")
    args = parser.parse_args()
    pixels = conus.read_image(args.input)[0][..., :3] if args.input else test_picture()
    h, w = pixels.shape[:2]
    u, v, r, k = map(float, args.focus.split(","))
    size = (max(1, w // 4), max(1, h // 4))
    f = conus.encode(pixels, foci=[(u, v, r, k)], size=size)
    # Zoomed on the focus: a square of side 2r (in widths) around its centre.
    half_u, half_v = r, r * w / h
    view = (u - half_u, v - half_v, u + half_u, v + half_v)
    x0, y0 = int(round(view[0] * w)), int(round(view[1] * h))
    x1, y1 = int(round(view[2] * w)), int(round(view[3] * h))
    truth = pixels[y0:y1, x0:x1]
    ours = conus.decode(f, view=view, size=(x1 - x0, y1 - y0))
    uniform = conus.decode(conus.uniform(pixels, size), view=view, size=(x1 - x0, y1 - y0))
    panels = [("source", truth, None), ("CoNUS", ours, conus.psnr(ours, truth)), ("uniform", uniform, conus.psnr(uniform, truth))]
    fig, axes = plt.subplots(1, 3, figsize=(12, 4.4))
    for ax, (title, img, db) in zip(axes, panels):
        ax.imshow(conus.linear_to_srgb(img), interpolation="nearest")
        ax.set_title(title if db is None else f"{title}: {db:.1f} dB")
        ax.axis("off")
    fig.suptitle(f"focus {args.focus} at 1/16 of the pixels ({size[0]}x{size[1]} of {w}x{h})")
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.savefig(args.output, dpi=80)
    print(f"wrote {args.output}: CoNUS {panels[1][2]:.1f} dB, uniform {panels[2][2]:.1f} dB in the focus")


if __name__ == "__main__":
    main()
