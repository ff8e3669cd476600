#!/usr/bin/python3
"""CoNUS in the browser against deep zoom (bench/README.md, "In the browser").

To show a 4096^2 photograph's whole frame (at 1024x1024) plus a region of interest at full detail:
- CoNUS: one request, one file (`conus encode --fast --exact-k` at 1024x1024 with one focus on the
  region; the same as `conus serve`'s /frame), the two views decoded from it (`conus decode`);
- deep zoom: a DZI pyramid of the same photograph (`vips dzsave`, 254-pixel JPEG tiles with one
  pixel of overlap, OpenSeadragon's defaults), the tiles the two views need at their levels (the
  whole frame's level and the full-resolution level; a viewer would also fetch coarser levels
  first, which is not counted), at the lowest JPEG quality whose views are as close to the
  photograph (PSNR, 8-bit sRGB) as the CoNUS views are.
Then, in headless Chromium (SwiftShader): the time from navigation to the first complete frame of a
2048^2 CoNUS file at 1280x720, and of a frame `conus serve` encodes on request; the pan/zoom rate
at 1280x720 (frames drawn and waited for); and `conus serve`'s time for a 1024^2 frame of the
4096^2 picture around a new focus.

    bench/web_bench.py [--photo PATH] [--focus u,v,r] [--bin build/bin] [--out build/bench-results/web.json]
"""
import argparse
import json
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request

import numpy as np
from PIL import Image

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "web"))
Image.MAX_IMAGE_PIXELS = None


def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return 10 * np.log10(255.0 ** 2 / mse)


def run(*args):
    return subprocess.run([str(a) for a in args], check=True, capture_output=True, text=True)


def rgb(path):
    return np.asarray(Image.open(path).convert("RGB"))


def dzi_views(folder, size, whole_level, roi_box, tile=254, overlap=1):
    """The two views rebuilt from DZI tiles, and the tiles they need: (whole, roi, files)."""
    files = folder / "photo_files"
    top = max(int(p.name) for p in files.iterdir() if p.name.isdigit())

    def level_image(level, box):
        scale = 2 ** (top - level)
        w = -(-size // scale)
        x0, y0, x1, y1 = [int(c // scale) for c in box[:2]] + [int(-(-c // scale)) for c in box[2:]]
        canvas = np.zeros((w, w, 3), np.uint8)
        used = []
        for j in range(y0 // tile, (min(y1, w) - 1) // tile + 1):
            for i in range(x0 // tile, (min(x1, w) - 1) // tile + 1):
                path = files / str(level) / f"{i}_{j}.jpg"
                used.append(path)
                t = np.asarray(Image.open(path).convert("RGB"))
                ox, oy = (overlap if i else 0), (overlap if j else 0)
                part = t[oy:oy + tile, ox:ox + tile]
                canvas[j * tile:j * tile + part.shape[0], i * tile:i * tile + part.shape[1]] = part
        return canvas[y0:y1, x0:x1], used

    whole, a = level_image(whole_level, (0, 0, size, size))
    roi, b = level_image(top, roi_box)
    return whole, roi, a + b + [folder / "photo.dzi"]


from web_page_speed import GL, browser  # noqa: E402 (beside this file)


def browser_figures(conus, folder, file_name, picture, gl):
    from conftest import wait_title
    driver, profile = browser(gl)
    server = subprocess.Popen([conus, "serve", folder, "--port", "0", "-q", "--max-side", "2048"], stdout=subprocess.PIPE, text=True)
    url = server.stdout.readline().split(" at ")[1].split(" ")[0]
    try:
        renderer = driver.execute_script(
            "const g = document.createElement('canvas').getContext('webgl2');"
            "return g.getParameter(g.getExtension('WEBGL_debug_renderer_info').UNMASKED_RENDERER_WEBGL);")
        ready, timings = [], []
        for _ in range(3):
            driver.get(url + f"?file={file_name}&size=1280x720")
            assert wait_title(driver, 120) == "ready", driver.title
            ready.append(driver.execute_script("return window.conusReadyAt"))
            timings.append(json.loads(driver.execute_script("return JSON.stringify(window.conusTimings)")))
        # Frames a second of a drag (whole pixels, one scale), a zoom, and both at once: each frame
        # drawn and waited for; and the drag and zoom one an animation frame (what is shown).
        rate = {kind: driver.execute_script(f"return window.conusPanZoomRate(30, '{kind}')") for kind in ("pan", "zoom", "both")}
        for kind in ("pan", "zoom"):
            rate["shown_" + kind] = driver.execute_async_script(f"window.conusShownRate(30, '{kind}').then(arguments[0])")
        remote = []
        for k in range(3):  # a new focus each time: encoded on request
            driver.get(url + f"?picture={picture}&size=1280x720&frame=1024x1024&view={0.2 + 0.2 * k},0.3,{0.3 + 0.2 * k},0.4")
            assert wait_title(driver, 300) == "ready", driver.title
            remote.append(driver.execute_script("return window.conusReadyAt"))
        serve_times = []
        for k in range(3):
            t0 = time.perf_counter()
            with urllib.request.urlopen(url + f"frame?file={picture}&focus={0.31 + 0.1 * k},0.62,0.06,4&size=1024x1024") as r:
                r.read()
            serve_times.append(time.perf_counter() - t0)
        return {"renderer": renderer, "first_frame_ms": statistics.median(ready), "first_frame_ms_all": ready,
                "first_frame_parts_ms": timings[ready.index(statistics.median(ready))], "pan_zoom_fps": rate,
                "remote_first_frame_ms": statistics.median(remote), "remote_first_frame_ms_all": remote,
                "serve_frame_s": statistics.median(serve_times), "serve_frame_s_all": serve_times}
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)
        server.terminate()
        server.wait(10)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--photo", default="/usr/share/backgrounds/Infinite-Sea_by_Aury88.jpg", help="a 4096x4096 photograph")
    p.add_argument("--focus", default="0.52,0.42,0.06", help="u,v,r of the region of interest")
    p.add_argument("--bin", default=str(ROOT / "build" / "bin"))
    p.add_argument("--out", default=str(ROOT / "build" / "bench-results" / "web.json"))
    a = p.parse_args()
    conus = pathlib.Path(a.bin) / "conus"
    u, v, r = map(float, a.focus.split(","))
    work = pathlib.Path(tempfile.mkdtemp(prefix="conus-web-bench-"))
    source = np.asarray(Image.open(a.photo).convert("RGB"))
    size = source.shape[0]
    assert source.shape[:2] == (4096, 4096), f"{a.photo} is not 4096x4096"
    Image.fromarray(source).save(work / "photo.png")

    # The two views, and the photograph's pixels there.
    side = round(2 * r * size)
    x0, y0 = round((u - r) * size), round((v - r) * size)
    roi_box = [x0, y0, x0 + side, y0 + side]
    roi_view = ",".join(f"{c / size:.6f}" for c in roi_box)
    roi_px = roi_box[2] - roi_box[0]
    whole_ref = np.asarray(Image.fromarray(source).reduce(4))
    roi_ref = source[roi_box[1]:roi_box[3], roi_box[0]:roi_box[2]]

    # CoNUS: one frame.
    t0 = time.perf_counter()
    run(conus, "encode", work / "photo.png", "-o", work / "frame.exr", "--size", "1024x1024", "--focus", f"{u},{v},{r},4",
        "--exact-k", "--fast", "-q")
    encode_s = time.perf_counter() - t0
    run(conus, "decode", work / "frame.exr", "-o", work / "whole.png", "--view", "0,0,1,1", "--size", "1024x1024", "-q")
    run(conus, "decode", work / "frame.exr", "-o", work / "roi.png", "--view", roi_view, "--size", f"{roi_px}x{roi_px}", "-q")
    conus_whole, conus_roi = psnr(rgb(work / "whole.png"), whole_ref), psnr(rgb(work / "roi.png"), roi_ref)
    conus_bytes = (work / "frame.exr").stat().st_size
    print(f"conus: whole {conus_whole:.2f} dB, roi {conus_roi:.2f} dB, 1 request, {conus_bytes} bytes, encoded in {encode_s:.1f} s")

    # The same frame stored lossy (dwaa, which `conus` writes and the page does not read yet): bytes and views.
    run(conus, "encode", work / "photo.png", "-o", work / "frame-dwaa.exr", "--size", "1024x1024", "--focus", f"{u},{v},{r},4",
        "--exact-k", "--fast", "--compression", "dwaa", "-q")
    run(conus, "decode", work / "frame-dwaa.exr", "-o", work / "whole-dwaa.png", "--view", "0,0,1,1", "--size", "1024x1024", "-q")
    run(conus, "decode", work / "frame-dwaa.exr", "-o", work / "roi-dwaa.png", "--view", roi_view, "--size", f"{roi_px}x{roi_px}", "-q")
    dwaa = {"bytes": (work / "frame-dwaa.exr").stat().st_size, "whole_db": psnr(rgb(work / "whole-dwaa.png"), whole_ref),
            "roi_db": psnr(rgb(work / "roi-dwaa.png"), roi_ref)}
    print(f"conus dwaa: whole {dwaa['whole_db']:.2f} dB, roi {dwaa['roi_db']:.2f} dB, {dwaa['bytes']} bytes")

    # Deep zoom at rising JPEG quality until both views are as close as CoNUS's.
    dzi, dzi_rows = None, []
    for q in [50, 60, 70, 75, 80, 85, 90, 95, 98]:
        folder = work / f"dzi{q}"
        folder.mkdir()
        run("vips", "dzsave", work / "photo.png", folder / "photo", "--tile-size", "254", "--overlap", "1", "--suffix", f".jpg[Q={q}]")
        whole, roi, files = dzi_views(folder, size, 10, roi_box)
        row = {"quality": q, "whole_db": psnr(whole, whole_ref), "roi_db": psnr(roi, roi_ref),
               "bytes": sum(f.stat().st_size for f in files), "requests": len(files)}
        print(f"dzi Q={q}: whole {row['whole_db']:.2f} dB, roi {row['roi_db']:.2f} dB, {row['requests']} requests, {row['bytes']} bytes")
        dzi = row
        dzi_rows.append(row)
        if row["whole_db"] >= conus_whole and row["roi_db"] >= conus_roi:
            break

    # The browser: a 2048^2 CoNUS file beside the page, and frames from conus serve.
    run(conus, "encode", work / "photo.png", "-o", work / "frame2048.exr", "--size", "2048x2048", "--focus", f"{u},{v},{r},2",
        "--fast", "-q")
    browser = {gl: browser_figures(conus, work, "frame2048.exr", "photo.png", gl) for gl in GL}

    result = {"photo": a.photo, "focus": [u, v, r], "roi_pixels": roi_px,
              "conus": {"bytes": conus_bytes, "requests": 1, "whole_db": conus_whole, "roi_db": conus_roi, "encode_s": encode_s},
              "conus_dwaa": dwaa, "dzi": dzi, "dzi_rows": dzi_rows, "browser": browser,
              "machine": os.uname().nodename, "cores": os.cpu_count(), "load": os.getloadavg()[0],
              "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}
    out = pathlib.Path(a.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=1))
    c, d = result["conus"], dzi
    print(f"| whole frame 1024² + {roi_px}² ROI at full detail | CoNUS: 1 request, {c['bytes'] / 1024:.0f} KiB "
          f"({c['whole_db']:.1f} / {c['roi_db']:.1f} dB) | DZI Q={d['quality']}: {d['requests']} requests, {d['bytes'] / 1024:.0f} KiB "
          f"({d['whole_db']:.1f} / {d['roi_db']:.1f} dB) | **{d['bytes'] / c['bytes']:.2f}x** bytes, {d['requests']}x requests |")
    for gl, b in browser.items():
        parts = ", ".join(f"{k} {v:.0f}" for k, v in b["first_frame_parts_ms"].items())
        print(f"| first frame, 2048² CoNUS file at 1280x720, {gl} | {b['first_frame_ms']:.0f} ms ({parts}) | target ≤ 1000 ms |")
        print(f"| first frame from conus serve (1024² frame encoded on request), {gl} | {b['remote_first_frame_ms']:.0f} ms | |")
        rates = ", ".join(f"{k} {v:.1f}" for k, v in b["pan_zoom_fps"].items())
        print(f"| pan/zoom at 1280x720, {gl} | {rates} frames/s | target ≥ 30 |")
        print(f"| conus serve: 1024² frame of the 4096² picture, new focus | {b['serve_frame_s']:.2f} s | target ≤ 0.5 s |")
    print(f"results: {out}")


if __name__ == "__main__":
    main()
