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
"""
import atexit
import os
import pickle
import subprocess
import sys
import tempfile
import threading

import numba

from . import compile_clock, disk_cache

POLL = 0.05          # seconds between looks at a helper
STARTED = [0]        # helpers this process has started (tests, benchmarks)
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


def compile_all(calls):
    """Compile (or load from the cache) each (dispatcher, args) of `calls` for
    its arguments' types: the first missing one here, the other missing ones
    in helpers at the same time."""
    sigs = [(d, signature(args)) for d, args in calls]
    missing = [(d, sig) for d, sig in sigs if not loaded(d, sig)]
    helpers = []
    try:
        if len(missing) > 1 and enabled():
            helpers = [Helper(d, sig) for d, sig in missing[1:]]
            missing = missing[:1]
        for d, sig in missing:
            d.compile(sig)
        for helper in helpers:
            helper.wait()
    finally:
        for helper in helpers:
            helper.stop()
    for d, sig in sigs:
        d.compile(sig)          # what the helpers compiled, from the cache


class Helper:
    """A process compiling `dispatcher` for `sig` into the cache."""

    def __init__(self, dispatcher, sig):
        fn = dispatcher.py_func
        self.what = f"{fn.__module__}.{fn.__qualname__}"
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(disk_cache.PACKAGE.parent), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))
        # stderr to a file: a pipe nobody reads could fill and stall the helper.
        self.errors = tempfile.TemporaryFile()
        self.process = subprocess.Popen(
            [sys.executable, "-c", f"from {disk_cache.PACKAGE.name}.kernel.compile_workers "
             "import _serve; _serve()"],
            stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=self.errors, env=env)
        with _LOCK:
            _HELPERS.add(self)
            STARTED[0] += 1
        job = pickle.dumps((fn.__module__, fn.__name__, sig))
        self.process.stdin.write(len(job).to_bytes(8, "little") + job)
        self.process.stdin.flush()

    def wait(self):
        """Until the helper has compiled its kernel (counted as compiling)."""
        with compile_clock.waiting():
            while self.process.poll() is None:
                try:
                    self.process.wait(POLL)
                except subprocess.TimeoutExpired:
                    pass
        if self.process.returncode == -9 or self.process.returncode == STOPPED:
            raise Stopped(self.what)
        if self.process.returncode != 0:
            self.errors.seek(0)
            lines = self.errors.read().decode(errors="replace").strip().splitlines()
            raise CompileError(f"compiling {self.what} in a helper process failed: "
                               f"{lines[-1] if lines else f'exit {self.process.returncode}'}")

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


STOPPED = 3          # a helper's exit status when its parent went away


def stop_all():
    """End every helper of this process now (Ctrl-C, exit)."""
    with _LOCK:
        helpers = list(_HELPERS)
    for helper in helpers:
        helper.stop()


atexit.register(stop_all)


def _serve():
    """In a helper: read the job, compile it, leave (os._exit: no teardown)."""
    stdin = sys.stdin.buffer
    size = int.from_bytes(stdin.read(8), "little")
    module, name, sig = pickle.loads(stdin.read(size))

    def watch_parent():
        stdin.read()              # returns at the end of stdin: the parent is gone
        os._exit(STOPPED)
    threading.Thread(target=watch_parent, daemon=True).start()
    from importlib import import_module
    from .jit import collector_paused
    dispatcher = getattr(import_module(module), name)
    with collector_paused():
        dispatcher.compile(sig)
    sys.stderr.flush()
    os._exit(0)
