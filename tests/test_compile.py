"""What a render's compile is made of: kernels compiled side by side in helper
processes, the seconds it reports, and the spinner that shows it."""
import io
import os
import re
import subprocess
import sys
import time

import pytest
from watch import Watched

import rtweekend as rt
from rtweekend.io.progress import Spinner
from rtweekend.kernel import compile_clock, compile_workers
from rtweekend.path import renderer as renderers

# cornell_box with the books' mixture and the denoiser's two passes: three
# kernels, none calling another.  With a helper standing by (as the command
# starts one), the Renderer compiles them before packing the scene, typed by a
# stand-in of its arrays; the helper compiles the denoiser's two beside this
# one, then steps of the render's kernel (kernel/claims.py).  Prints a hash of
# the film and of the light-seen estimate, the helpers started, the seconds
# before the first pass against those reported, the split of the compile,
# whether packing waited, how many compiles came after compile(), and whether
# the arrays packed are pack_scene's.
# A script's first lines: t0, its start; `compiled`, the functions this process
# compiles.
WATCH_COMPILES = """
import time
t0 = time.perf_counter()
from numba.core import event

compiled = []
class Watch(event.Listener):
    def on_start(self, ev):
        compiled.append(ev.data["dispatcher"].py_func.__name__)
    def on_end(self, ev):
        pass
event.register("numba:compile", Watch())
"""

THREE_KERNELS = WATCH_COMPILES + """
import hashlib, os
import numpy as np
import rtweekend as rt
from rtweekend.kernel import compile_workers
from rtweekend.path import seen_light
from rtweekend.path.pack import pack_scene

def digest(*arrays):
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()

compile_workers.prestart()
scene = rt.load_scene("cornell_box")
r = rt.Renderer(scene, width=20, height=16, sampling="mixture", denoise=True, threads=1)
deferred = r._frame is None
r.compile()
before_first_pass = time.perf_counter() - t0
del compiled[:]
r.add_samples(4)
light, _ = seen_light.estimate(r.frame, np.zeros((16, 20, 3)), 4, 1000, 1)
after = len(compiled)
share = compile_workers.SHARE
here = share.get(os.getpid(), 0)
same_arrays = digest(*r.frame.scene[:10]) == digest(*pack_scene(scene)[:10])
print(digest(*r.film, light), compile_workers.STARTED[0], before_first_pass,
      r.compile_seconds, here, sum(share.values()) - here, deferred, after, same_arrays)
"""


def _three_kernels(tmp_path, name, helpers):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / name),
               RTWEEKEND_COMPILE_HELPERS="1" if helpers else "0")
    run = subprocess.run([sys.executable, "-c", THREE_KERNELS], env=env, capture_output=True,
                         text=True, timeout=900)
    assert run.returncode == 0, run.stderr[-2000:]
    digest, started, before, reported, here, helpers, *flags = run.stdout.split()
    return (digest, int(started), float(before), float(reported), int(here), int(helpers),
            *(f == "True" if f in ("True", "False") else int(f) for f in flags))


@pytest.mark.skipif(not compile_workers.enabled(), reason="needs 2 CPUs and file locks")
def test_kernels_compiled_side_by_side_give_the_bits_of_kernels_compiled_here(tmp_path):
    alone = _three_kernels(tmp_path, "alone", helpers=False)
    beside = _three_kernels(tmp_path, "beside", helpers=True)
    assert alone[1] == 0 and beside[1] >= 1
    assert beside[0] == alone[0]
    # The helpers took the denoiser's passes and steps of the render's kernel;
    # this process, the kernel and its other steps (kernel/claims.py).
    here, helpers = beside[4], beside[5]
    assert here >= 20 and helpers >= 2 + 20, (here, helpers)
    # Alone, the scene is packed first; beside a helper, after the kernels,
    # which the stand-in typed as the render calls them (nothing compiled
    # after compile()), the arrays packed as pack_scene packs them.
    assert alone[6:] == (False, 0, True)
    assert beside[6:] == (True, 0, True)
    for _, _, before, reported, *_ in (alone, beside):
        # Every compile is counted (packing, kernels, waiting for the helpers);
        # what is not is importing and packing (a second or so, not a ratio:
        # benchmarks/compile.py measures the ratio on the default scene).
        assert 0 < reported <= before and before - reported < 5.0


# Two compiles: vec3.dot for tuples (here), and for an array and an int, which
# cannot be typed (in a helper).  Prints the error compile_all raises.
FAILING_HELPER = """
import numpy as np
from rtweekend.kernel import compile_workers
from rtweekend.kernel.vec3 import dot
try:
    compile_workers.compile_all([(dot, ((1.0, 2.0, 3.0), (4.0, 5.0, 6.0))),
                                 (dot, (np.zeros(3), 1))])
except Exception as e:
    print(type(e).__name__, "|", e)
"""


@pytest.mark.skipif(not compile_workers.enabled(), reason="needs 2 CPUs and file locks")
def test_a_kernel_that_fails_in_a_helper_is_one_clear_error(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    run = subprocess.run([sys.executable, "-c", FAILING_HELPER], env=env, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    kind, message = run.stdout.strip().split(" | ", 1)
    assert kind == "CompileError"
    assert message.startswith("compiling rtweekend.kernel.vec3.dot in a helper process "
                              "failed: TypingError: ") and "\n" not in message


def test_a_helpers_failed_kernel_is_marked_done_only_after_its_failure_is_written(tmp_path,
                                                                                 monkeypatch):
    # The parent reads the failure once it sees the kernel done: seen done first,
    # with no failure yet, it compiled the kernel again itself (TypingError, not
    # the one CompileError).  The helper's loop, in this process.
    import numpy as np
    from numba.core.errors import TypingError
    from rtweekend.kernel import claims
    from rtweekend.kernel.vec3 import dot
    failures_when_done = []
    mark = claims.Session.done

    def done(self, key):
        mark(self, key)
        if self.is_done(key):
            failures_when_done.append(self.failure())
    monkeypatch.setattr(claims.Session, "done", done)
    sig = compile_workers.signature((np.zeros(3), 1))
    with claims.Session(str(tmp_path)) as session, pytest.raises(TypingError):
        compile_workers.compile_own(session, [("rtweekend.kernel.vec3", "dot", sig)])
    assert failures_when_done and all(f and f.startswith("TypingError: ") and "\x1b" not in f
                                      for f in failures_when_done)
    assert dot((1.0, 2.0, 3.0), (4.0, 5.0, 6.0)) == 32.0


def _children(pid):
    """The pids of pid's child processes (Linux /proc)."""
    out = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    if int(f.read().rsplit(")", 1)[1].split()[1]) == pid:
                        out.append(int(entry))
            except (OSError, IndexError, ValueError):
                pass
    return out


@pytest.mark.skipif(not (compile_workers.enabled() and os.path.isdir("/proc")),
                    reason="needs helpers and /proc")
@pytest.mark.parametrize("scene", [[], ["weekend"]], ids=["default", "weekend"])
def test_ctrl_c_while_compiling_stops_the_helpers_too(tmp_path, scene):
    # The default scene needs bdpt and its photon maps' tracer: one compiles in
    # a helper.  Ctrl-C: the command leaves at once, and so does the helper.
    # weekend has a BVH: stopped while its kernel compiles (before the scene is
    # packed: renderer.py), the command must not pack it then, which would
    # wait for the compile it left behind.
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "empty_cache"))
    run = Watched([sys.executable, "-m", "rtweekend", "render", *scene, "-o",
                   str(tmp_path / "x.png"), "--spp", "1", "--width", "8", "--height", "8"],
                  env=env)
    run.wait_for(b"compiling")
    deadline = time.monotonic() + 120
    while not (helpers := _children(run.p.pid)) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert helpers, "no helper process was started"
    if scene:
        time.sleep(2.0)                 # into the kernel's compile
    run.interrupt()
    status, _, err = run.finish(timeout=60)
    assert status == 130 and "Ctrl-C while compiling" in err
    deadline = time.monotonic() + 10
    while any(os.path.exists(f"/proc/{pid}") for pid in helpers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(os.path.exists(f"/proc/{pid}") for pid in helpers), "a helper outlived it"


# The command on a scene read from an OBJ file, its compiles watched: each
# compile that starts with no other running says whether a spinner was up, and
# whether it runs in the main thread.  Its triangle is packed by the compiled
# loop, as a mesh of over NUMPY_PACK_MAX triangles would be.
SPINNER_UP = """
import sys, threading
from numba.core import event
from rtweekend.io.progress import Spinner
from rtweekend import cli
from rtweekend.path.shapes import triangle
triangle.NUMPY_PACK_MAX = 0

class Watch(event.Listener):
    depth = 0
    def on_start(self, ev):
        if Watch.depth == 0:
            name = ev.data["dispatcher"].py_func.__module__
            main = threading.current_thread() is threading.main_thread()
            print(name, Spinner._active, main, flush=True)
            if name.endswith("integrators.path"):      # the render kernel: enough
                sys.stdout.flush()
                import os; os._exit(0)
        Watch.depth += 1
    def on_end(self, ev):
        Watch.depth -= 1
event.register("numba:compile", Watch())
cli.main(["render", sys.argv[1], "-o", sys.argv[2], "--spp", "1", "--sampling", "mixture"])
"""

MESH_SCENE = """
[camera]
lookfrom = [0, 0, 3]
lookat = [0, 0, 0]
width = 8
height = 8

[materials]
grey = { type = "lambertian", albedo = [0.5, 0.5, 0.5] }

[[objects]]
type = "mesh"
file = "tri.obj"
material = "grey"
"""


def test_the_spinner_is_up_before_the_first_compile(tmp_path):
    # A backslash (in a comment): a file for the compiled reader (io/obj_lines.py).
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n# by hand \\\nf 1 2 3\n")
    (tmp_path / "mesh.toml").write_text(MESH_SCENE)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "empty_cache"))
    run = subprocess.run([sys.executable, "-c", SPINNER_UP, str(tmp_path / "mesh.toml"),
                          str(tmp_path / "x.png")], env=env, cwd=tmp_path,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    lines = [line.split() for line in run.stdout.splitlines()]
    modules = [module for module, _, _ in lines]
    # Reading the mesh, packing its triangles, then the kernel: each inside a spinner.
    assert modules == ["rtweekend.io.obj", "rtweekend.path.shapes.triangle",
                       "rtweekend.path.integrators.path"]
    assert all(int(active) >= 1 for _, active, _ in lines), lines
    # None in the main thread, which waits awake to Ctrl-C (kernel/calls.py): a
    # Ctrl-C landing inside Numba's compiler was at times lost, or left it half
    # done ("no compiled object yet") and the command ended in a traceback.
    assert all(main == "False" for _, _, main in lines), lines


def test_the_spinner_shows_only_while_something_compiles(monkeypatch):
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    with Spinner(True):
        time.sleep(0.5)                       # nothing compiles: nothing shown
        assert err.getvalue() == ""
        with compile_clock.waiting():         # as while helpers compile
            # After GRACE; on a loaded machine (the suite's other process
            # compiling) the spinner's thread may take longer to draw.
            deadline = time.monotonic() + 30
            while "compiling (00:" not in err.getvalue() and time.monotonic() < deadline:
                time.sleep(0.05)
            assert "compiling (00:" in err.getvalue()
        time.sleep(0.3)
    shown = err.getvalue()
    assert re.search(r"compiling \(00:\d\d\)$", shown.rstrip("\r ")) or "\r" in shown


def test_compile_seconds_count_the_compiles_of_packing_the_scene(monkeypatch):
    pack = renderers.pack_scene

    def slow_pack(*args, **kwargs):           # as a BVH builder compiling
        with compile_clock.waiting():
            time.sleep(0.3)
        return pack(*args, **kwargs)
    monkeypatch.setattr(renderers, "pack_scene", slow_pack)
    r = rt.Renderer(rt.load_scene("cornell_box"), width=8, height=8, sampling="mixture")
    assert r.compile_seconds >= 0.3
    assert r.compile() >= 0.3                  # and the kernel's, compiled or loaded


def test_the_cache_look_up_before_a_compile_and_its_save_after_count(monkeypatch):
    # Numba looks a function up in the cache and saves it outside its compile
    # event: the clock counts a look-up that misses (a compile follows) and the
    # save, but not a hit.
    from numba.core import caching

    from rtweekend.kernel import disk_cache
    from rtweekend.path import bvh_build
    found = [None]

    def look_up(self, sig, target_context):
        time.sleep(0.3)
        return found[0]

    def save(self, sig, data):
        time.sleep(0.2)
    # The package's loader calls Numba's look-up without its refresh
    # (disk_cache._load), after readying NRT for the loaded code.
    monkeypatch.setattr(caching.FunctionCache, "_load_overload", look_up)
    monkeypatch.setattr(disk_cache.rtsys, "initialize", lambda context: None)
    monkeypatch.setattr(caching.FunctionCache, "save_overload", save)
    cache = bvh_build._triangle_bounds._cache
    assert isinstance(cache, disk_cache.PackageCache)

    def counted(block):
        # The clock against the wall: a loaded machine may oversleep, so the
        # bounds are the sleeps below and the wall's time above.
        before, start = compile_clock.seconds(), time.perf_counter()
        block()
        return compile_clock.seconds() - before, time.perf_counter() - start

    def miss():
        assert cache.load_overload((), None) is None
        cache.save_overload((), None)
    seconds, wall = counted(miss)
    assert 0.5 <= seconds <= wall + 0.01
    found[0] = "a compiled result"             # a hit is a load, not a compile
    assert compile_clock.running() is None
    seconds, wall = counted(lambda: cache.load_overload((), None))
    assert wall >= 0.3 and seconds < 0.05
    found[0] = None                            # inside a compile: counted once

    def in_a_compile():
        with compile_clock.waiting():
            miss()
    seconds, wall = counted(in_a_compile)
    assert 0.5 <= seconds <= wall + 0.01


def test_the_command_counts_the_compiles_of_reading_the_scene(monkeypatch, tmp_path, capsys):
    from rtweekend import cli
    from rtweekend.scene import loader
    load = loader.load_scene

    def slow_load(*args, **kwargs):           # as an OBJ file's reader compiling
        with compile_clock.waiting():
            time.sleep(0.4)
        return load(*args, **kwargs)
    monkeypatch.setattr(loader, "load_scene", slow_load)
    rt.render(rt.load_scene("cornell_box"), spp=1, width=8, height=8, sampling="mixture")
    assert cli.main(["render", "cornell_box", "-o", str(tmp_path / "x.png"), "--spp", "1",
                     "--width", "8", "--height", "8", "--sampling", "mixture", "-q"]) in (0, None)
    summary = capsys.readouterr().out
    seconds = float(re.search(r"plus ([0-9.]+) s compiling", summary).group(1))
    assert seconds >= 0.4, summary


# Packs `weekend` (a BVH), with a standby helper asked to compile the builder
# ahead (as a Renderer does while it compiles its kernels) or alone, and lists
# the functions compiled in this process; prints a hash of the packed arrays.
PACK_WITH_HELPER = WATCH_COMPILES + """
import hashlib, sys
import numpy as np
import rtweekend as rt
from rtweekend.kernel import compile_workers
from rtweekend.path.pack import pack_scene
compile_workers.prestart()
if sys.argv[1:] == ["ahead"]:
    from rtweekend.path import wide_bvh
    compile_workers.compile_ahead(wide_bvh.compile_ahead)
arrays = pack_scene(rt.load_scene("weekend"))
h = hashlib.sha256()
for a in (*arrays.wide, arrays.bvh_prims):
    h.update(np.ascontiguousarray(a).tobytes())
print(h.hexdigest(), " ".join(sorted(set(compiled))))
"""


@pytest.mark.skipif(not compile_workers.enabled(), reason="needs 2 CPUs and file locks")
def test_the_helper_compiles_the_bvh_builder_ahead(tmp_path):
    def pack(name, helpers, *args):
        env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / name),
                   RTWEEKEND_COMPILE_HELPERS="1" if helpers else "0")
        run = subprocess.run([sys.executable, "-c", PACK_WITH_HELPER, *args], env=env,
                             capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, run.stderr[-2000:]
        digest, *compiled = run.stdout.split()
        return digest, set(compiled)
    alone = pack("alone", False)
    assert {"_grow", "_collapse", "_blocks"} <= alone[1]
    # Asked ahead (a Renderer does, then compiles its kernels): the helper
    # compiles the builder and the collapse, this process waits and loads them.
    ahead = pack("ahead", True, "ahead")
    assert not {"_grow", "_assemble", "_collapse", "_blocks"} & ahead[1], ahead[1]
    assert ahead[0] == alone[0]


def _kernel_types(frame, denoise):
    from rtweekend.kernel.disk_cache import signature
    from rtweekend.path import film as films
    film = films.new_film(1, 1, renderers.splats(frame), frame.aov)
    return [(d.py_func.__module__, signature(args))
            for d, args in renderers.kernel_calls(frame, film, denoise)]


@pytest.mark.parametrize("name", [n for n in rt.bundled_scenes()
                                  if rt.load_scene(n).resolved_integrator() == "path"])
def test_the_stand_in_types_each_kernel_as_the_scene_does(name):
    from rtweekend.options import SAMPLINGS, RenderOptions
    scene = rt.load_scene(name)
    cases = [dict(), dict(denoise=True, aov="albedo,normal")]
    if name == "cornell_glass":
        cases += [dict(sampling=m) for m in SAMPLINGS]
    for fields in cases:
        options = RenderOptions.named("test", "path", **fields).for_scene(scene)
        denoise = bool(options.denoise)
        real = _kernel_types(renderers.freeze(scene, options), denoise)
        assert _kernel_types(renderers.freeze(scene, options, stand_in=True), denoise) == real
