"""Reaction wheels on the base: momentum devices inside the robot (dissertation sec 3.4).

A reaction wheel is a rotor on a continuous joint whose parent is the base. Its torque is internal,
so the system's momentum stays what it was, but the wheel stores part of it: with the wheel rates
``Omega`` among the joint rates, the momentum constraint of eq 69 reads

.. math:: H_0 \\dot x_0 + H_{0a} \\dot q_a + H_{0w} \\Omega = M,

and the arm sees the non-zero momentum ``M - H_{0w} Omega`` in eqs 84-88 (the GJM of the arm with
the wheels' stored momentum as its momentum term; :mod:`freefloat.space.control.wheel_attitude`).

Two ways to have wheels: *declared* over continuous joints the URDF already has (child of the
root link, a leaf), or *added* by freefloat: a new continuous joint on the base (Pinocchio's
``RUBZ`` joint, placed so that its z axis is the spin axis) carrying an axisymmetric rotor of
given mass and inertia. Either way the result is a :class:`Robot` whose joint vector includes the
wheels, and the :class:`Wheel` records that say where they are and what they can take.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import RobotModelError, did_you_mean
from .robot import Robot

#: Relative tolerance of the unit-axis and zero-length checks.
AXIS_TOLERANCE = 1e-9
#: Suffix of an added wheel's body (link) frame: the rotor of wheel ``w`` is the link ``w_rotor``.
ROTOR = "_rotor"


@dataclass(frozen=True)
class WheelSpec:
    """What a scene says about one wheel (SI units).

    Attributes:
        name: the continuous joint of the URDF to use as a wheel (``declared``), or the name of
            the joint freefloat adds (with ``axis``).
        axis: spin axis in the base-link frame (3,), any length but zero; None: the joint is the
            URDF's and its axis is read from the model.
        position: rotor centre in the base-link frame, m (3,) (added wheels only).
        mass: rotor mass, kg (added wheels only).
        inertia: rotor moment of inertia about its spin axis, kg m^2 (added wheels only).
        transverse_inertia: about a diameter, kg m^2 (added wheels; None: half the axial one, a
            thin disc).
        max_momentum: the most momentum the wheel may store relative to the base,
            ``|I_a Omega|``, N m s (its speed limit times ``inertia``).
        max_torque: the motor's torque limit, N m.
        key: where the spec came from (``"wheels[0]"``), for error messages.
    """

    name: str
    max_momentum: float
    max_torque: float
    axis: tuple[float, ...] | None = None
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mass: float = 1.0
    inertia: float = 0.01
    transverse_inertia: float | None = None
    key: str = "wheel"


@dataclass(frozen=True)
class Wheel:
    """A reaction wheel of a robot.

    Attributes:
        name: its joint's name.
        joint_id: its Pinocchio joint index.
        v_index: its rate's index in Pinocchio's ``v`` (nv,).
        column: its index in the actuated joint vector (n_joints,), e.g. telemetry ``tau``.
        axis: unit spin axis in the base-link frame (3,).
        inertia: moment of inertia of the rotor about the spin axis, kg m^2.
        max_momentum: stored-momentum limit ``|I_a Omega|``, N m s.
        max_torque: torque limit, N m.
    """

    name: str
    joint_id: int
    v_index: int
    column: int
    axis: np.ndarray
    inertia: float
    max_momentum: float
    max_torque: float

    @property
    def max_speed(self) -> float:
        """Speed limit relative to the base, ``max_momentum / inertia``, rad/s."""
        return self.max_momentum / self.inertia


@dataclass(frozen=True, eq=False)
class Wheels:
    """A robot with reaction wheels, and the wheels.

    Attributes:
        robot: the robot; its joints include the wheels (added ones last).
        wheels: the wheels, in the order of the scene.
    """

    robot: Robot
    wheels: tuple[Wheel, ...]

    @property
    def v_indices(self) -> np.ndarray:
        """Indices of the wheel rates in Pinocchio's ``v`` (nw,)."""
        return np.array([w.v_index for w in self.wheels], dtype=int)

    @property
    def columns(self) -> np.ndarray:
        """Indices of the wheels in the actuated joint vector (nw,)."""
        return np.array([w.column for w in self.wheels], dtype=int)

    @property
    def arm_columns(self) -> np.ndarray:
        """Indices of the other actuated joints (the arms) in the joint vector (n_joints - nw,)."""
        return np.setdiff1d(np.arange(self.robot.n_joints), self.columns)

    @property
    def inertias(self) -> np.ndarray:
        """Axial inertias, kg m^2 (nw,)."""
        return np.array([w.inertia for w in self.wheels])

    @property
    def max_momenta(self) -> np.ndarray:
        """Stored-momentum limits, N m s (nw,)."""
        return np.array([w.max_momentum for w in self.wheels])

    @property
    def max_torques(self) -> np.ndarray:
        """Torque limits, N m (nw,)."""
        return np.array([w.max_torque for w in self.wheels])

    def axes(self) -> np.ndarray:
        """Unit spin axes in the base-link frame, one per column (3, nw)."""
        return np.array([w.axis for w in self.wheels]).T.reshape(3, -1)

    def speeds(self, v: np.ndarray) -> np.ndarray:
        """Wheel rates relative to the base ``Omega``, rad/s (nw,), or (N, nw) from rows of ``v``."""
        return v[..., self.v_indices]

    def momenta(self, v: np.ndarray) -> np.ndarray:
        """Stored momentum of each wheel about its axis, ``I_a Omega``, N m s (nw,) or (N, nw)."""
        return self.speeds(v) * self.inertias

    def without_rates(self, v: np.ndarray) -> np.ndarray:
        """``v`` with the wheel rates set to zero (nv,): the arm's view of the state, whose momentum
        is ``M - H_0w Omega`` (the wheels' stored momentum taken out)."""
        out = np.array(v, dtype=float)
        out[self.v_indices] = 0.0
        return out

    def on(self, robot: Robot) -> Wheels:
        """The same wheels on ``robot``, a model that keeps their joints and rotors (the robot with
        joints locked, or with a captured target attached): their indices read from its model,
        their axes, inertias and limits kept.

        Raises:
            RobotModelError: naming the wheel whose joint ``robot`` does not have.
        """
        model, moved = robot.model, []
        for w in self.wheels:
            if not model.existJointName(w.name):
                raise RobotModelError(f"{robot.urdf_path.name}: no joint '{w.name}' to carry the reaction wheel (a wheel "
                                      "cannot be locked)")
            j = model.getJointId(w.name)
            moved.append(dataclasses.replace(w, joint_id=j, v_index=int(model.idx_vs[j]),
                                             column=int(model.idx_vs[j]) - robot.n_base))
        return Wheels(robot, tuple(moved))

    def stored_momentum(self, q: np.ndarray, v: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
        """The part of the centroidal momentum the wheel rates carry, ``A_g[:, w] Omega``
        ([linear; angular about the system CoM], inertial frame, (6,)), from Pinocchio's
        centroidal momentum matrix."""
        model = self.robot.model
        data = model.createData() if data is None else data
        Ag = pin.computeCentroidalMap(model, data, q)
        return Ag[:, self.v_indices] @ self.speeds(v)


def mount_wheels(robot: Robot, specs: list[WheelSpec] | tuple[WheelSpec, ...]) -> Wheels:
    """``robot`` with the wheels of ``specs``: declared over its continuous joints (``axis`` None)
    or added on the base. A declared wheel's link is no end-effector (the loader takes every leaf
    by default): it is removed from ``end_effectors`` and ``arms``.

    Raises:
        RobotModelError: naming the spec's key and the joint: no such joint, a joint that is not
            continuous, not on the base or not a leaf, a name already taken, an axis of zero length,
            not three numbers or (on a planar base) not along z, a mass or inertia that is no
            rotor's (the inertia must be positive and the transverse inertia at least half the
            axial one), or a limit that is not positive.
    """
    if not specs:
        raise RobotModelError(f"{robot.urdf_path.name}: no wheel to mount")
    model = pin.Model(robot.model)
    names = [s.name for s in specs]
    for spec in specs:
        if names.count(spec.name) > 1:
            raise RobotModelError(f"{spec.key}: wheel '{spec.name}' is named twice")
        for limit in ("max_momentum", "max_torque"):
            value = getattr(spec, limit)
            if not (np.isfinite(value) and value > 0.0):
                raise RobotModelError(f"{spec.key}.{limit}: must be a positive number, got {value!r}")
    end_effectors = list(robot.end_effectors)
    for spec in specs:
        if spec.axis is None:
            link = _check_declared(robot, model, spec)
            if link in end_effectors:
                end_effectors.remove(link)
        else:
            _add(robot, model, spec)
    mounted = dataclasses.replace(robot, model=model, end_effectors=tuple(end_effectors),
                                  arms=tuple(a for a in robot.arms if a.end_effector in end_effectors))
    if mounted.model.nq != robot.model.nq and mounted.visual_model is not None:
        mounted = dataclasses.replace(mounted, visual_model=_with_rotors(mounted, specs))
    wheels = tuple(_wheel(mounted, spec) for spec in specs)
    if robot.base == "planar":
        for spec, wheel in zip(specs, wheels):
            if np.linalg.norm(wheel.axis[:2]) > AXIS_TOLERANCE:
                raise RobotModelError(f"{spec.key}.{'joint' if spec.axis is None else 'axis'}: wheel '{spec.name}' spins "
                                      f"about {np.round(wheel.axis, 6).tolist()} in the base-link frame, out of a planar "
                                      "base's plane; the planar joint turns about z only, so a wheel there must spin "
                                      "about z (or give the robot a free base)")
    return Wheels(mounted, wheels)


def _check_declared(robot: Robot, model: pin.Model, spec: WheelSpec) -> str:
    """Check that ``spec.name`` is a continuous joint of the base that moves a leaf; its link."""
    where = f"{spec.key}.joint"
    if not model.existJointName(spec.name) or model.getJointId(spec.name) < 2:
        raise RobotModelError(f"{where}: '{spec.name}' is not a joint of {robot.urdf_path.name}"
                              f"{did_you_mean(spec.name, robot.joint_names, 'joints')}")
    j = model.getJointId(spec.name)
    kind = model.joints[j].shortname()
    if (model.nqs[j], model.nvs[j]) != (2, 1) or "RUB" not in kind and "Unbounded" not in kind:
        raise RobotModelError(f"{where}: '{spec.name}' is a {kind} joint; a reaction wheel turns without limit "
                              "on a continuous joint (URDF type=\"continuous\")")
    if model.parents[j] != 1:
        raise RobotModelError(f"{where}: '{spec.name}' hangs from '{model.names[model.parents[j]]}'; a reaction "
                              "wheel's joint must be a child of the base (the root link)")
    if any(model.parents[k] == j for k in range(j + 1, model.njoints)):
        raise RobotModelError(f"{where}: '{spec.name}' carries further joints; a reaction wheel is a leaf")
    bodies = [f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == j]
    return bodies[0] if bodies else spec.name


def _add(robot: Robot, model: pin.Model, spec: WheelSpec) -> None:
    """Add the wheel joint with its joint frame, and its rotor body with its body frame
    ``<name>_rotor``, to ``model`` (in place)."""
    if model.existJointName(spec.name) or model.existFrame(spec.name) or model.existFrame(f"{spec.name}{ROTOR}"):
        raise RobotModelError(f"{spec.key}.name: '{spec.name}' is already a joint or frame of "
                              f"{robot.urdf_path.name}; name the added wheel otherwise")
    axis = np.asarray(spec.axis, dtype=float)
    if axis.shape != (3,) or not np.isfinite(axis).all():
        raise RobotModelError(f"{spec.key}.axis: must be three finite numbers, got {list(spec.axis)}")
    length = float(np.linalg.norm(axis))
    if length < AXIS_TOLERANCE:
        raise RobotModelError(f"{spec.key}.axis: has zero length {list(spec.axis)}; give the spin axis in the "
                              "base-link frame")
    transverse = 0.5 * spec.inertia if spec.transverse_inertia is None else spec.transverse_inertia
    if not (spec.mass > 0.0 and spec.inertia > 0.0 and 2.0 * transverse >= spec.inertia * (1.0 - 1e-12)):
        raise RobotModelError(f"{spec.key}: mass {spec.mass} kg, inertia {spec.inertia} and transverse_inertia "
                              f"{transverse} kg m^2 are no rotor's: mass and inertia must be > 0 and "
                              "2 transverse_inertia >= inertia")
    placement = pin.SE3(spin_frame(axis / length), np.asarray(spec.position, dtype=float))
    j = model.addJoint(1, pin.JointModelRUBZ(), placement, spec.name)
    model.appendBodyToJoint(j, pin.Inertia(spec.mass, np.zeros(3), np.diag([transverse, transverse, spec.inertia])),
                            pin.SE3.Identity())
    joint_frame = model.addJointFrame(j, model.getFrameId(model.names[1], pin.FrameType.JOINT))
    model.addBodyFrame(f"{spec.name}{ROTOR}", j, pin.SE3.Identity(), joint_frame)


def spin_frame(axis: np.ndarray) -> np.ndarray:
    """A rotation (3, 3) whose third column is the unit vector ``axis`` (3,)."""
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    x = np.cross(helper, axis)
    x /= np.linalg.norm(x)
    return np.column_stack((x, np.cross(axis, x), axis))


def _wheel(robot: Robot, spec: WheelSpec) -> Wheel:
    """The :class:`Wheel` of a mounted spec: axis in the base-link frame and axial inertia read
    from the model (so declared and added wheels are read the same way)."""
    model = robot.model
    j = model.getJointId(spec.name)
    S = _subspace(model, j)
    rotation = model.jointPlacements[j].rotation
    axis_joint = S[3:]
    inertia = model.inertias[j]
    axial = float(axis_joint @ inertia.inertia @ axis_joint)
    lever = inertia.lever - (inertia.lever @ axis_joint) * axis_joint  # CoM off the axis
    axial += inertia.mass * float(lever @ lever)
    if axial <= 0.0:
        raise RobotModelError(f"{spec.key}: wheel '{spec.name}' has no inertia about its axis; it cannot store momentum")
    return Wheel(name=spec.name, joint_id=j, v_index=int(model.idx_vs[j]), column=int(model.idx_vs[j]) - robot.n_base,
                 axis=rotation @ axis_joint, inertia=axial, max_momentum=float(spec.max_momentum),
                 max_torque=float(spec.max_torque))


def _subspace(model: pin.Model, j: int) -> np.ndarray:
    """Motion subspace ``[linear; angular]`` (6,) of the 1-DOF joint ``j`` in its own frame."""
    data = model.joints[j].createData()
    model.joints[j].calc(data, pin.neutral(model))
    return np.asarray(data.S).reshape(6)


def _with_rotors(robot: Robot, specs: list[WheelSpec] | tuple[WheelSpec, ...]) -> pin.GeometryModel:
    """The visual model with a cylinder for each added wheel (radius from its inertia and mass,
    ``I_a = m r^2 / 2``)."""
    import coal

    visual = robot.visual_model.copy()
    for spec in specs:
        if spec.axis is None:
            continue
        j = robot.model.getJointId(spec.name)
        radius = float(np.sqrt(2.0 * spec.inertia / spec.mass))
        geometry = pin.GeometryObject(f"{spec.name}_rotor", j, pin.SE3.Identity(), coal.Cylinder(radius, 0.3 * radius))
        geometry.meshColor = np.array([0.8, 0.6, 0.1, 1.0])
        visual.addGeometryObject(geometry)
    return visual


__all__ = ["AXIS_TOLERANCE", "ROTOR", "Wheel", "WheelSpec", "Wheels", "mount_wheels", "spin_frame"]
