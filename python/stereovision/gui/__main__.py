"""``python -m stereovision.gui``."""

import sys

from stereovision.gui import main

sys.exit(main())
