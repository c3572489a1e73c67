"""``python -m stereovision``: the same command line as ``stereovision`` (its entry point)."""

import sys


def main() -> int:
    """The ``stereovision`` command: :func:`stereovision.cli.main`, once it is imported.

    Its imports (NumPy, OpenCV, the extension: 0.2 s) are the first thing the command does; a
    Ctrl+C in them printed a traceback. It is said as the CLI says it: one line, exit 130.
    """
    try:
        from stereovision.cli import main as cli_main
    except KeyboardInterrupt:
        print("stereovision: interrupted", file=sys.stderr)
        return 130
    return cli_main()


if __name__ == "__main__":
    sys.exit(main())
