"""The typed stub ``_core.pyi`` says what the extension really exports, with its parameters.

``mypy.stubtest`` imports the built module and compares every function's name, parameters
(PyO3 gives each one a text signature) and defaults with the stub's: a kernel added, renamed or
given a new parameter without its stub fails here, not in a user's type checker.
"""

from __future__ import annotations

import subprocess
import sys


def test_stub_matches_the_built_extension() -> None:
    run = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "stereovision._core"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
    assert "Success" in run.stdout
