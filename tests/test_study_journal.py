"""A study's journal read back for a resume (freefloat.lab.reproduce.study_journal): lines that
are not entries, or entries the study cannot use, are refused naming the line."""

from __future__ import annotations

import json

import pytest

from freefloat.errors import RunFolderError
from freefloat.lab.reproduce.study_journal import entries

SETTINGS = {"quick": True, "runs": 2}


def journal(tmp_path, *lines: str, end: str = "\n"):
    path = tmp_path / "samples.jsonl"
    path.write_text("\n".join(lines) + end)
    return path


def test_entries_of_these_settings_are_read_and_others_skipped(tmp_path):
    """Entries of these settings come back without them, in order; another run's are skipped."""
    path = journal(tmp_path, json.dumps({"settings": SETTINGS, "sample": 1}), json.dumps({"settings": {}, "sample": 0}),
                   json.dumps({"settings": SETTINGS, "sample": 0}))
    assert entries(path, SETTINGS, lambda e: None) == [{"sample": 1}, {"sample": 0}]


def test_a_last_line_cut_by_a_kill_is_dropped(tmp_path):
    """A last line without its newline (a kill during the append) is dropped, not refused."""
    path = journal(tmp_path, json.dumps({"settings": SETTINGS, "sample": 0}), '{"settings": {"qu', end="")
    assert entries(path, SETTINGS, lambda e: None) == [{"sample": 0}]


@pytest.mark.parametrize("line", ["{not json", "[1, 2]", "42"])
def test_a_line_that_is_not_an_entry_is_refused_naming_it(tmp_path, line):
    """A whole line that is not a JSON object is refused naming the file and the line."""
    path = journal(tmp_path, json.dumps({"settings": SETTINGS, "sample": 0}), line)
    with pytest.raises(RunFolderError, match=r"samples.jsonl' line 2 is not a JSON object"):
        entries(path, SETTINGS, lambda e: None)


@pytest.mark.parametrize("sample, message", [
    ({"sample": 7, "status": "ok", "error_mm": [0.1, 0.2]}, "names sample 7, which a run of 2 samples does not have"),
    ({"sample": "0", "status": "ok", "error_mm": [0.1, 0.2]}, "names sample '0'"),
    ({"status": "ok", "error_mm": [0.1, 0.2]}, "names sample None"),
    ({"sample": 1, "status": "ok", "error_mm": "small"}, "gives sample 1 an error_mm of 'small'"),
    ({"sample": 1, "status": "great"}, "gives sample 1 the status 'great'"),
])
def test_a_robustness_sample_the_study_cannot_use_is_refused(tmp_path, sample, message):
    """A journaled robustness sample out of range, without an index, a status or its errors is
    refused naming the line, not read as a result (nor a KeyError later)."""
    from freefloat.lab.reproduce.five_bar_report import _resumable

    path = journal(tmp_path, json.dumps({"settings": SETTINGS, **sample}))
    with pytest.raises(RunFolderError, match=f"line 1 {message}"):
        _resumable(path, SETTINGS)
