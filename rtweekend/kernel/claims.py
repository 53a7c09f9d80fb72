"""Two processes compiling one kernel: each step goes to the first to claim it.

A kernel is a tree of steps, and Numba compiles a step when it types the call
to it: to go on typing the caller it needs the step's return type, and to
lower the caller, the step's code.  So a second process can share the work
of one kernel: both walk the same tree; a step neither has claimed is claimed
and compiled by whichever gets there first (and saved to the cache); a step
the other process claimed is only typed here (most of a compile is lowering
and LLVM, not typing), which tells its return type, so the walk goes on past
it; and where this process must lower a call to such a step, it waits until
the claimant has saved the step and loads it from the cache.  The process
that types ahead thus takes the later steps while the other compiles the
earlier ones, and the two meet in the middle.

A claim is a file made with O_EXCL in the session's folder, holding the
claimant's pid; the claimant marks the step done when it is in the cache.  A
process waits only for steps of the other's, at lowering, and never for one
of its own callers' -- the call graph has no cycle -- so it never waits for
ever; a claimant gone (killed, crashed) is taken over.

The session is the one compile in progress: `with Session(folder):` in each
process (kernel/compile_workers.py starts the helper and makes the folder).
"""
import hashlib
import os
import time

from numba.core import compiler, sigutils
from numba.core.compiler import CompilerBase, DefaultPassBuilder
from numba.core.compiler_lock import global_compiler_lock
from numba.core.compiler_machinery import FunctionPass, register_pass
from numba.core.typed_passes import NopythonTypeInference

from . import compile_clock

POLL = 0.01            # seconds between looks at a step the other process compiles
_SESSION = [None]


def current():
    """The session of the compile in progress, or None."""
    return _SESSION[0]


class Session:
    """The claims of one compile shared by processes, in `folder`."""

    def __init__(self, folder):
        self.folder = folder
        self.mine = set()               # keys this process claimed
        # A helper's own jobs: marked done by the job (compile_workers.py), after
        # a failure's line is written, not by the compile inside it -- else the
        # other process could see the job done, find no failure yet, and
        # compile the kernel again itself.
        self.jobs = set()

    def __enter__(self):
        _SESSION[0] = self
        return self

    def __exit__(self, *exc):
        _SESSION[0] = None

    @staticmethod
    def key(dispatcher, args):
        fn = dispatcher.py_func
        text = f"{fn.__module__}.{fn.__qualname__}:{tuple(args)}"
        return hashlib.sha256(text.encode()).hexdigest()[:24]

    def _path(self, kind, key):
        return os.path.join(self.folder, f"{key}.{kind}")

    def claim(self, key):
        """Is this step this process's to compile (claimed now or before)?"""
        if key in self.mine:
            return True
        try:
            fd = os.open(self._path("claim", key), os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            return False
        os.write(fd, str(os.getpid()).encode())
        os.close(fd)
        self.mine.add(key)
        return True

    def claim_for(self, key, pid):
        """Claim a step (a kernel) for another process, which will compile it."""
        with open(self._path("claim", key), "w") as f:
            f.write(str(pid))

    def fail(self, message):
        """A process could not compile a kernel of its own: why, in a line."""
        with open(os.path.join(self.folder, "failed"), "w") as f:
            f.write(message)

    def failure(self):
        """The line fail() left, or None."""
        try:
            with open(os.path.join(self.folder, "failed")) as f:
                return f.read()
        except OSError:
            return None

    def done(self, key):
        """The step is in the cache (or failed: the other compiles it itself).
        Not one of self.jobs: its job marks it, once out of that set."""
        if key not in self.jobs:
            open(self._path("done", key), "w").close()

    def is_done(self, key):
        return os.path.exists(self._path("done", key))

    def wait(self, key):
        """Until the other process has the step in the cache, or is gone."""
        with compile_clock.waiting():
            while not self.is_done(key) and self._claimant_alive(key):
                time.sleep(POLL)

    def claimed_by(self):
        """{pid: how many steps and kernels it claimed} so far."""
        out = {}
        for name in os.listdir(self.folder):
            if name.endswith(".claim"):
                pid = _pid(os.path.join(self.folder, name))
                if pid is not None:
                    out[pid] = out.get(pid, 0) + 1
        return out

    def _claimant_alive(self, key):
        pid = _pid(self._path("claim", key))
        if pid is None:
            return False
        try:
            os.kill(pid, 0)         # (0: a claim being written; its claimant is alive)
            return True
        except OSError:
            return False


def _pid(claim):
    """The pid a claim file holds, or None (gone, or not written yet)."""
    try:
        with open(claim) as f:
            return int(f.read() or 0)
    except (OSError, ValueError):
        return None


@register_pass(mutates_CFG=False, analysis_only=True)
class _ReturnTypeOnly(FunctionPass):
    """Ends a compile at its types: the result is the return type."""
    _name = "rtweekend_return_type_only"

    def __init__(self):
        FunctionPass.__init__(self)

    def run_pass(self, state):
        state.cr = state.return_type
        return False


class _TypeOnly(CompilerBase):
    """Numba's pipeline up to type inference: a function's return type, no code."""

    def define_pipelines(self):
        pm = DefaultPassBuilder.define_nopython_pipeline(self.state)
        passes = [p for p, _ in pm.passes]
        del pm.passes[passes.index(NopythonTypeInference) + 1:]
        pm.add_pass(_ReturnTypeOnly, "the return type")
        pm.finalize()
        return [pm]


@global_compiler_lock
def return_type(dispatcher, args):
    """What `dispatcher` returns for arguments of types `args`, by typing it
    alone (the steps it calls are compiled or typed as the session says)."""
    c = dispatcher._compiler
    flags = compiler.Flags()
    c.targetdescr.options.parse_as_flags(flags, c.targetoptions)
    flags = c._customize_flags(flags)
    return compiler.compile_extra(c.targetdescr.typing_context, c.targetdescr.target_context,
                                  dispatcher.py_func, args=tuple(args), return_type=None,
                                  flags=flags, locals=dispatcher.locals,
                                  pipeline_class=_TypeOnly)


def normalized(sig):
    args, _ = sigutils.normalize_signature(sig)
    return tuple(args)
