"""``freefloat reproduce`` into folders: one study into its folder (:func:`run_study`), or every
study into one folder each under a common one, then the report (:func:`run_all`).

A study's journal (if any) is appended to in place; every other file is made in a private
subfolder and moved in once the study is done, so a file appears only whole and already in the
folder's ownership record. A study stopped or killed leaves its journal, which a rerun of the same
command resumes from, and nothing half-made. ``all`` keeps each finished study's folder: a rerun
skips the studies whose report is there (made with the same ``--quick``), runs the others, and
rebuilds the report from what exists.
"""

from __future__ import annotations

import json
import shutil
import time
import warnings
from collections.abc import Callable
from pathlib import Path

from ...app.outputs import versions
from ...app.run_folder import LOCK, RECORD, RunFolder
from ...errors import MissingExtra, RunFolderError, spelled
from ...extras import require
from . import STUDIES

#: Files ``all`` writes into its folder besides one folder per study.
REPORT_FILES = ("report.html", "report.pdf", "entries.json")


def run_study(name: str, out: Path, overwrite: bool, quick: bool, options: dict) -> dict:
    """Run the study ``name`` (:data:`~freefloat.lab.reproduce.STUDIES`) into ``out``; its report.

    Raises:
        KeyboardInterrupt: on Ctrl-C, SIGTERM or SIGHUP, saying what was kept.
        FreefloatError: for a folder that cannot be used, or a study's own refusal.
    """
    study = STUDIES[name]
    for extra in study.extras:
        require(extra, f"freefloat reproduce {name}")
    with RunFolder(out, overwrite, keep_foreign=False, resume=True) as folder:
        journal = folder.claim(study.journal) if study.journal else None  # ours before it exists
        making = folder.private_dir()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                report = study.run(making, quick, journal=journal, **options)
            for made in sorted(making.iterdir()):
                folder.place(made)
        except KeyboardInterrupt:
            kept = f"the finished parts are journaled in {out} (rerun the same command to resume)" if journal else \
                "nothing of this study was kept"
            raise KeyboardInterrupt(f"; {kept}") from None
        finally:
            shutil.rmtree(making, ignore_errors=True)
    return report


def available(name: str) -> str:
    """"" when the study can run here, else why not (an extra it needs is not installed)."""
    try:
        for extra in STUDIES[name].extras:
            require(extra, f"freefloat reproduce {name}")
    except MissingExtra as exc:
        return str(exc)
    return ""


def foreign_files(folder: Path) -> list[str]:
    """Names in ``folder`` that its ownership record (:data:`~...app.run_folder.RECORD`) does not list."""
    record = folder / RECORD
    lines = record.read_text(errors="replace").splitlines() if record.is_file() and not record.is_symlink() else []
    owned = {line.split("/")[0] for line in lines if line.strip() and not line.startswith("#")}
    return sorted(p.name for p in folder.iterdir() if p.name not in owned | {LOCK, RECORD})


def finished(folder: Path, quick: bool) -> dict | None:
    """The report a study left in ``folder`` with the same ``quick``, or None."""
    path = folder / "report.json"
    if not path.is_file():
        return None
    try:
        report = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    return report if report.get("settings", {}).get("quick", quick) == quick else None


def run_all(out: Path, overwrite: bool, quick: bool, options: dict, say: Callable[[str], None] = print,
            names: tuple[str, ...] | None = None) -> dict:
    """Every study that can run here (or those ``names``) into ``out/<study>``, then the report
    (:data:`REPORT_FILES`) into ``out``. Studies already finished there with the same ``quick`` are kept, not rerun.
    Returns ``{"studies": {name: wall time or why skipped}, "entries": n, "not_reproduced": [...]}``.

    Raises:
        KeyboardInterrupt: on Ctrl-C, SIGTERM or SIGHUP, naming the studies kept.
    """
    from .report.pages import build, provenance
    from .report.results import Results, commit

    names = list(STUDIES if names is None else names)
    if overwrite:  # each study's folder cleared by its own record first, so the folders empty out
        held = [out / name for name in names if (out / name).is_dir()]
        if links := [folder for folder in held if folder.is_symlink()]:
            raise RunFolderError(f"'{links[0]}' is a symbolic link where freefloat keeps a study's folder; freefloat "
                                 f"neither follows nor removes links it did not create (remove it, or choose another {spelled('out=', '--out')})")
        for folder in held:  # all checked before any is cleared
            if foreign := foreign_files(folder):
                raise RunFolderError(f"output folder '{folder}' holds files freefloat did not write ({', '.join(foreign)}); "
                                     "not clearing it or any other study's folder (move them away or choose another "
                                     f"{spelled('out=', '--out')})")
        for folder in held:
            RunFolder(folder, overwrite=True, keep_foreign=False).close()
    done: dict[str, dict] = {}
    with RunFolder(out, overwrite, keep_foreign=False, resume=True) as folder:
        try:
            for k, name in enumerate(names, 1):
                into = folder.claim(f"{name}/")
                if reason := available(name):
                    done[name] = {"skipped": reason}
                    say(f"[{k}/{len(names)}] {name}: skipped, {reason}")
                    continue
                if (report := finished(into, quick)) is not None:
                    done[name] = {"wall_time_s": round(report.get("wall_time_s", 0.0), 1), "kept": True}
                    say(f"[{k}/{len(names)}] {name}: kept from an earlier run")
                    continue
                say(f"[{k}/{len(names)}] {name}: {STUDIES[name].help} ...")
                start = time.perf_counter()
                stale = (into / "report.json").is_file()  # finished with the other --quick: made again
                run_study(name, into, stale, quick, options)
                done[name] = {"wall_time_s": round(time.perf_counter() - start, 1)}
                say(f"[{k}/{len(names)}] {name}: done in {done[name]['wall_time_s']:.0f} s")
        except KeyboardInterrupt as exc:
            kept = ", ".join(n for n, d in done.items() if "skipped" not in d) or "none"
            raise KeyboardInterrupt(f"{exc}; studies finished and kept in {out}: {kept} (rerun the same command to "
                                    "resume and build the report)") from None
        making = folder.private_dir()
        try:
            settings = {"quick": quick, **options}
            record = provenance(out, settings, done, commit(), versions())
            say(f"report: {len(names)} studies -> {', '.join(REPORT_FILES)}")
            start = time.perf_counter()
            built = build(Results(out), making, record)
            for made in sorted(making.iterdir()):
                folder.place(made)
        finally:
            shutil.rmtree(making, ignore_errors=True)
    missing = [f"{b.entry.document} {b.entry.number}" for b in built if b.missing]
    say(f"report: {len(built)} entries in {time.perf_counter() - start:.0f} s; not reproduced: {', '.join(missing) or 'none'}")
    return {"studies": done, "entries": len(built), "not_reproduced": missing}
