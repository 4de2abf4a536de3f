"""Reproductions of the documents' experiments against the exact reference, one registry of
studies: :data:`STUDIES` (``freefloat reproduce NAME`` takes its choices and help from it).

A new study is one module with ``reproduce(out, quick=False, ...) -> report`` (it writes
``report.json`` and ``report.md`` into ``out``; one that journals its parts also takes
``journal=PATH``) plus one ``STUDIES.register`` line. Modules are imported when their study
runs, so the command line starts without them.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...registry import Registry


@dataclass(frozen=True)
class Study:
    """One study of the documents.

    Attributes:
        name: the ``freefloat reproduce`` argument.
        help: one line for the command's help.
        module: its module in this package.
        function: the module's ``reproduce(out, quick=..., **options)``.
        options: the command-line options it takes besides ``--quick`` (e.g. ``workers``).
        journal: the file it appends its finished parts to, if any (``models``: each part;
            ``robustness``: each sample), so that an interrupted study keeps them and a rerun into
            the same folder resumes.
        extras: the optional parts it needs (:data:`freefloat.extras.EXTRAS`), checked before it
            starts.
    """

    name: str
    help: str
    module: str
    function: str = "reproduce"
    options: tuple[str, ...] = ()
    journal: str | None = None
    extras: tuple[str, ...] = ()

    def run(self, out: Path, quick: bool = False, journal: Path | None = None, **options: Any) -> dict:
        """Run the study into ``out``, appending to ``journal`` (default ``out /``
        :attr:`journal`) if it keeps one; ``options`` beyond :attr:`options` are ignored."""
        reproduce = getattr(importlib.import_module(f"{__name__}.{self.module}"), self.function)
        chosen = {k: v for k, v in options.items() if k in self.options}
        if self.journal is not None and journal is not None:
            chosen["journal"] = journal
        return reproduce(out, quick=quick, **chosen)


#: Every study, in the order the command lists them.
STUDIES: Registry[Study] = Registry("study")

for _study in (
    Study("models", "which dynamics model matches the exact one, where", "models_report", options=("workers",),
          journal="parts.jsonl"),
    Study("task_space", "sec 5.2 (Tables 2-5, figs 20-40)", "task_space_report"),
    Study("phases", "one model per capture phase vs exact", "phases_report"),
    Study("five_bar", "the 5R's sliding-mode gains and tracking (thesis sec 5.6)", "five_bar_report"),
    Study("closure_stability", "loop-closure drift over step, integrator and Baumgarte lambda", "five_bar_report",
          "reproduce_stability"),
    Study("chattering", "sign(s) against tanh(100 s) over the control period", "chattering_report"),
    Study("robustness", "Monte-Carlo of the 5R controller through Dask", "five_bar_report", "reproduce_robustness",
          ("runs", "relative_error", "scheduler"), "samples.jsonl", ("dask",)),
    Study("stability", "the largest stable step per integrator and scene", "stability_report"),
    Study("rsu_ppap_sliding", "the 2RSU+PPaP's gains, sliding mode vs computed torque", "rsu_ppap_sliding_report"),
    Study("series", "the runs behind the time-series figures of secs 5.1 and 5.3 (figs 8-19, 41-56)", "series_report"),
):
    STUDIES.register(_study)

#: The ``freefloat reproduce`` argument that runs every study and builds the report.
ALL_STUDIES = "all"

#: Every study's journal (``freefloat reproduce`` claims a study's in its folder before the study runs).
JOURNALS = tuple(study.journal for study in STUDIES.values() if study.journal)

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
