"""Input checks shared by every entry point (images, pairs, dtypes, calibration numbers).

Every public function of the package validates its inputs here, at the top, so that a bad input
fails with one :class:`ValueError` that names the argument, what was received and what was
expected -- never with an obscure error from deep inside NumPy, OpenCV or the Rust kernels.

Image conventions (algorithms.md section 0): images are ``(H, W)`` ``float32`` grey levels in
``[0, 1]``; colour input is OpenCV's channel order (BGR or BGRA) and is converted with the usual
luma weights.
"""

from __future__ import annotations

import contextvars
import dataclasses
import decimal
import functools
import inspect
import math
import numbers
import os
import re
import reprlib
import sys
import warnings
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, TypeGuard, TypeVar, cast

import numpy as np
import numpy.typing as npt

from stereovision import _core

__all__ = [
    "LUMA_WEIGHTS_BGR",
    "UNIT_RANGE_TOL",
    "as_bgr_uint8",
    "as_gray_float",
    "as_gray_uint8",
    "as_image_array",
    "check_pair",
    "check_unit_range",
    "disparity_range",
    "finite_number",
    "float_sized",
    "int_in_range",
    "positive_finite",
    "positive_whole",
    "xy_points",
]

_T = TypeVar("_T")
_F = TypeVar("_F", bound=Callable[..., Any])

#: ITU-R BT.601 luma weights in OpenCV's B, G, R channel order (the weights ``cv2.cvtColor``
#: uses for ``COLOR_BGR2GRAY``), applied here in floating point without intermediate rounding.
LUMA_WEIGHTS_BGR: tuple[float, float, float] = (0.114, 0.587, 0.299)

#: Full-scale values of the accepted integer image dtypes.
_INT_FULL_SCALE: dict[np.dtype[Any], float] = {
    np.dtype(np.uint8): 255.0,
    np.dtype(np.uint16): 65535.0,
}

_EXPECTED = "uint8, uint16 or floating point in [0, 1]"


def _describe(arr: np.ndarray) -> str:
    return f"shape {arr.shape} dtype {arr.dtype}"


def path_given(obj: object) -> str | None:
    """The file name ``obj`` is (a str, bytes, os.PathLike, a NumPy string or 0-d string
    array: a name taken from a table), as plain text for a message; None for anything else.

    Parameters
    ----------
    obj : object
        What was given where an image or a calibration goes.

    Returns
    -------
    str or None
        The path (``np.str_('left.png')`` said as ``'left.png'``), or None; None too for text
        holding a NUL, which no file name holds: an encoded file's bytes (``requests.get(url)
        .content``, ``open(f, 'rb').read()``) were "got the path" with all their bytes, a
        message of a megabyte.
    """
    if isinstance(obj, np.ndarray) and obj.ndim == 0 and obj.dtype.kind in "US":
        obj = obj.item()
    if isinstance(obj, (str, bytes, os.PathLike)):
        path = os.fspath(obj)
        text = os.fsdecode(path) if isinstance(path, bytes) else str(path)
        return None if "\x00" in text else text
    return None


def as_path(path: object, name: str = "path", *, file: bool = False) -> Path:
    """``path`` as a :class:`pathlib.Path`, or a TypeError naming the argument: pathlib's own
    "argument should be a str object or an os.PathLike object returning str, not <class
    'bytes'>" (or "... not 'NoneType'") named none, and a bytes name got no hint to decode it.

    Parameters
    ----------
    path : object
        What was given as a file or folder name (str or os.PathLike).
    name : str
        The argument's name, for the message.
    file : bool
        ``path`` names a file: an empty name is refused (``Path("")`` is the current folder).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    TypeError
        If ``path`` is bytes (the library's paths are str or os.PathLike) or no name at all.
    ValueError
        If ``file`` and ``path`` is empty, or ``path`` holds a null byte.
    """
    if isinstance(path, bytes):
        said = path_given(path)
        shown = f"the bytes {said!r}" if said is not None else f"{len(path)} bytes"
        raise TypeError(
            f"{name}: expected a str or os.PathLike file name, got {shown}: "
            f"decode it first (os.fsdecode({name}))"
        )
    if isinstance(path, (str, os.PathLike)):
        fs = os.fspath(path)
        if isinstance(fs, str):
            if file and not fs:
                # Path("") is Path("."): a write said "cannot write .: it is a folder", a read
                # "not a regular file: ."
                raise ValueError(f"{name}: expected a file name, got ''")
            if "\x00" in fs:  # the OS's bare "embedded null byte" named no argument
                raise ValueError(f"{name}: expected a path without a null byte, got {fs!r}")
            return Path(fs)
    raise TypeError(f"{name}: expected a str or os.PathLike file name, got {type(path).__name__}")


#: Most pixels of an image the kernels take, and its longest side: the Rust kernels hold pixel
#: indices and counts in u32 and columns and rows in i32 (``MAX_PIXELS``, ``MAX_SIDE`` of
#: rust/core/src/image.rs, whose ``TooLarge`` message :func:`check_index_range` repeats).
MAX_PIXELS = 2**32 - 1
MAX_SIDE = 2**31 - 1


def check_index_range(
    shape: tuple[int, ...], name: str, what: str = "image", *, max_pixels: int = MAX_PIXELS
) -> None:
    """Refuse an ``(H, W, ...)`` shape past the kernels' 32-bit pixel indices, from the shape alone.

    Called before any copy or conversion: a broadcast or memory-mapped image of 70000 x 70000
    takes no memory as given, but its grey or BGR copy needs 5-20 GiB, so without this check
    the user got a MemoryError (or the OOM killer) instead of the limit the kernel would state.

    Parameters
    ----------
    shape : tuple of int
        The array's shape, ``(H, W)`` or ``(H, W, C)``.
    name : str
        Argument name used in the error message.
    what : str
        What the array is, for the message: ``"image"``, or ``"map"`` for a disparity map.
    max_pixels : int
        The kernel's own limit of ``W * H``, for one whose numbers reach fewer pixels than
        :data:`MAX_PIXELS` (the graph segmentation's ``2**31``).

    Raises
    ------
    ValueError
        If the width or height exceeds :data:`MAX_SIDE` or ``W * H`` exceeds ``max_pixels``.

    Examples
    --------
    >>> check_index_range((70000, 70000), "left")
    Traceback (most recent call last):
    ...
    ValueError: left: image of 70000x70000 pixels is too large: ...
    """
    h, w = int(shape[0]), int(shape[1])
    if w > MAX_SIDE or h > MAX_SIDE or w * h > max_pixels:
        raise ValueError(
            f"{name}: {what} of {w}x{h} pixels is too large: the kernels index pixels with 32-bit "
            f"integers (at most {max_pixels} pixels, {MAX_SIDE} per side)"
        )


def _refuse_masked(a: object, name: str, fill: str) -> None:
    """Refuse a :class:`numpy.ma.MaskedArray` with masked pixels, saying to pass
    ``name.filled(fill)``: ``np.asarray`` reads its data, the masked pixels' values as real
    ones (a masked 10 px disparity came out a depth of 8.4 m). One rule for the takers of a
    map (depth_from_disparity, reproject, refine_disparity); a mask of nothing is no loss."""
    if isinstance(a, np.ma.MaskedArray):
        n = int(np.count_nonzero(np.ma.getmaskarray(a)))
        if n:
            raise ValueError(
                f"{name}: a masked array (numpy.ma) with {n} masked pixel{'s' * (n != 1)}, "
                f"whose values would be read as real ones; pass {name}.filled({fill})"
            )


def as_image_array(img: object, name: str = "image") -> np.ndarray:
    """Convert ``img`` to a NumPy image array and check its shape and dtype (no value checks).

    Parameters
    ----------
    img : array_like
        Grey ``(H, W)`` or colour ``(H, W, C)`` image with ``C`` in 1, 3 (BGR), 4 (BGRA).
    name : str
        Argument name used in error messages.

    Returns
    -------
    numpy.ndarray
        The image as an array (no copy when ``img`` already is one in native byte order; a
        big-endian one is converted), shape ``(H, W)`` or ``(H, W, C)``, dtype ``uint8``,
        ``uint16`` or floating point.

    Raises
    ------
    ValueError
        If ``img`` is None (what ``cv2.imread`` returns for a file it cannot read: the message
        says so), is not array-like, has the wrong number of dimensions or channels, is empty,
        has an unsupported dtype (bool, signed integer, complex, object, strings, ...), or is
        past the kernels' 32-bit pixel indices (:func:`check_index_range`, from its shape
        alone: a broadcast image too large to copy is refused before any copy).
    """
    if img is None:
        # most often cv2.imread's answer for a path it could not read: say so
        raise ValueError(
            f"{name}: got None, not an image (cv2.imread returns None for a file it cannot "
            "read: check the path)"
        )
    path = path_given(img)
    if path is not None:
        # a file name where the README's cv2.imread(...) goes: "got str converting to <U8"
        raise ValueError(
            f"{name}: got the path {path!r}, not an image: read it first "
            "(cv2.imread(path) or stereovision.io.imread(path))"
        )
    if isinstance(img, bytes):  # no path (path_given): most often an encoded file's bytes
        raise ValueError(
            f"{name}: got {len(img)} bytes, not an image: decode an encoded file first "
            "(cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED))"
        )
    try:
        arr = np.asarray(img)
    except (ValueError, TypeError) as exc:  # ragged nested sequences and the like
        raise ValueError(
            f"{name}: expected an image array (H, W) or (H, W, 3), got {type(img).__name__} "
            f"that NumPy cannot convert ({exc})"
        ) from None
    if arr.dtype == object or arr.dtype.kind in "USV":
        raise ValueError(
            f"{name}: expected a numeric image array, got {type(img).__name__} "
            f"converting to dtype {arr.dtype}"
        )
    if arr.ndim in (2, 3):
        check_index_range(arr.shape, name)  # before the byte-order copy below and the callers'
    if not arr.dtype.isnative:
        # Big-endian data (FITS, some TIFF and PNG readers): the same values in native order.
        # ">u2" is not np.uint16, so a big-endian 16-bit image was refused as an "unsupported
        # dtype >u2" when uint16 was the expected one.
        arr = arr.astype(arr.dtype.newbyteorder("="))
    if arr.ndim not in (2, 3):
        raise ValueError(
            f"{name}: expected a grey (H, W) or colour (H, W, C) image, got {arr.ndim} "
            f"dimension(s) with shape {arr.shape}"
        )
    if arr.ndim == 3 and arr.shape[2] not in (1, 3, 4):
        raise ValueError(
            f"{name}: expected 1, 3 (BGR) or 4 (BGRA) channels, got {arr.shape[2]} "
            f"(shape {arr.shape})"
        )
    if arr.size == 0:
        raise ValueError(f"{name}: image is empty (shape {arr.shape})")
    if arr.dtype not in _INT_FULL_SCALE and arr.dtype.kind != "f":
        raise ValueError(f"{name}: unsupported dtype {arr.dtype}; expected {_EXPECTED}")
    return arr


#: A uint16 image whose values all lie below this is most likely 12-bit (or 8-bit) data in a
#: 16-bit container: scaled as 16-bit, its 8-bit copy keeps 4 bits of it (or none). The matchers
#: read the float grey image, all of its bits.
LOW_UINT16_MAX = 4096

#: The error of a depth-only request on a result computed without a calibration, ``{what}``
#: naming what was asked for: :class:`~stereovision.depth.DepthResult`'s and the exporters'
#: (:mod:`stereovision.export`) say it alike, with the same hint.
NO_DEPTH = (
    "no {what}: depth_map was called without a calibration (or with an "
    "UncalibratedRectification, which has no metric scale); pass calib=Calibration.from_file(...)"
)

#: Library warnings' and errors' advice in the words of where they are shown: the Python API's,
#: as raised (an array to scale, ``calib=``), the command line's (files and options; cli.py's
#: warning hook and error line) and the GUI page's (its fields and buttons). :func:`advice_for`
#: swaps them. A ``{name}`` field stands for a number the message holds, kept in the swap.
ADVICE: dict[str, dict[str, str]] = {
    "low_uint16": {
        "api": "scale it to the full range first (img << 4 for 12-bit data, or "
        "img.astype(np.uint8) for 8-bit values)",
        "cli": "save it scaled to the full 16-bit range first (12-bit data shifted left by 4 "
        "bits), or as an 8-bit image for 8-bit values",
    },
    "unrectified": {
        "api": "(calib=Calibration.from_file(...); one marked rectified is used as it is), or "
        "rectify the pair from its features (stereovision.uncalibrated.rectify_uncalibrated)",
        "cli": "(--calib; one marked rectified is used as it is), or rectify the pair from its "
        "features (stereovision rectify LEFT RIGHT -o DIR)",
        "page": "(the scene's calib.txt or --calib; one marked rectified is used as it is), or "
        "rectify the pair from its features (the Rectify button)",
    },
    # a pair resized from the calibration's images (depth_map's size error; its whole phrase,
    # not triangulation's "use calib.scaled_to" of a map); no command scales a calibration,
    # so the CLI's remedy is the images or a file saved once in Python
    "resized": {
        "api": "images resized, not cropped: calib.scaled_to(({w}, {h}))",
        "cli": "images resized, not cropped: resize them back to the calibration's size, or "
        "save it scaled to them once in Python with "
        "Calibration.from_file(path).scaled_to(({w}, {h})).save('rig.yaml') and give rig.yaml",
    },
    # a disparity map of a resized pair read with the calibration of the full-size images
    # (triangulation's warning, and the same in Matches.to_points): the depths are off by the
    # factor; at the command line the calibration is a file and the map a depth run's output
    "resized_map": {
        "api": "use calib.scaled_to(({w}, {h}))",
        "cli": "give --calib a calibration scaled to {w}x{h} images (save it once in Python with "
        "Calibration.from_file(path).scaled_to(({w}, {h})).save('rig.yaml')), or resize the "
        "images back to the calibration's size",
    },
    # depth_map's refusal of a range not below the pair's width (or of a pair too narrow for
    # the automatic one): the keyword is an option at the command line; the page keeps the
    # words (its field is no keyword, but no flag either)
    "range": {
        "api": "give a max_disparity below {n}",
        "cli": "give a --max-disparity below {n}",
        "page": "give a max_disparity below {n}",
    },
    "own_range": {
        "api": "a max_disparity of your own",
        "cli": "a --max-disparity of your own",
        "page": "a max_disparity of your own",
    },
    # batch's pair with no calibration asked for its floor: the workers said the CLI's words
    # (depth_outputs') to run_batch's caller too; no page asks for a floor
    "ground_calib": {
        "api": "ground=True needs calib=... or a calib.txt beside the pair",
        "cli": "--ground needs --calib",
        "page": "ground=True needs calib=... or a calib.txt beside the pair",
    },
}
ADVICE["low_uint16"]["page"] = ADVICE["low_uint16"]["cli"]  # on the page too, a file
# the page refuses a pair of another size than the one a size-less --calib was read at
# (StereoApp._calib_for; one with a size is fitted to the frames): no calibration is scaled there
ADVICE["resized"]["page"] = (
    "images resized, not cropped: choose images, an image folder or cameras of the "
    "calibration's size, or start gui again with a --calib for {w}x{h} images"
)
ADVICE["resized_map"]["page"] = ADVICE["resized_map"]["cli"]
LOW_UINT16_ADVICE = ADVICE["low_uint16"]["api"]


def refuse_no_image(img: object, name: str) -> None:
    """Raise :func:`as_image_array`'s error for None (``cv2.imread``'s answer for a file it
    cannot read, a camera's dropped frame) or a path given as an image: readers that cast
    first said "expected a uint8 image, got object" (``<U10`` for a path), or "got ()"."""
    if img is None or path_given(img) is not None:
        as_image_array(img, name)  # raises


def advice_for(text: str, where: str) -> str:
    """``text``, a library warning or error, with its Python advice in the words of ``where``
    (``"cli"`` or ``"page"``): ``img << 4`` or ``calib=`` is no help to a user who gave files
    and options, or who clicks."""
    for said in ADVICE.values():
        # the API's words as a pattern, each {field} a number carried into the other words
        api = re.sub(r"\\\{(\w+)\\\}", r"(?P<\1>\\d+)", re.escape(said["api"]))
        text = re.sub(api, functools.partial(_said_with, said[where]), text)
    return text


def _said_with(words: str, found: re.Match[str]) -> str:
    """``words`` with the numbers of their ``{fields}`` that ``found`` read."""
    return words.format(**found.groupdict())


def _warn_low_uint16(arr: np.ndarray, name: str, effect: str | None = None) -> None:
    """Warn when a uint16 image uses only its lowest 12 bits: it is scaled by 65535 (by 257 to
    8 bits), so its 8-bit copy (colours, the fill's colour segments) has 0-16 grey levels of a
    12-bit camera's image; the matchers read all its bits, the automatic range stretches it.
    ``effect``, with its leading separator, says what the scaling does to another reader
    (refine's contrast floor, OpenCV's matchers) instead; a ``{bits}`` in it is the bits the
    8-bit copy keeps. Alpha is no grey level: a BGRA image's is left out (an
    opaque one is 65535, which hid 12-bit colours, scaled as dark as any other's)."""
    import warnings

    colour = arr[:, :, :3] if arr.ndim == 3 and arr.shape[2] == 4 else arr
    top = int(colour.max())
    if top < LOW_UINT16_MAX:
        bits = f"{max(0.0, np.log2(max(top, 1) / 257)):.0f}"
        if effect is None:
            effect = (
                "; the matchers read all its bits, but its 8-bit copy (colours, the fill's "
                "colour segments) keeps about {bits} bits of it"
            )
        effect = effect.replace("{bits}", bits)
        warnings.warn(
            f"{name}: uint16 image whose largest value is {top} (12-bit or 8-bit data in a "
            f"16-bit container?): it is scaled as 16-bit{effect}; {LOW_UINT16_ADVICE}",
            UserWarning,
            stacklevel=user_stacklevel(),  # reached at many depths: as_gray_float, depth_map, match
        )


#: How far a float grey level may lie outside ``[0, 1]`` and still be read (clipped by
#: :func:`as_gray_float`): float rounding of an image's own arithmetic (a luma sum, a blend), some
#: float32 steps of 1.19e-7, is no mistake of scale to refuse.
UNIT_RANGE_TOL = 1e-6


def _grey_level(v: float) -> str:
    """``v`` in its shortest form that reads back as ``v``: ``:g`` (``255``, ``1e+300``), else
    the float32's shortest (``1.000002``, ``1e+30``: a float32 image's values), else 9 figures."""
    short = f"{v:g}"
    if float(short) == v:
        return short
    f32 = np.float32(v)
    if np.isfinite(f32) and float(f32) == v:
        return str(f32)
    return f"{v:.9g}"


def _unit_range_error(lo: float, hi: float, name: str) -> str | None:
    """The error of a float image whose finite values span ``[lo, hi]``, or None when that lies
    in ``[0, 1]`` (within :data:`UNIT_RANGE_TOL`): one message for :func:`as_gray_float` and
    :func:`check_unit_range`. The range's figures read back as the values (with ``:g``,
    ``1.000002`` was shown as ``1``: "must lie in [0, 1], got range [0, 1]"), and the advice
    fits them: 8-bit data is divided by 255, an overshoot of resampling (a bicubic remap reaches
    about -0.2 and 1.2) is clipped."""
    if lo >= -UNIT_RANGE_TOL and hi <= 1.0 + UNIT_RANGE_TOL:
        return None
    if lo >= -0.5 and hi <= 1.5:
        advice = "clip an overshoot of resampling with numpy.clip(img, 0, 1)"
    elif lo >= 0.0 and hi <= 255.0:
        advice = "divide 8-bit data by 255, or pass the uint8 array itself"
    elif lo >= 0.0 and hi <= 65535.0:
        advice = "divide 16-bit data by 65535, or pass the uint16 array itself"
    else:
        advice = "scale both images of the pair to [0, 1] alike"
    got = f"[{_grey_level(lo)}, {_grey_level(hi)}]"
    return f"{name}: float image values must lie in [0, 1], got range {got} ({advice})"


def _to_unit_float(arr: np.ndarray, name: str, warn: bool = True) -> npt.NDArray[np.float32]:
    """Scale a validated image array to float32 in [0, 1] (channels untouched); ``warn=False``
    for an image whose low-values warning its caller has given already."""
    if arr.dtype in _INT_FULL_SCALE:
        if arr.dtype == np.uint16 and warn:
            _warn_low_uint16(arr, name)
        # divide (not multiply by the reciprocal) so that full scale maps to exactly 1.0
        return arr.astype(np.float32) / np.float32(_INT_FULL_SCALE[arr.dtype])
    if not np.isfinite(arr).all():
        n_bad = int(np.count_nonzero(~np.isfinite(arr)))
        raise ValueError(
            f"{name}: float image contains {n_bad} NaN/inf value(s); expected finite grey levels "
            "in [0, 1]"
        )
    # Rescaling by the maximum would give the two images of a pair different scales, so a
    # float image outside [0, 1] is an error rather than a guess.
    lo, hi = float(arr.min()), float(arr.max())
    err = _unit_range_error(lo, hi, name)
    if err is not None:
        raise ValueError(err)
    if lo < 0.0 or hi > 1.0:  # float rounding: the documented range, exactly
        return np.clip(arr.astype(np.float32), 0.0, 1.0)
    return arr.astype(np.float32)


def as_gray_float(img: object, name: str = "left", *, warn: bool = True) -> npt.NDArray[np.float32]:
    """Return ``img`` as a C-contiguous grey ``(H, W)`` ``float32`` image in ``[0, 1]``.

    Scaling: ``uint8`` is divided by 255, ``uint16`` by 65535. Floating point images must already
    be finite and lie in ``[0, 1]`` (they are not rescaled: rescaling by the maximum would put the
    two images of a pair on different scales); an excursion of float rounding, up to
    :data:`UNIT_RANGE_TOL`, is clipped. Colour images (BGR or BGRA, OpenCV order) are
    converted with the BT.601 luma weights :data:`LUMA_WEIGHTS_BGR` in floating point; alpha is
    ignored.

    Parameters
    ----------
    img : array_like
        ``(H, W)``, ``(H, W, 1)``, ``(H, W, 3)`` BGR or ``(H, W, 4)`` BGRA image of dtype
        ``uint8``, ``uint16``, ``float16``, ``float32`` or ``float64``.
    name : str
        Argument name used in error messages.
    warn : bool
        Warn about a ``uint16`` image whose values all lie below 4096 (12-bit data in a 16-bit
        container?). False for an image its caller has warned about already (its 8-bit copy).

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``float32`` array with values in ``[0, 1]`` (always a new array).

    Raises
    ------
    ValueError
        If ``img`` is not an image array, has the wrong number of dimensions or channels, is
        empty, has an unsupported dtype (bool, signed integer, complex, object), or is a float
        image with NaN/inf or values outside ``[0, 1]``.

    Examples
    --------
    >>> import numpy as np
    >>> as_gray_float(np.array([[0, 255]], dtype=np.uint8))
    array([[0., 1.]], dtype=float32)
    """
    arr = as_image_array(img, name)
    if arr.dtype == np.uint8 and (arr.ndim == 2 or arr.shape[2] in (1, 3, 4)):
        # The same float32 operations in Rust, in one parallel pass: bit-identical, and
        # faster than the NumPy planes (tests/test_validate.py checks the identity).
        return _core.gray_u8(np.ascontiguousarray(arr), luma_weights())
    out = _to_unit_float(arr, name, warn)
    if out.ndim == 3:
        if out.shape[2] == 1:
            out = out[:, :, 0]
        else:
            # numpy planes, not cv2.transform: that is 2x faster but differs by 1 ulp in some
            # pixels, and the evaluation figures are measured on this exact conversion.
            b, g, r = LUMA_WEIGHTS_BGR
            gray = (
                np.float32(b) * out[:, :, 0]
                + np.float32(g) * out[:, :, 1]
                + np.float32(r) * out[:, :, 2]
            )
            # The weights sum to 1 up to float rounding; keep the documented range exact.
            out = np.clip(gray, 0.0, 1.0)
    return np.ascontiguousarray(out, dtype=np.float32)


def as_bgr_uint8(img: object, name: str = "image", *, warn: bool = True) -> npt.NDArray[np.uint8]:
    """Return ``img`` as a C-contiguous ``(H, W, 3)`` ``uint8`` BGR image (for OpenCV).

    ``uint8`` BGR input is returned as is (no copy when already contiguous). Grey input is
    replicated to three channels; BGRA drops alpha; ``uint16`` is divided by 257 and floats in
    ``[0, 1]`` multiplied by 255, both rounded to nearest.

    Parameters
    ----------
    img : array_like
        Image accepted by :func:`as_gray_float`.
    name : str
        Argument name used in error messages.
    warn : bool
        Warn about a ``uint16`` image whose values all lie below 4096, as
        :func:`as_gray_float` does; False for an image its caller has warned about.

    Returns
    -------
    numpy.ndarray
        ``(H, W, 3)`` ``uint8``.

    Raises
    ------
    ValueError
        As :func:`as_gray_float`.
    """
    arr = as_image_array(img, name)
    if arr.dtype != np.uint8:
        arr = np.rint(_to_unit_float(arr, name, warn) * np.float32(255.0)).astype(np.uint8)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.shape[2] == 1:
        arr = np.repeat(arr, 3, axis=2)
    elif arr.shape[2] == 4:
        arr = arr[:, :, :3]
    return np.ascontiguousarray(arr)


def as_gray_uint8(img: object, name: str = "image", *, warn: bool = True) -> npt.NDArray[np.uint8]:
    """Return ``img`` as a C-contiguous ``(H, W)`` ``uint8`` grey image (for OpenCV).

    Colour input goes through :func:`as_bgr_uint8` and ``cv2.cvtColor(..., COLOR_BGR2GRAY)``,
    i.e. exactly what OpenCV users get from an 8-bit BGR image.

    Parameters
    ----------
    img : array_like
        Image accepted by :func:`as_gray_float`.
    name : str
        Argument name used in error messages.
    warn : bool
        As :func:`as_bgr_uint8`'s.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``uint8``.

    Raises
    ------
    ValueError
        As :func:`as_gray_float`.
    """
    import cv2

    arr = as_image_array(img, name)
    if arr.ndim == 2 or arr.shape[2] == 1:
        if arr.dtype != np.uint8:
            arr = np.rint(_to_unit_float(arr, name, warn) * np.float32(255.0)).astype(np.uint8)
        return np.ascontiguousarray(arr.reshape(arr.shape[:2]))
    bgr = as_bgr_uint8(arr, name, warn=warn)
    return np.asarray(cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY), dtype=np.uint8)


def _channels_text(shape: tuple[int, ...]) -> str:
    """``grey``, ``colour``, ``colour with alpha`` or ``N channels`` for an image's shape."""
    c = shape[2] if len(shape) == 3 else 1
    return {1: "grey", 3: "colour", 4: "colour with alpha"}.get(c, f"{c} channels")


def pair_shape_error(left: tuple[int, ...], right: tuple[int, ...]) -> ValueError:
    """The refusal of a pair of two shapes; one size read two ways (``cv2.imread(path, 0)``
    beside ``cv2.imread(path)``) says which is grey and how to read them alike.

    Parameters
    ----------
    left, right : tuple of int
        The two images' shapes.

    Returns
    -------
    ValueError
        The error to raise.
    """
    text = f"left and right images must have the same shape, got left {left} and right {right}"
    if left[:2] == right[:2]:
        said = _channels_text(left), _channels_text(right)
        if said[0] == said[1]:  # (H, W) beside (H, W, 1): "left is grey, right is grey"
            side = "left" if len(left) == 3 else "right"
            text += f": both are grey, {side} with a channel axis of 1; drop it ({side}[..., 0])"
        else:
            text += (
                f": left is {said[0]}, right is {said[1]}; read both alike (cv2.imread(path) "
                "reads both in colour)"
            )
    return ValueError(text)


def check_pair(
    left: object, right: object
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """Validate a stereo pair and return it as grey ``float32`` images in ``[0, 1]``.

    Parameters
    ----------
    left, right : array_like
        Images accepted by :func:`as_gray_float`, of identical shape (same height, width and
        channel count).

    Returns
    -------
    tuple of numpy.ndarray
        ``(left, right)``, each ``(H, W)`` ``float32`` in ``[0, 1]``.

    Raises
    ------
    ValueError
        If either image is invalid (the message names ``left`` or ``right``) or if their shapes
        differ (the message gives both shapes).
    """
    larr = as_image_array(left, "left")
    rarr = as_image_array(right, "right")
    if larr.shape != rarr.shape:
        raise pair_shape_error(larr.shape, rarr.shape)
    return as_gray_float(larr, "left"), as_gray_float(rarr, "right")


def check_unit_range(img: npt.NDArray[np.float32], name: str) -> None:
    """Check that a float grey image's finite values lie in ``[0, 1]``.

    For the matchers that take a float32 grey image as it is (no scaling): the kernels refuse
    NaN and inf themselves, but read any finite value, and one large one (``1e30``, whose square
    is infinite in float32) spoilt the whole map without a word (the refinement's NaN
    everywhere, a quarter of the Gabor map NaN).

    Parameters
    ----------
    img : numpy.ndarray
        Float image.
    name : str
        Argument name used in the error message.

    Raises
    ------
    ValueError
        If a finite value lies outside ``[0, 1]`` by more than :data:`UNIT_RANGE_TOL` (float
        rounding; NaN and inf are left to the kernel's own message).

    Examples
    --------
    >>> check_unit_range(np.array([[0.0, 1.0]], np.float32), "left")
    >>> check_unit_range(np.array([[0.0, 255.0]], np.float32), "left")
    Traceback (most recent call last):
    ...
    ValueError: left: float image values must lie in [0, 1], got range [0, 255] ...
    """
    lo, hi = float(img.min()), float(img.max())
    if not (math.isfinite(lo) and math.isfinite(hi)):
        # NaN or inf: the kernel names them (with their count)
        return
    err = _unit_range_error(lo, hi, name)
    if err is not None:
        raise ValueError(err)


def u8_pair(left: object, right: object) -> tuple[np.ndarray, np.ndarray] | None:
    """Both images as C-contiguous ``uint8`` arrays when they are valid 8-bit images of one shape.

    For kernels that convert 8-bit images to grey themselves (bit-identical to
    :func:`as_gray_float`, without the ``float32`` intermediates).

    Parameters
    ----------
    left, right : object
        Candidate images.

    Returns
    -------
    tuple of numpy.ndarray or None
        ``(left, right)`` when both are non-empty ``uint8`` arrays of the same shape ``(H, W)``
        or ``(H, W, C)`` with ``C`` in 1, 3, 4; else None (callers then use :func:`check_pair`,
        which also raises the errors).
    """
    if not (isinstance(left, np.ndarray) and isinstance(right, np.ndarray)):
        return None
    if left.dtype != np.uint8 or right.dtype != np.uint8 or left.shape != right.shape:
        return None
    ok = left.ndim == 2 or (left.ndim == 3 and left.shape[2] in (1, 3, 4))
    if not ok or left.size == 0:
        return None
    h, w = left.shape[:2]
    if w > MAX_SIDE or h > MAX_SIDE or w * h > MAX_PIXELS:
        return None  # too large: check_pair refuses it from its shape, before any copy
    return np.ascontiguousarray(left), np.ascontiguousarray(right)


def luma_weights() -> tuple[float, float, float]:
    """:data:`LUMA_WEIGHTS_BGR` as the ``float32`` values the grey conversion uses."""
    b, g, r = (float(np.float32(w)) for w in LUMA_WEIGHTS_BGR)
    return b, g, r


def _real_array(a: object) -> np.ndarray | None:
    """``a`` as an array of real numbers (bool, int, float), or None when it holds something
    else (complex, text, None). An object array of real numbers only (``np.array(values,
    dtype=object)``, a pandas object column) is their float64 array: a dtype check alone
    refused it, where ``np.asarray(a, np.float32)`` had read it."""
    raw = np.asarray(a)
    if raw.dtype.kind in "biuf":
        return raw
    if raw.dtype == object and all(
        isinstance(v, numbers.Real) and not isinstance(v, np.bool_) for v in raw.flat
    ):
        return raw.astype(np.float64)
    return None


#: What Python or NumPy count as numbers but no parameter takes as one: a bool (an int: True
#: was a count of 1), an np.bool_, and an np.timedelta64 (an np.integer and a numbers.Integral:
#: 3 ns was a count of 3). Every check of a number or a count refuses them (:func:`real_number`,
#: :func:`whole_value`).
NOT_NUMBERS: tuple[type, ...] = (bool, np.bool_, np.timedelta64)


def real_number(value: object) -> TypeGuard[int | float | np.integer[Any] | np.floating[Any]]:
    """Whether ``value`` is one real number: a Python or NumPy int or float, none of
    :data:`NOT_NUMBERS`.

    Examples
    --------
    >>> real_number(np.float32(0.5)), real_number(True), real_number(np.timedelta64(3))
    (True, False, False)
    """
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, NOT_NUMBERS
    )


def _plain_real(value: Any) -> Any:
    """A real number that is no Python or NumPy number (a :class:`fractions.Fraction`, a
    :class:`decimal.Decimal`) as its float, anything else as it is.

    :func:`finite_number` refuses them as "no finite number", where ``fuse`` and
    ``fused_dense`` had compared them as the numbers they are; read as its float each gives the
    plain float's result, as :func:`stereovision.matching.gabor.gabor_disparity` reads them. A
    value too large for a float is left for ``finite_number`` to refuse, naming the parameter.
    """
    real = isinstance(value, (numbers.Real, decimal.Decimal))
    if real and not isinstance(value, (int, float, np.generic)):
        try:
            out = float(value)
        except (OverflowError, ValueError):
            return value
        # a finite Decimal past a float's range is no OverflowError, as a Fraction's is, but
        # an infinity: Decimal('1e400') was refused as "got inf"
        if math.isinf(out) and isinstance(value, decimal.Decimal) and value.is_finite():
            return value
        return out
    return value


def _plain_option(value: Any) -> Any:
    """An option's number as :func:`fuse` and :func:`fused_dense` use it: a Fraction or a
    Decimal as its float (:func:`_plain_real`), a NumPy integer or float scalar or size-1
    array as the Python int or float of its value, anything else as it is.

    Not the NumPy scalar of its dtype: ``np.array([16], np.uint8)`` as ``r_spatial`` squared
    to 0 in uint8 (one offset searched instead of 797), ``np.array([1], np.uint8)`` as
    ``speckle_area`` was NumPy's "Python integer 4800 out of bounds for uint8"; a Python
    number gives the plain number's maps.

    :func:`finite_number` passes a size-1 array, which ``np.array([3])`` as ``edge_radius``
    then made NumPy's bare "only 0-dimensional arrays can be converted" after every matcher
    had run; and only the confidences read a Fraction or a Decimal, which ``r_spatial`` or
    ``radius`` refused (one config read with ``parse_float=Decimal`` passed half its keys).
    """
    value = _plain_real(value)
    if isinstance(value, np.ndarray) and value.size == 1 and value.dtype.kind in "iuf":
        value = value.reshape(())[()]
    # by dtype kind, not np.integer: np.timedelta64 is one, and its item() made 16 ns a 16
    # (accepted as r_spatial=16) and 16 s a datetime.timedelta (the error misnamed the value)
    if isinstance(value, np.generic) and value.dtype.kind in "iuf":
        return value.item()
    return value


#: The most digits :func:`whole_value` reads a Decimal's int with: Python's own limit of an int
#: read from a str (``sys.int_info.default_max_str_digits``), against the same cost.
_WHOLE_DIGITS = 4300


def whole_value(value: object) -> int | None:
    """``value`` as a Python int when it is a whole number, else None: one rule for every
    count (``min_agree``'s, :func:`int_in_range`'s, the matchers' counts).

    A whole number is an int or a NumPy integer, or a finite integral float, Fraction or
    Decimal (``3.0``, ``np.float32(2)``, ``Fraction(2)``: a value read from a config or a
    computation), or a size-1 array of one (a value read from an array) -- never one of
    :data:`NOT_NUMBERS`, nor a Decimal of over 4300 digits (``Decimal('1e1000000')``, whose int
    takes a minute to build).

    Examples
    --------
    >>> whole_value(3.0), whole_value(np.array([2])), whole_value(2.5), whole_value(True)
    (3, 2, None, None)
    """
    if isinstance(value, np.ndarray) and value.size == 1 and value.dtype.kind in "iuf":
        value = value.reshape(())[()]
    if isinstance(value, NOT_NUMBERS):
        return None
    # each kind judged by its own value, not by its nearest float: Fraction(3 * 10**17 + 1,
    # 10**17) and Decimal('3.00000000000000001') were 3.0 as floats, Decimal('9007199254740993')
    # 9007199254740992, and np.longdouble(3) (whose item() is no float) no count at all
    if isinstance(value, (int, np.integer)):
        return int(value)  # an IntEnum member as its int
    if isinstance(value, numbers.Rational):
        return int(value.numerator) if value.denominator == 1 else None
    if isinstance(value, decimal.Decimal):
        whole = value.is_finite() and value == value.to_integral_value()  # sNaN: not compared
        # its int is built digit by digit: Decimal('1e1000000') took 53 s, '1e999999999999999999'
        # never ends; past the digits Python itself turns a str into an int, no count
        if whole and value and value.adjusted() >= _WHOLE_DIGITS:
            return None
        return int(value) if whole else None
    if isinstance(value, (float, np.floating)):
        return int(value) if np.isfinite(value) and value == np.floor(value) else None
    plain = _plain_real(value)  # another numbers.Real: as its float, as before
    if isinstance(plain, float) and math.isfinite(plain) and plain.is_integer():
        return int(plain)
    return None


def refuse_not_numbers(params: dict[str, Any], defaults: dict[str, Any]) -> None:
    """A ``ValueError`` naming the first of ``params`` whose default is a number (not a switch)
    and whose value is one of :data:`NOT_NUMBERS`: a matcher's kernel read True as 1 and 3 ns
    as 3 (``A=True``, ``k_cand=np.timedelta64(3)``). A switch's True is its own. A size-1 array
    is judged by its value, as :func:`read_numbers` reads one: ``A=np.array(True)`` ran as 1,
    and one of a string or a datetime (``np.array('3')``, of dtype object too) as 3. Nor is
    anything else but a real number (a Fraction and a Decimal are) one: ``s_min='0.5'``, None
    or ``[0.5]`` was the binding's "parameter `s_min`: TypeError: must be real number, not
    str", where the Gabor channel says "s_min: expected a number, got '0.5'". A switch (a
    bool default) is True or False (a NumPy bool too)."""
    for name, v in params.items():
        d = defaults.get(name)
        array = isinstance(v, np.ndarray) and v.size == 1
        scalar = v.reshape(())[()] if array else v
        number = isinstance(d, (int, float)) and not isinstance(d, bool)
        real = isinstance(scalar, (numbers.Real, decimal.Decimal))
        if number and (isinstance(scalar, NOT_NUMBERS) or not real):
            raise ValueError(f"{name}: expected a number, got {_shown(v)}")
        # a switch is True or False: edge_test='no' was the binding's "parameter `edge_test`:
        # TypeError: 'str' object is not an instance of 'bool'" (MCGM's debug says it so)
        if isinstance(d, bool) and not isinstance(v, (bool, np.bool_)):
            raise ValueError(f"{name}: expected True or False, got {_shown(v)}")


def read_numbers(params: dict[str, Any], defaults: dict[str, Any]) -> dict[str, Any]:
    """``params`` with each count (a parameter whose default is an int) that is a whole number
    as :func:`whole_value` reads it (``8.0``, ``Fraction(8)``, ``np.array([8])``) as that int,
    and each real (a float default) given as a size-1 array as its number; anything else as
    given, for the kernel to name. The Hopfield and MCGM kernels took neither: ``k_cand=8.0``
    was "parameter `k_cand`: TypeError: 'float' object cannot be interpreted as an integer",
    ``A=np.array([3.0])`` "only 0-dimensional arrays can be converted", where the Gabor and
    census wrappers take both.

    Raises
    ------
    ValueError
        A count past any 64-bit integer, named as given: the kernel named the int it was read
        as (``1e300``: 301 digits; an int of over 4300 digits: "got ?").

    Examples
    --------
    >>> read_numbers({"k": 8.0, "a": np.array([0.5]), "s": "x"}, {"k": 1, "a": 1.0, "s": "y"})
    {'k': 8, 'a': np.float64(0.5), 's': 'x'}
    """
    out = dict(params)
    for name, v in params.items():
        d = defaults.get(name)
        if isinstance(d, bool) or not isinstance(d, (int, float)):
            continue  # a switch, a choice, a list: the kernel's own
        if isinstance(d, int):
            whole = whole_value(v)
            # a Decimal of over 4300 digits is no whole_value (its int takes minutes) and went
            # to the kernel as given: "TypeError: 'decimal.Decimal' object cannot be interpreted"
            huge = isinstance(v, decimal.Decimal) and v.is_finite() and v.adjusted() >= 64
            if huge or (whole is not None and not -(2**63) <= whole < 2**64):
                shown = too_large_for_float(v, why=False) or reprlib.repr(v)
                raise ValueError(f"{name}: expected an integer of at most 64 bits, got {shown}")
            if whole is not None:
                out[name] = whole
        elif isinstance(v, np.ndarray) and v.size == 1 and v.dtype.kind in "iuf":
            out[name] = v.reshape(())[()]
    return out


def _real_scalar(value: object) -> float:
    """``value`` as a float when it is one real number: a Python or NumPy int or float, or a
    size-1 NumPy array of them (``np.array(3.0)``, ``np.array([3.0])``: a value read from an
    array); a TypeError otherwise (a bool, a string, a list: a slider's ``[1.0]`` is no
    number). One rule for :func:`positive_finite` and :func:`finite_number` (the second refused
    ``np.array(3.0)`` and the first ``2**70``, each taken by the other)."""
    if real_number(value):  # not np.asarray: 2**70 is an object array there
        return float(value)
    if not isinstance(value, np.ndarray) or value.size != 1 or value.dtype.kind not in "iuf":
        raise TypeError(type(value).__name__)
    return float(value.reshape(()))


def positive_finite(value: object, name: str) -> float:
    """Return ``value`` as a Python float, checking that it is finite and strictly positive.

    Parameters
    ----------
    value : float-like
        A real scalar (Python or NumPy number, or a size-1 array, as :func:`finite_number`).
    name : str
        Field or argument name used in the error message.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        If ``value`` is not a real number, is NaN/inf, or is ``<= 0``.
    """
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name}: expected a positive finite number, got bool {value!r}")
    if too_large_for_float(value):  # np.asarray made it an object array: its 400 digits shown
        raise ValueError(f"{name}: expected a positive finite number, got {number_shown(value)}")
    try:
        out = _real_scalar(value)
    except TypeError:
        raise ValueError(
            f"{name}: expected a positive finite number, got "
            + (
                _shown(value)
                if isinstance(value, np.ndarray)
                else f"{type(value).__name__} {_shown(value)}"
            )
        ) from None
    if not math.isfinite(out) or out <= 0.0:
        raise ValueError(f"{name}: expected a positive finite number, got {out!r}")
    return out


def int_in_range(value: object, name: str, lo: int, hi: int) -> int:
    """``value`` as an ``int`` within ``[lo, hi]`` (a whole number as :func:`whole_value` reads
    it: an integral float, Fraction or Decimal, or a size-1 array of one, is accepted).

    Raises
    ------
    ValueError
        Naming ``name``, for a bool, a non-number, a non-integral or non-finite number, or one
        outside the range.
    """
    whole = whole_value(value)  # the one rule of a count (a bool, np.timedelta64: no count)
    if whole is None or not lo <= whole <= hi:  # exact: a float of 2**63 - 1 is 2**63
        raise ValueError(f"{name}: expected an integer from {lo} to {hi}, got {_shown(value)}")
    return whole


def positive_whole(value: object, name: str, expected: str = "a positive integer") -> int:
    """``value`` as an ``int`` above 0: a whole number as :func:`whole_value` reads it (an
    integer, not a bool, or a finite whole float such as ``3.0``, Fraction, Decimal or size-1
    array of one).

    Parameters
    ----------
    value : object
        The count given (pairs to take, a period in pairs).
    name : str
        Its keyword, named in the error.
    expected : str
        What it should be, in the error's words (``"a positive number of pairs"``).

    Returns
    -------
    int

    Raises
    ------
    ValueError
        ``"NAME: expected EXPECTED, got VALUE"`` for a bool, a non-number, a NaN, an infinity,
        a fraction (2.5 pairs were taken as 3, NaN as none) or a number below 1.
    """
    whole = whole_value(value)  # the one rule of a count, its own check merged into it
    if whole is None or whole < 1:
        raise ValueError(f"{name}: expected {expected}, got {_shown(value)}")
    return whole


def float_sized(value: _T, name: str) -> _T:
    """``value`` unchanged, after a ``ValueError`` naming ``name`` if it is a Python int beyond
    a float's range (``10**400``: the OverflowError of ``float()`` and of the bindings' f32 / f64
    parameters). Other values are left to the caller's own checks.

    Examples
    --------
    >>> float_sized(3, "gamma")
    3
    >>> float_sized(10**400, "gamma")
    Traceback (most recent call last):
    ...
    ValueError: gamma: an integer of 401 digits is beyond a float's range
    """
    if isinstance(value, int) and not isinstance(value, bool):
        try:
            float(value)
        except OverflowError:
            raise ValueError(f"{name}: {_shown(value)} is beyond a float's range") from None
    return value


#: The longest repr :func:`_shown` gives as it is: a message is one short line.
_SHOWN_MAX = 80


def _shown(value: object) -> str:
    """``repr(value)``, or for an int beyond a float its size (10**5000 has no repr), in
    :func:`too_large_for_float`'s words (one wording for every message); another value with
    such an int inside (``Fraction(10**5000)``, a count to :func:`whole_value`) by its type.

    A repr of several lines or over :data:`_SHOWN_MAX` characters is shortened to one line: an
    array by its shape and dtype (a ``(4, 4)`` array as a count was its 4 lines of values, a
    camera frame's hundreds), anything else as :mod:`reprlib` cuts it (a 500-character str)."""
    big = too_large_for_float(value, why=False)
    if big:
        return big
    try:
        text = repr(value)
    except ValueError:  # Python's limit of an int's str: its message named no parameter
        return f"a {type(value).__name__} of over 4300 digits"
    if "\n" not in text and len(text) <= _SHOWN_MAX:
        return text
    if isinstance(value, np.ndarray):
        return f"array of shape {value.shape} dtype {value.dtype}"  # as io says one
    return " ".join(reprlib.repr(value).split())


def too_large_for_float(value: object, *, why: bool = True) -> str | None:
    """What a message says of ``value`` when it is an int beyond a float's range (``10**400``),
    else None: its number of digits, never the digits themselves (one line; an int of over 4300
    digits has no ``str``), and (``why``) why it is refused though it is finite.

    Examples
    --------
    >>> too_large_for_float(10**400)
    'an integer of 401 digits (too large for a float)'
    >>> too_large_for_float(-(10**400))
    'a negative integer of 401 digits (too large for a float)'
    >>> too_large_for_float(10**400, why=False)
    'an integer of 401 digits'
    >>> too_large_for_float(2**70) is None
    True
    """
    if not isinstance(value, int) or isinstance(value, bool):
        return None  # NumPy integers all fit a float
    try:
        float(value)
        return None
    except OverflowError:
        pass
    size = abs(value)
    digits = int(math.log10(size)) + 1  # log10 of a big int is a float: corrected exactly
    if size < 10 ** (digits - 1):
        digits -= 1
    elif size >= 10**digits:
        digits += 1
    sign = "a negative" if value < 0 else "an"
    return f"{sign} integer of {digits} digits" + (" (too large for a float)" if why else "")


def number_shown(value: object) -> str:
    """``repr(value)`` for a message, or :func:`too_large_for_float`'s words for an int beyond a
    float's range."""
    return too_large_for_float(value) or _shown(value)


def text_shown(value: object) -> str:
    """``repr(value)`` for a message, a str subclass (``np.str_`` read from an array or a table)
    as its text: ``'cm'``, not ``np.str_('cm')``.

    Examples
    --------
    >>> text_shown(np.str_("cm"))
    "'cm'"
    >>> text_shown(["m"])
    "['m']"
    """
    return repr(str(value)) if isinstance(value, str) else repr(value)


def known_unit(unit: object, units: Iterable[str], name: str = "unit") -> str:
    """``unit`` as a plain str when it is one of ``units``, else a ValueError naming them.

    Parameters
    ----------
    unit : object
        What was given (a str, ``np.str_``, or anything else: refused by name, not by the
        TypeError ``in`` raises for an unhashable list).
    units : iterable of str
        The known units, in the order the message lists them.
    name : str
        Argument name used in the message.

    Returns
    -------
    str
        ``unit`` as a built-in str (an ``np.str_`` would otherwise reach later messages).

    Raises
    ------
    ValueError
        If ``unit`` is not one of ``units``.

    Examples
    --------
    >>> known_unit(np.str_("furlong"), ["m", "mm"])
    Traceback (most recent call last):
    ...
    ValueError: unit: expected one of ['m', 'mm'], got 'furlong'
    """
    known = list(units)
    if not isinstance(unit, str) or unit not in known:
        raise ValueError(f"{name}: expected one of {known}, got {text_shown(unit)}")
    return str(unit)


def same_aspect(calib_size: tuple[int, int], size: tuple[int, int]) -> bool:
    """Whether ``size`` scales ``calib_size`` by one factor on both sides, within 1 % of the
    larger (a halved odd side rounds: 450x375 -> 225x188)."""
    sx, sy = size[0] / calib_size[0], size[1] / calib_size[1]
    return abs(sx - sy) <= 0.01 * max(sx, sy)


def crop_or_pad_hint(calib_size: tuple[int, int], size: tuple[int, int]) -> str | None:
    """Advice for frames a few rows or columns off a calibration's size, else None.

    A resize moves both sides one way; one side kept (KITTI's 1242x376 frames against
    1242x375) or one larger and one smaller, within :func:`same_aspect`, is a crop or pad,
    which a scaled calibration would take for a stretch of one axis (0.27 % there, the
    principal point moved ~0.5 px).

    Parameters
    ----------
    calib_size, size : tuple of int
        ``(width, height)`` of the calibration and of the frames.

    Returns
    -------
    str or None
        "images cropped or padded, not resized (1 row more): crop or pad them to WxH", or None
        when the sizes are equal, a resize, or another aspect ratio.

    Examples
    --------
    >>> crop_or_pad_hint((1242, 375), (1242, 376))
    'images cropped or padded, not resized (1 row more): crop or pad them to 1242x375'
    """
    (cw, ch), (w, h) = calib_size, size
    dw, dh = w - cw, h - ch
    if (dw, dh) == (0, 0) or dw * dh > 0 or not same_aspect(calib_size, size):
        return None
    off = " and ".join(
        f"{abs(d)} {what}{'s' if abs(d) > 1 else ''} {'more' if d > 0 else 'fewer'}"
        for d, what in ((dw, "column"), (dh, "row"))
        if d
    )
    return f"images cropped or padded, not resized ({off}): crop or pad them to {cw}x{ch}"


def calib_size_hint(calib_size: tuple[int, int], size: tuple[int, int]) -> str:
    """What images of ``size`` against a calibration of ``calib_size`` likely are, and the
    remedy (:data:`ADVICE`'s Python words): depth_map's and :meth:`Calibration.rectify`'s
    refusal of another size (rectify named the two sizes only: a pair resized from the
    calibration's images, a robot's lower camera mode, was not told of ``scaled_to``).

    Examples
    --------
    >>> calib_size_hint((640, 480), (320, 240))
    'images resized, not cropped: calib.scaled_to((320, 240))'
    """
    (cw, ch), (w, h) = calib_size, size
    if (cw, ch) == (h, w):
        return "width and height swapped? image_size is (width, height)"
    if (crop := crop_or_pad_hint((cw, ch), (w, h))) is not None:
        return crop
    if same_aspect((cw, ch), (w, h)):
        # fit_to_frames' 1 % (stream and gui scale such frames): a halved odd side rounds
        return ADVICE["resized"]["api"].format(w=w, h=h)
    return "another aspect ratio: another camera mode or camera, or cropped images"


def pixels_shown(value: float) -> str:
    """A number of pixels for a message: every digit of a whole number up to 12 digits
    (``:g`` showed 3e10 + 48 as "3e+10"), a fraction as given (16.5), beyond that 12 digits; an
    int beyond a float's range (match's min_disparity of 10**400) by its size: ``:g`` of it is an
    OverflowError."""
    return too_large_for_float(value, why=False) or f"{value:.12g}"


def figure_shown(value: float) -> str:
    """A measured figure (a depth, a bar label) for a message: three significant digits, whole
    units from 999.5 on, where ``.3g`` switched to exponent form ("2.27e+03 mm", "1e+03")."""
    return f"{value:.3g}" if abs(value) < 999.5 else f"{value:.0f}"


def unreachable_range(min_disparity: float, max_disparity: float, width: int) -> ValueError | None:
    """The error of a range no pixel of a ``width`` px wide pair can match in, or None.

    A match ``xr = xl - d`` needs both columns in the image, so ``|d| < width``: a
    ``min_disparity`` at the width or above (or a ``max_disparity`` at minus the width or
    below) searched nothing and returned an all-NaN map, or a float32 kernel parameter error
    ("invalid parameter `d_max`") for a range beyond float32's resolution (3e10 to 3e10 + 16).
    """
    if min_disparity >= width:
        return ValueError(
            f"min_disparity ({pixels_shown(min_disparity)}) is not below the image width "
            f"{width}: no pixel has a match that far to its left in the right image; give a "
            f"min_disparity below {width}"
        )
    if max_disparity <= -width:
        return ValueError(
            f"max_disparity ({pixels_shown(max_disparity)}) is not above minus the image width "
            f"(-{width}): no pixel has a match that far to its right in the right image; give "
            f"a max_disparity above -{width}"
        )
    return None


def refuse_unreachable_range(min_disparity: float, max_disparity: float, width: int) -> None:
    """Raise :func:`unreachable_range`'s error, if any: the matchers' own entry points refuse
    such a range as ``match()`` and ``depth_map`` do (their kernels clip the range to the image
    and return nothing without a word)."""
    err = unreachable_range(min_disparity, max_disparity, width)
    if err is not None:
        raise err


def first_line(exc: BaseException, paths: Iterable[object] = ()) -> str:
    """What a one-line error message says of ``exc``: its message's first line with text (its
    type's name if none), as the CLI, the GUI and the stream print errors and warnings.

    Parameters
    ----------
    exc : BaseException
        The error.
    paths : iterable, optional
        Paths the message may name, shown :func:`escaped` where they hold a control character
        (:func:`escape_paths`): one holding a newline is not cut.

    Returns
    -------
    str
        One line.

    Examples
    --------
    >>> first_line(RuntimeError("the offscreen render returned no image\\nat line 2"))
    'the offscreen render returned no image'
    >>> first_line(MemoryError())
    'MemoryError'
    >>> first_line(ValueError("\\nthe pair differs in size"))
    'the pair differs in size'
    """
    # the first line with text: a message opening with a line break said nothing
    text = [line for line in escape_paths(_message(exc), paths).splitlines() if line.strip()]
    # a control character left (a tab, an ESC sequence in a file name found in a folder) would
    # be obeyed by the terminal: shown escaped
    return _CONTROL.sub(_escape_one, text[0]) if text else type(exc).__name__


def _message(exc: BaseException) -> str:
    """``str(exc)``, or "" for an error that cannot say its message: the str of one holding an
    int of over 4300 digits (``KeyError(10**5000)``) is itself a ValueError, which the CLI's
    last handler then let out as a traceback."""
    try:
        return str(exc)
    except Exception:
        return ""


#: The characters a one-line message does not show as they are: C0 and C1 controls (a
#: newline, a tab, ESC that starts a sequence rewriting the terminal), the line and
#: paragraph separators ``str.splitlines`` also cuts at, and lone surrogates (a file name's
#: byte that is not UTF-8, as :func:`os.fsdecode` gives it): a UTF-8 standard output not in
#: the C locale cannot encode one, so printing the line raised UnicodeEncodeError.
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029\ud800-\udfff]")


def _escape_one(m: re.Match[str]) -> str:
    return repr(m.group())[1:-1]  # "\n", "\t", "\x1b", "\u2028", "\udce9"


def escaped(text: str) -> str:
    """``text`` as a one-line message shows a path: as it is, unless it holds a control
    character or a lone surrogate (:data:`_CONTROL`), then with those escaped as Python writes
    them (``\\udce9`` for a name's byte 0xE9 that is not UTF-8) and its backslashes doubled
    (so that ``a\\nb`` is not read as ``a``, newline, ``b``).

    Parameters
    ----------
    text : str
        A path or a part of one.

    Returns
    -------
    str
        One line.

    Examples
    --------
    >>> escaped("my scans/é.png")
    'my scans/é.png'
    >>> print(escaped("a\\nb.png"), escaped("\\x1b[2Jx.png"))
    a\\nb.png \\x1b[2Jx.png
    """
    if not _CONTROL.search(text):
        return text
    return _CONTROL.sub(_escape_one, text.replace("\\", "\\\\"))


def escape_paths(message: str, paths: Iterable[object] = ()) -> str:
    """``message`` with each part of ``paths`` that holds a control character shown
    :func:`escaped`, wherever it is in the message (the path as given, made absolute or joined
    to a file name under it): a path holding a newline cut a one-line message in two, its
    first line naming another file (``image file not found: a`` for ``a\\nb.png``).

    Parameters
    ----------
    message : str
        An error message, which may name the paths.
    paths : iterable
        The paths the message may name (str or os.PathLike; others are passed over).

    Returns
    -------
    str
        ``message``, the paths in it escaped; its own line breaks kept.

    Examples
    --------
    >>> print(escape_paths("image file not found: scans/a\\nb.png", ["a\\nb.png"]))
    image file not found: scans/a\\nb.png
    """
    # by the system's separators alone: a POSIX name's backslash is its own, to be doubled
    seps = "".join(re.escape(s) for s in (os.sep, os.altsep) if s)
    parts: set[str] = set()
    for p in paths:
        if isinstance(p, str | os.PathLike):
            text = os.fspath(p)
            if isinstance(text, str) and _CONTROL.search(text):
                # by its parts: the message may name it absolute, or a file under it
                parts |= {x for x in re.split(f"[{seps}]", text) if _CONTROL.search(x)}
    if not parts:
        return message
    # A part that opens or ends with a control character matches only as a whole name, what
    # bounds a name before and after it: "a\n" of "scans/a\n" is also in "data\nhint" and
    # "data\n\nhint", "\nb" of "scans/\nb" in "cannot read:\nbad", the message's own break.
    alternatives = []
    for part in sorted(parts, key=len, reverse=True):
        pattern = re.escape(part)
        if _CONTROL.match(part) or _CONTROL.match(part[-1]):
            pattern = _NAME_BEFORE + pattern + _NAME_AFTER
        alternatives.append(pattern)
    return re.sub("|".join(alternatives), lambda m: escaped(m.group()), message)


#: What may stand before (after) a name in a message: its start (end), a separator, a space,
#: a quote or a bracket, punctuation after it.
_NAME_BEFORE = r"""(?<![^ /\\'"`(\[{<:=,])"""
_NAME_AFTER = r"""(?![^\s/\\'"`)\]}>:;,.!?\x00-\x1f\x7f-\x9f\u2028\u2029])"""


#: RuntimeError's subclasses that are a bug of ours, never a failure to say as it is: a
#: recursion past Python's limit, a method no subclass implemented. The CLI and the GUI said
#: them as an expected error (a RuntimeError), without "internal" or a trace in the log.
BUG_ERRORS = (RecursionError, NotImplementedError)


def internal_error(exc: BaseException) -> str:
    """The one line the CLI and ``python -m stereovision.gui`` print for an unexpected error (a
    bug of ours), instead of a traceback.

    Parameters
    ----------
    exc : BaseException
        The error.

    Returns
    -------
    str
        ``"stereovision: error: internal TYPE: FIRST LINE (please report this)"``, or
        ``"... internal TYPE (please report this)"`` for an error without a message.

    Examples
    --------
    >>> internal_error(KeyError("k"))
    "stereovision: error: internal KeyError: 'k' (please report this)"
    """
    # without a message (a bare assert) the type alone: "AssertionError:  (" said nothing twice
    what = type(exc).__name__ + (f": {first_line(exc)}" if _message(exc).strip() else "")
    return f"stereovision: error: internal {what} (please report this)"


def finite_number(value: object, name: str) -> float:
    """``value`` as a finite Python float.

    A size-1 array is its value (as :func:`positive_finite`). An integer too large for a
    float (``2**1100``: its number of digits is shown), NaN, an infinity or a non-number is a
    ``ValueError`` naming ``name``, not an OverflowError or NumPy's "ufunc 'isfinite' not
    supported" (which a Python int beyond 64 bits gave).

    Examples
    --------
    >>> finite_number(2**70, "max_disparity")
    1.1805916207174113e+21
    >>> finite_number(np.array(3.0), "blur")
    3.0
    >>> finite_number(float("nan"), "blur")
    Traceback (most recent call last):
    ...
    ValueError: blur: expected a finite number, got nan
    """
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name}: expected a finite number, got {_shown(value)}")
    if too_large_for_float(value):  # finite, only too large for a float: say so, not its digits
        raise ValueError(f"{name}: expected a finite number, got {number_shown(value)}")
    try:
        out = _real_scalar(value)
    except TypeError:
        raise ValueError(f"{name}: expected a finite number, got {_shown(value)}") from None
    if not math.isfinite(out):
        raise ValueError(f"{name}: expected a finite number, got {_shown(value)}")
    return out


def float32_reach(value: _T) -> _T | float:
    """``value`` as a float32 map's comparison reads it: itself within float32's range, else
    its signed infinity.

    A tolerance or radius of 1e308 (or ``10**300``) compared with a float32 map is cast to
    float32 first, as its infinity, which reads it right (every difference is within it), but
    the cast printed NumPy's "RuntimeWarning: overflow encountered in cast". Values within the
    range are returned as given, for the same results.

    Examples
    --------
    >>> float32_reach(2.0), float32_reach(1e308), float32_reach(-(10**300))
    (2.0, inf, -inf)
    """
    v = float(value)  # type: ignore[arg-type]
    if abs(v) <= float(np.finfo(np.float32).max):
        return value
    return math.copysign(math.inf, v)


def refuse_beyond_float32(a: npt.NDArray[Any], name: str, fate: str) -> None:
    """Refuse a float64 (or wider) array holding finite values beyond float32's range.

    The float32 cast makes a finite 1e300 an inf with only NumPy's overflow warning; ``fate``
    says what would then become of it ("would be written as inf"). Narrower floats and
    integers pass unlooked-at (no integer reaches float32's max).

    Parameters
    ----------
    a : numpy.ndarray
        The array about to be cast to float32.
    name : str
        The argument's name, for the message.
    fate : str
        What the cast would make of such a value, for the message.

    Raises
    ------
    ValueError
        If ``a`` holds a finite value beyond float32's range.

    Examples
    --------
    >>> refuse_beyond_float32(np.array([1.0, 1e300]), "arr", "would be written as inf")
    Traceback (most recent call last):
    ...
    ValueError: arr: 1 finite value(s) beyond float32's range (e.g. 1e+300) would be written as inf
    """
    if a.dtype.kind != "f" or a.dtype.itemsize <= 4:
        return
    with np.errstate(invalid="ignore"):
        big = np.isfinite(a) & (np.abs(a) > float(np.finfo(np.float32).max))
    if big.any():
        raise ValueError(
            f"{name}: {int(big.sum())} finite value(s) beyond float32's range (e.g. "
            f"{float(a[big][0])!r}) {fate}"
        )


def _whole(v: float) -> str:
    """``v`` as Python writes it, a whole number without ".0" (10, not 10.0; 10.0000001)."""
    return str(int(v)) if v.is_integer() and abs(v) < 1e16 else repr(v)


def disparity_range(min_disparity: object, max_disparity: object) -> tuple[float, float]:
    """Check a disparity search range ``[min_disparity, max_disparity]``: both finite numbers
    (:func:`finite_number`), the maximum the larger; the kernels' own messages named their
    ``d_min`` and ``d_max``.

    Examples
    --------
    >>> disparity_range(0, 64)
    (0.0, 64.0)
    >>> disparity_range(32, 32)
    Traceback (most recent call last):
    ...
    ValueError: empty disparity range: max_disparity (32) must be larger than min_disparity (32)
    >>> disparity_range(10, 10.0000001)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: empty disparity range in float32, ... are the same float32 number (10); ...
    """
    lo = finite_number(min_disparity, "min_disparity")
    hi = finite_number(max_disparity, "max_disparity")
    if not hi > lo:
        raise ValueError(
            "empty disparity range: "
            f"max_disparity ({max_disparity}) must be larger than min_disparity ({min_disparity})"
        )
    # the kernels take float32: 10 to 10.0000001 (or 1e8 to 1e8 + 1) is one float32 number, and
    # their own "invalid parameter `d_max`: must be > d_min (10), got 10" named neither argument
    top = float(np.finfo(np.float32).max)
    if abs(lo) <= top and abs(hi) <= top and not np.float32(hi) > np.float32(lo):
        raise ValueError(
            "empty disparity range in float32, the matchers' precision: max_disparity "
            f"({_whole(hi)}) and min_disparity ({_whole(lo)}) are the same float32 number "
            f"({float(np.float32(lo)):.9g}); give a wider range"
        )
    return lo, hi


def xy_points(points: object, name: str = "points") -> npt.NDArray[np.float64]:
    """``points`` as an ``(N, 2)`` float64 array of ``(x, y)`` pixels.

    A ``(2, N)`` array (Bouguet's layout) or homogeneous ``(N, 3)`` points are a ``ValueError``
    naming the shape (and the transpose for the first), not points reshaped and mapped as
    others; so is what holds no real numbers (:data:`NOT_NUMBERS`, text, None, complex) or
    what NumPy cannot read as an array (a ragged list): the float64 cast read ``'1'`` as 1,
    None as NaN, True as 1 and 3 ns as 3, and said the rest in NumPy's words naming nothing.

    Examples
    --------
    >>> xy_points([[1, 2], [3, 4]]).shape
    (2, 2)
    >>> xy_points(np.zeros((2, 5)))
    Traceback (most recent call last):
    ...
    ValueError: points: expected shape (N, 2) of (x, y), got (2, 5) (transpose a (2, N) array)
    """
    try:
        raw = np.asarray(points)
    except (ValueError, TypeError):  # ragged nested lists
        raise ValueError(
            f"{name}: expected an (N, 2) array of (x, y), got {type(points).__name__} that "
            "NumPy cannot read as an array"
        ) from None
    real = raw.dtype.kind in "iuf" or (
        raw.dtype == object
        and all(
            isinstance(v, (numbers.Real, decimal.Decimal)) and not isinstance(v, NOT_NUMBERS)
            for v in raw.flat
        )
    )
    if not real:
        raise ValueError(f"{name}: expected (x, y) pixels as numbers, got dtype {raw.dtype}")
    try:
        pts = raw.astype(np.float64, copy=False)  # a float64 array as given, not a copy: as before
    except OverflowError:  # an int past a float's range (10**400): Python's words, naming nothing
        raise ValueError(
            f"{name}: expected (x, y) pixels as numbers, got an integer too large for a float"
        ) from None
    if pts.ndim != 2 or pts.shape[1] != 2:
        hint = (
            " (transpose a (2, N) array)"
            if pts.ndim == 2 and pts.shape[0] == 2 and pts.shape[1] != 2
            # one pixel as its (x, y), as triangulate's points say it: the shape alone did not
            # say what to pass
            else " (one point: [[x, y]])"
            if pts.shape == (2,)
            else ""
        )
        raise ValueError(f"{name}: expected shape (N, 2) of (x, y), got {pts.shape}{hint}")
    return pts


#: The classes :func:`require` checks for, by name, and their modules (imported on use: the
#: modules that check do not import them at load time).
_CLASSES = {
    "Calibration": "stereovision.calibration",
    "DepthResult": "stereovision.depth",
    "GroundPlane": "stereovision.ground",
}


def refuse_unknown(what: str, given: object, valid: object, where: str = "") -> None:
    """Raise ``ValueError`` naming the unknown keys of ``given``, the nearest valid spelling of
    each and every valid key (``where``: the name of the defaults' dict, for the docs).

    Examples
    --------
    >>> refuse_unknown("MCGM parameter", {"ght_min_scor": 1}, ["ght_min_score", "k_cand"])
    Traceback (most recent call last):
    ...
    ValueError: unknown MCGM parameter(s) ['ght_min_scor'] (did you mean 'ght_min_score'?): \
expected one of ght_min_score, k_cand
    """
    import difflib

    keys = sorted(str(k) for k in valid)  # type: ignore[attr-defined]
    unknown = sorted(set(given) - set(keys))  # type: ignore[call-overload]
    if not unknown:
        return
    near = [m[0] for u in unknown if (m := difflib.get_close_matches(u, keys, n=1, cutoff=0.7))]
    hint = f" (did you mean {', '.join(repr(n) for n in near)}?)" if near else ""
    src = f" ({where})" if where else ""
    raise ValueError(f"unknown {what}(s) {unknown}{hint}: expected one of {', '.join(keys)}{src}")


def require(value: object, kind: str, name: str) -> None:
    """A TypeError naming the argument when ``value`` is not a ``stereovision.<kind>`` (None
    included): a public function given the wrong object says so instead of failing on an
    attribute deep inside.

    Parameters
    ----------
    value : object
        The argument.
    kind : str
        ``"Calibration"``, ``"DepthResult"`` or ``"GroundPlane"``.
    name : str
        The argument's name.
    """
    import importlib

    cls = getattr(importlib.import_module(_CLASSES[kind]), kind)
    if not isinstance(value, cls):
        path = path_given(value) if kind == "Calibration" else None
        if path is not None:  # a calib.txt's name, as depth_map says it
            raise TypeError(
                f"{name}: got the path {path!r}, not a calibration: read it first "
                "(stereovision.Calibration.from_file(path))"
            )
        raise TypeError(f"{name}: expected a stereovision.{kind}, got {type(value).__name__}")


def not_a_result(value: object, name: str, field: str) -> None:
    """A TypeError when a whole ``DepthResult`` is passed where one of its arrays is meant,
    saying which (it failed deep inside with "float() argument must be ... not 'DepthResult'").
    """
    if type(value).__name__ == "DepthResult" and hasattr(value, "disparity"):
        raise TypeError(f"{name}: got a DepthResult; pass its array, result.{field}")


def remap_image(img: np.ndarray, *args: Any, **kwargs: Any) -> np.ndarray:
    """``cv2.remap`` of an image of any dtype :func:`as_image_array` accepts, returned in that
    dtype: float16 and long-double images (which OpenCV's remap refuses) go through float32 /
    float64."""
    import cv2

    work = img
    if img.dtype.kind == "f" and img.dtype.itemsize == 2:
        work = img.astype(np.float32)
    elif img.dtype.kind == "f" and img.dtype.itemsize > 8:
        work = img.astype(np.float64)
    out = np.asarray(cv2.remap(work, *args, **kwargs))
    return out if out.dtype == img.dtype else out.astype(img.dtype)


def user_stacklevel() -> int:
    """The ``stacklevel`` that points a warning at the first frame outside this package.

    For a warning raised by a helper that public functions reach at different depths (the
    swapped-pair warning: ``estimate_max_disparity`` called directly, or through ``depth_map``
    or ``match``), where a fixed ``stacklevel`` is right for one path only.

    Returns
    -------
    int
        The level to pass to :func:`warnings.warn` from the function calling this one.
    """
    frame = sys._getframe(1)  # the function that will call warnings.warn: stacklevel 1
    level = 1
    while frame.f_back is not None and _inside_package(frame):
        frame = frame.f_back
        level += 1
    return level


#: A source's warnings held for the caller in this context (:func:`source_warning`): the
#: stream's grabbing thread sets it, as a warning raised there pointed at threading.py.
HELD_WARNINGS: contextvars.ContextVar[list[tuple[str, type[Warning]]] | None] = (
    contextvars.ContextVar("stereovision_held_warnings", default=None)
)


def points_as_float32(raw: np.ndarray) -> tuple[np.ndarray, str | None]:
    """``raw`` (N, 3) points cast to float32, and how many became inf in the cast (a finite
    coordinate beyond float32's range, ``1e39``), with an example, or None.

    The cast itself is silent (NumPy's "overflow encountered in cast" named nothing); the
    caller says the words (``read_ply``'s file, ``point_cloud``'s points)."""
    if raw.dtype == object:
        # a list holding an int past int64 (10**39) is an object array: its cast made the int
        # inf without a word, and one past a float64 (10**400) was NumPy's bare OverflowError
        flat = list(raw.flat)
        over_flat = np.zeros(len(flat), bool)
        wide_flat = np.empty(len(flat))
        for i, v in enumerate(flat):
            try:
                # NumPy's own element cast, as the array cast had it: None is NaN (a missing
                # coordinate, dropped), not float()'s TypeError; what is no number raises
                wide_flat[i] = v
            except OverflowError:
                wide_flat[i], over_flat[i] = (math.inf if v > 0 else -math.inf), True
        wide, over = wide_flat.reshape(raw.shape), over_flat.reshape(raw.shape)
        with np.errstate(over="ignore"):
            pts = wide.astype(np.float32)
        lost = over | (np.isfinite(wide) & ~np.isfinite(pts))
        if lost.any():
            n = int(lost.any(axis=-1).sum()) if lost.ndim > 1 else int(lost.sum())
            first = flat[int(np.flatnonzero(lost.ravel())[0])]
            shown = too_large_for_float(first, why=False) or repr(float(first))
            return pts, f"{n} point(s) with a coordinate beyond float32's range (e.g. {shown})"
        return pts, None
    with np.errstate(over="ignore"):
        pts = np.asarray(raw, dtype=np.float32)
    if raw.dtype.kind == "f" and raw.dtype.itemsize > 4:
        with np.errstate(invalid="ignore"):
            lost = np.isfinite(raw) & ~np.isfinite(pts)
        if lost.any():
            n = int(lost.any(axis=-1).sum()) if lost.ndim > 1 else int(lost.sum())
            return pts, (
                f"{n} point(s) with a coordinate beyond float32's range "
                f"(e.g. {float(raw[lost][0])!r})"
            )
    return pts, None


def source_warning(message: str, category: type[Warning] = UserWarning) -> None:
    """Warn at the first line outside the package (:func:`user_stacklevel`), or, in a thread
    reading a source for the caller (:data:`HELD_WARNINGS` set), hold the warning for the
    caller's thread to give at its own line.

    Parameters
    ----------
    message : str
        The warning's text.
    category : type of Warning
        Its category.
    """
    held = HELD_WARNINGS.get()
    if held is not None:
        held.append((message, category))
        return
    warnings.warn(message, category, stacklevel=user_stacklevel())


_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _inside_package(frame: Any) -> bool:
    """Whether ``frame`` runs this package's code: its files, and the ``__init__`` that
    :mod:`dataclasses` generates for its classes (file ``<string>``) with ``dataclasses.replace``
    calling it: a :class:`~stereovision.calibration.Calibration`'s warning pointed there."""
    code = frame.f_code
    if code.co_filename.startswith(_PACKAGE_DIR):
        return True
    if code.co_filename == "<string>" or code.co_filename == dataclasses.__file__:
        made = frame.f_locals.get("self", frame.f_locals.get("obj"))
        return type(made).__module__.startswith(f"{__package__}.")
    return False


def renamed_keyword(old: str, new: str) -> Callable[[_F], _F]:
    """Keep a renamed parameter's old keyword working, with a :class:`DeprecationWarning`.

    The decorated function's signature (what ``help``, ``inspect.signature`` and type checkers
    see) has the new name only; a call with ``old=`` is passed on as ``new=``, warned about at
    the caller's line; a call with both is a :class:`TypeError` naming both. The wrapper is one
    more frame: a warning the function itself gives with a ``stacklevel`` counts it. Stacked
    (one decorator per renamed parameter) they still make one wrapper, so one frame.

    Parameters
    ----------
    old : str
        The parameter's former name.
    new : str
        Its name now.

    Returns
    -------
    callable
        A decorator.
    """

    def decorate(func: _F) -> _F:
        renames: dict[str, str] = {old: new}
        inner = getattr(func, "_renamed_keywords", None)
        if inner is not None:  # another renamed_keyword below: one wrapper for both
            renames.update(inner)
            func = func.__wrapped__  # type: ignore[attr-defined]
        signature = inspect.signature(func)
        for now in renames.values():
            if now not in signature.parameters:
                raise TypeError(f"{func.__qualname__}() has no parameter {now}= to rename to")
        name = func.__qualname__
        if name.endswith(".__init__"):  # a class: called by its own name
            name = name[: -len(".__init__")]

        @functools.wraps(func)
        def call(*args: Any, **kwargs: Any) -> Any:
            for was, now in renames.items():
                if was not in kwargs:
                    continue
                if now in kwargs or now in signature.bind_partial(*args).arguments:
                    raise TypeError(f"{name}() got {was}= and {now}=: {was} is {now}'s old name")
                warnings.warn(
                    f"{name}(): the keyword {was}= is now {now}= ({was}= will be removed)",
                    DeprecationWarning,
                    stacklevel=2,
                )
                kwargs[now] = kwargs.pop(was)
            return func(*args, **kwargs)

        call._renamed_keywords = renames  # type: ignore[attr-defined]
        return cast(_F, call)

    return decorate
