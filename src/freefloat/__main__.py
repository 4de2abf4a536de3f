"""``python -m freefloat``: the ``freefloat`` command."""

import sys

from .app.signals import defer_until_main

defer_until_main()  # Ctrl-C before the command line starts: counted, not a traceback

from .app.cli import main  # noqa: E402

sys.exit(main())
