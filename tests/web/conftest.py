"""What the browser tests share: the conus binary (CONUS_BIN_DIR), a folder of CoNUS files made
by it from an asymmetric picture, `conus serve` of that folder on a free localhost port, and
Debian's Chromium driven headless through chromedriver (selenium), WebGL2 on SwiftShader."""
import base64
import io
import os
import pathlib
import shutil
import subprocess
import tempfile

import numpy as np
import pytest
from PIL import Image

BIN_DIR = pathlib.Path(os.environ.get("CONUS_BIN_DIR", pathlib.Path(__file__).resolve().parents[2] / "build" / "bin"))
CONUS = str(BIN_DIR / "conus")
CHROMIUM_ARGS = ["--headless=new", "--enable-unsafe-swiftshader", "--use-angle=swiftshader", "--no-sandbox",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync", "--no-first-run",
                 "--disable-default-apps", "--mute-audio"]


def conus(*args, **kw):
    return subprocess.run([CONUS, *map(str, args)], check=True, capture_output=True, text=True, **kw)


def picture(w, h):
    """An asymmetric 8-bit sRGB picture: ramps, rings of rising frequency, a bright bar, dark print."""
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    r = np.hypot(x - 0.3 * w, y - 0.4 * h)
    img = np.zeros((h, w, 3))
    img[..., 0] = 0.5 + 0.4 * np.sin(r * r / (6.0 * w))
    img[..., 1] = x / (w - 1)
    img[..., 2] = 0.3 + 0.25 * np.sin(y / 9.0) * np.cos(x / 23.0)
    img[int(0.7 * h):int(0.75 * h), int(0.1 * w):int(0.6 * w)] = (1.0, 0.95, 0.2)
    for k in range(12):  # dark strokes of "print" near the focus
        x0 = int(0.22 * w) + 9 * k
        img[int(0.36 * h):int(0.44 * h), x0:x0 + 2 + k % 3] *= 0.15
    return (np.clip(img, 0, 1) * 255 + 0.5).astype(np.uint8)


@pytest.fixture(scope="session")
def served(tmp_path_factory):
    """A folder holding photo.png (768x512) and CoNUS files of it: foci (half, zip), detail
    importance (float, uncompressed), a ground-plane analytic map (half, zip), and broken files."""
    d = tmp_path_factory.mktemp("served")
    Image.fromarray(picture(768, 512)).save(d / "photo.png")
    conus("encode", d / "photo.png", "-o", d / "foci.exr", "--size", "192x128", "--focus", "0.3,0.4,0.1,4", "--fast", "-q")
    conus("encode", d / "photo.png", "-o", d / "detail.exr", "--size", "256x160", "--importance", "detail", "--fast",
          "--float", "--compression", "none", "-q")
    conus("map", "ground", "--eye-height", "2", "--near", "1", "--far", "40", "-o", d / "ground-map.exr")
    conus("encode", d / "photo.png", "-o", d / "ground.exr", "--size", "200x140", "--map", d / "ground-map.exr", "--fast", "-q")
    conus("encode", d / "photo.png", "-o", d / "piz.exr", "--size", "192x128", "--focus", "0.6,0.5,0.1,3", "--fast",
          "--compression", "piz", "-q")
    good = (d / "foci.exr").read_bytes()
    (d / "truncated.exr").write_bytes(good[:len(good) * 3 // 5])
    (d / "not-exr.exr").write_bytes((d / "photo.png").read_bytes())
    damaged = bytearray(good)
    for k in range(len(damaged) // 2, len(damaged) // 2 + 64):
        damaged[k] ^= 0x5A
    (d / "damaged.exr").write_bytes(bytes(damaged))
    subprocess.run(["oiiotool", str(d / "photo.png"), "-o", str(d / "plain.exr")], check=True, capture_output=True)
    return d


@pytest.fixture(scope="session")
def server(served):
    """`conus serve` of the folder on a free localhost port: its base URL."""
    process = subprocess.Popen([CONUS, "serve", str(served), "--port", "0", "-q"], stdout=subprocess.PIPE, text=True)
    line = process.stdout.readline()
    assert line.startswith("serving "), line
    url = line.split(" at ")[1].split(" ")[0]
    yield {"url": url, "process": process}
    process.terminate()
    process.wait(timeout=10)


@pytest.fixture(scope="session")
def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    profile = tempfile.mkdtemp(prefix="conus-chromium-")
    for a in CHROMIUM_ARGS + ["--user-data-dir=" + profile]:
        options.add_argument(a)
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver") or "/usr/bin/chromedriver"), options=options)
    driver.set_page_load_timeout(60)
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


def wait_title(driver, timeout=60):
    """The page's title once it says `ready` or `error: ...`."""
    from selenium.webdriver.support.ui import WebDriverWait
    WebDriverWait(driver, timeout).until(lambda d: d.title == "ready" or d.title.startswith("error: "))
    return driver.title


def canvas_rgb(driver):
    """The canvas as an RGB array, read back through toDataURL (the drawing buffer is kept)."""
    url = driver.execute_script("return document.getElementById('view').toDataURL('image/png');")
    data = base64.b64decode(url.split(",", 1)[1])
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))


def png_rgb(path):
    return np.asarray(Image.open(path).convert("RGB"))


def psnr8(a, b):
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return float("inf") if mse == 0 else 10 * np.log10(255.0 ** 2 / mse)
