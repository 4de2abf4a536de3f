"""Jerk by the composition of motion: the time derivatives of the linear and angular
accelerations of the bodies, end-effectors and link centres of mass of any Pinocchio tree (serial
chains, branched trees, fixed, planar or free-floating roots), the thesis proposal's eqs 4-5 and
19-21 applied joint by joint as eqs 31-60 apply their first two orders (sec 5.3).

Every vector is in the inertial frame N's axes; every derivative is a classical time derivative
in N (not a spatial, Plücker one): for a point P, ``v = dP/dt``, ``a = d^2P/dt^2`` and the jerk
``j = d^3P/dt^3``; for a body, ``w``, ``alpha = dw/dt`` and ``alpha_dot = d^2 w/dt^2``.

Rigid body (Poisson, eqs 1, 3, 5), points P and O of one body, ``r = P - O``:

.. math::
    v_P = v_O + \\omega \\times r, \\quad
    a_P = a_O + \\alpha \\times r + \\omega \\times (\\omega \\times r), \\\\
    j_P = j_O + \\dot\\alpha \\times r + 2 \\alpha \\times (\\omega \\times r)
          + \\omega \\times (\\alpha \\times r) + \\omega \\times (\\omega \\times (\\omega \\times r)).

Eq 4 as printed has ``alpha x (alpha x r)`` where differentiating eq 3 gives ``alpha x (omega x
r)``; eq 5 (the same line with eq 1 substituted) is right. Both are kept:
:data:`POISSON_FORMS` (``"eq5"``, the default; ``"printed_eq4"``, the printed variant, wrong unless
``alpha x (alpha x r) = alpha x (omega x r)``). The text above eq 21 also leaves
``omega x (omega x (omega x r))`` out of the drag part and calls the relative jerk
``xddot i + ...``; eq 20 and eq 21 themselves are right.

Composition (a point or body C moving relative to a body B; "drag" ``arr``: the motion C would
have fixed to B; "relative" ``rel``: C's motion seen from B, differentiated in B, then expressed
in N's axes), eqs 15, 18, 21 and 37, 53:

.. math::
    j = j_{arr} + j_{rel} + 3 (\\alpha_B \\times v_{rel} + \\omega_B \\times (\\omega_B \\times v_{rel})
        + \\omega_B \\times a_{rel}), \\\\
    \\dot\\alpha_C = \\dot\\alpha_B + \\dot\\alpha_{rel} + 2 \\omega_B \\times \\alpha_{rel}
        + \\alpha_B \\times \\omega_{rel} + \\omega_B \\times (\\omega_B \\times \\omega_{rel}).

The angular line is not printed (the document composes angular velocities and accelerations
only, eqs 37 and 53); it is eq 53 differentiated once more.

A Pinocchio joint moves its child frame C relative to the frame F it hangs from (fixed in the
parent body) with the body twist ``nu = S qd`` (C's axes, [linear; angular]); the joints taken
here have a constant motion subspace S (:data:`JOINTS`), so ``nu_dot = S qdd`` and ``nu_ddot = S
qddd``. With ``R`` C's orientation and ``(v, w) = nu``, ``(v', w') = nu_dot``, ``(v'', w'') =
nu_ddot``, C's motion relative to F in N's axes is

.. math::
    \\omega_{rel} = R w, \\ \\alpha_{rel} = R w', \\ \\dot\\alpha_{rel} = R (w \\times w' + w''), \\\\
    v_{rel} = R v, \\ a_{rel} = R (w \\times v + v'), \\
    j_{rel} = R (w' \\times v + 2 w \\times v' + w \\times (w \\times v) + v'').

The generalized jerk ``qddd`` is the time derivative of Pinocchio's generalized acceleration ``a``
(for a free-flyer root: the second derivative of the base's body twist, local frame). Every
result is affine in it: ``j = J qddd + j(q, qd, qdd, 0)`` with J the point's linear Jacobian
(the jerk's analogue of eq 49).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ..errors import BadShape, InvalidArgument, UnknownName
from .conventions import cross3

#: Pinocchio joints whose motion subspace S is constant in the child frame (what the composition
#: below assumes), by ``JointModel.shortname()``.
JOINTS = frozenset({
    "JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned",
    "JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned",
    "JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned",
    "JointModelFreeFlyer", "JointModelPlanar", "JointModelSpherical", "JointModelTranslation",
})


class Motion(NamedTuple):
    """A point of a body and the body itself, to third order, at one instant; N's axes, SI units.

    Attributes:
        position: the point, m (3,).
        velocity: its velocity, m/s (3,).
        acceleration: its classical acceleration, m/s^2 (3,).
        jerk: its jerk, the time derivative of ``acceleration``, m/s^3 (3,).
        rotation: the body's orientation, body axes to N (3, 3).
        angular_velocity: rad/s (3,).
        angular_acceleration: rad/s^2 (3,).
        angular_jerk: the time derivative of ``angular_acceleration``, rad/s^3 (3,).
    """

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray
    rotation: np.ndarray
    angular_velocity: np.ndarray
    angular_acceleration: np.ndarray
    angular_jerk: np.ndarray


def poisson_jerk(jerk_o: np.ndarray, w: np.ndarray, alpha: np.ndarray, alpha_dot: np.ndarray, r: np.ndarray,
                 form: str = "eq5") -> np.ndarray:
    """Jerk (3,) of a point P of a body from that of a point O of the same body (eq 5): ``jerk_o``
    (3,), the body's ``w``, ``alpha``, ``alpha_dot`` (3,) and ``r = P - O`` (3,), all in N's axes.

    Args:
        form: ``"eq5"`` (the derivative of eq 3) or ``"printed_eq4"`` (eq 4 as printed, with
            ``alpha x (alpha x r)`` in place of ``alpha x (omega x r)``): :data:`POISSON_FORMS`.
    """
    if form not in POISSON_FORMS:
        raise UnknownName("Poisson jerk form", form, POISSON_FORMS)
    wr = cross3(w, r)
    middle = cross3(alpha, wr) + (cross3(alpha, wr) if form == "eq5" else cross3(alpha, cross3(alpha, r)))
    return jerk_o + cross3(alpha_dot, r) + middle + cross3(w, cross3(alpha, r)) + cross3(w, cross3(w, wr))


#: The forms of the Poisson jerk formula :func:`poisson_jerk` takes.
POISSON_FORMS = ("eq5", "printed_eq4")


def point_of(body: Motion, point: np.ndarray, form: str = "eq5") -> Motion:
    """The motion of a point fixed to ``body`` (whose ``position`` is the body's reference point O),
    at ``point`` (3,) in N (eqs 1, 3, 5); the body's angular quantities carried over."""
    r = np.asarray(point, float) - body.position
    w, alpha = body.angular_velocity, body.angular_acceleration
    wr = cross3(w, r)
    return body._replace(position=body.position + r, velocity=body.velocity + wr,
                         acceleration=body.acceleration + cross3(alpha, r) + cross3(w, wr),
                         jerk=poisson_jerk(body.jerk, w, alpha, body.angular_jerk, r, form))


def compose(drag: Motion, relative: Motion) -> Motion:
    """Absolute motion of C from its drag motion and its motion relative to a body B (eqs 15, 18,
    21; 37, 53 and their derivative, module docstring).

    Args:
        drag: C's point as if fixed to B (:func:`point_of` at C's position); its angular fields
            are B's.
        relative: C's motion seen from B, derivatives taken in B, expressed in N's axes
            (``position`` and ``rotation`` are C's absolute ones, carried over).
    """
    w, alpha = drag.angular_velocity, drag.angular_acceleration
    v_rel, a_rel, w_rel, alpha_rel = relative.velocity, relative.acceleration, relative.angular_velocity, \
        relative.angular_acceleration
    return Motion(
        position=relative.position, rotation=relative.rotation,
        velocity=drag.velocity + v_rel,                                                    # eq 15
        acceleration=drag.acceleration + a_rel + 2.0 * cross3(w, v_rel),               # eq 18
        jerk=drag.jerk + relative.jerk + 3.0 * (cross3(alpha, v_rel) + cross3(w, cross3(w, v_rel))
                                                + cross3(w, a_rel)),                   # eq 21
        angular_velocity=w + w_rel,                                                        # eq 37
        angular_acceleration=alpha + alpha_rel + cross3(w, w_rel),                      # eq 53
        angular_jerk=drag.angular_jerk + relative.angular_jerk + 2.0 * cross3(w, alpha_rel)
        + cross3(alpha, w_rel) + cross3(w, cross3(w, w_rel)))


def joint_motions(model: pin.Model, q: np.ndarray, v: np.ndarray, a: np.ndarray, j: np.ndarray,
                  data: pin.Data | None = None, form: str = "eq5") -> list[Motion]:
    """The motion of every joint frame's origin and body (index = Pinocchio joint id; 0 the
    inertial frame, at rest), joint by joint from the root by :func:`compose`.

    Args:
        q, v, a, j: configuration (nq,), generalized velocity, acceleration and jerk (nv,) in
            Pinocchio's convention (a free-flyer's v is the base's body twist, local frame).
        data: a ``pin.Data`` of ``model`` to use (its placements are overwritten), or None.
        form: the Poisson form (:func:`poisson_jerk`) of every drag motion.

    Raises:
        InvalidArgument: for a joint whose motion subspace is not constant (not in
            :data:`JOINTS`), naming it; BadShape for vectors of the wrong size.
    """
    _check(model, q, v, a, j)
    data = model.createData() if data is None else data
    pin.forwardKinematics(model, data, q)
    zero = np.zeros(3)
    out = [Motion(zero, zero, zero, zero, np.eye(3), zero, zero, zero)]
    for i in range(1, model.njoints):
        joint = model.joints[i]
        if joint.shortname() not in JOINTS:
            raise InvalidArgument(f"joint '{model.names[i]}' is a {joint.shortname()}: the jerk composition takes "
                                  f"joints with a constant motion subspace ({', '.join(sorted(JOINTS))})")
        S = np.asarray(data.joints[i].S).reshape(6, joint.nv)
        rows = slice(joint.idx_v, joint.idx_v + joint.nv)
        nu, nu_d, nu_dd = (S @ x[rows] for x in (v, a, j))
        lin, ang, lin_d, ang_d, lin_dd, ang_dd = nu[:3], nu[3:], nu_d[:3], nu_d[3:], nu_dd[:3], nu_dd[3:]
        R, origin = data.oMi[i].rotation, data.oMi[i].translation.copy()
        relative = Motion(origin, R @ lin, R @ (cross3(ang, lin) + lin_d),
                          R @ (cross3(ang_d, lin) + 2.0 * cross3(ang, lin_d) + cross3(ang, cross3(ang, lin)) + lin_dd),
                          R.copy(), R @ ang, R @ ang_d, R @ (cross3(ang, ang_d) + ang_dd))
        parent = out[model.parents[i]]
        out.append(compose(point_of(parent, origin, form), relative))
    return out


def frame_motion(model: pin.Model, q: np.ndarray, v: np.ndarray, a: np.ndarray, j: np.ndarray, frame: str | int,
                 form: str = "eq5") -> Motion:
    """The motion of a frame's origin and of the body it is fixed to (an end-effector, a tool
    point): :func:`joint_motions`, then eqs 1, 3, 5 to the frame's origin.

    Raises:
        InvalidArgument: as :func:`joint_motions`; UnknownName for a frame ``model`` has not.
    """
    if isinstance(frame, str):
        if not model.existFrame(frame):
            raise UnknownName("frame", frame, [f.name for f in model.frames])
        frame = model.getFrameId(frame)
    data = model.createData()
    joint = model.frames[frame].parentJoint
    body = joint_motions(model, q, v, a, j, data, form)[joint]
    placement = data.oMi[joint] * model.frames[frame].placement
    return point_of(body, placement.translation, form)._replace(rotation=placement.rotation)


def com_motions(model: pin.Model, q: np.ndarray, v: np.ndarray, a: np.ndarray, j: np.ndarray,
                form: str = "eq5") -> list[Motion]:
    """The motion of every body's centre of mass (Pinocchio's ``model.inertias[i].lever`` on joint
    i, the bodies of fixed joints merged in), one per joint 1..njoints-1 in Pinocchio's order."""
    data = model.createData()
    bodies = joint_motions(model, q, v, a, j, data, form)
    return [point_of(bodies[i], data.oMi[i].act(model.inertias[i].lever), form) for i in range(1, model.njoints)]


def _check(model: pin.Model, q: np.ndarray, v: np.ndarray, a: np.ndarray, j: np.ndarray) -> None:
    """Shapes and finiteness of the state.

    Raises:
        BadShape: naming the argument, the shape expected and the shape given.
        InvalidArgument: for a non-finite entry.
    """
    for name, x, size in (("q", q, model.nq), ("v", v, model.nv), ("a", a, model.nv), ("j", j, model.nv)):
        if np.shape(x) != (size,):
            raise BadShape(f"jerk: '{name}' must have shape ({size},), got {np.shape(x)}")
        if not np.isfinite(x).all():
            raise InvalidArgument(f"jerk: '{name}' is not finite")
