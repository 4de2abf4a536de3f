"""The cases of ``freefloat reproduce models``: the momentum regimes and the model grids, shared
by the study and its output."""

from __future__ import annotations

from ...dynamics.models import MODELS

REGIMES = {"zero momentum": (None, None), "angular momentum only (P = 0)": (None, (3.0, -2.0, 5.0)),
           "linear and angular momentum": ((20.0, -10.0, 5.0), (3.0, -2.0, 5.0))}
GRID_MODELS = ("exact", "standard", "nidc")
EXACT_PLANT_CONTROLLERS = ("exact", "standard", "nidc", "standard_corrected")
TUMBLING_MODELS = tuple(m for m in MODELS if m != "exact")
