"""import conus: the bindings against the real binary, OpenEXR's own tools and numpy."""
import json
import re
import subprocess
import threading

import numpy as np
import pytest

import conus

FOCUS = (0.1, 0.12, 0.08, 4.0)  # on the red patch


def run(*args):
    return subprocess.run(list(args), capture_output=True, text=True, check=True)


def test_encode_write_read_round_trip(tmp_path, asymmetric, conus_bin):
    f = conus.encode(asymmetric, foci=[FOCUS], size=(120, 80), exact_k=True)  # the focus as given, recorded
    assert f.pixels.shape == (80, 120, 4) and f.pixels.dtype == np.float32
    assert f.channels == ["R", "G", "B", "A"]
    path = str(tmp_path / "a.exr")
    conus.write(path, f)
    g = conus.read(path)
    assert g.source_size == (240, 160)
    assert g.attributes["analytic"]["foci"] == [pytest.approx(FOCUS)]
    # Half floats in the file: within half's precision of what was encoded.
    np.testing.assert_allclose(g.pixels, f.pixels, rtol=1e-3, atol=1e-3)
    # The real binary and OpenEXR's own exrheader read the same file.
    info = json.loads(run(conus_bin, "info", path, "--json").stdout)
    assert info["source"]["width"] == 240 and info["source"]["height"] == 160
    header = run("exrheader", path).stdout
    assert "dataWindow (type box2i): (0 0) - (119 79)" in header and 'name (type string): "samplingmap"' in header


def test_python_encode_matches_the_cli(tmp_path, asymmetric, conus_bin):
    src = str(tmp_path / "src.exr")
    conus.write_image(src, asymmetric)
    pixels, channels = conus.read_image(src)  # what the CLI reads: half-float values
    assert channels == ["R", "G", "B", "A"]
    cli = str(tmp_path / "cli.exr")
    run(conus_bin, "encode", src, "-o", cli, "--focus", ",".join(map(str, FOCUS)), "--size", "120x80", "--backend", "cpu", "-q")
    ours = conus.encode(pixels, foci=[FOCUS], size=(120, 80), channels=channels)
    theirs = conus.read(cli)
    np.testing.assert_array_equal(ours.map.nodes, theirs.map.nodes)
    np.testing.assert_allclose(ours.pixels, theirs.pixels, atol=1e-3)


def test_decode_puts_the_patch_back_and_beats_uniform_in_the_focus(asymmetric):
    f = conus.encode(asymmetric, foci=[FOCUS], size=(120, 80))
    frame = conus.decode(f)
    assert frame.shape == (160, 240, 4)
    assert frame[8, 10, 0] > 0.9 and frame[8, 10, 1] < 0.1  # red, top-left
    assert frame[150, 230, 0] < 0.3  # not red, bottom-right
    assert frame[80, 230, 3] == pytest.approx(0.5, abs=0.02)  # partial alpha kept
    # The focus region, zoomed: CoNUS beats the uniform image of the same pixel count.
    view = (0.0, 0.0, 0.25, 0.25)
    zoom = conus.decode(f, view=view, size=(60, 40))
    truth = asymmetric[:40, :60]
    small = conus.uniform(asymmetric, size=(120, 80))
    uniform_zoom = conus.decode(small, view=view, size=(60, 40))
    assert conus.psnr(zoom, truth) > conus.psnr(uniform_zoom, truth) + 3.0


def test_maps_distort_undistort_and_density():
    m = conus.Map.foci([(0.5, 0.5, 0.1, 4)])
    assert (m.columns, m.rows) == (conus.DEFAULT_MAP_SIDE, conus.DEFAULT_MAP_SIDE)
    rng = np.random.default_rng(7)
    p = rng.random((1000, 2))
    d = m.distort(p)
    assert d.shape == p.shape and not np.allclose(d, p)
    np.testing.assert_allclose(m.undistort(d), p, atol=1e-9)
    # Vectorized over any leading shape.
    assert m.distort(p.reshape(10, 100, 2)).shape == (10, 100, 2)
    identity = conus.Map.identity(5, 3)
    np.testing.assert_allclose(identity.distort(p), p, atol=1e-12)
    density = m.density(np.array([[0.5, 0.5], [0.02, 0.98]]))
    assert density[0] > 4 and density[1] < 1  # k^2 = 16 at the centre, as far as a 65-node grid resolves it
    nodes = m.nodes
    assert nodes.shape == (m.rows, m.columns, 2) and not nodes.flags.writeable
    assert np.shares_memory(nodes, m.nodes)  # a view, not a copy
    rebuilt = conus.Map.from_nodes(np.array(nodes))
    np.testing.assert_allclose(rebuilt.distort(p), d, atol=1e-6)


def test_foci_falloff_and_measures():
    # A narrower transition (falloff 1.25) spends fewer samples on the ring r..2r than today's
    # (2, density); a bad falloff is refused. measures() is what `conus info` reports.
    grid = np.stack(np.meshgrid((np.arange(200) + 0.5) / 200, (np.arange(200) + 0.5) / 200), -1).reshape(-1, 2)
    ring = np.hypot(grid[:, 0] - 0.4, (grid[:, 1] - 0.55) / 1.5) / 0.08
    shares = {}
    for falloff in ("2", "1.25", "1.5,logr"):
        m = conus.Map.foci([(0.4, 0.55, 0.08, 4)], aspect=1.5, falloff=falloff)
        d = m.density(grid)
        shares[falloff] = d[(ring > 1) & (ring < 2)].sum() / d.sum()
        measures = m.measures(1.5)
        assert measures["max_anisotropy"] > 1.5 and measures["min_cell_density"] < 1 < measures["max_cell_density"]
    assert shares["1.25"] < shares["2"] and shares["1.5,logr"] < shares["2"]
    # The default is the narrow ring, 1.25 (widened where the anisotropy bound needs).
    assert conus.Map.foci([(0.4, 0.55, 0.08, 4)], aspect=1.5, falloff="1.25").measures(1.5) == conus.Map.foci([(0.4, 0.55, 0.08, 4)], aspect=1.5).measures(1.5)
    with pytest.raises(conus.Error, match="falloff"):
        conus.Map.foci([(0.5, 0.5, 0.1, 4)], falloff="0.5")


def test_auto_and_springs_maps_concentrate_where_asked():
    importance = np.zeros((64, 96), np.float32)
    importance[10:20, 60:80] = 1.0
    m = conus.Map.auto(importance, grid=33)
    box, far = m.density(np.array([[0.73, 0.23], [0.2, 0.8]]))
    assert box > 2 * far
    s = conus.Map.springs([(0.3, 0.6, 0.15, 1.0)], grid=17)
    inside, outside = s.density(np.array([[0.3, 0.6], [0.85, 0.15]]))
    assert inside > outside


def test_detail_importance_is_the_sobel_of_what_a_display_shows(asymmetric):
    from scipy import ndimage
    detail = np.asarray(conus.importance(asymmetric, "detail", channels=["R", "G", "B", "A"]))
    assert detail.shape == (160, 240, 1) and detail.dtype == np.float32
    # The same by scipy: alpha divided out, sRGB-encoded, clamped, the mean of R, G, B, a Sobel
    # gradient magnitude with the edges clamped.
    colour = np.clip(asymmetric[..., :3] / asymmetric[..., 3:], 0, 1)
    shown = conus.linear_to_srgb(colour).mean(axis=2)
    expected = np.hypot(ndimage.sobel(shown, 1, mode="nearest"), ndimage.sobel(shown, 0, mode="nearest"))
    assert np.allclose(detail[..., 0], expected, atol=2e-3)
    # High on the red patch's right edge and the blue disc's rim, nothing inside either.
    assert detail[10, 35, 0] > 0.3 and detail[115, 160, 0] > 0.5 and detail[95, 180, 0] > 0.5
    assert detail[8, 10, 0] < 1e-6 and detail[115, 180, 0] < 1e-6
    auto = conus.Map.auto(detail, grid=33)
    rim, flat = auto.density(np.array([[160.5 / 240, 115.5 / 160], [10.5 / 240, 8.5 / 160]]))
    assert rim > flat
    with pytest.raises(conus.Error, match="kind"):
        conus.importance(asymmetric, "saliency")


ASTRONAUT = "/usr/lib/python3/dist-packages/skimage/data/astronaut.png"  # python3-skimage (scripts/packages.txt)


def test_faces_importance_is_the_clis(tmp_path, conus_bin):
    """conus.importance(pixels, "faces") finds the astronaut's face through the library the CLI uses:
    Map.auto of it has the nodes of `conus map auto --importance faces`; a picture without a face is
    refused, as the CLI refuses it (exit 1)."""
    pixels, channels = conus.read_image(ASTRONAUT)
    faces = np.asarray(conus.importance(pixels, "faces", channels=channels))
    h, w = faces.shape[:2]
    assert faces.shape[2] == 1 and faces.dtype == np.float32
    # The face is around (0.44, 0.23); the flag at the left edge and the suit are nothing.
    assert faces[int(0.23 * h), int(0.44 * w), 0] == 1.0
    assert faces[int(0.6 * h), int(0.1 * w), 0] == 0.0 and faces[int(0.85 * h), int(0.8 * w), 0] == 0.0
    ours = conus.Map.auto(faces)
    cli = str(tmp_path / "faces.exr")
    run(conus_bin, "map", "auto", "--importance", "faces", "--image", ASTRONAUT, "-o", cli)
    np.testing.assert_array_equal(ours.nodes, conus.read(cli).map.nodes)
    face, suit = ours.density(np.array([[0.44, 0.23], [0.8, 0.85]]))
    assert face > 3 * suit
    flat = np.full((64, 96, 3), 0.4, np.float32)
    with pytest.raises(conus.Error, match="no face found") as e:
        conus.importance(flat, "faces")
    assert e.value.code == "unsupported"
    with pytest.raises(conus.Error, match="is not one of detail, faces"):
        conus.importance(flat, "saliency")


def test_encode_without_foci_follows_the_pictures_detail_as_the_cli_does(tmp_path, conus_bin):
    """No foci and no map: the map of the picture's own detail, as `conus encode` makes it (the same
    nodes), so a detailed corner gets more samples than the flat rest; a UserWarning says so."""
    h, w = 160, 240
    picture = np.full((h, w, 3), 0.4, np.float32)
    rng = np.random.default_rng(3)
    picture[:50, 170:] = rng.random((50, 70, 3)).astype(np.float32)  # detail in the top-right corner only
    src = str(tmp_path / "src.exr")
    conus.write_image(src, picture)
    pixels, channels = conus.read_image(src)
    with pytest.warns(UserWarning, match="own detail"):
        ours = conus.encode(pixels, channels=channels, size=(60, 40), fit=0)
    corner, flat = ours.map.density(np.array([[205 / w, 25 / h], [60 / w, 110 / h]]))
    assert corner > 2 * flat
    assert ours.budget is None and ours.attributes.get("analytic") is None
    cli = str(tmp_path / "cli.exr")
    out = run(conus_bin, "encode", src, "-o", cli, "--size", "60x40", "--fast", "--backend", "cpu")
    assert "detail, context floor" in out.stdout
    np.testing.assert_array_equal(ours.map.nodes, conus.read(cli).map.nodes)


def test_frame_loss_budget_sets_the_floor(asymmetric):
    h, w = asymmetric.shape[:2]
    importance = np.zeros((h, w), np.float32)
    importance[h // 4:h // 2, w // 2:3 * w // 4] = 1.0
    size = (w // 4, h // 4)
    # On this picture every map of the family its encodes measure loses 0.75 dB or more over the
    # frame (the ramp, which the uniform image keeps best), so the tight budget is 1 dB: the loss
    # said is what the kept map's own encode measured, and it holds.
    tight = conus.Map.auto_for_frame_loss(importance, asymmetric[..., :3], size, 1.0, grid=33)
    loose = conus.Map.auto_for_frame_loss(importance, asymmetric[..., :3], size, 2.0, grid=33)
    # (map, floor, loss, ROI gain): a looser budget buys a lower floor and more gain.
    assert loose[1] < tight[1]
    assert tight[2] <= 1.0 + 1e-9 and loose[2] <= 2.0 + 1e-9
    assert loose[3] > tight[3]
    with pytest.raises(conus.Error):
        conus.Map.auto_for_frame_loss(importance, asymmetric[..., :3], size, -1.0)


def test_views_and_ownership(asymmetric):
    f = conus.encode(asymmetric, foci=[FOCUS], size=(120, 80))
    a, b = f.pixels, f.pixels
    assert np.shares_memory(a, b)
    a[0, 0, 0] = 42.0
    assert f.pixels[0, 0, 0] == 42.0  # the File's own pixels
    frame = conus.decode(f, size=(30, 20))
    assert not frame.flags.owndata and frame.base is not None  # the C++ image, not copied
    del f
    assert np.isfinite(frame).all()


def test_errors_carry_their_rule(tmp_path):
    folded = np.array(conus.Map.identity(3, 3).nodes)
    folded[1, 1] = (0.9, 0.9)  # the centre node past its neighbours: cells fold
    with pytest.raises(conus.Error) as e:
        conus.Map.from_nodes(folded)
    assert e.value.code == "invalid-map" and e.value.rule == 11
    bad = tmp_path / "bad.exr"
    bad.write_bytes(b"not an exr at all")
    with pytest.raises(conus.Error) as e:
        conus.read(str(bad))
    assert e.value.rule == 1 and "\n" not in str(e.value)
    with pytest.raises(conus.Error) as e:
        conus.encode(np.zeros((4, 4, 3), np.float32), foci=[(0.5, 0.5, 0.1, 100)])
    assert e.value.code == "invalid-argument" and e.value.rule is None
    with pytest.raises(conus.Error):
        conus.encode(np.zeros((4, 4, 2, 2), np.float32))


def test_long_calls_release_the_gil(asymmetric):
    # Two threads decode at once; each result equals the single-threaded one.
    f = conus.encode(asymmetric, foci=[FOCUS], size=(120, 80))
    expected = conus.decode(f, size=(480, 320))
    results = [None, None]

    def work(i):
        results[i] = conus.decode(f, size=(480, 320))

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        np.testing.assert_array_equal(r, expected)


def test_gpu_encode_agrees_with_the_cpu_reference(asymmetric):
    f_cpu = conus.encode(asymmetric, foci=[FOCUS], size=(120, 80))
    f_gl = conus.encode(asymmetric, foci=[FOCUS], size=(120, 80), backend="egl")
    assert conus.psnr(f_gl.pixels, f_cpu.pixels) > 45.0


def test_fit_brings_the_decoded_frame_closer_for_conus_and_uniform(tmp_path, asymmetric, conus_bin):
    """encode(fit=N) and uniform(fit=N): the decoded frame at the source's size nearer the source
    than without the fit; the fitted encode is what `conus encode --fit --fit-iterations N` writes."""
    def mse(a, b):
        return float(np.mean((a[..., :4] - b[..., :4]) ** 2))
    plain, fitted = (conus.encode(asymmetric, foci=[FOCUS], size=(60, 40), fit=n) for n in (0, 3))
    assert mse(conus.decode(fitted), asymmetric) < 0.9 * mse(conus.decode(plain), asymmetric)
    small, small_fit = (conus.uniform(asymmetric, size=(60, 40), fit=n) for n in (0, 3))
    assert mse(conus.decode(small_fit), asymmetric) < 0.9 * mse(conus.decode(small), asymmetric)
    src = str(tmp_path / "src.exr")
    conus.write_image(src, asymmetric)
    pixels, channels = conus.read_image(src)
    cli = str(tmp_path / "cli.exr")
    run(conus_bin, "encode", src, "-o", cli, "--focus", ",".join(map(str, FOCUS)), "--size", "60x40", "--backend", "cpu",
        "--fit", "--fit-iterations", "3", "--float", "-q")
    ours = conus.encode(pixels, foci=[FOCUS], size=(60, 40), channels=channels, fit=3)
    np.testing.assert_allclose(ours.pixels, conus.read(cli).pixels, atol=1e-4)
    with pytest.raises(conus.Error):
        conus.encode(asymmetric, foci=[FOCUS], size=(60, 40), fit=-1)
    # fit_hold=0: the plain least squares, no damping toward the filtered encode: closer still
    # (through the same map: the budget's confirming encodes are fitted with the hold given).
    unheld = conus.encode(asymmetric, map=fitted.map, size=(60, 40), fit=3, fit_hold=0.0)
    assert mse(conus.decode(unheld), asymmetric) <= mse(conus.decode(fitted), asymmetric)
    with pytest.raises(conus.Error):
        conus.encode(asymmetric, foci=[FOCUS], size=(60, 40), fit=3, fit_hold=-1.0)


def test_encode_holds_the_frame_loss_budget(tmp_path, conus_bin):
    """Two large foci on a detailed picture ask more pixels than there are: encode(foci=...) lowers
    every k alike to hold the budget, warns, and says what it gave in File.budget, as `conus encode`
    does (the same k in the same file); exact_k=True keeps k and warns what the frame pays."""
    rng = np.random.default_rng(5)
    h, w = 160, 240
    y, x = np.mgrid[0:h, 0:w]
    detail = (0.5 + 0.25 * np.sin(0.31 * x + 0.17 * y)[..., None] + 0.25 * rng.random((h, w, 3))).astype(np.float32)
    foci = [(0.3, 0.4, 0.16, 4.0), (0.7, 0.55, 0.15, 4.0)]
    with pytest.warns(UserWarning, match=r"the loss budget \(whole frame 1\.5 dB, tiles 4 dB\) lowered k from 4, 4 to "):
        f = conus.encode(detail, foci=foci, size=(60, 40), fit=0)
    b = f.budget
    assert b["lowered"] and b["k_asked"] == [4.0, 4.0] and b["frame_loss"] == 1.5
    assert 1.0 < b["k_given"][0] < 4.0 and b["k_given"][0] == pytest.approx(b["k_given"][1])
    assert b["predicted_frame_loss"] <= 1.5 and b["predicted_tile_loss"] <= 4.0 and b["ask"] > 1.0
    # fit=0: no encode confirms the model, which overstates the foci's gain: not given (as --fast
    # does not print it); fitted, one encode confirms it and the gain is given.
    assert not b["confirmed"] and b["predicted_roi_gain"] is None
    with pytest.warns(UserWarning):
        fitted = conus.encode(detail, foci=foci, size=(60, 40)).budget
    assert fitted["confirmed"] and isinstance(fitted["predicted_roi_gain"], float)
    assert b["context_downscale"] > b["uniform_downscale"] == pytest.approx(4.0)
    assert [focus[3] for focus in f.attributes["analytic"]["foci"]] == pytest.approx(b["k_given"])
    # The binary gives the same k for the same picture.
    src = str(tmp_path / "detail.exr")
    conus.write_image(src, detail)
    pixels, channels = conus.read_image(src)
    cli = str(tmp_path / "cli.exr")
    out = run(conus_bin, "encode", src, "-o", cli, "--size", "60x40", "--fast", *[a for fo in foci for a in ("--focus", ",".join(map(str, fo)))]).stdout
    assert re.search(r"focus 1 at .*: k [0-9.]+ \(asked 4\)", out) and "k as asked: --exact-k" in out
    with pytest.warns(UserWarning):
        ours = conus.encode(pixels, foci=foci, size=(60, 40), channels=channels, fit=0)
    theirs = [focus[3] for focus in conus.read(cli).attributes["analytic"]["foci"]]
    assert [focus[3] for focus in ours.attributes["analytic"]["foci"]] == pytest.approx(theirs)
    # exact_k keeps k, a looser budget gives more, and no foci means no budget.
    with pytest.warns(UserWarning, match="exact_k"):
        e = conus.encode(detail, foci=foci, size=(60, 40), fit=0, exact_k=True)
    assert e.budget["k_given"] == [4.0, 4.0] and not e.budget["lowered"]
    # What the anisotropy bound cost each k = 4 focus, as the CLI prints it.
    assert any(n.startswith("focus 0.3,0.4,0.16,4: transition widened from 1.25 to ") for n in e.budget["builder_notes"])
    assert e.budget["predicted_frame_loss"] > 1.5 or e.budget["predicted_tile_loss"] > 4.0
    with pytest.warns(UserWarning):
        tight = conus.encode(detail, foci=foci, size=(60, 40), fit=0, frame_loss=0.1)
    assert tight.budget["k_given"][0] < b["k_given"][0]
    assert conus.encode(detail, size=(60, 40), fit=0).budget is None


def test_encode_writes_the_budgets_confirming_encode(asymmetric):
    """The budget's confirming encode of the map it keeps is the File's pixels (not encoded again):
    the same as a fresh encode and fit through that File's own map, and a fit that did something."""
    foci = [(0.62, 0.4, 0.13, 3.0)]
    for exact in (True, False):
        with pytest.warns(UserWarning):
            f = conus.encode(asymmetric, foci=foci, size=(60, 40), exact_k=exact)
        again = conus.encode(asymmetric, map=f.map, size=(60, 40))
        np.testing.assert_allclose(f.pixels, again.pixels, atol=1e-5)
        unfitted = conus.encode(asymmetric, map=f.map, size=(60, 40), fit=0)
        assert np.abs(f.pixels - unfitted.pixels).max() > 1e-3
