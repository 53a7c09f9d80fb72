"""The OBJ readers (io/obj.py compiled, io/obj_lines.py for small plain
files) against trimesh: the same triangles, texture coordinates and normals,
numbers parsed exactly as Python's float() parses them, and trimesh's turn
for what they do not read; the two readers' tables the same, bit for bit."""
import math

import numpy as np
import pytest

from rtweekend.io import obj, obj_lines
from rtweekend.scene import meshes

import rtweekend as rt

from test_meshes import GREY, sphere_mesh


@pytest.fixture(autouse=True, params=["lines", "compiled"])
def reader(request, monkeypatch):
    """Each test with small files read in Python, then by the compiled scan."""
    if request.param == "compiled":
        monkeypatch.setattr(obj_lines, "MAX_BYTES", -1)
    return request.param


def _corners(mesh):
    """Each triangle's corners (x, y, z[, u, v][, nx, ny, nz]) turned to start
    at its smallest (the winding kept), the triangles sorted: a form that
    depends neither on how vertices are shared nor on which corner a
    polygon's triangles start from (trimesh starts a quad's second at its
    third corner)."""
    v, f, uv, n = mesh
    parts = [v[f]]
    if uv is not None:
        parts.append(uv[f])
    if n is not None:
        parts.append(n[f])
    corners = np.concatenate(parts, axis=2)                 # [F, 3, columns]
    rows = []
    for tri in corners:
        first = min(range(3), key=lambda i: tuple(tri[i]))
        rows.append(np.roll(tri, -first, axis=0).ravel())
    rows = np.array(rows)
    return rows[np.lexsort(rows.T[::-1])]


def _same_as_trimesh(path):
    pytest.importorskip("trimesh", reason="needs the meshes extra")
    ours, theirs = obj.read(path), meshes.read_with_trimesh(path)
    assert ours is not None
    for a, b in zip(ours[2:], theirs[2:]):
        assert (a is None) == (b is None)
    np.testing.assert_array_equal(_corners(ours), _corners(theirs))
    return ours


def test_positions_faces_uvs_and_normals_are_trimeshs(tmp_path):
    v, f = sphere_mesh(9, 17, radius=1.7, center=(0.1, -2.0, 3.0))
    rng = np.random.default_rng(1)
    uv = rng.random((len(v), 2))
    n = v / np.linalg.norm(v, axis=1, keepdims=True)
    lines = ["# a sphere", "mtllib none.mtl", "o ball", "g part"]
    lines += [f"v {x:.9g} {y:.6f} {z:.12e}" for x, y, z in v]
    lines += [f"vt {a:.7f} {b:.7f}" for a, b in uv]
    lines += [f"vn {a:.6f} {b:.6f} {c:.6f}" for a, b, c in n]
    lines += ["usemtl shiny", "s 1"]
    lines += ["f " + " ".join(f"{i + 1}/{i + 1}/{i + 1}" for i in face) for face in f]
    (tmp_path / "full.obj").write_text("\n".join(lines) + "\n")
    _same_as_trimesh(tmp_path / "full.obj")
    # Positions only, CRLF line ends, a quad and a pentagon (fans).
    text = ("v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\nv -0.5 0.5 0\r\n"
            "f 1 2 3 4\r\nf 1 4 5\r\nf 1 2 3 4 5\r\n")
    (tmp_path / "poly.obj").write_text(text)
    v, f, uv, n = _same_as_trimesh(tmp_path / "poly.obj")
    assert len(f) == 2 + 1 + 3 and uv is None and n is None


def test_corners_that_name_different_normals_make_vertices_of_their_own(tmp_path):
    # A hard edge: the two faces share positions but not normals.
    text = ("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.5\nvn 0 0 1\nvn 0 -0.5 1\n"
            "f 1//1 2//1 3//1\nf 2//2 4//2 3//2\n")
    (tmp_path / "crease.obj").write_text(text)
    v, f, uv, n = _same_as_trimesh(tmp_path / "crease.obj")
    assert len(v) == 6 and uv is None
    # Negative indices count back from the vertices read so far, as the format
    # says; 'v/vt' corners.
    text = ("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf -3/-3 -2/-2 -1/-1\n"
            "v 5 0 0\nv 6 0 0\nv 5 1 0\nf -3/1 -2/2 -1/3\n")
    (tmp_path / "relative.obj").write_text(text)
    v, f, uv, n = obj.read(tmp_path / "relative.obj")
    np.testing.assert_array_equal(v[f], [[[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                                         [[5, 0, 0], [6, 0, 0], [5, 1, 0]]])
    np.testing.assert_array_equal(uv[f], [[[0, 0], [1, 0], [0, 1]]] * 2)


def test_numbers_are_parsed_as_python_parses_them(tmp_path):
    rng = np.random.default_rng(7)
    x = np.concatenate([rng.normal(size=3000) * 10.0 ** rng.integers(-12, 12, 3000),
                        [0.1, 0.2, 0.3, 1e-22, 9.999999999999999e22, 123456789012345.0]])
    words = [f"{a:.{int(p)}g}" for a, p in zip(x, rng.integers(1, 16, len(x)))]
    words += ["-0.0", "+5", "5.", ".5", "1E3", "-2.5e-3", "0.000000", "007.50",
              "0.12345678901234567", "1e300", "-4.9e-324", "123456789012345678901234"]
    words += [f"{a:.6f}" for a in x[:200]]
    words = words[: len(words) // 3 * 3]
    lines = [f"v {a} {b} {c}" for a, b, c in zip(*[iter(words)] * 3)]
    (tmp_path / "numbers.obj").write_text("\n".join(lines) + "\nf 1 2 3\n")
    v, f, _, _ = obj.read(tmp_path / "numbers.obj")
    expect = np.array([float(w) for w in words]).reshape(-1, 3)
    assert np.array_equal(v.view(np.int64), expect.view(np.int64))   # -0.0 too
    assert math.copysign(1.0, v.ravel()[words.index("-0.0")]) == -1.0


@pytest.mark.parametrize("text", [
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n3\n",                       # continued line
    "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "v 1.5x 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2/ 3/\n",
    "vt 0.5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",                     # a 1-D texture
])
def test_what_it_cannot_read_exactly_is_left_to_trimesh(tmp_path, text):
    (tmp_path / "odd.obj").write_text(text)
    with pytest.raises(obj.Unread, match=r"odd.obj, line [14]: "):
        obj.read(tmp_path / "odd.obj")


def test_a_comment_ends_any_line(tmp_path):
    # Exporters put comments after faces ('f 1 2 3 # tri'), which sent the file
    # to trimesh (and failed there: "could not be read to its end").
    text = ("v 0 0 0 # origin\nv 1 0 0#x\nv 0 1 0\t# y\nvt 0 0 # uv\nvt 1 0\nvt 0 1#\n"
            "vn 0 0 1 # up\nf 1/1/1 2/2/1 3/3/1 # tri\nf 1/1/1 3/3/1 2/2/1#back\n"
            "# a comment \\\nf 2/2/1 3/3/1 1/1/1 #\n")
    (tmp_path / "notes.obj").write_text(text)
    v, f, uv, n = obj.read(tmp_path / "notes.obj")
    np.testing.assert_array_equal(v[f], [[[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                                         [[0, 0, 0], [0, 1, 0], [1, 0, 0]],
                                         [[1, 0, 0], [0, 1, 0], [0, 0, 0]]])
    np.testing.assert_array_equal(uv[f][0], [[0, 0], [1, 0], [0, 1]])
    np.testing.assert_array_equal(n, [[0, 0, 1]] * len(v))
    # A comment where a number should be: too few numbers, on that line.
    (tmp_path / "short.obj").write_text("v 0 0 0\nv 1 0 # z?\n")
    with pytest.raises(obj.Unread, match=r"short.obj, line 2: too few numbers after 'v'$"):
        obj.read(tmp_path / "short.obj")


@pytest.mark.parametrize("face, message", [
    ("f 0 1 2", "line 7: corner '0' names vertex 0 (OBJ indices start at 1, or count back "
                "from -1)"),
    ("f 1 2 4", "line 7: corner '4' names vertex 4, but the file has 3 vertices"),
    ("f 1 2 3\nf 1 2 3 1 9", "line 8: corner '9' names vertex 9, but the file has 3 vertices"),
    ("f -1 -2 -4", "line 7: corner '-4' counts back 4 vertices, but 3 are before this line"),
    ("f 1/1/1 2/2/1 3/3/1", "line 7: corner '2/2/1' names texture coordinate 2, but the "
                            "file has 1 texture coordinate"),
    ("f 1/1/1 2/1/1 3/1/-2", "line 7: corner '3/1/-2' counts back 2 normals, but 1 is "
                             "before this line"),
    ("f 1//1 2//0 3//1", "line 7: corner '2//0' names normal 0 (OBJ indices"),
])
def test_a_face_naming_what_the_file_does_not_have_names_its_line(tmp_path, face, message):
    # Such a face was left for the mesh check, which named it after fan
    # triangulation, zero-based, 0 shown as -1 ("face 0 refers to vertex [-1,
    # 0, 1]"), and a uv or normal out of range dropped every uv or normal.
    text = f"# made by hand\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n{face}\n"
    (tmp_path / "bad.obj").write_text(text)
    with pytest.raises(obj.ObjError) as e:
        obj.read(tmp_path / "bad.obj")
    assert not isinstance(e.value, obj.Unread)
    assert str(e.value).startswith(f"{tmp_path / 'bad.obj'}, line ")
    assert message in str(e.value), str(e.value)


def test_an_obj_file_is_read_without_trimesh(tmp_path, monkeypatch):
    import builtins
    real = builtins.__import__

    def no_trimesh(name, *args, **kwargs):
        if name == "trimesh" or name.startswith("trimesh."):
            raise ImportError(name)
        return real(name, *args, **kwargs)
    monkeypatch.setattr(builtins, "__import__", no_trimesh)
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    v, f, _, _ = meshes.read(tmp_path / "tri.obj")
    assert f.tolist() == [[0, 1, 2]]
    (tmp_path / "tri.ply").write_text("ply\n")
    with pytest.raises(Exception, match="needs trimesh"):
        meshes.read(tmp_path / "tri.ply")
    # A line it does not read: named, not "reading mesh files needs trimesh".
    assert _odd_corner_error(tmp_path, "1/") == (
        f"{_corner_not_read(tmp_path, '1/')}, which rtweekend's OBJ reader does not read; "
        f"trimesh may: {meshes.INSTALL}")


def _odd_corner_error(tmp_path, corner):
    """rt.mesh's error for a file whose fifth line has a face corner `corner`."""
    (tmp_path / "odd.obj").write_text(f"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf {corner} 2 3\n")
    with pytest.raises(rt.SceneError) as e:
        rt.mesh(tmp_path / "odd.obj", GREY)
    return str(e.value)


def _corner_not_read(tmp_path, corner):
    return (f"mesh: file: {tmp_path / 'odd.obj'}, line 5: '{corner}' is not a face corner "
            f"(v, v/vt, v//vn or v/vt/vn)")


def test_a_line_neither_reader_reads_is_named_by_the_obj_readers_message(tmp_path):
    # trimesh's own error for such a file ("string or file could not be read to
    # its end due to unmatched data") names no line.
    pytest.importorskip("trimesh", reason="needs the meshes extra")
    assert _odd_corner_error(tmp_path, "1/x") == (
        f"{_corner_not_read(tmp_path, '1/x')}, which neither rtweekend's OBJ reader nor "
        f"trimesh reads")


def test_a_mesh_file_too_big_for_memory_is_refused_before_it_is_read(tmp_path, monkeypatch):
    from rtweekend import memory
    import rtweekend as rt
    v, f = sphere_mesh(30, 60)
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in v]
    lines += ["f " + " ".join(str(i + 1) for i in face) for face in f]
    (tmp_path / "ball.obj").write_text("\n".join(lines) + "\n")
    monkeypatch.setattr(memory, "available", lambda: (10_000, "MemAvailable"))
    made = []
    monkeypatch.setattr(obj.np, "empty", lambda *a, **k: made.append(a))
    with pytest.raises(rt.SceneError, match=rf"file: .*ball.obj: its {len(f):,} triangles need "
                       r"about [0-9.]+ kB of memory to read, and 10.0 kB is available "
                       r"\(MemAvailable\)"):
        rt.mesh(tmp_path / "ball.obj", rt.lambertian((0.5, 0.5, 0.5)))
    assert made == []                    # refused after counting, before any table
    pytest.importorskip("trimesh", reason="needs the meshes extra")
    (tmp_path / "ball.ply").write_bytes(b"ply\n" + b"\0" * 20_000)
    with pytest.raises(rt.SceneError, match=r"ball.ply: its contents need about"):
        rt.mesh(tmp_path / "ball.ply", rt.lambertian((0.5, 0.5, 0.5)))


def _random_obj(rng):
    """A random OBJ file obj_lines reads: v, vt and vn lines of numbers
    written many ways, faces of 1 to 6 corners of one form each (indices
    forward and back), comments, lines the readers skip, CRLF or LF."""
    def number():
        x = rng.normal() * 10.0 ** rng.integers(-25, 25)
        form = rng.integers(7)
        if form == 0:
            return f"{x:.{rng.integers(1, 20)}g}"
        if form == 1:
            return f"{x:.{rng.integers(0, 12)}f}"
        if form == 2:
            return f"{x:.{rng.integers(0, 18)}E}"
        if form == 3:
            return str(int(rng.integers(-10**6, 10**6)))
        if form == 4:
            return rng.choice(["-0.0", "+5", "5.", ".5", "-.25e+2", "007.50", "0e5", "1e400",
                               "-1e-400", "123456789012345678901234", "0.30000000000000004"])
        return repr(float(x))
    lines, counts = [], [0, 0, 0]
    for _ in range(rng.integers(1, 60)):
        what = rng.integers(8)
        space = " " * int(rng.integers(1, 3)) if rng.random() < 0.8 else "\t"
        if what <= 2:
            key, width = [("v", 3), ("vt", 2), ("vn", 3)][what]
            words = [number() for _ in range(width + int(rng.random() < 0.1))]
            lines.append(key + space + space.join(words))
            counts[what] += 1
        elif what <= 5 and counts[0]:
            form = rng.integers(4)
            corners = []
            for _ in range(rng.integers(1, 7)):
                parts = []
                for s, named in enumerate((True, form in (1, 3), form in (2, 3))):
                    if named and counts[s]:
                        k = int(rng.integers(counts[s]))
                        parts.append(str(k + 1) if rng.random() < 0.7 else str(k - counts[s]))
                    else:
                        parts.append("")
                corners.append("/".join(parts).rstrip("/") if form < 2 or not parts[2]
                               else "/".join(parts))
            lines.append("f " + " ".join(corners))
        else:
            lines.append(rng.choice(["# a comment", "o thing", "g part", "s 1", "usemtl x",
                                     "", "   ", "vp 0.5", "l 1 2", "f", "v1 2 3"]))
        if rng.random() < 0.15:
            lines[-1] += rng.choice([" # note", "#x", "\t#"])
    return ("\r\n" if rng.random() < 0.3 else "\n").join(lines) + "\n"


def test_the_python_reader_gives_the_compiled_scans_tables_bit_for_bit(tmp_path):
    rng = np.random.default_rng(11)
    plain = 0
    for i in range(300):
        data = _random_obj(rng).encode()
        ours = obj_lines.read(data, lambda *counts: None)
        try:
            theirs = obj._scanned("x.obj", np.frombuffer(data, np.uint8), lambda *c: None)
        except obj.ObjError:
            assert ours is None, data          # the scan's errors are the scan's to say
            continue
        if ours is None:
            continue
        plain += 1
        for a, b in zip(ours, theirs):
            assert a.dtype == b.dtype and a.shape == b.shape
            assert a.tobytes() == b.tobytes(), data
    assert plain >= 250          # most random files are plain ones


@pytest.mark.parametrize("text", [
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n3\n",        # a backslash
    "v 1_0 0 0\n",                                          # float() reads it, the scan not
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/-/3 2 3\n",           # a corner form of the scan's own
    "v 0 0 0\nf 1 1 +1\n",
    "v 0 0 0\nf 1 1 0\n",
    "v 0 0 0\nf 1 1 2\n",
    "v 0 0 0\nf 1 -1 -2\n",
    "v 0 0 0\x0b1 0\n",
])
def test_what_is_not_plain_is_left_to_the_compiled_scan(text):
    assert obj_lines.read(text.encode(), lambda *counts: None) is None
