"""Visualisation of runs: self-contained meshcat animation pages and dissertation-style figures."""

from .figures import write_figures
from .meshcat_html import ExtraBody, frame_indices, write_trajectory_html

__all__ = ["ExtraBody", "frame_indices", "write_figures", "write_trajectory_html"]
