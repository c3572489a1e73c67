"""Gabor phase-disparity channel: parity with the NumPy reference, sign/magnitude, edge cases.

Tolerances are chosen to be ~100x above float32 round-off yet far below what a sign flip, a
conjugated phase or a one-pixel shift produces (each of those is asserted to FAIL them).
"""

from __future__ import annotations

import hashlib
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from stereovision import _core
from stereovision.matching.gabor import DEFAULTS, GaborResult, gabor_disparity, gabor_responses
from tests.reference import gabor_ref as ref

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"

#: Relative tolerance of the filter-bank responses (max |diff| / max |y|).
RESP_RTOL = 1e-4
#: Newton-step parity: |delta| difference (px) and confidence difference, on 99.9 % of pixels.
STEP_ATOL_PX = 1e-3
STEP_ATOL_CONF = 1e-3
STEP_SHARE = 0.999
#: One-level pipeline parity: disparity difference (px) on pixels valid in both, share of them,
#: and agreement of the validity masks.
PIPE_ATOL_PX = 0.01
PIPE_SHARE = 0.995
PIPE_MASK_AGREE = 0.995


def _grey(scene: str, crop: tuple[slice, slice] | None = None) -> tuple[np.ndarray, np.ndarray]:
    cv2 = pytest.importorskip("cv2")
    d = DATA / scene
    if not (d / "left.png").exists():
        pytest.skip(f"shared data not found: {d}")
    left = cv2.imread(str(d / "left.png"), cv2.IMREAD_GRAYSCALE).astype(np.float32) / 255
    right = cv2.imread(str(d / "right.png"), cv2.IMREAD_GRAYSCALE).astype(np.float32) / 255
    if crop is not None:
        left, right = left[crop], right[crop]
    return np.ascontiguousarray(left), np.ascontiguousarray(right)


def _texture(h: int, w: int, shift: float, seed: int) -> np.ndarray:
    """Random band-limited texture, circularly Fourier-shifted: ``out(x) = base(x + shift)``."""
    rng = np.random.default_rng(seed)
    base = rng.standard_normal((h, w))
    fx = np.fft.fftfreq(w)[None, :]
    fy = np.fft.fftfreq(h)[:, None]
    spec = np.fft.fft2(base) * np.exp(-((fx**2 + fy**2) / (2 * 0.15**2)))
    img = np.real(np.fft.ifft2(spec * np.exp(2j * np.pi * fx * shift)))
    return (0.5 + 0.15 * img / img.std()).clip(0, 1).astype(np.float32)


def _rel_err(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


# --- filter bank ------------------------------------------------------------------------------


@pytest.mark.parametrize("scene", ["middlebury2001/tsukuba", "middlebury2003/cones"])
@pytest.mark.parametrize("theta", [0.0, 30.0, -60.0])
def test_responses_match_reference(scene: str, theta: float) -> None:
    left, _ = _grey(scene)
    ours = gabor_responses(left, 0.25, theta)
    want = ref.responses(left, ref.channel(0.25, theta))
    assert ours.shape == left.shape and ours.dtype == np.complex64
    assert _rel_err(ours, want) < RESP_RTOL
    # The tolerance catches a one-pixel shift, a transposed carrier sign (conjugate) and the
    # correlation/convolution confusion (mirrored kernel = conjugate for a symmetric envelope).
    assert _rel_err(np.roll(ours, 1, axis=1), want) > 100 * RESP_RTOL
    assert _rel_err(np.roll(ours, 1, axis=0), want) > 100 * RESP_RTOL
    assert _rel_err(np.conj(ours), want) > 100 * RESP_RTOL


def test_kernel_is_zero_dc() -> None:
    for theta in ref.ORIENTATIONS:
        ch = ref.channel(0.25, theta)
        kernel = np.outer(ch.hy, ch.hx) - ch.dc * np.outer(ch.gy, ch.gx)
        assert abs(kernel.sum()) < 1e-7  # float32 taps; |sum h| before the correction ~2e-3
        y = gabor_responses(np.full((40, 50), 0.73, np.float32), 0.25, theta)
        assert np.max(np.abs(y)) < 1e-6


# --- one level's phase-difference / local-frequency / confidence step ------------------------


def _step_case(shift_px: float = 0.0) -> tuple[np.ndarray, ...]:
    left, right = _grey("middlebury2001/tsukuba")
    gt = ref_disp_tsukuba(left.shape)
    disp = (gt + shift_px).astype(np.float32)
    d_ours, c_ours = _core.gabor_newton_step(left, right, disp)
    chans = [ref.channel(0.25, t) for t in ref.ORIENTATIONS]
    lv, rv = ref.level_data(left, chans), ref.level_data(right, chans)
    thr2 = ref.thresholds2(lv, rv, 0.02)
    d_ref, c_ref = ref.newton_step(lv, rv, chans, thr2, gt.astype(np.float64))
    return d_ours, c_ours, d_ref, c_ref


def test_step_names_a_map_of_another_size() -> None:
    # the core's pair check called it "right"
    img = np.zeros((20, 30), np.float32)
    with pytest.raises(ValueError, match=r"disp: map is \(10, 10\) .*the images are \(20, 30\)"):
        _core.gabor_newton_step(img, img, np.zeros((10, 10), np.float32))


def ref_disp_tsukuba(shape: tuple[int, int]) -> np.ndarray:
    """A smooth, non-trivial disparity field (sub-pixel, varying in x and y) for the step test."""
    h, w = shape
    y, x = np.mgrid[0:h, 0:w]
    return (6.0 + 3.0 * np.sin(x / 37.0) + 2.0 * np.cos(y / 23.0) + 0.37).astype(np.float32)


def test_newton_step_matches_reference() -> None:
    d_ours, c_ours, d_ref, c_ref = _step_case()
    both = (c_ours > 0) & (c_ref > 0)
    assert both.mean() > 0.3, "too few confident pixels to compare"
    assert np.mean(np.abs(d_ours - d_ref)[both] <= STEP_ATOL_PX) >= STEP_SHARE
    assert np.mean(np.abs(c_ours - c_ref) <= STEP_ATOL_CONF) >= STEP_SHARE
    # A sign flip of the update fails the tolerance...
    assert np.mean(np.abs(-d_ours - d_ref)[both] <= STEP_ATOL_PX) < 0.5


def test_newton_step_detects_one_pixel_offset() -> None:
    # ... and so does evaluating our step at a disparity off by one pixel.
    d_ours, c_ours, _, _ = _step_case(shift_px=1.0)
    _, _, d_ref, c_ref = _step_case()
    both = (c_ours > 0) & (c_ref > 0)
    assert np.mean(np.abs(d_ours - d_ref)[both] <= STEP_ATOL_PX) < 0.5


def test_lr_check_matches_reference() -> None:
    rng = np.random.default_rng(3)
    dl = rng.uniform(0, 8, (30, 40)).astype(np.float32)
    dr = (dl + rng.normal(0, 0.8, dl.shape)).astype(np.float32)
    dl[0, :5] = np.nan
    ours = _core.gabor_lr_check(dl, dr, 1.0)
    want = ref.lr_check(dl.astype(np.float64), dr.astype(np.float64), 1.0)
    assert ours.dtype == np.bool_
    assert np.array_equal(ours, want)
    assert 0.2 < ours.mean() < 0.95


def _constant_steps_agree(disparities: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The Newton step of kernel and reference agree on a tsukuba crop at each constant
    disparity given (within the step tolerances, with a confident pixel); gives the crop."""
    left, right = _grey("middlebury2001/tsukuba", (slice(100, 160), slice(100, 220)))
    chans = [ref.channel(0.25, t) for t in ref.ORIENTATIONS]
    lv, rv = ref.level_data(left, chans), ref.level_data(right, chans)
    thr2 = ref.thresholds2(lv, rv, 0.02)
    for d in disparities:
        disp = np.full(left.shape, d, np.float32)
        d_ours, c_ours = _core.gabor_newton_step(left, right, disp)
        d_ref, c_ref = ref.newton_step(lv, rv, chans, thr2, disp.astype(np.float64))
        assert c_ours.max() > 0.5, d
        assert np.abs(c_ours - c_ref).max() <= STEP_ATOL_CONF, d
        assert np.abs(d_ours - d_ref).max() <= STEP_ATOL_PX, d
    return left, right


def test_the_reference_rounds_half_pixel_shifts_as_the_kernel() -> None:
    """On a map of half-integer disparities: the Newton step reads the right stability at
    round(x - d) with ties to even and the left-right check rounds x - d half away from zero;
    the reference rounded both half up (floor(s + 0.5)), so its confidence differed by up to
    0.99 at 12 % of the pixels (the update by up to 4 px) and its mask passed pixels matched
    half a pixel left of the row."""
    _constant_steps_agree((-1.5, 0.5, 2.5, 3.5))
    # The mask with any tolerance is "x - d rounds into the row": x - d of 7.5 (the last
    # pixel, 8), -0.5 (-1), 8.5 (9, past the row's end) and -0.4 (-0, the first pixel).
    dl = np.array([[-7.5, 1.5, -6.5, -5.5, 4.5, -3.0, 6.0, 7.4, 8.5]], np.float32)
    dr = np.zeros_like(dl)
    want = [True, False, False, False, False, True, True, True, False]
    np.testing.assert_array_equal(_core.gabor_lr_check(dl, dr, np.inf)[0], want)
    np.testing.assert_array_equal(
        ref.lr_check(dl.astype(np.float64), dr.astype(np.float64), np.inf)[0], want
    )


def test_the_reference_computes_x_minus_d_in_float32_as_the_kernel() -> None:
    """One float32 ulp from a half pixel, ``x - d`` rounds onto the tie in the kernel's float32
    (``100 - 0.50000006`` is ``99.5``) but not in float64: the reference's Newton step read the
    right stability one pixel off at every other pixel (confidence off by up to 0.83 at 12 % of
    them, the update by 4 px), its search one pixel off, and its left-right check kept a pixel
    matched past the row's end and dropped a difference the kernel's float32 makes exactly
    ``tol``."""
    up = np.float32(np.inf)
    left, right = _constant_steps_agree(
        (np.nextafter(np.float32(0.5), up), np.nextafter(np.float32(-1.5), up))
    )
    # x 119 (the last pixel) - (-0.49999997) is 119.5 in float32: 120, past the row; at x 10,
    # 1.7 - 0.7 (dr at round(8.3)) is exactly 1 in float32 (1 + 6e-8 in float64): within tol 1.
    dl = np.zeros((1, 120), np.float32)
    dr = np.zeros_like(dl)
    dl[0, 119] = np.nextafter(np.float32(-0.5), up)
    dl[0, 10], dr[0, 8] = 1.7, 0.7
    for mask in (
        _core.gabor_lr_check(dl, dr, 1.0)[0],
        ref.lr_check(dl.astype(np.float64), dr.astype(np.float64), 1.0)[0],
    ):
        assert not mask[119]
        assert mask[10]
    # The search's integer shift floor(x - d + 0.5) too: from min_disparity 0.50000006 the
    # reference's one-level pipeline searched one pixel off (masks agreed at 95 %, 49 % of
    # the pixels off by > 0.05).
    d0 = float(np.nextafter(np.float32(0.5), up))
    ours = gabor_disparity(
        left,
        right,
        min_disparity=d0,
        max_disparity=d0 + 12,
        n_levels=1,
        lr_check=False,
        speckle_size=0,
    ).disparity
    want, _ = ref.disparity_one_level(left, right, d0, d0 + 12)
    vo, vr = np.isfinite(ours), np.isfinite(want)
    assert np.mean(vo == vr) >= PIPE_MASK_AGREE
    assert vo.mean() > 0.5
    assert np.mean(np.abs(ours - want)[vo & vr] <= PIPE_ATOL_PX) >= PIPE_SHARE


def test_one_level_pipeline_matches_reference() -> None:
    crop = (slice(60, 180), slice(40, 240))
    left, right = _grey("middlebury2001/tsukuba", crop)
    ours = gabor_disparity(
        left, right, max_disparity=16, n_levels=1, lr_check=False, speckle_size=0
    ).disparity
    want, _ = ref.disparity_one_level(left, right, 0.0, 16.0)
    vo, vr = np.isfinite(ours), np.isfinite(want)
    assert np.mean(vo == vr) >= PIPE_MASK_AGREE
    both = vo & vr
    assert both.mean() > 0.5
    assert np.mean(np.abs(ours - want)[both] <= PIPE_ATOL_PX) >= PIPE_SHARE
    assert np.mean(np.abs(ours - (want + 1.0))[both] <= PIPE_ATOL_PX) < 0.1


# --- behaviour ----------------------------------------------------------------------------------


@pytest.mark.parametrize("d", [-4.6, -1.3, 0.35, 2.7, 4.95])
def test_recovers_subpixel_shift(d: float) -> None:
    left = _texture(96, 128, 0.0, seed=11)
    right = _texture(96, 128, d, seed=11)  # right(x) = left(x + d)
    res = gabor_disparity(left, right, min_disparity=-8.0, max_disparity=8.0)
    inner = res.disparity[8:-8, 16:-16]
    assert np.isfinite(inner).mean() > 0.8
    assert abs(float(np.nanmedian(inner)) - d) < 0.05


def test_constant_pair_gives_all_nan() -> None:
    img = np.full((48, 64), 0.4, np.float32)
    res = gabor_disparity(img, img, max_disparity=16)
    assert isinstance(res, GaborResult)
    assert res.disparity.dtype == np.float32 and res.confidence.dtype == np.float32
    assert np.isnan(res.disparity).all()
    assert (res.confidence == 0).all()


def test_output_contract_on_real_pair() -> None:
    left, right = _grey("middlebury2003/cones")
    res = gabor_disparity(left, right, max_disparity=64)
    d, c = res.disparity, res.confidence
    assert d.shape == left.shape and c.shape == left.shape
    fin = np.isfinite(d)
    assert 0.6 < fin.mean() < 1.0
    assert np.all((c >= 0) & (c <= 1))
    assert np.all(c[~fin] == 0) and np.all(c[fin] > 0)
    assert np.nanmin(d) >= -1.0 and np.nanmax(d) <= 65.0


def test_invalid_inputs_raise_value_error() -> None:
    a = np.zeros((10, 12), np.float32)
    with pytest.raises(ValueError):
        gabor_disparity(np.zeros((10, 12, 3), np.float32), a, max_disparity=8)
    with pytest.raises(ValueError):
        gabor_disparity(a, np.zeros((10, 13), np.float32), max_disparity=8)
    with pytest.raises(ValueError):
        gabor_disparity(a, a, max_disparity=0.0)
    with pytest.raises(ValueError):
        gabor_disparity(a, a, max_disparity=float("nan"))
    with pytest.raises(ValueError):
        gabor_disparity(a, a, max_disparity=8, freq=0.9)
    with pytest.raises(ValueError):
        gabor_disparity(a, a, max_disparity=8, no_such_param=1)
    bad = a.copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError):
        gabor_disparity(bad, a, max_disparity=8)


@pytest.mark.parametrize(("name", "value"), [("search_pool_radius", 17), ("research_radius", 17)])
def test_a_radius_out_of_range_is_named(name: str, value: int) -> None:
    """The kernel checks both radii in one test: ``search_pool_radius=20`` was reported as
    "invalid parameter `research_radius`", a parameter the caller had not touched."""
    a = np.random.default_rng(0).random((20, 30), dtype=np.float32)
    assert np.isfinite(gabor_disparity(a, a, max_disparity=8, **{name: 16}).disparity).any()
    with pytest.raises(ValueError, match=name) as exc:
        gabor_disparity(a, a, max_disparity=8, **{name: value})
    other = {"search_pool_radius": "research_radius", "research_radius": "search_pool_radius"}
    assert other[name] not in str(exc.value)


# --- determinism ----------------------------------------------------------------------------------

_HASH_SCRIPT = """
import hashlib, sys, numpy as np
from stereovision.matching.gabor import gabor_disparity
rng = np.random.default_rng(5)
from scipy import ndimage
base = ndimage.gaussian_filter(rng.random((120, 160)), 1.2).astype(np.float32)
left = base[:, 6:]
right = base[:, :-6]
r = gabor_disparity(np.ascontiguousarray(left), np.ascontiguousarray(right), max_disparity=16)
print(hashlib.sha256(r.disparity.tobytes() + r.confidence.tobytes()).hexdigest())
"""


def test_bit_identical_runs_and_thread_counts() -> None:
    left, right = _grey("middlebury2001/tsukuba")
    a = gabor_disparity(left, right, max_disparity=16)
    b = gabor_disparity(left, right, max_disparity=16)
    assert a.disparity.tobytes() == b.disparity.tobytes()
    assert a.confidence.tobytes() == b.confidence.tobytes()
    digests = []
    for n in ("1", "2"):
        env = {**os.environ, "RAYON_NUM_THREADS": n}
        out = subprocess.run(
            [sys.executable, "-c", _HASH_SCRIPT],
            env=env,
            capture_output=True,
            text=True,
            check=True,
        )
        digests.append(out.stdout.strip())
    assert digests[0] == digests[1]
    assert len(digests[0]) == len(hashlib.sha256().hexdigest())


@pytest.mark.parametrize(("min_size", "max_diff"), [(9, 1.0), (100, 1.0), (40, 0.5)])
def test_remove_speckles_equals_opencv_filter_speckles(min_size: int, max_diff: float) -> None:
    """The speckle kernel (also the fused map's step 6) against OpenCV's filterSpeckles, the rule
    it follows, on a real raw Gabor map (no speckle step, values on OpenCV's 1/16 px grid)."""
    import cv2

    left, right = _grey("middlebury2003/cones")
    g = gabor_disparity(left, right, max_disparity=64, speckle_size=0, lr_check=False)
    d = np.round(g.disparity * 16) / 16
    ours = _core.gabor_remove_speckles(d.astype(np.float32), min_size, max_diff)
    q = np.where(np.isfinite(d), d * 16, -32768).astype(np.int16)
    # OpenCV removes regions of at most maxSpeckleSize pixels; the kernel, fewer than min_size.
    cv2.filterSpeckles(q, -32768, min_size - 1, max_diff * 16)
    theirs = np.where(q == -32768, np.nan, q / 16).astype(np.float32)
    removed = np.isfinite(d) & np.isnan(ours)
    assert removed.sum() > 100  # a real test: the map has speckles of that size
    np.testing.assert_array_equal(ours, theirs)
    with pytest.raises(ValueError, match="max_diff"):
        _core.gabor_remove_speckles(d.astype(np.float32), 9, float("nan"))


def test_match_with_the_gabor_channel(data_dir: Path) -> None:
    """``stereovision.match(method="gabor")`` shares the Matches API (issue 3): the channel's
    confident pixels, one match each along the row, scored by the confidence."""
    import stereovision as sv
    from stereovision._validate import check_pair
    from stereovision.evaluate import sparse_metrics
    from stereovision.io import load_scene

    sc = load_scene(data_dir / "eth3d" / "terrace")
    m = sv.match(sc.left, sc.right, method="gabor", max_disparity=32)
    g = gabor_disparity(*check_pair(sc.left, sc.right), max_disparity=32)
    assert isinstance(m, sv.Matches) and m.xl.dtype == np.float32
    assert len(m) == np.isfinite(g.disparity).sum() > 200_000  # 247361 measured
    np.testing.assert_array_equal(np.isnan(m.dispx), np.isnan(g.disparity))
    np.testing.assert_allclose(m.dispx, g.disparity, atol=1e-4, equal_nan=True)  # float32 xr
    assert np.all(m.yl == m.yr) and np.all(
        m.score == g.confidence[m.yl.astype(int), m.xl.astype(int)]
    )
    sm = sparse_metrics(m.xl, m.yl, m.xr, sc.gt)
    assert sm.precision[2.0] > 97.0 and sm.count > 100_000  # 98.25 % of 129271 measured
    with pytest.raises(ValueError, match="expected one of hopfield, best, mcgm, fused, gabor"):
        sv.match(sc.left, sc.right, method="census", max_disparity=32)


@pytest.mark.parametrize(
    ("lo", "hi", "says"),
    [
        (0.0, 1e300, "got 1e+300 - 0.0"),  # float32's inf in the kernel: "`d_max` must be finite"
        (0.0, 2**70, "got 1180591620717411303424 - 0.0"),
        (0.0, 8193.0, "got 8193.0 - 0.0"),
        (-1e300, 8.0, "got 8.0 - -1e+300"),
    ],
)
def test_a_range_beyond_the_kernel_names_the_arguments(lo: float, hi: float, says: str) -> None:
    # The kernel's own message named its `d_max` (and `d_min`), not the caller's arguments.
    ok = np.random.default_rng(0).random((40, 60), dtype=np.float32)
    with pytest.raises(ValueError, match=r"max_disparity - min_disparity: .* at most 8192 px") as e:
        gabor_disparity(ok, ok, min_disparity=lo, max_disparity=hi)
    assert says in str(e.value) and "d_max" not in str(e.value)


def test_the_widest_range_is_searched() -> None:
    ok = np.random.default_rng(0).random((40, 60), dtype=np.float32)
    res = gabor_disparity(ok, np.roll(ok, -3, axis=1), max_disparity=8192.0)
    assert float(np.nanmedian(res.disparity)) == pytest.approx(3.0, abs=0.05)


def test_the_wrappers_own_checks_name_the_argument() -> None:
    """Checks the wrapper makes before the kernel, each in the caller's words: a range 8192.5 px
    wide, a search_pool_radius of 17, 21 Newton steps (iters_finest's named as its own), a
    count of None (only n_levels means automatic), a uint8
    image, images differing only in width, a switch that is not a bool (TypeError)."""
    img = np.random.default_rng(0).random((24, 40)).astype(np.float32)
    cases: list[tuple[dict[str, object], str]] = [
        (
            {"max_disparity": 8192.5},
            r"max_disparity - min_disparity: the Gabor search range is at most 8192 px, got "
            r"8192\.5 - 0",
        ),
        ({"search_pool_radius": 17}, "search_pool_radius must be at most 16 px, got 17"),
        ({"iters_per_level": None}, "iters_per_level must be a non-negative integer, got None"),
        # the kernel named iters_per_level for either ("iterations must be <= 20")
        ({"iters_finest": 21}, "iters_finest must be at most 20, got 21"),
        ({"iters_per_level": 21}, "iters_per_level must be at most 20, got 21"),
    ]
    for kw, says in cases:
        with pytest.raises(ValueError, match="^" + says):
            gabor_disparity(img, img, **{"max_disparity": 8, **kw})
    assert gabor_disparity(img, img, max_disparity=8, n_levels=None).disparity.shape == img.shape
    with pytest.raises(
        ValueError, match=r"^left must be float32 grey levels in \[0, 1\], got dtype uint8"
    ):
        gabor_disparity((img > 0.5).astype(np.uint8), img, max_disparity=8)
    with pytest.raises(ValueError, match=r"^left \(24, 40\) and right \(24, 41\) images differ"):
        gabor_disparity(img, np.zeros((24, 41), np.float32), max_disparity=8)
    with pytest.raises(TypeError, match=r"^lr_check: expected True or False, got 1"):
        gabor_disparity(img, img, max_disparity=8, lr_check=1)


def test_direct_call_refuses_an_unreachable_range_as_match_does() -> None:
    """min_disparity at the width or above (or max_disparity at minus the width or below): no
    pixel has a match there. match() refused it; gabor_disparity returned an all-NaN map
    without a word (as hopfield_match and mcgm_match did). It now raises match()'s error."""
    import re

    import stereovision as sv

    rng = np.random.default_rng(0)
    left = rng.random((40, 48), dtype=np.float32)
    right = np.roll(left, -5, axis=1)
    for lo, hi in ((48, 60), (48.5, 49), (-60, -48)):
        with pytest.raises(ValueError) as want:
            sv.match(left, right, method="gabor", max_disparity=hi, min_disparity=lo)
        assert "image width" in str(want.value)
        with pytest.raises(ValueError, match=f"^{re.escape(str(want.value))}$"):
            gabor_disparity(left, right, max_disparity=hi, min_disparity=lo)
    # one column short of the width is searched: no error
    assert gabor_disparity(left, right, max_disparity=48, min_disparity=47).disparity.shape == (
        40,
        48,
    )


def test_defaults_are_the_kernels() -> None:
    """DEFAULTS mirror GaborParams::default and gabor_responses' defaults the channel the
    tests compare with: lr_light=True or a freq default of 0.2 survived a mutation audit (the
    golden figures included)."""
    left, right = _grey("middlebury2001/tsukuba")
    got = gabor_disparity(left, right, max_disparity=16)
    disp, conf = _core.gabor_disparity(left, right, 0.0, 16.0)
    np.testing.assert_array_equal(got.disparity, disp)
    np.testing.assert_array_equal(got.confidence, conf)
    np.testing.assert_array_equal(gabor_responses(left), gabor_responses(left, 0.25, 0.0, 1.5, 1.0))


def test_input_types_taken_and_refused() -> None:
    """A second mutation audit found unasserted: a float64 image taken as float32, NumPy bools
    and integers taken as switches and counts, True refused as a count, an orientation array
    taken and a bare number refused, a (0, 5) image refused as empty, and a bad right image
    named as right."""
    rng = np.random.default_rng(0)
    img = rng.random((24, 40)).astype(np.float32)
    right = np.roll(img, -2, axis=1)
    want = gabor_disparity(img, right, max_disparity=8, lr_check=False, speckle_size=5)
    same = [
        gabor_disparity(
            img.astype(np.float64), right, max_disparity=8, lr_check=False, speckle_size=5
        ),
        gabor_disparity(img, right, max_disparity=8, lr_check=np.False_, speckle_size=np.int64(5)),
    ]
    for got in same:
        np.testing.assert_array_equal(got.disparity, want.disparity)
    a = gabor_disparity(img, right, max_disparity=8, orientations_deg=np.array([0.0, 60.0]))
    b = gabor_disparity(img, right, max_disparity=8, orientations_deg=[0.0, 60.0])
    np.testing.assert_array_equal(a.disparity, b.disparity)
    cases: list[tuple[object, object, dict[str, object], str]] = [
        (
            img,
            right,
            {"speckle_size": True},
            "speckle_size must be a non-negative integer, got True",
        ),
        (
            img,
            right,
            {"orientations_deg": 5},
            "orientations_deg must be a sequence of degrees, got 5",
        ),
        (
            np.zeros((0, 5), np.float32),
            np.zeros((0, 5), np.float32),
            {},
            r"left is empty: shape \(0, 5\)",
        ),
        (img, right * 3, {}, r"right: float image values must lie in \[0, 1\]"),
    ]
    for lft, rgt, kw, says in cases:
        with pytest.raises(ValueError, match="^" + says):
            gabor_disparity(lft, rgt, max_disparity=8, **kw)


@pytest.mark.parametrize("value", ["ab", [None], [0.0, "x"], np.array(0.0)])
def test_orientations_of_another_type_are_named(value: object) -> None:
    """orientations_deg="ab" was "could not convert string to float: 'a'" and [None] float()'s
    bare TypeError, naming no parameter; np.array(0.0) (a 0-d array: one number, as 0.0 itself
    is refused) NumPy's bare TypeError "iteration over a 0-d array"."""
    img = np.random.default_rng(0).random((24, 40), dtype=np.float32)
    with pytest.raises(ValueError, match=r"^orientations_deg must be a sequence of degrees, got "):
        gabor_disparity(img, img, max_disparity=8, orientations_deg=value)


_REAL_KEYS = [k for k, v in DEFAULTS.items() if isinstance(v, float) or k == "smooth_sigma"]


@pytest.mark.parametrize(
    ("name", "value"),
    [
        (k, v)
        for k in _REAL_KEYS
        for v in ("0.3", None, True, [0.3])
        if not (k == "smooth_sigma" and v is None)
    ],
)
def test_a_real_parameter_that_is_no_number_is_named(name: str, value: object) -> None:
    """freq, bandwidth_oct, ... given a string, None or a list were the binding's TypeError
    "must be real number, not str", naming no parameter (depth_map(method="gabor",
    freq="0.3") too), and True a value of 1 (aspect=True ran as aspect 1.0). smooth_sigma's
    None is its default (automatic)."""
    img = np.random.default_rng(0).random((24, 40), dtype=np.float32)
    with pytest.raises(ValueError, match=f"^{name}: expected a number, got "):
        gabor_disparity(img, img, max_disparity=8, **{name: value})


def test_a_real_parameter_read_from_an_array_is_its_number() -> None:
    """A size-1 array is its value (np.array([0.25]) was NumPy's "only 0-dimensional arrays
    can be converted"), as are a NumPy float and a Fraction: the map of the plain float."""
    from fractions import Fraction

    rng = np.random.default_rng(0)
    left = rng.random((48, 80), dtype=np.float32)
    right = np.roll(left, -4, axis=1)
    base = gabor_disparity(left, right, max_disparity=16, freq=0.25).disparity
    assert np.count_nonzero(np.isfinite(base)) > 1000
    for v in (np.array(0.25), np.array([0.25]), np.float32(0.25), Fraction(1, 4)):
        got = gabor_disparity(left, right, max_disparity=16, freq=v).disparity
        np.testing.assert_array_equal(got, base)


def test_a_range_read_from_an_array_is_its_number() -> None:
    """max_disparity / min_disparity of np.array([16.0]) passed the range check (finite_number
    reads a size-1 array as its value, as sgm_disparity does) and then failed in float() with
    NumPy's bare TypeError "only 0-dimensional arrays can be converted", naming neither. They
    give the map of the plain floats (match refuses them, as depth_map does: below)."""
    rng = np.random.default_rng(0)
    left = rng.random((48, 80), dtype=np.float32)
    right = np.roll(left, -4, axis=1)
    base = gabor_disparity(left, right, max_disparity=16.0, min_disparity=1.0).disparity
    assert np.count_nonzero(np.isfinite(base)) > 1000
    got = gabor_disparity(
        left, right, max_disparity=np.array([16.0]), min_disparity=np.array([1.0])
    ).disparity
    np.testing.assert_array_equal(got, base)


def test_match_refuses_a_gabor_range_read_from_an_array_as_depth_map_does() -> None:
    """match(method="gabor") with min_disparity=np.array([1.0]) gave NumPy's bare TypeError
    "only 0-dimensional arrays can be converted" (its range filter's float()), and a
    max_disparity of np.array([[4.05]]) a 2-D keep mask, NumPy's IndexError "too many indices
    for array" once a match was out of range; 6902f6b0 took them as their number, where the
    other methods and depth_map refused them. Each is now depth_map's TypeError."""
    import stereovision as sv

    rng = np.random.default_rng(0)
    left = rng.random((48, 80), dtype=np.float32)
    right = np.roll(left, -4, axis=1)
    for lo, hi, words in (
        (np.array([1.0]), 4.05, "min_disparity: expected a number of pixels, got array([1.])"),
        (1.0, np.array([[4.05]]), "max_disparity: expected a number of pixels, got "),
    ):
        with pytest.raises(TypeError, match=re.escape(words)):
            sv.match(left, right, method="gabor", max_disparity=hi, min_disparity=lo)


def test_a_decimal_real_parameter_is_its_number() -> None:
    """A Decimal (a config read with ``json.loads(parse_float=Decimal)``) is no numbers.Real:
    the check of the real parameters refused it as "freq: expected a number, got
    Decimal('0.25')", where the binding had read it as its float. It gives that float's map."""
    from decimal import Decimal

    rng = np.random.default_rng(0)
    left = rng.random((48, 80), dtype=np.float32)
    right = np.roll(left, -4, axis=1)
    base = gabor_disparity(left, right, max_disparity=16, freq=0.25, lr_tol=1.5).disparity
    assert np.count_nonzero(np.isfinite(base)) > 1000
    kw = {"freq": Decimal("0.25"), "lr_tol": Decimal("1.5")}
    np.testing.assert_array_equal(
        gabor_disparity(left, right, max_disparity=16, **kw).disparity, base
    )


def test_gabor_responses_take_a_parameter_read_from_an_array_as_its_number() -> None:
    """freq=np.array([0.25]) (a value read from an array, which gabor_disparity takes as 0.25)
    was the binding's bare TypeError "only 0-dimensional arrays can be converted", naming no
    parameter; each parameter now gives the plain number's response."""
    img = np.random.default_rng(0).random((24, 40), dtype=np.float32)
    plain = {"freq": 0.2, "theta_deg": 30.0, "bandwidth_oct": 1.0, "aspect": 0.8}
    want = gabor_responses(img, **plain)
    assert np.abs(want).max() > 0.01
    for name, value in plain.items():
        got = gabor_responses(img, **{**plain, name: np.array([value])})
        np.testing.assert_array_equal(got, want, err_msg=name)


@pytest.mark.parametrize("name", ["freq", "theta_deg", "bandwidth_oct", "aspect"])
@pytest.mark.parametrize("value", ["0.3", None, True, [0.3]])
def test_gabor_responses_name_a_parameter_that_is_no_number(name: str, value: object) -> None:
    """gabor_responses took no part of gabor_disparity's rule: a string, None or a list was the
    binding's TypeError "must be real number, not str", naming no parameter, and True ran as 1
    (aspect=True gave the aspect-1.0 response). Each is a ValueError naming the parameter; a
    Fraction or a Decimal is still its number."""
    from decimal import Decimal
    from fractions import Fraction

    img = np.random.default_rng(0).random((24, 40), dtype=np.float32)
    with pytest.raises(ValueError, match=f"^{name}: expected a number, got "):
        gabor_responses(img, **{name: value})
    want = gabor_responses(img, freq=0.25, aspect=0.5)
    np.testing.assert_array_equal(gabor_responses(img, freq=Fraction(1, 4), aspect=0.5), want)
    np.testing.assert_array_equal(gabor_responses(img, freq=0.25, aspect=Decimal("0.5")), want)


def test_every_parameter_is_documented() -> None:
    """Each of DEFAULTS' keys is named in gabor_disparity's docstring and said in a comment
    beside its default (as the Hopfield, MCGM and census DEFAULTS are): seven of them
    (``lr_light``, ``fine_levels``, ...) were in neither, so only the Rust source told what
    they do."""
    import inspect

    from stereovision.matching import gabor

    doc = gabor_disparity.__doc__ or ""
    params = doc[doc.index("**params") : doc.index("Returns")]
    assert [k for k in DEFAULTS if f"``{k}``" not in params] == []
    src = inspect.getsource(gabor)
    block = src[src.index("DEFAULTS: dict") : src.index("\n}\n")]
    for key in DEFAULTS:
        line = next(ln for ln in block.splitlines() if f'"{key}":' in ln)
        above = block.splitlines()[block.splitlines().index(line) - 1].strip()
        assert "#" in line or above.startswith("#"), key


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_gabor_responses_name_a_non_finite_image_by_its_keyword(bad: float) -> None:
    """The kernel named its own argument, ``img``, the keyword renamed ``image`` (whose use
    is deprecated): "img: image contains non-finite values (NaN or inf) at 1 pixels"."""
    img = np.full((12, 16), 0.5, np.float32)
    img[3, 4] = bad
    with pytest.raises(
        ValueError, match=r"^image: image contains non-finite values \(NaN or inf\) at 1 pix"
    ):
        gabor_responses(img)


def test_results_compare_and_hash_by_identity() -> None:
    """Two results of one pair: ``a == b`` (and ``b in [a]``) compared their maps and raised
    NumPy's 'truth value of an array ... is ambiguous', and a result was unhashable. Equal to
    itself only, and hashable (as TriangulationResult)."""
    img = np.random.default_rng(0).random((24, 32)).astype(np.float32)
    a, b = (gabor_disparity(img, img, max_disparity=4) for _ in range(2))
    assert a == a and a != b and b not in [a]
    assert {a: 1, b: 2}[a] == 1 and len({a, b, a}) == 2
