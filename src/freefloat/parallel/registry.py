"""Closed-chain mechanisms that mechanism scenes can run, by name (``[mechanism] name``).

An entry turns a closure file (the URDF spanning tree plus its loop closures, see
:mod:`freefloat.parallel.closed_chain`) and a plant name into a :class:`MechanismSetup`: the
nominal model the controller believes, the "true" plant that is simulated, the loaded closed
chain that draws the animation, and an assembly guess.

To add a mechanism:

1. write ``<name>_setup(closure: Path, plant: str) -> MechanismSetup``. ``nominal`` and
   ``plant`` must share the coordinates ``q = [q#; chain joints in the closure file's order]``
   (the order :func:`~freefloat.parallel.closed_chain.load_closed_chain` gives), have as many
   actuators as platform coordinates (square ``B = C^T U``), and ``guess(q#)`` must return chain
   joints from which ``plant.assemble`` converges at the scene's start;
2. add ``"<name>": MechanismEntry(plants=(...), build=<name>_setup)`` to :data:`REGISTRY`
   (``plants``: the parameter sets a scene may pick as ``[mechanism] plant``);
3. add a scene file in ``src/freefloat/scenes/`` with ``[mechanism] name = "<name>"``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ..registry import Registry
from .closed_chain import ClosedChain, load_closed_chain
from .five_bar import (
    TRUE_PARAMETERS,
    TRUE_PARAMETERS_50,
    FiveBarParameters,
    elbow_guess,
    five_bar,
)
from .mechanism import ParallelMechanism
from .rsu_ppap import assembly_guess, load_data, load_rsu_ppap
from .rsu_ppap_masses import PLANT_ERRORS, plant_masses, tree_inertias, with_masses


class MechanismSetup(NamedTuple):
    """One mechanism ready to simulate.

    Attributes:
        nominal: the model the controller uses, coordinates ``q = [q#; q°]`` (n_q,).
        plant: the simulated mechanism, same coordinates, its parameters possibly off nominal.
        display: the closure file loaded (Pinocchio spanning tree, for the animation).
        guess: ``q# (p,) -> q° (n_q - p,)``: chain joints near the assembly at those platform
            coordinates (Newton's start in :meth:`ParallelMechanism.assemble`).
        tree_inertias: writes the plant's link inertias into a Pinocchio model of the closure
            file's URDF (the spanning tree on a moving base, :mod:`~freefloat.parallel.free_base`);
            the default leaves the URDF's, right where they are the plant's.
    """

    nominal: ParallelMechanism
    plant: ParallelMechanism
    display: ClosedChain
    guess: Callable[[np.ndarray], np.ndarray]
    tree_inertias: Callable[[pin.Model], None] = lambda model: None


@dataclass(frozen=True)
class MechanismEntry:
    """A registry entry: the mechanism's ``name`` (``[mechanism] name`` of a scene), the plant
    names a scene may choose and the builder ``build(closure file, plant name) -> MechanismSetup``."""

    name: str
    plants: tuple[str, ...]
    build: Callable[[Path, str], MechanismSetup]


#: The 5R's plants: the document's parameters, and the 15 % and 50 % errors of sec 5.6.
FIVE_BAR_PLANTS = {"nominal": FiveBarParameters(), "true_15": TRUE_PARAMETERS, "true_50": TRUE_PARAMETERS_50}


def five_bar_setup(closure: Path, plant: str) -> MechanismSetup:
    """The 5R (thesis proposal sec 5.6): the nominal model is the closure file's (its URDF is
    generated from :class:`FiveBarParameters`), the plant is built from ``FIVE_BAR_PLANTS[plant]``
    (``"nominal"``: the closure file's model itself); elbows outward."""
    chain = load_closed_chain(closure)
    params = FIVE_BAR_PLANTS[plant]
    true = chain.mechanism if plant == "nominal" else five_bar(params)
    return MechanismSetup(nominal=chain.mechanism, plant=true, display=chain, guess=partial(elbow_guess, params),
                          tree_inertias=partial(five_bar_inertias, params))


def five_bar_inertias(params: FiveBarParameters, model: pin.Model) -> None:
    """The links of ``params`` in a model of ``five_bar.urdf`` (joints ``c<i>_joint<k>``): mass,
    CoM at lg along the link's x, inertia Jz about z at the CoM, as
    :func:`~freefloat.parallel.five_bar.five_bar_spec` writes them (the lengths are the URDF's)."""
    links = ((params.m1, params.lg1, params.Jz1), (params.m2, params.lg2, params.Jz2))
    for arm in ("c1", "c2"):
        for k, (mass, lg, jz) in enumerate(links, start=1):
            model.inertias[model.getJointId(f"{arm}_joint{k}")] = pin.Inertia(mass, np.array([lg, 0.0, 0.0]),
                                                                              np.diag([0.0, 0.0, jz]))


def rsu_ppap_setup(closure: Path, plant: str) -> MechanismSetup:
    """The 2RSU+PPaP (assumed numbers in ``urdf/rsu_ppap.data.toml``): the closure file's model is
    the nominal model; the plant has the uncertain masses of
    :func:`~freefloat.parallel.rsu_ppap_masses.plant_masses` (``"nominal"``: the model itself);
    assembly guesses from :func:`~freefloat.parallel.rsu_ppap.assembly_guess`."""
    chain, data = load_rsu_ppap(closure), load_data()
    masses = plant_masses(data, plant)
    true = chain.mechanism if plant == "nominal" else with_masses(chain.mechanism, data, masses)
    return MechanismSetup(nominal=chain.mechanism, plant=true, display=chain, guess=partial(assembly_guess, data),
                          tree_inertias=partial(tree_inertias, data, masses))


#: Mechanism name -> entry (``freefloat.MECHANISMS``).
REGISTRY: Registry[MechanismEntry] = Registry("mechanism")
REGISTRY.register(MechanismEntry("five_bar", plants=tuple(FIVE_BAR_PLANTS), build=five_bar_setup))
REGISTRY.register(MechanismEntry("rsu_ppap", plants=tuple(PLANT_ERRORS), build=rsu_ppap_setup))
