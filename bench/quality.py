#!/usr/bin/python3
"""Quality of CoNUS against the uniform image of the same pixel count, on real photographs, in one
command: `bench/quality.py [--out DIR] [--quick]`. Writes DIR/quality.md (the tables of
bench/README.md) and DIR/*.png (rate-distortion and gain-loss plots), DIR defaulting to
build/quality.

Everything is measured in linear light (the values the EXR holds) against the source:
- ROI PSNR and SSIM: inside each region of interest (a disc of radius r, a fraction of the width),
  CoNUS (one focus u,v,r,k per region, k = 4) against uniform, at 1/4, 1/16 and 1/64 of the pixels;
- whole-frame loss: uniform's PSNR over the whole frame minus CoNUS's;
- aliasing check in the context ring (r..2r): each decoded view against the source low-passed to
  the rate it was sampled at there (a Gaussian of sigma 0.5 / rate source pixels, the rate from
  the map's density), CoNUS and uniform alike: a comb or a staircase shows as error against it;
- equal bytes (1/16): the CoNUS and uniform images compressed with JPEG XL (cjxl) and JPEG 2000
  (opj_compress), against the full-resolution photograph compressed with either to the same
  bytes. OpenJPEG has no spatial region of interest (its -ROI upshifts a whole component), so the
  full-resolution JPEG 2000 at equal bytes stands for JPEG 2000's own ROI coding;
- gain against loss: foci of k = 2..6 and automatic maps from ROI importance (1 in the discs, 0
  elsewhere) with their context floor swept, or chosen by a whole-frame loss budget
  (Map.auto_for_frame_loss, `encode --frame-loss`), and with an anisotropy limit swept: the
  frontier each method reaches.
- fitted to the decoder (`encode --fit`, `uniform --fit`; codec/image/fit.h): every measure above
  again with both images fitted, CoNUS against the fitted uniform image, and the gain-loss points of
  the foci, the automatic maps and the budgets with the fit.
Photographs: Debian's python3-skimage (astronaut, chelsea, motorcycle) and mate-backgrounds
(ladybird, dandelion, garden; reduced to 1280 px wide by an area filter to keep the run short).
"""
import argparse
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "build" / "python"))
import conus  # noqa: E402  (the package built by cmake)

SKIMAGE = pathlib.Path("/usr/lib/python3/dist-packages/skimage/data")
MATE = pathlib.Path("/usr/share/backgrounds/mate/nature")
# name, file, regions (u, v, r): r a fraction of the width.
PHOTOS = [
    ("astronaut", SKIMAGE / "astronaut.png", [(0.44, 0.23, 0.08), (0.33, 0.75, 0.06)]),
    ("chelsea", SKIMAGE / "chelsea.png", [(0.37, 0.38, 0.07), (0.71, 0.45, 0.07)]),
    ("motorcycle", SKIMAGE / "motorcycle_left.png", [(0.55, 0.62, 0.08), (0.72, 0.31, 0.05)]),
    ("ladybird", MATE / "LadyBird.jpg", [(0.70, 0.50, 0.05)]),
    ("dandelion", MATE / "TwoWings.jpg", [(0.50, 0.45, 0.07), (0.74, 0.40, 0.06)]),
    ("garden", MATE / "Garden.jpg", [(0.55, 0.55, 0.09)]),
]
MAX_WIDTH = 1280
FRACTIONS = [(2, "1/4"), (4, "1/16"), (8, "1/64")]  # side divisor, share of the pixels
K = 4
BUDGETS = [0.5, 1.0, 1.5, 2.0, 2.5, 3.0]  # --frame-loss budgets swept (dB)
BUDGET_GRID, BUDGET_MAX_DENSITY = 129, 64.0
ANISOTROPY_LIMITS = [4.0, 6.0, 8.0, 12.0, 16.0, 24.0]  # --max-anisotropy swept, at the loosest budget
FIT = 4  # --fit iterations (the default of `encode --fit`) of the fitted variant (0: --no-fit leaves it out)
FIT_HOLD = None  # --fit-hold (None: the encoder's default)
METHODS = ("foci", "auto", "budget", "limited", "foci+fit", "auto+fit", "budget+fit")


def psnr(a, b, mask=None):
    d = (a - b) ** 2
    mse = d[mask].mean() if mask is not None else d.mean()
    return 10 * np.log10(1.0 / max(mse, 1e-20))


def ssim(a, b, mask):
    from skimage.metrics import structural_similarity
    _, full = structural_similarity(np.clip(a, 0, 1), np.clip(b, 0, 1), channel_axis=2, data_range=1.0, full=True)
    return float(full[mask].mean())


def discs(shape, regions, inner=0.0, outer=1.0):
    """Mask of the points within (inner*r, outer*r] of any region's centre (r in widths)."""
    h, w = shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    mask = np.zeros((h, w), bool)
    for u, v, r in regions:
        d = np.hypot(x + 0.5 - u * w, y + 0.5 - v * h) / (r * w)
        mask |= (d > inner) & (d <= outer)
    return mask


def srgb8(linear):
    c = np.clip(linear[..., :3], 0, 1)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return np.round(s * 255).astype(np.uint8)


def linear(srgb):
    s = srgb.astype(np.float32) / 255
    return np.where(s <= 0.04045, s / 12.92, np.power((s + 0.055) / 1.055, 2.4)).astype(np.float32)


def write_png(path, rgb8):
    from PIL import Image
    Image.fromarray(rgb8).save(path)


def read_png(path):
    from PIL import Image
    return np.asarray(Image.open(path).convert("RGB"))


def lowpassed(source, rate):
    """The source low-passed per pixel to a linear sampling rate (samples per source pixel): a
    Gaussian of sigma 0.5 / rate, from a stack of blurs a quarter octave apart."""
    from scipy.ndimage import gaussian_filter
    sigma = 0.5 / np.clip(rate, 1e-3, 1.0)
    levels = np.exp(np.arange(np.log(0.25), np.log(sigma.max()) + 0.3, np.log(2) / 4))
    index = np.clip(np.searchsorted(levels, sigma), 0, len(levels) - 1)
    out = np.empty_like(source)
    for i, s in enumerate(levels):
        pick = index == i
        if pick.any():
            out[pick] = gaussian_filter(source, (s, s, 0))[pick]
    return out


def codec_round_trip(pixels, tool, level, work):
    """8-bit sRGB of `pixels` compressed by tool ('jxl' distance, 'j2k' ratio); (linear, bytes)."""
    png, packed, back = work / "in.png", work / ("c." + tool), work / "back.png"
    write_png(png, srgb8(pixels))
    if tool == "jxl":
        subprocess.run(["cjxl", str(png), str(packed), "-d", str(level), "-e", "7"], check=True, capture_output=True)
        subprocess.run(["djxl", str(packed), str(back)], check=True, capture_output=True)
    else:
        subprocess.run(["opj_compress", "-i", str(png), "-o", str(packed), "-r", str(level)], check=True, capture_output=True)
        subprocess.run(["opj_decompress", "-i", str(packed), "-o", str(back)], check=True, capture_output=True)
    return linear(read_png(back)), packed.stat().st_size


def load(path):
    pixels, channels = conus.read_image(str(path))
    pixels = np.ascontiguousarray(pixels[..., :3], np.float32)
    h, w = pixels.shape[:2]
    if w > MAX_WIDTH:
        pixels = conus.uniform(pixels, size=(MAX_WIDTH, round(h * MAX_WIDTH / w)))
    return np.ascontiguousarray(pixels, np.float32)


def view_of(file, w, h):
    return np.asarray(conus.decode(file, size=(w, h)))[..., :3]


def encode_with(src, size, regions, k=K, map=None, fit=0):
    hold = {} if FIT_HOLD is None else {"fit_hold": FIT_HOLD}
    if map is not None:
        return conus.encode(src, map=map, size=size, fit=fit, **hold)
    return conus.encode(src, foci=[(u, v, r, k) for u, v, r in regions], size=size, fit=fit, **hold)


def uniform_view(src, size, fit=0):
    h, w = src.shape[:2]
    return np.asarray(conus.resize(conus.uniform(src, size=size, fit=fit), size=(w, h)))[..., :3]


def measure(name, src, regions, out, quick):
    h, w = src.shape[:2]
    roi, ring = discs(src.shape, regions), discs(src.shape, regions, 1.0, 2.0)
    rows = []
    for divisor, share in FRACTIONS:
        size = (max(1, w // divisor), max(1, h // divisor))
        cfile = encode_with(src, size, regions)
        cview = view_of(cfile, w, h)
        uview = uniform_view(src, size)
        # Rates in samples per source pixel: the uniform image's, times sqrt(density) for CoNUS.
        base = np.sqrt(size[0] * size[1] / (w * h))
        y, x = np.mgrid[0:h, 0:w]
        points = np.stack([(x + 0.5) / w, (y + 0.5) / h], axis=-1)
        rate = base * np.sqrt(np.asarray(cfile.map.density(points)))
        ring_ref_c = lowpassed(src, rate)
        ring_ref_u = lowpassed(src, np.full((h, w), base))
        rows.append(dict(photo=name, share=share,
                         roi_c=psnr(cview, src, roi), roi_u=psnr(uview, src, roi),
                         ssim_c=ssim(cview, src, roi), ssim_u=ssim(uview, src, roi),
                         frame_c=psnr(cview, src), frame_u=psnr(uview, src),
                         alias_c=psnr(cview, ring_ref_c, ring), alias_u=psnr(uview, ring_ref_u, ring)))
        if FIT:
            fview, ufview = view_of(encode_with(src, size, regions, fit=FIT), w, h), uniform_view(src, size, FIT)
            rows[-1].update(fitted=dict(roi_c=psnr(fview, src, roi), roi_u=psnr(ufview, src, roi),
                                        ssim_c=ssim(fview, src, roi), ssim_u=ssim(ufview, src, roi),
                                        frame_c=psnr(fview, src), frame_u=psnr(ufview, src),
                                        alias_c=psnr(fview, ring_ref_c, ring), alias_u=psnr(ufview, ring_ref_u, ring)))
            if share == "1/16":
                write_png(out / f"{name}-conus-fit.png", srgb8(fview))
        if share == "1/16":
            write_png(out / f"{name}-conus.png", srgb8(cview))
            write_png(out / f"{name}-uniform.png", srgb8(uview))
            rows[-1]["zones"] = zones(src, regions, cfile, cview, uview, size)
    return rows


def zones(src, regions, cfile, cview, uview, size):
    """Where the whole-frame loss comes from: by distance from the regions (in radii), the share of
    the frame, the map's mean density and median anisotropy (its Jacobian's singular value ratio in
    pixels, by central differences), CoNUS's error over uniform's, and the uniform image at that
    mean density's error over uniform's (what the density alone would cost)."""
    h, w = src.shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    points = np.stack([(x + 0.5) / w, (y + 0.5) / h], axis=-1)
    out = []
    for lo, hi in ((0, 1), (1, 2), (2, 3), (3, None)):
        mask = discs(src.shape, regions, lo, hi) if hi else ~discs(src.shape, regions, 0, lo)
        if not mask.any():
            continue
        p = points[mask][::16]
        e, a = 1e-4, w / h
        du = (np.asarray(cfile.map.distort(p + [e, 0])) - np.asarray(cfile.map.distort(p - [e, 0]))) / (2 * e)
        dv = (np.asarray(cfile.map.distort(p + [0, e])) - np.asarray(cfile.map.distort(p - [0, e]))) / (2 * e)
        jac = np.stack([np.stack([du[:, 0], dv[:, 0] * a], -1), np.stack([du[:, 1] / a, dv[:, 1]], -1)], 1)
        sv = np.linalg.svd(jac, compute_uv=False)
        density = float(np.mean(np.asarray(cfile.map.density(points[mask]))))
        scaled = (max(1, round(size[0] * np.sqrt(min(density, 1e6)))), max(1, round(size[1] * np.sqrt(min(density, 1e6)))))
        ideal = np.asarray(conus.resize(conus.uniform(src, size=(min(scaled[0], w), min(scaled[1], h))), size=(w, h)))[..., :3]
        err = lambda view: ((view - src) ** 2)[mask].mean()
        out.append(dict(zone=f"{lo}r..{hi}r" if hi else f"beyond {lo}r", share=float(mask.mean()), density=density,
                        anisotropy=float(np.median(sv[:, 0] / sv[:, 1])),
                        conus=10 * np.log10(err(cview) / err(uview)), ideal=10 * np.log10(err(ideal) / err(uview))))
    return out


def frontier(name, src, regions, quick):
    """ROI gain and frame loss at 1/16 for foci of several k and automatic maps from ROI
    importance with several context floors."""
    h, w = src.shape[:2]
    size = (w // 4, h // 4)
    roi = discs(src.shape, regions)
    uview = uniform_view(src, size)
    ref_roi, ref_frame = psnr(uview, src, roi), psnr(uview, src)
    importance = discs(src.shape, regions).astype(np.float32)
    points = {"foci": [], "auto": [], "budget": [], "limited": []}
    if FIT:
        # The fitted variants against the fitted uniform image: the same settings, each map once.
        ufview = uniform_view(src, size, FIT)
        fit_roi, fit_frame = psnr(ufview, src, roi), psnr(ufview, src)
        points.update({"foci+fit": [], "auto+fit": [], "budget+fit": []})

        def add_fitted(method, setting, m=None, k=K, extra=()):
            view = view_of(encode_with(src, size, regions, k=k, map=m, fit=FIT), w, h)
            points[method].append((setting, fit_frame - psnr(view, src), psnr(view, src, roi) - fit_roi) + tuple(extra))
    else:
        def add_fitted(*args, **kwargs):
            pass
    for k in ([2, 4, 6] if quick else [2, 3, 4, 5, 6]):
        view = view_of(encode_with(src, size, regions, k=k), w, h)
        points["foci"].append((k, ref_frame - psnr(view, src), psnr(view, src, roi) - ref_roi))
        add_fitted("foci+fit", k, k=k)
    for floor in ([0.6, 0.3] if quick else [0.8, 0.6, 0.45, 0.3, 0.2]):
        try:
            m = conus.Map.auto(importance, min_density=floor, max_density=36.0)
        except Exception as e:  # a refusal of the bounds: say so, go on
            print(f"  {name}: auto map with floor {floor}: {e}", file=sys.stderr)
            continue
        view = view_of(encode_with(src, size, regions, map=m), w, h)
        points["auto"].append((floor, ref_frame - psnr(view, src), psnr(view, src, roi) - ref_roi))
        add_fitted("auto+fit", floor, m=m)
    # The frame-loss budget (`encode --frame-loss`): the floor chosen by the predicted loss, a higher
    # density cap so that a loose budget can spend it. The setting records the budget and what was
    # predicted, beside what is measured.
    for budget in ([1.0, 2.5] if quick else BUDGETS):
        m, floor, p_loss, p_gain = conus.Map.auto_for_frame_loss(importance, src, size, budget, grid=BUDGET_GRID,
                                                                 max_density=BUDGET_MAX_DENSITY)
        view = view_of(encode_with(src, size, regions, map=m), w, h)
        points["budget"].append((budget, ref_frame - psnr(view, src), psnr(view, src, roi) - ref_roi, p_loss, p_gain, floor))
        add_fitted("budget+fit", budget, m=m, extra=(p_loss, p_gain, floor))
    # The same with an anisotropy limit (`--max-anisotropy`): the builder tempers the density until
    # every footprint is at most that elongated, which costs magnification but spares the context.
    for limit in ([4.0, 8.0] if quick else ANISOTROPY_LIMITS):
        m, floor, p_loss, p_gain = conus.Map.auto_for_frame_loss(importance, src, size, BUDGETS[-1], grid=BUDGET_GRID,
                                                                 max_density=BUDGET_MAX_DENSITY, max_anisotropy=limit)
        view = view_of(encode_with(src, size, regions, map=m), w, h)
        points["limited"].append((limit, ref_frame - psnr(view, src), psnr(view, src, roi) - ref_roi, p_loss, p_gain, floor))
    return points


def equal_bytes(name, src, regions, quick):
    """ROI PSNR against bytes at 1/16: CoNUS and uniform through JPEG XL and JPEG 2000, and the
    full-resolution photograph through both."""
    h, w = src.shape[:2]
    size = (w // 4, h // 4)
    roi = discs(src.shape, regions)
    cfile = encode_with(src, size, regions)
    pixels = np.asarray(cfile.pixels)
    original = pixels.copy()
    small = np.asarray(conus.uniform(src, size=size))[..., :3]
    curves = {}
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        for tool, levels, full_levels in (("jxl", [0.3, 0.6, 1, 2, 4, 8], [3, 6, 12, 25]),
                                          ("j2k", [2, 4, 8, 16, 32, 64], [40, 80, 160, 320, 640])):
            if quick:
                levels, full_levels = levels[::2], full_levels[::2]
            for label in ("conus", "uniform", "full"):
                curve = []
                for level in (full_levels if label == "full" else levels):
                    if label == "conus":
                        back, size_bytes = codec_round_trip(original, tool, level, work)
                        pixels[..., :3] = back
                        view = view_of(cfile, w, h)
                        pixels[...] = original
                    elif label == "uniform":
                        back, size_bytes = codec_round_trip(small, tool, level, work)
                        view = np.asarray(conus.resize(np.ascontiguousarray(back), size=(w, h)))[..., :3]
                    else:
                        view, size_bytes = codec_round_trip(src, tool, level, work)
                    curve.append((size_bytes, psnr(view, src, roi), psnr(view, src)))
                curves[f"{label} + {tool}"] = sorted(curve)
    return curves


def at_bytes(curve, target):
    """ROI PSNR of a curve at `target` bytes (linear in log bytes; None outside its range)."""
    b = np.log([c[0] for c in curve])
    if not (b[0] <= np.log(target) <= b[-1]):
        return None
    return float(np.interp(np.log(target), b, [c[1] for c in curve]))


def plots(out, all_curves, all_points):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(all_curves)
    fig, axes = plt.subplots(2, (len(names) + 1) // 2, figsize=(5 * ((len(names) + 1) // 2), 8), squeeze=False)
    styles = {"conus": "-o", "uniform": "--s", "full": ":^"}
    for ax, name in zip(axes.flat, names):
        for label, curve in all_curves[name].items():
            who, tool = label.split(" + ")
            ax.plot([c[0] / 1024 for c in curve], [c[1] for c in curve], styles[who], label=label,
                    color="C0" if tool == "jxl" else "C1")
        ax.set_xscale("log")
        ax.set_title(name)
        ax.set_xlabel("KiB")
        ax.set_ylabel("ROI PSNR (dB, linear light)")
        ax.grid(True, alpha=0.3)
    axes.flat[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "rate-distortion.png", dpi=90)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(7, 5))
    for method in [m for m in METHODS if m in next(iter(all_points.values()))]:
        marker = {"foci": "o", "auto": "s", "budget": "^", "limited": "D"}[method.split("+")[0]]
        xs = [np.mean([p[method][i][1] for p in all_points.values()]) for i in range(min(len(p[method]) for p in all_points.values()))]
        ys = [np.mean([p[method][i][2] for p in all_points.values()]) for i in range(len(xs))]
        ax.plot(xs, ys, (":" if method.endswith("+fit") else "-") + marker, label={"foci": "one focus per region, k = 2..6", "auto": "automatic map from ROI importance, floor swept",
                                                "budget": f"automatic map, --frame-loss budget swept (max density {BUDGET_MAX_DENSITY:g}, grid {BUDGET_GRID})",
                                                "limited": f"the same at {BUDGETS[-1]:g} dB, --max-anisotropy {ANISOTROPY_LIMITS[0]:g}..{ANISOTROPY_LIMITS[-1]:g} swept",
                                                "foci+fit": f"foci, --fit {FIT} (against uniform --fit {FIT})",
                                                "auto+fit": f"automatic map, floor swept, --fit {FIT}",
                                                "budget+fit": f"automatic map, --frame-loss swept, --fit {FIT}"}[method])
    ax.axvline(2.5, color="grey", ls=":")
    ax.axhline(6.5, color="grey", ls=":")
    ax.set_xlabel("whole-frame loss against uniform (dB)")
    ax.set_ylabel("mean ROI gain over uniform (dB)")
    ax.set_title("1/16 of the pixels, mean over the photographs")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(out / "gain-loss.png", dpi=90)
    plt.close(fig)


def summary(rows):
    lines = []
    for share in [s for _, s in FRACTIONS]:
        sel = [r for r in rows if r["share"] == share]
        gain = np.mean([r["roi_c"] - r["roi_u"] for r in sel])
        loss = np.mean([r["frame_u"] - r["frame_c"] for r in sel])
        worst = min(r["roi_c"] - r["roi_u"] for r in sel)
        ring = np.mean([r["alias_u"] - r["alias_c"] for r in sel])
        lines.append(f"- {share}: mean ROI gain {gain:+.1f} dB (worst {worst:+.1f}), mean whole-frame loss {loss:.1f} dB, "
                     f"ring check CoNUS {ring:.1f} dB below uniform")
    return lines


def report(rows, all_curves, all_points):
    lines = ["| photo | pixels | ROI PSNR CoNUS / uniform (gain) | ROI SSIM CoNUS / uniform | whole-frame loss | ring vs low-passed source: CoNUS / uniform |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['photo']} | {r['share']} | {r['roi_c']:.1f} / {r['roi_u']:.1f} ({r['roi_c'] - r['roi_u']:+.1f}) | "
                     f"{r['ssim_c']:.3f} / {r['ssim_u']:.3f} | {r['frame_u'] - r['frame_c']:.1f} dB | {r['alias_c']:.1f} / {r['alias_u']:.1f} |")
    lines.append("")
    lines += summary(rows)
    if FIT:
        fitted = [dict(r["fitted"], photo=r["photo"], share=r["share"]) for r in rows]
        lines += ["", f"Fitted to the decoder (`--fit {FIT}`), CoNUS against the uniform image fitted the same way "
                  "(`uniform --fit`); 'vs plain': the fitted CoNUS against today's uniform image", "",
                  "| photo | pixels | ROI PSNR CoNUS / uniform (gain) | ROI SSIM CoNUS / uniform | whole-frame loss | ring vs low-passed source: CoNUS / uniform | vs plain: gain, loss |",
                  "|---|---|---|---|---|---|---|"]
        for r, f in zip(rows, fitted):
            lines.append(f"| {f['photo']} | {f['share']} | {f['roi_c']:.1f} / {f['roi_u']:.1f} ({f['roi_c'] - f['roi_u']:+.1f}) | "
                         f"{f['ssim_c']:.3f} / {f['ssim_u']:.3f} | {f['frame_u'] - f['frame_c']:.1f} dB | "
                         f"{f['alias_c']:.1f} / {f['alias_u']:.1f} | {f['roi_c'] - r['roi_u']:+.1f}, {r['frame_u'] - f['frame_c']:.1f} dB |")
        lines.append("")
        lines += summary(fitted)
    lines += ["", "Where the loss comes from at 1/16: error over uniform's by zone (distance from the regions in radii); "
              "'uniform at that density': the uniform image of the zone's mean density", "",
              "| photo | zone | share | mean density | median anisotropy | CoNUS | uniform at that density |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        for z in r.get("zones", []):
            lines.append(f"| {r['photo']} | {z['zone']} | {100 * z['share']:.0f}% | {z['density']:.2f} | {z['anisotropy']:.2f} | "
                         f"{z['conus']:+.1f} dB | {z['ideal']:+.1f} dB |")
    lines += ["", "Gain against loss at 1/16 (mean over the photographs): method, setting: frame loss, ROI gain", ""]
    for method in [m for m in METHODS if m in next(iter(all_points.values()))]:
        n = min(len(p[method]) for p in all_points.values())
        for i in range(n):
            setting = all_points[next(iter(all_points))][method][i][0]
            loss = np.mean([p[method][i][1] for p in all_points.values()])
            gain = np.mean([p[method][i][2] for p in all_points.values()])
            worst = min(p[method][i][2] for p in all_points.values())
            name = {"foci": "k", "auto": "floor", "budget": "frame-loss", "limited": "max-anisotropy"}[method.split("+")[0]]
            line = f"- {method} {name} {setting}: loss {loss:.2f} dB, gain {gain:+.2f} dB (worst photo {worst:+.2f})"
            if method in ("budget", "limited", "budget+fit"):
                p_loss = np.mean([p[method][i][3] for p in all_points.values()])
                p_gain = np.mean([p[method][i][4] for p in all_points.values()])
                floors = ", ".join(f"{p[method][i][5]:.2f}" for p in all_points.values())
                line += f"; predicted loss {p_loss:.2f} dB, gain {p_gain:+.2f} dB; floors {floors}"
            lines.append(line)
    lines += ["", "Equal bytes at 1/16: ROI PSNR (dB) of each at the bytes of CoNUS + JPEG XL -d 1 ('-': outside its range)", "",
              "| photo | KiB | CoNUS + jxl | uniform + jxl | full + jxl | CoNUS + j2k | uniform + j2k | full + j2k |", "|---|---|---|---|---|---|---|---|"]
    for name, curves in all_curves.items():
        # The bytes of CoNUS + JPEG XL at distance 1 (the third of its levels; the second in --quick).
        ref = curves["conus + jxl"]
        target = ref[-3][0] if len(ref) >= 3 else ref[0][0]
        cells = []
        for label in ("conus + jxl", "uniform + jxl", "full + jxl", "conus + j2k", "uniform + j2k", "full + j2k"):
            v = at_bytes(curves[label], target)
            cells.append("-" if v is None else f"{v:.1f}")
        lines.append(f"| {name} | {target / 1024:.0f} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main():
    global FIT, FIT_HOLD
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=str(ROOT / "build" / "quality"))
    parser.add_argument("--quick", action="store_true", help="two photographs, fewer settings (a smoke run)")
    parser.add_argument("--fit", type=int, default=FIT, help=f"iterations of the fitted variant (default {FIT})")
    parser.add_argument("--no-fit", action="store_true", help="leave the fitted variant out")
    parser.add_argument("--fit-hold", type=float, default=None, help="the fit's --fit-hold (default: the encoder's)")
    args = parser.parse_args()
    FIT = 0 if args.no_fit else args.fit
    FIT_HOLD = args.fit_hold
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for tool in ("cjxl", "djxl", "opj_compress", "opj_decompress"):
        if subprocess.run(["which", tool], capture_output=True).returncode != 0:
            sys.exit(f"bench/quality.py: {tool} is missing (apt-get install libjxl-tools libopenjp2-tools)")
    photos = PHOTOS[:2] if args.quick else PHOTOS
    rows, all_curves, all_points = [], {}, {}
    for name, path, regions in photos:
        if not path.exists():
            sys.exit(f"bench/quality.py: {path} is missing (apt-get install python3-skimage mate-backgrounds)")
        print(f"== {name}", flush=True)
        src = load(path)
        rows += measure(name, src, regions, out, args.quick)
        all_points[name] = frontier(name, src, regions, args.quick)
        all_curves[name] = equal_bytes(name, src, regions, args.quick)
    text = report(rows, all_curves, all_points)
    (out / "quality.md").write_text(text)
    plots(out, all_curves, all_points)
    print(text)
    print(f"wrote {out / 'quality.md'}, {out / 'rate-distortion.png'}, {out / 'gain-loss.png'}")


if __name__ == "__main__":
    main()
