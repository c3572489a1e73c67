"""The extension reads NumPy buffers in row-major order whatever the array's memory layout.

A Fortran-ordered array is contiguous too, but its buffer holds the transpose: the bindings copy
it into row-major order (grey images, maps a kernel works on in place) or refuse it with a
``ValueError`` naming the array (maps read in place), never read it as if it were row-major.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stereovision import _core
from stereovision._validate import as_gray_float
from stereovision.baselines import opencv_sgbm
from stereovision.io import load_scene


def _pair(data_dir: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    s = load_scene(data_dir / "middlebury2003" / "cones")
    return as_gray_float(s.left), as_gray_float(s.right), opencv_sgbm(s.left, s.right, 64)


def test_fortran_ordered_images_give_the_row_major_result(data_dir: Path) -> None:
    gl, gr, d = _pair(data_dir)
    fl, fr, fd = (np.asfortranarray(a) for a in (gl, gr, d))
    assert fl.flags.f_contiguous and not fl.flags.c_contiguous
    sgm = _core.sgm_disparity(gl, gr, 0, 64, 8, 96, 16.0, 5, 1, 4)
    np.testing.assert_array_equal(_core.sgm_disparity(fl, fr, 0, 64, 8, 96, 16.0, 5, 1, 4), sgm)
    fat = _core.fattened(d, gl, 3, 2.0, 2.0)
    assert fat.sum() > 100
    np.testing.assert_array_equal(_core.fattened(fd, fl, 3, 2.0, 2.0), fat)
    np.testing.assert_array_equal(_core.row_fill(fd), _core.row_fill(d))
    np.testing.assert_array_equal(_core.mcgm_log(fl, 2.0), _core.mcgm_log(gl, 2.0))


def test_fortran_ordered_maps_read_in_place_are_refused(data_dir: Path) -> None:
    _, _, d = _pair(data_dir)
    conf = np.ones_like(d)
    z, _ = _core.depth_rectified(d, conf, 100.0, 0.0, 0.1, 0.0, 0.05, 0.5)
    assert np.isfinite(z).sum() > 1000
    with pytest.raises(ValueError, match="C-contiguous"):
        _core.depth_rectified(np.asfortranarray(d), conf, 100.0, 0.0, 0.1, 0.0, 0.05, 0.5)
