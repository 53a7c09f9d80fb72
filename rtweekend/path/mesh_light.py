"""A mesh in the lights list: one light of the books' mixture, a point drawn
uniformly over its whole surface (a triangle picked by area, then a point in
it), and the density of a direction under that.

The lights list's density is the books' hittable_pdf: every point of the
light along a direction counts, whatever lies in between -- a closed mesh is
met twice, its near side and its far one, and either may have been drawn.  So
the density of d at p sums t^2 / |cos| over every triangle of the mesh the
ray meets (wide_bvh.solid_angle_sum), over the mesh's area.  Next-event
estimation does not use this: it picks an emitting mesh's triangles one at a
time, by power (lights.py).

Layout.Triangles.groups[g] = (first object, triangle count, first row of
group_cdf) for each mesh in the lights list; group_cdf holds each mesh's
cumulative triangle areas over its total (the last is 1), group_area its area.
Every function takes the mesh tables first (None: no mesh, nothing compiled).
"""
import math

import numpy as np

from ..kernel.jit import jit_step, like
from . import lights, wide_bvh
from .shapes import triangle

NAN = math.nan


def pack(obj_f, meshes):
    """(groups int64 [G, 3], group_cdf float64, group_area float64 [G]) for the
    meshes (first object, triangle count) of the lights list."""
    groups, cdfs, areas, row = [], [], [], 0
    for first, count in meshes:
        area = obj_f[first:first + count, triangle.AREA]
        total = float(area.sum())
        cdf = np.cumsum(area) / total
        cdf[-1] = 1.0
        groups.append((first, count, row))
        cdfs.append(cdf)
        areas.append(total)
        row += count
    return (np.array(groups, dtype=np.int64).reshape(-1, 3),
            np.concatenate(cdfs) if cdfs else np.zeros(0), np.array(areas, dtype=np.float64))


def objects(arrays):
    """int64: the objects the lights list covers, each mesh's triangles all."""
    out = []
    groups = arrays.tris.groups if arrays.tris is not None else np.zeros((0, 3), np.int64)
    for k in lights.listed(arrays):
        g = np.flatnonzero(groups[:, 0] == k)
        out.append(np.arange(k, k + groups[g[0], 1]) if len(g) else np.array([k]))
    return np.concatenate(out).astype(np.int64) if out else np.zeros(0, dtype=np.int64)


@jit_step
def group_of(tris, k):
    """The lights list's mesh that starts at object k, or -1 (k is another kind)."""
    if tris is None:
        return -1
    groups = tris.groups
    for g in range(groups.shape[0]):
        if groups[g, 0] == k:
            return g
    return -1


@jit_step
def pick(cdf, start, count, u):
    """The first index i in start .. start + count - 1 with u < cdf[i] (a
    binary search), as an offset from start."""
    lo, hi = 0, count - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if u < cdf[start + mid]:
            hi = mid
        else:
            lo = mid + 1
    return lo


@jit_step
def sample_toward(tris, obj_f, g, p, u1, u2):
    """The unit direction from p to mesh g's point for the unit square's
    (u1, u2), uniform over its area for a uniform point: u1 picks the triangle
    by area and is stretched back to [0, 1) within its share, so that a
    stratified point stays stratified over each triangle."""
    if tris is None:
        return (NAN, NAN, NAN)
    first, count, start = tris.groups[g, 0], tris.groups[g, 1], tris.groups[g, 2]
    cdf = tris.group_cdf
    i = pick(cdf, start, count, u1)
    below = cdf[start + i - 1] if i > 0 else 0.0
    v1 = min((u1 - below) / (cdf[start + i] - below), 1.0)
    return triangle.sample_toward(tris, obj_f, first + i, p, v1, u2)


@jit_step
def pdf_toward(tris, wide, obj_f, g, p, d, from_obj):
    """Solid-angle density at p of direction d under sample_toward(g): the sum
    over the mesh's triangles d meets of distance^2 / |cos|, over its area
    (wide: the scene's WideBVH, None if it has none: then every triangle)."""
    if tris is None:
        return like(p[0], NAN)
    first, count = tris.groups[g, 0], tris.groups[g, 1]
    if wide is None:
        total = 0.0
        for k in range(first, first + count):
            if k != from_obj:
                total += triangle.solid_angle_term(obj_f, k, p, d)
        return total / tris.group_area[g]
    return wide_bvh.solid_angle_sum(wide, obj_f, p, d, first, count, from_obj) / \
        tris.group_area[g]
