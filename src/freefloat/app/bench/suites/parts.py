"""A suite measured in parts, run into the bench's folder: ``bench_<name>.json`` is rewritten
after each part, so Ctrl-C, SIGTERM, SIGHUP or a kill keeps every part measured; once all are,
``bench_<name>.png`` is drawn from it, and the lines of the module's optional
``summary(report) -> list[str]`` are printed."""

from __future__ import annotations

from types import ModuleType
from typing import Callable, NamedTuple

from ...outputs import strict_json, versions
from ...run_folder import RunFolder
from ..options import Options


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
    report = {"suite": name, "settings": settings, "versions": versions(), "status": "running"}
    try:
        for key, value in module.measure(settings):
            report[key] = value
            folder.write_text(data, strict_json(report))
            progress(f"{name}: {key} measured")
        report["status"] = "completed"
    except KeyboardInterrupt as stop:
        parts = [key for key in report if key not in ("suite", "settings", "versions", "status")]
        report["status"] = (f"interrupted ({str(stop) or 'SIGINT'}) after {len(parts)} parts"
                            f"{': ' if parts else ''}{', '.join(parts)}; no chart")
    folder.write_text(data, strict_json(report))
    if report["status"] != "completed":
        return Ended(report["status"], [f"{name}: {report['status']}"])
    module.chart(report, folder.claim(drawing))
    summary = getattr(module, "summary", None)  # optional: lines printed beside the files
    return Ended("completed", [f"{name}: {data}, {drawing}", *(summary(report) if summary else [])])
