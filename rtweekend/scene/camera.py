"""The path tracer's camera: the books' positionable thin-lens camera."""
from dataclasses import dataclass

import numpy as np

from . import fields
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
        set_(self, "width", fields.integer(self.width, "width", hi=fields.MAX_SIZE))
        set_(self, "height", fields.integer(self.height, "height", hi=fields.MAX_SIZE))
        view = np.subtract(self.lookat, self.lookfrom)
        dist = float(np.linalg.norm(view))
        if dist == 0.0:
            raise FieldError("lookat", "equals lookfrom: the view direction is undefined")
        up = np.asarray(self.vup)
        if np.linalg.norm(np.cross(up, view)) <= 1e-12 * dist * np.linalg.norm(up):
            raise FieldError("vup", f"{list(self.vup)} is parallel to the view direction")
        if self.focus_dist is None:
            set_(self, "focus_dist", dist)
        set_(self, "focus_dist", fields.number(self.focus_dist, "focus_dist",
                                               lo=0.0, lo_open=True))
