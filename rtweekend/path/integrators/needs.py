"""What an estimator needs of the driver beyond its kernel, declared by it.

Each estimator module (path.py, light.py, bdpt.py) has NEEDS, a Needs; the
renderer (path/renderer.py) asks it and names no estimator.  A field left out
is what an estimator needing nothing more would say.

    splats        its film has the splat arrays (film.py): it carries light to
                  pixels other than its sample's
    feature_images  its paths start at the camera, so it can give what they first
                  see (film.py: the albedo, normal and emission images)
    check(sampling, arrays)        SceneError (naming the option) if it cannot
                  render the packed scene
    lights(strategy, arrays)       the lights list its mixture draws towards
                  (strategies whose shadow rays reach the emitters keep the
                  other objects of the list only: attractors, e.g. a glass ball)
    features(strategy, scene, arrays)  {Features field: value} it compiles with
    runs_as(strategy, scene)       None, or (sampling, why) when it renders the
                  scene as another strategy does, bit for bit (the summary says so)
    extra_bytes(strategy)          memory it holds beside the film and the scene
    kernels(frame)                 [(kernel, arguments)] it calls beside its
                  render_pass (compiled with it, side by side)
    block(frame, features, s0, s1, threads)   the features for samples s0 .. s1 - 1
                  of one block of samples (what it prepares per block)
"""
from typing import Callable, NamedTuple

import numpy as np

from .. import lights


def _nothing_to_check(sampling, arrays):
    pass


def _lights_as_listed(strategy, arrays):
    return arrays


def _no_features(strategy, scene, arrays):
    return {}


def _as_named(strategy, scene):
    return None


def _no_bytes(strategy):
    return 0


def _no_kernels(frame):
    return []


def _same_features(frame, features, s0, s1, threads):
    return features


class Needs(NamedTuple):
    splats: bool
    feature_images: bool = True
    check: Callable = _nothing_to_check
    lights: Callable = _lights_as_listed
    features: Callable = _no_features
    runs_as: Callable = _as_named
    extra_bytes: Callable = _no_bytes
    kernels: Callable = _no_kernels
    block: Callable = _same_features


def emitters_left_out(arrays):
    """The packed scene with the emitters left out of its lights list: for a
    strategy whose shadow rays (or photons) reach the emitters, the mixture
    draws towards the list's other objects only (attractors, e.g. a glass ball)."""
    return lights.relisted(arrays, np.setdiff1d(lights.listed(arrays), lights.emitters(arrays)))
