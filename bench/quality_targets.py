"""The targets table of `bench/quality.py --defaults-only`: what the `conus` program gives with its
defaults, measured the way image codecs are compared (8-bit sRGB pictures), in minutes.

Every picture goes through the real binary as a user runs it: the photograph reduced to at most
MAX_WIDTH px wide and written as an 8-bit sRGB PNG; `conus uniform` (the baseline) and `conus
encode` with its defaults, with one `--focus u,v,r,4` per region, with `--importance` of an image
that is 1 in the regions and 0 elsewhere, and with nothing (the no-focus default); each CoNUS file
decoded to the source's size by the CPU decoder, the uniform one by a bilinear resize. On the
8-bit sRGB pictures a user looks at (and each beside `conus uniform --fit`, the baseline fitted alike):
- ROI: PSNR and SSIM inside each region (a disc of radius r, a fraction of the width);
- whole frame: PSNR and SSIM; loss = uniform's PSNR minus CoNUS's;
- tiles outside the regions: tiles of max(W, H) / 32 px that touch no region, each with loss
  10 log10((mse_conus + e) / (mse_uniform + e)), e = (2/255)^2 (values in [0, 1]): the 95th
  percentile and the worst.
A contact sheet per photograph (source | default encode | uniform, whole frames) goes to DIR, and
every row with the run's stamp (date, commit, machine) to DIR/targets.json, from which
bench/make_readme_tables.py makes the README's table.
"""
import json
import pathlib
import re
import subprocess
import tempfile
import time

import numpy as np

from run_stamp import run_stamp

SKIMAGE = pathlib.Path("/usr/lib/python3/dist-packages/skimage/data")
MATE = pathlib.Path("/usr/share/backgrounds/mate/nature")
LOMIRI = pathlib.Path("/usr/share/backgrounds")  # lomiri-wallpapers-16.04 and -20.04
# name, file, regions (u, v, r): r a fraction of the width; marked by looking at each picture.
PHOTOS = [
    ("astronaut", SKIMAGE / "astronaut.png", [(0.44, 0.23, 0.08), (0.33, 0.75, 0.06)]),
    ("chelsea", SKIMAGE / "chelsea.png", [(0.37, 0.38, 0.07), (0.71, 0.45, 0.07)]),
    ("motorcycle", SKIMAGE / "motorcycle_left.png", [(0.55, 0.62, 0.08), (0.72, 0.31, 0.05)]),
    ("ladybird", MATE / "LadyBird.jpg", [(0.70, 0.50, 0.05)]),
    ("dandelion", MATE / "TwoWings.jpg", [(0.50, 0.45, 0.07), (0.74, 0.40, 0.06)]),
    ("garden", MATE / "Garden.jpg", [(0.55, 0.55, 0.09)]),
]
# Photographs the measures above were not tuned on (Debian lomiri-wallpapers-16.04 / -20.04):
# two dog faces each filling about a fifth of the width, a fig in a bowl, a nuthatch on a trunk,
# wine and a coffee grinder at the right border, a dragonfly, a dandelion at the top border, and
# paint brushes at the left border.
UNSEEN = [
    ("dogs", LOMIRI / "friends_by_Aitzol_Berasategi.jpg", [(0.41, 0.30, 0.15), (0.56, 0.53, 0.15)]),
    ("fig", LOMIRI / "Picture_0B_by_freespace.jpg", [(0.585, 0.55, 0.12)]),
    ("nuthatch", LOMIRI / "Kleiber_by_Lukas_Baubkus.jpg", [(0.46, 0.50, 0.08)]),
    ("wine", LOMIRI / "Wine_by_Jakkub_Mede.jpg", [(0.45, 0.24, 0.10), (0.81, 0.26, 0.08)]),
    ("dragonfly", LOMIRI / "Dragonfly_by_Bolly.jpg", [(0.58, 0.40, 0.14)]),
    ("seeding", LOMIRI / "seeding_by_Clements_Engelhardt.jpg", [(0.29, 0.32, 0.16)]),
    ("brushes", LOMIRI / "Picture_1A_by_freespace.jpg", [(0.42, 0.50, 0.10), (0.12, 0.24, 0.11)]),
]
ALL_PHOTOS = PHOTOS + UNSEEN
MAX_WIDTH = 1280
K = 4
E = (2 / 255) ** 2


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


def discs(shape, regions, inner=0.0, outer=1.0):
    """Mask of the points within (inner*r, outer*r] of any region's centre (r in widths)."""
    h, w = shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    mask = np.zeros((h, w), bool)
    for u, v, r in regions:
        d = np.hypot(x + 0.5 - u * w, y + 0.5 - v * h) / (r * w)
        mask |= (d > inner) & (d <= outer)
    return mask


def psnr8(a, b, mask=None):
    """PSNR (dB) of two 8-bit pictures, over `mask` when given."""
    d = (a.astype(np.float64) - b.astype(np.float64)) ** 2
    mse = d[mask].mean() if mask is not None else d.mean()
    return 10 * np.log10(255.0 ** 2 / max(mse, 1e-10))


def ssim8(a, b, masks):
    """SSIM of two 8-bit pictures (skimage, 7x7 windows, the channels' mean), over each mask."""
    from skimage.metrics import structural_similarity
    _, full = structural_similarity(a, b, channel_axis=2, data_range=255, full=True)
    full = full.mean(axis=2)
    return [float(full[m].mean()) if m is not None else float(full.mean()) for m in masks]


def tile_losses(conus8, uniform8, source8, roi):
    """Loss of each tile of max(W, H)/32 px touching no region (10 log10 of the MSE ratio, e added)."""
    h, w = source8.shape[:2]
    t = max(1, max(w, h) // 32)
    sc = ((conus8.astype(np.float64) - source8) / 255) ** 2
    su = ((uniform8.astype(np.float64) - source8) / 255) ** 2
    out = []
    for y in range(0, h, t):
        for x in range(0, w, t):
            if roi[y:y + t, x:x + t].any():
                continue
            out.append(10 * np.log10((sc[y:y + t, x:x + t].mean() + E) / (su[y:y + t, x:x + t].mean() + E)))
    return np.array(out)


def scores(view8, uniform8, source8, regions, tiles_everywhere=False):
    """The row of one encode against the uniform picture, all on 8-bit sRGB (the tiles: those
    touching no region, or every tile)."""
    roi = discs(source8.shape, regions)
    masks = [discs(source8.shape, [r]) for r in regions]
    gains = [psnr8(view8, source8, m) - psnr8(uniform8, source8, m) for m in masks]
    s_c = ssim8(view8, source8, [roi, None])
    s_u = ssim8(uniform8, source8, [roi, None])
    tiles = tile_losses(view8, uniform8, source8, np.zeros_like(roi) if tiles_everywhere else roi)
    return dict(roi_gain=psnr8(view8, source8, roi) - psnr8(uniform8, source8, roi), worst_roi=min(gains),
                frame_loss=psnr8(uniform8, source8) - psnr8(view8, source8),
                roi_ssim=(s_c[0], s_u[0]), frame_ssim=(s_c[1], s_u[1]),
                tile95=float(np.percentile(tiles, 95)) if len(tiles) else 0.0,
                tile_worst=float(tiles.max()) if len(tiles) else 0.0)


def run(binary, args):
    """Runs `conus` with args; returns (what it said: stdout and the warnings, wall seconds)."""
    start = time.monotonic()
    r = subprocess.run([str(binary)] + [str(a) for a in args], capture_output=True, text=True)
    wall = time.monotonic() - start
    if r.returncode != 0:
        raise RuntimeError(f"conus {' '.join(map(str, args))}: {r.stderr.strip()}")
    return r.stdout + "".join(line + "\n" for line in r.stderr.splitlines() if "warning:" in line), wall


def decoded8(conus, path, w, h):
    return srgb8(np.asarray(conus.decode(conus.read(str(path)), size=(w, h)))[..., :3])


def measure_photo(conus, binary, name, path, regions, out, extra_args=(), detail=False):
    """The default encodes of one photograph against `conus uniform`: a dict of rows by method."""
    pixels, _ = conus.read_image(str(path))
    pixels = np.ascontiguousarray(pixels[..., :3], np.float32)
    h, w = pixels.shape[:2]
    if w > MAX_WIDTH:
        pixels = conus.uniform(pixels, size=(MAX_WIDTH, round(h * MAX_WIDTH / w))).pixels
    source8 = srgb8(np.asarray(pixels))
    h, w = source8.shape[:2]
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        src = work / f"{name}.png"
        write_png(src, source8)
        importance = work / "roi.png"
        write_png(importance, np.repeat((discs(source8.shape, regions) * 255).astype(np.uint8)[..., None], 3, axis=2))
        run(binary, ["uniform", src, "-o", work / "u.exr", "-q"])
        uniform8 = srgb8(np.asarray(conus.resize(np.asarray(conus.read(str(work / "u.exr")).pixels)[..., :3], size=(w, h))))
        # The baseline fitted the same way (`uniform --fit`): what the fit alone gives, like for like.
        run(binary, ["uniform", src, "-o", work / "uf.exr", "--fit", "-q"])
        fitted8 = srgb8(np.asarray(conus.resize(np.asarray(conus.read(str(work / "uf.exr")).pixels)[..., :3], size=(w, h))))
        foci = [a for u, v, r in regions for a in ("--focus", f"{u},{v},{r},{K}")]
        methods = [("foci", foci), ("importance", ["--importance", importance]), ("no focus", [])]
        if detail:  # the detail map asked for by name, beside whatever the no-focus default is
            methods.append(("detail", ["--importance", "detail"]))
        for method, args in methods:
            try:
                text, wall = run(binary, ["encode", src, "-o", work / "c.exr"] + list(args) + list(extra_args))
            except RuntimeError as e:  # a refusal is a result: the row says so
                rows[method] = dict(refused=str(e).splitlines()[-1])
                continue
            view8 = decoded8(conus, work / "c.exr", w, h)
            everywhere = method in ("no focus", "detail")  # no region was given: every tile counts
            rows[method] = dict(scores(view8, uniform8, source8, regions, everywhere), wall=wall, said=said(text),
                                vs_fit=scores(view8, fitted8, source8, regions, everywhere))
            if method == "foci":
                sheet = np.concatenate([source8, np.full((h, 8, 3), 255, np.uint8), view8,
                                        np.full((h, 8, 3), 255, np.uint8), uniform8], axis=1)
                write_png(out / f"{name}-sheet.png", sheet)
    return rows


def said(text):
    """What `conus encode` said about the map and the budget: its lines but 'wrote', and the k the
    'wrote' line gives in brackets."""
    lines = [line.strip() for line in text.splitlines() if line.strip() and not line.startswith("wrote")]
    given = [m.group(1) for m in re.finditer(r"sampling map \(([^)]*)\)", text)]
    return " / ".join(lines + given).replace("|", "/")


def table(results):
    """Markdown: a row per photograph and method, then the means and the targets."""
    lines = ["| photo | method | ROI gain (worst ROI) | ROI SSIM CoNUS / uniform | whole-frame loss | frame SSIM CoNUS / uniform "
             "| tile loss p95 / worst | against `uniform --fit`: ROI gain, frame loss, tile p95 | encode s | what encode said |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name, rows in results.items():
        for method, r in rows.items():
            if "refused" in r:
                lines.append(f"| {name} | {method} | refused: {r['refused']} | | | | | | | |")
                continue
            lines.append(f"| {name} | {method} | {r['roi_gain']:+.2f} ({r['worst_roi']:+.2f}) | {r['roi_ssim'][0]:.3f} / {r['roi_ssim'][1]:.3f} "
                         f"| {r['frame_loss']:.2f} dB | {r['frame_ssim'][0]:.3f} / {r['frame_ssim'][1]:.3f} "
                         f"| {r['tile95']:.2f} / {r['tile_worst']:.2f} dB "
                         f"| {r['vs_fit']['roi_gain']:+.2f}, {r['vs_fit']['frame_loss']:.2f}, {r['vs_fit']['tile95']:.2f} dB "
                         f"| {r['wall']:.2f} | {r['said']} |")
    lines.append("")
    for method in next(iter(results.values())):
        sel = [rows[method] for rows in results.values() if "refused" not in rows[method]]
        refused = len(results) - len(sel)
        if not sel:
            lines.append(f"- {method}: refused on every photograph")
            continue
        lines.append(f"- {method}: " + (f"refused on {refused} of {len(results)} photographs; the others: " if refused else ""))
        lines[-1] += (f"mean ROI gain {np.mean([r['roi_gain'] for r in sel]):+.2f} dB, worst ROI "
                     f"{min(r['worst_roi'] for r in sel):+.2f} dB, whole-frame loss mean {np.mean([r['frame_loss'] for r in sel]):.2f} dB "
                     f"(worst {max(r['frame_loss'] for r in sel):.2f}), tile loss p95 worst photo {max(r['tile95'] for r in sel):.2f} dB "
                     f"(worst tile {max(r['tile_worst'] for r in sel):.2f} dB); against `uniform --fit`: ROI gain "
                     f"{np.mean([r['vs_fit']['roi_gain'] for r in sel]):+.2f} dB, whole-frame loss {np.mean([r['vs_fit']['frame_loss'] for r in sel]):.2f} dB "
                     f"(worst {max(r['vs_fit']['frame_loss'] for r in sel):.2f}), tile p95 worst {max(r['vs_fit']['tile95'] for r in sel):.2f} dB")
    return "\n".join(lines) + "\n"


def contact_sheet(out, names):
    """All the per-photo sheets in one PNG (each scaled to 1200 px wide), and a half-size copy
    (contact-sheet-600.png, the one bench/README.md shows)."""
    from PIL import Image
    tiles = []
    for name in names:
        if not (out / f"{name}-sheet.png").exists():
            continue
        im = Image.open(out / f"{name}-sheet.png")
        tiles.append(im.resize((1200, max(1, round(im.height * 1200 / im.width))), Image.LANCZOS))
    sheet = Image.new("RGB", (1200, sum(t.height + 8 for t in tiles)), "white")
    y = 0
    for t in tiles:
        sheet.paste(t, (0, y))
        y += t.height + 8
    sheet.save(out / "contact-sheet.png")
    sheet.resize((600, round(sheet.height / 2)), Image.BOX).save(out / "contact-sheet-600.png")


def defaults_only(conus, binary, out, photos=ALL_PHOTOS, extra_args=(), detail=False):
    stamp, start = run_stamp(), time.monotonic()
    results = {}
    for name, path, regions in photos:
        if not path.exists():
            raise SystemExit(f"bench/quality.py: {path} is missing (scripts/packages.txt: python3-skimage, mate-backgrounds, "
                             "lomiri-wallpapers-16.04, lomiri-wallpapers-20.04)")
        print(f"== {name}", flush=True)
        results[name] = measure_photo(conus, binary, name, path, regions, out, extra_args, detail)
    text = table(results)
    (out / "targets.md").write_text(text)
    (out / "targets.json").write_text(json.dumps({"stamp": stamp, "seconds": time.monotonic() - start,
                                                  "encode_args": list(map(str, extra_args)), "results": results}, indent=1))
    contact_sheet(out, [n for n, _, _ in photos])
    print(text)
    print(f"wrote {out / 'targets.md'}, {out / 'targets.json'}, {out / 'contact-sheet.png'}")
    return results
