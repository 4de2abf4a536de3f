"""Reading a written meshcat page back: its command packets, embedded files and settings."""

from __future__ import annotations

import base64
import gzip
import re
from pathlib import Path

import numpy as np
import umsgpack


def packets(path: Path) -> list[dict]:
    """Decode every command packet embedded in a page."""
    blobs = re.findall(r'freefloat_command\("([A-Za-z0-9+/=]+)"\);', path.read_text())
    return [umsgpack.unpackb(base64.b64decode(blob)) for blob in blobs]


def animation(found: list[dict]) -> dict[str, dict[str, list]]:
    """{node path: {track name: [(time in frames, value list), ...]}} of the animation among
    a page's packets ``found`` (each track's times and values are Float64Arrays: msgpack
    extension 0x18)."""
    (command,) = [p for p in found if p["type"] == "set_animation"]
    out: dict[str, dict[str, list]] = {}
    for clip in command["animations"]:
        out[clip["path"]] = {}
        for track in clip["clip"]["tracks"]:
            assert track["times"].type == track["values"].type == 0x18
            times = np.frombuffer(track["times"].data, "<f8")
            values = np.frombuffer(track["values"].data, "<f8").reshape(len(times), -1)
            out[clip["path"]][track["name"]] = [(float(t), v.tolist()) for t, v in zip(times, values)]
    return out


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
