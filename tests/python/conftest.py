"""What the Python tests share: the conus binary (CONUS_BIN_DIR), the shared data, and the build
installed as docs/README.md tells a user to install it (`installed`)."""
import os
import pathlib
import re
import subprocess
import sys

import pytest

BIN_DIR = pathlib.Path(os.environ.get("CONUS_BIN_DIR", pathlib.Path(__file__).resolve().parents[2] / "build" / "bin"))
SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
SHARED_DATA = SOURCE_DIR.parent / "shared" / "data"
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.S | re.M)  # a fenced block of a Markdown page: (language, code)


def readme_setup():
    """docs/README.md's set-up block: its install line and its `export` line."""
    text = (SOURCE_DIR / "docs" / "README.md").read_text()
    block = next(code for lang, code in BLOCK.findall(text) if "export PATH=" in code)
    install = next(line for line in block.splitlines() if line.startswith("cmake --install"))
    export = next(line for line in block.splitlines() if line.startswith("export "))
    return install, export


@pytest.fixture(scope="session")
def installed(tmp_path_factory):
    """The environment of a user who followed docs/README.md: the build installed to a fresh
    $HOME/conus, and its `export` line run on a PATH that holds nothing of the build tree (the
    interpreter running the tests first, as `python3`) and no PYTHONPATH."""
    install, export = readme_setup()
    assert install == 'cmake --install build --prefix "$HOME/conus"', install
    home = tmp_path_factory.mktemp("home")
    subprocess.run(["cmake", "--install", str(BIN_DIR.parent), "--prefix", str(home / "conus")], check=True,
                   capture_output=True)
    build = str(BIN_DIR.parent)
    base = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON") and k != "CONUS_BIN_DIR"}
    base.update(HOME=str(home), MPLBACKEND="Agg", PYTHONDONTWRITEBYTECODE="1",
                PATH=os.pathsep.join([str(pathlib.Path(sys.executable).parent)] +
                                     [p for p in os.environ["PATH"].split(os.pathsep) if not p.startswith(build)]))
    done = subprocess.run(["bash", "-c", export + "\nenv -0"], env=base, capture_output=True, check=True)
    env = dict(item.split("=", 1) for item in done.stdout.decode().split("\0") if "=" in item)
    assert env["PATH"].startswith(str(home / "conus" / "bin")), env["PATH"]
    assert (pathlib.Path(env["PYTHONPATH"]) / "conus" / "__init__.py").is_file(), env["PYTHONPATH"]
    return env


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
