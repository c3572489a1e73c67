"""Typed stub of the Rust extension ``stereovision._core`` (see rust/py/src)."""

from typing import Any

import numpy as np
import numpy.typing as npt

__version__: str

def gabor_disparity(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    d_min: float,
    d_max: float,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
def hopfield_interest(
    img: npt.NDArray[np.float32],
    rel_threshold: float = ...,
    nms_half: int = ...,
    tile: int = ...,
    floor_rel: float = ...,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.int32], npt.NDArray[np.float32]]: ...
def hopfield_match(
    left: npt.NDArray[np.float32], right: npt.NDArray[np.float32], params: dict[str, Any]
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float64], dict[str, Any]]: ...
def hopfield_candidates(
    left: npt.NDArray[np.float32], right: npt.NDArray[np.float32], params: dict[str, Any]
) -> npt.NDArray[np.float32]: ...
