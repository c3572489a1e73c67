"""Reading and writing images, PFM disparity maps, PLY point clouds and evaluation scenes.

Every writer in this module writes atomically: the data goes to a temporary file in the
destination directory which then replaces the destination with :func:`os.replace`, so a reader
never sees a half-written file and an interrupted write leaves the previous file intact.

Scene layout (evaluation.md)::

    <scene>/left.png  right.png   rectified pair, 8-bit
    <scene>/gt_disp.pfm           GT disparity of the left image (pixels, +inf = unknown)
    <scene>/calib.txt             Middlebury-style calibration (optional)
    <scene>/Q.dat                 else OpenCV's 4x4 Q matrix, baseline in metres (optional)
"""

from __future__ import annotations

import errno
import math
import os
import re
import stat
import tempfile
import threading
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import NOT_NUMBERS, as_path, escaped
from stereovision.baselines import round_up16

if TYPE_CHECKING:
    from stereovision.calibration import Calibration

__all__ = [
    "MAX_DISPARITY_MARGIN",
    "PLY_CLOUD_COMMENT",
    "Scene",
    "atomic_write",
    "decode_image",
    "find_scenes",
    "imread",
    "load_scene",
    "read_image",
    "read_pfm",
    "read_ply",
    "scene_max_disparity",
    "scene_too_narrow",
    "write_pfm",
    "write_ply",
]

PathLike = str | os.PathLike[str]

#: evaluation.md: every method searches ``1.1 x`` the largest finite GT disparity, rounded up to
#: a multiple of 16 (so OpenCV's matchers accept it).
MAX_DISPARITY_MARGIN = 1.1

#: Fallback search range without GT or calibration: a quarter of the image width.
_WIDTH_FRACTION = 4


def _current_umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _mode_for(dest: Path) -> int:
    """The permissions a new ``dest`` gets: those of the file it replaces, as ``open(dest, "w")``
    keeps them (a private 0600 file came back 0644), else a plain open()'s (not mkstemp's 0600).
    """
    try:
        st = os.stat(dest)
    except OSError:  # none yet (or unreadable: replaced all the same)
        return 0o666 & ~_current_umask()
    # permission bits only: a set-user-ID bit is not carried to new contents
    return st.st_mode & 0o777 if stat.S_ISREG(st.st_mode) else 0o666 & ~_current_umask()


def make_folder(path: PathLike) -> Path:
    """``mkdir -p``, with an error that names the file in the way (``mkdir`` says only
    "[Errno 17] File exists" with the file's name, or "Not a directory").

    Parameters
    ----------
    path : str or os.PathLike
        The folder to create, with any missing folders above it.

    Returns
    -------
    pathlib.Path
        The folder.

    Raises
    ------
    NotADirectoryError
        If ``path`` or a folder above it is a file, a FIFO, or a link to nothing or in a loop.
    """
    folder = as_path(path)  # bytes: pathlib's TypeError named no argument
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        if exc.errno not in (errno.EEXIST, errno.ENOTDIR, errno.ELOOP):
            raise
        # the one in the way, deepest first: a link to nothing (or a FIFO) was not is_file(),
        # so the folder asked for was named "a file" ("out/sub is a file" of no file at all)
        blocker = next((p for p in (folder, *folder.parents) if _not_a_folder(p)), None)
        if blocker is None:  # gone again since (a race): the system's own words
            raise
        raise NotADirectoryError(
            f"cannot make the folder {folder}: {blocker} is {_not_a_folder(blocker)}"
        ) from None
    return folder


def _not_a_folder(path: Path) -> str:
    """What ``path`` is when something other than a folder stands there (``"a file, not a
    folder"``, a link to nothing or in a loop, ``"not a folder"``), else ``""``."""
    if path.is_symlink() and not path.exists():
        return _broken_link(path)
    if not path.exists() or path.is_dir():
        return ""
    return "a file, not a folder" if path.is_file() else "not a folder"


def missing_folders(path: PathLike) -> list[Path]:
    """The folders :func:`make_folder` would create for ``path``, ``path`` first, each as an
    absolute path: a command that fails before writing anything removes them again (deepest
    first, each only when empty) and leaves no empty folder behind.

    A ``..`` is not a folder ``mkdir -p`` makes (``new/../out`` makes ``new`` and ``out``), so
    it is skipped, and removing one (``rmdir new/..``) would fail and keep ``new``.

    Parameters
    ----------
    path : str or os.PathLike
        The folder about to be made.

    Returns
    -------
    list of pathlib.Path
        The folders that do not exist yet.
    """
    missing = []
    folder = Path(path).absolute()
    while not folder.exists() and not folder.is_symlink() and folder != folder.parent:
        if folder.name != "..":
            missing.append(folder)
        folder = folder.parent
    return missing


def lock_folder(folder: PathLike) -> tuple[int | None, bool]:
    """An exclusive ``flock`` on ``folder`` itself (no file is left in it; the system releases
    it when the process ends, killed or not), without waiting.

    Parameters
    ----------
    folder : str or os.PathLike
        The folder to lock.

    Returns
    -------
    fd : int or None
        The locked descriptor (closing it releases the lock); None when not locked.
    busy : bool
        True when another process holds the lock; False when it is ours, or when the system or
        filesystem cannot lock (Windows, some network filesystems: ``fd`` None).
    """
    try:
        import fcntl
    except ImportError:  # Windows
        return None, False
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return None, False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as exc:
        os.close(fd)
        return None, isinstance(exc, BlockingIOError)
    return fd, False


def remove_empty_folders(folders: Sequence[Path]) -> None:
    """Remove ``folders`` (:func:`missing_folders`' list, deepest first) while each is empty:
    the first that holds anything, and every folder above it, stay.

    Parameters
    ----------
    folders : sequence of pathlib.Path
        The folders a command made, deepest first.
    """
    for folder in folders:
        try:
            folder.rmdir()
        except OSError:  # not empty (something else in it), or gone already
            if folder.exists():
                return


def refuse_an_input(flag: str, output: Path, inputs: dict[str, str | None]) -> None:
    """Refuse an output path that names one of the run's input files.

    Parameters
    ----------
    flag : str
        The option that names ``output`` (``--plot``), for the message.
    output : pathlib.Path
        The file about to be written.
    inputs : dict
        What each input is (``"the left image"``) -> its path as given (None: not given).

    Raises
    ------
    ValueError
        If ``output`` is one of ``inputs`` (the same file, through any link or spelling).
    """
    for what, given in inputs.items():
        if not given:
            continue
        try:
            same = os.path.samefile(output, given)
        except OSError:  # one of them does not exist (yet): compare the spelled-out paths
            same = output.resolve() == Path(given).resolve()
        if same:
            raise ValueError(f"{flag} {output}: is {what} ({given}); give another file name")


def check_output_folder(folder: PathLike, flag: str) -> None:
    """A folder a command will create (or fill), checked before its work: refused if a file
    stands in its way or the nearest existing folder above it is not writable.

    Parameters
    ----------
    folder : str or os.PathLike
        The output folder (it need not exist yet).
    flag : str
        How the user gave it (``"-o"``, ``"--report"``), for the message.

    Raises
    ------
    ValueError
        If ``folder`` is the text ``-`` (standard output, to many tools: a folder of files
        cannot go there; ``./-`` or ``Path("-")`` is a folder), or it or a folder above it is
        a file (or a FIFO: "not a folder") or a link to nothing (or in a loop).
    PermissionError
        If the nearest existing folder above it is not writable.
    """
    if isinstance(folder, str) and folder == "-":
        # `-o -` made a folder named "-" and said "-/disparity.png", where the user meant stdout.
        # The text as typed only: Path("./-") is Path("-"), and `-o ./-` names a folder
        raise ValueError(
            f"{flag} -: the outputs are files in a folder, not a stream for standard output: "
            "name a folder"
        )
    home = _unexpanded_home(folder)
    if home is not None:
        # `--output=~/out` (bash expands no ~ after "=", nor in quotes) made a folder named "~"
        # in the current one; ./~/out still names such a folder
        raise ValueError(
            f"{flag} {folder}: ~ is not expanded here (the shell leaves it as typed after '=' "
            f"or in quotes): give {escaped(home)}, or ./{folder} for a folder named ~"
        )
    path = Path(folder)
    if path.exists() and not path.is_dir():
        # a FIFO is no file either: "not a folder", as make_folder says it
        raise ValueError(f"{flag} {path}: is {_not_a_folder(path)}")
    above = path
    while not above.exists() and above.parent != above:
        if above.is_symlink():  # to nothing or in a loop: make_folder refused it after the work
            where = "" if above == path else f"{above} "
            raise ValueError(f"{flag} {path}: {where}is {_broken_link(above)}")
        above = above.parent
    if above.exists() and not above.is_dir():
        raise ValueError(f"{flag} {path}: {above} is {_not_a_folder(above)}")
    why = cannot_write_in(above) if above.exists() else None
    if why:
        raise PermissionError(f"{flag} {path}: cannot write in {above} ({why})")


def _unexpanded_home(path: PathLike) -> str | None:
    """``path`` with its leading ``~`` (or ``~user``) expanded, when it is text that starts
    with one the shell left as typed and no such file or folder is in the current folder
    (``~/out`` with no ``./~``); else None."""
    if not isinstance(path, str) or not path.startswith("~"):
        return None
    first = path.split("/", 1)[0]
    home = os.path.expanduser(first)
    if home == first or os.path.lexists(first):
        return None
    return os.path.expanduser(path)


def cannot_write_in(folder: PathLike) -> str | None:
    """Why no file can be made in ``folder`` (the system's reason), or None if one can.

    A probe file, made and removed as :func:`atomic_write` makes its temporary: ``os.access``
    says yes to root everywhere, ``/proc`` included.

    Parameters
    ----------
    folder : str or os.PathLike
        An existing folder.

    Returns
    -------
    str or None
    """
    try:
        fd, probe = tempfile.mkstemp(prefix=".", suffix=".probe", dir=folder)
    except OSError as exc:
        return exc.strerror or str(exc)
    os.close(fd)
    os.remove(probe)
    return None


def check_destinations(folder: PathLike, names: Sequence[str], flag: str) -> None:
    """Refuse, before the work, a file a command will write into ``folder`` that it could not:
    what stands under one of ``names`` (a link, a folder) is checked as :func:`atomic_write`
    and :func:`write_together` would check it, at the end of the work.

    A folder itself writable (:func:`check_output_folder`) can still hold ``left.yaml`` as a
    link to a file in a folder that is not, a link that loops or dangles into a missing
    folder, or a folder under the name: each failed after minutes of calibration, with the
    calibration file already written.

    Parameters
    ----------
    folder : str or os.PathLike
        The output folder (it need not exist yet: then nothing stands in the way).
    names : sequence of str
        The files the command writes there, in the order it writes them together.
    flag : str
        How the user gave the folder (``"--ros"``), for the messages.

    Raises
    ------
    IsADirectoryError, NotADirectoryError, FileNotFoundError, OSError
        If a name is a folder (or a link to one), a link into a missing folder or a link that
        loops, naming ``flag`` and ``folder``.
    PermissionError
        If a name is a link to a file whose folder cannot be written.
    ValueError
        If two of the names are one file (one a link to the other).
    """
    d = Path(folder)
    if not d.is_dir():
        return  # made by the command, empty (a file there: check_output_folder's refusal)
    targets: list[tuple[Path, Path]] = []
    for name in names:
        dest = d / name
        if not (dest.is_symlink() or dest.exists()):
            continue
        try:
            target = _through_links(dest)
            _writable_destination(target)
        except OSError as exc:
            # a dangling link's error names its target only: the link is named too
            link = (
                f"{name} is a link to {os.readlink(dest)}; "
                if dest.is_symlink() and exc.errno != errno.ELOOP
                else ""
            )
            refused = type(exc)(f"{flag} {folder}: {link}{exc}")
            refused.errno = exc.errno
            raise refused from None
        why = cannot_write_in(target.parent)
        if why:  # a link's target is replaced in its own folder, not in ``folder``
            raise PermissionError(
                f"{flag} {folder}: cannot write {dest}: it is a link to {target}, whose folder "
                f"{target.parent} is not writable ({why})"
            )
        for earlier, earlier_target in targets:
            if _one_file(earlier_target, target):
                raise ValueError(
                    f"{flag} {folder}: {dest} and {earlier} are one file (the second written "
                    "would replace the first); move or remove the link"
                )
        targets.append((dest, target))


def _same_bytes(a: Path, b: Path, chunk: int = 1 << 20) -> bool:
    """Whether files ``a`` and ``b`` hold the same bytes, read a chunk at a time (no cache, as
    :func:`filecmp.cmp` keeps by size and modification time)."""
    if a.stat().st_size != b.stat().st_size:
        return False
    with open(a, "rb") as fa, open(b, "rb") as fb:
        while True:
            x, y = fa.read(chunk), fb.read(chunk)
            if x != y:
                return False
            if not x:
                return True


def replaced_words(
    kept: object, existed: bool, replaced: str = "the one it", held: str = "it"
) -> str:
    """What the line of a calibration written says of the file it replaced.

    Parameters
    ----------
    kept : object
        The copy :func:`keep_previous` made (a path, or the paths' text), or None / ``""``.
    existed : bool
        Whether the file(s) existed before the write.
    replaced, held : str
        The subject of the two phrases (``"the ones they"`` and ``"they"`` for two files).

    Returns
    -------
    str
        `` (the one it replaced kept as X)``, `` (unchanged: it held this calibration)`` when
        the file held the new bytes already (no copy made), or ``""`` for a new file.
    """
    if kept:  # escaped: a folder named with a newline cut the line in two
        return f" ({replaced} replaced kept as {escaped(str(kept))})"
    return f" (unchanged: {held} held this calibration)" if existed else ""


def keep_previous(path: PathLike, new: bytes | None = None) -> Path | None:
    """Copy an existing file aside as ``NAME.previous.EXT`` before a command replaces it.

    A calibration written again under the same name (``calibrate -o rig.yaml`` run twice,
    ``check --fix rig2.yaml``) replaced the earlier one without a word; its copy is kept, so a
    worse calibration can be undone. It is a copy, not a rename: should the new file fail to be
    written, the earlier one is still in place. An earlier copy is never replaced (a third run
    with worse pairs would otherwise lose the good rig of the first): when ``NAME.previous.EXT``
    holds other bytes, the copy is ``NAME.previous.2.EXT`` (``.3``, ...: the first free name);
    a file already kept byte for byte is not copied again, its copy is returned. A name taken
    by a link (to a file, to a folder, dangling or looping) or a folder is left untouched and
    the next name is tried: the copy is never written through a link the user made.

    Parameters
    ----------
    path : str or os.PathLike
        The file about to be written.
    new : bytes, optional
        The bytes about to be written: when ``path`` already holds exactly these (the same
        board or plot written again), nothing is replaced, so nothing is copied.

    Returns
    -------
    pathlib.Path or None
        The copy, or None when ``path`` held no file or already held ``new``.
    """
    import shutil

    p = as_path(path, file=True)
    if not p.is_file():
        return None
    if new is not None and p.stat().st_size == len(new) and p.read_bytes() == new:
        return None  # rewriting the same bytes loses nothing: no NAME.previous clutter
    # compared and copied in chunks, not read whole: besides calibrations, `demo` keeps a
    # cloud.ply of any size aside this way
    n = 1
    # a "suffix" too long to keep beside .previous ('x.' + 250 letters, a legal name) is the
    # name's body: the whole name is cut instead (cutting the stem alone never fitted: a hang)
    stem, suffix = (p.stem, p.suffix) if len(os.fsencode(p.suffix)) <= 200 else (p.name, "")
    while True:
        tail = f".previous{'' if n == 1 else f'.{n}'}{suffix}"
        # the stem is cut when NAME.previous.EXT would pass NAME_MAX ("File name too long"
        # refused the write of a legal 250-byte name)
        kept = p.with_name(_fit_name(stem, _NAME_MAX - len(os.fsencode(tail))) + tail)
        # a link is taken, not followed: a dangling one had the copy made at its target
        # (elsewhere), one to NAME.EXT itself passed for the copy of the file about to be
        # replaced, and a looping one failed after the work; none is a copy this made
        if kept.is_symlink():
            n += 1
            continue
        if not kept.exists():
            break
        if kept.is_file() and _same_bytes(kept, p):
            return kept  # already kept: nothing to copy
        n += 1
    with open(p, "rb") as src, atomic_write(kept) as dst:
        shutil.copyfileobj(src, dst, 1 << 20)
    return kept


def _through_links(dest: Path) -> Path:
    """The file a write to ``dest`` lands in: a link's target (created when missing), as
    ``open(dest, "w")`` writes it, not a regular file replacing the link.

    Raises
    ------
    OSError
        If ``dest`` is a link that loops (ELOOP), naming ``dest``.
    IsADirectoryError
        If ``dest`` is a link to a folder, naming ``dest`` and the folder.
    """
    if not dest.is_symlink():
        return dest
    try:
        target = Path(os.path.realpath(dest, strict=True))
    except OSError as exc:
        if exc.errno != errno.ELOOP:
            # dangling: its target is created, as open() does; or a path open() refuses too (a
            # file where a folder should be), said by _writable_destination, not as a loop
            return Path(os.path.realpath(dest))
        loop = OSError(f"cannot write {dest}: it is a link that loops")  # str() without [Errno 40]
        loop.errno = errno.ELOOP
        raise loop from exc
    if target.is_dir():  # said of the folder alone, the name the user gave was not in it
        raise IsADirectoryError(
            f"cannot write {dest}: it is a link to the folder {target}; give a file name"
        )
    return target


def _one_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file: through links (theirs or their folders') or as
    hard links of one another."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist yet: not one file
        return False


def _special_kind(path: Path) -> str:
    """What ``path``, there but not a regular file nor a folder, is: ``"a FIFO"``, ``"a
    socket"``, ``"a character device"`` or ``"a block device"`` (a socket was called "a FIFO or
    a device")."""
    try:
        mode = path.stat().st_mode
    except OSError:
        return "not a file"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    return "not a regular file"


def _writable_destination(dest: Path, given: Path | None = None) -> Path:
    """``dest``'s folder, after refusing a ``dest`` that is a folder or a folder that is missing
    or a file (the errors :func:`atomic_write` documents). ``given``: the name the user gave,
    when ``dest`` is its link's target (:func:`_through_links`), named with it."""
    directory = dest.parent if str(dest.parent) else Path(".")
    if dest.is_dir():
        raise IsADirectoryError(f"cannot write {dest}: it is a folder; give a file name")
    if dest.exists() and not dest.is_file():
        # a FIFO (a reader waiting on it) or a device was replaced by a regular file unsaid;
        # a link to one was refused naming the target alone, not the name given
        kind = _special_kind(dest)
        if given is not None and given != dest and given.is_symlink():
            raise OSError(
                f"cannot write {given}: it is a link to {dest}, not a regular file ({kind})"
            )
        raise OSError(f"cannot write {dest}: it is not a regular file ({kind})")
    if directory.exists() and not directory.is_dir():
        raise NotADirectoryError(f"cannot write {dest}: {directory} is a file, not a folder")
    if not directory.is_dir():
        # a link whose target moved (or a loop) was "directory out does not exist" alone, of
        # a name ls lists: what the link reaches is said, as the readers' "not found" says it
        if directory.is_symlink():
            raise FileNotFoundError(
                f"cannot write {dest}: directory {directory} is {_broken_link(directory)}"
            )
        raise FileNotFoundError(f"cannot write {dest}: directory {directory} does not exist")
    return directory


def temp_refused(dest: Path, exc: OSError) -> OSError:
    """The error to raise when the temporary file of a write to ``dest`` cannot be made in its
    folder: ``dest`` and the folder named, not the temporary file ('[Errno 13] Permission
    denied: '.../.rig.yaml.k2j3abcd.tmp''), in ``exc``'s class and errno.

    Parameters
    ----------
    dest : pathlib.Path
        The file being written (not its temporary file).
    exc : OSError
        What making the temporary file in ``dest``'s folder raised.

    Returns
    -------
    OSError
        An error of ``exc``'s class and errno naming ``dest`` and its folder (a
        PermissionError: the folder is not writable).
    """
    directory = dest.parent if str(dest.parent) else Path(".")
    if isinstance(exc, PermissionError):
        refused = PermissionError(
            f"cannot write {dest}: its folder {directory} is not writable (the new contents "
            "are made there, then put in place)"
        )
        refused.errno = errno.EACCES
        return refused
    # any other refusal of the folder (/proc: ENOENT, a read-only filesystem: EROFS) named
    # the temporary file too ('No such file or directory: '/proc/.x.png.58m0qpf3.tmp'')
    failed = type(exc)(
        f"cannot write {dest}: no file can be made in its folder {directory} "
        f"({exc.strerror or exc})"
    )
    failed.errno = exc.errno
    return failed


#: Errors of a write into a full disk or quota (the body of :func:`atomic_write` raises them
#: naming no file).
_DISK_FULL = frozenset({errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC)})


def _not_written(dest: Path, exc: OSError) -> OSError:
    """The error to raise when the new contents of ``dest`` cannot be written or put in place
    (a full disk, a rename refused): ``dest`` named, in ``exc``'s class and errno. os.replace's
    own named the temporary file first ('[Errno 28] No space left on device:
    '.../.x.pfm.k2j3abcd.tmp' -> '.../x.pfm''), a write's none."""
    failed = type(exc)(f"cannot write {dest}: {exc.strerror or exc}")
    failed.errno = exc.errno
    return failed


def _close_quietly(fh: IO[Any]) -> None:
    """Close ``fh`` whose contents are dropped: its close flushes what is left in its buffer,
    which fails again on a full disk (the file is closed all the same)."""
    try:
        fh.close()
    except OSError:
        pass


#: Longest file name (bytes) of Linux's and macOS's filesystems, NAME_MAX.
_NAME_MAX = 255


def _fit_name(name: str, room: int) -> str:
    """``name`` cut to at most ``room`` bytes in the filesystem's encoding (whole characters)."""
    while name and len(os.fsencode(name)) > room:  # "" ends it: a room below 0 looped on it
        name = name[:-1]
    return name


def _temp_beside(dest: Path, suffix: str) -> tuple[int, str]:
    """A new temporary file in ``dest``'s folder (``os.replace`` is atomic within a filesystem
    only), open; a folder that refuses it is named, not the temporary file
    (:func:`temp_refused`)."""
    directory = dest.parent if str(dest.parent) else Path(".")
    # '.NAME.' + mkstemp's 8 random characters + suffix: a legal name of 241+ bytes made a
    # temporary name past NAME_MAX, and the write failed ("File name too long"); it is cut
    name = _fit_name(dest.name, _NAME_MAX - 2 - 8 - len(suffix))
    try:
        return tempfile.mkstemp(prefix=f".{name}.", suffix=suffix, dir=directory)
    except OSError as exc:
        raise temp_refused(dest, exc) from exc


@contextmanager
def atomic_write(path: PathLike, mode: str = "wb") -> Iterator[IO[Any]]:
    """Open a temporary file next to ``path``; on success it atomically replaces ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        Destination file. Its directory must exist. A link is written through: its target
        is replaced (created when missing) and the link kept, as ``open(path, "w")`` does.
    mode : str
        ``"wb"`` (default) or ``"w"`` (text, UTF-8): the file is replaced whole, so a mode
        that keeps or reads its contents (``"a"``, ``"x"``, ``"r+"``) is refused.

    Yields
    ------
    file object
        The open temporary file. If the ``with`` body raises, the temporary file is removed and
        ``path`` is left untouched.

    Raises
    ------
    ValueError
        If ``mode`` is not a writing mode (``"w"``, ``"wb"``, ``"wt"``, ``"+"`` allowed).
    FileNotFoundError
        If the destination directory does not exist.
    IsADirectoryError, NotADirectoryError
        If ``path`` is a folder or a name ending in ``/`` (a folder's), or its directory is a
        file.
    OSError
        If ``path`` is a link that loops, or a FIFO, a socket or a device (replaced, the reader
        waiting on it got nothing), or a link to one; or if the new contents cannot be written
        or put in place (a full disk, a rename refused): the message names ``path``, and the
        temporary file is removed.
    """
    if (
        not isinstance(mode, str)
        or "w" not in mode
        or set(mode) - set("wbt+")
        # checked here, not by fdopen: its "can't have text and binary mode" came after the
        # temporary file was made, and its descriptor was left open
        or len(set(mode)) != len(mode)
        or {"b", "t"} <= set(mode)
    ):
        # the temporary file replaces the whole file: "a" left the body's lines alone (a log's
        # old lines lost), "x" replaced the existing file it is there to keep, without a word
        raise ValueError(
            f"mode: expected 'wb' or 'w' (atomic_write replaces the whole file), got {mode!r}"
        )
    given = as_path(path, file=True)
    text = os.fspath(path)
    if text.endswith(("/", os.sep)) and not given.is_dir():
        # Path() drops the slash: 'new/' was written as a file named 'new' (open() refuses it)
        raise IsADirectoryError(
            f"cannot write {text}: a name ending in '/' is a folder's; give a file name"
        )
    dest = _through_links(given)
    _writable_destination(dest, given)
    fd, tmp = _temp_beside(dest, ".tmp")
    try:
        encoding = None if "b" in mode else "utf-8"
        with os.fdopen(fd, mode, encoding=encoding) as fh:
            try:
                yield fh
            except BaseException as exc:
                # closed here, what the body wrote dropped: the with's close flushed it again
                # into a full disk, and its bare "[Errno 28]" replaced this error
                _close_quietly(fh)
                # the body's write into a full disk named no file
                if isinstance(exc, OSError) and exc.filename is None and exc.errno in _DISK_FULL:
                    raise _not_written(dest, exc) from exc
                raise
            try:
                fh.flush()
                os.fsync(fh.fileno())
            except OSError as exc:
                _close_quietly(fh)  # as above: a full disk fails the flush at close again
                raise _not_written(dest, exc) from exc
        try:
            # mkstemp creates 0600; give the result the permissions open() would (the
            # replaced file's, else a new file's)
            os.chmod(tmp, _mode_for(dest))
            os.replace(tmp, dest)
        except OSError as exc:
            raise _not_written(dest, exc) from exc
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def write_together(files: list[tuple[Path, bytes]]) -> None:
    """Write files that belong together (a map's picture and YAML, a rig's two camera_info) all or
    nothing.

    Every file is written and synced to a temporary file next to its destination; then each
    replaces its destination in order (the last one commits the set), a copy of each previous
    destination being kept under a temporary name until the last is in place. On any failure the
    destinations already replaced get their previous contents back (or are removed if they did
    not exist) and every temporary file is removed, except a copy of previous contents that could
    not be put back: it is kept, and the exception's notes name it and its destination.

    Parameters
    ----------
    files : list of (pathlib.Path, bytes)
        Destinations and their contents, in the order they are to replace the destinations.
        A link is written through, as by :func:`atomic_write`.

    Raises
    ------
    IsADirectoryError, NotADirectoryError, FileNotFoundError, OSError
        As :func:`atomic_write`, for any destination, before anything is written.
    ValueError
        If two destinations are one file (a link to the other, a hard link, the same name
        twice): the second would replace the first. Nothing is written.
    """
    import shutil

    # checked first, in atomic_write's words: os.replace's error named the temporary file
    # ('Is a directory: .../.right.yaml.x1y2.tmp -> .../right.yaml')
    # a link is written through (its target replaced, the link kept), as open(path, "w") does
    given = [dest for dest, _ in files]
    files = [(_through_links(dest), data) for dest, data in files]
    for (dest, _), gave in zip(files, given, strict=True):
        _writable_destination(dest, gave)
    # written through links, right.yaml -> left.yaml put the right camera over the left one
    for i, (dest, _) in enumerate(files):
        for j in range(i):
            if _one_file(files[j][0], dest):
                raise ValueError(
                    f"cannot write {given[j]} and {given[i]} together: they are one file (the "
                    "second would replace the first)"
                )
    temps: list[Path] = []  # the new contents, not yet in place
    kept: list[tuple[Path, Path | None]] = []  # (destination, its previous contents or None)
    replaced = 0  # how many of kept's destinations hold their new contents
    try:
        for dest, data in files:
            fd, name = _temp_beside(dest, ".tmp")
            temps.append(Path(name))
            try:
                with os.fdopen(fd, "wb") as fh:
                    fh.write(data)
                    fh.flush()
                    os.fsync(fh.fileno())
                os.chmod(name, _mode_for(dest))  # mkstemp's 0600 -> what open() leaves
            except OSError as exc:  # a full disk named no file
                raise _not_written(dest, exc) from exc
        for (dest, _), new in zip(files, temps, strict=True):
            previous: Path | None = None
            if dest.is_file():
                fd, name = _temp_beside(dest, ".old")
                os.close(fd)
                previous = Path(name)
            # listed before the copy: a copy failing half-way (a full disk) is removed below
            kept.append((dest, previous))
            if previous is not None:
                shutil.copy2(dest, previous)  # dest stays in place meanwhile
            try:
                os.replace(new, dest)
            except OSError as exc:  # it named the temporary file first
                raise _not_written(dest, exc) from exc
            replaced += 1
    except BaseException as exc:
        stranded: list[tuple[Path, Path]] = []  # (destination, the only copy of its old contents)
        # (a destination whose own replacement failed still holds its previous contents)
        for dest, previous in reversed(kept[:replaced]):
            try:
                if previous is not None:
                    os.replace(previous, dest)
                elif dest.exists():
                    os.unlink(dest)
            except OSError:
                if previous is not None:
                    # not removed below: it holds the previous contents, the destination the new
                    stranded.append((dest, previous))
        for left_over in temps + [p for _, p in kept if p is not None]:
            if any(left_over == copy for _, copy in stranded):
                continue
            try:
                os.unlink(left_over)
            except FileNotFoundError:
                pass
        for dest, copy in stranded:
            note = f"{dest} could not be restored: its previous contents are in {copy}"
            if hasattr(exc, "add_note"):
                exc.add_note(note)
            else:  # Python 3.10: no notes; a warning still says where the contents are
                warnings.warn(note, RuntimeWarning, stacklevel=3)
        raise
    for _, previous in kept:
        if previous is not None:
            try:
                os.unlink(previous)
            except FileNotFoundError:
                pass


def _describe(a: np.ndarray) -> str:
    return f"shape {a.shape} dtype {a.dtype}"


def image_size_text(image: np.ndarray) -> str:
    """An image's size as the project writes it: ``"450x375 (colour)"``, ``"(grey)"`` for one
    channel, ``"(4 channels)"`` otherwise.

    Parameters
    ----------
    image : numpy.ndarray
        ``(H, W)`` or ``(H, W, C)`` image.

    Returns
    -------
    str

    Examples
    --------
    >>> image_size_text(np.zeros((375, 450, 3), np.uint8))
    '450x375 (colour)'
    >>> image_size_text(np.zeros((2, 3), np.uint8))
    '3x2 (grey)'
    """
    h, w = image.shape[:2]
    c = image.shape[2] if image.ndim == 3 else 1
    kind = "grey" if c == 1 else "colour" if c == 3 else f"{c} channels"
    return f"{w}x{h} ({kind})"


def check_pair_files(
    left: np.ndarray,
    right: np.ndarray,
    left_path: PathLike,
    right_path: PathLike,
    names: tuple[str, str] | None = None,
) -> str | None:
    """Check a pair read from two files: the same size, and not one file (or image) twice.

    Parameters
    ----------
    left, right : numpy.ndarray
        The two images as read.
    left_path, right_path : str or os.PathLike
        The files they came from (named in the messages).
    names : tuple of str, optional
        How to name the two files instead (e.g. the GUI's short labels).

    Returns
    -------
    str or None
        A warning when both are the same file or the same pixels (every disparity would come
        out 0), else None. The caller shows it (the CLI as a warning, the GUI on the page).

    Raises
    ------
    ValueError
        If their sizes differ, e.g. ``"left.png is 450x375 (colour), right.png is 384x288
        (colour): the two images of a pair have one size"``.
    """
    ln, rn = names if names is not None else (str(left_path), str(right_path))
    if left.shape != right.shape:
        raise ValueError(
            f"{ln} is {image_size_text(left)}, {rn} is {image_size_text(right)}: the two "
            "images of a pair have one size"
        )
    try:
        same_file = os.path.samefile(left_path, right_path)
    except OSError:
        same_file = False
    if same_file or np.array_equal(left, right):
        return (
            f"{ln} and {rn} are the same {'file' if same_file else 'image'}: every disparity "
            "comes out 0 (two views of the scene are needed)"
        )
    return None


def _broken_link(link: Path) -> str:
    """Why ``link``, a link that ``exists()`` says reaches no file, reaches none: its target
    does not exist, or it is one of a loop of links. ``exists()`` is False for both (ELOOP);
    "which does not exist" of a loop's target, which is there, sent the user looking for a
    moved file."""
    # escaped: a target holding a newline cut the CLI's one-line error there ("... (a link to
    # moved"), the rest of it lost
    target = escaped(os.readlink(link))
    try:
        os.stat(link)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            return f"a link to {target}, one of a loop of links that never reaches a file"
    # a link to a link whose target moved (data -> current -> /mnt/disk2/data) was "a link to
    # current, which does not exist", of a name ls lists: each link is named, to the missing one
    hops = [target]
    at = os.path.join(os.path.dirname(link), os.readlink(link))
    while os.path.islink(at) and len(hops) < 40:  # 40: Linux's own limit (ELOOP past it)
        step = os.readlink(at)
        hops.append(escaped(step))
        at = os.path.join(os.path.dirname(at), step)
    return ", ".join(f"a link to {t}" for t in hops) + ", which does not exist"


def _other_suffix(path: Path) -> str:
    """`` (did you mean left.jpg?)`` for a missing image ``left.png`` beside which exactly one
    image file of the same stem and another image suffix lies (``--left left.png`` of a folder of
    JPEGs was "not found" alone), else ""."""
    from stereovision.batch import IMAGE_EXTS

    try:
        names = [
            e.name
            for e in os.scandir(path.parent)
            if Path(e.name).stem == path.stem
            and e.name != path.name
            and Path(e.name).suffix.lower() in IMAGE_EXTS
            and e.is_file()  # a folder named left.jpg is no image to offer
        ]
    except OSError:  # no such folder, or one not readable: nothing to suggest
        return ""
    if len(names) != 1:
        return ""
    return f" (did you mean {escaped(str(path.with_name(names[0])))}?)"


def _missing_hint(path: PathLike, p: Path) -> str:
    """What a not-found message adds for ``p`` (``path`` as given): a link whose target moved
    reads as no file at all, so which one is missing is said; a ``~`` the shell left as typed
    (``--calib=~/rig.yaml``) names the home's file when that one exists; else ""."""
    if p.is_symlink():
        return f" ({_broken_link(p)})"
    home = _unexpanded_home(path)
    if home is not None and os.path.exists(home):
        return f" (~ is not expanded here: did you mean {escaped(home)}?)"
    return ""


def _existing_file(path: PathLike, what: str) -> Path:
    p = as_path(path, file=True)
    if not p.exists():
        gone = _missing_hint(path, p)
        if not gone and what == "image file":
            gone = _other_suffix(p)
        raise FileNotFoundError(f"{what} not found: {p}{gone}")
    if not p.is_file():
        hint = _pair_in_folder(p) if what == "image file" else ""
        raise ValueError(f"{what} is not a regular file: {p}{hint}")
    return p


#: The names :func:`_folder_pair` looks for, as the messages about a folder without them say.
FOLDER_PAIR_NAMES = "looked for left.png + right.png or im0.png + im1.png, any image suffix"


def _pair_in_folder(folder: Path) -> str:
    """What to give instead of a scene folder given as an image (``stereovision depth cones``,
    as ``eval`` and ``batch`` take it): the folder's left and right images, when it holds one of
    each, else ""."""
    pair = _folder_pair(folder)
    if pair is None:
        if not folder.is_dir():  # a FIFO or a device: no folder to speak of
            return ""
        # "not a regular file" alone did not say what was expected of it
        what, detail = _no_single_pair(folder)
        return f" (a folder {what}: {detail}; give two image files)"
    return f" (a folder holding a pair: give its two images, {pair[0]} and {pair[1]})"


def _no_single_pair(folder: PathLike) -> tuple[str, str]:
    """What a folder without a single pair (:func:`_folder_pair` None) holds, and the detail,
    for the messages about it given as the images: its pairs by name (``left01.jpg`` +
    ``right01.jpg``, ..., which ``stereovision batch`` takes) are not "no pair"."""
    pairs = _named_pairs(folder)
    if len(pairs) > 1:
        first, second = pairs[0]
        return (
            f"of {len(pairs)} pairs",
            f"{first.name} + {second.name}, ...; stereovision batch takes such a folder",
        )
    return "with no pair in it", FOLDER_PAIR_NAMES


def _named_pairs(folder: PathLike) -> list[tuple[Path, Path]]:
    """The images directly in ``folder`` named with ``left`` whose name with ``right`` in its
    place is there too (``left_0001.png`` + ``right_0001.png``), as
    :func:`stereovision.batch.find_pairs` pairs them; [] when it is no readable folder."""
    from stereovision.batch import IMAGE_EXTS, _last_left, _swap

    folder = Path(folder)
    try:
        names = {f for f in os.listdir(folder) if Path(f).suffix.lower() in IMAGE_EXTS}
    except OSError:
        return []
    pairs = []
    for name in sorted(names):
        m = _last_left(Path(name).stem)
        if m is not None and (right := _swap(Path(name), m, "right").name) in names:
            pairs.append((folder / name, folder / right))
    return pairs


def _folder_pair(folder: PathLike) -> tuple[Path, Path] | None:
    """The left and right image of a scene folder holding one pair (``left.png`` +
    ``right.png``, Middlebury's ``im0.png`` + ``im1.png``, else one pair named as
    :func:`_named_pairs` finds them: ``left_0001.png`` + ``right_0001.png``), for a message
    saying what to give instead of the folder.

    Parameters
    ----------
    folder : str or os.PathLike
        The folder given where images were expected.

    Returns
    -------
    (Path, Path) or None
        The two images under ``folder``; None when it is no readable folder or holds no single
        pair (``left01.png``, ``left02.png``, ... is a calibration set, not a pair).
    """
    from stereovision.batch import IMAGE_EXTS

    folder = Path(folder)
    try:
        images = [f for f in os.listdir(folder) if Path(f).suffix.lower() in IMAGE_EXTS]
    except OSError:  # not a folder, or not readable: nothing to suggest
        return None
    for left, right in (("left", "right"), ("im0", "im1")):
        ls = sorted(f for f in images if Path(f).stem.lower() == left)
        rs = sorted(f for f in images if Path(f).stem.lower() == right)
        if len(ls) == 1 and len(rs) == 1:
            return folder / ls[0], folder / rs[0]
    # one pair named as capture saves it (left_0001.png + right_0001.png), cam_left.jpg + ...
    named = _named_pairs(folder)
    return named[0] if len(named) == 1 else None


# --------------------------------------------------------------------------------------- images


def decode_image(data: npt.NDArray[np.uint8] | bytes) -> npt.NDArray[np.uint8] | None:
    """``cv2.imdecode`` to BGR with OpenCV's own logging silenced for the call: a file it cannot
    read returns None, and the caller's error names the file (OpenCV would also print its own
    ``[ERROR] ... imdecode_`` line on stderr, a second message for one problem).

    Parameters
    ----------
    data : ndarray of uint8 or bytes
        The encoded file's bytes (PNG, JPEG, PPM/PGM, ...): bytes, a bytearray or memoryview,
        or a ``uint8`` array of shape ``(N,)``, ``(N, 1)`` or ``(1, N)``.

    Returns
    -------
    numpy.ndarray or None
        ``uint8`` ``(H, W, 3)`` BGR; None if the bytes are empty or not a readable image, a
        PFM file's floating-point values included (:func:`_is_pfm`).

    Raises
    ------
    TypeError
        If ``data`` is neither bytes nor a ``uint8`` vector (None and a str were an
        AttributeError, an image-shaped array OpenCV's "buf.checkVector(1, CV_8U) > 0").
    """
    if isinstance(data, (bytes, bytearray, memoryview)):
        buf = np.frombuffer(data, np.uint8)
    elif (
        isinstance(data, np.ndarray)
        and data.dtype == np.uint8
        and (data.ndim == 1 or (data.ndim == 2 and 1 in data.shape))
    ):
        # a row or a column too: OpenCV 4's cv2.imencode gives its bytes as (N, 1)
        buf = data.reshape(-1)
    else:
        what = (
            f"array of shape {data.shape} dtype {data.dtype}"
            if isinstance(data, np.ndarray)
            else type(data).__name__
        )
        raise TypeError(f"data: expected the file's bytes or a 1-D uint8 array, got {what}")
    if buf.size == 0 or _is_pfm(buf):
        return None
    if buf[:4].tobytes() in _TIFF_MAGIC:
        # a TIFF's depth seen in the one decode of an 8-bit file (ANYDEPTH gives it
        # IMREAD_COLOR's very pixels): one of negative int16 pixels is refused
        # (_negative_int16_tiff), others of 16 bits or more decoded as before
        img = _imdecode(buf, cv2.IMREAD_COLOR | cv2.IMREAD_ANYDEPTH)
        if img is None or img.dtype == np.uint8:
            return img
        if img.dtype == np.int16 and int(img.min()) < 0:
            return None
    img = _imdecode(buf, cv2.IMREAD_COLOR)
    return None if img is None else np.asarray(img, dtype=np.uint8)


_TIFF_MAGIC = (b"II*\x00", b"MM\x00*")


def _negative_int16_tiff(buf: npt.NDArray[np.uint8]) -> bool:
    """Whether ``buf`` is a TIFF of signed 16-bit pixels, some negative.

    ``IMREAD_COLOR`` takes an ``int16`` pixel's bits as unsigned ones and keeps the top 8: -5
    read as 255 (white), -32768 as 128, a dark pixel the brightest, without a word. Such a file
    is no 8- or 16-bit image (:func:`decode_image` refuses it, :func:`_not_an_image_hint`
    says why); one of values >= 0 reads as its unsigned twin does. Other formats hold no
    signed pixels.
    """
    if buf[:4].tobytes() not in _TIFF_MAGIC:
        return False
    pixels = _imdecode(buf, cv2.IMREAD_UNCHANGED)
    return pixels is not None and pixels.dtype == np.int16 and int(pixels.min()) < 0


def _is_pfm(buf: npt.NDArray[np.uint8]) -> bool:
    """Whether ``buf`` starts as a PFM file (``Pf`` or ``PF`` and a whitespace character).

    OpenCV decodes a PFM even under ``IMREAD_COLOR``, its floats rounded and clipped to 0-255
    (a disparity of 300 px read as 255, 0.4 as 0), a ``Pf`` file as a 2-D ``(H, W)`` array: a
    disparity map given as an image was matched as one, and ``imread(gray=True)`` was
    OpenCV's "Bad number of channels". Such a file is no 8- or 16-bit image: it is refused
    (:func:`read_pfm` reads it), as a float TIFF is.
    """
    return buf.size >= 3 and buf[:2].tobytes() in (b"Pf", b"PF") and bytes(buf[2:3]).isspace()


_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _png_cut_short(buf: npt.NDArray[np.uint8]) -> bool:
    """Whether ``buf`` is a PNG whose chunks stop before a whole ``IEND`` chunk (a file cut
    short by an interrupted copy or download), found from the chunks' lengths alone.

    libpng prints "libpng error: PNG input buffer is incomplete" on the C stderr for such a
    file, once per decode, before OpenCV returns None: the CLI's one error line came after one
    or two of these, which OpenCV's log level does not silence. A PNG without its ``IEND`` is
    None from OpenCV either way, so refusing it here changes no result.
    """
    if buf.size < 8 or buf[:8].tobytes() != _PNG_SIGNATURE:
        return False
    pos, size = 8, int(buf.size)
    while pos + 8 <= size:
        length = int.from_bytes(buf[pos : pos + 4].tobytes(), "big")
        end = pos + 12 + length  # length, type, data, CRC
        if buf[pos + 4 : pos + 8].tobytes() == b"IEND":
            return end > size
        pos = end
    return True


def _imdecode(buf: npt.NDArray[np.uint8], flags: int) -> npt.NDArray[Any] | None:
    """``cv2.imdecode``, quiet, None for bytes it cannot decode: a header whose size is 0,
    negative or over OpenCV's pixel limit (a corrupt or hostile PNG, a PFM of width -3) raised
    cv2.error from its size check where other unreadable bytes give None. A MemoryError when
    the pixels of a readable image cannot be allocated: not "cannot decode" of a good file.
    A PNG cut short is None without being decoded (:func:`_png_cut_short`)."""
    if _png_cut_short(buf):
        return None
    with _opencv_quiet():
        try:
            return cv2.imdecode(buf, flags)  # type: ignore[no-any-return]
        except cv2.error as exc:
            if exc.code == cv2.Error.StsNoMem:
                raise MemoryError(f"not enough memory to decode the image: {exc.err}") from None
            return None


# OpenCV's log level is process-wide: the first of concurrent decodes silences it and the last
# puts back what was there (a plain save and restore per call could leave it silenced for good
# when two threads interleave).
_QUIET_LOCK = threading.Lock()
_quiet = {"depth": 0, "level": 0}


@contextmanager
def _opencv_quiet() -> Iterator[None]:
    log = cv2.utils.logging  # type: ignore[attr-defined]
    with _QUIET_LOCK:
        if _quiet["depth"] == 0:
            _quiet["level"] = log.getLogLevel()
            log.setLogLevel(log.LOG_LEVEL_SILENT)
        _quiet["depth"] += 1
    try:
        yield
    finally:
        with _QUIET_LOCK:
            _quiet["depth"] -= 1
            if _quiet["depth"] == 0:
                log.setLogLevel(_quiet["level"])


#: Files a first run passes where one image per camera is wanted (``depth LEFT RIGHT``).
_VIDEO_SUFFIXES = (".avi", ".mp4", ".mkv", ".mov", ".webm", ".m4v", ".mpg", ".mpeg", ".h264")
_BAG_SUFFIXES = (".bag", ".db3", ".mcap")


def _not_an_image_hint(path: Path, data: npt.NDArray[np.uint8]) -> str:
    """What an undecodable file (its bytes ``data``) looks like instead, as the end of the
    error's one line."""
    if data.size == 0:
        # an interrupted copy or save leaves 0 bytes: "cannot decode" alone read as a damaged
        # or unknown format
        return ": the file is empty (0 bytes)"
    if _is_pfm(data):
        return (
            ": it is a PFM file of floating-point values (a disparity map?), not an 8- or "
            "16-bit image"
        )
    if _png_cut_short(data):
        # "cannot decode" alone read as a damaged or unknown format, of a PNG whose end is gone
        # (said from its chunks' lengths: a damaged length reads as a file cut short too)
        return (
            f": the PNG file ends before its last chunk ({data.size} bytes: cut short by an "
            "interrupted copy?)"
        )
    if _negative_int16_tiff(data):
        return (
            ": its pixels are signed 16-bit values, some negative, not unsigned 8- or 16-bit "
            "ones (save it as an unsigned 8- or 16-bit PNG or TIFF)"
        )
    if data[:4].tobytes() in _TIFF_MAGIC:
        # a TIFF of float32 or int32 pixels decodes, but not as 8 or 16 bits: "cannot decode"
        # alone read as a damaged file
        pixels = _imdecode(data, cv2.IMREAD_UNCHANGED)
        if pixels is not None and pixels.dtype not in (np.uint8, np.uint16):
            return (
                f": its pixels are {pixels.dtype} values, not 8- or 16-bit ones (save it as an "
                "8- or 16-bit PNG or TIFF)"
            )
    suffix = path.suffix.lower()
    if suffix in _VIDEO_SUFFIXES:
        return (
            ": it is a video; this command takes one image per camera (stream, capture and "
            "calibrate read videos: --left VIDEO --right VIDEO)"
        )
    if suffix in _BAG_SUFFIXES:
        return (
            ": it is a ROS bag; this command takes one image per camera (stream, capture, "
            "calibrate and gui read bags: --from-bag BAG)"
        )
    return ""


def imread(path: PathLike, gray: bool = False) -> npt.NDArray[np.uint8]:
    """Read an image file as OpenCV does (8-bit, BGR channel order).

    Parameters
    ----------
    path : str or os.PathLike
        Image file (any format OpenCV decodes: PNG, JPEG, ...).
    gray : bool
        Return a grey ``(H, W)`` image instead of BGR ``(H, W, 3)``, converted with
        ``cv2.cvtColor(COLOR_BGR2GRAY)`` (BT.601 luma). True or False, not ``cv2.imread``'s
        flags.

    Returns
    -------
    numpy.ndarray
        ``uint8``, ``(H, W, 3)`` BGR or ``(H, W)`` grey.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        If the file cannot be decoded as an image (or is a TIFF of signed 16-bit pixels, some
        negative: OpenCV read -5 as 255).
    TypeError
        If ``gray`` is not True or False.
    """
    if not isinstance(gray, (bool, np.bool_)):
        # imread(p, 0) as cv2.imread(p, 0) (IMREAD_GRAYSCALE) gave the colour image, and 1
        # (IMREAD_COLOR) or "no" the grey one, each without a word
        raise TypeError(
            f"gray: expected True or False, got {gray!r} (not cv2.imread's flags: "
            "gray=True for a grey image)"
        )
    p = _existing_file(path, "image file")
    # imdecode from bytes: works for non-ASCII paths, and fails loudly instead of returning None.
    data = np.fromfile(p, dtype=np.uint8)
    img = decode_image(data)
    if img is None:
        raise ValueError(f"cannot decode {p} as an image{_not_an_image_hint(p, data)}")
    if gray:
        # Same conversion as everywhere else in the package (cv2.cvtColor, BT.601), not the
        # codec's own (libpng's differs by one grey level on some pixels).
        return np.asarray(cv2.cvtColor(img, cv2.COLOR_BGR2GRAY), dtype=np.uint8)
    return img


def read_image(path: PathLike) -> npt.NDArray[np.uint8] | npt.NDArray[np.uint16]:
    """Read an image file keeping a 16-bit file's 16 bits (``stereovision depth``'s reader).

    A 16-bit PNG or TIFF (a machine-vision camera's 12- or 16-bit frames) comes back as
    ``uint16`` BGR, which :func:`stereovision.depth_map` scales by 65535 (and warns about when
    only the low 12 bits are used); :func:`imread` keeps its top 8 bits (OpenCV's
    ``IMREAD_COLOR``: a 12-bit frame's 0-4095 became 0-15). A signed 16-bit TIFF of values
    >= 0 reads as its unsigned twin (one with negative values is refused). Any other file is
    read as :func:`imread` reads it.

    Parameters
    ----------
    path : str or os.PathLike
        Image file.

    Returns
    -------
    numpy.ndarray
        ``(H, W, 3)`` BGR, ``uint16`` for a 16-bit file, else ``uint8``.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        If the file cannot be decoded as an image.
    """
    p = _existing_file(path, "image file")
    img = _decode_8_or_16bit(np.fromfile(p, dtype=np.uint8))
    return img if img is not None else imread(p)  # imread's message for the rest


def _decode_8_or_16bit(
    data: npt.NDArray[np.uint8] | bytes,
) -> npt.NDArray[np.uint8] | npt.NDArray[np.uint16] | None:
    """An image file's bytes as BGR, ``uint16`` for a 16-bit file, else ``uint8``
    (:func:`read_image`'s, and ``batch``'s, as ``stereovision depth`` reads them); None for an
    empty, unreadable, PFM or floating-point file.

    One decode: ``IMREAD_ANYDEPTH`` gives an 8-bit file ``IMREAD_COLOR``'s very pixels (the
    EXIF turn included); a 16-bit try and then :func:`imread` decoded every 8-bit file twice.
    """
    buf = np.frombuffer(data, np.uint8) if isinstance(data, bytes) else data
    if buf.size == 0 or _is_pfm(buf):
        return None
    img = _imdecode(buf, cv2.IMREAD_COLOR | cv2.IMREAD_ANYDEPTH)
    if img is not None and img.dtype == np.int16 and int(img.min()) >= 0:
        # a signed 16-bit TIFF of values >= 0 (a 12-bit frame): imread's top 8 bits (0-4095 as
        # 0-15) where the same frame unsigned keeps 16; its values, unsigned. Negative: refused
        return img.astype(np.uint16)
    if img is None or img.dtype not in (np.uint8, np.uint16):
        return None
    return np.asarray(img)


# ------------------------------------------------------------------------------------------ PFM

# the three header fields, up to the scale and the whitespace character after it (or the
# file's end: a file cut there is truncated)
_PFM_HEADER = re.compile(rb"^(P[Ff])\s+(\d+)\s+(\d+)\s+([-+]?[0-9.]+(?:[eE][-+]?\d+)?)(?=\s|\Z)")
# the scale line's end as Windows tools (CRLF) and others (trailing spaces) write it
_PFM_LINE_END = re.compile(rb"[ \t]*\r?\n")
# a whole file that is the start of a header and no more (an interrupted save): 'Pf', 'Pf\n3 2'
_PFM_HEADER_CUT = re.compile(rb"P[Ff](?:\s+(?:\d+(?:\s+(?:\d+(?:\s+[-+]?)?)?)?)?)?\s*\Z")


def read_pfm(path: PathLike) -> npt.NDArray[np.float32]:
    """Read a PFM file (Middlebury convention) into a top-down ``float32`` array.

    PFM stores rows bottom-up; a negative scale means little-endian data, a positive one
    big-endian. Both endiannesses, grey (``Pf``) and colour (``PF``) files are read, their
    header lines ended by LF or CRLF (Windows tools), trailing spaces allowed. Values are
    returned as stored (``inf`` stays ``inf``; see :func:`load_scene` for the GT convention).

    Parameters
    ----------
    path : str or os.PathLike
        PFM file.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` (``Pf``) or ``(H, W, 3)`` (``PF``) native-endian ``float32``, row 0 = top.
        A ``PF`` file's channels come in the file's order, **RGB** (the format's), not the BGR
        of :func:`imread` and ``cv2.imread`` (which flips a PFM's itself): ``img[..., ::-1]``
        gives OpenCV's order.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        If the header is not a PFM header (a scale that is no number or zero, a grey ``Pf`` of
        a colour map's data or a colour ``PF`` of a grey one's) or the file is truncated (in
        its data, within its header, or empty), naming the file.

    Warns
    -----
    UserWarning
        When the finite values read in the scale's byte order are mostly of magnitudes below
        ``1e-30`` or beyond ``1e30`` and read in the other order are plausible (a scale of the
        wrong sign); they are returned as the scale says all the same.
    """
    p = _existing_file(path, "PFM file")
    raw = p.read_bytes()
    m = _PFM_HEADER.match(raw[:256])
    # a file ending right after its scale (cut before the line feed) is truncated, not "bad
    # header"; a scale cut by the 256 bytes looked at is no header
    if m is not None and m.end() == 256 < len(raw):
        m = None
    if m is None:
        # a file cut within its header (0 bytes: a save interrupted at once) was "bad header",
        # the words of another format's file, where one cut in its data is "truncated"
        if not raw:
            raise ValueError(f"truncated PFM file {p}: the file is empty (0 bytes)")
        if _PFM_HEADER_CUT.match(raw):
            raise ValueError(
                f"truncated PFM file {p}: it ends within its header ({len(raw)} bytes: "
                f"{raw.decode('ascii')!r})"
            )
        raise ValueError(f"not a PFM file (bad header): {p}")
    channels = 3 if m.group(1) == b"PF" else 1
    width, height = int(m.group(2)), int(m.group(3))
    try:
        scale = float(m.group(4))
    except ValueError:  # "1.0.0", ".": float()'s own message named no file
        raise ValueError(
            f"bad PFM header in {p}: scale {m.group(4).decode()!r} is not a number"
        ) from None
    if width <= 0 or height <= 0 or scale == 0.0 or not math.isfinite(scale):
        raise ValueError(
            f"bad PFM header in {p}: width {width}, height {height}, scale {scale} "
            "(expected positive sizes and a non-zero scale)"
        )
    dtype = np.dtype("<f4") if scale < 0 else np.dtype(">f4")
    count = width * height * channels
    # the scale line ends in a line feed (the format), after Windows tools' \r or trailing
    # spaces: that \r or space taken as the whole line ending began the data a byte or more
    # early, every value misread. Only a header ended by one other whitespace character and no
    # line feed (PNM's rule) starts its data right after that character.
    line_end = _PFM_LINE_END.match(raw, m.end())
    start = m.end() + 1 if line_end is None else line_end.end()
    # ... also when its data begins with bytes that read as such a line end (a float whose
    # first byte is 0x0A after "-1.0 " lost that byte): one space or tab, then exactly the data
    # to the file's end (a CR is taken as CRLF's: a CRLF file one byte short is truncated)
    if line_end is not None and len(raw) - count * 4 == m.end() + 1 and raw[m.end()] in b" \t":
        start = m.end() + 1
    nbytes = max(len(raw) - start, 0)
    # a magic of the other kind (a writer's "PF" before a grey map: PF is colour) was
    # "truncated" of a whole file, or, Pf before colour data, its first third read as a grey
    # map of interleaved R, G, B values without a word
    grey = width * height * 4
    if nbytes == (grey if channels == 3 else 3 * grey):
        held, kind, other = (
            (f"{width}x{height} grey values", "colour map (3 values a pixel)", "a grey map's is Pf")
            if channels == 3
            else (
                f"{width}x{height}x3 values",
                "grey map (1 value a pixel)",
                "a colour map's is PF",
            )
        )
        raise ValueError(
            f"bad PFM header in {p}: {m.group(1).decode()} says a {kind}, but its {nbytes} data "
            f"bytes hold {held}: {other}"
        )
    if nbytes < count * 4:
        raise ValueError(
            f"truncated PFM file {p}: expected {count * 4} data bytes for {width}x{height}x"
            f"{channels}, got {nbytes}"
        )
    data = np.frombuffer(raw, dtype=dtype, count=count, offset=start)
    _warn_if_byte_order_wrong(data, p, scale)
    shape = (height, width, 3) if channels == 3 else (height, width)
    # a copy, always: of a single row, ascontiguousarray kept the read-only view of ``raw``
    # (load_scene's ``gt[...] = nan`` was "assignment destination is read-only")
    return np.array(data.reshape(shape)[::-1], dtype=np.float32, order="C")


def _out_of_range(values: npt.NDArray[Any]) -> npt.NDArray[np.bool_]:
    """Where ``values`` are finite, non-zero and below ``1e-30`` or beyond ``1e30`` in
    magnitude: what floats read in the wrong byte order mostly are (14.0 -> 3.4e-41, inf ->
    4.6e-41), and a map's or an image's are not."""
    with np.errstate(invalid="ignore"):
        size = np.abs(values)
        return np.isfinite(values) & (values != 0) & ((size < 1e-30) | (size > 1e30))


def _warn_if_byte_order_wrong(data: npt.NDArray[Any], path: Path, scale: float) -> None:
    """Warn when ``data``, read in the byte order its scale's sign gives, is mostly out of range
    (:func:`_out_of_range`) where the other order reads plausibly throughout: a writer that
    gave the scale the wrong sign (``1.0`` before little-endian data). Such a GT was read as
    garbage (tsukuba's 14 px as 3.4e-41) without a word; the values are still returned as the
    header says, the order is not guessed."""
    from stereovision._validate import source_warning

    read = data[:: max(1, data.size // 65536)]  # a bounded look: a large map's cost is one read
    finite = int(np.count_nonzero(np.isfinite(read)))
    wrong = int(np.count_nonzero(_out_of_range(read))) / max(finite, 1)
    if wrong < 0.1:
        return
    other = read.view(read.dtype.newbyteorder())
    # a NaN the other order makes of a large value (float32's largest: 0xffff7f7f) is no
    # plausible reading; one made of a tiny value is a GT's NaN (unknown) read here swapped
    with np.errstate(invalid="ignore"):
        made_nan = np.isnan(other) & ~(np.abs(read) < 1e-30)
    if np.count_nonzero(_out_of_range(other) | made_nan) > 0.001 * read.size:
        return
    said, other_order = ("little", "big") if scale < 0 else ("big", "little")
    source_warning(
        f"PFM file {path}: its scale {scale:g} says {said}-endian, but {wrong:.0%} of its "
        f"finite values read so are below 1e-30 or beyond 1e30, where read {other_order}-endian "
        "they are plausible: its writer may have given the scale the wrong sign (negative: "
        "little-endian)"
    )


def write_pfm(path: PathLike, arr: npt.ArrayLike, little_endian: bool = True) -> Path:
    """Write a ``float32`` array as a PFM file (bottom-up rows, scale magnitude 1), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination file.
    arr : array_like
        ``(H, W)`` (written as ``Pf``) or ``(H, W, 3)`` (``PF``) real array, cast to
        ``float32``. NaN and inf are written as they are, bit for bit. A ``PF`` file's
        channels are **RGB** (the format's, as :func:`read_pfm` gives them back): flip an
        OpenCV BGR image first, ``img[..., ::-1]`` (``cv2.imwrite`` flips it itself).
    little_endian : bool
        Byte order of the data (scale ``-1`` when True, ``+1`` otherwise).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        If ``arr`` has the wrong shape or a non-real dtype, finite values beyond float32's
        range (they would be written as inf), or masked pixels (a ``numpy.ma`` array: pass
        ``arr.filled(np.nan)``).
    TypeError
        If ``little_endian`` is not True or False.
    """
    dest = as_path(path, file=True)
    if not isinstance(little_endian, (bool, np.bool_)):
        # "no" was true: a little-endian file where the caller asked for the other order
        raise TypeError(f"little_endian: expected True or False, got {little_endian!r}")
    from stereovision._validate import _refuse_masked, check_index_range, refuse_beyond_float32

    # asarray reads a masked array's data: its masked pixels were written as real values
    _refuse_masked(arr, "arr", "np.nan")
    a = np.asarray(arr)
    if a.dtype.kind not in "iuf" or a.size == 0:
        raise ValueError(f"arr: expected a non-empty real array, got {_describe(a)}")
    if not (a.ndim == 2 or (a.ndim == 3 and a.shape[2] == 3)):
        raise ValueError(f"arr: expected shape (H, W) or (H, W, 3), got {a.shape}")
    check_index_range(a.shape, "arr", "map")  # before the float32 copy and the file's bytes
    refuse_beyond_float32(a, "arr", "would be written as inf")
    height, width = a.shape[:2]
    magic = b"PF" if a.ndim == 3 else b"Pf"
    dtype = np.dtype("<f4") if little_endian else np.dtype(">f4")
    body = np.ascontiguousarray(a[::-1], dtype=dtype).tobytes()
    scale = b"-1.0" if little_endian else b"1.0"
    header = magic + b"\n" + f"{width} {height}".encode() + b"\n" + scale + b"\n"
    with atomic_write(dest) as fh:
        fh.write(header)
        fh.write(body)
    return dest


# ------------------------------------------------------------------------------------------ PLY

_PLY_TYPES: dict[str, str] = {
    "char": "i1",
    "int8": "i1",
    "uchar": "u1",
    "uint8": "u1",
    "short": "i2",
    "int16": "i2",
    "ushort": "u2",
    "uint16": "u2",
    "int": "i4",
    "int32": "i4",
    "uint": "u4",
    "uint32": "u4",
    "float": "f4",
    "float32": "f4",
    "double": "f8",
    "float64": "f8",
}


#: The UTF-8 byte-order mark a Windows editor puts before a text file's first line.
_UTF8_BOM = b"\xef\xbb\xbf"

#: Comment of :func:`write_ply`'s header: the units and frame of the project's clouds.
PLY_CLOUD_COMMENT = "stereovision point cloud (metres, X right, Y down, Z forward)"


def write_ply(
    path: PathLike,
    points: npt.ArrayLike,
    colors: npt.ArrayLike | None = None,
    drop_invalid: bool = True,
    *,
    comment: str | None = None,
) -> Path:
    """Write a point cloud as a binary little-endian PLY file, atomically.

    Vertex properties: ``float x, y, z`` and, with colours, ``uchar red, green, blue``. The
    header's comment gives the units and frame (:data:`PLY_CLOUD_COMMENT` by default, the
    project's convention), as the mesh and PCD writers' headers do.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.ply`` file; its folder must exist. Written under a temporary name and renamed,
        so a reader never sees half a file.
    points : array_like
        ``(N, 3)`` (or ``(H, W, 3)``, flattened row-major) coordinates, cast to ``float32``;
        the project's frame is the left rectified camera, metres, X right, Y down, Z forward.
    colors : array_like, optional
        ``uint8`` colours in **RGB** order, same leading shape as ``points`` (flip OpenCV's BGR
        with ``img[..., ::-1]``).
    drop_invalid : bool
        Skip points with a non-finite coordinate (NaN = no depth). When False they are written.
    comment : str, optional
        The header's comment line, for points in another unit or frame (one line of printable
        ASCII); default :data:`PLY_CLOUD_COMMENT`.

    Returns
    -------
    pathlib.Path
        The file written (its ``element vertex`` count is the number of points kept).

    Raises
    ------
    ValueError
        If ``points`` is not ``(..., 3)`` real, holds finite values beyond float32's range
        (they would become inf) or masked values (``numpy.ma``: pass
        ``points.filled(np.nan)``), ``colors`` does not match it or is not ``uint8``, or
        ``comment`` is not one line of printable ASCII.
    FileNotFoundError
        If the folder of ``path`` does not exist.
    TypeError
        If ``drop_invalid`` is not True or False.
    """
    dest = as_path(path, file=True)
    if not isinstance(drop_invalid, (bool, np.bool_)):
        # "no" (true) dropped the NaN points the caller meant to keep, None kept them
        raise TypeError(f"drop_invalid: expected True or False, got {drop_invalid!r}")
    if comment is None:
        comment = PLY_CLOUD_COMMENT
    if not (isinstance(comment, str) and comment.isascii() and comment.isprintable()):
        raise ValueError(f"comment: expected one line of printable ASCII, got {comment!r}")
    from stereovision._validate import _refuse_masked, refuse_beyond_float32

    # asarray reads a masked array's data: its masked points were written as real ones (NaN
    # points are dropped, as drop_invalid says)
    _refuse_masked(points, "points", "np.nan")
    pts = np.asarray(points)
    if pts.dtype.kind not in "iuf" or pts.ndim < 2 or pts.shape[-1] != 3:
        raise ValueError(f"points: expected a real (N, 3) array, got {_describe(pts)}")

    # a float64 point past float32's range became inf in the cast: dropped without a word
    # (drop_invalid), else written as inf, with NumPy's overflow warning alone
    fate = "would become inf (the point dropped)" if drop_invalid else "would be written as inf"
    refuse_beyond_float32(pts, "points", fate)
    # no copy of float32 points, no filtered copy when every point is finite: a 15 M point map
    # held four copies of itself on the way to the file
    pts = pts.reshape(-1, 3).astype(np.float32, copy=False)
    cols: np.ndarray | None = None
    if colors is not None:
        cols = np.asarray(colors)
        if cols.dtype != np.uint8:
            raise ValueError(f"colors: expected dtype uint8, got {cols.dtype}")
        shape = np.shape(points)
        # a flat (N, 3) side pairs by count; two images by their shape (a transposed
        # (W, H, 3) colour image of (H, W, 3) points paired each point with another's colour)
        mismatch = len(shape) > 2 and cols.ndim > 2 and cols.shape != shape
        if cols.ndim < 2 or cols.shape[-1] != 3 or cols.size != pts.size or mismatch:
            raise ValueError(
                f"colors: expected shape {np.asarray(points).shape} (RGB per point), "
                f"got {cols.shape}"
            )
        cols = cols.reshape(-1, 3)
    if drop_invalid:
        keep = np.isfinite(pts).all(axis=1)
        if not keep.all():
            pts = pts[keep]
            if cols is not None:
                cols = cols[keep]
    fields: list[tuple[str, str]] = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if cols is not None:
        fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
    rec = np.empty(len(pts), dtype=np.dtype(fields))
    rec["x"], rec["y"], rec["z"] = pts[:, 0], pts[:, 1], pts[:, 2]
    lines = [
        "ply",
        "format binary_little_endian 1.0",
        f"comment {comment}",
        f"element vertex {len(pts)}",
        "property float x",
        "property float y",
        "property float z",
    ]
    if cols is not None:
        rec["red"], rec["green"], rec["blue"] = cols[:, 0], cols[:, 1], cols[:, 2]
        lines += ["property uchar red", "property uchar green", "property uchar blue"]
    lines.append("end_header")
    with atomic_write(dest) as fh:
        fh.write(("\n".join(lines) + "\n").encode("ascii"))
        fh.write(rec.view(np.uint8))  # the records' bytes, not a copy of them (tobytes)
    return dest


def read_ply(
    path: PathLike,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8] | None]:
    """Read a PLY point cloud with ``x, y, z`` and optional ``red, green, blue`` (or
    ``diffuse_red, diffuse_green, diffuse_blue``).

    Reads the files :func:`write_ply` writes and other ASCII or binary (little- or big-endian)
    PLY files (a UTF-8 byte-order mark before ``ply`` allowed) with a ``vertex`` element of
    scalar properties (elements after it are ignored,
    the rows of those before it, MeshLab's ``camera``, skipped: in a binary file only elements
    of scalar properties). Colours of a floating-point type are taken as 0-1 (as some tools
    write them) and scaled to 0-255, or as 0-255 when any of them is above 1. Colours of a
    wider integer type are taken as 0-255 when none is above 255, else as 16-bit 0-65535
    (PDAL's ``ushort`` colours of a LAS cloud) and scaled to 0-255; negative ones as 0.

    Parameters
    ----------
    path : str or os.PathLike
        PLY file.

    Returns
    -------
    points : numpy.ndarray
        ``(N, 3)`` ``float32``.
    colors : numpy.ndarray or None
        ``(N, 3)`` ``uint8`` RGB, or None if the file has no colour properties.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        ``"not a PLY file"`` for anything else; missing ``x/y/z``, truncated or damaged data
        are also reported as ValueError.
    """
    p = _existing_file(path, "PLY file")
    # an ASCII cloud saved by a Windows editor opens with a UTF-8 byte-order mark: it was "not a
    # PLY file"
    raw = p.read_bytes()
    if not raw:  # "not a PLY file" alone read as another format's file (imread says this)
        raise ValueError(f"not a PLY file (the file is empty, 0 bytes): {p}")
    raw = raw.removeprefix(_UTF8_BOM)
    # the first line is "ply" (a CR, trailing blanks kept): "plyfoo" was read as a PLY file
    magic = re.match(rb"ply[ \t\r]*\n", raw) is not None
    # the line that is "end_header", not the first "end_header" (a comment may hold one)
    found = re.search(rb"(?m)^end_header[ \t\r]*$", raw) if magic else None
    end = found.start() if found else -1
    if not magic or end < 0:
        raise ValueError(f"not a PLY file: {p}")
    nl = raw.find(b"\n", end)
    if nl < 0:
        raise ValueError(f"not a PLY file (header not terminated): {p}")
    # a comment's text is free (an author's name, a place, in UTF-8: refused as a "non-ASCII
    # header", a cloud its writer reads); every other header line is ASCII
    # split as bytes: str.splitlines also breaks at U+0085, a byte of UTF-8's "Å" (C3 85)
    header = [line.decode("latin-1") for line in raw[:end].splitlines()]
    if not all(
        line.isascii()
        for line in header
        if line.split(maxsplit=1)[:1] not in (["comment"], ["obj_info"])
    ):
        raise ValueError(f"not a PLY file (non-ASCII header): {p}")
    order = ""
    count = -1
    props: list[tuple[str, str]] = []
    # elements before the vertices (MeshLab writes its camera first): [name, rows, bytes a
    # binary row takes, holds a list property], their rows skipped
    before: list[list[Any]] = []
    in_vertex = False
    for line in header[1:]:
        tok = line.split()
        if not tok or tok[0] in ("comment", "obj_info"):
            continue
        if tok[0] == "format":
            fmt = tok[1] if len(tok) > 1 else ""
            if fmt == "binary_little_endian":
                order = "<"
            elif fmt == "binary_big_endian":
                order = ">"
            elif fmt == "ascii":
                order = "="
            else:
                raise ValueError(
                    f"unsupported PLY format {fmt!r} in {p} (ascii, binary_little_endian or "
                    "binary_big_endian)"
                )
        elif tok[0] == "element":
            if count >= 0 and in_vertex:
                in_vertex = False
                break
            in_vertex = len(tok) > 1 and tok[1] == "vertex"
            # the name as written, not a list: a bare `element` said "first element is []"
            if len(tok) == 1:
                raise ValueError(
                    f"PLY file {p}: an element line names no element (expected vertex)"
                )
            if not in_vertex:
                # a legal file whose first element is another (MeshLab's camera) was refused
                rows = " ".join(tok[2:])
                if len(tok) != 3 or not rows.isascii() or not rows.isdigit():
                    raise ValueError(
                        f"PLY file {p}: {tok[1]} count {rows!r} is not a whole number (>= 0)"
                    )
                before.append([tok[1], int(rows), 0, False])
                continue
            # a vertex line without its one count was told off as "first element is
            # ['vertex'], expected vertex"
            if len(tok) == 2:
                raise ValueError(f"PLY file {p}: element vertex has no count")
            # int()'s own "invalid literal" named no file; -3 read as no vertex element
            given = " ".join(tok[2:])
            if len(tok) != 3 or not given.isascii() or not given.isdigit():
                raise ValueError(
                    f"PLY file {p}: vertex count {given!r} is not a whole number (>= 0)"
                )
            count = int(tok[2])
        elif tok[0] == "property" and in_vertex:
            if len(tok) != 3 or tok[1] not in _PLY_TYPES:
                raise ValueError(f"PLY file {p}: unsupported vertex property {line!r}")
            if any(tok[2] == name for name, _ in props):  # NumPy's "occurs more than once"
                raise ValueError(f"PLY file {p}: vertex property {tok[2]!r} given twice")
            props.append((tok[2], tok[1]))
        elif tok[0] == "property" and before and count < 0:
            if len(tok) > 1 and tok[1] == "list":
                before[-1][3] = True
            elif len(tok) == 3 and tok[1] in _PLY_TYPES:
                before[-1][2] += np.dtype(_PLY_TYPES[tok[1]]).itemsize
            else:
                raise ValueError(f"PLY file {p}: unsupported {before[-1][0]} property {line!r}")
    if order and count < 0 and before:
        elements = ", ".join(name for name, *_ in before)
        raise ValueError(f"PLY file {p}: no vertex element (elements: {elements})")
    if not order or count < 0:
        raise ValueError(f"not a PLY file (no format or vertex element): {p}")
    names = [n for n, _ in props]
    if not {"x", "y", "z"} <= set(names):
        raise ValueError(f"PLY file {p}: vertex has properties {names}, expected x, y, z")
    # an ASCII file's float x, y, z as their text's float64: a 1e39 was made inf in the cast to
    # float, said by nothing but NumPy's "overflow encountered in cast" (_float32_coordinates)
    dtype = np.dtype(
        [
            (n, "f8")
            if order == "=" and n in ("x", "y", "z") and _PLY_TYPES[t][0] == "f"
            else (n, order + _PLY_TYPES[t])
            for n, t in props
        ]
    )
    start = nl + 1
    if order == "=":
        # an element's row is a line, whatever its properties
        for _ in range(sum(rows for _, rows, _, _ in before)):
            start = raw.find(b"\n", start) + 1
            if start == 0:
                raise ValueError(f"truncated PLY file {p}: expected {count} vertices")
        rec = _ascii_ply_vertices(raw[start:], dtype, count, p)
    else:
        # an element of no rows has nothing to skip (an empty face list written first)
        listed = [name for name, rows, _, has_list in before if has_list and rows]
        if listed:
            raise ValueError(
                f"PLY file {p}: element {listed[0]!r} before vertex holds a list property (its "
                "binary rows are not skipped)"
            )
        start += sum(rows * size for _, rows, size, _ in before)
        if len(raw) - start < count * dtype.itemsize:
            raise ValueError(
                f"truncated PLY file {p}: expected {count} vertices of {dtype.itemsize} bytes"
            )
        rec = np.frombuffer(raw, dtype=dtype, count=count, offset=start)
    pts = _float32_coordinates(np.stack([rec["x"], rec["y"], rec["z"]], axis=1), p, "PLY")
    cols: npt.NDArray[np.uint8] | None = None
    prefix = next(
        (q for q in ("", "diffuse_") if {f"{q}red", f"{q}green", f"{q}blue"} <= set(names)), None
    )
    if prefix is not None:  # "diffuse_red": MeshLab's and Blender's older name
        rgb = np.stack([rec[f"{prefix}{c}"] for c in ("red", "green", "blue")], axis=1)
        if rgb.dtype.kind == "f":
            rgb = np.nan_to_num(rgb)
            # 0-1 (a uint8 cast made every colour 0 or 1: black), unless a value is above 1:
            # 0-255 then, as Open3D reads float colours (as 0-1 they all came out white)
            top = 1.0 if rgb.size == 0 or float(rgb.max()) <= 1.0 else 255.0
            rgb = np.rint(np.clip(rgb, 0.0, top) * (255.0 / top))
        elif rgb.dtype != np.uint8:
            # wider or signed integers wrapped in the uint8 cast (PDAL writes a LAS cloud's
            # 16-bit colours as ushort: 65535 was 255 but 32768 was 0, 256 was 0, -5 was 251):
            # 0-255 when none is above 255, else 16-bit 0-65535 scaled to 0-255
            wide = rgb.astype(np.int64)
            top = 255.0 if wide.size == 0 or int(wide.max()) <= 255 else 65535.0
            rgb = np.rint(np.clip(wide, 0, top) * (255.0 / top))
        cols = rgb.astype(np.uint8)
    return pts, cols


def _float32_coordinates(xyz: npt.NDArray[Any], path: Path, kind: str) -> npt.NDArray[np.float32]:
    """A cloud's ``(N, 3)`` coordinates, as read (a double PLY's or PCD's), as ``float32``.

    A finite coordinate beyond float32's range (``1e39``) becomes inf in the cast, no point,
    as before; it is said in one warning naming the file (``read_ply``'s and
    ``export.read_pcd``'s), where NumPy's "overflow encountered in cast" named nothing.
    """
    from stereovision._validate import points_as_float32, source_warning

    pts, lost = points_as_float32(xyz)
    if lost is not None:
        source_warning(f"{kind} file {path}: {lost} read as inf (no point)")
    return pts


def _ascii_table(
    body: bytes,
    path: Path,
    kind: str,
    columns: int,
    *,
    rows: int | None = None,
    first: bool = False,
) -> npt.NDArray[np.float64]:
    """The numbers of an ASCII point file's body, a row a line, as a 2-D ``float64`` table
    (``read_ply``'s and ``export.read_pcd``'s): ``rows`` rows at the most (None: all), the
    ``first`` ``columns`` of each only (else every column). An empty body is ``(0, columns)``
    (NumPy warned "input contained no data" and gave ``(0, 1)``).

    Raises
    ------
    ValueError
        A short or damaged row: NumPy's words, with ``kind`` ("PLY", "PCD") and the file's name.
    """
    import io as _io

    if not body.strip():
        return np.zeros((0, columns))
    try:
        with warnings.catch_warnings():
            # a blank line in the body (an exporter's, a hand edit's) is skipped, as it was,
            # but NumPy said so in a 4-line UserWarning about its max_rows since NumPy 1.23,
            # printed before the CLI's own output
            warnings.filterwarnings("ignore", "Input line", UserWarning)
            return np.loadtxt(
                _io.BytesIO(body),
                dtype=np.float64,
                ndmin=2,
                max_rows=rows,
                usecols=range(columns) if first else None,
            )
    except ValueError as exc:  # a short or damaged row: NumPy's words, with the file's name
        raise ValueError(f"damaged {kind} file {path}: {str(exc).splitlines()[0]}") from None


def _ascii_ply_vertices(
    body: bytes, dtype: np.dtype[Any], count: int, path: Path
) -> npt.NDArray[Any]:
    """The first ``count`` rows of an ASCII PLY body as records of ``dtype`` (one value per
    property; rows of later elements, faces, are not read)."""
    if count == 0:
        return np.empty(0, dtype=dtype)
    names = dtype.names or ()
    # no more rows than the body has lines: a damaged count (99999999999 of one row) was a
    # MemoryError of terabytes (NumPy's table, the records), not "truncated"
    rows = min(count, body.count(b"\n") + 1)
    table = _ascii_table(body, path, "PLY", len(names), rows=rows, first=True)
    if table.shape[0] < count:
        raise ValueError(f"truncated PLY file {path}: expected {count} vertices")
    rec = np.empty(count, dtype=dtype)
    for i, name in enumerate(names):
        kind = dtype[name]
        column = table[:, i]
        if kind.kind in "iu":
            # the cast wrapped a value the property's type cannot hold: a uchar red of 300
            # came back 44, -1 255
            info = np.iinfo(kind)
            bad = ~((column >= info.min) & (column <= info.max) & (column == np.round(column)))
            if bad.any():
                raise ValueError(
                    f"damaged PLY file {path}: vertex property {name!r} holds "
                    f"{float(column[bad][0]):g}, not a whole number {info.min} to {info.max} "
                    "as its type"
                )
        rec[name] = column
    return rec


# --------------------------------------------------------------------------------------- scenes


@dataclass(eq=False)
class Scene:
    """One evaluation scene of ``../shared/data`` (evaluation.md "Data layout").

    Attributes
    ----------
    name : str
        ``"<family>/<scene>"``, e.g. ``"middlebury2001/tsukuba"``.
    left, right : numpy.ndarray
        The rectified pair as read: ``(H, W, 3)`` ``uint8`` BGR (``uint16`` for 16-bit files
        loaded with ``full_bits``).
    gt : numpy.ndarray or None
        ``(H, W)`` ``float32`` GT disparity of the left image in pixels, NaN where unknown
        (the files' ``+inf``); None when the scene has no ``gt_disp.pfm``.
    calib : Calibration or None
        From ``calib.txt`` (Middlebury format, unit mm) when present, else from ``Q.dat``
        (OpenCV's ``Q``, unit m); None without either.
    max_disparity : int
        Disparity search range for every method (multiple of 16): ``1.1 x`` the largest finite
        GT disparity rounded up; without GT the calibration's ``ndisp`` rounded up when the
        images are wider than that, else a quarter of the width rounded up.
    path : pathlib.Path
        The scene directory.
    """

    name: str
    left: npt.NDArray[np.uint8] | npt.NDArray[np.uint16]
    right: npt.NDArray[np.uint8] | npt.NDArray[np.uint16]
    gt: npt.NDArray[np.float32] | None
    calib: Calibration | None
    max_disparity: int
    path: Path

    def __repr__(self) -> str:
        h, w = self.left.shape[:2]
        return (
            f"Scene({self.name!r}, {w}x{h}, max_disparity={self.max_disparity}, "
            f"gt={'yes' if self.gt is not None else 'no'}, "
            f"calib={'yes' if self.calib is not None else 'no'})"
        )


def _refuse_no_scene(scene: object) -> None:
    """Refuse what is not a scene (a :class:`Scene` or an object with its attributes) with a
    TypeError naming ``scene``, in :func:`scene_too_narrow`'s and ``bench_scene``'s words.

    A scene folder was "AttributeError: 'str' object has no attribute 'max_disparity'" (as
    bench_scene said it, d6b69581), None "'NoneType' object has no attribute 'left'"."""
    from stereovision._validate import _shown

    if isinstance(scene, (str, bytes, os.PathLike)):
        raise TypeError(
            f"scene: got the path {os.fsdecode(scene)!r}, not a scene: load it first "
            "(stereovision.io.load_scene(path))"
        )
    if not all(hasattr(scene, a) for a in ("left", "right", "gt", "calib", "max_disparity")):
        raise TypeError(
            f"scene: expected a scene (stereovision.io.load_scene(path)), got {_shown(scene)}"
        )


def scene_too_narrow(scene: Scene) -> str | None:
    """Why a scene cannot be matched over its own range, or None: images not wider than its
    ``max_disparity`` (:func:`scene_max_disparity`, 16 px at least). ``eval`` and ``bench`` say
    it in these words: the range is the scene's, never the caller's.

    Parameters
    ----------
    scene : Scene
        A scene :func:`load_scene` loaded.

    Returns
    -------
    str or None
        The reason, naming the images' width, the scene's range and the width it needs; for a
        range its GT sets (above 16 px), the GT's largest disparity and that the GT may not
        be in pixels (KITTI's PNGs hold 256 x the disparity).

    Raises
    ------
    TypeError
        If ``scene`` is a path (a scene folder: :func:`load_scene` reads it) or no scene
        (None).
    """
    from stereovision._validate import figure_shown

    _refuse_no_scene(scene)
    md, width = scene.max_disparity, scene.left.shape[1]
    if md < width:
        return None
    needs = f"a scene needs images at least {md + 1} px wide"
    gt = scene.gt
    top = float(np.nanmax(gt, initial=-np.inf, where=np.isfinite(gt))) if gt is not None else 0.0
    if top > 0 and 16 < md == scene_max_disparity(gt, width):
        # a GT kept in KITTI's 256 x scale (4458 px on a 300 px crop) was said to need images
        # 4913 px wide and nothing more: the rule's number, not the GT that set it
        return (
            f"images {width} px wide, not wider than the scene's disparity range ({md} px: 1.1 "
            f"x its largest GT disparity, {figure_shown(top)} px, rounded up to a multiple of "
            f"16): {needs}, or its gt_disp.pfm is not in pixels (KITTI's PNGs hold 256 x the "
            "disparity)"
        )
    return (
        f"images {width} px wide, not wider than the scene's disparity range ({md} px, "
        f"evaluation.md's rule: 16 at least): {needs}"
    )


def scene_max_disparity(
    gt: npt.NDArray[np.floating[Any]] | None,
    width: int,
    ndisp: float | None = None,
) -> int:
    """Disparity search range of a scene (evaluation.md rule), a multiple of 16.

    Parameters
    ----------
    gt : numpy.ndarray or None
        GT disparity (pixels; non-finite = unknown).
    width : int
        Image width in pixels (fallback).
    ndisp : float, optional
        ``ndisp`` of a Middlebury ``calib.txt`` (fallback).

    Returns
    -------
    int
        ``round_up16(1.1 * max finite GT)``; without usable GT ``round_up16(ndisp)`` when that
        is below ``width``, else ``round_up16(width // 4)`` (an ``ndisp`` the images have no room
        for bounds nothing: ETH3D's calib.txt gives the width).

    Raises
    ------
    ValueError
        If ``width`` is not a positive integer, or ``ndisp`` is given and is not a positive
        finite number (a width of 0 gave 16, an ndisp of NaN or -5 the width's range).
    """
    from stereovision._validate import positive_finite

    if not isinstance(width, (int, np.integer)) or isinstance(width, NOT_NUMBERS) or width <= 0:
        raise ValueError(
            f"width: expected the image width in pixels (a positive integer), got {width!r}"
        )
    if ndisp is not None:
        ndisp = positive_finite(ndisp, "ndisp")
    if gt is not None:
        finite = gt[np.isfinite(gt)]
        if finite.size and float(finite.max()) > 0:
            # 1.1 x in exact arithmetic: in floats 1.1 * 800 is 880.0000000000001, which
            # rounded up to 896 where the rule gives 880 (also 1440, 1600, 1760 px ...)
            margin = Fraction(repr(MAX_DISPARITY_MARGIN)) * Fraction(float(finite.max()))
            return round_up16(math.ceil(margin))
    # an ndisp whose range the images have no room for bounds nothing: ETH3D's calib.txt gives
    # the width (941 on playground: 944 px), and such a scene without GT was too narrow for its
    # own range (bench and view refused it)
    if ndisp is not None and round_up16(ndisp) < width:
        return round_up16(ndisp)
    return round_up16(width // _WIDTH_FRACTION)


#: Why a folder of ``Left.png`` or ``right.PNG`` is no scene (:func:`scan_scenes`).
_LOWER_CASE_NAMES = "a scene's images are named left.png and right.png, in lower case"
_SCENE_PAIR = ("left.png", "right.png")


def _cased_pair(folder: Path) -> str | None:
    """Why ``folder`` of ``Left.png`` or ``right.PNG`` (neither ``left.png`` nor ``right.png``)
    is no scene, in :func:`scan_scenes`' words; None for any other folder."""
    if any(os.path.lexists(folder / n) for n in ("left.png", "right.png")):
        return None
    try:
        cased = sorted(q.name for q in folder.iterdir() if q.name.lower() in _SCENE_PAIR)
    except OSError:
        return None
    return f"holds {', '.join(cased)}: {_LOWER_CASE_NAMES}" if cased else None


def _absolute_as_read(path: Path) -> Path:
    """``path`` made absolute with each '..' folded as the OS follows it, links' names kept.

    :func:`os.path.abspath` folds '..' as text: ``home/link/../x`` gave ``home/x``, where the OS
    reads ``x`` beside the link's target. A '..' after a link goes up from its target here; any
    other '..' drops the name before it, as abspath does.
    """
    shown = Path(path.anchor) if path.is_absolute() else Path(os.getcwd())
    for part in path.parts[1:] if path.is_absolute() else path.parts:
        if part != "..":
            shown = shown / part
        elif shown.is_symlink():
            shown = Path(os.path.realpath(shown)).parent
        else:
            shown = shown.parent
    return shown


def _present(path: Path) -> bool:
    """Whether a scene's optional file is there; a link to nothing is refused, not absent.

    ``exists()`` is False for a link whose target moved (a dataset linked in from a download
    folder that was then moved): the scene was loaded without its GT or calibration, and
    ``eval`` said "no ground truth (gt_disp.pfm)" of a folder that lists one.

    Raises
    ------
    FileNotFoundError
        If ``path`` is a link whose target does not exist, naming both.
    """
    if path.exists():
        return True
    if path.is_symlink():
        said = _broken_link(path)
        moved = " (moved or deleted?)" if said.endswith("does not exist") else ""
        raise FileNotFoundError(f"{path} is {said}{moved}")
    return False


def load_scene(directory: PathLike, *, full_bits: bool = False) -> Scene:
    """Load one scene directory (``left.png``, ``right.png``, optional GT and calibration).

    The calibration is ``calib.txt`` (Middlebury format, :meth:`Calibration.from_middlebury`),
    else ``Q.dat`` (OpenCV's 4x4 ``Q`` matrix, baseline in metres,
    :meth:`Calibration.from_q`), else none.

    Parameters
    ----------
    directory : str or os.PathLike
        Scene directory.
    full_bits : bool
        Read a 16-bit ``left.png`` / ``right.png`` at its 16 bits (:func:`read_image`, as
        ``stereovision depth`` and ``batch`` read them: ``eval``, ``bench`` and ``view`` do); by
        default their top 8 (:func:`imread`). 8-bit files are read alike either way.

    Returns
    -------
    Scene

    Raises
    ------
    FileNotFoundError
        If the directory, ``left.png`` or ``right.png`` is missing (for a folder of
        Middlebury's ``im0.png`` + ``im1.png``, naming the files to rename; of ``Left.png`` +
        ``Right.png``, saying the names are lower case), or ``gt_disp.pfm``,
        ``calib.txt`` or ``Q.dat`` is a link to a file that does not exist.
    NotADirectoryError
        If ``directory`` is a file (``cones/left.png``: the scene is its folder) or another
        thing that is no folder (``/dev/null``, a pipe).
    ValueError
        If an image cannot be decoded, the pair sizes differ, the GT is not one channel, its
        size differs from the left image or its known disparities are all negative (the other
        sign convention), or the calibration file is invalid (an
        ``ndisp`` of NaN, 0 or below included) or ``calib.txt``'s ``width`` and ``height`` are
        not the left image's.
    """
    from stereovision._validate import figure_shown
    from stereovision.calibration import Calibration, parse_middlebury_calib

    d = as_path(directory, "directory")
    if d.is_file():
        # load_scene('cones/left.png') was "scene directory not found" of a file that is there
        raise NotADirectoryError(
            f"{d} is a file, not a scene directory: a scene is the folder holding left.png and "
            f"right.png ({d.parent}?)"
        )
    if d.exists() and not d.is_dir():
        # load_scene('/dev/null') (a device, a pipe: there, neither file nor folder) was
        # "scene directory not found" of a path that is there
        raise NotADirectoryError(
            f"{d} is not a folder (a device or a pipe), not a scene directory: a scene is the "
            "folder holding left.png and right.png"
        )
    if not d.is_dir():
        # a link whose target moved (a dataset on a disk since unmounted) was "not found" alone,
        # of a name ls lists: its target is named, as eval's and the file readers' words name it
        gone = f" ({_broken_link(d)})" if d.is_symlink() and not d.exists() else ""
        raise FileNotFoundError(f"scene directory not found: {d}{gone}")
    if not any(os.path.lexists(d / n) for n in ("left.png", "right.png")) and all(
        (d / n).is_file() for n in ("im0.png", "im1.png")
    ):
        # a folder as Middlebury ships it: said as eval and bench say it (scan_scenes), not
        # only "image file not found: .../left.png" with the names to use unsaid
        raise FileNotFoundError(f"image file not found: {d / 'left.png'}; {d} {_MIDDLEBURY_NAMES}")
    cased = _cased_pair(d)
    if cased:  # Left.png + Right.png: "image file not found: .../left.png" alone, beside them
        raise FileNotFoundError(f"image file not found: {d / 'left.png'}; {d} {cased}")
    read = read_image if full_bits else imread
    left, right = read(d / "left.png"), read(d / "right.png")
    if left.shape != right.shape:
        raise ValueError(
            f"scene {d}: left.png is {image_size_text(left)}, right.png is "
            f"{image_size_text(right)}: the two images of a pair have one size"
        )
    gt: npt.NDArray[np.float32] | None = None
    gt_path = d / "gt_disp.pfm"
    if _present(gt_path):
        gt = read_pfm(gt_path)
        if gt.ndim == 3:  # else refused below as 'gt_disp.pfm is 6x4, left.png 6x4'
            raise ValueError(
                f"scene {d}: gt_disp.pfm holds {gt.shape[2]} channels (a colour PF file): a GT "
                "disparity map has one value per pixel (Pf)"
            )
        if gt.shape != left.shape[:2]:
            raise ValueError(
                f"scene {d}: gt_disp.pfm is {gt.shape[1]}x{gt.shape[0]}, left.png "
                f"{left.shape[1]}x{left.shape[0]}"
            )
        gt[~np.isfinite(gt)] = np.nan
        low, high = float(np.nanmin(gt, initial=np.inf)), float(np.nanmax(gt, initial=-np.inf))
        if low < 0 and high <= 0:
            # a GT of the other sign convention (x_right - x_left) was evaluated as it was:
            # every method 100 % bad on every threshold, without a word
            raise ValueError(
                f"scene {d}: gt_disp.pfm's disparities are all negative ({figure_shown(high)} "
                f"to {figure_shown(low)} px), where a left image's are >= 0 (x_left - x_right): "
                "a GT of the other sign (negate it), or the right image's?"
            )
    calib: Calibration | None = None
    ndisp: float | None = None
    calib_path = d / "calib.txt"
    if _present(calib_path):
        calib = Calibration.from_middlebury(calib_path)
        if tuple(calib.image_size) != (left.shape[1], left.shape[0]):
            # loaded as it was, eval and view failed at the first depth with depth_map's
            # "calibration is for 80x40 images, got 40x20", naming neither scene nor file
            cw, ch = calib.image_size
            raise ValueError(
                f"scene {d}: calib.txt is for {cw}x{ch} images (its width and height), left.png "
                f"is {left.shape[1]}x{left.shape[0]}"
            )
        ndisp = parse_middlebury_calib(calib_path).get("ndisp")
        if ndisp is not None and not (math.isfinite(ndisp) and ndisp > 0):
            # NaN, -5 or 0 were taken as no ndisp (the width's range), without a word
            raise ValueError(
                f"{calib_path}: ndisp={ndisp:g}: expected the disparity range in pixels, a "
                "positive finite number"
            )
    elif _present(d / "Q.dat"):
        calib = Calibration.from_q(d / "Q.dat", (left.shape[1], left.shape[0]))
    # named from the absolute path, '..' folded: '.', 'tsukuba' or '../tsukuba' gave '/',
    # '/tsukuba' or '../tsukuba' (links keep their own names, as resolve() would not)
    # ('/tsukuba', a folder under the filesystem's root, has no family: named alone)
    named = _absolute_as_read(d)
    return Scene(
        name=f"{named.parent.name}/{named.name}" if named.parent.name else named.name,
        left=left,
        right=right,
        gt=gt,
        calib=calib,
        max_disparity=scene_max_disparity(gt, left.shape[1], ndisp),
        path=d,
    )


def distinct_scenes(dirs: Sequence[Path]) -> tuple[list[Path], list[Path]]:
    """``dirs`` without the scenes already listed (the same real folder: a scene and a folder
    holding it, both given), in order, and the dropped ones.

    Parameters
    ----------
    dirs : sequence of pathlib.Path
        Scene folders, as :func:`find_scenes` lists them.

    Returns
    -------
    kept, dropped : list of pathlib.Path
    """
    seen: set[Path] = set()
    kept: list[Path] = []
    dropped: list[Path] = []
    for s in dirs:
        real = s.resolve()
        (dropped if real in seen else kept).append(s)
        seen.add(real)
    return kept, dropped


def scene_names(dirs: Sequence[Path]) -> list[str]:
    """The names ``eval`` and ``bench`` show the scenes of ``dirs`` by: :func:`load_scene`'s
    ``family/scene``, with as many more of a folder's parents as tell it from another of
    ``dirs`` of that name (``day1/cam/0001`` and ``day2/cam/0001``, both ``cam/0001`` to
    :func:`load_scene`: two rows of one name in the table and the JSON lines).

    Parameters
    ----------
    dirs : sequence of pathlib.Path
        Distinct scene folders (:func:`distinct_scenes`).

    Returns
    -------
    list of str
        One name per folder, in order.
    """
    parts = [_absolute_as_read(Path(d)).parts[1:] for d in dirs]  # the anchor '/' left out
    depth = [2] * len(parts)
    while True:
        names = ["/".join(p[-k:]) for p, k in zip(parts, depth, strict=True)]
        count: dict[str, int] = {}
        for n in names:
            count[n] = count.get(n, 0) + 1
        longer = [i for i, n in enumerate(names) if count[n] > 1 and depth[i] < len(parts[i])]
        if not longer:
            return names
        for i in longer:
            depth[i] += 1


def find_scenes(root: PathLike) -> list[Path]:
    """Scene directories under ``root`` (any depth, through links to folders outside it, each
    once, hidden folders excepted) that contain ``left.png`` and ``right.png``.

    Parameters
    ----------
    root : str or os.PathLike
        Directory to search, e.g. ``../shared/data``.

    Returns
    -------
    list of pathlib.Path
        Sorted scene directories (``root`` itself if it is a scene).

    Raises
    ------
    FileNotFoundError
        If ``root`` does not exist.
    NotADirectoryError
        If ``root`` is a file (``cones/left.png``) or another thing that is no folder.
    PermissionError
        If ``root`` cannot be listed (an :class:`OSError` of its kind for another reason).
    """
    return scan_scenes(root)[0]


# Why a folder of Middlebury's names (im0.png + im1.png, as its archives ship a scene) is no
# scene: eval and bench said "no scene (left.png + right.png)" there, the names to use unsaid.
_MIDDLEBURY_FIX = (
    "a scene's images are named left.png + right.png and its ground truth gt_disp.pfm (rename "
    "im0.png, im1.png and disp0.pfm or disp0GT.pfm; calib.txt is read as it is)"
)
_MIDDLEBURY_NAMES = f"has Middlebury's im0.png + im1.png: {_MIDDLEBURY_FIX}"


def scan_scenes(root: PathLike) -> tuple[list[Path], list[tuple[Path, str]]]:
    """:func:`find_scenes`'s scenes, and the folders left out as half a scene, each with why.

    ``eval`` and ``bench`` dropped a folder holding ``left.png`` without ``right.png`` without
    a word (``batch`` reports such an image as unpaired): they now say so from this list.
    Hidden folders (``.git``, ``.Trash``) under ``root`` are not searched, as ``batch`` does
    not (a hidden copy of a scene was evaluated twice); ``root`` itself is searched even if
    hidden, as given. A folder of Middlebury's names (``im0.png`` + ``im1.png``, no
    ``left.png`` or ``right.png``) is left out too, saying the names a scene's files take (it
    was "no scene" without a word on the names expected), and so is a folder of ``Left.png`` or
    ``right.PNG`` (its scene was left out of a run without a word).

    Parameters
    ----------
    root : str or os.PathLike
        Directory to search.

    Returns
    -------
    scenes : list of pathlib.Path
        Sorted scene directories.
    skipped : list of (pathlib.Path, str)
        Sorted folders holding one image of a scene's two, Middlebury's names or a pair
        named in another case, and why they are no scene.

    Raises
    ------
    FileNotFoundError
        If ``root`` does not exist.
    NotADirectoryError
        If ``root`` is a file (``cones/left.png``) or another thing that is no folder.
    PermissionError
        If ``root`` cannot be listed (an :class:`OSError` of its kind for another reason).
    """
    r = as_path(root, "root")
    if r.exists() and not r.is_dir():
        # "scene root not found" of a file that is there (load_scene says this since e412c27)
        kind = "a file" if r.is_file() else "not a folder (a device or a pipe)"
        raise NotADirectoryError(
            f"{r} is {kind}, not a scene root: give the folder holding the scene folders (or "
            "one scene folder, holding left.png and right.png)"
        )
    if not r.is_dir():
        # a link whose target moved: its target named, as load_scene's words name it
        gone = f" ({_broken_link(r)})" if r.is_symlink() and not r.exists() else ""
        raise FileNotFoundError(f"scene root not found: {r}{gone}")
    from stereovision.batch import _must_list, _walk

    # one that cannot be listed (no permission) was the walk's warning that its pairs are left
    # out, then eval's "no scene under" it, as if it held none (as batch's input was)
    _must_list(r, "scene root")
    # Links followed: Path.rglob does not enter a link to a folder, so scenes linked into a
    # folder were not found. As batch's walk, a link to a folder inside the root (or holding
    # it: a loop), or to one entered already, is an alias, not entered: `latest -> run3` listed
    # run3's scenes twice and `bench` counted them twice in its mean.
    found: list[Path] = []
    skipped: list[tuple[Path, str]] = []
    for folder, dirs, files, _ in _walk(r):
        dirs[:] = [x for x in dirs if not x.startswith(".")]
        # a right.png that is a link to nothing is listed, as such a left.png is: load_scene
        # says which link is broken (the scene was left out without a word, so eval skipped it)
        right = os.path.join(folder, "right.png")
        has_left = "left.png" in files
        has_right = os.path.lexists(right) and not os.path.isdir(right)
        if has_left and has_right:
            found.append(Path(folder))
        elif has_left or has_right:
            why = (
                # a left.png that is a folder was "no left.png", as the right one was before
                "has right.png but left.png is a folder"
                if has_right and os.path.isdir(os.path.join(folder, "left.png"))
                else "has right.png but no left.png"
                if has_right
                else "has left.png but right.png is a folder"
                if os.path.isdir(right)
                else "has left.png but no right.png"
            )
            skipped.append((Path(folder), f"{why} (a scene folder holds both)"))
        elif "im0.png" in files and "im1.png" in files:
            skipped.append((Path(folder), _MIDDLEBURY_NAMES))
        elif cased := sorted(f for f in files if f.lower() in ("left.png", "right.png")):
            # a scene of Left.png + Right.png under the root was left out without a word (the
            # run's mean over one scene fewer), and a tree of them was "no scene" alone
            skipped.append((Path(folder), f"holds {', '.join(cased)}: {_LOWER_CASE_NAMES}"))
    return sorted(found), sorted(skipped)


def _no_scene_under(folder: Path, given: str, half: Sequence[tuple[Path, str]] = ()) -> str:
    """The one line of ``eval`` and ``bench`` for a folder holding no scene, naming what is
    missing from it.

    Parameters
    ----------
    folder : pathlib.Path
        The folder searched.
    given : str
        The folder as the user gave it.
    half : sequence of (pathlib.Path, str)
        :func:`scan_scenes`'s half scenes under it, with why.

    Returns
    -------
    str
        ``"FOLDER: has left.png but no right.png (a scene folder holds both)"`` when the folder
        itself is half a scene (in its entry of ``half``'s words when it has one: a right.png
        that is a folder); else ``"no scene (left.png + right.png) under FOLDER"``, with the
        left/right images found that are not PNG, and the half scenes skipped under it (they
        were not named: the line hid why a folder of them gave nothing).
    """
    pair = ("left.png", "right.png")
    # the folder's own Left.png + Right.png are said below as found in it
    half = [(f, why) for f, why in half if not (f == folder and why.endswith(_LOWER_CASE_NAMES))]
    # the folder itself half a scene: in scan_scenes' words, which tell a right.png that is a
    # folder ("has left.png but no right.png" here) or a broken link (said as a half scene
    # skipped under the folder) from a missing one
    others = sorted(
        q.name
        for q in folder.iterdir()
        if q.is_file() and q.stem.lower() in ("left", "right") and q.name not in pair
    )
    # Left.png or right.PNG is a PNG: "a scene's images are PNG" sent the user looking for
    # another format, where the names are the trouble
    cased = [n for n in others if n.lower() in pair]
    lower = _LOWER_CASE_NAMES.removeprefix("a scene's images are ")
    own = [why for f, why in half if f == folder]
    have = [n for n in pair if (folder / n).is_file()]
    if own or len(have) == 1:
        if not own:
            missing = pair[1 - pair.index(have[0])]
            own = [f"has {have[0]} but no {missing} (a scene folder holds both)"]
        hint = f"; {', '.join(cased)} found: a scene's images are {lower}" if cased else ""
        return f"{given}: {own[0]}{hint}"
    why = "a scene's images are " + (
        lower if len(cased) == len(others) else f"PNG, {lower}" if cased else "PNG"
    )
    found = f" ({', '.join(others)} found: {why})" if others else ""
    middlebury = [f for f, why in half if why == _MIDDLEBURY_NAMES]
    if middlebury:
        shown = ", ".join(str(f) for f in middlebury[:3])
        more = f" and {len(middlebury) - 3} more" if len(middlebury) > 3 else ""
        verb = "holds" if len(middlebury) == 1 else "hold"
        found += f"; {shown}{more} {verb} Middlebury's im0.png + im1.png: {_MIDDLEBURY_FIX}"
        half = [(f, why) for f, why in half if why != _MIDDLEBURY_NAMES]
    # folders of Left.png + Right.png under it: named with their names, not as half scenes
    cased_dirs = [(f, why) for f, why in half if why.endswith(_LOWER_CASE_NAMES)]
    if cased_dirs:
        shown = ", ".join(
            f"{f} {why.removesuffix(f': {_LOWER_CASE_NAMES}')}" for f, why in cased_dirs[:3]
        )
        more = f" and {len(cased_dirs) - 3} more" if len(cased_dirs) > 3 else ""
        found += f"; {shown}{more}: {_LOWER_CASE_NAMES}"
        half = [(f, why) for f, why in half if not why.endswith(_LOWER_CASE_NAMES)]
    # a few named, the rest counted: the line stays one line under a tree of them
    named = [f"{f} {why.removesuffix(' (a scene folder holds both)')}" for f, why in half[:3]]
    if len(half) > 3:
        named.append(f"{len(half) - 3} more")
    skipped = (
        f"; skipped {len(half)} half scene{'s' if len(half) > 1 else ''} (a scene folder holds "
        f"both images): {', '.join(named)}"
        if half
        else ""
    )
    return f"no scene (left.png + right.png) under {given}{found}{skipped}"
