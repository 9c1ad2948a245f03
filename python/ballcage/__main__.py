"""``python -m ballcage``: the same as the ``ballcage`` script."""

import sys

from ballcage.cli import main

raise SystemExit(main(sys.argv[1:]))
