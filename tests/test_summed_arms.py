"""The printed multi-arm form that sums every arm's joint equations (eqs 109-115) against ABA."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.dynamics.models import make_model
from freefloat.dynamics.models.summed_arms import summed_arms_acceleration, summing_operator
from freefloat.dynamics.models.underactuated import UnderactuatedGJM
from freefloat.errors import InvalidArgument
from freefloat.paths import URDF_DIR

from .conftest import load_text, random_state


def robot(name: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(URDF_DIR / f"{name}.urdf", visuals=False)


def chain_urdf(links: int) -> str:
    """One arm of ``links`` revolute joints on a base (a single-arm robot)."""
    inertial = ('<inertial><origin xyz="0.2 0.05 0"/><mass value="{m}"/><inertia ixx="0.03" iyy="0.04" izz="0.05" '
                'ixy="0" ixz="0" iyz="0"/></inertial>')
    parts = ['<robot name="chain">', f'<link name="base">{inertial.format(m=20.0)}</link>']
    for i in range(1, links + 1):
        parent = "base" if i == 1 else f"l{i - 1}"
        parts += [f'<link name="l{i}">{inertial.format(m=1.5)}</link>',
                  f'<joint name="j{i}" type="revolute"><parent link="{parent}"/><child link="l{i}"/>'
                  f'<origin xyz="0.4 0.1 0.05" rpy="0.3 -0.2 0.1"/><axis xyz="{i % 2} {1 - i % 2} 1"/>'
                  '<limit lower="-3" upper="3" effort="100" velocity="10"/></joint>']
    return "\n".join(parts + ["</robot>"])


def state_and_forces(robot, seed: int):
    """A random state, random joint torques and a random wrench on every joint."""
    rng = np.random.default_rng(seed)
    q, v = random_state(robot, rng)
    tau = np.concatenate((np.zeros(robot.n_base), rng.normal(size=robot.n_joints)))
    return q, v, tau, [pin.Force(rng.normal(size=6)) for _ in range(robot.model.njoints)]


@pytest.mark.parametrize("name", ["four_arm_planar", "dual_arm_satellite"])
def test_exact_accelerations_satisfy_the_summed_equations(name):
    """ABA's joint accelerations satisfy I_n^T (H* qddot) = I_n^T (tau + Q - c) to 1e-12 relative: the sum is
    a consequence of the exact per-arm equations (eq 113)."""
    r = robot(name)
    S = summing_operator(r)
    for seed in range(5):
        q, v, tau, fext = state_and_forces(r, seed)
        exact = make_model("exact", r).acceleration(q, v, tau, fext)
        model = UnderactuatedGJM(r, full_hdot=True, corrected_c0=True, backend="numpy")
        terms = model.terms(q, v, fext)
        H, c = model.joint_space(terms)
        rhs = S @ (tau[r.n_base:] + terms.Q_q - c)
        assert np.abs(S @ H @ exact[r.n_base:] - rhs).max() < 1e-12 * np.abs(rhs).max()


@pytest.mark.parametrize("name, floor", [("four_arm_planar", 0.5), ("dual_arm_satellite", 0.1)])
def test_summed_form_misses_the_exact_accelerations_with_two_or_more_arms(name, floor):
    """With n >= 2 arms the printed summed form leaves N - m accelerations free: its minimum-norm
    solution is off ABA's by more than ``floor`` relative (measured 0.94-1.13 four-arm, 0.18-0.73 dual-arm)."""
    r = robot(name)
    assert summing_operator(r).shape[0] < r.n_joints
    for seed in range(5):
        q, v, tau, fext = state_and_forces(r, seed)
        exact = make_model("exact", r).acceleration(q, v, tau, fext)
        assert np.abs(summed_arms_acceleration(r, q, v, tau, fext) - exact).max() > floor * np.abs(exact).max()


def test_summed_form_is_exact_with_one_arm(tmp_path):
    """With one arm (I_1 = 1) the printed form is the exact one: ABA's accelerations to 1e-10 relative."""
    r = load_text(tmp_path, chain_urdf(4))
    assert len(r.arms) == 1 and np.array_equal(summing_operator(r), np.eye(r.n_joints))
    for seed in range(5):
        q, v, tau, fext = state_and_forces(r, seed)
        exact = make_model("exact", r).acceleration(q, v, tau, fext)
        assert np.abs(summed_arms_acceleration(r, q, v, tau, fext) - exact).max() < 1e-10 * np.abs(exact).max()


def test_arms_of_unequal_length_are_refused_naming_them(tmp_path):
    """Eq 113's sum needs arms of equal length: a tree with a 1-joint and a 2-joint arm is refused with both named."""
    text = chain_urdf(2).replace("</robot>", '<link name="s1"><inertial><mass value="1"/><inertia ixx="0.01" '
                                 'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link><joint name="k1" '
                                 'type="revolute"><parent link="base"/><child link="s1"/><origin xyz="-0.4 0 0"/>'
                                 '<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="10"/></joint>'
                                 '</robot>')
    with pytest.raises(InvalidArgument, match="equal length.*l2.*s1|equal length.*s1.*l2"):
        summing_operator(load_text(tmp_path, text))
