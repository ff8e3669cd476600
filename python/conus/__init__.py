"""CoNUS: coherent non-uniform sampling images, over numpy.

    import conus
    pixels, channels = conus.read_image("photo.jpg")          # linear float32, (H, W, C)
    f = conus.encode(pixels, foci=[(0.42, 0.31, 0.08, 4)])     # a quarter of each side
    conus.write("photo.exr", f)
    g = conus.read("photo.exr")                                # .pixels .channels .map .attributes
    face = conus.decode(g, view=(0.36, 0.15, 0.52, 0.31), size=(512, 512))
    m = conus.Map.foci([(0.5, 0.5, 0.1, 4)]); m.undistort(m.distort(points))
    m = conus.Map.auto(conus.importance(pixels, "faces", channels=channels))  # as --importance faces
    f = conus.encode(pixels)   # as `conus encode` with no focus: the samples follow the picture's detail
    u = conus.uniform(pixels)  # as `conus uniform`: the uniform image of the same pixel count, a File

Float pixels are linear light (read_image linearizes sRGB pictures); uint8 and uint16 arrays are
display-encoded codes, converted as an 8- or 16-bit PNG is (colorspace= overrides). To save a
decoded array with another library, encode it for display first: linear_to_srgb. Errors raise
conus.Error, whose .rule names the spec rule broken; arguments of the wrong type raise a one-line
TypeError. Warnings (UserWarning) name the call and point at the line that made it. Work past one
machine: conus.dask.encode_files.
"""
import contextlib as _contextlib
import functools as _functools
import os as _os
import sys as _sys
import threading as _threading
import warnings as _warnings

import numpy as _np

from . import _conus
from ._conus import DEFAULT_MAP_SIDE, MAX_IMAGE_SIDE, MAX_MAP_SIDE, Error, File, Map

_PACKAGE_DIR = _os.path.dirname(_os.path.abspath(__file__))
# Per thread: `call`, the public function running (its warnings name it); `kept`, a list that
# takes the warnings instead of the warnings module (conus.dask's tasks, see _keeping_warnings).
_calls = _threading.local()


def _warn(text):
    """Every warning of the compiled module comes here: a UserWarning at the line that called into
    the package (the first frame outside it), naming the call that gave it."""
    call = getattr(_calls, "call", None)
    if call and not text.startswith("conus."):
        text = f"conus.{call}: {text}"
    kept = getattr(_calls, "kept", None)
    if kept is not None:
        kept.append(text)
        return
    level, frame = 2, _sys._getframe(1)
    while frame is not None and _os.path.dirname(_os.path.abspath(frame.f_code.co_filename)) == _PACKAGE_DIR:
        level, frame = level + 1, frame.f_back
    _warnings.warn(text, UserWarning, stacklevel=level)


@_contextlib.contextmanager
def _keeping_warnings(kept):
    """Within the block, this thread's warnings go to the list `kept` (a task of conus.dask, which
    reports them with its input)."""
    before = getattr(_calls, "kept", None)
    _calls.kept = kept
    try:
        yield kept
    finally:
        _calls.kept = before


def _public(function, name):
    """`function` as the package offers it: its warnings name it (_warn), and its argument type
    errors (pybind11's many lines, the whole array among them) become one line: what was given and
    the signature expected."""
    @_functools.wraps(function)
    def call(*args, **kwargs):
        outer = getattr(_calls, "call", None)
        _calls.call = outer or name
        try:
            return function(*args, **kwargs)
        except TypeError as e:
            lines = str(e).splitlines()
            if not lines or "incompatible function arguments" not in lines[0]:
                raise
            expected = next((line.strip()[3:] for line in lines[1:] if line.strip().startswith("1. ")), "(...)")
            expected = expected.replace("conus._conus.", "conus.")
            given = ", ".join([type(a).__name__ for a in args] + [f"{k}={type(v).__name__}" for k, v in kwargs.items()])
            raise TypeError(f"conus.{name}({given}): expected {name.split('.')[-1]}{expected}") from None
        finally:
            _calls.call = outer
    return call


for _name in ("read", "write", "encode", "decode", "uniform", "resize", "psnr", "importance", "read_image", "write_image",
              "read_mesh", "read_volume"):
    globals()[_name] = _public(getattr(_conus, _name), _name)
for _name in ("identity", "foci", "springs", "auto", "auto_for_frame_loss", "from_nodes"):
    setattr(Map, _name, staticmethod(_public(getattr(Map, _name), "Map." + _name)))
for _name in ("distort", "undistort", "density", "measures"):
    setattr(Map, _name, _public(getattr(Map, _name), "Map." + _name))
del _name

__all__ = ["Error", "File", "Map", "read", "write", "encode", "decode", "uniform", "resize", "psnr", "importance",
           "read_image", "write_image", "read_mesh", "read_volume", "srgb_to_linear", "linear_to_srgb", "MAX_IMAGE_SIDE", "MAX_MAP_SIDE",
           "DEFAULT_MAP_SIDE"]
__version__ = "1.0.0"


def srgb_to_linear(values):
    """sRGB-encoded values in [0, 1] (or uint8 / uint16 codes) to linear light, float32."""
    a = _np.asarray(values)
    if a.dtype == _np.uint8:
        a = a.astype(_np.float32) / 255.0
    elif a.dtype == _np.uint16:
        a = a.astype(_np.float32) / 65535.0
    a = a.astype(_np.float32, copy=False)
    return _np.where(a <= 0.04045, a / 12.92, ((a + 0.055) / 1.055) ** 2.4).astype(_np.float32)


def linear_to_srgb(values):
    """Linear light to sRGB-encoded values in [0, 1], float32 (clipped)."""
    a = _np.clip(_np.asarray(values, dtype=_np.float32), 0.0, 1.0)
    return _np.where(a <= 0.0031308, a * 12.92, 1.055 * a ** (1.0 / 2.4) - 0.055).astype(_np.float32)
