"""Every material, tested the way Mitsuba 3 tests its BSDFs: sample() against
pdf() by chi-square, sample's weight = f |cos| / pdf = eval / pdf, eval
reciprocal, and what a delta material must say (eval and pdf 0, a unit
direction, the books' weight and choice).  The estimators' closed forms and
furnaces are in test_accuracy.py."""
import math

import numpy as np
import pytest
from numba import njit

from rtweekend.kernel import sampler
from rtweekend.kernel.vec3 import reflect
from rtweekend.path import materials
from rtweekend.path.materials import DIELECTRIC, LAMBERTIAN, MATERIAL_TAGS, METAL
from rtweekend.path.materials import Bsdf, dielectric, isotropic

from stats import assert_chi2

N_SAMPLES = 200_000
COS_BINS, PHI_BINS, SUB = 16, 32, 24
ALBEDO = (0.7, 0.4, 0.2)
NORMALS = [(0.0, 0.0, 1.0), (1.0, -2.0, 0.5), (0.0, -1.0, 0.0)]


def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    return tuple(float(c) for c in v / np.linalg.norm(v))


def _bsdf(kind, n, param=0.0, front=True):
    """A record of material `kind`: param, its first parameter or all of them."""
    params = tuple(map(float, np.atleast_1d(param)))
    return Bsdf(np.int64(kind), ALBEDO, (*params, *(0.0,) * (2 - len(params))), _unit(n),
                front, _unit(n), True)


def _frame(n):
    """An orthonormal (u, v, n) as rows, for binning directions about n."""
    n = np.asarray(n)
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, a)
    u /= np.linalg.norm(u)
    return np.array([u, np.cross(n, u), n])


@njit
def _samples(bsdf, wo, count, seed):
    """(wi, weight, pdf, delta, eval's product) of `count` draws of sample()."""
    wis, weights, evals = np.empty((count, 3)), np.empty((count, 3)), np.empty((count, 3))
    pdfs, deltas = np.empty(count), np.empty(count, dtype=np.bool_)
    for i in range(count):
        wi, weight, p, delta, _ = materials.sample(bsdf, wo, sampler.start(i, 0, seed, 0))
        att, s = materials.eval(bsdf, wo, wi, 1.0)
        for c in range(3):
            wis[i, c], weights[i, c], evals[i, c] = wi[c], weight[c], att[c] * s
        pdfs[i], deltas[i] = p, delta
    return wis, weights, pdfs, deltas, evals


@njit
def _pdfs(bsdf, wo, dirs):
    out = np.empty(dirs.shape[0])
    for i in range(dirs.shape[0]):
        out[i] = materials.pdf(bsdf, wo, (dirs[i, 0], dirs[i, 1], dirs[i, 2]))
    return out


@njit
def _isotropic(count, seed):
    out = np.empty((count, 3))
    for i in range(count):
        d, _ = isotropic.sample(sampler.start(i, 0, seed, 0).state)
        out[i, 0], out[i, 1], out[i, 2] = d
    return out


def _binned(dirs, n, density):
    """(observed counts, probabilities) of directions binned on an equal-area
    (cos theta, phi) grid about n: each bin's integral of density(directions)
    by the midpoint rule, each bin refined until two resolutions agree (a
    narrow lobe -- a rough glass's refraction -- needs far more points than
    the rest of the sphere)."""
    frame = _frame(n)
    local = dirs @ frame.T
    cos_t = np.clip(local[:, 2], -1, 1 - 1e-15)
    phi = np.mod(np.arctan2(local[:, 1], local[:, 0]), 2 * math.pi)
    i = ((cos_t + 1) / 2 * COS_BINS).astype(int)
    j = np.minimum((phi / (2 * math.pi) * PHI_BINS).astype(int), PHI_BINS - 1)
    observed = np.bincount(i * PHI_BINS + j, minlength=COS_BINS * PHI_BINS)
    return observed, _integrated(density, frame)


def _integrated(density, frame):
    """density(directions) integrated over each bin of the grid about frame's
    normal."""
    bins = np.arange(COS_BINS * PHI_BINS)
    prob = _bin_integrals(density, frame, bins, SUB)
    finer = _bin_integrals(density, frame, bins, 2 * SUB)
    sub = 2 * SUB
    while True:
        rough = np.abs(finer - prob) > 1e-6 + 1e-4 * finer
        if not rough.any() or sub >= 32 * SUB:
            return finer
        prob = finer.copy()
        sub *= 2
        finer[rough] = _bin_integrals(density, frame, bins[rough], sub)


def _bin_integrals(density, frame, bins, sub):
    """The integrals of density over the bins (flat indices), by the midpoint
    rule on sub x sub cells in (theta, phi) -- not in cos theta, where a lobe
    at a pole is a near-singular spike."""
    k = (np.arange(sub) + 0.5) / sub
    rows = bins // PHI_BINS
    lo = np.arccos(np.minimum(1.0, (rows + 1) / COS_BINS * 2 - 1))     # theta of the bin's top
    hi = np.arccos((rows / COS_BINS) * 2 - 1)
    t = (lo[:, None] + (hi - lo)[:, None] * k[None, :])[:, :, None]    # (bins, sub, 1)
    p = ((bins % PHI_BINS)[:, None] + k[None, :])[:, None, :] / PHI_BINS * 2 * math.pi
    shape = (len(bins), sub, sub)
    local = np.stack([np.broadcast_to(np.sin(t) * np.cos(p), shape),
                      np.broadcast_to(np.sin(t) * np.sin(p), shape),
                      np.broadcast_to(np.cos(t), shape)], -1)
    values = density(np.ascontiguousarray(local.reshape(-1, 3) @ frame)).reshape(shape)
    area = np.sin(t) * ((hi - lo) / sub)[:, None, None] * (2 * math.pi / (PHI_BINS * sub))
    return (values * area).sum(axis=(1, 2))


def _chi2_against(dirs, n, density, absorbed=0):
    """Chi-square of directions about n against density; `absorbed` draws gave
    none, against the share of probability the density leaves out."""
    observed, prob = _binned(dirs, n, density)
    expected = (len(dirs) + absorbed) * prob
    keep = expected > 20                # pool the bins with few expected samples
    observed = np.append(observed[keep], [observed[~keep].sum(), absorbed])
    expected = np.append(expected[keep], [expected[~keep].sum(),
                                          (len(dirs) + absorbed) * max(0.0, 1 - prob.sum())])
    assert_chi2(observed, expected)


# The chi-square adapter: every smooth material (sampled, evaluated: not delta,
# not a light, not a medium's) with the parameters to test it with -- one line
# per kind.  Its draws must follow its pdf (chi-square), each drawn pdf be what
# pdf() says, and each weight be eval / pdf, for wo from the normal to grazing,
# on either side of the surface (front: a rough glass's two media).
SMOOTH = {"lambertian": [()], "rough_conductor": [(0.1,), (0.4,), (1.0,)],
          "rough_dielectric": [(1.5, 0.15), (1.5, 0.5), (1.33, 1.0)]}
WOS = [(0.0, 0.0, 1.0), (0.6, 0.3, 0.74), (0.97, 0.0, 0.2)]


def _smooth_cases():
    return [(name, params) for name, cases in SMOOTH.items() for params in cases]


def test_the_adapter_has_every_smooth_material():
    from rtweekend.path.materials import DELTA, EMITS, MEDIUM
    smooth = {name for name in MATERIAL_TAGS
              if not materials.kind_has(name, DELTA | EMITS | MEDIUM)}
    assert set(SMOOTH) == smooth


@pytest.mark.parametrize("front", [True, False])
@pytest.mark.parametrize("wo", WOS)
@pytest.mark.parametrize("n", NORMALS)
@pytest.mark.parametrize("name, params", _smooth_cases())
def test_a_smooth_material_draws_by_its_pdf_with_weight_eval_over_pdf(name, params, n, wo,
                                                                     front):
    frame = _frame(_unit(n))
    wo = _unit(np.asarray(wo) @ frame)          # wo about this normal
    padded = (*map(float, params), *(0.0,) * (2 - len(params)))
    bsdf = Bsdf(np.int64(MATERIAL_TAGS[name]), ALBEDO, padded, _unit(n), front, _unit(n), True)
    wis, weights, pdfs, deltas, evals = _samples(bsdf, wo, N_SAMPLES, 3)
    assert not deltas.any()
    drawn = pdfs > 0
    np.testing.assert_allclose(np.linalg.norm(wis[drawn], axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(pdfs[drawn], _pdfs(bsdf, wo, wis[drawn]), rtol=1e-9)
    np.testing.assert_allclose(weights[drawn], evals[drawn] / pdfs[drawn, None], rtol=1e-9)
    _chi2_against(wis[drawn], bsdf.n, lambda d: _pdfs(bsdf, wo, d), absorbed=int((~drawn).sum()))


@pytest.mark.parametrize("n", NORMALS)
def test_lambertian_pdf_integrates_to_one_and_is_zero_below(n):
    bsdf, wo = _bsdf(LAMBERTIAN, n), _unit(n)
    dirs = _isotropic(400_000, 7)
    v = _pdfs(bsdf, wo, dirs) * 4 * math.pi
    assert abs(v.mean() - 1.0) < 5 * v.std() / math.sqrt(len(v))
    assert (v[dirs @ np.asarray(bsdf.n) <= 0] == 0).all()


@pytest.mark.parametrize("n", NORMALS)
def test_lambertian_weight_is_eval_over_pdf_and_eval_is_albedo_cos_over_pi(n):
    bsdf, wo = _bsdf(LAMBERTIAN, n), _unit(n)
    wis, weights, pdfs, _, evals = _samples(bsdf, wo, 5000, 5)
    np.testing.assert_allclose(weights, evals / pdfs[:, None], rtol=1e-12)
    np.testing.assert_allclose(weights, np.broadcast_to(ALBEDO, weights.shape), rtol=1e-12)
    cos = wis @ np.asarray(bsdf.n)
    np.testing.assert_allclose(evals, np.outer(cos / math.pi, ALBEDO), rtol=1e-12)


@njit
def _eval_pairs(bsdf, a, b, scale):
    out = np.empty((a.shape[0], 2))
    for i in range(a.shape[0]):
        x, y = (a[i, 0], a[i, 1], a[i, 2]), (b[i, 0], b[i, 1], b[i, 2])
        att, s = materials.eval(bsdf, x, y, scale)
        out[i, 0] = att[0] * s
        att, s = materials.eval(bsdf, y, x, scale)
        out[i, 1] = att[0] * s
    return out


@pytest.mark.parametrize("n", NORMALS)
def test_lambertian_is_reciprocal_and_scales_like_the_books(n):
    """f(wo, wi) = f(wi, wo) with f = eval / |cos theta_i|; eval(..., scale) is
    scale x eval(..., 1) to the last bit (MIS weights are folded in that way)."""
    bsdf = _bsdf(LAMBERTIAN, n)
    rng_ = np.random.default_rng(9)
    a, b = _isotropic(2000, 1), _isotropic(2000, 2)
    nn = np.asarray(bsdf.n)
    a *= np.sign(a @ nn)[:, None]          # both above the surface
    b *= np.sign(b @ nn)[:, None]
    e = _eval_pairs(bsdf, a, b, 1.0)
    f_ab, f_ba = e[:, 0] / (b @ nn), e[:, 1] / (a @ nn)
    np.testing.assert_allclose(f_ab, f_ba, rtol=1e-12)
    np.testing.assert_allclose(f_ab, ALBEDO[0] / math.pi, rtol=1e-12)
    # the kernel's own order of operations: dot left to right, then scale x c / pi
    cosines = [nn[0] * x + nn[1] * y + nn[2] * z for x, y, z in b]
    for scale in rng_.uniform(0.01, 3.0, 5):
        scaled = _eval_pairs(bsdf, a, b, scale)
        assert np.array_equal(scaled[:, 0], np.array(
            [ALBEDO[0] * (scale * c * (1 / math.pi)) for c in cosines]))


@pytest.mark.parametrize("kind, param", [(METAL, 0.0), (METAL, 0.4), (DIELECTRIC, 1.5)])
def test_delta_materials_are_sampled_only(kind, param):
    bsdf = _bsdf(kind, (0.0, 0.0, 1.0), param)
    wo = _unit((0.3, -0.2, 0.9))
    wis, weights, pdfs, deltas, evals = _samples(bsdf, wo, 4000, 8)
    assert deltas.all()
    assert (evals == 0).all() and (_pdfs(bsdf, wo, wis) == 0).all()
    kept = pdfs > 0
    np.testing.assert_allclose(np.linalg.norm(wis[kept], axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(weights[kept], np.broadcast_to(ALBEDO, weights[kept].shape))
    assert materials.delta(bsdf) and materials.scatters(bsdf)


def test_metal_reflects_within_its_fuzz_and_absorbs_below_the_surface():
    n = (0.0, 0.0, 1.0)
    wo = _unit((0.6, 0.0, 0.2))                 # a grazing ray: fuzz pushes some below
    d = tuple(-c for c in wo)
    mirror = np.array(reflect(d, n))
    sharp = _samples(_bsdf(METAL, n, 0.0), wo, 100, 1)
    np.testing.assert_allclose(sharp[0], np.broadcast_to(mirror, (100, 3)), rtol=1e-12)
    wis, _, pdfs, _, _ = _samples(_bsdf(METAL, n, 0.5), wo, 20_000, 2)
    angle = np.arccos(np.clip(wis @ mirror / np.linalg.norm(mirror), -1, 1))
    assert angle.max() <= math.asin(0.5) + 1e-9        # within the fuzz ball's cone
    below = wis[:, 2] <= 0
    assert below.any() and (pdfs[below] == 0).all() and (pdfs[~below] == 1).all()


@pytest.mark.parametrize("front", [True, False])
@pytest.mark.parametrize("cos_in", [0.95, 0.5, 0.15])
def test_dielectric_reflects_with_schlicks_probability(front, cos_in):
    ior = 1.5
    n = (0.0, 0.0, 1.0)
    wo = (math.sqrt(1 - cos_in ** 2), 0.0, cos_in)
    wis, _, _, _, _ = _samples(_bsdf(DIELECTRIC, n, ior, front), wo, 40_000, 4)
    reflected = wis[:, 2] > 0
    ratio = 1 / ior if front else ior
    sin_out = ratio * math.sqrt(1 - cos_in ** 2)
    p = 1.0 if sin_out > 1 else dielectric.schlick(cos_in, ratio)
    sigma = math.sqrt(max(p * (1 - p), 1e-12) / len(wis))
    assert abs(reflected.mean() - p) <= 5 * sigma + 1e-12
    if p < 1:                                           # Snell's law on the refracted ones
        t = wis[~reflected]
        np.testing.assert_allclose(np.hypot(t[:, 0], t[:, 1]), sin_out, rtol=1e-9)


def test_isotropic_phase_is_uniform_over_the_sphere():
    dirs = _isotropic(N_SAMPLES, 12)
    _chi2_against(dirs, (0.0, 0.0, 1.0), lambda d: np.full(len(d), isotropic.pdf()))
    assert isotropic.pdf() == 1 / (4 * math.pi)


def test_a_light_emits_from_its_front_and_does_not_scatter():
    from rtweekend.path.materials import DIFFUSE_LIGHT
    front, back = _bsdf(DIFFUSE_LIGHT, (0, 0, 1)), _bsdf(DIFFUSE_LIGHT, (0, 0, 1), front=False)
    assert materials.emitted(front) == (True, ALBEDO)
    assert materials.emitted(back) == (False, (0.0, 0.0, 0.0))
    assert not materials.scatters(front) and not materials.delta(front)
    wis, weights, pdfs, _, _ = _samples(front, (0.0, 0.0, 1.0), 10, 1)
    assert (pdfs == 0).all()


# Estimators ask what a kind is through its flags (materials/flags.py), never
# its kind: each kind's flags must say what its own functions do.
@pytest.mark.parametrize("name", sorted(MATERIAL_TAGS))
def test_each_kinds_flags_say_what_its_functions_do(name):
    from rtweekend.path.materials import DELTA, EMITS, FORKS, JOIN, MEDIUM, PHOTON
    kind = np.int64(MATERIAL_TAGS[name])
    for flag in (DELTA, EMITS, FORKS, JOIN, MEDIUM, PHOTON):
        assert materials.kind_has(name, flag) == materials.has(kind, flag)
    has = lambda flag: materials.kind_has(name, flag)  # noqa: E731
    if has(MEDIUM):                 # a volume's phase function (media.py): no surface
        assert name == "isotropic" and has(JOIN) and not has(DELTA | EMITS | PHOTON | FORKS)
        return
    param = {"dielectric": 1.5, "rough_conductor": 0.3,           # metal: a mirror
             "rough_dielectric": (1.5, 0.3)}.get(name, 0.0)
    n, wo = (0.0, 0.0, 1.0), _unit((0.3, -0.2, 0.9))
    bsdf = _bsdf(kind, n, param)
    assert materials.delta(bsdf) == has(DELTA)
    assert materials.scatters(bsdf) == (not has(EMITS))
    assert materials.emitted(bsdf)[0] == has(EMITS)
    wis, _, pdfs, _, evals = _samples(bsdf, wo, 2000, 3)
    evaluated = (evals > 0).any() and (_pdfs(bsdf, wo, wis) > 0).any()
    assert has(JOIN) == evaluated       # a join needs f and its density
    assert not has(PHOTON) or evaluated
    if has(DELTA):                      # one direction, or both of branches()
        drawn = {tuple(w) for w in wis[pdfs > 0]}
        assert len(drawn) == (2 if has(FORKS) else 1)
        if has(FORKS):
            first, second, chance = materials.branches(bsdf, tuple(-c for c in wo))
            assert drawn == {first, second} and 0.0 < chance < 1.0
    else:
        assert not has(FORKS)


def _above(n, count, seed):
    """count unit directions above the surface of normal n."""
    d = _isotropic(count, seed)
    return d * np.sign(d @ np.asarray(n))[:, None]


@pytest.mark.parametrize("n", NORMALS)
@pytest.mark.parametrize("name, params", _smooth_cases())
def test_a_smooth_material_is_reciprocal(name, params, n):
    # f(wo, wi) = f(wi, wo), f = eval / |cos theta_i|: light and importance
    # see the same material (bdpt joins it both ways).
    padded = (*map(float, params), *(0.0,) * (2 - len(params)))
    bsdf = Bsdf(np.int64(MATERIAL_TAGS[name]), ALBEDO, padded, _unit(n), True, _unit(n), True)
    a, b = _above(bsdf.n, 2000, 1), _above(bsdf.n, 2000, 2)
    nn = np.asarray(bsdf.n)
    e = _eval_pairs(bsdf, a, b, 1.0)
    np.testing.assert_allclose(e[:, 0] / (b @ nn), e[:, 1] / (a @ nn), rtol=1e-9, atol=1e-300)
    assert (e[:, 0] > 0).mean() > 0.5


def test_a_nearly_smooth_rough_conductor_stays_finite_and_mirrors():
    # alpha towards 0: large densities, but finite, and the draws gather at
    # the mirror direction with weight albedo (G1 -> 1), as the books' metal.
    n, wo = (0.0, 0.0, 1.0), _unit((0.6, 0.0, 0.8))
    bsdf = Bsdf(np.int64(MATERIAL_TAGS["rough_conductor"]), ALBEDO, (1e-4, 0.0), n, True, n,
                True)
    wis, weights, pdfs, _, evals = _samples(bsdf, wo, 4000, 7)
    assert np.isfinite(weights).all() and np.isfinite(pdfs).all() and np.isfinite(evals).all()
    kept = pdfs > 0
    assert kept.mean() > 0.999
    angle = np.arccos(np.clip(wis[kept] @ np.array([-0.6, 0.0, 0.8]), -1, 1))
    assert np.median(angle) < 1e-3 and angle.max() < 0.1
    np.testing.assert_allclose(weights[kept], np.broadcast_to(ALBEDO, weights[kept].shape),
                               rtol=1e-3)
    np.testing.assert_allclose(weights[kept], evals[kept] / pdfs[kept, None], rtol=1e-6)


# -- rough glass (rough_dielectric.py) ------------------------------------------

def _rough_glass(n, ior, alpha, front=True):
    return Bsdf(np.int64(MATERIAL_TAGS["rough_dielectric"]), (1.0, 1.0, 1.0),
                (float(ior), float(alpha)), _unit(n), front, _unit(n), True)


def test_the_exact_fresnel_reflectance():
    from rtweekend.path.materials import rough_dielectric
    for eta in (1.5, 1.33, 1 / 1.5):
        f, cos_t = rough_dielectric.fresnel(1.0, eta)          # normal incidence
        assert f == pytest.approx(((eta - 1) / (eta + 1)) ** 2, rel=1e-12) and cos_t == 1.0
    # Brewster's angle: the p-polarised half vanishes, F = rs^2 / 2
    eta = 1.5
    cos_b = math.cos(math.atan(eta))
    f, cos_t = rough_dielectric.fresnel(cos_b, eta)
    sin_t = math.sqrt(1 - cos_b ** 2) / eta
    assert cos_t == pytest.approx(math.sqrt(1 - sin_t ** 2), rel=1e-12)
    rs = (cos_b - eta * cos_t) / (cos_b + eta * cos_t)
    assert f == pytest.approx(rs * rs / 2, rel=1e-12)
    # past the critical angle from inside: total internal reflection
    assert rough_dielectric.fresnel(0.5, 1 / 1.5) == (1.0, 0.0)


@pytest.mark.parametrize("n", NORMALS)
@pytest.mark.parametrize("ior, alpha", [(1.5, 0.2), (1.33, 0.7)])
def test_rough_glass_is_reciprocal_with_the_squeeze_of_radiance(n, ior, alpha):
    # f(wo, wi) / eta_wo^2 = f(wi, wo) / eta_wi^2 (Veach's thesis, 5.2),
    # f = eval / |cos theta_i|, each side's record with its normal on its own
    # wo's side; the adjoint's factor 1 / eta^2 on the way out of the glass
    # turns f(wi, wo) back into f(wo, wi).
    outside, inside = _rough_glass(n, ior, alpha), _rough_glass(
        tuple(-c for c in _unit(n)), ior, alpha, front=False)
    nn = np.asarray(outside.n)
    a, b = _above(nn, 3000, 1), -_above(nn, 3000, 2)       # a outside, b inside
    e_ab = _eval_pairs_with(outside, inside, a, b)
    f_ab, f_ba = e_ab[:, 0] / np.abs(b @ nn), e_ab[:, 1] / np.abs(a @ nn)
    assert (f_ab > 0).mean() > 0.1           # into glass: only within a cone
    np.testing.assert_allclose(f_ab * ior ** 2, f_ba, rtol=1e-7, atol=1e-14)
    adj = np.array([materials.adjoint(inside, tuple(y), tuple(x)) for x, y in zip(a[:50], b)])
    np.testing.assert_allclose(adj, 1 / ior ** 2, rtol=1e-12)
    assert materials.adjoint(outside, tuple(a[0]), tuple(a[1])) == 1.0


@njit
def _eval_pairs_with(front, back, a, b):
    """eval(front, a -> b) and eval(back, b -> a), first channel."""
    out = np.empty((a.shape[0], 2))
    for i in range(a.shape[0]):
        x, y = (a[i, 0], a[i, 1], a[i, 2]), (b[i, 0], b[i, 1], b[i, 2])
        att, s = materials.eval(front, x, y, 1.0)
        out[i, 0] = att[0] * s
        att, s = materials.eval(back, y, x, 1.0)
        out[i, 1] = att[0] * s
    return out


@pytest.mark.parametrize("front", [True, False])
@pytest.mark.parametrize("cos_in", [0.95, 0.5, 0.15])
def test_nearly_smooth_rough_glass_is_the_exact_fresnel_glass(front, cos_in):
    # alpha towards 0: finite, reflecting with the exact Fresnel chance,
    # refracting by Snell's law with weight 1 / eta^2 (radiance squeezed).
    from rtweekend.path.materials import rough_dielectric
    ior, n = 1.5, (0.0, 0.0, 1.0)
    wo = (math.sqrt(1 - cos_in ** 2), 0.0, cos_in)
    bsdf = _rough_glass(n, ior, 1e-4, front)
    wis, weights, pdfs, _, evals = _samples(bsdf, wo, 20_000, 4)
    assert np.isfinite(weights).all() and np.isfinite(pdfs).all() and np.isfinite(evals).all()
    kept = pdfs > 0
    assert kept.mean() > 0.999
    reflected = wis[:, 2] > 0
    eta = ior if front else 1 / ior
    p, _ = rough_dielectric.fresnel(cos_in, eta)
    sigma = math.sqrt(max(p * (1 - p), 1e-12) / len(wis))
    assert abs(reflected.mean() - p) <= 5 * sigma + 1e-3
    # GGX has long tails: most draws within 1e-3 of the smooth glass's
    # directions, weights its (1; 1 / eta^2 refracted)
    refl = wis[kept & reflected]
    mirror = np.array([-wo[0], -wo[1], wo[2]])
    assert np.median(np.arccos(np.clip(refl @ mirror, -1, 1))) < 1e-3
    np.testing.assert_allclose(np.median(weights[kept & reflected], axis=0), 1.0, rtol=1e-4)
    if p < 1:
        t = wis[kept & ~reflected]
        sin_t = np.hypot(t[:, 0], t[:, 1])
        assert np.median(np.abs(sin_t - math.sqrt(1 - cos_in ** 2) / eta)) < 1e-3
        np.testing.assert_allclose(np.median(weights[kept & ~reflected], axis=0), 1 / eta ** 2,
                                   rtol=1e-4)


@pytest.mark.parametrize("front", [True, False])
@pytest.mark.parametrize("alpha", [0.05, 0.3, 1.0])
def test_rough_glass_loses_no_more_than_single_scattering_does(front, alpha):
    # A white furnace of one bounce: the mean of sample's weight, times eta^2
    # where it refracts (energy, not radiance), is the integral of eval (so
    # times) over the sphere, which is at most 1 (energy is not made) and 1
    # for a smooth glass (the draws that leave on the wrong side and G1 < 1
    # are what single scattering loses as it roughens).
    ior = 1.5
    bsdf = _rough_glass((0.0, 0.0, 1.0), ior, alpha, front)
    eta = ior if front else 1 / ior
    wo = _unit((0.5, 0.2, 0.8))
    wis, weights, pdfs, _, _ = _samples(bsdf, wo, 40_000, 6)
    energy = weights[:, 0] * np.where(wis[:, 2] < 0, eta * eta, 1.0) * (pdfs > 0)
    mean, se = energy.mean(), energy.std() / math.sqrt(len(energy))

    def kept(d):
        e = _evals(bsdf, wo, d)
        return e * np.where(d[:, 2] < 0, eta * eta, 1.0)
    integral = _integrated(kept, _frame(bsdf.n)).sum()
    assert abs(mean - integral) < 4 * se + 1e-4
    assert integral <= 1 + 1e-4
    if alpha == 0.05:
        assert integral > 0.98


@njit
def _evals(bsdf, wo, dirs):
    out = np.empty(dirs.shape[0])
    for i in range(dirs.shape[0]):
        att, s = materials.eval(bsdf, wo, (dirs[i, 0], dirs[i, 1], dirs[i, 2]), 1.0)
        out[i] = att[0] * s
    return out
