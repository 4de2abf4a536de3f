"""Mesh and texture files a page embeds: only from allowed folders, each file once, gzipped.

A page may carry only files the robot's description legitimately points to: a mesh or a
Collada texture must resolve (symbolic links followed) inside the URDF's folder or a package
directory (:func:`allowed_folders`). A mesh elsewhere (``file:///etc/...``,
``package://../../..``) is refused: the geometry is left out with a :class:`FreefloatWarning`
naming the URDF, the geometry and the path. A texture elsewhere, missing, not an image, or named
by a URL (``http://``, ``//host/...``) is dropped with a warning and the mesh is drawn untextured;
its name is also removed from the Collada text the page embeds (rewritten from the parsed file,
so that a name in CDATA or split by a comment goes as well), so a page never names a URL a
browser would fetch (no tracking pixel, nothing loaded from the network).

Each allowed file is stored once in an :class:`AssetTable` however many geometries use it,
gzip-compressed at the fastest level (:data:`LEVEL`; ``mtime=0``, so pages stay
bit-reproducible); command packets hold the
placeholder ``freefloat-asset:<index>`` in its place, which the page resolves after inflating
the table (``DecompressionStream``).
"""

from __future__ import annotations

import base64
import gzip
import mimetypes
import re
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

from ...robot.loading import FreefloatWarning, example_robot_data_share

#: gzip level of the embedded files: on the UR5's seven visual meshes (6.7 MB of Collada) level 9
#: took 1.30 s for 2.03 MB, level 1 0.13 s for 2.43 MB (each page of a UR5 robot compressed them).
LEVEL = 1

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
        self._index: dict[object, int] = {}

    def placeholder(self, path: Path, kind: str) -> str:
        """The placeholder of ``path`` (read, compressed and stored on first use)."""
        resolved = path.resolve()
        if resolved not in self._index:
            packed = gzip.compress(resolved.read_bytes(), compresslevel=LEVEL, mtime=0)
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

    def collada(self, dae: Path) -> tuple[str, dict[str, str]]:
        """The placeholder of a Collada file's text, with the textures that may not be embedded
        removed from it, and ``{<init_from> text: data URI}`` of those that may (resolved
        against the file's folder); each dropped texture is named in a warning."""
        resources, dropped = self.collada_textures(dae)
        if not dropped:
            return self.placeholder_text(dae, dae.read_text(errors="replace")), resources
        root = ET.parse(dae).getroot()
        for element in _texture_sources(root):
            if _content(element) in dropped:
                element.text = None
                element[:] = []
        return self.placeholder_text(dae, _xml(root)), resources

    def collada_textures(self, dae: Path) -> tuple[dict[str, str], set[str]]:
        """``{<init_from> text: data URI}`` of the textures of a Collada file that may be embedded
        (resolved against the file's folder), and the names of those dropped with a warning."""
        resources, dropped = {}, set()
        for element in _texture_sources(ET.parse(dae).getroot()):
            name = _content(element)
            if not name:
                continue
            if _URL.match(name):
                _warn(f"{self.source}: texture '{name}' of {dae.name} is a URL; dropped (a page loads nothing "
                      "from the network), mesh drawn untextured")
                dropped.add(name)
                continue
            image = dae.parent / name.removeprefix("file://")
            if not (inside(image, self.folders) and image.is_file() and image.suffix.lower() in IMAGE_SUFFIXES):
                _warn(f"{self.source}: texture '{name}' of {dae.name} is not an image file inside the URDF's "
                      "folder or the package directories; dropped, mesh drawn untextured")
                dropped.add(name)
                continue
            mime = mimetypes.guess_type(image.name)[0] or "image/png"
            resources[name] = f"data:{mime};base64,{base64.b64encode(image.read_bytes()).decode('ascii')}"
        return resources, dropped

    def placeholder_text(self, path: Path, text: str) -> str:
        """The placeholder of ``text`` stored as the (rewritten) contents of ``path``."""
        key = (path.resolve(), text)
        if key not in self._index:
            packed = gzip.compress(text.encode(), compresslevel=LEVEL, mtime=0)
            self._index[key] = len(self.entries)
            self.entries.append(("text", base64.b64encode(packed).decode("ascii")))
        return f"{PLACEHOLDER}{self._index[key]}"


#: A URI with a scheme other than ``file:`` (``http:``, ``https:``, ``data:``, ``ftp:`` ...) or a
#: network-path reference (``//host/...``).
_URL = re.compile(r"^\s*(?!file:)[A-Za-z][A-Za-z0-9+.-]*:|^\s*//")


def _texture_sources(root: ET.Element) -> list[ET.Element]:
    """The ``<init_from>`` and ``<ref>`` elements of a Collada tree's images (Collada 1.4 and 1.5)."""
    return [e for image in root.iter() if image.tag.rsplit("}", 1)[-1] == "image"
            for e in image.iter() if e.tag.rsplit("}", 1)[-1] in ("init_from", "ref")]


def _content(element: ET.Element) -> str:
    """An element's whole text, as the page's loader reads it (the DOM's ``textContent``): CDATA
    included, comments left out, child elements' text joined, stripped. (Its ``.text`` alone
    stopped at a comment or a child, and a URL split there reached the page.)"""
    return "".join(element.itertext()).strip()


def _warn(message: str) -> None:
    """One :class:`FreefloatWarning`."""
    warnings.warn(message, FreefloatWarning, stacklevel=4)


def _xml(root: ET.Element) -> str:
    """The tree ``root`` as XML text, in its root's namespace as the default one (as Collada files
    are written) when every element allows it."""
    namespace = root.tag[1:].split("}", 1)[0] if root.tag.startswith("{") else None
    try:
        return ET.tostring(root, encoding="unicode", default_namespace=namespace)
    except ValueError:  # an element outside any namespace: prefixes for the others
        return ET.tostring(root, encoding="unicode")
