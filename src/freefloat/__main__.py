"""``python -m freefloat``: the ``freefloat`` command."""

import sys

from .app.cli import main

sys.exit(main())
