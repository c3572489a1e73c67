"""Interrupts: SIGTERM as an interrupt, and blocks that an interrupt must not cut in half."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, systemd, a container's stop) raised as an interrupt in the main thread
    by the CLI, so that every command's Ctrl-C path runs: the stream's bag is finished, the
    batch summary says it was interrupted, a capture's half-saved pair is removed."""


def raise_terminated(signum: int, _frame: object) -> None:
    """A SIGTERM handler: :class:`Terminated` in the main thread."""
    raise Terminated(f"signal {signum}")


@contextmanager
def signals_deferred() -> Iterator[None]:
    """Hold Ctrl-C and SIGTERM until the block ends, then deliver them to the handlers the
    process had: what the block writes goes out whole or not at all. Only the main thread
    receives signals; in another thread this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []
    kept = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        kept[sig] = signal.getsignal(sig)
        signal.signal(sig, lambda signum, _frame: got.append(signum))
    try:
        yield
    finally:
        for sig, handler in kept.items():
            signal.signal(sig, handler)
        for signum in dict.fromkeys(got):
            signal.raise_signal(signum)
