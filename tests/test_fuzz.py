"""A slice of each class of the fuzz corpus (tests/fuzz_corpus.py; the whole corpus:
scripts/fuzz.py): mutated URDFs, scenes and closure files end in success, a run stopped early or
a clean refusal, never a traceback, a hang, a non-finite result or a file outside the run folder;
output folders keep a user's files and links' targets, pages name no URL, a signal at a
checkpoint leaves a whole folder that a rerun takes, and the Python API refuses what it cannot
take with one of freefloat's errors."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from .fuzz_corpus import CLASSES, GOOD
from .fuzzing import urdf_case

#: Seeds of each class's slice (cheap: a few cases for the classes that start processes), and the
#: outcomes the slice must show (its mutations are neither all fatal nor all harmless).
SLICES = {"urdf": (range(10_000, 10_150), {"refused", "completed"}),
          "scene": (range(10_000, 10_150), {"refused", "completed"}),
          "folders": (range(10_000, 10_012), {"refused", "completed"}),
          "links": (range(10_000, 10_012), {"refused"}),  # a link where freefloat writes is never taken (issue 41)
          "textures": (range(10_000, 10_006), {"completed"}),
          "signals": (range(10_000, 10_002), {"stopped"}),
          "api": (range(10_000, 10_060), {"refused", "completed"})}


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(SLICES))
def test_a_slice_of_the_corpus_is_handled(tmp_path, kind):
    """Every case of the class's slice ends in one of the good outcomes, and the slice shows the
    outcomes it should."""
    seeds, expected = SLICES[kind]
    seen, bad = set(), []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for seed in seeds:
            case = CLASSES[kind](seed)
            outcome, detail = case.run(tmp_path / str(seed))
            seen.add(outcome)
            if outcome not in GOOD:
                bad.append(f"seed {seed} ({case.mutation}): {outcome}: {detail}")
    assert not bad, "\n".join(bad)
    assert expected <= seen, seen


def test_the_harness_reports_a_traceback(tmp_path, monkeypatch):
    """A case whose run raises is reported as a traceback (the harness can fail)."""
    from freefloat.app import cli

    def broken(*args, **kwargs):
        raise ZeroDivisionError("planted")

    monkeypatch.setattr(cli, "_simulate", broken)
    outcome, detail = urdf_case(0).run(tmp_path)
    assert outcome == "traceback" and "planted" in detail


def test_the_folder_classes_report_a_user_file_touched(tmp_path, monkeypatch):
    """A run that deletes what it finds in its folder is reported as touching the user's files
    (the folder classes can fail)."""
    from freefloat.app.run_folder import RunFolder

    close = RunFolder.close

    def wiping(self):
        for path in self.path.rglob("*"):
            if path.is_file() and not path.name.startswith("."):
                path.unlink()
        close(self)

    monkeypatch.setattr(RunFolder, "close", wiping)
    seed = next(s for s in range(100) if CLASSES["folders"](s).overwrite and CLASSES["folders"](s).previous)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outcome, detail = CLASSES["folders"](seed).run(tmp_path)
    assert outcome in ("touched", "corrupted"), (outcome, detail)


def test_the_texture_class_reports_a_url_in_the_page(tmp_path, monkeypatch):
    """A page that keeps the Collada text as written is reported as naming the URL's host (the
    texture class can fail)."""
    from freefloat.app.viz.assets import AssetTable

    monkeypatch.setattr(AssetTable, "collada",
                        lambda self, dae: (self.placeholder_text(dae, dae.read_text()), {}))
    seed = next(s for s in range(100) if not CLASSES["textures"](s).mesh_url)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outcome, _ = CLASSES["textures"](seed).run(tmp_path)
    assert outcome == "network"


@pytest.mark.parametrize("call, outcome", [(lambda: 1 / 0, "traceback"), (lambda: np.array([np.nan]), "non-finite"),
                                           (lambda: np.zeros(2), "accepted")])
def test_the_api_class_reports_what_escapes(tmp_path, monkeypatch, call, outcome):
    """A call that raises another error, returns NaN or takes a plainly wrong argument is
    reported as such (the API class can fail)."""
    from . import fuzzing_api

    monkeypatch.setattr(fuzzing_api, "MAKERS", [lambda rng: ("planted", True, call)])
    assert CLASSES["api"](0).run(tmp_path)[0] == outcome


def test_the_oracle_reports_a_broken_balance_that_a_run_called_completed(tmp_path, monkeypatch):
    """With the runner's conservation check made to let everything pass and a spurious torque in the recorded
    momentum, the harness itself reports ``violated``, naming the quantity (the fuzzer's oracle
    is the runner's function, not a copy)."""
    from freefloat.app import runner

    from .conftest import leak_momentum
    from .fuzzing import Case, run_case

    leak_momentum(monkeypatch)
    monkeypatch.setattr(runner, "check", lambda summary: None)  # the runner lets it pass
    outcome, detail = run_case(Case("scene", 0, {}, "tumbling", "planted leak"), tmp_path)
    assert outcome == "violated" and "momentum_drift_max" in detail


def test_a_mesh_url_on_a_link_named_base_still_writes_the_page(tmp_path):
    """Texture seed 1 (a mesh URL on the link 'base', which shares its name with another frame):
    the link is drawn as a stick and the page is written (the page writer looked the link up by
    name alone, and Pinocchio refused the ambiguous name)."""
    case = CLASSES["textures"](1)
    assert case.mesh_url
    assert case.run(tmp_path)[0] == "completed"


def test_a_flipped_telemetry_file_is_refused_as_damaged(tmp_path):
    """API seed 132 (Telemetry.load of a file with a flipped byte that zipfile reads as an unknown
    zip version): a TelemetryFileError, not zipfile's NotImplementedError."""
    outcome, detail = CLASSES["api"](132).run(tmp_path)
    assert outcome == "refused", detail
