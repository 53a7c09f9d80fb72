"""Where a sample's time goes: the compiled kernel's source lines, beside the yardstick's.

    python benchmarks/profile_kernel.py [--scene cornell_glass] [--sampling mixture]
                                        [--seconds 20] [--no-yardstick]

Each side runs in a process of its own -- one thread, an empty Numba cache,
Numba's debug records on (NUMBA_DEBUGINFO=1) but not what Numba's debug mode
does besides (keeping_the_code below), so that the optimised code keeps its
shape -- rendering 300x300 passes of two samples under `perf record` for
--seconds.  A kernel is one machine-code
function with every step inlined, so a symbol says nothing: each sampled
address is looked up in the library that holds it, emitted again as an object
file (the JIT's own code, byte for byte but for relocated operands), and
`addr2line -i` gives the chain of source lines inlined at that address.  A
sample counts for every function on its chain (inclusive share) and for the
innermost line (leaf share).  The yardstick: ../shared/yardsticks/numba_probe.py,
its float64 build under rtweekend's fastmath flags (benchmarks/yardstick.py),
the same scene and estimator (its lines are known less well: STRING_SOURCE).

Samples/s here are each side alone, not a ratio (benchmarks/paired.py gives
that).  Needs Linux perf and binutils (addr2line, nm); says so in one
line without them.  Writes benchmark-results/profile_kernel.json.

    python benchmarks/profile_kernel.py --count [--passes 8] [--size 64]

counts instead of sampling: each side runs under valgrind's callgrind,
counting switched on (callgrind_control) around --passes passes of
size x size x 2 once the kernel is compiled, and every instruction the kernel
executed is classed by its opcode (floating point, loads from and stores to
the stack, other moves, jumps, compares, other integer work) and, for
rtweekend, by the step of its path loop it was inlined from (the callee
named on the `trace` line of its chain).  Per camera sample, exact and
repeatable where timings on a shared machine are not.  Needs valgrind
(with callgrind_control) and binutils (objdump besides); writes
benchmark-results/profile_kernel_count.json.

    python benchmarks/profile_kernel.py --count --branches

counts the conditional branches callgrind's branch simulator
(--branch-sim=yes) finds mispredicted instead of instructions, each side's
by the line its branch came from (rtweekend's by step too): a simulated
predictor, not the processor's, but the same for both sides.  Writes
benchmark-results/profile_kernel_branches.json.
"""
import argparse
import ast
import bisect
import collections
import functools
import gc
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import yardstick  # noqa: E402
from common import machine, save_json  # noqa: E402
from common import parser as bench_parser  # noqa: E402

SIZE, SPP = 300, 2
TOOLS = ("perf", "addr2line", "nm")
COUNT_TOOLS = ("valgrind", "callgrind_control", "addr2line", "nm", "objdump")
MIN_SYMBOL_SHARE = 0.005     # symbols below this share are not looked into
# The yardstick's prange loop is compiled from generated source: its lines come
# as "<string>" with the line numbers of the yardstick's file, and the code Numba
# inlined into it (the yardstick's inline="always" functions) often with no
# line at all, counted for the file alone.
STRING_SOURCE = {}


def workload(side, scene, sampling, size=SIZE):
    """A function rendering one pass (size x size x SPP) of the side's kernel
    (compiled by then)."""
    if side == "rtweekend":
        import rtweekend as rt
        r = rt.Renderer(rt.load_scene(scene), seed=1, sampling=sampling, width=size,
                        height=size)
        r.compile()
        r.add_samples(1)
        return lambda: r.add_samples(SPP)
    probe = yardstick.load("rtweekend_flags_f64")
    STRING_SOURCE["<string>"] = probe.__file__
    passes = iter(range(1, 1 << 30))
    probe.render(size, size, 1)
    return lambda: probe.render(size, size, SPP, pass0=SPP * next(passes))


def jit_symbols():
    """[(address, name)] of every function Numba's JIT holds, sorted."""
    from numba.core.registry import cpu_target
    engine = cpu_target.target_context.codegen()._engine
    found = []
    for name in engine._defined_symbols:
        try:
            address = engine.get_function_address(name)
        except Exception:       # a global that is no function
            continue
        if address:
            found.append((address, name))
    return sorted(found)


def object_of(symbol, folder):
    """(object file, offset of symbol in its code section, section) of the
    library defining symbol, emitted again; None if no library has it."""
    import numba
    for lib in gc.get_objects():
        if not isinstance(lib, numba.core.codegen.CPUCodeLibrary):
            continue
        module = getattr(lib, "_final_module", None)
        if module is None:
            continue
        try:
            if module.get_function(symbol).is_declaration:
                continue
        except NameError:
            continue
        path = folder / f"lib{id(lib)}.o"
        if not path.exists():
            path.write_bytes(lib._codegen._tm.emit_object(module))
        table = subprocess.run(["nm", str(path)], capture_output=True, text=True).stdout
        for line in table.splitlines():
            if line.endswith(" " + symbol):
                return path, int(line.split()[0], 16)
    return None


def inline_chains(path, offsets):
    """{offset: [file:line, ...]} innermost first, by addr2line -i."""
    text = "\n".join(f"{o:x}" for o in offsets) + "\n"
    out = subprocess.run(["addr2line", "-a", "-i", "-e", str(path)], input=text,
                         capture_output=True, text=True).stdout.splitlines()
    chains, current = {}, None
    for line in out:
        if line.startswith("0x"):
            current = chains.setdefault(int(line, 16), [])
        elif current is not None:
            current.append(line.split(" (discriminator")[0])
    return chains


@functools.lru_cache(maxsize=None)
def _functions_of(path):
    """[(first line, last line, name)] of a Python file's functions."""
    try:
        tree = ast.parse(Path(path).read_text())
    except (OSError, SyntaxError, ValueError):
        return []
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            found.append((node.lineno, node.end_lineno, node.name))
    return sorted(found, key=lambda f: f[1] - f[0])      # innermost first


def function_at(frame):
    """'module.py:function' for a file:line frame (file alone if unknown)."""
    path, _, line = frame.rpartition(":")
    path = STRING_SOURCE.get(Path(path).name, path)
    short = path.split("rtweekend/")[-1] if "rtweekend/" in path else Path(path).name
    if line.isdigit():
        for first, last, name in _functions_of(path):
            if first <= int(line) <= last:
                return f"{short}:{name}"
    return short


def keeping_the_code():
    """Numba's debug mode also marks every function noinline (but those that
    must be inlined), keeps variables alive to the end of their blocks and
    checks every array index against its bounds: the yardstick, whose helpers
    LLVM inlines, then ran 1.84x the instructions per sample, rtweekend 1.73x
    (counted under callgrind; the bounds checks alone cost rtweekend 1.39x).
    Undone here, only the debug records stay: the same instruction counts as
    without them, to a few in a million.  (A function that asks for bounds
    checks itself keeps them.)"""
    from numba.core import cpu, lowering
    finalize, pre_lower = cpu.CPUTargetOptions.finalize, lowering.Lower.pre_lower

    def plain_finalize(self, flags, options):
        flags.dbg_extend_lifetimes = False
        if not flags.is_set("boundscheck"):
            flags.boundscheck = False
        finalize(self, flags, options)

    def inlinable_pre_lower(self):
        marked = "noinline" in self.builder.function.attributes
        pre_lower(self)
        if not marked:
            self.builder.function.attributes.discard("noinline")

    cpu.CPUTargetOptions.finalize = plain_finalize
    lowering.Lower.pre_lower = inlinable_pre_lower


def profile_here(side, scene, sampling, seconds):
    """The child process's work: render under perf, attribute, print JSON."""
    keeping_the_code()
    render = workload(side, scene, sampling)
    symbols = jit_symbols()
    starts = [a for a, _ in symbols]
    render()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        data = tmp / "perf.data"
        perf = subprocess.Popen(["perf", "record", "-F", "2000", "-q", "-p", str(os.getpid()),
                                 "-o", str(data)], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        time.sleep(1.0)                         # perf attached
        t0, passes = time.perf_counter(), 0
        while time.perf_counter() - t0 < seconds:
            render()
            passes += 1
        elapsed = time.perf_counter() - t0
        perf.send_signal(signal.SIGINT)
        perf.wait()
        ips = subprocess.run(["perf", "script", "-i", str(data), "-F", "ip"],
                             capture_output=True, text=True).stdout.split()
        by_symbol = collections.defaultdict(collections.Counter)
        total = 0
        for ip in ips:
            ip = int(ip, 16)
            total += 1
            i = bisect.bisect_right(starts, ip) - 1
            if i >= 0 and (i + 1 == len(starts) or ip < starts[i + 1]):
                by_symbol[symbols[i][1]][ip - starts[i]] += 1
        inclusive, leaf = collections.Counter(), collections.Counter()
        attributed = 0
        for symbol, offsets in by_symbol.items():
            if sum(offsets.values()) < MIN_SYMBOL_SHARE * total:
                continue
            found = object_of(symbol, tmp)
            if found is None:
                continue
            path, base = found
            chains = inline_chains(path, [base + o for o in offsets])
            for offset, count in offsets.items():
                chain = chains.get(base + offset) or ["?"]
                attributed += count
                leaf[function_at(chain[0]) + ":" + chain[0].rpartition(":")[2]] += count
                for name in dict.fromkeys(function_at(f) for f in chain):
                    inclusive[name] += count

    def share(counts):
        return [dict(name=k, share=v / total) for k, v in counts.most_common(60)]
    print(json.dumps(dict(samples=total, attributed=attributed / max(total, 1),
                          samples_per_s=passes * SIZE * SIZE * SPP / elapsed,
                          inclusive=share(inclusive), leaf=share(leaf))))


# -- counting under callgrind ------------------------------------------------------

def _wait_for(path):
    """Poll for a file (not block: callgrind takes its commands between the
    program's instructions, so a process asleep in a read would never see them)."""
    while not path.exists():
        time.sleep(0.01)


def callgrind_costs(path, event="Ir"):
    """{address: count of `event`} of a callgrind dump made with
    --dump-instr=yes (its compressed positions: absolute, +/- relative, * the
    same; a call's cost line, which counts the callee's inclusive cost, left
    out).  Ir: instructions executed; Bcm: conditional branches mispredicted
    (--branch-sim=yes; a line leaves out its trailing zero counts)."""
    costs, last, after_call = collections.Counter(), 0, False
    positions, column = 1, 0
    for line in Path(path).read_text().splitlines():
        if line.startswith("positions:"):
            positions = len(line.split()) - 1
            continue
        if line.startswith("events:"):
            column = line.split()[1:].index(event)
            continue
        if line.startswith("calls="):
            after_call = True
            continue
        fields = line.split()
        if len(fields) < 2 or not (fields[0][0] in "+-*" or fields[0].startswith("0x")):
            continue
        a = fields[0]
        position = (int(a, 16) if a.startswith("0x") else last + int(a) if a[0] in "+-"
                    else last)
        last = position
        if after_call:
            after_call = False
            continue
        counts = fields[positions:]
        if column < len(counts) and counts[column].isdigit():
            costs[position] += int(counts[column])
    return costs


def opcode_class(opcode, operands):
    """The class of one instruction, as `objdump -d` writes it (AT&T)."""
    if opcode == "?":
        return "not disassembled"
    if "(%rsp)" in operands:
        return "stack load" if operands.index("(%rsp)") < operands.rfind(",") else "stack store"
    if opcode.startswith("j"):
        return "jump"
    if opcode.startswith("v") and opcode.endswith(("sd", "pd", "ss", "ps")):
        return "floating point"
    if opcode.startswith("mov"):
        return "other move"
    if opcode in ("cmp", "test"):
        return "compare"
    return "other integer"


def symbol_size(path, symbol):
    """The size in bytes of a function of an object file (nm -S)."""
    table = subprocess.run(["nm", "-S", str(path)], capture_output=True, text=True).stdout
    for line in table.splitlines():
        fields = line.split()
        if len(fields) == 4 and fields[3] == symbol:
            return int(fields[1], 16)
    return 0


def jit_disassembly(start, end, folder):
    """{address: (opcode, operands)} of the JIT's own code from start to end
    in this process (read from its memory: the object file emitted again can
    encode some instructions otherwise, the yardstick's large code model)."""
    with open("/proc/self/mem", "rb") as memory:
        memory.seek(start)
        code = memory.read(end - start)
    raw = folder / f"code_{start:x}.bin"
    raw.write_bytes(code)
    text = subprocess.run(["objdump", "-D", "-b", "binary", "-m", "i386:x86-64",
                           "--no-show-raw-insn", f"--adjust-vma={start}", str(raw)],
                          capture_output=True, text=True).stdout
    found = {}
    for line in text.splitlines():
        head, _, rest = line.partition(":\t")
        if rest and head.strip() and all(c in "0123456789abcdef" for c in head.strip()):
            opcode, _, operands = rest.strip().partition(" ")
            found[int(head.strip(), 16)] = (opcode, operands.strip())
    return found


def count_here(side, scene, sampling, passes, size, signals, event="Ir"):
    """The child's work under callgrind: compile, then passes with counting on
    (the parent switches it), then attribute the kernel's counts of `event`
    (Ir: instructions; Bcm: mispredicted conditional branches)."""
    keeping_the_code()
    render = workload(side, scene, sampling, size)
    render()
    (signals / "ready").touch()
    _wait_for(signals / "go")
    for _ in range(passes):
        render()
    (signals / "done").touch()
    _wait_for(signals / "bye")
    costs = callgrind_costs(max(signals.glob("callgrind.out.*"),
                                key=lambda f: int(f.suffix[1:])), event)
    symbols = jit_symbols()
    starts = [a for a, _ in symbols]
    by_symbol = collections.defaultdict(dict)
    for address, n in costs.items():
        i = bisect.bisect_right(starts, address) - 1
        if i >= 0 and (i + 1 == len(starts) or address < starts[i + 1]):
            by_symbol[symbols[i][1]][address - starts[i]] = n
    samples = passes * size * size * SPP
    index = {name: i for i, (_, name) in enumerate(symbols)}
    classes, steps, lines = collections.Counter(), collections.Counter(), collections.Counter()
    for symbol, offsets in by_symbol.items():
        found = object_of(symbol, signals)
        if found is None:
            continue
        path, base = found
        start, size = starts[index[symbol]], symbol_size(path, symbol)
        # Addresses past the function's end are another library's (libm, Python).
        offsets = {o: n for o, n in offsets.items() if o < size}
        code = jit_disassembly(start, start + size, signals)
        chains = inline_chains(path, [base + o for o in offsets])
        for offset, n in offsets.items():
            opcode, operands = code.get(start + offset, ("?", ""))
            classes[opcode_class(opcode, operands)] += n
            classes["all"] += n
            chain = chains.get(base + offset) or ["?"]
            lines[function_at(chain[0]) + ":" + chain[0].rpartition(":")[2]] += n
            if side == "rtweekend":
                steps[_step(chain)] += n
    per_sample = {k: v / samples for k, v in classes.most_common()}
    by_step = {k: v / samples for k, v in steps.most_common()}
    by_line = {k: v / samples for k, v in lines.most_common(40)}
    print(json.dumps(dict(samples=samples, per_sample=per_sample, by_step=by_step,
                          by_line=by_line)))


def _step(chain):
    """The step of the path loop an instruction comes from: the function called
    on the `trace` line of its chain (trace itself where it is the innermost),
    or 'outside trace' (the camera ray, the sampler's start, the film)."""
    names = [function_at(f) for f in chain]
    for i, name in enumerate(names):
        if name.endswith(":trace"):
            return names[i - 1].rpartition(":")[2] if i > 0 else "trace (its own lines)"
    return "outside trace"


def count_side(side, args):
    """Run the side under callgrind, counting around its passes; its JSON."""
    env = dict(os.environ, NUMBA_DEBUGINFO="1", NUMBA_NUM_THREADS="1",
               RTWEEKEND_COMPILE_HELPERS="0")
    with tempfile.TemporaryDirectory() as tmp:
        signals = Path(tmp)
        env["NUMBA_CACHE_DIR"] = str(signals / "cache")
        # The child's output to files: a pipe nobody reads while it runs would
        # fill with valgrind's and Numba's messages and stop it.
        out_file, err_file = signals / "stdout.txt", signals / "stderr.txt"
        with out_file.open("w") as out, err_file.open("w") as err:
            child = subprocess.Popen(
                ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--dump-instr=yes",
                 "--smc-check=all-non-file", f"--branch-sim={'yes' if args.branches else 'no'}",
                 f"--callgrind-out-file={signals / 'callgrind.out'}",
                 sys.executable, __file__, "--child", side, "--count", "--scene", args.scene,
                 "--sampling", args.sampling, "--passes", str(args.passes), "--size",
                 str(args.size), "--signals", str(signals)]
                + (["--branches"] if args.branches else []),
                env=env, stdout=out, stderr=err)

        def failed():
            return SystemExit(f"profile_kernel: the {side} process failed:\n"
                              f"{err_file.read_text()[-2000:]}")

        def when(signal, *command):
            """Once the child touched `signal`, callgrind_control `command` on it."""
            while not (signals / signal).exists():
                if child.poll() is not None:
                    raise failed()
                time.sleep(0.1)
            subprocess.run(["callgrind_control", *command, str(child.pid)],
                           capture_output=True, check=True)

        try:
            when("ready", "-i", "on")           # compiled and warmed up: count
            (signals / "go").touch()
            when("done", "-i", "off")           # its passes rendered
            when("done", "-d")                  # the counts to a file it reads
            (signals / "bye").touch()
            child.wait()
        finally:
            if child.poll() is None:
                child.kill()
        if child.returncode:
            raise failed()
        return json.loads(out_file.read_text().strip().splitlines()[-1])


def count(args):
    missing = [t for t in COUNT_TOOLS if shutil.which(t) is None]
    if missing:
        print(f"profile_kernel: --count needs {', '.join(missing)}; not run")
        return
    sides = ["rtweekend"]
    if not args.no_yardstick and args.scene == "cornell_glass" and args.sampling == "mixture":
        if yardstick.available():
            sides.append("yardstick")
    results = {side: count_side(side, args) for side in sides}
    # Mispredicted branches are all conditional jumps: no classes but "all".
    classes = (["all"] if args.branches else
               list(dict.fromkeys(k for r in results.values() for k in r["per_sample"])))
    digits = 1 if args.branches else 0
    what = ("mispredicted conditional branches (callgrind's simulated predictor)"
            if args.branches else "instructions")
    print(f"kernel {what} per camera sample ({args.scene}, {args.sampling}, "
          f"{args.passes} passes of {args.size}x{args.size}x{SPP}, one thread):")
    print(f"  {'':16s}" + "".join(f"{side:>12s}" for side in results))
    for k in classes:
        print(f"  {k:16s}" + "".join(f"{r['per_sample'].get(k, 0.0):12.{digits}f}"
                                      for r in results.values()))
    if "rtweekend" in results:
        print("rtweekend by step of its path loop:")
        for k, v in results["rtweekend"]["by_step"].items():
            print(f"  {v:8.{digits}f}  {k}")
    if args.branches:
        for side, r in results.items():
            print(f"{side}, its lines with the most:")
            for k, v in list(r["by_line"].items())[:15]:
                print(f"  {v:8.1f}  {k}")
    name = "profile_kernel_branches.json" if args.branches else "profile_kernel_count.json"
    path = save_json(name,
                     dict(machine=machine(), scene=args.scene, sampling=args.sampling,
                          size=args.size, passes=args.passes, sides=results), args.out)
    print(f"wrote {path}")


def run_side(side, args):
    env = dict(os.environ, NUMBA_DEBUGINFO="1", NUMBA_NUM_THREADS="1",
               RTWEEKEND_COMPILE_HELPERS="0")
    with tempfile.TemporaryDirectory() as cache:
        env["NUMBA_CACHE_DIR"] = cache
        r = subprocess.run([sys.executable, __file__, "--child", side, "--scene", args.scene,
                            "--sampling", args.sampling, "--seconds", str(args.seconds)],
                           env=env, capture_output=True, text=True)
    if r.returncode:
        raise SystemExit(f"profile_kernel: the {side} process failed:\n{r.stderr[-2000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def main():
    p = bench_parser(__doc__)
    p.add_argument("--scene", default="cornell_glass")
    p.add_argument("--sampling", default="mixture")
    p.add_argument("--seconds", type=float, default=20.0)
    p.add_argument("--no-yardstick", action="store_true")
    p.add_argument("--count", action="store_true",
                   help="count instructions under callgrind instead of sampling time")
    p.add_argument("--passes", type=int, default=8, help="--count: passes counted")
    p.add_argument("--size", type=int, default=64, help="--count: the image's side")
    p.add_argument("--branches", action="store_true",
                   help="--count: mispredicted conditional branches, not instructions")
    p.add_argument("--child", help=argparse.SUPPRESS)
    p.add_argument("--signals", help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.child and args.count:
        count_here(args.child, args.scene, args.sampling, args.passes, args.size,
                   Path(args.signals), "Bcm" if args.branches else "Ir")
        return
    if args.child:
        profile_here(args.child, args.scene, args.sampling, args.seconds)
        return
    if args.count:
        count(args)
        return
    missing = [t for t in TOOLS if shutil.which(t) is None]
    if missing:
        print(f"profile_kernel: needs {', '.join(missing)} (Linux perf, binutils); not run")
        return
    if args.quick:
        args.seconds = 2.0
    sides = ["rtweekend"]
    if not args.no_yardstick and args.scene == "cornell_glass" and args.sampling == "mixture":
        if yardstick.available():
            sides.append("yardstick")
        else:
            print(f"profile_kernel: no yardstick at {yardstick.PATH}; rtweekend alone")
    results = {side: run_side(side, args) for side in sides}
    for side, r in results.items():
        print(f"\n{side}: {r['samples_per_s'] / 1e6:.2f} M samples/s alone, {r['samples']} "
              f"perf samples, {r['attributed']:.0%} attributed to source lines")
        print("  inclusive (a sample counts for every function inlined on its chain):")
        for row in r["inclusive"][:25]:
            print(f"    {row['share']:6.1%}  {row['name']}")
        print("  leaf lines:")
        for row in r["leaf"][:15]:
            print(f"    {row['share']:6.1%}  {row['name']}")
    if not args.quick:
        path = save_json("profile_kernel.json", dict(machine=machine(), scene=args.scene,
                                                     sampling=args.sampling, size=SIZE,
                                                     seconds=args.seconds, sides=results),
                         args.out)
        print(f"\nwrote {path}")


if __name__ == "__main__":
    main()
