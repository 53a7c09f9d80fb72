"""The classic ray tracer (Computer Graphics from Scratch): pixels derived by hand,
shadows, reflections, the camera, rounding, and a NumPy twin of the whole book."""
import math

import numba
import numpy as np
import pytest

from rtweekend.classic.kernel import AMBIENT, DIRECTIONAL, POINT, classic_arrays, render_canvas


def sphere(center, radius, color, specular=-1, reflective=0.0):
    return dict(center=center, radius=radius, color=color, specular=specular,
                reflective=reflective)


# The book's reflections demo (raytracer-05): red, blue, green, yellow floor.
DEMO_SPHERES = [
    sphere((0, -1, 3), 1, (255, 0, 0), 500, 0.2),
    sphere((2, 0, 4), 1, (0, 0, 255), 500, 0.3),
    sphere((-2, 0, 4), 1, (0, 255, 0), 10, 0.4),
    sphere((0, -5001, 0), 5000, (255, 255, 0), 1000, 0.5),
]
DEMO_LIGHTS = [
    dict(type="ambient", intensity=0.2),
    dict(type="point", intensity=0.6, position=(2, 1, 0)),
    dict(type="directional", intensity=0.2, direction=(1, 4, 4)),
]
# The book's camera demo (raytracer-06): moved and turned 45 degrees about y.
BOOK_POSITION = (3, 0, 1)
BOOK_ROTATION = [[0.7071, 0, -0.7071], [0, 1, 0], [0.7071, 0, 0.7071]]
# 90 degrees about y: the camera's forward z becomes world +x, its right x world -z.
TURN_Y = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])


def render(spheres, lights, width, height, depth=3, **camera):
    return render_canvas(*classic_arrays(spheres, lights), width, height, depth, **camera)


# ---------------------------------------------------------------------------
# The twin: the book's algorithm again, in NumPy over all rays at once, with
# TraceRay recursive as the book writes it.  Independent of classic.py.

def twin_roots(spheres, Orig, D):
    """IntersectRaySphere for every ray (rows of Orig, D: the book's O, D) and
    every sphere: t1, t2 [M, N]."""
    C = np.array([s["center"] for s in spheres], dtype=float)
    r = np.array([s["radius"] for s in spheres], dtype=float)
    OC = Orig[:, None, :] - C[None, :, :]
    k1 = np.sum(D * D, axis=1)[:, None]
    k2 = 2 * np.sum(OC * D[:, None, :], axis=2)
    k3 = np.sum(OC * OC, axis=2) - r * r
    disc = k2 * k2 - 4 * k1 * k3
    sq = np.sqrt(np.maximum(disc, 0.0))
    t1 = np.where(disc < 0, np.inf, (-k2 + sq) / (2 * k1))
    t2 = np.where(disc < 0, np.inf, (-k2 - sq) / (2 * k1))
    return t1, t2


def twin_closest(spheres, Orig, D, t_min, t_max):
    """ClosestIntersection: (sphere index or -1, t) per ray."""
    t1, t2 = twin_roots(spheres, Orig, D)
    closest_t = np.full(len(Orig), np.inf)
    closest = np.full(len(Orig), -1)
    for k in range(len(spheres)):
        for ts in (t1[:, k], t2[:, k]):
            better = (ts < closest_t) & (t_min < ts) & (ts < t_max)
            closest_t = np.where(better, ts, closest_t)
            closest = np.where(better, k, closest)
    return closest, closest_t


def twin_lighting(spheres, lights, P, N, V, s):
    """ComputeLighting per point; s: specular exponent per point."""
    i = np.zeros(len(P))
    for light in lights:
        if light["type"] == "ambient":
            i += light["intensity"]
            continue
        if light["type"] == "point":
            L, t_max = np.asarray(light["position"], dtype=float) - P, 1.0
        else:
            L, t_max = np.broadcast_to(np.asarray(light["direction"], dtype=float), P.shape), np.inf
        blocker, _ = twin_closest(spheres, P, L, 0.001, t_max)
        lit = blocker < 0
        n_dot_l = np.sum(N * L, axis=1)
        diffuse = n_dot_l / (np.linalg.norm(N, axis=1) * np.linalg.norm(L, axis=1))
        i += np.where(lit & (n_dot_l > 0), light["intensity"] * diffuse, 0.0)
        R = 2 * N * n_dot_l[:, None] - L
        r_dot_v = np.sum(R * V, axis=1)
        shiny = lit & (s != -1) & (r_dot_v > 0)
        base = np.where(shiny, r_dot_v / (np.linalg.norm(R, axis=1) * np.linalg.norm(V, axis=1)),
                        1.0)
        i += np.where(shiny, light["intensity"] * base ** s, 0.0)
    return i


def twin_trace(spheres, lights, Orig, D, t_min, t_max, depth, bg):
    """TraceRay for every ray: colours [M, 3] on the 0..255 scale."""
    color = np.tile(np.asarray(bg, dtype=float), (len(Orig), 1))
    k, t = twin_closest(spheres, Orig, D, t_min, t_max)
    hit = k >= 0
    if not hit.any():
        return color
    k, Orig, D = k[hit], Orig[hit], D[hit]
    P = Orig + t[hit][:, None] * D
    N = P - np.array([spheres[j]["center"] for j in k], dtype=float)
    N = N / np.linalg.norm(N, axis=1)[:, None]
    V = -D
    s = np.array([spheres[j]["specular"] for j in k], dtype=float)
    local = (np.array([spheres[j]["color"] for j in k], dtype=float)
             * twin_lighting(spheres, lights, P, N, V, s)[:, None])
    r = np.array([spheres[j]["reflective"] for j in k], dtype=float)
    mirror = r > 0
    if depth > 0 and mirror.any():
        Vm, Nm = V[mirror], N[mirror]
        R = 2 * Nm * np.sum(Nm * Vm, axis=1)[:, None] - Vm        # ReflectRay(V, N)
        reflected = twin_trace(spheres, lights, P[mirror], R, 0.001, np.inf, depth - 1, bg)
        rm = r[mirror][:, None]
        local[mirror] = local[mirror] * (1 - rm) + reflected * rm
    color[hit] = local
    return color


def twin_render(spheres, lights, width, height, depth, background=(0, 0, 0),
                position=(0, 0, 0), rotation=None, viewport=(1, 1), d=1.0):
    """The book's main loop: canvas x in [-Cw/2, Cw/2), y in [-Ch/2, Ch/2)
    (JavaScript's real division, so half-integers for odd sizes), PutPixel at
    column Cw/2 + x, row Ch/2 - y - 1, stored as a Uint8ClampedArray does."""
    x = -width / 2 + np.arange(width)
    y = -height / 2 + np.arange(height)
    X, Y = np.meshgrid(x, y)
    viewport_points = np.stack([X * viewport[0] / width, Y * viewport[1] / height,
                                np.full(X.shape, float(d))], axis=-1).reshape(-1, 3)
    rotation = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
    D = viewport_points @ rotation.T
    Orig = np.tile(np.asarray(position, dtype=float), (len(D), 1))
    color = twin_trace(spheres, lights, Orig, D, 1.0, np.inf, depth, background)
    image = np.zeros((height, width, 3), dtype=np.uint8)
    cols = (width / 2 + X).astype(int).reshape(-1)
    rows = (height / 2 - Y - 1).astype(int).reshape(-1)
    image[rows, cols] = np.clip(np.rint(color), 0, 255)
    return image


def assert_close_images(a, b, max_pixels, flips=0):
    """Equal but for at most max_pixels pixels off by one level, and `flips`
    pixels off by any amount (a ray exactly on a shadow or silhouette edge)."""
    assert a.shape == b.shape
    diff = np.abs(a.astype(int) - b.astype(int)).max(axis=2)
    assert np.count_nonzero(diff > 1) <= flips, f"largest difference {diff.max()}"
    assert np.count_nonzero(diff) <= max_pixels + flips


# ---------------------------------------------------------------------------

def test_classic_arrays_layout():
    sph_f, light_i, light_f = classic_arrays(DEMO_SPHERES, DEMO_LIGHTS)
    assert sph_f.shape == (4, 9) and sph_f.dtype == np.float64
    assert sph_f[2].tolist() == [-2, 0, 4, 1, 0, 255, 0, 10, 0.4]
    assert light_i.dtype == np.int64 and light_i.tolist() == [AMBIENT, POINT, DIRECTIONAL]
    assert light_f.shape == (3, 4) and light_f.dtype == np.float64
    assert light_f.tolist() == [[0.2, 0, 0, 0], [0.6, 2, 1, 0], [0.2, 1, 4, 4]]
    empty = classic_arrays([], [])
    assert empty[0].shape == (0, 9) and empty[1].shape == (0,) and empty[2].shape == (0, 4)


# On a 4x4 canvas, canvas (0, -2) is column 2, row 3: D = (0, -1/2, 1), which
# meets the red sphere (center (0,-1,3), r 1) at t = 2:
#   a = <D,D> = 5/4, <OC,D> = -7/2, c = |OC|^2 - 1 = 9: t = (7/2 - 1) / (5/4) = 2,
# so P = (0, -1, 2), N = (0, 0, -1), V = -D = (0, 1/2, -1).
# A point light at (0, -1, 0) gives L = P->light = (0, 0, -2):
#   diffuse  <N,L>/|L| = 2/2 = 1;  R = 2N<N,L> - L = (0, 0, -2);
#   specular <R,V>/(|R||V|) = 2 / (2 sqrt(5/4)) = 2/sqrt(5), to the 10th = (4/5)^5.
P_ROW, P_COL = 3, 2
FRONT_LIGHT = dict(type="point", intensity=0.6, position=(0, -1, 0))
AMBIENT_02 = dict(type="ambient", intensity=0.2)


def test_lit_pixel_matches_the_formulas_by_hand():
    color = (255, 128, 0)
    diffuse = 0.6 * 2 / 2
    specular = 0.6 * (2 / (2 * math.sqrt(5 / 4))) ** 10
    assert specular == pytest.approx(0.6 * 0.8 ** 5)

    matte = render([sphere((0, -1, 3), 1, color)], [AMBIENT_02, FRONT_LIGHT], 4, 4)
    i = 0.2 + diffuse                                     # 0.8
    assert matte[P_ROW, P_COL].tolist() == [round(255 * i), round(128 * i), 0]   # 204, 102

    shiny = render([sphere((0, -1, 3), 1, color, specular=10)], [AMBIENT_02, FRONT_LIGHT], 4, 4)
    i = 0.2 + diffuse + specular                          # 0.996608
    assert shiny[P_ROW, P_COL].tolist() == [round(255 * i), round(128 * i), 0]   # 254, 128

    # Half a mirror: its reflected ray ReflectRay(V, N) = (0, -1/2, -1) escapes,
    # so the pixel is half the local colour and half the background.
    bg = (0, 0, 200)
    mirror = render([sphere((0, -1, 3), 1, color, specular=10, reflective=0.5)],
                    [AMBIENT_02, FRONT_LIGHT], 4, 4, depth=1, background=bg)
    assert mirror[P_ROW, P_COL].tolist() == [round(0.5 * 255 * i), round(0.5 * 128 * i),
                                             round(0.5 * 200)]                   # 127, 64, 100


def test_canvas_centre_grazes_the_top_of_the_red_sphere():
    # Canvas (0, 0) = column 2, row 1 of a 4x4 canvas; D = (0, 0, 1) touches the
    # red sphere at its top: <OC,D>^2 - a c = 9 - 9 = 0, t = 3, P = (0, 0, 3),
    # N = (0, 1, 0).  The book's light at (2, 1, 0): L = (2, 1, -3), <N,L> = 1,
    # |L| = sqrt(14); R = 2N - L = (-2, 1, 3) faces away from V = (0, 0, -1).
    image = render([sphere((0, -1, 3), 1, (255, 0, 0), specular=500)],
                   [AMBIENT_02, dict(type="point", intensity=0.6, position=(2, 1, 0))], 4, 4)
    i = 0.2 + 0.6 * 1 / math.sqrt(14)                     # 0.36036
    assert image[1, 2].tolist() == [round(255 * i), 0, 0]                     # 92, 0, 0
    assert image[0].tolist() == [[0, 0, 0]] * 4           # the row above: sky


def test_shadow_leaves_only_the_ambient_term():
    red = sphere((0, -1, 3), 1, (255, 0, 0), specular=10)
    # Both on the line from P towards the light: one between (t in 0.375..0.625),
    # one past the light (t in 1.375..1.625, outside the shadow ray's (0.001, 1)).
    between = sphere((0, -1, 1), 0.25, (0, 255, 0))
    beyond = sphere((0, -1, -1), 0.25, (0, 255, 0))
    lights = [AMBIENT_02, FRONT_LIGHT]
    lit = render([red], lights, 4, 4)[P_ROW, P_COL, 0]
    assert lit == 254                                     # 255 x (0.2 + 0.6 + 0.6 (4/5)^5)
    assert render([red, between], lights, 4, 4)[P_ROW, P_COL].tolist() == [51, 0, 0]   # 255 x 0.2
    assert render([red, beyond], lights, 4, 4)[P_ROW, P_COL, 0] == lit

    # A directional light along the same line is blocked at any distance.
    sun = [AMBIENT_02, dict(type="directional", intensity=0.6, direction=(0, 0, -1))]
    assert render([red], sun, 4, 4)[P_ROW, P_COL, 0] == lit    # L = (0,0,-1): same terms
    assert render([red, beyond], sun, 4, 4)[P_ROW, P_COL].tolist() == [51, 0, 0]


def test_rounding_half_to_even_and_clamping():
    # Ambient light only: each channel is color x intensity exactly.
    big = [sphere((0, 0, 5), 3, (255, 253, 1))]
    half = render(big, [dict(type="ambient", intensity=0.5)], 2, 2)
    assert half.dtype == np.uint8 and half.shape == (2, 2, 3)
    assert (half == [128, 126, 0]).all()                  # 127.5, 126.5, 0.5 -> even
    assert (render(big, [dict(type="ambient", intensity=2.0)], 2, 2) == [255, 255, 2]).all()
    assert (render(big, [dict(type="ambient", intensity=-1.0)], 2, 2) == 0).all()
    # No spheres: every ray shows the background, rounded the same way.
    sky = render([], [], 3, 2, background=(0.5, 1.5, 300.0))
    assert sky.shape == (2, 3, 3) and (sky == [0, 2, 255]).all()


def test_depth_changes_only_pixels_that_see_a_mirror():
    # Red and the floor are matte here; green and blue reflect.
    spheres = [dict(s, reflective=0.0) if s["color"] in [(255, 0, 0), (255, 255, 0)] else s
               for s in DEMO_SPHERES]
    w = h = 48
    flat = render(spheres, DEMO_LIGHTS, w, h, depth=0)
    once = render(spheres, DEMO_LIGHTS, w, h, depth=1)
    # Which sphere each primary ray sees, from the twin.
    x, y = np.meshgrid(-w / 2 + np.arange(w), h / 2 - np.arange(h) - 1)
    D = np.stack([x / w, y / h, np.ones_like(x)], axis=-1).reshape(-1, 3)
    first, _ = twin_closest(spheres, np.zeros_like(D), D, 1.0, np.inf)
    first = first.reshape(h, w)
    sees_mirror = np.isin(first, [1, 2])
    assert 100 < np.count_nonzero(sees_mirror) < w * h - 100
    changed = (flat != once).any(axis=2)
    assert not changed[~sees_mirror].any()
    assert np.count_nonzero(changed[sees_mirror]) > 0.9 * np.count_nonzero(sees_mirror)


@pytest.mark.parametrize("size, camera", [
    ((48, 48), {}),
    ((40, 40), dict(position=BOOK_POSITION, rotation=BOOK_ROTATION)),
    ((33, 27), dict(position=(0.5, 1.0, -1.0), viewport=(1.5, 1.0), d=1.2, background=(10, 20, 30),
                    rotation=[[0.96, -0.28, 0.0], [0.28, 0.96, 0.0], [0.0, 0.0, 1.0]])),
], ids=["book", "book-camera", "odd-size-tilted"])
def test_matches_the_numpy_twin(size, camera):
    w, h = size
    ours = render(DEMO_SPHERES, DEMO_LIGHTS, w, h, depth=3, **camera)
    twin = twin_render(DEMO_SPHERES, DEMO_LIGHTS, w, h, 3, **camera)
    assert_close_images(ours, twin, max_pixels=3)


def test_book_figure_at_full_size_matches_the_twin():
    ours = render(DEMO_SPHERES, DEMO_LIGHTS, 600, 600, depth=3)
    twin = twin_render(DEMO_SPHERES, DEMO_LIGHTS, 600, 600, 3)
    assert_close_images(ours, twin, max_pixels=60)        # 60 of 360,000 pixels
    # The figure itself: red front and centre-bottom, green left, blue right, black sky.
    assert ours[420, 300].argmax() == 0
    assert ours[260, 40].argmax() == 1
    assert ours[260, 560].argmax() == 2
    assert (ours[20] == 0).all()


def test_camera_turned_90_degrees_about_y_looks_along_x():
    ball = sphere((4, 0, 0), 1, (255, 255, 255))
    lights = [dict(type="ambient", intensity=1.0)]
    assert (render([ball], lights, 8, 8) == 0).all()      # behind the default camera's view
    turned = render([ball], lights, 8, 8, rotation=TURN_Y)
    assert (turned[3:5, 3:5] == 255).all() and (turned[0] == 0).all()
    # The camera's right (canvas +x) is world -z.
    right = render([sphere((4, 0, -1.5), 0.5, (255, 255, 255))], lights, 8, 8, rotation=TURN_Y)
    assert right[:, 4:].any() and not right[:, :4].any()


def test_moving_the_camera_equals_moving_the_scene():
    # Turn and shift the whole scene by (TURN_Y, shift), and the camera with it:
    # the same picture (all coordinates stay exact; only sums change order).
    shift = np.array([1.0, 2.0, -3.0])

    def moved(p):
        return tuple(TURN_Y @ np.asarray(p, dtype=float) + shift)

    spheres = [dict(s, center=moved(s["center"])) for s in DEMO_SPHERES]
    lights = [dict(light, position=moved(light["position"])) if "position" in light else
              dict(light, direction=tuple(TURN_Y @ np.asarray(light["direction"], dtype=float)))
              if "direction" in light else light for light in DEMO_LIGHTS]
    here = render(DEMO_SPHERES, DEMO_LIGHTS, 64, 64)
    there = render(spheres, lights, 64, 64, position=shift, rotation=TURN_Y)
    # Pixel (45, 4) sees the green sphere at a point whose shadow ray to the
    # point light is exactly tangent to the red sphere (discriminant 0): the
    # last bit decides lit or not, so it may flip.
    assert_close_images(here, there, max_pixels=8, flips=1)


def test_thread_count_does_not_change_a_bit():
    previous = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = render(DEMO_SPHERES, DEMO_LIGHTS, 64, 48, position=BOOK_POSITION,
                     rotation=BOOK_ROTATION)
        numba.set_num_threads(2)
        two = render(DEMO_SPHERES, DEMO_LIGHTS, 64, 48, position=BOOK_POSITION,
                     rotation=BOOK_ROTATION)
    finally:
        numba.set_num_threads(previous)
    assert np.array_equal(one, two)
