"""A wheel carries everything a run needs: installed from it, freefloat runs the built-in robot
and mechanism scenes from an empty folder (not from the repository)."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from freefloat.app.scenes import builtin_scenes
from freefloat.paths import URDF_DIR

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """The project built as a wheel (pip wheel, isolated build) and unpacked into a folder of
    its own with ``pip install --target`` (dependencies come from the test environment)."""
    root = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(REPO), "--no-deps", "-q", "-w", str(root / "dist")],
                   check=True, timeout=900)
    wheel = next((root / "dist").glob("freefloat-*.whl"))
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(root / "site"),
                    str(wheel)], check=True, timeout=300)
    return root


def freefloat_from(installed: Path, *args: str, cwd: Path) -> subprocess.CompletedProcess:
    """``freefloat ARGS`` with the wheel's package first on the path, run in ``cwd``."""
    code = (f"import sys; sys.path.insert(0, {str(installed / 'site')!r}); import freefloat; "
            f"assert freefloat.__file__.startswith({str(installed / 'site')!r}), freefloat.__file__; "
            "from freefloat.app.cli import main; sys.exit(main(sys.argv[1:]))")
    return subprocess.run([sys.executable, "-c", code, *args], cwd=cwd, capture_output=True, text=True, timeout=600)


def test_wheel_ships_every_builtin_robot_mechanism_and_scene(installed):
    """Every file of urdf/ and every built-in scene is inside the wheel."""
    wheel = next((installed / "dist").glob("freefloat-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    expected = {f"freefloat/urdf/{p.name}" for p in URDF_DIR.iterdir() if p.suffix in (".urdf", ".toml")}
    expected |= {f"freefloat/app/scenes/{p.name}" for p in builtin_scenes().values()}
    assert expected <= names, sorted(expected - names)
    assert any(n.endswith("licenses/LICENSE") for n in names)


def test_default_scene_runs_from_an_empty_folder(installed, tmp_path):
    """The main job runs from a folder that is not the repository and writes its run folder."""
    done = freefloat_from(installed, "simulate", "--quiet", "--no-html", "--no-figures", "--out", "out",
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out" / "summary.json").is_file()


def test_mechanism_closure_file_is_found_from_an_empty_folder(installed, tmp_path):
    """A mechanism scene naming the built-in closure file by name finds it inside the package."""
    scene = builtin_scenes()["five_bar_computed_torque"].read_text()
    (tmp_path / "s.toml").write_text(scene.replace("duration = 0.5", "duration = 0.002")
                                     .replace("reaching_phase = 0.2", "reaching_phase = 0.001"))
    done = freefloat_from(installed, "simulate", "s.toml", "--quiet", "--no-html", "--no-figures", "--out", "out",
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr
