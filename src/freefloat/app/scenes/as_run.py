"""A scene as it ran, as a scene file: what a run folder's ``scene.toml`` holds, so that
``freefloat simulate runs/<run>/scene.toml`` runs the same thing again (the robot given by
``--robot``, every default, the files it read and the model ``"auto"`` chose)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from ...errors import SceneError
from ...inputs import toml_text
from ...paths import URDF_DIR
from . import resolve_file
from .mechanism_schema import MechanismScene
from .schema import Scene


def scene_as_run(scene: Scene | MechanismScene, model_choice: dict[str, Any] | None = None) -> str:
    """The TOML text of ``scene`` with every key written out: files as the run found them (a
    built-in file or a known robot by name, any other file by its absolute path) and, for
    ``simulation.model = "auto"``, the ``model`` and ``lock`` of ``model_choice`` (the record in
    the run's summary)."""
    table = {k: v for k, v in scene_table(scene).items() if k != "source"}
    if isinstance(scene, MechanismScene):
        table["mechanism"]["closure"] = _file_as_run(scene, scene.mechanism.closure, "mechanism.closure")
    else:
        table["robot"]["urdf"] = _file_as_run(scene, scene.robot.urdf, "robot.urdf")
        if scene.simulation.model == "auto" and model_choice is not None:
            table["simulation"].update(model=model_choice["model"], lock=model_choice["lock"])
    origin = f"from {scene.source}" if scene.source is not None else "built in code"
    note = "" if table.get("simulation", {}).get("model") == getattr(scene.simulation, "model", None) else \
        '; simulation.model and lock: what model = "auto" chose (summary.json: model_choice)'
    return f"# The scene as freefloat ran it ({origin}{note}).\n" + toml_text(table)


def scene_table(scene: Scene | MechanismScene) -> dict[str, Any]:
    """``scene`` as the tables of its file (``dataclasses.asdict``, in field order, with each
    entry's ``kind`` and settings in one table): ``[controller]``, the ``wrench_profile`` fields
    as ``[[wrenches]]``, the other fields as ``[[environment]]``, ``plugins`` and ``kind`` when
    the scene has them, and the sections of experiment kinds as their own tables."""
    table: dict[str, Any] = {}
    for f in dataclasses.fields(scene):
        value = getattr(scene, f.name)
        if f.name == "controller":
            table[f.name] = _entry(value)
        elif f.name == "environment":
            table["wrenches"] = [dataclasses.asdict(e.settings) for e in value if e.kind == "wrench_profile"]
            others = [_entry(e) for e in value if e.kind != "wrench_profile"]
            if others:
                table["environment"] = others
        elif f.name == "named_kind":
            if value:
                table["kind"] = value
        elif f.name == "sections":
            table.update({name: dataclasses.asdict(settings) for name, settings in value.items()})
        elif f.name != "plugins" or value:
            table[f.name] = _plain(value)
    return table


def _plain(value: Any) -> Any:
    """A section (a dataclass) or an array of them as tables; any other value as it is."""
    if dataclasses.is_dataclass(value):
        return dataclasses.asdict(value)
    if isinstance(value, tuple) and value and dataclasses.is_dataclass(value[0]):
        return [dataclasses.asdict(v) for v in value]
    return value


def _entry(section: Any) -> dict[str, Any]:
    """An entry's section as one table: its ``kind``, then its settings."""
    return {"kind": section.kind, **dataclasses.asdict(section.settings)}


def _file_as_run(scene: Scene | MechanismScene, value: str, key: str) -> str:
    """``value`` as a rerun from another folder finds the same file: a built-in file's name, an
    absolute path, or ``value`` itself when it names no file (a known robot's name)."""
    try:
        path = resolve_file(scene, value, key)
    except SceneError:
        return value
    return path.name if path.resolve().parent == Path(URDF_DIR).resolve() else str(path.resolve())
