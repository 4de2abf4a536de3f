"""The report of ``freefloat reproduce all``: every table and figure of both documents beside
freefloat's, one page each (HTML and PDF). ``entries`` (what each entry compares), ``figures``
(freefloat's drawings), ``results`` (the studies' saved outputs) and ``pages`` (the pages)."""

from ....lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
