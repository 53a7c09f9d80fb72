"""What lights a scene: its emitters and the background.

A ray that escapes the scene takes the background's radiance: a constant, or
book 1's sky gradient (SceneArrays.bg_kind).
"""
from ..kernel.jit import jit_step
from .layout import BG_SKY


@jit_step
def background(scene, d):
    """Radiance of a ray that escapes along the unit direction d."""
    if scene.bg_kind == BG_SKY:
        a = 0.5 * (d[1] + 1.0)
        return (1.0 - 0.5 * a, 1.0 - 0.3 * a, 1.0)
    bg = scene.bg
    return (bg[0], bg[1], bg[2])
