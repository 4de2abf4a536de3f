"""Every entry of the report of ``freefloat reproduce all``, in the documents' order: the
dissertation's tables, figures and errata (:mod:`.dissertation`), then the thesis's
(:mod:`.thesis`) and its remaining programme (:mod:`.programme`)."""

from __future__ import annotations

from . import dissertation, programme, thesis
from .entry import Entry

#: The report's entries, one page each, in this order.
ENTRIES: tuple[Entry, ...] = (*dissertation.ENTRIES, *thesis.ENTRIES, *programme.ENTRIES)
