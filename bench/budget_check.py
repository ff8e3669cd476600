#!/usr/bin/python3
"""The loss budget's prediction against real encodes, per photograph, in one run:
`bench/budget_check.py [--out DIR] [--fit] [--photos NAME,...]`.

For each photograph (reduced to at most 1280 px wide, written as an 8-bit sRGB PNG, as
bench/quality_targets.py does) `conus encode` runs with its defaults and one `--focus u,v,r,4` per
region; what it printed (the whole-frame loss, the 95th percentile of the tiles outside the foci
and the foci's gain, 'measured by the encode kept' or 'predicted', the column 'printed as') is set beside what the
decoded file loses against `conus uniform` of the same pixel count on 8-bit sRGB
(quality_targets.scores). Targets: printed within 0.5 dB of measured for the frame and 1 dB for the
p95 tile; measured frame loss within the budget and p95 tile loss <= 4 dB. The photographs:
bench/quality_targets.PHOTOS (the model's constants were fitted on these: the 'fitted' set), its
UNSEEN ones and HELD_OUT below, on which nothing was fitted; the summary gives the two apart.

`--fast`: the same with `encode --fast`, whose budget is the model alone (no confirming encode).

`--fit`: the data the constants of codec/src/builders/frame_budget.cpp were fitted on and the fit
itself: on the fitting photographs, encodes with `--exact-k` at several k (and with `--fast`), each
tile's measured mean squared error of the CoNUS and the uniform image beside the model's terms (the
picture's box-pyramid band energies, the map's Jacobian at 3x3 points of the tile), and the
constants a, b (per image kind) and c (shared) minimizing the squared error of log(e + f) over the tiles.
"""
import argparse
import json
import pickle
import pathlib
import re
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "build" / "python"))
sys.path.insert(0, str(ROOT / "bench"))
import conus  # noqa: E402  (the package built by cmake)
from quality_targets import E, MAX_WIDTH, PHOTOS, UNSEEN, discs, run, scores, srgb8, write_png  # noqa: E402

BINARY = ROOT / "build" / "bin" / "conus"
BACKGROUNDS = pathlib.Path("/usr/share/backgrounds")
MATE = BACKGROUNDS / "mate" / "nature"
# Photographs nothing was fitted or tuned on (Debian lomiri-wallpapers and mate-backgrounds, already
# in scripts/packages.txt); the foci are placed on each picture's subject by eye.
HELD_OUT = [
    ("bridge", BACKGROUNDS / "Bridge_by_Sander_Klootwijk.jpg", [(0.50, 0.45, 0.10)]),
    ("aitzgorri", BACKGROUNDS / "aitzgorri_by_Aitzol_Berasategi.jpg", [(0.50, 0.45, 0.10)]),
    ("sunset", BACKGROUNDS / "sunset_by_Aitzol_Berasategi.jpg", [(0.50, 0.50, 0.10)]),
    ("umang", BACKGROUNDS / "umang_by_Abhishek_Mudgal.jpg", [(0.50, 0.50, 0.10)]),
    ("meadow", MATE / "GreenMeadow.jpg", [(0.45, 0.55, 0.08), (0.70, 0.35, 0.06)]),
    ("raindrops", MATE / "RainDrops.jpg", [(0.50, 0.50, 0.10)]),
    ("wood", MATE / "Wood.jpg", [(0.35, 0.45, 0.08), (0.65, 0.55, 0.08)]),
    ("yellowflower", MATE / "YellowFlower.jpg", [(0.50, 0.50, 0.10)]),
]
FIT_K = [1.5, 2.5, 4.0, 6.0]
TILES = 32
LEVELS = 9
BUDGET_FRAME_DEFAULT, BUDGET_TILE = 1.5, 4.0  # encode's defaults (codec::kDefaultFrameLoss, kDefaultTileLoss)


def source8(name, path):
    pixels, _ = conus.read_image(str(path))
    pixels = np.ascontiguousarray(pixels[..., :3], np.float32)
    h, w = pixels.shape[:2]
    if w > MAX_WIDTH:
        pixels = conus.uniform(pixels, size=(MAX_WIDTH, round(h * MAX_WIDTH / w))).pixels
    return srgb8(np.asarray(pixels))


def decoded8(path, w, h):
    f = conus.read(str(path))
    return srgb8(np.asarray(conus.decode(f, size=(w, h)))[..., :3]), f


def uniform8(work, src, w, h):
    run(BINARY, ["uniform", src, "-o", work / "u.exr", "-q"])
    return srgb8(np.asarray(conus.resize(np.asarray(conus.read(str(work / "u.exr")).pixels)[..., :3], size=(w, h))))


def predicted(text):
    """The whole-frame loss and p95 tile loss the encode printed (dB; a gain is a negative loss)."""
    def value(pattern):
        m = re.search(pattern, text)
        if not m:
            raise RuntimeError(f"the encode did not print /{pattern}/:\n{text}")
        v = float(m.group(2))
        return -v if m.group(1) in ("gains", "gain") else v
    said = re.search(r"\n  (predicted|measured by the encode kept): the whole frame", text)
    roi = re.search(r"the foci gain ([-0-9.]+) dB", text)
    return (value(r"whole frame (loses|gains) ([-0-9.]+) dB"),
            value(r"tiles outside the foci (lose|gain) ([-0-9.]+) dB"),
            "measured" if said and said.group(1).startswith("measured") else "predicted",
            float(roi.group(1)) if roi else float("nan"))


def roi_text(r):
    """The ROI gain printed against measured (the encode prints none where it cannot predict it)."""
    if np.isnan(r["predicted_roi"]):
        return f"not printed / {r['roi_gain']:+.2f}"
    return f"{r['predicted_roi']:+.2f} / {r['roi_gain']:+.2f} ({r['predicted_roi'] - r['roi_gain']:+.2f})"


def check(photos, out, extra=()):
    rows = []
    for group, name, path, regions in photos:
        s8 = source8(name, path)
        h, w = s8.shape[:2]
        with tempfile.TemporaryDirectory() as tmp:
            work = pathlib.Path(tmp)
            src = work / f"{name}.png"
            write_png(src, s8)
            u8 = uniform8(work, src, w, h)
            foci = [a for u, v, r in regions for a in ("--focus", f"{u},{v},{r},4")]
            text, wall = run(BINARY, ["encode", src, "-o", work / "c.exr"] + foci + list(extra))
            c8, _ = decoded8(work / "c.exr", w, h)
            m = scores(c8, u8, s8, regions)
            pf, pt, said, pr = predicted(text)
            ks = ", ".join(re.findall(r": k ([0-9.]+) \(asked", text))
            rows.append(dict(group=group, name=name, size=f"{w}x{h}", k=ks, predicted_frame=pf,
                             measured_frame=m["frame_loss"], predicted_tile=pt, measured_tile=m["tile95"],
                             roi_gain=m["roi_gain"], predicted_roi=pr, wall=wall, said=said))
        r = rows[-1]
        print(f"{group:8} {name:12} k {r['k']:12} frame {r['predicted_frame']:+.2f} / {r['measured_frame']:+.2f} dB  "
              f"tile p95 {r['predicted_tile']:+.2f} / {r['measured_tile']:+.2f} dB  ROI {roi_text(r)} dB  "
              f"{wall:.1f} s", flush=True)
    lines = ["| set | photo | size | k given | printed as | frame loss printed / measured (diff) | p95 tile loss printed / measured (diff) "
             "| ROI gain printed / measured (diff) | encode s |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        df, dt = r["predicted_frame"] - r["measured_frame"], r["predicted_tile"] - r["measured_tile"]
        lines.append(f"| {r['group']} | {r['name']} | {r['size']} | {r['k']} | {r['said']} | {r['predicted_frame']:+.2f} / "
                     f"{r['measured_frame']:+.2f} ({df:+.2f}) | {r['predicted_tile']:+.2f} / {r['measured_tile']:+.2f} ({dt:+.2f}) | "
                     f"{roi_text(r)} | {r['wall']:.1f} |")
    lines.append("")
    # The set the constants were fitted on, and the others (unseen and held-out: nothing fitted on them), apart.
    for label, subset in (("fitted", [r for r in rows if r["group"] == "fitted"]),
                          ("not fitted on (unseen, held-out)", [r for r in rows if r["group"] != "fitted"])):
        if not subset:
            continue
        df = np.array([r["predicted_frame"] - r["measured_frame"] for r in subset])
        dt = np.array([r["predicted_tile"] - r["measured_tile"] for r in subset])
        dr = np.array([r["predicted_roi"] - r["roi_gain"] for r in subset if not np.isnan(r["predicted_roi"])])
        lines += [f"- {label}: frame printed within 0.5 dB of measured on {sum(abs(d) <= 0.5 for d in df)} of {len(subset)} "
                  f"(mean |diff| {np.abs(df).mean():.2f} dB, worst {df[np.abs(df).argmax()]:+.2f} dB); p95 tile within 1 dB on "
                  f"{sum(abs(d) <= 1.0 for d in dt)} of {len(subset)} (mean |diff| {np.abs(dt).mean():.2f} dB, worst "
                  f"{dt[np.abs(dt).argmax()]:+.2f} dB); measured frame loss over the {BUDGET_FRAME_DEFAULT} dB budget on "
                  f"{sum(r['measured_frame'] > BUDGET_FRAME_DEFAULT for r in subset)}, p95 tile loss over {BUDGET_TILE} dB on "
                  f"{sum(r['measured_tile'] > BUDGET_TILE for r in subset)}; "
                  + (f"ROI gain printed within 1 dB of measured on {sum(abs(d) <= 1.0 for d in dr)} of {len(dr)} (mean |diff| "
                     f"{np.abs(dr).mean():.2f} dB, worst {dr[np.abs(dr).argmax()]:+.2f} dB)" if len(dr) else "no ROI gain printed")]
    lines += [f"- measured: worst frame loss {max(r['measured_frame'] for r in rows):.2f} dB, worst p95 tile loss "
              f"{max(r['measured_tile'] for r in rows):.2f} dB; mean ROI gain {np.mean([r['roi_gain'] for r in rows]):+.2f} dB; "
              f"printed as measured on {sum(r['said'] == 'measured' for r in rows)} of {len(rows)}"]
    text = "\n".join(lines) + "\n"
    (out / "budget_check.md").write_text(text)
    (out / "budget_check.json").write_text(json.dumps(rows, indent=1))
    print(text)
    return rows


# --- the fit ---------------------------------------------------------------------------------

def display(s8):
    return s8.astype(np.float64) / 255


def tile_grid(w, h):
    t = max(1, max(w, h) // TILES)
    return t, -(-w // t), -(-h // t)


def band_energies(s8):
    """Per tile, the box pyramid's band energies (frame_budget.cpp's, on 8-bit sRGB / 255)."""
    h, w = s8.shape[:2]
    t, cols, rows = tile_grid(w, h)
    out = np.zeros((rows, cols, LEVELS))
    level = display(s8)
    for j in range(LEVELS):
        lh, lw = level.shape[0] // 2, level.shape[1] // 2
        if lh < 1 or lw < 1:
            break
        c = level[:2 * lh, :2 * lw].reshape(lh, 2, lw, 2, -1)
        mean = c.mean(axis=(1, 3))
        energy = ((c - mean[:, None, :, None]) ** 2).mean(axis=(1, 3)).mean(axis=-1)
        cell = 2 ** (j + 1)
        full = np.zeros((h, w))  # each cell's energy over the source pixels it covers
        full[:lh * cell, :lw * cell] = np.kron(energy, np.ones((cell, cell)))[:h, :w]
        padded = np.zeros((rows * t, cols * t))
        padded[:h, :w] = full
        out[:, :, j] = padded.reshape(rows, t, cols, t).sum(axis=(1, 3))
        level = mean
    counts = np.zeros((rows * t, cols * t))
    counts[:h, :w] = 1
    n = counts.reshape(rows, t, cols, t).sum(axis=(1, 3))
    return out / n[..., None], n


def tile_mse(view8, s8):
    h, w = s8.shape[:2]
    t, cols, rows = tile_grid(w, h)
    d = (((view8.astype(np.float64) - s8) / 255) ** 2).mean(axis=-1)
    padded = np.zeros((rows * t, cols * t))
    padded[:h, :w] = d
    counts = np.zeros_like(padded)
    counts[:h, :w] = 1
    return padded.reshape(rows, t, cols, t).sum(axis=(1, 3)) / counts.reshape(rows, t, cols, t).sum(axis=(1, 3))


def footprints(f, w, h, sw, sh):
    """Per tile, the footprint axes (source pixels per sample, largest first) at 3x3 points of it."""
    t, cols, rows = tile_grid(sw, sh)
    pts = []
    for ty in range(rows):
        for tx in range(cols):
            x0, y0 = tx * t, ty * t
            tw, th = min(sw, x0 + t) - x0, min(sh, y0 + t) - y0
            for j in range(3):
                for i in range(3):
                    pts.append(((x0 + (i + 0.5) / 3 * tw) / sw, (y0 + (j + 0.5) / 3 * th) / sh))
    p = np.array(pts)
    eps = 1e-4
    m = f.map
    du = (np.asarray(m.distort(np.clip(p + [eps, 0], 0, 1))) - np.asarray(m.distort(np.clip(p - [eps, 0], 0, 1)))) / (2 * eps)
    dv = (np.asarray(m.distort(np.clip(p + [0, eps], 0, 1))) - np.asarray(m.distort(np.clip(p - [0, eps], 0, 1)))) / (2 * eps)
    a, b = w * du[:, 0] / sw, w * dv[:, 0] / sh
    c, d = h * du[:, 1] / sw, h * dv[:, 1] / sh
    s1 = a * a + b * b + c * c + d * d
    det = np.abs(a * d - b * c)
    root = np.sqrt(np.maximum(0, s1 * s1 - 4 * det * det))
    l1, l2 = np.sqrt(0.5 * (s1 + root)), np.sqrt(np.maximum(1e-18, 0.5 * (s1 - root)))
    return np.stack([1 / l2, 1 / l1], axis=-1).reshape(rows, cols, 9, 2)


def model(bands, sigma, a, b, c):
    """a * mean over the footprint's axes and points of sum_j E_j R(log2 sigma - j - b), R a
    smoothstep from -c to c."""
    j = np.arange(bands.shape[-1])
    l = np.log2(sigma)[..., None] - b - j  # (..., points, 2, levels)
    x = np.clip((l + c) / (2 * c), 0, 1)
    r = x * x * (3 - 2 * x)
    return a * (bands[..., None, None, :] * r).sum(axis=-1).mean(axis=(-1, -2))


def collect(photos):
    data = []
    for name, path, regions in photos:
        s8 = source8(name, path)
        h, w = s8.shape[:2]
        bands, _ = band_energies(s8)
        with tempfile.TemporaryDirectory() as tmp:
            work = pathlib.Path(tmp)
            src = work / f"{name}.png"
            write_png(src, s8)
            u8 = uniform8(work, src, w, h)
            uf = conus.read(str(work / "u.exr"))
            cw, ch = uf.pixels.shape[1], uf.pixels.shape[0]
            su = np.full(bands.shape[:2] + (9, 2), 0.0)
            su[..., 0], su[..., 1] = max(w / cw, h / ch), min(w / cw, h / ch)
            data.append(dict(kind="uniform", name=name, k=0, bands=bands, sigma=su, mse=tile_mse(u8, s8)))
            for fast in (False, True):
                for k in FIT_K:
                    foci = [a for u, v, r in regions for a in ("--focus", f"{u},{v},{r},{k}")]
                    run(BINARY, ["encode", src, "-o", work / "c.exr", "--exact-k", "-q"] + foci + (["--fast"] if fast else []))
                    c8, f = decoded8(work / "c.exr", w, h)
                    data.append(dict(kind="fast" if fast else "fitted", name=name, k=k, bands=bands,
                                     sigma=footprints(f, cw, ch, w, h), mse=tile_mse(c8, s8)))
            print(f"collected {name}", flush=True)
    return data


def fit(data):
    out = {}
    best_total = None
    for c in [0.5, 0.75, 1.0, 1.25, 1.5]:
        total, found = 0.0, {}
        for kind in ("uniform", "fitted", "fast"):
            rows = [d for d in data if d["kind"] == kind]
            best = None
            for b in np.arange(-1.5, 1.51, 0.05):
                s = np.concatenate([model(d["bands"], d["sigma"], 1.0, b, c).ravel() for d in rows])
                m = np.concatenate([d["mse"].ravel() for d in rows])
                for la in np.arange(-1.5, 1.51, 0.02):
                    a = 10 ** la
                    err = ((np.log10(a * s + E) - np.log10(m + E)) ** 2).mean()
                    if best is None or err < best[0]:
                        best = (err, a, b)
            found[kind] = best
            total += best[0]
        print(f"c {c}: " + ", ".join(f"{k} a {v[1]:.3f} b {v[2]:+.2f} rms {10 * np.sqrt(v[0]):.2f} dB" for k, v in found.items()))
        if best_total is None or total < best_total[0]:
            best_total = (total, c, found)
    _, c, found = best_total
    out = dict(c=c, **{k: dict(a=v[1], b=v[2], rms_db=10 * np.sqrt(v[0])) for k, v in found.items()})
    print(json.dumps(out, indent=1))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=str(ROOT / "build" / "budget"))
    ap.add_argument("--fit", action="store_true", help="fit the model's constants on the fitting photographs")
    ap.add_argument("--photos", help="only these (names, comma-separated)")
    ap.add_argument("--fast", action="store_true", help="encode with --fast (the model alone: no confirming encode)")
    ap.add_argument("--reuse", action="store_true", help="with --fit: fit again on the data of the last --fit run")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    chosen = set(args.photos.split(",")) if args.photos else None
    if args.fit:
        photos = [p for p in PHOTOS if not chosen or p[0] in chosen]
        cache = out / "fit-data.pickle"
        if args.reuse and cache.exists():
            data = pickle.loads(cache.read_bytes())
        else:
            data = collect(photos)
            cache.write_bytes(pickle.dumps(data))
        (out / "fit.json").write_text(json.dumps(fit(data), indent=1))
        return
    photos = ([("fitted", *p) for p in PHOTOS] + [("unseen", *p) for p in UNSEEN] + [("held-out", *p) for p in HELD_OUT])
    check([p for p in photos if not chosen or p[1] in chosen], out, ["--fast"] if args.fast else [])


if __name__ == "__main__":
    main()
