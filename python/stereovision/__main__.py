"""``python -m stereovision``: the same command line as ``stereovision``."""

import sys

from stereovision.cli import main

sys.exit(main())
