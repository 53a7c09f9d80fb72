"""The books' thin-lens camera, packed into one float array for the kernels.

Pixel (i, j) covers [i, i+1) x [j, j+1) of a viewport that spans exactly vfov
vertically (the v4 mapping: divide by W, not W - 1); row 0 is the top.
"""
import math

import numpy as np

from ..kernel import rng, sampler
from ..kernel.jit import jit_step

# Columns of the packed camera (each a 3-vector but LENS).
ORIGIN = 0           # lookfrom
CORNER = 3           # upper-left corner of the viewport on the focus plane
HORIZONTAL = 6       # viewport width vector
VERTICAL = 9         # viewport height vector (up)
LENS_U = 12          # camera u (right), to move the origin on the lens
LENS_V = 15          # camera v (up)
LENS = 18            # lens radius (0: pinhole)


def pack_camera(camera):
    """The array get_ray reads, for a validated scene.Camera."""
    origin = np.asarray(camera.lookfrom, dtype=np.float64)
    w = origin - np.asarray(camera.lookat, dtype=np.float64)
    w /= np.linalg.norm(w)
    u = np.cross(np.asarray(camera.vup, dtype=np.float64), w)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    viewport_h = 2.0 * math.tan(math.radians(camera.vfov) / 2.0) * camera.focus_dist
    viewport_w = viewport_h * camera.width / camera.height
    horizontal = viewport_w * u
    vertical = viewport_h * v
    corner = origin - horizontal / 2 + vertical / 2 - camera.focus_dist * w
    return np.concatenate([origin, corner, horizontal, vertical, u, v,
                           [camera.aperture / 2.0]])


@jit_step
def sample_ray(cam, x, y, width, height, smp):
    """(origin, unit direction, smp) of a ray through pixel (x, y): its position
    in the pixel is the sampler's next 2-D point, its place on the lens from the
    stream."""
    jx, jy, smp = sampler.next_2d(smp)
    o, d, state = get_ray_at(cam, x, y, width, height, jx, jy, smp.state)
    return o, d, sampler.resume(smp, state)


@jit_step
def get_ray(cam, x, y, width, height, state):
    """(origin, unit direction, state) of a jittered ray through pixel (x, y)."""
    jx, state = rng.uniform(state)
    jy, state = rng.uniform(state)
    return get_ray_at(cam, x, y, width, height, jx, jy, state)


@jit_step
def get_ray_at(cam, x, y, width, height, jx, jy, state):
    """get_ray with the position in the pixel given: (x + jx, y + jy)."""
    s = (x + jx) / width
    t = (y + jy) / height
    ox, oy, oz = cam[ORIGIN], cam[ORIGIN + 1], cam[ORIGIN + 2]
    lens = cam[LENS]
    if lens > 0.0:
        disk, state = rng.in_unit_disk(state)
        a = lens * disk[0]
        b = lens * disk[1]
        ox += a * cam[LENS_U] + b * cam[LENS_V]
        oy += a * cam[LENS_U + 1] + b * cam[LENS_V + 1]
        oz += a * cam[LENS_U + 2] + b * cam[LENS_V + 2]
    dx = cam[CORNER] + s * cam[HORIZONTAL] - t * cam[VERTICAL] - ox
    dy = cam[CORNER + 1] + s * cam[HORIZONTAL + 1] - t * cam[VERTICAL + 1] - oy
    dz = cam[CORNER + 2] + s * cam[HORIZONTAL + 2] - t * cam[VERTICAL + 2] - oz
    inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    return (ox, oy, oz), (dx * inv, dy * inv, dz * inv), state
