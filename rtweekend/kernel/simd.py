"""Four at once: the slab tests of a 4-wide BVH node's children, and the
watertight test of a leaf's four triangles, as vector code (LLVM's
<4 x double>).

Numba compiles scalar code, and leaves LLVM's SLP vectoriser off, so a wide
node's four box tests (wide_bvh.py) ran one after the other; as vector
operations a node visit costs less, and a leaf's triangles tested together
make incoherent rays faster again (benchmarks/meshes.py, docs/performance.md,
benchmarks/results/measurements.md).

The arithmetic is the scalar code's, lane by lane and in the same order --
Numba's own max and min (max(p, q) = q if q > p else p: a NaN from 0 x inf
as q gives p, as p stays NaN, as in the scalar slab test), shapes/triangle.py's
edge functions, determinant and scaled distance -- so the same children are
entered, and the same hits found, as by the scalar code, bit for bit
(tests/test_simd.py).
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


@intrinsic
def watertight4(typingctx, tri, block, o, frame):
    """(det_0..3, t_scaled_0..3): shapes/triangle.py's watertight test of the
    four triangles of `block` in tri (float64 [B, 9, 4], C-contiguous: row r
    of a block is coordinate r of P0, P1, P2 for its four triangles) for the
    ray from o in frame (triangle.ray_frame: kx, ky, kz, sx, sy, sz); det is
    0 where the edge functions' signs say miss.  What is left -- the distance
    against t_max, t = t_scaled / det -- the caller does per triangle, in
    order, as hit_in_frame does."""
    f64, i64 = types.float64, types.int64
    if not (isinstance(tri, types.Array) and tri.ndim == 3 and tri.layout == "C"
            and tri.dtype == f64 and o == types.UniTuple(f64, 3)
            and frame == types.Tuple((i64, i64, i64, f64, f64, f64))):
        return None
    out = types.UniTuple(f64, 2 * LANES)

    def codegen(context, builder, signature, args):
        tri_v, block_v, o_v, frame_v = args
        data = context.make_array(signature.args[0])(context, builder, tri_v).data
        first = builder.mul(block_v, ir.Constant(block_v.type, 9 * LANES))
        kx, ky, kz = (builder.extract_value(frame_v, i) for i in range(3))
        sx, sy, sz = (_splat(builder, builder.extract_value(frame_v, i)) for i in range(3, 6))
        o3 = [builder.extract_value(o_v, i) for i in range(3)]

        def axis(k):                            # o's component k, splat
            zero, two = ir.Constant(k.type, 0), ir.Constant(k.type, 2)
            c = builder.select(builder.icmp_signed("==", k, zero), o3[0], o3[1])
            return _splat(builder, builder.select(builder.icmp_signed("==", k, two), o3[2], c))
        okx, oky, okz = axis(kx), axis(ky), axis(kz)

        def coordinate(vertex, k):              # P_vertex's coordinate k, four triangles
            r = builder.add(ir.Constant(k.type, 3 * vertex), k)
            at = builder.add(first, builder.mul(r, ir.Constant(k.type, LANES)))
            return builder.load(builder.bitcast(builder.gep(data, [at]), _V.as_pointer()),
                                align=8)

        def sheared(vertex):                    # (x, y, z) of P - o in the ray's frame
            px = builder.fsub(coordinate(vertex, kx), okx)
            py = builder.fsub(coordinate(vertex, ky), oky)
            pz = builder.fsub(coordinate(vertex, kz), okz)
            return (builder.fsub(px, builder.fmul(sx, pz)),
                    builder.fsub(py, builder.fmul(sy, pz)), pz)
        ax, ay, az = sheared(0)
        bx, by, bz = sheared(1)
        cx, cy, cz = sheared(2)
        u = builder.fsub(builder.fmul(cx, by), builder.fmul(cy, bx))
        v = builder.fsub(builder.fmul(ax, cy), builder.fmul(ay, cx))
        w = builder.fsub(builder.fmul(bx, ay), builder.fmul(by, ax))
        zero = ir.Constant(_V, [0.0] * LANES)

        def any_of(op, a, b, c):
            return builder.or_(builder.or_(builder.fcmp_ordered(op, a, zero),
                                           builder.fcmp_ordered(op, b, zero)),
                               builder.fcmp_ordered(op, c, zero))
        outside = builder.and_(any_of("<", u, v, w), any_of(">", u, v, w))
        det = builder.select(outside, zero, builder.fadd(builder.fadd(u, v), w))
        t_scaled = builder.fadd(builder.fadd(builder.fmul(builder.fmul(u, sz), az),
                                             builder.fmul(builder.fmul(v, sz), bz)),
                                builder.fmul(builder.fmul(w, sz), cz))
        result = cgutils.get_null_value(context.get_value_type(out))
        for i in range(LANES):
            lane = ir.Constant(_I32, i)
            result = builder.insert_value(result, builder.extract_element(det, lane), i)
            result = builder.insert_value(result, builder.extract_element(t_scaled, lane),
                                          LANES + i)
        return result
    return out(tri, block, o, frame), codegen
