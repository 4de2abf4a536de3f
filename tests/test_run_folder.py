"""The run folder: locked, checked before the run, cleared only when asked, written atomically."""

from __future__ import annotations

import errno
import os
import zipfile

import numpy as np
import pytest

from freefloat import FreefloatError
from freefloat.app.run_folder import LOCK, PARTS, RECORD, RunFolder
from freefloat.dynamics.telemetry import MechanismTelemetry


def tiny(rows: int, start: float = 0.0) -> MechanismTelemetry:
    t = start + np.arange(rows, dtype=float)
    return MechanismTelemetry(t=t, platform=np.zeros((rows, 2)), platform_reference=np.zeros((rows, 2)),
                              joints=np.zeros((rows, 3)), efforts=np.zeros((rows, 2)), drift=np.zeros(rows),
                              orientation_drift=np.zeros(rows), sliding=np.zeros((rows, 2)))


def test_a_second_run_into_a_held_folder_is_refused(tmp_path):
    """While one run holds a folder, another is refused at once, naming the folder."""
    with RunFolder(tmp_path / "out"):
        with pytest.raises(FreefloatError, match="in use by another freefloat run"):
            RunFolder(tmp_path / "out")
    RunFolder(tmp_path / "out").close()  # free again once released


def previous_run(folder, *names: str) -> None:
    """A run that wrote ``names`` (and a checkpoint) into ``folder``."""
    with RunFolder(folder) as out:
        for name in names:
            out.write_text(name, "old")
        out.checkpoint(tiny(2))


def test_a_folder_that_is_not_empty_needs_overwrite(tmp_path):
    """A folder with a previous run is refused without overwrite, naming the argument as the caller
    spells it (``overwrite=True`` from Python, ``--overwrite`` on the command line); with it, the
    previous run is cleared."""
    from freefloat.errors import command_line

    previous_run(tmp_path / "out", "summary.json", "old_figure.png")
    with pytest.raises(FreefloatError, match="holds a previous run; choose another out=, or pass overwrite=True") as python:
        RunFolder(tmp_path / "out")
    assert "--" not in str(python.value)
    with pytest.raises(FreefloatError, match="holds a previous run; choose another --out, or pass --overwrite"), \
            command_line():
        RunFolder(tmp_path / "out")
    with RunFolder(tmp_path / "out", overwrite=True):
        assert not (tmp_path / "out" / "old_figure.png").exists()
        assert not (tmp_path / "out" / PARTS).exists()


@pytest.mark.parametrize("overwrite", [False, True])
def test_a_folder_that_holds_no_run_is_refused_with_a_hint_that_works(tmp_path, overwrite):
    """A folder of someone's files (no ownership record) is refused with or without overwrite,
    naming the files, and the hint is another folder, never overwriting (which would not clear
    it either); the files are left."""
    (tmp_path / "thesis").mkdir()
    (tmp_path / "thesis" / "chapter1.tex").write_text("precious")
    with pytest.raises(FreefloatError, match=r"holds files freefloat did not write \(chapter1.tex\); choose another "
                                             r"out= \(a new or empty folder\)") as refused:
        RunFolder(tmp_path / "thesis", overwrite=overwrite)
    assert "overwrite" not in str(refused.value)
    assert (tmp_path / "thesis" / "chapter1.tex").read_text() == "precious"


def test_the_overwrite_hint_names_the_files_it_would_keep(tmp_path):
    """A previous run beside the user's file: overwriting is suggested (it works), saying that the
    user's file stays; with it, it does."""
    previous_run(tmp_path / "out", "summary.json")
    (tmp_path / "out" / "notes.txt").write_text("mine")
    with pytest.raises(FreefloatError, match=r"overwrite=True to replace that run \(your files there stay: notes.txt\)"):
        RunFolder(tmp_path / "out")
    with pytest.warns(UserWarning, match="kept 1 file"), RunFolder(tmp_path / "out", overwrite=True):
        pass
    assert (tmp_path / "out" / "notes.txt").read_text() == "mine"


def test_a_summary_json_alone_does_not_make_a_folder_freefloat_s(tmp_path):
    """A summary.json that looks like freefloat's, beside the user's files, clears nothing."""
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "summary.json").write_text('{"status": "completed", "versions": {}}')
    (tmp_path / "out" / "notes.md").write_text("mine")
    with pytest.raises(FreefloatError, match="did not write"):
        RunFolder(tmp_path / "out", overwrite=True)
    assert {p.name for p in (tmp_path / "out").iterdir()} == {"summary.json", "notes.md"}


def test_overwrite_removes_only_what_freefloat_wrote(tmp_path):
    """The user's document, data folder and a note put into telemetry-parts/ survive --overwrite."""
    out = tmp_path / "out"
    previous_run(out, "summary.json", "telemetry.npz")
    (out / "thesis.tex").write_text("precious")
    (out / "data").mkdir()
    (out / "data" / "measured.csv").write_text("1,2")
    (out / PARTS / "note.txt").write_text("keep me")
    with pytest.warns(UserWarning, match="kept 3 file"), RunFolder(out, overwrite=True):
        pass
    assert (out / "thesis.tex").read_text() == "precious"
    assert (out / "data" / "measured.csv").read_text() == "1,2"
    assert sorted(p.name for p in (out / PARTS).iterdir()) == ["note.txt"]
    assert not (out / "summary.json").exists() and not (out / "telemetry.npz").exists()


def test_a_run_never_replaces_a_file_it_did_not_write(tmp_path):
    """A user's file with the name of a run's output is refused, named, and kept."""
    previous_run(tmp_path / "out", "telemetry.npz")
    (tmp_path / "out" / "summary.json").write_text("the user's own")
    with pytest.warns(UserWarning, match="kept 1"), RunFolder(tmp_path / "out", overwrite=True) as folder:
        with pytest.raises(FreefloatError, match="summary.json' exists and freefloat did not write it"):
            folder.write_text("summary.json", "{}")
    assert (tmp_path / "out" / "summary.json").read_text() == "the user's own"


def test_a_record_naming_paths_outside_the_folder_is_refused(tmp_path):
    """An ownership record edited to name ../ paths clears nothing."""
    previous_run(tmp_path / "out", "summary.json")
    (tmp_path / "victim.txt").write_text("precious")
    with open(tmp_path / "out" / RECORD, "a") as record:
        record.write("../victim.txt\n")
    with pytest.raises(FreefloatError, match="not a path inside the folder"):
        RunFolder(tmp_path / "out", overwrite=True)
    assert (tmp_path / "victim.txt").read_text() == "precious"


def test_a_lock_that_is_a_link_is_not_followed(tmp_path):
    """A .freefloat.lock linking to another file is refused, naming it; the file is untouched."""
    (tmp_path / "out").mkdir()
    (tmp_path / "victim.txt").write_text("precious")
    (tmp_path / "out" / LOCK).symlink_to(tmp_path / "victim.txt")
    with pytest.raises(FreefloatError, match="freefloat.lock' is a symbolic link"):
        RunFolder(tmp_path / "out")
    assert (tmp_path / "victim.txt").read_text() == "precious"


def test_a_temporary_file_that_is_a_link_is_not_followed(tmp_path):
    """A link planted under a temporary name of the run is replaced, never written through."""
    (tmp_path / "victim.txt").write_text("precious")
    with RunFolder(tmp_path / "out") as folder:
        folder.write_text("summary.json", "{}")
        folder.save("telemetry.npz", tiny(2))
        for name in (".summary.json.partial", ".telemetry.npz.partial"):
            (tmp_path / "out" / name).symlink_to(tmp_path / "victim.txt")
        folder.write_text("summary.json", '{"new": 1}')
        folder.save("telemetry.npz", tiny(3))
    assert (tmp_path / "victim.txt").read_text() == "precious"
    assert (tmp_path / "out" / "summary.json").read_text() == '{"new": 1}'


def test_a_link_under_a_temporary_name_before_the_run_is_refused(tmp_path):
    """A link left under a temporary name the run has not claimed is refused, naming it."""
    (tmp_path / "victim.txt").write_text("precious")
    with RunFolder(tmp_path / "out") as folder:
        (tmp_path / "out" / ".summary.json.partial").symlink_to(tmp_path / "victim.txt")
        with pytest.raises(FreefloatError, match="summary.json.partial' exists"):
            folder.write_text("summary.json", "{}")
    assert (tmp_path / "victim.txt").read_text() == "precious"


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


def test_checkpoints_are_stored_uncompressed(tmp_path):
    """A checkpoint part is written without compression (a finished run removes it; deflating
    cost the default job about a tenth of its wall time)."""
    with RunFolder(tmp_path / "out") as folder:
        folder.checkpoint(tiny(3))
    [part] = (tmp_path / "out" / PARTS).glob("part-*.npz")
    with zipfile.ZipFile(part) as archive:
        assert {info.compress_type for info in archive.infolist()} == {zipfile.ZIP_STORED}


def test_a_chunk_handed_again_replaces_its_own_part(tmp_path):
    """A chunk checkpointed twice (its hand-over was interrupted) is saved once: no row twice."""
    chunk = tiny(3)
    with RunFolder(tmp_path / "out") as folder:
        folder.checkpoint(chunk)
        folder.checkpoint(chunk)
        folder.checkpoint(tiny(2, start=3.0))
    back = MechanismTelemetry.load_parts(tmp_path / "out" / PARTS)
    assert np.array_equal(back.t, np.arange(5.0))


def test_a_resumed_folder_drops_what_a_killed_run_was_making(tmp_path):
    """A folder taken again to resume removes the private subfolder a killed run left half-made
    there, and keeps the files that run finished."""
    with RunFolder(tmp_path) as folder:
        folder.write_text("report.json", "{}")
        making = folder.private_dir()
        (making / "figure.png").write_bytes(b"\x89PNG half")  # never placed: the run was killed here
    with RunFolder(tmp_path, resume=True):
        assert not making.exists()
    assert (tmp_path / "report.json").read_text() == "{}"


def test_a_name_freefloat_removed_is_no_longer_its_own(tmp_path):
    """Once a run ends, its record lists only what is still there, so --overwrite keeps a user's
    file made later under a name the run had used and removed itself (its checkpoints, a
    temporary name): it deleted them."""
    out = tmp_path / "out"
    with RunFolder(out) as folder:
        folder.checkpoint(tiny(3))
        folder.save("telemetry.npz", tiny(3))
        folder.drop_checkpoints()
    assert (out / RECORD).read_text().splitlines()[1:] == ["telemetry.npz"]
    (out / PARTS).mkdir()
    (out / PARTS / "part-00000.npz").write_text("mine")
    (out / ".telemetry.npz.partial").symlink_to(tmp_path / "elsewhere")
    with RunFolder(out, overwrite=True):
        pass
    assert (out / PARTS / "part-00000.npz").read_text() == "mine" and (out / ".telemetry.npz.partial").is_symlink()
    assert not (out / "telemetry.npz").exists()


def test_a_recorded_subfolder_replaced_by_a_link_is_neither_cleared_nor_written_through(tmp_path):
    """A link where the record names a subfolder of freefloat's refuses --overwrite and resuming,
    naming it, and a claim through a link that appears mid-run is refused; the user's files the
    link points to stay as they were."""
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "part-00000.npz").write_text("precious")
    previous_run(tmp_path / "out", "summary.json")
    (tmp_path / "out" / PARTS).rename(tmp_path / "moved")
    (tmp_path / "out" / PARTS).symlink_to(mine)
    for options in ({"overwrite": True}, {"resume": True}):
        with pytest.raises(FreefloatError, match=f"{PARTS}' is a symbolic link"):
            RunFolder(tmp_path / "out", **options)
    (tmp_path / "out" / PARTS).unlink()
    with RunFolder(tmp_path / "new") as folder:
        (tmp_path / "new" / "sub").symlink_to(mine)
        with pytest.raises(FreefloatError, match="sub' is a symbolic link"):
            folder.write_text("sub/part-00000.npz", "mine")
    assert [p.name for p in mine.iterdir()] == ["part-00000.npz"] and (mine / "part-00000.npz").read_text() == "precious"


def test_a_folder_a_refused_run_made_and_left_empty_is_removed(tmp_path):
    """A run that made its folder and wrote nothing (refused after opening it) leaves no folder;
    a folder that existed before stays, and so does one the run wrote into."""
    RunFolder(tmp_path / "new").close()
    assert not (tmp_path / "new").exists()
    (tmp_path / "mine").mkdir()
    RunFolder(tmp_path / "mine").close()
    assert (tmp_path / "mine").is_dir() and list((tmp_path / "mine").iterdir()) == []
    with RunFolder(tmp_path / "written") as folder:
        folder.write_text("summary.json", "{}")
    assert (tmp_path / "written" / "summary.json").read_text() == "{}"


def test_journal_entries_drop_a_cut_last_line_and_refuse_a_bad_one(tmp_path):
    """journal_entries reads what Journal appended, drops a last line a kill cut short, and
    refuses a whole line that is not a JSON object, naming the file and the line."""
    from freefloat.app.run_folder import journal_entries

    path = tmp_path / "j.jsonl"
    path.write_text('{"a": 1}\n\n{"b": 2}\n{"c"')
    assert journal_entries(path, "start again") == [(1, {"a": 1}), (3, {"b": 2})]
    path.write_text('{"a": 1}\n[2]\n')
    with pytest.raises(FreefloatError, match=r"j.jsonl' line 2 is not a JSON object; not resuming from it \(start again\)"):
        journal_entries(path, "start again")
