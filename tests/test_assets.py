"""Tests of freefloat.app.viz.assets: a page embeds only files inside the URDF's folder or the
package directories (hostile meshes and Collada textures are refused)."""

from __future__ import annotations

import importlib.metadata
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from freefloat.app.viz import write_trajectory_html
from freefloat.app.viz.mechanism_page import write_mechanism_html
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.robot.loading import FreefloatWarning, load_robot

from .conftest import REPO
from .pages import assets, everything, objects

SHARE = Path(str(importlib.metadata.distribution("example-robot-data").locate_file("cmeel.prefix/share")))
DAE = SHARE / "example-robot-data/robots/ur_description/meshes/ur5/visual/wrist3.dae"
SECRET = b"freefloat-secret-6b1f0c"

URDF = """<robot name="hostile">
  <link name="base"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><mesh filename="{mesh}"/></geometry></visual></link>
  <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <visual><geometry><box size="1 0.1 0.1"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>
"""


def _hostile_dae(path: Path, image: str) -> Path:
    """UR5's wrist mesh with a ``<library_images>`` entry naming ``image``."""
    text = DAE.read_text().replace(
        "<library_images/>", f'<library_images><image id="leak" name="leak"><init_from>{image}</init_from></image></library_images>')
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def _secret_stl(path: Path) -> Path:
    """A one-triangle ASCII STL whose name line carries SECRET."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"solid {SECRET.decode()}\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                    f"vertex 0 1 0\nendloop\nendfacet\nendsolid {SECRET.decode()}\n")
    return path


def _page(folder: Path, mesh: str) -> tuple[Path, list[warnings.WarningMessage]]:
    """Load the hostile robot naming ``mesh`` and write its page; returns the page and the warnings."""
    urdf = folder / "robot" / "hostile.urdf"
    urdf.parent.mkdir(parents=True, exist_ok=True)
    urdf.write_text(URDF.format(mesh=mesh))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(urdf)
    assert robot.visual_model is not None and robot.visual_model.ngeoms == 2
    t = np.linspace(0.0, 1.0, 5)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        page = write_trajectory_html(robot, t, np.tile(robot.neutral(), (5, 1)), folder / "page.html")
    return page, [w for w in caught if issubclass(w.category, FreefloatWarning)]


def test_collada_texture_outside_is_dropped(tmp_path):
    """A Collada texture naming /etc/passwd is dropped with a warning; the page carries no byte of it."""
    _hostile_dae(tmp_path / "robot" / "evil.dae", "/etc/passwd")
    page, caught = _page(tmp_path, "evil.dae")
    assert any("texture '/etc/passwd'" in str(w.message) and "dropped" in str(w.message) for w in caught)
    assert b"root:x:0:0" not in everything(page) and Path("/etc/passwd").read_bytes()[:32] not in everything(page)
    (mesh,) = [o for o in objects(page).values() if o["object"].get("format") == "dae"]
    assert mesh["object"]["resources"] == {}


@pytest.mark.parametrize("url", ["http://tracker.example/pixel.png", "HTTPS://tracker.example/p.png",
                                 "//tracker.example/p.png", " ftp://tracker.example/p.png",
                                 "<![CDATA[http://tracker.example/p.png]]>", "http://tracker<!-- x -->.example/p.png",
                                 "http://<b/>tracker.example/p.png"])
def test_collada_texture_url_never_reaches_the_page(tmp_path, url):
    """A Collada texture naming a URL, also wrapped in CDATA, split by a comment or spread over a
    child element (the loader reads the element's whole text: those reached the page), is
    dropped with a warning naming it, and the page (its text and every file it embeds) no longer
    names the host: opening it contacts nothing."""
    _hostile_dae(tmp_path / "robot" / "evil.dae", url)
    page, caught = _page(tmp_path, "evil.dae")
    assert any("tracker.example/p" in str(w.message) and "is a URL; dropped" in str(w.message) for w in caught)
    assert b"tracker" not in everything(page)


def test_collada_texture_traversal_is_dropped(tmp_path):
    """A relative texture path climbing out of the URDF's folder is dropped."""
    _secret_stl(tmp_path / "outside" / "secret.png")
    _hostile_dae(tmp_path / "robot" / "evil.dae", "../outside/secret.png")
    page, caught = _page(tmp_path, "evil.dae")
    assert any("../outside/secret.png" in str(w.message) for w in caught) and SECRET not in everything(page)


def test_collada_texture_inside_is_embedded(tmp_path):
    """An image beside the URDF is embedded as the texture's data URI (so the check refuses only what it must)."""
    image = tmp_path / "robot" / "skin.png"
    image.parent.mkdir(parents=True, exist_ok=True)
    image.write_bytes(b"\x89PNG\r\n\x1a\n" + SECRET)
    _hostile_dae(tmp_path / "robot" / "evil.dae", "skin.png")
    page, caught = _page(tmp_path, "evil.dae")
    assert not caught and SECRET in everything(page)


@pytest.mark.parametrize("mesh", ["file://{outside}", "package://../outside/secret.stl"])
def test_mesh_outside_is_refused(tmp_path, mesh):
    """A mesh reached through file:// or package://../ outside the allowed folders is not drawn,
    with a warning naming it, and none of its bytes reach the page."""
    outside = _secret_stl(tmp_path / "outside" / "secret.stl")
    page, caught = _page(tmp_path, mesh.format(outside=outside))
    assert any("secret.stl" in str(w.message) and "refused" in str(w.message) for w in caught)
    assert SECRET not in everything(page) and not assets(page)


def test_mesh_inside_is_embedded(tmp_path):
    """The same STL beside the URDF is embedded."""
    _secret_stl(tmp_path / "robot" / "secret.stl")
    page, caught = _page(tmp_path, "secret.stl")
    assert not caught and assets(page) == [(tmp_path / "robot" / "secret.stl").read_bytes()]


def test_mechanism_page_refuses_hostile_texture(tmp_path):
    """A mechanism whose URDF names a hostile Collada mesh gets a page without /etc/passwd."""
    for name in ("five_bar.urdf", "five_bar.closure.toml"):
        shutil.copy(REPO / "urdf" / name, tmp_path / name)
    urdf = tmp_path / "five_bar.urdf"
    urdf.write_text(urdf.read_text().replace('<box size="0.11 0.02 0.02"/>', '<mesh filename="evil.dae"/>', 1))
    _hostile_dae(tmp_path / "evil.dae", "/etc/passwd")
    chain = load_closed_chain(tmp_path / "five_bar.closure.toml")
    n_q = max(chain.joint_coordinates.values()) + 1
    q = np.tile(np.linspace(0.1, 0.5, n_q), (4, 1))
    with pytest.warns(FreefloatWarning, match="/etc/passwd"):
        page = write_mechanism_html(chain, np.linspace(0.0, 0.3, 4), q, tmp_path / "page.html", fps=10.0)
    assert b"root:x:0:0" not in everything(page)
    assert any(o["object"].get("format") == "dae" for o in objects(page).values())
