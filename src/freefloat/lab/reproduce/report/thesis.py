"""The thesis's entries in the report (sec 5.6, the 5R: figs 6-25, table 2, eq 187, then its
errata), in its order: :data:`ENTRIES`.

Each entry is declared once; the time series of figs 10-25 come from one function per group of
runs. What the thesis prints is in :mod:`..printed`; what the report computes itself, in
:mod:`.checks`.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from .. import printed
from . import figures as rf
from .checks import (
    CIRCLE,
    dh_entry_1_3,
    distance,
    five_bar_points,
    link_lengths,
    s_x_with_printed_error,
    saturation,
    saturation_slope_at_zero,
)
from .entry import THESIS, Entry, Row, row
from .results import Results

FB = "five_bar"
#: Where the thesis's 5R starts, as its figures and rows write it.
START = f"({printed.START[0]}, {printed.START[1]})"


def _cases(r: Results, *names: str) -> dict[str, dict]:
    return {name: r.report(FB)["cases"][name] for name in names}


def _case_rows(r: Results, name: str, printed_error: tuple | None) -> list[Row]:
    c = r.report(FB)["cases"][name]
    rows = [row(f"{name}: max |error| after 0.2 s, {axis} (mm)", None if printed_error is None else printed_error[i],
                c["error_after_0.2s_mm"][i]) for i, axis in enumerate("xy")]
    if name.startswith("sliding"):
        rows.insert(0, row(f"{name}: reaching time of s_y, |s| < 0.02 (s)", printed.REACHING_TIME_S,
                           c["reaching_time_s"][1]))
    return rows


def _lengths() -> str:
    return ", ".join(f"{v:.4g}" for v in link_lengths())


def _workspace_rows(r: Results) -> list[Row]:
    fb, threshold = r.report(FB), r.report(FB)["settings"]["max_condition"]
    w, sing = fb["workspace"], fb["singularities"]
    cell = (w["x"][1] - w["x"][0]) * (w["y"][1] - w["y"][0])
    reached = sum(v is not None for rw in w["condition"] for v in rw)
    return [row("workspace area (m^2), exact / grid cells reached", None,
                f"{sing['area_m2']:.4g} / {2 * reached * cell:.4g} (the grid covers y > 0; doubled by symmetry)"),
            row("non-singular grid points (condition < threshold)", None,
                int(sum(v is not None and v < threshold for rw in w["condition"] for v in rw))),
            row("threshold on cond(A°), cond(C^T U)", "not stated", threshold),
            row(f"circle's distance to the type II locus of mode {sing['mode']} (m)", None,
                distance(sing["loci"].get("II", []))),
            row("circle's distance to the workspace boundary (m)", None,
                distance([pt for arc in sing["boundary"] for pt in arc["points"]]))]


def _series_figure(r: Results, cases: tuple[str, ...], key: str, column: int, title: str, what: str):
    return rf.five_bar_series(_cases(r, *cases), key, column, title, what,
                              symlog=1e-3 if key != "torque_Nm" else None)


def five_bar_figures(first: int, cases: tuple[str, ...], level: str, peaks: tuple[float, float] | None,
                     note: str) -> tuple[Entry, ...]:
    """Figs ``first`` on: the 5R's actuator torques, errors (and for sliding mode, sliding
    variables) over time in the runs ``cases`` (the first is the thesis's), the plant's parameters
    ``level`` off; the first figure's rows compare each run's peak errors with the printed
    ``peaks`` (x, y, mm; None: not printed)."""
    law = "computed torque (eq 190)" if cases[0].startswith("computed") else "sliding mode"
    numbers = [("torque_Nm", 0, "actuator 1 torque (N m)"), ("torque_Nm", 1, "actuator 2 torque (N m)"),
               ("e_mm", 0, "error x (mm)"), ("e_mm", 1, "error y (mm)")]
    if law == "sliding mode":
        numbers += [("s", 0, "s_x (m/s)"), ("s", 1, "s_y (m/s)")]
    return tuple(
        Entry(THESIS, f"Fig {first + k}", f"{what.split(' (')[0].capitalize()}, {law}, parameters {level} off."
              + (" (Printed caption says 'x' for fig 19.)" if first + k == 19 else ""), FB,
              partial(_series_figure, cases=cases, key=key, column=column, title=f"Thesis fig {first + k}: {what}",
                      what=what),
              (lambda r: [x for c in cases for x in _case_rows(r, c, peaks)]) if k == 0 else None,
              note if k == 0 else "")
        for k, (key, column, what) in enumerate(numbers))


ENTRIES: tuple[Entry, ...] = (
    Entry(THESIS, "Fig 6", "The 5R five-bar mechanism: two RR chains joined at a point end-effector.", "",
          lambda r: rf.five_bar_linkage(five_bar_points(), f"Thesis fig 6: the 5R at {START} m", ("chain 1", "chain 2")),
          lambda r: [row("tips of both chains (m)", START,
                         "; ".join(", ".join(f"{v:.6f}" for v in c[-1]) for c in five_bar_points()))],
          "Base joints at x = +-l0 = +-0.05 m (l0 is not printed; the author's code uses 0.05 m)."),
    Entry(THESIS, "Fig 7", "One RR serial chain (links l1, l2, joints q1, q2).", "",
          lambda r: rf.five_bar_linkage(five_bar_points()[:1], "Thesis fig 7: chain 1 (RR)", ("chain 1",)),
          lambda r: [row("link lengths l1, l2 (m)", printed.LINKS, _lengths())]),
    Entry(THESIS, "Table 2", "Denavit-Hartenberg parameters of the RR chain: a = l_i, alpha = 0, d = 0, theta = q_i.",
          "", None, lambda r: [row("a1, a2 (m)", f"l1, l2 = {printed.LINKS}", _lengths()),
                               row("alpha, d", "0, 0", "0, 0 (a planar chain)")]),
    Entry(THESIS, "Fig 8", "Workspace of the 5R: out of reach, near-singular and non-singular regions and the reference "
          "circle.", FB,
          lambda r: rf.workspace(r.report(FB)["workspace"], r.report(FB)["settings"]["max_condition"], CIRCLE,
                                 "Thesis fig 8: 5R workspace", r.report(FB)["singularities"]),
          _workspace_rows,
          "Exact boundary in closed form and the singularity loci of the circle's working mode bisected from a grid "
          "(freefloat.parallel.maps), over the conditioning grid of the gain design. The thesis draws its near-singular "
          "region without a threshold; freefloat's is 6. With --quick the grids are 3 cm, else 1 cm (loci from 2 cm)."),
    Entry(THESIS, "Eq 187", "Worst-case sliding-mode gains over the non-singular grid and the 64 extreme parameter sets "
          "(eta = 20).", FB, None,
          lambda r: [row(f"{key} {axis}", r.report(FB)["eq_187"][key][i], r.report(FB)["gains"][key][i])
                     for key in ("n", "xdot2", "xdot_ydot", "ydot2") for i, axis in enumerate("xy")],
          "The gains depend on the grid and its singularity threshold, which the thesis does not state."),
    Entry(THESIS, "Fig 9", "The saturation tanh(100 s) that replaces sign(s).", "",
          lambda r: rf.saturation("Thesis fig 9: tanh(100 s)"),
          lambda r: [row("f_sat(0.023)", printed.SATURATION_AT_0_023, saturation(0.023)),
                     row("f_sat'(0)", printed.SATURATION_GAIN, saturation_slope_at_zero())]),
    *five_bar_figures(10, ("sliding mode, 15 %", "sliding mode, eq 187's gains, 15 %"), "15 %", None,
                      f"Circle of eq 189 from {START} at rest, lambda = 40, tanh(100 s): freefloat's gains over its "
                      "grid, and eq 187's printed gains, with which s_y is reached in the document's ~0.008 s."),
    *five_bar_figures(16, ("sliding mode, 50 %",), "50 %", None,
                      "As figs 10-15 with the plant 50 % off; the errors stay in the hundredths of a millimetre, as the "
                      "document says."),
    *five_bar_figures(22, ("computed torque, 15 %", "computed torque, 50 %"), "15 %", printed.COMPUTED_TORQUE_PEAKS_MM,
                      "Computed torque (eq 190, lambda = 40, critically damped). The document's peaks (12 / 27 mm) "
                      "match freefloat's run with the parameters 50 % off, not the 15 % the text states."),
    # errata
    Entry(THESIS, "Eq 142", "Tracking error printed as e = qddot_d - q.", FB, None,
          lambda r: [row("s(0) = -(edot + lambda e) at the start (m/s)", f"{printed.S_0} (sec 5.6 text)",
                         ", ".join(f"{v:.3g}" for v in r.report(FB)["cases"]["sliding mode, 15 %"]["s"][0])),
                     row("s_x(0) with the printed e", printed.S_0, f"{s_x_with_printed_error():.4g}")],
          "With e = q_d - q the start gives the s(0) = [0, -2] the text states; with the printed e it would not.",
          erratum=True),
    Entry(THESIS, "Eq 22", "DH matrix entry (1,3) printed sin(theta) cos(alpha).", "", None,
          lambda r: [row("entry (1,3) at theta = alpha = 30 deg", *dh_entry_1_3(np.pi / 6))],
          "The standard matrix has sin(theta) sin(alpha); for the 5R (alpha = 0) both vanish, so its results do not "
          "depend on it.", erratum=True),
)
