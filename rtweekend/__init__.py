"""rtweekend: the Ray Tracing in One Weekend books' path tracer, Numba-compiled.

    import rtweekend as rt
    scene = rt.load_scene("cornell_box")          # a bundled name or a .toml path
    image, stats = rt.render(scene, spp=64, seed=1)
    rt.save_image(image, "cornell.png")

Scenes with phong materials and ambient/point/directional lights are rendered
by the classic ray tracer of Computer Graphics from Scratch instead.
"""
from .errors import SceneError
from .classic_scene import ClassicCamera, ambient, directional, point
from .image import save_image
from .render import Renderer, render
from .result import RenderResult, RenderStats
from .scene import SKY, Camera, Scene
from .scenefile import bundled_scenes, load_scene
from .shapes import (box, dielectric, diffuse_light, lambertian, metal, phong, sphere,
                     xy_rect, xz_rect, yz_rect)

__all__ = [
    "SceneError", "load_scene", "bundled_scenes", "save_image",
    "render", "Renderer", "RenderResult", "RenderStats", "Scene", "Camera", "SKY",
    "lambertian", "metal", "dielectric", "diffuse_light",
    "sphere", "xy_rect", "xz_rect", "yz_rect", "box",
    "phong", "ambient", "point", "directional", "ClassicCamera",
]
