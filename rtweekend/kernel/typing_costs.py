"""Three costs of Numba's compiler that buy this package nothing, taken out once
before anything is compiled (kernel/jit.py imports it).

Type inference tries templates until one fits, and a failed try is cheap only
in principle:

- **Messages in colour.**  With colorama installed (many tools bring it),
  Numba colours every error message it *formats*, and it formats many it
  never shows: each constant it cannot make a literal type (a float) and each
  template that does not fit raises an error whose text is coloured through
  colorama's stream wrappers, set up and torn down per message.  Here messages
  stay plain (one_line() in compile_workers.py strips colours anyway).
- **NumPy's operator templates on scalars.**  `x * y` on two floats is first
  offered to NumPy's ufunc rules, which search the ufunc's whole loop table
  for the operand types and only then notice that no operand is an array and
  decline.  Here they decline before the search: the same answer (None), so
  every type, and every bit of code, is what Numba made before.
- **An event per call into LLVM.**  Numba has llvmlite's lock call it back on
  every acquire and release, to broadcast a "numba:llvm_lock" event to each
  compile's timer (one per level of nested compiles): tens of thousands of
  events per kernel.  Here the callbacks are removed; what is lost is the
  "llvm_lock" entry of a compile's metadata["timers"], which then reads 0
  (NUMBA_LLVM_PASS_TIMINGS=1 still times LLVM's passes).

What they cost (py-spy, a cold compile of cornell_box, helpers off): about 4%,
3% and 4% of its compile; benchmarks/results/measurements.md has the figures.
All three are process-wide: Numba code of the user's own in the same process
gets the plain messages too, the same types, and no llvm_lock timer.
"""
from llvmlite.binding import ffi
from numba.core import errors, types
from numba.core.typing import npydecl


def _as_is(msg):
    return msg


def _on_arrays_only(generic):
    """NumPy's operator template, declining at once when no operand is an array
    (what it returns at its end in that case)."""
    def on_arrays(self, args, kws):
        if not any(isinstance(a, types.ArrayCompatible) for a in args):
            return None
        return generic(self, args, kws)
    on_arrays.numbas_own = generic
    return on_arrays


def install():
    """Take the three out; what a Numba or llvmlite version does not have is
    left alone (each lives in their internals)."""
    # Numba's modules each keep the one scheme object (errors.termcolor()):
    # its methods are replaced on that object.
    scheme = errors.termcolor()
    for name in ("code", "errmsg", "filename", "indicate", "highlight", "reset"):
        setattr(scheme, name, _as_is)
    operator = getattr(npydecl, "NumpyRulesArrayOperator", None)
    if operator is not None and not hasattr(operator.generic, "numbas_own"):
        operator.generic = _on_arrays_only(operator.generic)
    lock = getattr(ffi.lib, "_lock", None)
    for callbacks in list(getattr(lock, "_cblist", ())):
        if getattr(callbacks[0], "__qualname__", "").startswith("_initialize_llvm_lock_event"):
            lock.unregister(*callbacks)

install()
