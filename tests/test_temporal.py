"""A still rig's frames averaged over time (:mod:`stereovision.temporal`): real scenes with
seeded sensor noise, still, drifting, or with something moving through the view."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest

import stereovision as sv
from stereovision.evaluate import dense_metrics
from stereovision.io import load_scene
from stereovision.temporal import TemporalFilter, noise_sigma
from tests.test_exposure import noisy

VENUS = "middlebury2001/venus"


def test_noise_sigma_measures_sensor_noise(data_dir: Path) -> None:
    """Gaussian noise of 8 per colour channel is 5.34 on the grey image (BT.601 weights)."""
    img = load_scene(data_dir / VENUS).left
    clean = noise_sigma(img)
    with_noise = noise_sigma(noisy(img, 8.0, np.random.default_rng(0)))
    assert clean < 1.5, clean  # measured 0.90: the flattest 30 % still hold some texture
    assert 4.8 < with_noise < 6.5, with_noise  # measured 5.66
    assert noise_sigma(cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)) == clean  # grey in: the same
    with pytest.raises(ValueError, match="at least 3 x 3"):
        noise_sigma(np.zeros((2, 5), np.uint8))


def test_noise_of_a_16_bit_image_and_images_it_cannot_read(data_dir: Path) -> None:
    """A 16-bit frame (read_image's uint16 of a 16-bit PNG) counted every pixel over 255 as
    clipped and read noise 0; it is measured in 8-bit grey levels now, as the same frame in 8
    bits. Two or five channels raised OpenCV's own cv2.error, bool and complex images read 0."""
    img = noisy(load_scene(data_dir / VENUS).left, 8.0, np.random.default_rng(0))
    eight = noise_sigma(img)
    sixteen = noise_sigma(img.astype(np.uint16) * np.uint16(257))  # 8 bits spread over 16
    # 5.700 and 5.718: the 8-bit grey image is rounded to whole levels, the 16-bit one is not
    assert sixteen == pytest.approx(eight, rel=0.01) and 4.8 < sixteen < 6.5
    # a big-endian frame (raw sensor data read as '>u2') is the same frame: it read 0
    for frame in (img, cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)):
        native = frame.astype(np.uint16) * np.uint16(257)
        assert noise_sigma(native.astype(">u2")) == noise_sigma(native) > 4.8
    for channels in (2, 5):
        with pytest.raises(ValueError, match=f"expected 1, 3 or 4 channels, got {channels}"):
            noise_sigma(np.zeros((8, 8, channels), np.uint8))
    for dtype in (bool, complex):
        with pytest.raises(ValueError, match="expected grey levels"):
            noise_sigma(np.ones((8, 8), dtype))


@pytest.mark.parametrize("dtype", [np.float64, np.float16, np.int32, np.int64])
@pytest.mark.parametrize("channels", [3, 4])
def test_noise_of_a_colour_image_of_any_number_type(
    data_dir: Path, dtype: type, channels: int
) -> None:
    """A colour image of float64 (an image scaled in NumPy), float16 or int (a nested list's
    int64) raised OpenCV's cv2.error from the grey conversion, which takes uint8, uint16 and
    float32 only; it is measured as the same image in float32."""
    img = noisy(load_scene(data_dir / VENUS).left, 8.0, np.random.default_rng(0))
    if channels == 4:
        img = cv2.cvtColor(img, cv2.COLOR_BGR2BGRA)
    expected = noise_sigma(img.astype(np.float32))
    assert 4.8 < expected < 6.5, expected
    if np.issubdtype(dtype, np.integer):  # 8-bit levels: read as the uint8 image, bit for bit
        expected = noise_sigma(img)
    assert noise_sigma(img.astype(dtype)) == pytest.approx(expected, rel=1e-3)


def test_noise_of_int_levels_as_from_a_nested_list(data_dir: Path) -> None:
    """A nested list of ints (an image sent as JSON) is int64: its colour image was measured as
    float grey levels, not rounded as its uint8 image's (5.477 for 5.450 on this 160x120 crop;
    the whole image's lists took 0.8 s to build and read), and a list of 16-bit levels read 0
    (every pixel over 255 clipped). 8-bit levels read as the uint8 image; levels outside 0-255
    are refused, naming uint16."""
    img = noisy(load_scene(data_dir / VENUS).left, 8.0, np.random.default_rng(0))
    img = np.ascontiguousarray(img[:120, :160])
    for frame in (img, cv2.cvtColor(img, cv2.COLOR_BGR2BGRA), img[..., 1]):
        assert noise_sigma(frame.tolist()) == noise_sigma(frame) > 4.8
    with pytest.raises(
        ValueError, match=r"int64 grey levels must lie in 0-255, got \d+-\d+ .*uint16"
    ):
        noise_sigma((img.astype(np.int64) * 257).tolist())
    with pytest.raises(ValueError, match=r"int16 grey levels must lie in 0-255, got -1-0"):
        noise_sigma(-np.eye(5, dtype=np.int16))


def test_a_negative_int_level_is_not_told_to_be_uint16() -> None:
    """An int image with a negative level was told "(a 16-bit image: pass it as uint16)",
    which cannot hold it; the advice is kept for levels over 255 only."""
    with pytest.raises(ValueError) as exc:
        noise_sigma(np.arange(-128, 128, dtype=np.int16).reshape(16, 16))
    assert str(exc.value) == (
        "image: int16 grey levels must lie in 0-255, got -128-127 (a grey level cannot be negative)"
    )
    with pytest.raises(ValueError, match=r"got 0-300 \(a 16-bit image: pass it as uint16\)$"):
        noise_sigma(np.linspace(0, 300, 16, dtype=np.int32)[None].repeat(4, axis=0))


@pytest.mark.parametrize("channels", [0, 3])
def test_a_float64_level_past_float32s_range_is_clipped_without_a_warning(
    channels: int,
) -> None:
    """A float64 level of 1e40 (past float32's range) in a frame raised NumPy's "overflow
    encountered in cast" RuntimeWarning from the grey copy; it is a clipped level, measured as
    inf (and any level over 255) is: left out with its neighbours, without a warning."""
    img = np.random.default_rng(0).uniform(50, 200, (24, 24))
    if channels:
        img = np.repeat(img[..., None], channels, axis=2)
    huge, inf = img.copy(), img.copy()
    huge[5, 5], inf[5, 5] = 1e40, np.inf
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sigma = noise_sigma(huge)
    assert sigma == noise_sigma(inf) > 10  # uniform 50-200: about 35 grey levels


def test_a_black_border_is_no_noiseless_image(data_dir: Path) -> None:
    """Venus with noise 8 and a black border over its left 46 % (a fisheye's corners, a
    rectified frame's border): the noise reads as without the border. The border's pixels were
    the flattest 30 %: the noise read 0.003 and every frame of a still rig restarted."""
    img = load_scene(data_dir / VENUS).left
    rng = np.random.default_rng(0)
    plain = noise_sigma(noisy(img, 8.0, rng))
    frames = []
    for _ in range(4):
        frame = noisy(img, 8.0, rng)
        frame[:, :200] = 0
        frames.append(frame)
    assert noise_sigma(frames[0]) == pytest.approx(plain, rel=0.05)
    tf = TemporalFilter()
    for frame in frames:
        tf(frame, frame)
    assert tf.restarts == 0 and tf.mean_frames() > 3.5
    assert noise_sigma(np.zeros((10, 10), np.uint8)) == 0.0
    assert noise_sigma(np.full((10, 10, 3), 255, np.uint8)) == 0.0


@pytest.mark.parametrize("border", [100, 200, 394])
def test_a_rig_moving_behind_a_black_border_starts_again(data_dir: Path, border: int) -> None:
    """Venus moving 2 px a frame, noise 8, black over its left 100, 200 or 394 columns: every
    frame starts again. The border's zero differences pulled the motion test's median down: 2
    and 0 restarts of 5, the moving frames averaged into a smear; with 394 (91 % black) a
    share rule kept the black pixels in: 0 restarts of 5."""
    img = load_scene(data_dir / VENUS).left
    h, w = img.shape[:2]
    rng = np.random.default_rng(0)
    tf = TemporalFilter()
    for i in range(6):
        shift = np.float32([[1, 0, 2 * i], [0, 1, 0]])
        frame = noisy(cv2.warpAffine(img, shift, (w, h), borderMode=cv2.BORDER_REFLECT), 8.0, rng)
        frame[:, :border] = 0
        tf(frame, frame)
    assert tf.restarts == 5 and tf.mean_frames() == 1.0


@pytest.mark.parametrize("grey", [False, True])
def test_a_small_rig_moving_behind_a_black_border_starts_again(data_dir: Path, grey: bool) -> None:
    """Venus shrunk to 32 x 32 px (64 sampled pixels in all), moving 2 px a frame, noise 4,
    black over its left half: every frame starts again. A rule keeping the black pixels while
    fewer than 64 others are sampled kept them on any image this small: 0 restarts of 5 (the
    moving frames averaged into a smear); left out, 5 of 5, in grey and in colour."""
    img = cv2.resize(load_scene(data_dir / VENUS).left, (52, 32), interpolation=cv2.INTER_AREA)
    if grey:
        img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    rng = np.random.default_rng(0)
    tf = TemporalFilter()
    for i in range(6):
        frame = noisy(np.ascontiguousarray(img[:, 2 * i : 2 * i + 32]), 4.0, rng)
        frame[:, :16] = 0
        tf(frame, frame)
    assert tf.restarts == 5 and tf.mean_frames() == 1.0
    # the same small frame held still keeps averaging: the 32 sampled pixels left suffice
    still = TemporalFilter()
    for _ in range(4):
        frame = noisy(np.ascontiguousarray(img[:, :32]), 4.0, rng)
        frame[:, :16] = 0
        still(frame, frame)
    assert still.restarts == 0 and still.mean_frames() > 3.99


@pytest.mark.parametrize("border", [394, 420])
def test_a_still_rig_behind_a_wide_black_border_keeps_averaging(
    data_dir: Path, border: int
) -> None:
    """Venus still, noise 8, black over 91 % or 97 % of its width: the strip left (40 and 14
    columns, 1000 and 350 sampled pixels) is enough for the motion test's median; no restart."""
    img = load_scene(data_dir / VENUS).left
    rng = np.random.default_rng(0)
    tf = TemporalFilter()
    for _ in range(4):
        frame = noisy(img, 8.0, rng)
        frame[:, :border] = 0
        tf(frame, frame)
    assert tf.restarts == 0 and tf.mean_frames() > 3.99


def test_a_still_noisy_rig_matches_as_if_lessnoisy(data_dir: Path) -> None:
    """Venus, noise 8 on each channel, 8 still frames: the default map's bad-2.0 measured 4.98
    % on the last frame alone, 1.37 % on the filter's output (0.83 % without noise)."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(1)
    tf = TemporalFilter()
    for _ in range(8):
        left, right = noisy(sc.left, 8.0, rng), noisy(sc.right, 8.0, rng)
        avg_l, avg_r = tf(left, right)
    assert tf.restarts == 0 and tf.mean_frames() > 7.8
    # The averaged image's noise: about 1/sqrt(8) of a frame's.
    resid = avg_l.astype(np.float32) - sc.left
    assert np.std(resid) < 0.45 * np.std(left.astype(np.float32) - sc.left)

    def bad2(lft: np.ndarray, rgt: np.ndarray) -> float:
        res = sv.depth_map(lft, rgt, max_disparity=sc.max_disparity)
        return dense_metrics(res.disparity, sc.gt).bad[2.0]

    single, averaged = bad2(left, right), bad2(avg_l, avg_r)
    assert averaged < 0.5 * single, (averaged, single)


def test_a_still_clean_rig_is_unchanged(data_dir: Path) -> None:
    sc = load_scene(data_dir / VENUS)
    tf = TemporalFilter()
    for _ in range(4):
        out = tf(sc.left, sc.right)
        assert np.array_equal(out[0], sc.left) and np.array_equal(out[1], sc.right)
    assert tf.restarts == 0 and tf.mean_frames() == 4.0


@pytest.mark.parametrize("sigma", [0.0, 8.0])
def test_a_moving_rig_starts_again(data_dir: Path, sigma: float) -> None:
    """The view drifting by 1 px a frame (a panning rig), with and without noise: every frame
    after the first is found moving and passes through unchanged (teddyH and reindeer: the
    same bad-2.0 as unfiltered on every frame; wood2's smooth grain under noise is averaged
    across the drift and gains, docs/robotics.md)."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(2)
    tf = TemporalFilter()
    h, w = sc.left.shape[:2]
    for k in range(5):
        shift = np.float32([[1, 0, -k], [0, 1, 0]])
        left, right = (
            cv2.warpAffine(img, shift, (w, h), borderMode=cv2.BORDER_REPLICATE)
            for img in (sc.left, sc.right)
        )
        if sigma:
            left, right = noisy(left, sigma, rng), noisy(right, sigma, rng)
        out = tf(left, right)
        assert np.array_equal(out[0], left) and np.array_equal(out[1], right), k
    assert tf.restarts == 4


@pytest.mark.parametrize("saved", [False, True])
def test_a_new_size_measures_its_own_noise(data_dir: Path, saved: bool) -> None:
    """After 8 pairs with noise 12, the camera switches to a smaller mode with noise 2 and
    pans 1 px a pair: every pair is found moving and passes through unchanged, as for a new
    filter. The first mode's noise median (8.3) carried over, and the first three pairs of the
    new mode were averaged into a smear (0 restarts, up to 2.9 frames a pixel).

    ``saved``: the means forgotten first, as capture does after each pair it saves: the size
    was compared with the means' alone, so a camera that switched mode right after a save kept
    the old mode's noise median and averaged the moving new mode."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(9)
    tf = TemporalFilter()
    for _ in range(8):
        tf(noisy(sc.left, 12.0, rng), noisy(sc.right, 12.0, rng))
    assert tf.sigma > 7.0 and tf.restarts == 0
    if saved:
        tf._forget_means()  # capture's saved pair
    h, w = sc.left.shape[:2]
    small = (slice(0, h - 40), slice(0, w - 40))
    for k in range(1, 5):
        left, right = (noisy(np.roll(i, k, 1)[small], 2.0, rng) for i in (sc.left, sc.right))
        out = tf(left, right)
        assert np.array_equal(out[0], left) and np.array_equal(out[1], right), k
        assert tf.sigma < 3.0, (k, tf.sigma)
    assert tf.restarts == 3 and tf.mean_frames() == 1.0 and tf.frames == 12


def test_something_moving_through_a_still_view_leaves_no_ghost(data_dir: Path) -> None:
    """A textured patch (cones' left image) crosses the still, noisy venus view 12 px a frame:
    the rig is not taken for moving (no restart), the background keeps averaging, and where
    the patch is or just was, the output is the current frame, not a blend."""
    sc = load_scene(data_dir / VENUS)
    patch = load_scene(data_dir / "middlebury2003/cones").left[100:180, 100:180]
    rng = np.random.default_rng(3)
    tf = TemporalFilter()
    for k in range(8):
        left = sc.left.copy()
        x = 40 + 12 * k
        left[150:230, x : x + 80] = patch
        left, right = noisy(left, 8.0, rng), noisy(sc.right, 8.0, rng)
        out_l, _ = tf(left, right)
    assert tf.restarts == 0
    diff = np.abs(out_l.astype(np.float32) - left)
    patch_now = (slice(152, 228), slice(x + 2, x + 78))
    uncovered = (slice(152, 228), slice(x - 12 + 2, x - 2))  # the patch's place a frame ago
    # Where the patch is and where it just left, the output is the frame (or nearly: a pixel
    # within 3 sigma of its old mean may have averaged).
    assert np.median(diff[patch_now]) == 0.0 and np.median(diff[uncovered]) == 0.0
    # Far from its path the background averaged: its noise is down by more than half.
    far = (slice(20, 120), slice(20, 400))
    clean_far = sc.left[far].astype(np.float32)
    assert np.std(out_l[far] - clean_far) < 0.5 * np.std(left[far] - clean_far)


def test_a_new_size_starts_again_and_bad_input_is_named() -> None:
    tf = TemporalFilter(max_frames=4)
    a = np.full((20, 30), 100, np.uint8)
    tf(a, a)
    tf(a, a)
    assert tf.mean_frames() == 2.0
    b = np.full((10, 30), 50, np.uint8)
    out = tf(b, b)
    assert np.array_equal(out[0], b) and tf.mean_frames() == 1.0
    with pytest.raises(ValueError, match="left: expected a uint8 image, got float32"):
        tf(b.astype(np.float32), b)
    with pytest.raises(ValueError, match="left and right differ in shape"):
        tf(a, b)
    with pytest.raises(ValueError, match="max_frames: expected at least 1"):
        TemporalFilter(max_frames=0)
    with pytest.raises(ValueError, match="k: expected a positive number"):
        TemporalFilter(k=-1.0)
    with pytest.raises(ValueError, match="k: expected a positive number of sigmas, got '3'"):
        TemporalFilter(k="3")  # type: ignore[arg-type]  # was a TypeError from np.isfinite
    tf.reset()
    assert tf.mean_frames() == 0.0


def test_only_max_frames_and_k_are_parameters() -> None:
    """The counters and the noise estimate are state, not parameters (the docstring's
    Parameters are max_frames and k): TemporalFilter(8, 3.0, 5) started at frames=5, and
    sigma=2.0 (read as a noise level) was taken silently and replaced by the first pair's."""
    import inspect

    assert list(inspect.signature(TemporalFilter).parameters) == ["max_frames", "k"]
    with pytest.raises(TypeError, match="positional argument"):
        TemporalFilter(8, 3.0, 5)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="unexpected keyword argument 'sigma'"):
        TemporalFilter(sigma=2.0)  # type: ignore[call-arg]
    tf = TemporalFilter(4, 2.0)
    assert (tf.max_frames, tf.k, tf.frames, tf.restarts, tf.sigma, tf.relit) == (
        4,
        2.0,
        0,
        0,
        0.0,
        0,
    )
    assert (
        repr(tf) == "TemporalFilter(max_frames=4, k=2.0, frames=0, restarts=0, sigma=0.0, relit=0)"
    )


def test_max_frames_caps_the_mean_and_a_new_light_is_followed() -> None:
    """Beyond ``max_frames`` the mean follows a still pixel's new value by 1/max_frames each;
    a change of the whole image's brightness (a flickering light, an auto-exposure step) is
    carried into the mean first, so the averaging goes on."""
    tf = TemporalFilter(max_frames=3)
    rng = np.random.default_rng(4)
    base = rng.integers(60, 200, (40, 40)).astype(np.uint8)
    for _ in range(6):
        tf(base, base)
    assert tf.mean_frames() == 3.0 and tf.relit == 0
    patch = base.copy()
    patch[:4] += 2  # a tenth of the image, within the noise test: averaged, 1/3 of the way
    out, _ = tf(patch, patch)
    assert np.array_equal(out[:4], base[:4] + 1) and np.array_equal(out[4:], base[4:])
    assert tf.mean_frames() == 3.0
    relit = tf.relit  # the patch may have moved the fit by a hair (no visible change)
    brighter = np.clip(base * 1.04 + 3, 0, 255).astype(np.uint8)  # the whole image
    out, _ = tf(brighter, brighter)
    assert tf.relit == relit + 2 and tf.restarts == 0 and tf.mean_frames() == 3.0
    assert np.abs(out.astype(int) - brighter).max() <= 1  # the new light, not a blend


def test_a_flickering_light_keeps_averaging(data_dir: Path) -> None:
    """Venus with noise 8 under a light that flickers by up to 4 % from frame to frame: the
    means are relit, not restarted (before the relighting: 7 restarts of 7, nothing averaged),
    and the map gains as in a steady light (measured 4.58 -> 1.80 %, 14 relit images)."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(6)
    tf = TemporalFilter()
    for k in range(8):
        gain = 1.0 + 0.04 * np.sin(2.1 * k)
        left, right = (
            noisy(np.clip(img * gain, 0, 255).astype(np.uint8), 8.0, rng)
            for img in (sc.left, sc.right)
        )
        avg = tf(left, right)
    assert tf.restarts == 0 and tf.relit >= 10 and tf.mean_frames() > 7.8
    md = sc.max_disparity
    one = dense_metrics(sv.depth_map(left, right, max_disparity=md).disparity, sc.gt).bad[2.0]
    many = dense_metrics(sv.depth_map(*avg, max_disparity=md).disparity, sc.gt).bad[2.0]
    assert many < 0.5 * one, (many, one)


@pytest.mark.parametrize("colour", [True, False])
def test_kernels_match_the_numpy_reference(data_dir: Path, colour: bool) -> None:
    """The Rust passes against tests/reference/temporal_ref.py on teddyH with noise, a mean
    of a few frames and mixed counts (some pixels restarting): bit for bit."""
    from stereovision import _core
    from tests.reference import temporal_ref as ref

    img = load_scene(data_dir / "middeval3/teddyH").left
    if not colour:
        img = np.ascontiguousarray(cv2.cvtColor(img, cv2.COLOR_BGR2GRAY))
    rng = np.random.default_rng(5)
    mean = np.ascontiguousarray(
        np.clip(img + rng.normal(0, 3, img.shape), 0, 255).astype(np.float32)
    )
    frame = noisy(img, 8.0, rng)
    # Something moved there: black where the block was bright, white where it was dark.
    block = frame[100:200, 100:300]
    grey = cv2.cvtColor(block, cv2.COLOR_BGR2GRAY) if colour else block
    frame[100:200, 100:300] = np.where(grey > 127, 0, 255).astype(np.uint8)[
        (..., None) if colour else ...
    ]
    count = rng.integers(1, 9, img.shape[:2]).astype(np.uint8)
    diff = _core.temporal_grey_difference(frame, mean)
    np.testing.assert_array_equal(diff, ref.grey_difference(frame, mean))
    want = ref.running_mean(frame, mean, count, diff, 16.0, 8)
    out = _core.temporal_running_mean(frame, mean, count, diff, 16.0, 8)  # mean, count in place
    got = (mean, count, out)
    for g, w in zip(got, want, strict=True):
        assert g.shape == w.shape and g.dtype == w.dtype
        np.testing.assert_array_equal(g, w)
    # Both outcomes occur: the changed block restarts, most of the rest keeps averaging.
    assert (got[1][100:200, 100:300] == 1).all() and (got[1] > 1).mean() > 0.8
    with pytest.raises(ValueError, match="mean shape"):
        _core.temporal_grey_difference(frame, mean[:10])
    with pytest.raises(ValueError, match="count shape"):
        _core.temporal_running_mean(frame, mean, count[:10], diff, 16.0, 8)
    with pytest.raises(ValueError, match="count must be C-contiguous"):
        _core.temporal_running_mean(frame, mean, np.asfortranarray(count), diff, 16.0, 8)


def test_bgra_and_grey_frames(data_dir: Path) -> None:
    """BGRA (alpha 255, left out of the grey and the saturation test), grey and (H, W, 1)
    frames average as BGR ones do."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(7)
    for convert in (cv2.COLOR_BGR2BGRA, cv2.COLOR_BGR2GRAY, None):
        tf = TemporalFilter()
        for _ in range(4):
            left, right = (
                cv2.cvtColor(noisy(i, 8.0, rng), cv2.COLOR_BGR2GRAY if convert is None else convert)
                for i in (sc.left, sc.right)
            )
            if convert is None:
                left, right = left[..., None], right[..., None]
            out = tf(left, right)
        assert tf.restarts == 0 and tf.mean_frames() > 3.9
        assert out[0].shape == left.shape
        if convert == cv2.COLOR_BGR2BGRA:
            assert (out[0][..., 3] == 255).all()


def test_a_new_light_leaves_bgra_alpha_alone(data_dir: Path) -> None:
    """A BGRA rig (alpha 255 on every frame) whose light dims by 20 %: the colour means are
    relit, the alpha is not light and stays 255. It was scaled with them: 214 on the first dim
    pair (the mean of 255s), creeping back over the following pairs."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(8)
    tf = TemporalFilter()
    for gain in (1.0, 1.0, 1.0, 1.0, 0.8, 0.8):
        left, right = (
            cv2.cvtColor(
                noisy(np.clip(i * gain, 0, 255).astype(np.uint8), 8.0, rng), cv2.COLOR_BGR2BGRA
            )
            for i in (sc.left, sc.right)
        )
        out = tf(left, right)
        assert (out[0][..., 3] == 255).all() and (out[1][..., 3] == 255).all(), gain
    assert tf.restarts == 0 and tf.relit == 2
    bgr = tuple(cv2.cvtColor(o, cv2.COLOR_BGRA2BGR) for o in out)
    for o, img in zip(bgr, (sc.left, sc.right), strict=True):  # the dimmed light, averaged
        assert np.abs(o.astype(float) - img * 0.8).mean() < 3.0


def test_k_beyond_64_bits() -> None:
    # np.isfinite(2**70) was NumPy's TypeError "ufunc 'isfinite' not supported", naming no k
    assert TemporalFilter(k=2**70).k == 2**70
    with pytest.raises(ValueError, match=r"^k: expected a positive number of sigmas, got 1000"):
        TemporalFilter(k=10**400)


def test_filters_compare_and_hash_by_identity() -> None:
    """Two filters that had each seen a pair: ``a == b`` compared their running means' arrays
    and raised NumPy's 'truth value of an array ... is ambiguous', and a filter could not go in
    a set or key a dict. A filter is equal to itself only, and hashable."""
    img = np.random.default_rng(0).integers(0, 255, (20, 20), dtype=np.uint8)
    a, b = TemporalFilter(), TemporalFilter()
    a(img, img)
    b(img, img)
    assert a == a and a != b
    assert {a: 1, b: 2}[a] == 1 and len({a, b, a}) == 2


@pytest.mark.parametrize("k", [1e38, 2**130, 1e300])
def test_a_k_past_float32_averages_as_a_large_one(data_dir: Path, k: float) -> None:
    """The kernel takes ``k * sigma`` as float32: a k the constructor accepts (1e38, 2**130,
    1e300) made it +inf there, and the second noisy pair raised "invalid parameter `ks`",
    a name the caller never gave. Such a k restarts no pixel, as k = 1e4 does: the same frames
    out, bit for bit."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(3)
    pairs = [(noisy(sc.left, 8.0, rng), noisy(sc.right, 8.0, rng)) for _ in range(4)]
    big, ref = TemporalFilter(k=k), TemporalFilter(k=1e4)
    for left, right in pairs:
        got, want = big(left, right), ref(left, right)
        assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
    assert big.sigma > 3.0 and big.restarts == ref.restarts == 0
    assert big.mean_frames() == ref.mean_frames() == 4.0


def test_a_k_too_small_for_float32_restarts_every_changed_pixel() -> None:
    """A k the constructor accepts (1e-300) times the noise is 0 in the kernel's float32: the
    second pair raised "invalid parameter `ks`: ... is 0 in float32", a name the caller never
    gave. It is a threshold of 0 now: a pixel that did not change averages, any other starts
    again."""
    rng = np.random.default_rng(0)
    img = rng.integers(0, 256, (20, 30), np.uint8)
    tf = TemporalFilter(k=1e-300)
    tf(img, img)
    left, right = tf(img, img)
    assert np.array_equal(left, img) and np.array_equal(right, img)
    assert tf.sigma > 1.0 and tf.mean_frames() == 2.0
    moved = img.copy()
    moved[5:8, 5:8] ^= 1  # 9 pixels one grey level off: k = 3 would average them
    left, _ = tf(moved, img)
    assert np.array_equal(left, moved) and tf.restarts == 0
    counts = tf._means[0].count
    assert np.count_nonzero(counts == 1) == 9 and counts[5:8, 5:8].tolist() == [[1] * 3] * 3


@pytest.mark.parametrize("k", [np.float32(3e38), np.float16(60000.0)])
def test_a_numpy_k_past_its_type_averages_without_an_overflow_warning(
    data_dir: Path, k: np.floating
) -> None:
    """A NumPy k (np.float32's or np.float16's large values, which the constructor accepts)
    times the noise was multiplied in k's own type: inf, with NumPy's "overflow encountered in
    scalar multiply" RuntimeWarning on every pair. It is a large k now: no warning, the same
    frames as k = 1e4, bit for bit."""
    import warnings

    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(3)
    pairs = [(noisy(sc.left, 8.0, rng), noisy(sc.right, 8.0, rng)) for _ in range(3)]
    big, ref = TemporalFilter(k=k), TemporalFilter(k=1e4)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for left, right in pairs:
            got, want = big(left, right), ref(left, right)
            assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
    assert big.restarts == 0 and big.mean_frames() == 3.0


@pytest.mark.parametrize("shape", [(1, 1), (1, 64), (2, 2), (64, 2), (2, 8, 3)])
def test_frames_too_small_name_the_pair_and_the_size_needed(shape: tuple[int, ...]) -> None:
    """Frames under 3 x 3 px were refused in noise_sigma's words ("image: expected an (H, W) or
    (H, W, C) image of at least 3 x 3"), naming an argument the caller never gave; the error
    names the pair, its size and the size needed, and the filter keeps no frame."""
    frame = np.full(shape, 100, np.uint8)
    filt = TemporalFilter()
    w, h = shape[1], shape[0]
    with pytest.raises(
        ValueError,
        match=rf"^left and right: {w}x{h} px, too small to measure their noise: images of at "
        r"least 3 x 3 px are needed$",
    ):
        filt(frame, frame.copy())
    assert filt.frames == 0
    out_l, _ = filt(np.full((3, 3), 100, np.uint8), np.full((3, 3), 100, np.uint8))
    assert out_l.shape == (3, 3) and filt.frames == 1


# ------------------------------------------------------------------ mutation audit (value tests)


def test_a_view_of_another_brightness_restarts_and_is_counted() -> None:
    """A gain outside 0.5-2 (a third of the brightness) is another view: the frame passes
    through, both means start again, and the restart is counted."""
    rng = np.random.default_rng(10)
    base = rng.integers(60, 200, (40, 40)).astype(np.uint8)
    tf = TemporalFilter()
    tf(base, base)
    tf(base, base)
    dim = base // 3
    out = tf(dim, dim)
    assert np.array_equal(out[0], dim) and np.array_equal(out[1], dim)
    assert tf.restarts == 1 and tf.relit == 0 and tf.mean_frames() == 1.0


def test_a_nearly_black_still_view_keeps_averaging() -> None:
    """Grey levels 0-5 leave nothing to fit a light's change to: the gain is 1, not another view
    (a dark room restarted on every frame)."""
    dark = np.random.default_rng(11).integers(0, 6, (40, 40)).astype(np.uint8)
    tf = TemporalFilter()
    for _ in range(3):
        out = tf(dark, dark)
    assert tf.restarts == 0 and tf.mean_frames() == 3.0 and np.array_equal(out[0], dark)


def test_a_rig_that_moves_after_holding_still_starts_again(data_dir: Path) -> None:
    """Six still noisy frames, then the view shifts by 1 px: the motion test's expected noise
    is that of a frame minus a 6-frame mean (sqrt(1 + 1/n)), and the shift is caught."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(12)
    h, w = sc.left.shape[:2]
    tf = TemporalFilter()
    for _ in range(6):
        tf(noisy(sc.left, 8.0, rng), noisy(sc.right, 8.0, rng))
    assert tf.restarts == 0
    shift = np.float32([[1, 0, 1], [0, 1, 0]])
    left, right = (
        noisy(cv2.warpAffine(i, shift, (w, h), borderMode=cv2.BORDER_REPLICATE), 8.0, rng)
        for i in (sc.left, sc.right)
    )
    out = tf(left, right)
    assert tf.restarts == 1 and np.array_equal(out[0], left)


@pytest.mark.parametrize(
    ("kwargs", "says"),
    [
        ({"max_frames": 256}, "max_frames: expected at least 1 and at most 255, got 256"),
        ({"max_frames": True}, "max_frames: expected an integer, got True"),
    ],
)
def test_max_frames_fits_the_uint8_count(kwargs: dict, says: str) -> None:
    with pytest.raises(ValueError, match=re.escape(says)):
        TemporalFilter(**kwargs)
    assert TemporalFilter(max_frames=255).max_frames == 255


def test_two_channel_frames_are_named() -> None:
    two = np.zeros((8, 8, 2), np.uint8)
    with pytest.raises(ValueError, match=re.escape("expected (H, W) or (H, W, 1|3|4) images")):
        TemporalFilter()(two, two)


def test_the_noise_is_the_median_of_the_recent_frames_estimates(data_dir: Path) -> None:
    """One frame of a far noisier burst (noise 40 against 8) does not move the noise estimate:
    it is the median of the last 8 frames' own estimates (the docstring's), not the latest or
    the largest."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(13)
    tf = TemporalFilter()
    each = []
    for _ in range(5):
        left = noisy(sc.left, 8.0, rng)
        each.append(noise_sigma(left))
        tf(left, noisy(sc.right, 8.0, rng))
    assert tf.sigma == pytest.approx(float(np.median(each)), rel=1e-12)
    burst = noisy(sc.left, 40.0, rng)
    tf(burst, burst)
    assert noise_sigma(burst) > 3 * tf.sigma
    assert tf.sigma == pytest.approx(float(np.median([*each, noise_sigma(burst)])), rel=1e-12)
    assert tf.sigma < 1.1 * max(each)


def test_the_light_fit_on_clipped_rounded_and_other_views() -> None:
    """``_brightness_change`` on a synthetic mean and frame: pixels the brighter light clips at
    255 are left out (measured 1.29990 for 1.3; with them 1.2986, with 250-254 counted as
    unclipped 1.2946); a noiseless camera's rounding to whole levels is within the fit's noise
    floor of 1 (with sigma 0 the fit held no pixel: another view); another view of the same
    brightness fits under half of the pixels (the gain of sums was 1.003); nine lit pixels are
    nothing to fit (gain 1), not another view."""
    from stereovision.temporal import _brightness_change

    rng = np.random.default_rng(20)
    mean = rng.uniform(20, 254, (64, 64)).astype(np.float32)
    clipped = np.clip(np.round(1.3 * mean), 0, 255).astype(np.float32)
    assert (clipped == 255).mean() > 0.2
    assert _brightness_change(clipped - mean, mean, 1.0) == pytest.approx(1.3, abs=3e-4)
    rounded = np.round(1.3 * mean).astype(np.float32)  # not clipped: a float frame
    assert _brightness_change(rounded - mean, mean, 0.0) == pytest.approx(1.3, abs=3e-4)
    other = rng.uniform(20, 230, (64, 64)).astype(np.float32)
    assert _brightness_change(other - mean, mean, 2.0) is None
    dark = np.zeros((64, 64), np.float32)
    dark[::4, ::4][:3, :3] = 100  # 9 of the 256 pixels the fit samples
    assert _brightness_change(np.zeros_like(dark), dark, 1.0) == 1.0


def test_an_overexposed_window_stays_out_of_the_motion_test(data_dir: Path) -> None:
    """Venus (grey, noise 4) with its left 40 % clipped at 255 (a window), then the light
    dimmed by 10 %: the window stays 255 while its relit mean reads 229.5, so it is left out of
    the motion test (under half of the view) and the rig is not taken for moving (measured: no
    restart, the window's pixels restart alone, 3.4 frames a pixel; with the window counted, or
    250-254 taken as unclipped, the rig restarted)."""
    grey = cv2.cvtColor(load_scene(data_dir / VENUS).left, cv2.COLOR_BGR2GRAY).astype(np.float32)
    rng = np.random.default_rng(20)
    cut = int(0.4 * grey.shape[1])

    def frame(gain: float) -> np.ndarray:
        f = np.clip(gain * grey + rng.normal(0, 4, grey.shape), 0, 255)
        f[:, :cut] = 255
        return f.astype(np.uint8)

    tf = TemporalFilter()
    for _ in range(4):
        f = frame(1.0)
        tf(f, f)
    assert tf.restarts == 0 and tf.relit == 0
    f = frame(0.9)
    tf(f, f)
    assert tf.restarts == 0 and tf.relit == 2
    assert tf.mean_frames() == pytest.approx(0.6 * 5 + 0.4 * 1, abs=0.01)


def test_a_view_three_times_brighter_restarts_too() -> None:
    """The gain's upper bound: a frame three times as bright as the mean (over 2) is another
    view, as a third is (with the bound at 5 it was relit, both images, and averaged on)."""
    rng = np.random.default_rng(14)
    base = rng.integers(30, 80, (40, 40)).astype(np.uint8)
    tf = TemporalFilter()
    tf(base, base)
    tf(base, base)
    bright = base * np.uint8(3)
    out = tf(bright, bright)
    assert np.array_equal(out[0], bright) and np.array_equal(out[1], bright)
    assert tf.restarts == 1 and tf.relit == 0 and tf.mean_frames() == 1.0


def test_a_second_mutation_audit_of_the_filters_edges() -> None:
    """A second mutation audit found unasserted: noise_sigma refusing a frame 2 px wide (only
    one 2 px tall was), a uint16 frame divided by 257 (256 was within the 1 % allowed), max_frames
    1 taken and k 0 refused, (H, W) and (H, W, 1) frames called a pair, and a restart handing
    back the caller's own arrays (writing to the output changed the input)."""
    with pytest.raises(ValueError, match=re.escape("at least 3 x 3, got (5, 2)")):
        noise_sigma(np.zeros((5, 2), np.uint8))
    rng = np.random.default_rng(0)
    img = rng.integers(20, 230, (40, 50), dtype=np.uint8)
    as16 = noise_sigma(img.astype(np.uint16) * np.uint16(257))
    assert as16 == pytest.approx(noise_sigma(img.astype(np.float32)), rel=1e-6)
    assert TemporalFilter(max_frames=1).max_frames == 1
    with pytest.raises(ValueError, match="k: expected a positive number of sigmas, got 0"):
        TemporalFilter(k=0)
    grey = np.full((8, 8), 100, np.uint8)
    with pytest.raises(ValueError, match="left and right differ in shape"):
        TemporalFilter()(grey, grey[..., None])
    tf = TemporalFilter()
    out = tf(grey, grey)
    assert not np.shares_memory(out[0], grey) and not np.shares_memory(out[1], grey)


def test_mean_frames_counts_both_images() -> None:
    """mean_frames() averages both cameras' counts (the left one alone passed): a patch that
    changes in the right image only restarts there, and the mean says so."""
    left = np.full((80, 80), 100, np.uint8)
    right = left.copy()
    tf = TemporalFilter()
    tf(left, right)
    moved = right.copy()
    moved[:10, :10] = 160  # 100 of 6400 px: something moved in the right view
    tf(left, moved)
    assert tf.restarts == 0
    assert tf.mean_frames() == pytest.approx((2.0 + (2.0 - 100 / 6400)) / 2)


def test_a_moving_rig_without_blue_behind_a_black_border_starts_again(data_dir: Path) -> None:
    """Black is all three colour channels at 0: a view without blue (a red-lit scene) behind a
    black border, moving 2 px a frame, restarts each frame (a mutant reading black off the blue
    channel alone took the whole view for black, kept the border in: 0 restarts of 5)."""
    img = load_scene(data_dir / VENUS).left
    h, w = img.shape[:2]
    rng = np.random.default_rng(0)
    tf = TemporalFilter()
    for i in range(6):
        shift = np.float32([[1, 0, 2 * i], [0, 1, 0]])
        frame = noisy(cv2.warpAffine(img, shift, (w, h), borderMode=cv2.BORDER_REFLECT), 8.0, rng)
        frame[..., 0] = 0
        frame[:, :200] = 0
        tf(frame, frame)
    assert tf.restarts == 5 and tf.mean_frames() == 1.0


def test_a_noiseless_view_restarts_a_pixel_changed_by_two_levels() -> None:
    """With noise 0 the per-pixel limit k * sigma is 0: a pixel changed by 2 grey levels starts
    again there (a floor of 1 grey level on sigma passed every test and averaged it to 101)."""
    left = np.full((80, 80), 100, np.uint8)
    tf = TemporalFilter()
    tf(left, left)
    changed = left.copy()
    changed[:10, :10] = 102
    out = tf(changed, changed)
    assert tf.restarts == 0 and tf.relit == 0
    assert np.array_equal(out[0], changed) and np.array_equal(out[1], changed)
    assert tf.mean_frames() == pytest.approx(2.0 - 100 / 6400)


def test_the_light_range_is_inclusive_and_a_dark_object_is_no_light_change() -> None:
    """A gain of exactly 0.5 or 2 is a light's change (relit, kept averaging), 0.49
    is another view; and a black object over 40 % of a still view is something that moved there,
    not a darker light (a mutant fitting the light on pixels gone black took the pair for
    another view and restarted both means)."""
    for before, after, restarts, relit in ((100, 50, 0, 2), (50, 100, 0, 2), (100, 49, 1, 0)):
        tf = TemporalFilter()
        a, b = np.full((40, 40), before, np.uint8), np.full((40, 40), after, np.uint8)
        tf(a, a)
        out = tf(b, b)
        assert (tf.restarts, tf.relit) == (restarts, relit), (before, after)
        assert np.array_equal(out[0], b)
    view = np.full((40, 40), 100, np.uint8)
    dark = view.copy()
    dark[:, :16] = 0
    tf = TemporalFilter()
    tf(view, view)
    out = tf(dark, dark)
    assert tf.restarts == 0 and np.array_equal(out[0], dark)
    assert tf.mean_frames() == pytest.approx(1.6)  # restarted under the object only


def test_the_noise_is_read_on_the_flattest_30_percent(data_dir: Path) -> None:
    """Venus' noise measured on its flattest 30 % (a mutant on 50 % stayed inside the bounds
    of test_noise_sigma_measures_sensor_noise): 0.93 as given, 5.72 with noise 8."""
    img = load_scene(data_dir / VENUS).left
    assert noise_sigma(img) == pytest.approx(0.9276, rel=0.01)
    assert noise_sigma(noisy(img, 8.0, np.random.default_rng(0))) == pytest.approx(5.718, rel=0.01)


def test_the_light_fit_band_ends() -> None:
    """``_brightness_change`` fits on grey levels strictly inside 5-250 in both the mean and the
    frame (a third mutation audit left each end, its constant and its comparison, unasserted): a
    pixel at 5 or 250 is left out, one at 6 or 249 is fitted. Each case is 224 pixels lit by a
    clear gain and 16 + 16 on either side of one end, on the fit's every-4th-pixel grid."""
    from stereovision.temporal import _brightness_change

    def fit(groups: list[tuple[int, float, float]], sigma: float = 2.0) -> float | None:
        pairs = [(m, f) for count, m, f in groups for _ in range(count)]
        mean = np.zeros((64, 64), np.float32)
        frame = np.zeros((64, 64), np.float32)
        mean[::4, ::4] = np.array([m for m, _ in pairs], np.float32).reshape(16, 16)
        frame[::4, ::4] = np.array([f for _, f in pairs], np.float32).reshape(16, 16)
        return _brightness_change(frame - mean, mean, sigma)

    # (count, mean, frame); the expected gain sums the groups inside the band by hand
    cases = [
        ([(224, 100, 110), (16, 5, 8), (16, 6, 9)], (224 * 110 + 16 * 9) / (224 * 100 + 16 * 6)),
        ([(224, 100, 110), (16, 8, 5), (16, 9, 6)], (224 * 110 + 16 * 6) / (224 * 100 + 16 * 9)),
        (
            [(224, 100, 101), (16, 250, 249), (16, 249, 248)],
            (224 * 101 + 16 * 248) / (224 * 100 + 16 * 249),
        ),
        (
            [(224, 100, 101), (16, 249, 250), (16, 248, 249)],
            (224 * 101 + 16 * 249) / (224 * 100 + 16 * 248),
        ),
    ]
    for groups, gain in cases:
        assert fit(groups) == pytest.approx(gain, rel=1e-12), groups
    # 16 usable pixels are enough to fit (gain 1.2, not the "nothing to fit" 1.0)
    assert fit([(16, 100, 120), (240, 0, 0)]) == pytest.approx(1.2, rel=1e-12)
    # the fit holding exactly half of the pixels is a light's change, under half another view:
    # the 64 + 64 pixels 30 levels off the gain 1.1 cancel in the sums and fall out of the refit
    assert fit([(128, 100, 110), (64, 50, 85), (64, 50, 25)], 1.0) == pytest.approx(1.1)
    assert fit([(127, 100, 110), (1, 100, 200), (64, 50, 85), (64, 50, 25)], 1.0) is None
    # a refit on fewer than 16 pixels is no fit: 12 of 24 usable at the gain 1.1 (exactly half
    # kept), 12 off it by 20 levels (a mutation audit's survivor: refitted on 12, it said 1.1)
    assert fit([(12, 100, 110), (6, 100, 130), (6, 100, 90), (232, 0, 0)], 1.0) is None


@pytest.mark.parametrize(
    ("kind", "share", "restarts"),
    [
        ("grey", 0.4, [0, 0, 0, 0, 0]),
        ("grey", 0.5, [0, 0, 0, 0, 1]),
        ("bgr", 0.4, [0, 0, 0, 0, 0]),
        ("bgra", 0.4, [0, 0, 0, 0, 0]),
    ],
)
def test_the_motion_tests_saturation_rule(kind: str, share: float, restarts: list[int]) -> None:
    """A window clipped at 250 or above stays out of the motion test when the light dims 10 %
    (its relit mean reads ~25 below it), under half of the view; at exactly half it counts, and
    the pair restarts. Synthetic: a ramp with noise 4, the window 255 with its sampled pixels
    (every 4th) at 250 in grey, or blue 220 in colour (saturated is the brightest of B, G and R,
    not their mean, and not the alpha); the 255s keep the window out of the noise estimate. A
    third mutation audit left ``>= 250``, the constant, the channels and ``< 0.5`` unasserted."""
    rng = np.random.default_rng(0)
    h, w = 96, 160
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    ramp = 60 + 0.6 * x + 0.5 * y
    cut = round(w * (1 - share))
    tf = TemporalFilter()
    seen = []
    for gain in (1.0, 1.0, 1.0, 1.0, 0.9):
        shape = ramp.shape if kind == "grey" else (h, w, 3)
        lit = ramp if kind == "grey" else ramp[..., None]
        f = np.clip(np.round(gain * lit + rng.normal(0, 4, shape)), 0, 255)
        f[:, cut:] = 255
        if kind == "grey":
            f[::4, cut::4] = 250
        else:
            f[::4, cut::4, 0] = 220  # grey 251: out of the light's fit too
        if kind == "bgra":
            f = np.concatenate([f, np.full((h, w, 1), 255.0)], axis=2)
        frame = f.astype(np.uint8)
        tf(frame, frame)
        seen.append(tf.restarts)
    assert seen == restarts
    # not restarted: the view averaged 5 frames, the window's pixels restarted alone
    expected = 1.0 if restarts[-1] else (1 - share) * 5 + share * 1
    assert tf.mean_frames() == pytest.approx(expected, abs=0.03)


@pytest.mark.parametrize("level", [1, 254])
def test_noise_beside_clipped_pixels_is_left_out(level: int) -> None:
    """Noise 8 on a flat grey 128, beside a region at ``level`` whose noise clips at 0 or 255
    over most of the view (a dark corner, a saturated sky): the clipped pixels' unclipped
    neighbours, whose Laplacian sees a clipped value, are left out with them. A mutation audit
    of a stream left that erosion unasserted: without it the estimate read 5.9-6.0, not ~8."""
    rng = np.random.default_rng(0)
    img = np.full((240, 320), 128.0)
    img[:, :256] = level
    img = np.clip(np.round(img + rng.normal(0, 8, img.shape)), 0, 255).astype(np.uint8)
    assert noise_sigma(img) == pytest.approx(8.0, abs=0.5)


def test_a_light_that_saturates_part_of_the_view_keeps_averaging_there() -> None:
    """A ramp with noise 4 and a strip at 235 lit 15 % brighter: the strip clips at 255 and
    its relit mean (235 * 1.15 = 270) is clipped to the frame's range, so the strip agrees with
    the frame and keeps averaging with the rest (5 frames of 5 nearly everywhere, output 255 bar
    a few). A mutation audit of a stream left that clip unasserted: unclipped, the strip's pixels
    restarted (4.59 frames on average)."""
    rng = np.random.default_rng(1)
    base = np.tile(np.linspace(40, 200, 320), (240, 1))
    base[:, 280:] = 235
    tf = TemporalFilter()
    for gain in (1.0, 1.0, 1.0, 1.0, 1.15):
        frame = np.clip(np.round(base * gain + rng.normal(0, 4, base.shape)), 0, 255)
        out, _ = tf(frame.astype(np.uint8), frame.astype(np.uint8))
    assert tf.restarts == 0 and tf.relit == 2
    assert np.mean(out[:, 280:] == 255) > 0.99  # a few means relit to 253-254
    assert tf.mean_frames() > 4.9, tf.mean_frames()


def test_a_one_percent_change_of_light_is_relit() -> None:
    """A light 1 % brighter on a still ramp with noise 4 relights both means (above the 0.2 %
    tolerance; a mutation audit raised it to 2 % and no test failed): averaging goes on, and
    the output follows the new light (within a level), not a blend of the two."""
    rng = np.random.default_rng(2)
    base = np.tile(np.linspace(40, 200, 320), (240, 1))
    tf = TemporalFilter()
    for gain in (1.0, 1.0, 1.0, 1.0, 1.01):
        frame = np.clip(np.round(base * gain + rng.normal(0, 4, base.shape)), 0, 255)
        out, _ = tf(frame.astype(np.uint8), frame.astype(np.uint8))
    assert (tf.restarts, tf.relit) == (0, 2)
    assert np.abs(out.astype(float) - base * 1.01).mean() < 2.0


def test_a_reset_filter_behaves_as_a_new_one(data_dir: Path) -> None:
    """reset() forgot the means only: the noise median of the frames before, `frames`,
    `restarts`, `relit` and `sigma` carried over, so a reset filter fed a quiet scene after a
    noisy one restarted, relit and averaged otherwise than a new filter. After a reset every
    output and counter equals a new filter's on the same frames."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(11)
    h, w = sc.left.shape[:2]

    def frames(sigma: float) -> list[tuple[np.ndarray, np.ndarray]]:
        out = []
        for k in range(6):  # a flickering light, then a drift of 1 px a frame
            gain = 1.0 + 0.04 * np.sin(2.1 * k)
            shift = np.float32([[1, 0, -max(0, k - 3)], [0, 1, 0]])
            pair = []
            for img in (sc.left, sc.right):
                lit = np.clip(img * gain, 0, 255).astype(np.uint8)
                moved = cv2.warpAffine(lit, shift, (w, h), borderMode=cv2.BORDER_REPLICATE)
                pair.append(noisy(moved, sigma, rng) if sigma else moved)
            out.append((pair[0], pair[1]))
        return out

    used = TemporalFilter(max_frames=4, k=2.5)
    for pair in frames(12.0):
        used(*pair)
    assert used.frames == 6 and used.restarts > 0 and used.relit > 0 and used.sigma > 5
    used.reset()
    fresh = TemporalFilter(max_frames=4, k=2.5)
    counters = ("frames", "restarts", "relit", "sigma")
    assert [getattr(used, c) for c in counters] == [getattr(fresh, c) for c in counters]
    assert used.mean_frames() == 0.0
    for pair in frames(2.0):
        a, b = used(*pair), fresh(*pair)
        assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
        assert [getattr(used, c) for c in counters] == [getattr(fresh, c) for c in counters]
        assert used.mean_frames() == fresh.mean_frames()
    # the noise estimates and the means themselves too
    assert list(used._sigmas) == list(fresh._sigmas)
    for m, n in zip(used._means, fresh._means, strict=True):
        assert np.array_equal(m.mean, n.mean) and np.array_equal(m.count, n.count)


def test_int_levels_of_every_integer_type_read_as_their_uint8_image(data_dir: Path) -> None:
    """A mutation audit: unsigned types other than uint8 and uint16 (uint32, uint64) were not
    asserted to be read as their uint8 image, nor the edges of 0-255 (255 taken, 256 and -1
    refused, -1 as negative, not as 16-bit)."""
    img = noisy(load_scene(data_dir / VENUS).left, 8.0, np.random.default_rng(0))
    want = noise_sigma(img)
    for dtype in (np.uint32, np.uint64, np.int16, ">i4"):
        assert noise_sigma(img.astype(dtype)) == want > 4.8
    edge = img.astype(np.int32)
    edge[0, 0] = 255
    assert noise_sigma(edge) == noise_sigma(edge.astype(np.uint8))
    edge[0, 0] = 256
    with pytest.raises(ValueError, match=r"got 0-256 \(a 16-bit image: pass it as uint16\)$"):
        noise_sigma(edge)
    edge[0, 0] = -1
    with pytest.raises(ValueError, match=r"got -1-255 \(a grey level cannot be negative\)$"):
        noise_sigma(edge)


def test_black_frames_before_a_still_scene_are_no_estimate_of_its_noise(data_dir: Path) -> None:
    """A webcam's black frames while it starts have no unclipped pixel, so no noise estimate:
    counted as noise 0 they held the median at 0 (then at half the noise), and of the still
    scene's first frames after 6 of them 4 were taken for motion and not averaged (4 restarts,
    not 1)."""
    sc = load_scene(data_dir / VENUS)
    rng = np.random.default_rng(21)
    tf = TemporalFilter()
    black = np.zeros_like(sc.left)
    for _ in range(6):
        tf(black, black)
    assert tf.sigma == 0.0 and tf.restarts == 0
    each = []
    for _ in range(5):
        left = noisy(sc.left, 8.0, rng)
        each.append(noise_sigma(left))
        tf(left, noisy(sc.right, 8.0, rng))
    assert tf.restarts == 1  # the black view to the scene, once
    assert tf.sigma == pytest.approx(float(np.median(each)), rel=1e-12)
    assert tf.mean_frames() == pytest.approx(5.0, abs=0.05)
    assert noise_sigma(black) == 0.0  # the function itself still says 0 for "no noise seen"


@pytest.mark.parametrize(
    ("red", "gains", "fit"),
    [
        (400.0, (1.0, 1.0, 1.0, 0.96), 0.96),  # clipped in the mean (and the frame)
        (280.0, (1.0, 1.0, 1.0, 0.8), 0.8),  # clipped in the mean only (224 in the frame)
        (220.0, (1.0, 1.0, 1.0, 1.3), 1.3),  # clipped in the brighter frame only
    ],
)
def test_a_clipped_colour_channel_is_no_part_of_the_lights_fit(
    data_dir: Path, red: float, gains: tuple[float, ...], fit: float
) -> None:
    """A red object over a fifth of art's view, its red channel clipped at 255 where the grey
    stays well inside 5-250: it does not follow the light. Fitted on grey alone, a 4 % dimming
    read 3.4 % (1.3 brighter: 1.278), the relit means were off, and the still rig was taken for
    moving (1 restart, nothing averaged); the channels clipped in the mean or the frame are left
    out now, as _SATURATED says."""
    from stereovision.temporal import _brightness_change

    sc = load_scene(data_dir / "middlebury2005" / "art")
    scene = sc.left.astype(np.float64) * (0.7 if red < 255 else 1.0)
    scene[:, : scene.shape[1] // 5, 2] = red
    rng = np.random.default_rng(22)
    tf = TemporalFilter()
    for gain in gains:
        frame = noisy(scene * gain, 4.0, rng)
        mean = tf._means[0].mean.copy() if tf._means else None
        tf(frame, frame)
    assert tf.restarts == 0 and tf.relit == 2
    assert tf.mean_frames() > 3.7
    assert mean is not None
    diff = sv._core.temporal_grey_difference(frame, mean)
    # within 3e-3: noisy() truncates, both frame and mean half a level low
    assert _brightness_change(diff, mean, tf.sigma, frame) == pytest.approx(fit, abs=3e-3)


def test_a_large_k_restarts_no_pixel_even_at_the_largest_grey_difference(data_dir: Path) -> None:
    """Mutation audit of the k cap (_KS_MAX): it must lie past any grey difference, so that a
    large k restarts no pixel, as documented. A 12 x 12 px patch black in one pair and white in
    the next (a difference of 255) is averaged to mid-grey by k = 1e38 (capped) and 1e4 alike;
    a cap at 100 grey levels restarted it (255 out)."""
    sc = load_scene(data_dir / VENUS)
    first = [sc.left.copy(), sc.right.copy()]
    second = [sc.left.copy(), sc.right.copy()]
    for img in first:
        img[100:112, 200:212] = 0
    for img in second:
        img[100:112, 200:212] = 255
    for k in (1e38, 1e4):
        filt = TemporalFilter(k=k)
        filt(*first)
        out = filt(*second)
        assert filt.restarts == 0
        for img in out:
            assert set(np.unique(img[100:112, 200:212])) <= {127, 128}, k


def test_a_dropped_frame_or_a_path_is_named_as_no_image() -> None:
    """A frame the camera dropped (``cap.read()``'s None) or a file cv2.imread could not read
    was "left: expected a uint8 image, got object" (a path: "got <U10"), and noise_sigma's
    "expected an (H, W) or (H, W, C) image ..., got ()"; they are said in the package's words,
    and no frame is counted."""
    img = np.zeros((20, 20), np.uint8)
    tf = TemporalFilter()
    with pytest.raises(ValueError, match=r"^right: got None, not an image \(cv2\.imread returns"):
        tf(img, None)
    with pytest.raises(ValueError, match=r"^left: got the path '/tmp/l\.png', not an image"):
        tf("/tmp/l.png", "/tmp/r.png")
    assert tf.frames == 0
    with pytest.raises(ValueError, match=r"^image: got None, not an image"):
        noise_sigma(None)
    with pytest.raises(ValueError, match=r"^image: got the path 'left\.png', not an image"):
        noise_sigma("left.png")


def test_a_noisy_still_rig_is_not_relit_by_its_noise(data_dir: Path) -> None:
    """A still rig with noise 25 in a steady light: the light's fit scatters past _GAIN_TOL on
    such frames, and the means were relit on nearly every frame by the noise alone (measured on
    this crop: 13 of the 14 images after the first pair; 152 of 150 pairs at 200 x 250), the
    output's brightness wandering with it. A gain within 3 standard errors of the fit's 1 is the
    noise's now: no relight; a real change of light on the same frames is still followed."""
    left, right = (
        cv2.imread(str(data_dir / VENUS / f"{side}.png"))[:120, :150] for side in ("left", "right")
    )
    rng = np.random.default_rng(1)
    tf = TemporalFilter()
    for _ in range(8):
        tf(noisy(left, 25.0, rng), noisy(right, 25.0, rng))
    assert tf.relit == 0 and tf.restarts == 0
    dim = [np.clip(img * 0.8, 0, 255).astype(np.uint8) for img in (left, right)]
    tf(noisy(dim[0], 25.0, rng), noisy(dim[1], 25.0, rng))
    assert tf.relit == 2 and tf.restarts == 0
