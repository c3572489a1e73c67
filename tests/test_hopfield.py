"""Hopfield channel (algorithms.md C + C.10): parity with the NumPy reference, network dynamics,
sub-pixel sign and magnitude, edge cases, bad input and accuracy on real scenes.

Tolerances: the interest operator is bit-exact (same float64 summation order). The matcher's
ZNCC is float32 in Rust and float64 in the reference, so a candidate whose similarity sits
within ~1e-5 of a threshold (``s_min``, a peak test, a half-window argmax) may flip; the match
sets are compared with a small bounded share of such differences.
"""

from __future__ import annotations

import csv
import re
from collections.abc import Callable
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import cv2
import numpy as np
import pytest

import stereovision as sv
from stereovision import io
from stereovision.evaluate import count_at_precision, sparse_metrics
from stereovision.matching import hopfield as hp
from tests.reference import hopfield_ref as ref

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"

#: Float32 vs float64 ZNCC: largest similarity difference allowed between Rust and reference.
SIM_ATOL = 1e-4
#: Share of matches allowed to differ between Rust and the reference (threshold flips).
MATCH_DIFF_SHARE = 0.02
#: Sub-pixel disparity agreement between Rust and the reference (px).
SUBPIX_ATOL = 2e-3
#: Relative tolerance of the energy values (float64 net inputs, float32 weights in both).
ENERGY_RTOL = 1e-6


def _scene(name: str) -> io.Scene:
    d = DATA / name
    if not (d / "left.png").exists():
        pytest.skip(f"shared data not found: {d}")
    return io.load_scene(d)


def _grey(name: str) -> tuple[np.ndarray, np.ndarray, io.Scene]:
    sc = _scene(name)
    return sv._validate.as_gray_float(sc.left), sv._validate.as_gray_float(sc.right), sc


def _texture(h: int, w: int, shift: float, seed: int) -> np.ndarray:
    """Band-limited random texture, circularly Fourier-shifted: ``out(x) = base(x + shift)``."""
    rng = np.random.default_rng(seed)
    base = rng.standard_normal((h, w))
    fx = np.fft.fftfreq(w)[None, :]
    fy = np.fft.fftfreq(h)[:, None]
    spec = np.fft.fft2(base) * np.exp(-((fx**2 + fy**2) / (2 * 0.2**2)))
    img = np.real(np.fft.ifft2(spec * np.exp(2j * np.pi * fx * shift)))
    return (0.5 + 0.12 * img / img.std()).clip(0, 1).astype(np.float32)


# --- interest operator ---


@pytest.mark.parametrize(
    "scene", ["middlebury2001/tsukuba", "middlebury2003/cones", "eth3d/terrace"]
)
def test_interest_values_exactly_equal_reference(scene: str) -> None:
    left, _, _ = _grey(scene)
    ours = hp.interest_points(left)
    want_m = ref.moravec(left)
    assert np.array_equal(ours.response, want_m)  # bit for bit
    xy, vals = ref.interest_points(left)
    assert len(ours) == len(xy) > 1000
    assert np.array_equal(ours.xy.astype(np.int64), xy)
    assert np.array_equal(ours.values, vals)


def test_moravec_needs_the_squares_and_finds_corners() -> None:
    img = np.zeros((40, 40), np.float32)
    img[20:, 20:] = 1.0  # one corner at (20, 20)
    m = hp.moravec(img)
    # Along a straight edge one direction sees no change: M = 0 (no false response).
    assert m[30, 20] == 0.0 and m[20, 30] == 0.0
    # At the corner all four directions change: M > 0. Without the squares the horizontal sum
    # would telescope to I(x-2) - I(x+3) and could be negative.
    assert m[20, 20] > 0.0
    pts = hp.interest_points(img)
    assert len(pts) >= 1
    x, y = pts.xy[np.argmax(pts.values)]
    assert abs(x - 20) <= 2 and abs(y - 20) <= 2  # the Moravec peak sits 1-2 px inside


# --- matcher parity ---


@pytest.mark.parametrize(
    ("scene", "crop"),
    [
        ("middlebury2003/cones", (slice(100, 190), slice(150, 330))),
        ("middlebury2005/art", (slice(150, 240), slice(120, 300))),
    ],
)
def test_matches_equal_reference_on_real_crops(scene: str, crop: tuple[slice, slice]) -> None:
    left, right, sc = _grey(scene)
    lc, rc = np.ascontiguousarray(left[crop]), np.ascontiguousarray(right[crop])
    dmax = sc.max_disparity
    cand = hp.hopfield_candidates(lc, rc, max_disparity=dmax)
    want_c = ref.candidates(lc, rc, 0, dmax, ref.DEFAULTS)
    ours_keys = {(int(c[0]), int(c[3])): float(c[5]) for c in cand}
    want_keys = {(n["point"], n["xr"]): n["sim"] for n in want_c}
    common = ours_keys.keys() & want_keys.keys()
    assert len(common) >= (1 - MATCH_DIFF_SHARE) * max(len(ours_keys), len(want_keys))
    assert max(abs(ours_keys[k] - want_keys[k]) for k in common) < SIM_ATOL

    ours = hp.hopfield_match(lc, rc, max_disparity=dmax)
    want, trace = ref.hopfield_match(lc, rc, 0, dmax)
    assert len(ours) > 100
    np.testing.assert_allclose(ours.energy_trace[0], trace[0], rtol=ENERGY_RTOL)
    key_o = {(int(x), int(y)): xr for x, y, xr in zip(ours.xl, ours.yl, ours.xr, strict=True)}
    key_w = {(int(r[0]), int(r[1])): r[2] for r in want}
    both = key_o.keys() & key_w.keys()
    assert len(both) >= (1 - MATCH_DIFF_SHARE) * max(len(key_o), len(key_w))
    assert max(abs(key_o[k] - key_w[k]) for k in both) < SUBPIX_ATOL

    best_o = hp.best_match(lc, rc, max_disparity=dmax)
    best_w = ref.best_match(lc, rc, 0, dmax)
    assert abs(len(best_o) - len(best_w)) <= MATCH_DIFF_SHARE * len(best_w) + 1


# --- network dynamics ---


@pytest.mark.parametrize("scene", ["middlebury2005/art", "eth3d/terrace"])
def test_energy_never_increases_and_converges(scene: str) -> None:
    left, right, sc = _grey(scene)
    m = hp.hopfield_match(left, right, max_disparity=sc.max_disparity)
    e = m.energy_trace
    assert m.stats["converged"] and len(e) == m.stats["sweeps"] + 1 >= 3
    steps = np.diff(e)
    assert np.all(steps <= 1e-9 * np.abs(e[:-1]))  # monotone up to float64 rounding
    assert steps[0] < 0  # the dynamics do something from the preset state
    assert e[-1] == e[-2]  # last sweep: no flip
    assert m.stats["n_weights"] > 100_000


def test_same_seed_identical_other_seeds_close() -> None:
    left, right, sc = _grey("middlebury2003/cones")
    a = hp.hopfield_match(left, right, max_disparity=sc.max_disparity, seed=7)
    b = hp.hopfield_match(left, right, max_disparity=sc.max_disparity, seed=7)
    assert np.array_equal(a.to_array(), b.to_array())
    assert np.array_equal(a.energy_trace, b.energy_trace)
    pa = sparse_metrics(a.xl, a.yl, a.xr, sc.gt)
    for seed in (1, 2):
        c = hp.hopfield_match(left, right, max_disparity=sc.max_disparity, seed=seed)
        pc = sparse_metrics(c.xl, c.yl, c.xr, sc.gt)
        assert abs(len(c) - len(a)) <= 0.02 * len(a)
        assert abs(pc.precision[1.0] - pa.precision[1.0]) <= 0.5


# --- synthetic ---


@pytest.mark.parametrize("d", [2.25, 5.6])
def test_fourier_shifted_texture_recovers_sign_and_magnitude(d: float) -> None:
    left = _texture(120, 160, 0.0, seed=3)
    right = _texture(120, 160, d, seed=3)  # right(x) = left(x + d)  =>  x_l - x_r = +d
    m = hp.hopfield_match(left, right, max_disparity=16)
    assert len(m) > 200
    disp = m.xl - m.xr
    assert abs(float(np.median(disp)) - d) < 0.1
    assert float(np.mean(np.abs(disp - d) < 0.5)) > 0.95
    assert np.all(m.yl == m.yr)


def test_textureless_image_gives_zero_matches() -> None:
    flat = np.full((80, 100), 0.5, np.float32)
    m = hp.hopfield_match(flat, flat, max_disparity=16)
    assert len(m) == 0 and m.to_array().shape == (0, 4)
    assert m.energy_trace.tolist() == [0.0]
    assert np.isnan(m.dispx).all()
    assert len(hp.interest_points(flat)) == 0
    tiny = np.random.default_rng(0).random((5, 5), dtype=np.float32)
    assert len(hp.hopfield_match(tiny, tiny, max_disparity=2)) == 0


# --- bad input ---


def _bad_inputs() -> list[tuple[object, object, dict[str, object]]]:
    ok = np.random.default_rng(0).random((40, 50), dtype=np.float32)
    nan = ok.copy()
    nan[3, 4] = np.nan
    return [
        (ok[None], ok[None], {}),  # 3-D with a bad channel count
        (ok.astype(bool), ok.astype(bool), {}),  # bool dtype
        (ok.astype(np.int32), ok.astype(np.int32), {}),  # signed integers
        (nan, ok, {}),  # NaN
        (ok, ok[:, :40], {}),  # mismatched sizes
        (np.zeros((0, 5), np.float32), np.zeros((0, 5), np.float32), {}),  # empty
        (ok * 3, ok * 3, {}),  # float outside [0, 1]
        (ok, ok, {"max_disparity": -4}),
        (ok, ok, {"unknown_param": 1}),
        (ok, ok, {"candidates": "sideways"}),
        (ok, ok, {"s_min": 2.0}),
        (ok, ok, {"k_cand": 0}),
    ]


@pytest.mark.parametrize("case", range(12))
def test_bad_input_raises_value_error(case: int) -> None:
    left, right, kw = _bad_inputs()[case]
    kw = {"max_disparity": 8, **kw}
    with pytest.raises(ValueError):
        sv.match(left, right, **kw)


def test_bad_calibration_and_method() -> None:
    ok = np.random.default_rng(0).random((40, 50), dtype=np.float32)
    with pytest.raises(ValueError, match="method"):
        sv.match(ok, ok, method="sgbm", max_disparity=8)
    with pytest.raises(ValueError, match="calib"):
        sv.match(ok, ok, calib="calib.txt", max_disparity=8)  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        hp.interest_points(ok, rel_threshold=1.5)


# --- API ---


def test_match_api_and_matches_type(tmp_path: Path) -> None:
    sc = _scene("middlebury2001/tsukuba")
    m = sv.match(sc.left, sc.right)  # BGR uint8, max_disparity estimated from the pair
    assert isinstance(m, sv.Matches) and len(m) > 500
    for a in (m.xl, m.yl, m.xr, m.yr, m.score):
        assert a.dtype == np.float32 and a.shape == (len(m),)
    arr = m.to_array()
    assert arr.shape == (len(m), 4) and arr.dtype == np.float32
    dx = m.dispx
    assert dx.shape == sc.gt.shape and dx.dtype == np.float32
    assert np.count_nonzero(np.isfinite(dx)) == len(m)
    i = 0
    assert dx[int(m.yl[i]), int(m.xl[i])] == pytest.approx(m.xl[i] - m.xr[i])
    assert np.nanmax(np.abs(m.dispy)) == 0.0  # rectified: row candidates
    path = tmp_path / "m.csv"
    m.save_csv(path)
    rows = list(csv.reader(path.read_text().splitlines()))
    assert rows[0] == ["x_left", "y_left", "x_right", "y_right", "score"]
    assert len(rows) == len(m) + 1
    assert float(rows[1][2]) == pytest.approx(float(m.xr[0]), abs=1e-4)
    assert not list(tmp_path.glob(".m.csv.*"))  # no temporary left behind


# --- accuracy on real scenes (issue 4 targets; the bench covers every scene) ---

#: (scene, min precision@1 %, min count with GT): measured values minus a small margin.
ACCURACY = [
    ("middlebury2003/cones", 98.5, 2500),
    ("middlebury2001/tsukuba", 97.0, 850),
    ("eth3d/terrace", 97.0, 1700),
]


@pytest.mark.parametrize(("scene", "min_p1", "min_count"), ACCURACY)
def test_accuracy_on_real_scenes(scene: str, min_p1: float, min_count: int) -> None:
    sc = _scene(scene)
    m = sv.match(sc.left, sc.right, max_disparity=sc.max_disparity)
    r = sv.match(sc.left, sc.right, method="best", max_disparity=sc.max_disparity)
    sm = sparse_metrics(m.xl, m.yl, m.xr, sc.gt)
    sr = sparse_metrics(r.xl, r.yl, r.xr, sc.gt)
    assert sm.precision[1.0] >= min_p1
    assert sm.count >= min_count
    assert sm.coverage == 16
    # Sub-pixel refinement works. Tsukuba's GT is integer-valued and the side rescue keeps
    # matches next to depth edges: 87.6 % @0.5 against 97.96 % @1 (margin 12 points).
    assert sm.precision[0.5] >= sm.precision[1.0] - 12.0
    # The network is at least as precise as the best-match reference on the same points.
    assert sm.precision[1.0] >= sr.precision[1.0] - 0.2


def test_points_mode_is_precise() -> None:
    sc = _scene("middlebury2003/cones")
    m = sv.match(sc.left, sc.right, max_disparity=sc.max_disparity, candidates="points")
    sm = sparse_metrics(m.xl, m.yl, m.xr, sc.gt)
    assert sm.count > 300 and sm.precision[1.0] >= 97.0


def test_side_rescue_adds_matches_at_equal_precision() -> None:
    # The side rescue of the half-window test (rescue_min) keeps matches whose failing half has
    # only agreeing matches on its side: many more matches, precision within half a point.
    sc = _scene("eth3d/terrace")
    on = sv.match(sc.left, sc.right, max_disparity=sc.max_disparity)
    off = sv.match(sc.left, sc.right, max_disparity=sc.max_disparity, rescue_min=0)
    s_on = sparse_metrics(on.xl, on.yl, on.xr, sc.gt)
    s_off = sparse_metrics(off.xl, off.yl, off.xr, sc.gt)
    assert s_on.count >= 1.3 * s_off.count
    assert s_on.precision[1.0] >= s_off.precision[1.0] - 0.5


def test_thin_surface_fallback_matches_the_reference_count_on_wood2() -> None:
    # wood2's strip at d = 24 (y 144-151) is narrower than the 40x40 window: the dominant
    # surface's inhibition switches its single-candidate, edge-clean points off, with no
    # support left. The thin-surface fallback gives them back; the network then has at least
    # the best-match reference's count at its own precision (issue 4), without losing precision.
    sc = _scene("middlebury2006/wood2")
    on = sv.match(sc.left, sc.right, max_disparity=sc.max_disparity)
    off = sv.match(sc.left, sc.right, max_disparity=sc.max_disparity, fallback_group=False)
    best = sv.match(sc.left, sc.right, method="best", max_disparity=sc.max_disparity)
    s_on = sparse_metrics(on.xl, on.yl, on.xr, sc.gt)
    s_off = sparse_metrics(off.xl, off.yl, off.xr, sc.gt)
    strip = (np.abs(on.yl - 147.5) <= 4) & (on.xl >= 317) & (on.xl <= 426)
    assert np.count_nonzero(np.abs((on.xl - on.xr)[strip] - 24) <= 1) >= 20
    assert s_on.count > s_off.count
    assert s_on.precision[1.0] >= s_off.precision[1.0] - 0.05
    at_p = count_at_precision(best.xl, best.yl, best.xr, best.score, sc.gt, s_on.precision[1.0])
    assert s_on.count >= at_p


@pytest.mark.parametrize("layout", ["bgr", "grey", "grey1", "bgra"])
def test_uint8_input_gives_the_float_path_matches(layout: str) -> None:
    # 8-bit pairs are converted to grey inside the kernel's call; the matches must be those of
    # the float32 grey images check_pair makes (bit for bit).
    from stereovision._validate import as_gray_float

    sc = _scene("middlebury2003/cones")
    left, right = sc.left[40:240, 60:360], sc.right[40:240, 60:360]
    if layout != "bgr":
        left = cv2.cvtColor(left, cv2.COLOR_BGR2GRAY if layout != "bgra" else cv2.COLOR_BGR2BGRA)
        right = cv2.cvtColor(right, cv2.COLOR_BGR2GRAY if layout != "bgra" else cv2.COLOR_BGR2BGRA)
        if layout == "grey1":
            left, right = left[:, :, None], right[:, :, None]
    a = hp.hopfield_match(left, right, max_disparity=sc.max_disparity)
    b = hp.hopfield_match(as_gray_float(left), as_gray_float(right), max_disparity=sc.max_disparity)
    assert len(a) > 200
    for f in ("xl", "yl", "xr", "yr", "score"):
        assert np.array_equal(getattr(a, f), getattr(b, f)), f
    assert a.image_shape == b.image_shape == (200, 300)


def test_match_keeps_min_disparity() -> None:
    # The parabola's sub-pixel vertex reached half a pixel below min_disparity (5.5 at 6).
    sc = _scene("middlebury2001/tsukuba")
    for method in ("hopfield", "best"):
        m = sv.match(sc.left, sc.right, method=method, max_disparity=8, min_disparity=6)
        d = m.xl - m.xr
        assert len(m) > 500 and float(d.min()) >= 6.0 and float(d.max()) <= 8.0
        assert m.stats["n_out_of_range"] > 0


def test_unknown_parameter_names_the_valid_ones() -> None:
    ok = np.random.default_rng(0).random((40, 50), dtype=np.float32)
    with pytest.raises(
        ValueError, match=r"\['k_cnd'\] \(did you mean 'k_cand'\?\): expected one of .*s_min"
    ):
        sv.match(ok, ok, method="hopfield", max_disparity=8, k_cnd=3)


def test_a_misspelt_keyword_of_match_names_the_keyword() -> None:
    """A misspelling of match()'s own keyword landed in **params, where the matcher named its
    parameters only: max_disparty=8 was "unknown Hopfield parameter(s) ['max_disparty']" with
    no hint ("did you mean 'min_disparity'?" with "fused"), calibration= likewise. Keys near a
    parameter of the method are still the matcher's to name."""
    ok = np.zeros((8, 12), np.float32)  # refused before any matching
    for method, key, meant in [
        ("hopfield", "max_disparty", "max_disparity"),
        ("fused", "max_disparty", "max_disparity"),
        ("mcgm", "calibration", "calib"),
        ("gabor", "min_disp", "min_disparity"),
        ("best", "methods", "method"),
    ]:
        with pytest.raises(ValueError) as err:
            sv.match(ok, ok, method=method, **{key: 8})
        assert (
            str(err.value) == f"match: unknown keyword argument {key!r} (did you mean {meant!r}?)"
        )
    with pytest.raises(
        ValueError, match=r"^unknown fusion option\(s\) \['mod'\] \(did you mean 'mode'"
    ):
        sv.match(ok, ok, method="fused", max_disparity=8, mod="vote")
    # depth_map's own method, given by keyword, was "unknown" alone (positional: test_newuser)
    with pytest.raises(ValueError) as err:
        sv.match(ok, ok, method="census")
    assert str(err.value) == (
        "unknown method 'census': expected one of hopfield, best, mcgm, fused, gabor ('census' "
        "is a method of stereovision.depth_map, not of match)"
    )


_NON_NEGATIVE = ["A", "B", "D", "theta", "compat_theta", "compat_slope", "compat_grad",
                 "tau_y", "edge_penalty", "rescue_med", "agree_tol"]  # fmt: skip


@pytest.mark.parametrize("name", _NON_NEGATIVE)
def test_a_negative_weight_or_tolerance_is_refused(name: str) -> None:
    """A negative energy weight turns its term into its opposite (A=-1: neighbours of another
    disparity support a match), a negative tolerance passes nothing (agree_tol=-1: no match at
    all): they ran without a word (MCGM refuses its own so); 0 stays allowed."""
    ok = np.random.default_rng(0).random((40, 60), dtype=np.float32)
    right = np.roll(ok, -3, axis=1)
    bad = -1 if name == "agree_tol" else -0.5
    with pytest.raises(
        ValueError, match=rf"^invalid parameter `{name}`: must be finite and >= 0, got {bad}$"
    ):
        sv.match(ok, right, method="hopfield", max_disparity=8, **{name: bad})
    with pytest.raises(ValueError, match=rf"^invalid parameter `{name}`: must be finite and >= 0"):
        hp.hopfield_candidates(ok, right, max_disparity=8, **{name: bad})
    sv.match(ok, right, method="hopfield", max_disparity=8, **{name: 0})


@pytest.mark.parametrize("method", ["hopfield", "best"])
@pytest.mark.parametrize(
    ("lo", "shown"), [(32.5, "32.5"), (1e300, "1e+300"), (2**70, "1180591620717411303424")]
)
def test_min_disparity_above_max_is_refused_as_given(method: str, lo: float, shown: str) -> None:
    # The check compared the rounded and clipped range: 32.5 over 32 (floor 32 <= ceil 32) ran
    # and dropped every match without a word; 1e300 was named by its clip, 2147483647.
    ok = np.random.default_rng(0).random((40, 60), dtype=np.float32)
    with pytest.raises(
        ValueError, match=re.escape(f"max_disparity (32) must be >= min_disparity ({shown})")
    ):
        sv.match(ok, np.roll(ok, -3, axis=1), method=method, max_disparity=32, min_disparity=lo)


def test_match_best_is_the_reference_without_the_network() -> None:
    rng = np.random.default_rng(0)
    left = rng.random((60, 80), dtype=np.float32)
    right = np.roll(left, -5, axis=1)
    m = sv.match(left, right, method="best", max_disparity=16)
    ref = hp.best_match(left, right, max_disparity=16)
    assert len(m) > 100 and len(m.energy_trace) == 0
    np.testing.assert_array_equal(m.to_array(), ref.to_array())
    assert len(sv.match(left, right, method="hopfield", max_disparity=16).energy_trace) > 0


def test_match_fused_keeps_count_and_sources_per_member_in_range() -> None:
    # a member dropped out of range takes its count and sources along
    sc = _scene("middlebury2001/tsukuba")
    m = sv.match(sc.left, sc.right, method="fused", max_disparity=8.5, min_disparity=6)
    d = m.xl - m.xr
    assert m.stats["n_out_of_range"] > 0 and float(d.min()) >= 6.0 and float(d.max()) <= 8.5
    assert len(m.stats["count"]) == len(m.stats["sources"]) == len(m) > 100


def _stereopi_raw(data_dir: Path) -> tuple[np.ndarray, np.ndarray, sv.Calibration]:
    """The StereoPi rig's raw (unrectified, distorted) scene pair and its calibration."""
    from tests.test_calibration import stereopi_calib

    sp = data_dir / "stereopi_rig" / "scene_photo"
    left, right = (cv2.imread(str(sp / f"{side}.png")) for side in ("left", "right"))
    return left, right, stereopi_calib(data_dir)


@pytest.mark.parametrize("method", ["hopfield", "mcgm"])
def test_match_with_a_raw_rig_is_the_match_of_the_pair_rectified_by_hand(
    data_dir: Path, method: str
) -> None:
    """match(l, r, raw_calib) is match() of calib.rectify(l, r): an 8-bit pair through its 8-bit
    copy, a float (or mixed uint8/float) pair through its own grey levels, the automatic range
    estimated on the rectified pair (48 px here). A pair rectified with its images swapped, a
    float pair not rectified at all, a mixed pair through the 8-bit copy, or a fixed 64 px range
    survived the tests."""
    from stereovision._validate import as_gray_float

    left, right, cal = _stereopi_raw(data_dir)
    assert not cal.rectified
    lr, rr = cal.rectify(left, right)
    got = sv.match(left, right, cal, method=method, max_disparity=40)
    want = sv.match(lr, rr, method=method, max_disparity=40)
    assert len(got) > 200
    np.testing.assert_array_equal(got.to_array(), want.to_array())
    # float and mixed pairs: the grey images, rectified, clipped to [0, 1]
    rf = right.astype(np.float32) / 255
    for lf in (left.astype(np.float32) / 255, left):
        got = sv.match(lf, rf, cal, method=method, max_disparity=40)
        gl, gr = cal.rectify(as_gray_float(lf, "left"), as_gray_float(rf, "right"))
        want = sv.match(np.clip(gl, 0, 1), np.clip(gr, 0, 1), method=method, max_disparity=40)
        assert len(got) > 200
        np.testing.assert_array_equal(got.to_array(), want.to_array())
    # no max_disparity: estimated on the rectified pair
    est = sv.estimate_max_disparity(lr, rr)
    assert est == 48
    auto = sv.match(left, right, cal, method=method)
    np.testing.assert_array_equal(
        auto.to_array(), sv.match(lr, rr, method=method, max_disparity=est).to_array()
    )


def _blurred_pair(shift: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """A smooth random texture and itself shifted ``shift`` px left (disparity ``shift``)."""
    img = cv2.GaussianBlur(
        np.random.default_rng(0).random((48, 80)).astype(np.float32), (0, 0), 1.5
    )
    img = (img - img.min()) / (img.max() - img.min())
    return img, np.ascontiguousarray(np.roll(img, -shift, axis=1))


def test_tau_y_default_drops_a_conflict_two_rows_off() -> None:
    """C.5 disambiguation at tau_y = 1 px: a 16x16 patch of the right view moved 2 rows up
    (its points' candidates all 2 rows off the singles' median 0, several on at once with the
    network's inhibition off) loses those points; tau_y 2 kept them (tau_y 1.0 -> 2.0 changed
    no match on cones, tsukuba or terrace)."""
    base = cv2.GaussianBlur(
        np.random.default_rng(1).random((90, 140)).astype(np.float32), (0, 0), 1.5
    )
    base = (base - base.min()) / (base.max() - base.min())
    left = np.ascontiguousarray(base[5:85, 10:130])  # right = left 6 px on ...
    right = base[5:85, 16:136].copy()
    right[30:46, 50:66] = base[37:53, 66:82]  # ... but 2 rows up in the patch
    kw = {"max_disparity": 10, "candidates": "points", "s_min": 0.5, "A": 0.0, "B": 0.0}
    kw["theta"] = 0.0
    default = hp.hopfield_match(left, right, **kw)
    np.testing.assert_array_equal(
        default.to_array(), hp.hopfield_match(left, right, tau_y=1.0, **kw).to_array()
    )
    # the kernel's own default (HopfieldParams::default) too
    m, _trace, _stats = sv._core.hopfield_match(left, right, {**kw, "method": "hopfield"})
    np.testing.assert_array_equal(m[:, :4], default.to_array())
    wide = hp.hopfield_match(left, right, tau_y=2.0, **kw)
    got = {(x, y): (x - xr, y - yr) for x, y, xr, yr in default.to_array().tolist()}
    more = {(x, y): (x - xr, y - yr) for x, y, xr, yr in wide.to_array().tolist()}
    assert len(got) == 261 and len(more) == 265
    extra = {k: v for k, v in more.items() if k not in got}
    assert sorted(extra) == [(62.0, 42.0), (64.0, 42.0), (65.0, 38.0), (67.0, 38.0)]
    for d, dy in extra.values():
        assert d == pytest.approx(6.0, abs=0.1) and dy == 2.0
    assert all(more[k] == v for k, v in got.items())


def test_tau_y_default_drops_a_conflict_one_and_a_half_rows_off() -> None:
    """C.5 at a half-pixel reference: one textured patch three times on a flat view, A on its
    row, B one row up and C both two rows up and one down in the right view. A's and B's 7
    single matches each put the vertical reference at 0.5, so C's conflict is 1.5 px off either
    way: dropped at the default tau_y = 1 px, kept from 1.5 (a default of 1.5 survived the
    tests: no scene has such a conflict; 1.0 -> 1.5 changed no match on the 17 GT scenes)."""
    size = 10
    patch = cv2.GaussianBlur(
        np.random.default_rng(0).random((size, size)).astype(np.float32), (0, 0), 1.0
    )
    patch = (patch - patch.mean()) / patch.std() * 0.15
    left = np.full((80, 110), 0.5, np.float32)
    right = left.copy()
    placed = [
        (left, 30, 20),  # A, disparity 6 ...
        (right, 24, 20),  # ... on its row
        (left, 60, 20),  # B ...
        (right, 54, 19),  # ... one row up
        (left, 45, 45),  # C ...
        (right, 39, 43),  # ... two rows up
        (right, 39, 46),  # ... and one down
    ]
    for img, x, y in placed:
        img[y : y + size, x : x + size] += patch
    kw = {"max_disparity": 10, "candidates": "points", "s_min": 0.5, "A": 0.0, "B": 0.0}
    kw["theta"] = 0.0
    default = hp.hopfield_match(left, right, **kw).to_array()
    np.testing.assert_array_equal(
        default, hp.hopfield_match(left, right, tau_y=1.0, **kw).to_array()
    )
    dy = default[:, 1] - default[:, 3]
    assert len(default) == 14 and (dy == 0).sum() == 7 and (dy == 1).sum() == 7
    assert len(hp.hopfield_match(left, right, tau_y=1.49, **kw)) == 14
    wide = hp.hopfield_match(left, right, tau_y=1.5, **kw).to_array()
    extra = [r for r in wide.tolist() if r[1] >= 40]
    assert len(wide) == 15 and len(extra) == 1
    assert extra[0][:2] == [48.0, 46.0] and extra[0][3] == 44.0


def test_the_range_is_rounded_outwards_and_one_level_is_searched() -> None:
    """min_disparity 2.5 searches from level 2 (floor: the same matches as 2), max == min is a
    one-level search, not an error; rel_threshold/floor_rel above 1 and nms_half 0 are refused."""
    left, right = _blurred_pair()
    half = hp.hopfield_match(left, right, max_disparity=8, min_disparity=2.5)
    assert len(half) > 50
    np.testing.assert_array_equal(
        half.to_array(),
        hp.hopfield_match(left, right, max_disparity=8, min_disparity=2).to_array(),
    )
    assert len(hp.hopfield_match(left, right, max_disparity=3, min_disparity=3)) > 0
    for kw, says in (
        ({"rel_threshold": 1.5}, r"rel_threshold must lie in \[0, 1\], got 1.5"),
        ({"floor_rel": 1.0001}, r"floor_rel must lie in \[0, 1\], got 1.0001"),
        ({"nms_half": 0}, "nms_half: expected an integer from 1 to 2147483647, got 0"),
    ):
        with pytest.raises(ValueError, match="^" + says):
            hp.interest_points(left, **kw)


@pytest.mark.parametrize("run", [hp.hopfield_match, hp.best_match])
def test_direct_call_refuses_an_unreachable_range_as_match_does(
    run: Callable[..., sv.Matches],
) -> None:
    """min_disparity at the width or above: no pixel has a match there. match() refused it; the
    direct call returned 0 matches without a word. Both now raise match()'s ValueError."""
    rng = np.random.default_rng(0)
    left = rng.random((60, 80), dtype=np.float32)
    right = np.roll(left, -5, axis=1)
    method = "hopfield" if run is hp.hopfield_match else "best"
    for lo in (80, 81.5, 10**400):
        with pytest.raises(ValueError) as want:
            sv.match(left, right, method=method, max_disparity=lo, min_disparity=lo)
        assert str(want.value).startswith("min_disparity (")
        with pytest.raises(ValueError, match=f"^{re.escape(str(want.value))}$"):
            run(left, right, max_disparity=lo, min_disparity=lo)
    # 8-bit frames take the kernel's own grey conversion: the same refusal
    l8, r8 = ((255 * im).astype(np.uint8) for im in (left, right))
    with pytest.raises(ValueError, match=r"^min_disparity \(80\) is not below the image width 80"):
        run(l8, r8, max_disparity=80, min_disparity=80)
    # one column short of the width is searched: nothing there, 0 matches and no error
    assert len(run(left, right, max_disparity=79, min_disparity=79, min_agree=0)) == 0


def test_candidates_refuse_an_unreachable_range_as_match_does() -> None:
    """hopfield_candidates with min_disparity at the width or above returned an empty (0, 6)
    array without a word (the kernel clips the range to the image); it now raises match()'s
    ValueError, and one column short of the width still returns without error."""
    rng = np.random.default_rng(0)
    left = rng.random((60, 80), dtype=np.float32)
    right = np.roll(left, -5, axis=1)
    for lo in (80, 81.5, 10**400):
        with pytest.raises(ValueError) as want:
            sv.match(left, right, method="hopfield", max_disparity=lo, min_disparity=lo)
        with pytest.raises(ValueError, match=f"^{re.escape(str(want.value))}$"):
            hp.hopfield_candidates(left, right, max_disparity=lo, min_disparity=lo)
    assert hp.hopfield_candidates(left, right, max_disparity=79, min_disparity=79).shape[1] == 6


@pytest.mark.parametrize(
    "kw",
    [
        {"rel_threshold": 0.0, "floor_rel": 0.0},
        {"rel_threshold": 1.0, "floor_rel": 1.0, "tile": 0},
        {"tile": 0},
        {"nms_half": 2, "tile": 16, "rel_threshold": 0.05},
    ],
)
def test_interest_parameters_at_their_bounds_equal_the_reference(kw: dict[str, float]) -> None:
    """A second mutation audit: rel_threshold/floor_rel of exactly 0 or 1 refused, tile 0 (the
    whole image) refused and the arrays' documented float32 dtypes survived the tests."""
    left, _, _ = _grey("middlebury2001/tsukuba")
    ours = hp.interest_points(left, **kw)
    xy, vals = ref.interest_points(left, **kw)
    assert len(ours) == len(xy) > 0
    assert ours.xy.dtype == ours.values.dtype == ours.response.dtype == np.float32
    assert ours.xy.shape == (len(xy), 2) and ours.response.shape == left.shape
    assert np.array_equal(ours.xy.astype(np.int64), xy)
    assert np.array_equal(ours.values, vals)


def test_range_types_taken_and_refused() -> None:
    """NumPy integers and floats are pixel counts as Python's are; True and inf are refused
    (a mutation audit found each of the four unasserted)."""
    left, right = _blurred_pair()
    want = hp.hopfield_match(left, right, max_disparity=8).to_array()
    for v in (np.int64(8), np.int32(8), np.float32(8.0), np.float64(8.0)):
        got = hp.hopfield_match(left, right, max_disparity=v)
        np.testing.assert_array_equal(got.to_array(), want)
    for v, shown in ((True, "True"), (float("inf"), "inf")):
        with pytest.raises(
            ValueError, match=f"^max_disparity must be a non-negative .*got {shown}$"
        ):
            hp.hopfield_match(left, right, max_disparity=v)


@pytest.mark.parametrize("mode", ["row", "points"])
def test_defaults_are_the_kernels(mode: str) -> None:
    """DEFAULTS mirror HopfieldParams::default: the wrapper's matches equal the kernel's with
    only the range given (a changed seed, tau_y, dy_window, min_agree_sparse or
    fallback_min_support survived the tests, golden figures included)."""
    lc, rc, sc = _grey("middlebury2003/cones")  # whole: a crop missed fallback_alt_support
    for method, run in (("hopfield", hp.hopfield_match), ("best", hp.best_match)):
        got = run(lc, rc, max_disparity=sc.max_disparity, candidates=mode)
        m, trace, stats = sv._core.hopfield_match(
            lc, rc, {"max_disparity": sc.max_disparity, "method": method, "candidates": mode}
        )
        assert len(got) > 300
        np.testing.assert_array_equal(np.stack([got.xl, got.yl, got.xr, got.yr, got.score], 1), m)
        np.testing.assert_array_equal(got.energy_trace, trace)
        assert got.stats == dict(stats)
        # score is the match's ZNCC (a Matches with yr as score passed); yr its right row
        assert np.all((got.score >= hp.DEFAULTS["s_min"]) & (got.score <= 1.0 + 1e-6))
    if mode == "points":
        assert np.any(got.yr != got.yl)  # off-row candidates: yr is not yl


def test_best_match_on_8bit_frames_is_the_reference() -> None:
    """8-bit input goes through the kernel's own grey conversion: best_match there ran the
    network (the method was not passed on that path) without a test noticing."""
    from stereovision._validate import as_gray_float

    sc = _scene("middlebury2003/cones")
    left, right = sc.left[40:240, 60:360], sc.right[40:240, 60:360]
    a = hp.best_match(left, right, max_disparity=sc.max_disparity)
    b = hp.best_match(as_gray_float(left), as_gray_float(right), max_disparity=sc.max_disparity)
    assert len(a) > 200 and len(a.energy_trace) == 0
    np.testing.assert_array_equal(a.to_array(), b.to_array())
    np.testing.assert_array_equal(a.score, b.score)


@pytest.mark.parametrize("value", ["x", None, [0.1]])
def test_interest_thresholds_of_another_type_are_named(value: object) -> None:
    """rel_threshold="x" was "could not convert string to float: 'x'" and None float()'s bare
    TypeError, naming no parameter."""
    img = np.random.default_rng(0).random((30, 40), dtype=np.float32)
    for name in ("rel_threshold", "floor_rel"):
        with pytest.raises(ValueError, match=rf"^{name} must lie in \[0, 1\], got "):
            hp.interest_points(img, **{name: value})


@pytest.mark.parametrize(
    "value", [np.array([0.05]), np.array(0.05), Fraction(1, 20), Decimal("0.05")]
)
def test_interest_thresholds_read_as_hopfield_match_reads_them(value: object) -> None:
    """A size-1 array, a Fraction or a Decimal is its number, as hopfield_match takes it for the
    same keys: interest_points refused each as 'rel_threshold must lie in [0, 1], got
    array([0.05])', a value within [0, 1]."""
    img = np.random.default_rng(0).random((30, 40), dtype=np.float32)
    for name in ("rel_threshold", "floor_rel"):
        want = hp.interest_points(img, **{name: 0.05})
        got = hp.interest_points(img, **{name: value})
        np.testing.assert_array_equal(got.xy, want.xy)
        assert len(want) > 0
    with pytest.raises(ValueError, match=r"^rel_threshold must lie in \[0, 1\], got array"):
        hp.interest_points(img, rel_threshold=np.array([1.5]))


@pytest.mark.parametrize(
    ("name", "extra"),
    [("nms_half", {}), ("edge_tol", {}), ("dy_window", {"candidates": "points"})],
)
def test_a_window_past_the_image_is_the_whole_image_up_to_2_64(
    name: str, extra: dict[str, object]
) -> None:
    """The kernel added these sizes to a coordinate, which wrapped for 2**64 - 1 (accepted) to a
    window ending before the point: on a cones crop nms_half kept 374 interest points (160
    matches) where a window over the crop keeps one, edge_tol gave 0 matches instead of 372 and
    dy_window (points mode) 0 instead of 134."""
    left, right, sc = _grey("middlebury2003/cones")
    lc, rc = (
        np.ascontiguousarray(left[100:200, 100:300]),
        np.ascontiguousarray(right[100:200, 100:300]),
    )
    want, got = (
        hp.hopfield_match(lc, rc, max_disparity=sc.max_disparity, **{name: v}, **extra)
        for v in (1000, 2**64 - 1)
    )
    np.testing.assert_array_equal(got.to_array(), want.to_array())
    assert got.stats == want.stats
    if name == "nms_half":
        assert want.stats["n_points"] == 1
    else:
        assert len(want) > 20


@pytest.mark.parametrize("s_min", [0.0, -1.0])
def test_textureless_right_windows_are_no_candidates_at_any_s_min(s_min: float) -> None:
    """An undefined ZNCC (a textureless window) reads 0: with s_min <= 0 (accepted) a flat right
    image gave every left point a candidate of score 0 and, with the edge test off, a match of
    score 0. Defined similarities still pass, as in the reference."""
    left = _texture(60, 120, 0.0, seed=4)
    kw: dict[str, object] = {"s_min": s_min, "s_init": 0.0, "edge_test": False}
    flat = np.full_like(left, 0.5)
    assert len(hp.hopfield_candidates(left, flat, max_disparity=16, **kw)) == 0
    assert len(hp.best_match(left, flat, max_disparity=16, **kw)) == 0
    assert len(hp.hopfield_match(left, flat, max_disparity=16, **kw)) == 0
    # Flat over columns 40..70: right windows centred in 43..66 lie inside it.
    right = _texture(60, 120, 3.0, seed=4)
    right[:, 40:70] = 0.5
    cand = hp.hopfield_candidates(left, right, max_disparity=16, **kw)
    want = ref.candidates(left, right, 0, 16, {**ref.DEFAULTS, **kw})
    assert len(cand) > 100
    assert not np.any((cand[:, 3] >= 43) & (cand[:, 3] <= 66))
    ours = {(int(c[0]), int(c[3])) for c in cand}
    assert ours == {(n["point"], n["xr"]) for n in want}


def test_counts_and_reals_are_read_as_the_librarys_numbers() -> None:
    """The library's one rule of a count (whole_value: gabor's, sgm's, fuse's) was not the
    network's: k_cand=8.0, Fraction(8) or np.array([8.0]) was "parameter `k_cand`: TypeError:
    'float' object cannot be interpreted as an integer", and A=np.array([3.0]) "only
    0-dimensional arrays can be converted". Each gives the plain number's matches; 8.5 is still
    refused by name."""
    from fractions import Fraction

    rng = np.random.default_rng(0)
    left = rng.random((40, 60), dtype=np.float32)
    right = np.roll(left, -4, axis=1)
    base = {"k_cand": 8, "A": 3.0, "max_sweeps": 50}
    want = hp.hopfield_match(left, right, max_disparity=8, **base)
    assert len(want) > 50
    for kw in (
        {"k_cand": 8.0},
        {"k_cand": Fraction(8)},
        {"k_cand": np.array([8.0]), "max_sweeps": np.float32(50)},
        {"A": np.array([3.0])},
    ):
        got = hp.hopfield_match(left, right, max_disparity=8, **{**base, **kw})
        np.testing.assert_array_equal(got.xr, want.xr, err_msg=str(kw))
    with pytest.raises(ValueError, match="k_cand"):
        hp.hopfield_match(left, right, max_disparity=8, k_cand=8.5)


@pytest.mark.parametrize(
    ("value", "shown"),
    [
        (1e300, "1e+300"),
        (-1e300, "-1e+300"),
        (Decimal("1e4000"), "Decimal('1E+4000')"),
        (np.array([1e300]), "array([1.e+300])"),
        (10**400, "an integer of 401 digits"),
        (10**5000, "an integer of 5001 digits"),
        (Decimal("1e5000"), "Decimal('1E+5000')"),
        (Decimal("-1.5e9999"), "Decimal('-1.5E+9999')"),
    ],
    ids=["1e300", "-1e300", "Decimal", "array", "10**400", "10**5000", "Dec5000", "Dec-9999"],
)
def test_a_count_beyond_64_bits_is_shown_as_given(value: object, shown: str) -> None:
    """read_numbers turned a whole count into its int before the kernel named it, so
    k_cand=1e300 was "... got 1000000000000000052504760255204420248704468581108159..." (301
    digits: not what was given), Decimal('1e4000') 4001 digits, and an int of over 4300 digits
    "got ?". A count past any 64-bit integer is now named as given, on one short line; a
    Decimal of over 4300 digits (no whole_value) was then the kernel's bare "TypeError:
    'decimal.Decimal' object cannot be interpreted as an integer"."""
    left = np.random.default_rng(0).random((20, 30), dtype=np.float32)
    with pytest.raises(ValueError) as exc:
        hp.hopfield_match(left, left, max_disparity=8, k_cand=value)
    msg = str(exc.value)
    assert msg == f"k_cand: expected an integer of at most 64 bits, got {shown}"


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("A", np.array(True)),
        ("A", np.array([True])),
        ("A", np.array(np.timedelta64(3, "ns"))),
        ("k_cand", np.array(True)),
        ("A", np.array("3")),
        ("A", np.array("3", dtype=object)),
        ("A", np.array([b"3"])),
        ("A", np.array(np.datetime64(3, "ns"))),
        ("k_cand", np.array(["3"])),
    ],
    ids=[
        "A=array(True)",
        "A=array([True])",
        "A=array(3 ns)",
        "k_cand=array(True)",
        "A=array('3')",
        "A=array('3', object)",
        "A=array([b'3'])",
        "A=array(datetime)",
        "k_cand=array(['3'])",
    ],
)
def test_a_bool_or_a_time_in_a_size_1_array_is_no_number(name: str, value: object) -> None:
    """refuse_not_numbers caught A=True and k_cand=3 ns, but not the same given as a size-1
    array: A=np.array(True) ran as A=1 without a word (the kernel's float of it) and
    k_cand=np.array(True) was its bare "TypeError: only integer scalar arrays can be converted
    to a scalar index". Each is now named as its scalar is. Then A=np.array('3') (and the
    same of dtype object, or 3 ns since the epoch) still ran as A=3 though A='3' is refused."""
    left = np.random.default_rng(0).random((20, 30), dtype=np.float32)
    with pytest.raises(ValueError) as exc:
        hp.hopfield_match(left, left, max_disparity=8, **{name: value})
    assert str(exc.value) == f"{name}: expected a number, got {value!r}"


def test_a_text_none_or_list_parameter_is_named_as_gabor_names_it() -> None:
    """s_min='0.5' was the binding's "parameter `s_min`: TypeError: must be real number, not
    str" (k_cand=None "... 'NoneType' object cannot be interpreted as an integer", MCGM's
    knn='6' likewise), where gabor_disparity says "s_min: expected a number, got '0.5'"."""
    from stereovision.matching import mcgm

    left = np.zeros((8, 12), np.float32)  # refused before any matching
    for call, name, value in [
        (hp.hopfield_match, "s_min", "0.5"),
        (hp.best_match, "k_cand", None),
        (hp.hopfield_match, "A", [3.0]),
        (mcgm.mcgm_match, "knn", "6"),
    ]:
        with pytest.raises(ValueError) as exc:
            call(left, left, max_disparity=4, **{name: value})
        assert str(exc.value) == f"{name}: expected a number, got {value!r}"


def test_a_switch_that_is_no_bool_is_named() -> None:
    """edge_test="no" was the binding's "parameter `edge_test`: TypeError: 'str' object is not
    an instance of 'bool'" (MCGM's sides=1 likewise), where MCGM's debug says "debug: expected
    True or False"; a NumPy bool is one."""
    from stereovision.matching import mcgm

    left = np.zeros((8, 12), np.float32)  # refused before any matching
    for call, name, value in [
        (hp.hopfield_match, "edge_test", "no"),
        (mcgm.mcgm_match, "sides", 1),
    ]:
        with pytest.raises(ValueError) as exc:
            call(left, left, max_disparity=4, **{name: value})
        assert str(exc.value) == f"{name}: expected True or False, got {value!r}"
    assert len(hp.best_match(left, left, max_disparity=4, subpixel=np.False_)) == 0


@pytest.mark.parametrize("method", ["hopfield", "best", "mcgm", "gabor", "fused"])
def test_a_float16_range_gives_the_floats_matches_without_a_warning(method: str) -> None:
    """A range given as np.float16 (read from a half-precision map) was clipped against
    2**31 - 1 cast to float16: NumPy's "overflow encountered in cast", up to four times per
    call (match's range filter, the Hopfield and MCGM wrappers, the census map's check), for
    the same matches as the float's."""
    import warnings

    from stereovision.matching.sgm import sgm_disparity

    rng = np.random.default_rng(2)
    right = rng.random((40, 64)).astype(np.float32)
    left = np.roll(right, 5, axis=1)
    want = sv.match(left, right, method=method, max_disparity=12.5, min_disparity=2.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = sv.match(
            left,
            right,
            method=method,
            max_disparity=np.float16(12.5),
            min_disparity=np.float16(2.5),
        )
        sgm = sgm_disparity(left, right, max_disparity=np.float16(12.5))
    np.testing.assert_array_equal(got.to_array(), want.to_array())
    np.testing.assert_array_equal(sgm, sgm_disparity(left, right, max_disparity=12.5))


def test_interest_points_compare_and_hash_by_identity() -> None:
    """Two InterestPoints of one image: ``a == b`` compared their arrays and raised NumPy's
    'truth value of an array ... is ambiguous', and they were unhashable. Equal to themselves
    only, and hashable."""
    img = np.random.default_rng(0).random((24, 32)).astype(np.float32)
    a, b = hp.interest_points(img), hp.interest_points(img)
    assert len(a) > 1
    assert a == a and a != b and b not in [a]
    assert {a: 1, b: 2}[a] == 1 and len({a, b, a}) == 2
