"""``stereovision gui``: the paper's three windows (acquisition, stereo output, 3-D view).

A local trame web app, because robots are often headless and watched from another machine::

    stereovision gui                                  # bundled demo scene
    stereovision gui --left 0 --right 1 --calib rig.yaml
    stereovision gui --left l.avi --right r.avi --calib calib.txt --data ~/scenes

It listens on 127.0.0.1 unless ``--host`` says otherwise. Files chosen on the page can only come
from the bundled demo data and the folders given with ``--data``.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import errno
import logging
import signal
import sys
import threading
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import Any

__all__ = ["DEFAULT_HOST", "DEFAULT_PORT", "add_cli", "build_app", "cmd_gui", "main", "url_for"]

#: Loopback only by default: exposing the robot's cameras is an explicit decision (--host).
DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8080
#: The names of this machine alone (its loopback); any other name may resolve to a public
#: address. Compared case-insensitively, as a resolver does.
LOOPBACK_NAMES = frozenset({"localhost", "localhost."})


def is_loopback_host(host: str) -> bool:
    """Whether listening on ``host`` keeps the page to this machine: a loopback address (any
    of 127.0.0.0/8, ``::1``, ``::ffff:127.0.0.1``, in any form the bind reads: ``127.1``) or
    ``localhost`` (``localhost.``).

    Examples
    --------
    >>> [is_loopback_host(h) for h in ("127.0.0.2", "::ffff:127.0.0.1", "localhost.", "127.1")]
    [True, True, True, True]
    >>> [is_loopback_host(h) for h in ("0.0.0.0", "192.168.1.5", "localhost.example.com")]
    [False, False, False]
    """
    import ipaddress
    import socket

    if host.lower() in LOOPBACK_NAMES:
        return True
    try:
        addrs = [ipaddress.ip_address(host)]
    except ValueError:
        # The bind reads the host as getaddrinfo does, inet_aton's short forms too: 127.1,
        # 0x7f.1 and 2130706433 are 127.0.0.1 (they got the note). Numeric only: a name other
        # than localhost may resolve anywhere.
        try:
            found = socket.getaddrinfo(host, None, flags=socket.AI_NUMERICHOST)
            addrs = [ipaddress.ip_address(info[4][0]) for info in found]
        except (OSError, UnicodeError, ValueError):
            return False
    # Python 3.11's is_loopback is False for an IPv4-mapped one (::ffff:127.0.0.1)
    return bool(addrs) and all(
        a.is_loopback
        or (
            isinstance(a, ipaddress.IPv6Address)
            and a.ipv4_mapped is not None
            and a.ipv4_mapped.is_loopback
        )
        for a in addrs
    )


def bundled_data_dir() -> Path:
    """Folder of the bundled demo data (``stereovision/data``)."""
    return Path(str(resources.files("stereovision") / "data"))


def build_app(args: argparse.Namespace) -> Any:
    """Validate the arguments, open the sources and build the app (without starting the server).

    Raises
    ------
    ValueError, FileNotFoundError, OSError
        ``--left`` without ``--right`` (or the reverse), a missing data folder or calibration, a
        camera that cannot be opened.
    """
    from stereovision.gui.sources import AllowedFolders, open_stereo_source

    try:  # before a camera is opened
        import trame.app  # noqa: F401
    except ImportError:
        raise RuntimeError("the GUI needs trame: pip install 'stereovision-rs[gui]'") from None
    if (args.left is None) != (args.right is None):
        raise ValueError("give both --left and --right camera sources, or neither")
    if getattr(args, "fourcc", None) is not None and args.left is None:
        raise ValueError("--fourcc asks the cameras for a format: give --left and --right too")
    from_bag = getattr(args, "from_bag", None)
    if from_bag is not None and args.left is not None:
        raise ValueError("--from-bag replaces --left and --right: give one source")
    topics = (getattr(args, "left_topic", None), getattr(args, "right_topic", None))
    if from_bag is None and topics != (None, None):
        # as capture and calibrate refuse them: the page was served with the topic ignored
        raise ValueError("--left-topic and --right-topic are for --from-bag")
    if not 0 <= args.port <= 65535:
        # 0 is no port but "a free one": said, as --help does not say it
        from stereovision.cli import PORT_WORDS

        raise ValueError(f"--port: {PORT_WORDS}, got {args.port}")
    folders = AllowedFolders([bundled_data_dir(), *(args.data or [])])
    calib = None
    sizeless = None
    if args.calib is not None:
        from stereovision.calibration import _sizeless
        from stereovision.cli import load_calibration

        if Path(args.calib).exists() and _sizeless(args.calib):
            # OpenCV stereo_calib output (a Q.dat alone, a KITTI file without S_rect_02) holds
            # no image size: the first pair it is used with sizes it (as batch's first pair,
            # stream's frames); read now at a stand-in size only to refuse a bad file or unit
            load_calibration(args.calib, args.calib_unit, size=(640, 480))
            sizeless = (str(args.calib), args.calib_unit)
        else:
            # gui has no --rectification, which the refusal of rectify's homographies named
            from stereovision.cli import _HOMOGRAPHIES_USE

            calib = load_calibration(
                args.calib,
                args.calib_unit,
                homographies="gui takes no homographies (its Rectify button finds them anew "
                f"from the pair on show); {_HOMOGRAPHIES_USE}",
            )
    elif args.calib_unit is not None:  # refused as the other commands refuse it (it was ignored)
        from stereovision.cli import load_calibration

        load_calibration(None, args.calib_unit)
    if from_bag is not None and getattr(args, "read_timeout", None) is not None:
        raise ValueError("--read-timeout bounds a camera's read: a bag is read from disk")
    from stereovision.capture import cli_read_timeout

    read_timeout = cli_read_timeout(args)  # also for the cameras opened on the page
    source = None
    label = None
    names = (str(args.left or ""), str(args.right or ""))
    if args.left is not None:
        from stereovision.capture import _refuse_one_camera_twice, _same_path
        from stereovision.gui.sources import parse_source

        left, right = parse_source(args.left), parse_source(args.right)
        # in capture's and stream's words (--left 3 --right 3 was "'3' and '3' are both
        # camera /dev/video3" here, "both camera 3" there): the second open failed with a
        # hint about another program using the camera
        _refuse_one_camera_twice(left, right)
        source = open_stereo_source(
            args.left, args.right, fourcc=getattr(args, "fourcc", None), read_timeout=read_timeout
        )
        if _same_path(left, right):
            # said as capture and stream say it (once the source opened: a missing one is
            # said as such); the page showed every disparity 0 without a word
            import warnings

            from stereovision.capture import mask_url_secrets

            try:
                warnings.warn(
                    f"--left and --right are the same source {mask_url_secrets(str(left))!r}: "
                    "every pair is one view twice and every disparity comes out 0 (two "
                    "cameras' views are needed)",
                    UserWarning,
                    stacklevel=2,
                )
            except BaseException:  # made an error (python -W error): the source is not used
                source.close()
                raise
    elif from_bag is not None:
        from stereovision.gui.sources import open_bag_source

        source, bag_calib, topics = open_bag_source(
            from_bag, getattr(args, "left_topic", None), getattr(args, "right_topic", None)
        )
        calib = calib if calib is not None or sizeless is not None else bag_calib
        label = f"bag {Path(from_bag).name}: {topics[0]} / {topics[1]}"
    from trame.app import get_server

    from stereovision.gui.app import StereoApp

    server = get_server("stereovision-gui", client_type="vue3")
    server.state.trame__title = "stereovision"
    return StereoApp(
        server,
        folders,
        bundled_data_dir() / "cones",
        source=source,
        calib=calib,
        source_names=names,
        source_label=label,
        sizeless_calib=sizeless,
        read_timeout=read_timeout,
    )


def url_for(host: str, port: int) -> str:
    """The page's address: ``http://host:port/`` (an IPv6 host in brackets).

    Examples
    --------
    >>> url_for("127.0.0.1", 8080)
    'http://127.0.0.1:8080/'
    >>> url_for("::1", 8080)
    'http://[::1]:8080/'
    """
    from stereovision.stream import _host_port  # stream --serve's rule, said once

    return f"http://{_host_port(host, port)}/"


#: What the server's libraries log when a page is closed while a message to it is being sent.
_CLOSED_PAGE = ("ClientConnectionResetError", "Cannot write to closing transport")


class ClosedPageFilter(logging.Filter):
    """Drops the server libraries' tracebacks of a page closed mid-message.

    Closing the browser tab while the 3-D view streamed a frame printed about 40 lines of
    tracebacks in the terminal (wslink's "Exception raised", its repr and trace, then
    aiohttp's "Error handling request"), for nothing that went wrong. wslink's bare
    "Exception raised" line is dropped for every exception: its next two lines name the
    exception and its trace, and they stay for any other one.
    """

    def filter(self, record: logging.LogRecord) -> bool:
        exc = record.exc_info[1] if record.exc_info else None
        if isinstance(exc, ConnectionResetError):
            return False
        msg = record.getMessage()
        if msg == "Exception raised":
            return False
        return not any(s in msg for s in _CLOSED_PAGE)


#: The loggers :class:`ClosedPageFilter` is put on by :func:`cmd_gui`.
SERVER_LOGGERS = ("wslink.protocol", "aiohttp.server")


def quiet_closed_pages() -> ClosedPageFilter:
    """Put one :class:`ClosedPageFilter` on each of :data:`SERVER_LOGGERS` (again: no second
    one) and return it."""
    for name in SERVER_LOGGERS:
        for f in logging.getLogger(name).filters:
            if isinstance(f, ClosedPageFilter):
                return f
    flt = ClosedPageFilter()
    for name in SERVER_LOGGERS:
        logging.getLogger(name).addFilter(flt)
    return flt


def cmd_gui(args: argparse.Namespace) -> int:
    """``stereovision gui``: build the app and serve it until interrupted.

    The address is printed once the server listens, with the port it got (``--port 0``: a
    free one the system chose).

    Raises
    ------
    KeyboardInterrupt
        Ctrl+C (SIGINT) stopped the server (:class:`~stereovision._interrupt.Terminated` for
        SIGTERM), once the page's work is stopped and the camera closed: the CLI's exit 130
        (143), where trame's own stop returned and the command exited 0.
    OSError
        The server cannot listen there: ``"port 8080 on 127.0.0.1 is in use ..."`` when another
        program holds the port, the system's reason otherwise.
    """
    from stereovision._interrupt import Terminated

    app = build_app(args)
    quiet_closed_pages()
    bound = []

    def announce(**_: Any) -> None:
        bound.append(app.server.port)
        url = url_for(args.host, app.server.port)
        print(f"stereovision gui on {url} (Ctrl+C to stop)", flush=True)
        # 127.0.0.2 (all of 127/8 is loopback) and "localhost." got the note too
        if not is_loopback_host(args.host):
            print(
                f"note: listening on {args.host}: anyone who can reach this address sees the "
                "cameras",
                file=sys.stderr,
            )

    stopped_by: list[int] = []
    loops: list[asyncio.AbstractEventLoop] = []
    # the caller's handlers: the loop's (aiohttp's, then ours) were left in place once the
    # server stopped, so a program calling this had its Ctrl+C ignored from then on
    kept = _signal_state()

    def stop_on(signum: int) -> None:
        stopped_by.append(signum)
        raise SystemExit  # how aiohttp's own handler stops the loop; trame's start returns

    def hear_signals(**_: Any) -> None:
        # aiohttp's handlers (set once the server is set up: on ready, ours replace them) stop
        # the server as ours do but leave no trace of the signal: Ctrl+C exited 0, not 130
        with contextlib.suppress(RuntimeError, ValueError, NotImplementedError):
            loop = asyncio.get_running_loop()  # RuntimeError: none (not served by a loop)
            for signum in (signal.SIGINT, signal.SIGTERM):
                loop.add_signal_handler(signum, stop_on, signum)
            loops.append(loop)

    def ready(**_: Any) -> None:
        # one hook, in this order (trame keeps its hooks in a set, called in no set order): a
        # Ctrl+C as soon as the address is said stops the server; after the bind: the real
        # port, and only if it bound
        hear_signals()
        announce()

    app.ctrl.on_server_ready.add(ready)
    # trame parses sys.argv itself: give it only --nosignalhandlers. aiohttp's own handlers (set
    # when the server is set up, until on_server_ready put ours) stopped it without a trace: a
    # signal then exited 0; without them Python's (KeyboardInterrupt, the CLI's Terminated) act
    argv, sys.argv = sys.argv, [*sys.argv[:1], "--nosignalhandlers"]
    try:
        app.server.start(
            port=args.port,
            host=args.host,
            open_browser=not args.no_browser,
            show_connection_info=False,
            timeout=0,
        )
        if stopped_by[:1] == [signal.SIGTERM]:
            raise Terminated(f"signal {signal.SIGTERM}")
        if stopped_by:
            raise KeyboardInterrupt
    except OSError as exc:
        if bound:  # a later failure: its own message
            raise
        if exc.errno == errno.EADDRINUSE:
            msg = (
                f"port {args.port} on {args.host} is in use (another server?): choose another "
                "with --port, or --port 0 for a free one"
            )
        else:
            msg = f"cannot listen on {args.host} port {args.port}: {exc.strerror or exc}"
        err = OSError(msg)
        err.errno = exc.errno
        raise err from exc
    finally:
        sys.argv = argv
        # trame's server is one per process ("stereovision-gui"), its hooks kept: a program's
        # second gui.main ran the first's too (its address said twice, a Ctrl+C maybe heard
        # by the first's handler, its stop unseen: exit 0)
        app.ctrl.on_server_ready.discard(ready)
        app.detach()  # the app's own hooks too: its ready hook, its state handlers
        try:
            app.stop_work()  # the computation under way is not waited for (a Save is)
            if app.source is not None:
                app.source.close()
        finally:
            # last: until the Save is whole and the camera closed, a second signal stays the
            # loop's; put back even if the close failed (its error left them the loop's)
            _restore_signals(kept, loops)
    return 0


def _signal_state() -> tuple[dict[int, Any], int] | None:
    """The SIGINT and SIGTERM handlers and the wakeup fd as they are, to be put back by
    :func:`_restore_signals`; None outside the main thread (signals cannot be set there)."""
    if threading.current_thread() is not threading.main_thread():
        return None
    fd = signal.set_wakeup_fd(-1)  # read by setting: there is no getter
    signal.set_wakeup_fd(fd)
    return {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}, fd


def _restore_signals(
    kept: tuple[dict[int, Any], int] | None, loops: Sequence[asyncio.AbstractEventLoop]
) -> None:
    """Put back the handlers :func:`_signal_state` kept: the server's loop took SIGINT and
    SIGTERM (its no-op handler, a wakeup fd into its pipe) and kept them after it stopped."""
    if kept is None:
        return
    for loop in loops:
        # taken from the loop too: closing it later (its collection) set Python's defaults
        for sig in (signal.SIGINT, signal.SIGTERM):
            with contextlib.suppress(RuntimeError, ValueError, NotImplementedError):
                loop.remove_signal_handler(sig)
    handlers, fd = kept
    for signum, handler in handlers.items():
        if handler is not None:  # None: set outside Python, cannot be put back
            signal.signal(signum, handler)
    with contextlib.suppress(ValueError):  # a closed or blocking fd: left unset
        signal.set_wakeup_fd(fd)


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The ``gui`` options."""
    p.add_argument("--left", help="left camera: device index, video file or image pattern")
    p.add_argument("--right", help="right camera: device index, video file or image pattern")
    from stereovision.capture import add_bag_args, fourcc_code

    p.add_argument(
        "--fourcc",
        type=fourcc_code,
        help="pixel format asked of the cameras: YUYV (raw) or MJPG (compressed; two webcams on "
        "one USB 2 bus often need it)",
    )
    add_bag_args(
        p,
        "play a rig recorded in a ROS 1 / ROS 2 bag instead (its camera_info as calibration)",
        skew=False,
    )
    from stereovision.capture import add_read_timeout

    add_read_timeout(p)
    from stereovision.cli import CALIB_FILES_HELP, add_calib_unit

    p.add_argument("--calib", help=f"calibration of the camera pair: {CALIB_FILES_HELP}")
    add_calib_unit(p)
    p.add_argument(
        "--data",
        action="append",
        metavar="DIR",
        help="folder the page may open files from (repeatable; the demo data is always allowed)",
    )
    p.add_argument(
        "--port",
        type=int,
        default=DEFAULT_PORT,
        help=f"port the page is served on (default {DEFAULT_PORT})",
    )
    from stereovision.cli import listen_address

    p.add_argument(
        "--host",
        type=listen_address,
        default=DEFAULT_HOST,
        help=f"listen address (default {DEFAULT_HOST})",
    )
    p.add_argument("--no-browser", action="store_true", help="do not open a browser")


def add_cli(subparsers: Any) -> None:
    """Register ``stereovision gui`` on the CLI's sub-parsers."""
    p = subparsers.add_parser("gui", help="three-panel stereo GUI in the browser (trame)")
    add_arguments(p)
    p.set_defaults(func=cmd_gui)


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m stereovision.gui``: as ``stereovision gui`` (errors: one line, exit 2).

    Run as the process's own command (``argv`` None), it ends the process itself, as the CLI's
    ``main`` does, when a camera's open or read it gave up is still in OpenCV
    (``--read-timeout 1e-300``): that thread coming back out while the interpreter shut down
    aborted the process, "terminate called without an active exception" and exit 134, not 2.
    """
    status = _main(argv)
    if argv is None:
        from stereovision.cli import end_past_native_threads

        end_past_native_threads(status)
    return status


def _main(argv: Sequence[str] | None) -> int:
    """:func:`main`'s work: parse ``argv`` and run the GUI."""
    # the CLI's parser: a refused value in one line, with the unit hint (``--read-timeout
    # 10s``), where argparse's own printed its usage block and no hint
    from stereovision._interrupt import HeldInterrupts, Terminated

    try:  # the CLI's module and the options' are imported here (0.2 s), as the CLI's _main
        # held until they are whole, as the CLI's are: a Ctrl+C inside NumPy's C
        # initialisation came out as NumPy's ImportError, a traceback
        with HeldInterrupts():
            from stereovision.cli import _Parser

            p = _Parser(prog="stereovision gui", description=__doc__.splitlines()[0])
            add_arguments(p)
        args = p.parse_args(argv)
    except Terminated:  # python -m stereovision.gui's handler, set before these imports
        print("stereovision: terminated (SIGTERM)", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("stereovision: interrupted", file=sys.stderr)
        return 130
    from stereovision.cli import run_parsed

    # run as the CLI runs a command: its one-line errors and warnings (a calibration's warning
    # came out as Python's "<frozen runpy>:88: UserWarning: ..."; a path given with a newline
    # was cut there), SIGTERM as Terminated (143)
    args.func = cmd_gui
    return run_parsed(args)
