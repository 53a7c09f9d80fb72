"""Vector identities: reflect, refract (Snell), Schlick, the orthonormal basis."""
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rtweekend.kernel import vec3
from rtweekend.path.materials.dielectric import schlick

angles = st.floats(0.0, 2 * math.pi)


def direction(theta, phi):
    return (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))


@given(angles, angles, angles, angles)
def test_reflect_mirrors_about_the_normal(t1, p1, t2, p2):
    v, n = direction(t1, p1), direction(t2, p2)
    r = vec3.reflect(v, n)
    assert math.isclose(vec3.dot(r, n), -vec3.dot(v, n), abs_tol=1e-12)   # normal part flips
    assert math.isclose(vec3.length(r), 1.0, rel_tol=1e-12)               # length kept
    # tangential part kept: r - v is along n
    d = vec3.sub(r, v)
    assert vec3.length(vec3.cross(d, n)) < 1e-12


@given(st.floats(0.0, math.pi / 2 - 1e-6), st.floats(0.2, 3.0))
def test_refract_obeys_snell(theta_i, eta):
    n = (0.0, 0.0, 1.0)
    uv = (math.sin(theta_i), 0.0, -math.cos(theta_i))   # arriving against n
    sin_t = eta * math.sin(theta_i)
    if sin_t > 1.0:
        return   # total internal reflection: the caller never refracts here
    t = vec3.refract(uv, n, eta)
    assert math.isclose(vec3.length(t), 1.0, rel_tol=1e-9)
    assert math.isclose(t[0], sin_t, abs_tol=1e-9)       # sin(theta_t) = eta sin(theta_i)
    assert t[2] <= 0.0                                   # goes through the surface
    assert t[1] == 0.0                                   # stays in the plane of incidence


def test_refract_at_normal_incidence_goes_straight():
    assert np.allclose(vec3.refract((0.0, 0.0, -1.0), (0.0, 0.0, 1.0), 1 / 1.5), (0, 0, -1))


def test_schlick_end_points_and_monotone():
    r0 = ((1 - 1.5) / (1 + 1.5)) ** 2
    assert math.isclose(schlick(1.0, 1.5), r0)            # normal incidence: 0.04
    assert math.isclose(schlick(1.0, 1 / 1.5), r0)        # symmetric in the ratio
    assert math.isclose(schlick(0.0, 1.5), 1.0)           # grazing: total
    values = [schlick(c, 1.5) for c in np.linspace(0, 1, 50)]
    assert all(a >= b for a, b in zip(values, values[1:]))


@settings(max_examples=300)
@given(angles, angles)
def test_onb_is_right_handed_orthonormal(theta, phi):
    w = direction(theta, phi)
    u, v = vec3.onb(w)
    m = np.array([u, v, w])
    assert np.allclose(m @ m.T, np.eye(3), atol=1e-9)
    assert np.allclose(np.cross(u, v), w, atol=1e-9)
