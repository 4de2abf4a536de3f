"""Mesh and texture files a page embeds: only from allowed folders, each file once, gzipped.

A page may carry only files the robot's description legitimately points to: a mesh or a
Collada texture must resolve (symbolic links followed) inside the URDF's folder or a package
directory (:func:`allowed_folders`). A mesh elsewhere (``file:///etc/...``,
``package://../../..``) is refused: the geometry is left out with a :class:`FreefloatWarning`
naming the URDF, the geometry and the path. A texture elsewhere, missing, or not an image is
dropped with a warning and the mesh is drawn untextured.

Each allowed file is stored once in an :class:`AssetTable` however many geometries use it,
gzip-compressed (``mtime=0``, so pages stay bit-reproducible); command packets hold the
placeholder ``freefloat-asset:<index>`` in its place, which the page resolves after inflating
the table (``DecompressionStream``).
"""

from __future__ import annotations

import base64
import gzip
import mimetypes
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

from ...robot.loading import FreefloatWarning, example_robot_data_share

#: Placeholder prefix of an embedded file inside a command packet.
PLACEHOLDER = "freefloat-asset:"
#: Texture types a page embeds (by file suffix).
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".gif", ".bmp", ".webp", ".tga")


def allowed_folders(urdf: Path) -> list[Path]:
    """Folders whose files a page may embed: the URDF's folder and the package directories
    freefloat resolves ``package://`` through (example-robot-data's ``share``), resolved."""
    folders = [urdf.resolve().parent]
    if (share := example_robot_data_share()) is not None:
        folders.append(share.resolve())
    return folders


def inside(path: Path, folders: list[Path]) -> bool:
    """Whether ``path``, resolved (links followed, ``..`` removed), lies inside one of ``folders``."""
    resolved = path.resolve()
    return any(resolved.is_relative_to(folder) for folder in folders)


class AssetTable:
    """Files embedded in one page, each once, in first-use order.

    Attributes:
        folders: where embedded files must lie (see :func:`allowed_folders`).
        source: the description the files come from (named in warnings).
        entries: per file, ``(kind, base64 of the gzipped bytes)``; kind ``"text"`` (decoded
            as UTF-8 in the page) or ``"binary"`` (a ``Uint8Array``).
    """

    def __init__(self, folders: list[Path], source: Path) -> None:
        self.folders = folders
        self.source = source
        self.entries: list[tuple[str, str]] = []
        self._index: dict[Path, int] = {}

    def placeholder(self, path: Path, kind: str) -> str:
        """The placeholder of ``path`` (read, compressed and stored on first use)."""
        resolved = path.resolve()
        if resolved not in self._index:
            packed = gzip.compress(resolved.read_bytes(), compresslevel=9, mtime=0)
            self._index[resolved] = len(self.entries)
            self.entries.append((kind, base64.b64encode(packed).decode("ascii")))
        return f"{PLACEHOLDER}{self._index[resolved]}"

    def allowed_mesh(self, path: Path, geometry: str) -> bool:
        """Whether mesh file ``path`` of ``geometry`` may be embedded; warns when refused."""
        if inside(path, self.folders) and path.is_file():
            return True
        _warn(f"{self.source}: mesh '{path}' of geometry '{geometry}' lies outside the URDF's folder "
              f"and the package directories ({', '.join(map(str, self.folders))}); refused, geometry not drawn")
        return False

    def collada_textures(self, dae: Path) -> dict[str, str]:
        """``{<init_from> text: placeholder}`` of the textures of a Collada file that may be
        embedded (resolved against the file's folder); the others are dropped with a warning."""
        resources = {}
        root = ET.parse(dae).getroot()
        images = [e for lib in root.iter() if lib.tag.endswith("library_images") for e in lib.iter()
                  if e.tag.endswith("init_from") and (e.text or "").strip()]
        for element in images:
            name = element.text.strip()
            image = dae.parent / name.removeprefix("file://")
            if not (inside(image, self.folders) and image.is_file() and image.suffix.lower() in IMAGE_SUFFIXES):
                _warn(f"{self.source}: texture '{name}' of {dae.name} is not an image file inside the URDF's "
                      "folder or the package directories; dropped, mesh drawn untextured")
                continue
            mime = mimetypes.guess_type(image.name)[0] or "image/png"
            resources[name] = f"data:{mime};base64,{base64.b64encode(image.read_bytes()).decode('ascii')}"
        return resources


def _warn(message: str) -> None:
    """One :class:`FreefloatWarning`."""
    warnings.warn(message, FreefloatWarning, stacklevel=4)
