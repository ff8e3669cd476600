"""Batch conversion through Dask (a LocalCluster of two worker processes, and an object store),
and the example figure script, as a user runs them."""
import os
import subprocess
import sys

import distributed
import fsspec
import numpy as np
import pytest

import conus
import conus.dask

from conftest import SOURCE_DIR


@pytest.fixture
def pictures(tmp_path, asymmetric):
    folder = tmp_path / "photos"
    folder.mkdir()
    for i in range(4):
        conus.write_image(str(folder / f"p{i}.png"), np.roll(asymmetric[..., :3], 20 * i, axis=1))
    (folder / "broken.png").write_bytes(b"\x89PNG\r\n\x1a\n truncated")
    return folder


def test_a_local_cluster_of_two_workers_converts_a_directory(tmp_path, pictures):
    out = tmp_path / "exr"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        summary = conus.dask.encode_files(str(pictures / "*.png"), str(out), foci=[(0.5, 0.5, 0.1, 3)], size=(60, 40))
        workers = {w["id"] for w in client.scheduler_info()["workers"].values()}
    assert len(workers) == 2
    assert (summary.count("converted"), summary.count("failed")) == (4, 1)
    failed = [r for r in summary if r["status"] == "failed"][0]
    assert failed["input"].endswith("broken.png") and failed["error"]
    for r in summary:
        if r["status"] == "converted":
            f = conus.read(r["output"])
            assert f.pixels.shape == (40, 60, 3) and f.source_size == (240, 160)
    assert "4 converted, 0 skipped, 1 failed" in summary.table()
    assert sorted(os.listdir(out)) == ["p0.exr", "p1.exr", "p2.exr", "p3.exr"]  # no temporary left
    # Run again: idempotent, everything already there is skipped.
    again = conus.dask.encode_files(str(pictures / "*.png"), str(out), scheduler="threads")
    assert (again.count("skipped"), again.count("failed")) == (4, 1)


def test_an_output_that_is_its_input_is_refused_and_the_input_kept(pictures, asymmetric):
    source = pictures / "e.exr"  # a picture the encoder would replace by its CoNUS file
    conus.write_image(str(source), asymmetric[..., :3])
    before = source.read_bytes()
    for path in (source, pictures / "link.exr"):
        if path != source:
            path.symlink_to(source)
        summary = conus.dask.encode_files([str(path)], str(pictures), name="{name}", skip_existing=False, scheduler="sync")
        row = list(summary)[0]
        assert row["status"] == "failed", row
        assert row["error"].startswith(f"refusing to write {pictures}/{path.name}: it is the input"), row["error"]
        assert source.read_bytes() == before
    assert sorted(os.listdir(pictures)) == ["broken.png", "e.exr", "link.exr", "p0.png", "p1.png", "p2.png", "p3.png"]


def test_an_object_store_prefix_in_and_out(pictures):
    store = fsspec.filesystem("memory")
    for name in ("p0.png", "p1.png"):
        store.pipe(f"/in/{name}", (pictures / name).read_bytes())
    summary = conus.dask.encode_files("memory://in/*.png", "memory://out", name="{stem}-{index}.exr", scheduler="sync")
    assert summary.count("converted") == 2, summary.table()
    assert sorted(store.ls("/out", detail=False)) == ["/out/p0-1.exr", "/out/p1-2.exr"]
    data = store.cat("/out/p1-2.exr")
    assert data[:4] == b"\x76\x2f\x31\x01"  # an OpenEXR file


def test_example_figure_script_writes_its_figure(tmp_path):
    out = tmp_path / "figure.png"
    env = dict(os.environ, MPLBACKEND="Agg")
    done = subprocess.run([sys.executable, str(SOURCE_DIR / "examples" / "figure.py"), "-o", str(out)], env=env,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "CoNUS" in done.stdout
    pixels, channels = conus.read_image(str(out))
    assert pixels.shape[1] > 2 * pixels.shape[0]  # three panels side by side
    assert pixels[..., :3].std() > 0.05  # a picture, not a blank
