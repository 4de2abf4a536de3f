"""A suite measured in parts, run into the bench's folder: ``bench_<name>.json`` is rewritten
after each part, so Ctrl-C, SIGTERM, SIGHUP or a kill keeps every part measured; once all are,
``bench_<name>.png`` is drawn from it, and the lines of the module's optional
``summary(report) -> list[str]`` are printed (without one: each part's ratios,
:func:`ratio_lines`). A ``--quick`` run says it is a smoke test in its lines, its JSON
(``smoke_test``) and its chart (:func:`~.drawing.mark_smoke`)."""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType
from typing import NamedTuple

from ....app.outputs import strict_json, versions
from ....app.run_folder import RunFolder
from ..options import SMOKE, Options
from .drawing import mark_smoke

#: Words of a report key that make it a ratio :func:`ratio_lines` prints.
RATIO_WORDS = ("_over_", "ratio", "speedup", "speed_up")


class Ended(NamedTuple):
    """How one suite's run ended.

    Attributes:
        status: ``"completed"``, or ``"interrupted (SIGNAL) ..."`` saying what was kept.
        lines: what the command prints about it.
    """

    status: str
    lines: list[str]


def run_parts(name: str, module: ModuleType, options: Options, folder: RunFolder,
              progress: Callable[[str], None]) -> Ended:
    """Measure the suite ``name`` (its ``module``: ``settings``, ``measure``, ``chart``) into the
    held ``folder``: the report holds the suite's name, its settings, the versions, its
    ``status`` and one key per part measured."""
    data, drawing = f"bench_{name}.json", f"bench_{name}.png"
    settings = module.settings(options.quick, options.repeats)
    report = {"suite": name, **({"smoke_test": SMOKE} if options.quick else {}), "settings": settings,
              "versions": versions(), "status": "running"}
    try:
        for key, value in module.measure(settings):
            report[key] = value
            folder.write_text(data, strict_json(report))
            progress(f"{name}: {key} measured")
        report["status"] = "completed"
    except KeyboardInterrupt as stop:
        parts = [key for key in report if key not in HEAD]
        report["status"] = (f"interrupted ({str(stop) or 'SIGINT'}) after {len(parts)} parts"
                            f"{': ' if parts else ''}{', '.join(parts)}; no chart")
    folder.write_text(data, strict_json(report))
    if report["status"] != "completed":
        return Ended(report["status"], [f"{name}: {report['status']}"])
    module.chart(report, folder.claim(drawing))
    if options.quick:
        mark_smoke(folder.path / drawing)
    summary = getattr(module, "summary", None)  # optional: lines printed beside the files
    lines = summary(report) if summary else ratio_lines(name, report)
    return Ended("completed", [f"{name}: {data}, {drawing}", *([f"{name}: {SMOKE}"] if options.quick else []), *lines])


#: The keys of a report that are not parts.
HEAD = ("suite", "smoke_test", "settings", "versions", "status")


def ratio_lines(name: str, report: dict) -> list[str]:
    """One line per part of ``report``: its ratios (the numbers whose key has a word of
    :data:`RATIO_WORDS`, at the part's top level or one table down), to 4 significant digits."""
    lines = []
    for part, value in report.items():
        if part in HEAD or not isinstance(value, dict):
            continue
        found = {key: v for key, v in value.items() if _ratio(key, v)}
        for key, table in value.items():
            if isinstance(table, dict):
                found.update({f"{key}.{k}": v for k, v in table.items() if _ratio(k, v)})
        if found:
            lines.append(f"{name}: {part}: " + ", ".join(f"{key} {v:.4g}" for key, v in found.items()))
    return lines


def _ratio(key: str, value: object) -> bool:
    return isinstance(value, float) and any(word in key for word in RATIO_WORDS)
