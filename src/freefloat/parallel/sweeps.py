"""Sweeps that outgrow one machine, through Dask: the worst-case gain design over the workspace
grid, and a Monte-Carlo robustness study of the sliding-mode controller (issue 6, item 7).

Both take a ``dask.distributed.Client``: :func:`freefloat.distributed.client` (also importable
from here) starts a local cluster by default or connects to a scheduler address to scale out.
Dask is an optional dependency (``pip install -e ".[dask]"``); a progress bar shows the tasks as
they finish.

A sweep survives its workers: a sample that raises is recorded as failed (with the reason)
instead of aborting the others, no result within ``timeout`` s (every worker lost) ends the
sweep with the samples finished so far, and ``on_result`` lets the caller save each finished
sample so that a rerun resumes (``done``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ..distributed import client, settle_futures
from ..errors import FreefloatError, InvalidArgument, spelled
from .closed_loop import track_five_bar
from .five_bar import FiveBarParameters, five_bar
from .gain_design import LinearParameterModel, SlidingModeGains, WorstCase, gains_from_worst_case, worst_case
from .sliding_mode import UNCERTAINTY, FiveBarModel, PlatformControl, circle_reference

#: ``client`` lives in :mod:`freefloat.distributed` and stays importable from here.
__all__ = ["client", "design_gains_distributed", "monte_carlo"]


def design_gains_distributed(dask_client, model: LinearParameterModel | FiveBarParameters, points: np.ndarray,
                             eta: float = 20.0, chunks: int = 16, quiet: bool = True,
                             timeout: float = 600.0) -> SlidingModeGains:
    """The gain design (:func:`freefloat.parallel.gain_design.design_gains`) of ``model`` (5R
    parameters stand for :class:`~freefloat.parallel.sliding_mode.FiveBarModel` of them) with the
    grid split into ``chunks`` tasks, worst cases reduced by maximum.

    Raises:
        FreefloatError: when a chunk fails or none finishes within ``timeout`` s (the design
            needs every point).
    """
    model = FiveBarModel(model) if isinstance(model, FiveBarParameters) else model
    parts = [chunk for chunk in np.array_split(points, chunks) if len(chunk)]
    futures = {i: dask_client.submit(worst_case, model, chunk, pure=False) for i, chunk in enumerate(parts)}
    settled = settle_futures(futures, "gain design", quiet, timeout)
    failed = [i for i in range(len(parts)) if not isinstance(settled.get(i), WorstCase)]
    if failed:
        reasons = {str(settled.get(i, f"no result within {timeout:g} s")) for i in failed}
        # base class: the chunks' failures, of any kind, gathered
        raise FreefloatError(f"gain design: {len(failed)} of {len(parts)} chunks failed ({'; '.join(sorted(reasons))})")
    worst = settled[0]
    for i in range(1, len(parts)):
        worst = worst.combine(settled[i])
    return gains_from_worst_case(worst, eta, points)


#: Most Monte-Carlo samples one call takes: each is a closed loop of about a second here, and
#: every sample's plant and task are made before the first runs (10 000 is about three hours on
#: two workers).
MAX_RUNS = 10_000


def check_monte_carlo(runs: object, relative_error: object) -> None:
    """Refuse a Monte-Carlo before any work: ``runs`` must be an integer in [1, :data:`MAX_RUNS`]
    and ``relative_error`` in [0, 1) (the drawn parameters stay positive).

    Raises:
        InvalidArgument: naming the argument as the caller spells it (:func:`~freefloat.errors.spelled`).
    """
    if isinstance(runs, bool) or not isinstance(runs, (int, np.integer)) or not 1 <= runs <= MAX_RUNS:
        raise InvalidArgument(f"{spelled('runs', '--runs')} must be an integer from 1 to {MAX_RUNS:,} (each sample "
                              f"is a closed loop of about a second), got {runs!r}")
    if isinstance(relative_error, bool) or not isinstance(relative_error, (int, float)) \
            or not 0.0 <= relative_error < 1.0:
        raise InvalidArgument(f"{spelled('relative_error', '--error')} must be in [0, 1) (the drawn parameters stay "
                              f"positive), got {relative_error!r}")


def _robustness_run(gains: SlidingModeGains | None, plant: FiveBarParameters, duration: float, step: float,
                    settle: float) -> dict:
    """One closed loop: the tracking error after ``settle`` s (mm) and the peak torques."""
    control = PlatformControl(five_bar(FiveBarParameters()), circle_reference, 40.0, gains)
    tel = track_five_bar(plant, control, duration, step).telemetry
    t, e, efforts = tel.t[:-1], control.sliding_variables(tel.t, tel.q, tel.v)[0][:-1], tel.efforts[:-1]
    return {"error_mm": (np.abs(e[t > settle]).max(axis=0) * 1e3).tolist(), "peak_torque": np.abs(efforts).max(axis=0).tolist()}


def monte_carlo(dask_client, gains: SlidingModeGains | None, runs: int, relative_error: float, seed: int = 0,
                duration: float = 0.3, step: float = 2e-4, settle: float = 0.2, quiet: bool = True,
                timeout: float = 600.0, done: dict[int, dict] | None = None,
                on_result: Callable[[int, dict], None] | None = None) -> list[dict]:
    """Closed loops on plants whose six uncertain parameters are drawn uniformly within
    ``relative_error`` of the nominal ones (seeded). Each result gives its ``sample`` index, the
    drawn parameters and ``status``: ``"ok"`` with the errors, ``"failed"`` with the reason (the
    sample raised, or no worker finished it within ``timeout`` s). Samples in ``done`` (by index,
    from an earlier run with the same seed) are not run again; ``on_result(index, result)`` is
    called as each new one finishes.

    Raises:
        InvalidArgument: for ``runs`` or ``relative_error`` that :func:`check_monte_carlo` refuses.
    """
    check_monte_carlo(runs, relative_error)
    rng = np.random.default_rng(seed)
    nominal = FiveBarParameters()
    plants = [replace(nominal, **{n: getattr(nominal, n) * (1 + rng.uniform(-relative_error, relative_error)) for n in UNCERTAINTY})
              for _ in range(runs)]
    done = dict(done or {})
    todo = {i: dask_client.submit(_robustness_run, gains, plant, duration, step, settle, pure=False)
            for i, plant in enumerate(plants) if i not in done}

    def described(i: int, outcome: object) -> dict:
        parameters = {n: getattr(plants[i], n) for n in UNCERTAINTY}
        if isinstance(outcome, dict):
            return dict(outcome, sample=i, status="ok", parameters=parameters)
        return {"sample": i, "status": "failed", "reason": f"{type(outcome).__name__}: {outcome}", "parameters": parameters}

    def finished(i: int, outcome: object) -> None:
        done[i] = described(i, outcome)
        if on_result is not None:
            on_result(i, done[i])

    settled = settle_futures(todo, "Monte Carlo", quiet, timeout, finished)
    for i in todo:
        if i not in settled:
            done[i] = described(i, TimeoutError(f"no worker finished it within {timeout:g} s"))
    return [done[i] for i in range(runs)]
