"""A NamedTuple of arrays handed to the steps by reference.

Numba passes a NamedTuple argument by value, flattened: every array in it is
seven to nine machine words (pointers, size, shape, strides), so a step that
takes the scene (SceneArrays, some fifteen arrays) has 125 parameters, and
each call packs them and each step unpacks them again.  That plumbing was
most of the LLVM IR the compiler made, typed and optimised -- a ten-line step
such as lights.background came to 300 lines.

A kernel instead makes `by_ref(scene)`: the tuple stored once in its own
stack frame, and a pointer to it that every step takes (one parameter) and
reads a field through (`scene.obj_f` loads that field alone).  Every step is
inlined into the kernel (kernel/jit.py), where LLVM turns the stored tuple
back into values (the pointer never leaves the kernel): the machine code reads
the arrays as before, and the same bits come out.

A Ref reads like the tuple it points to -- its fields by name, `is None` on
an optional field -- so a step is written the same for either; called from
Python (tests) a step gets the plain tuple.
"""
from llvmlite import ir
from numba.core import cgutils, types
from numba.core.imputils import impl_ret_borrowed, lower_getattr_generic
from numba.core.typing.templates import AttributeTemplate
from numba.extending import infer_getattr, intrinsic, models, register_model


class Ref(types.Type):
    """A pointer to a NamedTuple (`target`) in a kernel's stack frame."""

    def __init__(self, target):
        self.target = target
        super().__init__(name=f"Ref({target})")


@register_model(Ref)
class _RefModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        pointee = dmm.lookup(fe_type.target).get_value_type()
        super().__init__(dmm, fe_type, ir.PointerType(pointee))


@infer_getattr
class _RefFields(AttributeTemplate):
    key = Ref

    def generic_resolve(self, ref, attr):
        target = ref.target
        if attr in target.fields:
            return target.types[target.fields.index(attr)]
        return None


@lower_getattr_generic(Ref)
def _field(context, builder, ref, pointer, attr):
    i = ref.target.fields.index(attr)
    value = builder.load(cgutils.gep_inbounds(builder, pointer, 0, i))
    return impl_ret_borrowed(context, builder, ref.target.types[i], value)


@intrinsic
def by_ref(typingctx, record):
    """A Ref to `record` (a NamedTuple), valid while the calling kernel runs;
    None stays None (a feature the kernel is compiled without)."""
    if isinstance(record, types.NoneType):
        return record(record), lambda context, builder, signature, args: args[0]
    if not isinstance(record, types.BaseNamedTuple):
        return None

    def codegen(context, builder, signature, args):
        slot = cgutils.alloca_once(builder, context.get_value_type(record))
        builder.store(args[0], slot)
        return slot

    return Ref(record)(record), codegen
