"""A robot scene's ``[[closures]]``: loop closures between frames of its robot, active from the
start (:mod:`freefloat.dynamics.closures`). The scene's initial joint positions are where the
loop is assembled from (Gauss-Newton on the joint coordinates, the base held) and its initial
velocity is projected onto the velocities the closed loop allows (least change)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...dynamics.closures import Closure, closure_kind, kinematics, stacked
from ...errors import SceneError, did_you_mean
from ...robot.robot import Robot
from ..scenes import Scene

#: Assembly: largest residual accepted (m and rad), and most Gauss-Newton steps.
ASSEMBLY_TOLERANCE = 1e-10
ASSEMBLY_STEPS = 100


def where_of(scene: Scene) -> str:
    """How messages name the scene: its file, or its name."""
    return f"{scene.source}: " if scene.source else f"scene '{scene.name}': "


def scene_closures(scene: Scene, robot: Robot) -> list[Closure]:
    """The scene's closures on ``robot``'s frames.

    Raises:
        SceneError: naming ``closures[i].frames`` for a frame the robot does not have (with the
            nearest frames it has), ``closures[i].kind`` for an unknown kind.
    """
    model, out = robot.model, []
    for i, spec in enumerate(scene.closures):
        kind = closure_kind(spec.kind)
        for name in spec.frames:
            if not model.existFrame(name):
                raise SceneError(f"{where_of(scene)}'closures[{i}].frames' names '{name}', which is no frame of "
                                 f"{robot.urdf_path.name}{did_you_mean(name, [f.name for f in model.frames], 'frames')}")
        out.append(Closure.between(model, spec.frames[0], spec.frames[1], kind, f"closures[{i}]"))
    return out


def assemble(scene: Scene, robot: Robot, closures: list[Closure], q0: np.ndarray, v0: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """``(q, v)``: ``q0`` with its joints moved until every closure holds, and ``v0`` projected on
    the velocities that keep them (module docstring).

    Raises:
        SceneError: naming the closure with the largest residual when the loop cannot be assembled
            from the scene's initial joints.
    """
    model, data, nb = robot.model, robot.model.createData(), robot.n_base
    q = q0.copy()
    for _ in range(ASSEMBLY_STEPS):
        kinematics(model, data, q, np.zeros(model.nv))
        e, J, _ = stacked(closures, model, data, drift=False)
        if np.abs(e).max(initial=0.0) <= ASSEMBLY_TOLERANCE:
            break
        step = np.zeros(model.nv)
        step[nb:] = -np.linalg.lstsq(J[:, nb:], e, rcond=1e-10)[0]
        q = pin.integrate(model, q, step)
    else:
        worst = int(np.argmax([np.abs(stacked([c], model, data, drift=False)[0]).max() for c in closures]))
        residual = np.abs(stacked([closures[worst]], model, data, drift=False)[0]).max()
        raise SceneError(f"{where_of(scene)}'closures[{worst}]' ({' - '.join(closures[worst].frames)}, "
                         f"{closures[worst].kind.name}) cannot be assembled from [initial]: residual {residual:.3g} "
                         f"after {ASSEMBLY_STEPS} Gauss-Newton steps on the joints; start the joints nearer a pose "
                         "where the loop closes")
    kinematics(model, data, q, v0)
    J = stacked(closures, model, data, drift=False)[1]
    return q, v0 - np.linalg.pinv(J, rcond=1e-10) @ (J @ v0)
