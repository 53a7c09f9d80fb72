"""Write models/knot.obj: a (2, 3) torus knot, a tube of triangles with vertex
normals, for the bundled scene cornell_mesh.

    python scenes/make_knot.py > scenes/models/knot.obj

Made here rather than downloaded so that the scene ships whole.  The knot's
centre line is ((2 + cos 3t) cos 2t, (2 + cos 3t) sin 2t, sin 3t) (radius 3
around the origin); a circle of radius TUBE follows it in the frame of its
tangent, sampled at SEGMENTS x SIDES points.
"""
import math
import sys

import numpy as np

SEGMENTS, SIDES, TUBE = 200, 14, 0.45


def centre(t):
    return np.stack([(2 + np.cos(3 * t)) * np.cos(2 * t), (2 + np.cos(3 * t)) * np.sin(2 * t),
                     np.sin(3 * t)], axis=-1)


def knot():
    t = np.arange(SEGMENTS) * 2 * math.pi / SEGMENTS
    c = centre(t)
    tangent = centre(t + 1e-4) - centre(t - 1e-4)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    normal = centre(t + 1e-4) + centre(t - 1e-4) - 2 * c      # towards the curvature
    normal -= (normal * tangent).sum(axis=1, keepdims=True) * tangent
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    binormal = np.cross(tangent, normal)
    a = np.arange(SIDES) * 2 * math.pi / SIDES
    ring = (np.cos(a)[None, :, None] * normal[:, None, :] +
            np.sin(a)[None, :, None] * binormal[:, None, :])          # [SEGMENTS, SIDES, 3]
    vertices = (c[:, None, :] + TUBE * ring).reshape(-1, 3)
    normals = ring.reshape(-1, 3)
    faces = []
    for i in range(SEGMENTS):
        for j in range(SIDES):
            a0 = i * SIDES + j
            a1 = i * SIDES + (j + 1) % SIDES
            b0 = (i + 1) % SEGMENTS * SIDES + j
            b1 = (i + 1) % SEGMENTS * SIDES + (j + 1) % SIDES
            faces += [(a0, b0, b1), (a0, b1, a1)]
    faces = np.array(faces)
    # Counter-clockwise seen from outside: the face normal along the vertex normals.
    v = vertices
    n = np.cross(v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]])
    inward = (n * normals[faces].sum(axis=1)).sum(axis=1) < 0
    faces[inward] = faces[inward][:, ::-1]
    return vertices, normals, faces


def main(out=sys.stdout):
    vertices, normals, faces = knot()
    out.write(f"# A (2, 3) torus knot: {len(vertices)} vertices, {len(faces)} triangles "
              "(scenes/make_knot.py)\n")
    out.writelines(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in vertices)
    out.writelines(f"vn {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in normals)
    out.writelines(f"f {a + 1}//{a + 1} {b + 1}//{b + 1} {c + 1}//{c + 1}\n" for a, b, c in faces)


if __name__ == "__main__":
    main()
