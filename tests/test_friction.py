"""Joint friction (freefloat.dynamics.friction): the law, its dissipation and where it is read from."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import InvalidArgument
from freefloat.dynamics.friction import SLIP_SPEED, JointFriction


def test_force_is_viscous_plus_regularised_coulomb():
    """f = b v + c tanh(v / v_s): at rest zero, beyond a few slip speeds b v + c sign(v)."""
    friction = JointFriction([0.5, 0.0], [0.2, 1.0], slip_speed=0.01)
    np.testing.assert_array_equal(friction.force(np.zeros(2)), [0.0, 0.0])
    np.testing.assert_allclose(friction.force([1.0, -1.0]), [0.5 + 0.2, -1.0], rtol=1e-12)
    np.testing.assert_allclose(friction.force([0.01, 0.0]), [0.005 + 0.2 * np.tanh(1.0), 0.0], rtol=1e-15)


def test_friction_never_feeds_energy_in():
    """The dissipated power f(v) . v is >= 0 at random rates, batched over leading axes."""
    rng = np.random.default_rng(0)
    friction = JointFriction(rng.uniform(0, 1, 4), rng.uniform(0, 1, 4))
    rates = rng.normal(scale=0.05, size=(50, 4))
    power = friction.power(rates)
    assert power.shape == (50,) and (power >= 0.0).all()
    np.testing.assert_allclose(power, np.einsum("ij,ij->i", friction.force(rates), rates), rtol=1e-14)


def test_stiffness_is_the_slope_at_rest():
    """b + c / v_s equals the central difference of f at zero rate."""
    friction = JointFriction([0.3], [0.05], slip_speed=SLIP_SPEED)
    h = 1e-7
    slope = (friction.force([h]) - friction.force([-h])) / (2 * h)
    np.testing.assert_allclose(friction.stiffness(), slope, rtol=1e-6)


@pytest.mark.parametrize(("viscous", "coulomb", "slip", "message"), [
    ([-0.1], [0.0], 0.01, "'viscous' must be finite and >= 0"),
    ([0.0], [np.nan], 0.01, "'coulomb' must be finite and >= 0"),
    ([0.0, 1.0], [0.0], 0.01, "two vectors of one length"),
    ([0.0], [0.0], 0.0, "'slip_speed' must be a positive speed"),
])
def test_bad_coefficients_are_refused(viscous, coulomb, slip, message):
    """A negative, non-finite or misshapen coefficient, or a slip speed <= 0: InvalidArgument naming it."""
    with pytest.raises(InvalidArgument, match=message):
        JointFriction(viscous, coulomb, slip)


@pytest.mark.filterwarnings("ignore")  # the planar robot's printed inertias
def test_of_model_reads_the_urdf_dynamics(tmp_path):
    """A URDF's <dynamics damping friction> reaches JointFriction.of_model through Pinocchio's model,
    zero on a joint without <dynamics> and on the floating root."""
    from freefloat.robot.loading import load_robot

    from .conftest import REPO

    text = (REPO / "urdf" / "two_arm_planar.urdf").read_text()
    end = text.index("</joint>", text.index('<joint name="arm1_joint1"'))
    (tmp_path / "r.urdf").write_text(text[:end] + '<dynamics damping="0.3" friction="0.05"/>' + text[end:])
    robot = load_robot(tmp_path / "r.urdf", visuals=False)
    friction = JointFriction.of_model(robot.model)
    assert np.count_nonzero(friction.viscous) == 1 and np.count_nonzero(friction.coulomb) == 1
    assert friction.viscous.max() == 0.3 and friction.coulomb.max() == 0.05
    assert not friction[: robot.n_base]


def test_concatenate_joins_and_refuses_mixed_slip_speeds():
    """Frictions of one slip speed join in order; of two, InvalidArgument."""
    a, b = JointFriction([1.0], [2.0]), JointFriction([3.0, 4.0], [5.0, 6.0])
    joined = JointFriction.concatenate([a, b])
    np.testing.assert_array_equal(joined.viscous, [1.0, 3.0, 4.0])
    with pytest.raises(InvalidArgument, match="slip speeds"):
        JointFriction.concatenate([a, JointFriction([1.0], [1.0], 0.1)])


def test_pinocchio_model_fields_are_what_of_model_reads():
    """of_model takes model.damping and model.friction, so a model built in code carries it too."""
    model = pin.Model()
    model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j")
    model.damping[:] = 0.2
    model.friction[:] = 0.7
    friction = JointFriction.of_model(model, 0.05)
    assert friction.viscous.tolist() == [0.2] and friction.coulomb.tolist() == [0.7] and friction.slip_speed == 0.05
