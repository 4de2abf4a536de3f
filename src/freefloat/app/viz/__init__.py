"""Visualisation of runs: self-contained meshcat animation pages and dissertation-style figures.

The names below are imported when first used, so that a submodule (the figure helper's
:mod:`.rendering`, :mod:`.plotting`) loads without the figures' and pages' own imports
(Pinocchio, SciPy, the URDF loader).
"""

from __future__ import annotations

from ...lazy import lazy_exports

#: Public name -> the submodule that defines it.
_WHERE = {"write_figures": ".figures", "ExtraBody": ".meshcat_html", "frame_indices": ".meshcat_html",
          "write_trajectory_html": ".meshcat_html"}

__all__ = ["ExtraBody", "frame_indices", "write_figures", "write_trajectory_html"]

__getattr__ = lazy_exports(__name__, _WHERE, globals())  # and its modules, as attributes
