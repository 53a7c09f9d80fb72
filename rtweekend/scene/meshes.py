"""Triangle meshes as plain arrays: read from a file (OBJ by io/obj.py, or what
trimesh reads, the optional `meshes` extra: OBJ, PLY, STL, OFF, glTF/GLB) or
given directly, and checked.

A mesh is (vertices float64 [V, 3], faces int64 [F, 3], uvs float64 [V, 2] or
None, normals float64 [V, 3] unit or None).  Faces with no area (two equal
vertices, or three in a line) are left out: they cannot be hit and have no
normal.  A file of several objects or materials becomes one mesh, each part
placed by the file's own transforms; the scene's material covers all of it.
Vertex normals are the file's (OBJ `vn`, PLY nx/ny/nz, glTF NORMAL) when every
part of it has them; they make the mesh shade smoothly (path/shapes/triangle.py).
"""
from pathlib import Path

import numpy as np

from ..io import obj
from .. import memory
from ..errors import FieldError

INSTALL = "pip install 'rtweekend[meshes]'"


def read(path):
    """(vertices, faces, uvs, normals) of the mesh file at path (FieldError on
    `file`): uvs and normals None where the file does not give every part's.
    An OBJ file is read by io/obj.py where it can, others by trimesh."""
    path = Path(path)
    if not path.is_file():
        raise FieldError("file", f"no such mesh file: {path}")
    unread = None
    if path.suffix.lower() == ".obj":
        def fits(needed, triangles):
            _fits(path, needed + path.stat().st_size, f"its {triangles:,} triangles")
        try:
            mesh = obj.read(path, fits)
        except OSError as e:
            raise FieldError("file", f"cannot read the mesh {path}: {e}") from None
        except obj.Unread as e:
            unread = str(e)             # trimesh's turn
        except obj.ObjError as e:
            raise FieldError("file", str(e)) from None
        else:
            if len(mesh[1]) == 0:
                raise FieldError("file", f"{path} holds no triangles")
            return mesh
    return read_with_trimesh(path, unread)


def _fits(path, needed, what):
    """FieldError (on `file`) unless `needed` bytes fit in what this process
    can still get (memory.py), before a mesh file is read."""
    free, source = memory.available()
    if free is not None and needed > memory.SHARE * free:
        raise FieldError("file", f"{path}: {what} need about {memory.size(needed)} of memory "
                         f"to read, and {memory.size(free)} is available ({source})")


# What trimesh holds reading a file, per byte of it (its text or binary
# arrays, then NumPy's, then ours): a bound, not a measure.
TRIMESH_BYTES_PER_FILE_BYTE = 4


def read_with_trimesh(path, unread=None):
    """read(), by trimesh for every format; unread: why the OBJ reader did
    not read it (obj.Unread's message), said if trimesh is not installed."""
    try:
        import trimesh
    except ImportError:
        if unread:
            raise FieldError("file", f"{unread}, which rtweekend's OBJ reader does not "
                             f"read; trimesh may: {INSTALL}") from None
        raise FieldError("file", f"reading mesh files needs trimesh: {INSTALL}") from None
    path = Path(path)
    _fits(path, TRIMESH_BYTES_PER_FILE_BYTE * path.stat().st_size, "its contents")
    try:
        # process=False: the file's vertices as they are (their uvs and normals
        # with them).  A scene keeps each part's normals, which a mesh
        # concatenated by trimesh would recompute from the faces.
        scene = trimesh.load_scene(str(path), process=False)
    except Exception as e:          # trimesh raises many kinds for a file it cannot read
        if unread:                  # the OBJ reader's message names the line
            raise FieldError("file", f"{unread}, which neither rtweekend's OBJ reader "
                             f"nor trimesh reads") from None
        why = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise FieldError("file", f"cannot read the mesh {path}: {why}") from None
    parts = []
    for node in scene.graph.nodes_geometry:
        transform, name = scene.graph[node]
        part = scene.geometry.get(name)
        if isinstance(part, trimesh.Trimesh) and len(part.faces):
            parts.append((np.asarray(transform, dtype=np.float64), part))
    if not parts:
        raise FieldError("file", f"{path} holds no triangles")
    vertices, faces, uvs, normals, count = [], [], [], [], 0
    for transform, part in parts:
        m, offset = transform[:3, :3], transform[:3, 3]
        f = np.asarray(part.faces, dtype=np.int64)
        v = np.asarray(part.vertices, dtype=np.float64)
        if not np.array_equal(transform, np.eye(4)):    # (keeps a NaN where it was)
            v = v @ m.T + offset
            if np.linalg.det(m) < 0:
                f = f[:, ::-1]      # a mirroring transform: the front stays outward
        vertices.append(v)
        faces.append(f + count)
        count += len(part.vertices)
        uv = getattr(part.visual, "uv", None)
        uvs.append(None if uv is None or len(uv) != len(part.vertices) else np.asarray(uv))
        normals.append(_file_normals(part, m))
    return (np.concatenate(vertices), np.concatenate(faces),
            None if any(u is None for u in uvs) else np.concatenate(uvs),
            None if any(n is None for n in normals) else np.concatenate(normals))


def _file_normals(part, m):
    """The vertex normals the file gave `part` (trimesh keeps them in its cache;
    the public vertex_normals would make some up from the faces), placed by the
    3x3 map m (normals go by its inverse transpose), or None."""
    if "vertex_normals" not in part._cache:
        return None
    n = np.asarray(part._cache["vertex_normals"], dtype=np.float64)
    if n.shape != (len(part.vertices), 3):
        return None
    if np.array_equal(m, np.eye(3)):
        return n
    try:
        return n @ np.linalg.inv(m)     # (M^-T n) for each row n
    except np.linalg.LinAlgError:
        return None


def check(vertices, faces, uvs=None, normals=None, where="mesh", from_file=False):
    """Clean copies of the arrays, or FieldError naming what is wrong:
    vertices finite [V, 3], faces [F, 3] of indices below V, uvs [V, 2] finite,
    normals [V, 3] finite and not zero (made unit) at the vertices of the faces
    kept -- from_file: a file's normal that is not is made from the faces
    (unit_normals) --; faces without area dropped (at least one must remain)."""
    try:
        v = np.array(vertices, dtype=np.float64)
        f = np.array(faces)
    except (TypeError, ValueError) as e:
        raise FieldError(where, f"not arrays of numbers: {e}") from None
    if v.ndim != 2 or v.shape[1] != 3:
        raise FieldError(where, f"vertices: expected an array of shape (V, 3), got {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3:
        raise FieldError(where, f"faces: expected triangles, an array of shape (F, 3), got "
                         f"{f.shape}")
    if len(f) == 0:
        raise FieldError(where, "has no triangles")
    if not np.issubdtype(f.dtype, np.integer):
        raise FieldError(where, "faces: expected integer vertex indices")
    bad = ~np.isfinite(v).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise FieldError(where, f"vertex {i} is not finite: {v[i].tolist()}")
    out = (f < 0) | (f >= len(v))
    if out.any():
        i = int(np.flatnonzero(out.any(axis=1))[0])
        raise FieldError(where, f"face {i} refers to vertex {f[i].tolist()}, but the mesh has "
                         f"{len(v)} vertices (0..{len(v) - 1})")
    f = f.astype(np.int64)
    if uvs is not None:
        uvs = np.array(uvs, dtype=np.float64)
        if uvs.shape != (len(v), 2) or not np.isfinite(uvs).all():
            uvs = None              # texture coordinates that do not fit: none
    area = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    keep = area > 0.0
    if not keep.any():
        raise FieldError(where, f"none of its {len(f)} triangles has an area")
    f = f[keep]
    if normals is not None:
        normals = unit_normals(normals, v, f, where, mend=from_file)
    return v, f, uvs, normals


def unit_normals(normals, vertices, faces, where, mend=False):
    """normals [V, 3] made unit, or FieldError: the wrong shape, or one of a
    vertex of `faces` that is not a direction (not finite, or no length).
    mend (a file's normals): such a vertex gets the normal its faces make
    instead.  A vertex of no face keeps any unit normal: it is never read."""
    try:
        n = np.array(normals, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise FieldError(where, f"normals: not an array of numbers: {e}") from None
    if n.shape != (len(vertices), 3):
        raise FieldError(where, f"normals: expected one per vertex, an array of shape "
                         f"({len(vertices)}, 3), got {n.shape}")
    length = np.linalg.norm(n, axis=1)
    bad = ~(np.isfinite(n).all(axis=1) & (length > 0.0) & np.isfinite(length))
    if bad.any():
        used = np.zeros(len(n), dtype=bool)
        used[faces.ravel()] = True
        wrong = bad & used
        if wrong.any() and not mend:
            i = int(np.flatnonzero(wrong)[0])
            raise FieldError(where, f"normals[{i}] is not a direction: {n[i].tolist()} "
                             f"(the normal of vertices[{i}] must be finite and not zero)")
        if wrong.any():
            # Exporters write `vn 0 0 0` (or NaN) where they could not make a
            # normal.  Blender reads a zero custom normal as "the automatic
            # one": the area-weighted normal of the faces around that point,
            # as smooth = true makes them; so does this, the faces around the
            # position (not only those naming this vertex's file normal), so
            # the shading stays continuous with its neighbours instead of one
            # flat facet in a smooth surface.
            n[wrong] = faces_normals(vertices, faces, wrong)
        n[bad & ~used] = (0.0, 0.0, 1.0)
        length = np.linalg.norm(n, axis=1)
    return n / length[:, None]


def faces_normals(vertices, faces, which):
    """Unit normals [which.sum(), 3] of the vertices `which` (a mask) made
    from the faces around their positions, vertices at the same point counted
    as one (smooth_normals of the welded mesh)."""
    points, weld = np.unique(vertices, axis=0, return_inverse=True)
    weld = weld.ravel()
    return smooth_normals(points, weld[faces])[weld[which]]


def smooth_normals(vertices, faces):
    """Vertex normals made from the faces: each vertex's the sum of its faces'
    (P1 - P0) x (P2 - P0), so weighted by area, made unit (a vertex whose faces
    cancel keeps the first face's normal)."""
    cross = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]],
                     vertices[faces[:, 2]] - vertices[faces[:, 0]])
    n = np.zeros_like(vertices)
    for c in range(3):
        np.add.at(n, faces[:, c], cross)
    length = np.linalg.norm(n, axis=1)
    lone = ~(length > 0.0)
    if lone.any():                  # faces that cancel there: one of them
        face = np.zeros(len(vertices), dtype=np.int64)
        for c in range(3):
            face[faces[:, c]] = np.arange(len(faces))
        n[lone] = cross[face[lone]]
        length = np.linalg.norm(n, axis=1)
    length[length == 0.0] = 1.0     # a vertex of no face: never read
    return n / length[:, None]


def areas(vertices, faces):
    """float64 [F]: each triangle's area."""
    e1 = vertices[faces[:, 1]] - vertices[faces[:, 0]]
    e2 = vertices[faces[:, 2]] - vertices[faces[:, 0]]
    return 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
