"""The multiple importance sampling weight of one bidirectional strategy
(Veach's thesis 10.2; pbrt-v4's MISWeight): the power heuristic over every
strategy that could have made the same path, computed from the vertices'
densities without evaluating any of them whole.

A path of n = s + t vertices, s from the light and t from the camera, could
also have been made by (s - 1, t + 1), (s + 1, t - 1), ...  The density of
each, relative to this one's, is a product of ratios REV / FWD, walking from
the connection outwards along either subpath: moving vertex i of the camera
subpath to the light side multiplies by its REV / FWD (REV: its density drawn
from the light's side).  A ratio of 0 / 0 at a delta vertex counts as 1 and
a strategy that would connect at a delta vertex is left out: nothing could
have made the path that way.  The connection changes four densities -- both
endpoints' and their predecessors' REV, now drawn across the new edge --
which the caller computes and passes in (pt_rev, ptm_rev, qs_rev, qsm_rev;
qs_fwd: the light endpoint's own FWD, a light point drawn anew for s = 1).

The weight is 1 / (1 + sum of the others' (density ratio)^POWER): POWER 2 is
Veach's power heuristic, 1 the balance heuristic.  A path seen directly (s +
t = 2: the camera ray hits a light) has one strategy only, (0, 2): light
tracing's (1, 1) is not used.  Light carried to the camera (t = 1) counts the
camera ray densities of the whole film, as many samples as pixels (film.py).

Only the two vertices nearest the connection on each side change with it;
the rest of each sum is a subpath's own, the same for all its strategies.
So accumulate() walks each subpath once when it is drawn and stores, at
vertex i, ACC_i = ok_i + r_{i-1} ACC_{i-1} (r_i: vertex i's REV / FWD ratio,
ok_i: a strategy may move vertex i across), and a strategy's sum on one side
is r_1 ok_1 + r_1 r_2 ACC_2, its two changed ratios times what lies beyond
them: O(1) per strategy instead of a loop over its vertices.
"""
from ...kernel.jit import jit_step
from .vertices import ACC, DELTA, FWD, REV

POWER = 2


@jit_step
def ratio(rev, fwd):
    """(rev / fwd)^POWER, a zero on either side (a delta vertex) read as 1."""
    r = (rev if rev != 0.0 else 1.0) / (fwd if fwd != 0.0 else 1.0)
    if POWER == 2:
        return r * r
    return r


@jit_step
def movable(vi, i):
    """1 if a strategy may connect at vertex i (moving it to the other
    subpath): neither it nor the one before it is delta."""
    if vi[i, DELTA] != 0 or (i > 0 and vi[i - 1, DELTA] != 0):
        return 0.0
    return 1.0


@jit_step
def accumulate(vf, vi, first, n):
    """Set ACC of vertices first..n-1 of a subpath (first: 1 for the camera's,
    whose vertex 0 no strategy moves; 0 for the light's)."""
    acc = 0.0
    for i in range(first, n):
        if i > first:
            acc *= ratio(vf[i - 1, REV], vf[i - 1, FWD])
        acc += movable(vi, i)
        vf[i, ACC] = acc


@jit_step
def power(density):
    """density^POWER, a zero (a delta vertex's) read as 1."""
    x = density if density != 0.0 else 1.0
    if POWER == 2:
        return x * x
    return x


@jit_step
def side(vf, vi, end, end_rev, end_fwd, prev_rev, first):
    """The sum over one subpath of the strategies that move its vertices end,
    end - 1, ... across, as (numerator, denominator): the ratios at `end` (its
    REV end_rev and FWD end_fwd, as the connection makes them) and at end - 1
    (REV prev_rev) times the subpath's own ACC beyond them.  A fraction, so
    that weight divides once."""
    if end < first:
        return 0.0, 1.0
    rev, fwd = power(end_rev), power(end_fwd)
    # The endpoint itself is joined, so never delta: only its predecessor counts.
    ok = 0.0 if end > 0 and vi[end - 1, DELTA] != 0 else 1.0
    if end - 1 < first:
        return rev * ok, fwd
    prev_fwd = power(vf[end - 1, FWD])
    return rev * (ok * prev_fwd + power(prev_rev) * vf[end - 1, ACC]), fwd * prev_fwd


@jit_step
def weight(cf, ci, lf, li, s, t, pt_rev, ptm_rev, qs_fwd, qs_rev, qsm_rev):
    """The MIS weight of strategy (s, t): light vertices lf/li[0:s], camera
    vertices cf/ci[0:t] (their ACC set: accumulate), joined by an edge from
    light vertex s - 1 to camera vertex t - 1 (their changed densities given:
    above)."""
    if s + t == 2:
        return 1.0
    # 1 / (1 + a / b + c / d), one division.
    a, b = side(cf, ci, t - 1, pt_rev, cf[t - 1, FWD], ptm_rev, 1)
    c, d = side(lf, li, s - 1, qs_rev, qs_fwd, qsm_rev, 0)
    return b * d / (b * d + a * d + c * b)
