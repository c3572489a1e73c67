"""stereovision: binocular depth perception for robots.

Two cameras in; calibrated, rectified pairs, correspondences, metric depth maps and point
clouds out.
The hot kernels are Rust (``stereovision._core``); this package owns the API.

>>> import stereovision as sv
>>> calib = sv.Calibration.from_file("calib.txt")            # doctest: +SKIP
>>> result = sv.depth_map(left, right, calib)                 # doctest: +SKIP
>>> result.depth, result.points, result.to_ply("cloud.ply")   # doctest: +SKIP
"""

import functools as _functools
import importlib as _importlib
import importlib.util as _importlib_util
import sys as _sys
import types as _types
from collections.abc import Callable as _Callable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from stereovision import evaluate, io
    from stereovision._core import __version__
    from stereovision.calibration import Calibration
    from stereovision.depth import DepthResult, depth_map, estimate_max_disparity
    from stereovision.ground import (
        GroundPlane,
        LaserScan,
        fit_ground_plane,
        laser_scan,
        obstacle_mask,
    )
    from stereovision.match import match
    from stereovision.matches import Matches
    from stereovision.rectification_check import check_rectification, refine_rectification
    from stereovision.temporal import TemporalFilter
    from stereovision.triangulation import depth_from_disparity, triangulate

#: Where each name of the API lives, imported on its first use: ``import stereovision`` took
#: 0.18 s (NumPy, OpenCV, the extension) before the command line's entry could run, so a
#: Ctrl+C in it printed a traceback, not the CLI's one line.
_WHERE = {
    "__version__": "stereovision._core",
    "Calibration": "stereovision.calibration",
    "DepthResult": "stereovision.depth",
    "depth_map": "stereovision.depth",
    "estimate_max_disparity": "stereovision.depth",
    "GroundPlane": "stereovision.ground",
    "LaserScan": "stereovision.ground",
    "fit_ground_plane": "stereovision.ground",
    "laser_scan": "stereovision.ground",
    "obstacle_mask": "stereovision.ground",
    "match": "stereovision.match",
    "Matches": "stereovision.matches",
    "check_rectification": "stereovision.rectification_check",
    "refine_rectification": "stereovision.rectification_check",
    "TemporalFilter": "stereovision.temporal",
    "depth_from_disparity": "stereovision.triangulation",
    "triangulate": "stereovision.triangulation",
}


if not TYPE_CHECKING:
    # hidden from type checkers: a module's __getattr__ makes every attribute of it Any to
    # mypy, so a user's typo (sv.depth_mapp) passed --strict; the names above are their types

    def __getattr__(name: str) -> Any:
        """A name of the API (or a submodule: ``stereovision.depth``), imported on first use."""
        if name in _WHERE:
            value = getattr(_importlib.import_module(_WHERE[name]), name)
        elif (
            name.isidentifier()  # getattr(sv, "a.b") imported stereovision.a, or failed to
            and not name.startswith("__")
            and _importlib_util.find_spec(f"{__name__}.{name}")
        ):
            value = _importlib.import_module(f"{__name__}.{name}")  # binds it here too
        else:
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
        globals()[name] = value  # once: later uses do not come here
        return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


class _Package(_types.ModuleType):
    """This package: ``stereovision.match`` stays the function when its module is imported."""

    def __setattr__(self, name: str, value: Any) -> None:
        # importing a submodule sets it here: the module stereovision.match (imported by the
        # CLI, depth) replaced the function `match`, as the eager import put it after the module
        if name == "match" and isinstance(value, _types.ModuleType):
            value = value.match
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package


@_functools.cache
def _malloc_trim() -> "_Callable[[int], int] | None":
    """glibc's ``malloc_trim``, or None where the C library has none (musl, macOS, Windows)."""
    import ctypes  # here: only release_memory needs it

    try:
        trim = ctypes.CDLL(None).malloc_trim
    except (OSError, TypeError, AttributeError):  # no process handle (Windows) or no symbol
        return None
    trim.argtypes = [ctypes.c_size_t]
    trim.restype = ctypes.c_int
    return trim


def release_memory() -> int:
    """Return the memory kept for the next call to the operating system.

    The extension keeps freed image-sized blocks and its kernels' buffers for the next frame
    (at most 128 + 256 + 256 MiB, see ``_core.kept_memory``); this frees them. Freed memory
    stays in the C library's heap, counted in the process's resident size, until that heap is
    trimmed: after a ``depth_map`` on a 3600 x 3000 pair glibc held 11 GB that nothing used.
    Where the C library is glibc, ``malloc_trim(0)`` then hands every free page back; elsewhere
    that step is skipped.

    Returns
    -------
    int
        Bytes the extension's caches released (the trimmed heap is not counted: glibc does not
        say how much it returned).

    Examples
    --------
    >>> import stereovision as sv
    >>> sv.release_memory() >= 0
    True
    """
    from stereovision import _core

    released = _core.release_memory()
    trim = _malloc_trim()
    if trim is not None:
        trim(0)
    return released


__all__ = [
    "Calibration",
    "DepthResult",
    "GroundPlane",
    "LaserScan",
    "Matches",
    "TemporalFilter",
    "__version__",
    "check_rectification",
    "depth_from_disparity",
    "depth_map",
    "estimate_max_disparity",
    "evaluate",
    "fit_ground_plane",
    "io",
    "laser_scan",
    "match",
    "obstacle_mask",
    "refine_rectification",
    "release_memory",
    "triangulate",
]
