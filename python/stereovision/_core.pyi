"""Typed stub of the Rust extension ``stereovision._core`` (see rust/py/src).

An integer argument outside its Rust type's range (a negative count, ``2**64``) is a
``ValueError`` naming the argument and the range; one that is no integer, a ``TypeError``.
"""

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = [
    "__version__",
    "depth_rectified",
    "fattened",
    "fill_planes",
    "gabor_disparity",
    "gabor_lr_check",
    "gabor_newton_step",
    "gabor_remove_speckles",
    "gabor_responses",
    "graph_segments",
    "gray_u8",
    "hopfield_candidates",
    "hopfield_interest",
    "hopfield_match",
    "hopfield_match_u8",
    "kept_memory",
    "lzf_decompress",
    "mcgm_curves",
    "mcgm_filter",
    "mcgm_log",
    "mcgm_match",
    "plane_fill",
    "quantised_regions",
    "refine_disparity",
    "release_memory",
    "row_fill",
    "sgm_disparity",
    "side_fill",
    "temporal_grey_difference",
    "temporal_running_mean",
]

__version__: str

# --- Gabor phase-disparity channel (rust/py/src/gabor.rs) ---------------------------------------

def gabor_disparity(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    d_min: float,
    d_max: float,
    *,
    freq: float = 0.25,
    orientations_deg: Sequence[float] | None = None,
    bandwidth_oct: float = 1.5,
    aspect: float = 1.0,
    n_levels: int | None = None,
    iters_per_level: int = 1,
    amp_rel_thresh: float = 0.02,
    stability_tau: float = 1.25,
    smooth_sigma: float | None = None,
    conf_min: float = 0.15,
    research_radius: int = 3,
    search_pool_radius: int = 0,
    lr_check: bool = True,
    lr_tol: float = 1.5,
    lr_coarse_levels: int = 1,
    iters_finest: int = 1,
    research_finest: bool = True,
    orientations_finest: int = 1,
    fine_levels: int = 1,
    lr_light: bool = False,
    speckle_size: int = 100,
    speckle_range: float = 1.0,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """Dense Gabor phase disparity; ``(disparity, confidence)`` float32 (H, W), NaN = none."""

def gabor_responses(
    img: npt.NDArray[np.float32],
    freq: float = 0.25,
    theta_deg: float = 0.0,
    bandwidth_oct: float = 1.5,
    aspect: float = 1.0,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """Zero-DC complex response of one channel as ``(re, im)`` float32 (H, W)."""

def gabor_newton_step(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    disp: npt.NDArray[np.float32],
    *,
    freq: float = 0.25,
    orientations_deg: Sequence[float] | None = None,
    bandwidth_oct: float = 1.5,
    aspect: float = 1.0,
    amp_rel_thresh: float = 0.02,
    stability_tau: float = 1.25,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """One raw full-resolution Newton step at ``disp``: ``(delta, conf)`` before smoothing."""

def gabor_lr_check(
    disp_left: npt.NDArray[np.float32],
    disp_right: npt.NDArray[np.float32],
    tol: float = 1.0,
) -> npt.NDArray[np.bool_]:
    """Left-right consistency mask (``disp_right`` on the right-image grid)."""

def gabor_remove_speckles(
    disp: npt.NDArray[np.float32], min_size: int, max_diff: float
) -> npt.NDArray[np.float32]:
    """A copy with 4-connected regions (neighbours within ``max_diff``) smaller than
    ``min_size`` pixels set to NaN."""

# --- Hopfield network channel (rust/py/src/hopfield.rs) ------------------------------------------

def hopfield_interest(
    img: npt.NDArray[np.float32],
    rel_threshold: float = 1e-3,
    nms_half: int = 1,
    tile: int = 64,
    floor_rel: float = 1e-4,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.int32], npt.NDArray[np.float32]]: ...
def hopfield_match(
    left: npt.NDArray[np.float32], right: npt.NDArray[np.float32], params: dict[str, Any]
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float64], dict[str, Any]]: ...
def hopfield_match_u8(
    left: npt.NDArray[np.uint8],
    right: npt.NDArray[np.uint8],
    weights: tuple[float, float, float],
    params: dict[str, Any],
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float64], dict[str, Any]]: ...
def hopfield_candidates(
    left: npt.NDArray[np.float32], right: npt.NDArray[np.float32], params: dict[str, Any]
) -> npt.NDArray[np.float32]: ...

# --- Multi-channel graph matching (rust/py/src/mcgm.rs) -----------------------------------------

def mcgm_log(img: npt.NDArray[np.float32], sigma: float) -> npt.NDArray[np.float32]:
    """Separable zero-mean scale-normalised LoG, ``(H, W)`` float32."""

def mcgm_curves(img: npt.NDArray[np.float32], params: dict[str, Any]) -> list[dict[str, Any]]:
    """Per channel: LoG, zero-crossing maps, labels, segments and R-tables (see ChannelCurves)."""

def mcgm_match(
    left: npt.NDArray[np.float32], right: npt.NDArray[np.float32], params: dict[str, Any]
) -> tuple[npt.NDArray[np.float32], dict[str, Any], list[dict[str, Any]]]:
    """``(matches (N, 6) [xl, yl, xr, yr, score, channel], stats, per-channel debug dicts)``."""

def mcgm_filter(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    matches: npt.NDArray[np.float32],
    params: dict[str, Any],
) -> npt.NDArray[np.bool_]:
    """B.8 occlusion filters on ``(N, 4)`` matches: kept flags. ``ValueError``: a row with a
    NaN or infinite coordinate, or a point outside the images (``-0.5 .. W - 0.5``,
    ``-0.5 .. H - 0.5``)."""

# --- Hole fills (rust/py/src/fill.rs, segment.rs) -------------------------------------------------

def graph_segments(
    image: npt.NDArray[np.float32], k: float, min_size: int
) -> npt.NDArray[np.uint32]:
    """Felzenszwalb-Huttenlocher segments of an ``(H, W, C)`` image, labels in raster order of
    first pixels (``k`` 0: the regions of equal value)."""

def quantised_regions(
    image: npt.NDArray[np.uint8], step: int, offset: int
) -> npt.NDArray[np.uint32]:
    """Regions of equal bin ``(value + offset) // step`` of an ``(H, W, C)`` uint8 image (C 1-3),
    labels in raster order of first pixels (``graph_segments`` with ``k`` 0 on the bins)."""

def plane_fill(
    disp: npt.NDArray[np.float32],
    labels: npt.NDArray[np.uint32],
    min_pixels: int,
    max_residual: float,
    lo: float,
    hi: float,
) -> tuple[npt.NDArray[np.float32], int, int]:
    """Holes filled by their segment's plane; ``(filled, planes used, holes filled)``."""

def fill_planes(
    disp: npt.NDArray[np.float32],
    image: npt.NDArray[np.uint8],
    passes: list[tuple[int, int]],
    max_residual: float,
) -> npt.NDArray[np.float32]:
    """``planes.fill_planes``'s passes ``(step, min_pixels)`` on the blurred ``(H, W, C)`` image:
    per pass two cuts (offsets 0 and ``step // 2``), their planes, the mean where both fill.
    ``ValueError``: an image of another size or C outside 1-3, a step outside 1-255."""

def row_fill(disp: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    """A copy with each hole (non-finite) given the smaller of the nearest valid values left and
    right of it in its row (one side only: that one; none: NaN)."""

def side_fill(
    disp: npt.NDArray[np.float32], lab: npt.NDArray[np.float32], tau: float
) -> npt.NDArray[np.float32]:
    """A copy where each hole run with a nearer left than right neighbour in its row takes, per
    pixel, the left value if its ``(H, W, 3)`` colour is closer to the left neighbour's by more
    than ``tau``, else the right value; other holes stay. ``ValueError``: ``lab`` of another
    size, a negative ``tau``."""

def fattened(
    disp: npt.NDArray[np.float32],
    guide: npt.NDArray[np.float32],
    radius: int,
    ratio: float,
    jump: float,
) -> npt.NDArray[np.bool_]:
    """The pixels between a disparity jump (> ``jump``, on the row-filled map) and the strongest
    step of ``guide`` within ``radius`` on its background side, if that step is ``ratio`` times
    the one at the jump; along rows and along columns (a ``radius`` beyond the map: the whole
    row or column). ``ValueError``: shapes differ, a negative ``ratio`` / ``jump``, or a NaN or
    inf in ``guide`` (an image)."""

# --- Triangulation (rust/py/src/triangulation.rs) ------------------------------------------------

def depth_rectified(
    disp: npt.NDArray[np.float32],
    conf: npt.NDArray[np.float32],
    fb: float,
    doffs: float,
    s0: float,
    slope: float,
    s_min: float,
    s_fill: float,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """``(Z, sigma_Z)``: ``fb / (d + doffs)``, ``Z max(s0 + slope clip(c), s_min) / (d+doffs)``
    (``Z s_fill / (d + doffs)`` where ``c < 0``); NaN where ``d`` is not finite or ``d + doffs``
    is not above that ``sigma_d``."""

def refine_disparity(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    disp: npt.NDArray[np.float32],
    conf: npt.NDArray[np.float32],
    d_min: float,
    d_max: float,
    base_sigma: float,
    win_sigma: float,
    win_radius: int,
    search: int,
    step: float,
    fill_search: int,
    fill_step: float,
    var_floor: float,
    fills: list[tuple[float, float]],
    fill_confidence: float,
    fill_plane: bool,
    fill_max_residual: float,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32], int]:
    """``(disparity, confidence, n_filled)``: ZNCC sub-pixel refinement and validated fill."""

def sgm_disparity(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    d_min: int,
    d_max: int,
    p1: int,
    p2: int,
    gamma: float,
    uniqueness: int,
    lr_tol: int,
    edge_margin: int,
    paths: int = 8,
) -> npt.NDArray[np.float32]:
    """Census semi-global disparity over ``[d_min, d_max]``, NaN where rejected; ``paths`` 8
    (two passes over a cost volume) or 3 (left, right and top, one pass)."""

def gray_u8(
    image: npt.NDArray[np.uint8], weights: tuple[float, float, float]
) -> npt.NDArray[np.float32]:
    """Grey ``float32`` in ``[0, 1]`` of an ``(H, W)`` or ``(H, W, 1|3|4)`` uint8 image (BGR
    order, any memory layout), bit-identical to ``as_gray_float``'s NumPy path."""

def temporal_grey_difference(
    frame: npt.NDArray[np.uint8], mean: npt.NDArray[np.float32]
) -> npt.NDArray[np.float32]:
    """``(H, W)`` grey value of ``frame - mean`` (channel weights B 0.114, G 0.587, R 0.299;
    alpha 0), both ``(H, W)`` or ``(H, W, 1|3|4)``."""

def temporal_running_mean(
    frame: npt.NDArray[np.uint8],
    mean: npt.NDArray[np.float32],
    count: npt.NDArray[np.uint8],
    diff: npt.NDArray[np.float32],
    ks: float,
    max_frames: int,
) -> npt.NDArray[np.uint8]:
    """One more frame into ``mean`` and ``count``, in place (both C-contiguous, else a
    ``ValueError`` naming the one that is not); returns the mean rounded to uint8. A pixel
    with ``|diff| <= ks sqrt(1 + 1/count)`` keeps averaging (``count`` up to ``max_frames``),
    any other starts again from the frame."""

def release_memory() -> int:
    """Return the memory the extension keeps for the next call to the system; bytes released."""

def kept_memory() -> tuple[tuple[int, int], int]:
    """``((blocks, bytes), pool_bytes)``: freed blocks of >= 128 KiB the allocator keeps (128 MiB
    at most), and the kernels' own pools: the Gabor planes' (256 MiB at most) and the census
    matcher's cost volume and row sums (256 MiB at most)."""

# --- LZF decompression (rust/py/src/lzf.rs) ------------------------------------------------------

def lzf_decompress(data: bytes | bytearray | memoryview, out_len: int) -> bytes:
    """The ``out_len`` bytes the LZF stream ``data`` (any bytes-like object) decompresses to
    (liblzf's ``lzf_decompress``: PCL's ``binary_compressed`` PCD data). A damaged or cut
    stream, or one that does not decompress to exactly ``out_len`` bytes, is a ``ValueError``
    saying what is wrong; an ``out_len`` more than 88 times the size of ``data`` in bytes is
    refused before any allocation; ``data`` that is not bytes-like is a ``TypeError``."""
