"""The report of ``freefloat reproduce all`` as files: ``report.html`` (one self-contained page,
figures embedded as base64 PNG, no network), ``report.pdf`` (matplotlib's PdfPages: a title page
with the report's provenance as a table, then a text page per entry with its figure below) and
``entries.json`` (every entry's compared numbers).

The report is built from whatever studies the folder holds (:class:`~.report_results.Results`);
an entry whose study is missing says so and which command finishes it. A report of ``--quick``
studies says so on its title page, at the top of the HTML page, on every PDF page and on every
figure (:data:`QUICK`): its numbers come from shortened runs.
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
from matplotlib.lines import Line2D

from ...errors import FreefloatError
from ..outputs import strict_json
from .report_entries import ENTRIES, Entry, Row
from .report_results import Results

A4 = (8.27, 11.69)
PNG_DPI = 90
#: The mark of a report made with ``--quick``, on every figure and page.
QUICK = "QUICK RUN (--quick): shortened studies, smoke numbers, not the documents' reproduction"
#: Colour of the mark.
QUICK_COLOR = "#c00000"


@dataclass
class Built:
    """One entry as built: its rows, its figure as PNG bytes (or None), and why a part is
    missing (``"not reproduced: ..."``, or "")."""

    entry: Entry
    rows: list[Row]
    png: bytes | None
    missing: str


def build_entry(entry: Entry, results: Results, quick: bool = False) -> Built:
    """Compute ``entry``'s rows and draw its figure from ``results`` (marked :data:`QUICK` when
    ``quick``); a missing study or file (a :class:`FreefloatError`) is kept as the entry's reason."""
    try:
        rows = entry.rows(results) if entry.rows else []
        png = None
        if entry.draw is not None:
            fig = entry.draw(results)
            if quick:
                mark_quick(fig, top=False)
            buffer = io.BytesIO()
            fig.savefig(buffer, format="png", dpi=PNG_DPI)
            png = buffer.getvalue()
        return Built(entry, rows, png, "")
    except FreefloatError as exc:
        return Built(entry, [], None, f"not reproduced: {exc}")
    except KeyError as exc:  # a study's output without the key: made by an older freefloat
        return Built(entry, [], None, f"not reproduced: the output of study '{entry.study}' has no {exc}; it was made by "
                                      "an older freefloat: rerun with --overwrite")


def mark_quick(fig: Figure, top: bool = True) -> None:
    """Stamp :data:`QUICK` in the top right corner of ``fig`` (a page), or in its bottom right
    corner (a figure, whose title is on top)."""
    fig.text(0.995, 0.995 if top else 0.005, QUICK, ha="right", va="top" if top else "bottom", fontsize=8,
             weight="bold", color=QUICK_COLOR, bbox={"facecolor": "white", "edgecolor": QUICK_COLOR, "alpha": 0.85,
                                                     "pad": 2.0})


def is_quick(provenance: dict) -> bool:
    """Whether the report's studies ran with ``--quick``."""
    return bool(provenance.get("settings", {}).get("quick"))


def build(results: Results, out: Path, provenance: dict, progress=lambda done, total: None) -> list[Built]:
    """Write ``report.html``, ``report.pdf`` and ``entries.json`` into ``out``; the built entries."""
    built = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the studies' runs said theirs (e.g. the printed inertias)
        for k, entry in enumerate(ENTRIES):
            built.append(build_entry(entry, results, is_quick(provenance)))
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
             "reason; and each erratum with the number that shows it.</p>"]
    if is_quick(provenance):
        parts.append(f"<p style='color:{QUICK_COLOR};font-weight:bold;border:2px solid {QUICK_COLOR};padding:.4em'>"
                     f"{html.escape(QUICK)}</p>")
    parts.append("<h2>Made by</h2><table>")
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
    """A title page (:func:`title_page`), then one A4 page per entry (:func:`entry_page`)."""
    from matplotlib.backends.backend_pdf import PdfPages

    quick = is_quick(provenance)
    with PdfPages(path) as pdf:
        pdf.savefig(title_page(provenance))
        for b in built:
            pdf.savefig(entry_page(b, quick))


def provenance_rows(provenance: dict) -> list[tuple[str, str, str]]:
    """The report's provenance as (section, name, value) rows: what made it (commit, date,
    folder), the settings, the package versions and each study (its wall time, kept from an
    earlier run, or why it was skipped)."""
    rows = [("Made", "commit", str(provenance.get("commit", "-"))), ("Made", "date", str(provenance.get("made", "-"))),
            ("Made", "folder", str(provenance.get("folder", "-")))]
    rows += [("Settings", key, str(value)) for key, value in provenance.get("settings", {}).items()]
    rows += [("Versions", key, str(value)) for key, value in provenance.get("versions", {}).items()]
    for name, record in provenance.get("studies", {}).items():
        study = json.loads(record) if isinstance(record, str) else record
        if "skipped" in study:
            value = f"skipped: {study['skipped']}"
        else:
            value = f"{study.get('wall_time_s', 0.0):.1f} s" + (", kept from an earlier run" if study.get("kept") else "")
        rows.append(("Studies", name, value))
    return rows


def title_page(provenance: dict) -> Figure:
    """The PDF's first page: the title, what the report holds, the :data:`QUICK` mark of a quick
    report, and the provenance as a table (:func:`provenance_rows`: a section's name once,
    each value wrapped in its column)."""
    fig = Figure(figsize=A4)
    FigureCanvasAgg(fig)
    fig.text(0.08, 0.94, "freefloat: the documents reproduced", fontsize=20, weight="bold", va="top")
    fig.text(0.08, 0.905, "The dissertation's chapters 4 and 5 and the thesis's sec 5.6, against the exact reference",
             fontsize=10.5, va="top")
    y = 0.875
    if is_quick(provenance):
        fig.text(0.08, y, textwrap.fill(QUICK, 80), fontsize=10.5, weight="bold", color=QUICK_COLOR, va="top",
                 bbox={"facecolor": "white", "edgecolor": QUICK_COLOR, "pad": 4.0})
        mark_quick(fig)
        y -= 0.045
    step, left, middle, right = 0.0145, 0.08, 0.36, 0.94
    section = None
    for name, key, value in provenance_rows(provenance):
        if name != section:
            y -= 0.012
            fig.text(left, y, name, fontsize=10.5, weight="bold", va="top")
            y -= step * 1.25
            fig.add_artist(Line2D([left, right], [y + 0.003, y + 0.003], color="#606060", linewidth=0.8))
            section = name
        lines = textwrap.wrap(value, 62) or [""]
        fig.text(left, y, key, fontsize=8.5, va="top")
        fig.text(middle, y, "\n".join(lines), fontsize=8.5, va="top", family="monospace", linespacing=1.25)
        y -= step * len(lines)
        fig.add_artist(Line2D([left, right], [y + 0.003, y + 0.003], color="#d0d0d0", linewidth=0.5))
    return fig


def entry_page(b: Built, quick: bool = False) -> Figure:
    """One entry's A4 page: its heading, its text, its figure below (all marked :data:`QUICK`
    when ``quick``)."""
    from matplotlib.image import imread

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
    if quick:
        mark_quick(fig)
    return fig


def provenance(root: Path, settings: dict, studies: dict[str, dict], commit: str, versions: dict) -> dict:
    """What made the report: commit, versions, settings, each study's wall time and settings."""
    return {"commit": commit, "made": time.strftime("%Y-%m-%d %H:%M:%S %Z"), "folder": str(root),
            "settings": settings, "versions": versions,
            "studies": {name: json.dumps(s) for name, s in studies.items()}}
