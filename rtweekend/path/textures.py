"""Textures in the kernel (The Next Week): a material's colour looked up at the
hit point, from tables packed once per scene.

The kernel takes a TextureArrays only when some material of the scene has a
texture; otherwise the argument is None and Numba compiles none of this.

  tex_i[t] = (kind, a, b, table)      tex_f[t] = (r, g, b, scale)
  SOLID    colour
  CHECKER  a where sin(s x) sin(s y) sin(s z) >= 0 else b (texture indices;
           checkers of checkers are walked in a loop, no recursion)
  NOISE    style a (NOISE_PLAIN, TURBULENCE, MARBLE), Perlin tables `table`
  IMAGE    image `table`: images[table] = (first texel, width, height) in texels

Perlin noise is the book's: 256 random unit gradients and three permutations
per texture, drawn in NumPy from the texture's seed; trilinear interpolation of
the eight corners' dot products with Hermite smoothing; turbulence sums 7
octaves.
"""
import math
from typing import NamedTuple

import numpy as np

from ..kernel.jit import jit_step
from . import shapes
from .layout import NO_HIT

SOLID = 0
CHECKER = 1
NOISE = 2
IMAGE = 3
NOISE_PLAIN = 0
TURBULENCE = 1
MARBLE = 2
STYLES = {"noise": NOISE_PLAIN, "turbulence": TURBULENCE, "marble": MARBLE}
KIND, A, B, TABLE = 0, 1, 2, 3
SCALE = 3
POINTS = 256
TURB_DEPTH = 7


class TextureArrays(NamedTuple):
    mat_tex: np.ndarray    # int64 [M]: the texture of material m's colour, -1: none
    tex_i: np.ndarray      # int64 [T, 4]
    tex_f: np.ndarray      # float64 [T, 4]
    gradients: np.ndarray  # float64 [P, POINTS, 3]: Perlin's random unit vectors
    perm: np.ndarray       # int64 [P, 3, POINTS]: its permutations (x, y, z)
    texels: np.ndarray     # float64 [texels, 3]: every image, row after row (top first)
    images: np.ndarray     # int64 [I, 3]: first texel, width, height


def perlin_tables(seed):
    """(gradients [POINTS, 3], perm [3, POINTS]) for one noise texture."""
    rng = np.random.default_rng(seed)
    g = rng.uniform(-1.0, 1.0, (POINTS, 3))
    norm = np.linalg.norm(g, axis=1)
    while (norm < 1e-6).any():         # a zero vector has no direction: draw again
        bad = norm < 1e-6
        g[bad] = rng.uniform(-1.0, 1.0, (int(bad.sum()), 3))
        norm = np.linalg.norm(g, axis=1)
    perm = np.stack([rng.permutation(POINTS) for _ in range(3)]).astype(np.int64)
    return g / norm[:, None], perm


def pack_textures(materials):
    """TextureArrays for a list of Materials, or None when none has a texture."""
    if not any(m.texture is not None for m in materials):
        return None
    tex_i, tex_f, gradients, perm, texels, images = [], [], [], [], [], []
    seen = {}

    def add(texture):
        if id(texture) in seen:
            return seen[id(texture)]
        t = len(tex_i)
        seen[id(texture)] = t
        tex_i.append([0, 0, 0, 0])
        tex_f.append([0.0, 0.0, 0.0, texture.scale])
        if texture.kind == "solid":
            tex_i[t][KIND] = SOLID
            tex_f[t][:3] = texture.color
        elif texture.kind == "checker":
            even, odd = add(texture.even), add(texture.odd)
            tex_i[t] = [CHECKER, even, odd, 0]
        elif texture.kind == "noise":
            g, p = perlin_tables(texture.seed)
            tex_i[t] = [NOISE, STYLES[texture.style], 0, len(gradients)]
            gradients.append(g)
            perm.append(p)
        elif texture.kind == "image":
            h, w = texture.pixels.shape[:2]
            first = sum(len(x) for x in texels)
            tex_i[t] = [IMAGE, 0, 0, len(images)]
            images.append([first, w, h])
            texels.append(texture.pixels.reshape(-1, 3))
        else:
            raise ValueError(f"pack_textures: unknown texture kind {texture.kind}")
        return t

    mat_tex = np.array([add(m.texture) if m.texture is not None else -1 for m in materials],
                       dtype=np.int64)
    return TextureArrays(
        mat_tex, np.array(tex_i, dtype=np.int64).reshape(-1, 4),
        np.array(tex_f, dtype=np.float64).reshape(-1, 4),
        np.array(gradients, dtype=np.float64).reshape(-1, POINTS, 3),
        np.array(perm, dtype=np.int64).reshape(-1, 3, POINTS),
        np.concatenate(texels) if texels else np.zeros((0, 3)),
        np.array(images, dtype=np.int64).reshape(-1, 3))


@jit_step
def _hermite(t):
    return t * t * (3.0 - 2.0 * t)


@jit_step
def noise(gradients, perm, q, p):
    """The book's Perlin noise at p, in about [-1, 1], with tables q."""
    fx, fy, fz = math.floor(p[0]), math.floor(p[1]), math.floor(p[2])
    u, v, w = p[0] - fx, p[1] - fy, p[2] - fz
    i, j, k = int(fx), int(fy), int(fz)
    uu, vv, ww = _hermite(u), _hermite(v), _hermite(w)
    accum = 0.0
    for di in range(2):
        for dj in range(2):
            for dk in range(2):
                g = perm[q, 0, (i + di) & 255] ^ perm[q, 1, (j + dj) & 255] \
                    ^ perm[q, 2, (k + dk) & 255]
                dot = (gradients[q, g, 0] * (u - di) + gradients[q, g, 1] * (v - dj)
                       + gradients[q, g, 2] * (w - dk))
                accum += ((di * uu + (1 - di) * (1.0 - uu)) * (dj * vv + (1 - dj) * (1.0 - vv))
                          * (dk * ww + (1 - dk) * (1.0 - ww)) * dot)
    return accum


@jit_step
def turbulence(gradients, perm, q, p):
    """|sum of TURB_DEPTH octaves of noise|, each at twice the frequency and half
    the weight of the one before."""
    accum = 0.0
    weight = 1.0
    x, y, z = p
    for _ in range(TURB_DEPTH):
        accum += weight * noise(gradients, perm, q, (x, y, z))
        weight *= 0.5
        x, y, z = 2.0 * x, 2.0 * y, 2.0 * z
    return abs(accum)


@jit_step(inline=False)
def noise_value(gradients, perm, q, style, scale, p):
    """The grey level of a noise texture at p.  Called, not inlined: it holds
    fifteen copies of noise (two turbulences of seven octaves, and one), and a
    kernel looks textures up in several places (a mixed scene's bdpt kernel
    held ninety copies); the call costs nothing next to the octaves."""
    if style == MARBLE:
        return 0.5 * (1.0 + math.sin(scale * p[2] + 10.0 * turbulence(gradients, perm, q, p)))
    sp = (scale * p[0], scale * p[1], scale * p[2])
    if style == TURBULENCE:
        return turbulence(gradients, perm, q, sp)
    return 0.5 * (1.0 + noise(gradients, perm, q, sp))


@jit_step
def image_value(texels, images, i, u, v):
    """The texel under (u, v) (clamped to [0, 1]; v = 1 is the image's top row)."""
    first, width, height = images[i, 0], images[i, 1], images[i, 2]
    u = min(max(u, 0.0), 1.0)
    v = 1.0 - min(max(v, 0.0), 1.0)
    x = min(int(u * width), width - 1)
    y = min(int(v * height), height - 1)
    j = first + y * width + x
    return (texels[j, 0], texels[j, 1], texels[j, 2])


@jit_step
def value(textures, t, u, v, p):
    """Texture t's colour at the surface point p with coordinates (u, v)."""
    tex_i, tex_f = textures.tex_i, textures.tex_f
    while tex_i[t, KIND] == CHECKER:
        s = tex_f[t, SCALE]
        sines = math.sin(s * p[0]) * math.sin(s * p[1]) * math.sin(s * p[2])
        t = tex_i[t, B] if sines < 0.0 else tex_i[t, A]
    kind = tex_i[t, KIND]
    if kind == NOISE:
        g = noise_value(textures.gradients, textures.perm, tex_i[t, TABLE], tex_i[t, A],
                        tex_f[t, SCALE], p)
        return (g, g, g)
    if kind == IMAGE:
        return image_value(textures.texels, textures.images, tex_i[t, TABLE], u, v)
    return (tex_f[t, 0], tex_f[t, 1], tex_f[t, 2])


@jit_step
def color_and_uv(scene, textures, m, k, p, color, time):
    """(colour, (u, v)): material m's colour at p on object k (NO_HIT: a point
    inside a medium, which has no (u, v)) -- its texture's value there, or
    `color` if untextured -- and the coordinates it was looked up with."""
    t = textures.mat_tex[m]
    if t < 0:
        return color, (0.0, 0.0)
    u, v = 0.0, 0.0
    if k != NO_HIT:
        u, v = shapes.uv(scene, k, p, time)
    return value(textures, t, u, v, p), (u, v)


@jit_step
def color_at(scene, textures, m, k, p, color, time):
    """The colour of color_and_uv."""
    return color_and_uv(scene, textures, m, k, p, color, time)[0]
