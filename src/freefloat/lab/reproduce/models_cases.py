"""The cases of ``freefloat reproduce models``: the dissertation's Table 1, the momentum regimes
and the model grids, shared by the study and its output."""

from __future__ import annotations

from ...dynamics.models import MODELS

#: Table 1 of the dissertation (nested RMS, per arm and overall): plant FM-NIC-A.
TABLE_1 = {"nidc": [4.91e-7, 4.91e-7, 4.91e-7, 4.91e-7, 4.91e-7],
           "standard": [1.18e-4, 1.18e-4, 1.13e-4, 1.13e-4, 1.16e-4]}
REGIMES = {"zero momentum": (None, None), "angular momentum only (P = 0)": (None, (3.0, -2.0, 5.0)),
           "linear and angular momentum": ((20.0, -10.0, 5.0), (3.0, -2.0, 5.0))}
GRID_MODELS = ("exact", "standard", "nidc")
EXACT_PLANT_CONTROLLERS = ("exact", "standard", "nidc", "standard_corrected")
TUMBLING_MODELS = tuple(m for m in MODELS if m != "exact")
