"""Depth for every pair of a folder tree, on Dask distributed (``stereovision batch``).

Each pair found under the input (:func:`find_pairs`) becomes one Dask task that computes what
``stereovision depth`` writes for it (:func:`stereovision.cli.depth_outputs`): the task receives the
image bytes and returns the output files' bytes, so workers need neither the input nor the output
folder -- a multi-node cluster works without a shared filesystem. The client (this process) writes
each finished pair into ``OUT/<name>/`` atomically (a hidden temporary folder renamed into place;
into a folder already there, each file renamed over its own name, the rest of the folder kept)
and records it in ``OUT/summary.json`` (itself replaced atomically after every pair, or at most a
tenth of the time for a large one).

A re-run skips the pairs the summary records as done whose inputs (size, modification time; for
a time alone that differs, the content: a copy without timestamps) and options are unchanged and
whose outputs are all still in its folder (one missing some is done again), without starting a
cluster when nothing is left to do. A pair that fails (an unreadable image, sizes that differ,
...) is recorded with its error and the others go on; a re-run tries it again once its files
(or the options) change, or with ``retry_failed``. Ctrl-C (or SIGTERM, for the CLI) cancels
what is running, keeps everything already written and marks the summary as interrupted; the
LocalCluster's worker processes do not take Ctrl-C themselves (they block SIGINT): the client
stops them.
"""

from __future__ import annotations

import argparse
import contextlib
import contextvars
import datetime as _dt
import hashlib
import json
import math
import os
import re
import shutil
import signal
import socket
import stat
import sys
import tempfile
import threading
import time
import uuid
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from stereovision._interrupt import HeldInterrupts, raise_terminated

__all__ = [
    "IMAGE_EXTS",
    "SUMMARY_NAME",
    "BatchInterrupted",
    "BatchResult",
    "PairJob",
    "add_cli",
    "cmd_batch",
    "find_pairs",
    "process_pair",
    "run_batch",
]

#: File name of the run record in the output folder.
SUMMARY_NAME = "summary.json"
#: Image files considered for left/right pairs.
IMAGE_EXTS = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm", ".webp")
#: Tasks in flight per worker: enough to keep each busy while the client writes results, few
#: enough that the client does not read the whole input into memory up front.
IN_FLIGHT_PER_WORKER = 2
#: Seconds between the plain progress lines written when stderr is not a terminal (there is
#: also one every tenth of the pairs).
PROGRESS_SECONDS = 10.0
#: Seconds the check of the pairs' files against the summary (their sha256 read again for files
#: copied without their times) runs before its bar shows on a terminal: a quick one draws none.
CHECK_BAR_DELAY = 2.0
#: The summary is rewritten after a finished pair once this many times the duration of its last
#: write has passed since (after every pair for a small one; at most a tenth of the time goes to
#: rewriting a large one).
SAVE_COST_RATIO = 10.0
#: Seconds to wait for an existing scheduler.
CONNECT_TIMEOUT = "10s"
#: 2: every pair whose folder holds outputs of a run lists them (``outputs``); a version 1
#: summary's failed pairs did not when a redo failed or lost an image (before ed0f5f2).
#: 3: a pair sent to the workers records its input files' sha256 (``hashes``), so that a
#: copy of them without their times is known as the same; pairs of older summaries have none
#: until they are done again (a time that differs is then a change, as before).
_SUMMARY_VERSION = 3
#: Output names added after summary version 1 (4715e5e): no version 1 batch wrote them, so a
#: file under one in a version 1 pair's folder is the user's.
_NAMES_SINCE_V2 = ("overview.png",)
_LEFT_RE = re.compile(r"left", re.IGNORECASE)
_RIGHT_RE = re.compile(r"right", re.IGNORECASE)
_SCENE_CALIBS = ("calib.txt", "Q.dat")
#: depth_map's method when none is given, recorded by its name in the summary's options.
_DEFAULT_METHOD = "fused"
#: Sibling folders holding a rig's two cameras, left one first (matched without case): images
#: of the same path under both are a pair (``left/0001.png`` + ``right/0001.png``; KITTI's
#: ``image_2``/``image_3`` colour and ``image_0``/``image_1`` grey, its raw drives'
#: ``image_02/data``/``image_03/data`` and ``image_00/data``/``image_01/data``; EuRoC's
#: ``cam0/data`` + ``cam1/data``; TartanAir's ``image_left/000000_left.png`` +
#: ``image_right/000000_right.png``).
CAMERA_FOLDERS = (
    ("left", "right"),
    ("l", "r"),
    ("image_2", "image_3"),
    ("image_0", "image_1"),
    # KITTI's raw drives (2011_09_26_drive_0001_sync/image_02/data/0000000000.png), whose
    # calib_cam_to_cam.txt --calib reads: a drive was "no pair under ..."
    ("image_02", "image_03"),
    ("image_00", "image_01"),
    ("cam0", "cam1"),
    # TartanAir's trajectories (P000/image_left/000000_left.png + image_right/000000_right.png,
    # paired by number): each image was "unpaired" (no 000000_right.png beside it)
    ("image_left", "image_right"),
)
#: Camera folders named for their side, whose images are reported as half pairs when the
#: other side's folder is not there (the other :data:`CAMERA_FOLDERS` alone may be a mono
#: recording's: EuRoC's cam0/, KITTI's image_2/ of its object benchmark).
_SIDED_FOLDERS = ("left", "right", "image_left", "image_right")
_GONE = "its outputs were gone at the end of the run (the output folder moved or deleted?)"


@dataclass(frozen=True)
class PairJob:
    """One pair to process.

    Attributes
    ----------
    name : str
        Output sub-folder (POSIX path relative to the output folder).
    left, right : pathlib.Path
        The images.
    calib : pathlib.Path or None
        Calibration file of the pair.
    """

    name: str
    left: Path
    right: Path
    calib: Path | None = None


def _last(regex: re.Pattern[str], stem: str) -> re.Match[str] | None:
    found = list(regex.finditer(stem))
    return found[-1] if found else None


def _last_left(stem: str) -> re.Match[str] | None:
    return _last(_LEFT_RE, stem)


def _swap(path: Path, m: re.Match[str], to: str) -> Path:
    """``path`` with the word ``m`` (``left`` or ``right``) replaced by ``to``, its case kept."""
    word = m.group(0)
    new = to.upper() if word.isupper() else to.title() if word[0].isupper() else to
    return path.with_name(path.stem[: m.start()] + new + path.stem[m.end() :] + path.suffix)


def _by_suffix_case(names: set[str]) -> dict[str, list[str]]:
    """``names`` by their spelling with the extension in lower case (``left.png`` for
    ``left.PNG``), for :func:`_other_image`."""
    spelt: dict[str, list[str]] = {}
    for f in sorted(names):
        p = Path(f)
        spelt.setdefault(p.stem + p.suffix.lower(), []).append(f)
    return spelt


def _other_image(path: Path, names: set[str], spelt: dict[str, list[str]], own: str) -> Path:
    """The other image of the pair of the image named ``own``, ``path`` (:func:`_swap`'s), as
    spelt among ``names``: of the same stem, its extension in any case (``right.png`` beside
    ``left.PNG``, a camera's and a tool's spellings); ``path`` itself when it is there, or when
    none or two are, or ``own`` has another spelling too (``left.PNG`` beside ``left.png``,
    whose ``right.png`` it is: not guessed)."""
    if path.name in names:
        return path
    mine = Path(own)
    if len(spelt.get(mine.stem + mine.suffix.lower(), [])) != 1:
        return path
    found = spelt.get(path.stem + path.suffix.lower(), [])
    return path.with_name(found[0]) if len(found) == 1 else path


@dataclass(frozen=True)
class _Unpaired:
    """An image named as one of a pair whose other image is not there."""

    name: str
    present: Path
    missing: Path
    side: str  # of ``present``: "left" or "right"

    @property
    def error(self) -> str:
        from stereovision._validate import escaped

        # a newline in a file's name cut the summary's one line there
        return f"unpaired image: {escaped(self.what)}"

    @property
    def what(self) -> str:
        """``no x_right.png beside .../x_left.png``; ``no .../right/0001.png for
        .../left/0001.png`` when the other image goes in a sibling camera folder."""
        if self.missing.parent != self.present.parent:
            return f"no {self.missing} for {self.present}"
        return f"no {self.missing.name} beside {self.present}"


def _stem_without(stem: str, m: re.Match[str]) -> str:
    """``0001`` for ``left_0001``: ``stem`` without the word ``m`` and the separators around it
    (empty for ``left``)."""
    before, after = stem[: m.start()].rstrip("_-. "), stem[m.end() :].lstrip("_-. ")
    return "_".join(x for x in (before, after) if x)


def _is_right(stem: str) -> bool:
    """``right`` (in any case) alone, the stem of a scene's right image."""
    m = _last(_RIGHT_RE, stem)
    return m is not None and not _stem_without(stem, m)


def _scene_calib(folder: Path, names: set[str]) -> Path | None:
    """The calibration of a scene ``folder`` holding the files ``names``, as
    :func:`~stereovision.io.load_scene` reads it: its ``calib.txt``, else its ``Q.dat`` when
    the image that sizes it is there (:func:`~stereovision.calibration._sizing_images`)."""
    from stereovision.calibration import _sizing_images

    if "calib.txt" in names:
        return folder / "calib.txt"
    if "Q.dat" in names and _sizing_images(folder / "Q.dat"):
        return folder / "Q.dat"
    return None


def _pair_name(p: Path, m: re.Match[str], rel: str, root: Path) -> str:
    """``seq/0001`` for ``seq/left_0001.png``: the folder and the stem without the word ``m``
    (and separators around it); the folder alone for ``left.jpg``, like a scene."""
    short = _stem_without(p.stem, m)
    if not short:
        return rel if rel != "." else root.resolve().name
    return short if rel == "." else f"{rel}/{short}"


def find_pairs(
    root: str | os.PathLike[str], calib: str | os.PathLike[str] | None = None
) -> list[PairJob]:
    """Every pair under ``root``: scene folders, ``...left...`` / ``...right...`` image files and
    the same file names in sibling camera folders.

    * A folder holding ``left.png`` and ``right.png`` (evaluation.md's scene layout), or else
      Middlebury's ``im0.png`` and ``im1.png`` (a Middlebury 2014 or ETH3D scene as shipped), is
      one pair, named by its path relative to ``root`` (``root``'s own name when ``root`` is the
      scene); its ``calib.txt`` is used when present, else its ``Q.dat``. So is one holding
      ``left`` + ``right`` of another suffix or case (``left.jpg`` + ``right.jpg``, ``LEFT.PNG``
      + ``RIGHT.PNG``), its ``Q.dat`` when a ``left.png`` or ``left.jpg`` sizes it. An
      ``im0.png`` without its ``im1.png`` (or the other way round) is not a pair (reported
      as below).
    * Any other image whose name contains ``left`` (``left_0001.png`` as ``stereovision capture``
      saves them, ``cam_left.jpg``, ``0001_Left.png``) pairs with the file named with ``right``
      in its place (its extension in any case: ``left.PNG`` + ``right.png``); the pair is
      named by its folder and the file name without ``left`` (and separators around it), e.g.
      ``seq/0001``. Files without a counterpart are not pairs
      (:func:`run_batch` reports them as failed pairs).
    * Two sibling camera folders (:data:`CAMERA_FOLDERS`: ``left/`` + ``right/``, ``L/`` +
      ``R/``, KITTI's ``image_2/`` + ``image_3/`` and ``image_0/`` + ``image_1/`` (a raw
      drive's ``image_02/`` + ``image_03/`` and ``image_00/`` + ``image_01/``), EuRoC's
      ``cam0/`` + ``cam1/``, TartanAir's ``image_left/`` + ``image_right/``): the images of
      the same path under both (any depth) are a pair, named by the parent folder and that
      path without the extension (``seq/0001`` for ``seq/left/0001.png``,
      ``mav0/data/1403...`` for ``mav0/cam0/data/1403....png``); when one folder holds
      several such rigs, the name keeps the left camera's folder (``00/image_2/000000``);
      TartanAir's ``P000/image_left/000000_left.png`` is ``P000/000000``. Images with
      ``left`` or ``right`` in their names are paired by name as above; the images left over
      (and those named so without the other beside them) by the number in their names, in the
      same sub-folder, the names otherwise the same but for ``left`` / ``right`` and a number
      after the frame's glued to a word, which a camera's names share (its index;
      ``seq/left/left_0001.png`` + ``seq/right/right_0001.png`` -> ``seq/0001``,
      ``pair01_cam0.png`` + ``pair01_cam1.png``; not ``000000_10.png`` + ``000000_11.png``); an
      image without the other is not a pair (reported as above). Only ``calib`` applies to
      these pairs (no ``calib.txt`` is looked for; the package holds no dataset's own
      calibration: give TartanAir's, fx = fy = 320 px, baseline 0.25 m, as ``calib``).

    Folders linked into ``root`` from elsewhere are searched too, each once, their pairs named
    by the link; a link to a folder under ``root`` (an alias) or holding it (a loop) is not.

    Parameters
    ----------
    root : path
        Folder to search (any depth).
    calib : path, optional
        Calibration for every pair (overrides the scenes' ``calib.txt``).

    Returns
    -------
    list of PairJob
        Sorted by name; names are unique (a numeric suffix resolves clashes).

    Raises
    ------
    FileNotFoundError
        If ``root`` (or ``calib``) does not exist.
    NotADirectoryError
        If ``root`` is not a folder.
    PermissionError
        If ``root`` cannot be listed (an :class:`OSError` of its kind for another reason).

    Warns
    -----
    UserWarning
        For a folder under ``root`` that cannot be listed (no permission), named: its pairs,
        if any, are left out.
    """
    return _scan(root, calib)[0]


def _scan(
    root: str | os.PathLike[str],
    calib: str | os.PathLike[str] | None = None,
    calib_unit: str | None = None,
    output: str | os.PathLike[str] | None = None,
    words: str = "api",
) -> tuple[list[PairJob], list[_Unpaired], tuple[int, int] | None]:
    """:func:`_search`, each folder that cannot be listed warned of once (:func:`_not_listed`)."""
    token = _TOLD_UNLISTED.set(set())
    try:
        return _search(root, calib, calib_unit, output, words)
    finally:
        _TOLD_UNLISTED.reset(token)


def _search(
    root: str | os.PathLike[str],
    calib: str | os.PathLike[str] | None = None,
    calib_unit: str | None = None,
    output: str | os.PathLike[str] | None = None,
    words: str = "api",
) -> tuple[list[PairJob], list[_Unpaired], tuple[int, int] | None]:
    """:func:`find_pairs`, and the images named as one of a pair without the other: a ``left``
    image without its ``right`` one, a ``right`` image (no ``left`` in its name) without its
    ``left`` one; named as their pair would be, after the pairs' names. Also the image size
    ``calib`` is read at when it holds none (:func:`_calib_size`), else None. ``output``, the
    run's output folder, is not searched when it lies below ``root``: ``batch seq -o
    seq/left/out`` paired its own disparity.png files on the next run (each a failed pair)."""
    from stereovision._validate import as_path

    r = as_path(root, "root")
    if not r.exists():
        from stereovision.capture import mask_url_secrets
        from stereovision.io import _broken_link

        # a URL given (Path made rtsp:// rtsp:/): its password is not said
        given = os.fspath(root)
        # a link whose target moved (a dataset linked in from a disk since unmounted) was "not
        # found" alone, of a name ls lists: its target is named, as io's readers name it
        gone = f" ({_broken_link(r)})" if r.is_symlink() else ""
        raise FileNotFoundError(
            f"input folder not found: {mask_url_secrets(given) if '://' in given else r}{gone}"
        )
    if not r.is_dir():
        raise NotADirectoryError(f"input is not a folder: {r}")
    # one that cannot be listed (no permission) was os.walk's warning, then "no pair under" it
    # naming the layouts, as if it held none of them
    _must_list(r, "input folder")
    cal = as_path(calib, "calib") if calib is not None else None
    if calib is not None and cal is not None and not cal.exists():
        # a link whose target moved, a ~ left as typed: said, as depth --calib says them
        from stereovision.io import _missing_hint

        raise FileNotFoundError(f"calibration file not found: {cal}{_missing_hint(calib, cal)}")
    found: list[PairJob] = []
    unpaired: list[_Unpaired] = []
    cam_found: list[PairJob] = []  # in sibling camera folders
    cam_unpaired: list[_Unpaired] = []
    cam_taken: set[Path] = set()  # named images paired (or reported) across camera folders
    cam_images: set[Path] = set()  # every image of a camera folder's pair or half pair
    lone_unpaired: list[_Unpaired] = []  # the images of a left/ without its right/ (or so)
    skip = _output_below(r, output)
    for d, _dirs, files, listed in _walk(r, skip):
        dirs = sorted(_dirs)
        _dirs[:] = [x for x in dirs if not x.startswith(".")]
        here = Path(d)
        rel = here.relative_to(r).as_posix()
        names = set(files)
        paired: set[str] = set()
        # Middlebury 2014's and ETH3D's im0.png + im1.png (as their archives ship a scene, its
        # calib.txt beside them) too: such a folder was passed over without a word
        for lname, rname in (("left.png", "right.png"), ("im0.png", "im1.png")):
            if lname not in names or rname not in names:
                continue
            # as load_scene: calib.txt, else OpenCV's Q (sized by the scene's left image)
            scene_cal = next((here / n for n in _SCENE_CALIBS if n in names), None)
            found.append(
                PairJob(
                    rel if rel != "." else r.resolve().name,
                    here / lname,
                    here / rname,
                    cal if cal is not None else scene_cal,
                )
            )
            paired |= {lname, rname}
            break
        else:
            # an im0.png without its im1.png (or the other way round) is a half scene, as a
            # left.png alone is: it was left out without a word
            halves = (("im0.png", "im1.png", "left"), ("im1.png", "im0.png", "right"))
            for present, missing, side in halves:
                if present in names and missing not in names and here / present not in cam_images:
                    name = rel if rel != "." else r.resolve().name
                    unpaired.append(_Unpaired(name, here / present, here / missing, side))
        images = [f for f in sorted(files) if Path(f).suffix.lower() in IMAGE_EXTS and f[0] != "."]
        # left.PNG + right.png were two half pairs, "no right.PNG beside left.PNG" and back
        by_case = _by_suffix_case(names)
        for f in images:
            p = here / f
            m = _last_left(p.stem)
            if m is None or f in paired or p in cam_taken:
                continue
            rp = _other_image(_swap(p, m, "right"), names, by_case, f)
            if rp.name not in names:
                unpaired.append(_Unpaired(_pair_name(p, m, rel, r), p, rp, "left"))
                continue
            named_cal = None
            if cal is None and not _stem_without(p.stem, m) and _is_right(rp.stem):
                # left.jpg + right.jpg (or LEFT.PNG ...) is a scene too: its calib.txt was
                # passed over and no depth came out, unsaid. Its Q.dat is read when the image
                # that sizes it (left.png, left.jpg) is there.
                named_cal = _scene_calib(here, names)
            found.append(PairJob(_pair_name(p, m, rel, r), p, rp, named_cal or cal))
            paired |= {f, rp.name}
        for f in images:
            p = here / f
            m = _last(_RIGHT_RE, p.stem)
            if m is None or f in paired or p in cam_taken or _last_left(p.stem) is not None:
                continue
            lp = _other_image(_swap(p, m, "left"), names, by_case, f)
            if lp.name not in names:
                unpaired.append(_Unpaired(_pair_name(p, m, rel, r), p, lp, "right"))
        # links not entered included: camera folders named by links to the input's own
        cams = _camera_folders(sorted(x for x in listed if not x.startswith(".")))
        for left_dir, right_dir in cams:
            # several rigs in one folder (KITTI's grey image_0/1 and colour image_2/3): each
            # pair's name keeps its left camera's folder, so that they do not take each other's
            prefix = "/".join(
                x for x in (rel, left_dir if len(cams) > 1 else "") if x not in ("", ".")
            )
            pairs, alone, by_number = _sibling_pairs(
                here / left_dir, here / right_dir, prefix, cal, skip
            )
            cam_found += pairs
            cam_unpaired += alone
            cam_taken |= by_number
            cam_images |= {x for j in pairs for x in (j.left, j.right)}
            cam_images |= {u.present for u in alone}
        # a folder named for its camera's side (left/, image_left/) without its sibling at all
        # (a copy cut short): its images were left out without a word, where a right/ folder
        # short of some of them has each reported. Not cam0/, L/, image_2/ alone: a mono
        # recording, KITTI's left images alone (its object benchmark), are no half pairs
        spelt = {x.lower(): x for x in listed if not x.startswith(".")}
        for lone in (x for x in _SIDED_FOLDERS if x in spelt):
            cam = spelt[lone]
            m = _last_left(cam) or _last(_RIGHT_RE, cam)
            assert m is not None
            side = "left" if m.group(0).lower() == "left" else "right"
            other = _swap(Path(cam), m, "right" if side == "left" else "left").name
            if other.lower() in spelt or sum(x.lower() == lone for x in listed) > 1:
                continue  # paired above (or two spellings, not guessed)
            for f in sorted(_camera_images(here / cam, skip)):
                short = f.rsplit(".", 1)[0]
                name = "/".join(x for x in (rel, short) if x not in ("", "."))
                lone_unpaired.append(_Unpaired(name, here / cam / f, here / other / f, side))
                # as a rig's: its im0.png alone was also "no im1.png beside" it, two for one
                cam_images.add(here / cam / f)
    # after the other layouts' pairs, so that those keep their names in a clash (the sort is
    # stable): camera folders' images were not pairs before
    found += cam_found
    # an image of a lone left/ that is a pair of its own (left/im0.png + im1.png) is no half
    in_pairs = {x for j in found for x in (j.left, j.right)}
    cam_unpaired += [u for u in lone_unpaired if u.present not in in_pairs]
    found.sort(key=lambda j: j.name)
    # a clash takes the next suffix no pair has: x~2 beside a folder x~2 of its own made two
    # pairs x~2, one output folder and one summary entry
    own = {j.name for j in found}
    unique: list[PairJob] = []
    used: set[str] = set()
    for j in found:
        name, n = j.name, 1
        while name in used or (n > 1 and name in own):
            n += 1
            name = f"{j.name}~{n}"
        used.add(name)
        unique.append(j if n == 1 else PairJob(name, j.left, j.right, j.calib))
    unique.sort(key=lambda j: j.name)
    if output is not None:
        # -o given as the input (or above it): a pair's output folder inside a camera folder
        # (KITTI's 00/image_0/000000/, a sequence of two rigs) held its disparity.png and
        # overview.png, each reported on the next run as an image without its pair (exit 1)
        from stereovision.cli import DEPTH_OUTPUTS

        outs = {os.path.realpath(Path(output) / j.name) for j in unique}
        mine = [u for u in unpaired + cam_unpaired if u.present.name in DEPTH_OUTPUTS]
        ours = {id(u) for u in mine if os.path.realpath(u.present.parent) in outs}
        unpaired = [u for u in unpaired if id(u) not in ours]
        cam_unpaired = [u for u in cam_unpaired if id(u) not in ours]
    # the pairs keep the names they had before these were reported; these take the next ones
    taken = {j.name for j in unique}
    named: list[_Unpaired] = []
    in_order = sorted(unpaired, key=lambda u: (u.name, u.present.name))
    for u in in_order + sorted(cam_unpaired, key=lambda u: (u.name, u.present.name)):
        name, n = u.name, 1
        while name in taken:
            n += 1
            name = f"{u.name}~{n}"
        taken.add(name)
        named.append(_Unpaired(name, u.present, u.missing, u.side))
    size = _calib_size(cal, unique)
    if cal is not None and (size is not None or not _sizeless(cal)):
        # One calibration for every pair: read it once here, so that a bad file is one error
        # now, not one failed pair per scene. (One that holds no size, without a pair whose
        # left image decodes to size it, is each pair's error.) In the command line's words
        # for it: cmd_batch searched the input a first time to size it so
        if words == "cli":
            _cli_calibration(cal, calib_unit, size)
        else:
            from stereovision.calibration import Calibration

            Calibration.from_file(cal, image_size=size, unit=calib_unit)
    return unique, named, size


def _sizeless(cal: Path) -> bool:
    from stereovision.calibration import _sizeless as sizeless

    return sizeless(cal)


def _calib_size(cal: Path | None, jobs: list[PairJob]) -> tuple[int, int] | None:
    """The image size to read ``cal`` at when the file holds none (OpenCV ``stereo_calib``
    output, a ``Q.dat`` alone, a KITTI file without ``S_rect_02``): the size of the first
    pair's left image (the first one that can be read and decoded); None for a calibration
    that holds its size, or when no left image can be read."""
    if cal is None or not _sizeless(cal):
        return None
    for job in jobs:
        if not job.left.is_file():  # a FIFO's read waits for a writer: the run hung
            continue
        with contextlib.suppress(OSError, ValueError):
            img = _decode(str(job.left), job.left.read_bytes())
            return int(img.shape[1]), int(img.shape[0])
    return None


def _recorded_calib_size(pairs: dict[str, Any], calib: Path) -> tuple[int, int] | None:
    """The ``calib_size`` an earlier run recorded for ``calib`` (a calibration that holds no
    image size), else None.

    Parameters
    ----------
    pairs : dict
        The summary's pair records.
    calib : Path
        The calibration given to this run.

    Returns
    -------
    tuple of int or None
        The ``(width, height)`` most pairs done with the same calibration (the same path,
        its files' sizes and times unchanged) were done at; None when no pair was done with it
        (a size under which every pair failed is not kept).
    """
    try:
        now = {k: [p.stat().st_size, p.stat().st_mtime_ns] for k, p in _calib_inputs(calib).items()}
    except OSError:
        return None
    counts: dict[tuple[int, int], int] = {}
    for entry in pairs.values():
        if not isinstance(entry, dict) or entry.get("status") != "done":
            continue
        size = (entry.get("options") or {}).get("calib_size")
        fp = entry.get("fingerprint") or {}
        if (
            entry.get("calib") != _recorded(calib)
            or not isinstance(size, list)
            or len(size) != 2
            or not all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in size)
            or {k: v for k, v in fp.items() if k.startswith("calib")} != now
        ):
            continue
        key = (size[0], size[1])
        counts[key] = counts.get(key, 0) + 1
    return max(counts, key=lambda k: counts[k]) if counts else None


def _output_below(root: Path, output: str | os.PathLike[str] | None) -> frozenset[str]:
    """The real path of ``output`` when it lies strictly below ``root`` (a folder
    :func:`_walk` is not to enter), else nothing."""
    if output is None:
        return frozenset()
    top, out = os.path.realpath(root), os.path.realpath(output)
    try:
        below = out != top and os.path.commonpath([out, top]) == top
    except ValueError:  # another drive (Windows)
        below = False
    return frozenset({out}) if below else frozenset()


#: The warnings :func:`_not_listed` gave in one search of the input (:func:`_scan`), set for
#: its length: a camera folder is walked three times (its images, its named ones, the input's
#: walk), a folder in it that cannot be listed warned of three times.
_TOLD_UNLISTED: contextvars.ContextVar[set[str] | None] = contextvars.ContextVar(
    "stereovision_told_unlisted", default=None
)


def _not_listed(err: OSError) -> None:
    """Warn of a folder :func:`_walk` cannot list: os.walk passed over it (no permission, an
    I/O error) without a word, its pairs left out of a run that said nothing was missing.
    Once per search (:data:`_TOLD_UNLISTED`), at the caller's line outside the package: from
    os.walk's ``onerror`` it was ``<frozen os>``'s."""
    from stereovision._validate import escaped, user_stacklevel

    message = (
        f"cannot search folder {escaped(str(err.filename))}: {err.strerror or err}; the pairs "
        "in it, if any, are left out"
    )
    told = _TOLD_UNLISTED.get()
    if told is not None:
        if message in told:
            return
        told.add(message)
    warnings.warn(message, stacklevel=user_stacklevel())


def _must_list(folder: Path, what: str) -> None:
    """Raise the listing error of a top folder ``_walk`` would only warn of, naming it
    (``PermissionError`` for no permission, another :class:`OSError` of its kind else)."""
    try:
        with os.scandir(folder):
            pass
    except OSError as e:
        raise type(e)(f"cannot search {what} {folder}: {e.strerror or e}") from None


def _walk(
    top: Path, skip: frozenset[str] = frozenset()
) -> Iterator[tuple[str, list[str], list[str], list[str]]]:
    """:func:`os.walk` (top-down) that also enters links to folders outside ``top``, each once;
    also yields each folder's sub-folders as listed, links not entered included.

    A drive's scene folders linked into the input (``in/tsukuba -> /data/tsukuba``) were not
    entered and their pairs left out without a word. A link to a folder inside ``top``, or to
    one holding it, or to one entered already, is an alias (or a loop): not entered (camera
    folders named by such links, ``seq/left -> ../raw/cam_l``, are still paired: their
    search is their own). Hidden folders (``.git``, ``.Trash``) are not entered: a hidden
    link sorted first claimed the folder a visible link also named, and the caller's skip of
    hidden folders then dropped the folder's scenes (``.cache -> /d/s`` beside ``s -> /d/s``).
    Folders whose real path is in ``skip`` (the output folder) are not entered either. A
    folder that cannot be listed is warned of (:func:`_not_listed`)."""
    top_real = os.path.realpath(top)
    seen = {top_real}
    # warned of here, not in os.walk's onerror: a frame of os's between the caller and the
    # warning stopped user_stacklevel there
    unlisted: list[OSError] = []
    for d, dirs, files in os.walk(top, followlinks=True, onerror=unlisted.append):
        while unlisted:
            _not_listed(unlisted.pop(0))
        listed = list(dirs)
        keep = []
        # in name order, so that of two links to one folder the same one names its pairs on
        # every filesystem (the listing's order took the other one: ``in/b`` for ``in/a``)
        for x in sorted(dirs):
            if x.startswith("."):
                continue
            p = os.path.join(d, x)
            if skip and os.path.realpath(p) in skip:
                continue
            if os.path.islink(p):
                real = os.path.realpath(p)
                try:
                    inside = os.path.commonpath([real, top_real]) in (real, top_real)
                except ValueError:  # another drive (Windows)
                    inside = False
                if inside or real in seen:
                    continue
                seen.add(real)
            keep.append(x)
        dirs[:] = keep
        yield d, dirs, files, listed
    while unlisted:  # the last folders os.walk tried
        _not_listed(unlisted.pop(0))


def _camera_folders(dirs: list[str]) -> list[tuple[str, str]]:
    """The pairs of :data:`CAMERA_FOLDERS` among the (non-hidden) sub-folders ``dirs``, as
    spelt there; a folder name matching two spellings (``left`` and ``Left``) is not guessed."""
    by_lower: dict[str, list[str]] = {}
    for d in dirs:
        by_lower.setdefault(d.lower(), []).append(d)
    cams = []
    for a, b in CAMERA_FOLDERS:
        la, lb = by_lower.get(a, []), by_lower.get(b, [])
        if len(la) == 1 and len(lb) == 1:
            cams.append((la[0], lb[0]))
    return cams


def _named_image(f: str) -> bool:
    """An image :func:`find_pairs` pairs by its name (``left`` or ``right`` in it)."""
    stem = Path(f).stem
    return _last_left(stem) is not None or _last(_RIGHT_RE, stem) is not None


def _camera_images(folder: Path, skip: frozenset[str] = frozenset()) -> set[str]:
    """The images under ``folder`` (any depth, hidden ones and ``skip``'s excepted) not paired
    by their name, as POSIX paths relative to it."""
    images: set[str] = set()
    for d, dirs, files, _ in _walk(folder, skip):
        dirs[:] = [x for x in dirs if not x.startswith(".")]
        sub = Path(d).relative_to(folder)
        for f in files:
            if Path(f).suffix.lower() in IMAGE_EXTS and f[0] != "." and not _named_image(f):
                images.add((sub / f).as_posix())
    return images


def _sibling_pairs(
    left_dir: Path,
    right_dir: Path,
    prefix: str,
    cal: Path | None,
    skip: frozenset[str] = frozenset(),
) -> tuple[list[PairJob], list[_Unpaired], set[Path]]:
    """The pairs of two sibling camera folders: the images of the same path under both (those
    with ``left`` or ``right`` in their names are paired by name, as everywhere); then those
    left, and the images named as one of a pair without the other beside them, by the number
    in their names (``left/left_0001.png`` + ``right/right_0001.png``). Each is named
    ``prefix`` + its left image's path under the camera folder without the extension (and
    without ``left``: ``seq/data/0001`` for ``seq/cam0/data/0001.png``, ``seq/0001`` for
    ``seq/left/left_0001.png``); an image without the other is an :class:`_Unpaired` (a named
    one too when its other is not in the other folder). Also returns the named images paired
    or reported here (the folder's own walk does not report them).
    Folders in ``skip`` (the output folder) are not searched."""
    lefts, rights = _camera_images(left_dir, skip), _camera_images(right_dir, skip)
    lone_lefts = _lone_named_images(left_dir, skip)
    lone_rights = _lone_named_images(right_dir, skip)

    def name(sub: str) -> str:
        short = sub.rsplit(".", 1)[0]
        return f"{prefix}/{short}" if prefix else short

    pairs = [PairJob(name(f), left_dir / f, right_dir / f, cal) for f in sorted(lefts & rights)]
    # the others, by the number in their names (left/left_0001.png + right/right_0001.png)
    by_number = _by_number((lefts - rights) | lone_lefts, (rights - lefts) | lone_rights)
    for a, b in by_number:
        pairs.append(PairJob(name(_without_side(a)), left_dir / a, right_dir / b, cal))
    taken = {a for a, _ in by_number} | {b for _, b in by_number}
    alone = [
        _Unpaired(name(f), left_dir / f, right_dir / f, "left")
        for f in lefts - rights
        if f not in taken
    ]
    alone += [
        _Unpaired(name(f), right_dir / f, left_dir / f, "right")
        for f in rights - lefts
        if f not in taken
    ]
    # a named image whose other is not in the other camera's folder either (TartanAir's
    # image_left/000002_left.png, its right frame dropped) was reported by its folder's own
    # walk as "no 000002_right.png beside .../image_left/000002_left.png", named
    # P000/image_left/000002: the other folder's file is the one missing, the pair P000/000002
    told: set[Path] = set()
    for own, other, lone, side in (
        (left_dir, right_dir, lone_lefts - taken, "left"),
        (right_dir, left_dir, lone_rights - taken, "right"),
    ):
        for f in sorted(lone):
            m = _last_left(Path(f).stem) if side == "left" else _last(_RIGHT_RE, Path(f).stem)
            if m is None or (side == "right" and _last_left(Path(f).stem) is not None):
                continue  # a right image in the left camera's folder: its walk says it
            partner = _swap(Path(f), m, "right" if side == "left" else "left")
            if (other / partner).exists():
                continue  # there, not paired (a number two images carry): not guessed
            left_name = f if side == "left" else partner.as_posix()
            alone.append(_Unpaired(name(_without_side(left_name)), own / f, other / partner, side))
            told.add(own / f)
    # an image whose other's folder cannot be listed (no permission) was "no right/sub/0002.png
    # for ...", a file that may be there: its pair is left out, as _walk's warning says. A
    # folder above it counts too: an execute-only right/ lets right/sub/ be listed, but the
    # walk never reached it
    listable: dict[Path, bool] = {}

    def unreached(u: _Unpaired) -> bool:
        top = right_dir if u.side == "left" else left_dir
        for d in (u.missing.parent, *u.missing.parent.parents):
            if d not in listable:
                listable[d] = _listable(d)
            if not listable[d]:
                return True
            if d == top:
                break
        return False

    alone = [u for u in alone if not unreached(u)]
    return (
        pairs,
        alone,
        {left_dir / a for a, _ in by_number} | {right_dir / b for _, b in by_number} | told,
    )


def _listable(folder: Path) -> bool:
    """False for a folder that is there but cannot be listed (no permission, an I/O error);
    True for one that can, or that is not there at all."""
    try:
        with os.scandir(folder):
            return True
    except (FileNotFoundError, NotADirectoryError):
        return True
    except OSError:
        return False


def _lone_named_images(folder: Path, skip: frozenset[str] = frozenset()) -> set[str]:
    """The images under ``folder`` (any depth, hidden ones and ``skip``'s excepted) named as
    one of a pair (``left`` or ``right`` in the name) without the other beside them, as POSIX
    paths relative to it."""
    lone: set[str] = set()
    for d, dirs, files, _ in _walk(folder, skip):
        dirs[:] = [x for x in dirs if not x.startswith(".")]
        sub, names = Path(d).relative_to(folder), set(files)
        spelt = _by_suffix_case(names)
        for f in files:
            if Path(f).suffix.lower() not in IMAGE_EXTS or f[0] == ".":
                continue
            m = _last_left(Path(f).stem)
            other = None if m is None else _swap(Path(f), m, "right")
            if other is None:
                m = _last(_RIGHT_RE, Path(f).stem)
                other = None if m is None else _swap(Path(f), m, "left")
            if other is not None and _other_image(other, names, spelt, f).name not in names:
                lone.add((sub / f).as_posix())
    return lone


def _by_number(lefts: set[str], rights: set[str]) -> list[tuple[str, str]]:
    """Images of two camera folders paired by the number in their names (the frame number,
    read as ``calibrate`` reads it: the last number that differs between the names of one side
    in one sub-folder, :func:`stereovision.calibrate._number_place`, or of the other side when
    this one holds one image there), in the same sub-folder,
    whose names are otherwise the same but for ``left`` / ``right``, separators and the numbers
    after the pair's glued to a word, which all of a side's names there share (the camera's
    index: ``left_0001.png`` + ``right_1.png``, ``pair01_cam0.png`` + ``pair01_cam1.png``; not
    ``000000_11.png`` + ``000001_11.png`` nor ``000000_10.png`` + ``000000_11.png``, other
    frames of a KITTI pair); the images left then by each name's last
    number alone, as before; a number two images of one side carry is not paired (which is
    meant is not guessed)."""
    from stereovision.calibrate import _number_place

    def rest(f: str, drop: list[tuple[int, int]]) -> str:
        stem = Path(f).stem
        # the pair's number (first) is not compared, nor one after it glued to a word (the
        # camera's index in pair01_cam0); one on its own (KITTI's frame in 000000_10, a year)
        # is, else 000000_10 paired with 000000_11
        for i, (a, b) in sorted(enumerate(drop), key=lambda x: -x[1][0]):
            word = i > 0 and a > 0 and stem[a - 1].isalpha()
            stem = stem[:a] + ("\0" if i == 0 or word else f"\0{int(stem[a:b])}") + stem[b:]
        m = _last_left(stem) or _last(_RIGHT_RE, stem)
        if m is not None:
            stem = stem[: m.start()] + stem[m.end() :]
        return re.sub(r"[-_. \0]", "", stem)

    def by_folder(files: set[str]) -> dict[str, list[tuple[str, list[re.Match[str]]]]]:
        out: dict[str, list[tuple[str, list[re.Match[str]]]]] = {}
        for f in sorted(files):
            out.setdefault(Path(f).parent.as_posix(), []).append(
                (f, list(re.finditer(r"\d+", Path(f).stem)))
            )
        return out

    def places(files: set[str]) -> dict[str, int]:
        """Each sub-folder's pair-number place where two or more names carry numbers (-1,
        the last, when their counts differ)."""
        told = {}
        for folder, names in by_folder(files).items():
            known = [[m.group(0) for m in r] for _, r in names if r]
            if len(known) >= 2:
                told[folder] = _number_place(known)
        return told

    def index(files: set[str], at_of: dict[str, int]) -> dict[tuple[str, str, int], str]:
        found: dict[tuple[str, str, int], list[str]] = {}
        for folder, names in by_folder(files).items():
            for f, r in names:
                at = at_of.get(folder, -1)
                if r and len(r) < -at:  # fewer numbers than the other side's place needs
                    at = -1
                if r:
                    # the numbers after the pair's, which all of the side's names share (the
                    # camera's index in pair01_cam0.png, a year), told the two sides apart;
                    # those before it are compared (KITTI's 000000_10 is not 000001_10)
                    drop = [m.span() for m in r[len(r) + at :]]
                    key = (folder, rest(f, drop), int(r[at].group(0)))
                    found.setdefault(key, []).append(f)
        return {key: v[0] for key, v in found.items() if len(v) == 1}

    # a side whose names there tell no place (one image: a camera folder with gaps) is read at
    # the other side's (pair01_cam0.png alone + pair01_cam1.png, pair02_cam1.png)
    pl, pr = places(lefts), places(rights)
    il, ir = index(lefts, pr | pl), index(rights, pl | pr)
    pairs = [(il[k], ir[k]) for k in il.keys() & ir.keys()]
    # then each name on its own, by its last number (a side of one image, or names carrying
    # different counts of numbers, tells no place apart: seq_5_left_0001 + seq_5_right_0001)
    taken = {f for p in pairs for f in p}
    il, ir = index(lefts, {}), index(rights, {})
    pairs += [
        (il[k], ir[k]) for k in il.keys() & ir.keys() if il[k] not in taken and ir[k] not in taken
    ]
    return sorted(pairs)


def _without_side(sub: str) -> str:
    """``seq/0001.png`` for ``seq/left_0001.png``: a pair's name does not say ``left``."""
    p = Path(sub)
    m = _last_left(p.stem)
    if m is None:
        return sub
    short = _stem_without(p.stem, m) or p.stem
    return (p.parent / (short + p.suffix)).as_posix()


# ------------------------------------------------------------------------------- the worker


def _decode(name: str, data: bytes) -> Any:
    import numpy as np

    from stereovision.io import _decode_8_or_16bit, _not_an_image_hint, decode_image

    # 16-bit files keep their 16 bits, as `stereovision depth` reads them (read_image)
    img: Any = _decode_8_or_16bit(data)
    if img is None:
        img = decode_image(data)
    if img is None:
        # imread's words: a float32 TIFF or a PFM was "cannot decode" alone, as a damaged file
        hint = _not_an_image_hint(Path(name), np.frombuffer(data, np.uint8))
        raise ValueError(f"cannot decode {name} as an image{hint}")
    return img


def _pixels(value: float) -> int | float:
    """A disparity range for the summary: an int when whole (as recorded before), else the
    float searched (write_npz keeps it so too)."""
    v = float(value)
    return int(v) if v.is_integer() else v


def process_pair(task: dict[str, Any]) -> dict[str, Any]:
    """Compute one pair's ``stereovision depth`` outputs (runs on a Dask worker).

    Parameters
    ----------
    task : dict
        ``name``; ``left`` and ``right``: ``(file name, bytes)``; ``calib``: ``(file name,
        bytes)`` or None; ``method`` (None = default), ``max_disparity`` (None = estimated),
        ``fill``; ``ground`` and ``grid`` (:func:`run_batch`'s).

    Returns
    -------
    dict
        ``files`` ({output file name: bytes}), ``max_disparity``, ``density``, ``points``,
        ``seconds`` (compute time), ``worker`` (host:pid), ``warnings`` (the messages of the
        warnings the pair gave, each once, in order; not printed by the worker).

    Raises
    ------
    ValueError
        An image that cannot be decoded, a pair of different sizes, a calibration for another
        size, ... (as ``stereovision depth`` reports them); ``ground`` without ``calib``.
    """
    from stereovision._validate import ADVICE

    if task.get("ground") and task.get("calib") is None:
        # before depth_outputs, whose refusal is the CLI's ("CliError: --ground needs
        # --calib"); a CLI run's summary swaps these words back (_error_line)
        raise ValueError(f"{ADVICE['ground_calib']['api']} (the floor is found in metres)")
    # The pair's warnings go back with its files: a worker printed them on its own stderr as
    # Python does (".../dask/_task_spec.py:768: UserWarning: left: uint16 image ..." and a
    # source line, naming no pair, across the progress bar), or into a remote worker's log.
    # Shown as the CLI shows them: each text once, no ResourceWarning.
    with _pair_warnings() as said:
        res = _compute_pair(task)
    res["warnings"] = [m for i, m in enumerate(said) if m not in said[:i]]
    return res


#: The warnings of the pair each thread computes (:func:`_pair_warnings`).
_PAIR_SINK = threading.local()
_PAIR_LOCK = threading.Lock()
#: Pairs being computed in this process, and the state they replaced (the first one's).
_pair_count = 0
_pair_state: contextlib.ExitStack | None = None


@contextlib.contextmanager
def _pair_warnings() -> Iterator[list[str]]:
    """Collect the messages of the warnings this thread gives, as :func:`process_pair` returns
    them.

    ``warnings.catch_warnings`` swaps process-wide state: a worker computing two pairs at once
    (``dask worker --nthreads 2``, a cluster's default; in-process workers) gave one pair's
    warnings to the other, and the last to end could leave a finished pair's recorder in place.
    The state is set once while any pair runs in this process (the first sets it, the last
    restores it) and each warning goes to its own thread's pair; other threads' warnings are
    shown as they were (with the pairs' filter meanwhile).
    """
    global _pair_count, _pair_state
    caught: list[str] = []
    with _PAIR_LOCK:
        if _pair_count == 0:
            stack = contextlib.ExitStack()
            stack.enter_context(warnings.catch_warnings())
            shown = warnings.showwarning

            def show(
                message: Warning | str,
                category: type[Warning],
                filename: str,
                lineno: int,
                file: Any = None,
                line: str | None = None,
            ) -> None:
                sink = getattr(_PAIR_SINK, "caught", None)
                if sink is None:
                    shown(message, category, filename, lineno, file, line)
                else:
                    sink.append(str(message))

            warnings.showwarning = show
            _pair_state = stack
        # set afresh for each pair: a filter set resets the registry that would hide a
        # message an earlier pair gave from the same line ("default": once per line)
        warnings.simplefilter("default")
        warnings.simplefilter("ignore", ResourceWarning)
        _pair_count += 1
    _PAIR_SINK.caught = caught
    try:
        yield caught
    finally:
        _PAIR_SINK.caught = None
        with _PAIR_LOCK:
            _pair_count -= 1
            if _pair_count == 0 and _pair_state is not None:
                _pair_state.close()
                _pair_state = None


def _compute_pair(task: dict[str, Any]) -> dict[str, Any]:
    """:func:`process_pair`'s work, its warnings not yet caught."""
    from stereovision.calibration import Calibration
    from stereovision.cli import depth_outputs

    t0 = time.perf_counter()
    left = _decode(task["left"][0], task["left"][1])
    right = _decode(task["right"][0], task["right"][1])
    with tempfile.TemporaryDirectory(prefix="stereovision-batch-") as tmp:
        calib = None
        if task.get("calib") is not None:
            cname, cdata = task["calib"]
            cpath = Path(tmp) / Path(cname).name
            cpath.write_bytes(cdata)
            calib = Calibration.from_file(cpath)
        out = Path(tmp) / "out"
        res, written = depth_outputs(
            left,
            right,
            calib,
            out,
            method=task.get("method"),
            max_disparity=task.get("max_disparity"),
            fill=task.get("fill"),
            ground=bool(task.get("ground", False)),
            grid=task.get("grid"),
            name=str(task.get("name", "pair")),
        )
        files = {name: Path(p).read_bytes() for name, p in written.items()}
    return {
        "files": files,
        # a fractional range searched (max_disparity=20.5) was recorded as 20
        "max_disparity": _pixels(res.max_disparity),
        "density": float(res.density),
        "points": len(res.points),
        "seconds": time.perf_counter() - t0,
        "worker": f"{socket.gethostname()}:{os.getpid()}",
    }


# ------------------------------------------------------------------------------- the client


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def _calib_inputs(calib: Path | None) -> dict[str, Path]:
    """The files :meth:`~stereovision.calibration.Calibration.from_file` reads for ``calib``,
    by their fingerprint keys: ``calib`` for the file itself, ``calib:NAME`` for a file it reads
    in a folder (``rig/`` of OpenCV ``stereo_calib``: its intrinsics.yml and extrinsics.yml; a
    ROS camera_info folder's left.yaml and right.yaml) or beside it (``left.yaml``'s
    ``right.yaml``). A folder's own time and size were its fingerprint, and a file rewritten
    in it (a new T in extrinsics.yml) changes neither: its pairs were skipped as done. The
    image that sizes a calibration holding no size (the ``left.png`` beside a ``Q.dat``, the
    image beside a KITTI file without ``S_rect_02``) is one too, ``calib:NAME``: another one
    there changed the calibration read, and its pairs were skipped as done."""
    from stereovision.calibration import (
        _ros_pair_from_folder,
        _ros_sibling,
        _sizing_images,
        _stereo_calib_files,
    )

    if calib is None:
        return {}
    files: tuple[Path, ...] = ()
    pair = _stereo_calib_files(calib)
    if pair is not None:
        files = pair
    elif calib.is_dir():
        ros = _ros_pair_from_folder(calib)
        own = [f for f in (calib / "calib.txt", calib / "Q.dat") if f.is_file()]
        files = ros if ros is not None else tuple(own[:1])
    elif calib.suffix.lower() in (".yaml", ".yml"):
        files = _ros_sibling(calib) or ()
    inputs = {} if files and calib.is_dir() else {"calib": calib}
    inputs.update({f"calib:{f.name}": f for f in files if f != calib})
    inputs.update({f"calib:{f.name}": f for f in _sizing_images(calib)})
    return inputs


def _inputs(job: PairJob) -> dict[str, Path]:
    """The files a pair is made of, by their fingerprint keys: ``left``, ``right`` and its
    calibration's (:func:`_calib_inputs`) but the pair's own images (a scene's ``Q.dat`` is
    sized by its ``left.png``, already ``left``)."""
    inputs = {"left": job.left, "right": job.right}
    for key, path in _calib_inputs(job.calib).items():
        if path not in (job.left, job.right):
            inputs[key] = path
    return inputs


def _fingerprint(job: PairJob) -> dict[str, Any]:
    """The size and time of each of the pair's input files (:func:`_inputs`).

    Raises
    ------
    ValueError
        If its left or right image is no regular file (a FIFO, a socket, a link to /dev/zero
        named ``left/0001.png``): reading it waited for a writer, or without end, and the run
        hung; the pair fails instead.
    """
    fp: dict[str, Any] = {}
    for key, p in _inputs(job).items():
        st = p.stat()
        if key in ("left", "right") and not stat.S_ISREG(st.st_mode):
            kind = (
                "a FIFO"
                if stat.S_ISFIFO(st.st_mode)
                else "a socket"
                if stat.S_ISSOCK(st.st_mode)
                else "a folder"
                if stat.S_ISDIR(st.st_mode)
                else "a device"
            )
            raise ValueError(f"image file is not a regular file: {p} ({kind})")
        fp[key] = [st.st_size, st.st_mtime_ns]
    return fp


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _hashes(job: PairJob, task: dict[str, Any]) -> dict[str, str]:
    """The sha256 of the pair's input files (of the bytes ``task`` ships for its images, read
    once for both; of each calibration file read, :func:`_calib_inputs`)."""
    hashes = {side: hashlib.sha256(task[side][1]).hexdigest() for side in ("left", "right")}
    for key, path in _inputs(job).items():
        if key not in hashes and path.is_file():
            hashes[key] = _sha256(path)
    return hashes


def _same_content(entry: dict[str, Any], fp: dict[str, Any], job: PairJob) -> bool:
    """Whether ``job``'s files are those ``entry`` recorded though their modification times
    differ (a copy that did not keep them: ``cp -r``, a sync, a restore): the same files with
    the same sizes, each whose time differs holding the bytes of the sha256 recorded for it
    (read only then). A record without hashes (a summary before version 3) vouches for none."""
    old, hashes = entry.get("fingerprint"), entry.get("hashes")
    if not isinstance(old, dict) or not isinstance(hashes, dict) or old.keys() != fp.keys():
        return False
    paths: dict[str, Path | None] = dict(_inputs(job))
    for key, (size, mtime) in fp.items():
        rec = old[key]
        if not isinstance(rec, list) or len(rec) != 2 or rec[0] != size:
            return False
        if rec[1] == mtime:
            continue
        path, digest = paths.get(key), hashes.get(key)
        if path is None or not isinstance(digest, str) or not path.is_file():
            return False
        try:
            if _sha256(path) != digest:
                return False
        except OSError:
            return False
    return True


def _recorded(path: Path) -> str:
    """``path`` as the summary records it: absolute (a path relative to one run's working
    directory named another file, or none, for a run from another one), each '..' folded as
    the OS follows it (``os.path.abspath`` made ``home/link/../x`` ``home/x``, not the ``x``
    read beside the link's target)."""
    from stereovision.io import _absolute_as_read

    return str(_absolute_as_read(Path(path)))


def _same_file(recorded: Any, path: Path) -> bool:
    """Whether ``recorded`` (an image path a summary holds) names the file ``path``."""
    if not isinstance(recorded, str):
        return False
    with contextlib.suppress(OSError, RuntimeError):
        return Path(recorded).resolve() == path.resolve()
    return False


def _foreign_output(
    dest: Path, job: PairJob, opts: dict[str, Any], recorded: list[str] | None
) -> Path | None:
    """The first file in the pair's folder ``dest`` under a name this run may write for it
    that no earlier run recorded writing (``recorded``, from the summary), or a link (the
    user's, recorded or not: :func:`stereovision.cli.foreign_outputs`), else None."""
    from stereovision.cli import foreign_outputs, planned_depth_outputs

    if not dest.is_dir():
        return None
    names = planned_depth_outputs(
        job.calib is not None, bool(opts.get("ground")), opts.get("grid") is not None
    )
    return next(iter(foreign_outputs(dest, names, recorded or [])), None)


def _pending_outputs(entry: dict[str, Any]) -> list[str]:
    """The files the run that left ``entry`` (a summary record still ``"pending"``) may have
    written into the pair's folder, from the calibration and options it recorded."""
    from stereovision.cli import planned_depth_outputs

    options = entry.get("options")
    if not isinstance(options, dict):
        return []
    return list(
        planned_depth_outputs(
            entry.get("calib") is not None,
            bool(options.get("ground")),
            options.get("grid") is not None,
        )
    )


def _commit_pair(
    out: Path, name: str, files: dict[str, bytes], previous: list[str] | None = None
) -> Path:
    """Write a pair's files into ``out/name``.

    A new folder appears whole: the files are written into a hidden temporary folder renamed
    into place. An existing folder is not replaced (that deleted what else it held: the folders
    of the pairs nested in it, a user's files, the input images of an output folder given as
    the input folder): each file is renamed over its own name, and of the files an earlier run
    recorded (``previous``) those this run did not write are removed. A file where the folder
    goes is a :class:`NotADirectoryError` naming it (the pair fails, the file is kept); a folder
    where one of the files goes an :class:`IsADirectoryError` naming it, before any file moves
    (the pair fails, its earlier files and the folder are kept).
    """
    from stereovision.cli import DEPTH_OUTPUTS
    from stereovision.io import _broken_link

    dest = out / name
    for folder in (dest, *dest.parents):
        if folder == out:
            break
        if folder.exists() and not folder.is_dir():
            raise NotADirectoryError(
                f"{folder} is a file, where the pair's output folder {dest} goes: move it away"
            )
        if folder.is_symlink() and not folder.exists():
            # a link to an unmounted disk: the rename said "Not a directory: '.../.a.partial-
            # 1a2b3c4d' -> '.../a'" (a hidden folder), under it mkdir stopped the run (File exists)
            raise NotADirectoryError(
                f"{folder} is {_broken_link(folder)}, where the pair's output folder {dest} "
                "goes: make its target, or remove the link"
            )
    for fname in files:
        # checked before any file moves: the files renamed over theirs before the folder was
        # met were the new run's, the others the earlier run's
        target = dest / fname
        if target.is_dir() and not target.is_symlink():
            raise IsADirectoryError(
                f"{target} is a folder, where the pair's {fname} goes: move it away (the "
                "pair's earlier outputs are kept)"
            )
    dest.parent.mkdir(parents=True, exist_ok=True)
    partial = f".{_partial_stem(dest.name)}.partial-{uuid.uuid4().hex[:8]}"
    tmp = dest.parent / partial
    if dest.is_dir() and os.stat(dest).st_dev != os.stat(dest.parent).st_dev:
        # OUT/a a link to (or a mount of) a folder on another disk: no file is renamed across
        # disks ("Invalid cross-device link" stopped the run, every run); staged inside it
        tmp = dest / partial
    tmp.mkdir()
    try:
        for fname, data in files.items():
            with open(tmp / fname, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
        if not dest.exists():
            os.replace(tmp, dest)
            return dest
        for fname in files:
            os.replace(tmp / fname, dest / fname)
        for fname in previous or []:
            stale = dest / fname
            if fname in DEPTH_OUTPUTS and fname not in files and stale.is_file():
                if not stale.is_symlink():
                    stale.unlink()
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return dest


_PARTIAL_RE = re.compile(r"\.(.+)\.partial-[0-9a-f]{8}")
#: Bytes of a file name (NAME_MAX of the usual filesystems) and those its staging folder's
#: name adds to the pair's: ``.`` and ``.partial-1a2b3c4d``.
_NAME_MAX = 255
_PARTIAL_EXTRA = 18


def _partial_stem(name: str) -> str:
    """The part of a pair's folder name ``name`` its staging folder's name holds: all of it,
    or as much as fits in a file name. A name of 238 to 255 bytes (its folder can be made) gave
    a staging folder's name past 255, "File name too long", and every run stopped there."""
    raw = os.fsencode(name)
    if len(raw) + _PARTIAL_EXTRA <= _NAME_MAX:
        return name
    # a character cut in two stays its bytes (surrogate escapes), as the listing reads them
    return os.fsdecode(raw[: _NAME_MAX - _PARTIAL_EXTRA])


def _remove_partials(out: Path, names: list[str]) -> None:
    """Remove the temporary folders (``.NAME.partial-1a2b3c4d`` beside ``OUT/NAME``, or in it
    when it is on another disk) that a
    run killed while writing those pairs left (SIGKILL, the OOM killer, a power cut: its
    ``finally`` did not run); each held a pair's outputs and stayed, hidden, for good. Only
    folders of that pattern for the pairs ``names`` are touched, under the run's lock."""
    by_parent: dict[Path, set[str]] = {}
    for name in names:
        dest = out / name
        by_parent.setdefault(dest.parent, set()).add(_partial_stem(dest.name))
        # and inside it, where a folder on another disk has them (_commit_pair)
        by_parent.setdefault(dest, set()).add(_partial_stem(dest.name))
    for parent, pairs in by_parent.items():
        try:
            entries = list(os.scandir(parent))
        except OSError:  # not made yet
            continue
        for e in entries:
            m = _PARTIAL_RE.fullmatch(e.name)
            if m and m.group(1) in pairs and e.is_dir(follow_symlinks=False):
                shutil.rmtree(e.path, ignore_errors=True)


def _killed(memory: int, workers: int, scheduler: str | None, words: str = "api") -> str:
    """What a pair's ``KilledWorker`` says: the worker processes computing it died on every try.

    Dask said "Attempted to run task 'stereovision-5bf7...' on 4 different workers, but all
    those workers died while running it ... Inspecting worker logs is often a good next step",
    logs a LocalCluster's silences: a pair needing more than a worker's memory limit (the
    machine's memory over the workers, one per core: 2 GB each on 8 cores and 16 GB, where a
    1920x1080 pair peaks at 2.2 GB) failed so, its remedy unsaid."""
    if scheduler is None and memory > 0 and workers > 1:
        option = "--workers" if words == "cli" else "workers"
        return (
            "the worker processes computing it died on every try: out of memory? Each of the "
            f"{workers} workers is stopped past 95 % of its share of the memory, "
            f"{memory / 2**30:.2f} GiB; fewer {option} give each more"
        )
    if scheduler is None and memory > 0:
        return (
            "the worker process computing it died on every try: out of memory? It is stopped "
            f"past 95 % of the memory, {memory / 2**30:.2f} GiB"
        )
    return (
        "the worker processes computing it died on every try (out of memory, or a crash: see "
        "the workers' logs)"
    )


def _warning_line(text: str, words: str = "api", job: PairJob | None = None) -> str:
    """A pair's warning (its message, from the worker) as a summary line: its first line with
    text, the files of ``job`` escaped and its advice in ``words``, as :func:`_error_line` says
    an error (and the CLI a warning)."""
    from stereovision._validate import advice_for, first_line

    paths = () if job is None else (job.left, job.right, job.calib, job.name)
    line = first_line(UserWarning(text), paths)
    return line if words == "api" else advice_for(line, words)


def _error_line(exc: BaseException, words: str = "api", job: PairJob | None = None) -> str:
    """``exc`` as a summary line, ``Type: first line``, its advice in ``words`` ("api" as
    raised, or "cli": :func:`stereovision._validate.advice_for`). The files of ``job`` and its
    output folder's name that hold a control character are shown escaped
    (:func:`stereovision._validate.escape_paths`): one with a newline in its name cut the line
    there, naming another file."""
    from stereovision._validate import _message, first_line

    # the name too: OUT/<name>/, named by a failure to write there, is no part of the images'
    paths = () if job is None else (job.left, job.right, job.calib, job.name)
    # _message, not str(exc): an error that cannot say its message (KeyError(10**5000)) raised
    # here, in the handler closing a failed run's record
    msg = first_line(exc, paths) if _message(exc).strip() else ""
    if words != "api":
        from stereovision._validate import advice_for

        msg = advice_for(msg, words)
    return f"{type(exc).__name__}: {msg}" if msg else type(exc).__name__


@dataclass
class BatchResult:
    """What one :func:`run_batch` did.

    Attributes
    ----------
    processed, skipped, failed : list of str
        Pair names, by outcome in this run (``skipped``: done before).
    failed_before : list of str
        Pairs skipped because they failed before on the same inputs and options.
    unpaired : list of str
        Images named as one of a pair whose other image is missing (``failed`` lists them
        too; their summary entry says which file is missing).
    missing : list of str
        Pairs recorded as done whose outputs were not in the output folder at the end of the run
        (it was moved or deleted meanwhile); recorded as pending, so that a re-run redoes them.
    redone : list of str
        Pairs done before on the same images with other options, redone (outputs replaced).
    pending : list of str
        Pairs not finished (interrupted run).
    seconds : float
        Wall time of the run.
    summary_path : pathlib.Path
        ``OUT/summary.json``.
    interrupted : bool
        The run was stopped by Ctrl-C.
    """

    processed: list[str]
    skipped: list[str]
    failed: list[str]
    pending: list[str]
    seconds: float
    summary_path: Path
    interrupted: bool = False
    failed_before: list[str] = field(default_factory=list)
    unpaired: list[str] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    redone: list[str] = field(default_factory=list)


class BatchInterrupted(KeyboardInterrupt):
    """The KeyboardInterrupt :func:`run_batch` raises once it has recorded an interrupted run.

    Attributes
    ----------
    result : BatchResult
        What the run did up to the interrupt (``interrupted`` is True).
    """

    def __init__(self, result: BatchResult) -> None:
        super().__init__()
        self.result = result


class _Summary:
    """``OUT/summary.json``: one entry per pair, rewritten atomically after every change
    (:meth:`save`), or after a finished pair once enough time has passed (:meth:`record`)."""

    def __init__(self, out: Path, log: Callable[[str], None] | None = None) -> None:
        self.path = out / SUMMARY_NAME
        self.log = log
        self._dirty = False  # changes recorded but not yet written
        self._cost = 0.0  # seconds the last save took
        self._saved_at = -math.inf  # time.monotonic() at its end
        self.data: dict[str, Any] = {"version": _SUMMARY_VERSION, "pairs": {}}
        if self.path.exists() or self.path.is_symlink():
            try:
                old = json.loads(self.path.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                old = None
            if not (isinstance(old, dict) and isinstance(old.get("pairs"), dict)):
                # the user's summary.json (no batch run writes another): it was replaced
                raise FileExistsError(
                    f"output folder {out}: {self.path} is not a batch summary and would be "
                    "replaced: give another output folder, or move or remove that file"
                )
            self.data = old
            if old.get("version") == 1:
                _list_legacy_outputs(out, self.pairs)
            self.data["version"] = _SUMMARY_VERSION

    @property
    def pairs(self) -> dict[str, Any]:
        return self.data["pairs"]  # type: ignore[no-any-return]

    def ensure_folder(self) -> None:
        """Make the output folder again if it went away (moved or deleted during the run)."""
        folder = self.path.parent
        if not folder.is_dir():
            if self.log is not None:
                self.log(f"{folder} is gone (moved or deleted?): made again for the pairs to come")
            folder.mkdir(parents=True, exist_ok=True)

    def record(self) -> None:
        """Write the summary after a finished pair, unless the last write ended less than
        :data:`SAVE_COST_RATIO` times its own duration ago: a small summary is written after
        every pair, a large one no more than a tenth of the time (every pair rewrote all of it:
        0.5 s at 10000 pairs, a quadratic cost that throttled a long run to a few pairs a
        second). The run's end, an interrupt or an error writes what is left (:meth:`flush`)."""
        self._dirty = True
        if time.monotonic() - self._saved_at >= SAVE_COST_RATIO * self._cost:
            self.save()

    def flush(self) -> None:
        """Write the changes :meth:`record` has not written yet."""
        if self._dirty:
            self.save()

    def save(self) -> None:
        from stereovision.io import atomic_write

        t0 = time.monotonic()
        pairs = self.pairs.values()
        self.ensure_folder()
        self.data["counts"] = {
            s: sum(1 for p in pairs if p.get("status") == s) for s in ("done", "failed", "pending")
        }
        with atomic_write(self.path, "w") as fh:
            json.dump(self.data, fh, indent=1, sort_keys=False)
            fh.write("\n")
        self._dirty = False
        self._saved_at = time.monotonic()
        self._cost = self._saved_at - t0


def _list_legacy_outputs(out: Path, pairs: dict[str, Any]) -> None:
    """List, in each entry of a version 1 summary without ``outputs``, the files under the
    standard output names (:data:`stereovision.cli.DEPTH_OUTPUTS`) in the pair's folder.

    A batch before ed0f5f2 recorded a pair redone on a damaged image, or whose other image had
    gone, as failed without the outputs its folder still held from the run that did it: a
    rerun with the images mended refused those files as not listed (exit 2), and a user
    upgrading could not go on in the output folder. Only regular files are taken (a folder or
    a link under such a name is still refused); the other files are not touched. Names a
    version 1 batch never wrote (:data:`_NAMES_SINCE_V2`: ``overview.png``) are not taken: a
    file under one is the user's, and is refused as not listed, not replaced."""
    from stereovision.cli import DEPTH_OUTPUTS

    legacy = [f for f in DEPTH_OUTPUTS if f not in _NAMES_SINCE_V2]
    for name, entry in pairs.items():
        if not isinstance(entry, dict) or isinstance(entry.get("outputs"), list):
            continue
        folder = out / name
        with contextlib.suppress(OSError, ValueError):
            if not folder.is_dir() or folder.is_symlink():
                continue
            found = sorted(
                f for f in legacy if (folder / f).is_file() and not (folder / f).is_symlink()
            )
            if found:
                entry["outputs"] = found


def _recorded_options(entry: dict[str, Any]) -> Any:
    """The options ``entry`` records, an earlier version's ``method`` None (the default, not
    named) read as ``_DEFAULT_METHOD``, the name recorded now."""
    options = entry.get("options")
    if isinstance(options, dict) and "method" in options and options["method"] is None:
        return {**options, "method": _DEFAULT_METHOD}
    return options


def _unchanged(entry: dict[str, Any] | None, fp: dict[str, Any], opts: dict[str, Any]) -> bool:
    return entry is not None and entry.get("fingerprint") == fp and _recorded_options(entry) == opts


def _changes(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    """``method: gabor -> census`` for each option that differs (no ``ground`` key: off)."""

    def show(v: Any) -> str:
        return "default" if v is None else "on" if v is True else "off" if v is False else str(v)

    a, b = {"ground": False, "grid": None, **old}, {"ground": False, "grid": None, **new}
    return [
        f"{k}: {show(a.get(k))} -> {show(b.get(k))}" for k in {**a, **b} if a.get(k) != b.get(k)
    ]


def _skip(
    entry: dict[str, Any] | None,
    fp: dict[str, Any],
    opts: dict[str, Any],
    out: Path,
    name: str,
    retry_failed: bool,
) -> bool:
    """Done with the same inputs and options (and its outputs are there), or failed on them."""
    if entry is None or not _unchanged(entry, fp, opts):
        return False
    if entry.get("status") == "done":
        return not _outputs_missing(entry, out, name)
    return entry.get("status") == "failed" and not retry_failed


def _outputs_missing(entry: dict[str, Any], out: Path, name: str) -> list[str]:
    """The outputs ``entry`` (a done pair's record) lists that are not files in its folder,
    and ``disparity.pfm`` (written for every pair) if it is not. Only disparity.pfm was looked
    for: a pair whose cloud.ply had gone was skipped as done, its cloud never written again.
    disparity.pfm whatever the list: a version 1 summary's entry lists the files found in its
    folder (:func:`_list_legacy_outputs`), without a disparity.pfm that had gone."""
    listed = entry.get("outputs")
    names = [str(f) for f in listed] if isinstance(listed, list) else []
    names += [] if "disparity.pfm" in names else ["disparity.pfm"]
    return [f for f in names if not (out / name / f).is_file()]


def _in_thread_without_sigint(fn: Callable[[], None]) -> None:
    """Run ``fn`` in a thread that blocks SIGINT, and so do the threads it starts and the
    processes those start (a signal mask survives fork and exec): LocalCluster's worker
    processes then ignore the Ctrl-C a terminal sends to the whole process group, where each
    printed its own KeyboardInterrupt traceback; this process stops them itself."""
    errors: list[BaseException] = []

    def target() -> None:
        try:
            fn()
        except BaseException as exc:
            errors.append(exc)

    thread = threading.Thread(target=target, name="stereovision-batch-start", daemon=True)
    if hasattr(signal, "pthread_sigmask"):
        # multiprocessing's resource tracker unblocks SIGINT in the thread that starts it: it
        # is started here, from this thread, before the mask is set
        from multiprocessing import resource_tracker

        resource_tracker.ensure_running()
        old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            thread.start()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
    else:
        thread.start()
    thread.join()
    if errors:
        raise errors[0]


class _Dask:
    """The client (and the LocalCluster) of a run: started and closed with interrupts held."""

    def __init__(self) -> None:
        self.client: Any = None
        self.cluster: Any = None
        self.desc = ""
        self._quiet = contextlib.ExitStack()  # Dask's low-level logs off until close()

    def start(self, scheduler: str | None, workers: int) -> None:
        try:
            import logging

            from distributed import Client, LocalCluster
        except ImportError:
            raise RuntimeError(
                "batch needs Dask distributed: pip install 'stereovision-rs[batch]'"
            ) from None

        def connect() -> None:
            from stereovision.capture import _mask_secrets_of, mask_url_secrets

            # an address's password (tcp://user:pw@host) is not said, nor written in the run
            address = str(scheduler)
            said = mask_url_secrets(address)
            try:
                self.client = Client(scheduler, timeout=CONNECT_TIMEOUT)
            except (OSError, TimeoutError) as exc:
                raise OSError(
                    f"cannot reach the Dask scheduler at {said}: "
                    f"{_mask_secrets_of(_error_line(exc), address)}"
                ) from None
            except ValueError as exc:  # Dask's "invalid address 'user:pw@host'"
                message = _mask_secrets_of(str(exc), address)
                if message == str(exc):
                    raise
                raise ValueError(message) from None
            self.desc = said

        def local() -> None:
            # One worker process per core by default, each kernel with its share of the cores,
            # so the workers do not oversubscribe the machine.
            threads = str(max(1, (os.cpu_count() or 1) // workers))
            env = {
                "RAYON_NUM_THREADS": threads,
                "OMP_NUM_THREADS": threads,
                "OPENCV_LOG_LEVEL": "ERROR",
            }
            self.cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                # The scheduler serves its HTTP routes (health, metrics) even without the
                # dashboard, on port 8787 unless told otherwise: where that port was taken (a
                # Jupyter or another cluster's dashboard) it warned "Port 8787 is already in
                # use" and left the socket of its failed bind unclosed (a ResourceWarning),
                # two lines beside the CLI's one. Any free port, on this machine only.
                scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                silence_logs=logging.CRITICAL,  # failures are reported per pair
                env=env,
            )
            self.client = Client(self.cluster)
            self.desc = f"LocalCluster({workers} worker processes)"

        import dask

        # Dask's client (and a LocalCluster's scheduler, in this process) log their last 1000
        # messages under 1 MB for debugging, each submitted pair's image bytes with them: the
        # client grew by the pairs' size (0.7 MB a pair of 384x288 PNGs, 21 MB over 30), up to
        # a GB over a night's run. Read as each log is made: when they start, and when the
        # scheduler meets a worker its nanny restarted (a worker killed: set only for the
        # start, that worker's log held the pairs sent to it again), so until close().
        self._quiet.enter_context(dask.config.set({"distributed.admin.low-level-log-length": 0}))
        try:
            with HeldInterrupts():
                if scheduler is not None:
                    connect()
                else:
                    _in_thread_without_sigint(local)
        except BaseException:
            self._quiet.close()
            raise

    def close(self, futures: list[Any]) -> None:
        with HeldInterrupts():
            try:
                if self.client is not None and futures:
                    self.client.cancel(futures)
                if self.client is not None:
                    self.client.close()
                if self.cluster is not None:
                    self.cluster.close()
            except Exception:  # shutting down is best effort; the results are already written
                pass
            finally:
                self._quiet.close()  # Dask's config as it was


def _calib_payload(
    path: Path,
    unit: str | None = None,
    size: tuple[int, int] | list[int] | None = None,
    grey: bool = False,
) -> tuple[str, bytes]:
    """A calibration as one file's name and bytes for a worker: a ROS camera_info folder
    (left.yaml, right.yaml) is read here and shipped as this package's JSON, and so is a
    ``Q.dat`` (sized by the ``left.png`` beside it, which the worker's copy has not), a file
    read in the ``unit`` given (the JSON states it; the worker reads the file without it) and
    one that holds no image size, read at ``size`` (OpenCV ``stereo_calib`` output).

    A file is shipped as it is only when a lone copy of it reads as the same calibration: one
    camera's ROS camera_info (``left.yaml``, its partner beside it) or a KITTI file sized by
    the image beside it was shipped alone, and every pair failed in the worker ("its partner
    ... is not beside it"). ``grey``: a KITTI file read for its grey cameras 0 and 1
    (:func:`_grey_kitti`)."""
    from stereovision.calibration import Calibration

    image_size = None if size is None else (int(size[0]), int(size[1]))
    if grey:
        calib = Calibration.from_kitti(path, image_size=image_size, cameras=(0, 1))
        with tempfile.TemporaryDirectory(prefix="stereovision-calib-") as tmp:
            out = calib.save(Path(tmp) / "calib.json")
            return out.name, out.read_bytes()
    calib = Calibration.from_file(path, image_size=image_size, unit=unit)
    with tempfile.TemporaryDirectory(prefix="stereovision-calib-") as tmp:
        if path.is_file() and unit is None and size is None:
            data = path.read_bytes()
            alone = Path(tmp) / path.name
            alone.write_bytes(data)
            try:
                same = Calibration.from_file(alone) == calib
            except (OSError, ValueError):  # it needs a file beside it (a Q.dat, a ROS partner)
                same = False
            if same:
                return path.name, data
        out = calib.save(Path(tmp) / "calib.json")
        return out.name, out.read_bytes()


#: KITTI's grey rig's camera folders (odometry's, a raw drive's), left and right.
_KITTI_GREY = (("image_0", "image_1"), ("image_00", "image_01"))


def _grey_kitti(job: PairJob) -> bool:
    """Whether ``job`` is a pair of KITTI's grey cameras (``image_0/`` + ``image_1/``, a raw
    drive's ``image_00/`` + ``image_01/``) calibrated by a KITTI file that holds them
    (``P_rect_00``/``P_rect_01``, ``P0``/``P1``): read as the colour pair, as that file is
    by default, their depths were 0.8 % short (baselines 0.537 against 0.533 m)."""
    from stereovision.calibration import parse_kitti_calib

    if job.calib is None or not job.calib.is_file():
        return False
    left, right = [x.lower() for x in job.left.parts], [x.lower() for x in job.right.parts]
    if len(left) != len(right):
        return False
    if [(a, b) for a, b in zip(left, right, strict=True) if a != b] not in (
        [pair] for pair in _KITTI_GREY
    ):
        return False
    try:
        if job.calib.stat().st_size > 65536:
            return False
        text = job.calib.read_text(encoding="utf-8")
        if text.lstrip().startswith(("%YAML", "<?xml", "<opencv", "{")) or not re.search(
            r"^\s*(P_rect_02|P2)\s*:", text, re.MULTILINE
        ):
            return False  # read as another format (as Calibration.from_file orders them)
        keys = parse_kitti_calib(job.calib)
    except (OSError, UnicodeDecodeError, ValueError):
        return False
    return {"P_rect_00", "P_rect_01"} <= keys.keys() or {"P0", "P1"} <= keys.keys()


def _task(
    job: PairJob,
    opts: dict[str, Any],
    payloads: dict[tuple[Path, bool], tuple[str, bytes]] | None = None,
) -> dict[str, Any]:
    """A pair's task for a worker. ``payloads`` holds the run's calibrations already made
    ready (:func:`_calib_payload`): a ``--calib`` shared by every pair is read once a run,
    not once a pair."""
    if payloads is None:
        payloads = {}
    calib = None
    if job.calib is not None:
        # a KITTI file calibrates the grey pairs by their own cameras (0 and 1)
        key = (job.calib, _grey_kitti(job))
        calib = payloads.get(key)
        if calib is None:
            size = opts.get("calib_size")
            if size is None and job.calib == job.left.parent / "Q.dat":
                # a scene's Q.dat beside im0.png (no left.png to size it): the pair failed
                # ("Q.dat does not give the image size"); its own left image sizes it
                size = _calib_size(job.calib, [job])
            calib = _calib_payload(job.calib, opts.get("calib_unit"), size, grey=key[1])
            payloads[key] = calib
    return {
        "name": job.name,
        "left": (str(job.left), job.left.read_bytes()),
        "right": (str(job.right), job.right.read_bytes()),
        "calib": calib,
        **opts,
    }


@contextlib.contextmanager
def _output_lock(out: Path) -> Iterator[None]:
    """Hold an exclusive lock on the output folder for a run (``flock`` on the folder itself:
    no file is left in it, and the system releases it when the process ends, killed or not).

    Two runs into one folder each replaced the whole summary with their own, so the one that
    finished last dropped the other's records without a word. Where the system or filesystem
    cannot lock (Windows, some network filesystems), the run goes on unlocked, as before.

    Raises
    ------
    ValueError
        If another run holds the folder.
    """
    from stereovision.io import lock_folder

    fd, busy = lock_folder(out)
    if busy:
        raise ValueError(
            f"output folder {out} is in use by another stereovision batch run; wait "
            "for it to end, or give another output folder"
        )
    try:
        yield
    finally:
        if fd is not None:
            os.close(fd)  # releases the lock


def run_batch(
    input_dir: str | os.PathLike[str],
    output_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    method: str | None = None,
    max_disparity: float | None = None,
    fill: bool | None = None,
    calib: str | os.PathLike[str] | None = None,
    calib_unit: str | None = None,
    retry_failed: bool = False,
    ground: bool = False,
    grid: float | None = None,
    log: Callable[[str], None] | None = None,
    progress: bool = True,
    words: str = "api",
) -> BatchResult:
    """Process every pair under ``input_dir`` into ``output_dir`` on Dask (see the module doc).

    Parameters
    ----------
    input_dir, output_dir : path
        Input tree and output folder (created if missing).
    workers : int, optional
        Worker processes of the LocalCluster (default: the number of cores), at most one per
        pair to do. Not with ``scheduler`` (its cluster's workers are its own).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``).
    method : str, optional
        Matcher; None = ``depth_map``'s default.
    max_disparity : float, optional
        Largest disparity searched in every pair, in pixels: any positive number (a fractional
        one as :func:`~stereovision.depth.depth_map` searches it, recorded as given); None =
        estimated per pair. Not ``"auto"`` (None is).
    fill : bool, optional
        Fill the holes (:func:`depth_map`'s ``fill``); None = the method's default.
    calib : path, optional
        Calibration for every pair (else each scene's ``calib.txt``).
    calib_unit : str, optional
        Length unit of ``calib``'s ``T`` when the file does not state it (a ``Q.dat``, OpenCV
        ``stereo_calib`` output); :meth:`~stereovision.calibration.Calibration.from_file`'s
        ``unit``. A ``calib`` that holds no image size (``stereo_calib`` output, a ``Q.dat``
        alone) is read at the size of the first pair's left image; a pair of another size
        fails ("calibration is for WxH images, got ...").
    ground : bool
        Also write each pair's floor (``ground.json``, ``obstacles.png``, ``scan.json``;
        :func:`stereovision.ground.fit_ground_plane`, :func:`~stereovision.ground.laser_scan`).
    grid : float, optional
        With ``ground``: each pair's occupancy grid of this cell side (``map.png``, ``map.yaml``).
    retry_failed : bool
        Also redo the pairs that failed before on the same inputs (by default a failed pair is
        redone only once its files or the options change).
    log : callable, optional
        Receives one line per failed pair, one per warning a pair gave (``NAME: warning:
        ...``, as ``stereovision depth`` warns: 12-bit data in 16-bit files), and notes: pairs
        done before with other options (redone), an output folder that went away during the run.
    progress : bool
        Show a progress bar on a terminal (stderr), else a plain line on stderr every tenth of
        the pairs or every :data:`PROGRESS_SECONDS`; before it, when the check of the pairs'
        files against the summary runs long (files copied without their times are read
        again), a bar over that check (a plain line every :data:`PROGRESS_SECONDS`).
    words : {"api", "cli"}
        Whose words the errors recorded in ``summary.json`` (and given to ``log``) advise in:
        the Python API's, as raised (``calib.scaled_to((w, h))``, ``max_disparity``), or the
        command line's (``--calib``, ``--max-disparity``), as ``stereovision batch`` records
        them; so is a refusal of ``calib`` (``--calib-unit``, as the command says it).

    Returns
    -------
    BatchResult

    Raises
    ------
    FileNotFoundError, NotADirectoryError
        A missing input folder or calibration file.
    ValueError
        ``workers`` not a whole number above 0 or given with ``scheduler``, a bad
        ``max_disparity``, an unknown ``method``, no pair under the input, an output folder
        that is a file (or below one), or one holding the outputs of pairs of the same names
        that a run over another input folder made from other images (they would be replaced),
        or one that another run is writing into.
    TypeError
        A ``fill`` that is not True, False or None, a ``ground`` or ``retry_failed`` that is
        not True or False, a ``max_disparity`` or ``grid`` that is not a number.
    PermissionError
        If the output folder cannot be written, or the input folder cannot be listed.
    OSError
        The scheduler cannot be reached.
    BatchInterrupted
        A KeyboardInterrupt (Ctrl-C, or a SIGTERM that the caller turns into one) raised in the
        main thread during the run, after Dask was stopped and the summary recorded the run as
        interrupted; its ``result`` tells what was done. An interrupt before the summary is
        first written (while the input is searched) is raised as it came.
    """
    from stereovision._validate import as_path

    # pathlib's TypeError for a bytes name (or None) named no argument
    as_path(input_dir, "input_dir")
    as_path(output_dir, "output_dir")
    if workers is not None:
        from stereovision._validate import positive_whole

        # 1.5 failed in the LocalCluster's start, "2" in a comparison, True passed as 1
        workers = positive_whole(workers, "workers", "a whole number above 0")
    if workers is not None and scheduler is not None:
        # workers was ignored with a scheduler: workers=8 ran on the cluster's own workers
        # without a word (the CLI refuses --workers with --scheduler alike)
        raise ValueError(
            "workers sizes the local cluster; scheduler's workers are the cluster's own: "
            "give one of them"
        )
    if words not in ("api", "cli"):
        raise ValueError(f"words: expected 'api' or 'cli', got {words!r}")
    import numpy as np

    from stereovision._validate import (
        escaped,
        finite_number,
        number_shown,
        real_number,
        too_large_for_float,
    )
    from stereovision.depth import METHODS

    # True or False, as the CLI gives them (store_true) and depth_map takes a switch: "no"
    # was true (a floor asked for, every pair failing without a calibration; failed pairs redone)
    for name, flag in (("ground", ground), ("retry_failed", retry_failed)):
        if not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"{name}: expected True or False, got {flag!r}")
    ground, retry_failed = bool(ground), bool(retry_failed)

    if grid is not None:
        # "0.2" failed in isfinite ("must be real number, not str"), a NumPy float32 at the
        # summary's first write (no JSON)
        if not real_number(grid):
            raise TypeError(f"grid: expected a cell side in metres, got {grid!r}")
        if too_large_for_float(grid):  # 10**400: float() raised a bare OverflowError
            raise ValueError(
                f"grid: expected a cell side from 0.01 to 10 m, got {number_shown(grid)}"
            )
        grid = float(grid)
    if grid is not None and not ground:
        raise ValueError("grid: the occupancy grid lies on the floor; it needs ground=True")
    if grid is not None and not (math.isfinite(grid) and 0.01 <= grid <= 10):
        raise ValueError(f"grid: expected a cell side from 0.01 to 10 m, got {grid}")

    # refused here, as depth_map refuses them: in the workers every pair failed alike (a
    # cluster started, each pair recorded as failed, a finished pair's record too)
    if max_disparity is not None:
        if not real_number(max_disparity):  # True passed as 1, "16" failed in the comparison
            raise TypeError(f"max_disparity: expected a number of pixels, got {max_disparity!r}")
        if isinstance(max_disparity, np.generic):  # a NumPy number is no JSON for the summary
            max_disparity = max_disparity.item()
        # an int too large for a float (10**400): depth_map's finite_number refuses it, so
        # every pair failed alike in the workers; refused here in its words
        if too_large_for_float(max_disparity):
            finite_number(max_disparity, "max_disparity")
        if not (math.isfinite(max_disparity) and max_disparity > 0):
            given = number_shown(max_disparity)
            raise ValueError(f"max_disparity: expected a positive number, got {given}")
    if method is not None and method not in METHODS:
        raise ValueError(f"unknown method {method!r}: expected one of {', '.join(METHODS)}")
    if fill is not None and not isinstance(fill, (bool, np.bool_)):
        raise TypeError(f"fill: expected True, False or None, got {fill!r}")
    fill = None if fill is None else bool(fill)  # numpy's True_ is no JSON for the summary
    from stereovision.io import check_output_folder

    t0 = time.perf_counter()
    if calib_unit is not None and calib is None:
        raise ValueError("calib_unit is the unit of calib's file: give calib too")
    jobs, unpaired, calib_size = _scan(input_dir, calib, calib_unit, output_dir, words)
    # a file in the way, or a folder that cannot be written: said as such, before a cluster
    # starts (it was "[Errno 17] File exists" or "[Errno 2] No such file or directory")
    check_output_folder(output_dir, "output folder")
    if not jobs:
        alone = (
            f"; {len(unpaired)} image(s) without the other of their pair, e.g. {unpaired[0].what}"
            if unpaired
            else ""
        )
        raise ValueError(
            f"no pair under {input_dir} (scene folders with left.png + right.png or "
            "im0.png + im1.png, files named ...left... / ...right..., or the same file names in "
            "sibling camera folders left/ + right/, L/ + R/, image_2/ + image_3/, "
            f"image_02/ + image_03/, cam0/ + cam1/, image_left/ + image_right/){alone}"
        )
    out = Path(output_dir)
    from stereovision.io import missing_folders

    # removed again if the run never starts (io.missing_folders: new/../OUT left new/ behind)
    made = missing_folders(out)
    # a summary this run writes into a folder that had none is its own, removed with it too
    fresh = not os.path.lexists(out / SUMMARY_NAME)
    out.mkdir(parents=True, exist_ok=True)
    with _output_lock(out):  # a second run into OUT would drop this one's records
        summary = _Summary(out, log)
        # -o given as the input: the outputs of a pair one of whose images was deleted since
        # (00/image_0/000001/disparity.png) were each reported as an image without its pair
        unpaired = [u for u in unpaired if not _earlier_output(u.present, out, summary.pairs)]
        # the input folder of the runs that wrote OUT before (None for a new OUT)
        earlier_input = summary.data.get("input") if summary.pairs else None
        # the method by its name: --method fused after a run without --method (the default)
        # redid every pair, None and "fused" two options (an earlier None is read as it)
        chosen = _DEFAULT_METHOD if method is None else method
        opts: dict[str, Any] = {"method": chosen, "max_disparity": max_disparity, "fill": fill}
        if ground:  # only when asked: outputs of earlier runs without it stay valid
            opts.update(ground=True, grid=grid)
        if calib_unit is not None:  # as ground: only when given
            opts["calib_unit"] = calib_unit
        if calib_size is not None:  # a calibration without a size, sized by the first pair
            # ... or by the pairs an earlier run into OUT did with it: a pair of another size
            # added since that sorts first changed the size of every pair (all redone, all but
            # it failed); it fails alone now, as any pair of the wrong size does
            assert calib is not None
            calib_size = _recorded_calib_size(summary.pairs, Path(calib)) or calib_size
            opts["calib_size"] = list(calib_size)
        summary.data.update(
            input=str(Path(input_dir).resolve()),
            output=str(out.resolve()),
        )
        todo: list[PairJob] = []
        previous: dict[str, list[str]] = {}  # the outputs an earlier run recorded, per pair
        skipped: list[str] = []
        failed_before: list[str] = []
        redone: list[str] = []
        incomplete: list[tuple[str, list[str]]] = []  # done as now, some outputs gone: (name, them)
        changes: set[str] = set()
        others: list[tuple[str, str]] = []  # done from another input folder's images: (name, image)
        foreign: Path | None = None  # a file under an output name no run recorded writing
        foreign_listed: list[str] = []  # the outputs recorded in its pair's folder
        unreadable: list[tuple[PairJob, str]] = []  # an image or calibration not there
        checking = _Checking(len(jobs), progress)
        for job in checking.over(jobs):
            try:
                fp = _fingerprint(job)
            # a broken link, an unmounted drive, a FIFO named as an image: this pair alone fails
            except (OSError, ValueError) as exc:
                unreadable.append((job, _error_line(exc, words, job)))
                continue
            entry = summary.pairs.get(job.name)
            # new times: the files are read again (a copy of a large dataset took minutes with
            # nothing shown before the pairs' bar)
            checking.reading |= entry is not None and entry.get("fingerprint") != fp
            if (
                entry is not None
                and entry.get("fingerprint") != fp
                and _same_content(entry, fp, job)
            ):
                # copied without its times (cp -r, a sync): the same bytes, so what was done (or
                # failed) on them stands; the record names these files and their times now
                entry.update(
                    fingerprint=fp,
                    left=_recorded(job.left),
                    right=_recorded(job.right),
                    calib=None if job.calib is None else _recorded(job.calib),
                )
            if _skip(entry, fp, opts, out, job.name, retry_failed):
                assert entry is not None
                # its images where they are now: an input moved with its times named the old
                # place, and a new drive made there passed for these images (not refused as
                # made from other images, its outputs replacing these). A path that still names
                # the image is kept: rewritten to one through a link, the link pointed at
                # another drive passed for these images just so
                for key, path in (("left", job.left), ("right", job.right), ("calib", job.calib)):
                    if path is None or not _same_file(entry.get(key), path):
                        entry[key] = None if path is None else _recorded(path)
                entry["this_run"] = "skipped"
                (skipped if entry["status"] == "done" else failed_before).append(job.name)
                continue
            if (
                entry is not None
                and entry.get("status") == "done"
                and earlier_input is not None
                and earlier_input != summary.data["input"]
                # its images are not this pair's: a run over another input since is not enough
                and not _same_file(entry.get("left"), job.left)
                and entry.get("fingerprint") != fp
                and (out / job.name / "disparity.pfm").is_file()
            ):
                others.append((job.name, str(entry.get("left"))))
            if (
                entry is not None
                and entry.get("status") == "done"
                and entry.get("fingerprint") == fp
                and (out / job.name / "disparity.pfm").is_file()
            ):
                if _recorded_options(entry) != opts:  # other options: its outputs are replaced
                    redone.append(job.name)
                    changes.update(_changes(_recorded_options(entry) or {}, opts))
                else:  # as it was, but some of its outputs are gone: written again
                    incomplete.append((job.name, _outputs_missing(entry, out, job.name)))
            if entry is not None and isinstance(entry.get("outputs"), list):
                previous[job.name] = [str(f) for f in entry["outputs"]]
            summary.pairs[job.name] = {
                "status": "pending",
                "left": _recorded(job.left),
                "right": _recorded(job.right),
                "calib": None if job.calib is None else _recorded(job.calib),
                "options": opts,
                "fingerprint": fp,
            }
            if job.name in previous:
                # still in its folder until this run writes the pair: a run stopped before (or
                # failing it) keeps them listed, so the next one removes those it does not write
                summary.pairs[job.name]["outputs"] = previous[job.name]
            todo.append(job)
            if foreign is None:
                recorded = list(previous.get(job.name) or [])
                if entry is not None and entry.get("status") == "pending":
                    # a run stopped before recording the pair (killed, or its summary held back
                    # by record()) may have written it: that run found no file under these names
                    # that was not its own before it began, so what is there now is its output
                    recorded += _pending_outputs(entry)
                foreign = _foreign_output(out / job.name, job, opts, recorded)
                foreign_listed = recorded
        if others:
            # a second drive under the same pair names replaced the first one's outputs, unsaid
            name, image = others[0]
            raise ValueError(
                f"output folder {out} holds the outputs of {len(others)} pair(s) of the same names "
                # the example's image names its folder: the last run's input may be another one
                f"made from other images (e.g. {name} from {image}); give "
                f"another output folder, or remove those pairs' folders to replace them"
            )
        if foreign is not None:  # the user's own file in a pair's folder: replaced, unsaid
            from stereovision.cli import not_ours

            raise FileExistsError(
                f"output folder {out}: {foreign} {not_ours(foreign, foreign_listed)} and would "
                "be replaced: give another output folder, or move or remove that file"
            )
        _remove_partials(out, [j.name for j in jobs])
        if redone and log is not None:
            shown = sorted(changes)[:3] + (["..."] if len(changes) > 3 else [])
            log(
                f"{len(redone)} pair(s) were done with other options ({'; '.join(shown)}); they "
                "are redone and their outputs replaced"
            )
        if incomplete and log is not None:
            name, gone_files = incomplete[0]
            log(
                f"{len(incomplete)} pair(s) done before miss some of their outputs (e.g. {name}: "
                f"{', '.join(gone_files)}); they are done again"
            )
        processed: list[str] = []
        failed: list[str] = []

        def record_failed(
            name: str, left: Path, right: Path, calib: Path | None, error: str
        ) -> None:
            earlier = summary.pairs.get(name) or {}
            summary.pairs[name] = {
                "status": "failed",
                "left": _recorded(left),
                "right": _recorded(right),
                "calib": None if calib is None else _recorded(calib),
                "error": error,
                "finished": _now(),
                "this_run": "failed",
            }
            if isinstance(earlier.get("outputs"), list):  # an earlier run's, still in its folder
                summary.pairs[name]["outputs"] = earlier["outputs"]
            failed.append(name)
            if log is not None:
                log(f"failed {escaped(name)}: {error}")

        for u in unpaired:  # a failed pair, every run until the missing image is there
            left, right = (u.present, u.missing) if u.side == "left" else (u.missing, u.present)
            record_failed(u.name, left, right, None, u.error)
        for job, error in unreadable:  # tried again every run, as its files may come back
            record_failed(job.name, job.left, job.right, job.calib, error)
        # the records of pairs not under this input (removed since, or another input's) are
        # kept with their outputs; they said what the run that saw them last did to them
        here = {j.name for j in jobs} | {u.name for u in unpaired}
        for name, entry in summary.pairs.items():
            if name not in here and isinstance(entry, dict):
                entry["this_run"] = "not in input"
        # no more worker processes than pairs to do: each starts Python, NumPy and OpenCV (a 64-core
        # machine started 64 for 2 pairs), and the cores go to the kernels' own threads instead
        n_workers = max(1, min(workers or os.cpu_count() or 1, len(todo)))
        run: dict[str, Any] = {
            "started": _now(),
            "scheduler": None,
            "pairs": len(jobs) + len(unpaired),
            "processed": 0,
            "skipped": len(skipped),
            "skipped_failed": len(failed_before),
            "failed": len(failed),
            "unpaired": len(unpaired),
            "interrupted": False,
        }
        summary.data["run"] = run
        interrupted = False
        cause: KeyboardInterrupt | None = None
        try:
            summary.save()
            if todo:
                _run_jobs(
                    todo,
                    opts,
                    out,
                    summary,
                    run,
                    scheduler,
                    n_workers,
                    log,
                    progress,
                    processed,
                    failed,
                    previous,
                    words,
                )
        except KeyboardInterrupt as exc:
            interrupted = True
            cause = exc
        except Exception as exc:
            # the scheduler not reached, Dask not installed: a run that never started left its
            # summary (every pair pending) in a folder it had just made; nothing of it is left
            if run["scheduler"] is None:  # set once Dask is up
                _remove_unstarted(out, made, fresh)
                raise
            # an error once pairs went to the workers (the output disk full): the pairs finished
            # are kept and recorded; the record of the run was left without its end, it is
            # closed with the error, as an interrupted run's is
            with HeldInterrupts(replay=False):
                run.update(
                    finished=_now(),
                    seconds=round(time.perf_counter() - t0, 3),
                    error=_error_line(exc, words, job),
                )
                unsaved = ""
                try:
                    summary.save()
                except OSError as err:  # the disk that is full, maybe
                    unsaved = err.strerror or str(err)
            if not isinstance(exc, OSError):
                raise
            done = len(processed) + len(failed)
            ended = set(processed) | set(failed)
            to_do = sum(1 for j in todo if j.name not in ended)
            # "recorded in summary.json" of a summary that could not be written (a long run's
            # is written every few pairs: those finished since are not in it)
            kept_said = (
                f"kept in {out}; {summary.path} could not be updated ({unsaved}): the pairs "
                "finished since it was last written are not recorded in it"
                if unsaved
                else f"kept in {out} and recorded in {summary.path}"
            )
            said = OSError(
                f"{exc}; {done} of {done + to_do} pairs finished this run, {kept_said}; run again "
                "to continue"
            )
            said.errno = exc.errno
            raise said from exc
        with HeldInterrupts(replay=False) as held:  # the record of the run is written whole
            gone = _outputs_gone(out, summary, [j.name for j in jobs])
            seconds = time.perf_counter() - t0
            run.update(
                finished=_now(),
                seconds=round(seconds, 3),
                interrupted=interrupted,
                missing=len(gone),
            )
            summary.save()
        if held.received and not interrupted:
            interrupted = True
            run["interrupted"] = True
            summary.save()
        pending = [j.name for j in todo if j.name not in processed and j.name not in failed]
        result = BatchResult(
            processed,
            skipped,
            failed,
            pending,
            seconds,
            summary.path,
            interrupted=interrupted,
            failed_before=failed_before,
            unpaired=[u.name for u in unpaired],
            missing=gone,
            redone=redone,
        )
        if interrupted:
            raise BatchInterrupted(result) from cause
        return result


def _cli_calibration(
    calib: str | os.PathLike[str] | None, unit: str | None, size: tuple[int, int] | None = None
) -> None:
    """Read ``--calib`` as ``stereovision batch`` does, its refusals in the command line's words
    (``--calib-unit``); batch has no ``--rectification``, which the refusal of rectify's
    homographies names."""
    from stereovision.cli import _HOMOGRAPHIES_USE, load_calibration

    homographies = f"batch takes no homographies; {_HOMOGRAPHIES_USE}"
    load_calibration(calib, unit, size=size, homographies=homographies)


def _earlier_output(image: Path, out: Path, pairs: dict[str, Any]) -> bool:
    """Whether ``image`` is an output a run recorded in ``out`` (one of the ``outputs`` of the
    summary's pair whose folder holds it), not an input image.

    Parameters
    ----------
    image : Path
        An image the search found (inside ``out`` when ``-o`` is the input or lies in it).
    out : Path
        The output folder.
    pairs : dict
        The summary's pair records.

    Returns
    -------
    bool
        True for a file the summary lists as its pair's output.
    """
    try:
        rel = Path(os.path.realpath(image.parent)).relative_to(os.path.realpath(out))
    except ValueError:  # not under out
        return False
    entry = pairs.get(rel.as_posix())
    outputs = entry.get("outputs") if isinstance(entry, dict) else None
    return isinstance(outputs, list) and image.name in outputs


def _remove_unstarted(out: Path, made: list[Path], fresh: bool) -> None:
    """Remove the summary of a run that never started when the folder had none before it
    (``fresh``: an output folder that was there, empty, kept it, every pair pending), and the
    folders it made for it while empty (an output folder that was there is kept)."""
    from stereovision.io import remove_empty_folders

    if fresh:
        with contextlib.suppress(OSError):
            (out / SUMMARY_NAME).unlink(missing_ok=True)
    remove_empty_folders(made)  # out first, then the parents it needed, while empty


def _outputs_gone(out: Path, summary: _Summary, names: list[str]) -> list[str]:
    """The pairs of ``names`` recorded as done whose outputs are not in ``out`` (moved or
    deleted during the run), recorded as pending with a note: the next run redoes them."""
    gone = []
    for name in names:
        entry = summary.pairs.get(name)
        if entry and entry.get("status") == "done" and not (out / name / "disparity.pfm").is_file():
            entry.update(status="pending", note=_GONE)
            gone.append(name)
    return gone


class _Progress:
    """A tqdm bar on a terminal; elsewhere (a log file, a pipe, a service's journal) a plain line
    on stderr every tenth of the pairs or every :data:`PROGRESS_SECONDS`, whichever comes first:
    ``batch: 12/40 pairs, 1 failed, 31 s, about 72 s left``. The time left is the pace of the
    pairs the workers finished (done, or failed there) since they were up, times the pairs
    left; a pair that failed before it reached them (an unreadable image) took none of that
    time. The estimate shows once a worker has finished a pair."""

    def __init__(self, total: int, enabled: bool) -> None:
        from tqdm import tqdm

        tty = sys.stderr.isatty()
        self.bar = tqdm(
            total=total, desc="pairs", unit="pair", file=sys.stderr, disable=not enabled or not tty
        )
        self.plain = enabled and not tty
        self.total, self.n, self.failed = total, 0, 0
        self.worked = 0  # pairs finished by the workers: the pace's (not the instant failures)
        self.step = max(1, math.ceil(total / 10))
        self.t0 = self.last = self.t_work = time.monotonic()

    def started(self) -> None:
        """The workers are up: the time left is estimated from the pairs' pace since (the
        cluster's start, seconds on a loaded machine, made the first lines' estimate a multiple
        of the run's remaining time)."""
        self.t_work = time.monotonic()

    def update(self, failed: bool = False, instant: bool = False) -> None:
        """One pair finished: ``failed`` or done; ``instant`` when it failed before it reached
        the workers (its files not read), a time the pace does not count."""
        self.bar.update(1)
        self.n += 1
        self.failed += failed
        self.worked += not instant
        now = time.monotonic()
        if not self.plain or self.n >= self.total:  # the final line says the rest
            return
        if self.n % self.step and now - self.last < PROGRESS_SECONDS:
            return
        self.last = now
        spent = now - self.t0
        # 3 unreadable pairs failed at once beside 1 done in 10 s said "about 15 s left" for 6
        # more (60 s): the pace counted them as done in the same 10 s
        left = ""
        if self.worked:
            pace = (now - self.t_work) / self.worked
            left = f", about {pace * (self.total - self.n):.0f} s left"
        fails = f", {self.failed} failed" if self.failed else ""
        print(
            f"batch: {self.n}/{self.total} pairs{fails}, {spent:.0f} s{left}",
            file=sys.stderr,
            flush=True,
        )

    def close(self) -> None:
        self.bar.close()


class _Checking:
    """Progress of the check of every pair's files against the summary, which reads the files
    again whose times changed (:func:`_same_content`): on a terminal a bar over the pairs, shown
    once the check has run :data:`CHECK_BAR_DELAY` seconds; elsewhere, once files are being
    read, a plain line every :data:`PROGRESS_SECONDS`: ``batch: checking the pairs' files
    (their times changed): 120/400 pairs, 31 s``."""

    def __init__(self, total: int, enabled: bool) -> None:
        from tqdm import tqdm

        tty = sys.stderr.isatty()
        self.bar = tqdm(
            total=total,
            desc="checking files",
            unit="pair",
            file=sys.stderr,
            delay=CHECK_BAR_DELAY,
            disable=not enabled or not tty,
        )
        self.plain = enabled and not tty
        self.total, self.n = total, 0
        #: set by the caller once a pair's files are read again (their times changed)
        self.reading = False
        self.t0 = self.last = time.monotonic()

    def over(self, jobs: list[PairJob]) -> Iterator[PairJob]:
        """``jobs``, each counted once the caller is done with it; the bar closed at the end
        (or when the caller stops)."""
        try:
            for job in jobs:
                yield job
                self._update()
        finally:
            self.bar.close()

    def _update(self) -> None:
        self.bar.update(1)
        self.n += 1
        now = time.monotonic()
        if not (self.plain and self.reading) or self.n >= self.total:
            return
        if now - self.last < PROGRESS_SECONDS:
            return
        self.last = now
        print(
            f"batch: checking the pairs' files (their times changed): {self.n}/{self.total} "
            f"pairs, {now - self.t0:.0f} s",
            file=sys.stderr,
            flush=True,
        )


def _run_jobs(
    todo: list[PairJob],
    opts: dict[str, Any],
    out: Path,
    summary: _Summary,
    run: dict[str, Any],
    scheduler: str | None,
    n_workers: int,
    log: Callable[[str], None] | None,
    progress: bool,
    processed: list[str],
    failed: list[str],
    previous: dict[str, list[str]] | None = None,
    words: str = "api",
) -> None:
    """Run ``todo`` on Dask, recording each pair as it finishes into ``processed`` / ``failed``
    and the summary (errors in ``words``, :func:`_error_line`); a KeyboardInterrupt is raised
    on after Dask is stopped."""
    from stereovision._validate import escaped

    bar = _Progress(len(todo), progress)
    futures: dict[Any, PairJob] = {}
    dask = _Dask()
    try:
        dask.start(scheduler, n_workers)  # first: without Dask it names the extra to install
        bar.started()
        from distributed import as_completed

        client = dask.client
        run["scheduler"] = dask.desc
        live = client.scheduler_info().get("workers", {})
        n_live = len(live) or n_workers
        # each worker's memory limit, past 95 % of which its nanny kills it (a LocalCluster's:
        # the machine's memory over its workers)
        memory = min((int(w.get("memory_limit") or 0) for w in live.values()), default=0)
        limit = max(1, IN_FLIGHT_PER_WORKER * n_live)
        queue: Iterator[PairJob] = iter(todo)
        ac = as_completed()
        payloads: dict[tuple[Path, bool], tuple[str, bytes]] = {}

        def submit_next() -> bool:
            job = next(queue, None)
            if job is None:
                return False
            try:
                task = _task(job, opts, payloads)
                # read from the bytes shipped: a copy of these files without their times is
                # known; its calibration files read again (an OSError there stopped the run)
                hashes = _hashes(job, task)
            except (OSError, ValueError) as exc:  # unreadable input or calibration (a scene's
                # Q.dat is read here): a failed pair, not a failed run
                if isinstance(exc, OSError):
                    # a file not read (permission denied, an I/O error) is tried again every
                    # run, as one whose size cannot be read: with its fingerprint the next run
                    # skipped it as failed before, though it was readable again (chmod
                    # changes neither its size nor its time)
                    for key in ("options", "fingerprint"):
                        summary.pairs[job.name].pop(key, None)
                record_failure(job, exc, instant=True)
                return True
            summary.pairs[job.name]["hashes"] = hashes
            fut = client.submit(process_pair, task, key=f"stereovision-{uuid.uuid4().hex}")
            futures[fut] = job
            ac.add(fut)
            return True

        def record_failure(
            job: PairJob, exc: BaseException, line: str | None = None, instant: bool = False
        ) -> None:
            entry = summary.pairs[job.name]
            entry.update(
                status="failed",
                error=line or _error_line(exc, words, job),
                finished=_now(),
                this_run="failed",
            )
            failed.append(job.name)
            run["failed"] = len(failed)
            summary.record()
            bar.update(failed=True, instant=instant)
            if log is not None:
                log(f"failed {escaped(job.name)}: {entry['error']}")

        while len(futures) < limit and submit_next():
            pass
        for fut in ac:
            job = futures.pop(fut)
            exc = fut.exception()
            if exc is not None and type(exc).__name__ == "KilledWorker":
                # Dask's words sent to "worker logs" a LocalCluster silences, naming a task key
                record_failure(
                    job, exc, f"KilledWorker: {_killed(memory, n_live, scheduler, words)}"
                )
            elif exc is not None:
                record_failure(job, exc)
            else:
                res = fut.result()
                summary.ensure_folder()
                try:
                    _commit_pair(out, job.name, res["files"], (previous or {}).get(job.name))
                except (NotADirectoryError, IsADirectoryError) as err:
                    # a file where its folder goes, a folder where one of its files goes: this
                    # pair alone fails (the pairs to come can be written), and a rerun meets it
                    # again: the output folder's failure, not its inputs', so it is recorded
                    # without them, as an unreadable image's (with them, once the obstacle was
                    # moved away, the rerun skipped the pair as failed before)
                    for key in ("options", "fingerprint"):
                        summary.pairs[job.name].pop(key, None)
                    record_failure(job, err)
                    fut.release()
                    while len(futures) < limit and submit_next():
                        pass
                    continue
                except OSError as err:
                    # the output disk full, a folder turned read-only: every pair to come would
                    # fail alike, so the run stops; it said "[Errno 28] No space left on device"
                    # alone, naming neither the pair nor the folder
                    why = err.strerror or str(err)
                    stop = OSError(
                        f"cannot write the outputs of {job.name} into {out / job.name}: {why}"
                    )
                    stop.errno = err.errno
                    raise stop from err
                entry = summary.pairs[job.name]
                entry.update(
                    status="done",
                    outputs=sorted(res["files"]),
                    max_disparity=res["max_disparity"],
                    density=round(res["density"], 4),
                    points=res["points"],
                    seconds=round(res["seconds"], 3),
                    worker=res["worker"],
                    finished=_now(),
                    this_run="processed",
                )
                entry.pop("error", None)
                # what `stereovision depth` warns of for these images (12-bit data in 16 bits),
                # said with the pair's name, not by the worker that ran it
                said = [_warning_line(text, words, job) for text in res.get("warnings") or []]
                if said:
                    entry["warnings"] = said
                processed.append(job.name)
                run["processed"] = len(processed)
                summary.record()
                bar.update()
                if log is not None:
                    for line in said:
                        log(f"{escaped(job.name)}: warning: {line}")
            fut.release()
            while len(futures) < limit and submit_next():
                pass
    except BaseException:
        bar.close()
        dask.close(list(futures))
        # what record() held back; on the disk that is full this fails too, and its bare
        # "[Errno 28] No space left on device" took the place of the error naming the pair
        # (run_batch writes the summary again, and says when it cannot)
        with contextlib.suppress(OSError):
            summary.flush()
        raise
    bar.close()
    dask.close(list(futures))
    summary.flush()  # what record() held back


# ---------------------------------------------------------------------------------------- CLI


def _check_scheduler_address(address: str) -> None:
    """Refuse ``--scheduler``'s address as Dask would (no port, an unknown scheme), before any
    work: a run whose pairs were all done before never reached Dask, and took any value.

    Raises
    ------
    ValueError
        Dask's reason after ``--scheduler:``, a password in the address said as ``***``.
    """
    try:
        from distributed.comm.addressing import parse_address
        from distributed.comm.registry import get_backend
    except ImportError:  # run_batch names the extra to install once it needs Dask
        return
    from stereovision.capture import _mask_secrets_of, mask_url_secrets

    try:
        scheme, location = parse_address(address)
        try:
            get_backend(scheme).get_address_host_port(location)
        except NotImplementedError:
            # ucx://, inproc://: their backends read no host and port before they connect
            # (Dask's get_address_host_port refused them: "don't know how to extract...")
            pass
    except ValueError as exc:
        reason = _mask_secrets_of(str(exc), address)
        # Dask reads an address without a scheme as tcp://, and names a piece of it its own way
        # ("invalid literal for int() with base 10: 's3cret@h'" for tcp://admin:s3cret@h), which
        # the masking does not recognise: an address holding a secret is said masked, whole
        url = address if "://" in address else f"tcp://{address}"
        if mask_url_secrets(url) != url:
            reason = (
                f"invalid address {mask_url_secrets(url).split('://', 1)[-1]!r}: a scheduler's "
                "address is [scheme://]host:port, with no user, password or query"
            )
        raise ValueError(f"--scheduler: {reason}") from None


def cmd_batch(args: argparse.Namespace) -> int:
    """``stereovision batch INPUT -o OUT``: exit status 0, 1 when a pair has no outputs, 130 when
    interrupted (Ctrl-C), 143 when terminated (SIGTERM): one line, the summary marked as
    interrupted."""
    from stereovision._interrupt import Terminated
    from stereovision._validate import escaped
    from stereovision.cli import EXIT_INTERRUPTED, EXIT_TERMINATED

    # in the option's name, as --count and --max-pairs are (run_batch names its parameter)
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers: expected a whole number above 0, got {args.workers}")
    if args.workers is not None and args.scheduler is not None:
        # run_batch ignores workers with a scheduler: --workers 8 ran on the cluster's own
        # workers without a word
        raise ValueError(
            "--workers sizes the local cluster; --scheduler's workers are the cluster's own: "
            "give one of them"
        )
    # as depth says them: run_batch's words were its parameters' ("it needs ground=True")
    if args.grid is not None and not args.ground:
        raise ValueError("--grid needs --ground (the grid lies on the floor)")
    if args.grid is not None and not (math.isfinite(args.grid) and 0.01 <= args.grid <= 10):
        raise ValueError(f"--grid: expected a cell side from 0.01 to 10 m, got {args.grid}")

    def log(line: str) -> None:
        from tqdm import tqdm

        from stereovision._validate import advice_for

        # the CLI's words, as its own error line (a pair's error already is: words="cli")
        tqdm.write(advice_for(line, "cli"), file=sys.stderr)

    # SIGTERM (a service manager, `kill`) stops the run as Ctrl-C does, unless the caller
    # already handles it (the CLI may turn it into a KeyboardInterrupt itself).
    term = None
    if threading.current_thread() is threading.main_thread():
        if signal.getsignal(signal.SIGTERM) in (signal.SIG_DFL, None):
            term = signal.signal(signal.SIGTERM, raise_terminated)
    from stereovision.io import check_output_folder

    if args.calib_unit is not None or (args.calib is not None and Path(args.calib).exists()):
        # refused in the CLI's words (--calib-unit), before a cluster starts; one that holds
        # no image size (OpenCV stereo_calib output) is read at the first pair's size by
        # run_batch's search of the input, in these words too (words="cli"): searched here
        # first to size it, the input was searched twice
        if not (args.calib is not None and _sizeless(Path(args.calib))):
            _cli_calibration(args.calib, args.calib_unit)
    if args.scheduler is not None:
        _check_scheduler_address(args.scheduler)
    check_output_folder(args.output, "-o")
    try:
        res = run_batch(
            args.input,
            args.output,
            workers=args.workers,
            scheduler=args.scheduler,
            method=args.method,
            max_disparity=args.max_disparity,
            fill=args.fill,
            calib=args.calib,
            calib_unit=args.calib_unit,
            retry_failed=args.retry_failed,
            ground=args.ground,
            grid=args.grid,
            log=log,
            words="cli",  # summary.json's errors as the command line's user gives things
        )
    except KeyboardInterrupt as exc:
        terminated = isinstance(exc, Terminated) or isinstance(exc.__cause__, Terminated)
        what = "terminated (SIGTERM)" if terminated else "interrupted"
        if isinstance(exc, BatchInterrupted):
            r = exc.result
            done = len(r.processed) + len(r.failed)
            print(
                f"stereovision: {what}: {done} of {done + len(r.pending)} pairs finished "
                f"this run, in {escaped(str(args.output))} and recorded in "
                f"{escaped(str(r.summary_path))}; run again to continue",
                file=sys.stderr,
            )
        else:  # while the input was searched, or a second Ctrl-C
            print(
                f"stereovision: {what}; finished pairs are kept in {escaped(str(args.output))}, "
                "run again to continue",
                file=sys.stderr,
            )
        return EXIT_TERMINATED if terminated else EXIT_INTERRUPTED
    finally:
        if term is not None:
            signal.signal(signal.SIGTERM, term)
    again = (
        f", {len(res.failed_before)} skipped (failed before; --retry-failed redoes them)"
        if res.failed_before
        else ""
    )
    alone = f" ({len(res.unpaired)} with an image missing)" if res.unpaired else ""
    # a folder named with a newline cut these lines in two (escaped, as errors name it)
    print(
        f"{len(res.processed)} processed, {len(res.skipped)} skipped (done before){again}, "
        f"{len(res.failed)} failed{alone} in {res.seconds:.1f} s; summary: "
        f"{escaped(str(res.summary_path))}"
    )
    if res.failed_before and not res.failed:
        # the exit status counts every pair without outputs, this run's failures or earlier ones
        print(f"exit status 1: {len(res.failed_before)} pair(s) still without outputs")
    if res.missing:
        print(
            f"exit status 1: {len(res.missing)} pair(s) recorded as done have no outputs in "
            f"{escaped(str(args.output))} any more (moved or deleted during the run?); run "
            "again to redo them"
        )
    return 1 if res.failed or res.failed_before or res.missing else 0


def add_cli(subparsers: Any) -> None:
    """Register ``stereovision batch`` on the CLI's sub-parsers."""
    # cli builds its parser
    from stereovision.cli import (
        _METHOD_HELP,
        CALIB_FILES_HELP,
        add_calib_unit,
        cell_metres,
        positive_pixels,
    )
    from stereovision.depth import METHODS

    p = subparsers.add_parser(
        "batch",
        help="depth outputs of every pair under a folder, on Dask (local or a cluster)",
        description="Process every pair under INPUT into OUT/<name>/ (the files `stereovision "
        "depth` writes): scene folders (left.png + right.png, or im0.png + im1.png as "
        "Middlebury and ETH3D ship them, with calib.txt or Q.dat), image "
        "files named ...left.../...right... (seq/0001_left.png + seq/0001_right.png -> seq/0001), "
        "and images of the same name in sibling camera folders: left/ + right/, L/ + R/, KITTI's "
        "image_2/ + image_3/ (image_0/ + image_1/; a raw drive's image_02/ + image_03/, "
        "image_00/ + image_01/), EuRoC's cam0/ + cam1/, TartanAir's image_left/ + "
        "image_right/ (seq/left/0001.png + "
        "seq/right/0001.png -> seq/0001; mav0/cam0/data/1.png -> mav0/data/1). An image "
        "without the other of its pair is a failed pair. Pairs are recorded in OUT/summary.json; a "
        "re-run skips finished pairs. Exit status 1 when a pair failed (its error is in the "
        "summary), 2 on errors, 130 when interrupted (Ctrl-C), 143 when terminated (SIGTERM).",
    )
    p.add_argument(
        "input", help="folder with scene folders, left/right image pairs or camera folders"
    )
    p.add_argument("-o", "--output", required=True, help="output folder")
    p.add_argument(
        "--workers",
        type=int,
        help="LocalCluster worker processes (default: cores; at most one per pair)",
    )
    p.add_argument("--scheduler", metavar="ADDRESS", help="existing Dask scheduler, tcp://...")
    p.add_argument("--method", choices=METHODS, help=_METHOD_HELP)
    p.add_argument(
        "--max-disparity",
        type=positive_pixels,
        metavar="N",
        help="disparity range to search, in pixels, for every pair (default: estimated per pair)",
    )
    p.add_argument(
        "--calib",
        help=f"calibration for every pair: {CALIB_FILES_HELP} (default: each scene's calib.txt "
        "or Q.dat)",
    )
    add_calib_unit(p)
    # one or the other: both given, the last silently won
    fill = p.add_mutually_exclusive_group()
    fill.add_argument(
        "--fill", action="store_const", const=True, help="fill holes (default: the method's)"
    )
    fill.add_argument(
        "--no-fill", dest="fill", action="store_const", const=False, help="leave holes NaN"
    )
    p.add_argument(
        "--retry-failed", action="store_true", help="redo pairs that failed on unchanged inputs"
    )
    p.add_argument(
        "--ground",
        action="store_true",
        help="also each pair's floor and obstacles (ground.json, obstacles.png, scan.json)",
    )
    p.add_argument(
        "--grid",
        type=cell_metres,
        metavar="M",
        help="with --ground: an occupancy grid of M-metre cells",
    )
    p.set_defaults(func=cmd_batch)
