"""Checks for one field of a scene object: each returns the clean value or
raises FieldError naming the field.  Shared by the builder and the loader."""
from collections.abc import Sequence

from .. import checks
from ..checks import LARGEST, MAX_SIZE, SMALLEST, length  # noqa: F401  (the bounds, here too)
from ..errors import FieldError

# What the builders' signatures say a value is (the checks accept any sequence
# of three numbers, NumPy arrays too).
Vec3 = Sequence[float]                 # a point or a direction: (x, y, z)
Color = Sequence[float]                # (r, g, b): linear, or 0..255 for phong

_show = checks.show


def _real(value, field):
    return checks.real(value, field)


def number(value, field, *, lo=None, hi=None, lo_open=False, hi_open=False,
           nonzero=False):
    """A finite float within [lo, hi] (or open ends) and within +-LARGEST."""
    return checks.real(value, field, lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open,
                       nonzero=nonzero)


def integer(value, field, *, lo=1, hi=None):
    return checks.integer(value, field, lo=lo, hi=hi)


def vec3(value, field):
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 3:
        raise FieldError(field, f"expected 3 numbers [x, y, z], got {_show(value)}")
    return tuple(_real(c, field) for c in value)


def angles(value, field):
    """Three rotation angles in degrees [rx, ry, rz], each finite."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 3:
        raise FieldError(field, f"expected 3 angles in degrees [rx, ry, rz], got "
                         f"{_show(value)}")
    return tuple(_real(c, field) for c in value)


def color(value, field, *, hi=None):
    """An RGB triple with components >= 0 (and <= hi for albedos)."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 3:
        raise FieldError(field, f"expected 3 numbers [r, g, b], got {_show(value)}")
    rgb = tuple(_real(c, field) for c in value)
    if min(rgb) < 0.0:
        raise FieldError(field, f"components must be >= 0, got {list(rgb)}")
    if hi is not None and max(rgb) > hi:
        raise FieldError(field, f"components must be <= {hi:g}, got {list(rgb)}")
    return rgb


def boolean(value, field):
    if not isinstance(value, bool):
        raise FieldError(field, f"expected true or false, got {_show(value)}")
    return value


def text(value, field):
    if not isinstance(value, str):
        raise FieldError(field, f"expected a string, got {_show(value)}")
    return value


SKY = "sky"


def background(value, field="background"):
    """The path tracer's background: an RGB radiance triple or "sky" (book 1's
    gradient); returned as given, validated."""
    if isinstance(value, str):
        if value != SKY:
            raise FieldError(field, f'expected [r, g, b] or "sky", got "{value}"')
        return SKY
    return color(value, field)
