"""A slice of the fuzz corpus (tests/fuzzing.py; the whole corpus: scripts/fuzz.py): mutated
URDFs, scenes and closure files end in success, a run stopped early or a clean refusal, never a
traceback, a hang, a non-finite result or a file outside the run folder."""

from __future__ import annotations

import warnings

import pytest

from .fuzzing import GOOD, run_case, scene_case, urdf_case

SLICE = 150


@pytest.mark.parametrize("make", [urdf_case, scene_case], ids=["urdf", "scene"])
def test_a_slice_of_the_corpus_is_handled(tmp_path, make):
    """Every case of the slice ends in one of the good outcomes, and both refusals and
    completions occur (the mutations are neither all fatal nor all harmless)."""
    seen, bad = set(), []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for seed in range(10_000, 10_000 + SLICE):
            case = make(seed)
            outcome, detail = run_case(case, tmp_path / str(seed))
            seen.add(outcome)
            if outcome not in GOOD:
                bad.append(f"seed {seed} ({case.mutation}): {outcome}: {detail}")
    assert not bad, "\n".join(bad)
    assert {"refused", "completed"} <= seen


def test_the_harness_reports_a_traceback(tmp_path, monkeypatch):
    """A case whose run raises is reported as a traceback (the harness can fail)."""
    from freefloat.app import cli

    def broken(*args, **kwargs):
        raise ZeroDivisionError("planted")

    monkeypatch.setattr(cli, "_simulate", broken)
    outcome, detail = run_case(urdf_case(0), tmp_path)
    assert outcome == "traceback" and "planted" in detail
