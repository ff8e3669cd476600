"""CoNUS: coherent non-uniform sampling images, over numpy.

    import conus
    pixels, channels = conus.read_image("photo.jpg")          # linear float32, (H, W, C)
    f = conus.encode(pixels, foci=[(0.42, 0.31, 0.08, 4)])     # a quarter of each side
    conus.write("photo.exr", f)
    g = conus.read("photo.exr")                                # .pixels .channels .map .attributes
    face = conus.decode(g, view=(0.36, 0.15, 0.52, 0.31), size=(512, 512))
    m = conus.Map.foci([(0.5, 0.5, 0.1, 4)]); m.undistort(m.distort(points))
    m = conus.Map.auto(conus.importance(pixels, "detail", channels=channels))  # as --importance detail

Pixels are linear light (sRGB pictures are linearized by read_image; see srgb_to_linear for
arrays from elsewhere). Errors raise conus.Error, whose .rule names the spec rule broken.
Work past one machine: conus.dask.encode_files.
"""
import numpy as _np

from ._conus import (DEFAULT_MAP_SIDE, MAX_IMAGE_SIDE, MAX_MAP_SIDE, Error, File, Map, decode, encode, importance,
                     psnr, read, read_image, read_mesh, read_volume, resize, uniform, write, write_image)

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
