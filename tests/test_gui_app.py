"""The GUI without a browser: its command line and server start, and ``StereoApp``'s handlers
called in process (what each click, field and toggle does to the page's state and texts).

The same page driven in headless chromium is tested in test_gui_browser.py; the sources
(allowed folders, cameras, image folders) in test_gui_sources.py.
"""

from __future__ import annotations

import argparse
import math
import re
import signal
import socket
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
import synthetic_scene as syn
from gui_helpers import CONES, STARTUP_TIMEOUT_S
from gui_helpers import decode_data_url as _decode
from gui_helpers import write_video as _write_video

from stereovision.gui import sources
from stereovision.gui.sources import AllowedFolders

# -------------------------------------------------------------------------- command line and server


def test_gui_cli_errors_exit_2(tmp_path, capsys):
    from stereovision.gui import main

    assert main(["--left", "0", "--port", "0"]) == 2
    assert "give both --left and --right" in capsys.readouterr().err
    assert main(["--left", str(tmp_path / "x.avi"), "--right", str(tmp_path / "y.avi")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("stereovision: error: ") and "not found" in err
    assert main(["--data", str(tmp_path / "nope")]) == 2
    assert "data folder not found" in capsys.readouterr().err


def _gui_process(*args: str) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "stereovision.gui", "--no-browser", *args]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_a_page_closed_mid_message_prints_no_traceback():
    """Closing the browser tab while the 3-D view streamed a frame printed about 40 lines of
    wslink and aiohttp tracebacks in the terminal. They are filtered now; any other error of
    those libraries still prints its name and trace."""
    import logging

    from stereovision.gui import SERVER_LOGGERS, quiet_closed_pages

    flt = quiet_closed_pages()
    try:
        assert quiet_closed_pages() is flt  # once only
        seen: list[str] = []

        class Keep(logging.Handler):
            def emit(self, record: logging.LogRecord) -> None:
                seen.append(record.getMessage())

        keep = Keep()
        wslink, aiohttp = (logging.getLogger(n) for n in SERVER_LOGGERS)
        for lg in (wslink, aiohttp):
            lg.addHandler(keep)
        try:
            closed = ConnectionResetError("Cannot write to closing transport")
            wslink.error("Exception raised")
            wslink.error("ClientConnectionResetError('Cannot write to closing transport')")
            wslink.error("Traceback ...\nClientConnectionResetError: Cannot write to closing")
            aiohttp.error("Error handling request from 127.0.0.1", exc_info=closed)
            wslink.error("Exception raised")
            wslink.error("ValueError('bad')")
            aiohttp.error("Error handling request from 127.0.0.1", exc_info=ValueError("x"))
            aiohttp.error("Error handling request from ::1", exc_info=OSError(28, "No space"))
        finally:
            for lg in (wslink, aiohttp):
                lg.removeHandler(keep)
        assert seen == [
            "ValueError('bad')",
            "Error handling request from 127.0.0.1",
            "Error handling request from ::1",  # an OSError other than a closed page stays
        ]
    finally:
        for n in SERVER_LOGGERS:
            logging.getLogger(n).removeFilter(flt)


def test_gui_port_0_announces_the_port_it_got():
    """``gui --port 0`` printed ``http://127.0.0.1:0/``: the address was printed before the
    server bound. It is now printed once the server listens, with the port the system chose."""
    import threading
    import urllib.request

    pytest.importorskip("trame")
    proc = _gui_process("--port", "0")
    watchdog = threading.Timer(STARTUP_TIMEOUT_S, proc.kill)  # a hung start ends the read
    watchdog.start()
    try:
        line = proc.stdout.readline()  # blocks until the server listens (or exits)
        watchdog.cancel()
        m = re.fullmatch(
            r"stereovision gui on http://127\.0\.0\.1:(\d+)/ \(Ctrl\+C to stop\)\n", line
        )
        assert m is not None, (line, proc.poll())
        port = int(m.group(1))
        assert port > 0
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=30) as reply:
            assert reply.status == 200 and b"<html" in reply.read().lower()
    finally:
        watchdog.cancel()
        proc.terminate()
        proc.wait(timeout=30)


def _signal_the_serving_gui(argv: list[str], signum: int) -> tuple[int, str, str]:
    """Start ``argv`` (a GUI serving on a free port), send ``signum`` once the server listens
    (its signal handlers are then set), and give back its exit status, stdout and stderr."""
    import threading

    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    watchdog = threading.Timer(STARTUP_TIMEOUT_S, proc.kill)  # a hung start ends the read
    watchdog.start()
    try:
        line = proc.stdout.readline()  # the server listens: its signal handlers are set
        watchdog.cancel()
        assert line.startswith("stereovision gui on http://127.0.0.1:"), (line, proc.poll())
        proc.send_signal(signum)
        out, err = proc.communicate(timeout=60)
    finally:
        watchdog.cancel()
        if proc.poll() is None:
            proc.kill()
            proc.wait(timeout=30)
    return proc.returncode, out, err


#: Each entry point with each stop signal: its exit status and the one line it says.
_EACH_ENTRY_AND_SIGNAL = pytest.mark.parametrize(
    ("entry", "signum", "status", "said"),
    [
        ("stereovision", signal.SIGINT, 130, "interrupted"),
        ("stereovision", signal.SIGTERM, 143, "terminated (SIGTERM)"),
        ("stereovision.gui", signal.SIGINT, 130, "interrupted"),
        ("stereovision.gui", signal.SIGTERM, 143, "terminated (SIGTERM)"),
    ],
)


@_EACH_ENTRY_AND_SIGNAL
def test_gui_stopped_by_ctrl_c_exits_130_as_the_cli(
    entry: str, signum: int, status: int, said: str
) -> None:
    """Ctrl+C on a serving GUI exited 0 without a word (aiohttp's signal handlers stop the
    server quietly and trame's start returns), SIGTERM too: the CLI's other commands exit 130
    (143) and say so. Both entry points now do."""
    pytest.importorskip("trame")
    command = [sys.executable, "-m", entry, *(["gui"] if entry == "stereovision" else [])]
    code, out, err = _signal_the_serving_gui([*command, "--no-browser", "--port", "0"], signum)
    assert (code, out, err) == (status, "", f"stereovision: {said}\n")


_SIGNAL_AS_THE_SERVER_IS_SET_UP = """
import os, signal, sys
from aiohttp import web

real = web.TCPSite.start
async def start(self):  # the runner is set up (aiohttp's handlers then), the page not ready
    os.kill(os.getpid(), {signum})
    await real(self)
web.TCPSite.start = start
from {module} import main
sys.exit(main([{argv}"--no-browser", "--port", "0"]))
"""


@_EACH_ENTRY_AND_SIGNAL
def test_a_signal_while_the_server_is_set_up_is_not_exit_0(
    entry: str, signum: int, status: int, said: str
) -> None:
    """A signal between the server's set-up and its ready hook (where ours replace aiohttp's
    handlers) was heard by aiohttp's, which stop the server without a trace: exit 0, silent.
    trame is now told to set none; Python's (SIGTERM: the CLI's Terminated) say it: 130
    (143), one line."""
    pytest.importorskip("trame")
    module = "stereovision.cli" if entry == "stereovision" else "stereovision.gui"
    code = _SIGNAL_AS_THE_SERVER_IS_SET_UP.format(
        signum=int(signum), module=module, argv='"gui", ' if entry == "stereovision" else ""
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=STARTUP_TIMEOUT_S + 60,
    )
    assert (done.returncode, done.stdout, done.stderr) == (status, "", f"stereovision: {said}\n")


_SIGTERM_WHILE_THE_GUI_STARTS = """
import os, signal, sys
import stereovision.gui as gui

def build_app(_args):  # the cameras being opened: SIGTERM from a service manager
    os.kill(os.getpid(), signal.SIGTERM)
    raise AssertionError("not interrupted")
gui.build_app = build_app
sys.exit(gui.main(["--no-browser", "--port", "0"]))
"""


def test_python_m_stereovision_gui_takes_sigterm_as_the_cli() -> None:
    """``python -m stereovision.gui`` set no SIGTERM handler before its server's (``stereovision
    gui`` has the CLI's): a SIGTERM while it started killed it (status -15, no word, the
    camera not closed). It is now the CLI's Terminated: 143 and one line."""
    done = subprocess.run(
        [sys.executable, "-c", _SIGTERM_WHILE_THE_GUI_STARTS],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert (done.returncode, done.stdout, done.stderr) == (
        143,
        "",
        "stereovision: terminated (SIGTERM)\n",
    )


_CALLER_OF_THE_GUI = """
import os, signal, sys
import stereovision.gui as gui

heard = []
def mine(signum, _frame):
    heard.append(signum)
signal.signal(signal.SIGINT, mine)
signal.signal(signal.SIGTERM, mine)
status = gui.main(["--no-browser", "--port", "0"])
back = [signal.getsignal(s) is mine for s in (signal.SIGINT, signal.SIGTERM)]
fd = signal.set_wakeup_fd(-1)
os.kill(os.getpid(), signal.SIGINT)
os.kill(os.getpid(), signal.SIGTERM)
print(status, back, fd, heard, flush=True)
"""


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_program_calling_the_gui_gets_its_signal_handlers_back(signum: int) -> None:
    """The server's loop took SIGINT and SIGTERM (a no-op handler and a wakeup fd into its
    pipe) and kept them once it had stopped: a program that ran ``gui.main`` and went on had
    its own handlers replaced, every later Ctrl+C ignored. They are put back, the wakeup fd
    too."""
    pytest.importorskip("trame")
    code, out, err = _signal_the_serving_gui([sys.executable, "-c", _CALLER_OF_THE_GUI], signum)
    status = 130 if signum == signal.SIGINT else 143
    # the signal stopped the GUI; the caller's handlers then heard the two sent after it
    assert (code, out) == (0, f"{status} [True, True] -1 [2, 15]\n"), err


_CALLER_OF_THE_GUI_TWICE = """
import os, signal, threading
import stereovision.gui as gui

real = gui.url_for
sent = []
def url_for(*args):
    if len(sent) < runs[0]:  # once a run: the address is said when the server listens
        sent.append(1)
        threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
    return real(*args)
gui.url_for = url_for
runs, statuses = [0], []
for _ in range(2):
    runs[0] += 1
    statuses.append(gui.main(["--no-browser", "--port", "0"]))
print(statuses, flush=True)
"""


def test_a_program_calling_the_gui_twice_runs_the_second_alone() -> None:
    """trame's server is one per process and keeps its hooks: a second ``gui.main`` in the
    same program ran the first's ready hook too, its address said twice and a Ctrl+C maybe
    heard by the first's handler (the second then exits 0). Each run says its address once
    and is stopped by its Ctrl+C: 130 twice."""
    pytest.importorskip("trame")
    done = subprocess.run(
        [sys.executable, "-c", _CALLER_OF_THE_GUI_TWICE],
        capture_output=True,
        text=True,
        timeout=120,
    )
    lines = done.stdout.splitlines()
    assert [line.startswith("stereovision gui on http://127.0.0.1:") for line in lines] == [
        True,
        True,
        False,
    ], done.stdout + done.stderr
    assert lines[2] == "[130, 130]", done.stderr
    assert done.stderr == "stereovision: interrupted\n" * 2


_CALLER_OF_THE_GUI_TWICE_WATCHING_ITS_APPS = (
    _CALLER_OF_THE_GUI_TWICE.replace(
        "runs, statuses = [0], []",
        "from stereovision.gui.app import StereoApp\n"
        "apps, heard = [], []\n"
        "init, on_ready = StereoApp.__init__, StereoApp._on_ready\n"
        "on_method = StereoApp._on_method\n"
        "def __init__(self, *a, **k):\n"
        "    apps.append(self)\n"
        "    init(self, *a, **k)\n"
        "def _on_ready(self, **k):\n"
        "    heard.append(('ready', apps.index(self)))\n"
        "    return on_ready(self, **k)\n"
        "def _on_method(self, **k):\n"
        "    if probing:\n"
        "        heard.append(('method', apps.index(self)))\n"
        "        return None\n"
        "    return on_method(self, **k)\n"
        "StereoApp.__init__, StereoApp._on_ready, StereoApp._on_method = (\n"
        "    __init__, _on_ready, _on_method)\n"
        "probing = False\n"
        "runs, statuses = [0], []",
    )
    .replace(
        '    statuses.append(gui.main(["--no-browser", "--port", "0"]))\n',
        '    statuses.append(gui.main(["--no-browser", "--port", "0"]))\n'
        "    probing = True  # a change once the run is over: its app no longer hears it\n"
        "    apps[-1].state.method = 'sgm' if apps[-1].state.method != 'sgm' else 'mcgm'\n"
        "    apps[-1].state.flush()\n"
        "    probing = False\n",
    )
    .replace("print(statuses, flush=True)", "print(statuses, heard, flush=True)")
)


def test_a_second_gui_in_one_program_is_served_by_its_own_app_alone() -> None:
    """93b9cff took cmd_gui's own hook off trame's one server, but the first app's were kept
    there: its ready hook ran again in the second run (it loaded and matched the demo scene
    into the page the second app shows; with cameras, it read from the closed ones), and its
    handlers heard the page's changes after its run (a method chosen: it recomputed). Each
    app's hooks are taken off when its run ends."""
    pytest.importorskip("trame")
    done = subprocess.run(
        [sys.executable, "-c", _CALLER_OF_THE_GUI_TWICE_WATCHING_ITS_APPS],
        capture_output=True,
        text=True,
        timeout=120,
    )
    last = done.stdout.splitlines()[-1]
    assert last == "[130, 130] [('ready', 0), ('ready', 1)]", done.stderr


_CALLER_OF_A_GUI_WHOSE_CLOSE_FAILS = _CALLER_OF_THE_GUI.replace(
    "status = gui.main(",
    "from stereovision.gui.app import StereoApp\n"
    "def fails(self):\n"
    "    raise OSError('the camera did not close')\n"
    "StereoApp.stop_work = fails\n"
    "status = gui.main(",
)


def test_the_callers_signal_handlers_come_back_when_the_close_fails() -> None:
    """The handlers were put back after the camera's close: a close that raised left them the
    stopped loop's (a no-op, a wakeup fd into its pipe), the caller's Ctrl+C ignored."""
    pytest.importorskip("trame")
    code, out, err = _signal_the_serving_gui(
        [sys.executable, "-c", _CALLER_OF_A_GUI_WHOSE_CLOSE_FAILS], signal.SIGINT
    )
    # the close's error said (not the interrupt), then the caller's handlers heard both
    assert (code, out) == (0, "2 [True, True] -1 [2, 15]\n"), err
    assert err == "stereovision: error: the camera did not close\n"


def test_gui_on_a_busy_port_says_so_in_one_line():
    """A busy port: the address was announced first, then
    ``[Errno 98] error while attempting to bind on address ...``. Now nothing is announced and
    the error says which port is taken and what to do."""
    pytest.importorskip("trame")
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        proc = _gui_process("--port", str(port))
        out, err = proc.communicate(timeout=60)
    assert proc.returncode == 2
    assert out == ""
    assert err == (
        f"stereovision: error: port {port} on 127.0.0.1 is in use (another server?): "
        "choose another with --port, or --port 0 for a free one\n"
    )


def test_gui_url_brackets_an_ipv6_host():
    from stereovision.gui import url_for

    assert url_for("127.0.0.1", 8080) == "http://127.0.0.1:8080/"
    assert url_for("::1", 41000) == "http://[::1]:41000/"
    assert url_for("localhost", 1) == "http://localhost:1/"
    assert url_for("2001:db8:0:0:0:0:0:1", 80) == "http://[2001:db8:0:0:0:0:0:1]:80/"


def test_add_cli_registers_gui():
    from stereovision.gui import DEFAULT_HOST, add_cli

    parser = argparse.ArgumentParser()
    add_cli(parser.add_subparsers())
    args = parser.parse_args(["gui", "--left", "0", "--right", "1", "--no-browser"])
    assert (args.left, args.right, args.host, args.no_browser) == ("0", "1", DEFAULT_HOST, True)
    assert DEFAULT_HOST == "127.0.0.1"


# ------------------------------------------------------- mutation audit: cmd_gui and main with a
# stand-in app (its server's start binds, or fails, as told), no trame server started


class _Ready(list):
    """trame's function set, as cmd_gui uses it: its hook added, then discarded."""

    def add(self, fn: Any) -> None:
        self.append(fn)

    def discard(self, fn: Any) -> None:
        self.discarded = [*getattr(self, "discarded", []), fn]


class _Source:
    closed = 0

    def close(self) -> None:
        self.closed += 1


class _Server:
    def __init__(self, fail: BaseException | None, after_bind: bool) -> None:
        self.port, self.fail, self.after_bind = 43210, fail, after_bind
        self.ready = _Ready()
        self.started: dict[str, Any] = {}

    def start(self, **kw: Any) -> None:
        self.started = dict(kw, argv=list(sys.argv))
        if self.fail is not None and not self.after_bind:
            raise self.fail
        for fn in self.ready:
            fn()
        if self.fail is not None:
            raise self.fail


class _App:
    def __init__(self, fail: BaseException | None = None, after_bind: bool = False) -> None:
        self.server = _Server(fail, after_bind)
        self.ctrl = argparse.Namespace(on_server_ready=self.server.ready)
        self.source = _Source()
        self.stopped = 0

    def stop_work(self) -> None:
        self.stopped += 1

    def detach(self) -> None:
        self.detached = getattr(self, "detached", 0) + 1


def _gui_args(*argv: str) -> argparse.Namespace:
    from stereovision.gui import add_arguments

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return parser.parse_args(list(argv))


def test_cmd_gui_starts_the_server_as_asked_and_closes_the_cameras(monkeypatch, capsys):
    """What cmd_gui hands the server (port, host, browser), the address it prints once bound,
    the note for a non-loopback host, trame's view of sys.argv and the cameras closed after."""
    import stereovision.gui as gui

    args = _gui_args()
    assert (args.port, args.host, args.no_browser) == (8080, "127.0.0.1", False)
    for argv, browser, note in (
        ([], True, ""),
        (["--no-browser", "--host", "::1", "--port", "0"], False, ""),
        (["--host", "0.0.0.0"], True, "note: listening on 0.0.0.0: anyone who can reach this "
         "address sees the cameras\n"),
    ):  # fmt: skip
        app = _App()
        monkeypatch.setattr(gui, "build_app", lambda _args, app=app: app)
        args = _gui_args(*argv)
        monkeypatch.setattr(sys, "argv", ["stereovision", "gui", *argv])
        assert gui.cmd_gui(args) == 0
        assert app.server.started == {
            "port": args.port,
            "host": args.host,
            "open_browser": browser,
            "show_connection_info": False,
            "timeout": 0,
            # trame parses sys.argv: it sees none of ours, and sets no signal handlers
            "argv": ["stereovision", "--nosignalhandlers"],
        }
        assert sys.argv == ["stereovision", "gui", *argv]
        assert app.source.closed == 1 and app.stopped == 1
        out, err = capsys.readouterr()
        assert out == f"stereovision gui on {gui.url_for(args.host, 43210)} (Ctrl+C to stop)\n"
        assert err == note


def test_the_public_host_note_is_not_said_of_a_loopback_host(monkeypatch, capsys):
    """Any 127.0.0.0/8 address, ``::ffff:127.0.0.1`` and ``localhost.`` are this machine
    alone: ``--host 127.0.0.2`` printed "anyone who can reach this address sees the cameras"
    (only 127.0.0.1, localhost and ::1 were known), and so did ``127.1``, which the server
    binds as 127.0.0.1. Another address or name still gets it."""
    import stereovision.gui as gui

    note = "note: listening on {}: anyone who can reach this address sees the cameras\n"
    for host, public in (
        ("127.0.0.2", False),
        ("127.255.255.254", False),
        ("::ffff:127.0.0.1", False),
        ("localhost.", False),
        ("LocalHost", False),
        ("::1", False),
        # inet_aton's forms of 127.0.0.1, as the bind reads them (getaddrinfo)
        ("127.1", False),
        ("0x7f.1", False),
        ("2130706433", False),
        ("192.168.1.5", True),
        ("10.1", True),
        ("::", True),
        ("::ffff:10.0.0.1", True),
        ("localhost.example.com", True),
        ("127.0.0.1.example.com", True),
    ):
        monkeypatch.setattr(gui, "build_app", lambda _args: _App())
        assert gui.cmd_gui(_gui_args("--no-browser", "--host", host)) == 0
        assert capsys.readouterr().err == (note.format(host) if public else ""), host


def test_cmd_gui_says_why_the_server_cannot_listen(monkeypatch, capsys):
    """A bind that fails: one message naming the port and host (errno kept), nothing announced,
    the cameras closed; a failure after the bind is raised as it came."""
    import errno

    import stereovision.gui as gui

    cases = (
        (OSError(errno.EADDRINUSE, "Address already in use"), ["--port", "8181"],
         "port 8181 on 127.0.0.1 is in use (another server?): choose another with --port, or "
         "--port 0 for a free one"),
        (OSError(errno.EACCES, "Permission denied"), ["--port", "80"],
         "cannot listen on 127.0.0.1 port 80: Permission denied"),
        (OSError("no such host"), ["--host", "nowhere.invalid"],
         "cannot listen on nowhere.invalid port 8080: no such host"),
    )  # fmt: skip
    for exc, argv, said in cases:
        app = _App(exc)
        monkeypatch.setattr(gui, "build_app", lambda _args, app=app: app)
        with pytest.raises(OSError) as raised:
            gui.cmd_gui(_gui_args(*argv))
        assert str(raised.value) == said and raised.value.errno == exc.errno
        assert raised.value.__cause__ is exc and app.source.closed == 1
        assert capsys.readouterr() == ("", "")
        assert gui.main(argv) == 2
        assert capsys.readouterr() == ("", f"stereovision: error: {said}\n")
    later = OSError(errno.EADDRINUSE, "Address already in use")
    app = _App(later, after_bind=True)
    monkeypatch.setattr(gui, "build_app", lambda _args: app)
    with pytest.raises(OSError) as raised:
        gui.cmd_gui(_gui_args())
    assert raised.value is later and app.source.closed == 1


def test_the_page_may_open_the_demo_data_and_the_data_folders(tmp_path):
    """``--data DIR`` adds DIR to the folders the page may open files from; the bundled demo
    data stays allowed."""
    pytest.importorskip("trame")
    from stereovision.gui import build_app, bundled_data_dir

    app = build_app(_gui_args("--data", str(tmp_path), "--no-browser"))
    assert app.folders.roots == (bundled_data_dir().resolve(), tmp_path.resolve())
    assert app.folders.resolve(bundled_data_dir() / "cones" / "left.png").is_file()


def test_gui_main_errors_are_one_line(monkeypatch, capsys, tmp_path):
    """``python -m stereovision.gui``: Ctrl+C is exit 130; a missing optional package (trame,
    rosbags for --from-bag) one line and exit 2. Without rosbags, ``--from-bag`` printed
    ImportError's traceback here, where ``stereovision gui`` says the line."""
    import stereovision.gui as gui

    def interrupted(_args: argparse.Namespace) -> Any:
        raise KeyboardInterrupt

    def too_large(_args: argparse.Namespace) -> Any:
        raise MemoryError("Unable to allocate 30.0 GiB for an array")

    monkeypatch.setattr(gui, "build_app", interrupted)
    assert gui.main([]) == 130
    assert capsys.readouterr().err == "stereovision: interrupted\n"  # as the CLI; it said nothing
    monkeypatch.setattr(gui, "build_app", too_large)
    assert gui.main([]) == 2  # as the CLI; MemoryError's traceback came out
    assert capsys.readouterr().err == (
        "stereovision: error: Unable to allocate 30.0 GiB for an array\n"
    )

    def a_bug(_args: argparse.Namespace) -> Any:
        raise KeyError("view")

    monkeypatch.setattr(gui, "build_app", a_bug)
    assert gui.main([]) == 2  # as the CLI: one line, where a bug of ours printed a traceback
    assert capsys.readouterr().err == (
        "stereovision: error: internal KeyError: 'view' (please report this)\n"
    )

    def too_deep(_args: argparse.Namespace) -> Any:
        raise RecursionError("maximum recursion depth exceeded")

    # a RuntimeError, but a bug of ours (181c822 said it so in the CLI, not here)
    monkeypatch.setattr(gui, "build_app", too_deep)
    assert gui.main([]) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: internal RecursionError: maximum recursion depth exceeded"
        " (please report this)\n"
    )
    monkeypatch.undo()
    for argv in (["--port", "65536"], ["--port", "-1"]):
        assert gui.main(argv) == 2
        err = capsys.readouterr().err
        assert err == (
            "stereovision: error: --port: expected a port 1 to 65535, or 0 for a free one, "
            f"got {argv[1]}\n"
        )
    monkeypatch.setitem(sys.modules, "trame.app", None)  # trame not installed
    assert gui.main([]) == 2
    err = capsys.readouterr().err
    assert err == "stereovision: error: the GUI needs trame: pip install 'stereovision-rs[gui]'\n"
    monkeypatch.undo()
    pytest.importorskip("trame")
    monkeypatch.setitem(sys.modules, "rosbags.highlevel", None)  # rosbags not installed
    bag = tmp_path / "rig.bag"
    bag.write_bytes(b"")
    assert gui.main(["--from-bag", str(bag), "--no-browser"]) == 2
    assert capsys.readouterr() == (
        "",
        "stereovision: error: reading ROS bags needs rosbags: pip install 'stereovision-rs[ros]'\n",
    )


def test_gui_main_says_warnings_and_a_path_with_a_newline_in_one_line_as_the_cli(capsys, tmp_path):
    """``python -m stereovision.gui`` said a calibration's warning as Python does (``<frozen
    runpy>:88: UserWarning: baseline ...``, no "stereovision: warning:") and cut an error at a
    newline in a path given (``left source not found: a``), where ``stereovision gui`` says
    both in one line. It now runs the command as the CLI does."""
    import stereovision.gui as gui

    calib = tmp_path / "calib.txt"  # a 9 km baseline: warned of, then the camera is refused
    calib.write_text(
        "cam0=[700 0 300; 0 700 200; 0 0 1]\ncam1=[700 0 300; 0 700 200; 0 0 1]\n"
        "doffs=0\nbaseline=9000000\nwidth=600\nheight=400\n"
    )
    left = str(tmp_path / "a\nb.avi")
    argv = ["--no-browser", "--calib", str(calib), "--left", left, "--right", left]
    assert gui.main(argv) == 2
    out, err = capsys.readouterr()
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 2, err
    assert lines[0].startswith("stereovision: warning: baseline 9e+06 mm = 9000 m, longer")
    assert lines[1] == f"stereovision: error: left source not found: {tmp_path}/a\\nb.avi"


def test_scaled_calibration_and_compute_view():
    from stereovision.gui.app import compute_view, draw_matches

    calib = syn.calibration()
    half = sources.scaled_calibration(calib, 0.5, (syn.W // 2, syn.H // 2))
    assert half.K1[0, 0] == pytest.approx(syn.F / 2)
    assert half.K1[0, 2] == pytest.approx((syn.CX + 0.5) / 2 - 0.5)
    assert half.image_size == (syn.W // 2, syn.H // 2)
    res = syn.depth_result()
    right = np.roll(res.left_rectified, -4, axis=1)
    view = compute_view(res.left_rectified, right, calib, "opencv-sgbm", max_disparity=16)
    assert view.left_url.startswith("data:image/jpeg;base64,")
    assert view.disparity_url.startswith("data:image/jpeg;base64,")
    assert view.result.method == "opencv-sgbm"
    with pytest.raises(ValueError, match="unknown method"):
        compute_view(res.left_rectified, right, calib, "nope")
    # frames at half the calibration's resolution: the calibration is scaled, with a note
    small, small_r, _ = sources.scale_pair(res.left_rectified, right, 80)
    half_view = compute_view(small, small_r, calib, "opencv-sgbm", max_disparity=16)
    assert half_view.result.calibration.K1[0, 0] == pytest.approx(syn.F / 2)
    assert "warning: the calibration is for 160x120 and the frames are 80x60" in half_view.stats
    cropped = np.ascontiguousarray(res.left_rectified[:, :100])
    with pytest.raises(ValueError, match=r"calibration is for 160x120 .* another aspect"):
        compute_view(cropped, cropped, calib, "opencv-sgbm")
    sparse = np.full(res.disparity.shape, np.nan, np.float32)
    sparse[60, 100] = 10.0
    canvas = draw_matches(res.left_rectified, right, sparse)
    assert canvas.shape == (syn.H, 2 * syn.W, 3)
    assert (canvas[60, 100] != np.hstack([res.left_rectified, right])[60, 100]).any()


@pytest.mark.parametrize(
    ("shape", "method", "said"),
    [
        (
            (300, 2, 3),
            "opencv-sgbm",
            # the width needed (it said neither that nor a range that fits: OpenCV has none)
            "image too narrow for opencv-sgbm: 2 px wide, and its disparity range (a multiple "
            "of 16, at least 16 px) needs images at least 17 px wide",
        ),
        # baselines' words: the height StereoBM's block needs (OpenCV's "(-211: ...
        # SADWindowSize must be odd, ... not larger than image width or height")
        (
            (2, 300, 3),
            "opencv-bm",
            "StereoBM's 15 px block needs images at least 16 px high, got 2",
        ),
    ],
)
def test_opencv_methods_on_a_pair_they_cannot_take_say_why(shape, method, said):
    """An OpenCV reference method on a pair too small for it: the page showed OpenCV's own
    message, "OpenCV(5.x) /io/opencv/modules/core/src/alloc.cpp:73: error: (-4:Insufficient
    memory) Failed to allocate 18446744073709551600 bytes" for a 2 px wide pair."""
    from stereovision.gui.app import compute_view

    img = np.random.default_rng(0).integers(0, 255, shape, dtype=np.uint8)
    with pytest.raises(ValueError) as err:
        compute_view(img, img, None, method)
    assert str(err.value).startswith(said) and "/opencv/" not in str(err.value)


def test_an_opencv_method_on_a_pair_too_narrow_for_any_of_its_ranges_says_so():
    """OpenCV's ranges are multiples of 16: a 12 px wide pair with no max disparity was told
    "disparity range 16 is not smaller than the image width 12 ..., or give a max_disparity
    below 12", a range nobody gave, and the max_disparity it advised (8) got the same words.
    It says the width the method needs, whatever range is given."""
    from stereovision.gui.app import compute_view

    rng = np.random.default_rng(0)
    for width, method, need in (
        (12, "opencv-sgbm", 17),
        (16, "opencv-bm", 30),
        (20, "opencv-bm", 30),
    ):
        img = rng.integers(0, 255, (40, width, 3), dtype=np.uint8)
        for max_disparity in (None, 8, 40):
            with pytest.raises(ValueError) as err:
                compute_view(
                    img, np.roll(img, -2, axis=1), None, method, max_disparity=max_disparity
                )
            said = str(err.value)
            if width == 20 and max_disparity != 40:  # baselines' own words, unchanged
                assert said.startswith("StereoBM's 15 px block and a 16 px"), said
                continue
            assert said.startswith(f"image too narrow for {method}: {width} px wide"), said
            assert said.endswith(f"images at least {need} px wide"), said
            assert "max_disparity" not in said, said


def test_a_sparse_method_on_a_pair_too_narrow_for_the_automatic_range_says_so():
    """A sparse method on a 12 px wide pair with no max disparity: the page said "disparity
    range 16 is not smaller than the image width 12", a range nobody gave (the GUI's own
    estimate, passed to match as given), where the dense methods say the pair is too narrow.
    It says what depth_map says now."""
    from stereovision import depth_map
    from stereovision.gui.app import compute_view

    img = np.random.default_rng(0).integers(0, 255, (20, 12, 3), dtype=np.uint8)
    with pytest.raises(ValueError) as dense:
        depth_map(img, np.roll(img, -2, axis=1), None)
    for method in ("hopfield", "mcgm"):
        with pytest.raises(ValueError) as err:
            compute_view(img, np.roll(img, -2, axis=1), None, method)
        assert str(err.value) == str(dense.value), method
        assert str(err.value).startswith("image too narrow for stereo matching: 12 px wide")


def test_the_depth_picture_says_the_distances_of_its_colours():
    """The depth picture had no key ("depth (near = warm)"), and its colour scale changes with
    every pair: its caption now gives the distances at its two ends, those of its colour map
    (1st and 99th percentile of 1 / depth), so that a colour can be read in metres."""
    from stereovision.calibration import Calibration
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import NO_DEPTH_CAPTION, compute_view

    cones = bundled_data_dir() / "cones"
    left, right = (cv2.imread(str(cones / f"{s}.png")) for s in ("left", "right"))
    view = compute_view(left, right, Calibration.from_file(cones / "calib.txt"), "fast")
    got = re.fullmatch(r"depth: red ([0-9.]+)\xa0m … blue ([0-9.]+)\xa0m", view.depth_caption)
    assert got is not None, view.depth_caption
    inv = 1.0 / view.result.depth[np.isfinite(view.result.depth)]
    near, far = 1.0 / np.percentile(inv, 99), 1.0 / np.percentile(inv, 1)
    assert float(got.group(1)) == pytest.approx(near, abs=0.006) and near < 3.0
    assert float(got.group(2)) == pytest.approx(far, abs=0.006) and far > 4.0
    assert compute_view(left, right, None, "fast").depth_caption == NO_DEPTH_CAPTION  # no depth

    app = _scene_app("test-depth-caption", [bundled_data_dir()])
    app._load_scene(cones)
    _run(app, app.recompute)
    assert app.state.depth_caption == view.depth_caption


def test_the_depth_picture_of_a_pair_without_calibration_says_why_it_is_black():
    """Without a calibration (a Middlebury scene, an image folder) the depth picture was black
    under the caption "depth (near = warm)", which promises colours: it now says there is no
    depth without a calibration, in both units."""
    from stereovision.gui.app import compute_view

    left, right = (cv2.imread(str(CONES / f"{s}.png")) for s in ("left", "right"))
    view = compute_view(left, right, None, "fast")
    assert view.result.depth is None
    for unit in ("m", "ft"):
        assert view.texts(unit)[0] == "depth: none without a calibration", view.texts(unit)


def test_the_disparity_picture_says_the_pixels_of_its_colours():
    """The disparity picture was captioned "disparity", with no key to its colours (0 px to the
    99th percentile, which changes with every pair). Its caption now gives both ends; the
    picture itself is the one it was."""
    from stereovision.cli import colorize
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import DISPARITY_CAPTION, _data_url, compute_view

    cones = bundled_data_dir() / "cones"
    left, right = (cv2.imread(str(cones / f"{s}.png")) for s in ("left", "right"))
    view = compute_view(left, right, None, "fast")
    got = re.fullmatch(r"disparity: blue 0\xa0px … red ([0-9.]+)\xa0px", view.disparity_caption)
    assert got is not None, view.disparity_caption
    d = view.result.disparity
    assert float(got.group(1)) == pytest.approx(np.percentile(d[np.isfinite(d)], 99), abs=0.05)
    assert 40 < float(got.group(1)) < 70  # cones: up to about 55 px
    assert view.disparity_url == _data_url(colorize(d, lo=0.0))
    empty = compute_view(np.zeros((60, 80, 3), np.uint8), np.zeros((60, 80, 3), np.uint8),
                         None, "opencv-bm", max_disparity=16)  # fmt: skip
    assert empty.disparity_caption == DISPARITY_CAPTION

    app = _scene_app("test-disparity-caption", [bundled_data_dir()])
    app._load_scene(cones)
    _run(app, app.recompute)
    assert app.state.disparity_caption.startswith("disparity: blue 0\xa0px … red ")


def test_a_map_of_negative_disparities_is_captioned_by_its_colours_ends(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The page coloured the disparity from 0 px up to the 99th percentile, both ends given:
    for a map below 0 px (a swapped pair's) the picture was one colour and its caption read
    "blue 0 px … red -1.4 px". Its ends are now colorize's own (colour_range: the map's 1st
    and 99th percentiles there), the caption saying them."""
    import stereovision.depth
    from stereovision.cli import colorize
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import _data_url, compute_view

    real = stereovision.depth.depth_map

    def below_zero(*args: Any, **kwargs: Any) -> Any:
        res = real(*args, **kwargs)
        res.disparity = -1.0 - res.disparity  # every finite value below 0 px
        return res

    monkeypatch.setattr(stereovision.depth, "depth_map", below_zero)
    cones = bundled_data_dir() / "cones"
    left, right = (cv2.imread(str(cones / f"{s}.png")) for s in ("left", "right"))
    view = compute_view(left, right, None, "fast")
    d = view.result.disparity
    lo, hi = (float(np.percentile(d[np.isfinite(d)], q)) for q in (1, 99))
    assert lo < hi < 0
    assert view.disparity_caption == f"disparity: blue {lo:.1f}\xa0px … red {hi:.1f}\xa0px"
    assert view.disparity_url == _data_url(colorize(d, lo=lo, hi=hi))
    assert view.disparity_url == _data_url(colorize(d, lo=0.0))  # the file's colours
    assert len(np.unique(colorize(d, lo=lo, hi=hi).reshape(-1, 3), axis=0)) > 50


def test_a_number_and_its_unit_are_never_broken_apart():
    """On a narrow page the statistics line broke "median depth 3.50 m" as "3.50" at the end
    of a line and "m" alone on the next. The page's texts hold a non-breaking space between
    each number and its unit (the captions, the statistics, their warnings, in both units)."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import compute_view, nowrap_units
    from stereovision.io import load_scene

    scene = load_scene(bundled_data_dir() / "cones")
    view = compute_view(scene.left, scene.right, scene.calib, "opencv-bm", max_disparity=40)
    breakable = re.compile(r"[0-9∞] (px|m|ft|s|%)(?![A-Za-z])")
    for unit in ("m", "ft"):
        caption, stats = view.texts(unit)
        for text in (caption, stats, view.disparity_caption):
            assert not breakable.search(text), text
    assert f"median depth {view.median_depth:.2f}\xa0m" in view.texts("m")[1]
    assert "searched as 48\xa0px" in view.stats
    assert nowrap_units("2 matches in 3 s, 1 m") == "2 matches in 3\xa0s, 1\xa0m"
    # Find floor's line: its angles too ("pitch -0.40" then "deg" alone on a narrow page)
    assert nowrap_units("pitch -0.40 deg, roll 2 degrees") == "pitch -0.40\xa0deg, roll 2 degrees"


def test_an_unrectified_pair_is_advised_in_the_page_s_words():
    """An unrectified pair (an image folder of raw camera pairs) put the library's advice on the
    page: "calib=Calibration.from_file(...)" and "stereovision.uncalibrated.rectify_uncalibrated",
    Python calls a user of the page cannot make. The page names its own ways: a calibration
    (the scene's calib.txt or --calib) and its Rectify button."""
    from stereovision.gui.app import compute_view

    left = cv2.imread(str(CONES / "left.png"))
    right = np.roll(cv2.imread(str(CONES / "right.png")), 30, axis=0)  # rows 30 px apart
    stats = compute_view(left, right, None, "fast").stats
    assert "look unrectified" in stats, stats
    assert "Calibration.from_file" not in stats and "stereovision.uncalibrated" not in stats
    assert "--calib" in stats and "the Rectify button" in stats, stats


def test_the_unit_toggle_shows_lengths_in_feet():
    """Depth was shown in metres only. The unit toggle (metres by default) shows the depth
    caption, the median depth and the 3-D translation sliders in feet; the sliders' values are
    converted, so the view does not move, and back in metres they read as before."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-units", [bundled_data_dir()])
    assert app.state.unit == "m"
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    metres = app.state.depth_caption, app.state.stats
    near_m, far_m = (float(v) for v in re.findall(r"([0-9.]+)\xa0m", metres[0]))
    median_m = float(re.search(r"median depth ([0-9.]+)\xa0m", metres[1]).group(1))
    app.state.forward = 1.0
    app._apply_camera()
    pose = app.plotter.camera.position
    app._on_unit(unit="ft")
    got = re.fullmatch(
        r"depth: red ([0-9.]+)\xa0ft … blue ([0-9.]+)\xa0ft", app.state.depth_caption
    )
    assert got is not None, app.state.depth_caption
    assert float(got.group(1)) == pytest.approx(near_m / 0.3048, abs=0.02)
    assert float(got.group(2)) == pytest.approx(far_m / 0.3048, abs=0.02)
    median_ft = float(re.search(r"median depth ([0-9.]+)\xa0ft", app.state.stats).group(1))
    assert median_ft == pytest.approx(median_m / 0.3048, abs=0.02)
    assert not re.search(r"[0-9][ \xa0]m\b", app.state.stats)
    assert app.state.forward == pytest.approx(3.281) and app.state.translation_range == 16.4
    np.testing.assert_allclose(app.plotter.camera.position, pose, atol=1e-3)  # did not move
    _run(app, app.recompute)  # a new result comes in the unit on show
    assert "\xa0ft … " in app.state.depth_caption
    app._on_unit(unit="m")
    assert app.state.depth_caption == metres[0] and app.state.forward == pytest.approx(1.0)
    app._on_unit(unit="furlong")
    assert app.state.error == "unit: expected one of ['m', 'ft'], got 'furlong'"
    assert app.state.unit == "m"


def test_the_unit_toggle_keeps_the_translations_inside_the_feet_sliders_range():
    """The translation sliders' +-5 m are shown as +-16.4 ft, yet the toggle converted 5 m to
    16.404 ft (4.999 m to 16.401 ft): values past the feet sliders' range, the thumb stuck at
    its end. They are clamped to the range shown, as :func:`sliders_from_pose` clamps, and the
    view does not move (the 1.3 mm the clamp takes is no camera move)."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-units-range", [bundled_data_dir()])
    app.state.forward, app.state.up, app.state.right = 5.0, -4.999, 4.998
    app._apply_camera()
    pose = app.plotter.camera.position
    app._on_unit(unit="ft")
    assert (app.state.translation_range, app.state.translation_step) == (16.4, 0.1)
    assert (app.state.forward, app.state.up, app.state.right) == (16.4, -16.4, 16.398)
    np.testing.assert_allclose(app.plotter.camera.position, pose, atol=1e-9)  # did not move
    app._on_unit(unit="m")
    assert (app.state.translation_range, app.state.translation_step) == (5.0, 0.05)
    assert (app.state.forward, app.state.up, app.state.right) == (4.999, -4.999, 4.998)


def test_view_texts_say_no_far_end_as_infinity_and_refuse_an_unknown_unit():
    """The depth caption's far end is infinite when the colours reach no depth: it reads
    "∞", not "inf ft"; an unknown unit is a ValueError naming it, with or without depths."""
    from stereovision.gui.app import ViewData

    view = ViewData(
        None, "", "", "", "", "", None, None, "0.3 s", "", depth_ends=(0.6096, math.inf)
    )
    assert view.texts("ft")[0] == "depth: red 2.00\xa0ft … blue ∞"
    assert view.texts()[0] == "depth: red 0.61\xa0m … blue ∞"
    for v in (view, ViewData(None, "", "", "", "", "", None, None, "0.3 s", "")):
        with pytest.raises(ValueError, match="unit: expected one of \\['m', 'ft'\\], got 'yd'"):
            v.texts("yd")
        # a NumPy string by its text, not "got np.str_('yd')" (known_unit's message)
        with pytest.raises(ValueError, match=r"^unit: expected one of \['m', 'ft'\], got 'yd'$"):
            v.texts(np.str_("yd"))


def test_the_max_disparity_field_is_applied_and_checked():
    """The disparity range could not be set on the page. Its field is empty for automatic (the
    pair's own range, shown as its hint); a number is applied on Enter, and a bad one is said
    on the page without computing anything."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import parse_max_disparity

    app = _scene_app("test-max-disp", [bundled_data_dir()])
    spawned: list = []
    app._spawn = spawned.append
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    auto = app.max_disparity
    assert app.state.max_disp_hint == f"auto: {auto} px at full size"
    assert f"disparities 0–{auto}\xa0px" in app.state.stats
    for typed, said in (
        (
            "abc",
            "max disparity: expected a whole number of pixels above 0 (empty: automatic), "
            "got 'abc'",
        ),
        (
            "-5",
            "max disparity: expected a whole number of pixels above 0 (empty: automatic), got '-5'",
        ),
        (
            "2.5",
            "max disparity: expected a whole number of pixels above 0 (empty: automatic), "
            "got '2.5'",
        ),
        ("450", "max disparity 450 px is not smaller than the pair's width 450 px"),
    ):
        app.state.max_disp = typed
        app.apply_max_disparity()
        assert app.state.error == said and spawned == [], typed
    app.state.max_disp = " 32 "
    app.apply_max_disparity(True)  # focused: nothing yet
    assert spawned == []
    app.apply_max_disparity(False)  # left the field
    assert app.state.error == "" and len(spawned) == 1
    _run(app, spawned.pop)
    assert "disparities 0–32\xa0px" in app.state.stats and app.state.computations == 2
    app.apply_max_disparity()  # Enter again: the same value, nothing to compute
    assert spawned == []
    app.state.max_disp = "auto"
    app.apply_max_disparity()
    _run(app, spawned.pop)
    assert f"disparities 0–{auto}\xa0px" in app.state.stats
    assert parse_max_disparity(None, 10) is None
    # A refused value stayed in the field over a new pair, its error gone at the computation's
    # end, the pair at another range: the field now shows the range in use (empty: automatic)
    app.state.max_disp = "600"
    app.apply_max_disparity()
    assert app.state.error == "max disparity 600 px is not smaller than the pair's width 450 px"
    app._load_scene(bundled_data_dir() / "cones")  # a new pair
    _run(app, app.recompute)
    assert (app.state.error, app.state.max_disp) == ("", "")
    assert f"disparities 0–{auto}\xa0px" in app.state.stats
    app.chosen_max_disparity, app._max_disp_refused = 32, "refused"  # a range typed before
    app._max_disp_back()
    assert app.state.max_disp == "32" and app._max_disp_refused is None


def test_the_max_disparity_field_is_searched_as_typed():
    """The page rounded the field up to a multiple of 16 px (40 searched 48 px) although
    depth_map searches any range: a rounding from the GUI's first commit that only OpenCV's
    matchers need. The library's methods now search the value as typed (scaled to a lower
    resolution, up to a whole pixel, kept below the width and said so); the OpenCV reference
    methods still round up, said in the statistics. 449 px at width 450 is taken."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import parse_max_disparity

    app = _scene_app("test-max-disp-typed", [bundled_data_dir()])
    spawned: list = []
    app._spawn = spawned.append
    app._load_scene(bundled_data_dir() / "cones")
    app.state.max_disp = "40"
    app.apply_max_disparity()
    _run(app, spawned.pop)
    assert app.state.error == "" and app.view.result.max_disparity == 40
    assert " · disparities 0–40\xa0px · " in app.state.stats and "warning" not in app.state.stats
    app.state.method = "opencv-bm"
    _run(app, app.recompute)
    assert app.state.error == "" and " · disparities 0–48\xa0px · " in app.state.stats
    assert (
        "warning: max disparity 40\xa0px searched as 48\xa0px (OpenCV's matchers take multiples of "
        "16\xa0px)" in app.state.stats
    )
    assert parse_max_disparity("449", 450) == 449
    with pytest.raises(ValueError, match=r"^max disparity 450 px is not smaller than the pair"):
        parse_max_disparity("450", 450)
    app.state.method = "fast"
    app.state.max_disp = "449"
    app.apply_max_disparity()
    _run(app, spawned.pop)
    assert app.state.error == "" and "disparities 0–449\xa0px" in app.state.stats
    app.state.resolution = "320"  # 449 x 320 / 450 = 319.3: up to 320, the width
    _run(app, app.recompute)
    assert app.state.error == "" and app.view.result.disparity.shape[1] == 320
    assert "disparities 0–319\xa0px" in app.state.stats
    assert "warning: max disparity 320\xa0px at width 320 searched as 319\xa0px" in app.state.stats


def test_opencv_bm_searches_no_range_its_block_has_no_room_for():
    """opencv-bm with a max disparity near the width (440 on the 450 px cones, searched as 448)
    showed StereoBM's garbage: disparities up to 2041 px, density 49-75 % (another each run),
    a median depth of 0.1 m. Its range is kept where the 15 px block fits (432 px), said in
    the statistics; opencv-sgbm keeps the range below the width, as before."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import compute_view
    from stereovision.io import load_scene

    scene = load_scene(bundled_data_dir() / "cones")
    view = compute_view(scene.left, scene.right, scene.calib, "opencv-bm", max_disparity=440)
    assert view.result.max_disparity == 432
    assert not (view.result.disparity >= 432).any()  # NaN compares False
    assert view.stats.endswith(
        "warning: max disparity 448\xa0px at width 450 searched as 432\xa0px (opencv-bm's "
        "15\xa0px block must fit beside it)"
    )
    sgbm = compute_view(scene.left, scene.right, scene.calib, "opencv-sgbm", max_disparity=440)
    assert sgbm.result.max_disparity == 448


def test_a_max_disparity_scaled_to_a_whole_pixel_is_not_rounded_up_past_it():
    """159 px at width 424 is 120 px at width 320 exactly; scaled in floats it was
    120.00000000000001 px, searched as 121 px (and said as '121 px searched as 128 px' by
    the OpenCV methods)."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import compute_view

    cones = bundled_data_dir() / "cones"
    left, right = (cv2.imread(str(cones / f"{s}.png"))[:, :424] for s in ("left", "right"))
    view = compute_view(left, right, None, "fast", width=320, max_disparity=159)
    assert view.result.max_disparity == 120
    view = compute_view(left, right, None, "opencv-bm", width=320, max_disparity=159)
    assert "warning: max disparity 120\xa0px searched as 128\xa0px" in view.stats


def test_a_range_too_wide_for_a_pair_16_px_wide_is_refused_not_narrowed():
    """A range reaching the width is narrowed below it (with a note) only on a pair wider than
    16 px; on a narrower one it is depth_map's to refuse, in its words (narrowing there too
    survived a mutation audit)."""
    from stereovision.gui.app import compute_view

    img = np.random.default_rng(0).integers(0, 255, (20, 12, 3), dtype=np.uint8)
    with pytest.raises(ValueError, match=r"^disparity range 12 is not smaller than the image"):
        compute_view(img, img, None, "gabor", max_disparity=12)
    wide = np.random.default_rng(0).integers(0, 255, (20, 17, 3), dtype=np.uint8)
    view = compute_view(wide, wide, None, "gabor", max_disparity=17)
    assert view.result.max_disparity == 16
    assert "warning: max disparity 17\xa0px at width 17 searched as 16\xa0px" in view.stats


def test_a_dense_map_with_few_matches_draws_them_and_the_median_depth_is_the_median():
    """A dense method's map below SPARSE_DENSITY has its matches drawn between the images; the
    statistics' median depth is the points' median, not their mean (both survived a mutation
    audit)."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import compute_view
    from stereovision.io import load_scene

    flat = np.full((60, 80, 3), 128, np.uint8)
    view = compute_view(flat, flat, None, "fast", max_disparity=16)
    assert view.result.density == 0.0 and view.matches_url.startswith("data:image/jpeg")
    scene = load_scene(bundled_data_dir() / "cones")
    view = compute_view(scene.left, scene.right, scene.calib, "fast", width=320)
    assert view.matches_url == ""
    z = view.result.points[:, 2]
    assert abs(np.median(z) - np.mean(z)) > 0.01  # the two differ on this scene
    assert view.median_depth == pytest.approx(float(np.median(z)))
    assert f"median depth {np.median(z):.2f}\xa0m" in view.stats


@pytest.mark.parametrize("method", ["gabor", "fused"])
def test_progress_goes_forward_and_says_what_runs(method):
    """The status read "prepare done" during the whole matching (most of the time: it looked
    stalled), and gabor's refinement, missing from the stages' table, put the bar back from
    75 % to 50 %."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import compute_view

    cones = bundled_data_dir() / "cones"
    left, right = (cv2.imread(str(cones / f"{s}.png")) for s in ("left", "right"))
    said: list = []
    compute_view(left, right, None, method, progress=lambda pct, text: said.append((pct, text)))
    percents = [p for p, _ in said]
    assert percents == sorted(percents) and percents[-1] == 92, said
    assert (20, f"{method}: prepare done, matching…") in said


def test_compute_view_shows_the_swapped_warning(data_dir):
    """A swapped pair: the page's statistics line carries the library's warning (once), and the
    pair given the right way round carries none."""
    from stereovision.gui.app import compute_view
    from stereovision.io import load_scene

    s = load_scene(data_dir / "middlebury2003" / "cones")
    swapped = compute_view(s.right, s.left, None, "gabor")
    assert swapped.stats.count("warning: the left and right images look swapped") == 1
    assert "warning" not in compute_view(s.left, s.right, None, "gabor").stats


def test_app_controllers_report_errors_and_compute(tmp_path, monkeypatch):
    """The page's controllers in-process (no browser): errors land in ``state.error``."""
    import asyncio

    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import StereoApp

    app = StereoApp(
        get_server("test-controllers", client_type="vue3"),
        AllowedFolders([bundled_data_dir()]),
        bundled_data_dir() / "cones",
    )
    app.state.left_file, app.state.right_file = "/etc/passwd", "cones/right.png"
    app.load_files()
    assert app.state.error == "path outside the allowed folders: /etc/passwd"
    app.state.cloud_path = "cones/left.png"
    app.open_cloud()
    assert app.state.error.startswith("not a point cloud file")
    _capture(app)
    assert app.state.error.startswith("no camera open")
    # an emptied field sends None (a TypeError the page never showed)
    app.state.left_file, app.state.cloud_path = None, None
    app.load_files()
    assert app.state.error == "empty or invalid path"
    app.state.error = ""
    app.open_cloud()
    assert app.state.error == "empty or invalid path"
    app._on_scene(scene="../../../../etc")
    assert app.state.error == "path outside the allowed folders: ../../../../etc"
    assert [s["title"] for s in app.state.scenes] == ["data/cones"]

    # computed by hand below (a spawned computation as well would supersede these)
    app._spawn = lambda coro: coro.close()

    async def run() -> None:
        app._lock = asyncio.Lock()
        app.state.method = "opencv-bm"
        app.state.left_file, app.state.right_file = "cones/left.png", "cones/right.png"
        app.load_files()  # no --calib: disparity only, the 3-D panel says why it is empty
        await app.recompute()

    asyncio.run(run())
    assert app.state.error == ""
    assert app.state.computations == 1
    asyncio.run(app.check_rows())
    assert app.state.rows_label.startswith("rectification ok: median |dy| 0.0")

    async def reload() -> None:
        app.load_files()  # a new pair: the old verdict goes

    asyncio.run(reload())
    assert app.state.rows_label == ""
    assert app.state.stats.startswith("opencv-bm · 450×375")
    assert "No calibration" in app.state.message_3d

    # A pair that fails to compute: the page keeps the previous one, and so does the app (Check
    # rows and Find floor used to work on the failed pair the page did not show).
    tiny = np.zeros((8, 8, 3), np.uint8)
    app.pair, app.state.source_label = (tiny, tiny), "tiny files"

    async def fails() -> None:
        await app.recompute()

    asyncio.run(fails())
    assert app.state.error.endswith("(the page still shows the previous pair)")
    assert app.pair[0].shape == (375, 450, 3) and app.state.source_label == "files"
    assert app.state.computations == 1

    # A pair too large for the machine's memory: the census map's check refuses it, and the page
    # says so instead of the task dying.
    from stereovision.matching import sgm

    async def too_big() -> None:
        app.state.method = "fused"
        await app.recompute()

    # The buffers the extension keeps from earlier calls count as available: none here.
    monkeypatch.setattr(sgm, "_available_bytes", lambda: 1000)
    monkeypatch.setattr(sgm._core, "kept_memory", lambda: ((0, 0), 0))
    asyncio.run(too_big())
    assert app.state.error.startswith("the census semi-global map needs about")
    assert app.state.computations == 1


def test_files_at_another_resolution_keep_the_calibration_and_the_view_mode(data_dir, tmp_path):
    """Files twice the calibration's size are matched with it scaled (it was dropped, and the
    page asked for --calib); another shape says why there is no depth. A new result is drawn
    as the points / surface toggle shows (it went back to the surface)."""
    import asyncio

    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.calibration import Calibration
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import StereoApp

    cones = bundled_data_dir() / "cones"  # with its calib.txt
    for side in ("left", "right"):
        img = cv2.imread(str(cones / f"{side}.png"))
        cv2.imwrite(str(tmp_path / f"big_{side}.png"), cv2.resize(img, None, fx=2, fy=2))
        cv2.imwrite(str(tmp_path / f"wide_{side}.png"), cv2.resize(img, (900, 375)))
    app = StereoApp(
        get_server("test-files-calib", client_type="vue3"),
        AllowedFolders([tmp_path]),
        cones,
        calib=Calibration.from_file(cones / "calib.txt"),
    )
    app._spawn = lambda coro: coro.close()  # computed by hand below

    async def load(prefix: str) -> None:
        app._lock = asyncio.Lock()
        app.state.left_file = str(tmp_path / f"{prefix}_left.png")
        app.state.right_file = str(tmp_path / f"{prefix}_right.png")
        app.load_files()
        await app.recompute()

    app.state.method = "fast"
    app.state.view_mode = "points"
    asyncio.run(load("big"))
    assert app.state.error == "" and app.calib is not None
    assert "No calibration" not in app.state.message_3d and "median depth" in app.state.stats
    shown = app.plotter.actors["scene"].GetMapper().GetInput()
    assert shown.GetNumberOfPolys() == 0 and shown.GetNumberOfPoints() > 1000  # points, no faces
    asyncio.run(load("wide"))
    assert app.calib is None and "another aspect ratio" in app.state.rows_label
    # --calib was given: the 3-D panel says it does not fit (it said "give --calib")
    assert app.state.message_3d == (
        "No calibration: the --calib calibration does not fit these images (disparity only)."
    )


def test_a_pair_exactly_twice_as_wide_as_high_stays_side_by_side(tmp_path):
    """``WIDE_ASPECT``'s boundary (a ``>=`` for its ``>`` survived a mutation audit): images
    of exactly 2:1 (one camera's picture, e.g. 320x160) are shown side by side, 2:1 and a pixel
    wider (a KITTI-like strip) one above the other, when loaded and when their result is shown."""
    import asyncio

    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import WIDE_ASPECT, StereoApp

    assert WIDE_ASPECT == 2.0
    cones = bundled_data_dir() / "cones"
    for name, size in (("two", (320, 160)), ("wider", (321, 160))):
        for side in ("left", "right"):
            img = cv2.imread(str(cones / f"{side}.png"))
            cv2.imwrite(str(tmp_path / f"{name}_{side}.png"), cv2.resize(img, size))
    app = StereoApp(
        get_server("test-wide-pair", client_type="vue3"), AllowedFolders([tmp_path]), cones
    )
    app._spawn = lambda coro: coro.close()  # computed by hand below
    app.state.method = "fast"
    seen: list[bool] = []
    real = app._publish

    def publish(view: Any) -> None:
        seen.append(bool(app.state.wide_pair))  # as loaded, before the result is shown
        real(view)

    app._publish = publish  # type: ignore[method-assign]

    async def load(prefix: str) -> None:
        app._lock = asyncio.Lock()
        app.state.left_file = str(tmp_path / f"{prefix}_left.png")
        app.state.right_file = str(tmp_path / f"{prefix}_right.png")
        app.load_files()
        await app.recompute()

    asyncio.run(load("two"))
    assert app.state.error == "" and app.state.wide_pair is False and seen == [False]
    asyncio.run(load("wider"))
    assert app.state.error == "" and app.state.wide_pair is True and seen == [False, True]


def test_a_later_success_clears_an_error_and_a_scene_can_be_chosen_again(data_dir):
    """A failed camera open left the toolbar on "error" while the old results stayed; a later
    successful Check rows now clears it. Choosing the scene on show again after files were
    loaded reloaded nothing: trame reports only a changed choice."""

    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import StereoApp

    cones = bundled_data_dir() / "cones"
    app = StereoApp(
        get_server("test-error-clears", client_type="vue3"),
        AllowedFolders([bundled_data_dir()]),
        cones,
    )
    app.state.method = "fast"
    app._spawn = lambda coro: coro.close()  # no server loop here: computed by hand below

    app._on_scene(scene=str(cones))
    _run(app, app.recompute)
    assert app.state.status == "ready" and app.state.computations == 1
    app.state.cam_left, app.state.cam_right = "cones/none.mp4", "cones/none.mp4"
    app.open_cameras()
    assert app.state.status == "error" and app.state.error.startswith("no such file")
    _run(app, app.check_rows)
    assert app.state.status == "ready" and app.state.error == ""
    assert app.state.rows_label.startswith("rectification ok")

    app.state.scene = str(cones)
    app.state.left_file, app.state.right_file = "cones/right.png", "cones/right.png"
    app.load_files()
    assert app.state.source_label == "files" and app.state.scene is None
    assert app.pair[0] is app.pair[1] or np.array_equal(app.pair[0], app.pair[1])
    app._on_scene(scene=str(cones))
    assert app.state.source_label == "scene data/cones"
    assert not np.array_equal(app.pair[0], app.pair[1])


def _run_clicked(app, click: Callable[[], None]) -> None:
    """The page's ``click`` ("Open", "Capture"), and the open or read it spawns run to its end
    (no server loop here); the computation that follows is spawned as the test's ``_spawn``
    has it."""
    import asyncio

    spawned: list[Any] = []
    keep = app._spawn
    app._spawn = spawned.append
    try:
        click()
    finally:
        app._spawn = keep
    for coro in spawned:
        asyncio.run(coro)


def _open_cameras(app) -> None:
    """The page's "Open", run to its end (:func:`_run_clicked`)."""
    _run_clicked(app, app.open_cameras)


def _capture(app) -> None:
    """The page's "Capture", run to its end (:func:`_run_clicked`)."""
    _run_clicked(app, app.capture)


def _play(app) -> None:
    """The page's image-folder "Play", its first pair read to its end (:func:`_run_clicked`)."""
    _run_clicked(app, app.open_pair_folder)


def _start(app) -> None:
    """The page's start-up with cameras given (``--left``/``--right``), their first read run to
    its end (:func:`_run_clicked`)."""
    _run_clicked(app, app._on_ready)


def _queue_spawns(app, tasks: list) -> None:
    """Inside a running loop: a lock of that loop, and the computations the app spawns queued
    in ``tasks`` as futures (to be awaited by the test)."""
    import asyncio

    app._lock = asyncio.Lock()
    app._spawn = lambda coro: tasks.append(asyncio.ensure_future(coro))


def _scene_app(name: str, folders: list[Path], **kw):
    """A StereoApp on the bundled cones, its tasks run by hand (no server loop here)."""
    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import StereoApp

    app = StereoApp(
        get_server(name, client_type="vue3"),
        AllowedFolders(folders),
        bundled_data_dir() / "cones",
        **kw,
    )
    app.state.method = "fast"
    app._spawn = lambda coro: coro.close()
    return app


def _tiny_scene(folder: Path) -> None:
    """An 8x8 black pair in ``folder``: it loads, then fails to compute."""
    folder.mkdir()
    for side in ("left", "right"):
        cv2.imwrite(str(folder / f"{side}.png"), np.zeros((8, 8, 3), np.uint8))


def _chooser(app: Any, root: Path) -> Any:
    """``choose(name)``: the scene ``root/name`` chosen in the page's scene list."""

    def choose(name: str) -> None:
        app.state.scene = str(root / name)
        app._on_scene(scene=str(root / name))

    return choose


def test_the_demo_scene_is_the_scene_list_choice_at_start_up(tmp_path):
    """At start-up the page showed "scene data/cones" above a scene list whose choice was an
    empty entry (the state's "" is a chosen value to the select). The demo's entry is now the
    choice; a pair from elsewhere clears it to None (no choice, the select's label alone)."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-demo-choice", [bundled_data_dir(), tmp_path])
    assert app.state.scene is None
    app._on_ready()
    demo = str((bundled_data_dir() / "cones").resolve())
    assert app.state.error == "" and app.state.source_label == "scene data/cones"
    assert app.state.scene == demo
    assert {i["value"]: i["title"] for i in app.state.scenes}[demo] == "data/cones"
    app._other_source()
    assert app.state.scene is None and app._scene == ""


def _run(app, action) -> None:
    import asyncio

    async def go() -> None:
        app._lock = app._lock or asyncio.Lock()
        await action()

    asyncio.run(go())


def test_a_computed_pair_hands_its_memory_back():
    """The server kept what a pair's computation left: after a 3600 x 3000 pair, 11-12 GB
    resident. Each computation now ends with release_memory (the kept buffers and glibc's free
    pages go back)."""
    from stereovision import _core
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-release", [bundled_data_dir()])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    assert app.state.error == "" and app.state.computations == 1
    assert _core.kept_memory() == ((0, 0), 0)


def test_an_opened_cloud_stays_shown_in_both_view_modes(tmp_path, monkeypatch):
    """After "Open" of a PLY the points / surface toggle swapped in the scene's points while the
    caption still named the file. The file now stays on show in both modes (it has no surface:
    the caption says so), until the next computed pair replaces it. A new pair that computes,
    then fails, leaves it on show under its own caption: it was said to be "the previous one"
    meanwhile, and one opened meanwhile lost its caption to the previous pair's."""
    import asyncio

    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir

    n = 500
    pts = np.random.default_rng(0).uniform([-1, -1, 2], [1, 1, 4], (n, 3)).astype("<f4")
    header = f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\n"
    header += "property float x\nproperty float y\nproperty float z\nend_header\n"
    (tmp_path / "blob.ply").write_bytes(header.encode() + pts.tobytes())
    app = _scene_app("test-cloud-modes", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")  # with its calibration: a 3-D scene
    _run(app, app.recompute)

    def shown() -> tuple[int, int]:
        poly = app.plotter.actors["scene"].GetMapper().GetInput()
        return poly.GetNumberOfPoints(), poly.GetNumberOfPolys()

    assert shown()[0] > 10 * n and shown()[1] > 0  # the scene's surface
    app.state.cloud_path = str(tmp_path / "blob.ply")
    app.open_cloud()
    assert app.state.error == ""
    label = app.folders.label((tmp_path / "blob.ply").resolve())
    assert shown() == (n, 0)
    no_surface = " (a point cloud has no surface: shown as points)"
    assert app.state.message_3d == f"{label}: {n} points{no_surface}"
    for mode in ("points", "surface", "points"):
        app.state.view_mode = mode
        app._on_view_mode()
        assert shown() == (n, 0), mode
        assert app.state.message_3d.startswith(f"{label}: {n} points"), mode
    assert app.state.message_3d == f"{label}: {n} points"
    _run(app, app.recompute)  # a new pair: its scene replaces the file, drawn as points
    assert shown()[0] > 10 * n and shown()[1] == 0
    assert "blob" not in app.state.message_3d
    monkeypatch.setattr(gui_app, "compute_view", _fails)
    during: list[str] = []

    async def a_new_pair_fails(open_before: bool) -> None:
        app._lock = asyncio.Lock()
        if open_before:
            app.open_cloud()
        app._load_scene(bundled_data_dir() / "cones")  # another pair: computed, then fails
        task = asyncio.ensure_future(app.recompute())
        await asyncio.sleep(0)  # it computes
        if open_before:
            during.append(app.state.message_3d)
        else:
            app.open_cloud()
        await task

    for open_before in (False, True):
        asyncio.run(a_new_pair_fails(open_before))
        assert app.state.error == "boom (the page still shows the previous pair)", open_before
        assert shown() == (n, 0) and app.state.message_3d == f"{label}: {n} points", open_before
    assert during == [f"{label}: {n} points"]


def test_a_big_cloud_is_shown_as_a_capped_subset_and_says_so(tmp_path, monkeypatch):
    """The 3-D view drew every point: a 10 M point PLY took 12.5 s to its first frame (2.7 GB).
    A cloud over the cap (an opened file, or a computed pair in points mode) is drawn as an
    evenly spaced subset, the caption says how many of how many, and the file is only read."""
    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir
    from stereovision.io import write_ply

    monkeypatch.setattr(gui_app, "MAX_SHOWN_POINTS", 100, raising=False)  # old: none
    n = 500
    pts = np.random.default_rng(1).uniform([-1, -1, 2], [1, 1, 4], (n, 3)).astype(np.float32)
    write_ply(tmp_path / "big.ply", pts)
    before = (tmp_path / "big.ply").read_bytes()
    app = _scene_app("test-cloud-cap", [bundled_data_dir(), tmp_path])

    def shown() -> Any:
        poly = app.plotter.actors["scene"].GetMapper().GetInput()
        return np.asarray(poly.GetPoints().GetData())

    app.state.view_mode = "points"
    app.state.cloud_path = str(tmp_path / "big.ply")
    app.open_cloud()
    assert app.state.error == ""
    label = app.folders.label((tmp_path / "big.ply").resolve())
    assert app.state.message_3d == f"{label}: 100 of 500 points shown, evenly spaced"
    np.testing.assert_array_equal(shown(), pts[::5])  # every 5th: deterministic, spread
    assert (tmp_path / "big.ply").read_bytes() == before
    # a computed pair in points mode: its cloud capped too, and said after its own caption
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    total = len(app.view.result.points)
    assert total > 10_000 and len(shown()) == 100
    assert app.state.message_3d == f"100 of {total:,} points shown, evenly spaced"
    app.state.view_mode = "surface"  # the surface has its own (smaller) vertex budget
    app._on_view_mode()
    assert len(shown()) > 100 and app.state.message_3d == ""
    app.state.view_mode = "points"
    app._on_view_mode()
    assert app.state.message_3d == f"100 of {total:,} points shown, evenly spaced"


def test_a_failed_scene_choice_puts_the_list_back(tmp_path):
    """A scene that failed (to load, or to compute) stayed chosen in the list, so choosing it
    again did nothing (trame reports only a changed value). The list now goes back to the
    scene on show, and choosing the failed one again retries (and fails again, saying so)."""
    import asyncio
    import shutil

    from stereovision.gui import bundled_data_dir

    good = tmp_path / "good"
    shutil.copytree(bundled_data_dir() / "cones", good)
    (tmp_path / "tiny").mkdir()  # loads, then fails to compute
    (tmp_path / "odd").mkdir()  # fails to load: the two images differ in size
    for side in ("left", "right"):
        cv2.imwrite(str(tmp_path / "tiny" / f"{side}.png"), np.zeros((8, 8, 3), np.uint8))
    cv2.imwrite(str(tmp_path / "odd" / "left.png"), np.zeros((40, 50, 3), np.uint8))
    cv2.imwrite(str(tmp_path / "odd" / "right.png"), np.zeros((40, 60, 3), np.uint8))
    app = _scene_app("test-scene-back", [tmp_path])
    app._lock = asyncio.Lock()
    app._spawn = asyncio.run  # a loaded scene is computed at once

    def choose(path: Path) -> None:
        app.state.scene = str(path)
        app._on_scene(scene=str(path))

    choose(good)
    assert app.state.computations == 1 and app.state.scene == str(good)
    for bad in ("odd", "tiny", "odd", "tiny"):
        app.state.error = ""
        choose(tmp_path / bad)
        assert app.state.error != "", bad  # it was tried (the first time, and again)
        assert app.state.scene == str(good), bad
        assert app.state.source_label == "scene data/good" or app.state.source_label.endswith(
            "/good"
        ), bad
        assert app.state.computations == 1, bad
    # the good scene is still the one the app works on
    assert app.pair[0].shape == (375, 450, 3)


def test_a_pair_that_fails_takes_its_files_warning_with_it(tmp_path):
    """Files that load but cannot be matched (8 px wide) put the page back on the previous
    pair, but the acquisition panel kept the failed files' warning ("... are the same image")
    above the previous pair's images, and its Check rows verdict was gone. The previous
    pair's line comes back with it."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-files-fail-rows", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.check_rows)
    verdict = app.state.rows_label
    assert verdict.startswith("rectification ok"), verdict
    tiny = np.random.default_rng(0).integers(0, 255, (8, 8, 3)).astype(np.uint8)
    cv2.imwrite(str(tmp_path / "tiny.png"), tiny)
    app.state.left_file = app.state.right_file = str(tmp_path / "tiny.png")
    app.load_files()
    assert app.state.rows_label.startswith("warning: ")  # said while it is tried
    _run(app, app.recompute)
    assert app.state.error.startswith("image too narrow for stereo matching")
    assert app.state.error.endswith("(the page still shows the previous pair)")
    assert app.state.source_label == "scene data/cones"
    assert app.state.rows_label == verdict


def test_a_scene_chosen_during_a_computation_is_not_shown_the_previous_result(tmp_path):
    """A scene chosen while another was computing: the running computation recorded the new
    scene's pair as the one on show, and put its (previous) result under the new scene's name.
    When the new scene then failed, the app kept its pair (Check rows worked on it) and the list
    and label named it, while the page showed the other scene's disparity."""
    import asyncio
    import shutil

    from stereovision.gui import bundled_data_dir

    for name in ("first", "second"):
        shutil.copytree(bundled_data_dir() / "cones", tmp_path / name)
    _tiny_scene(tmp_path / "tiny")
    app = _scene_app("test-scene-during-compute", [tmp_path])
    tasks: list = []
    choose = _chooser(app, tmp_path)

    async def run() -> None:
        _queue_spawns(app, tasks)
        choose("first")
        await asyncio.gather(*tasks)
        choose("second")
        await asyncio.sleep(0)  # its computation is running in the worker
        choose("tiny")
        await asyncio.gather(*tasks)

    asyncio.run(run())
    first = app.folders.label((tmp_path / "first").resolve())
    assert app.state.error.endswith("(the page still shows the previous pair)")
    assert app.state.source_label == f"scene {first}"
    assert app.state.scene == str(tmp_path / "first")
    assert app.pair[0].shape == (375, 450, 3) and app._scene == str(tmp_path / "first")
    assert app.state.computations == 1  # the superseded "second" was not put on the page


def test_a_new_pair_does_not_show_the_previous_pairs_results_while_it_computes(tmp_path):
    """While a newly chosen scene computed (23 s for a 1850 px pair), the page showed the
    previous scene's images, disparity, depth and floor under the new scene's name. The new
    pair's images now show at once, the previous results are cleared (the 3-D caption says the
    view is the previous pair's), and they come back if the new pair fails."""
    import asyncio
    import shutil

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import PENDING_3D, PENDING_FLOOR, _data_url

    shutil.copytree(bundled_data_dir() / "cones", tmp_path / "cones")
    shutil.copytree(bundled_data_dir() / "cones", tmp_path / "swapped")
    for side, other in (("left", "right"), ("right", "left")):  # another pair, same size
        src = bundled_data_dir() / "cones" / f"{other}.png"
        (tmp_path / "swapped" / f"{side}.png").write_bytes(src.read_bytes())
    _tiny_scene(tmp_path / "tiny")
    app = _scene_app("test-new-pair-pending", [tmp_path])
    tasks: list = []
    seen: dict = {}
    choose = _chooser(app, tmp_path)

    async def run() -> None:
        _queue_spawns(app, tasks)
        choose("cones")
        await asyncio.gather(*tasks)
        await app.find_floor()
        seen["page"] = {k: app.state[k] for k in ("img_disparity", "stats", "floor_label")}
        for name in ("swapped", "tiny"):
            choose(name)
            await asyncio.sleep(0)  # its computation is running in the worker
            seen[name] = {k: app.state[k] for k in ("img_left", "img_disparity", "stats")}
            seen[name]["message_3d"] = app.state.message_3d
            await app.find_floor()
            seen[name]["floor_label"] = app.state.floor_label
            await asyncio.gather(*tasks)

    asyncio.run(run())
    swapped = seen["swapped"]
    assert swapped["img_left"] == _data_url(cv2.imread(str(tmp_path / "swapped" / "left.png")))
    assert swapped["img_disparity"] == "" and swapped["stats"] == ""
    assert swapped["message_3d"] == PENDING_3D and swapped["floor_label"] == PENDING_FLOOR
    assert seen["tiny"]["img_disparity"] == "" and seen["tiny"]["stats"] == ""
    # "tiny" failed: the page shows the swapped pair's results again, as the error says
    assert app.state.error.endswith("(the page still shows the previous pair)")
    assert app.state.computations == 2 and app.state.stats.startswith("fast · 450×375")
    assert app.state.img_disparity not in ("", seen["page"]["img_disparity"])
    assert app.state.img_left == swapped["img_left"] and app.state.message_3d == ""


def test_a_failed_method_puts_the_toggle_back_to_the_result_on_show(monkeypatch):
    """A method that fails on the pair on show (fused refused for memory, when fast fits):
    the toggle stayed on the failed method above the previous method's disparity. It goes back
    to the method on show, without computing it again, and the error says what is shown."""
    from stereovision import _core
    from stereovision.gui import bundled_data_dir
    from stereovision.matching import sgm

    app = _scene_app("test-method-back", [bundled_data_dir()])
    spawned: list = []
    app._spawn = lambda coro: (spawned.append(coro), coro.close())
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    assert app.state.stats.startswith("fast · ") and app.state.computations == 1
    app.state.ready()  # from here the toggles' listeners run at each flush, as on the server
    monkeypatch.setattr(sgm, "_available_bytes", lambda: 1000)
    monkeypatch.setattr(_core, "kept_memory", lambda: ((0, 0), 0))
    app.state.method = "fused"
    spawned.clear()
    _run(app, app.recompute)
    assert app.state.error.startswith("the census semi-global map needs about")
    assert app.state.error.endswith("(the page still shows fast at full resolution)")
    assert app.state.method == "fast" and app.state.stats.startswith("fast · ")
    # one computation asked: the click's (its listener ran at the first flush); the toggle's
    # return to "fast" asks none
    assert len(spawned) == 1 and app.state.computations == 1
    # the method and resolution on show failing again: nothing to put back, nothing added
    from stereovision.gui import app as gui_app

    monkeypatch.setattr(gui_app, "compute_view", _fails)
    _run(app, app.recompute)
    assert app.state.error == "boom" and app.state.method == "fast"


def _fails(*args: Any, **kwargs: Any) -> Any:
    raise ValueError("boom")


def test_a_failed_pair_puts_back_the_calibration_and_gt_stays_with_its_scene(monkeypatch):
    """Files after a scene: the scene's GT is not said of them (its pair only), and a scene
    that then fails to compute puts back the files' inputs, their calibration (none) with them
    (both survived a mutation audit: the GT given for any pair, the calibration not put back)."""
    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-fail-puts-back-calib", [bundled_data_dir()])
    app._spawn = lambda coro: coro.close()
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    assert ", on GT bad-2.0" in app.state.stats and app.calib is not None
    app.state.left_file, app.state.right_file = "cones/left.png", "cones/right.png"
    app.load_files()
    _run(app, app.recompute)
    assert app.state.error == "" and "GT" not in app.state.stats and app.calib is None
    monkeypatch.setattr(gui_app, "compute_view", _fails)
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    assert app.state.error == "boom (the page still shows the previous pair)"
    assert app.calib is None and app.state.source_label == "files"


def test_a_scene_without_calibration_is_not_told_to_give_calib(tmp_path):
    """A scene without calib.txt: the 3-D panel and Find floor said "give --calib", but a
    scene's calibration is its own calib.txt (--calib is for cameras and files), so a restart
    with --calib changed nothing. They now name the missing file."""
    from stereovision.gui import bundled_data_dir

    scene = tmp_path / "nocalib"
    scene.mkdir()
    for side in ("left", "right"):
        (scene / f"{side}.png").write_bytes(
            (bundled_data_dir() / "cones" / f"{side}.png").read_bytes()
        )
    app = _scene_app("test-scene-no-calib", [tmp_path])
    app._load_scene(scene)
    _run(app, app.recompute)
    label = app.folders.label(scene.resolve())
    assert app.state.error == "" and app.state.computations == 1
    assert (
        app.state.message_3d == f"No calibration: scene {label} has no calib.txt (disparity only)."
    )
    _run(app, app.find_floor)
    assert app.state.floor_label == (
        f"finding the floor needs a calibration (scene {label} has no calib.txt)"
    )
    app._load_scene(bundled_data_dir() / "cones")  # with its calib.txt: depth and 3-D
    _run(app, app.recompute)
    assert app.state.message_3d == "" and "median depth" in app.state.stats


def test_buttons_before_a_pair_say_so():
    """Check rows, Rectify, Find floor and a method click before any pair: one sentence on the
    page (they did nothing, silently)."""
    import asyncio

    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import NO_PAIR, StereoApp

    app = StereoApp(
        get_server("test-no-pair", client_type="vue3"),
        AllowedFolders([bundled_data_dir()]),
        bundled_data_dir() / "cones",
    )
    app.pair = None
    app.view = None
    # the start-up state (the page not up yet, no lock): a method set then is no click
    app._on_method()
    assert app.state.error == ""
    app._lock = asyncio.Lock()
    for action in (app.check_rows, app.rectify_from_features, app.find_floor):
        app.state.error = ""
        asyncio.run(action())
        assert app.state.error == NO_PAIR, action.__name__
    app.state.error = ""
    app._on_method()
    assert app.state.error == NO_PAIR


def test_find_floor_controller_on_kitti(data_dir):
    """The stereo panel's "Find floor", in-process: on KITTI (scaled to the page's width) the
    camera's height above the road and a picture of floor and obstacles; without a
    calibration, a sentence saying so."""
    import asyncio

    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.gui.app import StereoApp

    app = StereoApp(
        get_server("test-floor", client_type="vue3"),
        AllowedFolders([data_dir]),
        data_dir / "kitti2015" / "000005_10",
    )

    async def run() -> None:
        app._lock = asyncio.Lock()
        app._load_scene(data_dir / "kitti2015" / "000005_10")
        await app.recompute()
        await app.find_floor()

    asyncio.run(run())
    assert app.state.error == ""
    text = app.state.floor_label
    height = float(re.search(r"camera ([0-9.]+)\xa0m above it", text).group(1))
    assert height == pytest.approx(1.62, abs=0.05)
    assert app.state.img_floor.startswith("data:image/jpeg;base64,")
    picture = _decode(app.state.img_floor)
    assert (np.abs(picture[..., 1] - picture[..., 0]) > 60).mean() > 0.05  # green floor shown

    async def no_calib() -> None:
        app.calib = None
        await app.recompute()
        await app.find_floor()

    asyncio.run(no_calib())
    assert app.state.floor_label == "finding the floor needs a calibration (--calib)"
    assert app.state.img_floor == ""


def test_find_floor_says_its_heights_in_the_unit_on_show(data_dir):
    """With feet chosen, Find floor still said "camera 1.62 m above it" (the ground module's
    line) under a picture captioned "obstacles 0.15-2 m". Both follow the unit toggle now: a
    floor found in metres is said again in feet, one found in feet is said in feet, and back
    in metres the line is the library's own."""
    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.gui.app import StereoApp, nowrap_units

    scene = data_dir / "kitti2015" / "000005_10"
    app = StereoApp(
        get_server("test-floor-ft", client_type="vue3"), AllowedFolders([data_dir]), scene
    )
    app._spawn = lambda coro: coro.close()
    assert app.state.floor_caption == "floor (green), obstacles 0.15-2\xa0m (red)"
    app._load_scene(scene)
    _run(app, app.recompute)
    _run(app, app.find_floor)
    metres = app.state.floor_label
    assert metres == nowrap_units(app.view.floor.describe())
    height_m = float(re.search(r"camera ([0-9.]+)\xa0m above it", metres).group(1))
    app._on_unit(unit="ft")
    assert app.state.floor_caption == "floor (green), obstacles 0.49-6.56\xa0ft (red)"
    height_ft = float(re.search(r"camera ([0-9.]+)\xa0ft above it", app.state.floor_label).group(1))
    assert height_ft == pytest.approx(height_m / 0.3048, abs=0.002)
    assert not re.search(r"[0-9][ \xa0]m\b", app.state.floor_label)
    assert app.state.floor_label.replace(f"{height_ft:.3f}\xa0ft", f"{height_m:.3f}\xa0m") == metres
    _run(app, app.recompute)  # a new depth map: its floor is found in feet
    assert app.state.floor_label == ""
    _run(app, app.find_floor)
    assert re.search(r"camera [0-9.]+\xa0ft above it", app.state.floor_label)
    app._on_unit(unit="m")
    assert app.state.floor_label == metres
    assert app.state.floor_caption == "floor (green), obstacles 0.15-2\xa0m (red)"
    from stereovision.gui.app import floor_text

    assert floor_text(None, "ft").startswith("ground plane: none found")


def test_find_floor_says_why_no_floor_was_found(data_dir):
    """Find floor said "no near-level plane holds 3 % of the pixels" of any map without a
    floor, also of one with fewer disparities than a fit needs (ground.MIN_PIXELS), where no
    fit was tried. It gives ``depth --ground``'s reason now, from the same code."""
    pytest.importorskip("trame")
    from types import SimpleNamespace

    from trame.app import get_server

    from stereovision.ground import MIN_PIXELS
    from stereovision.gui.app import StereoApp, floor_text

    scene = data_dir / "kitti2015" / "000005_10"
    app = StereoApp(
        get_server("test-floor-why", client_type="vue3"), AllowedFolders([data_dir]), scene
    )
    app._spawn = lambda coro: coro.close()
    app._load_scene(scene)
    _run(app, app.recompute)
    res = app.view.result
    disparity = res.disparity.copy()
    res.disparity[:] = np.nan  # nothing matched: no fit is tried
    import threading

    from stereovision import ground

    fit, threads = ground._fit_ground, []

    def spy(*args, **kwargs):
        threads.append(threading.current_thread())
        return fit(*args, **kwargs)

    ground._fit_ground = spy
    try:
        _run(app, app.find_floor)
    finally:
        ground._fit_ground = fit
    # one fit, in the executor, never on the page's loop: the line saying why is that fit's
    # (it ran the fit a second time)
    assert len(threads) == 1 and threading.main_thread() not in threads
    assert app.state.error == ""
    assert app.state.floor_label == (
        f"ground plane: none found (0 pixels have a disparity; a fit needs {MIN_PIXELS})"
    )
    assert app.state.img_floor == ""
    # enough disparities to try a fit (the pixels the fit counts: finite, in front of the rig)
    disparity[:] = np.nan
    disparity.flat[:MIN_PIXELS] = 40.0
    enough = SimpleNamespace(disparity=disparity, calibration=res.calibration)
    assert floor_text(None, "ft", enough) == (
        "ground plane: none found (no near-level plane holds 3 % of the pixels)"
    )
    disparity.flat[0] = -1e9  # behind the camera: not a disparity the fit counts
    assert floor_text(None, "ft", enough) == (
        f"ground plane: none found ({MIN_PIXELS - 1} pixels have a disparity giving a depth and "
        "1 one of 0 px or less (no depth: at infinity or behind the camera); a fit needs 500)"
    )


def test_save_writes_the_pair_on_show_as_depth_does_and_never_overwrites(tmp_path):
    """The page had no way to keep a result. "Save" writes the pair on show with the depth
    command's writer (disparity PNG + PFM, 16-bit depth PNG in mm, cloud.ply) into a folder
    inside --data; a folder already holding one of those files is refused, naming it, and
    the file is left as it was; a folder outside --data is refused."""
    from stereovision.export import read_depth_png
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import NO_PAIR, SAVED_DEPTH_FILES, SAVED_FILES
    from stereovision.io import read_pfm

    app = _scene_app("test-save", [bundled_data_dir(), tmp_path])
    assert app.state.save_dir == str(tmp_path.resolve() / "saved")
    _run(app, app.save)
    assert app.state.error == NO_PAIR
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    out = tmp_path / "saved"
    assert app.state.error == ""
    assert sorted(p.name for p in out.iterdir()) == sorted(SAVED_FILES + SAVED_DEPTH_FILES)
    assert app.state.save_label.startswith(f"saved 450×375 to {tmp_path.name}/saved: ")
    res = app.view.result
    np.testing.assert_array_equal(read_pfm(out / "disparity.pfm"), res.disparity)
    depth = read_depth_png(out / "depth_mm.png")
    ok = np.isfinite(res.depth) & (res.depth < 60)
    assert np.nanmax(np.abs(depth[ok] - res.depth[ok])) < 0.001
    # typed into a folder that holds the files: refused, nothing replaced
    (out / "cloud.ply").write_text("mine")
    (out / "disparity.pfm").unlink()
    app.state.save_label = ""
    app.state.save_dir = "saved"
    _run(app, app.save)
    assert app.state.error == (
        f"save: {tmp_path.name}/saved already holds disparity.png, depth.png, depth.npy, "
        "depth_mm.png, cloud.ply, render.png, overview.png; nothing was overwritten: choose "
        "another folder"
    )
    assert (out / "cloud.ply").read_text() == "mine" and not (out / "disparity.pfm").exists()
    for outside in ("../elsewhere", "/tmp", str(bundled_data_dir() / "x")):
        app.state.save_dir = outside
        _run(app, app.save)
        assert app.state.error == f"folder outside the --data folders: {outside}", outside
    app.state.save_dir = "second"  # relative: inside the first --data folder
    _run(app, app.save)
    assert app.state.error == "" and (tmp_path / "second" / "cloud.ply").stat().st_size > 1000
    # only the bundled data: nowhere to write, said so
    bare = _scene_app("test-save-bare", [bundled_data_dir()])
    bare.view = app.view
    assert bare.state.save_dir == ""
    assert bare.state.save_hint == "Save writes into a --data folder: start the GUI with --data DIR"
    _run(bare, bare.save)
    assert bare.state.error == "empty or invalid folder"
    bare.state.save_dir = "x"
    _run(bare, bare.save)
    assert bare.state.error == "no folder to write into: start the GUI with --data DIR"


def test_save_writes_the_overview_as_depth_does_in_the_pages_unit(tmp_path):
    """Save said it wrote the pair "as depth -o does", but not overview.png (the pictures with
    their labelled colour bars), which depth, demo and batch write. It is written by the same
    writer: its title names the pair as the page does, its depth bar is in the page's unit; a
    folder that holds a user's overview.png is refused, the file left as it was."""
    from stereovision.cli import write_overview
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import overview_name

    app = _scene_app("test-save-overview", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app._on_unit(unit="ft")
    _run(app, app.save)
    assert app.state.error == "" and "overview.png" in app.state.save_label
    assert overview_name(app.state.source_label) == "scene data/cones"
    reference = tmp_path / "reference"
    reference.mkdir()
    write_overview(app.view.result, reference, "scene data/cones", "ft")
    saved = cv2.imread(str(tmp_path / "saved" / "overview.png"))
    np.testing.assert_array_equal(saved, cv2.imread(str(reference / "overview.png")))
    # in feet, not the metres of the default: another picture
    write_overview(app.view.result, reference, "scene data/cones", "m")
    assert not np.array_equal(saved, cv2.imread(str(reference / "overview.png")))
    assert overview_name("folder seq: pair 2 · 640×480 …") == "folder seq: pair 2 | 640x480 ..."
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "overview.png").write_bytes(b"my picture")
    app.state.save_dir = "mine"
    _run(app, app.save)
    assert app.state.error == (
        f"save: {tmp_path.name}/mine already holds overview.png; nothing was overwritten: "
        "choose another folder"
    )
    assert sorted(p.name for p in mine.iterdir()) == ["overview.png"]
    assert (mine / "overview.png").read_bytes() == b"my picture"


def test_save_writes_render_png_of_the_3d_view_from_the_sliders_pose(tmp_path, monkeypatch):
    """Save wrote depth's files but not render.png, the 3-D view. It is now written too: the
    view on show seen from the pose the sliders set (translations in the page's unit), at the
    pair's size. A render that fails, or a pair without calibration, is said at the end of the
    Save's line; the other files are written all the same; a user's render.png is kept."""
    from stereovision import render
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import SAVED_DEPTH_FILES, SAVED_FILES, shown_cloud

    app = _scene_app("test-save-render", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app._on_unit(unit="ft")
    app.state.yaw, app.state.right = 15.0, -1.0  # 1 ft to the left
    _run(app, app.save)
    assert app.state.error == ""
    assert app.state.save_label.endswith(", overview.png, render.png")
    png = cv2.imread(str(tmp_path / "saved" / "render.png"), cv2.IMREAD_UNCHANGED)
    assert png.shape == (375, 450, 3) and png.dtype == np.uint8
    assert png.astype(np.float64).std() > 20.0  # a picture, not a blank window
    assert not render.is_blank(png[..., ::-1], min_fraction=0.5)
    view = app.view
    posed = render.CameraControls(yaw=15.0, right=-0.3048)
    expected = render.render_view(view.mesh, posed, intrinsics=view.intrinsics)
    assert np.abs(png[..., ::-1].astype(np.int16) - expected).mean() < 1.0
    default = render.render_view(view.mesh, intrinsics=view.intrinsics)
    assert np.abs(png[..., ::-1].astype(np.int16) - default).mean() > 10.0  # the pose counts
    # the points mode on show: its points, from the same pose
    app.state.view_mode, app.state.save_dir = "points", "points"
    _run(app, app.save)
    assert app.state.error == ""
    points = cv2.imread(str(tmp_path / "points" / "render.png"))
    cloud = shown_cloud(view.result.points, view.result.colors)[0]
    expected = render.render_view(cloud, posed, intrinsics=view.intrinsics)
    assert np.abs(points[..., ::-1].astype(np.int16) - expected).mean() < 1.0
    assert np.abs(points.astype(np.int16) - png).mean() > 3.0
    app.state.view_mode = "surface"
    # the user's render.png in a typed folder: refused, kept
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "render.png").write_bytes(b"my render")
    app.state.save_dir = "mine"
    _run(app, app.save)
    assert app.state.error == (
        f"save: {tmp_path.name}/mine already holds render.png; nothing was overwritten: "
        "choose another folder"
    )
    assert (mine / "render.png").read_bytes() == b"my render"

    # a render that fails: said in the line, the other files written
    def broken(*args: Any, **kw: Any) -> Any:
        raise RuntimeError("the offscreen render returned no image\nline 2")

    monkeypatch.setattr(render, "render_view", broken)
    app.state.save_dir = "broken"
    _run(app, app.save)
    assert app.state.error == ""
    assert app.state.save_label.startswith(f"saved 450×375 to {tmp_path.name}/broken: ")
    assert app.state.save_label.endswith(
        ", overview.png (render.png not written: the offscreen render returned no image)"
    )
    assert sorted(p.name for p in (tmp_path / "broken").iterdir()) == sorted(
        n for n in SAVED_FILES + SAVED_DEPTH_FILES if n != "render.png"
    )
    # no calibration: no depth, said
    scene = tmp_path / "nocalib"
    scene.mkdir()
    for side in ("left", "right"):
        (scene / f"{side}.png").write_bytes(
            (bundled_data_dir() / "cones" / f"{side}.png").read_bytes()
        )
    app._load_scene(scene)
    _run(app, app.recompute)
    app.state.save_dir = "nocalib-out"
    _run(app, app.save)
    assert app.state.error == ""
    assert app.state.save_label == (
        f"saved 450×375 to {tmp_path.name}/nocalib-out: disparity.png, disparity.pfm, "
        "overview.png (no calibration: disparity only; no depth, cloud.ply or render.png)"
    )
    assert sorted(p.name for p in (tmp_path / "nocalib-out").iterdir()) == sorted(SAVED_FILES)


def test_save_renders_the_3d_view_as_the_mouse_left_it(tmp_path):
    """render.png was the view from the sliders' pose even after the view was dragged with the
    mouse (the sliders do not follow it): not what the page showed. The page's view is rendered
    on the server, whose camera the mouse moves: render.png is now that camera's view, said in
    the Save's line, until a slider puts the view back on the sliders' pose."""
    from stereovision import render
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-save-mouse", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app.state.yaw = 10.0
    app._on_controls()
    view = app.view
    posed = render.render_view(
        view.mesh, render.CameraControls(yaw=10.0), intrinsics=view.intrinsics
    )
    # what the trackball style does on a drag: turn about the focal point
    cam = app.plotter.camera
    cam.Azimuth(-25.0)
    cam.Elevation(12.0)
    cam.OrthogonalizeViewUp()
    dragged = render.CameraState.of(cam)
    app.state.save_dir = "dragged"
    _run(app, app.save)
    assert app.state.error == ""
    assert app.state.save_label.endswith(
        ", overview.png, render.png (render.png: the 3-D view as the mouse left it, not the "
        "sliders' pose)"
    )
    png = cv2.imread(str(tmp_path / "dragged" / "render.png"))[..., ::-1].astype(np.int16)
    assert png.shape == (375, 450, 3)
    expected = render.render_view(view.mesh, intrinsics=view.intrinsics, camera=dragged)
    assert np.abs(png - expected).mean() < 1.0
    assert np.abs(png - posed).mean() > 10.0
    # a slider moved after the drag: the view is on the sliders' pose again, and render.png
    app.state.yaw = 5.0
    app._on_controls()
    app.state.save_dir = "slid"
    _run(app, app.save)
    assert app.state.save_label.endswith(", overview.png, render.png")
    png = cv2.imread(str(tmp_path / "slid" / "render.png"))[..., ::-1].astype(np.int16)
    expected = render.render_view(
        view.mesh, render.CameraControls(yaw=5.0), intrinsics=view.intrinsics
    )
    assert np.abs(png - expected).mean() < 1.0


def test_the_unit_toggle_and_the_view_mode_keep_the_view_the_mouse_left(tmp_path):
    """The unit toggle (which converts the translation sliders so that their pose stays) and the
    surface/points toggle put the view back on the sliders' pose: a view dragged with the mouse
    was lost, and render.png was the sliders' pose again. The dragged view now stays."""
    from stereovision import render
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import MOUSE_RENDER

    app = _scene_app("test-save-mouse-unit", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app.state.right = 0.123
    app._on_controls()
    cam = app.plotter.camera
    cam.Azimuth(-25.0)
    cam.Elevation(12.0)
    cam.OrthogonalizeViewUp()
    dragged = render.CameraState.of(cam)
    app.state.unit = "ft"
    app._on_unit("ft")
    assert app.state.right == pytest.approx(0.404)  # 0.123 m in feet, rounded as the slider
    assert render.CameraState.of(app.plotter.camera).same_view(dragged)
    app.state.view_mode = "points"
    app._on_view_mode()
    assert render.CameraState.of(app.plotter.camera).same_view(dragged)
    app.state.save_dir = "ft"
    _run(app, app.save)
    assert app.state.save_label.endswith(f", overview.png, render.png ({MOUSE_RENDER})")
    # not dragged: the toggle leaves the view on the sliders' pose (no mouse view said)
    app.reset_camera()
    app.state.right = 0.5
    app._on_controls()
    app.state.unit = "m"
    app._on_unit("m")
    app.state.save_dir = "m"
    _run(app, app.save)
    assert app.state.save_label.endswith(", overview.png, render.png")


def _mouse_drag(app: Any, path: list[tuple[float, float]]) -> None:
    """A left-button drag of the 3-D view along ``path`` (fractions of the view), sent as the
    page's server-side view sends the browser's mouse events (trame-vtk's mouse handler)."""
    from vtkmodules.vtkWebCore import vtkWebApplication, vtkWebInteractionEvent

    iren = app.plotter.iren.interactor
    iren.Initialize()  # the served page's view has it; the app alone does not
    iren.Enable()
    web = vtkWebApplication()
    for i, (x, y) in enumerate(path):
        event = vtkWebInteractionEvent()
        down = i < len(path) - 1  # the last point: the button released
        event.SetButtons(vtkWebInteractionEvent.LEFT_BUTTON if down else 0)
        event.SetX(x)
        event.SetY(y)
        assert web.HandleInteractionEvent(app.plotter.render_window, event)


def test_sliders_from_pose_clamps_values_past_the_sliders_range():
    """The pose the mouse leaves can be past the sliders' range (yaw 150 after orbiting the
    scene, 7 m forward after zooming): each value is clamped to its slider's range, in the
    page's unit for the translations, and said so."""
    from stereovision import render
    from stereovision.gui.app import sliders_from_pose

    pose = render.camera_pose(roll=10.0, pitch=-20.0, yaw=30.0, forward=1.5, up=0.2, right=-0.3)
    values, clamped = sliders_from_pose(pose)
    assert not clamped
    expected = {"roll": 10.0, "pitch": -20.0, "yaw": 30.0, "forward": 1.5, "up": 0.2}
    assert values == pytest.approx({**expected, "right": -0.3}, abs=1e-9)
    values, clamped = sliders_from_pose(pose, "ft")
    assert not clamped
    assert values["forward"] == pytest.approx(1.5 / 0.3048) and values["yaw"] == pytest.approx(30)
    values, clamped = sliders_from_pose(render.camera_pose(yaw=150.0, pitch=5.0, forward=7.0))
    assert clamped
    assert values["yaw"] == 90.0 and values["forward"] == 5.0
    assert values["pitch"] == pytest.approx(5.0) and values["roll"] == pytest.approx(0.0)
    values, clamped = sliders_from_pose(render.camera_pose(roll=-120.0, right=-7.0), "ft")
    assert clamped and values["roll"] == -90.0 and values["right"] == -16.4  # the page's range
    with pytest.raises(ValueError, match="unit"):
        sliders_from_pose(pose, "yd")


def test_the_sliders_follow_the_view_the_mouse_left(tmp_path):
    """The sliders stayed where they were when the 3-D view was dragged with the mouse, so the
    next slider move put the view back on their old pose: the drag was undone. The end of a
    drag now sets the sliders from the view's camera, and a slider moved next continues from
    the dragged view."""
    from stereovision import render
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-follow-mouse", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app.state.yaw = 10.0
    app._on_controls()
    _mouse_drag(app, [(0.5, 0.5), (0.55, 0.52), (0.6, 0.55), (0.6, 0.55)])
    dragged = render.controls_from_pose(render.pose_from_camera(app.plotter.camera))
    assert abs(dragged.yaw - 10.0) > 5.0 and abs(dragged.pitch) > 5.0  # the drag turned it
    names = ("roll", "pitch", "yaw", "forward", "up", "right")
    assert {n: app.state[n] for n in names} == pytest.approx(
        {n: getattr(dragged, n) for n in names}, abs=1e-9
    )
    assert app._mouse_camera() is None  # the view is the sliders' pose: Save renders it
    app.state.yaw = dragged.yaw + 5.0
    app._on_controls()
    moved = render.controls_from_pose(render.pose_from_camera(app.plotter.camera))
    assert moved.yaw == pytest.approx(dragged.yaw + 5.0)
    assert moved.pitch == pytest.approx(dragged.pitch) and moved.up == pytest.approx(dragged.up)
    # a click (nothing moved) leaves the sliders alone
    before = {n: app.state[n] for n in names}
    _mouse_drag(app, [(0.3, 0.3), (0.3, 0.3)])
    assert {n: app.state[n] for n in names} == before
    # the wheel (as the page's view sends it: the interactor's wheel event) moves forward
    app.plotter.iren.interactor.MouseWheelForwardEvent()
    zoomed = render.controls_from_pose(render.pose_from_camera(app.plotter.camera))
    assert zoomed.forward > before["forward"] + 0.1
    assert app.state.forward == pytest.approx(zoomed.forward, abs=1e-9)


def test_a_drag_past_the_sliders_range_clamps_them_and_keeps_the_view(tmp_path):
    """A drag that turns the view past the sliders' +-90 degrees sets them clamped; the view
    stays as the mouse left it (Save says so) until a slider moves it from the clamped pose."""
    from stereovision import render
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-follow-mouse-clamped", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    # the sliders' listeners run at each flush, as on the server: setting the sliders from the
    # view must not put the view on their (clamped) pose
    app.state.ready()
    cam = app.plotter.camera
    cam.Azimuth(-130.0)  # orbiting the scene: the camera turns right past yaw 90
    cam.OrthogonalizeViewUp()
    app.plotter.iren.interactor.InvokeEvent("EndInteractionEvent")
    dragged = render.CameraState.of(cam)
    assert app.state.yaw == 90.0
    assert render.CameraState.of(app.plotter.camera).same_view(dragged)
    assert app._mouse_camera() is not None  # not the sliders' pose: Save renders this view
    app.state.pitch = 3.0
    app._on_controls()
    moved = render.controls_from_pose(render.pose_from_camera(app.plotter.camera))
    assert moved.yaw == pytest.approx(90.0) and moved.pitch == pytest.approx(3.0)


def test_a_toggle_after_a_followed_drag_keeps_the_view_and_its_pivot(tmp_path):
    """Once the sliders followed a drag, the unit and surface/points toggles put the view on
    the sliders' pose again: the focal point (the centre of the next drag, 1.35 m ahead after
    the wheel) went back to the scene's median depth (3.5 m) and the feet slider's rounding
    moved the camera. The view the mouse left now stays whole, still the sliders' pose."""
    from stereovision import render
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-follow-mouse-toggle", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _mouse_drag(app, [(0.5, 0.5), (0.55, 0.52), (0.6, 0.55), (0.6, 0.55)])
    for _ in range(5):
        app.plotter.iren.interactor.MouseWheelForwardEvent()
    dragged = render.CameraState.of(app.plotter.camera)
    assert app.plotter.camera.GetDistance() < 2.0  # the wheel brought the pivot nearer
    app.state.unit = "ft"
    app._on_unit("ft")
    assert render.CameraState.of(app.plotter.camera).same_view(dragged)
    app.state.view_mode = "points"
    app._on_view_mode()
    assert render.CameraState.of(app.plotter.camera).same_view(dragged)
    assert app._mouse_camera() is None  # still the sliders' pose: Save says no mouse view


def _page_sets(app: Any, **values: Any) -> None:
    """``values`` set as the page sends them: one update of the server's state, flushed, the
    change listeners run in that flush (a handler's own changes are flushed after it)."""
    with app.state:
        app.state.update(values)


def test_the_unit_toggle_clicked_on_the_page_keeps_the_view_the_mouse_left(tmp_path):
    """On the served page the unit toggle lost the view the mouse left (kept by
    test_the_unit_toggle_and_the_view_mode_keep_the_view_the_mouse_left, which calls the
    handler with the state's listeners off): the translation sliders it converts were flushed
    after its handler had kept the view, and their listener put the view on the sliders' pose
    (a drag past their range undone, render.png no longer the view shown). The view stays; a
    slider moved next still moves it."""
    from stereovision import render
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-unit-click-keeps-mouse", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app.state.ready()  # the listeners run at each flush, as on the server
    _page_sets(app, right=0.123, forward=1.0)
    cam = app.plotter.camera
    assert cam.position == pytest.approx((0.123, 0.0, 1.0), abs=1e-9)
    cam.Azimuth(-130.0)  # a drag past the yaw slider's 90 degrees
    cam.OrthogonalizeViewUp()
    app.plotter.iren.interactor.InvokeEvent("EndInteractionEvent")
    dragged = render.CameraState.of(cam)
    assert app.state.yaw == 90.0 and app._mouse_camera() is not None
    metres = {n: app.state[n] for n in ("forward", "up", "right")}
    _page_sets(app, unit="ft")
    for name, value in metres.items():  # converted (inside the feet sliders' 16.4 ft)
        feet = min(max(round(value / 0.3048, 3), -16.4), 16.4)
        assert app.state[name] == pytest.approx(feet), name
    assert render.CameraState.of(cam).same_view(dragged)
    assert app._mouse_camera() is not None  # still not the sliders' pose: Save says so
    app._on_unit("m")  # called outside a flush: its changes flushed at its block's end
    assert render.CameraState.of(cam).same_view(dragged)
    _page_sets(app, pitch=3.0)  # a slider moved: from the sliders' (clamped) pose
    moved = render.controls_from_pose(render.pose_from_camera(cam))
    assert moved.yaw == pytest.approx(90.0) and moved.pitch == pytest.approx(3.0)
    for name, value in metres.items():
        assert getattr(moved, name) == pytest.approx(value, abs=2e-3), name  # the rounding


def test_save_of_the_pair_ignores_a_drag_of_an_opened_cloud_file(tmp_path):
    """With a point-cloud file shown in the 3-D view, a drag moves the view of that file (another
    scene, framed without the pair's intrinsics), yet Save rendered the pair from that camera
    and said it was the 3-D view as the mouse left it: render.png is the pair's from the
    sliders' pose, as when nothing was dragged."""
    from stereovision import render
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import MOUSE_RENDER

    app = _scene_app("test-save-cloud-drag", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app.state.save_dir = "first"
    _run(app, app.save)
    app.state.cloud_path = str((tmp_path / "first" / "cloud.ply").resolve())
    app.open_cloud()
    assert app.state.error == "" and app._cloud is not None
    cam = app.plotter.camera
    cam.Azimuth(-25.0)
    cam.OrthogonalizeViewUp()
    app.state.save_dir = "second"
    _run(app, app.save)
    assert app.state.error == ""
    assert MOUSE_RENDER not in app.state.save_label
    assert app.state.save_label.endswith(", overview.png, render.png")
    png = cv2.imread(str(tmp_path / "second" / "render.png"))[..., ::-1].astype(np.int16)
    view = app.view
    posed = render.render_view(view.mesh, render.CameraControls(), intrinsics=view.intrinsics)
    assert np.abs(png - posed).mean() < 1.0


def test_save_says_a_3d_view_it_cannot_render_and_writes_the_rest(tmp_path):
    """A view's camera CameraState refuses (its up along the view direction) stopped the Save
    before any file was written; it is said as a failed render, the other files written."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import SAVED_DEPTH_FILES, SAVED_FILES

    app = _scene_app("test-save-bad-camera", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    cam = app.plotter.camera
    cam.SetViewUp(*cam.GetDirectionOfProjection())
    app.state.save_dir = "bad"
    _run(app, app.save)
    assert app.state.error == ""
    assert app.state.save_label.startswith(f"saved 450×375 to {tmp_path.name}/bad: ")
    assert re.search(
        r", overview\.png \(render\.png not written: CameraState: up \([^)]+\) is along the "
        r"view direction \(or zero\): no way is up\)$",
        app.state.save_label,
    ), app.state.save_label
    assert sorted(p.name for p in (tmp_path / "bad").iterdir()) == sorted(
        n for n in SAVED_FILES + SAVED_DEPTH_FILES if n != "render.png"
    )


def test_a_failed_render_of_a_dragged_view_is_not_said_as_written(tmp_path, monkeypatch):
    """A render of the view the mouse left that fails: the Save's line says render.png was not
    written, not also that render.png is the mouse's view (both were said in a mutation
    audit)."""
    import stereovision.render as render
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import MOUSE_RENDER

    def fails(*args: Any, **kwargs: Any) -> Any:
        raise RuntimeError("the offscreen render failed")

    app = _scene_app("test-save-mouse-render-fails", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app.plotter.camera.Azimuth(10)  # the mouse's view, no slider's
    assert app._mouse_camera() is not None
    monkeypatch.setattr(render, "render_view", fails)
    app.state.save_dir = "dragged"
    _run(app, app.save)
    assert app.state.error == ""
    assert app.state.save_label.endswith(
        ", overview.png (render.png not written: the offscreen render failed)"
    ), app.state.save_label
    assert MOUSE_RENDER not in app.state.save_label


def test_the_save_hint_says_where_a_typed_folder_goes(tmp_path, monkeypatch):
    """A bare name typed in the save field goes into the first --data folder, not the current
    one: only the field's tooltip said so. The line under the field says where it goes."""
    pytest.importorskip("trame")
    from stereovision.gui.app import SAVE_HINT, StereoApp
    from stereovision.gui.sources import display_path

    data = tmp_path / "scenes"
    (tmp_path / "here").mkdir()
    data.mkdir()
    monkeypatch.chdir(tmp_path / "here")
    app = StereoApp.__new__(StereoApp)  # the save field's rule alone: a page takes 0.7 s
    app.folders = AllowedFolders([data])
    app._save_roots = list(app.folders.roots)
    app._offered_save_dir = display_path(data.resolve() / "saved")
    shown = display_path(data.resolve())  # absolute: outside the current folder
    assert app._save_hint("mine") == (
        f"a Save writes into {shown}/mine (relative to the --data folder {shown})"
    )
    # relative to the current folder, as the field shows paths; absolute
    assert app._save_hint("../scenes/typed") == f"a Save writes into {shown}/typed"
    assert app._save_hint(str(data / "abs")) == f"a Save writes into {shown}/abs"
    assert app._save_hint("../outside") == SAVE_HINT  # refused by the Save, in its words


def test_the_save_field_shows_the_data_folder_short_and_saves_where_it_says(tmp_path, monkeypatch):
    """The save field showed the --data folder's absolute path (the README's picture: a
    temporary /tmp/sv-.../scenes/saved). It shows it relative to the current directory when
    it is under it, else ~-abbreviated, else absolute, the whole path in its tooltip; a path
    typed as the field shows them (relative to the current directory) is saved there, a bare
    name still in the first --data folder."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.sources import display_path

    data = tmp_path / "scenes"
    data.mkdir()
    monkeypatch.chdir(tmp_path)
    app = _scene_app("test-save-shown", [bundled_data_dir(), data])
    assert app.state.save_dir == "scenes/saved"
    full = str(data.resolve() / "saved")
    assert app.state.save_dir_title == f"{full} (or the next new saved-N)"
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    assert app.state.error == "" and (data / "saved" / "cloud.ply").is_file()
    for typed, where in (("scenes/mine", data / "mine"), ("other", data / "other")):
        app._on_save_dir(typed)
        assert app.state.save_dir_title == str(where.resolve()), typed
        app.state.save_dir = typed
        _run(app, app.save)
        assert app.state.error == "" and (where / "cloud.ply").is_file(), typed
    assert not (data / "scenes").exists()
    app._on_save_dir("../outside")
    assert app.state.save_dir_title == ""
    # under the home folder, not the current directory: ~/...
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.chdir("/")
    home_app = _scene_app("test-save-home", [bundled_data_dir(), data])
    assert home_app.state.save_dir == "~/scenes/saved"
    assert display_path(data, cwd=Path("/nowhere"), home=Path("/nohome")) == str(data)


def test_a_save_as_offered_into_a_read_only_data_folder_goes_to_the_home_folder(
    tmp_path, monkeypatch
):
    """The offered save folder is <first --data>/saved; with a read-only data set there (as
    /work/shared/data), every Save as offered failed ("cannot write in ..."). It goes to
    ~/stereovision-saved (then -2, ...) instead, the Save's line saying where and why; a folder
    typed in the read-only --data is refused, naming it (no other folder written); with the
    home folder read-only too, both are named. The field's tooltip says where it goes."""
    import stereovision.io as svio
    from stereovision.gui import bundled_data_dir

    data, home = tmp_path / "data", tmp_path / "home"
    data.mkdir()
    home.mkdir()
    real = svio.cannot_write_in
    read_only = [data.resolve()]

    def cannot_write_in(folder):
        return "Read-only file system" if Path(folder).resolve() in read_only else real(folder)

    monkeypatch.setattr(svio, "cannot_write_in", cannot_write_in)
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir("/")
    app = _scene_app("test-save-read-only", [bundled_data_dir(), data])
    # the hint and the field's tooltip named data/saved, where no Save as offered goes
    assert app.state.save_hint == (
        "the --data folder cannot be written: as offered, a new one each Save in the home "
        "folder (stereovision-saved, stereovision-saved-2, ...)"
    )
    assert app.state.save_dir_title == (
        f"{home.resolve() / 'stereovision-saved'} (or the next new -N: "
        f"{data.resolve() / 'saved'} cannot be written: Read-only file system)"
    )
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    # one pair of brackets (it read '(... cannot be written (Read-only file system))')
    why = f"({data.resolve() / 'saved'} cannot be written: Read-only file system)"
    for name in ("stereovision-saved", "stereovision-saved-2"):
        _run(app, app.save)
        assert app.state.error == "", name
        assert app.state.save_label.startswith(f"saved 450×375 to ~/{name}: disparity.png, ")
        assert app.state.save_label.endswith(why), name
        assert (home / name / "cloud.ply").is_file(), name
    assert list(data.iterdir()) == []

    app.state.save_dir = "mine"  # typed: refused, naming it
    _run(app, app.save)
    assert app.state.error == (
        f"save folder {data.resolve() / 'mine'}: cannot write in {data.resolve()} "
        "(Read-only file system)"
    )
    saved = sorted(p.name for p in home.glob("stereovision-saved*"))  # (~/.cache aside)
    assert saved == ["stereovision-saved", "stereovision-saved-2"]

    read_only.append(home.resolve())
    app.state.save_dir = app._offered_save_dir
    _run(app, app.save)
    assert app.state.error == (
        f"save: {data.resolve() / 'saved'} cannot be written (Read-only file system), nor "
        "~/stereovision-saved-3 (Read-only file system)"
    )
    assert list(data.iterdir()) == [] and len(list(home.glob("stereovision-saved*"))) == 2


def test_saves_into_the_offered_folder_go_to_a_new_numbered_folder_each(tmp_path):
    """Each Save after the first was refused ("saved already holds ...") until a new folder was
    typed: saving several pairs meant typing a folder for each. Left as offered (or emptied),
    the field now sends each Save to the first of saved, saved-2, saved-3, ... that is new or
    empty, and the page says which; nothing is overwritten."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import SAVED_DEPTH_FILES, SAVED_FILES

    app = _scene_app("test-save-numbered", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    (tmp_path / "saved-2").mkdir()
    (tmp_path / "saved-2" / "notes.txt").write_text("mine")  # not empty: skipped
    (tmp_path / "saved-4").mkdir()  # empty: taken in turn
    said = []
    for _ in range(3):
        app.state.save_label = ""
        _run(app, app.save)
        assert app.state.error == ""
        said.append(app.state.save_label.split(":")[0])
    assert said == [
        f"saved 450×375 to {tmp_path.name}/{n}" for n in ("saved", "saved-3", "saved-4")
    ]
    for name in ("saved", "saved-3", "saved-4"):
        assert sorted(p.name for p in (tmp_path / name).iterdir()) == sorted(
            SAVED_FILES + SAVED_DEPTH_FILES
        )
    assert [p.name for p in (tmp_path / "saved-2").iterdir()] == ["notes.txt"]
    app.state.save_dir = "  "  # emptied: as offered
    _run(app, app.save)
    assert app.state.save_label.startswith(f"saved 450×375 to {tmp_path.name}/saved-5: ")
    assert app.state.save_dir == "  "  # the field is left as the user left it
    # a folder typed just before the click, not yet in the server's state: the click's own
    # copy of the field is the one saved into (the page's test saved into "saved" instead)
    app.state.save_dir = app._offered_save_dir
    pending: list = []
    app._spawn = pending.append
    app.save_clicked("typed")
    _run(app, pending.pop)
    assert app.state.save_label.startswith(f"saved 450×375 to {tmp_path.name}/typed: ")


@pytest.mark.parametrize("how", ["unlistable", "unwritable", "a file"])
def test_the_offered_save_folder_skips_a_saved_that_cannot_be_used(tmp_path, monkeypatch, how):
    """A ``saved`` in a writable --data folder that could not be listed failed every Save as
    offered with the bare "[Errno 13] Permission denied: '.../saved'"; an empty one that could
    not be written sent the Saves home, said as "the --data folder cannot be written". Either
    is now skipped as a full one is (a file named ``saved`` already was): the Save goes to
    ``saved-2``, its line saying why ``saved`` was left alone; nothing is written into it.
    (Permissions are faked: root lists and writes every folder.)"""
    import stereovision.io as svio
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import SAVE_HINT, SAVED_DEPTH_FILES, SAVED_FILES

    data, home = tmp_path / "mine", tmp_path / "home"
    data.mkdir()
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))
    bad = data / "saved"
    if how == "a file":
        bad.write_text("not a folder")
    else:
        bad.mkdir()
    real_iterdir, real_cannot = Path.iterdir, svio.cannot_write_in

    def iterdir(self: Path) -> Any:
        if how == "unlistable" and self.resolve() == bad.resolve():
            raise PermissionError(13, "Permission denied", str(self))
        return real_iterdir(self)

    def cannot_write_in(folder: Any) -> str | None:
        if how == "unwritable" and Path(folder).resolve() == bad.resolve():
            return "Permission denied"
        return real_cannot(folder)

    monkeypatch.setattr(Path, "iterdir", iterdir)
    monkeypatch.setattr(svio, "cannot_write_in", cannot_write_in)
    app = _scene_app(f"test-save-unusable-{how.replace(' ', '-')}", [bundled_data_dir(), data])
    assert app.state.save_hint == SAVE_HINT  # Saves do not go home
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    assert app.state.error == ""
    assert app.state.save_label.startswith("saved 450×375 to mine/saved-2: ")
    why = {
        "unlistable": " (saved cannot be listed: Permission denied: left alone)",
        "unwritable": " (saved cannot be written: Permission denied: left alone)",
        "a file": "",
    }[how]
    assert app.state.save_label.endswith(f".png{why}")
    assert sorted(p.name for p in (data / "saved-2").iterdir()) == sorted(
        SAVED_FILES + SAVED_DEPTH_FILES
    )
    if how == "a file":
        assert bad.read_text() == "not a folder"
    else:
        assert list(real_iterdir(bad)) == []
    assert list(home.glob("stereovision-saved*")) == []  # nothing went home


@pytest.mark.parametrize("becomes", ["removed", "a file"])
def test_a_saved_changed_while_looked_at_is_not_said_unusable(tmp_path, monkeypatch, becomes):
    """A ``saved`` removed (or replaced by a file) between its look and its listing was said
    "saved cannot be listed: No such file or directory" ("Not a directory"): left alone as
    unusable, the Save sent to ``saved-2``. A removed one is made by the Save, as one that
    never was; a file put in its place is skipped as a file named ``saved`` is, unsaid."""
    from stereovision.gui import bundled_data_dir

    data = tmp_path / "mine"
    bad = data / "saved"
    bad.mkdir(parents=True)
    real_iterdir = Path.iterdir

    def iterdir(self: Path) -> Any:
        if self.resolve() == bad.resolve() and bad.is_dir():  # the race, made certain
            bad.rmdir()
            if becomes == "a file":
                bad.write_text("not a folder")
        return real_iterdir(self)

    monkeypatch.setattr(Path, "iterdir", iterdir)
    app = _scene_app(f"test-save-race-{becomes.replace(' ', '-')}", [bundled_data_dir(), data])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    if not bad.is_dir():  # the page's hints looked at it too: the race again at the Save
        bad.unlink(missing_ok=True)
        bad.mkdir()
    _run(app, app.save)
    assert app.state.error == ""
    into = "saved" if becomes == "removed" else "saved-2"
    assert app.state.save_label.startswith(f"saved 450×375 to mine/{into}: ")
    assert app.state.save_label.endswith(".png")  # nothing said left alone
    assert (data / into / "disparity.png").is_file()


def test_the_offered_save_folder_skips_a_link_named_saved(tmp_path):
    """A ``saved`` in --data that was a symbolic link leading outside it made every Save as
    offered fail with "folder outside the --data folders: saved", a folder the user never
    typed. A link is now skipped, whatever it leads to (nothing is written through it), and the
    page says so; a link the user types is still refused."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import SAVED_DEPTH_FILES, SAVED_FILES

    data, outside = tmp_path / "mine", tmp_path / "outside"
    data.mkdir()
    outside.mkdir()
    (data / "saved").symlink_to(outside, target_is_directory=True)
    app = _scene_app("test-save-link", [bundled_data_dir(), data])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    assert app.state.error == ""
    assert app.state.save_label.startswith("saved 450×375 to mine/saved-2: ")
    assert app.state.save_label.endswith(
        " (saved: a symbolic link, not a folder of --data: left alone)"
    )
    assert sorted(p.name for p in (data / "saved-2").iterdir()) == sorted(
        SAVED_FILES + SAVED_DEPTH_FILES
    )
    assert list(outside.iterdir()) == []
    app.state.save_dir = "saved"  # typed: refused, nothing written
    _run(app, app.save)
    assert app.state.error == "folder outside the --data folders: saved"
    assert list(outside.iterdir()) == []
    # two links skipped: both named (only the first was, in a mutation audit)
    (data / "saved-3").symlink_to(outside, target_is_directory=True)
    app.state.save_dir = app._offered_save_dir
    _run(app, app.save)
    assert app.state.save_label.startswith("saved 450×375 to mine/saved-4: ")
    assert app.state.save_label.endswith(
        " (saved, saved-3: a symbolic link, not a folder of --data: left alone)"
    )
    with pytest.raises(ValueError, match=r"^empty or invalid folder$"):  # not "embedded null byte"
        app._typed_save_folder("mine\x00x")


def test_a_saved_cloud_is_offered_in_the_point_cloud_list(tmp_path):
    """The file lists were walked once, at start-up: the cloud.ply a Save had just written was
    not in the 3-D panel's point-cloud list (to be shown, its path had to be typed). Each Save
    now refreshes the lists, and its cloud opens in the 3-D view."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-save-list", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    assert app.state.clouds == []
    _run(app, app.save)
    saved = str((tmp_path / "saved" / "cloud.ply").resolve())
    assert [c["value"] for c in app.state.clouds] == [saved]
    assert app.state.clouds[0]["title"] == f"{tmp_path.name}/saved/cloud.ply"
    app.state.cloud_path = saved
    app.open_cloud()
    assert app.state.error == "" and app._cloud is not None


def test_clouds_saved_in_the_home_folder_are_offered_to_show_again(tmp_path, monkeypatch):
    """With a read-only --data folder a Save goes to ~/stereovision-saved (-2, ...), but the
    3-D panel's point-cloud list offered only the --data folders' files, and "Show" refused
    the saved cloud ("path outside the allowed folders"): what was just saved could not be
    looked at again. Those home folders' clouds are offered (an earlier session's too), named
    as the Save's line names them, and open; a link named like them that leads elsewhere, and
    other home folders, are not offered nor opened."""
    import stereovision.io as svio
    from stereovision.export import write_ply
    from stereovision.gui import bundled_data_dir

    data, home, outside = tmp_path / "data", tmp_path / "home", tmp_path / "outside"
    for d in (data, home / "stereovision-saved-3", home / "other", outside):
        d.mkdir(parents=True)
    points = np.array([[0.0, 0.0, 1.0], [0.1, 0.0, 1.0], [0.0, 0.1, 1.2]], np.float32)
    for where in (home / "stereovision-saved-3", home / "other", outside):
        write_ply(where / "cloud.ply", points)  # an earlier session's, and two elsewhere
    (home / "stereovision-saved-4").symlink_to(outside, target_is_directory=True)
    real = svio.cannot_write_in
    read_only = data.resolve()
    monkeypatch.setattr(
        svio,
        "cannot_write_in",
        lambda f: "Read-only file system" if Path(f).resolve() == read_only else real(f),
    )
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir("/")
    app = _scene_app("test-home-clouds", [bundled_data_dir(), data])
    earlier = str((home / "stereovision-saved-3" / "cloud.ply").resolve())
    assert app.state.clouds == [{"title": "~/stereovision-saved-3/cloud.ply", "value": earlier}]
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    assert app.state.save_label.startswith("saved 450×375 to ~/stereovision-saved: ")
    saved = str((home / "stereovision-saved" / "cloud.ply").resolve())
    assert app.state.clouds == [
        {"title": "~/stereovision-saved/cloud.ply", "value": saved},
        {"title": "~/stereovision-saved-3/cloud.ply", "value": earlier},
    ]
    app.state.cloud_path = saved
    app.open_cloud()
    assert app.state.error == "" and app._cloud is not None
    assert app.state.message_3d.startswith("~/stereovision-saved/cloud.ply: ")
    for elsewhere in (home / "other", home / "stereovision-saved-4", outside):
        app.state.cloud_path = str(elsewhere / "cloud.ply")
        app.open_cloud()
        assert app.state.error.startswith("path outside the allowed folders: "), elsewhere


def test_a_home_relative_path_without_a_home_folder_is_said_on_the_page(tmp_path, monkeypatch):
    """No home folder known (HOME unset, no password entry): "~/stereovision-saved/cloud.ply"
    typed in the point-cloud field, or "~/out" in the save field, raised Path.expanduser's
    RuntimeError out of the page's handler (Show said nothing, the field's tooltip broke).
    Show says why on the page; the field's tooltip is empty, as for any unusable folder."""
    import pwd

    from stereovision.gui import bundled_data_dir

    def no_entry(uid: int) -> Any:
        raise KeyError(uid)

    app = _scene_app("test-no-home-tilde", [bundled_data_dir(), tmp_path])
    monkeypatch.delenv("HOME", raising=False)
    monkeypatch.setattr(pwd, "getpwuid", no_entry)
    app.state.cloud_path = "~/stereovision-saved/cloud.ply"
    app.open_cloud()
    assert app.state.error == (
        "no home folder is known for ~/stereovision-saved/cloud.ply (HOME is not set): "
        "give the whole path"
    )
    assert app._save_title("~/out") == ""


def test_home_clouds_are_offered_when_saves_go_home_past_a_writable_saved(tmp_path, monkeypatch):
    """A read-only --data folder holding a writable, full ``saved`` (made before it was made
    read-only): a Save as offered goes to ``saved-2``, which cannot be made, so home; but the
    point-cloud list decided on ``saved`` alone (writable: "Saves do not go home"), so the cloud
    just saved to ~/stereovision-saved was not offered and "Show" refused it. The list now asks
    what the Save asks: the folder the next Save as offered would write into."""
    import stereovision.io as svio
    from stereovision.gui import bundled_data_dir

    data, home = tmp_path / "data", tmp_path / "home"
    (data / "saved").mkdir(parents=True)
    (data / "saved" / "notes.txt").write_text("an earlier Save's")
    home.mkdir()
    real = svio.cannot_write_in
    read_only = data.resolve()
    monkeypatch.setattr(
        svio,
        "cannot_write_in",
        lambda f: "Read-only file system" if Path(f).resolve() == read_only else real(f),
    )
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir("/")
    app = _scene_app("test-home-clouds-saved-2", [bundled_data_dir(), data])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    assert app.state.save_label.startswith("saved 450×375 to ~/stereovision-saved: ")
    saved = str((home / "stereovision-saved" / "cloud.ply").resolve())
    assert {"title": "~/stereovision-saved/cloud.ply", "value": saved} in app.state.clouds
    app.state.cloud_path = saved
    app.open_cloud()
    assert app.state.error == "" and app._cloud is not None


def test_the_save_hint_and_tooltip_name_the_home_folder_past_a_writable_saved(
    tmp_path, monkeypatch
):
    """A read-only --data folder holding a writable, full ``saved``: a Save as offered goes to
    ``saved-2``, cannot make it and goes home, but the start-up hint said "in a --data
    folder" and the field's tooltip named data/saved: both asked of ``saved`` alone. They ask
    what the Save asks (the folder the next Save as offered takes), and name the home
    folder, and saved-2 as the folder that cannot be written, as the Save's line does."""
    import stereovision.io as svio
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import READ_ONLY_SAVE_HINT

    data, home = tmp_path / "data", tmp_path / "home"
    (data / "saved").mkdir(parents=True)
    (data / "saved" / "notes.txt").write_text("an earlier Save's")
    home.mkdir()
    real = svio.cannot_write_in
    read_only = data.resolve()
    monkeypatch.setattr(
        svio,
        "cannot_write_in",
        lambda f: "Read-only file system" if Path(f).resolve() == read_only else real(f),
    )
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir("/")
    app = _scene_app("test-save-hint-saved-2", [bundled_data_dir(), data])
    assert app.state.save_hint == READ_ONLY_SAVE_HINT
    refused = f"{data.resolve() / 'saved-2'} cannot be written: Read-only file system"
    title = f"{Path.home() / 'stereovision-saved'} (or the next new -N: {refused})"
    assert app.state.save_dir_title == title
    app._on_save_dir("")  # an emptied field: as offered
    assert app.state.save_dir_title == title
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    assert app.state.save_label.startswith("saved 450×375 to ~/stereovision-saved: ")
    assert app.state.save_label.endswith(f"({refused})")  # as the tooltip said


def test_the_save_hint_and_tooltip_follow_a_save_that_fills_the_last_writable_saved(
    tmp_path, monkeypatch
):
    """A read-only --data folder holding a writable, empty ``saved``: the first Save as
    offered fills it, the next goes home, and the point-cloud list says so after the Save;
    but the save field's hint and tooltip, set at start-up alone, still said "in a --data
    folder" and named data/saved. They follow each Save as the list does."""
    import stereovision.io as svio
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import READ_ONLY_SAVE_HINT, SAVE_HINT

    data, home = tmp_path / "data", tmp_path / "home"
    (data / "saved").mkdir(parents=True)
    home.mkdir()
    real = svio.cannot_write_in
    read_only = data.resolve()
    monkeypatch.setattr(
        svio,
        "cannot_write_in",
        lambda f: "Read-only file system" if Path(f).resolve() == read_only else real(f),
    )
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir("/")
    app = _scene_app("test-save-hint-follows", [bundled_data_dir(), data])
    assert app.state.save_hint == SAVE_HINT
    assert app.state.save_dir_title == f"{data.resolve() / 'saved'} (or the next new saved-N)"
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    assert app.state.save_label.startswith(f"saved 450×375 to {app.folders.label(data / 'saved')}")
    assert app.state.save_hint == READ_ONLY_SAVE_HINT
    refused = f"{data.resolve() / 'saved-2'} cannot be written: Read-only file system"
    title = f"{Path.home() / 'stereovision-saved'} (or the next new -N: {refused})"
    assert app.state.save_dir_title == title
    _run(app, app.save)  # as the hint and tooltip now say
    assert app.state.save_label.startswith("saved 450×375 to ~/stereovision-saved: ")
    assert app.state.save_label.endswith(f"({refused})")


def test_a_home_folder_that_is_a_link_is_shown_as_tilde(tmp_path, monkeypatch):
    """HOME a symbolic link (/home/me -> /data/me): the Save's line and the point-cloud list
    showed the home folder's saves by their resolved, absolute paths, since they were asked
    of HOME as given alone. They show ``~/...`` for a path under HOME as given or resolved,
    and agree."""
    import stereovision.io as svio
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.sources import display_path

    data, home, link = tmp_path / "data", tmp_path / "real-home", tmp_path / "home"
    data.mkdir()
    home.mkdir()
    link.symlink_to(home, target_is_directory=True)
    real = svio.cannot_write_in
    read_only = data.resolve()
    monkeypatch.setattr(
        svio,
        "cannot_write_in",
        lambda f: "Read-only file system" if Path(f).resolve() == read_only else real(f),
    )
    monkeypatch.setenv("HOME", str(link))
    monkeypatch.chdir("/")
    assert display_path(home / "x.ply") == display_path(link / "x.ply") == "~/x.ply"
    assert display_path(home) == "~" and display_path(tmp_path) == str(tmp_path)
    app = _scene_app("test-home-link", [bundled_data_dir(), data])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    assert app.state.save_label.startswith("saved 450×375 to ~/stereovision-saved: ")
    saved = str((home / "stereovision-saved" / "cloud.ply").resolve())
    assert {"title": "~/stereovision-saved/cloud.ply", "value": saved} in app.state.clouds


def test_a_second_save_into_the_folder_being_written_is_refused(tmp_path, monkeypatch):
    """Save pressed twice (or again after a new pair came) while the first still wrote: the
    second found none of the files yet, wrote too, and replaced the first's files without a
    word. A typed folder being written is now refused like one that holds the files; the
    offered folder sends the second Save to the next numbered one."""
    import asyncio
    import threading

    import stereovision.cli as cli
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-save-twice", [bundled_data_dir(), tmp_path])
    app.state.save_dir = "saved"  # typed
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    real = cli.write_depth_outputs
    started, gate = threading.Event(), threading.Event()
    calls: list = []

    def held(result, folder):
        calls.append(folder)
        started.set()
        gate.wait(60)
        return real(result, folder)

    monkeypatch.setattr(cli, "write_depth_outputs", held)

    async def twice() -> None:
        app._lock = asyncio.Lock()
        first = asyncio.ensure_future(app.save())
        await asyncio.get_running_loop().run_in_executor(None, started.wait, 60)
        await app.save()  # the first is still writing
        assert app.state.error == (
            f"save: {tmp_path.name}/saved is being written by the previous Save; nothing was "
            "overwritten: choose another folder"
        )
        gate.set()
        await first

    asyncio.run(twice())
    assert len(calls) == 1
    assert app.state.save_label.startswith(f"saved 450×375 to {tmp_path.name}/saved: ")
    app._done()
    app.state.save_label = ""
    _run(app, app.save)  # and once written, the folder holds the files: refused as before
    assert app.state.error.startswith(f"save: {tmp_path.name}/saved already holds disparity.png")
    # the offered folder, pressed twice: the second Save goes to the next numbered folder
    app._done()
    app.state.save_dir = app._offered_save_dir
    calls.clear()
    started.clear()
    gate.clear()

    async def twice_offered() -> None:
        first = asyncio.ensure_future(app.save())
        await asyncio.get_running_loop().run_in_executor(None, started.wait, 60)
        gate.set()
        await app.save()
        await first

    asyncio.run(twice_offered())
    assert app.state.error == ""
    # each written in its own staging folder beside it, then moved into place
    assert [c.name for c in calls] == ["saved-2", "saved-3"]
    assert all(c.parent.parent == tmp_path.resolve() for c in calls)
    assert all(c.parent.name.startswith(".stereovision-partial-") for c in calls)
    assert (tmp_path / "saved-2" / "cloud.ply").is_file()
    assert (tmp_path / "saved-3" / "cloud.ply").is_file()
    assert not list(tmp_path.glob(".stereovision-partial-*"))


def _disk_full_at(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Make ``stereovision.io.atomic_write`` fail as a full disk does (ENOSPC) for the file
    whose name is the returned list's one item (set it before each Save; "" fails none)."""
    import contextlib
    import errno

    import stereovision.io as svio

    real = svio.atomic_write
    failing = [""]

    @contextlib.contextmanager
    def full_disk(path, mode="wb"):
        if Path(path).name == failing[0]:
            raise OSError(errno.ENOSPC, "No space left on device")
        with real(path, mode) as fh:
            yield fh

    monkeypatch.setattr(svio, "atomic_write", full_disk)
    return failing


def test_a_failed_save_of_a_pair_without_depth_names_the_file_that_failed(tmp_path, monkeypatch):
    """A pair without a calibration: its Save writes disparity.png, disparity.pfm and
    overview.png. One that failed at disparity.pfm or overview.png said "depth.png could not
    be written", the first file of the full write order not written, a file that Save never
    writes; it names the file that failed."""
    import shutil

    from stereovision.gui import bundled_data_dir

    scene = tmp_path / "cones-uncalibrated"
    scene.mkdir()
    for side in ("left", "right"):
        shutil.copy(bundled_data_dir() / "cones" / f"{side}.png", scene / f"{side}.png")
    app = _scene_app("test-save-without-depth", [tmp_path])
    app._load_scene(scene)
    _run(app, app.recompute)
    assert app.view.result.depth is None
    failing = _disk_full_at(monkeypatch)
    for name in ("disparity.png", "disparity.pfm", "overview.png"):
        failing[0] = name
        app.state.save_dir = app._offered_save_dir
        _run(app, app.save)
        assert app.state.save_label.startswith(
            f"save: {name} could not be written ([Errno 28] No space left on device); "
        ), name
        assert not (tmp_path / "saved").exists()


def test_a_save_folder_made_by_someone_else_while_the_save_wrote(tmp_path):
    """The Save's folder did not exist and another program made it while the files were
    written: the rename of the staging folder onto it failed with "[Errno 39] Directory not
    empty: '.../.stereovision-partial-.../saved' -> '.../saved'", naming a hidden folder the
    user never saw, where a folder that existed at the start gets its files moved in one by
    one, or "disparity.png appeared in ... while the Save wrote". The folder come meanwhile is
    treated as one that existed: a file of the Save's there is refused by name, nothing
    replaced; otherwise the files join the other program's."""
    pytest.importorskip("trame")
    from stereovision.gui.app import save_all_or_nothing

    folder = tmp_path / "saved"

    def write(notes: str, into: Path) -> None:
        (into / "disparity.png").write_bytes(b"png")
        (into / "overview.png").write_bytes(b"overview")
        folder.mkdir()
        (folder / notes).write_text("theirs")

    with pytest.raises(FileExistsError) as info:
        save_all_or_nothing(lambda into: write("disparity.png", into), folder)
    assert str(info.value) == (
        f"save: disparity.png appeared in {folder} while the Save wrote; nothing was "
        "overwritten: choose another folder"
    )
    assert [p.name for p in folder.iterdir()] == ["disparity.png"]
    assert (folder / "disparity.png").read_text() == "theirs"
    (folder / "disparity.png").unlink()
    folder.rmdir()
    written = save_all_or_nothing(lambda into: write("notes.txt", into), folder)
    assert written == {
        "disparity.png": folder / "disparity.png",
        "overview.png": folder / "overview.png",
    }
    assert sorted(p.name for p in folder.iterdir()) == [
        "disparity.png",
        "notes.txt",
        "overview.png",
    ]
    assert (folder / "notes.txt").read_text() == "theirs"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["saved"]  # no staging folder left


def test_save_all_or_nothing_says_a_failure_in_one_line_with_the_folders_path(tmp_path):
    """What a failed writer said is told in its first line, its staging path
    (``.stereovision-partial-...``, a folder the user never saw) written as the folder's; the
    files written are listed in the write order, not as the writer wrote them."""
    pytest.importorskip("trame")
    from stereovision.gui.app import SaveFailed, save_all_or_nothing

    folder = tmp_path / "saved"

    def failing(into: Path) -> None:
        (into / "disparity.png").write_bytes(b"png")
        raise OSError(f"cannot write {into / 'depth.png'}\nsecond line of the reason")

    with pytest.raises(SaveFailed) as info:
        save_all_or_nothing(failing, folder)
    assert str(info.value) == f"depth.png could not be written (cannot write {folder}/depth.png)"
    assert not folder.exists() and sorted(p.name for p in tmp_path.iterdir()) == []

    def backwards(into: Path) -> None:
        for name in ("overview.png", "depth.png", "disparity.png"):
            (into / name).write_bytes(b"x")

    written = save_all_or_nothing(backwards, folder)
    assert list(written) == ["disparity.png", "depth.png", "overview.png"]  # SAVE_WRITE_ORDER's


@pytest.mark.parametrize(
    ("name", "shown"), [("my\tsaved", "my\\tsaved"), ("my\nsaved", "my\\nsaved")]
)
def test_save_all_or_nothing_names_a_folder_with_a_control_character_not_its_staging_one(
    tmp_path, name, shown
):
    """The failure is said with the folder's path, escaped on the one line: first_line
    (e005247) escaped the tab in the message before the staging path in it was replaced by the
    folder's, so the replace missed and the hidden ``.stereovision-partial-...`` folder was
    named; a newline cut the line at the folder's name."""
    pytest.importorskip("trame")
    from stereovision.gui.app import SaveFailed, save_all_or_nothing

    folder = tmp_path / name

    def failing(into: Path) -> None:
        raise OSError(f"cannot write {into / 'depth.png'}\nsecond line of the reason")

    with pytest.raises(SaveFailed) as info:
        save_all_or_nothing(failing, folder)
    assert str(info.value) == (
        f"disparity.png could not be written (cannot write {tmp_path}/{shown}/depth.png)"
    )


def test_a_save_whose_writer_fails_leaves_no_partial_folder_and_names_the_file(
    tmp_path, tmp_path_factory, monkeypatch
):
    """Save wrote its files one by one into the folder: a writer that failed midway (disk full)
    left a partial set there. A Save is now all or nothing: written into a staging folder and
    moved into place once every file is; a failure leaves the folder as it was (absent when it
    was), no staging folder behind, and the Save's line names the file that failed.

    Its 27 Saves are of one pair from one pose: the 3-D view is rendered once (the first Save)
    and that image handed to the others, which write it as render.png all the same. The pair is
    the middle quarter of the demo's cones (225 x 188, its calibration's principal point moved
    with the crop): every file a Save writes, at a quarter of the pixels to write."""

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import SAVE_WRITE_ORDER, SAVED_DEPTH_FILES, SAVED_FILES

    assert sorted(SAVE_WRITE_ORDER) == sorted(SAVED_FILES + SAVED_DEPTH_FILES)
    scene = tmp_path_factory.mktemp("quarter-cones")
    for side in ("left", "right"):
        image = cv2.imread(str(bundled_data_dir() / "cones" / f"{side}.png"))
        assert cv2.imwrite(str(scene / f"{side}.png"), image[94:282, 112:337])
    (scene / "calib.txt").write_text(
        "cam0=[700 0 113; 0 700 93; 0 0 1]\ncam1=[700 0 113; 0 700 93; 0 0 1]\ndoffs=0\n"
        "baseline=160\nwidth=225\nheight=188\nndisp=64\n"
    )
    app = _scene_app("test-save-all-or-nothing", [tmp_path, scene])
    app._load_scene(scene)
    _run(app, app.recompute)
    render, rendered = app._render_for_save, []

    def render_once(view, camera=None):
        if not rendered:
            rendered.append(render(view, camera))
        return rendered[0]

    monkeypatch.setattr(app, "_render_for_save", render_once)
    failing = _disk_full_at(monkeypatch)
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("mine")
    for name in SAVE_WRITE_ORDER:
        failing[0] = name
        for typed, folder in (("", "saved"), ("mine", "mine"), ("new/deeper", "new/deeper")):
            app.state.save_dir = typed or app._offered_save_dir
            app.state.save_label = ""
            _run(app, app.save)
            said = (
                f"save: {name} could not be written ([Errno 28] No space left on device); "
                f"nothing was saved in {tmp_path.name}/{folder}"
            )
            assert app.state.save_label == said, (name, typed)
            assert app.state.error == said
            assert not (tmp_path / "saved").exists() and not (tmp_path / "new").exists()
            assert [p.name for p in (tmp_path / "mine").iterdir()] == ["notes.txt"]
            assert not list(tmp_path.glob(".*")), (name, typed)
    # the disk has room again: the same Saves write every file
    failing[0] = ""
    for typed in ("", "mine", "new/deeper"):
        app.state.save_dir = typed or app._offered_save_dir
        _run(app, app.save)
        assert app.state.error == ""
    for folder in ("saved", "new/deeper"):
        assert sorted(p.name for p in (tmp_path / folder).iterdir()) == sorted(SAVE_WRITE_ORDER)
    assert sorted(p.name for p in (tmp_path / "mine").iterdir()) == sorted(
        ("notes.txt", *SAVE_WRITE_ORDER)
    )
    assert not list(tmp_path.glob(".*")) and not list((tmp_path / "mine").glob(".*"))


def _still_cameras_app(name: str, data_dir: Path, raw: tuple) -> Any:
    """A :class:`StereoApp` (demo scene cones) whose cameras give ``raw`` on every read."""
    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.gui.app import StereoApp

    class Cameras:
        def read(self):
            return raw

        def close(self):
            pass

    return StereoApp(
        get_server(name, client_type="vue3"),
        AllowedFolders([data_dir]),
        data_dir / "middlebury2003" / "cones",
        source=Cameras(),
    )


def test_rectify_controller_without_a_calibration(data_dir):
    """The acquisition panel's "Rectify", in-process, on StereoPi's raw pair (rows 0.59 px
    apart): rectified from its features, the rows check passes, and the cameras' next pair
    goes through the same homographies; with a calibration, a sentence saying so."""
    import asyncio

    sp = data_dir / "stereopi_rig" / "scene_photo"
    from stereovision.gui.app import nowrap_units

    raw = (cv2.imread(str(sp / "left.png")), cv2.imread(str(sp / "right.png")))
    app = _still_cameras_app("test-rectify", data_dir, raw)

    async def run() -> None:
        app._lock = asyncio.Lock()
        app._grab()
        await app.check_rows()
        assert "NOT rectified" in app.state.rows_label
        await app.rectify_from_features()
        said.append(app.state.rows_label)
        await app.check_rows()

    said: list = []
    asyncio.run(run())
    assert app.state.error == ""
    rect = app.homographies
    # the homographies' line, its numbers and units kept together as every line on the page
    assert said == [nowrap_units(rect.describe())] and said[0] != rect.describe()
    assert rect is not None and app.pair[0].shape[:2] == rect.size[::-1]
    assert app.state.rows_label.startswith("rectification ok")
    assert app.view is not None and app.view.result.max_disparity >= rect.max_disparity
    app._grab()  # the next pair from the cameras: rectified the same way
    np.testing.assert_array_equal(app.pair[0], rect.rectify(*raw)[0])
    assert app.state.source_label.endswith("(rectified from features)")

    async def again() -> None:
        await app.rectify_from_features()  # pressed a second time

    # It starts again from the raw pair: its homographies still fit the cameras' frames (the
    # second press rectified the rectified pair, and the next capture went unrectified).
    asyncio.run(again())
    assert app.homographies.input_size == (raw[0].shape[1], raw[0].shape[0])
    assert app.state.source_label.count("(rectified from features)") == 1
    app._grab()
    np.testing.assert_array_equal(app.pair[0], app.homographies.rectify(*raw)[0])
    assert app.state.source_label.count("(rectified from features)") == 1

    async def with_calib() -> None:
        from types import SimpleNamespace

        app.calib = SimpleNamespace(image_size=(app.pair[0].shape[1], app.pair[0].shape[0]))
        await app.rectify_from_features()

    asyncio.run(with_calib())
    assert app.state.rows_label == "this pair has a calibration: it is rectified with it"


def test_rectify_with_a_calib_that_fits_no_camera_mode_says_it_does_not_fit():
    """Cameras in a mode --calib does not fit (another aspect ratio): "Rectify" said "this pair
    has a calibration: it is rectified with it", of a pair no computation could use it on."""
    import asyncio
    from types import SimpleNamespace

    pytest.importorskip("trame")
    from stereovision.gui.app import StereoApp

    class State(SimpleNamespace):  # the page's state, as the button's handler uses it
        def __enter__(self) -> None:
            pass

        def __exit__(self, *exc: object) -> None:
            pass

    app = StereoApp.__new__(StereoApp)  # the button's handler alone: a page takes 0.7 s
    app.state = State(rows_label="")
    app.calib = app.source_calib = syn.calibration()  # 160x120
    frame = np.zeros((120, 320, 3), np.uint8)  # twice as wide
    app.pair = (frame, frame)
    asyncio.run(app.rectify_from_features())
    assert app.state.rows_label == (
        "the calibration does not fit this pair (calibration is for 160x120 images, the "
        "frames are 320x120: another aspect ratio (a camera mode that crops), which needs its "
        "own calibration): Rectify finds no homographies for a pair with one (start the page "
        "without --calib to rectify from features)"
    )


def test_rectify_uses_a_pair_already_rectified_as_given(data_dir):
    """ "Rectify" on a pair whose rows already agree (cones, a rectified dataset) warped it by
    homographies fitted to those rows: resampled, 455x378 px instead of 450x375. As `rectify`
    without --calib, the rows check now says it is rectified and the pair is used as given."""
    cones = data_dir / "middlebury2003" / "cones"
    raw = (cv2.imread(str(cones / "left.png")), cv2.imread(str(cones / "right.png")))

    class Cameras:
        def read(self):
            return raw

        def close(self):
            pass

    app = _scene_app("test-rectify-given", [data_dir], source=Cameras())
    app._grab()
    _run(app, app.recompute)
    assert app.state.computations == 1
    _run(app, app.rectify_from_features)
    assert app.state.error == ""
    got = re.fullmatch(
        r"already rectified \(rows median \|dy\| (0\.[0-9]+) px over ([0-9]+) matches, "
        r"tolerance 0\.5\): used as given",
        app.state.rows_label,
    )
    assert got is not None, app.state.rows_label
    assert float(got.group(1)) < 0.5 and int(got.group(2)) >= 30
    assert app.homographies is None and app.pair[0] is raw[0] and app.pair[0].shape == (375, 450, 3)
    assert app.state.computations == 1  # the result on show is this pair's: nothing to compute
    assert "rectified from features" not in app.state.source_label
    # a pair warped earlier (its homographies kept) goes back to the pair as it comes
    from stereovision.uncalibrated import rectify_uncalibrated

    app.homographies = rectify_uncalibrated(*raw)
    app._grab()
    assert app.pair[0].shape != raw[0].shape
    _run(app, app.rectify_from_features)
    assert app.homographies is None and app.pair[0] is raw[0]
    assert app.max_disparity is None  # the homographies' range went with them
    assert app.state.computations == 2 and " · 450×375 · " in app.state.stats


def test_an_image_folder_plays_its_pairs_one_per_capture(tmp_path):
    """The page could open two files or a scene, not a folder of pairs (what `capture` saves,
    or left/ + right/ camera folders). "Play" takes a folder's pairs as `batch` finds them,
    one per Capture, starting again after the last; a scene's calib.txt comes with its pair;
    a folder without pairs, or whose images lead outside --data, says so."""
    import shutil

    from stereovision.gui import bundled_data_dir

    cones = bundled_data_dir() / "cones"
    left, right = (cv2.imread(str(cones / f"{s}.png")) for s in ("left", "right"))
    data, outside = tmp_path / "data", tmp_path / "outside"
    seq, rig = data / "seq", data / "rig"
    for d in (seq, rig / "left", rig / "right", outside, data / "empty"):
        d.mkdir(parents=True)
    for k, scale in ((1, 1.0), (2, 0.5)):
        for side, img in (("left", left), ("right", right)):
            cv2.imwrite(str(seq / f"{side}_{k:04d}.png"), cv2.resize(img, None, fx=scale, fy=scale))
    for side, img in (("left", left), ("right", right)):
        cv2.imwrite(str(rig / side / "0001.png"), img)
        cv2.imwrite(str(outside / f"{side}.png"), img)
    shutil.copytree(cones, data / "scenes" / "cones")
    (data / "escape").mkdir()
    (data / "escape" / "left_0001.png").symlink_to(outside / "left.png")
    (data / "escape" / "right_0001.png").symlink_to(outside / "right.png")

    app = _scene_app("test-pair-folder", [data])
    assert str(seq.resolve()) in [i["value"] for i in app.state.pair_folders]
    app.state.pair_folder = str(seq)
    _play(app)
    assert app.state.error == "" and app.state.live
    assert app.state.source_label == "folder data/seq: pair 0001 (1 of 2)"
    np.testing.assert_array_equal(app.pair[0], left)
    assert app.calib is None
    _capture(app)
    assert app.state.source_label == "folder data/seq: pair 0002 (2 of 2)"
    assert app.pair[0].shape == (188, 225, 3)
    _capture(app)  # after the last, the first again
    assert app.state.source_label == "folder data/seq: pair 0001 (1 of 2)"
    app.state.pair_folder = str(rig)
    _play(app)
    assert app.state.source_label.startswith("folder data/rig: pair ")
    assert app.state.source_label.endswith(" (1 of 1)")
    np.testing.assert_array_equal(app.pair[1], right)
    app.state.pair_folder = str(data / "scenes")
    _play(app)
    assert app.state.error == "" and app.calib is not None  # the scene's calib.txt
    for bad in ("empty", "escape"):
        app.state.pair_folder = str(data / bad)
        _play(app)
        assert app.state.error == (
            f"no image pairs in data/{bad} (left_0001.png + right_0001.png, left/ + right/ "
            "folders, or scene folders with left.png + right.png)"
        ), bad
    app.state.pair_folder = str(seq / "left_0001.png")
    _play(app)
    assert app.state.error == "not a folder: data/seq/left_0001.png"
    assert app.state.source_label.startswith("folder data/scenes: pair ")  # still in use


def test_a_capture_of_a_folder_pair_of_two_sizes_is_said_and_keeps_the_pair(tmp_path):
    """Capture's pair whose two images differ in size (a ValueError of _grab) is said on the
    page and the pair on show stays (capture caught OSError and RuntimeError alone in a
    mutation audit, and no test failed)."""
    from stereovision.gui import bundled_data_dir

    cones = bundled_data_dir() / "cones"
    left, right = (cv2.imread(str(cones / f"{s}.png")) for s in ("left", "right"))
    seq = tmp_path / "data" / "seq"
    seq.mkdir(parents=True)
    for k in (1, 2):
        cv2.imwrite(str(seq / f"left_{k:04d}.png"), left)
        cv2.imwrite(str(seq / f"right_{k:04d}.png"), right if k == 1 else right[:, :200])
    app = _scene_app("test-folder-two-sizes", [tmp_path / "data"])
    spawned: list = []
    app._spawn = spawned.append
    app.state.pair_folder = str(seq)
    _play(app)
    assert app.state.error == "" and len(spawned) == 1
    shown = app.pair
    _capture(app)
    assert app.state.error.startswith("folder data/seq: pair 0002 (2 of 2): left 450")
    assert app.state.status == "error" and app.state.captures == 1 and len(spawned) == 1
    assert app.pair is shown and app.state.source_label == "folder data/seq: pair 0001 (1 of 2)"


def test_rectify_and_check_rows_of_a_pair_replaced_meanwhile_are_dropped(data_dir, monkeypatch):
    """A scene chosen while "Rectify" or "Check rows" ran on the cameras' pair: their results
    were put on the new scene (its label read "(rectified from features)" above the cameras'
    rectified pair, its rows line was the cameras' verdict). The newer choice wins."""
    import asyncio
    import threading

    import stereovision.rectification_check as rc

    sp = data_dir / "stereopi_rig" / "scene_photo"
    raw = (cv2.imread(str(sp / "left.png")), cv2.imread(str(sp / "right.png")))
    venus = data_dir / "middlebury2001" / "venus"
    app = _still_cameras_app("test-superseded-buttons", data_dir, raw)
    real = rc.check_rectification
    started, gate = threading.Event(), threading.Event()

    def held(*args: Any, **kwargs: Any) -> Any:
        started.set()
        gate.wait(60)
        return real(*args, **kwargs)

    monkeypatch.setattr(rc, "check_rectification", held)
    tasks: list = []

    async def pressed_then_scene(action: Any) -> None:
        started.clear()
        gate.clear()
        tasks.clear()
        _queue_spawns(app, tasks)
        app._grab()
        running = asyncio.ensure_future(action())
        await asyncio.get_running_loop().run_in_executor(None, started.wait, 60)
        app._on_scene(scene=str(venus))  # chosen while the button's work runs
        gate.set()
        await running
        await asyncio.gather(*tasks)

    label = f"scene {app.folders.label(app.folders.resolve(str(venus)))}"
    for action in (app.rectify_from_features, app.check_rows):
        asyncio.run(pressed_then_scene(action))
        assert app.state.error == "" and app.homographies is None
        assert app.pair[0].shape == (383, 434, 3) and app.state.source_label == label
        assert app.state.rows_label == ""
        assert app.view is not None and app.view.result.disparity.shape == (383, 434)


@pytest.mark.parametrize("fails", [False, True])
def test_a_floor_found_for_a_pair_replaced_meanwhile_is_dropped(data_dir, monkeypatch, fails):
    """Find floor on a scene, then another scene chosen while the fit ran: the first scene's
    floor picture and height were put on the page under the new scene's name while it computed
    (its images shown, the previous results cleared), until its own depth map came. A fit that
    fails then is not said over the new scene either (saying it survived a mutation audit)."""
    import asyncio
    import threading

    import stereovision.gui.app as app_mod

    first = data_dir / "tartanair" / "oldtown_easy_p000_001116"
    venus = data_dir / "middlebury2001" / "venus"
    app = _scene_app("test-floor-superseded", [data_dir])
    real = app_mod._floor_view
    started, gate = threading.Event(), threading.Event()

    def held(res: Any) -> Any:
        started.set()
        gate.wait(60)
        if fails:
            raise ValueError("no floor here")
        return real(res)

    monkeypatch.setattr(app_mod, "_floor_view", held)
    tasks: list = []

    def choose(scene: Path) -> None:
        app.state.scene = str(scene)
        app._on_scene(scene=str(scene))

    async def run() -> None:
        _queue_spawns(app, tasks)
        choose(first)
        await asyncio.gather(*tasks)
        floor = asyncio.ensure_future(app.find_floor())
        await asyncio.get_running_loop().run_in_executor(None, started.wait, 60)
        choose(venus)  # chosen while the floor is fitted
        await asyncio.sleep(0)
        gate.set()
        await floor
        # venus computes: its images are on the page, no result (or error) of the previous scene
        assert app.state.img_floor == "" and app.state.floor_label == ""
        assert app.state.error == ""
        await asyncio.gather(*tasks)

    asyncio.run(run())
    assert app.state.error == "" and app.state.source_label.endswith("venus")
    assert app.view is not None and app.view.result.disparity.shape == (383, 434)
    assert app.state.img_floor == "" and app.state.floor_label == ""


def test_capture_averages_still_frames_when_asked(data_dir):
    """The acquisition panel's "average 8 still frames", in-process: cameras giving venus with
    fresh noise of 8 grey levels on every read. Off, a capture is one noisy frame; on, it is
    the mean of 8 (its noise about a third) and the label says so."""
    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision.gui.app import AVERAGE_FRAMES, StereoApp
    from tests.test_exposure import noisy

    venus = data_dir / "middlebury2001" / "venus"
    clean = [cv2.imread(str(venus / f"{s}.png")) for s in ("left", "right")]
    rng = np.random.default_rng(0)

    class Cameras:
        reads = 0

        def read(self):
            Cameras.reads += 1
            return tuple(noisy(c, 8.0, rng) for c in clean)

        def close(self):
            pass

    app = StereoApp(
        get_server("test-average", client_type="vue3"),
        AllowedFolders([data_dir]),
        data_dir / "middlebury2003" / "cones",
        source=Cameras(),
    )

    def noise() -> float:
        return float(np.std(app.pair[0].astype(np.float32) - clean[0]))

    app._grab()
    single = noise()
    assert Cameras.reads == 1 and "averaged" not in app.state.source_label
    app.state.average = True
    app._grab()
    assert Cameras.reads == 1 + AVERAGE_FRAMES
    assert noise() < 0.45 * single, (noise(), single)
    assert app.state.source_label.endswith("(8.0 frames averaged)")


def test_averaging_16_bit_frames_is_refused_naming_the_source(tmp_path):
    """The acquisition panel's "average" of a 16-bit image sequence said "left: expected a
    uint8 image, got uint16", the filter's words for an argument the user never passed (as
    capture --temporal did before 256afa8d); it now says capture --temporal's words. Without
    averaging the frames are read as they are."""
    from stereovision.gui.app import _read_pair
    from stereovision.gui.sources import open_stereo_source

    for i in range(3):
        deep = np.full((24, 32), 100 + i, np.uint16) * 257
        cv2.imwrite(str(tmp_path / f"left_{i:03d}.png"), deep)
        cv2.imwrite(str(tmp_path / f"right_{i:03d}.png"), (deep // 257).astype(np.uint8))
    src = open_stereo_source(str(tmp_path / "left_%03d.png"), str(tmp_path / "right_%03d.png"))
    try:
        assert _read_pair(src, False).left.dtype == np.uint16
        with pytest.raises(ValueError) as info:
            _read_pair(src, True)
    finally:
        src.close()
    assert str(info.value) == (
        "temporal averaging takes 8-bit frames: the left source delivers uint16 ones (a 16-bit "
        "image sequence?); convert them to 8 bits, or leave the averaging out"
    )


def test_a_16_bit_pair_is_shown_as_it_looks_not_white():
    """A 16-bit image sequence's pair went to the page as it came: JPEG holds 8 bits, and
    OpenCV cut every level to 255, both images shown white. It is shown at 8 bits now
    (uint16 / 257, a float image in [0, 1] times 255), as an 8-bit pair of it is."""
    from stereovision.gui.app import _data_url

    img = np.tile(np.linspace(20, 220, 64).astype(np.uint8), (48, 1))
    flat = _decode(_data_url(img))
    for deep in (img.astype(np.uint16) * 257, img.astype(np.float32) / 255):
        shown = _decode(_data_url(deep))
        assert np.abs(shown - flat).max() <= 1, (deep.dtype, shown.min(), shown.max())
    assert flat.min() < 30 and flat.max() > 210


def test_cameras_that_cannot_be_paired_leave_the_open_ones_in_use(tmp_path):
    """Two videos of different sizes open, but give no pair: "Open" closed the cameras in use
    and kept the unusable pair, so every later Capture failed (and a capture was labelled with
    the names typed in the fields, not those of the cameras it came from). The open cameras
    now stay until new ones have given a pair."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.sources import open_stereo_source

    cones = bundled_data_dir() / "cones"
    left, right = (cv2.imread(str(cones / f"{s}.png")) for s in ("left", "right"))
    lv = _write_video(tmp_path / "l.avi", left)
    rv = _write_video(tmp_path / "r.avi", right)
    small = _write_video(tmp_path / "small.avi", cv2.resize(right, (400, 300)))

    lonely = _scene_app("test-cameras-unpaired-none", [tmp_path])
    lonely.state.cam_left, lonely.state.cam_right = str(lv), str(small)
    _open_cameras(lonely)
    assert lonely.state.error.startswith("right source") and "400x300" in lonely.state.error
    assert lonely.source is None and lonely.state.live is False and lonely.pair is None

    app = _scene_app(
        "test-cameras-unpaired",
        [tmp_path],
        source=open_stereo_source(str(lv), str(rv)),
        source_names=(str(lv), str(rv)),
    )
    app._grab()
    assert app.state.source_label == "cameras l.avi / r.avi"
    app.state.cam_right = str(small)
    _open_cameras(app)
    assert app.state.error.startswith("right source") and "400x300" in app.state.error
    # video files in use: not said to be "the cameras"
    assert app.state.error.endswith("(the source in use, l.avi and r.avi, is unchanged)")
    app.state.error = ""
    _capture(app)  # from the cameras still open
    assert app.state.error == "" and app.state.captures == 1
    assert app.state.source_label == "cameras l.avi / r.avi"
    assert app.pair[0].shape == app.pair[1].shape and app.pair[0].shape[1] == 450
    app.source.close()


def test_open_cameras_asks_the_chosen_pixel_format(data_dir, monkeypatch):
    """The camera row's "format" select, in-process: "MJPG" and "YUYV" reach the cameras as
    ``StereoCamera(..., fourcc=)`` (what ``capture --fourcc`` asks), "driver" asks nothing, and
    ``stereovision gui --fourcc`` does the same for the cameras it opens."""
    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision import capture
    from stereovision.gui import add_arguments, build_app
    from stereovision.gui.app import FOURCCS, StereoApp

    asked: list[str | None] = []
    frame = cv2.imread(str(data_dir / "middlebury2001" / "venus" / "left.png"))

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            asked.append(fourcc)

        def read(self):
            return frame, frame

        def close(self):
            pass

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    app = StereoApp(
        get_server("test-fourcc", client_type="vue3"),
        AllowedFolders([data_dir]),
        data_dir / "middlebury2003" / "cones",
    )
    monkeypatch.setattr(app, "_spawn", lambda coro: coro.close())  # no event loop here
    assert app.state.fourccs == list(FOURCCS) and app.state.fourcc == "driver"
    app.state.cam_left, app.state.cam_right = "0", "1"
    for choice in ("MJPG", "YUYV", "driver"):
        app.state.fourcc = choice
        _open_cameras(app)
        assert app.state.error == "" and app.state.live
    assert asked == ["MJPG", "YUYV", None]
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    built = build_app(parser.parse_args(["--left", "0", "--right", "1", "--fourcc", "MJPG"]))
    assert asked[-1] == "MJPG" and built.state.live
    with pytest.raises(SystemExit):  # refused by argparse, in the option's name
        parser.parse_args(["--left", "0", "--right", "1", "--fourcc", "MJPEG"])
    with pytest.raises(ValueError, match="--fourcc asks the cameras for a format"):
        build_app(parser.parse_args(["--fourcc", "MJPG"]))


def test_gui_read_timeout_reaches_every_camera_read(data_dir, monkeypatch):
    """`gui` had no --read-timeout (capture and stream now have one) and read its cameras
    without a limit. The option reaches the opens and reads of the cameras it opens and of
    those opened on the page: 0.2 s, 'none' (no limit), capture's 10 s when not given; a bag
    is refused."""
    pytest.importorskip("trame")
    from trame.app import get_server

    from stereovision import capture
    from stereovision.gui import add_arguments, app, build_app

    frame = cv2.imread(str(data_dir / "middlebury2001" / "venus" / "left.png"))
    timeouts: list[float | None] = []
    opens: list[float | None] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            opens.append(open_timeout)

        def read(self):
            return frame, frame

        def close(self):
            pass

    def spy(camera, timeout=capture.DEFAULT_READ_TIMEOUT):
        timeouts.append(timeout)
        return camera.read()

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    monkeypatch.setattr(sources, "read_within", spy)
    apps: list[dict[str, Any]] = []
    real_app = app.StereoApp
    # the app itself (a 3-D plotter, a second or so) is built once, below
    monkeypatch.setattr(app, "StereoApp", lambda *a, **kw: apps.append(kw) or kw)
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    cams = ["--left", "0", "--right", "1"]
    for given, timeout in (
        (["--read-timeout", "0.2"], 0.2),
        (["--read-timeout", "none"], None),
        ([], capture.DEFAULT_READ_TIMEOUT),
    ):
        opens.clear()
        built = build_app(parser.parse_args([*cams, *given]))
        timeouts.clear()
        built["source"].read()
        assert timeouts == [timeout] and built["read_timeout"] == timeout
        assert opens == [timeout]  # the cameras' open is bounded as their reads
    # no cameras given: the app opens those typed on the page with it
    assert build_app(parser.parse_args(["--read-timeout", "0.2"]))["read_timeout"] == 0.2
    page = real_app(
        get_server("test-read-timeout", client_type="vue3"),
        AllowedFolders([data_dir]),
        data_dir / "middlebury2003" / "cones",
        read_timeout=0.2,
    )
    monkeypatch.setattr(page, "_spawn", lambda coro: coro.close())  # no event loop here
    page.state.cam_left, page.state.cam_right = "0", "1"
    timeouts.clear()
    opens.clear()
    _open_cameras(page)
    assert page.state.error == "" and page.state.live and timeouts == [0.2]
    # the page's open runs in a thread of its own, bounded by the page's wait for it (0.2 s,
    # test_a_wedged_camera_open_leaves_the_page_free), not inside the cameras' open
    assert opens == [None]
    with pytest.raises(ValueError, match=r"^--read-timeout bounds a camera's read: a bag is"):
        build_app(parser.parse_args(["--from-bag", "x.bag", "--read-timeout", "5"]))


def _collect_opens(app: Any) -> list[Any]:
    """Run the page's spawned camera opens as tasks of the test's loop (returned, to await);
    other spawned work (an opened pair's computation) is closed unrun."""
    import asyncio

    opens: list[Any] = []
    app._spawn = lambda coro: (
        opens.append(asyncio.ensure_future(coro)) if "_open" in coro.__qualname__ else coro.close()
    )
    return opens


def test_a_wedged_camera_open_leaves_the_page_free(monkeypatch):
    """ "Open" ran the cameras' open in the page's handler: a wedged camera froze the page for
    the whole --read-timeout, and each retry left one more thread blocked in it. The handler
    now returns at once, the page saying "opening ..."; the open is given up after the
    timeout, said on the page; another Open of those cameras is refused, in words, until the
    given-up open returns (its late cameras are closed then); a camera that opens is used."""
    import asyncio
    import threading
    import time

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    release = threading.Event()
    made: list[Any] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            self.closed = False
            made.append(self)
            release.wait(1.0)  # a wedged device (bounded: a broken app cannot hang the test)

        def read(self):
            return frame, frame

        def close(self):
            self.closed = True

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    app = _scene_app("test-wedged-open", [bundled_data_dir()], read_timeout=0.2)
    app.state.cam_left, app.state.cam_right = "0", "1"
    # the opens are run here; the computation of an opened pair is not
    opens = _collect_opens(app)

    async def clicks() -> None:
        t0 = time.perf_counter()
        app.open_cameras()
        assert time.perf_counter() - t0 < 0.1  # the handler returned at once
        assert app.state.status == "opening camera 0 and camera 1..." and app.state.error == ""
        app.open_cameras()  # clicked again while it opens
        refused = (
            "camera 0 is still opening (an earlier Open has not returned): wait for it, or "
            "unplug and replug the camera"
        )
        assert app.state.error == refused and len(opens) == 1
        await opens[0]
        assert app.state.status == "error" and app.state.error == (
            "camera 0 and camera 1 did not open within 0.2 s (the open did not return: a wedged "
            "camera or driver, or a stalled stream); unplug and replug it, or give gui a "
            "longer --read-timeout"
        )
        app.open_cameras()  # a retry while the given-up open is still inside the camera
        assert app.state.error == refused and len(opens) == 1 and len(made) == 1
        assert app.source is None and app.state.live is False
        release.set()  # the wedged open returns now
        for _ in range(100):
            if not app._opening:
                break
            await asyncio.sleep(0.01)
        assert made[0].closed  # nobody took it: closed (it held the devices)
        app.open_cameras()
        await opens[1]
        assert len(made) == 2 and not made[1].closed and app.source is not None
        assert app.state.error == "" and app.state.live
        assert app.state.source_label == "cameras 0 / 1" and app.state.captures == 1

    asyncio.run(clicks())


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="V4L2 device paths")
def test_a_camera_still_opening_is_refused_by_its_dev_video_path_too(monkeypatch):
    """The pending-open check compared the sources as typed: camera 0 still opening, its
    ``/dev/video0`` (accepted where a data folder holds /dev) was opened again beside it."""
    import asyncio
    import threading

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    release = threading.Event()

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            release.wait(1.0)  # wedged (bounded: a broken app cannot hang the test)

        def read(self):
            return frame, frame

        def close(self):
            pass

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    app = _scene_app("test-dev-video-pending", [bundled_data_dir()], read_timeout=0.2)
    # as if /dev were an allowed folder holding the device (no camera on the test machine)
    monkeypatch.setattr(app.folders, "resolve", lambda p: Path(p))
    opens = _collect_opens(app)

    async def clicks() -> None:
        app.state.cam_left, app.state.cam_right = "0", "1"
        app.open_cameras()
        app.state.cam_left, app.state.cam_right = "/dev/video0", "2"
        app.open_cameras()
        assert len(opens) == 1
        assert app.state.error.startswith("video0 is still opening (an earlier Open")
        release.set()
        await opens[0]
        for _ in range(100):
            if not app._opening:
                break
            await asyncio.sleep(0.01)
        assert not app._opening  # the keys settled under the same names

    asyncio.run(clicks())


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="V4L2 device paths")
def test_a_camera_typed_by_its_device_node_or_by_id_link_opens(tmp_path, monkeypatch):
    """A camera typed in the page's field as ``/dev/video2`` or by its ``/dev/v4l/by-id/...``
    link (how a rig keeps left and right apart across reboots) was refused as "path outside
    the allowed folders" (unless /dev was a --data folder), where its index "2" opens. It
    opens as that node; other paths outside the allowed folders are still refused."""
    import asyncio

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    opened: list[tuple[Any, Any]] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            opened.append((left, right))

        def read(self):
            return frame, frame

        def close(self):
            pass

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    links = tmp_path / "by-id"  # not an allowed folder
    links.mkdir()
    (links / "usb-Rig_Left-video-index0").symlink_to("/dev/video7")
    app = _scene_app("test-dev-video-typed", [bundled_data_dir()])
    opens = _collect_opens(app)

    async def open_typed(left: str, right: str) -> None:
        app.state.cam_left, app.state.cam_right = left, right
        app.open_cameras()
        if opens:
            await opens.pop()

    asyncio.run(open_typed(str(links / "usb-Rig_Left-video-index0"), "/dev/video8"))
    assert app.state.error == "" and opened == [("/dev/video7", "/dev/video8")]
    assert app.state.source_label == "cameras usb-Rig_Left-video-index0 / video8"
    outside = tmp_path / "video9"  # named like a node, not one
    outside.touch()
    asyncio.run(open_typed(str(outside), "/dev/video8"))
    assert app.state.error.startswith("path outside the allowed folders: ")
    assert len(opened) == 1


def test_a_late_camera_open_does_not_replace_a_newer_choice_nor_hide_its_error(monkeypatch):
    """The page's Open runs in a thread and is waited for: cameras 0/1 still opening (slow, not
    yet given up) when cameras 2/3 were opened and used replaced them once they came, the
    older click winning over the newer; and an open failing with an error of another type
    than OSError/ValueError/RuntimeError (cv2.error from a backend) left the page saying
    "opening camera 4 and camera 5..." for good, the error lost in the server's log. The
    late cameras are closed, the newer ones stay; the error is said on the page."""
    import asyncio
    import threading

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    release = threading.Event()
    made: dict[Any, Any] = {}

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            if left == 4:
                raise cv2.error("backend failed")
            self.closed = False
            made[left] = self
            if left == 0:
                release.wait(1.0)  # slow, within the page's 2 s

        def read(self):
            return frame, frame

        def close(self):
            self.closed = True

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    app = _scene_app("test-late-open", [bundled_data_dir()], read_timeout=2.0)
    opens = _collect_opens(app)

    async def clicks() -> None:
        app.state.cam_left, app.state.cam_right = "0", "1"
        app.open_cameras()
        app.state.cam_left, app.state.cam_right = "2", "3"
        app.open_cameras()
        await opens[1]
        assert app.source._camera is made[2] and app.state.source_label == "cameras 2 / 3"
        release.set()
        await opens[0]
        assert made[0].closed and not made[2].closed
        assert app.source._camera is made[2] and app.state.source_label == "cameras 2 / 3"
        assert not app._opening
        app.state.cam_left, app.state.cam_right = "4", "5"
        app.open_cameras()
        await opens[2]
        assert app.state.status == "error" and app.state.error == (
            "backend failed (the cameras in use, camera 2 and camera 3, are unchanged)"
        )
        assert app.source._camera is made[2] and not app._opening

    asyncio.run(clicks())


def test_a_scene_chosen_while_cameras_open_stays_on_show(monkeypatch):
    """A scene chosen from the list while an Open was still under way was replaced by the
    cameras' pair once they came (the list emptied), the older click winning. The scene
    stays; the late cameras are closed."""
    import asyncio
    import threading

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    release = threading.Event()
    made: list[Any] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            self.closed = False
            made.append(self)
            release.wait(1.0)

        def read(self):
            return frame, frame

        def close(self):
            self.closed = True

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    app = _scene_app("test-scene-while-open", [bundled_data_dir()], read_timeout=2.0)
    app.state.cam_left, app.state.cam_right = "0", "1"
    opens = _collect_opens(app)
    cones = str((bundled_data_dir() / "cones").resolve())

    async def clicks() -> None:
        app.open_cameras()
        await asyncio.sleep(0)  # the open's thread is inside the cameras
        app._on_scene(scene=cones)
        release.set()
        await opens[0]
        assert made[0].closed and app.source is None
        assert app.state.source_label.startswith("scene ") and app._scene == cones

    asyncio.run(clicks())


def _collect_reads(app: Any) -> list[Any]:
    """Run the page's spawned camera opens and reads (Capture, start-up, Play) as tasks of the
    test's loop (returned, to await); other spawned work (a pair's computation) is closed
    unrun."""
    import asyncio

    tasks: list[Any] = []

    def spawn(coro: Any) -> None:
        if coro.__qualname__.endswith(("._open", "._capture", "._first_pair")):
            tasks.append(asyncio.ensure_future(coro))
        else:
            coro.close()

    app._spawn = spawn
    return tasks


async def _until(done: Callable[[], bool]) -> None:
    """Let the loop run until ``done()`` (at most 10 s: the work runs on executor threads,
    which a loaded 2-core machine starved past a one-second limit during a whole-suite run)."""
    import asyncio

    for _ in range(1000):
        if done():
            return
        await asyncio.sleep(0.01)
    raise AssertionError("not done within 10 s")


def test_the_end_of_a_computation_leaves_a_pending_reads_status(monkeypatch):
    """A Capture clicked while a pair computes said "reading ...", and the computation's end
    then said "ready" (or "error") while the read went on, as it did over an Open's "opening
    ...". The end, and its progress meanwhile, say the read or open; with neither under way
    the end says "ready" as before."""
    import asyncio
    import threading

    from stereovision import capture
    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    read_gate, compute_gate, open_gate = threading.Event(), threading.Event(), threading.Event()
    reads: list[Any] = []
    opens: list[Any] = []
    outcome: list[BaseException] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            opens.append(self)
            open_gate.wait(1.0)

        def read(self):
            reads.append(self)
            read_gate.wait(1.0)  # bounded: a broken app cannot hang the test
            return frame, frame

        def close(self):
            pass

    real = gui_app.compute_view

    def gated(*args: Any, **kwargs: Any) -> Any:
        compute_gate.wait(1.0)
        if outcome:
            raise outcome[0]
        return real(*args, **kwargs)

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    monkeypatch.setattr(gui_app, "compute_view", gated)
    app = _scene_app("test-compute-end-reading", [bundled_data_dir()], read_timeout=2.0)
    app.state.cam_left, app.state.cam_right = "0", "1"
    tasks = _collect_reads(app)
    reading = "reading camera 0 and camera 1..."

    async def computed_during_a_capture(n: int) -> None:
        read_gate.clear()
        compute_gate.clear()
        computing = asyncio.ensure_future(app.recompute())
        await _until(lambda: app._computing)
        app.capture()
        await _until(lambda: len(reads) == n)
        assert app.state.status == reading
        app._set_progress(50, "census")  # a progress step meanwhile: both said
        assert app.state.status == f"census; {reading}"
        compute_gate.set()
        await computing
        assert app.state.status == reading and not app.state.busy
        read_gate.set()
        await tasks[-1]

    async def clicks() -> None:
        app._lock = asyncio.Lock()
        read_gate.set()
        open_gate.set()
        app.open_cameras()
        await tasks[0]  # open, their pair taken (its computation closed unrun)
        await computed_during_a_capture(2)
        assert app.state.computations == 1 and app.state.error == ""
        assert app.state.captures == 2
        outcome.append(ValueError("bad pair"))  # a computation that fails meanwhile
        await computed_during_a_capture(3)
        assert app.state.error.startswith("bad pair") and app.state.computations == 1
        outcome.clear()
        compute_gate.set()
        await app.recompute()  # no read under way
        assert app.state.status == "ready" and app.state.computations == 2
        compute_gate.clear()
        open_gate.clear()
        computing = asyncio.ensure_future(app.recompute())
        await _until(lambda: app._computing)
        app.open_cameras()
        await _until(lambda: len(opens) == 2)
        compute_gate.set()
        await computing
        assert app.state.status == "opening camera 0 and camera 1..."
        assert app.state.computations == 3
        open_gate.set()
        await tasks[-1]
        assert app.state.error == "" and app.state.captures == 4

    asyncio.run(clicks())


def test_a_read_that_fails_during_a_computation_is_said_after_it(monkeypatch):
    """A Capture's read that failed while a pair computed left "census; reading camera 0 and
    camera 1..." in the status until the computation's end, which then said "ready" and
    cleared the read's error: the failure was never seen. The reading part goes when the read
    returns; the read's error stays on the page after the computation ("error")."""
    import asyncio
    import threading

    from stereovision import capture
    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    read_gate, compute_gate = threading.Event(), threading.Event()
    reads: list[Any] = []
    fail: list[str] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            if left == 7:
                raise OSError("camera 7 did not open")

        def read(self):
            reads.append(self)
            read_gate.wait(1.0)  # bounded: a broken app cannot hang the test
            if fail:
                raise OSError(fail[0])
            return frame, frame

        def close(self):
            pass

    real = gui_app.compute_view

    def gated(*args: Any, **kwargs: Any) -> Any:
        compute_gate.wait(1.0)
        return real(*args, **kwargs)

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    monkeypatch.setattr(gui_app, "compute_view", gated)
    app = _scene_app("test-read-fails-computing", [bundled_data_dir()], read_timeout=2.0)
    app.state.cam_left, app.state.cam_right = "0", "1"
    tasks = _collect_reads(app)

    async def clicks() -> None:
        app._lock = asyncio.Lock()
        read_gate.set()
        app.open_cameras()
        await tasks[0]
        read_gate.clear()
        compute_gate.clear()
        computing = asyncio.ensure_future(app.recompute())
        await _until(lambda: app._computing)
        fail.append("camera 0 delivered no frame in 2 s")
        app.capture()
        await _until(lambda: len(reads) == 2)
        app._set_progress(50, "census")
        assert app.state.status == "census; reading camera 0 and camera 1..."
        read_gate.set()
        await tasks[-1]
        # the computation goes on: its step alone, the read's error beside it
        assert app.state.status == "census" and app.state.busy
        assert app.state.error == "camera 0 delivered no frame in 2 s"
        compute_gate.set()
        await computing
        assert app.state.computations == 1 and not app.state.busy
        assert app.state.status == "error"
        assert app.state.error == "camera 0 delivered no frame in 2 s"
        # the next computation, with nothing failed meanwhile, clears it as before
        await app.recompute()
        assert (app.state.status, app.state.error) == ("ready", "")
        assert app.state.computations == 2
        # an Open whose first read fails while a pair computes: the same
        read_gate.clear()
        compute_gate.clear()
        computing = asyncio.ensure_future(app.recompute())
        await _until(lambda: app._computing)
        app.state.cam_left, app.state.cam_right = "2", "3"
        app.open_cameras()
        await _until(lambda: len(reads) == 3)
        read_gate.set()
        await tasks[-1]
        said = (
            "camera 0 delivered no frame in 2 s "
            "(the cameras in use, camera 0 and camera 1, are unchanged)"
        )
        assert (app.state.status, app.state.error) == ("computing (fast)", said)
        compute_gate.set()
        await computing
        assert (app.state.status, app.state.error) == ("error", said)
        assert app.state.source_label == "cameras 0 / 1"
        # an Open that fails (the cameras do not open) while a pair computes: the same
        compute_gate.clear()
        computing = asyncio.ensure_future(app.recompute())
        await _until(lambda: app._computing)
        app.state.cam_left, app.state.cam_right = "7", "8"
        app.open_cameras()
        await tasks[-1]
        said = "camera 7 did not open (the cameras in use, camera 0 and camera 1, are unchanged)"
        assert (app.state.status, app.state.error) == ("computing (fast)", said)
        compute_gate.set()
        await computing
        assert (app.state.status, app.state.error) == ("error", said)

    asyncio.run(clicks())


#: A pair refused by the page (:meth:`StereoApp._calib_for`), in the tests below.
_REFUSED = "calibration is for 640x480 images, got 450x375"


def _refuse_pairs(app: Any) -> None:
    """From now, every pair read is refused by ``app`` (as a --calib of another size)."""

    def refuse(left: Any) -> Any:
        raise ValueError(_REFUSED)

    app._calib_for = refuse


def _cameras_computing(monkeypatch: Any, name: str) -> tuple[Any, Any, Any]:
    """``(app, during, open_gate)``: an app on fake cameras (camera 5's open wedged until
    ``open_gate`` is set; ``--read-timeout`` 0.3 s), and ``during(click, said, first)``, a
    coroutine: cameras 0 / 1 opened, then ``first()``, then ``click`` while a pair computes
    says ``said``, which outlasts the computation's end ("error") until the next one."""
    import asyncio
    import threading

    from stereovision import capture
    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    compute_gate, open_gate = threading.Event(), threading.Event()

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            if left == 5:
                open_gate.wait(2.0)  # bounded: a broken app cannot hang the test

        def read(self):
            return frame, frame

        def close(self):
            pass

    real = gui_app.compute_view

    def gated(*args: Any, **kwargs: Any) -> Any:
        compute_gate.wait(1.0)
        return real(*args, **kwargs)

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    monkeypatch.setattr(gui_app, "compute_view", gated)
    app = _scene_app(name, [bundled_data_dir()], read_timeout=0.3)
    app.state.cam_left, app.state.cam_right = "0", "1"
    tasks = _collect_reads(app)

    async def during(click: Callable[[], None], said: str, first: Callable[[], None]) -> None:
        app._lock = asyncio.Lock()
        app.open_cameras()  # their first pair on show
        await tasks[-1]
        assert app.state.error == "" and app.state.source_label == "cameras 0 / 1"
        first()
        compute_gate.clear()
        computing = asyncio.ensure_future(app.recompute())
        await _until(lambda: app._computing)
        click()
        await tasks[-1]
        assert (app.state.status, app.state.error) == ("computing (fast)", said)
        compute_gate.set()
        await computing
        assert (app.state.status, app.state.error) == ("error", said)
        assert app.state.source_label == "cameras 0 / 1"
        await app.recompute()  # nothing failed meanwhile: cleared as before
        assert (app.state.status, app.state.error) == ("ready", "")

    compute_gate.set()
    return app, during, open_gate


def test_a_captured_pair_refused_during_a_computation_is_said_after_it(monkeypatch):
    """A Capture's pair refused (``_capture`` -> ``_use_pair``) while a pair computed: the
    keep-the-error flag off there passed every test. It is still said after the computation."""
    import asyncio

    app, during, _ = _cameras_computing(monkeypatch, "test-capture-refused-computing")

    asyncio.run(during(app.capture, _REFUSED, lambda: _refuse_pairs(app)))


def test_an_opened_pair_refused_during_a_computation_is_said_after_it(monkeypatch):
    """An Open's first pair refused (``_switch_source``'s failure path) while a pair computed:
    the keep-the-error flag off there passed every test. It is still said after the
    computation, the cameras in use kept."""
    import asyncio

    app, during, _ = _cameras_computing(monkeypatch, "test-open-refused-computing")

    def first() -> None:
        _refuse_pairs(app)
        app.state.cam_left, app.state.cam_right = "2", "3"

    said = f"{_REFUSED} (the cameras in use, camera 0 and camera 1, are unchanged)"
    asyncio.run(during(app.open_cameras, said, first))


def test_an_open_given_up_during_a_computation_is_said_after_it(monkeypatch):
    """An Open that did not return within --read-timeout while a pair computed: the
    keep-the-error flag off there passed every test. It is still said after the
    computation."""
    import asyncio

    app, during, open_gate = _cameras_computing(monkeypatch, "test-open-timeout-computing")
    said = (
        "camera 5 and camera 6 did not open within 0.3 s (the open did not return: a wedged "
        "camera or driver, or a stalled stream); unplug and replug it, or give gui a longer "
        "--read-timeout (the cameras in use, camera 0 and camera 1, are unchanged)"
    )

    def first() -> None:
        app.state.cam_left, app.state.cam_right = "5", "6"

    try:
        asyncio.run(during(app.open_cameras, said, first))
    finally:
        open_gate.set()  # the wedged open returns: its cameras are closed


def test_start_up_cameras_and_play_read_their_first_pair_off_the_page(tmp_path, monkeypatch):
    """The first pair of cameras given at start-up (--left/--right), and of an image folder's
    "Play", were read in the page's handler: a camera that hung (or a folder on a stalled
    share) froze the page. They are read in a thread as a Capture's, the page saying
    "reading ..." meanwhile; the pair, or the read's error, comes after."""
    import asyncio
    import threading
    import time

    import stereovision.io as svio
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    gate, inside = threading.Event(), threading.Event()
    fail: list[str] = []

    class Cameras:
        def read(self):
            inside.set()
            gate.wait(1.0)  # a wedged read (bounded: a broken app cannot hang the test)
            if fail:
                raise OSError(fail[0])
            return frame.copy(), frame.copy()

        def close(self):
            pass

    seq = tmp_path / "seq"
    seq.mkdir()
    for side in ("left", "right"):
        cv2.imwrite(str(seq / f"{side}_0001.png"), frame)
    real = svio.read_image  # the folder's reader (read_image decodes without imread)

    def held(*args: Any, **kwargs: Any) -> Any:
        inside.set()
        gate.wait(1.0)
        return real(*args, **kwargs)

    monkeypatch.setattr(svio, "read_image", held)

    def started(name: str) -> Any:
        app = _scene_app(
            name, [bundled_data_dir(), tmp_path], source=Cameras(), source_names=("0", "1")
        )
        return app, _collect_reads(app)

    async def clicks() -> None:
        app, tasks = started("test-start-up-read")
        for step in ("start-up", "play"):
            gate.clear()
            inside.clear()
            t0 = time.perf_counter()
            if step == "start-up":
                app._on_ready()
                said = "reading camera 0 and camera 1..."
            else:
                app.state.pair_folder = str(seq)
                app.open_pair_folder()
                said = f"reading folder {tmp_path.name}/seq..."
            assert time.perf_counter() - t0 < 0.2, step  # the handler returned at once
            assert app.state.status == said and app.state.error == "", step
            await _until(inside.is_set)
            gate.set()
            await tasks[-1]
            assert app.state.error == "" and app.pair is not None, step
        assert app.state.source_label == f"folder {tmp_path.name}/seq: pair 0001 (1 of 1)"

        fail.append("camera 0 delivered no frame in 5 s")
        app, tasks = started("test-start-up-read-fails")
        gate.clear()
        app._on_ready()
        assert app.state.status == "reading camera 0 and camera 1..."
        gate.set()
        await tasks[0]
        assert app.state.error == "camera 0 delivered no frame in 5 s"
        assert app.state.status == "error" and app.pair is None and app._reading == []

    asyncio.run(clicks())


def test_capture_waits_for_the_first_pair_of_a_folder_being_played(tmp_path, monkeypatch):
    """Play's first pair now comes from a thread; a Capture clicked before it came said "no
    camera open: give --left/--right or open cameras below" (none yet: the folder was chosen),
    or read the start-up cameras the folder replaces, their pair shown and computed before the
    folder's. It is refused in words until that pair comes; then Capture plays the folder."""
    import asyncio
    import threading

    import stereovision.io as svio
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    gate = threading.Event()
    camera_reads: list[int] = []

    class Cameras:
        def read(self):
            camera_reads.append(1)
            return frame.copy(), frame.copy()

        def close(self):
            pass

    seq = tmp_path / "seq"
    seq.mkdir()
    for n in ("0001", "0002"):
        for side in ("left", "right"):
            cv2.imwrite(str(seq / f"{side}_{n}.png"), frame)
    real = svio.read_image  # the folder's reader (read_image decodes without imread)

    def held(*args: Any, **kwargs: Any) -> Any:
        gate.wait(1.0)  # a stalled share (bounded: a broken app cannot hang the test)
        return real(*args, **kwargs)

    monkeypatch.setattr(svio, "read_image", held)
    said = f"still reading folder {tmp_path.name}/seq (its first pair has not come): wait for it"

    async def clicks(source: Any) -> None:
        app = _scene_app(
            f"test-capture-first-pair-{source is None}",
            [bundled_data_dir(), tmp_path],
            source=source,
            source_names=("0", "1"),
        )
        tasks = _collect_reads(app)
        app._lock = asyncio.Lock()
        if source is not None:
            app._on_ready()
            await tasks[-1]
        reads_before = len(camera_reads)
        gate.clear()
        app.state.pair_folder = str(seq)
        app.open_pair_folder()
        app.capture()
        assert app.state.error == said
        assert app.state.status == f"reading folder {tmp_path.name}/seq..."
        assert len(tasks) == (2 if source is not None else 1)  # no read of the cameras
        gate.set()
        await tasks[-1]
        assert len(camera_reads) == reads_before
        assert app.state.error == ""
        assert app.state.source_label.endswith("seq: pair 0001 (1 of 2)")
        app.capture()  # the folder's next pair
        await tasks[-1]
        assert app.state.error == ""
        assert app.state.source_label.endswith("seq: pair 0002 (2 of 2)")

    asyncio.run(clicks(None))
    asyncio.run(clicks(Cameras()))


def test_a_wedged_camera_read_leaves_the_page_free(monkeypatch):
    """After an Open, the cameras' first read, and every Capture's, ran in the page's handler:
    a wedged camera froze the page up to --read-timeout. They run in a thread now, the page
    saying "reading ..."; the pair or the read's error comes after; a second Capture while one
    reads is refused, in words; a read that returns after a newer choice (a scene) leaves it
    on show."""
    import asyncio
    import threading
    import time

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    gate = threading.Event()
    reads: list[Any] = []
    fail: list[str] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            pass

        def read(self):
            reads.append(self)
            gate.wait(1.0)  # a wedged read (bounded: a broken app cannot hang the test)
            if fail:
                raise OSError(fail[0])
            return frame, frame

        def close(self):
            pass

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    app = _scene_app("test-wedged-read", [bundled_data_dir()], read_timeout=0.5)
    app.state.cam_left, app.state.cam_right = "0", "1"
    tasks = _collect_reads(app)
    cones = str((bundled_data_dir() / "cones").resolve())
    reading = "reading camera 0 and camera 1..."

    async def clicks() -> None:
        app.open_cameras()
        await _until(lambda: len(reads) == 1)  # opened; its first read is inside the camera
        assert app.state.status == reading and app.state.error == "" and app.source is None
        gate.set()
        await tasks[0]
        assert app.source is not None and app.state.source_label == "cameras 0 / 1"
        assert app.state.captures == 1 and app.state.error == ""
        shown = app.pair

        gate.clear()
        fail.append("camera 0 delivered no frame in 0.5 s")
        t0 = time.perf_counter()
        app.capture()
        assert time.perf_counter() - t0 < 0.1  # the handler returned at once
        assert app.state.status == reading and len(tasks) == 2
        app.capture()  # clicked again while it reads
        assert app.state.error == (
            "still reading camera 0 and camera 1 (an earlier Capture has not returned): wait "
            "for it, or unplug and replug it"
        )
        assert len(tasks) == 2 and len(reads) == 1
        await _until(lambda: len(reads) == 2)
        gate.set()
        await tasks[1]
        assert app.state.error == "camera 0 delivered no frame in 0.5 s"
        assert app.state.status == "error" and app.pair is shown and app.state.captures == 1

        gate.clear()
        fail.clear()
        app.capture()
        await _until(lambda: len(reads) == 3)
        app._on_scene(scene=cones)  # chosen while the cameras are read
        gate.set()
        await tasks[2]
        assert app.state.source_label.startswith("scene ") and app._scene == cones
        assert app.state.captures == 1 and app.state.error == ""

    asyncio.run(clicks())


def test_cameras_replaced_while_a_capture_reads_them_are_closed_once_the_read_returns(
    monkeypatch,
):
    """Other cameras opened while a Capture still reads the cameras in use: those are closed
    only once their read returns (not under a grab in another thread), and the late pair does
    not replace the new cameras' pair."""
    import asyncio
    import threading

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    gate, inside = threading.Event(), threading.Event()
    made: dict[Any, Any] = {}
    closed_under_read: list[bool] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            self.left, self.closed, self.hold = left, False, False
            made[left] = self

        def read(self):
            if self.hold:
                inside.set()
                gate.wait(1.0)
                closed_under_read.append(self.closed)
            return frame, frame

        def close(self):
            self.closed = True

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    app = _scene_app("test-replaced-while-read", [bundled_data_dir()], read_timeout=2.0)
    tasks = _collect_reads(app)

    async def clicks() -> None:
        app.state.cam_left, app.state.cam_right = "0", "1"
        app.open_cameras()
        await tasks[0]
        made[0].hold = True
        app.capture()
        await _until(inside.is_set)
        app.state.cam_left, app.state.cam_right = "2", "3"
        app.open_cameras()
        await tasks[2]
        assert app.source._camera is made[2] and not made[0].closed  # still read
        gate.set()
        await tasks[1]
        assert closed_under_read == [False] and made[0].closed
        assert app.source._camera is made[2] and app.state.source_label == "cameras 2 / 3"
        assert app.state.captures == 2 and app.state.error == ""

    asyncio.run(clicks())


def test_a_capture_is_not_dropped_for_an_open_that_failed_meanwhile(monkeypatch):
    """A Capture's pair was dropped, without a word, when an Open of other cameras was clicked
    while it read, even when that Open failed (the cameras read stayed in use, nothing else
    came on show). It is shown; a scene chosen meanwhile still drops it."""
    import asyncio
    import threading

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    gate, inside = threading.Event(), threading.Event()
    hold: list[bool] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            if left == 5:
                raise OSError("cannot open camera 5 (left)")

        def read(self):
            if hold:
                inside.set()
                gate.wait(1.0)
            return frame.copy(), frame.copy()

        def close(self):
            pass

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    app = _scene_app("test-capture-then-failed-open", [bundled_data_dir()], read_timeout=2.0)
    tasks = _collect_reads(app)

    async def clicks() -> None:
        app.state.cam_left, app.state.cam_right = "0", "1"
        app.open_cameras()
        await tasks[0]
        shown, source = app.pair, app.source
        hold.append(True)
        app.capture()
        await _until(inside.is_set)
        app.state.cam_left, app.state.cam_right = "5", "6"
        app.open_cameras()
        await tasks[2]
        assert app.source is source and app.state.error == (
            "cannot open camera 5 (left) (the cameras in use, camera 0 and camera 1, are unchanged)"
        )
        gate.set()
        await tasks[1]
        assert app.pair is not shown and app.state.captures == 2

        inside.clear()
        gate.clear()
        shown = app.pair
        app.capture()
        await _until(inside.is_set)
        app._on_scene(scene=str((bundled_data_dir() / "cones").resolve()))
        gate.set()
        await tasks[3]
        assert app.state.source_label == "scene data/cones" and app.state.captures == 2

    asyncio.run(clicks())


@pytest.mark.parametrize("step", ["read", "read fails", "open", "open fails"])
def test_a_dropped_read_or_open_does_not_leave_its_status(monkeypatch, step):
    """A Capture (or Open) under way when a scene was chosen: the scene's computation ended on
    "reading ..." ("opening ..."), as the read went on, and the read's pair (or error), dropped
    for the scene, said nothing: "reading camera 0 and camera 1..." stayed on for good. Its
    end puts the status the page would have without it back ("ready")."""
    import asyncio
    import threading

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    gate, inside = threading.Event(), threading.Event()
    hold: list[str] = []

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            if "open" in hold:
                inside.set()
                gate.wait(30.0)
                if step == "open fails":
                    raise OSError("cannot open camera 2 (left)")

        def read(self):
            if "read" in hold:
                inside.set()
                gate.wait(30.0)
                if step == "read fails":
                    raise OSError("camera 0 gave no frame")
            return frame.copy(), frame.copy()

        def close(self):
            pass

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    # the gate opens after the scene computed: the bounds only end a hang (1 s and 2 s were
    # passed by a scene computed under load, the read done before the status was looked at)
    app = _scene_app("test-dropped-read-status", [bundled_data_dir()], read_timeout=30.0)
    tasks = _collect_reads(app)

    async def clicks() -> None:
        app._lock = asyncio.Lock()
        app.state.cam_left, app.state.cam_right = "0", "1"
        app.open_cameras()
        await tasks[0]
        hold.append(step.split()[0])
        if step.startswith("read"):
            app.capture()
            said = "reading camera 0 and camera 1..."
        else:
            app.state.cam_left, app.state.cam_right = "2", "3"
            app.open_cameras()
            said = "opening camera 2 and camera 3..."
        await _until(inside.is_set)
        app._on_scene(scene=str((bundled_data_dir() / "cones").resolve()))
        await app.recompute()  # the scene computes while the read or open goes on
        assert app.state.status == said
        gate.set()
        await tasks[-1]
        assert app.state.source_label == "scene data/cones" and app.state.error == ""
        assert app.state.status == "ready"

    asyncio.run(clicks())


@pytest.mark.parametrize("raised", [StopIteration, SystemExit])
def test_a_read_that_raises_oddly_is_said_and_frees_the_cameras(monkeypatch, raised):
    """A read (or open) that raised StopIteration could not be handed to the page's loop (a
    Future refuses it): the page said "reading ..." for good and the cameras stayed "still
    opening", never to be opened again; SystemExit (KeyboardInterrupt alike) raised into the
    loop stopped the server. Either is said on the page, the cameras free again."""
    import asyncio

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    fail = {"open": False, "read": True}

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            if fail["open"]:
                raise raised("odd")

        def read(self):
            if fail["read"]:
                raise raised("odd")
            return frame, frame

        def close(self):
            pass

    monkeypatch.setattr(capture, "StereoCamera", Cameras)
    app = _scene_app("test-odd-read-" + raised.__name__, [bundled_data_dir()], read_timeout=2.0)
    app.state.cam_left, app.state.cam_right = "0", "1"
    tasks = _collect_reads(app)
    said = f"the camera read ended with {raised.__name__}: odd"

    async def clicks() -> None:
        app.open_cameras()  # its first read raises
        await asyncio.wait_for(tasks[0], 1.5)
        assert app.state.error == said and app.state.status == "error"
        assert app._opening == set() and app.source is None
        fail["read"] = False
        app.open_cameras()  # not "still opening"
        await asyncio.wait_for(tasks[1], 1.5)
        assert app.state.error == "" and app.source is not None
        fail["read"] = True
        app.capture()
        await asyncio.wait_for(tasks[2], 1.5)
        assert app.state.error == said and app.state.status == "error"
        assert app._reading == []
        fail["open"] = True
        app.open_cameras()
        await asyncio.wait_for(tasks[3], 1.5)
        in_use = "(the cameras in use, camera 0 and camera 1, are unchanged)"
        assert app.state.error == f"{said.replace('read', 'open')} {in_use}"
        assert app._opening == set()

    asyncio.run(clicks())


def test_opencv_stereo_calib_output_is_sized_by_the_first_pair_it_is_used_with(
    data_dir, tmp_path, capsys
):
    """OpenCV stereo_calib's intrinsics.yml + extrinsics.yml hold no image size: `gui --calib`
    refused them ("this command cannot read it from its images, so save the rig once in Python
    ..."), while depth, batch and stream take the size from their pairs. The first pair the
    calibration is used with sizes it: the cameras' first frames, an image folder's first
    pair, files (a scene has its own calib.txt); a pair of another size is refused in depth's
    words, the pair on show stays. --calib-unit is still asked for in one line."""
    from test_calibration import _opencv_stereo_calib

    from stereovision.gui import add_arguments, build_app, main

    rig, data = tmp_path / "rig", tmp_path / "data"
    rig.mkdir()
    _opencv_stereo_calib(rig)  # 640x480, T (-120, 1.5, 0.8) mm
    for d in ("big", "small", "seq"):
        (data / d).mkdir(parents=True)
    for n in ("01", "02"):
        for side in ("left", "right"):
            img = cv2.imread(str(data_dir / "chessboard" / f"{side}{n}.jpg"))
            assert img.shape == (480, 640, 3)
            cv2.imwrite(str(data / "big" / f"{side}_00{n}.png"), img)
            cv2.imwrite(str(data / "small" / f"{side}_00{n}.png"), cv2.resize(img, (320, 240)))
            cv2.imwrite(str(data / "seq" / f"{side}{n}.png"), img)
    assert main(["--calib", str(rig), "--data", str(data)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.endswith(
        "(the board's square size): pass --calib-unit (m, mm, cm, ft or in)\n"
    )
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    args = ["--calib", str(rig), "--calib-unit", "mm", "--data", str(data)]
    app = build_app(parser.parse_args(args))
    app._spawn = lambda coro: coro.close()
    app._on_ready()  # the demo scene, with its own calibration
    assert app.state.error == "" and app.calib.image_size == (450, 375)
    app.state.pair_folder = str(data / "big")
    _play(app)
    assert app.state.error == ""
    assert app.calib.image_size == (640, 480) and app.calib.unit == "mm"
    assert app.calib.baseline_m == pytest.approx(np.linalg.norm([120.0, 1.5, 0.8]) / 1000)
    said = "calibration is for 640x480 images, got 320x240 (images resized, not cropped: "
    said += "choose images, an image folder or cameras of the calibration's size, or start gui "
    said += "again with a --calib for 320x240 images)"
    app.state.left_file = str(data / "small" / "left_0001.png")
    app.state.right_file = str(data / "small" / "right_0001.png")
    app.load_files()
    assert app.state.error == said
    assert app.pair[0].shape == (480, 640, 3)  # the pair on show stays
    app.state.pair_folder = str(data / "small")
    _play(app)
    assert app.source.name.endswith("data/big")  # the folder in use, named: not "cameras"
    assert app.state.error == f"{said} (the folder {app.source.name} in use is unchanged)"
    assert app.state.source_label.endswith("data/big: pair 0001 (1 of 2)")
    app.state.left_file = str(data / "big" / "left_0002.png")
    app.state.right_file = str(data / "big" / "right_0002.png")
    app.state.error = ""  # (a computation clears it: none runs here)
    app.load_files()
    assert app.state.error == "" and app.calib is app.source_calib
    assert app.state.source_label == "files"
    assert app.state.rows_label == ""  # no "does not fit" note

    # files first; cameras (an image sequence) sized by their first frames
    app = build_app(parser.parse_args(args))
    app._spawn = lambda coro: coro.close()
    app.state.left_file = str(data / "small" / "left_0002.png")
    app.state.right_file = str(data / "small" / "right_0002.png")
    app.load_files()
    assert app.state.error == "" and app.calib.image_size == (320, 240)
    seq = ["--left", str(data / "seq" / "left%02d.png"), "--right"]
    app = build_app(parser.parse_args([*args, *seq, str(data / "seq" / "right%02d.png")]))
    app._spawn = lambda coro: coro.close()
    _start(app)
    assert app.state.error == "" and app.calib.image_size == (640, 480)


def test_calib_unit_without_calib_is_refused():
    """`gui --calib-unit mm` without --calib started the page with the option ignored; it is
    refused in the other commands' words (cli.load_calibration)."""
    pytest.importorskip("trame")
    from stereovision.gui import add_arguments, build_app

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    with pytest.raises(ValueError) as err:
        build_app(parser.parse_args(["--calib-unit", "mm"]))
    assert str(err.value) == "--calib-unit is the unit of --calib's file: give --calib too"


def test_homographies_as_calib_are_not_sent_to_an_option_gui_has_not(tmp_path):
    """`gui --calib rectification.json` (rectify's homographies) was told "give it as
    --rectification", an option gui has not (argparse then: 'unrecognized arguments')."""
    pytest.importorskip("trame")
    from stereovision.gui import add_arguments, build_app
    from stereovision.uncalibrated import UncalibratedRectification

    rect = UncalibratedRectification(
        np.eye(3), np.eye(3), (40, 30), (40, 30), np.eye(3), 40, 0.1, 0.2, (1.0, 8.0), 16,
        (0.0, 0.0), (1.0, 1.0),
    )  # fmt: skip
    js = str(rect.save(tmp_path / "rectification.json"))
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    with pytest.raises(ValueError) as err:
        build_app(parser.parse_args(["--calib", js]))
    assert str(err.value) == (
        f"{js} holds the homographies `stereovision rectify` found for a rig without a "
        "calibration (disparity only): gui takes no homographies (its Rectify button finds them "
        "anew from the pair on show); `stereovision depth LEFT RIGHT --rectification FILE` "
        "rectifies a raw pair with them"
    )


def test_a_one_point_cloud_is_captioned_1_point(tmp_path):
    """A cloud file of one point was captioned "1 points"."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import shown_cloud
    from stereovision.io import write_ply

    assert shown_cloud(np.ones((1, 3)))[1] == "1 point"
    assert shown_cloud(np.ones((2, 3)))[1] == "2 points"
    write_ply(tmp_path / "one.ply", np.array([[0.1, 0.2, 2.0]], np.float32))
    app = _scene_app("test-one-point", [bundled_data_dir(), tmp_path])
    app.state.view_mode = "points"
    app.state.cloud_path = str(tmp_path / "one.ply")
    app.open_cloud()
    label = app.folders.label((tmp_path / "one.ply").resolve())
    assert app.state.error == "" and app.state.message_3d == f"{label}: 1 point"


def test_cloud_and_save_errors_show_short_paths(tmp_path, monkeypatch):
    """A point-cloud file or a Save folder that failed was named by its whole absolute path
    (/tmp/.../data/bad.ply) where the page shows paths short (the Save field: data/saved);
    the errors show them as the Save field does (display_path)."""
    from stereovision.gui import bundled_data_dir

    data = tmp_path / "data"
    data.mkdir()
    (data / "bad.ply").write_text("not a cloud at all\n")
    (data / "afile").write_text("mine")
    monkeypatch.chdir(tmp_path)
    app = _scene_app("test-short-paths", [bundled_data_dir(), data])
    assert app.state.save_dir == "data/saved"
    app.state.cloud_path = str(data / "bad.ply")
    app.open_cloud()
    assert app.state.error == "not a PLY file: data/bad.ply"
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app.state.save_dir = "data/afile"
    _run(app, app.save)
    assert app.state.error == "save folder data/afile: is a file, not a folder"
    app.state.save_dir = "data/afile/inside"
    _run(app, app.save)
    assert app.state.error == "save folder data/afile/inside: data/afile is a file, not a folder"
    assert (data / "afile").read_text() == "mine"
    assert str(tmp_path) not in app.state.error


def test_the_max_disparity_hint_says_full_size_and_the_processing_width():
    """At 320 the max-disparity field's hint gave the full-size range alone (64 px on the
    450 px cones, 46 px searched). The field is in full-size pixels: the hint says so, and the
    range searched at the processing width."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-max-disp-hint", [bundled_data_dir()])
    app._load_scene(bundled_data_dir() / "cones")
    auto = app.max_disparity
    app.state.resolution = "320"
    _run(app, app.recompute)
    searched = -(-auto * 320 // 450)
    assert app.state.max_disp_hint == (f"auto: {auto} px at full size ({searched} at 320)")
    assert f"disparities 0–{searched}\xa0px" in app.state.stats
    app.state.resolution = "full"
    _run(app, app.recompute)
    assert app.state.max_disp_hint == f"auto: {auto} px at full size"


def test_the_max_disparity_field_and_the_overview_name_edge_values():
    """At full processing width the hint says the full-size range once (no "(64 at 450)"),
    "auto" is read in any case, as the field's hint writes it, and a pair with no label is
    called "pair" in a saved overview's title."""
    from stereovision.gui.app import max_disparity_hint, overview_name, parse_max_disparity

    assert max_disparity_hint(64, 450, 450) == "auto: 64 px at full size"
    assert max_disparity_hint(None, 450, 320) == "auto: estimated from the images"
    assert [parse_max_disparity(t, 450) for t in ("AUTO", "Auto", " 63 ")] == [None, None, 63]
    assert overview_name("  ") == "pair"


def test_the_progress_plan_names_only_the_stages_depth_map_runs():
    """The status's stages are those ``depth_map`` runs for the method: gabor re-measures and
    fills nothing, the dense methods fill (fast does not re-measure), and nothing is
    triangulated without a calibration."""
    from stereovision.gui.app import _planned_stages

    base = ["rectify", "prepare", "match"]
    assert _planned_stages("gabor", False) == [*base, "refine"]
    assert _planned_stages("gabor", True) == [*base, "refine", "triangulate"]
    assert _planned_stages("fused", True) == [*base, "fill", "triangulate"]
    assert _planned_stages("census", False) == [*base, "fill"]
    assert _planned_stages("fast", False) == [*base, "fill"]


@pytest.mark.parametrize("method", ["mcgm", "hopfield"])
def test_the_sparse_channels_are_offered_and_their_matches_drawn(method):
    """The page offered fused, gabor, census, fast and the OpenCV references: MCGM and Hopfield,
    the paper's other channels, were not on it (its list was depth_map's methods; the sparse
    drawing path named them but was never reached). They are offered: the matches on show are
    stereovision.match's on the same scaled pair, the statistics give their count and their
    precision@1 against the scene's GT, and the 3-D view shows their points in either mode."""
    from stereovision import match
    from stereovision.evaluate import sparse_metrics
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.sources import scale_pair, scaled_calibration
    from stereovision.io import load_scene

    app = _scene_app(f"test-sparse-{method}", [bundled_data_dir()])
    assert method in app.state.methods
    cones = bundled_data_dir() / "cones"
    app._load_scene(cones)
    app.state.method, app.state.resolution = method, "320"
    _run(app, app.recompute)
    assert app.state.error == ""
    view = app.view
    scene = load_scene(cones)
    left_s, right_s, s = scale_pair(scene.left, scene.right, 320)
    calib_s = scaled_calibration(scene.calib, s, (left_s.shape[1], left_s.shape[0]))
    d_max = -(-scene.max_disparity * 320 // 450)
    assert view.result.max_disparity == d_max
    expected = match(left_s, right_s, calib_s, method=method, max_disparity=d_max)
    assert len(expected) > 500 and len(view.matches) == len(expected)
    np.testing.assert_array_equal(view.matches.to_array(), expected.to_array())
    np.testing.assert_array_equal(view.result.disparity, expected.dispx)
    h_s, w_s = left_s.shape[:2]
    gt_s = cv2.resize(scene.gt, (w_s, h_s), interpolation=cv2.INTER_NEAREST_EXACT) * (w_s / 450)
    m = sparse_metrics(expected.xl, expected.yl, expected.xr, gt_s)
    assert m.precision[1.0] > 90
    said = (
        f"{len(expected)} matches, precision@1 {m.precision[1.0]:.1f}\xa0% of the {m.count} on GT"
    )
    assert said in app.state.stats and "density" not in app.state.stats
    n = len(view.result.points)
    assert n == np.isfinite(expected.dispx).sum()
    # matches rounding to one pixel are one point (dispx keeps the better): the note said
    # "its N points" under statistics of more matches, the difference unexplained
    k = len(expected)
    assert k > n if method == "mcgm" else k == n  # 21 of 3468 MCGM matches share a pixel
    dropped = (
        f" ({k - n} of {k} matches not drawn: another match on the same pixel, or no valid depth)"
        if k > n
        else ""
    )
    for mode in ("surface", "points"):
        app.state.view_mode = mode
        app._on_view_mode()
        poly = app.plotter.actors["scene"].GetMapper().GetInput()
        assert (poly.GetNumberOfPoints(), poly.GetNumberOfPolys()) == (n, 0), mode
        assert app.state.message_3d == (
            f"{method} is sparse: no dense map, its {n} points shown as points{dropped}"
        )
        assert app.state.view_mode == "points" and app.state.points_only, mode
    # after Rectify (or for another pair) the scene's GT is not that pair's: no precision said
    app._scene_gt = (None, scene.gt)
    _run(app, app.recompute)
    assert f"{len(expected)} matches ·" in app.state.stats and "precision" not in app.state.stats


def test_statistics_without_a_gt_pixel_say_so_not_nan():
    """GT of the pair's size with no known pixel (all NaN), or none where the matches are:
    the statistics say so, not "bad-2.0 nan %" or "precision@1 nan %" (both lines survived a
    mutation audit)."""
    import types

    from stereovision.gui.app import _dense_gt_text, _sparse_precision

    left = np.zeros((10, 20, 3), np.uint8)
    gt = np.full((10, 20), np.nan, np.float32)
    assert _dense_gt_text(np.ones((10, 20), np.float32), gt, left, left) == ", no GT pixel"
    gt[0, 0] = 1.0  # known only where no match is
    matches = types.SimpleNamespace(xl=np.array([5.0]), yl=np.array([5.0]), xr=np.array([4.0]))
    assert _sparse_precision(matches, gt, left, left) == ", none on GT"
    matches.xl, matches.yl, matches.xr = np.array([0.0]), np.array([0.0]), np.array([-1.0])
    assert _sparse_precision(matches, gt, left, left) == ", precision@1 100.0 % of the 1 on GT"


def test_the_scaled_gt_is_sampled_at_the_scaled_pixels_centres():
    """scaled_gt took each scaled pixel's GT from the first source pixel it covers
    (cv2.INTER_NEAREST: floor(x * w / w_s)), not the one at its centre, as the images' INTER_AREA
    averages them: the GT sat half a scaled pixel left of and above the images, and the cones'
    fast map at 160 px said bad-2.0 6.4 % where its own GT gives 5.8 %. It takes the pixel at
    the centre (INTER_NEAREST_EXACT); its values are in the scaled pair's pixels, an unknown
    (NaN, inf) stays unknown, and at full size the GT is as given."""
    from stereovision.gui.app import scaled_gt

    ramp = np.tile(np.arange(8, dtype=np.float32), (4, 1))  # disparity = column, 8 x 4 px
    ramp[:, 5] = np.nan
    ramp[2, :] = np.inf
    g = scaled_gt(ramp, np.zeros((4, 8, 3), np.uint8), np.zeros((2, 2, 3), np.uint8))
    # scaled pixel 0 covers columns 0-3 (centre 1.5): column 2; pixel 1 covers 4-7: column 6;
    # rows: 0-1 -> row 1, 2-3 -> row 3 (the inf row 2 is not the centre's); x 2/8 the values
    np.testing.assert_array_equal(g, [[0.5, 1.5], [0.5, 1.5]])
    g = scaled_gt(ramp, np.zeros((4, 8, 3), np.uint8), np.zeros((4, 4, 3), np.uint8))
    assert np.isnan(g[0, 2]) and np.isinf(g[2]).all()  # column 5, row 2: unknown, not filled
    np.testing.assert_array_equal(g[0], [0.5, 1.5, np.nan, 3.5])
    full = scaled_gt(ramp, np.zeros((4, 8, 3), np.uint8), np.zeros((4, 8, 3), np.uint8))
    np.testing.assert_array_equal(full, ramp)


@pytest.mark.parametrize("method", ["fast", "opencv-bm"])
def test_a_dense_method_says_its_bad_2_and_density_on_the_scenes_gt(method):
    """The sparse methods' statistics said their precision@1 against the scene's GT, the dense
    ones no GT figure at all. They say the map's bad-2.0 (holes counted as errors) and density
    over the GT pixels (evaluation.md), dense_metrics' on the scaled map and the GT scaled as
    the images were; after Rectify (or for another pair) they say none."""
    from stereovision.evaluate import dense_metrics
    from stereovision.gui import bundled_data_dir
    from stereovision.io import load_scene

    app = _scene_app(f"test-dense-gt-{method}", [bundled_data_dir()])
    cones = bundled_data_dir() / "cones"
    app._load_scene(cones)
    app.state.method, app.state.resolution = method, "320"
    _run(app, app.recompute)
    assert app.state.error == ""
    scene = load_scene(cones)
    disparity = app.view.result.disparity
    h_s, w_s = disparity.shape
    assert w_s == 320
    gt_s = cv2.resize(scene.gt, (w_s, h_s), interpolation=cv2.INTER_NEAREST_EXACT) * (w_s / 450)
    m = dense_metrics(disparity, gt_s)
    assert 0 < m.bad[2.0] < 60 and 50 < m.density <= 100
    said = f", on GT bad-2.0 {m.bad[2.0]:.1f}\xa0% (holes count) at density {m.density:.1f}\xa0%"
    assert said in app.state.stats
    app._scene_gt = (None, scene.gt)
    _run(app, app.recompute)
    assert app.state.error == "" and "bad-2.0" not in app.state.stats
    assert "density" in app.state.stats


def test_the_view_mode_toggle_says_points_for_a_sparse_method():
    """For mcgm and hopfield the 3-D view shows points in either mode, and the surface / points
    toggle still said "surface". It says "points" and is disabled while a sparse method's
    matches are on show; a dense method's result is drawn again as the user had chosen (the
    toggle enabled, back to it)."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-sparse-toggle", [bundled_data_dir()])
    app._load_scene(bundled_data_dir() / "cones")
    app.state.resolution = "320"
    _run(app, app.recompute)
    assert (app.state.view_mode, app.state.points_only) == ("surface", False)
    dense = app.plotter.actors["scene"].GetMapper().GetInput()
    assert dense.GetNumberOfPolys() > 0  # the surface
    app.state.method = "mcgm"
    _run(app, app.recompute)
    assert app.state.error == ""
    assert (app.state.view_mode, app.state.points_only) == ("points", True)
    app.state.view_mode = "surface"  # a change from the page while it is disabled: put back
    app._on_view_mode()
    assert app.state.view_mode == "points"
    poly = app.plotter.actors["scene"].GetMapper().GetInput()
    assert poly.GetNumberOfPolys() == 0 and poly.GetNumberOfPoints() == len(app.view.result.points)
    app.state.method = "fast"
    _run(app, app.recompute)
    assert (app.state.view_mode, app.state.points_only) == ("surface", False)
    assert app.plotter.actors["scene"].GetMapper().GetInput().GetNumberOfPolys() > 0
    app.state.view_mode = "points"  # the user's points, kept through a sparse method and back
    app._on_view_mode()
    assert app.plotter.actors["scene"].GetMapper().GetInput().GetNumberOfPolys() == 0
    app.state.method = "hopfield"
    _run(app, app.recompute)
    assert (app.state.view_mode, app.state.points_only) == ("points", True)
    app.state.method = "fast"
    _run(app, app.recompute)
    assert (app.state.view_mode, app.state.points_only) == ("points", False)
    assert app.plotter.actors["scene"].GetMapper().GetInput().GetNumberOfPolys() == 0


def test_the_lines_between_the_images_are_coloured_by_disparity():
    """The matches' lines between the two images were coloured by their index (a hue ramp over
    the list: two matches of one disparity in two colours). Each line and its end dots have
    the colour of its disparity on the disparity picture's scale, as the dots of draw_sparse."""
    from stereovision.cli import colorize
    from stereovision.gui.app import draw_matches, draw_sparse

    left = np.zeros((40, 200, 3), np.uint8)
    right = np.zeros_like(left)
    disparity = np.full((40, 200), np.nan, np.float32)
    disparity[5, 150], disparity[20, 60], disparity[35, 180] = 30.0, 30.0, 10.0
    canvas = draw_matches(left, right, disparity, lo=0.0, hi=32.0)
    ramp = colorize(np.array([[30.0, 10.0]], np.float32), lo=0.0, hi=32.0)[0]
    for (y, x), c in zip(((5, 150), (20, 60), (35, 180)), (ramp[0], ramp[0], ramp[1]), strict=True):
        xr = 200 + x - round(float(disparity[y, x]))
        np.testing.assert_array_equal(canvas[y, x], c)  # the left end
        np.testing.assert_array_equal(canvas[y, xr], c)  # the right end
        # the line between, antialiased: its colour a little darker
        line = canvas[y, (x + xr) // 2].astype(float)
        k = line[np.argmax(c)] / c.max()
        assert 0.8 < k <= 1 and np.allclose(line, k * c, atol=2), (line, c)
    # the dots of the sparse picture have the same colours
    dots = draw_sparse(left, disparity, 0.0, 32.0)
    np.testing.assert_array_equal(dots[20, 60], canvas[20, 60])
    # by default the ends are the disparity picture's: 0 px and the map's 99th percentile
    np.testing.assert_array_equal(
        draw_matches(left, right, disparity)[35, 180], colorize(disparity, lo=0.0)[35, 180]
    )


def test_draw_sparse_colours_each_match_by_its_value():
    """A sparse method's picture: each matched pixel in the colour colorize gives its value on
    the dense pictures' scale, the rest the image dimmed in grey."""
    from stereovision.cli import colorize
    from stereovision.gui.app import draw_sparse

    image = np.full((40, 60, 3), 200, np.uint8)
    values = np.full((40, 60), np.nan, np.float32)
    values[10, 10], values[30, 50] = 2.0, 30.0
    out = draw_sparse(image, values, 0.0, 32.0)
    ramp = colorize(np.array([[2.0, 30.0]], np.float32), lo=0.0, hi=32.0)[0]
    np.testing.assert_array_equal(out[10, 10], ramp[0])
    np.testing.assert_array_equal(out[30, 50], ramp[1])
    np.testing.assert_array_equal(out[0, 0], [100, 100, 100])
    assert not np.array_equal(ramp[0], ramp[1])


def test_a_16_bit_pairs_sparse_pictures_are_drawn_at_8_bits():
    """A 16-bit pair (a 16-bit PNG sequence) with a sparse method: draw_sparse cast it to
    uint8, keeping each level's low byte (the left image under the dots noise), draw_matches
    drew 8-bit colours on the 16-bit pair (255 of 65535: near-black lines on the page), and
    the empty depth picture, 16-bit zeros, was warned of as 'largest value is 0'."""
    import warnings

    from stereovision.gui.app import compute_view, draw_matches, draw_sparse

    rng = np.random.default_rng(0)
    left8 = rng.integers(0, 256, (30, 40, 3), dtype=np.uint8)
    left16 = left8.astype(np.uint16) * 256 + 128  # low byte 128 everywhere
    values = np.full((30, 40), np.nan, np.float32)
    values[5, 30] = 4.0
    np.testing.assert_array_equal(
        draw_sparse(left16, values, 0.0, 8.0), draw_sparse(left8, values, 0.0, 8.0)
    )
    lines16 = draw_matches(left16, left16, values, lo=0.0, hi=8.0)
    lines8 = draw_matches(left8, left8, values, lo=0.0, hi=8.0)
    assert lines16.dtype == np.uint8
    np.testing.assert_array_equal(lines16[5, 30], lines8[5, 30])  # the left end's colour
    assert lines16[5, 30].max() > 200  # not drawn at 255 of 65535: near black once shown
    left, right = (cv2.imread(str(CONES / f"{s}.png")) for s in ("left", "right"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        view = compute_view(
            left.astype(np.uint16) * 257, right.astype(np.uint16) * 257, None, "mcgm", width=160
        )
    assert [str(c.message) for c in caught] == []
    assert not _decode(view.depth_url).any()  # no calibration: black


def test_a_12_bit_pairs_warnings_are_said_on_the_page_not_again_in_the_log():
    """A 12-bit pair in 16 bits: the matching's warnings went on the page, but the pictures'
    8-bit copies warned again outside it, into the server's log ("right: ..." from the matches
    picture, "image: uint16 image whose largest value is 4077 ..." from the right image's)."""
    import warnings

    from stereovision.gui.app import compute_view

    left, right = (
        cv2.imread(str(CONES / f"{s}.png")).astype(np.uint16) * 16 for s in ("left", "right")
    )
    for method in ("mcgm", "fast"):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            view = compute_view(left, right, None, method, width=160)
        assert [str(c.message) for c in caught] == [], method
        assert "warning: left: uint16 image whose largest value is" in view.stats
        assert "warning: right: uint16 image whose largest value is" in view.stats


def test_a_16_bit_calibrated_pairs_sparse_result_has_8_bit_colours_and_saves(tmp_path):
    """A calibrated 16-bit pair with a sparse (or OpenCV) method: _result_from_disparity cast
    the colours to uint8 (each level's low byte: a cloud of noise) and kept the 16-bit left
    image, which failed the Save's overview ('result: expected a uint8 left image, got
    uint16'). A grey pair's colours were an IndexError."""
    from stereovision.calibration import Calibration
    from stereovision.cli import write_overview
    from stereovision.gui.app import _sparse_result

    left, right = (cv2.imread(str(CONES / f"{s}.png")) for s in ("left", "right"))
    left, right, s = sources.scale_pair(left, right, 160)
    calib = sources.scaled_calibration(
        Calibration.from_file(CONES / "calib.txt"), s, (left.shape[1], left.shape[0])
    )
    r8, _ = _sparse_result("mcgm", left, right, calib, 32)
    left16, right16 = (im.astype(np.uint16) * 256 + 128 for im in (left, right))
    r16, _ = _sparse_result("mcgm", left16, right16, calib, 32)
    assert r16.left_rectified.dtype == np.uint8 and len(r16.colors) > 0
    diff = r16.left_rectified.astype(int) - r8.left_rectified.astype(int)
    assert np.abs(diff).max() <= 1  # the 8-bit pair's picture, to the rounding
    xs, ys = r16.pixels.T
    np.testing.assert_array_equal(r16.colors, r16.left_rectified[ys, xs, ::-1])  # not 128s
    write_overview(r16, tmp_path, "pair", "m")  # raised ValueError
    assert (tmp_path / "overview.png").is_file()
    grey, _ = _sparse_result("mcgm", left[:, :, 1], right[:, :, 1], calib, 32)
    assert grey.left_rectified.shape[2] == 3 and (grey.colors[:, 0] == grey.colors[:, 2]).all()


# ----------------------------------------------------------------------------- page events


def test_the_scene_list_after_start_up_cameras_and_a_choice_put_back(tmp_path):
    """The scene list's choice and what it says: a failed choice after start-up goes back to
    the demo scene, choosing the scene on show (the list put back) computes nothing, another
    scene drops the previous pair's Check rows verdict, and a camera pair clears the choice so
    that choosing the scene again reloads it."""
    import shutil

    from stereovision.gui import bundled_data_dir

    shutil.copytree(bundled_data_dir() / "cones", tmp_path / "other")
    (tmp_path / "odd").mkdir()  # fails to load: the two images differ in size
    cv2.imwrite(str(tmp_path / "odd" / "left.png"), np.zeros((40, 50, 3), np.uint8))
    cv2.imwrite(str(tmp_path / "odd" / "right.png"), np.zeros((40, 60, 3), np.uint8))
    app = _scene_app("test-scene-list-events", [bundled_data_dir(), tmp_path])
    spawned: list = []
    app._spawn = lambda coro: (spawned.append(coro), coro.close())
    app._on_ready()
    demo = str((bundled_data_dir() / "cones").resolve())
    choose = _chooser(app, tmp_path)
    choose("odd")
    assert app.state.error != "" and app.state.scene == demo
    spawned.clear()
    app._on_scene(scene=demo)  # the list put back on the scene on show
    assert spawned == [] and app.state.source_label == "scene data/cones"
    _run(app, app.check_rows)
    assert app.state.rows_label.startswith("rectification ok")
    choose("other")
    assert app.state.rows_label == "" and len(spawned) == 1

    left, right = app.pair

    class Cameras:
        def read(self):
            return left.copy(), right.copy()

        def close(self):
            pass

    app._switch_source(Cameras(), ("0", "1"))
    assert app.state.scene is None and app.state.source_label == "cameras 0 / 1"
    app._on_scene(scene=str(tmp_path / "other"))
    assert app.state.source_label.startswith("scene ") and app.state.source_label.endswith("other")


def test_cameras_after_a_scene_count_captures_close_the_old_and_use_their_own_range():
    """A camera pair after a scene: the scene's disparity range (cones: 64) is not the cameras',
    the previous cameras are closed, each pair counts as a capture, and homographies the
    features gave another rig's pair are not put on the cameras' next pairs after a scene or
    files were shown."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-cameras-after-scene", [bundled_data_dir()])
    app._load_scene(bundled_data_dir() / "cones")
    assert app.max_disparity == 64
    left, right = app.pair
    closed: list = []

    class Cameras:
        def __init__(self, name: str) -> None:
            self.name = name

        def read(self):
            return left.copy(), right.copy()

        def close(self):
            closed.append(self.name)

    class Rectified:  # the features' homographies of a 450x375 pair
        input_size = (450, 375)
        max_disparity = 50

        def rectify(self, a, b):
            return a, b

    class NoFrames(Cameras):
        def read(self):
            raise OSError("camera 9 gave no frame")

    app._switch_source(NoFrames("none"), ("9", "9"))
    assert app.state.error == "camera 9 gave no frame" and closed == ["none"]
    closed.clear()
    app._switch_source(Cameras("a"), ("0", "1"))
    assert app.state.error == ""
    assert app.max_disparity is None and app.state.captures == 1 and closed == []
    app._switch_source(Cameras("b"), ("2", "3"))
    assert closed == ["a"] and app.state.captures == 2
    _capture(app)
    assert app.state.captures == 3
    for other in ("scene", "files"):
        app.homographies = Rectified()
        if other == "scene":
            app._load_scene(bundled_data_dir() / "cones")
        else:
            app.state.left_file, app.state.right_file = "cones/left.png", "cones/right.png"
            app.load_files()
        _capture(app)  # says what is on show (test_a_capture_after_a_scene_says_so_first)
        assert "on show, not camera 2 and camera 3" in app.state.error, other
        _capture(app)
        assert app.state.error == "", other
        assert app.state.source_label == "cameras 2 / 3", other
        assert app.max_disparity is None, other


def test_a_capture_after_a_scene_says_so_first(tmp_path):
    """Capture with a scene (or files) chosen after an image folder or cameras opened went back
    to that source without a word: the scene left, the list emptied, the folder's next pair on
    show. The first Capture now says why it does not capture the scene; another, with no choice
    since, goes back to the source (the folder's next pair, the cameras' pair)."""
    from stereovision.gui import bundled_data_dir

    cones = bundled_data_dir() / "cones"
    left, right = (cv2.imread(str(cones / f"{s}.png")) for s in ("left", "right"))
    seq = tmp_path / "seq"
    seq.mkdir()
    for k in (1, 2):
        cv2.imwrite(str(seq / f"left_{k:04d}.png"), left)
        cv2.imwrite(str(seq / f"right_{k:04d}.png"), right)
    app = _scene_app("test-capture-after-scene", [bundled_data_dir(), tmp_path])
    app.state.pair_folder = str(seq)
    _play(app)
    seq_name = app.folders.label(seq.resolve())
    assert app.state.source_label == f"folder {seq_name}: pair 0001 (1 of 2)"
    demo = str(cones.resolve())
    app.state.scene = demo
    app._on_scene(scene=demo)
    _capture(app)
    assert app.state.error == (
        f"scene data/cones is on show, not folder {seq_name}: a scene or files cannot be "
        "captured; Capture again to go on with its next pair"
    )
    assert app.state.source_label == "scene data/cones" and app.state.scene == demo
    _capture(app)
    assert (
        app.state.error == "" and app.state.source_label == f"folder {seq_name}: pair 0002 (2 of 2)"
    )
    assert app.state.scene is None
    _capture(app)  # the folder's pairs on show: no word
    assert (
        app.state.error == "" and app.state.source_label == f"folder {seq_name}: pair 0001 (1 of 2)"
    )

    class Cameras:
        def read(self):
            return left.copy(), right.copy()

        def close(self):
            pass

    app._switch_source(Cameras(), ("0", "1"))
    app.state.left_file, app.state.right_file = "cones/left.png", "cones/right.png"
    app.load_files()
    _capture(app)
    assert app.state.error == (
        "the loaded files are on show, not camera 0 and camera 1: a scene or files cannot be "
        "captured; Capture again to read a pair from them"
    )
    assert app.state.source_label == "files"
    app._on_scene(scene=demo)  # another choice: the next Capture says it again
    _capture(app)
    assert app.state.error.startswith("scene data/cones is on show, not camera 0 and camera 1")
    _capture(app)
    assert app.state.error == "" and app.state.source_label == "cameras 0 / 1"


def test_a_capture_after_a_failed_first_read_reads_the_cameras(tmp_path):
    """Cameras given at start-up (--left/--right) whose first read failed: the page shows no
    pair, and the Capture that retries was refused as if a scene were on show (" is on show,
    not camera 0 and camera 1: a scene or files cannot be captured"). It reads the cameras; a
    scene chosen after them still makes the first Capture say so."""
    from stereovision.gui import bundled_data_dir

    frame = cv2.imread(str(CONES / "left.png"))
    reads: list[int] = []

    class Cameras:
        def read(self):
            reads.append(1)
            if len(reads) == 1:
                raise OSError("camera 0 delivered no frame in 5 s")
            return frame.copy(), frame.copy()

        def close(self):
            pass

    app = _scene_app(
        "test-capture-after-failed-start",
        [bundled_data_dir()],
        source=Cameras(),
        source_names=("0", "1"),
    )
    _start(app)
    assert app.state.error == "camera 0 delivered no frame in 5 s" and app.pair is None
    _capture(app)
    assert app.state.error == "" and len(reads) == 2 and app.state.captures == 1
    assert app.state.source_label == "cameras 0 / 1" and app.pair is not None
    app._on_scene(scene=str((bundled_data_dir() / "cones").resolve()))
    _capture(app)
    assert app.state.error.startswith("scene data/cones is on show, not camera 0 and camera 1")
    assert len(reads) == 2


def test_a_capture_after_a_scene_that_failed_to_compute_reads_the_cameras(tmp_path):
    """A scene chosen over the cameras' pair that fails to compute puts the cameras' pair back
    on the page, but the next Capture was refused as if the scene were on show ("cameras 0 / 1
    is on show, not camera 0 and camera 1: a scene or files cannot be captured"). It reads the
    cameras, as from their pair; other cameras whose pair fails to compute put the scene back,
    and with it the first Capture's word."""
    from stereovision.gui import bundled_data_dir

    _tiny_scene(tmp_path / "tiny")
    frame = cv2.imread(str(CONES / "left.png"))
    tiny = np.zeros((8, 8, 3), np.uint8)
    give = [frame]

    class Cameras:
        def read(self):
            return give[0].copy(), give[0].copy()

        def close(self):
            pass

    app = _scene_app("test-capture-after-failed-scene", [bundled_data_dir(), tmp_path])
    app._switch_source(Cameras(), ("0", "1"))
    _run(app, app.recompute)
    assert app.state.error == "" and app.state.source_label == "cameras 0 / 1"
    app._on_scene(scene=str(tmp_path / "tiny"))
    _run(app, app.recompute)
    assert app.state.error.endswith("(the page still shows the previous pair)")
    assert app.state.source_label == "cameras 0 / 1"
    _capture(app)
    assert app.state.error == "" and app.state.captures == 2

    app._on_scene(scene=str((bundled_data_dir() / "cones").resolve()))
    _run(app, app.recompute)
    assert app.state.error == "" and app.state.source_label == "scene data/cones"
    give[0] = tiny
    app._switch_source(Cameras(), ("2", "3"))  # a pair too small to compute: the scene back
    _run(app, app.recompute)
    assert app.state.source_label == "scene data/cones"
    _capture(app)
    assert app.state.error.startswith("scene data/cones is on show, not camera 2 and camera 3")


def test_the_computations_a_page_asks_and_what_they_are_given(monkeypatch):
    """What each computation is given and how many run: the max-disparity field wins over the
    scene's range, the same value applied again computes nothing, three quick requests compute
    the first and the newest only, and the first pair's 3-D caption does not speak of a
    previous pair while it computes."""
    import asyncio

    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir

    real = gui_app.compute_view
    calls: list = []

    def spy(*args: Any, **kwargs: Any) -> Any:
        calls.append((kwargs["max_disparity"], app.state.message_3d))
        return real(*args, **kwargs)

    monkeypatch.setattr(gui_app, "compute_view", spy)
    app = _scene_app("test-computations-asked", [bundled_data_dir()])
    spawned: list = []
    app._spawn = lambda coro: (spawned.append(coro), coro.close())
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    assert calls == [(64, "")]  # the scene's range; no previous pair to speak of
    app.apply_max_disparity(text="40")
    assert app.state.error == "" and len(spawned) == 1
    _run(app, app.recompute)
    assert calls[-1][0] == 40
    assert app.state.max_disp_hint == "auto: 64 px at full size"  # the automatic one, not 40
    app.apply_max_disparity(text="40")
    assert len(spawned) == 1  # unchanged: nothing to compute
    calls.clear()

    async def three() -> None:
        await asyncio.gather(app.recompute(), app.recompute(), app.recompute())

    _run(app, three)
    assert len(calls) == 2 and app.state.computations == 3


def test_toggles_during_a_computation_and_a_failure_keep_the_unit(tmp_path):
    """The unit and surface/points toggles while a new pair computes leave its cleared results
    and its 3-D caption alone (they put the previous pair's statistics under the new pair's
    images); when the pair then fails, the previous pair's statistics and floor come back in
    the unit chosen meanwhile. An unknown unit is refused and the toggle put back."""
    import asyncio
    import shutil

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import PENDING_3D

    shutil.copytree(bundled_data_dir() / "cones", tmp_path / "cones")
    _tiny_scene(tmp_path / "tiny")
    app = _scene_app("test-toggles-while-computing", [tmp_path])
    app.state.unit = "yd"  # as the page sends it
    app._on_unit(unit="yd")
    assert app.state.error.startswith("unit: expected one of") and app.state.unit == "m"
    tasks: list = []
    seen: dict = {}
    choose = _chooser(app, tmp_path)

    async def run() -> None:
        _queue_spawns(app, tasks)
        choose("cones")
        await asyncio.gather(*tasks)
        await app.find_floor()
        seen["floor"] = app.state.floor_label
        choose("tiny")
        await asyncio.sleep(0)  # its computation is running in the worker
        app.state.unit = "ft"
        app._on_unit(unit="ft")
        app.state.view_mode = "points"
        app._on_view_mode()
        seen["during"] = (app.state.stats, app.state.message_3d)
        await asyncio.gather(*tasks)

    asyncio.run(run())
    assert "\xa0m above it" in seen["floor"]
    assert seen["during"] == ("", PENDING_3D)
    assert app.state.error.endswith("(the page still shows the previous pair)")
    assert app.state.stats == app.view.texts("ft")[1] and "\xa0ft" in app.state.stats
    assert "\xa0ft above it" in app.state.floor_label


def test_a_new_pair_clears_the_previous_saves_line(tmp_path):
    """The Save's line ("saved 450×375 to ...") named the previous pair's folder under the next
    computed pair: it goes with the pair it was said of."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-save-line-cleared", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    _run(app, app.save)
    assert app.state.save_label.startswith("saved 450×375 to ")
    _run(app, app.recompute)
    assert app.state.error == "" and app.state.save_label == ""


def test_check_rows_that_fails_on_a_pair_replaced_meanwhile_says_nothing(monkeypatch):
    """Check rows that failed after another scene was chosen put its error over the new
    scene's page: the failure was of a pair no longer on show."""
    import asyncio
    import threading

    import stereovision.rectification_check as rc
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-rows-fail-replaced", [bundled_data_dir()])
    started, gate = threading.Event(), threading.Event()

    def fails(*args: Any, **kwargs: Any) -> Any:
        started.set()
        gate.wait(60)
        raise ValueError("no features to check")

    monkeypatch.setattr(rc, "check_rectification", fails)

    async def pressed_then_scene() -> None:
        app._lock = asyncio.Lock()
        app._load_scene(bundled_data_dir() / "cones")
        running = asyncio.ensure_future(app.check_rows())
        await asyncio.get_running_loop().run_in_executor(None, started.wait, 60)
        app._load_scene(bundled_data_dir() / "cones")  # another pair, chosen meanwhile
        gate.set()
        await running

    asyncio.run(pressed_then_scene())
    assert app.state.error == ""
    _run(app, app.check_rows)  # on the pair on show it is said
    assert app.state.error == "no features to check"


def test_rectify_that_fails_on_a_pair_replaced_meanwhile_says_nothing(monkeypatch):
    """As Check rows: Rectify that failed after another pair was chosen is not said over the
    new pair's page (saying it survived a mutation audit)."""
    import asyncio
    import threading

    import stereovision.rectification_check as rc
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-rectify-fail-replaced", [bundled_data_dir()])
    started, gate = threading.Event(), threading.Event()

    def fails(*args: Any, **kwargs: Any) -> Any:
        started.set()
        gate.wait(60)
        raise ValueError("no features to match")

    monkeypatch.setattr(rc, "already_rectified", fails)

    async def pressed_then_scene() -> None:
        app._lock = asyncio.Lock()
        app._load_scene(bundled_data_dir() / "cones")
        app.calib = None  # Rectify works on a pair without a calibration
        running = asyncio.ensure_future(app.rectify_from_features())
        await asyncio.get_running_loop().run_in_executor(None, started.wait, 60)
        app._load_scene(bundled_data_dir() / "cones")  # another pair, chosen meanwhile
        app.calib = None
        gate.set()
        await running

    asyncio.run(pressed_then_scene())
    assert app.state.error == ""
    _run(app, app.rectify_from_features)  # on the pair on show it is said
    assert app.state.error == "no features to match"


def test_a_cloud_opened_after_a_failed_start_up_clears_the_error_status(tmp_path):
    """Cameras that gave no pair at start-up left the toolbar on "error"; a point-cloud file
    then opened cleared the message but the toolbar still said "error" above a page with no
    error on it (the status went back to "ready" only once a pair was on show)."""
    from stereovision.gui import bundled_data_dir
    from stereovision.io import write_ply

    class NoFrames:
        def read(self):
            raise OSError("camera 0 gave no frame")

        def close(self):
            pass

    write_ply(tmp_path / "blob.ply", np.random.default_rng(2).uniform(1, 3, (50, 3)))
    app = _scene_app(
        "test-cloud-after-failed-start", [bundled_data_dir(), tmp_path], source=NoFrames()
    )
    _start(app)
    assert app.state.status == "error" and app.state.error == "camera 0 gave no frame"
    app.state.cloud_path = str(tmp_path / "blob.ply")
    app.open_cloud()
    assert app.state.error == "" and app.state.status == "ready"
    assert app.state.message_3d.endswith(
        ": 50 points (a point cloud has no surface: shown as points)"
    )


def test_reset_puts_all_six_sliders_back_to_zero():
    """The 3-D view's Reset: every slider at 0 (the left camera's pose), the view with them."""
    from stereovision import render
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import _CONTROL_NAMES

    app = _scene_app("test-reset-sliders", [bundled_data_dir()])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    for k, name in enumerate(_CONTROL_NAMES):
        app.state[name] = 0.5 + k
    app._on_controls()
    app.reset_camera()
    assert {n: app.state[n] for n in _CONTROL_NAMES} == dict.fromkeys(_CONTROL_NAMES, 0.0)
    pose = render.controls_from_pose(render.pose_from_camera(app.plotter.camera))
    assert [getattr(pose, n) for n in _CONTROL_NAMES] == pytest.approx([0.0] * 6, abs=1e-6)


def test_a_pair_superseded_while_it_fails_leaves_the_newer_choice_and_the_page(tmp_path):
    """A scene that failed after a newer one was chosen put its failure on the page and the
    previous pair back in the app, so the newer choice computed the previous pair; a new pair
    queued behind a superseded one took the blank page as the one to put back on failure."""
    import asyncio
    import shutil

    from stereovision.gui import bundled_data_dir

    for name in ("cones", "other"):
        shutil.copytree(bundled_data_dir() / "cones", tmp_path / name)
    _tiny_scene(tmp_path / "tiny")
    app = _scene_app("test-superseded-failure", [tmp_path])
    tasks: list = []
    choose = _chooser(app, tmp_path)
    seen: dict = {}

    async def run() -> None:
        _queue_spawns(app, tasks)
        choose("cones")
        await asyncio.gather(*tasks)
        choose("tiny")  # fails, but "other" is chosen while it runs
        await asyncio.sleep(0)
        choose("other")
        await asyncio.gather(*tasks)
        seen["other"] = (app.state.error, app.state.source_label, app.state.computations)
        seen["page"] = (app.state.stats, app.state.img_disparity)
        choose("cones")  # queued behind "tiny", which is superseded: both then fail
        choose("tiny")
        await asyncio.gather(*tasks)

    asyncio.run(run())
    other = app.folders.label((tmp_path / "other").resolve())
    assert seen["other"] == ("", f"scene {other}", 2)
    assert app.state.error.endswith("(the page still shows the previous pair)")
    assert app.state.source_label == f"scene {other}" and app.state.computations == 2
    assert seen["page"][1] != "" and (app.state.stats, app.state.img_disparity) == seen["page"]


def test_an_image_sequence_typed_as_a_camera_is_opened_by_its_folder(tmp_path):
    """A camera field may hold an image sequence (``seq/left%02d.png``): its folder is checked
    against --data, the pattern is no file of its own."""
    from stereovision.gui import bundled_data_dir

    left, right = (cv2.imread(str(CONES / f"{s}.png")) for s in ("left", "right"))
    (tmp_path / "seq").mkdir()
    for k in range(2):
        cv2.imwrite(str(tmp_path / "seq" / f"left{k:02d}.png"), left)
        cv2.imwrite(str(tmp_path / "seq" / f"right{k:02d}.png"), right)
    app = _scene_app("test-camera-sequence", [bundled_data_dir(), tmp_path])
    app.state.cam_left = str(tmp_path / "seq" / "left%02d.png")
    app.state.cam_right = str(tmp_path / "seq" / "right%02d.png")
    _open_cameras(app)
    assert app.state.error == ""
    assert app.state.source_label == "cameras left%02d.png / right%02d.png"
    assert app.pair[0].shape == (375, 450, 3)
    app.source.close()


@pytest.mark.parametrize("opener", ["capture", "fallback"])
def test_a_sequence_starting_at_5_typed_as_a_camera_opens(tmp_path, monkeypatch, opener):
    """An image sequence whose first number is 5 or more opens with ``stereovision capture``
    and ``stream``; the page's fallback (VideoPair, when ``StereoCamera`` cannot be imported)
    said "cannot open camera" of it (cv2.VideoCapture alone looks at numbers 0-4). The page
    opens it either way, its pairs in order and again after the last."""
    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    if opener == "fallback":  # `from stereovision.capture import StereoCamera` fails
        monkeypatch.delattr(capture, "StereoCamera")
    left, right = (cv2.imread(str(CONES / f"{s}.png")) for s in ("left", "right"))
    (tmp_path / "seq").mkdir()
    for k in (7, 8):
        cv2.imwrite(str(tmp_path / "seq" / f"left{k:02d}.png"), left // (k - 5))
        cv2.imwrite(str(tmp_path / "seq" / f"right{k:02d}.png"), right // (k - 5))
    app = _scene_app(f"test-camera-sequence-at-7-{opener}", [bundled_data_dir(), tmp_path])
    app.state.cam_left = str(tmp_path / "seq" / "left%02d.png")
    app.state.cam_right = str(tmp_path / "seq" / "right%02d.png")
    _open_cameras(app)
    assert app.state.error == ""
    assert app.state.source_label == "cameras left%02d.png / right%02d.png"
    try:
        for k in (7, 8, 7):
            if k != 7 or app.state.captures > 1:
                _capture(app)
            assert app.state.error == ""
            np.testing.assert_array_equal(app.raw_pair[0], left // (k - 5))
            np.testing.assert_array_equal(app.raw_pair[1], right // (k - 5))
    finally:
        app.source.close()


def test_a_negative_camera_index_typed_on_the_page_is_refused_as_capture_refuses_it(tmp_path):
    """ "-1" in a camera field was looked for as a file ("no such file: -1"); it is the index
    capture refuses (OpenCV's -1 crashes where no camera is present), said in its words."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-camera-negative", [bundled_data_dir(), tmp_path])
    app.state.cam_left, app.state.cam_right = "-1", "0"
    app.open_cameras()
    assert app.state.error == (
        "camera index -1 is negative: cameras are numbered from 0 (./-1 for a file)"
    )
    assert app.source is None and app.state.live is False


def test_loading_files_names_sizes_and_warns_of_one_file_twice(tmp_path):
    """The files' size mismatch said "left (375, 450, 3) and right (288, 384, 3) differ in
    size"; the same file as left and right computed a flat 0 disparity without a word."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-files-twice", [bundled_data_dir(), tmp_path])
    cv2.imwrite(str(tmp_path / "small.png"), np.full((288, 384, 3), 50, np.uint8))
    app.state.left_file, app.state.right_file = "cones/left.png", str(tmp_path / "small.png")
    app.load_files()
    assert app.state.error == (
        f"data/cones/left.png is 450x375 (colour), {tmp_path.name}/small.png is 384x288 "
        "(colour): the two images of a pair have one size"
    )
    app.state.error = ""
    app.state.left_file = app.state.right_file = "cones/left.png"
    app.load_files()
    assert app.state.error == ""
    assert app.state.rows_label == (
        "warning: data/cones/left.png and data/cones/left.png are the same file: every "
        "disparity comes out 0 (two views of the scene are needed)"
    )
    app.state.right_file = "cones/right.png"
    app.load_files()
    assert app.state.rows_label == ""


@pytest.mark.parametrize(
    ("method", "calibrated", "steps"),
    [
        ("fused", False, ["preparing", "matching", "filling", "drawing"]),
        ("gabor", False, ["preparing", "matching", "refining", "drawing"]),
        ("fast", True, ["preparing", "matching", "filling", "triangulating", "drawing"]),
    ],
)
def test_progress_names_the_step_that_really_follows(method, calibrated, steps, data_dir):
    """The status named a fixed next step: "refining and filling" after fused's match (it only
    fills), "filling" after gabor's refinement (it does not fill) and "triangulating" without a
    calibration (nothing is triangulated)."""
    from stereovision.gui.app import compute_view
    from stereovision.io import load_scene

    name = "tartanair/oldtown_easy_p000_001116" if calibrated else "middlebury2001/tsukuba"
    sc = load_scene(data_dir / name)
    assert (sc.calib is not None) == calibrated
    said: list = []
    compute_view(
        sc.left, sc.right, sc.calib, method, width=320, progress=lambda p, t: said.append(t)
    )
    done = [t for t in said if " done, " in t]
    assert [t.split(", ", 1)[1] for t in done] == [f"{s}…" for s in steps], said
    assert said.index("drawing") == said.index(done[-1]) + 1


def test_a_pair_rectified_by_its_calibration_is_shown_rectified_on_both_sides():
    """With a calibration of unrectified cameras, the acquisition panel showed the rectified
    left image (the one the disparity belongs to) beside the right image as the cameras gave
    it, and the matches were drawn on the raw pair. Both images are the rectified pair now."""
    import dataclasses

    from stereovision.calibration import Calibration
    from stereovision.gui.app import _data_url, compute_view

    left, right = (cv2.imread(str(CONES / f"{s}.png")) for s in ("left", "right"))
    ideal = Calibration.ideal((450, 375), 60, 0.16)
    turned = cv2.Rodrigues(np.array([0.0, 0.03, 0.02]))[0]
    calib = dataclasses.replace(ideal, R=turned, rectified=False)
    rect_left, rect_right = calib.rectify(left, right)
    view = compute_view(left, right, calib, "fast")
    np.testing.assert_array_equal(view.result.left_rectified, rect_left)
    assert view.left_url == _data_url(rect_left)
    assert view.right_url == _data_url(rect_right) != _data_url(right)
    # a rectified calibration's pair is shown as it comes
    plain = compute_view(left, right, ideal, "fast")
    assert (plain.left_url, plain.right_url) == (_data_url(left), _data_url(right))


def test_the_average_switch_is_offered_only_for_sources_it_averages(tmp_path):
    """With an image folder playing, the "average 8 still frames" switch was enabled and did
    nothing (a folder's pairs are one view after another, never averaged). It is enabled for
    cameras (and recordings) only."""
    left, right = (cv2.imread(str(CONES / f"{s}.png")) for s in ("left", "right"))
    for side, img in (("left", left), ("right", right)):
        cv2.imwrite(str(tmp_path / f"{side}_0001.png"), img)

    class Cameras:
        def read(self):
            return left.copy(), right.copy()

        def close(self):
            pass

    app = _scene_app("test-average-offered", [tmp_path])
    assert not app.state.live and not app.state.can_average  # the demo scene
    app.state.pair_folder = str(tmp_path)
    _play(app)
    assert app.state.error == "" and app.state.live and not app.state.can_average
    app._switch_source(Cameras(), ("0", "1"))
    assert app.state.error == "" and app.state.can_average
    app.state.average = True
    _capture(app)
    assert app.state.source_label.endswith("(8.0 frames averaged)")


def test_a_dangling_link_in_a_typed_save_folder_is_a_file_it_holds(tmp_path):
    """A link named ``overview.png`` whose target is gone is refused as a file the folder
    holds, before anything is written (not as a file that "appeared while the Save wrote")."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-save-dangling-link", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "overview.png").symlink_to(tmp_path / "gone.png")
    app.state.save_dir = "mine"
    _run(app, app.save)
    assert app.state.error == (
        f"save: {tmp_path.name}/mine already holds overview.png; nothing was overwritten: "
        "choose another folder"
    )
    assert [p.name for p in mine.iterdir()] == ["overview.png"]


def test_a_failed_click_during_a_computation_leaves_its_progress(tmp_path):
    """A bad max disparity typed while a pair computes is said, and the toolbar still shows
    the computation running (it said "error" and not busy while the work went on)."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-fail-while-computing", [bundled_data_dir()])
    app._load_scene(bundled_data_dir() / "cones")
    app._computing = True
    app.state.busy, app.state.status = True, "computing (fast)"
    app.apply_max_disparity(text="-3")
    assert app.state.error.startswith("max disparity: expected a whole number of pixels")
    assert (app.state.busy, app.state.status) == (True, "computing (fast)")
    app._computing = False
    app.apply_max_disparity(text="x")
    assert (app.state.busy, app.state.status) == (False, "error")


def test_the_max_disparity_in_use_typed_again_clears_its_refusal(tmp_path):
    """A bad max disparity ("abc") corrected back to the value in use computed nothing (the
    same range) and said nothing: the refusal "got 'abc'" and the toolbar's "error" stayed
    under a field holding a good value. The refusal goes; another error on the page stays.
    Another action's success that clears the refusal (a Show, Find floor, Check rows, Save)
    left the refused value in the field, no error said under it: it shows the range in use."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-max-disp-typed-again", [bundled_data_dir(), tmp_path])
    spawned: list = []
    app._spawn = spawned.append
    app._load_scene(bundled_data_dir() / "cones")
    app.apply_max_disparity(text="64")
    assert app.chosen_max_disparity == 64 and len(spawned) == 1
    spawned.pop().close()
    for typed_again in ("64", " 64 "):
        app.apply_max_disparity(text="abc")
        assert app.state.error.endswith("got 'abc'") and app.state.status == "error"
        app.apply_max_disparity(text=typed_again)
        assert (app.state.error, app.state.status) == ("", "ready"), typed_again
        assert app.chosen_max_disparity == 64 and spawned == []  # nothing to compute
    app.apply_max_disparity(text="abc")
    app.apply_max_disparity(text="auto")  # a change: computed, its refusal gone as before
    assert app.state.error == "" and app.chosen_max_disparity is None and len(spawned) == 1
    spawned.pop().close()
    app.apply_max_disparity(text="0")
    app._fail(OSError("cannot open camera 5 (left)"))  # said since: not the field's
    app.apply_max_disparity(text="auto")
    assert app.state.error == "cannot open camera 5 (left)" and spawned == []
    (tmp_path / "one.ply").write_text(
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 1\n"
    )
    app.state.cloud_path = str(tmp_path / "one.ply")
    for in_use, said in ((None, ""), (32, "32")):
        app.chosen_max_disparity = in_use
        app.apply_max_disparity(text="500")
        assert app.state.error.startswith("max disparity 500 px is not smaller")
        app.open_cloud()  # taken: its success clears the refusal, and the refused value
        assert (app.state.error, app.state.max_disp) == ("", said), in_use


def test_an_emptied_slider_is_said_on_the_page(tmp_path):
    """A slider's value the page sent as null (an emptied field) is said as an error; the
    view stays (a TypeError escaped the controller)."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-emptied-slider", [bundled_data_dir()])
    app.state.roll = None
    app._apply_camera()
    assert app.state.error == "float() argument must be a string or a real number, not 'NoneType'"


def test_the_unit_toggle_with_an_emptied_slider_converts_the_others_and_says_it():
    """The unit toggle with a translation slider the page sent as null raised a TypeError out
    of its handler half done: the unit was feet, the other sliders' metres read as feet (the
    view moved) and the captions stayed in metres. The toggle now converts the others and the
    emptied slider is said, as a slider move says it."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-unit-emptied-slider", [bundled_data_dir()])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    app.state.up = 1.0
    app.state.forward = None
    app._on_unit(unit="ft")
    assert app._unit == "ft" and app.state.up == 3.281 and app.state.forward is None
    assert app.state.depth_caption.endswith("\u00a0ft") and "m" not in app.state.depth_caption
    assert app.state.error == "float() argument must be a string or a real number, not 'NoneType'"


def test_an_unexpected_error_of_a_computation_or_a_save_is_said_and_frees_the_page(
    tmp_path, monkeypatch, caplog
):
    """An error no handler expected (a bug of ours: IndexError, TypeError) went past the
    computation's ``except``: the page stayed "computing" under its progress bar for good, and
    Save and Find floor said "the new pair is being computed"; a Save's said nothing. It is now
    said in one line, as the CLI says one, its trace in the server's log, and the page works on."""
    import stereovision.cli as cli
    import stereovision.gui.app as gui_app
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-unexpected-error", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)
    shown = app.view
    compute = gui_app.compute_view

    def broken(*args: Any, **kw: Any) -> Any:
        raise IndexError("index 3 is out of bounds")

    monkeypatch.setattr(gui_app, "compute_view", broken)
    app.state.method = "census"
    _run(app, app.recompute)
    assert app.state.error == (
        "internal IndexError: index 3 is out of bounds (please report this) (the page still "
        "shows fast at full resolution)"
    )
    assert (app.state.busy, app.state.status, app.state.method) == (False, "error", "fast")
    assert app.view is shown and app._page_before is None
    assert "gui: computing census failed" in caplog.text and "IndexError" in caplog.text
    monkeypatch.setattr(gui_app, "compute_view", compute)

    def writer(*args: Any, **kw: Any) -> Any:
        raise TypeError("an odd array")

    monkeypatch.setattr(cli, "write_depth_outputs", writer)
    app.state.save_dir = str(tmp_path / "out")
    _run(app, app.save)  # the pair on show is saved, not refused as still computing
    assert app.state.error == "internal TypeError: an odd array (please report this)"
    assert not (tmp_path / "out").exists() and app._saving_into == set()


def test_a_recursion_or_not_implemented_error_is_said_as_a_bug_of_ours(
    tmp_path, monkeypatch, caplog
):
    """RecursionError and NotImplementedError are RuntimeErrors, and the page took them as an
    expected failure: said as they are ("maximum recursion depth exceeded"), no trace in the
    server's log. Both are bugs of ours: said as one ("internal ... (please report this)"),
    their trace logged, from the worker thread (a computation) and from a handler's own
    ``except RuntimeError`` (choosing a scene) alike."""
    import stereovision.gui.app as gui_app
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-bug-runtime-error", [bundled_data_dir(), tmp_path])
    app._load_scene(bundled_data_dir() / "cones")
    _run(app, app.recompute)

    def deep(*args: Any, **kw: Any) -> Any:
        raise RecursionError("maximum recursion depth exceeded")

    monkeypatch.setattr(gui_app, "compute_view", deep)
    app.state.method = "census"
    _run(app, app.recompute)
    assert app.state.error == (
        "internal RecursionError: maximum recursion depth exceeded (please report this) (the "
        "page still shows fast at full resolution)"
    )
    assert "gui: computing census failed" in caplog.text
    assert "Traceback" in caplog.text and "RecursionError" in caplog.text
    caplog.clear()

    def unimplemented(*args: Any, **kw: Any) -> Any:
        raise NotImplementedError("no such source")

    monkeypatch.setattr(app, "_load_scene", unimplemented)
    app._on_scene(str(bundled_data_dir() / "cones2"))
    assert app.state.error == "internal NotImplementedError: no such source (please report this)"
    assert "Traceback" in caplog.text and "NotImplementedError" in caplog.text


def test_an_image_sequence_typed_as_a_camera_outside_the_data_folders_is_refused(tmp_path):
    """A pattern's folder is checked against --data like a file: one outside is refused."""
    from stereovision.gui import bundled_data_dir

    left = cv2.imread(str(CONES / "left.png"))
    out = tmp_path / "out"
    out.mkdir()
    for k in range(2):
        for side in ("left", "right"):
            cv2.imwrite(str(out / f"{side}{k:02d}.png"), left)
    (tmp_path / "in").mkdir()
    app = _scene_app("test-camera-sequence-outside", [bundled_data_dir(), tmp_path / "in"])
    app.state.cam_left, app.state.cam_right = str(out / "left%02d.png"), str(out / "right%02d.png")
    app.open_cameras()
    assert app.state.error == f"path outside the allowed folders: {out}"
    assert app.source is None and app.pair is None


def test_homographies_of_another_frame_size_are_not_put_on_the_cameras_next_pair(tmp_path):
    """The features' homographies fit one frame size: a pair of another size (the cameras'
    resolution changed) is shown as it comes, not warped by them under "(rectified from
    features)"."""
    from stereovision.gui import bundled_data_dir

    small = (np.full((30, 40, 3), 7, np.uint8), np.full((30, 40, 3), 9, np.uint8))

    class Cameras:
        def read(self):
            return small

        def close(self):
            pass

    class Homographies:  # fitted to 450x375 frames
        input_size = (450, 375)
        max_disparity = 60

        def rectify(self, left, right):
            raise AssertionError("homographies of 450x375 frames put on a 40x30 pair")

    app = _scene_app(
        "test-homographies-size", [bundled_data_dir()], source=Cameras(), source_names=("0", "1")
    )
    app.homographies = Homographies()
    app._grab()
    assert app.pair[0] is small[0] and app.pair[1] is small[1] and app.max_disparity is None
    assert app.state.source_label == "cameras 0 / 1"


def test_a_scenes_gt_is_given_only_with_a_calibration_that_leaves_the_pair_as_it_is(monkeypatch):
    """The scene's GT disparity is of the pair as given: a calibration that rectifies the pair
    (not rectified) moves its pixels, and the GT is then not given (a bad-2.0 of another
    pair's pixels)."""
    from types import SimpleNamespace

    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir

    given: list = []

    def spy(*args: Any, **kwargs: Any) -> Any:
        given.append((args[2], kwargs["gt"] is not None))
        raise ValueError("not computed here")

    monkeypatch.setattr(gui_app, "compute_view", spy)
    app = _scene_app("test-gt-given", [bundled_data_dir()])
    app._load_scene(bundled_data_dir() / "cones")
    rectified = app.calib
    _run(app, app.recompute)
    app.calib = SimpleNamespace(rectified=False)  # one that rectifies the pair
    _run(app, app.recompute)
    app.calib = None
    _run(app, app.recompute)
    assert [g for _, g in given] == [True, False, True]
    assert given[0][0] is rectified and rectified.rectified


def test_files_loaded_after_rectifying_the_cameras_drop_their_homographies(tmp_path):
    """Files loaded after "Rectify" on the cameras' pair: the homographies of that pair go
    (the next capture is not warped by them, and "Rectify" on the files starts afresh)."""
    from stereovision.gui import bundled_data_dir

    raw = (cv2.imread(str(CONES / "left.png")), cv2.imread(str(CONES / "right.png")))

    class Cameras:
        def read(self):
            return raw

        def close(self):
            pass

    class Homographies:  # fitted to the cameras' 450x375 frames
        input_size = (450, 375)
        max_disparity = 60

        def rectify(self, left, right):
            raise AssertionError("the cameras' homographies put on a pair after the files")

    app = _scene_app(
        "test-files-drop-homographies",
        [bundled_data_dir()],
        source=Cameras(),
        source_names=("0", "1"),
    )
    app.homographies = Homographies()
    app.state.left_file, app.state.right_file = "cones/left.png", "cones/right.png"
    app.load_files()
    assert app.state.error == "" and app.homographies is None
    app._grab()
    assert app.pair[0] is raw[0] and app.state.source_label == "cameras 0 / 1"


def test_other_cameras_drop_the_homographies_a_failed_switch_keeps_them():
    """Cameras opened after "Rectify" on the cameras' pair: that rig's homographies go with it
    (the new cameras' pairs were warped by them in a mutation audit, no test failing); cameras
    that fail to open leave the ones in use with their homographies."""
    from stereovision.gui import bundled_data_dir

    raw = (cv2.imread(str(CONES / "left.png")), cv2.imread(str(CONES / "right.png")))

    class Cameras:
        def __init__(self, pair):
            self.pair = pair

        def read(self):
            if self.pair is None:
                raise OSError("camera 3 gave no frame")
            return self.pair

        def close(self):
            pass

    class Homographies:  # fitted to the first cameras' 450x375 frames
        input_size = (450, 375)
        max_disparity = 60

        def rectify(self, left, right):
            return left[:, ::-1].copy(), right[:, ::-1].copy()

    app = _scene_app(
        "test-switch-drops-homographies",
        [bundled_data_dir()],
        source=Cameras(raw),
        source_names=("0", "1"),
    )
    app._spawn = lambda coro: coro.close()
    rect = app.homographies = Homographies()
    app._switch_source(Cameras(None), ("2", "3"))
    assert app.state.error == (
        "camera 3 gave no frame (the cameras in use, camera 0 and camera 1, are unchanged)"
    )
    assert app.homographies is rect
    app._switch_source(Cameras(raw), ("2", "3"))
    assert app.state.error == "" and app.homographies is None
    assert app.pair[0] is raw[0] and app.state.source_label == "cameras 2 / 3"


def test_a_failed_open_names_the_source_it_leaves_in_use(tmp_path, monkeypatch):
    """An Open or Play that failed said "(the cameras in use are unchanged)" whatever was in
    use: an image folder being played, video files, a bag. It names what stays: the cameras,
    the folder, or (files, a bag) the source."""
    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.sources import FolderPairs

    raw = (cv2.imread(str(CONES / "left.png")), cv2.imread(str(CONES / "right.png")))

    class Cameras:
        def __init__(self, pair):
            self.pair = pair

        def read(self):
            if self.pair is None:
                raise OSError("camera 3 gave no frame")
            return self.pair

        def close(self):
            pass

    def refused(**kw: Any) -> str:
        app = _scene_app("test-failed-open-names", [bundled_data_dir(), tmp_path / "scenes"], **kw)
        app._spawn = lambda coro: coro.close()
        app._switch_source(Cameras(None), ("2", "3"))
        assert app.source is kw.get("source"), kw
        return str(app.state.error)

    seq = tmp_path / "scenes" / "seq"
    seq.mkdir(parents=True)
    cv2.imwrite(str(seq / "left_0001.png"), raw[0])
    cv2.imwrite(str(seq / "right_0001.png"), raw[1])
    said = "camera 3 gave no frame"
    cameras = refused(source=Cameras(raw), source_names=("0", "1"))
    assert cameras == f"{said} (the cameras in use, camera 0 and camera 1, are unchanged)"
    videos = refused(source=Cameras(raw), source_names=("left.mp4", "right.mp4"))
    assert videos == f"{said} (the source in use, left.mp4 and right.mp4, is unchanged)"
    bag = refused(source=Cameras(raw), source_names=("", ""), source_label="bag rig.bag: /l / /r")
    assert bag == f"{said} (the source in use, bag rig.bag: /l / /r, is unchanged)"
    assert refused() == said  # nothing in use: nothing said of it
    # a folder being played; then an Open whose first read fails (_first_pair)
    app = _scene_app("test-failed-open-folder", [bundled_data_dir(), tmp_path / "scenes"])
    app._spawn = lambda coro: coro.close()
    app.state.pair_folder = str(seq)
    _play(app)
    assert app.state.error == "" and isinstance(app.source, FolderPairs)
    playing = app.source
    app._switch_source(Cameras(None), ("2", "3"))
    assert app.state.error == f"{said} (the folder scenes/seq in use is unchanged)"
    assert app.source is playing
    app.state.cam_left, app.state.cam_right = "2", "3"
    monkeypatch.setattr(gui_app, "open_stereo_source", lambda *a, **k: Cameras(None))
    _open_cameras(app)
    assert app.state.error == f"{said} (the folder scenes/seq in use is unchanged)"
    assert app.source is playing


def test_an_open_that_cannot_open_names_the_source_that_stays_in_use(tmp_path, monkeypatch):
    """An Open whose cameras did not open (the open raised, or was given up, or a typed file
    was missing) said only what failed ("cannot open camera 5 (left)"): nothing told that the
    source on show kept running, as a failed first read tells it. Each now says what failed,
    then the source that stays in use, named; with nothing in use, only what failed."""
    import threading

    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    raw = (cv2.imread(str(CONES / "left.png")), cv2.imread(str(CONES / "right.png")))
    wedged = threading.Event()

    class Cameras:
        def __init__(self, left, right, *, image_size=None, fourcc=None, open_timeout=None):
            if left == 7:
                wedged.wait(2.0)  # an open that does not return in time (bounded)
            if left in (5, 7):
                raise OSError(f"cannot open camera {left} (left)")

        def read(self):
            return raw

        def close(self):
            pass

    monkeypatch.setattr(capture, "StereoCamera", Cameras)

    def failed(left: str, **kw: Any) -> str:
        app = _scene_app(
            "test-open-fails-names", [bundled_data_dir(), tmp_path], read_timeout=0.2, **kw
        )
        kept = app.source
        app.state.cam_left, app.state.cam_right = left, "6"
        _open_cameras(app)
        assert app.source is kw.get("source") is kept and app.state.status == "error"
        return str(app.state.error)

    cams = {"source": Cameras(0, 1), "source_names": ("0", "1")}
    in_use = "(the cameras in use, camera 0 and camera 1, are unchanged)"
    assert failed("5", **cams) == f"cannot open camera 5 (left) {in_use}"
    assert failed("5") == "cannot open camera 5 (left)"  # nothing in use: nothing said of it
    videos = {"source": Cameras(0, 1), "source_names": ("l.avi", "r.avi")}
    assert failed("5", **videos) == (
        "cannot open camera 5 (left) (the source in use, l.avi and r.avi, is unchanged)"
    )
    assert failed("none.avi", **cams) == f"no such file: none.avi {in_use}"
    try:
        assert failed("7", **cams) == (
            "camera 7 and camera 6 did not open within 0.2 s (the open did not return: a "
            "wedged camera or driver, or a stalled stream); unplug and replug it, or give gui "
            f"a longer --read-timeout {in_use}"
        )
    finally:
        wedged.set()


def test_a_failed_open_calls_cameras_typed_by_their_device_node_cameras(tmp_path):
    """Cameras in use typed as ``/dev/video0`` and ``/dev/video1`` (or one of each form): a
    failed Open said "the source in use is unchanged" of them, as of video files; the
    capture code takes such a node for a camera, and so does the page now."""
    from stereovision.gui import bundled_data_dir

    raw = (cv2.imread(str(CONES / "left.png")), cv2.imread(str(CONES / "right.png")))

    class Cameras:
        def __init__(self, pair):
            self.pair = pair

        def read(self):
            if self.pair is None:
                raise OSError("camera 3 gave no frame")
            return self.pair

        def close(self):
            pass

    def refused(names: tuple[str, str]) -> str:
        app = _scene_app(
            "test-failed-open-node", [bundled_data_dir()], source=Cameras(raw), source_names=names
        )
        app._spawn = lambda coro: coro.close()
        app._switch_source(Cameras(None), ("2", "3"))
        return str(app.state.error)

    said = "camera 3 gave no frame"
    cameras = f"{said} (the cameras in use, video0 and video1, are unchanged)"
    assert refused(("/dev/video0", "/dev/video1")) == cameras
    cameras = f"{said} (the cameras in use, camera 0 and video1, are unchanged)"
    assert refused(("0", "/dev/video1")) == cameras
    # a file, a stream or a path that only looks like a node is no camera; a stream is named
    # by its whole URL (its last part, "0", read as a camera's number)
    source = f"{said} (the source in use, video0 and right.mp4, is unchanged)"
    assert refused(("/dev/video0", "right.mp4")) == source
    source = f"{said} (the source in use, rtsp://rig/0 and rtsp://rig/1, is unchanged)"
    assert refused(("rtsp://rig/0", "rtsp://rig/1")) == source
    source = f"{said} (the source in use, video0x and video1, is unchanged)"
    assert refused(("/dev/video0x", "/dev/video1")) == source


def test_a_streams_password_is_not_said_on_the_page_nor_logged(caplog):
    """A stream is named by its whole URL since f723ecb (it was named by its last part):
    one typed with a password (``rtsp://admin:s3cret@cam/0``) had it said in the page's
    messages ("reading ...", a failed Open's "the source in use, ...") and in the server's
    log. The password is said as ``***``; the user and the rest are kept. The pair's label
    named streams by their last part still ("cameras 0 / 1"): by their URLs now."""
    import logging

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import _source_name

    raw = (cv2.imread(str(CONES / "left.png")), cv2.imread(str(CONES / "right.png")))

    class Cameras:
        def __init__(self, pair):
            self.pair = pair

        def read(self):
            if self.pair is None:
                raise OSError("camera 3 gave no frame")
            return self.pair

        def close(self):
            pass

    names = ("rtsp://admin:s3cret@cam/0", "rtsp://admin:p@ss:w@cam:554/1?x=a:b@c")
    app = _scene_app("test-stream-password", [bundled_data_dir()], source=Cameras(raw))
    app._source_names = names
    app._spawn = lambda coro: coro.close()
    caplog.set_level(logging.INFO, logger="stereovision")
    app._switch_source(Cameras(None), ("2", "3"))
    assert app.state.error == (
        "camera 3 gave no frame (the source in use, rtsp://admin:***@cam/0 and "
        "rtsp://admin:***@cam:554/1?x=a:b@c, is unchanged)"
    )
    assert "s3cret" not in caplog.text and "p@ss" not in caplog.text
    assert app.state.error in caplog.text  # logged, as said
    # the pair's label names the streams so too: "cameras 0 / 1" was said of them, as of
    # cameras 0 and 1
    app._switch_source(Cameras(raw), ("rtsp://rig/0", names[0]))
    assert app.state.error == ""
    assert app.state.source_label == "cameras rtsp://rig/0 / rtsp://admin:***@cam/0"
    # no password: the URL as typed (a port, an "@" after the host's "/" is no password)
    for url in ("rtsp://cam:554/0", "rtsp://admin@cam/0", "http://cam:80/a:b@c"):
        assert _source_name(url) == url


def test_check_rows_of_files_at_another_resolution_uses_the_calibration_scaled(tmp_path):
    """Files at half the --calib size: "Check rows" checks them with the calibration scaled
    to them, as their view is computed (not refused as of another image size)."""
    from stereovision.calibration import Calibration
    from stereovision.gui import bundled_data_dir

    for side in ("left", "right"):
        img = cv2.imread(str(CONES / f"{side}.png"))
        cv2.imwrite(str(tmp_path / f"half_{side}.png"), cv2.resize(img, (225, 188)))
    app = _scene_app(
        "test-check-rows-scaled",
        [bundled_data_dir(), tmp_path],
        calib=Calibration.from_file(CONES / "calib.txt"),
    )
    app.state.left_file = str(tmp_path / "half_left.png")
    app.state.right_file = str(tmp_path / "half_right.png")
    app.load_files()
    assert app.calib is not None and app.calib.image_size == (450, 375)
    _run(app, app.check_rows)
    assert app.state.error == ""
    assert app.state.rows_label.startswith("rectification ok")


def test_a_streams_password_is_not_said_when_it_does_not_open(monkeypatch, caplog):
    """A stream URL with a password: the page said it typed in the camera fields ("no such
    file: rtsp://admin:s3cret@cam/0", logged too), showed it in those fields to every browser
    when given as ``gui --left``, and a stream that does not open was refused as "cannot open
    left source 'rtsp://admin:s3cret@cam/0'" (VideoPair: "left camera source not found: ...").
    The password and a token parameter are said as ``***``; the URL opened is the one given."""
    import logging

    from stereovision import capture
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.sources import VideoPair, open_stereo_source

    url = "rtsp://admin:s3cret@cam/0?token=tok77"
    caplog.set_level(logging.INFO, logger="stereovision")
    app = _scene_app("test-stream-password-typed", [bundled_data_dir()])
    app.state.cam_left, app.state.cam_right = url, "rtsp://cam/1"
    _open_cameras(app)
    assert app.state.error == (
        "rtsp://admin:***@cam/0?token=***: a stream's URL is given to gui --left/--right at "
        "start-up, not typed here (the page opens cameras, and files in the --data folders)"
    )
    assert app.state.error in caplog.text  # logged, as said
    app.state.cam_left = "http://cam:8080/video"  # any stream: not opened from the page
    _open_cameras(app)
    assert app.state.error.startswith("http://cam:8080/video: a stream's URL is given to gui ")
    # given as gui --left: shown in the page's field without it
    app = _scene_app(
        "test-stream-password-given", [bundled_data_dir()], source_names=(url, "rtsp://cam/1")
    )
    assert (app.state.cam_left, app.state.cam_right) == (
        "rtsp://admin:***@cam/0?token=***",
        "rtsp://cam/1",
    )
    opened: list[str] = []

    def down(path: str, first: Any) -> Any:
        opened.append(path)
        return cv2.VideoCapture()  # not open: the stream is down

    monkeypatch.setattr(capture, "_open_path", down)
    with pytest.raises(OSError) as err:
        open_stereo_source(url, "rtsp://cam/1")
    assert str(err.value) == "cannot open left source 'rtsp://admin:***@cam/0?token=***'"
    assert opened == [url]  # opened as given
    # OpenCV's own pair (no capture module): a URL is opened, not looked for as a file ("left
    # camera source not found: ..."), and refused without its password
    monkeypatch.setattr("stereovision.gui.sources._open_capture", down)
    with pytest.raises(OSError) as err:
        VideoPair(url, "rtsp://cam/1")
    assert str(err.value) == "cannot open camera 'rtsp://admin:***@cam/0?token=***' (left)"
    with pytest.raises(OSError) as err:  # one with a pattern's "%" too
        VideoPair("http://admin:s3cret@cam/f_%03d.jpg", "rtsp://cam/1")
    assert str(err.value) == "cannot open camera 'http://admin:***@cam/f_%03d.jpg' (left)"
    assert "s3cret" not in caplog.text and "tok77" not in caplog.text


def test_gui_main_as_the_command_ends_past_an_open_it_gave_up(monkeypatch, capsys):
    """``python -m stereovision.gui --read-timeout 1e-300``: the open given up, its line said,
    then the open came back out of OpenCV while the interpreter shut down: "terminate called
    without an active exception" and exit 134 (1 of 5 runs), as ``stereovision capture`` did
    before the CLI's ``main`` ended the process itself. ``gui.main`` now does as the CLI's."""
    import os
    import threading

    import stereovision.gui as gui

    class Ended(Exception):
        pass

    def exit_(status: int) -> None:
        raise Ended(status)

    release = threading.Event()

    def given_up(_args: argparse.Namespace) -> Any:
        # the open left in native code, as _open_within leaves it after its timeout
        threading.Thread(target=release.wait, name="stereovision-gui-open", daemon=True).start()
        raise ValueError("left source 'x' did not open within 1e-300 s")

    monkeypatch.setattr(gui, "build_app", given_up)
    monkeypatch.setattr(os, "_exit", exit_)
    monkeypatch.setattr(sys, "argv", ["stereovision gui", "--no-browser"])
    try:
        with pytest.raises(Ended) as ended:
            gui.main()
        assert ended.value.args == (2,)
        assert capsys.readouterr().err == (
            "stereovision: error: left source 'x' did not open within 1e-300 s\n"
        )
        # given its argv (an in-process caller), it returns: the caller's process is its own
        assert gui.main(["--no-browser"]) == 2
    finally:
        release.set()


def test_gui_main_ends_past_a_computation_running_when_the_server_stops(monkeypatch):
    """Ctrl+C while a pair computed: the server stopped, then the interpreter's shutdown waited
    for the worker thread's computation (135 s for a 3600 x 3000 pair, the "Ctrl+C to stop"
    seemingly ignored). ``gui.main`` now ends the process past it, as past a camera's read."""
    import os
    import threading

    import stereovision.gui as gui
    from stereovision.gui import bundled_data_dir

    class Ended(Exception):
        pass

    def exit_(status: int) -> None:
        raise Ended(status)

    app = _scene_app("test-stop-past-work", [bundled_data_dir()])
    release, running = threading.Event(), threading.Event()
    queued: list[Any] = []

    def start(**_: Any) -> None:  # the server runs a computation, then stops (Ctrl+C)
        app._executor.submit(lambda: (running.set(), release.wait()))
        assert running.wait(10)
        queued.append(app._executor.submit(lambda: None))  # a check clicked meanwhile

    monkeypatch.setattr(app.server, "start", start)
    monkeypatch.setattr(gui, "build_app", lambda _args: app)
    monkeypatch.setattr(os, "_exit", exit_)
    monkeypatch.setattr(sys, "argv", ["stereovision gui", "--no-browser"])
    try:
        with pytest.raises(Ended) as ended:
            gui.main()
        assert ended.value.args == (0,)
        assert queued[0].cancelled()  # what was queued behind it is dropped, not run
    finally:
        release.set()


def test_a_save_under_way_when_the_server_stops_is_finished_first(tmp_path):
    """Stopping the server's work waits for a Save that writes (its folder whole), and a Save
    not begun then writes nothing."""
    import threading

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import SaveFailed

    app = _scene_app("test-stop-save", [bundled_data_dir()])
    half, go = threading.Event(), threading.Event()

    def write(into: Path) -> None:
        (into / "disparity.png").write_bytes(b"a")
        half.set()
        assert go.wait(10)
        (into / "overview.png").write_bytes(b"b")

    names = ["disparity.png", "overview.png"]
    saving = app._executor.submit(app._write_save, write, tmp_path / "out", names)
    assert half.wait(10)
    stopper = threading.Thread(target=app.stop_work)
    stopper.start()
    stopper.join(0.3)
    assert stopper.is_alive()  # waiting for the Save
    go.set()
    stopper.join(10)
    assert not stopper.is_alive()
    assert set(saving.result(10)) == set(names)
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == names
    with pytest.raises(SaveFailed, match="the server is stopping: nothing was written"):
        app._write_save(write, tmp_path / "later", names)
    assert not (tmp_path / "later").exists()


def test_gui_main_refuses_a_value_in_one_line_with_the_unit_hint(capsys):
    """``python -m stereovision.gui --read-timeout 10s`` printed argparse's usage block and its
    line without the hint 4f409a7 gave every number option of ``stereovision gui`` (and of the
    other commands): its parser is the CLI's now, one line as ``stereovision gui`` says it."""
    import stereovision.gui as gui

    with pytest.raises(SystemExit) as raised:
        gui.main(["--read-timeout", "10s"])
    assert raised.value.code == 2
    assert capsys.readouterr() == (
        "",
        "stereovision gui: error: argument --read-timeout: expected seconds above 0 or 'none' "
        "(no limit) without a unit (5 for 5 s), got '10s' (see stereovision gui --help)\n",
    )


@pytest.mark.parametrize(
    "argv",
    [
        ["--left-topic", "/cam/left"],
        ["--right-topic", "/r"],
        ["--left", "0", "--right", "1", "--left-topic", "/l"],
    ],
)
def test_a_topic_without_a_bag_is_refused_before_the_server_starts(
    capsys: pytest.CaptureFixture[str], argv: list[str]
) -> None:
    """``gui --left-topic /cam/left`` without --from-bag served the page, the topic ignored
    without a word (capture and calibrate refuse it): refused now before any camera is opened
    or the server started, one line, exit 2."""
    import stereovision.gui as gui

    said = "--left-topic and --right-topic are for --from-bag"
    with pytest.raises(ValueError, match=f"^{said}$"):
        gui.build_app(_gui_args(*argv))
    assert gui.main([*argv, "--no-browser"]) == 2
    assert capsys.readouterr() == ("", f"stereovision: error: {said}\n")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="V4L2 device nodes")
@pytest.mark.parametrize(("left", "right"), [("3", "3"), ("3", "/dev/video3")])
def test_one_camera_given_twice_is_refused_as_capture_refuses_it(
    capsys: pytest.CaptureFixture[str], left: str, right: str
) -> None:
    """``gui --left 3 --right 3`` (or ``/dev/video3``) opened the camera twice, the second open
    failing with a hint about another program using it, where capture and stream refuse it
    before any open: refused now in their words (``3`` and ``3`` was "'3' and '3' are both
    camera /dev/video3", stream's "both camera 3"), one line, exit 2."""
    import stereovision.gui as gui
    from stereovision.cli import main

    assert main(["stream", "--left", left, "--right", right]) == 2
    stream_said = capsys.readouterr()
    said = {
        "3": "--left and --right are both camera 3",
        "/dev/video3": "--left '3' and --right '/dev/video3' are both camera /dev/video3",
    }[right]
    assert stream_said == ("", f"stereovision: error: {said}: give the rig's two cameras\n")
    assert gui.main(["--left", left, "--right", right, "--no-browser", "--port", "0"]) == 2
    assert capsys.readouterr() == stream_said


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="V4L2 device nodes")
def test_one_camera_typed_in_both_fields_is_refused_before_any_open(monkeypatch) -> None:
    """The page's Open of camera 3 in both fields (or 3 and /dev/video3) opened it twice, the
    second open failing with a hint about another program using the camera: refused now, as
    gui --left/--right are, before any open (nothing is opened, the source in use stays)."""
    from stereovision import capture
    from stereovision.gui import bundled_data_dir

    opened: list[Any] = []
    monkeypatch.setattr(capture, "StereoCamera", lambda *a, **k: opened.append(a))
    app = _scene_app("test-one-camera-twice", [bundled_data_dir()])
    for left, right in (("3", "3"), ("3", "/dev/video3")):
        app.state.cam_left, app.state.cam_right = left, right
        app.open_cameras()
        assert app.state.error == (
            "the left and right fields are both camera /dev/video3: give the rig's two cameras"
        )
    assert opened == [] and app.source is None


def test_one_file_given_twice_is_warned_of_as_capture_does(tmp_path: Path) -> None:
    """``gui --left l.avi --right ./l.avi`` showed every disparity 0 without a word, where
    capture and stream warn that every pair is one view twice; the GUI warns in their words
    (and, the warning made an error, closes the source it opened)."""
    import warnings

    import stereovision.gui as gui
    from stereovision.gui import sources as gui_sources

    video = _write_video(tmp_path / "l.avi", cv2.imread(str(CONES / "left.png")))
    opened: list[Any] = []
    real_open = gui_sources.open_stereo_source

    def recorded(*args: Any, **kwargs: Any) -> Any:
        opened.append(real_open(*args, **kwargs))
        return opened[-1]

    args = _gui_args("--left", str(video), "--right", f"{tmp_path}/./l.avi")
    with pytest.MonkeyPatch.context() as mp, warnings.catch_warnings():
        mp.setattr(gui_sources, "open_stereo_source", recorded)
        warnings.simplefilter("error")
        with pytest.raises(UserWarning) as said:
            gui.build_app(args)
    assert str(said.value) == (
        f"--left and --right are the same source {str(video)!r}: every pair is one view twice "
        "and every disparity comes out 0 (two cameras' views are needed)"
    )
    assert len(opened) == 1
    with pytest.raises(OSError, match="closed"):
        opened[0].read()


def test_fail_says_a_path_with_a_newline_escaped_on_its_one_line(tmp_path):
    """_fail took the first line of the error before its path was shortened, and gave
    first_line no path: a cloud file named with a newline cut the page's error line at it
    (``not a PLY file: .../my``), its name lost."""
    pytest.importorskip("trame")
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-fail-path-newline", [bundled_data_dir(), tmp_path])
    path = tmp_path / "my\ncloud.ply"
    app._fail(ValueError(f"not a PLY file: {path}\nsecond line"), path)
    assert app.state.error == f"not a PLY file: {tmp_path}/my\\ncloud.ply"
    plain = tmp_path / "cloud.ply"
    app._fail(ValueError(f"not a PLY file: {plain}"), plain)
    assert app.state.error == f"not a PLY file: {plain}"
    # a Load of files so named was cut alike: "no such file: cones/no", "cannot decode .../my"
    app.state.left_file, app.state.right_file = "cones/no\nne.png", "cones/right.png"
    app.load_files()
    assert app.state.error == "no such file: cones/no\\nne.png"
    (tmp_path / "my\nleft.png").write_bytes(b"not an image")
    app.state.left_file = str(tmp_path / "my\nleft.png")
    app.load_files()
    assert app.state.error == f"cannot decode {tmp_path}/my\\nleft.png as an image"


def test_a_scene_put_back_after_another_failed_keeps_its_gt_figures(tmp_path):
    """A scene chosen after one with GT that failed to compute put the page back on the first,
    but its GT stayed the failed scene's: the first scene's statistics lost their "on GT
    bad-2.0" from its next computation on (a method chosen: "census · 450×375 · ... · density
    100 % · 0.37 s"). The GT comes back with the pair."""
    import asyncio

    from stereovision.gui import bundled_data_dir
    from stereovision.io import read_pfm, write_pfm

    cones, good = bundled_data_dir() / "cones", tmp_path / "good"
    good.mkdir()
    for name in ("left.png", "right.png"):  # 40 rows of the cones, their GT with them
        cv2.imwrite(str(good / name), cv2.imread(str(cones / name))[150:190])
    write_pfm(good / "gt_disp.pfm", read_pfm(cones / "gt_disp.pfm")[150:190])
    _tiny_scene(tmp_path / "tiny")
    app = _scene_app("test-scene-back-gt", [tmp_path])
    app._lock = asyncio.Lock()
    app._spawn = asyncio.run  # a loaded scene is computed at once
    choose = _chooser(app, tmp_path)
    choose("good")
    assert ", on GT bad-2.0 " in app.state.stats
    choose("tiny")
    # the scene's own range in eval's words: "disparity range 16 is not smaller than the
    # image width 8" named a range nobody gave
    assert app.state.error == (
        "images 8 px wide, not wider than the scene's disparity range (16 px, evaluation.md's "
        "rule: 16 at least): a scene needs images at least 17 px wide, or give a max_disparity "
        "below 8 (the page still shows the previous pair)"
    )
    app._on_method()  # computed again (a method or resolution chosen)
    assert app.state.error == "" and ", on GT bad-2.0 " in app.state.stats


def test_image_sequences_typed_as_cameras_that_start_apart_are_said_paired_in_order(tmp_path):
    """Two image sequences opened on the page that start at different numbers (left01.png
    deleted, blurred) are paired in order, not by number: every left image with the right one
    before its own. StereoCamera's warning of it went to the server's log alone; the page said
    nothing ("cameras left%02d.png / right%02d.png", no error). It is now said under the pair,
    as a pair of files' warning is (given to gui --left/--right: under the first pair, the
    terminal's line at start-up being out of the page's sight); sequences that start together
    say nothing."""
    import warnings

    from stereovision.gui import bundled_data_dir
    from stereovision.gui.app import short_paths

    img = np.zeros((24, 40, 3), np.uint8)
    (tmp_path / "seq").mkdir()
    for k in (2, 3):
        cv2.imwrite(str(tmp_path / "seq" / f"left{k:02d}.png"), img)
        cv2.imwrite(str(tmp_path / "seq" / f"right{k - 1:02d}.png"), img)
    app = _scene_app("test-camera-sequences-apart", [bundled_data_dir(), tmp_path])
    app.state.cam_left = str(tmp_path / "seq" / "left%02d.png")
    app.state.cam_right = str(tmp_path / "seq" / "right%02d.png")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # the server's log's
        _open_cameras(app)
    try:
        assert app.state.error == "" and app.state.source_label.startswith("cameras left%02d")
        assert app.state.rows_label == (
            "warning: the left sequence starts at left02.png, the right one at right01.png: "
            "images are paired in order (left02.png with right01.png), not by their numbers; "
            "if the numbers name the pairs, remove the images without a partner (or renumber)"
        )
    finally:
        app.source.close()
    # given to gui --left/--right: said in the terminal at start-up, and under the first pair
    from stereovision.gui import add_arguments, build_app

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    args = ["--data", str(tmp_path), "--left", app.state.cam_left, "--right"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        started = build_app(parser.parse_args([*args, app.state.cam_right]))
    started._spawn = lambda coro: coro.close()
    _start(started)
    try:
        assert started.state.error == "" and started.state.rows_label == app.state.rows_label
        _capture(started)  # a pair of its own: no warning under it (as after an Open)
        assert started.state.captures == 2 and started.state.rows_label == ""
    finally:
        started.source.close()
    cv2.imwrite(str(tmp_path / "seq" / "left01.png"), img)  # now both start at 01
    # ... and both have a gap (04 deleted): 05 is never read. They ended at it and started
    # again without a word (the chessboard pairs without their 10: 11-14 never shown), where
    # capture and stream say it; the Capture that starts them again says it now
    for name in ("right03.png", "left05.png", "right05.png"):
        cv2.imwrite(str(tmp_path / "seq" / name), img)
    _open_cameras(app)
    try:
        assert app.state.error == "" and app.state.rows_label == ""
        said = []
        for _ in range(4):
            _capture(app)
            said.append(app.state.rows_label)
    finally:
        app.source.close()
    gap = (
        "{0} source '{1}/{0}%02d.png' ended after 3 images: {0}04.png is missing, so the 1 "
        "image numbered after it was not read (renumber them without the gap)"
    )
    folder = short_paths(str(tmp_path / "seq"), tmp_path / "seq")
    restarted = "; ".join(gap.format(side, folder) for side in ("left", "right"))
    assert app.state.error == ""
    assert said == ["", "", f"warning: started again from the first pair: {restarted}", ""]


def test_a_max_disparity_refused_while_a_pair_computes_stays_said_after_it():
    """A max disparity refused while a pair computed ("500" on the 450 px cones: "... is not
    smaller than the pair's width 450 px") was cleared by the computation's end, "ready" said
    under a field still holding 500 over a result of the old range (0-64 px), as if it had
    been taken. The refusal now stays after the computation, as a camera's failed read does."""
    import asyncio

    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-max-disp-refused-while-computing", [bundled_data_dir()])
    left, right = (cv2.imread(str(CONES / f"{s}.png"))[150:190] for s in ("left", "right"))
    app.pair = app.raw_pair = (left, right)  # 40 rows of the cones: 450 px wide

    async def run() -> None:
        app._lock = asyncio.Lock()
        computing = asyncio.ensure_future(app.recompute())
        await _until(lambda: app._computing)
        app.apply_max_disparity(text="500")
        await computing

    asyncio.run(run())
    refusal = "max disparity 500 px is not smaller than the pair's width 450 px"
    assert app.state.computations == 1 and app.chosen_max_disparity is None
    assert (app.state.error, app.state.status) == (refusal, "error")
    app.apply_max_disparity(text="auto")  # the range in use typed again: the refusal goes
    assert (app.state.error, app.state.status) == ("", "ready")


def test_a_load_or_scene_taken_after_a_failure_clears_it_before_computing(tmp_path):
    """A Load (or a scene chosen) after one that failed kept the failure on the page while the
    new pair computed: "no such file: cones/none.png" above the files being computed, as if
    this Load had failed too (until the computation's end). A choice taken clears it, as a
    Capture, a Play and an Open clear it when they start; a refused one still says its own."""
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-load-clears-failure", [bundled_data_dir()])
    spawned: list = []
    app._spawn = spawned.append
    app.state.left_file, app.state.right_file = "cones/none.png", "cones/right.png"
    app.load_files()
    assert app.state.error == "no such file: cones/none.png" and spawned == []
    app.state.left_file = "cones/left.png"
    app.load_files()
    assert (app.state.error, app.state.source_label, len(spawned)) == ("", "files", 1)
    spawned.pop().close()
    app._fail(ValueError("an earlier failure"))
    app._on_scene(scene=str(bundled_data_dir() / "cones"))
    assert (app.state.error, app.state.source_label, len(spawned)) == ("", "scene data/cones", 1)
    spawned.pop().close()


def test_a_click_refused_while_a_pair_computes_stays_said_after_it(tmp_path, monkeypatch):
    """A Load of a missing file, a Show, an Open, a scene, a Play, a Capture or a Save refused
    while a pair computed was said until the computation's end, which then said "ready" and
    cleared it ("no such file: cones/none.png" gone, as if the files had been taken; a Save
    whose writer failed, as if saved). The refusal now stays after it, as a camera's read."""
    import asyncio
    import threading

    from stereovision.gui import app as gui_app
    from stereovision.gui import bundled_data_dir

    app = _scene_app("test-click-refused-while-computing", [bundled_data_dir(), tmp_path])
    left, right = (cv2.imread(str(CONES / f"{s}.png"))[150:190] for s in ("left", "right"))
    app.pair = app.raw_pair = (left, right)  # 40 rows of the cones: fast
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "overview.png").write_bytes(b"")
    st = app.state
    computed, written = threading.Event(), threading.Event()
    real = gui_app.compute_view

    def gated(*args: Any, **kwargs: Any) -> Any:
        computed.wait(2.0)  # bounded: a broken app cannot hang the test
        return real(*args, **kwargs)

    def failing_write(*_: Any) -> list[str]:
        written.wait(2.0)  # fails once the pair computes
        raise OSError("disk full")

    monkeypatch.setattr(gui_app, "compute_view", gated)

    def load() -> None:
        st.left_file, st.right_file = "cones/none.png", "cones/right.png"
        app.load_files()

    def show() -> None:
        st.cloud_path = "cones/none.ply"
        app.open_cloud()

    def open_twice() -> None:
        st.cam_left = st.cam_right = "/dev/video0"
        app.open_cameras()

    def play() -> None:
        st.pair_folder = "cones/left.png"
        app.open_pair_folder()

    clicks = [
        (load, "no such file: cones/none.png"),
        (show, "no such file: cones/none.ply"),
        (open_twice, "the left and right fields are both camera /dev/video0: give the rig's"),
        (lambda: app._on_scene(scene="nowhere"), "no such file: nowhere"),
        (play, "not a folder: data/cones/left.png"),
        (app.capture, "no camera open: give --left/--right or open cameras below"),
        (lambda: app.save_clicked("mine"), f"save: {tmp_path.name}/mine already holds "),
    ]

    async def run() -> list[tuple[str, str]]:
        app._lock = asyncio.Lock()
        app._spawn = asyncio.ensure_future
        computed.set()
        await app.recompute()  # a result on show (a Save needs one)
        said = []
        for click, _ in clicks:
            computed.clear()
            computing = asyncio.ensure_future(app.recompute())
            await _until(lambda: app._computing)
            click()
            await asyncio.sleep(0.01)  # a Save's task runs to its refusal
            computed.set()
            await computing
            said.append((st.status, st.error))
        app._write_save = failing_write  # a Save under way when the pair starts computing
        st.save_dir = ""
        saving = asyncio.ensure_future(app.save())
        await asyncio.sleep(0.01)
        computing = asyncio.ensure_future(app.recompute())
        await _until(lambda: app._computing)
        written.set()
        await saving
        await computing
        said.append((st.status, st.error))
        return said

    said = asyncio.run(run())
    assert st.computations == 1 + len(clicks) + 1
    for (status, error), (_, start) in zip(said, clicks, strict=False):
        assert status == "error" and error.startswith(start), (status, error)
    assert said[-1][0] == "error" and said[-1][1].endswith("disk full"), said[-1]


def test_the_page_reads_a_16_bit_pair_at_its_16_bits_as_depth_does(tmp_path):
    """A scene, a Load of files and a folder of pairs read 16-bit PNGs at their top 8 bits
    (imread: a 12-bit pair matched from its 0-15 grey levels) where `depth`, `batch`, `eval` and
    `view` keep 16. They are read as `depth` reads them now (read_image)."""
    from stereovision.gui import bundled_data_dir
    from stereovision.gui.sources import FolderPairs
    from stereovision.io import read_image

    scene = tmp_path / "sc"
    scene.mkdir()
    for name in ("left.png", "right.png"):
        img = cv2.imread(str(bundled_data_dir() / "cones" / name))[:24, :40]
        cv2.imwrite(str(scene / name), np.rint(img * (4095 / 255)).astype(np.uint16))
    want = read_image(scene / "left.png")
    assert want.dtype == np.uint16 and want.max() > 255
    app = _scene_app("test-16-bit-pair", [tmp_path])
    app._load_scene(scene)
    assert app.pair is not None and np.array_equal(app.pair[0], want)
    app.pair = None
    app._spawn = lambda coro: coro.close()  # the computation: not the point here
    app.state.left_file, app.state.right_file = "sc/left.png", "sc/right.png"
    app.load_files()
    assert app.state.error == "" and app.pair is not None and np.array_equal(app.pair[0], want)
    left, _ = FolderPairs(scene, "sc").read()
    assert np.array_equal(left, want)
