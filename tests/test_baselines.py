"""Tests of the OpenCV references and the reference row fill (evaluation.md)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from stereovision.baselines import (
    opencv_bm,
    opencv_sgbm,
    ros_stereo_image_proc,
    round_up16,
    row_fill,
    stereovision_1_0,
)
from stereovision.evaluate import dense_metrics
from stereovision.io import load_scene
from tests.reference import row_fill_ref

NAN = np.nan


def test_round_up16() -> None:
    assert [round_up16(n) for n in (0, 1, 15.4, 16, 16.0001, 32, 101.2 * 1.1)] == [
        16,
        16,
        16,
        16,
        32,
        32,
        112,
    ]
    for bad in (-1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="disparity range"):
            round_up16(bad)


def test_row_fill_hand_made() -> None:
    d = np.array(
        [
            [NAN, 3, NAN, NAN, 1, NAN],  # leading/trailing holes take their one side
            [5, NAN, 2, NAN, NAN, 7],  # inner holes take the smaller side
            [NAN, NAN, NAN, NAN, NAN, NAN],  # empty row stays empty
            [1, 2, 3, 4, 5, 6],  # no holes: unchanged
        ],
        dtype=np.float32,
    )
    expected = np.array(
        [
            [3, 3, 1, 1, 1, 1],
            [5, 2, 2, 2, 2, 7],
            [NAN] * 6,
            [1, 2, 3, 4, 5, 6],
        ],
        dtype=np.float32,
    )
    got = row_fill(d)
    assert got.dtype == np.float32
    np.testing.assert_array_equal(got, expected)
    assert np.isnan(d[0, 0])  # input untouched


def _row_fill_loop(d: np.ndarray) -> np.ndarray:
    """Plain per-pixel reference of the rule (an oracle of the kernel on odd shapes)."""
    out = d.astype(np.float32).copy()
    for r in range(d.shape[0]):
        row = d[r]
        valid = np.flatnonzero(np.isfinite(row))
        for c in range(d.shape[1]):
            if np.isfinite(row[c]) or valid.size == 0:
                continue
            left = valid[valid < c]
            right = valid[valid > c]
            cands = ([row[left[-1]]] if left.size else []) + ([row[right[0]]] if right.size else [])
            out[r, c] = min(cands)
    return out


@settings(max_examples=50, deadline=None)
@given(
    hnp.arrays(
        np.float32,
        hnp.array_shapes(min_dims=2, max_dims=2, min_side=1, max_side=9),
        elements=st.one_of(st.just(np.nan), st.floats(0, 100, width=32)),
    )
)
def test_row_fill_matches_loop(d: np.ndarray) -> None:
    np.testing.assert_array_equal(row_fill(d), _row_fill_loop(d))


@pytest.mark.parametrize("scene", ["middlebury2003/cones", "kitti2015/000005_10"])
def test_row_fill_kernel_equals_numpy_reference(data_dir: Path, scene: str) -> None:
    """The Rust kernel against tests/reference/row_fill_ref.py on SGBM-3WAY's real maps, with
    an infinite value and an empty row added."""
    s = load_scene(data_dir / scene)
    d = opencv_sgbm(s.left, s.right, s.max_disparity)
    d[5, 7] = np.inf
    d[9, :] = np.nan
    assert 0.05 < np.isnan(d).mean() < 0.5  # a real test: many holes
    got = row_fill(d)
    np.testing.assert_array_equal(got, row_fill_ref.row_fill(d))
    assert np.isnan(got[9]).all() and np.isfinite(got[5, 7])


def test_row_fill_rejects_bad_input() -> None:
    with pytest.raises(ValueError, match="disp"):
        row_fill(np.zeros(5))


def _shifted_pair(shift: int) -> tuple[np.ndarray, np.ndarray]:
    """Random texture with left(x) = right(x - shift): disparity ``x_l - x_r = shift``."""
    rng = np.random.default_rng(3)
    tex = rng.integers(0, 256, (60, 160 + shift), dtype=np.uint8)
    tex = cv2.GaussianBlur(tex, (3, 3), 0)
    left = tex[:, :-shift]
    right = tex[:, shift:]
    return np.ascontiguousarray(left), np.ascontiguousarray(right)


@pytest.mark.parametrize("fn", [opencv_bm, opencv_sgbm])
def test_references_recover_a_known_shift(fn) -> None:
    left, right = _shifted_pair(7)
    d = fn(left, right, 16)
    assert d.dtype == np.float32 and d.shape == left.shape
    # interior, away from the borders the matchers cannot handle
    inner = d[10:-10, 40:-10]
    ok = np.isfinite(inner)
    assert ok.mean() > 0.9
    assert np.median(inner[ok]) == pytest.approx(7.0, abs=0.1)
    assert np.isnan(d[:, :5]).all()  # no match possible at the left border -> NaN, not -1


def test_references_accept_gray_bgr_and_float() -> None:
    left, right = _shifted_pair(5)
    bgr_l, bgr_r = cv2.cvtColor(left, cv2.COLOR_GRAY2BGR), cv2.cvtColor(right, cv2.COLOR_GRAY2BGR)
    for fn in (opencv_bm, opencv_sgbm):
        a = fn(left, right, 16)
        b = fn(bgr_l, bgr_r, 16)
        c = fn(left / 255.0, right / 255.0, 16)
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)


def test_references_equal_raw_opencv_over_16() -> None:
    left, right = _shifted_pair(4)
    raw = cv2.StereoBM.create(32, 15).compute(left, right)
    expected = raw.astype(np.float32) / 16
    expected[raw < 0] = np.nan
    np.testing.assert_array_equal(opencv_bm(left, right, 20), expected)  # 20 -> D16 = 32


def test_bm_refuses_a_range_that_leaves_its_block_no_room() -> None:
    """StereoBM with a range near the image's width computed it anyway: on the cones (450 px)
    at 448 px, disparities up to 2041 px, most pixels "valid", and not the same from one run to
    the next. Such a range is refused, naming the widest that fits (:func:`bm_widest_range`);
    that one gives disparities inside it, the same each run."""
    from stereovision.baselines import BM_BLOCK_SIZE, bm_widest_range

    left, right = _shifted_pair(7)  # 160 px wide
    widest = bm_widest_range(160)
    assert widest == 144 and widest + BM_BLOCK_SIZE - 1 <= 160 < widest + 16 + BM_BLOCK_SIZE - 1
    with pytest.raises(ValueError) as err:
        opencv_bm(left, right, widest + 1)
    assert str(err.value) == (
        "StereoBM's 15 px block and a 160 px disparity range (a multiple of 16) need images at "
        "least 174 px wide, got 160; give a max_disparity of at most 144"
    )
    runs = [opencv_bm(left, right, widest) for _ in range(3)]
    for d in runs[1:]:
        np.testing.assert_array_equal(d, runs[0])
    assert not (runs[0] >= widest).any()  # NaN compares False
    narrow = np.zeros((20, 29), np.uint8)
    with pytest.raises(ValueError, match=r"at least 30 px wide, got 29$"):  # no range fits
        opencv_bm(narrow, narrow, 1)
    assert opencv_bm(left[:, :30], right[:, :30], 16).shape == (60, 30)


def test_references_reject_mismatched_pair() -> None:
    with pytest.raises(ValueError, match=r"left \(10, 20\) and right \(10, 21\)"):
        opencv_sgbm(np.zeros((10, 20), np.uint8), np.zeros((10, 21), np.uint8), 16)
    with pytest.raises(ValueError, match="disparity range"):
        opencv_bm(np.zeros((10, 20), np.uint8), np.zeros((10, 20), np.uint8), -3)


def test_sgbm_tsukuba_reference_figures(data_dir: Path) -> None:
    """evaluation.md table: SGBM-3WAY bad-2 5.3 %, bad-1 6.4 %, density 98 %, + fill 4.2 %;
    BM bad-2 12.7 %."""
    s = load_scene(data_dir / "middlebury2001" / "tsukuba")
    assert s.gt is not None
    m = dense_metrics(opencv_sgbm(s.left, s.right, s.max_disparity), s.gt)
    assert m.bad[2.0] == pytest.approx(5.3, abs=0.5)
    assert m.bad[1.0] == pytest.approx(6.4, abs=0.5)
    assert m.density == pytest.approx(98.0, abs=0.5)
    filled = dense_metrics(row_fill(opencv_sgbm(s.left, s.right, s.max_disparity)), s.gt)
    assert filled.bad[2.0] == pytest.approx(4.2, abs=0.5)
    assert filled.density == 100.0
    bm = dense_metrics(opencv_bm(s.left, s.right, s.max_disparity), s.gt)
    assert bm.bad[2.0] == pytest.approx(12.7, abs=0.5)


def test_tool_defaults_relate_to_the_references(data_dir: Path) -> None:
    """ROS's BM is the BM reference plus the node's speckle filter (100 px, range 4): a subset of
    its pixels with the same values; StereoVision 1.0.4's BM is OpenCV's BM at window 21. The
    SGBM settings are told apart by their figures on cones (benches/bench_tools.py, 2026-12-03:
    bad-2.0 holes counted ROS BM 30.9, ROS SGBM 25.2, 1.0.4 BM 34.1, 1.0.4 SGBM 21.1 %)."""
    s = load_scene(data_dir / "middlebury2003" / "cones")
    assert s.gt is not None and s.max_disparity is not None
    ref = opencv_bm(s.left, s.right, s.max_disparity)
    ros = ros_stereo_image_proc(s.left, s.right, s.max_disparity)
    kept = np.isfinite(ros)
    assert np.isfinite(ref[kept]).all()
    np.testing.assert_array_equal(ros[kept], ref[kept])
    assert 0.8 < kept.sum() / np.isfinite(ref).sum() < 0.99  # the speckle filter took some
    raw = cv2.StereoBM.create(round_up16(s.max_disparity), 21).compute(
        cv2.cvtColor(s.left, cv2.COLOR_BGR2GRAY), cv2.cvtColor(s.right, cv2.COLOR_BGR2GRAY)
    )
    expected = np.where(raw < 0, np.nan, raw / 16).astype(np.float32)
    np.testing.assert_array_equal(stereovision_1_0(s.left, s.right, s.max_disparity), expected)
    figures = {
        ("ros", "bm"): 30.9,
        ("ros", "sgbm"): 25.2,
        ("1.0", "bm"): 34.1,
        ("1.0", "sgbm"): 21.1,
    }
    for (tool, algo), bad2 in figures.items():
        fn = ros_stereo_image_proc if tool == "ros" else stereovision_1_0
        m = dense_metrics(fn(s.left, s.right, s.max_disparity, algo), s.gt)
        assert m.bad[2.0] == pytest.approx(bad2, abs=0.1), (tool, algo)


def test_tool_defaults_reject_an_unknown_algorithm() -> None:
    left, right = _shifted_pair(3)
    for fn in (ros_stereo_image_proc, stereovision_1_0):
        with pytest.raises(ValueError, match="algorithm: expected 'bm' or 'sgbm', got 'hh'"):
            fn(left, right, 16, "hh")
        assert np.median(fn(left, right, 16, "sgbm")[10:-10, 40:-10]) == pytest.approx(3, abs=0.1)


# evaluation.md "Reference figures": scene -> (BM bad-2, SGBM bad-1, SGBM bad-2, SGBM density,
# SGBM + fill bad-2), all in percent, printed to 0.1 (density to 1).
REFERENCE_TABLE = {
    "eth3d/playground": (17.3, 9.4, 7.8, 93, 3.3),
    "eth3d/terrace": (21.2, 14.9, 10.7, 95, 8.5),
    "kitti2015/000005_10": (60.6, 43.5, 29.5, 80, 21.2),
    "middeval3/teddyH": (36.8, 28.1, 25.3, 80, 18.2),
    "middlebury2001/tsukuba": (12.7, 6.4, 5.3, 98, 4.2),
    "middlebury2001/venus": (20.2, 11.0, 9.9, 92, 1.8),
    "middlebury2003/cones": (30.7, 22.7, 21.6, 82, 11.2),
    "middlebury2003/teddy": (35.6, 27.0, 24.4, 81, 15.0),
    "middlebury2005/art": (53.3, 40.8, 39.2, 69, 25.2),
    "middlebury2005/books": (40.4, 30.0, 26.4, 78, 12.3),
    "middlebury2005/dolls": (39.8, 30.7, 27.9, 77, 14.1),
    "middlebury2005/laundry": (52.2, 38.6, 35.1, 75, 27.4),
    "middlebury2005/moebius": (39.4, 30.2, 27.9, 78, 13.0),
    "middlebury2005/reindeer": (49.4, 33.0, 32.1, 75, 14.4),
    "middlebury2006/cloth3": (24.7, 18.5, 17.8, 84, 10.0),
    "middlebury2006/wood2": (36.5, 22.0, 21.7, 79, 2.4),
    "tartanair/oldtown_easy_p000_001116": (32.4, 23.3, 19.7, 89, 10.2),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(REFERENCE_TABLE))
def test_reference_table_reproduced(data_dir: Path, name: str) -> None:
    """Every accuracy figure of evaluation.md's reference table, to its printed precision."""
    bm_b2, b1, b2, density, fill_b2 = REFERENCE_TABLE[name]
    s = load_scene(data_dir / name)
    assert s.gt is not None
    sgbm = opencv_sgbm(s.left, s.right, s.max_disparity)
    m = dense_metrics(sgbm, s.gt)
    assert m.bad[1.0] == pytest.approx(b1, abs=0.051)
    assert m.bad[2.0] == pytest.approx(b2, abs=0.051)
    assert m.density == pytest.approx(density, abs=0.51)
    assert dense_metrics(row_fill(sgbm), s.gt).bad[2.0] == pytest.approx(fill_b2, abs=0.051)
    bm = dense_metrics(opencv_bm(s.left, s.right, s.max_disparity), s.gt)
    assert bm.bad[2.0] == pytest.approx(bm_b2, abs=0.051)


def _colour_pair(shift: int) -> tuple[np.ndarray, np.ndarray]:
    """A BGR pair whose channels differ (so grey and colour matching give different maps)."""
    rng = np.random.default_rng(5)
    tex = cv2.GaussianBlur(rng.integers(0, 256, (60, 160 + shift, 3), dtype=np.uint8), (3, 3), 0)
    return np.ascontiguousarray(tex[:, :-shift]), np.ascontiguousarray(tex[:, shift:])


def _raw(matcher: cv2.StereoMatcher, left: np.ndarray, right: np.ndarray) -> np.ndarray:
    raw = matcher.compute(left, right)
    out = raw.astype(np.float32) / 16
    out[raw < 0] = np.nan
    return out


def test_references_equal_opencv_configured_as_documented() -> None:
    # every parameter written out from the docstrings (evaluation.md's SGBM-3WAY, the ROS node's
    # defaults, StereoVision 1.0's): one changed in the code changes the map
    left, right = _colour_pair(6)
    gl, gr = (cv2.cvtColor(x, cv2.COLOR_BGR2GRAY) for x in (left, right))
    sgbm = cv2.StereoSGBM.create(
        minDisparity=0, numDisparities=32, blockSize=5, P1=8 * 3 * 25, P2=32 * 3 * 25,
        disp12MaxDiff=1, uniquenessRatio=10, speckleWindowSize=100, speckleRange=2,
        mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY,
    )  # fmt: skip
    np.testing.assert_array_equal(opencv_sgbm(left, right, 20), _raw(sgbm, left, right))
    bm = cv2.StereoBM.create(32, 15)
    bm.setPreFilterSize(9)
    bm.setPreFilterCap(31)
    bm.setUniquenessRatio(15)
    bm.setSpeckleWindowSize(100)
    bm.setSpeckleRange(4)
    np.testing.assert_array_equal(ros_stereo_image_proc(left, right, 20), _raw(bm, gl, gr))
    sg = cv2.StereoSGBM.create(
        minDisparity=0, numDisparities=32, blockSize=15, P1=200, P2=400, disp12MaxDiff=0,
        preFilterCap=31, uniquenessRatio=15, speckleWindowSize=100, speckleRange=4,
        mode=cv2.STEREO_SGBM_MODE_SGBM,
    )  # fmt: skip
    np.testing.assert_array_equal(
        ros_stereo_image_proc(left, right, 20, algorithm="sgbm"), _raw(sg, gl, gr)
    )
    bm21 = cv2.StereoBM.create(32, 21)
    np.testing.assert_array_equal(stereovision_1_0(left, right, 20), _raw(bm21, gl, gr))
    sg3 = cv2.StereoSGBM.create(
        minDisparity=0, numDisparities=32, blockSize=3, P1=216, P2=864, disp12MaxDiff=1,
        uniquenessRatio=10, speckleWindowSize=100, speckleRange=32, mode=cv2.STEREO_SGBM_MODE_SGBM,
    )  # fmt: skip
    np.testing.assert_array_equal(
        stereovision_1_0(left, right, 20, algorithm="sgbm"), _raw(sg3, left, right)
    )


def test_a_zero_disparity_is_a_value_not_a_hole() -> None:
    # OpenCV's "no match" is minDisparity - 1 = -1 px; 0 px (a point at infinity) is a match
    left, _ = _shifted_pair(4)
    for fn in (opencv_bm, opencv_sgbm):
        inner = fn(left, left, 16)[10:-10, 40:-10]
        assert np.isfinite(inner).mean() > 0.9
        assert np.nanmax(np.abs(inner)) == 0.0


def test_row_fill_refuses_bool_and_returns_float32_when_empty() -> None:
    with pytest.raises(ValueError, match="dtype bool"):
        row_fill(np.zeros((2, 3), bool))
    out = row_fill(np.zeros((0, 3), np.float64))
    assert out.dtype == np.float32 and out.shape == (0, 3)


def test_tool_sgbm_speckle_filters_as_documented(data_dir: Path) -> None:
    # the synthetic colour pair has no speckle for the filters to take; a cones crop has some
    s = load_scene(data_dir / "middlebury2003" / "cones")
    left = np.ascontiguousarray(s.left[100:220, 150:330])
    right = np.ascontiguousarray(s.right[100:220, 150:330])
    expected = _raw(cv2.StereoSGBM.create(**_SV_SGBM), left, right)
    unfiltered = _raw(cv2.StereoSGBM.create(**{**_SV_SGBM, "speckleWindowSize": 0}), left, right)
    assert (np.isnan(expected) != np.isnan(unfiltered)).sum() > 10  # the filter acts here
    np.testing.assert_array_equal(stereovision_1_0(left, right, 50, algorithm="sgbm"), expected)


_SV_SGBM = {
    "minDisparity": 0,
    "numDisparities": 64,
    "blockSize": 3,
    "P1": 216,
    "P2": 864,
    "disp12MaxDiff": 1,
    "uniquenessRatio": 10,
    "speckleWindowSize": 100,
    "speckleRange": 32,
    "mode": cv2.STEREO_SGBM_MODE_SGBM,
}


@pytest.mark.parametrize("fn", [ros_stereo_image_proc, stereovision_1_0])
@pytest.mark.parametrize("algorithm", ["bm", "sgbm"])
def test_tool_ranges_round_up_to_16_and_refuse_a_negative_one(fn, algorithm: str) -> None:
    left, right = _shifted_pair(3)
    np.testing.assert_array_equal(
        fn(left, right, 0, algorithm), fn(left, right, 16, algorithm)
    )  # 0 -> 16 levels, not OpenCV's error for 0
    np.testing.assert_array_equal(fn(left, right, 17, algorithm), fn(left, right, 32, algorithm))
    with pytest.raises(ValueError, match="disparity range must be finite and >= 0, got -3"):
        fn(left, right, -3, algorithm)
    with pytest.raises(ValueError, match=f"expected 'bm' or 'sgbm', got '{algorithm.upper()}'"):
        fn(left, right, 16, algorithm.upper())  # the node's names, not case-folded


def test_bm_reads_a_grey_image_beside_a_colour_one_as_the_grey_pair() -> None:
    # the BM reference matches grey images: a pair of one size but read grey and in colour
    # is the same pair to it (only the sizes must agree)
    left, right = _colour_pair(4)
    grey_right = cv2.cvtColor(right, cv2.COLOR_BGR2GRAY)
    grey_left = cv2.cvtColor(left, cv2.COLOR_BGR2GRAY)
    np.testing.assert_array_equal(
        opencv_bm(left, grey_right, 16), opencv_bm(grey_left, grey_right, 16)
    )


def test_row_fill_takes_integer_maps_and_refuses_3d_ones() -> None:
    got = row_fill(np.array([[0, 3, 7]], dtype=np.int32))
    assert got.dtype == np.float32
    np.testing.assert_array_equal(got, np.array([[0, 3, 7]], np.float32))
    with pytest.raises(ValueError, match=r"disparity: expected a real \(H, W\) array, got shape"):
        row_fill(np.zeros((2, 3, 1), np.float32))


def test_sgbm_refuses_a_grey_image_beside_a_colour_one(data_dir: Path) -> None:
    """The SGBM references compared only height and width: cones' left read grey beside its
    colour right was matched in colour, bad-2 31.4 % for 21.6 %, without a word. Refused in
    the API's words; BM converts both to grey, so it stays as it is."""
    s = load_scene(data_dir / "middlebury2003" / "cones")
    grey = cv2.cvtColor(s.left, cv2.COLOR_BGR2GRAY)
    grey3 = cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR)
    said = r"left is grey, right is colour; read both alike \(cv2.imread\(path\) reads both"
    for fn in (opencv_sgbm, lambda a, b, d: stereovision_1_0(a, b, d, algorithm="sgbm")):
        with pytest.raises(
            ValueError, match=rf"left \(375, 450\) and right \(375, 450, 3\): {said}"
        ):
            fn(grey, s.right, 64)
        fn(grey, grey3, 64)  # a grey file read in colour beside it: the same pair
        # two three-channel images are not judged by content: a covered lens (equal channels)
        # beside a colour frame is a pair a live comparison must take
        dark = np.zeros_like(s.right)
        assert (
            fn(dark, s.right, 64).shape == grey.shape and fn(s.left, grey3, 64).shape == grey.shape
        )
    bm = opencv_bm(grey, s.right, 64)
    np.testing.assert_array_equal(opencv_bm(grey3, s.right, 64), bm)
    sv1 = stereovision_1_0(grey, s.right, 64)  # its BM reads the grey pair too
    np.testing.assert_array_equal(stereovision_1_0(grey3, s.right, 64), sv1)


def test_sgbm_refuses_a_range_not_narrower_than_the_images() -> None:
    """OpenCV's SGBM-3WAY with a range (``max_disparity`` rounded up to 16) of the image's width
    + 1 killed the process (a segmentation fault: 63 px wide at a max_disparity of 50 or 64,
    31 px at 20 or 32), and at other widths up to the range failed with OpenCV's words ("Failed
    to allocate 18446744073709548353 bytes", "count > 0 in function 'allocate'"). Such a range
    is refused, naming the width it needs and the widest range that fits; run in a child
    process, where the old code's crash is a failure, not the end of the test session."""
    import subprocess
    import sys

    code = """if True:
        import numpy as np
        from stereovision.baselines import opencv_sgbm
        rng = np.random.default_rng(0)
        for width, md in ((63, 50), (63, 64), (64, 64), (31, 32), (17, 32), (16, 1)):
            img = (rng.random((20, width, 3)) * 255).astype(np.uint8)
            try:
                opencv_sgbm(img, img, md)
                print("computed", width, md)
            except ValueError as e:
                print(e)
        img = (rng.random((20, 65, 3)) * 255).astype(np.uint8)
        print(opencv_sgbm(img, img, 64).shape)  # the range + 1 px: computed
    """
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-500:]

    def said(num: int, width: int) -> str:
        fits = f"; give a max_disparity of at most {(width - 1) // 16 * 16}" if width > 16 else ""
        return (
            f"SGBM-3WAY's {num} px disparity range (max_disparity rounded up to a multiple of "
            f"16) needs images at least {num + 1} px wide, got {width}{fits}"
        )

    assert proc.stdout.splitlines() == [
        said(64, 63),
        said(64, 63),
        said(64, 64),
        said(32, 31),
        said(32, 17),
        said(16, 16),
        "(20, 65)",
    ]


@pytest.mark.parametrize(("fn", "block"), [(ros_stereo_image_proc, 15), (stereovision_1_0, 21)])
def test_tool_bms_refuse_a_range_that_leaves_their_block_no_room(
    data_dir: Path, fn, block: int
) -> None:
    """The tools' StereoBM (ROS's 15 px block, StereoVision 1.0's 21 px) with a range near the
    width computed it anyway, as opencv_bm did before it refused: on the cones (450 px) at 432
    px StereoVision 1.0's disparities reached 2035 px, its density 51 % or 70 % from one run to
    the next; ROS's at 448 px 25 % or 50 %, up to 498 px. Such a range is refused, naming the
    widest that fits (its block inside the image); that one is computed as before."""
    scene = load_scene(data_dir / "middlebury2003" / "cones")
    widest = (450 - block + 1) // 16 * 16  # 432 (ROS), 416 (StereoVision 1.0)
    assert widest + block - 1 <= 450 < widest + 16 + block - 1
    with pytest.raises(ValueError) as err:
        fn(scene.left, scene.right, widest + 1, "bm")
    assert str(err.value) == (
        f"StereoBM's {block} px block and a {widest + 16} px disparity range (a multiple of 16) "
        f"need images at least {widest + 16 + block - 1} px wide, got 450; give a max_disparity "
        f"of at most {widest}"
    )
    runs = [fn(scene.left, scene.right, widest, "bm") for _ in range(3)]
    for d in runs[1:]:
        np.testing.assert_array_equal(d, runs[0])
    assert not (runs[0] > widest).any()  # NaN compares False
    narrow = scene.left[:40, : block + 14]  # no range of 16 fits beside the block
    with pytest.raises(ValueError, match=rf"at least {block + 15} px wide, got {block + 14}$"):
        fn(narrow, narrow, 1, "bm")


@pytest.mark.parametrize(("fn", "block"), [(ros_stereo_image_proc, 15), (stereovision_1_0, 3)])
def test_tool_sgbms_refuse_a_range_too_wide_for_the_images(fn, block: int) -> None:
    """The tools' StereoSGBM (MODE_SGBM: ROS's 15 px block, StereoVision 1.0's 3 px) with a range
    that leaves less than half its block beside it failed in OpenCV's words, a cv2.error
    ("... 'params.calcSADWindowSize().width/2' is 7"), naming neither the range nor the width.
    It is a ValueError naming the width needed and the widest range that fits; the first
    width that fits is computed."""
    rng = np.random.default_rng(0)
    need = 64 + block // 2 + 1  # 72 (ROS), 66 (StereoVision 1.0)
    img = (rng.random((20, need - 1, 3)) * 255).astype(np.uint8)
    with pytest.raises(ValueError) as err:
        fn(img, img, 50, "sgbm")
    assert str(err.value) == (
        f"StereoSGBM's {block} px block and a 64 px disparity range (a multiple of 16) need "
        f"images at least {need} px wide, got {need - 1}; give a max_disparity of at most 48"
    )
    tiny = img[:, : block // 2 + 16]  # no range of 16 fits
    with pytest.raises(ValueError, match=rf"at least {block // 2 + 17} px wide, got "):
        fn(tiny, tiny, 1, "sgbm")
    wide = (rng.random((20, need, 3)) * 255).astype(np.uint8)
    assert fn(wide, wide, 64, "sgbm").shape == (20, need)


@pytest.mark.parametrize(
    ("fn", "block"),
    [
        (opencv_bm, 15),
        (lambda left, right, d: ros_stereo_image_proc(left, right, d, "bm"), 15),
        (lambda left, right, d: stereovision_1_0(left, right, d, "bm"), 21),
    ],
)
def test_bms_refuse_images_no_higher_than_their_block(fn, block: int) -> None:
    """StereoBM on images no higher than its block failed as a cv2.error in OpenCV's words
    ("SADWindowSize must be odd, be within 5..255 and be not larger than image width or
    height"), which eval and bench printed as an internal error to report; a ValueError names
    the height needed. One row more is computed."""
    rng = np.random.default_rng(0)
    img = (rng.random((block, 200, 3)) * 255).astype(np.uint8)
    with pytest.raises(ValueError) as err:
        fn(img, img, 32)
    assert str(err.value) == (
        f"StereoBM's {block} px block needs images at least {block + 1} px high, got {block}"
    )
    taller = (rng.random((block + 1, 200, 3)) * 255).astype(np.uint8)
    assert fn(taller, taller, 32).shape == (block + 1, 200)


@pytest.mark.parametrize("bad", [None, "64", True, [64], np.array([64, 64]), 10**400])
def test_references_refuse_a_range_that_is_no_number_naming_it(bad: object) -> None:
    """A max_disparity of None or [64] was float()'s TypeError naming nothing ("float()
    argument must be a string or a real number, not 'NoneType'"), "64" and True were taken
    (True as 1: a 16 px range), 10**400 an OverflowError ('int too large to convert to
    float'). Each is a ValueError naming the disparity range and the value."""
    img = np.zeros((40, 60, 3), np.uint8)
    for fn in (opencv_sgbm, opencv_bm, round_up16):
        with pytest.raises(ValueError, match=r"^disparity range must be "):
            fn(img, img, bad) if fn is not round_up16 else fn(bad)  # type: ignore[operator]
    with pytest.raises(
        ValueError, match=r"got an integer of 401 digits \(too large for a float\)$"
    ):
        round_up16(10**400)
    assert round_up16(np.int64(17)) == round_up16(np.float32(17.0)) == 32


@pytest.mark.parametrize(
    ("fn", "width", "need"),
    [
        (opencv_bm, 30, 46),  # its 15 px block: 16 + 15 - 1 = 30 px hold a 16 px range
        (lambda left, right, d: ros_stereo_image_proc(left, right, d, "bm"), 30, 46),
        (lambda left, right, d: stereovision_1_0(left, right, d, "bm"), 36, 52),  # 21 px
        (lambda left, right, d: ros_stereo_image_proc(left, right, d, "sgbm"), 24, 40),  # 15 // 2
        (lambda left, right, d: stereovision_1_0(left, right, d, "sgbm"), 18, 34),  # 3 // 2
    ],
)
def test_a_width_that_holds_only_the_16_px_range_names_it(fn, width: int, need: int) -> None:
    """Mutation audit: the refusals name the widest range that fits from 16 px on (``widest >=
    16``); at the width where that is exactly 16 a 32 px range is refused with 'give a
    max_disparity of at most 16', and 16 is computed."""
    img = (np.random.default_rng(0).random((30, width, 3)) * 255).astype(np.uint8)
    with pytest.raises(ValueError, match=rf"at least {need} px wide, got {width}; give a "
                       r"max_disparity of at most 16$"):  # fmt: skip
        fn(img, img, 32)
    assert fn(img, img, 16).shape == (30, width)


def test_row_fill_refuses_a_value_beyond_float32_rather_than_fill_over_it() -> None:
    """A float64 map's finite 1e300 became inf in the float32 cast and was filled over as a
    hole ([[1e300, NaN, 2]] -> [[2, 2, 2]], only NumPy's overflow warning); it is refused."""
    with pytest.raises(
        ValueError,
        match=r"^disparity: 2 finite value\(s\) beyond float32's range \(e\.g\. 1e\+300\) "
        r"would be filled over as holes$",
    ):
        row_fill(np.array([[1e300, np.nan, 2.0], [np.nan, -1e300, 1.0]]))
    # the float32 range's edge, an inf (a hole) and float64 values within range read as before
    big = float(np.finfo(np.float32).max)
    np.testing.assert_array_equal(
        row_fill(np.array([[big, np.nan, 2.0], [np.inf, 1.5, np.nan]])),
        np.array([[big, 2.0, 2.0], [1.5, 1.5, 1.5]], np.float32),
    )


@pytest.mark.parametrize("name", ["opencv_bm", "opencv_sgbm", "ros", "stereovision_1_0"])
def test_a_12_bit_pair_is_said_to_reach_opencv_as_its_8_bit_copy(name: str) -> None:
    """A uint16 pair of 12-bit data was warned about in the package's words, 'the matchers read
    all its bits, but its 8-bit copy ... keeps about 4 bits of it': OpenCV's matchers read that
    copy alone (terrace: SGBM-3WAY's bad-2.0 26.1 % for 13.9 % on the 8-bit pair). One warning
    per image says so; a full-range uint16 pair is matched without one, as before."""
    import warnings

    fn = {"ros": ros_stereo_image_proc, "opencv_bm": opencv_bm, "opencv_sgbm": opencv_sgbm}.get(
        name, stereovision_1_0
    )
    rng = np.random.default_rng(0)
    img = rng.integers(0, 4000, (40, 64, 3)).astype(np.uint16)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        fn(img, img, 16)
    texts = [str(w.message) for w in seen]
    assert [t.split(":")[0] for t in texts] == ["left", "right"], texts
    assert all(
        "it is scaled as 16-bit; OpenCV's matchers read its 8-bit copy, about 4 bits of it;" in t
        for t in texts
    ), texts
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fn(img << 4, img << 4, 16)
