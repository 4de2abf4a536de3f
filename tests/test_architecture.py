"""The package layout is the architecture: lower layers never import higher ones, the two task
families never import each other, no module imports itself back through others, and nothing in
the product (every module but the lab's) names the lab.

Imports are read from the source (module level and inside functions alike), so a deferred import
cannot hide an upward dependency or a circle.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import freefloat

from .conftest import REPO

SRC = Path(freefloat.__file__).resolve().parent

#: Layer of each family of modules, lowest first; the facade (``freefloat`` itself, its public
#: aliases and ``__main__``) sits above everything.
LAYERS = {
    "base": 0,
    "freefloat.robot": 1,
    "freefloat.dynamics": 2,
    "freefloat.space": 3, "freefloat.parallel": 3,
    "freefloat.app": 4,
    "freefloat.lab": 5,
}
FACADE = 6
#: The lab: above the product, which never names it (its commands come in through a plug-in).
LAB = "freefloat.lab"
#: A string naming a lab module, absolutely or relatively: what ``importlib`` would import.
LAB_NAME = re.compile(r"(freefloat\.|\.+)lab(\.\w+)*")
#: The base: single modules that form one family (they may import each other).
BASE = {"freefloat.errors", "freefloat.paths", "freefloat.distributed", "freefloat.inputs", "freefloat.lazy",
        "freefloat.extras", "freefloat.arguments", "freefloat.registry", "freefloat.documents"}


def module_files() -> dict[str, Path]:
    """Every module of the package by dotted name."""
    out = {}
    for path in sorted(SRC.rglob("*.py")):
        parts = ["freefloat", *path.relative_to(SRC).with_suffix("").parts]
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = module_files()


def family(module: str) -> str | None:
    """The layer family (a key of LAYERS) ``module`` belongs to, or None for the facade."""
    if module in BASE:
        return "base"
    return next((f for f in LAYERS if module == f or module.startswith(f + ".")), None)


def layer(module: str) -> int:
    found = family(module)
    return FACADE if found is None else LAYERS[found]


def imports(module: str) -> set[str]:
    """freefloat modules ``module`` imports (``from pkg import submodule`` counts as the submodule)."""
    path = MODULES[module]
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("freefloat"):
                continue
            subs = [f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in MODULES]
            found.update(subs if len(subs) == len(node.names) else [target, *subs])
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.startswith("freefloat"))
    return {m for m in found if m in MODULES and m != module}


GRAPH = {m: imports(m) for m in MODULES}


def violations(graph: dict[str, set[str]], module: str) -> list[str]:
    """Modules ``module`` imports from a higher layer or from a sibling family."""
    return sorted(t for t in graph[module] if layer(t) > layer(module)
                  or (layer(t) == layer(module) and family(t) != family(module)))


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Groups of modules that import each other, directly or through others (Tarjan's strongly
    connected components of more than one module)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(m: str) -> None:
        index[m] = low[m] = len(index)
        stack.append(m)
        on_stack.add(m)
        for t in graph[m]:
            if t not in index:
                visit(t)
                low[m] = min(low[m], low[t])
            elif t in on_stack:
                low[m] = min(low[m], index[t])
        if low[m] == index[m]:
            component = []
            while True:
                x = stack.pop()
                on_stack.discard(x)
                component.append(x)
                if x == m:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for m in graph:
        if m not in index:
            visit(m)
    return found


def test_every_module_belongs_to_a_layer():
    """Every module but the facade (freefloat, its public aliases, __main__) is in a layer."""
    facade = sorted(m for m in MODULES if family(m) is None)
    assert facade == ["freefloat", "freefloat.__main__", "freefloat.gjm", "freefloat.models", "freefloat.simulation"]


@pytest.mark.parametrize("module", sorted(m for m in MODULES if family(m) is not None))
def test_no_module_imports_a_higher_layer_or_a_sibling_family(module):
    """A module imports only its own family and lower layers."""
    assert not violations(GRAPH, module), f"{module} (layer {layer(module)}) imports {violations(GRAPH, module)}"


def test_no_import_circles():
    """No module reaches itself through the imports of others."""
    assert not circles(GRAPH), f"import circles: {circles(GRAPH)}"


def test_the_checks_catch_a_planted_upward_import_and_circle():
    """The old upward import models.exact -> control.computed_torque, which also closed a circle
    back to models, is caught by both checks (so they can fail)."""
    exact, torque = "freefloat.dynamics.models.exact", "freefloat.space.control.computed_torque"
    planted = {**GRAPH, exact: GRAPH[exact] | {torque}}
    assert violations(planted, exact) == [torque]
    assert any(exact in c and torque in c for c in circles(planted))


def lab_names(graph: dict[str, set[str]], module: str, source: str | None = None) -> list[str]:
    """The lab modules ``module`` imports, then the strings in its source (``source``, default its
    file) that name a lab module, as a deferred import by name would (``"freefloat.lab.plugin"``)."""
    tree = ast.parse(MODULES[module].read_text() if source is None else source)
    strings = [node.value for node in ast.walk(tree)
               if isinstance(node, ast.Constant) and isinstance(node.value, str) and LAB_NAME.fullmatch(node.value)]
    return sorted(t for t in graph[module] if family(t) == LAB) + strings


def test_the_product_never_names_the_lab():
    """No module outside freefloat.lab imports it, by an import statement or by a string."""
    named = {m: found for m in MODULES if family(m) != LAB and (found := lab_names(GRAPH, m))}
    assert not named, f"the product names the lab: {named}"


def test_the_check_catches_a_planted_import_of_the_lab():
    """The lab imported by the command line, by an import statement or by name, and by the facade
    (above every layer), is caught (so the check can fail)."""
    cli, plugin = "freefloat.app.cli", "freefloat.lab.plugin"
    planted = {**GRAPH, cli: GRAPH[cli] | {plugin}, "freefloat": GRAPH["freefloat"] | {plugin}}
    assert lab_names(planted, cli) == [plugin] and lab_names(planted, "freefloat") == [plugin]
    assert violations(planted, cli) == [plugin]
    source = 'import importlib\nimportlib.import_module("freefloat.lab.plugin")\nHEAVY = {"bench": "..lab.bench"}\n'
    assert lab_names(GRAPH, cli, source) == ["freefloat.lab.plugin", "..lab.bench"]


def test_the_public_names_stay():
    """freefloat.load_robot, freefloat.gjm.compute, freefloat.models.make_model and
    freefloat.simulation.run are the layered modules' own functions."""
    import freefloat.gjm
    import freefloat.models
    import freefloat.simulation
    from freefloat.dynamics import gjm, models, simulation
    from freefloat.robot import loading

    assert freefloat.load_robot is loading.load_robot
    assert freefloat.gjm.compute is gjm.compute and freefloat.gjm.derivatives is gjm.derivatives
    assert freefloat.models.make_model is models.make_model and freefloat.models.MODELS is models.MODELS
    assert freefloat.simulation.run is simulation.run and freefloat.simulation.Result is simulation.Result


#: The page that draws the layers; its section "The source tree" tables every subpackage.
ARCHITECTURE = REPO / "docs" / "architecture.md"


def subpackages(root: Path) -> set[str]:
    """Dotted names of the package at ``root`` and of every folder below it with an ``__init__.py``."""
    return {".".join(["freefloat", *path.parent.relative_to(root).parts]) for path in root.rglob("__init__.py")}


def tabled(page: str) -> list[str]:
    """The packages in the first column of the table in ``page``'s section "The source tree"."""
    section = page[page.index("## The source tree"):]
    end = section.find("\n## ")
    section = section if end < 0 else section[:end]
    return re.findall(r"^\| `(freefloat[\w.]*)` \|", section, re.MULTILINE)


def test_the_architecture_page_tables_every_subpackage():
    """docs/architecture.md's source tree has one row per subpackage of src/freefloat (every folder
    with an ``__init__.py``, the package itself too), none twice and none that is gone."""
    rows = tabled(ARCHITECTURE.read_text())
    packages = subpackages(REPO / "src" / "freefloat")
    assert sorted(rows) == sorted(set(rows)), "a subpackage tabled twice"
    assert not packages - set(rows), f"docs/architecture.md does not name {sorted(packages - set(rows))}"
    assert not set(rows) - packages, f"docs/architecture.md names no longer existing {sorted(set(rows) - packages)}"


def test_the_table_check_catches_a_planted_subpackage(tmp_path):
    """A folder with an ``__init__.py`` counts as a subpackage at any depth and a data folder does
    not, and a row is read only from the source tree's table (so the check can fail)."""
    for folder in ("a", "a/b", "a/b/c"):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "__init__.py").write_text("")
    (tmp_path / "data").mkdir()
    (tmp_path / "__init__.py").write_text("")
    assert subpackages(tmp_path) == {"freefloat", "freefloat.a", "freefloat.a.b", "freefloat.a.b.c"}
    page = ("# A\n\n| `freefloat.x` | before |\n\n## The source tree\n\n| subpackage |\n|---|\n"
            "| `freefloat` | root |\n| `freefloat.a` | 1 |\n\n## Later\n\n| `freefloat.a.b` | after |\n")
    assert tabled(page) == ["freefloat", "freefloat.a"]
