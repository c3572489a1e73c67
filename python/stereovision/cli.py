"""Command line: ``stereovision COMMAND`` (demo, depth, check, info, eval, capture, stream, ...).

Errors print one line on stderr and exit with status 2 (never a traceback); every output file is
written atomically after all computation succeeded, so an error never destroys earlier outputs.
"""

from __future__ import annotations

import argparse
import ast
import contextlib
import difflib
import functools
import json
import math
import os
import re
import shlex
import signal
import sys
import threading
import time
import warnings
from collections.abc import Callable, Collection, Iterable, Iterator, Sequence
from importlib import resources
from pathlib import Path
from typing import Any, NoReturn

import cv2
import numpy as np

from stereovision._interrupt import HeldInterrupts, Terminated, raise_terminated
from stereovision._jsonout import json_line
from stereovision._validate import (
    BUG_ERRORS,
    advice_for,
    escape_paths,
    escaped,
    figure_shown,
    first_line,
    float32_reach,
    internal_error,
)

EXIT_ERROR = 2
EXIT_CANNOT_TELL = 3  # `check`: too little texture (or one image twice) to tell the rows
EXIT_INTERRUPTED = 130
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, what a shell reports for `yes | head`
EXIT_TERMINATED = 143  # 128 + SIGTERM


class CliError(Exception):
    """A user-facing error: printed as one line, exit status 2."""


# ----------------------------------------------------------------------------- output helpers


def _refuse_an_input(flag: str, output: Path, inputs: dict[str, str | None]) -> None:
    """:func:`stereovision.io.refuse_an_input`, its refusal a :class:`CliError`."""
    from stereovision.io import refuse_an_input

    try:
        refuse_an_input(flag, output, inputs)
    except ValueError as exc:
        raise CliError(str(exc)) from None


def _atomic_write_bytes(path: Path, data: bytes) -> None:
    from stereovision.io import atomic_write, make_folder

    make_folder(path.parent)
    with atomic_write(path, "wb") as fh:
        fh.write(data)


def colorize(values: np.ndarray, *, lo: float | None = None, hi: float | None = None) -> np.ndarray:
    """Colour-map a float map (TURBO, NaN black) robustly scaled to its 1st-99th percentiles.

    Parameters
    ----------
    values : ndarray, float (H, W)
    lo, hi : float, optional
        Value range mapped to the ends of the colour map (default: 1st and 99th percentiles).

    Returns
    -------
    ndarray, uint8 (H, W, 3)
        BGR image.
    """
    from stereovision.overview import colour_levels, colour_range

    ends = colour_range(values, lo, hi)  # overview.png's colour bars use the same ends
    if ends is None:
        return np.zeros((*values.shape, 3), np.uint8)
    out = cv2.applyColorMap(colour_levels(values, *ends), cv2.COLORMAP_TURBO)
    out[~np.isfinite(values)] = 0
    return out


def _png_bytes(img: np.ndarray) -> bytes:
    ok, buf = cv2.imencode(".png", img)
    if not ok:
        raise CliError("could not encode a PNG image")
    return buf.tobytes()


def _npy_bytes(arr: np.ndarray) -> bytes:
    import io as _io

    bio = _io.BytesIO()
    np.save(bio, arr)
    return bio.getvalue()


def write_depth_outputs(
    result: Any,
    out_dir: Path,
    voxel: float | None = None,
    *,
    counts: dict[str, int] | None = None,
) -> dict[str, Path]:
    """Write disparity.png, disparity.pfm, depth.png, depth.npy, depth_mm.png (16-bit,
    millimetres) and cloud.ply (one point per ``voxel`` cube when given) into ``out_dir``.

    Everything is encoded in memory first, then each file is replaced atomically. When
    ``counts`` is given, ``counts["cloud.ply"]`` is set to the number of points written there
    (``depth --voxel`` reports it without reading the file back).
    """
    from stereovision.io import make_folder, write_pfm, write_ply

    files: dict[str, bytes] = {"disparity.png": _png_bytes(colorize(result.disparity, lo=0.0))}
    if result.depth is not None:
        # Near = warm: colour the inverse depth so the map reads like the disparity.
        inv = np.where(np.isfinite(result.depth), 1.0 / result.depth, np.nan)
        files["depth.png"] = _png_bytes(colorize(inv))
        files["depth.npy"] = _npy_bytes(result.depth.astype(np.float32))
        from stereovision.export import encode_depth_png

        files["depth_mm.png"] = encode_depth_png(result.depth)
    make_folder(out_dir)
    written: dict[str, Path] = {}
    for name, data in files.items():
        _atomic_write_bytes(out_dir / name, data)
        written[name] = out_dir / name
    written["disparity.pfm"] = Path(write_pfm(out_dir / "disparity.pfm", result.disparity))
    if result.depth is not None:
        points, colors = result.points, result.colors
        if voxel is not None:
            from stereovision.export import voxel_downsample

            points, colors = voxel_downsample(points, colors, voxel)
        written["cloud.ply"] = Path(write_ply(out_dir / "cloud.ply", points, colors))
        if counts is not None:
            counts["cloud.ply"] = len(points)
    return written


def write_overview(result: Any, out_dir: Path, name: str, unit: str = "m") -> dict[str, Path]:
    """Write ``overview.png`` into ``out_dir``: the left image, the disparity, the depth (with
    a calibration) and the confidence, downscaled side by side, each map with a labelled colour
    bar (:func:`stereovision.overview.overview_image`; the depth bar labelled in ``unit``),
    under a title naming the pair (``name``), the method, the range searched and the density.

    Returns
    -------
    dict
        ``{"overview.png": path}``.
    """
    from stereovision.overview import overview_image, overview_title

    picture = overview_image(result, overview_title(name, result), unit)
    path = out_dir / "overview.png"
    _atomic_write_bytes(path, _png_bytes(picture.image))
    return {"overview.png": path}


# ----------------------------------------------------------------------------- commands


#: ``--calib-unit``'s help, the same on every command that loads a calibration.
CALIB_UNIT_HELP = (
    "length unit of the calibration's T (baseline) when the file does not state it: OpenCV "
    "stereo_calib's intrinsics.yml + extrinsics.yml (the unit of the board's square size; "
    "needed), an OpenCV YAML/XML or JSON file without a unit field (needed) or a Q.dat "
    "(default m). A file that states its unit (YAML/JSON, calib.txt, KITTI, ROS, Kalibr) is "
    "refused when it disagrees"
)


#: What ``--calib`` reads (:meth:`Calibration.from_file` for every command: depth, stream,
#: batch, gui), one text so that no command's help lists fewer formats than another's.
CALIB_FILES_HELP = (
    "OpenCV YAML/XML or JSON calibration, Middlebury calib.txt, KITTI calib, Kalibr camchain, "
    "a ROS camera_info folder (left.yaml, right.yaml) or calibrationdata.tar.gz, OpenCV "
    "stereo_calib output (intrinsics.yml + extrinsics.yml, with --calib-unit), a Q.dat or a "
    "scene folder (its calib.txt or Q.dat)"
)


def add_calib_unit(parser: argparse.ArgumentParser) -> None:
    """Add ``--calib-unit`` (the unit of a ``--calib`` file that does not state it) to a
    command that loads a calibration; :func:`load_calibration` reads it."""
    from stereovision.calibration import UNIT_TO_METRES

    parser.add_argument("--calib-unit", choices=list(UNIT_TO_METRES), help=CALIB_UNIT_HELP)


#: Where rectify's homographies go, for the commands without --rectification that refuse them
#: as --calib (info, rectify, batch, gui).
_HOMOGRAPHIES_USE = (
    "`stereovision depth LEFT RIGHT --rectification FILE` rectifies a raw pair with them"
)


def load_calibration(
    path: str | os.PathLike[str] | None,
    unit: str | None = None,
    pair: np.ndarray | None = None,
    size: tuple[int, int] | None = None,
    size_words: str | None = None,
    homographies: str | None = None,
) -> Any:
    """A command's calibration, its refusals in the CLI's words.

    Parameters
    ----------
    path : str or os.PathLike or None
        The calibration (``--calib``); None gives None.
    unit : str, optional
        ``--calib-unit``: the unit of a file that does not state its own (OpenCV
        ``stereo_calib`` output, ``Q.dat``); checked against a file that does.
    pair : numpy.ndarray, optional
        The run's left image: it sizes a calibration that holds no image size (a ``Q.dat``
        with no ``left.png`` beside it, ``stereo_calib`` output), the images it is given with.
    size : tuple of int, optional
        ``(width, height)`` the user gave (``info --size``): passed on as ``image_size``.
    size_words : str, optional
        How the command's user gives an image size, for the refusal of a calibration that
        holds none when there is no ``pair`` (default: the Python call that converts it).
    homographies : str, optional
        What to do with ``rectify``'s ``rectification.json`` given as ``--calib`` in a command
        that has no ``--rectification`` (default: give it as ``--rectification``).

    Returns
    -------
    Calibration or None
        The calibration.

    Raises
    ------
    ValueError
        As :meth:`~stereovision.calibration.Calibration.from_file`, said with
        ``--calib-unit`` for ``unit``; ``unit`` without ``path``.
    """
    if path is None:
        if unit is not None:
            raise ValueError("--calib-unit is the unit of --calib's file: give --calib too")
        return None
    from stereovision.calibration import Calibration, _sizeless

    if size is None and pair is not None and _sizeless(path):
        size = (pair.shape[1], pair.shape[0])
    try:
        return Calibration.from_file(path, image_size=size, unit=unit)
    except ValueError as exc:
        text = str(exc)
        text = text.replace("unit='m'/'mm'/...", "--calib-unit (m, mm, cm, ft or in)")
        text = re.sub(r"the unit '(\w+)' given", r"--calib-unit \1", text)
        text = text.replace("leave unit out", "leave --calib-unit out")
        if homographies is not None:  # "give it as --rectification", an option it has not
            text = re.sub(r": give it as --rectification .*", f": {homographies}", text)
        if "lacks field 'unit'" in text:  # a YAML/JSON without it: the option says it too
            text += " (or give --calib-unit)"
        how = size_words or (
            "the image size: this command cannot read it from its images, so save the rig once "
            "in Python with Calibration.from_file(path, image_size=(width, height), "
            "unit=...).save('rig.yaml') and give rig.yaml"
        )
        text = text.replace("image_size=(width, height)", how)
        if size is not None:  # info --size for a calibration that states another size
            text = re.sub(
                r"the image_size \((\d+), (\d+)\) given: leave image_size out, .*",
                r"--size \1x\2: leave --size out (it sizes a calibration that holds no size)",
                text,
            )
        raise ValueError(text) from None


def _check_pair(left: np.ndarray, right: np.ndarray, calib: Any, max_disparity: Any) -> None:
    """What :func:`stereovision.depth.depth_map` refuses of the pair before any work, in its
    words, checked before :func:`refuse_foreign_outputs` speaks of a file in the ``-o`` folder:
    images of two sizes, a calibration for another size, a ``max_disparity`` not below the
    width, or a pair too narrow for the automatic range (16 px wide or less)."""
    from stereovision.depth import (
        _DISPARITY_STEP,
        _range_too_wide,
        _rig_to_warp_by,
        _too_narrow,
    )
    from stereovision.rectification_check import _two_sizes

    (h, w), (hr, wr) = np.shape(left)[:2], np.shape(right)[:2]
    if (h, w) != (hr, wr):
        # width x height, as check and rectify say it: NumPy's (375, 450, 3) read as 375 wide
        raise ValueError(_two_sizes(w, h, wr, hr))
    _rig_to_warp_by(calib, w, h, max_disparity)  # a calibration for another image size
    if max_disparity is not None and max_disparity >= w:
        raise _range_too_wide(max_disparity, w)
    if max_disparity is None and w <= _DISPARITY_STEP:  # the automatic range is 16 px there
        raise _too_narrow(w, _DISPARITY_STEP)


def depth_outputs(
    left: np.ndarray,
    right: np.ndarray,
    calib: Any,
    out_dir: Path,
    *,
    method: str | None = None,
    max_disparity: int | None = None,
    fill: bool | None = None,
    refine: bool | None = None,
    max_depth: float | None = None,
    max_sigma: float | None = None,
    voxel: float | None = None,
    ground: bool = False,
    grid: float | None = None,
    log: Any = None,
    counts: dict[str, int] | None = None,
    name: str = "pair",
    unit: str = "m",
    removed: list[Path] | None = None,
    unfiltered: list[Any] | None = None,
) -> tuple[Any, dict[str, Path]]:
    """What ``stereovision depth`` computes and writes for one pair (``batch`` writes the same).

    Parameters
    ----------
    left, right : ndarray
        The pair as read (BGR ``uint8``); raw when ``calib`` is an unrectified rig calibration.
    calib : Calibration or None
        Without it only the disparity outputs are written.
    out_dir : pathlib.Path
        Output folder (created if missing). The run's files are written into a hidden folder
        inside it (:func:`staged_outputs`) and moved in together at the end, the earlier run's
        files this run did not write then removed (:func:`commit_outputs`): an error or an
        interrupt before that leaves the earlier run's files as they were. A file there under
        one of the output names that :data:`DEPTH_MANIFEST` does not list (not an earlier run's)
        is refused before the matching (:func:`refuse_foreign_outputs`).
    method : str, optional
        Matcher; None = :func:`stereovision.depth.depth_map`'s default.
    max_disparity : int, optional
        None = estimated from the pair.
    fill : bool, optional
        Fill the holes (:func:`depth_map`'s ``fill``); None = the method's default.
    refine : bool, optional
        Sub-pixel refinement; None = the method's default (:func:`depth_map`).
    max_depth, max_sigma : float, optional
        Keep only depths up to ``max_depth`` metres with a one-sigma uncertainty up to
        ``max_sigma`` metres in the depth outputs and the cloud (:meth:`DepthResult.filtered`).
    voxel : float, optional
        Write the cloud with one point per cube of this side in metres
        (:func:`stereovision.export.voxel_downsample`).
    ground : bool
        Also fit the floor and write ``ground.json`` and ``obstacles.png`` (needs ``calib``).
    grid : float, optional
        With ``ground``: a bird's-eye occupancy grid of this cell side (``map.png``,
        ``map.yaml``).
    log : callable, optional
        Receives the floor's one-line description.
    counts : dict, optional
        Receives ``"cloud.ply"``: the number of points written there
        (:func:`write_depth_outputs`).
    name : str
        The pair's name in ``overview.png``'s title (:func:`write_overview`).
    unit : str
        The unit of ``overview.png``'s depth bar and of the lengths ``log`` receives (a key of
        :data:`stereovision.calibration.UNIT_TO_METRES`); the files' own units do not change
        (``depth.npy`` and the cloud in metres, ``depth_mm.png`` in millimetres), nor do the
        options' (``max_depth``, ``max_sigma``, ``voxel``, ``grid``: metres).
    removed : list, optional
        Receives the earlier run's files that were removed, not rewritten by this run.
    unfiltered : list, optional
        Receives the result as matched, before ``max_depth`` and ``max_sigma`` (when given):
        the summary names its nearest depth when ``max_depth`` leaves none.

    Returns
    -------
    tuple
        ``(DepthResult, {file name: path})``.
    """
    from stereovision.depth import depth_map
    from stereovision.io import check_output_folder
    from stereovision.render import render_outputs

    check_output_folder(out_dir, "-o")  # before the matching, not after it
    from stereovision.calibration import UNIT_TO_METRES

    if unit not in UNIT_TO_METRES:
        raise CliError(f"--unit: expected one of {', '.join(UNIT_TO_METRES)}, got {unit!r}")
    # Every usage error that needs no work first, then a file of the user's under an output
    # name, then the work: a wrong --max-depth was reported as that file, then as itself.
    given = [
        f for f, v in (("--max-depth", max_depth), ("--max-sigma", max_sigma)) if v is not None
    ]
    if calib is None and given:  # the ones given: --max-sigma alone was told of --max-depth too
        need = "needs" if len(given) == 1 else "need"
        raise CliError(f"{' and '.join(given)} {need} --calib (no depth without one)")
    if ground and calib is None:
        raise CliError("--ground needs --calib (the floor is found in metres)")
    if grid is not None and not ground:
        raise CliError("--grid needs --ground (the grid lies on the floor)")
    lo, hi = GRID_CELL_M
    if grid is not None and not (math.isfinite(grid) and lo <= grid <= hi):
        raise CliError(f"--grid: expected a cell side from {lo:g} to {hi:g} m, got {grid}")
    from stereovision._validate import positive_finite

    for value, flag in ((max_depth, "--max-depth"), (max_sigma, "--max-sigma"), (voxel, "--voxel")):
        if value is not None:
            positive_finite(value, flag)
    _check_pair(left, right, calib, max_disparity)
    names = planned_depth_outputs(calib is not None, ground, grid is not None)
    earlier = refuse_foreign_outputs(out_dir, names)  # before the matching, too
    # an earlier run's file, listed, replaced by a folder: found only once all was written
    refuse_folders_under(out_dir, names)
    kw: dict[str, Any] = {} if method is None else {"method": method}
    res = depth_map(left, right, calib, max_disparity=max_disparity, fill=fill, refine=refine, **kw)
    if max_depth is not None or max_sigma is not None:
        if unfiltered is not None:
            unfiltered.append(res)
        res = res.filtered(max_depth=max_depth, max_sigma=max_sigma)
    # Every file is written into a hidden folder inside out_dir first and moved in only when
    # all are there: an error or interrupt in a later writer left the new disparity files
    # beside the earlier run's overview.png, depth.npy and cloud.ply, without a word.
    with staged_outputs(out_dir) as stage:
        try:
            staged = write_depth_outputs(res, stage, voxel, counts=counts)
        except ValueError as exc:  # voxel_downsample's words: its parameter, not the option
            tiny = re.fullmatch(r"voxel: (\S+) is too small for points reaching (\S+)", str(exc))
            if tiny is None:
                raise
            raise CliError(
                f"--voxel: {tiny[1]} m is too small for points reaching {tiny[2]} m"
            ) from None
        staged.update(render_outputs(res, stage))
        staged.update(write_overview(res, stage, name, unit))
        if ground:
            staged.update(_ground_outputs(res, calib, stage, grid, log, unit))
        written, gone = commit_outputs(out_dir, staged, earlier)
    if removed is not None:
        removed.extend(gone)
    return res, written


#: Every file ``stereovision depth`` may write into its ``-o`` folder.
DEPTH_OUTPUTS = (
    "disparity.png",
    "disparity.pfm",
    "depth.png",
    "depth.npy",
    "depth_mm.png",
    "cloud.ply",
    "render.png",
    "overview.png",
    "ground.json",
    "obstacles.png",
    "scan.json",
    "map.png",
    "map.yaml",
)


#: What ``stereovision depth`` (or ``demo``) wrote into its ``-o`` folder on its last run there
#: (JSON list of file names): the only files a later run replaces or removes. It is written
#: before a run's first output (its earlier files and the ones it may write) and again at the end
#: (what it wrote).
DEPTH_MANIFEST = ".stereovision-depth.json"


def planned_depth_outputs(calib: bool, ground: bool = False, grid: bool = False) -> tuple[str, ...]:
    """The files ``stereovision depth`` (or ``demo``) may write into its ``-o`` folder.

    Parameters
    ----------
    calib : bool
        Whether the run has a calibration (depth maps, cloud and render).
    ground, grid : bool
        ``--ground`` given (floor, obstacles, scan); ``--grid`` given (occupancy grid).

    Returns
    -------
    tuple of str
        File names, a subset of :data:`DEPTH_OUTPUTS` in its order.
    """
    names = {"disparity.png", "disparity.pfm", "overview.png"}
    if calib:
        names |= {"depth.png", "depth.npy", "depth_mm.png", "cloud.ply", "render.png"}
    if ground:
        names |= {"ground.json", "obstacles.png", "scan.json"}
    if grid:
        names |= {"map.png", "map.yaml"}
    return tuple(n for n in DEPTH_OUTPUTS if n in names)


def _manifest_names(out_dir: Path, manifest: str = DEPTH_MANIFEST) -> set[str]:
    """The file names the manifest (:data:`DEPTH_MANIFEST`, or ``rectify``'s
    :data:`RECTIFY_MANIFEST`) in ``out_dir`` lists (none when missing or unreadable)."""
    try:
        earlier = json.loads((out_dir / manifest).read_text(encoding="utf-8"))
    except (OSError, ValueError):  # none (a folder this command never wrote), or unreadable
        return set()
    if not isinstance(earlier, list):
        return set()
    return {n for n in earlier if isinstance(n, str)}


def refuse_foreign_outputs(
    out_dir: Path, names: Sequence[str], manifest: str = DEPTH_MANIFEST, flag: str = "-o"
) -> set[str]:
    """Refuse, before any work, to replace a file of ``out_dir`` that this tool did not write.

    A file (or anything else, a folder) under one of ``names`` in ``out_dir`` is this tool's
    only when ``manifest`` there lists it: an earlier run of the command into the folder wrote
    it, and a rerun replaces it. Any other, e.g. the user's own ``cloud.ply`` in a folder given
    as ``-o``, would be replaced silently; so would a link, listed or not (runs write files).

    Parameters
    ----------
    out_dir : pathlib.Path
        The ``-o`` folder (it need not exist).
    names : sequence of str
        The files this run may write (:func:`planned_depth_outputs`).
    manifest : str
        The manifest's file name: :data:`DEPTH_MANIFEST` (``depth``, ``demo``) or
        :data:`RECTIFY_MANIFEST` (or ``calibrate``'s, in its ``--ros`` and ``--report``
        folders).
    flag : str
        How the user gave the folder, for the message.

    Returns
    -------
    set of str
        What the manifest lists (the earlier runs' files).

    Raises
    ------
    FileExistsError
        Naming the first such file, and what to do.
    """
    earlier = _manifest_names(out_dir, manifest)
    foreign = foreign_outputs(out_dir, names, earlier)
    if foreign:
        raise FileExistsError(
            f"{flag} {out_dir}: {foreign[0]} {not_ours(foreign[0], earlier)} and would be "
            f"replaced: give another {flag} folder, or move or remove that file"
        )
    return earlier


def foreign_outputs(out_dir: Path, names: Sequence[str], listed: Collection[str]) -> list[Path]:
    """What stands in ``out_dir`` under one of ``names`` (a file, a folder, a link, a broken
    one too) that ``listed`` (an earlier run's recorded outputs) does not name, in the order of
    ``names``: what a run would replace that it did not write. A link is never a run's output
    (runs write files), so one under a listed name is the user's too: moved over, it was lost
    unsaid; written through (``io.atomic_write``, ``calibrate --report``), its target was."""
    return [
        out_dir / n
        for n in names
        if (n not in listed and (out_dir / n).exists()) or (out_dir / n).is_symlink()
    ]


def not_ours(path: Path, listed: Collection[str]) -> str:
    """Why :func:`foreign_outputs` named ``path``, for the line refusing to replace it."""
    if path.name in listed:  # only a link
        return "is a link, not the file an earlier run wrote there,"
    return "is not listed as an earlier run's output there"


def record_outputs(
    out_dir: Path,
    names: set[str],
    manifest: str = DEPTH_MANIFEST,
    known: Sequence[str] = DEPTH_OUTPUTS,
) -> None:
    """Write the manifest (:data:`DEPTH_MANIFEST` by default) in ``out_dir`` (created if
    missing): ``names`` are this tool's files there (those of them in ``known``, the command's
    output names)."""
    from stereovision.io import atomic_write, make_folder

    make_folder(out_dir)
    with atomic_write(out_dir / manifest, "w") as fh:
        json.dump(sorted(n for n in names if n in known), fh)


#: The hidden folder a run writes its files into, inside its ``-o`` folder (the same file
#: system, so that each file moves in atomically), followed by a random suffix.
STAGING_PREFIX = ".stereovision-partial-"


@contextlib.contextmanager
def staged_outputs(out_dir: Path) -> Iterator[Path]:
    """A hidden temporary folder inside ``out_dir`` (created if missing) to write a run's files
    into before :func:`commit_outputs` moves them in.

    The folder is removed when the block ends, however it ends (an error, Ctrl-C, SIGTERM as
    the CLI raises it); ``out_dir`` and the folders above it that the block created too, when
    it fails with them empty (:func:`stereovision.io.missing_folders`). Such a folder of a run
    killed outright (SIGKILL) that no running process holds is removed.

    Parameters
    ----------
    out_dir : pathlib.Path
        The ``-o`` folder.

    Yields
    ------
    pathlib.Path
        The temporary folder (``.stereovision-partial-XXXXXXXX``).
    """
    import shutil
    import tempfile

    from stereovision.io import lock_folder, make_folder, missing_folders, remove_empty_folders

    made = missing_folders(out_dir)  # out_dir and the folders above it that it needs
    make_folder(out_dir)
    stage = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out_dir))
    held, _ = lock_folder(stage)  # held while the run lives: the next run removes it otherwise
    try:
        _remove_orphan_stages(out_dir, stage)
        yield stage
    except BaseException as exc:
        shutil.rmtree(stage, ignore_errors=True)
        # only while empty: nothing else is touched (-o new/o left new/ behind)
        remove_empty_folders(made)
        if isinstance(exc, OSError) and str(stage) in str(exc):
            # a write's error named the file in this folder, gone now ("cannot write
            # o/.stereovision-partial-wex201ov/disparity.png: No space left on device"): the
            # file is named where it goes
            failed = type(exc)(str(exc).replace(str(stage), str(out_dir)))
            failed.errno = exc.errno
            raise failed from exc
        raise
    finally:
        if held is not None:
            os.close(held)
    shutil.rmtree(stage, ignore_errors=True)


def _remove_orphan_stages(out_dir: Path, own: Path) -> None:
    """Remove the :func:`staged_outputs` folders in ``out_dir`` of runs killed outright
    (SIGKILL, power loss: no ``finally`` ran), which stayed there for good: those no running
    process holds (:func:`stereovision.io.lock_folder`). Where nothing can be locked none is
    touched."""
    import shutil

    from stereovision.io import lock_folder

    for folder in out_dir.glob(f"{STAGING_PREFIX}*"):
        if folder == own or folder.is_symlink() or not folder.is_dir():
            continue
        fd, _ = lock_folder(folder)
        if fd is None:  # a run in progress holds it (or no locks here)
            continue
        try:
            shutil.rmtree(folder, ignore_errors=True)
        finally:
            os.close(fd)


def refuse_folders_under(out_dir: Path, names: Iterable[str]) -> None:
    """Refuse a folder standing in ``out_dir`` under one of ``names``: an earlier run's file,
    listed in its manifest (so :func:`refuse_foreign_outputs` lets it be), since replaced by a
    folder. Checked before the work, and by :func:`commit_outputs` before any file moves.

    Parameters
    ----------
    out_dir : pathlib.Path
        The ``-o`` folder (it need not exist).
    names : iterable of str
        The files the run writes there.

    Raises
    ------
    IsADirectoryError
        Naming the first such folder.
    """
    for name in names:
        target = out_dir / name
        if target.is_dir() and not target.is_symlink():
            raise IsADirectoryError(
                f"{target} is a folder, where the run's {name} goes: move it away (the earlier "
                "outputs are kept as they were)"
            )


def commit_outputs(
    out_dir: Path,
    staged: dict[str, Path],
    earlier: Collection[str],
    manifest: str = DEPTH_MANIFEST,
    known: Sequence[str] = DEPTH_OUTPUTS,
    stale: Callable[[Path], bool] | None = None,
) -> tuple[dict[str, Path], list[Path]]:
    """Move a run's files from :func:`staged_outputs`'s folder into ``out_dir``, then remove
    the earlier run's files that this run did not write, and record the run's in ``manifest``.

    Each file is moved with one rename (atomic); Ctrl-C and SIGTERM are held until all are in
    and the earlier run's are gone (:class:`~stereovision._interrupt.HeldInterrupts`), so the
    folder holds one run's files, the earlier run's or this one's. A folder where a file goes
    is refused before any file moves. The manifest lists this run's files before the first
    move; a failure before any file moved in puts the earlier manifest back (or none), so that
    a folder the run made is left empty and removed (:func:`staged_outputs`). A rename that
    fails after others moved in (the folder made read-only meanwhile) leaves files of both
    runs, all listed in the manifest: a rerun replaces them.

    Parameters
    ----------
    out_dir : pathlib.Path
        The ``-o`` folder.
    staged : dict
        The run's files: name -> path in the temporary folder.
    earlier : collection of str
        The earlier run's files there (its manifest's: :func:`refuse_foreign_outputs`). Of
        those, the regular files in ``known`` that this run did not write are removed, and
        only they: a file of the user's stays.
    manifest : str
        :data:`DEPTH_MANIFEST` or :data:`RECTIFY_MANIFEST`.
    known : sequence of str
        The command's output names (:data:`DEPTH_OUTPUTS`, :data:`RECTIFY_OUTPUTS`).
    stale : callable, optional
        Whether an earlier run's file this run did not write is to go (default: each does).

    Returns
    -------
    tuple
        ``({name: path in out_dir}, [files removed])``.

    Raises
    ------
    IsADirectoryError
        A folder under one of the names; nothing is moved.
    """
    from stereovision._interrupt import HeldInterrupts

    refuse_folders_under(out_dir, staged)  # again: one may have been made during the work
    written: dict[str, Path] = {}
    removed: list[Path] = []
    listed = out_dir / manifest
    try:
        before: bytes | None = listed.read_bytes()
    except OSError:  # none yet (or unreadable: replaced below all the same)
        before = None
    with HeldInterrupts():
        # claimed before the first move: should the process die halfway, a rerun replaces them
        record_outputs(out_dir, set(earlier) | set(staged), manifest, known)
        try:
            for name, path in staged.items():
                try:
                    os.replace(path, out_dir / name)
                except OSError as exc:
                    # it named the staging folder's file, removed by then; staged_outputs's
                    # renaming of that folder made it "'o/disparity.png' -> 'o/disparity.png'"
                    failed = type(exc)(f"cannot write {out_dir / name}: {exc.strerror or exc}")
                    failed.errno = exc.errno
                    raise failed from exc
                written[name] = out_dir / name
        except BaseException:
            # a second Ctrl-C during the first rename is raised once it returns, before the
            # file counts as written: only a first file still in the staging folder moved nowhere
            first = next(iter(staged.values()), None)
            if not written and (first is None or os.path.lexists(first)):
                # nothing moved in: the earlier manifest back (or none), so that the folder is
                # as it was, and a folder the run made is empty and removed (staged_outputs)
                with contextlib.suppress(OSError):
                    if before is None:
                        listed.unlink()
                    else:
                        _atomic_write_bytes(listed, before)
            raise
        for name in known:
            path = out_dir / name
            if name in earlier and name not in written and path.is_file() and not path.is_symlink():
                if stale is None or stale(path):
                    path.unlink()
                    removed.append(path)
        record_outputs(out_dir, set(written), manifest, known)
    return written, removed


def _pair_name(left: str) -> str:
    """A pair's name for ``overview.png``'s title: its left image's folder and file name
    (``terrace/left.png``)."""
    path = Path(left)
    return f"{path.parent.name}/{path.name}" if path.parent.name else path.name


def cmd_depth(args: argparse.Namespace) -> int:
    """``stereovision depth LEFT RIGHT -o DIR``."""
    from stereovision.io import read_image

    if args.calib is None:
        # no depth without a calibration: these would be accepted and do nothing, as
        # --max-depth and --ground are refused (depth_outputs, which batch shares)
        if args.unit is not None:
            raise CliError("--unit needs --calib (no depth to say in it without one)")
        if args.voxel is not None:
            raise CliError("--voxel needs --calib (no cloud.ply without one)")
    unit = "m" if args.unit is None else args.unit
    # 16-bit files keep their 16 bits (imread's 8-bit copy kept the top 8 of them)
    left = read_image(args.left)
    right = read_image(args.right)
    if not args.rectification:  # (rectified, the pair may change size: checked below)
        # a pair depth_map refuses is said alone: a 1x1 px pair was "the same image" first
        _check_pair(left, right, None, args.max_disparity)
    same = left.shape == right.shape and np.array_equal(left, right)
    calib = load_calibration(args.calib, args.calib_unit, left)
    max_disparity = args.max_disparity
    if args.rectification:
        from stereovision.uncalibrated import UncalibratedRectification

        if calib is not None:
            raise CliError("--rectification and --calib: give one way to rectify the pair")
        rect = UncalibratedRectification.load(args.rectification)
        left, right = rect.rectify(left, right)
        width = np.shape(left)[1]
        if max_disparity is None and width >= 2 and rect.max_disparity >= width:
            # the file's range (hand-edited) was told "give a --max-disparity below N", an
            # option the user had not given: the file is named as where the value came from
            raise CliError(
                f"{args.rectification}: its max_disparity {rect.max_disparity} is not smaller "
                f"than the rectified width {width}: edit it below {width} there, or give a "
                f"--max-disparity below {width}"
            )
        max_disparity = max_disparity or rect.max_disparity
        # the pair as it is matched, refused alone (before the same-image warning below)
        _check_pair(left, right, None, max_disparity)
    elif calib is not None:  # a calibration for another image size, refused alone too
        _check_pair(left, right, calib, max_disparity)
    counts: dict[str, int] = {}
    removed: list[Path] = []
    unfiltered: list[Any] = []
    from stereovision.io import check_output_folder

    check_output_folder(args.output, "-o")  # the text: depth_outputs is given a Path
    res, written = depth_outputs(
        left,
        right,
        calib,
        Path(args.output),
        method=args.method,
        max_disparity=max_disparity,
        fill=args.fill,
        refine=args.refine,
        max_depth=args.max_depth,
        max_sigma=args.max_sigma,
        voxel=args.voxel,
        ground=args.ground,
        grid=args.grid,
        log=print,
        counts=counts,
        name=_pair_name(args.left),
        unit=unit,
        removed=removed,
        unfiltered=unfiltered,
    )
    if same:  # said of the result: a blank frame twice has no disparity at all, not 0 everywhere
        found = "every disparity comes out 0" if res.density > 0 else "no disparity comes out"
        warnings.warn(
            f"{args.left} and {args.right} are the same image: {found} "
            "(two views of the scene are needed)",
            stacklevel=1,
        )
    cloud = (
        f"{_depth_range(res.depth, unit)}, {len(res.points)} points"
        if res.depth is not None
        else "disparity only (no depth or cloud without --calib)"
    )
    if res.depth is not None and args.max_depth is not None and unfiltered:
        # "no depth, 0 points" did not say that --max-depth took it all, nor how far to go
        beyond = _beyond_max_depth(res.depth, unfiltered[0].depth, args.max_depth)
        if beyond is not None:
            cloud = f"{beyond}, {len(res.points)} points"
    if res.depth is not None and args.max_sigma is not None and unfiltered:
        # the outputs held no depth and nothing said that --max-sigma took it, nor what keeps some
        tight = _below_max_sigma(res.depth, unfiltered[0], args.max_sigma, args.max_depth)
        if tight is not None:
            warnings.warn(tight, stacklevel=1)
    for flag, value, of in (
        ("--max-depth", args.max_depth, "depth"),
        ("--max-sigma", args.max_sigma, "depth_sigma"),
    ):
        if value is not None and unfiltered:
            # --unit mm --max-depth 3000 kept every depth (3000 m): the limits stay in metres
            odd = _limit_not_in_unit(flag, value, unit, getattr(unfiltered[0], of))
            if odd is not None:
                warnings.warn(odd, stacklevel=1)
    if args.voxel is not None and "cloud.ply" in written:
        # the cloud.ply of --voxel holds fewer points than the result: "N points" read as its
        # (the count comes from the writer: the file was read back whole to count its points)
        cloud += f" ({counts['cloud.ply']} in cloud.ply, one per {args.voxel:g} m cube)"
    print(
        f"{args.method}: max_disparity {res.max_disparity} px, density {100 * res.density:.1f} %,"
        f" {cloud}, {sum(res.timings.values()):.2f} s"
    )
    if res.depth is not None:
        print(f"  {_depth_coverage(res)}")
    for name, path in written.items():
        # a folder named with a newline cut the line in two (escaped, as errors name it)
        print(f"  {name:14s} {escaped(str(path))}")
    for path in removed:
        print(f"  removed {path.name} of an earlier run (not written by this one)")
    return 0


def _depth_coverage(res: Any) -> str:
    """Where the depth is and why the other pixels with a disparity have none (counts).

    ``depth on 83.8 % of the pixels (disparity on 100.0 %): none on 27278 filled (16.2 %,
    guesses, not measured) nor on 0 measured (0.0 %) within sigma_d of infinite depth``: the depth
    map's holes where the disparity map has none, said with their reason. A reason with no
    pixel is left out (it read "none on 0 filled (0.0 %, ...) nor on 0 measured (0.0 %)"), and
    with neither the line says every pixel with a disparity has a depth; with no disparity at
    all, that none has one.
    """
    c = res.depth_counts()

    def pct(key: str) -> str:
        return f"{100 * c[key] / max(c['pixels'], 1):.1f} %"

    why = "outside the limits or within" if res.limits else "within"
    head = f"depth on {pct('depth')} of the pixels (disparity on {pct('disparity')})"
    parts = []
    if c["filled"]:
        parts.append(f"{c['filled']} filled ({pct('filled')}, guesses, not measured)")
    if c["dropped"]:
        parts.append(f"{c['dropped']} measured ({pct('dropped')}) {why} sigma_d of infinite depth")
    if not c["disparity"]:
        # "every pixel with a disparity has one" was true of none (a blank wall, a dark frame)
        return f"{head}: no pixel has a disparity to triangulate"
    if not parts:
        return f"{head}: every pixel with a disparity has one"
    return f"{head}: none on " + " nor on ".join(parts)


def _length(metres: float, unit: str, digits: int) -> str:
    """``metres`` said in ``unit`` (a key of ``UNIT_TO_METRES``) with ``digits`` decimals."""
    from stereovision.calibration import UNIT_TO_METRES

    return f"{metres / UNIT_TO_METRES[unit]:.{digits}f} {unit}"


def _beyond_max_depth(depth: np.ndarray, before: np.ndarray, max_depth: float) -> str | None:
    """``no depth within --max-depth 2 m (the nearest is 2.07 m)`` when ``--max-depth`` left
    no depth of the ones there were (``before``, metres); None otherwise. In metres, as the
    option is, with the digits it takes to read the nearest as beyond the limit."""
    if np.isfinite(depth).any() or not np.isfinite(before).any():
        return None
    nearest = float(np.nanmin(before))
    if nearest <= max_depth:  # --max-sigma took the depths within reach
        return None
    shown = figure_shown(nearest)
    if float(shown) <= max_depth:  # 2.0004 shown as "2" read as within --max-depth 2
        shown = f"{nearest:.7g}"
    return f"no depth within --max-depth {max_depth:g} m (the nearest is {shown} m)"


def _limit_not_in_unit(flag: str, value: float, unit: str, values: np.ndarray | None) -> str | None:
    """The warning of a ``--max-depth`` or ``--max-sigma`` (metres, whatever ``--unit``) that
    looks given in ``--unit``: in metres it keeps every one of ``values`` (the frame's depths
    or depth sigmas, metres), in ``unit`` it would have kept fewer (``--unit mm --max-depth
    3000`` kept all, 3000 m); None otherwise, and for ``--unit m``.

    Parameters
    ----------
    flag : str
        ``--max-depth`` or ``--max-sigma``.
    value : float
        The option's value, metres.
    unit : str
        ``--unit``, a key of :data:`~stereovision.calibration.UNIT_TO_METRES`.
    values : ndarray or None
        The frame's depths or depth sigmas before the limit, metres, NaN where none.

    Returns
    -------
    str or None
        ``--max-depth 3000 is in metres, whatever --unit: 3000 m keeps every depth (the
        largest 6.34 m); for 3000 mm give --max-depth 3``, or None.
    """
    from stereovision.calibration import UNIT_TO_METRES

    if unit == "m" or values is None or not np.isfinite(values).any():
        return None
    top = float(np.nanmax(values))
    meant = value * UNIT_TO_METRES[unit]
    if value < top or meant >= top:  # the limit takes some in metres, or none either way
        return None
    what = "depth" if flag == "--max-depth" else "depth sigma"
    return (
        f"{flag} {value:g} is in metres, whatever --unit: {value:g} m keeps every {what} (the "
        f"largest {figure_shown(top)} m); for {value:g} {unit} give {flag} {meant:g}"
    )


def _below_max_sigma(
    depth: np.ndarray, before: Any, max_sigma: float, max_depth: float | None = None
) -> str | None:
    """``--max-sigma 0.001 m left no depth: the smallest depth sigma of this frame is 0.0123 m``
    when ``--max-sigma`` took every depth ``before`` (the result as matched) had within
    ``max_depth``; None otherwise (some depth kept, none to begin with, or ``--max-depth``
    took them all: :func:`_beyond_max_depth` says so). The smallest sigma is shown with the
    digits it takes for ``--max-sigma`` of that value to keep its pixel (compared in float32,
    as :meth:`~stereovision.depth.DepthResult.filtered` does)."""
    sigma = before.depth_sigma
    if np.isfinite(depth).any() or sigma is None:
        return None
    z = before.depth
    within = np.isfinite(z) & np.isfinite(sigma)
    if max_depth is not None:
        # 1e300 is float32's inf, as filtered() reads it, without NumPy's cast warning
        within &= z <= float32_reach(max_depth)
    if not within.any():
        return None
    smallest = np.float32(sigma[within].min())
    if smallest <= max_sigma:  # not the sigma that took them (cannot happen: said of nothing)
        return None
    shown = figure_shown(float(smallest))
    if np.float32(float(shown)) < smallest:  # 0.01234 shown as 0.0123 would keep nothing
        shown = f"{float(smallest):.9g}"
    return (
        f"--max-sigma {max_sigma:g} m left no depth: the smallest depth sigma of this frame is "
        f"{shown} m (give --max-sigma {shown} or more to keep some)"
    )


def _depth_range(depth: np.ndarray, unit: str) -> str:
    """The summary's depth figures in ``unit``: ``depth 1.2-34.5 m (median 4.6 m)``, the
    depths the result keeps (``depth.npy``'s finite values)."""
    from stereovision.calibration import UNIT_TO_METRES

    z = depth[np.isfinite(depth)] / UNIT_TO_METRES[unit]
    if not z.size:
        return "no depth"
    lo, hi, mid = (figure_shown(float(v)) for v in (z.min(), z.max(), np.median(z)))
    return f"depth {lo}-{hi} {unit} (median {mid} {unit})"


def _ground_outputs(
    res: Any,
    calib: Any,
    out: Path,
    grid: float | None = None,
    log: Any = None,
    unit: str = "m",
) -> dict[str, Path]:
    """``depth --ground``: the floor's plane (``ground.json``), what stands on it
    (``obstacles.png``: 255 between 0.15 and 2 m above the floor) and its planar scan
    (``scan.json``, ``sensor_msgs/LaserScan``'s fields); with ``--grid M`` also a ROS map_server
    occupancy grid of M-metre cells (``map.png``, ``map.yaml``). The floor is fitted to the
    whole disparity map; obstacles, scan and grid come from its points within ``--max-depth``,
    filled pixels included unless ``--max-sigma`` asks for trusted depths only
    (:meth:`DepthResult.point_image`)."""
    import cv2

    from stereovision.ground import (
        _fit_ground,
        laser_scan,
        obstacle_mask,
        occupancy_grid,
    )
    from stereovision.io import atomic_write

    # the fit's own reason when it finds none: _no_floor_line ran the whole fit a second time
    plane, why = _fit_ground(res.disparity, calib)
    if plane is None:
        if log is not None:
            log(why)
        return {}
    if log is not None:
        log(plane.describe(unit))
        log("the camera on the floor, for ROS 2: " + plane.ros2_static_transform())
    rc = calib if calib.rectified else calib.rectified_calibration()
    points = res.point_image(filled=True)  # once, for the obstacles, the scan and the grid
    mask = obstacle_mask(points, plane)
    paths = {"ground.json": out / "ground.json", "obstacles.png": out / "obstacles.png"}
    with atomic_write(paths["ground.json"], "w") as fh:
        fh.write(json.dumps({**plane.as_dict(), "obstacle_share": float(mask.mean())}, indent=2))
    ok, buf = cv2.imencode(".png", mask.astype(np.uint8) * 255)
    if not ok:
        raise RuntimeError("could not encode obstacles.png")
    with atomic_write(paths["obstacles.png"]) as fh:
        fh.write(buf.tobytes())
    scan = laser_scan(points, plane, rc)
    paths["scan.json"] = out / "scan.json"
    with atomic_write(paths["scan.json"], "w") as fh:
        fh.write(json.dumps(scan.as_dict()))
    if log is not None:
        hits = np.isfinite(scan.ranges)
        if hits.any():
            i = int(np.nanargmin(np.where(hits, scan.ranges, np.nan)))
            log(
                f"scan: {int(hits.sum())} of {len(hits)} beams on an obstacle, the nearest "
                f"{_length(float(scan.ranges[i]), unit, 2)} away at "
                f"{math.degrees(scan.angles[i]):+.1f} deg"
            )
        else:
            log(f"scan: no obstacle on any of the {len(hits)} beams")
    if grid is not None:
        paths["map.png"], paths["map.yaml"] = occupancy_grid(points, plane, resolution=grid).save(
            out
        )
    return paths


def cmd_check(args: argparse.Namespace) -> int:
    """``stereovision check LEFT RIGHT [--calib F] [--fix OUT]``: is the pair (still)
    rectified? With ``--fix``, the rig's rotation corrected from the pair is written to OUT."""
    from stereovision.io import check_pair_files, read_image
    from stereovision.rectification_check import check_rectification

    if not (math.isfinite(args.tolerance) and args.tolerance > 0):  # before reading the pair
        raise CliError(f"--tolerance: expected a positive number of pixels, got {args.tolerance:g}")
    if args.plot and Path(args.plot).suffix.lower() not in ("", ".png"):
        # the plot is PNG bytes: p.jpg (or .gif, .pdf) held a PNG its viewers misread
        raise CliError(f"--plot {args.plot}: the plot is written as PNG; give a .png file name")
    # 16-bit files keep their 16 bits, as depth reads them: imread's 8-bit copy kept the top 8
    # (a 12-bit pair's 0-4095 as 0-15), and the rows were told from those grey levels
    left = read_image(args.left)
    right = read_image(args.right)
    same = (
        None if left.shape != right.shape else check_pair_files(left, right, args.left, args.right)
    )
    if same:  # said of the rows: check finds no disparity (the warning spoke of depth's)
        one_pair = same.replace("every disparity comes out 0", "their rows agree by themselves")
        warnings.warn(one_pair, stacklevel=1)
    # check has no --rectification, which the refusal of rectify's homographies named
    calib = load_calibration(
        args.calib,
        args.calib_unit,
        left,
        # not "check the pair they rectified": check finds features anew on the warped pair,
        # few (OpenCV's books: 18, 'cannot tell', exit 3, where the raw pair's 87 agree)
        homographies="check takes no homographies: in Python, stereovision.uncalibrated."
        "UncalibratedRectification.load(path).check(left, right) checks the raw pair through "
        "them (rectify says that check of the ones it finds; check of its left_rect.png and "
        "right_rect.png finds features anew, few on a warped pair)",
    )
    fix = Path(args.fix) if args.fix else None
    if fix is not None:
        if calib is None:
            raise CliError("--fix needs --calib: the calibration to correct")
        if fix.suffix.lower() not in (".yaml", ".yml", ".xml", ".json"):
            raise CliError(f"--fix {args.fix}: use a .yaml, .yml, .xml or .json file name")
        if str(fix.parent) and not fix.parent.is_dir():
            if fix.parent.exists():  # a file: "does not exist" sent the user looking for it
                raise CliError(
                    f"--fix {args.fix}: its folder {fix.parent}: is a file, not a folder"
                )
            raise FileNotFoundError(f"--fix {args.fix}: directory {fix.parent} does not exist")
        if fix.is_dir():  # else found when the corrected rig is saved, after the work
            raise CliError(f"--fix {args.fix}: is a folder; give a file name")
        from stereovision.io import check_destinations, check_output_folder

        # a folder that cannot be written too: found only after the check and the correction
        check_output_folder(fix.parent, f"--fix {args.fix}: its folder")
        # and a link, written through, into a missing or unwritable folder: the same
        check_destinations(fix.parent, [fix.name], f"--fix {args.fix}: its folder")
    inputs = {"the left image": args.left, "the right image": args.right,
              "the calibration": args.calib}  # fmt: skip
    if args.plot:
        _refuse_an_input("--plot", Path(args.plot), inputs)
        # said before the check, not after its matching and verdict (as --fix's folder is)
        from stereovision.io import check_output_folder

        if Path(args.plot).is_dir():
            raise CliError(f"--plot {args.plot}: is a folder; give a file name")
        plot_dir = Path(args.plot).parent
        check_output_folder(plot_dir, f"--plot {args.plot}: its folder")
        from stereovision.io import check_destinations

        # a link is written through: its target's folder too (else found after the check)
        check_destinations(plot_dir, [Path(args.plot).name], f"--plot {args.plot}: its folder")
    if fix is not None:  # the corrected calibration in place of the original lost it
        _refuse_an_input("--fix", fix, inputs)
    raw_left, raw_right = left, right
    if calib is not None:
        left, right = calib.rectify(left, right)
    res = check_rectification(left, right, tolerance=args.tolerance)
    # Rectified images (rectify's left_rect.png, a camera driver's image_rect) given with the raw
    # rig's calibration are rectified twice and fail: the line said only to recalibrate or
    # --fix, which "corrected" the rig to fit them (stereopi: 0.403 degrees; through that rig
    # its raw pair's rows went from 0.15 to 0.46 px). A drift of a rig whose raw rows agree
    # looks the same, so it is said, not refused.
    as_given = None
    # --json without --fix never says it (its JSON is the check's): a second matching for nothing
    said_twice = fix is not None or not args.json
    if (
        said_twice
        and res.ok is False
        and not res.swapped
        and calib is not None
        and not calib.rectified
    ):
        as_given = check_rectification(raw_left, raw_right, tolerance=args.tolerance)
        if as_given.ok is not True or as_given.swapped:
            as_given = None
    twice = (
        None
        if as_given is None
        else f"the images as given have rows that agree already ({as_given.rows_agree()}): "
        "if they are rectified images (rectify's left_rect.png, a camera's image_rect)"
    )
    # the end of the lines that leave the rig as it is (its check failing, --fix not writing):
    # --fix's "calibrate the rig again" or "still fails" alone sent them to recalibrate
    again = (
        ""
        if twice is None
        else f"; but {twice}, the raw rig's calibration rectifies them again: give the raw images"
    )
    # The other mix-up: raw images with a calibration of rectified images (rectify's
    # calib_rect.yaml), which rectifies nothing: the line said only to recalibrate or --fix
    raw_with_rectified = (
        "--calib is a calibration of rectified images (R = I, no distortion: rectify's "
        "calib_rect.yaml, a dataset's): if these are the raw images, give the raw rig's "
        "calibration"
        if calib is not None and calib.rectified and res.ok is False and not res.swapped
        else None
    )
    if raw_with_rectified is not None:
        again = f"; but {raw_with_rectified}"
    if args.plot:
        from stereovision.io import keep_previous
        from stereovision.rectification_check import draw_rectification_check

        # a file already there (an earlier plot, or the user's own picture) is copied aside
        plot = Path(args.plot)
        png = _png_bytes(draw_rectification_check(left, right, res))
        kept_plot = keep_previous(plot, png)  # the same plot again replaces nothing
        _atomic_write_bytes(plot, png)
        if kept_plot is not None:  # on stderr: with --json stdout is the one JSON object
            print(
                f"stereovision: {escaped(str(plot))} replaced; the earlier file is "
                f"{escaped(str(kept_plot))}",
                file=sys.stderr,
            )
    said = res.as_dict()  # with --json, printed once at the end: stdout is the one JSON object
    if not args.json:
        print(res.summary())
    elif fix is None or res.ok is None:
        print(json.dumps(said))
    if res.ok is False and not res.swapped and not args.json and fix is None:
        print(
            "  the calibration no longer rectifies this rig: recalibrate, or correct the right "
            "camera's pitch and roll with --fix OUT" + again
            if calib is not None
            else "  these images are not rectified: give the rig's calibration (--calib), or "
            "rectify them from their own features (stereovision rectify LEFT RIGHT -o DIR)"
        )
    if args.plot and not args.json:  # the picture asked for is named, as view -o names its own
        print(f"plot written to {escaped(args.plot)}")
    if res.ok is None:
        # Not an error of the command line (2), nor a verdict on the rig (1): the pair could
        # not be judged, so there is nothing to correct either.
        if fix is not None:
            print(
                f"stereovision: not corrected, nothing written to {escaped(str(fix))}: "
                + (
                    "the two images are identical (give the two cameras' views)"
                    if res.identical
                    else "too little texture to tell the rows (give a textured pair)"
                ),
                file=sys.stderr,
            )
        return EXIT_CANNOT_TELL
    if fix is None:
        return 0 if res.ok else 1
    if res.ok:
        # A passing pair's "correction" fits noise: tsukuba through its own (identity) rig,
        # 0.07 px, was turned 0.006 degrees and written; on their own calibrations playground
        # and TartanAir lose bad-2.0 that way (docs/robotics.md). A smaller --tolerance asks.
        if args.json:
            print(json.dumps(said))
        print(
            f"stereovision: not corrected, nothing written to {escaped(str(fix))}: the rows "
            f"agree already ({res.rows_agree()}): the calibration still "
            "rectifies this rig (a smaller --tolerance corrects a pair within it)",
            file=sys.stderr,
        )
        return 0
    from stereovision.rectification_check import refine_rectification

    # A verdict the pair cannot correct (exit 1, as a failed check), not an error of the command
    # line (2): said once, after the check's line, without repeating it.
    why = None
    if res.swapped:
        why = "the left and right images look swapped: give them the other way round"
    elif not np.isfinite(res.offset):
        why = "the matches fit no common row offset, too far off to correct: recalibrate"
    else:
        try:
            # the check above was of this pair through this calibration: reuse its matches
            fixed, after = refine_rectification(
                raw_left, raw_right, calib, tolerance=args.tolerance, check=res
            )
        except ValueError as exc:
            why = str(exc).removeprefix("cannot refine: ")
    if why is not None:
        if args.json:
            print(json.dumps(said))
        print(
            f"stereovision: not corrected, nothing written to {escaped(str(fix))}: {why}{again}",
            file=sys.stderr,
        )
        return 1
    turn = float(np.degrees(np.linalg.norm(cv2.Rodrigues(fixed.R @ calib.R.T)[0])))
    said["fixed"] = {"turn_deg": turn, "check": after.as_dict(), "written": None}
    if not args.json:
        print(f"corrected (the right camera turned {turn:.3f} degrees): {after.summary()}")
    if not after.ok:
        if args.json:
            print(json.dumps(said))
        print(
            f"stereovision: the corrected calibration still fails: not written{again}",
            file=sys.stderr,
        )
        return 1
    if twice is not None:
        warnings.warn(
            f"{twice}, the corrected calibration fits them, not the rig's raw images: give the "
            "raw images",
            stacklevel=1,
        )
    if raw_with_rectified is not None:  # written all the same: a rectified rig drifts too
        warnings.warn(f"{raw_with_rectified} (the correction fits them as given)", stacklevel=1)
    from stereovision.io import keep_previous, replaced_words

    # the same correction again (a rerun) replaces nothing: no copy is kept
    existed = Path(fix).is_file()
    kept = keep_previous(fix, fixed._file_text(fix).encode("utf-8"))
    fixed.save(fix)
    said["fixed"]["written"] = str(fix)
    replaced = replaced_words(kept, existed)
    if not args.json:
        print(f"corrected calibration written to {escaped(str(fix))}{replaced}")
    else:
        print(json.dumps(said))
        if kept:  # on stderr: stdout is the one JSON object
            print(
                f"stereovision: {escaped(str(fix))} replaced; the earlier file is "
                f"{escaped(str(kept))}",
                file=sys.stderr,
            )
    return 0


#: Every file ``stereovision rectify`` may write into its ``-o`` folder.
RECTIFY_OUTPUTS = (
    "left_rect.png",
    "right_rect.png",
    "check.png",
    "rectification.json",
    "calib_rect.yaml",
)

#: What ``stereovision rectify`` wrote into its ``-o`` folder (JSON list of file names, as
#: :data:`DEPTH_MANIFEST`): the files a later run may replace.
RECTIFY_MANIFEST = ".stereovision-rectify.json"


def _as_file_channels(img: np.ndarray, path: str) -> np.ndarray:
    """A rectified image with the channels of the file it came from: a grey file is read as
    three equal channels (read_image's BGR), and was written back as a colour PNG (16-bit grey
    in, 16-bit BGR out). The values are those of its first channel, the others' equal."""
    from stereovision.io import _imdecode

    if img.ndim != 3 or not (
        np.array_equal(img[..., 0], img[..., 1]) and np.array_equal(img[..., 0], img[..., 2])
    ):
        return img
    given = _imdecode(np.fromfile(path, np.uint8), cv2.IMREAD_UNCHANGED)
    return img[..., 0] if given is not None and given.ndim == 2 else img


def cmd_rectify(args: argparse.Namespace) -> int:
    """``stereovision rectify LEFT RIGHT -o DIR [--calib F] [--force]``: the rectified pair,
    and with no calibration the homographies found from the pair's features (a pair already
    rectified is written as given, unless ``--force``)."""
    from stereovision.io import check_pair_files, read_image
    from stereovision.rectification_check import (
        already_rectified,
        check_rectification,
        draw_rectification_check,
    )

    # 16-bit files keep their 16 bits, and the rectified pair is written at 16 bits: imread's
    # 8-bit copy kept the top 8 (a 12-bit pair's 0-4095 as 0-15), all that was written
    left = read_image(args.left)
    right = read_image(args.right)
    same = (
        None if left.shape != right.shape else check_pair_files(left, right, args.left, args.right)
    )
    if same:
        warnings.warn(same, stacklevel=1)
    calib = load_calibration(
        args.calib,
        args.calib_unit,
        left,
        homographies="rectify takes no homographies (without --calib it finds them anew); "
        + _HOMOGRAPHIES_USE,
    )
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise CliError(f"-o {args.output}: is a file; give a folder")
    from stereovision.io import check_output_folder

    # a file above it, or a folder that cannot be written, said before the pair is matched
    # (as depth and demo say it), not once the homographies were fitted; the text: `-o ./-`
    # names a folder where Path("./-") is Path("-")
    check_output_folder(args.output, "-o")
    inputs = {"the left image": args.left, "the right image": args.right,
              "the calibration": args.calib}  # fmt: skip
    for name in RECTIFY_OUTPUTS:
        _refuse_an_input("-o", out / name, inputs)  # rectifying rect/*.png again into rect/
    # a left_rect.png of the user's is not replaced; this command's own (its manifest's) are
    # with --calib: the rectified pair's own calibration, where without one its homographies
    own = "rectification.json" if calib is None else "calib_rect.yaml"
    names = (*RECTIFY_OUTPUTS[:3], own)
    earlier = refuse_foreign_outputs(out, names, RECTIFY_MANIFEST)
    refuse_folders_under(out, names)  # a listed one made a folder: not once the pair is warped
    given = None  # the pair's own check, when it is already rectified: written as given
    if calib is not None:
        if args.model != "auto":
            raise CliError("--model is for rectifying without a calibration (no --calib)")
        if args.force:
            raise CliError("--force is for rectifying without a calibration (no --calib)")
        lr, rr = calib.rectify(left, right)
        summary = None
    else:
        from stereovision.uncalibrated import rectify_uncalibrated

        if not args.force:
            # A pair whose features already lie on common rows (a rectified dataset, a camera
            # that rectifies on board): warping it by homographies fitted to those same rows
            # only resamples it, and changes its size.
            given = already_rectified(left, right)
        if given is None:
            rect = rectify_uncalibrated(left, right, model=args.model)
            lr, rr = rect.rectify(left, right)
            summary = rect
        else:
            lr, rr = left, right
            summary = None
    # Without a calibration the raw pair's own matches, moved by the homographies, are judged
    # (check_rectification's rule): SIFT on the warped pair matched 18 of the books' 107 and
    # said "cannot tell" under a line saying the rows agree to 0.25 px.
    check = (
        given
        if given is not None
        else summary.check(left, right)
        if summary is not None
        else check_rectification(lr, rr)
    )
    # Written into a hidden folder and moved in together, as depth's (commit_outputs): an
    # error or an interrupt halfway left new left_rect.png beside an earlier right_rect.png.
    # An earlier run's rectification.json (without --calib, or with --force) that this run
    # does not rewrite goes with the move: `depth --rectification` would warp the images
    # written now (calibrated, or the pair as given) by its homographies. It may have been
    # this very pair's (a --force run before a plain one): the line says why it goes, not
    # whose it was. A file of that name that the manifest does not list is the user's
    # (homographies of theirs, or of an earlier version's run): it stays, and the line says
    # they do not fit.
    with staged_outputs(out) as stage:
        staged: dict[str, Path] = {}
        for name, img in (
            ("left_rect.png", _as_file_channels(lr, args.left)),
            ("right_rect.png", _as_file_channels(rr, args.right)),
            ("check.png", draw_rectification_check(lr, rr, check)),
        ):
            staged[name] = stage / name
            _atomic_write_bytes(staged[name], _png_bytes(img))
        if summary is not None:
            staged["rectification.json"] = summary.save(stage / "rectification.json")
        if calib is not None:
            # without it `depth rect/*.png --calib rig.yaml` rectified the pair a second time:
            # depth on the rectified pair needs the rectified rig (R = I, no distortion)
            staged["calib_rect.yaml"] = calib.rectified_calibration().save(
                stage / "calib_rect.yaml"
            )
        written, removed = commit_outputs(
            out, staged, earlier, RECTIFY_MANIFEST, RECTIFY_OUTPUTS, stale=_stale_rectify_output
        )
    # the command to run next, its paths as the shell reads them: `-o "my rect"` gave
    # "depth my rect/left_rect.png ...", which the shell split into four words
    quoted = {name: _shell_path(path) for name, path in written.items()}
    if summary is not None:
        print(summary.describe())
        print(
            f"  disparity, not depth: for depth in metres calibrate the rig. Next: stereovision "
            f"depth {quoted['left_rect.png']} {quoted['right_rect.png']} --max-disparity "
            f"{summary.max_disparity} -o OUT"
        )
    if given is not None:
        # an explicit --model is not applied to a pair written as given: said, not dropped
        unused = f", --model {args.model} not used" if args.model != "auto" else ""
        print(
            f"already rectified ({given.rows_agree()}): written as given, not warped{unused} "
            "(--force rectifies it from its features anyway)"
        )
    else:
        print(check.summary())
        if summary is not None and check.ok is not None and math.isfinite(check.offset):
            print(
                f"  (the raw pair's feature matches moved by the homographies: {summary.matches} "
                f"fit one fundamental matrix, {check.matches} lie on one row model within 1 px)"
            )
    for name, path in written.items():
        print(f"  {name:19s} {escaped(str(path))}")
    if "calib_rect.yaml" in written:
        print(
            f"  depth on the rectified pair: stereovision depth {quoted['left_rect.png']} "
            f"{quoted['right_rect.png']} --calib {quoted['calib_rect.yaml']} -o OUT (the raw "
            "rig's calibration would rectify it again)"
        )
    now = (
        "the pair as given"
        if given is not None
        else "rectified by --calib"
        if calib is not None
        else "rectified from its features"
    )
    for path in removed:
        what = (
            "homographies do" if path.name == "rectification.json" else "rectified calibration does"
        )
        print(
            f"  removed {path.name} of an earlier run (its {what} not fit the images "
            f"written now: {now})"
        )
    mine = out / "rectification.json"
    if (
        summary is None
        and mine.name not in earlier
        and mine.is_file()
        and not mine.is_symlink()
        and _homographies(mine)
    ):
        print(
            f"  kept {escaped(str(mine))} (not listed as an earlier run's output there), but its "
            f"homographies do not fit the images written now ({now}): do not give it "
            "to depth --rectification with them"
        )
    return 0


def _shell_path(path: Path) -> str:
    """``path`` as a command the CLI suggests names it: quoted for the shell where it holds a
    space or another character the shell reads (``'my rect/left_rect.png'``), and a relative
    one that starts with ``-`` after ``./`` (else read as an option). One with a control
    character is ANSI-C quoted (``$'o\\nut/left_rect.png'``, as bash and zsh read it), its
    characters escaped as :func:`escaped` shows them (one past ASCII as its UTF-8 bytes): quoted
    as it is, a newline cut the line."""
    text = str(path)
    if text.startswith("-"):
        text = f"./{text}"
    shown = escaped(text)
    if shown != text:  # "\n", "\x1b", "\u2028" and doubled backslashes: $'...' reads them so
        # but a C1 control's "\x85" is read as the byte 0x85, not the character U+0085 (UTF-8
        # C2 85): another file's name; and "\u2028" as the character only in a UTF-8 locale
        # (in C, as "\u2028"): such a character as its UTF-8 bytes, read alike in any locale
        shown = _WIDE_ESCAPE.sub(_utf8_bytes, shown)
        return "$'" + shown.replace("'", "\\'") + "'"
    return shlex.quote(text)


#: An escape of a character past ASCII in :func:`escaped`'s text (``\x85``, ``\u2028``), not
#: after a backslash of the name (doubled there)
_WIDE_ESCAPE = re.compile(r"(?<!\\)((?:\\\\)*)\\(x[89][0-9a-f]|u[0-9a-f]{4})")


def _utf8_bytes(m: re.Match[str]) -> str:
    """:data:`_WIDE_ESCAPE`'s character as ``$'...'`` reads its UTF-8 bytes (``\\xc2\\x85``);
    a name's byte that is not UTF-8 (os.fsdecode's ``\\udce9``) as that byte (``\\xe9``)."""
    char = chr(int(m.group(2)[1:], 16))
    # surrogateescape: escaped() shows such a byte as "\udce9" (22cb4006), which UTF-8 cannot
    # encode: `rectify -o $'r\xe9'` wrote its files, then failed on its "Next:" line
    return m.group(1) + "".join(f"\\x{b:02x}" for b in char.encode("utf-8", "surrogateescape"))


def _stale_rectify_output(path: Path) -> bool:
    """Whether an earlier ``rectify`` run's file this run did not write goes: its
    ``calib_rect.yaml`` always (it is the calibration of the images it wrote), its
    ``rectification.json`` when it holds homographies (:func:`_homographies`)."""
    return path.name != "rectification.json" or _homographies(path)


def _homographies(path: Path) -> bool:
    """Whether ``path`` holds homographies ``depth --rectification`` would load."""
    from stereovision.uncalibrated import UncalibratedRectification

    try:
        UncalibratedRectification.load(path)
    except (OSError, ValueError):
        return False
    return True


def _paper_baseline_words(text: str, baseline: float) -> str:
    """The implausible-baseline warning of a rig on paper in ``info``'s words: its ``--baseline``
    is in metres, and the user gave no ``T``, square size or ``unit=`` that the library's
    warning asks about (``--baseline 120`` for 120 mm: "With unit='mm' it would be 12.0 cm")."""
    from stereovision.calibration import PLAUSIBLE_BASELINE_M, UNIT_TO_METRES

    # "baseline 120 m, ..." (a rig on paper is in metres: the library says no "= 120 m")
    found = re.match(r"baseline \S+ m(?: = \S+ m)?, (.*?): are T ", text)
    if found is None:
        return text
    lo, hi = PLAUSIBLE_BASELINE_M
    # every unit that makes it a plausible rig: 12 may be mm, cm or in (the first alone, mm,
    # was named: "12 mm is --baseline 0.012" for what is most likely a 12 cm rig)
    others = [
        f"{baseline:g} {u} is --baseline {baseline * k:g}"
        for u, k in UNIT_TO_METRES.items()
        if u != "m" and lo <= baseline * k <= hi
    ]
    hint = f" ({', '.join(others)})" if others else ""
    why = found.group(1)
    return f"--baseline {baseline:g}: {baseline:g} m is {why}; --baseline is in metres{hint}"


#: Longest ``info --baseline``, in metres: 1000 km, far past a robot's rig (warned of above 5 m,
#: with the unit meant: 4000 is a 4 m rig in mm); ``--baseline 1e308`` overflowed (NumPy's
#: RuntimeWarnings, then "baseline inf m", exit 0).
MAX_PAPER_BASELINE_M = 1e6


def paper_baseline(text: str) -> float:
    """argparse type of ``info --baseline``: :func:`metres` (its range is checked with the other
    options) whose unit hint keeps to :data:`MAX_PAPER_BASELINE_M`. A value past any float
    (``1e400``, ``1e-400``), or NaN, is refused here, as typed: after the parsing it was said
    as "got inf" ("got 0.0")."""
    value = metres(text, within=(0.0, MAX_PAPER_BASELINE_M))
    if math.isfinite(value) and not _past_float(text, value):
        return value
    if value > 0:
        raise argparse.ArgumentTypeError(
            f"expected at most {MAX_PAPER_BASELINE_M:g} m (a rig on paper), got {text!r}"
        )
    raise argparse.ArgumentTypeError(f"expected a positive number of metres, got {text!r}")


def _given_size_note(calib: Any, beside: Path | None = None) -> str:
    """``info CALIB --size WxH``'s line for a calibration that holds no image size: the field
    of view is the size given's (the depths are not), and a principal point outside that size
    is named (the rig's images are another size). ``beside``: the image that sizes it when no
    size is given (a Q.dat's left.png), not read."""
    w, h = calib.image_size
    rc = calib if calib.rectified else calib.rectified_calibration()
    cx, cy = float(rc.K1[0, 2]), float(rc.K1[1, 2])
    unread = "" if beside is None else f"; {beside.name} beside it not read"
    note = (
        f"image size {w}x{h} from --size (the file holds none{unread}): the field of view is for it"
    )
    if not (0 <= cx <= w - 1 and 0 <= cy <= h - 1):
        note += (
            f"; the principal point ({cx:.1f}, {cy:.1f}) px lies outside a {w}x{h} image: "
            "is it the rig's image size?"
        )
    return note


def cmd_info(args: argparse.Namespace) -> int:
    """``stereovision info CALIB``: what the rig can measure; ``info BAG``: what a recording
    holds (its topics, the stereo pair found) and, from its ``camera_info``, what its rig can
    measure."""
    from stereovision.rosbag import is_bag

    design = (args.size, args.hfov, args.baseline)
    if args.calib is None:
        if args.calib_unit is not None:
            raise CliError("--calib-unit is the unit of a calibration file: give one, or none")
        if None in design:
            flags = ("--size", "--hfov", "--baseline")
            missing = [f for f, v in zip(flags, design, strict=True) if v is None]
            # two of the three given read as if none were: the one left out is named
            left_out = f" ({' and '.join(missing)} missing)" if len(missing) < len(flags) else ""
            raise CliError(
                "give a calibration (or a bag), or a rig on paper: --size, --hfov and "
                f"--baseline{left_out}"
            )
        if (args.left_topic, args.right_topic) != (None, None):  # dropped without a word
            raise CliError("--left-topic and --right-topic are for a bag")
        from stereovision.calibration import Calibration
        from stereovision.capture import parse_size

        size = parse_size(args.size, "--size")
        assert size is not None
        if math.isfinite(args.baseline) and args.baseline > MAX_PAPER_BASELINE_M:
            raise CliError(
                f"--baseline: expected at most {MAX_PAPER_BASELINE_M:g} m (a rig on paper), "
                f"got {args.baseline:g}"
            )
        try:  # the rig before its heading: a bad value is the one line said, in the CLI's words
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                rig = Calibration.ideal(size, args.hfov, args.baseline)
        except ValueError as exc:
            text = str(exc).replace("hfov_deg:", "--hfov:").replace("baseline_m:", "--baseline:")
            raise CliError(text) from None
        for w in caught:
            warnings.warn(_paper_baseline_words(str(w.message), args.baseline), w.category, 1)
        print("a rig on paper (two ideal cameras, rectified):")
        print(rig.describe())
        return 0
    paper = [f for f, v in (("--hfov", args.hfov), ("--baseline", args.baseline)) if v is not None]
    if paper:  # the ones given: --hfov alone was told of --baseline too
        verb = "describes" if len(paper) == 1 else "describe"
        raise CliError(f"{' and '.join(paper)} {verb} a rig on paper: give no calibration")
    topics = (args.left_topic, args.right_topic)
    # a missing bag (run.bag, or a link to one since moved) was "calibration file not found":
    # a name a bag's is said as the bag reader says it ("bag not found: run.bag")
    name = os.fspath(args.calib)
    missing_bag = not os.path.exists(name) and name.endswith(
        (".bag", ".db3", ".mcap", ".bag.active")
    )
    if not missing_bag and not is_bag(args.calib):
        if topics != (None, None):
            raise CliError("--left-topic and --right-topic are for a bag")
        from stereovision.calibration import _sizeless, _sizing_images
        from stereovision.capture import parse_size

        # --size with a calibration: the image size of one that holds none (stereo_calib
        # output, a Q.dat alone), a check of the size of one that does
        size = parse_size(args.size, "--size")
        # info has no --rectification, which the refusal of rectify's homographies named
        calib = load_calibration(
            args.calib,
            args.calib_unit,
            size=size,
            size_words="--size WxH",
            homographies=f"info takes no homographies (they measure no depth); {_HOMOGRAPHIES_USE}"
            " (in Python: stereovision.uncalibrated.UncalibratedRectification.load(path)"
            ".describe() says what they hold)",
        )
        print(calib.describe())
        if size is not None and _sizeless(args.calib):
            # the field of view is --size's alone: a Q.dat of a 640x480 rig given 100x100 said
            # "field of view 10.5 x 13.2 degrees" for its 90 degree cameras, without a word
            print(_given_size_note(calib))
        elif size is not None and (beside := _sizing_images(args.calib)):
            # --size wins over the left.png beside a Q.dat (or a KITTI file) that sizes it
            # otherwise: its field of view was --size's, unsaid
            print(_given_size_note(calib, beside[0]))
        return 0
    if args.size is not None or args.calib_unit is not None:
        raise CliError("--size and --calib-unit are for a calibration file, not a bag")
    from stereovision.rosbag import BagCamera, bag_topics

    try:
        cam = BagCamera(args.calib, left_topic=topics[0], right_topic=topics[1])
    except ValueError:
        # no stereo pair found (or the topics given are not image topics): the topics are
        # still what `info BAG` shows, the reason below them (a depth bag of `stream --bag`
        # holds one camera's images: listing nothing hid what it holds)
        with contextlib.suppress(ValueError):
            print(bag_topics(args.calib))
        raise
    with cam:
        print(cam.summary())
        calib = cam.calibration()
    if calib is None and None not in cam.info_topics.values():
        # camera_info there, all zeros: "no camera_info" was not so
        print(
            "its camera_info say a camera is uncalibrated (K = 0): give the rig's "
            "calibration to the command that reads the bag (stream --from-bag BAG --calib RIG)"
        )
    elif calib is None and any(cam.info_topics.values()):
        # one camera's camera_info recorded, not the other's: "no camera_info beside the image
        # topics" under a listing that marks the one there ("<- left camera_info")
        side = "left" if cam.info_topics["left"] is None else "right"
        other = cam.info_topics["right" if side == "left" else "left"]
        print(
            f"no camera_info beside {cam.topics[side]} (the bag's {other} is the other "
            "camera's alone): give the rig's calibration to the command that reads the bag "
            "(stream --from-bag BAG --calib RIG)"
        )
    elif calib is None:
        print(
            "no camera_info beside the image topics: give the rig's calibration to the command "
            "that reads the bag (stream --from-bag BAG --calib RIG)"
        )
    else:
        print("the rig, from its camera_info:")
        print(calib.describe())
    return 0


def _demo_scene_dir() -> Path:
    return Path(str(resources.files("stereovision") / "data" / "cones"))


def cmd_demo(args: argparse.Namespace) -> int:
    """``stereovision demo``: the bundled Middlebury scene, end to end, with an evaluation line."""
    from stereovision.depth import depth_map
    from stereovision.evaluate import dense_metrics, depth_metrics, gt_depth
    from stereovision.io import check_output_folder, load_scene

    # before the work: a file named as -o was said after the scene was matched and evaluated
    out_dir = Path(args.output)
    check_output_folder(args.output, "-o")  # the text: `-o ./-` names a folder
    names = planned_depth_outputs(calib=True)
    # A file under an output name that no earlier run listed (the user's, or a demo folder of a
    # version before the manifest: `make demo` after an update) is copied aside, not refused:
    # the Quick start's command keeps working and nothing is lost.
    earlier = _manifest_names(out_dir)
    foreign = foreign_outputs(out_dir, names, earlier)
    if any(not p.is_file() or p.is_symlink() for p in foreign):
        refuse_foreign_outputs(out_dir, names)  # a folder or link under an output name
    refuse_folders_under(out_dir, names)  # a listed one made a folder: not once all is staged
    scene_dir = _demo_scene_dir()
    scene = load_scene(scene_dir)
    if scene.gt is None:
        raise CliError(f"the bundled demo scene in {scene_dir} lacks its ground truth")
    print(f"demo scene: Middlebury 2003 'Cones' ({scene_dir})")
    print("  (c) Scharstein & Szeliski, CVPR 2003; calibration nominal, see its README.md")
    from stereovision.rectification_check import check_rectification

    print(f"  {check_rectification(scene.left, scene.right, scene.calib).summary()}")
    res = depth_map(
        scene.left, scene.right, scene.calib, method=args.method, max_disparity=scene.max_disparity
    )
    from stereovision.render import render_outputs

    with staged_outputs(out_dir) as stage:  # moved in together, as depth's (depth_outputs)
        staged = write_depth_outputs(res, stage)
        staged.update(render_outputs(res, stage))
        staged.update(write_overview(res, stage, "cones (Middlebury 2003, the demo scene)"))
        kept_aside = _keep_foreign_aside(foreign, staged)
        written, removed = commit_outputs(out_dir, staged, earlier)
    raw = dense_metrics(res.disparity, scene.gt)
    from stereovision.baselines import opencv_sgbm, row_fill

    # A dense method's output is already filled (planes, then the row rule); one with holes
    # ("gabor") is shown with the reference row fill too, as the README's tables count it.
    bad2 = (
        f"bad-2.0 {raw.bad[2.0]:.1f} % (filled)"
        if raw.density >= 100.0
        else f"bad-2.0 {dense_metrics(row_fill(res.disparity), scene.gt).bad[2.0]:.1f} % with "
        f"row fill, {raw.bad[2.0]:.1f} % unfilled"
    )
    print(
        f"{args.method} on cones (max_disparity {res.max_disparity}): {bad2} "
        f"(density {raw.density:.1f} %, avgerr {raw.avgerr:.2f} px), "
        f"{sum(res.timings.values()):.2f} s"
    )
    # What the user has today, on the same pair: OpenCV's SGBM (evaluation.md's configuration),
    # as it comes and after the same reference row fill.
    t = time.perf_counter()
    sgbm = opencv_sgbm(scene.left, scene.right, res.max_disparity)
    t_sgbm = time.perf_counter() - t
    sg = dense_metrics(sgbm, scene.gt)
    print(
        f"  OpenCV StereoSGBM 3-way on the same pair: bad-2.0 {sg.bad[2.0]:.1f} % "
        f"(density {sg.density:.1f} %), {dense_metrics(row_fill(sgbm), scene.gt).bad[2.0]:.1f} % "
        f"with the row fill, {t_sgbm:.2f} s"
    )
    if res.depth is not None and scene.calib is not None:
        dm = depth_metrics(res.depth, gt_depth(scene.gt, scene.calib))
        print(
            f"  depth vs GT: median |dZ|/Z {dm.median_rel:.2f} %,"
            f" off by >5 % {dm.share_off_5:.1f} % over {dm.n} pixels;"
            f" {len(res.points)} points in the cloud"
        )
        print(f"  {_depth_coverage(res)}")
    print(f"outputs in {escaped(str(out_dir.resolve()))}:")
    for name, path in written.items():
        print(f"  {name:14s} {escaped(str(path))}")
    for path in removed:
        print(f"  removed {path.name} of an earlier run (not written by this one)")
    for name, kept in kept_aside:
        print(
            f"  the {name} that was there (no earlier run's output) is kept as {escaped(str(kept))}"
        )
    return 0


def _keep_foreign_aside(foreign: Sequence[Path], staged: dict[str, Path]) -> list[tuple[str, Path]]:
    """Copy aside (``NAME.previous.EXT``) each file of ``foreign`` that its staged output
    (``staged``, name -> new file) would replace with other bytes: a file holding the very
    bytes this run writes (the outputs of a demo before the manifest) loses nothing. Only the
    bytes count: one that differs in line endings alone (CRLF) is another file, kept. One gone
    since it was listed (the comparison comes after the matching) has nothing to keep.

    Returns
    -------
    list of (str, pathlib.Path)
        Each copied file's name and its copy.
    """
    from stereovision.io import _same_bytes, keep_previous

    kept = []
    for p in foreign:
        new = staged.get(p.name)
        try:
            if new is not None and _same_bytes(p, new):
                continue
        except FileNotFoundError:  # moved away while the scene was matched: nothing to keep
            continue
        copy = keep_previous(p)
        if copy is not None:
            kept.append((p.name, copy))
    return kept


def _eval_scene(scene: Any, method: str, with_opencv: bool, runs: int = 1) -> dict[str, Any]:
    """One scene's ``eval`` row; every ``*_ms`` is the median of ``runs`` interleaved runs.

    Ours, StereoBM and SGBM-3WAY run in turn (A, B, C, A, B, C, ...: evaluation.md "Speed"),
    ``runs`` times, after one untimed warm-up round when ``runs`` > 1 (evaluation.md: "median
    of >= 5 runs after a warm-up"; ``runs`` = 1 is one timed round, as before); the accuracy
    figures are those of the first round's outputs, so they do not depend on ``runs``.
    """
    from stereovision import baselines
    from stereovision.depth import depth_map
    from stereovision.evaluate import (
        dense_metrics,
        depth_metrics,
        gt_depth,
        saturated_gt_depth,
        table1_report,
    )

    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    md = scene.max_disparity
    calib = scene.calib if scene.calib is not None and scene.calib.rectified else None
    times: dict[str, list[float]] = {"ours": [], "bm": [], "sgbm": []}
    outputs: dict[str, Any] = {}

    def timed(name: str, run: Any) -> None:
        t = time.perf_counter()
        out = run()
        if warm:  # the warm-up round's time (first calls: thread pools, caches) is not kept
            times[name].append(1000 * (time.perf_counter() - t))
        outputs.setdefault(name, out)  # the first round's output is the one evaluated

    # StereoBM's block needs its range + 14 px of width: on a narrower scene the reference runs
    # on the widest range that fits (it refused, and the whole scene with it)
    bm_md = baselines.bm_reference_range(md, np.asarray(scene.left).shape[1])
    # a scene no higher than its block (or under 30 px wide) has none: ours and SGBM are
    # scored, StereoBM left out (its refusal failed the whole scene); cmd_eval says why
    shape = np.asarray(scene.left).shape
    with_bm = with_opencv and baselines.bm_reference_refusal(md, shape) is None
    warm = runs == 1
    for _ in range(runs if warm else runs + 1):
        timed(
            "ours",
            lambda: depth_map(
                scene.left,
                scene.right,
                calib,
                method=method,
                max_disparity=md,
                return_channels=method == "fused",
            ),
        )
        if with_bm:
            timed("bm", lambda: baselines.opencv_bm(scene.left, scene.right, bm_md))
        if with_opencv:
            timed("sgbm", lambda: baselines.opencv_sgbm(scene.left, scene.right, md))
        warm = True
    res = outputs["ours"]
    row: dict[str, Any] = {"scene": scene.name, "max_disparity": md, "method": method}
    row["ours"] = dense_metrics(res.disparity, scene.gt).as_dict()
    row["ours+fill"] = dense_metrics(baselines.row_fill(res.disparity), scene.gt).as_dict()
    row["ours_ms"] = float(np.median(times["ours"]))
    row["runs"] = runs
    sgbm = None
    if with_bm:
        row["bm_ms"] = float(np.median(times["bm"]))
        row["bm"] = dense_metrics(outputs["bm"], scene.gt).as_dict()
    if with_opencv:
        sgbm = outputs["sgbm"]
        row["sgbm_ms"] = float(np.median(times["sgbm"]))
        row["sgbm"] = dense_metrics(sgbm, scene.gt).as_dict()
        row["sgbm+fill"] = dense_metrics(baselines.row_fill(sgbm), scene.gt).as_dict()
    if calib is not None and res.depth is not None:
        zgt = gt_depth(scene.gt, calib)
        # a GT depth at float16's largest value (TartanAir's sky, 65504 m) is a clamp, not a
        # distance: scored, it took the validated matches' RMSE to 2060.75 % of the mean depth
        sky = saturated_gt_depth(zgt)
        if sky.any():  # said by _eval_summary; other scenes' rows as before
            row["gt_depth_saturated"] = int(np.count_nonzero(sky))
            zgt[sky] = np.nan
        row["depth"] = depth_metrics(res.depth, zgt).as_dict()
        if sgbm is not None:
            row["sgbm_depth"] = depth_metrics(calib.depth_from_disparity(sgbm), zgt).as_dict()
        # no pixel with both depths (ours has none where the GT is known): no points to draw,
        # the depth figures say n = 0 and the scene's other figures stand
        if row["depth"]["n"] > 0:
            rep = table1_report(res.depth, zgt, n_points=10, seed=0)
            row["table1"] = rep.as_dict()
            row["_table1_text"] = rep.format()
        # The same test on the three channels' validated matches (algorithms.md D): the fused
        # run's own members, else a fusion run for them.
        from stereovision._validate import as_gray_float
        from stereovision.matching.fusion import _members_in_range, fuse_pair

        if res.channels is not None:
            fused = res.channels["members"]
        else:
            gl = as_gray_float(scene.left, "left")
            gr = as_gray_float(scene.right, "right")
            # the fused run's members, those in the range searched (another method's report
            # kept those past it: playground at 17 px, 8324 members with a depth for 8172)
            fused = _members_in_range(fuse_pair(gl, gr, max_disparity=md), 0.0, float(md))
        z_members = calib.depth_from_disparity(fused.dispx)
        row["members_depth"] = depth_metrics(z_members, zgt).as_dict()
        # members under 1 px of disparity: a pixel's error is the whole distance there, and
        # one (playground, 0.74 px: 43.9 m for 8.6 m) took the members' RMSE from 6.30 % to
        # 10.16 %; the figures without them are said beside, the members' own unchanged
        near = np.where(fused.dispx >= 1.0, z_members, np.nan)
        row["members_depth_1px"] = depth_metrics(near, zgt).as_dict()
        if row["members_depth"]["n"] > 0:
            rep = table1_report(z_members, zgt, n_points=10, seed=0)
            row["members_table1"] = rep.as_dict()
            row["_members_table1_text"] = rep.format()
    return row


def _fmt_dense(m: dict[str, Any]) -> str:
    return f"{m['bad_2.0']:6.1f} {m['bad_1.0']:6.1f} {m['density']:6.1f}"


def _eval_time_line(row: dict[str, Any]) -> str:
    """An ``eval`` row's times in one line: ours, then OpenCV's and our ratio to SGBM-3WAY's.

    Parameters
    ----------
    row : dict
        A row of :func:`_eval_scene` (``ours_ms``, ``runs``; ``bm_ms``, ``sgbm_ms`` unless
        ``--no-opencv``).

    Returns
    -------
    str
        For example ``cones: time, median of 5 runs after a warm-up: ours 301.2 ms, StereoBM
        4.1 ms, SGBM-3WAY 14.0 ms (ours 21.5 x SGBM-3WAY)``.
    """
    runs = row["runs"]
    how = "one run, no warm-up" if runs == 1 else f"median of {runs} runs after a warm-up"
    line = f"{escaped(row['scene'])}: time, {how}: ours {row['ours_ms']:.1f} ms"
    if "bm_ms" in row:  # none on a scene StereoBM cannot run on
        line += f", StereoBM {row['bm_ms']:.1f} ms"
    if "sgbm_ms" in row:
        line += (
            f", SGBM-3WAY {row['sgbm_ms']:.1f} ms"
            f" (ours {row['ours_ms'] / row['sgbm_ms']:.1f} x SGBM-3WAY)"
        )
    return line


def middlebury_gt_hint(folder: Path) -> str:
    """What ``eval`` and ``bench`` add to the words of a scene without ``gt_disp.pfm`` whose
    GT kept Middlebury's (and ETH3D's) name, ``disp0GT.pfm`` or ``disp0.pfm`` (its images
    renamed, its GT not): ``"; it holds Middlebury's disp0GT.pfm: rename it gt_disp.pfm"``,
    or ``""`` (it was "no ground truth" without a word on the file beside them)."""
    named = [n for n in ("disp0GT.pfm", "disp0.pfm") if (folder / n).is_file()]
    return f"; it holds Middlebury's {named[0]}: rename it gt_disp.pfm" if named else ""


def scene_failed_line(folder: Path, error: BaseException) -> str:
    """The line saying one damaged scene of many (``eval``, ``bench``) failed, its folder named
    once: a message that names it already (a scene too narrow for its range, load_scene's
    ``scene FOLDER: gt_disp.pfm is ...``) is said without that name."""
    # a folder named with a newline cut the line in two (batch escapes its pairs' names)
    said, shown = escape_paths(str(error), [folder]), escaped(str(folder))
    # 'failed X: scene X: gt_disp.pfm is 299x200, left.png 300x200' named it twice
    for named in (f"{shown}: ", f"scene {shown}: "):
        said = said.removeprefix(named)
    return f"failed {shown}: {said}"


def _members_line(name: str, row: dict[str, Any]) -> str:
    """An ``eval`` row's line of the validated matches' depth figures (``members_depth``), the
    members under 1 px of disparity counted and the RMSE without them (``members_depth_1px``)
    said when there are any, and SGBM-3WAY's RMSE beside.

    Parameters
    ----------
    name : str
        The scene's name as shown.
    row : dict
        A row of :func:`_eval_scene` with ``members_depth``.

    Returns
    -------
    str
        The line.
    """
    m = row["members_depth"]
    line = f"{name}: validated matches (>= 2 of Gabor, MCGM, Hopfield agree)" + (
        f" with GT depth: {m['n']}, RMSE {m['rmse_pct']:.2f} % of the mean depth,"
        f" median |dZ|/Z {m['median_rel']:.2f} %"
        if m["n"]
        else ": none has a GT depth"
    )
    near = row.get("members_depth_1px")
    if m["n"] and near is not None and near["n"] < m["n"]:
        without = f"{near['rmse_pct']:.2f} %" if near["n"] else "none left"
        line += (
            f" ({m['n'] - near['n']} under 1 px of disparity, where a pixel's error is the "
            f"whole distance; RMSE without them: {without})"
        )
    if "sgbm_depth" in row and row["sgbm_depth"]["n"]:  # else said on the depth line
        line += f"; SGBM-3WAY's RMSE {row['sgbm_depth']['rmse_pct']:.2f} %"
    return line


def _saturated_line(name: str, row: dict[str, Any]) -> str:
    """An ``eval`` row's line saying how many GT pixels hold a depth at float16's largest
    value (``gt_depth_saturated``), left out of its depth figures and Table-1 tests.

    Parameters
    ----------
    name : str
        The scene's name as shown.
    row : dict
        A row of :func:`_eval_scene` with ``gt_depth_saturated`` and ``ours`` (``n_gt``).

    Returns
    -------
    str
        The line.
    """
    n, known = row["gt_depth_saturated"], row["ours"]["n_gt"]
    return (
        f"{name}: GT depth: {n} of {known} known pixels ({100.0 * n / known:.1f} %) are at "
        "65504 m, float16's largest value (sky: a clamp, not a distance); the depth figures "
        "and Table-1 tests leave them out, the disparity figures keep them"
    )


def _eval_summary(rows: list[dict[str, Any]], timed: bool) -> None:
    """Print ``eval``'s lines after its table: the mean bad-2.0 line, then per scene the time
    line (``timed``: ``--runs`` given), the depth line and the Table-1 reports."""
    # the table's columns, SGBM-3WAY + fill included (the reference a dense map must beat)
    columns = {
        "ours": "ours",
        "ours+fill": "ours+fill",
        "bm": "StereoBM",
        "sgbm": "SGBM-3WAY",
        "sgbm+fill": "SGBM+fill",
    }
    mean = {
        name: float(np.mean([r[k]["bad_2.0"] for r in rows]))
        for k, name in columns.items()
        if all(k in r for r in rows)
    }
    # a scene StereoBM cannot run on drops StereoBM's mean for the run: say so rather than leave
    # the run's other scenes' figures out without a word
    bm_missing = sum("sgbm" in r and "bm" not in r for r in rows)
    bm_note = (
        f"; StereoBM: no mean (no figures for {bm_missing} of {len(rows)} scenes)"
        if 0 < bm_missing < len(rows)
        else ""
    )
    print("mean bad-2.0: " + ", ".join(f"{k} {v:.1f} %" for k, v in mean.items()) + bm_note)
    for r in rows:
        name = escaped(r["scene"])  # a newline in it cut the line in two
        if timed:  # asked for: the medians, as --json has them
            print(_eval_time_line(r))
        if "gt_depth_saturated" in r:
            print(_saturated_line(name, r))
        if "depth" in r:
            dm = r["depth"]
            line = (
                f"{name}: depth over our {dm['n']} pixels:"
                f" median |dZ|/Z {dm['median_rel']:.2f} %, off >5 % {dm['share_off_5']:.1f} %"
                if dm["n"]
                else f"{name}: depth: none of our pixels has a GT depth"
            )
            if "sgbm_depth" in r:
                s = r["sgbm_depth"]
                line += (
                    f"; SGBM-3WAY over {s['n']}: {s['median_rel']:.2f} %, {s['share_off_5']:.1f} %"
                    if s["n"]
                    else "; SGBM-3WAY: none of its pixels has a GT depth"
                )
            print(line)
            if "_table1_text" in r:
                print(r["_table1_text"])
        if "members_depth" in r:
            print(_members_line(name, r))
            if "_members_table1_text" in r:
                print(r["_members_table1_text"])


def cmd_eval(args: argparse.Namespace) -> int:
    """``stereovision eval SCENE_DIR...``: evaluation.md metrics, ours beside OpenCV."""
    from tqdm import tqdm

    from stereovision.baselines import bm_reference_refusal
    from stereovision.evaluate import gt_at_zero_note
    from stereovision.io import (
        _no_scene_under,
        distinct_scenes,
        load_scene,
        scan_scenes,
        scene_names,
        scene_too_narrow,
    )

    dirs: list[Path] = []
    for d in args.scenes:
        p = Path(d)
        if not p.exists():
            from stereovision.io import _broken_link

            # a link whose target moved (a dataset on a disk since unmounted): its target named
            gone = f" ({_broken_link(p)})" if p.is_symlink() else ""
            raise FileNotFoundError(f"scene folder not found: {d}{gone}")
        if not p.is_dir():  # find_scenes said "scene root not found" of an existing image
            # /dev/null or a pipe is no file either (load_scene's words, aae87eaf)
            what = "is a file" if p.is_file() else "is not a folder (a device or a pipe)"
            raise CliError(f"{d}: {what}; give a scene folder (holding left.png, right.png)")
        found, half = scan_scenes(p)
        if not found:
            raise CliError(_no_scene_under(p, d, half))
        # half a scene among scenes was left out without a word (batch says it is unpaired)
        for folder, reason in half:
            print(f"stereovision: skipped {escaped(str(folder))}: {reason}", file=sys.stderr)
        dirs.extend(found)
    # a scene named twice (its folder and a folder holding it) is evaluated once: twice, it
    # counted twice in the mean line
    dirs, dropped = distinct_scenes(dirs)
    for s in dropped:
        print(
            f"stereovision: {escaped(str(s))} given more than once: evaluated once", file=sys.stderr
        )
    # two scenes of one family/scene name (day1/cam/0001, day2/cam/0001) shared a name in the
    # table, the JSON lines and the depth lines: each is named by as many parents as needed
    names = dict(zip(dirs, scene_names(dirs), strict=True))
    rows = []
    # the scene column as wide as the longest name (38 at least): a longer one pushed its row's
    # figures out from under their labels
    col = max([38] + [len(escaped(n)) for n in names.values()])
    # --no-opencv: no OpenCV columns (three blank ones under their names read as OpenCV
    # having failed on every scene)
    titles = ["ours", "ours+fill"] + (
        [] if args.no_opencv else ["StereoBM", "SGBM-3WAY", "SGBM+fill"]
    )
    header = f"{'scene':{col}s} {'D':>4s} | " + " | ".join(f"{t:^20s}" for t in titles)
    # each column's three labels over its three numbers (_fmt_dense: 6 characters each)
    labels = f"{'bad-2':>6s} {'bad-1':>6s} {'dens':>6s}"
    sub = f"{'':{col}s} {'':>4s} | " + " | ".join([labels] * len(titles))
    quiet = args.json or len(dirs) < 2 or not sys.stderr.isatty()
    failed: list[str] = []
    skipped = 0
    try:
        for d in tqdm(dirs, desc="scenes", file=sys.stderr, disable=quiet):
            try:
                scene = load_scene(d, full_bits=True)  # as `depth` reads a 16-bit pair
                scene.name = names[d]
                # a GT map with no known pixel (all +inf) is no ground truth either: its figures
                # would all be NaN (and NaN in the --json line, which is not JSON)
                why = (
                    "no ground truth (gt_disp.pfm)"
                    if scene.gt is None
                    else None
                    if np.isfinite(scene.gt).any()
                    else "no ground truth: gt_disp.pfm has no known (finite) pixel"
                )
                hint = middlebury_gt_hint(d) if scene.gt is None else ""
                if why is not None:
                    if len(dirs) == 1:
                        raise CliError(f"{d}: {why} to evaluate against{hint}")
                    tqdm.write(f"skipped {escaped(str(d))}: {why}{hint}", file=sys.stderr)
                    skipped += 1
                    continue
                # a GT converted keeping KITTI's 0 = unknown was scored against its 0s silently
                zero_note = gt_at_zero_note(scene.gt)
                if zero_note is not None:
                    tqdm.write(f"stereovision: {escaped(str(d))}: {zero_note}", file=sys.stderr)
                narrow = scene_too_narrow(scene)
                if narrow:
                    # the range is evaluation.md's, never the caller's: "disparity range 16 is not
                    # smaller than the image width 8" named a range nobody gave
                    raise ValueError(f"{d}: {narrow}")
                row = _eval_scene(scene, args.method, not args.no_opencv, args.runs or 1)
            except BUG_ERRORS:  # RuntimeErrors, but a bug of ours: not one damaged scene of many
                raise
            except (ValueError, OSError, RuntimeError) as e:
                if len(dirs) == 1:
                    raise
                # one damaged scene of many: say so and go on (the exit status says it at the end)
                failed.append(str(d))
                tqdm.write(scene_failed_line(d, e), file=sys.stderr)
                continue
            rows.append(row)
            if "sgbm" in row and "bm" not in row:  # StereoBM cannot run on it: say why it is blank
                no_bm = bm_reference_refusal(scene.max_disparity, scene.left.shape)
                tqdm.write(f"{escaped(str(d))}: no StereoBM figures: {no_bm}", file=sys.stderr)
            # each scene's line out as it is made (as bench's and stream's): in a pipe or a file
            # they waited in the buffer, lost to a kill (the OOM killer, a CI timeout) on a later
            # scene, and a reader saw nothing of a run of minutes until its end
            if args.json:
                line = json_line({k: v for k, v in row.items() if not k.startswith("_")})
                print(line, flush=True)
                continue
            if len(rows) == 1:  # the header over the first row: none over an error alone
                tqdm.write(header)
                tqdm.write(sub)
            cells = [_fmt_dense(row["ours"]), _fmt_dense(row["ours+fill"])]
            for key in () if args.no_opencv else ("bm", "sgbm", "sgbm+fill"):
                cells.append(_fmt_dense(row[key]) if key in row else " " * 20)
            name = escaped(row["scene"])  # one line, as the other lines name it
            tqdm.write(f"{name:{col}s} {row['max_disparity']:4d} | " + " | ".join(cells))
            sys.stdout.flush()
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM (Terminated): the scenes evaluated are kept
        # the mean, time and depth lines come after the loop: the medians of the scenes timed
        # were lost (bench keeps its scenes' timing likewise)
        if not args.json and rows:  # --json printed each scene's line as it went
            _eval_summary(rows, args.runs is not None)
        raise
    status = 0
    if failed:
        print(f"stereovision: {len(failed)} of {len(dirs)} scenes failed (above)", file=sys.stderr)
        status = 1
    elif skipped == len(dirs):  # nothing evaluated is not a success
        raise CliError(f"none of the {len(dirs)} scenes has ground truth to evaluate against")
    if args.json or not rows:
        return status
    _eval_summary(rows, args.runs is not None)
    return status


# ----------------------------------------------------------------------------- entry point


def positive_pixels(text: str) -> int:
    """argparse type of ``--max-disparity``: a whole number of pixels above 0.

    Refused by argparse in the option's name (``argument --max-disparity: ...``), not later by
    ``depth_map`` in its parameter's.
    """
    return _whole_above_zero(text, "a whole number of pixels above 0")


def pixel_tolerance(text: str) -> float:
    """argparse type of ``check --tolerance``: a finite number of pixels above 0, refused in
    the option's name with the value as typed (``1e400`` was said as "got inf", after the
    parsing)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a positive number of pixels, got {text!r}")
    return value


def positive_count(text: str) -> int:
    """argparse type of a count (``--frames``, ``--every``, ``--check-every``): a whole number
    above 0, refused in the option's name (the library's parameter name, ``frames:`` or
    ``check_every:``, was what the CLI said)."""
    return _whole_above_zero(text, "a whole number above 0")


#: Most timed rounds ``eval --runs`` and ``bench --runs`` take: generous (evaluation.md asks for
#: >= 5), while a typo's ``--runs 100000`` ran for days and ``--runs`` of 20 digits until killed.
MAX_RUNS = 1000


def run_count(text: str) -> int:
    """argparse type of ``eval --runs``: a whole number from 1 to :data:`MAX_RUNS`, refused in
    the option's name (any count was taken: 10**20 ran until killed)."""
    value = positive_count(text)
    if value > MAX_RUNS:
        raise argparse.ArgumentTypeError(f"expected at most {MAX_RUNS} runs, got {text!r}")
    return value


#: A whole number as typed: digits, a point and zeros after them or not (``64``, ``64.0``).
_WHOLE_TEXT = re.compile(r"\s*([-+]?\d+)(?:\.0*)?\s*")


def whole_number(text: str) -> int | None:
    """The whole number ``text`` writes, else None: ``64`` and ``64.0`` alike, as the library
    takes ``64.0`` (:func:`~stereovision._validate.whole_value`); ``64.5``, ``nan`` and words
    none, nor an exponent (``1e400`` is no count to take as 401 digits). One rule for every
    whole-number option: ``--max-disparity 64.0`` was refused as "expected a whole number"."""
    typed = _WHOLE_TEXT.fullmatch(text)
    try:
        return int(typed[1] if typed else text)  # int's own reading too (1_000)
    except ValueError:  # no number, or past Python's 4300 digits
        return None


def _typed_int(text: str) -> int:
    """argparse's ``type=int`` in :class:`_Parser`: :func:`whole_number`'s rule, so that the
    plain ``type=int`` options (``--workers``, ``--max-pairs``, ``--count``, ``--port``) take
    ``64.0`` as every other whole-number option does; refused as argparse refuses ``int``."""
    value = whole_number(text)
    if value is None:
        raise ValueError(text)
    return value


def _whole_above_zero(text: str, what: str) -> int:
    value = whole_number(text)
    if value is None or value < 1:
        raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}")
    return value


#: A number with a unit after it (``5m``, ``-50 cm``, ``2ft``, ``5'``): the metre options take
#: none.
_UNIT_SUFFIXED = re.compile(
    r"^\s*[-+]?(\d+\.?\d*|\.\d+)(e[-+]?\d+)?\s*([a-z]+|'|\")\s*$", re.IGNORECASE
)


#: The unit of each number option whose value is not metres nor a count, for the hint that
#: leaves a typed unit out (``--max-skew-ms 5ms``); the metre options say theirs themselves.
_OPTION_UNITS = {
    "--fps": "fps",
    "--read-timeout": "s",
    "--max-skew-ms": "ms",
    "--max-disparity": "px",
    "--tolerance": "px",
    "--hfov": "degrees",
    "--roll": "degrees",
    "--pitch": "degrees",
    "--yaw": "degrees",
    "--forward": "m",
    "--up": "m",
    "--right": "m",
    "--dpi": "dpi",
}


def _with_unit_hint(message: str) -> str:
    """argparse's refusal of an option's value, with the hint the metre options give
    (``without a unit (5 for 5 m)``) when the value was typed with a unit (``--fps 30fps``,
    ``--square 25mm``, ``--count 10x``); a message holding its own hint is kept.

    Parameters
    ----------
    message : str
        ``argument --opt: expected ..., got 'VALUE'`` (other messages are returned as given).

    Returns
    -------
    str
        The message, the hint before its ``, got``.
    """
    m = re.fullmatch(r"argument (\S+): (expected .*?), got ('.*'|\".*\")", message)
    if m is None or "unit" in m[2]:
        return message
    try:
        typed = ast.literal_eval(m[3])
    except (ValueError, SyntaxError):
        return message
    if not (isinstance(typed, str) and _UNIT_SUFFIXED.match(typed)):
        return message
    unit = _OPTION_UNITS.get(m[1].split("/")[-1])
    if unit == "m":  # view's moves, either way: 2ft said in metres, as the metre options say it
        from stereovision.render import VIEW_MAX_MOVE_M

        hint = _metres_hint(typed, signed=True, within=(-VIEW_MAX_MOVE_M, VIEW_MAX_MOVE_M))
        return f"argument {m[1]}: {m[2]}{hint}, got {m[3]}"
    example = f" (5 for 5 {unit})" if unit else ""
    return f"argument {m[1]}: {m[2]} without a unit{example}, got {m[3]}"


#: Narrowest and widest ``info --hfov`` (degrees): a rig on paper's pinhole cameras. A 1200 mm
#: telephoto on a full-frame sensor sees 1.7 degrees, a superzoom's long end about 0.7; 180 and
#: over is no pinhole's (a fisheye's 170 is said as the rectified pinhole pair would be). Below
#: 0.1 the focal length runs away (1e-300: 7e305 px and a depth of 9e302 m said, exit 0).
HFOV_RANGE_DEG = (0.1, 180.0)


def field_of_view(text: str) -> float:
    """argparse type of ``info --hfov``: degrees from 0.1 up to (not including) 180, refused in
    the option's name with the range (``1e-300`` was taken and said as absurd figures)."""
    lo, hi = HFOV_RANGE_DEG
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not lo <= value < hi:  # NaN too
        raise argparse.ArgumentTypeError(
            f"expected a horizontal field of view from {lo:g} to under {hi:g} degrees, got {text!r}"
        )
    return value


def positive_metres(text: str) -> float:
    """argparse type of ``--max-depth``, ``--max-sigma`` and ``--voxel``: a finite
    number of metres above 0, as a plain number.

    Refused by argparse in the option's name: ``5m`` was "expected a number", ``-5`` "expected
    a positive finite number" only after the images were read, and neither said the unit.
    """
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(
            f"expected a number of metres above 0{_metres_hint(text)}, got {text!r}"
        )
    return value


def metres(text: str, within: tuple[float, float] | None = None) -> float:
    """argparse type of a length option: a number of metres, as a plain number (its range is
    checked with the other options); ``5m`` said only "expected a number". ``within``: the
    option's range, which the hint for a value typed with a unit keeps to (:func:`_metres_hint`).
    """
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a number of metres{_metres_hint(text, within=within)}, got {text!r}"
        ) from None


#: Smallest and largest ``depth --grid`` cell side, in metres.
GRID_CELL_M = (0.01, 10.0)


def _past_float(text: str, value: float) -> bool:
    """Whether ``value``, ``float(text)``, is not the number typed: past the largest float
    (``1e400`` read as inf) or below the smallest (``1e-400`` read as 0)."""
    if math.isinf(value):
        return "inf" not in text.lower()
    return value == 0 and re.search(r"[1-9]", re.split(r"[eE]", text)[0]) is not None


def cell_metres(text: str) -> float:
    """argparse type of ``depth --grid``: :func:`metres` (its range is checked with the other
    options, in :func:`run_depth`) whose unit hint keeps to :data:`GRID_CELL_M`: ``50ft`` was
    told "give 15.24", which the option then refused. A value past any float (``1e400``,
    ``1e-400``) is refused here, as typed: after the parsing it was said as "got inf" ("0.0")."""
    value = metres(text, within=GRID_CELL_M)
    if _past_float(text, value):
        lo, hi = GRID_CELL_M
        raise argparse.ArgumentTypeError(
            f"expected a cell side from {lo:g} to {hi:g} m, got {text!r}"
        )
    return value


#: The length units typed as a mark: 5' is 5 ft, 5" 5 in.
_UNIT_MARKS = {"'": "ft", '"': "in"}


def _metres_hint(text: str, signed: bool = False, within: tuple[float, float] | None = None) -> str:
    """The hint of a metre option's refusal of ``text`` typed with a unit: a positive length
    (any nonzero one for a ``signed`` option: ``view --forward -2ft``) in another unit of
    :data:`~stereovision.calibration.UNIT_TO_METRES` said in metres (``5ft`` -> `` without a
    unit (5 ft is 1.524 m: give 1.524)``), since "5 for 5 m" sent the user to 5 m; any other
    unit word ``(5 for 5 m)``; no unit, nothing. A length outside the option's range
    ``within`` (metres, inclusive) is said with that range, not as a value to give (``--grid
    50ft`` was told "give 15.24", past its 10 m)."""
    from stereovision.calibration import UNIT_TO_METRES

    typed = _UNIT_SUFFIXED.match(text)
    if typed is None:
        return ""
    unit = _UNIT_MARKS.get(typed[3], typed[3].lower())
    value = float(text.strip()[: -len(typed[3])])
    length = math.isfinite(value) and (value != 0 if signed else value > 0)
    if unit == "m" or unit not in UNIT_TO_METRES or not length:
        return " without a unit (5 for 5 m)"
    in_metres = value * UNIT_TO_METRES[unit]
    shown = f"{in_metres:g}"
    if within is not None and not within[0] <= in_metres <= within[1]:
        lo, hi = within
        return f" without a unit ({value:g} {unit} is {shown} m, outside {lo:g} to {hi:g} m)"
    return f" without a unit ({value:g} {unit} is {shown} m: give {shown})"


def positive_rate(text: str) -> float:
    """argparse type of ``--fps``: a finite number above 0, refused in the option's name (it
    was the library's ``fps: expected a positive number``, after the parsing)."""
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a frame rate above 0, got {text!r}")
    return value


def skew_ms(text: str) -> float:
    """argparse type of ``--max-skew-ms``: milliseconds from 0 to
    :data:`~stereovision.rosbag.MAX_SKEW_MS`, refused in the option's name (``nan`` and ``-5``
    were the library's ``max_skew_ms: ...``, ``1e308`` an internal OverflowError)."""
    from stereovision.rosbag import MAX_SKEW_MS

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 <= value <= MAX_SKEW_MS:  # NaN too
        raise argparse.ArgumentTypeError(
            f"expected milliseconds from 0 to {MAX_SKEW_MS:g}, got {text!r}"
        )
    return value


#: ``--read-timeout``'s spelling of "no limit" (a camera's read waits as long as it takes).
NO_READ_TIMEOUT = "none"

#: Longest ``--read-timeout`` (seconds): a day, far past any camera's cold start; a longer
#: wait is meant as no limit, which is ``none`` (1e10 overflowed the wait: an internal error).
MAX_READ_TIMEOUT_S = 86400.0


def read_timeout_seconds(text: str) -> float:
    """argparse type of ``--read-timeout``: seconds above 0, up to a day
    (:data:`MAX_READ_TIMEOUT_S`), or ``none`` (no limit).

    Refused in the option's name, as ``--fps`` is. ``0`` is refused, not read as "no limit":
    the library refuses it too, and a word of its own cannot be mistaken for a short wait.

    Parameters
    ----------
    text : str
        The option's value.

    Returns
    -------
    float
        The seconds; ``math.inf`` for ``none``
        (:func:`stereovision.capture.cli_read_timeout` makes it None).
    """
    if text.strip().lower() == NO_READ_TIMEOUT:
        return math.inf
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(
            f"expected seconds above 0 or {NO_READ_TIMEOUT!r} (no limit), got {text!r}"
        )
    if value > MAX_READ_TIMEOUT_S:
        raise argparse.ArgumentTypeError(
            f"expected at most {MAX_READ_TIMEOUT_S:g} seconds (a day), or {NO_READ_TIMEOUT!r} "
            f"for no limit, got {text!r}"
        )
    return value


#: What a port option takes, as ``stream --serve`` and ``gui --port`` refuse another value.
PORT_WORDS = "expected a port 1 to 65535, or 0 for a free one"


def port_number(text: str) -> int:
    """argparse type of ``--serve``: a TCP port, 0 (any free one) to 65535."""
    whole = whole_number(text)  # 8080.0 too, as gui --port (type=int) and every count
    value, shown = (-1, repr(text)) if whole is None else (whole, str(whole))
    if not 0 <= value <= 65535:
        # in gui --port's words (PORT_WORDS): one wording for both options
        raise argparse.ArgumentTypeError(f"{PORT_WORDS}, got {shown}")
    return value


def listen_address(text: str) -> str:
    """argparse type of ``stream --host`` and ``gui --host``: an address to listen on, not
    empty (an empty one binds every interface: ``--host "$HOST"`` with the variable unset);
    an IPv6 one may come in a URL's brackets (``[::1]``), given without them."""
    try:
        return check_listen_address(text)
    except ValueError:
        raise argparse.ArgumentTypeError(_listen_address_words(text)) from None


def _listen_address_words(text: object) -> str:
    return (
        "expected an address to listen on (127.0.0.1: this machine alone; 0.0.0.0: every "
        f"interface), got {text!r}"
    )


def check_listen_address(host: str, name: str = "--host") -> str:
    """``host`` when it is an address to listen on, an IPv6 one in a URL's brackets
    (``[::1]``) without them; ValueError (naming ``name``) for an empty or blank one, which a
    bind takes for every interface (0.0.0.0), or one holding a space or control character."""
    # "127.0.0.1\n" (a host read from a file) reached the bind, and its error was cut at
    # the newline: no address holds one, and said as repr the refusal is one line
    if (
        not isinstance(host, str)
        or not host.strip()
        or any(c.isspace() or not c.isprintable() for c in host)
    ):
        raise ValueError(f"{name}: {_listen_address_words(host)}")
    if "[" in host or "]" in host:
        # "[::1]" as a URL writes it was bound as a host name (not found) and said
        # "[[::1]]:8765"; the address is inside. No name holds a bracket, so anything else
        # ("[::1", "[]", "[127.0.0.1]", "[::1]:8080") was bound, after the cameras opened
        import ipaddress

        inner = host[1:-1] if host.startswith("[") and host.endswith("]") else ""
        try:
            ipaddress.IPv6Address(inner)  # a scope too: fe80::1%eth0
            if "[" in inner or "]" in inner:  # ipaddress takes any scope: "fe80::1%]"
                raise ValueError(inner)
        except ValueError:
            raise ValueError(f"{name}: {_listen_address_words(host)}") from None
        return inner
    return host


class _Parser(argparse.ArgumentParser):
    """argparse with its errors in one line, as the command's own (not the usage block)."""

    #: The words this parser (a subcommand's: those after its name) was given, for error().
    typed: tuple[str, ...] = ()

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        # type=int read as the other whole-number options: --workers 2.0 was refused
        self.register("type", int, _typed_int)

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: Any = None
    ) -> tuple[Any, list[str]]:
        self.typed = tuple(sys.argv[1:] if args is None else args)
        namespace, extras = super().parse_known_args(args, namespace)
        self._refuse_empty_values(namespace)
        return namespace, extras

    def parse_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: Any = None
    ) -> Any:
        """argparse's, but words no option took are refused by the command they were typed
        to: ``stereovision info ... --max-disparity 64`` said "stereovision: error:
        unrecognized arguments: --max-disparity (see stereovision --help)", the help of the
        command list, and a mistyped option (``--maxdisparity``) was not named."""
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            subs = [a for a in self._actions if isinstance(a, argparse._SubParsersAction)]
            command = getattr(parsed, subs[0].dest, None) if subs else None
            by = subs[0].choices.get(command, self) if isinstance(command, str) else self
            known = [o for a in by._actions for o in a.option_strings if o.startswith("--")]
            typed = [w.split("=")[0] for w in extras if w.startswith("--")]
            near = [m for w in typed for m in difflib.get_close_matches(w, known, n=1)]
            hint = f"; did you mean {', '.join(dict.fromkeys(near))}?" if near else ""
            by.error(f"unrecognized arguments: {' '.join(extras)}{hint}")
        return parsed

    def _refuse_empty_values(self, namespace: Any) -> None:
        """An empty value typed for a path, source, topic or pattern (``-o "$OUT"``, ``batch
        "$DATA"`` with the variable unset) was taken as the current folder: ``batch ''``
        processed the folder it was run in, ``-o ''`` wrote there, ``--calib ''`` loaded the
        Q.dat found there. Refused here, before any work; the options with a type of their
        own (``--host``, numbers) say it in their own words."""
        for action in self._actions:
            if action.type is not None or action.choices is not None or action.nargs == 0:
                continue
            value = getattr(namespace, action.dest, None)
            if value == "" or (isinstance(value, list) and "" in value):
                name = "/".join(action.option_strings) or action.metavar or action.dest
                self.error(f"argument {name}: expected a value, got '' (an unset variable?)")

    def error(self, message: str) -> NoReturn:
        # argparse names the Python type ("invalid float value: 'abc'"): said as what to type.
        # The value is in repr's quotes: double ones when it holds a ' ("5'", feet)
        message = re.sub(
            r"invalid (float|int) value: ('.*'|\".*\")$",
            lambda m: f"expected a {'number' if m[1] == 'float' else 'whole number'}, got {m[2]}",
            message,
        )
        one = re.fullmatch(r"argument (\S+): expected one argument", message)
        if one is not None:
            message = self._dash_value(one[1]) or message
        missing = "the following arguments are required: right"
        if message == missing or message.startswith(f"{missing}, "):
            message = self._folder_for_a_pair(message, message[len(missing) + 2 :])
        # a path typed with a newline in it (or a tab, an ESC) is shown escaped, on the one line
        message = first_line(ValueError(_with_unit_hint(message)), self.typed)
        sys.stderr.write(f"{self.prog}: error: {message} (see {self.prog} --help)\n")
        sys.exit(EXIT_ERROR)

    def _dash_value(self, names: str) -> str | None:
        """``--max-depth -5m``: argparse takes a value starting with ``-`` (other than a plain
        negative number) for an option, and says only "expected one argument". The line for the
        value typed after option ``names`` (argparse's ``-o/--output``): the option's own
        refusal of it, else how to give it; None when no such value was typed."""
        action = next(
            (a for a in self._actions if "/".join(a.option_strings) == names and a.nargs is None),
            None,
        )
        if action is None:
            return None
        for word, value in zip(self.typed, self.typed[1:], strict=False):
            # the option as typed, or by a unique prefix (--max-d), as argparse takes it
            hits = [s for s in self._option_string_actions if s.startswith(word)]
            named = word in action.option_strings or (
                word.startswith("--")
                and self.allow_abbrev
                and hits
                and all(self._option_string_actions[s] is action for s in hits)
            )
            if not (named and value.startswith("-") and len(value) > 1):
                continue
            if self._names_an_option(value):
                # `-o --calib rig.yaml`: the value was left out, not typed with a '-'; argparse's
                # "expected one argument" says so (not "give it as --output=--calib")
                return None
            if action.type in (int, float):  # a plain number type: said as _Parser.error does
                try:
                    action.type(value)
                except ValueError:
                    kind = "number" if action.type is float else "whole number"
                    return f"argument {names}: expected a {kind}, got {value!r}"
            elif callable(action.type) and action.type is not str:
                try:
                    action.type(value)
                except (argparse.ArgumentTypeError, ValueError) as exc:
                    return f"argument {names}: {exc}"
            return (
                f"argument {names}: {value!r} starts with '-' and was taken for an option; "
                f"give it as {max(action.option_strings, key=len)}={value}"
            )
        return None

    def _names_an_option(self, word: str) -> bool:
        """Whether argparse reads ``word`` as one of this parser's options: by its name, its
        ``--name=value`` form, a unique prefix of a long one (``--cal``) or a short one with its
        value attached (``-oout``)."""
        name = word.split("=", 1)[0] if word.startswith("--") else word
        if name in self._option_string_actions:
            return True
        if word.startswith("--"):
            known = self._option_string_actions
            return self.allow_abbrev and any(s.startswith(name) for s in known)
        return word[:2] in self._option_string_actions

    def _words_given(self) -> list[str]:
        """The words typed that are no option nor an option's value."""
        words: list[str] = []
        i = 0
        while i < len(self.typed):
            word = self.typed[i]
            if word == "--":  # argparse: every word after it is a positional
                words.extend(self.typed[i + 1 :])
                break
            action = self._option_string_actions.get(word)
            if action is None and self.allow_abbrev and word.startswith("--") and "=" not in word:
                # argparse takes an option by a unique prefix (--meth census): its value too
                hits = {a for s, a in self._option_string_actions.items() if s.startswith(word)}
                action = hits.pop() if len(hits) == 1 else None
            if action is not None:  # an option: its value (if it takes one) follows
                i += 1 if action.nargs == 0 else 2
                continue
            if not word.startswith("-"):  # (--opt=value is one word)
                words.append(word)
            i += 1
        return words

    def _folder_for_a_pair(self, message: str, also: str) -> str:
        """``stereovision depth cones -o out``: one positional, a scene folder (as eval and
        batch take it). argparse said only that ``right`` is required; the folder's two images
        are what to type (as imread says of a folder given as an image)."""
        from stereovision.io import _folder_pair, _no_single_pair

        given = self._words_given()
        if len(given) != 1 or not os.path.isdir(given[0]):
            return message
        pair = _folder_pair(given[0])
        also = f" (also required: {also})" if also else ""
        if pair is None:  # argparse's "required: right" did not say the folder was the problem
            what, detail = _no_single_pair(given[0])
            return (
                f"the right image is missing; {given[0]} is a folder {what} ({detail}): "
                f"give two image files, left and right{also}"
            )
        return (
            f"the right image is missing; {given[0]} is a folder holding a pair: give its two "
            f"images, {pair[0]} and {pair[1]}{also}"
        )


_METHOD_HELP = (
    "matcher (default fused, the most accurate; census about half its time; fast a quarter; "
    "gabor the live-rate channel, holes left unfilled)"
)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``stereovision`` command."""
    from stereovision.calibration import UNIT_TO_METRES
    from stereovision.depth import METHODS

    p = _Parser(
        prog="stereovision",
        description="Binocular depth for robots: calibrate a stereo rig, then disparity, "
        "metric depth and point clouds from its pairs.",
        epilog="Start with `stereovision demo` (the bundled scene: no camera, no network). "
        "`stereovision COMMAND --help` lists a command's options. Errors print one line and "
        "exit with status 2.",
    )
    from stereovision import __version__

    p.add_argument("--version", action="version", version=f"stereovision {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    d = sub.add_parser("demo", help="run the pipeline on the bundled Middlebury scene")
    d.add_argument(
        "-o", "--output", default="demo_output", help="output folder (default demo_output)"
    )
    d.add_argument("--method", default=METHODS[0], choices=METHODS, help=_METHOD_HELP)
    d.set_defaults(func=cmd_demo)

    d = sub.add_parser("depth", help="disparity, depth and point cloud of one pair")
    d.add_argument("left", help="left image: raw with a rig's --calib, else rectified")
    d.add_argument("right", help="right image, the same size")
    d.add_argument(
        "--calib",
        help=CALIB_FILES_HELP,
    )
    add_calib_unit(d)
    d.add_argument(
        "--max-disparity",
        type=positive_pixels,
        default=None,
        metavar="N",
        # with --rectification the default is its own range (cmd_depth), not an estimate
        help="disparity range to search, in pixels (default: estimated from the images; with "
        "--rectification, the search range it holds)",
    )
    d.add_argument("--method", default=METHODS[0], choices=METHODS, help=_METHOD_HELP)
    # one or the other: both given, the last silently won
    fill = d.add_mutually_exclusive_group()
    fill.add_argument(
        "--fill", action="store_const", const=True, help="fill holes (default: the method's)"
    )
    fill.add_argument(
        "--no-fill", dest="fill", action="store_const", const=False, help="leave holes NaN"
    )
    d.add_argument(
        "--no-refine",
        dest="refine",
        action="store_const",
        const=False,
        help="skip the sub-pixel refinement (default: the method's)",
    )
    d.add_argument(
        "--max-depth",
        type=positive_metres,
        metavar="M",
        help="keep depths up to M metres (and points)",
    )
    d.add_argument(
        "--max-sigma",
        type=positive_metres,
        metavar="M",
        help="keep depths whose one-sigma uncertainty is at most M metres",
    )
    d.add_argument(
        "--voxel",
        type=positive_metres,
        metavar="M",
        help="with --calib: cloud.ply with one point per M-metre cube",
    )
    d.add_argument(
        "--ground",
        action="store_true",
        help="find the floor: camera height, pitch and roll (ground.json), what stands on it "
        "(obstacles.png) and a planar scan of it (scan.json, ROS LaserScan)",
    )
    d.add_argument(
        "--grid",
        type=cell_metres,
        metavar="M",
        help="with --ground: a bird's-eye occupancy grid of M-metre cells, 20 m ahead and 10 m "
        "to each side, as ROS map_server's map.png and map.yaml",
    )
    d.add_argument(
        "--rectification",
        metavar="JSON",
        help="a raw pair of a rig rectified without a calibration: the homographies "
        "`stereovision rectify` wrote (rectification.json); disparity only",
    )
    d.add_argument(
        "--unit",
        choices=tuple(UNIT_TO_METRES),
        help="with --calib: unit of the printed depths and of overview.png's depth bar: m "
        "(default), ft, mm, cm or in; the files keep theirs (depth.npy and cloud.ply in metres, "
        "depth_mm.png in millimetres) and --max-depth, --max-sigma, --voxel and --grid stay in "
        "metres",
    )
    d.add_argument("-o", "--output", required=True, help="output folder")
    d.set_defaults(func=cmd_depth)

    d = sub.add_parser(
        "check",
        help="is a pair rectified? row offset of its features (exit 1 if not, 3 if it cannot tell)",
        description="Measure how far a pair's SIFT feature matches lie off each other's rows "
        "after rectification, to catch a calibration that a bump or heat has spoiled. Exit "
        "status 0 when the median is within --tolerance (with --fix: the corrected calibration "
        "is; a pair within it is not corrected, nothing is written), 1 when not (with --fix: "
        "or when this pair cannot correct the calibration; nothing "
        "is written), 2 on an error, 3 when the pair has too little texture to tell, or its "
        "two images are the same pixels (one file or camera twice; with --fix: nothing is "
        "written).",
    )
    d.add_argument("left", help="left image: raw with --calib, else rectified")
    d.add_argument("right", help="right image, the same size")
    d.add_argument("--calib", help="the rig's calibration (omit for a rectified pair)")
    add_calib_unit(d)
    d.add_argument(
        "--tolerance", type=pixel_tolerance, default=0.5, help="median |dy| in px (default 0.5)"
    )
    d.add_argument(
        "--json",
        action="store_true",
        help='one JSON object instead of the lines (with --fix, the correction under "fixed": '
        "turn_deg, its check, the file written or null)",
    )
    d.add_argument("--plot", metavar="PNG", help="draw the rectified pair and its matches")
    d.add_argument(
        "--fix",
        metavar="OUT",
        help="correct the rig's pitch and roll from this pair and write the calibration to OUT",
    )
    d.set_defaults(func=cmd_check)

    d = sub.add_parser(
        "rectify",
        help="rectify a pair: with --calib, or without a calibration from its own features",
        description="Write the rectified pair (left_rect.png, right_rect.png) and how its rows "
        "agree. With --calib also calib_rect.yaml, the rectified pair's calibration (for "
        "depth --calib on left_rect.png and right_rect.png). Without --calib the homographies "
        "are found from the pair's feature matches (disparity, not metric depth) and saved as "
        "rectification.json, with the disparity "
        "range to search; a pair whose rows already agree (as `check` measures them) is "
        "written as given, not warped, unless --force.",
    )
    d.add_argument("left", help="left camera's raw image")
    d.add_argument("right", help="right camera's raw image, the same size")
    d.add_argument("--calib", help="the rig's calibration (default: none, from the features)")
    add_calib_unit(d)
    d.add_argument(
        "--model",
        default="auto",
        choices=("auto", "quasi-euclidean", "projective"),
        help="without --calib: turned cameras (quasi-euclidean), Hartley's homographies of F "
        "(projective), or the first when it fits (auto, the default); a pair already rectified "
        "is written as given all the same (said), --force warps it with the model",
    )
    d.add_argument(
        "--force",
        action="store_true",
        help="without --calib: rectify from the features even a pair whose rows already agree "
        "(default: such a pair is written as given)",
    )
    d.add_argument("-o", "--output", required=True, help="output folder")
    d.set_defaults(func=cmd_rectify)

    d = sub.add_parser(
        "info",
        help="what a calibrated rig can measure: field of view, depth range and resolution",
    )
    d.add_argument(
        "calib",
        nargs="?",
        help="calibration file, ROS camera_info folder, or a ROS 1 / ROS 2 bag",
    )
    d.add_argument(
        "--size",
        metavar="WxH",
        help="a rig on paper: image size, e.g. 1280x720; with a calibration that holds none "
        "(stereo_calib output, a Q.dat alone), its image size",
    )
    add_calib_unit(d)
    d.add_argument(
        "--hfov",
        type=field_of_view,
        metavar="DEG",
        help=f"a rig on paper: horizontal FOV, {HFOV_RANGE_DEG[0]:g} to under "
        f"{HFOV_RANGE_DEG[1]:g} degrees",
    )
    d.add_argument(
        "--baseline", type=paper_baseline, metavar="M", help="a rig on paper: baseline (m)"
    )
    d.add_argument("--left-topic", help="a bag: its left image topic (default: found)")
    d.add_argument("--right-topic", help="a bag: its right image topic (default: found)")
    d.set_defaults(func=cmd_info)

    d = sub.add_parser("eval", help="evaluate against ground truth, OpenCV beside")
    d.add_argument("scenes", nargs="+", help="scene folders (or folders containing scenes)")
    d.add_argument("--method", default=METHODS[0], choices=METHODS, help=_METHOD_HELP)
    d.add_argument("--json", action="store_true", help="one JSON object per scene on stdout")
    d.add_argument("--no-opencv", action="store_true", help="skip the OpenCV references")
    d.add_argument(
        "--runs",
        type=run_count,
        default=None,
        metavar="N",
        help="time ours (--method), StereoBM and SGBM-3WAY N times, interleaved, after a "
        "warm-up round when N > 1 (--runs 1: one run, no warm-up), and print the medians (a "
        "time line per scene; --json: always, one run without --runs); "
        f"evaluation.md's speed figures need >= 5 (at most {MAX_RUNS}); accuracy is the same "
        "for any N",
    )
    d.set_defaults(func=cmd_eval)

    # Commands owned by their pipeline stage's module.
    from stereovision import batch, bench, calibrate, capture, gui, render, stream

    capture.add_cli(sub)
    stream.add_cli(sub)
    batch.add_cli(sub)
    bench.add_cli(sub)
    calibrate.add_cli(sub)
    render.add_cli(sub)
    gui.add_cli(sub)
    return p


def _one_line_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
    paths: Sequence[object] = (),
) -> None:
    """Warnings as one line, like the errors (not Python's file:line and source echo): the
    message's first line with text; one with none (``warnings.warn(SomeWarning())``) is named
    by its category. The ``paths`` given on the command line (:func:`_given_texts`) are shown
    escaped where they hold a control character, as in an error (:func:`first_line`)."""
    warning = message if isinstance(message, Warning) else category(message)
    text = first_line(warning, paths)
    print(f"stereovision: warning: {advice_for(text, 'cli')}", file=sys.stderr)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit status.

    0 ok; 1 a verdict or partial result (``check`` finds the rows disagree, ``batch`` had pairs
    fail); 2 an error (one line on stderr); 3 ``check`` cannot tell; 130 interrupted (Ctrl-C);
    141 a closed pipe (``| head``); 143 terminated (SIGTERM). A refusal of the command line
    itself (an unknown option, a value an option does not take: ``--voxel 0``, ``--square 25mm``),
    ``--help`` and ``--version`` exit as argparse's do, by ``SystemExit`` (2, or 0), before any
    work.

    Run as the process's own command (``argv`` None), it ends the process itself (its output
    flushed) when a camera's open or grab it gave up is still in OpenCV: one coming back out of
    it while the interpreter shut down aborted the process, "terminate called without an active
    exception" under the error line and exit 134, not 2 (``capture --read-timeout 1e-300``, a
    slow camera given up).
    """
    status = _main(argv)
    if argv is None:
        end_past_native_threads(status)
    return status


def end_past_native_threads(status: int) -> None:
    """End the process with ``status`` (its output flushed) when a thread given up in OpenCV's
    native code (:data:`_NATIVE_THREADS`) is still alive; return otherwise.

    For a command's ``main`` run as the process's own command (``stereovision``, ``python -m
    stereovision``, ``python -m stereovision.gui``): such a thread coming back out of OpenCV
    while the interpreter shut down aborted the process (exit 134, not ``status``).

    Parameters
    ----------
    status : int
        The exit status the command returned.
    """
    if any(t.name in _NATIVE_THREADS and t.is_alive() for t in threading.enumerate()):
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):  # a closed pipe: nothing more to say
                stream.flush()
        os._exit(status)


#: The daemon threads that may be left in OpenCV's native code, given up (a hung or slow
#: camera's open or grab): the process must not shut its interpreter down under them. And the
#: GUI's worker (``gui.app.WORK_THREAD_PREFIX``): a computation running when the server stopped
#: was waited for at the interpreter's shutdown, minutes for a large pair after Ctrl+C.
_NATIVE_THREADS = (
    "stereovision-grab",
    "stereovision-gui-read",
    "stereovision-gui-open",
    "stereovision-gui-work_0",
)


def _main(argv: Sequence[str] | None) -> int:
    """:func:`main`'s work: parse ``argv`` and run its command."""
    try:
        # the commands' modules are imported here (0.2 s): a Ctrl-C right after the command
        # was typed printed a traceback of the import it stopped; held until they are whole
        # (an interrupt inside a C extension's initialisation can come out as its ImportError)
        with HeldInterrupts():
            parser = build_parser()
        args = parser.parse_args(argv)
    except Terminated:  # python -m stereovision's handler, set before these imports
        print("stereovision: terminated (SIGTERM)", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        print("stereovision: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    return run_parsed(args)


def run_parsed(args: argparse.Namespace) -> int:
    """Run the command ``args.func`` with its parsed ``args`` as the CLI does: warnings and
    errors in one line each (the paths given shown escaped), SIGTERM as :class:`Terminated`;
    returns the exit status. Also ``python -m stereovision.gui``'s, which said its warnings
    as Python does (``<frozen runpy>:88: UserWarning: ...``) and cut a path at its newline."""
    with warnings.catch_warnings():
        # Each run shows its warnings afresh (setting a filter resets the registry that would
        # hide a message already shown by an earlier call in the same process).
        warnings.simplefilter("default")
        # a file a Ctrl-C or SIGTERM caught between its open() and its `with` is closed by the
        # collector, which warns "unclosed file": Python's own default hides that (a developer's
        # warning), and "default" above had made it a line after the interrupt's
        warnings.simplefilter("ignore", ResourceWarning)
        # a path with a newline cut the warning there, naming another file ("warning: a")
        warnings.showwarning = functools.partial(_one_line_warning, paths=_given_texts(args))
        if threading.current_thread() is not threading.main_thread():
            return _run(args)
        kept = signal.signal(signal.SIGTERM, raise_terminated)
        try:
            return _run(args)
        finally:
            signal.signal(signal.SIGTERM, kept)


def _given_texts(args: argparse.Namespace) -> list[object]:
    """The paths (and other text) given on the command line, for :func:`first_line` to show
    those holding a control character escaped wherever its message names them: a path with a
    newline was cut there (``image file not found: a`` for ``a\\nb.png``)."""
    given: list[object] = []
    for value in vars(args).values():
        given += value if isinstance(value, list | tuple) else [value]
    return given


def _run(args: argparse.Namespace) -> int:
    try:
        status = int(args.func(args))
    except Terminated:
        print("stereovision: terminated (SIGTERM)", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        print("stereovision: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # The reader went away (`stereovision eval DIR | head`): stop quietly, as Unix tools do,
        # and keep Python from reporting the pipe again when it flushes stdout at exit.
        with contextlib.suppress(OSError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except BUG_ERRORS as exc:  # RuntimeErrors, but ours: said below as any bug of ours
        print(internal_error(exc), file=sys.stderr)
        return EXIT_ERROR
    # ImportError: an optional package missing (trame, rosbags, dask), said with its pip line
    except (CliError, ValueError, OSError, RuntimeError, MemoryError, ImportError) as exc:
        line = first_line(exc, _given_texts(args))
        print(f"stereovision: error: {advice_for(line, 'cli')}", file=sys.stderr)
        return EXIT_ERROR
    except Exception as exc:  # a bug of ours: still one line, never a traceback
        print(internal_error(exc), file=sys.stderr)
        return EXIT_ERROR
    return status


if __name__ == "__main__":
    sys.exit(main())
