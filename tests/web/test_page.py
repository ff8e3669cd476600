"""The browser viewer against `conus decode`: the page, served by `conus serve`, draws a view at a
size (?file=NAME&view=...&size=WxH) in headless Chromium (WebGL2 on SwiftShader); its canvas, read
back, is the same view decoded by `conus decode --view ... --size ...` within 40 dB PSNR (8-bit),
for foci, importance (float, uncompressed) and analytic ground-map files, zoomed in, whole and
zoomed out. Broken and non-CoNUS files show one line of error."""
import pathlib
import subprocess

import pytest
from selenium.webdriver.support.ui import WebDriverWait

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
    assert sorted(p.name for p in site.iterdir()) == ["conus-exr.js", "conus-gl.js", "conus-shaders.js", "conus-view.js",
                                                       "index.html", "piz.exr", "piz.exr.js"]
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


def test_drag_wheel_and_double_click_move_the_view(browser, server):
    """Mouse drag pans by the pixels dragged, the wheel zooms about the pointer, double-click zooms in 2x there."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.actions.wheel_input import ScrollOrigin
    assert open_page(browser, server, "file=foci.exr") == "ready"
    canvas = browser.find_element("id", "view")
    width = browser.execute_script("return document.getElementById('view').getBoundingClientRect().width")
    before = browser.execute_script("return window.conusView()")
    ActionChains(browser).move_to_element(canvas).click_and_hold().move_by_offset(100, 0).release().perform()
    after = browser.execute_script("return window.conusView()")
    shift = 100 / width * (before[2] - before[0])
    assert abs((before[0] - after[0]) - shift) < 1e-3 and abs(after[1] - before[1]) < 1e-9, (before, after)
    ActionChains(browser).scroll_from_origin(ScrollOrigin.from_element(canvas), 0, 200).perform()
    WebDriverWait(browser, 10).until(lambda d: d.execute_script("return window.conusView()")[2] - d.execute_script("return window.conusView()")[0] > (after[2] - after[0]) * 1.01)
    out = browser.execute_script("return window.conusView()")
    # Zoomed about the pointer (the canvas's centre): the centre stays where it was.
    assert abs((out[0] + out[2]) / 2 - (after[0] + after[2]) / 2) < 1e-3, (after, out)
    ActionChains(browser).double_click(canvas).perform()
    WebDriverWait(browser, 10).until(lambda d: abs((d.execute_script("return window.conusView()")[2] - d.execute_script("return window.conusView()")[0]) * 2 - (out[2] - out[0])) < 1e-6)
    assert browser.title == "ready"


def test_conus_web_keeps_the_input(served, tmp_path):
    """A folder that holds the input already is refused in one line, the input untouched."""
    site = tmp_path / "here"
    site.mkdir()
    (site / "piz.exr").write_bytes((served / "piz.exr").read_bytes())
    before = (site / "piz.exr").read_bytes()
    done = subprocess.run([CONUS, "web", site / "piz.exr", "-o", site], capture_output=True, text=True)
    assert done.returncode != 0 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert sorted(p.name for p in site.iterdir()) == ["piz.exr"] and (site / "piz.exr").read_bytes() == before


SHARED = pathlib.Path(__file__).resolve().parents[3] / "shared" / "data"
HOSTILE = ["hostile/dw_32768x32768_rgb_dwab.exr", "hostile/tiled_65536x16384_tile_4096_64ch.exr",
           "exr/damaged/clusterfuzz-testcase-minimized-openexr_exrcheck_fuzzer-4675763792117760",
           "exr/damaged/NULL_pointer", "exr/Beachball_multipart.0001.exr"]


def test_hostile_files_say_one_line_at_once(browser, server, served):
    """Files made to break readers (sizes that would take gigabytes, names with control bytes, damaged
    chunks, a multipart EXR that is not CoNUS) end in one line of error, before any pixel memory."""
    if not SHARED.is_dir():
        pytest.skip(f"{SHARED} is absent: the hostile files were not tried")
    for name in HOSTILE:
        target = served / ("hostile-" + pathlib.Path(name).name)
        target.write_bytes((SHARED / name).read_bytes())
        title = open_page(browser, server, f"file={target.name}&size=64x64")
        assert title.startswith("error: ") and "\n" not in title, (name, title)


def exr_part_attribute(data, part_name, attribute):
    """Where the value of `attribute` of the part named `part_name` lies in a multipart EXR's headers: (offset, size)."""
    at = 8
    while data[at] != 0:
        found, name = None, None
        while data[at] != 0:
            end = data.index(b"\0", at)
            key = data[at:end].decode()
            type_end = data.index(b"\0", end + 1)
            size = int.from_bytes(data[type_end + 1:type_end + 5], "little")
            value = type_end + 5
            if key == "name":
                name = data[value:value + size].decode()
            if key == attribute:
                found = (value, size)
            at = value + size
        at += 1
        if name == part_name:
            return found
    raise KeyError(part_name)


def test_a_map_finer_than_its_image_is_refused(browser, server, served):
    """V7: a map no finer than 4 nodes a pixel of the image's longer side (plus one), 129 always. The
    192x128 image of foci.exr may have a map of 769 nodes a side; its map's grid declared 800x140 is
    refused before any pixel is read, and 769x140 is not refused for that reason."""
    good = bytearray((served / "foci.exr").read_bytes())
    at, size = exr_part_attribute(good, "samplingmap", "dataWindow")
    assert size == 16
    for columns, finer in [(800, True), (769, False)]:
        patched = bytearray(good)
        patched[at + 8:at + 12] = (columns - 1).to_bytes(4, "little", signed=True)
        patched[at + 12:at + 16] = (139).to_bytes(4, "little", signed=True)
        name = f"finer-map-{columns}.exr"
        (served / name).write_bytes(bytes(patched))
        title = open_page(browser, server, f"file={name}&size=64x64")
        assert title.startswith("error: "), title
        refused = "finer than its 192x128 image can show (at most 769 nodes a side, V7)" in title
        assert refused == finer, title


@pytest.mark.parametrize("name", ["foci.exr", "ground.exr"])
def test_a_drag_moves_the_kept_frame_and_gives_the_decoded_view(browser, server, served, tmp_path, name):
    """A drag moves the frame kept on the GPU by whole pixels and draws only the strips it uncovers:
    after drags right-up and left-down the canvas is `conus decode` of the view the page shows then,
    and the frames were moved, not drawn whole."""
    from selenium.webdriver.common.action_chains import ActionChains
    assert open_page(browser, server, f"file={name}&view=0.2,0.25,0.5,0.45&size=300x200") == "ready"
    canvas = browser.find_element("id", "view")
    for dx, dy in [(37, -23), (-11, 29)]:
        ActionChains(browser).move_to_element(canvas).click_and_hold().move_by_offset(dx, dy).release().perform()
    moved = browser.execute_script("return window.conusMoved || 0")
    assert moved >= 2, moved
    view = browser.execute_script("return window.conusView()")
    # Whole pixels: the view moved by (26, -6) of its 300x200 pixels, each 0.3/300 by 0.2/200 wide.
    assert abs(view[0] - (0.2 - 26 * 0.001)) < 1e-9 and abs(view[1] - (0.25 - 6 * 0.001)) < 1e-9, view
    reference = tmp_path / "reference.png"
    text = ",".join(repr(v) for v in view)
    subprocess.run([CONUS, "decode", served / name, "-o", reference, "--view", text, "--size", "300x200", "-q"], check=True)
    quality = psnr8(canvas_rgb(browser), png_rgb(reference))
    assert quality >= 40.0, f"{name} dragged to {text}: canvas {quality:.1f} dB from conus decode"
