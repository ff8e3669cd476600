#!/usr/bin/python3
"""Quality of CoNUS against the uniform image of the same pixel count, on real photographs, in one
command: `bench/quality.py [--out DIR] [--quick | --defaults-only]`. Writes DIR/quality.md (the
tables of bench/README.md) and DIR/*.png (rate-distortion and gain-loss plots), DIR defaulting to
build/quality. `--defaults-only`: only the targets table of the `conus` program's defaults on 8-bit
sRGB pictures (quality_targets.py: DIR/targets.md and a contact sheet), in minutes.

At 1/16 the 8-bit sRGB measures of quality_targets.py too (ROI and whole-frame PSNR and SSIM, the
tile loss outside the regions). Everything else is measured in linear light (the values the EXR
holds) against the source:
- ROI PSNR and SSIM: inside each region of interest (a disc of radius r, a fraction of the width),
  CoNUS (one focus u,v,r,k per region, k = 4) against uniform, at 1/4, 1/16 and 1/64 of the pixels;
- whole-frame loss: uniform's PSNR over the whole frame minus CoNUS's;
- aliasing check in the context ring (r..2r): each decoded view against the source low-passed to
  the rate it was sampled at there (a Gaussian of sigma 0.5 / rate source pixels, the rate from
  the map's density), CoNUS and uniform alike: a comb or a staircase shows as error against it;
  and against the source low-passed by each pixel's own footprint ellipse (a Gaussian of sigma
  0.5 * spacing along the Jacobian's singular directions: what the sampling can represent there),
  beside the uniform image at each ring pixel's own density against its own such reference;
- equal bytes (1/16): the CoNUS and uniform images compressed with JPEG XL (cjxl) and JPEG 2000
  (opj_compress), against the full-resolution photograph compressed with either to the same
  bytes. OpenJPEG has no spatial region of interest (its -ROI upshifts a whole component), so the
  full-resolution JPEG 2000 at equal bytes stands for JPEG 2000's own ROI coding;
- gain against loss: foci of k = 2..6, foci of k = 4 with the transition's width and shape swept
  (`--falloff`), and automatic maps from ROI importance (1 in the discs, 0
  elsewhere) with their context floor swept, or chosen by a whole-frame loss budget
  (Map.auto_for_frame_loss, `encode --frame-loss`), and with an anisotropy limit swept: the
  frontier each method reaches; and automatic maps from the picture's own detail (`--importance
  detail`: no region marked) under the same budgets, measured on the marked regions.
- fitted to the decoder (`encode --fit`, `uniform --fit`; codec/image/fit.h): every measure above
  again with both images fitted, CoNUS against the fitted uniform image, and the gain-loss points of
  the foci, the automatic maps and the budgets with the fit.
Photographs: Debian's python3-skimage (astronaut, chelsea, motorcycle), mate-backgrounds (ladybird,
dandelion, garden) and lomiri-wallpapers-16.04 / -20.04 (seven more, quality_targets.UNSEEN), reduced
to at most 1280 px wide by an area filter to keep the run short. The sweeps hold k exact
(`exact_k=True`): they measure what each k gives.
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
from quality_targets import (ALL_PHOTOS as PHOTOS, MAX_WIDTH, defaults_only, discs, linear, read_png,  # noqa: E402
                             scores, srgb8, write_png)

# The photographs and their regions, and the 8-bit sRGB measures: quality_targets.py.
FRACTIONS = [(2, "1/4"), (4, "1/16"), (8, "1/64")]  # side divisor, share of the pixels
K = 4
BUDGETS = [0.5, 1.0, 1.5, 2.0, 2.5, 3.0]  # --frame-loss budgets swept (dB)
BUDGET_GRID, BUDGET_MAX_DENSITY = 129, 64.0
ANISOTROPY_LIMITS = [4.0, 6.0, 8.0, 12.0, 16.0, 24.0]  # --max-anisotropy swept, at the loosest budget
FIT = 4  # --fit iterations (the default of `encode --fit`) of the fitted variant (0: --no-fit leaves it out)
FIT_HOLD = None  # --fit-hold (None: the encoder's default)
METHODS = ("foci", "auto", "budget", "limited", "detail", "falloff", "foci+fit", "falloff+fit", "auto+fit", "budget+fit")
# Foci of k = 4 with their transition's width and shape swept (`--falloff`; "2": the default).
FALLOFFS = ["1.25", "1.5", "1.75", "2", "3", "1.5,log", "1.5,logr", "3,logr"]
QUICK_FALLOFFS = ["1.5", "2", "3,logr"]
# Narrower transitions with the fit (k = 4): the fit keeps their rims from combing (tests/codec/image/comb_test.cpp).
FIT_FALLOFFS = ["1.75", "1.5"]


def psnr(a, b, mask=None):
    d = (a - b) ** 2
    mse = d[mask].mean() if mask is not None else d.mean()
    return 10 * np.log10(1.0 / max(mse, 1e-20))


def ssim(a, b, mask):
    from skimage.metrics import structural_similarity
    _, full = structural_similarity(np.clip(a, 0, 1), np.clip(b, 0, 1), channel_axis=2, data_range=1.0, full=True)
    return float(full[mask].mean())


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


def footprint_sigmas(cmap, size, shape, mask):
    """At each point of `mask`: the Gaussian of the sampling's own footprint, sigma_i = 0.5 *
    spacing_i source pixels along the singular directions of F = diag(W, H) J^-1 diag(1/w, 1/h)
    (J the map's Jacobian by central differences, (w, h) the CoNUS image's size): F takes a step of
    one CoNUS pixel to source pixels. Returns (major sigma, minor sigma, unit major direction (x, y)),
    the sigmas at least 0.5 (a rate of at most one sample per source pixel, as lowpassed())."""
    h, w = shape[:2]
    y, x = np.nonzero(mask)
    p = np.stack([(x + 0.5) / w, (y + 0.5) / h], axis=-1)
    e = 1e-4
    du = (np.asarray(cmap.distort(p + [e, 0])) - np.asarray(cmap.distort(p - [e, 0]))) / (2 * e)
    dv = (np.asarray(cmap.distort(p + [0, e])) - np.asarray(cmap.distort(p - [0, e]))) / (2 * e)
    jac = np.stack([du, dv], axis=-1)  # rows: d(ud, vd); columns: d/du, d/dv
    f = np.linalg.inv(jac) * [1.0 / size[0], 1.0 / size[1]]  # columns scaled: a CoNUS pixel in (u, v)
    f = f * np.array([[w], [h]])  # rows scaled: (u, v) in source pixels
    cov = 0.25 * f @ np.swapaxes(f, 1, 2)  # (0.5 F)(0.5 F)^T
    a, b, c = cov[:, 0, 0], cov[:, 0, 1], cov[:, 1, 1]
    mid, half = 0.5 * (a + c), np.sqrt(0.25 * (a - c) ** 2 + b * b)
    major, minor = np.sqrt(mid + half), np.sqrt(np.maximum(mid - half, 0))
    angle = 0.5 * np.arctan2(2 * b, a - c)
    return np.maximum(major, 0.5), np.maximum(minor, 0.5), np.stack([np.cos(angle), np.sin(angle)], -1), (y, x)


def lowpassed_footprint(source, major, minor, direction, where):
    """The source low-passed at the points `where` (rows, columns) by each point's own elliptical
    Gaussian: an isotropic Gaussian of the minor sigma (the nearest of a stack of blurs a quarter
    octave apart), then a line Gaussian along the major direction for the rest of the major variance,
    taps 1.5 sigma of the stack level apart (bilinear, so no tap skips detail the level keeps)."""
    from scipy.ndimage import gaussian_filter, map_coordinates
    ys, xs = where
    levels = np.exp(np.arange(np.log(0.5), np.log(minor.max()) + 0.3, np.log(2) / 4))
    index = np.clip(np.rint(np.log(minor / levels[0]) / (np.log(2) / 4)).astype(int), 0, len(levels) - 1)
    out = np.zeros((len(ys), source.shape[2]), np.float64)
    for i, s in enumerate(levels):
        pick = np.nonzero(index == i)[0]
        if not len(pick):
            continue
        line = np.sqrt(np.maximum(major[pick] ** 2 - s * s, 0))
        step = 1.5 * s
        taps = np.ceil(3 * line / step).astype(int)
        # Blur only the box these points reach (their taps, and the blur's own reach beyond them).
        reach = int(np.ceil(4 * s + 3 * line.max() + 2))
        y0, y1 = max(0, ys[pick].min() - reach), min(source.shape[0], ys[pick].max() + reach + 1)
        x0, x1 = max(0, xs[pick].min() - reach), min(source.shape[1], xs[pick].max() + reach + 1)
        blurred = gaussian_filter(source[y0:y1, x0:x1], (s, s, 0))
        acc = np.zeros((len(pick), source.shape[2]))
        weight = np.zeros(len(pick))
        for t in range(0, taps.max() + 1):
            live = np.nonzero(taps >= t)[0]
            for sign in ((1,) if t == 0 else (1, -1)):
                d = sign * t * step
                wgt = np.exp(-0.5 * (d / np.maximum(line[live], 1e-9)) ** 2) if t else np.ones(len(live))
                cy = ys[pick[live]] - y0 + d * direction[pick[live], 1]
                cx = xs[pick[live]] - x0 + d * direction[pick[live], 0]
                for ch in range(source.shape[2]):
                    acc[live, ch] += wgt * map_coordinates(blurred[..., ch], [cy, cx], order=1, mode="nearest")
                weight[live] += wgt
        out[pick] = acc / weight[:, None]
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
        pixels = conus.uniform(pixels, size=(MAX_WIDTH, round(h * MAX_WIDTH / w))).pixels
    return np.ascontiguousarray(pixels, np.float32)


def view_of(file, w, h):
    return np.asarray(conus.decode(file, size=(w, h)))[..., :3]


def encode_with(src, size, regions, k=K, map=None, fit=0, falloff=None):
    hold = {} if FIT_HOLD is None else {"fit_hold": FIT_HOLD}
    if map is None and falloff is not None:
        h, w = src.shape[:2]
        map = conus.Map.foci([(u, v, r, k) for u, v, r in regions], aspect=w / h, falloff=falloff)
    if map is not None:
        return conus.encode(src, map=map, size=size, fit=fit, **hold)
    return conus.encode(src, foci=[(u, v, r, k) for u, v, r in regions], size=size, fit=fit, exact_k=True, **hold)


def uniform_view(src, size, fit=0):
    h, w = src.shape[:2]
    return np.asarray(conus.resize(conus.uniform(src, size=size, fit=fit).pixels, size=(w, h)))[..., :3]


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
        # The footprint's own ellipse as the reference: what each sampling can represent there.
        major, minor, direction, where = footprint_sigmas(cfile.map, size, src.shape, ring)
        fp_c = lowpassed_footprint(src, major, minor, direction, where)
        identity = conus.Map.identity(2, 2)
        umajor, uminor, udirection, _ = footprint_sigmas(identity, size, src.shape, ring)
        fp_u = lowpassed_footprint(src, umajor, uminor, udirection, where)
        # Uniform at each ring pixel's own density (the nearest of uniform images a quarter octave
        # of rate apart), each against its own reference: what the local rate alone scores (a finer
        # rate is held to a sharper reference, which holds more detail to miss).
        local = np.asarray(cfile.map.density(points[where]))
        step = np.log(2) / 4
        level = np.rint(np.log(local) / (2 * step)).astype(int)
        dview, fp_d = np.empty((len(local), 3)), np.empty((len(local), 3))
        for lv in np.unique(level):
            pick = np.nonzero(level == lv)[0]
            scale = np.exp(lv * step)
            dsize = (min(w, max(1, round(size[0] * scale))), min(h, max(1, round(size[1] * scale))))
            view = np.asarray(conus.resize(conus.uniform(src, size=dsize).pixels, size=(w, h)))[..., :3]
            dview[pick] = view[where[0][pick], where[1][pick]]
            dmajor, dminor, ddirection, _ = footprint_sigmas(identity, dsize, src.shape, ring)
            fp_d[pick] = lowpassed_footprint(src, dmajor[pick], dminor[pick], ddirection[pick], (where[0][pick], where[1][pick]))
        dense = float(np.mean(local))
        rows.append(dict(photo=name, share=share,
                         roi_c=psnr(cview, src, roi), roi_u=psnr(uview, src, roi),
                         ssim_c=ssim(cview, src, roi), ssim_u=ssim(uview, src, roi),
                         frame_c=psnr(cview, src), frame_u=psnr(uview, src),
                         alias_c=psnr(cview, ring_ref_c, ring), alias_u=psnr(uview, ring_ref_u, ring),
                         fp_c=psnr(cview[where], fp_c), fp_u=psnr(uview[where], fp_u), fp_d=psnr(dview, fp_d), ring_density=dense,
                         ring_anisotropy=float(np.median(major / minor))))
        if FIT:
            fview, ufview = view_of(encode_with(src, size, regions, fit=FIT), w, h), uniform_view(src, size, FIT)
            rows[-1].update(fitted=dict(roi_c=psnr(fview, src, roi), roi_u=psnr(ufview, src, roi),
                                        ssim_c=ssim(fview, src, roi), ssim_u=ssim(ufview, src, roi),
                                        frame_c=psnr(fview, src), frame_u=psnr(ufview, src),
                                        alias_c=psnr(fview, ring_ref_c, ring), alias_u=psnr(ufview, ring_ref_u, ring),
                                        fp_c=psnr(fview[where], fp_c), fp_u=psnr(ufview[where], fp_u), fp_d=psnr(dview, fp_d)))
            if share == "1/16":
                write_png(out / f"{name}-conus-fit.png", srgb8(fview))
        if share == "1/16":
            write_png(out / f"{name}-conus.png", srgb8(cview))
            write_png(out / f"{name}-uniform.png", srgb8(uview))
            rows[-1]["srgb"] = scores(srgb8(cview), srgb8(uview), srgb8(src), regions)
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
        ideal = np.asarray(conus.resize(conus.uniform(src, size=(min(scaled[0], w), min(scaled[1], h))).pixels, size=(w, h)))[..., :3]
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
    points = {"foci": [], "falloff": [], "auto": [], "budget": [], "limited": [], "detail": []}
    if FIT:
        # The fitted variants against the fitted uniform image: the same settings, each map once.
        ufview = uniform_view(src, size, FIT)
        fit_roi, fit_frame = psnr(ufview, src, roi), psnr(ufview, src)
        points.update({"foci+fit": [], "falloff+fit": [], "auto+fit": [], "budget+fit": []})

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
    # The transition's width and shape at k = 4: gain, loss, the map's largest anisotropy
    # (MapMeasures) and the share of the CoNUS image's samples in the regions and in their rings.
    ring = discs(src.shape, regions, 1.0, 2.0)
    y, x = np.mgrid[0:h, 0:w]
    pts = np.stack([(x + 0.5) / w, (y + 0.5) / h], axis=-1)
    for falloff in (QUICK_FALLOFFS if quick else FALLOFFS):
        cfile = encode_with(src, size, regions, falloff=falloff)
        view = view_of(cfile, w, h)
        density = np.asarray(cfile.map.density(pts))
        points["falloff"].append((falloff, ref_frame - psnr(view, src), psnr(view, src, roi) - ref_roi,
                                  cfile.map.measures(w / h)["max_anisotropy"],
                                  density[roi].sum() / density.sum(), density[ring].sum() / density.sum()))
    for falloff in FIT_FALLOFFS:
        add_fitted("falloff+fit", falloff, m=conus.Map.foci([(u, v, r, K) for u, v, r in regions], aspect=w / h, falloff=falloff))
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
    # The picture's own detail (`--importance detail`, conus.importance) instead of the marked
    # regions, under the same budgets: what a user gets who marks nothing, measured on the regions.
    own = np.asarray(conus.importance(src, "detail"))[..., 0]
    for budget in ([1.0, 2.5] if quick else BUDGETS):
        m, floor, p_loss, p_gain = conus.Map.auto_for_frame_loss(own, src, size, budget, grid=BUDGET_GRID,
                                                                 max_density=BUDGET_MAX_DENSITY)
        view = view_of(encode_with(src, size, regions, map=m), w, h)
        points["detail"].append((budget, ref_frame - psnr(view, src), psnr(view, src, roi) - ref_roi, p_loss, p_gain, floor))
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
    small = np.asarray(conus.uniform(src, size=size).pixels)[..., :3]
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
    fig, ax = plt.subplots(figsize=(11, 5))
    for method in [m for m in METHODS if m in next(iter(all_points.values()))]:
        marker = {"foci": "o", "falloff": "v", "auto": "s", "budget": "^", "limited": "D", "detail": "x"}[method.split("+")[0]]
        xs = [np.mean([p[method][i][1] for p in all_points.values()]) for i in range(min(len(p[method]) for p in all_points.values()))]
        ys = [np.mean([p[method][i][2] for p in all_points.values()]) for i in range(len(xs))]
        ax.plot(xs, ys, ("" if method == "falloff" else ":" if method.endswith("+fit") else "-") + marker, label={"foci": "one focus per region, k = 2..6",
                                                "falloff": "k = 4, --falloff " + " ".join(QUICK_FALLOFFS if len(xs) == len(QUICK_FALLOFFS) else FALLOFFS),
                                                "auto": "automatic map from ROI importance, floor swept",
                                                "budget": f"automatic map, --frame-loss budget swept (max density {BUDGET_MAX_DENSITY:g}, grid {BUDGET_GRID})",
                                                "limited": f"the same at {BUDGETS[-1]:g} dB, --max-anisotropy {ANISOTROPY_LIMITS[0]:g}..{ANISOTROPY_LIMITS[-1]:g} swept",
                                                "detail": "automatic map from --importance detail (no region marked), --frame-loss swept",
                                                "foci+fit": f"foci, --fit {FIT} (against uniform --fit {FIT})",
                                                "falloff+fit": f"k = 4, --fit {FIT} --falloff " + " ".join(FIT_FALLOFFS),
                                                "auto+fit": f"automatic map, floor swept, --fit {FIT}",
                                                "budget+fit": f"automatic map, --frame-loss swept, --fit {FIT}"}[method])
    ax.axvline(2.5, color="grey", ls=":")
    ax.axhline(6.5, color="grey", ls=":")
    ax.set_xlabel("whole-frame loss against uniform (dB)")
    ax.set_ylabel("mean ROI gain over uniform (dB)")
    ax.set_title("1/16 of the pixels, mean over the photographs")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.02, 0.5))  # beside the axes: the points stay visible
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
        ring_fp = np.mean([r["fp_u"] - r["fp_c"] for r in sel])
        ring_d = np.mean([r["fp_d"] - r["fp_c"] for r in sel])
        lines.append(f"- {share}: mean ROI gain {gain:+.1f} dB (worst {worst:+.1f}), mean whole-frame loss {loss:.1f} dB, "
                     f"ring check CoNUS {ring:.1f} dB below uniform (isotropic reference), {ring_fp:.1f} dB (footprint reference), "
                     f"{ring_d:.1f} dB below uniform at the local density")
    return lines


def report(rows, all_curves, all_points):
    lines = ["| photo | pixels | ROI PSNR CoNUS / uniform (gain) | ROI SSIM CoNUS / uniform | whole-frame loss | ring vs low-passed source: CoNUS / uniform "
             "| ring vs footprint-filtered source: CoNUS / uniform / uniform at the local density | ring's mean density, median footprint anisotropy |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['photo']} | {r['share']} | {r['roi_c']:.1f} / {r['roi_u']:.1f} ({r['roi_c'] - r['roi_u']:+.1f}) | "
                     f"{r['ssim_c']:.3f} / {r['ssim_u']:.3f} | {r['frame_u'] - r['frame_c']:.1f} dB | {r['alias_c']:.1f} / {r['alias_u']:.1f} | "
                     f"{r['fp_c']:.1f} / {r['fp_u']:.1f} / {r['fp_d']:.1f} | {r['ring_density']:.2f}, {r['ring_anisotropy']:.2f} |")
    lines.append("")
    lines += summary(rows)
    lines += ["", "8-bit sRGB at 1/16 (quality_targets.py's measures)", "",
              "| photo | ROI gain (worst ROI) | ROI SSIM CoNUS / uniform | whole-frame loss | tile loss outside the regions: p95 / worst |",
              "|---|---|---|---|---|"]
    for r in rows:
        if "srgb" in r:
            g = r["srgb"]
            lines.append(f"| {r['photo']} | {g['roi_gain']:+.2f} ({g['worst_roi']:+.2f}) | {g['roi_ssim'][0]:.3f} / {g['roi_ssim'][1]:.3f} | "
                         f"{g['frame_loss']:.2f} dB | {g['tile95']:.2f} / {g['tile_worst']:.2f} dB |")
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
            name = {"foci": "k", "falloff": "k 4, falloff", "auto": "floor", "budget": "frame-loss", "limited": "max-anisotropy",
                    "detail": "frame-loss"}[method.split("+")[0]]
            line = f"- {method} {name} {setting}: loss {loss:.2f} dB, gain {gain:+.2f} dB (worst photo {worst:+.2f})"
            if method == "falloff":
                line += "; max anisotropy " + ", ".join(f"{p[method][i][3]:.1f}" for p in all_points.values())
                line += (f"; samples in the regions {100 * np.mean([p[method][i][4] for p in all_points.values()]):.1f}%, "
                         f"in r..2r {100 * np.mean([p[method][i][5] for p in all_points.values()]):.1f}%")
            if method in ("budget", "limited", "budget+fit", "detail"):
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
    parser.add_argument("--defaults-only", action="store_true",
                        help="only the targets table of `conus encode`'s defaults, 8-bit sRGB (minutes)")
    parser.add_argument("--encode-args", default="", help="with --defaults-only: more `conus encode` options (e.g. '--fast')")
    parser.add_argument("--detail", action="store_true", help="with --defaults-only: `--importance detail` as a row too")
    parser.add_argument("--photos", default="", help="with --defaults-only: a comma-separated subset of the photographs")
    args = parser.parse_args()
    if args.defaults_only:
        out = pathlib.Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        photos = [p for p in PHOTOS if not args.photos or p[0] in args.photos.split(",")]
        defaults_only(conus, ROOT / "build" / "bin" / "conus", out, photos, args.encode_args.split(), args.detail)
        return
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
            sys.exit(f"bench/quality.py: {path} is missing (apt-get install python3-skimage mate-backgrounds "
                     "lomiri-wallpapers-16.04 lomiri-wallpapers-20.04)")
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
