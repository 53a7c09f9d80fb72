"""The isotropic phase function of a constant medium (The Next Week): every
direction equally likely, p = f = 1 / (4 pi), weight = albedo."""
import math

from ...kernel import rng
from ...kernel.jit import jit_step
from .flags import JOIN, MEDIUM

FLAGS = JOIN | MEDIUM
DENSITY = 0         # its parameter: the medium's density (media.py)


def params(material):
    """Its parameters, as packed (scene/materials.py's Material)."""
    return (material.param,)

INV_4PI = 1.0 / (4.0 * math.pi)


@jit_step
def pdf():
    return INV_4PI


@jit_step
def sample(state):
    """(direction, state): uniform over the sphere, two numbers of the stream."""
    return rng.unit_vector(state)
