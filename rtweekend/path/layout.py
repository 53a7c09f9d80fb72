"""What the path tracer's kernels read: the tags, the shared columns, and the
NamedTuples that carry the arrays.

The kernels take NamedTuples of flat arrays and scalars (named, so a
kernel reads `scene.obj_f`, never the 20th positional argument):

  SceneArrays  the objects, materials, lights, background and BVH (here)
  PathParams   the camera, image size, seed, depth, sampling and clamp (here)
  Features     what the kernel is compiled with (here)
  Film         the running sums of an image (film.py)

Objects (primitives) are rows of obj_i (kind tag, material) and obj_f (the
kind's own floats: each kind module in shapes/ names its columns and packs its
row).  Materials are mat_i (kind tag) and mat_f (colour, parameter).  Tags are
small integers because Numba branches on them; the description layer names
kinds with strings, and pack.py maps one to the other when it freezes a Scene.
This module imports nothing of the renderer, so any kernel module can use it.
"""
from typing import NamedTuple

import numpy as np

# -- tags ------------------------------------------------------------------------

# Primitive kinds (obj_i[:, OBJ_KIND]); shapes/__init__.py dispatches on them.
SPHERE = 0
RECT = 1             # any rectangle: turned book rects, quads' rectangles
XY_RECT = 2          # the book's rects, not turned: tested on their own axis
XZ_RECT = 3
YZ_RECT = 4
BOX = 5              # a box turned and moved: one slab test
TRIANGLE = 6         # a mesh's face (shapes/triangle.py; the mesh tables: Triangles)
PRIMITIVE_KINDS = (SPHERE, RECT, XY_RECT, XZ_RECT, YZ_RECT, BOX, TRIANGLE)

# Material kinds (mat_i): their tags are path/materials/'s (MATERIAL_TAGS).

# Background kinds.
BG_COLOR = 0
BG_SKY = 1

# "No object": closest_hit found nothing / a ray that starts at no surface.
NO_HIT = -1

# An index read from a table, `& NON_NEGATIVE`: the same number (a table's
# indices are >= 0), which tells LLVM so and spares each array access it
# reaches the test for a negative index (Python's a[-1]: a shift, a load of the
# shape, an add).
NON_NEGATIVE = 0x7FFFFFFFFFFFFFFF

# -- columns -----------------------------------------------------------------------

# light_rows (lights.py): the object, its part (a box's face; -1: the whole), its role
LIGHT_OBJ = 0
LIGHT_PART = 1
LIGHT_ROLE = 2
# the roles, also the rows of light_ranges: an emitting primitive picked by
# power, an entry of the books' lights list picked uniformly
EMITTED = 0
LISTED = 1
# light_f (lights.py)
LIGHT_AREA = 0
LIGHT_POWER = 1
LIGHT_PROB = 2
LIGHT_CDF = 3

# obj_i
OBJ_KIND = 0
OBJ_MAT = 1
OBJ_INTS = 2
# obj_f: as wide as the widest kind's row (each kind's columns: shapes/<kind>.py)
OBJ_FLOATS = 20
# mat_f
MAT_COLOR = 0        # 0:3 albedo, or emitted radiance
MAT_PARAMS = 3       # 3:5 the kind's parameters, named by its module (materials/)
N_PARAMS = 2
MAT_FLOATS = MAT_PARAMS + N_PARAMS


class SceneArrays(NamedTuple):
    """What the path-tracing kernel reads of a scene; plain arrays, picklable."""
    obj_i: np.ndarray      # int64 [N, OBJ_INTS]: kind, material
    obj_f: np.ndarray      # float64 [N, OBJ_FLOATS]
    mat_i: np.ndarray      # int64 [M]: kind
    mat_f: np.ndarray      # float64 [M, MAT_FLOATS]: colour, parameters
    dark_sides: np.ndarray  # float64 [D, 4]: where the lights give nothing (pack.py)
    # The light table (lights.py): emitting primitives, then the lights list
    light_rows: np.ndarray  # int64 [L, 3]: object, part, role
    light_f: np.ndarray    # float64 [L, 4]: area, power, probability, cumulative
    light_ranges: np.ndarray  # int64 [2, 2]: each role's rows [first, end)
    light_pick: np.ndarray  # float64 [N]: how often next events pick each object
    bg_kind: int           # BG_COLOR or BG_SKY
    bg: np.ndarray         # float64 [3]: the background's radiance (BG_COLOR)
    # The binary hierarchy as built (bvh.py, bvh_build.py): bvh_prims lists
    # every object the search tests; the nodes are empty once it is made
    # 4-wide (wide), and for small scenes, which test every object.
    bvh_box: np.ndarray
    bvh_node: np.ndarray
    bvh_prims: np.ndarray
    # The meshes' tables, None in a scene without meshes: then the kernels
    # compile none of the triangle's code (shapes/triangle.py).
    tris: object = None
    # The 4-wide BVH (wide_bvh.py, WideBVH) the search walks, None in a scene
    # too small for a hierarchy: then it tests every object in one loop.
    wide: object = None
    # True where a material of the scene is glossy (materials/flags.py), None
    # else: then the kernels compile none of the glossy materials' code.
    glossy: object = None
    # A scene without hierarchy (wide None, no nodes): int64 [len(PRIMITIVE_KINDS)
    # + 1], bvh_prims[kind_first[K]:kind_first[K + 1]] its objects of kind K
    # (bvh.kind_walk); None else.
    kind_first: object = None


class WideBVH(NamedTuple):
    """The hierarchy with four children to a node (wide_bvh.py)."""
    box: np.ndarray        # float64 [W, 6, 4]: each node's children's boxes
    child: np.ndarray      # int64 [W, 4]: a wide node, or a leaf (first block, count)
    leaf_prim: np.ndarray  # int64 [4 B]: the leaves' objects (-1 - k: not a triangle)
    leaf_tri: np.ndarray   # float64 [B, 9, 4]: their triangles' vertices, four a block;
    #                        [0, 9, 4] in a scene without meshes


class Triangles(NamedTuple):
    """What a mesh's triangles have beyond their rows of obj_f, by the row's
    INDEX (shapes/triangle.py)."""
    uvs: np.ndarray        # float64 [T, 6]: (u, v) at P0, P1, P2; [0, 6]: none
    normals: np.ndarray    # float64 [T, 9]: unit vertex normals at P0, P1, P2 (NaN: a
    #                        flat triangle); [0, 9]: no mesh shades smoothly
    mesh: np.ndarray       # int64 [T]: the object of its mesh's first triangle (the
    #                        surface photons are gathered on: photons.py)
    groups: np.ndarray     # int64 [G, 3]: the lights list's meshes (mesh_light.py)
    group_cdf: np.ndarray  # float64: their triangles' cumulative areas over the total
    group_area: np.ndarray  # float64 [G]: their areas


class PathParams(NamedTuple):
    """The render's parameters, as the kernel reads them."""
    cam: np.ndarray        # float64 [camera.CAM_FLOATS]
    width: int
    height: int
    seed: int
    max_depth: int         # ray segments per path
    light_weight: float    # the mixture's share of light sampling (pdf.py)
    clamp: float           # cap on each sample's channels; inf: none
    pairs: int             # Sobol pairs per sample (kernel/sampler.py); None: the stream
    #                        only, and a kernel compiled without the Sobol points' code
    # bdpt's strategy (s, t) alone and unweighted, pbrt's per-strategy images
    # (integrators/bdpt.py; set by tests); -1: all of them, weighted by MIS.
    only_s: int = -1
    only_t: int = -1


class Features(NamedTuple):
    """What a kernel is compiled with or without: each None when unused, so that
    a scene and a strategy pay only for what they use (the kernel's `is None`
    tests on its arguments are pruned by Numba).  Unpacked into the kernel's
    arguments in one place (renderer.render_samples)."""
    events: object = None    # next-event estimation: the roulette's first segment (0: none)
    textures: object = None  # textures.TextureArrays
    media: object = None     # int64 [K]: the constant media's objects
    motion: object = None    # 0 when something moves
    # bdpt's caustic photon maps (integrators/photons.py): their settings and
    # the maps of the samples a kernel call renders (renderer.render_samples)
    caustics: object = None
    # Manifold connections through smooth glass (mnee.py; the path tracer's
    # and bdpt's): the longest chain of refractions they solve
    manifold: object = None
