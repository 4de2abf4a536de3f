"""A wheel carries everything a run needs: installed from it, freefloat runs the built-in robot
and mechanism scenes from an empty folder (not from the repository)."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest

from freefloat.app.scenes import builtin_scenes
from freefloat.paths import URDF_DIR

REPO = Path(__file__).resolve().parents[1]


def run_group(args: list[str], timeout: float, **kwargs) -> subprocess.CompletedProcess:
    """``subprocess.run`` in a process group of its own that is killed whole when the call ends
    early (timeout, Ctrl-C): a wheel build's compilers never outlive the test."""
    with subprocess.Popen(args, start_new_session=True, text=True, **kwargs) as process:
        try:
            out, err = process.communicate(timeout=timeout)
        finally:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()
    return subprocess.CompletedProcess(args, process.returncode, out, err)


@pytest.fixture(scope="session")
def installed(tmp_path_factory) -> Path:
    """The project built as a wheel once per test session (pip wheel, isolated build; the C++
    objects of an earlier build of this tree are reused, see setup.py) and unpacked into a folder
    of its own with ``pip install --target`` (dependencies come from the test environment)."""
    root = tmp_path_factory.mktemp("wheel")
    built = run_group([sys.executable, "-m", "pip", "wheel", str(REPO), "--no-deps", "-q", "-w", str(root / "dist")],
                      timeout=900, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert built.returncode == 0, built.stderr
    wheel = next((root / "dist").glob("freefloat-*.whl"))
    unpacked = run_group([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(root / "site"),
                          str(wheel)], timeout=300, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert unpacked.returncode == 0, unpacked.stderr
    return root


def freefloat_from(installed: Path, *args: str, cwd: Path) -> subprocess.CompletedProcess:
    """``freefloat ARGS`` with the wheel's package first on the path, run in ``cwd``."""
    code = (f"import sys; sys.path.insert(0, {str(installed / 'site')!r}); import freefloat; "
            f"assert freefloat.__file__.startswith({str(installed / 'site')!r}), freefloat.__file__; "
            "from freefloat.app.cli import main; sys.exit(main(sys.argv[1:]))")
    return run_group([sys.executable, "-c", code, *args], timeout=600, cwd=cwd, stdout=subprocess.PIPE,
                     stderr=subprocess.PIPE)


@pytest.mark.slow
def test_wheel_ships_every_builtin_robot_mechanism_and_scene(installed):
    """Every file of urdf/ and every built-in scene is inside the wheel."""
    wheel = next((installed / "dist").glob("freefloat-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    expected = {f"freefloat/urdf/{p.name}" for p in URDF_DIR.iterdir() if p.suffix in (".urdf", ".toml")}
    expected |= {f"freefloat/app/scenes/{p.name}" for p in builtin_scenes().values()}
    assert expected <= names, sorted(expected - names)
    assert any(n.endswith("licenses/LICENSE") for n in names)


@pytest.mark.slow
def test_default_scene_runs_from_an_empty_folder(installed, tmp_path):
    """The main job runs from a folder that is not the repository and writes its run folder."""
    done = freefloat_from(installed, "simulate", "--quiet", "--no-html", "--no-figures", "--out", "out",
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out" / "summary.json").is_file()


@pytest.mark.slow
def test_mechanism_closure_file_is_found_from_an_empty_folder(installed, tmp_path):
    """A mechanism scene naming the built-in closure file by name finds it inside the package."""
    scene = builtin_scenes()["five_bar_computed_torque"].read_text()
    (tmp_path / "s.toml").write_text(scene.replace("duration = 0.5", "duration = 0.002")
                                     .replace("reaching_phase = 0.2", "reaching_phase = 0.001"))
    done = freefloat_from(installed, "simulate", "s.toml", "--quiet", "--no-html", "--no-figures", "--out", "out",
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr


@pytest.mark.slow
def test_the_lab_comes_in_through_its_entry_point(installed, tmp_path):
    """The wheel declares the lab's plug-in (entry point ``lab`` of group freefloat.plugins), and
    freefloat run from the wheel finds bench and reproduce through it and runs them."""
    wheel = next((installed / "dist").glob("freefloat-*.whl"))
    with zipfile.ZipFile(wheel) as files:
        points = files.read(next(n for n in files.namelist() if n.endswith(".dist-info/entry_points.txt"))).decode()
    assert "[freefloat.plugins]\nlab = freefloat.lab.plugin" in points
    done = freefloat_from(installed, "--help", cwd=tmp_path)
    assert done.returncode == 0 and re.search(r"\{simulate,.*,verify,reproduce,bench,atlas\}", done.stdout), done.stdout
    done = freefloat_from(installed, "reproduce", "chattering", "--quick", "--out", "out", cwd=tmp_path)
    assert done.returncode == 0 and (tmp_path / "out" / "report.json").is_file(), done.stderr


def test_a_command_past_its_timeout_leaves_no_process_behind(tmp_path):
    """A command killed at its timeout takes the processes it started with it (as a wheel build's
    compilers would be)."""
    pid_file = tmp_path / "pid"
    script = ("import subprocess, sys, time; "
              "child = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(120)']); "
              f"open({str(pid_file)!r}, 'w').write(str(child.pid)); time.sleep(120)")
    with pytest.raises(subprocess.TimeoutExpired):
        run_group([sys.executable, "-c", script], timeout=5)
    status = Path(f"/proc/{pid_file.read_text()}/status")

    def dead() -> bool:  # gone, or a zombie not yet reaped
        try:
            return "State:\tZ" in status.read_text()
        except FileNotFoundError:
            return True

    deadline = time.monotonic() + 10  # SIGKILL was sent; give the kernel a moment to act on it
    while not dead() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert dead()
