"""Base parameters by QR in an order of preference: the counts a closed form gives, the base
regressor reproducing the full one on samples it never saw, the grouped combinations."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.identification.base import base_parameters, preferred_order
from freefloat.dynamics.identification.parameters import parameter_names
from freefloat.dynamics.identification.regressors import torque_regressor
from freefloat.dynamics.identification.tree import random_states, structural_base
from freefloat.errors import BadShape, InvalidArgument
from freefloat.robot.catalog import find_robot

from .conftest import random_urdf


def planar_2r(gravity: bool) -> pin.Model:
    """Two revolute joints about z, links 0.5 m along x, CoMs off the axis in x and y."""
    model = pin.Model()
    j1 = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j1")
    model.appendBodyToJoint(j1, pin.Inertia(2.0, np.array([0.2, 0.03, 0.01]), np.diag([0.01, 0.02, 0.03])), pin.SE3.Identity())
    j2 = model.addJoint(j1, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([0.5, 0.0, 0.0])), "j2")
    model.appendBodyToJoint(j2, pin.Inertia(1.0, np.array([0.25, -0.02, 0.0]), np.diag([0.01, 0.01, 0.02])), pin.SE3.Identity())
    model.gravity = pin.Motion(np.array([0.0, -9.81, 0.0]) if gravity else np.zeros(3), np.zeros(3))
    return model


@pytest.mark.parametrize(("gravity", "count"), [(True, 6), (False, 4)])
def test_planar_2r_has_the_closed_form_number_of_base_parameters(gravity, count):
    """A planar RR arm has 6 base parameters under in-plane gravity (Izz_1 + m_2 l_1^2, mx_1 +
    m_2 l_1, my_1, Izz_2, mx_2, my_2) and 4 without (first moments of link 1 never act):
    Khalil and Dombre's grouped parameters."""
    model = planar_2r(gravity)
    base = structural_base(model, np.random.default_rng(0))
    assert base.rank == count
    labels = base.labels()
    assert "j1.Izz + 0.25 j2.m" in labels
    if gravity:
        assert "j1.mcx + 0.5 j2.m" in labels


@pytest.mark.parametrize("seed", [0, 1])
def test_base_regressor_reproduces_the_full_one_on_fresh_samples(seed):
    """W_1 beta(pi) = W pi for any pi and states never used to find the base (random tree on a
    free-flyer), and the rank equals the SVD rank of the full regressor."""
    rng = np.random.default_rng(seed)
    model = pin.buildModelFromXML(random_urdf(rng, 5), pin.JointModelFreeFlyer())
    base = structural_base(model, rng, samples=60)
    W = torque_regressor(model, *random_states(model, 20, rng))
    pi = rng.normal(size=W.shape[1])
    np.testing.assert_allclose(base.regressor(W) @ base.of(pi), W @ pi, atol=1e-9 * np.abs(W @ pi).max())
    assert base.rank == np.linalg.matrix_rank(W)


def test_ur5_has_36_base_parameters_in_grouped_form():
    """The UR5 (example-robot-data, fixed base, gravity) has 36 base parameters, the count its
    6R geometry gives; the wrist's last link keeps its own mcx."""
    model = pin.buildModelFromUrdf(str(find_robot("ur5")))
    base = structural_base(model, np.random.default_rng(1))
    assert base.rank == 36
    assert "wrist_3_joint.mcx" in base.labels()


def test_preimage_gives_back_the_base_parameters():
    """Any preimage of beta has beta as its base parameters."""
    model = planar_2r(True)
    base = structural_base(model, np.random.default_rng(2))
    beta = np.random.default_rng(3).normal(size=base.rank)
    reference = np.random.default_rng(4).normal(size=len(base.names))
    np.testing.assert_allclose(base.of(base.preimage(beta, reference)), beta, atol=1e-12)
    np.testing.assert_allclose(base.of(base.preimage(beta)), beta, atol=1e-12)


def test_preferred_order_lists_each_body_reversed():
    """Body by body, Izz first and the mass last."""
    assert preferred_order(2).tolist() == [9, 8, 7, 6, 5, 4, 3, 2, 1, 0, 19, 18, 17, 16, 15, 14, 13, 12, 11, 10]


def test_bad_regressors_are_refused():
    """Too few rows, names that do not match, a zero regressor or a bad order are named."""
    names = parameter_names(planar_2r(True))
    with pytest.raises(BadShape, match="rows"):
        base_parameters(np.ones((3, 20)), names)
    with pytest.raises(BadShape, match="one column per name"):
        base_parameters(np.ones((30, 19)), names)
    with pytest.raises(InvalidArgument, match="zero"):
        base_parameters(np.zeros((30, 20)), names)
    with pytest.raises(InvalidArgument, match="order"):
        base_parameters(np.ones((30, 20)), names, order=np.zeros(20, int))
