"""Materials as plain Python values, built the way the books' main.cc builds them:

    white = lambertian((.73, .73, .73))
    light = diffuse_light((15, 15, 15))

Each builder checks its fields and raises SceneError naming the material and the
field.  `kind` is the material's name as written in a scene file.
"""
from dataclasses import dataclass

from . import fields
from .fields import Color
from ..errors import FieldError, checked
from .textures import Texture, texture_or_color


@dataclass(frozen=True, eq=False)
class Material:
    kind: str             # "lambertian", "metal", ... (the builder's name)
    color: tuple          # albedo, or emitted radiance; phong: 0..255 colour
    param: float = 0.0    # metal: fuzz; (rough_)dielectric: ior; phong: specular exponent;
                          # isotropic: density
    name: str | None = None
    reflective: float = 0.0   # phong only: the mirror's share, in [0, 1]
    texture: object = None    # a Texture (textures.py) in place of `color`, or None
    alpha: float = 0.0        # rough_conductor, rough_dielectric: the GGX roughness

    @property
    def medium(self):
        """An isotropic medium's material: its shape is a volume's boundary."""
        return self.kind == "isotropic"


def _colour(value, field, hi=None):
    """(color, texture) of a colour-or-texture field: a texture keeps its mean
    as the colour (for anything that wants one number per channel)."""
    value = texture_or_color(value, field, hi=hi)
    if isinstance(value, Texture):
        return value.mean(), value
    return value, None


@checked("lambertian")
def lambertian(albedo: Color | Texture, *, name: str | None = None) -> Material:
    """albedo: a colour or a texture (textures.py)."""
    color, texture = _colour(albedo, "albedo", hi=1.0)
    return Material("lambertian", color, 0.0, name, texture=texture)


@checked("metal")
def metal(albedo: Color | Texture, fuzz: float = 0.0, *,
          name: str | None = None) -> Material:
    """The books' metal: reflects with colour `albedo`, the direction blurred by
    a random point of a sphere of radius `fuzz` (0: a mirror; clamped at 1)."""
    # The book clamps fuzz to 1; a negative fuzz is a mistake, not a clamp.
    fuzz = min(fields.number(fuzz, "fuzz", lo=0.0), 1.0)
    return Material("metal", fields.color(albedo, "albedo", hi=1.0), fuzz, name)


@checked("rough_conductor")
def rough_conductor(albedo: Color | Texture, alpha: float, *,
                    name: str | None = None) -> Material:
    """A rough metal: GGX microfacets of roughness `alpha` (0 < alpha <= 1;
    towards 0 it tends to a mirror, 1 is very rough) reflecting `albedo` (a
    colour or a texture), with no Fresnel term -- Mitsuba 3's roughconductor
    with material "none"."""
    color, texture = _colour(albedo, "albedo", hi=1.0)
    return Material("rough_conductor", color, 0.0, name, texture=texture,
                    alpha=fields.number(alpha, "alpha", lo=0.0, lo_open=True, hi=1.0))


@checked("dielectric")
def dielectric(ior: float, *, name: str | None = None) -> Material:
    """The books' glass of index of refraction `ior`: reflects with Schlick's
    probability (always under total internal reflection), else refracts."""
    return Material("dielectric", (1.0, 1.0, 1.0),
                    fields.number(ior, "ior", lo=0.0, lo_open=True), name)


@checked("rough_dielectric")
def rough_dielectric(ior: float, alpha: float, *, name: str | None = None) -> Material:
    """Frosted glass of index of refraction `ior`: GGX microfacets of
    roughness `alpha` (0 < alpha <= 1; towards 0 it tends to smooth glass)
    reflecting with the exact Fresnel reflectance and refracting the rest
    (Walter et al. 2007) -- Mitsuba 3's roughdielectric."""
    return Material("rough_dielectric", (1.0, 1.0, 1.0),
                    fields.number(ior, "ior", lo=0.0, lo_open=True), name,
                    alpha=fields.number(alpha, "alpha", lo=0.0, lo_open=True, hi=1.0))


@checked("diffuse_light")
def diffuse_light(emit: Color | Texture, *, name: str | None = None) -> Material:
    """emit: the radiance of its front side, a colour or a texture."""
    color, texture = _colour(emit, "emit")
    return Material("diffuse_light", color, 0.0, name, texture=texture)


@checked("isotropic")
def isotropic(albedo: Color | Texture, density: float = 1.0, *,
              name: str | None = None) -> Material:
    """The phase function of a constant medium (shapes.constant_medium): it
    scatters uniformly in all directions, keeping `albedo` (a colour or a
    texture) of the light; `density` is its extinction per unit length."""
    color, texture = _colour(albedo, "albedo", hi=1.0)
    return Material("isotropic", color, fields.number(density, "density", lo=0.0), name,
                    texture=texture)


@checked("phong")
def phong(color: Color, specular: float = -1, reflective: float = 0.0, *,
          name: str | None = None) -> Material:
    """Computer Graphics from Scratch's material (classic integrator only):
    a 0..255 colour, a Phong exponent (-1: matte) and a mirror share."""
    specular = fields.number(specular, "specular")
    if specular < 0 and specular != -1:
        raise FieldError("specular", f"must be -1 (matte) or >= 0, got {specular:g}")
    return Material("phong", fields.color(color, "color", hi=255.0), specular, name,
                    fields.number(reflective, "reflective", lo=0.0, hi=1.0))


# The builders by kind, for the loader: the path tracer's, then the classic one.
MATERIALS = {f.kind: f for f in (lambertian, metal, dielectric, diffuse_light, rough_conductor,
                                  rough_dielectric, phong)}
# Not a surface's: constant_medium (shapes.py) makes it.
MEDIUM_MATERIALS = {"isotropic": isotropic}
CLASSIC_MATERIALS = ("phong",)
# What the package offers (scene/__init__.py, rtweekend/__init__.py): every builder.
__all__ = ["Material", *MATERIALS, *MEDIUM_MATERIALS]


def check_material(value):
    """A shape's material field: a Material, else FieldError."""
    if not isinstance(value, Material):
        raise FieldError("material", f"expected a material, got {type(value).__name__}")
    return value
