"""Two-camera capture: synchronised pairs, atomic saving, chessboard auto-capture.

A source is anything :class:`cv2.VideoCapture` opens -- a device index (``0``), a video file
(``left.avi``) or an image-sequence pattern (``frames/left_%03d.png``) -- so everything here is
testable without cameras; a recording in a ROS bag is read by
:class:`~stereovision.rosbag.BagCamera`, which has the same interface (``--from-bag``). A pair
is taken the way OpenCV recommends for multi-camera rigs: *grab* both cameras first (cheap,
latches the frames), then *retrieve* (decode) both, and each grab is timestamped so the
left/right skew can be measured and reported.

Saved pairs are numbered ``left_0001.png`` / ``right_0001.png``; each file is encoded in memory,
written to a temporary file in the destination directory and then given its final name (a hard
link, which never replaces a file: two captures into one folder take turns for the numbers), so a
reader never sees a half-written image. The right image of a pair is written last: a pair is
complete when its right image exists.

In chessboard mode (:class:`ChessboardCollector`) a pair is saved only when both cameras see the
board and its pose -- ``(x, y, size, skew)`` as in ROS's ``camera_calibration`` -- differs enough
from every pair saved so far; the coverage of each of the four parameters is printed as it grows.
With a ChArUco board (``charuco=``) a pair needs enough corners seen by both cameras (the board
may be cut by the image edge) and its pose is that of the whole board, placed through the
homography of the corners seen.

With ``temporal=N`` (``--temporal N``) each saved pair is the mean of N frames of a still view
(:class:`~stereovision.temporal.TemporalFilter`): less sensor noise in low light, for a board on
a stand or a still scene.
"""

from __future__ import annotations

import argparse
import contextlib
import contextvars
import dataclasses
import errno
import functools
import glob
import itertools
import math
import os
import re
import secrets
import statistics
import sys
import threading
import time
import warnings
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar, overload

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    NOT_NUMBERS,
    as_image_array,
    as_path,
    escaped,
    float_sized,
    path_given,
    positive_whole,
    renamed_keyword,
    source_warning,
    too_large_for_float,
)
from stereovision.calibrate import (
    DEFAULT_READ_TIMEOUT,
    POSE_PARAM_NAMES,
    POSE_PARAM_RANGES,
    board_pose_params,
    parse_pattern,
)
from stereovision.charuco import CharucoBoard
from stereovision.io import _broken_link, _opencv_quiet, check_output_folder, make_folder

__all__ = [
    "MIN_POSE_DISTANCE",
    "SECRET_QUERY_KEYS",
    "CaptureResult",
    "ChessboardCollector",
    "PairSource",
    "SkewStats",
    "SourceError",
    "StereoCamera",
    "StereoFrame",
    "add_bag_args",
    "add_cli",
    "add_read_timeout",
    "add_source_args",
    "capture",
    "cli_read_timeout",
    "fourcc_text",
    "mask_url_secrets",
    "open_source",
    "parse_fourcc",
    "parse_size",
    "parse_source",
    "remove_stale_temps",
    "resize_frame",
    "save_pair",
    "temporal_average",
]

PathLike = str | os.PathLike[str]
Source = int | str | os.PathLike[str] | Any

#: ROS camera_calibration's "good sample" rule: a new view is kept when the sum of absolute
#: differences of its (x, y, size, skew) to every kept view is above 0.2.
MIN_POSE_DISTANCE = 0.2
#: Live detection runs on frames scaled down to at most this width (ROS does the same): the
#: classic detector with FAST_CHECK answers in a few ms at VGA, and the pose parameters are
#: relative, so the scale does not change them.
DETECT_MAX_WIDTH = 640
#: Flags of the live detector: adaptive threshold and normalisation for uneven light; FAST_CHECK
#: rejects board-less frames quickly.
LIVE_DETECT_FLAGS = (
    cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_FAST_CHECK
)
#: ``temporal``: a pair is taken once a pixel's mean holds this share of the frames asked for on
#: average (a few pixels start again: something crossed them, or noise beyond 3 sigmas).
_TEMPORAL_FULL = 0.95
#: Width of each coverage bar in the progress line (characters).
PROGRESS_BAR_WIDTH = 10
#: A board capture resumed into its folder reads the board poses of at most this many pairs
#: there, the last ones: each is two image reads and a board search (~60 ms of CPU at VGA, ~100
#: ms at 1280x720), and 200 pairs there held the first pair back 12-22 s in silence.
RESUME_POSES_MAX = 20
#: File name pattern of saved pairs (index from 1; 4 digits sort well up to 9999 pairs).
PAIR_NAME = "{side}_{index:04d}{ext}"
_PAIR_RE = re.compile(r"^(left|right)_(\d+)\.[A-Za-z0-9]+$")
#: The image format's extension of saved pairs (``.png``, ``.jpg``): the names _PAIR_RE reads.
_EXT_RE = re.compile(r"^\.[A-Za-z0-9]+$")


class SourceError(OSError):
    """A camera or video source failed to open or stopped delivering frames.

    Parameters
    ----------
    message : str
    side : str, optional
        ``"left"``, ``"right"`` or ``"both"``: the source(s) concerned.
    end : bool
        True when a source came to its end (a file or sequence read to its last frame, a camera
        that stopped delivering): :func:`capture` without ``count`` then ends normally. False
        for a failure of another kind (a frame that does not decode, a frame of another shape,
        a closed camera).
    frames : int, optional
        Frames read from the source concerned before this (pairs read before).
    other_had_frames : bool, optional
        With one ``side`` ended: whether the other source still delivered a frame.
    expected_frames : int, optional
        The frame count an ended video file (or sequence) announces (``CAP_PROP_FRAME_COUNT``),
        when it announced more than were read.
    gap : str, optional
        The image whose absence ended an image sequence while images numbered after it exist.

    Attributes
    ----------
    side, end, frames, other_had_frames, expected_frames, gap
        As given.
    """

    def __init__(
        self,
        message: str,
        *,
        side: str | None = None,
        end: bool = True,
        frames: int | None = None,
        other_had_frames: bool | None = None,
        expected_frames: int | None = None,
        gap: str | None = None,
    ) -> None:
        super().__init__(message)
        self.side = side
        self.end = end
        self.frames = frames
        self.other_had_frames = other_had_frames
        self.expected_frames = expected_frames
        self.gap = gap

    @property
    def ended_early(self) -> bool:
        """A source ended while the other still had frames, before the frames it announced, or
        at a gap in its numbered images."""
        return (
            bool(self.other_had_frames) or self.expected_frames is not None or self.gap is not None
        )

    def _kwargs(self) -> dict[str, Any]:
        return {
            "side": self.side,
            "end": self.end,
            "frames": self.frames,
            "other_had_frames": self.other_had_frames,
            "expected_frames": self.expected_frames,
            "gap": self.gap,
        }

    def with_message(self, message: str) -> SourceError:
        """The same error with another message (its attributes kept).

        Parameters
        ----------
        message : str
            The new message.

        Returns
        -------
        SourceError
            A new error; ``self`` is unchanged.
        """
        return SourceError(message, **self._kwargs())

    def __reduce__(self) -> tuple[Any, ...]:
        return (_source_error, (str(self), self._kwargs()))


def _source_error(message: str, kwargs: dict[str, Any]) -> SourceError:
    return SourceError(message, **kwargs)


# --------------------------------------------------------------------------------- parsing


def _negative_index(n: int, text: str | None = None) -> str:
    # the file as typed: "./-1" for "-01" was another file
    return (
        f"camera index {n} is negative: cameras are numbered from 0 "
        f"(./{n if text is None else text} for a file)"
    )


#: Largest device index OpenCV takes (a C int): a larger one failed in cv2.VideoCapture's
#: overload resolution, said as "did not open: OpenCV failed (in function 'VideoCapture'".
MAX_CAMERA_INDEX = 2**31 - 1


def _too_large_index(n: int, text: str | None = None) -> str:
    return (
        f"camera index {n} is too large: cameras are numbered from 0 to {MAX_CAMERA_INDEX} "
        f"(./{n if text is None else text} for a file)"
    )


def parse_source(text: str | int) -> int | str:
    """A device index for an all-digit string (``"0"`` -> ``0``), else the text (file/pattern).

    Parameters
    ----------
    text : str or int
        ``--left`` / ``--right`` as given.

    Returns
    -------
    int or str
        The device index, or ``text`` unchanged (a video file, an image pattern, a URL).

    Raises
    ------
    ValueError
        A negative index (``-1`` or ``"-1"``): OpenCV's -1 is "any camera", no side of a rig,
        and crashes the process where no camera is present; as text it was taken for a file.
        One above :data:`MAX_CAMERA_INDEX`, which OpenCV cannot take.
    """
    # a bool is no camera (True opened camera 1); NumPy's integers are (AttributeError: strip)
    if isinstance(text, (bool, np.bool_)):
        raise ValueError(f"camera source: expected a device index or a path, got {text!r}")
    if isinstance(text, (int, np.integer)):
        if text < 0:
            raise ValueError(_negative_index(int(text)))
        if text > MAX_CAMERA_INDEX:
            raise ValueError(_too_large_index(int(text)))
        return int(text)
    # "-0" is no negative index: a path, as it was (its message said "camera index 0 is negative")
    if re.fullmatch(r"-\d+", text.strip(), re.ASCII) and int(text) < 0:
        raise ValueError(_negative_index(int(text), text.strip()))
    # isdecimal, not isdigit: "²" is a digit that int() refuses ("invalid literal for int()")
    if not text.strip().isdecimal():
        return text
    if int(text) > MAX_CAMERA_INDEX:
        raise ValueError(_too_large_index(int(text), text.strip()))
    return int(text)


#: Largest frame side accepted for ``--size`` (16K video is 15360 px wide).
MAX_SIDE = 16384


def parse_size(text: str | tuple[int, int] | None, name: str = "size") -> tuple[int, int] | None:
    """Parse ``"1280x720"`` to ``(1280, 720)``.

    Parameters
    ----------
    text : str or tuple of int or None
        ``"WIDTHxHEIGHT"``, a ``(width, height)`` tuple or list of whole numbers (checked the
        same way), or None.
    name : str
        What the messages call it (the parameter or option it came from).

    Returns
    -------
    tuple of int or None
        ``(width, height)`` in pixels, or None for None.

    Raises
    ------
    ValueError
        If the text is not two positive integers separated by ``x``, or a side exceeds
        :data:`MAX_SIDE`.
    """
    if text is None:
        return None
    if isinstance(text, str):
        m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
        vals = (int(m.group(1)), int(m.group(2))) if m else (0, 0)
    else:
        # int() cut (640.7, 480) to 640x480 and took (True, 480) as 1x480 without a word
        listed = isinstance(text, (tuple, list))
        items = tuple(text) if listed or (isinstance(text, np.ndarray) and text.ndim == 1) else ()
        whole = len(items) == 2 and all(
            not isinstance(v, NOT_NUMBERS)  # (np.timedelta64(640), 480) was 640x480
            and isinstance(v, (int, float, np.integer, np.floating))
            # an int as it is: math.isfinite(10**400) raised OverflowError, naming nothing
            and (isinstance(v, (int, np.integer)) or (math.isfinite(v) and float(v).is_integer()))
            for v in items
        )
        vals = (int(items[0]), int(items[1])) if whole else (0, 0)
    if min(vals) <= 0:
        big = isinstance(text, (tuple, list)) and any(map(too_large_for_float, text))
        shown = f"({', '.join(map(_int_shown, text))})" if big else repr(text)
        raise ValueError(f"{name}: expected WIDTHxHEIGHT with positive integers, got {shown}")
    # Frames of another size are resized to this one: 100000x100000 made OpenCV fail to
    # allocate 30 GB per frame, an internal error instead of a word about the size.
    if max(vals) > MAX_SIDE:
        big = any(map(too_large_for_float, vals))
        shown = f"({', '.join(map(_int_shown, vals))})" if big else f"{vals[0]}x{vals[1]}"
        raise ValueError(f"{name}: at most {MAX_SIDE} px per side, got {shown}")
    return vals


def _int_shown(value: object) -> str:
    """``repr(value)`` for a message, an int beyond a float as its digits' count: the 401
    digits of 10**400 filled the line, and 10**5000 has no str (Python's "Exceeds the limit
    (4300 digits)" ValueError, naming no keyword)."""
    return too_large_for_float(value, why=False) or repr(value)


# ---------------------------------------------------------------------------------- camera


def parse_fourcc(text: str | None) -> str | None:
    """A pixel format's four-character code (``"MJPG"``, ``"YUYV"``), checked; None stays None.

    Parameters
    ----------
    text : str or None
        The code as given (``--fourcc``).

    Returns
    -------
    str or None
        ``text`` itself, or None for None.

    Raises
    ------
    ValueError
        If it is not four printable ASCII characters.
    """
    if text is None:
        return None
    if not (isinstance(text, str) and len(text) == 4 and all(" " <= c <= "~" for c in text)):
        raise ValueError(f"fourcc: expected four characters such as 'MJPG' or 'YUYV', got {text!r}")
    return text


def fourcc_code(text: str) -> str:
    """argparse type of ``--fourcc``: four printable ASCII characters, refused in the option's
    name (the library's parameter, ``fourcc: expected ...``, was what the CLI said)."""
    try:
        return str(parse_fourcc(text))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected four characters such as 'MJPG' or 'YUYV', got {text!r}"
        ) from None


def fourcc_text(code: float) -> str:
    """``CAP_PROP_FOURCC``'s number as its four characters.

    Parameters
    ----------
    code : float
        The number OpenCV's ``get(CAP_PROP_FOURCC)`` returns.

    Returns
    -------
    str
        Four characters (``"MJPG"``), or ``""`` for 0, a non-finite number or unprintable
        characters.
    """
    n = int(code) if math.isfinite(code) and code > 0 else 0
    text = "".join(chr((n >> (8 * k)) & 0xFF) for k in range(4))
    return text if n and all(" " <= c <= "~" for c in text) else ""


@dataclass(eq=False)  # array fields: == by identity (== raised)
class StereoFrame:
    """One synchronised pair.

    Attributes
    ----------
    left, right : numpy.ndarray
        The frames (BGR ``uint8``, resized to the camera's output size if needed; an image
        sequence's 16-bit images stay ``uint16``).
    t_left, t_right : float
        Host time (``time.monotonic()``, seconds) at which each grab returned.
    index : int
        0-based pair counter of the camera.
    pos_left_ms, pos_right_ms : float
        The sources' own timestamps (``CAP_PROP_POS_MSEC``; a video file's media time).
    delivered : tuple of numpy.ndarray or None
        The two frames as the sources delivered them, when either was resized to the output
        size (None when neither was): what a :class:`~stereovision.temporal.TemporalFilter`
        averages when they were enlarged, before the interpolation spreads their noise.
    """

    left: np.ndarray
    right: np.ndarray
    t_left: float
    t_right: float
    index: int
    pos_left_ms: float = math.nan
    pos_right_ms: float = math.nan
    delivered: tuple[np.ndarray, np.ndarray] | None = None

    @property
    def skew_ms(self) -> float:
        """``|t_left - t_right|`` in milliseconds: how far apart the two grabs were."""
        return abs(self.t_left - self.t_right) * 1000.0


def _media_ms(cap: Any) -> float:
    """``CAP_PROP_POS_MSEC``; NaN for a source that has none (``CAP_IMAGES`` says -1)."""
    ms = float(cap.get(cv2.CAP_PROP_POS_MSEC))
    return ms if ms >= 0 else math.nan


_SCHEME = r"[A-Za-z][A-Za-z0-9+.-]*://"
#: A URL's password: the scheme and user kept (group 1 or 2). The authority ends at the first
#: "/", "?" or "#", its user part at its last "@" and the user at its first ":", as FFmpeg
#: splits a URL (a raw "@" in a password, or in a user named by an e-mail address);
#: failing that, at the first "/": a password typed with a raw "#" or "?" (which FFmpeg
#: cannot open, so it is said in the error) is a password still.
_URL_PASSWORD = re.compile(
    r"(" + _SCHEME + r"[^/?#:]*):[^/?#]*@|(" + _SCHEME + r"[^/?#@:]*):[^/]*@"
)
#: What :data:`_URL_PASSWORD`'s fallback (a raw "?" or "#" in a password) took for a user
#: part but is an IPv6 host (``[::1]``, its port optional) and then a query: the ":" inside its
#: brackets was taken for a user's, and ``rtsp://[::1]:554?x=a@b`` said ``rtsp://[:***@b``. A
#: user part holds no "[" (RFC 3986), so nothing is leaked by reading it so.
_PORT_THEN_QUERY = re.compile(_SCHEME + r"\[[0-9A-Fa-f:.]*(?:%[^\]/?#@]*)?\](?::\d{1,5})?\?[^=@]*=")
#: The same shape with a host name (``rtsp://cam:554?x=a@b``) reads as ``user:password@`` too
#: (``rtsp://admin:1234?pw=x@cam/0``, a password with a raw "?"): it stays hidden, a leak being
#: worse than too much hidden, and the secret parameters after its "@" are masked all the same
#: (``cam:554?mail=a@b&token=t`` said its token when they were looked for after a "?" only).
_NAMED_PORT_THEN_QUERY = re.compile(_SCHEME + r"[^/?#@:]*:\d{1,5}\?[^=@]*=")
#: A URL inside other text (a GStreamer pipeline's ``location=rtsp://...``): its scheme at
#: the start or after a space, "=" or a quote; it ends at a space or a quote.
_URL_IN_TEXT = re.compile(r"(?:^|(?<=[\s=\"']))" + _SCHEME + r"[^\s\"']*")
#: Query parameters whose value is a secret (case-insensitive): what IP cameras and stream
#: servers take a token or password as, and a presigned URL's signature (S3's, a CDN's).
SECRET_QUERY_KEYS = (
    "access_token",
    "api_key",
    "apikey",
    "auth",
    "client_secret",
    "key",
    "passwd",
    "password",
    "pwd",
    "secret",
    "sig",
    "signature",
    "token",
    "x-amz-credential",
    "x-amz-security-token",
    "x-amz-signature",
)
_URL_SECRET_PARAM = re.compile(
    r"([?&;](?:" + "|".join(SECRET_QUERY_KEYS) + r")=)[^&;#]+", re.IGNORECASE
)


def mask_url_secrets(source: str) -> str:
    """``source`` as it may be said (in a message, a log, a written file): a URL's password and
    the values of its :data:`SECRET_QUERY_KEYS` query parameters as ``***``.

    Only what is said is masked: the source is opened as given.

    Parameters
    ----------
    source : str
        A camera source as given: a stream URL, a path or a device index's text.

    Returns
    -------
    str
        ``source`` unchanged unless it is a URL (``scheme://``) holding a password or a secret
        parameter: ``rtsp://admin:s3cret@cam/0?token=abc`` is ``rtsp://admin:***@cam/0?token=***``.

    Notes
    -----
    The user part is looked for in the authority (RFC 3986: before the first ``/``, ``?`` or
    ``#``) and ends at its last ``@`` (``me@mail.com:pw@cam`` hides ``pw``). Where that holds no
    ``@``, a ``user:password@`` running on to the first ``/`` is hidden all the same: a
    password typed with a raw ``?`` or ``#`` (``admin:pa?ss@cam``) reads like the start of a
    query, and a leak is worse than too much hidden. So is ``cam:554?x=a@b`` (a port then a
    query holding an ``@``, or the password ``1234?x=a``): said ``cam:***@b``, with the secret
    parameters after it masked too. An IPv6 host (``[::1]:554?x=a@b``, ``[::1]?x=a@b``) holds
    no user part and is said as given.

    Examples
    --------
    >>> mask_url_secrets("http://user:pw@host:8080/x?size=2&access_token=abc")
    'http://user:***@host:8080/x?size=2&access_token=***'
    >>> mask_url_secrets("rtsp://cam:554/0")
    'rtsp://cam:554/0'
    """
    said, at = [], 0
    for start, end, masked in _url_secrets(source):
        said += [source[at:start], masked]
        at = end
    return "".join(said) + source[at:]


def _url_secrets(source: str) -> list[tuple[int, int, str]]:
    """Where ``source`` (a URL, or text holding URLs such as a GStreamer pipeline; none for a
    path, whose name may hold ``user:pw@`` or ``?key=``) holds a secret: ``(start, end,
    masked)`` of each part, ``admin:s3cret@`` to be said ``admin:***@``, ``?token=abc``
    ``?token=***``; in their order in ``source``."""
    if "://" not in source:
        return []
    body = source.lstrip()
    if re.match(_SCHEME, body):  # one URL (a space in it is the URL's, as it is opened)
        spans = [(len(source) - len(body), len(source))]
    else:  # URLs in a pipeline: the password in "location=rtsp://u:pw@h/" was said
        spans = [m.span() for m in _URL_IN_TEXT.finditer(source)]
    parts = []
    for first, last in spans:
        password = _URL_PASSWORD.match(source, first, last)
        if password and password[2] is not None and _PORT_THEN_QUERY.match(password[0]):
            password = None  # "[::1]:554?x=a@b": an IPv6 port, then a query holding an "@"
        ambiguous = bool(
            password and password[2] is not None and _NAMED_PORT_THEN_QUERY.match(password[0])
        )
        if password:
            parts.append((first, password.end(), f"{password[1] or password[2]}:***@"))
        # the query alone: from the first "?" after the authority to the fragment ("#"); after
        # a hidden "cam:554?x=a@" (a query, maybe) from its "@" on, "?" or not
        start = source.find("?", password.end() if password else first, last)
        if ambiguous and password:
            start = password.end() - 1
        if start >= 0:
            end = source.find("#", start, last)
            query = _URL_SECRET_PARAM.finditer(source, start, end if end >= 0 else last)
            parts += [(m.start(), m.end(), f"{m.group(1)}***") for m in query]
    return parts


def _mask_secrets_of(text: str, source: str) -> str:
    """``text`` (another library's message, that names ``source`` in its own way: Dask's
    ``invalid address 'admin:pw@host:1'``) with the parts of ``source`` that hold a secret
    (``admin:pw@``, ``?token=abc``) masked as :func:`mask_url_secrets` masks them."""
    # the whole URL first, with or without its scheme (as Dask says an address): a part
    # alone may be in it twice ("&key=1" in a path too)
    said = mask_url_secrets(source)
    for raw, masked in ((source, said), (source.split("://", 1)[-1], said.split("://", 1)[-1])):
        if raw in text:
            return text.replace(raw, masked)
    for start, end, masked in _url_secrets(source):  # a part said alone
        text = text.replace(source[start:end].split("://", 1)[-1], masked.split("://", 1)[-1])
    return text


def _describe_source(src: Source) -> str:
    # a NumPy index is a device too (StereoCamera opens it): it was described as 'int64'
    if isinstance(src, (int, np.integer)):
        return f"camera {int(src)}"
    if isinstance(src, (str, os.PathLike)):
        # a stream's password is not said (in an error, a log line, a report)
        return repr(mask_url_secrets(os.fspath(src)))
    return type(src).__name__


#: What a ``%`` of an image-sequence pattern starts: a literal percent sign (``%%``) or the
#: frame number (``left_%03d.png``; ``%03u``, printf's unsigned, as ``CAP_IMAGES`` allows).
_SEQ_TOKEN_RE = re.compile(r"%%|%(0?\d*)[du]")


_T = TypeVar("_T")
#: Seconds an interrupted wait still gives the grab under way to come back (:func:`_within`).
_INTERRUPT_GRACE_S = 2.0
#: The bound on a :class:`StereoCamera`'s native grab in this context (:func:`read_within`).
_READ_TIMEOUT: contextvars.ContextVar[float | None] = contextvars.ContextVar(
    "stereovision_read_timeout", default=None
)


def check_read_timeout(timeout: float | None, name: str = "read_timeout") -> None:
    """Refuse a ``read_timeout`` that is not a positive, finite number of seconds or None
    (checked by :func:`read_within`, and by :func:`capture`,
    :func:`~stereovision.stream.run_stream` and
    :func:`~stereovision.calibrate.calibrate_from_video` before they open anything);
    ``name`` is the keyword said (:class:`StereoCamera`'s ``open_timeout``)."""
    # inf (meant as no limit) passed, then overflowed the wait ("timestamp out of range for
    # platform time_t"); True passed as 1 s
    if timeout is not None and (
        isinstance(timeout, NOT_NUMBERS)  # 3 ns: NumPy's bare UFuncTypeError in the comparison
        # an int as it is: math.isfinite(10**400) raised OverflowError (said below as too long)
        or not (timeout > 0 and (isinstance(timeout, (int, np.integer)) or math.isfinite(timeout)))
    ):
        raise ValueError(
            f"{name}: expected a positive number of seconds (None: no limit), "
            f"got {_int_shown(timeout)}"
        )
    # 1e10 s passed too, and overflowed the wait as inf did (an internal OverflowError)
    if timeout is not None and timeout > threading.TIMEOUT_MAX:
        raise ValueError(
            f"{name}: expected at most {threading.TIMEOUT_MAX:g} seconds (None: no limit), "
            f"got {_int_shown(timeout)}"
        )


def check_min_distance(min_distance: object) -> float:
    """``min_distance`` of :class:`ChessboardCollector` as a float, refused unless a finite
    number of 0 or more (checked by the collector, and by
    :func:`~stereovision.calibrate.calibrate_from_video` and
    :func:`~stereovision.calibrate.calibrate_from_bag` before they open anything)."""
    from stereovision._validate import finite_number

    value = finite_number(min_distance, "min_distance")
    if value < 0:
        raise ValueError(f"min_distance: expected a finite number of 0 or more, got {value!r}")
    return value


def read_within(camera: Any, timeout: float | None = DEFAULT_READ_TIMEOUT) -> StereoFrame:
    """``camera.read()``, its native grab given up after ``timeout`` seconds.

    A :class:`StereoCamera` (also behind a wrapper that calls its ``read``) runs its grab and
    retrieve, the part in OpenCV that a hung camera never returns from, in a daemon thread
    while the caller waits on an event, which Ctrl-C and SIGTERM interrupt at once: in the
    main thread a read in native code holds them off until it returns. The rest of the read,
    and its warnings, stay in the caller's thread (a warning raised in the worker would point
    at threading.py). Another source (a recording, an object of the user's) is read as it is.

    Parameters
    ----------
    camera : object
        Anything with ``read()`` (a :class:`StereoCamera`, a recording).
    timeout : float or None
        Seconds to wait (:data:`DEFAULT_READ_TIMEOUT`); None waits as long as the grab takes.

    Returns
    -------
    StereoFrame
        What ``read`` returned.

    Raises
    ------
    SourceError
        If a :class:`StereoCamera`'s grab did not return within ``timeout`` (``end`` False),
        naming its sources; or as ``read`` raises it.
    ValueError
        If ``timeout`` is not a positive number of seconds (or None).
    """
    check_read_timeout(timeout)
    token = _READ_TIMEOUT.set(timeout)
    try:
        return camera.read()  # type: ignore[no-any-return]
    finally:
        _READ_TIMEOUT.reset(token)


def _within(
    work: Callable[[], _T],
    timeout: float | None,
    name: str,
    cancel: Callable[[], bool] | None = None,
    hung: str | Callable[[], str] | None = None,
    side: str = "both",
) -> _T:
    """``work()`` in a daemon thread, given up after ``timeout`` s (None: called here).

    On an interrupt, ``cancel()`` (when given) is asked first whether it kept ``work`` from
    beginning (True); only one under way is waited for, up to :data:`_INTERRUPT_GRACE_S`.
    Given up, it raises :class:`SourceError` saying ``hung`` (called then, when callable;
    default: a read's words, with ``name``, the sources) about ``side``.
    """
    if timeout is None:
        return work()
    done = threading.Event()
    box: list[Any] = []

    def run() -> None:
        try:
            box.append(work())
        except BaseException as exc:  # raised in the caller's thread below
            box.append(exc)
        finally:
            done.set()

    try:
        threading.Thread(target=run, name="stereovision-grab", daemon=True).start()
        finished = done.wait(timeout)
    except Exception:  # no thread started ("can't start new thread"): nothing under way
        raise
    except BaseException:
        # Ctrl-C (SIGTERM) mid-grab, or while the thread started: the grab, not hung, comes back
        # within milliseconds; let it before the interrupt goes on. A thread coming back out of
        # OpenCV while the interpreter shut down aborted the process (SIGABRT, exit -6, not 130).
        # One not begun yet is given up instead: waiting let it begin and grab a pair then lost.
        if cancel is None or not cancel():
            done.wait(min(timeout, _INTERRUPT_GRACE_S))
        raise
    if not finished:
        # the thread stays in OpenCV (nothing stops native code); its frame, if it ever comes,
        # is dropped
        raise SourceError(
            (hung() if callable(hung) else hung)
            or f"{name} delivered no frame in {timeout:g} s (its read did not return: a hung or "
            "unplugged USB camera, a stalled stream); unplug and replug it",
            side=side,
            end=False,
        )
    if isinstance(box[0], BaseException):
        raise box[0]
    return box[0]  # type: ignore[no-any-return]


def _open_within(
    make: Callable[[], Any],
    timeout: float | None,
    side: str,
    src: Source,
    configure: Callable[[Any, Callable[[str], None]], None] | None = None,
) -> Any:
    """``make()``, the ``cv2.VideoCapture`` of ``side``'s source ``src``, then
    ``configure(cap, doing)``, given up together after ``timeout`` s as a read is
    (:func:`_within`; None: no limit): a wedged V4L2 device, or a stream that stalls, can keep
    OpenCV's open, or a ``set``/``get`` after it, from ever returning. Both run in one worker
    (no thread per call). ``configure`` says what it is about to do (``doing("setting its
    frame width to 640")``) for the message, should that hang. A capture that opens, or ends
    its settings, after it was given up is released then (it held the device), never while a
    ``set`` is under way in it (a release under OpenCV crashed the process); one whose
    ``configure`` raised is released.

    OpenCV's log stays silent (:func:`~stereovision.io._opencv_quiet`) until the open returns,
    given up or not: the caller's quiet ended when it was given up, and a late open printed
    its backends' lines. An open that never returns keeps it silent for the process's life.
    The settings are not silenced (OpenCV's word on a setting a driver refused is kept).
    A ``cv2.error`` of the open or of a setting is a :class:`SourceError` naming the source
    and the step, as a hang is.
    """
    doing = ["its open"]
    what = f"{side} source {_describe_source(src)}"

    def note(step: str) -> None:
        doing[0] = step

    def failed(exc: cv2.error) -> SourceError:
        # OpenCV's words on what it refused (a setting a backend cannot take, in its exception
        # mode): a source's failure as a hung setting's, not a bug's raw cv2.error
        from stereovision.calibration import _first_line

        said = (
            f"did not open: OpenCV failed ({_first_line(exc)})"
            if doing[0] == "its open"
            else f"was not set up: {doing[0]} failed in OpenCV ({_first_line(exc)})"
        )
        return SourceError(f"{what} {said}", side=side, end=False)

    def made_now() -> Any:
        try:
            return make()
        except cv2.error as exc:
            raise failed(exc) from exc

    def configured(cap: Any) -> Any:
        if configure is not None:
            try:
                configure(cap, note)
            except BaseException as exc:  # nobody will have it
                _release([cap])
                if isinstance(exc, cv2.error):
                    raise failed(exc) from exc
                raise
        return cap

    if timeout is None:
        with _opencv_quiet():
            cap = made_now()
        return configured(cap)
    lock = threading.Lock()
    given_up = [False]
    made: list[Any] = []  # the capture, once made in time; the one that gives up releases it

    def opened() -> Any:
        with _opencv_quiet():
            cap = made_now()
            with lock:
                late = given_up[0]
            if late:  # nobody will have it
                _release([cap])
                return cap
        configured(cap)
        with lock:
            late = given_up[0]
            if not late:
                made.append(cap)
        if late:  # given up during its settings: released now that none is under way
            with _opencv_quiet():
                _release([cap])
        return cap

    # a URL or file has no plug, and a network stream may just be slow (FFmpeg's own open
    # waits 30 s): "unplug and replug it" is a device's advice alone, a longer limit either's
    # a camera by its index or by its V4L2 node (/dev/video0, a /dev/v4l/by-id link): a device
    path = isinstance(src, (str, os.PathLike))
    device = _camera_device(os.fspath(src) if isinstance(src, os.PathLike) else src) is not None
    # a capture of the caller's was open already, and may be a camera's or a stream's
    given = not device and not path
    why = (
        "a wedged camera or driver, or a stalled stream"
        if given
        else "a wedged camera or driver"
        if device
        else "a stalled stream or network share"
    )
    todo = (
        "give it a longer timeout, or unplug and replug the camera"
        if given
        else "unplug and replug it, or give it a longer timeout"
        if device
        else "give it a longer timeout"
    )
    verb = "was not set up" if given else "did not open"
    try:
        return _within(
            opened,
            timeout,
            what,
            hung=lambda: (
                f"{what} {verb} within {timeout:g} s ({doing[0]} did not return: {why}); {todo}"
            ),
            side=side,
        )
    except BaseException:  # given up, interrupted, or the open failed
        with lock:
            given_up[0] = True
            gone, made[:] = made[:], []
        _release(gone)
        raise


def _sequence_parts(path: str) -> tuple[str, str, str] | None:
    """An image-sequence pattern's text before its number, the number's printf format and the
    text after it, each ``%%`` read as the ``%`` it stands for (``take_50%%_%03d.png`` ->
    ``("take_50%_", "%03d", ".png")``); None when ``path`` holds no number format."""
    for m in _SEQ_TOKEN_RE.finditer(path):
        if m.group(0) != "%%":  # "%%" is a literal percent sign, never a frame number
            head, tail = path[: m.start()], path[m.end() :]
            return head.replace("%%", "%"), m.group(0), tail.replace("%%", "%")
    return None


def _sequence_name(path: str, number: int) -> str:
    """The file of image-sequence pattern ``path`` numbered ``number`` (``path`` holds a
    number format: :func:`_sequence_parts`)."""
    parts = _sequence_parts(path)
    assert parts is not None
    return parts[0] + parts[1] % number + parts[2]


def _sequence_digits(path: str) -> list[str]:
    """The digits in the number's place of every file named as image-sequence pattern ``path``
    around its number (``007``, ``0012`` for ``left_%03d.png``; ``  7`` for ``left_%3d.png``),
    whatever their width. Every file of its folder is looked at: a sequence's start and the
    images after a gap may be anywhere in the file system's listing order."""
    parts = _sequence_parts(path)
    if parts is None:
        return []
    head, _, tail = parts
    names: Iterable[str] = glob.iglob(_sequence_glob(path) or "")
    if os.sep not in tail and (os.altsep is None or os.altsep not in tail):
        # the number in the file's name: sliced from it alone, glob giving "dir//l_007.png"
        # as "dir/l_007.png" (a number a character short, "07": a start from 7 did not open)
        head, names = os.path.basename(head), (os.path.basename(name) for name in names)
    else:
        # the number in a folder's name: glob gives "dir//run*/x.png" as "dir/run7/x.png"
        # too, a folder from 7 did not open; each run of separators read as one, both sides
        head, tail = _one_separator(head), _one_separator(tail)
        names = (_one_separator(name) for name in names)
    found = (name[len(head) : len(name) - len(tail)] for name in names)
    # printf's "%3d" pads with spaces (left_  7.png), as CAP_IMAGES names them
    return [digits for digits in found if digits.lstrip(" ").isdecimal()]


def _one_separator(path: str) -> str:
    """``path`` with each run of path separators as one (``dir//run7`` -> ``dir/run7``)."""
    seps = re.escape(os.sep + (os.altsep or ""))
    return re.sub(f"[{seps}]+", lambda _: os.sep, path)


def _sequence_numbers(path: str) -> list[int]:
    """The numbers of the files that image-sequence pattern ``path`` names, sorted."""
    parts = _sequence_parts(path)
    if parts is None:
        return []
    # as the pattern prints it: left_%03d.png names left_007.png, not left_0007.png
    return sorted(int(d) for d in _sequence_digits(path) if parts[1] % int(d) == d)


def _sequence_first(path: str, digits: list[str] | None = None) -> tuple[int, str] | None:
    """The first file of an image-sequence pattern and its number: the lowest number of the
    files it names (FFmpeg's image2 and OpenCV's own reader look at 0-4 alone, so a sequence
    starting at 5 or later did not open); None when ``path`` is no pattern or names no file.
    ``digits`` is :func:`_sequence_digits` of ``path`` when the caller has listed the folder
    already (a listing of 200,000 files takes a fifth of a second)."""
    parts = _sequence_parts(path)
    if "://" in path or parts is None or os.path.exists(path):
        return None
    for i in range(5):  # the usual starts, without a listing of the folder
        name = _sequence_name(path, i)
        if os.path.exists(name):
            return i, name
    # a first number wider than the pattern pads to is no start (left_%03d.png for left_0001.png
    # ... left_10000.png: its files are a %04d run, and left_10000.png alone is no sequence)
    fmt = parts[1]
    width = int(fmt[1:-1] or 0)
    digits = _sequence_digits(path) if digits is None else digits
    numbers = sorted(int(d) for d in digits if fmt % int(d) == d and (not width or len(d) == width))
    if not numbers:
        return None
    # nor is a number after a file of the run the pattern does not print: left_%d.png over
    # left_01.png ... left_150.png prints 10-150 as named, and opened there (left_01-09 left
    # out); such a pattern is told the files' own (_pattern_hint)
    if any(int(d) < numbers[0] and fmt % int(d) != d for d in digits):
        return None
    return numbers[0], _sequence_name(path, numbers[0])


def _sequence_gap(path: str, read: int, first: int | None = None) -> tuple[str, int] | None:
    """For an image-sequence pattern read to its end after ``read`` images: the file that
    stopped it (the next number, missing; from its pattern's folder, ``run3/x.png`` for
    ``run%d/x.png``) and how many files numbered after it exist; None
    when no file is numbered after it (the sequence's real end) or ``path`` is no pattern.
    ``first``: the number the sequence opened at (else looked up now, as
    :func:`_sequence_first`), which an image copied in or moved away since would change."""
    parts = _sequence_parts(path)
    if parts is None:
        return None
    digits = _sequence_digits(path)  # one listing of the folder for the start and the rest
    if first is None:
        found = _sequence_first(path, digits)
        if found is None:
            return None
        first = found[0]
    number = first + read
    # as the pattern prints them (_sequence_numbers)
    later = sum(1 for d in digits if parts[1] % int(d) == d and int(d) > number)
    # named from the number's folder or file on: of "run%d/x.png" the basename was "x.png",
    # every image's name, and its "does not read" looked for it in the pattern's folder
    name = os.path.basename(parts[0]) + parts[1] % number + parts[2]
    return (name, later) if later else None


#: A numbered file: its name before the number, the number, the extension (``left_``,
#: ``0001``, ``.png``).
_NUMBERED_RE = re.compile(r"^(.*?)(\d+)(\.[A-Za-z0-9]+)$")
#: Files :func:`_forms_that_work` looks at in a folder at most (a listing stays cheap).
_HINT_MAX_FILES = 20000


def _merge_space_padded(runs: dict[tuple[str, str], list[str]]) -> set[tuple[str, str]]:
    """Merge, in place, the runs of ``runs`` (``(head, ext)``: numbers) that are one
    space-padded numbering, as printf's and ``CAP_IMAGES``'s ``%3d`` names them (``sp_  7.png``,
    ``sp_ 10.png``, ``sp_100.png``: heads ``"sp_  "``, ``"sp_ "``, ``"sp_"``); each merged run's
    numbers keep their spaces (``"  7"``), a number padded otherwise (``sp_007.png``) left in
    its own run. The keys of the runs merged."""
    groups: dict[tuple[str, str], list[tuple[str, str]]] = {}
    for head, ext in runs:
        groups.setdefault((head.rstrip(" "), ext), []).append((head, ext))
    spaced: set[tuple[str, str]] = set()
    for key, heads in groups.items():
        # one head alone is no padding: "frame 1.png ... frame 12.png" is "frame %d.png"
        if len(heads) < 2 or not any(head.endswith(" ") for head, _ in heads):
            continue
        # each number as padded, by its width: one stray name (sp_007.png beside sp_  7.png
        # ... sp_ 12.png, a12.png beside a 10.png) left the whole group out, and the hint named
        # a part of it ("sp_ %02d.png", which opens nothing)
        widths: dict[int, list[tuple[tuple[str, str], str]]] = {}
        for run in heads:
            for d in runs[run]:
                p = run[0][len(key[0]) :] + d
                if f"{int(p):{len(p)}d}" == p:
                    widths.setdefault(len(p), []).append((run, d))
        taken = max(widths.values(), key=len, default=[])
        if len({run for run, _ in taken}) < 2:
            continue
        chosen = set(taken)
        left = {run: [d for d in runs[run] if (run, d) not in chosen] for run in heads}
        # the unpadded run's other numbers keep its key when more (the hint names the largest
        # run alone); nor is a run merged after a number left out, as its pattern would not
        # open (_sequence_first: q 5.png before q  7.png ... is no start of "q%3d.png")
        lowest = min(int(d) for _, d in taken)
        if len(left.get(key, [])) >= len(taken) or any(
            int(d) < lowest for numbers in left.values() for d in numbers
        ):
            continue
        for run in heads:
            if left[run]:
                runs[run] = left[run]
            else:
                del runs[run]
        runs[key] = [run[0][len(key[0]) :] + d for run, d in taken]
        spaced.add(key)
    return spaced


def _forms_that_work(side: str, folder: str, names: Iterable[str]) -> tuple[str, str] | None:
    """What ``--left``/``--right`` could name among ``names``, files of ``folder`` as typed:
    the image-sequence pattern of the largest numbered run (one named after ``side`` first)
    and the words for it (``"pattern such as DIR/left_%04d.png (its files are named
    left_0001.png ...)"``), else a video file (one named after ``side`` first); None when
    neither is there."""
    from stereovision.batch import IMAGE_EXTS
    from stereovision.io import _VIDEO_SUFFIXES

    runs: dict[tuple[str, str], list[str]] = {}
    videos: list[str] = []
    for name in names:
        if name.startswith("."):
            continue
        ext = os.path.splitext(name)[1].lower()
        m = _NUMBERED_RE.match(name)
        if m is not None and ext in IMAGE_EXTS:
            runs.setdefault((m.group(1), m.group(3)), []).append(m.group(2))
        elif ext in _VIDEO_SUFFIXES:
            videos.append(name)

    def ours(name: str) -> bool:  # named after this side ("left_", "Left", "cam_left")
        return side in name.lower()

    # a space-padded run was taken for one run a width (sp_ 10.png ...: "sp_ %02d.png", which
    # opens nothing) and the rest left out
    spaced = _merge_space_padded(runs)
    if runs:
        (head, ext), digits = max(runs.items(), key=lambda r: (ours(r[0][0]), len(r[1])))
        digits.sort(key=int)
        # the narrowest number's width, when every wider one prints alike at it (%04d prints
        # 10000 as is; %d would name left_1.png for left_0001.png ...): else unpadded, %d
        width = min(len(d) for d in digits)
        if any(len(d) > width and d.startswith("0") for d in digits):
            width = 0
        # a percent sign in a name is "%%" in its pattern (printf's, OpenCV's)
        number = f"%{width}d" if (head, ext) in spaced else f"%0{width}d" if width > 1 else "%d"
        pattern = os.path.join(folder, head.replace("%", "%%") + number + ext)
        shown = ", ".join(f"{head}{d}{ext}" for d in digits[:2])
        more = " ..." if len(digits) > 2 else ""
        return pattern, f"pattern such as {pattern} (its files are named {shown}{more})"
    if videos:
        videos.sort(key=lambda v: (not ours(v), v))
        video = os.path.join(folder, videos[0])
        return video, f"video file such as {video}"
    return None


def _listing(folder: str) -> list[str]:
    """The names in ``folder`` (at most :data:`_HINT_MAX_FILES`; none when unreadable)."""
    try:
        with os.scandir(folder or ".") as it:
            return [e.name for _, e in zip(range(_HINT_MAX_FILES), it, strict=False)]
    except OSError:
        return []


def _anything_hint(side: str, folder: str) -> str:
    return (
        "a video file, an image-sequence pattern such as "
        f"{os.path.join(folder, side + '_%04d.png')} or a camera index"
    )


def _folder_hint(side: str, path: str) -> str:
    """The one line for a folder given as a source, naming what would work in it."""
    names = _listing(path)
    if "metadata.yaml" in names or any(n.endswith((".db3", ".mcap")) for n in names):
        return f"{side} source {path} is a folder holding a ROS 2 bag: read it with --from-bag"
    form = _forms_that_work(side, path, names)
    return f"{side} source {path} is a folder: give " + (
        f"a {form[1]}" if form else _anything_hint(side, path)
    )


def _glob_hint(side: str, path: str) -> str:
    """The one line for a shell glob given as a source (OpenCV expands none), naming the
    pattern of the files it matches."""
    folder = os.path.dirname(path)
    matched = glob.glob(path)[:_HINT_MAX_FILES]
    said = f"{side} source {path} is a glob, which OpenCV does not expand"
    if len(matched) == 1 and os.path.isfile(matched[0]):  # one file: it is the source
        return f"{said}: give the file it matches, {matched[0]}"
    if re.search(r"[*?[]", folder):
        # a wildcard in a folder part ('runs/run*/x.png'): the hint named a pattern in the
        # folder as typed ('runs/run*/left_%04d.png', which opens nothing); a sequence's
        # pattern is one folder's, so the folders matched are what to choose from
        folders = sorted({os.path.dirname(m) for m in matched if os.path.isfile(m)})
        if not folders:
            return (
                f"{said} (it matches no file): give a video file, an image-sequence pattern in "
                f"one folder (no wildcard in it; the number as %04d: {side}_%04d.png) or a "
                "camera index"
            )
        if len(folders) > 1:
            shown = ", ".join(folders[:2]) + (" ..." if len(folders) > 2 else "")
            inside = [os.path.basename(m) for m in matched if os.path.dirname(m) == folders[0]]
            form = _forms_that_work(side, folders[0], inside)
            one = f"a {form[1]}" if form else _anything_hint(side, folders[0])
            return (
                f"{said}: it matches files in {len(folders)} folders ({shown}) and a source is "
                f"one folder's: give e.g. {one}"
            )
        folder = folders[0]
    names = [os.path.basename(m) for m in matched if os.path.dirname(m) == folder]
    form = _forms_that_work(side, folder, names)
    if form is not None:
        return f"{said}: give a {form[1]}"
    none = "" if matched else " (it matches no file)"
    return f"{said}{none}: give {_anything_hint(side, folder)}"


def _pattern_hint(side: str, path: str, matched: list[str] | None = None) -> str | None:
    """For an image-sequence pattern that names no file while files of another numbering are
    there (``left_%03d.png`` for ``left_0001.png ...``): the one line naming the pattern they
    need; None when they need this one (or none is there). ``matched``: the files of
    :func:`_sequence_glob` when the caller has listed them already."""
    folder = os.path.dirname(path)
    matching = _sequence_glob(path)
    if matching is None:
        return None
    if matched is None:
        matched = list(itertools.islice(glob.iglob(matching), _HINT_MAX_FILES))
    names = [os.path.basename(m) for m in matched[:_HINT_MAX_FILES]]
    form = _forms_that_work(side, folder, names)
    if form is None or form[0] == path:
        return None
    return f"{side} source: no file fits {path}; give a {form[1]}"


def _sequence_glob(path: str) -> str | None:
    """The glob of the files image-sequence pattern ``path`` may name, whatever their number's
    width (``left_*.png`` for ``left_%03d.png``); None when ``path`` is no pattern."""
    parts = _sequence_parts(path)
    return None if parts is None else glob.escape(parts[0]) + "*" + glob.escape(parts[2])


class _ImageSequence:
    """The numbered images of a pattern read in turn from the first one there, a
    ``cv2.VideoCapture`` stand-in for the sequences OpenCV's reader cannot open: one that
    starts at 5 or later (``CAP_IMAGES`` and FFmpeg look at 0-4), one at 2-4 whose name holds
    other digits before the number (``CAP_IMAGES`` opened by its first file took those for
    it), or a pattern ``CAP_IMAGES`` refuses: a literal percent sign (``%%``, a folder
    ``100%``) or a number 10 or more digits wide (``%010d``). Frames
    are read as ``CAP_IMAGES`` reads them (``cv2.IMREAD_UNCHANGED``, each at its own size);
    the sequence is the run of consecutive numbers from the first, and ends at a missing one
    (its backend is said as ``CV_IMAGES``: the end and a gap are told as for OpenCV's).

    ``get`` and ``set`` answer as ``CAP_IMAGES``'s do (OpenCV 5.1, side by side in
    tests/test_capture.py): ``CAP_PROP_FRAME_COUNT`` is the run of files from the first that
    OpenCV has a reader for (``cv2.haveImageReader``: a gap, or a file that is no image, ends
    it, as the reading ends there); ``CAP_PROP_POS_AVI_RATIO`` is the position over the last
    frame's (``POS_FRAMES / (FRAME_COUNT - 1)``), and a seek to a ratio goes to that frame;
    the width and height are the last frame read's (the first's before any). Where OpenCV's
    answer is no answer, ours differs: a seek by ``CAP_PROP_POS_MSEC`` is refused (False),
    as an image has no media time (``get`` says -1), where ``CAP_IMAGES`` took the
    milliseconds for a frame number (2 ms went to frame 2, 2000 ms to the last); a NaN seek
    is refused where ``CAP_IMAGES`` took it for frame 2**31 - 1 and read nothing more; the
    ratio stays within 0-1 where ``CAP_IMAGES`` said 1.2 once the last of 6 frames was read
    (and NaN or inf for one image); after the end the size stays the last frame's, where
    ``CAP_IMAGES`` says 0x0."""

    def __init__(self, path: str, first: int) -> None:
        self._path, self._first, self._next = path, first, 0
        self._frame: np.ndarray | None = None
        self._count = 0
        # as CAP_IMAGES counts: a file present that no codec reads (a stray text file in the
        # numbering) was counted, so the count promised frames the reading never gave. The
        # file's presence first: haveImageReader of a missing one logs OpenCV's "can't
        # open/read file" warning, on stderr at every open
        while os.path.exists(name := _sequence_name(path, first + self._count)) and (
            cv2.haveImageReader(name)
        ):
            self._count += 1
        probe = cv2.imread(_sequence_name(path, first), cv2.IMREAD_UNCHANGED)
        self._size = (0, 0) if probe is None else (probe.shape[1], probe.shape[0])
        self._open = probe is not None

    def isOpened(self) -> bool:
        return self._open

    def getBackendName(self) -> str:
        return "CV_IMAGES"

    def grab(self) -> bool:
        self._frame = None
        if not self._open:
            return False
        name = _sequence_name(self._path, self._first + self._next)
        frame = cv2.imread(name, cv2.IMREAD_UNCHANGED)
        if frame is None:
            return False
        self._frame = frame
        self._size = (frame.shape[1], frame.shape[0])  # each frame at its own size
        self._next += 1
        return True

    def retrieve(self) -> tuple[bool, np.ndarray | None]:
        return self._frame is not None, self._frame

    def read(self) -> tuple[bool, np.ndarray | None]:
        return self.retrieve() if self.grab() else (False, None)

    def get(self, prop: int) -> float:
        values = {
            cv2.CAP_PROP_FRAME_WIDTH: self._size[0],
            cv2.CAP_PROP_FRAME_HEIGHT: self._size[1],
            cv2.CAP_PROP_FRAME_COUNT: self._count,
            cv2.CAP_PROP_POS_FRAMES: self._next,
            cv2.CAP_PROP_POS_MSEC: -1,  # no media time, as CAP_IMAGES says
            cv2.CAP_PROP_FPS: -1,
            # CAP_IMAGES's ratio (the inverse of its seek), kept within 0-1 (see the class)
            cv2.CAP_PROP_POS_AVI_RATIO: min(self._next / max(self._count - 1, 1), 1.0),
        }
        return float(values.get(prop, 0))

    def set(self, prop: int, value: float) -> bool:
        # CAP_IMAGES seeks by frame or by ratio (the position kept within the images counted
        # at the open, as its own) and refuses every other setting: a file cannot be asked a
        # size or a rate. A NaN position is refused: round() raised ValueError where cv2's
        # set() never raises. POS_MSEC is refused: see the class
        seeks = (cv2.CAP_PROP_POS_FRAMES, cv2.CAP_PROP_POS_AVI_RATIO)
        if prop not in seeks or not self._count or math.isnan(value):
            return False
        if prop == cv2.CAP_PROP_POS_AVI_RATIO:
            value = min(max(value, 0.0), 1.0) * (self._count - 1)
        # round() as OpenCV's cvRound: half to even (2.5 goes to frame 2 in both)
        self._next = round(min(max(value, 0), self._count - 1))
        return True

    def release(self) -> None:
        self._open, self._frame = False, None


def _refuse_non_utf8(path: str, what: str) -> None:
    """Raise :class:`SourceError` for a ``path`` that is not UTF-8 text: a file or folder name
    with a byte of another encoding (a Latin-1 ``\xff``, which :func:`os.fsdecode` gives as the
    lone surrogate ``\udcff``) crashed the process in OpenCV's conversion of the argument
    (``cv2.VideoCapture``, ``cv2.imread``: SIGSEGV, exit 139, not a word). ``what`` names the
    source (``left source``)."""
    try:
        path.encode("utf-8")
    except UnicodeEncodeError:
        raise SourceError(
            f"cannot open {what} {_describe_source(path)}: its name holds a byte that is not "
            "UTF-8, which OpenCV cannot take; rename it, or give a link to it with a UTF-8 name",
            side=what.split()[0] if what.split()[0] in ("left", "right") else None,
            end=False,
        ) from None


def _open_path(path: str, first: tuple[int, str] | None) -> Any:
    """``cv2.VideoCapture`` of a file, a URL or an image-sequence pattern (``first``: its
    :func:`_sequence_first`).

    A pattern is opened with OpenCV's own image reader (``CAP_IMAGES``): FFmpeg's, the default,
    rescales a frame of another size to the first frame's before anyone sees it (a 300x300
    frame in a 384x288 sequence came out stretched to 384x288), while ``CAP_IMAGES`` gives
    every frame at its own size, so that :class:`StereoCamera`'s size and shape rules apply.
    ``CAP_IMAGES`` starts a pattern at number 0 or 1 and refuses any ``%`` besides the number's
    (a literal ``%%``, a folder ``100%``): a sequence that starts later, or names a percent
    sign, is read by :class:`_ImageSequence` the same way.
    The default backend remains for what neither reader opens. A name that is not UTF-8
    is refused (:func:`_refuse_non_utf8`).
    """
    _refuse_non_utf8(path, "source")
    # any other "%" (a literal "%%", or a lone one as in a folder "100%") CAP_IMAGES refuses:
    # it takes the path's first "%" for the number and allows no second
    if first is not None and (first[0] > 1 or path.count("%") > 1):
        return _ImageSequence(path, first[0])
    if first is not None:
        cap = cv2.VideoCapture(path, cv2.CAP_IMAGES)
        if cap.isOpened():
            return cap
        cap.release()
        # CAP_IMAGES refuses a width of 10 or more (its pattern is 0?[1-9][du]): FFmpeg's
        # opened l_%010d.png, rescaling a frame of another size, its gaps untold
        sequence = _ImageSequence(path, first[0])
        if sequence.isOpened():
            return sequence
    return cv2.VideoCapture(path)


def _damaged_first(path: str, first: int, opened: bool) -> str | None:
    """What is wrong with the first image of sequence ``path`` (numbered ``first``) that neither
    ``CAP_IMAGES`` nor :class:`_ImageSequence` opened; None when it reads.

    FFmpeg's reader, the last resort, opened a sequence whose first PNG was truncated and said
    "ended after 0 of the 4 frames its header announces: the file ended early", of a video;
    one from 5 on was "cannot open" without a word of the file. A first image OpenCV has no
    reader for is said only when nothing opened it: FFmpeg may read a format OpenCV does not
    (TGA)."""
    name = _sequence_name(path, first)
    with _opencv_quiet():
        known = cv2.haveImageReader(name)
        if (opened and not known) or cv2.imread(name, cv2.IMREAD_UNCHANGED) is not None:
            return None
    return f"its first image, {os.path.basename(name)}, does not read (damaged?)"


def camera_hint(src: object) -> str:
    """Why a camera index may not open, where Linux can tell (V4L2 device nodes)."""
    if not isinstance(src, (int, np.integer)) or not os.path.isdir("/dev"):
        return ""
    node = f"/dev/video{int(src)}"
    if not os.path.exists(node):
        return f" (no {node}: is the camera plugged in?)"
    if not os.access(node, os.R_OK | os.W_OK):
        return f" ({node} is not readable: is this user in the 'video' group?)"
    return f" ({node} exists: is another program using it?)"


#: :class:`SkewStats` keeps this many of the latest skews one by one.
SKEW_WINDOW = 1024
#: Beyond :data:`SKEW_WINDOW` pairs the median comes from a histogram of bins this wide in
#: log(ms) (1 %: the median within 0.5 %), from :data:`_SKEW_FLOOR_MS` up; about 230 bins a
#: decade of skews at most.
_SKEW_BIN = math.log(1.01)
_SKEW_FLOOR_MS = 1e-4


class SkewStats(Sequence[float]):
    """The grab skews of a pair source in bounded memory (a long stream read for days kept
    every one before).

    As a sequence it holds the latest :data:`SKEW_WINDOW` skews (all of them for a shorter run,
    so it reads as the list it replaces); :attr:`n`, :attr:`mean_ms`, :attr:`max_ms` and
    :meth:`median_ms` cover every skew appended, the median exactly up to :data:`SKEW_WINDOW`
    and within 0.5 % beyond (a histogram of 1 % bins).
    """

    def __init__(self, window: int = SKEW_WINDOW) -> None:
        self.recent: deque[float] = deque(maxlen=window)
        self.n = 0
        self._sum = 0.0
        self.max_ms = math.nan
        self._bins: dict[int, int] = {}

    def append(self, skew_ms: float) -> None:
        """Add one pair's skew."""
        x = float(skew_ms)
        self.recent.append(x)
        self.n += 1
        self._sum += x
        self.max_ms = x if self.n == 1 else max(self.max_ms, x)
        k = math.floor(math.log(x / _SKEW_FLOOR_MS) / _SKEW_BIN) if x > _SKEW_FLOOR_MS else -1
        self._bins[k] = self._bins.get(k, 0) + 1

    @property
    def mean_ms(self) -> float:
        """Mean of every skew appended (NaN for none)."""
        return self._sum / self.n if self.n else math.nan

    def median_ms(self) -> float:
        """Median of every skew appended.

        Returns
        -------
        float
            Milliseconds (NaN for none): exact over the recent window, else from the
            logarithmic histogram of every skew.
        """
        if self.n == 0:
            return math.nan
        if self.n <= (self.recent.maxlen or 0):
            return float(statistics.median(self.recent))
        ranks = [(self.n - 1) // 2, self.n // 2]
        values: list[float] = []
        seen = 0
        for k in sorted(self._bins):
            seen += self._bins[k]
            while ranks and ranks[0] < seen:
                ranks.pop(0)
                values.append(0.0 if k < 0 else _SKEW_FLOOR_MS * math.exp((k + 0.5) * _SKEW_BIN))
        return float(statistics.fmean(values))

    def report(self) -> dict[str, float]:
        """Summary of every skew appended.

        Returns
        -------
        dict of str to float
            ``n``, ``mean_ms``, ``median_ms``, ``max_ms`` (milliseconds; NaN for none).
        """
        return {
            "n": self.n,
            "mean_ms": self.mean_ms,
            "median_ms": self.median_ms(),
            "max_ms": self.max_ms,
        }

    def __len__(self) -> int:
        return len(self.recent)

    @overload
    def __getitem__(self, i: int) -> float: ...

    @overload
    def __getitem__(self, i: slice) -> list[float]: ...

    def __getitem__(self, i: int | slice) -> float | list[float]:
        return list(self.recent)[i] if isinstance(i, slice) else self.recent[i]

    def __iter__(self) -> Iterator[float]:
        return iter(self.recent)

    def __repr__(self) -> str:
        return f"SkewStats(n={self.n}, latest {len(self.recent)})"


def _rate_words(fps: float) -> str:
    """A source's frame rate in words: ``30 fps``, or ``no frame rate given`` for OpenCV's 0,
    a rate it does not know (an image sequence, some webcams and containers): "0 fps" read as
    a source delivering nothing."""
    return f"{fps:.3g} fps" if fps > 0 else "no frame rate given"


class PairSource:
    """What every pair source shares (:class:`StereoCamera`,
    :class:`~stereovision.rosbag.BagCamera`): iteration until the end, the skew report, ``with``.
    A subclass provides :meth:`read`, :meth:`close` and ``skews_ms`` (a :class:`SkewStats`,
    or a list of every skew)."""

    skews_ms: SkewStats | list[float]
    delivered_size: dict[str, tuple[int, int]]
    delivered_fps: dict[str, float]

    def _delivered(
        self, names: dict[str, str], sizes: dict[str, tuple[int, int]] | None = None
    ) -> str:
        """``left NAME: WxH @ F fps; right ...``: what each side delivered (``sizes``, by
        default :attr:`delivered_size`). A size not known is left out (it was said "?")."""
        sizes = self.delivered_size if sizes is None else sizes
        parts = []
        for side in ("left", "right"):
            d = sizes.get(side)
            fps = self.delivered_fps.get(side, 0.0)
            if d:
                rate = f"@ {fps:.3g} fps" if fps > 0 else f"({_rate_words(fps)})"
                parts.append(f"{side} {names[side]}: {d[0]}x{d[1]} {rate}")
            else:
                parts.append(f"{side} {names[side]}: {_rate_words(fps)}")
        return "; ".join(parts)

    def read(self) -> StereoFrame:
        """The next pair.

        Returns
        -------
        StereoFrame
            The left and right frames with their timestamps.

        Raises
        ------
        SourceError
            At the end of the source (``end`` True), or for a frame that cannot be used.
        """
        raise NotImplementedError

    def close(self) -> None:
        """Release the source (idempotent)."""
        raise NotImplementedError

    def frames(self, *, stop_at_end: bool = True) -> Iterator[StereoFrame]:
        """Iterate over pairs; the end of a source ends the iteration when ``stop_at_end``
        (another :class:`SourceError`, such as a frame of another shape, is raised).

        Parameters
        ----------
        stop_at_end : bool
            End the iteration at the source's end (else its :class:`SourceError` is raised).

        Yields
        ------
        StereoFrame
            Each pair, as :meth:`read` returns it.
        """
        while True:
            try:
                frame = self.read()
            except SourceError as exc:
                if stop_at_end and exc.end:
                    return
                raise
            yield frame

    def skew_report(self) -> dict[str, float]:
        """Skew between the left and right grabs over the pairs read.

        Returns
        -------
        dict of str to float
            ``n`` (pairs), ``mean_ms``, ``median_ms``, ``max_ms`` (NaN without pairs).
        """
        s = self.skews_ms
        if isinstance(s, SkewStats):
            return s.report()
        if not s:
            return {"n": 0, "mean_ms": math.nan, "median_ms": math.nan, "max_ms": math.nan}
        return {
            "n": len(s),
            "mean_ms": float(statistics.fmean(s)),
            "median_ms": float(statistics.median(s)),
            "max_ms": float(max(s)),
        }

    def __enter__(self) -> PairSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _paired_in_order_note(camera: Any) -> str | None:
    """What :class:`StereoCamera` warns of at its open when its two image sequences start at
    different numbers (they are paired in order, not by number), None otherwise (or for a
    source that is no StereoCamera): for a caller that says it elsewhere (the GUI's page).

    Pairs are read in order: left_0001.png deleted (blurred) paired every left image with the
    right one before its own, without a word until the end.
    """
    starts = getattr(camera, "_sequence_start", None) or {}
    if len(starts) != 2 or starts["left"] == starts["right"]:
        return None
    first = {
        side: os.path.basename(_sequence_name(os.fspath(src), starts[side]))
        for side, src in camera.sources.items()
        if isinstance(src, (str, os.PathLike))  # a sequence is a path
    }
    return (
        f"the left sequence starts at {first['left']}, the right one at "
        f"{first['right']}: images are paired in order ({first['left']} with "
        f"{first['right']}), not by their numbers; if the numbers name the pairs, "
        "remove the images without a partner (or renumber)"
    )


def _out_of_reach(path: str) -> str | None:
    """Why ``path``, which ``os.path.exists`` says is not there, cannot be reached when it may
    be there (``Permission denied``: a folder on its way, or a link's, this user may not
    enter), else None (it is not there)."""
    try:
        os.stat(path)
    except PermissionError as exc:
        return exc.strerror or "Permission denied"
    except (OSError, ValueError):
        return None
    return None


class StereoCamera(PairSource):
    """Two video sources read as synchronised pairs.

    Parameters
    ----------
    left, right : int, str, os.PathLike or VideoCapture-like
        Device index, video file, image-sequence pattern (``frames/left_%03d.png``, read with
        OpenCV's image reader so that each frame comes at its own size), or an object with the
        ``cv2.VideoCapture`` methods ``isOpened grab retrieve get set release``.
    image_size : tuple of int or str, optional
        Requested ``(width, height)`` (or ``"WxH"``), asked of the sources with
        ``CAP_PROP_FRAME_WIDTH`` / ``CAP_PROP_FRAME_HEIGHT``. Frames that come in another size
        (a file cannot be asked) are resized to it, with one :class:`UserWarning` per camera;
        frames of another shape (4:3
        for 16:9) are kept at their own size instead, as a resize would stretch them, and a
        right source whose shape differs from the left's raises :class:`SourceError`. Default:
        the left source's size. The keyword ``size=``, its former name, still works, with a
        DeprecationWarning (the attribute stays :attr:`size`).
    fps : float, optional
        Requested frame rate (``CAP_PROP_FPS``); what the source reports is in
        :attr:`delivered_fps`. A camera or stream that reports another rate (more than 1 %
        off; 0 is none reported) gets one :class:`UserWarning`; a file, or an ``http(s)://``
        URL (which may name one), is read as it is. Without it, two cameras that report other
        rates (30 and 15 fps) get one: a pair waits for the slower one while the faster one's
        frames queue, so its two frames may be a frame or more apart.
    fourcc : str, optional
        Pixel format asked of the sources before the size and rate (``CAP_PROP_FOURCC``; with
        V4L2 the format decides which sizes and rates a webcam offers): ``"YUYV"`` for
        uncompressed frames, ``"MJPG"`` for the compressed stream that lets two webcams share
        one USB bus at a higher size or rate. JPEG costs the matchers some accuracy
        (docs/robotics.md, "Webcams: compressed or raw"). A source that delivers another
        format gets one :class:`UserWarning`; what each delivers is in :attr:`delivered_fourcc`.
    open_timeout : float or None
        Seconds each source's open, with the format, size and rate asked of it and read back
        (``set``/``get``), may take (:data:`DEFAULT_READ_TIMEOUT`, 10; None: no limit): a
        wedged V4L2 device can keep OpenCV's open, or a setting, from ever returning. Given
        up, it raises :class:`SourceError` naming the source, the seconds and the step
        (``left source camera 0 did not open within 10 s (setting its frame width to 640 did
        not return ...``); a capture that opens or ends its settings later is released then.

    Attributes
    ----------
    size : tuple of int
        Output size of both frames (known after the first pair when not requested).
    delivered_size : dict of str to tuple of int
        What each source actually delivered (``{"left": (w, h), "right": (w, h)}``), updated
        from the frames themselves.
    delivered_fps : dict of str to float
        ``CAP_PROP_FPS`` of each source after the request (0 when unknown).
    delivered_fourcc : dict of str to str
        ``CAP_PROP_FOURCC`` of each source after the request, as four characters (``""`` when
        the source reports none; a video file reports its codec).
    skews_ms : SkewStats
        Grab skews: the latest :data:`SKEW_WINDOW` as a sequence of float (every one for a
        shorter run), the count, mean, median and maximum over every pair read
        (:meth:`skew_report`), in bounded memory.

    Raises
    ------
    FileNotFoundError
        If a source is a file path (not a pattern) that does not exist.
    SourceError
        If a source cannot be opened, OpenCV raises on its open or on a setting asked of it
        (``cv2.error``, chained), or it does not open within ``open_timeout`` (the message
        names it, and the step).
    ValueError
        If ``image_size``, ``fps``, ``fourcc`` or ``open_timeout`` is invalid, or a source is a
        negative device index.
    """

    @renamed_keyword("size", "image_size")
    def __init__(
        self,
        left: Source,
        right: Source,
        *,
        image_size: tuple[int, int] | str | None = None,
        fps: float | None = None,
        fourcc: str | None = None,
        open_timeout: float | None = DEFAULT_READ_TIMEOUT,
    ) -> None:
        check_read_timeout(open_timeout, "open_timeout")
        self.sources = {"left": left, "right": right}
        for side, src in self.sources.items():
            if isinstance(src, bytes):
                # taken for a capture object: "'bytes' object has no attribute 'isOpened'"
                as_path(src, side)
            if not isinstance(src, (str, os.PathLike, int, np.integer, np.bool_)) and not hasattr(
                src, "isOpened"
            ):
                # None (a setting left out) too: "'NoneType' object has no attribute 'isOpened'"
                raise TypeError(
                    f"{side} source: expected a device index, a path or a capture object "
                    f"(cv2.VideoCapture's methods), got {type(src).__name__}"
                )
        self.requested_size = parse_size(image_size, "image_size")
        # True was taken as 1 fps, and "30" gave math's TypeError
        float_sized(fps, "fps")  # 10**400: math.isfinite's OverflowError, naming nothing
        if fps is not None and (
            isinstance(fps, NOT_NUMBERS)  # True was 1 fps, 3 ns 3 fps
            or not isinstance(fps, (int, float, np.integer, np.floating))
            or not (math.isfinite(fps) and fps > 0)
        ):
            raise ValueError(f"fps: expected a positive number, got {fps!r}")
        self.requested_fourcc = parse_fourcc(fourcc)
        self.delivered_fourcc: dict[str, str] = {}
        self.size: tuple[int, int] | None = self.requested_size
        self.delivered_size: dict[str, tuple[int, int]] = {}
        self.delivered_fps: dict[str, float] = {}
        self.skews_ms = SkewStats()
        self.count = 0
        self._warned: set[str] = set()
        self._size_locked = False  # a frame has fixed the output size
        self._caps: dict[str, Any] = {}
        # A grab given up as hung (read_within) may still be inside OpenCV: releasing its
        # capture under it, or grabbing it again, crashed the process (SIGSEGV). The grab that
        # is running, and whether close() left the release to it, under this lock.
        self._grab_lock = threading.Lock()
        self._grabbing = False
        self._release_on_return = False
        #: Sources read by OpenCV's image-sequence reader (it logs a warning at the end).
        self._sequence: dict[str, bool] = {}
        # the number each image sequence opened at: its gap is counted from it at the end,
        # whatever was copied into or moved out of its folder while it was read
        self._sequence_start: dict[str, int] = {}
        self._media_offset: float | None = None  # left - right media time of the first pair
        # which sources are cameras, with no end: devices (an index, /dev/video0, a
        # /dev/v4l/by-id link), known at the open (a by-id link is gone once its camera is
        # unplugged), and live network streams (rtsp://, _live_stream)
        self._device: dict[str, bool] = {}
        # The warnings below are inside too: one made an error (python -W error) left both
        # captures open, the object never returned to be closed.
        try:
            for side, src in self.sources.items():
                self._caps[side] = self._open(side, src, fps, open_timeout)
                path = os.fspath(src) if isinstance(src, os.PathLike) else src
                self._device[side] = _camera_device(path) is not None or _live_stream(path)
            note = _paired_in_order_note(self)
            if note is not None:
                warnings.warn(
                    note,
                    UserWarning,
                    stacklevel=3,  # __init__, renamed_keyword's wrapper, the caller
                )
            rate = self.delivered_fps
            slow, fast = sorted((rate.get("left", 0.0), rate.get("right", 0.0)))
            if (
                fps is None  # a rate asked and not given is said per side (_open)
                and all(map(_rate_askable, self.sources.values()))
                and slow > 0
                and fast - slow > 0.01 * fast
            ):
                # two cameras of other rates (two webcam models): the grab skew said a pair was
                # a fraction of a ms apart while the faster camera's frames waited in its queue
                name = {side: _describe_source(src) for side, src in self.sources.items()}
                warnings.warn(
                    f"left source {name['left']} reports {rate['left']:g} fps, right source "
                    f"{name['right']} {rate['right']:g} fps: each pair waits for the slower "
                    "camera while the faster one's frames queue in its buffer, so a pair's two "
                    "frames may be taken a frame or more apart, which the grab skew does not "
                    f"show; ask both for one rate (fps={slow:g}, --fps {slow:g})",
                    UserWarning,
                    stacklevel=3,  # __init__, renamed_keyword's wrapper, the caller
                )
        except BaseException:
            self.close()
            raise

    def _open(self, side: str, src: Source, fps: float | None, timeout: float | None) -> Any:
        configure = functools.partial(self._configure, side, fps)
        if isinstance(src, (str, os.PathLike)):
            path = os.fspath(src)
            if "\x00" in path:
                # exists() is False of it: "left source not found: a<NUL>b.mp4", the byte raw
                raise ValueError(
                    f"{side} source: expected a path without a null byte, got {path!r}"
                )
            if "%" not in path and "://" not in path and not os.path.exists(path):
                if re.search(r"[*?[]", path):  # "not found" said nothing of the pattern
                    raise FileNotFoundError(_glob_hint(side, path))
                link = os.path.islink(path)
                denied = _out_of_reach(path)
                if denied is not None:
                    # there, behind a folder this user may not enter: "not found" (or a link's
                    # target "which does not exist") sent the user looking for a moved file
                    to = f" (a link to {escaped(os.readlink(path))})" if link else ""
                    raise PermissionError(f"{side} source cannot be read: {path}{to}: {denied}")
                # a link whose target moved (a recording on a disk since unmounted) was "not
                # found" alone, of a name ls lists: its target is named, as io's readers name it
                gone = f" ({_broken_link(Path(path))})" if link else ""
                raise FileNotFoundError(f"{side} source not found: {path}{gone}")
            # before any OpenCV call: such a name crashed the process there
            _refuse_non_utf8(path, f"{side} source")
            if os.path.isdir(path):  # "cannot open" said nothing of what to give instead
                raise SourceError(_folder_hint(side, path), side=side, end=False)
            # looked for once: each look at a late start lists the whole folder (0.2 s for
            # 200,000 files), and a sequence found needs no listing to know it has files
            first = _sequence_first(path)
            # the text around the number matched as written (a folder "run[1]" is no glob)
            pattern = _sequence_glob(path) if "://" not in path and first is None else None
            matched = None if pattern is None else glob.glob(pattern)  # for the hint too
            if matched is not None:
                if not matched:
                    # said here: FFmpeg would print its own line first
                    raise FileNotFoundError(f"{side} source: no file matches {path}")
            exists = os.path.exists(path)  # a file whose name holds "%d" is no pattern
            if "%" in path and "://" not in path and not exists and first is None:
                # files of another numbering: FFmpeg's line, then "cannot open", said neither
                hint = _pattern_hint(side, path, matched)
                if hint is not None:
                    raise FileNotFoundError(hint)
            # OpenCV's log of its backends' attempts stays quiet (_open_within): the error
            # below says what failed
            cap: Any = _open_within(lambda: _open_path(path, first), timeout, side, src, configure)
            self._sequence[side] = cap.isOpened() and cap.getBackendName() == "CV_IMAGES"
            if self._sequence[side] and first is not None:
                self._sequence_start[side] = first[0]
            if first is not None and not self._sequence[side]:
                damaged = _damaged_first(path, first[0], cap.isOpened())
                if damaged is not None:
                    cap.release()
                    raise SourceError(
                        f"cannot open {side} source {_describe_source(src)}: {damaged}",
                        side=side,
                        end=False,
                    )
        elif isinstance(src, (bool, np.bool_)):  # True opened camera 1
            raise ValueError(f"{side} source: expected a device index or a path, got {src!r}")
        elif isinstance(src, (int, np.integer)):
            if src < 0:  # cv2.VideoCapture(-1) crashes the process when no camera is present
                raise ValueError(f"{side} source: {_negative_index(int(src))}")
            cap = _open_within(lambda: cv2.VideoCapture(int(src)), timeout, side, src, configure)
        else:  # a capture of the caller's: its settings bounded as a device's
            cap = _open_within(lambda: src, timeout, side, src, configure)
        if not cap.isOpened():
            cap.release()
            what = f"{_describe_source(src)}{camera_hint(src)}"
            raise SourceError(f"cannot open {side} source {what}")
        got = self.delivered_fourcc[side]
        if self.requested_fourcc is not None and got != self.requested_fourcc:
            try:
                warnings.warn(
                    f"{side} source {_describe_source(src)} delivers "
                    f"{repr(got) if got else 'no reported format'}, not "
                    f"{self.requested_fourcc!r}",
                    UserWarning,
                    stacklevel=4,  # _open, __init__, renamed_keyword's wrapper, the caller
                )
            except BaseException:  # made an error: this capture is not in _caps to close
                cap.release()
                raise
        rate = self.delivered_fps.get(side, 0.0)
        # a camera's or stream's (a file is read as it is): --fps 60 of a webcam that gives 30
        # at that size streamed at 30 without a word; 0 is no rate reported, nothing to compare
        # An http(s) URL may name a video file (as _LIVE_SCHEMES has it): --fps 30 of
        # http://host/clip.mp4 warned "a rate this camera does not give"
        live = _rate_askable(src)
        if fps is not None and live and rate > 0 and abs(rate - fps) > 0.01 * fps:
            try:
                warnings.warn(
                    f"{side} source {_describe_source(src)} reports {rate:g} fps, not the "
                    f"{fps:g} fps asked (a rate this camera does not give at this size and "
                    "format?)",
                    UserWarning,
                    stacklevel=4,  # _open, __init__, renamed_keyword's wrapper, the caller
                )
            except BaseException:  # made an error: this capture is not in _caps to close
                cap.release()
                raise
        return cap

    def _configure(
        self, side: str, fps: float | None, cap: Any, doing: Callable[[str], None]
    ) -> None:
        """Ask ``side``'s just opened ``cap`` for the requested format, size and rate, then
        read back what it delivers: in :func:`_open_within`'s worker, as a wedged device can
        hang a ``set`` or ``get`` as it hangs its open (``doing`` says which, for the
        message). The warnings are the caller's (:meth:`_open`)."""
        if not cap.isOpened():  # said by the caller
            return
        # The format first: V4L2 offers sizes and rates per format.
        if self.requested_fourcc is not None:
            doing(f"setting its pixel format to {self.requested_fourcc!r}")
            cap.set(cv2.CAP_PROP_FOURCC, cv2.VideoWriter.fourcc(*self.requested_fourcc))
        if self.requested_size is not None:
            doing(f"setting its frame width to {self.requested_size[0]}")
            cap.set(cv2.CAP_PROP_FRAME_WIDTH, self.requested_size[0])
            doing(f"setting its frame height to {self.requested_size[1]}")
            cap.set(cv2.CAP_PROP_FRAME_HEIGHT, self.requested_size[1])
        if fps is not None:
            doing(f"setting its frame rate to {fps:g} fps")
            cap.set(cv2.CAP_PROP_FPS, float(fps))
        doing("reading back its settings")
        # CAP_IMAGES says -1 (no rate): 0 for unknown, as other sources say it.
        self.delivered_fps[side] = max(0.0, float(cap.get(cv2.CAP_PROP_FPS) or 0.0))
        w, h = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
        if w > 0 and h > 0:
            self.delivered_size[side] = (w, h)
        self.delivered_fourcc[side] = fourcc_text(cap.get(cv2.CAP_PROP_FOURCC))

    # -- reading

    def _fail(self, side: str, what: str) -> SourceError:
        return SourceError(
            f"{side} source {_describe_source(self.sources[side])} {what} after "
            f"{_pairs(self.count)}",
            side=side,
            end=False,
            frames=self.count,
        )

    def _announced(self, side: str) -> int | None:
        """The frame count a video file or image sequence announces (None for others)."""
        if not isinstance(self.sources[side], (str, os.PathLike)):
            return None  # a camera has none; an object's may mean anything
        try:
            total = float(self._caps[side].get(cv2.CAP_PROP_FRAME_COUNT))
        except Exception:  # a VideoCapture-like without it
            return None
        return int(total) if math.isfinite(total) and total > 0 else None

    def _short(self, side: str) -> int | None:
        """The announced frame count of a source that ended clearly before it (None if not).

        A container without an index estimates its count from its duration (off by a frame
        or so), hence the margin: more than one frame and 1 % short."""
        total = self._announced(side)
        n = self.count
        return total if total is not None and total - n > max(1, total // 100) else None

    def _gap(self, side: str) -> tuple[str, int] | None:
        """:func:`_sequence_gap` of an image-sequence source (None for others)."""
        src = self.sources[side]
        if not self._sequence.get(side) or not isinstance(src, (str, os.PathLike)):
            return None
        return _sequence_gap(os.fspath(src), self.count, self._sequence_start.get(side))

    def _end_phrase(self, side: str) -> str:
        src, n = self.sources[side], self.count
        name = _describe_source(src)
        if self._device.get(side, False) or isinstance(src, (int, np.integer)):
            return f"{side} source {name} stopped delivering frames after {n} (disconnected?)"
        total = self._short(side)
        gap = self._gap(side)
        if gap is not None:
            # a numbered image taken out of a sequence (a blurred frame deleted) ended it there:
            # the images after it were never read, which "ended after 4 frames" did not say
            # one that is there but does not read (damaged) was told "missing" too
            # in the folder as read ("50%% done/f_%03d.png" reads from "50% done")
            parts = _sequence_parts(os.fspath(src))
            folder = os.path.dirname(parts[0]) if parts is not None else ""
            there = os.path.exists(os.path.join(folder, gap[0]))
            why, fix = (
                ("does not read (damaged?)", "replace or remove it")
                if there
                else ("is missing", "renumber them without the gap")
            )
            return (
                f"{side} source {name} ended after {_counted(n, 'image')}: {gap[0]} {why}, so the "
                f"{gap[1]} image{'s' if gap[1] > 1 else ''} numbered after it "
                f"{'were' if gap[1] > 1 else 'was'} not read ({fix})"
            )
        if total is None:
            return f"{side} source {name} ended after {_counted(n, 'frame')}"
        if self._sequence.get(side):
            return (
                f"{side} source {name} ended after {n} of its {total} images: the next one "
                "does not read (damaged?)"
            )
        return (
            f"{side} source {name} ended after {n} of the {total} frames its header announces: "
            f"the file ended early (likely truncated or damaged; its last frame, in pair {n}, "
            "may be incomplete)"
        )

    def _ended(self, ok: dict[str, bool]) -> SourceError:
        """The end of one source or both, said as it is: which one, whether the other still had
        frames, and whether a file ended before the frames its header announces."""
        gone = [side for side in ("left", "right") if not ok[side]]
        short = [t for side in gone if (t := self._short(side)) is not None]
        gaps = [g[0] for side in gone if (g := self._gap(side)) is not None]
        devices = [s for s in gone if self._device.get(s, False)]
        if len(gone) == 2 and not short and not gaps and not devices:
            message = f"both sources ended after {_counted(self.count, 'frame')}"
        elif len(gone) == 2:
            message = "; ".join(self._end_phrase(side) for side in gone)
        else:
            other = "right" if gone[0] == "left" else "left"
            message = f"{self._end_phrase(gone[0])}; the {other} source still had frames"
        return SourceError(
            message,
            side=gone[0] if len(gone) == 1 else "both",
            end=True,
            frames=self.count,
            other_had_frames=len(gone) == 1,
            expected_frames=short[0] if short else None,
            gap=gaps[0] if gaps else None,
        )

    def _fit(self, side: str, frame: np.ndarray) -> np.ndarray:
        if frame.ndim == 2:
            frame = cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR)
        h, w = frame.shape[:2]
        self.delivered_size[side] = (w, h)
        if self.size is None:
            self.size = (w, h)
        if (w, h) == self.size:
            self._size_locked = True
            return frame
        if abs((w / h) / (self.size[0] / self.size[1]) - 1) > 0.01:
            # A resize to another shape would stretch the frames (and every calibration made
            # of them): the first frame's own size is kept instead, and two sources of
            # different shapes are refused.
            if self._size_locked:
                name = _describe_source(self.sources[side])
                if self.count == 0:
                    first = "right" if side == "left" else "left"
                    raise SourceError(
                        f"{side} source {name} delivers {w}x{h}, the {first} source "
                        f"{self.size[0]}x{self.size[1]}: frames of another shape cannot be "
                        "paired without stretching one (ask both for the same size)",
                        side=side,
                        end=False,
                        frames=self.count,
                    )
                raise SourceError(
                    f"{side} source {name} delivers {w}x{h} in pair {self.count + 1}, after "
                    f"{self.count} pairs of {self.size[0]}x{self.size[1]}: a frame of another "
                    "shape cannot be paired without stretching it",
                    side=side,
                    end=False,
                    frames=self.count,
                )
            source_warning(
                f"{side} source {_describe_source(self.sources[side])} delivers {w}x{h}, not "
                f"{self.size[0]}x{self.size[1]}: another shape, so its frames are kept at "
                f"{w}x{h} (a resize would stretch them)",
            )
            # not marked as warned: a later frame resized to this size is said (it was not)
            self.size = (w, h)
            self._size_locked = True
            return frame
        self._size_locked = True
        if side not in self._warned:
            self._warned.add(side)
            source_warning(
                f"{side} source {_describe_source(self.sources[side])} delivers {w}x{h}, not "
                f"{self.size[0]}x{self.size[1]}: its frames are resized",
            )
        return resize_frame(frame, self.size)

    def read(self) -> StereoFrame:
        """Grab both sources, then retrieve both; return the timestamped pair.

        Returns
        -------
        StereoFrame
            The pair (at the requested size, if any), with each grab's time (``t_left``,
            ``t_right``), its index and, for a file, each frame's position in it.

        Raises
        ------
        SourceError
            If a source delivers no frame (device unplugged, end of a file or sequence): the
            message names the source that ended, the frames read, whether the other still had
            frames and whether a file ended before the frames its header announces (attributes
            ``side``, ``frames``, ``other_had_frames``, ``expected_frames``; ``end`` True). A
            frame that does not decode, of another shape, empty or no image (a capture of the
            user's) raises it with ``end`` False.
        """
        timeout = _READ_TIMEOUT.get()
        name = " and ".join(_describe_source(src) for src in self.sources.values())
        with self._grab_lock:  # with close(): a capture released here is not grabbed
            caps = self._caps
            if len(caps) != 2:
                raise SourceError("the stereo camera is closed", end=False)
            if self._grabbing:
                raise SourceError(
                    f"{name}: an earlier read given up as hung has not returned; "
                    "unplug and replug the camera, then open it again",
                    side="both",
                    end=False,
                )
            self._grabbing = True
        claim = ["pending"]  # "entered" by the grab, or "abandoned" by this thread first

        def abandon() -> bool:
            # A grab that never began (its thread not started: "can't start new thread", or
            # Ctrl-C before it) left the camera grabbing for good: every read refused as hung
            # and close() leaving the release to it. One that began ends it itself.
            release = False
            with self._grab_lock:
                if claim[0] == "entered":
                    return False
                if claim[0] == "pending":
                    claim[0] = "abandoned"
                    self._grabbing = False
                    release, self._release_on_return = self._release_on_return, False
            if release:  # closed meanwhile (by another thread)
                _release(caps.values())
            return True

        try:
            ok_l, t_l, ok_r, t_r, got = _within(
                lambda: self._grab(caps, claim), timeout, name, cancel=abandon
            )
        except BaseException:
            abandon()  # also when _within did not ask (no thread started, no interrupt)
            raise
        if not (ok_l and ok_r):
            raise self._ended({"left": ok_l, "right": ok_r})
        frames, delivered = {}, {}
        for side in ("left", "right"):
            ok, img = got[side]
            if not ok or img is None:
                raise self._fail(side, "could not decode a frame")
            # a capture of the user's (a camera SDK's wrapper) that said True: an empty frame
            # (a dropped one) divided by zero in _fit once a pair had fixed the size, and an
            # array that is no image raised IndexError or failed in OpenCV further on
            img = np.asarray(img)
            if img.ndim not in (2, 3) or (img.ndim == 3 and img.shape[2] not in (1, 3, 4)):
                raise self._fail(side, f"delivered a frame of shape {img.shape}, not an image")
            if img.size == 0:
                raise self._fail(side, f"delivered an empty frame ({img.shape[1]}x{img.shape[0]})")
            if img.ndim == 2 or img.shape[2] == 1:
                img = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
            elif img.shape[2] == 4:  # an image sequence's PNGs with alpha: BGR as the rest
                img = cv2.cvtColor(img, cv2.COLOR_BGRA2BGR)
            delivered[side] = img
            frames[side] = self._fit(side, img)
        resized = any(frames[side] is not delivered[side] for side in frames)
        frame = StereoFrame(
            left=frames["left"],
            right=frames["right"],
            t_left=t_l,
            t_right=t_r,
            index=self.count,
            pos_left_ms=_media_ms(caps["left"]),
            pos_right_ms=_media_ms(caps["right"]),
            delivered=(delivered["left"], delivered["right"]) if resized else None,
        )
        self.count += 1
        self.skews_ms.append(frame.skew_ms)
        self._check_media_drift(frame)
        return frame

    def _grab(
        self, caps: dict[str, Any], claim: list[str]
    ) -> tuple[bool, float, bool, float, dict[str, Any]]:
        """Grab both sources, then retrieve both (the native part of :meth:`read`, which
        :func:`read_within` bounds): each grab's success and time, each retrieve's result.
        Not begun (nothing grabbed) when :meth:`read` gave it up before it started."""
        with self._grab_lock:
            if claim[0] == "abandoned":  # read() has ended the grab for it
                return False, 0.0, False, 0.0, {}
            claim[0] = "entered"
        try:
            ok_l = self._grab_one(caps, "left")
            t_l = time.monotonic()
            ok_r = self._grab_one(caps, "right")
            t_r = time.monotonic()
            if not (ok_l and ok_r):
                return ok_l, t_l, ok_r, t_r, {}
            got = {side: self._native(caps, side, "retrieve") for side in ("left", "right")}
            return ok_l, t_l, ok_r, t_r, got
        finally:
            with self._grab_lock:
                self._grabbing = False
                release, self._release_on_return = self._release_on_return, False
            if release:  # closed while this grab hung: released now that it is out of OpenCV
                _release(caps.values())

    def _grab_one(self, caps: dict[str, Any], side: str) -> Any:
        """``side``'s grab (:meth:`_native`), OpenCV's log quiet for an image sequence's alone:
        its reader logs a warning for the file after the last. The level is process-wide: both
        grabs quiet lost the other side's warnings, and every thread's while a camera hung."""
        with _opencv_quiet() if self._sequence.get(side) else contextlib.nullcontext():
            return self._native(caps, side, "grab")

    def _native(self, caps: dict[str, Any], side: str, step: str) -> Any:
        """``caps[side].grab()`` or ``.retrieve()`` (``step``); a ``cv2.error`` it raises (a
        backend failing mid-stream, in its exception mode) is a :class:`SourceError` naming
        the side and the step, with ``end`` False: it came out raw, which the CLI called an
        internal error."""
        try:
            return getattr(caps[side], step)()
        except cv2.error as exc:
            from stereovision.calibration import _first_line

            name = _describe_source(self.sources[side])
            raise SourceError(
                f"{side} source {name} failed in OpenCV's {step} of pair {self.count + 1} "
                f"({_first_line(exc)})",
                side=side,
                end=False,
                frames=self.count,
            ) from exc

    def _video_files(self) -> bool:
        """Both sources are local video files, whose media times are comparable."""
        return all(
            isinstance(src, (str, os.PathLike))
            and "://" not in os.fspath(src)
            and not self._sequence.get(side)
            for side, src in self.sources.items()
        )

    @property
    def media_clock(self) -> bool:
        """Whether the pairs carry their own time: both sources are local video files (no
        camera, URL or image sequence), each frame's ``pos_left_ms`` / ``pos_right_ms`` its time
        in the video (``CAP_PROP_POS_MSEC``). :func:`~stereovision.stream.run_stream` stamps
        such pairs by it, not by the wall clock of their read."""
        return self._video_files() and all(
            _camera_device(src) is None for src in self.sources.values()
        )

    def _check_media_drift(self, frame: StereoFrame) -> None:
        """Warn once when two video files' media times drift apart by more than a frame.

        The grab skew is host time (``time.monotonic``): two files read in turn are always a
        fraction of a millisecond apart, even when one runs at 15 fps and the other at 30 (pair
        49 at 1633 and 3267 ms of media time). The media times (``CAP_PROP_POS_MSEC``) tell:
        their difference, taken from the first pair's (a container may start at another time),
        may move by up to a frame period of the slower source (its frames stand for that long).
        """
        if "media drift" in self._warned or not self._video_files():
            return
        pl, pr = frame.pos_left_ms, frame.pos_right_ms
        if not (math.isfinite(pl) and math.isfinite(pr)):
            return
        if self._media_offset is None:
            self._media_offset = pl - pr
            return
        rates = [f for f in self.delivered_fps.values() if f > 0]
        if not rates:
            return
        period = 1000.0 / min(rates)
        if abs(pl - pr - self._media_offset) <= period:
            return
        self._warned.add("media drift")
        fps = {side: self.delivered_fps.get(side, 0.0) for side in ("left", "right")}
        name = {side: _describe_source(src) for side, src in self.sources.items()}
        source_warning(
            f"left source {name['left']} ({_rate_words(fps['left'])}) and right source "
            f"{name['right']} ({_rate_words(fps['right'])}) drift apart: pair "
            f"{frame.index + 1} is at {pl:.0f} ms of the left video and {pr:.0f} ms of the "
            f"right, more than a frame ({period:.0f} ms) from the first pair's offset; the pairs "
            "are not simultaneous (the grab skew only says when each frame was read)",
        )

    def describe(self) -> str:
        """Requested vs delivered size, fps and pixel format of each source.

        Returns
        -------
        str
            One line for a terminal or a log.
        """
        req = self.requested_size
        asked = f"asked {req[0]}x{req[1]}" if req else "native size"
        if self.requested_fourcc:
            asked += f" {self.requested_fourcc}"
        names = {side: _describe_source(src) for side, src in self.sources.items()}
        out = f"{asked}; " + self._delivered(names)
        formats = [f"{side} {f}" for side, f in self.delivered_fourcc.items() if f]
        return out + (f"; format {', '.join(formats)}" if formats else "")

    def close(self) -> None:
        """Release both sources (idempotent). While a read given up as hung is still inside
        OpenCV, its return releases them instead (a release under it crashed the process)."""
        with self._grab_lock:
            caps, self._caps = self._caps, {}
            if self._grabbing:
                self._release_on_return = True
                return
        _release(caps.values())

    def __enter__(self) -> StereoCamera:
        return self


def _release(caps: Iterable[Any]) -> None:
    """Release each capture, best effort."""
    for cap in caps:
        try:
            cap.release()
        except Exception:  # releasing is best effort
            pass


def resize_frame(frame: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """``frame`` at ``size`` as the pair sources resize their frames: ``INTER_AREA`` to shrink,
    ``INTER_LINEAR`` to enlarge.

    Parameters
    ----------
    frame : numpy.ndarray
        ``(H, W)`` or ``(H, W, 3)`` image.
    size : tuple of int
        ``(width, height)`` in pixels.

    Returns
    -------
    numpy.ndarray
        The resized frame, of ``frame``'s dtype; ``frame`` itself when it is already that size.
    """
    h, w = frame.shape[:2]
    if (w, h) == tuple(size):
        return frame
    interp = cv2.INTER_AREA if w > size[0] else cv2.INTER_LINEAR
    return np.asarray(cv2.resize(frame, tuple(size), interpolation=interp))


def _averaged_before_resize(frame: StereoFrame) -> bool:
    """Whether :func:`temporal_average` averages ``frame`` as delivered: it was enlarged, and
    both sources delivered frames of one shape (the filter's means are of one shape). A frame
    shrunk (``INTER_AREA``) is averaged as shrunk: its noise stays the pixel's own (venus halved:
    0 restarts), and the filter costs the delivered size's time (a 1920x1080 pair 243 ms in the
    grab thread, at 640x360 21 ms)."""
    d = frame.delivered
    return d is not None and d[0].shape == d[1].shape and d[0].shape[1] < frame.left.shape[1]


def _check_8_bit_frames(left: np.ndarray, right: np.ndarray) -> None:
    """Refuse frames that temporal averaging cannot take, naming the source that delivers them
    (``temporal_average``'s check, the GUI's "average" too).

    Raises
    ------
    ValueError
        If a source delivers frames of more than 8 bits (a 16-bit image sequence), which the
        filter does not average.
    """
    for side, img in (("left", left), ("right", right)):
        if img.dtype != np.uint8:
            # the filter's own words named a "left" image the caller never passed: "left:
            # expected a uint8 image, got uint16"
            hint = " (a 16-bit image sequence?)" if img.dtype == np.uint16 else ""
            raise ValueError(
                f"temporal averaging takes 8-bit frames: the {side} source delivers {img.dtype} "
                f"ones{hint}; convert them to 8 bits, or leave the averaging out"
            )


def temporal_average(tf: Any, frame: StereoFrame) -> tuple[np.ndarray, np.ndarray]:
    """``tf(left, right)`` (a :class:`~stereovision.temporal.TemporalFilter`) of a pair, on
    the frames as delivered when the source enlarged them (:attr:`StereoFrame.delivered`), the
    means then enlarged to the pair's size: an enlargement spreads each pixel's noise over its
    neighbours, which the filter's motion test took for motion (every pair of a still rig
    restarted, nothing averaged). Frames the source shrank are averaged as shrunk.

    Parameters
    ----------
    tf : stereovision.temporal.TemporalFilter
        The filter (its running means are updated).
    frame : StereoFrame
        The pair.

    Returns
    -------
    left, right : numpy.ndarray
        The filter's running means (uint8), at the pair's size.

    Raises
    ------
    ValueError
        If a source delivers frames of more than 8 bits (a 16-bit image sequence), which the
        filter does not average.
    """
    _check_8_bit_frames(frame.left, frame.right)
    if not _averaged_before_resize(frame):
        left, right = tf(frame.left, frame.right)
        return left, right
    assert frame.delivered is not None
    size = (frame.left.shape[1], frame.left.shape[0])
    left, right = tf(*frame.delivered)
    return resize_frame(left, size), resize_frame(right, size)


# ---------------------------------------------------------------------------- CLI sources


def add_bag_args(p: argparse.ArgumentParser, what: str, *, skew: bool = True) -> None:
    """``--from-bag BAG`` (``what`` says what it holds) and its topic (and skew) options."""
    p.add_argument("--from-bag", metavar="BAG", help=what)
    p.add_argument("--left-topic", help="--from-bag: left image topic (default: found)")
    p.add_argument("--right-topic", help="--from-bag: right image topic (default: found)")
    if skew:
        from stereovision.cli import skew_ms  # cli builds its parser with it

        p.add_argument(
            "--max-skew-ms",
            type=skew_ms,
            help="--from-bag: largest stamp difference of a pair (default: half a frame period)",
        )


def add_source_args(p: argparse.ArgumentParser) -> None:
    """The pair source options of ``capture`` and ``stream``: two cameras, or a ROS bag."""
    p.add_argument("--left", help="device index, video file or pattern (%%03d)")
    p.add_argument("--right", help="device index, video file or pattern")
    p.add_argument(
        "--fourcc",
        type=fourcc_code,
        help="pixel format asked of the cameras: YUYV (raw) or MJPG (compressed, more size/fps "
        "over USB; costs some accuracy)",
    )
    add_bag_args(p, "read the pairs from a recorded ROS 1 bag or ROS 2 bag folder instead")
    add_read_timeout(p)


def add_read_timeout(p: argparse.ArgumentParser) -> None:
    """``--read-timeout SECONDS`` of the commands that read cameras (``capture``, ``stream``,
    ``gui``); :func:`cli_read_timeout` reads it."""
    from stereovision.cli import read_timeout_seconds  # cli builds its parser with it

    p.add_argument(
        "--read-timeout",
        type=read_timeout_seconds,
        metavar="SECONDS",
        help=f"give a camera up as hung when its open or a pair's read takes longer (default "
        f"{DEFAULT_READ_TIMEOUT:g} s; raise it for a camera slow to deliver its first frame on a "
        "cold start, some GigE and USB3 ones; 'none': no limit)",
    )


def cli_read_timeout(args: argparse.Namespace) -> float | None:
    """The ``read_timeout`` that ``--read-timeout`` (:func:`add_read_timeout`) asks for.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (``--read-timeout``, absent or None when not given).

    Returns
    -------
    float or None
        The seconds given; :data:`DEFAULT_READ_TIMEOUT` when the option is not given; None (no
        limit) for ``none``, which the parser gives as ``math.inf``.
    """
    given = getattr(args, "read_timeout", None)
    if given is None:
        return DEFAULT_READ_TIMEOUT
    return None if math.isinf(given) else float(given)


def _same_path(left: object, right: object) -> bool:
    """Whether two file, pattern or URL sources name the same thing."""
    if not (isinstance(left, (str, os.PathLike)) and isinstance(right, (str, os.PathLike))):
        return False
    a, b = os.fspath(left), os.fspath(right)
    if a == b:
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:  # a pattern, a URL, a missing file: the text decides
        return os.path.normpath(a) == os.path.normpath(b)


_VIDEO_NODE_RE = re.compile(r"^/dev/video\d+$")


def _camera_device(src: object) -> str | None:
    """The V4L2 device node a camera source opens (``0`` -> ``/dev/video0``; a path such as
    ``/dev/video0`` or a ``/dev/v4l/by-id/...`` link -> the node it resolves to), or None for
    a file, pattern or URL."""
    if isinstance(src, (int, np.integer)) and not isinstance(src, NOT_NUMBERS):
        return os.path.realpath(f"/dev/video{int(src)}")
    if isinstance(src, str) and "://" not in src:
        node = os.path.realpath(src)
        return node if _VIDEO_NODE_RE.match(node) else None
    return None


#: URL schemes of live streams (an IP camera's RTSP, RTMP, SRT, raw UDP/RTP/TCP), which have
#: no end: one that stops delivering was lost, as an unplugged camera. ``http(s)://`` is not
#: among them: it may name a video file, which ends.
_LIVE_SCHEMES = ("rtsp", "rtsps", "rtmp", "rtmps", "rtp", "srt", "udp", "tcp")


def _live_stream(src: object) -> bool:
    """Whether ``src`` is the URL of a live network stream (:data:`_LIVE_SCHEMES`)."""
    if not isinstance(src, str):
        return False
    m = re.match(r"\s*([A-Za-z][A-Za-z0-9+.-]*)://", src)
    return m is not None and m.group(1).lower() in _LIVE_SCHEMES


def _http_url(src: object) -> bool:
    """Whether ``src`` is an ``http://`` or ``https://`` URL, which may name a video file."""
    return isinstance(src, str) and re.match(r"\s*https?://", src, re.IGNORECASE) is not None


def _rate_askable(src: object) -> bool:
    """Whether a frame rate can be asked of ``src``: a camera (an index, its node), a live
    stream's URL, or a capture object of the caller's; a video file, an image sequence or an
    ``http(s)://`` URL (which may name a file) is read as it is."""
    if not isinstance(src, (str, os.PathLike)):
        return True
    path = os.fspath(src)
    return ("://" in path and not _http_url(path)) or _camera_device(path) is not None


def _refuse_one_camera_twice(left: object, right: object) -> None:
    """Refuse ``--left`` and ``--right`` sources (as :func:`parse_source` reads them) that name
    one camera: its second open failed with a hint about another program using the camera.
    Said in one way by capture, stream and gui.

    Raises
    ------
    ValueError
        If both are one camera index, or name one device (``0`` and ``/dev/video0``).
    """
    if isinstance(left, int) and left == right:
        raise ValueError(f"--left and --right are both camera {left}: give the rig's two cameras")
    device = _camera_device(left)
    if device is not None and device == _camera_device(right):
        # one camera named two ways (--left 0 --right /dev/video0, or a /dev/v4l link)
        raise ValueError(
            f"--left {str(left)!r} and --right {str(right)!r} are both camera {device}: give "
            "the rig's two cameras"
        )


def open_source(args: argparse.Namespace, *, fps: float | None = None) -> Any:
    """The :class:`StereoCamera` or :class:`~stereovision.rosbag.BagCamera` the options name.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (``--left``/``--right``, or ``--from-bag`` and its options;
        ``--size``, ``--fourcc``; ``--read-timeout``, which bounds each camera's open too).
    fps : float, optional
        Frame rate to request of the cameras.

    Returns
    -------
    StereoCamera or stereovision.rosbag.BagCamera
        The source, opened (the caller closes it).

    Raises
    ------
    ValueError
        If both or neither source kind is given, a bag option comes without ``--from-bag``,
        or ``--left`` and ``--right`` name one camera (``0`` and ``/dev/video0``).
    """
    size = parse_size(args.size, "--size")
    if args.from_bag:
        if args.left is not None or args.right is not None:
            raise ValueError("--from-bag replaces --left and --right: give one source")
        if fps is not None:
            raise ValueError("--fps: a bag is read as recorded, it has no frame rate to ask for")
        if getattr(args, "fourcc", None):
            raise ValueError("--fourcc asks a camera for a format: a bag holds what it recorded")
        if getattr(args, "read_timeout", None) is not None:
            # ignored before it was refused: a bag's read never waits on a camera
            raise ValueError("--read-timeout bounds a camera's read: a bag is read from disk")
        from stereovision.rosbag import BagCamera

        return BagCamera(
            args.from_bag,
            left_topic=args.left_topic,
            right_topic=args.right_topic,
            max_skew_ms=args.max_skew_ms,
            image_size=size,
            realtime=bool(getattr(args, "realtime", False)),
        )
    if getattr(args, "realtime", False):
        raise ValueError("--realtime plays a recording at its pace: it goes with --from-bag")
    if args.left_topic or args.right_topic or args.max_skew_ms is not None:
        raise ValueError("--left-topic, --right-topic and --max-skew-ms are for --from-bag")
    if args.left is None or args.right is None:
        raise ValueError("give the two cameras (--left and --right) or a recording (--from-bag)")
    left, right = parse_source(args.left), parse_source(args.right)
    _refuse_one_camera_twice(left, right)
    cam = StereoCamera(
        left,
        right,
        image_size=size,
        fps=fps,
        fourcc=getattr(args, "fourcc", None),
        open_timeout=cli_read_timeout(args),  # a wedged device hung its open as its reads
    )
    if _same_path(left, right):
        # a typo: every pair is one view twice, every disparity 0, and nothing said it (said
        # once the source opens: a missing one is said as such)
        try:
            warnings.warn(
                f"--left and --right are the same source {mask_url_secrets(str(left))!r}: "
                "every pair is one view twice and every disparity comes out 0 (two cameras' "
                "views are needed)",
                UserWarning,
                stacklevel=2,
            )
        except BaseException:  # made an error (python -W error): cam is never returned
            cam.close()
            raise
    return cam


# ---------------------------------------------------------------------------------- saving


#: A temporary file of :func:`save_pair`: ``.left_0001.png.<pid>-<random>.tmp`` (before,
#: ``tempfile``'s ``.left_0001.png.<random>.tmp``, without the writer's process id).
_TMP_RE = re.compile(r"^\.(?:left|right)_\d+\.[A-Za-z0-9]+\.(?:(\d+)-)?[a-z0-9_]+\.tmp$")


def _check_ext(ext: object) -> None:
    """Refuse an ``ext`` that is no image format's extension: ``"png"`` (no dot) was "cannot
    encode the left image as png", after the camera's first pair; ``"/x.png"`` wrote below the
    folder, ``".png "`` names the numbering does not read."""
    if not isinstance(ext, str) or not _EXT_RE.match(ext):
        raise ValueError(f"ext: expected an image format's extension such as '.png', got {ext!r}")


def _atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to a temporary file beside ``path``, then give it the name ``path`` if
    no file has it (:class:`FileExistsError` otherwise; another capture into the folder may
    have saved it meanwhile).

    The temporary file is named before it exists, so that any exception -- KeyboardInterrupt
    included, at any point from its creation on -- removes it; its name carries this process's
    id, so that :func:`remove_stale_temps` can tell a file a killed capture left from one being
    written. The name is given by a hard link, which fails on an existing file (a rename
    replaced it: two captures into one folder overwrote each other's pairs); on a filesystem
    without hard links (FAT), by a rename after a check."""
    from stereovision.io import temp_refused

    tmp = path.with_name(f".{path.name}.{os.getpid()}-{secrets.token_hex(4)}.tmp")
    try:
        try:
            flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
            fd = os.open(tmp, flags, 0o666)
        except OSError as exc:
            # the temporary file was named ('No such file or directory: '/proc/.left_0001.png
            # .32467-0f59063e.tmp''), not the pair's file and its folder
            raise temp_refused(path, exc) from exc
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
        except OSError as exc:
            # a full disk said "[Errno 28] No space left on device" alone, naming no file
            failed = type(exc)(f"cannot write {path}: {exc.strerror or exc}")
            failed.errno = exc.errno
            raise failed from exc
        try:
            os.link(tmp, path)
        except FileExistsError:
            raise
        except OSError:  # no hard links here
            if os.path.lexists(path):
                raise FileExistsError(errno.EEXIST, "file exists", str(path)) from None
            try:
                os.replace(tmp, path)
            except OSError as exc:
                # it named the temporary file first ('.left_0001.png.1234-9f2c.tmp' -> ...)
                failed = type(exc)(f"cannot write {path}: {exc.strerror or exc}")
                failed.errno = exc.errno
                raise failed from exc
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    with contextlib.suppress(OSError):
        os.unlink(tmp)


def _pid_alive(pid: int) -> bool:
    """Whether process ``pid`` runs (True when it cannot be told)."""
    if pid == os.getpid() or os.name != "posix":
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's: alive
        return True
    return True


def remove_stale_temps(directory: PathLike) -> list[str]:
    """Remove the temporary files of :func:`save_pair` that a killed capture left in
    ``directory`` (``.left_0003.png.1234-9f2c.tmp``: a capture ended by SIGKILL, or SIGTERM
    without a handler, has no chance to remove its own); those of a process still running are
    kept.

    Parameters
    ----------
    directory : str or os.PathLike
        The capture's output folder (a missing one: nothing to remove).

    Returns
    -------
    list of str
        The file names removed, sorted.
    """
    d = as_path(directory, "directory")
    removed: list[str] = []
    if not d.is_dir():
        return removed
    for p in d.iterdir():
        m = _TMP_RE.match(p.name)
        if m is None or (m.group(1) is not None and _pid_alive(int(m.group(1)))):
            continue
        try:
            if p.is_file():
                p.unlink()
                removed.append(p.name)
        except OSError:  # gone meanwhile, or not ours to remove
            pass
    return sorted(removed)


def next_pair_index(directory: PathLike) -> int:
    """1 + the largest pair index already in ``directory`` (1 when none)."""
    d = as_path(directory, "directory")
    if not d.is_dir():
        return 1
    found = [int(m.group(2)) for p in d.iterdir() if (m := _PAIR_RE.match(p.name))]
    return max(found, default=0) + 1


#: The types a lossless format holds (OpenCV's writers: .tiff cut int64 to int32, and wrote
#: float16 and bool as 8 bits, as .png writes every type but these two).
_HELD_BY = {
    ".png": ("uint8", "uint16"),
    ".tiff": tuple("uint8 int8 uint16 int16 int32 uint32 uint64 float32 float64".split()),
}


def _lossless_advice(dtype: np.dtype, ext: str, writes: str) -> str:
    """What to do with a ``dtype`` image that ``ext`` would write as ``writes`` (``"8 bits"``,
    ``"float32"`` or another type's name): :func:`save_pair`'s advice, naming only a format
    that holds the type. It said ".tiff holds float16" (and bool) of .hdr, though .tiff writes
    both as 8 bits, and advised uint8 "(a float image in [0, 1]: times 255)" for a 16-bit
    image .png holds."""
    ext = ".tiff" if ext.lower() == ".tif" else ext.lower()
    if dtype.kind == "b":
        return "convert it to uint8 first (True as 255)"
    holders = [e for e, held in _HELD_BY.items() if dtype.name in held and e != ext]
    if dtype.kind == "f":
        if writes == "float32":  # .hdr, .pfm: float32 as it is
            return f".tiff holds {dtype}" if holders else "convert it to float32 first (no loss)"
        # a float32 image as .png was told to become uint8 "(a float image in [0, 1]: times
        # 255)", its values cut to 256 levels, where .tiff keeps them
        if holders:
            return f".tiff holds {dtype}"
        return "convert it to float32 first (.tiff holds float32)"  # float16
    if holders:
        return f"{' and '.join(holders)} hold{'s' if len(holders) == 1 else ''} {dtype}"
    # int64 (a list's ints): no format here holds it; .tiff cuts it to int32
    if writes == "float32":
        return "convert it to uint8 or float32 first"
    return "convert it to int32 or float64 first" if ext == ".tiff" else "convert it to uint8 first"


def save_pair(
    directory: PathLike,
    index: int,
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    ext: str = ".png",
) -> tuple[Path, Path]:
    """Save a pair atomically as ``left_NNNN.ext`` and ``right_NNNN.ext``.

    Both images are encoded in memory first; each is then written to a temporary file in
    ``directory`` (``.left_0001.png.<pid>-<random>.tmp``) and given its final name, left
    first, right last; an existing file is never replaced. Ctrl-C (and SIGTERM where Python
    handles it) is held until both are written; a failure of the right image removes the left
    one, so a pair is saved whole or not at all. Any exception, KeyboardInterrupt included,
    removes the temporary file; one that a killed process left is removed by the next
    :func:`capture` into the folder (:func:`remove_stale_temps`).

    Parameters
    ----------
    directory : str or os.PathLike
        Destination (created if missing).
    index : int
        Pair number (``>= 0``).
    left, right : array_like
        ``uint8`` images (grey or BGR); another type (``uint16``, ``float32``) only in a
        format that holds it (``.png`` for ``uint16``, ``.tiff`` for both). ``.hdr`` writes
        three float32 channels (RGBE, steps of about 1 %) whatever it is given: ``uint8`` as
        float in [0, 1], ``float32`` as it is; another type is refused.
    ext : str
        Image format by extension (``.png`` lossless by default).

    Returns
    -------
    tuple of pathlib.Path
        The two final paths.

    Raises
    ------
    ValueError
        If ``index`` is not an integer ``>= 0``, ``ext`` is no extension (``.png``), an image
        is None or empty (a frame the camera dropped), a path or an encoded file's bytes, or
        an image cannot be encoded in that format, or not without loss (a float image in
        ``.png``: it would be written as 8 bits).
    FileExistsError
        If ``left_NNNN`` or ``right_NNNN`` exists (nothing of this pair is left behind), or
        ``directory`` is a file.
    NotADirectoryError
        If ``directory`` is a link to nothing, or a folder above it a file.
    OSError
        If writing fails (no partial file, and no half pair, is left behind).
    """
    # -1 made left_-001.png, a name next_pair_index does not read; a float failed on the format
    if not isinstance(index, (int, np.integer)) or isinstance(index, NOT_NUMBERS) or index < 0:
        raise ValueError(f"index: expected a pair number >= 0, got {index!r}")
    _check_ext(ext)
    for side, img in (("left", left), ("right", right)):
        empty = isinstance(img, np.ndarray) and img.size == 0
        if img is None or path_given(img) is not None or isinstance(img, bytes) or empty:
            # a frame the camera dropped (cap.read()'s None or an empty frame), a path or an
            # encoded file's bytes was "cannot encode the left image as .png", a format's
            # fault, and the folder made: said as TemporalFilter and refine_disparity say it
            # (as_image_array's words)
            as_image_array(img, side)  # raises
    d = as_path(directory, "directory")
    if d.exists() and not d.is_dir():  # FileExistsError, as mkdir's: capture stops on it
        raise FileExistsError(f"cannot write the pair into {d}: it is a file, not a folder")
    # mkdir's bare "[Errno 17] File exists" of a link to nothing (an unmounted drive), or
    # "[Errno 20] Not a directory" under a file, named no cause
    make_folder(d)
    data = []
    for side, img in (("left", left), ("right", right)):
        arr = np.asarray(img)
        try:
            # a type the format cannot hold is refused below: OpenCV's log line ("[ WARN ...]
            # ... fallbacked to CV_8U") came first on stderr, as if the image had been written
            with _opencv_quiet() if arr.dtype != np.uint8 else contextlib.nullcontext():
                ok, buf = cv2.imencode(ext, arr)
        except cv2.error:
            ok = False
        if not ok:
            raise ValueError(f"cannot encode the {side} image as {ext}")
        if arr.dtype != np.uint8:
            # a format without the image's depth is written as 8 bits: a float image in
            # [0, 1] was saved black (0 and 1), a 16-bit one in .jpg white, without a word
            back = cv2.imdecode(buf, cv2.IMREAD_UNCHANGED)
            # .hdr writes float32 (RGBE, 1 % steps) whatever it is given: a 16-bit image
            # was said to be "written as 8 bits", and uint8 advised, which .hdr turns
            # into float32 too
            writes = "8 bits" if back is None or back.dtype == np.uint8 else back.dtype.name
            if back is None or back.dtype != arr.dtype:
                raise ValueError(
                    f"cannot save the {side} image ({arr.dtype}) as {ext} without loss: that "
                    f"format would write it as {writes}; {_lossless_advice(arr.dtype, ext, writes)}"
                )
        data.append(buf.tobytes())
    paths = tuple(d / PAIR_NAME.format(side=s, index=index, ext=ext) for s in ("left", "right"))
    # A pair is saved whole or not at all: Ctrl-C (SIGTERM in the CLI) is held until both
    # images are written, and the left image is removed when the right one fails (a left
    # image alone stayed: `calibrate --left 'left_*' --right 'right_*'` then refused the
    # folder for its file counts, and every later capture numbered its pairs after it).
    from stereovision._interrupt import HeldInterrupts

    with HeldInterrupts():
        _atomic_write_bytes(paths[0], data[0])
        try:
            _atomic_write_bytes(paths[1], data[1])
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(paths[0])
            raise
    return paths[0], paths[1]


# -------------------------------------------------------------------------- chessboard mode


def _board_search_image(image: np.ndarray) -> np.ndarray:
    """``image`` as the live board searches read it: an 8-bit one as it is; one of more bits
    as 8-bit grey, a dark one (a 10- or 12-bit camera's frames in 16-bit PNGs) stretched by
    the gain that brings its brightest grey to 255, as calibrate reads it (``_board_gray``).
    Cut to its top 8 bits, a 10-bit board of levels 120-426 kept 3 grey levels and was found in
    no frame (calibrate found it in each), with a warning of its bits for every frame. A
    black one is black, without that warning (``_board_gray``'s rules, one place)."""
    from stereovision._validate import as_image_array
    from stereovision.calibrate import _board_gray

    arr = as_image_array(image, "image")
    return arr if arr.dtype == np.uint8 else _board_gray(arr, "image")


def detect_board_live(image: np.ndarray, pattern: tuple[int, int]) -> np.ndarray | None:
    """Fast board detection for a live stream (scaled to <= :data:`DETECT_MAX_WIDTH`).

    Parameters
    ----------
    image : numpy.ndarray
        Grey, BGR or BGRA; ``uint8``, ``uint16`` or float in [0, 1] (searched as 8-bit grey; a
        dark one of more bits, a 10- or 12-bit camera's, stretched as calibrate reads it).
    pattern : tuple of int
        Inner corners ``(cols, rows)``.

    Returns
    -------
    numpy.ndarray or None
        ``(cols * rows, 2)`` corners in full-resolution pixels (about 1 px accurate: for choosing
        views, not for calibrating), or None.
    """
    from stereovision._validate import as_gray_uint8

    # 8-bit grey, as calibrate and the ChArUco mode search: an image sequence's 16-bit PNGs
    # came as they are, and findChessboardCorners' cv2.error on them came out raw
    gray = as_gray_uint8(_board_search_image(image), "image")
    scale = min(1.0, DETECT_MAX_WIDTH / gray.shape[1])
    small = gray
    if scale < 1.0:
        dsize = (round(gray.shape[1] * scale), round(gray.shape[0] * scale))
        small = np.asarray(cv2.resize(gray, dsize, interpolation=cv2.INTER_AREA))
    ok, corners = cv2.findChessboardCorners(small, pattern, flags=LIVE_DETECT_FLAGS)
    if not ok:
        return None
    c = np.asarray(corners, np.float64).reshape(-1, 2) / scale
    if c[0].sum() > c[-1].sum():  # same orientation rule as calibrate.find_corners
        c = c[::-1].copy()
    return c


@dataclass
class Decision:
    """What :meth:`ChessboardCollector.consider` decided for one pair."""

    save: bool
    reason: str
    params: tuple[float, float, float, float] | None = None


def charuco_pose_params(
    ids: npt.ArrayLike, corners: npt.ArrayLike, board: CharucoBoard, image_size: tuple[int, int]
) -> tuple[float, float, float, float]:
    """:func:`~stereovision.calibrate.board_pose_params` of a ChArUco board seen in part.

    The whole board's inner corners are placed in the image through the homography of the
    corners seen, so that a board cut by the image edge gets the pose it has, not that of the
    part in view.
    """
    obj = board.object_points(ids)[:, :2].astype(np.float64)
    H, _ = cv2.findHomography(obj, np.asarray(corners, np.float64).reshape(-1, 2))
    if H is None:  # a degenerate layout (corners_span_plane guards against it)
        raise ValueError("the corners seen do not fix the board's pose")
    full = board.object_points()[:, :2].astype(np.float64).reshape(-1, 1, 2)
    grid = cv2.perspectiveTransform(full, H).reshape(-1, 2)
    return board_pose_params(grid, board.inner, image_size)


@dataclass
class ChessboardCollector:
    """Choose pairs for calibration: both boards found, pose new enough (ROS's rule).

    Parameters
    ----------
    pattern : tuple of int
        ``(cols, rows)`` inner corners, or ``"9x6"`` as :func:`~stereovision.calibrate.calibrate`
        takes it (ignored with ``board``).
    min_distance : float
        A pair is kept when ``sum(|p - q|)`` over ``(x, y, size, skew)`` is above this for every
        kept pair ``q`` (:data:`MIN_POSE_DISTANCE`); a finite number, 0 or more.
    board : stereovision.charuco.CharucoBoard, optional
        A ChArUco board instead of a chessboard: a pair counts when both cameras see at least
        :data:`~stereovision.calibrate.CHARUCO_MIN_COMMON` common corners, not all on one line.

    Raises
    ------
    TypeError
        If ``board`` is given and is not a :class:`~stereovision.charuco.CharucoBoard`, or
        ``pattern`` is no pattern (:func:`~stereovision.calibrate.parse_pattern`).
    ValueError
        If ``pattern`` is a bad pattern, or ``min_distance`` is not a finite number of 0 or more.

    Attributes
    ----------
    kept : list of tuple of float
        The ``(x, y, size, skew)`` pose of each pair kept, in order.
    """

    pattern: tuple[int, int]
    min_distance: float = MIN_POSE_DISTANCE
    # state, not a parameter: ChessboardCollector(pattern, min_distance, board), the documented
    # order, put the board into kept and collected chessboards
    kept: list[tuple[float, float, float, float]] = field(default_factory=list, init=False)
    board: CharucoBoard | None = None

    def __post_init__(self) -> None:
        # Checked here, not at the first board seen: "9x6" reached findChessboardCorners as a
        # raw cv2.error, board="9x6" was AttributeError "'str' object has no attribute
        # 'resolved'", min_distance NaN kept every pair (the same pose over and over) and "0.2"
        # was TypeError "'<=' not supported" once a second board was seen.
        from stereovision.charuco import _require_board

        if self.board is not None:
            _require_board(self.board)
        else:
            self.pattern = parse_pattern(self.pattern)
        self.min_distance = check_min_distance(self.min_distance)

    def _charuco_pose(self, frame: StereoFrame) -> tuple[float, float, float, float] | str:
        from stereovision.calibrate import CHARUCO_MIN_COMMON
        from stereovision.charuco import corners_span_plane, find_charuco_corners

        assert self.board is not None
        # a dark 10- or 12-bit frame stretched, as the chessboard's search reads it
        left, right = _board_search_image(frame.left), _board_search_image(frame.right)
        if not self.board.resolved:
            found = self.board.resolve(left)
            if found is None:
                return "no board in left"
            self.board = found
        fl = find_charuco_corners(left, self.board)
        if fl is None:
            return "no board in left"
        fr = find_charuco_corners(right, self.board)
        if fr is None:
            return "no board in right"
        common = np.intersect1d(fl[0], fr[0])
        if len(common) < CHARUCO_MIN_COMMON or not corners_span_plane(self.board, common):
            return f"only {len(common)} corners seen by both cameras"
        h, w = frame.left.shape[:2]
        try:
            return charuco_pose_params(fl[0], fl[1], self.board, (w, h))
        except ValueError as exc:
            return str(exc)

    def _pose(self, frame: StereoFrame) -> tuple[float, float, float, float] | str:
        """The board's ``(x, y, size, skew)`` in ``frame``, or why there is none."""
        if self.board is not None:
            return self._charuco_pose(frame)
        cl = detect_board_live(frame.left, self.pattern)
        if cl is None:
            return "no board in left"
        if detect_board_live(frame.right, self.pattern) is None:
            return "no board in right"
        h, w = frame.left.shape[:2]
        return board_pose_params(cl, self.pattern, (w, h))

    def remember(self, frame: StereoFrame) -> bool:
        """Count the board's pose in ``frame`` as kept, new or not (a pair saved before, by an
        earlier capture into the folder).

        Parameters
        ----------
        frame : StereoFrame
            The pair.

        Returns
        -------
        bool
            Whether the board was found in both images (its pose then remembered).
        """
        pose = self._pose(frame)
        if isinstance(pose, str):
            return False
        self.kept.append(pose)
        return True

    def consider(self, frame: StereoFrame) -> Decision:
        """Decide whether ``frame`` is worth saving; a kept pose is remembered.

        Parameters
        ----------
        frame : StereoFrame
            The pair to judge.

        Returns
        -------
        Decision
            ``save`` True for a new pose (then remembered), else False with the ``reason`` (no
            board in a view, too few corners, a pose too close to a kept one); ``params`` the
            pose's ``(x, y, size, skew)`` when the board was found.
        """
        pose = self._pose(frame)
        if isinstance(pose, str):
            return Decision(False, pose)
        p = pose
        if self.kept:
            nearest = min(sum(abs(a - b) for a, b in zip(p, q, strict=True)) for q in self.kept)
            if nearest <= self.min_distance:
                return Decision(False, f"pose too close to a saved one ({nearest:.3f})", p)
        self.kept.append(p)
        return Decision(True, "new pose", p)

    def progress(self) -> dict[str, float]:
        """Coverage of each pose parameter: span of the kept values / ROS's target span.

        Returns
        -------
        dict of str to float
            By parameter name (:data:`POSE_PARAM_NAMES`), in ``[0, 1]`` (0 before any pose).
        """
        out = {}
        for k, (name, span) in enumerate(zip(POSE_PARAM_NAMES, POSE_PARAM_RANGES, strict=True)):
            vals = [p[k] for p in self.kept]
            out[name] = min(1.0, (max(vals) - min(vals)) / span) if vals else 0.0
        return out

    def format_progress(self) -> str:
        """:meth:`progress` as bars, as ROS's calibrator shows it.

        Returns
        -------
        str
            One line: ``x [#####-----]  50%  y [...] ...``.
        """
        parts = []
        for name, v in self.progress().items():
            n = round(v * PROGRESS_BAR_WIDTH)
            bar = "#" * n + "-" * (PROGRESS_BAR_WIDTH - n)
            parts.append(f"{name} [{bar}] {100 * v:3.0f}%")
        return "  ".join(parts)


# ---------------------------------------------------------------------------------- capture


@dataclass
class CaptureResult:
    """What :func:`capture` did.

    Attributes
    ----------
    saved : list of tuple of pathlib.Path
        The ``(left, right)`` files of each pair saved, in order.
    frames_read : int
        Pairs read from the camera by this capture (saved or not; not those of an earlier
        capture on the same camera).
    skew : dict of str to float
        Left/right grab skew over the pairs this capture read: ``n``, ``mean_ms``,
        ``median_ms``, ``max_ms`` (NaN without pairs).
    coverage : dict of str to float or None
        With a board: each pose parameter's coverage in ``[0, 1]``
        (:meth:`ChessboardCollector.progress`); None without one.
    ended : str
        ``"count reached"``, ``"end of stream"`` (both sources ended together, as announced),
        or, when a source ended before the other or a file before its announced frames, what
        ended (``"right source 'r.avi' ended after 100 frames; the left source still had
        frames"``).
    removed_temps : list of str
        Temporary files a killed capture had left in the folder, removed at the start.
    """

    saved: list[tuple[Path, Path]]
    frames_read: int
    skew: dict[str, float]
    coverage: dict[str, float] | None = None
    ended: str = "count reached"
    #: Temporary files a killed capture had left in the folder, removed at the start.
    removed_temps: list[str] = field(default_factory=list)


def _frames_announced(cam: Any) -> int:
    """The frame pairs a recording announces (the fewer of its two videos' frames, or of its
    bag's two topics' messages), 0 when unknown (a camera: a bar of its frames has no end):
    the total of the frames bar of ``capture`` and ``calibrate`` from a recording."""
    # StereoCamera's (CAP_PROP_FRAME_COUNT); BagCamera's (the bag's index): a bag's bar had
    # no total though the index knows each topic's messages
    announced = getattr(cam, "_announced", None)
    if announced is None:
        return 0
    counts = [announced(side) for side in ("left", "right")]
    return min(counts) if None not in counts else 0


def capture(
    camera: StereoCamera,
    directory: PathLike,
    *,
    count: int | None = None,
    chessboard: tuple[int, int] | str | None = None,
    charuco: CharucoBoard | None = None,
    min_distance: float = MIN_POSE_DISTANCE,
    every: int = 1,
    ext: str = ".png",
    log: Callable[[str], None] | None = None,
    temporal: int | None = None,
    read_timeout: float | None = DEFAULT_READ_TIMEOUT,
    progress: Callable[[int], None] | None = None,
) -> CaptureResult:
    """Save pairs from ``camera`` into ``directory`` until ``count`` are saved.

    Parameters
    ----------
    camera : StereoCamera
    directory : str or os.PathLike
        Created if missing; numbering continues after pairs already there (none is overwritten).
        With a board, the poses of the last :data:`RESUME_POSES_MAX` of them count as saved
        ones (a capture resumed into its folder saves only poses new to them; said to ``log``,
        with the number of earlier pairs not read). Temporary files a killed capture left
        there are removed first (said to ``log``).
    count : int, optional
        Pairs to save. Without it, capture runs until a source ends (normal for files); when
        one ends before the other, or a video file before the frames its header announces
        (truncated), :attr:`CaptureResult.ended` says so (the CLI prints it). A camera device
        or a live stream (``rtsp://``, ``srt://``, ...) has no end: one that stops delivering
        (unplugged, its network gone) raises :class:`SourceError`, its message saying the
        pairs saved, which are kept.
    chessboard : tuple of int or str, optional
        Pattern (``(9, 6)`` or ``"9x6"``): save only pairs with the board in both images and a
        new pose (:class:`ChessboardCollector`).
    charuco : stereovision.charuco.CharucoBoard, optional
        The same with a ChArUco board (it may be cut by the image edges); not with
        ``chessboard``.
    min_distance : float
        Pose distance of the chessboard mode.
    every : int
        Save every ``every``-th pair; not with ``chessboard`` or ``charuco`` (the board's new
        poses choose the pairs).
    ext : str
        Image format of the saved files.
    log : callable, optional
        Receives one line per saved pair (with coverage in chessboard mode) and, with
        ``temporal``, one for a mean the source's end (or an interrupt) left unfinished (not
        saved); with a board, one at the end when no pair was saved, saying why (``no board in
        left``, counted) and naming the pattern of one corner fewer each way when the last
        left image shows it (squares counted: ``10x7`` for a board of 9x6 inner corners).
    temporal : int, optional
        Save each pair as the mean of ``temporal`` (2-255) frames of a still view
        (:class:`~stereovision.temporal.TemporalFilter`: a moving rig or board starts the mean
        again, so a pair is saved only once the view has held still that long), and start
        afresh after each saved pair. Low light: on a rendered rig with grey noise of 20 levels,
        8 frames a pair halved the calibration's range error (docs/robotics.md). Not with
        ``every``.
    read_timeout : float or None
        Seconds a pair's read may take (:data:`DEFAULT_READ_TIMEOUT`, 10; None: no limit): a
        camera whose read does not return by then (a hung USB camera) raises a
        :class:`SourceError` naming it, the pairs saved so far kept (:func:`read_within`).
    progress : callable, optional
        Called with the number of pairs read so far after each pair read (a progress bar's
        tick: ``stereovision capture`` draws one for a recording on a terminal).

    Returns
    -------
    CaptureResult

    Raises
    ------
    SourceError
        If a source fails (a frame that does not decode or of another shape, with or without
        ``count``), ends before ``count`` pairs were saved, or ends before a first pair could
        be read; the pairs saved so far stay on disk, and the message says how many.
    TypeError
        If ``charuco`` is not a :class:`~stereovision.charuco.CharucoBoard`.
    ValueError
        For an invalid ``count``, ``every`` (or one with a board), ``temporal``, ``ext`` or
        pattern, a ``directory`` that is a file (or below one), or one whose saved pairs an
        image-sequence source would read as its next frames (``--left 'pairs/left_%04d.png'
        -o pairs``); a recorded frame that does not decode (a bag), its message saying how many
        pairs were saved and are kept.
    PermissionError
        If ``directory`` cannot be written.
    OSError
        If a pair cannot be written (a full disk): the message names the file and says the
        pairs saved so far, which are kept.
    """
    # 2.5 saved 3 pairs and NaN none ("count reached"); every=NaN saved none to the end
    if count is not None:
        count = positive_whole(count, "count", "a positive number of pairs")
    every = positive_whole(every, "every")
    check_read_timeout(read_timeout)
    _check_ext(ext)
    if not cv2.haveImageWriter("pair" + ext):  # said before a pair is read, not after
        raise ValueError(f"ext: cannot encode images as {ext}: OpenCV has no writer for it")
    if chessboard and charuco is not None:
        raise ValueError("chessboard and charuco: give one calibration target, not both")
    if every != 1 and (chessboard or charuco is not None):
        # ignored without a word (every=3 over 3 new poses saved 3), as --every was before
        # the CLI refused it: the board's pose chooses the pairs, not their number
        raise ValueError(
            "every is for a capture without a board: chessboard and charuco save a pair for "
            "each new pose of the board"
        )
    tf = None
    if temporal is not None:
        if not isinstance(temporal, (int, np.integer)) or isinstance(temporal, NOT_NUMBERS):
            raise ValueError(f"temporal: expected a number of frames, got {temporal!r}")
        if not 2 <= temporal <= 255:
            raise ValueError(f"temporal: expected 2-255 frames a pair, got {temporal}")
        if every != 1:
            raise ValueError("every and temporal: give one (temporal saves a pair per still view)")
        from stereovision.temporal import TemporalFilter

        tf = TemporalFilter(max_frames=int(temporal))
    collector = None
    if charuco is not None:
        from stereovision.charuco import _require_board

        # "10x7" was AttributeError "'str' object has no attribute 'inner'" here
        _require_board(charuco, "charuco")
        collector = ChessboardCollector(charuco.inner, min_distance, board=charuco)
    elif chessboard:
        collector = ChessboardCollector(parse_pattern(chessboard), min_distance)
    out = as_path(directory, "directory")
    # a file in the way, or a folder that cannot be written: said as such (it was "[Errno 17]
    # File exists" or "[Errno 2] No such file or directory")
    check_output_folder(out, "output folder")
    _refuse_own_output(getattr(camera, "sources", None), out, ext, "output folder")
    # the folders made here, deepest first (-o new/pairs makes two)
    made = [f for f in (out, *out.parents) if not f.exists()]
    out.mkdir(parents=True, exist_ok=True)
    stale = remove_stale_temps(out)
    if stale and log is not None:
        log(
            f"removed {len(stale)} temporary file{'s' if len(stale) > 1 else ''} an interrupted "
            f"capture left in {escaped(str(out))}: {', '.join(stale)}"
        )
    index = next_pair_index(out)
    if collector is not None and index > 1:
        # a capture resumed into its folder ("run again to add more") judged new poses
        # against none: the poses saved before were saved again, the coverage from 0 %
        seen, older = _remember_saved_poses(collector, out)
        where = escaped(str(out))
        # the pairs not read may hold poses the new ones repeat: said, not hidden
        unread = f" ({older} before them not read, for a quick start)" if older else ""
        if seen and log is not None:
            had = (
                f"{seen} of the last {RESUME_POSES_MAX} pairs in {where} "
                f"{'shows' if seen == 1 else 'show'} the board{unread}"
                if older
                else f"{_pairs(seen)} already in {where} with the board"
            )
            log(
                f"{had}: new poses must differ from {'it' if seen == 1 else 'them'} too  "
                + collector.format_progress()
            )
        elif older and log is not None:
            log(f"none of the last {RESUME_POSES_MAX} pairs in {where} shows the board{unread}")
    saved: list[tuple[Path, Path]] = []
    ended = "count reached"
    last_index = -1  # the frame index of the pair saved last
    read = 0  # pairs read by this capture
    # a camera read before (an earlier capture on it) counts its pairs too: this capture's
    # count and skews are its own
    read_before = getattr(camera, "count", 0)
    skews = SkewStats()
    # temporal: how many frames the mean being built holds while it is short of a pair's
    # (None once a pair is taken from it, or without temporal)
    unfinished: float | None = None
    # with a board, while no pair is saved: why the pairs judged were not, and the last left
    # image (a capture that found no board said "0 pairs saved" alone, naming no cause)
    missed: dict[str, int] = {}
    last_left: np.ndarray | None = None

    def say_unsaid(when: str) -> None:
        """The frames read since the last pair, dropped without a word before, and with a
        board, why no pair was saved: said."""
        if unfinished is not None and log is not None:
            log(
                f"not saved: the last mean, of {unfinished:.1f} frames of the {temporal} "
                f"asked, was unfinished when {when}"
            )
        if collector is not None and missed and not saved and log is not None:
            log(_no_board_note(collector, missed, last_left))

    def kept_note() -> str:
        if count is not None:
            return f"{len(saved)} of {count} pairs were saved in {out} and are kept"
        if len(saved) == 1:
            return f"1 pair was saved in {out} and is kept"
        return f"{len(saved)} pairs were saved in {out} and are kept"

    while count is None or len(saved) < count:
        try:
            frame = read_within(camera, read_timeout)
        except SourceError as exc:
            # an end before any pair is an error, as in `stream` (a bag whose frames found no
            # partner said "0 pairs saved (end of stream)" and exited 0)
            # a camera device has no end: one that stops delivering (unplugged) was said as
            # "end of stream", exit 0, as a video's end, where stream fails
            # this capture's reads (`read`), not the camera's: a second capture on an ended
            # file read nothing and said "0 pairs saved (end of stream)", exit 0
            if count is None and exc.end and read > 0 and not _device_ended(camera, exc):
                ended = _end_reason(exc, saved, last_index)
                say_unsaid("the source ended")
                break
            # with count too (the end is then an error), or a source's failure: the mean was
            # dropped without a word ("1 of 4 pairs were saved" of 5 frames at temporal=3)
            say_unsaid("the source ended" if exc.end else "the source failed")
            if exc.end and read == 0 and read_before > 0:
                raise exc.with_message(
                    f"{exc}, before this capture read a pair (an earlier read of this camera "
                    f"took its frames: open it again); {kept_note()}"
                ) from exc
            raise exc.with_message(f"{exc}; {kept_note()}") from exc
        except KeyboardInterrupt:  # Ctrl-C while a frame is awaited (SIGTERM in the CLI)
            say_unsaid("the capture was interrupted")
            raise
        except ValueError as exc:
            # a recording's frame that does not decode (BagCamera names its topic and stamp):
            # the pairs saved before it stay, and are said as for a video's failing frame
            say_unsaid("a frame could not be read")
            if not saved:
                raise
            raise ValueError(f"{exc}; {kept_note()}") from exc
        read += 1
        skews.append(frame.skew_ms)
        if progress is not None:
            progress(read)
        averaged = None
        if tf is not None:
            if tf.frames == 0:
                warn_resampled_for_temporal(camera, stacklevel=2, frame=frame)
            try:
                left, right = temporal_average(tf, frame)
            except KeyboardInterrupt:
                # Ctrl-C while a frame was averaged (not awaited) dropped the mean unsaid
                say_unsaid("the capture was interrupted")
                raise
            averaged = tf.mean_frames()
            # Every pixel's mean full but a few that something crossed (or noise beyond 3
            # sigmas started again).
            if averaged < _TEMPORAL_FULL * tf.max_frames:
                unfinished = averaged
                continue
            unfinished = None
            frame = dataclasses.replace(frame, left=left, right=right)
        if collector is not None:
            decision = collector.consider(frame)
            if not decision.save:
                if not saved:
                    # "only 12 corners seen by both cameras", "pose too close to a saved one
                    # (0.012)" (one resumed): one reason each, whatever the number
                    why = re.sub(r"^only \d+ corners", "too few corners", decision.reason)
                    why = re.sub(r" \([\d.]+\)$", "", why)
                    missed[why] = missed.get(why, 0) + 1
                    last_left = frame.left
                continue
        elif frame.index % every:
            continue
        try:
            while True:
                try:
                    paths = save_pair(out, index, frame.left, frame.right, ext=ext)
                    break
                except FileExistsError:  # another capture into the folder took this number
                    taken = (
                        PAIR_NAME.format(side=s, index=index, ext=ext) for s in ("left", "right")
                    )
                    if not any(os.path.lexists(out / name) for name in taken):
                        raise  # not a number taken (the folder became a file): no endless retry
                    index = max(index + 1, next_pair_index(out))
                except KeyboardInterrupt:
                    # held while both images were written (save_pair): a pair whose right
                    # image is there is saved whole, and said so before the interrupt goes on
                    rp = out / PAIR_NAME.format(side="right", index=index, ext=ext)
                    if log is not None and rp.exists():
                        lp = out / PAIR_NAME.format(side="left", index=index, ext=ext)
                        log(f"saved {lp.name} {rp.name} (skew {frame.skew_ms:.2f} ms)")
                    raise
        except ValueError:
            # a frame the format cannot hold (float32 as .png) fails the first pair: the folder
            # made for it was left behind, empty
            if not saved:
                with contextlib.suppress(OSError):
                    for folder in made:
                        folder.rmdir()
            raise
        except OSError as exc:
            # a full disk, a card turned read-only: the pairs saved before are said, as for a
            # source's failure (the error said neither them nor, from a write, the file)
            failed = type(exc)(f"{exc}; {kept_note()}")
            failed.errno = exc.errno
            raise failed from exc
        saved.append(paths)
        last_index = frame.index
        index += 1
        if tf is not None:
            tf._forget_means()  # the next pair from frames of its own, the same rig's noise
        if log is not None:
            line = f"saved {paths[0].name} {paths[1].name} (skew {frame.skew_ms:.2f} ms)"
            if averaged is not None:
                line += f" mean of {averaged:.1f} frames"
            if collector is not None:
                line += "  " + collector.format_progress()
            log(line)
    return CaptureResult(
        saved=saved,
        frames_read=read,
        # the camera's own report when it read nothing before (as exact for a bag's list)
        skew=camera.skew_report() if not read_before else skews.report(),
        coverage=None if collector is None else collector.progress(),
        ended=ended,
        removed_temps=stale,
    )


def _remember_saved_poses(collector: ChessboardCollector, out: Path) -> tuple[int, int]:
    """Give ``collector`` the board poses of the last :data:`RESUME_POSES_MAX` pairs already in
    ``out`` (saved by an earlier capture: ``left_0001.png`` with ``right_0001.png``); the
    number of pairs whose board it found, and the number of earlier pairs not read. An image
    that does not read is passed over."""
    from stereovision.io import read_image

    names = {p.name for p in out.iterdir()}
    pairs: list[tuple[int, str, str]] = []
    for name in names:
        m = _PAIR_RE.match(name)
        other = "right" + name[len("left") :]
        if m is not None and m.group(1) == "left" and other in names:
            pairs.append((int(m.group(2)), name, other))
    pairs.sort()  # by index: left_10000 after left_9999
    found = 0
    for _, name, other in pairs[-RESUME_POSES_MAX:]:
        try:
            left, right = read_image(out / name), read_image(out / other)
        except (OSError, ValueError):  # damaged, or not an image: no pose to count
            continue
        found += collector.remember(StereoFrame(left, right, 0.0, 0.0, 0))
    return found, max(0, len(pairs) - RESUME_POSES_MAX)


def _no_board_note(
    collector: ChessboardCollector, missed: dict[str, int], last_left: np.ndarray | None
) -> str:
    """:func:`capture`'s line for a board capture that saved no pair: why the pairs judged
    were not saved (``missed``: each reason's count) and, when no left image showed the
    chessboard, whether the last one shows a board of one corner fewer each way: the pattern
    counted the squares (10x7 for a board of 9x6 inner corners), the most common slip, which
    ``calibrate`` names too."""
    judged = sum(missed.values())
    reasons = ", ".join(f"{why} ({_pairs(n)})" for why, n in missed.items())
    note = f"no pair saved of the {_pairs(judged)} judged: {reasons}"
    cols, rows = collector.pattern
    fewer = (cols - 1, rows - 1)
    if (
        collector.board is None
        and set(missed) == {"no board in left"}
        and last_left is not None
        and min(fewer) >= 3  # calibrate's MIN_PATTERN_CORNERS
        and detect_board_live(last_left, fewer) is not None
    ):
        note += (
            f"; the last left image shows a board of {fewer[0]}x{fewer[1]} inner corners: the "
            "pattern counts the points where four squares meet, one fewer each way than the "
            f"squares (chessboard=({fewer[0]}, {fewer[1]}), --chessboard {fewer[0]}x{fewer[1]})"
        )
    return note


def _reads_own_output(sources: Any, out: PathLike, ext: str = ".png") -> str | None:
    """The image-sequence pattern (``left_%04d.png``) among ``sources`` (a camera's ``sources``
    dict) that would read the pairs saved in ``out`` as its next frames, or None."""
    if not isinstance(sources, dict):
        return None
    names = [PAIR_NAME.format(side=side, index=1, ext=ext) for side in ("left", "right")]
    for src in sources.values():
        if not isinstance(src, (str, os.PathLike)):
            continue
        path = os.fspath(src)
        folder, base = os.path.split(path)
        parts = _sequence_parts(base)
        if "://" in path or parts is None:
            continue
        # the folder as read: "%%" is a percent sign there too ("50%% done" reads "50% done")
        folder = folder.replace("%%", "%")
        regex = re.escape(parts[0]) + r"\d+" + re.escape(parts[2])
        try:
            same = os.path.samefile(folder or ".", out)
        except OSError:
            same = False
        if same and any(re.fullmatch(regex, name) for name in names):
            return path
    return None


def warn_resampled_for_temporal(
    camera: Any, stacklevel: int = 1, frame: StereoFrame | None = None
) -> None:
    """Warn once when ``camera``'s frames reach a :class:`~stereovision.temporal.TemporalFilter`
    already resampled: a bag's rectified topics, or frames enlarged to the size asked that
    :func:`temporal_average` cannot average as delivered (the two sources deliver frames of
    different sizes). Their interpolation spreads each pixel's noise over its neighbours, which
    the filter's motion test takes for motion (every pair of a still rig restarted: nothing
    averaged, and ``capture --temporal`` saved no pair). Call it after the first pair is read
    (its size is known then).

    Parameters
    ----------
    camera : StereoCamera or BagCamera
        The source, after its first :meth:`read`.
    stacklevel : int
        Of the warning, counted from the caller.
    frame : StereoFrame, optional
        That first pair: when :func:`temporal_average` averages it as delivered, an
        enlargement is not said (None: it is).
    """
    note = resampled_for_temporal_note(camera, frame)
    if note is not None:
        warnings.warn(note, UserWarning, stacklevel=stacklevel + 1)


def resampled_for_temporal_note(camera: Any, frame: StereoFrame | None = None) -> str | None:
    """The text of :func:`warn_resampled_for_temporal`'s warning, None when there is none: for a
    caller that warns elsewhere (the stream's grabbing thread hands it to the caller's)."""
    topics = getattr(camera, "topics", None)
    why: tuple[str, str] | None = None
    if getattr(camera, "rectified_topics", False) and topics:
        why = (
            f"the topics {topics['left']} and {topics['right']} are rectified",
            "give the raw image topics (--left-topic, --right-topic)",
        )
    size = getattr(camera, "size", None)
    if frame is not None and _averaged_before_resize(frame):
        size = None  # averaged before the resize
    for side, (w, h) in sorted(getattr(camera, "delivered_size", {}).items()):
        if why is None and size is not None and size[0] > w:
            why = (
                f"the {side} frames are enlarged from {w}x{h} to {size[0]}x{size[1]}",
                "ask for the cameras' own size",
            )
    if why is None:
        return None
    return (
        f"temporal averaging: {why[0]}, and interpolation spreads their noise, which the "
        f"filter takes for motion (it may average nothing); {why[1]}"
    )


def _refuse_own_output(sources: Any, out: PathLike, ext: str, flag: str) -> None:
    """ValueError when a source would read the pairs saved in ``out`` (:func:`_reads_own_output`):
    each pair saved became the sequence's next frame, and the capture never ended, filling the
    disk."""
    looping = _reads_own_output(sources, out, ext)
    if looping is not None:
        raise ValueError(
            f"{flag} {out}: the source {looping} would read the pairs saved there as its next "
            "frames, without end; save them in another folder"
        )


def _device_ended(camera: Any, exc: SourceError) -> bool:
    """Whether the source(s) whose end ``exc`` reports include a camera device (an index, or
    its node as StereoCamera knew it at the open: ``/dev/video0``, a ``/dev/v4l/by-id`` link):
    a file or sequence ends, a device that stops delivering was lost."""
    sides = ("left", "right") if exc.side in (None, "both") else (exc.side,)
    device = getattr(camera, "_device", None)
    if isinstance(device, dict):
        # an index alone was taken for a device: /dev/video0 unplugged ended as a file does
        return any(device.get(side, False) for side in sides)
    sources = getattr(camera, "sources", None)
    if not isinstance(sources, dict):
        return False
    return any(isinstance(sources.get(side), (int, np.integer)) for side in sides)


def _end_reason(exc: SourceError, saved: list[tuple[Path, Path]], last_index: int) -> str:
    """``"end of stream"`` when both sources ended together as announced; else what ended
    (:meth:`StereoCamera.read`'s words) and, for a file that ended early, which saved pair holds
    its last frame."""
    if not exc.ended_early:
        return "end of stream"
    reason = str(exc)
    frames = exc.frames
    if exc.expected_frames is not None and frames and saved and last_index == frames - 1:
        left, right = saved[-1]
        reason += f"; that pair was saved as {left.name}, {right.name}"
    return reason


# -------------------------------------------------------------------------------------- CLI


class _FramesBar:
    """``stereovision capture``'s bar over a recording's frames on a terminal: a board search
    through a recording (``--chessboard``, ``--from-bag``) read hundreds of pairs between two
    "saved" lines without a word, where the recording says its frames (``total``). Nothing for
    a camera (no total: its "saved" lines are its progress) nor off a terminal (a log); the
    lines said go above the bar, the warnings too."""

    def __init__(self) -> None:
        self.bar: Any = None
        self._shown: Any = None  # warnings.showwarning before the bar's

    def start(self, total: int) -> None:
        """Draw the bar of ``total`` frames, on a terminal only (none for a total of 0)."""
        if total > 0 and sys.stderr.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc="frames", unit="frame", file=sys.stderr, leave=False)
            # a warning while reading (a source's frames resized) was printed onto the bar's
            # line ("| 0/6 [...]stereovision: warning: ..."): it now goes above the bar
            shown = self._shown = warnings.showwarning

            def above(*args: Any, **kwargs: Any) -> None:
                with tqdm.external_write_mode(file=sys.stderr):
                    shown(*args, **kwargs)

            warnings.showwarning = above

    def update(self, read: int) -> None:
        if self.bar is not None:
            # past the total (CAP_PROP_FRAME_COUNT is a container's guess) tqdm counts on
            # without one
            self.bar.update(read - self.bar.n)

    def write(self, line: str) -> None:
        # each line out as it is said: in a pipe or a file (`capture ... | tee log`) the
        # "saved" lines waited in the buffer, none there while pairs were written, and a kill
        # (SIGKILL, a CI timeout) lost them all though their pairs were on disk
        if self.bar is None:
            print(line, flush=True)
        else:
            self.bar.write(line, file=sys.stdout)
            sys.stdout.flush()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None
            warnings.showwarning = self._shown


def cmd_capture(args: argparse.Namespace) -> int:
    """``stereovision capture --left 0 --right 1 --size 1280x720 -o pairs/``."""
    pattern = parse_pattern(args.chessboard, "--chessboard") if args.chessboard else None
    board = None
    if args.charuco:
        from stereovision.charuco import CharucoBoard, board_error_words

        if pattern is not None:
            raise ValueError("--chessboard and --charuco: give one calibration target, not both")
        if args.square is None or args.marker is None:
            raise ValueError("--charuco: give the board's --square and --marker sides too")
        try:
            board = CharucoBoard(args.charuco, args.square, args.marker, args.dictionary)
        except ValueError as exc:
            raise ValueError(board_error_words(exc, "--charuco", "--charuco")) from None
    elif args.square is not None or args.marker is not None or args.dictionary != "auto":
        raise ValueError("--square, --marker and --dictionary are for --charuco")
    if args.count is not None and args.count <= 0:
        raise ValueError(f"--count: expected a positive number, got {args.count}")
    if args.temporal is not None and not 2 <= args.temporal <= 255:
        raise ValueError(f"--temporal: expected 2-255 frames a pair, got {args.temporal}")
    if args.every != 1 and (pattern is not None or board is not None):
        # ignored before: the board's pose chooses the pairs (collector), not their number
        raise ValueError(
            "--every is for a capture without a board: --chessboard and --charuco save a pair "
            "for each new pose of the board"
        )
    if args.temporal is not None and args.every != 1:
        raise ValueError(
            "--every and --temporal: give one (--temporal saves a pair per still view)"
        )
    check_output_folder(args.output, "-o")  # before the cameras are opened
    ext = "." + getattr(args, "format", "png")
    if not args.from_bag:
        _refuse_own_output({"left": args.left, "right": args.right}, args.output, ext, "-o")
    cam = open_source(args, fps=args.fps)
    saved = [0]  # the pairs this run saved, as capture says them (not another capture's)
    bar = _FramesBar()

    def log(line: str) -> None:
        if line.startswith("saved "):
            saved[0] += 1
        bar.write(line)

    try:
        print(cam.describe(), flush=True)  # the source's line, before its pairs' lines
        bar.start(_frames_announced(cam))  # below the source's line
        result = capture(
            cam,
            args.output,
            count=args.count,
            chessboard=pattern,
            charuco=board,
            every=args.every,
            log=log,
            temporal=args.temporal,
            read_timeout=cli_read_timeout(args),
            progress=bar.update,
            ext=ext,
        )
    except ValueError as exc:
        # "... .tiff holds float32" of a float32 image sequence: no option chose .tiff
        if ext != ".tiff" and re.search(r"\.tiff holds \w+$", str(exc)):
            raise ValueError(f"{exc}: give --format tiff") from None
        raise
    except KeyboardInterrupt as exc:
        # what was kept, as `batch` says it (it was "stereovision: interrupted" alone)
        from stereovision._interrupt import Terminated
        from stereovision.cli import EXIT_INTERRUPTED, EXIT_TERMINATED

        bar.close()  # off the screen before the interrupt's words
        what = "terminated (SIGTERM)" if isinstance(exc, Terminated) else "interrupted"
        n = saved[0]  # the pair being saved is saved whole, and said
        # -o a<newline>b cut the line in two (escaped, as cli.py's lines name a path)
        print(
            f"stereovision: {what}: {_pairs(n)} saved in {escaped(args.output)} this run "
            f"{'is' if n == 1 else 'are'} kept; run "
            "again to add more",
            file=sys.stderr,
        )
        return EXIT_TERMINATED if isinstance(exc, Terminated) else EXIT_INTERRUPTED
    finally:
        bar.close()  # off the screen before the last words (or the error)
        cam.close()
    sk = result.skew
    # "delivered native size; left ..." read as no sentence: describe() names the sources
    print(
        f"{_pairs(len(result.saved))} saved in {escaped(args.output)} ({result.ended}); "
        f"{_pairs(result.frames_read)} read; sources: {cam.describe()}; "
        f"skew mean {sk['mean_ms']:.2f} ms, max {sk['max_ms']:.2f} ms"
    )
    return 0


def _pairs(n: int) -> str:
    """``1 pair``, ``2 pairs``: the CLI's counts ("1 pairs saved" read badly)."""
    return _counted(n, "pair")


def _counted(n: int, thing: str) -> str:
    """``1 frame``, ``0 frames``, ``2 frames``: a count said with its noun ("ended after 1
    frames", "after 1 images" read badly)."""
    return f"{n} {thing}" if n == 1 else f"{n} {thing}s"


def board_side(text: str) -> float:
    """argparse type of ``capture --square`` and ``--marker``: a finite number above 0, in any
    unit (the two in the same one: only their ratio finds the board). Refused in the option's
    name: ``25mm`` was "expected a number" (no word of the unit), ``nan`` the library's
    ``--charuco: square_size: ...``."""
    from stereovision.cli import _UNIT_SUFFIXED

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        hint = " without a unit (25 for 25 mm; " if _UNIT_SUFFIXED.match(text) else " ("
        raise argparse.ArgumentTypeError(
            f"expected a side above 0{hint}--square and --marker in one unit, any), got {text!r}"
        )
    return value


def _temporal_frames(text: str) -> int:
    """argparse type of ``capture --temporal``: a whole number, refused in the words of
    :func:`cmd_capture`'s range check (``8.5`` was "expected a whole number", ``1`` "expected
    2-255 frames a pair": two wordings of one refusal). The range is checked there."""
    from stereovision.cli import whole_number  # 8.0 too, as every whole-number option

    value = whole_number(text)
    if value is None:
        raise argparse.ArgumentTypeError(f"expected 2-255 frames a pair, got {text!r}")
    return value


def add_cli(subparsers: Any) -> None:
    """Register the ``capture`` subcommand on an ``argparse`` subparsers object."""
    from stereovision.cli import positive_count, positive_rate  # cli builds its parser with these

    p = subparsers.add_parser(
        "capture",
        help="capture stereo pairs from two cameras (or videos / image sequences / a ROS bag)",
        description="Save synchronised pairs; with --chessboard, only pairs with the board in "
        "both views and a new pose.",
    )
    add_source_args(p)
    p.add_argument(
        "--size",
        help="requested size WIDTHxHEIGHT (frames of the same shape are resized if needed; "
        "another shape keeps its own size, with a warning)",
    )
    p.add_argument("--fps", type=positive_rate, help="requested frame rate")
    p.add_argument("-o", "--output", required=True, help="output directory")
    p.add_argument(
        "--format",
        choices=("png", "tiff"),
        default="png",
        help="image format of the saved pairs: png (8 or 16 bits, default) or tiff (float32 "
        "frames too, a float TIFF sequence's)",
    )
    p.add_argument("--count", type=int, help="pairs to save (default: until a source ends)")
    p.add_argument("--chessboard", metavar="COLSxROWS", help="auto-capture distinct board poses")
    p.add_argument(
        "--charuco",
        metavar="COLSxROWS",
        help="auto-capture distinct poses of a ChArUco board of COLSxROWS squares",
    )
    p.add_argument(
        "--square",
        type=board_side,
        help="--charuco: square side, in any unit (only its ratio to --marker finds the board)",
    )
    p.add_argument("--marker", type=board_side, help="--charuco: marker side, in --square's unit")
    p.add_argument(
        "--dictionary", default="auto", help="--charuco: ArUco dictionary (default: found)"
    )
    p.add_argument(
        "--every",
        type=positive_count,
        default=1,
        help="without a board: save every Nth pair (default 1)",
    )
    p.add_argument(
        "--temporal",
        type=_temporal_frames,
        metavar="N",
        help="save each pair as the mean of N frames of a still view (low light; hold the "
        "board or rig still)",
    )
    p.set_defaults(func=cmd_capture)
