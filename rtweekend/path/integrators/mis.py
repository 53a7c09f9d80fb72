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
"""
from ...kernel.jit import jit_step
from .vertices import DELTA, FWD, REV

POWER = 2


@jit_step
def ratio(rev, fwd):
    """(rev / fwd)^POWER, a zero on either side (a delta vertex) read as 1."""
    r = (rev if rev != 0.0 else 1.0) / (fwd if fwd != 0.0 else 1.0)
    if POWER == 2:
        return r * r
    return r


@jit_step
def weight(cf, ci, lf, li, s, t, pt_rev, ptm_rev, qs_fwd, qs_rev, qsm_rev):
    """The MIS weight of strategy (s, t): light vertices lf/li[0:s], camera
    vertices cf/ci[0:t], joined by an edge from light vertex s - 1 to camera
    vertex t - 1 (their changed densities given: above)."""
    if s + t == 2:
        return 1.0
    others = 0.0
    r = 1.0
    for i in range(t - 1, 0, -1):
        rev = pt_rev if i == t - 1 else (ptm_rev if i == t - 2 else cf[i, REV])
        r *= ratio(rev, cf[i, FWD])
        if (i == t - 1 or ci[i, DELTA] == 0) and ci[i - 1, DELTA] == 0:
            others += r
    r = 1.0
    for i in range(s - 1, -1, -1):
        if i == s - 1:
            rev, fwd = qs_rev, qs_fwd
        else:
            rev, fwd = (qsm_rev if i == s - 2 else lf[i, REV]), lf[i, FWD]
        r *= ratio(rev, fwd)
        before_delta = i > 0 and li[i - 1, DELTA] != 0      # area lights are never delta
        if (i == s - 1 or li[i, DELTA] == 0) and not before_delta:
            others += r
    return 1.0 / (1.0 + others)
