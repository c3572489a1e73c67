"""Interrupts: SIGTERM as an interrupt, and blocks that an interrupt must not cut in half."""

from __future__ import annotations

import signal
import threading
from types import FrameType, TracebackType
from typing import Any


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, systemd, a container's stop) raised as an interrupt in the main thread
    by the CLI, so that every command's Ctrl-C path runs: the stream's bag is finished, the
    batch summary says it was interrupted, a capture's half-saved pair is removed."""


def raise_terminated(signum: int, _frame: object) -> None:
    """A SIGTERM handler: :class:`Terminated` in the main thread."""
    raise Terminated(f"signal {signum}")


class HeldInterrupts:
    """Hold Ctrl-C (and SIGTERM when Python handles it, as the CLI does) for a block that an
    interrupt must not cut in half: a bag frame's messages, Dask starting or stopping (a client
    stopped half-way through its constructor cannot be closed), a run's record.

    The first signal is only recorded here and, with ``replay``, sent again once the block is
    over; a second one is not held. Does nothing outside the main thread (signal handlers cannot
    be set there).
    """

    def __init__(self, replay: bool = True) -> None:
        self.replay = replay
        self.received: list[int] = []
        self._old: dict[int, Any] = {}
        self._gone = False

    def __enter__(self) -> HeldInterrupts:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                handler = signal.getsignal(sig)
                if callable(handler):  # Python's KeyboardInterrupt, a caller's SIGTERM handler
                    self._old[sig] = handler
                    signal.signal(sig, self._hold)
        return self

    def _hold(self, signum: int, frame: FrameType | None) -> None:
        if not self.received:
            self.received.append(signum)
            return
        # the caller's handler, looked up before _restore forgets it (a second SIGTERM was
        # KeyboardInterrupt's, not the CLI's Terminated): a second signal is acted on now
        handler = self._old.get(signum, signal.default_int_handler)
        self._restore()
        self._gone = True
        handler(signum, frame)

    def _restore(self) -> None:
        for sig, handler in self._old.items():
            signal.signal(sig, handler)
        self._old = {}

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self._restore()
        if self.received and self.replay and not self._gone:
            signal.raise_signal(self.received[0])  # the restored handler raises
