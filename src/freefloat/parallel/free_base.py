"""A parallel mechanism on a moving base: its spanning tree on a planar or free-flyer root joint
(the satellite that carries it), the loop closures as Pinocchio rigid constraints, and the
platform law of the fixed-base mechanism acting relative to the base.

The plant is Pinocchio's ``constraintDynamics`` on that tree
(:class:`~freefloat.dynamics.plants.ConstraintDynamicsPlant`):

.. math::

    M(q) a + h(q, v) = S^T u + J(q)^T \\lambda, \\qquad
    J a = -\\dot J v - 2 \\lambda_B J v - \\lambda_B^2 e(q)

``q`` (nq,) the tree's configuration, root joint first (planar: x, y, cos, sin of the yaw in the
inertial xy-plane; free flyer: position and quaternion xyzw), ``v`` (nv,) its velocity (the
root's in Pinocchio's local convention), ``S`` (k, nv) the actuated joints' rows, ``J`` the
closures' Jacobians, ``e`` the closure gaps, ``lambda_B`` Baumgarte's rate (1/s). At zero gravity
nothing outside acts on the system, so its momentum is conserved; on a planar base, the
in-plane components (linear x, y, angular z).

With ``closed_tree`` dynamics (freefloat's constrained dynamics,
:class:`~freefloat.dynamics.closures.ClosedModel`) a moving-base run goes through the compiled
robot loop (:func:`~freefloat.dynamics.simulation.run` with :attr:`FloatingMechanism.robot`, the
tree on its root joint as a :class:`~freefloat.robot.robot.Robot`), the law called from Python
once per control period (:class:`JointEfforts`); the other plants run in the Python loop
(:func:`~freefloat.dynamics.simulation.run_plant`). Both give the same telemetry
(:class:`~freefloat.dynamics.telemetry.PlantTelemetry`; tested equal to round-off).

The controller (:class:`BaseFrameControl`) measures what a controller on the base can: the joint
angles (relative to the base) and the platform point in the base frame, by the fixed-base tree's
forward kinematics. It maps them to Orsino's coordinates ``q = [q#; q°]`` of the fixed-base
mechanism, so the thesis's laws (:class:`~freefloat.parallel.sliding_mode.PlatformControl`)
track the reference relative to the base; the base's reaction is a disturbance they do not model.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from ..dynamics.closures import ClosedModel
from ..dynamics.integrators import INTEGRATORS, make_integrator
from ..dynamics.plants import ClosedTreePlant, ConstraintDynamicsPlant
from ..dynamics.simulation import Result, run, run_plant
from ..dynamics.telemetry import Arrays, PlantTelemetry, Telemetry
from ..errors import InvalidArgument, did_you_mean
from ..robot.loading import BASE_COM_FRAME
from ..robot.robot import Robot
from .closed_chain import AXES, ClosedChain, read_closures

#: Base kinds: ``fixed`` (the URDF's root link is the inertial frame), ``planar`` (x, y and yaw
#: in the inertial xy-plane), ``free`` (6 DOF).
BASES = ("fixed", "planar", "free")
#: Root joint of each moving base.
ROOT_JOINTS = {"planar": pin.JointModelPlanar, "free": pin.JointModelFreeFlyer}
#: Components of the momentum ``[linear; angular]`` that nothing outside changes, per moving base
#: (a planar joint bears the out-of-plane force and moments).
CONSERVED = {"planar": (0, 1, 5), "free": (0, 1, 2, 3, 4, 5)}
#: Regularisation of Pinocchio's proximal solver on a moving base. A closure row can be redundant
#: (the 5R's point closure along the normal of its plane): with mu = 1e-12 the solver's rounding
#: there grows as 1/mu and, on a tumbling base, broke momentum conservation by 9e-6 N s in 0.05 s
#: (torque-free 5R, RK4 at 0.1 ms); with 1e-4, 9e-14 N s, the accelerations unchanged (to 2e-11).
#: On the ground too: the 5R's revolute closure as two point contacts (6 rows, rank 2 in the plane)
#: with Baumgarte 100 at a 1 um closure gap gave accelerations off by 1.4e4 m/s^2 (of 595) with
#: mu = 1e-12, 7e-4 with 1e-4 (freefloat's closed_tree as the reference).
PROXIMAL_MU = 1e-4


def base_problem(kind: str, mass: float | None = None, inertia: Sequence[float] | None = None,
                 com: Sequence[float] | None = None, gravity: Sequence[float] | None = None) -> tuple[str, str] | None:
    """What is wrong with a base description, as ``(field, problem)``, or None.

    ``kind`` one of :data:`BASES`; ``mass`` > 0 (kg); ``inertia`` three principal moments about
    the base's CoM (kg m^2), positive and each at most the sum of the other two (a rigid body);
    ``com`` and ``gravity`` three finite numbers (m, m/s^2). The body's fields (mass, inertia,
    com) describe a moving base; a fixed base takes none.
    """
    if kind not in BASES:
        return "kind", f"is {kind!r}{did_you_mean(kind, BASES)}"
    if kind == "fixed":
        given = [name for name, value in (("mass", mass), ("inertia", inertia), ("com", com)) if value is not None]
        if given:
            return given[0], "describes the base body, which plays no part on a fixed base"
    if mass is not None and not (np.isfinite(mass) and mass > 0):
        return "mass", f"must be > 0 (kg), got {mass!r}"
    for name, value in (("inertia", inertia), ("com", com), ("gravity", gravity)):
        if value is not None and (np.shape(value) != (3,) or not np.isfinite(np.asarray(value, float)).all()):
            return name, f"must be three finite numbers, got {list(np.ravel(value))!r}"
    if inertia is not None:
        moments = np.asarray(inertia, float)
        if (moments <= 0).any() or (2.0 * moments.max() > moments.sum() * (1.0 + 1e-12)):
            return "inertia", (f"must be three positive principal moments (kg m^2), each at most the sum of the "
                               f"other two (a rigid body), got {moments.tolist()}")
    return None


@dataclass(frozen=True)
class BaseBody:
    """The moving base (a satellite) and the gravity it flies in.

    Attributes:
        kind: ``"planar"`` or ``"free"`` (:data:`ROOT_JOINTS`), or ``"fixed"`` (the tree on the
            ground: a tree plant of a fixed-base mechanism; no body fields).
        mass: kg; None: the URDF root link's.
        inertia: principal moments (3,) about the base's CoM along the root link's axes, kg m^2;
            None: the URDF root link's inertia.
        com: the base's CoM in the root link's frame (3,), m; None: the URDF's.
        gravity: inertial frame (3,), m/s^2; None: the closure file's.

    Raises:
        FreefloatError: naming the field (:func:`base_problem`).
    """

    kind: str = "free"
    mass: float | None = None
    inertia: tuple[float, float, float] | None = None
    com: tuple[float, float, float] | None = None
    gravity: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        problem = base_problem(self.kind, self.mass, self.inertia, self.com, self.gravity)
        if problem is not None:
            raise InvalidArgument(f"BaseBody '{problem[0]}' {problem[1]}")


@dataclass
class BaseTelemetry(Arrays):
    """The moving base and the whole system along a run, one row per step.

    Attributes:
        t: time, s (N,).
        q: the tree's configuration, root joint first (N, nq).
        v: its velocity (N, nv).
        base_position: the root link's origin, inertial frame, m (N, 3).
        base_rotation: rotation vector of the base's attitude against its attitude at t = 0,
            ``log3(R(0)^T R(t))``, rad (N, 3) (its norm: the angle turned).
        momentum: the system's momentum about its CoM, inertial axes, ``[linear; angular]``,
            N s and N m s (N, 6).
        com: the system's CoM, inertial frame, m (N, 3).
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    base_position: np.ndarray
    base_rotation: np.ndarray
    momentum: np.ndarray
    com: np.ndarray


class FloatingMechanism:
    """A closure file's mechanism with its spanning tree on a moving base.

    Args:
        chain: the mechanism loaded on its fixed base (:class:`ClosedChain`: Orsino's model, its
            coordinates and the fixed-base tree, which gives the base-frame kinematics).
        closure: the closure file it was loaded from (the same URDF and closures).
        base: the base body and the gravity.
        tree_inertias: writes the plant's link inertias into the tree (a registry's
            ``MechanismSetup.tree_inertias``); the default keeps the URDF's.

    Attributes:
        model: the tree on its root joint (joint 1, ``root_joint``), the base body's inertia on
            it, gravity set.
        constraints: one ``RigidConstraintModel`` per closure on ``model``.
        actuated: velocity index in ``model`` of each actuator, in the closure file's order (k,).

    Raises:
        FreefloatError: as :func:`read_closures`; for a platform with an angle among its
            coordinates (the law here reads translations of the platform frame only).
    """

    def __init__(self, chain: ClosedChain, closure: str | Path, base: BaseBody,
                 tree_inertias: Callable[[pin.Model], None] = lambda model: None):
        if chain.mechanism.rotates:
            raise InvalidArgument(f"{closure}: the platform's coordinates include its angle ('rz'); a mechanism on a base "
                                  "body takes translational platform coordinates only (its law reads the platform "
                                  "frame's x, y, z)")
        moving = base.kind in ROOT_JOINTS
        closures = read_closures(closure, ROOT_JOINTS[base.kind]() if moving else None)
        model = closures.model
        tree_inertias(model)
        if moving:
            root = model.inertias[1]
            model.inertias[1] = pin.Inertia(root.mass if base.mass is None else float(base.mass),
                                            root.lever if base.com is None else np.asarray(base.com, float),
                                            root.inertia if base.inertia is None else np.diag(np.asarray(base.inertia, float)))
        if base.gravity is not None:
            model.gravity = pin.Motion(np.asarray(base.gravity, float), np.zeros(3))
        self.chain, self.base, self.model, self.constraints = chain, base, model, closures.constraints
        self.closures, self.friction = closures.closures, closures.friction
        self.actuated = np.array([model.idx_vs[j] for j in closures.actuated])
        self.root_nq, self.root_nv = (model.nqs[1], model.nvs[1]) if moving else (0, 0)
        fixed = chain.model
        for j in range(1, fixed.njoints):  # the same URDF: its joints follow the root, in the same order
            if model.idx_qs[model.getJointId(fixed.names[j])] != self.root_nq + fixed.idx_qs[j]:
                raise InvalidArgument(f"{closure}: joint '{fixed.names[j]}' is ordered differently on a moving base")
        p, n_q = chain.mechanism.p, chain.mechanism.n_q
        owner = {i: j for j, i in sorted(chain.joint_coordinates.items(), reverse=True)}  # the first joint of each
        #: Orsino's chain coordinate q°_i is the fixed tree's coordinate ``joint_index[i]``.
        self.joint_index = np.array([fixed.idx_qs[owner[i]] for i in range(p, n_q)])
        spec = closures.spec["platform"]
        self.platform_frame = fixed.getFrameId(spec["frame"])
        self.axes = [AXES[c] for c in spec.get("coordinates", ["x", "y", "z"])]
        self.data, self.fixed_data = model.createData(), fixed.createData()
        self.mass = pin.computeTotalMass(model)
        self.urdf = Path(closure)
        self._robot: Robot | None = None

    @property
    def robot(self) -> Robot:
        """The tree on its root joint as a robot of the compiled loop (a moving base only): a copy
        of :attr:`model` with the base CoM frame the loop records, the root link as its base link,
        no end-effectors; joint ids, closures and :attr:`actuated` hold on it.

        Raises:
            FreefloatError: on a fixed base (a robot's root joint is planar or free).
        """
        if self._robot is None:
            if not self.root_nv:
                raise InvalidArgument("a mechanism on a fixed base is no robot: its tree has no root joint")
            model = pin.Model(self.model)
            root = model.inertias[1]
            model.addFrame(pin.Frame(BASE_COM_FRAME, 1, 0, pin.SE3(np.eye(3), root.lever), pin.FrameType.OP_FRAME))
            link = next(f.name for f in model.frames if f.parentJoint == 1 and f.type == pin.FrameType.BODY)
            self._robot = Robot(model=model, visual_model=None, urdf_path=self.urdf, base_link=link,
                                base=self.base.kind, base_com=root.lever.copy(), base_com_rotation=np.eye(3),
                                end_effectors=(), arms=(), link_coms={})
        return self._robot

    def closed_model(self, baumgarte: float = 0.0) -> ClosedModel:
        """The compiled loop's plant on :attr:`robot`: the tree with :attr:`closures`, Baumgarte
        ``baumgarte`` (1/s); the same equations as :class:`~freefloat.dynamics.plants.ClosedTreePlant`."""
        return ClosedModel(self.robot, self.closures, baumgarte)

    def compiled(self, dynamics: str, integrator: str) -> str | None:
        """Why a run with this plant and integrator cannot take the compiled robot loop, or None
        when it can: a moving base, ``closed_tree`` dynamics, no joint friction (the closure file's
        ``[joints]``; the loop has the armature, not the friction) and an integrator the loop has."""
        if not self.root_nv:
            return "the mechanism is on a fixed base"
        if dynamics != ClosedTreePlant.name:
            return f"the plant is '{dynamics}', not '{ClosedTreePlant.name}'"
        if self.friction is not None:
            return "the closure file gives joint friction, which the compiled loop lacks"
        spec = INTEGRATORS.get(integrator, None)
        if spec is None or not spec.compiled:
            return f"integrator '{integrator}' is not compiled"
        return None

    def drift(self, q: np.ndarray) -> tuple[float, float]:
        """Largest closure position residual (m) and rotation residual (rad) at ``q``: those of
        :func:`~freefloat.dynamics.closures.closure_drift` (the distance between the two frames;
        a weld's angle ``|log3(R1^T R2)|``, a revolute's ``|(z x R1^T R2 z)_xy|``) from the
        placements alone, 1e-15 apart from it and about 20 times cheaper (no Jacobians)."""
        data = self.data
        pin.forwardKinematics(self.model, data, q)
        position = rotation = 0.0
        for c in self.closures:
            first, second = data.oMi[c.joint1] * c.placement1, data.oMi[c.joint2] * c.placement2
            position = max(position, float(np.linalg.norm(second.translation - first.translation)))
            rows = list(c.kind.rotation_rows)
            relative = first.rotation.T @ second.rotation
            if len(rows) == 3:
                rotation = max(rotation, float(np.linalg.norm(pin.log3(relative))))
            elif rows:
                rotation = max(rotation, float(np.linalg.norm(np.cross([0.0, 0.0, 1.0], relative[:, 2])[rows])))
        return position, rotation

    def plant_rows(self, telemetry: Telemetry, control: Any) -> PlantTelemetry:
        """A compiled robot run's rows (:class:`~freefloat.dynamics.telemetry.Telemetry`) as the
        Python loop records them (:class:`~freefloat.dynamics.telemetry.PlantTelemetry`): the
        actuated joints' efforts, ``control.reference(t)`` and the closure drift of each row."""
        n = len(telemetry.t)
        drift = np.array([self.drift(q) for q in telemetry.q]).reshape(n, 2)
        reference = np.array([control.reference(t) for t in telemetry.t]).reshape(n, -1)
        return PlantTelemetry(t=telemetry.t, q=telemetry.q, v=telemetry.v,
                              efforts=telemetry.tau[:, self.actuated - self.root_nv], reference=reference,
                              drift=drift[:, 0], orientation_drift=drift[:, 1])

    @property
    def conserved(self) -> tuple[int, ...]:
        """Indices of the momentum components ``[linear; angular]`` nothing outside changes but
        gravity (:data:`CONSERVED`)."""
        return CONSERVED[self.base.kind]

    def plant(self, baumgarte: float = 0.0, max_drift: float = 1.0,
              dynamics: str = ConstraintDynamicsPlant.name) -> ConstraintDynamicsPlant | ClosedTreePlant:
        """The plant of the one loop on :attr:`model` with the closures, efforts on
        :attr:`actuated`, Baumgarte ``lambda`` (1/s): ``dynamics`` ``"constraint_dynamics"``
        (Pinocchio's, the proximal solver's mu :data:`PROXIMAL_MU`) or
        ``"closed_tree"`` (freefloat's, :mod:`freefloat.dynamics.closures`); with the closure
        file's joint friction, if any."""
        if dynamics == ClosedTreePlant.name:
            return ClosedTreePlant(self.model, self.closures, self.actuated, baumgarte, max_drift, self.friction)
        return ConstraintDynamicsPlant(self.model, self.constraints, self.actuated, baumgarte, max_drift,
                                       mu=PROXIMAL_MU, friction=self.friction)

    def tree_state(self, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The tree's ``(q (nq,), v (nv,))`` at Orsino's ``q``, ``qd`` (n_q,), the base at the
        inertial origin, unturned and at rest."""
        config, velocity = pin.neutral(self.model), np.zeros(self.model.nv)
        config[self.root_nq:] = self.chain.pinocchio_q(q)
        velocity[self.root_nv:] = self.chain.pinocchio_q(qd)
        return config, velocity

    def relative(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Orsino's ``(q, qd)`` (n_q,) relative to the base at the tree's state ``(q, v)``: the
        platform point's coordinates q# and rates in the base frame (the root link's; the
        fixed-base tree's forward kinematics at the joints), and the chains' joints q°."""
        fixed, data = self.chain.model, self.fixed_data
        joints, rates = q[self.root_nq:], v[self.root_nv:]
        pin.forwardKinematics(fixed, data, joints, rates)
        frame = pin.updateFramePlacement(fixed, data, self.platform_frame)
        velocity = pin.getFrameVelocity(fixed, data, self.platform_frame, pin.LOCAL_WORLD_ALIGNED).linear
        return (np.concatenate((frame.translation[self.axes], joints[self.joint_index])),
                np.concatenate((velocity[self.axes], rates[self.joint_index])))

    def relative_rows(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`relative` at each recorded state (N, nq), (N, nv): two arrays (N, n_q)."""
        rows = [self.relative(qk, vk) for qk, vk in zip(q, v)]
        n_q = self.chain.mechanism.n_q
        return (np.array([r[0] for r in rows]).reshape(-1, n_q), np.array([r[1] for r in rows]).reshape(-1, n_q))

    def base_placement(self, q: np.ndarray) -> pin.SE3:
        """The root link's placement in the inertial frame at the tree's ``q`` (the identity on a
        fixed base)."""
        if not self.root_nv:
            return pin.SE3.Identity()
        pin.forwardKinematics(self.model, self.data, q)
        return self.data.oMi[1]

    def momentum(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The system's momentum about its CoM, inertial axes, ``[linear; angular]`` (6,), and its
        CoM (3,), m."""
        pin.computeCentroidalMomentum(self.model, self.data, q, v)
        return self.data.hg.vector.copy(), self.data.com[0].copy()

    def describe(self, telemetry: PlantTelemetry) -> BaseTelemetry:
        """The base and system quantities of a run's rows (:class:`BaseTelemetry`)."""
        n = len(telemetry.t)
        position, rotation, momentum, com = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 6)), np.zeros((n, 3))
        start = None
        for k in range(n):
            placement = self.base_placement(telemetry.q[k])
            start = placement.rotation.copy() if start is None else start
            position[k], rotation[k] = placement.translation, pin.log3(start.T @ placement.rotation)
            momentum[k], com[k] = self.momentum(telemetry.q[k], telemetry.v[k])
        return BaseTelemetry(t=telemetry.t, q=telemetry.q, v=telemetry.v, base_position=position,
                             base_rotation=rotation, momentum=momentum, com=com)

    def momentum_drift(self, telemetry: BaseTelemetry) -> np.ndarray:
        """Per row, the largest change of a conserved momentum component beyond gravity's
        impulse: ``max_i |h_i(t) - h_i(0) - [m g t; 0]_i|`` over :attr:`conserved` (N,), N s or
        N m s (gravity exerts no moment about the CoM)."""
        impulse = np.zeros((len(telemetry.t), 6))
        impulse[:, :3] = self.mass * np.outer(telemetry.t - telemetry.t[0], self.model.gravity.linear)
        change = telemetry.momentum - telemetry.momentum[:1] - impulse
        return np.abs(change[:, list(self.conserved)]).max(axis=1)


class BaseFrameControl:
    """A platform law of the fixed-base mechanism on Orsino's coordinates (its ``torque(t, q,
    qd)``, :class:`~freefloat.parallel.sliding_mode.PlatformControl`), on the moving base: it
    reads the joints and the platform in the base frame (:meth:`FloatingMechanism.relative`) and
    its efforts drive the actuated joints (the plant's ``actuated``, the same order).

    Args:
        compiled: evaluate the law by its compiled form when it has one
            (:meth:`~freefloat.parallel.sliding_mode.PlatformControl.compiled_torque`: the same
            efforts to round-off, about 10 times cheaper); False: its numpy ``torque``, the reference.

    Attributes:
        law: the fixed-base law.
        mechanism: the mechanism on its moving base.
    """

    def __init__(self, law: Any, mechanism: FloatingMechanism, compiled: bool = True):
        self.law, self.mechanism = law, mechanism
        fast = getattr(law, "compiled_torque", lambda: None)() if compiled else None
        self._efforts = law.torque if fast is None else fast

    @property
    def model(self) -> Any:
        """The nominal model the law believes."""
        return self.law.model

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Actuator efforts (k,) at the tree's state ``(q, v)``, N m or N."""
        return self._efforts(t, *self.mechanism.relative(q, v))

    def reference(self, t: float) -> np.ndarray:
        """The platform reference q#_d (p,) in the base frame."""
        return self.law.reference(t)


class JointEfforts:
    """A controller of the tree's actuators as a robot controller of the compiled loop
    (:func:`~freefloat.dynamics.simulation.run`): torques on every joint but the root's, the
    controller's efforts on the actuated joints and zero on the passive ones.

    Args:
        control: efforts ``torque(t, q, v)`` (k,) at the tree's state, in :attr:`FloatingMechanism.actuated`'s order.
        mechanism: the mechanism on its moving base.
    """

    def __init__(self, control: Any, mechanism: FloatingMechanism):
        self.control = control
        self.index = mechanism.actuated - mechanism.root_nv
        self.n_joints = mechanism.model.nv - mechanism.root_nv

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Joint torques (nv - root nv,), N m or N."""
        tau = np.zeros(self.n_joints)
        tau[self.index] = self.control.torque(t, q, v)
        return tau

    def reference(self, t: float) -> None:
        """No joint reference (the platform's is the mechanism telemetry's)."""
        return None


def track(mechanism: FloatingMechanism, law: Any, q0: np.ndarray, v0: np.ndarray, duration: float, step: float,
          baumgarte: float = 100.0, integrator: str = "rkmk4", dynamics: str = ConstraintDynamicsPlant.name,
          backend: str = "auto", substeps: int = 1, rtol: float = 1e-10, atol: float = 1e-12,
          control: Any = None, **kwargs: Any) -> Result:
    """The closed loop on the moving base from the tree's ``(q0, v0)``: the law (through
    :class:`BaseFrameControl`) evaluated every ``step`` s and held, one telemetry row per step.

    ``closed_tree`` dynamics on a moving base with a compiled integrator go through the compiled
    robot loop (:func:`~freefloat.dynamics.simulation.run` on :attr:`FloatingMechanism.robot`,
    :meth:`FloatingMechanism.closed_model`; the law from Python once per step); anything else
    through :func:`~freefloat.dynamics.simulation.run_plant` on :meth:`FloatingMechanism.plant` (the
    Python loop). Either way the telemetry is a :class:`~freefloat.dynamics.telemetry.PlantTelemetry`.

    Args:
        dynamics: the plant (:meth:`FloatingMechanism.plant`).
        backend: ``"auto"`` (compiled when it can), ``"compiled"`` or ``"python"``.
        substeps: integrator steps per control step; ``rtol``, ``atol``: an adaptive integrator's.
        control: the controller on the tree's state, default ``BaseFrameControl(law, mechanism)``.
        kwargs: ``progress``, ``checkpoint`` (called with PlantTelemetry chunks), ``record_every``.

    Raises:
        InvalidArgument: ``"compiled"`` for a run the compiled loop cannot do (with the reason).
    """
    control = BaseFrameControl(law, mechanism) if control is None else control
    reason = mechanism.compiled(dynamics, integrator)
    if backend == "compiled" and reason is not None:
        raise InvalidArgument(f"the compiled loop cannot run this: {reason}")
    if backend == "python" or reason is not None:
        return run_plant(mechanism.plant(baumgarte, dynamics=dynamics), q0, v0, duration, step, integrator, control,
                         substeps, rtol, atol, backend="python", **kwargs)
    checkpoint = kwargs.pop("checkpoint", None)
    result = run_compiled(mechanism, control, q0, v0, duration, step, baumgarte, integrator, substeps, rtol, atol,
                          checkpoint=None if checkpoint is None else
                          (lambda rows: checkpoint(mechanism.plant_rows(rows, control))), **kwargs)
    return dataclasses.replace(result, telemetry=mechanism.plant_rows(result.telemetry, control))


def run_compiled(mechanism: FloatingMechanism, control: Any, q0: np.ndarray, v0: np.ndarray, duration: float,
                 period: float, baumgarte: float, integrator: str, substeps: int = 1, rtol: float = 1e-10,
                 atol: float = 1e-12, **kwargs: Any) -> Result:
    """The compiled robot loop of :func:`track` (``closed_tree`` on a moving base): ``control``'s
    efforts (on the tree's state) held over each ``period`` s, ``substeps`` steps of
    ``integrator`` per period, the robot's telemetry
    (:class:`~freefloat.dynamics.telemetry.Telemetry`, one row per period; :meth:`FloatingMechanism.plant_rows`
    makes it the Python loop's). ``kwargs``: :func:`~freefloat.dynamics.simulation.run`'s
    ``progress``, ``checkpoint``, ``record_every``.

    Raises:
        InvalidArgument: when the compiled loop cannot run it (with the reason).
    """
    robot = mechanism.robot
    return run(robot, q0, v0, duration, period, make_integrator(integrator, robot.model, substeps, rtol, atol),
               mechanism.closed_model(baumgarte), JointEfforts(control, mechanism), backend="compiled", **kwargs)
