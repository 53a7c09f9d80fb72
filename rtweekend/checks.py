"""Every number that reaches the renderer is checked here: its type, that it is
finite, and its range.

Scene fields (scene/fields.py, for the builder and the TOML loader), render
options (options.py, for render(), the command line and Renderer) and the
Renderer's methods all call `real` and `integer` below, so `inf`, `nan`, 2.5
samples or a bool never get further than this module, and every message has the
same shape.  Each raises FieldError(field, problem); callers add the file and
the object.
"""
import math
import numbers

from .errors import FieldError

# Intersection tests square coordinates and radii: beyond this they overflow.
LARGEST = 1e100
# ... and below this a length's square leaves double precision's normal range
# (1e-308): lengths (radii, extents, camera distances) must be at least this.
SMALLEST = 1e-100
# Pixels per side, a sanity bound (the memory check says what a size needs).
MAX_SIZE = 65536
# Samples per pixel and path segments: sample indices and counts stay far from
# 64-bit overflow, and a loop bound this large is a typo, not a render.
MAX_SPP = 10**9
MAX_DEPTH = 10**6


def show(value):
    """A value as a message shows it: its repr, cut at 40 characters."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def real(value, field, *, lo=None, hi=None, lo_open=False, hi_open=False,
         nonzero=False, bound=LARGEST):
    """A finite float within [lo, hi] (or open ends) and within +-bound.

    bool is an int in Python; `radius = true` is a mistake, not 1.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise FieldError(field, f"expected a number, got {show(value)}")
    try:
        x = float(value)
    except OverflowError:          # an int beyond float's range
        raise FieldError(field, f"must be within +-{bound:g}") from None
    if not math.isfinite(x):
        raise FieldError(field, f"must be finite, got {x}")
    if bound is not None and abs(x) > bound:
        raise FieldError(field, f"must be within +-{bound:g}, got {x:g}")
    if lo is not None and (x < lo or (lo_open and x == lo)):
        raise FieldError(field, f"must be {'>' if lo_open else '>='} {lo:g}, got {x:g}")
    if hi is not None and (x > hi or (hi_open and x == hi)):
        raise FieldError(field, f"must be {'<' if hi_open else '<='} {hi:g}, got {x:g}")
    if nonzero and x == 0.0:
        raise FieldError(field, "must not be 0")
    return x


def integer(value, field, *, lo=1, hi=None, hi_text=None):
    """An int within [lo, hi]; a float only if it is a whole number (TOML's 4.0).

    hi_text: how a message writes hi ("2**63 - 1").
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise FieldError(field, f"expected an integer, got {show(value)}")
    value = int(value)
    if value < lo:
        raise FieldError(field, f"must be >= {lo}, got {value}")
    if hi is not None and value > hi:
        raise FieldError(field, f"must be <= {hi_text or hi}, got {value}")
    return value


def length(value, field, *, signed=False):
    """A length: finite, at most LARGEST and, unless 0 is caught before, at
    least SMALLEST in magnitude (signed: negative allowed, e.g. a bubble's radius)."""
    x = real(value, field, lo=None if signed else 0.0)
    if x == 0.0:
        raise FieldError(field, "must not be 0")
    if abs(x) < SMALLEST:
        raise FieldError(field, f"{x:g} is too small: lengths below {SMALLEST:g} "
                         "underflow when squared")
    return x


# -- the render options: one rule each, for render(), Renderer and the command --

def option(name, value, *, integrator="path", threads_available=None):
    """A render option's value, checked (FieldError otherwise); None passes."""
    if value is None:
        return None
    if name == "spp":
        return integer(value, name, lo=1, hi=MAX_SPP)
    if name == "time":
        return real(value, name, lo=0.0, lo_open=True)
    if name == "seed":
        return integer(value, name, lo=0, hi=2**63 - 1, hi_text="2**63 - 1")
    if name in ("width", "height"):
        return integer(value, name, lo=1, hi=MAX_SIZE)
    if name == "max_depth":
        return integer(value, name, lo=0 if integrator == "classic" else 1, hi=MAX_DEPTH)
    if name == "threads":
        return integer(value, name, lo=1, hi=threads_available)
    if name == "clamp":
        return real(value, name, lo=0.0, lo_open=True)
    raise KeyError(name)
