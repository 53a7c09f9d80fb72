"""The estimators, side by side: each a module with its own kernel over image
rows, over the same scene arrays, materials, lights, sampler, camera and film.

    render_pass(film, scene, params, queue, s0, s1, events, textures, media, motion,
                caustics, manifold)

adds samples s0..s1-1 of the pixels of the rows it claims from the queue
(kernel/rows.py: each of a pass's threads calls it with the same queue) to the
film, and NEEDS (needs.py) says what else it needs of the driver, which names
no estimator: whether its film needs the splat arrays (film.py: path.py adds
each sample to its own pixel; light.py and bdpt.py carry light to whatever
pixel it reaches), its checks, lights list, features, memory, the kernels
beside it and what it prepares per block of samples (bdpt's photon maps).  The
Frame names the estimator (path/renderer.py) and carries the feature record
(layout.Features), unpacked into the kernel's arguments in one place,
renderer.render_samples, because Numba prunes `is None` tests only on
arguments.
"""
from ..materials import DELTA, EMITS, GLOSSY, kind_has
from . import bdpt, light, path, photons, through_glass
from .sampling import Sampling  # noqa: F401  (options.py's)

ESTIMATORS = {"path": path, "light": light, "bdpt": bdpt}
# Every named strategy, as each estimator declares them (`--sampling`).
SAMPLINGS = {**path.STRATEGIES, **light.STRATEGIES, **bdpt.STRATEGIES}


def needs_of(strategy):
    """What the estimator of a Sampling needs of the driver (needs.py)."""
    return ESTIMATORS[strategy.estimator].NEEDS


# The default: the strategy with the lowest error at equal time, by what the
# scene holds (benchmarks/strategies.py and accuracy.py; docs/accuracy.md).
# Where emitters light metal or glass, smooth or rough (delta and glossy
# materials: path/materials/flags.py), that is a noticeable part of the scene
# (SPECULAR_SHARE of its surface area or more), bidirectional path tracing finds
# the caustics and the light through glass or off mirrors that camera paths find
# only by chance, and its caustic photon maps the caustics seen through smooth
# glass where the lights list names what to aim them at, its manifold
# connections the light of an emitter that smooth glass encloses (a lamp in a
# glass globe: through_glass.encloses_an_emitter); elsewhere it pays for
# connections that find little new (benchmarks/strategies.py and accuracy.py;
# the figures: benchmarks/results/measurements.md).  "mixture" is the books'.
DEFAULT_SAMPLING = "mixture+sobol"
SPECULAR_DEFAULT = "bdpt+sobol"
PHOTONS_DEFAULT = "bdpt+photons"
GLASS_DEFAULT = "bdpt+mnee"
SPECULAR_SHARE = 0.02


def default_sampling(scene):
    """The sampling a path-traced scene gets when none is asked for:
    bidirectional (SPECULAR_DEFAULT; PHOTONS_DEFAULT where its caustic maps
    serve: path/integrators/photons.serve; GLASS_DEFAULT where smooth glass
    encloses an emitter: through_glass.py) when it has an emitter and metal or
    glass, smooth or rough, make up at least SPECULAR_SHARE of its surfaces'
    area, else DEFAULT_SAMPLING."""
    surfaces = [shape for shape in scene.objects if not shape.medium]
    if not any(kind_has(shape.material.kind, EMITS) for shape in surfaces):
        return DEFAULT_SAMPLING
    total = sum(shape.area for shape in surfaces)
    specular = sum(shape.area for shape in surfaces
                   if kind_has(shape.material.kind, DELTA | GLOSSY))
    if specular < SPECULAR_SHARE * total:
        return DEFAULT_SAMPLING
    if photons.serve(scene):
        return PHOTONS_DEFAULT
    if through_glass.encloses_an_emitter(scene) and through_glass.skipped(scene) is None:
        return GLASS_DEFAULT
    return SPECULAR_DEFAULT

