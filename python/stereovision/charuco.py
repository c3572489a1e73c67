"""ChArUco calibration boards: description, detection, synthetic views and printable images.

A ChArUco board is a chessboard whose white squares carry ArUco markers. Each inner corner has an
id, so a board seen only in part (cut by the image edge, hidden by a hand, too oblique at one
end) still gives corners whose board position is known. That is what a lens needs most: corners
near the image border, where the distortion is largest and where a whole chessboard rarely fits.
:func:`stereovision.calibrate.calibrate` takes ``board=CharucoBoard(...)`` and then uses, for each
pair, the corners seen by both cameras.

Conventions (OpenCV's ``cv2.aruco.CharucoBoard``):

- ``squares = (cols, rows)`` counts squares, not inner corners; the board has ``(cols - 1) x
  (rows - 1)`` inner corners and ``cols * rows // 2`` markers.
- Corner ``id`` sits at ``((id % (cols - 1) + 1) s, (id // (cols - 1) + 1) s, 0)`` with ``s``
  the square side: the origin is the board's top-left outer corner.
- OpenCV 4.6 changed the layout of boards with an even number of rows (``legacy`` is the old
  one). Boards printed from older generators (and calib.io's, by their docs) may need
  ``legacy=True``; ``legacy=None`` tries both on the first board found and keeps the one that
  gives more corners (a board cut on one side can give both as many, the wrong one every id a
  square off: then the one whose black squares the image shows black).
"""

from __future__ import annotations

import math
import struct
import sys
import warnings
import zlib
from dataclasses import dataclass, replace
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import int_in_range, real_number
from stereovision.synthetic import _REMAP_MAX_SIDE, render_plane

__all__ = [
    "DICTIONARY_FAMILIES",
    "MIN_CORNERS",
    "CharucoBoard",
    "board_png",
    "corners_span_plane",
    "dictionary_name",
    "find_charuco_corners",
    "render_charuco",
]

F64 = npt.NDArray[np.float64]

#: Fewest corners seen in both images for a pair to be used: a plane's homography needs four in
#: general position; six leave two for the distortion and keep views whose corners crowd one
#: corner of the board from dominating the intrinsics.
MIN_CORNERS = 6

#: Dictionary families ``dictionary="auto"`` tries, each as its OpenCV names and sizes, smallest
#: first (within a family the smaller dictionaries are prefixes of the larger ones).
DICTIONARY_FAMILIES: dict[str, tuple[tuple[str, int], ...]] = {
    **{
        fam: tuple((f"DICT_{fam}_{n}", n) for n in (50, 100, 250, 1000))
        for fam in ("4X4", "5X5", "6X6", "7X7")
    },
    "ARUCO_ORIGINAL": (("DICT_ARUCO_ORIGINAL", 1024),),
    "APRILTAG_16H5": (("DICT_APRILTAG_16H5", 30),),
    "APRILTAG_25H9": (("DICT_APRILTAG_25H9", 35),),
    "APRILTAG_36H10": (("DICT_APRILTAG_36H10", 2320),),
    "APRILTAG_36H11": (("DICT_APRILTAG_36H11", 587),),
    "ARUCO_MIP_36H12": (("DICT_ARUCO_MIP_36H12", 250),),
}
#: Fewest markers of the board that must be decoded to settle the dictionary.
AUTO_MIN_MARKERS = 2


#: Largest board image (pixels) :meth:`CharucoBoard.image` and :func:`board_png` make: a 1 m board
#: at 600 dpi is 5.6e8 px; 2.5e8 (250 MB of grey) covers A0 at 300 dpi with room to spare.
MAX_IMAGE_PIXELS = 250_000_000


def dictionary_name(name: str | int) -> str:
    """Canonical OpenCV name of a predefined ArUco dictionary.

    Parameters
    ----------
    name : str or int
        ``"DICT_5X5_100"``, ``"5x5_100"``, ``"apriltag_36h11"`` ..., or OpenCV's constant
        (``cv2.aruco.DICT_5X5_100``).

    Returns
    -------
    str
        The ``cv2.aruco`` attribute name, e.g. ``"DICT_5X5_100"``.

    Raises
    ------
    ValueError
        If no predefined dictionary has that name.
    """
    if isinstance(name, (int, np.integer)) and not isinstance(name, (bool, np.timedelta64)):
        # OpenCV's constant, as its samples pass it: cv2.aruco.DICT_5X5_100 (5) was "unknown
        # ArUco dictionary 5"
        for members in DICTIONARY_FAMILIES.values():
            for known_name, _ in members:
                if getattr(cv2.aruco, known_name) == name:
                    return known_name
    key = str(name).strip().upper()
    if not key.startswith("DICT_"):
        key = "DICT_" + key
    if hasattr(cv2.aruco, key) and key.startswith("DICT_"):
        return key
    known = ", ".join(n[5:] for members in DICTIONARY_FAMILIES.values() for n, _ in members)
    raise ValueError(f"dictionary: unknown ArUco dictionary {name!r}; expected one of {known}")


def _dictionary(name: str) -> Any:
    return cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, name))


def _require_board(board: object, name: str = "board") -> None:
    """A TypeError naming ``board`` (as the parameter ``name``) when it is no
    :class:`CharucoBoard` (calibrate's words): a pattern string or None failed deep inside,
    AttributeError "'str' object has no attribute 'resolved'"."""
    if not isinstance(board, CharucoBoard):
        raise TypeError(
            f"{name}: expected a stereovision.charuco.CharucoBoard, got {type(board).__name__}"
        )


#: CharucoBoard's parameters as the command line's options give them (the squares: a
#: command's own option, board/calibrate --pattern, capture --charuco).
_OPTION_OF = {
    "square_size": "--square",
    "marker_size": "--marker",
    "dictionary": "--dictionary",
    "legacy": "--legacy",
}


def board_error_words(exc: ValueError, squares_option: str, context: str) -> str:
    """A :class:`CharucoBoard` refusal in the command line's words: the parameter it names
    (``marker_size: 0.05 must be smaller than square_size 0.03``) said as the option that gave
    it (``--marker: 0.05 must be smaller than --square 0.03``); any other text after
    ``context`` (the option that asked for the board)."""
    names = {**_OPTION_OF, "squares": squares_option}
    head, sep, rest = str(exc).partition(": ")
    if not sep or head not in names:
        return f"{context}: {exc}"
    return f"{names[head]}: {rest.replace('than square_size ', 'than --square ')}"


@dataclass(frozen=True)
class CharucoBoard:
    """A ChArUco board's geometry and marker dictionary.

    Parameters
    ----------
    squares : tuple of int or str
        ``(cols, rows)`` squares, or ``"7x5"``; each at least 3, and at least
        :data:`MIN_CORNERS` inner corners (not 3x3).
    square_size : float
        Side of a square, in the calibration's unit.
    marker_size : float
        Side of a marker, same unit, smaller than ``square_size``. A marker whose white border
        is under 70 % of one of its cells (0.028 in 0.03 squares) is warned of when the board
        is first used: OpenCV places its corners less well.
    dictionary : str or int
        A predefined ArUco dictionary (``"DICT_5X5_100"``, ``"5X5_100"``, ...; or OpenCV's
        constant, ``cv2.aruco.DICT_5X5_100``, kept as its name), or ``"auto"``:
        found from the first image that shows the board (the family that decodes most of the
        board's marker ids).
    legacy : bool or None
        OpenCV's pre-4.6 layout for boards with an even number of rows; None: decided from the
        first board found (it matters only for an even number of rows).

    Raises
    ------
    ValueError
        If a size is not positive and finite, the marker does not fit in a square, there are too
        few squares (or inner corners), the dictionary is unknown or too small for the board's
        markers, or ``legacy`` is not True, False (0, 1) or None.
    """

    squares: tuple[int, int]
    square_size: float
    marker_size: float
    dictionary: str = "auto"
    legacy: bool | None = None

    def __post_init__(self) -> None:
        from stereovision._validate import positive_finite
        from stereovision.calibrate import parse_pattern

        sq = self.squares
        try:  # the chessboard's "COLSxROWS" parser; a ChArUco board counts squares, >= 3 each
            vals = list(parse_pattern(sq))
        except (TypeError, ValueError):
            vals = []
        if len(vals) != 2 or min(vals) < 3:
            raise ValueError(
                f"squares: expected a ChArUco board's squares as COLSxROWS, each at least 3 "
                f"(e.g. 7x5), got {sq!r}"
            )
        corners = (vals[0] - 1) * (vals[1] - 1)
        if corners < MIN_CORNERS:
            # a 3x3 board's 4 corners are never a view (find_charuco_corners wants MIN_CORNERS):
            # `board` printed it and calibrate found it in none of the images
            raise ValueError(
                f"squares: a {vals[0]}x{vals[1]} board has {corners} inner corners, and a view "
                f"of it needs at least {MIN_CORNERS} (e.g. 4x3 squares)"
            )
        object.__setattr__(self, "squares", (vals[0], vals[1]))
        largest = max(n for members in DICTIONARY_FAMILIES.values() for _, n in members)
        if self.n_markers > largest:
            raise ValueError(
                f"squares: a {vals[0]}x{vals[1]} board has {self.n_markers} markers; no predefined "
                f"dictionary holds more than {largest}"
            )
        s = positive_finite(self.square_size, "square_size")
        m = positive_finite(self.marker_size, "marker_size")
        if m >= s:
            raise ValueError(
                f"marker_size: {m:g} must be smaller than square_size {s:g} (the marker sits "
                "inside a white square)"
            )
        object.__setattr__(self, "square_size", s)
        object.__setattr__(self, "marker_size", m)
        if isinstance(self.dictionary, str) and self.dictionary.strip().lower() == "auto":
            # as the names: "5x5_100" is DICT_5X5_100, and "AUTO" was an unknown dictionary
            object.__setattr__(self, "dictionary", "auto")
        if self.dictionary != "auto":
            name = dictionary_name(self.dictionary)
            size = int(_dictionary(name).bytesList.shape[0])
            if size < self.n_markers:
                raise ValueError(
                    f"dictionary: {name} has {size} markers, but a {vals[0]}x{vals[1]} board "
                    f"needs {self.n_markers}"
                )
            object.__setattr__(self, "dictionary", name)
        if self.legacy is not None:
            # a switch: bool("no") and bool("false") were True, the pre-4.6 layout, and 0.5
            # True as well; True/False, NumPy's bools and the integers 0 and 1 are one
            v = self.legacy
            flag = isinstance(v, (bool, np.bool_)) or (
                isinstance(v, (int, np.integer))
                and not isinstance(v, np.timedelta64)
                and v in (0, 1)
            )
            if not flag:
                raise ValueError(f"legacy: expected True, False or None, got {v!r}")
            object.__setattr__(self, "legacy", bool(v))

    # ---------------------------------------------------------------------------- geometry

    @property
    def inner(self) -> tuple[int, int]:
        """Inner corners ``(cols - 1, rows - 1)``: the chessboard pattern of the board."""
        return self.squares[0] - 1, self.squares[1] - 1

    @property
    def n_corners(self) -> int:
        """Number of inner corners (ids ``0 .. n_corners - 1``)."""
        c, r = self.inner
        return c * r

    @property
    def n_markers(self) -> int:
        """Number of markers (ids ``0 .. n_markers - 1``)."""
        return self.squares[0] * self.squares[1] // 2

    def object_points(self, ids: npt.ArrayLike | None = None) -> npt.NDArray[np.float32]:
        """Board coordinates of corners (``Z = 0``), in the order of ``ids`` (default: all).

        Parameters
        ----------
        ids : array_like of int, optional
            Inner-corner ids, ``0 .. n_corners - 1`` (as :func:`find_charuco_corners` gives
            them); default: every corner in id order.

        Returns
        -------
        numpy.ndarray
            ``(N, 3)`` ``float32``.

        Raises
        ------
        ValueError
            If an id is not a whole number or lies outside ``0 .. n_corners - 1``.
        """
        cols = self.inner[0]
        if ids is None:
            i = np.arange(self.n_corners)
        else:
            raw = np.asarray(ids)
            # the cast truncated 1.7 to corner 1, and an id past the board (or negative) gave a
            # point off it (id 24 of a 7x5 board's 24 corners: on a fifth row of its four)
            whole = raw.dtype.kind in "iu" or (
                raw.dtype.kind == "f" and bool(np.all(np.isfinite(raw) & (raw == np.round(raw))))
            )
            if not whole:
                # on one line: NumPy's repr wrapped eight ids such as 0.12345679 over two
                flat = raw.ravel()
                shown = np.array2string(flat[:8], separator=", ", max_line_width=sys.maxsize)
                more = ", ...]" if flat.size > 8 else "]"
                raise ValueError(f"ids: expected whole corner ids, got {shown[:-1]}{more}")
            if raw.size and not 0 <= raw.min() <= raw.max() < self.n_corners:
                raise ValueError(
                    f"ids: expected corner ids from 0 to {self.n_corners - 1} (a "
                    f"{self.squares[0]}x{self.squares[1]} board), got {raw.min():g} to "
                    f"{raw.max():g}"
                )
            i = raw.astype(np.int64).ravel()
        out = np.zeros((i.size, 3), np.float32)
        out[:, 0] = ((i % cols) + 1) * self.square_size
        out[:, 1] = ((i // cols) + 1) * self.square_size
        return out

    @property
    def resolved(self) -> bool:
        """True once the dictionary and (for an even number of rows) the layout are known."""
        return self.dictionary != "auto" and (self.legacy is not None or self.squares[1] % 2 == 1)

    def describe(self, unit: str = "") -> str:
        """The board in one line: squares, inner corners, sizes, dictionary and layout.

        Parameters
        ----------
        unit : str
            Unit written after the sizes (``"m"``, ``"mm"``; default none).

        Returns
        -------
        str
            E.g. ``ChArUco 7x5 squares (6x4 inner corners), square 0.04 m, marker 0.03 m,
            DICT_5X5_100``.
        """
        u = f" {unit}" if unit else ""
        c, r = self.inner
        # OpenCV's two layouts differ only with an even number of rows: an odd-rowed board
        # printed with legacy=True is the same board, not a "legacy layout" to look for
        layout = " (legacy layout)" if self.legacy and self.squares[1] % 2 == 0 else ""
        return (
            f"ChArUco {self.squares[0]}x{self.squares[1]} squares ({c}x{r} inner corners), "
            f"square {self.square_size:g}{u}, marker {self.marker_size:g}{u}, "
            f"{self.dictionary}{layout}"
        )

    def cv_board(self) -> Any:
        """The board as OpenCV's object.

        Returns
        -------
        cv2.aruco.CharucoBoard
            With this board's squares, sizes, dictionary and layout.

        Raises
        ------
        ValueError
            If the dictionary is not known yet (``dictionary="auto"``: :meth:`resolve` first).
        """
        if self.dictionary == "auto":
            # said what to do: image() and render_charuco of CharucoBoard("10x7", 0.03, 0.022),
            # the README's board (its default dictionary "auto"), stopped at this bare line
            raise ValueError(
                "the board's dictionary is not known yet (dictionary='auto'): give one (e.g. "
                "dictionary='DICT_5X5_100' for a board to print), or resolve() the board on an "
                "image of it"
            )
        return _cv_board(
            self.squares, self.square_size, self.marker_size, self.dictionary, bool(self.legacy)
        )

    # ---------------------------------------------------------------------------- images

    def image(self, pixels_per_square: int = 100, margin: int | None = None) -> np.ndarray:
        """The board as a black-and-white image, for printing or rendering.

        Parameters
        ----------
        pixels_per_square : int
            Side of a square in pixels.
        margin : int, optional
            White border in pixels (default: one square).

        Returns
        -------
        numpy.ndarray
            ``uint8`` ``(rows * p + 2 margin, cols * p + 2 margin)``.
        """
        p = int_in_range(pixels_per_square, "pixels_per_square", 10, 20000)
        mg = p if margin is None else int_in_range(margin, "margin", 0, 10 * p)
        cols, rows = self.squares
        size = (cols * p + 2 * mg, rows * p + 2 * mg)
        if size[0] * size[1] > MAX_IMAGE_PIXELS:
            raise ValueError(
                f"pixels_per_square: a {size[0]}x{size[1]} image is over "
                f"{MAX_IMAGE_PIXELS:.2g} pixels; use fewer pixels per square"
            )
        cv_board = self.cv_board()
        need = int(cv_board.getDictionary().markerSize) + 2  # the bits and a black border
        marker_px = p * self.marker_size / self.square_size
        if marker_px < need:  # OpenCV failed an assertion here
            raise ValueError(
                f"marker_size: a {self.marker_size:g} marker in a {self.square_size:g} square is "
                f"{marker_px:.2g} px at {p} px per square; {self.dictionary}'s markers need at "
                f"least {need} px: use a larger marker or more pixels per square"
            )
        try:
            return np.asarray(cv_board.generateImage(size, marginSize=mg, borderBits=1))
        except cv2.error:
            # OpenCV's generateImage fails its own assertion on the ROI of a marker of some
            # sizes (21.6 px in 27 px squares; 35 of 1820 whole-mm boards at 72-300 dpi,
            # `board` said "internal error"): drawn here then, the same layout
            return _drawn_board(cv_board, self.squares, p, mg, round(marker_px))

    def markers_seen(self, image: npt.ArrayLike) -> tuple[str, int]:
        """The dictionary family that decodes most of this board's marker ids in an image.

        Parameters
        ----------
        image : array_like
            Grey or BGR image (a dark one of more than 8 bits stretched by its own range, as
            :func:`find_charuco_corners` reads it).

        Returns
        -------
        str, int
            The family's smallest dictionary that holds the board's markers (``""`` if none
            decodes any) and how many markers with the board's ids it decodes.
        """
        from stereovision.calibrate import _board_gray

        gray = _board_gray(image, "image")  # a dark 12-bit image at its own range (c59fa44)
        best, best_count = "", 0
        for members in DICTIONARY_FAMILIES.values():
            fitting = [name for name, size in members if size >= self.n_markers]
            if not fitting:
                continue
            name = fitting[0]
            det = cv2.aruco.ArucoDetector(_dictionary(name))
            _, ids, _ = det.detectMarkers(gray)
            n = 0 if ids is None else int(np.count_nonzero(ids.ravel() < self.n_markers))
            if n > best_count:
                best, best_count = name, n
        return best, best_count

    def resolve(self, image: npt.ArrayLike) -> CharucoBoard | None:
        """The board with its dictionary and layout found from one image (None if not seen).

        Parameters
        ----------
        image : array_like
            Grey or BGR image showing the board (a dark one of more than 8 bits stretched by
            its own range, as :func:`find_charuco_corners` reads it).

        Returns
        -------
        CharucoBoard or None
            A copy with ``dictionary`` and ``legacy`` decided (``self`` itself when both were
            known), or None if the image shows too few markers or corners to decide.
        """
        from stereovision.calibrate import _board_gray

        gray = _board_gray(image, "image")  # a dark 12-bit image at its own range (c59fa44)
        board = self
        if board.dictionary == "auto":
            best, best_count = self.markers_seen(gray)
            if best_count < AUTO_MIN_MARKERS:
                return None
            board = replace(board, dictionary=best)
        if board.legacy is None:
            if board.squares[1] % 2 == 1:
                return replace(board, legacy=False)
            counts, misplaced = [], []
            for legacy in (False, True):
                trial = replace(board, legacy=legacy)
                found = find_charuco_corners(gray, trial)
                counts.append(0 if found is None else len(found[0]))
                misplaced.append(
                    None if found is None else _white_black_squares(gray, trial, *found)
                )
            if max(counts) == 0:
                return None
            # A view of part of the board (its last column cut off) fits both layouts with as
            # many corners, the wrong one with every id a square off (55 px on a 7X7 11x8 board
            # at 0.45 m): that one's board reaches past the edge seen, its black squares on the
            # white margin. The corner count decides when that does not tell them apart.
            a, b = misplaced
            if a is not None and b is not None and min(a, b) == 0 and max(a, b) >= 2:
                board = replace(board, legacy=b == 0)
            else:
                board = replace(board, legacy=counts[1] > counts[0])
        return board


def _drawn_board(
    cv_board: Any, squares: tuple[int, int], p: int, margin: int, marker_px: int
) -> npt.NDArray[np.uint8]:
    """The board's image as ``generateImage`` draws it: black squares, and in each white square
    its marker (``marker_px`` px, one black border bit) centred, upright, with the board's ids
    and positions (``getObjPoints``, so the layout, legacy or not, is OpenCV's)."""
    cols, rows = squares
    img = np.full((rows * p + 2 * margin, cols * p + 2 * margin), 255, np.uint8)
    side = float(cv_board.getSquareLength())
    dictionary = cv_board.getDictionary()
    white = {}
    for quad, marker_id in zip(cv_board.getObjPoints(), np.ravel(cv_board.getIds()), strict=True):
        cx, cy = np.asarray(quad, np.float64).reshape(-1, 3)[:, :2].mean(axis=0)
        white[(math.floor(cx / side), math.floor(cy / side))] = int(marker_id)
    off = (p - marker_px) // 2
    for r in range(rows):
        for c in range(cols):
            y0, x0 = margin + r * p, margin + c * p
            if (c, r) not in white:
                img[y0 : y0 + p, x0 : x0 + p] = 0
                continue
            marker = cv2.aruco.generateImageMarker(dictionary, white[(c, r)], marker_px, None, 1)
            img[y0 + off : y0 + off + marker_px, x0 + off : x0 + off + marker_px] = marker
    return img


def _white_black_squares(
    gray: npt.NDArray[np.uint8], board: CharucoBoard, ids: npt.NDArray[np.int64], pts: F64
) -> int | None:
    """How many of ``board``'s black squares the image shows white, where the found corners'
    homography puts them (centres in the image, the whole board), or None when it cannot tell.

    A wrong layout's corners and markers can agree with a view whose board is cut on one side,
    every id a square off: the board then reaches a square past the edge seen, where its black
    squares fall on the white margin. The right layout's black squares are black.
    """
    obj = board.object_points(ids)[:, :2].astype(np.float64)
    try:
        hom, _ = cv2.findHomography(obj, pts.astype(np.float64), 0)
    except cv2.error:
        return None
    if hom is None or not np.isfinite(hom).all():
        return None
    s, m = board.square_size, board.marker_size
    white = set()
    for quad in board.cv_board().getObjPoints():
        cx, cy = np.asarray(quad, np.float64).reshape(-1, 3)[:, :2].mean(axis=0)
        white.add((math.floor(cx / s), math.floor(cy / s)))
    (x0, y0), (x1, y1) = obj.min(axis=0), obj.max(axis=0)
    g = (s + m) / 4  # a square's centre to the middle of the white gap around its marker
    h, w = gray.shape

    def grey(board_pts: list[tuple[float, float]]) -> npt.NDArray[np.float64]:
        q = cv2.perspectiveTransform(np.array(board_pts, np.float64).reshape(-1, 1, 2), hom)
        xy = np.round(q.reshape(-1, 2))
        inside = (xy[:, 0] >= 0) & (xy[:, 0] < w) & (xy[:, 1] >= 0) & (xy[:, 1] < h)
        out = np.full(len(xy), np.nan)
        xi = xy[inside].astype(np.int64)
        out[inside] = gray[xi[:, 1], xi[:, 0]]
        return out

    # the two tones, from the squares between the corners found
    gaps, dark = [], []
    for r in range(board.squares[1]):
        for c in range(board.squares[0]):
            cx, cy = (c + 0.5) * s, (r + 0.5) * s
            if x0 < cx < x1 and y0 < cy < y1:
                if (c, r) in white:
                    gaps += [(cx + g, cy), (cx - g, cy), (cx, cy + g), (cx, cy - g)]
                else:
                    dark.append((cx, cy))
    if not gaps or not dark:
        return None
    tone_w, tone_b = np.nanmedian(grey(gaps)), np.nanmedian(grey(dark))
    if not tone_w - tone_b > 20:  # NaN too: no contrast to judge by
        return None
    black = [
        ((c + 0.5) * s, (r + 0.5) * s)
        for r in range(board.squares[1])
        for c in range(board.squares[0])
        if (c, r) not in white
    ]
    centres = grey(black)
    return int(np.count_nonzero(centres > (tone_w + tone_b) / 2))


_CV_BOARDS: dict[tuple[Any, ...], Any] = {}
#: (square, marker, cells) whose too narrow marker border has been warned of.
_BORDER_SAID: set[tuple[float, float, int]] = set()
_DETECTORS: dict[tuple[Any, ...], Any] = {}


def _cv_board(
    squares: tuple[int, int], square: float, marker: float, dictionary: str, legacy: bool
) -> Any:
    key = (squares, square, marker, dictionary, legacy)
    if key not in _CV_BOARDS:
        from stereovision.io import _opencv_quiet

        # OpenCV's own check, said in its log ("[ WARN:0@1.8] ... Marker border 0.001 is less
        # than 70% of ArUco pin size 0.004. Please increase markerSeparation or decrease
        # markerLength"), naming no parameter of this package: said here as a warning
        cells = int(_dictionary(dictionary).markerSize) + 2
        border, need = (square - marker) / 2, 0.7 * marker / cells
        said = (square, marker, cells)  # once a board: both layouts and the detector build it
        if border < need * (1 - 1e-9) and said not in _BORDER_SAID:  # not 0.025 in 0.03 (equal)
            _BORDER_SAID.add(said)
            warnings.warn(
                f"ChArUco markers of {marker:g} in squares of {square:g} leave a white border of "
                f"{border:.2g} around them, under the {need:.2g} (70 % of a marker's cell) that "
                "OpenCV needs to place the corners well (0.028 in 0.03: a rendered view's "
                "corners 0.49 px off on average, 0.08 px with 0.022); a board to print needs "
                f"markers of at most {_down_to_3_digits(square / (1 + 1.4 / cells)):.3g}",
                UserWarning,
                stacklevel=3,
            )
        with _opencv_quiet():
            b = cv2.aruco.CharucoBoard(squares, square, marker, _dictionary(dictionary))
        b.setLegacyPattern(legacy)
        _CV_BOARDS[key] = b
    return _CV_BOARDS[key]


def _down_to_3_digits(x: float) -> float:
    """``x`` (positive) rounded down to 3 significant digits, within the border check's 1e-9
    (0.03 / 1.2 is 0.0249999... and 0.025 is taken): a largest marker said rounded up was one
    the check refuses."""
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.floor(x * (1 + 1e-9) / step) * step


def _detector(board: CharucoBoard) -> Any:
    key = (board.squares, board.square_size, board.marker_size, board.dictionary, board.legacy)
    if key not in _DETECTORS:
        _DETECTORS[key] = cv2.aruco.CharucoDetector(board.cv_board())
    return _DETECTORS[key]


def corners_span_plane(board: CharucoBoard, ids: npt.NDArray[np.int64]) -> bool:
    """Whether the corners ``ids`` of ``board`` are not all on one line of the board.

    Parameters
    ----------
    board : CharucoBoard
        The board.
    ids : numpy.ndarray
        Inner-corner ids (int64), as :func:`find_charuco_corners` gives them.

    Returns
    -------
    bool
        True for at least three corners spanning the board's plane (a homography or pose can
        be fitted to them); False for fewer, or all on one row, column or diagonal.

    Raises
    ------
    TypeError
        If ``board`` is not a :class:`CharucoBoard`.
    ValueError
        If an id is not a whole corner id of the board (:meth:`CharucoBoard.object_points`).
    """
    _require_board(board)
    pts = board.object_points(ids)[:, :2].astype(np.float64)
    if len(pts) < 3:
        return False
    centred = pts - pts.mean(axis=0)
    sv = np.linalg.svd(centred, compute_uv=False)
    return bool(sv[1] > 1e-6 * max(sv[0], 1e-300))


def find_charuco_corners(
    image: npt.ArrayLike, board: CharucoBoard
) -> tuple[npt.NDArray[np.int64], F64] | None:
    """Find a ChArUco board's inner corners, with their ids, to sub-pixel accuracy.

    OpenCV's ``CharucoDetector`` decodes the markers, interpolates the corners between them and
    refines each with ``cornerSubPix`` in a window that stays clear of the markers. (A second
    refinement with the chessboard's window, 0.3 x the square, reaches the markers' edges: on
    rendered views it moved the corners from 0.04-0.08 px to 0.06-0.49 px mean error.)

    Parameters
    ----------
    image : array_like
        Grey or BGR image (``uint8``, ``uint16`` or float in [0, 1]).
        A dark image of more than 8 bits (12-bit data in ``uint16``) is stretched by its own
        range, as :func:`~stereovision.calibrate.calibrate` reads it.
    board : CharucoBoard
        The board; with ``dictionary="auto"`` or an undecided layout it is first resolved on
        this image (:meth:`CharucoBoard.resolve`).

    Returns
    -------
    tuple of numpy.ndarray or None
        ``ids`` (``(N,)`` ``int64``, ascending) and ``corners`` (``(N, 2)`` ``float64`` pixel
        ``(x, y)``), or None when fewer than :data:`MIN_CORNERS` corners are found or they all
        lie on one line of the board.

    Raises
    ------
    TypeError
        If ``board`` is not a :class:`CharucoBoard`.
    """
    from stereovision.calibrate import _board_gray

    _require_board(board)
    gray = _board_gray(image, "image")  # a dark 12-bit image at its own range, as calibrate's
    if not board.resolved:
        resolved = board.resolve(gray)
        if resolved is None:
            return None
        board = resolved
    corners, ids, _, _ = _detector(board).detectBoard(gray)
    if ids is None or corners is None or len(ids) < MIN_CORNERS:
        return None
    ids = np.asarray(ids, np.int64).ravel()
    pts = np.asarray(corners, np.float32).reshape(-1, 1, 2)
    order = np.argsort(ids, kind="stable")
    ids, pts = ids[order], pts[order]
    if not corners_span_plane(board, ids):
        return None
    return ids, pts.reshape(-1, 2).astype(np.float64)


# ------------------------------------------------------------------------------ synthetic views


def render_charuco(
    board: CharucoBoard,
    K: npt.ArrayLike,
    D: npt.ArrayLike,
    rvec: npt.ArrayLike,
    tvec: npt.ArrayLike,
    *,
    image_size: tuple[int, int] = (640, 480),
    supersample: int = 3,
    pixels_per_square: int = 120,
    background: int = 60,
    model: str = "pinhole",
) -> npt.NDArray[np.uint8]:
    """Render a ChArUco board seen by a camera, for tests and demos (antialiased, distorted).

    :func:`stereovision.synthetic.render_plane` of the board's image: every supersampled pixel's
    ray (lens distortion undone) meets the board plane and looks up the board's image there. The
    board lies in its ``Z = 0`` plane as :meth:`CharucoBoard.object_points`; its white margin is
    one square wide.

    Parameters
    ----------
    board : CharucoBoard
        The board (its dictionary must be known).
    K, D : array_like
        Camera matrix and OpenCV distortion coefficients (None or none at all: no distortion).
    rvec, tvec : array_like
        Board-to-camera rotation (Rodrigues) and translation, in the board's unit.
    image_size : tuple of int
        ``(width, height)``.
    supersample : int
        Samples per pixel side.
    pixels_per_square : int
        Resolution of the board image that is looked up.
    background : int
        Grey level off the board, 0 to 255 (the board is 0 and 255; it is mapped to 25 .. 230).
    model : str
        ``"pinhole"`` or ``"fisheye"`` (``D`` then holds ``cv2.fisheye``'s k1..k4).

    Returns
    -------
    numpy.ndarray
        ``(height, width)`` ``uint8``.

    Raises
    ------
    ValueError
        A board whose dictionary is not known, ``pixels_per_square`` outside 10 to 2000 or
        making the board's image (its margin included) over 32766 pixels a side, a
        ``background`` that is no grey level from 0 to 255, or a camera, pose, size,
        ``supersample`` or ``model`` :func:`~stereovision.synthetic.render_plane` refuses.
    TypeError
        If ``board`` is not a :class:`CharucoBoard`.
    """
    _require_board(board)
    p = int_in_range(pixels_per_square, "pixels_per_square", 10, 2000)
    # a grey level of the uint8 image: 300 and -5 were clipped to 255 and 0, True was 1 and
    # "60" 60, each without a word
    if not (real_number(background) and 0 <= background <= 255):
        raise ValueError(f"background: expected a grey level from 0 to 255, got {background!r}")
    cols, rows = board.squares
    if (max(cols, rows) + 2) * p > _REMAP_MAX_SIDE:
        # render_plane's refusal named its texture and units_per_pixel, neither of them this
        # function's, and only after drawing the board (25x3 at 1300 px: 5 s, 1 GB of it)
        w, h = (cols + 2) * p, (rows + 2) * p
        raise ValueError(
            f"pixels_per_square: a {cols}x{rows} board of {p} px squares is a {w}x{h} image (its "
            f"margin of one square included), past OpenCV's remap's {_REMAP_MAX_SIDE} a side; "
            f"use at most {_REMAP_MAX_SIDE // (max(cols, rows) + 2)} pixels per square"
        )
    img = board.image(p, margin=p)
    tone = (img.astype(np.float32) * ((230.0 - 25.0) / 255.0) + 25.0).astype(np.float32)
    # Board coordinate 0 is the outer edge of the squares: the image's pixel p - 0.5 (centres).
    out = render_plane(
        tone,
        board.square_size / p,
        K,
        D,
        rvec,
        tvec,
        image_size=image_size,
        supersample=supersample,
        background=background,
        model=model,
        origin_px=(p - 0.5, p - 0.5),
    )
    return np.asarray(np.clip(np.round(out), 0, 255), np.uint8)


# ------------------------------------------------------------------------------ printable board


def _board_scale(square_metres: float, dpi: float) -> tuple[int, int]:
    """``(pixels per square, pixels per metre)`` of :func:`board_png`'s image: the square is
    ``round(square / 25.4 mm x dpi)`` whole pixels, and the file's resolution is that count over
    the square's size (rounded to a whole pixel per metre, as PNG stores it), so a print at
    100 % gives the exact square size (30 mm at 300 dpi: 354 px, 11800 px/m, 299.72 dpi; the
    requested 300 dpi printed 29.97 mm squares)."""
    from stereovision._validate import positive_finite

    p = positive_finite(square_metres, "square_metres") / 0.0254 * positive_finite(dpi, "dpi")
    if not 10 <= p <= 20000:
        raise ValueError(
            f"a {square_metres * 1000:g} mm square at {dpi:g} dpi is {p:.6g} px; use a square "
            "and dpi giving 10 to 20000 px per square"
        )
    pix = round(p)
    ppm = round(pix / square_metres)
    if ppm > _PNG_MAX_PPM:  # struct.pack's bare error, said as "internal error" by board
        raise ValueError(
            f"a {square_metres * 1000:g} mm square at {dpi:g} dpi is {pix} px, {ppm:.6g} px per "
            f"metre: past the {_PNG_MAX_PPM} a PNG's resolution holds (about "
            f"{_PNG_MAX_PPM * 0.0254:.3g} dpi); use a lower dpi"
        )
    return pix, ppm


#: The most pixels per metre a PNG's ``pHYs`` chunk stores (an unsigned 32-bit count).
_PNG_MAX_PPM = 2**32 - 1


def _png_with_ppm(img: np.ndarray, ppm: int) -> bytes:
    """PNG bytes with a ``pHYs`` chunk of ``ppm`` pixels per metre, so that printing at 100 %
    gives the board's true size."""
    ok, buf = cv2.imencode(".png", img)
    if not ok:
        raise ValueError("could not encode the board as PNG")
    data = buf.tobytes()
    body = b"pHYs" + struct.pack(">IIB", ppm, ppm, 1)
    chunk = struct.pack(">I", 9) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    ihdr_end = 8 + 8 + 13 + 4  # signature, IHDR length+type, IHDR data, CRC
    return data[:ihdr_end] + chunk + data[ihdr_end:]


def _too_large(what: str, squares: tuple[int, int], pix: int, square_metres: float) -> ValueError:
    """The error of a board whose image (``squares`` and a one-square margin of ``pix`` px)
    is over MAX_IMAGE_PIXELS, with the most pixels per square it may have and the dpi giving
    them at ``square_metres``: "too large" alone left the user guessing what to ask for."""
    cols, rows = squares
    # whole pixels: most**2 <= MAX // area exactly when most**2 * area <= MAX
    most = math.isqrt(MAX_IMAGE_PIXELS // ((cols + 2) * (rows + 2)))
    head = (
        f"{what} at {pix} px per square is too large (over {MAX_IMAGE_PIXELS:.2g} pixels with "
        "its margins)"
    )
    if most < 10:  # _board_scale's least square: no square and dpi would do
        return ValueError(f"{head}, even at 10 px per square (the least): use fewer squares")
    mm = f"{square_metres * 1000:g}"
    return ValueError(
        f"{head}: at most {most} px per square, {mm} mm squares at up to "
        f"{_dpi_for(most, square_metres, mm):g} dpi"
    )


def _dpi_for(pix: int, square_metres: float, mm: str) -> float:
    """The dpi, to 6 significant digits, at which squares of ``square_metres``, or of ``mm``
    millimetres as said and typed back (metres in Python, the CLI's ``--square`` in mm), are
    ``pix`` pixels each (:func:`_board_scale`).

    Rounded to the nearest it could fall under ``pix`` and, at the 10 px floor, be refused
    (70 mm at 3.62857 dpi is 9.99999 px): raised by a last digit until all give ``pix``."""
    from stereovision.calibration import UNIT_TO_METRES

    squares = (square_metres, float(f"{mm}e-3"), float(mm) / 1000, float(mm) * UNIT_TO_METRES["mm"])
    dpi = float(f"{pix * 0.0254 / square_metres:.6g}")
    step = 10.0 ** (math.floor(math.log10(dpi)) - 5)  # one in the 6th digit
    for _ in range(10):  # a step or two: the 6-digit rounding is 1e-5 of it at most
        if all(10 <= (p := s / 0.0254 * dpi) and round(p) == pix for s in squares):
            break
        dpi = float(f"{dpi + step:.6g}")
    return dpi


#: Fewest pixels per cell of a marker (its bits and black border) a printed board is written
#: with: the markers of a board's own image at 1.2-2.5 px per cell were at times none decoded
#: (3 mm markers at 72 dpi: 0 of 17), from 3.1 px all of them (4X4 to 7X7, AprilTag, ArUco).
MIN_PX_PER_CELL = 3.0


def _check_marker_cells(board: CharucoBoard, pix: int, square_metres: float, dpi: float) -> None:
    """Refuse a printable board whose markers get under :data:`MIN_PX_PER_CELL` pixels a cell at
    ``pix`` px per square (``board`` wrote boards no detector decodes), naming the dpi that
    gives enough: its square is then at least that many whole pixels (``_board_scale``)."""
    cells = int(_dictionary(board.dictionary).markerSize) + 2
    ratio = board.marker_size / board.square_size
    per_cell = pix * ratio / cells
    if per_cell >= MIN_PX_PER_CELL:
        return
    need_px = math.ceil(MIN_PX_PER_CELL * cells / ratio)
    # The least whole dpi whose square, rounded to whole pixels as _board_scale does, is taken
    # here: rounded up from need_px it was often one more (8 mm squares, 4 mm 4X4 markers:
    # "use 115 dpi", and 114 gave the same 36 px squares). From a px lower: need_px's ceil can
    # be one over (3 x 7 / 0.7 is 30.000000000000004, and 30 px squares are taken)
    lo = max(1, math.floor((need_px - 1.5) * 0.0254 / square_metres))

    def taken(d: int) -> bool:
        return round(square_metres / 0.0254 * d) * ratio / cells >= MIN_PX_PER_CELL

    # bisected, not a dpi a step: a step is square / 25.4 mm px, so the 1.5 px from lo were
    # 38 million steps of 1e-6 mm squares (9 s) and 38 billion of 1e-9 mm (board hung)
    hi = lo
    while not taken(hi):  # doubled until taken: a handful of steps at any square
        lo, hi = hi + 1, 2 * hi
    while lo < hi:  # the least taken in [lo, hi]: the square grows with the dpi
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if taken(mid) else (mid + 1, hi)
    need_dpi = lo
    said = (
        f"marker_size: a {square_metres * ratio * 1000:g} mm marker at {dpi:g} dpi is "
        f"{pix * ratio:.1f} px, {per_cell:.1f} px a cell of {board.dictionary}'s {cells} (its "
        f"bits and border); a printed marker needs {MIN_PX_PER_CELL:g} to be decoded: "
    )
    # a dpi board_png refuses is no advice: it answered "use a lower dpi" (3e-9 m squares: 1e10
    # px per metre, past a PNG's pHYs) or "10 to 20000 px per square" (0.5 mm markers on 1 m
    # squares: 42008 px)
    need_pix = round(square_metres / 0.0254 * need_dpi)
    if need_pix > 20000:
        raise ValueError(
            f"{said}{need_dpi} dpi gives that, with {need_pix} px squares, past the 20000 a "
            "board image takes: use a larger marker"
        )
    if round(need_pix / square_metres) > _PNG_MAX_PPM:
        raise ValueError(
            f"{said}{need_dpi} dpi gives that, past the about {_PNG_MAX_PPM * 0.0254:.3g} dpi "
            "a PNG's resolution holds: use a larger square and marker"
        )
    raise ValueError(f"{said}use {need_dpi} dpi or more, or a larger marker")


def board_png(
    board: CharucoBoard | tuple[int, int],
    square_metres: float,
    dpi: float = 300.0,
) -> tuple[bytes, tuple[int, int]]:
    """A printable PNG of a board at its true size (its resolution is stored in the file).

    The square is ``round(square / 25.4 mm x dpi)`` whole pixels; the file's ``pHYs`` resolution
    is that count over the square's size (``_board_scale``), not ``dpi`` itself, so a print
    at 100 % gives the exact square size (30 mm at 300 dpi: 354 px per square stored at 11800
    px/m, 299.72 dpi; stored at 300 dpi it printed 29.97 mm squares).

    Parameters
    ----------
    board : CharucoBoard or tuple of int
        A ChArUco board (resolved dictionary), or a chessboard's inner corners ``(cols, rows)``.
    square_metres : float
        The square's side in metres (sets the pixel size at ``dpi``).
    dpi : float
        Printer resolution the square's pixel count is chosen at.

    Returns
    -------
    bytes, tuple of int
        The PNG file's bytes and its ``(width, height)`` in pixels.

    Raises
    ------
    ValueError
        A square or dpi giving under 10 or over 20000 px per square, an image over
        :data:`MAX_IMAGE_PIXELS`, markers too small to be decoded at ``dpi``, a ChArUco board
        whose dictionary is ``"auto"``, or a chessboard pattern that is none.
    """
    pix, ppm = _board_scale(square_metres, dpi)
    if isinstance(board, CharucoBoard):
        if board.dictionary == "auto":
            # its marker check looked the name up in cv2.aruco: AttributeError "module
            # 'cv2.aruco' has no attribute 'auto'" (`board` picks a dictionary first)
            raise ValueError(
                "dictionary: a printed board needs its dictionary ('auto' is found from the "
                "images of a board already printed): give one, e.g. 'DICT_5X5_100'"
            )
        cols, rows = board.squares
        # checked here too: image() names its pixels_per_square, which board_png's caller
        # did not give (they gave the square and dpi)
        if (cols + 2) * (rows + 2) * pix * pix > MAX_IMAGE_PIXELS:
            raise _too_large(f"a {cols}x{rows} ChArUco board", (cols, rows), pix, square_metres)
        _check_marker_cells(board, pix, square_metres, dpi)
        img = board.image(pix, margin=pix)
    else:
        from stereovision.calibrate import parse_pattern

        cols, rows = parse_pattern(board)
        sq_c, sq_r = cols + 1, rows + 1
        if (sq_c + 2) * (sq_r + 2) * pix * pix > MAX_IMAGE_PIXELS:
            raise _too_large(f"a {cols}x{rows} chessboard", (sq_c, sq_r), pix, square_metres)
        img = np.full((sq_r * pix + 2 * pix, sq_c * pix + 2 * pix), 255, np.uint8)
        for r in range(sq_r):
            for c in range(sq_c):
                if (r + c) % 2 == 0:
                    y0, x0 = pix + r * pix, pix + c * pix
                    img[y0 : y0 + pix, x0 : x0 + pix] = 0
    return _png_with_ppm(img, ppm), (img.shape[1], img.shape[0])
