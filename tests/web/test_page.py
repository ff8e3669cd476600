"""The browser viewer against `conus decode`: the page, served by `conus serve`, draws a view at a
size (?file=NAME&view=...&size=WxH) in headless Chromium (WebGL2 on SwiftShader); its canvas, read
back, is the same view decoded by `conus decode --view ... --size ...` within 40 dB PSNR (8-bit),
for foci, importance (float, uncompressed) and analytic ground-map files, zoomed in, whole and
zoomed out. Broken and non-CoNUS files show one line of error."""
import subprocess

import pytest

from conftest import CONUS, canvas_rgb, png_rgb, psnr8, wait_title

VIEWS = [
    ("0,0,1,1", "384x256"),          # the whole frame, CoNUS pixels magnified in the context
    ("0.2,0.3,0.4,0.5", "300x200"),  # zoomed into the focus
    ("0,0,1,1", "96x64"),            # zoomed out: the pyramid's levels
    ("0.55,0.1,0.95,0.6", "200x250"),  # off the focus, a view of its own aspect
]


def open_page(browser, server, query):
    browser.get(server["url"] + "?" + query)
    return wait_title(browser)


@pytest.mark.parametrize("name", ["foci.exr", "detail.exr", "ground.exr"])
@pytest.mark.parametrize("view,size", VIEWS)
def test_canvas_is_the_decoded_view(browser, server, served, tmp_path, name, view, size):
    title = open_page(browser, server, f"file={name}&view={view}&size={size}")
    assert title == "ready", title
    canvas = canvas_rgb(browser)
    reference = tmp_path / "reference.png"
    subprocess.run([CONUS, "decode", served / name, "-o", reference, "--view", view, "--size", size, "-q"], check=True)
    expected = png_rgb(reference)
    assert canvas.shape == expected.shape, (canvas.shape, expected.shape)
    quality = psnr8(canvas, expected)
    assert quality >= 40.0, f"{name} view {view} at {size}: canvas {quality:.1f} dB from conus decode"
    # Not a flat picture that any two renderers agree on: the view has structure.
    assert expected.std() > 10


def test_outlines_and_density_change_the_canvas(browser, server):
    assert open_page(browser, server, "file=foci.exr&view=0,0,1,1&size=192x128") == "ready"
    plain = canvas_rgb(browser)
    assert open_page(browser, server, "file=foci.exr&view=0,0,1,1&size=192x128&outlines=1") == "ready"
    outlined = canvas_rgb(browser)
    changed = (abs(outlined.astype(int) - plain.astype(int)).sum(axis=2) > 0)
    # The circle at r = 0.1 of the width around (0.3, 0.4): green pixels there, none far away.
    assert changed[int(0.4 * 128), int(0.4 * 192) - 1:int(0.4 * 192) + 2].any()
    assert not changed[int(0.9 * 128), int(0.9 * 192)]
    assert outlined[changed][:, 1].mean() > 200
    assert open_page(browser, server, "file=foci.exr&view=0,0,1,1&size=192x128&density=1") == "ready"
    heat = canvas_rgb(browser).astype(float)
    # The heat map is brightest at the focus, where the density is highest.
    assert heat[int(0.4 * 128), int(0.3 * 192)].sum() > heat[int(0.9 * 128), int(0.9 * 192)].sum() + 100


@pytest.mark.parametrize("name,words", [
    ("truncated.exr", "damaged file"),
    ("not-exr.exr", "not an OpenEXR file"),
    ("damaged.exr", "damaged file"),
    ("plain.exr", "not a CoNUS file"),
    ("piz.exr", "compression piz"),
    ("missing.exr", "404"),
])
def test_broken_files_say_one_line(browser, server, name, words):
    title = open_page(browser, server, f"file={name}&size=64x64")
    assert title.startswith("error: ") and words in title, title
    status = browser.execute_script("return document.getElementById('status').textContent")
    assert status == title and "\n" not in status


def test_conus_web_folder(browser, served, tmp_path):
    """`conus web` writes a folder that shows the file opened from disk (file://), piz rewritten as zip."""
    site = tmp_path / "site"
    done = subprocess.run([CONUS, "web", served / "piz.exr", "-o", site], check=True, capture_output=True, text=True)
    assert "index.html" in done.stdout
    assert sorted(p.name for p in site.iterdir()) == ["conus-exr.js", "conus-shaders.js", "conus-view.js", "index.html",
                                                       "piz.exr", "piz.exr.js"]
    header = subprocess.run(["exrheader", str(site / "piz.exr")], check=True, capture_output=True, text=True).stdout
    compression = [line for line in header.splitlines() if line.startswith("compression")]
    assert len(compression) == 2 and all("): zip," in line for line in compression), compression
    browser.get((site / "index.html").as_uri() + "?view=0.4,0.3,0.8,0.7&size=200x200")
    assert wait_title(browser) == "ready"
    reference = tmp_path / "reference.png"
    subprocess.run([CONUS, "decode", served / "piz.exr", "-o", reference, "--view", "0.4,0.3,0.8,0.7", "--size", "200x200", "-q"],
                   check=True)
    assert psnr8(canvas_rgb(browser), png_rgb(reference)) >= 40.0


def test_conus_web_refuses_what_is_not_conus(served, tmp_path):
    for name in ["plain.exr", "truncated.exr", "not-exr.exr"]:
        done = subprocess.run([CONUS, "web", served / name, "-o", tmp_path / name], capture_output=True, text=True)
        assert done.returncode != 0
        assert len(done.stderr.strip().splitlines()) == 1, done.stderr
        assert not (tmp_path / name).exists()
