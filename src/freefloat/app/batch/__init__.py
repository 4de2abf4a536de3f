"""Batches: N seeded runs of one scene with its initial state or plant varied, run one after
another, on threads of this process, on a process pool or on Dask workers, into one table
(``freefloat batch``).

Modules: ``bands`` (the keys and bands of ``--vary``), ``variations`` (each run's seeded draws), ``one_run`` (a run as a worker
runs it, reduced to a row), ``executors`` (serial, threads, pool, Dask), ``driver`` (the folder and the
table). What the bench measures of a batch (plans, one run, the row's timings, a worker's loaded
robots) is exported here too.
"""

from __future__ import annotations

from ...lazy import lazy_exports

#: Exported name -> its module, imported on first use: the command line reads :mod:`.bands`
#: for its help without loading the runs' modules.
_EXPORTS = {"VARIES": ".bands", "Band": ".bands", "parse_band": ".bands", "BatchResult": ".driver",
            "run_batch": ".driver", "Workers": ".executors", "plan_runs": ".variations", "run_one": ".one_run",
            "TIMINGS": ".one_run", "forget_robots": ".one_run"}
__getattr__ = lazy_exports(__name__, _EXPORTS, globals())
__all__ = sorted(_EXPORTS)
