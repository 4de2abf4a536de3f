"""The default job end to end: ``freefloat simulate`` on the built-in chapter-4 scene."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from freefloat.app import shown_warnings
from freefloat.app.cli import main
from freefloat.app.progress_bar import LoopBar
from freefloat.app.run_folder import RECORD
from freefloat.app.scenes import DEFAULT_SCENE, builtin_scenes
from freefloat.dynamics.telemetry import Telemetry
from freefloat.paths import URDF_DIR

from .conftest import scene_variant, toml_text


@pytest.fixture(scope="module")
def default_run(tmp_path_factory):
    """Run ``freefloat simulate`` with no scene, as the README says, into a temporary folder."""
    out = tmp_path_factory.mktemp("run")
    status = main(["simulate", "--out", str(out), "--quiet"])
    return status, out, json.loads((out / "summary.json").read_text())


@pytest.mark.slow
def test_default_job_writes_every_artefact(default_run):
    """Telemetry, summary, scene, the default set's three figures and a self-contained HTML
    animation are written."""
    status, out, _ = default_run
    names = {p.name for p in out.iterdir() if p.name != RECORD}
    assert status == 0
    assert names == {"telemetry.npz", "summary.json", "scene.toml", "trajectory.html", "joint_errors.png",
                     "torques.png", "com_drift.png"}


@pytest.mark.slow
def test_default_job_imports_no_library_it_does_not_use(tmp_path):
    """The default job (figures and page included) leaves yourdfpy (its URDF is read by
    freefloat.robot.urdf_model), pinocchio.visualize with viser and trimesh (the page draws its
    primitives itself) and scipy (imported where a scene needs it) unimported: 1.1-1.6 s of CPU
    at start-up before."""
    unused = ("yourdfpy", "trimesh", "networkx", "viser", "pinocchio.visualize", "scipy")
    code = (f"import sys\nfrom freefloat.app.cli import main\nmain(['simulate', '--out', {str(tmp_path)!r}, '--quiet'])\n"
            f"print(sorted(m for m in {unused!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip().splitlines()[-1] == "[]"


@pytest.mark.slow
def test_end_effectors_start_on_the_axes(default_run):
    """End-effectors start at (7.75, 0), (0, 7.75), (-7.75, 0), (0, -7.75) m (dissertation Table 5)."""
    start = default_run[2]["end_effectors_start"]
    expected = [[7.75, 0, 0], [0, 7.75, 0], [-7.75, 0, 0], [0, -7.75, 0]]
    np.testing.assert_allclose([start[f"arm{i}_ee"] for i in range(1, 5)], expected, atol=1e-9)


@pytest.mark.slow
def test_system_com_stays_put(default_run):
    """The system CoM drifts less than 1e-8 m (no external force; 4th-order integrator)."""
    assert default_run[2]["com_drift_max"] < 1e-8


@pytest.mark.slow
def test_base_moves_along_the_negative_bisector_without_turning(default_run):
    """The base translates along (-x, -y) with equal components and negligible rotation."""
    dx, dy, dz = default_run[2]["base_displacement"]
    assert dx < -0.1 and abs(dx - dy) < 1e-9 * abs(dx) and dz == 0.0
    assert default_run[2]["base_rotation_max"] < 1e-10


@pytest.mark.slow
def test_tracking_is_at_least_as_good_as_the_dissertation(default_run):
    """Nested-RMS tracking error is at or below FM-NIC-A's 4.91e-7 rad (Table 1)."""
    assert default_run[2]["tracking_rms_overall"] <= 4.91e-7


@pytest.mark.slow
def test_energy_balances_the_joint_work(default_run):
    """Kinetic energy changes exactly by the work of the held joint torques."""
    assert default_run[2]["energy_drift_max"] < 1e-9


@pytest.mark.slow
def test_summary_records_provenance(default_run):
    """The summary holds the scene, versions and settings that made it."""
    summary = default_run[2]
    assert summary["scene"]["name"] == DEFAULT_SCENE
    assert {"pin", "numpy", "freefloat", "python"} <= set(summary["versions"])
    assert summary["settings"]["integrator"] == "rkmk4" and summary["steps"] == 5000


@pytest.mark.slow
def test_telemetry_has_every_step(default_run):
    """telemetry.npz has 5001 samples from 0 to 5 s with q, v, tau and references."""
    tel = Telemetry.load(default_run[1] / "telemetry.npz")
    assert tel.q.shape[0] == 5001 and tel.t[-1] == pytest.approx(5.0)
    assert np.isfinite(tel.joint_reference).all()


def test_diverging_scene_exits_1_and_keeps_its_samples(tmp_path):
    """A run that blows up exits with status 1, says so, and still writes its telemetry."""
    raw = tomllib.loads(builtin_scenes()[DEFAULT_SCENE].read_text())
    raw["robot"]["urdf"] = str(URDF_DIR / "four_arm_planar.urdf")
    raw["controller"] = {"kind": "none"}
    raw["task"] = {"kind": "none"}
    raw["initial"]["joint_velocities"] = {"arm1_ee": 3000.0}
    raw["simulation"].update(integrator="euler", control_period=0.05, duration=50.0)
    raw["output"] = {"html": False, "figures": False}
    scene = tmp_path / "bad.toml"
    scene.write_text(toml_text(raw))
    status = main(["simulate", str(scene), "--out", str(tmp_path / "out"), "--quiet"])
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert status == 1 and summary["status"] == "diverged"
    assert 0 < Telemetry.load(tmp_path / "out" / "telemetry.npz").t.size < 1001


def test_bad_scene_exits_2_naming_the_key(tmp_path, capsys):
    """A scene with an unknown key exits with status 2 and names the key."""
    scene = tmp_path / "bad.toml"
    scene.write_text('name = "x"\nspeed = 3\n[robot]\nurdf = "a.urdf"\n')
    assert main(["simulate", str(scene), "--out", str(tmp_path / "o")]) == 2
    assert "unknown top-level key 'speed'" in capsys.readouterr().err


@pytest.fixture(scope="module")
def mechanism_run(tmp_path_factory):
    """``freefloat simulate`` on the sliding-mode 5R scene shortened to 0.01 s (error after 5 ms)."""
    folder = tmp_path_factory.mktemp("mechanism")
    scene = scene_variant(folder / "five_bar.toml", "five_bar_sliding_mode", simulation={"duration": 0.01},
                          metrics={"reaching_phase": 0.005})
    status = main(["simulate", str(scene), "--out", str(folder / "out"), "--quiet"])
    return status, folder / "out", json.loads((folder / "out" / "summary.json").read_text())


@pytest.mark.slow
def test_mechanism_scene_writes_every_artefact(mechanism_run):
    """A mechanism scene writes telemetry, summary, scene, four figures and the HTML page; exit 0."""
    status, out, _ = mechanism_run
    assert status == 0
    assert {p.name for p in out.iterdir() if p.name != RECORD} == {"telemetry.npz", "summary.json", "scene.toml", "trajectory.html",
                                                "platform_tracking.png", "efforts.png", "loop_closure_drift.png",
                                                "sliding_variables.png"}


@pytest.mark.slow
def test_mechanism_summary_records_provenance(mechanism_run):
    """The summary holds the metrics, the mechanism, the scene, the settings and the versions."""
    summary = mechanism_run[2]
    assert summary["steps"] == 100 and summary["status"] == "completed"
    assert summary["mechanism"]["plant"] == "true_15" and summary["mechanism"]["joints"] == [
        "c1_joint1", "c1_joint2", "c2_joint1", "c2_joint2"]
    assert summary["scene"]["controller"]["kind"] == "sliding_mode" and summary["settings"]["integrator"] == "rk4"
    assert {"pin", "numpy", "freefloat"} <= set(summary["versions"])
    assert len(summary["tracking_error_max"]) == 2 and len(summary["peak_efforts"]) == 2


def test_mechanism_page_animates_the_5r_joints_where_orsino_puts_them(mechanism_run):
    """The page has a node per 5R joint; chain 1's elbow ends where Orsino's kinematics put it."""
    from freefloat.dynamics.telemetry import MechanismTelemetry
    from freefloat.parallel.five_bar import TRUE_PARAMETERS, chain

    from .pages import animation as _animation
    from .pages import packets as _packets

    out = mechanism_run[1]
    tracks = _animation(_packets(out / "trajectory.html"))
    joints = {path.rsplit("/", 1)[-1]: tr for path, tr in tracks.items()}
    assert {"c1_joint1", "c1_joint2", "c2_joint1", "c2_joint2"} <= set(joints)
    tel = MechanismTelemetry.load(out / "telemetry.npz")
    _, frames = chain(TRUE_PARAMETERS, +1).frames(tel.joints[-1, :2])
    np.testing.assert_allclose(joints["c1_joint2"][".position"][-1][1], frames[1][:3, 3], atol=1e-9)


def test_no_html_skips_the_mechanism_page(tmp_path):
    """--no-html writes no trajectory.html for a mechanism scene."""
    scene = scene_variant(tmp_path / "s.toml", "five_bar_computed_torque", simulation={"duration": 0.001},
                          output={"figures": False})
    assert main(["simulate", str(scene), "--out", str(tmp_path / "out"), "--quiet", "--no-html"]) == 0
    assert not (tmp_path / "out" / "trajectory.html").exists() and (tmp_path / "out" / "summary.json").exists()


def test_diverging_mechanism_exits_1_and_keeps_its_samples(tmp_path, capsys):
    """A mechanism that comes apart exits with status 1, says so, and writes its telemetry."""
    scene = scene_variant(tmp_path / "s.toml", "five_bar_computed_torque",
                          simulation={"integrator": "euler", "step": 1e-3, "baumgarte": 1000.0},
                          output={"figures": False, "html": False})
    status = main(["simulate", str(scene), "--out", str(tmp_path / "out"), "--quiet"])
    assert status == 1 and "run stopped early: loop-closure residual" in capsys.readouterr().err
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "diverged"


def test_scenes_lists_the_mechanism_scenes(capsys):
    """`freefloat scenes` lists the 5R scenes beside the default robot scene."""
    assert main(["scenes"]) == 0
    listed = capsys.readouterr().out
    assert "five_bar_sliding_mode: 5R" in listed and "five_bar_computed_torque: 5R" in listed
    assert f"{DEFAULT_SCENE} (default)" in listed


def test_version_and_module_entry_point():
    """``python -m freefloat --version`` prints the package version."""
    import subprocess
    import sys

    import freefloat

    out = subprocess.run([sys.executable, "-m", "freefloat", "--version"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == f"freefloat {freefloat.__version__}"


@pytest.mark.parametrize(("name", "expected"), [("../../x", "x"), ("/abs/dir", "abs_dir"), ("a b", "a_b"), ("..", "scene")])
def test_scene_names_become_one_folder_under_runs(name, expected, tmp_path, monkeypatch):
    """A scene name cannot steer the default output folder out of runs/."""
    from freefloat.app.folder_names import default_folder

    monkeypatch.chdir(tmp_path)
    folder = default_folder(name)
    assert folder.parent == Path("runs") and folder.name.startswith(f"{expected}-") and "/" not in folder.name


def test_a_long_scene_name_gives_a_folder_the_file_system_takes(tmp_path, monkeypatch):
    """A scene named with 300 characters gets a default folder that can be created (it raised
    'File name too long')."""
    from freefloat.app.folder_names import MAX_FOLDER_NAME, default_folder

    monkeypatch.chdir(tmp_path)
    folder = default_folder("batch-" + "n" * 300)
    folder.mkdir(parents=True)
    assert folder.name.startswith("batch-nnn") and len(folder.name) <= MAX_FOLDER_NAME + 20


def test_a_second_run_into_the_same_out_needs_overwrite(tmp_path, capsys):
    """Running twice into one --out exits 2 naming --overwrite; with it the folder is replaced."""
    scene = scene_variant(tmp_path / "s.toml", DEFAULT_SCENE, simulation={"duration": 0.01},
                          output={"figures": False, "html": False})
    args = ["simulate", str(scene), "--out", str(tmp_path / "out"), "--quiet"]
    assert main(args) == 0
    assert main(args) == 2 and "--overwrite" in capsys.readouterr().err
    assert main([*args, "--overwrite"]) == 0
    assert (tmp_path / "out" / "telemetry.npz").is_file()


def test_overwrite_keeps_the_user_s_files_in_out(tmp_path, capsys):
    """--overwrite replaces the previous run and keeps a document and a data folder the user put
    beside it, naming them."""
    scene = scene_variant(tmp_path / "s.toml", DEFAULT_SCENE, simulation={"duration": 0.01},
                          output={"figures": False, "html": False})
    args = ["simulate", str(scene), "--out", str(tmp_path / "out"), "--quiet", "--overwrite"]
    assert main(args) == 0
    (tmp_path / "out" / "report.docx").write_text("precious")
    (tmp_path / "out" / "data").mkdir()
    (tmp_path / "out" / "data" / "x.csv").write_text("1")
    assert main(args) == 0
    assert "kept 2 file(s)" in capsys.readouterr().err
    assert (tmp_path / "out" / "report.docx").read_text() == "precious"
    assert (tmp_path / "out" / "data" / "x.csv").read_text() == "1"


@pytest.mark.parametrize("overwrite", [[], ["--overwrite"]])
def test_reproduce_never_writes_over_the_user_s_report(tmp_path, capsys, overwrite):
    """reproduce --out into a folder holding the user's report.md and report.json exits 2 naming
    them, and leaves both."""
    (tmp_path / "report.md").write_text("my report")
    (tmp_path / "report.json").write_text("{}")
    assert main(["reproduce", "chattering", "--quick", "--out", str(tmp_path), *overwrite]) == 2
    assert "report.md" in capsys.readouterr().err or overwrite
    assert (tmp_path / "report.md").read_text() == "my report" and (tmp_path / "report.json").read_text() == "{}"


@pytest.mark.slow
def test_reproduce_writes_its_folder_and_a_rerun_resumes_into_it(tmp_path):
    """reproduce exits 0 with each file it wrote whole and in the folder's record, and the same
    command again takes that folder (it exited 2 on its own report.json: 'exists and freefloat
    did not write it')."""
    from .folder_checks import folder_problems

    args = ["reproduce", "phases", "--quick", "--out", str(tmp_path / "out")]
    assert main(args) == 0 and main(args) == 0
    assert {"report.json", "report.md"} <= {p.name for p in (tmp_path / "out").iterdir()}
    assert not folder_problems(tmp_path / "out")


def test_an_interrupted_study_keeps_its_journal_and_nothing_half_made(tmp_path, monkeypatch, capsys):
    """Ctrl-C in a study leaves its journal, in the folder's record, and none of the files it had
    begun (report.json cut short and unrecorded: a rerun refused the folder as not freefloat's)."""
    from freefloat.lab.reproduce import STUDIES

    class Halfway:
        name, help, journal, extras = "phases", "a study stopped half-way", "parts.jsonl", ()

        def run(self, out, quick, journal, **options):
            journal.write_text('{"part": 1}\n')
            (out / "report.json").write_text('{"cut')
            raise KeyboardInterrupt

    monkeypatch.setitem(STUDIES, "phases", Halfway())
    out = tmp_path / "out"
    assert main(["reproduce", "phases", "--out", str(out)]) == 1
    assert "journaled in" in capsys.readouterr().err
    assert {p.name for p in out.iterdir()} == {RECORD, "parts.jsonl"}
    assert "parts.jsonl" in (out / RECORD).read_text()


def test_sigterm_after_the_work_is_an_interruption_too(monkeypatch, capsys):
    """SIGTERM at any moment of a command, even once its work is done, stops it as Ctrl-C does:
    exit 1 and one line (between a batch's last run and its report it killed the process,
    exit -15)."""
    import os
    import signal

    from freefloat.app import cli

    killed = []
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: killed.append(signum))

    def scenes():
        os.kill(os.getpid(), signal.SIGTERM)
        return 0

    monkeypatch.setattr(cli, "_scenes", scenes)
    try:
        status = main(["scenes"])
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert status == 1 and not killed and "freefloat: interrupted" in capsys.readouterr().err


@pytest.mark.parametrize(("extra", "message"), [(["--seed", "-1"], "--seed must be >= 0"),
                                                 (["--json", "."], "must be a file in an existing folder"),
                                                 (["--json", "no/such/dir/v.json"], "must be a file in an existing folder")])
def test_verify_arguments_are_checked_before_it_runs(extra, message, capsys):
    """Bad verify arguments exit 2 naming the option, not a traceback after the checks."""
    assert main(["verify", str(URDF_DIR / "two_arm_planar.urdf"), *extra]) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize(("section", "values", "message"), [
    ("simulation", {"duration": 1.0005}, "'simulation.duration' \\(1.0005 s\\) must be a whole number of 'simulation.control_period'"),
    ("output", {"html_fps": 1e12}, "'output.html_fps' is 1000000000000.0; at most 1000"),
    ("simulation", {"duration": 1e9}, "needs about .* GB of telemetry"),
    ("simulation", {"duration": 100.0, "substeps": 1_000_000}, "estimated at .* h"),
    ("simulation", {"substeps": 1_000_000_000}, "'simulation.substeps' must be from 1 to 1000000"),
    ("simulation", {"integrator": "dopri5", "rtol": 1e-300}, "'simulation.rtol' must be >= 1e-16"),
])
def test_runs_too_big_or_impossible_are_refused_before_they_start(tmp_path, capsys, section, values, message):
    """Durations off the period grid, absurd frame rates, runs that would not fit in memory or
    would take more than a day exit 2 at once, naming the keys and the estimate."""
    import re
    import time

    scene = scene_variant(tmp_path / "s.toml", DEFAULT_SCENE, **{section: values})
    start = time.perf_counter()
    assert main(["simulate", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert re.search(message, capsys.readouterr().err)
    assert time.perf_counter() - start < 30 and not (tmp_path / "out").exists()


def test_a_scene_with_robot_and_mechanism_is_refused(tmp_path, capsys):
    """Both [robot] and [mechanism] in one file: the message says a scene has one or the other."""
    scene = tmp_path / "s.toml"
    scene.write_text('name = "x"\n[robot]\nurdf = "a.urdf"\n[mechanism]\nname = "five_bar"\n')
    assert main(["simulate", str(scene)]) == 2
    assert "either [robot]" in capsys.readouterr().err


def test_a_scene_file_that_is_not_utf8_is_named(tmp_path, capsys):
    """A scene in another encoding exits 2 naming the file."""
    scene = tmp_path / "s.toml"
    scene.write_bytes('name = "é"\n'.encode("latin-1"))
    assert main(["simulate", str(scene)]) == 2
    assert "not UTF-8" in capsys.readouterr().err


def test_info_lists_joints_links_and_end_effectors(capsys):
    """freefloat info names every movable joint with its limits, link masses and the end-effectors."""
    assert main(["info", "panda"]) == 0
    out = capsys.readouterr().out
    assert "panda_joint4                 revolute   axis (0, 0, 1)  [-3.0718, -0.0698] rad" in out
    assert "panda_link1                  4.97068 kg" in out and "panda_hand_tcp               arm: panda_joint1" in out


def test_simulate_any_known_robot_by_name(tmp_path):
    """--robot runs the tumbling scene with that robot; its momentum is conserved."""
    assert main(["simulate", "--robot", "solo12", "--out", str(tmp_path / "out"), "--quiet", "--no-html",
                 "--no-figures"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["robot"]["urdf"].endswith("solo12.urdf") and summary["momentum_drift_max"] < 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0.2, 0.4, 0.8])
def test_ctrl_c_while_starting_stops_cleanly(tmp_path, delay):
    """Ctrl-C in the first second (imports, robot loading) is never swallowed by a library and
    never a traceback: the command stops with exit 1 (it was ignored in 7 of 10 tries). (Before
    freefloat's first line runs, about 0.1 s into the interpreter's start on a busy machine, a
    Ctrl-C is Python's own.)"""
    import signal
    import time

    from .conftest import cli_process

    scene = scene_variant(tmp_path / "s.toml", DEFAULT_SCENE, simulation={"duration": 500.0},
                          output={"figures": False, "html": False})
    proc = cli_process("simulate", str(scene), "--out", str(tmp_path / "out"), "--quiet")
    time.sleep(delay)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 1 and "Traceback" not in err, f"exit {proc.returncode}; stderr:\n{err}"
    summary = tmp_path / "out" / "summary.json"
    assert not summary.exists() or json.loads(summary.read_text())["status"] == "interrupted"


@pytest.mark.parametrize("command", ["", "simulate", "batch", "bench", "reproduce", "verify", "info", "view", "scenes", "robots"])
def test_help_texts_are_plain(command, capsys):
    """``--help`` shows no reStructuredText markup (double backticks, roles)."""
    with pytest.raises(SystemExit):
        main([command, "--help"] if command else ["--help"])
    text = capsys.readouterr().out
    assert "usage: freefloat" in text and "``" not in text and not re.search(r":(func|class|mod|data|meth):", text)


@pytest.mark.slow
def test_a_warning_is_shown_once_per_run(tmp_path):
    """The detumble scene loads its robot for the plant and for the controller: the inertia note
    is printed once (it was printed twice), on one line (it took two), as a note: the built-in
    robot's inertias are the dissertation's on purpose."""
    path = scene_variant(tmp_path / "s.toml", "detumble_impulse_arm1_joint3", simulation={"duration": 0.02},
                         output={"figures": False, "html": False})
    done = subprocess.run([sys.executable, "-m", "freefloat", "simulate", str(path), "--out", str(tmp_path / "out"),
                           "--quiet"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    said = [line for line in done.stderr.splitlines() if line.startswith(("freefloat: ", "  "))]
    assert len(said) == 1 and said[0].startswith("freefloat: note: ") and "I1 + I2 >= I3" in said[0]


@pytest.fixture
def fresh_warnings(monkeypatch):
    """This process as if it had shown no warning yet (each is shown once per process)."""
    monkeypatch.setattr(shown_warnings, "SHOWN", set())


def _short(tmp_path: Path) -> Path:
    """The default scene, 20 ms, without figures or page."""
    return scene_variant(tmp_path / "s.toml", DEFAULT_SCENE, simulation={"duration": 0.02},
                         output={"figures": False, "html": False})


@pytest.mark.parametrize(("options", "output", "starts"), [
    ((), {"figures": False}, False), (("--figures", ""), {"figures": True}, False),
    (("--no-figures",), {"figures": True}, False), ((), {"figures": ["com_drift"]}, True),
    (("--figures", "com_drift"), {"figures": False}, True)])
def test_simulate_starts_the_figure_helper_only_for_figures(options, output, starts, tmp_path, monkeypatch):
    """simulate starts the figure helper before its imports when its options and scene file may
    draw a figure, and never for a scene file or options that turn them off."""
    from freefloat.app.cli import _may_draw_figures, _Parser

    scene = scene_variant(tmp_path / "s.toml", DEFAULT_SCENE, output=output)
    parser = _Parser()
    parser.add_argument("scene")
    parser.add_argument("--figures", default=None)
    parser.add_argument("--no-figures", action="store_true")
    assert _may_draw_figures(parser.parse_args([str(scene), *options])) is starts


def test_a_scene_that_draws_no_figure_leaves_no_figure_helper(tmp_path, monkeypatch):
    """A scene file that turns figures off runs without a figure helper left running."""
    from freefloat.app.viz import rendering

    monkeypatch.setattr(rendering, "_helper", None)
    assert main(["simulate", str(_short(tmp_path)), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert rendering._helper is None


def test_a_warning_is_shown_once_per_process(tmp_path, capsys, fresh_warnings):
    """Two runs in one process (a script calling main twice) show the robot's note once."""
    for out in ("a", "b"):
        assert main(["simulate", str(_short(tmp_path)), "--out", str(tmp_path / out), "--quiet"]) == 0
    assert capsys.readouterr().err.count("freefloat: note:") == 1


def test_a_refused_command_prints_its_error_alone(tmp_path, capsys, fresh_warnings):
    """Bad input met after the robot has loaded (a folder of the user's files as --out, a joint the
    robot does not have) exits 2 with the error alone: no note it does not explain before it (the
    inertia note came first)."""
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("mine")
    for args in (["simulate", str(_short(tmp_path)), "--out", str(tmp_path / "mine"), "--quiet"],
                 ["simulate", str(scene_variant(tmp_path / "bad.toml", DEFAULT_SCENE,
                                                initial={"joint_positions": {"arm1_jiont1": 5.0}})),
                  "--out", str(tmp_path / "out"), "--quiet"]):
        assert main(args) == 2
        err = capsys.readouterr().err
        assert err.startswith("freefloat: error:") and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()
    assert main(["simulate", str(_short(tmp_path)), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert "freefloat: note:" in capsys.readouterr().err  # held back, not lost


def test_a_user_s_folder_gets_a_hint_that_works(tmp_path, capsys):
    """--out naming a folder of the user's files: the hint is another folder, with or without
    --overwrite (it suggested --overwrite, which then refused the folder); the file is kept."""
    (tmp_path / "myresults").mkdir()
    (tmp_path / "myresults" / "notes.txt").write_text("mine")
    args = ["simulate", str(_short(tmp_path)), "--out", str(tmp_path / "myresults"), "--quiet"]
    for extra in ([], ["--overwrite"]):
        assert main([*args, *extra]) == 2
        err = capsys.readouterr().err
        assert "choose another --out (a new or empty folder)" in err and "--overwrite" not in err
    assert [p.name for p in (tmp_path / "myresults").iterdir()] == ["notes.txt"]


def test_the_progress_bar_and_the_summary_give_one_time(tmp_path, capsys, monkeypatch):
    """The bar's last line and the summary's "completed: N steps in T s" measure the same
    interval, the loop's (the bar's ran on through the summary and the files: 3 s against 0.98 s):
    N over the bar's rate is T; the time after the loop gets its own line."""
    monkeypatch.setattr(LoopBar, "DELAY", 0.0)
    scene = scene_variant(tmp_path / "s.toml", DEFAULT_SCENE, simulation={"duration": 0.5},
                          output={"figures": False, "html": False})
    assert main(["simulate", str(scene), "--out", str(tmp_path / "out")]) == 0
    captured = capsys.readouterr()
    steps, wall = re.search(r"completed: (\d+) steps in ([\d.]+) s", captured.out).groups()
    rates = re.findall(r"(\d+)/(\d+) \[[\d:]+<[\d:?]+, +([\d.]+)step/s\]", captured.err)
    done, total, rate = rates[-1]
    assert done == total == steps
    assert int(steps) / float(rate) == pytest.approx(float(wall), rel=0.05, abs=0.006)  # wall printed to 0.01 s
    assert re.search(r"summarising the run \.\.\. [\d.]+ s\nwriting telemetry", captured.err)


def test_the_summary_prints_units_and_four_digits(tmp_path, capsys):
    """Headline keys are printed with their unit and 4 significant digits (16 digits and no unit
    before); summary.json keeps every digit."""
    assert main(["simulate", str(_short(tmp_path)), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    out = capsys.readouterr().out
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert f"  tracking_rms_overall: {summary['tracking_rms_overall']:.4g} rad\n" in out
    assert f"  energy_drift_max: {summary['energy_drift_max']:.4g} J\n" in out
    shown = ", ".join(f"{x:.4g}" for x in summary["base_displacement"])
    assert f"  base_displacement: [{shown}] m\n" in out
    assert len(repr(summary["tracking_rms_overall"])) > 10  # full precision in the file


@pytest.mark.parametrize("args, said", [
    (["simulte"], "invalid choice: 'simulte'; did you mean 'simulate'?"),
    (["reproduce", "chatering"], "invalid choice: 'chatering'; did you mean 'chattering'?"),
    (["simulate", "five_bar_slidng_mode"], "did you mean 'five_bar_sliding_mode'"),
    (["simulate", "--robot", "ur55"], "did you mean 'ur5'?"),
    (["info", "talso"], "did you mean 'talos'"),
    (["batch", "--vary", "joint_angel=1"], "unknown key 'joint_angel'; did you mean 'joint_angle'"),
    (["bench", "--suite", "simulaton"], "did you mean 'simulation'?"),
])
def test_every_mistyped_name_gets_the_nearest_valid_one(args, said, tmp_path, capsys):
    """A mistyped command, study, scene, robot, --vary key or suite exits 2 naming the nearest
    valid name (a scene key did; a scene name listed all 27, a robot name about 80), the list cut
    short."""
    try:
        status = main([*args, "--out", str(tmp_path / "o")] if args[0] in ("simulate", "batch", "bench") else args)
    except SystemExit as exit:  # argparse's own refusal
        status = exit.code
    err = capsys.readouterr().err
    assert status == 2 and said in err and len(err) < 900, err
    assert not (tmp_path / "o").exists()


def test_robots_lists_the_robots_known_by_name(capsys):
    """``freefloat robots`` lists every name a robot can be given by, an alias with its file."""
    assert main(["robots"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "dual_arm_satellite" and "talos: talos_reduced.urdf" in lines and "ur5: ur5_robot.urdf" in lines


@pytest.fixture
def plugin_points(monkeypatch):
    """Plug-ins not loaded yet in this process, and the calls to importlib.metadata.entry_points
    (the lab's entry point only, as the package declares it)."""
    from importlib import metadata

    from freefloat import registry

    calls: list[str | None] = []

    def entry_points(group: str | None = None, **kwargs) -> list[metadata.EntryPoint]:
        calls.append(group)
        return [metadata.EntryPoint("lab", "freefloat.lab.plugin", group)] if group == registry.GROUP else []

    monkeypatch.setattr(registry, "_LOADER", registry._Loader())
    monkeypatch.setattr(metadata, "entry_points", entry_points)
    return calls


def test_version_and_built_in_commands_start_without_the_plugins(plugin_points, capsys):
    """--version and a built-in command never read the entry points; --help does, and lists the
    lab's commands."""
    with pytest.raises(SystemExit):
        main(["--version"])
    assert main(["scenes"]) == 0 and plugin_points == []
    with pytest.raises(SystemExit):
        main(["--help"])
    assert plugin_points == ["freefloat.plugins"]
    assert re.search(r"\{simulate,.*,verify,reproduce,bench,atlas\}", capsys.readouterr().out)


def test_a_plugin_command_runs_with_no_other_edit(monkeypatch, capsys):
    """A Command registered in COMMANDS is listed by --help, parses its own arguments and runs
    with its exit status; its FreefloatError exits 2."""
    from freefloat.app.commands import COMMANDS, Command
    from freefloat.errors import FreefloatError

    def run(args) -> int:
        if args.times < 0:
            raise FreefloatError("--times must be >= 0")
        print("hello " * args.times)
        return 0

    monkeypatch.setitem(COMMANDS, "hello", Command("hello", "say hello", lambda p: p.add_argument("--times", type=int),
                                                   run))
    with pytest.raises(SystemExit):
        main(["--help"])
    assert "say hello" in capsys.readouterr().out
    assert main(["hello", "--times", "2"]) == 0 and capsys.readouterr().out.strip() == "hello hello"
    assert main(["hello", "--times", "-1"]) == 2 and "--times must be >= 0" in capsys.readouterr().err


def test_a_plugin_that_fails_or_takes_a_built_in_name_is_refused(plugin_points, monkeypatch, capsys):
    """A plug-in registering a built-in command's name, or one failing to import, stops the
    command line with exit 2 and says why."""
    from importlib import metadata

    from freefloat.app.commands import COMMANDS, Command

    monkeypatch.setitem(COMMANDS, "batch", Command("batch", "a second batch", lambda p: None, lambda a: 0))
    assert main(["--help"]) == 2 and "registers the command 'batch', which is freefloat's own" in capsys.readouterr().err
    monkeypatch.setattr(metadata, "entry_points", lambda group=None, **kwargs: [
        metadata.EntryPoint("broken", "no_such_plugin_module", group)])
    from freefloat import registry

    monkeypatch.setattr(registry, "_LOADER", registry._Loader())
    assert main(["bench"]) == 2
    assert "plug-in 'broken' (no_such_plugin_module, entry point of group freefloat.plugins) failed to import: " \
           "ModuleNotFoundError" in capsys.readouterr().err


@pytest.mark.parametrize("closed", ["stdout", "stderr"])
def test_a_closed_output_stream_costs_the_run_none_of_its_files(tmp_path, closed):
    """``freefloat simulate | head`` (or ``2>&1 | head``): the reader gone before the summary or
    the stage lines are printed, the run still writes its data and exits as it ran (a scene
    that prints nothing before its loop ends, and a loop too short for a progress bar)."""
    scene = scene_variant(tmp_path / "s.toml", "satellite_dual_arm", simulation={"duration": 0.05})
    out = tmp_path / "run"
    command = [sys.executable, "-m", "freefloat", "simulate", str(scene), "--out", str(out), "--no-figures",
               "--no-html"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    getattr(process, closed).close()  # no reader: the first line printed there meets a broken pipe
    kept = process.stderr if closed == "stdout" else process.stdout
    printed = kept.read()
    assert process.wait(timeout=300) == 0, printed
    assert "Traceback" not in printed
    assert {"telemetry.npz", "summary.json", "scene.toml"} <= {p.name for p in out.iterdir()}


@pytest.mark.parametrize("skipped", [[], ["figures"]])
def test_an_interrupt_while_writing_says_what_it_cut_short(capsys, skipped):
    """An interrupt during the writing exits 1; the message says the skipped drawings are missing,
    or, when it came during the last wait and cut nothing, that every file listed was written."""
    from types import SimpleNamespace

    from freefloat.app.cli import _report

    done = SimpleNamespace(folder=Path("out"), written=[Path("out/telemetry.npz")], skipped=skipped, completed=True,
                           interrupted_writing=True)
    assert _report(done) == 1
    err = capsys.readouterr().err
    expected = "the drawings listed as skipped are not there" if skipped else "every file listed was written"
    assert f"interrupted while writing out: the data are whole, {expected}" in err
