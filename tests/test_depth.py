"""depth_map end to end: values, units, frames, bad input."""

from __future__ import annotations

import dataclasses
import re
import warnings
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

import stereovision as sv
from stereovision._validate import as_gray_float
from stereovision.calibration import Calibration
from stereovision.io import load_scene, read_ply


def _texture(h: int, w: int, seed: int = 0) -> np.ndarray:
    """Band-limited random texture in [0, 1] (smooth enough for sub-pixel shifts)."""
    rng = np.random.default_rng(seed)
    spec = np.fft.fft2(rng.standard_normal((h, w)))
    fy = np.fft.fftfreq(h)[:, None]
    fx = np.fft.fftfreq(w)[None, :]
    spec *= np.exp(-((fx**2 + fy**2) / (2 * 0.12**2)))
    img = np.real(np.fft.ifft2(spec))
    img = (img - img.min()) / (img.max() - img.min())
    return img.astype(np.float32)


def _shift(img: np.ndarray, d: float) -> np.ndarray:
    """right(x) = left(x + d): a fronto-parallel plane at disparity d (Fourier shift)."""
    w = img.shape[1]
    fx = np.fft.fftfreq(w)[None, :]
    out = np.real(np.fft.ifft(np.fft.fft(img, axis=1) * np.exp(2j * np.pi * fx * d), axis=1))
    return np.clip(out, 0.0, 1.0).astype(np.float32)


def _rect_calib(w: int, h: int, f: float = 500.0, baseline_mm: float = 100.0) -> Calibration:
    k = np.array([[f, 0, (w - 1) / 2], [0, f, (h - 1) / 2], [0, 0, 1]], np.float64)
    return Calibration(
        K1=k,
        D1=np.zeros(5),
        K2=k.copy(),
        D2=np.zeros(5),
        R=np.eye(3),
        T=np.array([-baseline_mm, 0.0, 0.0]),
        image_size=(w, h),
        unit="mm",
        rectified=True,
    )


def test_plane_gives_metric_depth_and_points() -> None:
    h, w, d = 96, 160, 6.5
    left = _texture(h, w)
    right = _shift(left, d)
    calib = _rect_calib(w, h)
    res = sv.depth_map(left, right, calib, max_disparity=16)
    core = res.disparity[10:-10, 20:-20]
    assert np.isfinite(core).mean() > 0.9
    assert abs(float(np.nanmedian(core)) - d) < 0.1
    z_expected = 500.0 * 0.1 / d  # metres
    assert res.depth is not None
    assert abs(float(np.nanmedian(res.depth)) - z_expected) / z_expected < 0.02
    # Points: left rectified camera frame, metres, X right, Y down, Z forward.
    assert res.points.dtype == np.float32 and res.points.shape[1] == 3
    assert (
        len(res.points) == len(res.colors) == len(res.pixels) == int(np.isfinite(res.depth).sum())
    )
    x, y = res.pixels[0]
    p = res.points[0]
    assert p[2] == pytest.approx(res.depth[y, x], rel=1e-5)
    assert p[0] == pytest.approx((x - (w - 1) / 2) * p[2] / 500.0, rel=1e-4, abs=1e-6)
    assert p[1] == pytest.approx((y - (h - 1) / 2) * p[2] / 500.0, rel=1e-4, abs=1e-6)


def test_depth_sigma_formula_on_a_plane() -> None:
    """sigma_Z = Z^2 sigma_d / (f B), sigma_d from the confidence (f 500 px, B 0.1 m)."""
    h, w, d = 96, 160, 6.5
    left = _texture(h, w)
    right = _shift(left, d)
    kw = {"method": "gabor", "max_disparity": 16}
    raw = sv.depth_map(left, right, _rect_calib(w, h), refine=False, **kw)
    res = sv.depth_map(left, right, _rect_calib(w, h), **kw)
    for r, refined in ((raw, False), (res, True)):
        assert r.depth is not None and r.depth_sigma is not None
        ok = np.isfinite(r.depth)
        assert np.array_equal(ok, np.isfinite(r.depth_sigma))
        filled = np.isnan(raw.disparity) & np.isfinite(r.disparity)
        sd = sv.depth.disparity_sigma(r.confidence, refined=refined, filled=filled)
        expected = r.depth**2 * sd / (500.0 * 0.1)
        np.testing.assert_allclose(r.depth_sigma[ok], expected[ok], rtol=1e-4)
    # The prediction is monotone in confidence: raw 0.74 px at 0, 0.22 px at 1; refined 0.405
    # at 0, 0.184 at 1; filled pixels 0.63 px.
    np.testing.assert_allclose(
        sv.depth.disparity_sigma([0.0, 0.5, 1.0, 2.0], refined=False),
        [0.74, 0.48, 0.22, 0.22],
        rtol=1e-6,
    )
    np.testing.assert_allclose(
        sv.depth.disparity_sigma([0.0, 1.0, 0.5], filled=[False, False, True]),
        [0.405, 0.184, 0.63],
        rtol=1e-5,
    )


def test_disparity_sigma_takes_a_single_bool_for_every_pixel() -> None:
    """``filled=True`` (every pixel filled) and ``filled=False`` gave the whole map's sigmas
    until the shape check of the mask refused them as of shape ``()``."""
    conf = np.array([[0.0, 1.0], [0.5, 0.25]], np.float32)
    for every in (True, np.True_, np.array(True)):
        np.testing.assert_array_equal(
            sv.depth.disparity_sigma(conf, filled=every), np.full((2, 2), 0.63, np.float32)
        )
    np.testing.assert_allclose(
        sv.depth.disparity_sigma(conf, filled=False), [[0.405, 0.184], [0.2945, 0.34975]]
    )


def test_disparity_sigma_takes_a_nan_confidence_as_the_depth_kernel_does() -> None:
    """disparity_sigma(NaN) was NaN, where depth_map's kernel counts a NaN confidence as 0:
    the documented formula and the depth sigma it explains disagreed on that pixel."""
    from stereovision.depth import _depth_rectified

    conf = np.array([[np.nan, 0.0, 0.5, 1.0]], np.float32)
    disp = np.full((1, 4), 10.0, np.float32)
    calib = _rect_calib(4, 1)
    for refined in (True, False):
        sd = sv.depth.disparity_sigma(conf, refined=refined)
        assert sd[0, 0] == sd[0, 1] == np.float32(0.405 if refined else 0.74)
        depth, depth_sigma = _depth_rectified(disp, conf, calib, refined, None)
        # sigma_Z = Z sigma_d / (d + doffs), from the kernel's own sigma_d
        np.testing.assert_allclose(depth_sigma * 10.0 / depth, sd, rtol=1e-5)
    assert float(sv.depth.disparity_sigma(np.nan)) == np.float32(0.405)


def test_disparity_sigma_reads_an_object_array_of_numbers() -> None:
    """``np.array(values, dtype=object)`` of numbers gave their sigmas until today's dtype
    check refused it; one holding None is still refused, as None is."""
    conf = np.array([[0.0, 1.0], [0.5, 0.25]], np.float32)
    np.testing.assert_array_equal(
        sv.depth.disparity_sigma(conf.astype(object)), sv.depth.disparity_sigma(conf)
    )
    with pytest.raises(ValueError, match=r"confidence: expected real numbers in .* object$"):
        sv.depth.disparity_sigma(np.array([0.5, None]))


def test_disparity_sigma_refuses_what_is_no_confidence_map() -> None:
    """None gave a NaN sigma and a complex map lost its imaginary part with NumPy's warning
    only; a ``filled`` mask of one row was spread over every row of the map (and another shape
    refused in NumPy's broadcasting words). Each is a ValueError naming the argument."""
    conf = np.array([[0.0, 1.0], [0.5, 0.25]], np.float32)
    for bad in (None, conf.astype(np.complex64), "0.5"):
        with pytest.raises(ValueError, match="confidence: expected real numbers in"):
            sv.depth.disparity_sigma(bad)  # type: ignore[arg-type]
    for mask in ([[True, False]], np.ones((3, 2), bool)):
        said = re.escape(str(np.shape(mask)))
        with pytest.raises(ValueError, match=rf"filled: expected .* \(2, 2\), got {said}$"):
            sv.depth.disparity_sigma(conf, filled=mask)
    # a whole mask, a bool or integer confidence, a scalar: as before
    np.testing.assert_allclose(
        sv.depth.disparity_sigma(conf, filled=[[True, False], [False, False]]),
        [[0.63, 0.184], [0.2945, 0.34975]],
        rtol=1e-5,
    )
    assert sv.depth.disparity_sigma(np.array([True]))[0] == pytest.approx(0.184)
    assert float(sv.depth.disparity_sigma(0)) == pytest.approx(0.405)


def test_disparity_sigma_refuses_a_refined_that_is_no_bool() -> None:
    """``refined`` is a switch, as depth_map's: ``"no"`` (true) gave the refined line's 0.405
    px at confidence 0, None (false) the raw one's 0.74, without a word."""
    for bad in ("no", None, 0, 1):
        with pytest.raises(TypeError, match=rf"^refined: expected True or False, got {bad!r}$"):
            sv.depth.disparity_sigma(0.0, refined=bad)  # type: ignore[arg-type]
    assert float(sv.depth.disparity_sigma(0.0, refined=np.False_)) == pytest.approx(0.74)


@cache
def _sigma_scene(path: Path, refine: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A GT scene's depth_map ``(disparity, confidence)`` and GT, computed once per module: the
    refine=True case needs the refine=False maps that its sibling case scores."""
    scene = load_scene(path)
    res = sv.depth_map(scene.left, scene.right, max_disparity=scene.max_disparity, refine=refine)
    return res.disparity, res.confidence, scene.gt


@pytest.mark.parametrize("refine", [True, False])
def test_depth_sigma_predicts_the_error(data_dir: Path, refine: bool) -> None:
    """The error in units of the predicted sigma is about standard normal in its core.

    Pooled over terrace, playground, cones and tsukuba (the model is a line fitted on all 17
    GT scenes; per scene the median of |t| runs from 0.31 on venus to 1.76 on KITTI, whose
    LiDAR GT is itself ~0.4 px off). Measured, refined (default): median |t| 0.61, 69 % within
    1 sigma, 88 % within 2; all 17 scenes pooled: 0.68, 64 %, 83 % (standard normal: 0.67,
    68 %, 95 %). As the channel comes (refine=False), its own line: 0.64, 67 %, 88 %.
    """
    ts = []
    for name in (
        "eth3d/terrace",
        "eth3d/playground",
        "middlebury2003/cones",
        "middlebury2001/tsukuba",
    ):
        disparity, confidence, gt = _sigma_scene(data_dir / name, refine)
        filled = None
        if refine:
            raw = _sigma_scene(data_dir / name, False)[0]
            filled = np.isnan(raw) & np.isfinite(disparity)
        sd = sv.depth.disparity_sigma(confidence, refined=refine, filled=filled)
        ok = np.isfinite(disparity) & np.isfinite(gt)
        ts.append(np.abs(disparity[ok] - gt[ok]) / sd[ok])
    t = np.concatenate(ts)
    assert 0.5 < float(np.median(t)) < 0.85
    assert 0.6 < float(np.mean(t <= 1)) < 0.8
    assert float(np.mean(t <= 2)) > 0.8


@pytest.fixture(scope="module")
def terrace_depth(data_dir: Path) -> tuple[Any, sv.DepthResult]:
    """ETH3D terrace (metric calib.txt, its range 32 px) and its default
    ``depth_map(left, right, calib, max_disparity=32)``: the same call for the three tests that
    read it (none changes it), computed once."""
    scene = load_scene(data_dir / "eth3d" / "terrace")
    assert scene.calib is not None and scene.max_disparity == 32
    return scene, sv.depth_map(scene.left, scene.right, scene.calib, max_disparity=32)


def test_points_equal_reproject_on_a_metric_scene(
    terrace_depth: tuple[Any, sv.DepthResult],
) -> None:
    """The cloud is Calibration.reproject (cv2.reprojectImageTo3D's maths) at the valid pixels."""
    scene, res = terrace_depth
    xyz = scene.calib.reproject(np.where(res.confidence > 0, res.disparity, np.nan))
    xs, ys = res.pixels[:, 0], res.pixels[:, 1]
    assert len(res.points) > 100000
    np.testing.assert_allclose(res.points, xyz[ys, xs], rtol=1e-6, atol=1e-7)
    # Depth is depth_from_disparity's at the measured pixels; colours are the left pixel's RGB.
    z = scene.calib.depth_from_disparity(np.where(res.confidence > 0, res.disparity, np.nan))
    assert res.depth is not None
    np.testing.assert_allclose(res.depth, z, rtol=1e-6, equal_nan=True)
    assert res.left_rectified is not None
    np.testing.assert_array_equal(res.colors, res.left_rectified[ys, xs][:, ::-1])


def test_without_calibration_no_depth() -> None:
    left = _texture(64, 96, seed=1)
    res = sv.depth_map(left, _shift(left, 3.0), max_disparity=16)
    assert res.depth is None and res.depth_sigma is None and res.points.shape == (0, 3)
    with pytest.raises(ValueError, match="calibration"):
        res.to_ply("unused.ply")


def test_textureless_pair_gives_nan_not_error() -> None:
    flat = np.full((48, 64), 0.5, np.float32)
    res = sv.depth_map(flat, flat, max_disparity=16)
    assert np.isnan(res.disparity).all()
    assert (res.confidence == 0).all()


def test_fill_flag_fills_but_keeps_depth_measured_only() -> None:
    left = _texture(64, 128, seed=2)
    right = _shift(left, 4.0)
    left[:, 60:70] = 0.5  # a textureless stripe: holes there
    right[:, 56:66] = 0.5
    calib = _rect_calib(128, 64)
    raw = sv.depth_map(left, right, calib, max_disparity=16)
    filled = sv.depth_map(left, right, calib, max_disparity=16, fill=True)
    assert np.isfinite(filled.disparity).sum() >= np.isfinite(raw.disparity).sum()
    assert filled.depth is not None and raw.depth is not None
    np.testing.assert_array_equal(np.isfinite(filled.depth), np.isfinite(raw.depth))
    # The fill is a stage of its own in the timings (the stream reports it).
    unfilled = sv.depth_map(left, right, calib, max_disparity=16, fill=False)
    assert filled.timings["fill"] > 0 and "fill" not in unfilled.timings
    assert list(filled.timings)[-2:] == ["fill", "triangulate"]


@pytest.mark.parametrize(
    ("scene", "orb_alone", "coarse_alone"),
    [
        ("kitti2015/000005_10", 96, 128),
        ("eth3d/playground", 16, 32),
        ("middlebury2001/venus", 32, 16),
    ],
)
def test_auto_max_disparity_covers_the_near_ground(
    data_dir: Path, scene: str, orb_alone: int, coarse_alone: int
) -> None:
    """The range covers the GT's 99.5th percentile where the ORB features alone fall short
    (KITTI's near road, playground's near ground: the shrunk SGBM's dense map sees them) and
    where the dense map alone would (venus: the shrunk SGBM reaches 12.5 px of 18.5)."""
    from stereovision.depth import _coarse_top, _orb_top

    s = load_scene(data_dir / scene)
    md = sv.estimate_max_disparity(s.left, s.right)
    top = float(np.percentile(s.gt[np.isfinite(s.gt)], 99.5))
    assert top <= md <= 2 * top + 16 and md % 16 == 0
    gl, gr = (np.asarray(as_gray_float(a) * 255, np.uint8) for a in (s.left, s.right))
    orb, coarse = _orb_top(gl, gr), _coarse_top(gl, gr)
    assert orb is not None and coarse is not None
    # Each estimate alone (1.15 x, rounded up to 16); the range takes the larger.
    alone = [int(np.ceil(1.15 * t / 16) * 16) for t in (orb, coarse)]
    assert alone == [orb_alone, coarse_alone]
    assert md == max(alone)


@pytest.mark.parametrize(
    ("shape", "expected"),
    [((1, 1), 16), ((1, 120), 16), ((120, 1), 16), ((62, 300), 48), ((2, 2), 16)],
)
def test_auto_max_disparity_on_images_too_small_for_features(
    shape: tuple[int, int], expected: int
) -> None:
    """A side under ORB's 63 px gives no features (a 1-px side made OpenCV's pyramid fail, a
    cv2.error out of ``depth_map``): the range falls back to width / 8 (at least 16; the shrunk
    SGBM needs 64 rows), and ``depth_map`` either runs or names the problem."""
    rng = np.random.default_rng(5)
    left = (rng.random(shape) * 255).astype(np.uint8)
    right = np.roll(left, -2, axis=1)
    assert sv.estimate_max_disparity(left, right) == expected
    if shape[1] > expected:
        assert sv.depth_map(left, right).disparity.shape == shape
    else:
        with pytest.raises(ValueError, match="too narrow for stereo matching"):
            sv.depth_map(left, right)


@pytest.mark.parametrize("width", [8, 16])
def test_too_narrow_images_are_named_not_a_range_never_given(width: int) -> None:
    """An image 16 px wide or narrower, no range given: the error is the image's width and the
    17 px the automatic range needs (it named "disparity range 16.0", a range the caller never
    gave); a range the caller gives that fits runs, one that does not is named."""
    rng = np.random.default_rng(5)
    left = (rng.random((12, width)) * 255).astype(np.uint8)
    right = np.roll(left, -1, axis=1)
    calib = sv.Calibration.ideal((width, 12), 90, 0.1)
    with pytest.raises(
        ValueError,
        match=rf"^image too narrow for stereo matching: {width} px wide, .* needs images at "
        rf"least 17 px wide; give a max_disparity below {width} to match it$",
    ):
        sv.depth_map(left, right, calib)
    res = sv.depth_map(left, right, calib, max_disparity=width // 2, method="census")
    assert res.disparity.shape == (12, width) and res.max_disparity == width // 2
    with pytest.raises(ValueError, match=rf"disparity range 40 is not smaller .* width {width}"):
        sv.depth_map(left, right, calib, max_disparity=40)


def test_swapped_pair_is_warned_about(data_dir: Path) -> None:
    """Swapped cameras are a classic set-up mistake: the range estimate's feature matches then
    have negative disparities, and it says so (given the right way round: no warning)."""
    import warnings

    s = load_scene(data_dir / "middlebury2003" / "cones")
    with pytest.warns(UserWarning, match=r"look swapped: 100% of the \d+ feature matches"):
        sv.estimate_max_disparity(s.right, s.left)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sv.estimate_max_disparity(s.left, s.right)


def test_swapped_warning_points_at_the_callers_line(data_dir: Path) -> None:
    """The swapped warning names the user's line, through ``depth_map`` and ``match`` as when
    ``estimate_max_disparity`` is called directly (a fixed stacklevel named a line of depth.py
    through ``depth_map``)."""
    import warnings

    s = load_scene(data_dir / "middlebury2003" / "cones")
    calls = (
        lambda: sv.estimate_max_disparity(s.right, s.left),
        lambda: sv.depth_map(s.right, s.left),
        lambda: sv.match(s.right, s.left, method="best"),
    )
    for call in calls:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            call()
        said = [w for w in caught if "look swapped" in str(w.message)]
        assert len(said) == 1
        assert said[0].filename == __file__, said[0].filename


def test_auto_max_disparity_on_real_scene(data_dir: Path) -> None:
    scene = load_scene(data_dir / "middlebury2003" / "cones")
    md = sv.estimate_max_disparity(scene.left, scene.right)
    gt_max = float(np.nanmax(scene.gt))
    # Covers the true range, and not absurdly more than it.
    assert gt_max <= md <= 2 * gt_max + 16
    assert md % 16 == 0


def test_real_scene_ply_round_trip(
    tmp_path: Path, terrace_depth: tuple[Any, sv.DepthResult]
) -> None:
    _, res = terrace_depth  # depth_map(calib, max_disparity=scene.max_disparity): 32 px
    path = res.to_ply(tmp_path / "cloud.ply")
    pts, cols = read_ply(path)
    np.testing.assert_array_equal(pts, res.points)
    np.testing.assert_array_equal(cols, res.colors)
    # Terrace is an outdoor scene a few metres away: metres, not millimetres.
    assert 1.0 < float(np.median(pts[:, 2])) < 30.0


@pytest.mark.parametrize(
    ("left", "right", "match"),
    [
        (np.zeros((10, 12)), np.zeros((10, 13)), "differ|mismatch|shape"),
        (np.zeros((0, 12)), np.zeros((0, 12)), "empty"),
        (np.zeros((10, 12, 2)), np.zeros((10, 12, 2)), "channel"),
        (np.full((10, 12), np.nan, np.float32), np.zeros((10, 12), np.float32), "NaN|finite"),
        (np.zeros((10, 12), complex), np.zeros((10, 12), complex), "dtype"),
    ],
)
def test_bad_images_raise_value_error(left: np.ndarray, right: np.ndarray, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        sv.depth_map(left, right, max_disparity=8)


def test_bad_arguments_raise_value_error() -> None:
    img = _texture(32, 48)
    with pytest.raises(ValueError, match="method"):
        sv.depth_map(img, img, method="nope", max_disparity=8)
    with pytest.raises(ValueError, match="max_disparity"):
        sv.depth_map(img, img, max_disparity=0)
    with pytest.raises(ValueError, match="width"):
        sv.depth_map(img, img, max_disparity=64)
    with pytest.raises(ValueError, match="calibration is for"):
        sv.depth_map(img, img, _rect_calib(100, 50), max_disparity=8)
    # the type first: "no" was true, True a disparity of 1, "8" a NumPy ufunc error
    for kw, says in (
        ({"fill": "no"}, "fill: expected True, False or None, got 'no'"),
        ({"refine": 1}, "refine: expected True, False or None, got 1"),
        ({"max_disparity": True}, "max_disparity: expected a number of pixels, got True"),
        ({"max_disparity": "8"}, "max_disparity: expected a number of pixels, got '8'"),
        ({"min_disparity": None}, "min_disparity: expected a number of pixels, got None"),
    ):
        with pytest.raises(TypeError, match=re.escape(says)):
            sv.depth_map(img, img, **{"max_disparity": 8, **kw})
    assert sv.depth_map(img, img, max_disparity=np.int64(8), fill=np.bool_(False)).max_disparity


def test_cloud_false_keeps_depth_and_to_ply_writes_the_full_cloud(
    terrace_depth: tuple[Any, sv.DepthResult], tmp_path: Path
) -> None:
    """depth_map(cloud=False) (live use) has the same depth and no per-frame cloud; to_ply
    still writes every point."""
    from stereovision.io import read_ply

    scene, full = terrace_depth
    lean = sv.depth_map(scene.left, scene.right, scene.calib, max_disparity=32, cloud=False)
    assert full.depth is not None and lean.depth is not None
    np.testing.assert_array_equal(lean.depth, full.depth)
    assert lean.points.shape == (0, 3) and lean.colors.shape == (0, 3)
    pts, cols = read_ply(lean.to_ply(tmp_path / "lean.ply"))
    assert len(full.points) > 100000
    np.testing.assert_array_equal(pts, full.points)
    np.testing.assert_array_equal(cols, full.colors)


def test_filtered_keeps_a_working_range_and_trusted_depths(data_dir: Path) -> None:
    """ETH3D terrace, metric: filtering by range and by uncertainty drops exactly the pixels
    outside the limits from depth, depth_sigma and the cloud; the disparity stays whole."""
    scene = load_scene(data_dir / "eth3d" / "terrace")
    res = sv.depth_map(scene.left, scene.right, scene.calib, method="gabor", max_disparity=32)
    assert res.depth is not None and res.depth_sigma is not None
    z = res.depth
    med = float(np.nanmedian(z))
    near = res.filtered(min_depth=1.0, max_depth=med)
    kept = np.isfinite(near.depth)
    with np.errstate(invalid="ignore"):
        np.testing.assert_array_equal(kept, np.isfinite(z) & (z >= 1.0) & (z <= med))
    assert 0.3 < kept.sum() / np.isfinite(z).sum() < 0.7
    np.testing.assert_array_equal(near.depth[kept], z[kept])
    np.testing.assert_array_equal(near.disparity, res.disparity)
    assert len(near.points) == kept.sum() and near.points[:, 2].max() <= med + 1e-5
    on = kept[res.pixels[:, 1], res.pixels[:, 0]]
    np.testing.assert_array_equal(near.points, res.points[on])
    np.testing.assert_array_equal(near.colors, res.colors[on])
    # the median sigma here is 0.13 m (3.0 % of the depth)
    sure = res.filtered(max_sigma=0.15, max_relative_sigma=0.03)
    ok = np.isfinite(sure.depth)
    assert 0.2 < ok.sum() / np.isfinite(z).sum() < 0.8
    assert (sure.depth_sigma[ok] <= 0.15).all()
    assert (sure.depth_sigma[ok] <= 0.03 * sure.depth[ok]).all()
    assert np.isnan(sure.depth_sigma[~ok]).all()
    assert np.isfinite(res.depth).sum() == np.isfinite(z).sum()  # the original is untouched
    for bad in ({"max_depth": -1.0}, {"max_sigma": 0.0}, {"min_depth": float("nan")}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            res.filtered(**bad)
    bare = sv.depth_map(scene.left, scene.right, None, method="gabor", max_disparity=32)
    with pytest.raises(ValueError, match="no depth to filter"):
        bare.filtered(max_depth=5.0)


def test_results_print_as_summaries() -> None:
    """At a prompt a DepthResult printed 3.5 kB of arrays; it and Matches now say what they
    hold in one line."""
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")  # with its calib.txt
    res = sv.depth_map(s.left, s.right, s.calib, method="fast", max_disparity=64)
    text = repr(res)
    assert text.startswith("DepthResult(method='fast'; 450x375; disparity [0, 64] px, 100.0 %")
    z = res.depth[np.isfinite(res.depth)]
    assert f"(median {np.median(z):.3g} m)" in text and f"; {len(res.points)} points;" in text
    assert len(text) < 250 and "\n" not in text
    assert "no calibration: no depth" in repr(sv.depth_map(s.left, s.right, method="fast"))
    m = sv.match(s.left, s.right, method="hopfield", max_disparity=64)
    assert repr(m).startswith(f"Matches({len(m)} matches in 450x375; disparity ")
    assert repr(sv.Matches(*(np.zeros(0),) * 5, image_shape=(4, 5))) == "Matches(0 matches in 5x4)"


def test_a_result_owns_its_arrays_and_a_filtered_copy_is_a_copy() -> None:
    """The result kept the caller's left image (a camera loop refilling its frame blackened
    the cloud written later), and filtered()'s 'copy' shared the disparity map."""
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    left = s.left.copy()
    res = sv.depth_map(left, s.right, s.calib, method="fast", cloud=False)
    assert not np.may_share_memory(res.left_rectified, left)
    kept = res.left_rectified.copy()
    left[:] = 0  # cap.read(left) for the next frame
    np.testing.assert_array_equal(res.left_rectified, kept)
    f = res.filtered(max_depth=3.0)
    f.disparity[0, 0] = -999.0
    assert res.disparity[0, 0] != -999.0
    with pytest.raises(ValueError, match=r"min_depth, max_depth: an empty range, 5 > 3 m"):
        res.filtered(min_depth=5, max_depth=3)


def _valid_named(text: str) -> set[str]:
    """The keys an unknown-parameter error names as valid ("expected one of a, b (where)")."""
    listed = text.split("expected one of ", 1)[1].split(" (", 1)[0]
    return set(listed.split(", "))


def test_an_unknown_matcher_parameter_names_what_the_method_takes() -> None:
    """The matchers' own checks named their own keys only: method="census" left out the dense
    map's second_confidence (which it takes), "fused" the dense map's options and semi_global
    while naming remeasure_gabor, dense_sgm and census_members, which depth_map sets itself:
    given, they failed as "fuse_pair() got multiple values for keyword argument"."""
    from stereovision.matching import fusion, gabor, sgm

    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    takes = {
        "census": {*sgm.DEFAULTS, "second_confidence", "speckle_area", "edge_jump"},
        "fast": {*sgm.DEFAULTS, "second_confidence", "edge_radius"},
        "fused": {*fusion.DEFAULTS, *fusion.DENSE_DEFAULTS, "semi_global", "channels"},
        "gabor": set(gabor.DEFAULTS),
    }
    for method, keys in takes.items():
        with pytest.raises(
            ValueError, match=r"^unknown \w+ (option|parameter)\(s\) \['bogus'\]"
        ) as e:
            sv.depth_map(img, img, max_disparity=8, method=method, bogus=1)
        named = _valid_named(str(e.value))
        assert keys <= named, (method, keys - named)
        assert not named & {"remeasure_gabor", "dense_sgm", "census_members", "min_disparity"}
    for key, says in (
        ("remeasure_gabor", "give refine= instead"),
        ("dense_sgm", "give semi_global= instead"),
        ("census_members", "its dense map is checked anyway"),
    ):
        with pytest.raises(
            ValueError, match=f"^{key}: depth_map sets this fuse_pair option itself \\({says}\\)$"
        ):
            sv.depth_map(img, img, max_disparity=8, **{key: False})
    # a switch: "no" ran the census map, None skipped it
    for bad in ("no", None, 0):
        with pytest.raises(TypeError, match=r"^semi_global: expected True or False, got "):
            sv.depth_map(img, img, max_disparity=8, semi_global=bad)


def test_fused_channels_without_the_gabor_channel_are_named() -> None:
    """depth_map(method="fused") takes fuse_pair's channels (c9f1031 named it), but its dense
    map is the Gabor map's: without "gabor" it failed as a bare KeyError 'gabor' after every
    channel had run, with no sparse one after them too, and "gabor,mcgm" was read letter by
    letter. Each is refused before the rectification; a tuple, list or array of names works.
    A one-pass iterator of names is read once, as fuse_pair reads it (its checks used it up
    before the run: refused, though fuse_pair took it)."""
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    right = np.roll(img, -3, axis=1)
    for bad in (("mcgm", "hopfield"), ("gabor",), "gabor,mcgm", ("gabor", "mcgm", "sgm"), [[1]]):
        stages: list[str] = []
        with pytest.raises(
            ValueError, match=r"^channels: depth_map\(method='fused'\) needs 'gabor'"
        ):
            sv.depth_map(img, right, max_disparity=8, channels=bad, progress=stages.append)
        assert stages == []
    want = sv.depth_map(img, right, max_disparity=8, channels=("gabor", "mcgm")).disparity
    assert np.isfinite(want).mean() > 0.9
    for good in (["gabor", "mcgm"], np.array(["gabor", "mcgm"]), iter(("gabor", "mcgm"))):
        got = sv.depth_map(img, right, max_disparity=8, channels=good).disparity
        np.testing.assert_array_equal(got, want)


def test_fused_channels_given_as_an_iterable_that_is_no_collection_are_taken() -> None:
    """10da932 read a one-pass iterator once, as fuse_pair does, but an iterable that is no
    iterator and no collection (an object with __iter__ only) was still refused ("needs
    'gabor'") though fuse_pair and match(method="fused") take it. It now gives the tuple's map."""

    class Names:
        def __iter__(self) -> Iterator[str]:
            return iter(("gabor", "mcgm"))

    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    right = np.roll(img, -3, axis=1)
    want = sv.depth_map(img, right, max_disparity=8, channels=("gabor", "mcgm")).disparity
    got = sv.depth_map(img, right, max_disparity=8, channels=Names()).disparity
    assert np.isfinite(want).mean() > 0.9
    np.testing.assert_array_equal(got, want)


def test_every_type_error_of_depth_map_is_documented() -> None:
    """depth_map raises TypeError for a switch that is no bool (semi_global's, new, refuses 1
    and 0), a range that is no number, a progress that is not callable and calibration=; its
    Raises section named ValueError and MemoryError only. Each argument is named there."""
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    doc = sv.depth_map.__doc__ or ""
    section = doc.split("    Raises\n", 1)[1].split("    Examples\n", 1)[0]
    assert "\n    TypeError\n" in section
    entry = " ".join(section.split("    TypeError\n", 1)[1].split("\n    MemoryError")[0].split())
    bad: dict[str, object] = {
        "fill": "no",
        "refine": 1,
        "return_channels": None,
        "cloud": "yes",
        "semi_global": 1,
        "check_members": "no",
        "edge_members": None,
        "max_disparity": "32",
        "min_disparity": True,
        "progress": 3,
        "calibration": None,
    }
    for name, value in bad.items():
        with pytest.raises(TypeError, match=name):
            sv.depth_map(img, img, **({"max_disparity": 8} | {name: value}))  # type: ignore[arg-type]
        assert f"``{name}" in entry, name


def test_pair_and_calibration_mistakes_are_named() -> None:
    """A grey and a colour image made a pair (match() refused it); calibration= failed as an
    unknown fusion option; a size error always suggested scaled_to, even for swapped sizes or
    another aspect ratio (scaled_to then stretches the intrinsics)."""
    import dataclasses

    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    grey = s.left[:, :, 0].copy()
    with pytest.raises(ValueError, match=r"same shape, got left \(375, 450\) and right \(375, "):
        sv.depth_map(grey, s.right, method="fast")
    with pytest.raises(TypeError, match="the calibration is the argument calib, not calibration"):
        sv.depth_map(s.left, s.right, calibration=s.calib)
    swapped = dataclasses.replace(s.calib, image_size=(375, 450))
    with pytest.raises(ValueError, match=r"450x375 \(width and height swapped\? image_size is"):
        sv.depth_map(s.left, s.right, swapped)
    other = dataclasses.replace(s.calib, image_size=(640, 480))
    with pytest.raises(ValueError, match=r"got 450x375 \(another aspect ratio: another camera"):
        sv.depth_map(s.left, s.right, other)
    half = dataclasses.replace(s.calib, image_size=(900, 750))
    with pytest.raises(ValueError, match=r"calib.scaled_to\(\(450, 375\)\)"):
        sv.depth_map(s.left, s.right, half)
    # match() checks the rig as depth_map does (one helper): its size error had no hint
    with pytest.raises(ValueError, match=r"450x375 \(width and height swapped\? image_size is"):
        sv.match(s.left, s.right, swapped, method="best")
    with pytest.raises(
        ValueError, match=r"Calibration \(or an UncalibratedRectification\), got dict"
    ):
        sv.match(s.left, s.right, {"K1": 1}, method="best")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^calib: got the path 'calib.yaml', not a calib"):
        sv.match(s.left, s.right, "calib.yaml", method="best")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("size", "said"),
    [
        ((450, 374), "1 row more"),  # a KITTI frame of 1242x376 against 1242x375
        ((450, 377), "2 rows fewer"),
        ((449, 376), "1 column more and 1 row fewer"),
    ],
)
def test_a_frame_padded_or_cropped_by_a_few_rows_is_not_said_resized(
    size: tuple[int, int], said: str
) -> None:
    """A frame a row or two off the calibration's size (KITTI's 1242x375 and 1242x376) was
    said "images resized, not cropped: calib.scaled_to(...)", a 0.3 % stretch of one axis:
    with one side unchanged (or one larger, one smaller) no resize made it."""
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    calib = dataclasses.replace(s.calib, image_size=size)
    with pytest.raises(
        ValueError,
        match=rf"^calibration is for {size[0]}x{size[1]} images, got 450x375 \(images cropped "
        rf"or padded, not resized \({said}\): crop or pad them to {size[0]}x{size[1]}",
    ):
        sv.depth_map(s.left, s.right, calib)


def test_a_whole_result_or_a_wrong_unit_is_named(tmp_path: Path) -> None:
    """A DepthResult passed where one of its arrays is meant failed deep inside ("float()
    argument must be ... not 'DepthResult'"); to_ply('x.pcd') wrote PLY bytes, a depth PNG named
    .jpg was PNG bytes, and a depth map in millimetres wrote an all-zero image silently; a
    12-bit image in uint16 reached the matchers as 0-16 grey levels without a word."""
    import warnings

    from stereovision import export
    from stereovision.evaluate import dense_metrics
    from stereovision.ground import fit_ground_plane

    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    res = sv.depth_map(s.left, s.right, s.calib, method="fast")
    with pytest.raises(TypeError, match=r"disparity: got a DepthResult; pass its array, result.d"):
        fit_ground_plane(res, s.calib)
    with pytest.raises(TypeError, match=r"disparity: got a DepthResult; pass its array, result.d"):
        dense_metrics(res, s.gt)
    with pytest.raises(TypeError, match=r"points: got a DepthResult; pass its array, result.poi"):
        export.voxel_downsample(res, 0.05)
    with pytest.raises(ValueError, match=r"cloud.pcd: to_ply writes a .ply file"):
        res.to_ply(tmp_path / "cloud.pcd")
    with pytest.raises(ValueError, match=r"d.jpg: a 16-bit depth image is written as .png"):
        export.write_depth_png(tmp_path / "d.jpg", res)
    assert not (tmp_path / "d.jpg").exists()
    with pytest.warns(UserWarning, match=r"depth: none of its \d+ values fits 1..65535 at scale"):
        export.write_depth_png(tmp_path / "mm.png", res.depth * 1000)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        export.write_depth_png(tmp_path / "m.png", res)
    twelve = s.left.astype(np.uint16) * 16  # a 12-bit camera's image
    with pytest.warns(UserWarning) as seen:
        sv.depth_map(twelve, s.right.astype(np.uint16) * 16, method="fast")
    texts = [str(w.message) for w in seen if "uint16 image whose largest value" in str(w.message)]
    assert {t.split(" image")[0] for t in texts} == {"left: uint16", "right: uint16"}, texts
    assert any("left: uint16 image whose largest value is 4080 (12" in str(w.message) for w in seen)
    from stereovision import render

    with pytest.raises(ValueError, match=r"max_side: expected at least 16 pixels, got 0"):
        render.render_result(res, max_side=0)  # was a ZeroDivisionError


def test_results_compare_by_identity() -> None:
    """``==`` on two results raised "truth value of an array is ambiguous", and a floor could
    not be hashed (a dict key, a set) although frozen."""
    import copy

    from stereovision.ground import fit_ground_plane

    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    res = sv.depth_map(s.left, s.right, s.calib, method="fast")
    assert res == res and res != copy.deepcopy(res)
    plane = fit_ground_plane(res.disparity, res.calibration, max_tilt_deg=80)
    assert plane is not None and {plane: 1}[plane] == 1 and plane != copy.deepcopy(plane)


def test_matches_select_and_triangulate() -> None:
    """Matches could not be sliced or filtered (``m[0:5]`` was a TypeError) nor turned into
    3-D points without raw pixels; the points equal the dense reprojection at those pixels."""
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    m = sv.match(s.left, s.right, method="hopfield", max_disparity=64)
    good = m[m.score > 0.95]
    assert isinstance(good, sv.Matches) and 0 < len(good) < len(m)
    assert (good.score > 0.95).all() and good.image_shape == m.image_shape
    assert len(m[0:5]) == 5 and m[3].xl[0] == m.xl[3] and len(m[-1]) == 1
    pts = good.to_points(s.calib)
    assert pts.shape == (len(good), 3) and pts.dtype == np.float32
    disp = np.full(s.left.shape[:2], np.nan, np.float32)
    xi, yi = np.rint(good.xl).astype(int), np.rint(good.yl).astype(int)
    on_pixel = (good.xl == xi) & (good.yl == yi)  # hopfield's points are pixel centres
    assert on_pixel.sum() > 0.9 * len(good)
    disp[yi[on_pixel], xi[on_pixel]] = (good.xl - good.xr)[on_pixel]
    ref = s.calib.reproject(disp)[yi[on_pixel], xi[on_pixel]]
    np.testing.assert_allclose(pts[on_pixel], ref, rtol=1e-5)
    np.testing.assert_allclose(good.to_points(s.calib, unit="mm"), pts * 1000, rtol=1e-5)
    with pytest.raises(TypeError, match=r"calib: expected a stereovision\.Calibration"):
        good.to_points(None)


def test_a_16_bit_raw_pair_is_matched_on_its_own_grey_levels(data_dir: Path) -> None:
    """A raw rig's calibration (or the homographies of one without) rectified a 16-bit pair's
    8-bit copy, and the matchers saw 8 bits of it: on a dark 13-bit exposure of ETH3D terrace
    bad-2.0 rose from 1.6 % (a rectified calibration) to 11.1 % (an identity raw rig)."""
    from stereovision.evaluate import dense_metrics
    from stereovision.uncalibrated import UncalibratedRectification

    s = load_scene(data_dir / "eth3d" / "terrace")
    dark = [(img.astype(np.uint16) * 257) // 8 for img in (s.left, s.right)]  # up to 8191
    h, w = s.left.shape[:2]
    raw = dataclasses.replace(_rect_calib(w, h), rectified=False)
    as_is = sv.depth_map(*dark, _rect_calib(w, h), method="fast", max_disparity=32)
    ident = np.eye(3)
    homographies = UncalibratedRectification(
        ident, ident, (w, h), (w, h), np.zeros((3, 3)), 100, 0.0, 0.0, (0.0, 20.0), 32,
        (0.0, 0.0), (1.0, 1.0),
    )  # fmt: skip
    for calib in (raw, homographies):
        res = sv.depth_map(*dark, calib, method="fast", max_disparity=32)
        np.testing.assert_array_equal(res.disparity, as_is.disparity)
    assert dense_metrics(as_is.disparity, s.gt).bad[2.0] < 2.5
    # match() rectified the 8-bit copy too: 3622 hopfield matches instead of 5744
    ref = sv.match(*dark, _rect_calib(w, h), method="hopfield", max_disparity=32)
    got = sv.match(*dark, raw, method="hopfield", max_disparity=32)
    assert len(got) == len(ref) > 500
    np.testing.assert_array_equal(got.to_array(), ref.to_array())


@pytest.mark.parametrize("rectified", [None, True, False])
def test_a_12_bit_pair_is_warned_about_once_per_image(rectified: bool | None) -> None:
    """A 12-bit pair in uint16 was warned about twice per image (the 8-bit copy's and the grey
    image's conversions each warned), and the warning said the matchers got about 4 bits of it
    while they read the float grey image, all 12; only its 8-bit copy keeps 4."""
    import warnings

    left = np.rint(_texture(48, 96) * 4095).astype(np.uint16)
    right = np.rint(_shift(_texture(48, 96), 4.0) * 4095).astype(np.uint16)
    calib = (
        None if rectified is None else dataclasses.replace(_rect_calib(96, 48), rectified=rectified)
    )
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        sv.depth_map(left, right, calib, method="fast", max_disparity=16)
    texts = [str(w.message) for w in seen if "uint16 image whose largest value" in str(w.message)]
    assert sorted(t.split(":")[0] for t in texts) == ["left", "right"], texts
    assert "the matchers read all its bits, but its 8-bit copy" in texts[0]
    assert "keeps about 4 bits of it" in texts[0] and "leaving the matchers" not in texts[0]


def test_a_fractional_range_is_reported_as_searched(tmp_path: Path) -> None:
    """``max_disparity=37.5`` was reported as 37 (``int()``), while the Gabor channel searched
    up to 37.5 (its map reaches past 37); the NPZ bundle kept the 37 too."""
    from stereovision.export import read_npz, write_npz

    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    res = sv.depth_map(s.left, s.right, s.calib, method="gabor", max_disparity=37.5)
    assert res.max_disparity == 37.5 and float(np.nanmax(res.disparity)) > 37.0
    assert "disparity [0, 37.5] px" in repr(res)
    assert float(read_npz(write_npz(tmp_path / "r.npz", res))["max_disparity"]) == 37.5
    whole = sv.depth_map(s.left, s.right, method="gabor", max_disparity=np.float64(32.0))
    assert type(whole.max_disparity) is int and whole.max_disparity == 32


@pytest.mark.parametrize(("method", "max_disparity"), [("fused", 37), ("gabor", 37.5)])
def test_the_map_stays_in_the_range_searched(method: str, max_disparity: float) -> None:
    """The fused map ran past a range set below the scene's (cones with 37: 13897 pixels up to
    38.6, from its Gabor input and the plane fills): values more than half a pixel out are
    holes (then filled), the map is clipped to the range."""
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    res = sv.depth_map(s.left, s.right, s.calib, method=method, max_disparity=max_disparity)
    d = res.disparity
    if method == "fused":
        assert np.isfinite(d).mean() > 0.99  # still dense: the holes were filled in range
    assert float(np.nanmin(d)) >= 0.0 and float(np.nanmax(d)) <= max_disparity
    assert float(np.nanmax(d)) > max_disparity - 0.5  # cones reaches 55 px: the top is hit


def test_a_fractional_range_reaches_the_next_whole_pixel_in_the_census_map() -> None:
    """max_disparity 37.5: the census semi-global map searches up to 38 (as DepthResult's
    max_disparity says), so the fast and fused maps reach 38 on cones (55 px at most), not
    37.5, while the result still reports the range given."""
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    for method in ("fast", "fused"):
        res = sv.depth_map(s.left, s.right, s.calib, method=method, max_disparity=37.5)
        assert res.max_disparity == 37.5
        assert float(np.nanmax(res.disparity)) == 38.0, method
        assert np.count_nonzero(res.disparity > 37.5) > 5000, method


def test_the_gabor_map_keeps_its_holes_by_default() -> None:
    """fill defaults to True for the dense methods only: the Gabor map as depth_map gives it
    keeps its holes (82 % of cones' pixels measured, none filled), as fill=False does."""
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    res = sv.depth_map(s.left, s.right, s.calib, method="gabor", max_disparity=64)
    assert 0.75 < res.density < 0.9
    assert res.depth_counts()["filled"] == 0
    unfilled = sv.depth_map(s.left, s.right, s.calib, method="gabor", max_disparity=64, fill=False)
    np.testing.assert_array_equal(res.disparity, unfilled.disparity)


def test_census_depth_sigma_is_one_value_as_documented() -> None:
    """The docs of ``depth_sigma`` did not say that ``"fast"`` and ``"census"`` without the
    re-measure give every pixel sigma_d 0.63 px (and 0.29 px with it): one confidence, 0.5."""
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    doc = " ".join((sv.DepthResult.__doc__ or "").split())
    for method, refine, want in (
        ("fast", None, 0.63),
        ("census", False, 0.63),
        ("census", None, 0.29),
    ):
        res = sv.depth_map(s.left, s.right, s.calib, method=method, refine=refine, max_disparity=64)
        assert res.depth is not None and res.depth_sigma is not None and res.calibration is not None
        ok = np.isfinite(res.depth)
        cal = res.calibration
        sigma_d = res.depth_sigma[ok] * cal.focal_px * cal.baseline_m / res.depth[ok] ** 2
        assert ok.sum() > 100_000 and np.allclose(sigma_d, want, atol=6e-3), (method, refine)
    assert "one ``sigma_d``: 0.29 px when re-measured" in doc
    assert '0.63 px, as filled pixels, when not (``"fast"``\'s default' in doc


@pytest.mark.parametrize("scene", ["middeval3/teddyH", "kitti2015/000005_10"])
def test_auto_max_disparity_of_a_10_bit_pair_in_16_bits(data_dir: Path, scene: str) -> None:
    """A 10-bit camera's pair in uint16 (at most 1023 of 65535) was cut to 8 bits for ORB's
    features as 0-3 grey levels: the automatic range came out 464 px on teddyH (112 from its
    8-bit pair) and 624 on KITTI (128). One gain for both images now gives the 8-bit pair's."""
    left = cv2.imread(str(data_dir / scene / "left.png"))
    right = cv2.imread(str(data_dir / scene / "right.png"))
    expected = sv.estimate_max_disparity(left, right)
    assert expected in (112, 128)
    got = sv.estimate_max_disparity(left.astype(np.uint16) * 4, right.astype(np.uint16) * 4)
    assert got == expected


def _known_depth_result(calib: Calibration | None) -> sv.DepthResult:
    """A result with hand-set depths (1 m, 2 m, none, 0.3048 m) and two points."""
    depth = np.array([[1.0, 2.0], [np.nan, 0.3048]], np.float32)
    return sv.DepthResult(
        disparity=np.ones((2, 2), np.float32),
        confidence=np.ones((2, 2), np.float32),
        depth=depth if calib is not None else None,
        points=np.array([[0.5, -1.0, 1.0], [0.0, 0.0, 0.3048]], np.float32),
        colors=np.zeros((2, 3), np.uint8),
        pixels=np.array([[0, 0], [1, 1]], np.int32),
        method="fused",
        max_disparity=16,
        calibration=calib,
        depth_sigma=depth / 10 if calib is not None else None,
    )


def test_depth_and_points_in_feet_and_other_units_against_hand_values() -> None:
    """1 m = 3.28084 ft = 1000 mm = 100 cm = 39.3701 in; the result itself stays in metres."""
    res = _known_depth_result(_rect_calib(2, 2))
    ft = res.depth_in("ft")
    np.testing.assert_allclose(ft, [[3.28084, 6.56168], [np.nan, 1.0]], rtol=1e-6)
    assert ft.dtype == np.float32 and ft is not res.depth
    np.testing.assert_allclose(res.depth_sigma_in("ft"), ft / 10, rtol=1e-6)
    np.testing.assert_allclose(
        res.points_in("ft"), [[1.64042, -3.28084, 3.28084], [0.0, 0.0, 1.0]], rtol=1e-6
    )
    np.testing.assert_allclose(res.depth_in("mm")[0], [1000.0, 2000.0], rtol=1e-6)
    np.testing.assert_allclose(res.depth_in("cm")[0], [100.0, 200.0], rtol=1e-6)
    np.testing.assert_allclose(res.depth_in("in")[0], [39.3701, 78.7402], rtol=1e-6)
    m = res.depth_in()  # metres: a copy, equal
    np.testing.assert_array_equal(m, res.depth)
    m[0, 0] = 5.0
    assert res.depth[0, 0] == 1.0 and res.points[0, 2] == 1.0  # the result is untouched


def test_depth_in_agrees_with_triangulations_unit() -> None:
    """One unit table: depth_map's depth in feet is depth_from_disparity(unit="ft")'s."""
    h, w = 64, 96
    left = _texture(h, w, seed=2)
    calib = _rect_calib(w, h)
    res = sv.depth_map(left, _shift(left, 5.0), calib, max_disparity=16)
    z = sv.triangulation.depth_from_disparity(res.disparity, calib, unit="ft")
    known = np.isfinite(res.require_depth())
    np.testing.assert_allclose(res.depth_in("ft")[known], z[known], rtol=1e-5)


def test_depth_in_an_unknown_unit_or_without_depth_is_named() -> None:
    res = _known_depth_result(_rect_calib(2, 2))
    for method in (res.depth_in, res.depth_sigma_in, res.points_in):
        with pytest.raises(ValueError, match=r"^unit: expected one of \['m', 'mm', 'cm', 'ft', "
                           r"'in'\], got 'feet'$"):  # fmt: skip
            method("feet")
        with pytest.raises(ValueError, match=r"^unit: expected one of"):
            method(None)  # type: ignore[arg-type]
    bare = _known_depth_result(None)
    for method, what in ((bare.depth_in, "depth"), (bare.depth_sigma_in, "depth uncertainty"),
                         (bare.points_in, "depth")):  # fmt: skip
        with pytest.raises(ValueError) as err:
            method("ft")
        assert str(err.value).startswith(f"no {what}: depth_map was called without a calibration")


def test_a_hand_made_result_whose_cloud_arrays_disagree_is_refused_up_front() -> None:
    """5 colours for 6 points were taken without a word, then filtered() failed in NumPy's
    words ("boolean index did not match indexed array along axis 0")."""
    good = _known_depth_result(_rect_calib(2, 2))
    with pytest.raises(ValueError) as err:
        dataclasses.replace(good, colors=np.zeros((1, 3), np.uint8))
    assert str(err.value) == (
        "points, colors, pixels: expected one row per point in each, got 2, 1 and 2 rows"
    )
    with pytest.raises(ValueError) as err:
        dataclasses.replace(good, pixels=np.zeros((2, 3), np.int32))
    assert str(err.value) == "pixels: expected an (N, 2) array, one row per point, got shape (2, 3)"
    assert len(good.filtered(max_depth=1.5).points) == 2  # agreeing arrays are taken as before


def test_a_hand_made_result_whose_maps_disagree_in_shape_is_refused_up_front() -> None:
    """A (3, 2) depth beside a (2, 2) disparity failed in depth_counts() and filtered() with
    NumPy's "operands could not be broadcast together", a 1-D disparity in repr()."""
    good = _known_depth_result(_rect_calib(2, 2))
    with pytest.raises(ValueError) as err:
        dataclasses.replace(good, depth=np.ones((3, 2), np.float32))
    assert str(err.value) == "depth: expected the disparity's shape (2, 2), got (3, 2)"
    with pytest.raises(ValueError) as err:
        dataclasses.replace(good, confidence=None)
    assert str(err.value) == "confidence: expected the disparity's shape (2, 2), got ()"
    with pytest.raises(ValueError) as err:
        dataclasses.replace(good, disparity=np.ones(4, np.float32))
    assert str(err.value) == "disparity: expected an (H, W) map, got shape (4,)"
    assert _known_depth_result(None).depth is None  # no depth, no depth_sigma: as before


def test_filtered_refuses_a_hand_made_result_whose_pixels_leave_the_map() -> None:
    """A point at x = -1 was kept or dropped by the map's last column without a word, one at
    y = 2 of a 2-row map was NumPy's "index 2 is out of bounds for axis 0 with size 2"."""
    good = _known_depth_result(_rect_calib(2, 2))
    cases = [([[0, 0], [-1, 1]], "x -1 to 0, y 0 to 1"), ([[0, 0], [1, 2]], "x 0 to 1, y 0 to 2")]
    for pixels, said in cases:
        bad = dataclasses.replace(good, pixels=np.array(pixels, np.int32))
        with pytest.raises(ValueError) as err:
            bad.filtered(max_depth=1.5)
        assert str(err.value) == f"pixels: each point's (x, y) must lie in the 2x2 map, got {said}"
    bad = dataclasses.replace(good, pixels=np.array([[0.0, 0.0], [1.0, 1.0]]))
    with pytest.raises(ValueError) as err:
        bad.filtered(max_depth=1.5)
    assert str(err.value) == "pixels: expected integer (x, y) pixels, got dtype float64"


def test_depth_counts_say_why_a_pixel_with_a_disparity_has_no_depth() -> None:
    """The demo's depth panel had holes on 16 % of the pixels where the disparity map had none,
    with no count or reason given: depth_counts() splits them into filled pixels (confidence 0,
    guesses) and measured ones dropped (within sigma_d of infinite depth, or outside the limits)."""
    nan = np.nan
    res = sv.DepthResult(
        disparity=np.array([[10, 10, 10], [nan, 0.2, 10]], np.float32),
        confidence=np.array([[0.5, 0, 0], [0, 0.5, 0.5]], np.float32),
        depth=np.array([[1, nan, nan], [nan, nan, 2]], np.float32),
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
        method="fused",
        max_disparity=16,
        calibration=_rect_calib(3, 2),
        depth_sigma=np.full((2, 3), 0.01, np.float32),
    )
    assert res.depth_counts() == {
        "pixels": 6,
        "disparity": 5,
        "depth": 2,
        "filled": 2,
        "dropped": 1,
    }
    near = res.filtered(max_depth=1.5)  # the 2 m pixel is measured, now outside the limits
    assert near.depth_counts() == {
        "pixels": 6,
        "disparity": 5,
        "depth": 1,
        "filled": 2,
        "dropped": 2,
    }
    with pytest.raises(ValueError, match="calibration"):
        dataclasses.replace(res, depth=None).depth_counts()


def test_the_demo_scenes_missing_depth_is_its_filled_pixels() -> None:
    """On the bundled scene every pixel with a disparity but no depth (16 % of them) is one the
    fill completed (not measured: depth_map(fill=False) has no disparity there); none is lost
    to the sigma rule, a range cut or the calibration."""
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    res = sv.depth_map(s.left, s.right, s.calib, max_disparity=64, cloud=False)
    raw = sv.depth_map(s.left, s.right, s.calib, max_disparity=64, cloud=False, fill=False)
    c = res.depth_counts()
    unmeasured = int((~np.isfinite(raw.disparity)).sum())
    assert c["disparity"] == c["pixels"] == 450 * 375
    assert c["filled"] == unmeasured and 0.1 < unmeasured / c["pixels"] < 0.25
    assert c["dropped"] == 0 and c["depth"] == c["pixels"] - unmeasured


@pytest.mark.parametrize(
    ("key", "value", "says"),
    [
        ("return_channels", "no", "return_channels: expected True or False, got 'no'"),
        ("return_channels", 1, "return_channels: expected True or False, got 1"),
        ("cloud", None, "cloud: expected True or False, got None"),
        ("cloud", "x", "cloud: expected True or False, got 'x'"),
        ("progress", 3, "progress: expected a callable taking a stage name, or None, got 3"),
    ],
)
def test_output_switches_and_callback_are_checked(key: str, value: object, says: str) -> None:
    # "no" returned the channels and None dropped the cloud without a word; progress=3 failed
    # after the rectification with "'int' object is not callable"
    rng = np.random.default_rng(0)
    left = rng.random((40, 60), dtype=np.float32)
    with pytest.raises(TypeError, match=re.escape(says)):
        sv.depth_map(
            left, np.roll(left, -3, axis=1), method="gabor", max_disparity=8, **{key: value}
        )


@pytest.mark.parametrize("key", ["min_depth", "max_depth", "max_sigma", "max_relative_sigma"])
def test_filtered_limits_beyond_64_bits(key: str) -> None:
    # np.isfinite(2**70) was NumPy's TypeError "ufunc 'isfinite' not supported for the input
    # types", naming no limit; 2**70 is a limit as 1e300 is, 10**400 beyond a float is refused
    rng = np.random.default_rng(0)
    left = rng.random((40, 60), dtype=np.float32)
    calib = Calibration.ideal((60, 40), 60.0, 0.1)
    res = sv.depth_map(left, np.roll(left, -3, axis=1), calib, method="gabor", max_disparity=8)

    def kept(**limit: float) -> int:
        return int(np.isfinite(res.filtered(**limit).depth_in("m")).sum())

    want = 0 if key == "min_depth" else kept()  # nothing is that far; everything that close
    assert kept(**{key: 2**70}) == kept(**{key: 1e300}) == want
    assert kept() > 1000
    with pytest.raises(
        ValueError,
        match=f"^{key}: expected a positive number, got an integer of 401 digits "
        r"\(too large for a float\)$",
    ):
        res.filtered(**{key: 10**400})


@pytest.mark.parametrize("filled", ["no", None, 1])
def test_point_image_filled_must_be_a_switch(filled: object) -> None:
    # "no" (true) gave the filled pixels and None (false) left them out without a word
    rng = np.random.default_rng(0)
    left = rng.random((40, 60), dtype=np.float32)
    calib = Calibration.ideal((60, 40), 60.0, 0.1)
    res = sv.depth_map(left, np.roll(left, -3, axis=1), calib, method="gabor", max_disparity=8)
    assert res.point_image(filled=np.bool_(True)).shape == (40, 60, 3)
    with pytest.raises(
        TypeError, match=re.escape(f"filled: expected True or False, got {filled!r}")
    ):
        res.point_image(filled=filled)  # type: ignore[arg-type]


def test_point_image_is_the_cloud_where_a_value_past_the_range_was_kept() -> None:
    """A measured disparity up to half a pixel past ``max_disparity`` keeps its value for the
    depth and the cloud, while ``disparity`` is clipped to the range. ``point_image`` rebuilt
    its points from the clipped map: on a plane at 16.3 px searched up to 16 px, the fused
    map's Z was up to 3 % farther than ``depth`` and ``points`` on 13,272 of 13,755 pixels
    (and a ``cloud=False`` result's organised PCD with it)."""
    h, w = 96, 160
    left = _texture(h, w)
    res = sv.depth_map(left, _shift(left, 16.3), _rect_calib(w, h), max_disparity=16)
    depth = res.require_depth()
    has = np.isfinite(depth)
    assert has.sum() > 10_000 and np.nanmax(res.disparity) == 16
    # the case itself: depths of values measured past 16 px (f B = 50 px m)
    assert (50.0 / depth[has] > 16.2).sum() > 10_000
    pts = res.point_image()
    np.testing.assert_array_equal(pts[..., 2][has], depth[has])
    assert np.isnan(pts[~has]).all()
    x, y = res.pixels[:, 0], res.pixels[:, 1]
    np.testing.assert_array_equal(pts[y, x], res.points)


@pytest.mark.parametrize("method", ["fused", "gabor"])
def test_a_map_measured_past_the_range_is_not_warned_of_as_fixed_point(method: str) -> None:
    """refine_disparity's warning of a caller's map mostly above the range ("fixed-point
    values? ... divide by 16") fired inside depth_map, on its own matcher's map of a plane at
    16.3 px searched up to 16 px (13291 of 13419 values above): words about OpenCV's int16 maps
    to a caller who gave none. depth_map's refinements do not say it."""
    h, w = 96, 160
    left = _texture(h, w)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = sv.depth_map(
            left, _shift(left, 16.3), _rect_calib(w, h), max_disparity=16, method=method
        )
    # the fused map measures the plane; Gabor's bands, all past 16 px, keep none of it
    assert np.isfinite(res.disparity).mean() > (0.5 if method == "fused" else -1)


@pytest.mark.parametrize("min_disparity", [0, 5])
def test_one_px_wide_pair_is_told_the_width_it_needs_not_an_impossible_range(
    min_disparity: int,
) -> None:
    """A 1 px wide pair, no range given: no max_disparity can match it (a range of a whole pixel
    needs 2 px), so the error names the widths needed, not "a max_disparity below 1" (or below
    ``min_disparity + 1``), which no range of a pixel or more fits."""
    rng = np.random.default_rng(5)
    left = (rng.random((12, 1)) * 255).astype(np.uint8)
    with pytest.raises(
        ValueError,
        match=r"^image too narrow for stereo matching: 1 px wide, and the automatic disparity "
        r"range \((at least 16 px|5 to 16 px: 11 px, its max_disparity at least 16)\) needs "
        r"images at least 1[27] px wide; a max_disparity of your own needs images at least 2 px "
        r"wide$",
    ):
        sv.depth_map(left, left.copy(), min_disparity=min_disparity)


@pytest.mark.parametrize(
    ("width", "max_disparity", "min_disparity", "says"),
    [
        (1, 1, 0, "1: it needs images at least 2 px wide (a range of a pixel or more needs 2 px)"),
        (3, 4, 0, "3: it needs images at least 5 px wide, or give a max_disparity below 3"),
        (8, 16.5, 2, "8: it needs images at least 15 px wide, or give a max_disparity below 10"),
    ],
)
def test_a_range_given_wider_than_the_pair_names_the_width_it_needs(
    width: int, max_disparity: float, min_disparity: int, says: str
) -> None:
    """A range the caller gave that is not below the width: the error said only that ("disparity
    range 4 is not smaller than the image width 3"), not the width the range needs nor the
    max_disparity this pair takes."""
    rng = np.random.default_rng(5)
    left = (rng.random((12, width)) * 255).astype(np.uint8)
    span = max_disparity - min_disparity
    with pytest.raises(
        ValueError,
        match="^"
        + re.escape(f"disparity range {span:g} is not smaller than the image width {says}")
        + "$",
    ):
        sv.depth_map(left, left.copy(), max_disparity=max_disparity, min_disparity=min_disparity)


def test_too_narrow_with_a_min_disparity_names_the_range_it_searched() -> None:
    """With a min_disparity the automatic range is shorter than its max_disparity (at least 16):
    the error said "(at least 16 px) needs images at least 12 px wide"; it names the range's
    ends and length, whose width is the one needed."""
    rng = np.random.default_rng(5)
    left = (rng.random((12, 8)) * 255).astype(np.uint8)
    with pytest.raises(ValueError) as err:
        sv.depth_map(left, left.copy(), min_disparity=5)
    assert str(err.value) == (
        "image too narrow for stereo matching: 8 px wide, and the automatic disparity range "
        "(5 to 16 px: 11 px, its max_disparity at least 16) needs images at least 12 px wide; "
        "give a max_disparity below 13 to match it"
    )


def test_min_disparity_above_the_automatic_range_names_the_estimate() -> None:
    """A min_disparity not below the estimated max_disparity was refused as "max_disparity (16)
    must be larger than min_disparity (20)", a max_disparity the caller never gave; the error
    says it is the estimate's, and what to give; a max_disparity given runs."""
    rng = np.random.default_rng(5)
    left = (rng.random((32, 64)) * 255).astype(np.uint8)
    right = np.roll(left, -2, axis=1)
    assert sv.estimate_max_disparity(left, right) == 16
    with pytest.raises(ValueError) as err:
        sv.depth_map(left, right, min_disparity=20)
    assert str(err.value) == (
        "min_disparity (20) is not below the automatic max_disparity (16, estimated from the "
        "pair): give a max_disparity above 20"
    )
    res = sv.depth_map(left, right, min_disparity=20, max_disparity=24, method="census")
    assert res.disparity.shape == (32, 64)


@pytest.mark.parametrize("method", ["hopfield", "best", "mcgm", "fused", "gabor"])
def test_match_min_disparity_above_the_automatic_range_names_the_estimate(method: str) -> None:
    """match(min_disparity=20) with no max_disparity was refused in the matchers' own words,
    "max_disparity (16) must be >= min_disparity (20)" (hopfield, best, mcgm) or "empty
    disparity range: max_disparity (16) must be larger than min_disparity (20)" (fused,
    gabor), a max_disparity the caller never gave; it is now depth_map's error."""
    rng = np.random.default_rng(5)
    left = (rng.random((32, 64)) * 255).astype(np.uint8)
    right = np.roll(left, -2, axis=1)
    assert sv.estimate_max_disparity(left, right) == 16
    with pytest.raises(ValueError) as err:
        sv.match(left, right, method=method, min_disparity=20)
    assert str(err.value) == (
        "min_disparity (20) is not below the automatic max_disparity (16, estimated from the "
        "pair): give a max_disparity above 20"
    )
    if method in ("gabor", "fused"):  # they search no single level: at the estimate too
        with pytest.raises(ValueError, match=r"^min_disparity \(16\) is not below the auto"):
            sv.match(left, right, method=method, min_disparity=16)
    else:  # a one-level search at the estimate, as before
        got = sv.match(left, right, method=method, min_disparity=16)
        assert np.all(got.xl - got.xr == 16)


@pytest.mark.parametrize("method", sv.depth.METHODS)
@pytest.mark.parametrize(
    ("min_disparity", "max_disparity", "shown"),
    [(48, 64, "48"), (100, 116, "100"), (3e10, 3e10 + 16, "30000000000")],
)
def test_a_min_disparity_not_below_the_width_is_refused(
    method: str, min_disparity: float, max_disparity: float, shown: str
) -> None:
    """No pixel of a 48 px wide pair has a match 48 px or more to its left: such a range returned
    an all-NaN map without a word, or for 3e10 (float32 rounds 3e10 + 16 to 3e10) the kernel's
    "invalid parameter `d_max`: must be > d_min"; the error names min_disparity, the width and
    what works."""
    rng = np.random.default_rng(0)
    left = rng.integers(0, 256, (24, 48), dtype=np.uint8)
    with pytest.raises(ValueError) as err:
        sv.depth_map(
            left,
            left.copy(),
            method=method,
            min_disparity=min_disparity,
            max_disparity=max_disparity,
        )
    assert str(err.value) == (
        f"min_disparity ({shown}) is not below the image width 48: no pixel has a match that far "
        "to its left in the right image; give a min_disparity below 48"
    )


def test_a_max_disparity_not_above_minus_the_width_is_refused() -> None:
    """The Gabor map searches negative disparities too: a range at minus the width or below
    (-100 to -84 on a 48 px wide pair) returned an all-NaN map without a word."""
    rng = np.random.default_rng(0)
    left = rng.integers(0, 256, (24, 48), dtype=np.uint8)
    with pytest.raises(ValueError) as err:
        sv.depth_map(left, left.copy(), method="gabor", min_disparity=-100, max_disparity=-84)
    assert str(err.value) == (
        "max_disparity (-84) is not above minus the image width (-48): no pixel has a match that "
        "far to its right in the right image; give a max_disparity above -48"
    )


def test_a_range_just_below_the_width_still_runs() -> None:
    """min_disparity 47 on a 48 px wide pair is a range a pixel can match in: not refused (the
    pair, l == r, has none there, so the map is NaN)."""
    rng = np.random.default_rng(0)
    left = rng.integers(0, 256, (24, 48), dtype=np.uint8)
    res = sv.depth_map(left, left.copy(), method="gabor", min_disparity=47, max_disparity=63)
    assert res.disparity.shape == (24, 48)
    assert res.min_disparity == 47.0


def test_range_errors_show_every_digit_of_a_whole_number() -> None:
    """``:g`` printed -3e10 + 48 as "-3e+10" (and the range 3e10 + 10 as "3e+10"): the max_disparity
    to give was not the number it names."""
    rng = np.random.default_rng(0)
    left = rng.integers(0, 256, (24, 48), dtype=np.uint8)
    with pytest.raises(ValueError) as err:
        sv.depth_map(left, left.copy(), method="gabor", min_disparity=-3e10, max_disparity=10)
    assert str(err.value) == (
        "disparity range 30000000010 is not smaller than the image width 48: it needs images at "
        "least 30000000011 px wide, or give a max_disparity below -29999999952"
    )


def test_a_min_disparity_not_below_the_width_with_the_automatic_range_says_so() -> None:
    """With no max_disparity, min_disparity 100 on a 48 px wide pair was told "give a
    max_disparity above 100", which only led to the refusal of a min_disparity no pixel reaches:
    the error says that at once."""
    left = np.random.default_rng(0).integers(0, 256, (24, 48), dtype=np.uint8)
    with pytest.raises(ValueError) as err:
        sv.depth_map(left, left.copy(), min_disparity=100)
    assert str(err.value) == (
        "min_disparity (100) is not below the image width 48: no pixel has a match that far to "
        "its left in the right image; give a min_disparity below 48"
    )


def _hand_result() -> sv.DepthResult:
    """A 2x3 result built by hand (f B = 50 m px): depth 5, 2 and 1 m measured, a filled pixel
    (confidence 0, 2.5 m as a guess), a dropped one (confidence 0.2) and a hole."""
    nan = np.nan
    disp = np.array([[10, 20, 25], [nan, 50, 5]], np.float32)
    return sv.DepthResult(
        disparity=disp,
        confidence=np.array([[0.5, 0, 0.5], [0, 0.5, 0.2]], np.float32),
        depth=np.array([[5, nan, 2], [nan, 1, nan]], np.float32),
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
        method="fused",
        max_disparity=64,
        calibration=_rect_calib(3, 2),
        depth_sigma=np.array([[0.5, nan, 0.1], [nan, 0.05, nan]], np.float32),
    )


def _kept(depth: np.ndarray) -> list[float]:
    return sorted(float(z) for z in depth[np.isfinite(depth)])


def _wider_than_its_images() -> pytest.WarningsRecorder:
    """The warning of point_image(filled=True)'s guesses on :func:`_hand_result`: its map (up to
    50 px) is wider than its calibration's 3 px images (it was a stray warning of the run)."""
    return pytest.warns(
        UserWarning, match=r"^disparity: values up to 50 px, wider than the calibration's images"
    )


def test_a_hand_made_result_counts_filters_and_converts_by_hand_values(tmp_path: Path) -> None:
    r = _hand_result()
    counts = r.depth_counts()
    assert counts == {"pixels": 6, "disparity": 5, "depth": 3, "filled": 1, "dropped": 1}
    # the limits are inclusive
    assert _kept(r.filtered(min_depth=2).require_depth()) == [2, 5]
    assert _kept(r.filtered(max_depth=5).require_depth()) == [1, 2, 5]
    assert _kept(r.filtered(min_depth=2, max_depth=2).require_depth()) == [2]
    assert _kept(r.filtered(max_sigma=0.1).require_depth()) == [1, 2]
    # relative: sigma <= 0.06 z keeps 0.1 at 2 m and 0.05 at 1 m, not 0.5 at 5 m
    assert _kept(r.filtered(max_relative_sigma=0.06).require_depth()) == [1, 2]
    with pytest.raises(ValueError, match="max_depth: expected a positive number, got 0"):
        r.filtered(max_depth=0)
    # filtering twice keeps the tighter of each limit
    twice = r.filtered(min_depth=1, max_depth=5).filtered(min_depth=2, max_depth=10)
    assert twice.limits == {"min_depth": 2.0, "max_depth": 5.0}
    # point_image: measured pixels; with filled=True also the guess, inside the range (inclusive)
    # and never under a sigma limit (a guess has none); max_depth=5 leaves the dropped pixel out
    z = r.point_image()[..., 2]
    assert _kept(z) == [1, 2, 5]
    with _wider_than_its_images() as said:
        assert _kept(r.filtered(max_depth=5).point_image(filled=True)[..., 2]) == [1, 2, 2.5, 5]
    assert said[0].filename == __file__  # the caller's line, not depth.py's
    near = r.filtered(min_depth=2.5, max_depth=5)
    with _wider_than_its_images():
        assert _kept(near.point_image(filled=True)[..., 2]) == [2.5, 5]
    trusted = r.filtered(max_depth=5, max_relative_sigma=1.0)
    assert _kept(trusted.point_image(filled=True)[..., 2]) == [1, 2, 5]
    with pytest.raises(ValueError, match="unit: expected one of"):
        r.depth_in(["m"])  # type: ignore[arg-type]
    no_sigma = dataclasses.replace(r, depth_sigma=None)
    with pytest.raises(ValueError, match="no depth uncertainty"):
        no_sigma.require_depth_sigma()
    pts, cols = read_ply(r.to_ply(tmp_path / "cloud.PLY"))
    # no cloud and no left image: the depth map's points, black
    assert pts.shape == (3, 3) and cols.shape == (3, 3) and not cols.any()


def test_a_min_depth_of_0_is_a_limit_and_the_filled_guess_obeys_max_depth() -> None:
    """min_depth 0 (the only limit that may be 0) keeps every depth and is recorded; the filled
    pixel's guess (2.5 m) is left out of point_image(filled=True) beyond max_depth 2 m as a
    measured depth (5 m) is."""
    r = _hand_result()
    zero = r.filtered(min_depth=0)
    assert zero.limits == {"min_depth": 0.0}
    assert _kept(zero.require_depth()) == [1, 2, 5]
    with pytest.raises(ValueError, match="max_sigma: expected a positive number, got 0"):
        r.filtered(max_sigma=0)
    near = r.filtered(max_depth=2)
    assert _kept(near.require_depth()) == [1, 2]
    with _wider_than_its_images():
        assert _kept(near.point_image(filled=True)[..., 2]) == [1, 2]
        assert _kept(r.filtered(max_depth=2.5).point_image(filled=True)[..., 2]) == [1, 2, 2.5]


@pytest.mark.parametrize(
    ("first", "then", "said"),
    [
        ({"max_depth": 2.5}, {"min_depth": 3}, "3 > 2.5 m (max_depth from an earlier filtered())"),
        (
            {"max_depth": 2.5},
            {"min_depth": 3, "max_depth": 10},
            "3 > 2.5 m (max_depth from an earlier filtered())",
        ),
        ({"min_depth": 3}, {"max_depth": 2}, "3 > 2 m (min_depth from an earlier filtered())"),
        ({"max_depth": 5}, {"min_depth": 3, "max_depth": 2}, "3 > 2 m"),
    ],
)
def test_chained_filtered_calls_refuse_an_empty_range_as_one_call_does(
    first: dict[str, float], then: dict[str, float], said: str
) -> None:
    """``filtered(max_depth=2.5).filtered(min_depth=3)`` was silently empty (limits min 3, max
    2.5) where ``filtered(min_depth=3, max_depth=2.5)`` is refused: the chain is refused too,
    naming the limit of the earlier call; a range of one depth is still a range."""
    r = _hand_result()
    with pytest.raises(ValueError) as err:
        r.filtered(**first).filtered(**then)
    assert str(err.value) == f"min_depth, max_depth: an empty range, {said}"
    one = r.filtered(max_depth=2).filtered(min_depth=2)
    assert one.limits == {"max_depth": 2.0, "min_depth": 2.0}
    assert _kept(one.require_depth()) == [2]


def test_a_hand_made_result_prints_its_depth_range_and_counts_a_zero_confidence_depth() -> None:
    """The summary gives the depth range lowest first (1-5 m, median 2 m, on 3 of 6 pixels);
    a measured pixel with confidence 0 that has a depth is not "filled": the counts still add
    up, disparity == depth + filled + dropped."""
    r = _hand_result()
    assert "; depth 1-5 m (median 2 m) on 50.0 %; 0 points" in repr(r)
    conf = r.confidence.copy()
    conf[0, 0] = 0  # the 5 m pixel: measured, a depth, confidence 0
    counts = dataclasses.replace(r, confidence=conf).depth_counts()
    assert counts == {"pixels": 6, "disparity": 5, "depth": 3, "filled": 1, "dropped": 1}


def test_a_result_prints_depths_past_999_5_m_in_whole_metres() -> None:
    """``.3g`` said a depth of 2000 m as "2e+03 m"; past 999.5 it is whole metres, as the CLI's
    ``depth`` summary and the overview's labels say it (below, three digits as before)."""
    r = _hand_result()
    far = dataclasses.replace(r, depth=r.depth * np.float32(400))  # 400, 800 and 2000 m
    assert "; depth 400-2000 m (median 800 m) on 50.0 %; 0 points" in repr(far)
    near = dataclasses.replace(r, depth=r.depth * np.float32(199.9))  # 999.5 m: whole
    assert "; depth 200-1000 m (median 400 m) on 50.0 %" in repr(near)


def test_depth_uses_doffs_and_points_use_fx_and_fy_and_rgb_colours() -> None:
    h, w, d = 96, 160, 6.5
    tex = _texture(h, w)
    left = np.dstack([tex, 0.5 * tex, 0.2 * tex])  # BGR, channels apart
    right = np.dstack([_shift(tex, d), 0.5 * _shift(tex, d), 0.2 * _shift(tex, d)])
    k1 = np.array([[500, 0, 79.5], [0, 600, 47.5], [0, 0, 1]], np.float64)
    k2 = k1.copy()
    k2[0, 2] = 82.5  # doffs = 3 px
    calib = Calibration(
        K1=k1, D1=np.zeros(5), K2=k2, D2=np.zeros(5), R=np.eye(3),
        T=np.array([-100.0, 0.0, 0.0]), image_size=(w, h), unit="mm", rectified=True,
    )  # fmt: skip
    assert calib.doffs_px == 3.0
    res = sv.depth_map(left, right, calib, max_disparity=16, min_disparity=0)
    ok = np.isfinite(res.require_depth())
    assert ok.mean() > 0.5
    np.testing.assert_allclose(res.depth[ok], 50.0 / (res.disparity[ok] + 3.0), rtol=1e-5)
    x, y = res.pixels[:, 0], res.pixels[:, 1]
    z = res.points[:, 2]
    np.testing.assert_allclose(res.points[:, 0], (x - 79.5) / 500 * z, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(res.points[:, 1], (y - 47.5) / 600 * z, rtol=1e-5, atol=1e-6)
    bgr = res.left_rectified
    assert bgr is not None
    np.testing.assert_array_equal(res.colors, bgr[y, x][:, ::-1])


def test_an_empty_or_unreachable_range_given_is_named() -> None:
    left = _texture(32, 64)
    with pytest.raises(ValueError, match=r"max_disparity \(16\) must be larger than min_disparity"):
        sv.depth_map(left, left, max_disparity=16, min_disparity=16)
    with pytest.raises(ValueError, match=r"max_disparity \(-64\) is not above minus the image"):
        sv.depth_map(left, left, max_disparity=-64, min_disparity=-80)


def test_a_negative_min_disparity_with_the_fused_method_names_the_methods_that_take_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The fused map's graph-matching and Hopfield channels search from 0 px: depth_map's
    default method refused min_disparity=-2 in their words ("min_disparity must be a
    non-negative number of pixels, got -2.0"), naming neither the method nor those that take
    it, which its docstring did not say either."""
    h, w = 64, 96
    left = _texture(h, w)
    right = _shift(left, 6.3)
    with pytest.raises(
        ValueError,
        match=r"^min_disparity: method='fused' searches from 0 px .*, got -2; method='gabor', "
        r"'census' or 'fast' search a negative range$",
    ):
        sv.depth_map(left, right, max_disparity=16, min_disparity=-2)
    # refused before the images' work: it came after the automatic range's estimate (1.4 s of
    # a 3600 x 3000 pair) and the rectification
    import stereovision.depth as depth_mod

    def estimated(*_: object) -> float:
        raise AssertionError("the range was estimated before the refusal")

    with monkeypatch.context() as m:
        m.setattr(depth_mod, "estimate_max_disparity", estimated)
        with pytest.raises(ValueError, match=r"^min_disparity: method='fused' searches from 0"):
            sv.depth_map(left, right, min_disparity=-2)
        # NaN, too, is refused in its own words before that work
        with pytest.raises(ValueError, match=r"^min_disparity"):
            sv.depth_map(left, right, min_disparity=float("nan"))
    for method in ("gabor", "census", "fast"):
        res = sv.depth_map(left, right, method=method, max_disparity=16, min_disparity=-2)
        assert res.min_disparity == -2
        assert abs(float(np.nanmedian(res.disparity)) - 6.3) < 0.3


def test_match_names_the_method_that_takes_a_negative_min_disparity_as_depth_map_does(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """match(method='mcgm'|'hopfield'|'best'|'fused', min_disparity=-2) said "min_disparity
    must be a non-negative number of pixels, got -2", naming neither the method nor 'gabor',
    the one that takes it; depth_map says both."""
    import importlib

    match_mod = importlib.import_module("stereovision.match")

    left = _texture(64, 96)
    right = _shift(left, 6.3)
    why = {
        "mcgm": "graph matching takes",
        "hopfield": "the Hopfield network takes",
        "best": "the best-match search takes",
        "fused": "its graph-matching and Hopfield channels take",
    }
    for method, channel in why.items():
        said = (
            f"^min_disparity: method='{method}' searches from 0 px \\({channel} no negative "
            r"disparity\), got -2; method='gabor' searches a negative range$"
        )
        with pytest.raises(ValueError, match=said):
            sv.match(left, right, method=method, max_disparity=16, min_disparity=-2)

        def estimated(*_: object) -> float:
            raise AssertionError("the range was estimated before the refusal")

        with monkeypatch.context() as m:  # no range given: refused before the estimate
            m.setattr(match_mod, "estimate_max_disparity", estimated)
            with pytest.raises(ValueError, match=said):
                sv.match(left, right, method=method, min_disparity=-2)
    got = sv.match(left, right, method="gabor", max_disparity=16, min_disparity=-2)
    assert len(got) > 100 and abs(float(np.nanmedian(got.dispx)) - 6.3) < 0.3


def test_a_negative_min_disparity_with_fused_names_the_channels_that_run() -> None:
    """match(method='fused', channels=('hopfield',), min_disparity=-2) said "its
    graph-matching and Hopfield channels take no negative disparity" of a graph-matching
    channel that does not run (depth_map too with ('gabor', 'hopfield')), and with
    channels=('gabor',) that refusal came before the channels' own error."""
    left = _texture(64, 96)
    right = _shift(left, 6.3)
    for channels, said in (
        (("hopfield",), "its Hopfield channel takes"),
        (("mcgm",), "its graph-matching channel takes"),
        (("gabor", "hopfield"), "its Hopfield channel takes"),
        (("mcgm", "hopfield"), "its graph-matching and Hopfield channels take"),
    ):
        for max_disparity in (None, 16):  # refused before the estimate, and after the checks
            with pytest.raises(ValueError, match=rf"^min_disparity: .*\({said} no negative "):
                sv.match(
                    left,
                    right,
                    method="fused",
                    channels=channels,
                    max_disparity=max_disparity,
                    min_disparity=-2,
                )
            if "gabor" in channels:
                with pytest.raises(ValueError, match=rf"\({said} no negative .* 'fast' search"):
                    sv.depth_map(
                        left,
                        right,
                        channels=channels,
                        max_disparity=max_disparity,
                        min_disparity=-2,
                    )
    # a channels no fused match is made of is said first, as with min_disparity=0
    for channels, said in ((("gabor",), "at least one sparse"), (("bogus",), "unknown channel")):
        for lo in (0, -2):
            with pytest.raises(ValueError, match=said):
                sv.match(left, right, method="fused", channels=channels, min_disparity=lo)
    # a one-pass iterator is read once: the refusal still names its channel
    with pytest.raises(ValueError, match=r"\(its Hopfield channel takes"):
        sv.match(left, right, method="fused", channels=iter(["hopfield"]), min_disparity=-2)
    # with no negative min_disparity to refuse, channels are checked where fuse_pair checks
    # them, after its options and switches, as before: checked first, a bad switch beside
    # them was said as the channels' ValueError, a misspelt option as an unknown channel
    with pytest.raises(TypeError, match=r"^check_members: expected True or False, got .no.$"):
        sv.match(left, right, method="fused", channels="gabor", check_members="no")
    with pytest.raises(ValueError, match=r"^unknown fusion option\(s\) \['chanels'\]"):
        sv.match(left, right, method="fused", channels=("bogus",), chanels=1)


def test_a_misspelt_keyword_of_depth_map_names_the_keyword() -> None:
    """``depth_map(..., max_disparty=8)`` was "unknown fusion option(s) ['max_disparty']" (a
    list of 22 options without the one meant), and the SGM's or Gabor's list with the others:
    now named as depth_map's own keyword, as match() names its own, before any work. A
    method of match() given as method= was said as unknown, as if no function had it."""
    img = np.zeros((8, 12), np.uint8)
    for method in ("fused", "gabor", "census", "fast"):
        for typo, meant in (("max_disparty", "max_disparity"), ("refin", "refine")):
            with pytest.raises(ValueError) as err:
                sv.depth_map(img, img, method=method, max_disparity=4, **{typo: 8})
            assert str(err.value) == (
                f"depth_map: unknown keyword argument {typo!r} (did you mean {meant!r}?)"
            )
    # match's methods: said as unknown, as if no function had them
    with pytest.raises(ValueError) as err:
        sv.depth_map(img, img, method="hopfield", max_disparity=4)
    assert str(err.value) == (
        "unknown method 'hopfield': expected one of fused, gabor, census, fast ('hopfield' is a "
        "method of stereovision.match, not of depth_map)"
    )
    # a key nearest to an option of the method is still the method's to name
    with pytest.raises(ValueError, match=r"^unknown SGM option\(s\) \['radius'\] \(did you"):
        sv.depth_map(img, img, method="census", max_disparity=4, radius=3)


def test_the_automatic_range_is_clamped_to_half_the_width() -> None:
    from stereovision.depth import estimate_max_disparity

    tex = _texture(128, 128, seed=2)
    # 60 px x 1.15 headroom is 69, rounded up 80: past half the width, so 64
    assert estimate_max_disparity(tex, _shift(tex, 60)) == 64
    # the half width is rounded up to a multiple of 16 as the range is: 100 -> 112 px
    wide = _texture(128, 200, seed=2)
    assert estimate_max_disparity(wide, _shift(wide, 95)) == 112
    flat = np.zeros((128, 96), np.float32)
    assert estimate_max_disparity(flat, flat) == 16  # no features: width / 8, at least 16


def test_a_dark_12_bit_pair_gets_the_range_of_its_full_scale_copy() -> None:
    from stereovision.depth import estimate_max_disparity

    tex = _texture(128, 128, seed=2)
    right = _shift(tex, 20)
    full = estimate_max_disparity(tex, right)
    dark = [(x * 4095).astype(np.uint16) for x in (tex, right)]  # 12-bit data in 16 bits
    assert full == 32
    assert estimate_max_disparity(*dark) == full  # cut to 8 bits unstretched it found 16


def test_values_past_the_range_are_holes_beyond_half_a_pixel() -> None:
    # a plane at 6.5 px: searched from 7.2, the Gabor channel measures it 0.7 px below the range
    # (holes); the census map locks at 7 px, 0.2 below (kept, clipped to 7.2). Searched up to
    # 5.6: 0.9 px past the Gabor range (holes), within half a pixel of the census map's 6.
    left = _texture(96, 160)
    right = _shift(left, 6.5)
    kw = {"fill": False, "refine": False}
    for method, lo, hi, top, dense in (
        ("gabor", 7.2, 16, 16, False),
        ("census", 7.2, 16, 16, True),
        ("gabor", 0, 5.6, 5.6, False),
        ("census", 0, 5.6, 6, True),
    ):
        res = sv.depth_map(left, right, method=method, max_disparity=hi, min_disparity=lo, **kw)
        valid = res.valid
        assert (valid.mean() > 0.9) if dense else (valid.mean() < 0.3), (method, lo, hi)
        assert lo <= np.nanmin(res.disparity) and np.nanmax(res.disparity) <= top
        assert (res.confidence[~valid] == 0).all()  # no confidence without a disparity


def test_filtered_keeps_limits_inclusive_and_its_cloud_and_maps_its_own() -> None:
    """Second audit: a relative-sigma limit met exactly, the cloud's pixels, copies of the
    confidence and left image, and a sigma limit on a result without depth_sigma were free."""
    r = _hand_result()
    # sigma 0.05 at 1 m and 0.1 at 2 m are exactly 5 % of the depth: kept (as max_sigma is)
    assert _kept(r.filtered(max_relative_sigma=0.05).require_depth()) == [1, 2]
    # the cloud loses the same pixels as the depth map: points, colours and pixels alike
    k = _known_depth_result(_rect_calib(2, 2))
    k.colors[:] = [[1, 2, 3], [4, 5, 6]]
    near = k.filtered(max_depth=0.5)
    np.testing.assert_array_equal(near.points, k.points[1:])
    np.testing.assert_array_equal(near.pixels, [[1, 1]])
    np.testing.assert_array_equal(near.colors, [[4, 5, 6]])
    # a copy: writing into its maps leaves the original's alone
    k.left_rectified = np.zeros((2, 2, 3), np.uint8)
    f = k.filtered(max_depth=5)
    assert f.left_rectified is not None
    f.confidence[0, 0] = -1.0
    f.left_rectified[0, 0] = 255
    assert k.confidence[0, 0] == 1.0 and k.left_rectified[0, 0, 0] == 0
    # and its timings: a stage the caller times on the copy was the original's too
    f.timings["export"] = 0.25
    assert k.timings == {} and f.timings == {"export": 0.25}
    # and its channels' dict: one dropped from (or put in) the copy's went from the original's
    sgm = np.zeros((2, 2), np.float32)
    g = dataclasses.replace(k, channels={"sgm": sgm})
    h = g.filtered(max_depth=5)
    assert h.channels == {"sgm": sgm}
    h.channels.clear()
    assert g.channels == {"sgm": sgm}
    assert k.filtered(max_depth=5).channels is None  # none stays none
    no_sigma = dataclasses.replace(r, depth_sigma=None)
    with pytest.raises(ValueError, match=r"^max_sigma: this result has no depth_sigma"):
        no_sigma.filtered(max_sigma=1.0)
    # the limit given is named (a relative one was told off as max_sigma, never given)
    with pytest.raises(ValueError, match=r"^max_relative_sigma: this result has no depth_sigma"):
        no_sigma.filtered(max_relative_sigma=0.1)


def test_point_image_guesses_exclude_dropped_pixels_and_keep_the_range_inclusive() -> None:
    r = _hand_result()
    # the dropped pixel (measured 5 px at confidence 0.2, 10 m) is no guess: left out
    with _wider_than_its_images():
        assert _kept(r.point_image(filled=True)[..., 2]) == [1, 2, 2.5, 5]
        # the guess at 2.5 m is inside a max_depth of 2.5 m
        assert _kept(r.filtered(max_depth=2.5).point_image(filled=True)[..., 2]) == [1, 2, 2.5]


def test_a_raw_rig_gives_depth_and_points_in_its_rectified_calibration() -> None:
    """A raw (unrectified) calibration: the result's calibration, its depth and its cloud are
    the rectified rig's (K1 here 499.5 px, not the raw 500), not the raw one's."""
    h, w, d = 96, 160, 6.5
    left = _texture(h, w)
    lens = np.array([-0.1, 0, 0, 0, 0.0])
    raw = dataclasses.replace(_rect_calib(w, h), rectified=False, D1=lens, D2=lens.copy())
    rect = raw.rectified_calibration()
    assert rect.K1[0, 0] != raw.K1[0, 0]
    res = sv.depth_map(left, _shift(left, d), raw, method="gabor", max_disparity=16)
    assert res.calibration is not None and res.calibration.rectified
    np.testing.assert_array_equal(res.calibration.K1, rect.K1)
    ok = np.isfinite(res.require_depth())
    assert ok.mean() > 0.5
    z = rect.depth_from_disparity(res.disparity)
    np.testing.assert_allclose(res.depth[ok], z[ok], rtol=1e-5)
    x, y = res.pixels[:, 0], res.pixels[:, 1]
    k = rect.K1
    z = res.points[:, 2]
    np.testing.assert_allclose(res.points[:, 0], (x - k[0, 2]) / k[0, 0] * z, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(res.points[:, 1], (y - k[1, 2]) / k[1, 1] * z, rtol=1e-5, atol=1e-6)


def test_an_enclosed_far_region_the_fill_took_over_is_counted_as_filled(data_dir: Path) -> None:
    """TartanAir's sky, enclosed and measured at 0 px, takes its surround's disparity in the
    fill: those pixels are guesses (confidence 0, no depth), counted as filled, not dropped."""
    s = load_scene(data_dir / "tartanair" / "oldtown_easy_p000_001116")
    kw = {"max_disparity": 64, "cloud": False}
    res = sv.depth_map(s.left, s.right, s.calib, **kw)
    raw = sv.depth_map(s.left, s.right, s.calib, fill=False, **kw)
    taken = raw.valid & (res.disparity != raw.disparity)
    assert taken.sum() > 1000  # measured: 1985 pixels (1992 at the scene's own range, 48)
    assert (res.confidence[taken] == 0).all() and np.isnan(res.require_depth()[taken]).all()
    c = res.depth_counts()
    assert c["filled"] == int((res.valid & (res.confidence == 0)).sum())
    assert c["filled"] >= int((~raw.valid).sum()) + int(taken.sum())


def test_depth_map_argument_edges_of_the_second_audit() -> None:
    """The homographies' range stands in only for a max_disparity not given; a pair of two
    sizes is refused before a raw rig would warp both to its size; an unknown method is named
    before the images are looked at; min_disparity is reported as a float."""
    from stereovision.uncalibrated import UncalibratedRectification

    h, w = 64, 96
    left = _texture(h, w, seed=3)
    right = _shift(left, 4.0)
    ident = np.eye(3)
    homographies = UncalibratedRectification(
        ident, ident, (w, h), (w, h), np.zeros((3, 3)), 100, 0.0, 0.0, (0.0, 20.0), 32,
        (0.0, 0.0), (1.0, 1.0),
    )  # fmt: skip
    own = sv.depth_map(left, right, homographies, method="gabor")
    given = sv.depth_map(left, right, homographies, method="gabor", max_disparity=16)
    assert own.max_disparity == 32 and given.max_disparity == 16
    raw = dataclasses.replace(_rect_calib(w, h), rectified=False)
    wider = np.zeros((h, w + 8), np.float32)
    with pytest.raises(ValueError, match=r"same shape, got left \(64, 96\) and right \(64, 104\)"):
        sv.depth_map(left, wider, raw, max_disparity=16)
    with pytest.raises(ValueError, match="unknown method 'best'"):
        sv.depth_map(np.zeros((0, 4)), np.zeros((0, 4)), method="best", max_disparity=8)
    res = sv.depth_map(left, right, method="fast", max_disparity=16, min_disparity=np.int64(2))
    assert type(res.min_disparity) is float and res.min_disparity == 2.0


def test_min_disparity_above_the_rectifications_range_names_it() -> None:
    """With an UncalibratedRectification and no max_disparity, a min_disparity above its search
    range was "max_disparity (32) must be larger than min_disparity (40)" (match: "... must be
    >= ..."), a max_disparity the caller never gave; the error names the rectification's."""
    from stereovision.uncalibrated import UncalibratedRectification

    h, w = 64, 96
    left = _texture(h, w, seed=3)
    right = _shift(left, 4.0)
    ident = np.eye(3)
    homographies = UncalibratedRectification(
        ident, ident, (w, h), (w, h), np.zeros((3, 3)), 100, 0.0, 0.0, (0.0, 20.0), 32,
        (0.0, 0.0), (1.0, 1.0),
    )  # fmt: skip
    said = (
        "min_disparity (40) is not below the automatic max_disparity (32, the rectification's "
        "search range): give a max_disparity above 40"
    )
    runs = (
        lambda: sv.depth_map(left, right, homographies, method="gabor", min_disparity=40),
        lambda: sv.match(left, right, homographies, method="gabor", min_disparity=40),
        lambda: sv.match(left, right, homographies, method="best", min_disparity=40),
    )
    for run in runs:
        with pytest.raises(ValueError) as err:
            run()
        assert str(err.value) == said
    # a max_disparity given is the caller's, said as before
    with pytest.raises(ValueError, match=r"^max_disparity \(32\) must be larger than min"):
        sv.depth_map(left, right, homographies, min_disparity=40, max_disparity=32)


def test_stages_are_timed_apart_and_reported_in_order() -> None:
    """Each timing is its own stage's (they add up to at most the call), and progress hears the
    stages in the order they ran."""
    import time

    h, w = 64, 96
    left = _texture(h, w, seed=4)
    said: list[str] = []
    t0 = time.perf_counter()
    res = sv.depth_map(
        left, _shift(left, 4.0), _rect_calib(w, h), max_disparity=16, progress=said.append
    )
    wall = time.perf_counter() - t0
    assert said == list(res.timings) == ["rectify", "prepare", "match", "fill", "triangulate"]
    assert 0 < sum(res.timings.values()) <= wall


def test_gabor_with_fill_only_re_measures_and_census_takes_the_fused_fill() -> None:
    """``"gabor"`` with ``fill=True``: only the re-measure runs (the refinement's own hole
    passes would give guesses a depth): the depth stays on the Gabor channel's pixels.
    ``"census"`` is filled as the fused map is (side rule, enclosed far regions)."""
    from stereovision.depth import fill_holes

    left = _texture(64, 128, seed=2)
    right = _shift(left, 4.0)
    left[:, 60:70] = 0.5  # a textureless stripe: holes there
    right[:, 56:66] = 0.5
    calib = _rect_calib(128, 64)
    kw = {"method": "gabor", "max_disparity": 16}
    raw = sv.depth_map(left, right, calib, refine=False, fill=False, **kw)
    done = sv.depth_map(left, right, calib, fill=True, **kw)
    grown = sv.depth_map(left, right, calib, fill=False, **kw)  # the refinement fills some
    z = done.require_depth()
    assert (np.isfinite(z) <= raw.valid).all() and np.isfinite(z).sum() > 0.5 * raw.valid.sum()
    assert (np.isfinite(grown.require_depth()) & ~raw.valid).any()
    s = load_scene(Path(sv.__file__).parent / "data" / "cones")
    kw = {"method": "census", "max_disparity": 64, "cloud": False}
    filled = sv.depth_map(s.left, s.right, **kw)
    holes = sv.depth_map(s.left, s.right, fill=False, **kw)
    grey = as_gray_float(s.left, "left")
    for fused, same in ((True, True), (False, False)):
        disp, _ = fill_holes(holes.disparity.copy(), s.left, fused=fused, grey=grey)
        assert np.array_equal(np.clip(disp, 0, 64), filled.disparity) == same, fused


def test_a_result_prints_its_limits_and_no_depth_and_refuses_a_switch_as_a_limit() -> None:
    r = _hand_result()
    assert "limits max_depth=5" in repr(r.filtered(max_depth=5))
    assert "limits" not in repr(r)
    empty = r.filtered(min_depth=100)
    assert "; no depth; 0 points" in repr(empty)
    with pytest.raises(ValueError, match="max_depth: expected a positive number, got True"):
        r.filtered(max_depth=True)


def test_a_dark_region_locked_at_a_min_disparity_above_0_is_filled_without_depth() -> None:
    """The enclosed far region step looks at the range's floor (min_disparity, not 0), and the
    pixels it fills are guesses: the surround's disparity, confidence 0, no depth."""
    h, w = 96, 160
    bright = 0.4 + 0.6 * _texture(h, w, seed=5)
    dark = 0.15 * _texture(h, w, seed=6)
    left = bright.copy()
    left[30:66, 60:110] = dark[30:66, 60:110]  # a dark square at 2 px in a wall at 8 px
    right = _shift(bright, 8.0)
    right[30:66, 58:108] = _shift(dark, 2.0)[30:66, 58:108]
    kw = {"max_disparity": 16, "min_disparity": 2, "cloud": False}
    res = sv.depth_map(left, right, _rect_calib(w, h), **kw)
    raw = sv.depth_map(left, right, _rect_calib(w, h), fill=False, **kw)
    inner = (slice(35, 61), slice(65, 105))
    assert float(np.nanmedian(raw.disparity[inner])) == pytest.approx(2.0, abs=0.1)
    assert float(np.median(res.disparity[inner])) == pytest.approx(8.0, abs=0.2)
    assert (res.confidence[inner] == 0).mean() > 0.9  # measured: 94 %
    assert np.isnan(res.require_depth()[inner]).mean() > 0.9
    assert not (np.isfinite(res.depth) & (res.confidence == 0)).any()


def test_the_12_bit_warning_points_at_the_callers_line() -> None:
    """The low-uint16 warning had ``stacklevel=4``, right for one depth only: through
    ``depth_map`` it named a line of depth.py, through ``match`` one of _validate.py."""
    import warnings

    left = np.rint(_texture(48, 96) * 4095).astype(np.uint16)
    right = np.rint(_shift(_texture(48, 96), 4.0) * 4095).astype(np.uint16)
    calls = {
        "depth_map": lambda: sv.depth_map(left, right, method="fast", max_disparity=16),
        "match": lambda: sv.match(left, right, max_disparity=16),
    }
    for how, call in calls.items():
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            call()
        said = [w for w in seen if "uint16 image whose largest value" in str(w.message)]
        assert [w.filename for w in said] == [__file__, __file__], how


@pytest.mark.parametrize(
    ("call", "name"),
    [
        ("match", "max_disparity"),
        ("match", "min_disparity"),
        ("depth_map", "max_disparity"),
        ("depth_map", "min_disparity"),
        ("match", "method"),
        ("depth_map", "method"),
    ],
)
def test_a_bad_range_or_method_is_said_in_one_short_line(call, name):
    """match's and depth_map's own refusals of max_disparity, min_disparity and method showed
    an array's whole repr (4 lines for a (4, 4) array, cut at the first by the CLI), and an
    array as the method failed in the test itself ("truth value ... is ambiguous"): one line
    now, the array by its shape and dtype."""
    img = np.zeros((20, 30), np.uint8)
    bad = np.ones((4, 4))
    with pytest.raises((ValueError, TypeError)) as info:
        getattr(sv, call)(img, img, **{name: bad})
    msg = str(info.value)
    assert "\n" not in msg
    assert "array of shape (4, 4) dtype float64" in msg
    assert (name if name != "method" else "unknown method") in msg


def test_to_ply_of_an_empty_path_names_it() -> None:
    """``to_ply('')`` said ": to_ply writes a .ply file ...", the path that was wrong not shown."""
    img = np.tile(np.arange(32, dtype=np.uint8) * 8, (8, 1))
    res = sv.depth_map(img, img, _rect_calib(32, 8), method="fast", max_disparity=8)
    with pytest.raises(ValueError, match=r"^path: expected a file name, got ''$"):
        res.to_ply("")
