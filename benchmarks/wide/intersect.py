"""Closest-hit search for a batch of rays in structure-of-arrays form.

Every kernel loops over objects in the OUTER loop and over rays in the INNER
loop: an object's parameters are loop-invariant scalars (broadcast once into a
vector register), and the inner loop body is straight-line arithmetic ending in
selects (`x if ok else y`), no branch, no call: LLVM's loop vectoriser turns it
into packed AVX-512 code, 8 doubles per instruction, with masked stores of the
running nearest distance t[i] and hit id hit[i].

Self-intersection is rtweekend's, without epsilon (shapes/*.py): a ray that left
object from_obj (frm[i]) never meets a plane or a convex surface it left
outward again, and meets a sphere or box it entered only at the far root /
far slab.  The ids written are rtweekend's object indices.

Rays [n, cap) of a buffer are padding (so that packets are whole); init_hits
gives them, and dead rays, t = 0, which no test can beat.
"""
import math


from .jitopts import kernel

INF = math.inf


@kernel
def init_hits(n, cap, alive, t, hit):
    for i in range(cap):
        live = (i < n) & (alive[i] != 0)
        t[i] = INF if live else 0.0
        hit[i] = -1


@kernel
def rects(n, tab, ids, oa, ob, on, da, db, dn, frm, t, hit):
    """Axis-aligned rects of one kind: the caller passes the coordinate arrays
    in the kind's axis order (a, b: the plane's axes, n: the normal's)."""
    for j in range(tab.shape[0]):
        a0, a1, b0, b1, k = tab[j, 0], tab[j, 1], tab[j, 2], tab[j, 3], tab[j, 4]
        obj = ids[j]
        for i in range(n):
            tt = (k - on[i]) / dn[i]         # dn = 0: inf or nan, rejected below
            x = oa[i] + tt * da[i]
            y = ob[i] + tt * db[i]
            ok = ((tt > 0.0) & (tt < t[i]) & (x >= a0) & (x <= a1) & (y >= b0)
                  & (y <= b1) & (frm[i] != obj))
            t[i] = tt if ok else t[i]
            hit[i] = obj if ok else hit[i]


@kernel
def spheres(n, tab, ids, ox, oy, oz, dx, dy, dz, frm, fin, t, hit):
    """Spheres (unit directions): near root unless the ray left this sphere,
    far root only if it left it inwards."""
    for j in range(tab.shape[0]):
        cx, cy, cz, r2 = tab[j, 0], tab[j, 1], tab[j, 2], tab[j, 3]
        obj = ids[j]
        for i in range(n):
            ex = ox[i] - cx
            ey = oy[i] - cy
            ez = oz[i] - cz
            hb = ex * dx[i] + ey * dy[i] + ez * dz[i]
            c = ex * ex + ey * ey + ez * ez - r2
            disc = hb * hb - c
            sq = math.sqrt(max(disc, 0.0))
            other = frm[i] != obj
            t0 = -hb - sq
            t1 = -hb + sq
            tb = t[i]
            ok0 = other & (t0 > 0.0) & (t0 < tb)
            ok1 = (other | (fin[i] != 0)) & (t1 > 0.0) & (t1 < tb)
            ok = (disc >= 0.0) & (ok0 | ok1)
            t[i] = (t0 if ok0 else t1) if ok else tb
            hit[i] = obj if ok else hit[i]


@kernel
def boxes(n, tab, ids, ox, oy, oz, dx, dy, dz, frm, fin, t, hit):
    """Boxes turned about y and moved (box.py's row): the ray is taken into the
    box's frame and the three slabs are intersected."""
    for j in range(tab.shape[0]):
        lo0, lo1, lo2 = tab[j, 0], tab[j, 1], tab[j, 2]
        hi0, hi1, hi2 = tab[j, 3], tab[j, 4], tab[j, 5]
        c, s = tab[j, 6], tab[j, 7]
        fx, fy, fz = tab[j, 8], tab[j, 9], tab[j, 10]
        obj = ids[j]
        for i in range(n):
            qx = ox[i] - fx
            qz = oz[i] - fz
            lx = c * qx - s * qz
            ly = oy[i] - fy
            lz = s * qx + c * qz
            ex = 1.0 / (c * dx[i] - s * dz[i])
            ey = 1.0 / dy[i]
            ez = 1.0 / (s * dx[i] + c * dz[i])
            u0 = (lo0 - lx) * ex
            u1 = (hi0 - lx) * ex
            v0 = (lo1 - ly) * ey
            v1 = (hi1 - ly) * ey
            w0 = (lo2 - lz) * ez
            w1 = (hi2 - lz) * ez
            near = max(min(u0, u1), min(v0, v1), min(w0, w1))
            far = min(max(u0, u1), max(v0, v1), max(w0, w1))
            other = frm[i] != obj
            use_near = other & (near > 0.0)
            tt = near if use_near else far
            ok = ((other | (fin[i] != 0)) & (near <= far) & (tt > 0.0) & (tt < t[i]))
            t[i] = tt if ok else t[i]
            hit[i] = obj if ok else hit[i]


@kernel
def reciprocals(n, dx, dy, dz, ix, iy, iz):
    for i in range(n):
        ix[i] = 1.0 / dx[i]
        iy[i] = 1.0 / dy[i]
        iz[i] = 1.0 / dz[i]


@kernel
def packet_bvh(n, packet, bvh_box, bvh_node, bvh_prims, sph, sph_row,
               ox, oy, oz, dx, dy, dz, ix, iy, iz, frm, fin, t, hit):
    """rtweekend's stackless BVH walk, for a packet of `packet` rays at once.

    A node's box is tested against every ray of the packet (one vectorised
    loop with an OR reduction); the packet descends if any ray enters it, and
    a leaf's spheres are tested against every ray of the packet (vectorised,
    rays that did not enter the leaf's box just fail the test).  Packets are
    consecutive rays of the batch; padding rays (t = 0) never enter a box.

    The packet's rays are taken as slices, indexed from 0: Numba then knows the
    index is non-negative (no wraparound select), so LLVM sees contiguous
    loads and stores instead of gathers, and vectorises both loops."""
    n_nodes = bvh_node.shape[0]
    for p0 in range(0, n, packet):
        p1 = p0 + packet
        pox, poy, poz = ox[p0:p1], oy[p0:p1], oz[p0:p1]
        pdx, pdy, pdz = dx[p0:p1], dy[p0:p1], dz[p0:p1]
        pix, piy, piz = ix[p0:p1], iy[p0:p1], iz[p0:p1]
        pfrm, pfin, pt, phit = frm[p0:p1], fin[p0:p1], t[p0:p1], hit[p0:p1]
        m = pt.shape[0]
        i = 0
        while i < n_nodes:
            x0, y0, z0 = bvh_box[i, 0], bvh_box[i, 1], bvh_box[i, 2]
            x1, y1, z1 = bvh_box[i, 3], bvh_box[i, 4], bvh_box[i, 5]
            enter = False
            for r in range(m):
                a0 = (x0 - pox[r]) * pix[r]
                a1 = (x1 - pox[r]) * pix[r]
                b0 = (y0 - poy[r]) * piy[r]
                b1 = (y1 - poy[r]) * piy[r]
                c0 = (z0 - poz[r]) * piz[r]
                c1 = (z1 - poz[r]) * piz[r]
                near = max(min(a0, a1), min(b0, b1), min(c0, c1))
                far = min(max(a0, a1), max(b0, b1), max(c0, c1))
                enter |= (near <= far) & (far > 0.0) & (near < pt[r])
            if not enter:
                i = bvh_node[i, 2]
                continue
            count = bvh_node[i, 1]
            if count == 0:
                i += 1
                continue
            first = bvh_node[i, 0]
            for q in range(first, first + count):
                obj = bvh_prims[q]
                row = sph_row[obj]
                cx, cy, cz, r2 = sph[row, 0], sph[row, 1], sph[row, 2], sph[row, 3]
                for r in range(m):
                    ex = pox[r] - cx
                    ey = poy[r] - cy
                    ez = poz[r] - cz
                    hb = ex * pdx[r] + ey * pdy[r] + ez * pdz[r]
                    c = ex * ex + ey * ey + ez * ez - r2
                    disc = hb * hb - c
                    sq = math.sqrt(max(disc, 0.0))
                    other = pfrm[r] != obj
                    t0 = -hb - sq
                    t1 = -hb + sq
                    tb = pt[r]
                    ok0 = other & (t0 > 0.0) & (t0 < tb)
                    ok1 = (other | (pfin[r] != 0)) & (t1 > 0.0) & (t1 < tb)
                    ok = (disc >= 0.0) & (ok0 | ok1)
                    pt[r] = (t0 if ok0 else t1) if ok else tb
                    phit[r] = obj if ok else phit[r]
            i = bvh_node[i, 2]
