"""The identification figure: each parameter's error and interval as the summary gives them."""

from __future__ import annotations

import numpy as np

from freefloat.app.viz.identification_figures import INERTIA_COMPONENTS, IdentifiedParameters, identification_figure


def _summary(rng: np.random.Generator) -> dict:
    """A capture_identification summary's target keys, drawn at random."""
    inertia = rng.standard_normal((3, 3))
    return {"target_mass_estimate": 50.2, "target_mass_half_width": 0.3, "target_mass_true": 50.0,
            "target_com_estimate": rng.standard_normal(3).tolist(), "target_com_half_width": [1e-3, 2e-3, 3e-3],
            "target_com_true": rng.standard_normal(3).tolist(),
            "target_inertia_estimate": (inertia + inertia.T).tolist(), "target_inertia_half_width": np.full((3, 3), 0.01).tolist(),
            "target_inertia_true": np.eye(3).tolist()}


def test_each_panel_plots_the_estimate_minus_the_truth_with_its_half_width():
    """The points are estimate - true (CoM in mm) and the bars span the 95 % half-widths, read
    back from the drawn figure against the summary's numbers."""
    summary = _summary(np.random.default_rng(0))
    fig = identification_figure(IdentifiedParameters.of(summary))
    mass, com, inertia = fig.axes
    pairs = [(i, j) for (i, j), _ in INERTIA_COMPONENTS]
    expected = (
        (mass, [summary["target_mass_estimate"] - summary["target_mass_true"]], [summary["target_mass_half_width"]]),
        (com, 1e3 * (np.array(summary["target_com_estimate"]) - summary["target_com_true"]),
         1e3 * np.array(summary["target_com_half_width"])),
        (inertia, [np.array(summary["target_inertia_estimate"])[p] - np.eye(3)[p] for p in pairs], [0.01] * 6),
    )
    for ax, error, half in expected:
        points = next(line for line in ax.lines if line.get_marker() == "o")
        np.testing.assert_allclose(points.get_ydata(), error, rtol=1e-12)
        caps = sorted((line for line in ax.lines if line.get_marker() == "_"), key=lambda c: np.mean(c.get_ydata()))
        np.testing.assert_allclose(caps[-1].get_ydata() - caps[0].get_ydata(), 2 * np.asarray(half), rtol=1e-12)
