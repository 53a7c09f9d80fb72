"""The `rtweekend` command: a thin layer over the Python API.

    rtweekend render [SCENE] [-o OUT] [--spp N | --time S] [--width W] ...
                     [--scheduler ADDRESS | --workers N]
    rtweekend scenes

Bad input is reported in one line on stderr with exit status 2.
"""
import argparse
import os
import signal
import sys
import threading
import traceback
from pathlib import Path

from . import checks
from .errors import FieldError, OutputError, SceneError
from .io.formats import HDR, LDR
from .version import version
from .options import SAMPLINGS

DEFAULT_SCENE = "cornell_glass"
EXIT_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130
RENDER_EPILOG = """\
examples:
  rtweekend render                          cornell_glass to ./cornell_glass.png
  rtweekend render cornell_box --spp 16 -o box.png
  rtweekend render weekend --width 600 --time 30      (the height keeps the aspect)
  rtweekend render my_scene.toml -o out.exr --denoise --aov albedo,normal
  rtweekend scenes                          the bundled scenes, a line each

The image goes to SCENE.png in the current folder unless -o says otherwise.
Ctrl-C finishes the pass under way, writes what was rendered and exits with
status 130; a second Ctrl-C stops at once and writes nothing.  Bad input: one
line on stderr and status 2, before anything is rendered.  Scene files:
docs/scenes.md."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        # One line, no usage dump, and the prefix of every other error:
        # "rtweekend: error: render: --spp: ..." (argparse says "argument --spp").
        command = self.prog.partition(" ")[2]
        message = message.removeprefix("argument ")
        self.exit(EXIT_BAD_INPUT, f"rtweekend: error: {command + ': ' if command else ''}"
                                  f"{message} (see {self.prog} --help)\n")


def _option(name, parse=int, **rule):
    """An argparse type for a numeric render option: parsed here, its range
    checked by checks.option, the one rule render() and Renderer use too."""
    def convert(text):
        try:
            value = parse(text)
        except ValueError:
            kind = "an integer" if parse is int else "a number"
            raise argparse.ArgumentTypeError(f"expected {kind}, got '{text}'") from None
        try:
            # threads: the upper bound (Numba's thread count) is checked by
            # render(), so that parsing does not import Numba.
            return checks.option(name, value, threads_available=None, **rule)
        except FieldError as e:
            raise argparse.ArgumentTypeError(e.problem) from None
    return convert


def _positive_int(text):
    """--workers: a count of processes."""
    return _option("threads")(text)


def build_parser():
    parser = _Parser(prog="rtweekend",
                     description="Path-trace the Ray Tracing in One Weekend scenes.")
    parser.add_argument("--version", action="version", version=f"rtweekend {version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    r = sub.add_parser("render", help="render a scene to an image",
                       description="Render a scene file or a bundled scene.",
                       epilog=RENDER_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    r.add_argument("scene", nargs="?", default=DEFAULT_SCENE,
                   help=f"a .toml file or a bundled scene name (default: {DEFAULT_SCENE})")
    r.add_argument("-o", "--output", help=f"output image, by extension: {', '.join(LDR)} "
                   f"(8 bits, the books' tone map) or {', '.join(HDR)} (linear float32; "
                   ".exr needs pip install 'rtweekend[exr]'); default: SCENE.png")
    budget = r.add_mutually_exclusive_group()
    budget.add_argument("--spp", type=_option("spp"), help="samples per pixel "
                        "(default: the scene's)")
    budget.add_argument("--time", type=_option("time", float), metavar="SECONDS",
                        help="render passes until this many seconds are spent")
    r.add_argument("--width", type=_option("width"), help="image width (default: the scene's; "
                   "alone, the height follows the scene's aspect ratio)")
    r.add_argument("--height", type=_option("height"), help="image height (default: the "
                   "scene's; alone, the width follows)")
    r.add_argument("--seed", type=_option("seed"), default=0, help="random seed (default 0)")
    # 0 is the classic ray tracer's (no reflections); render() rejects it for the path tracer.
    r.add_argument("--max-depth", type=_option("max_depth", integrator="classic"),
                   help="ray segments per path (default: the scene's, 50 in the books); "
                   "for a classic scene, the reflections followed (3 in the book, 0 allowed)")
    r.add_argument("--threads", type=_option("threads"), help="threads of a local render "
                   "(default: all cores)")
    r.add_argument("--sampling", choices=tuple(SAMPLINGS),
                   help="diffuse sampling: the books' 0.5/0.5 mixture, cosine only, lights "
                   "only, or nee: next-event estimation (shadow rays, MIS) with Russian "
                   "roulette; lightpath: light tracing; bdpt: bidirectional path tracing "
                   "(caustics without fireflies); +sobol: low-discrepancy points for the "
                   "pixel position and the first bounce; mnee: nee+sobol with connections "
                   "to the lights through smooth glass; bdpt+photons: bdpt+sobol with "
                   "caustic photon maps for caustics seen through glass (consistent); "
                   "bdpt+mnee: bdpt+sobol with mnee's connections where the camera sees "
                   "through glass (default: bdpt+photons, bdpt+mnee or bdpt+sobol where "
                   "light can reach metal or glass, else mixture+sobol)")
    r.add_argument("--clamp", type=_option("clamp", float), metavar="X", help="cap every sample's "
                   "channels at X: fewer fireflies, but BIASED (darker); off by default")
    r.add_argument("--denoise", action="store_true", help="write the image denoised by Intel "
                   "Open Image Denoise (biased: smooth, not exact; .npy/.exr also keep the "
                   "unbiased one as the layer 'unbiased'). Needs pip install "
                   "'rtweekend[denoise]'")
    r.add_argument("--tev", nargs="?", const="", metavar="HOST:PORT",
                   help="stream the image to a running tev viewer as it renders, with the "
                   "standard error as channels stderr.R/G/B (default address: tev's own, "
                   "127.0.0.1:14158); none listening: one warning, the render goes on")
    r.add_argument("--aov", metavar="NAMES", help="also save feature images, comma-separated: "
                   "albedo, normal, emission, and the per-pixel standard error stderr (.exr: "
                   "layers NAME.R/G/B; .npy: OUT.NAME.npy beside OUT.npy)")
    cluster = r.add_mutually_exclusive_group()
    cluster.add_argument("--scheduler", metavar="ADDRESS", help="render on the Dask cluster "
                         "of this scheduler (tcp://HOST:8786); same image as here. Needs "
                         "pip install 'rtweekend[dask]'")
    cluster.add_argument("--workers", type=_positive_int, metavar="N", help="render on a "
                         "local Dask cluster of N single-threaded worker processes")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    sub.add_parser("scenes", help="list the bundled scenes",
                   description="List the bundled scenes with a line about each.")
    c = sub.add_parser("cache", help="list or clear the compiled kernels on disk",
                       description="The compiled kernels, each kept until the sources it "
                       "was built from change; say how much is there, or remove the old ones.")
    c.add_argument("action", nargs="?", choices=("list", "clear"), default="list")
    c.add_argument("--all", action="store_true", help="with clear: every kernel "
                   "(the next render compiles again)")
    return parser


def _warn_in_one_line(message, category, filename, lineno, file=None, line=None):
    """Warnings (SceneWarning: a scene that renders but looks unintended) as the
    command's other messages: one line on stderr; the render goes on."""
    print(f"rtweekend: warning: {message}", file=sys.stderr)


def main(argv=None):
    import warnings
    in_main_thread = threading.current_thread() is threading.main_thread()
    interrupt = signal.getsignal(signal.SIGINT) if in_main_thread else None
    try:
        with warnings.catch_warnings():      # restored on return (main in a test)
            warnings.showwarning = _warn_in_one_line
            return _main(argv)
    finally:
        # _render ignores Ctrl-C once its file is written; a caller of main()
        # (a test, a script) gets its own handler back -- and the processes it
        # starts then do not inherit an ignored Ctrl-C.
        if in_main_thread:
            signal.signal(signal.SIGINT, interrupt)


def _main(argv):
    args = build_parser().parse_args(argv)
    try:
        if args.command == "scenes":
            return _scenes()
        if args.command == "cache":
            return _cache(args)
        return _render(args)
    except SceneError as e:
        print(f"rtweekend: error: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except RuntimeError as e:
        from .kernel.compile_workers import CompileError
        if not isinstance(e, CompileError):
            raise
        print(f"rtweekend: error: {e}", file=sys.stderr)
        return EXIT_FAILED
    except MemoryError:
        # The memory check (memory.py) comes first; this is its safety net.
        print("rtweekend: error: out of memory: render a smaller image; nothing written",
              file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as e:
        # A second Ctrl-C, one before rendering began, or one during the write:
        # stop at once.  The files being written are removed; nothing else was.
        writer = sys.modules.get(f"{__package__}.io.image")   # loaded if it wrote
        if writer is not None:
            writer.abandon_writes()
        _leave(EXIT_INTERRUPTED, f"rtweekend: {_what_was_interrupted(e)}; nothing written")


def _what_was_interrupted(error):
    """"Ctrl-C while compiling" when Numba was compiling (reading a mesh or
    packing the scene compiles too), else "interrupted"."""
    frames = traceback.extract_tb(error.__traceback__)
    clock = sys.modules.get(f"{__package__}.kernel.compile_clock")
    compiling = (any("/numba/" in frame.filename.replace("\\", "/") for frame in frames)
                 or (clock is not None and clock.running() is not None))
    return "Ctrl-C while compiling" if compiling else "interrupted"


def _leave(status, line):
    """Print one line and exit now: os._exit, not interpreter shutdown, because
    a compile or a pass abandoned on Ctrl-C may still be running in its thread
    (kernel/calls.py), and shutting down under it can crash or hang."""
    print(line, file=sys.stderr)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)


# The renderer is imported when a command needs it, so that --help, `scenes` and
# a bad option answer without loading Numba (half a second).

def _scenes():
    from .scene.loader import bundled_scenes
    scenes = bundled_scenes()
    width = max(map(len, scenes))
    for name, description in scenes.items():
        print(f"{name:<{width}}  {description}")
    return 0


def _cache(args):
    from . import cache
    if args.action == "clear":
        removed, freed = cache.clear(everything=args.all)
        print(f"removed {removed} file{'s' * (removed != 1)}, {freed / 1e6:.1f} MB, "
              f"from {cache.current()}")
        return 0
    total, stale, old = cache.summary()
    print(f"{cache.current()}  {total / 1e6:7.1f} MB, of which {stale / 1e6:.1f} MB built "
          "from sources that have changed since")
    for folder, size in old:
        print(f"{folder}  {size / 1e6:7.1f} MB  (an earlier release's)")
    return 0


def _render(args):
    from .api import render
    from .distributed import dask_client
    from .io.image import check_output_path, save_image
    from .io.progress import Spinner
    from .kernel.calls import call_awake
    from .kernel.compile_clock import Stopwatch
    from .kernel.compile_workers import prestart
    from .scene.loader import load_scene

    if not (args.scheduler or args.workers):
        prestart()      # a helper process: it can compile beside this one (compile_workers)
    loading = Stopwatch()               # the command's compiles start here
    with Spinner(not args.quiet):       # a mesh file's reader may compile first
        # In the worker thread, this one awake (kernel/calls.py): a Ctrl-C that
        # lands inside Numba's compiler can be lost or leave it half done.
        scene = call_awake(lambda: load_scene(args.scene))
    loading_compile = loading.seconds()
    output = Path(args.output) if args.output else Path(f"{scene.name}.png")
    check_output_path(output)            # before spending minutes on the render
    layered = output.suffix.lower() in (".npy", ".exr")
    if args.aov and not layered:
        raise SceneError(f"--aov: {output}: only .npy and .exr files hold feature images; "
                         "write one of those")
    with dask_client(scene, scheduler=args.scheduler, workers=args.workers,
                     threads=args.threads) as client:
        result = render(scene, spp=args.spp, time=args.time, seed=args.seed,
                        width=args.width, height=args.height, max_depth=args.max_depth,
                        threads=args.threads, sampling=args.sampling, clamp=args.clamp,
                        progress=not args.quiet, client=client, aov=args.aov,
                        denoise=args.denoise,
                        preview=False if args.tev is None else f"tev://{args.tev}")
    stats = result.stats
    if loading_compile > 0:             # the mesh reader's, before the render's own
        stats.compile_seconds += loading_compile
        stats.compiled = True
    if stats.samples == 0:
        when = "while compiling" if stats.seconds == 0 else "before the first samples"
        _leave(EXIT_INTERRUPTED, f"rtweekend: {stats.stopped_by or 'stopped'} {when}; "
               "nothing written")
    image, layers = result.image, dict(result.aov)
    if result.denoised is not None:
        image = result.denoised
        if layered:
            layers["unbiased"] = result.image
    metadata = dict(spp=stats.spp, seed=stats.seed, seconds=f"{stats.seconds:.3f}",
                    sampling=stats.sampling_named if stats.sampling else "", version=version(),
                    denoised=result.denoised is not None)
    try:
        # In the worker thread, this one awake: Ctrl-C during a long encode
        # stops at once (and _main removes what was being written).
        call_awake(lambda: save_image(image, output, layers, metadata))
    except OSError as e:
        raise OutputError(f"{output}: cannot write: {e.strerror or e}") from None
    # The file is in place: a Ctrl-C now would only turn the exit status into
    # a signal's; the two lines below take no time.
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    print(f"{output}: {stats.summary()}")
    if stats.interrupted:
        why = "interrupted" if stats.stopped_by in (None, "Ctrl-C") else stats.stopped_by
        print(f"rtweekend: {why}; {output} holds the {stats.spp} spp rendered"
              f"{stats.partial_note}", file=sys.stderr)
        return EXIT_INTERRUPTED
    return 0


if __name__ == "__main__":
    sys.exit(main())
