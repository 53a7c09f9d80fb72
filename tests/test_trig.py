"""kernel/trig.py: the cosine and sine of an angle in turns, without libm, as
libm's to a few units in the last place; and bdpt's cosine lobe drawn with it
is the lambertian's."""
import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from rtweekend.kernel.trig import cos_sin_turns
from rtweekend.path.materials import lambertian

turns = st.floats(0.0, 1.0, exclude_max=True)


@given(turns)
def test_cos_sin_turns_are_libms_to_rounding(u):
    c, s = cos_sin_turns(u)
    # 2 pi u itself rounds by up to half an ulp of 2 pi (4.4e-16).
    assert abs(c - math.cos(2 * math.pi * u)) < 1e-15
    assert abs(s - math.sin(2 * math.pi * u)) < 1e-15
    assert abs(c * c + s * s - 1.0) < 1e-15


def test_the_quarter_turns_and_their_neighbours():
    for k in range(8):
        for u in (k / 8, np.nextafter(k / 8, 0.0), np.nextafter(k / 8, 1.0)):
            if 0.0 <= u < 1.0:
                c, s = cos_sin_turns(u)
                assert abs(c - math.cos(2 * math.pi * u)) < 1e-15
                assert abs(s - math.sin(2 * math.pi * u)) < 1e-15


@given(turns, turns, st.floats(0.0, math.pi), st.floats(0.0, 2 * math.pi))
def test_the_cosine_lobe_is_cosine_at_to_rounding(u1, u2, theta, phi):
    n = (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))
    a, b = lambertian.cosine_lobe(n, u1, u2), lambertian.cosine_at(n, u1, u2)
    assert max(abs(x - y) for x, y in zip(a, b)) < 1e-14
