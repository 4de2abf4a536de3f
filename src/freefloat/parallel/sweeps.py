"""Sweeps that outgrow one machine, through Dask: the worst-case gain design over the workspace
grid, and a Monte-Carlo robustness study of the sliding-mode controller (issue 6, item 7).

Both take a ``dask.distributed.Client``: :func:`client` starts a local cluster by default or
connects to a scheduler address to scale out. Dask is an optional dependency
(``pip install -e ".[dask]"``); a progress bar shows the tasks as they finish.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from tqdm import tqdm

from .five_bar import FiveBarParameters
from .sliding_mode import (
    UNCERTAINTY,
    PlatformController,
    SlidingModeGains,
    circle_reference,
    gains_from_worst_case,
    track,
    worst_case,
)


def client(address: str | None = None, workers: int = 2, processes: bool = True):
    """A Dask client: connected to ``address`` (e.g. ``tcp://host:8786``) or to a new local cluster
    of ``workers`` workers on this machine (loopback only)."""
    from dask.distributed import Client, LocalCluster

    if address:
        return Client(address)
    network = {"host": "127.0.0.1"} if processes else {}  # in-process clusters have no sockets
    return Client(LocalCluster(n_workers=workers, threads_per_worker=1, processes=processes,
                               dashboard_address=None, **network))


def _gather(dask_client, futures, label: str, quiet: bool) -> list:
    """Results of ``futures`` in submission order, with a progress bar as they complete."""
    from dask.distributed import as_completed

    with tqdm(total=len(futures), desc=label, disable=quiet) as bar:
        for _ in as_completed(futures):
            bar.update(1)
    return dask_client.gather(futures)


def design_gains_distributed(dask_client, nominal: FiveBarParameters, points: np.ndarray, eta: float = 20.0,
                             chunks: int = 16, quiet: bool = True) -> SlidingModeGains:
    """The gain design with the grid split into ``chunks`` tasks, worst cases reduced by maximum."""
    parts = [chunk for chunk in np.array_split(points, chunks) if len(chunk)]
    futures = [dask_client.submit(worst_case, nominal, chunk, UNCERTAINTY, pure=False) for chunk in parts]
    results = _gather(dask_client, futures, "gain design", quiet)
    Dmax = np.max([r[0] for r in results], axis=0)
    d0max = np.max([r[1] for r in results], axis=0)
    dijmax = {k: np.max([r[2][k] for r in results], axis=0) for k in results[0][2]}
    return gains_from_worst_case(Dmax, d0max, dijmax, eta, points)


def _robustness_run(gains: SlidingModeGains | None, plant: FiveBarParameters, duration: float, step: float,
                    settle: float) -> dict:
    """One closed loop: the tracking error after ``settle`` s (mm) and the peak torques."""
    controller = PlatformController(FiveBarParameters(), circle_reference, 40.0, gains)
    _, _, efforts, log = track(plant, controller, duration, step)
    t = np.array([row[0] for row in log])
    e = np.array([row[1] for row in log])
    return {"error_mm": (np.abs(e[t > settle]).max(axis=0) * 1e3).tolist(), "peak_torque": np.abs(efforts).max(axis=0).tolist()}


def monte_carlo(dask_client, gains: SlidingModeGains | None, runs: int, relative_error: float, seed: int = 0,
                duration: float = 0.3, step: float = 2e-4, settle: float = 0.2, quiet: bool = True) -> list[dict]:
    """Closed loops on plants whose six uncertain parameters are drawn uniformly within
    ``relative_error`` of the nominal ones (seeded); each result gives the drawn parameters."""
    rng = np.random.default_rng(seed)
    nominal = FiveBarParameters()
    plants = [replace(nominal, **{n: getattr(nominal, n) * (1 + rng.uniform(-relative_error, relative_error)) for n in UNCERTAINTY})
              for _ in range(runs)]
    futures = [dask_client.submit(_robustness_run, gains, plant, duration, step, settle, pure=False) for plant in plants]
    results = _gather(dask_client, futures, "Monte Carlo", quiet)
    return [dict(r, parameters={n: getattr(p, n) for n in UNCERTAINTY}) for r, p in zip(results, plants)]
