"""Rigid-body inertias that no rigid body has: the triangle inequality of principal moments
(``I1 + I2 >= I3``), the bodies that break it, and a balanced copy of a model (what
``[robot] inertias = "balanced"`` loads, and what MuJoCo is given)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def triangle_violations(model: pin.Model, tol: float = 0.0) -> list[tuple[str, np.ndarray]]:
    """Bodies (Pinocchio joint names) whose principal moments (ascending, kg m^2, about the CoM)
    break ``I1 + I2 >= I3 - tol``."""
    bad = []
    for j in range(1, model.njoints):
        moments = np.linalg.eigvalsh(model.inertias[j].inertia)
        if moments[0] + moments[1] < moments[2] - tol:
            bad.append((model.names[j], moments))
    return bad


def balanced(model: pin.Model) -> tuple[pin.Model, dict[str, float]]:
    """A copy whose every body satisfies the triangle inequality, and the relative rise of each
    changed body's least principal moment (Pinocchio joint name -> fraction).

    A body with principal moments ``I1 <= I2 <= I3`` and deficit ``d = I3 - I1 - I2 > 0`` gets
    ``I1 + d/2`` and ``I2 + d/2`` (then ``I1 + I2 = I3``) about the same principal axes; mass and
    CoM are kept, and unchanged bodies stay bit-equal.
    """
    copy = model.copy()
    raised = {}
    for name, _ in triangle_violations(model):
        j = model.getJointId(name)
        inertia = model.inertias[j]
        moments, axes = np.linalg.eigh(inertia.inertia)
        deficit = moments[2] - moments[0] - moments[1]
        moved = moments + np.array([0.5, 0.5, 0.0]) * deficit * (1.0 + 1e-9)
        copy.inertias[j] = pin.Inertia(inertia.mass, inertia.lever, axes @ np.diag(moved) @ axes.T)
        raised[name] = 0.5 * deficit / moments[0]
    return copy, raised
