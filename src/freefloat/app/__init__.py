"""The application layer: from a scene file to a run folder, and the command line.

``scenes`` (TOML schema, built-in scenes), ``experiments`` (one module per experiment kind and
their registry), ``runner`` (the one loop life cycle: start, progress, interruption, partial
results), ``outputs`` (the one run-folder writer), ``viz`` (meshcat pages, figures),
``reproduce`` (the documents' studies), ``bench`` (side by side with MuJoCo), ``batch`` (N
seeded varied runs of a scene, serially, on a process pool or on Dask) and ``cli`` (the
``freefloat`` command).

May import every layer below: :mod:`freefloat.space`, :mod:`freefloat.parallel`,
:mod:`freefloat.dynamics`, :mod:`freefloat.robot`. Nothing imports it but the command line.
"""

from ..lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
