"""Wavefront OBJ files, read by compiled code: the common subset, fast.

A million-triangle OBJ is 50 MB of text; trimesh reads it in Python and NumPy,
a large part of a whole render of it.  This reads the
lines rtweekend needs -- `v`, `vt`, `vn` and `f` (polygons as fans, corners
`v`, `v/vt`, `v//vn`, `v/vt/vn`, negative indices counted back from the
vertices read so far) -- and skips the rest (`o`, `g`, `s`, `usemtl`,
`mtllib`, `l`, comments; a `#` ends any line).  Anything else -- a line
continued with a backslash, a word where a number should be (`nan`), a
corner of another form -- raises Unread naming the line, and the caller
reads the file with trimesh instead (meshes.read).  A face naming index 0,
or a vertex, texture coordinate or normal the file does not have, raises
ObjError naming the line (trimesh would not say where, or take 0 as -1).

Numbers are correctly rounded, as Python's float() rounds them: a decimal of
at most 15 significant digits is an integer m < 2^53 times 10^e, and with
|e| <= 22 both are exact doubles, so m x 10^e (or m / 10^-e) is one rounding
(Clinger's fast path); the few others are handed to float() itself.

A corner that names a texture coordinate or a normal makes a vertex of its
own for each different (v, vt, vn) it names, as trimesh does; uvs and normals
are given only when every corner names one.

The reader's parts (a number, an index, a corner) are steps (jit_step, exact:
no fastmath), typed once and inlined into _scan as IR: compiled as functions
of their own, each with its wrapper and reference counting, they made the
first read of a file and every read slower (benchmarks/results/measurements.md).
"""
import numpy as np

from ..kernel.jit import jit_host, jit_step
from . import obj_lines

MAX_DIGITS = 15
MAX_EXP10 = 22
_POW10 = np.array([10.0 ** i for i in range(MAX_EXP10 + 1)])

# What a line is, by its first word.
OTHER, V, VT, VN, F = 0, 1, 2, 3, 4


@jit_step(exact=True)
def _space(c):
    return c == 32 or c == 9 or c == 13


@jit_step(exact=True)
def _kind(text, i, n):
    """(kind, position after the word) of the line that starts at i."""
    while i < n and _space(text[i]):
        i += 1
    if i >= n:
        return OTHER, i
    c = text[i]
    if c == 118:                                        # v
        nxt = text[i + 1] if i + 1 < n else 10
        if _space(nxt):
            return V, i + 1
        after = text[i + 2] if i + 2 < n else 10
        if nxt == 116 and _space(after):                # vt
            return VT, i + 2
        if nxt == 110 and _space(after):                # vn
            return VN, i + 2
    elif c == 102:                                      # f
        if i + 1 >= n or _space(text[i + 1]):
            return F, i + 1
    return OTHER, i


@jit_step(exact=True)
def _end(text, i, n):
    while i < n and text[i] != 10:
        i += 1
    return i


@jit_step(exact=True)
def _stop(c):
    """Whether c ends a number or a corner: a space, or a '#' (a comment to
    the end of the line; checked here, where a word ends, rather than for
    every character of the file)."""
    return _space(c) or c == 35


EXACT, HARD, BAD = 0, 1, 2


@jit_step(exact=True)
def _number(text, i, end, pow10):
    """(value, start, next position, status) of the decimal number at i
    (spaces first): EXACT, parsed here; HARD, well formed but beyond the fast
    path (read() parses it with float()); BAD, not a number ('nan', '1.5x')."""
    while i < end and _space(text[i]):
        i += 1
    start = i
    negative = False
    if i < end and (text[i] == 45 or text[i] == 43):
        negative = text[i] == 45
        i += 1
    m = 0
    digits = 0                      # significant digits (those in m, if few enough)
    exp10 = 0
    seen = False
    fraction = False
    while i < end:
        c = text[i]
        if 48 <= c <= 57:
            seen = True
            if m > 0 or c != 48:
                digits += 1
                if digits <= MAX_DIGITS:
                    m = m * 10 + (c - 48)
                else:
                    exp10 += 1          # a digit dropped: HARD anyway
            if fraction:
                exp10 -= 1
        elif c == 46 and not fraction:
            fraction = True
        else:
            break
        i += 1
    if not seen:
        return 0.0, start, i, BAD
    if i < end and (text[i] == 101 or text[i] == 69):
        i += 1
        sign = 1
        if i < end and (text[i] == 45 or text[i] == 43):
            sign = -1 if text[i] == 45 else 1
            i += 1
        if not (i < end and 48 <= text[i] <= 57):
            return 0.0, start, i, BAD
        e = 0
        while i < end and 48 <= text[i] <= 57:
            e = min(e * 10 + (text[i] - 48), 100000)
            i += 1
        exp10 += sign * e
    if i < end and not _stop(text[i]):
        return 0.0, start, i, BAD
    if m == 0:
        value = 0.0
    elif digits > MAX_DIGITS or exp10 > MAX_EXP10 or -exp10 > MAX_EXP10:
        return 0.0, start, i, HARD
    elif exp10 >= 0:
        value = float(m) * pow10[exp10]
    else:
        value = float(m) / pow10[-exp10]
    return -value if negative else value, start, i, EXACT


# An index of a corner: not there, one, or 0 (which names nothing).
ABSENT, PRESENT, ZERO = 0, 1, 2


@jit_step(exact=True)
def _index(text, i, end, count):
    """(0-based index, next position, ABSENT/PRESENT/ZERO) of one index of a
    corner (after it: '/', a space or the end); count: the items of its kind
    read so far, which a negative index counts back from (below 0 if it
    counts back past the first)."""
    negative = False
    if i < end and text[i] == 45:
        negative = True
        i += 1
    k = 0
    seen = False
    while i < end and 48 <= text[i] <= 57:
        k = min(k * 10 + (text[i] - 48), 1 << 40)
        seen = True
        i += 1
    if not seen:
        return -1, i, ABSENT
    if k == 0:
        return -1, i, ZERO
    return (count - k) if negative else (k - 1), i, PRESENT


@jit_step(exact=True)
def _corner(text, j, end, nv, nvt, nvn):
    """((v, vt, vn), (their states), next position, ok): one corner of a
    face, -1 for an index it does not name; ok False if it is not one of the
    four forms."""
    a, j, sa = _index(text, j, end, nv)
    b, c = -1, -1
    sb, sc = ABSENT, ABSENT
    if j < end and text[j] == 47:
        b, j, sb = _index(text, j + 1, end, nvt)
        if j < end and text[j] == 47:
            c, j, sc = _index(text, j + 1, end, nvn)
            if sc == ABSENT:
                return (a, b, c), (sa, sb, sc), j, False
        elif sb == ABSENT:
            return (a, b, c), (sa, sb, sc), j, False    # 'v/' with nothing after
    ok = sa != ABSENT and (j >= end or _stop(text[j]))
    return (a, b, c), (sa, sb, sc), j, ok


# How _scan ended: read, or where it stopped.  CONTINUED, NOT_NUMBER and
# NOT_CORNER: a line this reader does not read (trimesh may); ZERO_INDEX and
# OUT_OF_RANGE: a face that names what is not in the file.
READ, CONTINUED, NOT_NUMBER, NOT_CORNER, ZERO_INDEX, OUT_OF_RANGE = range(6)


@jit_host
def _scan(text, pow10, fill, v, vt, vn, corners, hard):
    """Count (fill False) or read (fill True) the file's lines: (vertices,
    uvs, normals, triangles, numbers left to float(), status, part, line,
    word): status READ, or why it stopped at the word starting at `word` of
    the line starting at `line` (part: which index of a corner, 0 v, 1 vt,
    2 vn).  hard[h] = (kind, row, column, start, end) of each number left to
    float().  Indices beyond the file's tables are caught when filling (the
    tables' sizes known: an index may name a later line)."""
    n = text.shape[0]
    nv = nvt = nvn = nt = nh = 0
    i = 0
    while i < n:
        kind, j = _kind(text, i, n)
        end = _end(text, j, n)
        last = end - 1
        while last >= j and _space(text[last]):
            last -= 1
        if last >= j and text[last] == 92 and text[j] != 35:   # a backslash continues it
            return nv, nvt, nvn, nt, nh, CONTINUED, 0, i, last
        if kind == V or kind == VT or kind == VN:
            width = 2 if kind == VT else 3
            row = nv if kind == V else (nvt if kind == VT else nvn)
            for c in range(width):
                x, start, j, status = _number(text, j, end, pow10)
                if status == BAD:
                    return nv, nvt, nvn, nt, nh, NOT_NUMBER, 0, i, start
                if status == HARD:
                    if fill:
                        hard[nh, 0], hard[nh, 1], hard[nh, 2] = kind, row, c
                        hard[nh, 3], hard[nh, 4] = start, j
                    nh += 1
                if fill:
                    if kind == V:
                        v[nv, c] = x
                    elif kind == VT:
                        vt[nvt, c] = x
                    else:
                        vn[nvn, c] = x
            if kind == V:
                nv += 1
            elif kind == VT:
                nvt += 1
            else:
                nvn += 1
        elif kind == F:
            first = (-1, -1, -1)
            previous = (-1, -1, -1)
            m = 0
            while True:
                while j < end and _space(text[j]):
                    j += 1
                if j >= end or text[j] == 35:           # the end, or a comment
                    break
                word = j
                corner, states, j, ok = _corner(text, j, end, nv, nvt, nvn)
                if not ok:
                    return nv, nvt, nvn, nt, nh, NOT_CORNER, 0, i, word
                for s in range(3):
                    if states[s] == ZERO:
                        return nv, nvt, nvn, nt, nh, ZERO_INDEX, s, i, word
                    if states[s] == PRESENT:
                        size = v.shape[0] if s == 0 else (vt.shape[0] if s == 1
                                                          else vn.shape[0])
                        if corner[s] < 0 or (fill and corner[s] >= size):
                            return nv, nvt, nvn, nt, nh, OUT_OF_RANGE, s, i, word
                if m == 0:
                    first = corner
                elif m >= 2:                            # a fan from the first corner
                    if fill:
                        for s in range(3):
                            corners[nt, 0, s] = first[s]
                            corners[nt, 1, s] = previous[s]
                            corners[nt, 2, s] = corner[s]
                    nt += 1
                previous = corner
                m += 1
        i = end + 1
    return nv, nvt, nvn, nt, nh, READ, 0, 0, 0


class ObjError(ValueError):
    """A line of an OBJ file that is wrong: one line naming the file and the
    line (a face naming vertex 0, or one beyond the file's)."""


class Unread(ObjError):
    """A line this reader does not read (a continued line, a word where a
    number should be, a corner of another form): trimesh may."""


NAMES = (("vertex", "vertices"), ("texture coordinate", "texture coordinates"),
         ("normal", "normals"))


def _stopped(path, text, status, part, line, word, totals, seen):
    """The ObjError (or Unread) for a scan that stopped at `word` on the line
    starting at `line`."""
    number = int(np.count_nonzero(text[:line] == 10)) + 1
    stop = word
    while stop < len(text) and text[stop] not in b" \t\r\n#":
        stop += 1
    written = text[word:stop].tobytes().decode("utf-8", "replace")
    where = f"{path}, line {number}"
    if status == CONTINUED:
        return Unread(f"{where}: a line continued with a backslash")
    if status == NOT_NUMBER:
        if not written:
            keyword = text[line:word].tobytes().decode("utf-8", "replace").split()
            return Unread(f"{where}: too few numbers after {keyword[0]!r}")
        return Unread(f"{where}: {written!r} is not a number")
    if status == NOT_CORNER:
        return Unread(f"{where}: {written!r} is not a face corner (v, v/vt, v//vn or v/vt/vn)")
    one, many = NAMES[part]
    index = written.split("/")[part]
    if status == ZERO_INDEX:
        return ObjError(f"{where}: corner {written!r} names {one} 0 (OBJ indices start at 1, "
                        f"or count back from -1)")
    if index.startswith("-"):
        return ObjError(f"{where}: corner {written!r} counts back {index[1:]} {many}, but "
                        f"{seen[part]:,} {'are' if seen[part] != 1 else 'is'} before this line")
    return ObjError(f"{where}: corner {written!r} names {one} {index}, but the file has "
                    f"{totals[part]:,} {many if totals[part] != 1 else one}")


# A file this long holds more triangles than a scene needs for a BVH.
AHEAD_BYTES = 4096


def _builder_ahead():
    """A mesh this long will be searched through a BVH: a helper process
    standing by compiles the builder, if it is not compiled yet, while this
    one reads the file (a large one by the compiled reader) and compiles the kernels
    (kernel/compile_workers.py, path/renderer.py)."""
    from ..kernel import compile_workers
    from ..path import wide_bvh
    if compile_workers.standing_by() and not wide_bvh.compiled():
        compile_workers.compile_ahead(wide_bvh.compile_ahead, needed=False)


def read(path, fits=None):
    """(vertices, faces, uvs, normals) of the OBJ file at path, as
    meshes.read gives them.  Unread if it holds what this reader does not
    read exactly (the caller then uses trimesh), ObjError for a face that
    names what is not in the file.  fits(bytes, triangles), if given, is
    asked once the lines are counted, before the arrays are made (it raises
    if they would not fit in memory)."""
    text = np.fromfile(path, dtype=np.uint8)
    if len(text) > AHEAD_BYTES:
        _builder_ahead()
    if text[:3].tobytes() == b"\xef\xbb\xbf":        # a UTF-8 byte order mark
        text = text[3:]

    def counted(nv, nvt, nvn, nt):
        if fits is not None:
            # The tables, the corners, and making vertices of them (unique keys).
            fits(8 * (3 * nv + 2 * nvt + 3 * nvn) + 8 * nt * (9 + 3 * 4 + 3), nt)
    plain = obj_lines.read(text.tobytes(), counted) if len(text) <= obj_lines.MAX_BYTES else None
    v, vt, vn, corners = plain or _scanned(path, text, counted)
    nv, nvt, nvn, nt = len(v), len(vt), len(vn), len(corners)
    vi, ti, ni = corners[:, :, 0], corners[:, :, 1], corners[:, :, 2]
    # Every index is in range (_scan); a corner's uv or normal counts only if
    # every corner names one.
    has_uv = nt > 0 and (ti >= 0).all()
    has_n = nt > 0 and (ni >= 0).all()
    if not has_uv and not has_n:
        return v, vi, None, None
    if nv * max(nvt, 1) * max(nvn, 1) >= 2 ** 62:
        raise Unread(f"{path}: too many vertices, texture coordinates and normals to pair")
    # A vertex for each different (v, vt, vn) the corners name.
    key = vi.ravel()
    if has_uv:
        key = key * nvt + ti.ravel()
    if has_n:
        key = key * nvn + ni.ravel()
    _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    corner_v = vi.ravel()[first]
    uvs = vt[ti.ravel()[first]] if has_uv else None
    normals = vn[ni.ravel()[first]] if has_n else None
    return v[corner_v], inverse.reshape(nt, 3).astype(np.int64), uvs, normals


def _scanned(path, text, counted):
    """(v, vt, vn, corners) of the file's bytes by the compiled scan: counted,
    then read into tables made to size."""
    nv, nvt, nvn, nt, nh, status, part, line, word = _scan(
        text, _POW10, False, np.zeros((0, 3)), np.zeros((0, 2)), np.zeros((0, 3)),
        np.zeros((0, 3, 3), dtype=np.int64), np.zeros((0, 5), dtype=np.int64))
    if status != READ:
        raise _stopped(path, text, status, part, line, word, None, (nv, nvt, nvn))
    counted(nv, nvt, nvn, nt)
    v, vt, vn = np.empty((nv, 3)), np.empty((nvt, 2)), np.empty((nvn, 3))
    corners = np.empty((nt, 3, 3), dtype=np.int64)
    hard = np.empty((nh, 5), dtype=np.int64)
    _, _, _, _, _, status, part, line, word = _scan(text, _POW10, True, v, vt, vn, corners, hard)
    if status != READ:              # an index beyond the file's tables
        raise _stopped(path, text, status, part, line, word, (nv, nvt, nvn), None)
    tables = {V: v, VT: vt, VN: vn}
    for kind, row, column, start, end in hard:      # beyond the fast path: float()
        tables[kind][row, column] = float(text[start:end].tobytes())
    return v, vt, vn, corners
