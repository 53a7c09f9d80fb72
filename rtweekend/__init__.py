"""rtweekend: the Ray Tracing in One Weekend books' path tracer, Numba-compiled.

    import rtweekend as rt
    scene = rt.load_scene("cornell_box")          # a bundled name or a .toml path
    image, stats = rt.render(scene, spp=64, seed=1)
    rt.save_image(image, "cornell.png")

Scenes with phong materials and ambient/point/directional lights are rendered
by the classic ray tracer of Computer Graphics from Scratch instead.

The package by role: scene/ (descriptions and the TOML loader), path/ and
classic/ (each integrator's kernels and how a scene is frozen for them),
kernel/ (what both share), local.py and distributed/ (the drivers), io/, and
api.py, which ties them together.  docs/architecture.md walks through it.
"""
from .api import render
from .errors import OutputError, SceneError, SceneWarning
from .io.image import save_image, tonemap
from .path.renderer import Renderer
from .result import RenderResult, RenderStats
from .version import version as _version
from .scene import (SKY, Camera, ClassicCamera, Scene, ambient, box, bundled_scenes,
                    checker_texture, constant_medium, directional, image_texture, load_scene,
                    noise_texture, mesh, point, quad, solid_color, sphere, xy_rect, xz_rect,
                    yz_rect)
from .scene import materials as _materials
from .scene.materials import *  # noqa: F403  (every material's builder)

__version__ = _version()

__all__ = [
    "SceneError", "OutputError", "SceneWarning", "load_scene", "bundled_scenes",
    "save_image", "tonemap",
    "render", "Renderer", "RenderResult", "RenderStats", "Scene", "Camera", "SKY",
    "sphere", "xy_rect", "xz_rect", "yz_rect", "box", "quad", "mesh", "constant_medium",
    "solid_color", "checker_texture", "noise_texture", "image_texture",
    "ambient", "point", "directional", "ClassicCamera",
    *(name for name in _materials.__all__ if name != "Material"),
]


def __dir__():
    """The public names (and the version), not the submodules imported on the way."""
    return sorted(__all__ + ["__version__"])
