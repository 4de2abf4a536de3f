"""``freefloat reproduce redundancy``: the internal forces of shared efforts."""

from __future__ import annotations

import numpy as np

from freefloat.lab.reproduce.redundancy_report import internal_forces
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar, redundant_five_bar
from freefloat.parallel.redundancy import EffortDistribution

P = FiveBarParameters()


def test_internal_forces_are_what_weights_add_to_the_minimum_norm_efforts():
    """At random states the minimum-norm efforts have no internal part (1e-12 of their size); 1:1:4
    weights' efforts have one, equal to their difference from the minimum-norm efforts (both give
    the same platform force); square actuation has none."""
    rng = np.random.default_rng(0)
    plant = redundant_five_bar(P)
    for _ in range(3):
        point = np.array([0.07, 0.17]) + rng.uniform(-0.02, 0.02, 2)
        q = plant.assemble(point, elbow_guess(P, point))
        qd = plant.velocity_map(q) @ rng.normal(size=2)
        u, ZT, _, _ = plant.required_force(q, qd[:2], rng.normal(size=2))
        minimum = EffortDistribution().efforts(ZT, u)
        weighted = EffortDistribution(weights=np.array([1.0, 1.0, 4.0])).efforts(ZT, u)
        rows = internal_forces(plant, np.array([q, q]), np.array([qd, qd]), np.array([minimum, weighted]))
        assert np.abs(rows[0]).max() < 1e-12 * np.abs(minimum).max()
        np.testing.assert_allclose(rows[1], weighted - minimum, atol=1e-12 * np.abs(weighted).max())
        assert np.abs(rows[1]).max() > 1e-3 * np.abs(weighted).max()
    square = five_bar(P)
    q = square.assemble(np.array([0.07, 0.17]), elbow_guess(P, np.array([0.07, 0.17])))
    assert not internal_forces(square, q[None], np.zeros((1, len(q))), np.ones((1, 2))).any()
