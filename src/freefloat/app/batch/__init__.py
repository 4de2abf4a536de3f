"""Batches: N seeded runs of one scene with its initial state or plant varied, run one after
another, on a process pool or on Dask workers, into one table (``freefloat batch``).

Modules: ``variations`` (the bands and each run's seeded draws), ``one_run`` (a run as a worker
runs it, reduced to a row), ``executors`` (serial, pool, Dask), ``driver`` (the folder and the
table).
"""

from __future__ import annotations

from .driver import BatchResult, run_batch
from .executors import Workers
from .variations import VARIES, Band, parse_band

__all__ = ["VARIES", "Band", "BatchResult", "Workers", "parse_band", "run_batch"]
