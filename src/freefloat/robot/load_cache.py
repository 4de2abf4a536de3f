"""The on-disk cache of checked robot loads, keyed by the URDF's content.

:func:`~freefloat.robot.loading.load_robot` parses a URDF twice (freefloat's reader and
urdfdom), checks it, builds the Pinocchio model and its mass matrix at the neutral posture: 0.5 s
on a 198-DoF tree, at every process. An entry keeps what those steps found (the model, through
Pinocchio's own serialization, the Robot's other fields, the warnings and notes), so that a later
process loading the same bytes with the same options skips them and still prints the same
warnings. What depends on other files or on this machine is redone at every load: the mesh
files' existence, the visual geometry, the memory check.

An entry is keyed by the sha256 of the URDF's bytes, the file's name (the warnings name it),
whether it is one of freefloat's own robots, ``base``, ``end_effectors`` and ``inertias``, and
the versions that make the result (:data:`FORMAT`, freefloat's version and loader source,
Pinocchio's and numpy's). Gravity is no part of the key: it is set on the model after the load.
An entry is one file, ``<key>.json``, whose first line is the sha256 of the rest: an entry
freefloat did not write whole (cut short, edited, another format) is ignored and written again,
never an error and never a different model. It is written to a temporary file and renamed, so
another process reads the old entry or the new one; an unwritable folder means no cache. A folder
keeps the :data:`MAX_ENTRIES` most recently used entries. No entry is ever executed (JSON, and
Pinocchio's text archive of the model, never pickle).

Where: ``$FREEFLOAT_CACHE_DIR/robots`` (empty: no cache), else ``$XDG_CACHE_HOME/freefloat/robots``,
else ``~/.cache/freefloat/robots``. Deleting the folder at any time is safe.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import re
import tempfile
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np
import pinocchio as pin

from .urdf_checks import is_built_in
from .visuals import MissingMesh

#: Format of an entry; raised whenever what an entry holds or means changes.
FORMAT = 1
#: The environment variable naming the cache folder (empty: no cache).
CACHE_DIR_VARIABLE = "FREEFLOAT_CACHE_DIR"
#: Entries a folder keeps; writing one more removes the least recently used (about 2.5 kB per joint
#: each: 470 kB for 192 joints).
MAX_ENTRIES = 200
#: The name of an entry file: the sha256 of its inputs (the only files the cache reads or removes).
ENTRY_NAME = re.compile(r"[0-9a-f]{64}\.json")


@dataclass
class CheckedLoad:
    """What the loader's parse, checks and build found in a URDF, ready to be a Robot.

    Attributes:
        model: the checked Pinocchio model (floating root joint, the base CoM frame, inertias as
            asked), gravity not yet set.
        base_link: name of the URDF root link.
        base_com: base-link centre of mass in the base-link frame, m (shape (3,)).
        base_com_rotation: rotation from the base CoM frame to the base-link frame (shape (3, 3)).
        end_effectors: end-effector link names.
        link_coms: CoM of every URDF link in its own link frame, m (3,) each.
        warnings: the loader's warnings on the file itself (not the mesh files').
        notes: the loader's notes (what is so on purpose).
        meshes: every visual mesh the file names (link, filename as written), in file order.
    """

    model: pin.Model
    base_link: str
    base_com: np.ndarray
    base_com_rotation: np.ndarray
    end_effectors: tuple[str, ...]
    link_coms: dict[str, np.ndarray]
    warnings: tuple[str, ...]
    notes: tuple[str, ...]
    meshes: tuple[MissingMesh, ...]


def cache_folder() -> Path | None:
    """The folder of the entries, or None when the cache is off (``FREEFLOAT_CACHE_DIR=""``) or
    there is no home folder to put it in."""
    configured = os.environ.get(CACHE_DIR_VARIABLE)
    if configured is not None:
        return Path(configured).expanduser() / "robots" if configured else None
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    try:
        root = Path(xdg) if os.path.isabs(xdg) else Path.home() / ".cache"  # a relative XDG path is ignored
    except RuntimeError:  # no home folder
        return None
    return root / "freefloat" / "robots"


def entry_inputs(raw: bytes, path: Path, base: str, end_effectors: list[str] | tuple[str, ...] | None,
                 inertias: str) -> dict:
    """Everything an entry's content depends on: the URDF's bytes ``raw`` (read from ``path``),
    the load's options and the versions (see the module's docstring)."""
    return {
        "format": FORMAT, "freefloat": _freefloat_version(), "loader": _loader_digest(),
        "pinocchio": pin.__version__, "numpy": np.__version__,
        "urdf": hashlib.sha256(raw).hexdigest(), "name": path.name, "built_in": is_built_in(path),
        "base": base, "end_effectors": None if end_effectors is None else list(end_effectors), "inertias": inertias,
    }


def read(folder: Path, inputs: dict) -> CheckedLoad | None:
    """The entry of ``inputs`` in ``folder``; None when there is none or it is not one freefloat
    wrote whole for these inputs."""
    entry_file = folder / _file_name(inputs)
    try:
        digest, _, body = entry_file.read_bytes().partition(b"\n")
        if hashlib.sha256(body).hexdigest().encode() != digest:
            return None
        entry = json.loads(body)
        if entry["inputs"] != inputs:
            return None
        model = pin.Model()
        model.loadFromString(entry["model"])
        with contextlib.suppress(OSError):  # recently used (a read-only folder keeps its times)
            os.utime(entry_file)
        return CheckedLoad(
            model=model, base_link=str(entry["base_link"]), base_com=np.array(entry["base_com"], dtype=float),
            base_com_rotation=np.array(entry["base_com_rotation"], dtype=float),
            end_effectors=tuple(map(str, entry["end_effectors"])),
            link_coms={str(name): np.array(com, dtype=float) for name, com in entry["link_coms"].items()},
            warnings=tuple(map(str, entry["warnings"])), notes=tuple(map(str, entry["notes"])),
            meshes=tuple(MissingMesh(str(link), str(filename)) for link, filename in entry["meshes"]))
    except (OSError, ValueError, KeyError, TypeError, AttributeError, RuntimeError):
        return None


def write(folder: Path, inputs: dict, checked: CheckedLoad) -> None:
    """Store ``checked`` as the entry of ``inputs`` in ``folder`` (created if need be), atomically;
    nothing when the folder cannot be written."""
    body = json.dumps({
        "inputs": inputs, "model": checked.model.saveToString(), "base_link": checked.base_link,
        "base_com": checked.base_com.tolist(), "base_com_rotation": checked.base_com_rotation.tolist(),
        "end_effectors": list(checked.end_effectors),
        "link_coms": {name: com.tolist() for name, com in checked.link_coms.items()},
        "warnings": list(checked.warnings), "notes": list(checked.notes), "meshes": [list(m) for m in checked.meshes],
    }).encode()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(dir=folder, prefix=".entry-", suffix=".tmp")
        try:
            with os.fdopen(handle, "wb") as out:
                out.write(hashlib.sha256(body).hexdigest().encode() + b"\n" + body)
            os.replace(temporary, folder / _file_name(inputs))
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
            raise
        _forget_the_oldest(folder)
    except OSError:
        return


def _forget_the_oldest(folder: Path) -> None:
    """Remove the least recently used entries of ``folder`` beyond :data:`MAX_ENTRIES` (entry
    files only: :data:`ENTRY_NAME`)."""
    entries = []
    for entry in os.scandir(folder):
        if ENTRY_NAME.fullmatch(entry.name):
            with contextlib.suppress(OSError):  # removed meanwhile by another process
                entries.append((entry.stat().st_mtime_ns, entry.path))
    for _, path in sorted(entries)[:max(0, len(entries) - MAX_ENTRIES)]:
        with contextlib.suppress(OSError):
            os.unlink(path)


def _file_name(inputs: dict) -> str:
    """The entry file of ``inputs``: the sha256 of their JSON."""
    return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest() + ".json"


@functools.cache
def _freefloat_version() -> str:
    """The installed freefloat distribution's version ("" when it is run from a source tree that
    is not installed: the loader's digest still tells its code)."""
    try:
        return version("freefloat")
    except PackageNotFoundError:
        return ""


@functools.cache
def _loader_digest() -> str:
    """sha256 of the robot package's sources and of freefloat's error texts: an edited checkout
    (same version) never reads an entry an older loader wrote."""
    package = Path(__file__).parent
    digest = hashlib.sha256()
    for source in sorted(package.glob("*.py")) + [package.parent / "errors.py"]:
        digest.update(source.name.encode() + b"\0" + source.read_bytes() + b"\0")
    return digest.hexdigest()
