"""`conus serve`: frames encoded on request around a focus, read back with OpenEXR's own tools and
decoded by the page; names confined to the folder; bad parameters a 400 (missing names a 404) of
one line; the server still answers after 100 concurrent bad requests."""
import http.client
import json
import os
import subprocess
import threading
import time
import urllib.parse

import pytest

from conftest import CONUS, canvas_rgb, png_rgb, psnr8, wait_title


def get(server, path):
    """(status, body) of GET path, sent as written (no normalisation of `..`)."""
    host = urllib.parse.urlsplit(server["url"])
    connection = http.client.HTTPConnection(host.hostname, host.port, timeout=60)
    try:
        connection.putrequest("GET", path, skip_accept_encoding=True)
        connection.endheaders()
        response = connection.getresponse()
        return response.status, response.read()
    finally:
        connection.close()


def test_frame_is_a_conus_file_around_the_focus(server, served, tmp_path):
    status, body = get(server, "/frame?file=photo.png&focus=0.7,0.25,0.08,4&size=256x160")
    assert status == 200, body
    frame = tmp_path / "frame.exr"
    frame.write_bytes(body)
    header = subprocess.run(["exrheader", str(frame)], check=True, capture_output=True, text=True).stdout
    assert "samplingmap" in header and "conus:foci" in header
    info = subprocess.run([CONUS, "info", frame, "--json"], check=True, capture_output=True, text=True).stdout
    described = json.loads(info)
    foci = described["analyticMap"]["foci"]
    assert len(foci) == 1 and all(abs(foci[0][key] - asked) < 1e-6 for key, asked in (("u", 0.7), ("v", 0.25), ("r", 0.08))), foci
    # Asked again: the kept bytes.
    assert get(server, "/frame?file=photo.png&focus=0.7,0.25,0.08,4&size=256x160") == (200, body)
    # Another focus: another frame.
    assert get(server, "/frame?file=photo.png&focus=0.2,0.6,0.08,4&size=256x160")[1] != body


def test_page_shows_served_frames(browser, server, served, tmp_path):
    """?picture=NAME: the page asks /frame for the view's centre and draws the answer as decode does."""
    browser.get(server["url"] + "?picture=photo.png&view=0.1,0.2,0.5,0.6&size=240x240&frame=256x160")
    assert wait_title(browser) == "ready", browser.title
    canvas = canvas_rgb(browser)
    asked = browser.execute_script("return performance.getEntriesByType('resource').map(e => e.name)"
                                   ".filter(n => n.includes('/frame?'))")
    assert len(asked) == 1, asked
    query = urllib.parse.urlsplit(asked[0]).query
    focus = urllib.parse.parse_qs(query)["focus"][0].split(",")
    assert abs(float(focus[0]) - 0.3) < 1e-6 and abs(float(focus[1]) - 0.4) < 1e-6, focus
    status, body = get(server, "/frame?" + query)
    assert status == 200
    frame = tmp_path / "frame.exr"
    frame.write_bytes(body)
    reference = tmp_path / "reference.png"
    subprocess.run([CONUS, "decode", frame, "-o", reference, "--view", "0.1,0.2,0.5,0.6", "--size", "240x240", "-q"], check=True)
    assert psnr8(canvas, png_rgb(reference)) >= 40.0


BAD = [
    ("/frame?file=../../../../etc/passwd&focus=0.5,0.5,0.1,4&size=64x64", 400),
    ("/frame?file=/etc/passwd&focus=0.5,0.5,0.1,4&size=64x64", 400),
    ("/frame?file=link-out.png&focus=0.5,0.5,0.1,4&size=64x64", 400),
    ("/frame?file=photo.png&focus=nan,0.5,0.1,4&size=64x64", 400),
    ("/frame?file=photo.png&focus=0.5,0.5,0.1,inf&size=64x64", 400),
    ("/frame?file=photo.png&focus=0.5,0.5,0.1&size=64x64", 400),
    ("/frame?file=photo.png&focus=1.5,0.5,0.1,4&size=64x64", 400),
    ("/frame?file=photo.png&focus=0.5,0.5,0.1,4&size=99999x99999", 400),
    ("/frame?file=photo.png&focus=0.5,0.5,0.1,4&size=1e9x64", 400),
    ("/frame?file=photo.png&focus=0.5,0.5,0.1,4&size=-64x64", 400),
    ("/frame?file=photo.png&focus=0.5,0.5,0.1,4&size=1024x1024", 400),  # larger than the picture
    ("/frame?file=photo.png&focus=0.5,0.5,0.1,4", 400),
    ("/frame?file=foci.exr.missing&focus=0.5,0.5,0.1,4&size=64x64", 404),
    ("/frame?file=truncated.exr&focus=0.5,0.5,0.1,4&size=64x64", 400),
    ("/../../../../etc/passwd", 400),
    ("/%2e%2e/%2e%2e/%2e%2e/etc/passwd", 400),
    ("/link-out.png", 400),
    ("/nothing-here.exr", 404),
    ("/huge.exr", 413),  # past the 1 GiB that serve sends (a sparse file)
]


@pytest.fixture(scope="module")
def link_out(served):
    """A link out of the folder, and a file too large to send (sparse: it takes no disk)."""
    link = served / "link-out.png"
    if not link.exists():
        os.symlink("/etc/passwd", link)
    with open(served / "huge.exr", "wb") as f:
        f.truncate((1 << 30) + 1)
    return link


@pytest.mark.parametrize("path,expected", BAD)
def test_bad_requests_get_one_line(server, link_out, path, expected):
    status, body = get(server, path)
    assert status == expected, (path, status, body)
    text = body.decode()
    assert text.endswith("\n") and text.count("\n") == 1 and "root:" not in text, text


def test_hundred_concurrent_bad_requests(server, link_out, served):
    """100 bad requests from 100 threads released at once (a barrier), each on its own connection to
    the real server: each answered with its own status, the server alive and serving after."""
    results = []
    lock = threading.Lock()
    together = threading.Barrier(100)

    def ask(k):
        path, expected = BAD[k % len(BAD)]
        together.wait(60)
        try:
            status, _ = get(server, path)
        except OSError as e:
            status = repr(e)
        with lock:
            results.append((path, status, expected))

    threads = [threading.Thread(target=ask, args=(k,)) for k in range(100)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert len(results) == 100
    wrong = [r for r in results if r[1] != r[2]]
    assert not wrong, wrong[:5]
    assert server["process"].poll() is None
    status, body = get(server, "/")
    assert status == 200 and b"conus-view.js" in body
    assert get(server, "/foci.exr") == (200, (served / "foci.exr").read_bytes())


def test_double_click_asks_for_a_frame_there(browser, server):
    """?picture: a double-click asks /frame for a focus at the clicked point; the last frame stays until it arrives."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.support.ui import WebDriverWait
    browser.get(server["url"] + "?picture=photo.png&size=300x200&frame=192x128")
    assert wait_title(browser) == "ready", browser.title
    frames = "return performance.getEntriesByType('resource').map(e => e.name).filter(n => n.includes('/frame?'))"
    assert len(browser.execute_script(frames)) == 1
    canvas = browser.find_element("id", "view")
    # 60 px right of and 40 px above the centre of a 300x200 canvas showing the whole frame.
    ActionChains(browser).move_to_element_with_offset(canvas, 60, -40).double_click().perform()
    WebDriverWait(browser, 60).until(lambda d: len(d.execute_script(frames)) == 2)
    focus = urllib.parse.parse_qs(urllib.parse.urlsplit(browser.execute_script(frames)[1]).query)["focus"][0].split(",")
    assert abs(float(focus[0]) - 0.7) < 0.01 and abs(float(focus[1]) - 0.3) < 0.01, focus
    WebDriverWait(browser, 60).until(lambda d: "focus 0.7" in d.execute_script("return document.getElementById('status').textContent"))
    assert browser.title == "ready"


def test_a_second_server_on_the_same_port_is_refused(server, served):
    """No port sharing (SO_REUSEPORT): a second `conus serve` on the port in use says so in one line."""
    port = urllib.parse.urlsplit(server["url"]).port
    done = subprocess.run([CONUS, "serve", served, "--port", str(port)], capture_output=True, text=True, timeout=30)
    assert done.returncode != 0 and "cannot listen" in done.stderr and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert get(server, "/")[0] == 200


def test_kept_pictures_give_the_frames_of_fresh_ones(server, served, tmp_path):
    """Pictures kept decoded with the encoder's levels (the default --memory) answer a new focus
    with the bytes a server that keeps nothing (--memory 0: each frame read and built afresh) sends."""
    process = subprocess.Popen([CONUS, "serve", str(served), "--port", "0", "-q", "--memory", "0"], stdout=subprocess.PIPE, text=True)
    try:
        line = process.stdout.readline()
        assert line.startswith("serving "), line
        fresh = {"url": line.split(" at ")[1].split(" ")[0]}
        for focus in ["0.35,0.45,0.06,5", "0.8,0.7,0.05,3", "0.5,0.5,0.2,2"]:
            path = f"/frame?file=photo.png&focus={focus}&size=200x150"
            kept_status, kept = get(server, path)
            fresh_status, made = get(fresh, path)
            assert kept_status == fresh_status == 200
            assert kept == made, focus
    finally:
        process.terminate()
        process.wait(timeout=10)


def test_the_page_of_a_picture_prepares_it(served):
    """GET /?picture=NAME starts reading NAME and building its encoder levels on a thread of its own
    (the log says so, once, however often the page is asked for); the frame asked for next is the
    one a server that keeps nothing (--memory 0) sends; a name outside the folder prepares nothing."""
    process = subprocess.Popen([CONUS, "serve", str(served), "--port", "0"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    fresh = subprocess.Popen([CONUS, "serve", str(served), "--port", "0", "-q", "--memory", "0"], stdout=subprocess.PIPE, text=True)
    log = []
    reader = threading.Thread(target=lambda: log.extend(iter(process.stderr.readline, "")), daemon=True)
    try:
        url = lambda p: {"url": p.stdout.readline().split(" at ")[1].split(" ")[0]}
        warmed, plain = url(process), url(fresh)
        reader.start()
        assert get(warmed, "/?picture=../../etc/passwd")[0] == 200
        for _ in range(3):
            status, body = get(warmed, "/?picture=photo.png&view=0.1,0.1,0.6,0.6")
            assert status == 200 and b"conus-view.js" in body
        for _ in range(600):
            if any(line.startswith("warm photo.png: picture and levels ready") for line in log):
                break
            time.sleep(0.1)
        path = "/frame?file=photo.png&focus=0.45,0.55,0.07,4&size=224x160"
        assert get(warmed, path) == get(plain, path)
        warm_lines = [line for line in log if line.startswith("warm ")]
        assert len(warm_lines) == 1 and "photo.png" in warm_lines[0], log
        frame_lines = [line for line in log if line.startswith("frame photo.png")]
        assert len(frame_lines) == 1 and "(picture kept," in frame_lines[0], log
    finally:
        for p in (process, fresh):
            p.terminate()
            p.wait(timeout=10)
