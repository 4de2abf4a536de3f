"""One run of a batch: the varied plant, the flat row, and a failure kept as a row."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

from freefloat.app import runner
from freefloat.app.batch.bands import Band
from freefloat.app.batch.one_run import flatten, run_one, with_plant_masses
from freefloat.app.batch.variations import plan_runs
from freefloat.app.scenes import load_scene

from .conftest import leak_momentum, scene_variant


@pytest.fixture
def short_task(tmp_path):
    """The default task (computed torque), 0.05 s, no drawings."""
    return load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.05},
                                    output={"figures": False, "html": False}))


def prepared(scene):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return runner.prepare(scene)


def test_the_plant_gets_the_scaled_bodies_and_the_controller_keeps_the_nominal(short_task):
    """Each body's mass and inertia are scaled by its factor about an unchanged CoM (Pinocchio's
    CRBA of the plant changes by those factors); the controller's model does not change."""
    setup = prepared(short_task)
    nominal = setup.robot.model
    factors = {name: 1.0 + 0.01 * j for j, name in enumerate(nominal.names) if j > 0}
    controller_model = setup.controller.dynamics.model.model  # the controller's ExactModel's pin.Model
    with_plant_masses(setup, factors)
    plant = setup.robot.model
    for j in range(1, nominal.njoints):
        f = factors[nominal.names[j]]
        assert plant.inertias[j].mass == pytest.approx(f * nominal.inertias[j].mass, rel=1e-14)
        np.testing.assert_allclose(plant.inertias[j].lever, nominal.inertias[j].lever, rtol=0, atol=0)
        np.testing.assert_allclose(plant.inertias[j].inertia, f * nominal.inertias[j].inertia, rtol=1e-14)
    assert pin.computeTotalMass(plant) == pytest.approx(sum(factors[nominal.names[j]] * nominal.inertias[j].mass
                                                            for j in range(1, nominal.njoints)), rel=1e-14)
    assert setup.model.model is plant and setup.controller.dynamics.model.model is controller_model is nominal


def test_a_varied_mass_changes_the_run_but_not_its_momentum_conservation(short_task):
    """With the plant 20 % off, the tracking differs from the nominal run while momentum is still
    conserved (the summary uses the plant's masses)."""
    nominal = prepared(short_task)
    same, varied = (plan_runs(short_task, nominal, bands, 1, seed=2)[0] for bands in ([], [Band("mass", 0.2)]))
    a, b = run_one(same), run_one(varied)
    assert a["status"] == b["status"] == "completed"
    assert a["tracking_rms_overall"] != b["tracking_rms_overall"]
    assert b["momentum_drift_max"] < 1e-10


def test_a_run_that_raises_is_a_failed_row(short_task, monkeypatch):
    """An error in a run becomes its row's status and message, with the drawn values kept."""
    from freefloat.app.batch import one_run

    plan = plan_runs(short_task, prepared(short_task), [Band("joint_rate", 1.0)], 1, seed=0)[0]

    def broken(scene):
        raise ValueError("no such thing")

    monkeypatch.setattr(one_run, "experiment_for", broken)
    row = run_one(plan)
    assert row["status"] == "failed" and row["message"] == "ValueError: no such thing"
    assert row["initial.joint_velocities.arm1_joint1"] == plan.varied["initial.joint_velocities.arm1_joint1"]


def test_flatten_names_tables_and_lists():
    """Nested tables become key.sub, lists key[i], numpy scalars plain numbers."""
    flat = flatten({"a": 1.0, "b": [1, [2, 3]], "c": {"x": np.float64(2.5), "y": [4]}})
    assert flat == {"a": 1.0, "b[0]": 1, "b[1][0]": 2, "b[1][1]": 3, "c.x": 2.5, "c.y[0]": 4}
    assert type(flat["c.x"]) is float


def test_a_worker_loads_its_robot_once_and_rows_do_not_depend_on_it(short_task, monkeypatch):
    """Runs of a batch in one process parse and check the robot's URDF once (again once
    forget_robots was called), and each row equals the row of the same run in a process that kept
    nothing (robots and compiled loops forgotten)."""
    from freefloat.app.batch import one_run
    from freefloat.dynamics import compiled
    from freefloat.robot import loading

    plans = plan_runs(short_task, prepared(short_task), [Band("joint_rate", 2.0), Band("mass", 0.1)], 3, seed=5)
    one_run.ROBOTS.clear()
    compiled.clear_loops()
    fresh = []
    for plan in plans:
        one_run.forget_robots()
        compiled.clear_loops()
        fresh.append(run_one(plan))
    parsed = []
    original = loading._load
    monkeypatch.setattr(loading, "_load", lambda *args: parsed.append(1) or original(*args))
    one_run.ROBOTS.clear()
    kept = [run_one(plan) for plan in plans]
    assert len(parsed) == 1
    timings = set(one_run.TIMINGS)
    assert [{k: v for k, v in r.items() if k not in timings} for r in kept] == \
           [{k: v for k, v in r.items() if k not in timings} for r in fresh]
    assert all(r["status"] == "completed" for r in kept)
    one_run.forget_robots()
    run_one(plans[0])
    assert len(parsed) == 2


def test_a_remembered_robot_is_a_copy_with_the_same_warnings(tmp_path):
    """Within remembered_loads a second load of an unchanged file gives an equal robot with its own
    pin.Model and the same warnings; a changed file is loaded again."""
    from freefloat.paths import URDF_DIR
    from freefloat.robot.loading import load_robot, remembered_loads

    store: dict = {}
    with remembered_loads(store), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        first = load_robot(URDF_DIR / "four_arm_planar.urdf", visuals=False)
        n_first = len(caught)
        second = load_robot(URDF_DIR / "four_arm_planar.urdf", visuals=False)
    assert n_first > 0 and [str(w.message) for w in caught[n_first:]] == [str(w.message) for w in caught[:n_first]]
    assert second.model is not first.model and second.model == first.model
    assert second.end_effectors == first.end_effectors and len(store) == 1
    copy = tmp_path / "robot.urdf"
    copy.write_text((URDF_DIR / "two_arm_planar.urdf").read_text())
    with remembered_loads(store), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        load_robot(copy, visuals=False)
        copy.write_text(copy.read_text() + "\n")
        load_robot(copy, visuals=False)
    assert len(store) == 3


def test_the_quiet_section_holds_until_the_last_thread_leaves_and_restores_the_filters():
    """Thread A enters the quiet section, B enters, A leaves: B's warnings are still ignored;
    once B leaves, the filters are exactly what they were (warnings.catch_warnings per thread
    restored A's copy under B, and left B's filters behind after the batch)."""
    import threading

    from freefloat.app.batch.one_run import QUIET

    before = list(warnings.filters)
    steps = [threading.Event() for _ in range(3)]
    caught: list[int] = []

    def a() -> None:
        with QUIET:
            steps[0].set()
            assert steps[1].wait(10)
        steps[2].set()

    def b() -> None:
        assert steps[0].wait(10)
        with QUIET:
            steps[1].set()
            assert steps[2].wait(10)
            with warnings.catch_warnings(record=True) as seen:  # records what the filters let through
                warnings.warn("should be ignored", UserWarning)
            caught.append(len(seen))

    threads = [threading.Thread(target=a), threading.Thread(target=b)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(20)
    assert caught == [0] and warnings.filters == before


def test_a_run_that_breaks_its_conservation_law_is_a_failed_row(short_task, monkeypatch):
    """A run whose recorded momentum gains a spurious 1e-3 N m torque's impulse is a failed row
    naming momentum_drift_max, as ``freefloat simulate`` fails it (one check for both)."""
    plan = plan_runs(short_task, prepared(short_task), [Band("joint_rate", 1.0)], 1, seed=0)[0]
    assert run_one(plan)["status"] == "completed"
    leak_momentum(monkeypatch)
    row = run_one(plan)
    assert row["status"] == "failed" and row["message"].startswith("conservation violated: momentum_drift_max")
