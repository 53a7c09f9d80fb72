"""The vertices of bidirectional path tracing's two subpaths (Veach's thesis
ch. 10; pbrt-v4's Vertex), kept in two arrays per subpath so that a strategy
can join any camera vertex to any light vertex.

Row i of `vf` (floats) and `vi` (integers) is vertex i:

  P      the point                       TYPE   CAMERA, LIGHT, SURFACE, MEDIUM
  NG     the outward geometric normal    OBJ    its object (NO_HIT: camera, medium)
         (0 for the camera and media)    MKIND  its material's kind (layout.py)
  BETA   the subpath's throughput up     DELTA  1: a delta material (metal, glass):
         to it (as pbrt's beta)                 sampled, never connected
  COLOR  its albedo there (a light's emitted radiance)
  PARAMS its material's parameters (materials.Bsdf.params)
  FWD    the area density of this vertex as its own subpath drew it
  REV    the area density of it drawn the other way, from the next vertex (MIS)
         (a delta vertex drawn from a smooth one: per projected solid angle, below)
  ACC    the MIS weights' running sum up to it, set once the subpath is drawn
         (mis.accumulate)
  WO     the unit direction from it to the vertex before (0 at vertex 0)
  BACK   what turns a solid-angle density at it towards the vertex before into
         that vertex's density (area_factor, or projected; 0 at vertex 0)
  NS     the shading normal on NG's side (NG itself but on a smooth mesh)

A vertex answers, for a pair of directions leaving it (wo towards where its
light goes or comes from, wi the other): `scatter` = f(wo, wi) |cos theta_i|
(the phase function at a medium, the emitted radiance times its cosine at a
light) and `direction_pdf` = the solid-angle density of wi.  `area_factor`
turns a solid-angle density at one vertex into the area density of the next:
times |cos| at the next if it lies on a surface, over the distance squared; put
stores each vertex's WO and BACK towards the vertex before, which every
strategy joined at it needs, so they are worked out once per vertex.  The
material at a surface vertex is rebuilt from its row with its normal turned to
wo's side, which is how the books make every material two-sided.

Delta chains.  A strategy that moves a chain of delta vertices (glass, metal)
from one subpath to the other multiplies the MIS ratios of every vertex of it,
and only the first of each direction is drawn from a smooth vertex: the rest
follow by reflection or refraction (density 0, read as 1 by mis.ratio).  In
area measure those two densities carry the geometry of the chain's first
segment only -- 1 / distance^2 to the nearest glass --, so a floor point a few
units under a glass ball made the camera's random hits on the light through
the ball look far likelier than light tracing's caustic, and took the
weight (bdpt was far noisier there than light tracing alone:
benchmarks/results/measurements.md).  The densities the
two ways really compare in are per projected solid angle at the smooth end
vertices: the chain's generalised geometry term (Hanika et al. 2015, manifold
next-event estimation) is the same both ways and cancels.  So a delta vertex
drawn from a smooth vertex stores its density per projected solid angle at
that vertex (pdf / |cos|; `projected`), both as FWD and as REV (through BACK).
"""
import math

from ...kernel.jit import jit_step
from ...kernel.vec3 import dot
from .. import camera, materials
from ..materials import JOIN, Bsdf, isotropic

# Columns of vf.
P, NG, BETA, COLOR, PARAMS, FWD, REV, ACC, WO, BACK, NS = 0, 3, 6, 9, 12, 14, 15, 16, 17, 20, 21
NF = 24
# Columns of vi.
TYPE, OBJ, MKIND, DELTA = 0, 1, 2, 3
NI = 4
# Vertex types.
CAMERA, LIGHT, SURFACE, MEDIUM = 0, 1, 2, 3
INV_PI = 1.0 / math.pi
ZERO = (0.0, 0.0, 0.0)


@jit_step
def put(path, i, kind, p, normals, beta, color, params, obj, mkind, delta, density):
    """Write vertex i of path (its arrays: vf, vi), and its WO and BACK towards
    vertex i - 1 (its REV is set later, when the next vertex is drawn).
    normals: its geometric and shading normals (outward); density: vertex 0's
    area density, or the solid-angle density vertex i - 1 drew it with (FWD is
    its area density)."""
    vf, vi = path
    n, ns = normals
    wo, back, fwd = ZERO, 0.0, density
    if i > 0:
        wo, dist = toward(p, col(vf, i - 1, P))
        surface = kind == SURFACE or kind == LIGHT
        if vi[i - 1, DELTA] != 0:
            back = projected(wo, n, surface)
        else:
            back = area_factor(wo, dist, col(vf, i - 1, NG), on_surface(vi, i - 1))
        if delta:
            fwd = density * projected(wo, col(vf, i - 1, NG), on_surface(vi, i - 1))
        else:
            fwd = density * area_factor(wo, dist, n, surface)
    for c in range(3):
        vf[i, P + c] = p[c]
        vf[i, NG + c] = n[c]
        vf[i, NS + c] = ns[c]
        vf[i, BETA + c] = beta[c]
        vf[i, COLOR + c] = color[c]
        vf[i, WO + c] = wo[c]
    vf[i, PARAMS], vf[i, PARAMS + 1] = params            # (layout.N_PARAMS of them)
    vf[i, FWD] = fwd
    vf[i, REV] = 0.0
    vf[i, BACK] = back
    vi[i, TYPE] = kind
    vi[i, OBJ] = obj
    vi[i, MKIND] = mkind
    vi[i, DELTA] = 1 if delta else 0


@jit_step
def col(vf, i, c):
    return (vf[i, c], vf[i, c + 1], vf[i, c + 2])


@jit_step
def on_surface(vi, i):
    """Does vertex i lie on a surface (its area density has a cosine)?"""
    return vi[i, TYPE] == SURFACE or vi[i, TYPE] == LIGHT


@jit_step
def connectible(vi, i):
    """Can a strategy join a path to vertex i?  Not at a delta material, nor
    at a surface that only emits (it scatters nothing)."""
    if vi[i, TYPE] != SURFACE:
        return True
    return vi[i, DELTA] == 0 and materials.has(vi[i, MKIND], JOIN)


@jit_step
def toward(a, b):
    """(unit direction from a to b, distance)."""
    d = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    dist = math.sqrt(dot(d, d))
    return (d[0] / dist, d[1] / dist, d[2] / dist), dist


@jit_step
def bsdf_facing(glossy, vf, vi, i, wo):
    """The material at surface vertex i, its normals on wo's side (glossy: the
    scene's SceneArrays.glossy)."""
    ng, n = col(vf, i, NG), col(vf, i, NS)
    front = dot(wo, ng) > 0.0
    if not front:
        ng, n = (-ng[0], -ng[1], -ng[2]), (-n[0], -n[1], -n[2])
    return Bsdf(vi[i, MKIND], col(vf, i, COLOR), (vf[i, PARAMS], vf[i, PARAMS + 1]), n, front,
                ng, glossy)


@jit_step
def light_scatter(glossy, vf, vi, i, wo, wi):
    """scatter at vertex i of a light subpath, light arriving from wo and
    leaving along wi: at a smooth mesh's vertex or a glossy one's, times the
    adjoint's factor (materials.eval_adjoint: exactly 1 elsewhere)."""
    f = scatter(glossy, vf, vi, i, wo, wi)
    if vi[i, TYPE] == SURFACE and (materials.any_glossy(glossy)
                                   or vf[i, NS] != vf[i, NG] or vf[i, NS + 1] != vf[i, NG + 1]
                                   or vf[i, NS + 2] != vf[i, NG + 2]):
        a = materials.eval_adjoint(bsdf_facing(glossy, vf, vi, i, wo), wo, wi)
        f = (f[0] * a, f[1] * a, f[2] * a)
    return f


@jit_step
def scatter(glossy, vf, vi, i, wo, wi):
    """f(wo, wi) |cos theta_i| at vertex i as an RGB: a surface's material, a
    medium's phase function (no cosine), a light's radiance towards wi times
    its cosine (front side only)."""
    kind = vi[i, TYPE]
    if kind == SURFACE:
        att, f = materials.eval(bsdf_facing(glossy, vf, vi, i, wo), wo, wi, 1.0)
        return (att[0] * f, att[1] * f, att[2] * f)
    if kind == MEDIUM:
        f = isotropic.pdf()
        return (vf[i, COLOR] * f, vf[i, COLOR + 1] * f, vf[i, COLOR + 2] * f)
    if kind == LIGHT:
        c = dot(wi, col(vf, i, NG))
        if c > 0.0:
            return (vf[i, COLOR] * c, vf[i, COLOR + 1] * c, vf[i, COLOR + 2] * c)
    return ZERO


@jit_step
def direction_pdf(cam, glossy, vf, vi, i, wo, wi):
    """Solid-angle density of wi as vertex i draws its next direction (having
    been reached from wo): the camera's ray directions, a light's cosine lobe
    about its front, a material's sampling, the isotropic phase function."""
    kind = vi[i, TYPE]
    if kind == SURFACE:
        return materials.pdf(bsdf_facing(glossy, vf, vi, i, wo), wo, wi)
    if kind == MEDIUM:
        return isotropic.pdf()
    if kind == LIGHT:
        c = dot(wi, col(vf, i, NG))
        return c * INV_PI if c > 0.0 else 0.0
    return camera.pdf_direction(cam, wi)


@jit_step
def area_factor(w, dist, n_q, surface):
    """What turns a solid-angle density into the area density at the point q at
    `dist` along the unit direction w: |cos theta_q| / distance^2 (1 /
    distance^2 if q is in a medium or the camera)."""
    if surface:
        return abs(dot(w, n_q)) / (dist * dist)
    return 1.0 / (dist * dist)


@jit_step
def projected(w, n, surface):
    """What turns a solid-angle density at a point (normal n) into the density
    per projected solid angle there: 1 / |cos| (1 in a medium or the camera)."""
    if surface:
        c = abs(dot(w, n))
        return 1.0 / c if c > 0.0 else 0.0
    return 1.0


@jit_step
def back_density(cam, glossy, vf, vi, i, wi):
    """The area density of vertex i - 1 drawn from vertex i, which was reached
    along wi: its REV as a strategy joined at vertex i makes it."""
    return direction_pdf(cam, glossy, vf, vi, i, wi, col(vf, i, WO)) * vf[i, BACK]
