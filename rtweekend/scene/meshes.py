"""Triangle meshes as plain arrays: read from a file (OBJ, PLY, STL, OFF, glTF/GLB:
what trimesh reads, the optional `meshes` extra) or given directly, and checked.

A mesh is (vertices float64 [V, 3], faces int64 [F, 3], uvs float64 [V, 2] or
None).  Faces with no area (two equal vertices, or three in a line) are left out:
they cannot be hit and have no normal.  A file of several objects or materials
becomes one mesh; the scene's material covers all of it.
"""
from pathlib import Path

import numpy as np

from ..errors import FieldError

INSTALL = "pip install 'rtweekend[meshes]'"


def read(path):
    """(vertices, faces, uvs) of the mesh file at path (FieldError on `file`)."""
    try:
        import trimesh
    except ImportError:
        raise FieldError("file", f"reading mesh files needs trimesh: {INSTALL}") from None
    path = Path(path)
    if not path.is_file():
        raise FieldError("file", f"no such mesh file: {path}")
    try:
        # force="mesh": a file of several objects is concatenated into one mesh;
        # process=False: the file's vertices as they are (and their uvs with them).
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except Exception as e:          # trimesh raises many kinds for a file it cannot read
        why = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise FieldError("file", f"cannot read the mesh {path}: {why}") from None
    faces = getattr(mesh, "faces", None)
    if faces is None or len(faces) == 0:
        raise FieldError("file", f"{path} holds no triangles")
    uvs = getattr(getattr(mesh, "visual", None), "uv", None)
    return np.asarray(mesh.vertices), np.asarray(faces), uvs


def check(vertices, faces, uvs=None, where="mesh"):
    """Clean copies of the arrays, or FieldError naming what is wrong:
    vertices finite [V, 3], faces [F, 3] of indices below V, uvs [V, 2] finite;
    faces without area dropped (at least one must remain)."""
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
    return v, f[keep], uvs


def areas(vertices, faces):
    """float64 [F]: each triangle's area."""
    e1 = vertices[faces[:, 1]] - vertices[faces[:, 0]]
    e2 = vertices[faces[:, 2]] - vertices[faces[:, 0]]
    return 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
