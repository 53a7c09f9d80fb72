"""kernel/typing_costs.py: what it takes out of Numba's compiler, and that the
types Numba infers are the ones it inferred before."""
import itertools
import operator

import numpy as np
import pytest
from llvmlite.binding import ffi
from numba import njit, types
from numba.core import errors
from numba.core.registry import cpu_target
from numba.core.typing import npydecl
from numba.core.typing.templates import Signature

from rtweekend.kernel import jit, typing_costs  # noqa: F401  (jit installs it)

SCALARS = [types.float64, types.float32, types.int64, types.boolean, types.uint64]
ARRAYS = [types.float64[:], types.int64[:, :], types.float32[::1]]
OPERATORS = [operator.add, operator.mul, operator.truediv, operator.lt, operator.and_]


def _both_templates(op):
    """The operator's NumPy template as installed, and Numba's own generic."""
    template_class = type("Template", (npydecl.NumpyRulesArrayOperator,), dict(key=op))
    template = template_class(cpu_target.typing_context)
    return template, npydecl.NumpyRulesArrayOperator.generic.numbas_own


@pytest.mark.parametrize("op", OPERATORS)
def test_numpys_operator_template_answers_as_before(op):
    template, numbas_own = _both_templates(op)
    assert template.generic.__func__ is not numbas_own          # installed
    for a, b in itertools.product(SCALARS + ARRAYS, repeat=2):
        mine = template.generic((a, b), {})
        before = numbas_own(template, (a, b), {})
        assert mine == before, (op, a, b)
        if a in SCALARS and b in SCALARS:
            assert mine is None
    # and an array operand still gets NumPy's loop
    assert isinstance(template.generic((types.int64[:], types.int64), {}), Signature)


def test_scalar_operands_never_search_numpys_loops(monkeypatch):
    def search(*args):
        raise AssertionError("searched NumPy's loop table for scalar operands")
    monkeypatch.setattr(npydecl, "ufunc_find_matching_loop", search)
    template, _ = _both_templates(operator.mul)
    assert template.generic((types.float64, types.float64), {}) is None


def test_compiled_arithmetic_is_unchanged():
    @njit
    def f(a, b):
        return a * b + 1.0, a / b, a < b
    assert f(3.0, 2.0) == (7.0, 1.5, False)
    assert np.array_equal(f(np.arange(3.0), 2.0)[0], [1.0, 3.0, 5.0])


def test_messages_stay_plain():
    scheme = errors.termcolor()
    for name in ("code", "errmsg", "filename", "indicate", "highlight", "reset"):
        assert getattr(scheme, name)("a message") == "a message"

    @njit
    def g(x):
        return x.no_such_field
    with pytest.raises(errors.TypingError) as e:
        g(1.0)
    assert "no_such_field" in str(e.value) and "\x1b[" not in str(e.value)


def test_no_event_per_call_into_llvm():
    names = [acquire.__qualname__ for acquire, _ in ffi.lib._lock._cblist]
    assert not [n for n in names if n.startswith("_initialize_llvm_lock_event")]
    typing_costs.install()                                      # twice: no harm
    _, numbas_own = _both_templates(operator.add)
    assert not hasattr(numbas_own, "numbas_own")                # not wrapped twice


def _ir_of(fn):
    """The untyped IR of a Python function, as Numba's front end makes it."""
    from numba.core import compiler
    return compiler.run_frontend(fn)


def _kitchen_sink(a, b, n, *rest):
    total = 0.0
    pairs = [(i, i * 2) for i in range(n)]
    for i, j in pairs:
        if i % 2 and j > a[0]:
            total += a[i] * b[j, 0]
        elif i > 3:
            break
        else:
            a[i] = np.sqrt(abs(total)) + max(i, j, key=None)
    t = (a, b, total, *rest)
    d = {"x": total, "y": n}
    try:
        total += d["x"] / n
    except ZeroDivisionError:
        raise ValueError("n")
    return t[2], np.zeros(shape=(n, 2), dtype=np.float64), total if total > 0 else -total


def test_variables_are_listed_as_numba_lists_them(monkeypatch):
    """Every liveness and use-def analysis asks each statement for its
    variables: the faster walk gives the same Var objects in the same order."""
    from numba.core import ir
    from rtweekend.path import bvh
    from rtweekend.path.integrators import path
    assert ir.Inst._rec_list_vars is typing_costs._vars_in        # installed
    statements = [stmt for fn in (_kitchen_sink, path.trace.py_func,
                                  bvh.stackless_walk.py_func)
                  for block in _ir_of(fn).blocks.values() for stmt in block.body]
    loc = ir.Loc("f", 1)
    scope = ir.Scope(None, loc)
    x, y, z = (ir.Var(scope, name, loc) for name in "xyz")
    # values nested in lists, tuples and dicts, and an instruction of a kind
    # that lists its own (Yield: its value only)
    nested = ir.Expr.build_tuple([x, (y, [z, {"k": x}])], loc)
    statements += [ir.Assign(nested, y, loc), ir.Assign(ir.Yield(z, loc, 0), x, loc)]
    mine = [[id(v) for v in stmt.list_vars()] for stmt in statements]
    assert nested.list_vars() == [x, y, z, x]
    monkeypatch.setattr(ir.Inst, "_rec_list_vars", typing_costs._vars_in.numbas_own)
    before = [[id(v) for v in stmt.list_vars()] for stmt in statements]
    assert mine == before
    assert sum(len(v) > 1 for v in before) > 200          # the IR had variables to list
