"""A batch's runs many at a time in one compiled call (freefloat.app.batch.compiled_runs): the
rows are run_one's for the same plans, which runs can share a call, and Ctrl-C keeps the
finished rows."""

from __future__ import annotations

import warnings

import pytest

from freefloat.app import runner
from freefloat.app.batch import compiled_runs
from freefloat.app.batch.bands import Band
from freefloat.app.batch.one_run import TIMINGS, run_one
from freefloat.app.batch.variations import plan_runs
from freefloat.app.scenes import load_scene
from freefloat.dynamics import stop_request

from .conftest import scene_variant


def plans_of(tmp_path, builtin: str, bands: list[Band], runs: int, **simulation):
    scene = load_scene(scene_variant(tmp_path / "s.toml", builtin, simulation=simulation,
                                     output={"figures": False, "html": False}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return plan_runs(scene, runner.prepare(scene), bands, runs, seed=3)


def without_timings(row: dict) -> dict:
    return {k: v for k, v in row.items() if k not in TIMINGS}


@pytest.mark.parametrize("lockstep", [False, None])
@pytest.mark.parametrize("builtin, bands", [
    ("tumbling", [Band("joint_rate", 2.0), Band("base_rate", 1.0)]),
    ("tumbling", [Band("joint_rate", 2.0), Band("mass", 0.1)]),  # each run its own plant
    ("four_arm_joint_space", [Band("joint_angle", 5.0)]),  # computed torque: each run's own quintic
    ("four_arm_joint_space", [Band("mass", 0.2)]),  # computed torque on the nominal robot, plants varied
])
def test_rows_are_those_of_each_run_alone(tmp_path, monkeypatch, builtin, bands, lockstep):
    """Eleven runs on two threads, in groups of a call each (two groups and a part), one loop per
    thread or in lockstep (the default): every row equals run_one's for its plan, timings aside."""
    plans = plans_of(tmp_path, builtin, bands, 11, duration=0.05)
    rows: list[dict] = []
    monkeypatch.setattr(compiled_runs, "GROUP_PER_THREAD", 3)
    monkeypatch.setattr(compiled_runs, "LOCKSTEP", lockstep)
    compiled_runs.run_in_groups(plans, 2, rows.append)
    assert sorted(r["run"] for r in rows) == list(range(11))
    alone = {plan.index: run_one(plan) for plan in plans}
    for row in rows:
        assert row["status"] == "completed" and row["loop"] == "compiled"
        assert without_timings(row) == without_timings(alone[row["run"]])


def test_what_shares_a_call(tmp_path):
    """Varied masses under computed torque (the controller on the nominal robot, its compiled law on
    that robot's model), varied angles, varied masses torque-free: each batch shares calls; a
    momentum-projecting integrator (not compiled) does not."""
    assert compiled_runs.can_run(plans_of(tmp_path, "four_arm_joint_space", [Band("mass", 0.1)], 2, duration=0.01))
    assert compiled_runs.can_run(plans_of(tmp_path, "four_arm_joint_space", [Band("joint_angle", 1.0)], 2,
                                          duration=0.01))
    assert compiled_runs.can_run(plans_of(tmp_path, "tumbling", [Band("mass", 0.1)], 2, duration=0.01))
    assert not compiled_runs.can_run(plans_of(tmp_path, "tumbling", [Band("mass", 0.1)], 2, duration=0.01,
                                              project_momentum=True))


def test_an_interrupt_gives_the_finished_rows_and_propagates(tmp_path):
    """A stop request (what Ctrl-C does to runs off the main thread) during 20 s runs: the batch
    raises KeyboardInterrupt, and every row it gave is a completed run's."""
    plans = plans_of(tmp_path, "tumbling", [Band("joint_rate", 1.0)], 6, duration=20.0)
    rows: list[dict] = []
    with stop_request.stopping(), pytest.raises(KeyboardInterrupt):
        compiled_runs.run_in_groups(plans, 2, rows.append)
    assert all(row["status"] == "completed" for row in rows)


def test_an_error_keeping_a_row_stops_the_groups_and_propagates(tmp_path, monkeypatch):
    """Keeping the first row fails (a full disk): the error propagates at once, and of the three
    groups of 40 runs no more than the running one and the one prepared beside it were started."""
    plans = plans_of(tmp_path, "tumbling", [Band("joint_rate", 1.0)], 40, duration=1.0)
    started = []
    start_runs = compiled_runs.start_runs
    monkeypatch.setattr(compiled_runs, "start_runs", lambda *a, **k: started.append(1) or start_runs(*a, **k))

    def full(row: dict) -> None:
        raise OSError("No space left on device")

    with pytest.raises(OSError, match="No space left"):
        compiled_runs.run_in_groups(plans, 2, full)
    assert len(started) <= 2
