"""The conus binary as a newcomer meets it: what a batch says when interrupted or warned, sizes
that keep the aspect, usage checked before work, quiet when asked, times that add up, echoes of
what was given."""
import os
import re
import signal
import subprocess
import time

import numpy as np
import pytest

import conus


def run(*args, **kwargs):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, **kwargs)


def picture(path, width, height, seed=0):
    """An sRGB PNG of smooth colour with some detail, width x height."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    rng = np.random.default_rng(seed)
    img = np.stack([x / width, y / height, 0.5 + 0.4 * np.sin(x / 9.0) * np.cos(y / 7.0)], axis=-1)
    img += 0.05 * rng.random(img.shape, dtype=np.float32)
    conus.write_image(str(path), np.clip(img, 0, 1).astype(np.float32))
    return str(path)


def test_ctrl_c_in_a_batch_says_what_was_done_and_what_is_left(tmp_path, conus_bin):
    inputs = [picture(tmp_path / f"p{i:02}.png", 1200, 900, i) for i in range(8)]
    out = tmp_path / "exr"
    batch = subprocess.Popen([conus_bin, "encode", *inputs, "--out-dir", str(out), "--focus", "0.5,0.5,0.1,4", "--fit"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    # One job at a time: once the second output is there, the first is counted as done.
    while not (out.exists() and len(list(out.glob("*.exr"))) >= 2) and time.monotonic() < deadline and batch.poll() is None:
        time.sleep(0.05)
    assert batch.poll() is None, "the batch ended before it could be interrupted"
    batch.send_signal(signal.SIGINT)
    stdout, stderr = batch.communicate(timeout=120)
    assert batch.returncode == -signal.SIGINT, (batch.returncode, stderr)
    found = re.search(r"conus encode: interrupted: (\d+) done, (\d+) left \(no partial output is left behind\); "
                      r"run again with --skip-existing to finish", stderr)
    assert found, stderr
    done, left = int(found.group(1)), int(found.group(2))
    assert done >= 1 and done + left == 8
    written = sorted(os.listdir(out))
    assert all(name.endswith(".exr") for name in written), written  # no temporary left
    assert done <= len(written) <= done + 1  # the one being written when interrupted may have been renamed in time
    for name in written:
        assert run(conus_bin, "validate", out / name).returncode == 0
    again = run(conus_bin, "encode", *inputs, "--out-dir", out, "--focus", "0.5,0.5,0.1,4", "--skip-existing")
    assert again.returncode == 0, again.stderr
    assert f"{8 - len(written)} converted, {len(written)} skipped" in again.stdout


def test_a_warning_that_holds_for_every_input_is_printed_once(tmp_path, conus_bin):
    inputs = [picture(tmp_path / f"w{i}.png", 150, 100, i) for i in range(3)]
    m = tmp_path / "m.exr"
    assert run(conus_bin, "map", "foci", "--focus", "0.5,0.5,0.1,3", "-o", m, "-q").returncode == 0
    done = run(conus_bin, "encode", *inputs, "--out-dir", tmp_path / "out", "--map", m)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("warning: the map") == 1, done.stderr
    assert re.search(r'the warning "the map .*" held for 3 of 3 inputs \(printed once\)', done.stderr), done.stderr


def test_decode_size_keeps_the_aspect_when_one_side_is_given(tmp_path, conus_bin):
    src = picture(tmp_path / "wide.png", 300, 100)
    exr = tmp_path / "wide.exr"
    assert run(conus_bin, "encode", src, "-o", exr, "--focus", "0.5,0.5,0.1,3", "-q").returncode == 0
    for size, expected in (("256", (256, 85)), ("256x", (256, 85)), ("x50", (150, 50))):
        out = tmp_path / f"s{size}.png"
        done = run(conus_bin, "decode", exr, "-o", out, "--size", size)
        assert done.returncode == 0, done.stderr
        assert "stretches" not in done.stderr
        assert conus.read_image(str(out))[0].shape[1::-1] == expected, size
    # The view's aspect: a 0.2 x 0.6 view of the 300x100 source is 60x60 pixels, square.
    done = run(conus_bin, "decode", exr, "-o", tmp_path / "v.png", "--view", "0.4,0.2,0.6,0.8", "--size", "x120")
    assert conus.read_image(str(tmp_path / "v.png"))[0].shape[:2] == (120, 120)
    stretched = run(conus_bin, "decode", exr, "-o", tmp_path / "sq.png", "--size", "256x256")
    assert stretched.returncode == 0
    assert "warning: --size 256x256 stretches the view (300x100 source pixels, aspect 3) to aspect 1; --size 256x keeps" \
        in stretched.stderr, stretched.stderr
    bad = run(conus_bin, "decode", exr, "-o", tmp_path / "b.png", "--size", "0x")
    assert bad.returncode == 2 and "read" not in bad.stderr.split("conus decode: size")[0], bad.stderr


def test_usage_is_checked_before_work_and_exit_codes_say_whose_fault(tmp_path, conus_bin):
    src = picture(tmp_path / "p.png", 160, 120)
    bad = run(conus_bin, "encode", src, "-o", tmp_path / "o.exr", "--focus", "0.3,0.4,0.1")
    assert bad.returncode == 2
    assert bad.stderr.startswith('conus encode: focus "0.3,0.4,0.1" has 3 values'), bad.stderr
    assert "read" not in bad.stderr
    bad = run(conus_bin, "decode", tmp_path / "missing.exr", "-o", tmp_path / "o.png", "--view", "0.5,0.5,0.2,0.9")
    assert bad.returncode == 2 and "is empty or inverted" in bad.stderr, bad.stderr
    # The picture decides whether a face is found: bad data (1), not usage (2).
    faces = run(conus_bin, "encode", src, "-o", tmp_path / "f.exr", "--importance", "faces")
    assert faces.returncode == 1, faces.stderr
    assert "no face found" in faces.stderr or "face detector" in faces.stderr, faces.stderr
    missing = run(conus_bin, "validate", tmp_path / "nosuch.exr")
    assert missing.returncode == 1
    assert missing.stderr.strip() == f"conus validate: {tmp_path / 'nosuch.exr'}: no such file", missing.stderr


def test_quiet_is_quiet_on_success(tmp_path, conus_bin):
    src = picture(tmp_path / "p.png", 160, 120)
    done = run(conus_bin, "encode", src, "-o", tmp_path / "q.exr", "--focus", "0.3,0.4,0.1,3", "-q")
    assert (done.returncode, done.stdout, done.stderr) == (0, "", "")
    for args in (("decode", tmp_path / "q.exr", "-o", tmp_path / "q.png"), ("uniform", src, "-o", tmp_path / "u.exr"),
                 ("map", "foci", "--focus", "0.3,0.4,0.1,3", "-o", tmp_path / "m.exr", "--preview", tmp_path / "m.png")):
        done = run(conus_bin, *args, "-q")
        assert (done.returncode, done.stdout, done.stderr) == (0, "", ""), args
    done = run(conus_bin, "encode", src, src.replace("p.png", "nosuch.png"), "--out-dir", tmp_path / "b", "-q",
               "--focus", "0.3,0.4,0.1,3")
    assert done.returncode == 1 and "1 converted, 0 skipped (output exists), 1 failed" in done.stdout  # failures still say
    done = run(conus_bin, "validate", tmp_path / "q.exr", "-q")
    assert (done.returncode, done.stdout, done.stderr) == (0, "", "")
    info = run(conus_bin, "info", "-q", tmp_path / "q.exr")
    assert info.returncode == 0 and "sampling map" in info.stdout, info.stderr


def test_stage_times_add_up_to_the_total(tmp_path, conus_bin):
    src = picture(tmp_path / "p.png", 800, 600)
    done = run(conus_bin, "encode", src, "-o", tmp_path / "t.exr", "--focus", "0.3,0.4,0.1,3")
    assert done.returncode == 0, done.stderr
    stages = [float(s) for s in re.findall(r" done \((\d+\.\d+) s\)", done.stderr)]
    total = re.search(r"done in (\d+\.\d+) s: (\d+) stages (\d+\.\d+) s, start-up (\d+\.\d+) s, outside the stages "
                      r"(\d+\.\d+) s", done.stderr)
    assert total, done.stderr
    whole, count, staged, start, rest = (float(x) for x in total.groups())
    assert count == len(stages) >= 3
    assert staged == pytest.approx(sum(stages), abs=0.011 * len(stages))
    assert whole == pytest.approx(staged + start + rest, abs=0.02)


def test_a_camera_is_echoed_as_given(tmp_path, conus_bin):
    field = tmp_path / "terrain.exr"
    assert run(conus_bin, "heightfield", "encode", "procedural", "-o", field, "--size", "64x64", "-q").returncode == 0
    done = run(conus_bin, "decode", field, "-o", tmp_path / "above.png", "--camera", "0,3000,-500,0,0,3000,50",
               "--size", "160x90")
    assert done.returncode == 0, done.stderr
    assert "camera 0,3000,-500,0,0,3000,50\n" in done.stdout, done.stdout
