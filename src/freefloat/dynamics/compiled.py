"""The simulation loop in compiled code (``freefloat.dynamics._sim``, built on Pinocchio's C++).

The same loop as :func:`freefloat.dynamics.simulation.run`, period for period: zero-order-hold
control, the tree's forward dynamics as the plant (freefloat's dynamics kernel, :mod:`.kernel`,
wherever it has the tree's joints, else Pinocchio's ABA: :data:`TREE_ABA`), the integrators of
:mod:`freefloat.dynamics.integrators` (the same tableaus, ``dexp^{-1}`` series and step-size
control), the joint-space computed torque of eqs 136-137 with the exact ``H*`` and ``c*``, and the
telemetry row of :class:`~freefloat.dynamics.simulation.Recorder`. The Pinocchio model is handed
over as arrays and rebuilt in C++ (and read into the kernel); :class:`CompiledLoop` checks the
plant's accelerations against ``pin.aba`` before it is used. Python is entered once per telemetry chunk or progress report, so Ctrl-C, checkpoints and
progress bars work as in the Python loop.

The plant is the exact tree (Pinocchio's ABA) or, for a
:class:`~freefloat.dynamics.closures.ClosedModel`, the tree with its loop closures: the constrained
dynamics of :func:`freefloat.dynamics.closures.solve` (CRBA, RNEA with the external wrenches, the
closure rows from Pinocchio's kinematics, the Delassus solve with the same redundancy rule;
``cpp/sim/closures.hpp``).

Two ways to drive it: a whole chunk of periods per call when nothing needs Python between
periods (no controller, or one with a ``compiled_law``, a :class:`CompiledLaw`: the computed
torque on a quintic, the detumbling law or the two-hand law;
external wrenches with their profiles; no stop event),
or one call per period (:meth:`CompiledLoop.step`) with the torques, the active wrenches and the
stop event from Python: any controller then keeps its Python code, and the period's integration
and telemetry row are compiled.

Reuse across runs: building a loop builds a Pinocchio model and its ``Data`` in C++ (each
``Data`` allocates and zeroes four nv^3 tensors, about 85 ms at nv 198, which the loop keeps
none of), and checking it against ``pin.aba`` needs a Python ``Data``. So a process keeps the
loops it has built (:data:`MAX_IDLE` of them, idle between runs) by the robot's structure (joints,
axes, frames); :meth:`CompiledLoop.release` hands one back when its run ends, and the next run on
a robot of the same structure takes it, resets it (:meth:`_sim.Simulation.configure`) and gives it
the robot's numbers (inertias, placements, armature, gravity) when they changed. The check runs
once per model. A reused loop gives the same numbers bit for bit as a new one (tested).
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import fields
from typing import Any, ClassVar, Protocol

import numpy as np
import pinocchio as pin

from ..errors import InvalidArgument
from ..robot.joints import JointCoordinates
from ..robot.loading import BASE_COM_FRAME
from ..robot.robot import Robot
from . import _sim
from .integrators import INTEGRATORS
from .telemetry import Telemetry
from .wrenches import WrenchProfiles

__all__ = ["COMPILED_INTEGRATORS", "COMPILED_PLANTS", "CONVENTION", "MAX_IDLE", "TREE_ABA", "CompiledEngine", "CompiledLaw",
           "CompiledLoop", "chunk_arrays", "closure_arrays", "clear_loops", "joint_arrays", "law_of", "model_arrays",
           "unsupported"]

if _sim.PINOCCHIO_VERSION != pin.__version__:  # the module is linked to the library it was built with
    raise ImportError(f"freefloat's compiled loop was built against Pinocchio {_sim.PINOCCHIO_VERSION} but "
                      f"Pinocchio {pin.__version__} is installed: reinstall freefloat (pip install -e .) or "
                      f"pin {_sim.PINOCCHIO_VERSION}")

#: Integrators the compiled loop runs (the registry's entries marked compiled; momentum projection
#: is not compiled). ``_sim.INTEGRATORS`` lists the compiled side's names; a test checks both agree.
COMPILED_INTEGRATORS = tuple(name for name, spec in INTEGRATORS.items() if spec.compiled)

#: Plant models the compiled loop integrates: the exact tree, and the tree with loop closures
#: (``ClosedModel``, its ``closures`` and ``baumgarte`` handed over).
COMPILED_PLANTS = ("exact", "exact_closed")
#: ABA of the rebuilt model against ``pin.aba`` at a random state: largest relative difference.
REBUILD_TOLERANCE = 1e-9
#: Pinocchio's convention of the compiled plant's ABA and the law's CRBA (``_sim.Simulation.convention``):
#: ``"world"`` (spatial quantities in the inertial frame) and ``"local"`` (in each joint's frame)
#: give the same numbers to round-off (tested to 1e-12), and WORLD was the faster or as fast at
#: every size measured side by side, RKMK4 steps taking turns (``freefloat bench --suite
#: simulation``, part ``convention``: docs/bench.md), so every loop uses it.
CONVENTION = "world"
#: The tree's forward dynamics in the compiled plant (``_sim.Simulation.tree_aba``): ``"kernel"``,
#: freefloat's dynamics kernel (:mod:`.kernel`), wherever the tree has only joints it has (free,
#: planar or no root joint; revolute, continuous and prismatic joints), else Pinocchio's ABA; or
#: ``"pinocchio"`` everywhere. Both give the same numbers to round-off (tested); the kernel costs
#: less per evaluation (``freefloat bench --suite kernel``: docs/bench.md).
TREE_ABA = "kernel"
#: Idle compiled loops a process keeps for the next runs (each holds its model and two ``Data``
#: without the nv^3 tensors: about 4 MB at nv 198), the least recently used dropped first.
MAX_IDLE = 4
#: Fields of :func:`model_arrays` that make the loop's structure (its ``Data`` depend on them);
#: the others are the plant's numbers, set on a reused loop.
_STRUCTURE = ("parent", "kind", "name", "subspace", "frame_parent")

_idle: OrderedDict[tuple, list[tuple[Any, bytes]]] = OrderedDict()  # structure -> [(sim, numbers' digest)]
_checked: OrderedDict[bytes, None] = OrderedDict()  # digests of models whose rebuild passed the check
_lock = threading.Lock()


def clear_loops() -> None:
    """Forget the idle loops and the checked models of this process (the next run builds anew)."""
    with _lock:
        _idle.clear()
        _checked.clear()


def _digest(*parts: Any) -> bytes:
    h = hashlib.blake2b(digest_size=16)
    for part in parts:
        h.update(np.ascontiguousarray(part).tobytes() if isinstance(part, np.ndarray) else repr(part).encode())
    return h.digest()


def unsupported(model: Any, integrator: Any) -> str | None:
    """Why a run with this plant and integrator cannot use the compiled loop, or None when it can:
    the plant must be one of :data:`COMPILED_PLANTS` (the exact model, Pinocchio's ABA, or a
    ``ClosedModel``: the exact tree with loop closures) and the integrator one of
    :data:`COMPILED_INTEGRATORS` (not wrapped in momentum projection)."""
    if getattr(model, "name", None) not in COMPILED_PLANTS:
        return f"the plant model is '{getattr(model, 'name', model)}', not one of {', '.join(COMPILED_PLANTS)}"
    spec = INTEGRATORS.get(getattr(integrator, "name", None), None)
    if spec is None or not spec.compiled or not hasattr(integrator, "model"):
        return f"integrator '{getattr(integrator, 'name', integrator)}' is not compiled"
    return None


class CompiledLaw(Protocol):
    """A controller's law as the compiled loop runs it: one record per law kind (fields named, never
    read by position), defined beside its controller (``QuinticComputedTorqueLaw`` in
    :mod:`freefloat.space.control.computed_torque`, ``DetumblingLaw``, ``LoopDetumblingLaw``,
    ``PlatformLaw`` in :mod:`freefloat.parallel.sliding_mode`); this module knows only this protocol.
    A stateful law also has ``collect(simulation)``, called after each compiled chunk to take back
    the state the loop kept; a law with ``plant_bound = True`` computes on the plant's own numbers
    (its closures), never on a robot of the controller's own."""

    kind: ClassVar[str]

    def install(self, simulation: Any, robot: Robot) -> None:
        """Hand this law to ``simulation`` (a ``_sim.Simulation`` or ``ChainSimulation``) of ``robot``."""
        ...


def closure_arrays(closure: Any) -> tuple:
    """A ``closures.Closure`` as ``_sim`` takes it: (joint1, placement1 (4, 4), joint2,
    placement2 (4, 4), rotation rows)."""
    return (int(closure.joint1), closure.placement1.homogeneous, int(closure.joint2), closure.placement2.homogeneous,
            list(closure.kind.rotation_rows))


def law_of(controller: Any, plant: Robot | None = None) -> CompiledLaw | None:
    """The controller's ``compiled_law()`` (see ``ComputedTorque.compiled_law`` and
    ``DetumblingController.compiled_law``), or None. Given the ``plant``, also None when the
    controller's robot has another structure than the plant's, or when a two-hand law's robot has
    other numbers (that law works on the plant's closures). A controller whose robot has the plant's
    structure and other numbers (a batch's varied masses: the controller keeps the nominal robot)
    keeps its compiled law, which then computes on that robot's model (:func:`law_robot`)."""
    return law_and_robot(controller, plant)[0]


def law_and_robot(controller: Any, plant: Robot | None = None) -> tuple[CompiledLaw | None,
                                                                       Robot | None]:
    """:func:`law_of` and, when the law computes on a robot of its own, that robot
    (:func:`law_robot`; None otherwise), the controller's model compared with the plant's once."""
    law = getattr(controller, "compiled_law", lambda: None)() if controller is not None else None
    own = law_robot(controller, plant) if law is not None and plant is not None else None
    if own is not None and (getattr(law, "plant_bound", False) or not same_structure(own, plant)):
        return None, None
    return law, own


def law_robot(controller: Any, plant: Robot) -> Robot | None:
    """The controller's robot when its model has other numbers than the ``plant``'s (inertias,
    placements, armature or gravity): the robot a compiled law computes ``H*``, ``c*`` and the
    generalized Jacobian on (:class:`CompiledLoop`'s ``law_robot``); None when it has the plant's."""
    own = getattr(controller, "robot", None)
    if own is None or own.model is plant.model or same_numbers(own.model, plant.model):
        return None
    return own


def same_structure(a: Robot, b: Robot) -> bool:
    """Whether two robots rebuild into compiled loops of one structure: the same joints (kinds,
    axes, parents), base, actuated joints and end-effectors (by frame name and parent joint), as
    :class:`CompiledLoop` keys its loops but for joint names, without rebuilding their arrays."""
    ma, mb = a.model, b.model
    if ((ma.nq, ma.nv, a.n_base, a.n_joints, a.end_effectors) != (mb.nq, mb.nv, b.n_base, b.n_joints, b.end_effectors)
            or list(ma.parents) != list(mb.parents)):
        return False
    return (all(x == y for x, y in zip(ma.joints, mb.joints))
            and all(ma.frames[ma.getFrameId(e)].parentJoint == mb.frames[mb.getFrameId(e)].parentJoint
                    for e in a.end_effectors))


def same_numbers(a: pin.Model, b: pin.Model, bodies: bool = True) -> bool:
    """Whether two models of one structure (joints, parents, nv) have the same joint placements,
    armature and gravity and, with ``bodies``, the same bodies (mass, CoM, rotational inertia),
    exactly (False for another structure)."""
    if (a.njoints, a.nv) != (b.njoints, b.nv) or list(a.parents) != list(b.parents):
        return False
    return ((not bodies or all(np.array_equal(x.toDynamicParameters(), y.toDynamicParameters())
                               for x, y in zip(a.inertias, b.inertias)))
            and all(np.array_equal(x.homogeneous, y.homogeneous) for x, y in zip(a.jointPlacements, b.jointPlacements))
            and np.array_equal(a.armature, b.armature) and np.array_equal(a.gravity.linear, b.gravity.linear))


def joint_arrays(model: pin.Model) -> dict[str, Any]:
    """The joints and inertias of ``model`` as the arrays ``_sim.Simulation`` and ``_sim.Kernel``
    rebuild it from.

    Per joint 1..njoints-1: parent joint index; Pinocchio kind; motion subspace ``[linear;
    angular]`` (6,) in the joint frame (zeros for multi-dof joints, which need none); placement in
    the parent joint's frame (4, 4); mass, kg; CoM in the joint frame (3,), m; rotational inertia
    about the CoM in joint-frame axes (3, 3), kg m^2. Armature (nv,), gravity in the inertial
    frame (3,), m/s^2.
    """
    q0 = pin.neutral(model)
    joints = range(1, model.njoints)
    subspace = []
    for j in joints:
        joint = model.joints[j]
        data = joint.createData()
        joint.calc(data, q0)
        S = np.asarray(data.S)  # (6,) for one-dof joints, (6, nv) otherwise
        subspace.append(S if S.ndim == 1 else np.zeros(6))
    return dict(
        parent=[int(model.parents[j]) for j in joints],
        kind=[model.joints[j].shortname() for j in joints],
        name=[model.names[j] for j in joints],
        subspace=np.array(subspace).reshape(-1, 6),
        placement=np.array([model.jointPlacements[j].homogeneous for j in joints]).reshape(-1, 4, 4),
        mass=np.array([model.inertias[j].mass for j in joints]),
        lever=np.array([model.inertias[j].lever for j in joints]).reshape(-1, 3),
        rotational=np.array([model.inertias[j].inertia for j in joints]).reshape(-1, 3, 3),
        armature=np.asarray(model.armature, dtype=float),
        gravity=np.asarray(model.gravity.linear, dtype=float),
    )


def model_arrays(robot: Robot) -> dict[str, Any]:
    """:func:`joint_arrays` of ``robot.model`` and its frames, as ``_sim.Simulation`` takes them:
    in order the base CoM frame then each end-effector, parent joint and placement in its frame
    (4, 4)."""
    model = robot.model
    frames = [model.getFrameId(BASE_COM_FRAME), *robot.end_effector_frame_ids]
    return dict(
        **joint_arrays(model),
        frame_parent=[int(model.frames[f].parentJoint) for f in frames],
        frame_placement=np.array([model.frames[f].placement.homogeneous for f in frames]).reshape(-1, 4, 4),
    )


def chunk_arrays(chunk: Telemetry) -> tuple[np.ndarray, ...]:
    """The chunk's arrays in field order, not copied (the compiled loop fills them in place)."""
    return tuple(getattr(chunk, f.name) for f in fields(chunk))


class CompiledEngine:
    """What both compiled loops (:class:`CompiledLoop`, a robot; and
    :class:`~freefloat.dynamics.compiled_chain.CompiledChainLoop`, a coupled closed chain) share
    of the engine interface, over their extension object ``sim``: chunks of periods, the bound
    chunk, one period, the state and the counts."""

    backend = "compiled"
    sim: Any

    def run(self, last_period: int, chunk: Any, row: int) -> tuple[int, str | None]:
        """Advance to period ``last_period`` or until ``chunk`` is full, writing rows from ``row``.

        Returns the rows written and, when the state blew up, the Python loop's message (None
        otherwise); the run then stopped at the last good period, its rows kept.
        """
        return self.sim.run(last_period, chunk_arrays(chunk), row)

    def bind(self, chunk: Any) -> None:
        """The chunk :meth:`record` writes into."""
        self.sim.bind(chunk_arrays(chunk))

    def record(self, row: int, reference: np.ndarray | None = None) -> None:
        """Row ``row`` of the bound chunk at the current state, with the controller's ``reference``
        (default: the compiled law's, or NaN)."""
        self.sim.record(row, reference)

    def step(self) -> None:
        """One control period. Raises ``OverflowError`` (the Python loop's message) on a blow-up."""
        self.sim.step()

    @property
    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """The current ``(q, v)``."""
        return self.sim.q, self.sim.v

    @property
    def periods_done(self) -> int:
        """Control periods done since period 0."""
        return self.sim.periods_done

    def evaluations(self) -> int:
        """Dynamics evaluations made by the integrator."""
        return self.sim.evaluations


class CompiledLoop(CompiledEngine):
    """One compiled simulation of ``robot``: plant, integrator, controller, telemetry. The same
    per-period interface as :class:`~freefloat.dynamics.simulation.PythonPeriods`.

    Args:
        robot: the robot (its Pinocchio model is rebuilt in C++).
        integrator: an integrator of the registry (its name and settings are copied: ``substeps``,
            and for ``dopri5`` ``rtol``, ``atol``).
        control_period: zero-order-hold period, s.
        start_time: time of period 0, s.
        record_every: one telemetry row every this many periods.
        law: a controller's :class:`CompiledLaw` (its ``compiled_law()``), or None for a
            torque-free run.
        wrenches: external wrenches the loop selects by their profiles at each period of
            :meth:`run` (the per-period interface takes them through :meth:`set_wrenches` instead).
        data: a ``pin.Data`` of ``robot.model`` to check the rebuilt model with (e.g. the exact
            plant's; default: a new one, which costs as much as the loop's own at large nv), or a
            function giving one or None, called only when the check runs (once per model).
        plant: the run's plant model; a ``ClosedModel`` (:data:`COMPILED_PLANTS`) hands its
            closures and Baumgarte rate to the loop, which then integrates the constrained dynamics.
        law_robot: the robot the computed-torque or detumbling ``law`` computes on when it is not
            ``robot`` (:func:`law_robot`: a controller that keeps the nominal robot); it must have
            ``robot``'s structure.
        arrays: ``robot``'s arrays (:func:`model_arrays`) when the caller has them (the loops of
            a lockstep batch: 10 ms each at nv 198); default: made here.

    Raises:
        InvalidArgument: for a joint kind or integrator the compiled loop does not have, or when
            the rebuilt model's ABA differs from ``pin.aba`` (it then names the difference).
    """

    backend = "compiled"

    def __init__(self, robot: Robot, integrator: Any, control_period: float, start_time: float = 0.0,
                 record_every: int = 1, law: CompiledLaw | None = None,
                 wrenches: WrenchProfiles | None = None, data: pin.Data | Callable[[], pin.Data | None] | None = None,
                 plant: Any = None, law_robot: Robot | None = None, arrays: dict[str, Any] | None = None):
        self.robot = robot
        self.law = law
        n_ee = len(robot.end_effectors)
        arrays = model_arrays(robot) if arrays is None else arrays
        coords = JointCoordinates(robot)
        joints = _sim.JointMap(coords.scalar_q.tolist(), coords.scalar_pos.tolist(), coords.circle_q.tolist(),
                               coords.circle_pos.tolist(), robot.n_joints)
        self._structure = (_digest(*(arrays[k] for k in _STRUCTURE), robot.n_base, n_ee, coords.scalar_q,
                                   coords.scalar_pos, coords.circle_q, coords.circle_pos, robot.n_joints),)
        numbers = {k: v for k, v in arrays.items() if k not in _STRUCTURE}
        self._numbers = _digest(*numbers.values())
        settings = dict(integrator=integrator.name, substeps=getattr(integrator, "substeps", 1),
                        rtol=getattr(integrator, "rtol", 1e-10), atol=getattr(integrator, "atol", 1e-12),
                        control_period=control_period, start_time=start_time, record_every=record_every)
        try:
            self.sim = self._take(settings, arrays)
            if self.sim is None:
                self.sim = _sim.Simulation(**arrays, joints=joints, n_base=robot.n_base, **settings, base_frame=0,
                                           ee_frames=list(range(1, n_ee + 1)))
        except ValueError as exc:
            raise InvalidArgument(f"{robot.urdf_path.name}: {exc}") from exc
        self.sim.convention = CONVENTION
        self.sim.tree_aba = "kernel" if TREE_ABA == "kernel" and self.sim.kernel_refusal is None else "pinocchio"
        if law is not None:
            law.install(self.sim, robot)
        if law_robot is not None:
            self.sim.set_law_model(**model_arrays(law_robot))
        if wrenches is not None:
            self.sim.set_wrench_profiles(*wrenches.profiles())
        if getattr(plant, "closures", None):
            self.sim.set_closures([closure_arrays(c) for c in plant.closures], float(plant.baumgarte))
        key = self._structure[0] + self._numbers
        if key not in _checked:
            self._check_rebuild(data)
            with _lock:
                _checked[key] = None
                while len(_checked) > 64:
                    _checked.popitem(last=False)
        self._released = False

    def _take(self, settings: dict[str, Any], arrays: dict[str, Any]) -> Any:
        """An idle loop of this structure, reset for this run with ``settings`` and given the
        robot's numbers when they differ from its last; None when there is none."""
        with _lock:
            idle = _idle.get(self._structure)
            if not idle:
                return None
            sim, numbers = idle.pop()
            if not idle:  # no empty lists: release() evicts from the oldest list
                del _idle[self._structure]
        sim.configure(**settings)
        if numbers != self._numbers:
            sim.set_model(**arrays)
        return sim

    def release(self, numbers_changed: bool = False) -> None:
        """Hand the loop back for the next run on a robot of this structure (its run is over: this
        object must not be used after). Called by :func:`~freefloat.dynamics.simulation.run`.
        ``numbers_changed``: its plant's bodies were set since (runs of other masses,
        :mod:`.many_runs`), so the next run gives it its numbers."""
        if self._released:
            return
        self._released = True
        self.sim.configure("euler", 1, 1e-10, 1e-12, 1.0, 0.0, 1)  # drops the law and the chunk it held
        with _lock:
            _idle.setdefault(self._structure, []).append((self.sim, b"" if numbers_changed else self._numbers))
            _idle.move_to_end(self._structure)
            while sum(len(v) for v in _idle.values()) > MAX_IDLE:
                oldest = next(iter(_idle))
                if _idle[oldest]:
                    _idle[oldest].pop(0)
                if not _idle[oldest]:
                    del _idle[oldest]

    def _check_rebuild(self, data: Any = None) -> None:
        model = self.robot.model
        rng = np.random.default_rng(0)
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, tau = rng.standard_normal(model.nv), rng.standard_normal(model.nv)
        data = data() if callable(data) else data
        expected = pin.aba(model, model.createData() if data is None else data, q, v, tau)
        got = self.sim.acceleration(q, v, tau)
        error = np.abs(got - expected).max() / max(1.0, np.abs(expected).max())
        if not error <= REBUILD_TOLERANCE:
            raise InvalidArgument(f"{self.robot.urdf_path.name}: the compiled model's ABA differs from pin.aba by "
                                  f"{error:.3g} (relative); use the Python loop")

    def start(self, q: np.ndarray, v: np.ndarray, period: int = 0, work: float = 0.0) -> None:
        """Set the state at the start of control period ``period``."""
        self.sim.set_state(q, v, period, work)

    def run(self, last_period: int, chunk: Telemetry, row: int) -> tuple[int, str | None]:
        """:meth:`CompiledEngine.run`, handing the compiled law's state back to its controller."""
        written, blow_up = super().run(last_period, chunk, row)
        collect = getattr(self.law, "collect", None)
        if collect is not None:
            collect(self.sim)
        return written, blow_up

    def hold(self, tau: np.ndarray) -> None:
        """Hold the joint torques ``tau`` (n_joints,) from the current period on."""
        self.sim.hold(tau)

    def set_wrenches(self, field: WrenchProfiles | None) -> None:
        """Hold the wrenches ``field`` has active (after ``field.activate(t)``), or none."""
        self.sim.set_wrenches(*(field.active() if field is not None else ([], np.zeros((0, 3)), np.zeros((0, 3)),
                                                                          np.zeros((0, 3)))))

    def generalized_jacobian(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(J*, J0, J0E H0^-1 M, H0^-1 M)`` at (q, v) from Pinocchio's Jacobians, as in
        :class:`~freefloat.dynamics.gjm.GJMState`: (6k, n), (6, n), (6k,), (6,)."""
        return self.sim.generalized_jacobian(q, v)

    def detumbling_solve(self, q: np.ndarray, v: np.ndarray, rows: np.ndarray, joints: np.ndarray, method: str,
                         secondary: str = "base_angular_velocity", rcond: float = 1e-10) -> tuple[np.ndarray, np.ndarray]:
        """The compiled ``freefloat.space.detumbling.solve`` at (q, v): ``(qdot, residual)`` (n,), (r,)."""
        return self.sim.detumbling_solve(q, v, [int(r) for r in rows], [int(j) for j in joints], method, secondary,
                                         rcond)
