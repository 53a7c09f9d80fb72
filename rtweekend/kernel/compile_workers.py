"""Compiling a render's kernels side by side, in helper processes.

A render can need several kernels that do not call each other: bdpt and its
photon maps' tracer, the denoiser's pass that estimates the light seen.
Numba compiles one function at a time per process (its compiler lock), but
not per machine, and its cache is shared: so each kernel missing from the
cache but the first is compiled by a helper process of its own, into the same
cache (kernel/disk_cache.py locks its index files), while this process
compiles the first; then this one loads what the helpers saved.

A helper is this Python running `_serve`, told which function to compile
for which argument types (pickled Numba types) on its stdin, which stays
open: a helper whose parent is gone -- interrupted, killed -- reads the end of
its stdin and leaves at once.  stop_all() ends every helper now (Ctrl-C
during a compile: kernel/calls.py, local.py).  A helper that fails is one
clear error naming what it compiled.

The standby helper (prestart) can also be asked to compile ahead
(compile_ahead): to run a function that compiles into the cache what this
process will need after what it is compiling now -- the BVH's builder while
this process compiles the render's kernels -- then to wait for its job.
"""
import atexit
import os
import pickle
import re
import shutil
import subprocess
import sys
import tempfile
import threading

from . import claims, disk_cache
from .disk_cache import loaded, signature

POLL = 0.05          # seconds between looks at a helper
STARTED = [0]        # helpers this process has started (tests, benchmarks)
SHARE = {}           # the last shared compile: {pid: functions it compiled} (tests, benchmarks)
_HELPERS = set()     # the helpers running now
_LOCK = threading.Lock()


class CompileError(RuntimeError):
    """A kernel could not be compiled in a helper process (the command says
    so in one line)."""


class Stopped(Exception):
    """The helpers were stopped (stop_all) while this process waited for them."""


def cpus():
    """CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:        # not on Linux
        return os.cpu_count() or 1


def enabled():
    """Helpers only with a second CPU for them, and a lock for the cache
    ($RTWEEKEND_COMPILE_HELPERS=0 turns them off)."""
    return (cpus() > 1 and disk_cache.CAN_LOCK
            and os.environ.get("RTWEEKEND_COMPILE_HELPERS", "1") != "0")


def compile_all(calls):
    """Compile (or load from the cache) each (dispatcher, args) of `calls` for
    its arguments' types: the first missing one here, with the help of helper
    processes that compile the other missing ones first (kernel/claims.py)."""
    sigs = [(d, signature(args)) for d, args in calls]
    missing = [(d, sig) for d, sig in sigs if not loaded(d, sig)]
    if not missing:
        _drop_standby()
    elif enabled():
        folder = tempfile.mkdtemp(prefix="rtweekend-compile-")
        try:
            with claims.Session(folder) as session:
                _share(session, missing)
                SHARE.update(session.claimed_by())
        finally:
            shutil.rmtree(folder, ignore_errors=True)
    for d, sig in sigs:
        d.compile(sig)          # what the helpers compiled, from the cache; or here


def _share(session, missing):
    """The first missing kernel here; each helper first compiles its share of
    the others, then helps with the first (claims.py).  The standby helper
    first runs what it was asked to compile ahead: waited for before it is
    stopped (this process would need it next)."""
    (first, first_sig), others = missing[0], missing[1:]
    count = max(1, min(cpus() - 1, len(others)))
    helpers = [Helper(session, others[i::count], (first, first_sig), _standby())
               for i in range(count)]
    try:
        first.compile(first_sig)
        for helper in helpers:
            helper.wait()
        for ahead in list(_AHEADS.values()):
            if ahead.needed:
                ahead.wait()
    finally:
        for helper in helpers:
            helper.stop()


class Helper:
    """A process compiling kernels `own` into the cache, then helping with
    `assist` (a kernel this process compiles: claims.py) until stopped."""

    def __init__(self, session, own, assist, started=None):
        self.session = session
        self.keys = [session.key(d, sig) for d, sig in own]
        self.what = ", ".join(_name(d) for d, _ in own)
        self.process, self.errors = started or _spawn()
        for key in self.keys:             # its kernels are its own from the start
            session.claim_for(key, self.process.pid)
        with _LOCK:
            _HELPERS.add(self)
        _send(self.process, ("job", session.folder, [_job(d, sig) for d, sig in own],
                             _job(*assist)))

    def wait(self):
        """Until the helper's own kernels are in the cache (counted as compiling);
        CompileError if it could not compile one."""
        for key in self.keys:
            self.session.wait(key)
        failed = self.session.failure()
        if failed:
            raise CompileError(f"compiling {self.what} in a helper process failed: {failed}")
        if not all(self.session.is_done(key) for key in self.keys):     # it is gone
            if self.process.poll() in (-9, STOPPED):
                raise Stopped(self.what)
            self.errors.seek(0)
            lines = self.errors.read().decode(errors="replace").strip().splitlines()
            raise CompileError(f"compiling {self.what} in a helper process failed: "
                               f"{lines[-1] if lines else f'exit {self.process.poll()}'}")

    def stop(self):
        """End the helper now, if it is still running."""
        with _LOCK:
            _HELPERS.discard(self)
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        for stream in (self.process.stdin, self.errors):
            try:
                stream.close()
            except OSError:
                pass


def _spawn():
    """A helper process: (Popen, its stderr file).  It imports the package, then
    waits for its job on stdin."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(disk_cache.PACKAGE.parent), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))
    # stderr to a file: a pipe nobody reads could fill and stall the helper.
    errors = tempfile.TemporaryFile()
    process = subprocess.Popen(
        [sys.executable, "-c", f"from {disk_cache.PACKAGE.name}.kernel.compile_workers "
         "import _serve; _serve()"],
        stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=errors, env=env)
    with _LOCK:
        STARTED[0] += 1
    return process, errors


_STANDBY = []        # a helper started ahead of the compile (prestart), not yet used


def prestart():
    """Start a helper now, so that it has imported the package by the time the
    render compiles (while this process reads and packs the scene); the next
    compile_all gives it its job, or stops it when nothing is missing."""
    if enabled() and not _STANDBY:
        _STANDBY.append(_spawn())


def _standby():
    """The helper prestart() started, or None."""
    return _STANDBY.pop() if _STANDBY else None


def _drop_standby():
    standby = _standby()
    if standby is not None:
        process, errors = standby
        process.kill()
        process.wait()
        process.stdin.close()
        errors.close()


def _send(process, message):
    data = pickle.dumps(message)
    process.stdin.write(len(data).to_bytes(8, "little") + data)
    process.stdin.flush()


class Ahead:
    """A compile_ahead in the standby helper: wait() until it is done."""

    def __init__(self, session, key, name, needed):
        self.session, self.key, self.name, self.needed = session, key, name, needed

    def wait(self):
        """Until the helper has run it (counted as compiling); if the helper
        is gone instead, this process compiles what it needs itself."""
        if _AHEADS.get(self.name) is self:
            self.session.wait(self.key)
            shutil.rmtree(self.session.folder, ignore_errors=True)
            del _AHEADS[self.name]


_AHEADS = {}         # asked of the standby helper, not yet waited for: {name: Ahead}


def standing_by():
    """Is a helper started (prestart) and not yet given its job?"""
    return bool(_STANDBY)


def compile_ahead(fn, needed=True):
    """Have the standby helper call fn (a module-level function of this package
    that compiles, or loads, what this process will need soon) while this
    process compiles something else; then the helper waits for its job as
    before.  An Ahead to wait() for (the same one if fn was asked for before),
    or None without a standby helper.  Its claim and done mark are a
    claims.Session's, as for a kernel.  needed=False: it may turn out not to
    be (a guess), so the helper may be stopped before it is done; asked for
    again as needed, it is waited for before the helper is stopped."""
    name = f"{fn.__module__}.{fn.__name__}"
    if name in _AHEADS:
        _AHEADS[name].needed |= needed
        return _AHEADS[name]
    if not _STANDBY:
        return None
    process, _ = _STANDBY[0]
    session, key = claims.Session(tempfile.mkdtemp(prefix="rtweekend-ahead-")), fn.__name__
    session.claim_for(key, process.pid)
    try:
        _send(process, ("ahead", fn.__module__, fn.__name__, session.folder, key))
    except OSError:                 # the helper is gone
        shutil.rmtree(session.folder, ignore_errors=True)
        return None
    _AHEADS[name] = Ahead(session, key, name, needed)
    return _AHEADS[name]


def requested(fn):
    """The Ahead of fn if the standby helper was asked to compile it and it was
    not waited for yet, else None."""
    return _AHEADS.get(f"{fn.__module__}.{fn.__name__}")


def _name(dispatcher):
    return f"{dispatcher.py_func.__module__}.{dispatcher.py_func.__qualname__}"


def _job(dispatcher, sig):
    return dispatcher.py_func.__module__, dispatcher.py_func.__name__, sig


STOPPED = 3          # a helper's exit status when its parent went away


def stop_all():
    """End every helper of this process now (Ctrl-C, exit)."""
    _drop_standby()
    with _LOCK:
        helpers = list(_HELPERS)
    for helper in helpers:
        helper.stop()


atexit.register(stop_all)


def one_line(error):
    """An exception's message on one line, without the terminal colours Numba
    puts in its typing errors."""
    return " ".join(re.sub(r"\x1b\[[0-9;]*m", "", str(error)).split())


def compile_own(session, own):
    """In a helper: compile its own kernels [(module, name, sig)], each marked
    done when it is in the cache -- or, failed, after the failure's line is
    written (the parent reads it once it sees the kernel done)."""
    from importlib import import_module
    for m, n, s in own:
        dispatcher = getattr(import_module(m), n)
        key = session.key(dispatcher, s)
        session.mine.add(key)
        session.jobs.add(key)
        try:
            dispatcher.compile(s)
        except Exception as e:
            session.fail(f"{type(e).__name__}: {one_line(e)}"[:500])
            raise
        finally:
            session.jobs.discard(key)
            session.done(key)


def _serve():
    """In a helper: run what is asked ahead, read the job, compile its kernels,
    help with the parent's, leave (os._exit: no teardown)."""
    import queue
    from importlib import import_module
    from .. import path  # noqa: F401  (the kernels' modules, imported while waiting)
    messages = queue.SimpleQueue()

    def read():
        stdin = sys.stdin.buffer
        while len(header := stdin.read(8)) == 8:
            messages.put(pickle.loads(stdin.read(int.from_bytes(header, "little"))))
        os._exit(STOPPED)         # stdin ended: the parent is gone, or needs no helper
    threading.Thread(target=read, daemon=True).start()
    from .jit import collector_paused
    while (message := messages.get())[0] == "ahead":
        _, module, name, folder, key = message
        try:
            with collector_paused():
                getattr(import_module(module), name)()
        except Exception as e:    # the parent compiles it itself; the job may still come
            print(f"compiling ahead {module}.{name}: {type(e).__name__}: {e}", file=sys.stderr)
        finally:
            claims.Session(folder).done(key)
    _, folder, own, (module, name, sig) = message
    with collector_paused(), claims.Session(folder) as session:
        compile_own(session, own)
        claims.return_type(getattr(import_module(module), name), sig)
    sys.stderr.flush()
    os._exit(0)
