"""Dynamics in the platform coordinates q# (thesis proposal eq 137) and its parts (eqs 162-163).

With ``qdot = C qdot#`` and ``qddot = C qddot# + c``, ``c = [0; A°^+ b]``, the coupled dynamics
``C^T (M' qddot + v' + g') = C^T u'`` become ``H qddot# + h = u*``:

.. math:: H = C^T M' C, \\quad h = C^T (M' c + v') + C^T g', \\quad u^* = C^T U \\tau.

The velocity-dependent part is a quadratic form in qdot#, ``v_M = sum_{i >= j} delta_ij
qdot#_i qdot#_j`` (eq 162); its coefficients are found by polarisation. Joint friction, which is
not quadratic, joins it as ``C^T f(C qdot#)`` (:meth:`ParallelMechanism.joint_friction`).
"""

from __future__ import annotations

import numpy as np

from .mechanism import ParallelMechanism


def platform_dynamics(mech: ParallelMechanism, q: np.ndarray, qd_sharp: np.ndarray):
    """``(H, v_M, g_M, B)`` at an assembled q and platform rates: (p, p), (p,), (p,) and
    ``B = C^T U`` (p, k), which maps actuator efforts to u*; ``v_M`` includes the joint friction
    ``C^T f``."""
    qd = mech.velocity_map(q) @ qd_sharp
    A, b, C, M, v, g = mech.terms(q, qd)
    c = np.concatenate((np.zeros(mech.p), mech.passive_solve(A, b[:, None])[:, 0]))
    return C.T @ M @ C, C.T @ (M @ c + v + mech.joint_friction(qd)), C.T @ g, C.T @ mech.selection()


def quadratic_coefficients(mech: ParallelMechanism, q: np.ndarray) -> dict[tuple[int, int], np.ndarray]:
    """``delta_ij`` (p,) of ``v_M`` for i >= j (eq 162), by polarisation (of the mechanism without
    its joint friction, the part of ``v_M`` that is not quadratic)."""
    mech, p = mech.frictionless(), mech.p
    basis = np.eye(p)
    single = [platform_dynamics(mech, q, basis[i])[1] for i in range(p)]
    out = {}
    for i in range(p):
        out[(i, i)] = single[i]
        for j in range(i):
            out[(i, j)] = platform_dynamics(mech, q, basis[i] + basis[j])[1] - single[i] - single[j]
    return out
