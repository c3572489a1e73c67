"""render_plane against geometry worked out by hand: a fronto-parallel plane whose texture is
a ramp, so each pixel's value is the texture coordinate its centre sees."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from stereovision.synthetic import pixel_rays, render_plane

# f = 100 px, plane at Z = 1, 0.01 units per texture pixel: one texture pixel per image pixel.
# The principal point (-5, -3) puts image pixel (u, v) on texture pixel (u + 4.5, v + 2.5)
# (texture pixel centres sit half a pixel in from the origin).
K = np.array([[100.0, 0.0, -5.0], [0.0, 100.0, -3.0], [0.0, 0.0, 1.0]])
D = np.zeros(5)
TEX = np.zeros((60, 80, 3), np.float32)
TEX[..., 0] = np.arange(80)[None, :]  # column ramp
TEX[..., 1] = np.arange(60)[:, None]  # row ramp
TEX[..., 2] = 7.0


@pytest.mark.parametrize(("ss", "z", "s"), [(1, 1.0, 0.01), (3, 1.0, 0.01), (3, 2.0, 0.02)])
def test_a_fronto_parallel_ramp_lands_where_the_geometry_says(ss: int, z: float, s: float) -> None:
    """Twice as far with texture pixels twice as large: the same image (the ray's plane point
    is divided by its depth)."""
    out = render_plane(TEX, s, K, D, np.zeros(3), [0, 0, z], image_size=(20, 12), supersample=ss)
    assert out.shape == (12, 20, 3) and out.dtype == np.float32
    u, v = np.meshgrid(np.arange(20), np.arange(12))
    np.testing.assert_allclose(out[..., 0], u + 4.5, atol=1e-3)
    np.testing.assert_allclose(out[..., 1], v + 2.5, atol=1e-3)
    np.testing.assert_allclose(out[..., 2], 7.0, atol=1e-4)


def test_the_origin_moves_the_texture_and_integers_are_rounded() -> None:
    tex = np.tile(np.arange(80, dtype=np.uint8)[None, :], (60, 1))
    out = render_plane(
        tex, 0.01, K, D, np.zeros(3), [0, 0, 1.0], image_size=(20, 12), origin_px=(2.0, 0.0)
    )
    assert out.dtype == np.uint8
    u = np.arange(20)
    # coordinate u + 7 = u + 4.5 + 2.5 shifts columns only; u + 4.5 + 2 would be u + 6.5
    np.testing.assert_array_equal(out, np.tile(u + 7, (12, 1)))
    rows = render_plane(
        TEX, 0.01, K, D, np.zeros(3), [0, 0, 1.0], image_size=(20, 12), origin_px=(2.0, 0.0)
    )[..., 1]
    np.testing.assert_allclose(rows, np.tile(np.arange(12)[:, None] + 3.0, (1, 20)), atol=1e-3)
    half = render_plane(
        tex, 0.01, K, D, np.zeros(3), [0, 0, 1.0], image_size=(20, 12), origin_px=(1.75, 0.0)
    )
    np.testing.assert_array_equal(half, np.tile(u + 7, (12, 1)))  # u + 6.75 rounded, not cut


def test_off_the_plane_and_behind_the_camera_is_background_in_every_channel() -> None:
    out = render_plane(
        TEX, 0.01, K, D, np.zeros(3), [0, 0, 1.0], image_size=(100, 12), background=33.0
    )
    np.testing.assert_allclose(out[:, 90:], 33.0)  # columns past the texture's 80
    # the plane at Z = -1, where these rays, taken backwards, would meet it on the texture
    k_left = np.array([[100.0, 0.0, 25.0], [0.0, 100.0, 15.0], [0.0, 0.0, 1.0]])
    behind = render_plane(
        TEX, 0.01, k_left, D, np.zeros(3), [0, 0, -1.0], image_size=(20, 12), background=33.0
    )
    np.testing.assert_allclose(behind, 33.0)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"model": "fish"}, "model"),
        ({"supersample": 9}, "supersample"),
        ({"supersample": 0}, "supersample"),
        ({"image_size": (0, 10)}, "image_size"),
    ],
)
def test_bad_arguments_are_named(kw: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        render_plane(TEX, 0.01, K, D, np.zeros(3), [0, 0, 1.0], **kw)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"texture": np.zeros((0, 0))}, r"^texture: expected a non-empty .* got shape \(0, 0\)$"),
        ({"texture": np.zeros(10)}, r"^texture: .* got shape \(10,\)$"),  # was one column
        ({"texture": np.zeros((5, 5, 6))}, r"^texture: .*\(H, W, 1-4\) image, got shape"),
        ({"K": np.eye(2)}, r"^K: expected a 3 x 3 camera matrix \(finite\), got shape \(2, 2\)$"),
        ({"D": np.zeros(3)}, r"^D: expected 4, 5, 8, 12 or 14 coefficients \(or none\)"),
        ({"D": np.zeros(5), "model": "fisheye"}, r"^D: expected 4 coefficients for model 'fish"),
        ({"rvec": [0.0, 0.0]}, r"^rvec: expected 3 numbers \(finite\), got shape \(2,\)$"),
        ({"tvec": [0.0, np.nan, 1.0]}, r"^tvec: expected 3 numbers \(finite\), got shape \(3,\)$"),
        ({"tvec": [0.0, 0.0, 0.0]}, r"^tvec: the camera lies in the plane \(seen edge-on\)"),
    ],
)
def test_a_bad_texture_or_camera_is_named(kw: dict, message: str) -> None:
    """OpenCV's and NumPy's errors named no argument ("!_src.empty() in function 'remap'",
    "Singular matrix", a cv2.error for K), and a 1-D texture was drawn as one column."""
    args = {"texture": TEX, "K": K, "D": D, "rvec": np.zeros(3), "tvec": [0, 0, 1.0], **kw}
    with pytest.raises(ValueError, match=message):
        render_plane(units_per_pixel=0.01, image_size=(20, 12), **args)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"K": np.eye(3, dtype=bool)}, r"^K: expected a 3 x 3 camera matrix \(finite\), got "),
        ({"D": np.zeros(5, dtype=bool)}, r"^D: expected 4, 5, 8, 12 or 14 coefficients"),
        ({"rvec": [False] * 3}, r"^rvec: expected 3 numbers \(finite\), got shape"),
    ],
)
def test_a_bool_camera_is_refused_as_triangulate_refuses_it(kw: dict, message: str) -> None:
    """An identity mask as K was drawn as a camera of focal length 1 px (a mask of five as D
    was no distortion), without a word; triangulate refuses bools. render_chessboard shares
    the check."""
    from stereovision.calibrate import render_chessboard

    args = {"K": K, "D": D, "rvec": np.zeros(3), "tvec": [0, 0, 1.0], **kw}
    with pytest.raises(ValueError, match=message + r".* dtype bool$"):
        render_plane(TEX, 0.01, image_size=(20, 12), **args)
    with pytest.raises(ValueError, match=message + r".* dtype bool$"):
        render_chessboard(image_size=(20, 12), **args)


@pytest.mark.parametrize("model", ["pinhole", "fisheye"])
@pytest.mark.parametrize(
    ("k", "said"),
    [
        (np.zeros((3, 3)), "fx=0, fy=0"),  # an uncalibrated camera's camera_info K
        ([[100.0, 0.0, 9.5], [0.0, 0.0, 5.5], [0.0, 0.0, 1.0]], "fx=100, fy=0"),
        ([[-100.0, 0.0, 9.5], [0.0, 100.0, 5.5], [0.0, 0.0, 1.0]], "fx=-100, fy=100"),
    ],
)
def test_a_camera_matrix_without_positive_focal_lengths_is_named(
    model: str, k: object, said: str
) -> None:
    """K = 0 (or a zero focal length) gave every ray NaN: a picture of the background only,
    with NumPy's "invalid value encountered" warnings; a negative fx mirrored the picture.
    Refused in Calibration's words; a positive K renders the plane."""
    d = np.zeros(4) if model == "fisheye" else None
    kw = {"image_size": (20, 12), "model": model}
    with pytest.raises(ValueError, match=rf"^K: focal lengths must be positive, got {said}$"):
        render_plane(TEX, 0.01, k, d, np.zeros(3), [0, 0, 1.0], **kw)
    good = np.array([[100.0, 0.0, 9.5], [0.0, 100.0, 5.5], [0.0, 0.0, 1.0]])
    assert not np.all(render_plane(TEX, 0.01, good, d, np.zeros(3), [0, 0, 1.0], **kw) == 60)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"units_per_pixel": "0.01"}, r"^units_per_pixel: expected a positive finite number"),
        ({"units_per_pixel": True}, r"^units_per_pixel: expected a positive finite number"),
        ({"background": "60"}, r"^background: expected a number, got '60'$"),
        ({"background": True}, r"^background: expected a number, got True$"),
        (
            {"background": np.nan},
            r"^background: expected a value of the uint8 texture \(0 to 255\), got nan$",
        ),
        (
            {"background": 300},
            r"^background: expected a value of the uint8 texture \(0 to 255\), got 300$",
        ),
        ({"background": -1, "texture": np.zeros((4, 4), np.uint16)}, r"uint16 texture \(0 to "),
        ({"origin_px": "ab"}, r"^origin_px: expected two finite numbers \(x, y\), got 'ab'$"),
        ({"origin_px": (np.nan, 0.0)}, r"^origin_px: expected two finite numbers"),
        ({"origin_px": (1.0,)}, r"^origin_px: expected two finite numbers \(x, y\), got \(1.0,\)$"),
    ],
)
def test_a_bad_scale_or_background_is_named(kw: dict, message: str) -> None:
    """units_per_pixel "0.01" or True (1) and background "60" or True were taken as numbers;
    a NaN background on a uint8 texture was NumPy's "invalid value encountered in cast" and
    black (0), 300 clipped to 255; origin_px "ab" was NumPy's UFuncTypeError, a NaN one drew
    the background alone. Refused naming the argument; a float texture keeps NaN."""
    args = {"texture": np.full((4, 4), 128, np.uint8), "units_per_pixel": 0.01, **kw}
    with pytest.raises(ValueError, match=message):
        render_plane(K=K, D=D, rvec=np.zeros(3), tvec=[0, 0, 1.0], image_size=(20, 12), **args)
    far = render_plane(TEX, 0.01, K, D, np.zeros(3), [9.0, 9.0, 1.0], background=np.nan)
    assert np.isnan(far).all()  # off the plane everywhere: NaN, a float texture's value


def test_no_distortion_coefficients_is_no_distortion() -> None:
    kw = {"image_size": (20, 12)}
    none = render_plane(TEX, 0.01, K, np.zeros(0), np.zeros(3), [0, 0, 1.0], **kw)
    np.testing.assert_array_equal(
        none, render_plane(TEX, 0.01, K, D, np.zeros(3), [0, 0, 1.0], **kw)
    )


def test_none_for_distortion_is_no_distortion() -> None:
    """D=None (OpenCV's distCoeffs for none) was asarray's NaN: "D: expected 4, 5, 8, 12 or 14
    coefficients (or none) for model 'pinhole' (finite), got shape (1,)"."""
    from stereovision.charuco import CharucoBoard, render_charuco

    kw = {"image_size": (20, 12)}
    np.testing.assert_array_equal(
        render_plane(TEX, 0.01, K, None, np.zeros(3), [0, 0, 1.0], **kw),
        render_plane(TEX, 0.01, K, D, np.zeros(3), [0, 0, 1.0], **kw),
    )
    board = CharucoBoard("5x4", 0.04, 0.03, "DICT_5X5_100")
    pose = ([0.0, 0.0, 0.0], [-0.1, -0.08, 0.5])
    kc = np.array([[300.0, 0.0, 80.0], [0.0, 300.0, 60.0], [0.0, 0.0, 1.0]])
    got = render_charuco(board, kc, None, *pose, image_size=(160, 120), supersample=1)
    want = render_charuco(board, kc, D, *pose, image_size=(160, 120), supersample=1)
    np.testing.assert_array_equal(got, want)
    assert 0 < got.min() < got.max()  # the board is in view
    with pytest.raises(ValueError, match=r"^D: expected 4 coefficients .* \(finite\), got None$"):
        render_plane(TEX, 0.01, K, None, np.zeros(3), [0, 0, 1.0], model="fisheye", **kw)


@pytest.mark.parametrize("s", [0.0, -0.01, float("nan"), float("inf")])
def test_units_per_pixel_must_be_positive(s: float) -> None:
    with pytest.raises(ValueError, match="units_per_pixel"):
        render_plane(TEX, s, K, D, np.zeros(3), [0, 0, 1.0])


def test_fisheye_and_pinhole_rays_of_one_camera_are_not_shared() -> None:
    """The equidistant model puts pixel u at angle (u - cx) / f, so the plane at Z = 1 is read
    at tan((u + 5) / 100) * 100 - 0.5; the pinhole rays were cached under the same camera."""
    kw = {"image_size": (20, 12)}
    pin = render_plane(TEX, 0.01, K, np.zeros(4), np.zeros(3), [0, 0, 1.0], **kw)
    fish = render_plane(TEX, 0.01, K, np.zeros(4), np.zeros(3), [0, 0, 1.0], model="fisheye", **kw)
    u = np.arange(20)
    np.testing.assert_allclose(pin[0, :, 0], u + 4.5, atol=1e-3)
    np.testing.assert_allclose(fish[0, :, 0], np.tan((u + 5) / 100) * 100 - 0.5, atol=0.02)


def test_a_fisheye_ray_past_90_degrees_sees_the_background_not_the_plane() -> None:
    """With k1 = -0.1 the equidistant lens puts angle theta at r = f theta (1 - 0.1 theta^2):
    90 degrees at r = 118.3 px for f = 100, so pixels 120 px off the centre look behind the
    camera. OpenCV's inverse gave them a mirrored ray (tan theta < 0) that met the plane at
    Z = 1, which was drawn there; the cut at theta_d = r / f >= 90 degrees missed them."""
    k = np.array([[100.0, 0.0, 100.0], [0.0, 100.0, 100.0], [0.0, 0.0, 1.0]])
    d = np.array([-0.1, 0.0, 0.0, 0.0])
    tex = np.full((400, 400), 200.0, np.float32)  # 40 x 40 units, centred on the axis
    out = render_plane(
        tex,
        0.1,
        k,
        d,
        np.zeros(3),
        [-20.0, -20.0, 1.0],
        image_size=(240, 201),
        model="fisheye",
        supersample=1,
        background=60.0,
    )
    r = np.arange(0, 140)

    def angle(theta_d: float) -> float:
        """The smallest theta >= 0 with theta - 0.1 theta^3 = theta_d (inf: none)."""
        roots = np.roots([-0.1, 0.0, 1.0, -theta_d])
        real = [t.real for t in roots if abs(t.imag) < 1e-9 and t.real >= 0]
        return min(real, default=np.inf)

    theta = np.array([angle(x / 100) for x in r])  # of each pixel right of the centre
    front = theta < np.pi / 2
    assert front[:118].all() and not front[119:].any()
    # in front and within the plane's 20 units (tan theta <= 20): the plane, else background
    seen = front & (np.tan(np.where(front, theta, 0)) < 19)
    gone = ~front
    np.testing.assert_array_equal(out[100, 100 + r[seen]], 200.0)
    np.testing.assert_array_equal(out[100, 100 + r[gone]], 60.0)


def test_a_fisheye_ray_whose_distorted_angle_passes_90_degrees_still_sees_the_plane() -> None:
    """With k1 = 0.3, k2 = 0.1 the lens puts angle theta at r = f theta (1 + 0.3 theta^2 +
    0.1 theta^4): 90 degrees lies at r = 368 px for f = 100, 64 degrees already at r = 170 px.
    cv2.fisheye.undistortPoints clamps theta_d = r / f at 90 degrees, so every pixel past
    157 px (the image's corners) got a wrong ray, which the round trip cut: background where
    the plane is (484 of these 48240 pixels). They are solved by render_plane now."""
    k = np.array([[100.0, 0.0, 100.0], [0.0, 100.0, 100.0], [0.0, 0.0, 1.0]])
    d = np.array([0.3, 0.1, 0.0, 0.0])
    tex = np.full((400, 400), 200.0, np.float32)  # 40 x 40 units: tan theta <= 20 in view
    kw = {"image_size": (240, 201), "model": "fisheye", "supersample": 1, "background": 60.0}
    out = render_plane(tex, 0.1, k, d, np.zeros(3), [-20.0, -20.0, 1.0], **kw)
    np.testing.assert_array_equal(out, 200.0)  # corner: r = 172 px, theta 65 degrees
    rays = pixel_rays(k, d, (240, 201), 1, "fisheye")
    for dx, dy in ((139, 0), (120, 100), (139, 100)):  # r = 139, 156 (OpenCV's), 171 px
        r = np.hypot(dx, dy)
        roots = np.roots([0.1, 0.0, 0.3, 0.0, 1.0, -r / 100])
        theta = min(t.real for t in roots if abs(t.imag) < 1e-9 and t.real >= 0)
        want = np.array([dx, dy]) / r * np.tan(theta)
        np.testing.assert_allclose(rays[100 + dy, 100 + dx], want, rtol=1e-9)


def test_a_one_channel_texture_gives_a_one_channel_image() -> None:
    """88b0743 takes an (H, W, 1) texture, but cv2.remap drops its channel axis: the render
    came back (height, width), where 2 to 4 channels keep theirs. It is (height, width, 1) now,
    the values those of the (H, W) texture's render."""
    rng = np.random.default_rng(5)
    tex = (rng.random((60, 80)) * 255).astype(np.uint8)
    k = np.array([[120.0, 0.0, 40.0], [0.0, 120.0, 30.0], [0.0, 0.0, 1.0]])
    args = (0.01, k, np.zeros(5), np.zeros(3), [-0.4, -0.3, 1.0])
    kw = {"image_size": (80, 60), "supersample": 2}
    grey = render_plane(tex, *args, **kw)
    one = render_plane(tex[:, :, None], *args, **kw)
    assert one.shape == (60, 80, 1) and one.dtype == np.uint8
    np.testing.assert_array_equal(one[:, :, 0], grey)
    assert render_plane(np.dstack([tex] * 4), *args, **kw).shape == (60, 80, 4)


def test_the_fisheye_solve_reads_k_as_opencv_does_skew_ignored() -> None:
    """cv2.fisheye's undistortPoints and distortPoints ignore K's skew K[0, 1] (the rays of
    the pixels they solve are those of the unskewed K), but the solve past theta_d = 90
    degrees subtracted K[0, 1] y: its ray then failed the round trip through distortPoints,
    and every such pixel saw the background (K[0, 1] = 2: 484 of 48240 pixels)."""
    k = np.array([[100.0, 2.0, 100.0], [0.0, 100.0, 100.0], [0.0, 0.0, 1.0]])
    d = np.array([0.3, 0.1, 0.0, 0.0])
    tex = np.full((400, 400), 200.0, np.float32)
    kw = {"image_size": (240, 201), "model": "fisheye", "supersample": 1, "background": 60.0}
    out = render_plane(tex, 0.1, k, d, np.zeros(3), [-20.0, -20.0, 1.0], **kw)
    np.testing.assert_array_equal(out, 200.0)
    plain = k.copy()
    plain[0, 1] = 0.0
    rays = pixel_rays(k, d, (240, 201), 1, "fisheye")
    np.testing.assert_array_equal(rays, pixel_rays(plain, d, (240, 201), 1, "fisheye"))


def test_a_transposed_camera_matrix_is_refused() -> None:
    """A transposed K (MATLAB's IntrinsicMatrix) drew the plane as seen from a centre at
    (0, 0): 81 % of a 640 x 480 view background, without a word. Refused in Calibration's
    words, for both models."""
    k = np.array([[100.0, 0.0, 9.5], [0.0, 100.0, 5.5], [0.0, 0.0, 1.0]])
    for model, d in (("pinhole", None), ("fisheye", np.zeros(4))):
        with pytest.raises(ValueError, match=r"\(transposed\? pass K\.T\)$"):
            render_plane(
                TEX, 0.01, k.T, d, np.zeros(3), [0, 0, 1.0], image_size=(20, 12), model=model
            )


def test_a_texture_of_no_grey_levels_is_refused() -> None:
    """A bool texture (a mask) was rendered through float32 and cast back to bool: every
    blended edge and the background (60) came out True, 74 % True of a half-True board; a
    complex one lost its imaginary part with NumPy's ComplexWarning alone. Both are refused;
    the mask as uint8 renders."""
    mask = np.kron(np.indices((8, 8)).sum(0) % 2, np.ones((8, 8), np.int64)).astype(bool)
    k = np.array([[100.0, 0.0, 9.5], [0.0, 100.0, 5.5], [0.0, 0.0, 1.0]])
    args = (0.01, k, D, np.zeros(3), [-0.3, -0.3, 1.0])
    with pytest.raises(ValueError) as err:
        render_plane(mask, *args, image_size=(20, 12))
    assert str(err.value) == (
        "texture: expected integer or float grey levels, got bool (a mask: pass "
        "mask.astype(np.uint8) * 255)"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the ComplexWarning: no silent cast
        with pytest.raises(ValueError, match=r"^texture: .* got complex64$"):
            render_plane(mask.astype(np.complex64), *args, image_size=(20, 12))
    grey = render_plane(mask.astype(np.uint8) * 255, *args, image_size=(20, 12))
    assert grey.dtype == np.uint8 and 0.4 < (grey > 127).mean() < 0.6


def test_the_ray_cache_is_bounded_by_bytes_least_recently_used_first(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The rays were kept for up to nine cameras whatever their size: three 1080p cameras at
    supersample 3 held 896 MB. The cache now keeps _RAYS_MAX_BYTES (here two 20 x 10
    cameras' rays, 3200 bytes each), the least recently used going first, the newest kept."""
    from stereovision import synthetic

    monkeypatch.setattr(synthetic, "_RAYS", {})
    monkeypatch.setattr(synthetic, "_RAYS_MAX_BYTES", 7000, raising=False)
    cams = [np.array([[100.0 + i, 0.0, 9.5], [0.0, 100.0, 4.5], [0.0, 0.0, 1.0]]) for i in range(4)]
    first = pixel_rays(cams[0], D, (20, 10), 1)
    for k in cams[1:3]:
        pixel_rays(k, D, (20, 10), 1)
    assert [key[0] for key in synthetic._RAYS] == [cams[1].tobytes(), cams[2].tobytes()]
    pixel_rays(cams[1], D, (20, 10), 1)  # used again: cams[2]'s rays are now the oldest
    pixel_rays(cams[3], D, (20, 10), 1)
    assert [key[0] for key in synthetic._RAYS] == [cams[1].tobytes(), cams[3].tobytes()]
    np.testing.assert_array_equal(pixel_rays(cams[0], D, (20, 10), 1), first)  # recomputed
    monkeypatch.setattr(synthetic, "_RAYS_MAX_BYTES", 1000)
    pixel_rays(cams[2], D, (20, 10), 1)  # larger than the bound: kept alone
    assert [key[0] for key in synthetic._RAYS] == [cams[2].tobytes()]


def test_the_ray_cache_is_safe_when_another_thread_renders_meanwhile(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The cache was a bare module dict used by the GUI's and batch threads: another thread
    filling it between one call's store and its lookup evicted that call's rays (KeyError),
    and an eviction during another's byte sum was 'dictionary changed size during iteration'.
    Here a second thread renders nine other cameras the moment the first stores its rays."""
    import threading

    from stereovision import synthetic

    errors: list[BaseException] = []
    others = [np.array([[60.0 + i, 0.0, 2.0], [0.0, 60.0, 1.5], [0.0, 0.0, 1.0]]) for i in range(9)]

    def fill() -> None:
        try:
            for k in others:
                pixel_rays(k, D, (4, 3), 1)
        except BaseException as exc:  # reported by the main thread
            errors.append(exc)

    class Cache(dict):  # type: ignore[type-arg]
        thread: threading.Thread | None = None

        def __setitem__(self, key: object, value: object) -> None:
            super().__setitem__(key, value)
            if Cache.thread is None and threading.current_thread() is threading.main_thread():
                Cache.thread = threading.Thread(target=fill)
                Cache.thread.start()
                Cache.thread.join(0.05)  # waits on the lock once there is one

    monkeypatch.setattr(synthetic, "_RAYS", Cache())
    cam = np.array([[100.0, 0.0, 2.0], [0.0, 100.0, 1.5], [0.0, 0.0, 1.0]])
    rays = pixel_rays(cam, D, (4, 3), 1)
    assert Cache.thread is not None
    Cache.thread.join()
    assert errors == []
    np.testing.assert_allclose(rays[1, 2], [0.0, -0.005], atol=1e-12)  # (2 - cx, 1 - cy) / f
    assert [key[0] for key in synthetic._RAYS] == [k.tobytes() for k in others]  # the oldest out


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"texture": np.zeros((2, 32767), np.uint8)}, "texture: expected at most 32766 pixels a "
         "side (OpenCV's remap), got shape (2, 32767): shrink it and scale units_per_pixel up"),
        ({"image_size": (4096, 2), "supersample": 8}, "supersample: 8 samples a side of a 4096 x "
         "2 image are 32768 x 16, past OpenCV's remap's 32766 a side: use a lower supersample"),
    ],
)  # fmt: skip
def test_a_texture_or_picture_past_remaps_sides_is_named(kw: dict, message: str) -> None:
    """cv2.remap takes fewer than SHRT_MAX (32767) pixels a side: a long texture (a 40 m
    corridor at 1 mm a pixel) or a big picture's supersampling was its assertion 'dst.cols <
    SHRT_MAX && ... in function remap', naming no argument, the picture's only after all its
    rays were traced. Each is refused up front; 32766 pixels render."""
    args = {"texture": np.zeros((4, 4), np.uint8), "image_size": (8, 6), "supersample": 1, **kw}
    with pytest.raises(ValueError, match=f"^{re.escape(message)}"):
        render_plane(args.pop("texture"), 0.01, K, D, np.zeros(3), [0.0, 0.0, 1.0], **args)
    out = render_plane(np.zeros((2, 32766), np.uint8), 0.01, K, D, np.zeros(3), [0, 0, 1.0],
                       image_size=(8, 6), supersample=1)  # fmt: skip
    assert out.shape == (6, 8)
