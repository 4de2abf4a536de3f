"""Euclidean coordinates as a Pinocchio configuration space, so that every integrator of the
registry (written on Lie groups) integrates them: on R^n, ``integrate(q, dq) = q + dq`` and
``dexp^-1`` is the identity, so the Runge-Kutta-Munthe-Kaas schemes are the classical ones."""

from __future__ import annotations

import functools

import pinocchio as pin


@functools.lru_cache(maxsize=32)
def vector_space(n: int) -> pin.Model:
    """R^n as a Pinocchio model: ``n`` prismatic joints in series (nq = nv = n), massless.

    The returned model is shared between callers (cached): do not modify it.
    """
    model = pin.Model()
    parent = 0
    for i in range(n):
        parent = model.addJoint(parent, pin.JointModelPX(), pin.SE3.Identity(), f"x{i}")
    return model
