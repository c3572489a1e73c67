"""Sparse correspondences: the result type of the feature-based channels (``stereovision.match``).

Conventions (algorithms.md section 0): ``x`` = column, ``y`` = row, origin at the centre of the
top-left pixel; disparity ``dx = x_left - x_right`` (>= 0 for a standard rig), ``dy = y_left -
y_right`` (about 0 on rectified pairs), stored at the rounded left-image positions.
"""

from __future__ import annotations

import contextlib
import decimal
import math
import numbers
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    NOT_NUMBERS,
    _shown,
    as_path,
    refuse_beyond_float32,
    user_stacklevel,
)
from stereovision.calibration import Calibration
from stereovision.io import atomic_write

__all__ = ["Matches"]

F32 = npt.NDArray[np.float32]

_CSV_HEADER = "x_left,y_left,x_right,y_right,score"

#: The stats with one entry per match, which a selection picks with the matches.
_PER_MATCH_STATS = ("channel", "count", "sources")


def _per_match(value: object, n: int) -> bool:
    """Whether ``value`` is an array with one row per match (of ``n``)."""
    return isinstance(value, np.ndarray) and value.ndim >= 1 and value.shape[0] == n


def _f32_1d(a: npt.ArrayLike, name: str) -> F32:
    raw = np.asarray(a)
    # The float32 cast dropped a complex array's imaginary part with only NumPy's warning.
    if raw.dtype.kind not in "biuf":
        raise ValueError(f"{name}: expected real values, got dtype {raw.dtype}")
    # a finite 1e40 became inf with only NumPy's "overflow encountered in cast" (from_csv
    # refuses it in a file)
    refuse_beyond_float32(raw, name, "would be read as inf (the matches are float32)")
    # checked before the cast: ascontiguousarray makes a plain number (shape ()) one match
    if raw.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array, got shape {raw.shape}")
    return np.ascontiguousarray(raw, dtype=np.float32)


def _float32_text(values: F32) -> list[str]:
    """``str`` of each float32 (the shortest text that round-trips), computed once per distinct
    value: str of a NumPy float32 is slow (about 2 us), and a row index or an integer column
    repeats few values (save_csv of teddy's 130,614 Gabor matches: 1.2 s -> 0.7 s)."""
    # distinct bit patterns, not values: np.unique would make -0.0 and 0.0 one ("0.0")
    bits = np.ascontiguousarray(values, dtype=np.float32).view(np.uint32)
    uniq, inverse = np.unique(bits, return_inverse=True)
    text = np.array([str(v) for v in uniq.view(np.float32)], dtype=object)
    out: list[str] = text[inverse.reshape(-1)].tolist()
    return out


def _whole_positive(v: object) -> bool:
    """Whether ``v`` is a positive whole number: an integer (not a bool) or a finite whole
    float (``64.0``; not ``64.5``); never one of NOT_NUMBERS (3 ns was 3 pixels)."""
    if isinstance(v, NOT_NUMBERS):
        return False
    if isinstance(v, (int, np.integer)):
        return bool(v > 0)
    if isinstance(v, (float, np.floating)):
        return bool(math.isfinite(v) and v == math.floor(v) and v > 0)
    return False


@dataclass(frozen=True, eq=False)
class Matches:
    """Point correspondences between a left and a right image.

    Attributes
    ----------
    xl, yl : numpy.ndarray
        ``(N,)`` float32 left-image positions (px).
    xr, yr : numpy.ndarray
        ``(N,)`` float32 matched right-image positions (px; ``xr`` sub-pixel).
    score : numpy.ndarray
        ``(N,)`` float32, higher is better; what it measures depends on the matcher
        (:func:`stereovision.match`'s ``method``): ``"hopfield"`` and ``"best"`` the 7x7 ZNCC
        (in ``[-1, 1]``; from ``s_min``, 0.8, up), ``"mcgm"`` the GHT score of the matched segment
        pair (in ``[0, 1]``), ``"gabor"`` the channel's confidence (in ``[0, 1]``), ``"fused"``
        the share of the available channels that agree (2/3 or 1 with all three).
    image_shape : tuple of int
        ``(H, W)`` of the left image (size of :attr:`dispx` / :attr:`dispy`).
    energy_trace : numpy.ndarray
        ``(n_sweeps + 1,)`` float64 network energy: initial state, then after every sweep (empty
        for matchers without a network).
    stats : dict
        Counters of the run (points, neurons, weights, sweeps, converged, ...).
    """

    xl: F32
    yl: F32
    xr: F32
    yr: F32
    score: F32
    image_shape: tuple[int, int]
    energy_trace: npt.NDArray[np.float64] = field(
        default_factory=lambda: np.zeros(0, dtype=np.float64)
    )
    stats: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        names = ("xl", "yl", "xr", "yr", "score")
        arrs = [_f32_1d(getattr(self, n), n) for n in names]
        if len({a.shape for a in arrs}) != 1:
            raise ValueError(
                f"xl, yl, xr, yr, score must have one length, got {[len(a) for a in arrs]}"
            )
        for n, a in zip(names, arrs, strict=True):
            object.__setattr__(self, n, a)
        # int() of each entry read 64.5 as 64 and True as 1; None and (64,) were a TypeError
        # or an unpacking error naming nothing. A whole float (64.0) is a count, as elsewhere.
        shape = self.image_shape
        dims = tuple(shape) if isinstance(shape, (tuple, list, np.ndarray)) else ()
        ok = len(dims) == 2 and all(_whole_positive(v) for v in dims)
        if not ok:
            raise ValueError(f"image_shape must be positive (H, W) integers, got {shape!r}")
        h, w = int(dims[0]), int(dims[1])
        object.__setattr__(self, "image_shape", (h, w))
        # None is no trace and no stats: np.asarray(None, float) made a trace of one NaN
        # energy, and None as the stats an AttributeError at the first selection (m[:5])
        trace = np.asarray(np.zeros(0) if self.energy_trace is None else self.energy_trace)
        # Fractions or Decimals (a trace read back with parse_float=Decimal) are real values,
        # read as their floats as before 210655ad, whose dtype check refused them (object)
        if trace.dtype == object and all(
            isinstance(v, (numbers.Real, decimal.Decimal)) for v in trace.reshape(-1)
        ):
            # 10**400 (past a float) or Decimal('sNaN') was a bare OverflowError or "cannot
            # convert signaling NaN to float": refused below as before (dtype object)
            with contextlib.suppress(OverflowError, ValueError):
                trace = trace.astype(np.float64)
        # text was NumPy's "could not convert string to float", naming nothing
        if trace.dtype.kind not in "biuf":
            raise ValueError(f"energy_trace: expected real values, got dtype {trace.dtype}")
        object.__setattr__(self, "energy_trace", trace.astype(np.float64).reshape(-1))
        if self.stats is None:
            object.__setattr__(self, "stats", {})
        elif not isinstance(self.stats, dict):
            raise TypeError(
                f"stats: expected a dict of the run's counters, got {type(self.stats).__name__}"
            )

    def __len__(self) -> int:
        return int(self.xl.shape[0])

    if not TYPE_CHECKING:  # hidden from mypy, which refuses a Matches where an array is meant

        def __array__(self, dtype=None, copy=None):
            # a Matches is a sequence of one-match Matches: np.asarray(m) (triangulate(m, ...),
            # voxel_downsample(m)) nested them 64 deep, 36 s for tsukuba's 4,877 MCGM matches,
            # then "setting an array element with a sequence ... maximum number of dimension"
            raise TypeError(
                f"Matches ({len(self)} matches) is not an array: m.to_array() is the (N, 4) "
                "array [x, y, x', y'] (left then right position), m.xl, m.yl, m.xr, m.yr, "
                "m.score each column"
            )

    def __repr__(self) -> str:
        # A summary, not the five arrays (``to_array()`` gives the numbers).
        h, w = self.image_shape
        n = len(self)
        if n == 0:
            return f"Matches(0 matches in {w}x{h})"
        # over the finite values, the others counted: one NaN (a row another tool wrote as
        # "nan", read by from_csv) made the whole summary "disparity nan-nan px (median nan)"
        d = self.xl - self.xr
        d, s = d[np.isfinite(d)], self.score[np.isfinite(self.score)]
        disparity = (
            f"disparity {float(d.min()):.2f}-{float(d.max()):.2f} px (median "
            f"{float(np.median(d)):.2f})"
            if d.size
            else "no finite disparity"
        )
        score = f"score {float(s.min()):.3g}-{float(s.max()):.3g}" if s.size else "no finite score"
        if 0 < d.size < n:
            disparity += f", {n - d.size} not finite"
        if 0 < s.size < n:
            score += f", {n - s.size} not finite"
        return f"Matches({n} matches in {w}x{h}; {disparity}; {score})"

    def __getitem__(self, index: Any) -> Matches:
        """The matches picked by a slice, an integer array or a boolean mask, as ``Matches``
        (``m[m.score > 0.9]``); the image shape and stats are kept, the energy trace too, the
        per-match stats (``"mcgm"``'s ``channel``, ``"fused"``'s ``count`` and ``sources``)
        picked with the matches. The counters are the run's and stay as they were
        (``"fused"``'s ``members`` still counts the matches returned by the run, ``n_matches``
        likewise): ``len()`` of the selection is its own count. An integer gives that one
        match; beyond the matches it is an IndexError, as is a boolean scalar."""
        if isinstance(index, (bool, np.bool_)) or (
            isinstance(index, np.ndarray) and index.ndim == 0 and index.dtype == bool
        ):
            # a Python bool is an int (m[True] gave match 1) and NumPy reads a scalar bool as a
            # new axis (a 2-D pick): neither is a selection of matches; it is mostly a mask
            # reduced by mistake (m[m.score.max() > 0.5]), so it is refused
            raise IndexError(
                f"Matches: a boolean scalar ({bool(index)}) is not an index; give an integer, "
                "a slice, an integer array or a boolean mask with one value per match"
            )
        if isinstance(index, np.ndarray) and index.ndim == 0 and index.dtype.kind in "iu":
            index = int(index)  # a 0-d integer array (an argmax kept as an array) is an integer
        if isinstance(index, (int, np.integer)):
            # As a slice an index beyond the end was an empty Matches, so iterating (by index
            # until IndexError) never ended.
            i, n = int(index), len(self)
            if not -n <= i < n:
                raise IndexError(f"Matches: index {i} is out of range for {n} matches")
            index = slice(i, i + 1 or None)
        mask = np.asarray(index) if isinstance(index, (list, np.ndarray)) else None
        if mask is not None and mask.dtype == bool and mask.ndim == 1 and len(mask) != len(self):
            # a mask of other matches (m[other.score > 0.9]) was NumPy's "boolean index did not
            # match indexed array along axis 0", naming no Matches
            raise IndexError(
                f"Matches: a boolean mask of {len(mask)} values for {len(self)} matches; give "
                "one value per match (m[m.score > 0.9])"
            )
        kind = mask.dtype.kind if mask is not None and mask.size else "i"
        if isinstance(index, (float, np.floating, str, bytes)) or kind not in "biu":
            # NumPy's "only integers, slices (`:`), ellipsis (`...`), numpy.newaxis (`None`)
            # ..." (m[1.5], m["score"]) or "arrays used as indices must be of integer (or
            # boolean) type" (m[np.round(x)]) named no Matches, and offered a new axis
            raise IndexError(
                "Matches: expected an integer, a slice, an integer array or a boolean mask "
                f"with one value per match, got {_shown(index)}"
            )
        pick = np.asarray(np.arange(len(self))[index])
        if pick.ndim != 1:
            raise IndexError(f"Matches: expected a 1-D index or mask, got shape {pick.shape}")
        return Matches(
            self.xl[pick],
            self.yl[pick],
            self.xr[pick],
            self.yr[pick],
            self.score[pick],
            self.image_shape,
            self.energy_trace,
            # one entry per match: kept whole, m[m.score > 0.5].stats["channel"] named the
            # sigmas of the first matches, not of those picked
            {
                k: v[pick] if k in _PER_MATCH_STATS and _per_match(v, len(self)) else v
                for k, v in self.stats.items()
            },
        )

    def to_points(self, calib: Calibration, unit: str = "m") -> npt.NDArray[np.float32]:
        """``(N, 3)`` float32 points of the matches, in the left rectified camera frame (X right,
        Y down, Z forward), metres unless ``unit`` says otherwise.

        The matches are in the rectified pair's pixels (what :func:`stereovision.match` gives,
        with or without a calibration); ``calib`` is the pair's calibration (a raw rig's
        rectified geometry is used). ``Z = f B / (x_l - x_r + doffs)``, ``doffs = cx_right -
        cx_left`` (:attr:`~stereovision.Calibration.doffs_px`): a match whose ``x_l - x_r +
        doffs`` is not positive gives NaN, not one whose disparity is not positive. With
        ``doffs > 0`` (Middlebury's rigs) a disparity down to ``-doffs`` still gives a point;
        with ``doffs < 0`` a positive disparity up to ``-doffs`` gives NaN; with ``doffs = 0``
        (OpenCV's rectification) the two read the same.

        Parameters
        ----------
        calib : Calibration
            The pair's calibration (rectified or raw).
        unit : str
            Output unit, metres by default (as :func:`stereovision.depth_from_disparity`).

        Returns
        -------
        numpy.ndarray
            ``(N, 3)`` float32, NaN rows where ``x_l - x_r + doffs <= 0``.

        Examples
        --------
        Disparities -10, 0 and 5 px with ``doffs = 50`` (``f B`` = 10 m px): three points;
        disparities 3 and 10 px with ``doffs = -5``: the first is NaN.

        >>> import numpy as np, stereovision as sv
        >>> K1 = np.array([[100.0, 0, 80], [0, 100, 60], [0, 0, 1]])
        >>> def rig(doffs):
        ...     K2 = K1 + [[0, 0, doffs], [0, 0, 0], [0, 0, 0]]
        ...     return sv.Calibration(K1=K1, D1=np.zeros(5), K2=K2, D2=np.zeros(5), R=np.eye(3),
        ...                           T=np.array([-0.1, 0, 0]), image_size=(160, 120),
        ...                           rectified=True)
        >>> def at_centre(d):
        ...     n = len(d)
        ...     return sv.Matches(xl=[80.0] * n, yl=[60.0] * n, xr=80.0 - np.array(d),
        ...                       yr=[60.0] * n, score=[1.0] * n, image_shape=(120, 160))
        >>> at_centre([-10, 0, 5]).to_points(rig(50))[:, 2].astype(float).round(4).tolist()
        [0.25, 0.2, 0.1818]
        >>> at_centre([3, 10]).to_points(rig(-5))[:, 2].tolist()
        [nan, 2.0]

        Raises
        ------
        TypeError
            If ``calib`` is not a :class:`~stereovision.Calibration`.
        ValueError
            An unknown ``unit``.

        Warns
        -----
        UserWarning
            When ``image_shape`` is the calibration's image size scaled by one factor (matches
            of a resized pair: their depths would be off by that factor, use
            :meth:`Calibration.scaled_to`), as :func:`stereovision.depth_from_disparity`.
        """
        from stereovision._validate import require
        from stereovision.triangulation import _warn_if_resized, depth_from_disparity

        require(calib, "Calibration", "calib")
        # matches of a resized pair read with the full-size calibration were off by the factor
        # without a word (half-size matches, 2 x the depths), which depth_from_disparity warns of
        _warn_if_resized(self.image_shape, calib, 2)
        cal = calib if calib.rectified else calib.rectified_calibration()
        z = depth_from_disparity((self.xl - self.xr)[None, :], cal, unit)[0].astype(np.float64)
        k = cal.K1
        out = np.empty((len(self), 3), np.float32)
        out[:, 0] = (self.xl - k[0, 2]) * z / k[0, 0]
        out[:, 1] = (self.yl - k[1, 2]) * z / k[1, 1]
        out[:, 2] = z
        return out

    def _raster(self, values: F32) -> F32:
        h, w = self.image_shape
        out = np.full((h, w), np.nan, dtype=np.float32)
        # Bounds on the rounded floats: NaN compares False (cast first, a NaN, inf or 1e30
        # position was NumPy's 'invalid value encountered in cast' warning).
        rx, ry = np.rint(self.xl), np.rint(self.yl)
        ok = (rx >= 0) & (rx < w) & (ry >= 0) & (ry < h)
        xi = np.where(ok, rx, 0).astype(np.int64)
        yi = np.where(ok, ry, 0).astype(np.int64)
        # Two matches can round to one pixel (MCGM: 15 of 5086 on tsukuba): the better-scored
        # one is written last, so it is the one kept. A NaN score (a CSV row's "nan") ranks
        # lowest: argsort puts NaN last, so such a match hid a scored one at its pixel, and
        # NaN read as -inf tied with a -inf score, which a later NaN hid. NaN first, then the
        # score (a stable sort: the later one wins a tie, as before).
        nan = np.isnan(self.score)
        order = np.lexsort((np.where(nan, 0, self.score), ~nan))
        order = order[ok[order]]
        out[yi[order], xi[order]] = values[order]
        return out

    @property
    def dispx(self) -> F32:
        """``(H, W)`` float32 ``x_left - x_right`` at the matched left pixels (rounded), NaN
        elsewhere; where two matches round to one pixel, the higher score's (the later one's on
        a tie; a NaN score is the lowest)."""
        return self._raster(self.xl - self.xr)

    @property
    def dispy(self) -> F32:
        """``(H, W)`` float32 ``y_left - y_right`` at the matched left pixels (rounded), NaN
        elsewhere; about 0 on a rectified pair (positive: the right point lies higher in its
        image); one match per pixel as :attr:`dispx`."""
        return self._raster(self.yl - self.yr)

    def to_array(self) -> F32:
        """The matches as one array, the paper's list.

        Returns
        -------
        ndarray
            float32 ``(N, 4)``, ``[x, y, x', y']`` (left then right position) per match.
        """
        return np.stack([self.xl, self.yl, self.xr, self.yr], axis=1).astype(np.float32)

    def save_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write ``x_left,y_left,x_right,y_right,score`` rows (header first), atomically.

        Every value is written as the shortest decimal that reads back as the same float32
        (``133.20274``, ``248.0``, ``0.9``): :meth:`from_csv` gives back the same arrays, bit for
        bit (4 decimals had lost up to 5e-5 px).

        Parameters
        ----------
        path : str or os.PathLike
            Destination; its directory must exist. The file is replaced only once fully written.

        Returns
        -------
        pathlib.Path
            ``path`` (as the other writers return it).
        """
        cols = [_float32_text(c) for c in (self.xl, self.yl, self.xr, self.yr, self.score)]
        with atomic_write(path, "w") as fh:
            fh.write(_CSV_HEADER + "\n")
            fh.writelines(f"{a},{b},{c},{d},{e}\n" for a, b, c, d, e in zip(*cols, strict=True))
        return Path(path)

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str], image_shape: tuple[int, int]) -> Matches:
        """Read a file :meth:`save_csv` wrote (also after a spreadsheet saved it with a BOM).

        Parameters
        ----------
        path : str or os.PathLike
            A CSV with the header ``x_left,y_left,x_right,y_right,score``, or a named pipe
            streaming one (a shell's ``<(...)``).
        image_shape : tuple of int
            ``(H, W)`` of the left image (the file does not hold it; :attr:`dispx` needs it).

        Returns
        -------
        Matches
            The positions and scores (no energy trace or stats).

        Raises
        ------
        FileNotFoundError
            If ``path`` does not exist.
        ValueError
            If ``path`` is a folder (or another file that is neither regular nor a pipe) or
            not UTF-8 text (an image given by mistake), another header, a row without five
            numbers or with a finite number beyond float32's range, naming the file (and the
            row's line), or an ``image_shape`` evidently given as ``(W, H)``: some matches' left
            positions lie outside it and all fit ``(W, H)``.

        Warns
        -----
        UserWarning
            If some matches' left positions lie outside ``image_shape`` otherwise (the count
            and the largest position): they are kept in the arrays and left out of
            :attr:`dispx` and :attr:`dispy`.
        """
        from stereovision.io import _existing_file

        # a folder was IsADirectoryError, and a binary file (a PNG given by mistake) a
        # UnicodeDecodeError naming no file: "'utf-8' codec can't decode byte 0x89 ...". A
        # pipe (a shell's <(...), /dev/stdin) is no regular file but is read as one.
        as_path(path)
        if not Path(path).is_fifo():
            _existing_file(path, "matches CSV file")
        # utf-8-sig: a file saved again by a spreadsheet (Excel) starts with a BOM, which made
        # the header "another header"
        try:
            with open(path, encoding="utf-8-sig") as fh:
                head = fh.readline().strip()
                if head != _CSV_HEADER:
                    raise ValueError(f"{path}: expected the header {_CSV_HEADER!r}, got {head!r}")
                # (line number, text) of the non-blank rows, for the messages; split at "\n"
                # only (text mode has made "\r\n" and "\r" one): splitlines also split at a
                # form feed or U+2028 within a row, and every line after it was named one on
                lines = [(k, ln) for k, ln in enumerate(fh.read().split("\n"), 2) if ln.strip()]
        except UnicodeDecodeError as exc:
            raise ValueError(
                f"{path}: not a CSV text file (a byte 0x{exc.object[exc.start]:02x} is not "
                f"UTF-8 text); expected the header {_CSV_HEADER!r}"
            ) from None
        # a row's values are its text between commas: its count of commas says how many
        short = next((k for k, (_, ln) in enumerate(lines) if ln.count(",") != 4), None)
        if short is not None:
            line, text = lines[short]
            raise ValueError(f"{path}: line {line} has {text.count(',') + 1} values, expected 5")
        # one float() per value over the rows joined, the same floats in half the time of a
        # list per row (270,000 rows: 3.5 -> 2.1 s on a loaded host); a value float() refuses
        # is found again row by row, to name its line.
        a = np.zeros((0, 5))
        try:
            if lines:  # "".split(",") is one empty value, not none
                a = np.array(list(map(float, ",".join(ln for _, ln in lines).split(","))))
        except ValueError:
            for line, text in lines:
                try:
                    [float(v) for v in text.split(",")]
                except ValueError as e:
                    # the line too, as for a short row ("could not convert string to float:
                    # ''" named no line of a file of thousands)
                    raise ValueError(f"{path}: line {line}: {e}") from None
            raise
        a = a.reshape(len(lines), -1) if lines else a
        if a.ndim != 2 or a.shape[1] != 5:
            raise ValueError(f"{path}: expected 5 numbers per row")
        # the float32 cast made a finite 1e40 an inf with only NumPy's RuntimeWarning
        with np.errstate(over="ignore"):
            a32 = a.astype(np.float32)
        big = np.isinf(a32) & np.isfinite(a)
        if big.any():
            row, col = (int(i[0]) for i in np.nonzero(big))
            raise ValueError(
                f"{path}: line {lines[row][0]}: {lines[row][1].split(',')[col].strip()} is beyond "
                "float32's range (the matches are float32: it would be read as inf)"
            )
        xl, yl, xr, yr, score = (a32[:, i] for i in range(5))
        m = cls(xl=xl, yl=yl, xr=xr, yr=yr, score=score, image_shape=image_shape)
        # The file does not hold the shape: one given as (W, H), as cv2 and image_size give it,
        # left every match past the height out of dispx/dispy without a word (tsukuba's MCGM
        # matches with (384, 288): 732 of 5,086 dropped). A position is where _raster puts it.
        h, w = m.image_shape
        rx, ry = np.rint(m.xl), np.rint(m.yl)
        with np.errstate(invalid="ignore"):
            # NaN is no position; an infinite one (a row's "inf") lies outside, as 1e30 does
            fin = ~np.isnan(rx) & ~np.isnan(ry)
            out = fin & ((rx < 0) | (rx >= w) | (ry < 0) | (ry >= h))
        if out.any():
            said = (
                f"{path}: {int(out.sum())} of the {len(m)} matches lie outside image_shape "
                f"{(h, w)} (left positions up to x {float(np.nanmax(m.xl[out])):g}, y "
                f"{float(np.nanmax(m.yl[out])):g})"
            )
            # Refused only when the shape is evidently swapped: every match fits (W, H) (all
            # of them, not only those outside: (80, 30) and (30, 80) each suggested the other).
            # A stray point of another tool's file (x -0.6) refused the whole file: it is read,
            # the point kept in the arrays and left out of dispx/dispy, as _raster does.
            if not np.any(fin & ((rx < 0) | (rx >= h) | (ry < 0) | (ry >= w))):
                raise ValueError(f"{said}; image_shape is the left image's (H, W): ({w}, {h})?")
            import warnings

            warnings.warn(
                f"{said}: kept in the arrays, left out of dispx and dispy",
                UserWarning,
                stacklevel=user_stacklevel(),
            )
        return m
