"""Four costs of Numba's compiler that buy this package nothing, taken out once
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
- **A list per value when listing an instruction's variables.**  Every
  liveness and use-def analysis (run again after most passes, for every
  function and signature) asks each statement for its variables; Numba's walk
  builds a list for every value it meets, a location or a name included, and
  tests each against four classes.  Here one list is filled, values that hold
  no variable are skipped by their type, and an expression's own walk is
  taken inline: the same variables, the same objects, in the same order.

What they cost (py-spy, a cold compile of cornell_box, helpers off): about 4%,
3%, 4% and 2% of its compile; benchmarks/results/measurements.md has the
figures.  All four are process-wide: Numba code of the user's own in the same
process gets the plain messages too, the same types and analyses, and no
llvm_lock timer.
"""
from llvmlite.binding import ffi
from numba.core import errors, ir, types
from numba.core.typing import npydecl

# Values an IR instruction holds that are neither variables nor hold any
# (the original walk returns [] for them after four isinstance tests each).
_LEAVES = frozenset({getattr(ir, "Loc", str), str, int, float, bool, type(None)})


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


def _gather(val, found):
    """Append the variables in val to found, in the order Numba's walk lists them."""
    kind = type(val)
    if kind in _LEAVES:
        return
    if kind is ir.Expr:                     # Expr.list_vars: the walk of its _kws
        for v in val._kws.values():
            _gather(v, found)
    elif isinstance(val, ir.Var):
        found.append(val)
    elif isinstance(val, ir.Inst):
        found.extend(val.list_vars())
    elif isinstance(val, (list, tuple)):
        for v in val:
            _gather(v, found)
    elif isinstance(val, dict):
        for v in val.values():
            _gather(v, found)


def _vars_in(self, val):
    """Numba's Inst._rec_list_vars (the variables an instruction uses or
    defines, for every liveness and use-def analysis), the same list in the
    same order, built into one list instead of one per value."""
    found = []
    _gather(val, found)
    return found


_vars_in.numbas_own = getattr(ir.Inst, "_rec_list_vars", None)


def _expr_walks_its_kws():
    """Does this Numba's Expr list its variables as _gather assumes (the walk
    of its _kws and nothing else)?"""
    code = getattr(ir.Expr.list_vars, "__code__", None)
    return code is not None and code.co_names == ("_rec_list_vars", "_kws")


def install():
    """Take the four out; what a Numba or llvmlite version does not have is
    left alone (each lives in their internals)."""
    # Numba's modules each keep the one scheme object (errors.termcolor()):
    # its methods are replaced on that object.
    scheme = errors.termcolor()
    for name in ("code", "errmsg", "filename", "indicate", "highlight", "reset"):
        setattr(scheme, name, _as_is)
    operator = getattr(npydecl, "NumpyRulesArrayOperator", None)
    if operator is not None and not hasattr(operator.generic, "numbas_own"):
        operator.generic = _on_arrays_only(operator.generic)
    if _vars_in.numbas_own is not None and _expr_walks_its_kws():
        ir.Inst._rec_list_vars = _vars_in
    lock = getattr(ffi.lib, "_lock", None)
    for callbacks in list(getattr(lock, "_cblist", ())):
        if getattr(callbacks[0], "__qualname__", "").startswith("_initialize_llvm_lock_event"):
            lock.unregister(*callbacks)

install()
