"""Textures as plain Python values (The Next Week, chapters "Texture Mapping" and
"Perlin Noise"), for a lambertian albedo, an isotropic medium's albedo or a
diffuse light's emission:

    checker = checker_texture((.2, .3, .1), (.9, .9, .9))
    marble = noise_texture(4)
    earth = image_texture("textures/planet.png")
    ground = lambertian(checker)

A colour triple where a texture may go is a solid colour.  Each builder checks
its fields (SceneError naming the texture and the field); an image is read
here, so a missing or unreadable file is reported when the scene is built, not
when it is rendered.  The kernel side is path/textures.py.
"""
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import fields
from .fields import Color
from ..errors import FieldError, checked

NOISE_STYLES = ("noise", "turbulence", "marble")
# An image is read as 8-bit sRGB-ish values and made linear as the books' v4
# rtw_image does (stb_image's loadf: (c / 255) ** 2.2).
IMAGE_GAMMA = 2.2
MAX_TEXELS = 1 << 26


@dataclass(frozen=True, eq=False)
class Texture:
    kind: str                 # "solid", "checker", "noise", "image"
    color: tuple = (0.0, 0.0, 0.0)      # solid
    even: object = None       # checker: a Texture (sines >= 0) ...
    odd: object = None        # ... and another (sines < 0)
    scale: float = 1.0        # checker: frequency of the sines; noise: of the noise
    style: str = "marble"     # noise: one of NOISE_STYLES
    seed: int = 0             # noise: its Perlin tables are drawn from this seed
    pixels: object = field(default=None, repr=False)   # image: float64 [H, W, 3] linear
    file: str = ""            # image: where it was read from (for messages)
    name: str | None = None

    def mean(self):
        """A representative colour (the average of the texture's values, roughly)."""
        if self.kind == "solid":
            return self.color
        if self.kind == "checker":
            return tuple(0.5 * (a + b) for a, b in zip(self.even.mean(), self.odd.mean()))
        if self.kind == "image":
            return tuple(float(c) for c in self.pixels.reshape(-1, 3).mean(axis=0))
        return (0.5, 0.5, 0.5)


def texture_or_color(value, field, *, hi=None):
    """A material's colour field: a Texture (checked where it was built) or an
    RGB triple, which becomes a solid texture only if the caller wants one."""
    if isinstance(value, Texture):
        if hi is not None and value.kind != "noise":
            _check_range(value, field, hi)
        return value
    return fields.color(value, field, hi=hi)


def _check_range(texture, field, hi):
    """Albedo textures must stay within [0, hi] everywhere."""
    if texture.kind == "solid":
        fields.color(texture.color, field, hi=hi)
    elif texture.kind == "checker":
        _check_range(texture.even, field, hi)
        _check_range(texture.odd, field, hi)
    elif texture.kind == "image" and texture.pixels.max() > hi:
        raise FieldError(field, f"the image {texture.file} has values above {hi:g}")


def _as_texture(value, field):
    if isinstance(value, Texture):
        return value
    return Texture("solid", fields.color(value, field))


@checked("solid_color")
def solid_color(color: Color, *, name: str | None = None) -> Texture:
    """A texture of one colour everywhere (the books' solid_color)."""
    return Texture("solid", fields.color(color, "color"), name=name)


@checked("checker_texture")
def checker_texture(even: Color | Texture, odd: Color | Texture, scale: float = 10.0, *,
                    name: str | None = None) -> Texture:
    """The Next Week's 3-D checker: `even` where sin(s x) sin(s y) sin(s z) >= 0,
    `odd` elsewhere (s = scale); even and odd are colours or textures."""
    return Texture("checker", even=_as_texture(even, "even"), odd=_as_texture(odd, "odd"),
                   scale=fields.number(scale, "scale", lo=0.0, lo_open=True), name=name)


@checked("noise_texture")
def noise_texture(scale: float = 1.0, style: str = "marble", seed: int = 0, *,
                  name: str | None = None) -> Texture:
    """Perlin noise (trilinear interpolation of random gradients, Hermite
    smoothed), as the book builds it up:
      noise       0.5 (1 + noise(scale p))              grey, in [0, 1]
      turbulence  turb(scale p), 7 octaves
      marble      0.5 (1 + sin(scale z + 10 turb(p)))  the book's final look
    seed: the Perlin tables' seed (the same seed, the same texture)."""
    style = fields.text(style, "style")
    if style not in NOISE_STYLES:
        raise FieldError("style", f"expected one of {', '.join(NOISE_STYLES)}, got '{style}'")
    return Texture("noise", scale=fields.number(scale, "scale", lo=0.0, lo_open=True),
                   style=style, seed=fields.integer(seed, "seed", lo=0, hi=2**63 - 1),
                   name=name)


@checked("image_texture")
def image_texture(file: str | Path, *, name: str | None = None,
                  base: str | Path | None = None) -> Texture:
    """An image (PNG, JPEG, ... anything imageio reads) wrapped on a sphere by its
    (u, v) or stretched over a rect or quad.  A relative path is taken from
    `base` (the scene file's folder) or the current one."""
    file = fields.text(file, "file")
    path = Path(file)
    if base is not None and not path.is_absolute():
        path = Path(base) / path
    try:
        import imageio.v3 as iio
        data = np.asarray(iio.imread(path))
    except FileNotFoundError:
        raise FieldError("file", f"no such image: {path}") from None
    except Exception as e:       # imageio raises many kinds for an unreadable file
        raise FieldError("file", f"cannot read the image {path}: "
                         f"{str(e).splitlines()[0] if str(e) else type(e).__name__}") from None
    if data.ndim == 2:
        data = np.repeat(data[:, :, None], 3, axis=2)
    if data.ndim != 3 or data.shape[2] < 3 or data.shape[0] == 0 or data.shape[1] == 0:
        raise FieldError("file", f"{path}: expected an RGB image, got an array of shape "
                         f"{data.shape}")
    if data.shape[0] * data.shape[1] > MAX_TEXELS:
        raise FieldError("file", f"{path}: {data.shape[1]}x{data.shape[0]} is more than "
                         f"{MAX_TEXELS} texels")
    rgb = data[:, :, :3]
    if rgb.dtype == np.uint8:
        linear = (rgb.astype(np.float64) / 255.0) ** IMAGE_GAMMA
    elif rgb.dtype == np.uint16:
        linear = (rgb.astype(np.float64) / 65535.0) ** IMAGE_GAMMA
    else:
        linear = rgb.astype(np.float64)       # float images are linear already
    if not np.isfinite(linear).all() or linear.min() < 0.0:
        raise FieldError("file", f"{path}: texel values must be finite and >= 0")
    return Texture("image", pixels=np.ascontiguousarray(linear), file=str(path), name=name)


TEXTURES = {f.kind: f for f in (solid_color, checker_texture, noise_texture, image_texture)}
