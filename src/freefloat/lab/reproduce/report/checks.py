"""The numbers the report computes itself from the package (no study's output): the momentum of
eq 182 against Pinocchio's, the 5R's geometry at its start, the reference circle and distances to
it, and the one-line checks of the thesis's printed equations."""

from __future__ import annotations

import numpy as np

from ..printed import CIRCLE_CENTRE, CIRCLE_RADIUS, CIRCLE_RATE, LAMBDA, SATURATION_GAIN, START

#: The circle of eq 189, 400 points (400, 2), m.
CIRCLE = np.column_stack((CIRCLE_RADIUS * np.cos(np.linspace(0, 2 * np.pi, 400)),
                          CIRCLE_CENTRE[1] + CIRCLE_RADIUS * np.sin(np.linspace(0, 2 * np.pi, 400))))


def momentum_eq_182(samples: int = 5, seed: int = 0) -> tuple[float, float]:
    """Largest relative error of the momentum about the inertial origin (6,) by eq 182 as printed
    and by the corrected form, against Pinocchio's centroidal momentum moved to the origin, at
    ``samples`` random states of the four-arm robot on a free-flyer base."""
    from ....dynamics import gjm
    from ....dynamics.reference import reference
    from ....dynamics.verify import random_state, relative_error
    from ....paths import URDF_DIR
    from ....robot.joints import JointCoordinates
    from ....robot.loading import load_robot

    robot = load_robot(URDF_DIR / "four_arm_planar.urdf", visuals=False)
    rng, coords, worst = np.random.default_rng(seed), JointCoordinates(robot), [0.0, 0.0]
    for _ in range(samples):
        q, v = random_state(robot, rng, coords)
        state, exact = gjm.compute(robot, q, v), reference(robot, q, v).momentum_origin
        for k, variant in enumerate(("printed_eq182", None)):
            value = gjm.momentum_about_origin(state, variant) if variant else gjm.momentum_about_origin(state)
            worst[k] = max(worst[k], relative_error(value, exact))
    return worst[0], worst[1]


def external_forces_eqs_95_99(samples: int = 5, seed: int = 0) -> dict[str, tuple[float, float]]:
    """Per GJM model, the largest relative acceleration error against ABA with the same forces, at
    ``samples`` zero-momentum and ``samples`` random states of the four-arm robot (free-flyer base)
    with gravity N(0, 1) m/s^2 and a N(0, 1) wrench on every joint: (zero momentum, random)."""
    import pinocchio as pin

    from ....dynamics.models import MODELS, make_model
    from ....dynamics.verify import random_state
    from ....paths import URDF_DIR
    from ....robot.joints import JointCoordinates
    from ....robot.loading import load_robot
    from ..states import state_with_momentum

    robot = load_robot(URDF_DIR / "four_arm_planar.urdf", visuals=False)
    rng, coords = np.random.default_rng(seed), JointCoordinates(robot)
    robot.model.gravity.linear[:] = rng.normal(size=3)
    models = {name: make_model(name, robot) for name in MODELS}
    worst = {name: [0.0, 0.0] for name in MODELS if name != "exact"}
    for k, draw in enumerate((lambda: state_with_momentum(robot, rng), lambda: random_state(robot, rng, coords))):
        for _ in range(samples):
            q, v = draw()
            tau = np.concatenate((np.zeros(robot.n_base), rng.normal(size=robot.n_joints)))
            fext = [pin.Force(rng.normal(size=6)) for _ in range(robot.model.njoints)]
            exact = models["exact"].acceleration(q, v, tau, fext)
            for name, errors in worst.items():
                a = models[name].acceleration(q, v, tau, fext)
                errors[k] = max(errors[k], float(np.abs(a - exact).max() / np.abs(exact).max()))
    return {name: (e[0], e[1]) for name, e in worst.items()}


def summed_arms_eqs_109_115(samples: int = 5, seed: int = 0) -> tuple[float, float]:
    """Largest relative acceleration error of the printed multi-arm form that sums the arms' joint
    equations (eqs 109-115) against ABA, and the largest relative residual of ABA's accelerations in
    those summed equations, at ``samples`` random states of the four-arm robot (free-flyer base)
    with random joint torques and a random wrench on every joint."""
    import pinocchio as pin

    from ....dynamics.models import make_model
    from ....dynamics.models.summed_arms import summed_arms_acceleration, summing_operator
    from ....dynamics.models.underactuated import UnderactuatedGJM
    from ....dynamics.verify import random_state
    from ....paths import URDF_DIR
    from ....robot.joints import JointCoordinates
    from ....robot.loading import load_robot

    robot = load_robot(URDF_DIR / "four_arm_planar.urdf", visuals=False)
    rng, coords, worst = np.random.default_rng(seed), JointCoordinates(robot), [0.0, 0.0]
    S, nb = summing_operator(robot), robot.n_base
    exact_model, terms_model = make_model("exact", robot), UnderactuatedGJM(robot, True, True, backend="numpy")
    for _ in range(samples):
        q, v = random_state(robot, rng, coords)
        tau = np.concatenate((np.zeros(nb), rng.normal(size=robot.n_joints)))
        fext = [pin.Force(rng.normal(size=6)) for _ in range(robot.model.njoints)]
        exact = exact_model.acceleration(q, v, tau, fext)
        terms = terms_model.terms(q, v, fext)
        H, c = terms_model.joint_space(terms)
        rhs = S @ (tau[nb:] + terms.Q_q - c)
        worst[0] = max(worst[0], np.abs(summed_arms_acceleration(robot, q, v, tau, fext) - exact).max() / np.abs(exact).max())
        worst[1] = max(worst[1], np.abs(S @ H @ exact[nb:] - rhs).max() / np.abs(rhs).max())
    return worst[0], worst[1]


def five_bar_points() -> list[np.ndarray]:
    """The 5R at its start :data:`~..printed.START`: each chain's base joint, elbow and tip (3, 2), m."""
    from ....parallel.five_bar import FiveBarParameters, elbow_guess, five_bar

    p = FiveBarParameters()
    q = five_bar(p).assemble(np.array(START), elbow_guess(p, np.array(START)))
    chains = []
    for side, (a, b) in ((1.0, q[2:4]), (-1.0, q[4:6])):
        base = np.array([side * p.l0, 0.0])
        elbow = base + p.l1 * np.array([side * np.cos(a), np.sin(a)])
        chains.append(np.array([base, elbow, elbow + p.l2 * np.array([side * np.cos(a + b), np.sin(a + b)])]))
    return chains


def link_lengths() -> np.ndarray:
    """The RR chain's link lengths l1, l2 (2,), m, measured on chain 1 of :func:`five_bar_points`."""
    return np.linalg.norm(np.diff(five_bar_points()[0], axis=0), axis=1)


def distance(points: list, path: np.ndarray = CIRCLE) -> float:
    """Smallest distance (m) from ``path`` (M, 2) to ``points`` (K, 2); inf without points."""
    points = np.asarray(points, float).reshape(-1, 2)
    return float(np.linalg.norm(path[:, None] - points[None], axis=2).min()) if len(points) else float("inf")


def saturation(s: float) -> float:
    """Fig 9's saturation tanh(GAIN s) at ``s``."""
    return float(np.tanh(SATURATION_GAIN * s))


def saturation_slope_at_zero() -> float:
    """The slope of :func:`saturation` at s = 0: GAIN (1 - tanh(0)^2)."""
    return float(SATURATION_GAIN * (1 - np.tanh(0.0) ** 2))


def s_x_with_printed_error() -> float:
    """s_x(0) = -(edot + lambda e) at rest at the start with eq 142's printed error e = qddot_d - q
    (qddot_d(0) = -r w^2 along x on the circle of eq 189; edot(0) = 0), m/s."""
    return -LAMBDA * (-CIRCLE_RADIUS * CIRCLE_RATE ** 2 - START[0])


def dh_entry_1_3(angle: float) -> tuple[float, float]:
    """Entry (1,3) of the DH matrix at theta = alpha = ``angle`` (rad): as eq 22 prints it (sin
    theta cos alpha) and the standard sin theta sin alpha."""
    return float(np.sin(angle) * np.cos(angle)), float(np.sin(angle) ** 2)
