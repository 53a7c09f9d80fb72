"""A small array on the machine stack, for compiled code that needs scratch
space per call (a BVH walk's stack of nodes to visit) without allocating.

    nodes = stack_array(STACK, np.int64)      # STACK: a compile-time constant

Numba has no such array; this asks LLVM for an `alloca` of a constant size in
the function's entry block (so an inlined caller in a loop reuses one block of
stack, not a new one per iteration) and describes it as a 1-D array with no
owner (no reference counting: it lives as long as the function that made it,
which must not return it).  Its items start undefined, as np.empty's do.
"""
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.arrayobj import populate_array


@intrinsic
def stack_array(typingctx, size, dtype):
    """A 1-D C array of `size` (a compile-time constant) items of `dtype`."""
    if not isinstance(size, types.IntegerLiteral):
        return None                      # the size must be known when compiling
    item = dtype.dtype
    array_type = types.Array(item, 1, "C")

    def codegen(context, builder, signature, args):
        n = size.literal_value
        llvm_item = context.get_value_type(item)
        data = cgutils.alloca_once(builder, llvm_item, size=n)
        itemsize = context.get_constant(types.intp, context.get_abi_sizeof(llvm_item))
        array = context.make_array(array_type)(context, builder)
        populate_array(array, data=data,
                       shape=cgutils.pack_array(builder, [context.get_constant(types.intp, n)]),
                       strides=cgutils.pack_array(builder, [itemsize]),
                       itemsize=itemsize, meminfo=None)
        return array._getvalue()
    return array_type(size, dtype), codegen
