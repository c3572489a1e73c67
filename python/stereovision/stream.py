"""Live depth from two cameras: grab, rectify, match, report (``stereovision stream``).

Two stages run at once (the machine this targets has two cores): a *producer* thread grabs the
next pair from the :class:`~stereovision.capture.StereoCamera` and rectifies it into a bounded
queue while the main thread computes the depth of the current one. The Rust kernels release the
GIL, so the producer's decoding and remapping overlap the matching instead of adding to it.

Every second a report is emitted: frames per second over that second, the mean time of each stage
(``grab``, ``rectify``, ``temporal``, ``prepare``, ``match``, ``fill``, ``triangulate``), the
mean latency from the start of a pair's grab to its depth, the time the matcher waited for the
producer, the left/right grab skew, the share of pixels with a disparity and the frames averaged
per pixel. ``--json`` prints each report as one JSON object on stdout, then a final
summary object (``"summary": true``).

The result is shown by serving it over HTTP (OpenCV's own windows are not part of the headless
OpenCV build the package depends on): ``http://HOST:PORT/`` is a page with the live left image and
colour-mapped disparity side by side, ``/stream.mjpg`` the MJPEG stream itself (any browser or
``ffplay`` plays it) and ``/frame.jpg`` the latest frame. Frames are encoded only while a client
asks for them, each once for all clients. ``--no-display`` turns the server off (headless robots).
"""

from __future__ import annotations

import argparse
import math
import queue
import socket
import statistics
import sys
import threading
import time
import warnings
from array import array
from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

import cv2
import numpy as np

from stereovision._interrupt import Terminated
from stereovision._jsonout import json_line
from stereovision._validate import (
    HELD_WARNINGS,
    _shown,
    _unit_range_error,
    as_image_array,
    escaped,
    finite_number,
    first_line,
    number_shown,
    path_given,
    positive_whole,
    real_number,
    require,
    too_large_for_float,
    user_stacklevel,
    whole_value,
)
from stereovision.calibration import Calibration, fit_to_frames
from stereovision.capture import (
    DEFAULT_READ_TIMEOUT,
    SourceError,
    StereoCamera,
    StereoFrame,
    _counted,
    _describe_source,
    _device_ended,
    add_source_args,
    check_read_timeout,
    cli_read_timeout,
    open_source,
    read_within,
    resampled_for_temporal_note,
    temporal_average,
)
from stereovision.rectification_check import RectificationCheck, check_rectification

__all__ = [
    "STAGES",
    "FrameServer",
    "StreamReport",
    "add_cli",
    "cmd_stream",
    "run_stream",
]

#: Stages timed for every pair, in pipeline order.
STAGES = ("grab", "rectify", "temporal", "prepare", "match", "fill", "triangulate")
#: Pairs grabbed ahead of the one being matched. One is enough to hide the grab and rectify
#: behind the matching; more would only age a live camera's frames.
QUEUE_SIZE = 1
#: Seconds the end of a pipelined stream waits for its grab thread to stop. A camera hung in
#: the read under way (``read_timeout=None``, or a longer one) keeps it longer: it is then left
#: behind, a daemon thread that does not hold up the interpreter's exit, with a warning.
GRAB_JOIN_TIMEOUT = 5.0
#: Seconds between two reports.
REPORT_PERIOD = 1.0
#: JPEG quality of the served frames.
JPEG_QUALITY = 80
DEFAULT_PORT = 8765
#: Seconds between the view server's checks for :meth:`FrameServer.close` (its longest wait).
SERVE_POLL_S = 0.05

_END = object()  # the producer's end-of-stream marker
#: ``ground_every``: warn when the camera's height above the floor moves by more than this
#: share of the first fit's, or its pitch or roll by more than :data:`GROUND_TILT_DEG` (a
#: mount that slipped; the fits of a still rig on KITTI agree to 0.1 % and 0.07 degrees).
GROUND_HEIGHT_SHARE = 0.05
GROUND_TILT_DEG = 2.0
#: ... and only when the first fit's plane no longer holds: its share of the pixels on the new
#: frame (:meth:`~stereovision.ground.GroundPlane.support`) below this part of its own. Frames of
#: a still rig keep 0.85-1.03 of it (JPEG noise on TartanAir, ETH3D, KITTI), where fresh fits
#: may differ by 4-20 degrees on uneven ground; a camera turned 2 degrees keeps 0.09.
GROUND_SUPPORT_KEPT = 0.5
#: Noise (grey levels, :func:`~stereovision.temporal.noise_sigma` of the first left frame) above
#: which the stream suggests ``--temporal``: Gaussian noise of 8 per colour channel measures
#: 5.2-6.6 on the GT scenes, the scenes as given 0.3-3.7 (fine texture counts a little).
NOISY_SIGMA = 4.5


@dataclass
class _Pair:
    """A grabbed (and rectified) pair on its way to the matcher."""

    left: np.ndarray
    right: np.ndarray
    index: int
    t_start: float  # perf_counter at the start of the grab
    grab_s: float
    rectify_s: float
    skew_ms: float
    check: RectificationCheck | None = None  # the rectification check of this pair, if any
    pair: int = 0  # index of the pair in this stream
    temporal_s: float = 0.0
    averaged: float = 1.0  # mean frames in a pixel's temporal mean (1: not averaged)
    stamp_ns: int = 0  # the grab's time, ns since the epoch (a recording: its own stamp)
    raw_left: np.ndarray | None = None  # the first pair's left frame as grabbed (its noise)
    # the temporal filter's (frames, restarts, sigma) once it took this pair: the summary's
    # figures are those of the last pair counted, not of pairs it took and never counted
    filtered: tuple[int, int, float] | None = None


@dataclass
class _Note:
    """A warning of the grabbing, given by :func:`run_stream` when it takes it: warned in the
    producer thread it was attributed to threading.py (unpipelined, to stream.py), not to the
    caller's line."""

    message: str
    category: type[Warning] = UserWarning
    #: Took a slot of the producer's (yielded by :func:`_pairs`); a source's warning held in
    #: the grabbing thread (:data:`~stereovision._validate.HELD_WARNINGS`) rides with its pair.
    slot: bool = True


@dataclass
class _Done:
    """Per-pair figures of a finished pair."""

    stages: dict[str, float]
    latency_s: float
    wait_s: float
    skew_ms: float
    density: float
    averaged: float = 1.0


@dataclass
class StreamReport:
    """Aggregate figures of a run of :func:`run_stream`.

    Attributes
    ----------
    frames : int
        Pairs processed.
    seconds : float
        Wall time from the first grab to the last depth map.
    fps : float
        ``frames / seconds``.
    stage_ms : dict of str to float
        Median time of each stage of :data:`STAGES` per pair, in milliseconds.
    latency_ms : float
        Median time from the start of a pair's grab to its depth map.
    wait_ms : float
        Median time the matcher waited for the next pair (0 when the producer keeps up).
    skew_ms : dict of str to float
        ``mean`` and ``max`` left/right grab skew.
    max_disparity : int or float
        Disparity range searched (a float when fractional; 0 when no pair came to estimate it).
    pipelined : bool
        Whether grab/rectify ran in the producer thread.
    ended : str
        ``"frames"`` (the ``frames`` limit), ``"end of stream"``, ``"interrupted"`` (Ctrl-C),
        ``"terminated"`` (SIGTERM, under the CLI), ``"source failed"`` (a source failed
        after the first pair: a frame that does not decode, of another shape or, with
        ``temporal``, of more than 8 bits, a camera
        device or live stream (``rtsp://``) that stopped delivering, unplugged or its network
        gone; see :attr:`error`) or ``"output failed"``
        (``on_result`` or ``on_stamped_result`` raised an OSError, e.g. a bag on a full disk:
        that pair is not counted; see :attr:`error`).
    rectification : dict or None
        :func:`~stereovision.rectification_check.check_rectification` of the first pair, as a
        dict (None when ``check=False`` or no pair came).
    checks : list of dict
        Every check made (the first pair's and, with ``check_every``, the later ones), each
        with the index of its ``pair``.
    grounds : list of dict
        With ``ground_every``: every floor fit (:meth:`~stereovision.ground.GroundPlane.as_dict`
        and the ``pair``), or ``{"pair": n, "found": False}`` when no floor was in view.
    ground_reason : str or None
        With ``ground_every``: why the last fit that found no floor found none (for example
        ``ground plane: none found (0 pixels have a disparity; a fit needs 500)``); None when
        every fit found one. Said on the CLI's ``floor:`` line when no fit found a floor; not
        in :meth:`as_dict`.
    noise_sigma : float
        Noise of the first left frame as grabbed (before rectification), in grey levels
        (:func:`~stereovision.temporal.noise_sigma`; NaN when no pair came, or the frame is all
        black or white: nothing to measure).
    temporal : dict or None
        With a :class:`~stereovision.temporal.TemporalFilter`: ``frames_averaged`` (mean over
        the pairs of the frames in a pixel's mean), ``restarts`` (pairs of this run on which
        the rig or scene moved, not those of an earlier run of the same filter) and
        ``noise_sigma`` (its last noise estimate, grey levels; NaN when it saw no frame, or
        none it could measure: all black or white), as
        of the last pair counted in :attr:`frames`. The filter itself also took the pairs that
        were not: the one whose output failed, and those grabbed ahead when pipelined (its own
        ``frames`` and ``restarts`` can be higher).
    error : str or None
        With ``ended`` ``"source failed"`` or ``"output failed"``: the error (None otherwise).
    density : float
        Mean over the pairs of :attr:`DepthResult.density
        <stereovision.depth.DepthResult.density>` (share of pixels with a disparity, 0-1).
    reports : list of dict
        The latest :data:`REPORTS_KEPT` per-second reports, as ``on_report`` got them (which
        gets every one; not in :meth:`as_dict`).
    """

    frames: int
    seconds: float
    fps: float
    stage_ms: dict[str, float]
    latency_ms: float
    wait_ms: float
    skew_ms: dict[str, float]
    max_disparity: float
    pipelined: bool
    ended: str
    density: float = math.nan
    reports: list[dict[str, Any]] = field(default_factory=list, repr=False)
    rectification: dict[str, Any] | None = None
    checks: list[dict[str, Any]] = field(default_factory=list, repr=False)
    grounds: list[dict[str, Any]] = field(default_factory=list, repr=False)
    ground_reason: str | None = field(default=None, repr=False)
    temporal: dict[str, float] | None = None
    noise_sigma: float = math.nan
    error: str | None = None

    def as_dict(self) -> dict[str, Any]:
        """The JSON summary object (``"summary": true``).

        Returns
        -------
        dict
            The report's fields by name but ``reports`` and ``ground_reason`` (times rounded:
            ``seconds``, ``fps``, ``stage_ms``, ``latency_ms``, ``wait_ms``, ``skew_ms``,
            ``density``, ``noise_sigma``), with ``"summary": True``.
        """
        return {
            "summary": True,
            "frames": self.frames,
            "seconds": round(self.seconds, 4),
            "fps": round(self.fps, 3),
            "stage_ms": {k: round(v, 3) for k, v in self.stage_ms.items()},
            "latency_ms": round(self.latency_ms, 3),
            "wait_ms": round(self.wait_ms, 3),
            "skew_ms": {k: round(v, 4) for k, v in self.skew_ms.items()},
            "density": round(self.density, 4),
            "max_disparity": self.max_disparity,
            "pipelined": self.pipelined,
            "ended": self.ended,
            "rectification": self.rectification,
            "checks": self.checks,
            "grounds": self.grounds,
            "temporal": self.temporal,
            "noise_sigma": round(self.noise_sigma, 3),
            "error": self.error,
        }


# ------------------------------------------------------------------------------------ serving


def _compose(left: np.ndarray, disparity: np.ndarray, max_disparity: float) -> np.ndarray:
    """Left image and colour-mapped disparity (fixed 0..max_disparity scale, NaN black)."""
    finite = np.isfinite(disparity)
    u8 = np.clip(np.nan_to_num(disparity, nan=0.0) * (255.0 / max(max_disparity, 1.0)), 0, 255)
    colour = cv2.applyColorMap(u8.astype(np.uint8), cv2.COLORMAP_TURBO)
    colour[~finite] = 0
    return np.hstack([_view_bgr(left), colour])


def _view_bgr(img: np.ndarray) -> np.ndarray:
    """``img`` as the 8-bit BGR image the JPEG view shows: an image sequence's PNGs with alpha
    or of 16 bits (a mono16 bag's too) reach the stream as they are, and their hstack with the
    colour map raised in the server's thread (alpha), or the JPEG clipped them to white."""
    if img.dtype == np.uint16:  # 0-65535 as 0-255, rounded, as as_bgr_uint8 does
        img = ((img.astype(np.uint32) + 128) // 257).astype(np.uint8)
    elif img.dtype != np.uint8:  # floats in [0, 1]
        img = np.clip(np.rint(np.nan_to_num(img * 255.0)), 0, 255).astype(np.uint8)
    if img.ndim == 2:
        img = img[:, :, None]
    if img.shape[2] == 1:
        return np.repeat(img, 3, axis=2)
    return img[:, :, :3]  # BGRA: without its alpha


class _ViewServer(ThreadingHTTPServer):
    """The view's HTTP server: a viewer that goes away mid-answer is no error."""

    daemon_threads = True

    def handle_error(self, request: Any, client_address: Any) -> None:
        # A browser tab closed or a player quit while it was answered (the page, a frame, the
        # MJPEG headers): socketserver printed a 20-line traceback of the reset on the
        # stream's stderr, among its reports. Any other error is still printed.
        if isinstance(sys.exc_info()[1], ConnectionError):
            return
        super().handle_error(request, client_address)


class _ViewServer6(_ViewServer):
    """:class:`_ViewServer` on an IPv6 address (``--host ::1``, ``::``): the IPv4 socket
    refused it ("Address family for hostname not supported")."""

    address_family = socket.AF_INET6


def _host_port(host: str, port: int) -> str:
    """``host:port`` as a URL says it: an IPv6 address in brackets (``[::1]:8765``), its zone's
    ``%`` escaped (RFC 6874: ``[fe80::1%25eth0]:8765``; a bare ``%eth0`` is an invalid escape
    to a strict URL parser; urllib and curl take both)."""
    if ":" not in host:
        return f"{host}:{port}"
    return f"[{host.replace('%', '%25')}]:{port}"


class FrameServer:
    """A tiny MJPEG-over-HTTP view of the latest result.

    ``GET /`` returns a page showing the stream, ``/stream.mjpg`` the multipart MJPEG stream,
    ``/frame.jpg`` the latest frame as one JPEG (503 before the first one); ``HEAD`` their
    status and headers.

    Parameters
    ----------
    host : str
        Address to listen on (``127.0.0.1`` by default: robots are often on shared networks);
        an IPv6 one (``::1``, ``::``) too.
    port : int
        TCP port; 0 picks a free one (see :attr:`port`).

    Raises
    ------
    OSError
        If the address cannot be bound (port in use, ...).
    ValueError
        If ``port`` is not 0 to 65535, or ``host`` is empty (a bind's every interface).
    """

    def __init__(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT) -> None:
        # a count's rule (whole_value): np.int64(8080) read from an array was refused
        from stereovision.cli import PORT_WORDS, check_listen_address

        whole = whole_value(port)
        if whole is None or not 0 <= whole <= 65535:
            # in --serve's and gui --port's words
            raise ValueError(f"port: {PORT_WORDS}, got {port!r}")
        port = whole

        # "" is a bind's every interface (0.0.0.0), said as http://:8765/
        host = check_listen_address(host, "host")
        self._cond = threading.Condition()
        self._latest: tuple[np.ndarray, np.ndarray, float] | None = None
        self._seq = 0
        # the latest frame's JPEG and its number: one encode per frame for every viewer
        self._jpeg: tuple[int, bytes] | None = None
        self._jpeg_lock = threading.Lock()
        self._closed = False
        self._host = host
        server = self

        class Handler(BaseHTTPRequestHandler):
            #: a HEAD request: the GET's status and headers, no body
            head = False

            def log_message(self, format: str, *args: Any) -> None:  # quiet
                return

            def do_HEAD(self) -> None:
                # a robot's health check (curl -I, a monitor's probe of /frame.jpg) got 501
                # "Unsupported method", as if the view were down
                self.head = True
                self.do_GET()

            def do_GET(self) -> None:
                path = self.path.split("?", 1)[0]
                if path == "/":
                    body = (
                        b"<!doctype html><title>stereovision stream</title>"
                        b'<body style="margin:0;background:#111">'
                        b'<img src="/stream.mjpg" style="width:100%"></body>'
                    )
                    self._send(200, "text/html; charset=utf-8", body)
                elif path == "/frame.jpg":
                    jpg = server.latest_jpeg()
                    if jpg is None:
                        self._send(503, "text/plain", b"no frame yet\n")
                    else:
                        self._send(200, "image/jpeg", jpg)
                elif path == "/stream.mjpg":
                    self._stream()
                else:
                    self._send(404, "text/plain", b"not found\n")

            def _send(self, code: int, ctype: str, body: bytes) -> None:
                self.send_response(code)
                self.send_header("Content-Type", ctype)
                self.send_header("Content-Length", str(len(body)))
                self.send_header("Cache-Control", "no-store")
                self.end_headers()
                if not self.head:
                    self.wfile.write(body)

            def _stream(self) -> None:
                self.send_response(200)
                self.send_header("Content-Type", "multipart/x-mixed-replace; boundary=frame")
                self.send_header("Cache-Control", "no-store")
                self.end_headers()
                if self.head:
                    return
                seen = -1
                try:
                    while True:
                        jpg, seen = server.wait_jpeg(seen, timeout=1.0)
                        if jpg is None:
                            if server.closed:
                                return
                            continue
                        self.wfile.write(
                            b"--frame\r\nContent-Type: image/jpeg\r\n"
                            + f"Content-Length: {len(jpg)}\r\n\r\n".encode()
                            + jpg
                            + b"\r\n"
                        )
                except (BrokenPipeError, ConnectionResetError):
                    return

        try:
            server_class = _ViewServer6 if ":" in host else _ViewServer
            address: tuple[Any, ...] = (host, port)
            if "%" in host:
                # a link-local address with its interface (fe80::1%eth0, which gui --host
                # serves on): bound as (host, port) it lost its scope, "Invalid argument";
                # getaddrinfo gives the (host, port, flow, scope id) bind needs
                info = socket.getaddrinfo(host, port, socket.AF_INET6, socket.SOCK_STREAM)
                address = info[0][4]
            self._httpd = server_class(address, Handler)
        except OSError as exc:
            # "[Errno 98] Address already in use" named neither the port nor the way out
            import errno

            why = exc.strerror or str(exc)
            hint = (
                "another stream running? choose another port with --serve PORT, or --no-display"
                if exc.errno == errno.EADDRINUSE
                else "check --host, or --no-display"
            )
            err = OSError(f"cannot serve the view on {_host_port(host, port)}: {why} ({hint})")
            err.errno = exc.errno
            raise err from None
        # close() waits for the server's loop to see the stop: at socketserver's 0.5 s poll
        # every stream with a view took 0.45-0.5 s longer to end (after Ctrl-C too)
        self._thread = threading.Thread(
            target=self._httpd.serve_forever,
            kwargs={"poll_interval": SERVE_POLL_S},
            name="stereovision-serve",
            daemon=True,
        )
        self._thread.start()

    @property
    def port(self) -> int:
        """The TCP port listened on."""
        return int(self._httpd.server_address[1])

    @property
    def url(self) -> str:
        """``http://host:port/`` (an IPv6 host in brackets: ``http://[::1]:8765/``)."""
        return f"http://{_host_port(self._host, self.port)}/"

    @property
    def closed(self) -> bool:
        """True after :meth:`close`."""
        return self._closed

    def update(self, left: np.ndarray, disparity: np.ndarray, max_disparity: float) -> None:
        """Publish a result (kept by reference: encoded when a client first asks, once for all).

        Raises
        ------
        ValueError
            If ``left`` is no image (uint8, uint16 or float in [0, 1]), or ``disparity`` not a
            2-D map of its size: the frame is composed side by side in the server's thread,
            where every request then failed (no answer, a traceback on stderr). If
            ``max_disparity``, the top of the colour scale, is not a positive number.
        """
        # NaN (np.nanmax of a map without a value) coloured every pixel of every frame as the
        # cast of NaN, with NumPy's RuntimeWarning from the server's thread
        top = finite_number(max_disparity, "max_disparity")
        if not top > 0:
            raise ValueError(f"max_disparity: expected a positive number, got {max_disparity!r}")
        # an array, kept by reference: a nested list failed in the server's thread as the map
        # of another size did ("'list' object has no attribute 'dtype'"), as did 2 channels (the
        # hstack) and an empty image (OpenCV's JPEG encoder)
        left = np.asarray(left)
        if left.ndim not in (2, 3) or left.size == 0:
            raise ValueError(f"left: expected an (H, W) or (H, W, C) image, got {left.shape}")
        if left.ndim == 3 and left.shape[2] == 2:  # (more: the first 3 shown, as BGRA's)
            raise ValueError(f"left: expected 1, 3 or 4 channels, got {left.shape[2]}")
        # the package's image dtypes: int64 (a list of grey levels) was shown white as floats
        # past 1, strings failed in the server's thread; a big-endian uint16 in native order
        left = as_image_array(left, "left")
        if left.dtype.kind == "f":
            # the view shows floats as [0, 1]: a left of 0-255 floats was shown all white, in
            # the words the package refuses such an image with (as_bgr_uint8's)
            finite = left[np.isfinite(left)]
            if finite.size:
                err = _unit_range_error(float(finite.min()), float(finite.max()), "left")
                if err is not None:
                    raise ValueError(err)
        lh, lw = left.shape[:2]
        if np.ndim(disparity) != 2 or np.shape(disparity) != (lh, lw):
            raise ValueError(
                f"disparity: expected a map of the left image's {lw}x{lh} px, got shape "
                f"{np.shape(disparity)}"
            )
        with self._cond:
            self._latest = (left, disparity, top)
            self._seq += 1
            self._cond.notify_all()

    def _encode(self, item: tuple[np.ndarray, np.ndarray, float], seq: int) -> bytes:
        # Each viewer (a browser tab, a dashboard polling /frame.jpg) composed and encoded
        # every frame again, 8.5 ms a 640x480 pair on the two cores the matcher runs on: frame
        # number seq is encoded once, by the first to ask, the others waiting for it.
        with self._jpeg_lock:
            if self._jpeg is not None and self._jpeg[0] == seq:
                return self._jpeg[1]
            img = _compose(*item)
            ok, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
            if not ok:
                raise OSError("could not encode a JPEG frame")
            jpg = bytes(buf.tobytes())
            if self._jpeg is None or self._jpeg[0] < seq:  # not over a newer one
                self._jpeg = (seq, jpg)
            return jpg

    def latest_jpeg(self) -> bytes | None:
        """The latest frame as JPEG.

        Returns
        -------
        bytes or None
            The encoded frame, or None before the first :meth:`update`.
        """
        with self._cond:
            item, seq = self._latest, self._seq
        return None if item is None else self._encode(item, seq)

    def wait_jpeg(self, seen: int, timeout: float) -> tuple[bytes | None, int]:
        """Wait for a frame newer than ``seen``.

        Parameters
        ----------
        seen : int
            Number of the last frame the caller has (0 for none).
        timeout : float
            Longest wait, seconds.

        Returns
        -------
        jpeg : bytes or None
            The newer frame encoded, or None on timeout.
        number : int
            Its number (``seen`` on timeout), for the next call.
        """
        with self._cond:
            if self._seq == seen or self._latest is None:
                self._cond.wait(timeout)
            if self._seq == seen or self._latest is None:
                return None, seen
            item, seq = self._latest, self._seq
        return self._encode(item, seq), seq

    def close(self) -> None:
        """Stop serving (idempotent)."""
        if self._closed:
            return
        self._closed = True
        with self._cond:
            self._cond.notify_all()
        self._httpd.shutdown()
        self._httpd.server_close()


# ----------------------------------------------------------------------------------- pipeline


def _pairs(
    camera: StereoCamera,
    calib: Calibration | None,
    frames: int | None,
    check_every: int | None = None,
    homographies: Any = None,
    temporal: Any = None,
    read_timeout: float | None = DEFAULT_READ_TIMEOUT,
    stop: threading.Event | None = None,
) -> Iterator[_Pair | _Note]:
    """Grab (and rectify, for a raw rig calibration) pairs until the end or ``frames`` pairs;
    check the rows of pair 0 and, when positive, every ``check_every``-th pair (None: none);
    a read taking over ``read_timeout`` s raises (:func:`~stereovision.capture.read_within`).
    Once ``stop`` is set, a read that returns ends it, its pair dropped untouched."""
    n = 0
    # video files: their own time, from the first pair's wall clock (None until it is read)
    media = getattr(camera, "media_clock", False) is True
    media_origin_ns: int | None = None
    last_stamp_ns: int | None = None  # of the pair before, for a media time that stalls
    media_fallback: tuple[int, int] | None = None  # (stamp, frame index) it steps on from
    stall: str | None = None  # the warning of a media time that stalled, not said yet
    while frames is None or n < frames:
        t0 = time.perf_counter()
        grabbed = getattr(camera, "grabbed", None) if isinstance(camera, _FirstPairRead) else None
        try:
            fr = read_within(camera, read_timeout)
        except SourceError as exc:
            # no first frame, or a failure that is not an end (a frame that does not decode or
            # of another shape): an error; an end is the end of the stream, said plainly when
            # one source ended before the other or before the frames its file announced
            if camera.count == 0 or not getattr(exc, "end", True):
                raise
            if _device_ended(camera, exc):
                # a camera has no end: one that stops delivering (unplugged, a loose cable)
                # ended a robot's stream as "end of stream", exit 0, silently when both did
                raise SourceError(str(exc), side=exc.side, end=False, frames=exc.frames) from exc
            if getattr(exc, "ended_early", False):
                yield _Note(str(exc))
            return
        except ValueError as exc:
            # a recording's frame that does not decode (BagCamera names its topic and stamp):
            # after the first pair, a failure of the source that ends the stream with its
            # summary (run_stream), as a video frame that does not decode does
            if camera.count == 0:
                raise
            raise SourceError(str(exc), end=False, frames=camera.count) from exc
        if stop is not None and stop.is_set():
            # the stream ended during this read (the grab thread left behind on a hung camera):
            # averaging it into the caller's TemporalFilter, after run_stream returned, mixed a
            # stale frame into the caller's next stream
            return
        t1 = time.perf_counter()
        grab_s = t1 - t0
        if n == 0 and grabbed is not None:  # read ahead to size the calibration: its own grab
            t0, grab_s = grabbed[0], grabbed[1] - grabbed[0]
        recorded = getattr(camera, "stamps_ns", None)
        if recorded:  # a recording (BagCamera): the stamp of the pair just read
            stamp_ns = int(recorded[-1])
        else:  # the wall clock at the middle of the two grabs (host monotonic times)
            ago = time.monotonic() - 0.5 * (fr.t_left + fr.t_right)
            stamp_ns = time.time_ns() - round(1e9 * ago)
            at = None  # the pair's place in the video, as a stamp
            if media and media_fallback is None and math.isfinite(fr.pos_left_ms):
                # a video file's pair at its place in the video: the read's wall clock made
                # the stamps (a --bag's) follow the processing speed, not the video's 1/fps
                if media_origin_ns is None:
                    media_origin_ns = stamp_ns - round(1e6 * fr.pos_left_ms)
                at = media_origin_ns + round(1e6 * fr.pos_left_ms)
            if media and at is not None and (last_stamp_ns is None or at > last_stamp_ns):
                stamp_ns = at
            elif media:
                # a container or backend whose position stalls (0, a repeated value) or goes
                # back gave two pairs one stamp, or a stamp before the last: from here on the
                # frame period steps the stamps (the wall clock without one), said once
                if media_fallback is None:
                    media_fallback = (
                        (stamp_ns, fr.index)
                        if last_stamp_ns is None
                        else (last_stamp_ns, fr.index - 1)
                    )
                    stall = _media_stall_note(camera, fr)
                stamp_ns = _stepped_stamp(camera, fr, media_fallback, last_stamp_ns, stamp_ns)
            last_stamp_ns = stamp_ns
        left, right = fr.left, fr.right
        # The mean of the frames as the cameras give them, then rectified: the filter measures
        # the noise of each pixel (temporal.noise_sigma), which rectification's interpolation
        # blurs into its neighbours (a half-pixel shift read 1.1 instead of 5.7 grey levels),
        # and its motion test then took every pair of a still raw rig for a moving one.
        averaged = 1.0
        filtered = None
        note = None
        if temporal is not None:
            if n == 0:
                note = resampled_for_temporal_note(camera, fr)
            try:
                left, right = temporal_average(temporal, fr)
            except ValueError as exc:
                # a frame it cannot average after pairs were done (a 16-bit image in an 8-bit
                # sequence): raised as it was, it lost the summary of those pairs (a --bag's
                # line too); the source failing ends the stream, as a frame that does not decode
                if n == 0:
                    raise
                raise SourceError(str(exc), end=False, frames=camera.count) from exc
            averaged = temporal.mean_frames()
            filtered = (temporal.frames, temporal.restarts, _filter_noise(temporal))
        t2 = time.perf_counter()
        if calib is not None and not calib.rectified:
            left, right = calib.rectify(left, right)
        elif homographies is not None:
            left, right = homographies.rectify(left, right)
        t3 = time.perf_counter()
        checked = None
        # In the producer thread when pipelined: the matcher keeps working meanwhile.
        if check_every is not None and (n == 0 or (check_every > 0 and n % check_every == 0)):
            checked = check_rectification(left, right)
        if stall is not None:  # said before the pair, outside its timings
            yield _Note(stall)
            stall = None
        if note is not None:
            yield _Note(note)
        yield _Pair(
            left,
            right,
            fr.index,
            t0,
            grab_s,
            t3 - t2,
            fr.skew_ms,
            checked,
            n,
            temporal_s=t2 - t1,
            averaged=averaged,
            stamp_ns=stamp_ns,
            raw_left=_noise_frame(fr) if n == 0 else None,
            filtered=filtered,
        )
        n += 1


def _media_period_ns(camera: Any) -> int | None:
    """The left video's frame period in ns (its ``CAP_PROP_FPS``), None when unknown."""
    fps = float(getattr(camera, "delivered_fps", {}).get("left", 0.0) or 0.0)
    return round(1e9 / fps) if math.isfinite(fps) and fps > 0 else None


def _media_stall_note(camera: Any, fr: StereoFrame) -> str:
    """The warning, once, of a video whose media time (``CAP_PROP_POS_MSEC``) did not move on."""
    name = _describe_source(getattr(camera, "sources", {}).get("left", "?"))
    step = (
        "stamped by the frame index and the video's frame rate"
        if _media_period_ns(camera) is not None
        else "stamped by the wall clock of their read (the video reports no frame rate)"
    )
    pos = f"{fr.pos_left_ms:.0f} ms" if math.isfinite(fr.pos_left_ms) else "none"
    return (
        f"left source {name}: its media time did not move on at pair {fr.index + 1} "
        f"(position {pos}; the container or backend reports a stalled or repeated one): this "
        f"pair and the next are {step}"
    )


def _stepped_stamp(
    camera: Any, fr: StereoFrame, since: tuple[int, int], last_ns: int | None, wall_ns: int
) -> int:
    """The stamp of pair ``fr`` of a video whose media time stalled: ``since``'s stamp plus a
    frame period for each frame read after its index, or without a known rate the wall clock
    ``wall_ns``; after ``last_ns`` in either case (the stamps strictly increase)."""
    period = _media_period_ns(camera)
    stamp = wall_ns if period is None else since[0] + (fr.index - since[1]) * period
    return stamp if last_ns is None or stamp > last_ns else last_ns + 1


def _noise_frame(fr: StereoFrame) -> np.ndarray:
    """The left frame whose noise the hint measures: as delivered when the source enlarged it
    (the enlargement spreads the noise, which then reads 0.5 of 6.4 grey levels), the frame
    matched otherwise (a shrink averages the noise away: cones at 320x240, noise 8, halved
    read 4.2 grey levels, and the hint on the delivered frames' 6.0 warned that the depth maps
    of the halved ones suffered)."""
    d = fr.delivered
    if d is not None and d[0].shape[1] < fr.left.shape[1]:
        return d[0]
    return fr.left


class _Producer(threading.Thread):
    """Runs :func:`_pairs` ahead of the matcher; errors travel through the queue too.

    A pair is grabbed only when a slot is free (at most :data:`QUEUE_SIZE` pairs ahead of the
    one being matched), so a live camera's pair is fresh when the matcher takes it rather than
    aged in a queue.
    """

    def __init__(
        self, source: Iterator[_Pair | _Note], q: queue.Queue[Any], stop: threading.Event
    ) -> None:
        super().__init__(name="stereovision-grab", daemon=True)
        self._source = source
        self._q = q
        self.slots = threading.Semaphore(QUEUE_SIZE)
        #: set when the stream ends; the source checks it too, after each read
        self.stop = stop
        #: set when :meth:`run` returns (is_alive() after a join cut by Ctrl-C said False on
        #: Python 3.11, the thread still inside a read)
        self.finished = threading.Event()

    def _acquire(self) -> bool:
        while not self.stop.is_set():
            if self.slots.acquire(timeout=0.1):
                return True
        return False

    def run(self) -> None:
        try:
            self._run()
        finally:
            self.finished.set()

    def _run(self) -> None:
        # the source's own warnings (a StereoCamera's resized frames), raised in this thread,
        # pointed at threading.py: held here, each goes to the consumer before its pair
        held: list[tuple[str, type[Warning]]] = []
        HELD_WARNINGS.set(held)  # this thread's context only
        try:
            while self._acquire():
                pair = next(self._source, None)
                self._hand_over(held)
                if pair is None:
                    break
                self._q.put(pair)
        except BaseException as exc:  # handed to the consumer, which re-raises it
            self._hand_over(held)
            self._q.put(exc)
            return
        self._q.put(_END)

    def _hand_over(self, held: list[tuple[str, type[Warning]]]) -> None:
        for message, category in held:
            self._q.put(_Note(message, category, slot=False))
        held.clear()


def _camera_name(camera: Any) -> str:
    """A camera as its errors name it: its sources (``camera 0 and camera 1``), else its type."""
    sources = getattr(camera, "sources", None)
    if isinstance(sources, dict) and sources:
        return " and ".join(_describe_source(src) for src in sources.values())
    return type(camera).__name__


def _mean(values: list[float]) -> float:
    return float(statistics.fmean(values)) if values else math.nan


#: Latest per-second reports :attr:`StreamReport.reports` keeps (an hour of them at the default
#: period, 4.7 MB): every one kept, 1.3 kB each, grew by 114 MB a day, and with
#: ``report_period=0`` (one per pair) by 140 MB an hour at 30 fps. ``on_report`` gets each one.
REPORTS_KEPT = 3600
#: Latest pairs the summary's medians are taken over (an hour at 30 fps, 80 bytes a pair); its
#: count, means and maximum cover every pair. A stream can run for days.
MEDIAN_PAIRS = 108_000


class _Tally:
    """The summary's figures of every finished pair in bounded memory (a list of every pair's
    record grew by about 600 bytes a pair)."""

    _MEDIANS = (*STAGES, "latency_s", "wait_s")

    def __init__(self) -> None:
        self.n = 0
        self._cols = {k: array("d") for k in self._MEDIANS}
        self._sums = {"skew_ms": 0.0, "density": 0.0, "averaged": 0.0}
        self.skew_max = math.nan

    def add(self, d: _Done) -> None:
        self.n += 1
        values = {**d.stages, "latency_s": d.latency_s, "wait_s": d.wait_s}
        for k, col in self._cols.items():
            col.append(values[k])
            if len(col) >= 2 * MEDIAN_PAIRS:  # drop the oldest half at once: amortised O(1)
                del col[:MEDIAN_PAIRS]
        for k in self._sums:
            self._sums[k] += float(getattr(d, k))
        # as max() over the list did: the first value, then any larger one
        if self.n == 1 or d.skew_ms > self.skew_max:
            self.skew_max = d.skew_ms

    def median(self, key: str) -> float:
        col = self._cols[key]
        return float(statistics.median(col[-MEDIAN_PAIRS:])) if self.n else math.nan

    def mean(self, key: str) -> float:
        return self._sums[key] / self.n if self.n else math.nan


def _window_report(
    done: list[_Done], t_window: float, total: int, elapsed: float, md: int, pipelined: bool
) -> dict[str, Any]:
    return {
        "t": round(elapsed, 3),
        "frames": len(done),
        "total_frames": total,
        "fps": round(len(done) / t_window, 3) if t_window > 0 else 0.0,
        "stage_ms": {k: round(1e3 * _mean([d.stages[k] for d in done]), 3) for k in STAGES},
        "latency_ms": round(1e3 * _mean([d.latency_s for d in done]), 3),
        "wait_ms": round(1e3 * _mean([d.wait_s for d in done]), 3),
        "skew_ms": {
            "mean": round(_mean([d.skew_ms for d in done]), 4),
            "max": round(max((d.skew_ms for d in done), default=math.nan), 4),
        },
        "density": round(_mean([d.density for d in done]), 4),
        "frames_averaged": round(_mean([d.averaged for d in done]), 3),
        "max_disparity": md,
        "pipelined": pipelined,
    }


def run_stream(
    camera: StereoCamera,
    calib: Calibration | None = None,
    *,
    method: str = "gabor",
    max_disparity: int | None = None,
    frames: int | None = None,
    pipelined: bool = True,
    refine: bool = False,
    fill: bool | None = None,
    on_report: Callable[[dict[str, Any]], None] | None = None,
    on_result: Callable[[np.ndarray, Any], None] | None = None,
    on_stamped_result: Callable[[np.ndarray, Any, int], None] | None = None,
    report_period: float = REPORT_PERIOD,
    check: bool = True,
    check_every: int | None = None,
    ground_every: int | None = None,
    on_ground: Callable[[Any], None] | None = None,
    homographies: Any = None,
    temporal: Any = None,
    read_timeout: float | None = DEFAULT_READ_TIMEOUT,
) -> StreamReport:
    """Depth maps from a stereo camera until it ends, ``frames`` pairs, or Ctrl-C.

    Parameters
    ----------
    camera : StereoCamera
        The two sources (devices, video files or image sequences).
    calib : Calibration, optional
        Rig calibration. A raw rig calibration is applied by the producer (rectification); a
        rectified one (Middlebury, KITTI) is used as is. Without one, only disparity is
        computed. One made at another resolution of the same aspect ratio is scaled to the
        frames (:meth:`~stereovision.calibration.Calibration.scaled_to`), with a warning. The
        frames are the first pair delivered (read before the pipeline starts), not the mode a
        camera reports: when they differ, a warning says so too.
    method : str
        Matcher (:data:`stereovision.depth.METHODS`). ``"gabor"`` by default: a live view wants
        the rate, and it is 3-4 times faster than ``depth_map``'s default ``"fused"``.
        ``"fast"`` with ``fill=False`` measures more pixels with less than half as many of them
        wrong (over the 17 GT scenes 82 % measured, 3.4 % off by more than 2 px, against 74 %
        and 7.7 %) at about three quarters of the Gabor channel's frame rate.
    max_disparity : int, optional
        Disparity range. None estimates it once, from the first pair (with a warning when that
        pair is one flat level, a capped lens or a camera still starting: the range is a guess).
    frames : int, optional
        Stop after this many pairs.
    pipelined : bool
        Grab and rectify in a producer thread while the main thread matches (default).
    refine : bool
        Sub-pixel refinement of every frame (:func:`stereovision.refine.refine_disparity`).
        Off by default: it takes 2-3 times the matching time, and a live view wants the rate;
        turn it on for measurements.
    fill : bool, optional
        Fill the holes (:func:`stereovision.depth.depth_map`'s ``fill``). None (default): the
        method's choice (``"fused"``, ``"census"`` and ``"fast"`` fill; the plane fill is about a
        third of the census mode's frame at 640x480).
    on_report : callable, optional
        Called with each per-second report (a JSON-ready dict, see the module doc).
    on_result : callable, optional
        Called with ``(left_rectified_bgr, DepthResult)`` of every pair. The result is computed
        with ``cloud=False``: its ``points`` are empty, its ``to_ply`` writes the full cloud.
    on_stamped_result : callable, optional
        Called like ``on_result`` with a third argument: the pair's time in nanoseconds since
        the epoch, taken at its grab (the middle of the two cameras' grabs; a recording's own
        stamp; for two video files, :attr:`~stereovision.capture.StereoCamera.media_clock`,
        the first pair's grab time plus the left video's ``CAP_PROP_POS_MSEC``, so that the
        stamps step by its frame period), not when its depth was done (a live frame's latency
        later): the time to stamp messages for TF and odometry with.
    report_period : float
        Seconds between reports (0: one per pair; inf: the last, partial one alone).
    check : bool
        Check that the first (rectified) pair's features lie on common rows
        (:func:`~stereovision.rectification_check.check_rectification`, 0.1-0.85 s) and warn
        when they do not: a spoiled calibration, or raw cameras without one.
    check_every : int, optional
        Also check every ``check_every``-th pair (in the grab thread when pipelined), and warn
        when the rows stop agreeing: a rig bumped while running. None: the first pair only.
        Not with ``check=False``.
    ground_every : int, optional
        Fit the floor (:func:`~stereovision.ground.fit_ground_plane`, 30-150 ms) on pair 0 and
        every ``ground_every``-th pair, and warn once when the camera's height moves by more
        than :data:`GROUND_HEIGHT_SHARE` of the first fit's or its pitch or roll by more than
        :data:`GROUND_TILT_DEG`: a mount that slipped. Needs ``calib``.
    homographies : UncalibratedRectification, optional
        For a rig without a calibration: every pair is rectified through these homographies
        (:func:`~stereovision.uncalibrated.rectify_uncalibrated`), disparity only; its search
        range is the default ``max_disparity``.
    on_ground : callable, optional
        With ``ground_every``: called with each fit's
        :class:`~stereovision.ground.GroundPlane` (None when no floor was found), before the
        pair's ``on_result``.
    temporal : TemporalFilter, optional
        Average a still rig's frames (:class:`~stereovision.temporal.TemporalFilter`; in the
        grab thread when pipelined) before matching: less noise in low light, the same pairs
        when the rig or the scene moves. It averages the frames as grabbed, before
        rectification (whose interpolation blurs the noise it measures). ``on_result`` gets
        the averaged left image. Pipelined, a stream ended by Ctrl-C or a failing output
        leaves the filter holding up to :data:`QUEUE_SIZE` pairs grabbed ahead and never
        matched (the report counts only the pairs matched): call its ``reset()`` before
        reusing it if the next stream's first pairs must hold none of them.
    read_timeout : float or None
        Seconds a pair's read may take (:data:`~stereovision.capture.DEFAULT_READ_TIMEOUT`,
        10); a camera whose read does not return by then (a hung USB camera) ends the stream
        with a :class:`~stereovision.capture.SourceError` naming it, as a failing source does.
        None waits as long as the read takes. Ctrl-C stops the wait at once either way.

    Returns
    -------
    StreamReport

    Raises
    ------
    SourceError
        If a source delivers no first frame, or fails on the first pair. A failure after it
        (a frame that does not decode, of another shape or, with ``temporal``, of more than 8
        bits; a camera device or a live stream
        such as ``rtsp://``, unlike a file, that stops delivering) ends the stream instead:
        the pairs done are reported, with ``ended`` ``"source failed"`` and the error in
        ``error``; an OSError of ``on_result`` or ``on_stamped_result`` (an output that cannot
        be written) ends it likewise, ``ended`` ``"output failed"``.
    ValueError
        If ``frames`` or ``max_disparity`` is not positive, ``method`` is unknown (before any
        grab), or the calibration does not fit the frames.
    TypeError
        Before any grab: if ``max_disparity`` is not a number (``"64"``, True), ``fill``,
        ``refine``, ``check`` or ``pipelined`` not a bool, a callback not callable, or
        ``calib``, ``homographies`` or ``temporal`` not what they name (a calibration file's
        path, ``temporal=8``).
    """
    from stereovision.depth import (
        METHODS,
        _refuse_range_types,
        depth_map,
        estimate_max_disparity,
    )

    # NaN matched no pair ("end of stream"), 2.5 three and True one
    if frames is not None:
        frames = positive_whole(frames, "frames", "a positive number of pairs")
    check_read_timeout(read_timeout)
    # "1" raised TypeError in the loop after a pair was taken; NaN gave no report but the last;
    # np.timedelta64 (an np.integer) the loop's UFuncTypeError after a pair was taken
    if not real_number(report_period) or not report_period >= 0:  # 3 ns was 3 s
        # -10**5000 by its size: it has no repr (Python's 4300-digit limit, naming nothing)
        shown = too_large_for_float(report_period, why=False) or repr(report_period)
        raise ValueError(f"report_period: expected a number of seconds >= 0, got {shown}")
    if max_disparity is not None:
        # refused before any grab, as batch refuses it: "64" failed in its comparison with 0
        # ("'<=' not supported between instances of 'str' and 'int"), and NaN, inf, True or a
        # timedelta passed it, refused by depth_map once a pair was taken off the camera
        _refuse_range_types(max_disparity, 0)
        if too_large_for_float(max_disparity):  # 10**400: said by its size, not its digits
            finite_number(max_disparity, "max_disparity")
        if not (math.isfinite(max_disparity) and max_disparity > 0):
            given = number_shown(max_disparity)
            raise ValueError(f"max_disparity: expected a positive number, got {given}")
    if homographies is not None and calib is not None:
        raise ValueError("homographies and calib: give one way to rectify the pairs")
    # usage errors before the first grab (the read ahead below takes a pair off the camera)
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}: expected one of {', '.join(METHODS)}")
    for name, flag in (("check", check), ("pipelined", pipelined)):
        # "no" (a config file's text) was true: the pairs checked, or a pipelined run whose
        # summary said "pipelined": "no"
        if not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"{name}: expected True or False, got {_shown(flag)}")
    check, pipelined = bool(check), bool(pipelined)
    if check_every is not None:  # 2.5 checked pairs 0, 5, 10
        check_every = positive_whole(check_every, "check_every", "a positive number of pairs")
        if not check:  # it checked no pair at all, without a word
            raise ValueError(
                "check_every: it checks the rows of pairs, which check=False turns off; give "
                "one or the other"
            )
    if ground_every is not None:
        ground_every = positive_whole(ground_every, "ground_every", "a positive number of pairs")
        if calib is None:
            raise ValueError("ground_every: the floor is found in metres; give a calibration")
    _refuse_wrong_objects(
        calib,
        homographies,
        temporal,
        {"fill": fill, "refine": refine},
        {
            "on_report": on_report,
            "on_result": on_result,
            "on_stamped_result": on_stamped_result,
            "on_ground": on_ground,
        },
    )
    if homographies is not None and max_disparity is None:
        # 0 was taken as "none given", where it is refused without them
        max_disparity = homographies.max_disparity
    stopped: str | None = None  # Ctrl-C or SIGTERM while the first pair was read ahead
    if calib is not None and getattr(camera, "count", None) == 0:
        # fitted to the first pair delivered, not to the mode the driver reports (a driver
        # that reports 640x480 and delivers 320x240 failed every pair), as batch and gui fit
        # a calibration to the images they read
        try:
            camera = _FirstPairRead(camera, read_timeout)  # type: ignore[assignment]
        except KeyboardInterrupt as exc:
            # as during the stream's own first grab: the summary of no pair, not an error
            stopped = "terminated" if isinstance(exc, Terminated) else "interrupted"
    # the run's time starts at the first grab, also when that pair was read ahead
    grabbed = camera.grabbed if isinstance(camera, _FirstPairRead) else None
    size = None if stopped else _frame_size(camera)
    if calib is not None and size is not None:
        calib, note = fit_to_frames(calib, size)
        if note is not None:
            warnings.warn(note, stacklevel=2)
        said = _mode_note(camera, size) if isinstance(camera, _FirstPairRead) else None
        if said is not None:
            warnings.warn(said, stacklevel=2)
    rect_calib = None
    if calib is not None:
        rect_calib = calib if calib.rectified else calib.rectified_calibration()
    kw: dict[str, Any] = {"refine": refine, "method": method, "fill": fill}
    # the temporal filter as it came, before the grab thread can take a pair: a filter reused
    # from a stream before (as reset()'s note allows) said that stream's restarts as this one's
    # (4 restarts on a still view that restarted once, 3 of them the run before)
    filtered = (
        None if temporal is None else (temporal.frames, temporal.restarts, _filter_noise(temporal))
    )
    restarts_before = 0 if filtered is None else filtered[1]
    stop = threading.Event()  # the end of the stream, for a grab thread left behind
    source: Iterator[_Pair | _Note] = (
        iter(())
        if stopped
        else _pairs(
            camera,
            calib,
            frames,
            (check_every or 0) if check else None,
            homographies,
            temporal,
            read_timeout,
            stop,
        )
    )
    producer: _Producer | None = None
    q: queue.Queue[Any] = queue.Queue()
    if pipelined:
        producer = _Producer(source, q, stop)
        producer.start()

    def next_item() -> _Pair | _Note | None:
        if producer is None:
            return next(source, None)
        item = q.get()
        if not isinstance(item, _Note) or item.slot:
            producer.slots.release()
        if item is _END:
            return None
        if isinstance(item, BaseException):
            raise item
        return item  # type: ignore[no-any-return]

    def next_pair() -> _Pair | None:
        item = next_item()
        while isinstance(item, _Note):
            warnings.warn(item.message, item.category, stacklevel=user_stacklevel())
            item = next_item()
        return item

    tally = _Tally()
    noise = math.nan  # the first left frame's noise
    # the temporal filter as of the last pair counted (before the first: as it came, above)
    checks: list[dict[str, Any]] = []
    grounds: list[dict[str, Any]] = []
    first_plane: list[Any] = []  # the first floor found, for the mount check
    no_floor: str | None = None  # why the last fit without a floor found none
    window: list[_Done] = []
    reports: deque[dict[str, Any]] = deque(maxlen=REPORTS_KEPT)
    md = max_disparity
    ended = stopped or "end of stream"
    error: str | None = None
    t_begin = grabbed[0] if grabbed is not None else time.perf_counter()
    t_window = t_begin
    t_last = t_begin
    try:
        while True:
            t_wait = time.perf_counter()
            try:
                pair = next_pair()
            except SourceError as exc:
                # a source that fails after pairs were done (a frame that does not decode or of
                # another shape): those pairs' figures (and a --bag of them) are the run's; it
                # raised past them, and the CLI printed the error without the summary
                if tally.n == 0:
                    raise
                ended, error = "source failed", str(exc)
                break
            if pair is None:
                break
            t_got = time.perf_counter()
            if pair.check is not None:
                _note_check(pair.pair, pair.check, checks)
            if md is None:
                md = estimate_max_disparity(pair.left, pair.right)
                _note_flat_range(pair.raw_left if pair.raw_left is not None else pair.left, md)
            if tally.n == 0:
                raw = pair.raw_left if pair.raw_left is not None else pair.left
                noise = _note_noise(raw, temporal is not None)
            # No point cloud per frame: the live view shows disparity and depth.
            res = depth_map(pair.left, pair.right, rect_calib, max_disparity=md, cloud=False, **kw)
            if ground_every is not None and tally.n % ground_every == 0:
                assert rect_calib is not None
                plane, why = _note_ground(tally.n, res.disparity, rect_calib, grounds, first_plane)
                if plane is None:
                    no_floor = why
                if on_ground is not None:
                    on_ground(plane)
            t_last = time.perf_counter()
            tm = res.timings
            stages = {
                "grab": pair.grab_s,
                "rectify": pair.rectify_s,
                "temporal": pair.temporal_s,
                # depth_map's own "rectify" is only input conversion for a rectified pair
                "prepare": tm.get("rectify", 0.0) + tm.get("prepare", 0.0),
                "match": tm.get("match", 0.0) + tm.get("refine", 0.0),
                "fill": tm.get("fill", 0.0),  # 0 for a method that leaves its holes
                "triangulate": tm.get("triangulate", 0.0),
            }
            d = _Done(
                stages=stages,
                latency_s=t_last - pair.t_start,
                wait_s=t_got - t_wait,
                skew_ms=pair.skew_ms,
                density=res.density,
                averaged=pair.averaged,
            )
            try:
                if on_result is not None:
                    on_result(pair.left, res)
                if on_stamped_result is not None:
                    on_stamped_result(pair.left, res, pair.stamp_ns)
            except OSError as exc:
                # an output that cannot be written (--bag on a full disk): the pairs written
                # before are the run's, reported as a failing source's are; it raised past
                # them, and the CLI printed the error without the summary
                ended, error = "output failed", str(exc)
                break
            tally.add(d)
            if pair.filtered is not None:
                filtered = pair.filtered
            window.append(d)
            if t_last - t_window >= report_period:
                rep = _window_report(
                    window, t_last - t_window, tally.n, t_last - t_begin, md, pipelined
                )
                reports.append(rep)
                if on_report is not None:
                    on_report(rep)
                window = []
                t_window = t_last
        if frames is not None and tally.n >= frames:
            ended = "frames"
    except KeyboardInterrupt as exc:
        ended = "terminated" if isinstance(exc, Terminated) else "interrupted"
    finally:
        if producer is not None:
            producer.stop.set()
            again = False
            try:
                producer.join(timeout=GRAB_JOIN_TIMEOUT)
            except KeyboardInterrupt as exc:
                # Ctrl-C (SIGTERM) again while the grab thread finished its read (a slow or hung
                # camera: up to GRAB_JOIN_TIMEOUT s): it raised out of here, and the summary of
                # the pairs done was lost. The wait stops; the run ends as interrupted.
                again = True
                if error is None:
                    ended = "terminated" if isinstance(exc, Terminated) else "interrupted"
            if again and not producer.finished.is_set():
                warnings.warn(
                    f"the grab thread is still inside a read of {_camera_name(camera)}, "
                    "interrupted while waiting for it: it is left behind; the pair it reads, "
                    "if any, is dropped",
                    UserWarning,
                    stacklevel=2,
                )
            elif producer.is_alive():
                # it returned silently: the stream seemed stopped while a thread was still
                # inside the camera (which a close then leaves to that read to release)
                warnings.warn(
                    f"the grab thread is still inside a read of {_camera_name(camera)}, "
                    f"{GRAB_JOIN_TIMEOUT:g} s after the stream ended (a hung camera): it is left "
                    "behind; the pair it reads, if any, is dropped",
                    UserWarning,
                    stacklevel=2,
                )
    if window:  # the last, partial second
        rep = _window_report(
            window, t_last - t_window, tally.n, t_last - t_begin, md or 0, pipelined
        )
        reports.append(rep)
        if on_report is not None:
            on_report(rep)
    n = tally.n
    seconds = t_last - t_begin
    return StreamReport(
        frames=n,
        seconds=seconds,
        fps=n / seconds if seconds > 0 else 0.0,
        stage_ms={k: 1e3 * tally.median(k) if n else math.nan for k in STAGES},
        latency_ms=1e3 * tally.median("latency_s") if n else math.nan,
        wait_ms=1e3 * tally.median("wait_s") if n else math.nan,
        skew_ms={"mean": tally.mean("skew_ms"), "max": tally.skew_max},
        # as searched: int() said a range of 8.5 px as 8, and 0.5 (accepted) as 0, where the
        # per-second reports gave 8.5 (an int when whole, as batch's summary says it)
        max_disparity=0 if not md else int(md) if float(md).is_integer() else float(md),
        pipelined=pipelined,
        ended=ended,
        density=tally.mean("density"),
        reports=list(reports),
        rectification=checks[0] if checks else None,
        checks=checks,
        grounds=grounds,
        ground_reason=no_floor,
        noise_sigma=noise,
        error=error,
        temporal=None
        if filtered is None
        else {
            "frames_averaged": round(tally.mean("averaged"), 3),
            "restarts": filtered[1] - restarts_before,
            # its starting 0.0 before any frame: a noise never measured (NaN, JSON null)
            "noise_sigma": round(filtered[2], 3) if filtered[0] else math.nan,
        },
    )


def _filter_noise(temporal: Any) -> float:
    """The temporal filter's noise estimate (grey levels), NaN while it has none: its ``sigma``
    is 0 until a frame with a pixel neither black nor white, which all-black frames (a capped
    lens, a dark room) never give, and the summary said "noise 0.0 grey levels"."""
    return float(temporal.sigma) if temporal._sigmas else math.nan


def _refuse_wrong_objects(
    calib: Any,
    homographies: Any,
    temporal: Any,
    flags: dict[str, Any],
    callbacks: dict[str, Any],
) -> None:
    """A TypeError naming the argument of :func:`run_stream` given the wrong object, before any
    grab: a calib.txt's path failed with "'str' object has no attribute 'rectified'" once a
    pair was taken off the camera, ``temporal=8`` (capture's ``temporal`` is a count of frames)
    with "'int' object has no attribute 'frames'", ``on_result=print_it()`` with "'NoneType'
    object is not callable" after the first pair was matched."""
    from stereovision.temporal import TemporalFilter

    if calib is not None:
        require(calib, "Calibration", "calib")
    if homographies is not None and not callable(getattr(homographies, "rectify", None)):
        path = path_given(homographies)
        raise TypeError(
            f"homographies: got the path {path!r}, not the homographies: read them first "
            "(stereovision.uncalibrated.UncalibratedRectification.load(path))"
            if path is not None
            else "homographies: expected a stereovision.uncalibrated.UncalibratedRectification,"
            f" got {type(homographies).__name__}"
        )
    if temporal is not None and not isinstance(temporal, TemporalFilter):
        count = whole_value(temporal)
        hint = (
            f" (a filter averaging up to {count} frames: TemporalFilter(max_frames={count}))"
            if count is not None
            else ""
        )
        raise TypeError(
            f"temporal: expected a stereovision.TemporalFilter, got {type(temporal).__name__}"
            + hint
        )
    for name, flag in flags.items():  # "no" was true (depth_map refused it after a grab)
        if flag is not None and not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"{name}: expected True, False or None, got {_shown(flag)}")
    for name, fn in callbacks.items():
        if fn is not None and not callable(fn):
            raise TypeError(f"{name}: expected a callable, or None, got {_shown(fn)}")


def _note_noise(left: np.ndarray, averaging: bool) -> float:
    """The first left frame's noise (NaN for a frame all black or white, which noise_sigma
    calls 0); a warning suggesting ``--temporal`` when it is high."""
    from stereovision.temporal import _measured_noise

    measured = _measured_noise(left)
    sigma = math.nan if measured is None else measured
    if sigma > NOISY_SIGMA and not averaging:
        warnings.warn(
            f"the cameras are noisy ({sigma:.1f} grey levels on the first frame; low light?): "
            "the depth maps suffer; if the rig holds still, --temporal 8 (TemporalFilter) "
            "averages its frames",
            UserWarning,
            stacklevel=3,
        )
    return sigma


def _note_flat_range(left: np.ndarray, md: float) -> None:
    """Warn when the first left frame as grabbed, the pair the range is estimated from, is one
    flat level: a capped lens, a dark room or a webcam's first black frames (exposure still
    settling) gave the estimate's fallback (width / 8) without a word, searched the whole run."""
    if (left == left[0, 0]).all():
        warnings.warn(
            "the first pair, which the disparity range is estimated from, is one flat level (a "
            f"capped lens, a dark room, a camera still starting): the stream searches {md:g} px, "
            "a guess, throughout; give the range (--max-disparity N)",
            UserWarning,
            stacklevel=3,
        )


def _note_check(pair: int, result: RectificationCheck, checks: list[dict[str, Any]]) -> None:
    """Record a pair's check; warn when the rows stop agreeing (once per change)."""
    # against the last check that could tell: one that could not (too few matches: a dark or
    # bare view, ok None) between two failing ones warned of the same bump again
    was_ok = next((c["ok"] for c in reversed(checks) if c["ok"] is not None), True)
    checks.append({"pair": pair, **result.as_dict()})
    if result.ok is False and was_ok is not False:
        where = "first pair" if pair == 0 else f"pair {pair}"
        warnings.warn(f"{where}: {result.summary()}", stacklevel=3)


def _note_ground(
    pair: int,
    disparity: np.ndarray,
    calib: Calibration,
    grounds: list[dict[str, Any]],
    first_plane: list[Any],
) -> tuple[Any, str]:
    """Fit the floor of a pair; warn (once) when the mount has moved from the first fit: the
    fits differ and the first fit's plane no longer holds. ``first_plane`` keeps that plane
    (empty until one is found). Returns the plane (None when none was found) and, without
    one, the reason :func:`~stereovision.ground.fit_ground_plane` found none ("" with one)."""
    from stereovision.ground import _fit_ground

    plane, why = _fit_ground(disparity, calib)
    if plane is None:
        # the record keeps its documented keys: the reason goes to the summary line
        grounds.append({"pair": pair, "found": False})
        return None, why
    entry = {"pair": pair, "found": True, **plane.as_dict(), "moved": False}
    first = next((g for g in grounds if g["found"]), None)
    if first is not None and first_plane:
        dh = entry["height_m"] / first["height_m"] - 1
        dp = entry["pitch_deg"] - first["pitch_deg"]
        dr = entry["roll_deg"] - first["roll_deg"]
        kept = first_plane[0].support(disparity, calib) / max(first["inlier_share"], 1e-9)
        entry["first_plane_kept"] = kept
        differ = abs(dh) > GROUND_HEIGHT_SHARE or max(abs(dp), abs(dr)) > GROUND_TILT_DEG
        moved = differ and kept < GROUND_SUPPORT_KEPT
        entry["moved"] = moved
        if moved and not any(g.get("moved") for g in grounds):
            warnings.warn(
                f"pair {pair}: the camera moved on its mount: {100 * dh:+.1f} % height, pitch "
                f"{dp:+.2f} deg, roll {dr:+.2f} deg since pair {first['pair']} (its floor "
                f"holds {100 * kept:.0f} % of its pixels there)",
                stacklevel=3,
            )
    elif first is None:
        first_plane.append(plane)
    grounds.append(entry)
    return plane, ""


# ---------------------------------------------------------------------------------------- CLI


def _format_report(rep: dict[str, Any]) -> str:
    st = rep["stage_ms"]
    stages = " ".join(f"{k} {st[k]:.1f}" for k in STAGES)
    return (
        f"{rep['fps']:5.1f} fps | {stages} ms | latency {rep['latency_ms']:.0f} ms,"
        f" waited {rep['wait_ms']:.1f} ms | skew {rep['skew_ms']['mean']:.2f} ms"
        f" | density {100 * rep['density']:.0f} %"
        + (f" | {rep['frames_averaged']:.1f} frames averaged" if rep["frames_averaged"] > 1 else "")
    )


def _frame_size(camera: Any) -> tuple[int, int] | None:
    """The size of ``camera``'s frames as known now: its output size (requested, or fixed by
    a pair read), else the size its left source reports (a video's or image sequence's first
    frame, a camera's mode); None when it states none (a bag before its first pair)."""
    size: tuple[int, int] | None = camera.size or camera.delivered_size.get("left")
    return size


class _FirstPairRead:
    """``camera`` with its first pair read already, to size a calibration by the frames it
    delivers (a driver may report one mode and deliver another): :meth:`read` returns that
    pair first, then the camera's next ones; every other attribute is the camera's.

    Attributes
    ----------
    reported : tuple of int or None
        The size the left source reported before its first frame (a camera's mode; None
        when it reported none).
    grabbed : tuple of float or None
        ``perf_counter`` at the start and the end of the first pair's grab, until that pair
        is handed out (the grab stage and the latency of pair 0, the start of the run's
        ``seconds``).

    Raises
    ------
    SourceError, ValueError
        As the camera's ``read`` of the first pair (no first frame, one that does not decode),
        or :func:`~stereovision.capture.read_within` (no pair within ``read_timeout`` s).
    """

    def __init__(self, camera: Any, read_timeout: float | None = DEFAULT_READ_TIMEOUT) -> None:
        self._camera = camera
        self.reported: tuple[int, int] | None = getattr(camera, "delivered_size", {}).get("left")
        t0 = time.perf_counter()
        self._first: StereoFrame | None = read_within(camera, read_timeout)
        self.grabbed: tuple[float, float] | None = (t0, time.perf_counter())

    def read(self) -> StereoFrame:
        """The first pair (read at construction), then the camera's next ones."""
        first, self._first = self._first, None
        if first is not None:
            return first
        self.grabbed = None
        return self._camera.read()  # type: ignore[no-any-return]

    def __getattr__(self, name: str) -> Any:
        return getattr(self._camera, name)


class _StoppedCamera:
    """``camera`` whose first pair Ctrl-C (SIGTERM) stopped while it was read ahead: :meth:`read`
    raises that interrupt again, without touching the camera, so that :func:`run_stream` ends
    with the summary of no pair; every other attribute is the camera's."""

    def __init__(self, camera: Any, interrupt: KeyboardInterrupt) -> None:
        self._camera = camera
        self._interrupt = interrupt

    def read(self) -> StereoFrame:
        """Raise the interrupt that stopped the first pair."""
        raise self._interrupt

    def __getattr__(self, name: str) -> Any:
        return getattr(self._camera, name)


def _mode_note(camera: _FirstPairRead, size: tuple[int, int]) -> str | None:
    """One line when the left source delivered frames of another size than the mode it
    reported (the calibration is fitted to the frames, ``size``); None when they agree."""
    got = getattr(camera, "delivered_size", {}).get("left")
    if camera.reported is None or got is None or tuple(got) == tuple(camera.reported):
        return None
    (rw, rh), (w, h) = camera.reported, got
    resized = "" if tuple(got) == tuple(size) else f", resized to {size[0]}x{size[1]}"
    return (
        f"the left camera reports {rw}x{rh} but delivers {w}x{h}{resized}: the calibration is "
        "fitted to the frames delivered"
    )


def _sized_calibration(path: str, unit: str | None, camera: Any) -> Calibration:
    """The calibration at ``path``, which holds no image size, read at the size of the frames
    of ``camera`` (opened; :func:`_frame_size`): ``--size``, else the first pair's when it was
    read (:class:`_FirstPairRead`, as :func:`cmd_stream` does), else what its left source
    reports; the size :func:`run_stream` fits a calibration to.

    Raises
    ------
    ValueError
        As :func:`stereovision.cli.load_calibration`; one asking for ``--size`` when the
        source states no size before its first frame (a bag).
    """
    from stereovision.cli import load_calibration

    size = _frame_size(camera)
    return load_calibration(  # type: ignore[no-any-return]
        path,
        unit,
        size=size,
        size_words="the image size: --size WxH (this source states none before its frames)",
    )


def cmd_stream(args: argparse.Namespace) -> int:
    """``stereovision stream --left SRC --right SRC``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`add_cli`'s options).

    Returns
    -------
    int
        The exit status: 0; 130 or 143 when SIGINT or SIGTERM cut the stream short (the
        summary is still written); 2 (the CLI's error status) when a pair failed, after the
        summary. A ``--bag`` that cannot be finished (a full disk) is said as its writes
        failing are: the summary (its ``error``; ``ended`` ``"output failed"`` unless a signal
        stopped it), then the error line, 2; after an earlier failure or a signal, both are
        said and the first's status kept.
    """
    from stereovision.calibration import _sizeless
    from stereovision.cli import load_calibration

    given = [o for o, v in (("--serve", args.serve), ("--host", args.host)) if v is not None]
    if args.no_display and given:
        # refused before any open, not ignored: the view the user asked an address for
        raise ValueError(
            f"{' and '.join(given)}: {'they place' if len(given) > 1 else 'it places'} the live "
            "view, which --no-display turns off; give one or the other"
        )
    if args.no_check and args.check_every is not None:
        # refused before any open, not ignored: no pair was checked, the summary's checks []
        raise ValueError(
            "--check-every: it checks the rows of pairs, which --no-check turns off; give one "
            "or the other"
        )
    if args.no_tf and not args.bag:  # refused before any open, not ignored
        raise ValueError("--no-tf leaves /tf out of a --bag: give --bag DIR")
    if args.no_tf and args.ground_every is None:
        # nothing to leave out: only a frame written with its floor carries /tf
        raise ValueError(
            "--no-tf: a bag has /tf only with --ground-every (the floor places the camera)"
        )
    # one that holds no image size (OpenCV stereo_calib output, a Q.dat alone) is read at the
    # size of the frames, once the sources are open
    sizeless = bool(args.calib) and not args.rectification and _sizeless(args.calib)
    calib = None if sizeless else load_calibration(args.calib or None, args.calib_unit)
    out = sys.stdout
    log = sys.stderr
    server: FrameServer | None = None
    homographies = None
    if args.rectification:
        from stereovision.uncalibrated import UncalibratedRectification

        if args.calib:
            raise ValueError("--rectification and --calib: give one way to rectify the pairs")
        homographies = UncalibratedRectification.load(args.rectification)
    temporal = None
    if args.temporal is not None:
        from stereovision.temporal import TemporalFilter

        if not 2 <= args.temporal <= 255:
            raise ValueError(f"--temporal: expected 2-255 pairs to average, got {args.temporal}")
        temporal = TemporalFilter(max_frames=args.temporal)
    read_timeout = cli_read_timeout(args)
    cam = open_source(args, fps=args.fps)
    stopped = False  # Ctrl-C or SIGTERM while the first pair was read to size the calibration
    if sizeless:
        try:
            if getattr(cam, "requested_size", None) is None:
                # sized by the first pair delivered, not by the mode the driver reports (one
                # that reports 640x480 and delivers 320x240 failed every pair); --size wins
                try:
                    cam = _FirstPairRead(cam, read_timeout)
                except KeyboardInterrupt as exc:
                    # the summary of no pair, as an interrupt anywhere else in the stream
                    # gives (it said 'interrupted' alone): run_stream meets it again at once
                    cam = _StoppedCamera(cam, exc)
                    stopped = True
            if not stopped:
                calib = _sized_calibration(args.calib, args.calib_unit, cam)
        except BaseException:
            cam.close()
            raise
    if hasattr(cam, "stamps_ns"):  # a recording: its results keep the frames' stamps
        if calib is None and homographies is None and not stopped:
            try:
                calib = cam.calibration()
            except BaseException:
                cam.close()
                raise
            if calib is not None:
                print(f"calibration: the bag's {' and '.join(cam.info_topics.values())}", file=log)
            elif None not in cam.info_topics.values():  # camera_info of uncalibrated cameras
                print(
                    f"calibration: none; the bag's {' and '.join(cam.info_topics.values())} say "
                    "a camera is uncalibrated (K = 0): disparity only (--calib RIG for depth)",
                    file=log,
                )
            elif any(cam.info_topics.values()):
                # one camera's camera_info recorded, not the other's: disparity only, unsaid
                side = "left" if cam.info_topics["left"] is None else "right"
                other = cam.info_topics["right" if side == "left" else "left"]
                print(
                    f"calibration: none; the bag holds {other} but no camera_info beside "
                    f"{cam.topics[side]}: disparity only (--calib RIG for depth)",
                    file=log,
                )
            elif not args.bag and args.ground_every is None:
                # no camera_info at all: disparity only, without a word (as info says it);
                # --bag and --ground-every are refused below for it, in their own words
                print(
                    "calibration: none; the bag holds no camera_info beside "
                    f"{cam.topics['left']} and {cam.topics['right']}: disparity only "
                    "(--calib RIG for depth)",
                    file=log,
                )
    bag = None
    report: StreamReport | None = None  # None after the try: an error or interrupt is raised
    close_error: str | None = None  # the bag could not be finished (a full disk)
    piped = False  # stdout's reader went away
    try:
        if args.bag and calib is None and not stopped:
            raise ValueError("--bag: a bag holds depth; give --calib")
        if args.ground_every is not None and calib is None and not stopped:
            # refused here, as --bag is, in the CLI's words: run_stream's refusal names its
            # keyword (ground_every) and "a calibration"
            raise ValueError("--ground-every: the floor is found in metres; give --calib")
        if args.bag and not stopped:
            from stereovision.rosbag import BagWriter

            try:
                bag = BagWriter(args.bag, tf=not args.no_tf)
            except OSError as exc:
                # BagWriter (a library class) names the folder, not the option that gave it,
                # as every other refusal of --bag does; type and errno kept
                said = type(exc)(f"--bag: {exc}")
                said.errno = exc.errno
                raise said from None
        sinks: list[Callable[[np.ndarray, Any], None]] = []
        if not args.no_display and not stopped:
            server = FrameServer(
                "127.0.0.1" if args.host is None else args.host,
                DEFAULT_PORT if args.serve is None else args.serve,
            )
            serving = f"serving the live view on {server.url}{_every_interface(server)}"
            print(serving, file=log, flush=True)
            srv = server
            sinks.append(
                lambda left, res: srv.update(left, res.disparity, float(res.max_disparity))
            )
        floor: list[Any] = [None]  # the latest fit of --ground-every
        if bag is not None:
            writer = bag

            def to_bag(left: np.ndarray, res: Any, stamp_ns: int) -> None:
                # stamped at the grab; with --ground-every: the obstacles on the latest floor
                # as a LaserScan
                writer.write(res, stamp_ns, ground=floor[0])

        def on_result(left: np.ndarray, res: Any) -> None:
            for sink in sinks:
                sink(left, res)

        def on_report(rep: dict[str, Any]) -> None:
            if args.json:
                print(json_line(rep), file=out, flush=True)
            else:
                print(_format_report(rep), file=out, flush=True)

        report = run_stream(
            cam,
            calib,
            method=args.method,
            max_disparity=args.max_disparity,
            frames=args.frames,
            pipelined=not args.no_pipeline,
            refine=args.refine,
            fill=args.fill,
            on_report=on_report,
            on_result=on_result if sinks else None,
            on_stamped_result=to_bag if bag is not None else None,
            check=not args.no_check,
            check_every=args.check_every,
            ground_every=None if stopped else args.ground_every,  # (it needs the calibration)
            on_ground=(lambda plane: floor.__setitem__(0, plane)) if bag is not None else None,
            homographies=homographies,
            temporal=temporal,
            read_timeout=read_timeout,
        )
    except BrokenPipeError:
        # the reader of the reports went away (`stream --json --bag DIR | head -n1`): the stream
        # stops, as Unix tools do (the CLI's 141), but what the bag holds is still said below
        piped = True
        raise
    finally:
        try:
            cam.close()
            if server is not None:
                server.close()
        finally:  # a camera or server that fails to close still lets the bag be finished
            if bag is not None:
                try:
                    bag.close()  # a bag cut short by Ctrl-C or an error is still a valid bag
                except OSError as exc:
                    # the disk still full at the last commit or metadata.yaml: it raised past the
                    # summary (the record of the run lost), or over the error already raised
                    close_error = first_line(exc)
                    if report is None:  # an error or interrupt is on its way out: it is said
                        # after this, and its exit status kept
                        print(f"stereovision: error: {close_error}", file=log)
                if bag.messages == 0:
                    # a run stopped before its first frame (a calibration for other frames, a
                    # source that does not open) left an empty bag in the way: the next run with the
                    # same --bag was refused ("bag folder already exists")
                    import shutil

                    shutil.rmtree(bag.path, ignore_errors=True)
                if piped:  # (on stderr: stdout is gone) each pair processed went into the bag
                    print(_bag_line(bag, bag.frames), file=log)
    if close_error is not None and report.error is None:
        # said in the summary as an output that failed while streaming is; a stream that ended
        # by itself ended with its output failing, an interrupted one keeps its end (and 130)
        from dataclasses import replace

        ended = report.ended if report.ended in ("interrupted", "terminated") else "output failed"
        report = replace(report, ended=ended, error=close_error)
        close_error = None
    summary = report.as_dict()
    skipped = getattr(cam, "skipped", 0)
    if skipped:
        summary["skipped"] = skipped
        print(
            f"{skipped} recorded pairs skipped: the matcher was slower than the recording "
            "(--realtime)",
            file=log,
        )
    if bag is not None:
        print(_bag_line(bag, report.frames), file=log)
    if args.json:
        # strict JSON: a figure with nothing to measure (no pair done: NaN) is null
        print(json_line(summary), file=out, flush=True)
    else:
        st = report.stage_ms
        # no pair: no time to say (each figure is NaN, "nan ms" in every stage)
        timings = (
            "median per pair "
            + ", ".join(f"{k} {st[k]:.1f}" for k in STAGES)
            + f" ms; latency {report.latency_ms:.0f} ms; skew mean"
            f" {report.skew_ms['mean']:.2f} ms, max {report.skew_ms['max']:.2f} ms"
            if report.frames
            else "no pair processed"
        )
        print(
            f"{_counted(report.frames, 'pair')} in {report.seconds:.2f} s ({report.ended}): "
            f"{report.fps:.1f} fps; {timings}; max_disparity {report.max_disparity}",
            file=out,
        )
        if report.temporal is not None and not report.frames:
            restarts = _counted(int(report.temporal["restarts"]), "restart")
            print(f"temporal: no pair filtered, {restarts}", file=out)
        elif report.temporal is not None:
            tp = report.temporal
            noise = (
                "no noise measured (frames all black or white)"
                if math.isnan(tp["noise_sigma"])
                else f"noise {tp['noise_sigma']:.1f} grey levels"
            )
            print(
                f"temporal: {tp['frames_averaged']:.1f} frames averaged per pixel on average,"
                f" {_counted(int(tp['restarts']), 'restart')} (the rig or the view moved), {noise}",
                file=out,
            )
        found = [g for g in report.grounds if g["found"]]
        if report.grounds:
            last = found[-1] if found else None
            # no floor in any fit: "0 of N fits" alone did not say why (no disparity, no
            # near-level plane, pixels along a line)
            why = f"; last (pair {report.grounds[-1]['pair']}): {report.ground_reason}"
            print(
                f"floor: {len(found)} of {len(report.grounds)} fits"
                + (
                    (why if report.ground_reason else "")
                    if last is None
                    else f"; last (pair {last['pair']}): camera {last['height_m']:.3f} m above it,"
                    f" pitch {last['pitch_deg']:+.2f} deg, roll {last['roll_deg']:+.2f} deg"
                ),
                file=out,
            )
    from stereovision.cli import EXIT_ERROR

    cut = {"interrupted": 130, "terminated": 143}.get(report.ended)
    if report.error is not None:
        # the summary and the bag are out; the failure is said last, as the CLI's errors are
        print(f"stereovision: error: {report.error.splitlines()[0]}", file=log)
    if close_error is not None:  # after a failure of its own: both said, the first's status
        print(f"stereovision: error: {close_error}", file=log)
    if cut is not None:
        # the summary and the bag are out; the exit status still tells a script it was cut short
        return cut
    return EXIT_ERROR if report.error is not None else 0


def _every_interface(server: FrameServer) -> str:
    """How to open a view served on every interface (``--host 0.0.0.0`` or ``::``), whose URL
    alone is no address to browse (browsers refuse 0.0.0.0); "" for any other host."""
    import ipaddress

    try:
        unspecified = ipaddress.ip_address(server._host).is_unspecified
    except ValueError:  # a name, or a scoped address
        return ""
    if not unspecified:
        return ""
    here = _host_port("::1" if ":" in server._host else "127.0.0.1", server.port)
    return f" (every interface: http://{here}/ on this machine, its network address from others)"


def _bag_line(bag: Any, pairs: int) -> str:
    """The stream's last word on its ``--bag``: how many of the ``pairs`` processed it holds.

    A full disk lets SQLite undo every frame since the bag's last commit (each
    :data:`~stereovision.rosbag.COMMIT_PERIOD_S`): the bag then holds fewer frames than pairs,
    which is said with the number lost (it said "2 pairs ... (output failed)" beside a bag of
    none, or of fewer, as if the pairs done were in it).
    """
    frames = int(bag.frames)
    n_lost = pairs - frames
    lost = (
        f"the disk filled and SQLite undid the frames since the bag's last commit "
        f"({n_lost} frame{'' if n_lost == 1 else 's'} lost)"
    )
    # a folder named with a newline cut the line in two (escaped, as errors name it)
    where = escaped(str(bag.path))
    if not bag.messages:  # the folder was removed (it said "written to DIR (0 messages)")
        if not pairs:
            return f"no ROS 2 bag written to {where}: no frame in it"
        return (
            f"no ROS 2 bag written to {where}: none of the {_counted(pairs, 'pair')} "
            "processed; " + lost
        )
    # "1 pairs", "1 frames" read badly (as capture's counts, said in the singular since fd8a1f4)
    held = (
        f"{frames} of the {_counted(pairs, 'pair')} processed"
        if frames <= pairs
        else _counted(frames, "frame")
    )
    line = f"ROS 2 bag written to {where} ({held}, {bag.messages} messages)"
    return line + "; " + lost if frames < pairs else line


def temporal_pairs(text: str) -> int:
    """argparse type of ``--temporal``: 2 to 255 pairs (the filter's bounds), refused in the
    option's name as the other counts are (``8.5`` was argparse's "invalid int value", and ``1``
    was refused only after ``--calib`` was read)."""
    from stereovision.cli import whole_number  # 8.0 too, as every whole-number option

    value = whole_number(text)
    if value is None or not 2 <= value <= 255:
        raise argparse.ArgumentTypeError(f"expected 2-255 pairs to average, got {text!r}")
    return value


def add_cli(subparsers: Any) -> None:
    """Register ``stereovision stream`` on the CLI's sub-parsers."""
    # cli builds its parser with these
    from stereovision.cli import (
        CALIB_FILES_HELP,
        add_calib_unit,
        listen_address,
        port_number,
        positive_count,
        positive_pixels,
        positive_rate,
    )
    from stereovision.depth import METHODS

    p = subparsers.add_parser(
        "stream",
        help="live depth from two cameras (videos, a ROS bag), with fps and per-stage latency",
        description="Grab synchronised pairs, rectify, compute depth, serve the live view "
        "over HTTP (MJPEG) and report fps, stage times and skew every second.",
    )
    add_source_args(p)
    p.add_argument(
        "--calib",
        help=f"calibration of the rig: {CALIB_FILES_HELP}; "
        "--from-bag: default the bag's camera_info",
    )
    add_calib_unit(p)
    p.add_argument(
        "--realtime",
        action="store_true",
        help="--from-bag: play the recording at its own pace, skipping the pairs a slower "
        "matcher would miss (as live cameras do)",
    )
    p.add_argument(
        "--rectification",
        metavar="JSON",
        help="a rig without a calibration: the homographies `stereovision rectify` found "
        "(disparity only)",
    )
    p.add_argument(
        "--size",
        help="requested size WIDTHxHEIGHT (frames of the same shape are resized if needed; "
        "another shape keeps its own size, with a warning)",
    )
    p.add_argument(
        "--fps",
        type=positive_rate,
        help="requested frame rate of the cameras (asked with the size and format; a file is "
        "read as it is; refused with --from-bag, a bag has no rate to ask)",
    )
    p.add_argument(
        "--max-disparity",
        type=positive_pixels,
        metavar="N",
        # with --rectification the default is its own range (run_stream), not an estimate
        help="disparity range to search, in pixels (default: estimated once, from the first "
        "pair; with --rectification, the search range it holds)",
    )
    p.add_argument(
        "--method",
        default="gabor",
        choices=METHODS,
        help="matcher (default: gabor, the quickest; fast --no-fill: half its wrong pixels)",
    )
    p.add_argument(
        "--frames", type=positive_count, help="stop after N pairs (default: until a source ends)"
    )
    p.add_argument(
        "--refine", action="store_true", help="sub-pixel refinement per frame (2-3x the time)"
    )
    # one or the other: both given, the last silently won
    fill = p.add_mutually_exclusive_group()
    fill.add_argument(
        "--fill", action="store_const", const=True, help="fill holes (default: the method's)"
    )
    fill.add_argument(
        "--no-fill", dest="fill", action="store_const", const=False, help="leave holes NaN"
    )
    p.add_argument("--no-display", action="store_true", help="headless: do not serve the view")
    # no argparse defaults: given with --no-display, which serves no view, they are refused
    p.add_argument(
        "--serve",
        type=port_number,
        metavar="PORT",
        help=f"view port (default {DEFAULT_PORT})",
    )
    p.add_argument("--host", type=listen_address, help="view address (default 127.0.0.1)")
    p.add_argument("--json", action="store_true", help="one JSON object per second on stdout")
    p.add_argument(
        "--no-check",
        action="store_true",
        help="skip the rectification check of the first pair (a warning when rows disagree)",
    )
    p.add_argument(
        "--check-every",
        type=positive_count,
        metavar="N",
        help="also check the rows of every N-th pair (a rig bumped while running)",
    )
    p.add_argument(
        "--bag",
        metavar="DIR",
        help="also record every frame into a new ROS 2 bag (rectified left image, camera_info, "
        "depth, points); needs a calibration (--calib, or with --from-bag the recording's "
        "camera_info) and the rosbags package",
    )
    p.add_argument(
        "--ground-every",
        type=positive_count,
        metavar="N",
        help="fit the floor on every N-th pair and warn when the camera's height, pitch or roll "
        "moves (a mount that slipped); needs a calibration (--calib, or with --from-bag the "
        "recording's camera_info)",
    )
    p.add_argument(
        "--no-tf",
        action="store_true",
        help="with --bag and --ground-every: leave /tf (the camera's optical frame under "
        "base_footprint, at its pose on the fitted floor) out of the bag, for a robot whose own "
        "transforms (robot_state_publisher, its URDF) already place the camera: a frame has one "
        "parent in tf",
    )
    p.add_argument(
        "--temporal",
        type=temporal_pairs,
        metavar="N",
        help="average a still rig's frames over up to N pairs (e.g. 8) before matching: less "
        "noise in low light; starts again where the rig or the scene moves",
    )
    p.add_argument(
        "--no-pipeline", action="store_true", help="grab, rectify and match in one thread"
    )
    p.set_defaults(func=cmd_stream)
