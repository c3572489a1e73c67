"""What the GUI reads: camera pairs (live, video, image sequences) and files from allowed folders.

Two safety rules of the GUI live here:

- :class:`AllowedFolders`: a path coming from the page is accepted only if, with every symbolic
  link and ``..`` resolved, it lies inside one of the folders named on the command line.
- Camera sources typed on the page are device indices, or files inside those folders.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from functools import partial
from pathlib import Path
from typing import Any, Protocol

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import escaped
from stereovision.capture import (
    DEFAULT_READ_TIMEOUT,
    _camera_device,
    _open_path,
    _open_within,
    _sequence_first,
    camera_hint,
    check_read_timeout,
    mask_url_secrets,
    read_within,
)
from stereovision.capture import parse_source as capture_parse_source
from stereovision.io import _opencv_quiet

__all__ = [
    "CLOUD_SUFFIXES",
    "IMAGE_SUFFIXES",
    "MAX_LISTED",
    "AllowedFolders",
    "FolderPairs",
    "StereoSource",
    "VideoPair",
    "display_path",
    "open_bag_source",
    "open_stereo_source",
    "parse_source",
]

#: File types offered by the page.
IMAGE_SUFFIXES = frozenset({".png", ".jpg", ".jpeg", ".bmp", ".ppm", ".pgm", ".tif", ".tiff"})
CLOUD_SUFFIXES = frozenset({".ply", ".pcd", ".npz"})
VIDEO_SUFFIXES = frozenset({".avi", ".mp4", ".mkv", ".mov", ".webm"})

#: At most this many files / scenes are listed per kind (a huge folder must not stall the page).
MAX_LISTED = 500

#: At most this many names of the folders walked are kept between the lists' refreshes
#: (:meth:`AllowedFolders._listed`): some 20 MB.
MAX_KEPT_NAMES = 300_000

#: A source's frame: BGR, ``uint16`` for a 16-bit image file or sequence (kept at its 16 bits,
#: as ``batch`` and ``capture`` read it), else ``uint8``.
Frame = npt.NDArray[np.uint8] | npt.NDArray[np.uint16]


def display_path(
    path: str | os.PathLike[str], cwd: Path | None = None, home: Path | None = None
) -> str:
    """How the page shows a folder or file: relative to the current directory when it is
    under it, else ``~``-abbreviated when it is under the home folder, else absolute.

    The save field showed the whole absolute path of the ``--data`` folder (a temporary
    ``/tmp/sv-ee05_o5h/scenes/saved`` in the README's picture).

    Parameters
    ----------
    path : path
        Absolute (a relative one is taken as relative to ``cwd``).
    cwd, home : Path, optional
        Default: the current directory and the user's home folder.

    Returns
    -------
    str

    Examples
    --------
    >>> display_path("/srv/scenes/saved", cwd=Path("/srv"), home=Path("/home/me"))
    'scenes/saved'
    >>> display_path("/home/me/scenes", cwd=Path("/srv"), home=Path("/home/me"))
    '~/scenes'
    >>> display_path("/mnt/x", cwd=Path("/srv"), home=Path("/home/me"))
    '/mnt/x'
    """
    if cwd is None:
        try:
            cwd = Path.cwd()
        except OSError:
            # the current folder was removed (a shell left in a build folder made again): the
            # GUI stopped at start-up with "[Errno 2] No such file or directory", naming nothing
            cwd = None
    if cwd is None:
        p = Path(os.path.normpath(path))
    else:
        p = Path(os.path.abspath(cwd / Path(path)))
        if p.is_relative_to(cwd) and cwd != Path(cwd.anchor):  # not "tmp/..." from "/"
            return p.relative_to(cwd).as_posix()
    try:
        home = Path.home() if home is None else home
    except RuntimeError:  # no home folder known
        return str(p)
    # as given and resolved: a HOME that is a symbolic link showed the resolved paths of the
    # home folder's saves whole
    for h in dict.fromkeys((home, Path(os.path.realpath(home)))):
        if p.is_relative_to(h) and h != Path(h.anchor):
            rel = p.relative_to(h).as_posix()
            return "~" if rel == "." else f"~/{rel}"
    return str(p)


def expand_home(text: str) -> Path:
    """``text`` as a path, a leading ``~`` expanded to the home folder.

    Raises
    ------
    ValueError
        ``text`` starts with ``~`` and no home folder is known (HOME unset, no password
        entry): Path.expanduser's RuntimeError went past the page's handlers, which said
        nothing. Or ``text`` starts with ``~user`` and no such user is known (it was said
        to be "HOME is not set", HOME set).
    """
    try:
        return Path(text).expanduser()
    except RuntimeError:
        user = Path(text).parts[0][1:]  # "~bob/x": "bob"; "~/x": ""
        why = f"no user {user} is known" if user else "HOME is not set"
        raise ValueError(
            f"no home folder is known for {text} ({why}): give the whole path"
        ) from None


def real_path(p: Path) -> Path:
    """``p`` with every symbolic link and ``..`` resolved (``Path.resolve``), as far as they
    lead: a link in a loop (``a.png -> b.png -> a.png``) is left where the loop was found,
    a path that does not exist, where Python 3.11's ``resolve`` raised RuntimeError("Symlink
    loop from ...") past the handlers (one such link in a ``--data`` folder stopped the GUI's
    start-up, listing its files)."""
    try:
        return p.resolve()
    except RuntimeError:
        return Path(os.path.realpath(p))


def _loop_note(p: Path) -> str:
    """`` (a link to b.png, one of a loop of links that never reaches a file)`` or `` (a link
    to moved/a.png, which does not exist)`` when ``p`` (as typed, not resolved) is a link that
    reaches no file, else ""."""
    with contextlib.suppress(OSError):
        os.stat(p)
        return ""
    with contextlib.suppress(OSError):
        if p.is_symlink():
            from stereovision.io import _broken_link

            # every such link, as --data's and the readers' words (e55e27d1): "loop" looked for
            # in the words noted a missing loops/a.png, and no other missing target
            return f" ({_broken_link(p)})"
    return ""


class AllowedFolders:
    """The folders the page may read files from, and the check that keeps it inside them.

    Parameters
    ----------
    roots : iterable of path
        Folders named on the command line (plus the bundled demo data). Each must exist.

    Raises
    ------
    FileNotFoundError
        If a root is not an existing folder.
    PermissionError
        If a root lies behind a folder this user may not enter.
    ValueError
        If a root is empty or blank (spaces naming no folder), or under the home folder of a
        user no one knows.
    """

    def __init__(self, roots: Iterable[str | os.PathLike[str]]) -> None:
        resolved: list[Path] = []
        for r in roots:
            text = os.fspath(r)
            if not text or not (text.strip() or os.path.isdir(text)):
                # an unset shell variable (--data "$SCENES") was the current folder: the page
                # listed, opened and saved into wherever the command was started (a folder
                # named with spaces, a legal name, is taken as the CLI takes it)
                raise ValueError(f"data folder: expected a folder, got {text!r}")
            # ~bob/x of an unknown user: said as the page says it (not "Could not determine
            # home directory.")
            p = expand_home(text)
            try:
                folder = p.is_dir()
            except PermissionError as exc:
                # behind a folder this user may not enter: "[Errno 13] Permission denied:
                # '/mnt/secret/data'" named a link's target alone, not the folder given
                to = f" (a link to {escaped(os.readlink(p))})" if os.path.islink(p) else ""
                raise PermissionError(
                    f"data folder cannot be read: {r}{to}: {exc.strerror}"
                ) from None
            if not folder:  # a file that is there was said only as "not found"
                there = " is a file, not a folder" if p.exists() else ""
                if not there and p.is_symlink():
                    from stereovision.io import _broken_link

                    # a link whose target moved (a dataset on a disk since unmounted) was "not
                    # found" alone, of a name ls lists: its target named, as load_scene's is
                    there = f" ({_broken_link(p)})"
                raise FileNotFoundError(f"data folder not found: {r}{there}")
            rp = p.resolve()
            if rp not in resolved:
                resolved.append(rp)
        self.roots: tuple[Path, ...] = tuple(resolved)
        # Each root's display name: its folder name, with as many parents as make it unique
        # (the bundled ".../stereovision/data" and a user's ".../shared/data" both read "data").
        self._names: dict[Path, str] = {}
        for r in self.roots:
            depth = 1
            while (
                depth < len(r.parts)
                and sum(o.parts[-depth:] == r.parts[-depth:] for o in self.roots) > 1
            ):
                depth += 1
            # Path(), not "/".join: a root at the top keeps its anchor ("/data", not "//data").
            self._names[r] = Path(*r.parts[-depth:]).as_posix()
        #: Each folder walked: its mtime, sub-folders to walk and file names (:meth:`_listed`).
        self._listing: dict[str, tuple[int, list[str], list[str]]] = {}
        self._kept_names = 0  # names held in _listing

    def resolve(self, path: str | os.PathLike[str]) -> Path:
        """The real path of ``path`` if it lies inside an allowed folder.

        A relative path is taken under the first root where it is (the first root when it is
        under none): as the page's lists name files (``<root label>/...``), relative to a root,
        or to the current folder (as the page's messages show paths). Symbolic links and
        ``..`` are resolved before the check, so neither can lead outside.

        Raises
        ------
        ValueError
            If the resolved path is outside every allowed folder (or empty).
        FileNotFoundError
            If it is inside but does not exist.
        PermissionError
            If it is inside, behind a folder this user may not enter.
        """
        text = os.fspath(path)
        if not text or "\x00" in text:
            raise ValueError("empty or invalid path")
        p = expand_home(text)
        # a stream URL typed: its password is not said; a newline in a name typed, escaped (it
        # cut the page's one-line error there: "no such file: a" for a\nb.png)
        said = escaped(mask_url_secrets(text))
        if not p.is_absolute():
            if not self.roots:
                raise ValueError(f"path outside the allowed folders: {said}")
            p = self._under_a_root(p)
        real = real_path(p)
        if not any(real == r or real.is_relative_to(r) for r in self.roots):
            raise ValueError(f"path outside the allowed folders: {said}")
        try:
            there = real.exists()
        except PermissionError as exc:
            # behind a folder this user may not enter: Python's "[Errno 13] Permission denied:
            # '/data/secret/x.png'" named neither what was typed nor that a link led there
            to = f" (a link to {escaped(os.readlink(p))})" if os.path.islink(p) else ""
            raise PermissionError(f"cannot read {said}{to}: {exc.strerror}") from None
        if not there:
            raise FileNotFoundError(f"no such file: {said}{_loop_note(p)}")
        return real

    def _under_a_root(self, p: Path) -> Path:
        """The relative path ``p`` under the first root it is in (that root's lists label it
        so, or it is relative to the root or to the current folder), else under the first
        root. Only the first root was tried: with ``--data`` that is the bundled demo data, so
        a pattern typed in a camera field ("seq/left%02d.png") or a file name as the lists
        show it ("data/seq/left01.png") was "no such file" of a file in the ``--data``
        folder."""
        found = [r / p for r in self.roots]
        for r in self.roots:  # as the page's lists name it: the root's label, then the rest
            label = Path(self._names[r]).parts
            if p.parts[: len(label)] == label:
                found.append(r.joinpath(*p.parts[len(label) :]))
        with contextlib.suppress(OSError):  # no current folder (removed): not tried
            found.append(Path.cwd() / p)
        for c in found:
            real = real_path(c)
            if os.path.lexists(c) and any(real == r or real.is_relative_to(r) for r in self.roots):
                return c
        return found[0]

    def resolve_output(
        self, path: str | os.PathLike[str], roots: Sequence[Path] | None = None
    ) -> Path:
        """The real path of a folder the page writes into (it need not exist yet).

        Parameters
        ----------
        path : path
            As typed on the page; relative to the first of ``roots``.
        roots : sequence of Path, optional
            The folders writing is allowed in (default: all of :attr:`roots`).

        Raises
        ------
        ValueError
            Empty, outside every one of ``roots`` (symbolic links and ``..`` resolved), or no
            such root at all.
        """
        allowed = tuple(self.roots if roots is None else roots)
        text = os.fspath(path) if path is not None else ""
        if not text.strip() or "\x00" in text:
            raise ValueError("empty or invalid folder")
        if not allowed:
            raise ValueError("no folder to write into: start the GUI with --data DIR")
        p = expand_home(text.strip())
        if not p.is_absolute():
            p = allowed[0] / p
        real = real_path(p)  # the existing part's links resolved, the rest as written
        if not any(real == r or real.is_relative_to(r) for r in allowed):
            raise ValueError(f"folder outside the --data folders: {escaped(text)}")
        return real

    def contains(self, path: str | os.PathLike[str]) -> bool:
        """True if :meth:`resolve` accepts ``path``."""
        try:
            self.resolve(path)
        except (ValueError, OSError):
            return False
        return True

    def _listed(self, folder: str) -> tuple[list[str], list[str]]:
        """The sorted sub-folders to walk (not hidden, not links) and file names of ``folder``,
        as ``os.walk`` finds them, kept while the folder's mtime stays (an entry added, removed
        or renamed changes it): the page's lists walked a 45k-file ``--data`` folder three
        times per refresh, in its loop (1.4 s, the page frozen). An unreadable folder lists
        nothing, as ``os.walk`` passes it over."""
        try:
            mtime = os.stat(folder).st_mtime_ns
        except OSError:
            return [], []
        kept = self._listing.get(folder)
        if kept is not None and kept[0] == mtime:
            return kept[1], kept[2]
        subs: list[str] = []
        names: list[str] = []
        try:
            with os.scandir(folder) as entries:
                for e in entries:
                    try:  # a link to a folder is not walked (nor a file): os.walk's rule
                        is_dir = e.is_dir()
                    except OSError:
                        is_dir = False
                    if not is_dir:
                        names.append(e.name)
                    elif not e.name.startswith(".") and not e.is_symlink():
                        subs.append(e.name)
        except OSError:
            return [], []
        subs.sort()
        names.sort()
        # a folder changed within the last 2 s may change again within its mtime's tick
        # (1 s or 2 s on some file systems): read again next time
        # (and at most MAX_KEPT_NAMES names in all: a --data of millions of files is read
        # each time, as before, not held in memory)
        kept_names = self._kept_names - (len(kept[1]) + len(kept[2]) if kept else 0)
        if time.time_ns() - mtime > 2_000_000_000:
            if kept_names + len(subs) + len(names) <= MAX_KEPT_NAMES:
                self._listing[folder] = (mtime, subs, names)
                self._kept_names = kept_names + len(subs) + len(names)
        return subs, names

    def _tree(self, root: Path) -> Iterator[tuple[str, list[str]]]:
        """``(folder, file names)`` of ``root`` and every folder below it, top-down in sorted
        order (hidden folders and links to folders left out), as ``os.walk`` walked it."""
        stack = [str(root)]
        while stack:
            folder = stack.pop()
            subs, names = self._listed(folder)
            yield folder, names
            stack.extend(os.path.join(folder, d) for d in reversed(subs))

    def _walk(self, suffixes: frozenset[str]) -> list[Path]:
        found: list[Path] = []
        seen: set[Path] = set()
        ends = tuple(suffixes)
        for root in self.roots:
            for dirpath, filenames in self._tree(root):
                for name in filenames:
                    # the suffix of the name as a string (its end first: cheaper still): a
                    # Path made of each of a 45k-file folder's names took 1 s
                    low = name.lower()
                    if low.endswith(ends) and os.path.splitext(low)[1] in suffixes:
                        p = Path(dirpath) / name
                        # Not twice: a root may lie inside another (``--data .`` of a checkout
                        # holds the bundled data). A symlink may point outside; another file
                        # is inside (no linked folder is walked): resolving each of 500 files
                        # took 0.15 s
                        inside = not os.path.islink(p) or self.contains(p)
                        if p not in seen and inside:
                            seen.add(p)
                            found.append(p)
                            if len(found) >= MAX_LISTED:
                                return found
        return found

    def files(self, suffixes: frozenset[str]) -> list[Path]:
        """Files with one of ``suffixes`` under the roots (sorted, at most :data:`MAX_LISTED`)."""
        return self._walk(suffixes)

    def scenes(self) -> list[Path]:
        """Scene folders (``left.png`` + ``right.png``) under the roots (sorted, at most
        :data:`MAX_LISTED`).

        The limit counts scenes: it counted PNG files, so a folder of calibration pairs listed
        first (500 images) left no scene after it in the list.
        """
        found: set[Path] = set()
        for root in self.roots:
            for dirpath, filenames in self._tree(root):
                d = Path(dirpath)
                names = set(filenames)
                if {"left.png", "right.png"} <= names and all(
                    self.contains(d / n) for n in ("left.png", "right.png")
                ):
                    found.add(d)
                    if len(found) >= MAX_LISTED:
                        return sorted(found)
        return sorted(found)

    def folders(self) -> list[Path]:
        """The roots and the folders directly in them (an image folder to play), sorted, at
        most :data:`MAX_LISTED`."""
        found: list[Path] = []
        for root in self.roots:
            found.append(root)
            try:
                subs = sorted(
                    p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")
                )
            except OSError:
                continue
            found += [p for p in subs if self.contains(p)]
        # A root inside another is also one of its sub-folders: listed once, where first met.
        return list(dict.fromkeys(found))[:MAX_LISTED]

    def label(self, path: Path) -> str:
        """Short display name: ``<root name>/<relative path>``."""
        for r in self.roots:
            if path == r or path.is_relative_to(r):
                rel, name = path.relative_to(r), self._names[r]
                return (Path(name) / rel).as_posix()  # "/" + "etc": "/etc", not "//etc"
        return path.name


# ----------------------------------------------------------------------------- camera pairs


class StereoSource(Protocol):
    """A pair of synchronised image sources."""

    def read(self) -> tuple[Frame, Frame]:
        """Grab a new (left, right) BGR pair (:data:`Frame`)."""
        ...

    def close(self) -> None:
        """Release the devices / files."""
        ...


def parse_source(text: str | int) -> int | str:
    """A camera source: an integer device index, or a video file / image-sequence pattern.

    Raises
    ------
    ValueError
        Empty, a bool, or a negative index (``-1``, ``"-1"``, a NumPy ``-1``), refused as
        :func:`stereovision.capture.parse_source` refuses them: :class:`VideoPair` passed -1 on
        to ``cv2.VideoCapture``, which crashes the process where no camera is present.
    """
    if isinstance(text, (bool, np.bool_, int, np.integer)):
        return capture_parse_source(text)
    s = str(text).strip()
    if not s:
        raise ValueError("empty camera source")
    return capture_parse_source(s)


def _ask_size(size: tuple[int, int], cap: Any, doing: Callable[[str], None]) -> None:
    """Ask an opened device ``cap`` for ``size`` (a :func:`_open_within` ``configure``)."""
    if cap.isOpened():
        doing(f"setting its frame width to {size[0]}")
        cap.set(cv2.CAP_PROP_FRAME_WIDTH, size[0])
        doing(f"setting its frame height to {size[1]}")
        cap.set(cv2.CAP_PROP_FRAME_HEIGHT, size[1])


def _is_file(src: int | str) -> bool:
    """Whether source ``src`` (as :func:`parse_source` gives it) is a file or image sequence,
    which ends and is started again, not a live source: a stream URL (``rtsp://``, ``http://``)
    or a camera's device node (``/dev/video2``, a ``/dev/v4l/by-id/...`` link,
    :func:`~stereovision.capture._camera_device`) has no end to rewind."""
    return isinstance(src, str) and "://" not in src and _camera_device(src) is None


def _open_capture(src: int | str, first: tuple[int, str] | None) -> Any:
    """A device, a video file or an image-sequence pattern (``first``: its first file,
    :func:`~stereovision.capture._sequence_first`) opened as ``stereovision capture`` and
    ``stream`` open them (:func:`stereovision.capture._open_path`): a sequence whose first
    number is 5 or more, or that OpenCV's image reader refuses, is read by
    :class:`~stereovision.capture._ImageSequence`. ``cv2.VideoCapture`` alone did not open
    such a sequence (FFmpeg's image2 looks at numbers 0-4 for its first file)."""
    if isinstance(src, str):
        return _open_path(src, first)
    return cv2.VideoCapture(src)


class VideoPair:
    """Two :class:`cv2.VideoCapture` sources read together (fallback when ``stereovision.capture``
    is not available).

    Video files and image sequences start again from their first frame when one of them ends
    (both together, so files of unequal lengths stay in step), so a recorded pair behaves like a
    camera that never stops.

    Parameters
    ----------
    left, right : int or str
        Device index or node (``/dev/video0``), stream URL, video file, or image-sequence
        pattern (``"img_%03d.png"``), opened as ``stereovision capture`` opens it (a sequence
        may start at any number).
    size : (int, int), optional
        Requested ``(width, height)`` for devices (by index or node).
    open_timeout : float or None
        Seconds each open, with the size asked of a device, may take (None: no limit), as
        :class:`~stereovision.capture.StereoCamera`'s.

    Raises
    ------
    FileNotFoundError
        A file source that does not exist.
    OSError
        A source OpenCV cannot open (``"cannot open camera ..."``), that does not open within
        ``open_timeout`` (:class:`~stereovision.capture.SourceError`) or that gives no frame.
    """

    def __init__(
        self,
        left: int | str,
        right: int | str,
        size: tuple[int, int] | None = None,
        open_timeout: float | None = DEFAULT_READ_TIMEOUT,
    ) -> None:
        check_read_timeout(open_timeout, "open_timeout")
        self._caps: list[cv2.VideoCapture] = []
        self._files = []
        #: Which sources are image sequences: their reader logs a warning for the file after
        #: the last, kept quiet; a camera's or video's warnings are not.
        self._sequence: list[bool] = []
        try:
            for side, src in (("left", left), ("right", right)):
                src = parse_source(src)
                # Text is a file only when it is no URL nor camera device node: a stream
                # (rtsp://cam/0) was refused as "camera source not found", a /dev/video2 was
                # not asked the size and its missing frame was taken for a file's end.
                device = not isinstance(src, str) or _camera_device(src) is not None
                is_file = _is_file(src)
                if is_file and "%" not in str(src) and not Path(str(src)).exists():
                    from stereovision.io import _broken_link

                    # a link whose target moved: its target named, as StereoCamera names it
                    link = Path(str(src))
                    gone = f" ({_broken_link(link)})" if link.is_symlink() else ""
                    raise FileNotFoundError(
                        f"{side} camera source not found: {mask_url_secrets(str(src))}{gone}"
                    )
                # bounded, the size asked with it: a wedged device hung its open, or a set,
                # forever (OpenCV's log of the open stays quiet: the error below says what failed)
                configure = None if size is None or not device else partial(_ask_size, size)
                first = _sequence_first(src) if isinstance(src, str) else None
                cap = _open_within(
                    partial(_open_capture, src, first), open_timeout, side, src, configure
                )
                if not cap.isOpened():
                    cap.release()
                    # a stream's password is not said (the page shows it, the server logs it)
                    name = mask_url_secrets(src) if isinstance(src, str) else src
                    raise OSError(f"cannot open camera {name!r} ({side}){camera_hint(src)}")
                self._caps.append(cap)
                self._files.append(is_file)
                self._sequence.append(first is not None)
        except BaseException:
            self.close()
            raise
        self.sources = (left, right)

    def _name(self, i: int) -> int | str:
        """Source ``i`` as said in an error: a stream's password masked."""
        src = self.sources[i]
        return mask_url_secrets(src) if isinstance(src, str) else src

    def _decode(self, i: int, grabbed: bool) -> npt.NDArray[np.uint8] | None:
        """Source ``i``'s grabbed frame; None when it is a file that ended."""
        ok, frame = self._caps[i].retrieve() if grabbed else (False, None)
        if not ok or frame is None:
            if self._files[i]:
                return None
            raise OSError(f"camera {self._name(i)!r} gave no frame")
        if frame.ndim == 2:
            frame = cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR)
        # in its own type, as the capture path gives it: a 16-bit sequence's frame was cast to
        # uint8, its levels wrapped modulo 256 (300 read as 44)
        return np.ascontiguousarray(frame)

    def _pair(self) -> tuple[npt.NDArray[np.uint8] | None, npt.NDArray[np.uint8] | None]:
        # Both grabbed before either is decoded: read() one after the other took the right
        # frame a whole decode later than the left.
        # Only a sequence's grab is quiet: OpenCV's log level is process-wide, and both grabs
        # quiet silenced a camera's or video's own warnings (and every thread's meanwhile).
        grabbed = []
        for cap, sequence in zip(self._caps, self._sequence, strict=True):
            with _opencv_quiet() if sequence else contextlib.nullcontext():
                grabbed.append(cap.grab())
        return self._decode(0, grabbed[0]), self._decode(1, grabbed[1])

    def read(self) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
        """Grab both, then decode both (keeps the pair as close in time as OpenCV allows)."""
        if not self._caps:
            raise OSError("camera pair is closed")
        left, right = self._pair()
        if left is None or right is None:
            # Every file starts again when one ends: files of unequal lengths, each started
            # again on its own, paired frames of different times from then on.
            for cap, is_file in zip(self._caps, self._files, strict=True):
                if is_file:
                    cap.set(cv2.CAP_PROP_POS_FRAMES, 0)
            left, right = self._pair()
        if left is None:
            raise OSError(f"camera {self._name(0)!r} gave no frame")
        if right is None:
            raise OSError(f"camera {self._name(1)!r} gave no frame")
        return left, right

    def close(self) -> None:
        """Release both captures."""
        for cap in self._caps:
            cap.release()
        self._caps = []


class _CaptureAdapter:
    """Wraps ``stereovision.capture.StereoCamera`` into :class:`StereoSource`.

    When both sources are files (videos, image sequences) and one ends, the pair is opened again
    from the start, like :class:`VideoPair`; a camera or stream (by index, device node or URL)
    that ends raises what ``StereoCamera`` says of it. A read is given up after
    ``read_timeout`` seconds (:func:`~stereovision.capture.read_within`; None: no limit).
    """

    def __init__(
        self,
        factory: Any,
        files: bool,
        read_timeout: float | None = None,
        sources: tuple[int | str, ...] = (),
    ) -> None:
        self._factory = factory
        #: The sources as opened (the page shortens their paths in what it says of them).
        self.sources = sources
        self._files = files
        self._read_timeout = read_timeout
        self._camera = factory()
        #: What ``StereoCamera`` said of a file that ended early when the last read started the
        #: files again (a gap in a numbered sequence, a video shorter than the other); None
        #: when it did not, or they ended together.
        self.restarted: str | None = None

    def read(self) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
        self.restarted = None
        try:
            return self._read()
        except OSError as exc:
            # a file's end starts it again; a read given up as hung (or refused after one) is
            # no end: opening the device again doubled the wait on it
            if not self._files or getattr(exc, "end", True) is False:
                raise
            self.close()
            self._camera = self._factory()
            got = self._read()
            if getattr(exc, "ended_early", False):
                # the images after a gap (left10.jpg deleted: 11-14 never shown), a longer
                # video's end: started again without a word, where capture and stream say it
                self.restarted = str(exc)
            return got

    def _read(self) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
        # bounded as capture's and stream's reads are: a hung camera froze the page for good
        got = read_within(self._camera, self._read_timeout)
        if isinstance(got, tuple) and len(got) == 2:
            left, right = got
        elif isinstance(got, tuple) and len(got) == 3 and isinstance(got[0], bool):
            ok, left, right = got
            if not ok:
                raise OSError("camera pair gave no frame")
        else:
            left, right = got.left, got.right
        return np.asarray(left), np.asarray(right)

    def notes(self) -> list[str]:
        """What the source's open warned of that concerns every pair, for the page to say (the
        warning went to the server's log alone): two image sequences that start at different
        numbers, paired in order (:func:`~stereovision.capture._paired_in_order_note`)."""
        from stereovision.capture import _paired_in_order_note

        note = _paired_in_order_note(self._camera)
        return [] if note is None else [note]

    def close(self) -> None:
        for name in ("close", "release"):
            fn = getattr(self._camera, name, None)
            if callable(fn):
                fn()
                return


class FolderPairs:
    """The left/right pairs of an image folder, one per read, starting again after the last.

    The pairs are those ``stereovision batch`` finds (:func:`stereovision.batch.find_pairs`):
    ``left_0001.png`` + ``right_0001.png`` as ``capture`` saves them, ``left/`` + ``right/``
    (or ``image_2/`` + ``image_3/``, ``cam0/`` + ``cam1/``) camera folders, scene folders.

    Parameters
    ----------
    folder : path
        The folder (any depth below it is searched).
    name : str
        What the page calls the folder.
    keep : callable, optional
        Keeps a pair only if it returns True for each of its files (the GUI: inside the allowed
        folders, so that a symbolic link cannot lead out).

    Raises
    ------
    FileNotFoundError, NotADirectoryError
        No such folder.
    ValueError
        No pair in it.
    """

    def __init__(self, folder: str | os.PathLike[str], name: str, keep: Any = None) -> None:
        from stereovision.batch import find_pairs

        jobs = find_pairs(folder)
        if keep is not None:
            jobs = [j for j in jobs if all(keep(p) for p in (j.left, j.right, j.calib) if p)]
        if not jobs:
            raise ValueError(
                f"no image pairs in {name} (left_0001.png + right_0001.png, left/ + right/ "
                "folders, or scene folders with left.png + right.png)"
            )
        self.jobs = jobs
        self.name = name
        self.folder = Path(folder)
        self.index = -1

    @property
    def current(self) -> Any:
        """The :class:`~stereovision.batch.PairJob` last read (None before the first read)."""
        return self.jobs[self.index] if self.index >= 0 else None

    def read(self) -> tuple[Frame, Frame]:
        """The next pair (BGR, a 16-bit pair at its 16 bits as ``batch`` reads it: ``uint16``,
        else ``uint8``), after the last one the first again.

        Raises
        ------
        FileNotFoundError, OSError, ValueError
            A file of the pair removed or changed since the folder was played, said with the
            pair (:meth:`describe`) and the file's path from the folder's ``name``; the next
            read goes on with the next pair.
        """
        from stereovision.io import read_image

        self.index = (self.index + 1) % len(self.jobs)
        job = self.jobs[self.index]
        try:
            # uint16 for a 16-bit pair, as a 16-bit sequence's frames are (_decode): the page
            # matches such a pair as it is and shows it at 8 bits
            return read_image(job.left), read_image(job.right)
        except (OSError, ValueError) as exc:
            raise self.said_of_pair(exc) from exc

    def said_of_pair(self, exc: OSError | ValueError) -> Exception:
        """``exc``, raised reading the pair last read (a file of it, its scene's calibration),
        as the page says it: with the pair (:meth:`describe`) and the file's path from the
        folder's ``name``.

        The file's whole path alone ("image file not found: /srv/data/seq/right_0002.png")
        was said under the previous pair's label, the next Capture going on to the pair after
        it: which pair was skipped went unsaid.

        Parameters
        ----------
        exc : OSError or ValueError
            As the file's reader raised it.

        Returns
        -------
        Exception
            Of the same kind: a FileNotFoundError, another OSError, or a ValueError.
        """
        said = str(exc).replace(str(self.folder) + os.sep, self.name.rstrip("/") + "/")
        said = f"{self.describe()}: {said}"
        if isinstance(exc, FileNotFoundError):
            return FileNotFoundError(said)
        return OSError(said) if isinstance(exc, OSError) else ValueError(said)

    def describe(self) -> str:
        """``folder data/seq: pair 0002 (2 of 20)``."""
        job = self.current
        if job is None:
            return f"folder {self.name}"
        return f"folder {self.name}: pair {job.name} ({self.index + 1} of {len(self.jobs)})"

    def close(self) -> None:
        """Nothing to release (files are read per pair)."""


def open_stereo_source(
    left: int | str,
    right: int | str,
    size: tuple[int, int] | None = None,
    fourcc: str | None = None,
    read_timeout: float | None = DEFAULT_READ_TIMEOUT,
    bound_open: bool = True,
) -> StereoSource:
    """Open a camera pair: ``stereovision.capture.StereoCamera`` if available, else OpenCV.

    Parameters
    ----------
    left, right : int or str
        Device index or node (``/dev/video0``), stream URL, video file or image-sequence
        pattern. A pair of files starts again when one ends; a camera or stream that ends is
        an error.
    size : (int, int), optional
        Requested ``(width, height)``.
    fourcc : str, optional
        Pixel format asked of the cameras (``"MJPG"``, ``"YUYV"``; None: the driver's), as
        ``stereovision capture --fourcc``: two webcams on one USB 2 bus often need MJPG.
    read_timeout : float or None
        Seconds a camera's open or a pair's read may take before the camera is given up as
        hung (:data:`~stereovision.capture.DEFAULT_READ_TIMEOUT`; None: no limit), as
        ``capture``'s and ``stream``'s ``--read-timeout``.
    bound_open : bool
        False: the open is not bounded here, the caller bounds it (the page waits for an open
        running in a thread of its own, and knows when a given-up open returns).

    Raises
    ------
    FileNotFoundError, OSError, ValueError
        A source that does not exist or cannot be opened.
    """
    left, right = parse_source(left), parse_source(right)
    open_timeout = read_timeout if bound_open else None
    try:
        from stereovision.capture import StereoCamera, parse_fourcc
    except ImportError:
        return VideoPair(left, right, size, open_timeout)
    code = parse_fourcc(fourcc)
    # only files start again: a stream or a device node (any text was a "file") that stopped
    # was opened again silently, its end said as nothing (VideoPair's rule, 73cb4e7)
    files = _is_file(left) and _is_file(right)
    first = [True]

    def make() -> StereoCamera:
        # only the first open is the caller's to bound: a file opened again at its end, in a
        # read, is bounded as the read is
        timeout = open_timeout if first[0] else read_timeout
        first[0] = False
        return StereoCamera(left, right, image_size=size, fourcc=code, open_timeout=timeout)

    return _CaptureAdapter(make, files, read_timeout, sources=(left, right))


def scale_pair(
    left: npt.NDArray[Any], right: npt.NDArray[Any], width: int | None
) -> tuple[npt.NDArray[Any], npt.NDArray[Any], float]:
    """Resize both images to ``width`` pixels wide (never up); returns the scale factor too.
    The images keep their type (a 16-bit pair stays 16-bit)."""
    w = left.shape[1]
    if width is None or width >= w:
        return left, right, 1.0
    s = width / w
    size = (width, max(1, round(left.shape[0] * s)))
    # in the images' own type: a 16-bit pair (a 16-bit PNG sequence) was cast to uint8, its
    # levels wrapped modulo 256, and matched as noise at 640 or 320 px
    return (
        np.asarray(cv2.resize(left, size, interpolation=cv2.INTER_AREA), dtype=left.dtype),
        np.asarray(cv2.resize(right, size, interpolation=cv2.INTER_AREA), dtype=right.dtype),
        s,
    )


def scaled_calibration(calib: Any, factor: float, size: Sequence[int]) -> Any:
    """``calib`` for images scaled by ``factor`` to ``size = (width, height)``
    (:meth:`~stereovision.calibration.Calibration.scaled_to`, from the exact size ratio)."""
    if calib is None or factor == 1.0:
        return calib
    return calib.scaled_to((int(size[0]), int(size[1])))


def open_bag_source(
    path: str | os.PathLike[str], left_topic: str | None = None, right_topic: str | None = None
) -> tuple[StereoSource, Any, tuple[str, str]]:
    """A rig recorded in a ROS bag, played like a camera pair that starts again at the end.

    Returns
    -------
    source : StereoSource
    calibration : Calibration or None
        From the bag's ``camera_info`` (None when it has none).
    names : tuple of str
        The two image topics (the page's camera fields show them).

    Raises
    ------
    FileNotFoundError, ValueError, ImportError
        As :class:`stereovision.rosbag.BagCamera` (no bag, no stereo topics, no ``rosbags``).
    """
    from stereovision.rosbag import BagCamera

    def factory() -> BagCamera:
        return BagCamera(path, left_topic=left_topic, right_topic=right_topic)

    with factory() as probe:
        calib = probe.calibration()
        names = (probe.topics["left"], probe.topics["right"])
    return _CaptureAdapter(factory, files=True), calib, names
