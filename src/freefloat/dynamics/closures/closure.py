"""One loop closure between two frames of a Pinocchio tree: its residual, Jacobian and the
acceleration drift term, from Pinocchio's kinematics (numpy; the readable reference).

With ``oM1 = (R1, p1)``, ``oM2 = (R2, p2)`` the closure frames, ``d = p2 - p1``, world angular
velocities ``w1, w2`` and ``dw = w2 - w1``, the rows are, in frame 1's axes,

.. math::
    e_p = R_1^T d, \\qquad \\dot e_p = R_1^T(\\dot d - \\omega_1 \\times d), \\qquad
    \\dot e_r = S\\,R_1^T \\Delta\\omega,

so ``J = [R1^T (J_2^L - J_1^L) + [e_p]_x R1^T J_1^A; S R1^T (J_2^A - J_1^A)]`` and, from the
classical accelerations at zero joint acceleration (superscript 0),

.. math::
    \\gamma_p = R_1^T(\\ddot d^0 - \\dot\\omega_1^0 \\times d - 2\\omega_1 \\times \\dot d
    + \\omega_1 \\times (\\omega_1 \\times d)), \\qquad
    \\gamma_r = S R_1^T (\\Delta\\dot\\omega^0 - \\omega_1 \\times \\Delta\\omega),

with ``J a + gamma`` the rows' second derivative. ``S`` picks the kind's rotation rows. The
orientation residual is ``log3(R1^T R2)`` (weld) or the tilt of frame 2's z axis,
``z x (R1^T R2 z)`` rows x, y (revolute): both the rotation rows' angle to first order.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ...robot.conventions import skew
from .kinds import ClosureKind


@dataclass(frozen=True)
class Closure:
    """A closure between frame 1 (``placement1`` on joint ``joint1``) and frame 2.

    Attributes:
        name: what messages call it (e.g. ``closures[0]`` or ``left_tool0-grasp``).
        kind: what it stops.
        joint1, joint2: Pinocchio joint ids the frames hang on (0: the inertial frame).
        placement1, placement2: the frames in their joints' frames.
        frames: the two frame names.
    """

    name: str
    kind: ClosureKind
    joint1: int
    placement1: pin.SE3
    joint2: int
    placement2: pin.SE3
    frames: tuple[str, str] = ("", "")

    @property
    def size(self) -> int:
        """Constraint rows."""
        return self.kind.size

    @classmethod
    def between(cls, model: pin.Model, frame1: str, frame2: str, kind: ClosureKind, name: str = "") -> Closure:
        """The closure between two frames of ``model`` (names it knows)."""
        f1, f2 = (model.frames[model.getFrameId(f)] for f in (frame1, frame2))
        return cls(name or f"{frame1}-{frame2}", kind, f1.parentJoint, f1.placement, f2.parentJoint, f2.placement,
                   (frame1, frame2))


@dataclass
class ClosureRows:
    """A closure evaluated at one state (m = ``closure.size`` rows, frame 1 axes).

    Attributes:
        residual: position-level error (m,): ``e_p`` (m) then the rotation rows' angle (rad).
        jacobian: ``d e / dt = J v`` (m, nv).
        drift: ``gamma`` (m,): the rows' second derivative at zero acceleration.
        rotation1: ``R1``, frame 1's orientation (3, 3).
    """

    residual: np.ndarray
    jacobian: np.ndarray
    drift: np.ndarray
    rotation1: np.ndarray


class FrameMotion(NamedTuple):
    """A frame's motion at one state, world axes.

    Attributes:
        pose: ``oMf``.
        velocity: linear velocity of the frame origin, m/s (3,).
        angular_velocity: rad/s (3,).
        acceleration: classical linear acceleration of the origin at zero joint acceleration (3,).
        angular_acceleration: angular acceleration at zero joint acceleration (3,).
        jacobian: ``[linear; angular]`` rows (6, nv): velocity = ``jacobian @ v``.
    """

    pose: pin.SE3
    velocity: np.ndarray
    angular_velocity: np.ndarray
    acceleration: np.ndarray
    angular_acceleration: np.ndarray
    jacobian: np.ndarray


def frame_motion(model: pin.Model, data: pin.Data, joint: int, placement: pin.SE3) -> FrameMotion:
    """The motion of the frame ``placement`` on ``joint`` (its acceleration ``J a`` + the returned
    drift for a joint acceleration ``a``). Needs :func:`kinematics` on ``data``."""
    oMf = data.oMi[joint] * placement
    R = oMf.rotation
    velocity = placement.actInv(data.v[joint])  # LOCAL
    acc = placement.actInv(data.a[joint])
    J_local = placement.inverse().action @ pin.getJointJacobian(model, data, joint, pin.LOCAL)
    return FrameMotion(oMf, R @ velocity.linear, R @ velocity.angular,
                       R @ (acc.linear + np.cross(velocity.angular, velocity.linear)), R @ acc.angular,
                       np.vstack((R @ J_local[:3], R @ J_local[3:])))


def evaluate(closure: Closure, model: pin.Model, data: pin.Data, drift: bool = True) -> ClosureRows:
    """The closure's rows at the state ``data`` holds.

    ``data`` must have had ``pin.forwardKinematics(model, data, q, v, 0 * v)`` and
    ``pin.computeJointJacobians(model, data, q)`` (:func:`kinematics`).
    """
    M1, v1, w1, a1, al1, J1 = frame_motion(model, data, closure.joint1, closure.placement1)
    M2, v2, w2, a2, al2, J2 = frame_motion(model, data, closure.joint2, closure.placement2)
    R1t = M1.rotation.T
    d, d_dot = M2.translation - M1.translation, v2 - v1
    e_p = R1t @ d
    rows = list(closure.kind.rotation_rows)
    J_p = R1t @ (J2[:3] - J1[:3]) + skew(e_p) @ R1t @ J1[3:]
    J_r = (R1t @ (J2[3:] - J1[3:]))[rows]
    relative = R1t @ M2.rotation
    if len(rows) == 3:
        e_r = pin.log3(relative)
    else:
        e_r = np.cross([0.0, 0.0, 1.0], relative[:, 2])[rows]
    gamma = None
    if drift:
        dw = w2 - w1
        g_p = R1t @ (a2 - a1 - np.cross(al1, d) - 2.0 * np.cross(w1, d_dot) + np.cross(w1, np.cross(w1, d)))
        g_r = (R1t @ (al2 - al1 - np.cross(w1, dw)))[rows]
        gamma = np.concatenate((g_p, g_r))
    return ClosureRows(np.concatenate((e_p, e_r)), np.vstack((J_p, J_r)), gamma, M1.rotation)


def kinematics(model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray) -> None:
    """What :func:`evaluate` reads: joint placements, velocities, accelerations at zero joint
    acceleration, and the joint Jacobians, at ``(q, v)``."""
    pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
    pin.computeJointJacobians(model, data, q)


def stacked(closures: list[Closure] | tuple[Closure, ...], model: pin.Model, data: pin.Data,
            drift: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """``(e, J, gamma)`` of all closures stacked in order: (m,), (m, nv), (m,) or None.
    ``data`` as :func:`evaluate` needs it."""
    rows = [evaluate(c, model, data, drift) for c in closures]
    if not rows:
        return np.zeros(0), np.zeros((0, model.nv)), (np.zeros(0) if drift else None)
    return (np.concatenate([r.residual for r in rows]), np.vstack([r.jacobian for r in rows]),
            np.concatenate([r.drift for r in rows]) if drift else None)
