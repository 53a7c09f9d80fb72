"""One atomic operation: add to an element of an int64 array from any thread.

    atomic_add(counts, (y, x, c), 5)        # returns the element before the add

Numba has no atomics on the CPU, so this emits LLVM's `atomicrmw add` itself
(monotonic ordering: each add is indivisible; no other memory is ordered by it,
and the threads of a pass are joined before anything reads the array).
Integers make the sum independent of the order of the adds, which is what
keeps images that gather contributions from every thread (film.py: splats) the
same bits for any thread count.  The value before the add hands out work: each
thread that adds 1 to a counter gets a number no other thread gets
(kernel/rows.py: the rows of a pass).
"""
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def atomic_add(typingctx, array, index, value):
    """array[index] += value, atomically, returning array[index] as it was
    before; array: int64, C-ordered; index: a tuple of as many integers as the
    array has dimensions (no wraparound, no bounds check: the caller's indices
    are in range)."""
    if not (isinstance(array, types.Array) and array.dtype == types.int64
            and isinstance(index, types.BaseTuple) and len(index) == array.ndim
            and all(isinstance(i, types.Integer) for i in index)
            and isinstance(value, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        array_type, index_type, value_type = signature.args
        ary = context.make_array(array_type)(context, builder, args[0])
        indices = [context.cast(builder, builder.extract_value(args[1], i), t, types.intp)
                   for i, t in enumerate(index_type)]
        pointer = cgutils.get_item_pointer(context, builder, array_type, ary, indices,
                                           wraparound=False)
        amount = context.cast(builder, args[2], value_type, types.int64)
        return builder.atomic_rmw("add", pointer, amount, "monotonic")

    return types.int64(array, index, value), codegen
