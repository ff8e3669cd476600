"""The round-four hostile files through Python's readers (conus.read_image, conus.read_mesh,
conus.read_volume, conus.read): each call runs in a child interpreter, so that a crash fails the
test instead of ending pytest, and the child reports its peak memory. Each must raise conus.Error
with one line."""
import json
import struct
import subprocess
import sys
import textwrap

import pytest

from conftest import SHARED_DATA

ROUND4 = SHARED_DATA / "hostile" / "round4"


def child(code, tmp_path):
    """Runs `code` in a child interpreter (ended after 60 s); returns (exit status, stdout, stderr).
    The code prints its own peak memory (VmHWM of its own address space: the rusage of a forked
    child would include the pytest process it was forked from)."""
    r = subprocess.run(["timeout", "60", sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


def refused(tmp_path, call, reason, max_mb=400):
    """`call` (Python source using `conus`) raises conus.Error with `reason` in one line, within
    `max_mb` of peak memory."""
    rc, out, err = child(f"""
        import conus
        try:
            {call}
        except conus.Error as e:
            print("REFUSED", str(e).replace(chr(10), "<newline>"))
        else:
            print("READ")
        peak = [line for line in open("/proc/self/status") if line.startswith("VmHWM:")][0]
        print("PEAK", int(peak.split()[1]) // 1024)
        """, tmp_path)
    assert rc == 0, f"the child died ({rc}): {err[-2000:]}"
    assert out.startswith("REFUSED") and reason in out and "<newline>" not in out, out
    mb = int(out.split("PEAK")[1])
    assert mb < max_mb, f"{mb} MB"
    return out


def dds_volume(width, height, depth):
    header = bytearray(128)
    header[0:4] = b"DDS "
    struct.pack_into("<7I", header, 4, 124, 0x801007, height, width, width * 4, depth, 0)
    struct.pack_into("<8I", header, 76, 32, 0x41, 0, 32, 0xFF0000, 0xFF00, 0xFF, 0xFF000000)
    struct.pack_into("<2I", header, 108, 0x1008, 0x200000)
    return bytes(header) + bytes(range(256)) * (width * height * depth * 4 // 256 + 1)


def test_a_volume_texture_is_refused_by_read_image(tmp_path):
    for name, (w, h, d) in {"v.dds": (4, 4, 4), "v.png": (8, 8, 3)}.items():
        (tmp_path / name).write_bytes(dds_volume(w, h, d))
        refused(tmp_path, f"conus.read_image({str(tmp_path / name)!r})", f"a volume texture of {w}x{h}x{d} samples")
    shared = ROUND4 / "images" / "vol4.dds"
    if shared.exists():
        refused(tmp_path, f"conus.read_image({str(shared)!r})", "a volume texture of 4x4x4 samples")


def chain(depth):
    nodes = [{"children": [i + 1]} for i in range(depth - 1)] + [{"mesh": 0}]
    return json.dumps({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "scene": 0, "nodes": nodes,
                       "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
                       "buffers": [{"uri": "data:application/octet-stream;base64,"
                                           "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA", "byteLength": 36}],
                       "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
                       "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                                      "min": [0, 0, 0], "max": [1, 1, 0]}]})


def test_deep_and_instanced_meshes_are_refused_by_read_mesh(tmp_path):
    (tmp_path / "deep.gltf").write_text(chain(20000))
    refused(tmp_path, f"conus.read_mesh({str(tmp_path / 'deep.gltf')!r})", "nodes deep, the limit")
    dag = json.loads(chain(1))
    dag["nodes"] = [{"children": [i + 1, i + 1]} for i in range(22)] + [{"mesh": 0}]
    (tmp_path / "dag.gltf").write_text(json.dumps(dag))
    refused(tmp_path, f"conus.read_mesh({str(tmp_path / 'dag.gltf')!r})", "its node tree expands to more than")
    (tmp_path / "json.gltf").write_text(chain(1)[:-1] + ', "extras": ' + "[" * 300000 + "]" * 300000 + "}")
    refused(tmp_path, f"conus.read_mesh({str(tmp_path / 'json.gltf')!r})", "its JSON nests more than")
    for name in ["deep_nodes_20000.gltf", "instance_dag_4M.gltf"]:
        if (ROUND4 / "mesh" / name).exists():
            refused(tmp_path, f"conus.read_mesh({str(ROUND4 / 'mesh' / name)!r})", "its node tree")


def test_a_material_library_out_of_the_folder_is_never_read(tmp_path):
    model = tmp_path / "model"
    model.mkdir()
    (tmp_path / "secret.env").write_text("API_TOKEN=sk-live-42\n")
    (model / "m.obj").write_text("mtllib ../secret.env\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    out = refused(tmp_path, f"conus.read_mesh({str(model / 'm.obj')!r})", "outside its folder")
    assert "sk-live" not in out
    shared = ROUND4 / "mesh" / "model" / "mtllib_passwd.obj"
    if shared.exists():
        assert "root:" not in refused(tmp_path, f"conus.read_mesh({str(shared)!r})", "outside its folder")


@pytest.mark.parametrize("text", [
    "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\nDATA FILE: /etc/passwd\n",
    "NRRD0004\rtype: uchar\rdimension: 3\rsizes: 4 4 4\rencoding: raw\rData File: /etc/passwd\r",
    "NRRD0004\r\ntype: uchar\r\ndimension: 3\r\nsizes: 4 4 4\r\nencoding: raw\r\ndatafile: /etc/passwd\r\n",
])
def test_an_nrrd_data_file_in_any_case_or_line_end_is_vetted(tmp_path, text):
    (tmp_path / "v.nhdr").write_text(text, newline="")
    out = refused(tmp_path, f"conus.read_volume({str(tmp_path / 'v.nhdr')!r})", "an absolute path")
    assert "root:" not in out


def test_a_map_finer_than_its_image_is_refused_by_read(tmp_path):
    shared = ROUND4 / "conus" / "map4097_img16.exr"
    if not shared.exists():
        pytest.skip("shared data not found")
    refused(tmp_path, f"conus.read({str(shared)!r})", "4097x4097 nodes is finer than its 16x16 image", max_mb=150)
