"""``python -m stereovision.gui``."""

import sys

if __name__ == "__main__":
    try:  # a Ctrl+C in the imports: one line, exit 130, as the CLI (it printed a traceback)
        from stereovision.gui import main
    except KeyboardInterrupt:
        print("stereovision: interrupted", file=sys.stderr)
        sys.exit(130)
    sys.exit(main())
