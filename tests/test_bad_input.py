"""Bad input: one line naming the file, object and field; exit 2; no file.

The command is run in-process here (rtweekend.cli.main) to keep the many cases
fast; tests/test_cli.py runs it as a subprocess for the end-to-end view.
"""
import textwrap

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rtweekend as rt
from rtweekend.cli import main
from rtweekend.path.pack import pack_scene
from rtweekend.scene.loader import scene_from_dict

GOOD = textwrap.dedent("""\
    description = "a test scene"
    lights = ["lamp"]

    [camera]
    lookfrom = [0, 0, 5]
    lookat = [0, 0, 0]
    width = 8
    height = 8

    [render]
    spp = 2
    max_depth = 5

    [materials]
    white = { type = "lambertian", albedo = [0.7, 0.7, 0.7] }
    glow = { type = "diffuse_light", emit = [4, 4, 4] }

    [[objects]]
    name = "ball"
    type = "sphere"
    center = [0, 0, 0]
    radius = 1
    material = "white"

    [[objects]]
    name = "lamp"
    type = "xz_rect"
    x0 = -1
    x1 = 1
    z0 = -1
    z1 = 1
    k = 3
    material = "glow"
    flip_face = true

    [[objects]]
    name = "crate"
    type = "box"
    p0 = [2, 0, 0]
    p1 = [3, 1, 1]
    material = "white"
    """)


def run_cli(tmp_path, capsys, *args):
    """(exit status, stderr lines) of `rtweekend ...` with the cwd at tmp_path."""
    try:
        status = main(list(args))
    except SystemExit as e:          # argparse's own errors
        status = e.code
    err = capsys.readouterr().err.strip().splitlines()
    return status, err


@pytest.fixture
def scene_file(tmp_path):
    def write(text):
        path = tmp_path / "bad.toml"
        path.write_text(text)
        return path
    return write


def test_the_good_scene_renders(tmp_path, capsys, scene_file):
    out = tmp_path / "ok.png"
    status, err = run_cli(tmp_path, capsys, "render", str(scene_file(GOOD)), "-o", str(out),
                          "-q")
    assert status == 0 and out.exists()


def _edit(old, new, count=1):
    assert old in GOOD, old
    return GOOD.replace(old, new, count)


BAD_SCENES = [
    # (scene text, words the one line must contain)
    ("lookfrom = [0, 0, 5\n", ["TOML syntax error", "line"]),
    (_edit('radius = 1', 'raduis = 1'), ["objects[0] (sphere 'ball')", "raduis",
                                           "did you mean 'radius'"]),
    (_edit('[render]', '[render]\nsamples = 4'), ["render", "samples", "did you mean 'spp'"]),
    (_edit('lookat = [0, 0, 0]', 'look_at = [0, 0, 0]'), ["camera", "look_at",
                                                           "did you mean 'lookat'"]),
    (_edit('description', 'descripton'), ["descripton", "did you mean 'description'"]),
    (_edit('albedo = [0.7, 0.7, 0.7] }', 'albdo = [0.7, 0.7, 0.7] }'),
     ["materials.white (lambertian)", "albdo", "did you mean 'albedo'"]),
    (_edit('radius = 1\n', ''), ["objects[0] (sphere 'ball')", "radius: missing"]),
    (_edit('material = "white"\n', ''), ["objects[0] (sphere 'ball')", "material: missing"]),
    (_edit('type = "sphere"\n', ''), ["objects[0]", "type: missing"]),
    (_edit('type = "sphere"', 'type = "cube"'), ["objects[0]", "'cube' is not an object type"]),
    (_edit('{ type = "lambertian", ', '{ '), ["materials.white", "type: missing"]),
    (_edit('radius = 1', 'radius = "big"'), ["sphere 'ball'", "radius: expected a number"]),
    (_edit('center = [0, 0, 0]', 'center = [0, 0]'), ["sphere 'ball'", "center: expected 3"]),
    (_edit('p1 = [3, 1, 1]', 'p1 = [3, 1, 1]\nrotate = [0, 90]'),
     ["objects[2] (box 'crate')", "rotate: expected 3 angles in degrees [rx, ry, rz]"]),
    (_edit('p1 = [3, 1, 1]', 'p1 = [3, 1, 1]\nrotate = "up"'),
     ["objects[2] (box 'crate')", "rotate: expected 3 angles"]),
    (_edit('p1 = [3, 1, 1]', 'p1 = [3, 1, 1]\nrotate = [nan, 0, 0]'),
     ["objects[2] (box 'crate')", "rotate: must be finite"]),
    (_edit('p1 = [3, 1, 1]', 'p1 = [3, 1, 1]\nrotate = [0, 30, 0]\nrotate_y = 30'),
     ["objects[2] (box 'crate')", "rotate_y: give rotate = [rx, ry, rz] or rotate_y, not both"]),
    (_edit('[0.7, 0.7, 0.7]', '"grey"'), ["materials.white", "albedo: expected 3"]),
    (_edit('flip_face = true', 'flip_face = 1'), ["xz_rect 'lamp'", "flip_face: expected true"]),
    (_edit('width = 8', 'width = 8.5'), ["camera", "width: expected an integer"]),
    (_edit('spp = 2', 'spp = "2"'), ["render", "spp: expected an integer"]),
    (_edit('lights = ["lamp"]', 'lights = "lamp"'), ["lights", "expected an array"]),
    (_edit('[0.7, 0.7, 0.7]', '[0.7, -0.1, 0.7]'), ["materials.white", "albedo",
                                                     "must be >= 0"]),
    (_edit('[0.7, 0.7, 0.7]', '[0.7, 1.5, 0.7]'), ["materials.white", "albedo",
                                                    "must be <= 1"]),
    (_edit('emit = [4, 4, 4]', 'emit = [4, -4, 4]'), ["materials.glow (diffuse_light)", "emit",
                                                      "must be >= 0"]),
    (_edit('white = {', 'glass = { type = "dielectric", ior = 0 }\nwhite = {'),
     ["materials.glass (dielectric)", "ior: must be > 0"]),
    (_edit('white = {', 'm = { type = "metal", albedo = [1, 1, 1], fuzz = -0.1 }\nwhite = {'),
     ["materials.m (metal)", "fuzz: must be >= 0"]),
    (_edit('white = {', 'm = { type = "rough_conductor", albedo = [1, 1, 1], alpha = 0 }\n'
                        'white = {'),
     ["materials.m (rough_conductor)", "alpha: must be > 0"]),
    (_edit('white = {', 'm = { type = "rough_conductor", albedo = [1, 1, 1], alpha = 1.5 }\n'
                        'white = {'),
     ["materials.m (rough_conductor)", "alpha: must be <= 1"]),
    (_edit('white = {', 'm = { type = "rough_conductor", albedo = [1, 1, 1] }\nwhite = {'),
     ["materials.m (rough_conductor)", "alpha"]),
    (_edit('width = 8', 'width = 0'), ["camera", "width: must be >= 1"]),
    (_edit('height = 8', 'height = -3'), ["camera", "height: must be >= 1"]),
    (_edit('spp = 2', 'spp = 0'), ["render", "spp: must be >= 1"]),
    (_edit('max_depth = 5', 'max_depth = 0'), ["render", "max_depth: must be >= 1"]),
    (_edit('material = "white"', 'material = "whte"'), ["sphere 'ball'",
                                                        "no material named 'whte'",
                                                        "did you mean 'white'"]),
    (_edit('lights = ["lamp"]', 'lights = ["lmap"]'), ["lights[0]", "no object named 'lmap'",
                                                       "did you mean 'lamp'"]),
    (_edit('name = "lamp"', 'name = "ball"'), ["objects[1]", "'ball' is already used"]),
    (_edit('max_depth = 5', 'max_depth = 5\nbackground = "skyy"'),
     ["render", "background", '"sky"']),
    (_edit('lookat = [0, 0, 0]', 'lookat = [0, 0, 5]'), ["camera", "lookat: equals lookfrom"]),
    (_edit('[camera]', '[camera]\nvfov = 180'), ["camera", "vfov: must be < 180"]),
    (_edit('radius = 1', 'radius = 0'), ["sphere 'ball'", "radius: must not be 0"]),
    (_edit('x1 = 1', 'x1 = -1'), ["xz_rect 'lamp'", "x1: must be greater than x0"]),
    (_edit('p1 = [3, 1, 1]', 'p1 = [2, 0, 0]'), ["box 'crate'", "p1:", "no volume"]),
    # The Next Week: textures, media, motion, quads.
    (_edit('[0.7, 0.7, 0.7]', '{ type = "checker_texture", even = [1, 1, 1] }'),
     ["materials.white (lambertian) albedo (checker_texture)", "odd: missing"]),
    (_edit('[0.7, 0.7, 0.7]', '{ type = "noise_texture", style = "wood" }'),
     ["materials.white (lambertian) albedo (noise_texture)", "style: expected one of",
      "'wood'"]),
    (_edit('[0.7, 0.7, 0.7]', '{ type = "noise_texture", scale = -1 }'),
     ["albedo (noise_texture)", "scale: must be > 0"]),
    (_edit('[0.7, 0.7, 0.7]', '{ type = "image_texture", file = "nope.png" }'),
     ["albedo (image_texture)", "file: no such image", "nope.png"]),
    (_edit('[0.7, 0.7, 0.7]', '{ type = "plaid" }'),
     ["materials.white (lambertian) albedo", "'plaid' is not a texture type",
      "checker_texture"]),
    (_edit('[0.7, 0.7, 0.7]', '{ type = "checker_texture", even = [1, 1, 1], '
           'odd = [2, 0, 0] }'), ["materials.white", "albedo", "must be <= 1"]),
    (_edit('[materials]', '[textures]\nmarble = { type = "noise_texture" }\n\n[materials]')
     .replace('[0.7, 0.7, 0.7]', '"marbel"'),
     ["materials.white (lambertian)", "no texture named 'marbel'", "did you mean 'marble'"]),
    (_edit('radius = 1', 'radius = 1\ncenter1 = [0, "up", 0]'),
     ["sphere 'ball'", "center1: expected a number"]),
    (_edit('type = "box"', 'type = "quad"\nQ = [0, 0, 0]\nu = [1, 0, 0]\nv = [2, 0, 0]')
     .replace('p0 = [2, 0, 0]\np1 = [3, 1, 1]\n', ''),
     ["objects[2] (quad 'crate')", "v:", "parallel to u"]),
    (_edit('type = "box"\np0 = [2, 0, 0]\np1 = [3, 1, 1]\nmaterial = "white"',
           'type = "constant_medium"\ndensity = -1\nalbedo = [1, 1, 1]\n'
           'boundary = { type = "box", p0 = [2, 0, 0], p1 = [3, 1, 1] }'),
     ["objects[2] (constant_medium 'crate')", "density: must be >= 0"]),
    (_edit('type = "box"\np0 = [2, 0, 0]\np1 = [3, 1, 1]\nmaterial = "white"',
           'type = "constant_medium"\ndensity = 1\nalbedo = [1, 1, 1]\n'
           'boundary = { type = "xy_rect", x0 = 0, x1 = 1, y0 = 0, y1 = 1, k = 0 }'),
     ["objects[2] (constant_medium 'crate')", "boundary: must be a sphere or a box"]),
    (_edit('type = "box"\np0 = [2, 0, 0]\np1 = [3, 1, 1]\nmaterial = "white"',
           'type = "constant_medium"\ndensity = 1\nalbedo = [1, 1, 1]\n'
           'boundary = { type = "box", p0 = [2, 0, 0], p1 = [3, 1, 1], material = "white" }'),
     ["objects[2] (constant_medium 'crate') boundary", "material: a medium's boundary is "
      "invisible"]),
    (_edit('type = "box"\np0 = [2, 0, 0]\np1 = [3, 1, 1]\nmaterial = "white"',
           'type = "constant_medium"\ndensity = 1\nalbedo = [1, 1, 1]\n'
           'boundary = { type = "box", p0 = [2, 0, 0], p1 = [2, 1, 1] }'),
     ["objects[2] (constant_medium 'crate') boundary (box)", "p1:", "no volume"]),
    (_edit('type = "box"\np0 = [2, 0, 0]\np1 = [3, 1, 1]\nmaterial = "white"',
           'type = "constant_medium"\nalbedo = [1, 1, 1]\n'
           'boundary = { type = "box", p0 = [2, 0, 0], p1 = [3, 1, 1] }'),
     ["objects[2] (constant_medium 'crate')", "density: missing"]),
    (_edit('lights = ["lamp"]', 'lights = ["lamp", "crate"]')
     .replace('type = "box"\np0 = [2, 0, 0]\np1 = [3, 1, 1]\nmaterial = "white"',
              'type = "constant_medium"\ndensity = 1\nalbedo = [1, 1, 1]\n'
              'boundary = { type = "box", p0 = [2, 0, 0], p1 = [3, 1, 1] }'),
     ["lights: constant_medium 'crate' is a medium"]),
]


@pytest.mark.parametrize("text, words", BAD_SCENES,
                         ids=[w[-1][:30] for _, w in BAD_SCENES])
def test_bad_scene_file(tmp_path, capsys, scene_file, text, words):
    path = scene_file(text)
    out = tmp_path / "out.png"
    out.write_bytes(b"keep me")
    status, err = run_cli(tmp_path, capsys, "render", str(path), "-o", str(out), "-q")
    assert status == 2
    assert len(err) == 1, err
    line = err[0]
    assert line.startswith(f"rtweekend: error: {path}: ")
    for w in words:
        assert w in line, (w, line)
    assert out.read_bytes() == b"keep me"          # neither replaced nor truncated
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml", "out.png"]
    # The API raises SceneError (a ValueError) with the same message.
    with pytest.raises(rt.SceneError) as info:
        rt.load_scene(path)
    assert isinstance(info.value, ValueError)
    assert line == f"rtweekend: error: {info.value}"


BAD_COMMANDS = [
    (["render", "no_such_scene"], ["unknown scene 'no_such_scene'", "cornell_glass", "metals"]),
    (["render", "metals", "-o", "/sys/rtweekend.png"], ["/sys/rtweekend.png",
                                                        "cannot write"]),
    (["render", "metals", "-o", "missing/x.png"], ["missing/x.png", "does not exist"]),
    (["render", "metals", "-o", "x.gif2"], ["x.gif2", "unknown output extension"]),
    (["render", "metals", "--spp", "4", "--time", "2"], ["--time", "not allowed with",
                                                         "--spp"]),
    (["render", "metals", "--spp", "-1"], ["--spp", "must be >= 1"]),
    (["render", "metals", "--width", "0"], ["--width", "must be >= 1"]),
    (["render", "metals", "--seed", "x"], ["--seed", "expected an integer"]),
    (["render", "metals", "--threads", "999"], ["render: threads: must be <= "]),
    # Every number: finite, of the right type, in range (checks.py), one line, exit 2.
    (["render", "metals", "--time", "inf"], ["--time", "must be finite, got inf"]),
    (["render", "metals", "--time", "nan"], ["--time", "must be finite, got nan"]),
    (["render", "metals", "--clamp", "inf"], ["--clamp", "must be finite"]),
    (["render", "metals", "--spp", "2.5"], ["--spp", "expected an integer, got '2.5'"]),
    (["render", "metals", "--spp", "10000000000"], ["--spp", "must be <= 1000000000"]),
    (["render", "metals", "--max-depth", "99999999999"], ["--max-depth", "must be <= "]),
    (["render", "metals", "--max-depth", "0"], ["render: max_depth: must be >= 1"]),
    (["render", "metals", "--seed", "-1"], ["--seed", "must be >= 0"]),
    (["render", "metals", "--seed", str(2**63)], ["--seed", "must be <= 2**63 - 1"]),
    (["render", "metals", "--width", "70000"], ["--width", "must be <= 65536"]),
    (["render", "metals", "--time", "0"], ["--time", "must be > 0"]),
    (["render", "metals", "--sampling", "magic"], ["--sampling", "invalid choice"]),
    (["render", "no_such.toml"], ["no_such.toml: no such scene file"]),
    (["rendr"], ["invalid choice: 'rendr'"]),
]


@pytest.mark.parametrize("args, words", BAD_COMMANDS, ids=[" ".join(a) for a, _ in BAD_COMMANDS])
def test_bad_command_line(tmp_path, capsys, monkeypatch, args, words):
    monkeypatch.chdir(tmp_path)
    status, err = run_cli(tmp_path, capsys, *args)
    assert status == 2
    assert len(err) == 1, err
    for w in words:
        assert w in err[0], (w, err[0])
    assert list(tmp_path.iterdir()) == []


# Property-based: any document either loads or raises SceneError.

VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-10**20, 10**20) | st.floats(allow_nan=True)
    | st.text(max_size=8) | st.sampled_from(["sky", "sphere", "box", "xz_rect", "lambertian",
                                             "metal", "white", "lamp", "ball"]),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(
        st.sampled_from(["type", "albedo", "center", "radius", "material", "name", "x0",
                         "x1", "z0", "z1", "k", "p0", "p1", "emit", "fuzz", "ior", "alpha",
                         "rotate", "rotate_y", "translate", "flip_face"]), inner,
                        max_size=6),
    max_leaves=12)

KEYS = ["description", "lights", "camera", "render", "materials", "objects", "bogus"]


@settings(max_examples=400, suppress_health_check=[HealthCheck.too_slow])
@given(doc=st.dictionaries(st.sampled_from(KEYS), VALUES, max_size=6))
def test_any_document_loads_or_raises_scene_error(doc):
    try:
        scene = scene_from_dict(doc)
    except rt.SceneError as e:
        assert "\n" not in str(e)
    else:
        pack_scene(scene)


def _mutated_good_docs():
    import tomllib
    good = tomllib.loads(GOOD)
    paths = []

    def walk(node, path):
        items = node.items() if isinstance(node, dict) else enumerate(node)
        for k, v in items:
            paths.append(path + (k,))
            if isinstance(v, (dict, list)):
                walk(v, path + (k,))
    walk(good, ())
    return good, paths


GOOD_DOC, GOOD_PATHS = _mutated_good_docs()


@settings(max_examples=400)
@given(path=st.sampled_from(GOOD_PATHS), value=VALUES)
def test_one_bad_field_in_a_good_document(path, value):
    import copy
    doc = copy.deepcopy(GOOD_DOC)
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    try:
        scene = scene_from_dict(doc)
    except rt.SceneError as e:
        assert "\n" not in str(e)
    else:
        pack_scene(scene)


@settings(max_examples=200)
@given(text=st.text(max_size=200))
def test_any_text_loads_or_raises_scene_error(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("fuzz") / "fuzz.toml"
    path.write_text(text)
    try:
        rt.load_scene(path)
    except rt.SceneError:
        pass


# The same rules for the API and a Renderer: SceneError (a ValueError), never
# OverflowError or TypeError, and nothing is compiled or rendered.

@pytest.mark.parametrize("options, words", [
    (dict(time=float("inf")), ["render: time: must be finite, got inf"]),
    (dict(time=float("nan")), ["render: time: must be finite, got nan"]),
    (dict(time=10**400), ["render: time: must be within"]),
    (dict(time="3"), ["render: time: expected a number, got '3'"]),
    (dict(spp=2.5), ["render: spp: expected an integer, got 2.5"]),
    (dict(spp=True), ["render: spp: expected an integer, got True"]),
    (dict(spp=-5), ["render: spp: must be >= 1, got -5"]),
    (dict(clamp=float("inf")), ["render: clamp: must be finite"]),
    (dict(seed=-1), ["render: seed: must be >= 0"]),
    (dict(seed=1.5), ["render: seed: expected an integer"]),
    (dict(width=0), ["render: width: must be >= 1"]),
    (dict(height=10**6), ["render: height: must be <= 65536"]),
    (dict(max_depth=0), ["render: max_depth: must be >= 1"]),
    (dict(threads=0), ["render: threads: must be >= 1"]),
    (dict(threads=1.0 + 2**-40), ["render: threads: expected an integer"]),
    (dict(bvh="yes"), ["render: bvh: must be True, False or None"]),
])
def test_bad_render_option_raises_scene_error(options, words):
    scene = rt.load_scene("metals")
    with pytest.raises(rt.SceneError) as info:
        rt.render(scene, **options)
    for w in words:
        assert w in str(info.value), (w, str(info.value))
    with pytest.raises(rt.SceneError) as again:      # the Renderer: the same rule
        rt.Renderer(scene, **options)
    assert str(again.value) == str(info.value)


def test_renderer_methods_check_their_numbers():
    r = rt.Renderer(rt.load_scene("metals"), width=4, height=2, threads=1)
    assert r.options.threads == 1
    for n, words in [(-5, "add_samples: n: must be >= 1, got -5"),
                     (0, "add_samples: n: must be >= 1, got 0"),
                     (2.5, "add_samples: n: expected an integer, got 2.5"),
                     (float("inf"), "add_samples: n: expected an integer, got inf"),
                     (10**10, "add_samples: n: must be <= ")]:
        with pytest.raises(rt.SceneError, match=words):
            r.add_samples(n)
    assert r.spp == 0 and r.seconds == 0.0
    with pytest.raises(rt.SceneError, match="Renderer: unknown option 'thread' "
                       r"\(did you mean 'threads'\?\)"):
        rt.Renderer(rt.load_scene("metals"), thread=1)


@pytest.mark.parametrize("build, words", [
    # Lengths whose squares would underflow are refused with the reason.
    (lambda: rt.Camera(lookfrom=(0, 0, 3e-170), lookat=(0, 0, 0)),
     ["camera: lookat: is only 3e-170 from lookfrom", "underflow"]),
    (lambda: rt.Camera(lookfrom=(1e50, 0, 0), lookat=(1e50, 0, 1e30)),
     ["camera: lookat: is only 1e+30 from lookfrom, at coordinates of 1e+50",
      "lost in rounding"]),
    (lambda: rt.Camera(vup=(0, 1e-170, 0)), ["camera: vup:", "too short"]),
    (lambda: rt.Camera(focus_dist=1e-120), ["camera: focus_dist: 1e-120 is too small"]),
    (lambda: rt.sphere((0, 0, 0), 1e-160, rt.lambertian((.5, .5, .5))),
     ["sphere: radius: 1e-160 is too small"]),
    (lambda: rt.xy_rect(0, 1e-120, 0, 1, 0, rt.lambertian((.5, .5, .5))),
     ["xy_rect: x1: is only 1e-120 from x0"]),
    (lambda: rt.box((0, 0, 0), (1, 1e-150, 1), rt.lambertian((.5, .5, .5))),
     ["box: p1: y is only 1e-150 from p0's y"]),
    (lambda: rt.directional(0.2, (0, 1e-170, 0)), ["directional light: direction:",
                                                   "too short"]),
])
def test_lengths_too_small_for_the_arithmetic(build, words):
    with pytest.raises(rt.SceneError) as info:
        build()
    for w in words:
        assert w in str(info.value), (w, str(info.value))


def test_a_camera_close_to_its_target_is_fine_when_the_scale_allows():
    # 1e-90 apart near the origin: squares of 1e-180 are normal doubles.
    camera = rt.Camera(lookfrom=(0, 0, 3e-90), lookat=(0, 0, 0))
    assert camera.focus_dist == 3e-90


def test_unknown_scene_hints_at_the_file(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "book1.toml").write_text(GOOD)
    status, err = run_cli(tmp_path, capsys, "render", "book1", "-q")
    assert status == 2 and len(err) == 1
    assert "unknown scene 'book1' (did you mean the file 'book1.toml'?)" in err[0]
    status, err = run_cli(tmp_path, capsys, "render", "cornel_box", "-q")
    assert "(did you mean 'cornell_box'?)" in err[0]


# -- what a newcomer tripped on ----------------------------------------------------

def test_a_misspelled_required_field_is_named(tmp_path, capsys, scene_file):
    path = scene_file(GOOD.replace('radius = 1\nmaterial = "white"',
                                   'radius = 1\nmaterail = "white"'))
    status, err = run_cli(tmp_path, capsys, "render", str(path), "-o", str(tmp_path / "x.png"))
    assert status == 2 and len(err) == 1
    assert err[0].endswith("objects[0] (sphere 'ball'): material: missing (required); "
                           "is 'materail' a misspelling of it?")
    assert not (tmp_path / "x.png").exists()


def test_the_expected_fields_are_listed_once(tmp_path, capsys, scene_file):
    path = scene_file(GOOD.replace("radius = 1\n", "radius = 1\ncolour = 2\n", 1))
    status, err = run_cli(tmp_path, capsys, "render", str(path))
    assert status == 2 and len(err) == 1
    listed = err[0].split("expected one of: ")[1].split(", ")
    assert len(listed) == len(set(listed)) and "material" in listed


def test_a_binary_file_is_not_a_scene_file(tmp_path, capsys):
    path = tmp_path / "photo.toml"
    path.write_bytes(bytes([0xd3, 0x00, 0xff, 0x10]))
    status, err = run_cli(tmp_path, capsys, "render", str(path))
    assert status == 2
    assert err == [f"rtweekend: error: {path}: not a scene file: it is not text (UTF-8); "
                   "scene files are TOML (docs/scenes.md)"]


def test_an_output_folder_says_to_name_a_file(tmp_path, capsys):
    status, err = run_cli(tmp_path, capsys, "render", "cornell_box", "-o", str(tmp_path))
    assert status == 2 and len(err) == 1
    assert f"{tmp_path}: cannot write: it is a folder; name a file in it" in err[0]


def test_a_lights_list_without_emitters_is_warned_about_and_renders(tmp_path, capsys,
                                                                   scene_file):
    path = scene_file(GOOD.replace('lights = ["lamp"]', 'lights = ["ball"]'))
    out = tmp_path / "x.png"
    status, err = run_cli(tmp_path, capsys, "render", str(path), "-o", str(out), "-q")
    assert status == 0 and out.exists()
    assert err == ["rtweekend: warning: lights: names no emitter (sphere 'ball'), while "
                   "xz_rect 'lamp' emits: the light pdf aims at objects that give no light; "
                   "list the emitters too"]
    with pytest.warns(rt.SceneWarning, match="names no emitter"):
        rt.Renderer(rt.load_scene(path), spp=1)


@pytest.mark.parametrize("move, words", [
    # `lights = [...]` written after [render]: TOML makes it render.lights.
    (lambda t: t.replace('lights = ["lamp"]\n', "").replace("max_depth = 5\n",
                                                             'max_depth = 5\nlights = ["lamp"]\n'),
     "render: 'lights' is a top-level key, but it fell into [render]"),
    (lambda t: t.replace('description = "a test scene"\n', "").replace(
        'material = "glow"\n', 'material = "glow"\ndescription = "a lamp"\n'),
     "(xz_rect 'lamp'): 'description' is a top-level key, but it fell into the [[objects]] "
     "table objects[1]"),
    (lambda t: t.replace("spp = 2\n", "").replace("height = 8\n", "height = 8\nspp = 2\n"),
     "camera: 'spp' belongs in [render], but it fell into [camera]"),
    (lambda t: t.replace("width = 8\n", "").replace("max_depth = 5\n",
                                                    "max_depth = 5\nwidth = 8\n"),
     "render: 'width' belongs in [camera], but it fell into [render]"),
])
def test_a_key_under_the_wrong_header_says_where_it_belongs(tmp_path, capsys, scene_file,
                                                            move, words):
    path = scene_file(move(GOOD))
    status, err = run_cli(tmp_path, capsys, "render", str(path), "-o", str(tmp_path / "x.png"))
    assert status == 2 and len(err) == 1, err
    assert words in err[0], err[0]
    assert not (tmp_path / "x.png").exists()
