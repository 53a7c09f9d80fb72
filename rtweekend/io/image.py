"""Writing images: the books' tone map for PNG, linear floats for analysis.

Every file is written to a temporary name in the target folder and renamed
over the target only when complete, so a failure or Ctrl-C never leaves a
truncated file behind.
"""
import io
import os
from collections.abc import Mapping
import tempfile
import threading
from pathlib import Path

import numpy as np

from ..errors import OutputError
from ..result import RenderResult
from .formats import FORMATS, HDR, LDR  # noqa: F401
from .tonemap import tonemap  # noqa: F401  (rtweekend.tonemap, and save_image's)



def check_output_path(path):
    """Raise OutputError unless `path` has a known extension and a writable folder."""
    path = Path(path)
    ext = path.suffix.lower()
    if path.is_dir():
        raise OutputError(f"{path}: cannot write: it is a folder; name a file in it, such "
                         f"as {path / 'image.png'}")
    if ext not in FORMATS:
        raise OutputError(f"{path}: unknown output extension '{path.suffix}'; "
                         f"use one of {', '.join(FORMATS)}")
    if ext == ".exr":
        try:
            import OpenEXR  # noqa: F401
        except ImportError:
            raise OutputError(f"{path}: writing .exr needs the OpenEXR package "
                             "(pip install 'rtweekend[exr]'); .npy keeps linear "
                             "floats too") from None
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"{path}: cannot write: folder '{folder}' does not exist")
    try:
        # Permission bits do not tell the whole story (root, read-only mounts,
        # /sys): create and remove the temporary file the write will use.
        fd, probe = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as e:
        raise OutputError(f"{path}: cannot write in folder '{folder}': "
                         f"{e.strerror or e}") from None


def encode(image, ext, layers=None, metadata=None):
    """The file contents for `image` (HxWx3 float) as bytes; .exr files also
    hold `layers` ({name: HxWx3}: channels name.R, name.G, name.B) and
    `metadata` ({name: str}: header attributes)."""
    image = _rgb(image, "image")
    buf = io.BytesIO()
    if ext == ".npy":
        np.save(buf, image)
    elif ext == ".exr":
        _write_exr(image, buf, layers or {}, metadata or {})
    else:
        import imageio.v3 as iio
        return iio.imwrite("<bytes>", tonemap(image), extension=ext)
    return buf.getvalue()


def _rgb(image, what):
    image = np.asarray(image, dtype=np.float32)
    if image.ndim != 3 or image.shape[2] != 3:
        raise OutputError(f"save_image: {what}: expected an HxWx3 image, got shape {image.shape}")
    return image


def _write_exr(image, buf, layers, metadata):
    import OpenEXR
    channels = {"RGB": np.ascontiguousarray(image)}
    for name, layer in layers.items():
        layer = _rgb(layer, name)
        for i, c in enumerate("RGB"):
            channels[f"{name}.{c}"] = np.ascontiguousarray(layer[..., i])
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage,
              **{f"rtweekend.{k}": str(v) for k, v in metadata.items()}}
    with tempfile.TemporaryDirectory() as tmp:
        # The bindings write to a path; go through a private file, then to memory.
        name = os.path.join(tmp, "image.exr")
        with OpenEXR.File(header, channels) as f:
            f.write(name)
        buf.write(Path(name).read_bytes())


def layer_path(path, name):
    """Where a .npy output's layer `name` goes: OUT.npy -> OUT.name.npy."""
    path = Path(path)
    return path.with_name(f"{path.stem}.{name}{path.suffix}")


def save_image(image: np.ndarray | RenderResult, path: str | Path,
               layers: Mapping[str, np.ndarray] | None = None,
               metadata: Mapping[str, object] | None = None) -> None:
    """Write `image` to `path`, atomically; the format follows the extension.

    image: an HxWx3 array of linear radiance, or what render() returned (the
    same file: a result is its .image).  .png/.jpg/...: the books' tone map
    (which writes a classic scene's canvas colours exactly); .npy and .exr:
    float32 linear values (.exr needs the `exr` extra).  layers ({name: HxWx3},
    .npy and .exr only): more images of the render -- feature images, the
    unbiased image beside a denoised one -- as the .exr's layers name.R/G/B, or
    beside a .npy as OUT.name.npy.  metadata ({name: value}): the .exr's
    header attributes rtweekend.name.
    """
    image = getattr(image, "image", image)
    path = Path(path)
    check_output_path(path)
    ext = path.suffix.lower()
    if layers and ext not in (".npy", ".exr"):
        raise OutputError(f"{path}: only .npy and .exr files can hold more layers "
                         f"({', '.join(layers)}); .png and the like hold one tone-mapped image")
    files = []
    if ext == ".npy":
        files = [(layer_path(path, name), encode(layer, ext))
                 for name, layer in (layers or {}).items()]
        layers = None
    files.append((path, encode(image, ext, layers, metadata)))
    _write_atomically(files)


# A write the command abandons on Ctrl-C goes on in its thread (kernel/calls.py)
# until the process exits: its temporary files are removed here and never
# renamed into place, so that nothing it was writing is left behind.
_WRITING = threading.Lock()
_temporary = set()                  # the temporary files of the writes under way
_abandoned = False


def abandon_writes():
    """Remove the files being written and keep them from being renamed into
    place: Ctrl-C during a write leaves no file (the command calls this)."""
    global _abandoned
    with _WRITING:
        _abandoned = True
        for tmp in _temporary:
            _unlink(tmp)
        _temporary.clear()


def _write_atomically(files):
    """Write each (path, bytes) under a temporary name beside it, then rename
    them all: a failure or Ctrl-C on the way leaves none of them."""
    tmps = []
    try:
        for path, data in files:
            fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part",
                                       dir=path.parent if str(path.parent) else ".")
            with _WRITING:
                _temporary.add(tmp)
            tmps.append(tmp)
            with os.fdopen(fd, "wb") as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
            os.chmod(tmp, 0o666 & ~_umask())
        with _WRITING:
            if _abandoned:
                raise KeyboardInterrupt
            for (path, _), tmp in zip(files, tmps):
                os.replace(tmp, path)
                _temporary.discard(tmp)
    except BaseException:
        with _WRITING:
            for tmp in tmps:
                _unlink(tmp)
                _temporary.discard(tmp)
        raise


def _unlink(path):
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask
