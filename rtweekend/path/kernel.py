"""The path tracer's only parallel code: one prange over image rows."""
import numba

from ..kernel.jit import jit_parallel
from .integrator import render_row


@jit_parallel
def render_pass(film, scene, params, rows, s0, s1, events, quasi, textures, media, motion):
    """Add samples s0..s1-1 of every pixel to the film; rows[k] spreads the
    work over threads (kernel/rows.py).  Each row is written by one thread
    only, and every sum is in sample order, so the film is the same whatever
    the thread count.  events, quasi: next-event estimation's and the Sobol
    points' (integrator.py); textures, media, motion: The Next Week's features
    (integrator.py).  None compiles a kernel without them."""
    for k in numba.prange(rows.shape[0]):
        render_row(rows[k], film, scene, params, s0, s1, events, quasi, textures, media,
                   motion)
