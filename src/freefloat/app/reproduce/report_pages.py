"""The report of ``freefloat reproduce all`` as files: ``report.html`` (one self-contained page,
figures embedded as base64 PNG, no network), ``report.pdf`` (matplotlib's PdfPages: a text page
per entry with its figure below) and ``entries.json`` (every entry's compared numbers).

The report is built from whatever studies the folder holds (:class:`~.report_results.Results`);
an entry whose study is missing says so and which command finishes it.
"""

from __future__ import annotations

import base64
import html
import io
import json
import textwrap
import time
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ...errors import FreefloatError
from ..outputs import strict_json
from .report_entries import ENTRIES, Entry, Row
from .report_results import Results

A4 = (8.27, 11.69)
PNG_DPI = 90


@dataclass
class Built:
    """One entry as built: its rows, its figure as PNG bytes (or None), and why a part is
    missing (``"not reproduced: ..."``, or "")."""

    entry: Entry
    rows: list[Row]
    png: bytes | None
    missing: str


def build_entry(entry: Entry, results: Results) -> Built:
    """Compute ``entry``'s rows and draw its figure from ``results``; a missing study or file
    (a :class:`FreefloatError`) is kept as the entry's reason."""
    try:
        rows = entry.rows(results) if entry.rows else []
        png = None
        if entry.draw is not None:
            fig = entry.draw(results)
            buffer = io.BytesIO()
            fig.savefig(buffer, format="png", dpi=PNG_DPI)
            png = buffer.getvalue()
        return Built(entry, rows, png, "")
    except FreefloatError as exc:
        return Built(entry, [], None, f"not reproduced: {exc}")
    except KeyError as exc:  # a study's output without the key: made by an older freefloat
        return Built(entry, [], None, f"not reproduced: the output of study '{entry.study}' has no {exc}; it was made by "
                                      "an older freefloat: rerun with --overwrite")


def build(results: Results, out: Path, provenance: dict, progress=lambda done, total: None) -> list[Built]:
    """Write ``report.html``, ``report.pdf`` and ``entries.json`` into ``out``; the built entries."""
    built = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the studies' runs said theirs (e.g. the printed inertias)
        for k, entry in enumerate(ENTRIES):
            built.append(build_entry(entry, results))
            progress(k + 1, len(ENTRIES))
    (out / "report.html").write_text(page(built, results, provenance))
    write_pdf(built, out / "report.pdf", provenance)
    records = [{"document": b.entry.document, "number": b.entry.number, "caption": b.entry.caption,
                "study": b.entry.study, "erratum": b.entry.erratum, "figure": b.png is not None,
                "rows": [asdict(r) for r in b.rows], "note": b.entry.note, "missing": b.missing} for b in built]
    (out / "entries.json").write_text(strict_json({"provenance": provenance, "entries": records}))
    return built


def heading(entry: Entry) -> str:
    return f"{entry.document} {'erratum, ' if entry.erratum else ''}{entry.number}"


def _anchor(entry: Entry) -> str:
    return f"{entry.document}-{entry.number}".lower().replace(" ", "-").replace(",", "")


def page(built: list[Built], results: Results, provenance: dict) -> str:
    """The HTML page: provenance, contents, entries, then each study's own report."""
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>freefloat: the documents reproduced</title>",
             "<style>body{font-family:sans-serif;max-width:1100px;margin:auto;padding:1em;line-height:1.4}"
             "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #bbb;padding:2px 6px;font-size:90%}"
             "img{max-width:100%}.missing{color:#b00}.erratum{background:#fff4e0}pre{background:#f4f4f4;padding:.5em;"
             "overflow-x:auto;font-size:80%}section{border-top:1px solid #ddd;margin-top:1em}</style></head><body>",
             "<h1>The dissertation's chapters 4 and 5 and the thesis's sec 5.6, reproduced against the exact reference</h1>",
             "<p>Every table and figure of the dissertation's chapters 4-5 and of the thesis's sec 5.6, in the documents' "
             "order: what the document shows (in our words), freefloat's figure on the exact plant (and on the "
             "document's own model where that differs), the printed values beside freefloat's, the difference and its "
             "reason; and each erratum with the number that shows it.</p>", "<h2>Made by</h2><table>"]
    parts += [f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>" for k, v in _flat(provenance)]
    parts.append("</table><h2>Contents</h2><ul>")
    parts += [f"<li><a href='#{_anchor(b.entry)}'>{html.escape(heading(b.entry))}</a>: {html.escape(b.entry.caption)}"
              f"{' <span class=missing>(not reproduced)</span>' if b.missing else ''}</li>" for b in built]
    parts.append("</ul>")
    for b in built:
        parts.append(f"<section id='{_anchor(b.entry)}'{' class=erratum' if b.entry.erratum else ''}>"
                     f"<h3>{html.escape(heading(b.entry))}</h3><p>{html.escape(b.entry.caption)}"
                     f"{f' <i>(study: {html.escape(b.entry.study)})</i>' if b.entry.study else ''}</p>")
        if b.missing:
            parts.append(f"<p class=missing>{html.escape(b.missing)}</p>")
        if b.png is not None:
            parts.append(f"<img alt='{html.escape(heading(b.entry))}' src='data:image/png;base64,{base64.b64encode(b.png).decode()}'>")
        if b.rows:
            parts.append("<table><tr><th>quantity</th><th>printed</th><th>freefloat</th><th>difference</th></tr>")
            parts += [f"<tr><td>{html.escape(r.quantity)}</td><td>{html.escape(r.printed)}</td><td>{html.escape(r.ours)}</td>"
                      f"<td>{html.escape(r.difference)}</td></tr>" for r in b.rows]
            parts.append("</table>")
        if b.entry.note:
            parts.append(f"<p>{html.escape(b.entry.note)}</p>")
        parts.append("</section>")
    parts.append("<h2>The studies' own reports</h2>")
    for study in provenance.get("studies", {}):
        report = results.root / study / "report.md"
        if report.is_file():
            parts.append(f"<section><h3>{html.escape(study)}</h3><pre>{html.escape(report.read_text())}</pre>")
            for png in sorted((results.root / study).glob("*.png")):
                parts.append(f"<img alt='{html.escape(png.name)}' src='data:image/png;base64,{base64.b64encode(png.read_bytes()).decode()}'>")
            parts.append("</section>")
    parts.append("</body></html>")
    return "\n".join(parts)


def _flat(record: dict, prefix: str = "") -> list[tuple[str, object]]:
    out = []
    for key, value in record.items():
        if isinstance(value, dict):
            out += _flat(value, f"{prefix}{key}.")
        else:
            out.append((f"{prefix}{key}", value))
    return out


def _text_lines(b: Built) -> list[str]:
    lines = textwrap.wrap(b.entry.caption + (f" (study: {b.entry.study})" if b.entry.study else ""), 95)
    if b.missing:
        lines += textwrap.wrap(b.missing, 95)
    for r in b.rows:
        lines += textwrap.wrap(f"- {r.quantity}: printed {r.printed}; freefloat {r.ours}; difference {r.difference}", 95,
                               subsequent_indent="    ")
    if b.entry.note:
        lines += textwrap.wrap(b.entry.note, 95)
    return lines


def write_pdf(built: list[Built], path: Path, provenance: dict) -> None:
    """One A4 page per entry (heading, text, the figure below), after a title page."""
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.image import imread

    with PdfPages(path) as pdf:
        title = Figure(figsize=A4)
        FigureCanvasAgg(title)
        lines = ["freefloat: the documents reproduced", "", "Dissertation chapters 4-5 and thesis sec 5.6", ""]
        lines += [f"{k}: {v}" for k, v in _flat(provenance)]
        title.text(0.06, 0.95, "\n".join(textwrap.fill(line, 100) for line in lines), va="top", family="monospace", fontsize=7)
        pdf.savefig(title)
        for b in built:
            fig = Figure(figsize=A4)
            FigureCanvasAgg(fig)
            fig.text(0.06, 0.96, heading(b.entry), va="top", fontsize=13, weight="bold")
            text = _text_lines(b)
            fig.text(0.06, 0.93, "\n".join(text[:40]), va="top", fontsize=7.5, family="monospace")
            if b.png is not None:
                top = max(0.1, 0.9 - 0.0125 * min(len(text), 40))
                ax = fig.add_axes((0.05, 0.03, 0.9, top - 0.05))
                ax.imshow(imread(io.BytesIO(b.png)))
                ax.set_anchor("N")  # right under the text
                ax.set_axis_off()
            pdf.savefig(fig)


def provenance(root: Path, settings: dict, studies: dict[str, dict], commit: str, versions: dict) -> dict:
    """What made the report: commit, versions, settings, each study's wall time and settings."""
    return {"commit": commit, "made": time.strftime("%Y-%m-%d %H:%M:%S %Z"), "folder": str(root),
            "settings": settings, "versions": versions,
            "studies": {name: json.dumps(s) for name, s in studies.items()}}
