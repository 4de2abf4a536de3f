"""Sweeps through Dask: the distributed gain design equals the serial one; Monte-Carlo runs."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.parallel.five_bar import FiveBarParameters
from freefloat.parallel.sliding_mode import design_gains
from freefloat.parallel.sweeps import client, design_gains_distributed, monte_carlo

POINTS = np.array([[0.07, 0.17], [0.0, 0.22], [-0.05, 0.13], [0.03, 0.12], [-0.02, 0.2]])


@pytest.fixture(scope="module")
def dask_client():
    with client(workers=2, processes=False) as c:
        yield c


def test_distributed_design_equals_the_serial_one(dask_client):
    """Splitting the grid across workers and reducing by maximum gives the serial gains exactly."""
    serial = design_gains(FiveBarParameters(), POINTS)
    distributed = design_gains_distributed(dask_client, FiveBarParameters(), POINTS, chunks=3)
    np.testing.assert_array_equal(distributed.n, serial.n)
    np.testing.assert_array_equal(distributed.T, serial.T)
    for key in serial.n_ij:
        np.testing.assert_array_equal(distributed.n_ij[key], serial.n_ij[key])


def test_monte_carlo_runs_are_seeded_and_within_the_error_band(dask_client):
    """Each run draws its parameters within the band around the nominal ones, reproducibly."""
    first = monte_carlo(dask_client, None, runs=2, relative_error=0.1, seed=3, duration=0.02, step=1e-3, settle=0.0)
    again = monte_carlo(dask_client, None, runs=2, relative_error=0.1, seed=3, duration=0.02, step=1e-3, settle=0.0)
    nominal = FiveBarParameters()
    for run, rerun in zip(first, again):
        assert run == rerun
        for name, value in run["parameters"].items():
            assert abs(value / getattr(nominal, name) - 1) <= 0.1
