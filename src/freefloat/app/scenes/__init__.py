"""Scenes as data: the schemas, the built-in scenes shipped with the package, and the files a
scene names.

A scene file is a robot scene (:class:`Scene`, ``[robot]``) or a mechanism scene
(:class:`MechanismScene`, ``[mechanism]``); its ``kind`` names the experiment that runs it
(:mod:`freefloat.app.experiments`).
"""

from __future__ import annotations

import contextlib
import dataclasses
from pathlib import Path
from typing import Any

from ...errors import InvalidArgument, PluginError, SceneError, did_you_mean, spelled
from ...inputs import read_toml
from ...paths import SCENES_DIR, URDF_DIR
from ...registry import use
from .mechanism_schema import MechanismScene, parse_mechanism_scene
from .schema import Scene, parse_robot_scene

#: The scene ``freefloat simulate`` runs without an argument.
DEFAULT_SCENE = "four_arm_joint_space"
#: The scene ``freefloat simulate --robot NAME`` runs without a scene argument.
ROBOT_SCENE = "tumbling"


def load_scene(path: str | Path) -> Scene | MechanismScene:
    """Read and validate a scene file: a robot scene, or a mechanism scene when it has a
    ``[mechanism]`` section.

    Raises:
        SceneError: naming the file and the key for unknown keys, wrong types, impossible values.
    """
    path = Path(path)
    raw = read_toml(path, "scene file", SceneError)
    return parse_scene(raw, source=path)


def parse_scene(raw: dict[str, Any], source: Path | None = None) -> Scene | MechanismScene:
    """Validate a scene given as a dict (the parsed TOML), robot or mechanism, after importing
    the modules its top-level ``plugins`` names (files relative to the scene file, or module
    names: :func:`freefloat.use`), whose entries it may then name.

    Raises:
        SceneError: naming the file for a ``plugins`` that is not a list of names, or a plug-in
            that is not found or fails to import.
    """
    plugins = use_plugins(raw, source)
    if "mechanism" in raw and "robot" in raw:
        where = f"{source}: " if source else "scene: "
        raise SceneError(f"{where}a scene has either [robot] (a robot scene) or [mechanism] (a mechanism scene), "
                         "not both")
    scene = parse_mechanism_scene(raw, source) if "mechanism" in raw else parse_robot_scene(raw, source)
    return dataclasses.replace(scene, plugins=plugins) if plugins else scene


def use_plugins(raw: dict[str, Any], source: Path | None) -> tuple[str, ...]:
    """Import the modules the scene's ``plugins`` names (see :func:`parse_scene`); their files
    as absolute paths, or their names."""
    where = f"{source}: " if source else "scene: "
    plugins = raw.get("plugins", [])
    if not isinstance(plugins, list) or not all(isinstance(p, str) and p for p in plugins):
        raise SceneError(f"{where}'plugins' must be a list of module names or .py files, got {plugins!r}")
    used = []
    for plugin in plugins:
        try:
            module = use(plugin, base=None if source is None else Path(source).parent)
        except (InvalidArgument, PluginError) as exc:
            raise SceneError(f"{where}'plugins': {exc}") from exc
        used.append(module.__file__ if plugin.endswith(".py") or "/" in plugin else plugin)
    return tuple(used)


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
    raise SceneError(f"'{name_or_path}' is neither a scene file nor a built-in scene"
                     f"{did_you_mean(name_or_path, builtins, 'built-in', 'freefloat scenes')}")


def with_robot(scene: Scene | MechanismScene, robot: str) -> Scene:
    """``scene`` with ``robot`` (a URDF path or a known robot name) in place of its own; the
    end-effectors are then the robot's defaults.

    Raises:
        SceneError: for a mechanism scene.
    """
    if not isinstance(scene, Scene):
        raise SceneError(f"scene '{scene.name}' is a mechanism scene; {spelled('robot', '--robot')} applies to robot "
                         "scenes")
    section = dataclasses.replace(scene.robot, urdf=str(robot), end_effectors=None)
    return dataclasses.replace(scene, robot=section)


def resolve_file(scene: Scene | MechanismScene, value: str, key: str) -> Path:
    """A file a scene names under ``key``: absolute, relative to the scene file, to the working
    directory, or a built-in file in ``urdf/``.

    Raises:
        SceneError: naming the key and the places searched.
    """
    name = Path(value)
    candidates = [name] if name.is_absolute() else [
        *([scene.source.parent / name] if scene.source else []), Path.cwd() / name, URDF_DIR / name
    ]
    for path in candidates:
        with contextlib.suppress(OSError):  # a name too long for the file system is just not there
            if path.is_file():
                return path
    raise SceneError(f"scene '{scene.name}': {key} '{name}' not found in {[str(c.parent) for c in candidates]}")


__all__ = ["DEFAULT_SCENE", "ROBOT_SCENE", "MechanismScene", "Scene", "builtin_scenes", "find_scene", "load_scene",
           "parse_scene", "resolve_file", "with_robot"]

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
