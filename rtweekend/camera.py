"""The books' thin-lens camera, packed into one float array for the kernels.

Pixel (i, j) covers [i, i+1) x [j, j+1) of a viewport that spans exactly vfov
vertically (the v4 mapping: divide by W, not W - 1); row 0 is the top.
"""
import math

import numpy as np

from . import rng
from .jit import jit_inline

# cam[0:3] origin, [3:6] upper-left corner of the viewport on the focus plane,
# [6:9] viewport width vector, [9:12] viewport height vector (up),
# [12:15] camera u (right), [15:18] camera v (up), [18] lens radius.
CAM_FLOATS = 19


def camera_array(lookfrom, lookat, vup, vfov, aperture, focus_dist, width, height):
    """Pack a validated camera into the array get_ray reads."""
    origin = np.asarray(lookfrom, dtype=np.float64)
    w = origin - np.asarray(lookat, dtype=np.float64)
    w /= np.linalg.norm(w)
    u = np.cross(np.asarray(vup, dtype=np.float64), w)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    viewport_h = 2.0 * math.tan(math.radians(vfov) / 2.0) * focus_dist
    viewport_w = viewport_h * width / height
    horizontal = viewport_w * u
    vertical = viewport_h * v
    corner = origin - horizontal / 2 + vertical / 2 - focus_dist * w
    return np.concatenate([origin, corner, horizontal, vertical, u, v,
                           [aperture / 2.0]])


@jit_inline
def get_ray(cam, x, y, width, height, state):
    """(origin, unit direction, state) of a jittered ray through pixel (x, y)."""
    jx, state = rng.uniform(state)
    jy, state = rng.uniform(state)
    s = (x + jx) / width
    t = (y + jy) / height
    ox, oy, oz = cam[0], cam[1], cam[2]
    lens = cam[18]
    if lens > 0.0:
        disk, state = rng.in_unit_disk(state)
        a = lens * disk[0]
        b = lens * disk[1]
        ox += a * cam[12] + b * cam[15]
        oy += a * cam[13] + b * cam[16]
        oz += a * cam[14] + b * cam[17]
    dx = cam[3] + s * cam[6] - t * cam[9] - ox
    dy = cam[4] + s * cam[7] - t * cam[10] - oy
    dz = cam[5] + s * cam[8] - t * cam[11] - oz
    inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    return (ox, oy, oz), (dx * inv, dy * inv, dz * inv), state
