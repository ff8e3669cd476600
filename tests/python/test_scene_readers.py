"""conus.read_mesh and conus.read_volume: the policy for files a scene file names (its own folder
only, allow_dirs for more, regular files only), lying lengths and bombs; and the Python argument
checks that run before any allocation (sizes, dtypes, non-finite points)."""
import gzip
import json
import os
import struct
import time

import numpy as np
import pytest

import conus
from conftest import SHARED_DATA

SCENE = SHARED_DATA / "hostile" / "scene"
TRIANGLE = struct.pack("<9f", 0, 0, 0, 2, 0, 0, 0, 3, 0)


def gltf(uri):
    return json.dumps({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "scene": 0, "nodes": [{"mesh": 0}],
                       "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
                       "buffers": [{"uri": uri, "byteLength": 36}],
                       "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
                       "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                                      "min": [0, 0, 0], "max": [2, 3, 0]}]})


@pytest.fixture
def folders(tmp_path):
    model, outside = tmp_path / "model", tmp_path / "outside"
    model.mkdir()
    outside.mkdir()
    (model / "tri.bin").write_bytes(TRIANGLE)
    (outside / "tri.bin").write_bytes(TRIANGLE)
    os.symlink(outside / "tri.bin", model / "link.bin")
    os.mkfifo(model / "fifo.bin")
    return model, outside


# Names a scene file may not give a file it reads: with the reason in the refusal.
NAMES_OUT_OF_FOLDER = [
    ("/etc/passwd", "an absolute path"),
    ("/dev/zero", "an absolute path"),
    ("../../../../../../../etc/passwd", "outside its folder"),
    ("link.bin", "outside its folder"),
    ("fifo.bin", "not a regular file"),
]


def refusal(call):
    with pytest.raises(conus.Error) as e:
        call()
    assert "\n" not in str(e.value)
    return e.value


def test_a_mesh_reads_with_its_buffer_beside_it(folders):
    model, _ = folders
    (model / "tri.gltf").write_text(gltf("tri.bin"))
    mesh = conus.read_mesh(str(model / "tri.gltf"))
    assert mesh["indices"].shape == (1, 3) and mesh["indices"].dtype == np.uint32
    corners = mesh["positions"][mesh["indices"][0]]
    np.testing.assert_array_equal(corners, [[0, 0, 0], [2, 0, 0], [0, 3, 0]])
    np.testing.assert_allclose(mesh["normals"][0], [0, 0, 1], atol=1e-6)


@pytest.mark.parametrize("uri, reason", NAMES_OUT_OF_FOLDER + [("../outside/tri.bin", "outside its folder")])
def test_a_mesh_naming_a_file_out_of_its_folder_is_refused(folders, uri, reason):
    model, _ = folders
    (model / "escape.gltf").write_text(gltf(uri))
    e = refusal(lambda: conus.read_mesh(str(model / "escape.gltf")))
    assert e.code == "io" and reason in str(e) and "escape.gltf" in str(e)


def test_allow_dirs_lets_a_mesh_name_another_folder(folders):
    model, outside = folders
    (model / "far.gltf").write_text(gltf("../outside/tri.bin"))
    refusal(lambda: conus.read_mesh(str(model / "far.gltf")))
    mesh = conus.read_mesh(str(model / "far.gltf"), allow_dirs=[str(outside)])
    assert mesh["indices"].shape == (1, 3)


def test_lying_glb_lengths_and_duplicates(tmp_path):
    if (SCENE / "glb_jsonlen.glb").exists():
        e = refusal(lambda: conus.read_mesh(str(SCENE / "glb_jsonlen.glb")))
        assert e.code == "corrupt" and "its GLB header declares 4294967295 bytes in a file of 400" in str(e)
    obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 4 4 4\n" + "f 1 2 3\nf 3 2 1\n" * 500 + "f 2 4 3\n"
    (tmp_path / "copies.obj").write_text(obj)
    mesh = conus.read_mesh(str(tmp_path / "copies.obj"))
    assert mesh["indices"].shape == (2, 3)


@pytest.mark.parametrize("name, reason", NAMES_OUT_OF_FOLDER + [("../outside/cube.raw", "outside its folder")])
def test_an_nrrd_data_file_out_of_its_folder_is_refused(folders, name, reason):
    model, outside = folders
    (outside / "cube.raw").write_bytes(bytes(range(64)))
    header = f"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\ndata file: {name}\n"
    (model / "v.nhdr").write_text(header)
    e = refusal(lambda: conus.read_volume(str(model / "v.nhdr")))
    assert e.code == "io" and reason in str(e)


def test_an_nrrd_reads_its_data_and_allow_dirs_widens_the_folder(folders):
    model, outside = folders
    (outside / "cube.raw").write_bytes(bytes(range(0, 128, 2)))
    (model / "v.nhdr").write_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n"
                                  "spacings: 0.5 1 2\ndata file: ../outside/cube.raw\n")
    values, spacing = conus.read_volume(str(model / "v.nhdr"), allow_dirs=[str(outside)])
    assert values.shape == (4, 4, 4) and spacing == (0.5, 1.0, 2.0)
    assert values[0, 0, 1] == 2 and values[3, 3, 3] == 126  # x fastest: (z, y, x) indexing


def test_a_gzip_nrrd_claiming_more_than_deflate_gives_is_refused(tmp_path):
    payload = gzip.compress(bytes(4096))
    (tmp_path / "bomb.nrrd").write_bytes(b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 512 512 512\n"
                                         b"encoding: gzip\n\n" + payload)
    start = time.monotonic()
    e = refusal(lambda: conus.read_volume(str(tmp_path / "bomb.nrrd")))
    assert e.code == "corrupt" and "need at least" in str(e)
    assert time.monotonic() - start < 5


def test_sizes_are_refused_before_allocating(asymmetric):
    e = refusal(lambda: conus.Map.identity(20000, 20000))
    assert e.code == "limit-exceeded"
    e = refusal(lambda: conus.encode(asymmetric, size=(32768, 32768)))
    assert e.code == "limit-exceeded" and "encode memory limit" in str(e)


def test_only_real_finite_numbers_are_taken(asymmetric):
    # Pixels of another dtype are the wrong type of argument: one line that names it (docs/python.md).
    with pytest.raises(TypeError, match=r"^pixels must be an array of numbers, not .*dtype complex64$"):
        conus.encode(asymmetric.astype(np.complex64))
    objects = np.empty((8, 8), dtype=object)
    objects[:] = 0.5
    with pytest.raises(TypeError, match=r"dtype object$"):
        conus.encode(objects)
    m = conus.Map.identity(3, 3)
    e = refusal(lambda: m.distort(np.array([[np.nan, np.inf]])))
    assert e.code == "invalid-argument" and "finite" in str(e)
    refusal(lambda: m.undistort(np.array([[0.5 + 1j, 0.5]])))
    np.testing.assert_allclose(m.distort(np.array([[0.25, 0.75]])), [[0.25, 0.75]])


def test_an_npz_bomb_is_refused_by_the_binary(tmp_path, conus_bin):
    import subprocess
    bomb = SCENE / "npz_bomb_1GiB.npz"
    if not bomb.exists():
        pytest.skip("shared data not found")
    r = subprocess.run([conus_bin, "heightfield", "encode", str(bomb), "-o", str(tmp_path / "t.exr")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "height samples" in r.stderr and not (tmp_path / "t.exr").exists()
