"""The methods a bench sweeps: freefloat's integrators in its Python and compiled loops, a bare
Python loop of Pinocchio calls, and MuJoCo's integrators; each a callable that runs a
:class:`.tumbling.TumblingScene` from its initial state and returns the final Pinocchio state."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ....dynamics.compiled import CompiledLoop, law_of
from ....dynamics.integrators import INTEGRATORS, Acceleration, make_integrator, swept
from ....dynamics.models import DynamicsModel, make_model
from ....dynamics.simulation import run as simulate
from ....dynamics.telemetry import Telemetry
from ..in_mujoco.mjcf import mjcf_from_model
from ..in_mujoco.state import from_mujoco, to_mujoco
from ..in_mujoco.wrenches import MujocoWrenches
from ..race.scene import Method, Run
from .controlled import ControlledScene, mujoco_law, periods, substeps
from .tumbling import TumblingScene

Scene = TumblingScene | ControlledScene

#: MuJoCo's integrators compared (names as in MJCF).
MUJOCO = ("Euler", "implicitfast", "RK4")
#: Tolerances of the reference run (dopri5 on the group; atol = rtol / 100 like every dopri5 point).
REFERENCE_RTOL, REFERENCE_ATOL = 1e-13, 1e-15


def _plant(scene: Scene, model: str) -> DynamicsModel:
    """The plant of a freefloat run: Pinocchio's ABA, or the registry model ``model``."""
    return make_model(model or "exact", scene.robot)


def torque_free(model: pin.Model) -> Acceleration:
    """``f(q, v)``: Pinocchio's ABA at zero torque (the exact plant, with nothing in between)."""
    data, tau = model.createData(), np.zeros(model.nv)
    return lambda q, v: pin.aba(model, data, q, v, tau)


def _model_torque_free(plant: DynamicsModel, nv: int) -> Acceleration:
    """``f(q, v)``: a registry model's acceleration at zero torque."""
    tau = np.zeros(nv)
    return lambda q, v: plant.acceleration(q, v, tau)


def _steps(scene: TumblingScene, h: float) -> int:
    """Number of equal steps of about ``h`` that fill the scene's duration."""
    return max(1, round(scene.duration / h))


def _stepper(scene: Scene, integrator: str, setting: float):
    """``(periods, integrator)``: fixed steps of about ``setting`` s, or dopri5 at rtol ``setting``
    and atol ``setting / 100``; a tumbling run is one period of the whole duration per step (or
    one period for dopri5), a controlled run has the scene's periods."""
    if INTEGRATORS[integrator].adaptive:
        stepper = make_integrator(integrator, scene.model, rtol=setting, atol=setting * 1e-2)
        return (periods(scene) if isinstance(scene, ControlledScene) else 1), stepper
    if isinstance(scene, ControlledScene):
        return periods(scene), make_integrator(integrator, scene.model, substeps=substeps(scene, setting))
    return _steps(scene, setting), make_integrator(integrator, scene.model)


def _controlled_run(scene: ControlledScene, integrator: str, setting: float, model: str, backend: str) -> Run:
    """Run of :func:`freefloat.dynamics.simulation.run` on a controlled scene (a fresh controller
    and integrator each call, so dopri5 carries no step size over)."""
    plant = _plant(scene, model)

    def run():
        _, stepper = _stepper(scene, integrator, setting)
        result = simulate(scene.robot, scene.q0, scene.v0, scene.duration, scene.period, stepper, plant,
                          scene.make_controller(), scene.wrenches, record_every=periods(scene), backend=backend)
        if result.status != "completed":
            raise FloatingPointError(result.message)
        return result.telemetry.q[-1], result.telemetry.v[-1]

    return run


def freefloat_run(scene: Scene, integrator: str, setting: float, model: str = "") -> Run:
    """Run of freefloat's ``integrator`` in its Python loop at step ``setting`` (s), or for dopri5
    at rtol ``setting`` and atol ``setting / 100``, on the plant ``model`` (registry name; empty:
    Pinocchio's ABA); built fresh each call, so dopri5 carries no step size over."""
    if isinstance(scene, ControlledScene):
        return _controlled_run(scene, integrator, setting, model, "python")
    f = torque_free(scene.model) if not model else _model_torque_free(_plant(scene, model), scene.model.nv)

    def run():
        if INTEGRATORS[integrator].adaptive:
            stepper = make_integrator(integrator, scene.model, rtol=setting, atol=setting * 1e-2)
        else:
            stepper = make_integrator(integrator, scene.model, substeps=_steps(scene, setting))
        return stepper.advance(f, scene.q0, scene.v0, scene.duration)

    return run


def compiled_run(scene: Scene, integrator: str, setting: float) -> Run:
    """Run of freefloat's compiled loop (:mod:`freefloat.dynamics.compiled`) with ``integrator`` at
    step ``setting`` (s), or for dopri5 at rtol ``setting`` and atol ``setting / 100``.

    When every period can run in compiled code (no controller or one with a compiled law, no
    wrenches) the loop is built once (like MuJoCo's model) and started afresh each call (dopri5
    from its first step guess); otherwise each call is :func:`freefloat.dynamics.simulation.run`
    with the controller and the wrenches in Python between compiled periods.
    """
    law = None
    if isinstance(scene, ControlledScene):
        law = law_of(scene.make_controller())
        if law is None or scene.wrenches:
            return _controlled_run(scene, integrator, setting, "", "compiled")
    n, stepper = _stepper(scene, integrator, setting)
    loop = CompiledLoop(scene.robot, stepper, scene.duration / n, record_every=n, law=law)
    robot = scene.robot
    chunk = Telemetry.allocate(1, robot.model.nq, robot.model.nv, robot.n_joints, len(robot.end_effectors))

    def run():  # a blow-up raises OverflowError, an ArithmeticError like MuJoCo's
        loop.start(scene.q0, scene.v0)
        _, blow_up = loop.run(n, chunk, 0)
        if blow_up is not None:
            raise OverflowError(blow_up)
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


def _mujoco_steps(scene: Scene, h: float, loop: str, model, data) -> None:
    """Step MuJoCo through the scene: ``n`` equal steps of a tumbling run, or per control period the
    law (a fresh freefloat controller on the mapped state, or :func:`.controlled.mujoco_law`) held
    as joint forces, and the scene's wrenches held, over the period's substeps."""
    import mujoco

    if not isinstance(scene, ControlledScene):
        for _ in range(_steps(scene, h)):
            mujoco.mj_step(model, data)
        return
    k, controller = substeps(scene, h), scene.make_controller()
    wrenches = MujocoWrenches(scene.robot, scene.wrenches,
                              lambda name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name))
    for i in range(periods(scene)):
        if loop == "native":
            mujoco.mj_forward(model, data)
            data.qfrc_applied[6:] = mujoco_law(scene, model, data)
        else:
            data.qfrc_applied[6:] = controller.torque(i * scene.period, *from_mujoco(data.qpos, data.qvel))
        if scene.wrenches:
            wrenches.apply(i * scene.period, from_mujoco(data.qpos, data.qvel)[0], data.xfrc_applied)
        for _ in range(k):
            mujoco.mj_step(model, data)


def mujoco_run(scene: Scene, integrator: str, h: float, loop: str = "python") -> Run:
    """Run of MuJoCo's ``integrator`` at step ``h`` on the scene's model (a Python loop of
    ``mj_step``; on a controlled scene the law each period, see :func:`_mujoco_steps`), from the
    scene's initial state mapped to MuJoCo's convention.

    The run raises ``FloatingPointError`` when MuJoCo met a non-finite or huge acceleration (it
    then silently resets the state to the model's rest state and goes on).
    """
    import mujoco

    # timestep as freefloat's substeps: both take equal steps that end at the same time
    dt = scene.period / substeps(scene, h) if isinstance(scene, ControlledScene) else scene.duration / _steps(scene, h)
    model = mujoco.MjModel.from_xml_string(mjcf_from_model(scene.model, scene.name, dt, integrator))
    data = mujoco.MjData(model)
    qpos, qvel = to_mujoco(scene.q0, scene.v0)

    def run():
        mujoco.mj_resetData(model, data)
        data.qpos[:], data.qvel[:] = qpos, qvel
        handler = mujoco.get_mju_user_warning()
        mujoco.set_mju_user_warning(lambda message: None)  # read from data.warning below, no MUJOCO_LOG.TXT
        try:
            _mujoco_steps(scene, h, loop, model, data)
        finally:
            mujoco.set_mju_user_warning(handler)
        if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:  # MuJoCo reset the state and went on
            raise FloatingPointError(f"MuJoCo {integrator} at h = {h} s went unstable (bad qacc) on {scene.name}")
        return from_mujoco(data.qpos.copy(), data.qvel.copy())

    return run


def method_run(scene: Scene, method: Method) -> Run:
    """The run of ``method`` on ``scene``."""
    if method.package == "mujoco":
        return mujoco_run(scene, method.integrator, method.setting, method.loop)
    if method.package == "pinocchio":
        return pinocchio_run(scene, method.setting)
    if method.loop == "compiled":
        return compiled_run(scene, method.integrator, method.setting)
    return freefloat_run(scene, method.integrator, method.setting, method.model)


def reference(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Final state by freefloat's dopri5 at rtol 1e-13, atol 1e-15 = rtol / 100, in its Python loop
    on Pinocchio's ABA (through the same zero-order hold on a controlled scene)."""
    return freefloat_run(scene, "dopri5", REFERENCE_RTOL)()


def methods(steps: tuple[float, ...], rtols: tuple[float, ...]) -> list[Method]:
    """Every method of a sweep: each fixed-step integrator at each step (freefloat's Python and
    compiled loops as the registry's ``bench`` says, the bare Pinocchio loop, MuJoCo), the adaptive
    ones at each rtol."""
    points = [Method("freefloat", name, h, loop) for loop in ("python", "compiled") for name in swept(loop, False)
              for h in steps]
    points += [Method("freefloat", name, rtol, loop) for loop in ("python", "compiled") for name in swept(loop, True)
               for rtol in rtols]
    points += [Method("pinocchio", "euler", h) for h in steps]
    return points + [Method("mujoco", name, h) for name in MUJOCO for h in steps]


def controlled_methods(steps: tuple[float, ...], rtols: tuple[float, ...]) -> list[Method]:
    """Every method of a controlled sweep: freefloat's compiled loop with each fixed-step
    integrator at each step and dopri5 at each rtol, its Python loop with rkmk4, and MuJoCo's
    integrators stepped by freefloat's controller and by the law on MuJoCo's own matrices."""
    points = [Method("freefloat", name, h, "compiled") for name in ("euler", "rkmk4", "rkmk8") for h in steps]
    points += [Method("freefloat", "dopri5", rtol, "compiled") for rtol in rtols]
    points += [Method("freefloat", "rkmk4", h) for h in steps]
    return points + [Method("mujoco", name, h, loop) for loop in ("python", "native") for name in MUJOCO for h in steps]
