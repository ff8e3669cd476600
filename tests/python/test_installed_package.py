"""The installed package as a user's own script meets it, run from an empty folder in the
environment docs/README.md gives: arrays it cannot mean refused in the caller's words, warnings at
the caller's line naming the call and the input (conus.dask's naming the inputs), and
conus.uniform a conus.File like the one `conus uniform` writes."""
import subprocess
import textwrap

import numpy as np

import conus


def run_script(installed, folder, text):
    (folder / "user.py").write_text(textwrap.dedent(text).lstrip())
    return subprocess.run(["python3", "-W", "always", "user.py"], cwd=folder, env=installed, capture_output=True, text=True,
                          timeout=300)


def test_arrays_it_cannot_mean_are_refused_in_the_callers_words(tmp_path, installed):
    done = run_script(installed, tmp_path, """
        import numpy as np
        import conus
        for shape in [(3, 40, 60), (40, 60, 0), (0, 60, 3)]:
            try:
                conus.encode(np.zeros(shape, np.float32))
                print("accepted", shape)
            except conus.Error as e:
                print(e.code, "|", e)
        # Channel names that say so: three rows of 60 channels.
        print(conus.uniform(np.zeros((3, 40, 60), np.float32), size=(20, 1), channels=[f"C{i}" for i in range(60)]))
    """)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == ("invalid-argument | pixels of shape (3, 40, 60) look channel-first (channels, height, width); "
                        "CoNUS takes (height, width, channels): pass numpy.moveaxis(pixels, 0, -1)"), lines[0]
    assert lines[1].startswith("invalid-argument | pixels of shape (40, 60, 0) have no channels"), lines[1]
    assert lines[2] == "invalid-argument | pixels of shape (0, 60, 3) hold no pixels", lines[2]
    assert lines[3].startswith("<conus.File 20x1 CoNUS image of a 40x3 source"), lines[3]
    assert "makeImage" not in done.stdout + done.stderr


def test_warnings_point_at_the_callers_line_and_name_the_input(tmp_path, installed):
    done = run_script(installed, tmp_path, """
        import numpy as np
        import conus, conus.dask
        pixels = np.full((40, 60, 3), 0.5, np.float32)
        pixels[5, 5] = np.nan
        conus.encode(pixels, map=conus.Map.foci([(0.5, 0.5, 0.1, 2)]), size=(30, 20), fit=0)
        conus.write_image("nan.exr", pixels)
        conus.write_image("fine.png", np.full((40, 60, 3), 0.5, np.float32))
        rows = conus.dask.encode_files(["nan.exr", "fine.png"], "exr", scheduler="sync", size=(30, 20), fit=0)
        print(rows.count("converted"), [r["warnings"] for r in rows])
    """)
    assert done.returncode == 0, done.stderr
    err = done.stderr
    nan = "pixels, an array of shape (40, 60, 3) and dtype float32, hold 3 NaN or infinite values;"
    assert f"user.py:5: UserWarning: conus.encode: {nan}" in err, err
    assert "user.py:5: UserWarning: conus.encode: the map was made for pictures of aspect 1" in err, err
    assert f"user.py:6: UserWarning: conus.write_image: {nan}" in err, err
    # A batch says each warning once, at the line that started it, with the inputs it held for.
    assert "user.py:8: UserWarning: conus.dask.encode_files: nan.exr: pixels, an array of shape (40, 60, 3)" in err, err
    assert "user.py:8: UserWarning: conus.dask.encode_files: 2 of 2 inputs (fine.png, nan.exr): conus.encode: no foci or map" in err, err
    assert "__init__.py" not in err and "dask.py" not in err, err
    assert done.stdout.startswith("2 [["), done.stdout


def test_uniform_is_a_file_like_the_one_conus_uniform_writes(tmp_path, installed, asymmetric):
    conus.write_image(str(tmp_path / "p.png"), asymmetric[..., :3])
    done = run_script(installed, tmp_path, """
        import conus
        pixels, channels = conus.read_image("p.png")
        u = conus.uniform(pixels, channels=channels)
        conus.write("u-py.exr", u)
        print(u, conus.decode(u).shape)
    """)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("<conus.File 60x40 CoNUS image of a 240x160 source, 2x2 map> (160, 240, 3)"), done.stdout
    cli = subprocess.run(["conus", "uniform", "p.png", "-o", "u-cli.exr", "--backend", "cpu", "-q"], cwd=tmp_path,
                         env=installed, capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    ours, theirs = conus.read(str(tmp_path / "u-py.exr")), conus.read(str(tmp_path / "u-cli.exr"))
    assert ours.channels == theirs.channels == ["R", "G", "B"]
    np.testing.assert_allclose(ours.pixels, theirs.pixels, atol=1e-3)  # both stored as half
    np.testing.assert_array_equal(ours.map.nodes, theirs.map.nodes)
