"""A planar 3-RRR: a platform that turns, the thesis proposal's angular constraints with
``P != 0`` (eqs 101-102).

Three RRR chains ``c1``, ``c2``, ``c3`` in the vertical xy plane (gravity along -y) from base
pivots at ``base_radius`` and angles ``theta_k = 90 + 120 k`` deg (k = 0, 1, 2), each ending at
the platform: link 1 (``l1``), link 2 (``l2``), then the platform from its attachment point (at
``platform_radius`` and angle ``theta_k`` in the platform frame) to its centre. The spanning tree
(``urdf/three_rrr.urdf``) gives each chain a third of the platform (mass, and inertia about the
centre, which a disc-like inertia keeps under turns about z) and ends each chain at the frame
``c<k>_ee`` on the platform centre, turned so that the three frames coincide with the platform
frame; ``urdf/three_rrr.closure.toml`` welds them (two weld closures) and actuates the three base
joints. Welded, the thirds are one rigid platform.

Orsino's model (:func:`freefloat.parallel.closed_chain.load_closed_chain`): q# = (x, y, rz), the
platform centre (m) and angle (rad) about N's z; each chain's tip on (x, y) (6 linear rows) and
each tip's angular velocity about z equal to rz's rate (3 angular rows, ``P`` on rz): 9
constraints for the 9 chain joints. No number comes from the documents; every one is here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FreefloatError
from ..paths import URDF_DIR
from .closed_chain import ClosedChain, load_closed_chain

CLOSURE = URDF_DIR / "three_rrr.closure.toml"


@dataclass(frozen=True)
class ThreeRRRParameters:
    """Lengths (m), masses (kg), inertias about z at the CoMs (kg m^2) and gravity (m/s^2, along
    -y) of the 3-RRR; each link's CoM half-way along it, the platform's at its centre."""

    base_radius: float = 0.2
    platform_radius: float = 0.05
    l1: float = 0.12
    l2: float = 0.12
    m1: float = 0.2
    m2: float = 0.15
    Jz1: float = 2.4e-4
    Jz2: float = 1.8e-4
    platform_mass: float = 0.3
    platform_Jz: float = 4.0e-4
    gravity: float = 9.8

    def angles(self) -> np.ndarray:
        """``theta_k`` (3,), rad: the base pivots' and the attachment points' directions."""
        return np.pi / 2 + 2.0 * np.pi / 3 * np.arange(3)


def three_rrr_spec(p: ThreeRRRParameters = ThreeRRRParameters()):
    """The spanning tree as a :class:`freefloat.robot.builders.RobotSpec` (module docstring): arm
    ``c<k>`` pivoted at ``base_radius (cos theta_k, sin theta_k)``, its third link from the
    attachment point to the platform centre (length ``platform_radius``) carrying a third of the
    platform at its tip; ``c<k>_ee`` turned by ``-(theta_k + pi)`` about z, so that it is the
    platform frame (x axis at the platform's angle) once assembled."""
    from ..robot.builders import ArmSpec, LinkSpec, RobotSpec

    third = p.platform_mass / 3.0, p.platform_Jz / 3.0

    def arm(k: int, theta: float) -> ArmSpec:
        links = (LinkSpec(p.l1, p.m1, (p.Jz1 / 2, p.Jz1 / 2, p.Jz1)), LinkSpec(p.l2, p.m2, (p.Jz2 / 2, p.Jz2 / 2, p.Jz2)),
                 LinkSpec(p.platform_radius, third[0], (third[1] / 2, third[1] / 2, third[1]), com=(p.platform_radius, 0.0, 0.0)))
        return ArmSpec(f"c{k + 1}", (p.base_radius * np.cos(theta), p.base_radius * np.sin(theta), 0.0), (0.0, 0.0, 0.0),
                       links, ee_rpy=(0.0, 0.0, -(theta + np.pi)))

    return RobotSpec(name="three_rrr", base_mass=1.0, base_inertia=(0.01, 0.01, 0.01), base_com=(0.0, 0.0, 0.0),
                     base_size=(0.05, 0.05, 0.02), arms=tuple(arm(k, t) for k, t in enumerate(p.angles())))


def load_three_rrr() -> ClosedChain:
    """Orsino's model and Pinocchio's constrained model of the 3-RRR, from its closure file:
    q = [x, y, rz, c1 (3 joints), c2, c3]."""
    return load_closed_chain(CLOSURE)


def assembly_guess(p: ThreeRRRParameters, pose: np.ndarray, elbows: tuple[int, int, int] = (1, 1, 1)) -> np.ndarray:
    """The chains' joint angles (9,), rad, at the platform pose ``(x, y, rz)`` (m, m, rad), each
    chain's elbow on the side ``elbows[k]`` (+1: link 2 turned positively from link 1): exact, the
    two-link inverse kinematics to the attachment point and the third joint turning the platform.

    Raises:
        FreefloatError: when an attachment point is out of its chain's reach, naming the chain.
    """
    x, y, rz = (float(c) for c in pose)
    out = []
    for k, theta in enumerate(p.angles()):
        pivot = p.base_radius * np.array([np.cos(theta), np.sin(theta)])
        attach = np.array([x, y]) + p.platform_radius * np.array([np.cos(theta + rz), np.sin(theta + rz)])
        d = attach - pivot
        cos2 = (d @ d - p.l1**2 - p.l2**2) / (2.0 * p.l1 * p.l2)
        if abs(cos2) > 1.0:
            raise FreefloatError(f"3-RRR: the platform pose {np.round(pose, 4).tolist()} is out of reach of chain c{k + 1}")
        q2 = elbows[k] * np.arccos(cos2)
        q1 = np.arctan2(d[1], d[0]) - np.arctan2(p.l2 * np.sin(q2), p.l1 + p.l2 * np.cos(q2))
        q3 = np.angle(np.exp(1j * (theta + np.pi + rz - q1 - q2)))
        out += [q1, q2, q3]
    return np.array(out)
