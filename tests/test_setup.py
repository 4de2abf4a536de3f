"""The build's layout (setup.py, cpp/): folders by concept with bindings apart, each unit one .cpp
file, which translation units include Pinocchio's headers, and the units the schedule knows. Read
from the sources: setup.py runs the build when imported."""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CPP = ROOT / "cpp"
INCLUDE = re.compile(r'\s*#include\s+([<"])([^>"]+)[>"]')


def setup_constant(name: str):
    """The literal value assigned to ``name`` at setup.py's top level."""
    for node in ast.parse((ROOT / "setup.py").read_text()).body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == name for t in node.targets):
            return ast.literal_eval(node.value)
    raise LookupError(name)


def includes(source: Path) -> list[tuple[str, str]]:
    """``source``'s #include lines as (bracket, name): ``"<"`` or ``'"'``."""
    return [match.groups() for match in map(INCLUDE.match, source.read_text().splitlines()) if match is not None]


def pinocchio_headers(source: Path, seen: set[Path] | None = None) -> set[str]:
    """The Pinocchio headers ``source`` includes, through the project's own headers."""
    seen = set() if seen is None else seen
    if source in seen:
        return set()
    seen.add(source)
    found = set()
    for bracket, name in includes(source):
        if bracket == "<":
            found |= {name} if name.startswith("pinocchio/") else set()
            continue
        local = next((base / name for base in (source.parent, CPP) if (base / name).is_file()), None)
        assert local is not None, f"{source}: #include \"{name}\" not found"
        found |= pinocchio_headers(local.resolve(), seen)
    return found


def test_only_the_plant_unit_includes_more_of_pinocchio_than_its_forward_declarations():
    including = {unit for unit in setup_constant("ORDER")
                 if pinocchio_headers((ROOT / unit).resolve()) - {"pinocchio/multibody/fwd.hpp"}}
    assert including == {"cpp/sim/pin_plant.cpp"}


def test_the_schedule_knows_every_unit_it_orders():
    order, memory = setup_constant("ORDER"), setup_constant("UNIT_MEMORY")
    assert sorted(order) == sorted(memory)
    assert all((ROOT / unit).is_file() for unit in order)


def test_every_source_is_a_scheduled_unit_and_none_includes_another():
    """Each .cpp under cpp/ is a translation unit of the schedule, and no file includes a .cpp."""
    units = {path.relative_to(ROOT).as_posix() for path in CPP.rglob("*.cpp")}
    assert units == set(setup_constant("ORDER"))
    assert set(setup_constant("OPTIMIZATION")) <= units
    included = {(source.name, name) for source in CPP.rglob("*.[ch]pp") for _, name in includes(source)
                if name.endswith(".cpp")}
    assert not included


def test_only_the_bindings_include_pybind11():
    """pybind11 is included only under cpp/bindings/: the numerics compile without it."""
    including = {source.relative_to(CPP).parts[0] for source in CPP.rglob("*.[ch]pp")
                 if any(name.startswith("pybind11/") for _, name in includes(source))}
    assert including == {"bindings"}


def test_each_unit_of_numerics_sits_beside_the_header_it_implements():
    """Every .cpp outside cpp/bindings/ includes a header of its own folder (the one it defines)."""
    beside = {unit.relative_to(CPP).as_posix(): [name for bracket, name in includes(unit)
                                                 if bracket == '"' and (unit.parent / name).is_file()]
              for unit in CPP.rglob("*.cpp") if unit.parent.name != "bindings"}
    assert beside and all(beside.values()), beside
