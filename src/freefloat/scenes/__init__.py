"""Scenes as data: the schema, and the built-in scenes shipped with the package."""

from __future__ import annotations

from pathlib import Path

from ..errors import SceneError
from ..paths import SCENES_DIR
from .mechanism_schema import MechanismScene
from .schema import Scene, load_scene, parse_scene

#: The scene ``freefloat simulate`` runs without an argument.
DEFAULT_SCENE = "four_arm_joint_space"


def builtin_scenes() -> dict[str, Path]:
    """Built-in scene names and their files."""
    return {p.stem: p for p in sorted(SCENES_DIR.glob("*.toml"))}


def find_scene(name_or_path: str | Path) -> Scene | MechanismScene:
    """A built-in scene by name, or a scene file by path (a robot or a mechanism scene).

    Raises:
        SceneError: when it is neither, listing the built-in names.
    """
    builtins = builtin_scenes()
    if str(name_or_path) in builtins:
        return load_scene(builtins[str(name_or_path)])
    path = Path(name_or_path)
    if path.is_file():
        return load_scene(path)
    raise SceneError(
        f"'{name_or_path}' is neither a scene file nor a built-in scene; built-in: {', '.join(builtins)}"
    )


__all__ = ["DEFAULT_SCENE", "MechanismScene", "Scene", "builtin_scenes", "find_scene", "load_scene", "parse_scene"]
