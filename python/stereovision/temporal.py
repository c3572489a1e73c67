"""Temporal averaging of a still rig's frames: less sensor noise for the matchers.

A camera in low light is noisy, and noise is what the matchers handle worst (docs/robotics.md,
"Cameras that expose differently"): 8 grey levels of it take the default map on wood2 from
0.63 to 19.32 % bad-2.0. A rig that holds still (a fixed mount over a work cell, a robot that
stops to look) sees the same scene frame after frame, and the mean of ``n`` frames has
``1 / sqrt(n)`` of one frame's noise. :class:`TemporalFilter` keeps a running mean of each
camera's frames while the scene holds still and starts again where it does not:

- **The rig moves** (or the whole view changes): the median absolute difference between the
  new frame and the mean, both Gaussian-blurred (sigma 1.5 px, which leaves about a fifth of the
  noise and all of the structure), exceeds what the noise alone gives (:data:`MOTION_MARGIN`
  times its expected value). Both cameras start again from the new pair: a moving rig's mean
  would be a smear.
- **Something moves in a still scene**: a pixel that differs from its mean by more than
  ``k`` noise sigmas (of the difference of a frame and an ``n``-frame mean) starts again there.
- **The light changes** (a lamp that flickers, an auto-exposure step): before those tests the
  mean is brought to the new frame's brightness, ``gain * mean``, the gain a ratio of grey sums
  over every 16th pixel, refitted on those within 3 noise sigmas (a moving object is not a
  change of light); a gain outside 0.5-2 counts as another view, one within 3 of the fit's
  standard errors of 1 as none (the noise's).
- **The noise**: estimated from each frame itself (:func:`noise_sigma`, a Laplacian's mean over
  the image's flattest 30 %; Immerkaer 1996), the median of the last 8 frames' estimates (a
  frame all black or white has none, and is left out; a new frame size starts them again).

A still, noiseless pair comes out unchanged (the mean of equal frames is the frame).

Give it the frames as the cameras deliver them, before rectification or resizing: their
interpolation spreads each pixel's noise over its neighbours, the estimate then reads a fraction
of it (1.1 instead of 5.7 grey levels after a half-pixel shift), and the motion test takes every
frame of a still rig for a moving one.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import cv2
import numpy as np
import numpy.typing as npt

from stereovision import _core
from stereovision._validate import (
    NOT_NUMBERS,
    check_index_range,
    real_number,
    refuse_no_image,
)

__all__ = ["MOTION_MARGIN", "TemporalFilter", "noise_sigma"]

#: The rig counts as moving when the blurred difference's median exceeds this many times what
#: noise alone would give it.
MOTION_MARGIN = 1.3
#: Gaussian sigma (px) of the blur the motion test compares.
_BLUR = 1.5
#: Share of the noise's standard deviation left by that blur: ``1 / (2 sqrt(pi) sigma)`` for
#: white noise under a 2-D Gaussian.
_BLUR_GAIN = 1.0 / (2.0 * np.sqrt(np.pi) * _BLUR)
#: Median of ``|x|`` for a zero-mean normal ``x`` of unit standard deviation.
_HALF_NORMAL_MEDIAN = 0.6745
#: Every how many pixels (in each direction) the image-wide statistics are taken (medians and
#: percentiles of a quarter-million values cost milliseconds; every 16th pixel says the same).
_STRIDE = 4
#: Fewest sampled pixels a motion test's median is taken over once black ones are left out (a
#: tenth of the sample where that is fewer).
_MIN_SAMPLES = 64


#: A brightness change smaller than this gain is left alone: a still, noiseless pair stays bit
#: for bit the frame, and a noisy one is not rescaled by its noise (the ratio's own scatter is
#: about 5e-4 with noise 8 at 640x480).
_GAIN_TOL = 0.002
#: A pixel with a channel at or above this value may be clipped: it does not follow a change
#: of light, so the light's fit and the motion test leave it out.
_SATURATED = 250
#: Gains outside this range are not a light's change but another view.
_GAIN_RANGE = (0.5, 2.0)
#: Cap of the per-pixel restart threshold ``k * sigma`` (grey levels): past any grey
#: difference, and within float32, the kernel's type.
_KS_MAX = 1e6


def _brightness_change(
    diff: npt.NDArray[np.float32],
    mean: npt.NDArray[np.float32],
    sigma: float,
    frame: npt.NDArray[np.uint8] | None = None,
) -> float | None:
    """The gain with ``frame ~ gain * mean`` in grey (a light or an exposure scales what the
    camera sees), from every :data:`_STRIDE`-th pixel off the clipped ends: the ratio of the
    sums, refitted on the pixels within 3 noise sigmas (a moving object is not a change of
    light). A ratio of sums, not a least-squares slope: the mean's own noise would bias a slope
    low and wash the mean's contrast out frame by frame. None when the fit holds for under half
    of the pixels or leaves :data:`_GAIN_RANGE` (another view). Colour pixels with a channel at
    :data:`_SATURATED` in the mean or in ``frame`` (the frame of ``diff``) are left out too."""
    sub = mean[::_STRIDE, ::_STRIDE]
    m = _grey(np.ascontiguousarray(sub)).ravel().astype(np.float64)
    f = m + diff[::_STRIDE, ::_STRIDE].ravel()
    usable = (m > 5) & (m < _SATURATED) & (f > 5) & (f < _SATURATED)
    if sub.ndim == 3 and sub.shape[2] >= 3:
        # one clipped channel leaves the grey well inside 5-250 but does not follow the light:
        # a red object clipped over a fifth of art's view read a 4 % dimming as 3.4 % (a 30 %
        # brightening as 27.8 %), and the still rig was taken for moving (1 restart of 1)
        usable &= sub[..., :3].max(axis=2).ravel() < _SATURATED
        if frame is not None:
            usable &= frame[::_STRIDE, ::_STRIDE, :3].max(axis=2).ravel() < _SATURATED
    if usable.sum() < 16:
        return 1.0  # a nearly black or white view: nothing to fit, nothing to relight
    m, f = m[usable], f[usable]
    keep = np.ones(m.shape, bool)
    gain = 1.0
    for _ in range(3):
        if keep.sum() < 16:
            return None
        gain = float(f[keep].sum() / m[keep].sum())
        keep = np.abs(f - gain * m) <= 3.0 * max(sigma, 1.0) * np.sqrt(2.0)
    if not _GAIN_RANGE[0] <= gain <= _GAIN_RANGE[1] or keep.mean() < 0.5:
        return None
    # A gain within 3 standard errors of 1 is the noise's, not a light's: with noise 25 on
    # every frame of a still rig the mean was relit on 152 frames of 150 by the scatter alone
    # (past _GAIN_TOL on small or noisy frames), and the output's brightness wandered
    # (-0.9 grey levels against -0.5 unrelit; at noise 40, -2.0 against -0.4).
    residual = f[keep] - gain * m[keep]
    if abs(gain - 1.0) <= 3.0 * float(np.sqrt(np.sum(residual**2)) / m[keep].sum()):
        return 1.0
    return gain


def _grey(img: np.ndarray) -> npt.NDArray[np.float32]:
    # A float64 level past float32's range becomes inf, which reads as clipped (left out) as
    # any level over 255 does; the cast's overflow RuntimeWarning (1e40 in a frame) said
    # nothing the result does not.
    with np.errstate(over="ignore"):
        if img.ndim == 3 and img.shape[2] == 1:
            img = img[..., 0]
        elif img.ndim == 3:
            if img.dtype not in (np.uint8, np.uint16, np.float32):
                # cvtColor takes only these: a float64, float16 or int colour image (a list's
                # int64) raised OpenCV's own cv2.error
                img = img.astype(np.float32)
            code = cv2.COLOR_BGRA2GRAY if img.shape[2] == 4 else cv2.COLOR_BGR2GRAY
            img = cv2.cvtColor(img, code)
        return np.asarray(img, dtype=np.float32)


def noise_sigma(image: npt.ArrayLike) -> float:
    """Standard deviation of an image's noise in grey levels, from the image itself.

    Immerkaer's estimate (the mean absolute response of a Laplacian difference kernel that
    cancels planes, ``sqrt(pi / 2) / 6`` of it) over the 30 % of pixels with the smallest
    gradient, where texture least passes for noise. Clipped pixels (grey 0 or 255: a black
    border, a saturated sky) and their neighbours are left out: noise does not show there.

    Parameters
    ----------
    image : array_like
        ``(H, W)`` grey or ``(H, W, 1|3|4)`` BGR(A) image, 0-255 (``uint8`` or float), or
        ``uint16`` (0-65535, measured in 8-bit grey levels: divided by 257, as
        :func:`stereovision.depth_map` scales it).

    Returns
    -------
    float
        Measured: 5.2-6.6 grey levels on the 17 GT scenes' left images with Gaussian noise of 8
        on each colour channel (5.3 on the grey image), 0.3-3.7 on the images as given (fine
        texture passes for some noise). 0 for an image without an unclipped pixel.

    Raises
    ------
    ValueError
        If the image is None (``cv2.imread``'s answer for a file it cannot read) or a path, is
        not 2-D grey or 3-D colour of 1, 3 or 4 channels, is smaller than
        3 x 3, is not of numbers (bool, complex), or is of integers other than uint16 outside
        0-255 (an int image's levels in 0-255 read as its uint8 image).
    """
    estimate = _measured_noise(image)
    return 0.0 if estimate is None else estimate


def _measured_noise(image: npt.ArrayLike) -> float | None:
    """:func:`noise_sigma`, None where it has no pixel to measure (all black or white) rather
    than its 0: the stream's summary said such a frame's noise was 0.0."""
    refuse_no_image(image, "image")
    img = np.asarray(image)
    if img.ndim not in (2, 3) or img.shape[0] < 3 or img.shape[1] < 3:
        raise ValueError(
            f"image: expected an (H, W) or (H, W, C) image of at least 3 x 3, got {img.shape}"
        )
    if img.ndim == 3 and img.shape[2] not in (1, 3, 4):
        # OpenCV's colour conversion raised its own error (cv2.error, not a ValueError)
        raise ValueError(f"image: expected 1, 3 or 4 channels, got {img.shape[2]}")
    check_index_range(img.shape, "image")  # before the float32 and grey copies
    if img.dtype == np.bool_ or not (
        np.issubdtype(img.dtype, np.integer) or np.issubdtype(img.dtype, np.floating)
    ):
        raise ValueError(f"image: expected grey levels (uint8, uint16 or float), got {img.dtype}")
    if img.dtype.kind == "u" and img.dtype.itemsize == 2:  # of either byte order
        # 0-65535: every pixel over 255 counted as clipped, and the noise came out 0 (so it
        # still did for a big-endian '>u2' frame, which is not np.uint16)
        img = img.astype(np.float32) / np.float32(257.0)
    elif img.dtype.kind in "iu" and img.dtype != np.uint8:
        # int levels (a nested list's int64): a colour image was measured as float, unrounded
        # grey (5.718 where its uint8 image reads 5.700), 16-bit levels all as clipped (0)
        lo, hi = int(img.min()), int(img.max())
        if lo < 0 or hi > 255:
            # uint16 cannot hold a negative level: no advice to pass -5 as one
            why = (
                "a grey level cannot be negative" if lo < 0 else "a 16-bit image: pass it as uint16"
            )
            raise ValueError(
                f"image: {img.dtype} grey levels must lie in 0-255, got {lo}-{hi} ({why})"
            )
        img = img.astype(np.uint8)
    return _noise_estimate(img)


def _noise_estimate(img: np.ndarray) -> float | None:
    """:func:`noise_sigma` of an image it has checked and converted (uint8 or float levels,
    0-255); None where it has no unclipped pixel to measure (all black or white)."""
    g = _grey(img)
    lap = np.array([[1, -2, 1], [-2, 4, -2], [1, -2, 1]], np.float32)
    resp = np.abs(cv2.filter2D(g, -1, lap))[1:-1, 1:-1]
    grad = np.abs(cv2.Sobel(g, cv2.CV_32F, 1, 0)) + np.abs(cv2.Sobel(g, cv2.CV_32F, 0, 1))
    grad = grad[1:-1, 1:-1]
    # Clipped pixels (black 0, white 255) and their neighbours carry no noise: a rectified
    # frame's black border or a fisheye's black corners are the flattest pixels there are, and
    # over 30 % of them read noise 8 as 0 (the filter then restarted on every frame).
    unclipped = ((g > 0) & (g < 255)).astype(np.uint8)
    unclipped = cv2.erode(unclipped, np.ones((3, 3), np.uint8))[1:-1, 1:-1].astype(bool)
    if not unclipped.any():
        return None  # all black or white: no noise to see
    resp, grad = resp[unclipped], grad[unclipped]
    flat = grad <= np.percentile(grad[:: _STRIDE * _STRIDE], 30)
    return float(np.sqrt(np.pi / 2) * resp[flat].mean() / 6.0)


@dataclass
class _Mean:
    """One camera's running mean and, per pixel, how many frames it holds."""

    mean: npt.NDArray[np.float32]
    count: npt.NDArray[np.uint8]


# eq=False: == and hash by identity. The generated == compared the running means' arrays and
# raised NumPy's "truth value of an array ... is ambiguous" once a pair was seen (and left the
# filter unhashable).
@dataclass(eq=False)
class TemporalFilter:
    """Running mean of a still stereo rig's frames (see the module doc); call it on each pair.

    Parameters
    ----------
    max_frames : int
        Most frames a pixel's mean holds (8: the noise to about a third). Beyond it the mean
        follows new frames by ``1 / max_frames`` each, so a slow change (light) still comes
        through.
    k : float
        A pixel further from its mean than this many noise sigmas starts again (something moved
        there).

    Attributes
    ----------
    frames : int
        Pairs seen.
    restarts : int
        Pairs on which the rig was found moving (both means started again).
    sigma : float
        The current noise estimate (grey levels), 0 before the first pair with an unclipped
        pixel (a frame all black or white has no estimate).
    relit : int
        Images whose mean was brought to a new brightness (a light that flickers, an
        auto-exposure step) before the motion test.

    Examples
    --------
    >>> tf = TemporalFilter()
    >>> for frame in camera.frames():                                 # doctest: +SKIP
    ...     left, right = tf(frame.left, frame.right)
    ...     res = sv.depth_map(left, right, calib)
    """

    max_frames: int = 8
    k: float = 3.0
    # The state is no parameter (init=False): TemporalFilter(8, 3.0, 5) started at frames=5 and
    # TemporalFilter(sigma=2.0), read as a noise level, was overwritten by the first pair.
    frames: int = field(default=0, init=False)
    restarts: int = field(default=0, init=False)
    sigma: float = field(default=0.0, init=False)
    relit: int = field(default=0, init=False)
    _means: list[_Mean] = field(default_factory=list, init=False, repr=False)
    _sigmas: deque[float] = field(default_factory=lambda: deque(maxlen=8), init=False, repr=False)
    # the last frame's shape, kept when the means are forgotten (capture, after a saved pair)
    _shape: tuple[int, ...] | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.max_frames, (int, np.integer)) or isinstance(
            self.max_frames, NOT_NUMBERS
        ):
            raise ValueError(f"max_frames: expected an integer, got {self.max_frames!r}")
        if not 1 <= self.max_frames <= 255:
            raise ValueError(
                f"max_frames: expected at least 1 and at most 255, got {self.max_frames}"
            )
        if not real_number(self.k):
            raise ValueError(f"k: expected a positive number of sigmas, got {self.k!r}")
        # math, not np.isfinite: 2**70 was NumPy's TypeError "ufunc 'isfinite' not supported"
        try:
            finite = math.isfinite(self.k)
        except OverflowError:  # an int beyond a float
            finite = False
        if not (finite and self.k > 0):
            raise ValueError(f"k: expected a positive number of sigmas, got {self.k!r}")

    def reset(self) -> None:
        """Start afresh: the filter behaves as a new one of the same ``max_frames`` and ``k``
        (means, noise estimates and counters all forgotten)."""
        # it forgot the means only: the noise median of the frames before (another scene,
        # another gain) and the counters carried over into what followed
        self._forget_means()
        self._sigmas = deque(maxlen=self._sigmas.maxlen)
        self._shape = None
        self.frames = self.restarts = self.relit = 0
        self.sigma = 0.0

    def _forget_means(self) -> None:
        """Forget the means only (capture's next pair of the same still rig: its noise
        estimate and counters go on)."""
        self._means = []

    def mean_frames(self) -> float:
        """How many frames a pixel's running mean holds, on average.

        Returns
        -------
        float
            Mean number of frames in a pixel's mean over both images (0 before the first pair).
        """
        if not self._means:
            return 0.0
        return float(np.mean([m.count.mean() for m in self._means]))

    def __call__(
        self, left: npt.ArrayLike, right: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
        """The pair averaged over the frames the scene held still for.

        Parameters
        ----------
        left, right : array_like
            ``uint8`` images of one shape, ``(H, W)`` or ``(H, W, C)``.

        Returns
        -------
        left, right : numpy.ndarray
            ``uint8``, the shape given: the running means, rounded.

        Raises
        ------
        ValueError
            If an image is None (a frame the camera dropped, a file ``cv2.imread`` could not
            read) or a path, is not ``uint8``, or the two differ in shape.
        """
        refuse_no_image(left, "left")
        refuse_no_image(right, "right")
        imgs = [np.asarray(left), np.asarray(right)]
        for name, img in zip(("left", "right"), imgs, strict=True):
            if img.dtype != np.uint8:
                raise ValueError(f"{name}: expected a uint8 image, got {img.dtype}")
        if imgs[0].shape != imgs[1].shape:
            raise ValueError(f"left and right differ in shape: {imgs[0].shape} and {imgs[1].shape}")
        if imgs[0].ndim not in (2, 3) or (imgs[0].ndim == 3 and imgs[0].shape[2] not in (1, 3, 4)):
            raise ValueError(f"expected (H, W) or (H, W, 1|3|4) images, got shape {imgs[0].shape}")
        if min(imgs[0].shape[:2]) < 3:
            # noise_sigma's words named an "image" the caller never passed
            h, w = imgs[0].shape[:2]
            raise ValueError(
                f"left and right: {w}x{h} px, too small to measure their noise: images of at "
                "least 3 x 3 px are needed"
            )
        check_index_range(imgs[0].shape, "left")  # before the copies and the float32 means
        imgs = [np.ascontiguousarray(img) for img in imgs]
        self.frames += 1
        if self._shape is not None and self._shape != imgs[0].shape:
            # Another size is another camera mode (binning, a crop, another camera): its noise
            # is its own. The old median (8.3 from noise 12) let a clean (noise 2) rig moving
            # 1 px a pair average three pairs into a smear before its own estimates took over.
            # The last frame's shape, not the means': capture forgets those after each saved
            # pair, and a mode switched there kept the old median.
            self._sigmas.clear()
        self._shape = imgs[0].shape
        # A black (or white) frame has no estimate, not one of 0: a webcam's dark frames while
        # it starts took the median to 0 and the first still frames after them were each
        # "moving" (6 dark frames: 3 restarts more, the next 4 frames not averaged).
        estimate = _noise_estimate(imgs[0])
        if estimate is not None:
            self._sigmas.append(estimate)
        self.sigma = float(np.median(self._sigmas)) if self._sigmas else 0.0
        if not self._means or self._means[0].mean.shape != imgs[0].shape:
            return self._restart(imgs)
        # Grey value of frame - mean per pixel (Rust; tests/reference/temporal_ref.py), after
        # the mean is brought to the frame's brightness (flickering light, auto-exposure).
        diffs = []
        for img, m in zip(imgs, self._means, strict=True):
            d = _core.temporal_grey_difference(img, m.mean)
            gain = _brightness_change(d, m.mean, self.sigma, img)
            if gain is None:
                self.restarts += 1
                return self._restart(imgs)
            if abs(gain - 1.0) > _GAIN_TOL:
                if m.mean.ndim == 3 and m.mean.shape[2] == 4:
                    # alpha is no light: relit with the colours, a BGRA frame's opaque 255
                    # came out 214 after a 20 % dimming, and crept back over max_frames pairs
                    m.mean[..., :3] = np.clip(m.mean[..., :3] * np.float32(gain), 0, 255)
                else:
                    m.mean = np.clip(m.mean * np.float32(gain), 0, 255)
                self.relit += 1
                d = _core.temporal_grey_difference(img, m.mean)
            diffs.append(d)
        # The blurred difference of a frame and an n-frame mean, noise alone: a normal of
        # sigma * _BLUR_GAIN * sqrt(1 + 1/n); its median absolute value is 0.6745 of that.
        for img, d, m in zip(imgs, diffs, self._means, strict=True):
            blurred = cv2.GaussianBlur(d, (0, 0), _BLUR)[::_STRIDE, ::_STRIDE]
            sub = img[::_STRIDE, ::_STRIDE]
            top = sub[..., :3].max(axis=2) if sub.ndim == 3 else sub
            # Black pixels (a rectified frame's border, a fisheye's corners) stay black when
            # the rig moves: left out, or their zero differences pull the median down (a rig
            # moving 2 px a frame behind a black border over 46 % of the width was averaged,
            # 0 restarts of 5). Kept only when too few others remain for a median: fewer than
            # _MIN_SAMPLES, or than a tenth of the sample where that is fewer (under 640
            # sampled, ~100 x 100 px). The count alone kept them on any image of 32 x 32 px or
            # less (a half-black one moving was averaged, 0 restarts of 5); a share alone (kept
            # at 90 % black) smeared a moving strip of 40 px into 3.7 frames.
            keep = np.ones(top.shape, bool)
            black = top == 0
            if np.count_nonzero(~black) >= min(_MIN_SAMPLES, 0.1 * black.size):
                keep &= ~black
            # Saturated pixels do not follow a change of light: left out of the test.
            bright = top >= _SATURATED
            if bright[keep].mean() < 0.5:
                keep &= ~bright
            blurred = blurred[keep]
            n = float(np.mean(m.count[::_STRIDE, ::_STRIDE]))
            expected = _HALF_NORMAL_MEDIAN * _BLUR_GAIN * self.sigma * np.sqrt(1.0 + 1.0 / n)
            if np.median(np.abs(blurred)) > MOTION_MARGIN * expected:
                self.restarts += 1
                return self._restart(imgs)
        # The kernel takes the threshold as float32: a k the constructor accepts (1e38, 2**130)
        # times the noise was +inf there, refused as "ks" on the second pair. Any threshold
        # over a grey difference's largest (255) restarts no pixel, so it is capped.
        # float(): a NumPy k (np.float32(3e38), np.float16(6e4)) multiplied in its own type,
        # overflowing with NumPy's RuntimeWarning on every pair
        # As the float32 it is there: a tiny k (1e-300) made a threshold that is 0 in float32,
        # refused as "invalid parameter `ks`"; 0 keeps the same pixels (a difference of 0 only)
        ks = float(np.float32(min(float(self.k) * self.sigma, _KS_MAX)))
        out = []
        for img, d, m in zip(imgs, diffs, self._means, strict=True):
            # In place: m.mean and m.count are updated.
            avg = _core.temporal_running_mean(img, m.mean, m.count, d, ks, self.max_frames)
            out.append(avg)
        return out[0], out[1]

    def _restart(
        self, imgs: list[np.ndarray]
    ) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
        shape = imgs[0].shape[:2]
        self._means = [_Mean(img.astype(np.float32), np.ones(shape, np.uint8)) for img in imgs]
        return np.array(imgs[0], copy=True), np.array(imgs[1], copy=True)
