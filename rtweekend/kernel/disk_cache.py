"""Where compiled kernels are kept on disk, and when one is still good.

Numba keys a cached function by the time stamp of its own file only, not of
the files its callees live in: edit path/pdf.py and a kernel in
integrators/path.py would load the old code.  Here a compiled function is
keyed by the sources it can reach -- its module and every module of the
package that module imports, followed through their own imports -- so an edit
compiles afresh exactly the kernels built from the edited file (an edit to
the classic tracer or the command line compiles no path-tracer kernel).

The files live in one folder, KERNELS, laid out as the package is and named
by that digest, so the package run from a cloned folder and the same sources
installed share their kernels, and kernels of several versions of the
sources sit side by side (`rtweekend cache clear` removes the ones no module
has any more).  Saving and loading take a lock on the folder: processes
compiling at once (kernel/compile_workers.py) must not lose each other's
entries in an index file.
"""
import ast
import hashlib
import os
import pickle
import re
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

import numba
from numba.core import caching, config
from numba.core.runtime import rtsys

from . import compile_clock

try:
    import fcntl
    CAN_LOCK = True
except ImportError:              # not on a POSIX system: no lock, no helper processes
    fcntl = None
    CAN_LOCK = False

PACKAGE = Path(__file__).resolve().parent.parent
KERNELS = "kernels"


def base():
    """The folder of every version's kernels: $NUMBA_CACHE_DIR/kernels, else
    the user's cache folder (a user folder also works for a read-only
    installed package), else a temporary one."""
    root = config.CACHE_DIR or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "rtweekend")
    path = os.path.join(root, KERNELS)
    try:
        os.makedirs(path, exist_ok=True)
        if os.access(path, os.W_OK):
            return path
    except OSError:
        pass
    path = os.path.join(tempfile.gettempdir(), f"rtweekend-{os.getuid()}", KERNELS)
    os.makedirs(path, exist_ok=True)
    return path


BASE = base()


def _module_name(path, root):
    """The dotted name of a package file, relative to the package ('path.bvh')."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _file_of(name, root):
    """The package file of module `name` (relative, dotted), or None."""
    stem = root.joinpath(*name.split(".")) if name else root
    for path in (stem.with_suffix(".py"), stem / "__init__.py"):
        if path.is_file():
            return path
    return None


# A module-level import statement: what a kernel's code can reach other
# modules through (Numba compiles no import inside a function).  Found by
# this pattern and parsed alone, which keeps reading the package quick (a
# docstring line that looks like one costs at most a needless dependency).
_IMPORT = re.compile(r"^(?:from[ \t]+\.*[\w.]*[ \t]+import[ \t]+(?:\([^)]*\)|[^\n]*)"
                     r"|import[ \t]+[\w., \t]+)$", re.M)


def _import_statements(path):
    found = [m.group(0) for m in _IMPORT.finditer(path.read_text())]
    try:
        return ast.parse("\n".join(found)).body          # all at once: quicker
    except SyntaxError:
        out = []
        for statement in found:
            try:
                out.extend(ast.parse(statement).body)
            except SyntaxError:
                pass
        return out


def imports(path, root=PACKAGE):
    """The package files that the file `path` imports by name (not the
    packages' __init__ files Python runs on the way: a step reaches no code of
    theirs unless it imports it by name)."""
    name = _module_name(path, root)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in _import_statements(path):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".") if package else []
                parts = parts[:len(parts) - (node.level - 1)]
                module = ".".join(parts + ([node.module] if node.module else []))
            elif node.module and node.module.partition(".")[0] == root.name:
                module = node.module.partition(".")[2]
            else:
                continue
            for alias in node.names:        # a submodule, or a name in the module
                found.add(_file_of(f"{module}.{alias.name}".lstrip("."), root)
                          or _file_of(module, root))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                top, _, rest = alias.name.partition(".")
                if top == root.name:
                    found.add(_file_of(rest, root))
    found.discard(None)
    return found


class Sources:
    """The package's files under `root` as read once: their imports, and the
    digest of what each one reaches."""

    def __init__(self, root=PACKAGE):
        self.root = root
        self._imports, self._digests = {}, {}

    def digest(self, path):
        """A hash of the sources the code in the file `path` is built from: the
        file and every package file it reaches through imports."""
        path = Path(path)
        if path not in self._digests:
            seen, todo = set(), [path]
            while todo:
                p = todo.pop()
                if p not in seen:
                    seen.add(p)
                    if p not in self._imports:
                        self._imports[p] = imports(p, self.root)
                    todo.extend(self._imports[p])
            h = hashlib.sha256()
            for p in sorted(seen):
                h.update(p.relative_to(self.root).as_posix().encode())
                h.update(b"\0")
                h.update(p.read_bytes())
            self._digests[path] = h.hexdigest()[:16]
        return self._digests[path]


# The sources this process runs, read once (they do not change under it).
SOURCES = Sources()
digest = SOURCES.digest


def _in_package(py_file, _memo={}):
    """The file's path relative to the package, or None for a file outside it."""
    if py_file not in _memo:
        try:
            _memo[py_file] = Path(py_file).resolve().relative_to(PACKAGE)
        except ValueError:
            _memo[py_file] = None
    return _memo[py_file]


class PackageLocator(caching._CacheLocator):
    """A function of this package: its cache files under BASE at the module's
    place in the package, stamped with the digest of its sources."""

    def __init__(self, py_func, py_file, relative):
        # Under the package's name: a copy imported under another name (the
        # benchmarks compare source trees so) names other types in its index.
        self._cache_path = os.path.join(BASE, PACKAGE.name, *relative.parent.parts)
        self._digest = digest(PACKAGE / relative)
        self._lineno = py_func.__code__.co_firstlineno

    def ensure_cache_path(self):
        os.makedirs(self._cache_path, exist_ok=True)

    def get_cache_path(self):
        return self._cache_path

    def get_source_stamp(self):
        return self._digest

    def get_disambiguator(self):
        # The digest in the name: versions of the sources keep files apart.
        return f"{self._lineno}-{self._digest}"

    @classmethod
    def from_function(cls, py_func, py_file):
        relative = _in_package(py_file)
        return None if relative is None else cls(py_func, py_file, relative)


@contextmanager
def locked():
    """The cache folder to this process alone (an advisory lock on its .lock)."""
    if not CAN_LOCK:
        yield
        return
    with open(os.path.join(BASE, ".lock"), "a+b") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)


def _reduce(self, cres):
    """Numba's reduce, less the typed-source listing it renders into every entry
    (str of the type annotation: about 2% of a cold compile, for a
    text only inspect_types shows)."""
    return cres._replace(type_annotation="")._reduce()


def impl_class(numba_impl):
    """A subclass of Numba's cache implementation `numba_impl` that locates a
    package function's files with PackageLocator, and keeps no typed-source
    listing (_reduce)."""
    return type(f"Package{numba_impl.__name__}", (numba_impl,), dict(
        _locator_classes=[PackageLocator, *numba_impl._locator_classes], reduce=_reduce))


class PackageCache(caching.FunctionCache):
    """Numba's cache of a function's compiled code, with the package's files
    and the folder's lock."""

    _impl_class = impl_class(caching.CompileResultCacheImpl)

    def load_overload(self, sig, target_context):
        if takes_a_function(sig):
            return None
        since = time.perf_counter()
        with locked():
            try:
                found = _load(self, sig, target_context)
            except (ImportError, AttributeError, EOFError, pickle.UnpicklingError):
                found = None          # an index naming what is not here: compile afresh
        if found is None:             # a compile follows: part of its cost
            compile_clock.add_since(since)
        return found

    def save_overload(self, sig, data):
        if takes_a_function(sig):
            return
        since = time.perf_counter()
        with locked():
            super().save_overload(sig, data)
        compile_clock.add_since(since)


def _load(cache, sig, target_context):
    """Numba's Cache.load_overload without its target_context.refresh(): the
    refresh imports and installs every implementation Numba has for compiling
    (its linear algebra's check for a BLAS imports SciPy when it is installed),
    0.7 s of a 3 s cached start, none of it needed to load machine code.  What
    loaded code calls is NRT's functions (initialised here: their symbols) and
    Numba's C helpers (registered when numba is imported); a compile later in
    the process refreshes first anyway (CompilerBase)."""
    rtsys.initialize(target_context)
    found = None
    with cache._guard_against_spurious_io_errors():
        found = cache._load_overload(sig, target_context)
    return found


def takes_a_function(sig):
    """Is one of sig's arguments a compiled function (integrators/pixels.py's
    loop takes the estimator's sample)?  Such a compile is not kept on its own:
    the key of its entry could not name the function's sources (its module is
    not among the loop's imports), so an entry would be found by no later
    process, or, keyed by the function's name, found stale after an edit.
    The kernel that calls it is kept whole, as any kernel is."""
    args = sig.args if hasattr(sig, "args") else sig
    return any(isinstance(t, numba.core.types.Dispatcher) for t in args)


def stale_files():
    """[(path, bytes)] of the files under BASE no module's sources match now:
    an earlier version's (another digest), a module's that is gone, a renamed
    copy's of the package (the benchmarks')."""
    out = []
    for path in Path(BASE).rglob("*"):
        if not path.is_file() or path.parent == Path(BASE):
            continue                                        # the lock
        package, *rel = path.parent.relative_to(BASE).parts
        source = PACKAGE.joinpath(*rel, path.name.partition(".")[0] + ".py")
        if not (package == PACKAGE.name and source.is_file()
                and f"-{digest(source)}." in path.name):
            out.append((path, path.stat().st_size))
    return out


def size():
    """Bytes under BASE."""
    return sum(p.stat().st_size for p in Path(BASE).rglob("*") if p.is_file())


def signature(args):
    """The Numba types a dispatcher compiles for when called with `args`."""
    return tuple(numba.typeof(a) for a in args)


def loaded(dispatcher, sig):
    """Is dispatcher compiled for sig in this process, or in the cache (then
    load it, as Dispatcher.compile would)?"""
    if sig in dispatcher.overloads:
        return True
    cres = dispatcher._cache.load_overload(sig, dispatcher.targetctx)
    if cres is None:
        return False
    dispatcher.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
    dispatcher.add_overload(cres)
    return True
