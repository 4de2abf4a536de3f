"""The lab beside the product: ``bench`` (speed against MuJoCo and the measurement suites) and
``reproduce`` (the documents' studies and their report), with the commands they add to
``freefloat`` through the plug-in :mod:`.plugin`.

The top layer: it may import every layer of freefloat, and nothing in the product imports it
(tests/test_architecture.py).
"""

from __future__ import annotations

from ..lazy import lazy_exports

#: The lab's registries (imported on first use): the bench suites and the studies.
_EXPORTS = {"BENCH_SUITES": ("freefloat.lab.bench.suites", "SUITES"), "STUDIES": "freefloat.lab.reproduce"}
__getattr__ = lazy_exports(__name__, _EXPORTS, globals())
__all__ = sorted(_EXPORTS)
