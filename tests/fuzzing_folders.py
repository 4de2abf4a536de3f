"""Fuzz classes of output folders (issues 24, 41): folders that hold a user's files, and folders
where symbolic links stand under the names freefloat writes. ``simulate``, ``batch``,
``reproduce`` or ``atlas`` runs into the folder, with or without ``--overwrite``, sometimes after
a run of its own there (an atlas's stopped after its first chunk, so the rerun resumes);
afterwards every user file must be byte-identical (``touched`` otherwise), no link's target may
have changed or appeared (``followed``), and what freefloat wrote must be whole (``corrupted``).
"""

from __future__ import annotations

import hashlib
import os
import random
import shutil
from dataclasses import dataclass, field
from pathlib import Path

from .conftest import scene_variant
from .folder_checks import folder_problems
from .fuzzing import Failure, cli, verdict

#: What a user might keep in a folder, by name (relative, ``/``-separated): documents, data,
#: files with the names freefloat writes, a note in its checkpoint folder, a hidden file.
USER_FILES = ["notes.txt", "data/x.csv", "summary.json", "telemetry.npz", "telemetry-parts/note.txt",
              "telemetry-parts/part-00000.npz", "report.md", "report.json", "runs.csv", "scene.toml",
              "figures/plot.png", ".hidden", "torques.png", "parts.jsonl", "bench.json", "chunks/note.txt",
              "chunks/chunk-00000.npz", "atlas.npz", "atlas-journal.jsonl"]
#: Names freefloat creates or may create in a folder: where a planted link may stand.
LINK_NAMES = [".freefloat.lock", ".freefloat-files", "summary.json", "telemetry.npz", ".telemetry.npz.partial",
              ".summary.json.partial", "telemetry-parts", "scene.toml", ".scene.toml.partial", "runs-partial.jsonl",
              "runs.json", "report.json", "report.md", "parts.jsonl", ".freefloat-write-check", "chunks",
              "atlas-journal.jsonl", "atlas.npz"]
#: Folders freefloat makes, planted as links to a folder elsewhere holding a user's files.
LINKED_FOLDERS = {"telemetry-parts": "keep.txt", "chunks": "chunk-00000.npz"}
COMMANDS = ["simulate", "simulate", "batch", "reproduce", "atlas"]
#: The atlas the ``atlas`` command maps: 1296 points in 6 chunks (a previous run is stopped after the first).
ATLAS = ["workspace", "two_arm_planar", "--grid", "6"]


def command(kind: str, scene: Path, out: Path, overwrite: bool) -> list[str]:
    """The argument list of a cheap ``kind`` command into ``out``."""
    flags = ["--overwrite"] if overwrite else []
    if kind == "simulate":
        return ["simulate", str(scene), "--quiet", "--out", str(out), *flags]
    if kind == "atlas":
        return ["atlas", *ATLAS, "--quiet", "--out", str(out), *flags]
    if kind == "batch":
        return ["batch", str(scene), "--runs", "3", "--vary", "base_rate=5", "--quiet", "--out", str(out), *flags]
    return ["reproduce", "phases", "--quick", "--workers", "1", "--out", str(out), *flags]


def _short_scene(folder: Path) -> Path:
    """The tumbling scene over 50 ms, without figures or page."""
    return scene_variant(folder / "scene-in.toml", "tumbling", simulation={"duration": 0.05},
                         output={"figures": False, "html": False})


def _digest(path: Path) -> str:
    """A file's SHA-256, or what stands there instead."""
    if path.is_symlink():
        return f"link -> {path.readlink()}"
    if not path.exists():
        return "missing"
    return hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else "folder"


@dataclass
class FolderCase:
    """An output folder holding a user's files (or links), and the command run into it."""

    kind: str
    seed: int
    command: str
    previous: bool  # a run of the same command into the folder first
    overwrite: bool
    plants: list[str] = field(default_factory=list)

    @property
    def mutation(self) -> str:
        return (f"{self.command}{' --overwrite' if self.overwrite else ''}{' after a run' if self.previous else ''}: "
                + ", ".join(self.plants))

    def run(self, folder: Path) -> tuple[str, str]:
        """Plant, run, check: the outcome and its detail."""
        rng = random.Random(self.seed)
        folder.mkdir(parents=True, exist_ok=True)
        out, outside = folder / "out", folder / "outside"
        args = command(self.command, _short_scene(folder), out, self.overwrite)
        try:
            if self.previous and self.command == "atlas":
                _interrupted_atlas(out)
            elif self.previous:
                cli(command(self.command, folder / "scene-in.toml", out, False))
            watched = self._plant(rng, out, outside)
            before = {path: _digest(path) for path in watched}
            status, err = cli(args)
        except Failure as failure:
            return failure.outcome, failure.detail
        changed = [str(p.relative_to(folder)) for p, digest in before.items() if _digest(p) != digest]
        if changed:
            return ("touched" if self.kind == "folders" else "followed"), f"changed: {', '.join(changed)}"
        problems = folder_problems(out, ignore={name.split("/")[0] for name in self.plants}) if status < 2 else []
        if problems:  # in what the command wrote (a refused one wrote nothing)
            return "corrupted", "; ".join(problems)[:300]
        return verdict(status, err)

    def _plant(self, rng: random.Random, out: Path, outside: Path) -> list[Path]:
        """Put the case's files (or links) in place; the paths whose contents must not change."""
        watched = []
        for name in self.plants:
            path = out / name
            replacing = os.path.lexists(path)
            if replacing:
                if self.kind == "folders" or path.is_dir() and name not in LINKED_FOLDERS:
                    continue  # a name the previous run wrote: a user's edit of its file is not this class
                if path.is_dir() and not path.is_symlink():
                    shutil.rmtree(path)  # freefloat's folder (an atlas's chunks) replaced by a link
                else:
                    path.unlink()  # freefloat's file replaced by a link: --overwrite may remove the link
            path.parent.mkdir(parents=True, exist_ok=True)
            if self.kind == "folders":
                path.write_bytes(rng.randbytes(rng.randrange(0, 200)))
                watched.append(path)
                continue
            target = outside / name.replace("/", "_").lstrip(".")
            target.parent.mkdir(parents=True, exist_ok=True)
            if name in LINKED_FOLDERS:  # a folder elsewhere, with a user's file in it
                target.mkdir(exist_ok=True)
                (target / LINKED_FOLDERS[name]).write_bytes(rng.randbytes(50))
                watched.append(target / LINKED_FOLDERS[name])
            elif rng.random() < 0.8:
                target.write_bytes(rng.randbytes(rng.randrange(1, 200)))
            watched += [target] if replacing else [path, target]  # a dangling link's target stays missing
            path.symlink_to(target)
        return watched


def _interrupted_atlas(out: Path) -> None:
    """:data:`ATLAS` into ``out`` stopped by Ctrl-C once its first chunk is journaled (its chunks
    folder and journal stay, for the next run to resume)."""
    import warnings

    from freefloat.app.atlas.engine import run_atlas
    from freefloat.app.atlas.kinds import Options

    def stop(done: int, total: int) -> None:
        if done:
            raise KeyboardInterrupt

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            run_atlas(ATLAS[0], ATLAS[1], Options(grid=int(ATLAS[3])), out, progress=stop)
        except KeyboardInterrupt:
            pass


def _case(kind: str, seed: int, pool: list[str]) -> FolderCase:
    rng = random.Random(seed)
    return FolderCase(kind, seed, rng.choice(COMMANDS), rng.random() < 0.4, rng.random() < 0.6,
                      sorted(rng.sample(pool, rng.randint(1, 4))))


def folders_case(seed: int) -> FolderCase:
    """An output folder holding 1-4 of a user's files (:data:`USER_FILES`)."""
    return _case("folders", seed, USER_FILES)


def links_case(seed: int) -> FolderCase:
    """An output folder where 1-4 of freefloat's names (:data:`LINK_NAMES`) are symbolic links to
    files (or a folder, or nothing) outside it."""
    return _case("links", seed, LINK_NAMES)

