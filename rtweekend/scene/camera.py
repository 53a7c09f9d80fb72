"""The path tracer's camera: the books' positionable thin-lens camera."""
import math
from dataclasses import dataclass

import numpy as np

from . import fields
from .. import checks
from ..errors import FieldError, SceneError


@dataclass(frozen=True)
class Camera:
    """The books' positionable thin-lens camera; defaults are book 1's."""
    lookfrom: tuple = (0.0, 0.0, 0.0)
    lookat: tuple = (0.0, 0.0, -1.0)
    vup: tuple = (0.0, 1.0, 0.0)
    vfov: float = 90.0                 # vertical, degrees
    aperture: float = 0.0              # lens diameter; 0 = pinhole
    focus_dist: float | None = None    # None: |lookfrom - lookat|
    width: int = 400
    height: int = 225

    def __post_init__(self):
        try:
            self._check()
        except FieldError as e:
            raise SceneError(f"camera: {e}") from None

    def _check(self):
        set_ = object.__setattr__          # normalise the frozen fields once
        for name in ("lookfrom", "lookat", "vup"):
            set_(self, name, fields.vec3(getattr(self, name), name))
        set_(self, "vfov", fields.number(self.vfov, "vfov", lo=0.0, hi=180.0,
                                         lo_open=True, hi_open=True))
        set_(self, "aperture", fields.number(self.aperture, "aperture", lo=0.0))
        set_(self, "width", checks.option("width", self.width))
        set_(self, "height", checks.option("height", self.height))
        # Distances with math.hypot, which neither underflows nor overflows:
        # numpy's norm squares first, and called two points 3e-170 apart equal.
        view = tuple(b - a for a, b in zip(self.lookfrom, self.lookat))
        dist = math.hypot(*view)
        if dist == 0.0:
            raise FieldError("lookat", "equals lookfrom: the view direction is undefined")
        if dist < fields.SMALLEST:
            raise FieldError("lookat", f"is only {dist:g} from lookfrom: the renderer squares "
                             f"distances, and below {fields.SMALLEST:g} their squares "
                             "underflow (scale the scene up)")
        # Relative to the camera's coordinates: the viewport's corner is computed
        # beside lookfrom, so the view must be well above the rounding there.
        scale = max(map(abs, self.lookfrom + self.lookat))
        if dist < RESOLUTION * scale:
            raise FieldError("lookat", f"is only {dist:g} from lookfrom, at coordinates of "
                             f"{scale:g}: less than {RESOLUTION:g} of them, the view "
                             "direction is lost in rounding")
        up_len = math.hypot(*self.vup)
        if up_len < fields.SMALLEST:
            raise FieldError("vup", f"{list(self.vup)} is too short: its length must be at "
                             f"least {fields.SMALLEST:g}")
        up = np.asarray(self.vup) / up_len
        w = np.asarray(view) / dist
        if np.linalg.norm(np.cross(up, w)) <= 1e-12:
            raise FieldError("vup", f"{list(self.vup)} is parallel to the view direction")
        if self.focus_dist is None:
            # numpy's norm, as always (the same bits; it is exact enough here).
            set_(self, "focus_dist", float(np.linalg.norm(view)))
        set_(self, "focus_dist", fields.length(self.focus_dist, "focus_dist"))
        if self.focus_dist < RESOLUTION * scale:
            raise FieldError("focus_dist", f"{self.focus_dist:g} is less than {RESOLUTION:g} "
                             f"of the camera's coordinates ({scale:g}): the viewport "
                             "would be lost in rounding")
        if self.aperture > 0.0:
            fields.length(self.aperture, "aperture")


# The smallest distance (lookfrom to lookat, the focus distance) relative to the
# camera's coordinates: doubles resolve 2e-16 of them; a 1000-pixel viewport
# then still has a million representable positions per pixel.
RESOLUTION = 1e-9
