#!/usr/bin/python3
"""The viewer page's own speed in headless Chromium, page against page (bench/notes/2026-12-07-web-speed.md).

Each FOLDER holds a page as `conus web` writes it (index.html, the scripts, the CoNUS file); the
folders are served by Python's own HTTP server (the same for every page, so the fetch is compared
fairly) and loaded in turn, round after round, so that the shared machine's load falls on all
alike. For each page and software GL: the time from navigation to the first complete frame (title
`ready`, window.conusReadyAt) and its parts (window.conusTimings), and at 1280x720 the rates of a
drag, a zoom and both at once (window.conusPanZoomRate: frames drawn and each waited for; a page
older than the drag's whole-pixel moves draws every kind as "both") and of a drag and a zoom one
frame an animation frame (window.conusShownRate, where the page has it); medians over the rounds.

    bench/web_page_speed.py FILE.exr FOLDER [FOLDER...] [--rounds 5] [--gl swiftshader,llvmpipe]
"""
import argparse
import functools
import http.server
import json
import pathlib
import shutil
import statistics
import sys
import tempfile
import threading

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "web"))

GL = {"swiftshader": [], "llvmpipe": ["--use-gl=angle", "--use-angle=gl-egl", "--ignore-gpu-blocklist"]}


class Quiet(http.server.SimpleHTTPRequestHandler):
    """Every request answered afresh (no browser cache between rounds), and no log."""
    def end_headers(self):
        self.send_header("Cache-Control", "no-store")
        super().end_headers()

    def log_message(self, *args):
        pass


def serve(folder):
    handler = functools.partial(Quiet, directory=str(folder))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    return httpd, f"http://127.0.0.1:{httpd.server_address[1]}/"


def browser(gl):
    from conftest import CHROMIUM_ARGS
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    profile = tempfile.mkdtemp(prefix="conus-bench-chromium-")
    for a in CHROMIUM_ARGS + ["--user-data-dir=" + profile, "--window-size=1400,900"] + GL[gl]:
        options.add_argument(a)
    options.binary_location = "/usr/bin/chromium"
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    driver.set_script_timeout(600)
    return driver, profile


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file")
    p.add_argument("folders", nargs="+")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--frames", type=int, default=30, help="pan/zoom frames per measure")
    p.add_argument("--gl", default="swiftshader,llvmpipe")
    p.add_argument("--size", default="1280x720")
    p.add_argument("--out", help="JSON of every figure")
    a = p.parse_args()
    from conftest import wait_title
    servers = [serve(f) for f in a.folders]
    result = {}
    for gl in a.gl.split(","):
        driver, profile = browser(gl)
        try:
            runs = {f: [] for f in a.folders}
            for _ in range(a.rounds):
                for folder, (_, url) in zip(a.folders, servers):
                    driver.get(url + f"index.html?file={a.file}&size={a.size}")
                    assert wait_title(driver, 120) == "ready", driver.title
                    figures = json.loads(driver.execute_script(
                        "return JSON.stringify(Object.assign({ready: window.conusReadyAt}, window.conusTimings))"))
                    for kind in ("pan", "zoom", "both"):  # a drag (whole pixels), a zoom, both at once
                        figures[kind] = driver.execute_script(f"return window.conusPanZoomRate({a.frames}, '{kind}')")
                    if driver.execute_script("return !!window.conusShownRate"):  # one frame an animation frame
                        for kind in ("pan", "zoom"):
                            figures["shown-" + kind] = driver.execute_async_script(
                                f"window.conusShownRate({a.frames}, '{kind}').then(arguments[0])")
                    runs[folder].append(figures)
            result[gl] = runs
            for folder in a.folders:
                keys = runs[folder][0].keys()
                med = {k: statistics.median(r[k] for r in runs[folder]) for k in keys}
                print(f"{gl:11s} {folder}: " + ", ".join(f"{k} {v:.1f}" for k, v in med.items()))
        finally:
            driver.quit()
            shutil.rmtree(profile, ignore_errors=True)
    for httpd, _ in servers:
        httpd.shutdown()
    if a.out:
        pathlib.Path(a.out).write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
