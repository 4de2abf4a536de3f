"""The notebooks, one per experiment, run top to bottom in their short mode (their cells assert
conservation laws and the documents' numbers, and end by printing ``checks passed``)."""

from __future__ import annotations

import nbformat
import pytest
from nbclient import NotebookClient

from .conftest import REPO

NOTEBOOKS = sorted((REPO / "notebooks").glob("*.ipynb"))


def test_there_is_a_notebook_per_experiment():
    """The quick start and the seven experiments each have a notebook."""
    assert {p.stem for p in NOTEBOOKS} >= {"quickstart", "gjm_verification", "model_truth_table", "task_space",
                                           "capture_detumbling", "five_bar_sliding_mode", "rsu_ppap", "work_precision"}


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_executes_and_its_checks_pass(path, tmp_path, monkeypatch):
    """Every cell runs without error in the short mode (FREEFLOAT_NOTEBOOK_QUICK=1), so every
    assert inside the notebook holds, and the last cell reports the checks passed."""
    monkeypatch.setenv("FREEFLOAT_NOTEBOOK_QUICK", "1")
    notebook = nbformat.read(path, as_version=4)
    NotebookClient(notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    assert "checks passed" in "".join(o.get("text", "") for o in outputs)
