"""``python -m stereovision``: the same command line as ``stereovision`` (its entry point)."""

import signal
import sys


def main() -> int:
    """The ``stereovision`` command: :func:`stereovision.cli.main`, once it is imported.

    Its imports (NumPy, OpenCV, the extension: 0.2 s) are the first thing the command does; a
    Ctrl+C in them printed a traceback. It is said as the CLI says it: one line, exit 130, once
    the imports are whole. A SIGTERM there (and in the parse, before the CLI's own handler)
    killed the process without a word: it is the CLI's ``Terminated`` from here on, one line
    and exit 143.
    """
    try:  # the package's __init__ alone (its API is imported on first use)
        from stereovision._interrupt import HeldInterrupts, Terminated, raise_terminated
    except KeyboardInterrupt:
        print("stereovision: interrupted", file=sys.stderr)
        return 130
    kept = signal.signal(signal.SIGTERM, raise_terminated)
    try:
        # held until the imports are whole: raised inside NumPy's C initialisation, the
        # interrupt came out as NumPy's ImportError ("Importing the numpy C-extensions
        # failed"), a traceback
        with HeldInterrupts():
            from stereovision.cli import main as cli_main

        return cli_main()
    except Terminated:
        print("stereovision: terminated (SIGTERM)", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("stereovision: interrupted", file=sys.stderr)
        return 130
    finally:
        signal.signal(signal.SIGTERM, kept)


if __name__ == "__main__":
    sys.exit(main())
