"""The atlas engine: a kind evaluated over its grid in chunks, journaled, into one folder.

:func:`run_atlas` resolves the kind and its target, checks that the grid's results fit in memory
(one point is evaluated first to learn its size), then evaluates the chunks not yet finished in
this process, on ``--workers N`` processes (this one and a pool of N - 1,
:func:`freefloat.distributed.process_pool`: each pool worker is handed chunks from the front
once it has started, a few at a time, while this process takes them from the back, so the pool's
start-up, a new interpreter per worker, costs no waiting) or on Dask (a local cluster or a scheduler's workers), as ``freefloat batch`` does. Each
chunk is saved under ``chunks/`` and a line appended to ``atlas-journal.jsonl`` as it finishes,
so Ctrl-C, SIGTERM or a kill keeps the finished chunks and the same command again resumes from
them (a folder holding another atlas's journal is refused). Once all are in, :mod:`.writer`
writes the data, the summary and the figures, and the chunks and the journal are removed.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import time
import zipfile
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, Future, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...distributed import client, process_pool, settle_futures, terminate
from ...errors import FreefloatError, RunFolderError, spelled
from ..batch import Workers
from ..run_folder import RunFolder, journal_entries
from .grid import Grid, check_memory
from .kinds import KINDS, AtlasKind, Options
from .writer import write_outputs

JOURNAL = "atlas-journal.jsonl"
CHUNKS = "chunks"
#: Chunks per worker the grid is cut into (progress and resumption at that grain) ...
CHUNKS_PER_WORKER = 8
#: ... each of at least this many points (the kind's per-call overhead amortised) and at most
#: this many (memory in flight, and what an interrupt loses).
MIN_CHUNK, MAX_CHUNK = 256, 20_000
#: Chunks handed at a time to each pool worker that has started.
IN_FLIGHT = 2
#: With Dask, the map ends when no chunk finishes within this many seconds.
DASK_TIMEOUT = 600.0
#: Names of a chunk file's own arrays besides the kind's: the map's settings digest and the chunk's span.
_RUN, _SPAN = "_atlas_run", "_atlas_span"


@dataclass(frozen=True)
class AtlasRun:
    """A finished atlas.

    Attributes:
        folder: the output folder.
        grid: the grid evaluated.
        result: every array of the kind, rows in flat grid order.
        summary: what ``summary.json`` holds.
        written: the files written.
    """

    folder: Path
    grid: Grid
    result: dict[str, np.ndarray]
    summary: dict
    written: list[Path]


def _restart() -> str:
    """How the caller starts a map again over a journal it cannot resume from."""
    return f"pass {spelled('overwrite=True', '--overwrite')} to start the map again"


def evaluate_chunk(kind: AtlasKind, context: Any, grid: Grid, start: int, stop: int) -> dict[str, np.ndarray]:
    """The kind's arrays at grid points ``start`` to ``stop`` (a worker's task; the kind travels
    as its registry object, so a worker needs no registry of its own)."""
    return kind.load().evaluate(context, grid.points(start, stop))


def chunk_size(grid: Grid, workers: int, minimum: int | None = None) -> int:
    """Points per chunk: about :data:`CHUNKS_PER_WORKER` chunks per worker, within
    [``minimum``, :data:`MAX_CHUNK`] (``minimum``: a kind's own ``MIN_CHUNK``, for points that
    take long each; default :data:`MIN_CHUNK`)."""
    minimum = MIN_CHUNK if minimum is None else minimum
    return int(min(MAX_CHUNK, max(minimum, math.ceil(grid.size / (CHUNKS_PER_WORKER * workers)))))


def run_atlas(kind: str, target: str, options: Options, out: Path, workers: Workers = Workers(),
              overwrite: bool = False, progress: Callable[[int, int], None] | None = None) -> AtlasRun:
    """Map ``kind`` of ``target`` into the folder ``out``.

    Args:
        kind: a name of :data:`~.kinds.KINDS`.
        target: what the kind maps (a robot's name or URDF file, a mechanism's name, ...).
        options: the command's options (only those the kind reads may be set).
        out: the output folder (created; a folder of this same atlas resumes from its journal).
        workers: this process, a process pool or Dask.
        overwrite: replace what freefloat wrote in ``out`` before.
        progress: called with (points done, points in all) as the map starts (the points a
            resumed map has already) and as chunks finish.

    Raises:
        UnknownName: for an unknown kind, listing the kinds.
        InvalidArgument: for an option the kind does not take, or a grid too large for memory.
        FreefloatError: the kind's own refusals of the target (naming it), and an output folder
            that is not free or holds another atlas.
    """
    started = time.perf_counter()
    entry = KINDS.get(kind)
    module = entry.check_options(options)
    context = module.prepare(target, options)
    grid = module.grid(context, options)
    check_memory(grid, 1)  # a byte a point at least, before the probe indexes a grid of 2^63 points or more
    probe = module.evaluate(context, grid.points(0, 1))
    check_memory(grid, sum(a.nbytes for a in probe.values()))
    settings = {"kind": kind, "target": target, "options": options.as_dict(), "grid": grid.describe()}
    with RunFolder(out, overwrite, keep_foreign=False, resume=True) as folder:
        size, done = _resumed(folder, settings, chunk_size(grid, workers.count, getattr(module, "MIN_CHUNK", None)),
                               grid.size)
        settings["chunk_size"] = size
        spans = grid.chunks(size)
        run_id = _run_id(settings)
        parts = {i: _load_chunk(folder.path, i, spans[i], run_id, probe) for i in done}
        chunks_dir = folder.subfolder(CHUNKS)
        with folder.journal(JOURNAL) as journal:
            if not done:
                journal.append(json.dumps({"settings": settings}))

            def finished(i: int, arrays: dict[str, np.ndarray]) -> None:
                with folder.atomic(f"{CHUNKS}/chunk-{i:05d}.npz") as partial, open(partial, "wb") as file:
                    np.savez(file, **arrays, **{_RUN: np.array(run_id), _SPAN: np.array(spans[i])})
                journal.append(json.dumps({"chunk": i, "start": spans[i][0], "stop": spans[i][1]}))
                parts[i] = arrays
                if progress is not None:
                    progress(sum(spans[j][1] - spans[j][0] for j in parts), grid.size)

            mapping = time.perf_counter()
            if progress is not None:
                progress(sum(spans[j][1] - spans[j][0] for j in parts), grid.size)
            todo = [i for i in range(len(spans)) if i not in parts]
            try:
                _execute(workers, entry, context, grid, spans, todo, finished)
            except KeyboardInterrupt:
                raise KeyboardInterrupt(f"; {len(parts)} of {len(spans)} chunks are journaled in {folder.path} "
                                        "(rerun the same command to resume)") from None
            mapped = {"points_mapped": sum(spans[i][1] - spans[i][0] for i in todo),
                      "map_wall_time_s": time.perf_counter() - mapping}
        result = {key: np.concatenate([parts[i][key] for i in range(len(spans))]) for key in probe}
        summary = {**settings, "points": grid.size, **mapped, "workers": workers.label,
                   "summary": module.summarise(context, grid, result)}
        written = write_outputs(folder, grid, result, summary, started,
                                lambda into: module.figures(context, grid, result, into))
        for i in range(len(spans)):
            (folder.path / CHUNKS / f"chunk-{i:05d}.npz").unlink(missing_ok=True)
        with contextlib.suppress(OSError):  # a file freefloat did not write stays, and so does the folder
            chunks_dir.rmdir()
        (folder.path / JOURNAL).unlink()
    return AtlasRun(folder.path, grid, result, json.loads((folder.path / "summary.json").read_text()), written)


def _resumed(folder: RunFolder, settings: dict, size: int, points: int) -> tuple[int, list[int]]:
    """The chunk size and the chunks a previous run of the same atlas journaled in ``folder``
    (``size`` and none when it has no journal; its own chunk size when it has, whatever the
    number of workers now). Every line is checked before any is used: the journal is data from
    a file anyone could have edited.

    Raises:
        RunFolderError: naming the journal and its line when a line does not parse, the journal
            is of another atlas (kind, target, options or grid), its chunk size is not an integer
            in [1, :data:`MAX_CHUNK`], or a chunk line names a chunk or span this grid does not
            have (``points`` points in chunks of the journal's size).
    """
    path = folder.path / JOURNAL
    if not path.is_file():
        return size, []
    lines = journal_entries(path, _restart())
    before = dict(lines[0][1].get("settings", {})) if lines else {}
    size = before.pop("chunk_size", size)
    if before != json.loads(json.dumps(settings)):
        raise RunFolderError(f"output folder '{folder.path}' holds the journal of another atlas "
                             f"({before or 'unreadable'}); pass {spelled('overwrite=True', '--overwrite')} or choose another "
                             f"{spelled('out=', '--out')}")
    if isinstance(size, bool) or not isinstance(size, int) or not 1 <= size <= MAX_CHUNK:
        raise RunFolderError(f"'{path}' gives a chunk size of {size!r}; an atlas journal's is an integer in "
                             f"[1, {MAX_CHUNK}]: not resuming from it ({_restart()})")
    count, owned = -(-points // size), set(folder.owned())
    done = set()
    for number, line in lines[1:]:
        i = line.get("chunk")
        if isinstance(i, bool) or not isinstance(i, int) or not 0 <= i < count \
                or [line.get("start"), line.get("stop")] != [i * size, min((i + 1) * size, points)]:
            raise RunFolderError(f"'{path}' line {number} names chunk {i!r} of points {line.get('start')!r} to "
                                 f"{line.get('stop')!r}, which this map of {points} points in chunks of {size} does "
                                 f"not have; not resuming from it ({_restart()})")
        if f"{CHUNKS}/chunk-{i:05d}.npz" in owned and (folder.path / CHUNKS / f"chunk-{i:05d}.npz").is_file():
            done.add(i)
    return size, sorted(done)


def _run_id(settings: dict) -> str:
    """A digest of the atlas's settings (chunk size included), saved in each chunk file."""
    return hashlib.sha256(json.dumps(settings, sort_keys=True).encode()).hexdigest()[:16]


def _load_chunk(folder: Path, i: int, span: tuple[int, int], run_id: str,
                probe: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The arrays of chunk ``i``, once its file is checked to be this map's chunk of points
    ``span`` (its run digest and span, and arrays of ``probe``'s names, shapes and kinds).

    Raises:
        RunFolderError: naming the file when it does not parse or is not that chunk.
    """
    path = folder / CHUNKS / f"chunk-{i:05d}.npz"
    again = f"not resuming from it ({_restart()})"
    try:
        with np.load(path) as data:
            arrays = {key: data[key] for key in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise RunFolderError(f"'{path}' is not a readable chunk file ({exc}); {again}") from None
    run, held = arrays.pop(_RUN, None), arrays.pop(_SPAN, None)
    if run is None or str(run) != run_id or held is None or held.tolist() != list(span):
        raise RunFolderError(f"'{path}' is not this map's chunk {i} of points {span[0]} to {span[1]} "
                             f"(it holds {'points ' + str(held.tolist()) if held is not None else 'no span'} "
                             f"of {'this' if run is not None and str(run) == run_id else 'another'} map); {again}")
    rows = span[1] - span[0]
    for key, like in probe.items():
        got = arrays.get(key)
        if got is None or got.shape != (rows, *like.shape[1:]) or got.dtype.kind != like.dtype.kind:
            raise RunFolderError(f"'{path}': array '{key}' is "
                                 f"{'missing' if got is None else f'{got.shape} of {got.dtype}'} where chunk {i} has "
                                 f"{(rows, *like.shape[1:])} of {like.dtype}; {again}")
    return {key: arrays[key] for key in probe}


def _execute(workers: Workers, kind: AtlasKind, context: Any, grid: Grid, spans: list[tuple[int, int]], todo: list[int],
             finished: Callable[[int, dict], None]) -> None:
    """Evaluate the chunks ``todo`` (indices into ``spans``) on ``workers``, calling
    ``finished(i, arrays)`` in this process as each finishes.

    Raises:
        FreefloatError: naming the chunk when a worker fails or is lost.
    """
    if workers.dask:
        with client(workers.scheduler, workers.count) as dask_client:
            futures = {i: dask_client.submit(evaluate_chunk, kind, context, grid, *spans[i], pure=False) for i in todo}
            settled = settle_futures(futures, "atlas", True, DASK_TIMEOUT, lambda i, r: _take(i, r, finished))
            missing = [i for i in todo if i not in settled]
            if missing:
                # base class: a cluster that did not answer
                raise FreefloatError(f"no Dask worker finished chunk {missing[0]} within {DASK_TIMEOUT:g} s")
    elif workers.count > 1 and len(todo) > 1:
        pool = process_pool(workers.count - 1)  # this process is the last worker
        try:
            started = [pool.submit(_start, kind) for _ in range(workers.count - 1)]
            queue, pending = list(todo), {}
            while queue or pending:
                room = IN_FLIGHT * sum(_started(future) for future in started) - len(pending)
                for _ in range(min(room, len(queue))):  # the front to the workers that have started
                    i = queue.pop(0)
                    pending[pool.submit(evaluate_chunk, kind, context, grid, *spans[i])] = i
                if queue:  # the back here, meanwhile
                    i = queue.pop()
                    finished(i, evaluate_chunk(kind, context, grid, *spans[i]))
                _drain(pending, finished, 0.0 if queue else None)
            if not all(future.done() for future in started):
                terminate(pool)  # a worker still starting has no chunk left: do not wait for its imports
        except BaseException:
            terminate(pool)
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
    else:
        for i in todo:
            finished(i, evaluate_chunk(kind, context, grid, *spans[i]))


def _start(kind: AtlasKind) -> None:
    """A pool worker's first task: import the kind's module (it has started once this returns)."""
    kind.load()


def _started(future: Future) -> bool:
    """Whether the pool worker whose start-up task is ``future`` has started.

    Raises:
        FreefloatError: when it could not start (its interpreter died), with the reason.
    """
    if not future.done():
        return False
    if future.exception() is not None:
        # base class: a worker that could not start, whatever its cause
        raise FreefloatError(f"an atlas worker process could not start: {future.exception()}")
    return True


def _drain(pending: dict[Future, int], finished: Callable[[int, dict], None], timeout: float | None) -> None:
    """Hand on the chunks of ``pending`` ({future: chunk}) that finish within ``timeout`` s (None:
    at least one), removing them."""
    if not pending:
        return
    ready, _ = wait(pending, timeout=timeout, return_when=FIRST_COMPLETED)
    for future in ready:
        i = pending.pop(future)
        exc = future.exception()
        _take(i, future.result() if exc is None else exc, finished)


def _take(i: int, result: object, finished: Callable[[int, dict], None]) -> None:
    """Hand a worker's chunk on, or raise what it raised (a kind's own error as it was)."""
    if isinstance(result, FreefloatError):
        raise result
    if isinstance(result, BaseException):
        # base class: the worker's error, of any kind, carried over
        raise FreefloatError(f"atlas chunk {i} failed in its worker: {type(result).__name__}: {result}") from result
    finished(i, result)
