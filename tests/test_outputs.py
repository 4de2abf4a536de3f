"""Tests of freefloat.app.outputs.write_run's figures: a robot run's figures go to the figure
helper, which draws them while the run writes its data and page (the run itself never imports
matplotlib); figures that do not pickle are drawn in the run's process; an interrupt while the
helper draws drops the figures and the next run draws again."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

from freefloat.app import runner
from freefloat.app.outputs import write_run
from freefloat.app.run_folder import RunFolder
from freefloat.app.viz import rendering

from .conftest import quiet_scene, scene_variant

#: The default scene, 50 ms of it, with the default figures and no page.
SHORT = {"simulation": {"duration": 0.05}, "output": {"html": False}}


def _short(tmp_path):
    from freefloat.app.scenes import load_scene

    return load_scene(scene_variant(tmp_path / "short.toml", "four_arm_joint_space", **SHORT))


def test_a_robot_run_writes_its_figures_without_importing_matplotlib(tmp_path):
    """The default job's figures are written, in the run's order, and the run's process has not
    imported matplotlib (the helper drew them)."""
    code = ("import sys, warnings; warnings.simplefilter('ignore')\n"
            "from freefloat.app.runner import run_scene\n"
            f"done = run_scene({str(tmp_path / 'scene.toml')!r}, {str(tmp_path / 'out')!r})\n"
            "print(' '.join(p.name for p in done.written))\n"
            "print(any(m == 'matplotlib' or m.startswith('matplotlib.') for m in sys.modules))\n")
    scene_variant(tmp_path / "scene.toml", "four_arm_joint_space", **SHORT)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600, check=True)
    written, imported = done.stdout.splitlines()[-2:]
    assert written.split() == ["telemetry.npz", "scene.toml", "summary.json", "joint_errors.png", "torques.png",
                               "com_drift.png"]
    assert imported == "False"
    assert all((tmp_path / "out" / name).stat().st_size > 0 for name in written.split())


def test_figures_that_do_not_pickle_are_drawn_in_the_run_s_process(tmp_path):
    """An outcome whose figures are a closure (no job the helper can take) still gets them,
    with the stage named as drawn here."""
    scene = _short(tmp_path)
    outcome = runner.simulate(scene)
    job = outcome.figures
    outcome = dataclasses.replace(outcome, figures=lambda into: job(into))
    stages: list[str] = []
    with RunFolder(tmp_path / "out") as folder:
        written, skipped = write_run(folder, scene, outcome, stage=stages.append)
    assert [p.name for p in written][3:] == ["joint_errors.png", "torques.png", "com_drift.png"] and not skipped
    assert stages == ["data", "figures"]


def test_an_interrupt_while_the_helper_draws_drops_the_figures_and_the_next_run_draws(tmp_path):
    """A second Ctrl-C (``interrupted()`` true) once the job is sent: no figure is placed, none is
    left half-made, the figures are listed as skipped; the next run's helper draws them."""
    scene = _short(tmp_path)
    outcome = runner.simulate(scene)
    calls = iter([False, True])  # sent, then interrupted at the figures' stage
    with RunFolder(tmp_path / "stopped") as folder:
        written, skipped = write_run(folder, scene, outcome, interrupted=lambda: next(calls, True))
    assert skipped == ["figures"] and not [p for p in written if p.suffix == ".png"]
    assert not list((tmp_path / "stopped").glob("*.png")) and not list((tmp_path / "stopped").glob(".*/*.png"))
    with RunFolder(tmp_path / "again") as folder:
        written, skipped = write_run(folder, scene, outcome)
    assert not skipped and [p.name for p in written if p.suffix == ".png"] == ["joint_errors.png", "torques.png",
                                                                               "com_drift.png"]
    assert rendering._helper is not None and rendering._helper.poll() is None


def test_quiet_scene_runs_draw_nothing(tmp_path):
    """A scene without figures starts no job (nothing sent, no private folder left)."""
    scene = quiet_scene(tmp_path, simulation={"duration": 0.02})
    with RunFolder(tmp_path / "out") as folder:
        written, skipped = write_run(folder, scene, runner.simulate(scene))
    assert [p.name for p in written] == ["telemetry.npz", "scene.toml", "summary.json"] and not skipped


def test_a_job_too_large_for_the_helper_is_drawn_here(tmp_path, monkeypatch):
    """Above the size limit the figures are drawn in the run's process, the same files."""
    from freefloat.app import outputs

    monkeypatch.setattr(outputs, "JOB_BYTES", 1000)
    scene = _short(tmp_path)
    stages: list[str] = []
    with RunFolder(tmp_path / "out") as folder:
        written, _ = write_run(folder, scene, runner.simulate(scene), stage=stages.append)
    assert stages == ["data", "figures"] and [p.name for p in written][3:] == ["joint_errors.png", "torques.png",
                                                                               "com_drift.png"]
