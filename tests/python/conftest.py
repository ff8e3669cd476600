"""Paths the Python tests share: the conus binary (CONUS_BIN_DIR) and the shared data."""
import os
import pathlib

import pytest

BIN_DIR = pathlib.Path(os.environ.get("CONUS_BIN_DIR", pathlib.Path(__file__).resolve().parents[2] / "build" / "bin"))
SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
SHARED_DATA = SOURCE_DIR.parent / "shared" / "data"


@pytest.fixture
def conus_bin():
    return str(BIN_DIR / "conus")


@pytest.fixture
def asymmetric():
    """A 240x160 linear RGBA picture: a horizontal ramp, a red patch in the top-left corner, a
    blue disc lower right, alpha 0.5 on the right third."""
    import numpy as np
    h, w = 160, 240
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    img = np.zeros((h, w, 4), np.float32)
    img[..., 0] = 0.1
    img[..., 1] = x / (w - 1)
    img[..., 2] = 0.2 + 0.1 * np.sin(y / 7.0)
    img[..., 3] = 1.0
    img[:24, :36, :3] = (1.0, 0.0, 0.0)
    disc = (x - 180) ** 2 + (y - 115) ** 2 < 20 ** 2
    img[disc, :3] = (0.0, 0.0, 1.0)
    img[:, 160:, 3] = 0.5
    img[:, 160:, :3] *= 0.5  # associated alpha, as CoNUS holds it
    return img
