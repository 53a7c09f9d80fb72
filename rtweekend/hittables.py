"""Ray-object intersection over the flat object arrays.

Layout (see scene.py for how objects get here):
  obj_i[k] = (kind, material)
  obj_f[k] = SPHERE: center(0:3), radius(3, signed), radius^2(4)
             RECT:   corner Q(0:3), edges u(3:6), v(6:9), unit normal n(9:12),
                     plane offset D = n.Q (12), u/|u|^2 (13:16), v/|v|^2 (16:19),
                     area (19)
A RECT is any rectangle: the books' xy/xz/yz rects, the six faces of a box and
rotated rects are all stored this way, rotate_y + translate already applied.
Its outward normal is unit(u x v); flip_face swaps u and v.  A sphere's outward
normal is (p - center) / radius, so a negative radius (the hollow bubble) or
flip_face turns it inward.

Self-intersection is avoided without an epsilon: a ray remembers the object it
leaves.  A rect can never be hit again by a ray leaving it, and a sphere only
at its far root when the ray enters it.  This is exact at every scale, so there
is no t_min to tune (the books' 0.001 breaks for scenes 1000x smaller).
"""
import math

from .jit import jit, jit_inline
from .tags import NO_HIT, OBJ_KIND, SPHERE
from .vec3 import dot, madd, sub

INF = math.inf
OBJ_FLOATS = 20   # a RECT's row; a SPHERE uses the first 5


@jit_inline
def sphere_t(obj_f, k, o, d, t_max, far_only):
    """Nearest root in (0, t_max) of |o + t d - c| = |r| for unit d, else inf."""
    oc = (o[0] - obj_f[k, 0], o[1] - obj_f[k, 1], o[2] - obj_f[k, 2])
    half_b = dot(oc, d)
    c = dot(oc, oc) - obj_f[k, 4]
    disc = half_b * half_b - c
    if disc < 0.0:
        return INF
    sq = math.sqrt(disc)
    if not far_only:
        t = -half_b - sq
        if 0.0 < t < t_max:
            return t
    t = -half_b + sq
    if 0.0 < t < t_max:
        return t
    return INF


@jit_inline
def rect_t(obj_f, k, o, d, t_max):
    """Distance along d to the rectangle, in (0, t_max), else inf.

    Helpers that are inlined take their caller's error model, so no division
    here may rely on error_model='numpy' turning x/0 into inf.
    """
    n = (obj_f[k, 9], obj_f[k, 10], obj_f[k, 11])
    denom = dot(n, d)
    if denom == 0.0:
        return INF                  # parallel to the plane
    t = (obj_f[k, 12] - dot(n, o)) / denom
    if not (0.0 < t < t_max):
        return INF
    p = madd(o, d, t)
    q = (p[0] - obj_f[k, 0], p[1] - obj_f[k, 1], p[2] - obj_f[k, 2])
    alpha = q[0] * obj_f[k, 13] + q[1] * obj_f[k, 14] + q[2] * obj_f[k, 15]
    if alpha < 0.0 or alpha > 1.0:
        return INF
    beta = q[0] * obj_f[k, 16] + q[1] * obj_f[k, 17] + q[2] * obj_f[k, 18]
    if beta < 0.0 or beta > 1.0:
        return INF
    return t


@jit_inline
def object_t(obj_i, obj_f, k, o, d, t_max, from_obj, from_inside):
    """Distance to object k for a ray leaving object from_obj (NO_HIT: none).

    from_inside: the ray entered from_obj's ball (only meaningful for spheres).
    """
    if obj_i[k, OBJ_KIND] == SPHERE:
        far_only = k == from_obj
        if far_only and not from_inside:
            return INF              # leaving a convex surface outward
        return sphere_t(obj_f, k, o, d, t_max, far_only)
    if k == from_obj:
        return INF                  # a plane is never hit twice
    return rect_t(obj_f, k, o, d, t_max)


@jit
def _reciprocal(x):
    """1/x, with 1/0 = inf of the same sign, under any error model."""
    return 1.0 / x if x != 0.0 else math.copysign(INF, x)


@jit_inline
def _box_entry(bvh_box, i, o, inv_d, t_max):
    """Does the ray enter box i before t_max?  (slab test, inv_d = 1 / d)"""
    t0 = (bvh_box[i, 0] - o[0]) * inv_d[0]
    t1 = (bvh_box[i, 3] - o[0]) * inv_d[0]
    near, far = min(t0, t1), max(t0, t1)
    t0 = (bvh_box[i, 1] - o[1]) * inv_d[1]
    t1 = (bvh_box[i, 4] - o[1]) * inv_d[1]
    near, far = max(near, min(t0, t1)), min(far, max(t0, t1))
    t0 = (bvh_box[i, 2] - o[2]) * inv_d[2]
    t1 = (bvh_box[i, 5] - o[2]) * inv_d[2]
    near, far = max(near, min(t0, t1)), min(far, max(t0, t1))
    return near <= far and far > 0.0 and near < t_max


@jit_inline
def closest_hit(obj_i, obj_f, bvh_box, bvh_node, bvh_prims, o, d, t_max, from_obj,
                from_inside):
    """(object index, t) of the nearest hit, or (NO_HIT, inf).

    With an empty BVH every object is tested; otherwise the stackless walk
    described in bvh.py.
    """
    best = NO_HIT
    # One loop for both cases, so object_t is inlined at one call site only
    # (each inlined copy costs compile time): no BVH is a single leaf node.
    no_bvh = bvh_node.shape[0] == 0
    n_nodes = 1 if no_bvh else bvh_node.shape[0]
    inv_d = (_reciprocal(d[0]), _reciprocal(d[1]), _reciprocal(d[2]))
    i = 0
    while i < n_nodes:
        if no_bvh:
            first, count, after = 0, obj_i.shape[0], 1
        elif _box_entry(bvh_box, i, o, inv_d, t_max):
            count = bvh_node[i, 1]
            if count == 0:
                i += 1                      # inner node: on to its left child
                continue
            first, after = bvh_node[i, 0], bvh_node[i, 2]
        else:
            i = bvh_node[i, 2]
            continue
        for j in range(first, first + count):
            k = j if no_bvh else bvh_prims[j]
            t = object_t(obj_i, obj_f, k, o, d, t_max, from_obj, from_inside)
            if t < t_max:
                t_max = t
                best = k
        i = after
    return best, t_max


@jit_inline
def outward_normal(obj_i, obj_f, k, p):
    """Unit normal at p on object k, pointing to its front side."""
    if obj_i[k, OBJ_KIND] == SPHERE:
        inv_r = 1.0 / obj_f[k, 3]
        return ((p[0] - obj_f[k, 0]) * inv_r,
                (p[1] - obj_f[k, 1]) * inv_r,
                (p[2] - obj_f[k, 2]) * inv_r)
    return (obj_f[k, 9], obj_f[k, 10], obj_f[k, 11])


@jit_inline
def enters(obj_i, obj_f, k, p, d):
    """Does a ray leaving object k at p along d go into its ball?  (spheres only)"""
    if obj_i[k, OBJ_KIND] != SPHERE:
        return False
    c = (obj_f[k, 0], obj_f[k, 1], obj_f[k, 2])
    return dot(d, sub(p, c)) < 0.0


@jit
def face_normal(d, n_out):
    """The books' set_face_normal: (front_face, normal facing the ray)."""
    if dot(d, n_out) < 0.0:
        return True, n_out
    return False, (-n_out[0], -n_out[1], -n_out[2])
