"""Scene files: TOML (stdlib tomllib) -> Scene, with one-line errors.

Every error names the file, the object and the field, e.g.
    scenes/x.toml: objects[3] (sphere 'ball'): radius: must not be 0
The format is documented in docs/scenes.md.
"""
import difflib
import inspect
import tomllib
from importlib import resources
from pathlib import Path

from . import fields
from .. import checks
from ..errors import FieldError, SceneError, label
from .camera import Camera
from .classic import LIGHTS, ClassicCamera
from .materials import MATERIALS, lambertian
from .textures import TEXTURES
from .scene import INTEGRATORS, Scene
from .shapes import SHAPES, constant_medium

TOP_KEYS = ("description", "integrator", "lights", "camera", "render", "textures",
            "materials", "objects")
PATH_CAMERA_KEYS = ("lookfrom", "lookat", "vup", "vfov", "aperture", "focus_dist")
CLASSIC_CAMERA_KEYS = ("position", "rotation", "viewport", "d")
SIZE_KEYS = ("width", "height")
RENDER_KEYS = ("spp", "max_depth", "background")
PLACEMENT_KEYS = ("rotate", "rotate_y", "translate", "flip_face")
OBJECT_KEYS = ("type", "name", "material") + PLACEMENT_KEYS
MEDIUM_KEYS = ("type", "name", "boundary", "density", "albedo")
# Fields of materials that take a colour or a texture (a table, or a name in [textures]).
TEXTURED_FIELDS = ("albedo", "emit")
# The material a medium's boundary gets while it is built (never rendered).
_BOUNDARY_MATERIAL = lambertian((0.0, 0.0, 0.0))


def bundled_dir():
    """The bundled scenes: the package rtweekend.scenes once installed; the
    top-level scenes/ folder when running from a source checkout."""
    try:
        return resources.files("rtweekend.scenes")
    except ModuleNotFoundError:
        return Path(__file__).resolve().parent.parent.parent / "scenes"


def bundled_scenes() -> dict[str, str]:
    """{name: description} of the scenes shipped with rtweekend."""
    out = {}
    for entry in sorted(bundled_dir().iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".toml"):
            doc = tomllib.loads(entry.read_text(encoding="utf-8"))
            out[entry.name[:-5]] = doc.get("description", "")
    return out


def resolve(name_or_path):
    """A bundled scene's name or a file path -> (display path, text)."""
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists() or len(path.parts) > 1:
        try:
            return str(path), path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise SceneError(f"{path}: no such scene file") from None
        except UnicodeDecodeError:
            raise SceneError(f"{path}: not a scene file: it is not text (UTF-8); scene "
                             "files are TOML (docs/scenes.md)") from None
        except OSError as e:
            raise SceneError(f"{path}: cannot read: {e.strerror or e}") from None
    entry = bundled_dir() / f"{name_or_path}.toml"
    if not entry.is_file():
        known = list(bundled_scenes())
        if Path(f"{name_or_path}.toml").is_file():
            hint = f" (did you mean the file '{name_or_path}.toml'?)"
        else:
            hint = did_you_mean(str(name_or_path), known)
        raise SceneError(f"unknown scene '{name_or_path}'{hint}: not a file and not one of "
                         f"the bundled scenes ({', '.join(known)})")
    return f"{name_or_path}.toml", entry.read_text(encoding="utf-8")


def load_scene(name_or_path: str | Path) -> Scene:
    """Load a scene file (or a bundled scene by name) into a Scene."""
    where, source = resolve(name_or_path)
    try:
        doc = tomllib.loads(source)
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{where}: TOML syntax error: {e}") from None
    path = Path(where)
    base = path.parent if path.exists() else Path(str(bundled_dir()))
    return scene_from_dict(doc, where=where, name=path.stem, base=base)


def scene_from_dict(doc, *, where="<scene>", name="scene", base=None):
    """A Scene from a parsed document (a dict shaped like the TOML file); image
    textures' relative paths are taken from `base` (default: the current folder)."""
    if not isinstance(doc, dict):
        raise SceneError(f"{where}: expected a table at the top level")
    return _Loader(where, base).scene(doc, name=name)


# The books' (and other renderers') names for our fields, for the hint.
SYNONYMS = {"samples_per_pixel": "spp", "samples": "spp", "depth": "max_depth",
            "image_width": "width", "image_height": "height", "fov": "vfov",
            "focus_distance": "focus_dist", "ref_idx": "ior", "ir": "ior",
            "eta": "ior", "color": "albedo", "radiance": "emit", "up": "vup",
            "origin": "lookfrom", "eye": "lookfrom", "target": "lookat"}


def did_you_mean(word, candidates):
    """" (did you mean 'x'?)" for the book's synonym or the closest candidate, or ""."""
    candidates = list(candidates)
    close = [SYNONYMS[word]] if SYNONYMS.get(word) in candidates else \
        difflib.get_close_matches(word, candidates, n=1)
    return f" (did you mean '{close[0]}'?)" if close else ""


def _unknown(key, allowed, where=None):
    """The message for `key` in a table that has no such field; `where`, the
    table's name, when the key may only have fallen into it (below)."""
    misplaced = _misplaced(key, where)
    if misplaced:
        return misplaced
    allowed = list(dict.fromkeys(allowed))           # each name once
    return f"unknown field '{key}'{did_you_mean(key, allowed)}; expected one of: " \
        + ", ".join(allowed)


def _table_name(where):
    """How the document spells the table `where` (render, objects[2], materials.red)."""
    if where.startswith("objects["):
        return f"the [[objects]] table {where}"
    return f"[{where}]"


def _misplaced(key, where):
    """A key of another table that fell into `where`: TOML gives every key after
    a [table] header to that table, so `lights = [...]` written below [render]
    is render.lights.  The hint says where it belongs, or ""."""
    if not where:
        return ""
    if key in TOP_KEYS:
        return (f"'{key}' is a top-level key, but it fell into {_table_name(where)}: TOML "
                f"puts every key after a [table] header into that table; write '{key}' "
                "above the first [table] header")
    camera_keys = PATH_CAMERA_KEYS + CLASSIC_CAMERA_KEYS + SIZE_KEYS
    for table, keys in (("render", RENDER_KEYS), ("camera", camera_keys)):
        if key in keys and where != table:
            return (f"'{key}' belongs in [{table}], but it fell into {_table_name(where)}; "
                    f"write it under the [{table}] header")
    return ""


def _missing(key, given):
    """"KEY: missing (required)", naming a given field that looks like a
    misspelling of it (materail for material)."""
    close = difflib.get_close_matches(key, [g for g in given if g != key], n=1, cutoff=0.75)
    return f"{key}: missing (required)" + (f"; is '{close[0]}' a misspelling of it?"
                                           if close else "")


class _Loader:
    def __init__(self, where, base=None):
        self.where = where
        self.base = base
        self.textures = {}

    def fail(self, what, message):
        prefix = f"{self.where}: {what}: " if what else f"{self.where}: "
        return SceneError(prefix + message)

    def table(self, value, what):
        if not isinstance(value, dict):
            raise self.fail(what, f"expected a table, got {type(value).__name__}")
        return value

    def check_keys(self, table, allowed, what):
        for key in table:
            if key not in allowed:
                raise self.fail(what, _unknown(key, allowed, what))

    def scene(self, doc, name):
        self.check_keys(doc, TOP_KEYS, "")
        scene = Scene(name=name)
        try:
            scene.description = fields.text(doc.get("description", ""), "description")
            if "integrator" in doc:
                scene.integrator = fields.text(doc["integrator"], "integrator")
                if scene.integrator not in INTEGRATORS:
                    raise FieldError("integrator", f"expected one of {', '.join(INTEGRATORS)}"
                                     f", got '{scene.integrator}'")
        except FieldError as e:
            raise self.fail("", str(e)) from None
        for tname, spec in self.table(doc.get("textures", {}), "textures").items():
            self.textures[tname] = self.texture(spec, f"textures.{tname}", tname)
        materials = self.materials(self.table(doc.get("materials", {}), "materials"))
        objects = doc.get("objects", [])
        if not isinstance(objects, list):
            raise self.fail("objects", "expected an array of tables ([[objects]])")
        named = {}
        for i, spec in enumerate(objects):
            shape = self.shape(spec, i, materials)
            if shape.name is not None:
                if shape.name in named:
                    raise self.fail(f"objects[{i}]",
                                    f"name: '{shape.name}' is already used by another object")
                named[shape.name] = shape
            scene.add(shape)
        self.lights(doc.get("lights", []), named, scene)
        if not scene.objects:
            raise self.fail("objects", "the scene has no objects")
        camera = self.table(doc.get("camera", {}), "camera")
        render = self.table(doc.get("render", {}), "render")
        classic = self.integrator(scene) == "classic"
        scene.camera = self.camera(camera, classic)
        classic = self.integrator(scene) == "classic"     # the camera may decide it
        self.render_defaults(render, scene, classic)
        try:
            scene.check()
        except SceneError as e:
            raise SceneError(f"{self.where}: {e}") from None
        return scene

    def integrator(self, scene):
        try:
            return scene.resolved_integrator()
        except SceneError as e:
            raise SceneError(f"{self.where}: {e}") from None

    def camera(self, table, classic):
        """The path tracer's Camera or the book's ClassicCamera, by its keys."""
        own = [k for k in table if k in CLASSIC_CAMERA_KEYS]
        other = [k for k in table if k in PATH_CAMERA_KEYS]
        if own and other:
            raise self.fail("camera", f"'{own[0]}' belongs to the classic camera and "
                            f"'{other[0]}' to the path tracer's; use one of them")
        classic = bool(own) or (classic and not other)
        keys = CLASSIC_CAMERA_KEYS + SIZE_KEYS if classic else PATH_CAMERA_KEYS + SIZE_KEYS
        self.check_keys(table, keys, "camera")
        try:
            return ClassicCamera(**table) if classic else Camera(**table)
        except SceneError as e:
            raise SceneError(f"{self.where}: {e}") from None

    def render_defaults(self, table, scene, classic):
        if classic and "spp" in table:
            raise self.fail("render", "spp: does not apply to the classic ray tracer "
                            "(one ray per pixel)")
        self.check_keys(table, RENDER_KEYS[1:] if classic else RENDER_KEYS, "render")
        try:
            if "spp" in table:
                scene.spp = checks.option("spp", table["spp"])
            if "max_depth" in table:
                scene.max_depth = checks.option("max_depth", table["max_depth"],
                                                integrator="classic" if classic else "path")
            if "background" in table:
                scene.background = table["background"]
                if classic:
                    fields.color(scene.background, "background", hi=255.0)
                else:
                    fields.background(scene.background)
        except FieldError as e:
            raise self.fail("render", str(e)) from None

    def check_type(self, kind, what, kinds, noun):
        """A table's `type` must be one of `kinds` (noun: "a material", ...)."""
        if not isinstance(kind, str) or kind not in kinds:
            hint = f"{kind!r} is not {noun} type" if kind is not None else "missing"
            raise self.fail(what, f"type: {hint}; expected one of: {', '.join(kinds)}")

    def material(self, spec, what, name=None):
        spec = self.table(spec, what)
        kind = spec.get("type")
        self.check_type(kind, what, MATERIALS, "a material")
        what = f"{what} ({kind})"
        args = {k: self.colour_or_texture(v, what, k) if k in TEXTURED_FIELDS else v
                for k, v in spec.items() if k != "type"}
        return self.call(MATERIALS[kind], args, ("type",), what, name=name)

    def colour_or_texture(self, value, what, field):
        """A colour field's value: a table is a texture, a string names one."""
        if isinstance(value, dict):
            return self.texture(value, f"{what} {field}")
        if isinstance(value, str):
            if value not in self.textures:
                known = (f"; the textures are: {', '.join(self.textures)}" if self.textures
                         else " (the scene has no [textures])")
                raise self.fail(what, f"{field}: expected 3 numbers [r, g, b] or a texture, "
                                f"got '{value}': no texture named '{value}'"
                                + did_you_mean(value, self.textures) + known)
            return self.textures[value]
        return value

    def texture(self, spec, what, name=None):
        """A texture table: type = solid_color, checker_texture, noise_texture or
        image_texture; a checker's even and odd are colours or textures too."""
        spec = self.table(spec, what)
        kind = spec.get("type")
        self.check_type(kind, what, TEXTURES, "a texture")
        what = f"{what} ({kind})"
        args = {k: v for k, v in spec.items() if k != "type"}
        for k in ("even", "odd"):
            if kind == "checker_texture" and k in args:
                args[k] = self.colour_or_texture(args[k], what, k)
        if kind == "image_texture":       # a relative file is the scene file's neighbour
            self.check_signature(TEXTURES[kind].raw, args, ("type",), what)
            try:
                return TEXTURES[kind].raw(**args, name=name, base=self.base)
            except FieldError as e:
                raise self.fail(what, str(e)) from None
        return self.call(TEXTURES[kind], args, ("type",), what, name=name)

    def materials(self, table):
        out = {}
        for name, spec in table.items():
            out[name] = self.material(spec, f"materials.{name}", name)
        return out

    def check_signature(self, fn, args, extra_keys, what):
        """The table's fields against fn's parameters: none unknown, none missing
        (`name` is the object's own and never a field of fn)."""
        params = [p for p in inspect.signature(fn).parameters.values()
                  if p.kind is not inspect.Parameter.VAR_KEYWORD
                  and p.name not in ("name", "base")]
        allowed = [p.name for p in params]
        for key in args:
            if key not in allowed:
                raise self.fail(what, _unknown(key, list(extra_keys) + allowed, what))
        for p in params:
            if p.default is inspect.Parameter.empty and p.name not in args:
                raise self.fail(what, _missing(p.name, args))

    def call(self, builder, args, extra_keys, what, name=None):
        """Call builder.raw with the table's fields, checking names first."""
        self.check_signature(builder.raw, args, extra_keys, what)
        # A builder that reads a file (a mesh) takes it relative to the scene file.
        if "base" in inspect.signature(builder.raw).parameters:
            args = {**args, "base": self.base}
        try:
            return builder.raw(**args, name=name)
        except FieldError as e:
            raise self.fail(what, str(e)) from None

    def shape(self, spec, i, materials, what=None):
        what = what or f"objects[{i}]"
        spec = self.table(spec, what)
        kind = spec.get("type")
        name = spec.get("name")
        if name is not None and not isinstance(name, str):
            raise self.fail(what, f"name: expected a string, got {name!r}")
        if kind == "constant_medium":
            return self.medium(spec, f"{what} ({label(kind, name)})", name)
        self.check_type(kind, what, [*SHAPES, "constant_medium"], "an object")
        what = f"{what} ({label(kind, name)})"
        if "material" not in spec:
            raise self.fail(what, _missing("material", spec))
        mat = spec["material"]
        if mat is _BOUNDARY_MATERIAL:
            pass
        elif isinstance(mat, str):
            if mat not in materials:
                raise self.fail(what, f"material: no material named '{mat}'"
                                + did_you_mean(mat, materials))
            mat = materials[mat]
        else:
            mat = self.material(mat, f"{what} material")
        args = {k: v for k, v in spec.items() if k not in OBJECT_KEYS}
        shape = self.call(SHAPES[kind], {**args, "material": mat}, OBJECT_KEYS, what,
                          name=name)
        try:
            if "rotate" in spec and "rotate_y" in spec:
                raise FieldError("rotate_y", "give rotate = [rx, ry, rz] or rotate_y, not "
                                 "both (rotate_y = a is rotate = [0, a, 0])")
            if "rotate" in spec:
                shape = shape.rotate(fields.angles(spec["rotate"], "rotate"))
            if "rotate_y" in spec:
                shape = shape.rotate_y(fields.number(spec["rotate_y"], "rotate_y"))
            if "translate" in spec:
                shape = shape.translate(fields.vec3(spec["translate"], "translate"))
            if fields.boolean(spec.get("flip_face", False), "flip_face"):
                shape = shape.flip_face()
        except FieldError as e:
            raise self.fail(what, str(e)) from None
        return shape

    def medium(self, spec, what, name):
        """A constant_medium: a boundary table (a sphere or a box with its
        placement, no material needed), density and albedo."""
        self.check_keys(spec, MEDIUM_KEYS, what)
        for key in ("boundary", "density", "albedo"):
            if key not in spec:
                raise self.fail(what, _missing(key, spec))
        boundary = dict(self.table(spec["boundary"], f"{what} boundary"))
        if "material" in boundary:
            raise self.fail(f"{what} boundary", "material: a medium's boundary is invisible "
                            "and has no material (give the medium's albedo instead)")
        if "name" in boundary:
            raise self.fail(f"{what} boundary", "name: name the constant_medium instead")
        boundary["material"] = _BOUNDARY_MATERIAL
        shape = self.shape(boundary, 0, {}, what=f"{what} boundary")
        albedo = self.colour_or_texture(spec["albedo"], what, "albedo")
        try:
            return constant_medium.raw(shape, spec["density"], albedo, name=name)
        except FieldError as e:
            raise self.fail(what, str(e)) from None

    def lights(self, entries, named, scene):
        """Names of shapes (the path tracer's light pdf) or tables of classic lights."""
        if not isinstance(entries, list):
            raise self.fail("lights", "expected an array of object names, or of "
                            "[[lights]] tables (ambient, point, directional)")
        for j, entry in enumerate(entries):
            if isinstance(entry, dict):
                scene.add_light(self.classic_light(entry, f"lights[{j}]"))
                continue
            if not isinstance(entry, str):
                raise self.fail(f"lights[{j}]", f"expected an object name or a table, "
                                f"got {entry!r}")
            if entry not in named:
                raise self.fail(f"lights[{j}]", f"no object named '{entry}'"
                                + did_you_mean(entry, named))
            scene.add_light(named[entry])

    def classic_light(self, spec, what):
        kind = spec.get("type")
        self.check_type(kind, what, LIGHTS, "a light")
        args = {k: v for k, v in spec.items() if k != "type"}
        self.check_signature(LIGHTS[kind], args, ("type",), f"{what} ({kind})")
        try:
            return LIGHTS[kind](**args)
        except SceneError as e:
            raise self.fail(what, str(e)) from None
