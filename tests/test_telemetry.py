"""Telemetry chunks and files: rows never counted twice, whatever interrupts the bookkeeping, and
damaged or foreign files refused with the file's name."""

from __future__ import annotations

import sys
import zipfile

import numpy as np
import pytest

from freefloat.dynamics import telemetry
from freefloat.dynamics.telemetry import Chunks, MechanismTelemetry, Telemetry
from freefloat.errors import TelemetryFileError

ROWS = 4


def tiny(rows: int, start: float = 0.0) -> MechanismTelemetry:
    t = start + np.arange(rows, dtype=float)
    return MechanismTelemetry(t=t, platform=np.zeros((rows, 2)), platform_reference=np.zeros((rows, 2)),
                              joints=np.zeros((rows, 3)), efforts=np.zeros((rows, 2)), drift=np.zeros(rows),
                              orientation_drift=np.zeros(rows), sliding=np.zeros((rows, 2)))


def record(chunks: Chunks, samples: int) -> None:
    """The loop's use of chunks: sample ``k`` has time ``k``."""
    for k in range(samples):
        chunk, row = chunks.next_row()
        chunk.t[row] = k
        chunks.commit()


def interrupted_at(instruction: int, samples: int) -> tuple[np.ndarray, np.ndarray] | None:
    """Record ``samples`` rows with KeyboardInterrupt raised at the ``instruction``-th bytecode
    run inside telemetry.py; the collected times and the times handed to ``on_chunk`` (saved as
    numbered parts, the way a run folder does), or None when the recording ended first."""
    parts: dict[int, np.ndarray] = {}
    count = [0]
    last: list = [None, -1]

    def save(chunk: MechanismTelemetry) -> None:  # as RunFolder.checkpoint: the same chunk again, the same part
        index = last[1] if chunk is last[0] else last[1] + 1
        parts[index] = chunk.t.copy()
        last[:] = [chunk, index]

    chunks = Chunks(lambda n: tiny(n), ROWS, save)
    fired = [False]

    def trace(frame, event, arg):
        if frame.f_code.co_filename != telemetry.__file__:
            return None
        frame.f_trace_opcodes = True
        if event == "opcode" and not fired[0]:
            count[0] += 1
            if count[0] == instruction:
                fired[0] = True
                raise KeyboardInterrupt
        return trace

    sys.settrace(trace)
    try:
        record(chunks, samples)
    except KeyboardInterrupt:
        pass
    finally:
        sys.settrace(None)
    if not fired[0]:
        return None
    collected = chunks.collect().t
    return collected, np.concatenate([parts[i] for i in sorted(parts)] or [np.zeros(0)])


def test_an_interrupt_at_any_instruction_never_repeats_a_row():
    """Ctrl-C at any bytecode of the chunk bookkeeping leaves rows 0..n-1 once each, in memory
    and in the parts handed on."""
    instruction = 1
    while (result := interrupted_at(instruction, 3 * ROWS + 1)) is not None:
        collected, saved = result
        assert np.array_equal(collected, np.arange(len(collected))), f"instruction {instruction}: {collected}"
        assert np.array_equal(saved, np.arange(len(saved))), f"instruction {instruction}: {saved}"
        instruction += 1
    assert instruction > 50  # the bookkeeping was actually interrupted all through


def test_collect_hands_on_every_row_once():
    """Without an interrupt, the parts handed on are the rows collected."""
    parts = []
    chunks = Chunks(lambda n: tiny(n), ROWS, parts.append)
    record(chunks, 2 * ROWS + 1)
    collected = chunks.collect()
    assert np.array_equal(collected.t, np.arange(2 * ROWS + 1))
    assert np.array_equal(np.concatenate([p.t for p in parts]), collected.t)


def test_a_foreign_npz_is_refused_naming_what_it_lacks(tmp_path):
    """An .npz of other arrays is refused, naming the file and the missing arrays."""
    np.savez(tmp_path / "other.npz", x=np.zeros(3))
    with pytest.raises(TelemetryFileError, match=r"other.npz' is not Telemetry telemetry: it lacks t, q"):
        Telemetry.load(tmp_path / "other.npz")


@pytest.mark.parametrize("damage", ["truncated", "text", "single_array", "lengths"])
def test_a_damaged_file_is_refused_naming_it(tmp_path, damage):
    """A truncated, non-npz, single-array or inconsistent file raises TelemetryFileError naming it."""
    path = tmp_path / "telemetry.npz"
    tiny(5).save(path)
    if damage == "truncated":
        path.write_bytes(path.read_bytes()[:200])
    elif damage == "text":
        path.write_text("not a telemetry file")
    elif damage == "single_array":
        np.save(tmp_path / "a.npy", np.zeros(3))
        (tmp_path / "a.npy").rename(path)
    else:
        with zipfile.ZipFile(path) as z:
            arrays = {n[:-4]: np.load(z.open(n)) for n in z.namelist()}
        arrays["drift"] = np.zeros(2)
        np.savez(path, **arrays)
    with pytest.raises(TelemetryFileError, match="telemetry.npz"):
        MechanismTelemetry.load(path)


def test_load_parts_names_the_damaged_part(tmp_path):
    """A damaged checkpoint part is named when the parts are read back."""
    tiny(2).save(tmp_path / "part-00000.npz")
    (tmp_path / "part-00001.npz").write_bytes(b"PK\x03\x04 broken")
    with pytest.raises(TelemetryFileError, match="part-00001.npz"):
        MechanismTelemetry.load_parts(tmp_path)


@pytest.mark.slow
def test_an_interrupt_while_saving_leaves_nothing_to_complain_later(tmp_path, monkeypatch):
    """Ctrl-C as a telemetry file's archive is closed leaves the previous file, and no archive
    that Python closes again at garbage collection (it printed 'Exception ignored ... seek of
    closed file' after a clean Ctrl-C: found by the fuzz class of signals at checkpoints)."""
    import gc

    path = tmp_path / "telemetry.npz"
    tiny(3).save(path)
    close, calls, unraisable = zipfile.ZipFile.close, [], []

    def interrupted(self):
        calls.append(1)
        if len(calls) == 1:
            raise KeyboardInterrupt
        close(self)

    monkeypatch.setattr(zipfile.ZipFile, "close", interrupted)
    monkeypatch.setattr(sys, "unraisablehook", unraisable.append)
    with pytest.raises(KeyboardInterrupt):
        tiny(5).save(path)
    gc.collect()
    assert not unraisable, [str(u.exc_value) for u in unraisable]
    assert np.array_equal(MechanismTelemetry.load(path).t, np.arange(3.0))


def test_a_saved_file_is_numpy_s_npz(tmp_path):
    """The file save writes is what numpy's savez_compressed writes: np.load reads every array."""
    tiny(4).save(tmp_path / "t.npz", scene="x")
    with np.load(tmp_path / "t.npz") as data:
        assert np.array_equal(data["t"], np.arange(4.0)) and str(data["meta_scene"]) == "x"
        assert data.zip.getinfo("t.npy").compress_type == zipfile.ZIP_DEFLATED


def test_an_uncompressed_file_is_stored_and_reads_the_same(tmp_path):
    """``compressed=False`` (the checkpoints) stores the arrays as they are; np.load and load read
    the same numbers as from the compressed file."""
    tiny(4).save(tmp_path / "c.npz")
    tiny(4).save(tmp_path / "s.npz", compressed=False)
    with np.load(tmp_path / "s.npz") as data:
        assert data.zip.getinfo("t.npy").compress_type == zipfile.ZIP_STORED
    stored, deflated = MechanismTelemetry.load(tmp_path / "s.npz"), MechanismTelemetry.load(tmp_path / "c.npz")
    assert all(np.array_equal(getattr(stored, f), getattr(deflated, f)) for f in ("t", "platform", "joints", "efforts"))
