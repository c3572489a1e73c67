"""``overview.png``: a run's pictures on one page, each colour map with a labelled colour bar.

``disparity.png`` and ``depth.png`` are colour-mapped at the input's size (to overlay on it) and
carry no scale. The overview puts the left image, the disparity map, the depth map (when there
is one) and the matcher's confidence side by side, downscaled, each map with a colour bar
whose two ends are labelled with their values and unit (the range the colours span) and round
values between them, under a one-line title (pair, method, range, density). The label column
beside the bars is as wide as its longest label (``cv2.getTextSize``; ``"116123 mm"``), 64 px at
least; an inner label keeps a digit's height of blank rows from an end's (:data:`_END_GAP`).
The maps are coloured exactly as ``disparity.png`` and ``depth.png`` are (:func:`colour_range`):
the disparity from 0 px (its 1st percentile when most of it is below 0 px) to its 99th
percentile, the depth on its inverse (near = warm) from the 1st to the 99th percentile of
``1 / Z``, so the depth bar's ticks are not evenly spaced.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import figure_shown

#: Widest panel (px); a larger image is downscaled by one factor for every panel.
PANEL_WIDTH = 640

_MARGIN = 10
_TITLE_H = 34
_CAPTION_H = 22  # the caption band above a panel; taller where a caption reaches a bar's label
_CAPTION_BASELINE = _CAPTION_H - 7  # a caption's baseline, from its cell's top
_CAPTION_SCALE = 0.5
#: Blank rows between a caption's box and the top label's box of its bar, where the caption is
#: wide enough to reach over the label column (panels under about 120 px wide)
_CAPTION_GAP = 3
_BAR_GAP = 8
_BAR_W = 16
_LABEL_W = 64  # the label column right of a bar at least; wider when a label needs it
_LABEL_X = 7  # from the bar's right edge to its labels' left edge
_LABEL_SCALE = 0.4
_TICK_SPACING = 16  # px between two labelled ticks at least
#: Blank rows between an end's label box and an inner label's at least (``cv2.getTextSize``
#: boxes; 6 leaves 8 blank rows between the inks, about a digit's 9): ticks 16 rows apart leave
#: 4 (6 between the inks), and an inner label read as part of the end one (``"6"`` right over
#: ``"6.5 m"`` at the bottom of the demo's depth bar).
_END_GAP = 6
_FONT = cv2.FONT_HERSHEY_SIMPLEX
_WHITE = (255, 255, 255)
_GREY = (40, 40, 40)


def colour_range(
    values: npt.NDArray[Any], lo: float | None = None, hi: float | None = None
) -> tuple[float, float] | None:
    """The values mapped to the ends of the colour map by ``stereovision.cli.colorize``.

    Parameters
    ----------
    values : ndarray, float
        The map (NaN = none).
    lo, hi : float, optional
        Given ends; a missing one is the 1st (``lo``) or 99th (``hi``) percentile of the finite
        values. When that percentile is not past the given end, or more than half of the
        finite values lie beyond the given end (``lo=0`` for a map of negative disparities: a
        swapped pair's, with or without a few positive outliers), both ends are the percentiles.

    Returns
    -------
    tuple of float or None
        ``(lo, hi)``; None when no value is finite (the map is black).
    """
    finite = np.isfinite(values)
    if not finite.any():
        return None
    v = values[finite]
    given = (lo, hi)
    lo = float(np.percentile(v, 1)) if lo is None else float(lo)
    hi = float(np.percentile(v, 99)) if hi is None else float(hi)
    # the given end past most of the map's values: a map of negative disparities (a swapped
    # pair's) from a given 0 px was one colour, its bar upside down (top -12 px, bottom 0 px),
    # and so was one with a few positive outliers (95 % of its pixels at level 0)
    beyond = given[0] is not None and np.count_nonzero(v < lo) * 2 > v.size
    beyond |= given[1] is not None and np.count_nonzero(v > hi) * 2 > v.size
    if None in given and (hi <= lo or beyond):
        lo, hi = float(np.percentile(v, 1)), float(np.percentile(v, 99))
    return lo, hi


def colour_levels(values: npt.NDArray[Any], lo: float, hi: float) -> npt.NDArray[np.uint8]:
    """The colour map's level (0-255) of each value, as ``colorize`` computes it: NaN at
    level 0, +inf at 255 and -inf at 0, without an overflow on the way."""
    scale = 255.0 / max(hi - lo, 1e-9)
    finite = np.nan_to_num(values, nan=lo, posinf=hi, neginf=lo)
    # float32 values more than float32's largest apart (-3e38 and 3e38) overflow to inf in
    # the difference, which the clip takes to 255 as it should: no RuntimeWarning for that
    with np.errstate(over="ignore"):
        return np.clip((finite - lo) * scale, 0, 255).astype(np.uint8)


@dataclass
class ColourBar:
    """One labelled colour bar of an overview.

    Attributes
    ----------
    box : tuple of int
        ``(x, y, width, height)`` of the bar in the overview; its top row is the colour map's
        level 255, its bottom row level 0.
    ticks : list of tuple
        ``(value, label, y)``: a labelled value and the row of the overview it is drawn at,
        from the top down. The first and the last are the bar's ends (the colour range's ends,
        their labels with the unit: ``"52.3 px"``, ``"2.07 m"``), the others round values
        between them (the number only).
    unit : str
        The unit the end labels name (``"px"``, the depth's unit; ``""`` for the confidence).
    """

    box: tuple[int, int, int, int]
    ticks: list[tuple[float, str, int]] = field(default_factory=list)
    unit: str = ""


@dataclass(eq=False)  # an array field: == by identity (== raised)
class Overview:
    """An overview picture and where its parts are.

    Attributes
    ----------
    image : ndarray, uint8 (H, W, 3)
        BGR picture.
    title : str
        Its one-line title.
    panels : dict
        Panel name (``"left"``, ``"disparity"``, ``"depth"``, ``"confidence"``) ->
        ``(x, y, width, height)`` of the downscaled picture.
    bars : dict
        Panel name -> its :class:`ColourBar` (maps only).
    scale : float
        Downscaling factor of every panel (1 for images up to :data:`PANEL_WIDTH` wide).
    caption_boxes : dict
        Panel name -> ``(x0, y0, x1, y1)`` of its caption as drawn (``cv2.getTextSize``'s box,
        the rows below the baseline included): clear of every bar label, inside its cell.
    captions : dict
        Panel name -> the caption above it; the depth panel's says on what share of the pixels
        there is a depth (``"depth (m) on 83.8 %, none where filled"``: the disparity's filled
        pixels get none, so its holes are not the disparity's; ``"... none where filled or
        too far to tell"`` where measured pixels got none, their disparity not above its
        uncertainty ``sigma_d``; ``"... none where filled or beyond the limits"`` for a
        :meth:`~stereovision.depth.DepthResult.filtered` result, ``"... or too far to tell"``
        added where its range, the calibration's depth of the disparity, could not have cut
        the measured pixels without one; the share alone when every pixel with a disparity has
        a depth).
    """

    image: npt.NDArray[np.uint8]
    title: str
    panels: dict[str, tuple[int, int, int, int]]
    bars: dict[str, ColourBar]
    scale: float
    captions: dict[str, str] = field(default_factory=dict)
    caption_boxes: dict[str, tuple[int, int, int, int]] = field(default_factory=dict)


def _nice_values(lo: float, hi: float) -> list[float]:
    """1-2-5 steps of every decade between ``lo`` and ``hi`` (both > 0), ascending."""
    out: list[float] = []
    for e in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1):
        for m in (1.0, 2.0, 5.0):
            v = float(f"{m * 10.0**e:.12g}")
            if lo <= v <= hi:
                out.append(v)
    return out


def _linear_ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    """About ``n`` round values in ``[lo, hi]``, evenly spaced."""
    raw = (hi - lo) / max(n, 1)
    if raw <= 0:
        return [lo]
    mag = 10.0 ** math.floor(math.log10(raw))
    step = next(m * mag for m in (1, 2, 5, 10) if m * mag >= raw)
    first = math.ceil(lo / step - 1e-9) * step
    count = math.floor((hi - first) / step + 1e-9) + 1
    return [float(f"{first + i * step:.12g}") for i in range(count)]


def _text_box(text: str, x: int, row: int) -> tuple[int, int, int, int]:
    """``(x0, y0, x1, y1)`` of a bar label whose tick is at ``row`` and whose bar's right edge is
    at ``x``, as ``cv2.getTextSize`` measures it (the rows above and below its baseline)."""
    (tw, th), base = cv2.getTextSize(text, _FONT, _LABEL_SCALE, 1)
    x0, baseline = x + _LABEL_X, row + 4
    return x0, baseline - th, x0 + tw, baseline + base


def _place_ticks(
    height: int,
    lo: float,
    hi: float,
    to_mapped: Callable[[float], float],
    values: list[float],
    ends: tuple[float, float],
    unit: str,
) -> list[tuple[float, str, int]]:
    """The labelled ticks of a bar ``height`` rows tall: ``(value, label, row)``, rows from
    the bar's top, sorted.

    ``to_mapped`` turns a labelled value into the colour-mapped one (the identity, or
    ``1 / Z`` for the depth). ``ends`` are the labelled values of the top and bottom rows
    (the colour range's ends), labelled with ``unit``; an inner value closer to the one above
    it or to the bottom row than :data:`_TICK_SPACING` is left out, and so is one whose label
    would come within :data:`_END_GAP` rows of an end's label (boxes of ``cv2.getTextSize``).
    """
    span = max(hi - lo, 1e-9)
    top, bottom = 0, height - 1
    # the ends first (a bar too short for two labels keeps its top one), then the values
    # between them, from the top down, each clear of the labels above and below it
    placed: list[tuple[float, str, int]] = [(ends[0], _end_label(ends[0], unit), top)]
    if bottom - top >= _TICK_SPACING:
        placed.append((ends[1], _end_label(ends[1], unit), bottom))
    end_boxes = [_text_box(text, 0, row) for _, text, row in placed]
    inner = []
    for value in values:
        level = (to_mapped(value) - lo) * 255.0 / span
        if not 0.0 <= level <= 255.0:
            continue
        inner.append((value, round((height - 1) * (1.0 - level / 255.0))))
    last_y = top
    for value, ty in sorted(inner, key=lambda t: t[1]):
        if ty - last_y < _TICK_SPACING or bottom - ty < _TICK_SPACING:
            continue
        text = _label(value)
        _, y0, _, y1 = _text_box(text, 0, ty)
        if any(y0 - _END_GAP < e1 and e0 < y1 + _END_GAP for _, e0, _, e1 in end_boxes):
            continue
        placed.append((value, text, ty))
        last_y = ty
    return sorted(placed, key=lambda t: t[2])


def _label_width(ticks: list[tuple[float, str, int]]) -> int:
    """The label column a bar's ``ticks`` need: from the bar's right edge to the widest
    label's right edge (``cv2.getTextSize``)."""
    return max(_text_box(text, 0, 0)[2] for _, text, _ in ticks)


def _bar(
    img: npt.NDArray[np.uint8],
    x: int,
    y: int,
    height: int,
    ticks: list[tuple[float, str, int]],
    unit: str,
) -> ColourBar:
    """Draw a vertical colour bar at ``(x, y)`` and its ``ticks`` (:func:`_place_ticks`)."""
    rows = np.arange(height, dtype=np.float64)
    levels = np.clip(np.rint(255.0 * (height - 1 - rows) / max(height - 1, 1)), 0, 255)
    strip = cv2.applyColorMap(levels.astype(np.uint8)[:, None], cv2.COLORMAP_TURBO)
    img[y : y + height, x : x + _BAR_W] = strip
    cv2.rectangle(img, (x - 1, y - 1), (x + _BAR_W, y + height), _WHITE, 1)
    bar = ColourBar(box=(x, y, _BAR_W, height), unit=unit)
    for value, text, row in ticks:
        ty = y + row
        x0, _, _, _ = _text_box(text, x + _BAR_W, ty)
        cv2.line(img, (x + _BAR_W, ty), (x + _BAR_W + 4, ty), _WHITE, 1)
        cv2.putText(img, text, (x0, ty + 4), _FONT, _LABEL_SCALE, _WHITE, 1, cv2.LINE_AA)
        bar.ticks.append((value, text, ty))
    return bar


#: Bar labels from here up are in exponent form: a depth map of ~0 px disparities (3e38 m)
#: was labelled with all 39 digits, a label column that made the overview twice as wide.
_EXPONENT_FROM = 1e9


def _label(value: float) -> str:
    """A bar label's number: :func:`figure_shown`'s, in exponent form from
    :data:`_EXPONENT_FROM` up (``3e+38``)."""
    if math.isfinite(value) and abs(value) >= _EXPONENT_FROM:
        return f"{value:.3g}"
    return figure_shown(value)


def _end_label(value: float, unit: str) -> str:
    """An end of a bar: its value as the ticks print theirs, and the unit (``"52.3 px"``)."""
    return f"{_label(value)} {unit}" if unit else _label(value)


#: ``str.translate`` table of :func:`cv2_text`: the ASCII control characters as ``?``.
_CONTROL_AS_QUESTION_MARK = {c: "?" for c in (*range(32), 127)}


def cv2_text(text: str) -> str:
    """``text`` as OpenCV's Hershey fonts can draw it on one line: every non-ASCII character
    and every control character (a newline, a tab, NUL) as ``?``.

    The fonts have glyphs for ASCII only, and a lone surrogate --
    a file name's non-UTF-8 byte as Python decodes it (``os.fsdecode``) -- crashes
    ``cv2.getTextSize`` and ``cv2.putText`` (a segmentation fault, not an exception). A
    newline (a folder name's) started a second line over the picture below the text, which
    ``cv2.getTextSize`` does not measure, and a NUL ended the text there.
    """
    ascii_text = text.encode("ascii", "replace").decode("ascii")
    return ascii_text.translate(_CONTROL_AS_QUESTION_MARK)


def _cut_by_limits(result: Any, dropped: npt.NDArray[np.bool_]) -> npt.NDArray[np.bool_]:
    """The ``dropped`` pixels (measured, no depth) a filtered result's limits may have cut:
    all of them when it has limits, but, for a range alone (``min_depth``, ``max_depth``) and
    a calibration, only those whose disparity's depth lies outside it; the others had no depth
    to cut (too far to tell). A result cut by ``--max-depth`` said "beyond the limits" of
    those too (even of a limit that cut nothing), telling cut pixels from too-far ones
    nowhere."""
    limits = getattr(result, "limits", None) or {}
    calib = getattr(result, "calibration", None)
    if not limits:
        return np.zeros_like(dropped)
    if calib is None or not set(limits) <= {"min_depth", "max_depth"}:
        return dropped  # a sigma limit's cut is not told by the disparity: one reason
    from stereovision.triangulation import _depth

    z = _depth(np.asarray(result.disparity, np.float64), calib, "m")
    with np.errstate(invalid="ignore"):
        outside = (z < limits.get("min_depth", -np.inf)) | (z > limits.get("max_depth", np.inf))
    return dropped & outside


def overview_image(result: Any, title: str, unit: str = "m") -> Overview:
    """The overview of a :class:`~stereovision.depth.DepthResult`.

    Parameters
    ----------
    result : DepthResult
        Its left (rectified) uint8 image (grey ``(H, W)`` or ``(H, W, 1)``, BGR or BGRA, drawn
        as BGR; None: black), disparity, depth (None without calibration) and confidence.
    title : str
        The one-line title (scaled down to fit; a character outside ASCII is drawn, and kept
        in :attr:`Overview.title`, as ``?``).
    unit : str
        The depth bar's unit (its caption and tick labels): ``"m"`` (default), ``"ft"``,
        ``"mm"``, ``"cm"`` or ``"in"`` (:data:`~stereovision.calibration.UNIT_TO_METRES`). The
        depth panel's colours do not depend on it (they are ``depth.png``'s).

    Returns
    -------
    Overview
        The picture (2 x 2 panels: left, disparity; depth, confidence; without a depth map
        left, disparity; confidence) and where its panels and bars are.

    Raises
    ------
    ValueError
        An unknown ``unit`` (the message names the allowed ones), a disparity map that is not
        ``(H, W)`` or has no pixel, a depth or confidence map of another shape, or a left image
        that is not grey, BGR or BGRA, not uint8, or of another size.
    """
    from stereovision._validate import known_unit
    from stereovision.calibration import UNIT_TO_METRES

    unit = known_unit(unit, UNIT_TO_METRES)
    size = UNIT_TO_METRES[unit]  # metres in one unit
    disparity = np.asarray(result.disparity, np.float32)
    if disparity.ndim != 2 or disparity.size == 0:
        # a 0x0 map divided the panel's width by 0 (ZeroDivisionError)
        raise ValueError(
            f"result: expected a (H, W) disparity map with pixels, got shape {disparity.shape}"
        )
    h, w = disparity.shape
    scale = min(1.0, PANEL_WIDTH / w)
    pw, ph = max(1, round(w * scale)), max(1, round(h * scale))
    left = result.left_rectified
    if left is None:
        left = np.zeros((h, w, 3), np.uint8)
    else:
        # a hand-made result's (H, W, 1) or BGRA image failed to fit the panel's 3 channels
        left = np.asarray(left)
        if left.size == 0 or not (
            left.ndim == 2 or (left.ndim == 3 and left.shape[2] in (1, 3, 4))
        ):
            raise ValueError(
                "result: expected a grey (H, W) or (H, W, 1), BGR or BGRA left image, got shape "
                f"{left.shape}"
            )
        if left.shape[:2] != disparity.shape:
            # a left image of another size was stretched to the panel without a word: its
            # pixels beside another place's disparities
            raise ValueError(
                f"result: expected a left image of the disparity map's shape {disparity.shape}, "
                f"got shape {left.shape}"
            )
        if left.dtype != np.uint8:
            # the panel is uint8: a uint16 image of 1000 was drawn as 232 (wrapped), a float
            # one of 0.5 black
            raise ValueError(f"result: expected a uint8 left image, got {left.dtype}")
        if left.ndim == 3 and left.shape[2] == 4:
            left = left[:, :, :3]  # BGRA: drawn without its alpha
        elif left.ndim == 3 and left.shape[2] == 1:
            left = left[:, :, 0]
        if left.ndim == 2:
            left = cv2.cvtColor(np.ascontiguousarray(left), cv2.COLOR_GRAY2BGR)
    valid = np.isfinite(disparity)
    # a hand-made result's maps of another size than its disparity map's gave NumPy's
    # "operands could not be broadcast together with shapes (120,200) (60,100)"
    for name in ("depth", "confidence"):
        shape = np.shape(getattr(result, name))
        if shape and shape != disparity.shape:
            raise ValueError(
                f"result: expected a {name} map of the disparity map's shape {disparity.shape}, "
                f"got shape {shape}"
            )
    confidence = np.where(valid, np.asarray(result.confidence, np.float32), np.nan)
    # name, values as mapped, fixed ends, caption, labelled value -> mapped value, tick values
    maps: list[tuple[str, Any, Any, str, Callable[[float], float], str, str]] = [
        ("disparity", disparity, (0.0, None), "disparity (px)", lambda v: v, "linear", "px")
    ]
    if result.depth is not None:
        depth = np.asarray(result.depth, np.float32)
        with np.errstate(divide="ignore"):
            inv = np.where(np.isfinite(depth), 1.0 / depth, np.nan)
        # coloured on 1 / Z in metres, as depth.png is; labelled in the unit asked for
        # the depth map has holes where the disparity map was filled (guesses get no depth)
        # and, filtered, beyond the limits: said with the share, the reasons that apply (none
        # for a map with nothing filled nor cut), shortened where the panel is too narrow
        has_depth = np.isfinite(depth)
        share = f"depth ({unit}) on {100 * float(has_depth.mean()):.1f} %"
        lost = valid & ~has_depth
        filled = lost & (np.asarray(result.confidence) == 0)
        why = ["filled"] if filled.any() else []
        # measured, no depth: not above its sigma_d, a one-sigma depth interval reaching
        # infinity (depth_counts' "dropped"; playground's gabor map: 5449 px, said nowhere),
        # or, filtered, cut by the limits
        dropped = lost & ~filled
        cut = _cut_by_limits(result, dropped)
        if cut.any():
            why.append("beyond the limits")
        if (dropped & ~cut).any():
            why.append("too far to tell")
        said = ", ".join(why[:-1]) + " or " + why[-1] if len(why) > 1 else "".join(why)
        caption_text = f"{share}, none where {said}" if why else share
        # the reasons where the caption stays clear of the bar's labels (left of their column)
        reach = pw + _BAR_GAP + _BAR_W + _LABEL_X
        if cv2.getTextSize(caption_text, _FONT, _CAPTION_SCALE, 1)[0][0] > reach:
            caption_text = share
        maps.append(
            ("depth", inv, (None, None), caption_text, lambda z: 1.0 / (z * size), "inverse", unit)
        )
    maps.append(
        ("confidence", confidence, (0.0, 1.0), "confidence (0-1)", lambda v: v, "linear", "")
    )
    # each map's colour range and labelled ticks first: the label column is as wide as the
    # widest label needs (64 px at least), the same beside every bar
    placed: list[tuple[Any, tuple[float, float] | None, list[tuple[float, str, int]]]] = []
    for _, values, ends, _, to_mapped, kind, bar_unit in maps:
        rng = colour_range(values, *ends)
        ticks: list[tuple[float, str, int]] = []
        if rng is not None:
            lo, hi = rng
            if kind == "inverse":
                # the ends depth.png colours: a depth's 1 / Z is > 0, so is lo (the old cap of
                # the far end at 1e6 m labelled a map reaching 5e7 m "1000000 m"); the
                # fallbacks are for a hand-made map of negative depths only
                near = 1.0 / hi if hi > 0 else 1e12
                far = 1.0 / lo if lo > 0 else 1e6
                near, far = near / size, far / size  # in the bar's unit
                # a range within a decade in even steps of depth (2.5, 3, 3.5 m), a wider one
                # in 1-2-5 steps of each decade (1, 2, 5, 10, 20 m)
                steps = _linear_ticks(near, far, 6) if far < 10 * near else _nice_values(near, far)
                bar_ends = (near, far)  # near (warm) at the top
            else:
                steps = _linear_ticks(lo, hi)
                bar_ends = (hi, lo)
            ticks = _place_ticks(ph, lo, hi, to_mapped, steps, bar_ends, bar_unit)
        placed.append((values, rng, ticks))
    label_w = max([_LABEL_W] + [_label_width(ticks) for _, _, ticks in placed if ticks])
    texts = ["left image"] + [m[3] for m in maps]
    sizes = [cv2.getTextSize(t, _FONT, _CAPTION_SCALE, 1) for t in texts]
    # a cell as wide as its caption at least (a panel of a few px had captions running over the
    # next cell's and out of the picture)
    cell_w = max([pw + _BAR_GAP + _BAR_W + label_w] + [tw for (tw, _), _ in sizes])
    # a caption reaching the label column of its bar (a panel under about 120 px wide) ends
    # _CAPTION_GAP rows above the bar's top label: the panel comes down (it was drawn over it)
    caption_h = _CAPTION_H
    for ((tw, _), base), (_, _, ticks) in zip(sizes[1:], placed, strict=True):
        if ticks and tw > pw + _BAR_GAP + _BAR_W + _LABEL_X:
            top = _text_box(ticks[0][1], 0, ticks[0][2])[1]  # its label's top, from the panel's
            caption_h = max(caption_h, _CAPTION_BASELINE + base + _CAPTION_GAP - top)
    cell_h = caption_h + ph
    cells = 1 + len(maps)
    cols = 2
    rows = (cells + cols - 1) // cols
    width = _MARGIN + cols * (cell_w + _MARGIN)
    height = _TITLE_H + rows * (cell_h + _MARGIN)
    img = np.full((height, width, 3), _GREY, np.uint8)

    def origin(i: int) -> tuple[int, int]:
        return _MARGIN + (i % cols) * (cell_w + _MARGIN), _TITLE_H + (i // cols) * (
            cell_h + _MARGIN
        )

    caption_boxes: dict[str, tuple[int, int, int, int]] = {}

    def caption(name: str, text: str, x: int, y: int) -> None:
        baseline = y + _CAPTION_BASELINE
        (tw, th), base = cv2.getTextSize(text, _FONT, _CAPTION_SCALE, 1)
        cv2.putText(img, text, (x, baseline), _FONT, _CAPTION_SCALE, _WHITE, 1, cv2.LINE_AA)
        caption_boxes[name] = (x, baseline - th, x + tw, baseline + base)

    panels: dict[str, tuple[int, int, int, int]] = {}
    bars: dict[str, ColourBar] = {}
    captions = {"left": "left image"}
    x, y = origin(0)
    caption("left", "left image", x, y)
    img[y + caption_h : y + cell_h, x : x + pw] = cv2.resize(
        left, (pw, ph), interpolation=cv2.INTER_AREA
    )
    panels["left"] = (x, y + caption_h, pw, ph)
    for i, ((name, _, _, text, _, _, bar_unit), (values, rng, ticks)) in enumerate(
        zip(maps, placed, strict=True), start=1
    ):
        x, y = origin(i)
        caption(name, text, x, y)
        captions[name] = text
        coloured: npt.NDArray[Any] = np.zeros((h, w, 3), np.uint8)
        if rng is not None:
            coloured = cv2.applyColorMap(colour_levels(values, *rng), cv2.COLORMAP_TURBO)
            coloured[~np.isfinite(values)] = 0
        # nearest: every pixel keeps a colour of the map (a blend of two is on no bar)
        img[y + caption_h : y + cell_h, x : x + pw] = cv2.resize(
            coloured, (pw, ph), interpolation=cv2.INTER_NEAREST
        )
        panels[name] = (x, y + caption_h, pw, ph)
        if rng is None:
            continue
        bars[name] = _bar(img, x + pw + _BAR_GAP, y + caption_h, ph, ticks, bar_unit)
    font_scale = 0.6
    title = cv2_text(title)
    (tw, _), _ = cv2.getTextSize(title, _FONT, font_scale, 1)
    if tw > width - 2 * _MARGIN:
        font_scale *= (width - 2 * _MARGIN) / tw
        # cv2 rounds each glyph's advance to whole pixels: at a small scale the text is wider
        # than the ratio says (200 x's 401 px in 308) and ran out of the picture
        while (
            font_scale > 1e-3
            and cv2.getTextSize(title, _FONT, font_scale, 1)[0][0] > width - 2 * _MARGIN
        ):
            font_scale *= 0.95
    cv2.putText(img, title, (_MARGIN, 23), _FONT, font_scale, _WHITE, 1, cv2.LINE_AA)
    return Overview(
        image=img,
        title=title,
        panels=panels,
        bars=bars,
        scale=scale,
        captions=captions,
        caption_boxes=caption_boxes,
    )


def overview_title(name: str, result: Any) -> str:
    """``"NAME | METHOD | max_disparity N px | density D %"``, the overview's title."""
    md = result.max_disparity
    return (
        f"{name} | {result.method} | max_disparity {md:g} px | density {100 * result.density:.1f} %"
    )
