"""Every `sh` and `python` block of docs/*.md runs, in order, page by page, as a user would paste
it: in a scratch folder that sees the repository's build/, tests/ and examples/, with the built
tools on PATH (then the interpreter running the tests, as `python3`), the package on PYTHONPATH
and HOME in the scratch folder (cpp.md installs there)."""
import os
import pathlib
import re
import subprocess
import sys

import pytest

from conftest import BIN_DIR, SOURCE_DIR

DOCS = sorted((SOURCE_DIR / "docs").glob("*.md"))
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.S | re.M)


def blocks(page):
    return [(lang, code) for lang, code in BLOCK.findall(page.read_text()) if lang in ("sh", "python")]


def test_every_page_has_runnable_blocks():
    pages = [p.name for p in DOCS if p.name != "README.md"]
    assert len(pages) >= 6
    for name in pages:
        assert blocks(SOURCE_DIR / "docs" / name), f"{name} has no sh or python block"


@pytest.mark.parametrize("page", [p for p in DOCS if p.name != "README.md"], ids=lambda p: p.name)
def test_page_runs(page, tmp_path):
    build = BIN_DIR.parent
    for name, target in (("build", build), ("tests", SOURCE_DIR / "tests"), ("examples", SOURCE_DIR / "examples")):
        (tmp_path / name).symlink_to(target)
    env = dict(os.environ, HOME=str(tmp_path), PATH=f"{BIN_DIR}:{pathlib.Path(sys.executable).parent}:{os.environ['PATH']}", MPLBACKEND="Agg",
               PYTHONPATH=str(build / "python"))
    for i, (lang, code) in enumerate(blocks(page)):
        command = ["bash", "-euo", "pipefail", "-c", code] if lang == "sh" else [sys.executable, "-c", code]
        done = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, f"{page.name} block {i + 1} ({lang}) failed:\n{code}\n--- stdout\n{done.stdout}\n--- stderr\n{done.stderr}"
