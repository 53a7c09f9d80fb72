"""The cosine and sine of an angle given in turns, without a call to libm.

A cosine-weighted bounce turns a uniform number u into the angle 2 pi u;
libm's sincos there was about a tenth of bidirectional path tracing's time
(a call, and its range reduction for any argument).  For u in [0, 1) the
reduction is exact and short: k = round(4u) quarter turns, and the rest,
x = 2 pi (u - k / 4) in [-pi/4, pi/4] (u - k / 4 is exact: Sterbenz), goes
to Cephes' minimax polynomials for sin and cos on that interval (relative
error about 1e-16); the quarter turns then swap and negate the pair.
"""
import math

from .jit import jit_step

TWO_PI = 2.0 * math.pi
# Cephes sin.c / cos.c: sin x = x + x^3 S(x^2), cos x = 1 - x^2 / 2 + x^4 C(x^2).
S0, S1, S2 = 1.58962301576546568060e-10, -2.50507477628578072866e-8, 2.75573136213857245213e-6
S3, S4, S5 = -1.98412698295895385996e-4, 8.33333333332211858878e-3, -1.66666666666666307295e-1
C0, C1, C2 = -1.13585365213876817300e-11, 2.08757008419747316778e-9, -2.75573141792967388112e-7
C3, C4, C5 = 2.48015872888517045348e-5, -1.38888888888730564116e-3, 4.16666666666665929218e-2


@jit_step
def cos_sin_turns(u):
    """(cos 2 pi u, sin 2 pi u) for u in [0, 1)."""
    k = math.floor(4.0 * u + 0.5)
    x = TWO_PI * (u - 0.25 * k)
    z = x * x
    s = x + x * z * (((((S0 * z + S1) * z + S2) * z + S3) * z + S4) * z + S5)
    c = 1.0 - 0.5 * z + z * z * (((((C0 * z + C1) * z + C2) * z + C3) * z + C4) * z + C5)
    quarter = int(k) & 3
    if quarter == 0:
        return c, s
    if quarter == 1:
        return -s, c
    if quarter == 2:
        return -c, -s
    return s, -c
