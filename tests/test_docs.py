"""The README and the docs site show only what works: every Python snippet runs and its numbers
agree with an independent reference, every ``freefloat`` command parses, every script exists,
every scene example is read as written."""

from __future__ import annotations

import os
import re
import shlex
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from freefloat.app import cli
from freefloat.app.commands import COMMANDS
from freefloat.app.scenes import parse_scene

from .conftest import REPO

PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
#: Placeholders in command synopses and what a check substitutes for them.
PLACEHOLDERS = {"SCENE": "four_arm_joint_space", "URDF": "urdf/four_arm_planar.urdf", "DIR": "runs/x",
                "FILE": "runs/x.json", "N": "2", "ADDR": "tcp://127.0.0.1:8786", "RUN_DIR": "runs/x",
                "ROBOT": "ur5"}


def blocks(language: str) -> list[tuple[str, str]]:
    """(where, code) of every fenced block in ``language`` on the pages."""
    found = []
    for page in PAGES:
        for i, code in enumerate(re.findall(rf"^```{language}\n(.*?)^```", page.read_text(), re.DOTALL | re.MULTILINE)):
            found.append((f"{page.name}#{language}{i}", code))
    return found


def commands() -> list[tuple[str, list[str]]]:
    """(where, argv) of every ``freefloat`` or ``python3 scripts/...`` line of the bash blocks,
    comments dropped, optional brackets opened and placeholders filled."""
    found = []
    for where, code in blocks("bash"):
        for line in code.splitlines():
            line = line.split("  #")[0].split(" # ")[0].strip()
            if not line.startswith(("freefloat", "python3 scripts/")):
                continue
            line = re.sub(r"\[([^\]]*)\]", r"\1", line)
            found.append((where, [PLACEHOLDERS.get(word, word) for word in shlex.split(line)]))
    return found


def _readme_scene(ns: dict) -> None:
    """The default job run from Python writes the folder the command writes (its summary.json is
    the outcome's, its telemetry has every step) and holds the dissertation's claims: tracking at or
    below FM-NIC-A's 4.91e-7 rad (Table 1), the CoM still; the run that writes nothing conserves
    its momentum."""
    import json

    from freefloat import Telemetry

    run, outcome = ns["run"], ns["outcome"]
    summary = run.summary
    assert run.status == "completed" and summary["tracking_rms_overall"] <= 4.91e-7
    assert summary["com_drift_max"] < 1e-8 and outcome.summary["momentum_drift_max"] < 1e-12
    assert json.loads((run.folder / "summary.json").read_text())["tracking_rms_overall"] == summary["tracking_rms_overall"]
    assert len(Telemetry.load(run.folder / "telemetry.npz").t) == summary["steps"] + 1


def _python_many_runs(ns: dict) -> None:
    """Each of the runs in one call ends where simulation.run from its own start ends, and
    conserves its momentum."""
    from freefloat import run

    robot, results = ns["robot"], ns["results"]
    for i in (0, 5):
        alone = run(robot, ns["q0"][i], ns["v0"][i], 1.0, 1e-3, ns["make_integrator"]("rkmk4", robot.model),
                    ns["make_model"]("exact", robot))
        np.testing.assert_array_equal(results[i].telemetry.q, alone.telemetry.q)
        momentum = results[i].telemetry.momentum
        assert np.abs(momentum - momentum[0]).max() < 1e-12 * max(1.0, np.abs(momentum).max())


def _python_tumbling(ns: dict) -> None:
    """The torque-free tumbling run conserves its momentum (a conservation law) and ends where an
    independent integration (dopri5 at rtol 1e-12) ends."""
    from freefloat import make_model
    from freefloat.dynamics.integrators import make_integrator

    result, robot = ns["result"], ns["robot"]
    momentum = result.telemetry.momentum
    assert result.status == "completed"
    assert np.abs(momentum - momentum[0]).max() < 1e-12 * max(1.0, np.abs(momentum).max())
    model = make_model("exact", robot)
    f = lambda q, v: model.acceleration(q, v, np.zeros(robot.model.nv))  # noqa: E731
    q, v = make_integrator("dopri5", robot.model, rtol=1e-12, atol=1e-14).advance(f, ns["q0"], ns["v0"], 1.0)
    assert np.abs(v - result.telemetry.v[-1]).max() < 1e-8


def _gjm_page(ns: dict) -> None:
    """The GJM state equals Pinocchio's counterparts (CRBA, centroidal momentum, frame
    Jacobians) at the snippet's state."""
    from freefloat.dynamics.reference import reference

    s, ref = ns["s"], reference(ns["robot"], ns["q"], ns["v"])
    for name in ("H0", "H0m", "Hm", "Hstar", "Jstar", "momentum_origin"):
        expected = getattr(ref, name)
        assert np.abs(getattr(s, name) - expected).max() <= 1e-10 * max(1.0, np.abs(expected).max()), name
    assert np.abs(s.end_effector_velocity() - ref.ee_velocity).max() <= 1e-10 * max(1.0, np.abs(ref.ee_velocity).max())


def _integrators_page(ns: dict) -> None:
    """rkmk6 and dopri5's dense output end at the same state, and rkmk6 keeps the momentum of
    the start (computed by Pinocchio)."""
    import pinocchio as pin

    model = ns["robot"].model
    data = model.createData()

    def momentum(q, v):
        return pin.computeCentroidalMomentum(model, data, q, v).vector.copy()

    assert np.abs(ns["V"][-1] - ns["v1"]).max() < 1e-6
    start = momentum(ns["q0"], ns["v0"])
    assert np.abs(momentum(ns["q1"], ns["v1"]) - start).max() < 1e-9 * max(1.0, np.abs(start).max())


def _python_closed_chain(ns: dict) -> None:
    """The compiled RKMK6 run ends where scipy's DOP853 (rtol 1e-12, the Python loop, another
    integrator and loop) ends, with the loop held closed."""
    from freefloat.parallel.closed_loop import track

    result = ns["result"]
    assert result.status == "completed" and result.backend == "compiled"
    assert result.telemetry.drift.max() < 1e-9
    reference = track(ns["plant"], ns["law"], ns["q0"], 0.1, 1e-4, 1e-4, integrator="dop853", rtol=1e-12, atol=1e-12)
    assert reference.backend == "python"
    assert np.abs(reference.telemetry.q[-1] - result.telemetry.q[-1]).max() < 1e-9


def _first_hour(ns: dict) -> None:
    """The default job run from Python wrote its folder (the telemetry and summary read back equal
    what it returned), tracks at or below the dissertation's FM-NIC-A (Table 1), keeps the system
    CoM still and the momentum constant (no external force, at rest at the start: conservation
    laws checked on the telemetry itself); the unwritten tumbling run conserves its momentum."""
    run, saved, on_disk, outcome = ns["run"], ns["saved"], ns["on_disk"], ns["outcome"]
    telemetry = run.telemetry
    assert run.status == "completed" and run.folder.name == "first"
    assert np.array_equal(saved.q, telemetry.q) and np.array_equal(saved.tau, telemetry.tau)
    assert on_disk["tracking_rms_overall"] == run.summary["tracking_rms_overall"] <= 4.91e-7
    assert np.abs(telemetry.com - telemetry.com[0]).max() < 1e-12
    assert np.abs(telemetry.momentum).max() < 1e-12
    assert outcome.status == "completed" and not (Path.cwd() / "runs" / "tumbling").exists()
    momentum = outcome.telemetry.momentum
    assert np.abs(momentum - momentum[0]).max() < 1e-12 * max(1.0, np.abs(momentum).max())


def _parallel_page(ns: dict) -> None:
    """The motor-driven 5R under the voltage drive ends where the same closed loop integrated by
    DOP853 (rtol 1e-12, a fresh drive) ends, to RK4's error on the windings at 0.1 ms (L/R =
    0.26 ms), with the loop held closed."""
    from freefloat import run
    from freefloat.dynamics.voltage_drive import VoltageDrive

    result, plant, motors = ns["result"], ns["plant"], ns["motors"]
    assert result.status == "completed" and result.telemetry.drift.max() < 1e-9
    drive = VoltageDrive(ns["law"], plant, motors.motors, bandwidth=3500.0, period=1e-4)
    reference = run(plant, ns["q0"], np.zeros(plant.space.nv), 0.01, 1e-4, "dop853", controller=drive, rtol=1e-12,
                    atol=1e-12)
    np.testing.assert_allclose(result.telemetry.q[-1], reference.telemetry.q[-1], atol=2e-5)  # 1.9e-6 measured
    np.testing.assert_allclose(result.telemetry.v[-1], reference.telemetry.v[-1], atol=1e-3)  # 1.1e-4 A measured


def _control_laws_page(ns: dict) -> None:
    """The adaptive run completes; its estimates move towards the plant's base parameters
    (five_bar_theta, checked against Orsino's dynamics) and the platform follows the circle
    (computed here from eq 189) within 5e-5 m over the last 0.1 s."""
    from freefloat.parallel.five_bar import TRUE_PARAMETERS_50
    from freefloat.parallel.platform_regressor import five_bar_theta

    tel, truth = ns["result"].telemetry, five_bar_theta(TRUE_PARAMETERS_50)
    assert ns["result"].status == "completed" and len(ns["t"]) == len(tel.t) - 1
    first, last = np.abs(ns["estimates"][0] / truth - 1).max(), np.abs(ns["estimates"][-1] / truth - 1).max()
    assert last < first / 3
    late = tel.t > 0.4
    circle = np.array([[0.07 * np.cos(28.57 * t), 0.17 + 0.07 * np.sin(28.57 * t)] for t in tel.t[late]])
    assert np.abs(tel.q[late, :2] - circle).max() < 5e-5


def _sensors_page(ns: dict) -> None:
    """The sensed detumbling run completes, the law read one recorded row per period, and the
    estimated momentum ends within 4 of its standard deviations of the telemetry's (Pinocchio's
    centroidal momentum) on the components a planar base conserves, closer than the readings' map."""
    result, seen = ns["result"], ns["seen"]
    assert result.status == "completed" and len(seen.t) == len(result.telemetry.t) - 1 == 500
    truth, rows = result.telemetry.momentum[-2], [0, 1, 5]
    assert np.all(np.abs(seen.estimate[-1, rows] - truth[rows]) < 4 * seen.spread[-1, rows])
    assert np.all(seen.spread[-1, rows] < np.sqrt(np.mean((seen.momentum[100:] - truth) ** 2, axis=0))[rows])


def _orbit_page(ns: dict) -> None:
    """The satellite released 5 deg off librates between +-5 deg, its downward zero crossings
    half a closed-form period apart to 0.5 %."""
    t, pitch = ns["t"], ns["pitch"]
    assert abs(pitch[0] - np.radians(5.0)) < 1e-12 and np.abs(pitch).max() < np.radians(5.0) + 1e-9
    down = np.flatnonzero((pitch[:-1] > 0.0) & (pitch[1:] <= 0.0))
    up = np.flatnonzero((pitch[:-1] < 0.0) & (pitch[1:] >= 0.0))
    crossings = np.sort(np.concatenate([t[i] + pitch[i] / (pitch[i] - pitch[i + 1]) * (t[i + 1] - t[i])
                                        for i in (down, up)]))
    assert crossings.size >= 4
    assert abs(2.0 * np.diff(crossings).mean() / ns["closed_form"] - 1.0) < 5e-3


#: What each Python snippet of the pages claims, checked against a reference of its own.
SNIPPET_CHECKS = {"README.md#python0": _readme_scene, "python.md#python0": _python_tumbling,
                  "python.md#python1": _python_closed_chain, "python.md#python2": _python_many_runs,
                  "gjm.md#python0": _gjm_page,
                  "integrators.md#python0": _integrators_page,
                  "control_laws.md#python0": _control_laws_page, "first_hour.md#python0": _first_hour,
                  "parallel.md#python0": _parallel_page, "sensors.md#python0": _sensors_page,
                  "orbit.md#python0": _orbit_page}


@pytest.mark.slow
@pytest.mark.parametrize(("where", "code"), blocks("python"), ids=[w for w, _ in blocks("python")])
def test_python_snippet_runs_and_its_numbers_hold(where, code, tmp_path, monkeypatch):
    """The snippet executes (from a fresh folder) and what it computes agrees with an independent
    reference (Pinocchio, a conservation law, another integrator); a new snippet needs a check."""
    assert where in SNIPPET_CHECKS, f"{where}: add a check of what the snippet computes to SNIPPET_CHECKS"
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "snippet"}
    exec(compile(code, where, "exec"), namespace)  # noqa: S102 -- running the snippet is half the test
    SNIPPET_CHECKS[where](namespace)


@pytest.mark.parametrize(("where", "argv"), commands(), ids=[" ".join(a) for _, a in commands()])
def test_command_parses(where, argv, monkeypatch):
    """A ``freefloat`` command is accepted by the command line (its work stubbed out); a script exists."""
    if argv[0] == "python3":
        assert (REPO / argv[1]).is_file(), f"{where}: no {argv[1]}"
        return
    seen = []
    for name in ("_simulate", "_batch", "_verify", "_scenes", "_robots", "_view", "_info", "_atlas"):
        monkeypatch.setattr(cli, name, lambda *args, name=name: seen.append(name) or 0)
    for command in COMMANDS.values():  # the plug-ins' (the lab's reproduce and bench)
        monkeypatch.setitem(COMMANDS, command.name, replace(command, run=lambda args: seen.append(args.command) or 0))
    assert cli.main(argv[1:]) == 0 and seen, f"{where}: {' '.join(argv)}"


def _plain(value):
    """Tuples to lists, recursively (the schema stores sequences as tuples)."""
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


@pytest.mark.parametrize(("where", "text"), blocks("toml"), ids=[w for w, _ in blocks("toml")])
def test_scene_example_is_read_as_written(where, text, monkeypatch):
    """A TOML example passes the scene validation, and every value it sets reaches the parsed
    scene unchanged (compared with tomllib's own reading of the text); an experiment kind's own
    section is read from ``scene.sections``."""
    monkeypatch.chdir(REPO / "src" / "freefloat" / "app" / "scenes")
    raw = tomllib.loads(text)
    scene = parse_scene(raw)
    for key, value in raw.items():
        if isinstance(value, dict):
            own = getattr(scene, "sections", {})
            _reached(own[key] if key in own else getattr(scene, key), value, f"{where}: {key}")
        elif not isinstance(value, list):
            assert getattr(scene, key) == value, f"{where}: {key}"


def _reached(section, table, where):
    """Every value of ``table`` is the same field of ``section``; a table inside it (``[sensors.joint_rate]``)
    is compared field by field with the record it became, a dict field (``joint_positions``) as a whole."""
    for field, expected in table.items():
        got = getattr(section, field)
        if isinstance(expected, dict) and not isinstance(got, dict):
            _reached(got, expected, f"{where}.{field}")
        else:
            assert _plain(got) == _plain(expected), f"{where}.{field}"


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The docs site built once with ``mkdocs build --strict`` (skipped without the docs extra):
    the completed process and the site's folder."""
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocstrings")
    import subprocess
    import sys

    folder = tmp_path_factory.mktemp("docs") / "site"
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(folder)],
                          check=False, cwd=REPO, capture_output=True, text=True, env=env, timeout=300)
    return done, folder


@pytest.mark.slow
def test_site_builds_with_warnings_as_errors(site):
    """``mkdocs build --strict`` succeeds (skipped without the docs extra)."""
    done, folder = site
    assert done.returncode == 0, done.stderr[-2000:]
    assert (folder / "index.html").is_file()


@pytest.mark.slow
def test_api_reference_renders_sphinx_roles_as_links(site):
    """No Sphinx role of the docstrings (``:func:`run```) reaches the API reference as text; one
    naming a documented object is a link to it (``:func:`run``` in ``freefloat.dynamics.simulation``,
    ``:class:`Robot``` in ``freefloat.robot.loading``), one naming an undocumented object is plain
    inline code."""
    done, folder = site
    assert done.returncode == 0, done.stderr[-2000:]
    html = (folder / "api" / "index.html").read_text()
    assert not re.findall(r":(?:func|class|mod|data|meth|attr|obj|exc):", html)
    assert "autoref" not in html.replace("autorefs", "")
    link = r'<a class="autorefs autorefs-internal"[^>]*href="#{0}"[^>]*><code>{1}</code></a>'
    assert re.search(link.format(r"freefloat\.dynamics\.simulation\.run", "run"), html)
    assert re.search(link.format(r"freefloat\.robot\.robot\.Robot", "Robot"), html)
    assert re.search(r'<span title="freefloat\.[\w.]+"><code>[\w.]+</code></span>', html)


def _sphinx_roles():
    """The docs' Griffe extension (docs/griffe_sphinx_roles.py), imported from its file."""
    import importlib.util

    path = REPO / "docs" / "griffe_sphinx_roles.py"
    spec = importlib.util.spec_from_file_location("griffe_sphinx_roles", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_sphinx_roles_resolve_as_python_would(tmp_path):
    """A role's target is resolved as a relative import (``.``: the docstring's package, ``..``
    its parent), in the documented object's scope (an imported name to where it is defined) or as
    a full path; ``~`` shows the last name only; an unknown target stays, shown as written."""
    griffe = pytest.importorskip("griffe")
    package = tmp_path / "pkg"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text('"""Top: :mod:`.sub` and :func:`~pkg.sub.core.step`."""\n')
    (package / "sub" / "__init__.py").write_text('"""Sub: :class:`.core.Engine`, :mod:`..other`."""\n')
    (package / "other.py").write_text("")
    (package / "sub" / "core.py").write_text(
        "from pkg.sub.helpers import helper\n"
        "class Engine:\n"
        '    """Runs :meth:`step` with :func:`helper`; see :data:`~.helpers.LIMIT`,\n'
        '    :class:`numpy.ndarray`."""\n'
        "    def step(self):\n"
        '        """One step of :class:`Engine`."""\n'
        "def step():\n"
        '    """:func:`.helpers.helper` and :attr:`Engine.step`."""\n')
    (package / "sub" / "helpers.py").write_text('LIMIT = 1\n"""A limit."""\ndef helper():\n    """Help."""\n')
    roles = _sphinx_roles()
    extensions = griffe.load_extensions(roles.SphinxRoles)
    loader = griffe.GriffeLoader(search_paths=[str(tmp_path)], extensions=extensions)
    pkg = loader.load("pkg")

    def ref(identifier, shown):
        return f'<autoref identifier="{identifier}" optional>`{shown}`</autoref>'

    assert pkg.docstring.value == f"Top: {ref('pkg.sub', 'sub')} and {ref('pkg.sub.core.step', 'step')}."
    assert pkg["sub"].docstring.value == (f"Sub: {ref('pkg.sub.core.Engine', 'core.Engine')}, "
                                          f"{ref('pkg.other', 'other')}.")
    engine = pkg["sub.core.Engine"]
    assert engine.docstring.value == (f"Runs {ref('pkg.sub.core.Engine.step', 'step')} with "
                                      f"{ref('pkg.sub.helpers.helper', 'helper')}; see "
                                      f"{ref('pkg.sub.helpers.LIMIT', 'LIMIT')},\n"
                                      f"{ref('numpy.ndarray', 'numpy.ndarray')}.")
    assert engine["step"].docstring.value == f"One step of {ref('pkg.sub.core.Engine', 'Engine')}."
    assert pkg["sub.core.step"].docstring.value == (f"{ref('pkg.sub.helpers.helper', 'helpers.helper')} and "
                                                    f"{ref('pkg.sub.core.Engine.step', 'Engine.step')}.")
