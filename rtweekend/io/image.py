"""Writing images: the books' tone map for PNG, linear floats for analysis.

Every file is written to a temporary name in the target folder and renamed
over the target only when complete, so a failure or Ctrl-C never leaves a
truncated file behind.
"""
import io
import os
import tempfile
from pathlib import Path

import numpy as np

from ..errors import SceneError
from .formats import FORMATS, HDR, LDR  # noqa: F401



def tonemap(image):
    """The books' write_color: gamma 2 (sqrt), clamp to [0, 0.999], x256.

    NaN becomes 0 (a render never produces one: bad samples are dropped).
    """
    c = np.sqrt(np.nan_to_num(np.maximum(image, 0.0), nan=0.0, posinf=1.0))
    return (256.0 * np.clip(c, 0.0, 0.999)).astype(np.uint8)


def check_output_path(path):
    """Raise SceneError unless `path` has a known extension and a writable folder."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in FORMATS:
        raise SceneError(f"{path}: unknown output extension '{path.suffix}'; "
                         f"use one of {', '.join(FORMATS)}")
    if ext == ".exr":
        try:
            import OpenEXR  # noqa: F401
        except ImportError:
            raise SceneError(f"{path}: writing .exr needs the OpenEXR package "
                             "(pip install 'rtweekend[exr]'); .npy keeps linear "
                             "floats too") from None
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise SceneError(f"{path}: cannot write: folder '{folder}' does not exist")
    if path.is_dir():
        raise SceneError(f"{path}: cannot write: it is a folder")
    try:
        # Permission bits do not tell the whole story (root, read-only mounts,
        # /sys): create and remove the temporary file the write will use.
        fd, probe = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as e:
        raise SceneError(f"{path}: cannot write in folder '{folder}': "
                         f"{e.strerror or e}") from None


def encode(image, ext):
    """The file contents for `image` (HxWx3 float) as bytes."""
    image = np.asarray(image, dtype=np.float32)
    if image.ndim != 3 or image.shape[2] != 3:
        raise SceneError(f"save_image: expected an HxWx3 image, got shape {image.shape}")
    buf = io.BytesIO()
    if ext == ".npy":
        np.save(buf, image)
    elif ext == ".exr":
        _write_exr(image, buf)
    else:
        import imageio.v3 as iio
        return iio.imwrite("<bytes>", tonemap(image), extension=ext)
    return buf.getvalue()


def _write_exr(image, buf):
    import OpenEXR
    channels = {"RGB": np.ascontiguousarray(image)}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with tempfile.TemporaryDirectory() as tmp:
        # The bindings write to a path; go through a private file, then to memory.
        name = os.path.join(tmp, "image.exr")
        with OpenEXR.File(header, channels) as f:
            f.write(name)
        buf.write(Path(name).read_bytes())


def save_image(image, path):
    """Write `image` to `path`, atomically; the format follows the extension.

    image: an HxWx3 array of linear radiance, or what render() returned (the
    same file: a result is its .image).  .png/.jpg/...: the books' tone map
    (which writes a classic scene's canvas colours exactly); .npy and .exr:
    float32 linear values (.exr needs the `exr` extra).
    """
    image = getattr(image, "image", image)
    path = Path(path)
    check_output_path(path)
    data = encode(image, path.suffix.lower())
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part",
                               dir=path.parent if str(path.parent) else ".")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask
