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


def test_a_failing_sample_is_recorded_and_the_others_run(dask_client, monkeypatch):
    """A sample that raises is kept as 'failed' with its reason; the sweep goes on."""
    from freefloat.parallel import sweeps

    real = sweeps._robustness_run

    def flaky(gains, plant, *args):
        if plant.m1 > FiveBarParameters().m1:  # about half of the draws
            raise ValueError("bad plant")
        return real(gains, plant, *args)

    monkeypatch.setattr(sweeps, "_robustness_run", flaky)
    results = monte_carlo(dask_client, None, runs=6, relative_error=0.2, seed=1, duration=0.02, step=1e-3, settle=0.0)
    statuses = {r["status"] for r in results}
    assert statuses == {"ok", "failed"} and [r["sample"] for r in results] == list(range(6))
    assert all(r["reason"] == "ValueError: bad plant" for r in results if r["status"] == "failed")


def test_a_sweep_whose_workers_never_answer_ends_with_failures(dask_client, monkeypatch):
    """With no result within the timeout (workers lost) the sweep ends, the rest marked failed."""
    import time

    from freefloat.parallel import sweeps

    monkeypatch.setattr(sweeps, "_robustness_run", lambda *args: time.sleep(3.0))
    start = time.perf_counter()
    results = monte_carlo(dask_client, None, runs=2, relative_error=0.1, timeout=0.5)
    assert time.perf_counter() - start < 2.5
    assert all(r["status"] == "failed" and "within 0.5 s" in r["reason"] for r in results)


@pytest.mark.slow
def test_a_rerun_resumes_from_the_finished_samples(dask_client):
    """Samples given as done are not run again; the new ones are reported as they finish."""
    first = monte_carlo(dask_client, None, runs=2, relative_error=0.1, seed=3, duration=0.02, step=1e-3, settle=0.0)
    seen = []
    again = monte_carlo(dask_client, None, runs=2, relative_error=0.1, seed=3, duration=0.02, step=1e-3, settle=0.0,
                        done={0: first[0]}, on_result=lambda i, r: seen.append(i))
    assert seen == [1] and again == first


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:1", "foo", "udp://x:1"])
def test_bad_or_dead_schedulers_are_named_quickly(address):
    """A malformed address or one where nothing listens is an error naming it (as the Python
    argument ``scheduler``), within seconds."""
    import time

    from freefloat import InvalidArgument

    start = time.perf_counter()
    with pytest.raises(InvalidArgument, match=f"^scheduler '{address}'"):
        client(address, connect_timeout=2.0)
    assert time.perf_counter() - start < 5.0


@pytest.mark.slow
def test_a_real_scheduler_with_worker_processes_runs_the_sweep():
    """--scheduler against a local scheduler whose worker is a separate process."""
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster:
        with client(cluster.scheduler_address) as remote:
            results = monte_carlo(remote, None, runs=2, relative_error=0.1, seed=3, duration=0.02, step=1e-3,
                                  settle=0.0, timeout=120.0)
    assert [r["status"] for r in results] == ["ok", "ok"]


@pytest.mark.parametrize("runs", [0, 10**9, 2.5])
def test_monte_carlo_refuses_a_run_count_outside_its_bound_before_any_work(runs):
    """runs outside [1, MAX_RUNS] (or not an integer) is refused naming runs and the bound, before
    a plant is drawn or a sample submitted (no client is needed to refuse)."""
    from freefloat.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match="runs must be an integer from 1 to 10,000"):
        monte_carlo(None, None, runs=runs, relative_error=0.1)
