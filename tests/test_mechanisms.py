"""The mechanism registry: the 5R entry gives the closure file's model as nominal, the chosen
parameter set as plant, the closure for display and an assembly guess."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.registry import REGISTRY

from .conftest import REPO

CLOSURE = REPO / "urdf" / "five_bar.closure.toml"
POINT = np.array([0.05, 0.19])


@pytest.fixture(scope="module")
def true_15():
    return REGISTRY["five_bar"].build(CLOSURE, "true_15")


def _state(mech, rates=(0.4, -0.3)):
    q = mech.assemble(POINT, elbow_guess(FiveBarParameters(), POINT))
    return q, mech.velocity_map(q) @ np.array(rates)


def test_nominal_is_the_documents_5r(true_15):
    """The nominal model (read from the closure file) has the data-built 5R's accelerations."""
    reference = five_bar(FiveBarParameters())
    q, qd = _state(reference)
    tau = np.array([0.03, -0.02])
    expected = reference.forward(q, qd, tau)
    np.testing.assert_allclose(true_15.nominal.forward(q, qd, tau), expected, atol=1e-12 * np.abs(expected).max())


def test_true_15_plant_has_the_15_percent_parameters(true_15):
    """The 'true_15' plant is the 5R with sec 5.6's TRUE_PARAMETERS, not the nominal one."""
    reference = five_bar(TRUE_PARAMETERS)
    q, qd = _state(reference)
    tau = np.array([0.03, -0.02])
    np.testing.assert_array_equal(true_15.plant.forward(q, qd, tau), reference.forward(q, qd, tau))
    assert not np.allclose(true_15.nominal.forward(q, qd, tau), reference.forward(q, qd, tau), rtol=1e-3)


def test_guess_lets_the_plant_assemble(true_15):
    """Newton from the entry's guess closes the loop at a workspace point, elbows outward."""
    q = true_15.plant.assemble(POINT, true_15.guess(POINT))
    assert np.abs(true_15.plant.constraint(q)).max() < 1e-12
    np.testing.assert_allclose(q[2:], elbow_guess(TRUE_PARAMETERS, POINT), atol=1e-9)


def test_display_is_the_closure_files_spanning_tree(true_15):
    """The display's Pinocchio tree holds both chains' joints, two of them actuated."""
    names = set(true_15.display.model.names[1:])
    assert names == {"c1_joint1", "c1_joint2", "c2_joint1", "c2_joint2"}
    assert [true_15.display.model.names[j] for j in true_15.display.actuated] == ["c1_joint1", "c2_joint1"]


def test_rsu_ppap_entry_assembles_and_actuates_the_cranks_and_rail():
    """The 2RSU+PPaP entry: its guess lets the plant close all loops at the home pose, and the
    display actuates the two cranks and the rail."""
    setup = REGISTRY["rsu_ppap"].build(REPO / "urdf" / "rsu_ppap.closure.toml", "nominal")
    home = np.array([0.0, 0.0, 0.4])
    q = setup.plant.assemble(home, setup.guess(home))
    assert np.abs(setup.plant.constraint(q)).max() < 1e-12
    assert np.abs(setup.plant.orientation_residual(q)).max() < 1e-12
    assert [setup.display.model.names[j] for j in setup.display.actuated] == ["rsu1_crank", "rsu2_crank", "ppap_rail"]
