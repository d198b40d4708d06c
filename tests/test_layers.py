"""The library's layers: the core never imports lessons or views; modules stay readable.

Layers, from the bottom: core (``course_lib/*.py`` but the view helpers) -> view helpers
(``plotting``, ``widgets``, ``players``) -> lessons (``course_lib/lessons/``) -> checks
(``course_lib/check/``) -> instructor tools (``course_lib/instructor/``). A module may
import only from its own layer or the layers below it.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "course_lib"
VIEW = {"plotting", "widgets", "players", "clips"}
RANK = {"core": 0, "view": 1, "lessons": 2, "check": 3, "instructor": 4}
#: Third-party packages that belong to views, never to the core.
VIEW_PACKAGES = {"matplotlib", "ipywidgets", "IPython"}
MAX_LINES = 330  # "under ~300 lines", with a little slack for a long docstring


def layer_of(module: str) -> str:
    """Layer of a dotted module name inside course_lib (``course_lib.x.y``)."""
    parts = module.split(".")[1:]
    if not parts or parts[0] in {"__init__", "_validate"}:
        return "core"
    if parts[0] in VIEW:
        return "view"
    if parts[0] in {"lessons", "check", "instructor"}:
        return parts[0]
    return "core"


def modules():
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG.parent).with_suffix("")
        yield ".".join(rel.parts), path


def imports_of(module: str, path: Path):
    """Absolute names of everything ``path`` imports, at any depth of the file."""
    # the package a relative import starts from: "course_lib.check" for check/__init__.py
    package = module.removesuffix(".__init__") if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if node.module is None:
                for alias in node.names:
                    yield f"{target}.{alias.name}"
            else:
                yield target


MODULES = list(modules())


@pytest.mark.parametrize("module,path", MODULES, ids=[m for m, _ in MODULES])
def test_imports_only_from_its_layer_or_below(module, path):
    mine = RANK[layer_of(module)]
    for target in imports_of(module, path):
        if target.startswith("course_lib"):
            theirs = RANK[layer_of(target)]
            assert theirs <= mine, f"{module} ({layer_of(module)}) imports {target} ({layer_of(target)})"
        elif layer_of(module) == "core":
            top = target.split(".")[0]
            assert top not in VIEW_PACKAGES, f"core module {module} imports {target}"


@pytest.mark.parametrize("module,path", MODULES, ids=[m for m, _ in MODULES])
def test_module_is_short_and_says_what_it_holds(module, path):
    text = path.read_text()
    n = len(text.splitlines())
    assert n <= MAX_LINES, f"{module} has {n} lines; split it (limit ~300)"
    if text.strip():
        doc = ast.get_docstring(ast.parse(text))
        assert doc and len(doc) > 20, f"{module} has no module docstring saying what it holds"


def test_importing_the_core_loads_no_view_package():
    import subprocess
    import sys

    code = ("import sys, course_lib, course_lib.springs, course_lib.hair, course_lib.collisions, "
            "course_lib.events, course_lib.sph, course_lib.rigid, course_lib.largestep\n"
            "bad = sorted(m for m in sys.modules if m.split('.')[0] in "
            f"{sorted(VIEW_PACKAGES)!r} or m.startswith('course_lib.lessons'))\n"
            "print(','.join(bad))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


CORE_NAMES = {
    "course_lib": ["integrate", "METHODS", "amplification_factor", "max_stable_dt", "Trajectory",
                   "forward_euler", "rk4", "symplectic_euler", "NewtonianSystem"],
    "course_lib.springs": ["SpringNetwork", "hair_chain", "cloth_grid", "stiffness_matrix",
                           "chain_pairs", "spring_force_pair", "max_frequency"],
    "course_lib.forces": ["constant_gravity", "nbody_gravity", "drag", "viscous_damping", "attractor"],
    "course_lib.systems": ["NewtonianSystem", "stack_state", "split_state", "newtonian",
                           "sum_forces", "oscillator"],
    "course_lib.fields": ["radial", "vortex", "constant_wind", "compose"],
    "course_lib.collisions": ["sphere", "plane", "self_contact"],
    "course_lib.cloth": ["simulate", "METHODS"],
    "course_lib.neighbors": ["pairs", "all_pairs"],
    "course_lib.sph": ["KERNELS", "dam_break"],
    "course_lib.rigid": ["free_body"],
}


@pytest.mark.parametrize("module", sorted(CORE_NAMES))
def test_core_names_stay_where_they_were(module):
    mod = importlib.import_module(module)
    missing = [n for n in CORE_NAMES[module] if not hasattr(mod, n)]
    assert not missing, f"{module} lost {missing}"


def _import_graph() -> dict[str, set[str]]:
    known = {m for m, _ in MODULES}
    graph: dict[str, set[str]] = {}
    for module, path in MODULES:
        targets = set()
        for target in imports_of(module, path):
            # "from course_lib.x import y" names module x, or x.y when y is a submodule
            while target and target not in known:
                target = target.rpartition(".")[0]
            if target and target != module and target.startswith("course_lib."):
                targets.add(target.removesuffix(".__init__"))
        graph[module.removesuffix(".__init__")] = targets
    return graph


def test_no_import_circles_lazy_imports_included():
    """Imports point one way inside a layer too: no module reaches itself through imports,
    whether they sit at the top of a file or inside a function. Imports of a package's own
    ``__init__`` by its submodules are the package's business and not counted."""
    graph = _import_graph()
    circles: list[list[str]] = []
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if node.startswith(nxt + "."):
                continue  # a submodule importing its own package
            if state.get(nxt) == 1:
                circles.append([*stack[stack.index(nxt):], nxt])
            elif nxt in graph and not state.get(nxt):
                visit(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if not state.get(node):
            visit(node)
    assert not circles, "import circles:\n" + "\n".join(" -> ".join(c) for c in circles)
