"""The books' diffuse_light: emits its colour (the radiance) from its front
side, scatters nothing (materials.emitted)."""
from .flags import EMITS

FLAGS = EMITS


def params(material):
    """No parameters: its colour is the emitted radiance."""
    return ()
