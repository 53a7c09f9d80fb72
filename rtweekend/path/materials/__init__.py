"""Materials: what a surface emits, and how it scatters, evaluated and sampled.

mat_i[m] = kind; mat_f[m] = colour (MAT_COLOR, 0:3), parameters (MAT_PARAMS,
N_PARAMS of them: Bsdf.params), each kind's named by its module
  LAMBERTIAN    colour = albedo                          lambertian.py
  METAL         colour = albedo, FUZZ                    metal.py
  DIELECTRIC    IOR (index of refraction)                dielectric.py
  DIFFUSE_LIGHT colour = emitted radiance, front face only  diffuse_light.py
  ISOTROPIC     colour = albedo, DENSITY: a constant medium's phase function
                                                         isotropic.py (media.py)
  ROUGH_CONDUCTOR colour = albedo, ALPHA (GGX roughness)  rough_conductor.py
  ROUGH_DIELECTRIC IOR, ALPHA (GGX roughness)             rough_dielectric.py

An estimator makes the material's record at a hit once, `bsdf = at(scene,
hit)` (its kind, colour there, parameter and shading normal: no array is read
after that), and asks it, never its kind; what a kind is (delta, emits, may be
joined, keeps photons, forks, a medium's) it asks as has(bsdf.kind, flag),
each kind's module declaring its FLAGS (flags.py):

  emitted(bsdf)                  -> (emits, radiance)
  scatters(bsdf), delta(bsdf)    does it scatter; is it sampled only
  sample(bsdf, wo, smp)          -> (wi, weight, pdf, delta, smp)
     sample_by_turns              the same, the lobe by kernel/trig.py (bdpt's)
     sample_at(bsdf, wo, u1, u2, smp) -> (wi, weight, pdf, smp): a smooth one, for a
                                  given point (smp: for a lobe's choice)
     sample_delta(bsdf, wo, smp)  the delta ones
  eval(bsdf, wo, wi, scale)      -> (attenuation, scattering)
  pdf(bsdf, wo, wi)              -> density of wi (solid angle)
  reverse_pdf(bsdf, wo, wi)      -> density of wo, having come from wi
  branches(bsdf, d)              -> both directions of one that FORKS
  adjoint(bsdf, wo, wi)          -> factor on sample's weight for a light subpath
  eval_adjoint(bsdf, wo, wi)     -> factor on eval for a light subpath's connection:
                                    the shading normal's (shading_adjoint) and a
                                    glossy refraction's

Directions point away from the surface: wo towards where the light goes (the
camera side, -d for a ray along d), wi the other direction of the pair.  The
record's normal is the shading normal on wo's side (Surface.n; a smooth mesh's
interpolated vertex normal, else the geometric one, ng), its colour the
material's at the hit (Surface.albedo: textured or not).  Where the two
normals differ, a lambertian scatters only to directions on the true surface's
side too (`behind`): the shading normal alone would let light through it.

eval returns f(wo, wi) |cos theta_i| as attenuation x scattering: the books'
attenuation (an RGB) and their scattering_pdf (a number), the way their
integrator multiplies them; `scale` (an estimator's weight such as MIS, 1
otherwise) is multiplied into the number before the material's own constants,
so that the arithmetic, and the bits, are the books'.  sample's weight is
f |cos| / pdf; for a smooth material it equals eval's product over pdf.

Delta materials (metal, dielectric) have no density to evaluate: sample
returns delta = True and pdf = 1, eval and pdf return 0.  An estimator follows
their direction with its weight and must not connect a path to them or weigh
them by MIS (they are what the books call skip_pdf).  pdf = 0 from sample means
the material gave no direction (a fuzzed metal ray below the surface, a light):
the path ends.
"""
from typing import NamedTuple

import numpy as np

from ...kernel import sampler
from ...kernel.jit import jit_step
from ...kernel.vec3 import dot
from ..layout import MAT_COLOR, MAT_PARAMS, N_PARAMS, OBJ_MAT
from . import dielectric, diffuse_light, isotropic, lambertian, metal, rough_conductor
from . import rough_dielectric
from .flags import DELTA, EMITS, FORKS, GLOSSY, JOIN, MEDIUM, PHOTON, REFRACTS  # noqa: F401

# The kinds by the description's names (scene/materials.py), each its module;
# a kind's tag (mat_i) is its place here.
KINDS = {"lambertian": lambertian, "metal": metal, "dielectric": dielectric,
         "diffuse_light": diffuse_light, "isotropic": isotropic,
         "rough_conductor": rough_conductor, "rough_dielectric": rough_dielectric}
MATERIAL_TAGS = {name: tag for tag, name in enumerate(KINDS)}
LAMBERTIAN, METAL, DIELECTRIC = (MATERIAL_TAGS[k] for k in ("lambertian", "metal", "dielectric"))
DIFFUSE_LIGHT, ISOTROPIC = MATERIAL_TAGS["diffuse_light"], MATERIAL_TAGS["isotropic"]
ROUGH_CONDUCTOR, ROUGH_DIELECTRIC = (MATERIAL_TAGS[k] for k in ("rough_conductor",
                                                                  "rough_dielectric"))
# Each kind's flags (flags.py), by its tag: what estimators ask through has().
KIND_FLAGS = np.array([module.FLAGS for module in KINDS.values()], dtype=np.int64)

NO_COLOR = (0.0, 0.0, 0.0)
NO_DIRECTION = (0.0, 0.0, 0.0)
NO_PARAMS = (0.0,) * N_PARAMS


@jit_step
def has(kind, flag):
    """Is `flag` (flags.py) one of material kind `kind`'s?  The question an
    estimator asks of a hit's material (bsdf.kind) or a vertex's."""
    return (KIND_FLAGS[kind] & flag) != 0


@jit_step
def kind_of(scene, k):
    """The kind of object k's material."""
    return scene.mat_i[scene.obj_i[k, OBJ_MAT]]


@jit_step
def smooth_ior(scene, m):
    """The index of refraction of material m if it is a smooth interface that
    refracts (REFRACTS: the books' glass), else 0."""
    if has(scene.mat_i[m], REFRACTS):
        return scene.mat_f[m, MAT_PARAMS + dielectric.IOR]
    return 0.0


@jit_step
def smooth_transmittance(d, n_out, ior):
    """What a ray along d carries across such an interface (outward normal
    n_out) by the books' rule, 0 under total internal reflection."""
    return dielectric.transmittance(d, n_out, ior)


def objects_with(obj_i, mat_i, flag):
    """Which packed objects' materials have `flag` (a bool per row of obj_i)."""
    return (KIND_FLAGS[mat_i[obj_i[:, OBJ_MAT]]] & flag) != 0


def kind_has(name, flag):
    """has() for a scene's material kind by its name ("metal"); False for a
    name the path tracer has no tag for (the classic tracer's)."""
    tag = MATERIAL_TAGS.get(name)
    return tag is not None and bool(KIND_FLAGS[tag] & flag)


class Bsdf(NamedTuple):
    """A material at one hit: what its functions read."""
    kind: np.int64         # LAMBERTIAN, METAL, ... (MATERIAL_TAGS above)
    albedo: tuple          # its colour there (emitted radiance for a light)
    params: tuple          # N_PARAMS floats: the kind's parameters (its module names them)
    n: tuple               # the shading normal, on the incoming ray's side
    front: bool            # the ray met the front side
    ng: tuple              # the geometric normal, on the incoming ray's side
    glossy: object         # the scene's SceneArrays.glossy: None, no glossy kind to ask


@jit_step
def color(scene, m):
    """Material m's colour (albedo or emitted radiance) where it has no texture;
    a textured one's is looked up at the hit (textures.py)."""
    f = scene.mat_f
    return (f[m, MAT_COLOR], f[m, MAT_COLOR + 1], f[m, MAT_COLOR + 2])


@jit_step
def at(scene, hit):
    """The Bsdf of the surface record `hit` (surface.py)."""
    m = hit.mat
    ng = hit.n_out if hit.front else (-hit.n_out[0], -hit.n_out[1], -hit.n_out[2])
    return Bsdf(scene.mat_i[m], hit.albedo, packed_params(scene.mat_f, m), hit.n, hit.front,
                ng, scene.glossy)


@jit_step
def packed_params(mat_f, m):
    """Material m's parameters as pack.py wrote them (Bsdf.params)."""
    return (mat_f[m, MAT_PARAMS], mat_f[m, MAT_PARAMS + 1])


@jit_step
def emitted(bsdf):
    """(emits, radiance): a diffuse light emits its colour from its front side."""
    if bsdf.kind == DIFFUSE_LIGHT and bsdf.front:
        return True, bsdf.albedo
    return False, NO_COLOR


@jit_step
def emitted_by(scene, m, front, color):
    """emitted() of material m with colour `color` at a point seen from its front
    side or not (a point sampled on a light: no whole record needed)."""
    return emitted(Bsdf(scene.mat_i[m], color, NO_PARAMS, NO_DIRECTION, front, NO_DIRECTION,
                        None))


@jit_step
def scatters(bsdf):
    """Does light scatter there (a light only emits)?"""
    return bsdf.kind != DIFFUSE_LIGHT


@jit_step
def delta(bsdf):
    """Is it sampled only, never evaluated (metal, dielectric)?"""
    return bsdf.kind == METAL or bsdf.kind == DIELECTRIC


@jit_step
def sample(bsdf, wo, smp):
    """(wi, weight, pdf, delta, smp): a direction drawn by the material's own
    sampling; pdf 0: none (the path ends).  What it draws: a smooth material
    the next 2-D point of the sampler (sample_at), a delta one what
    sample_delta says."""
    if delta(bsdf):
        return sample_delta(bsdf, wo, smp)
    u1, u2, smp = sampler.next_2d(smp)
    wi, weight, p, smp = sample_at(bsdf, wo, u1, u2, smp)
    return wi, weight, p, False, smp


@jit_step
def sample_delta(bsdf, wo, smp):
    """sample() of a delta material: dielectric draws one number of the stream,
    metal with fuzz three (pdf 0: the fuzz pushed the ray below the surface,
    where the books absorb it)."""
    d = (-wo[0], -wo[1], -wo[2])
    if bsdf.kind == METAL:
        wi, ok, state = metal.scatter(d, bsdf.n, bsdf.params[metal.FUZZ], smp.state)
        return wi, bsdf.albedo, 1.0 if ok else 0.0, True, sampler.resume(smp, state)
    if bsdf.kind == DIELECTRIC:
        u, smp = sampler.fork(smp)
        return dielectric.scatter_at(d, bsdf.n, bsdf.front, bsdf.params[dielectric.IOR], u), \
            bsdf.albedo, \
            1.0, True, smp
    # Not a delta material: no direction.
    return NO_DIRECTION, NO_COLOR, 0.0, True, smp


@jit_step
def sample_by_turns(bsdf, wo, smp):
    """sample(), but a lambertian's direction drawn by
    lambertian.cosine_lobe (kernel/trig.py's cosine and sine: no libm call;
    bidirectional path tracing's draws, bit for bit its own)."""
    if bsdf.kind == LAMBERTIAN:
        u1, u2, smp = sampler.next_2d(smp)
        wi = lambertian.cosine_lobe(bsdf.n, u1, u2)
        wi, weight, p = smooth_drawn(bsdf, wi, bsdf.albedo, lambertian.cosine_pdf(bsdf.n, wi))
        return wi, weight, p, False, smp
    return sample(bsdf, wo, smp)


@jit_step
def branches(bsdf, d):
    """The two directions of a material that FORKS (flags.py), for a ray along
    d: (first, second, the chance sample_delta takes the first); a dielectric's
    reflection and refraction (under total internal reflection both are the
    reflection, chance 1)."""
    return dielectric.branches(d, bsdf.n, bsdf.front, bsdf.params[dielectric.IOR])


@jit_step
def adjoint(bsdf, wo, wi):
    """What a subpath that carries light (not the camera's importance) multiplies
    sample's weight by, for light arriving along -wo and leaving along wi: 1 but
    at a refraction (dielectric.adjoint_weight).  Without it a light inside glass
    of index 1.5 comes out 2.25 times too dim; through a ball (in and out at the
    same angle) the factors cancel."""
    a = 1.0
    if bsdf.kind == DIELECTRIC and dot(wi, bsdf.n) < 0.0:    # through the surface
        a = dielectric.adjoint_weight(dot(wo, bsdf.n), -dot(wi, bsdf.n), bsdf.front,
                                      bsdf.params[dielectric.IOR])
    return a * glossy_adjoint(bsdf.glossy, bsdf, wo, wi) * shading_adjoint(bsdf, wo, wi)


@jit_step
def eval_adjoint(bsdf, wo, wi):
    """What a light subpath's connection multiplies eval by, for light arriving
    along -wo and leaving along wi: eval is the camera's f (radiance), and a
    refraction's is not symmetric (a glossy one's: its module's adjoint), nor
    is a shading normal (shading_adjoint).  Exactly 1 elsewhere."""
    return glossy_adjoint(bsdf.glossy, bsdf, wo, wi) * shading_adjoint(bsdf, wo, wi)


@jit_step
def behind(bsdf, wi):
    """Is wi on the far side of the true surface (the geometric normal ng, on
    wo's side) where the shading normal differs from it (a smooth mesh)?  The
    shading normal's hemisphere may reach below the triangle; a ray leaving
    there passes through it (it skips its own triangle), so a lambertian that
    scattered there would let a light behind the surface light its front.
    Such directions are absorbed (pbrt-v3's BSDF::f does the same).  False
    where n is ng: every other surface keeps its arithmetic and its bits."""
    return bent_normal(bsdf) and dot(wi, bsdf.ng) <= 0.0


@jit_step
def crosses_wrongly(bsdf, wi):
    """behind() for a material that refracts: where the shading normal is
    bent, is wi on one side of it and the other of the true surface (a
    reflection that would leave through the triangle, a refraction that would
    not cross it)?"""
    return bent_normal(bsdf) and (dot(wi, bsdf.n) > 0.0) != (dot(wi, bsdf.ng) > 0.0)


@jit_step
def bent_normal(bsdf):
    """Does its shading normal differ from the geometric one (a smooth mesh)?"""
    n, ng = bsdf.n, bsdf.ng
    return n[0] != ng[0] or n[1] != ng[1] or n[2] != ng[2]


@jit_step
def shading_adjoint(bsdf, wo, wi):
    """What light arriving along -wo and leaving along wi takes beside f |cos|
    where the shading normal n is not the geometric ng (a smooth mesh):
    |wo.n| |wi.ng| / (|wo.ng| |wi.n|), which makes a subpath that carries
    light see the same surface as one that carries importance (Veach's thesis
    5.3).  Exactly 1 where n is ng: every other surface."""
    if not bent_normal(bsdf):
        return 1.0
    n, ng = bsdf.n, bsdf.ng
    den = abs(dot(wo, ng)) * abs(dot(wi, n))
    if den == 0.0:
        return 0.0                      # grazing: no light, and no infinity
    return abs(dot(wo, n)) * abs(dot(wi, ng)) / den


@jit_step
def sample_at(bsdf, wo, u1, u2, smp):
    """(wi, weight, pdf, smp) of a smooth material's sampling for the 2-D point
    (u1, u2) (the mixture's share of it: pdf.py); delta materials have none.
    A kind with two lobes (a rough glass's reflection and refraction) picks
    one with a number of smp's stream, as the books' glass does."""
    if bsdf.kind == LAMBERTIAN:
        wi, weight, p = lambertian.sample(bsdf, wo, u1, u2)
        wi, weight, p = smooth_drawn(bsdf, wi, weight, p)
        return wi, weight, p, smp
    return glossy_sample(bsdf.glossy, bsdf, wo, u1, u2, smp)


@jit_step
def smooth_drawn(bsdf, wi, weight, p):
    """A smooth material's draw, absorbed where it leaves below the true
    surface (behind), as its pdf says."""
    if behind(bsdf, wi):
        return wi, NO_COLOR, 0.0
    return wi, weight, p


@jit_step
def eval(bsdf, wo, wi, scale):
    """(attenuation, scattering): their product is scale x f(wo, wi) |cos theta_i|
    (0 for delta materials and lights)."""
    if bsdf.kind == LAMBERTIAN:
        if behind(bsdf, wi):
            return bsdf.albedo, 0.0
        return lambertian.eval(bsdf, wo, wi, scale)
    return glossy_eval(bsdf.glossy, bsdf, wo, wi, scale)


@jit_step
def pdf(bsdf, wo, wi):
    """Solid-angle density of wi under sample() given wo (0 for delta materials);
    pdf(bsdf', wi, wo), with the normal on wi's side, is the reverse density."""
    if bsdf.kind == LAMBERTIAN:
        if behind(bsdf, wi):
            return 0.0
        return lambertian.pdf(bsdf, wo, wi)
    return glossy_pdf(bsdf.glossy, bsdf, wo, wi)


@jit_step
def reverse_pdf(bsdf, wo, wi):
    """The density of wo drawn having come from wi (a bidirectional walk's
    reverse density): pdf with the record turned to wi's side where wi went
    through the surface (a rough glass's refraction)."""
    return pdf(turned(bsdf, wi), wi, wo)


@jit_step
def turned(bsdf, w):
    """The record as seen from direction w: its normals on w's side, its front
    the other where w is on the far side of the true surface (only a glossy
    kind refracts: otherwise the record itself)."""
    if not any_glossy(bsdf.glossy) or dot(w, bsdf.ng) >= 0.0:
        return bsdf
    n, ng = bsdf.n, bsdf.ng
    return Bsdf(bsdf.kind, bsdf.albedo, bsdf.params, (-n[0], -n[1], -n[2]), not bsdf.front,
                (-ng[0], -ng[1], -ng[2]), bsdf.glossy)


# The glossy kinds' functions (flags.GLOSSY), each behind `glossy`: None in a
# scene without one, and Numba prunes the rest of the function before typing
# it, so that scene's kernels hold none of their code.

@jit_step
def glossy_sample(glossy, bsdf, wo, u1, u2, smp):
    if glossy is None:
        return NO_DIRECTION, NO_COLOR, 0.0, smp
    if bsdf.kind == ROUGH_CONDUCTOR:
        wi, weight, p = rough_conductor.sample(bsdf, wo, u1, u2)
        wi, weight, p = smooth_drawn(bsdf, wi, weight, p)
        return wi, weight, p, smp
    if bsdf.kind == ROUGH_DIELECTRIC:
        u, smp = sampler.uniform(smp)
        wi, weight, p = rough_dielectric.sample(bsdf, wo, u1, u2, u)
        if crosses_wrongly(bsdf, wi):
            return wi, NO_COLOR, 0.0, smp
        return wi, weight, p, smp
    return NO_DIRECTION, NO_COLOR, 0.0, smp


@jit_step
def glossy_eval(glossy, bsdf, wo, wi, scale):
    if glossy is None:
        return NO_COLOR, 0.0
    if bsdf.kind == ROUGH_CONDUCTOR:
        if behind(bsdf, wi):
            return bsdf.albedo, 0.0
        return rough_conductor.eval(bsdf, wo, wi, scale)
    if bsdf.kind == ROUGH_DIELECTRIC:
        if crosses_wrongly(bsdf, wi):
            return bsdf.albedo, 0.0
        return rough_dielectric.eval(bsdf, wo, wi, scale)
    return NO_COLOR, 0.0


@jit_step
def glossy_pdf(glossy, bsdf, wo, wi):
    if glossy is None:
        return 0.0
    if bsdf.kind == ROUGH_CONDUCTOR:
        if behind(bsdf, wi):
            return 0.0
        return rough_conductor.pdf(bsdf, wo, wi)
    if bsdf.kind == ROUGH_DIELECTRIC:
        if crosses_wrongly(bsdf, wi):
            return 0.0
        return rough_dielectric.pdf(bsdf, wo, wi)
    return 0.0


@jit_step
def glossy_adjoint(glossy, bsdf, wo, wi):
    if glossy is None:
        return 1.0
    if bsdf.kind == ROUGH_CONDUCTOR:
        return rough_conductor.adjoint(bsdf, wo, wi)
    if bsdf.kind == ROUGH_DIELECTRIC:
        return rough_dielectric.adjoint(bsdf, wo, wi)
    return 1.0


@jit_step
def is_glossy(bsdf):
    """Is the record's kind a glossy one (flags.GLOSSY)?  False, compiled away,
    in a scene without one."""
    return any_glossy(bsdf.glossy) and has(bsdf.kind, GLOSSY)


@jit_step
def any_glossy(glossy):
    """Has the scene a glossy kind (SceneArrays.glossy)?  A constant, for a
    test that a scene without one compiles away."""
    if glossy is None:
        return False
    return True
