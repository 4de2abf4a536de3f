"""The run folder: locked, checked before the run, cleared only when asked, written atomically."""

from __future__ import annotations

import errno
import os

import numpy as np
import pytest

from freefloat import FreefloatError
from freefloat.app.run_folder import PARTS, RunFolder
from freefloat.dynamics.telemetry import MechanismTelemetry


def tiny(rows: int, start: float = 0.0) -> MechanismTelemetry:
    t = start + np.arange(rows, dtype=float)
    return MechanismTelemetry(t=t, platform=np.zeros((rows, 2)), platform_reference=np.zeros((rows, 2)),
                              joints=np.zeros((rows, 3)), efforts=np.zeros((rows, 2)), drift=np.zeros(rows),
                              orientation_drift=np.zeros(rows))


def test_a_second_run_into_a_held_folder_is_refused(tmp_path):
    """While one run holds a folder, another is refused at once, naming the folder."""
    with RunFolder(tmp_path / "out"):
        with pytest.raises(FreefloatError, match="in use by another freefloat run"):
            RunFolder(tmp_path / "out")
    RunFolder(tmp_path / "out").close()  # free again once released


def test_a_folder_that_is_not_empty_needs_overwrite(tmp_path):
    """A folder with files is refused without overwrite; with it, the previous run is cleared."""
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "summary.json").write_text("{}")
    (tmp_path / "out" / "old_figure.png").write_text("x")
    with pytest.raises(FreefloatError, match="not empty.*--overwrite"):
        RunFolder(tmp_path / "out")
    with RunFolder(tmp_path / "out", overwrite=True):
        assert not (tmp_path / "out" / "old_figure.png").exists()


def test_overwrite_never_clears_a_folder_that_holds_no_run(tmp_path):
    """--overwrite refuses a folder of someone's files (no summary.json) and leaves them."""
    (tmp_path / "thesis").mkdir()
    (tmp_path / "thesis" / "chapter1.tex").write_text("precious")
    with pytest.raises(FreefloatError, match="no freefloat run"):
        RunFolder(tmp_path / "thesis", overwrite=True)
    assert (tmp_path / "thesis" / "chapter1.tex").read_text() == "precious"


def test_a_failed_write_leaves_the_previous_file_whole(tmp_path, monkeypatch):
    """A write that fails half-way (disk full) raises naming the file and keeps the old file."""
    with RunFolder(tmp_path / "out") as folder:
        folder.write_text("summary.json", '{"old": 1}')

        def full(*args, **kwargs):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        monkeypatch.setattr(os, "replace", full)
        with pytest.raises(FreefloatError, match="summary.json.*No space left"):
            folder.write_text("summary.json", '{"new": 2}')
        monkeypatch.undo()
        assert (tmp_path / "out" / "summary.json").read_text() == '{"old": 1}'
        assert [p.name for p in (tmp_path / "out").iterdir() if "partial" in p.name] == []


def test_checkpoints_load_back_as_one_telemetry(tmp_path):
    """Chunks checkpointed during a run read back, in order, as every row so far."""
    with RunFolder(tmp_path / "out") as folder:
        folder.checkpoint(tiny(3))
        folder.checkpoint(tiny(2, start=3.0))
    back = MechanismTelemetry.load_parts(tmp_path / "out" / PARTS)
    assert np.array_equal(back.t, np.arange(5.0))
