"""Checks for one field of a scene object: each returns the clean value or
raises FieldError naming the field.  Shared by the builder and the loader."""
import math
import numbers

from ..errors import FieldError


# Intersection tests square coordinates and radii: beyond this they overflow.
LARGEST = 1e100


def _real(value, field):
    # bool is an int in Python; `radius = true` is a mistake, not 1.
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise FieldError(field, f"expected a number, got {_show(value)}")
    try:
        value = float(value)
    except OverflowError:
        raise FieldError(field, f"must be within +-{LARGEST:g}") from None
    if not math.isfinite(value):
        raise FieldError(field, f"must be finite, got {value}")
    if abs(value) > LARGEST:
        raise FieldError(field, f"must be within +-{LARGEST:g}, got {value:g}")
    return value


def _show(value):
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def number(value, field, *, lo=None, hi=None, lo_open=False, hi_open=False,
           nonzero=False):
    """A finite float within [lo, hi] (or open ends)."""
    x = _real(value, field)
    if lo is not None and (x < lo or (lo_open and x == lo)):
        raise FieldError(field, f"must be {'>' if lo_open else '>='} {lo:g}, got {x:g}")
    if hi is not None and (x > hi or (hi_open and x == hi)):
        raise FieldError(field, f"must be {'<' if hi_open else '<='} {hi:g}, got {x:g}")
    if nonzero and x == 0.0:
        raise FieldError(field, "must not be 0")
    return x


def integer(value, field, *, lo=1, hi=None):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise FieldError(field, f"expected an integer, got {_show(value)}")
    if value < lo:
        raise FieldError(field, f"must be >= {lo}, got {value}")
    if hi is not None and value > hi:
        raise FieldError(field, f"must be <= {hi}, got {value}")
    return int(value)


def vec3(value, field):
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 3:
        raise FieldError(field, f"expected 3 numbers [x, y, z], got {_show(value)}")
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


# Pixels per side, a sanity bound (65536^2 would need ~200 GB of sums).
MAX_SIZE = 65536
SKY = "sky"


def background(value, field="background"):
    """The path tracer's background: an RGB radiance triple or "sky" (book 1's
    gradient); returned as given, validated."""
    if isinstance(value, str):
        if value != SKY:
            raise FieldError(field, f'expected [r, g, b] or "sky", got "{value}"')
        return SKY
    return color(value, field)
