"""Out-of-range arguments given to the extension directly are a ValueError naming them, never
an internal error from a panic, nor a result computed from garbage without a word."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

if sys.platform == "linux":
    import resource

import stereovision as sv
from stereovision import _core
from stereovision._validate import LUMA_WEIGHTS_BGR, as_gray_float
from stereovision.io import load_scene

#: refine_disparity's scalar arguments after the four maps (0..32 px, one fill pass).
REFINE_ARGS = (0.0, 32.0, 1.0, 1.5, 3, 2, 0.25, 2, 0.5, 1e-4, [(1.0, 0.5)], 0.1, True, 1.0)


@pytest.fixture(scope="module")
def crop(data_dir: Path) -> tuple[np.ndarray, np.ndarray]:
    s = load_scene(data_dir / "middlebury2003" / "cones")
    return s.left[100:200, 100:260], s.right[100:200, 100:260]


@pytest.mark.parametrize("tile", [10**3, 2**40, 2**62, 2**63, 2**64 - 1])
def test_a_tile_beyond_the_image_is_the_whole_image(
    tile: int, crop: tuple[np.ndarray, np.ndarray]
) -> None:
    """``tile * width`` wrapped to 0 for a tile of 2**62 or more: the Moravec selection panicked
    (``RuntimeError: internal error ... chunk_size must not be zero``) through ``_core`` and
    ``stereovision.match`` alike. Any tile larger than the image is now the one tile 0 means."""
    g = as_gray_float(crop[0])
    m0, xy0, v0 = _core.hopfield_interest(g, tile=0)
    m, xy, v = _core.hopfield_interest(g, tile=tile)
    assert len(xy0) > 10
    np.testing.assert_array_equal(xy, xy0)
    np.testing.assert_array_equal(v, v0)
    np.testing.assert_array_equal(m, m0)
    whole = sv.match(*crop, method="best", max_disparity=32, tile=0)
    got = sv.match(*crop, method="best", max_disparity=32, tile=tile)
    np.testing.assert_array_equal(got.xl, whole.xl)
    np.testing.assert_array_equal(got.xr, whole.xr)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -0.5])
def test_grey_weights_must_be_finite_and_non_negative(
    bad: float, crop: tuple[np.ndarray, np.ndarray]
) -> None:
    """A NaN weight made every grey level NaN (``gray_u8``) and the matcher silently found
    nothing (``hopfield_match_u8``)."""
    weights = (bad, *LUMA_WEIGHTS_BGR[1:])
    left, right = (np.ascontiguousarray(a) for a in crop)
    with pytest.raises(ValueError, match="weights"):
        _core.gray_u8(left, weights)
    with pytest.raises(ValueError, match="weights"):
        _core.hopfield_match_u8(left, right, weights, {"max_disparity": 32})
    assert np.isfinite(_core.gray_u8(left, LUMA_WEIGHTS_BGR)).all()


@pytest.mark.parametrize("tol", [-1.0, float("nan")])
def test_lr_check_tolerance_must_not_be_negative(tol: float) -> None:
    """A negative or NaN tolerance passed no pixel at all, without a word."""
    d = np.full((6, 9), 2.0, np.float32)
    assert _core.gabor_lr_check(d, d, 0.0)[:, 2:].all()
    assert _core.gabor_lr_check(d, d, float("inf"))[:, 2:].all()
    with pytest.raises(ValueError, match="tol"):
        _core.gabor_lr_check(d, d, tol)


def test_every_kernel_lets_other_python_threads_run(crop: tuple[np.ndarray, np.ndarray]) -> None:
    """The GIL is released around every kernel: a Python thread counting in a loop keeps
    counting while one runs. Concurrent calls from threads giving the serial results is
    tests/test_memory.py's."""
    import threading
    import time

    gl, gr = (np.ascontiguousarray(np.tile(as_gray_float(a), (6, 6))) for a in crop)
    bgr = np.ascontiguousarray(np.tile(crop[0], (6, 6, 1)))
    d, conf = np.full_like(gl, 5.0), np.full_like(gl, 0.5)
    holes = d.copy()
    holes[::7, ::5] = np.nan
    kernels = {
        "sgm_disparity": lambda: _core.sgm_disparity(gl, gr, 0, 127, 8, 32, 1.0, 10, 1, 0),
        "gabor_disparity": lambda: _core.gabor_disparity(gl, gr, 0.0, 64.0),
        "hopfield_match_u8": lambda: _core.hopfield_match_u8(
            bgr, bgr, LUMA_WEIGHTS_BGR, {"max_disparity": 64}
        ),
        "mcgm_match": lambda: _core.mcgm_match(gl, gr, {"max_disparity": 32}),
        "refine_disparity": lambda: _core.refine_disparity(gl, gr, d, conf, *REFINE_ARGS),
        "graph_segments": lambda: _core.graph_segments(bgr.astype(np.float32), 1.0, 20),
        "gabor_newton_step": lambda: _core.gabor_newton_step(gl, gr, d),
        "hopfield_match": lambda: _core.hopfield_match(gl, gr, {"max_disparity": 64}),
        "hopfield_candidates": lambda: _core.hopfield_candidates(gl, gr, {"max_disparity": 64}),
        "mcgm_curves": lambda: _core.mcgm_curves(gl, {"max_disparity": 32}),
        "fill_planes": lambda: _core.fill_planes(holes, bgr, [(16, 5)], 1.0),
        "temporal_running_mean": lambda: _core.temporal_running_mean(
            bgr, bgr.astype(np.float32), np.ones(gl.shape, np.uint8), conf, 2.0, 8
        ),
    }
    count = [0]
    stop = threading.Event()

    def spin() -> None:  # lets go of the GIL at every step: the main thread never waits
        while not stop.is_set():
            count[0] += 1
            time.sleep(0)

    def steps_during(kernel: Callable[[], object]) -> tuple[int, int, float]:
        """Calls ``kernel`` until 50 ms have passed and counts the other thread's steps: one
        3 ms call can end before a loaded machine has woken the other thread at all."""
        before, t0, calls = count[0], time.perf_counter(), 0
        while calls == 0 or time.perf_counter() - t0 < 0.05:
            kernel()
            calls += 1
        return count[0] - before, calls, time.perf_counter() - t0

    # With a switch interval of 10 s the main thread never hands the GIL over between calls:
    # a kernel holding it leaves the other thread 0 steps, however many times it is called.
    interval = sys.getswitchinterval()
    sys.setswitchinterval(10.0)
    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    try:
        held, _, _ = steps_during(lambda: re.match(r"(a|aa)*c", "a" * 22))
        assert held <= 2, f"a call holding the GIL let the other thread run {held} steps"
        for name, kernel in kernels.items():
            ran, calls, took = steps_during(kernel)
            # Released, hundreds of steps on an idle machine, fewer under the load of a full
            # run; held, 0 (the check above): the bound sits just above what a held GIL allows.
            assert ran >= 5, (
                f"{name}: the other thread ran {ran} steps in {calls} calls, {took:.3f} s"
            )
    finally:
        stop.set()
        spinner.join()
        sys.setswitchinterval(interval)


def test_plane_fill_range_must_not_be_empty() -> None:
    """``lo > hi`` filled nothing, without a word."""
    from stereovision.matching import planes

    disp = np.tile(np.arange(12, dtype=np.float32), (8, 1))
    disp[3, 4:7] = np.nan
    labels = np.zeros(disp.shape, np.uint32)
    filled, _, holes = _core.plane_fill(disp, labels, 5, 1.0, 0.0, 20.0)
    assert holes == 3 and np.isfinite(filled).all()
    with pytest.raises(ValueError, match="lo <= hi"):
        _core.plane_fill(disp, labels, 5, 1.0, 20.0, 0.0)
    with pytest.raises(ValueError, match="lo <= hi"):
        planes.plane_fill(disp, labels, lo=20.0, hi=0.0)


@pytest.mark.parametrize("key", [1, None, b"max_disparity"])
def test_parameter_dict_keys_must_be_names(key: object) -> None:
    """A non-str key of a params dict gave "'int' object is not an instance of 'str'", naming
    neither the dict nor the key."""
    g = np.random.default_rng(0).random((20, 30), dtype=np.float32)
    named = "Hopfield parameter names must be str.*" + re.escape(repr(key))
    with pytest.raises(TypeError, match=named):
        _core.hopfield_match(g, g, {key: 4})
    with pytest.raises(TypeError, match="MCGM parameter names must be str"):
        _core.mcgm_match(g, g, {key: 4})


@pytest.mark.parametrize(
    "bad", [{"sides_width": -1}, {"sides_width": 0}, {"sides_height": 0}, {"disc_dx": -1}]
)
def test_mcgm_filter_checks_its_parameters(bad: dict[str, int]) -> None:
    """``mcgm_filter`` ran B.8's filters without ``mcgm_match``'s parameter checks: a
    ``sides_width`` of -1 indexed past the half-window table (``RuntimeError: internal
    error ... index out of bounds``)."""
    g = np.random.default_rng(0).random((30, 50), dtype=np.float32)
    ms = np.array([[25, 15, 22, 15]], np.float32)
    assert _core.mcgm_filter(g, g, ms, {"max_disparity": 8}).shape == (1,)
    with pytest.raises(ValueError, match=re.escape("sides_width in 1..=16")):
        _core.mcgm_filter(g, g, ms, {"max_disparity": 8, **bad})


@pytest.mark.parametrize("column", [0, 1, 2, 3])
@pytest.mark.parametrize("value", [2.0**31, 1e10, -1e30, -5.0, 160.0])
def test_mcgm_filter_refuses_matches_outside_the_images(
    column: int, value: float, crop: tuple[np.ndarray, np.ndarray]
) -> None:
    """A coordinate of 2**31 or more overflowed the filters' window arithmetic (``RuntimeError:
    internal error in mcgm_filter: index out of bounds``); a point just outside was dropped
    without a word. Both are refused, as ``matching.mcgm.filter_matches`` refuses them."""
    gl, gr = (as_gray_float(a) for a in crop)
    ms = np.array([[80, 50, 70, 50], [40, 30, 28, 30]], np.float32)
    keep = _core.mcgm_filter(gl, gr, ms, {"max_disparity": 32})
    assert keep.dtype == np.bool_ and keep.shape == (2,)
    bad = ms.copy()
    bad[1, column] = value
    says = "matches: 1 of 2 rows lie outside the 160x100 images (row 1: (xl, yl, xr, yr) = ("
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.mcgm_filter(gl, gr, bad, {"max_disparity": 32})


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
def test_mcgm_filter_refuses_non_finite_matches(
    value: float, crop: tuple[np.ndarray, np.ndarray]
) -> None:
    """They were dropped without a word."""
    gl, gr = (as_gray_float(a) for a in crop)
    ms = np.array([[80, 50, 70, 50], [40, 30, 28, value]], np.float32)
    says = "matches: 1 of 2 rows have a NaN or infinite coordinate (row 1: (xl, yl, xr, yr) = ("
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.mcgm_filter(gl, gr, ms, {"max_disparity": 32})


@pytest.mark.parametrize("theta", [90.0, -95.0, float("nan")])
def test_gabor_responses_names_theta_deg(theta: float) -> None:
    """An angle out of range was blamed on ``orientations_deg``, a parameter this function
    does not have."""
    g = np.random.default_rng(0).random((20, 30), dtype=np.float32)
    with pytest.raises(ValueError, match="theta_deg") as exc:
        _core.gabor_responses(g, theta_deg=theta)
    assert "orientations_deg" not in str(exc.value)


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("edge_margin", float("nan")),
        ("edge_margin", -1.0),
        ("centre_tol", -1.0),
        ("agree_share", float("nan")),
        ("agree_share", 1.5),
    ],
)
def test_hopfield_slacks_and_shares_are_checked(
    key: str, value: float, crop: tuple[np.ndarray, np.ndarray]
) -> None:
    """These failed every edge / centre test (no matches at all) or switched the sparse-area
    rule off, without a word, through stereovision.match too."""
    assert len(sv.match(*crop, method="hopfield", max_disparity=32).xl) > 50
    with pytest.raises(ValueError, match=key):
        sv.match(*crop, method="hopfield", max_disparity=32, **{key: value})


@pytest.mark.parametrize("value", [float("nan"), -1.0])
def test_mcgm_sides_best_margin_is_checked(
    value: float, crop: tuple[np.ndarray, np.ndarray]
) -> None:
    """A negative ``sides_best_margin`` let no half-window pass (no matches at all) and a NaN
    one switched the test off, without a word."""
    assert len(sv.match(*crop, method="mcgm", max_disparity=32).xl) > 50
    with pytest.raises(ValueError, match="sides_best_margin"):
        sv.match(*crop, method="mcgm", max_disparity=32, sides_best_margin=value)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda a: _core.sgm_disparity(a.astype(np.float64), a, 0, 4, 8, 96, 16.0, 5, 1, 4),
            "left: expected a float32 array, got float64",
        ),
        (
            lambda a: _core.sgm_disparity(a, a.astype(np.float64), 0, 4, 8, 96, 16.0, 5, 1, 4),
            "right: expected a float32 array, got float64",
        ),
        (
            lambda a: _core.gray_u8(a, LUMA_WEIGHTS_BGR),
            "image: expected a uint8 array, got float32",
        ),
        (
            lambda a: _core.depth_rectified(a, a[None], 1.0, 0.0, 0.7, -0.5, 0.2, 0.9),
            "conf: expected a 2-D float32 array, got 3 dimensions",
        ),
        (
            lambda a: _core.depth_rectified(a.tolist(), a, 1.0, 0.0, 0.7, -0.5, 0.2, 0.9),
            "disp: expected a float32 array, got list",
        ),
    ],
)
def test_a_wrong_array_type_names_the_argument(
    call: Callable[[np.ndarray], object], message: str
) -> None:
    """The extension said only "type mismatch: from=float64, to=float32", naming neither the
    argument nor (for a caller's eyes) what it expects."""
    a = np.random.default_rng(0).random((12, 16), dtype=np.float32)
    with pytest.raises(TypeError, match=re.escape(message)):
        call(a)


def test_an_empty_8_bit_image_is_called_empty() -> None:
    """It said "buffer of 0 bytes does not hold 0x5x3"."""
    with pytest.raises(ValueError, match=re.escape("image is empty: got 5x0 pixels")):
        _core.gray_u8(np.zeros((0, 5, 3), np.uint8), LUMA_WEIGHTS_BGR)


@pytest.mark.parametrize("shape", [(0, 5), (4, 0, 3)])
def test_an_empty_temporal_frame_is_called_empty_by_its_size(shape: tuple[int, ...]) -> None:
    """The temporal kernels know only a pixel count: a 5x0 or 0x4 frame was "got 0x0"."""
    frame, mean = np.zeros(shape, np.uint8), np.zeros(shape, np.float32)
    grid = (np.zeros(shape[:2], np.uint8), np.zeros(shape[:2], np.float32))
    says = re.escape(f"image is empty: got {shape[1]}x{shape[0]} pixels")
    with pytest.raises(ValueError, match=says):
        _core.temporal_grey_difference(frame, mean)
    with pytest.raises(ValueError, match=says):
        _core.temporal_running_mean(frame, mean, *grid, 3.0, 8)


@pytest.mark.parametrize(
    ("name", "args"),
    [
        ("s_min", (0.74, -0.52, -0.2, 0.9)),
        ("s_min", (0.74, -0.52, 0.0, 0.9)),
        ("s_fill", (0.74, -0.52, 0.2, -0.9)),
        ("s_fill", (0.74, -0.52, 0.2, float("nan"))),
        ("slope", (0.74, float("inf"), 0.2, 0.9)),
    ],
)
def test_depth_sigma_model_is_checked(name: str, args: tuple[float, ...]) -> None:
    """A negative s_min or s_fill gave negative depth sigmas; a NaN one, NaN sigmas."""
    d = np.full((2, 3), 8.0, np.float32)
    c = np.array([[0.5, -1.0, 0.0], [1.0, 0.5, 0.5]], np.float32)
    with pytest.raises(ValueError, match=f"`{name}`"):
        _core.depth_rectified(d, c, 50.0, 0.0, *args)


def test_a_nan_confidence_gets_the_sigma_of_confidence_zero() -> None:
    """A NaN confidence went through ``max`` to ``s_min``: the smallest sigma, as if the match
    were the surest in the map."""
    d = np.full((1, 3), 8.0, np.float32)
    c = np.array([[np.nan, 0.0, 1.0]], np.float32)
    z, s = _core.depth_rectified(d, c, 50.0, 2.0, 0.74, -0.52, 0.2, 0.9)
    assert z.tolist() == [[5.0, 5.0, 5.0]]
    assert s[0, 0] == s[0, 1] == np.float32(5.0 * 0.74 / 10.0)
    assert s[0, 2] < s[0, 0]


@pytest.mark.parametrize("name", ["research_radius", "search_pool_radius"])
def test_the_kernel_names_the_radius_out_of_range(name: str) -> None:
    """The kernel checked both radii in one test and named ``research_radius`` for either."""
    a = np.random.default_rng(0).random((20, 30), dtype=np.float32)
    with pytest.raises(ValueError, match=f"`{name}`: must be <= 16 px, got 17"):
        _core.gabor_disparity(a, a, 0.0, 8.0, **{name: 17})


#: Run under ``ulimit -v`` (RLIMIT_AS) in a child: a failed allocation aborted the whole
#: process (SIGABRT, exit -6) instead of raising MemoryError.
_OOM_SCRIPT = """
import numpy as np
from stereovision import _core
from stereovision.matching import sgm
case = {case!r}
try:
    if case == "sgm":
        a = np.random.default_rng(0).random((1500, 2000), dtype=np.float32)
        _core.sgm_disparity(a, a, 0, 2047, 8, 96, 16.0, 5, 1, 4)
    elif case == "broadcast":
        _core.gabor_responses(np.broadcast_to(np.float32(0.5), (100_000, 100_000)))
    elif case == "lr_check":
        d = np.broadcast_to(np.float32(1.0), (100_000, 100_000))
        _core.gabor_lr_check(d, d, 1.0)
    elif case == "mcgm_filter":
        a = np.random.default_rng(0).random((40, 64), dtype=np.float32)
        m = np.broadcast_to(np.array([30, 20, 26, 20], np.float32), (2**27, 4))
        _core.mcgm_filter(a, a, m, {{"max_disparity": 16}})
    elif case in ("mcgm_filter_nan", "mcgm_filter_outside"):
        a = np.random.default_rng(0).random((40, 64), dtype=np.float32)
        row = [np.nan, 20, 26, 20] if case.endswith("nan") else [100, 20, 96, 20]
        m = np.broadcast_to(np.array(row, np.float32), (2**25, 4))
        import resource
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        try:
            _core.mcgm_filter(a, a, m, {{"max_disparity": 16}})
        except ValueError as e:
            print("ValueError:", e)
        # KiB on Linux: the matches' copy is reserved, not written, before the check
        print("peak RSS grew by", resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - peak)
    elif case == "mcgm_filter_huge":
        a = np.random.default_rng(0).random((40, 64), dtype=np.float32)
        m = np.broadcast_to(np.array([30, 20, 26, 20], np.float32), (2**40, 4))
        _core.mcgm_filter(a, a, m, {{"max_disparity": 16}})
    elif case == "interest_too_wide":
        try:
            _core.hopfield_interest(np.broadcast_to(np.float32(0.5), (1, 2**31 + 1)))
        except ValueError as e:
            print("ValueError:", e)
    elif case in (
        "plane_fill_too_large", "speckles_too_large", "regions_too_large", "fill_planes_too_large"
    ):
        d = np.broadcast_to(np.float32(1.0), (2**16, 2**16))
        img = np.broadcast_to(np.uint8(5), (2**16, 2**16, 3))
        try:
            if case == "plane_fill_too_large":
                labels = np.broadcast_to(np.uint32(0), (2**16, 2**16))
                _core.plane_fill(d, labels, 3, 1.0, 0.0, 2.0)
            elif case == "regions_too_large":
                _core.quantised_regions(img, 16, 0)
            elif case == "fill_planes_too_large":
                _core.fill_planes(d, img, [(16, 5)], 1.0)
            else:
                _core.gabor_remove_speckles(d, 10, 1.0)
        except ValueError as e:
            print("ValueError:", e)
    elif case in ("segments_too_wide", "segments_too_large", "segments_too_deep"):
        shape = {{
            "segments_too_wide": (1, 2**40, 3),
            "segments_too_large": (2**16, 2**16, 3),
            "segments_too_deep": (1, 1, 2**40),
        }}[case]
        img = np.lib.stride_tricks.as_strided(np.zeros(1, np.float32), shape, (0, 0, 0))
        try:
            _core.graph_segments(img, 1.0, 5)
        except ValueError as e:
            print("ValueError:", e)
    elif case == "u8_too_deep":
        deep = np.broadcast_to(np.uint8(5), (1, 1, 2**32))
        mean = np.broadcast_to(np.float32(1.0), deep.shape)
        # updated in place: writeable, one float32 seen 2**32 times
        store = np.lib.stride_tricks.as_strided(np.zeros(1, np.float32), deep.shape, (0, 0, 0))
        grid = (np.ones((1, 1), np.uint8), np.zeros((1, 1), np.float32))
        for call in (
            lambda: _core.gray_u8(deep, (0.1, 0.6, 0.3)),
            lambda: _core.hopfield_match_u8(deep, deep, (0.1, 0.6, 0.3), {{}}),
            lambda: _core.temporal_grey_difference(deep, mean),
            lambda: _core.temporal_running_mean(deep, store, *grid, 2.0, 8),
        ):
            try:
                call()
            except (ValueError, MemoryError) as e:
                print(f"{{type(e).__name__}}: {{e}}")
    elif case == "shapes_before_copies":
        # 12 GiB uint8 and 16 GiB float32 views of one value: a copy is a MemoryError here.
        big = np.broadcast_to(np.uint8(5), (2**16, 2**16, 3))
        grey = np.broadcast_to(np.float32(0.5), (2**16, 2**16))
        small = np.zeros((6, 8, 3), np.uint8)
        mean, one = np.zeros((6, 8, 3), np.float32), np.zeros((6, 8), np.uint8)
        d = np.ones((6, 8), np.float32)
        for call in (
            lambda: _core.temporal_grey_difference(big, mean),
            lambda: _core.temporal_running_mean(big, mean, one, d, 2.0, 8),
            lambda: _core.hopfield_match_u8(big, small, (0.1, 0.6, 0.3), {{}}),
            lambda: _core.refine_disparity(grey, grey, d, d, *{refine_args}),
        ):
            try:
                call()
            except (ValueError, MemoryError) as e:
                print(f"{{type(e).__name__}}: {{e}}")
    elif case == "refine_before_copies":
        # a 16 GiB float32 view of one value, with a right image of its shape, then another's
        grey = np.broadcast_to(np.float32(0.5), (2**16, 2**16))
        for right in (grey, np.zeros((6, 8), np.float32)):
            try:
                _core.refine_disparity(grey, right, grey, grey, *{refine_args})
            except (ValueError, MemoryError) as e:
                print(f"{{type(e).__name__}}: {{e}}")
    elif case == "pairs_before_copies":
        # the matchers' pair kernels: a 16 GiB view as left, with a right of its shape, then
        # another's
        grey = np.broadcast_to(np.float32(0.5), (2**16, 2**16))
        for right in (grey, np.zeros((6, 8), np.float32)):
            for call in (
                lambda: _core.gabor_disparity(grey, right, 0.0, 8.0),
                lambda: _core.hopfield_match(grey, right, {{}}),
                lambda: _core.hopfield_candidates(grey, right, {{}}),
                lambda: _core.mcgm_match(grey, right, {{}}),
                lambda: _core.mcgm_filter(grey, right, np.zeros((0, 4), np.float32), {{}}),
            ):
                try:
                    call()
                except (ValueError, MemoryError) as e:
                    print(f"{{type(e).__name__}}: {{e}}")
    elif case == "mismatch_before_copies":
        # the pair kernels without the 32-bit size limit: a 16 GiB view as left, a small right
        grey = np.broadcast_to(np.float32(0.5), (2**16, 2**16))
        right = np.zeros((6, 8), np.float32)
        for call in (
            lambda: _core.sgm_disparity(grey, right, 0, 16, 10, 120, 0.0, 10, 1, 0, 8),
            lambda: _core.gabor_newton_step(grey, right, grey),
        ):
            try:
                call()
            except (ValueError, MemoryError) as e:
                print(f"{{type(e).__name__}}: {{e}}")
    elif case == "params_before_copies":
        # a bad scalar with 16 GiB views: said before the copies
        grey = np.broadcast_to(np.float32(0.5), (2**16, 2**16))
        nan = float("nan")
        for call in (
            lambda: _core.gabor_responses(grey, freq=nan),
            lambda: _core.depth_rectified(grey, grey, nan, 0, 1, 0, 0.1, 1),
            lambda: _core.gabor_newton_step(grey, grey, grey, freq=nan),
        ):
            try:
                call()
            except (ValueError, MemoryError) as e:
                print(f"{{type(e).__name__}}: {{e}}")
    elif case in ("log_too_large", "log_bad_sigma"):
        img = np.broadcast_to(np.float32(0.5), (2**16, 2**16))
        try:
            _core.mcgm_log(img, 2.0 if case == "log_too_large" else 0.0)
        except ValueError as e:
            print("ValueError:", e)
    elif case == "available":
        print("available", sgm._available_bytes())
        raise MemoryError("none")
except MemoryError as e:
    print("MemoryError:", e)
"""


def _under_address_limit(
    case: str, limit: int, timeout: float = 300
) -> subprocess.CompletedProcess[str]:
    def limit_address_space() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    return subprocess.run(
        [sys.executable, "-c", _OOM_SCRIPT.format(case=case, refine_args=REFINE_ARGS)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        preexec_fn=limit_address_space,
    )


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
@pytest.mark.parametrize(
    ("case", "message"),
    [
        (
            "sgm",
            "out of memory: the census matcher's cost volume needs 5.72 GiB (6144000000 bytes)",
        ),
        ("broadcast", "out of memory: a copy of img needs 37.25 GiB (40000000000 bytes)"),
        ("lr_check", "out of memory: a copy of disp_left needs 37.25 GiB (40000000000 bytes)"),
        ("mcgm_filter", "out of memory: a copy of matches needs 3.00 GiB (3221225472 bytes)"),
    ],
)
def test_a_failed_allocation_is_a_memory_error(case: str, message: str) -> None:
    """``gabor_lr_check`` copied its maps and ``mcgm_filter`` its matches with an unchecked
    ``collect``: a huge (broadcast) array aborted the whole process where the other kernels'
    copies raise MemoryError."""
    out = _under_address_limit(case, 3_000_000 * 1024)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    assert f"MemoryError: {message} and the allocation failed" in out.stdout, out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
def test_hopfield_interest_refuses_a_row_past_int32_before_copying_it() -> None:
    """``hopfield_interest`` returns its points as int32 but checked no size: a column of
    2**31 or more wrapped negative. It copied the (broadcast) image first, too: under
    ``ulimit -v`` that was a MemoryError for the 8 GiB copy instead of the size's ValueError."""
    out = _under_address_limit("interest_too_wide", 3_000_000 * 1024)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    want = (
        "ValueError: img: image of 2147483649x1 pixels is too large: the kernels index pixels "
        "with 32-bit integers (at most 4294967295 pixels, 2147483647 per side)"
    )
    assert want in out.stdout, out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
@pytest.mark.parametrize(
    "case",
    ["plane_fill_too_large", "speckles_too_large", "regions_too_large", "fill_planes_too_large"],
)
def test_in_place_kernels_refuse_2_to_the_32_pixels_before_copying(case: str) -> None:
    """``plane_fill`` (no size check: its u32 pixel lists wrapped), ``gabor_remove_speckles``,
    ``quantised_regions`` and ``fill_planes`` (the kernel's check came after the copy) copied a
    65536 x 65536 (broadcast) map or image first: a 12-16 GiB MemoryError under ``ulimit -v``,
    not the size's ValueError. That error named no argument, and called a ``disp`` an image."""
    out = _under_address_limit(case, 3_000_000 * 1024)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    # the argument and what it is, as the Python side's check_index_range says them
    said = "disp: map" if case in ("plane_fill_too_large", "speckles_too_large") else "image: image"
    want = (
        f"ValueError: {said} of 65536x65536 pixels is too large: the kernels index pixels "
        "with 32-bit integers (at most 4294967295 pixels, 2147483647 per side)"
    )
    assert want in out.stdout, out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
def test_refine_disparity_refuses_a_huge_or_mismatched_pair_before_copying_it() -> None:
    """``refine_disparity`` copied ``left`` (and ``right``) before the kernel refused a size past
    its 32-bit warp columns, or a ``right`` of another shape: a broadcast 65536 x 65536 ``left``
    was its 16 GiB copy's MemoryError under ``ulimit -v`` (the memory taken without one)."""
    out = _under_address_limit("refine_before_copies", 3_000_000 * 1024, timeout=60)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    assert out.stdout.splitlines() == [
        "ValueError: left: image of 65536x65536 pixels is too large: the kernels index pixels "
        "with 32-bit integers (at most 4294967295 pixels, 2147483647 per side)",
        "ValueError: right: expected shape (65536, 65536) like left, got (6, 8)",
    ], out.stdout


def test_pair_kernels_refuse_a_huge_or_mismatched_pair_before_copying_it() -> None:
    """gabor_disparity, hopfield_match, hopfield_candidates, mcgm_match and mcgm_filter copied a
    broadcast ``left`` before the kernel refused its size, or a ``right`` of another shape, as
    refine_disparity did: a 65536 x 65536 one was "MemoryError: out of memory: a copy of left
    needs 16.00 GiB" under ``ulimit -v`` (the memory taken without one)."""
    out = _under_address_limit("pairs_before_copies", 3_000_000 * 1024, timeout=60)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    too_large = (
        "ValueError: left: image of 65536x65536 pixels is too large: the kernels index pixels "
        "with 32-bit integers (at most 4294967295 pixels, 2147483647 per side)"
    )
    differ = (
        "ValueError: left and right images differ in size: left (65536, 65536), right (8, 6) "
        "(width, height)"
    )
    assert out.stdout.splitlines() == [too_large] * 5 + [differ] * 5, out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
def test_sgm_and_newton_step_refuse_a_mismatched_pair_before_copying_it() -> None:
    """f6745d9f's siblings: sgm_disparity and gabor_newton_step copied a broadcast 65536 x 65536
    ``left`` before refusing a ``right`` of another shape: "MemoryError: out of memory: a copy
    of left needs 16.00 GiB" under ``ulimit -v`` (the memory taken without one)."""
    out = _under_address_limit("mismatch_before_copies", 3_000_000 * 1024, timeout=60)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    differ = (
        "ValueError: left and right images differ in size: left (65536, 65536), right (8, 6) "
        "(width, height)"
    )
    assert out.stdout.splitlines() == [differ] * 2, out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
def test_scalar_kernels_refuse_a_bad_parameter_before_copying() -> None:
    """``gabor_responses``, ``depth_rectified`` and ``gabor_newton_step`` copied a broadcast
    65536 x 65536 image or map (16 GiB each) before the kernel refused a NaN ``freq`` or
    ``fb``: "MemoryError: out of memory: a copy of img needs 16.00 GiB" under ``ulimit -v``
    (the memory taken without one). The kernel's own words now, before any copy."""
    out = _under_address_limit("params_before_copies", 3_000_000 * 1024, timeout=60)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    freq = "ValueError: invalid parameter `freq`: must be in (0, 0.5) cycles/px, got NaN"
    assert out.stdout.splitlines() == [
        freq,
        "ValueError: invalid parameter `fb`: must be finite, got NaN",
        freq,
    ], out.stdout


@pytest.mark.parametrize("channels", [2, 5])
def test_8_bit_images_of_other_channel_counts_name_the_image(channels: int) -> None:
    """The 8-bit kernels read 1, 3 or 4 channels; another count was "invalid parameter
    `channels`", a parameter none of them has: the error names the array now."""
    img = np.zeros((6, 8, channels), np.uint8)
    mean = img.astype(np.float32)
    grid = (np.ones((6, 8), np.uint8), np.zeros((6, 8), np.float32))
    says = f"expected 1, 3 or 4 channels, got {channels} (shape [6, 8, {channels}])"
    for name, call in [
        ("image", lambda: _core.gray_u8(img, LUMA_WEIGHTS_BGR)),
        ("left", lambda: _core.hopfield_match_u8(img, img, LUMA_WEIGHTS_BGR, {})),
        ("frame", lambda: _core.temporal_grey_difference(img, mean)),
        ("frame", lambda: _core.temporal_running_mean(img, mean.copy(), *grid, 2.0, 8)),
    ]:
        with pytest.raises(ValueError, match=re.escape(f"{name}: {says}")):
            call()


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
def test_8_bit_images_of_too_many_channels_are_refused_before_copying() -> None:
    """``gray_u8``, ``hopfield_match_u8`` and the temporal kernels copied a broadcast
    (1, 1, 2**32) image (4 GiB: a MemoryError under ``ulimit -v``, the memory taken without
    one) before the kernel refused its channel count."""
    out = _under_address_limit("u8_too_deep", 3_000_000 * 1024, timeout=60)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    says = "expected 1, 3 or 4 channels, got 4294967296 (shape [1, 1, 4294967296])"
    assert out.stdout.splitlines() == [
        f"ValueError: {name}: {says}" for name in ("image", "left", "frame", "frame")
    ], out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
@pytest.mark.parametrize(
    ("case", "message"),
    [
        (
            "segments_too_wide",
            "ValueError: image: image of 1099511627776x1 pixels is too large: the kernels index "
            "pixels with 32-bit integers (at most 2147483648 pixels, 2147483647 per side)",
        ),
        (
            "segments_too_large",
            "ValueError: image: image of 65536x65536 pixels is too large: the kernels index "
            "pixels with 32-bit integers (at most 2147483648 pixels, 2147483647 per side)",
        ),
        (
            "segments_too_deep",
            "MemoryError: out of memory: a copy of image needs 4096.00 GiB (4398046511104 bytes)",
        ),
    ],
)
def test_graph_segments_refuses_a_huge_image_before_reading_it(case: str, message: str) -> None:
    """``graph_segments`` looked for NaN over the whole view, with the GIL held, before any
    size check or copy: a broadcast (1, 2**40, 3) image kept the process reading 3.3e12 values,
    deaf to Ctrl-C (this test's 60 s ran out), and (65536, 65536, 3) read 1.3e10 first. The
    shape is refused now as the kernel would, and too many channels fail the copy at once."""
    out = _under_address_limit(case, 3_000_000 * 1024, timeout=60)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    assert message in out.stdout, out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
@pytest.mark.parametrize(
    ("case", "message"),
    [
        (
            "log_too_large",
            "img: image of 65536x65536 pixels is too large: the kernels index pixels with 32-bit "
            "integers (at most 4294967295 pixels, 2147483647 per side)",
        ),
        ("log_bad_sigma", "sigma must lie in [0.3, 64] px, got 0"),
    ],
)
def test_mcgm_log_refuses_before_copying_the_image(case: str, message: str) -> None:
    """``mcgm_log`` copied a non-contiguous (broadcast) image before checking anything: a
    65536 x 65536 one was a 16 GiB MemoryError under ``ulimit -v``, not the size's ValueError
    the matcher gives, and a bad sigma was said only after that copy."""
    out = _under_address_limit(case, 3_000_000 * 1024)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    assert f"ValueError: {message}" in out.stdout, out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
@pytest.mark.parametrize(
    ("case", "message"),
    [
        ("mcgm_filter_nan", "rows have a NaN or infinite coordinate (row 0: "),
        ("mcgm_filter_outside", "rows lie outside the 64x40 images (row 0: "),
    ],
)
def test_mcgm_filter_counts_bad_rows_without_listing_them(case: str, message: str) -> None:
    """``mcgm_filter``'s row check collected the indices of every bad row (8 bytes a row) with
    an unchecked ``collect``: 2**29 broadcast bad rows aborted the process (SIGABRT) under
    ``ulimit -v`` instead of refusing them with the count. The matches' copy (24 bytes a row)
    is reserved before the check now, so 2**29 rows are its MemoryError there; 2**25 fit and
    are refused with the count. At 2**25 a list of them (256 MiB) fits under the limit too:
    the peak resident size says whether one was made (the copy is reserved, never written)."""
    out = _under_address_limit(case, 3_000_000 * 1024)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    n = 2**25
    assert f"ValueError: matches: {n} of {n} {message}" in out.stdout, out.stdout
    grew = int(out.stdout.split("peak RSS grew by")[1])
    assert grew < 64 * 1024, f"{grew} KiB: the check holds something N-sized ({n} rows)"


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
def test_the_other_arguments_shapes_are_checked_before_an_image_is_copied() -> None:
    """``temporal_grey_difference``, ``temporal_running_mean`` and ``hopfield_match_u8`` copied
    the frame or left image, and ``refine_disparity`` both images, before the shapes of the
    other arguments were compared: a broadcast (65536, 65536, 3) frame with a mean of another
    shape was the frame's 12 GiB copy (its MemoryError under ``ulimit -v``), not the mismatch."""
    out = _under_address_limit("shapes_before_copies", 3_000_000 * 1024, timeout=120)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    assert out.stdout.splitlines() == [
        "ValueError: mean shape [6, 8, 3] differs from the frame's [65536, 65536, 3]",
        "ValueError: mean shape [6, 8, 3] differs from the frame's [65536, 65536, 3]",
        "ValueError: left and right images must have the same shape, got left "
        "[65536, 65536, 3] and right [6, 8, 3]",
        "ValueError: disp: expected shape (65536, 65536) like left, got (6, 8)",
    ], out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
def test_mcgm_filter_refuses_huge_matches_before_reading_them() -> None:
    """``mcgm_filter`` checked every row of ``matches`` (finite, inside the images) with the
    GIL held before reserving their copy: (2**40, 4) broadcast rows kept the process reading
    4.4e12 values, deaf to Ctrl-C (this test's 60 s ran out). The copy that cannot be made is
    said at once now."""
    out = _under_address_limit("mcgm_filter_huge", 3_000_000 * 1024, timeout=60)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    want = "MemoryError: out of memory: a copy of matches needs 24576.00 GiB (26388279066624 bytes)"
    assert want in out.stdout, out.stdout


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
def test_the_census_memory_check_counts_the_address_space_limit() -> None:
    """``_available_bytes`` read MemAvailable and cgroups only: under ``ulimit -v`` the check
    passed and the kernel's allocation failed."""
    limit = 3_000_000 * 1024
    out = _under_address_limit("available", limit)
    assert out.returncode == 0, out.stderr[-2000:]
    avail = int(out.stdout.split()[1])
    assert 0 < avail < limit


#: Runs a matcher on a large flat image under ``ulimit -v`` set just above what the process
#: holds (plus the bindings' copies of the pair, when they copy it), so that the kernel's own
#: first large buffer fails. The matcher runs once on a small pair first: its worker threads and
#: their heaps exist before the limit.
_KERNEL_OOM_SCRIPT = """
import resource
import sys

import numpy as np
from stereovision import _core

case, side, copies = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])


def run(a):
    if case == "gabor":
        _core.gabor_disparity(a, a, 0.0, 8.0)
    elif case == "gabor-one-way":
        _core.gabor_disparity(a, a, 0.0, 8.0, lr_check=False)
    elif case == "mcgm":
        _core.mcgm_match(a, a, {})
    elif case == "fattened":
        _core.fattened(a, a, 7, 1.5, 2.0)
    elif case == "depth":
        _core.depth_rectified(a, a, 50.0, 2.0, 0.74, -0.52, 0.2, 0.9)
    elif case == "refine":
        fills = [(16.0, 0.3)]
        args = (4.0, 4.5, 9, 2, 0.5, 2, 1.0, 1e-6, fills, 0.25, True, float("inf"))
        _core.refine_disparity(a, a, a, a, 0.0, 8.0, *args)
    elif case == "segments":
        _core.graph_segments(a[:, :, None], 300.0, 20)
    elif case == "census":
        _core.sgm_disparity(a, a, 0, 15, 8, 96, 16.0, 5, 1, 4)
    elif case == "grey":
        _core.gray_u8(a.reshape(-1).view(np.uint8)[: a.size].reshape(a.shape), (0.1, 0.6, 0.3))
    elif case == "planes":
        a[0, 0] = np.nan  # a hole to fill
        img = a.reshape(-1).view(np.uint8)[: a.size].reshape(*a.shape, 1)
        _core.fill_planes(a, img, [(16, 50)], 0.7)
    elif case == "speckles":
        # No two neighbours within max_diff (in place, no new memory): one label a pixel.
        a[:, 1::2] = 10.0
        a[1::2, :] += 20.0
        _core.gabor_remove_speckles(a, 2, 1.0)
    elif case == "temporal":
        # A uint8 frame viewing the first bytes of ``a``: no new memory.
        frame = a.reshape(-1).view(np.uint8)[: a.size].reshape(a.shape)
        _core.temporal_grey_difference(frame, a)
    else:
        _core.hopfield_match(a, a, {})


run(np.random.default_rng(0).random((64, 96), dtype=np.float32))
a = np.zeros((side, side), np.float32)
with open("/proc/self/status") as f:
    held = next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmSize:"))
limit = held + copies * a.nbytes + (256 << 20)
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
try:
    run(a)
except MemoryError as e:
    print("MemoryError:", e)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
@pytest.mark.parametrize(
    ("case", "side", "copies", "matcher"),
    [
        ("gabor", 16384, 0, "Gabor matcher"),
        # Without the left-right check no mirrored pair: the pooled planes come first.
        ("gabor-one-way", 16384, 0, "Gabor matcher"),
        ("mcgm", 8192, 2, "MCGM matcher"),
        ("hopfield", 16384, 0, "Hopfield matcher"),
        ("fattened", 16384, 0, "fattened-edge check's"),
        ("depth", 16384, 0, "depth map"),
        ("refine", 16384, 0, "refinement's window statistics"),
        ("segments", 16384, 0, "graph segmentation's edges"),
        ("temporal", 16384, 0, "temporal filter's grey difference"),
        # Small enough for the output map to fit: the census codes come next.
        ("census", 6144, 0, "census matcher's census codes"),
        ("grey", 16384, 0, "grey image"),
        # The binding's copy of the map fits; the kernel's regions do not.
        ("planes", 16384, 1, "colour regions' tables"),
        # The binding's copy, the labels and the bands' tables fit; the merged tables do not.
        ("speckles", 4096, 1, "speckle filter's label tables"),
    ],
)
def test_a_matcher_that_runs_out_of_memory_raises_memory_error(
    case: str, side: int, copies: int, matcher: str
) -> None:
    """The Gabor, MCGM and Hopfield kernels, the fattened-edge check, depth from disparity,
    the refinement, the graph segmentation, the plane fill, the temporal filter, the census
    codes and the 8-bit grey conversion allocated their image-sized buffers with ``vec!`` or
    ``collect``: a failed allocation aborted the whole process (SIGABRT, exit -6). The
    kernel's own buffer is named, with its size."""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    out = subprocess.run(
        [sys.executable, "-c", _KERNEL_OOM_SCRIPT, case, str(side), str(copies)],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    pattern = (
        rf"MemoryError: out of memory: [^\n]*{matcher}[^\n]* needs \d+\.\d\d [MG]iB "
        r"\(\d+ bytes\) and the allocation failed"
    )
    assert re.search(pattern, out.stdout), out.stdout


#: Runs the census matcher on a pair of two wide rows with 2048 levels under ``ulimit -v`` set
#: 256 MiB above what the process holds, after a small pair in both modes (its worker threads
#: and their heaps exist before the limit). The path buffers are then the first that do not fit.
_SGM_PATHS_OOM_SCRIPT = """
import resource
import sys

import numpy as np
from stereovision import _core

width, paths = int(sys.argv[1]), int(sys.argv[2])
small = np.random.default_rng(0).random((64, 96), dtype=np.float32)
for p in (3, 8):
    _core.sgm_disparity(small, small, 0, 15, 8, 96, 16.0, 5, 1, 4, p)
a = np.random.default_rng(1).random((2, width), dtype=np.float32)
with open("/proc/self/status") as f:
    held = next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmSize:"))
limit = held + (256 << 20)
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
try:
    _core.sgm_disparity(a, a, 0, 2047, 8, 96, 16.0, 5, 1, 4, paths)
    print("matched")
except MemoryError as e:
    print("MemoryError:", e)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
@pytest.mark.parametrize(
    ("width", "paths", "message"),
    [
        # Two rows of 65536 x 2050 path costs: the second does not fit.
        (65536, 3, "vertical path costs needs 128.12 MiB (134348800 bytes)"),
        # The vertical path (2 x 67 MB) and a row's costs fit, its path sums do not.
        (32768, 3, "row path sums needs 128.00 MiB (134217728 bytes)"),
        # The cost volume and the passes' row sums fit, their six rows of path costs do not.
        (16384, 8, "path costs needs 32.03 MiB (33587200 bytes)"),
    ],
)
def test_sgm_path_buffers_that_do_not_fit_raise_memory_error(
    width: int, paths: int, message: str
) -> None:
    """The 8-path passes' path costs and the 3-path vertical path and rows in flight were
    allocated with ``vec!``: a failed allocation aborted the whole process (SIGABRT, exit -6)."""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    out = subprocess.run(
        [sys.executable, "-c", _SGM_PATHS_OOM_SCRIPT, str(width), str(paths)],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    want = f"MemoryError: out of memory: the census matcher's {message} and the allocation failed"
    assert want in out.stdout, out.stdout


#: Each ``_core`` function that takes a parameter dict, called with one extra key.
PARAM_DICT_CALLS: dict[str, Callable[[np.ndarray, dict[str, object]], object]] = {
    "hopfield_match": lambda g, p: _core.hopfield_match(g, g, p),
    "hopfield_match_u8": lambda g, p: _core.hopfield_match_u8(
        (g * 255).astype(np.uint8), (g * 255).astype(np.uint8), LUMA_WEIGHTS_BGR, p
    ),
    "hopfield_candidates": lambda g, p: _core.hopfield_candidates(g, g, p),
    "mcgm_match": lambda g, p: _core.mcgm_match(g, g, p),
    "mcgm_curves": lambda g, p: _core.mcgm_curves(g, p),
    "mcgm_filter": lambda g, p: _core.mcgm_filter(g, g, np.zeros((0, 4), np.float32), p),
}


@pytest.mark.parametrize("call", list(PARAM_DICT_CALLS))
def test_an_unknown_key_of_a_parameter_dict_is_refused(call: str) -> None:
    """The Python wrappers refuse a misspelt keyword first (with "did you mean"); the bindings'
    own refusal of a key they do not know, for a caller of ``_core``, was unasserted: a
    mutation audit dropping it left every test passing, the key ignored without a word."""
    g = np.random.default_rng(0).random((24, 40), dtype=np.float32)
    channel = "Hopfield" if call.startswith("hopfield") else "MCGM"
    run = PARAM_DICT_CALLS[call]
    run(g, {"max_disparity": 8})
    with pytest.raises(ValueError, match=rf"^unknown {channel} parameter `max_disparit`$"):
        run(g, {"max_disparity": 8, "max_disparit": 4})


@pytest.mark.parametrize(("cl", "cr"), [(3, 4), (4, 3), (1, 3)])
def test_hopfield_match_u8_refuses_pairs_of_other_channel_counts(cl: int, cr: int) -> None:
    """Only the height and width of the pair were asserted: a mutation audit comparing those
    alone left every test passing; the kernel then refused the right image as "invalid
    parameter `image`: buffer of 3840 bytes does not hold 24x40x3", naming neither image."""
    rng = np.random.default_rng(0)
    left = rng.integers(0, 256, (24, 40, cl), dtype=np.uint8)
    right = rng.integers(0, 256, (24, 40, cr), dtype=np.uint8)
    _core.hopfield_match_u8(left, left, LUMA_WEIGHTS_BGR, {"max_disparity": 8})
    says = (
        "left and right images must have the same shape, got left "
        f"[24, 40, {cl}] and right [24, 40, {cr}]"
    )
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.hopfield_match_u8(left, right, LUMA_WEIGHTS_BGR, {"max_disparity": 8})


def test_mcgm_filter_refuses_a_range_one_short() -> None:
    """``max_disparity`` one below ``min_disparity`` is refused and an equal one taken: a
    mutation audit letting the range be one short left every test passing."""
    g = np.random.default_rng(0).random((30, 50), dtype=np.float32)
    ms = np.array([[25, 15, 17, 15]], np.float32)
    keep = _core.mcgm_filter(g, g, ms, {"min_disparity": 8, "max_disparity": 8})
    assert keep.shape == (1,) and keep.dtype == np.bool_
    says = "invalid parameter `max_disparity`: must be >= min_disparity (8), got 7"
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.mcgm_filter(g, g, ms, {"min_disparity": 8, "max_disparity": 7})


def test_plane_fill_labels_must_lie_below_the_pixel_count() -> None:
    """A label of H * W (one past the largest ``segments()`` gives) is refused, H * W - 1
    taken: a mutation audit letting H * W through left every test passing (the kernel then
    panicked: "RuntimeError: internal error in plane_fill: labels must be below ...")."""
    disp = np.tile(np.arange(12, dtype=np.float32), (8, 1))
    disp[3, 4:7] = np.nan
    labels = np.zeros(disp.shape, np.uint32)
    labels[0, 0] = disp.size - 1
    _core.plane_fill(disp, labels, 5, 1.0, 0.0, 20.0)
    labels[0, 0] = disp.size
    says = "labels: expected values below H * W = 96, as segments() numbers them"
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.plane_fill(disp, labels, 5, 1.0, 0.0, 20.0)


@pytest.mark.parametrize("shape", [(4, 5, 0), (0, 5, 3), (4, 0, 3)])
def test_graph_segments_refuses_an_image_with_a_zero_size(shape: tuple[int, int, int]) -> None:
    """An image of no channels was unasserted: a mutation audit letting it through to the
    kernel left every test passing (it panicked: "RuntimeError: internal error in
    graph_segments: image size does not match w * h * c")."""
    _core.graph_segments(np.zeros((4, 5, 3), np.float32), 1.0, 2)
    says = f"image: expected (H, W, C) with no zero size, got {shape}"
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.graph_segments(np.zeros(shape, np.float32), 1.0, 2)


def test_a_map_or_confidence_of_another_shape_names_the_argument() -> None:
    """``depth_rectified`` and ``refine_disparity`` said "confidence shape (1, 8) differs from
    the expected shape (6, 8)" of their argument ``conf`` (and "disparity" of ``disp``), the
    expected shape from an argument they did not name, and copied a strided ``disp`` before
    checking ``conf``."""
    g = np.random.default_rng(0).random((6, 8), dtype=np.float32)
    d, c = np.full_like(g, 2.0), np.full_like(g, 0.5)
    sigma = (50.0, 2.0, 0.74, -0.52, 0.2, 0.9)
    with pytest.raises(
        ValueError, match=re.escape("conf: expected shape (6, 8) like disp, got (1, 8)")
    ):
        _core.depth_rectified(d, c[:1], *sigma)
    with pytest.raises(
        ValueError, match=re.escape("disp: expected shape (6, 8) like left, got (6, 7)")
    ):
        _core.refine_disparity(g, g, d[:, :7], c, *REFINE_ARGS)
    with pytest.raises(
        ValueError, match=re.escape("conf: expected shape (6, 8) like left, got (8, 6)")
    ):
        _core.refine_disparity(g, g, d, c.T.copy(), *REFINE_ARGS)
    z, _ = _core.depth_rectified(d, c, *sigma)
    np.testing.assert_array_equal(z, np.full_like(g, 12.5))  # 50 / (2 + 2)


@pytest.mark.parametrize(
    "call",
    [
        lambda a: _core.hopfield_interest(a),
        lambda a: _core.mcgm_log(a, 2.0),
        lambda a: _core.mcgm_curves(a, {}),
    ],
    ids=["hopfield_interest", "mcgm_log", "mcgm_curves"],
)
@pytest.mark.parametrize("order", ["C", "F"])
def test_kernels_taking_img_name_it_img(call: Callable[[np.ndarray], object], order: str) -> None:
    """``hopfield_interest``, ``mcgm_log`` and ``mcgm_curves`` take ``img``: a float64 one was
    "img: expected a float32 array", a NaN in it "image: image contains non-finite values",
    an argument none of them has."""
    a = np.zeros((20, 30), np.float32, order=order)
    a[3, 4] = np.nan
    with pytest.raises(ValueError, match=r"^img: image contains non-finite values .* at 1 pix"):
        call(a)
    with pytest.raises(TypeError, match=r"^img: expected a float32 array, got float64$"):
        call(a.astype(np.float64))


@pytest.mark.parametrize("right_shape", [(6, 8), (6, 10), (5, 9)])
def test_lr_check_maps_must_have_one_shape(right_shape: tuple[int, int]) -> None:
    """A right map of another width was unasserted: a mutation audit comparing the heights
    alone left every test passing (a narrower map then panicked, "index out of bounds", and
    a wider one was read with the left's width without a word)."""
    d = np.full((6, 9), 2.0, np.float32)
    says = f"disp_left (6, 9) and disp_right {right_shape} differ in shape"
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.gabor_lr_check(d, np.full(right_shape, 2.0, np.float32), 1.0)


def test_hopfield_interest_refuses_a_zero_suppression_radius() -> None:
    """The Python wrapper refuses ``nms_half=0`` before the extension sees it; the extension's
    own refusal was unasserted: a mutation audit dropping it left every test passing (no
    suppression at all: 336 points on this image instead of 20, without a word)."""
    g = np.random.default_rng(0).random((20, 30), dtype=np.float32)
    assert len(_core.hopfield_interest(g, nms_half=1)[1]) > 0
    says = "rel_threshold and floor_rel must lie in [0, 1] and nms_half be >= 1"
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.hopfield_interest(g, nms_half=0)


@pytest.mark.parametrize(("step", "offset"), [(256, 0), (0, 0), (16, 256)])
def test_quantised_regions_bounds_are_the_bytes(step: int, offset: int) -> None:
    """Step 1-255 and offset 0-255: their ends were unasserted, and a mutation audit letting a
    step of 256 through left every test passing (one region, without a word)."""
    img = np.random.default_rng(0).integers(0, 256, (6, 8, 3), dtype=np.uint8)
    assert _core.quantised_regions(img, 255, 255).shape == (6, 8)
    assert _core.quantised_regions(img, 1, 0).max() > 0
    says = f"step must be in 1-255 and offset in 0-255, got step={step}, offset={offset}"
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.quantised_regions(img, step, offset)


@pytest.mark.parametrize(("step", "ok"), [(0, False), (1, True), (255, True), (256, False)])
def test_fill_planes_pass_steps_are_1_to_255(step: int, ok: bool) -> None:
    """The Python wrapper refuses a step of 0 first; the extension's own refusal was
    unasserted: a mutation audit letting 0 through left every test passing (the kernel then
    panicked: "RuntimeError: internal error in fill_planes: step must be positive")."""
    disp = np.tile(np.arange(12, dtype=np.float32), (8, 1))
    disp[3, 4:7] = np.nan
    img = np.zeros((8, 12, 3), np.uint8)
    if ok:
        assert np.isfinite(_core.fill_planes(disp, img, [(step, 5)], 1.0)).all()
        return
    says = f"invalid parameter `passes`: element 0 (({step}, 5)): step must be an integer in 1-255"
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.fill_planes(disp, img, [(step, 5)], 1.0)


def test_gabor_iters_per_level_reaches_the_kernel(crop: tuple[np.ndarray, np.ndarray]) -> None:
    """``iters_per_level`` and ``iters_finest`` both default to 1: a mutation audit passing
    ``iters_finest`` for ``iters_per_level`` left every test passing (3 iterations per
    level gave the map of 1)."""
    gl, gr = (as_gray_float(a) for a in crop)

    def run(per_level: int, finest: int) -> np.ndarray:
        d, _ = _core.gabor_disparity(
            gl, gr, 0.0, 32.0, iters_per_level=per_level, iters_finest=finest
        )
        return d

    one = run(1, 1)
    assert not np.array_equal(run(3, 1), one, equal_nan=True)
    assert not np.array_equal(run(3, 1), run(1, 3), equal_nan=True)


def test_mcgm_disc_dy_reaches_the_discontinuity_filter(crop: tuple[np.ndarray, np.ndarray]) -> None:
    """``disc_dy`` was unasserted at the binding: a mutation audit writing it into ``disc_dx``
    left every test passing. More rows in the window drop more matches; -1 is named."""
    gl, gr = (as_gray_float(a) for a in crop)
    off = {"max_disparity": 32, "disc": False, "sides": False}
    ms = np.ascontiguousarray(_core.mcgm_match(gl, gr, off)[0][:, :4])
    assert len(ms) > 300
    on = {**off, "disc": True}
    kept = [int(_core.mcgm_filter(gl, gr, ms, {**on, "disc_dy": dy}).sum()) for dy in (0, 1, 3, 8)]
    assert kept == sorted(set(kept), reverse=True), kept
    with pytest.raises(ValueError, match=re.escape("disc_dx = 6, disc_dy = -1")):
        _core.mcgm_filter(gl, gr, ms, {**on, "disc_dy": -1})


@pytest.mark.parametrize(
    ("call", "key", "value"),
    [
        (_core.hopfield_match, "min_disparity", -1),
        (_core.hopfield_match, "seed", 2**64),
        (_core.mcgm_match, "max_disparity", 2**70),
    ],
)
def test_a_dict_integer_out_of_range_names_its_range(
    call: Callable[..., object], key: str, value: int
) -> None:
    """The Python wrappers refuse these first; through ``_core`` the message naming the range
    was unasserted: a mutation audit giving back "parameter `min_disparity`: OverflowError:
    can't convert negative int to unsigned" left every test passing."""
    g = np.random.default_rng(0).random((20, 30), dtype=np.float32)
    says = f"invalid parameter `{key}`: expected an integer from 0 to {2**64 - 1}, got {value}"
    with pytest.raises(ValueError, match=f"^{re.escape(says)}$"):
        call(g, g, {key: value})


@pytest.mark.parametrize(
    ("name", "call"),
    [
        ("tau", lambda d, g, v: _core.side_fill(d, np.zeros((*d.shape, 3), np.float32), v)),
        ("ratio", lambda d, g, v: _core.fattened(d, g, 3, v, 2.0)),
        ("jump", lambda d, g, v: _core.fattened(d, g, 3, 2.0, v)),
        ("max_diff", lambda d, g, v: _core.gabor_remove_speckles(d, 10, v)),
        ("k", lambda d, g, v: _core.graph_segments(np.zeros((*d.shape, 3), np.float32), v, 2)),
        (
            "max_residual",
            lambda d, g, v: _core.plane_fill(d, np.zeros(d.shape, np.uint32), 5, v, 0.0, 9.0),
        ),
    ],
)
def test_non_negative_arguments_must_be_finite(
    name: str, call: Callable[[np.ndarray, np.ndarray, float], object]
) -> None:
    """0 is taken, infinity refused: a mutation audit letting infinity through (NaN and
    negative numbers still refused) left every test passing."""
    d = np.tile(np.arange(12, dtype=np.float32), (8, 1))
    g = np.ones_like(d)
    call(d, g, 0.0)
    says = f"{name}: expected a non-negative number, got inf"
    with pytest.raises(ValueError, match=f"^{re.escape(says)}$"):
        call(d, g, float("inf"))


def test_gabor_lr_coarse_levels_reaches_the_kernel(crop: tuple[np.ndarray, np.ndarray]) -> None:
    """``lr_coarse_levels`` and ``iters_finest`` both default to 1: a mutation audit passing
    each for the other left every test passing. Without the left-right check the coarse levels
    of the backward pass do nothing; iterations at full resolution do; 5 is named."""
    gl, gr = (as_gray_float(a) for a in crop)

    def run(**kw: object) -> np.ndarray:
        return _core.gabor_disparity(gl, gr, 0.0, 32.0, lr_check=False, **kw)[0]

    one = run()
    for levels in (0, 3):
        np.testing.assert_array_equal(run(lr_coarse_levels=levels), one)
    assert not np.array_equal(run(iters_finest=3), one, equal_nan=True)
    with pytest.raises(ValueError, match=re.escape("`lr_coarse_levels`: must be <= 4")):
        _core.gabor_disparity(gl, gr, 0.0, 32.0, lr_coarse_levels=5)


def test_hopfield_compat_theta_and_slope_reach_their_slots(
    crop: tuple[np.ndarray, np.ndarray],
) -> None:
    """``compat_theta`` and ``compat_slope`` are both float and both 2.0 by default: a
    mutation audit writing each into the other's slot was caught only by the names in the
    negative-value messages. A slope of 0 makes the compatibility 0 at every distance, so the
    crossing no longer matters; with a slope it does."""
    gl, gr = (as_gray_float(a) for a in crop)

    def run(theta: float, slope: float) -> tuple[np.ndarray, np.ndarray]:
        params = {"max_disparity": 32, "compat_theta": theta, "compat_slope": slope}
        m, trace, _ = _core.hopfield_match(gl, gr, params)
        return m, trace

    flat = run(0.5, 0.0)
    assert len(flat[0]) > 50
    for got, want in zip(run(8.0, 0.0), flat, strict=True):
        np.testing.assert_array_equal(got, want)
    assert not np.array_equal(run(0.5, 2.0)[1], run(8.0, 2.0)[1])


@pytest.mark.parametrize("name", ["prior_radius_sigmas", "prior_width_sigmas"])
def test_mcgm_prior_slots_are_their_own(name: str, crop: tuple[np.ndarray, np.ndarray]) -> None:
    """``prior_radius_sigmas`` and ``prior_width_sigmas`` are neighbouring float slots: a
    mutation audit writing each into the other left every test passing (test_mcgm's reference
    figures included: a radius of 2.8 and a width of 4 changed no asserted figure). The kernel
    names the slot a negative value reached."""
    gl, gr = (as_gray_float(a) for a in crop)
    with pytest.raises(ValueError, match=f"^invalid parameter `{name}`"):
        _core.mcgm_match(gl, gr, {"max_disparity": 32, name: -1.0})


@pytest.mark.parametrize(
    ("d_min", "d_max", "said"),
    [
        (float("nan"), 10.0, "invalid parameter `d_min`: must be finite, got NaN"),
        (0.0, float("inf"), "invalid parameter `d_max`: must be finite, got inf"),
        (5.0, 5.0, "invalid parameter `d_max`: must be > d_min (5), got 5"),
    ],
)
def test_refine_disparity_names_the_bound_it_refuses(d_min: float, d_max: float, said: str) -> None:
    """``refine_disparity`` said "invalid parameter `range`: need finite d_min < d_max, got NaN,
    10": no argument of that name; each bound is named now, in ``gabor_disparity``'s words."""
    a = np.random.default_rng(0).random((8, 12), dtype=np.float32)
    with pytest.raises(ValueError) as err:
        _core.refine_disparity(a, a, a, a, d_min, d_max, *REFINE_ARGS[2:])
    assert str(err.value) == said


@pytest.mark.parametrize(
    ("call", "said"),
    [
        (
            lambda a: _core.gabor_lr_check(a, a, 1e39),
            "invalid parameter `tol`: expected a number within float32's range, the kernel's "
            "precision, got 1e+39",
        ),
        (
            lambda a: _core.depth_rectified(a, a, 1e-50, 0.0, 1.0, 0.0, 0.1, 1.0),
            "invalid parameter `fb`: 1e-50 is 0 in float32, the kernel's precision (give 0, or "
            "a magnitude of at least 1e-45)",
        ),
        (
            lambda a: _core.gabor_responses(a, freq=10**400),
            "invalid parameter `freq`: expected a number within float32's range, the kernel's "
            f"precision, got {10**400}",
        ),
        (
            lambda a: _core.hopfield_match(a, a, {"compat_theta": -1e39}),
            "invalid parameter `compat_theta`: expected a number within float32's range, the "
            "kernel's precision, got -1e+39",
        ),
        (
            # an int past a double in a dict's float slot: it was "parameter `sides_mad`:
            # OverflowError: int too large to convert to float"
            lambda a: _core.mcgm_match(a, a, {"sides_mad": 10**400}),
            "invalid parameter `sides_mad`: expected a number within float32's range, the "
            f"kernel's precision, got {10**400}",
        ),
        (
            # a list's angle: it was cut to inf ("each must be in (-90, 90) degrees ..., got inf")
            lambda a: _core.gabor_newton_step(a, a, a, orientations_deg=[0.0, 1e39]),
            "invalid parameter `orientations_deg`: expected a number within float32's range, "
            "the kernel's precision, got 1e+39",
        ),
    ],
)
def test_a_float_argument_float32_cannot_hold_is_named(
    call: Callable[[np.ndarray], object], said: str
) -> None:
    """The bindings cut a float argument to float32 before any check: ``tol=1e39`` became inf
    and passed every pixel without a word, ``fb=1e-50`` was "must be > 0, got 0", 10**400 a
    bare OverflowError naming nothing. Such a value is refused naming the argument and the
    value given; NaN and inf still reach the kernels' own checks."""
    a = np.random.default_rng(0).random((8, 12), dtype=np.float32)
    with pytest.raises(ValueError) as err:
        call(a)
    assert str(err.value) == said


def test_a_float_argument_that_is_no_number_names_it() -> None:
    """A str for a float argument was NumPy's bare "must be real number, not str"."""
    a = np.zeros((8, 12), np.float32)
    with pytest.raises(TypeError) as err:
        _core.gabor_responses(a, freq="0.25")  # type: ignore[arg-type]
    assert str(err.value) == "invalid parameter `freq`: must be real number, not str"
    ok = _core.gabor_lr_check(a, a, np.float64(2))  # NumPy scalars and ints still taken
    assert ok.shape == (8, 12) and _core.gabor_lr_check(a, a, 2).shape == (8, 12)


@pytest.mark.parametrize(
    ("call", "said"),
    [
        (
            # a sigma given > 0 was "invalid parameter `fill sigma`: must be > 0, got 0"
            lambda a: _core.refine_disparity(
                a, a, a, a, *REFINE_ARGS[:10], [(1e-50, 0.3)], 0.1, True, 1.0
            ),
            "invalid parameter `fill sigma`: 1e-50 is 0 in float32, the kernel's precision (give "
            "0, or a magnitude of at least 1e-45)",
        ),
        (
            # "invalid parameter `fill min_score`: must be in (-1, 1), got inf"
            lambda a: _core.refine_disparity(
                a, a, a, a, *REFINE_ARGS[:10], [(16.0, 1e39)], 0.1, True, 1.0
            ),
            "invalid parameter `fill min_score`: expected a number within float32's range, the "
            "kernel's precision, got 1e+39",
        ),
        (
            # "parameter `sigmas`: OverflowError: int too large to convert to float"
            lambda a: _core.mcgm_match(a, a, {"sigmas": [2.0, 10**400]}),
            "invalid parameter `sigmas`: expected a number within float32's range, the kernel's "
            f"precision, got {10**400}",
        ),
        (
            # "invalid parameter `sigmas`: each sigma must lie in [0.3, 64] px, got inf"
            lambda a: _core.mcgm_curves(a, {"sigmas": [1e39]}),
            "invalid parameter `sigmas`: expected a number within float32's range, the kernel's "
            "precision, got 1e+39",
        ),
        (
            # "weights: expected three finite non-negative numbers (B, G, R), got [inf, 0.5, 0.5]"
            lambda a: _core.gray_u8(np.zeros(a.shape, np.uint8), (1e39, 0.5, 0.5)),
            "invalid parameter `weights`: expected a number within float32's range, the "
            "kernel's precision, got 1e+39",
        ),
        (
            # a bare "OverflowError: int too large to convert to float"
            lambda a: _core.hopfield_match_u8(
                np.zeros(a.shape, np.uint8), np.zeros(a.shape, np.uint8), (0.1, 10**400, 0.3), {}
            ),
            "invalid parameter `weights`: expected a number within float32's range, the "
            f"kernel's precision, got {10**400}",
        ),
        (
            lambda a: _core.refine_disparity(
                a, a, a, a, *REFINE_ARGS[:10], [(16.0,)], 0.1, True, 1.0
            ),
            "invalid parameter `fills`: element 0 ((16.0,)): expected a (sigma, min_score) pair",
        ),
    ],
)
def test_a_float_in_a_sequence_argument_float32_cannot_hold_is_named(
    call: Callable[[np.ndarray], object], said: str
) -> None:
    """The numbers inside ``refine_disparity``'s ``fills``, the MCGM dict's ``sigmas`` and the
    8-bit kernels' ``weights`` skipped the float32 check the scalar arguments have (3b1afe37):
    cut to inf or 0 before the kernel's check, which then quoted a value not given (a fill
    sigma of 1e-50 "must be > 0, got 0", through ``refine.refine_disparity`` too), or a bare
    OverflowError naming nothing. In-range values are taken as before."""
    a = np.random.default_rng(0).random((8, 12), dtype=np.float32)
    with pytest.raises(ValueError) as err:
        call(a)
    assert str(err.value) == said
    r = _core.refine_disparity(
        a, a, a, a, *REFINE_ARGS[:10], [(1, 0.3), (2.0, -0.5)], 0.1, True, 1.0
    )
    assert r[0].shape == (8, 12)
    assert _core.gray_u8(np.zeros((2, 3, 3), np.uint8), (0, 1, np.float64(0.5))).shape == (2, 3)


def test_refine_disparity_reads_a_fill_given_as_a_list_pair() -> None:
    """``_core.refine_disparity``'s fills were extracted as tuples: a list pair ([16, 0.3],
    JSON's or a config's) was "element 0 ([16.0, 0.3]): expected a (sigma, min_score) pair" of
    a pair. Any sequence of two reads as the tuple does; a string or three values do not."""
    a = np.random.default_rng(0).random((8, 12), dtype=np.float32)

    def run(fills: object) -> tuple[np.ndarray, np.ndarray, int]:
        return _core.refine_disparity(a, a, a, a, *REFINE_ARGS[:10], fills, 0.1, True, 1.0)

    want = run([(16.0, 0.3)])
    for got in (run([[16.0, 0.3]]), run([np.array([16.0, 0.3])])):
        np.testing.assert_array_equal(got[0], want[0])
        assert got[2] == want[2]
    for bad, shown in (("ab", "'ab'"), ([16.0, 0.3, 1.0], "[16.0, 0.3, 1.0]")):
        with pytest.raises(ValueError) as err:
            run([bad])
        assert str(err.value) == (
            f"invalid parameter `fills`: element 0 ({shown}): expected a (sigma, min_score) pair"
        )


def test_refine_disparity_refuses_bytes_or_a_dict_as_a_fill_pair() -> None:
    """572c0f16 read any item of two as a fill pair: bytes (b"\\x10\\x00": 16, 0) and a
    dict ({0: 16.0, 1: 0.3}) were taken, refused before as the tuple alone was read."""
    a = np.random.default_rng(0).random((8, 12), dtype=np.float32)
    for bad, shown in (
        (b"\x10\x00", "b'\\x10\\x00'"),
        (bytearray(b"\x10\x00"), "bytearray(b'\\x10\\x00')"),
        ({0: 16.0, 1: 0.3}, "{0: 16.0, 1: 0.3}"),
    ):
        with pytest.raises(ValueError) as err:
            _core.refine_disparity(a, a, a, a, *REFINE_ARGS[:10], [bad], 0.1, True, 1.0)
        assert str(err.value) == (
            f"invalid parameter `fills`: element 0 ({shown}): expected a (sigma, min_score) pair"
        )


def test_mcgm_curves_refuses_a_huge_image_before_copying_it() -> None:
    """``mcgm_curves`` copied ``img`` before its kernel's 32-bit size check, which
    ``mcgm_log`` (1eeb7ba4) and the matchers make from the shape first: a broadcast
    (2**30, 2**30) image was "MemoryError: out of memory: a copy of img needs 4294967296.00
    GiB", a 65536 x 65536 one a 16 GiB copy. It is the size's ValueError now, copying nothing."""
    big = np.broadcast_to(np.float32(0), (2**30, 2**30))
    with pytest.raises(ValueError) as err:
        _core.mcgm_curves(big, {})
    assert str(err.value) == (
        "img: image of 1073741824x1073741824 pixels is too large: the kernels index pixels with "
        "32-bit integers (at most 4294967295 pixels, 2147483647 per side)"
    )


def test_hopfield_match_u8_refuses_a_huge_pair_before_copying_it() -> None:
    """``hopfield_match_u8`` copied ``left`` before the kernel's 32-bit size check, which
    ``hopfield_match`` makes from the shapes first: a broadcast (2**30, 2**30) uint8 pair was
    "MemoryError: out of memory: a copy of left needs 1073741824.00 GiB", a 65536 x 65536 x 3
    one two 12 GiB copies. It is the size's ValueError now, as for the float pair."""
    big = np.broadcast_to(np.uint8(5), (2**30, 2**30))
    with pytest.raises(ValueError) as err:
        _core.hopfield_match_u8(big, big, (0.114, 0.587, 0.299), {})
    assert str(err.value) == (
        "left: image of 1073741824x1073741824 pixels is too large: the kernels index pixels with "
        "32-bit integers (at most 4294967295 pixels, 2147483647 per side)"
    )


def test_lzf_decompress_takes_any_bytes_like_data_and_names_other_data() -> None:
    """Only ``bytes`` was taken: a ``bytearray`` or ``memoryview`` (a message's payload) was
    pyo3's "'bytearray' object is not an instance of 'bytes'", and a str or list the same words,
    naming no argument. Any bytes-like object is decoded as ``zlib.decompress`` takes it; other
    data is a TypeError naming ``data``."""
    stream = b"\x03abcd\x20\x03"  # "abcd", then 3 bytes from 4 back
    for data in (
        bytearray(stream),
        memoryview(b"xx" + stream)[2:],
        np.frombuffer(stream, np.uint8),
    ):
        assert _core.lzf_decompress(data, 7) == b"abcdabc"
    with pytest.raises(ValueError, match=r"^corrupt LZF data: the data decompress to 7 bytes"):
        _core.lzf_decompress(bytearray(stream), 8)
    for bad, name in (("abcd", "str"), ([3, 97], "list"), (5, "int")):
        with pytest.raises(TypeError) as err:
            _core.lzf_decompress(bad, 7)  # type: ignore[arg-type]
        assert str(err.value) == (
            "invalid parameter `data`: expected a bytes-like object (bytes, bytearray, "
            f"memoryview), got {name}"
        )


def test_lzf_decompress_says_why_a_released_memoryview_is_not_read() -> None:
    """A released memoryview was "expected a bytes-like object (bytes, bytearray, memoryview),
    got memoryview": a memoryview refused as none. Python's own reason is said now."""
    view = memoryview(bytearray(b"\x02abc"))
    view.release()
    with pytest.raises(ValueError) as err:
        _core.lzf_decompress(view, 3)
    assert str(err.value) == (
        "invalid parameter `data`: operation forbidden on released memoryview object"
    )


@pytest.mark.parametrize("empty", ["left", "right"])
def test_an_empty_8_bit_image_is_named(empty: str) -> None:
    """The 8-bit kernels said "image is empty: got 5x0 pixels" of an empty ``left`` or
    ``right`` (which one?), ``frame`` or ``image``; the float ones named it ("left: image is
    empty: ..."). The argument is named now, with its own size."""
    pair = {"left": np.zeros((4, 5, 3), np.uint8), "right": np.zeros((4, 5, 3), np.uint8)}
    pair[empty] = np.zeros((4, 0, 3), np.uint8)
    with pytest.raises(ValueError) as err:
        _core.hopfield_match_u8(pair["left"], pair["right"], LUMA_WEIGHTS_BGR, {})
    assert str(err.value) == f"{empty}: image is empty: got 0x4 pixels"
    both = np.zeros((0, 5), np.uint8)
    with pytest.raises(ValueError) as err:
        _core.hopfield_match_u8(both, both, LUMA_WEIGHTS_BGR, {})
    assert str(err.value) == "left: image is empty: got 5x0 pixels"
    with pytest.raises(ValueError) as err:
        _core.gray_u8(both, LUMA_WEIGHTS_BGR)
    assert str(err.value) == "image: image is empty: got 5x0 pixels"
    with pytest.raises(ValueError) as err:
        _core.temporal_grey_difference(both, np.zeros((0, 5), np.float32))
    assert str(err.value) == "frame: image is empty: got 5x0 pixels"


def test_an_array_of_the_other_byte_order_is_said_to_be_one() -> None:
    """A big-endian float32 array (a PFM's, a file read with ``np.fromfile(..., ">f4")``) was
    "img: expected a float32 array, got >f4": float32 refused for not being float32. The error
    says it is the other byte order and how to convert it; other dtypes are said as before."""
    a = np.zeros((4, 5), np.float32)
    with pytest.raises(TypeError) as err:
        _core.gabor_responses(a.astype(">f4"))
    assert str(err.value) == (
        "img: expected a float32 array, got >f4 (float32 in the other byte order: convert it "
        "with .astype(np.float32))"
    )
    with pytest.raises(TypeError) as err:
        _core.gabor_responses(a.astype(">f8"))
    assert str(err.value) == "img: expected a float32 array, got >f8"


def test_an_array_updated_in_place_of_the_other_byte_order_is_said_to_be_kept() -> None:
    """``temporal_running_mean`` updates ``mean`` in place: the byte-order advice
    ("convert it with .astype(np.float32)") taken in the call updated that copy, and the
    caller's mean kept its old values without a word. The advice says to keep the converted
    array."""
    frame = np.full((2, 3), 9, np.uint8)
    mean = np.zeros((2, 3), ">f4")
    count, diff = np.zeros((2, 3), np.uint8), np.zeros((2, 3), np.float32)
    with pytest.raises(TypeError) as err:
        _core.temporal_running_mean(frame, mean, count, diff, 1.0, 8)
    assert str(err.value) == (
        "mean: expected a float32 array, got >f4 (float32 in the other byte order: it is "
        "updated in place, so convert the array you keep and pass that: mean = "
        "mean.astype(np.float32))"
    )
    mean = mean.astype(np.float32)  # as said: the update reaches the caller's array
    _core.temporal_running_mean(frame, mean, count, diff, 1.0, 8)
    assert mean.max() > 0
