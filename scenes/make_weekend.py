"""Write weekend.toml: book 1's final scene, its random spheres drawn once;
with --bouncing, bouncing_spheres.toml: The Next Week's first scene, the same
spheres with the diffuse ones moving up during the shutter, on a checker.

    python scenes/make_weekend.py > scenes/weekend.toml
    python scenes/make_weekend.py --bouncing > scenes/bouncing_spheres.toml

The book draws the small spheres anew on every run; we draw them once with a
fixed seed and store them, so the scene file is the whole truth and renders
are comparable across runs and machines.
"""
import sys

import numpy as np

SEED = 2020   # leaves 487 spheres in all


def small_spheres(rng, bouncing=False):
    """(center, center1 or None, material) of each small sphere."""
    for a in range(-11, 11):
        for b in range(-11, 11):
            choose_mat = rng.random()
            center = (a + 0.9 * rng.random(), 0.2, b + 0.9 * rng.random())
            if np.hypot(center[0] - 4.0, center[2] - 0.0) <= 0.9:
                continue
            center1 = None
            if choose_mat < 0.8:       # diffuse: albedo = random * random
                albedo = rng.random(3) * rng.random(3)
                material = f'{{ type = "lambertian", albedo = {_vec(albedo)} }}'
                if bouncing:           # The Next Week: up by random(0, 0.5)
                    center1 = (center[0], center[1] + rng.uniform(0.0, 0.5), center[2])
            elif choose_mat < 0.95:    # metal
                albedo = rng.uniform(0.5, 1.0, 3)
                fuzz = rng.uniform(0.0, 0.5)
                material = (f'{{ type = "metal", albedo = {_vec(albedo)}, '
                            f'fuzz = {fuzz:.4f} }}')
            else:                      # glass
                material = '"glass"'
            yield center, center1, material


def _vec(v):
    return "[" + ", ".join(f"{x:.4f}" for x in v) + "]"


def main(out=sys.stdout, bouncing=False):
    rng = np.random.default_rng(SEED)
    spheres = list(small_spheres(rng, bouncing))
    count = len(spheres) + 4
    if bouncing:
        description = (f"The Next Week's bouncing spheres: book 1's {count} spheres, the "
                       "diffuse ones moving (motion blur), on a checker")
        ground = ('{ type = "lambertian", albedo = { type = "checker_texture", '
                  'even = [0.2, 0.3, 0.1], odd = [0.9, 0.9, 0.9], scale = 10 } }')
        width, height, spp = 400, 225, 100
    else:
        description = f"Book 1's final scene: {count} spheres, depth of field, sky"
        ground = '{ type = "lambertian", albedo = [0.5, 0.5, 0.5] }'
        width, height, spp = 1200, 675, 500
    out.write(f'''description = "{description}"

[camera]
lookfrom = [13, 2, 3]
lookat = [0, 0, 0]
vup = [0, 1, 0]
vfov = 20
aperture = 0.1
focus_dist = 10
width = {width}
height = {height}

[render]
spp = {spp}
max_depth = 50
background = "sky"

[materials]
ground = {ground}
glass = {{ type = "dielectric", ior = 1.5 }}
brown = {{ type = "lambertian", albedo = [0.4, 0.2, 0.1] }}
bronze = {{ type = "metal", albedo = [0.7, 0.6, 0.5], fuzz = 0.0 }}

[[objects]]
type = "sphere"
center = [0, -1000, 0]
radius = 1000
material = "ground"

[[objects]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = "glass"

[[objects]]
type = "sphere"
center = [-4, 1, 0]
radius = 1
material = "brown"

[[objects]]
type = "sphere"
center = [4, 1, 0]
radius = 1
material = "bronze"

# The small spheres, drawn by scenes/make_weekend.py (seed {SEED}).
''')
    for center, center1, material in spheres:
        moving = "" if center1 is None else f"center1 = {_vec(center1)}\n"
        out.write(f'[[objects]]\ntype = "sphere"\ncenter = {_vec(center)}\n{moving}'
                  f'radius = 0.2\nmaterial = {material}\n\n')


if __name__ == "__main__":
    main(bouncing="--bouncing" in sys.argv[1:])
