"""``python -m stereovision.gui``."""

import signal
import sys

if __name__ == "__main__":
    try:  # a Ctrl+C in the imports: one line, exit 130, as the CLI (it printed a traceback)
        from stereovision._interrupt import Terminated, raise_terminated
        from stereovision.gui import main
    except KeyboardInterrupt:
        print("stereovision: interrupted", file=sys.stderr)
        sys.exit(130)
    # SIGTERM as the CLI's Terminated from here on, as python -m stereovision takes it: in
    # the imports and the parse (the 1 s before the CLI's runner set it) it killed the process
    # without a word
    signal.signal(signal.SIGTERM, raise_terminated)
    try:
        status = main()
    except Terminated:
        print("stereovision: terminated (SIGTERM)", file=sys.stderr)
        status = 143
    sys.exit(status)
