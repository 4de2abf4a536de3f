"""A URDF's visual geometry: its mesh files found (or not), and Pinocchio's visual model of what
was found.

A mesh file that cannot be found costs only its own ``<visual>``: the other links keep theirs,
and the loader's note names each link and file (and where it looked), whether or not the
geometry is built (``freefloat info`` loads without it). A page then draws the bare links as
the stick figure's pieces (:mod:`freefloat.app.viz.meshcat_html`).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import NamedTuple

import pinocchio as pin

from .catalog import example_robot_data_share

#: Missing meshes a note names one by one; the rest are counted.
NAMED = 3


class MissingMesh(NamedTuple):
    """A visual ``<mesh>`` a URDF names (missing: no file answers it): its link and the filename as
    written."""

    link: str
    filename: str


def package_dirs(path: Path) -> list[str]:
    """Where ``package://`` meshes of the URDF ``path`` are looked for: its folder, then
    example-robot-data's ``share`` when installed."""
    dirs = [str(path.parent.resolve())]
    if (share := example_robot_data_share()) is not None:
        dirs.append(str(share))
    return dirs


def visual_meshes(tree: ET.Element) -> list[MissingMesh]:
    """Every visual mesh the URDF ``tree`` names, as (link, filename as written), in file order
    (collision meshes are not drawn, so not looked for)."""
    return [MissingMesh(link.get("name", "?"), mesh.get("filename", ""))
            for link in tree.iter("link") for visual in link.findall("visual") for mesh in visual.iter("mesh")]


def missing_meshes(path: Path, meshes: list[MissingMesh]) -> list[MissingMesh]:
    """Those of ``meshes`` (:func:`visual_meshes` of the URDF ``path``) whose files are not found,
    in the same order (looked for on every load: they are other files than the URDF)."""
    dirs = package_dirs(path)
    return [mesh for mesh in meshes if _resolve_mesh(mesh.filename, path.parent, dirs) is None]


def missing_note(path: Path, missing: list[MissingMesh]) -> str:
    """The loader's note on ``missing`` (not empty): each link and file up to :data:`NAMED`, the
    folders looked in, and what the page draws instead."""
    named = ", ".join(f"link '{m.link}': '{m.filename}'" for m in missing[:NAMED])
    more = f" and {len(missing) - NAMED} more" if len(missing) > NAMED else ""
    what = "mesh" if len(missing) == 1 else f"{len(missing)} meshes"
    return (f"{path.name}: {what} not found ({named}{more}; looked in {', '.join(package_dirs(path))}); "
            f"{'that link is drawn as a stick' if len(missing) == 1 else 'those links are drawn as sticks'}, the rest with their meshes")


def visual_model(path: Path, model: pin.Model, tree: ET.Element, missing: list[MissingMesh],
                 notes: list[str]) -> pin.GeometryModel | None:
    """Pinocchio's visual geometry of the URDF ``tree`` (Pinocchio's copy of the file, read from
    ``path``) on ``model``, less the ``<visual>`` elements of the ``missing`` meshes; None, with a
    note, when the mesh library cannot read a mesh that was found."""
    gone = {(m.link, m.filename) for m in missing}
    for link in tree.iter("link"):
        for visual in link.findall("visual"):
            if any((link.get("name", "?"), mesh.get("filename", "")) in gone for mesh in visual.iter("mesh")):
                link.remove(visual)
    try:
        return pin.buildGeomFromUrdfString(model, ET.tostring(tree, encoding="unicode"), pin.GeometryType.VISUAL,
                                           package_dirs=package_dirs(path))
    except (RuntimeError, ValueError) as exc:  # coal cannot read a mesh file
        reason = str(exc).strip().splitlines()[-1] if str(exc).strip() else type(exc).__name__
        notes.append(f"{path.name}: meshes could not be read ({reason}); loaded for dynamics without visuals")
        return None


def _resolve_mesh(filename: str, urdf_dir: Path, dirs: list[str]) -> Path | None:
    """The mesh file a URDF filename points to, or None."""
    if filename.startswith("package://"):
        relative = filename[len("package://"):].lstrip("/")  # package:///a/b names package 'a' too
        candidates = [Path(d) / relative for d in dirs]
    elif filename.startswith("file://"):
        candidates = [Path(filename[len("file://"):])]
    else:
        candidates = [urdf_dir / filename]
    return next((c for c in candidates if c.is_file()), None)
