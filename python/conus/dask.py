"""Batch conversion past one machine: CoNUS as a task in Dask.

    import conus.dask
    from dask.distributed import Client
    client = Client("tcp://scheduler:8786")     # a real cluster; without one, Dask's local threads
    summary = conus.dask.encode_files("photos/*.jpg", "exr/", foci=[(0.5, 0.5, 0.1, 4)])
    print(summary.table())

Inputs are a list of paths, a glob, or an fsspec URL with a glob (s3://bucket/prefix/*.jpg when
s3fs is installed; memory://, file://). Each picture is one task: read it, encode it, write
OUT_DIR/<name> (local folders through a temporary file and a rename; object stores in one put),
so a task that is retried, or a batch that is run again, rewrites or (skip_existing, the default)
leaves the same output: retries are idempotent. Failures never stop the batch; they come back as
rows of the summary with their reason. A warning is kept in its input's row ("warnings") and said
once by encode_files, naming the inputs it held for. The compiled calls release the GIL, so
threads use every core.
"""
import os
import tempfile
import time
import warnings

import dask.bag
import fsspec
from fsspec.implementations.local import LocalFileSystem

from . import _conus, _keeping_warnings


def _outputs(out_dir, name, path, index):
    stem, ext = os.path.splitext(os.path.basename(path))
    return out_dir.rstrip("/") + "/" + name.format(stem=stem, name=os.path.basename(path), ext=ext.lstrip("."), index=index)


def _convert(item, out_dir, name, skip_existing, options):
    index, path = item
    output = _outputs(out_dir, name, path, index)
    row = {"input": path, "output": output, "status": "converted", "seconds": 0.0, "error": "", "warnings": []}
    start = time.perf_counter()
    try:
        out_fs, out_path = fsspec.core.url_to_fs(output)
        if skip_existing and out_fs.exists(out_path):
            row["status"] = "skipped"
            return row
        in_fs, in_path = fsspec.core.url_to_fs(path)
        if (isinstance(in_fs, LocalFileSystem) and isinstance(out_fs, LocalFileSystem) and os.path.exists(out_path)
                and os.path.samefile(in_path, out_path)):
            row["status"] = "failed"
            row["error"] = f"refusing to write {output}: it is the input {path} (the same file); name another output"
            return row
        with tempfile.TemporaryDirectory(prefix="conus-dask-") as work:
            local_in = in_path if isinstance(in_fs, LocalFileSystem) else os.path.join(work, os.path.basename(in_path))
            if local_in != in_path:
                in_fs.get(in_path, local_in)
            with _keeping_warnings(row["warnings"]):
                pixels, channels = _conus.read_image(local_in)
                encoded = _conus.encode(pixels, channels=channels, **options)
            if isinstance(out_fs, LocalFileSystem):
                out_fs.makedirs(os.path.dirname(out_path) or ".", exist_ok=True)
                _conus.write(out_path, encoded)  # a temporary file and a rename: atomic
            else:
                local_out = os.path.join(work, "out.exr")
                _conus.write(local_out, encoded)
                out_fs.put(local_out, out_path)  # one put: an object appears whole or not at all
    except (_conus.Error, OSError) as e:
        row["status"] = "failed"
        row["error"] = str(e)
    row["seconds"] = time.perf_counter() - start
    return row


def _expand(inputs):
    if isinstance(inputs, str):
        fs, pattern = fsspec.core.url_to_fs(inputs)
        found = sorted(fs.glob(pattern))
        if isinstance(fs, LocalFileSystem):
            return found
        protocol = fs.protocol[0] if isinstance(fs.protocol, (tuple, list)) else fs.protocol
        return [f"{protocol}://{p}" for p in found]
    return list(inputs)


def encode_bag(inputs, out_dir, name="{stem}.exr", skip_existing=True, partitions=None, **options):
    """A dask.bag of summary rows, one per input, not yet computed. `options` go to conus.encode
    (foci, size, map, backend); `name` may use {stem}, {name}, {ext} and {index}."""
    paths = _expand(inputs)
    items = list(enumerate(paths, start=1))
    bag = dask.bag.from_sequence(items, npartitions=partitions or max(1, min(len(items), 64)))
    return bag.map(_convert, out_dir, name, skip_existing, options)


class Summary(list):
    """The rows of a batch (dicts: input, output, status, seconds, error, warnings) with their counts."""

    def count(self, status):
        return sum(1 for row in self if row["status"] == status)

    def table(self):
        width = max([len("input")] + [len(r["input"]) for r in self])
        lines = [f"{'input':<{width}}  {'status':<9}  {'seconds':>7}  output / reason"]
        for r in self:
            lines.append(f"{r['input']:<{width}}  {r['status']:<9}  {r['seconds']:7.2f}  {r['error'] or r['output']}")
        lines.append(f"{self.count('converted')} converted, {self.count('skipped')} skipped, {self.count('failed')} failed")
        return "\n".join(lines)


def encode_files(inputs, out_dir, name="{stem}.exr", skip_existing=True, scheduler=None, **options):
    """Encodes every input on the active Dask scheduler (a distributed Client if one is set up,
    else `scheduler`, else local threads) and returns the Summary."""
    rows = encode_bag(inputs, out_dir, name=name, skip_existing=skip_existing, **options).compute(scheduler=scheduler)
    summary = Summary(sorted(rows, key=lambda r: r["input"]))
    # Each warning once, at the caller's line, with the inputs it held for (as `conus encode`'s batch).
    held = {}
    for row in summary:
        for text in row.get("warnings", ()):
            held.setdefault(text, []).append(row["input"])
    for text, paths in held.items():
        shown = ", ".join(paths[:3]) + (f" and {len(paths) - 3} more" if len(paths) > 3 else "")
        where = paths[0] if len(paths) == 1 else f"{len(paths)} of {len(summary)} inputs ({shown})"
        warnings.warn(f"conus.dask.encode_files: {where}: {text}", UserWarning, stacklevel=2)
    return summary
