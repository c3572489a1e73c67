"""Shared fixtures: the real stereo scenes of ``../shared/data`` (evaluation.md)."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest

DATA_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data"

# A suite started in the background by a non-interactive shell (`make test &`, nohup, some CI
# runners) inherits SIGINT ignored, and Python then installs no KeyboardInterrupt handler: the
# Ctrl-C tests (a signal raised in-process, or sent to a child, which inherits the ignore)
# failed with "DID NOT RAISE KeyboardInterrupt" and exit 0 for 130. Python's own handler, as an
# interactive run has it.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """``<repo>/../shared/data``; tests using it are skipped when the data is absent."""
    if not DATA_DIR.is_dir():
        pytest.skip(f"shared test data not found at {DATA_DIR}")
    return DATA_DIR
