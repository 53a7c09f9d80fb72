"""The books' thin-lens camera, packed into one float array for the kernels:
rays out of it, and the way back in.

Pixel (i, j) covers [i, i+1) x [j, j+1) of a viewport that spans exactly vfov
vertically (the v4 mapping: divide by W, not W - 1); row 0 is the top.  A ray
leaves a point of the lens (a disk of radius LENS about the origin, in the
plane facing FORWARD; a point for a pinhole) towards a point of the viewport,
which lies on the focus plane, at distance FOCUS in front of the origin.

The way back, for estimators that carry light towards the camera (light
tracing, bidirectional path tracing; Veach's thesis ch. 10, pbrt-v4's
PerspectiveCamera::We / PDF_We / SampleWi):

  raster(cam, ..., o, p)        where the ray from lens point o through p meets
                                the film, in pixels, and whether it is on it
  importance(cam, d)            W_e = 1 / (A a cos^4 theta) of a ray along d,
                                A the film's area at unit distance, a the
                                lens's area (1 for a pinhole), theta from FORWARD
  pdf_direction(cam, d)         1 / (A cos^3 theta): the density of a camera
                                ray's direction, film positions being uniform
  sample_lens(cam, ..., p, u)   a point of the lens seen from p: its direction
                                and distance, the solid-angle density at p
                                (d^2 / (cos a)), W_e and the raster position

W_e is normalised over the whole film: its integral, with cos theta, over the
film's directions and the lens is 1.  A pixel's measurement has W_e x (the
number of pixels) in it, so light carried to the camera by samples drawn for
every pixel (width x height x spp of them) adds up to a pixel value once its
sum is divided by spp alone, as camera samples are (film.py).
"""
import math

import numpy as np

from ..kernel import rng, sampler
from ..kernel.jit import jit_step
from ..kernel.vec3 import dot

# Columns of the packed camera (each a 3-vector but LENS).
ORIGIN = 0           # lookfrom
CORNER = 3           # upper-left corner of the viewport on the focus plane
HORIZONTAL = 6       # viewport width vector
VERTICAL = 9         # viewport height vector (up)
LENS_U = 12          # camera u (right), to move the origin on the lens
LENS_V = 15          # camera v (up)
LENS = 18            # lens radius (0: pinhole)
FORWARD = 19         # unit viewing direction (-w)
FOCUS = 22           # distance from the origin to the focus plane
FILM_AREA = 23       # the viewport's area at unit distance: A
LENS_AREA = 24       # pi LENS^2, or 1 for a pinhole (a point: W_e per unit of it)
CAM_FLOATS = 25


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
    lens = camera.aperture / 2.0
    return np.concatenate([origin, corner, horizontal, vertical, u, v, [lens], -w,
                           [camera.focus_dist, viewport_w * viewport_h / camera.focus_dist ** 2,
                            math.pi * lens * lens if lens > 0 else 1.0]])


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


@jit_step
def _col(cam, i):
    return (cam[i], cam[i + 1], cam[i + 2])


@jit_step
def raster(cam, width, height, o, p):
    """(x, y, on_film): where the ray from the lens point o through the point p
    meets the film, in pixels (x right, y down: pixel (int x, int y)); on_film
    False behind the camera or outside the image."""
    f = _col(cam, FORWARD)
    d = (p[0] - o[0], p[1] - o[1], p[2] - o[2])
    along = dot(d, f)
    if not along > 0.0:
        return -1.0, -1.0, False
    # The focus plane is dot(q - origin, f) = FOCUS, and the lens lies in the
    # plane through the origin: the ray meets it at t = FOCUS / along.
    t = cam[FOCUS] / along
    c = _col(cam, CORNER)
    q = (o[0] + t * d[0] - c[0], o[1] + t * d[1] - c[1], o[2] + t * d[2] - c[2])
    h, v = _col(cam, HORIZONTAL), _col(cam, VERTICAL)
    x = dot(q, h) / dot(h, h) * width
    y = -dot(q, v) / dot(v, v) * height
    return x, y, 0.0 <= x < width and 0.0 <= y < height


@jit_step
def importance(cam, d):
    """W_e of a ray leaving the lens along the unit direction d (for a point on
    the film: raster says whether it is)."""
    c = dot(d, _col(cam, FORWARD))
    if c <= 0.0:
        return 0.0
    c2 = c * c
    return 1.0 / (cam[FILM_AREA] * cam[LENS_AREA] * c2 * c2)


@jit_step
def pdf_direction(cam, d):
    """Solid-angle density of a camera ray's direction d (film positions
    uniform): 1 / (A cos^3 theta); the lens position's is 1 / LENS_AREA."""
    c = dot(d, _col(cam, FORWARD))
    if c <= 0.0:
        return 0.0
    return 1.0 / (cam[FILM_AREA] * c * c * c)


@jit_step
def sample_lens(cam, width, height, p, u1, u2):
    """A point of the lens seen from the scene point p, for the unit square's
    point (u1, u2): (wi from p towards it, distance, solid-angle density at p,
    W_e, x, y, on_film).  pdf = distance^2 / (cos theta LENS_AREA) (a pinhole: the
    lens is its one point, and the density is per unit of W_e's lens area)."""
    lens = cam[LENS]
    o = _col(cam, ORIGIN)
    if lens > 0.0:
        r = lens * math.sqrt(u1)
        phi = rng.TWO_PI * u2
        a, b = r * math.cos(phi), r * math.sin(phi)
        o = (o[0] + a * cam[LENS_U] + b * cam[LENS_V],
             o[1] + a * cam[LENS_U + 1] + b * cam[LENS_V + 1],
             o[2] + a * cam[LENS_U + 2] + b * cam[LENS_V + 2])
    x, y, on_film = raster(cam, width, height, o, p)
    d = (p[0] - o[0], p[1] - o[1], p[2] - o[2])
    dist = math.sqrt(dot(d, d))
    d = (d[0] / dist, d[1] / dist, d[2] / dist)      # from the lens towards p
    c = dot(d, _col(cam, FORWARD))
    if not on_film or c <= 0.0:
        return (-d[0], -d[1], -d[2]), dist, 0.0, 0.0, x, y, False
    return (-d[0], -d[1], -d[2]), dist, dist * dist / (c * cam[LENS_AREA]), \
        importance(cam, d), x, y, True
