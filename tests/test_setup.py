"""The build's layout (setup.py): which translation units include Pinocchio's headers, and the
units the schedule knows. Read from the sources: setup.py runs the build when imported."""

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


def pinocchio_headers(source: Path, seen: set[Path] | None = None) -> set[str]:
    """The Pinocchio headers ``source`` includes, through the project's own headers."""
    seen = set() if seen is None else seen
    if source in seen:
        return set()
    seen.add(source)
    found = set()
    for line in source.read_text().splitlines():
        match = INCLUDE.match(line)
        if match is None:
            continue
        bracket, name = match.groups()
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
    assert including == {"cpp/pin_plant.cpp"}


def test_the_schedule_knows_every_unit_it_orders():
    order, memory = setup_constant("ORDER"), setup_constant("UNIT_MEMORY")
    assert sorted(order) == sorted(memory)
    assert all((ROOT / unit).is_file() for unit in order)
