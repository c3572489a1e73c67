"""Semi-global matching on a census cost: the fused dense map's completion (issue 5).

The kernel lives in ``rust/core/src/matching/sgm.rs``: a 9x7 census of each image, the Hamming
distance as the cost, aggregation along 8 paths (Hirschmueller 2008) with an intensity-adaptive
P2, winner-take-all with a uniqueness test, a left-right check and a parabola vertex. It is not
one of the paper's three channels: :func:`stereovision.matching.fusion.fused_dense` uses it where
the Gabor channel has no value, and as a second opinion where it has one (algorithms.md A.9: a
filled SGBM is beaten only with global aggregation). ``depth_map(method="census")`` runs it
alone, re-measured, checked and filled as the fused map is (README, "Choosing a mode").
NumPy reference: ``tests/reference/sgm_ref.py``.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np
import numpy.typing as npt

from stereovision import _core
from stereovision._validate import (
    NOT_NUMBERS,
    _shown,
    as_gray_float,
    check_pair,
    finite_number,
    float_sized,
    refuse_unknown,
    refuse_unreachable_range,
    whole_value,
)

__all__ = ["DEFAULTS", "sgm_disparity"]

#: Default parameters (mirror ``SgmParams::default`` in Rust). Chosen once on the 17 shared
#: scenes (docs/fusion.md); the same for every scene.
DEFAULTS: dict[str, Any] = {
    "p1": 8,  # penalty of a 1-level change between path neighbours (census bits)
    "p2": 96,  # penalty of a larger jump, before the intensity adaptation
    "gamma": 16.0,  # grey levels (0-255) of intensity step per halving of P2
    "uniqueness": 5,  # %: another level (beyond +-1) this close to the winner rejects the pixel
    "lr_tol": 1,  # levels: left-right check tolerance
    # columns: in the left band (x < max_disparity) the winner's right pixel must lie this far
    # inside the right image (a match outside pushes the winner against the edge)
    "edge_margin": 4,
    # aggregation paths: 8 (Hirschmueller's, two passes over a cost volume) or 3 (left to right,
    # right to left, top to bottom: OpenCV SGBM-3WAY's set, one pass, no volume; about 0.6 x
    # the time, README "Choosing a mode")
    "paths": 8,
}

# Bytes per (pixel, level) cell at the kernel's peak: the u8 cost volume, and a u16 sum row for
# every row when the two aggregation passes meet in the middle (measured: a 3840 x 2160 pair
# over 577 levels peaked at 14.7 GB for the whole default depth_map, 4.8 G cells).
_BYTES_PER_CELL = 3
# paths=3 holds rows, not a volume: at most THREE_PATHS_LEAD + 1 (9) rows wait for the vertical
# path, one is being filled and one selected; the census codes take 16 bytes a pixel.
_ROWS_IN_FLIGHT_3 = 8 + 3
_MAX_LEVELS = 2048  # the kernel's limit
# The kernel's P2 limit (`MAX_P2` in sgm.rs: eight path costs of OUTSIDE + p2 fit a u16 sum); it
# also wants 0 < p1 < p2, so p1 is at most MAX_P2 - 1 and p2 at least 2.
_MAX_P2 = 4000
_F32_MAX = float(np.finfo(np.float32).max)  # gamma reaches the kernel as an f32
_I32_LIMIT = 2**31 - 1  # |min_disparity|, |max_disparity| below it: the kernel's i32 levels


def _address_space_room() -> int | None:
    """Bytes of address space left under the process's ``RLIMIT_AS`` (``ulimit -v``): the soft
    limit less the current ``VmSize``; None without a limit or where either cannot be read."""
    try:
        import resource
    except ImportError:  # not on Windows
        return None
    try:
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft == resource.RLIM_INFINITY:
            return None
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmSize:"):
                    return max(soft - int(line.split()[1]) * 1024, 0)
    except (OSError, ValueError):
        pass
    return None


def _available_bytes() -> int | None:
    """Memory this process can still take: Linux's MemAvailable, lowered by a cgroup v2 limit
    (a container's ``memory.max``) and by the address space left under ``RLIMIT_AS``
    (``ulimit -v``) when they are set; None where none can be read."""
    avail: int | None = None
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    avail = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError):
        pass
    try:
        with open("/sys/fs/cgroup/memory.max") as f:
            limit = f.read().strip()
        if limit != "max":
            with open("/sys/fs/cgroup/memory.current") as f:
                room = int(limit) - int(f.read().strip())
            avail = room if avail is None else min(avail, room)
    except (OSError, ValueError):
        pass
    as_room = _address_space_room()
    if as_room is not None:
        avail = as_room if avail is None else min(avail, as_room)
    return avail


def _check_memory(width: int, height: int, levels: int, paths: int = 8) -> None:
    """MemoryError, naming the sizes and what to change, when the kernel's peak would not fit:
    past that point the system's OOM killer ends the whole process (on a robot, every node in
    it) instead of one call failing."""
    rows = height if paths == 8 else min(height, _ROWS_IN_FLIGHT_3)
    need = _BYTES_PER_CELL * width * rows * levels + (0 if paths == 8 else 16 * width * height)
    avail = _available_bytes()
    if avail is None:
        return
    # Buffers kept from the previous call are reused or handed back, not allocated again.
    (_, allocator_kept), pools_kept = _core.kept_memory()
    avail += allocator_kept + pools_kept
    if need > avail:
        raise MemoryError(
            f"the census semi-global map needs about {need / 2**30:.1f} GiB for a {width}x"
            f"{height} pair over {levels} disparity levels, and {avail / 2**30:.1f} GiB is "
            "available: lower max_disparity, shrink the pair, or use method='fast' or 'gabor'"
        )


def sgm_disparity(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0.0,
    **params: Any,
) -> npt.NDArray[np.float32]:
    """Dense disparity of a rectified pair by census semi-global matching.

    Parameters
    ----------
    left, right : array_like
        Rectified pair, ``(H, W)`` grey (or anything :func:`as_gray_float` takes), same shape.
    max_disparity, min_disparity : float
        Search range (px); rounded outwards to integers. A range past the image's width is searched
        to the image's edge, without the error :func:`stereovision.match` raises (see
        :mod:`stereovision.matching`).
    **params
        :data:`DEFAULTS`' keys.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` float32 disparity, NaN where the uniqueness test or the left-right check
        fails. In the left ``max_disparity`` columns only the levels whose match lands in the
        right image compete, and a winner within ``edge_margin`` columns of its edge is NaN too
        (the true match probably lies outside).

    Raises
    ------
    ValueError
        Bad images, an unknown option, a range with ``max_disparity < min_disparity``, one no
        pixel can match in (``min_disparity`` not below the image width, or ``max_disparity``
        not above minus it; as :func:`stereovision.depth_map`) or a parameter out of its range.
    MemoryError
        When the kernel's peak (3 bytes per pixel and disparity level) exceeds the memory
        available (Linux's MemAvailable, a container's cgroup limit, or the address space left
        under ``ulimit -v``), before allocating it; or when an allocation fails anyway.
    """
    # with the nearest spelling, as the other matchers say it: uniquenes=5 named none
    refuse_unknown("SGM option", params, DEFAULTS, "stereovision.matching.sgm.DEFAULTS")
    p = {**DEFAULTS, **params}
    bounds: list[float] = []
    for name, v in (("max_disparity", max_disparity), ("min_disparity", min_disparity)):
        if isinstance(v, np.ndarray) and v.size == 1 and v.dtype.kind in "iuf":
            # its number, as _real_scalar reads it: np.array([16]) passed a check by it, then
            # raised NumPy's "only 0-dimensional arrays can be converted", naming no argument
            v = v.reshape(())[()]
        # True searched one level, a string or a list raised "must be real number, not str";
        # any other real number (a Fraction) is read as it was
        if isinstance(v, NOT_NUMBERS) or not isinstance(v, numbers.Real):  # 3 ns: no pixels
            raise ValueError(f"{name}: expected a number of pixels, got {v!r}")
        bounds.append(v)
        # The kernel takes i32 levels (and at most 2048 of them); 1e300 is finite, only too big.
        if not math.isfinite(float_sized(v, name)):
            raise ValueError(f"{name}: expected a finite number of pixels, got {v}")
        # its Python number: a float16 bound cast the limit to float16 (NumPy's overflow warning)
        if abs(v.item() if isinstance(v, np.generic) else v) >= _I32_LIMIT:
            raise ValueError(
                f"{name}: {v} is outside the census kernel's 32-bit integer levels "
                f"(|{name}| must be below {_I32_LIMIT})"
            )
    max_disparity, min_disparity = bounds
    if max_disparity < min_disparity:
        raise ValueError(
            f"max_disparity ({max_disparity}) is smaller than min_disparity ({min_disparity})"
        )
    # P1/P2 and uniqueness: the kernel's own limits (named here, not as its "invalid parameter
    # `p2`"); the rest: the kernel's u32 widths.
    for name, bottom, top in (
        ("p1", 1, _MAX_P2 - 1),
        ("p2", 2, _MAX_P2),
        ("uniqueness", 0, 100),
        ("lr_tol", 0, 2**32 - 1),
        ("edge_margin", 0, 2**32 - 1),
    ):
        v = p[name]
        # the library's one rule of a count (whole_value, as fuse's min_agree): 3.0 or
        # Fraction(3) was refused here and taken there, 3 ns was taken as 3
        whole = whole_value(v)
        if whole is None or not bottom <= whole <= top:
            # _shown: 10**5000's repr was Python's "Exceeds the limit (4300 digits)", no name
            raise ValueError(f"{name}: expected an integer in [{bottom}, {top}], got {_shown(v)}")
        p[name] = whole
    if p["p1"] >= p["p2"]:
        raise ValueError(f"p1: expected p1 < p2, got p1 = {p['p1']}, p2 = {p['p2']}")
    # NaN, inf, 10**400 and strings named as gamma (float() and the kernel named them otherwise)
    gamma = finite_number(p["gamma"], "gamma")
    if not gamma > 0:
        raise ValueError(f"gamma: expected a positive number, got {p['gamma']!r}")
    if gamma > _F32_MAX:  # the kernel's f32 made it inf, and said "got inf"
        raise ValueError(
            f"gamma: {p['gamma']!r} is beyond the kernel's 32-bit float range "
            f"(at most {_F32_MAX:.4g})"
        )
    if isinstance(p["paths"], np.ndarray) and p["paths"].size == 1:
        # its value, as np.array(8) was taken: np.array([8]) passed "in (3, 8)" and then
        # failed in int() as NumPy's "only 0-dimensional arrays can be converted", naming nothing
        p["paths"] = p["paths"].reshape(())[()]
    if isinstance(p["paths"], NOT_NUMBERS) or p["paths"] not in (3, 8):  # 3 ns was 3 paths
        raise ValueError(f"paths: expected 8 or 3, got {p['paths']!r}")
    gl, gr = check_pair(as_gray_float(left, "left"), as_gray_float(right, "right"))
    refuse_unreachable_range(min_disparity, max_disparity, gl.shape[1])
    levels = math.ceil(max_disparity) - math.floor(min_disparity) + 1
    if levels > _MAX_LEVELS:
        # the kernel's own message named its `d_max` ("the range holds 8192 levels; at most
        # 2048 are supported"), not the caller's arguments (match "fused" over 8191 px)
        raise ValueError(
            f"max_disparity - min_disparity: the census search range {min_disparity!r} to "
            f"{max_disparity!r} holds {levels} disparity levels; at most {_MAX_LEVELS} are "
            "supported"
        )
    _check_memory(gl.shape[1], gl.shape[0], levels, int(p["paths"]))
    return _core.sgm_disparity(
        np.ascontiguousarray(gl),
        np.ascontiguousarray(gr),
        math.floor(min_disparity),
        math.ceil(max_disparity),
        int(p["p1"]),
        int(p["p2"]),
        gamma,
        int(p["uniqueness"]),
        int(p["lr_tol"]),
        int(p["edge_margin"]),
        int(p["paths"]),
    )
