"""``simulation.model = "auto"`` (freefloat.app.experiments.model_choice): the plant chosen by a pilot."""

from __future__ import annotations

import json

import pytest

from freefloat.app import runner
from freefloat.app.experiments import experiment_for
from freefloat.app.experiments.model_choice import describe, pilot_periods, resolve, with_plant
from freefloat.app.scenes import load_scene
from freefloat.dynamics.models.selection import Candidate, Pilot, choose
from freefloat.errors import SceneError

from .conftest import ONE_ARM_TASK, quiet_scene


def test_auto_is_the_default_plant(tmp_path):
    """A scene that names no plant model gets ``model = "auto"`` with a 1e-6 tolerance."""
    path = tmp_path / "s.toml"
    path.write_text('name = "s"\n[robot]\nurdf = "four_arm_planar.urdf"\n')
    sim = load_scene(path).simulation
    assert (sim.model, sim.tolerance) == ("auto", 1e-6)


def test_auto_locks_the_held_arms_when_the_error_stays_under_the_tolerance(tmp_path):
    """With three arms held still, the locked exact plant's predicted error is under the tolerance, and the
    pilot keeps it exactly when its pilot also ran faster (wall times on a shared machine decide that part,
    so the test checks the rule, not the clock)."""
    auto = quiet_scene(tmp_path, task=ONE_ARM_TASK, simulation={"duration": 1.0, "model": "auto", "tolerance": 1e-4})
    resolved, record = resolve(auto)
    locked = next(t for t in record["trials"] if t["lock"] == "auto" and t["model"] == "exact")
    full = record["trials"][0]
    assert 0.0 < locked["predicted_error"] <= 1e-4 and record["pilot_duration"] == pytest.approx(0.02)
    faster = locked["pilot_wall_time_s"] < full["pilot_wall_time_s"]
    assert ((resolved.simulation.model, resolved.simulation.lock) == ("exact", "auto")) == faster


@pytest.mark.slow
def test_a_tolerance_below_the_locking_error_keeps_the_full_plant(tmp_path):
    """With a 1e-12 tolerance the locked plant's pilot error is too large, and the full exact plant is kept."""
    tight = quiet_scene(tmp_path, task=ONE_ARM_TASK, simulation={"duration": 1.0, "model": "auto", "tolerance": 1e-12})
    resolved, record = resolve(tight)
    assert (resolved.simulation.model, resolved.simulation.lock) == ("exact", "none")
    locked = next(t for t in record["trials"] if t["lock"] == "auto" and t["model"] == "exact")
    assert locked["predicted_error"] > 1e-12 and not locked["accepted"]
    assert describe(record).startswith("exact: no plant cheaper per call kept the predicted state error under 1e-12")


def test_a_model_wrong_for_the_scene_is_refused_by_the_error_check(tmp_path):
    """On a tumbling robot with momentum, eq 127's model (exact only at zero momentum) is refused even when
    it is claimed far cheaper: its pilot error is far above the tolerance."""
    tumbling = quiet_scene(tmp_path, "tumbling", simulation={"duration": 1.0, "model": "auto"})
    experiment, duration = experiment_for(tumbling), pilot_periods(tumbling) * 1e-3

    def pilot(name):
        outcome = experiment.run(experiment.prepare(with_plant(tumbling, name, "none", duration)))
        return Pilot(outcome.wall_time_s / 10.0 if name != "exact" else outcome.wall_time_s, outcome.telemetry.q,
                     outcome.telemetry.v)

    full = experiment.prepare(with_plant(tumbling, "exact", "none"))
    choice = choose(Candidate("exact", "none", 1.0, lambda: pilot("exact")),
                    [Candidate("momentum_mono", "none", 0.01, lambda: pilot("momentum_mono"))],
                    full.robot.model, 1e-6, 400.0)
    assert choice.model == "exact" and choice.trials[1].predicted_error > 1e-3


def test_the_choice_is_written_to_the_summary(tmp_path):
    """A run with ``model = "auto"`` writes the choice, its speed-up and error into summary.json and prints it."""
    auto = quiet_scene(tmp_path, task=ONE_ARM_TASK, simulation={"duration": 0.2, "model": "auto", "tolerance": 1e-5})
    done = runner.simulate(auto, out=tmp_path / "out")
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["model_choice"]["model"] == "exact" and summary["model_choice"]["lock"] in ("none", "auto")
    # which line depends on the pilots' wall time (a cheaper plant may or may not pay): both name the tolerance
    assert summary["model_auto"].startswith("exact") and "1e-05" in summary["model_auto"]
    assert "model_auto" in done.headline  # the command line prints it


def test_a_choice_with_nothing_piloted_says_so():
    """When no other plant is cheaper per call, the line says none was piloted (it said "0
    piloted for 0.06 s"), and when none applies at all, that."""
    from freefloat.app.experiments.model_choice import describe

    record = {"model": "exact", "lock": "none", "tolerance": 1e-6, "pilot_duration": 0.06,
              "trials": [{"pilot_wall_time_s": None, "accepted": True}, {"pilot_wall_time_s": None, "accepted": False}]}
    assert describe(record) == "exact: none of the 1 other plants is cheaper per call here (none piloted)"
    assert describe({**record, "trials": record["trials"][:1]}) == "exact: no other plant applies (none piloted)"
    tried = {**record, "trials": [record["trials"][0], {"pilot_wall_time_s": 0.01, "accepted": False}]}
    assert describe(tried).endswith("under 1e-06 (1 piloted over the first 0.06 s)")


def test_capture_scenes_keep_the_exact_plant_without_a_pilot(tmp_path):
    """A capture scene's ``auto`` is the exact plant, with the reason recorded."""
    capture = quiet_scene(tmp_path, "capture_planar", simulation={"model": "auto"})
    resolved, record = resolve(capture)
    assert resolved.simulation.model == "exact" and "capture" in record["reason"]


def test_a_run_no_longer_than_its_pilot_keeps_the_prepared_exact_plant(tmp_path, monkeypatch):
    """A run of at most PILOT_PERIODS control periods gets the exact plant without a pilot (piloting
    would cost more than the run), and the runner keeps the setup it prepared instead of preparing
    the scene again."""
    short = quiet_scene(tmp_path, simulation={"duration": 0.01, "control_period": 1e-3, "model": "auto"})
    assert pilot_periods(short) == 10
    setup = runner.prepare(short)
    monkeypatch.setattr(runner, "experiment_for", lambda scene: pytest.fail("prepared twice"))
    chosen = runner.choose_plant(short, setup)
    assert chosen is setup and chosen.model_choice["reason"] == "the run is no longer than a pilot run"


def test_preparing_auto_outside_the_runner_is_refused_with_the_key(tmp_path):
    """An experiment asked to prepare ``model = "auto"`` directly names the key and the runner."""
    auto = quiet_scene(tmp_path, simulation={"duration": 0.05, "model": "auto"})
    with pytest.raises(SceneError, match="'simulation.model = \"auto\"' is chosen by a pilot run"):
        experiment_for(auto).prepare(auto)
