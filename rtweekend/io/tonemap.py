"""The books' tone map: linear radiance to 8-bit colours (image.py writes
them; a RenderResult shows itself with them in a notebook)."""
from typing import Protocol

import numpy as np


class HasImage(Protocol):
    """What render() returns, as the tone map reads it: its .image."""
    image: np.ndarray


def tonemap(image: np.ndarray | HasImage, exposure: float = 1.0) -> np.ndarray:
    """HxWx3 linear radiance (or what render() returned: its .image) -> HxWx3
    uint8, as the PNG writer does: the books' write_color, gamma 2 (sqrt), clamp
    to [0, 0.999], x256; `exposure` multiplies the radiance first (2: one stop
    brighter).

    NaN becomes 0 (a render never produces one: bad samples are dropped).
    """
    image = np.asarray(getattr(image, "image", image), dtype=np.float64)
    if exposure != 1.0:
        image = image * float(exposure)
    c = np.sqrt(np.nan_to_num(np.maximum(image, 0.0), nan=0.0, posinf=1.0))
    return (256.0 * np.clip(c, 0.0, 0.999)).astype(np.uint8)
