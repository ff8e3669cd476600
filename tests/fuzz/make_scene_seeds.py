#!/usr/bin/python3
"""Writes the seed corpus of the scene-reader harnesses (tests/fuzz/corpus/{mesh,volume,dem}/):
small valid files of each form, files naming others (inside the folder, outside it, absolute, a
FIFO, a symbolic link out: the traps of tests/fuzz/scene_fixture.h), lying lengths and small
compression bombs. The seeds are committed; run this again when a reader learns a new form.
Usage: tests/fuzz/make_scene_seeds.py"""
import base64
import gzip
import io
import json
import os
import struct
import zipfile

import numpy as np

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")


def put(kind, name, data):
    os.makedirs(os.path.join(HERE, kind), exist_ok=True)
    with open(os.path.join(HERE, kind, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


# ---- meshes ----
CUBE = "".join(f"v {x} {y} {z}\n" for x in (0, 1) for y in (0, 1) for z in (0, 1))
CUBE += "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n"
put("mesh", "cube.obj", CUBE)
put("mesh", "cube-duplicates.obj", CUBE + "f 1 2 4\nf 4 2 1\nf 1 2 4\n")
for target in ("m.mtl", "../outside.bin", "/etc/passwd", "fifo.bin", "link.bin", "/dev/zero"):
    safe = target.replace("/", "_").replace(".", "_")
    put("mesh", f"mtllib{safe}.obj", f"mtllib {target}\nusemtl a\n" + CUBE)
put("mesh", "tri.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
put("mesh", "tri.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
    "endloop\nendfacet\nendsolid t\n")
put("mesh", "tri.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)


def gltf(uri, length=36):
    return json.dumps({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "scene": 0, "nodes": [{"mesh": 0}],
                       "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
                       "buffers": [{"uri": uri, "byteLength": length}],
                       "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": length}],
                       "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                                      "min": [0, 0, 0], "max": [1, 1, 0]}]})


put("mesh", "tri-embedded.gltf", gltf("data:application/octet-stream;base64," + base64.b64encode(positions).decode()))
for target in ("data.bin", "../outside.bin", "/etc/passwd", "fifo.bin", "link.bin", "/dev/zero"):
    safe = target.replace("/", "_").replace(".", "_")
    put("mesh", f"buffer{safe}.gltf", gltf(target))
put("mesh", "tri-lying-length.gltf", gltf("data.bin", 1 << 30))
j = gltf("").replace('"uri": "", ', "").encode()
j += b" " * (-len(j) % 4)
glb = b"glTF" + struct.pack("<II", 2, 12 + 8 + len(j) + 8 + len(positions)) + struct.pack("<I", len(j)) + b"JSON" + j
glb += struct.pack("<I", len(positions)) + b"BIN\0" + positions
put("mesh", "tri.glb", glb)
put("mesh", "lying-chunk.glb", glb[:12] + struct.pack("<I", 0xfffffff0) + glb[16:])
put("mesh", "lying-total.glb", glb[:8] + struct.pack("<I", 1 << 31) + glb[12:])

# ---- volumes ----
head = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: {}\n"
put("volume", "cube.nrrd", (head.format("raw") + "\n").encode() + bytes(range(64)))
put("volume", "cube-gz.nrrd", (head.format("gzip") + "\n").encode() + gzip.compress(bytes(range(64))))
put("volume", "cube-ascii.nrrd", head.format("ascii") + "\n" + " ".join(str(i) for i in range(64)) + "\n")
put("volume", "bomb-gz.nrrd", (head.replace("4 4 4", "1024 1024 64").format("gzip") + "\n").encode()
    + gzip.compress(bytes(1 << 16)))
put("volume", "double-gz.nrrd", (head.replace("uchar", "double").format("gzip") + "\n").encode()
    + gzip.compress(bytes(64 * 8)))
put("volume", "zero-direction.nrrd", (head.format("raw") + "space dimension: 3\nspace directions: (0,0,0) (0,1,0) (0,0,1)\n\n").encode() + bytes(64))
put("volume", "huge-spacing.nrrd", (head.format("raw") + "spacings: 1e308 1e308 1\n\n").encode() + bytes(64))
for target in ("data.bin", "../outside.bin", "/etc/passwd", "fifo.bin", "link.bin", "/dev/zero"):
    safe = target.replace("/", "_").replace(".", "_")
    put("volume", f"detached{safe}.nhdr", head.replace("4 4 4", "16 16 16").format("raw") + f"data file: {target}\n")
put("volume", "detached-list.nhdr", head.replace("4 4 4", "16 16 8").format("raw") + "data file: LIST\ndata.bin\n")
put("volume", "detached-pattern.nhdr", head.format("raw") + "data file: slice%03d.raw 1 4 1\n")
den = struct.pack("<h", 1) + struct.pack("<27h", *([0] * 24 + [4, 4, 4])) + struct.pack("<h", 0) + struct.pack("<i", 64)
put("volume", "cube.den", den + bytes(range(64)))
put("volume", "lying.den", den[:58] + struct.pack("<i", 1 << 30) + bytes(range(64)))
put("volume", "raw-uint8", b"4x4x4:uint8\n" + bytes(range(64)))
put("volume", "raw-float-nan", b"2x2x2:float32:0.5\n" + struct.pack("<8f", 0, 1, 2, 3, 4, 5, 6, float("nan")))
put("volume", "raw-short", b"8x8x8:uint16-be:1,2,3\n" + bytes(100))

# ---- elevation models ----


def npy(array):
    out = io.BytesIO()
    np.save(out, array)
    return out.getvalue()


def npz(compress=True, **arrays):
    out = io.BytesIO()
    (np.savez_compressed if compress else np.savez)(out, **arrays)
    return out.getvalue()


ramp = (np.arange(12 * 9, dtype=np.float64).reshape(9, 12) * 3.5)
put("dem", "ramp-f8.npy", npy(ramp))
put("dem", "ramp-i2.npy", npy(ramp.astype(">i2")))
put("dem", "ramp-nan.npy", npy(np.where(ramp > 100, np.nan, ramp)))
put("dem", "jacksboro-like.npz", npz(elevation=ramp.astype(np.int16), dx=np.float64(0.0002), dy=np.float64(0.0002),
                                     ymin=np.float64(36.0), ymax=np.float64(36.1)))
put("dem", "stored.npz", npz(False, elevation=ramp))
put("dem", "absurd-spacing.npz", npz(elevation=ramp, dx=np.float64(1e300), dy=np.float64(1e300)))
put("dem", "bomb-16MiB.npz", npz(elevation=np.zeros((2048, 1024), dtype=np.float64)))
put("dem", "lying-shape.npy", npy(ramp)[:128].replace(b"(9, 12)", b"(65536, 65536)"[:7]) + bytes(64))
