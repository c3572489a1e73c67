"""Typed stub of the Rust extension ``stereovision._core`` (see rust/py/src)."""

import numpy as np
import numpy.typing as npt

__version__: str

def gabor_disparity(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    d_min: float,
    d_max: float,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
