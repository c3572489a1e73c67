"""stereovision: binocular depth perception for robots.

Two cameras in; calibrated, rectified pairs, correspondences, metric depth maps and point
clouds out.
The hot kernels are Rust (``stereovision._core``); this package owns the API.

>>> import stereovision as sv
>>> calib = sv.Calibration.from_file("calib.txt")            # doctest: +SKIP
>>> result = sv.depth_map(left, right, calib)                 # doctest: +SKIP
>>> result.depth, result.points, result.to_ply("cloud.ply")   # doctest: +SKIP
"""

from stereovision import evaluate, io
from stereovision._core import __version__, release_memory
from stereovision.calibration import Calibration
from stereovision.depth import DepthResult, depth_map, estimate_max_disparity
from stereovision.ground import GroundPlane, LaserScan, fit_ground_plane, laser_scan, obstacle_mask
from stereovision.match import match
from stereovision.matches import Matches
from stereovision.rectification_check import check_rectification, refine_rectification
from stereovision.temporal import TemporalFilter
from stereovision.triangulation import depth_from_disparity, triangulate

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
