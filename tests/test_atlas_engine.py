"""The atlas engine (freefloat.app.atlas.engine, grid, kinds, writer) on a toy kind whose values
are known in closed form."""

from __future__ import annotations

import json
import os
import re

import numpy as np
import pytest

from freefloat.app.atlas import engine
from freefloat.app.atlas.engine import run_atlas
from freefloat.app.atlas.grid import Axis, Grid, check_memory
from freefloat.app.atlas.kinds import KINDS, AtlasKind, Options
from freefloat.app.batch import Workers
from freefloat.app.cli import main
from freefloat.errors import FreefloatError, InvalidArgument, UnknownName


@pytest.fixture(autouse=True)
def toy_kind(monkeypatch):
    """The toy kind registered for the test, and chunks of 8 points (several per toy grid)."""
    monkeypatch.setitem(KINDS, "toy", AtlasKind("toy", "a toy", "anything", "tests.atlas_toy_kind"))
    monkeypatch.setattr(engine, "MIN_CHUNK", 8)
    monkeypatch.setattr(engine, "CHUNKS_PER_WORKER", 100)


def expected(n: int = 7) -> np.ndarray:
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n + 1), indexing="ij")
    return (x**2 + 10 * y).ravel()


def test_grid_points_are_the_tensor_product_in_c_order():
    """Grid.points lists the tensor product with the last axis fastest, and chunks cover it once."""
    grid = Grid((Axis("a", 0, 1, 3), Axis("b", -1, 1, 2)))
    assert np.array_equal(grid.points(), [[0, -1], [0, 1], [0.5, -1], [0.5, 1], [1, -1], [1, 1]])
    assert np.array_equal(np.vstack([grid.points(a, b) for a, b in grid.chunks(4)]), grid.points())


def test_serial_map_equals_the_closed_form_and_writes_the_folder(tmp_path):
    """The map's data equal f on the grid; the folder holds the data, summary, CSV and figure, and no journal."""
    done = run_atlas("toy", "t", Options(), tmp_path / "out")
    assert np.allclose(done.result["f"], expected()) and done.result["gradient"].shape == (56, 2)
    with np.load(tmp_path / "out" / "atlas.npz") as data:
        assert np.allclose(data["f"], expected()) and np.allclose(data["axis_y"], np.linspace(0, 1, 8))
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["summary"]["max_f"] == pytest.approx(11.0) and summary["figures"] == ["toy.txt"]
    assert "max_f,11.0" in (tmp_path / "out" / "summary.csv").read_text()
    assert not (tmp_path / "out" / engine.JOURNAL).exists() and not (tmp_path / "out" / engine.CHUNKS).exists()


def test_the_map_reports_its_last_point_before_the_files_and_figures(tmp_path, monkeypatch, capsys):
    """Every point is reported done before the files and figures are written, so the command's bar
    ends there (it reached 100 % again after the figures); the line after it gives the map's time,
    the one the bar showed, and the points mapped."""
    reports, writing = [], []
    written = engine.write_outputs
    monkeypatch.setattr(engine, "write_outputs", lambda *a: writing.append(len(reports)) or written(*a))
    done = run_atlas("toy", "t", Options(), tmp_path / "out", progress=lambda n, total: reports.append((n, total)))
    assert reports[0] == (0, 56) and reports[-1] == (56, 56) and writing == [len(reports)]
    assert done.summary["points_mapped"] == 56 and 0 < done.summary["map_wall_time_s"] < done.summary["wall_time_s"]
    assert main(["atlas", "toy", "t", "--out", str(tmp_path / "cli"), "--quiet"]) == 0
    assert re.search(r"toy of t: 56 points in [\d.]+ s \(serial\) -> ", capsys.readouterr().out)


@pytest.mark.slow
def test_process_pool_gives_the_serial_map(tmp_path):
    """Two processes (this one and a pool of one) give the serial numbers; this process takes
    chunks from the back while the pool starts."""
    done = run_atlas("toy", "slow", Options(grid=9), tmp_path / "out", Workers(2))
    assert np.array_equal(done.result["f"], expected(9))
    assert done.result["process"][-1] == os.getpid()


def test_an_interrupted_map_resumes_from_its_journal(tmp_path, monkeypatch):
    """Ctrl-C after the second chunk keeps both journaled; the rerun evaluates only the rest, in
    the journal's chunks even where the rerun would cut others (another number of workers)."""
    def stop(done, total):
        if done >= 16:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt, match="2 of 7 chunks are journaled"):
        run_atlas("toy", "t", Options(), tmp_path / "out", progress=stop)
    evaluated = []
    original = engine.evaluate_chunk

    def counting(kind, context, grid, start, stop):
        evaluated.append(start)
        return original(kind, context, grid, start, stop)

    engine.evaluate_chunk = counting
    monkeypatch.setattr(engine, "MIN_CHUNK", 5)
    try:
        done = run_atlas("toy", "t", Options(), tmp_path / "out")
    finally:
        engine.evaluate_chunk = original
    assert evaluated == [16, 24, 32, 40, 48] and np.allclose(done.result["f"], expected())


def test_a_folder_of_another_atlas_is_refused(tmp_path):
    """A journal of other settings in --out is not mixed with this map."""
    def stop(done, total):
        if done:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_atlas("toy", "t", Options(), tmp_path / "out", progress=stop)
    with pytest.raises(Exception, match="journal of another atlas"):
        run_atlas("toy", "t", Options(grid=5), tmp_path / "out")


def test_unknown_kind_and_foreign_option_are_refused():
    """An unknown kind lists the kinds; an option the kind does not read is named."""
    with pytest.raises(UnknownName, match="toy"):
        KINDS.get("nope")
    with pytest.raises(InvalidArgument, match="--tolerance"):
        KINDS.get("toy").check_options(Options(tolerance=0.1))


def test_a_grid_too_large_for_memory_is_refused():
    """The memory check names the points and the memory."""
    with pytest.raises(InvalidArgument, match="grid too large for memory: 1000 x 1000"):
        check_memory(Grid((Axis("a", 0, 1, 1000), Axis("b", 0, 1, 1000))), 1000, available=2**30)


def test_cli_unknown_kind_exits_2_listing_the_kinds(capsys):
    """freefloat atlas with an unknown kind: exit 2, the kinds listed, the nearest first."""
    assert main(["atlas", "nope", "ur5", "--quiet"]) == 2
    assert "workspace" in capsys.readouterr().err
    assert main(["atlas", "workspce", "ur5", "--quiet"]) == 2
    assert "unknown atlas kind 'workspce'; did you mean 'workspace'?" in capsys.readouterr().err


def test_register_adds_a_kind():
    """KINDS.register puts the kind object under its name, after the built-in kinds."""
    kind = AtlasKind("other", "h", "t", "tests.atlas_toy_kind")
    KINDS.register(kind)
    try:
        assert KINDS.get("other") is kind and KINDS.names()[-1] == "other"
    finally:
        del KINDS["other"]


@pytest.mark.slow
def test_dask_local_cluster_gives_the_serial_map(tmp_path):
    """A local Dask cluster of 2 workers gives the serial numbers."""
    pytest.importorskip("distributed")
    done = run_atlas("toy", "t", Options(grid=9), tmp_path / "out", Workers(2, dask=True))
    assert np.array_equal(done.result["f"], expected(9))


def interrupted(out, chunks: int = 2) -> None:
    """A toy map into ``out`` stopped by Ctrl-C once ``chunks`` chunks of 8 points are journaled."""
    def stop(done, total):
        if done >= 8 * chunks:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_atlas("toy", "t", Options(), out, progress=stop)


@pytest.mark.parametrize("overwrite", [False, True])
def test_a_chunk_folder_replaced_by_a_link_is_neither_followed_nor_cleared(tmp_path, overwrite):
    """A resumed (or overwritten) map whose chunks/ is now a link to a user's folder is refused,
    naming the link; nothing in the user's folder is written or removed."""
    interrupted(tmp_path / "out")
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "chunk-00000.npz").write_text("precious")
    (tmp_path / "out" / engine.CHUNKS).rename(tmp_path / "moved")
    (tmp_path / "out" / engine.CHUNKS).symlink_to(mine)
    with pytest.raises(FreefloatError, match=r"chunks' is a symbolic link"):
        run_atlas("toy", "t", Options(), tmp_path / "out", overwrite=overwrite)
    assert sorted(p.name for p in mine.iterdir()) == ["chunk-00000.npz"]
    assert (mine / "chunk-00000.npz").read_text() == "precious"


def swap(out) -> None:
    """Chunk files 0 and 1 exchanged."""
    a, b = (out / engine.CHUNKS / f"chunk-0000{i}.npz" for i in (0, 1))
    a.rename(out / "t.npz"), b.rename(a), (out / "t.npz").rename(b)


def edit_journal(out, change) -> None:
    """The journal's lines (parsed) changed by ``change`` and written back."""
    path = out / engine.JOURNAL
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    path.write_text("".join(json.dumps(line) + "\n" for line in change(lines)))


@pytest.mark.parametrize("tamper, message", [
    (lambda out: (out / engine.JOURNAL).write_text("{not json\n"), "line 1 is not a JSON object"),
    (lambda out: edit_journal(out, lambda ls: ls + [{"chunk": 99, "start": 792, "stop": 800}]), "names chunk 99"),
    (lambda out: edit_journal(out, lambda ls: [{"settings": {**ls[0]["settings"], "chunk_size": "8"}}] + ls[1:]),
     "chunk size of '8'"),
    (lambda out: edit_journal(out, lambda ls: [{"settings": {**ls[0]["settings"], "chunk_size": -5}}] + ls[1:]),
     "chunk size of -5"),
    (lambda out: (out / engine.CHUNKS / "chunk-00001.npz").write_bytes(
        (out / engine.CHUNKS / "chunk-00001.npz").read_bytes()[:100]), "not a readable chunk file"),
    (lambda out: (out / engine.CHUNKS / "chunk-00001.npz").write_text("a user's notes"), "not a readable chunk file"),
    (swap, "not this map's chunk 0 of points 0 to 8 \\(it holds points \\[8, 16\\]"),
])
def test_a_tampered_journal_or_chunk_is_refused_not_read(tmp_path, tamper, message):
    """A journal line that does not parse or names a chunk the map lacks, a chunk size that is
    not a positive integer, and a chunk file truncated, foreign or of another span (swapped) are
    refused, naming the file, before any chunk is evaluated or read as data."""
    interrupted(tmp_path / "out")
    tamper(tmp_path / "out")
    with pytest.raises(FreefloatError, match=message):
        run_atlas("toy", "t", Options(), tmp_path / "out")


def test_a_grid_whose_point_count_passes_2_to_the_64_is_refused_by_the_memory_check():
    """The point count is an exact integer: a grid of 2^64 points does not wrap around to 0 and pass."""
    with pytest.raises(InvalidArgument, match="grid too large for memory"):
        check_memory(Grid((Axis("a", 0, 1, 2**32), Axis("b", 0, 1, 2**32))), 8, available=2**30)


def test_a_grid_past_2_to_the_63_points_is_refused_before_it_is_indexed(tmp_path):
    """A map of 2^64 points is refused by the memory check, not by numpy's indexing."""
    with pytest.raises(InvalidArgument, match="grid too large for memory: 4294967296 x 4294967297"):
        run_atlas("toy", "t", Options(grid=2**32), tmp_path / "out")


def test_cli_workers_0_is_refused_as_batch_refuses_it(tmp_path, capsys):
    """atlas --workers 0 exits 2 naming --workers, not a serial map."""
    assert main(["atlas", "toy", "t", "--workers", "0", "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "--workers must be an integer >= 1, got 0" in capsys.readouterr().err and not (tmp_path / "out").exists()


def test_grid_below_one_point_per_axis_is_refused():
    """--grid 0 is refused naming --grid, not replaced by the kind's default."""
    with pytest.raises(InvalidArgument, match="grid.*must be an integer >= 1, got 0"):
        Options(grid=0)
