"""Write next_week_final.toml, The Next Week's final scene, and the planet
texture it wraps on one sphere (textures/planet.png), both drawn once.

    python scenes/make_next_week.py

The book draws its boxes' heights and its cluster of 1000 spheres anew on every
run; we draw them once with a fixed seed and store them, so the scene file is
the whole truth.  The book's sphere wears a photograph of the Earth; ours is a
planet made here from random waves (continents, seas, ice caps), so that the
project ships no third-party image.
"""
import sys
from pathlib import Path

import numpy as np

SEED = 2023
HERE = Path(__file__).resolve().parent
PLANET = "textures/planet.png"


def planet(width=512, height=256, seed=SEED):
    """An equirectangular planet map as 8-bit sRGB: u = longitude, v = latitude
    (row 0 the north pole), as the sphere's (u, v) reads it."""
    rng = np.random.default_rng(seed)
    lon = (np.arange(width) + 0.5) / width * 2 * np.pi
    lat = np.pi / 2 - (np.arange(height) + 0.5) / height * np.pi
    lon, lat = np.meshgrid(lon, lat)
    p = np.stack([np.cos(lat) * np.cos(lon), np.sin(lat), np.cos(lat) * np.sin(lon)], axis=-1)
    # Fractal "noise" on the sphere: random plane waves, amplitude 1/frequency
    # (seamless, since it is a function of the 3-D point).
    h = np.zeros((height, width))
    for octave in range(6):
        freq = 1.5 * 2.0 ** octave
        for _ in range(6):
            k = rng.normal(size=3)
            k *= freq / np.linalg.norm(k)
            h += np.sin(p @ k + rng.uniform(0, 2 * np.pi)) / freq
    h = (h - h.mean()) / h.std()
    sea = np.array([0.05, 0.18, 0.45])
    shallow = np.array([0.10, 0.35, 0.60])
    low = np.array([0.20, 0.45, 0.15])
    high = np.array([0.50, 0.40, 0.25])
    ice = np.array([0.92, 0.94, 0.96])
    land = h > 0.3
    t_sea = np.clip((h + 1.5) / 1.8, 0, 1)[..., None]
    t_land = np.clip((h - 0.3) / 1.5, 0, 1)[..., None]
    rgb = np.where(land[..., None], low + (high - low) * t_land, sea + (shallow - sea) * t_sea)
    polar = np.abs(lat) > np.radians(72) - 0.05 * h
    rgb[polar] = ice
    return np.round(255 * np.sqrt(np.clip(rgb, 0, 1))).astype(np.uint8)


def _vec(v):
    return "[" + ", ".join(f"{x:.4f}".rstrip("0").rstrip(".") for x in v) + "]"


DESCRIPTION = ("The Next Week's final scene: boxes, moving, glass, metal, subsurface and "
               "marble spheres, fog, a planet, 1000 spheres")
HEADER = f'''description = "{DESCRIPTION}"
lights = ["light"]

[camera]
lookfrom = [478, 278, -600]
lookat = [278, 278, 0]
vup = [0, 1, 0]
vfov = 40
width = 800
height = 800

[render]
spp = 250
max_depth = 40
background = [0, 0, 0]

[textures]
planet = {{ type = "image_texture", file = "{PLANET}" }}
marble = {{ type = "noise_texture", scale = 0.2, style = "marble", seed = 1 }}

[materials]
ground = {{ type = "lambertian", albedo = [0.48, 0.83, 0.53] }}
light = {{ type = "diffuse_light", emit = [7, 7, 7] }}
orange = {{ type = "lambertian", albedo = [0.7, 0.3, 0.1] }}
glass = {{ type = "dielectric", ior = 1.5 }}
brushed = {{ type = "metal", albedo = [0.8, 0.8, 0.9], fuzz = 1.0 }}
planet = {{ type = "lambertian", albedo = "planet" }}
marble = {{ type = "lambertian", albedo = "marble" }}
white = {{ type = "lambertian", albedo = [0.73, 0.73, 0.73] }}

[[objects]]
# One-sided, facing down (u x v points to -y).
name = "light"
type = "quad"
Q = [123, 554, 147]
u = [300, 0, 0]
v = [0, 0, 265]
material = "light"

[[objects]]
name = "moving"
type = "sphere"
center = [400, 400, 200]
center1 = [430, 400, 200]
radius = 50
material = "orange"

[[objects]]
type = "sphere"
center = [260, 150, 45]
radius = 50
material = "glass"

[[objects]]
type = "sphere"
center = [0, 150, 145]
radius = 50
material = "brushed"

[[objects]]
# The subsurface sphere: glass holding a blue medium inside the same sphere.
name = "subsurface_glass"
type = "sphere"
center = [360, 150, 145]
radius = 70
material = "glass"

[[objects]]
name = "subsurface"
type = "constant_medium"
density = 0.2
albedo = [0.2, 0.4, 0.9]
boundary = {{ type = "sphere", center = [360, 150, 145], radius = 70 }}

[[objects]]
# Thin fog over everything (the camera is inside it).
name = "fog"
type = "constant_medium"
density = 0.0001
albedo = [1, 1, 1]
boundary = {{ type = "sphere", center = [0, 0, 0], radius = 5000 }}

[[objects]]
name = "planet"
type = "sphere"
center = [400, 200, 400]
radius = 100
material = "planet"

[[objects]]
name = "marble"
type = "sphere"
center = [220, 280, 300]
radius = 80
material = "marble"

'''


def main(out):
    rng = np.random.default_rng(SEED)
    out.write(HEADER)
    out.write(f"# The floor: 20 x 20 boxes of random heights (seed {SEED}).\n")
    for i in range(20):
        for j in range(20):
            x0, z0 = -1000.0 + i * 100.0, -1000.0 + j * 100.0
            y1 = rng.uniform(1.0, 101.0)
            out.write(f'[[objects]]\ntype = "box"\np0 = {_vec((x0, 0, z0))}\n'
                      f'p1 = {_vec((x0 + 100, y1, z0 + 100))}\nmaterial = "ground"\n\n')
    out.write("# The cluster: 1000 spheres in a cube of 165, turned and moved.\n")
    for _ in range(1000):
        c = rng.uniform(0.0, 165.0, 3)
        out.write(f'[[objects]]\ntype = "sphere"\ncenter = {_vec(c)}\nradius = 10\n'
                  'material = "white"\nrotate_y = 15\ntranslate = [-100, 270, 395]\n\n')


if __name__ == "__main__":
    import imageio.v3 as iio
    iio.imwrite(HERE / PLANET, planet())
    with open(HERE / "next_week_final.toml", "w") as f:
        main(f)
    print(f"wrote {HERE / 'next_week_final.toml'} and {HERE / PLANET}", file=sys.stderr)
