"""Four slab tests at once: what a 4-wide BVH node asks of every ray, as
vector code (LLVM's <4 x double>).

Numba compiles scalar code, and leaves LLVM's SLP vectoriser off, so the four
children's box tests of a wide node (wide_bvh.py) ran one after the other; as
one vector operation each (6 loads, 6 subtractions, 6 multiplications, 5
max/min, 2 compares) they take a node visit from about 90 cycles to about 70
(benchmarks/meshes.py, docs/performance.md).

The arithmetic is the scalar test's, lane by lane and in the same order, with
Numba's own max and min (max(p, q) = q if q > p else p, so a NaN from 0 x inf
takes the other operand): the same children are entered, and the same hits
found, as by the scalar code, bit for bit.
"""
import math

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

LANES = 4
_V = ir.VectorType(ir.DoubleType(), LANES)
_I32 = ir.IntType(32)


def _splat(builder, x):
    v = builder.insert_element(ir.Constant(_V, ir.Undefined), x, ir.Constant(_I32, 0))
    return builder.shuffle_vector(v, ir.Constant(_V, ir.Undefined),
                                  ir.Constant(ir.VectorType(_I32, LANES), [0] * LANES))


def _max(builder, p, q):            # Numba's max(p, q), lane by lane
    return builder.select(builder.fcmp_ordered(">", q, p), q, p)


def _min(builder, p, q):            # Numba's min(p, q)
    return builder.select(builder.fcmp_ordered("<", q, p), q, p)


@intrinsic
def slab4(typingctx, box, node, rows, o, inv_d, t_max):
    """(t_0, t_1, t_2, t_3): where the ray o + t d enters child c's box of
    wide node `node`, 0 if it starts inside, inf if it misses it or enters it
    only at t_max or beyond.  box: float64 [W, 6, 4], C-contiguous (row r of a
    node: bound r of its four children); rows: the int64 rows of the near
    planes of x, y, z and of the far ones (min where d goes up that axis);
    inv_d: 1 / d."""
    f64 = types.float64
    if not (isinstance(box, types.Array) and box.ndim == 3 and box.layout == "C"
            and box.dtype == f64 and o == types.UniTuple(f64, 3)
            and inv_d == types.UniTuple(f64, 3) and t_max == f64):
        return None                     # double precision only
    out = types.UniTuple(types.float64, LANES)

    def codegen(context, builder, signature, args):
        box_v, node_v, rows_v, o_v, inv_v, t_max_v = args
        data = context.make_array(signature.args[0])(context, builder, box_v).data
        first = builder.mul(node_v, ir.Constant(node_v.type, 6 * LANES))

        def bounds(r):                          # row r of the node: four doubles
            at = builder.add(first, builder.mul(r, ir.Constant(r.type, LANES)))
            return builder.load(builder.bitcast(builder.gep(data, [at]), _V.as_pointer()),
                                align=8)
        r = [builder.extract_value(rows_v, i) for i in range(6)]
        o3 = [_splat(builder, builder.extract_value(o_v, i)) for i in range(3)]
        inv3 = [_splat(builder, builder.extract_value(inv_v, i)) for i in range(3)]
        near = [builder.fmul(builder.fsub(bounds(r[i]), o3[i]), inv3[i]) for i in range(3)]
        far = [builder.fmul(builder.fsub(bounds(r[3 + i]), o3[i]), inv3[i]) for i in range(3)]
        zero = ir.Constant(_V, [0.0] * LANES)
        t0 = _max(builder, _max(builder, near[0], near[1]), _max(builder, near[2], zero))
        t1 = _min(builder, _min(builder, far[0], far[1]), far[2])
        enters = builder.and_(builder.fcmp_ordered("<=", t0, t1),
                              builder.fcmp_ordered("<", t0, _splat(builder, t_max_v)))
        t = builder.select(enters, t0, ir.Constant(_V, [math.inf] * LANES))
        result = cgutils.get_null_value(context.get_value_type(out))
        for i in range(LANES):
            result = builder.insert_value(
                result, builder.extract_element(t, ir.Constant(_I32, i)), i)
        return result
    return out(box, node, rows, o, inv_d, t_max), codegen
