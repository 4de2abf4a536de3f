"""The report of ``freefloat reproduce all``: every table and figure of both documents beside
freefloat's, one page each (HTML and PDF). ``entries`` (what each entry compares), ``figures``
(freefloat's drawings), ``results`` (the studies' saved outputs) and ``pages`` (the pages)."""
