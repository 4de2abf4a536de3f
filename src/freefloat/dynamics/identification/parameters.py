"""A kinematic tree's dynamic parameters: ten per joint's body, Pinocchio's order.

Pinocchio keeps one inertia per joint (every body fixed to the joint summed into it). Its ten
numbers, ``Inertia.toDynamicParameters()``, are

.. math:: \\pi_j = [m, m c_x, m c_y, m c_z, I_{xx}, I_{xy}, I_{yy}, I_{xz}, I_{yz}, I_{zz}]

in the joint frame: mass (kg), first moments (kg m) and the inertia about the joint frame's
origin (kg m^2), ``I = I_C + m S(c)^T S(c)``. The tree's vector stacks them for joints
1..njoints-1 (10 (njoints - 1),), the columns of Pinocchio's regressors.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...errors import BadShape

#: Pinocchio's order of one body's ten parameters (``Inertia.toDynamicParameters``).
PARAMETER_NAMES = ("m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")


def parameter_names(model: pin.Model) -> tuple[str, ...]:
    """``"<joint>.<parameter>"`` for every column of the tree's regressors (10 (njoints - 1),)."""
    return tuple(f"{model.names[j]}.{p}" for j in range(1, model.njoints) for p in PARAMETER_NAMES)


def model_parameters(model: pin.Model) -> np.ndarray:
    """The tree's dynamic parameters (10 (njoints - 1),): each joint's body in its joint frame."""
    return np.concatenate([model.inertias[j].toDynamicParameters() for j in range(1, model.njoints)])


def with_parameters(model: pin.Model, parameters: np.ndarray) -> pin.Model:
    """A copy of ``model`` whose bodies have ``parameters`` (10 (njoints - 1),).

    Raises:
        BadShape: for a vector of another length.
    """
    parameters = np.asarray(parameters, float)
    if parameters.shape != (10 * (model.njoints - 1),):
        raise BadShape(f"dynamic parameters: {model.name} has {model.njoints - 1} bodies, so 10 x "
                       f"{model.njoints - 1} = {10 * (model.njoints - 1)} parameters; got shape {parameters.shape}")
    out = pin.Model(model)
    for j in range(1, model.njoints):
        out.inertias[j] = pin.Inertia.FromDynamicParameters(parameters[10 * (j - 1): 10 * j])
    return out


def body_parameters(inertia: pin.Inertia, placement: pin.SE3 | None = None) -> np.ndarray:
    """The ten parameters (10,) of ``inertia`` expressed in another frame: ``placement`` is the
    pose of the inertia's frame in that frame (None: the same frame)."""
    return (inertia if placement is None else placement.act(inertia)).toDynamicParameters()


def about_com(parameters: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """``(m, c, I_C)`` of one body's ten parameters (10,): mass (kg), CoM (3,) in the parameters'
    frame (m) and the inertia about the CoM in its axes (3, 3), ``I_C = I - m S(c)^T S(c)``."""
    inertia = pin.Inertia.FromDynamicParameters(np.asarray(parameters, float))
    return float(inertia.mass), inertia.lever.copy(), inertia.inertia.copy()
