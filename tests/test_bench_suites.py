"""``freefloat bench --suite NAME``: the registry of suites, the command that reads it, and each
suite's quick run (its JSON's numbers agree with one another; speed itself is never asserted)."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest

from freefloat.app.cli import main
from freefloat.app.run_folder import RECORD
from freefloat.lab.bench.options import SMOKE
from freefloat.lab.bench.suites import ALL, DEFAULT, SUITES, Suite, named
from freefloat.lab.bench.suites.growth import exponent
from freefloat.lab.bench.suites.locking import SCENES as LOCKING_SCENES
from freefloat.lab.bench.suites.robots import robot_names

from . import toy_suite

#: The suites measured in parts (``bench_<name>.json``); the default one writes bench.json.
PARTS_SUITES = [name for name, suite in SUITES.items() if not suite.takes_scenes]
TOY = Suite("toy", "a toy suite of tests/toy_suite.py", "tests.toy_suite")


@pytest.fixture
def toy(monkeypatch):
    """The toy suite registered as ``toy``."""
    monkeypatch.setitem(SUITES, "toy", TOY)


def test_registry_lists_exactly_the_suites():
    """The registry holds the MuJoCo scenes, the eight former scripts, the platform laws', the
    fixed-cost suite, the two-hand capture's, the atlas's, the batch against mujoco.rollout and the
    dynamics kernel's, in the order ``all`` runs them."""
    assert list(SUITES) == [DEFAULT, "simulation", "integrators", "gjm", "models", "locking", "parallel", "laws", "batch",
                            "figures", "setup", "two_hands", "atlas", "rollout", "kernel"]


def test_help_lists_every_registered_suite(toy, capsys):
    """``freefloat bench --help`` names each suite with its help line, read from the registry."""
    with pytest.raises(SystemExit):
        main(["bench", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert all(f"{name}: {' '.join(suite.help.split())}" in text for name, suite in SUITES.items())
    assert "toy: a toy suite of tests/toy_suite.py" in text


def test_unknown_suite_exits_2_naming_the_valid_ones(toy, tmp_path, capsys):
    """An unknown suite is refused before any folder is made, the message listing the registry's names."""
    assert main(["bench", "--suite", "nope", "--out", str(tmp_path / "o")]) == 2
    valid = ", ".join([*SUITES, ALL])
    assert f"unknown bench suite 'nope'; valid: {valid}" in capsys.readouterr().err
    assert main(["bench", "--suite", "simulaton", "--out", str(tmp_path / "o")]) == 2
    assert "unknown bench suite 'simulaton'; did you mean 'simulation'?" in capsys.readouterr().err
    assert "toy" in valid and not (tmp_path / "o").exists()


def test_all_names_every_suite_once():
    """``all`` (with a suite named again) is every suite of the registry, each once, in its order."""
    assert named(["gjm", ALL]) == [SUITES["gjm"], *(s for n, s in SUITES.items() if n != "gjm")]


def test_a_registered_toy_suite_runs_with_no_other_edit(toy, tmp_path):
    """``freefloat bench --suite toy`` writes bench_toy.json (parts, settings, versions, status) and its chart."""
    assert main(["bench", "--suite", "toy", "--repeats", "2", "--out", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "bench_toy.json").read_text())
    assert report["status"] == "completed" and report["settings"] == {"quick": False, "repeats": 2}
    assert report["first"]["a_over_b"] == 4.0 and "second" in report and "freefloat" in report["versions"]
    assert toy_suite.DRAWN == ["first", "second"] and (tmp_path / "bench_toy.png").read_bytes()[1:4] == b"PNG"
    assert "smoke_test" not in report


def test_a_suite_without_a_summary_prints_its_ratios(toy, tmp_path, capsys):
    """A suite with no summary() of its own prints each part's ratios (it printed no number)."""
    assert main(["bench", "--suite", "toy", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "toy: first: a_over_b 4\n" in out and "toy: second: a_over_b 4\n" in out


def test_a_quick_suite_says_it_is_a_smoke_test(toy, tmp_path, capsys):
    """--quick: the printed lines, the JSON and the chart (a band above it) say it is a smoke test."""
    import matplotlib.pyplot as plt

    assert main(["bench", "--suite", "toy", "--quick", "--out", str(tmp_path)]) == 0
    assert f"toy: {SMOKE}" in capsys.readouterr().out
    assert json.loads((tmp_path / "bench_toy.json").read_text())["smoke_test"] == SMOKE
    chart = plt.imread(tmp_path / "bench_toy.png")
    assert chart.shape[0] == 240 + 28 and chart[2, chart.shape[1] // 2, 0] > 0.6 > chart[2, chart.shape[1] // 2, 1]


def test_a_suite_without_mujoco_runs_when_mujoco_is_missing(toy, tmp_path, monkeypatch):
    """With MuJoCo not importable, a suite that does not need it still runs."""
    monkeypatch.setitem(sys.modules, "mujoco", None)
    assert main(["bench", "--suite", "toy", "--out", str(tmp_path)]) == 0


def test_the_mujoco_suite_refuses_to_start_without_mujoco(tmp_path, monkeypatch, capsys):
    """Without MuJoCo the default suite exits 2 naming the extra to install, before any folder is made."""
    monkeypatch.setitem(sys.modules, "mujoco", None)
    assert main(["bench", "--quick", "--out", str(tmp_path / "o")]) == 2
    assert f'the bench suite {DEFAULT} needs mujoco: python3 -m pip install -e ".[bench]"' in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_scenes_without_the_mujoco_suite_are_refused(toy, tmp_path, capsys):
    """Scenes given to suites that take none exit 2 (they belong to the default suite)."""
    assert main(["bench", "four_arm", "--suite", "toy", "--out", str(tmp_path / "o")]) == 2
    assert f"belong to the {DEFAULT} suite" in capsys.readouterr().err


def test_sigterm_keeps_the_parts_measured(toy, tmp_path, monkeypatch):
    """SIGTERM in a suite's second part: exit 1, its JSON holds the first part and says where it
    stopped, and no chart is drawn from half a report."""
    monkeypatch.setattr(toy_suite, "INTERRUPT_AT", "second")
    assert main(["bench", "--suite", "toy", "--out", str(tmp_path)]) == 1
    report = json.loads((tmp_path / "bench_toy.json").read_text())
    assert report["status"] == "interrupted (SIGTERM) after 1 parts: first; no chart"
    assert "first" in report and "second" not in report and not (tmp_path / "bench_toy.png").exists()


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """``run(name)``: ``freefloat bench --suite NAME --quick`` once per suite; its exit status,
    folder and report."""
    done = {}

    def run(name: str):
        if name not in done:
            out = tmp_path_factory.mktemp(name) / "out"
            status = main(["bench", "--suite", name, "--quick", "--out", str(out)])
            done[name] = status, out, json.loads((out / f"bench_{name}.json").read_text())
        return done[name]

    return run


def _values(value, key=""):
    """Every ``(key, leaf)`` of a JSON value."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _values(v, k)
    elif isinstance(value, list):
        for v in value:
            yield from _values(v, key)
    else:
        yield key, value


@pytest.mark.slow
@pytest.mark.parametrize("name", PARTS_SUITES)
def test_quick_suite_writes_its_json_and_chart(quick, name):
    """Exit 0, a completed report with settings and versions, its chart, and no other file."""
    status, out, report = quick(name)
    assert status == 0 and report["status"] == "completed"
    assert report["settings"] and report["versions"]["pin"]
    assert {p.name for p in out.iterdir()} == {f"bench_{name}.json", f"bench_{name}.png", RECORD}


@pytest.mark.slow
@pytest.mark.parametrize("name", PARTS_SUITES)
def test_quick_suite_numbers_are_finite(quick, name):
    """Every number is finite; the only nulls are accuracy bands no method reached."""
    _, _, report = quick(name)
    for key, value in _values(report):
        assert value is not None or key in ("fastest", "lead"), key
        assert not isinstance(value, float) or math.isfinite(value), key


def _simulation(r):
    best = r["loop_overhead"]["seconds_per_step_best"]
    assert r["loop_overhead"]["python_over_compiled_full_telemetry"] == pytest.approx(best["python_full"] / best["compiled_full"])
    assert r["base_kind"]["ratio_free_over_planar"] == pytest.approx(
        r["base_kind"]["free"]["seconds_per_step_best"] / r["base_kind"]["planar"]["seconds_per_step_best"])
    walls = r["detumbling"]["wall_s_best"]
    assert r["detumbling"]["per_period_over_whole_chunks"] == pytest.approx(
        walls["compiled_per_period"] / walls["compiled_whole_chunks"])
    for row in r["convention"].values():
        step = row["seconds_per_step"]
        assert row["world_over_local"] == pytest.approx(step["world"] / step["local"])
        assert row["state_difference"] < 1e-12  # the same run to round-off


def _integrators(r):
    for robot in r["settings"]["robots"]:
        wp = r[f"{robot} work precision"]
        errors = [p["state_error"] for p in sorted(wp["points"], key=lambda p: -p["setting"])
                  if p["integrator"] == "rkmk4"]
        assert wp["observed_orders"]["freefloat rkmk4"] == pytest.approx(
            [math.log2(a / b) for a, b in zip(errors, errors[1:])])
        band = wp["bands"]["1e-03"]
        seconds = list(band["seconds"].values())
        assert band["fastest"] == min(band["seconds"], key=band["seconds"].get)
        assert band["lead"] == pytest.approx(seconds[1] / seconds[0])
        cost = r[f"{robot} cost per step"]
        assert cost["time_ratio_to_rkmk4"]["rkmk8"] == pytest.approx(
            cost["seconds_per_step"]["rkmk8"] / cost["seconds_per_step"]["rkmk4"])


def _gjm(r):
    for row in (r[name] for name in robot_names(r["settings"]["arm_counts"])):
        t = row["seconds_per_call"]
        assert row["ratios"]["compiled_over_pinocchio_calls"] == pytest.approx(t["compiled"] / t["pinocchio_calls"])
    arms = [r[name] for name in robot_names(r["settings"]["arm_counts"]) if name.startswith("arms")]
    assert r["growth"]["compiled"] == pytest.approx(
        exponent([row["n_joints"] + 6 for row in arms], [row["seconds_per_call"]["compiled"] for row in arms]))


def _models(r):
    for row in (r[name] for name in robot_names(r["settings"]["arm_counts"])):
        assert row["compiled_over_aba"] == pytest.approx({k: t / row["aba_s"] for k, t in row["compiled_s"].items()})
    arms = [r[name] for name in robot_names(r["settings"]["arm_counts"]) if name.startswith("arms")]
    assert r["growth"]["time"]["reduced"] == pytest.approx(
        exponent([row["n_joints"] + 6 for row in arms], [row["compiled_s"]["reduced"] for row in arms]))


def _locking(r):
    for row in (r[label] for label, _, _ in LOCKING_SCENES):
        assert row["locked_loop_speedup"] == pytest.approx(row["loop_s"]["unlocked"] / row["loop_s"]["locked"])
        assert row["auto_total_over_exact_total"] == pytest.approx(row["total_s"]["auto"] / row["total_s"]["unlocked"])


def _parallel(r):
    for name in ("five_bar", "rsu_ppap"):
        f, inv = r[name]["forward"], r[name]["inverse_compiled"]
        assert f["compiled_over_pinocchio"] == pytest.approx(f["compiled_s"] / f["pinocchio_s"])
        assert inv["trajectory_over_loop"] == pytest.approx(inv["trajectory_points_per_s"] / inv["loop_points_per_s"])
    assert [row["turns"] for row in r["coarse_paths"]] == [1, 2, 4, 8]


def _laws(r):
    from freefloat.parallel.five_bar import FiveBarParameters
    from freefloat.parallel.platform_regressor import five_bar_theta

    cost = r["cost"]
    assert cost["over_computed_torque"] == pytest.approx({k: v / cost["seconds_per_call"]["computed_torque"]
                                                          for k, v in cost["seconds_per_call"].items()})
    for plant in ("15", "50"):
        runs = r[f"tracking_{plant}"]
        for law in runs.values():  # the last turn lies after 0.2 s
            assert max(law["steady_error_max_m"]) <= max(law["error_max_after_0.2s_m"])
        adaptive = runs["adaptive_sliding_mode"]
        assert adaptive["estimate_over_true"][0] == pytest.approx(
            list(five_bar_theta(FiveBarParameters()) / adaptive["true"]))
        assert adaptive["lyapunov_largest_rise"] == pytest.approx(max(np.diff(adaptive["lyapunov"])))


def _batch(r):
    for name in r["settings"]["scenes"]:
        row = r[name]
        assert row["best_s"] == {k: min(t) for k, t in row["times_s"].items()}
        assert row["runs_per_second"] == pytest.approx({k: row["runs"] / t for k, t in row["best_s"].items()})


def _figures(r):
    t = r["figures"]
    for key in ("default_png", "all_png", "all_png_pdf"):
        assert t[f"{key}_over_simulation"] == pytest.approx(t[f"{key}_s"] / t["simulation_s"])


def _setup(r):
    for arms in r["settings"]["arm_counts"]:
        row = r[f"nv{6 + 4 * arms}"]
        assert row["best_s"] == {"new_loop": min(row["fixed_s"]["new_loop"]), "kept_loop": min(row["fixed_s"]["kept_loop"]),
                                 "loop_1s": min(row["loop_1s_s"])}
        assert row["fixed_over_loop"]["kept_loop"] == pytest.approx(row["best_s"]["kept_loop"] / row["best_s"]["loop_1s"])
    for name in r["settings"]["scenes"]:
        row = r[name]
        assert row["rows_identical"] and row["completed"] == row["runs"]
        assert row["reused_over_fresh"] == pytest.approx(row["best_s"]["fresh"] / row["best_s"]["reused"])


def _two_hands(r):
    part = r["post_grasp"]
    per_second = {k: min(t) / r["settings"]["duration_s"] for k, t in part["times_s"].items()}
    assert part["per_simulated_second_s"] == pytest.approx(per_second)
    assert part["two_hands_over_one_hand"] == pytest.approx(per_second["two_hands compiled"] / per_second["one_hand compiled"])
    assert part["python_over_compiled"] == pytest.approx(per_second["two_hands python"] / per_second["two_hands compiled"])
    assert part["loop"] == {"two_hands python": "python", "two_hands compiled": "compiled", "one_hand compiled": "compiled"}
    assert set(part["status"].values()) == {"completed"} and part["final_state_difference"] < 1e-10


def _atlas(r):
    part, points = r["evaluate"], r["settings"]["grid"] ** 2
    assert part["points"] == r["command"]["points"] == points
    assert part["evaluate_over_gjm_compute"] == pytest.approx(part["seconds"]["evaluate"] / part["seconds"]["gjm_compute"])
    assert part["per_point_us"] == pytest.approx({k: t / points * 1e6 for k, t in part["seconds"].items()})
    assert r["command"]["serial"]["singular_share_free"] == r["command"]["pool_of_2"]["singular_share_free"]


def _rollout(r):
    row, threads = r["tumbling"], r["settings"]["threads"]
    assert row["best_s"] == {k: min(t) for k, t in row["times_s"].items()}
    rate = row["runs_per_second"]
    for k in threads:
        assert row["per_core_over_mujoco"][f"freefloat loop, {k}"] == pytest.approx(
            rate[f"freefloat loop, {k}"] / rate[f"mujoco.rollout, {k}"])
    assert row["scaling_per_repeat"]["mujoco.rollout"] == pytest.approx(
        [a / b for a, b in zip(row["times_s"]["mujoco.rollout, 1"], row["times_s"]["mujoco.rollout, 2"])])
    assert row["rows_identical"] and row["completed"] == row["runs"]
    assert row["final_position_and_joints_difference"] < 1e-6  # RKMK4 and RK4 at 1 ms on a slow tumble
    assert row["run_many_equals_loop"]  # the compiled batch's run 0 ends where simulation.run's does


def _kernel(r):
    names = robot_names(r["settings"]["arm_counts"])
    for name in names:
        row = r[f"evaluation/{name}"]
        assert row["over_pinocchio"] == pytest.approx({k: t / row["seconds"]["pinocchio"] for k, t in row["seconds"].items()})
        step, calls = r[f"step/{name}"], r[f"step/{name}"]["lockstep_calls"]
        assert step["over_mujoco"]["loop kernel"] == pytest.approx(step["seconds"]["loop kernel"] / step["seconds"]["mujoco rk4"])
        assert step["seconds"]["lockstep"] == pytest.approx(
            (calls["seconds"] - calls["one_step_seconds"]) / ((calls["periods"] - 1) * r["settings"]["lanes"]))
        for runs in r["settings"]["batches"]:
            batch = r[f"batch/{name}"][str(runs)]
            assert batch["runs_per_second"] == pytest.approx({k: runs / t for k, t in batch["seconds"].items()})
            assert batch["over_rollout"]["lockstep"] == pytest.approx(
                batch["runs_per_second"]["lockstep"] / batch["runs_per_second"]["mujoco.rollout"])


#: Per suite, what its numbers must agree on (a new suite needs a check).
CHECKS = {"simulation": _simulation, "integrators": _integrators, "gjm": _gjm, "models": _models,
          "locking": _locking, "parallel": _parallel, "laws": _laws, "batch": _batch, "figures": _figures, "setup": _setup,
          "two_hands": _two_hands, "atlas": _atlas, "rollout": _rollout, "kernel": _kernel}


@pytest.mark.slow
@pytest.mark.parametrize("name", PARTS_SUITES)
def test_quick_suite_numbers_agree(quick, name):
    """Each ratio the suite reports is the quotient of the two times it reports (and likewise)."""
    assert name in CHECKS, f"add a check of the {name} suite's numbers to CHECKS"
    CHECKS[name](quick(name)[2])


@pytest.mark.slow
def test_mujoco_suite_runs_its_scenes_through_suite(tmp_path):
    """``freefloat bench dual_arm --suite mujoco --quick`` writes bench.json whose speed-ups are
    freefloat's time over MuJoCo's in each band."""
    assert main(["bench", "dual_arm", "--suite", DEFAULT, "--quick", "--out", str(tmp_path)]) == 0
    bands = json.loads((tmp_path / "bench.json").read_text())["scenes"]["dual_arm"]["bands"]
    reached = [b for b in bands if b["mujoco_speedup"] is not None]
    assert reached and all(b["mujoco_speedup"] == pytest.approx(b["freefloat"]["wall_time"] / b["mujoco"]["wall_time"])
                           for b in reached)


@pytest.mark.slow
def test_the_simulation_suite_prints_its_headline_ratios(quick):
    """``--suite simulation`` prints its headline ratios, one line per part, as measured (it
    printed no number)."""
    from freefloat.lab.bench.suites import simulation

    _, _, report = quick("simulation")
    lines = simulation.summary(report)
    assert len(lines) == 4 and all(line.startswith("simulation: ") for line in lines)
    assert f"{report['loop_overhead']['compiled_over_cpp_floor_full_telemetry']:.3g}x the C++ floor" in lines[0]
    assert lines[1].endswith(f"{report['base_kind']['ratio_free_over_planar']:.3g}")
    assert f"{report['detumbling']['python_over_whole_chunks']:.3g}x whole compiled chunks" in lines[2]
    assert all(f"nv {r['nv']} {r['world_over_local']:.3g}" in lines[3] for r in report["convention"].values())
