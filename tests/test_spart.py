"""Conformance with SPART (a peer toolkit): its values on its URDFs, after a change of convention.

SPART orders twists [w; v] and uses u0 = [base angular velocity in the BASE frame; base CoM
velocity, inertial], so ``x0dot = P u0`` with ``P = [[0, I], [R0, 0]]``; its Jacobians have rows
[w; v]; its end-effector point ``rp`` is the CoM of the end-effector link (freefloat's default is
the link frame origin, so the tests add a frame there). See ``tests/data/spart/README.md``.
"""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pinocchio as pin
import pytest

from freefloat import gjm, load_robot
from freefloat.dynamics.models import ExactModel
from freefloat.dynamics.verify import relative_error
from freefloat.robot.conventions import base_acceleration, state_from_base

CASES = ["SC_3DoF", "ManiSat_2Arm_2_2", "two_iiwa_base", "kuka_iiwa"]
SWAP = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])  # [v; w] <-> [w; v]


@pytest.fixture(scope="module", params=CASES)
def case(request, spart_dir):
    """SPART's JSON, our robot (end-effector as SPART's), our state and GJM at SPART's state."""
    ref = json.loads((spart_dir / "out" / f"{request.param}.json").read_text())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = with_end_effector_at_com(load_robot(spart_dir / "urdf" / ref["urdf"], visuals=False),
                                         ref["link_names"][ref["ee_link"]])
    R0 = np.array(ref["R0"])
    u0 = np.array(ref["u0"])
    P = np.block([[np.zeros((3, 3)), np.eye(3)], [R0, np.zeros((3, 3))]])
    q, v = state_from_base(robot, np.array(ref["r0"]), R0, P @ u0, np.array(ref["qm"]), np.array(ref["um"]))
    return ref, robot, q, v, P, gjm.compute(robot, q, v)


def with_end_effector_at_com(robot, link: str):
    """The robot with one end-effector: a frame at ``link``'s CoM (SPART's rp)."""
    model = robot.model
    body = model.frames[model.getFrameId(link, pin.FrameType.BODY)]
    placement = body.placement * pin.SE3(np.eye(3), robot.link_coms[link])
    model.addFrame(pin.Frame("spart_rp", body.parentJoint, placement, pin.FrameType.OP_FRAME))
    return dataclasses.replace(robot, end_effectors=("spart_rp",))


def spart_error(ours: np.ndarray, theirs: list) -> float:
    """Relative error of our value from SPART's JSON value, reshaped to ours."""
    return relative_error(np.asarray(ours), np.array(theirs, dtype=float).reshape(np.shape(ours)))


TOL = 1e-10  # SPART agrees with Pinocchio to about 1e-14 (shared/reference/spart/README.md)


def test_inertia_matrices_match_spart(case):
    """H0, H0m (mapped to u0) and Hm equal SPART's."""
    ref, _, _, _, P, s = case
    assert spart_error(P.T @ s.H0 @ P, ref["H0"]) < TOL
    assert spart_error(P.T @ s.H0m, ref["H0m"]) < TOL
    assert spart_error(s.Hm, ref["Hm"]) < TOL


def test_generalized_inertia_and_jacobian_match_spart(case):
    """H* and the GJM of the end-effector (rows [w; v]) equal SPART's."""
    ref, _, _, _, _, s = case
    assert spart_error(s.Hstar, ref["Hstar"]) < TOL
    assert spart_error(SWAP @ s.Jstar, ref["GJM"]) < TOL


def test_end_effector_jacobians_match_spart(case):
    """SPART's J0 (base columns, u0) and Jm equal SWAP J0E P and SWAP Jm; rp is our frame origin."""
    ref, _, _, _, P, s = case
    assert spart_error(SWAP @ s.J0E @ P, ref["J0"]) < TOL
    assert spart_error(SWAP @ s.Jm, ref["Jm"]) < TOL
    assert spart_error(s.ee_position[0], ref["rp"]) < TOL


def test_momentum_matches_spart(case):
    """SPART's H0 u0 + H0m um = [R0^T L about r0; P] equals ours mapped by P^T."""
    ref, _, _, _, P, s = case
    assert spart_error(P.T @ s.momentum_base, ref["momentum"]) < TOL


def test_zero_momentum_base_velocity_matches_spart(case):
    """The base velocity of zero momentum, u0 = -H0^-1 H0m um, equals SPART's."""
    ref, _, _, _, P, s = case
    assert spart_error(np.linalg.solve(P, s.J0 @ s.qdot), ref["u0_zero_momentum"]) < TOL


def test_system_com_matches_spart(case):
    """The system CoM (inertial frame) from Pinocchio at our state equals SPART's r_com."""
    ref, robot, q, _, _, _ = case
    assert spart_error(pin.centerOfMass(robot.model, robot.model.createData(), q), ref["r_com"]) < TOL


def test_forward_dynamics_matches_spart(case):
    """Exact forward dynamics (Pinocchio ABA) under SPART's torques gives SPART's u0dot and umdot."""
    ref, robot, q, v, P, s = case
    tau = np.concatenate((np.zeros(robot.n_base), ref["taum"]))
    a = ExactModel(robot).acceleration(q, v, tau)
    x0ddot = base_acceleration(robot, q, v, a)
    R0 = s.kinematics.R0
    u0dot = np.concatenate((R0.T @ x0ddot[3:], x0ddot[:3]))  # d/dt (R0^T w0) = R0^T dw0/dt
    assert spart_error(u0dot, ref["u0dot_FD"]) < 1e-9
    assert spart_error(a[robot.n_base:], ref["umdot_FD"]) < 1e-9
