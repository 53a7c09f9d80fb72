"""The description layer: scenes as plain Python values, validated, and the TOML
loader.  Nothing here imports a kernel: each integrator freezes a Scene into
the arrays its kernels read."""
from .camera import Camera
from .classic import ClassicCamera, ClassicLight, ambient, directional, point
from .fields import SKY
from .loader import bundled_scenes, load_scene, scene_from_dict
from . import materials as _materials
from .materials import *  # noqa: F403  (Material and every material's builder)
from .scene import Scene
from .shapes import Shape, box, constant_medium, mesh, quad, sphere, xy_rect, xz_rect, yz_rect
from .textures import Texture, checker_texture, image_texture, noise_texture, solid_color

__all__ = ["Camera", "ClassicCamera", "ClassicLight", "SKY", "Scene", "Shape",
           "ambient", "box", "bundled_scenes", "directional",
           "load_scene", "point", "scene_from_dict",
           "sphere", "xy_rect", "xz_rect", "yz_rect", "quad", "mesh", "constant_medium",
           "Texture", "solid_color", "checker_texture", "noise_texture", "image_texture",
           *_materials.__all__]
