"""Fuzz class of URL textures (issue 24): a robot whose Collada mesh names its texture by a URL,
spelled every way a Collada file allows (any scheme, ``//host``, upper case, leading blanks, in
CDATA, split by a comment or a child element, a character as an entity), sometimes beside an
allowed local texture; or a mesh named by a URL. ``freefloat simulate`` writes the page; the page
(its text and every file it embeds) must never name the URL's host (``network`` otherwise).
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from pathlib import Path

from .conftest import toml_text
from .fuzzing import Failure, cli, verdict
from .pages import everything
from .test_assets import DAE, URDF  # UR5's wrist mesh; a two-link robot drawing {mesh}

SCHEMES = ["http://", "https://", "HTTP://", "Https://", "ftp://", "ws://", "//", " http://", "\n\thttps://",
           "data:text/plain,", "javascript:", "http:/", "\\\\", "file://"]
WRAPS = ["plain", "cdata", "comment", "child", "entity", "padded"]


def _spelled(rng: random.Random, url: str, wrap: str) -> str:
    """``url`` as the text of an ``<init_from>``, wrapped as ``wrap`` says."""
    cut = rng.randrange(1, len(url))
    if wrap == "cdata":
        return f"<![CDATA[{url}]]>"
    if wrap == "comment":
        return f"{url[:cut]}<!-- {rng.randrange(100)} -->{url[cut:]}"
    if wrap == "child":
        return f"{url[:cut]}<b/>{url[cut:]}"
    if wrap == "entity":
        return "".join(f"&#{ord(c)};" if c in ":/." and rng.random() < 0.5 else c for c in url)
    if wrap == "padded":
        return f"\n  {url}  \n"
    return url


@dataclass
class TextureCase:
    """A robot whose Collada mesh (or mesh file name) names a URL."""

    seed: int
    host: str
    images: list[str] = field(default_factory=list)  # <init_from> texts
    mesh_url: str = ""  # a URL as the URDF's mesh file name instead
    local: bool = False  # an allowed texture beside them
    kind: str = "textures"

    @property
    def mutation(self) -> str:
        return f"mesh {self.mesh_url!r}" if self.mesh_url else f"textures {self.images!r}"[:200]

    def run(self, folder: Path) -> tuple[str, str]:
        """Write the robot and its scene, simulate with the page on, look for the host."""
        robot = folder / "robot"
        robot.mkdir(parents=True, exist_ok=True)
        entries = [f'<image id="i{k}" name="i{k}"><init_from>{text}</init_from></image>'
                   for k, text in enumerate(self.images + (["skin.png"] if self.local else []))]
        if self.local:
            (robot / "skin.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"\0" * 16)
        (robot / "evil.dae").write_text(DAE.read_text().replace(
            "<library_images/>", f"<library_images>{''.join(entries)}</library_images>"))
        (robot / "textured.urdf").write_text(URDF.format(mesh=self.mesh_url or "evil.dae"))
        scene = {"name": f"texture{self.seed}", "robot": {"urdf": "robot/textured.urdf", "base": "free"},
                 "task": {"kind": "none"}, "controller": {"kind": "none"},
                 "initial": {"base_angular_velocity": [5.0, -3.0, 8.0]},
                 "simulation": {"duration": 0.05, "control_period": 0.001},
                 "output": {"figures": False, "html": True}}
        (folder / "scene.toml").write_text(toml_text(scene))
        try:
            status, err = cli(["simulate", "scene.toml", "--quiet", "--out", "out"], folder)
        except Failure as failure:
            return failure.outcome, failure.detail
        page = folder / "out" / "trajectory.html"
        if page.is_file() and self.host.encode() in everything(page):
            return "network", f"{page.name} names {self.host}"
        if status == 0 and not page.is_file():
            return "traceback", f"exit 0 without a page: {err.strip()[-200:]}"
        return verdict(status, err)


def texture_case(seed: int) -> TextureCase:
    """1-3 texture URLs (:data:`SCHEMES`, :data:`WRAPS`) in a Collada mesh, or a mesh URL."""
    rng = random.Random(seed)
    host = f"trk{seed}.example"
    if rng.random() < 0.15:
        return TextureCase(seed, host, mesh_url=rng.choice(["http://", "https://", "//", "package://"]) + host + "/m.dae")
    images = [_spelled(rng, rng.choice(SCHEMES) + host + "/p.png", rng.choice(WRAPS))
              for _ in range(rng.randint(1, 3))]
    return TextureCase(seed, host, images, local=rng.random() < 0.3)
