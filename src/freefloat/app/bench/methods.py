"""The methods a bench sweeps: freefloat's integrators in its Python and compiled loops, a bare
Python loop of Pinocchio calls, and MuJoCo's integrators; each a callable that runs a
:class:`.scenes.TumblingScene` from its initial state and returns the final Pinocchio state."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import pinocchio as pin

from ...dynamics.compiled import CompiledLoop
from ...dynamics.integrators import make_integrator
from ...dynamics.telemetry import Telemetry
from .mjcf import mjcf_from_model
from .mujoco_state import from_mujoco, to_mujoco
from .scenes import TumblingScene

#: freefloat's fixed-step integrators and its adaptive one, in the Python loop and in the compiled one.
FREEFLOAT_FIXED = ("euler", "rkmk4", "rk4_naive")
FREEFLOAT_ADAPTIVE = ("dopri5",)
COMPILED_FIXED = ("euler", "rkmk4", "rkmk6", "rkmk8")
COMPILED_ADAPTIVE = ("dopri5",)
#: MuJoCo's integrators compared (names as in MJCF).
MUJOCO = ("Euler", "implicitfast", "RK4")
#: Tolerances of the reference run (dopri5 on the group).
REFERENCE_RTOL, REFERENCE_ATOL = 1e-13, 1e-15

Run = Callable[[], tuple[np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class Method:
    """One point of a sweep.

    Attributes:
        package: ``"freefloat"``, ``"pinocchio"`` (a bare Python loop of its calls) or ``"mujoco"``.
        integrator: integrator name in that package.
        setting: step h in s (fixed-step) or rtol (adaptive).
        loop: freefloat's ``"python"`` or ``"compiled"`` loop (``"python"`` for the others).
    """

    package: str
    integrator: str
    setting: float
    loop: str = "python"

    @property
    def label(self) -> str:
        """``package integrator [compiled]``, the curve a point belongs to."""
        return f"{self.package} {self.integrator}" + (" compiled" if self.loop == "compiled" else "")


def _torque_free(model: pin.Model) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    data, tau = model.createData(), np.zeros(model.nv)
    return lambda q, v: pin.aba(model, data, q, v, tau)


def _steps(scene: TumblingScene, h: float) -> int:
    """Number of equal steps of about ``h`` that fill the scene's duration."""
    return max(1, round(scene.duration / h))


def freefloat_run(scene: TumblingScene, integrator: str, setting: float) -> Run:
    """Run of freefloat's ``integrator`` at step ``setting`` (s), or for dopri5 at rtol ``setting``
    and atol ``setting / 100``; built fresh each call, so dopri5 carries no step size over."""
    f = _torque_free(scene.model)

    def run():
        if integrator in FREEFLOAT_ADAPTIVE:
            stepper = make_integrator(integrator, scene.model, rtol=setting, atol=setting * 1e-2)
        else:
            stepper = make_integrator(integrator, scene.model, substeps=_steps(scene, setting))
        return stepper.advance(f, scene.q0, scene.v0, scene.duration)

    return run


def compiled_run(scene: TumblingScene, integrator: str, setting: float) -> Run:
    """Run of freefloat's compiled loop (:mod:`freefloat.dynamics.compiled`) with ``integrator`` at
    step ``setting`` (s), or for dopri5 at rtol ``setting`` and atol ``setting / 100`` over one
    period; built once (like MuJoCo's model), started afresh each call (dopri5 from its first step
    guess)."""
    if integrator in COMPILED_ADAPTIVE:
        n, stepper = 1, make_integrator(integrator, scene.model, rtol=setting, atol=setting * 1e-2)
    else:
        n, stepper = _steps(scene, setting), make_integrator(integrator, scene.model)
    loop = CompiledLoop(scene.robot, stepper, scene.duration / n, record_every=n)
    robot = scene.robot
    chunk = Telemetry.allocate(1, robot.model.nq, robot.model.nv, robot.n_joints, len(robot.end_effectors))

    def run():
        loop.start(scene.q0, scene.v0)
        try:
            loop.run(n, chunk, 0)
        except RuntimeError as exc:  # the loop's blow-up check
            raise FloatingPointError(str(exc)) from exc
        return loop.state

    return run


def pinocchio_run(scene: TumblingScene, h: float) -> Run:
    """A bare Python loop of Pinocchio calls at step ``h``: semi-implicit Euler, ``pin.aba`` and
    ``pin.integrate`` and nothing else (the floor of any Python-side loop)."""
    model, n = scene.model, _steps(scene, h)
    data, tau, dt = model.createData(), np.zeros(model.nv), scene.duration / n

    def run():
        q, v = scene.q0, scene.v0
        for _ in range(n):
            v = v + dt * pin.aba(model, data, q, v, tau)
            q = pin.integrate(model, q, dt * v)
        return q, v

    return run


def mujoco_run(scene: TumblingScene, integrator: str, h: float) -> Run:
    """Run of MuJoCo's ``integrator`` at step ``h`` on the scene's model (a Python loop of
    ``mj_step``), from the scene's initial state mapped to MuJoCo's convention.

    The run raises ``FloatingPointError`` when MuJoCo met a non-finite or huge acceleration (it
    then silently resets the state to the model's rest state and goes on).
    """
    import mujoco

    n = _steps(scene, h)  # timestep duration / n, as freefloat's substeps: both end at the same time
    model = mujoco.MjModel.from_xml_string(mjcf_from_model(scene.model, scene.name, scene.duration / n, integrator))
    data = mujoco.MjData(model)
    qpos, qvel = to_mujoco(scene.q0, scene.v0)

    def run():
        mujoco.mj_resetData(model, data)
        data.qpos[:], data.qvel[:] = qpos, qvel
        handler = mujoco.get_mju_user_warning()
        mujoco.set_mju_user_warning(lambda message: None)  # read from data.warning below, no MUJOCO_LOG.TXT
        try:
            for _ in range(n):
                mujoco.mj_step(model, data)
        finally:
            mujoco.set_mju_user_warning(handler)
        if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:  # MuJoCo reset the state and went on
            raise FloatingPointError(f"MuJoCo {integrator} at h = {h} s went unstable (bad qacc) on {scene.name}")
        return from_mujoco(data.qpos.copy(), data.qvel.copy())

    return run


def method_run(scene: TumblingScene, method: Method) -> Run:
    """The run of ``method`` on ``scene``."""
    if method.package == "mujoco":
        return mujoco_run(scene, method.integrator, method.setting)
    if method.package == "pinocchio":
        return pinocchio_run(scene, method.setting)
    if method.loop == "compiled":
        return compiled_run(scene, method.integrator, method.setting)
    return freefloat_run(scene, method.integrator, method.setting)


def reference(scene: TumblingScene) -> tuple[np.ndarray, np.ndarray]:
    """Final state by freefloat's dopri5 at rtol 1e-13, atol 1e-15."""
    stepper = make_integrator("dopri5", scene.model, rtol=REFERENCE_RTOL, atol=REFERENCE_ATOL)
    return stepper.advance(_torque_free(scene.model), scene.q0, scene.v0, scene.duration)


def methods(steps: tuple[float, ...], rtols: tuple[float, ...]) -> list[Method]:
    """Every method of a sweep: each fixed-step integrator at each step (freefloat's Python and
    compiled loops, the bare Pinocchio loop, MuJoCo), dopri5 at each rtol in both loops."""
    points = [Method("freefloat", name, h) for name in FREEFLOAT_FIXED for h in steps]
    points += [Method("freefloat", name, rtol) for name in FREEFLOAT_ADAPTIVE for rtol in rtols]
    points += [Method("freefloat", name, h, "compiled") for name in COMPILED_FIXED for h in steps]
    points += [Method("freefloat", name, rtol, "compiled") for name in COMPILED_ADAPTIVE for rtol in rtols]
    points += [Method("pinocchio", "euler", h) for h in steps]
    return points + [Method("mujoco", name, h) for name in MUJOCO for h in steps]
