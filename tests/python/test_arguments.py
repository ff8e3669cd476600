"""What Python users pass, as the CLI takes it: integer arrays as display codes, one-line type
errors, the CLI's refusals (.png output, inverted views, fit=True), NaN handling, a map's aspect."""
import subprocess
import warnings

import numpy as np
import pytest

import conus

FOCUS = (0.3, 0.4, 0.1, 3.0)


def codes_of(linear):
    """8-bit sRGB codes of linear values, as a PNG holds them."""
    return np.round(conus.linear_to_srgb(linear) * 255).astype(np.uint8)


def test_uint8_arrays_are_display_codes_like_an_8_bit_png(tmp_path, asymmetric, conus_bin):
    rgb = np.ascontiguousarray(asymmetric[..., :3])
    codes = codes_of(rgb)
    png = str(tmp_path / "a.png")
    conus.write_image(png, codes)  # codes in, the same codes in the file
    read, channels = conus.read_image(png)
    assert np.abs(codes_of(read).astype(int) - codes).max() <= 1  # not a near-white picture
    # The array and the file read back are the same light, within 8-bit rounding ...
    np.testing.assert_allclose(conus.uniform(codes, size=(120, 80)).pixels, conus.uniform(read, size=(120, 80)).pixels, atol=1e-4)
    # ... and encode to the same CoNUS image through the same map. (The budget's choices, made on
    # its model and confirming encodes, may differ for two pictures that differ by rounding: the map is given here.)
    from_array = conus.encode(codes, foci=[FOCUS], size=(120, 80))
    from_file = conus.encode(read, map=from_array.map, size=(120, 80), channels=channels)
    np.testing.assert_allclose(from_array.pixels, from_file.pixels, atol=2e-3)
    # ... and to what the CLI makes of the PNG through that map.
    conus.write(str(tmp_path / "map.exr"), from_array)
    cli = str(tmp_path / "cli.exr")
    subprocess.run([conus_bin, "encode", png, "-o", cli, "--map", str(tmp_path / "map.exr"), "--size", "120x80",
                    "--backend", "cpu", "-q"], check=True)
    np.testing.assert_allclose(from_array.pixels, conus.read(cli).pixels, atol=3e-3)
    # Not 0..255 taken as light: the decoded frame has the source's range and mean (the plain
    # filtered encode: the default fit to the decoder may overshoot a little at edges).
    frame = conus.decode(conus.encode(codes, foci=[FOCUS], size=(120, 80), fit=0))
    assert frame.max() <= 1.01
    assert abs(frame.mean() - rgb.mean()) < 0.01
    # write_image of the decoded frame gives back the codes' picture.
    conus.write_image(str(tmp_path / "back.png"), frame)
    back, _ = conus.read_image(str(tmp_path / "back.png"))
    assert abs(back.mean() - rgb.mean()) < 0.01


def test_uint16_codes_and_the_colorspace_override(asymmetric):
    rgb = np.ascontiguousarray(asymmetric[..., :3])
    codes16 = np.round(conus.linear_to_srgb(rgb) * 65535).astype(np.uint16)
    a = conus.uniform(codes16, size=(60, 40)).pixels
    b = conus.uniform(rgb, size=(60, 40)).pixels
    np.testing.assert_allclose(a, b, atol=1e-3)
    # colorspace="linear": codes scaled to [0, 1] and taken as light; "srgb" on floats linearizes them.
    lin = conus.uniform(codes16, size=(60, 40), colorspace="linear").pixels
    np.testing.assert_allclose(lin, conus.uniform(codes16.astype(np.float32) / 65535, size=(60, 40)).pixels, atol=1e-5)
    srgb_floats = conus.uniform(conus.linear_to_srgb(rgb), size=(60, 40), colorspace="srgb").pixels
    np.testing.assert_allclose(srgb_floats, b, atol=2e-3)
    with pytest.raises(conus.Error, match="colorspace must be 'auto', 'srgb' or 'linear'"):
        conus.uniform(rgb, colorspace="rec709")
    with pytest.raises(TypeError, match="dtype int64: give float linear light, or uint8 / uint16"):
        conus.encode(np.zeros((8, 8, 3), np.int64))


def one_line_type_error(call):
    with pytest.raises(TypeError) as caught:
        call()
    text = str(caught.value)
    assert "\n" not in text and len(text) < 300, text
    assert "incompatible function arguments" not in text
    return text


def test_type_errors_are_one_readable_line(asymmetric):
    pixels = np.ascontiguousarray(asymmetric[..., :3])
    # A focus alone, as a tuple or a list, is one focus; a tuple of tuples is a list of foci.
    one = conus.encode(pixels, foci=FOCUS, size=(60, 40), exact_k=True)  # k as given, recorded
    assert one.attributes["analytic"]["foci"] == [pytest.approx(FOCUS)]
    both = conus.encode(pixels, foci=(FOCUS, (0.7, 0.6, 0.1, 2)), size=(60, 40))
    assert len(both.attributes["analytic"]["foci"]) == 2
    for three in ([(0.3, 0.4, 0.1)], (0.3, 0.4, 0.1)):
        with pytest.raises(conus.Error, match=r"focus 1 \(0.3, 0.4, 0.1\) has 3 values; a focus is \(u, v, r, k\)"):
            conus.encode(pixels, foci=three)
    assert "not the str 'RGB'" in one_line_type_error(lambda: conus.encode(pixels, channels="RGB"))
    text = one_line_type_error(lambda: conus.encode("photo.png"))
    assert "not the str 'photo.png'; read a picture file with conus.read_image" in text
    assert "not the str 'photo.exr'" in one_line_type_error(lambda: conus.decode("photo.exr"))
    assert "size must be (width, height)" in one_line_type_error(lambda: conus.decode(one, size=512))
    assert "view must be (u0, v0, u1, v1)" in one_line_type_error(lambda: conus.decode(one, view=(0, 0, 1)))
    assert "map must be a conus.Map" in one_line_type_error(lambda: conus.encode(pixels, map="m.exr"))
    # Whatever pybind11 itself refuses is one line too, with the signature expected.
    text = one_line_type_error(lambda: conus.Map.springs("strokes"))
    assert text.startswith("conus.Map.springs(str): expected springs(strokes:"), text
    assert "path: str" in one_line_type_error(lambda: conus.read(pixels))


def test_python_refuses_what_the_cli_refuses(tmp_path, asymmetric, conus_bin):
    pixels = np.ascontiguousarray(asymmetric[..., :3])
    f = conus.encode(pixels, foci=[FOCUS], size=(60, 40))
    with pytest.raises(conus.Error, match=r"x.png must end in .exr: a CoNUS file is an OpenEXR file") as caught:
        conus.write(str(tmp_path / "x.png"), f)
    assert caught.value.code == "invalid-argument"
    assert not (tmp_path / "x.png").exists()
    png = str(tmp_path / "p.png")
    conus.write_image(png, pixels)
    cli = subprocess.run([conus_bin, "encode", png, "-o", str(tmp_path / "y.png"), "--focus", "0.3,0.4,0.1,3"],
                         capture_output=True, text=True)
    assert cli.returncode == 2 and "must end in .exr" in cli.stderr
    # An inverted view: refused by both, in the same words.
    with pytest.raises(conus.Error, match=r"view \(0.7, 0.5, 0.3, 0.1\) is empty or inverted: it needs u0 < u1"):
        conus.decode(f, view=(0.7, 0.5, 0.3, 0.1))
    conus.write(str(tmp_path / "f.exr"), f)
    cli = subprocess.run([conus_bin, "decode", str(tmp_path / "f.exr"), "-o", str(tmp_path / "v.png"), "--view",
                          "0.7,0.5,0.3,0.1"], capture_output=True, text=True)
    assert cli.returncode == 2 and "is empty or inverted: it needs u0 < u1" in cli.stderr
    # A view wholly outside the picture: refused by both.
    with pytest.raises(conus.Error, match=r"view \(1.2, 0, 1.5, 0.5\) lies wholly outside the image"):
        conus.decode(f, view=(1.2, 0, 1.5, 0.5))
    # fit is a count, as --fit-iterations.
    assert "not True" in one_line_type_error(lambda: conus.encode(pixels, fit=True))
    with pytest.raises(conus.Error, match="fit must be 0 .none. or 1 to 100 iterations"):
        conus.uniform(pixels, fit=-1)


def test_nonfinite_pixels_warn_or_are_repaired_as_fix_nonfinite(tmp_path, asymmetric):
    pixels = np.ascontiguousarray(asymmetric[..., :3]).copy()
    pixels[50, 60] = np.nan
    pixels[51, 60, 1] = np.inf
    with pytest.warns(UserWarning, match=r"conus.uniform: pixels, an array of shape \(160, 240, 3\) and dtype float32, hold 4 NaN "
                                         r"or infinite values; .*fix_nonfinite='box3' or 'black'"):
        kept = conus.uniform(pixels, size=(240, 160)).pixels
    assert np.isnan(kept).any()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        black = conus.uniform(pixels, size=(240, 160), fix_nonfinite="black").pixels
        box3 = conus.uniform(pixels, size=(240, 160), fix_nonfinite="box3").pixels
    assert np.isfinite(black).all() and np.isfinite(box3).all()
    assert black[50, 60].tolist() == [0, 0, 0]
    # box3: the mean of the finite neighbours, close to the smooth picture around it.
    np.testing.assert_allclose(box3[50, 60], asymmetric[50, 60, :3], atol=0.05)
    f = conus.encode(pixels, foci=[FOCUS], fix_nonfinite="box3")
    assert np.isfinite(f.pixels).all()
    with pytest.warns(UserWarning, match="NaN or infinite values"):
        conus.write_image(str(tmp_path / "nan.exr"), pixels)
    conus.write_image(str(tmp_path / "fixed.exr"), pixels, fix_nonfinite="black")
    assert np.isfinite(conus.read_image(str(tmp_path / "fixed.exr"))[0]).all()


def test_a_map_made_for_another_aspect_warns(tmp_path, asymmetric, conus_bin):
    pixels = np.ascontiguousarray(asymmetric[..., :3])  # 240x160: aspect 1.5
    with pytest.warns(UserWarning, match=r"aspect 1 .* this one's is 1.5: its foci become ellipses"):
        conus.encode(pixels, map=conus.Map.foci([FOCUS]))
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*aspect")  # the budget's own notes may still come
        conus.encode(pixels, map=conus.Map.foci([FOCUS], aspect=1.5))
        conus.encode(pixels, map=conus.encode(pixels, foci=[FOCUS]).map)
    # The CLI: a map file of aspect 1 on a 1.5:1 picture warns; one made with --aspect 1.5 does not.
    png = str(tmp_path / "p.png")
    conus.write_image(png, pixels)
    for aspect, warned in (("1", True), ("1.5", False)):
        m = str(tmp_path / f"m{aspect}.exr")
        subprocess.run([conus_bin, "map", "foci", "--focus", "0.3,0.4,0.1,3", "--aspect", aspect, "-o", m, "-q"], check=True)
        done = subprocess.run([conus_bin, "encode", png, "-o", str(tmp_path / "e.exr"), "--map", m, "-q"],
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        assert ("foci become ellipses" in done.stderr) == warned, done.stderr


def test_a_map_finer_than_the_image_can_show_is_refused_as_the_cli_refuses_grid(tmp_path, asymmetric, conus_bin):
    pixels = np.ascontiguousarray(asymmetric[..., :3])  # 240x160
    fine = conus.Map.foci([FOCUS], aspect=1.5, grid=257)
    # 16x11 pixels hold at most 129 nodes a side (4 a pixel along the longer side plus one, 129 always).
    with pytest.raises(conus.Error, match=r"grid of 257 is finer than a 16x11 image can show; at most 129 nodes a side"):
        conus.encode(pixels, map=fine, size=(16, 11))
    assert conus.encode(pixels, map=fine, size=(64, 43)).map.columns == 257  # 4 nodes a pixel of 64, plus one
    # The CLI words the same rule for its --grid.
    png = str(tmp_path / "p.png")
    conus.write_image(png, pixels)
    done = subprocess.run([conus_bin, "encode", png, "-o", str(tmp_path / "e.exr"), "--focus", "0.3,0.4,0.1,3",
                           "--grid", "257", "--size", "16x11"], capture_output=True, text=True)
    assert done.returncode != 0
    assert "--grid 257 is finer than a 16x11 image can show; at most 129 nodes a side" in done.stderr, done.stderr


def test_linear_to_srgb_is_documented():
    from conftest import SOURCE_DIR
    assert "conus.linear_to_srgb" in (SOURCE_DIR / "docs" / "python.md").read_text()
    assert "linear_to_srgb" in conus.__doc__
