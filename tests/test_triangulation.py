"""Tests of stereovision.triangulation (algorithms.md E): synthetic round trips with distortion,
OpenCV oracles (undistortPoints, triangulatePoints, reprojectImageTo3D), degenerate cases."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest

from stereovision.baselines import opencv_sgbm
from stereovision.calibration import Calibration
from stereovision.io import load_scene
from stereovision.triangulation import (
    depth_from_disparity,
    reproject,
    triangulate,
    undistort_normalized,
)

SIZE = (640, 480)


def raw_calib(unit: str = "m", scale: float = 1.0, D1=None, D2=None) -> Calibration:
    """Unrectified rig with distortion, skew-free, 15 cm baseline, slight toe-in."""
    return Calibration(
        K1=np.array([[600.0, 0.0, 321.5], [0.0, 603.0, 238.2], [0.0, 0.0, 1.0]]),
        D1=np.array([-0.21, 0.09, 0.0012, -0.0007, -0.02]) if D1 is None else D1,
        K2=np.array([[610.0, 0.0, 316.1], [0.0, 611.5, 243.9], [0.0, 0.0, 1.0]]),
        D2=np.array([-0.18, 0.05, -0.0009, 0.0011, 0.01]) if D2 is None else D2,
        R=cv2.Rodrigues(np.array([0.008, -0.04, 0.005]))[0],
        T=np.array([-0.15, 0.003, 0.004]) * scale,
        image_size=SIZE,
        unit=unit,
    )


def rect_calib(doffs: float = 0.0) -> Calibration:
    K1 = np.array([[700.0, 0.0, 330.0], [0.0, 700.0, 240.0], [0.0, 0.0, 1.0]])
    K2 = K1.copy()
    K2[0, 2] += doffs
    return Calibration(
        K1=K1,
        D1=np.zeros(5),
        K2=K2,
        D2=np.zeros(5),
        R=np.eye(3),
        T=np.array([-120.0, 0.0, 0.0]),
        image_size=SIZE,
        unit="mm",
        rectified=True,
        doffs=doffs,
    )


def scene_points(n: int = 200, seed: int = 0) -> np.ndarray:
    """Points in front of the rig, inside both fields of view (metres)."""
    rng = np.random.default_rng(seed)
    z = rng.uniform(0.8, 6.0, n)
    x = rng.uniform(-0.35, 0.35, n) * z
    y = rng.uniform(-0.28, 0.28, n) * z
    return np.column_stack([x, y, z])


def project(calib: Calibration, pts_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    s = 1.0 / calib.to_metres_factor  # points in the calibration's unit
    pl = cv2.projectPoints(pts_m * s, np.zeros(3), np.zeros(3), calib.K1, calib.D1)[0]
    rvec = cv2.Rodrigues(calib.R)[0]
    pr = cv2.projectPoints(pts_m * s, rvec, calib.T, calib.K2, calib.D2)[0]
    return pl.reshape(-1, 2), pr.reshape(-1, 2)


# ---------------------------------------------------------------------------------- undistortion


@pytest.mark.parametrize(
    "D",
    [
        np.array([-0.21, 0.09, 0.0012, -0.0007, -0.02]),  # Bouguet's 5
        np.array([-0.21, 0.09, 0.0012, -0.0007]),  # 4
        np.array([0.3, -0.1, 0.001, 0.002, 0.01, 0.25, -0.05, 0.02]),  # rational
        np.array([-0.2, 0.05, 0.001, 0.0, 0.0, 0.0, 0.0, 0.0, 0.002, -0.001, 0.001, 0.0005]),
        np.array([-0.2, 0.05, 0.001, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
    ],
)
def test_undistort_matches_opencv(D: np.ndarray) -> None:
    K = np.array([[600.0, 0.0, 321.5], [0.0, 603.0, 238.2], [0.0, 0.0, 1.0]])
    rng = np.random.default_rng(1)
    px = np.column_stack([rng.uniform(0, 640, 300), rng.uniform(0, 480, 300)])
    ours, ok = undistort_normalized(px, K, D)
    assert ok.all()
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-15)
    ref = cv2.undistortPoints(px.reshape(-1, 1, 2), K, D, criteria=crit).reshape(-1, 2)
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9)
    # and it inverts the forward model: re-distorting gives the pixels back
    back = cv2.projectPoints(
        np.column_stack([ours, np.ones(len(ours))]), np.zeros(3), np.zeros(3), K, D
    )[0].reshape(-1, 2)
    np.testing.assert_allclose(back, px, rtol=0, atol=1e-7)


def test_undistort_skew() -> None:
    K = np.array([[500.0, 2.0, 300.0], [0.0, 510.0, 200.0], [0.0, 0.0, 1.0]])
    xy = np.array([[0.1, -0.2], [0.3, 0.05]])
    px = (np.column_stack([xy, np.ones(2)]) @ K.T)[:, :2]
    got, ok = undistort_normalized(px, K, np.zeros(5))
    assert ok.all()
    np.testing.assert_allclose(got, xy, atol=1e-14)
    # None is no distortion, as OpenCV takes it: it was "D: expected 4, 5, 8, 12 or 14
    # coefficients, got 1" (np.asarray(None) is one NaN)
    for none in (None, []):
        again, ok = undistort_normalized(px, K, none)
        assert ok.all()
        np.testing.assert_array_equal(again, got)


def test_undistort_flags_non_convergence() -> None:
    # barrel k1=-0.5, k2=0.1: r_d(r) peaks at 0.6 (r = 1), so r_d > 0.6 has no preimage
    K = np.array([[300.0, 0.0, 160.0], [0.0, 300.0, 120.0], [0.0, 0.0, 1.0]])
    D = np.array([-0.5, 0.1, 0.0, 0.0, 0.0])
    px = np.array([[160.0 + 300 * 0.65, 120.0], [160.0 + 300 * 0.3, 120.0]])
    xy, ok = undistort_normalized(px, K, D)
    assert ok.tolist() == [False, True]
    assert np.isnan(xy[0]).all() and np.isfinite(xy[1]).all()
    with pytest.raises(ValueError, match="tilted-sensor"):
        undistort_normalized(px, K, np.r_[np.zeros(12), 0.01, 0.0])


def test_undistortion_reaches_the_corners_of_a_wide_lens() -> None:
    """A StereoPi rig's 320x240 camera (strong radial terms): near its corners the fixed point
    creeps, and 100 rounds flagged 3.1 % of its pixels (these among them) as not converged,
    NaN points from triangulate, where cv2.undistortPoints inverts them. They converge within
    UNDISTORT_MAX_ITER now, to OpenCV's values and back onto their pixels."""
    K = np.array([[240.04, 0.0, 162.12], [0.0, 240.04, 126.07], [0.0, 0.0, 1.0]])
    D = np.array([0.5287, -3.0857, 0.0, 0.0, 4.9323])
    px = np.array([[32.0, 0.0], [16.0, 16.0], [312.0, 24.0]])
    assert not undistort_normalized(px, K, D, max_iter=100)[1].any()  # the old cap
    ours, ok = undistort_normalized(px, K, D)
    assert ok.all()
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 5000, 1e-15)
    ref = cv2.undistortPoints(px.reshape(-1, 1, 2), K, D, criteria=crit).reshape(-1, 2)
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9)
    back = cv2.projectPoints(
        np.column_stack([ours, np.ones(len(ours))]), np.zeros(3), np.zeros(3), K, D
    )[0].reshape(-1, 2)
    np.testing.assert_allclose(back, px, rtol=0, atol=1e-7)


def test_undistortion_solves_the_corner_points_the_iteration_cycles_around() -> None:
    """At the very corners of the same camera the fixed point repels: the iteration 2-cycles (a
    step of 0.3 for ever) and 1.2 % of its pixels stayed flagged at any cap, NaN points from
    triangulate, where the model has a preimage (its radial term is monotonic) that
    cv2.undistortPoints finds. They get OpenCV's solution, kept as it maps back onto the pixel;
    a pixel past the model's reach stays flagged (test_undistort_flags_non_convergence)."""
    K = np.array([[240.04, 0.0, 162.12], [0.0, 240.04, 126.07], [0.0, 0.0, 1.0]])
    D = np.array([0.5287, -3.0857, 0.0, 0.0, 4.9323])
    px = np.array([[0.0, 0.0], [0.0, 239.0], [319.0, 0.0], [319.0, 239.0]])
    ours, ok = undistort_normalized(px, K, D)
    assert ok.all()
    back = cv2.projectPoints(
        np.column_stack([ours, np.ones(len(ours))]), np.zeros(3), np.zeros(3), K, D
    )[0].reshape(-1, 2)
    np.testing.assert_allclose(back, px, rtol=0, atol=1e-9)
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 5000, 1e-15)
    ref = cv2.undistortPoints(px.reshape(-1, 1, 2), K, D, criteria=crit).reshape(-1, 2)
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9)


def test_a_point_caught_in_a_2_cycle_stops_when_it_repeats(monkeypatch: pytest.MonkeyPatch) -> None:
    """The corner points above 2-cycle exactly (the iterate back on its bits of two rounds
    before within 21 to 95 rounds) and never converge, yet ran all UNDISTORT_MAX_ITER rounds
    (1000: a 2-point call 87 -> 12 ms) before OpenCV's solution took them over. They stop when
    they repeat, with the same points (the StereoPi cameras' 460,800 pixels bit-identical)."""
    K = np.array([[240.04, 0.0, 162.12], [0.0, 240.04, 126.07], [0.0, 0.0, 1.0]])
    D = np.array([0.5287, -3.0857, 0.0, 0.0, 4.9323])
    px = np.array([[0.0, 0.0], [319.0, 239.0]])
    rounds = 0
    hypot = np.hypot

    def counted(*args: object, **kwargs: object) -> object:
        nonlocal rounds
        rounds += 1
        return hypot(*args, **kwargs)  # type: ignore[call-overload]

    monkeypatch.setattr(np, "hypot", counted)  # one step per round, one check of OpenCV's
    ours, ok = undistort_normalized(px, K, D)
    monkeypatch.undo()
    assert ok.all() and rounds < 100
    # OpenCV's solution of the normalised point, as after the 1000 rounds, bit for bit
    xd = (px - K[:2, 2]) / np.diag(K)[:2]
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 1000, 1e-12)
    ref = cv2.undistortPoints(xd.reshape(-1, 1, 2), np.eye(3), np.r_[D, np.zeros(7)], criteria=crit)
    np.testing.assert_array_equal(ours, ref.reshape(-1, 2).astype(np.float64))


# ---------------------------------------------------------------------------------- triangulate


def test_round_trip_with_distortion() -> None:
    c = raw_calib()
    pts = scene_points()
    xl, xr = project(c, pts)
    res = triangulate(xl, xr, c)
    assert res.valid.all() and res.unit == "m"
    assert res.XL.shape == (200, 3) and res.XL.dtype == np.float64
    np.testing.assert_allclose(res.XL, pts, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(res.XR, pts @ c.R.T + c.T, rtol=1e-9, atol=1e-9)


def test_round_trip_of_a_fisheye_rig() -> None:
    """A fisheye rig's k1..k4 (equidistant model) were read as the pinhole model's k1, k2, p1,
    p2: its points came out up to metres off, all flagged valid."""
    om = np.array([0.01, -0.02, 0.005])
    c = Calibration(
        K1=np.array([[280.0, 0.0, 640.0], [0.0, 280.0, 400.0], [0.0, 0.0, 1.0]]),
        D1=np.array([-0.01, 0.05, -0.06, 0.02]),
        K2=np.array([[285.0, 0.0, 645.0], [0.0, 282.0, 398.0], [0.0, 0.0, 1.0]]),
        D2=np.array([-0.012, 0.04, -0.05, 0.018]),
        R=cv2.Rodrigues(om)[0],
        T=np.array([-64.0, 1.0, 0.5]),
        image_size=(1280, 800),
        unit="mm",
        model="fisheye",
    )
    rng = np.random.default_rng(2)
    theta, phi = rng.uniform(0, np.radians(80), 200), rng.uniform(0, 2 * np.pi, 200)
    dist = rng.uniform(0.5, 10.0, 200)
    pts = (
        np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
        * dist[:, None]
    )  # metres, up to 80 degrees off axis
    xl = cv2.fisheye.projectPoints(pts[:, None], np.zeros(3), np.zeros(3), c.K1, c.D1)[0]
    xr = cv2.fisheye.projectPoints(pts[:, None] * 1000, om, c.T, c.K2, c.D2)[0]
    xl = np.vstack([xl.reshape(-1, 2), [[np.nan, 5.0], [-1e6, -1e6]]])
    xr = np.vstack([xr.reshape(-1, 2), [[5.0, 5.0], [5.0, 5.0]]])
    res = triangulate(xl, xr, c)
    assert res.valid.tolist() == [True] * 200 + [False, False]
    np.testing.assert_allclose(res.XL[:200], pts, rtol=1e-9, atol=1e-9)
    assert np.isnan(res.XL[200:]).all()


def test_units_metres_by_default_and_feet() -> None:
    pts = scene_points(20, seed=2)
    c_mm = raw_calib(unit="mm", scale=1000.0)  # same rig, T in millimetres
    xl, xr = project(c_mm, pts)
    np.testing.assert_allclose(triangulate(xl, xr, c_mm).XL, pts, rtol=1e-9)
    ft = triangulate(xl, xr, c_mm, unit="ft")
    assert ft.unit == "ft"
    np.testing.assert_allclose(ft.XL, pts / 0.3048, rtol=1e-9)
    with pytest.raises(ValueError, match="unit"):
        triangulate(xl, xr, c_mm, unit="yard")
    # the Calibration methods take the unit as the module functions do (they had none)
    disp = np.full((4, 5), 20.0)
    np.testing.assert_allclose(
        c_mm.depth_from_disparity(disp, unit="ft"),
        depth_from_disparity(disp, c_mm) / 0.3048,
        rtol=1e-6,
    )
    np.testing.assert_allclose(
        c_mm.reproject(disp, unit="mm"), reproject(disp, c_mm) * 1000, rtol=1e-6
    )


def test_agrees_with_cv2_triangulate_points() -> None:
    c = raw_calib()
    pts = scene_points(100, seed=3)
    xl, xr = project(c, pts)
    ours = triangulate(xl, xr, c).XL
    nl, _ = undistort_normalized(xl, c.K1, c.D1)
    nr, _ = undistort_normalized(xr, c.K2, c.D2)
    ul = (np.column_stack([nl, np.ones(len(nl))]) @ c.K1.T)[:, :2]  # undistorted pixels
    ur = (np.column_stack([nr, np.ones(len(nr))]) @ c.K2.T)[:, :2]
    P1 = c.K1 @ np.hstack([np.eye(3), np.zeros((3, 1))])
    P2 = c.K2 @ np.hstack([c.R, c.T.reshape(3, 1)])
    h = cv2.triangulatePoints(P1, P2, ul.T.copy(), ur.T.copy())
    ref = (h[:3] / h[3]).T
    np.testing.assert_allclose(ours, ref, rtol=1e-6)


def test_degenerate_points_are_invalid() -> None:
    c = rect_calib()
    xl = np.array([[400.0, 250.0], [400.0, 250.0], [400.0, 250.0], [np.nan, 1.0]])
    xr = np.array([[400.0, 250.0], [410.0, 250.0], [380.0, 250.0], [1.0, 1.0]])
    # parallel rays (d = 0), negative disparity (behind), a good one, NaN input
    res = triangulate(xl, xr, c)
    assert res.valid.tolist() == [False, False, True, False]
    assert np.isnan(res.XL[[0, 1, 3]]).all() and np.isnan(res.XR[[0, 1, 3]]).all()
    # Z = f B / d = 700 * 0.12 m / 20 = 4.2 m
    np.testing.assert_allclose(res.XL[2], [70 * 4.2 / 700, 10 * 4.2 / 700, 4.2], rtol=1e-12)


def test_non_converged_undistortion_is_invalid() -> None:
    c = raw_calib(D1=np.array([-0.5, 0.1, 0.0, 0.0, 0.0]))
    xl = np.array([[321.5 + 600 * 0.65, 238.2], [321.5 + 600 * 0.1, 238.2]])
    xr = xl - [30.0, 0.0]
    res = triangulate(xl, xr, c)
    assert res.valid.tolist() == [False, True]


def test_triangulate_input_errors() -> None:
    c = rect_calib()
    with pytest.raises(ValueError, match=r"xl: expected an \(N, 2\).*transpose"):
        triangulate(np.zeros((2, 5)), np.zeros((2, 5)), c)
    with pytest.raises(ValueError, match=r"xl and xr must have the same shape"):
        triangulate(np.zeros((4, 2)), np.zeros((3, 2)), c)
    # one correspondence as its pixel, (x, y): the shape alone did not say to pass [[x, y]]
    with pytest.raises(ValueError) as err:
        triangulate((320, 240), (300, 240), c)
    assert str(err.value) == (
        "xl: expected an (N, 2) real array of (x, y) pixels, got shape (2,) dtype int64 "
        "(one point: [[x, y]])"
    )
    with pytest.raises(ValueError, match=r"^pts: .* got shape \(2,\) dtype float64 \(one point"):
        undistort_normalized([320.0, 240.0], c.K1, None)


def test_rectified_triangulation_equals_shortcut() -> None:
    c = rect_calib(doffs=6.0)
    rng = np.random.default_rng(4)
    x, y, d = rng.uniform(0, 640, 50), rng.uniform(0, 480, 50), rng.uniform(1, 90, 50)
    # x_R = x_L - d in the right image's own pixels (its cx is larger by doffs)
    res = triangulate(np.column_stack([x, y]), np.column_stack([x - d, y]), c)
    z = depth_from_disparity(d[None, :], c)[0]
    assert res.valid.all()
    np.testing.assert_allclose(res.XL[:, 2], z, rtol=1e-6)
    # ignoring doffs would be visibly wrong: Z = f B / d
    assert not np.allclose(res.XL[:, 2], 700 * 0.12 / d, rtol=1e-3)


# ---------------------------------------------------------------------------- rectified shortcut


def test_depth_from_disparity_hand_computed() -> None:
    c = rect_calib(doffs=6.0)
    d = np.array([[34.0, -6.0, -10.0, np.nan, 0.0, np.inf]])
    z = depth_from_disparity(d, c)
    assert z.dtype == np.float32 and z.shape == d.shape
    # 700 px * 0.12 m / (34 + 6) = 2.1 m ; d = 0 -> 700 * 0.12 / 6 = 14 m
    np.testing.assert_allclose(z[0, [0, 4]], [2.1, 14.0], rtol=1e-6)
    assert np.isnan(z[0, [1, 2, 3, 5]]).all()
    np.testing.assert_allclose(depth_from_disparity(d, c, unit="mm")[0, 0], 2100.0, rtol=1e-6)
    np.testing.assert_array_equal(c.depth_from_disparity(d), z)
    with pytest.raises(ValueError, match="disparity"):
        depth_from_disparity(np.zeros(3), c)


def test_a_depth_past_float32_is_no_depth() -> None:
    """A positive disparity so small that f B / d overflows float32 (8.4e4 mm px over 1e-35 px,
    or 1e-300 px in float64) is no depth, as in depth_map's kernel: it was +inf, with NumPy's
    "overflow encountered in cast", and reproject's X, Y were -inf, +inf or NaN."""
    c = rect_calib()
    d = np.array([[1e-35, 1e-300, 4.0, 3e-34]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warning either
        z = depth_from_disparity(d, c, unit="mm")
        pts = reproject(d, c, unit="mm")
    assert np.isnan(z[0, :2]).all() and np.isnan(pts[0, :2]).all()
    np.testing.assert_allclose(z[0, 2:], [21000.0, 2.8e38], rtol=1e-6)  # f32 max: 3.4e38
    np.testing.assert_allclose(pts[0, 2], [(2 - 330) * 30.0, -240 * 30.0, 21000.0], rtol=1e-6)


def test_a_point_past_float32_is_no_point() -> None:
    """A wide-angle view (fx 300 px over 1280 px: |x - cx| / fx up to 2.1) at a depth near
    float32's largest (2e38 mm): reproject's X, 4.3e38, was +inf with NumPy's "overflow
    encountered in cast" though the depth passed; the point is NaN as a whole now, as one
    whose depth is past float32, and the points that fit keep their bits."""
    K = np.array([[300.0, 0.0, 640.0], [0.0, 300.0, 360.0], [0.0, 0.0, 1.0]])
    c = Calibration(
        K1=K,
        D1=np.zeros(5),
        K2=K.copy(),
        D2=np.zeros(5),
        R=np.eye(3),
        T=np.array([-120.0, 0.0, 0.0]),
        image_size=(1280, 720),
        unit="mm",
        rectified=True,
    )
    d = np.full((720, 1280), np.nan)
    d[0, [0, 640, 1279]] = 1.8e-34  # Z = 2.0e38 mm
    d[1, 1279] = 4.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warning either
        pts = reproject(d, c, unit="mm")
    assert np.isnan(pts[0, [0, 1279]]).all()  # X = -4.3e38, +4.3e38
    np.testing.assert_allclose(pts[0, 640], [0.0, -2.4e38, 2.0e38], rtol=1e-6)
    np.testing.assert_allclose(pts[1, 1279], [639 * 30.0, -359 * 30.0, 9000.0], rtol=1e-6)


def test_depth_from_disparity_refuses_a_bool_map() -> None:
    # a validity mask passed for the disparity was read as 1 px and 0 px: 700 px * 0.12 m / 7 px
    # and / 6 px, depths where nothing was measured (gt_depth, the Table-1 GT, reads through it)
    c = rect_calib(doffs=6.0)
    with pytest.raises(
        ValueError, match=r"^disparity: expected a real \(H, W\) array, got .* bool"
    ):
        depth_from_disparity(np.ones((2, 2), bool), c)


def test_a_map_of_the_pair_resized_is_warned_about() -> None:
    """A half-size map read with the full-size calibration gave twice the depths, silently."""
    c = rect_calib(doffs=12.5)  # 640x480, f 700 px, B 0.12 m
    half = np.full((240, 320), 20.0)  # 40 px at full size
    with pytest.warns(UserWarning, match=r"is 320x240 px, the calibration's images 640x480") as w:
        z = depth_from_disparity(half, c)
    assert "about 2 x the true depths; use calib.scaled_to((320, 240))" in str(w[0].message)
    assert w[0].filename == __file__  # the caller's line
    assert z[0, 0] == pytest.approx(700 * 0.12 / (20 + 12.5), rel=1e-6)  # 2.58 m for 1.6 m
    good = c.scaled_to((320, 240))
    assert good.depth_from_disparity(half)[0, 0] == pytest.approx(700 * 0.12 / 52.5, rel=1e-3)
    for call in (lambda: reproject(half, c), lambda: c.reproject(half)):
        with pytest.warns(UserWarning, match="320x240 px") as w:
            call()
        assert w[0].filename == __file__
    with pytest.warns(UserWarning, match="320x240 px") as w:
        c.depth_from_disparity(half)
    assert w[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # its own size, a crop, a toy map, a row of matches
        for shape in ((480, 640), (200, 640), (100, 90), (48, 64), (1, 500)):
            depth_from_disparity(np.full(shape, 20.0), c)


@pytest.mark.parametrize("doffs", [0.0, 12.5])
def test_reproject_equals_opencv(doffs: float) -> None:
    c = rect_calib(doffs=doffs)
    rng = np.random.default_rng(5)
    disp = rng.uniform(-20.0, 100.0, (48, 64)).astype(np.float32)
    disp[::7, ::5] = np.nan
    ours = reproject(disp, c)
    ref = cv2.reprojectImageTo3D(np.nan_to_num(disp, nan=-1e6), c.Q) * c.to_metres_factor
    valid = np.isfinite(disp) & (disp + doffs > 0)
    assert ours.shape == (48, 64, 3) and ours.dtype == np.float32
    np.testing.assert_allclose(ours[valid], ref[valid], rtol=2e-5, atol=1e-6)
    assert np.isnan(ours[~valid]).all()
    np.testing.assert_allclose(ours[..., 2][valid], depth_from_disparity(disp, c)[valid], rtol=1e-6)


def test_unrectified_calibration_uses_rectified_geometry() -> None:
    c = raw_calib()
    rc = c.rectified_calibration()
    disp = np.array([[10.0, 50.0]])
    np.testing.assert_array_equal(depth_from_disparity(disp, c), depth_from_disparity(disp, rc))
    ref = cv2.reprojectImageTo3D(disp.astype(np.float32), c.Q)
    np.testing.assert_allclose(reproject(disp, c), ref, rtol=1e-5)


def test_terrace_shortcut_equals_opencv(data_dir: Path) -> None:
    s = load_scene(data_dir / "eth3d" / "terrace")
    assert s.calib is not None
    disp = opencv_sgbm(s.left, s.right, s.max_disparity)
    pts = s.calib.reproject(disp)
    ref = cv2.reprojectImageTo3D(np.nan_to_num(disp, nan=-1.0), s.calib.Q) / 1000.0
    valid = np.isfinite(disp) & (disp > 0)
    np.testing.assert_allclose(pts[valid], ref[valid], rtol=1e-5, atol=1e-6)
    # 711.499 px * 0.0599432 m / 10 px = 4.265 m
    z = s.calib.depth_from_disparity(np.array([[10.0]]))
    assert z[0, 0] == pytest.approx(711.499 * 0.0599432 / 10, rel=1e-6)


def test_depth_kernel_matches_numpy_reference_on_a_real_scene(data_dir: Path) -> None:
    """Rust depth_rectified vs tests/reference/depth_ref.py on ETH3D terrace's Gabor map.

    Tolerance: 1 ulp relative (2.4e-7); NaN exactly where the reference has NaN. A wrong sign of
    doffs or of the confidence slope, or an off-by-one pixel, is orders of magnitude above it.
    Infinite disparities (no depth) and NaN confidences (read as 0) are in it: the reference
    gave the former the depth 0 and the latter no depth, where the kernel does not.
    """
    import stereovision as sv
    from stereovision import _core
    from stereovision.depth import _SIGMA_FILLED, _SIGMA_REFINED
    from tests.reference import depth_ref

    scene = load_scene(data_dir / "eth3d" / "terrace")
    res = sv.depth_map(scene.left, scene.right, max_disparity=32)
    cal = scene.calib
    disp = res.disparity.copy()
    disp[:5, :] = -cal.doffs_px - 1.0  # behind the camera: NaN
    args = (cal.focal_px * cal.baseline_m, cal.doffs_px, *_SIGMA_REFINED, _SIGMA_FILLED)
    conf = res.confidence.copy()
    conf[100:120] = -1.0  # the mark of a filled pixel
    disp[5:7], disp[7:9] = np.inf, -np.inf
    conf[200:220] = np.nan
    z, s = _core.depth_rectified(disp, conf, *args)
    zr, sr = depth_ref.depth_rectified(disp, conf, *args)
    assert int(np.isfinite(zr).sum()) > 100000
    assert np.array_equal(np.isnan(z), np.isnan(zr)) and np.array_equal(np.isnan(s), np.isnan(sr))
    assert np.isnan(z[:9]).all()
    assert np.isfinite(z[200:220]).sum() > 1000  # NaN confidence: a depth, as confidence 0
    np.testing.assert_allclose(z, zr, rtol=2.4e-7, equal_nan=True)
    np.testing.assert_allclose(s, sr, rtol=2.4e-7, equal_nan=True)
    ok = np.isfinite(s[100:120])
    np.testing.assert_allclose(
        s[100:120][ok], (z * _SIGMA_FILLED / (disp + cal.doffs_px))[100:120][ok], rtol=1e-6
    )
    with pytest.raises(ValueError, match="fb"):
        _core.depth_rectified(disp, conf, 0.0, *args[1:])
    with pytest.raises(ValueError, match="shape"):
        _core.depth_rectified(disp, conf[:, 1:].copy(), *args)


@pytest.mark.parametrize("dtype", [np.complex128, np.bool_])
def test_points_of_a_wrong_dtype_are_not_told_to_transpose(dtype: type) -> None:
    """A (2, 2) array of another dtype was told "(transpose a (2, N) array)": transposing it
    changes nothing; its dtype is what is wrong."""
    pts = np.array([[100.0, 50.0], [200.0, 80.0]], dtype=dtype)
    with pytest.raises(ValueError, match="dtype") as exc:
        triangulate(pts, pts, raw_calib())
    assert "transpose" not in str(exc.value)
    with pytest.raises(ValueError, match="transpose"):
        triangulate(np.zeros((2, 5)), np.zeros((2, 5)), raw_calib())


def test_matches_of_a_resized_pair_warn_as_a_map_does() -> None:
    # half-size matches read with the full-size calibration gave twice the depth without a word
    from stereovision.matches import Matches

    full = Calibration.ideal((256, 128), 60.0, 0.1)
    half = full.scaled_to((128, 64))
    m = Matches(xl=[60.0], yl=[30.0], xr=[55.0], yr=[30.0], score=[1.0], image_shape=(64, 128))
    with pytest.warns(UserWarning, match=r"128x64 px, the calibration's images 256x128") as rec:
        far = m.to_points(full)
    assert rec[0].filename == __file__  # pointed at the caller's line
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        near = m.to_points(half)  # the right calibration: no warning
        crop = m.to_points(Calibration.ideal((640, 480), 60.0, 0.1))  # a crop: read as one
    assert float(far[0, 2]) == pytest.approx(2 * float(near[0, 2]), rel=1e-6)
    assert np.isfinite(crop).all()


@pytest.mark.parametrize(
    ("key", "value", "says"),
    [
        ("max_iter", 0, "max_iter: expected an integer from 1 to 2147483647, got 0"),
        ("max_iter", -5, "max_iter: expected an integer from 1 to 2147483647, got -5"),
        ("max_iter", 2.5, "max_iter: expected an integer from 1 to 2147483647, got 2.5"),
        ("max_iter", True, "max_iter: expected an integer from 1 to 2147483647, got True"),
        ("tol", 0.0, "tol: expected a positive finite number, got 0.0"),
        ("tol", -1.0, "tol: expected a positive finite number, got -1.0"),
        ("tol", float("nan"), "tol: expected a positive finite number, got nan"),
        ("tol", "1", "tol: expected a positive finite number, got str '1'"),
    ],
)
def test_undistortion_limits_are_checked(key: str, value: object, says: str) -> None:
    # 0 or -5 iterations, a tol of 0, -1 or NaN gave every point NaN without a word ("did not
    # converge"); "1" was NumPy's UFuncTypeError from the comparison
    c = raw_calib()
    xl, xr = project(c, scene_points(5))
    assert triangulate(xl, xr, c).valid.all()
    with pytest.raises(ValueError, match=re.escape(says)):
        triangulate(xl, xr, c, **{key: value})
    # undistort_normalized, public too, took them unchecked: the same NaN for every point (or
    # UFuncTypeError, "'float' object cannot be interpreted as an integer" for 2.5)
    assert undistort_normalized(xl, c.K1, c.D1)[1].all()
    with pytest.raises(ValueError, match=re.escape(says)):
        undistort_normalized(xl, c.K1, c.D1, **{key: value})


# ------------------------------------------------------------------ mutation audit (value tests)


def test_noisy_correspondences_give_the_midpoint_of_the_closest_points() -> None:
    """With noise the rays miss each other: the point is the midpoint of their closest points
    (E.2), not the left ray's end. Reference: the two ray lengths by least squares, in the left
    frame, from OpenCV's undistortion."""
    c = raw_calib()
    pts = scene_points(30, seed=8)
    xl, xr = project(c, pts)
    rng = np.random.default_rng(9)
    xl = xl + rng.normal(0, 0.7, xl.shape)
    xr = xr + rng.normal(0, 0.7, xr.shape)
    res = triangulate(xl, xr, c)
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-15)
    nl = cv2.undistortPoints(xl.reshape(-1, 1, 2), c.K1, c.D1, criteria=crit).reshape(-1, 2)
    nr = cv2.undistortPoints(xr.reshape(-1, 1, 2), c.K2, c.D2, criteria=crit).reshape(-1, 2)
    centre_r = -c.R.T @ c.T  # right camera centre in the left frame
    want = []
    for a, b in zip(nl, nr, strict=True):
        dl, dr = np.r_[a, 1.0], c.R.T @ np.r_[b, 1.0]
        (zl, zr), *_ = np.linalg.lstsq(np.column_stack([dl, -dr]), centre_r, rcond=None)
        want.append(0.5 * (zl * dl + centre_r + zr * dr))
    assert res.valid.all()
    np.testing.assert_allclose(res.XL, np.array(want), rtol=1e-7, atol=1e-9)
    # the noise is visible at this tolerance: the midpoint is not the left ray's point
    assert np.abs(res.XL - pts).max() > 1e-3


def test_nearly_parallel_rays_are_invalid() -> None:
    """A disparity of 1e-5 px (rays 1.4e-8 rad apart) is no measurement: invalid, not a
    point 8400 km away."""
    c = rect_calib()
    xl = np.array([[400.0, 250.0], [400.0, 250.0]])
    xr = np.array([[400.0 - 1e-5, 250.0], [380.0, 250.0]])
    res = triangulate(xl, xr, c)
    assert res.valid.tolist() == [False, True]
    assert np.isnan(res.XL[0]).all()


def test_reproject_uses_fy_for_y_on_a_rectified_rig_with_non_square_pixels() -> None:
    """``Y = (y - cy) Z / fy`` (E.3): a rectified rig given with fx != fy (anisotropic pixels)
    had its Y scaled by fy / fx if fx were used."""
    K = np.array([[700.0, 0.0, 330.0], [0.0, 760.0, 240.0], [0.0, 0.0, 1.0]])
    c = Calibration(
        K1=K, D1=np.zeros(5), K2=K.copy(), D2=np.zeros(5), R=np.eye(3),
        T=np.array([-120.0, 0.0, 0.0]), image_size=SIZE, unit="mm", rectified=True,
    )  # fmt: skip
    disp = np.full((480, 640), 35.0)
    pts = reproject(disp, c)
    z = 700 * 0.12 / 35  # 2.4 m
    assert pts[400, 100].tolist() == pytest.approx(
        [(100 - 330) * z / 700, (400 - 240) * z / 760, z], rel=1e-6
    )


def test_undistortion_without_distortion_flags_nan_points() -> None:
    K = np.array([[600.0, 0.0, 321.5], [0.0, 603.0, 238.2], [0.0, 0.0, 1.0]])
    xy, ok = undistort_normalized(np.array([[np.nan, 5.0], [321.5, 238.2]]), K, np.zeros(5))
    assert ok.tolist() == [False, True]
    assert xy[1].tolist() == [0.0, 0.0]


def test_a_tilted_sensor_is_refused_for_either_tilt_term() -> None:
    K = np.eye(3)
    for tilt in ([0.01, 0.0], [0.0, 0.01]):
        with pytest.raises(ValueError, match="tilted-sensor"):
            undistort_normalized(np.zeros((1, 2)), K, np.r_[np.zeros(12), tilt])


def test_a_point_behind_the_right_camera_is_invalid() -> None:
    """A wrong match (rows 384 px apart): the left ray's closest point is 2.6 cm ahead, the
    right ray's 5 mm behind its camera (Z_R < 0) while the midpoint lies in front of both:
    no point, as E.2 asks of both depths."""
    c = raw_calib()
    good_l, good_r = project(c, scene_points(1))
    res = triangulate(
        np.vstack([[505.68, 424.24], good_l]), np.vstack([[452.53, 40.44], good_r]), c
    )
    assert res.valid.tolist() == [False, True]
    assert np.isnan(res.XL[0]).all() and np.isnan(res.XR[0]).all()


def test_a_point_behind_the_left_camera_is_invalid() -> None:
    """The mirror of the right camera's case: a wrong match whose left ray's closest point is
    3.7 mm behind the left camera (Z_L < 0) while the right one's and the midpoint lie in front
    of both cameras: no point."""
    c = raw_calib()
    good_l, good_r = project(c, scene_points(1))
    res = triangulate(
        np.vstack([[175.26, 45.64], good_l]), np.vstack([[116.82, 428.44], good_r]), c
    )
    assert res.valid.tolist() == [False, True]
    assert np.isnan(res.XL[0]).all() and np.isnan(res.XR[0]).all()


def test_the_parallel_ray_limit_is_an_angle_wherever_the_rays_point() -> None:
    """Rays 5e-7 rad apart are parallel (below 1e-6 rad) at the image corner of a wide lens as
    at its centre: the limit is on the squared sine, ``delta / (|u|^2 |xR|^2)``; on ``delta``
    alone the corner's longer rays (|x|^2 = 4.6) passed as a point 80 km away."""
    K = np.array([[200.0, 0.0, 320.0], [0.0, 200.0, 240.0], [0.0, 0.0, 1.0]])
    c = Calibration(
        K1=K, D1=np.zeros(5), K2=K.copy(), D2=np.zeros(5), R=np.eye(3),
        T=np.array([-120.0, 0.0, 0.0]), image_size=SIZE, unit="mm", rectified=True,
    )  # fmt: skip
    # normalised (1.5, 1.15): rays 1.5e-6 / 4.6 * sqrt(1 + 1.15^2) = 5e-7 rad apart
    e = 1.5e-6 * 200  # px
    xl = np.array([[620.0, 470.0], [620.0, 470.0]])
    xr = np.array([[620.0 - e, 470.0], [600.0, 470.0]])
    res = triangulate(xl, xr, c)
    assert res.valid.tolist() == [False, True]
    assert np.isnan(res.XL[0]).all()


def test_triangulate_gives_both_frames_in_the_unit_asked() -> None:
    """XR as XL: in feet when asked (``XR = R XL + T`` in that unit), not in metres."""
    pts = scene_points(10, seed=5)
    c = raw_calib(unit="mm", scale=1000.0)
    xl, xr = project(c, pts)
    m = triangulate(xl, xr, c)
    ft = triangulate(xl, xr, c, unit="ft")
    want_r = pts @ c.R.T + c.T / 1000.0  # metres
    np.testing.assert_allclose(m.XR, want_r, rtol=1e-9)
    np.testing.assert_allclose(ft.XR, want_r / 0.3048, rtol=1e-9)
    np.testing.assert_allclose(ft.XR, ft.XL @ c.R.T + c.T / 304.8, rtol=1e-9)
    # the unit a plain str, as known_unit gives it (an np.str_ one was kept as given)
    named = triangulate(xl, xr, c, unit=np.str_("ft"))
    assert type(named.unit) is str and "np.str_" not in repr(named)
    np.testing.assert_array_equal(named.XL, ft.XL)


def test_a_map_resized_with_a_pixel_of_rounding_is_warned_about() -> None:
    """640x480 shrunk by 0.502 with sizes rounded down is 321x240: its height is 0.75 px off
    480 * 321 / 640, within the pixel of rounding the check allows, so it warns."""
    c = rect_calib()
    with pytest.warns(UserWarning, match="is 321x240 px"):
        depth_from_disparity(np.full((240, 321), 20.0), c)


@pytest.mark.parametrize("n", [1, 3, 6, 7, 13])
def test_a_distortion_vector_of_an_opencv_unknown_length_is_refused(n: int) -> None:
    """OpenCV's models have 4, 5, 8, 12 or 14 coefficients: 6 values were read silently as
    k1, k2, p1, p2, k3 and the rational k4 (OpenCV refuses them)."""
    K = np.array([[600.0, 0.0, 320.0], [0.0, 600.0, 240.0], [0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match=rf"D: expected 4, 5, 8, 12 or 14 coefficients, got {n}"):
        undistort_normalized(np.zeros((1, 2)), K, np.full(n, 0.01))


def test_a_fisheye_rig_obeys_max_iter_and_flags_points_not_yet_back() -> None:
    """The fisheye inversion's iteration cap was untested (a cap fixed at 20 passed): cut
    short, a point is invalid, and every point still called valid is exact."""
    om = np.array([0.01, -0.02, 0.005])
    c = Calibration(
        K1=np.array([[280.0, 0.0, 640.0], [0.0, 280.0, 400.0], [0.0, 0.0, 1.0]]),
        D1=np.array([-0.01, 0.05, -0.06, 0.02]),
        K2=np.array([[285.0, 0.0, 645.0], [0.0, 282.0, 398.0], [0.0, 0.0, 1.0]]),
        D2=np.array([-0.012, 0.04, -0.05, 0.018]),
        R=cv2.Rodrigues(om)[0],
        T=np.array([-64.0, 1.0, 0.5]),
        image_size=(1280, 800),
        unit="mm",
        model="fisheye",
    )
    rng = np.random.default_rng(2)
    theta, phi = rng.uniform(0, np.radians(80), 200), rng.uniform(0, 2 * np.pi, 200)
    dist = rng.uniform(0.5, 10.0, 200)
    pts = (
        np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
        * dist[:, None]
    )
    xl = cv2.fisheye.projectPoints(pts[:, None], np.zeros(3), np.zeros(3), c.K1, c.D1)[0]
    xr = cv2.fisheye.projectPoints(pts[:, None] * 1000, om, c.T, c.K2, c.D2)[0]
    xl, xr = xl.reshape(-1, 2), xr.reshape(-1, 2)
    assert not triangulate(xl, xr, c, max_iter=1).valid.any()  # one round: none back
    res = triangulate(xl, xr, c, max_iter=2)
    assert 0 < res.valid.sum() < 100  # measured 17 of 200
    np.testing.assert_allclose(res.XL[res.valid], pts[res.valid], rtol=1e-9, atol=1e-9)
    assert triangulate(xl, xr, c, max_iter=5).valid.all()


def test_a_map_not_of_one_scale_both_ways_is_not_warned_about() -> None:
    """The resize check asks both sides to fit one factor within a pixel; the height alone
    (a mutant) warned about 100x76 against 640x480 (height 1 px off 75, width 1.3 px off 101.3)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        depth_from_disparity(np.full((76, 100), 20.0), rect_calib())
    with pytest.warns(UserWarning, match="100x75 px"):
        depth_from_disparity(np.full((75, 100), 20.0), rect_calib())


def test_a_map_of_three_dimensions_or_another_calibration_is_refused() -> None:
    """A (H, W, 1) map and a calib that is not a Calibration passed no test (dropping either
    check passed): both are named."""
    c = rect_calib()
    for call in (depth_from_disparity, reproject):
        with pytest.raises(
            ValueError, match=re.escape("expected a real (H, W) array, got shape (4, 5, 1)")
        ):
            call(np.zeros((4, 5, 1)), c)
    with pytest.raises(TypeError, match=r"calib: expected a stereovision\.Calibration, got dict"):
        triangulate(np.zeros((3, 2)), np.zeros((3, 2)), {})  # type: ignore[arg-type]


def test_a_masked_map_is_refused_naming_its_masked_pixels() -> None:
    """np.asarray read a numpy.ma map's data: its masked pixels' values came out as depths and
    points (a masked 10 px gave 8.4 m). A map with masked pixels is refused, saying what to
    pass; one with a mask of nothing gives the plain map's depths."""
    c = rect_calib()
    d = np.ma.masked_array(np.full((2, 3), 10.0), mask=[[True, False, False], [False, False, True]])
    for call in (depth_from_disparity, reproject):
        with pytest.raises(ValueError) as err:
            call(d, c)
        assert str(err.value) == (
            "disparity: a masked array (numpy.ma) with 2 masked pixels, whose values would be "
            "read as real ones; pass disparity.filled(np.nan)"
        )
        np.testing.assert_array_equal(call(np.ma.masked_array(d.data), c), call(d.data, c))


@pytest.mark.parametrize("call", ["triangulate", "depth", "reproject"])
def test_an_unknown_unit_is_named(call: str) -> None:
    """'km' (not among the units) was untested on these three: a mutant letting it through
    failed with a bare KeyError; it is a ValueError listing the units."""
    c = rect_calib()
    calls = {
        "triangulate": lambda: triangulate(np.zeros((1, 2)), np.zeros((1, 2)), c, unit="km"),
        "depth": lambda: depth_from_disparity(np.ones((2, 2)), c, unit="km"),
        "reproject": lambda: reproject(np.ones((2, 2)), c, unit="km"),
    }
    with pytest.raises(ValueError, match=r"unit: expected one of \[.*'m'.*\], got 'km'"):
        calls[call]()


def test_a_midpoint_behind_the_right_camera_is_invalid() -> None:
    """Both rays' closest points in front of their cameras (Z_L 5.0 mm, Z_R 4.2 mm) and the
    midpoint in front of the left camera (6.6 mm), but 0.39 mm behind the right one: no point
    (the rig is raw_calib's with the cameras' roles swapped, where a wrong match of two
    rays crossing just ahead of the cameras puts the midpoint there)."""
    c0 = raw_calib()
    with pytest.warns(UserWarning, match="swapped"):
        c = Calibration(
            K1=c0.K2, D1=c0.D2, K2=c0.K1, D2=c0.D1, R=c0.R.T, T=-c0.R.T @ c0.T,
            image_size=SIZE, unit="m",
        )  # fmt: skip
    good_l, good_r = project(c, scene_points(1))
    xl = np.vstack([[329.44, 323.18], good_l])
    xr = np.vstack([[354.86, 11.47], good_r])
    res = triangulate(xl, xr, c)
    assert res.valid.tolist() == [False, True]
    assert np.isnan(res.XL[0]).all() and np.isnan(res.XR[0]).all()


def test_rays_just_wider_than_the_parallel_limit_give_a_far_point() -> None:
    """The limit is 1e-6 rad: rays 3e-6 rad apart (a disparity of 2.1e-3 px at f = 700 px)
    still give their point, Z = f B / d = 700 * 0.12 m / 2.1e-3 = 40 km; 5e-7 rad do not."""
    c = rect_calib()
    d = np.array([3e-6, 5e-7]) * 700.0
    xl = np.array([[400.0, 250.0], [400.0, 250.0]])
    xr = xl - np.column_stack([d, np.zeros(2)])
    res = triangulate(xl, xr, c)
    assert res.valid.tolist() == [True, False]
    np.testing.assert_allclose(res.XL[0, 2], 700.0 * 0.12 / d[0], rtol=1e-4)
    assert res.XL[0, 2] == pytest.approx(40_000.0, rel=1e-4)


#: A Middlebury-2014-style calib.txt with a principal point offset (doffs = cx1 - cx0), mm.
_MB2014_CALIB = """cam0=[3979.911 0 1244.772; 0 3979.911 1019.507; 0 0 1]
cam1=[3979.911 0 1369.115; 0 3979.911 1019.507; 0 0 1]
doffs=124.343
baseline=193.001
width=2964
height=1988
ndisp=270
"""


def test_a_middlebury_calib_txt_gives_depth_and_points_by_its_own_numbers(
    tmp_path: Path,
) -> None:
    """Z = f B / (d + doffs) in metres (baseline in mm), feet by 0.3048 m, X = (x - cx) Z / f,
    Y = (y - cy) Z / f, from the file's numbers read here by hand; d + doffs <= 0, NaN and inf
    give no depth; cv2.reprojectImageTo3D with Q gives the same points in mm."""
    path = tmp_path / "calib.txt"
    path.write_text(_MB2014_CALIB)
    c = Calibration.from_file(path)
    f, cx, cy, cx1, doffs, b_mm = 3979.911, 1244.772, 1019.507, 1369.115, 124.343, 193.001
    assert c.doffs_px == pytest.approx(cx1 - cx, abs=1e-9) == pytest.approx(doffs, abs=1e-9)
    d = np.array([[100.0, 270.0, 0.0], [-doffs, -doffs - 1.0, np.nan], [np.inf, -50.0, 1.5]])
    z = depth_from_disparity(d, c)
    with np.errstate(divide="ignore"):
        want = f * b_mm / 1000.0 / (d + doffs)
    want[~(np.isfinite(d + doffs) & (d + doffs > 0))] = np.nan
    np.testing.assert_allclose(z, want, rtol=1e-6)
    assert np.isnan(z).tolist() == [[False] * 3, [True, True, True], [True, False, False]]
    # 3979.911 px * 0.193001 m / 224.343 px = 3.424 m; in feet / 0.3048, in mm * 1000
    assert float(z[0, 0]) == pytest.approx(3.4239, abs=1e-4)
    np.testing.assert_allclose(depth_from_disparity(d, c, unit="ft"), want / 0.3048, rtol=1e-6)
    np.testing.assert_allclose(depth_from_disparity(d, c, unit="mm"), want * 1000, rtol=1e-6)
    pts = reproject(d, c)
    ys, xs = np.mgrid[0:3, 0:3].astype(np.float64)
    np.testing.assert_allclose(pts[..., 0], (xs - cx) * want / f, rtol=1e-6)
    np.testing.assert_allclose(pts[..., 1], (ys - cy) * want / f, rtol=1e-6)
    np.testing.assert_allclose(pts[..., 2], want, rtol=1e-6)
    ok = np.isfinite(want)
    ref = cv2.reprojectImageTo3D(np.nan_to_num(d, nan=-1e3, posinf=-1e3).astype(np.float32), c.Q)
    np.testing.assert_allclose(pts[ok], ref[ok] / 1000.0, rtol=1e-5)


def test_an_infinite_pixel_is_nan_and_triangulates_without_a_warning() -> None:
    # without distortion the point came back inf (flagged False, where the docstring says NaN)
    # and triangulate warned "invalid value encountered in matmul" on it
    K = np.array([[600.0, 0.0, 321.5], [0.0, 603.0, 238.2], [0.0, 0.0, 1.0]])
    c = Calibration(K, np.zeros(5), K, np.zeros(5), np.eye(3), np.array([-0.1, 0, 0]), SIZE)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pts = np.array([[np.inf, 5.0], [321.5, -np.inf]])
        xy, ok = undistort_normalized(pts, K, np.zeros(5))
        assert ok.tolist() == [False, False] and np.isnan(xy).all()
        res = triangulate([[np.inf, 240.0], [331.5, 238.2]], [[300.0, 240.0], [321.5, 238.2]], c)
    assert res.valid.tolist() == [False, True]
    assert np.isnan(res.XL[0]).all() and res.XL[1].tolist() == pytest.approx([0.1, 0, 6.0])


def test_a_pixel_past_float64_squared_triangulates_without_a_warning() -> None:
    # 1e300 px squares to inf: delta's inf - inf warned "invalid value encountered in subtract"
    K = np.array([[600.0, 0.0, 321.5], [0.0, 603.0, 238.2], [0.0, 0.0, 1.0]])
    c = Calibration(K, np.zeros(5), K, np.zeros(5), np.eye(3), np.array([-0.1, 0, 0]), SIZE)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = triangulate([[1e300, 240.0], [331.5, 238.2]], [[1e300 - 1, 240.0], [321.5, 238.2]], c)
    assert res.valid.tolist() == [False, True]
    assert np.isnan(res.XL[0]).all() and res.XL[1].tolist() == pytest.approx([0.1, 0, 6.0])


@pytest.mark.parametrize(
    ("K", "D", "says"),
    [
        (np.eye(2), np.zeros(5), "K: expected a 3 x 3 camera matrix"),
        (np.zeros((3, 3)), np.zeros(5), "positive focal lengths, got shape (3, 3)"),
        (np.diag([600.0, np.nan, 1.0]), np.zeros(5), "K: expected a 3 x 3 camera matrix"),
        (np.diag([600.0, 600.0, 1.0]), [np.nan, 0, 0, 0], "D: expected finite coefficients"),
    ],
)
def test_undistortion_names_a_camera_that_is_none(K: np.ndarray, D: object, says: str) -> None:
    # a (2, 2) K was IndexError, a zero focal length inf points with a RuntimeWarning, a NaN
    # in K or D NaN points: nothing named the argument
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=re.escape(says)):
            undistort_normalized([[300.0, 200.0]], K, D)


def test_undistortion_names_a_camera_that_is_no_numbers() -> None:
    """A K or D of text, a ragged list or complex numbers was NumPy's words naming neither
    ("could not convert string to float: 'abc'", "setting an array element with a sequence"),
    and a complex D lost its imaginary part with a ComplexWarning alone. Each is refused naming
    it; an object array of numbers (a pandas column) is still read."""
    K = np.diag([600.0, 600.0, 1.0])
    says = "K: expected a 3 x 3 camera matrix of finite numbers with positive focal lengths, got"
    for bad_K in ("abc", [[600, 0, 0], [0, 600], [0, 0, 1]], K + 0j):
        with pytest.raises(ValueError, match="^" + re.escape(says)):
            undistort_normalized([[300.0, 200.0]], bad_K, None)
    for bad_D, shown in (("abc", "'abc'"), ([[0, 0], [0, 0, 0]], "[[0, 0], [0, 0, 0]]")):
        with pytest.raises(ValueError) as err:
            undistort_normalized([[300.0, 200.0]], K, bad_D)
        assert str(err.value) == f"D: expected finite coefficients, got {shown}"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the ComplexWarning: no silent cast
        with pytest.raises(ValueError, match=r"^D: expected finite coefficients, got array"):
            undistort_normalized([[300.0, 200.0]], K, np.zeros(5) + 1e-3j)
    D = np.array([0.1, -0.05, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(
        undistort_normalized([[300.0, 200.0]], K.astype(object), D.astype(object))[0],
        undistort_normalized([[300.0, 200.0]], K, D)[0],
    )


def test_undistortion_refuses_a_bool_camera() -> None:
    """A bool K or D was read as numbers, where triangulate refuses bool points: np.eye(3,
    dtype=bool) was a camera of focal length 1 px, a mask of five a D of zeros. Both are
    refused naming the argument."""
    K = np.diag([600.0, 600.0, 1.0])
    with pytest.raises(ValueError) as err:
        undistort_normalized([[300.0, 200.0]], np.eye(3, dtype=bool), None)
    assert str(err.value) == (
        "K: expected a 3 x 3 camera matrix of finite numbers with positive focal lengths, got "
        "array of shape (3, 3) dtype bool"
    )
    with pytest.raises(ValueError) as err:
        undistort_normalized([[300.0, 200.0]], K, np.zeros(5, dtype=bool))
    assert str(err.value).startswith("D: expected finite coefficients, got array([False, ")


def test_undistortion_refuses_a_camera_matrix_not_of_opencvs_form() -> None:
    """A transposed K (MATLAB's IntrinsicMatrix is K.T) was read with its centre at (0, 0):
    the principal point (320, 240) came out at (0.457, 0.343), not (0, 0), without a word.
    Refused in Calibration's words, with the transpose named where it would do."""
    K = np.array([[700.0, 0.0, 320.0], [0.0, 700.0, 240.0], [0.0, 0.0, 1.0]])
    assert undistort_normalized([[320.0, 240.0]], K, None)[0].tolist() == [[0.0, 0.0]]
    form = "K: expected a camera matrix [[fx, s, cx], [0, fy, cy], [0, 0, 1]], got "
    with pytest.raises(ValueError) as err:
        undistort_normalized([[320.0, 240.0]], K.T, None)
    assert str(err.value) == form + f"{K.T.tolist()} (transposed? pass K.T)"
    scaled = K * 2.0  # a bottom row of (0, 0, 2): no transpose to suggest
    with pytest.raises(ValueError) as err:
        undistort_normalized([[320.0, 240.0]], scaled, np.zeros(5))
    assert str(err.value) == form + f"{scaled.tolist()}"


def test_a_map_of_fixed_point_disparities_is_warned_about() -> None:
    """A KITTI disparity PNG read as it is (uint16, d * 256) gave depths 256 times too small,
    silently (KITTI 000005_10's GT: median 0.038 m for 9.78 m). A disparity wider than the
    calibration's images is no match: warned of, naming the PNG reader and OpenCV's d * 16,
    at the caller's line; a map in pixels warns of nothing."""
    c = rect_calib(doffs=12.5)  # 640x480, f 700 px, B 0.12 m
    px = np.array([[20.0, np.nan, 7.5], [200.0, 40.0, 0.5]])
    png = np.round(np.nan_to_num(px) * 256).astype(np.uint16)
    says = r"^disparity: values up to 51200 px, wider than the calibration's images \(640 px\)"
    for call in (
        lambda: depth_from_disparity(png, c),
        lambda: reproject(png, c),
        lambda: c.depth_from_disparity(png),
        lambda: c.reproject(png),
    ):
        with pytest.warns(UserWarning, match=says) as w:
            call()
        assert "export.read_disparity_png" in str(w[0].message) and "d * 16" in str(w[0].message)
        assert w[0].filename == __file__  # the caller's line
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        z = depth_from_disparity(png / 256.0, c)
        reproject(px, c)
        depth_from_disparity(np.full((2, 2), np.nan), c)  # no disparity at all
    assert z[0, 0] == pytest.approx(700 * 0.12 / (20 + 12.5), rel=1e-6)


def test_results_compare_and_hash_by_identity() -> None:
    """Two results of two points: ``a == b`` (and ``b in [a]``) compared their arrays and
    raised NumPy's 'truth value of an array ... is ambiguous', and a result could not go in a
    set or key a dict. A result is equal to itself only, and hashable (as DepthResult,
    GroundPlane and TemporalFilter)."""
    c = rect_calib()
    pts = ([[331.5, 238.2], [100.0, 100.0]], [[321.5, 238.2], [90.0, 100.0]])
    a, b = triangulate(*pts, c), triangulate(*pts, c)
    assert a == a and a != b and b not in [a]
    assert {a: 1, b: 2}[a] == 1 and len({a, b, a}) == 2
