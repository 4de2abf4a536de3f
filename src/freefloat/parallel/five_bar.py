"""The planar five-bar 5R of the thesis proposal (sec 5.6, eqs 171-190).

Two RR chains (DH a = l_i, alpha = 0, d = 0, theta = q_i), base joints at x = +l0 (chain 1) and
x = -l0 (chain 2, its base frame mirrored by diag(-1, 1, -1), eq 178); the platform is the
massless end-effector point (x, y), which both chain tips must reach; gravity 9.8 m/s^2 along -y
of the plane. l0 = 0.05 m is not printed in the text; it is the author's own code's value.
The base joints are actuated; :func:`redundant_five_bar` actuates chain 1's elbow too.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..arguments import real_number
from ..errors import NotAssembled
from .mechanism import ParallelMechanism
from .redundancy import EffortDistribution
from .serial import SerialChain


@dataclass(frozen=True)
class FiveBarParameters:
    """5R data (sec 5.6): lengths l1, l2, CoM distances lg1, lg2 from each link's joint, masses,
    inertias about z at the CoM, base half-distance l0 (m, kg, kg m^2)."""

    l1: float = 0.12
    l2: float = 0.15
    lg1: float = 0.06
    lg2: float = 0.075
    m1: float = 0.143
    m2: float = 0.171
    Jz1: float = 171.6e-6
    Jz2: float = 320.6e-6
    l0: float = 0.05
    gravity: float = 9.8


#: The 15 % errors of the simulations of sec 5.6 (the "true" plant against the nominal model).
TRUE_PARAMETERS = FiveBarParameters(lg1=0.051, lg2=0.086, m1=0.1645, m2=0.1967, Jz1=197.3e-6, Jz2=368.7e-6)
#: The same errors grown to 50 % (sec 5.6, last paragraph), with the signs of the 15 % case.
TRUE_PARAMETERS_50 = FiveBarParameters(lg1=0.03, lg2=0.1125, m1=0.2145, m2=0.2565, Jz1=257.4e-6, Jz2=480.9e-6)


#: The fields of :class:`FiveBarParameters` that are lengths (> 0) and masses or inertias (>= 0).
LENGTHS, MASSES = ("l0", "l1", "l2"), ("m1", "m2", "Jz1", "Jz2")


def check_parameters(p: FiveBarParameters) -> None:
    """Refuse 5R data no mechanism has (see :func:`five_bar`'s Raises)."""
    for name, value in vars(p).items():
        real_number(f"FiveBarParameters.{name}", value, above=0.0 if name in LENGTHS else None,
                    low=0.0 if name in MASSES else None)


def chain(p: FiveBarParameters, side: int) -> SerialChain:
    """Chain 1 (side +1, base at +l0) or chain 2 (side -1, base at -l0, mirrored)."""
    base = np.eye(4)
    base[0, 3] = side * p.l0
    if side < 0:
        base[:3, :3] = np.diag([-1.0, 1.0, -1.0])
    inertia = np.array([np.diag([0.0, 0.0, p.Jz1]), np.diag([0.0, 0.0, p.Jz2])])
    # DH frame B_i sits at the far end of link i with x along it: the CoM is at lg - l on x.
    com = np.array([[p.lg1 - p.l1, 0.0, 0.0], [p.lg2 - p.l2, 0.0, 0.0]])
    return SerialChain.from_dh(a=[p.l1, p.l2], alpha=[0.0, 0.0], d=[0.0, 0.0], theta=[0.0, 0.0], prismatic=[False, False],
                               mass=[p.m1, p.m2], com=com, inertia=inertia, base=base, gravity=[0.0, -p.gravity, 0.0])


def five_bar(p: FiveBarParameters = FiveBarParameters()) -> ParallelMechanism:
    """The 5R as a :class:`ParallelMechanism`: q = [x, y, q11, q12, q21, q22].

    Raises:
        InvalidArgument: naming the field of ``p`` that is not a finite number, a length
            (l0, l1, l2) that is not > 0, or a mass or inertia below 0.
    """
    check_parameters(p)
    E = np.zeros((4, 6))
    E[0, 0] = E[1, 1] = E[2, 3] = E[3, 4] = 1.0   # x, y of each tip
    return ParallelMechanism(chains=(chain(p, +1), chain(p, -1)), platform_mass=np.zeros((2, 2)),
                             platform_gravity=np.zeros(2), D=np.vstack((np.eye(2), np.eye(2))), d=np.zeros(4), E=E,
                             F=np.zeros((4, 4)), actuated=np.array([2, 4]))


#: Coordinates of q the redundant 5R actuates: both base joints, then chain 1's elbow (q12).
REDUNDANT_ACTUATED = (2, 4, 3)


def redundant_five_bar(p: FiveBarParameters = FiveBarParameters(),
                       distribution: EffortDistribution | None = None) -> ParallelMechanism:
    """The 5R with a third actuator at chain 1's elbow (redundant actuation: 3 efforts for 2
    platform coordinates, ``urdf/five_bar_redundant.closure.toml``): efforts ``[tau_11, tau_21,
    tau_12]``, shared by ``distribution`` (None: minimum norm)."""
    return replace(five_bar(p), actuated=np.array(REDUNDANT_ACTUATED), distribution=distribution)


def elbow_guess(p: FiveBarParameters, point: np.ndarray) -> np.ndarray:
    """Joint angles of both chains reaching ``point`` (x, y) with the elbows outward (4,).

    Raises:
        NotAssembled: when the point is out of either chain's reach.
    """
    out = []
    for side, c in ((+1, chain(p, +1)), (-1, chain(p, -1))):
        local = np.linalg.solve(c.base, np.array([point[0], point[1], 0.0, 1.0]))[:2]
        cos2 = (local @ local - p.l1**2 - p.l2**2) / (2 * p.l1 * p.l2)
        if abs(cos2) > 1.0:
            raise NotAssembled(f"5R: point {np.round(point, 4).tolist()} m is out of reach of chain {1 if side > 0 else 2}")
        q2 = np.arccos(cos2)
        q1 = np.arctan2(local[1], local[0]) - np.arctan2(p.l2 * np.sin(q2), p.l1 + p.l2 * np.cos(q2))
        out += [q1, q2]
    return np.array(out)


def five_bar_spec(p: FiveBarParameters = FiveBarParameters()):
    """The 5R's spanning tree as a :class:`freefloat.robot.builders.RobotSpec`: two RR arms ``c1``
    (pivot at +l0) and ``c2`` (pivot at -l0, turned by pi about y: eq 178's mirror), links with
    their CoM at lg along x and inertia Jz about z; the tips ``c1_ee``, ``c2_ee`` close the loop.
    The base is fixed (its mass plays no part)."""
    from ..robot.builders import ArmSpec, LinkSpec, RobotSpec

    def links():
        return (LinkSpec(p.l1, p.m1, (0.0, 0.0, p.Jz1), com=(p.lg1, 0.0, 0.0)),
                LinkSpec(p.l2, p.m2, (0.0, 0.0, p.Jz2), com=(p.lg2, 0.0, 0.0)))

    return RobotSpec(name="five_bar", base_mass=1.0, base_inertia=(0.01, 0.01, 0.01), base_com=(0.0, 0.0, 0.0),
                     base_size=(2.2 * p.l0, 0.02, 0.02),
                     arms=(ArmSpec("c1", (p.l0, 0.0, 0.0), (0.0, 0.0, 0.0), links()),
                           ArmSpec("c2", (-p.l0, 0.0, 0.0), (0.0, np.pi, 0.0), links())))
