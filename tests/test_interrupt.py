"""HeldInterrupts: the first Ctrl-C or SIGTERM waits for the block's end, a second does not."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from typing import Any

import pytest

from stereovision._interrupt import HeldInterrupts, Terminated, raise_terminated


@pytest.fixture
def counted() -> Iterator[list[int]]:
    """SIGINT handled by a handler that counts its calls (and raises KeyboardInterrupt)."""
    calls: list[int] = []

    def handler(signum: int, frame: Any) -> None:
        calls.append(signum)
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGINT, handler)
    try:
        yield calls
    finally:
        signal.signal(signal.SIGINT, old)


def _kill(sig: int) -> None:
    os.kill(os.getpid(), sig)
    time.sleep(0.05)  # a handler would have run here


def test_a_second_signal_is_acted_on_at_once_and_the_first_not_replayed(
    counted: list[int],
) -> None:
    done = []
    with pytest.raises(KeyboardInterrupt):
        with HeldInterrupts():
            _kill(signal.SIGINT)
            done.append("held")
            _kill(signal.SIGINT)
            done.append("not reached")
    assert done == ["held"]
    assert counted == [signal.SIGINT]  # the caller's handler, once: no replay on top
    assert getattr(signal.getsignal(signal.SIGINT), "__name__", None) == "handler"


def test_a_second_sigterm_is_the_callers_terminated_not_a_keyboard_interrupt() -> None:
    """The second signal called KeyboardInterrupt's handler whatever the signal: the handlers
    were put back (and forgotten) before the one to call was looked up, so a second SIGTERM
    was "interrupted", exit 130, not "terminated", 143."""
    old = signal.signal(signal.SIGTERM, raise_terminated)
    try:
        with pytest.raises(KeyboardInterrupt) as caught:
            with HeldInterrupts():
                _kill(signal.SIGTERM)
                _kill(signal.SIGTERM)
    finally:
        signal.signal(signal.SIGTERM, old)
    assert caught.type is Terminated


def test_without_replay_the_signal_is_only_recorded(counted: list[int]) -> None:
    with HeldInterrupts(replay=False) as held:
        _kill(signal.SIGINT)
    assert held.received == [signal.SIGINT] and counted == []


def test_sigterm_is_held_when_python_handles_it() -> None:
    old = signal.signal(signal.SIGTERM, raise_terminated)
    done = []
    try:
        with pytest.raises(Terminated):
            with HeldInterrupts():
                _kill(signal.SIGTERM)
                done.append("frame")
    finally:
        signal.signal(signal.SIGTERM, old)
    assert done == ["frame"]


def test_an_ignored_or_default_signal_is_left_alone() -> None:
    old = signal.signal(signal.SIGTERM, signal.SIG_IGN)
    try:
        with HeldInterrupts():
            assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGTERM, old)


# Ctrl-C at the moment the first VTK import reaches pyvista's own modules, from the finder
# that is asked for them (deterministic; a real Ctrl-C only sometimes lands inside a VTK
# module's initialisation, where it crashed the process: 6 of 30 runs exit -11)
_CTRL_C_IN_VTKS_IMPORT = """
import signal, sys
class CtrlC:
    def find_spec(self, name, path=None, target=None):
        if name.startswith("pyvista.core.") and not hit:
            hit.append(name)
            signal.raise_signal(signal.SIGINT)
        return None
hit = []
sys.meta_path.insert(0, CtrlC())
from stereovision.render import _pv
try:
    _pv()
except KeyboardInterrupt:
    print("interrupted", hit != [], "pyvista" in sys.modules)
"""


def test_ctrl_c_during_vtks_first_import_waits_for_it_to_finish() -> None:
    """A KeyboardInterrupt raised while a VTK extension module initialises can crash the
    process (SIGSEGV: ``stereovision gui`` interrupted on its way up, exit 139): render's
    import of pyvista and VTK holds the signal and raises it once they are whole."""
    pytest.importorskip("pyvista")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    env.pop("DISPLAY", None)
    proc = subprocess.run(
        [sys.executable, "-c", _CTRL_C_IN_VTKS_IMPORT],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert (proc.returncode, proc.stdout.strip()) == (0, "interrupted True True"), proc.stderr


_CTRL_C_IN_THE_IMPORTS = """
import importlib.abc, os, runpy, signal, sys

class CtrlC(importlib.abc.MetaPathFinder):  # one Ctrl+C, as {module} is first imported
    def find_spec(self, name, path=None, target=None):
        if name == {module!r} and self in sys.meta_path:
            sys.meta_path.remove(self)
            os.kill(os.getpid(), signal.{signal})
        return None

sys.meta_path.insert(0, CtrlC())
sys.argv = ["stereovision", *{argv!r}]
{run}
"""

#: The console script's wrapper (pyproject's [project.scripts]), ``python -m stereovision``
#: and ``python -m stereovision.gui``.
_ENTRIES = {
    "stereovision": "from stereovision.__main__ import main\nsys.exit(main())",
    "python -m stereovision": 'runpy.run_module("stereovision", run_name="__main__")',
    "python -m stereovision.gui": 'runpy.run_module("stereovision.gui", run_name="__main__")',
}


@pytest.mark.parametrize("module", ["numpy", "cv2", "stereovision._core"])
@pytest.mark.parametrize("entry", list(_ENTRIES))
def test_ctrl_c_in_the_start_up_imports_is_one_line_and_130(entry: str, module: str) -> None:
    """A Ctrl+C while the command imported NumPy, OpenCV or the extension (the 0.2 s before
    the CLI's main ran: ``import stereovision`` imported them all) printed a traceback (4 runs
    in 60 interrupted at random start-up times). The package imports them on first use now,
    and the entry points say the interrupt as the CLI: one line, exit 130."""
    argv = ["--version"] if entry != "python -m stereovision.gui" else ["--port", "-1"]
    code = _CTRL_C_IN_THE_IMPORTS.format(
        module=module, argv=argv, run=_ENTRIES[entry], signal="SIGINT"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120
    )
    assert (proc.returncode, proc.stdout, proc.stderr) == (130, "", "stereovision: interrupted\n")


# datetime: imported by NumPy's C initialisation (an interrupt there came out as NumPy's
# ImportError, a traceback); stereovision.depth: by the CLI's parser, after the start-up imports
@pytest.mark.parametrize("module", ["datetime", "stereovision.depth"])
@pytest.mark.parametrize("entry", ["stereovision", "python -m stereovision"])
@pytest.mark.parametrize(
    ("signame", "expected"),
    [
        ("SIGTERM", (143, "", "stereovision: terminated (SIGTERM)\n")),
        ("SIGINT", (130, "", "stereovision: interrupted\n")),
    ],
)
def test_a_signal_in_the_start_up_is_one_line(
    signame: str, expected: tuple[int, str, str], entry: str, module: str
) -> None:
    """A SIGTERM (``kill``, systemd) in the command's first 0.3 s, its imports and its parse,
    killed it without a word (Python's default until the CLI set its handler, after the
    parse), and a Ctrl+C inside NumPy's C initialisation printed NumPy's ImportError. The
    entry point takes SIGTERM as the CLI does from its first import on, and holds both until
    the imports are whole: one line, exit 143 or 130."""
    code = _CTRL_C_IN_THE_IMPORTS.format(
        module=module, argv=["--version"], run=_ENTRIES[entry], signal=signame
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120
    )
    assert (proc.returncode, proc.stdout, proc.stderr) == expected


# datetime: imported by NumPy's C initialisation; stereovision.cli: by the GUI's parser
@pytest.mark.parametrize("module", ["datetime", "stereovision.cli"])
@pytest.mark.parametrize(
    ("signame", "expected"),
    [
        ("SIGTERM", (143, "", "stereovision: terminated (SIGTERM)\n")),
        ("SIGINT", (130, "", "stereovision: interrupted\n")),
    ],
)
def test_a_signal_in_the_guis_start_up_is_one_line(
    signame: str, expected: tuple[int, str, str], module: str
) -> None:
    """``python -m stereovision.gui``, as ``python -m stereovision``: a SIGTERM in its imports
    and its parse (the second before the CLI's runner set its handler) killed it without a
    word, and a Ctrl+C inside NumPy's C initialisation printed NumPy's ImportError, exit 1."""
    code = _CTRL_C_IN_THE_IMPORTS.format(
        module=module,
        argv=["--port", "-1"],
        run=_ENTRIES["python -m stereovision.gui"],
        signal=signame,
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120
    )
    assert (proc.returncode, proc.stdout, proc.stderr) == expected
