"""The extension reads NumPy buffers in row-major order whatever the array's memory layout.

A Fortran-ordered array is contiguous too, but its buffer holds the transpose; a strided or
reversed view has no contiguous buffer at all; a field of a packed structured array has items
that are not aligned and strides that are no multiple of the item size. The bindings read such
an array through a row-major copy, never as if its buffer were row-major: every kernel gives
the result of the array's contiguous copy. Only the arrays a kernel updates in place
(``temporal_running_mean``'s ``mean`` and ``count``) must be C-contiguous and aligned, and the
error names the one that is not.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from stereovision import _core
from stereovision._validate import LUMA_WEIGHTS_BGR, as_gray_float
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


def test_fortran_ordered_maps_read_in_place_give_the_row_major_result(data_dir: Path) -> None:
    """``depth_rectified`` refused them ("disparity must be C-contiguous")."""
    _, _, d = _pair(data_dir)
    conf = np.ones_like(d)
    z, s = _core.depth_rectified(d, conf, 100.0, 0.0, 0.1, 0.0, 0.05, 0.5)
    assert np.isfinite(z).sum() > 1000
    fz, fs = _core.depth_rectified(np.asfortranarray(d), conf, 100.0, 0.0, 0.1, 0.0, 0.05, 0.5)
    np.testing.assert_array_equal(fz, z)
    np.testing.assert_array_equal(fs, s)


#: Views of the same values with another memory layout (2-D, or 3-D with channels last).
LAYOUTS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "fortran": np.asfortranarray,
    "reversed": lambda a: np.ascontiguousarray(a[::-1, ::-1])[::-1, ::-1],
    "every_other": lambda a: np.repeat(np.repeat(a, 2, axis=0), 3, axis=1)[::2, ::3],
    "row_stride": lambda a: np.pad(a, [(0, 0), (0, 5)] + [(0, 0)] * (a.ndim - 2))[:, : a.shape[1]],
    "packed_field": lambda a: _packed_field(a),
}


def _packed_field(a: np.ndarray) -> np.ndarray:
    """``a`` as the field of a packed structured array after one byte: items not aligned, and
    strides (5 bytes for float32) no multiple of the item size."""
    rec = np.zeros(a.shape, dtype=[("pad", "u1"), ("v", a.dtype)])
    rec["v"] = a
    return rec["v"]


#: Per kernel: its call on named arrays, and the role of each array (``"u8"``: the crop's BGR
#: image, ``"grey"``/``"grey_r"``: the grey pair, ``"disp"``/``"conf"``: a map with holes and
#: its confidence, ``"lab"``: float colour, ``"labels"``: segment labels, ``"mean"``: a float
#: copy of the frame, ``"diff"``: a grey difference, ``"matches"``: (N, 4) matches).
REFINE_ARGS = (0.0, 32.0, 1.0, 1.5, 3, 2, 0.25, 2, 0.5, 1e-4, [(1.0, 0.5)], 0.1, True, 1.0)
KERNELS: dict[str, Callable[[dict[str, np.ndarray]], Any]] = {
    "gabor_disparity": lambda a: _core.gabor_disparity(a["grey"], a["grey_r"], 0.0, 16.0),
    "gabor_responses": lambda a: _core.gabor_responses(a["grey"]),
    "gabor_newton_step": lambda a: _core.gabor_newton_step(a["grey"], a["grey_r"], a["dense"]),
    "gabor_lr_check": lambda a: _core.gabor_lr_check(a["disp"], a["dense"], 1.0),
    "gabor_remove_speckles": lambda a: _core.gabor_remove_speckles(a["disp"], 10, 1.0),
    "hopfield_interest": lambda a: _core.hopfield_interest(a["grey"]),
    "hopfield_match": lambda a: _core.hopfield_match(a["grey"], a["grey_r"], {"max_disparity": 32}),
    "hopfield_match_u8": lambda a: _core.hopfield_match_u8(
        a["u8"], a["u8_r"], LUMA_WEIGHTS_BGR, {"max_disparity": 32}
    ),
    "hopfield_candidates": lambda a: _core.hopfield_candidates(
        a["grey"], a["grey_r"], {"max_disparity": 32}
    ),
    "mcgm_log": lambda a: _core.mcgm_log(a["grey"], 2.0),
    "mcgm_match": lambda a: _core.mcgm_match(a["grey"], a["grey_r"], {"max_disparity": 32})[0],
    "mcgm_filter": lambda a: _core.mcgm_filter(
        a["grey"], a["grey_r"], a["matches"], {"max_disparity": 32}
    ),
    "graph_segments": lambda a: _core.graph_segments(a["lab"], 1.0, 20),
    "quantised_regions": lambda a: _core.quantised_regions(a["u8"], 16, 0),
    "plane_fill": lambda a: _core.plane_fill(a["disp"], a["labels"], 5, 1.0, 0.0, 60.0),
    "fill_planes": lambda a: _core.fill_planes(a["disp"], a["u8"], [(16, 5)], 1.0),
    "row_fill": lambda a: _core.row_fill(a["disp"]),
    "side_fill": lambda a: _core.side_fill(a["disp"], a["lab"], 1.0),
    "fattened": lambda a: _core.fattened(a["dense"], a["grey"], 3, 2.0, 2.0),
    "depth_rectified": lambda a: _core.depth_rectified(
        a["disp"], a["conf"], 100.0, 0.0, 0.1, 0.0, 0.05, 0.5
    ),
    "refine_disparity": lambda a: _core.refine_disparity(
        a["grey"], a["grey_r"], a["disp"], a["conf"], *REFINE_ARGS
    ),
    "sgm_disparity": lambda a: _core.sgm_disparity(
        a["grey"], a["grey_r"], 0, 32, 8, 96, 16.0, 5, 1, 4
    ),
    "gray_u8": lambda a: _core.gray_u8(a["u8"], LUMA_WEIGHTS_BGR),
    "gray_u8_one_channel": lambda a: _core.gray_u8(a["u8"][..., 1], LUMA_WEIGHTS_BGR),
    "temporal_grey_difference": lambda a: _core.temporal_grey_difference(a["u8"], a["mean"]),
    # mean and count are updated in place: fresh C-contiguous copies, returned with the output.
    "temporal_running_mean": lambda a: (
        lambda m, n: (_core.temporal_running_mean(a["u8"], m, n, a["diff"], 16.0, 8), m, n)
    )(np.array(a["mean"], order="C"), np.full(a["diff"].shape, 3, np.uint8)),
}


@pytest.fixture(scope="module")
def arrays(data_dir: Path) -> dict[str, np.ndarray]:
    """A 90 x 140 crop of Cones and the maps the kernels take, all C-contiguous."""
    s = load_scene(data_dir / "middlebury2003" / "cones")
    u8, u8_r = (np.ascontiguousarray(a[150:240, 100:240]) for a in (s.left, s.right))
    grey, grey_r = as_gray_float(u8), as_gray_float(u8_r)
    dense = np.ascontiguousarray(opencv_sgbm(s.left, s.right, 64)[150:240, 100:240])
    dense = np.nan_to_num(dense, nan=0.0)
    disp = dense.copy()
    disp[20:30, 10:40] = np.nan
    h, w = grey.shape
    mean = u8.astype(np.float32) + np.float32(3.5)
    return {
        "u8": u8,
        "u8_r": u8_r,
        "grey": grey,
        "grey_r": grey_r,
        "dense": dense,
        "disp": disp,
        "conf": np.linspace(-0.5, 1.0, h * w, dtype=np.float32).reshape(h, w),
        "lab": u8.astype(np.float32),
        "labels": (np.arange(h * w, dtype=np.uint32).reshape(h, w) // 700).astype(np.uint32),
        "mean": mean,
        "diff": _core.temporal_grey_difference(u8, mean),
        "matches": np.array([[60, 40, 45, 40], [80, 50, 70, 50], [30, 20, 12, 20]], np.float32),
    }


def _same(got: Any, want: Any) -> None:
    if isinstance(want, np.ndarray):
        assert got.dtype == want.dtype and got.shape == want.shape
        np.testing.assert_array_equal(got, want)
    elif isinstance(want, (tuple, list)):
        assert len(got) == len(want)
        for g, w in zip(got, want, strict=True):
            _same(g, w)
    elif isinstance(want, dict):
        assert got.keys() == want.keys()
        for k in want:
            _same(got[k], want[k])
    else:
        assert got == want


@pytest.mark.parametrize("layout", list(LAYOUTS))
@pytest.mark.parametrize("kernel", list(KERNELS))
def test_every_kernel_gives_the_contiguous_result_for_any_layout(
    kernel: str, layout: str, arrays: dict[str, np.ndarray]
) -> None:
    """``depth_rectified`` and ``refine_disparity`` (their maps), ``hopfield_match_u8``,
    ``gray_u8``, ``temporal_grey_difference`` and ``temporal_running_mean`` (their 8-bit
    frames, ``mean`` and ``diff``) refused any array that was not C-contiguous ("disparity must
    be C-contiguous"), one channel of a colour image included; they copy it now, as the other
    kernels did. A float field of a packed structured array (``packed_field``) was read with
    its 5-byte strides rounded down to one item by every kernel: other pixels than the
    array's, without a word; it is read through NumPy's copy now."""
    call = KERNELS[kernel]
    want = call(arrays)
    viewed = {}
    for name, a in arrays.items():
        v = LAYOUTS[layout](a)
        v.flags.writeable = False
        np.testing.assert_array_equal(v, a)
        if a.size > 12:  # the (3, 4) matches stay contiguous in "reversed" (one row each way)
            assert not v.flags.c_contiguous, (name, layout)
        viewed[name] = v
    _same(call(viewed), want)


def test_arrays_updated_in_place_must_be_c_contiguous(arrays: dict[str, np.ndarray]) -> None:
    """The one of ``mean`` and ``count`` that is not is named (the error named both)."""
    u8, diff = arrays["u8"], arrays["diff"]
    mean, count = arrays["mean"].copy(), np.full(diff.shape, 3, np.uint8)
    with pytest.raises(ValueError, match=r"^count must be C-contiguous: it is updated in place$"):
        _core.temporal_running_mean(u8, mean, np.asfortranarray(count), diff, 16.0, 8)
    with pytest.raises(ValueError, match=r"^mean must be C-contiguous: it is updated in place$"):
        _core.temporal_running_mean(u8, mean[:, ::-1], count, diff, 16.0, 8)
    np.testing.assert_array_equal(mean, arrays["mean"])  # nothing written before the refusal
    packed = _packed_field(mean)
    says = (
        "mean must be an aligned array whose strides are whole items (it is updated in place), "
        "got strides [2100, 15, 5] for items of 4 bytes"
    )
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.temporal_running_mean(u8, packed, count, diff, 16.0, 8)
    np.testing.assert_array_equal(packed, arrays["mean"])


def test_an_in_place_array_that_cannot_be_written_is_named(
    arrays: dict[str, np.ndarray],
) -> None:
    """A read-only ``mean``, or a ``diff`` that is a view of ``mean``, gave NumPy's bare
    ``TypeError: The given array is not writeable`` / ``already borrowed``, naming neither."""
    u8, diff = arrays["u8"], arrays["diff"]
    mean, count = arrays["mean"].copy(), np.full(diff.shape, 3, np.uint8)
    frozen = mean.copy()
    frozen.flags.writeable = False
    says = (
        "mean: The given array is not writeable (it is updated in place: it must be writeable "
        "and share no memory with another argument)"
    )
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.temporal_running_mean(u8, frozen, count, diff, 16.0, 8)
    says = (
        "diff: The given array is already borrowed (it shares memory with an array this call "
        "updates in place)"
    )
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.temporal_running_mean(u8, mean, count, mean[..., 0], 16.0, 8)
    np.testing.assert_array_equal(mean, arrays["mean"])


def _misaligned(a: np.ndarray) -> np.ndarray:
    """A C-contiguous copy of ``a`` one byte into a buffer: strides whole items, items not
    aligned."""
    buf = np.zeros(a.nbytes + 1, np.uint8)
    out = buf[1:].view(a.dtype).reshape(a.shape)
    out[...] = a
    assert out.flags.c_contiguous and not out.flags.aligned
    return out


def test_a_misaligned_array_updated_in_place_is_refused(arrays: dict[str, np.ndarray]) -> None:
    """Only strides that are no whole items (the packed field) were asserted: a mutation audit
    letting an array whose items are not aligned through as ``mean`` left every test passing
    (it was then refused as "mean and count must be C-contiguous", which it is). It is
    refused as not aligned, and left as it was."""
    u8, diff = arrays["u8"], arrays["diff"]
    count = np.full(diff.shape, 3, np.uint8)
    mean = _misaligned(arrays["mean"])
    _, w, c = mean.shape
    says = (
        "mean must be an aligned array whose strides are whole items (it is updated in place), "
        f"got strides [{w * c * 4}, {c * 4}, 4] for items of 4 bytes"
    )
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.temporal_running_mean(u8, mean, count, diff, 16.0, 8)
    np.testing.assert_array_equal(mean, arrays["mean"])


@pytest.mark.parametrize("kernel", ["sgm_disparity", "gabor_responses", "row_fill", "side_fill"])
def test_a_misaligned_array_read_gives_the_aligned_result(
    kernel: str, arrays: dict[str, np.ndarray]
) -> None:
    """An array read (not written) whose items are not aligned goes through NumPy's aligned
    copy: the result is the aligned array's."""
    want = KERNELS[kernel](arrays)
    # Bytes are always aligned.
    viewed = {k: _misaligned(a) if a.itemsize > 1 else a for k, a in arrays.items()}
    _same(KERNELS[kernel](viewed), want)
