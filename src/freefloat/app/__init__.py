"""The application layer: from a scene file to a run folder, and the command line.

``scenes`` (TOML schema, built-in scenes), ``experiments`` (one module per experiment kind and
their registry), ``runner`` (the one loop life cycle: start, progress, interruption, partial
results), ``outputs`` (the one run-folder writer), ``viz`` (meshcat pages, figures), ``batch`` (N
seeded varied runs of a scene, serially, on a process pool or on Dask), ``atlas`` (maps over a
grid), ``commands`` (the commands plug-ins add) and ``cli`` (the ``freefloat`` command).

May import every layer below: :mod:`freefloat.space`, :mod:`freefloat.parallel`,
:mod:`freefloat.dynamics`, :mod:`freefloat.robot`. Only the front door and :mod:`freefloat.lab`
import it.
"""

from __future__ import annotations

from ..lazy import lazy_exports

#: The app's registries (imported on first use): the atlas's kinds and the plug-ins' commands; its
#: modules are attributes too, imported on first use.
_EXPORTS = {"ATLAS_KINDS": ("freefloat.app.atlas.kinds", "KINDS"), "COMMANDS": "freefloat.app.commands"}
__getattr__ = lazy_exports(__name__, _EXPORTS, globals())
