"""Small OBJ files read in Python, so that a first run need not compile a reader.

io/obj.py's compiled scan reads a file of any size fast, but compiling it
costs a first run seconds, which a file of a few thousand lines does not
repay: such a file is read here, a line at a time (the splitting done by
Python's bytes methods), in milliseconds.  Only plain files: lines that are
comments or that the scan skips, `v`, `vt` and `vn` lines of numbers, and `f`
lines of corners of the four forms naming what the file has.  A `#` ends any
line.  Anything else -- a backslash, a word that is no number or corner as
the scan reads them, an index 0 or beyond the file's tables -- is left to
the compiled scan, which reads it or says what is wrong and where.  What this gives is
what the scan gives, bit for bit (tests/test_obj.py compares the two on
random files): the scan's numbers are float()'s.
"""
import re

import numpy as np

MAX_BYTES = 1 << 20     # larger files: the compiled scan (benchmarks/results/measurements.md)

# A number as the compiled scan reads one (obj._number); float() reads more.
NUMBER = re.compile(rb"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
INDEX = re.compile(rb"-?[0-9]+")
WIDTH = {b"v": 3, b"vt": 2, b"vn": 3}


def read(text, counted):
    """(v, vt, vn, corners) of the OBJ file's bytes, as obj._scan fills them
    (corners [triangles, 3, (v, vt, vn)], -1 where a corner names none), or
    None if the file is not a plain one (the compiled scan reads it).
    counted(vertices, uvs, normals, triangles) is told the sizes before any
    table is made (it may raise: obj.read's memory check)."""
    if any(odd in text for odd in (b"\\", b"\x0b", b"\x0c")):
        return None
    tables = {b"v": [], b"vt": [], b"vn": []}
    faces = []                              # (corners' words, tables' sizes then)
    for line in text.split(b"\n"):
        # On spaces, tabs and CRs (no \v or \f here); a '#' ends any line.
        words = line.split(b"#", 1)[0].split()
        if not words:
            continue
        key = words[0]
        if key in WIDTH:
            numbers = words[1:1 + WIDTH[key]]
            if len(numbers) < WIDTH[key] or not all(NUMBER.fullmatch(w) for w in numbers):
                return None
            tables[key].append([float(w) for w in numbers])
        elif key == b"f":
            faces.append((words[1:], len(tables[b"v"]), len(tables[b"vt"]),
                          len(tables[b"vn"])))
    totals = [len(tables[k]) for k in (b"v", b"vt", b"vn")]
    triangles = []
    for words, *seen in faces:
        corners = [_corner(w, seen, totals) for w in words]
        if None in corners:
            return None
        triangles += [(corners[0], corners[m - 1], corners[m]) for m in range(2, len(corners))]
    counted(*totals, len(triangles))
    v, vt, vn = (np.array(tables[k], dtype=np.float64).reshape(-1, WIDTH[k])
                 for k in (b"v", b"vt", b"vn"))
    return v, vt, vn, np.array(triangles, dtype=np.int64).reshape(-1, 3, 3)


def _corner(word, seen, totals):
    """(v, vt, vn) 0-based, -1 for one not named, of a corner `v`, `v/vt`,
    `v//vn` or `v/vt/vn`; None for another form, an index 0 or one naming
    what the file does not have (negative ones count back from `seen`, the
    tables' sizes at the face's line)."""
    parts = word.split(b"/")
    if len(parts) > 3 or not parts[0] or (len(parts) == 2 and not parts[1]) \
            or (len(parts) == 3 and not parts[2]):
        return None
    out = [-1, -1, -1]
    for s, part in enumerate(parts):
        if not part:
            continue
        if not INDEX.fullmatch(part):
            return None
        k = int(part)
        index = seen[s] + k if k < 0 else k - 1
        if k == 0 or not 0 <= index < totals[s]:
            return None
        out[s] = index
    return tuple(out)
