"""The three-panel stereo GUI as a local web app (trame + pyvista, rendered on the server).

Panels (the paper's three windows):

1. **Acquisition**: the left and right images, the source (bundled demo scene, a scene folder,
   a pair of image files, or live camera sources), the processing resolution, and a capture button
   that grabs a new pair from the cameras.
2. **Stereo output**: the disparity map and the colour depth map side by side, the method
   selector and, for sparse methods, the matches drawn between the two images.
3. **3-D view**: the textured depth surface (or a loaded point cloud) with the roll / pitch / yaw
   and forward / up / right controls, and the mouse.

Depth is computed in a worker thread; the page shows a progress bar and stays responsive. VTK
renders on the server (offscreen) and streams images to the page, so no GPU or display is needed
on the robot. Errors (a file that is not a point cloud, a camera that does not open, a path
outside the allowed folders) appear in an alert and leave the page usable.
"""

from __future__ import annotations

import asyncio
import base64
import concurrent.futures
import errno
import itertools
import logging
import math
import os
import re
import sys
import threading
import time
import warnings
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from stereovision import release_memory
from stereovision._validate import (
    ADVICE,
    BUG_ERRORS,
    _message,
    advice_for,
    first_line,
    internal_error,
    known_unit,
)
from stereovision.calibration import fit_to_frames
from stereovision.capture import DEFAULT_READ_TIMEOUT, _camera_device, mask_url_secrets
from stereovision.gui.sources import (
    CLOUD_SUFFIXES,
    IMAGE_SUFFIXES,
    AllowedFolders,
    FolderPairs,
    Frame,
    StereoSource,
    display_path,
    expand_home,
    open_stereo_source,
    parse_source,
    real_path,
    scale_pair,
    scaled_calibration,
)

__all__ = [
    "EXTRA_METHODS",
    "MATCH_METHODS",
    "RESOLUTIONS",
    "StereoApp",
    "compute_view",
    "draw_sparse",
    "max_disparity_hint",
    "nowrap_units",
    "parse_max_disparity",
    "short_paths",
]

log = logging.getLogger(__name__)
#: What a button that needs a pair says before there is one (it did nothing).
NO_PAIR = "no pair yet: capture from the cameras, load two files or choose a scene first"

#: Pixel formats the camera row offers ("driver": whatever the cameras deliver by default);
#: two webcams on one USB 2 bus often need MJPG for their full size and rate.
FOURCCS = ("driver", "MJPG", "YUYV")
#: Processing widths offered by the resolution control ("full" keeps the input size).
RESOLUTIONS = ("full", "640", "320")

#: Frames a capture averages when "average still frames" is on (a still rig in low light:
#: :class:`~stereovision.temporal.TemporalFilter`, docs/robotics.md).
AVERAGE_FRAMES = 8

#: OpenCV references offered beside the package's matchers (evaluation.md baselines).
EXTRA_METHODS = ("opencv-sgbm", "opencv-bm")

#: The paper's sparse channels, offered beside ``depth_map``'s methods: their matches
#: (:func:`stereovision.match`) are drawn on the left image, coloured by disparity (and by
#: depth), and the 3-D view shows their points. They were never on the page: its list was
#: ``depth_map``'s methods, which has no sparse one (this path's names never reached it).
#: ``"best"`` (Hopfield's reference without the network) is an ablation, not offered.
MATCH_METHODS = ("mcgm", "hopfield")

#: Methods whose output is sparse: their matches are drawn on the image pair.
SPARSE_METHODS = frozenset(MATCH_METHODS)

#: A result with fewer valid pixels than this fraction is treated as sparse (matches drawn).
SPARSE_DENSITY = 0.2

#: At most this many matches are drawn (evenly sampled), so the drawing stays readable.
MAX_DRAWN_MATCHES = 150

#: Images sent to the page are at most this wide (JPEG), to keep the websocket light.
DISPLAY_WIDTH = 480
JPEG_QUALITY = 85

#: The 3-D surface uses every ``step``-th pixel so that it has at most this many vertices.
MAX_MESH_VERTICES = 120_000

#: The 3-D view's width : height when it shows no camera's view (an opened cloud file); with
#: one it takes the camera image's own, so that the whole image is in view (a fixed 360 px
#: high view cut off both sides of a KITTI scene: 40 % of its width was shown).
VIEW_ASPECT = 4 / 3
#: The 3-D view is at most this high (px); a portrait image's view is then wider than the image.
VIEW_MAX_HEIGHT_PX = 480
#: A pair wider than this (width / height) shows its two images one above the other: side by
#: side, a KITTI pair (1242 x 375) was two pictures 60 px high. Strictly wider: a camera's own
#: picture at exactly 2:1 (the widest common modes, 4:3 and 16:9, are well below) keeps the
#: side-by-side layout, each half as high as its column is wide; the rule is for strips (KITTI
#: 3.3:1, a side-by-side USB camera's whole frame, 2 x 4:3 = 8:3 or 2 x 16:9, shown unsplit).
WIDE_ASPECT = 2.0

#: Most points the 3-D view draws of a cloud (an opened file, a computed pair in "points"
#: mode): more are shown as an evenly spaced subset of this many (``stereovision view``'s
#: cap, :func:`stereovision.render.display_subset`), said in the caption. Files are only read.
MAX_SHOWN_POINTS = 2_000_000

#: The name of the page's worker thread (computations, checks, Saves), ``_0`` appended: one
#: the process ends past when the server stops (:data:`stereovision.cli._NATIVE_THREADS`).
WORK_THREAD_PREFIX = "stereovision-gui-work"

#: Progress (per cent) reached at each stage reported by ``depth_map``.
_STAGE_PROGRESS = {
    "rectify": 10,
    "prepare": 20,
    "match": 75,
    "refine": 80,  # it was missing: 50, the bar went back after "match"
    "fill": 85,
    "triangulate": 90,
}
#: What each stage ``depth_map`` reports is called while it runs: the status names the step
#: that follows the one done (it said "prepare done" for the whole matching, which looked
#: like a stall).
_STEP_NAME = {
    "rectify": "rectifying",
    "prepare": "preparing",
    "match": "matching",
    "refine": "refining",
    "fill": "filling",
    "triangulate": "triangulating",
}

#: Why an OpenCV reference method searches more than the max-disparity field says.
_BY_16 = "(OpenCV's matchers take multiples of 16 px)"

#: The max-disparity field's hint when the pair has no range of its own.
AUTO_HINT = "auto: estimated from the images"

#: The disparity picture's caption when it has no disparity to scale (nothing matched).
DISPARITY_CAPTION = "disparity"


#: The 3-D view's box: the camera image's shape (``view_aspect``), at most
#: :data:`VIEW_MAX_HEIGHT_PX` high (a JavaScript expression of the page's state).
VIEW_STYLE = (
    "`position: relative; width: 100%; aspect-ratio: ${view_aspect}; "
    f"max-height: {VIEW_MAX_HEIGHT_PX}px;`"
)


def _planned_stages(method: str, calibrated: bool) -> list[str]:
    """The stages ``depth_map`` reports, in order, for ``method`` with its default ``fill`` and
    ``refine`` (as :func:`compute_view` calls it): the re-measure only for a method that is not
    dense by default (``"gabor"``), the fill only for the dense ones, and the triangulation only
    with a calibration. A fixed table said "refining and filling" after fused's match (it only
    fills) and "triangulating" without a calibration (nothing is triangulated)."""
    from stereovision.depth import _DENSE_METHODS, _REFINED_BY_DEFAULT

    stages = ["rectify", "prepare", "match"]
    if method in _REFINED_BY_DEFAULT and method not in _DENSE_METHODS:
        stages.append("refine")
    if method in _DENSE_METHODS:
        stages.append("fill")
    if calibrated:
        stages.append("triangulate")
    return stages


#: The depth picture's caption when it has no depth to scale (no calibration, no match).
DEPTH_CAPTION = "depth (near = warm)"
#: ... and over the black picture of a pair without a calibration (it promised colours)
NO_DEPTH_CAPTION = "depth: none without a calibration"

#: What "Save" writes (``stereovision depth``'s own files, by its writers): always, and with depth.
SAVED_FILES = ("disparity.png", "disparity.pfm", "overview.png")
SAVED_DEPTH_FILES = ("depth.png", "depth.npy", "depth_mm.png", "cloud.ply", "render.png")
#: The order Save's writers write its files in (``write_depth_outputs``' own order, then
#: ``overview.png`` and ``render.png``): of a Save that failed, the first not written is the one
#: that failed.
SAVE_WRITE_ORDER = (
    "disparity.png",
    "depth.png",
    "depth.npy",
    "depth_mm.png",
    "disparity.pfm",
    "cloud.ply",
    "overview.png",
    "render.png",
)
#: The save folder offered at start-up, inside the first ``--data`` folder.
SAVE_FOLDER = "saved"
#: Where a Save as offered goes, in the user's home folder, when the first ``--data`` folder
#: cannot be written (a read-only data set): ``~/stereovision-saved``, ``-2``, ...
FALLBACK_SAVE_FOLDER = "stereovision-saved"
#: Height of a button of a toggle row (Vuetify's compact button group).
TOGGLE_HEIGHT_PX = 36
#: What the page says under the Save folder field (with and without a --data folder).
SAVE_HINT = "in a --data folder; as offered, a new one each Save (saved, saved-2, ...)"
NO_SAVE_HINT = "Save writes into a --data folder: start the GUI with --data DIR"
READ_ONLY_SAVE_HINT = (
    "the --data folder cannot be written: as offered, a new one each Save in the home folder "
    f"({FALLBACK_SAVE_FOLDER}, {FALLBACK_SAVE_FOLDER}-2, ...)"
)

#: Length units the page can show (the unit toggle; metres by default), as
#: :data:`stereovision.calibration.UNIT_TO_METRES` names them.
UNITS = ("m", "ft")

#: Camera slider ranges: degrees for the rotations, metres for the translations (shown in the
#: page's unit: the range and step of the feet sliders are these in feet).
ANGLE_RANGE = 90.0
TRANSLATION_RANGE = 5.0
TRANSLATION_STEP = 0.05
_TRANSLATIONS = ("forward", "up", "right")
#: The 3-D sliders' name and value columns (one width each, so that the six tracks line up).
SLIDER_NAME_STYLE = "width: 6.5em; white-space: nowrap;"
SLIDER_VALUE_STYLE = "width: 4.5em; text-align: right; white-space: nowrap;"

_CONTROL_NAMES = ("roll", "pitch", "yaw", "forward", "up", "right")

#: What the page shows of a computed pair: cleared while a new pair computes (the previous
#: pair's disparity stayed under the new pair's name), put back if the new pair fails.
_RESULT_KEYS = (
    "depth_caption",
    "disparity_caption",
    "img_left",
    "img_right",
    "img_disparity",
    "img_depth",
    "img_matches",
    "img_floor",
    "floor_label",
    "stats",
    "message_3d",
    "wide_pair",
)
#: The 3-D caption while a new pair computes (the view keeps the previous pair until then).
PENDING_3D = "computing the new pair: the 3-D view still shows the previous one"
#: What Find floor says while a new pair computes (the depth on hand is the previous pair's).
PENDING_FLOOR = "the new pair is being computed: find its floor once its depth is shown"
#: What Save adds when render.png is the 3-D view as the mouse left it (the sliders' pose
#: is another).
MOUSE_RENDER = "render.png: the 3-D view as the mouse left it, not the sliders' pose"
#: What Save says while a new pair computes.
PENDING_SAVE = "the new pair is being computed: save it once its results are shown"


def translation_range(unit: str = "m") -> float:
    """The translation sliders' range (+-) as the page shows it in ``unit``:
    :data:`TRANSLATION_RANGE` metres, rounded to the feet sliders' 0.1 ft step (16.4 ft).

    The range is rounded down (5 m is 16.404 ft), so values converted into it are clamped to it
    (:meth:`StereoApp._on_unit`, :func:`sliders_from_pose`). The other way, a range rounded up
    to hold 16.404 ft (16.5 ft = 5.03 m) would in turn hold values past the metres sliders'
    5 m, and an unrounded one (16.404...) puts the slider's steps, counted from its minimum,
    off the round numbers; the clamp costs at most 1.3 mm, and the view stays where it was.

    Parameters
    ----------
    unit : str
        The page's length unit (:data:`UNITS`).

    Returns
    -------
    float
        The sliders' largest value (their smallest is its negative), in ``unit``.
    """
    from stereovision.calibration import UNIT_TO_METRES

    return round(TRANSLATION_RANGE / UNIT_TO_METRES[unit], 1)


class SaveFailed(OSError):
    """A Save's writer failed: the message names the file (nothing was moved into place)."""


def sliders_from_pose(pose: npt.ArrayLike, unit: str = "m") -> tuple[dict[str, float], bool]:
    """The 3-D view's six slider values for a camera ``pose``, each clamped to its slider's
    range, and whether any was (:func:`~stereovision.render.controls_from_pose`).

    A mouse drag can turn the camera past the rotation sliders' +-:data:`ANGLE_RANGE` degrees
    (yaw 150 after orbiting the scene) or move it past the translation sliders' range: those
    values are clamped, not wrapped. Wrapping has no pose to offer here: the other Euler
    triple of a rotation (``roll + 180, 180 - pitch, yaw + 180``) has ``|pitch| >= 90``, so
    a yaw of 150 taken to -30 would look the other way. A clamped value leaves the sliders at
    the nearest pose they can show, per slider, not the pose the mouse left.

    Parameters
    ----------
    pose : array_like, (4, 4)
        Camera-to-left-camera transform (:func:`~stereovision.render.pose_from_camera`).
    unit : str
        The page's length unit (:data:`UNITS`): the translations' values are in it.

    Returns
    -------
    values : dict of str to float
        Slider name to value (degrees, or lengths in ``unit``).
    clamped : bool
        True when a value was outside its slider's range (the sliders' pose is then another).

    Raises
    ------
    ValueError
        A pose that is not 4x4 or not finite, or an unknown unit.
    """
    from stereovision.calibration import UNIT_TO_METRES
    from stereovision.render import controls_from_pose

    unit = known_unit(unit, UNITS)
    controls = controls_from_pose(pose)
    metres = UNIT_TO_METRES[unit]
    values, clamped = {}, False
    for name in _CONTROL_NAMES:
        value = float(getattr(controls, name))
        if name in _TRANSLATIONS:
            value /= metres
            limit = translation_range(unit)  # the range the page shows (_on_unit)
        else:
            limit = ANGLE_RANGE
        kept = min(max(value, -limit), limit)
        clamped |= kept != value
        values[name] = kept
    return values, clamped


def save_all_or_nothing(
    write: Callable[[Path], None], folder: Path, files: Sequence[str] = SAVE_WRITE_ORDER
) -> dict[str, Path]:
    """Run a Save's writers into a staging folder and move their files into ``folder`` only
    once every one is written.

    The staging folder is ``stereovision depth -o``'s (:func:`stereovision.cli.staged_outputs`:
    hidden, locked while the Save runs, removed however it ends, and one a killed process
    left is removed by the next). It is made beside ``folder`` when ``folder`` does not exist
    (the whole folder then appears at once, by one rename), else inside it (its files then
    move in one by one, each by one rename, after checking that none is there; so too into a
    folder another program made while the Save wrote).

    Parameters
    ----------
    write : callable
        Writes the Save's files into the folder it is given (that folder exists).
    folder : pathlib.Path
        Where the files go (it need not exist; the folders above it are made as needed).
    files : sequence of str
        The files ``write`` writes, in the order it writes them (default
        :data:`SAVE_WRITE_ORDER`, all of them: a pair without depth writes three).

    Returns
    -------
    dict
        ``{name: path in folder}``, in :data:`SAVE_WRITE_ORDER`.

    Raises
    ------
    SaveFailed
        A writer failed, naming the first of ``files`` it did not write;
        ``folder`` is as it was (absent if it was), the folders made above it removed again.
    FileExistsError
        One of the files appeared in ``folder`` while the Save wrote (nothing was replaced).
    """
    from stereovision.cli import CliError, staged_outputs

    exists = os.path.isdir(folder)
    with staged_outputs(folder if exists else folder.parent) as stage:
        inner = stage / folder.name
        inner.mkdir()  # the mode a plain mkdir gives (the staging folder's is 0700)
        try:
            write(inner)
        except (ValueError, OSError, RuntimeError, CliError) as exc:
            done = {p.name for p in inner.iterdir()}
            # of the files this Save writes: a pair without depth that failed at disparity.pfm
            # said "depth.png could not be written", a file it never writes
            failed = next((n for n in files if n not in done), "a file")
            # its path as it would be, replaced before first_line escapes a tab in it (the
            # staging path was named then) and shown escaped (a newline cut the line there)
            said = str(exc).replace(str(inner), str(folder))
            why = first_line(ValueError(said), [folder]) if said.strip() else first_line(exc)
            raise SaveFailed(f"{failed} could not be written ({why})") from exc
        names = [n for n in SAVE_WRITE_ORDER if (inner / n).is_file()]
        moved = False
        if not exists:
            try:
                os.rename(inner, folder)  # fails (nothing replaced) if a folder with files came
                moved = True
            except OSError as exc:
                # another program made the folder meanwhile: it said "Directory not empty:
                # '.../.stereovision-partial-.../saved' -> ...", a folder the user never saw;
                # it is now one that existed, its files moved in as below
                if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST) or not folder.is_dir():
                    raise
        if not moved:
            came = [n for n in names if os.path.lexists(folder / n)]
            if came:
                raise FileExistsError(
                    f"save: {', '.join(came)} appeared in {folder} while the Save wrote; "
                    "nothing was overwritten: choose another folder"
                )
            for name in names:
                os.replace(inner / name, folder / name)
    return {n: folder / n for n in names}


def _cannot_make(folder: Path) -> str | None:
    """Why ``folder`` cannot be made or written in (the nearest existing folder at or above it
    refuses a file: :func:`~stereovision.io.cannot_write_in`), or None if it can."""
    from stereovision.io import cannot_write_in

    above = folder
    while not above.exists() and above.parent != above:
        above = above.parent
    return cannot_write_in(above) if above.is_dir() else None


def _data_url(image: npt.NDArray[np.uint8], width: int = DISPLAY_WIDTH) -> str:
    """A BGR image as a JPEG ``data:`` URL, scaled down to ``width`` pixels; one of more than
    8 bits (a 16-bit image sequence's) shown at 8 (:func:`~stereovision._validate.as_bgr_uint8`)."""
    shown: Any = image
    if image.dtype != np.uint8:
        from stereovision._validate import as_bgr_uint8

        # JPEG holds 8 bits: OpenCV cut a 16-bit frame to 255, the pair shown white
        shown = image = as_bgr_uint8(image, "image")
    if image.shape[1] > width:
        h = max(1, round(image.shape[0] * width / image.shape[1]))
        shown = cv2.resize(image, (width, h), interpolation=cv2.INTER_AREA)
    ok, buf = cv2.imencode(".jpg", shown, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
    if not ok:
        raise OSError("could not encode an image for the page")
    return "data:image/jpeg;base64," + base64.b64encode(buf.tobytes()).decode("ascii")


def shown_cloud(points: npt.ArrayLike, colors: npt.ArrayLike | None = None) -> tuple[Any, str]:
    """The cloud the 3-D view draws of ``points``, and what to say of its count.

    At most :data:`MAX_SHOWN_POINTS`, evenly spaced (:func:`~stereovision.render.display_subset`):
    a cloud of millions of points took the server tens of seconds per frame.

    Parameters
    ----------
    points : array_like, (N, 3)
    colors : array_like, (N, 3), optional

    Returns
    -------
    (pyvista.PolyData, str)
        The cloud drawn and its count: ``"N points"`` (``"1 point"``), or ``"2,000,000 of
        15,000,000 points shown"`` when a subset is drawn.

    Examples
    --------
    >>> cloud, said = shown_cloud(np.ones((5, 3)))
    >>> cloud.n_points, said
    (5, '5 points')
    >>> shown_cloud(np.ones((1, 3)))[1]
    '1 point'
    """
    from stereovision.render import display_subset, point_cloud

    pts, cols = display_subset(points, colors, MAX_SHOWN_POINTS)
    total = len(np.asarray(points))
    if len(pts) < total:
        said = f"{len(pts):,} of {total:,} points shown, evenly spaced"
    else:
        said = "1 point" if total == 1 else f"{total} points"
    return point_cloud(pts, cols), said


def draw_matches(
    left: npt.NDArray[np.uint8],
    right: npt.NDArray[np.uint8],
    disparity: npt.NDArray[np.float32],
    max_matches: int = MAX_DRAWN_MATCHES,
    *,
    lo: float | None = 0.0,
    hi: float | None = None,
) -> npt.NDArray[np.uint8]:
    """The pair side by side with lines from each matched left pixel to ``x - d`` on the right,
    each line and its end dots in the colour of its disparity on the disparity picture's scale
    (:func:`stereovision.cli.colorize`, as :func:`draw_sparse` colours the dots).

    Parameters
    ----------
    left, right : ndarray, (H, W, 3) uint8
        BGR rectified pair; grey, BGRA and 16-bit images are drawn at 8-bit BGR, as the page
        shows them.
    disparity : ndarray, float32 (H, W)
        NaN where there is no match.
    max_matches : int
        Evenly sampled subset drawn.
    lo, hi : float or None
        The disparities at the ends of the colour map: the disparity picture's (0 px and,
        when None, the map's 99th percentile).

    Returns
    -------
    ndarray, uint8 (H, 2W, 3)
    """
    from stereovision._validate import as_bgr_uint8
    from stereovision.cli import colorize

    w = disparity.shape[1]
    # at 8 bits: a 16-bit pair's lines were drawn in 8-bit colours (255 of 65535), near black
    canvas = np.hstack([as_bgr_uint8(left, "left"), as_bgr_uint8(right, "right")])
    ys, xs = np.nonzero(np.isfinite(disparity))
    if len(xs) == 0:
        return canvas
    colours = colorize(np.asarray(disparity, np.float32), lo=lo, hi=hi)[ys, xs]
    pick = np.linspace(0, len(xs) - 1, min(max_matches, len(xs))).astype(int)
    for i in pick:
        x, y = int(xs[i]), int(ys[i])
        xr = round(x - float(disparity[y, x])) + w
        c = tuple(int(v) for v in colours[i])
        cv2.line(canvas, (x, y), (xr, y), c, 1, cv2.LINE_AA)
        cv2.circle(canvas, (x, y), 2, c, -1)
        cv2.circle(canvas, (xr, y), 2, c, -1)
    return canvas


def draw_sparse(
    image: npt.NDArray[np.uint8],
    values: npt.NDArray[np.floating[Any]],
    lo: float | None,
    hi: float | None,
) -> npt.NDArray[np.uint8]:
    """A sparse method's matches on its left image: a dot at each matched pixel, coloured by
    ``values`` there (disparity, or 1 / depth) as the dense pictures colour theirs.

    Parameters
    ----------
    image : ndarray, (H, W, 3) uint8
        BGR left (rectified) image, shown dimmed in grey under the dots; grey, BGRA and 16-bit
        images are shown at 8 bits, as the page shows them.
    values : ndarray, float (H, W)
        NaN where there is no match.
    lo, hi : float or None
        The ends of the colour map (:func:`stereovision.cli.colorize`'s).

    Returns
    -------
    ndarray, uint8 (H, W, 3)
        The picture; a dot's centre has the colour ``colorize`` gives its value.
    """
    from stereovision._validate import as_bgr_uint8
    from stereovision.cli import colorize

    # at 8 bits as the page shows it: a 16-bit image cast to uint8 kept its low byte, noise
    grey = cv2.cvtColor(as_bgr_uint8(image, "image"), cv2.COLOR_BGR2GRAY)
    out: npt.NDArray[np.uint8] = np.repeat((grey // 2)[..., None], 3, axis=2).astype(np.uint8)
    ys, xs = np.nonzero(np.isfinite(values))
    if len(xs) == 0:
        return out
    colours = colorize(np.asarray(values, np.float32)[ys, xs][None, :], lo=lo, hi=hi)[0]
    # a dot about 2 px across on the page, whatever the pair's size (shown DISPLAY_WIDTH wide)
    radius = max(1, round(image.shape[1] / DISPLAY_WIDTH))
    for x, y, c in zip(xs.tolist(), ys.tolist(), colours.tolist(), strict=True):
        cv2.circle(out, (x, y), radius, tuple(c), -1)
    out[ys, xs] = colours  # each centre its own colour, where dots overlap too
    return out


@dataclass
class ViewData:
    """Everything the page shows for one computed pair (built in the worker thread)."""

    result: Any
    left_url: str
    right_url: str
    disparity_url: str
    depth_url: str
    matches_url: str
    mesh: Any
    intrinsics: Any
    stats: str
    message_3d: str
    #: The depth picture's caption: the distances its colour scale runs between.
    depth_caption: str = DEPTH_CAPTION
    #: The disparity picture's caption: the pixels its colour scale runs between.
    disparity_caption: str = DISPARITY_CAPTION
    #: The distances (metres; inf for none) at the near (red) and far (blue) ends of the depth
    #: picture's colours, the median depth, and the statistics line before and after it: what
    #: :meth:`texts` says in another unit.
    depth_ends: tuple[float, float] | None = None
    median_depth: float | None = None
    stats_parts: tuple[str, str] | None = None
    #: The floor Find floor found on this pair (None: not found, or not looked for yet), said
    #: again in another unit when the toggle changes.
    floor: Any = None
    #: A sparse method's matches (:func:`stereovision.match`'s output; None for a dense one):
    #: drawn on the left image, and the 3-D view shows their points whatever its mode.
    matches: Any = None

    def texts(self, unit: str = "m") -> tuple[str, str]:
        """The depth caption and the statistics line with their lengths in ``unit``.

        Parameters
        ----------
        unit : {"m", "ft"}
            One of :data:`UNITS`.

        Returns
        -------
        (str, str)
            ``(depth_caption, stats)``; in metres they are :attr:`depth_caption` and
            :attr:`stats`.

        Raises
        ------
        ValueError
            An unknown unit.
        """
        unit = known_unit(unit, UNITS)
        caption, stats = self.depth_caption, self.stats
        if self.depth_ends is not None:
            near, far = (_length(v, unit) for v in self.depth_ends)
            caption = f"depth: red {near} … blue {far}"
        if self.stats_parts is not None:
            head, tail = self.stats_parts
            median = ""
            if self.median_depth is not None:
                median = f" · median depth {_length(self.median_depth, unit)}"
            stats = head + median + tail
        return nowrap_units(caption), nowrap_units(stats)


#: The space between a number and its unit (px, m, ft, s, %, °, deg): one the page does not
#: break.
NBSP = "\u00a0"
_NUMBER_UNIT = re.compile(r"(?<=[0-9∞]) (?=(?:px|m|ft|s|%|°|deg)(?![A-Za-z0-9]))")


def nowrap_units(text: str) -> str:
    """``text`` with the space between each number and its unit made non-breaking.

    On a narrow page the statistics line broke "median depth 3.50 m" as "3.50" at the end of
    one line and "m" alone on the next.

    Examples
    --------
    >>> nowrap_units("0–64 px · density 100 % · 0.29 s · median depth 3.50 m, 2 matches")
    '0–64\\xa0px · density 100\\xa0% · 0.29\\xa0s · median depth 3.50\\xa0m, 2 matches'
    """
    return _NUMBER_UNIT.sub(NBSP, text)


def short_paths(message: str, path: str | os.PathLike[str]) -> str:
    """``message`` with ``path`` and its parent folders written as the page shows paths
    (:func:`~stereovision.gui.sources.display_path`: relative to the current folder, else
    ``~/...``).

    A point-cloud file or a Save folder that failed was named by its whole absolute path
    (``/tmp/sv-.../scenes/x.ply``) where the page shows short paths.

    Examples
    --------
    >>> import os
    >>> short_paths(f"not a PLY file: {os.getcwd()}/scenes/x.ply", Path("scenes/x.ply").resolve())
    'not a PLY file: scenes/x.ply'
    """
    p = Path(os.path.abspath(path))
    for folder in (p, *p.parents):
        if len(folder.parts) > 1 and str(folder) in message:
            shown = display_path(folder)
            if shown != str(folder):
                message = message.replace(str(folder), shown)
    return message


def _length(metres: float, unit: str) -> str:
    """A length in ``unit`` with two decimals (∞ for an infinite one)."""
    from stereovision.calibration import UNIT_TO_METRES

    if not math.isfinite(metres):
        return "∞"
    return f"{metres / UNIT_TO_METRES[unit]:.2f}{NBSP}{unit}"


#: What :func:`floor_text` says of no floor without the depth result to say why (Find floor
#: gives it: too few disparities for a fit, no near-level plane holding the floor's share, or
#: the likeliest floor's pixels along a line).
NO_FLOOR = "ground plane: none found"
#: The heights above the floor (metres) that Find floor paints as obstacles.
OBSTACLE_HEIGHTS = (0.15, 2.0)


def floor_caption(unit: str = "m") -> str:
    """The floor picture's caption, its obstacle heights in ``unit`` (one of :data:`UNITS`).

    Examples
    --------
    >>> floor_caption()
    'floor (green), obstacles 0.15-2\\xa0m (red)'
    >>> floor_caption("ft")
    'floor (green), obstacles 0.49-6.56\\xa0ft (red)'
    """
    from stereovision.calibration import UNIT_TO_METRES

    lo, hi = (round(h / UNIT_TO_METRES[unit], 2) for h in OBSTACLE_HEIGHTS)
    return f"floor (green), obstacles {lo:g}-{hi:g}{NBSP}{unit} (red)"


def floor_text(plane: Any, unit: str = "m", result: Any = None) -> str:
    """Find floor's line for a ground plane, its height in ``unit``: ``GroundPlane.describe(unit)``,
    numbers kept with their units. For None (none found) the reason that holds for ``result``'s
    disparity map, as ``depth --ground`` says it: too few disparities for a fit to be tried,
    no near-level plane holding the floor's share, or the likeliest floor's pixels along a line
    (:data:`NO_FLOOR` without a result)."""
    if plane is None:
        if result is None:
            return NO_FLOOR
        from stereovision.ground import _no_floor_line

        return _no_floor_line(result.disparity, result.calibration)
    return nowrap_units(str(plane.describe(unit)))


def floor_view(result: Any) -> tuple[Any, str]:
    """The floor of a depth result: the ground plane (None when none is found) and a picture
    of it, its obstacles in red (data URL; "" when none). :func:`floor_text` says the plane."""
    plane, url, _ = _floor_view(result)
    return plane, url


def _floor_view(result: Any) -> tuple[Any, str, str]:
    """:func:`floor_view`'s plane and picture, and with no plane the line saying why (as
    :func:`floor_text` gives it; "" with a plane), from the one fit."""
    from stereovision.ground import _fit_ground, obstacle_mask

    calib = result.calibration
    plane, why = _fit_ground(result.disparity, calib)
    if plane is None:
        return None, "", why
    img = result.left_rectified if result.left_rectified is not None else None
    if img is None:
        return plane, "", ""
    out = np.array(img, np.uint8)
    if out.ndim == 2:
        out = np.repeat(out[..., None], 3, axis=2)
    lo, hi = OBSTACLE_HEIGHTS
    obstacles = obstacle_mask(result.point_image(filled=True), plane, min_height=lo, max_height=hi)
    for mask, colour in ((plane.inliers, (60, 200, 60)), (obstacles, (40, 40, 230))):
        out[mask] = (0.5 * out[mask] + 0.5 * np.array(colour)).astype(np.uint8)
    return plane, _data_url(out), ""


def _opencv_result(method: str, left: np.ndarray, right: np.ndarray, calib: Any, d_max: int) -> Any:
    """A ``DepthResult`` from an OpenCV reference matcher (for comparison in the GUI)."""
    from stereovision import baselines
    from stereovision.baselines import BM_BLOCK_SIZE

    if calib is not None and not calib.rectified:
        left, right = calib.rectify(left, right)
        calib = calib.rectified_calibration()
    fn = baselines.opencv_sgbm if method == "opencv-sgbm" else baselines.opencv_bm
    w, h = left.shape[1], left.shape[0]
    # OpenCV's ranges are multiples of 16 (and BM's block must fit beside them): a pair with
    # room for none was told "disparity range 16 is not smaller than the image width 12, or
    # give a max_disparity below 12", a range nobody gave and a max_disparity that fails too
    need = 16 + (BM_BLOCK_SIZE - 1 if method == "opencv-bm" else 1)
    if d_max >= w and w < need:
        block = f" and its {BM_BLOCK_SIZE} px block" if method == "opencv-bm" else ""
        raise ValueError(
            f"image too narrow for {method}: {w} px wide, and its disparity range (a multiple "
            f"of 16, at least 16 px){block} need{'' if block else 's'} images at least {need} "
            "px wide"
        )
    if d_max >= w:  # depth_map's words (OpenCV failed to allocate 18446744073709 GB)
        from stereovision.depth import _range_too_wide

        raise _range_too_wide(d_max, w)
    try:
        disp = np.ascontiguousarray(fn(left, right, d_max), dtype=np.float32)
    except cv2.error as exc:
        # OpenCV's message starts with its version and a source path: the page says its reason
        reason = str(exc).split("error: ", 1)[-1].strip().splitlines()[0]
        raise ValueError(f"{method} cannot match this {w}x{h} pair: {reason}") from None
    return _result_from_disparity(method, disp, left, calib, d_max)


def _sparse_result(
    method: str, left: np.ndarray, right: np.ndarray, calib: Any, d_max: int | None
) -> tuple[Any, Any]:
    """A sparse method's matches (:func:`stereovision.match`) on the pair, and a ``DepthResult``
    of them: their disparity at the matched left pixels (:attr:`Matches.dispx`), NaN elsewhere,
    with the depth and points there."""
    from stereovision.depth import estimate_max_disparity
    from stereovision.match import match

    if calib is not None and not calib.rectified:
        left, right = calib.rectify(left, right)
        calib = calib.rectified_calibration()
    d = d_max if d_max is not None else estimate_max_disparity(left, right)
    if d_max is None and d >= left.shape[1]:
        # the estimate is no range the user gave: depth_map's words for the pair, as the other
        # methods say it (match, given it, said "disparity range 16 is not smaller than ...")
        from stereovision.depth import _too_narrow

        raise _too_narrow(left.shape[1], d)
    matches = match(left, right, calib, method=method, max_disparity=d)
    disp = np.ascontiguousarray(matches.dispx, dtype=np.float32)
    return _result_from_disparity(method, disp, left, calib, d), matches


def _result_from_disparity(
    method: str, disp: np.ndarray, left: np.ndarray, calib: Any, d_max: int
) -> Any:
    """A ``DepthResult`` of a disparity map (NaN: none) of the rectified ``left`` image (kept
    at 8 bits, BGR, as ``depth_map`` keeps its ``left_rectified``)."""
    from stereovision._validate import as_bgr_uint8
    from stereovision.depth import DepthResult

    # a 16-bit pair's colours were cast to uint8 (their low byte: a cloud of noise), and its
    # 16-bit left image failed the Save ("result: expected a uint8 left image, got uint16")
    left = as_bgr_uint8(left, "left")
    valid = np.isfinite(disp)
    depth = None
    points = np.zeros((0, 3), np.float32)
    colors = np.zeros((0, 3), np.uint8)
    pixels = np.zeros((0, 2), np.int32)
    if calib is not None:
        depth = calib.depth_from_disparity(disp).astype(np.float32)
        xyz = calib.reproject(disp)
        ok = np.isfinite(depth) & (depth > 0)
        ys, xs = np.nonzero(ok)
        points = np.ascontiguousarray(xyz[ys, xs], dtype=np.float32)
        colors = np.ascontiguousarray(left[ys, xs, ::-1], dtype=np.uint8)
        pixels = np.stack([xs, ys], axis=1).astype(np.int32)
    return DepthResult(
        disparity=disp,
        confidence=valid.astype(np.float32),
        depth=depth,
        points=points,
        colors=colors,
        pixels=pixels,
        method=method,
        max_disparity=int(d_max),
        calibration=calib,
        left_rectified=np.ascontiguousarray(left),
    )


def compute_view(
    left: npt.NDArray[np.uint8],
    right: npt.NDArray[np.uint8],
    calib: Any,
    method: str,
    *,
    width: int | None = None,
    max_disparity: int | None = None,
    progress: Any = None,
    gt: npt.NDArray[np.float32] | None = None,
) -> ViewData:
    """Depth of one pair and every picture the page shows of it (runs in the worker thread).

    Parameters
    ----------
    left, right : ndarray, (H, W, 3) uint8
        BGR pair; a grey, BGRA or 16-bit pair is matched as it is and shown at 8-bit BGR.
    calib : Calibration or None
        For the input size; scaled with the images.
    method : str
        A name of ``stereovision.depth.METHODS``, :data:`MATCH_METHODS` (sparse: the matches
        are drawn on the left image, their count said) or :data:`EXTRA_METHODS`.
    width : int, optional
        Processing width (images scaled down to it).
    max_disparity : int, optional
        At the input size; scaled with the images (None: chosen from the images).
    progress : callable, optional
        Called with ``(percent, text)``.
    gt : ndarray, float32 (H, W), optional
        The left image's GT disparity at the input size (NaN: unknown), of a pair used as
        given (no calibration, or a rectified one): a sparse method's statistics then say its
        precision@1 (the share of its matches with GT within 1 px of it), a dense one's its
        bad-2.0 (holes counted as errors) and density over the pixels with GT, at the size
        computed (the GT scaled with the images, :func:`scaled_gt`).

    Raises
    ------
    ValueError
        Unknown method, calibration for another image size, bad images.
    """
    from stereovision.baselines import BM_BLOCK_SIZE, bm_widest_range, round_up16
    from stereovision.cli import colorize
    from stereovision.depth import METHODS, depth_map, estimate_max_disparity
    from stereovision.overview import colour_range
    from stereovision.render import Intrinsics, surface_mesh

    def report(pct: int, text: str) -> None:
        if progress is not None:
            progress(pct, text)

    if method not in METHODS and method not in EXTRA_METHODS and method not in MATCH_METHODS:
        raise ValueError(f"unknown method {method!r}")
    notes: list[str] = []
    if calib is not None:
        # a calibration made at another resolution of the same aspect is scaled, with a note
        calib, note = fit_to_frames(calib, (left.shape[1], left.shape[0]))
        notes += [] if note is None else [note]
    left_s, right_s, s = scale_pair(left, right, width)
    calib_s = scaled_calibration(calib, s, (left_s.shape[1], left_s.shape[0]))
    # depth_map searches any range: the one given, at a lower resolution scaled and rounded
    # up to a whole pixel; OpenCV's matchers only multiples of 16 (baselines.round_up16), said
    opencv = method in EXTRA_METHODS
    # in whole numbers: max_disparity * s in floats can land above an exact product
    # (159 px x 320 / 424 = 120.00000000000001, searched as 121 px)
    w_in, w_s = left.shape[1], left_s.shape[1]
    d_max = None if max_disparity is None else max(1, -(-max_disparity * w_s // w_in))
    if opencv and d_max is not None and d_max % 16:
        notes.append(f"max disparity {d_max} px searched as {round_up16(d_max)} px " + _BY_16)
        d_max = round_up16(d_max)
    widest = (w_s - 1) // 16 * 16 if opencv else w_s - 1  # the range must stay below the width
    why = "the range must stay below the width"
    if method == "opencv-bm":
        # and leave BM's block inside it: a wider range gave disparities past the width (2041 px
        # at 448 px on the 450 px cones), most pixels "valid" and depths of 0.1 m
        widest = bm_widest_range(w_s)
        why = f"{method}'s {BM_BLOCK_SIZE} px block must fit beside it"
    if d_max is not None and d_max > widest and widest >= (16 if opencv else 1) and w_s > 16:
        # a range that fits the pair at its size, scaled down and rounded up, can reach the
        # smaller width (440 px at full size searched 320 px at width 320: refused); a pair
        # 16 px wide or less is the method's to refuse (depth_map's, match's, or
        # _opencv_result's for the OpenCV methods), one too narrow for BM's block opencv_bm's
        notes.append(f"max disparity {d_max} px at width {w_s} searched as {widest} px ({why})")
        d_max = widest
    t0 = time.perf_counter()
    report(5, f"{method}: matching {left_s.shape[1]}x{left_s.shape[0]}")
    # The library's warnings (a pair that looks swapped) go on the page, not the server's log.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        matches = None
        if method in EXTRA_METHODS:
            d = d_max or estimate_max_disparity(left_s, right_s)
            result = _opencv_result(method, left_s, right_s, calib_s, d)
        elif method in MATCH_METHODS:
            result, matches = _sparse_result(method, left_s, right_s, calib_s, d_max)
        else:
            planned = _planned_stages(method, calib_s is not None)

            def stage(name: str) -> None:
                text = f"{method}: {name} done"
                if name in planned:  # the step that follows, the picture after the last one
                    later = planned[planned.index(name) + 1 :]
                    text += f", {_STEP_NAME[later[0]] if later else 'drawing'}…"
                report(_STAGE_PROGRESS.get(name, 50), text)

            result = depth_map(
                left_s, right_s, calib_s, method=method, max_disparity=d_max, progress=stage
            )
    elapsed = time.perf_counter() - t0
    report(92, "drawing")
    shown_left = result.left_rectified if result.left_rectified is not None else left_s
    shown_right = right_s
    if calib_s is not None and not calib_s.rectified:
        # the left image shown is the rectified one the disparity belongs to: the right one
        # too (it was shown as the cameras gave it, beside a rectified left, and the matches
        # were drawn on the raw pair, off the rows they were found on)
        shown_right = calib_s.rectify(left_s, right_s)[1]
    if shown_right.dtype != np.uint8 or shown_left.dtype != np.uint8:
        from stereovision._validate import as_bgr_uint8

        # shown at 8 bits, once and quietly: the matching said the pair's warnings on the page
        # (a 12-bit pair in 16 bits), and each picture drawn of it said them again in the
        # server's log ("image: uint16 image whose largest value is 4077 ...")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            shown_left = as_bgr_uint8(shown_left, "left")
            shown_right = as_bgr_uint8(shown_right, "right")
    disparity_caption = DISPARITY_CAPTION
    disp_lo: float | None = 0.0
    disp_hi = None
    ends = colour_range(result.disparity, 0.0)
    if ends is not None:
        # colorize's own ends (0 px to the 99th percentile; the 1st to the 99th for a map below
        # 0 px, where 0 px up to its top was one colour, captioned "blue 0 px … red -1.4 px"),
        # said in pixels: the picture had no key, as the depth picture had none
        disp_lo, disp_hi = ends
        blue = "0 px" if disp_lo == 0 else f"{disp_lo:.1f} px"
        disparity_caption = f"disparity: blue {blue} … red {disp_hi:.1f} px"
    sparse = matches is not None
    if sparse:
        disparity_url = _data_url(draw_sparse(shown_left, result.disparity, disp_lo, disp_hi))
    else:
        disparity_url = _data_url(colorize(result.disparity, lo=disp_lo, hi=disp_hi))
    # 8-bit black: a 16-bit pair's zeros were warned of as "largest value is 0" when shown
    depth_img = np.zeros((*shown_left.shape[:2], 3), np.uint8)
    depth_caption = DEPTH_CAPTION if result.depth is not None else NO_DEPTH_CAPTION
    depth_ends = None
    if result.depth is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = np.where(np.isfinite(result.depth), 1.0 / result.depth, np.nan)
        finite = inv[np.isfinite(inv)]
        if finite.size:
            # colorize's own range (1st-99th percentile of 1 / depth), said in metres: the
            # picture had no key, and its scale changes with every pair
            lo, hi = (float(np.percentile(finite, q)) for q in (1, 99))
            if sparse:
                depth_img = draw_sparse(shown_left, inv, lo, hi)
            else:
                depth_img = colorize(inv, lo=lo, hi=hi)
            depth_ends = (1.0 / hi if hi > 0 else math.inf, 1.0 / lo if lo > 0 else math.inf)
            near, far = (_length(v, "m") for v in depth_ends)
            depth_caption = f"depth: red {near} … blue {far}"  # one line above the picture
    matches_url = ""
    if method in SPARSE_METHODS or result.density < SPARSE_DENSITY:
        matches_url = _data_url(
            draw_matches(shown_left, shown_right, result.disparity, lo=disp_lo, hi=disp_hi),
            2 * DISPLAY_WIDTH,
        )
    mesh = None
    intr = None
    message_3d = ""
    if result.depth is None:
        message_3d = "No calibration: give --calib to see the scene in 3-D."
    elif len(result.points) == 0:
        message_3d = "Empty point cloud: the matcher found no depth in this pair."
    elif matches is not None:  # sparse
        # no dense map to draw a surface of: the matched points, in either mode
        mesh, count = shown_cloud(result.points, result.colors)
        intr = Intrinsics.from_result(result)
        message_3d = f"{method} is sparse: no dense map, its {count} shown as points" + (
            f" ({len(matches) - len(result.points)} of {len(matches)} matches not drawn: another "
            "match on the same pixel, or no valid depth)"
            if len(matches) > len(result.points)
            else ""
        )
    else:
        report(95, "building the 3-D surface")
        step = max(1, math.ceil(math.sqrt(len(result.points) / MAX_MESH_VERTICES)))
        mesh = surface_mesh(result, step=step)
        intr = Intrinsics.from_result(result)
    if matches is not None:
        amount = f"{len(matches)} matches" + _sparse_precision(matches, gt, left, left_s)
    else:
        amount = f"density {100 * result.density:.0f} %"
        amount += _dense_gt_text(result.disparity, gt, left, left_s)
    head = (
        f"{method} · {left_s.shape[1]}×{left_s.shape[0]} · disparities 0–{result.max_disparity}"
        f" px · {amount} · {elapsed:.2f} s"
    )
    median_depth = None
    if result.depth is not None and len(result.points):
        median_depth = float(np.median(result.points[:, 2]))
    said = notes + [
        advice_for(str(c.message), "page") for c in caught if issubclass(c.category, UserWarning)
    ]
    tail = "".join(f" · warning: {msg}" for msg in dict.fromkeys(said))  # once each, in order
    median = "" if median_depth is None else f" · median depth {_length(median_depth, 'm')}"
    stats = head + median + tail
    return ViewData(
        result=result,
        left_url=_data_url(shown_left),
        right_url=_data_url(shown_right),
        disparity_url=disparity_url,
        depth_url=_data_url(depth_img),
        matches_url=matches_url,
        mesh=mesh,
        intrinsics=intr,
        stats=nowrap_units(stats),
        message_3d=message_3d,
        depth_caption=nowrap_units(depth_caption),
        disparity_caption=nowrap_units(disparity_caption),
        depth_ends=depth_ends,
        median_depth=median_depth,
        stats_parts=(head, tail),
        matches=matches,
    )


def scaled_gt(gt: Any, left: np.ndarray, left_s: np.ndarray) -> npt.NDArray[np.float32] | None:
    """The left image's GT disparity (``gt``, at the size of ``left``) at the size of
    ``left_s`` as the images were scaled: the GT pixel at each scaled pixel's centre (the
    centre of the area the images' ``INTER_AREA`` averages; never an interpolation, so an
    unknown NaN / inf stays unknown), its disparity in the scaled pair's pixels (times the
    width ratio). None without GT (or GT of another size)."""
    if gt is None or np.shape(gt) != left.shape[:2]:
        return None
    g = np.asarray(gt, np.float32)
    (h, w), (h_s, w_s) = left.shape[:2], left_s.shape[:2]
    if (h_s, w_s) != (h, w):
        # INTER_NEAREST takes the first source pixel a scaled one covers (floor(x * w / w_s)):
        # half a scaled pixel left of and above the images' pixels
        nearest = cv2.resize(g, (w_s, h_s), interpolation=cv2.INTER_NEAREST_EXACT)
        g = np.asarray(np.asarray(nearest) * (w_s / w), np.float32)
    return g


def _dense_gt_text(disparity: np.ndarray, gt: Any, left: np.ndarray, left_s: np.ndarray) -> str:
    """What the statistics say of a dense map (at the size of ``left_s``) against the left
    image's GT (evaluation.md: bad-2.0, holes counted as errors, and the density, over the
    pixels with GT): "" without GT."""
    from stereovision.evaluate import dense_metrics

    g = scaled_gt(gt, left, left_s)
    if g is None or g.shape != np.shape(disparity):
        return ""
    m = dense_metrics(disparity, g)
    if m.n_gt == 0:
        return ", no GT pixel"
    return f", on GT bad-2.0 {m.bad[2.0]:.1f} % (holes count) at density {m.density:.1f} %"


def _sparse_precision(matches: Any, gt: Any, left: np.ndarray, left_s: np.ndarray) -> str:
    """What the statistics say of a sparse method's matches against the left image's GT
    (``gt`` at the size of ``left``; scaled to that of ``left_s`` as the images were): ""
    without GT."""
    from stereovision.evaluate import sparse_metrics

    g = scaled_gt(gt, left, left_s)
    if g is None:
        return ""
    m = sparse_metrics(matches.xl, matches.yl, matches.xr, g)
    if m.count == 0:
        return ", none on GT"
    return f", precision@1 {m.precision[1.0]:.1f} % of the {m.count} on GT"


#: Characters of the page's labels that ``overview.png``'s title (OpenCV's ASCII font) says
#: otherwise; any other non-ASCII character is drawn as "?".
_ASCII_FOR = {"×": "x", "…": "...", "–": "-", "—": "-", "·": "|", "\u00a0": " "}


def overview_name(source_label: str) -> str:
    """The pair's name in a saved ``overview.png``'s title: what the page calls it (its source
    label: ``scene data/cones``, ``files``, ``folder data/seq: pair 0002 (2 of 20)``, the
    cameras), in the ASCII the picture's font draws.

    Parameters
    ----------
    source_label : str
        The page's label of the pair on show ("" when it has none: ``"pair"``).

    Returns
    -------
    str
    """
    from stereovision.overview import cv2_text

    return cv2_text("".join(_ASCII_FOR.get(c, c) for c in source_label.strip()) or "pair")


def max_disparity_hint(auto: int | None, full_width: int, width: int | None) -> str:
    """The max-disparity field's hint: the pair's own range at full size (the field is in
    full-size pixels), and what is searched at the processing width when it is smaller.

    At 320 the hint said the full-size range alone (64 px on a 450 px pair, 46 px searched).
    It is short enough for the field (it was cut at "the pair's rang" on a 1500 px page).

    Parameters
    ----------
    auto : int or None
        The pair's range at full size (None: estimated from the images, :data:`AUTO_HINT`).
    full_width : int
        The pair's width at full size.
    width : int or None
        The processing width (None: full size).

    Returns
    -------
    str

    Examples
    --------
    >>> max_disparity_hint(64, 450, None)
    'auto: 64 px at full size'
    >>> max_disparity_hint(64, 450, 320)
    'auto: 64 px at full size (46 at 320)'
    """
    if auto is None:
        return AUTO_HINT
    said = f"auto: {auto} px at full size"
    if width is not None and width < full_width:
        # as compute_view scales the range: rounded up to a whole pixel
        said += f" ({max(1, -(-auto * width // full_width))} at {width})"
    return said


def parse_max_disparity(text: str | None, width: int) -> int | None:
    """The page's max-disparity field: None for automatic (empty or "auto"), else its pixels.

    Parameters
    ----------
    text : str or None
        As typed.
    width : int
        The pair's width in pixels (at the size it comes in).

    Returns
    -------
    int or None

    Raises
    ------
    ValueError
        Not a whole number of pixels above 0, or not smaller than ``width`` (``depth_map``
        searches the range as typed; the OpenCV reference methods round it up to a multiple
        of 16 px, kept below the width, said in the statistics).

    Examples
    --------
    >>> parse_max_disparity(" auto ", 450), parse_max_disparity("64", 450)
    (None, 64)
    """
    said = "" if text is None else str(text).strip()
    if said.lower() in ("", "auto"):
        return None
    try:
        value = int(said)
    except ValueError:
        value = 0
    if value < 1:
        raise ValueError(
            "max disparity: expected a whole number of pixels above 0 (empty: automatic), "
            f"got {said!r}"
        )
    if value >= width:
        raise ValueError(
            f"max disparity {value} px is not smaller than the pair's width {width} px"
        )
    return value


def _pending_key(src: int | str) -> int | str:
    """``src`` as the pending-open check knows it: a Linux ``/dev/videoN`` is camera ``N``.

    Typed as ``0`` and as ``/dev/video0`` (a by-id link is resolved to it before this), one
    device was not recognised as still opening. Only that exact form is an index: other
    paths are files or streams.
    """
    if isinstance(src, str) and sys.platform.startswith("linux"):
        node = re.fullmatch(r"/dev/video(\d+)", src, re.ASCII)
        if node:
            return int(node.group(1))
    return src


def _source_name(src: int | str) -> str:
    """A camera source as the page names it: ``camera 0``, the file's name, or a stream's
    whole URL (``rtsp://rig/0`` was named ``0``, as camera 0 might be), its password and
    secret parameters, if any, said as ``***`` (:func:`~stereovision.capture.mask_url_secrets`):
    the name goes into the page's messages and the server's log."""
    if isinstance(src, int):
        return f"camera {src}"
    if "://" in src:
        return mask_url_secrets(src)
    return Path(src).name or src


@dataclass
class _Frames:
    """A pair read from a source (:func:`_read_pair`), not yet on show."""

    left: Frame
    right: Frame
    #: A folder pair's scene calib.txt, read (None: the page's ``--calib`` applies).
    calib: Any = None
    #: The folder pair's label (``folder data/seq: pair 0002 (2 of 20)``; "" for cameras).
    folder: str = ""
    #: `` (8.0 frames averaged)`` when averaged, else "".
    averaged: str = ""
    #: Why the files were started again from their first pair during this read, when one
    #: ended early (a gap in a numbered sequence: :attr:`_CaptureAdapter.restarted`), else "".
    restarted: str = ""


def _read_pair(source: StereoSource, average: bool) -> _Frames:
    """The next pair of ``source``, averaged over :data:`AVERAGE_FRAMES` reads when ``average``
    (not an image folder's: one pair after another). It touches nothing but ``source``: the
    page reads in a thread of its own (a wedged camera froze the page).

    Raises
    ------
    ValueError
        The two frames differ in size, or ``average`` of frames of more than 8 bits (a 16-bit
        image sequence), which the filter does not average.
    OSError, RuntimeError
        As the source's read raises them (a read given up after ``read_timeout``).
    """
    left, right = source.read()
    restarted = getattr(source, "restarted", None)
    folder = source if isinstance(source, FolderPairs) else None
    if left.shape != right.shape:
        from stereovision.io import image_size_text

        what = folder.describe() if folder else "the cameras give different sizes"
        raise ValueError(f"{what}: left {image_size_text(left)}, right {image_size_text(right)}")
    got = _Frames(left, right, restarted=restarted or "")
    if folder:  # one pair after another, not frames of one view: nothing to average
        got.folder = folder.describe()
        job = folder.current
        if job.calib is not None:  # a scene's calib.txt
            from stereovision.calibration import Calibration

            try:
                got.calib = Calibration.from_file(job.calib)
            except (OSError, ValueError) as exc:  # changed since played: said with its pair
                raise folder.said_of_pair(exc) from exc
    elif average:
        from stereovision.capture import _check_8_bit_frames
        from stereovision.temporal import TemporalFilter

        # a 16-bit image sequence or bag was "left: expected a uint8 image, got uint16", the
        # filter's words for an argument the user never passed (capture --temporal's check)
        _check_8_bit_frames(left, right)
        tf = TemporalFilter(max_frames=AVERAGE_FRAMES)
        got.left, got.right = tf(left, right)
        for _ in range(AVERAGE_FRAMES - 1):
            got.left, got.right = tf(*source.read())
            got.restarted = got.restarted or getattr(source, "restarted", None) or ""
        moved = f", {tf.restarts} restarts: the view moved" if tf.restarts else ""
        got.averaged = f" ({tf.mean_frames():.1f} frames averaged{moved})"
    return got


def _for_the_loop(exc: BaseException, what: str) -> BaseException:
    """``exc``, raised in a camera ``what`` ("open", "read") in a thread of the page's, as it
    can be handed to the page's loop: StopIteration cannot be set on a Future (the page said
    "reading ..." for good, the cameras "still opening"), and SystemExit or KeyboardInterrupt
    raised into the loop stopped the server; those become a RuntimeError naming them."""
    if isinstance(exc, Exception) and not isinstance(exc, StopIteration):
        return exc
    log.error("gui: a camera %s raised %s", what, type(exc).__name__, exc_info=exc)
    said = f": {exc}" if str(exc) else ""
    out = RuntimeError(f"the camera {what} ended with {type(exc).__name__}{said}")
    out.__cause__ = exc
    return out


#: What the page's worker thread raises for a failure the page says as it is (bad input, a
#: file, a pair too large, OpenCV refusing a pair); anything else is a bug (:func:`_as_said`),
#: :data:`~stereovision._validate.BUG_ERRORS` (RecursionError, NotImplementedError) too.
_SAID = (ValueError, OSError, RuntimeError, MemoryError, cv2.error)


def _as_said(exc: Exception, what: str) -> Exception:
    """``exc``, raised by the page's worker thread while ``what`` ("computing census",
    "saving"), as the page says it: itself when it is one of :data:`_SAID`, else (a bug of
    ours) a RuntimeError in the CLI's words for one (``internal IndexError: ... (please
    report this)``), its trace in the server's log.

    Such an error went past the handler's ``except``: a computation's left the page
    "computing" under its progress bar for good, Save and Find floor then saying "the new pair
    is being computed"; a Save's, a floor's or a rows check's said nothing at all."""
    if isinstance(exc, _SAID) and not isinstance(exc, BUG_ERRORS):
        return exc
    log.error("gui: %s failed", what, exc_info=exc)
    return RuntimeError(internal_error(exc).removeprefix("stereovision: error: "))


def _button_and_answer(
    v3: Any, html: Any, text: str, button_id: str, click: Any, answer: str, answer_id: str
) -> None:
    """A small button with the line it answers beside it (state variable ``answer``).

    The button is as wide as its label and the line takes the rest of the row: in a fixed
    quarter of it, "CHECK ROWS" stood out of both sides of its button on a 1000 px page.
    """
    with v3.VRow(dense=True, align="center", classes="my-1"):
        with v3.VCol(cols="auto", style="min-width: 25%;"):
            v3.VBtn(text, id=button_id, size="small", variant="outlined", block=True, click=click)
        with v3.VCol():
            html.Div("{{ " + answer + " }}", id=answer_id, classes="text-caption")


def _file_picker(label: str, model: str, items: str, element_id: str) -> None:
    """A combobox choosing one of the allowed files (``items`` holds ``{title, value}`` dicts)."""
    from trame.widgets import vuetify3 as v3

    v3.VCombobox(
        label=label,
        v_model=(model,),
        items=(items,),
        item_title="title",
        item_value="value",
        return_object=False,
        density="compact",
        hide_details=True,
        id=element_id,
    )


def _toggle(
    model: str,
    values: Any,
    element_id: str,
    button_ids: str | None = None,
    classes: str | None = None,
    button_classes: str | None = None,
    wrap: bool = False,
    disabled: str | None = None,
) -> None:
    """A row of buttons choosing one of ``values`` (state variable ``model``); each button's id
    is ``button_ids-VALUE`` when ``button_ids`` is given. With ``wrap``, buttons that do not
    fit go on to further rows of the same height (a wrapped group kept one row's height and
    squeezed its buttons to half of it). ``disabled`` names a state variable that, true,
    disables the row."""
    from trame.widgets import vuetify3 as v3

    if wrap:
        classes = " ".join(c for c in (classes, "flex-wrap h-auto") if c)
    extra: dict[str, Any] = {} if classes is None else {"classes": classes}
    if disabled is not None:
        extra["disabled"] = (disabled,)
    with v3.VBtnToggle(
        v_model=(model,),
        mandatory=True,
        density="compact",
        divided=True,
        variant="outlined",
        id=element_id,
        **extra,
    ):
        for v in values:
            kw: dict[str, Any] = {} if button_ids is None else {"id": f"{button_ids}-{v}"}
            if button_classes is not None:
                kw["classes"] = button_classes
            if wrap:
                kw["style"] = f"height: {TOGGLE_HEIGHT_PX}px;"
            v3.VBtn(v, value=v, size="small", **kw)


class StereoApp:
    """The trame application: state, controllers, layout and the worker thread.

    Parameters
    ----------
    server : trame server
        From ``trame.app.get_server(client_type="vue3")``.
    folders : AllowedFolders
        Where files chosen on the page may come from.
    demo_scene : Path
        Scene shown when no camera source is given.
    source : StereoSource, optional
        Opened live / video camera pair (``--left`` / ``--right``).
    calib : Calibration, optional
        Calibration of the camera pair (``--calib``).
    source_names : tuple of str
        The two camera sources as typed (shown in the page's camera fields).
    source_label : str, optional
        What the page calls the opened source (default: "cameras" and the sources' names).
    sizeless_calib : tuple of str, optional
        ``(path, unit)`` of a ``--calib`` that holds no image size (OpenCV ``stereo_calib``
        output, a ``Q.dat`` alone), given instead of ``calib``: the first pair it is used with
        (the cameras' or an image folder's first pair, files) sizes it; a pair of another size
        is then refused as ``depth`` refuses it ("calibration is for WxH images, got ...").
    read_timeout : float or None
        Seconds a read of the cameras opened on the page may take (``--read-timeout``;
        :data:`~stereovision.capture.DEFAULT_READ_TIMEOUT`; None: no limit).
    """

    def __init__(
        self,
        server: Any,
        folders: AllowedFolders,
        demo_scene: Path,
        source: StereoSource | None = None,
        calib: Any = None,
        source_names: tuple[str, str] = ("", ""),
        source_label: str | None = None,
        sizeless_calib: tuple[str, str | None] | None = None,
        read_timeout: float | None = DEFAULT_READ_TIMEOUT,
    ) -> None:
        from stereovision.depth import METHODS
        from stereovision.render import _pv, make_plotter

        pv = _pv()  # VTK's first import, Ctrl-C held: an interrupt inside it crashed the process
        pv.OFF_SCREEN = True
        self.server = server
        self.state = server.state
        self.ctrl = server.controller
        self.folders = folders
        self.demo_scene = demo_scene
        self.source = source
        self.source_calib = calib
        self.read_timeout = read_timeout
        #: ``--calib`` that holds no image size, until the first pair it is used with sizes it
        #: (:meth:`_calib_for`); then the size it was read at, which every pair must have.
        self._sizeless_calib = sizeless_calib
        self._calib_sized_by: tuple[int, int] | None = None
        self._source_label = source_label
        #: The open cameras' sources as typed (their label's names; the fields may since hold
        #: others that failed to open).
        self._source_names = source_names
        #: The pair's rectification from its features ("Rectify" button), kept for the
        #: cameras' next pairs; None when the pair is used as it comes.
        self.homographies: Any = None
        self.pair: tuple[np.ndarray, np.ndarray] | None = None
        # the pair as the source gave it, before "Rectify" (which starts from it again)
        self.raw_pair: tuple[np.ndarray, np.ndarray] | None = None
        self.calib: Any = None
        self._scene_gt: tuple[Any, Any] = (None, None)
        #: Why the scene on show cannot be matched over its own range (:func:`scene_too_narrow`),
        #: with the pair it belongs to, or None.
        self._scene_narrow: tuple[Any, str | None] = (None, None)
        #: Why the pair has no calibration when ``--calib`` would not help (a scene without
        #: calib.txt, files another calibration does not fit); None: "give --calib".
        self._no_calib: str | None = None
        self.max_disparity: int | None = None
        #: The page's max-disparity field, applied (None: automatic, the scene's range or one
        #: estimated from the images).
        self.chosen_max_disparity: int | None = None
        #: The page's words refusing the max-disparity field's last value (None: it was taken):
        #: cleared when the value in use is typed again.
        self._max_disp_refused: str | None = None
        self.view: ViewData | None = None
        #: The point-cloud file on show ("Open") and its caption: it stays in the 3-D view
        #: whichever way the surface / points toggle is set, until the next computed pair.
        self._cloud: Any = None
        self._cloud_caption = ""
        #: The 3-D caption's count of the computed pair's points when a subset is drawn.
        self._points_note = ""
        # what the page shows came from: put back when a new pair fails to compute, so that
        # Check rows and Find floor never work on a pair the page does not show
        self._shown: dict[str, Any] | None = None
        # the page's results of the shown pair while a new pair computes (None otherwise)
        self._page_before: dict[str, Any] | None = None
        #: The method and resolution of the result on show, and the flag that keeps their
        #: toggles' return to them (after a failed change) from computing it again.
        self._shown_settings: tuple[str, str] | None = None
        self._settings_back = False
        #: The scene list's value the current pair came from ("" for any other source): what
        #: the list goes back to when another choice fails.
        self._scene = ""
        self._computing = False
        #: The running computation's step as its status says it ("computing (census)"), without
        #: the reads under way (:meth:`_status_with_reads`).
        self._step: str | None = None
        #: The error of a camera read or open that failed while a pair computed: the
        #: computation's end keeps it on the page (it said "ready" and cleared it).
        self._failed_meanwhile: str | None = None
        #: Camera sources whose open (on the page's "Open") has not returned yet, given up or
        #: not: another Open of them is refused (each left one more thread blocked in them).
        self._opening: set[int | str] = set()
        #: The source choice (``_choice``) whose first pair is being read, an Open's cameras
        #: or a folder's Play (:meth:`_first_pair`), and how "reading ..." names it: a Capture
        #: meanwhile read the cameras that choice replaces, or said "no camera open".
        self._first_read: tuple[int, str] | None = None
        #: Counts the page's choices of what to show (Open, an image folder, a scene, files): an
        #: open that returns after a newer choice closes its cameras instead of replacing it.
        self._choice = 0
        #: Sources a read of the page's runs in now (:meth:`_read_in_thread`): a second Capture
        #: of one is refused; one replaced meanwhile is closed when its read returns (closing a
        #: camera under a grab in another thread is not safe).
        self._reading: list[StereoSource] = []
        #: The opens and reads under way (a token each) with their "opening ..." or "reading
        #: ..." status, which a computation's end and progress keep saying
        #: (:meth:`_status_with_reads`).
        self._under_way: list[tuple[object, str]] = []
        self._close_after_read: list[StereoSource] = []
        #: A scene or files are on show, chosen after :attr:`source` opened (False: its pair,
        #: or none: cameras given at start-up whose first read failed are read by a Capture).
        self._other_on_show = False
        #: Counts the pairs a choice put on show (a scene, files, an image folder, cameras): a
        #: Capture's pair that comes after one is dropped (not after an Open that failed).
        self._shows = 0
        #: ``_choice`` when a Capture was refused for a scene or files on show: another
        #: Capture with no choice since goes back to the source.
        self._capture_back: int | None = None
        #: The one worker thread of computations, checks and Saves, named so that the process
        #: can end past a computation when the server stops (:meth:`stop_work`).
        self._executor = concurrent.futures.ThreadPoolExecutor(
            max_workers=1, thread_name_prefix=WORK_THREAD_PREFIX
        )
        #: Held while a Save writes (:meth:`_write_save`); :meth:`stop_work` waits for it.
        self._save_lock = threading.Lock()
        self._stopped = False
        self._generation = 0
        self._lock: asyncio.Lock | None = None
        self.plotter = make_plotter((640, 480))
        self._remote_view: Any = None
        self._clip_tag: int | None = None
        #: The 3-D view's camera as the sliders last placed it: the mouse moves the view's
        #: camera on the server (the page's view is rendered there), not the sliders, so a
        #: camera that differs from it is one the mouse moved (None: not placed yet).
        self._slider_camera: Any = None
        #: True while the sliders are set from the view the mouse left (no slider move).
        self._following_mouse = False
        #: The six sliders' values as the unit toggle converted them (:meth:`_on_unit`), until
        #: the sliders' listener has seen them: it is no slider move (None: no conversion).
        self._unit_converted: dict[str, Any] | None = None
        if self.plotter.iren is not None:  # the page's mouse events drive it (mode="server")
            self.plotter.iren.interactor.AddObserver("EndInteractionEvent", self._on_mouse_end)
        from stereovision.gui import bundled_data_dir

        # "Save" writes only inside the --data folders (not into the installed package's data)
        bundled = bundled_data_dir().resolve()
        self._save_roots = [r for r in folders.roots if r != bundled]
        #: Folders a "Save" is writing into now (a second Save there would replace its files).
        self._saving_into: set[Path] = set()

        st = self.state
        st.methods = [*METHODS, *MATCH_METHODS, *EXTRA_METHODS]
        st.method = METHODS[0]
        st.resolutions = list(RESOLUTIONS)
        st.resolution = RESOLUTIONS[0]
        st.busy = False
        st.progress = 0
        st.status = "starting"
        st.error = ""
        st.computations = 0
        st.captures = 0
        st.average = False
        st.fourccs = list(FOURCCS)
        st.fourcc = FOURCCS[0]
        st.img_left = st.img_right = st.img_disparity = st.img_depth = st.img_matches = ""
        st.stats = ""
        st.depth_caption = DEPTH_CAPTION
        st.disparity_caption = DISPARITY_CAPTION
        st.message_3d = ""
        st.source_label = ""
        st.rows_label = ""
        st.floor_label = ""
        st.img_floor = ""
        st.floor_caption = floor_caption()
        # the page's fields, sent to every browser on it: a stream's password is not shown
        # (a URL is no file the page's Open takes: nothing typed there is lost)
        st.cam_left, st.cam_right = (mask_url_secrets(str(n)) for n in source_names)
        st.live = source is not None
        #: The average switch works on cameras (and recordings), not on a folder's pairs: one
        #: pair after another, never averaged (the switch was on and did nothing).
        st.can_average = st.live and not isinstance(source, FolderPairs)
        # None, not "": the select shows "" as a chosen, empty entry (its label raised above it)
        st.scene = None
        st.scenes = []
        st.cloud_path = ""
        st.clouds = []
        st.left_file = st.right_file = ""
        st.pair_folder = ""
        st.pair_folders = []
        st.images = []
        st.view_mode = "surface"
        #: The 3-D view shows points whatever the toggle (a sparse method's matches): the
        #: toggle says "points" and is disabled; the user's own choice comes back after.
        st.points_only = False
        self._chosen_view_mode = "surface"
        #: The mode the computed pair's geometry on show was drawn for (None: none drawn).
        self._drawn_mode: str | None = None
        st.view_aspect = VIEW_ASPECT
        st.wide_pair = False
        st.max_disp = ""
        st.max_disp_hint = AUTO_HINT
        st.units = list(UNITS)
        st.unit = UNITS[0]
        #: The unit the translation sliders' values are in (they are converted when it changes).
        self._unit = UNITS[0]
        st.translation_range, st.translation_step = translation_range(), TRANSLATION_STEP
        #: The save folder the page offers; left as offered (or emptied), each Save takes the
        #: first of it, ``saved-2``, ``saved-3``, ... that is new or empty.
        #: It is shown relative to the current directory (or ``~/...``), its whole path in the
        #: field's tooltip (the README's picture showed a temporary ``/tmp/sv-.../scenes/saved``).
        self._offered_save_dir = (
            display_path(self._save_roots[0] / SAVE_FOLDER) if self._save_roots else ""
        )
        st.save_dir = self._offered_save_dir
        st.save_label = ""  # the save field's hint and tooltip: _refresh_file_lists, below
        for name in _CONTROL_NAMES:
            st[name] = 0.0
        self._refresh_file_lists()
        self._build_ui()
        st.change(*_CONTROL_NAMES)(self._on_controls)
        st.change("method", "resolution")(self._on_method)
        st.change("view_mode")(self._on_view_mode)
        st.change("unit")(self._on_unit)
        st.change("scene")(self._on_scene)
        st.change("save_dir")(self._on_save_dir)
        self.ctrl.on_server_ready.add(self._on_ready)

    # ------------------------------------------------------------------------- helpers

    def _refresh_file_lists(self) -> None:
        """The lists of what the ``--data`` folders (and the home folder's saves) hold, and the
        save field's hint and tooltip, which follow the same rule as the point-cloud list
        (:meth:`_offered_save_folder`): set at start-up alone, they named the ``--data``
        folder after a Save filled the last writable ``saved-N`` of a read-only one, while
        the list and the next Save went home."""
        st = self.state
        st.save_dir_title = self._save_title(st.save_dir)
        st.save_hint = self._save_hint(st.save_dir)
        f = self.folders
        self.state.scenes = [{"title": f.label(p), "value": str(p)} for p in f.scenes()]
        home = self._home_saves()
        self.state.clouds = [
            {"title": f.label(p), "value": str(p)} for p in f.files(CLOUD_SUFFIXES)
        ] + [
            {"title": display_path(p), "value": str(p)}
            for p in (home.files(CLOUD_SUFFIXES) if home is not None else [])
        ]
        self.state.images = [
            {"title": f.label(p), "value": str(p)} for p in f.files(IMAGE_SUFFIXES)
        ]
        self.state.pair_folders = [{"title": f.label(p), "value": str(p)} for p in f.folders()]

    def _home_saves(self) -> AllowedFolders | None:
        """The home folder's ``stereovision-saved``, ``-2``, ... a Save as offered writes into
        when the first ``--data`` folder cannot be written (:meth:`_fallback_save_folder`), as
        folders the page may read (their clouds: the point-cloud list offered only the
        ``--data`` folders', and "Show" refused what was just saved). None when Saves do not
        go there. A link named so is left out: it may lead anywhere."""
        if not self._offered_save_folder_refused():
            return None
        try:
            home = Path.home()
            names = os.listdir(home)
        except (RuntimeError, OSError):  # no home folder known, or none to read
            return None
        saves: list[tuple[int, Path]] = []
        for name in names:
            m = re.fullmatch(re.escape(FALLBACK_SAVE_FOLDER) + r"(?:-(\d+))?", name, re.ASCII)
            p = home / name
            if m and not p.is_symlink() and p.is_dir():
                saves.append((int(m.group(1) or 1), p))
        try:
            return AllowedFolders(p for _, p in sorted(saves)) if saves else None
        except OSError:  # one removed meanwhile: listed at the next refresh
            return None

    def _cloud_file(self, typed: str) -> tuple[Path, str]:
        """The point-cloud file ``typed`` on the page and its name as the page says it: in the
        ``--data`` folders, or (an absolute path) in the home folder's saves
        (:meth:`_home_saves`).

        Raises
        ------
        ValueError, FileNotFoundError
            As :meth:`AllowedFolders.resolve` raises them for the ``--data`` folders.
        """
        try:
            path = self.folders.resolve(typed)
            return path, self.folders.label(path)
        except ValueError:
            home = self._home_saves() if expand_home(typed).is_absolute() else None
            if home is None or not home.contains(typed):
                raise
        path = home.resolve(typed)
        return path, display_path(path)

    def _typed_save_folder(self, typed: str) -> Path:
        """The folder a Save goes to for the save field's text (not the offered one).

        A relative path is read as the field shows paths, relative to the current directory,
        when that lands inside a ``--data`` folder; else relative to the first ``--data``
        folder (a bare name such as ``mine``).

        Raises
        ------
        ValueError
            Empty, or outside the ``--data`` folders.
        """
        text = typed.strip()
        p = expand_home(text) if text else None
        if p is not None and "\x00" not in text and not p.is_absolute():
            here = real_path(Path.cwd() / p)
            if any(here == r or here.is_relative_to(r) for r in self._save_roots):
                return here
        return self.folders.resolve_output(typed, self._save_roots)

    def _save_title(self, typed: str | None) -> str:
        """The save field's tooltip: the whole path a Save would write into ("" for none)."""
        text = str(typed or "").strip()
        if self._save_roots and text in ("", self._offered_save_dir):
            try:
                folder, why = self._offered_save_folder()
            except (ValueError, OSError):  # no such folder in --data: the Save says why
                return ""
            if not why:
                return f"{self._save_roots[0] / SAVE_FOLDER} (or the next new saved-N)"
            # a read-only --data folder: such a Save goes home (save), ``folder`` refused (not
            # ``saved``: saved-2 past a writable, full one)
            try:
                home = Path.home() / FALLBACK_SAVE_FOLDER
            except RuntimeError:  # no home folder known: the Save says so
                return f"{folder} cannot be written: {why}"
            return f"{home} (or the next new -N: {folder} cannot be written: {why})"
        try:
            return str(self._typed_save_folder(text))
        except (ValueError, OSError):
            return ""

    def _save_hint(self, typed: str | None) -> str:
        """The line under the save field: where a typed folder goes, in sight. A bare name
        (``mine``) goes into the first ``--data`` folder, not the current one, which only the
        field's tooltip said."""
        text = str(typed or "").strip()
        if not self._save_roots:
            return NO_SAVE_HINT
        if text in ("", self._offered_save_dir):
            # a read-only data set: save goes home
            return READ_ONLY_SAVE_HINT if self._offered_save_folder_refused() else SAVE_HINT
        try:
            folder = self._typed_save_folder(text)
            p = expand_home(text)
            in_data = not p.is_absolute() and real_path(Path.cwd() / p) != folder
        except (ValueError, OSError):  # the Save says why
            return SAVE_HINT
        where = f"a Save writes into {display_path(folder)}"
        if in_data:
            where += f" (relative to the --data folder {display_path(self._save_roots[0])})"
        return where

    def _on_save_dir(self, save_dir: str | None = None, **_: Any) -> None:
        self.state.save_dir_title = self._save_title(save_dir)
        self.state.save_hint = self._save_hint(save_dir)

    def _fail(
        self,
        exc: BaseException,
        path: Path | None = None,
        outlasts: bool = False,
        typed: Iterable[object] = (),
    ) -> None:
        """Say ``exc`` on the page (its first line), ``path`` in it as the page shows paths
        (:func:`short_paths`) when given, ``path`` and the names ``typed`` in it escaped (a
        newline in one cut the line there: :func:`first_line`). With ``outlasts`` (a camera's
        read or open, a click refused: a Load, a Show, an Open, a Save), an error said while a
        pair computes stays on the page after the computation's end (it cleared a missing
        file's "no such file", as if the click had been taken)."""
        if isinstance(exc, BUG_ERRORS):  # caught as a RuntimeError by the handlers: a bug
            exc = _as_said(exc, "an action")
        said = short_paths(_message(exc), path) if path is not None else ""
        # shortened before first_line escapes a control character in the path (the replace
        # missed it then), and said with the path escaped: a newline in it cut the line there
        msg = (
            first_line(ValueError(said), [path, *typed]) if said.strip() else first_line(exc, typed)
        )
        log.info("gui error: %s", msg)
        with self.state:
            self.state.error = msg
            if not self._computing:  # a failed click during a computation leaves its progress
                self.state.busy = False
                self.state.status = self._status_with_reads(None) or "error"
            elif outlasts:
                self._failed_meanwhile = msg

    def _done(self) -> None:
        """A button's action succeeded: an earlier failure's message and "error" status go (they
        stayed until the next computed pair), and a refused max disparity with its message
        (:meth:`_max_disp_back`)."""
        with self.state:
            self.state.error = ""
            # a refused max disparity went with the error: the field kept it ("500" after a
            # Find floor, Check rows, Show or Save) over a result of the range in use
            self._max_disp_back()
            # without a pair on show too: the toolbar said "error" above a page with no error
            # on it (cameras that failed at start-up, then a point-cloud file opened)
            if self._computing:
                return
            if self._under_way:
                self.state.status = self._status_with_reads(None)
            elif self.view is not None or self.state.status == "error":
                self.state.status = "ready"

    def _other_source(self) -> None:
        """The pair no longer comes from the scene list: clear its choice, so that choosing the
        same scene again loads it (trame reports only a changed value)."""
        self._scene = ""
        self.state.scene = None

    def _show_demo_in_list(self) -> None:
        """The scene list shows the demo scene on show at start-up (it showed an empty choice
        beside "scene data/cones"): its entry, found by its real path."""
        demo = str(Path(self.demo_scene).resolve())
        if any(item["value"] == demo for item in self.state.scenes):
            self._scene = demo
            self.state.scene = demo

    def _spawn(self, coro: Any) -> None:
        from trame.app import asynchronous

        asynchronous.create_task(coro)

    # ------------------------------------------------------------------------- sources

    def _load_scene(self, path: str | Path) -> None:
        from stereovision.io import load_scene, scene_too_narrow

        scene_dir = self.folders.resolve(path) if Path(path) != self.demo_scene else Path(path)
        # a 16-bit pair as `depth`, `eval` and `view` read it: at its top 8 bits a 12-bit
        # scene was matched from its 0-15 grey levels
        scene = load_scene(scene_dir, full_bits=True)
        self.pair = self.raw_pair = (scene.left, scene.right)
        #: The scene's GT disparity and the pair it belongs to (a sparse method's precision, a
        #: dense one's bad-2.0, are said while that pair is computed as given: not after
        #: Rectify, nor for another pair).
        self._scene_gt = (self.pair, scene.gt)
        self._scene_narrow = (self.pair, scene_too_narrow(scene))
        self.calib = scene.calib
        self.max_disparity = scene.max_disparity
        self.homographies = None  # another rig
        label = self.folders.label(scene_dir)
        # a scene's calibration is its own calib.txt (--calib is for cameras and files)
        self._no_calib = None if scene.calib is not None else f"scene {label} has no calib.txt"
        self.state.source_label = f"scene {label}"
        self.state.rows_label = ""
        self._other_on_show = True
        self._shows += 1

    def _grab(self) -> None:
        """Read a pair from the open source here and show it (the page's reads run in a thread:
        :meth:`_read_in_thread`)."""
        if self.source is None:
            raise OSError("no camera open: give --left/--right or open cameras below")
        self._use_pair(_read_pair(self.source, bool(self.state.average)))

    def _use_pair(self, got: _Frames) -> None:
        """Make ``got``, a pair read from :attr:`source`, the pair on show (on the page's loop).

        Raises
        ------
        ValueError
            A ``--calib`` sized by another pair (:meth:`_calib_for`).
        """
        left, right = got.left, got.right
        calib = got.calib
        if calib is None:  # --calib (one without an image size: sized by this pair, or refusing it)
            calib = self._calib_for(left)
        self.pair = self.raw_pair = (left, right)
        self._other_source()
        self._other_on_show = False
        self.calib = calib
        self._no_calib = None
        self.max_disparity = None
        # a stream by its URL, as the page's messages name it (_source_name): by its last part,
        # rtsp://rig/0 and rtsp://rig/1 were labelled "cameras 0 / 1", as cameras 0 and 1 are
        names = (
            _source_name(str(n)) if "://" in str(n) else Path(str(n)).name or str(n)
            for n in self._source_names
        )
        label = self._source_label or "cameras " + " / ".join(names)
        self.state.source_label = (got.folder or label) + got.averaged
        self.state.rows_label = ""
        if got.restarted:
            # the images after a gap in a sequence were never shown, the files started again
            # without a word (capture and stream say it): said under the pair, paths as the
            # page shows them
            said = got.restarted
            for src in getattr(self.source, "sources", ()):
                if isinstance(src, str) and "://" not in src:
                    said = short_paths(said, Path(src).parent)
            self.state.rows_label = f"warning: started again from the first pair: {said}"
        rect = self.homographies
        if rect is not None and rect.input_size == (left.shape[1], left.shape[0]):
            # the cameras rectified from their features: every new pair through the same
            # homographies (the rows stay as the button left them)
            self.pair = rect.rectify(left, right)
            self.max_disparity = rect.max_disparity
            self.state.source_label += " (rectified from features)"

    def _calib_for(self, left: np.ndarray) -> Any:
        """``--calib`` for a pair whose left image is ``left``. One that holds no image size
        is read at the size of the first pair it is used with, as ``batch`` reads it at its
        first pair's; a pair of another size is then refused in ``depth``'s words.

        Raises
        ------
        ValueError
            A pair of another size than the one that sized such a calibration.
        """
        from stereovision.depth import _rig_to_warp_by

        if self._sizeless_calib is not None:
            from stereovision.cli import load_calibration

            path, unit = self._sizeless_calib
            self.source_calib = load_calibration(path, unit, pair=left)
            self._sizeless_calib = None
            self._calib_sized_by = (left.shape[1], left.shape[0])
        if self._calib_sized_by is not None:
            # "calibration is for 640x480 images, got 320x240 (...)", as depth and batch say,
            # its remedy in the page's words (it said "calib.scaled_to((320, 240))")
            try:
                _rig_to_warp_by(self.source_calib, left.shape[1], left.shape[0], None)
            except ValueError as exc:
                raise ValueError(advice_for(str(exc), "page")) from None
        return self.source_calib

    def _camera_source(self, text: str) -> int | str:
        """The camera field's ``text`` as the Open opens it: a device index, a V4L2 device node
        (``/dev/video2``, or a ``/dev/v4l/by-id/...`` link: the node it leads to), else a file
        or pattern of the allowed folders.

        A device typed by its node was refused as "path outside the allowed folders" (unless
        ``--data /dev``): the same camera as its index, which opens, and by-id links are how
        a rig keeps its left and right cameras apart across reboots.

        Raises
        ------
        ValueError, FileNotFoundError
            As :func:`parse_source` and :meth:`AllowedFolders.resolve` raise them; a stream's
            URL (``rtsp://...``: streams are given to ``gui --left/--right``).
        """
        src = parse_source(text)
        if not isinstance(src, str):
            return src
        node = _camera_device(src) if sys.platform.startswith("linux") else None
        if node is not None:
            return node  # /dev/videoN: camera N, as _pending_key knows it
        if re.match(r"[A-Za-z][A-Za-z0-9+.-]*://", src):
            # the page opens no address typed in it (the server would connect wherever it was
            # told): said as "no such file: rtsp://...", which told nothing of what to do
            raise ValueError(
                f"{mask_url_secrets(src)}: a stream's URL is given to gui --left/--right at "
                "start-up, not typed here (the page opens cameras, and files in the --data folders)"
            )
        # Files only from the allowed folders; an image-sequence pattern by its folder.
        p = Path(src)
        if "%" in p.name:
            return str(self.folders.resolve(p.parent) / p.name)
        return str(self.folders.resolve(src))

    # ------------------------------------------------------------------------- controllers

    def _on_ready(self, **_: Any) -> None:
        self._lock = asyncio.Lock()
        source = self.source
        if source is not None:
            # the first pair read as a Capture's, in a thread (:meth:`_capture`): read here, in
            # the page's handler, a camera that hung froze the page up to --read-timeout
            what = self._source_what(source)
            self._begin_read(source, what)
            self._spawn(self._capture(source, what, bool(self.state.average), self._shows))
            return
        try:
            self._load_scene(self.demo_scene)
            self._show_demo_in_list()
        except (ValueError, OSError, RuntimeError) as exc:
            self._fail(exc)
            return
        self._spawn(self.recompute())

    def _on_method(self, **_: Any) -> None:
        if self._settings_back:  # put back after a failure: the page shows their result
            return
        if self.pair is not None:
            self._spawn(self.recompute())
        elif self._lock is not None:  # the page is up: a click, not the start-up state
            self._fail(ValueError(NO_PAIR))

    def _on_scene(self, scene: str = "", **_: Any) -> None:
        if not scene or scene == self._scene:  # cleared, or put back after a failure
            return
        try:
            self._load_scene(scene)
        except (ValueError, OSError, RuntimeError) as exc:
            self._fail(exc, outlasts=True)
            # the list shows the scene on show again, so that choosing the failed one retries
            # (trame reports only a changed value)
            self.state.scene = self._scene or None
            return
        self._scene = scene
        self._choice += 1  # an open still under way must not replace this scene
        self._done()  # an earlier failure stayed on the page while the scene computed
        self._spawn(self.recompute())

    def capture(self) -> None:
        """Read a new pair from the open source (cameras, an image folder) and recompute.

        The read runs in a thread of its own (:meth:`_capture`), the page saying "reading ..."
        meanwhile: run in the handler, a wedged camera froze the page up to ``read_timeout``.
        A second Capture while one reads is refused, said on the page.

        A scene or files chosen after the source opened are on show: the first Capture says
        so (it went back to the source without a word, the scene list emptied); another,
        with no choice since, goes back to the source.
        """
        source = self.source
        try:
            first = self._first_read
            if first is not None and first[0] == self._choice:
                # the chosen source's first pair comes: not the source it replaces
                raise OSError(
                    f"still reading {first[1]} (its first pair has not come): wait for it"
                )
            if source is None:
                raise OSError("no camera open: give --left/--right or open cameras below")
            what = self._source_what(source)
            if self._other_on_show and self._capture_back != self._choice:
                self._capture_back = self._choice
                shown = self.state.source_label
                shown = "the loaded files are" if shown == "files" else f"{shown} is"
                back = (
                    "go on with its next pair"
                    if isinstance(source, FolderPairs)
                    else "read a pair from them"
                )
                raise ValueError(
                    f"{shown} on show, not {what}: a scene or files cannot be captured; "
                    f"Capture again to {back}"
                )
            if any(r is source for r in self._reading):
                replug = "" if isinstance(source, FolderPairs) else ", or unplug and replug it"
                raise OSError(
                    f"still reading {what} (an earlier Capture has not returned): wait for "
                    f"it{replug}"
                )
        except (ValueError, OSError, RuntimeError) as exc:
            self._fail(exc, outlasts=True)
            return
        average = bool(self.state.average)
        self._begin_read(source, what)
        self._spawn(self._capture(source, what, average, self._shows))

    async def _capture(self, source: StereoSource, what: str, average: bool, shows: int) -> None:
        """Read ``source`` (:meth:`_read_in_thread`) and show its pair, or say why not; a pair
        (or an error) that comes after another was put on show (``_shows``: a scene, files,
        other cameras) is dropped: that one stays on show. An Open clicked meanwhile that
        fails drops nothing (the pair was lost without a word)."""
        try:
            got = await self._read_in_thread(source, average)
        except Exception as exc:  # any read error is said on the page (cv2.error too)
            if shows != self._shows or source is not self.source:
                return
            if not isinstance(exc, (ValueError, OSError, RuntimeError)):
                log.exception("gui: reading %s failed", what)
            self._fail(exc, outlasts=True)
            return
        if shows != self._shows or source is not self.source:
            return
        try:
            with self.state:
                self._use_pair(got)
                if self.state.captures == 0:  # the start-up cameras' first pair
                    self._say_source_notes(source)
                self.state.captures += 1
        except (ValueError, OSError, RuntimeError) as exc:
            self._fail(exc, outlasts=True)
            return
        self._spawn(self.recompute())

    def _source_what(self, source: StereoSource) -> str:
        """``source`` as the page's "reading ..." names it: ``camera 0 and camera 1``, the
        files' names, ``folder data/seq``, or the start-up source's label (a bag)."""
        if isinstance(source, FolderPairs):
            return f"folder {source.name}"
        if self._source_label:
            return self._source_label
        typed: list[int | str] = []
        for name in self._source_names:
            try:
                typed.append(parse_source(name))
            except ValueError:
                typed.append(str(name))
        return " and ".join(dict.fromkeys(_source_name(t) for t in typed))

    def _in_use_unchanged(self) -> str:
        """What a failed Open or Play leaves in use, as the page says it, named as its
        "reading ..." names it (:meth:`_source_what`): ``the cameras in use, camera 0 and
        camera 1, are unchanged``, ``the folder data/seq in use is unchanged``, or (video
        files, a bag) ``the source in use, l.avi and r.avi, is unchanged`` ("the cameras" was
        said of a folder's pairs too; the cameras and files were not named).
        A camera typed by its device node (``/dev/video0``, a ``/dev/v4l/by-id`` link) is a
        camera, as the capture code knows it: it was said to be "the source"."""
        source = self.source
        if isinstance(source, FolderPairs):
            return f"the folder {source.name} in use is unchanged"
        named = self._source_what(source) if source is not None else ""
        named = f", {named}," if named else ""  # a source given no name: none said
        if self._source_label is None:
            try:
                if all(_camera_device(parse_source(n)) for n in self._source_names):
                    return f"the cameras in use{named} are unchanged"
            except ValueError:  # a name no camera has: not said to be cameras
                pass
        return f"the source in use{named} is unchanged"

    def _fail_open(self, exc: BaseException, outlasts: bool = True) -> None:
        """Say an Open that failed (refused, given up, or the open raised): with the source
        still in use named (:meth:`_in_use_unchanged`), as a failed first read says it. An
        open that raised said only its error ("cannot open camera 5 (left)"): nothing told
        that the cameras on show kept running."""
        if isinstance(exc, BUG_ERRORS):  # before its words are wrapped into an OSError
            exc = _as_said(exc, "opening")
        if self.source is not None:
            exc = OSError(f"{first_line(exc)} ({self._in_use_unchanged()})")
        self._fail(exc, outlasts=outlasts)

    def _begin_read(self, source: StereoSource, what: str) -> None:
        """A read of ``source`` is under way from now (before its task runs: a click that
        comes meanwhile sees it); the page says so."""
        said = f"reading {what}..."
        self._reading.append(source)
        self._under_way.append((source, said))
        with self.state:
            self.state.error = ""
            self.state.status = said

    def _end_under_way(self, token: object) -> None:
        """The open or read of ``token`` (:attr:`_under_way`) has returned: a status saying it
        goes (its caller says more after this, but one dropped for a newer choice says
        nothing: "reading ..." stayed on for good over the scene computed meanwhile)."""
        said = [u[1] for u in self._under_way if u[0] is token]
        self._under_way = [u for u in self._under_way if u[0] is not token]
        if said and self._computing:
            # its step now, not on its next one: a read that failed on the last step left
            # "census; reading camera 0..." said until the computation's end
            with self.state:
                self.state.status = self._status_with_reads(self._step)
        elif said and self.state.status in said:
            with self.state:
                self.state.status = self._status_with_reads(None) or (
                    "ready" if self.view is not None else ""
                )

    def _status_with_reads(self, text: str | None) -> str:
        """The status ``text`` followed by the newest open or read under way's "opening ..." or
        "reading ..." ("census; reading camera 0..."), that alone for None, "" with neither:
        a computation's end and progress said "ready" or their step while a Capture read."""
        said = self._under_way[-1][1] if self._under_way else None
        if said is None or text is None:
            return said or text or ""
        return f"{text}; {said}"

    async def _read_in_thread(self, source: StereoSource, average: bool) -> _Frames:
        """:func:`_read_pair` of ``source`` in a daemon thread, waited for here (the page's loop
        stays free). The read is bounded inside the source (``read_timeout``).

        The thread touches only ``source``; its outcome comes back through the loop
        (``call_soon_threadsafe``), as the Open's does. ``source`` must be registered by
        :meth:`_begin_read`; it is no longer read once this returns or raises. A source
        replaced meanwhile (:meth:`_close_source`) is closed when its read returns.
        """
        loop = asyncio.get_running_loop()
        done: asyncio.Future[_Frames] = loop.create_future()

        def settle(got: _Frames | None, exc: BaseException | None) -> None:
            # on the page's loop
            self._reading = [r for r in self._reading if r is not source]
            self._end_under_way(source)
            if any(c is source for c in self._close_after_read):
                self._close_after_read = [c for c in self._close_after_read if c is not source]
                source.close()
            if done.done():  # the waiting task was cancelled (the server stops)
                return
            if exc is not None:
                done.set_exception(exc)
            else:
                done.set_result(got)  # type: ignore[arg-type]

        def run() -> None:
            got: _Frames | None = None
            error: BaseException | None = None
            try:
                got = _read_pair(source, average)
            except BaseException as exc:  # said on the page by the caller
                error = _for_the_loop(exc, "read")
            try:
                loop.call_soon_threadsafe(settle, got, error)
            except RuntimeError:  # the page's loop is closed (the server stopped)
                pass

        try:
            threading.Thread(target=run, name="stereovision-gui-read", daemon=True).start()
        except BaseException:  # no thread: nothing reads the source
            self._reading = [r for r in self._reading if r is not source]
            self._end_under_way(source)
            raise
        return await done

    def _close_source(self, source: StereoSource) -> None:
        """Close ``source`` now, or when the read under way in it returns."""
        if any(r is source for r in self._reading):
            self._close_after_read.append(source)
        else:
            source.close()

    def open_cameras(self) -> None:
        """Open the camera sources typed on the page (device index or allowed file).

        The sources are checked here; the open runs in a thread of its own (:meth:`_open`),
        the page saying "opening ..." meanwhile: run in the handler, a wedged camera froze the
        page for the whole ``read_timeout``. A source whose earlier open has not returned yet
        (given up or not) is refused, said on the page: each retry on a wedged device left one
        more thread blocked in it.

        The new cameras replace the open ones only once they gave a pair: sources that open
        but cannot be paired (frames of two sizes) leave the open cameras in use, and say so.
        """
        try:
            left = self._camera_source(self.state.cam_left)
            right = self._camera_source(self.state.cam_right)
            device = _camera_device(left)
            if device is not None and device == _camera_device(right):
                # refused as gui --left/--right are: the second open failed with a hint about
                # another program using the camera
                raise ValueError(
                    f"the left and right fields are both camera {device}: give the rig's two "
                    "cameras"
                )
            fourcc = None if self.state.fourcc == FOURCCS[0] else self.state.fourcc
            pending = [s for s in (left, right) if _pending_key(s) in self._opening]
            if pending:
                raise OSError(
                    f"{_source_name(pending[0])} is still opening (an earlier Open has not "
                    "returned): wait for it, or unplug and replug the camera"
                )
        except (ValueError, OSError, RuntimeError) as exc:
            self._fail_open(exc)
            return
        names = (str(self.state.cam_left), str(self.state.cam_right))
        self._choice += 1
        self._opening.update((_pending_key(left), _pending_key(right)))
        what = " and ".join(dict.fromkeys(_source_name(s) for s in (left, right)))
        with self.state:
            self.state.error = ""
            self.state.status = f"opening {what}..."
        self._spawn(self._open(left, right, fourcc, names, what, self._choice))

    async def _open(
        self,
        left: int | str,
        right: int | str,
        fourcc: str | None,
        names: tuple[str, str],
        what: str,
        choice: int,
    ) -> None:
        """Open ``left`` and ``right`` in a daemon thread, wait for it up to ``read_timeout``
        s, then read their first pair in another (:meth:`_read_in_thread`, the page saying
        "reading ..."), then use it (:meth:`_switch_source`) or say why not.

        A given-up open goes on in its thread: its sources stay in ``_opening`` (refused by
        :meth:`open_cameras`) until it returns; the cameras it opened late are closed then.
        Cameras that opened stay in ``_opening`` until their first read returns.
        ``choice`` is the page's source choice this Open made (``_choice``): cameras that come
        after a newer choice are closed, and its error is not said over that choice's page.
        """
        loop = asyncio.get_running_loop()
        opened: asyncio.Future[StereoSource] = loop.create_future()
        keys = (_pending_key(left), _pending_key(right))
        # said until the open returns or is given up (registered here, not by the click: a
        # task closed unrun would leave it said for good)
        token = object()
        self._under_way.append((token, f"opening {what}..."))

        def settle(source: StereoSource | None, exc: BaseException | None) -> None:
            # on the page's loop: the sources may be opened again from now, unless they
            # opened (then once their first pair is read, below)
            if opened.done():  # given up: nobody takes these cameras
                self._opening.difference_update(keys)
                if source is not None:
                    source.close()
            elif exc is not None:
                self._opening.difference_update(keys)
                opened.set_exception(exc)
            else:
                opened.set_result(source)  # type: ignore[arg-type]

        def run() -> None:
            source: StereoSource | None = None
            error: BaseException | None = None
            try:
                source = open_stereo_source(
                    left, right, fourcc=fourcc, read_timeout=self.read_timeout, bound_open=False
                )
            except BaseException as exc:  # said on the page, in settle
                error = _for_the_loop(exc, "open")
            try:
                loop.call_soon_threadsafe(settle, source, error)
            except RuntimeError:  # the page's loop is closed (the server stopped)
                if source is not None:
                    source.close()

        try:
            try:
                threading.Thread(target=run, name="stereovision-gui-open", daemon=True).start()
                # reads are bounded inside the source; its open by this wait (it cancels `opened`)
                source = await asyncio.wait_for(opened, self.read_timeout)
            finally:  # before an error is said: the status says no open then
                self._end_under_way(token)
        except asyncio.TimeoutError:
            if choice != self._choice:  # another source was chosen meanwhile: it is on show
                return
            self._fail_open(
                OSError(
                    f"{what} did not open within {self.read_timeout:g} s (the open did not "
                    "return: a wedged camera or driver, or a stalled stream); unplug and replug "
                    "it, or give gui a longer --read-timeout"
                )
            )
            return
        except Exception as exc:  # any open error is said on the page (cv2.error too)
            if not opened.done():  # the thread did not start: nothing will settle the keys
                self._opening.difference_update(keys)
            if choice != self._choice:
                return
            if not isinstance(exc, (ValueError, OSError, RuntimeError)):
                log.exception("gui: opening %s failed", what)
            self._fail_open(exc)
            return
        try:
            if choice != self._choice:  # a newer Open or folder is on show: nobody takes these
                source.close()
                return
            # the first pair read in a thread too: a camera that opens may still not deliver
            self._begin_read(source, what)
            self._first_read = (choice, what)
            await self._first_pair(source, names, what, choice)
        finally:
            self._opening.difference_update(keys)

    async def _first_pair(
        self, source: StereoSource, names: tuple[str, str], what: str, choice: int
    ) -> None:
        """Read the first pair of ``source``, newly opened (cameras, an image folder), in a
        thread (:meth:`_read_in_thread`; registered by :meth:`_begin_read`), then use it
        (:meth:`_switch_source`) or say why not. ``source`` is closed unless used; after a
        newer choice than ``choice`` (``_choice``), nothing is said. The caller set
        ``_first_read`` (a Capture is refused until this returns)."""
        try:
            got = await self._read_in_thread(source, bool(self.state.average))
        except Exception as exc:
            self._end_first_read(choice)
            source.close()
            if choice != self._choice:
                return
            if not isinstance(exc, (ValueError, OSError, RuntimeError)):
                log.exception("gui: reading %s failed", what)
            if isinstance(exc, BUG_ERRORS):  # before its words are wrapped into an OSError
                exc = _as_said(exc, f"reading {what}")
            if self.source is not None:
                exc = OSError(f"{first_line(exc)} ({self._in_use_unchanged()})")
            self._fail(exc, outlasts=True)
            return
        self._end_first_read(choice)
        if choice != self._choice:
            source.close()
            return
        with self.state:
            self._switch_source(source, names, got)

    def _end_first_read(self, choice: int) -> None:
        """The first read of ``choice``'s source returned: Capture is no longer refused for it."""
        if self._first_read is not None and self._first_read[0] == choice:
            self._first_read = None

    def open_pair_folder(self) -> None:
        """Play the pairs of the chosen image folder (as ``batch`` pairs them), one per
        Capture, starting again after the last.

        The first pair is read in a thread (:meth:`_first_pair`), the page saying "reading
        folder ..." meanwhile, as a Capture's: read in the handler, a folder on a stalled
        disk or network share froze the page.
        """
        try:
            folder = self.folders.resolve(self.state.pair_folder or "")
            label = self.folders.label(folder)
            if not folder.is_dir():
                raise NotADirectoryError(f"not a folder: {label}")
            source = FolderPairs(folder, label, keep=self.folders.contains)
        except (ValueError, OSError) as exc:
            self._fail(exc, outlasts=True)
            return
        self._choice += 1  # an open still under way must not replace these pairs
        what = self._source_what(source)
        self._begin_read(source, what)
        self._first_read = (self._choice, what)
        self._spawn(self._first_pair(source, ("", ""), what, self._choice))

    def _switch_source(
        self, source: StereoSource, names: tuple[str, str], got: _Frames | None = None
    ) -> None:
        """Use ``source`` once it gave a pair, ``got`` (None: read here; the page reads it in a
        thread first, :meth:`_first_pair`): else the source in use stays, and says so."""
        before = (self.source, self.homographies, self._source_label, self._source_names)
        self.source = source
        self.homographies = None
        self._source_label = None  # the cameras typed on the page, named by their fields
        self._source_names = names
        try:
            if got is None:
                got = _read_pair(source, bool(self.state.average))
            self._use_pair(got)  # sets the pair only once both frames came and fit together
        except (ValueError, OSError, RuntimeError) as exc:
            source.close()
            self.source, self.homographies, self._source_label, self._source_names = before
            if self.source is not None:
                exc = OSError(f"{first_line(exc)} ({self._in_use_unchanged()})")
            self._fail(exc, outlasts=True)
            return
        self._shows += 1
        self._say_source_notes(source)
        if before[0] is not None:
            self._close_source(before[0])  # a Capture may still be reading it
        self.state.live = True
        self.state.can_average = not isinstance(source, FolderPairs)
        self.state.error = ""
        self.state.captures += 1
        self._spawn(self.recompute())

    def _say_source_notes(self, source: StereoSource) -> None:
        """Say under the pair on show what ``source``'s open warned of (image sequences
        paired in order, not by their numbers: ``notes()`` of the page's sources), as a pair of
        files' warning is: the warning went to the server's log (or the terminal) alone."""
        notes = getattr(source, "notes", None)
        said = notes() if callable(notes) else []
        if said:
            self.state.rows_label = "; ".join(f"warning: {n}" for n in said)

    def load_files(self) -> None:
        """Use the chosen left / right image files (calibration: ``--calib`` if its size fits;
        one that holds no size is sized by the first pair it is used with, and refuses files of
        another size: :meth:`_calib_for`)."""
        from stereovision.io import check_pair_files, read_image

        try:  # an emptied field sends None
            lpath = self.folders.resolve(self.state.left_file or "")
            rpath = self.folders.resolve(self.state.right_file or "")
            # 16-bit files at their 16 bits, as `depth` reads them (imread kept the top 8)
            left, right = read_image(lpath), read_image(rpath)
            labels = (self.folders.label(lpath), self.folders.label(rpath))
            same = check_pair_files(left, right, lpath, rpath, names=labels)
            c, note = self._calib_for(left), ""
        except (ValueError, OSError) as exc:
            # a file named with a newline: "cannot decode .../bad" for bad\n.png
            self._fail(exc, outlasts=True, typed=(self.state.left_file, self.state.right_file))
            return
        self._choice += 1  # an open still under way must not replace these files
        self.pair = self.raw_pair = (left, right)
        self._other_source()
        self.homographies = None
        if c is not None and self._calib_sized_by is None:
            from stereovision.calibration import fit_to_frames

            try:  # another resolution of the same shape is scaled when the view is computed
                fit_to_frames(c, (left.shape[1], left.shape[0]))
            except ValueError as exc:
                c, note = None, f"{exc}: disparity only"
        self.calib = c
        self._no_calib = "the --calib calibration does not fit these images" if note else None
        self.max_disparity = None
        self.state.source_label = "files"
        self._other_on_show = True
        self._shows += 1
        self.state.rows_label = "; ".join(
            n for n in (f"warning: {same}" if same else "", note) if n
        )
        # the files are taken: an earlier failure ("no such file: ...") stayed on the page
        # while they computed, as if this Load had failed
        self._done()
        self._spawn(self.recompute())

    def open_cloud(self) -> None:
        """Show a point-cloud file (PLY / PCD / NPZ) from the allowed folders in the 3-D view."""
        from stereovision.export import load_cloud

        path: Path | None = None
        try:
            path, label = self._cloud_file(self.state.cloud_path or "")
            pts, cols = load_cloud(path)
            cloud, count = shown_cloud(pts, cols)
            del pts, cols  # the drawn subset is a copy: the file's arrays can go
        except (ValueError, OSError) as exc:
            # the file as the page shows paths, not its whole absolute path
            self._fail(exc, path, outlasts=True)
            return
        self._cloud = cloud
        self._cloud_caption = f"{label}: {count}"
        self._show_geometry(cloud, None)
        self._done()
        with self.state:
            self.state.message_3d = self._cloud_message()

    def _cloud_message(self) -> str:
        """The 3-D caption while a point-cloud file is shown (it has no surface to draw)."""
        if self.state.view_mode == "points":
            return self._cloud_caption
        return f"{self._cloud_caption} (a point cloud has no surface: shown as points)"

    def reset_camera(self) -> None:
        """Back to the left camera's pose (all six controls at zero)."""
        with self.state:
            for name in _CONTROL_NAMES:
                self.state[name] = 0.0
        self._apply_camera()

    # ------------------------------------------------------------------------- worker

    async def recompute(self) -> None:
        """Compute the current pair in the worker thread; the newest request wins."""
        if self.pair is None or self._lock is None:
            return
        self._generation += 1
        gen = self._generation
        async with self._lock:
            if gen != self._generation:
                return  # a newer request is queued behind us
            loop = asyncio.get_running_loop()
            # What this computation works on, taken now: a scene chosen while it runs replaces
            # self.pair at once, and this result must not be recorded as that scene's.
            computed = self._inputs()
            left, right = self.pair
            calib = self.calib
            chosen = self.chosen_max_disparity
            d_max = chosen if chosen is not None else self.max_disparity
            gt = None
            if self._scene_gt[0] is self.pair and (calib is None or calib.rectified):
                gt = self._scene_gt[1]
            # the scene's range, not one typed in the field, too wide for its images
            narrow = self._scene_narrow[1] if self._scene_narrow[0] is self.pair else None
            narrow = narrow if chosen is None else None
            if narrow is not None and left.shape[1] >= 2:
                narrow += ", or " + ADVICE["range"]["page"].format(n=left.shape[1])
            method = self.state.method
            res = self.state.resolution
            width = None if res == "full" else int(res)
            fresh = self._shown is None or self._shown["pair"] is not self.pair
            with self.state:
                st = self.state
                st.busy = True
                st.progress = 1
                self._step = f"computing ({method})"
                st.status = self._status_with_reads(self._step)
                st.max_disp_hint = max_disparity_hint(self.max_disparity, left.shape[1], width)
                if fresh:  # another pair: its images now, no result of the previous pair
                    if self._page_before is None:
                        self._page_before = {k: st[k] for k in _RESULT_KEYS}
                    st.img_left, st.img_right = _data_url(left), _data_url(right)
                    st.wide_pair = left.shape[1] > WIDE_ASPECT * left.shape[0]
                    st.img_disparity = st.img_depth = st.img_matches = st.img_floor = ""
                    st.floor_label = st.stats = ""
                    st.depth_caption = DEPTH_CAPTION
                    st.disparity_caption = DISPARITY_CAPTION
                    if self._cloud is not None:
                        # a point-cloud file is on show until the new pair's result: its
                        # caption stays (it was said to be "the previous one", or nothing)
                        st.message_3d = self._cloud_message()
                    else:
                        st.message_3d = PENDING_3D if self.view is not None else ""

            def progress(pct: int, text: str) -> None:
                loop.call_soon_threadsafe(self._set_progress, pct, text)

            def work() -> ViewData:
                try:
                    return compute_view(
                        left,
                        right,
                        calib,
                        method,
                        width=width,
                        max_disparity=d_max,
                        progress=progress,
                        gt=gt,
                    )
                except ValueError as exc:
                    # the scene's own range (evaluation.md's 16 px on a pair 8 px wide) was named
                    # as one given: "disparity range 16 is not smaller than the image width 8"
                    if narrow is None or d_max is None:
                        raise
                    from stereovision.depth import _range_too_wide

                    if str(exc) != str(_range_too_wide(d_max, left.shape[1])):
                        raise
                    raise ValueError(narrow) from None
                finally:
                    # A click is no frame loop: hand the extension's kept buffers and the C
                    # heap's free pages back (a 3600 x 3000 pair left the server at 11 GB).
                    release_memory()

            self._computing = True
            try:
                view = await loop.run_in_executor(self._executor, work)
            except Exception as exc:
                # MemoryError: the census map's check refused a pair too large for this machine;
                # cv2.error: an OpenCV reference method on a pair it cannot take.
                exc = _as_said(exc, f"computing {method}")
                self._computing = False
                if gen != self._generation:
                    return  # superseded: the newer request computes (and reports) its own pair
                self._failed_meanwhile = None  # the computation's error replaces it
                self._fail(exc)
                self._max_disp_back()
                page, self._page_before = self._page_before, None
                if page is not None:
                    with self.state:
                        for name, value in page.items():
                            self.state[name] = value
                        if self.view is not None:  # in the unit on show now
                            self.state.depth_caption, self.state.stats = self.view.texts(self._unit)
                            if self.state.floor_label and self.view.floor is not None:
                                self.state.floor_label = floor_text(self.view.floor, self._unit)
                        if self._cloud is not None:
                            # a file opened while the pair computed is still on show: the
                            # previous pair's caption was put back over it
                            self.state.message_3d = self._cloud_message()
                shown = self._shown
                if shown is not None and shown["pair"] is not self.pair:
                    for name, value in shown.items():
                        if name not in ("source_label", "rows_label"):
                            setattr(self, name, value)
                    with self.state:
                        self.state.source_label = shown["source_label"]
                        # the failed pair's line (its files' warning) went with it
                        self.state.rows_label = shown["rows_label"]
                        # the failed choice can be made again
                        self.state.scene = self._scene or None
                        self.state.error += " (the page still shows the previous pair)"
                elif self._shown_settings not in (None, (method, res)):
                    # the same pair with another method / resolution failed: the toggles go
                    # back to what the page shows (they named the failed one above its result)
                    self._settings_back = True
                    try:
                        with self.state:
                            self.state.method, self.state.resolution = self._shown_settings
                            m, r = self._shown_settings
                            self.state.error += f" (the page still shows {m} at {r} resolution)"
                    finally:
                        self._settings_back = False
                return
            finally:
                self._computing = False
            if gen != self._generation:
                # Superseded while it ran (another scene, files, method): showing it now would
                # put the previous pair's disparity under the new pair's name; the newer
                # request, queued behind this one, shows its own.
                return
            self._shown = computed
            self._shown_settings = (method, res)
            if view.result.depth is None and computed["_no_calib"] is not None:
                view.message_3d = f"No calibration: {computed['_no_calib']} (disparity only)."
            self._publish(view)

    def _inputs(self) -> dict[str, Any]:
        """The pair a computation works on, with what the page says of it (kept as
        ``_shown`` once its result is on the page)."""
        return {
            "pair": self.pair,
            "raw_pair": self.raw_pair,
            "calib": self.calib,
            "_no_calib": self._no_calib,
            "max_disparity": self.max_disparity,
            "homographies": self.homographies,
            "source_label": self.state.source_label,
            "rows_label": self.state.rows_label,
            "_scene": self._scene,
            # its GT with it: a scene that failed to compute left its own, and the pair put
            # back lost its statistics' GT figures (bad-2.0, precision@1) from then on
            "_scene_gt": self._scene_gt,
            "_scene_narrow": self._scene_narrow,
            # put back with the pair: a Capture says so over a scene or files, not over cameras
            "_other_on_show": self._other_on_show,
        }

    def check_rows_clicked(self) -> None:
        """The page's "Check rows" button."""
        self._spawn(self.check_rows())

    async def check_rows(self) -> None:
        """Check that the current pair's features lie on common rows (with its calibration)."""
        if self.pair is None:
            self._fail(ValueError(NO_PAIR))
            return
        from stereovision.calibration import fit_to_frames
        from stereovision.rectification_check import check_rectification

        pair = self.pair
        left, right = pair
        calib = self.calib

        def run() -> str:
            if calib is None:
                return check_rectification(left, right).summary()
            fitted, _ = fit_to_frames(calib, (left.shape[1], left.shape[0]))
            return check_rectification(left, right, fitted).summary()

        try:
            text = await asyncio.get_running_loop().run_in_executor(self._executor, run)
        except Exception as exc:
            exc = _as_said(exc, "checking the rows")
            if self.pair is pair:  # else another pair came meanwhile: not its failure
                self._fail(exc)
            return
        if self.pair is not pair:
            return  # another pair came meanwhile: this verdict is not of the pair on show
        self._done()
        text = nowrap_units(text)
        if self._shown is not None and self._shown["pair"] is pair:
            self._shown["rows_label"] = text  # what a failed next pair puts back
        with self.state:
            self.state.rows_label = text

    def rectify_clicked(self) -> None:
        """The page's "Rectify" button."""
        self._spawn(self.rectify_from_features())

    async def rectify_from_features(self) -> None:
        """Rectify the pair on show from its own features (no calibration: disparity only);
        the cameras' next pairs go through the same homographies."""
        if self.pair is None:
            self._fail(ValueError(NO_PAIR))
            return
        if self.calib is not None:
            from stereovision.calibration import fit_to_frames

            left = self.pair[0]
            said = "this pair has a calibration: it is rectified with it"
            try:
                fit_to_frames(self.calib, (left.shape[1], left.shape[0]))
            except ValueError as exc:
                # cameras in a mode --calib fits not (another aspect ratio): it was said to
                # rectify the pair, which no computation could use
                said = (
                    f"the calibration does not fit this pair ({exc}): Rectify finds no "
                    "homographies for a pair with one"
                )
                if self.calib is self.source_calib:
                    said += " (start the page without --calib to rectify from features)"
            with self.state:
                self.state.rows_label = said
            return
        from stereovision.rectification_check import already_rectified
        from stereovision.uncalibrated import rectify_uncalibrated

        # the pair pressed on: a pair chosen while this runs wins (the homographies of this one
        # were put on it, under its name)
        pressed = self.pair
        left, right = pressed
        before = self.homographies
        if before is not None and self.raw_pair is not None:
            # pressed again: estimate again from the raw pair, not from the rectified one (its
            # homographies would not fit the cameras' next frames)
            left, right = self.raw_pair

        def run() -> Any:
            # as `rectify` without --calib: a pair whose rows already agree is used as given
            # (homographies fitted to those rows only resampled it, and changed its size)
            given = already_rectified(left, right)
            return given if given is not None else rectify_uncalibrated(left, right)

        try:
            rect = await asyncio.get_running_loop().run_in_executor(self._executor, run)
        except Exception as exc:
            exc = _as_said(exc, "rectifying from features")
            if self.pair is pressed:
                self._fail(exc)
            return
        if self.pair is not pressed:
            return
        self.state.source_label = self.state.source_label.replace(" (rectified from features)", "")
        if not hasattr(rect, "rectify"):  # the rows check: already rectified
            self.homographies = None
            self.raw_pair = (left, right)
            with self.state:
                self.state.rows_label = f"already rectified ({rect.rows_agree()}): used as given"
            if before is not None:  # the pair on show was warped: the one as it comes now
                self.pair = (left, right)
                self.max_disparity = None
                await self.recompute()
            else:
                self._done()
            return
        self.homographies = rect
        self.raw_pair = (left, right)
        self.pair = rect.rectify(left, right)
        self.max_disparity = rect.max_disparity
        with self.state:
            self.state.rows_label = nowrap_units(rect.describe())
            self.state.source_label += " (rectified from features)"
        await self.recompute()

    def apply_max_disparity(self, focused: bool = False, text: str | None = None) -> None:
        """The max-disparity field, on Enter or when it loses focus: checked (a bad value is
        said on the page, the result on show stays), then the pair computed with it.

        Parameters
        ----------
        focused : bool
            The field's focus after the event (True: it was entered, nothing to apply yet).
        text : str, optional
            The field's text as the page has it (its state may not have reached the server
            before the key did); default: the state's.
        """
        if focused is True:
            return
        if text is not None:
            self.state.max_disp = text
        try:
            width = self.pair[0].shape[1] if self.pair is not None else math.inf
            chosen = parse_max_disparity(self.state.max_disp, int(min(width, 2**31)))
        except ValueError as exc:
            # kept past a computation under way: its end cleared the refusal, the field still
            # holding the value refused ("500" on a 450 px pair) over a result of the old range
            self._fail(exc, outlasts=True)
            self._max_disp_refused = self.state.error
            return
        if chosen == self.chosen_max_disparity:
            # the range in use typed again after a refused value: nothing to compute, but the
            # refusal ("got 'abc'") stayed on the page, and "error" in the toolbar, under a
            # field that now holds a good value (another error on the page stays)
            if self._max_disp_refused and self.state.error == self._max_disp_refused:
                self._done()
            self._max_disp_refused = None
            return
        self._max_disp_refused = None
        self.chosen_max_disparity = chosen
        self._done()
        if self.pair is not None:
            self._spawn(self.recompute())

    def _max_disp_back(self) -> None:
        """The max-disparity field back to the range in use (empty: automatic) once its
        refusal has left the page: a computation's end cleared "max disparity 300 px is not
        smaller than the pair's width 160 px" while the field kept 300 over a new pair computed
        at its automatic range. A refusal still on the page (said during the computation) keeps
        its value, as a refused Load keeps the names typed."""
        if self._max_disp_refused is None or self.state.error == self._max_disp_refused:
            return
        chosen = self.chosen_max_disparity
        self.state.max_disp = "" if chosen is None else str(chosen)
        self._max_disp_refused = None

    def _view_on_show(self, label: str, pending: str) -> ViewData | None:
        """The pair on show for a button that works on its results (Find floor, Save), or
        None, said: no pair (an error), or a new pair still computing (``pending`` in the
        state's ``label``: ``self.view`` is the previous pair's)."""
        view = self.view
        if view is None:
            self._fail(ValueError(NO_PAIR))
            return None
        if self._page_before is not None:
            with self.state:
                setattr(self.state, label, pending)
            return None
        return view

    def find_floor_clicked(self) -> None:
        """The page's "Find floor" button."""
        self._spawn(self.find_floor())

    async def find_floor(self) -> None:
        """Fit the floor of the depth map on show: the camera's height, pitch and roll, and a
        picture with the floor in green and what stands :data:`OBSTACLE_HEIGHTS` on it in red
        (the height in the page's unit)."""
        view = self._view_on_show("floor_label", PENDING_FLOOR)
        if view is None:
            return
        res = view.result
        if res.depth is None or getattr(res, "calibration", None) is None:
            why = (self._shown or {}).get("_no_calib") or "--calib"
            with self.state:
                self.state.floor_label = f"finding the floor needs a calibration ({why})"
            return

        def run() -> tuple[Any, str, str]:
            # why none comes from the same fit: floor_text(None, ..., res) would run it again
            return _floor_view(res)

        try:
            plane, url, why = await asyncio.get_running_loop().run_in_executor(self._executor, run)
        except Exception as exc:
            exc = _as_said(exc, "finding the floor")
            if self.view is view and self._page_before is None:
                self._fail(exc)
            return
        if self.view is not view or self._page_before is not None:
            # another pair came while the floor was fitted: this floor is not the one of the
            # pair on the page (its images show while it computes)
            return
        self._done()
        view.floor = plane
        with self.state:
            self.state.floor_label = why if plane is None else floor_text(plane, self._unit, res)
            self.state.img_floor = url

    def save_clicked(self, folder: str | None = None) -> None:
        """The page's "Save" button.

        Parameters
        ----------
        folder : str, optional
            The folder field's text as the page has it: a folder typed just before the click
            may not have reached the server's state yet (the Save went to the folder offered).
        """
        if folder is not None:
            self.state.save_dir = folder
        self._spawn(self.save())

    async def save(self) -> None:
        """Write the pair on show as ``stereovision depth -o`` does (its writers and file names:
        disparity PNG and PFM, depth PNGs and .npy, cloud.ply, ``overview.png``, its depth
        bar in the page's unit and its title naming the pair as the page does, and
        ``render.png``, the 3-D view as the page shows it: from the pose the sliders set, or
        from its camera as the mouse left it, said in the Save's line: :meth:`_render_for_save`)
        into the page's save folder.

        A render that fails (or a pair with no 3-D point to render) is said in the Save's line
        on the page, after the files written: the others are written all the same.

        A Save is all or nothing (:func:`save_all_or_nothing`): its files are written into a
        staging folder and moved into place once all of them are; a writer that fails (disk
        full, no permission) leaves the folder as it was (or absent), and the Save's line names
        the file that failed.

        The folder as offered (or an empty field) is a new one each time: the first of
        ``saved``, ``saved-2``, ``saved-3``, ... that does not exist or is empty, so several
        pairs can be saved one after the other; the page says which (and why it skipped one
        that cannot be listed or written: :meth:`_next_save_folder`). When that folder cannot
        be made or written (a read-only data set as ``--data``), the Save goes to the next new
        ``~/stereovision-saved`` (``-2``, ...), its line saying where and why. A folder the user
        typed that already holds one of those files is refused, naming them: nothing the user
        wrote is replaced (``depth`` replaces its own earlier outputs, the GUI cannot ask); one
        that cannot be written is refused, naming it (no other folder is written instead).
        """
        from stereovision.cli import DEPTH_OUTPUTS, CliError, write_depth_outputs, write_overview
        from stereovision.io import check_output_folder
        from stereovision.render import write_render

        view = self._view_on_show("save_label", PENDING_SAVE)
        if view is None:
            return
        result = view.result
        names = SAVED_FILES + (SAVED_DEPTH_FILES if result.depth is not None else ())
        names = tuple(sorted(names, key=DEPTH_OUTPUTS.index))  # in the order depth writes them
        shown = self._shown["source_label"] if self._shown else self.state.source_label
        title, unit = overview_name(shown), self._unit
        typed = str(self.state.save_dir or "").strip()
        skipped: list[str] = []
        unusable: list[str] = []  # saved-N folders that cannot be listed or written
        folder: Path | None = None
        elsewhere = ""  # why a Save as offered went to the home folder
        try:
            if self._save_roots and typed in ("", self._offered_save_dir):
                folder, why = self._offered_save_folder(skipped, unusable)
                if why:  # a read-only --data folder: the home folder's, said in the Save's line
                    elsewhere = f"{display_path(folder)} cannot be written: {why}"
                    folder = self._fallback_save_folder(folder, why)
            else:
                folder = self._typed_save_folder(typed)
            label = self.folders.label(folder) if not elsewhere else display_path(folder)
            if folder in self._saving_into:  # its files are not there yet: not "taken" below
                raise FileExistsError(
                    f"save: {label} is being written by the previous Save; nothing was "
                    "overwritten: choose another folder"
                )
            taken = [n for n in names if os.path.lexists(folder / n)]
            if taken:
                raise FileExistsError(
                    f"save: {label} already holds {', '.join(taken)}; nothing was overwritten: "
                    "choose another folder"
                )
            check_output_folder(folder, "save folder")
        except (ValueError, OSError) as exc:
            self._fail(exc, folder, outlasts=True)
            return

        # The 3-D view rendered here, in the thread that renders the page's view (VTK's
        # windows are not to be used from two threads); a failure is said after the files.
        image, no_render, mouse_camera = None, "", None
        if result.depth is not None:
            try:
                mouse_camera = self._mouse_view_of_pair()
                image = self._render_for_save(view, mouse_camera)
            except (ValueError, RuntimeError, MemoryError) as exc:
                no_render = f"render.png not written: {first_line(exc)}"

        def write(into: Path) -> None:
            write_depth_outputs(result, into)
            write_overview(result, into, title, unit)
            if image is not None:
                write_render(image, into)

        target = folder
        self._saving_into.add(target)
        try:
            order = [n for n in SAVE_WRITE_ORDER if n in names]
            if image is None:  # no render to write
                order = [n for n in order if n != "render.png"]
            written = await asyncio.get_running_loop().run_in_executor(
                self._executor, self._write_save, write, target, order
            )
        except SaveFailed as exc:
            msg = short_paths(f"save: {exc}; nothing was saved in {label}", target)
            self._fail(ValueError(msg), outlasts=True)
            with self.state:
                self.state.save_label = msg
            return
        except Exception as exc:
            said = exc if isinstance(exc, CliError) else _as_said(exc, "saving")
            self._fail(said, target, outlasts=True)
            return
        finally:
            self._saving_into.discard(target)
        self._done()
        h, w = result.disparity.shape
        if result.depth is None:
            without = " (no calibration: disparity only; no depth, cloud.ply or render.png)"
        else:
            without = f" ({no_render})" if no_render else ""
            if mouse_camera is not None and not no_render:
                without += f" ({MOUSE_RENDER})"
        if elsewhere:
            without += f" ({elsewhere})"
        if skipped:
            links = ", ".join(skipped)
            without += f" ({links}: a symbolic link, not a folder of --data: left alone)"
        if unusable:
            without += f" ({'; '.join(unusable)}: left alone)"
        with self.state:
            self.state.save_label = f"saved {w}×{h} to {label}: {', '.join(written)}{without}"
            # the lists offer what was just written: its cloud.ply to Show in the 3-D view
            self._refresh_file_lists()

    def _write_save(
        self, write: Callable[[Path], None], folder: Path, files: Sequence[str]
    ) -> dict[str, Path]:
        """:func:`save_all_or_nothing` in the worker thread, unless the server has stopped
        (:meth:`stop_work` waits for one under way: its files all in place, or none).

        Raises
        ------
        SaveFailed
            The server stopped before the Save began (nothing written).
        """
        with self._save_lock:
            if self._stopped:
                raise SaveFailed("the server is stopping: nothing was written")
            return save_all_or_nothing(write, folder, files)

    def detach(self) -> None:
        """Take this app's hooks off its server, which trame keeps one per process
        (``get_server("stereovision-gui")``): a program's second ``gui.main`` ran this app's
        ready hook again (the demo scene matched into the page the new app shows; with
        cameras, a read of the closed ones) and its handlers heard the new page's changes."""
        self.ctrl.on_server_ready.discard(self._on_ready)
        # trame has no call that removes a change handler: they are kept in this dict
        callbacks = getattr(self.state, "_change_callbacks", None) or {}
        for handlers in callbacks.values():
            handlers[:] = [h for h in handlers if getattr(h[0], "__self__", None) is not self]

    def stop_work(self) -> None:
        """The server has stopped: the computations and checks queued are dropped, and the one
        running is left to the process's end (``gui.main`` ends the process past it,
        :func:`stereovision.cli.end_past_native_threads`); a Save under way is waited for, so
        that its folder is whole (or as it was), and one not begun is not begun.

        After Ctrl+C during a computation the server waited for it to finish before the
        process ended: 135 s of a 3600 x 3000 pair, its "Ctrl+C to stop" seemingly ignored.
        """
        self._executor.shutdown(wait=False, cancel_futures=True)
        with self._save_lock:
            self._stopped = True

    def _render_for_save(self, view: ViewData, camera: Any = None) -> npt.NDArray[np.uint8]:
        """``render.png`` of the pair on show: its 3-D view (the surface, or points in the
        points mode or for a sparse method) from the pose the sliders set, or from ``camera``
        (the view's camera as the mouse left it, :meth:`_mouse_camera`), through the pair's
        intrinsics at most :data:`~stereovision.render.RENDER_MAX_SIDE` pixels wide or high.

        It rendered the sliders' pose after the view was dragged with the mouse (the sliders
        did not follow the mouse then): not the view the page showed.

        Parameters
        ----------
        view : ViewData
            The pair on show.
        camera : stereovision.render.CameraState, optional
            The view to render instead of the sliders' pose.

        Returns
        -------
        ndarray, uint8 (H, W, 3)
            RGB, as :func:`~stereovision.render.render_view` renders it.

        Raises
        ------
        ValueError
            No 3-D point to render, or a slider's value that is not a number.
        RuntimeError
            The offscreen render failed.
        """
        from stereovision.render import RENDER_MAX_SIDE, render_view

        res, intr = view.result, view.intrinsics
        if view.mesh is None or intr is None or len(res.points) == 0:
            raise ValueError("no 3-D point to render")
        geometry = view.mesh
        if view.matches is None and self.state.view_mode == "points":
            geometry = shown_cloud(res.points, res.colors)[0]
        scale = min(1.0, RENDER_MAX_SIDE / max(intr.width, intr.height))
        if camera is not None:
            return render_view(geometry, intrinsics=intr.scaled(scale), camera=camera)
        return render_view(geometry, self._controls(), intrinsics=intr.scaled(scale))

    def _next_save_folder(
        self,
        skipped: list[str] | None = None,
        home: Path | None = None,
        unusable: list[str] | None = None,
    ) -> Path:
        """The first of ``saved``, ``saved-2``, ``saved-3``, ... in the first ``--data``
        folder that does not exist or is an empty folder a file can be made in, and no Save is
        writing into; with ``home``, the first such of ``stereovision-saved``,
        ``stereovision-saved-2``, ... in it.

        A name that is a symbolic link is skipped (its name appended to ``skipped``): it may
        lead outside ``--data`` (the Save was refused as "outside the --data folders", naming
        a folder the user never typed) or into a folder the user made for something else.
        A folder that cannot be listed or written in is skipped as a full one is (why, with
        its name, appended to ``unusable``): one that could not be listed failed every Save
        as offered with the system's bare "[Errno 13] Permission denied: '.../saved'", and
        an empty one that could not be written sent the Saves home, said as "the --data
        folder cannot be written" of a folder that could.
        """
        from stereovision.io import cannot_write_in

        base = SAVE_FOLDER if home is None else FALLBACK_SAVE_FOLDER
        for n in itertools.count(1):
            name = base if n == 1 else f"{base}-{n}"
            if os.path.islink((self._save_roots[0] if home is None else home) / name):
                if skipped is not None:
                    skipped.append(name)
                continue
            if home is None:
                folder = self.folders.resolve_output(name, self._save_roots)
            else:
                folder = (home / name).resolve()
            if folder in self._saving_into:
                continue
            if not os.path.lexists(folder):
                return folder
            if not folder.is_dir():  # a file named so
                continue
            try:
                if any(folder.iterdir()):  # full
                    continue
                why = cannot_write_in(folder)
                why = why and f"cannot be written: {why}"
            except OSError as exc:  # it may hold files: not written into
                why = f"cannot be listed: {exc.strerror or exc}"
            # removed, or made a file, since it was looked at: not said to be unusable ("saved
            # cannot be listed: No such file or directory" of a folder the Save could make)
            if not why or not os.path.lexists(folder):
                return folder
            if not folder.is_dir():
                continue
            if unusable is not None:
                unusable.append(f"{name} {why}")
        raise AssertionError("unreachable")  # pragma: no cover

    def _offered_save_folder(
        self, skipped: list[str] | None = None, unusable: list[str] | None = None
    ) -> tuple[Path, str | None]:
        """The folder in the first ``--data`` folder a Save as offered takes next
        (:meth:`_next_save_folder`) and why it cannot be made or written (None if it can: else
        the Save goes home, :meth:`_fallback_save_folder`). The one rule of :meth:`save`, the
        field's hint and tooltip and the point-cloud list (they asked of ``saved`` alone: a
        writable, full one in a read-only ``--data`` named it where Saves went home).

        Raises
        ------
        ValueError, OSError
            As :meth:`_next_save_folder` raises them.
        """
        folder = self._next_save_folder(skipped, unusable=unusable)
        return folder, _cannot_make(folder)

    def _offered_save_folder_refused(self) -> bool:
        """True if a Save as offered goes to the home folder (:meth:`_offered_save_folder`)."""
        if not self._save_roots:
            return False
        try:
            return bool(self._offered_save_folder()[1])
        except (ValueError, OSError):  # no such folder in --data: save() says why
            return False

    def _fallback_save_folder(self, offered: Path, why: str) -> Path:
        """The folder a Save as offered goes to when ``offered`` (in the first ``--data``
        folder) cannot be made or written, ``why``: the next new ``~/stereovision-saved``.

        Raises
        ------
        PermissionError
            No home folder, or one that cannot be written either: both named.
        """
        said = f"{display_path(offered)} cannot be written ({why})"
        try:
            home = Path.home()
        except RuntimeError:  # no home folder known
            raise PermissionError(f"save: {said}, and no home folder is known") from None
        folder = self._next_save_folder(home=home)
        also = _cannot_make(folder)
        if also:
            raise PermissionError(f"save: {said}, nor {display_path(folder)} ({also})")
        return folder

    def _set_progress(self, pct: int, text: str) -> None:
        self._step = text
        with self.state:
            self.state.progress = pct
            self.state.status = self._status_with_reads(text)

    def _publish(self, view: ViewData) -> None:
        self.view = view
        self._page_before = None
        self._cloud = None  # the new pair's scene replaces an opened cloud file
        # a sparse method's matches are points in either mode: the toggle says so
        points_only = view.matches is not None
        if not self.state.points_only:  # the toggle is the user's: their choice
            self._chosen_view_mode = self.state.view_mode
        mode = "points" if points_only else self._chosen_view_mode
        self.state.view_mode, self.state.points_only = mode, points_only  # flushed below
        self._drawn_mode = mode
        if view.mesh is not None:  # drawn as the points / surface toggle shows
            self._show_geometry(self._geometry_for_mode(), view.intrinsics)
        else:
            self._points_note = ""
            actor = self.plotter.actors.get("scene")
            if actor is not None:
                self.plotter.renderer.remove_actor(actor)
            self._update_view()
        with self.state:
            st = self.state
            st.img_left, st.img_right = view.left_url, view.right_url
            st.img_disparity, st.img_depth = view.disparity_url, view.depth_url
            st.img_matches = view.matches_url
            h, w = view.result.disparity.shape[:2]
            st.wide_pair = w > WIDE_ASPECT * h
            st.depth_caption, st.stats = view.texts(self._unit)
            st.disparity_caption = view.disparity_caption
            st.message_3d = self._scene_message()
            st.progress = 100
            st.busy = False
            # a camera's read or open that failed meanwhile is still the page's news, unless
            # something said since replaced it
            kept = self._failed_meanwhile if st.error == self._failed_meanwhile else None
            self._failed_meanwhile = None
            st.status = self._status_with_reads(None) or ("error" if kept else "ready")
            st.error = kept or ""
            self._max_disp_back()
            st.floor_label = st.img_floor = ""  # a new depth map: its floor is not found yet
            st.save_label = ""
            st.computations += 1

    # ------------------------------------------------------------------------- 3-D view

    def _geometry_for_mode(self) -> Any:
        self._points_note = ""
        if self._cloud is not None:
            return self._cloud  # an opened file: points in either mode
        v = self.view
        if v is None or v.mesh is None:
            return None
        if v.matches is not None:
            return v.mesh  # a sparse method's points: no surface to draw
        if self.state.view_mode == "points":
            cloud, count = shown_cloud(v.result.points, v.result.colors)
            if cloud.n_points < len(v.result.points):
                self._points_note = count
            return cloud
        return v.mesh

    def _scene_message(self) -> str:
        """The 3-D caption of the computed pair on show: its own, and in "points" mode the
        count of a subset drawn."""
        said = self.view.message_3d if self.view is not None else ""
        return f"{said} {self._points_note}".strip() if self._points_note else said

    def _show_geometry(self, geometry: Any, intrinsics: Any) -> None:
        from stereovision.render import add_geometry, keep_robust_clipping, median_depth

        self._intrinsics = intrinsics
        aspect = VIEW_ASPECT if intrinsics is None else intrinsics.width / intrinsics.height
        with self.state:  # the view's shape: the camera image's, so that all of it is in view
            self.state.view_aspect = round(aspect, 4)
        self._focal = median_depth(geometry)
        add_geometry(self.plotter, geometry)
        if self._clip_tag is not None:
            self.plotter.renderer.RemoveObserver(self._clip_tag)
        self._clip_tag = keep_robust_clipping(self.plotter, geometry.points)
        self._apply_camera()

    def _controls(self) -> Any:
        """The 3-D view's pose as the page's sliders set it (translations from the page's
        unit to metres).

        Returns
        -------
        stereovision.render.CameraControls

        Raises
        ------
        ValueError
            A slider's value that is not a finite number.
        """
        from stereovision.calibration import UNIT_TO_METRES
        from stereovision.render import CameraControls

        metres = UNIT_TO_METRES[self._unit]  # the translations are in the page's unit
        try:
            return CameraControls(
                **{
                    n: float(self.state[n]) * (metres if n in _TRANSLATIONS else 1.0)
                    for n in _CONTROL_NAMES
                }
            )
        except TypeError as exc:  # float(None): a slider emptied (said as before)
            raise ValueError(str(exc)) from None

    def _apply_camera(self) -> None:
        from stereovision.render import apply_camera

        try:
            controls = self._controls()
        except ValueError as exc:
            self._fail(exc)
            return
        apply_camera(
            self.plotter,
            controls,
            intrinsics=getattr(self, "_intrinsics", None),
            focal_distance=getattr(self, "_focal", 1.0),
        )
        from stereovision.render import CameraState

        self._slider_camera = CameraState.of(self.plotter.camera)
        self._update_view()

    def _mouse_camera(self) -> Any:
        """The 3-D view's camera when the mouse moved it away from the sliders' pose, else
        None.

        The page's view is rendered on the server (``plotter_ui(mode="server")``): the mouse's
        events drive this plotter's camera, which is therefore the view the page shows. The
        sliders follow it when a drag ends (:meth:`follow_mouse`): the view differs from their
        pose during a drag, after a drag past their range (clamped), or after a camera move
        that was no mouse event.

        Returns
        -------
        stereovision.render.CameraState or None
        """
        from stereovision.render import CameraState

        now = CameraState.of(self.plotter.camera)
        if self._slider_camera is None or now.same_view(self._slider_camera):
            return None
        return now

    def _mouse_view_of_pair(self) -> Any:
        """:meth:`_mouse_camera` when the 3-D view shows the pair on show, else None: with a
        point-cloud file shown, the mouse moved the view of that file (another scene, framed
        without the pair's intrinsics), which is no view of the pair Save renders.

        Returns
        -------
        stereovision.render.CameraState or None
        """
        return None if self._cloud is not None else self._mouse_camera()

    def _keeping_mouse_view(self, change: Callable[[], None]) -> None:
        """``change()`` (which puts the view on the sliders' pose), then the view the mouse left,
        if it left one: the unit toggle and the surface/points toggle are no slider move, and a
        dragged view was lost to them (and render.png with it).

        A view on the sliders' pose stays whole too: after the sliders followed a drag
        (:meth:`follow_mouse`) ``change()`` reset its focal point (the next drag's pivot) to
        the scene's median depth, and the feet sliders' rounding moved it."""
        from stereovision.render import CameraState

        try:
            mouse = self._mouse_camera()
            shown = mouse or CameraState.of(self.plotter.camera)
        except ValueError:  # a camera CameraState refuses: the sliders' pose, as before
            mouse = shown = None
        change()
        if shown is not None:
            shown.apply(self.plotter)
            if mouse is None:  # the sliders' pose (to their rounding): no mouse view to say
                self._slider_camera = CameraState.of(self.plotter.camera)
            self._update_view()

    def _update_view(self) -> None:
        if self._remote_view is not None:
            self._remote_view.update()

    def _on_controls(self, **_: Any) -> None:
        converted, self._unit_converted = self._unit_converted, None
        if converted is not None and all(self.state[n] == v for n, v in converted.items()):
            # the unit toggle's conversion (it keeps the view itself): applied here, after the
            # toggle's handler on the server, it put the view on the sliders' pose again, and a
            # view the mouse left was lost
            return
        if not self._following_mouse:
            self._apply_camera()

    def _on_mouse_end(self, _obj: Any = None, _event: str = "") -> None:
        """The end of a mouse drag or wheel turn of the 3-D view (the server's interactor)."""
        self.follow_mouse()

    def follow_mouse(self) -> None:
        """Set the six sliders from the 3-D view's camera as the mouse left it.

        The sliders stayed where they were while the mouse moved the view, so the next slider
        move put the view back on their old pose (the drag undone, plus the move). They now
        take the view's pose (:func:`sliders_from_pose`), and a slider moved next continues
        from the view.

        A value past its slider's range is clamped, not wrapped (:func:`sliders_from_pose`):
        the view then stays as the mouse left it (Save renders it and says so), and the next
        slider move goes from the clamped pose. A click that moved nothing changes nothing.
        """
        from stereovision.render import CameraState, pose_from_camera

        try:
            mouse = self._mouse_camera()
            if mouse is None:
                return
            values, clamped = sliders_from_pose(pose_from_camera(self.plotter.camera), self._unit)
        except ValueError:  # a camera with no pose (on its focal point): the sliders stay
            return
        self._following_mouse = True  # the view is not to be put on the sliders' pose here
        try:
            with self.state:
                for name, value in values.items():
                    self.state[name] = value
        finally:
            self._following_mouse = False
        if clamped:  # the sliders' pose is another view: the mouse's stays on show
            self._keeping_mouse_view(self._apply_camera)
        else:  # the view is the sliders' pose; its focal point (the mouse's pivot) is kept
            self._slider_camera = CameraState.of(self.plotter.camera)

    def _on_unit(self, unit: str = "m", **_: Any) -> None:
        """The unit toggle: the depth caption, the statistics, the floor's height and obstacle
        heights and the translation sliders (their values converted, so that the view stays
        where it was) in metres or feet."""
        from stereovision.calibration import UNIT_TO_METRES

        try:
            unit = known_unit(unit, UNITS)  # a plain str: an np.str_ was shown by its repr
        except ValueError as exc:
            self._fail(exc)
            with self.state:
                self.state.unit = self._unit
            return
        if unit == self._unit:
            return
        factor = UNIT_TO_METRES[self._unit] / UNIT_TO_METRES[unit]
        self._unit = unit
        with self.state:
            st = self.state
            st.translation_range = limit = translation_range(unit)
            st.translation_step = TRANSLATION_STEP if unit == "m" else 0.1
            for name in _TRANSLATIONS:
                # clamped to the range shown: 5 m is 16.404 ft, past the feet sliders' 16.4
                # (their thumb stuck at the end); the view is kept below
                try:
                    value = round(float(st[name]) * factor, 3)
                except (TypeError, ValueError):
                    # an emptied slider is no length in either unit (said below, as a slider
                    # move says it): it raised here, the toggle half done, the other sliders'
                    # metres then read as feet and the captions left in metres
                    continue
                st[name] = min(max(value, -limit), limit)
            # the sliders' listener sees these values when they are flushed: at this block's
            # end, or (the page's click, itself flushed) after this handler has kept the view
            self._unit_converted = {n: st[n] for n in _CONTROL_NAMES}
            st.floor_caption = floor_caption(unit)
            if self.view is not None and self._page_before is None:
                st.depth_caption, st.stats = self.view.texts(unit)
                if st.floor_label and self.view.floor is not None:
                    st.floor_label = floor_text(self.view.floor, unit)
        self._keeping_mouse_view(self._apply_camera)

    def _on_view_mode(self, **_: Any) -> None:
        if self.state.points_only:
            # the toggle is disabled while points are all there is to show: it says "points"
            if self.state.view_mode != "points":
                with self.state:
                    self.state.view_mode = "points"
            return
        if self._cloud is not None:  # the opened file stays; only its caption changes
            with self.state:
                self.state.message_3d = self._cloud_message()
            return
        if self.state.view_mode == self._drawn_mode:
            return  # drawn so already (the mode _publish set)
        geometry = self._geometry_for_mode()
        if geometry is not None:
            self._drawn_mode = self.state.view_mode
            intrinsics = self.view.intrinsics if self.view else None
            self._keeping_mouse_view(lambda: self._show_geometry(geometry, intrinsics))
            if self._page_before is None:  # not while a new pair computes (its caption stays)
                with self.state:
                    self.state.message_3d = self._scene_message()

    # ------------------------------------------------------------------------- layout

    def _build_ui(self) -> None:
        from trame.ui.vuetify3 import SinglePageLayout
        from trame.widgets import html
        from trame.widgets import vuetify3 as v3
        from trame_pyvista.ui import plotter_ui

        ctrl = self.ctrl
        ctrl.capture = self.capture
        ctrl.open_cameras = self.open_cameras
        ctrl.load_files = self.load_files
        ctrl.open_cloud = self.open_cloud
        ctrl.reset_camera = self.reset_camera
        img_style = "width: 100%; display: block; background: #222; min-height: 60px;"

        with SinglePageLayout(self.server, full_height=True) as layout:
            layout.title.set_text("stereovision")
            layout.icon.hide()  # no navigation drawer in this app
            with layout.toolbar:
                v3.VSpacer()
                html.Span("{{ status }}", id="status", classes="text-body-2 mr-4")
                html.Span("{{ computations }}", id="computations", style="display: none")
                v3.VProgressLinear(
                    model_value=("progress",),
                    active=("busy",),
                    indeterminate=("busy && progress < 20",),
                    absolute=True,
                    location="bottom",
                    color="primary",
                    id="progress",
                )
            with layout.content:
                with v3.VContainer(fluid=True, classes="pa-2"):
                    v3.VAlert(
                        "{{ error }}",
                        v_if="error",
                        type="error",
                        closable=True,
                        density="compact",
                        classes="mb-2",
                        id="error-alert",
                        # the toolbar's "error" goes with the message (it stayed until the
                        # next computed pair); a computation's progress is not "error"
                        click_close="error = ''; if (status === 'error') status = 'ready'",
                    )
                    with v3.VRow(dense=True):
                        with v3.VCol(cols=12, md=4):
                            self._panel_acquisition(v3, html, img_style)
                        with v3.VCol(cols=12, md=4):
                            self._panel_stereo(v3, html, img_style)
                        with v3.VCol(cols=12, md=4):
                            with v3.VCard(id="panel-3d", classes="fill-height"):
                                v3.VCardTitle("3 · 3-D view")
                                with v3.VCardText():
                                    with html.Div(id="view-3d", style=(VIEW_STYLE,)):
                                        self._remote_view = plotter_ui(
                                            self.plotter,
                                            mode="server",
                                            add_menu=False,
                                            server=self.server,
                                        )
                                    html.Div(
                                        "{{ message_3d }}",
                                        v_if="message_3d",
                                        id="message-3d",
                                        classes="text-caption mt-1",
                                    )
                                    self._camera_controls(v3, html)

    def _panel_acquisition(self, v3: Any, html: Any, img_style: str) -> None:
        with v3.VCard(id="panel-acquisition", classes="fill-height"):
            v3.VCardTitle("1 · Acquisition")
            with v3.VCardText():
                html.Div("{{ source_label }}", id="source-label", classes="text-caption mb-1")
                _button_and_answer(
                    v3,
                    html,
                    "Check rows",
                    "check-rows-btn",
                    self.check_rows_clicked,
                    "rows_label",
                    "rows-label",
                )
                with v3.VRow(dense=True, classes="my-1"):
                    with v3.VCol(cols="auto", style="min-width: 25%;"):
                        v3.VBtn(
                            "Rectify",
                            id="rectify-btn",
                            size="small",
                            variant="outlined",
                            block=True,
                            click=self.rectify_clicked,
                            title="no calibration: rectify the pair from its own features",
                        )
                with v3.VRow(dense=True):
                    with v3.VCol(cols=("wide_pair ? 12 : 6",)):
                        html.Div("left", classes="text-caption")
                        html.Img(id="img-left", src=("img_left",), style=img_style)
                    with v3.VCol(cols=("wide_pair ? 12 : 6",)):
                        html.Div("right", classes="text-caption")
                        html.Img(id="img-right", src=("img_right",), style=img_style)
                with v3.VRow(dense=True, classes="mt-2", align="center"):
                    with v3.VCol(cols=6):
                        v3.VBtn(
                            "Capture",
                            id="capture-btn",
                            color="primary",
                            block=True,
                            click=self.ctrl.capture,
                            disabled=("!live",),
                            prepend_icon="mdi-camera",
                        )
                    with v3.VCol(cols=6):
                        html.Div("resolution", classes="text-caption")
                        # wraps: at 1000 px its "320" ran out of the panel, cut in half
                        _toggle(
                            "resolution", RESOLUTIONS, "resolution-toggle", "resolution", wrap=True
                        )
                # a row of its own: under the Capture button, in half the panel, its label
                # wrapped onto two lines
                v3.VSwitch(
                    label=f"average {AVERAGE_FRAMES} still frames (low light)",
                    v_model=("average",),
                    density="compact",
                    hide_details=True,
                    color="primary",
                    disabled=("!can_average",),
                    id="average-switch",
                )
                v3.VSelect(
                    label="Scene folder",
                    v_model=("scene",),
                    items=("scenes",),
                    density="compact",
                    hide_details=True,
                    classes="mt-3",
                    id="scene-select",
                )
                with v3.VRow(dense=True, classes="mt-1"):
                    with v3.VCol(cols=5):
                        _file_picker("Left image", "left_file", "images", "left-file")
                    with v3.VCol(cols=5):
                        _file_picker("Right image", "right_file", "images", "right-file")
                    with v3.VCol(cols=2):
                        v3.VBtn("Load", click=self.ctrl.load_files, id="load-files", block=True)
                with v3.VRow(dense=True, classes="mt-1"):
                    with v3.VCol(cols=10):
                        label = "Image folder (its pairs, one per Capture)"
                        _file_picker(label, "pair_folder", "pair_folders", "pair-folder")
                    with v3.VCol(cols=2):
                        v3.VBtn(
                            "Play", click=self.open_pair_folder, id="pair-folder-open", block=True
                        )
                # two rows: in one, a sixth of it for the format showed "d" for "driver"
                # under an "f." label (and less for the cameras clipped their labels)
                with v3.VRow(dense=True, classes="mt-1"):
                    with v3.VCol(cols=6):
                        v3.VTextField(
                            label="Left camera",
                            v_model=("cam_left",),
                            density="compact",
                            hide_details=True,
                            id="cam-left",
                        )
                    with v3.VCol(cols=6):
                        v3.VTextField(
                            label="Right camera",
                            v_model=("cam_right",),
                            density="compact",
                            hide_details=True,
                            id="cam-right",
                        )
                with v3.VRow(dense=True, classes="mt-1"):
                    with v3.VCol(cols=4):
                        v3.VSelect(
                            label="format",
                            v_model=("fourcc",),
                            items=("fourccs",),
                            density="compact",
                            hide_details=True,
                            id="cam-fourcc",
                        )
                    with v3.VCol(cols=2):
                        v3.VBtn("Open", click=self.ctrl.open_cameras, id="cam-open", block=True)

    def _panel_stereo(self, v3: Any, html: Any, img_style: str) -> None:
        with v3.VCard(id="panel-stereo", classes="fill-height"):
            v3.VCardTitle("2 · Stereo output")
            with v3.VCardText():
                _toggle("method", self.state.methods, "method-toggle", "method", wrap=True)
                with v3.VRow(dense=True, align="center", classes="mt-1"):
                    with v3.VCol(cols=8):
                        v3.VTextField(
                            label="max disparity (px; Enter)",
                            v_model=("max_disp",),
                            placeholder=("max_disp_hint",),
                            persistent_placeholder=True,
                            density="compact",
                            hide_details=True,
                            id="max-disparity",
                            __events=[("keyup_enter", "keyup.enter")],
                            keyup_enter=(self.apply_max_disparity, "[false, max_disp]"),
                            update_focused=(self.apply_max_disparity, "[$event, max_disp]"),
                        )
                    with v3.VCol(cols=4):
                        _toggle("unit", UNITS, "unit-toggle", "unit", button_classes="text-none")
                with v3.VRow(dense=True, classes="mt-2"):
                    with v3.VCol(cols=("wide_pair ? 12 : 6",)):
                        html.Div(
                            "{{ disparity_caption }}",
                            id="disparity-caption",
                            classes="text-caption",
                        )
                        html.Img(id="img-disparity", src=("img_disparity",), style=img_style)
                    with v3.VCol(cols=("wide_pair ? 12 : 6",)):
                        html.Div("{{ depth_caption }}", id="depth-caption", classes="text-caption")
                        html.Img(id="img-depth", src=("img_depth",), style=img_style)
                with html.Div(v_if="img_matches", classes="mt-2"):
                    html.Div("matches", classes="text-caption")
                    html.Img(id="img-matches", src=("img_matches",), style=img_style)
                html.Div("{{ stats }}", id="stats", classes="text-caption mt-2")
                _button_and_answer(
                    v3,
                    html,
                    "Find floor",
                    "floor-btn",
                    self.find_floor_clicked,
                    "floor_label",
                    "floor-label",
                )
                with html.Div(v_if="img_floor", classes="mt-1"):
                    html.Div("{{ floor_caption }}", id="floor-caption", classes="text-caption")
                    html.Img(id="img-floor", src=("img_floor",), style=img_style)
                with v3.VRow(dense=True, align="center", classes="mt-1"):
                    with v3.VCol(cols=9):
                        # The label alone (its explanation below): the field cut the long
                        # label at "as offered: saved, sa...", unreadable even when focused.
                        v3.VTextField(
                            label="Save folder",
                            v_model=("save_dir",),
                            density="compact",
                            hide_details=True,
                            id="save-dir",
                            title=("save_dir_title",),
                        )
                    with v3.VCol(cols=3):
                        v3.VBtn(
                            "Save",
                            click=(self.save_clicked, "[save_dir]"),
                            id="save-btn",
                            block=True,
                        )
                html.Div(
                    "{{ save_hint }}", id="save-hint", classes="text-caption text-medium-emphasis"
                )
                html.Div("{{ save_label }}", id="save-label", classes="text-caption")

    def _camera_controls(self, v3: Any, html: Any) -> None:
        with v3.VRow(dense=True, classes="mt-2", align="center"):
            with v3.VCol(cols=8):
                # a sparse method's matches have no surface: "points", disabled
                _toggle(
                    "view_mode",
                    ("surface", "points"),
                    "view-mode",
                    button_ids="view-mode",
                    disabled="points_only",
                )
            with v3.VCol(cols=4):
                v3.VBtn(
                    "Reset",
                    click=self.ctrl.reset_camera,
                    size="small",
                    id="reset-camera",
                    block=True,
                )
        # Each slider's name in a column of one width and its value at its end: with the name
        # as the slider's label, each track started where its name ended, so the six thumbs
        # at zero stood at six places, and a value showed only while its thumb was dragged.
        for name in _CONTROL_NAMES:
            if name in _TRANSLATIONS:  # in the page's unit
                label = f"{name} ({{{{ unit }}}})"
                value = f"{{{{ Number({name}).toFixed(2) }}}} {{{{ unit }}}}"
                rng: Any = ("-translation_range",), ("translation_range",)
                step: Any = ("translation_step",)
            else:
                label, rng, step = f"{name} (°)", (-ANGLE_RANGE, ANGLE_RANGE), 1.0
                value = f"{{{{ Number({name}).toFixed(0) }}}}°"
            with html.Div(id=f"slider-{name}"):
                with v3.VSlider(
                    v_model=(name,),
                    min=rng[0],
                    max=rng[1],
                    step=step,
                    density="compact",
                    hide_details=True,
                    thumb_label=True,
                ):
                    with v3.Template(v_slot_prepend=True):
                        html.Div(label, classes="slider-name", style=SLIDER_NAME_STYLE)
                    with v3.Template(v_slot_append=True):
                        html.Div(value, classes="slider-value", style=SLIDER_VALUE_STYLE)
        with v3.VRow(dense=True, classes="mt-1"):
            with v3.VCol(cols=9):
                label = "Point cloud file (PLY / PCD / NPZ)"
                _file_picker(label, "cloud_path", "clouds", "cloud-path")
            with v3.VCol(cols=3):
                v3.VBtn("Show", click=self.ctrl.open_cloud, id="cloud-open", block=True)
