"""A sampling strategy: the estimator that renders, and how it is fed.

Each estimator module declares its named strategies (STRATEGIES); the
package gathers them (integrators.SAMPLINGS), which `--sampling` and the API
take.
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class Sampling:
    """A sampling strategy of the path tracer: which estimator, fed how.

    light_weight: the share of the lights list in the mixture pdf that draws the
    next direction at a diffuse hit (path/pdf.py): 0 cosine, 0.5 the books' mixture.
    next_event: also sample a point on one emitter at each diffuse hit and trace a
    shadow ray to it, the two strategies weighted by the power heuristic (MIS);
    the mixture then draws towards the lights list's objects that do not emit
    (attractors such as a glass ball), and paths end by Russian roulette from
    depth `roulette_depth` on (max_depth still caps them).
    sobol_pairs: how many of a sample's 2-D points, in the order its estimator
    asks for them, are Owen-scrambled Sobol pairs (kernel/sobol.py) instead of
    numbers of the independent stream (which still gives every other number):
    0 none; the +sobol strategies cover the position in the pixel and the
    first bounce's decisions (its module says which).
    facing: at a point behind every light of the lights list (one-sided rect
    lights seen from their back: no light reaches it from them), the mixture
    draws from the cosine alone instead of sending samples to them (the books
    do); pack.dark_sides.  Only with sobol (the kernel tests it there).
    estimator: which kernel renders (path/integrators/): the path tracer, or
    light tracing (paths from the emitters connected to the camera; the other
    fields do not apply to it).
    """
    light_weight: float
    next_event: bool = False
    roulette_depth: int = 0      # 0: no Russian roulette
    sobol_pairs: int = 0
    facing: bool = False
    estimator: str = "path"      # its module's key in integrators.ESTIMATORS
    photons: bool = False        # bdpt: caustic photon maps (integrators/photons.py)
    manifold: bool = False       # path, bdpt: connections through smooth glass (mnee.py)
