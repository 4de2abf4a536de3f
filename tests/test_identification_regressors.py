"""A tree's dynamic parameters and Pinocchio's regressors stacked over samples: the joint
torques and the momentum they give equal Pinocchio's RNEA and centroidal momentum."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.identification.parameters import (
    about_com,
    body_parameters,
    model_parameters,
    parameter_names,
    with_parameters,
)
from freefloat.dynamics.identification.regressors import momentum_regressor, torque_regressor
from freefloat.errors import BadShape
from freefloat.robot.conventions import momentum_about_origin

from .conftest import random_urdf


@pytest.fixture(scope="module", params=[0, 1, 2])
def tree(request):
    """A random tree of 6 links on a free-flyer, and random states (5 samples)."""
    rng = np.random.default_rng(request.param)
    model = pin.buildModelFromXML(random_urdf(rng, 6), pin.JointModelFreeFlyer())
    q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)) for _ in range(5)])
    return model, q, rng.normal(size=(5, model.nv)), rng.normal(size=(5, model.nv))


def test_torque_regressor_times_the_parameters_is_rnea(tree):
    """Y pi over the stacked samples equals Pinocchio's RNEA sample by sample (round-off)."""
    model, q, v, a = tree
    data = model.createData()
    tau = np.concatenate([pin.rnea(model, data, *s) for s in zip(q, v, a)])
    np.testing.assert_allclose(torque_regressor(model, q, v, a) @ model_parameters(model), tau,
                               atol=1e-10 * np.abs(tau).max())


def test_momentum_regressor_times_the_parameters_is_the_momentum_about_the_origin(tree):
    """Y_h pi equals Pinocchio's centroidal momentum carried to the inertial origin."""
    model, q, v, _ = tree
    data = model.createData()
    for qk, vk in zip(q, v):
        h = momentum_about_origin(model, data, qk, vk)
        np.testing.assert_allclose(momentum_regressor(model, qk, vk) @ model_parameters(model), h,
                                   atol=1e-12 * max(1.0, np.abs(h).max()))


def test_with_parameters_round_trips_and_changes_the_dynamics(tree):
    """A model given other parameters reports them back, and RNEA follows them (Y pi')."""
    model, q, v, a = tree
    other = model_parameters(model) * 1.3
    changed = with_parameters(model, other)
    np.testing.assert_allclose(model_parameters(changed), other, rtol=1e-14)
    tau = pin.rnea(changed, changed.createData(), q[0], v[0], a[0])
    np.testing.assert_allclose(torque_regressor(model, q[:1], v[:1], a[:1]) @ other, tau, atol=1e-10 * np.abs(tau).max())


def test_names_follow_pinocchios_order():
    """Each joint's ten names, in toDynamicParameters order, one per column."""
    model = pin.buildSampleModelManipulator()
    names = parameter_names(model)
    assert len(names) == 10 * (model.njoints - 1) == model_parameters(model).size
    assert names[:4] == (f"{model.names[1]}.m", f"{model.names[1]}.mcx", f"{model.names[1]}.mcy", f"{model.names[1]}.mcz")
    assert names[9] == f"{model.names[1]}.Izz"


def test_about_com_and_a_change_of_frame_are_pinocchios():
    """(m, c, I_C) of ten parameters are the inertia's own; the parameters in another frame
    equal Pinocchio's SE3 action on the inertia."""
    inertia = pin.Inertia(2.0, np.array([0.1, -0.2, 0.3]), np.array([[0.5, 0.1, 0.0], [0.1, 0.4, 0.05], [0.0, 0.05, 0.3]]))
    placement = pin.SE3(pin.exp3(np.array([0.3, -1.1, 0.7])), np.array([1.0, 2.0, -0.5]))
    m, c, I = about_com(inertia.toDynamicParameters())
    assert m == pytest.approx(inertia.mass)
    np.testing.assert_allclose(c, inertia.lever, atol=1e-14)
    np.testing.assert_allclose(I, inertia.inertia, atol=1e-13)
    np.testing.assert_allclose(body_parameters(inertia, placement), placement.act(inertia).toDynamicParameters(),
                               atol=1e-13)


def test_wrong_shapes_are_named():
    """A parameter vector or samples of the wrong size raise BadShape naming the sizes."""
    model = pin.buildSampleModelManipulator()
    with pytest.raises(BadShape, match="parameters"):
        with_parameters(model, np.zeros(5))
    with pytest.raises(BadShape, match="v must have shape"):
        torque_regressor(model, np.zeros((2, model.nq)), np.zeros((3, model.nv)), np.zeros((2, model.nv)))
