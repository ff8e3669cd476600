"""Every `sh` and `python` block of docs/*.md runs, in order, page by page, as a user would paste
it from an empty folder with only the installed package: the build installed (`cmake --install`)
to a fresh $HOME/conus, the environment docs/README.md's `export` line gives (its PATH and
PYTHONPATH, nothing of the build tree or the sources), each page in an empty folder of its own;
each `python` block saved as a script and run with `python3 block.py` (the interpreter running
the tests), each `sh` block in a fresh shell. Then what the page says is checked against what its
blocks made: the view it names as the focus holds the demo's fine print and decodes sharper than
the same view of the uniform image, a size it says keeps the aspect does; and whatever the page
wrote is ignored by git when it is run from the repository root (.gitignore)."""
import re
import subprocess

import numpy as np
import pytest

from conftest import BLOCK, SOURCE_DIR

DOCS = sorted((SOURCE_DIR / "docs").glob("*.md"))


def blocks(page):
    return [(lang, code) for lang, code in BLOCK.findall(page.read_text()) if lang in ("sh", "python")]


def test_every_page_has_runnable_blocks():
    pages = [p.name for p in DOCS if p.name != "README.md"]
    assert len(pages) >= 6
    for name in pages:
        assert blocks(SOURCE_DIR / "docs" / name), f"{name} has no sh or python block"


def numbers(text):
    return [float(x) for x in text.split(",")]


def command_option(page_text, command, option):
    """The value of `option` on the page's first command line that starts with `command`."""
    for line in page_text.splitlines():
        if line.startswith(command):
            found = re.search(option + r"[ =](\S+)", line)
            if found:
                return found.group(1)
    raise AssertionError(f"no `{command} ... {option}` on the page")


def linear(path):
    import conus
    pixels, _ = conus.read_image(str(path))
    return pixels


def crop(pixels, view):
    """The source's pixels inside view (u0, v0, u1, v1)."""
    h, w = pixels.shape[:2]
    u0, v0, u1, v1 = view
    return pixels[round(v0 * h):round(v1 * h), round(u0 * w):round(u1 * w)]


def assert_fine_print(source, view):
    """The demo's fine print: most of the view is the panel's paper, some of it ink."""
    part = crop(source, view)[..., :3]
    paper = np.all(part > 0.7, axis=-1).mean()
    ink = np.all(part < 0.15, axis=-1).mean()
    assert paper > 0.5 and ink > 0.02, f"view {view} is not the fine print: {paper:.2f} paper, {ink:.3f} ink"


def assert_sharper(frame_path, uniform_path, source, view):
    """The decoded view is closer to the source's pixels there than the uniform image's, by 2 dB."""
    import conus
    frame, baseline = linear(frame_path), linear(uniform_path)
    h, w = frame.shape[:2]
    reference = conus.resize(np.ascontiguousarray(crop(source, view)), (w, h))
    gain = conus.psnr(frame[..., :3], reference[..., :3]) - conus.psnr(baseline[..., :3], reference[..., :3])
    assert gain > 2.0, f"{frame_path.name} is only {gain:.2f} dB closer to the source than {uniform_path.name}"


def assert_size_keeps_aspect(picture, source_width, source_height, side):
    import conus
    pixels = linear(picture)
    assert pixels.shape[1] == side, picture
    assert abs(pixels.shape[0] - side * source_height / source_width) <= 1, (picture, pixels.shape, source_width, source_height)


def check_convert_photos(text, folder):
    u, v, r, k = numbers(command_option(text, "conus encode demo/source.png -o photo.exr", "--focus"))
    view = numbers(command_option(text, "conus decode photo.exr -o print.png", "--view"))
    assert view[0] < u < view[2] and view[1] < v < view[3], "the print view holds the focus"
    source = linear(folder / "demo" / "source.png")
    assert_fine_print(source, view)
    assert_sharper(folder / "print.png", folder / "print-uniform.png", source, view)
    side = int(command_option(text, "conus decode exr/", "--size"))
    for stem in ("source", "view-frame"):
        frame = linear(folder / "demo" / f"{stem}.png")
        assert_size_keeps_aspect(folder / "views" / f"{stem}-small.jpg", frame.shape[1], frame.shape[0], side)


def check_view_and_zoom(text, folder):
    import conus
    view = numbers(command_option(text, "conus decode demo/conus.exr -o zoom.png", "--view"))
    foci = conus.read(str(folder / "demo" / "conus.exr")).attributes["analytic"]["foci"]
    assert any(view[0] < u < view[2] and view[1] < v < view[3] for u, v, _, _ in foci), f"no focus of {foci} in {view}"
    source = linear(folder / "demo" / "source.png")
    assert_fine_print(source, view)
    assert_sharper(folder / "zoom.png", folder / "zoom-uniform.png", source, view)


def check_python(text, folder):
    import conus
    view = [float(x) for x in re.search(r"view=\(([^)]*)\)", text).group(1).split(",")]
    source = linear(folder / "demo" / "source.png")
    assert_fine_print(source, view)
    # The page's zoom against the same view of the identity map's file of the same pixel count.
    uniform = conus.encode(source, map=conus.Map.identity(2, 2))
    zoom = linear(folder / "zoom.png")
    conus.write_image(str(folder / "zoom-uniform.png"), conus.decode(uniform, view=tuple(view), size=zoom.shape[1::-1]))
    assert_sharper(folder / "zoom.png", folder / "zoom-uniform.png", source, view)
    # The array saved through linear_to_srgb with PIL looks like the source (not dark, not white).
    from PIL import Image
    saved = np.asarray(Image.open(folder / "frame.png")).astype(float).mean()
    shown = np.asarray(Image.open(folder / "demo" / "source.png")).astype(float).mean()
    assert abs(saved - shown) < 3, (saved, shown)


def check_cluster(text, folder):
    import conus
    for name in ("a", "b"):
        assert conus.read(str(folder / "exr" / f"{name}.exr")).source_size[0] > 0


def check_web(text, folder):
    """The page's folder holds the viewer and the file; the served frame is a CoNUS file around the focus asked."""
    import conus
    assert (folder / "site" / "index.html").is_file() and (folder / "site" / "conus.exr").is_file()
    asked = numbers(re.search(r"focus=([0-9.,]+)&", text).group(1))
    frame = conus.read(str(folder / "frame.exr"))
    (u, v, r, _), = frame.attributes["analytic"]["foci"]
    assert abs(u - asked[0]) < 1e-6 and abs(v - asked[1]) < 1e-6 and abs(r - asked[2]) < 1e-6, (u, v, r, asked)


CHECKS = {"convert-photos.md": check_convert_photos, "web.md": check_web, "view-and-zoom.md": check_view_and_zoom, "python.md": check_python,
          "cluster.md": check_cluster}


def not_ignored(names):
    """Those of `names` (entries at the repository root) that git does not ignore; none when the
    sources are not a git work tree."""
    git = subprocess.run(["git", "-C", str(SOURCE_DIR), "rev-parse", "--is-inside-work-tree"], capture_output=True, text=True)
    if git.returncode != 0:
        return []
    # A folder's own files are what git would list: ask about one inside it.
    paths = [f"{name}/file" if is_dir else name for name, is_dir in names]
    done = subprocess.run(["git", "-C", str(SOURCE_DIR), "check-ignore", "--no-index", "--stdin"], input="\n".join(paths),
                          capture_output=True, text=True)
    ignored = set(done.stdout.split())
    return [p for p in paths if p not in ignored]


@pytest.mark.parametrize("page", [p for p in DOCS if p.name != "README.md"], ids=lambda p: p.name)
def test_page_runs_from_an_empty_folder_with_the_installed_package(page, tmp_path, installed):
    work = tmp_path / "work"
    work.mkdir()
    scripts = set()
    for i, (lang, code) in enumerate(blocks(page)):
        if lang == "sh":
            command = ["bash", "-euo", "pipefail", "-c", code]
        else:
            script = work / f"{page.stem}_block{i + 1}.py"
            script.write_text(code)
            scripts.add(script.name)
            command = ["python3", script.name]
        done = subprocess.run(command, cwd=work, env=installed, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, f"{page.name} block {i + 1} ({lang}) failed:\n{code}\n--- stdout\n{done.stdout}\n--- stderr\n{done.stderr}"
    if page.name in CHECKS:
        CHECKS[page.name](page.read_text(), work)
    written = [(p.name, p.is_dir()) for p in work.iterdir() if p.name not in scripts]
    assert written, f"{page.name} wrote nothing"
    assert not not_ignored(written), f"run from the repository root, {page.name} leaves these for git to see: {not_ignored(written)}"
