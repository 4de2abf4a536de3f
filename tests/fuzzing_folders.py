"""Fuzz classes of output folders (issue 24): folders that hold a user's files, and folders where
symbolic links stand under the names freefloat writes. ``simulate``, ``batch`` or ``reproduce``
runs into the folder, with or without ``--overwrite``, sometimes after a run of its own there;
afterwards every user file must be byte-identical (``touched`` otherwise), no link's target may
have changed or appeared (``followed``), and what freefloat wrote must be whole (``corrupted``).
"""

from __future__ import annotations

import hashlib
import os
import random
from dataclasses import dataclass, field
from pathlib import Path

from .conftest import scene_variant
from .folder_checks import folder_problems
from .fuzzing import Failure, cli, verdict

#: What a user might keep in a folder, by name (relative, ``/``-separated): documents, data,
#: files with the names freefloat writes, a note in its checkpoint folder, a hidden file.
USER_FILES = ["notes.txt", "data/x.csv", "summary.json", "telemetry.npz", "telemetry-parts/note.txt",
              "telemetry-parts/part-00000.npz", "report.md", "report.json", "runs.csv", "scene.toml",
              "figures/plot.png", ".hidden", "torques.png", "parts.jsonl", "bench.json"]
#: Names freefloat creates or may create in a folder: where a planted link may stand.
LINK_NAMES = [".freefloat.lock", ".freefloat-files", "summary.json", "telemetry.npz", ".telemetry.npz.partial",
              ".summary.json.partial", "telemetry-parts", "scene.toml", ".scene.toml.partial", "runs-partial.jsonl",
              "runs.json", "report.json", "report.md", "parts.jsonl", ".freefloat-write-check"]
COMMANDS = ["simulate", "simulate", "batch", "reproduce"]


def command(kind: str, scene: Path, out: Path, overwrite: bool) -> list[str]:
    """The argument list of a cheap ``kind`` command into ``out``."""
    flags = ["--overwrite"] if overwrite else []
    if kind == "simulate":
        return ["simulate", str(scene), "--quiet", "--out", str(out), *flags]
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
            if self.previous:
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
                if self.kind == "folders" or path.is_dir():
                    continue  # a name the previous run wrote: a user's edit of its file is not this class
                path.unlink()  # freefloat's file replaced by a link: --overwrite may remove the link
            path.parent.mkdir(parents=True, exist_ok=True)
            if self.kind == "folders":
                path.write_bytes(rng.randbytes(rng.randrange(0, 200)))
                watched.append(path)
                continue
            target = outside / name.replace("/", "_").lstrip(".")
            target.parent.mkdir(parents=True, exist_ok=True)
            if name == "telemetry-parts":  # a folder elsewhere, with a file in it
                target.mkdir(exist_ok=True)
                (target / "keep.txt").write_bytes(rng.randbytes(50))
                watched.append(target / "keep.txt")
            elif rng.random() < 0.8:
                target.write_bytes(rng.randbytes(rng.randrange(1, 200)))
            watched += [target] if replacing else [path, target]  # a dangling link's target stays missing
            path.symlink_to(target)
        return watched


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

