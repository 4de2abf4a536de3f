"""Integrators on the Lie group: orders of accuracy, the chart correction, the registry."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.dynamics.integrators import INTEGRATORS, TimeVarying, make_integrator
from freefloat.dynamics.integrators.lie import (
    ChartCorrection,
    _dexpinv_matrix,
    _dexpinv_se2,
    _dexpinv_se3,
)
from freefloat.dynamics.models import ExactModel
from freefloat.dynamics.plants import vector_space
from freefloat.robot.conventions import skew


@pytest.fixture(scope="module")
def tumbling(spart_dir):
    """A torque-free SC_3DoF with a fast-tumbling base, and a tight dopri5 reference after 1 s."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(spart_dir / "urdf" / "SC_3DoF.urdf")
    model = ExactModel(robot)
    rng = np.random.default_rng(0)
    q0 = robot.neutral()
    q0[7:] = rng.uniform(-1, 1, robot.n_joints)
    v0 = rng.uniform(-2, 2, robot.model.nv)
    tau = np.zeros(robot.model.nv)
    f = lambda q, v: model.acceleration(q, v, tau)
    reference = make_integrator("dopri5", robot.model, rtol=1e-13, atol=1e-14).advance(f, q0, v0, 1.0)
    return robot, f, q0, v0, reference


def errors(tumbling, name: str, substeps: list[int]) -> np.ndarray:
    robot, f, q0, v0, (q_ref, v_ref) = tumbling
    out = []
    for n in substeps:
        q, v = make_integrator(name, robot.model, substeps=n).advance(f, q0, v0, 1.0)
        out.append(np.linalg.norm(np.concatenate((pin.difference(robot.model, q_ref, q), v - v_ref))))
    return np.array(out)


def test_rkmk4_is_fourth_order(tumbling):
    """Halving the RKMK4 step divides the error by ~16."""
    e = errors(tumbling, "rkmk4", [100, 200, 400])
    assert 13.0 < e[1] / e[2] < 19.0


def test_naive_rk4_is_only_second_order_on_se3(tumbling):
    """RK4 adding body velocities without dexp^-1 divides the error by ~4 only."""
    e = errors(tumbling, "rk4_naive", [100, 200, 400])
    assert 3.0 < e[1] / e[2] < 5.0


def test_euler_is_first_order(tumbling):
    """Halving the semi-implicit Euler step halves the error."""
    e = errors(tumbling, "euler", [200, 400, 800])
    assert 1.7 < e[1] / e[2] < 2.3


def test_rkmk3_is_third_order(tumbling):
    """Halving the RKMK3 (Kutta) step divides the error by ~8: third order on SE(3) with the
    chart correction."""
    e = errors(tumbling, "rkmk3", [200, 400, 800])
    assert 6.5 < e[1] / e[2] < 9.5


def test_bs32_is_third_order_in_its_tolerance(tumbling):
    """The Bogacki-Shampine 3(2) pair: its error falls as rtol^(3/3) = rtol (a 3rd-order method
    whose steps follow the 2nd-order estimate: h ~ rtol^(1/3), error ~ h^3), so 1000x tighter
    tolerances give about 1000x smaller errors, and it needs about three evaluations per step."""
    robot, f, q0, v0, (q_ref, v_ref) = tumbling
    out = []
    for rtol in (1e-6, 1e-9):
        solver = make_integrator("bs32", robot.model, rtol=rtol, atol=rtol / 100)
        q, v = solver.advance(f, q0, v0, 1.0)
        out.append(np.linalg.norm(np.concatenate((pin.difference(robot.model, q_ref, q), v - v_ref))))
        assert solver.evaluations() <= 3 * (solver.accepted + solver.rejected) + 1
    assert 300.0 < out[0] / out[1] < 5000.0


def test_dopri5_meets_its_tolerance(tumbling):
    """The adaptive integrator at its default rtol 1e-10 lands within 1e-7 of the tight reference."""
    e = errors(tumbling, "dopri5", [1])  # substeps ignored; tolerance default 1e-10
    assert e[0] < 1e-7


@pytest.mark.parametrize("name", ["dopri5", "bs32"])
def test_an_adaptive_step_that_meets_nan_shrinks(name):
    """A first step so long that a stage leaves the dynamics' domain (NaN accelerations) is
    rejected and shrunk, not grown without end: the oscillator x'' = -x, undefined beyond |x| > 10,
    lands on cos(t)."""
    model = pin.Model()
    model.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), "x")
    solver = make_integrator(name, model, rtol=1e-10, atol=1e-12)
    q, v = solver.advance(lambda q, v: -q if abs(q[0]) < 10.0 else np.full(1, np.nan), np.ones(1), np.zeros(1), 30.0)
    assert abs(q[0] - np.cos(30.0)) < 1e-6 and solver.rejected < 50


@pytest.mark.parametrize("degree", [4, 6])
def test_planar_closed_form_equals_the_matrix_series(degree):
    """The se(2) closed form of dexp^-1 equals the ad-matrix series, to ad^4 and to ad^6."""
    rng = np.random.default_rng(1)

    def ad2(t):
        x, y, w = t
        return np.array([[0, -w, y], [w, 0, -x], [0, 0, 0.0]])

    for _ in range(20):
        theta, vel = rng.normal(size=3), rng.normal(size=3)
        expected = _dexpinv_matrix(ad2)(theta, vel, degree)
        np.testing.assert_allclose(_dexpinv_se2(theta, vel, degree), expected, atol=1e-14)


@pytest.mark.parametrize("degree", [4, 6])
def test_se3_scalar_series_equals_the_series_on_pinocchio_ad_matrices(degree):
    """The scalar se(3) dexp^-1 equals the series on Pinocchio's ad matrix (Motion.action), to ad^4 and ad^6."""
    rng = np.random.default_rng(2)
    reference = _dexpinv_matrix(lambda t: pin.Motion(t).action)
    for _ in range(20):
        theta, vel = rng.normal(size=6), rng.normal(size=6)
        np.testing.assert_allclose(_dexpinv_se3(theta, vel, degree), reference(theta, vel, degree), atol=1e-13)


def test_series_sums_to_the_closed_form_dexp_inverse_on_so3():
    """To ad^6 the series matches the closed-form so(3) dexp^-1 better than to ad^4 (error O(|theta|^8))."""
    rng = np.random.default_rng(4)
    theta, vel = 0.3 * rng.normal(size=3), rng.normal(size=3)
    a = np.linalg.norm(theta)
    W = skew(theta)
    exact = vel + 0.5 * W @ vel + (1 - a / 2 / np.tan(a / 2)) / a**2 * W @ W @ vel  # dexp^-1_{-theta}
    errors = [np.linalg.norm(_dexpinv_matrix(skew)(theta, vel, d) - exact) for d in (4, 6)]
    assert errors[1] < errors[0] / 20.0


def test_chart_correction_refuses_an_unsupported_degree():
    """A series degree other than 4 or 6 is refused, naming the degree."""
    with pytest.raises(ValueError, match="must be 4 or 6, got 5"):
        ChartCorrection(pin.buildSampleModelManipulator(), degree=5)


def test_unknown_integrator_lists_the_valid_names():
    """An unknown integrator name is rejected with the registry's names."""
    from freefloat.dynamics.integrators import INTEGRATORS
    from freefloat.errors import UnknownName

    model = pin.buildSampleModelManipulator()
    with pytest.raises(UnknownName, match="unknown integrator 'rk45'; did you mean 'rkmk4'\\? \\(valid: euler, "
                                          "explicit_euler, rkmk3, rkmk4, rk4_naive, rkmk6, rkmk8, dopri5, bs32, dop853\\)$"):
        make_integrator("rk45", model)
    assert len(INTEGRATORS) == 10


def test_the_compiled_loops_have_the_registrys_compiled_integrators():
    """The C++ side's integrator names (cpp/sim/rkmk.hpp) are the registry's compiled ones."""
    from freefloat.dynamics import _sim
    from freefloat.dynamics.integrators import INTEGRATORS

    assert list(_sim.INTEGRATORS) == [name for name, spec in INTEGRATORS.items() if spec.compiled]


class Heun:
    """A toy integrator (Heun's 2nd-order method, plain sums: Euclidean coordinates or small angles)."""

    name, order = "toy_heun", 2

    def __init__(self, model, substeps: int = 1):
        self.model, self.substeps, self.calls = model, substeps, 0

    def evaluations(self) -> int:
        return self.calls

    def advance(self, f, q, v, duration):
        h = duration / self.substeps
        for _ in range(self.substeps):
            a1 = f(q, v)
            q1, v1 = pin.integrate(self.model, q, h * v), v + h * a1
            a2 = f(q1, v1)
            q, v = pin.integrate(self.model, q, 0.5 * h * (v + v1)), v + 0.5 * h * (a1 + a2)
            self.calls += 2
        return q, v


@pytest.fixture
def toy_heun(monkeypatch):
    """Heun registered for the duration of one test: one registry line, nothing else edited."""
    from freefloat.dynamics.integrators import INTEGRATORS, IntegratorSpec

    spec = IntegratorSpec("toy_heun", "Heun, a toy", order=2, stages=2, lie=False, adaptive=False, compiled=False,
                          build=lambda model, substeps, rtol, atol: Heun(model, substeps))
    monkeypatch.setitem(INTEGRATORS, spec.name, spec)
    return spec


def test_a_registered_integrator_runs_in_simulate_batch_and_bench(toy_heun, tmp_path):
    """A toy integrator registered with one line is accepted by robot and mechanism scenes (run
    through the one loop in Python), runs every run of a batch, and is swept by freefloat bench."""
    from freefloat.app import runner
    from freefloat.app.batch import run_batch
    from freefloat.app.scenes import load_scene
    from freefloat.lab.bench.scenes.methods import methods

    from .conftest import scene_variant

    robot = load_scene(scene_variant(tmp_path / "r.toml", "tumbling",
                                     simulation={"duration": 0.01, "integrator": "toy_heun"}))
    outcome = runner.simulate(robot)
    assert outcome.status == "completed" and outcome.summary["momentum_drift_max"] < 1e-6
    mechanism = load_scene(scene_variant(tmp_path / "m.toml", "five_bar_computed_torque",
                                         simulation={"duration": 0.002, "integrator": "toy_heun"}))
    chain = runner.simulate(mechanism)
    assert chain.status == "completed" and chain.summary["loop"] == "python"
    assert chain.summary["loop_closure_drift_max"] < 1e-6
    batch = run_batch(robot, tmp_path / "batch", 2, [])
    assert [row["status"] for row in batch.rows] == ["completed", "completed"]
    assert any(m.integrator == "toy_heun" and m.loop == "python" for m in methods((1e-3,), (1e-6,)))


def test_explicit_euler_is_first_order(tumbling):
    """Halving the explicit Euler step halves the error (first order), like the semi-implicit one."""
    e = errors(tumbling, "explicit_euler", [2000, 4000, 8000])
    assert 1.7 < e[1] / e[2] < 2.3


def test_dop853_in_the_chart_ends_at_the_tight_reference(tumbling):
    """scipy's DOP853 stepped in the Munthe-Kaas chart (one chart over 0.1 s periods) ends within
    1e-8 of dopri5's rtol-1e-13 run on the Lie group: the chart and dexp^-1 are right."""
    robot, f, q0, v0, (q_ref, v_ref) = tumbling
    integrator = make_integrator("dop853", robot.model, rtol=1e-12, atol=1e-12)
    q, v = q0, v0
    for _ in range(10):
        q, v = integrator.advance(f, q, v, 0.1)
    error = np.linalg.norm(np.concatenate((pin.difference(robot.model, q_ref, q), v - v_ref)))
    assert error < 1e-8 and integrator.evaluations() > 0


@pytest.mark.parametrize("options, named", [({"substeps": None}, "substeps"), ({"substeps": 0}, "substeps"),
                                            ({"substeps": 10**7}, "substeps"), ({"rtol": float("nan")}, "rtol"),
                                            ({"rtol": 0.0}, "rtol"), ({"rtol": 1e-300}, "rtol"), ({"atol": -1.0}, "atol")])
def test_bad_integrator_settings_are_refused_naming_them(options, named):
    """make_integrator refuses a substep count or tolerance it cannot use with InvalidArgument
    naming it (a TypeError from a comparison, a bare ValueError, or a tolerance below a double's
    resolution accepted, before)."""
    from freefloat import InvalidArgument

    with pytest.raises(InvalidArgument, match=f"'{named}' must be"):
        make_integrator("dopri5" if "tol" in named else "rkmk4", pin.buildSampleModelHumanoidRandom(), **options)


@pytest.mark.parametrize("space", [None, "ur5", {}])
def test_make_integrator_refuses_a_space_that_is_not_a_pinocchio_model(space):
    """An integrator on None, a robot's name or a dict is refused naming 'model' and what it takes."""
    from freefloat.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match="'model' takes a pinocchio.Model"):
        make_integrator("rkmk4", space)


def forced_oscillator(t: float, x0: float, v0: float) -> np.ndarray:
    """The closed form of x'' = -x + cos(2 t) from (x0, v0) at 0: [x(t), x'(t)]."""
    a = x0 + 1.0 / 3.0
    return np.array([a * np.cos(t) + v0 * np.sin(t) - np.cos(2.0 * t) / 3.0,
                     -a * np.sin(t) + v0 * np.cos(t) + 2.0 * np.sin(2.0 * t) / 3.0])


def forced_errors(name: str, f, substeps=(8, 16), rtol=1e-9) -> np.ndarray:
    """|x - x(1)| + |v - v(1)| of x'' = -x + cos(2 t) (``f``) over 1 s on a prismatic joint from
    (0.3, -0.2), at each of ``substeps`` (fixed-step) or once at ``rtol`` (adaptive)."""
    space, q0, v0 = vector_space(1), np.array([0.3]), np.array([-0.2])
    exact = forced_oscillator(1.0, 0.3, -0.2)
    if INTEGRATORS[name].adaptive:
        runs = [make_integrator(name, space, rtol=rtol, atol=rtol).advance(f, q0, v0, 1.0)]
    else:
        runs = [make_integrator(name, space, substeps=n).advance(f, q0, v0, 1.0) for n in substeps]
    return np.array([np.abs(np.concatenate((q, v)) - exact).sum() for q, v in runs])


@pytest.mark.parametrize("name", list(INTEGRATORS))
def test_every_integrator_evaluates_a_time_varying_acceleration_at_its_stage_times(name):
    """On x'' = -x + cos(2 t), a TimeVarying acceleration, each integrator keeps its order
    (halving the step divides the error by at least 2^order / 1.25; an adaptive one lands within
    10 rtol of the closed form); with the time held at the call's start it is wrong at first order."""
    timed = TimeVarying(lambda t, q, v: -q + np.cos(2.0 * t))
    held = lambda q, v: -q + 1.0  # noqa: E731  the acceleration at the call's start, held
    spec = INTEGRATORS[name]
    if spec.adaptive:
        assert forced_errors(name, timed)[0] < 1e-8
        assert forced_errors(name, held)[0] > 0.1
    else:
        e, e_held = forced_errors(name, timed), forced_errors(name, held)
        assert e[0] / e[1] > 2.0**spec.order / 1.25
        assert e_held[0] / e_held[1] < 2.5 and e_held[1] > 1e-3


@pytest.mark.parametrize("name", ["rkmk4", "dopri5"])
def test_an_acceleration_that_ignores_time_steps_as_an_autonomous_one(tumbling, name):
    """A TimeVarying acceleration that ignores t gives the autonomous f(q, v)'s states bit for bit
    (the same arithmetic: the stage times never enter the state), fixed-step and adaptive."""
    robot, f, q0, v0, _ = tumbling
    plain = make_integrator(name, robot.model, substeps=10).advance(f, q0, v0, 0.5)
    timed = make_integrator(name, robot.model, substeps=10).advance(TimeVarying(lambda t, q, v: f(q, v)), q0, v0, 0.5)
    np.testing.assert_array_equal(plain[0], timed[0])
    np.testing.assert_array_equal(plain[1], timed[1])
