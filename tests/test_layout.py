"""The package's layout holds: layers import downwards, every kind is dispatched,
and the install finds every subpackage."""
import ast
import inspect
import tomllib

import pytest
from conftest import REPO

from rtweekend.path import layout, materials, shapes
from rtweekend.scene.materials import CLASSIC_MATERIALS, MATERIALS, MEDIUM_MATERIALS

# The sources in this checkout (the tests may run against an installed copy).
PACKAGE = REPO / "rtweekend"


def _imports(path):
    """Every module a source file imports, as written (relative ones with dots)."""
    tree = ast.parse(path.read_text())
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            out.append("." * node.level + (node.module or ""))
    return out


@pytest.mark.parametrize("path", sorted((PACKAGE / "scene").glob("*.py")), ids=lambda p: p.name)
def test_the_description_layer_imports_no_kernel(path):
    for name in _imports(path):
        assert not name.startswith(("..path", "..kernel", "..classic", "..distributed",
                                    "numba", "rtweekend")), f"{path.name} imports {name}"


def test_nothing_but_the_top_imports_the_api():
    for path in PACKAGE.rglob("*.py"):
        if path.parent == PACKAGE and path.name in ("__init__.py", "cli.py"):
            continue
        for name in _imports(path):
            assert not name.endswith("api") or name == "numba.extending", \
                f"{path.relative_to(PACKAGE)} imports {name}"


def test_distributed_imports_the_renderer_never_the_reverse():
    for path in (PACKAGE / "path").rglob("*.py"):
        assert not any("distributed" in n for n in _imports(path)), path.name
    assert any(n.endswith("path.renderer") for n in
               _imports(PACKAGE / "distributed" / "worker.py"))


def test_every_primitive_kind_has_its_module_and_every_operation():
    assert set(shapes.MODULES) == set(layout.PRIMITIVE_KINDS)
    for module in shapes.MODULES.values():
        for op in ("distance", "outward_normal", "enters", "sample_toward", "pdf_toward",
                   "uv", "bounds", "pack", "light_parts"):
            assert callable(getattr(module, op, None)), f"{module.__name__} lacks {op}"
        assert module.FLOATS <= layout.OBJ_FLOATS
    for op in ("distance", "outward_normal", "enters", "sample_toward", "pdf_toward", "uv"):
        # distance's branches are distance_as's (the kind given: bvh.kind_walk)
        body = inspect.getsource(getattr(shapes, "distance_as" if op == "distance" else op).py_func)
        for module in shapes.MODULES.values():
            assert f"{module.__name__.rsplit('.', 1)[1]}.{op}(" in body, \
                f"shapes.{op} has no branch for {module.__name__}"


def test_every_path_material_has_a_tag():
    path_materials = set(MATERIALS) - set(CLASSIC_MATERIALS) | set(MEDIUM_MATERIALS)
    assert set(materials.MATERIAL_TAGS) == path_materials


def test_no_material_kind_is_tested_outside_the_materials():
    # Estimators ask a material's flags (path/materials/flags.py): a new kind
    # is its module and its registration, no estimator edited.  Only
    # path/materials/ names the kinds.
    kinds = [name.upper() for name in materials.MATERIAL_TAGS]
    for name, module in materials.KINDS.items():
        assert isinstance(module.FLAGS, int) and module.FLAGS > 0, name
        assert materials.KIND_FLAGS[materials.MATERIAL_TAGS[name]] == module.FLAGS
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.startswith("path/materials/"):
            continue
        names = {n.id for n in ast.walk(ast.parse(path.read_text())) if isinstance(n, ast.Name)}
        names |= {n.attr for n in ast.walk(ast.parse(path.read_text()))
                  if isinstance(n, ast.Attribute)}
        names |= {a.name for n in ast.walk(ast.parse(path.read_text()))
                  if isinstance(n, ast.ImportFrom) for a in n.names}
        assert not names & set(kinds), f"{rel} names {sorted(names & set(kinds))}"


def _module_graph():
    """{module: the package's modules it imports} (at the top or in a function;
    `from PKG import name` is PKG.name where that is a module, else PKG)."""
    paths = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        paths[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    graph = {}
    for name, path in paths.items():
        here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        found = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                found |= {a.name for a in node.names}
            elif isinstance(node, ast.ImportFrom):
                base = here[:len(here) - node.level + 1] if node.level else []
                module = ".".join(base + ([node.module] if node.module else []))
                found |= {f"{module}.{a.name}" if f"{module}.{a.name}" in paths else module
                          for a in node.names}
        graph[name] = {m for m in found if m in paths and m != name}
    return graph


def test_no_module_imports_one_that_imports_it_back():
    # Layers import downwards: a cycle, even through an import inside a
    # function, means one of the two modules is in the wrong place.
    graph, state, cycles = _module_graph(), {}, []

    def visit(module, trail):
        state[module] = "open"
        for other in sorted(graph[module]):
            if state.get(other) == "open":
                cycles.append(trail[trail.index(other):] + [module, other])
            elif other not in state:
                visit(other, trail + [module])
        state[module] = "done"
    for module in sorted(graph):
        if module not in state:
            visit(module, [])
    assert not cycles, [" -> ".join(c) for c in cycles]


def test_pyproject_lists_every_subpackage():
    config = tomllib.loads((REPO / "pyproject.toml").read_text())
    listed = set(config["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(REPO).parts)
             for p in PACKAGE.rglob("__init__.py")}
    assert found <= listed, f"not in pyproject.toml: {sorted(found - listed)}"


def test_no_compiled_function_takes_more_than_twelve_arguments():
    # A long signature is a sign that a concept has no name: a subpath's
    # vertex arrays, the ray that leaves a vertex, the point on the lens.
    long = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef) and any(
                    "jit" in ast.unparse(d) for d in node.decorator_list):
                count = len(node.args.args) + len(node.args.kwonlyargs)
                if count > 12:
                    long.append(f"{path.relative_to(PACKAGE)}: {node.name} ({count})")
    assert not long, long


@pytest.mark.parametrize("source", ["path/renderer.py", "options.py"])
def test_the_driver_and_the_options_name_no_estimator(source):
    # Each estimator declares what it needs of the driver (integrators/needs.py)
    # and its named strategies: the renderer and the options ask, and import,
    # call or name none of them ("path" is also the integrator's name, beside
    # "classic").
    from rtweekend.options import SAMPLINGS
    from rtweekend.path.integrators import ESTIMATORS
    tree = ast.parse((PACKAGE / source).read_text())
    modules = set(ESTIMATORS) | {"photons", "mis", "subpaths", "vertices"}
    named = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            named |= {a.name for a in node.names} & modules
            named |= {(node.module or "").split(".")[-1]} & modules
        elif isinstance(node, ast.Name | ast.Attribute):
            named |= {node.id if isinstance(node, ast.Name) else node.attr} \
                & {"bdpt", "photons", "caustics"}
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            named |= {node.value} & (set(ESTIMATORS) | set(SAMPLINGS)) - {"path"}
    assert named == set(), named
    for name, module in ESTIMATORS.items():
        assert isinstance(module.NEEDS.splats, bool), name
        assert all(s.estimator == name for s in module.STRATEGIES.values()), name
