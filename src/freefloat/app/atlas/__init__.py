"""The atlas: maps over a grid (``freefloat atlas KIND TARGET``), one engine for every kind.

A *kind* is what is mapped (the free-floating workspace of a robot, its dynamic singularities, a
mechanism's workspace and singularity loci, a gain-feasibility map, ...); a *grid* is the
tensor product of a few axes (joint angles, platform coordinates, ...); the engine evaluates the
kind over the grid in chunks and writes one output folder.

The package lives under :mod:`freefloat.app` because it writes run folders and figures and the
command line imports it (see tests/test_architecture.py's layers); a kind may import every
layer below (robot, dynamics, space, parallel) and the rest of :mod:`freefloat.app`.

Modules:
    grid: :class:`~.grid.Axis`, :class:`~.grid.Grid` (points by flat index, chunks) and the memory
        check that refuses a grid too large for this machine.
    kinds: the registry :data:`~.kinds.KINDS` (name -> :class:`~.kinds.AtlasKind`) and the
        :class:`~.kinds.Options` every kind is handed.
    engine: :func:`~.engine.run_atlas`: chunks evaluated in this process, a process pool or on
        Dask, each journaled in the output folder as it finishes (Ctrl-C or SIGTERM keeps the
        finished chunks; the same command again resumes), then the data, summary and figures.
    writer: the output folder's files.
    workspace, singularities: the space-robot kinds.

The contract of a kind (adding one is one module here plus one ``KINDS.register`` line in
:mod:`.kinds`): the module defines, at top level,

- ``OPTIONS: frozenset[str]``: the :class:`~.kinds.Options` fields it reads (the others, when
  given on the command line, are refused with a message naming them);
- ``prepare(target: str, options: Options) -> context``: resolve the target (robot name, URDF
  file, scene, mechanism name), check it, and return a small picklable *context* (a frozen
  dataclass) that holds everything ``evaluate`` needs or can rebuild in a worker process (e.g.
  the robot's loading arguments, loaded once per process behind a cache). Bad targets raise a
  :class:`~freefloat.errors.FreefloatError` subclass naming them;
- ``grid(context, options) -> Grid``: its default grid, refined by ``options.grid`` (points per
  axis) and the other options;
- ``evaluate(context, points) -> dict[str, np.ndarray]``: the chunk evaluator, a top-level
  function (pickled by reference for the pool and Dask). ``points`` is (m, d), one row per grid
  point in the grid's axis order; every array returned has m rows (first axis), any trailing
  shape, the same for every chunk. Evaluate many points per call (vectorise, or loop in compiled
  code): the engine hands it hundreds to thousands at a time;
- ``summarise(context, grid, result) -> dict``: the headline numbers (JSON-able), ``result``
  holding every array with its rows in flat grid order (C order over the axes);
- ``figures(context, grid, result, out: Path) -> list[Path]``: the figures (PNG, and a meshcat
  page for 3-D point clouds), written into ``out``; import matplotlib and meshcat inside it;
- optionally ``SUMMARY_UNITS: dict[str, str]``: the unit of a summary key whose name does not
  say it (``"m/s"``), printed after its value on the terminal;
- optionally ``MIN_CHUNK: int``: the fewest points per chunk, for a kind whose points take long
  each (the engine's default amortises a fast kind's per-call overhead, and would make a slow
  kind's chunks, and what an interrupt loses, minutes long).

The output folder holds ``atlas.npz`` (the axes as ``axis_<name>`` plus every array, rows in flat
grid order), ``summary.json`` (settings, grid, versions, wall time and the kind's summary),
``summary.csv`` (the summary's scalar entries, one per line) and the figures. While the map is
computed, ``atlas-journal.jsonl`` and ``chunks/`` keep what is finished.
"""

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
