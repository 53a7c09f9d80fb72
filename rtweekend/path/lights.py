"""What lights a scene: its emitters, one row per emissive primitive, and the
background.

The light layer.  Every surface whose material emits (diffuse_light) becomes
one row of `light_rows` (object, part) -- a box one row per face (part 0..5,
box.sample_area), the other kinds one row (part -1) -- with its area and its
power in `light_f`:

  AREA   the row's surface area
  POWER  pi x luminance x area: what a one-sided lambertian emitter radiates
  PROB   POWER / the total: how often `pick` chooses it (by area if every
         emitter is black, so that the densities stay finite)
  CDF    the cumulative PROB, for the binary search of `pick`

and `light_pick[k]` is how often an object is picked, the sum of its rows'.
Next-event estimation picks an emitter this way (nee.py) and aims at it with
the shape's own light sampling (shapes/<kind>.py: sample_toward): bright
emitters get the shadow rays, tiny dim ones few; `sample_point`
gives a point on the surface by area, for estimators that start paths on
lights, and area_to_solid_angle turns its density into a direction's.

A ray that escapes the scene takes the background's radiance: a constant, or
book 1's sky gradient (SceneArrays.bg_kind).
"""
import math

import numpy as np

from ..kernel import sampler
from ..kernel.jit import jit_step
from . import shapes
from .materials import EMITS, objects_with
from .surface import color_of
from .layout import (BG_SKY, LIGHT_AREA, LIGHT_CDF, LIGHT_OBJ, LIGHT_PART,
                     LIGHT_POWER, LIGHT_PROB, MAT_COLOR, OBJ_KIND, OBJ_MAT)

# Rec. 709 luminance of linear RGB: how bright a colour is to the eye.
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def pack_lights(obj_i, obj_f, mat_i, mat_f):
    """(light_rows int64 [L, 2], light_f float64 [L, 4], light_pick float64 [N])."""
    rows, values = [], []
    for k in np.flatnonzero(objects_with(obj_i, mat_i, EMITS)):
        m = obj_i[k, OBJ_MAT]
        luminance = float(LUMINANCE @ mat_f[m, MAT_COLOR:MAT_COLOR + 3])
        for part, area in shapes.light_parts(obj_i[k, OBJ_KIND], obj_f[k]):
            rows.append((k, part))
            values.append((area, math.pi * luminance * area))
    rows = np.array(rows, dtype=np.int64).reshape(-1, 2)
    light_f = np.zeros((len(rows), 4))
    light_pick = np.zeros(len(obj_i))
    if len(rows):
        light_f[:, LIGHT_AREA], light_f[:, LIGHT_POWER] = np.array(values).T
        weight = light_f[:, LIGHT_POWER] if light_f[:, LIGHT_POWER].sum() > 0 \
            else light_f[:, LIGHT_AREA]
        light_f[:, LIGHT_PROB] = weight / weight.sum()
        light_f[:, LIGHT_CDF] = np.cumsum(light_f[:, LIGHT_PROB])
        light_f[-1, LIGHT_CDF] = 1.0             # no u in [0, 1) falls past the last row
        # An object's share from its own weights (not a sum of rounded shares):
        # exactly 1 for a scene's only emitter, box lights included.
        np.add.at(light_pick, rows[:, LIGHT_OBJ], weight)
        light_pick /= weight.sum()
    return rows, light_f, light_pick


@jit_step
def pick(scene, u):
    """The row chosen by u in [0, 1): the first whose cumulative probability
    exceeds u (a binary search over the rows, by power)."""
    light_f = scene.light_f
    lo, hi = 0, light_f.shape[0] - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if u < light_f[mid, LIGHT_CDF]:
            hi = mid
        else:
            lo = mid + 1
    return lo


@jit_step
def pick_emitter(scene, u):
    """The emitter (object) of the row chosen by u; scene.light_pick[k] is how
    often each is chosen."""
    return scene.light_rows[pick(scene, u), LIGHT_OBJ]


@jit_step
def sample_point(scene, row, u1, u2, time):
    """(object, point, outward normal, area density) of a point uniform over the
    surface of light row `row`, for the unit square's point (u1, u2).  The
    density is over the row's area; times light_f[row, PROB] it is over all the
    lights' area when the row itself was picked by `pick`."""
    k = scene.light_rows[row, LIGHT_OBJ]
    p, n, pdf = shapes.sample_area(scene, k, scene.light_rows[row, LIGHT_PART], u1, u2, time)
    return k, p, n, pdf


@jit_step
def area_to_solid_angle(pdf_area, p, q, n_q):
    """The solid-angle density at p of the direction towards q, a point drawn on a
    surface of normal n_q with density pdf_area: pdf_area x distance^2 / |cos|
    (0 for a direction along the surface)."""
    dx, dy, dz = q[0] - p[0], q[1] - p[1], q[2] - p[2]
    dist2 = dx * dx + dy * dy + dz * dz
    cosine = abs(dx * n_q[0] + dy * n_q[1] + dz * n_q[2]) / math.sqrt(dist2)
    if cosine == 0.0:
        return 0.0
    return pdf_area * dist2 / cosine


@jit_step
def background(scene, d):
    """Radiance of a ray that escapes along the unit direction d."""
    if scene.bg_kind == BG_SKY:
        a = 0.5 * (d[1] + 1.0)
        return (1.0 - 0.5 * a, 1.0 - 0.3 * a, 1.0)
    bg = scene.bg
    return (bg[0], bg[1], bg[2])


@jit_step
def origin_density(scene, k):
    """The area density of a point of emitter k as `pick` and `sample_point`
    draw it among all the emitters: P(row) / area(row), the same for every
    row of one object (its rows' shares are in proportion to their areas)."""
    rows, light_f = scene.light_rows, scene.light_f
    for row in range(rows.shape[0]):
        if rows[row, LIGHT_OBJ] == k:
            return light_f[row, LIGHT_PROB] / light_f[row, LIGHT_AREA]
    return 0.0


@jit_step
def light_point(scene, textures, time, smp):
    """A point on an emitter as light paths start: the row picked by power, the
    point by area.  Returns (object, point, outward normal, emitted radiance
    there, area density over all the emitters, smp)."""
    u, smp = sampler.uniform(smp)
    row = pick(scene, u)
    u1, u2, smp = sampler.next_2d(smp)
    k, p, n, pdf_area = sample_point(scene, row, u1, u2, time)
    return k, p, n, color_of(scene, textures, k, p, k, time), \
        pdf_area * scene.light_f[row, LIGHT_PROB], smp
