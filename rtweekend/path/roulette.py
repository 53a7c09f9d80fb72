"""Russian roulette: a path whose throughput has fallen goes on with
probability q and, if it does, carries 1/q more -- unbiased, and dim paths end
early."""
from ..kernel import sampler
from ..kernel.jit import jit_step


@jit_step
def roulette(beta, scale, smp):
    """(survives, throughput, smp): q = the largest channel of beta / scale (at
    most 1); scale is what beta started at (1 for a camera path)."""
    q = min(1.0, max(beta[0], beta[1], beta[2]) / scale)
    u, smp = sampler.uniform(smp)
    return u < q, (beta[0] / q, beta[1] / q, beta[2] / q), smp
