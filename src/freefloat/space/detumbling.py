"""The post-capture detumbling solver (dissertation sec 3.8.1, eqs 115-120 and 134).

With total momentum M (about the base CoM, inertial frame), end-effector velocities are
``x_Edot = J* qdot + J0E H0^-1 M`` (eq 115). Detumbling asks for joint rates that zero chosen
end-effector velocity components ``k`` (rows of the stacked ``[v_E; w_E]`` per end-effector)
using chosen mission joints S:

.. math:: J^*\\{k, S\\}\\, \\dot q_S = -J_{0E}\\{k\\} H_0^{-1} M, \\qquad \\dot q_{\\bar S} = 0.

Methods: ``single`` (one row, one mission joint: eq 120, ``qdot_j = b0 / a_j``),
``min_norm`` (the least-norm exact solution, eq 134 with a pseudo-inverse), ``null_space``
(the min-norm solution plus the null-space motion that minimises a secondary objective: the
base angular velocity or the base twist), ``least_squares`` (more rows than joints: the
least-squares compromise, which leaves a residual).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dynamics.gjm import GJMState
from ..errors import UnknownName, did_you_mean
from ..robot.robot import Robot

COMPONENTS = {"vx": 0, "vy": 1, "vz": 2, "wx": 3, "wy": 4, "wz": 5}
METHODS = ("single", "min_norm", "null_space", "least_squares")
SECONDARY = ("base_angular_velocity", "base_twist")


@dataclass(frozen=True)
class DetumblingSolution:
    """Joint rates and what they achieve.

    Attributes:
        qdot: joint rates (n,), zero outside the mission joints, rad/s or m/s.
        residual: ``J*{k} qdot + J0E{k} H0^-1 M`` (len(k),): the remaining velocity of the rows.
        base_twist: the base twist ``[v0; w0]`` of the base CoM, inertial frame, that these rates
            give with momentum M (6,).
        rows: the stacked row indices k into the 6k rows [v_E; w_E] per end-effector (r,).
        joints: the mission joint indices S into the actuated joints (s,).
    """

    qdot: np.ndarray
    residual: np.ndarray
    base_twist: np.ndarray
    rows: np.ndarray
    joints: np.ndarray


def task_rows(robot: Robot, spec: list[tuple[str, str]]) -> np.ndarray:
    """Stacked row indices for ``[(end_effector, component), ...]``; components vx..wz, or
    ``"angular"`` / ``"linear"`` / ``"all"`` for three or six rows.

    Raises:
        ValueError: naming an unknown end-effector or component.
    """
    groups = {"angular": ("wx", "wy", "wz"), "linear": ("vx", "vy", "vz"), "all": tuple(COMPONENTS)}
    rows = []
    for ee, component in spec:
        if ee not in robot.end_effectors:
            raise ValueError(f"no end-effector '{ee}'{did_you_mean(ee, robot.end_effectors, 'end-effectors')}")
        names = groups.get(component, (component,))
        for name in names:
            if name not in COMPONENTS:
                raise ValueError(f"unknown component '{component}' of '{ee}'"
                                 f"{did_you_mean(component, (*COMPONENTS, *groups), 'use')}")
            rows.append(6 * robot.end_effectors.index(ee) + COMPONENTS[name])
    return np.array(rows, dtype=int)


def joint_indices(robot: Robot, names: list[str] | None) -> np.ndarray:
    """Indices of mission joints by name (all joints when None).

    Raises:
        ValueError: naming a joint that does not exist.
    """
    if names is None:
        return np.arange(robot.n_joints)
    out = []
    for name in names:
        if name not in robot.joint_names:
            raise ValueError(f"no joint '{name}'{did_you_mean(name, robot.joint_names, 'joints')}")
        out.append(robot.joint_names.index(name))
    return np.array(out, dtype=int)


def check_task(rows: np.ndarray, joints: np.ndarray, method: str = "min_norm",
               secondary: str = "base_angular_velocity") -> None:
    """The rules of :func:`solve` that do not depend on the state.

    Raises:
        ValueError: unknown method or secondary objective; ``single`` without exactly one row and
            one joint; more rows than joints without ``least_squares``.
    """
    if method not in METHODS:
        raise UnknownName("method", method, METHODS)
    if secondary not in SECONDARY:
        raise UnknownName("secondary objective", secondary, SECONDARY)
    if method == "single" and (len(rows), len(joints)) != (1, 1):
        raise ValueError(f"method 'single' (eq 120) takes one row and one mission joint, got {len(rows)} and {len(joints)}")
    if method not in ("single", "least_squares") and len(rows) > len(joints):
        raise ValueError(f"{len(rows)} task rows but {len(joints)} mission joints: use method='least_squares' "
                         "or add joints")


def solve(state: GJMState, rows: np.ndarray, joints: np.ndarray, method: str = "min_norm",
          secondary: str = "base_angular_velocity", rcond: float = 1e-10) -> DetumblingSolution:
    """Joint rates that stop the rows ``rows`` given the state's momentum.

    Raises:
        ValueError: unknown method or secondary objective; ``single`` without exactly one row
            and one joint, or with a mission joint that cannot move the row; more rows than
            joints without ``least_squares``.
    """
    check_task(rows, joints, method, secondary)
    drift = state.J0E[rows] @ np.linalg.solve(state.H0, state.momentum_base)   # J0E{k} H0^-1 M
    A = state.Jstar[np.ix_(rows, joints)]
    if method == "single":
        if abs(A[0, 0]) < rcond * max(1.0, np.abs(state.Jstar).max()):
            raise ValueError(f"mission joint {joints[0]} does not move row {rows[0]} (coefficient {A[0, 0]:.2e}): choose another")
        qS = -drift / A[0, 0]
    else:
        pinv = np.linalg.pinv(A, rcond=rcond)
        qS = -pinv @ drift
        if method == "null_space":
            qS = qS + _null_space_step(state, A, pinv, joints, qS, secondary, rcond)
    qdot = np.zeros(state.Jstar.shape[1])
    qdot[joints] = qS
    base = state.J0 @ qdot + np.linalg.solve(state.H0, state.momentum_base)
    return DetumblingSolution(qdot=qdot, residual=state.Jstar[rows] @ qdot + drift, base_twist=base,
                              rows=rows, joints=joints)


def _null_space_step(state: GJMState, A: np.ndarray, pinv: np.ndarray, joints: np.ndarray,
                     qS: np.ndarray, secondary: str, rcond: float) -> np.ndarray:
    """Null-space motion of A minimising the base angular velocity (or whole twist).

    ``C N`` is rank-deficient whenever the spare joints cannot move every component of the
    objective; its pseudo-inverse drops singular values up to ``rcond`` times the largest, as the
    main solve does (numpy's default cut, 1e-15, kept round-off values near 1e-15 and returned
    rates of hundreds of rad/s)."""
    N = np.eye(len(joints)) - pinv @ A
    sel = slice(3, 6) if secondary == "base_angular_velocity" else slice(0, 6)
    C = state.J0[sel][:, joints]
    d = C @ qS + np.linalg.solve(state.H0, state.momentum_base)[sel]
    z = -np.linalg.pinv(C @ N, rcond=rcond) @ d
    return N @ z
