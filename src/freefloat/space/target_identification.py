"""A captured target's mass, centre of mass and inertia identified from the motion after the
capture, by the conservation of the whole system's momentum (issue 39; the route the
dissertation cites in Peng et al., Acta Astronautica 162, 2019; Murotsu et al., J. Guid. Control
Dyn. 17(3), 1994, for a free-flying robot).

After the grasp the robot and the target are one free system with no external force, so its
momentum about the inertial origin is a constant ``h_0`` (6,), which is unknown (the target's
momentum before contact was not measured). The robot's own share ``h_r(q, v)`` is known from its
model. The target, held rigidly by the end-effector's body, adds its spatial momentum, linear in
its ten parameters ``pi_t`` in the end-effector frame E (Pinocchio's ``toDynamicParameters``
order: m, m c, inertia about E's origin, E's axes):

.. math::
    h_r(q_k, \\dot q_k) + {}^{O}X_E^{*}(q_k)\\, Y_b\\big(0, v_E(q_k, \\dot q_k)\\big)\\, \\pi_t = h_0
    \\quad\\Longrightarrow\\quad
    \\begin{bmatrix} {}^{O}X_E^{*} Y_b & -I_6 \\end{bmatrix}
    \\begin{bmatrix} \\pi_t \\\\ h_0 \\end{bmatrix} = -h_r(q_k, \\dot q_k)
    \\qquad (1)

for every sample k, with ``Y_b(0, v_E)`` Pinocchio's ``bodyRegressor`` (the body's momentum
``I v_E`` in its frame), ``v_E`` the end-effector frame's twist in its own axes and ``{}^O X_E^*``
the dual action of its pose (:func:`~freefloat.dynamics.identification.regressors.body_momentum_regressor`).
Eq (1) is linear in the 16 unknowns; stacked over N samples it is solved by least squares with
the six components of a sample as one block (they share the noise of the measured base state,
:func:`~freefloat.dynamics.identification.least_squares.fit`). It needs q and v only: no joint
torque, no acceleration, no time derivative of noisy data.

Identifiability: the record must turn and move the end-effector in its own frame in enough
ways. Held still while the system spins about one axis, only the inertia about that axis shows;
so after a capture the arm runs an identification manoeuvre (exciting joint motion,
:mod:`freefloat.space.control.excitation`) before the detumbling.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ..dynamics.identification.least_squares import Estimate, fit
from ..dynamics.identification.measurements import noisy, noisy_configurations, smooth, smooth_configurations
from ..dynamics.identification.parameters import PARAMETER_NAMES, about_com, body_parameters
from ..dynamics.identification.regressors import body_momentum_regressor
from ..errors import BadShape, InvalidArgument, UnknownName
from ..robot.conventions import momentum_about_origin
from ..robot.robot import Robot

#: Names of the 16 unknowns of eq (1): the target's ten parameters, then h_0 = [P; L_O].
UNKNOWNS = (*(f"target.{p}" for p in PARAMETER_NAMES), "h0.Px", "h0.Py", "h0.Pz", "h0.Lx", "h0.Ly", "h0.Lz")


def momentum_rows(robot: Robot, end_effector: str, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eq (1) over N samples: ``(A, b)``, A (6 N, 16) and b (6 N,), sample-major; q (N, nq) and v
    (N, nv) the merged robot's (its telemetry), which has the robot's coordinates."""
    model, data = robot.model, robot.model.createData()
    frame = _frame_id(robot, end_effector)
    A, b = [], []
    for qk, vk in zip(q, v):
        h_r = momentum_about_origin(model, data, qk, vk)        # leaves the forward kinematics at (q, v)
        pin.updateFramePlacements(model, data)
        twist = pin.getFrameVelocity(model, data, frame, pin.LOCAL)
        A.append(np.hstack((body_momentum_regressor(data.oMf[frame], twist), -np.eye(6))))
        b.append(-h_r)
    return np.vstack(A), np.concatenate(b)


@dataclass(frozen=True)
class TargetEstimate:
    """The target identified by eq (1) (module docstring).

    Attributes:
        estimate: the least-squares estimate of the 16 unknowns :data:`UNKNOWNS` (values,
            covariance, residual noise per sample (6, 6), degrees of freedom, condition).
        end_effector: the frame E the parameters are in.
    """

    estimate: Estimate
    end_effector: str

    @property
    def parameters(self) -> np.ndarray:
        """The target's ten parameters in E (10,): kg, kg m, kg m^2 (about E's origin)."""
        return self.estimate.values[:10]

    @property
    def covariance(self) -> np.ndarray:
        """Their covariance (10, 10)."""
        return self.estimate.covariance[:10, :10]

    @property
    def momentum(self) -> np.ndarray:
        """The system's momentum ``h_0 = [P; L about the origin]`` (6,), inertial axes."""
        return self.estimate.values[10:]

    def physical(self) -> tuple[float, np.ndarray, np.ndarray]:
        """``(m, c, I_C)``: mass (kg), CoM in E (3,) (m) and inertia about the CoM in E's axes
        (3, 3) (kg m^2)."""
        return about_com(self.parameters)

    def physical_std(self) -> tuple[float, np.ndarray, np.ndarray]:
        """Standard deviations of :meth:`physical`'s ``(m, c, I_C)`` (first-order propagation of
        :attr:`covariance`, ``J cov J^T``, with the exact Jacobian of ``c = mc / m`` and
        ``I_C = I - (|mc|^2 1 - mc mc^T) / m``)."""
        J = _physical_jacobian(self.parameters)
        std = np.sqrt(np.diag(J @ self.covariance @ J.T))
        return float(std[0]), std[1:4], std[4:].reshape(3, 3)

    def physical_half_width(self, level: float = 0.95) -> tuple[float, np.ndarray, np.ndarray]:
        """Half-widths of the ``level`` intervals of :meth:`physical`'s ``(m, c, I_C)``: each
        standard deviation of :meth:`physical_std` times Student's t at the estimate's degrees
        of freedom (as :meth:`~freefloat.dynamics.identification.least_squares.Estimate.half_width`)."""
        scale = self.estimate.half_width(level)[0] / self.estimate.std[0]
        m, c, inertia = self.physical_std()
        return scale * m, scale * c, scale * inertia


def identify_target(robot: Robot, end_effector: str, q: np.ndarray, v: np.ndarray, window: int = 1,
                    weighting: str = "block") -> TargetEstimate:
    """The target held by ``end_effector`` of ``robot`` (the robot as known before the capture),
    from the merged robot's recorded configurations q (N, nq) and velocities v (N, nv) after the
    grasp (a run of the merged robot without external wrenches, e.g. the telemetry of
    :func:`~freefloat.space.after_capture.manoeuvre`): eq (1) by least squares.

    Args:
        window: 1 uses every sample as recorded; an odd number of samples smooths q and v by a
            local cubic over that many samples, taken every ``window`` samples
            (:func:`~freefloat.dynamics.identification.measurements.smooth`): for noisy records,
            whose noise in q and v would otherwise bias the estimate towards zero.
        weighting: :data:`~freefloat.dynamics.identification.least_squares.WEIGHTINGS`.

    Raises:
        UnknownName: for an end-effector frame the robot does not have.
        BadShape: for records of other shapes than the robot's.
        InvalidArgument: for a robot on a planar base (it does not conserve the whole momentum),
            or a record that does not excite every parameter (rank-deficient eq (1)).
    """
    if robot.base != "free":
        raise InvalidArgument(f"identify_target: the robot's base is '{robot.base}'; eq (1) needs a free-flyer base "
                              "(a planar base conserves only its in-plane momentum: load the robot with base='free')")
    q, v = np.atleast_2d(np.asarray(q, float)), np.atleast_2d(np.asarray(v, float))
    if q.shape[1:] != (robot.model.nq,) or v.shape != (len(q), robot.model.nv):
        raise BadShape(f"identify_target: q must be (N, {robot.model.nq}) and v (N, {robot.model.nv}) of the "
                       f"robot's coordinates, got {q.shape} and {v.shape}")
    if window > 1:
        q, v = smooth_configurations(robot.model, q, window)[1], smooth(v, window)[1]
    A, b = momentum_rows(robot, end_effector, q, v)
    return TargetEstimate(fit(A, b, 6, UNKNOWNS, weighting), end_effector)


def identify_measured(robot: Robot, end_effector: str, q: np.ndarray, v: np.ndarray, noise: float,
                      rng: np.random.Generator, window: int = 101) -> TargetEstimate:
    """:func:`identify_target` on the record (q (N, nq), v (N, nv)) read through seeded sensor
    noise: each tangent coordinate of q and each coordinate of v perturbed by ``noise`` (a
    fraction) of its size over the record (:func:`~freefloat.dynamics.identification.measurements.noisy_configurations`,
    :func:`~freefloat.dynamics.identification.measurements.noisy`), then smoothed over ``window`` samples."""
    return identify_target(robot, end_effector, noisy_configurations(robot.model, q, noise, rng),
                           noisy(v, noise, rng), window=window)


def held_parameters(merged: Robot, robot: Robot, end_effector: str) -> np.ndarray:
    """The ten parameters (10,) of what ``merged`` carries at ``end_effector`` beyond ``robot``
    (the captured target as :func:`~freefloat.space.capture.attach` appended it), in the
    end-effector frame: the truth an identification is compared with."""
    frame = merged.model.frames[_frame_id(merged, end_effector)]
    joint = frame.parentJoint
    extra = pin.Inertia.FromDynamicParameters(merged.model.inertias[joint].toDynamicParameters()
                                              - robot.model.inertias[joint].toDynamicParameters())
    return body_parameters(extra, frame.placement.inverse())


def with_target(robot: Robot, end_effector: str, parameters: np.ndarray) -> Robot:
    """The robot carrying a target of ten ``parameters`` (10,) in the end-effector frame, added
    to the end-effector's body: the merged model a controller believes (identified, or a nominal
    guess)."""
    model = pin.Model(robot.model)
    frame = model.frames[_frame_id(robot, end_effector)]
    added = frame.placement.act(pin.Inertia.FromDynamicParameters(np.asarray(parameters, float)))
    model.inertias[frame.parentJoint] = model.inertias[frame.parentJoint] + added
    return replace(robot, model=model, visual_model=None)


def _frame_id(robot: Robot, end_effector: str) -> int:
    """The frame id of ``end_effector``.

    Raises:
        UnknownName: naming the robot's end-effectors.
    """
    if end_effector not in robot.end_effectors or not robot.model.existFrame(end_effector):
        raise UnknownName("end-effector", end_effector, robot.end_effectors)
    return robot.model.getFrameId(end_effector)


def _physical_jacobian(parameters: np.ndarray) -> np.ndarray:
    """d(m, c, vec(I_C)) / d pi (13, 10) at ten parameters (10,) (:meth:`TargetEstimate.physical_std`)."""
    m, h = parameters[0], parameters[1:4]
    J = np.zeros((13, 10))
    J[0, 0] = 1.0
    J[1:4, 0] = -h / m**2
    J[1:4, 1:4] = np.eye(3) / m
    # I_C = I - (|h|^2 1 - h h^T) / m; I's six entries in Pinocchio's order.
    for k, (r, c) in enumerate(((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))):
        for rr, cc in {(r, c), (c, r)}:
            J[4 + 3 * rr + cc, 4 + k] = 1.0
    S = np.dot(h, h) * np.eye(3) - np.outer(h, h)
    J[4:, 0] = (S / m**2).ravel()
    for k in range(3):
        e = np.eye(3)[k]
        J[4:, 1 + k] = (-(2.0 * h[k] * np.eye(3) - np.outer(e, h) - np.outer(h, e)) / m).ravel()
    return J
