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
    return Bsdf(np.int64(kind), ALBEDO, (float(param), 0.0), _unit(n), front, _unit(n), True)


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
    (one jittered point per sub-cell)."""
    frame = _frame(n)
    local = dirs @ frame.T
    cos_t = np.clip(local[:, 2], -1, 1 - 1e-15)
    phi = np.mod(np.arctan2(local[:, 1], local[:, 0]), 2 * math.pi)
    i = ((cos_t + 1) / 2 * COS_BINS).astype(int)
    j = np.minimum((phi / (2 * math.pi) * PHI_BINS).astype(int), PHI_BINS - 1)
    observed = np.bincount(i * PHI_BINS + j, minlength=COS_BINS * PHI_BINS)
    jitter = np.random.default_rng(5).random((2, COS_BINS * SUB, PHI_BINS * SUB))
    c = (np.arange(COS_BINS * SUB)[:, None] + jitter[0]) / (COS_BINS * SUB) * 2 - 1
    p = (np.arange(PHI_BINS * SUB)[None, :] + jitter[1]) / (PHI_BINS * SUB) * 2 * math.pi
    s = np.sqrt(1 - c ** 2)
    grid = np.stack([s * np.cos(p), s * np.sin(p), c], -1).reshape(-1, 3) @ frame
    d_omega = 4 * math.pi / (COS_BINS * SUB * PHI_BINS * SUB)
    per_bin = density(np.ascontiguousarray(grid)).reshape(COS_BINS, SUB, PHI_BINS, SUB)
    return observed, per_bin.sum(axis=(1, 3)).ravel() * d_omega


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
SMOOTH = {"lambertian": [()], "rough_conductor": [(0.1,), (0.4,), (1.0,)]}
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
    param = {"dielectric": 1.5, "rough_conductor": 0.3}.get(name, 0.0)   # metal: a mirror
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
