"""stereovision: binocular depth perception for robots.

Two cameras in; calibrated, rectified pairs, correspondences, metric depth maps and point clouds out.
The hot kernels are Rust (``stereovision._core``); this package owns the API.
"""

from stereovision._core import __version__

__all__ = ["__version__"]
