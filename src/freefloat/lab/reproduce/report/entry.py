"""What an entry of the report of ``freefloat reproduce all`` is: one table, figure or erratum of
a document (:class:`Entry`), and the compared numbers it shows (:class:`Row`).

An entry names its document and number, describes the document's figure or table in our words,
says which study's output it is drawn from, and gives: a figure function (what freefloat drew), a
rows function (quantity, printed value, freefloat's value, difference) and a note (the difference's
reason). The entries themselves are declared per document (:mod:`.dissertation`, :mod:`.thesis`)
and listed in :mod:`.entries`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from matplotlib.figure import Figure

from .results import Results

DISSERTATION, THESIS = "Dissertation", "Thesis"


@dataclass(frozen=True)
class Row:
    """One compared number: what, the document's value, freefloat's, and their difference."""

    quantity: str
    printed: str
    ours: str
    difference: str


def row(quantity: str, printed: float | str | None, ours: float | str, fmt: str = ".3g") -> Row:
    """A :class:`Row`; for two numbers the difference is ours - printed and their ratio."""
    if isinstance(printed, (int, float)) and isinstance(ours, (int, float)):
        ratio = f", ratio {ours / printed:.3g}" if printed else ""
        return Row(quantity, format(printed, fmt), format(ours, fmt), f"{ours - printed:+{fmt}}{ratio}")
    shown = lambda x: "-" if x is None else (format(x, fmt) if isinstance(x, (int, float)) else str(x))  # noqa: E731
    return Row(quantity, shown(printed), shown(ours), "-")


@dataclass(frozen=True)
class Entry:
    """One table, figure or erratum of a document.

    Attributes:
        document: :data:`DISSERTATION` or :data:`THESIS`.
        number: as printed ("Fig 20", "Table 2", "Eq 140").
        caption: what the document shows there, in our words.
        study: the ``freefloat reproduce`` study its numbers come from ("" for none).
        draw: freefloat's figure from the results, or None (a table or erratum).
        rows: the compared numbers from the results, or None.
        note: the difference and its reason, or what to read in the figure.
        erratum: True for an error in the printed text.
    """

    document: str
    number: str
    caption: str
    study: str = ""
    draw: Callable[[Results], Figure] | None = None
    rows: Callable[[Results], list[Row]] | None = None
    note: str = ""
    erratum: bool = False
