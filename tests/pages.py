"""Reading a written meshcat page back: its command packets, embedded files and settings."""

from __future__ import annotations

import base64
import gzip
import re
from pathlib import Path

import umsgpack


def packets(path: Path) -> list[dict]:
    """Decode every command packet embedded in a page."""
    blobs = re.findall(r'freefloat_command\("([A-Za-z0-9+/=]+)"\);', path.read_text())
    return [umsgpack.unpackb(base64.b64decode(blob)) for blob in blobs]


def assets(path: Path) -> list[bytes]:
    """The files embedded in a page, inflated, in table order."""
    blobs = re.findall(r'freefloat_asset\("(?:text|binary)", "([A-Za-z0-9+/=]+)"\);', path.read_text())
    return [gzip.decompress(base64.b64decode(blob)) for blob in blobs]


def objects(path_or_packets) -> dict[str, dict]:
    """{node path: lowered object} of the page's set_object commands."""
    found = packets(path_or_packets) if isinstance(path_or_packets, Path) else path_or_packets
    return {p["path"]: p["object"] for p in found if p["type"] == "set_object"}


def everything(path: Path) -> bytes:
    """The page's text plus every embedded file and texture, decoded: what the page carries."""
    blobs = [path.read_bytes(), *assets(path)]
    for obj in objects(path).values():
        for uri in obj["object"].get("resources", {}).values():
            blobs.append(base64.b64decode(uri.split(",", 1)[1]))
    return b"\n".join(blobs)
