"""The 2RSU+PPaP's uncertain masses: plants whose bodies are off the data file's masses, and the
mechanism as a :class:`~freefloat.parallel.gain_design.LinearParameterModel` for the worst-case
gain design.

Assumed (stated in ``urdf/rsu_ppap.data.toml``): a body's spatial inertia scales with its mass
(uniform density, known shape: the data file's rods, boxes and spheres), its CoM stays at its
geometric centre, and the lengths are exact. A body of mass ``m`` then has ``m / m^`` times the
URDF's spatial inertia, so ``M'``, ``v'``, ``g'`` and eq 137's ``H``, ``v_M``, ``g_M`` are affine
in the uncertain masses theta (r,): ``pi(theta) = [1; theta]``, the constant term being the
bodies whose mass is certain.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ..errors import DataFileError
from .mechanism import ParallelMechanism
from .platform import platform_dynamics, quadratic_coefficients
from .rsu_ppap import CHAIN_JOINTS, assembly_guess, mass

#: The data file's mass of each tree joint's body (bar 2 moves with bar 1; Orsino's model adds
#: its inertia to bar 1's, both of ``ppap.bar_mass``).
BODY_MASS = {**{f"{leg}_{joint}": key for leg in ("rsu1", "rsu2")
                for joint, key in (("crank", "rsu.crank_mass"), ("s1", "rsu.joint_mass"), ("s2", "rsu.joint_mass"),
                                   ("s3", "rsu.rod_mass"), ("u1", "rsu.joint_mass"), ("u2", "rsu.joint_mass"))},
             "ppap_rail": "ppap.slider_mass", "ppap_bar1": "ppap.bar_mass", "ppap_bar2": "ppap.bar_mass",
             "ppap_coupler": "ppap.coupler_mass", "ppap_lift": "platform.mass"}
#: The plants of mechanism scenes (``[mechanism] plant``): every uncertain mass off by this
#: fraction, with :data:`PLANT_SIGNS`.
PLANT_ERRORS = {"nominal": 0.0, "true_15": 0.15, "true_50": 0.5}
#: Signs of the plants' errors (both ways, as the 5R's of sec 5.6): the RSU legs and the platform
#: heavier than the model, the PPaP leg's slider, bars and coupler lighter.
PLANT_SIGNS = {"platform.mass": 1.0, "rsu.crank_mass": 1.0, "rsu.rod_mass": 1.0, "rsu.joint_mass": 1.0,
               "ppap.slider_mass": -1.0, "ppap.bar_mass": -1.0, "ppap.coupler_mass": -1.0}


def plant_masses(data: dict, plant: str) -> dict[str, float]:
    """The uncertain masses (kg) of the named plant (:data:`PLANT_ERRORS`), keyed as
    ``data["uncertainty"]``."""
    return {key: mass(data, key) * (1.0 + PLANT_SIGNS[key] * PLANT_ERRORS[plant]) for key in data["uncertainty"]}


def with_masses(mech: ParallelMechanism, data: dict, masses: dict[str, float]) -> ParallelMechanism:
    """The mechanism loaded by :func:`~freefloat.parallel.rsu_ppap.load_rsu_ppap` with the bodies
    of ``masses`` (kg, keys of :data:`~freefloat.parallel.rsu_ppap.MASSES`; any mass >= 0) in place
    of the data file's: each such link's mass and inertia scaled by ``masses[key] / data mass``.

    Raises:
        FreefloatError: when a link's mass is not the data file's (the URDF was not generated
            from this data file), naming the joint.
    """
    chains = []
    for chain, joints in zip(mech.chains, CHAIN_JOINTS):
        scale = np.ones(chain.dof)
        for i, joint in enumerate(joints):
            key = BODY_MASS[joint]
            expected = mass(data, key) * (2.0 if joint == "ppap_bar1" else 1.0)
            if not np.isclose(chain.mass[i], expected, rtol=1e-12):
                raise DataFileError(f"2RSU+PPaP: the body of joint '{joint}' has {chain.mass[i]} kg, the data file's "
                                    f"'{key}' gives {expected} kg: regenerate urdf/rsu_ppap.urdf (scripts/generate_urdfs.py)")
            if key in masses:
                scale[i] = masses[key] / mass(data, key)
        chains.append(replace(chain, mass=chain.mass * scale, inertia=chain.inertia * scale[:, None, None]))
    return replace(mech, chains=tuple(chains))


def tree_inertias(data: dict, masses: dict[str, float], model: pin.Model) -> None:
    """Scale the bodies of ``masses`` in a Pinocchio model of ``rsu_ppap.urdf`` (the spanning tree
    on a moving base) as :func:`with_masses` does in Orsino's model."""
    for joint, key in BODY_MASS.items():
        if key in masses:
            j = model.getJointId(joint)
            inertia = model.inertias[j]
            s = masses[key] / mass(data, key)
            model.inertias[j] = pin.Inertia(inertia.mass * s, inertia.lever, inertia.inertia * s)


@dataclass(frozen=True, eq=False)
class RsuPpapModel:
    """The 2RSU+PPaP's uncertain masses (the data file's ``[uncertainty]``, in its order) as a
    :class:`~freefloat.parallel.gain_design.LinearParameterModel`: ``pi(theta) = [1; theta]``
    (r + 1,); H, g_M and delta_ij's coefficients from r + 1 evaluations of eq 137 (the certain
    bodies alone, then each uncertain body group at 1 kg on top).

    Attributes:
        mechanism: the nominal mechanism (:func:`~freefloat.parallel.rsu_ppap.load_rsu_ppap`).
        data: :func:`~freefloat.parallel.rsu_ppap.load_data`'s numbers.
    """

    mechanism: ParallelMechanism
    data: dict
    p: int = 3

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.data["uncertainty"])

    @property
    def nominal(self) -> np.ndarray:
        return np.array([mass(self.data, key) for key in self.names])

    @property
    def uncertainty(self) -> np.ndarray:
        return np.array([self.data["uncertainty"][key] for key in self.names], float)

    def linear_parameters(self, theta: np.ndarray) -> np.ndarray:
        """``[1; theta]`` (r + 1,) for the masses theta (r,), kg."""
        return np.concatenate(([1.0], theta))

    @functools.cached_property
    def basis(self) -> tuple[ParallelMechanism, ...]:
        """The mechanism with every uncertain mass zero, then with one of them at 1 kg (r + 1)."""
        unit = np.eye(len(self.names))
        return tuple(with_masses(self.mechanism, self.data, dict(zip(self.names, theta)))
                     for theta in (np.zeros(len(self.names)), *unit))

    def assemble(self, point: np.ndarray) -> np.ndarray:
        """q (19,) at the platform centre ``point`` (3,), m, from the assembly guess."""
        return self.mechanism.assemble(point, assembly_guess(self.data, point))

    def coefficients(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
        """H (r + 1, 3, 3), g_M (r + 1, 3), delta_ij {(i, j): (r + 1, 3)} on ``[1; theta]`` at q."""
        H, g, quad = [], [], []
        for mech in self.basis:
            H_k, _, g_k, _ = platform_dynamics(mech, q, np.zeros(self.p))
            H.append(H_k)
            g.append(g_k)
            quad.append(quadratic_coefficients(mech, q))
        H, g = np.array(H), np.array(g)
        H[1:] -= H[0]
        g[1:] -= g[0]
        out = {}
        for key in quad[0]:
            c = np.array([row[key] for row in quad])
            c[1:] -= c[0]
            out[key] = c
        return H, g, out
