"""Cross-check of the hand-built GJM quantities against Pinocchio over random states.

For each quantity the error is ``max |hand - reference| / max |reference|`` (max-norm relative),
maximised over the samples. References: CRBA in the GJM convention, centroidal momentum and
frame Jacobians (:mod:`freefloat.dynamics.reference`); fourth-order central differences of those
for the joint and time derivatives (:func:`central_differences`). H0, Hm and H* must also be
symmetric positive definite. Eq 182 as printed is reported beside the corrected momentum, for
information (it is expected to fail).

Derivatives are judged column by column (one joint, or the motion): the error of column k is
``max |hand_k - fd_k| / s_k`` with ``s_k = max(max |fd_k|, noise / DERIVATIVE_TOLERANCE)`` and
``noise = ROUNDING_ULPS eps max |H| / h_k``, the rounding floor of the differences of H. A column
that is large is held to the relative tolerance; a column so small (a gripper joint's, ~1e-4 of
|H|) that the differences cannot resolve it to that tolerance is held to what they resolve.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InvalidArgument
from ..robot.joints import JointCoordinates
from ..robot.robot import Robot
from . import gjm
from .reference import reference

VALUE_TOLERANCE = 1e-9
DERIVATIVE_TOLERANCE = 1e-6
#: Step of the fourth-order differences, per unit of the coordinate's size (rad or m, at least 1).
FD_STEP = 1e-3
#: Rounding of the differenced matrices, in units of eps max |H| (generous: H comes out of CRBA).
ROUNDING_ULPS = 100.0
VALUES = ("H0", "H0m", "Hm", "Hstar", "J0", "Jm", "J0E", "Jstar", "momentum_base", "momentum_origin")
DERIVATIVES = (("dH0", "H0"), ("dH0m", "H0m"), ("dHm", "Hm"))
TIME_DERIVATIVES = (("H0dot", "H0"), ("H0mdot", "H0m"), ("Hmdot", "Hm"))


@dataclass
class Check:
    """One line of the report: the worst relative error of a quantity over the samples."""

    quantity: str
    reference: str
    error: float
    tolerance: float
    informational: bool = False

    @property
    def passed(self) -> bool:
        return self.informational or self.error <= self.tolerance


@dataclass
class Report:
    """All checks for one robot."""

    robot: str
    samples: int
    seed: int
    checks: list[Check] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def table(self) -> str:
        """Plain-text table of the checks."""
        lines = [f"{'quantity':<30}{'reference':<44}{'max rel. error':>15}{'tolerance':>11}  result"]
        for c in self.checks:
            result = "info" if c.informational else ("ok" if c.passed else "FAIL")
            lines.append(f"{c.quantity:<30}{c.reference:<44}{c.error:>15.3e}{c.tolerance:>11.0e}  {result}")
        lines.append(f"{self.robot}: {self.samples} random states (seed {self.seed}): "
                     + ("all checks pass" if self.passed else "SOME CHECKS FAIL"))
        return "\n".join(lines)

    def to_json(self) -> str:
        out = {"robot": self.robot, "samples": self.samples, "seed": self.seed, "passed": self.passed,
               "checks": [dict(asdict(c), passed=c.passed) for c in self.checks]}
        return json.dumps(out, indent=2)


def relative_error(value: np.ndarray, ref: np.ndarray) -> float:
    """``max |value - ref| / max |ref|`` (absolute error when ref is zero)."""
    scale = np.abs(ref).max() if np.size(ref) else 0.0
    return float(np.abs(value - ref).max() / scale) if scale > 0 else float(np.abs(value - ref).max(initial=0.0))


def random_configuration(robot: Robot, rng: np.random.Generator, coords: JointCoordinates,
                         box: float = 2.0, joint_range: float = np.pi) -> np.ndarray:
    """A random Pinocchio configuration (nq,) of a free-flyer robot: base-link origin uniform in
    ``[-box, box]^3`` m (inertial frame), uniformly random attitude, joints uniform in
    ``[-joint_range, joint_range]``."""
    q = pin.neutral(robot.model)
    q[:3] = rng.uniform(-box, box, 3)
    quat = rng.normal(size=4)
    q[3:7] = quat / np.linalg.norm(quat)
    coords.set(q, rng.uniform(-joint_range, joint_range, robot.n_joints))
    return q


def random_state(robot: Robot, rng: np.random.Generator, coords: JointCoordinates) -> tuple[np.ndarray, np.ndarray]:
    """A random state: base pose in a 2 m box, any attitude, joints in [-pi, pi], speeds ~ N(0, 1)."""
    return random_configuration(robot, rng, coords), rng.normal(size=robot.model.nv)


def central_differences(robot: Robot, q: np.ndarray, v: np.ndarray, joint: int | None,
                        coords: JointCoordinates, h: float = FD_STEP) -> dict[str, np.ndarray]:
    """Fourth-order central differences of Pinocchio's H0, H0m, Hm (same shapes):
    along joint ``joint`` at fixed base pose with step ``h max(1, |theta_joint|)``, or along the
    motion ``(q, v)`` (step ``h``, time s) when ``joint`` is None.

    .. math:: f' \\approx \\frac{f(x - 2h) - 8 f(x - h) + 8 f(x + h) - f(x + 2h)}{12 h}
    """
    if joint is None:
        def shifted(k: int) -> np.ndarray:
            return pin.integrate(robot.model, q, k * h * v)
    else:
        theta = coords.get(q)
        h = h * max(1.0, abs(float(theta[joint])))

        def shifted(k: int) -> np.ndarray:
            out = q.copy()
            coords.set(out, theta + k * h * np.eye(robot.n_joints)[joint])
            return out
    refs = {k: reference(robot, shifted(k), v) for k in (-2, -1, 1, 2)}
    return {name: (getattr(refs[-2], name) - 8 * getattr(refs[-1], name) + 8 * getattr(refs[1], name)
                   - getattr(refs[2], name)) / (12 * h) for name in ("H0", "H0m", "Hm")}


def column_error(hand: np.ndarray, fd: np.ndarray, matrix: np.ndarray, h: float) -> float:
    """Error of one derivative column against its differences (see the module docstring):
    ``max |hand - fd| / max(max |fd|, noise / DERIVATIVE_TOLERANCE)``, with ``noise`` the rounding
    floor of differences of ``matrix`` with step ``h``."""
    noise = ROUNDING_ULPS * np.finfo(float).eps * np.abs(matrix).max() / h
    scale = max(float(np.abs(fd).max()), float(noise) / DERIVATIVE_TOLERANCE)
    error = float(np.abs(hand - fd).max())
    return float(error / scale) if scale > 0 else error


#: Most random states one check takes (each costs finite differences over every joint: about
#: 10 ms on a 16-joint robot, so the bound is some twenty minutes).
MAX_SAMPLES = 100_000


def check_robot(robot: Robot, samples: int = 10, seed: int = 0) -> Report:
    """Run every check on ``samples`` random states of ``robot`` (free-flyer base), for both GJM
    backends (compiled and numpy); each check reports the worse of the two.

    Raises:
        InvalidArgument: for ``samples`` outside [1, :data:`MAX_SAMPLES`] or a negative ``seed``.
    """
    if not isinstance(samples, int) or not 1 <= samples <= MAX_SAMPLES:
        raise InvalidArgument(f"samples must be from 1 to {MAX_SAMPLES}, got {samples!r}")
    if not isinstance(seed, int) or seed < 0:
        raise InvalidArgument(f"seed must be an integer >= 0, got {seed!r}")
    rng = np.random.default_rng(seed)
    coords = JointCoordinates(robot)
    worst: dict[str, float] = {}

    def note(name: str, error: float) -> None:
        worst[name] = max(worst.get(name, 0.0), error)

    for _ in range(samples):
        q, v = random_state(robot, rng, coords)
        ref = reference(robot, q, v)
        theta = coords.get(q)
        fd_joints = [central_differences(robot, q, v, k, coords) for k in range(robot.n_joints)]
        fd_motion = central_differences(robot, q, v, None, coords)
        for backend in gjm.BACKENDS:
            state = gjm.compute(robot, q, v, backend)
            for name in VALUES:
                note(name, relative_error(getattr(state, name), getattr(ref, name)))
            note("x_Edot (eq 88)", relative_error(state.end_effector_velocity(), ref.ee_velocity))
            note("momentum eq 182 as printed", relative_error(gjm.momentum_about_origin(state, "printed_eq182"), ref.momentum_origin))
            note("momentum eq 184 corrected", relative_error(gjm.momentum_about_origin(state), ref.momentum_origin))
            for name in ("H0", "Hm", "Hstar"):
                matrix = getattr(state, name)
                asym = relative_error(matrix, matrix.T)
                note(f"{name} symmetric pos. def.", asym if np.linalg.eigvalsh(matrix).min() > 0 else np.inf)
            der = gjm.derivatives(robot, q, v, backend)
            for k, fd in enumerate(fd_joints):
                for name, base in DERIVATIVES:
                    note(name, column_error(getattr(der, name)[k], fd[base], getattr(ref, base),
                                            FD_STEP * max(1.0, abs(float(theta[k])))))
            for name, base in TIME_DERIVATIVES:
                note(name, column_error(getattr(der, name), fd_motion[base], getattr(ref, base), FD_STEP))

    sources = {
        "H0": "CRBA, T^-T M_bb T^-1", "H0m": "CRBA, T^-T M_bq", "Hm": "CRBA, M_qq",
        "Hstar": "CRBA, M_qq - M_qb M_bb^-1 M_bq", "J0": "CRBA, -T M_bb^-1 M_bq",
        "Jm": "frame Jacobian, joint columns", "J0E": "frame Jacobian, base columns T^-1",
        "Jstar": "frame Jacobian and CRBA", "momentum_base": "centroidal momentum moved to r0",
        "momentum_origin": "centroidal momentum moved to origin", "x_Edot (eq 88)": "frame Jacobian @ v",
        "momentum eq 182 as printed": "centroidal momentum moved to origin",
        "momentum eq 184 corrected": "centroidal momentum moved to origin",
    }
    report = Report(robot=str(robot.urdf_path), samples=samples, seed=seed)
    for name, error in worst.items():
        if name in dict(DERIVATIVES) or name in dict(TIME_DERIVATIVES):
            ref_name = ("4th-order diff. of CRBA, fixed base pose" if name.startswith("d")
                        else "4th-order diff. along (q, v)")
            report.checks.append(Check(name, ref_name, error, DERIVATIVE_TOLERANCE))
        elif "symmetric" in name:
            report.checks.append(Check(name, "own transpose (inf if an eigenvalue <= 0)", error, VALUE_TOLERANCE))
        else:
            report.checks.append(Check(name, sources[name], error, VALUE_TOLERANCE, informational="printed" in name))
    return report


def write_report(report: Report, path: Path) -> None:
    """Write the report as JSON."""
    path.write_text(report.to_json())
