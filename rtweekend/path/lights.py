"""What lights a scene: one table of the lights its estimators pick from, and
the background.

The light layer.  Each row of the table is one thing a light sampler can
choose, in one of two roles (the row's ROLE, and light_ranges[role]: the rows
[first, end) of that role, each role's rows together):

  EMITTED  a primitive whose material emits (diffuse_light), picked by power:
           next events (nee.py), light paths (light_point), manifold
           connections.  A box is one row per face (part 0..5,
           box.sample_area), the other kinds one row (part -1).
  LISTED   an entry of the books' lights list, picked uniformly: the
           mixture pdf's lights (pdf.py), an emitter or an attractor (an
           object that does not emit, such as a glass ball).  It is sampled
           whole, by direction (shapes' sample_toward; a mesh, named by its
           first triangle: mesh_light.py), part -1.

light_rows holds (object, part, role); light_f, for an EMITTED row:

  AREA   the row's surface area: light_parts gives it (shapes/<kind>.py), and
         it is the one a point drawn on the row is dense by (sample_point)
  POWER  pi x luminance x area: what a one-sided lambertian emitter radiates

and for every row PROB, how often `pick` -- one picker for both roles --
chooses it among its role's rows (EMITTED: by power, or by area if every
emitter is black, so that the densities stay finite; LISTED: 1 / the list's
length), and CDF, its role's cumulative PROB (`pick` searches the emitters';
the list it picks as the books do, int(u n), which gives the same rows).
`light_pick[k]` is how often next events pick object k, the sum of its
EMITTED rows' PROB: the density of a direction that happens to reach k.

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
from .layout import (BG_SKY, EMITTED, LIGHT_AREA, LIGHT_CDF, LIGHT_OBJ, LIGHT_PART,
                     LIGHT_POWER, LIGHT_PROB, LISTED, MAT_COLOR, OBJ_KIND,
                     OBJ_MAT)

# Rec. 709 luminance of linear RGB: how bright a colour is to the eye.
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def pack_lights(obj_i, obj_f, mat_i, mat_f, listed):
    """(light_rows int64 [L, 3], light_f float64 [L, 4], light_ranges int64 [2, 2],
    light_pick float64 [N]) of a scene whose lights list names the objects
    `listed` (a mesh: its first triangle)."""
    rows, values = [], []
    for k in np.flatnonzero(objects_with(obj_i, mat_i, EMITS)):
        m = obj_i[k, OBJ_MAT]
        luminance = float(LUMINANCE @ mat_f[m, MAT_COLOR:MAT_COLOR + 3])
        for part, area in shapes.light_parts(obj_i[k, OBJ_KIND], obj_f[k]):
            rows.append((k, part, EMITTED))
            values.append((area, math.pi * luminance * area))
    rows = np.array(rows, dtype=np.int64).reshape(-1, 3)
    light_f = np.zeros((len(rows), 4))
    light_pick = np.zeros(len(obj_i))
    if len(rows):
        light_f[:, LIGHT_AREA], light_f[:, LIGHT_POWER] = np.array(values).T
        weight = light_f[:, LIGHT_POWER] if light_f[:, LIGHT_POWER].sum() > 0 \
            else light_f[:, LIGHT_AREA]
        _distribute(light_f, weight)
        # An object's share from its own weights (not a sum of rounded shares):
        # exactly 1 for a scene's only emitter, box lights included.
        np.add.at(light_pick, rows[:, LIGHT_OBJ], weight)
        light_pick /= weight.sum()
    return (*_with_listed(rows, light_f, listed), light_pick)


def _distribute(light_f, weight):
    """A role's PROB and CDF in its rows light_f from their weights; the last
    CDF is 1, so that no u in [0, 1) falls past the last row."""
    light_f[:, LIGHT_PROB] = weight / weight.sum()
    light_f[:, LIGHT_CDF] = np.cumsum(light_f[:, LIGHT_PROB])
    light_f[-1, LIGHT_CDF] = 1.0


def _with_listed(emitted, emitted_f, listed):
    """(light_rows, light_f, light_ranges): the EMITTED rows `emitted` (their
    light_f: emitted_f), then one LISTED row per object of `listed`, uniformly."""
    e, n = len(emitted), len(listed)
    listed_rows = np.column_stack([np.asarray(listed, dtype=np.int64), np.full(n, -1),
                                   np.full(n, LISTED)]).astype(np.int64).reshape(-1, 3)
    listed_f = np.zeros((n, 4))
    # Uniform (pick draws it as int(u n), without these; they say the same).
    listed_f[:, LIGHT_PROB] = 1.0 / max(n, 1)
    listed_f[:, LIGHT_CDF] = np.arange(1, n + 1) / max(n, 1)
    ranges = np.array([[0, e], [e, e + n]], dtype=np.int64)
    return np.concatenate([emitted, listed_rows]), np.concatenate([emitted_f, listed_f]), ranges


def relisted(arrays, listed):
    """The packed scene with its lights list made of the objects `listed`."""
    first, end = arrays.light_ranges[EMITTED]
    rows, light_f, ranges = _with_listed(arrays.light_rows[first:end],
                                         arrays.light_f[first:end], listed)
    return arrays._replace(light_rows=rows, light_f=light_f, light_ranges=ranges)


def rows_of(arrays, role):
    """The light table's rows of one role (NumPy: packing, checks, tests)."""
    first, end = arrays.light_ranges[role]
    return arrays.light_rows[first:end]


def listed(arrays):
    """int64: the objects of the books' lights list, in its order."""
    return rows_of(arrays, LISTED)[:, LIGHT_OBJ]


def emitters(arrays):
    """int64: the objects that emit, in order."""
    return np.unique(rows_of(arrays, EMITTED)[:, LIGHT_OBJ])


@jit_step
def count(scene, role):
    """How many rows the table has in `role`."""
    return scene.light_ranges[role, 1] - scene.light_ranges[role, 0]


@jit_step
def pick(scene, role, u):
    """The row of `role` chosen by u in [0, 1): the first whose cumulative
    probability exceeds u.  The lights list is uniform: its entry is the
    books' int(u n), computed so (no search, no branch to mispredict; role is
    a constant, so each caller compiles one way); the emitters by a binary
    search over their CDF."""
    lo, hi = scene.light_ranges[role, 0], scene.light_ranges[role, 1] - 1
    if role == LISTED:
        n = hi - lo + 1
        return lo + min(int(u * n), n - 1)
    light_f = scene.light_f
    while lo < hi:
        mid = (lo + hi) // 2
        if u < light_f[mid, LIGHT_CDF]:
            hi = mid
        else:
            lo = mid + 1
    return lo


@jit_step
def stretched(scene, role, row, u):
    """u, which picked `row` of `role`, stretched back to [0, 1] within the
    row's share: a stratified u stays stratified over what the row samples
    (the lights list: u n - its entry, as pick computes it)."""
    first = scene.light_ranges[role, 0]
    if role == LISTED:
        return min(u * count(scene, role) - (row - first), 1.0)
    light_f = scene.light_f
    below = light_f[row - 1, LIGHT_CDF] if row > first else 0.0
    return min((u - below) / light_f[row, LIGHT_PROB], 1.0)


@jit_step
def pick_emitter(scene, u):
    """The emitter (object) of the EMITTED row chosen by u; scene.light_pick[k]
    is how often each is chosen."""
    return scene.light_rows[pick(scene, EMITTED, u), LIGHT_OBJ]


@jit_step
def sample_point(scene, row, u1, u2, time):
    """(object, point, outward normal, area density) of a point uniform over the
    surface of EMITTED row `row`, for the unit square's point (u1, u2).  The
    density is 1 / the row's AREA; times light_f[row, PROB] it is over all the
    emitters' area when the row itself was picked by `pick`."""
    k = scene.light_rows[row, LIGHT_OBJ]
    p, n = shapes.sample_area(scene, k, scene.light_rows[row, LIGHT_PART], u1, u2, time)
    return k, p, n, 1.0 / scene.light_f[row, LIGHT_AREA]


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
    for row in range(scene.light_ranges[EMITTED, 0], scene.light_ranges[EMITTED, 1]):
        if rows[row, LIGHT_OBJ] == k:
            return light_f[row, LIGHT_PROB] / light_f[row, LIGHT_AREA]
    return 0.0


@jit_step
def light_point(scene, textures, time, smp):
    """A point on an emitter as light paths start: the row picked by power, the
    point by area.  Returns (object, point, outward normal, emitted radiance
    there, area density over all the emitters, smp)."""
    u, smp = sampler.uniform(smp)
    row = pick(scene, EMITTED, u)
    u1, u2, smp = sampler.next_2d(smp)
    k, p, n, pdf_area = sample_point(scene, row, u1, u2, time)
    return k, p, n, color_of(scene, textures, k, p, k, time), \
        pdf_area * scene.light_f[row, LIGHT_PROB], smp
