"""The books' metal: the mirror direction moved by a point of a ball of radius
`fuzz`, weight = albedo.

The fuzz ball gives directions no closed-form density (the books never
evaluate it: skip_pdf), so metal is a delta material for every estimator: it is
sampled and followed, never evaluated, connected to or weighed by MIS; eval
and pdf are 0 for it (materials.py).  With fuzz = 0 it is an ideal mirror.
"""
from ...kernel import rng
from ...kernel.jit import jit_step
from ...kernel.vec3 import dot, madd, reflect, unit
from .flags import DELTA

FLAGS = DELTA
FUZZ = 0            # its parameter (Bsdf.params)


def params(material):
    """Its parameters, as packed (scene/materials.py's Material)."""
    return (material.param,)


@jit_step
def scatter(d, n, fuzz, state):
    """(direction, ok, state) for a ray along d meeting the normal n that faces it;
    ok is False when the fuzz pushed the direction under the surface (book 1
    absorbs the ray there).  Three numbers of the stream when fuzz > 0, none else."""
    r = reflect(d, n)
    if fuzz > 0.0:
        b, state = rng.in_unit_sphere(state)
        r = madd(r, b, fuzz)
    return unit(r), dot(r, n) > 0.0, state
