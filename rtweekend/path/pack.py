"""Freezing a Scene into the arrays the path tracer's kernels read (layout.py).

Each shape becomes one primitive (a mesh: one per triangle), placed in the
world (its rotation, then translate) and packed by its kind's module
(shapes/<kind>.py).
"""
from dataclasses import replace

import numpy as np

from ..errors import SceneError
from ..kernel import compile_workers
from ..scene.fields import SKY
from . import bvh as hierarchy, mesh_light, wide_bvh
from .materials import EMITS, GLOSSY, KIND_FLAGS, KINDS, MATERIAL_TAGS, MEDIUM, objects_with
from .layout import (BG_COLOR, BG_SKY, BOX, MAT_FLOATS, N_PARAMS,
                     OBJ_FLOATS, OBJ_INTS, OBJ_KIND, OBJ_MAT, PRIMITIVE_KINDS, RECT,
                     SPHERE, TRIANGLE, XY_RECT, XZ_RECT, YZ_RECT, SceneArrays, Triangles,
                     WideBVH)
from .shapes import axis_rect, box, rect, sphere, triangle
from .lights import listed, pack_lights
from .textures import pack_textures


AXIS_RECTS = {"xy_rect": XY_RECT, "xz_rect": XZ_RECT, "yz_rect": YZ_RECT}
# The normal's axis of each axis-aligned kind.
AXIS_KINDS = {XY_RECT: 2, XZ_RECT: 1, YZ_RECT: 0}


def primitives(shape):
    """[(kind tag, obj_f row)] of one shape, placed in the world.

    A book rect that is not turned stays on its axis (axis_rect.py); turned, it
    becomes a general rect (rect.py).  A box is one primitive in its own frame
    (box.py), whatever its turn.
    """
    row = np.zeros(OBJ_FLOATS)
    rot, offset = shape.placement()
    if shape.kind == "box":
        box.pack(*shape.geometry, rot, offset, shape.flipped, row)
        return [(BOX, row)]
    if shape.kind == "sphere":
        center, radius = shape.geometry
        sphere.pack(rot @ np.asarray(center) + offset, -radius if shape.flipped else radius,
                    row, shape.velocity)
        return [(SPHERE, row)]
    if shape.kind == "quad":
        q, u, v = (np.asarray(a, dtype=np.float64) for a in shape.geometry)
        if shape.flipped:
            u, v = v, u
        rect.pack(rot @ q + offset, rot @ u, rot @ v, row)
        return [(RECT, row)]
    if not shape.turned:
        axis_rect.pack(shape.kind, shape.geometry, offset, shape.flipped, row)
        return [(AXIS_RECTS[shape.kind], row)]
    q, u, v = rect.axis_frame(shape.kind, shape.geometry)
    if shape.flipped:
        u, v = v, u         # swapping the edges reverses u x v, the front side
    rect.pack(rot @ np.asarray(q) + offset, rot @ np.asarray(u), rot @ np.asarray(v), row)
    return [(RECT, row)]


# What packing one primitive holds at most, in bytes: its rows in obj_i and obj_f
# (2 + OBJ_FLOATS values), BVH nodes (up to two per object: 6 + 3 values and a
# link, twice while threads build subtrees apart) and its index, six light rows
# (a box light: 2 + 4 values) and light_pick, and the Python objects packing
# makes on the way (a row array and a tuple each).
BYTES_PER_OBJECT = 8 * (OBJ_INTS + OBJ_FLOATS + 2 * 2 * 10 + 1 + 6 * 6 + 1) + 400


def scene_bytes(scene):
    """About the most memory packing `scene` holds (pack_scene), from its
    description alone, so that it can be checked before anything is packed
    (memory.py): its primitives, their BVH and light rows, and the textures'
    tables (image texels, Perlin noise)."""
    total = BYTES_PER_OBJECT * sum(shape.primitives for shape in scene.objects)
    seen = set()
    for shape in scene.objects:
        texture = shape.material.texture
        stack = [texture] if texture is not None else []
        while stack:
            t = stack.pop()
            if id(t) in seen:
                continue
            seen.add(id(t))
            total += 64
            if t.pixels is not None:
                total += 24 * t.pixels.size // 3
            if t.kind == "noise":
                total += 256 * 3 * 8 + 3 * 256 * 8
            stack.extend(c for c in (t.even, t.odd) if isinstance(c, type(t)))
    return total


def pack_background(value):
    """(kind, rgb array) for a validated background: an RGB triple or "sky"."""
    if isinstance(value, str) and value == SKY:
        return BG_SKY, np.zeros(3)
    return BG_COLOR, np.array(value, dtype=np.float64)


def scene_materials(scene):
    """The scene's distinct materials, in the order of their first object (the
    rows of mat_i and mat_f), and {id(material): row}."""
    materials, mat_index = [], {}
    for shape in scene.objects:
        if mat_index.setdefault(id(shape.material), len(materials)) == len(materials):
            materials.append(shape.material)
    return materials, mat_index


def pack_features(scene, arrays):
    """(textures, media, motion) of The Next Week's features, each None when the
    scene does not use it (integrators/path.py): TextureArrays, the media's object
    indices (int64), and 0 when a sphere moves."""
    textures = pack_textures(scene_materials(scene)[0])
    media = np.flatnonzero(objects_with(arrays.obj_i, arrays.mat_i, MEDIUM))
    motion = 0 if any(shape.moving for shape in scene.objects) else None
    return textures, (media.astype(np.int64) if len(media) else None), motion


def hierarchy_wanted(scene, bvh=None):
    """Does pack_scene build a hierarchy for `scene`: bvh (True or False), or
    when it has bvh.BVH_MIN_OBJECTS primitives the search tests (a constant
    medium's boundary is an object, media.py, but not one the search tests)."""
    if bvh is not None:
        return bvh
    return sum(s.primitives for s in scene.objects if not s.medium) >= \
        hierarchy.BVH_MIN_OBJECTS


def pack_scene(scene, bvh=None, *, stand_in=False):
    """The SceneArrays of a path-traced Scene (validated here).

    bvh: build a hierarchy (True), test every object (False), or decide by the
    number of primitives (None: hierarchy_wanted).  stand_in: arrays of the
    types the scene's own have, made in a moment, to type (and compile) its
    kernels before the real ones are packed: each mesh cut to one triangle,
    the hierarchy's tables empty, nothing built.
    """
    scene.check()
    if scene.resolved_integrator() != "path":
        raise SceneError("this scene is rendered by the classic integrator")
    bvh = hierarchy_wanted(scene, bvh)
    if stand_in:
        scene = _one_triangle_each(scene)
    materials, mat_index = scene_materials(scene)
    # Every primitive's rows, written in place (a mesh's millions by compiled
    # code: no list of rows, no copy).
    total = sum(shape.primitives for shape in scene.objects)
    obj_i = np.zeros((total, OBJ_INTS), dtype=np.int64)
    obj_f = np.zeros((total, OBJ_FLOATS))
    first, count = {}, 0
    tris = TriangleTables()
    for shape in scene.objects:
        first[id(shape)] = count
        if shape.kind == "mesh":
            n = tris.add(shape, obj_f[count:count + shape.primitives], count)
            obj_i[count:count + n, OBJ_KIND] = TRIANGLE
        else:
            kinds, rows = zip(*primitives(shape))
            assert set(kinds) <= set(PRIMITIVE_KINDS)   # the kernels' dispatch knows no other
            n = len(rows)
            obj_i[count:count + n, OBJ_KIND] = kinds
            obj_f[count:count + n] = np.asarray(rows).reshape(-1, OBJ_FLOATS)
        obj_i[count:count + n, OBJ_MAT] = mat_index[id(shape.material)]
        count += n
    mat_i = np.array([MATERIAL_TAGS[mt.kind] for mt in materials], dtype=np.int64)
    mat_f = np.array([(*mt.color, *_params(mt)) for mt in materials], dtype=np.float64)
    lights = np.array([first[id(s)] for s in scene.lights], dtype=np.int64)
    bg_kind, bg = pack_background(scene.resolved_background())
    surfaces = np.flatnonzero(~objects_with(obj_i, mat_i, MEDIUM))
    ids = None if len(surfaces) == len(obj_i) else surfaces
    wide = kind_first = None
    if bvh and len(surfaces) and stand_in:
        wide = WideBVH(*wide_bvh.empty())
        tree = hierarchy.empty_bvh(0)
    elif bvh and len(surfaces):
        # The builder, if a helper process compiles it while this one compiles
        # the kernels (renderer.py, kernel/compile_workers.py): wait for it.
        ahead = compile_workers.requested(wide_bvh.compile_ahead)
        if ahead is not None:
            ahead.wait()
        tree = hierarchy.build_bvh(obj_i, obj_f, ids)
        # Walked 4-wide: the binary nodes are not kept.
        wide = WideBVH(*wide_bvh.wide_tables(obj_i, obj_f, *tree, tris.count > 0))
        tree = (np.zeros((0, 6)), np.zeros((0, 3), dtype=np.int64), tree[2])
    else:
        tree = hierarchy.empty_bvh(len(obj_i), ids)
        prims, kind_first = hierarchy.sorted_by_kind(obj_i, tree[2])
        tree = (*tree[:2], prims)
    mat_f = mat_f.reshape(-1, MAT_FLOATS)
    mesh_lights = [(first[id(s)], s.primitives) for s in scene.lights if s.kind == "mesh"]
    return SceneArrays(obj_i, obj_f, mat_i, mat_f, np.zeros((0, 4)),
                       *pack_lights(obj_i, obj_f, mat_i, mat_f, lights), bg_kind, bg, *tree,
                       tris.arrays(obj_f, mesh_lights), wide,
                       True if (KIND_FLAGS[mat_i] & GLOSSY).any() else None, kind_first)


def _params(material):
    """A material's parameter columns, as its kind's module packs them (padded
    to N_PARAMS)."""
    values = KINDS[material.kind].params(material)
    assert len(values) <= N_PARAMS
    return (*map(float, values), *(0.0,) * (N_PARAMS - len(values)))


def _one_triangle_each(scene):
    """The scene with each mesh cut to its first triangle (pack_scene's stand-in)."""
    cut = {id(s): replace(s, geometry=_first_triangle(*s.geometry))
           for s in scene.objects if s.kind == "mesh"}
    if not cut:
        return scene
    return replace(scene, objects=[cut.get(id(s), s) for s in scene.objects],
                   lights=[cut.get(id(s), s) for s in scene.lights])


def _first_triangle(vertices, faces, uvs, normals):
    return vertices, faces[:1], uvs, normals


class TriangleTables:
    """The meshes' triangles as they are packed: their rows of obj_f, and the
    tables (layout.Triangles) their INDEX column points into."""

    def __init__(self):
        self.count, self.uvs, self.normals, self.mesh = 0, [], [], []

    def add(self, shape, rows, first_object):
        """Write the obj_f rows [F, OBJ_FLOATS] of a mesh shape, objects
        first_object..., into rows, placed in the world (its flip_face reverses
        the winding: the other side is the front); returns F."""
        vertices, faces, uvs, normals = shape.geometry
        rot, offset = shape.placement()
        world = vertices @ rot.T + offset
        if shape.flipped:
            faces = faces[:, ::-1]
        pack = triangle.pack_rows if len(faces) <= triangle.NUMPY_PACK_MAX else triangle.pack
        pack(world, np.ascontiguousarray(faces), self.count, rows)
        # Per triangle, for its three corners; vertex normals turn with the
        # mesh (a rotation keeps angles).  None: the mesh has none.
        self.uvs.append((len(faces), uvs[faces].reshape(-1, 6) if uvs is not None else None))
        self.normals.append((len(faces), (normals @ rot.T)[faces].reshape(-1, 9)
                             if normals is not None else None))
        self.mesh.append(np.full(len(faces), first_object, dtype=np.int64))
        self.count += len(faces)
        return len(faces)

    @staticmethod
    def _table(parts, columns, missing):
        """The parts' rows one after the other, `missing` for a mesh without
        them; [0, columns] if no mesh has any."""
        if all(rows is None for _, rows in parts):
            return np.zeros((0, columns))
        return np.concatenate([rows if rows is not None else np.full((n, columns), missing)
                               for n, rows in parts])

    def arrays(self, obj_f, mesh_lights):
        """layout.Triangles, with the lights list's meshes (first object,
        triangle count), or None when the scene has no mesh."""
        if self.count == 0:
            return None
        uvs = self._table(self.uvs, 6, 0.0)
        normals = self._table(self.normals, 9, np.nan)    # NaN: a flat triangle
        return Triangles(uvs, normals, np.concatenate(self.mesh),
                         *mesh_light.pack(obj_f, mesh_lights))


def dark_sides(arrays):
    """The front half-spaces (n, c: n.p >= c in front) of the lights list's
    emitters when every one of them is a one-sided rect (diffuse_light emits
    from its front only), else none.  A point behind all of them gets no light
    from any: a strategy with Sampling.facing does not sample the lights there
    (pdf.mixture_weight).  Attractors (lights that do not emit) do not count."""
    sides = []
    for k in listed(arrays):
        if not KIND_FLAGS[arrays.mat_i[arrays.obj_i[k, OBJ_MAT]]] & EMITS:
            continue
        kind, row = arrays.obj_i[k, 0], arrays.obj_f[k]
        if kind in AXIS_KINDS:
            n = np.zeros(3)
            n[AXIS_KINDS[kind]] = row[axis_rect.SIGN]
            sides.append((*n, row[axis_rect.SIGN] * row[axis_rect.K]))
        elif kind == RECT:
            sides.append((*row[rect.N:rect.N + 3], row[rect.PLANE]))
        else:
            return np.zeros((0, 4))      # a sphere or box light shines everywhere
    return np.array(sides, dtype=np.float64).reshape(-1, 4)
