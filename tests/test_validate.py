"""Tests of the shared input validators (property tests: valid inputs convert, invalid ones raise
ValueError and never another exception type)."""

from __future__ import annotations

import os
import re
import warnings
from decimal import Decimal
from fractions import Fraction
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from stereovision._validate import (
    LUMA_WEIGHTS_BGR,
    UNIT_RANGE_TOL,
    as_bgr_uint8,
    as_gray_float,
    as_gray_uint8,
    check_pair,
    finite_number,
    int_in_range,
    positive_finite,
    positive_whole,
)

SIDES = {"min_side": 1, "max_side": 6}


@st.composite
def valid_images(draw: st.DrawFn) -> np.ndarray:
    """Any accepted image: (H, W) or (H, W, C), C in 1/3/4; uint8, uint16 or float in [0, 1]."""
    dtype = draw(st.sampled_from([np.uint8, np.uint16, np.float16, np.float32, np.float64]))
    h, w = draw(st.integers(1, 6)), draw(st.integers(1, 6))
    shape = draw(st.sampled_from([(h, w), (h, w, 1), (h, w, 3), (h, w, 4)]))
    if np.dtype(dtype).kind == "f":
        width = 8 * np.dtype(dtype).itemsize
        elements = st.floats(0.0, 1.0, width=width)
    else:
        elements = st.integers(0, int(np.iinfo(dtype).max))
    return draw(hnp.arrays(dtype, shape, elements=elements))


def _expected_gray(img: np.ndarray) -> np.ndarray:
    scale = {np.dtype(np.uint8): 255.0, np.dtype(np.uint16): 65535.0}.get(img.dtype, 1.0)
    f = img.astype(np.float64) / scale
    if f.ndim == 3:
        f = (
            f[:, :, 0]
            if f.shape[2] == 1
            else f[..., 0] * 0.114 + f[..., 1] * 0.587 + f[..., 2] * 0.299
        )
    return f


@pytest.mark.filterwarnings("ignore:.*uint16 image whose largest value:UserWarning")  # any values
@settings(max_examples=200, deadline=None)
@given(valid_images())
def test_valid_images_convert_into_unit_range(img: np.ndarray) -> None:
    out = as_gray_float(img)
    assert out.dtype == np.float32
    assert out.shape == img.shape[:2]
    assert out.flags.c_contiguous
    assert np.all((out >= 0) & (out <= 1))
    np.testing.assert_allclose(out, _expected_gray(img), rtol=0, atol=2e-6)
    assert not np.shares_memory(out, img)


@pytest.mark.filterwarnings("ignore:.*uint16 image whose largest value:UserWarning")  # any values
@settings(max_examples=100, deadline=None)
@given(valid_images())
def test_valid_images_convert_to_bgr_uint8(img: np.ndarray) -> None:
    bgr = as_bgr_uint8(img)
    assert bgr.dtype == np.uint8 and bgr.shape == (*img.shape[:2], 3)
    gray = as_gray_uint8(img)
    assert gray.dtype == np.uint8 and gray.shape == img.shape[:2]
    # 8-bit round trip within one grey level of the float conversion
    assert np.abs(gray.astype(np.float64) / 255 - as_gray_float(img)).max() <= 1 / 255 + 1e-6


def _bad_dtype_arrays() -> st.SearchStrategy[np.ndarray]:
    dtypes = st.sampled_from(
        [np.bool_, np.int8, np.int16, np.int32, np.int64, np.uint32, np.uint64, np.complex64]
    )
    return dtypes.flatmap(
        lambda dt: hnp.arrays(dt, hnp.array_shapes(min_dims=2, max_dims=3, **SIDES))
    )


def _bad_shape_arrays() -> st.SearchStrategy[np.ndarray]:
    shapes = st.one_of(
        hnp.array_shapes(min_dims=0, max_dims=1, min_side=0, max_side=5),
        hnp.array_shapes(min_dims=4, max_dims=5, min_side=1, max_side=3),
        st.tuples(st.integers(1, 4), st.integers(1, 4), st.sampled_from([0, 2, 5, 6])),
        st.tuples(st.integers(0, 3), st.integers(0, 3)).filter(lambda s: 0 in s),
    )
    return shapes.flatmap(lambda s: hnp.arrays(np.uint8, s))


def _bad_float_arrays() -> st.SearchStrategy[np.ndarray]:
    # at least one NaN/inf or out-of-[0, 1] value
    bad = st.sampled_from([np.nan, np.inf, -np.inf, -0.5, 1.5, 255.0])
    return st.tuples(
        hnp.arrays(
            np.float32,
            st.tuples(st.integers(1, 4), st.integers(1, 4)),
            elements=st.floats(0, 1, width=32),
        ),
        bad,
        st.integers(0, 15),
    ).map(lambda t: _poke(*t))


def _poke(a: np.ndarray, value: float, i: int) -> np.ndarray:
    a = a.copy()
    a.flat[i % a.size] = value
    return a


junk = st.one_of(
    st.none(),
    st.integers(),
    st.floats(),
    st.text(max_size=5),
    st.lists(st.lists(st.integers(0, 255), max_size=3), max_size=3),  # ragged or int64
    st.dictionaries(st.text(max_size=2), st.integers(), max_size=2),
    st.just(object()),
    st.just(np.array([[object(), object()]])),
    st.just(np.array([["a", "b"]])),
)


@settings(max_examples=300, deadline=None)
@given(st.one_of(_bad_dtype_arrays(), _bad_shape_arrays(), _bad_float_arrays(), junk))
def test_invalid_inputs_raise_value_error_only(bad: object) -> None:
    for fn in (as_gray_float, as_bgr_uint8, as_gray_uint8):
        with pytest.raises(ValueError):
            fn(bad)


def test_messages_name_argument_and_values() -> None:
    with pytest.raises(ValueError, match=r"right: unsupported dtype bool"):
        as_gray_float(np.zeros((2, 2), bool), name="right")
    with pytest.raises(
        ValueError, match=r"left: expected 1, 3 \(BGR\) or 4 \(BGRA\) channels, got 2 "
    ):
        as_gray_float(np.zeros((2, 2, 2), np.uint8))
    with pytest.raises(ValueError, match=r"got 1 dimension\(s\) with shape \(5,\)"):
        as_gray_float(np.zeros(5, np.uint8))
    with pytest.raises(ValueError, match=r"left: image is empty \(shape \(0, 3\)\)"):
        as_gray_float(np.zeros((0, 3), np.uint8))
    with pytest.raises(ValueError, match=r"contains 1 NaN/inf"):
        as_gray_float(np.array([[0.5, np.nan]]))
    with pytest.raises(ValueError, match=r"range \[0, 255\].*divide 8-bit data by 255"):
        as_gray_float(np.array([[0.0, 255.0]]))
    with pytest.raises(ValueError, match=r"range \[0, 1e\+300\]"):
        as_gray_float(np.array([[0.0, 1e300]]))  # not reported as inf after a float32 cast
    with pytest.raises(ValueError, match="got None"):
        as_gray_float(None)
    with pytest.raises(ValueError, match="complex64"):
        as_gray_float(np.zeros((2, 2), np.complex64))


def test_exact_values() -> None:
    np.testing.assert_array_equal(
        as_gray_float(np.array([[0, 51, 255]], np.uint8)), np.float32([[0, 0.2, 1]])
    )
    assert as_gray_float(np.array([[65535]], np.uint16))[0, 0] == 1.0
    bgr = np.zeros((1, 1, 3), np.uint8)
    bgr[0, 0] = (255, 0, 0)  # pure blue -> 0.114
    assert as_gray_float(bgr)[0, 0] == pytest.approx(0.114, abs=1e-7)
    bgra = np.concatenate([bgr, np.full((1, 1, 1), 7, np.uint8)], axis=2)
    assert as_gray_float(bgra)[0, 0] == as_gray_float(bgr)[0, 0]  # alpha ignored
    # uint8 BGR goes to OpenCV untouched; grey is what cv2.cvtColor gives
    img = np.random.default_rng(0).integers(0, 256, (5, 7, 3), dtype=np.uint8)
    assert as_bgr_uint8(img) is img
    np.testing.assert_array_equal(as_gray_uint8(img), cv2.cvtColor(img, cv2.COLOR_BGR2GRAY))
    np.testing.assert_array_equal(as_bgr_uint8(np.float32([[0.0, 1.0]]))[0, 1], [255, 255, 255])
    with pytest.warns(UserWarning, match="largest value is 2570"):  # 8-bit values in 16 bits
        assert as_bgr_uint8(np.array([[257 * 10]], np.uint16))[0, 0, 0] == 10


def test_check_pair() -> None:
    a = np.zeros((4, 5), np.uint8)
    left, right = check_pair(a, a + 255)
    assert left.dtype == np.float32 and left.max() == 0 and right.min() == 1
    with pytest.raises(ValueError, match=r"left \(4, 5\) and right \(4, 6\)"):
        check_pair(a, np.zeros((4, 6), np.uint8))
    with pytest.raises(ValueError, match=r"left \(4, 5\) and right \(4, 5, 3\)"):
        check_pair(a, np.zeros((4, 5, 3), np.uint8))
    with pytest.raises(ValueError, match=r"^right: unsupported dtype"):
        check_pair(a, a.astype(bool))


@pytest.mark.parametrize("value", [1, 2.5, np.float32(3), np.array([4.0]), np.int64(7)])
def test_positive_finite_accepts(value: object) -> None:
    assert positive_finite(value, "f") == float(np.asarray(value).ravel()[0])


@pytest.mark.parametrize(
    "value", [0, -1.0, np.nan, np.inf, "3", None, True, [1.0, 2.0], 1 + 2j, np.array([])]
)
def test_positive_finite_rejects(value: object) -> None:
    with pytest.raises(ValueError, match=r"^baseline: expected a positive finite number"):
        positive_finite(value, "baseline")


def _numpy_grey(arr: np.ndarray) -> np.ndarray:
    """The NumPy path of as_gray_float for uint8 input (what the Rust conversion replaces)."""
    out = arr.astype(np.float32) / np.float32(255)
    if out.ndim == 3:
        if out.shape[2] == 1:
            return np.ascontiguousarray(out[:, :, 0])
        b, g, r = LUMA_WEIGHTS_BGR
        grey = np.float32(b) * out[:, :, 0] + np.float32(g) * out[:, :, 1]
        return np.clip(grey + np.float32(r) * out[:, :, 2], 0.0, 1.0)
    return out


@pytest.mark.parametrize("layout", ["bgr", "bgra", "grey", "grey1", "strided"])
def test_uint8_grey_conversion_is_bit_identical_to_numpy(layout: str, data_dir: Path) -> None:
    # A real photograph, plus all 256 levels in its first row.
    img = cv2.imread(str(data_dir / "middlebury2003" / "cones" / "left.png"), cv2.IMREAD_COLOR)
    assert img is not None
    img[0, :256] = np.arange(256, dtype=np.uint8)[:, None]
    arr = {
        "bgr": img,
        "bgra": cv2.cvtColor(img, cv2.COLOR_BGR2BGRA),
        "grey": img[:, :, 1],
        "grey1": img[:, :, 1:2],
        "strided": img[::2, ::3],
    }[layout]
    got = as_gray_float(arr)
    want = _numpy_grey(arr)
    assert got.dtype == np.float32 and got.flags.c_contiguous and got.shape == arr.shape[:2]
    assert np.array_equal(got.view(np.uint32), want.view(np.uint32))  # bit for bit
    if layout != "strided":
        assert got[0, 0] == 0.0 and got[0, 255] == 1.0


@pytest.mark.parametrize("dtype", ["uint16", "float32", "float64"])
def test_big_endian_images_give_the_native_result(dtype: str, data_dir: Path) -> None:
    """A big-endian uint16 image (``>u2``: FITS, some TIFF and PNG readers) was refused as an
    "unsupported dtype >u2; expected uint8, uint16 ..."; big-endian floats were accepted. Both
    now give what the same values in native byte order give, through the public API too."""
    img = cv2.imread(str(data_dir / "middlebury2003" / "cones" / "left.png"), cv2.IMREAD_COLOR)
    assert img is not None
    native = img.astype(dtype) * 257 if dtype == "uint16" else img.astype(dtype) / 255
    big = native.astype(np.dtype(dtype).newbyteorder(">"))
    assert not big.dtype.isnative and np.array_equal(big, native)
    assert np.array_equal(as_gray_float(big), as_gray_float(native))
    assert np.array_equal(as_bgr_uint8(big), as_bgr_uint8(native))
    assert np.array_equal(as_gray_uint8(big), as_gray_uint8(native))
    if dtype == "uint16":
        import stereovision as sv

        right = cv2.imread(str(data_dir / "middlebury2003" / "cones" / "right.png"))
        r16 = right.astype(np.uint16) * 257
        want = sv.depth_map(native, r16, method="census", max_disparity=64, cloud=False)
        got = sv.depth_map(big, r16.astype(">u2"), method="census", max_disparity=64, cloud=False)
        np.testing.assert_array_equal(got.disparity, want.disparity)


@pytest.mark.parametrize(
    ("value", "shown"),
    [
        (2**70, str(2**70)),
        (10**400, "an integer of 401 digits"),
        (10**5000, "an integer of 5001 digits"),
    ],
    ids=["2**70", "10**400", "10**5000"],
)
def test_int_in_range_names_the_parameter_of_a_huge_int(value: int, shown: str) -> None:
    """An int of over 4300 digits was a ValueError about Python's integer string conversion
    limit, naming no parameter (its repr in the message raised); it is shown by its size."""
    from stereovision._validate import int_in_range

    with pytest.raises(ValueError) as info:
        int_in_range(value, "nms_half", 1, 2**31 - 1)
    assert str(info.value) == f"nms_half: expected an integer from 1 to 2147483647, got {shown}"


def test_a_float_range_error_shows_the_values_that_are_outside() -> None:
    """A grey level of 1.000002 was refused as 'must lie in [0, 1], got range [0, 1] (divide
    8-bit data by 255)': the range rounded into [0, 1] and the advice
    for another mistake. The range is shown to float32 precision and the advice fits it, in
    as_gray_float and check_unit_range (the matchers' check) alike."""
    from stereovision._validate import check_unit_range

    above = np.float32([[0.0, 1.000002]])  # past the float rounding read as 1
    cases = [
        (above, r"got range \[0, 1\.000002\] \(clip an overshoot of resampling"),
        (np.float32([[-0.2, 1.2]]), r"got range \[-0\.2, 1\.2\] \(clip an overshoot"),
        (np.float32([[1e30, 0.00018996]]), r"got range \[0\.00018996, 1e\+30\] \(scale both"),
        (np.float32([[0.0, 255.0]]), r"got range \[0, 255\] \(divide 8-bit data by 255"),
        (np.float32([[0.0, 4095.0]]), r"got range \[0, 4095\] \(divide 16-bit data by 65535"),
    ]
    for img, message in cases:
        with pytest.raises(ValueError, match=r"left: float image values must lie in \[0, 1\], "):
            as_gray_float(img)
        with pytest.raises(ValueError, match=message):
            as_gray_float(img)
        with pytest.raises(ValueError, match=message):
            check_unit_range(img, "left")


def test_float_rounding_just_outside_0_1_is_read_not_refused() -> None:
    """A float image one float32 step above 1 or below 0 (1.0000001, -6e-8: the rounding of a
    luma sum or a blend of a [0, 1] image) was refused by as_gray_float and by the matchers'
    check_unit_range as if it had the wrong scale. Within UNIT_RANGE_TOL it is read now,
    as_gray_float clipping it to the documented range; past it, refused as before."""
    from stereovision._validate import UNIT_RANGE_TOL, check_unit_range
    from stereovision.matching.gabor import gabor_disparity

    one_up = np.nextafter(np.float32(1), np.float32(2))
    img = np.tile(np.float32([[0.25, one_up, -6e-8, 0.5]]), (24, 8))
    out = as_gray_float(img)
    assert out.min() == 0.0 and out.max() == 1.0
    np.testing.assert_array_equal(out, np.clip(img, 0, 1))
    check_unit_range(img, "left")  # no error
    assert gabor_disparity(img, img, max_disparity=4).disparity.shape == img.shape
    with pytest.raises(ValueError, match="must lie in"):
        as_gray_float(np.float32([[0.0, 1.0 + 3 * UNIT_RANGE_TOL]]))
    with pytest.raises(ValueError, match="must lie in"):
        check_unit_range(np.float32([[-3 * UNIT_RANGE_TOL, 1.0]]), "left")


def test_none_from_imread_says_the_path_was_not_read(data_dir: Path, tmp_path: Path) -> None:
    """cv2.imread's None for a path it cannot read was refused as "expected an image array
    ..., got None"; every public entry point now says what probably happened."""
    import stereovision as sv

    right = cv2.imread(str(data_dir / "middlebury2001" / "tsukuba" / "right.png"))
    left = cv2.imread(str(tmp_path / "no_such_left.png"))  # a typo in the path
    assert left is None
    calls = {
        "depth_map": lambda: sv.depth_map(left, right),
        "match": lambda: sv.match(left, right),
        "estimate_max_disparity": lambda: sv.estimate_max_disparity(left, right),
        "check_rectification": lambda: sv.check_rectification(left, right),
    }
    want = (
        "left: got None, not an image (cv2.imread returns None for a file it cannot read: "
        "check the path)"
    )
    for what, call in calls.items():
        with pytest.raises(ValueError) as err:
            call()
        assert str(err.value) == want, what
    with pytest.raises(ValueError) as err:
        sv.depth_map(right, None)
    assert str(err.value) == want.replace("left:", "right:")


def test_boundaries_of_the_low_uint16_warning_and_the_float_range() -> None:
    import warnings

    from stereovision._validate import LOW_UINT16_MAX, as_gray_uint8

    with pytest.warns(UserWarning, match="largest value is 4095"):
        as_gray_float(np.full((2, 2), LOW_UINT16_MAX - 1, np.uint16))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        as_gray_float(np.full((2, 2), LOW_UINT16_MAX, np.uint16))  # 12 bits and one: no warning
    # float rounding above 1 is clipped to exactly 1, on both sides of the range
    top = np.float32(1.0) + np.float32(5e-7)
    out = as_gray_float(np.array([[0.5, top]], np.float32))
    assert out[0, 1] == 1.0
    # an infinity is named as such, not as a range
    with pytest.raises(ValueError, match="1 NaN/inf"):
        as_gray_float(np.array([[0.5, np.inf]], np.float32))
    # 16-bit grey to 8 bits rounds to nearest: 32768 / 257 = 127.5 -> 128
    assert as_gray_uint8(np.array([[32768, 65535]], np.uint16))[0, 0] == 128


def test_big_endian_and_the_right_image_named() -> None:
    img = np.arange(12, dtype=np.uint16).reshape(3, 4) * 5000
    np.testing.assert_array_equal(as_gray_float(img.astype(">u2")), as_gray_float(img))
    good = np.zeros((2, 2), np.float32)
    with pytest.raises(ValueError, match=r"^right: float image"):
        check_pair(good, np.full((2, 2), 2.0, np.float32))


def test_check_unit_range_and_u8_pair() -> None:
    from stereovision._validate import check_unit_range, u8_pair

    check_unit_range(np.array([[np.nan, 0.5]], np.float32), "left")  # NaN: the kernel's to say
    a, b = np.zeros((2, 3), np.uint8), np.zeros((3, 2), np.uint8)
    assert u8_pair(a, b) is None
    assert u8_pair(a, a.copy()) is not None


def test_number_validators_at_their_boundaries() -> None:
    from stereovision._validate import (
        disparity_range,
        finite_number,
        float_sized,
        int_in_range,
        xy_points,
    )

    assert int_in_range(5, "n", 0, 5) == 5 and int_in_range(5.0, "n", 0, 5) == 5
    for bad in (2.5, True, 6, -1):
        with pytest.raises(ValueError, match="n: expected an integer from 0 to 5"):
            int_in_range(bad, "n", 0, 5)
    with pytest.raises(ValueError, match="positive finite"):
        positive_finite(1 + 0j, "f")
    with pytest.raises(ValueError, match="gamma: an integer of 401 digits"):
        float_sized(10**400, "gamma")
    for bad in (True, 10**400, float("inf")):
        with pytest.raises(ValueError, match="blur: expected a finite number"):
            finite_number(bad, "blur")
    with pytest.raises(ValueError, match=r"max_disparity \(32\) must be larger"):
        disparity_range(32, 32)
    with pytest.raises(ValueError, match=r"max_disparity \(10.0000001\) and min_disparity \(10\)"):
        disparity_range(10, 10.0000001)
    with pytest.raises(ValueError, match=r"got \(4, 3\)$"):
        xy_points(np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"got \(2, 3\) \(transpose"):
        xy_points(np.zeros((2, 3)))


def test_first_line_and_renamed_keyword() -> None:
    from stereovision._validate import first_line, renamed_keyword

    assert first_line(ValueError("a\nb")) == "a"

    @renamed_keyword("disp", "disparity")
    def f(disparity: int) -> int:
        return disparity

    with pytest.warns(DeprecationWarning, match="disp= is now disparity="):
        assert f(disp=3) == 3
    with pytest.raises(TypeError, match="got disp= and disparity="):
        f(1, disp=3)


def test_none_and_objects_are_named_for_what_they_are() -> None:
    with pytest.raises(ValueError, match=r"left: got None, not an image \(cv2.imread"):
        as_gray_float(None)
    with pytest.raises(ValueError, match="expected a numeric image array, got ndarray"):
        as_gray_float(np.array([[1, None]], dtype=object))


@pytest.mark.parametrize(
    ("value", "says"),
    [
        (10**400, "an integer of 401 digits (too large for a float)"),
        (10**400 - 1, "an integer of 400 digits (too large for a float)"),
        (-(10**400), "a negative integer of 401 digits (too large for a float)"),
        (10**5000, "an integer of 5001 digits (too large for a float)"),
    ],
    ids=["10**400", "10**400-1", "-10**400", "10**5000"],
)
def test_a_number_too_large_for_a_float_is_said_to_be_so(value: int, says: str) -> None:
    """An int beyond a float's range was refused as "expected a finite number, got 1000...0"
    (400 digits on one line), or "got an integer of 1329 bits": it is finite, only too large
    for a float. Every check of a finite number says so, by its number of digits."""
    import numpy as np

    from stereovision import export, refine
    from stereovision._validate import finite_number, positive_finite
    from stereovision.evaluate import count_at_precision
    from stereovision.render import CameraControls
    from tests.test_calibration import raw_calib

    one = np.ones(1)
    checks = [
        ("blur: expected a finite number, got ", lambda: finite_number(value, "blur")),
        ("f: expected a positive finite number, got ", lambda: positive_finite(value, "f")),
        ("alpha: expected a finite number, got ", lambda: raw_calib().rectified_calibration(value)),
        (
            "scale: expected a positive finite number, got ",
            lambda: export.encode_depth_png(np.ones((2, 2)), scale=value),
        ),
        (
            "tolerance: expected a positive finite number of pixels, got ",
            lambda: count_at_precision(one, one, one, one, np.ones((2, 2)), 50.0, value),
        ),
        (
            "camera control roll must be a finite number, got ",
            lambda: CameraControls(roll=value),
        ),
    ]
    checks.append(
        (
            "step must be a finite number, got ",
            lambda: refine.refine_disparity(
                np.zeros((4, 4), np.float32),
                np.zeros((4, 4), np.float32),
                np.zeros((4, 4), np.float32),
                max_disparity=2,
                step=value,
            ),
        )
    )
    for prefix, call in checks:
        with pytest.raises(ValueError) as info:
            call()
        assert str(info.value) == prefix + says


def test_a_second_mutation_audit_of_the_image_checks() -> None:
    """A second mutation audit found unasserted: a void-dtype array named as not numeric, an
    empty colour image, the low-uint16 warning's bits (its 257), warn=False, the advice's
    bounds (1.5 still an overshoot; a negative range is not 16-bit data), a float rounding
    below 0 clipped, an infinity left to the kernel by check_unit_range, and u8_pair taking a
    uint16 right image or empty ones."""
    import warnings

    from stereovision import _validate as v

    with pytest.raises(ValueError, match="expected a numeric image array"):
        v.as_image_array(np.zeros((2, 2), dtype="V4"))
    with pytest.raises(ValueError, match=r"image: image is empty \(shape \(0, 4, 3\)\)"):
        v.as_image_array(np.zeros((0, 4, 3), np.uint8))
    # log2(1450 / 257) = 2.497: 2 bits (by 256 it was 2.502, 3 bits)
    with pytest.warns(UserWarning, match="largest value is 1450 .* keeps about 2 bits"):
        v.as_gray_float(np.full((4, 4), 1450, np.uint16))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v.as_gray_float(np.full((4, 4), 1450, np.uint16), warn=False)
        v.check_unit_range(np.array([[0.0, np.inf]], np.float32), "left")  # the kernel's word
        v.check_unit_range(np.array([[np.nan, 0.5]], np.float32), "left")
    assert "clip an overshoot" in str(v._unit_range_error(-0.5, 1.5, "left"))
    assert "scale both images" in str(v._unit_range_error(-3.0, 300.0, "left"))
    assert v.as_gray_float(np.array([[-1e-7, 0.5]])).tolist() == [[0.0, 0.5]]
    assert v.as_gray_float(np.array([[0.5, 1.0 + 1e-7]])).tolist() == [[0.5, 1.0]]
    u8 = np.zeros((4, 4), np.uint8)
    assert v.u8_pair(u8, u8.astype(np.uint16)) is None
    assert v.u8_pair(u8[:0], u8[:0]) is None
    assert v.u8_pair(u8, u8) is not None


def test_a_second_mutation_audit_of_the_number_checks() -> None:
    """A second mutation audit found unasserted: a min_disparity of exactly the width (and a
    max_disparity of minus it) unreachable, a range past float32 without NumPy's overflow
    warning, a whole number of 1e20 written as 1e+20, a misspelling 0.8 alike suggested, the
    defaults' dict named, the digits of every power of ten past a float, and a 1-D or 3-D
    array refused as points."""
    import warnings

    from stereovision import _validate as v

    assert v.unreachable_range(10, 20, 10) is not None
    assert v.unreachable_range(9, 20, 10) is None
    assert v.unreachable_range(-30, -10, 10) is not None
    assert v.unreachable_range(-30, -9, 10) is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert v.disparity_range(0, 1e39) == (0.0, 1e39)
    with pytest.raises(ValueError, match=r"min_disparity \(1e\+20\) are the same float32"):
        v.disparity_range(1e20, 1e20 + 2**20)
    with pytest.raises(ValueError, match=r"did you mean 'k_cand'\?\): .* \(DEFAULTS\)"):
        v.refuse_unknown("parameter", {"kcan": 1}, ["k_cand", "other"], "DEFAULTS")
    for k in range(309, 1000):
        assert v.too_large_for_float(10**k, why=False) == f"an integer of {k + 1} digits"
    for bad in ([1.0, 2.0], np.zeros((2, 2, 2))):
        with pytest.raises(ValueError, match="expected shape"):
            v.xy_points(bad)


def test_the_low_uint16_warning_names_the_callers_line() -> None:
    """Its fixed stacklevel 4 was right for as_gray_float called directly only: through
    depth_map it named a line of depth.py, through match and check_pair one of _validate.py
    (a mutation audit's stacklevel 3 passed every test); it names the caller's line."""
    import warnings

    import stereovision as sv
    from stereovision import _validate as v

    img = np.random.default_rng(0).integers(0, 4000, (64, 96)).astype(np.uint16)
    calls = {
        "as_gray_float": lambda: v.as_gray_float(img),
        "check_pair": lambda: v.check_pair(img, img),
        "match": lambda: sv.match(img, img, max_disparity=16),
        "depth_map": lambda: sv.depth_map(img, img, max_disparity=16),
    }
    for name, call in calls.items():
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            call()
        low = [w for w in seen if "uint16 image whose largest value" in str(w.message)]
        assert low, name
        assert {w.filename for w in low} == {__file__}, name


def test_an_internal_error_without_a_message_is_one_clean_line() -> None:
    """A bare assert's AssertionError (no message) printed 'internal AssertionError:  (please
    report this)', a colon and two spaces before nothing; the type is said once, alone."""
    from stereovision._validate import internal_error

    assert internal_error(AssertionError()) == (
        "stereovision: error: internal AssertionError (please report this)"
    )
    assert internal_error(KeyError("k")) == (
        "stereovision: error: internal KeyError: 'k' (please report this)"
    )
    assert internal_error(ValueError("\nsecond line")) == (
        "stereovision: error: internal ValueError: second line (please report this)"
    )


def test_a_path_in_a_0d_bytes_array_is_said_as_a_path() -> None:
    # a file name read from a table as bytes (dtype S) was said as "converting to dtype |S8"
    with pytest.raises(ValueError, match=r"^left: got the path 'left\.png', not an image: "):
        as_gray_float(np.array(b"left.png"), "left")


def test_float_range_limits_are_inclusive() -> None:
    # UNIT_RANGE_TOL is the largest excursion read (and clipped), not the first one refused
    out = as_gray_float(np.array([[0.0, 1.0 + UNIT_RANGE_TOL]]), "left")
    np.testing.assert_array_equal(out, np.array([[0.0, 1.0]], np.float32))
    # 65535 itself is 16-bit data; just beyond it, no known scale
    with pytest.raises(ValueError, match=r"range \[0, 65535\] \(divide 16-bit data by 65535"):
        as_gray_float(np.array([[0.0, 65535.0]]), "left")
    with pytest.raises(ValueError, match=r"range \[0, 65535\.5\] \(scale both images"):
        as_gray_float(np.array([[0.0, 65535.5]]), "left")


def test_uint16_is_divided_by_full_scale_exactly() -> None:
    # a division, not a product with float32(1 / 65535): that differs by 1 ulp at 512 levels
    levels = np.arange(65536, dtype=np.uint16).reshape(256, 256)
    expected = levels.astype(np.float32) / np.float32(65535)
    np.testing.assert_array_equal(as_gray_float(levels, "left"), expected)
    assert as_gray_float(levels, "left")[-1, -1] == 1.0


def test_bgr_uint8_is_c_contiguous_from_bgra_and_strided_views() -> None:
    rng = np.random.default_rng(1)
    bgra = rng.integers(0, 256, (5, 8, 4), dtype=np.uint8)
    for img, expected in (
        (bgra, bgra[:, :, :3]),
        (bgra[:, ::2, :3], bgra[:, ::2, :3]),
        (bgra[:, :, 3][:, ::-1], np.repeat(bgra[:, ::-1, 3:], 3, axis=2)),
    ):
        out = as_bgr_uint8(img, "left")
        assert out.flags.c_contiguous, img.strides
        np.testing.assert_array_equal(out, expected)


def test_scalar_checks_take_the_same_numbers() -> None:
    """finite_number refused np.array(3.0) (a value read from an array) where positive_finite
    took a size-1 array, and positive_finite refused 2**70 (an object array to NumPy) where
    finite_number took it: one rule for both (a list, as CameraControls' slider [1.0], is no
    number to either), one message each for what neither takes."""
    from stereovision._validate import finite_number

    for value, want in ((np.array(3.0), 3.0), (np.array([2]), 2.0), (2**70, 2.0**70)):
        assert finite_number(value, "blur") == want
        assert positive_finite(value, "f") == want
    for bad in (np.array([1.0, 2.0]), np.array(True), np.array("3"), [1.0], "3"):
        with pytest.raises(ValueError, match=r"^blur: expected a finite number, got "):
            finite_number(bad, "blur")
        with pytest.raises(ValueError, match=r"^f: expected a positive finite number, got "):
            positive_finite(bad, "f")
    with pytest.raises(ValueError, match=r"^blur: expected a finite number, got array\(nan\)$"):
        finite_number(np.array(np.nan), "blur")


def test_real_array_reads_an_object_array_of_real_numbers_only() -> None:
    """A mutation audit: what ``_real_array`` gives was asserted only through its callers'
    values. Real numbers in an object array are their float64 array (float32 would round a
    float64 depth); a complex number, text or an empty text array is no real array (None)."""
    from stereovision._validate import _real_array

    got = _real_array(np.array([1, 2.5, 1e300, True], dtype=object))
    assert got is not None and got.dtype == np.float64
    np.testing.assert_array_equal(got, [1.0, 2.5, 1e300, 1.0])
    u8 = np.arange(4, dtype=np.uint8)
    assert _real_array(u8) is not None and _real_array(u8).dtype == np.uint8  # kept as given
    for bad in (
        np.array([1.0, 1 + 2j], dtype=object),
        np.array([1.0, "2"], dtype=object),
        np.array([], dtype="U1"),
        np.array([1 + 2j]),
        None,
    ):
        assert _real_array(bad) is None, bad


@pytest.mark.parametrize("value", [np.timedelta64(16), np.timedelta64(16, "ns")])
def test_a_timedelta_scalar_is_no_number(value: np.timedelta64) -> None:
    """np.timedelta64 is an np.integer, so finite_number and positive_finite took 16 ns as the
    number 16, where an array of timedeltas was refused as no number. The scalar is too."""
    from stereovision._validate import finite_number, positive_finite

    with pytest.raises(ValueError, match=r"^blur: expected a finite number, got np\.timedelta64"):
        finite_number(value, "blur")
    with pytest.raises(ValueError, match=r"^f: expected a positive finite number, got "):
        positive_finite(value, "f")


@pytest.mark.parametrize("value", [np.timedelta64(3), np.timedelta64(3, "ns")])
def test_a_timedelta_scalar_is_no_count(value: np.timedelta64) -> None:
    """2ff768b made finite_number refuse a timedelta64 scalar, but int_in_range (the counts:
    hopfield's nms_half and tile, planes' min_size, synthetic's supersample...) read it by
    np.integer, which np.timedelta64 is: 3 ns was the count 3. It is refused, named as given."""
    from stereovision._validate import int_in_range
    from stereovision.matching.hopfield import interest_points

    with pytest.raises(ValueError, match=r"^n: expected an integer from 1 to 10, got ") as info:
        int_in_range(value, "n", 1, 10)
    assert str(info.value).endswith(f"got {value!r}")
    img = np.zeros((20, 30), np.float32)
    with pytest.raises(ValueError, match=r"^nms_half: expected an integer"):
        interest_points(img, nms_half=value)


def _entry_points() -> dict[str, Any]:
    """Entry points whose number or count checks predate the shared rule (NOT_NUMBERS), each
    called with one value in the checked place."""
    from stereovision import bench, evaluate, export, refine
    from stereovision.calibrate import _check_max_pairs
    from stereovision.capture import check_read_timeout, save_pair
    from stereovision.io import scene_max_disparity
    from stereovision.matching import gabor, hopfield, mcgm, sgm
    from stereovision.matching.fusion import _fuse_options
    from stereovision.rosbag import _stamp
    from stereovision.stream import FrameServer, run_stream
    from stereovision.temporal import TemporalFilter
    from stereovision.uncalibrated import rectify_uncalibrated

    rng = np.random.default_rng(0)
    left = rng.random((24, 40), dtype=np.float32)
    right = np.roll(left, -2, axis=1)
    disp = np.full((24, 40), 2.0, np.float32)
    z = np.full((6, 6), 2.0)
    tmp = Path("/nonexistent-stereovision-test")  # refused before any file is written
    return {
        "interest rel_threshold": lambda v: hopfield.interest_points(left, rel_threshold=v),
        "interest floor_rel": lambda v: hopfield.interest_points(left, floor_rel=v),
        "hopfield max_disparity": lambda v: hopfield.hopfield_match(left, right, max_disparity=v),
        "hopfield k_cand": lambda v: hopfield.hopfield_match(
            left, right, max_disparity=8, k_cand=v
        ),
        "hopfield A": lambda v: hopfield.hopfield_match(left, right, max_disparity=8, A=v),
        "mcgm max_disparity": lambda v: mcgm.mcgm_match(left, right, max_disparity=v),
        "mcgm A": lambda v: mcgm.mcgm_match(left, right, max_disparity=8, A=v),
        "mcgm r_graph": lambda v: mcgm.mcgm_match(left, right, max_disparity=8, r_graph=v),
        "sgm paths": lambda v: sgm.sgm_disparity(left, right, max_disparity=8, paths=v),
        "rectify_uncalibrated ransac_px": lambda v: rectify_uncalibrated(left, right, ransac_px=v),
        "refine win_radius": lambda v: refine.refine_disparity(
            left, right, disp, max_disparity=8, win_radius=v
        ),
        "refine step": lambda v: refine.refine_disparity(
            left, right, disp, max_disparity=8, step=v
        ),
        "gabor iters_per_level": lambda v: gabor.gabor_disparity(
            left, right, max_disparity=8, iters_per_level=v
        ),
        "sgm p1": lambda v: sgm.sgm_disparity(left, right, max_disparity=8, p1=v),
        "sgm max_disparity": lambda v: sgm.sgm_disparity(left, right, max_disparity=v),
        "fuse min_agree": lambda v: _fuse_options("vote", 3, 1, 1, 0.5, v),
        "table1 seed": lambda v: evaluate.table1_report(z, z, seed=v),
        "table1 n_points": lambda v: evaluate.table1_report(z, z, n_points=v),
        "bench runs": lambda v: bench._check_runs(v, "runs"),
        "temporal max_frames": lambda v: TemporalFilter(max_frames=v),
        "temporal k": lambda v: TemporalFilter(k=v),
        "scene_max_disparity width": lambda v: scene_max_disparity(None, v),
        "save_pair index": lambda v: save_pair(tmp, v, left, left),
        "rosbag stamp_ns": lambda v: _stamp(v),
        "voxel_downsample voxel": lambda v: export.voxel_downsample(z[:, :3], voxel=v),
        "calibrate_from_bag max_pairs": lambda v: _check_max_pairs(v),
        "FrameServer port": lambda v: FrameServer(port=v),
        "run_stream report_period": lambda v: run_stream(None, report_period=v),  # type: ignore[arg-type]
        "capture read_timeout": lambda v: check_read_timeout(v),
    }


@pytest.mark.parametrize("value", [np.timedelta64(3), np.timedelta64(5), True, np.True_], ids=repr)
@pytest.mark.parametrize("entry", sorted(_entry_points()))
def test_no_entry_point_takes_a_bool_or_a_timedelta_as_a_number(entry: str, value: object) -> None:
    """One rule (NOT_NUMBERS): 3 ns was the count 3, a range of 3 px or the seed 3 in some
    checks, True the threshold 1.0 or the weight 1; all are refused naming the parameter."""
    name = entry.split()[1]
    with pytest.raises(ValueError, match=rf"^{name}\b.*got {re.escape(repr(value))}"):
        _entry_points()[entry](value)


def _timedelta_places(tmp_path: Path) -> dict[str, tuple[Any, type[Exception], str]]:
    """Checks whose message shows more than the value (a pair of numbers, a fixed phrase) or
    whose refusal of a non-number is a TypeError, each called with one value."""
    from stereovision import depth_map
    from stereovision.baselines import round_up16
    from stereovision.calibration import Calibration
    from stereovision.capture import parse_size
    from stereovision.export import encode_depth_png
    from stereovision.matches import Matches

    img = np.zeros((20, 30), np.uint8)
    q = tmp_path / "Q.dat"
    if tmp_path.is_dir():  # not when pytest collects the names, with a folder that is not there
        q.write_text("1 0 0 -5\n0 1 0 -4\n0 0 0 100\n0 0 10 0\n")
    no = np.zeros(0, np.float32)
    return {
        "depth_map max_disparity": (
            lambda v: depth_map(img, img, max_disparity=v),
            TypeError,
            "max_disparity: expected a number of pixels, got ",
        ),
        "depth_map min_disparity": (
            lambda v: depth_map(img, img, max_disparity=8, min_disparity=v),
            TypeError,
            "min_disparity: expected a number of pixels, got ",
        ),
        "png16 scale": (
            lambda v: encode_depth_png(np.ones((2, 2)), scale=v),
            TypeError,
            "scale: expected a number (units per metre), got timedelta64 ",
        ),
        "parse_size": (
            lambda v: parse_size((v, 480), "image_size"),
            ValueError,
            "image_size: expected WIDTHxHEIGHT with positive integers, got (",
        ),
        "from_q image_size": (
            lambda v: Calibration.from_q(q, (v, 480)),
            ValueError,
            "image_size for ",
        ),
        "Matches image_shape": (
            lambda v: Matches(no, no, no, no, no, image_shape=(v, 40)),
            ValueError,
            "image_shape must be positive (H, W) integers, got (",
        ),
        "round_up16": (
            lambda v: round_up16(v),
            ValueError,
            "disparity range must be a number of pixels, finite and >= 0, got ",
        ),
    }


@pytest.mark.parametrize("value", [np.timedelta64(640), np.timedelta64(640, "ns")], ids=repr)
@pytest.mark.parametrize("place", sorted(_timedelta_places(Path("/nonexistent-stereovision-test"))))
def test_no_pair_of_numbers_or_range_takes_a_timedelta(
    tmp_path: Path, place: str, value: np.timedelta64
) -> None:
    """640 ns was the width 640 (capture's image_size, from_q's, a Matches' image_shape), a
    cube side or a scale of 640 (export), a range of 640 px (round_up16); depth_map's range
    let it through its TypeError to a later ValueError in other words. Each is refused as a
    bool is there, naming the value."""
    call, kind, says = _timedelta_places(tmp_path)[place]
    with pytest.raises(kind, match="^" + re.escape(says)) as info:
        call(value)
    assert repr(value) in str(info.value)


@pytest.mark.parametrize("value", [40, 40.0, np.int64(40), np.array([40]), Fraction(40)], ids=repr)
def test_max_pairs_and_port_take_the_whole_numbers_every_count_takes(value: object) -> None:
    """calibrate_from_video/bag's max_pairs and FrameServer's port were checked by hand as a
    Python int: np.int64(40) read from an array (or 40.0 from a config) was refused, which
    every other count takes (whole_value). Both are that Python int now."""
    from stereovision.calibrate import _check_max_pairs
    from stereovision.stream import FrameServer

    got = _check_max_pairs(value)
    assert got == 40 and type(got) is int
    server = FrameServer(port=0 * value)  # type: ignore[operator]
    try:
        assert server.port > 0
    finally:
        server.close()


@pytest.mark.parametrize(
    "value", [3.0, np.float32(3), np.int64(3), Fraction(3), Decimal("3"), np.array([3])], ids=repr
)
def test_every_count_takes_the_whole_numbers_min_agree_takes(value: object) -> None:
    """gabor's and sgm's counts refused 3.0, Fraction(3) and a size-1 array where fuse's
    min_agree took them: all read them as 3 now (whole_value), with the results of 3."""
    from stereovision.matching import gabor, sgm
    from stereovision.matching.fusion import _fuse_options

    rng = np.random.default_rng(1)
    left = rng.random((24, 40), dtype=np.float32)
    right = np.roll(left, -2, axis=1)
    assert _fuse_options("vote", 3, 1, 1, 0.5, value)[-1] == 3
    assert int_in_range(value, "n", 0, 9) == 3
    want = gabor.gabor_disparity(left, right, max_disparity=8, iters_per_level=3).disparity
    got = gabor.gabor_disparity(left, right, max_disparity=8, iters_per_level=value).disparity
    np.testing.assert_array_equal(got, want)
    want = sgm.sgm_disparity(left, right, max_disparity=8, p1=3)
    np.testing.assert_array_equal(sgm.sgm_disparity(left, right, max_disparity=8, p1=value), want)


@pytest.mark.parametrize(
    ("value", "want"),
    [
        (Fraction(3 * 10**17 + 1, 10**17), None),  # its nearest float is 3.0
        (Decimal("3.00000000000000001"), None),
        (Decimal("9007199254740993"), 9007199254740993),  # not its float's ...992
        (Decimal("sNaN"), None),  # compared, it raised InvalidOperation
        (np.longdouble(3), 3),  # a NumPy float, as np.float32(3)
        (np.longdouble(3) + np.longdouble(2) ** -60, None),
        (np.array([3], np.longdouble), 3),
    ],
    ids=repr,
)
def test_whole_value_reads_each_number_by_its_own_value(value: object, want: int | None) -> None:
    """whole_value read a Fraction or a Decimal as its nearest float: a fraction a hair above
    3 was the count 3 and a 16-digit Decimal another count; np.longdouble(3) was no count
    (its item() is no Python float) where np.float32(3) was."""
    from stereovision._validate import whole_value

    got = whole_value(value)
    assert got == want and (want is None or type(got) is int)


def test_whole_value_gives_an_enum_member_as_its_int() -> None:
    """A count given as an IntEnum member came back as the member: the 'Python int' it says."""
    import enum

    from stereovision._validate import whole_value

    class Paths(enum.IntEnum):
        FEW = 3

    got = whole_value(Paths.FEW)
    assert got == 3 and type(got) is int


def test_whole_value_refuses_a_decimal_whose_int_has_no_end() -> None:
    """b87b5fa read a whole Decimal by int(): 9 characters, Decimal('1e1000000'), took 53 s
    (its int built digit by digit) and '1e999999999999999999' never ended, where its float
    had been inf, no count. Past 4300 digits (Python's own limit of an int read from a str) it
    is no count, at once; up to there it is read exactly, and a zero of any exponent is 0."""
    import time

    from stereovision._validate import positive_whole, whole_value

    start = time.perf_counter()
    assert whole_value(Decimal("1e100000")) is None  # before: an int of 100001 digits, 0.7 s
    assert whole_value(Decimal("-1E+999999999999999999")) is None
    with pytest.raises(ValueError, match=r"^frames: expected a positive number of pairs, got"):
        positive_whole(Decimal("1e1000000"), "frames", "a positive number of pairs")
    assert time.perf_counter() - start < 1.0
    assert whole_value(Decimal("1e4299")) == 10**4299  # 4300 digits: read exactly
    assert whole_value(Decimal("0E+999999999999999999")) == 0


def test_a_count_refused_with_no_repr_is_named() -> None:
    """whole_value reads Fraction(10**5000) as a count (b87b5fa); refused, the message's repr
    of it was Python's "Exceeds the limit (4300 digits) for integer string conversion",
    naming no parameter. It is named, the value said by its type."""
    from stereovision._validate import int_in_range, positive_whole

    want = r"min_agree: expected an integer from 1 to 8, got a Fraction of over 4300 digits$"
    with pytest.raises(ValueError, match=want):
        int_in_range(Fraction(10**5000), "min_agree", 1, 8)
    with pytest.raises(ValueError, match=r"^frames: expected a positive integer, got a Fraction"):
        positive_whole(Fraction(-(10**5000), 3), "frames")
    with pytest.raises(ValueError, match=r"got an integer of 5001 digits$"):  # as before
        int_in_range(10**5000, "min_agree", 1, 8)


@pytest.mark.parametrize("value", [10**5000, Fraction(10**5000)], ids=["int", "Fraction"])
def test_the_matchers_name_a_count_with_no_repr(value: object) -> None:
    """sgm_disparity's and gabor_disparity's counts said the value refused by its repr: for
    10**5000 (or its Fraction) Python's "Exceeds the limit (4300 digits) for integer string
    conversion", naming no parameter."""
    from stereovision.matching.gabor import gabor_disparity
    from stereovision.matching.sgm import sgm_disparity

    img = np.zeros((40, 60), np.float32)
    with pytest.raises(ValueError, match=r"^p1: expected an integer in \[1, "):
        sgm_disparity(img.astype(np.uint8), img.astype(np.uint8), max_disparity=16, p1=value)
    with pytest.raises(ValueError, match=r"^n_levels must be a non-negative integer, got an? "):
        gabor_disparity(img, img, max_disparity=16, n_levels=value)


@pytest.mark.parametrize(
    "value", [3.0, np.float32(3), np.int64(3), Fraction(3), Decimal("3"), np.array([3])], ids=repr
)
def test_positive_whole_takes_the_whole_numbers_every_count_takes(value: object) -> None:
    """positive_whole (capture's count/every, run_stream's frames) was a second rule of a
    count written beside whole_value: it refused Fraction(3), Decimal('3') and np.array([3])
    that min_agree and the matchers' counts take. It is whole_value above 0 now."""
    from stereovision._validate import positive_whole

    got = positive_whole(value, "count")
    assert got == 3 and type(got) is int


@pytest.mark.parametrize(
    "value", [0, -1.0, 2.5, Fraction(5, 2), Decimal("NaN"), True, np.timedelta64(3), "3"], ids=repr
)
def test_positive_whole_refuses_in_its_own_words(value: object) -> None:
    from stereovision._validate import positive_whole

    with pytest.raises(ValueError) as exc:
        positive_whole(value, "frames", "a positive number of pairs")
    assert str(exc.value) == f"frames: expected a positive number of pairs, got {value!r}"


@pytest.mark.parametrize("value", [2.5, "3", None, np.array([3, 3]), Fraction(5, 2)], ids=repr)
def test_every_count_refuses_what_min_agree_refuses(value: object) -> None:
    from stereovision.matching import gabor, sgm
    from stereovision.matching.fusion import _fuse_options

    left = np.zeros((8, 16), np.float32)
    with pytest.raises(ValueError, match=r"^min_agree"):
        _fuse_options("vote", 3, 1, 1, 0.5, value)
    with pytest.raises(ValueError, match=r"^n: expected an integer"):
        int_in_range(value, "n", 0, 9)
    with pytest.raises(ValueError, match=r"^iters_per_level"):
        gabor.gabor_disparity(left, left, max_disparity=8, iters_per_level=value)
    with pytest.raises(ValueError, match=r"^p1"):
        sgm.sgm_disparity(left, left, max_disparity=8, p1=value)


def test_mutation_audit_positive_whole_refuses_zero_in_any_type() -> None:
    """Mutation audit of b21f9f0: a count of 0 is refused as a float (0.0, np.float32(0.0),
    -0.0) as it is as an integer, not taken as 0 pairs; whole floats are their integers."""
    from stereovision._validate import positive_whole

    for bad in (0, 0.0, -0.0, np.float32(0.0), -2.0, np.int64(0)):
        with pytest.raises(ValueError, match=r"^every: expected a positive integer, got "):
            positive_whole(bad, "every")
    got = [positive_whole(v, "every") for v in (1.0, np.float32(2.0), np.int64(3), 4)]
    assert got == [1, 2, 3, 4] and all(type(v) is int for v in got)


def test_mutation_audit_whole_value_decimal_digits_limit_is_inclusive() -> None:
    """Mutation audit: a Decimal of 4300 digits is a count (its int as exact), one of 4301 is
    not (Python's own limit of an int read from text); ``> 4300`` passed the first refused."""
    from stereovision._validate import whole_value

    assert whole_value(Decimal("9e4299")) == 9 * 10**4299
    assert whole_value(Decimal("1e4300")) is None
    assert whole_value(Decimal("-1e4300")) is None


def test_mutation_audit_whole_value_reads_another_real_by_its_float() -> None:
    """Mutation audit: a numbers.Real that is no int, float, Fraction or Decimal is a count when
    its float is whole, else none (the branch's is_integer() check was untested)."""
    import numbers

    from stereovision._validate import whole_value

    class Real:
        def __init__(self, v: float) -> None:
            self.v = v

        def __float__(self) -> float:
            return self.v

    numbers.Real.register(Real)
    assert whole_value(Real(3.0)) == 3
    assert whole_value(Real(2.5)) is None
    assert whole_value(Real(float("inf"))) is None


def test_mutation_audit_float32_reach_keeps_float32s_largest_value() -> None:
    """Mutation audit: float32's largest value is within its range and returned as given (its
    cast warns of nothing); only values beyond it are its signed infinity."""
    from stereovision._validate import float32_reach

    top = float(np.finfo(np.float32).max)
    assert float32_reach(top) == top and float32_reach(-top) == -top
    assert float32_reach(top * 2) == np.inf and float32_reach(-top * 2) == -np.inf


def test_mutation_audit_empty_float32_range_shows_whole_numbers_without_point() -> None:
    """Mutation audit: the float32-empty range's message shows 1e8 and 1e8 + 1 as the whole
    numbers they are (every digit, no ".0") and names both arguments in order."""
    from stereovision._validate import disparity_range

    with pytest.raises(ValueError) as exc:
        disparity_range(1e8, 1e8 + 1)
    assert str(exc.value) == (
        "empty disparity range in float32, the matchers' precision: max_disparity (100000001) "
        "and min_disparity (100000000) are the same float32 number (100000000); give a wider "
        "range"
    )


def test_mutation_audit_known_unit_returns_a_str_and_refuses_a_0d_array() -> None:
    """Mutation audit: an np.str_ unit comes back as a plain str (it would reach later
    messages as np.str_('m')); a 0-d array equal to a unit is no str and refused by name."""
    from stereovision._validate import known_unit

    got = known_unit(np.str_("mm"), ["m", "mm"])
    assert got == "mm" and type(got) is str
    with pytest.raises(ValueError, match=r"^depth_unit: expected one of \['m', 'mm'\], got arr"):
        known_unit(np.array("m"), ["m", "mm"], "depth_unit")


def test_mutation_audit_same_aspect_is_within_one_percent() -> None:
    """Mutation audit: a halved odd side (450x375 -> 225x188) is one scale; 5 rows more of
    375 (1.3 %) is another aspect ratio, so no crop-or-pad hint is given for it either."""
    from stereovision._validate import crop_or_pad_hint, same_aspect

    assert same_aspect((450, 375), (225, 188))
    assert not same_aspect((1242, 375), (1242, 380))
    assert crop_or_pad_hint((1242, 375), (1242, 380)) is None
    assert crop_or_pad_hint((1242, 375), (1242, 376)) is not None


def test_mutation_audit_figure_shown_switches_to_whole_units_at_999_5() -> None:
    """Mutation audit: from 999.5 on a figure is shown in whole units ("1000", never "1e+03"),
    below it with three significant digits."""
    from stereovision._validate import figure_shown

    assert [figure_shown(v) for v in (999.4, 999.5, 999.7, -999.7, 2270.4, 0.01234)] == [
        "999",
        "1000",
        "1000",
        "-1000",
        "2270",
        "0.0123",
    ]


def test_mutation_audit_first_line_skips_blank_lines_of_spaces() -> None:
    """Mutation audit: a message opening with a line of spaces says its first line with text."""
    from stereovision._validate import first_line

    assert first_line(ValueError("   \n\t\nthe pair differs in size\nmore")) == (
        "the pair differs in size"
    )
    assert first_line(ValueError("  \n ")) == "ValueError"


def test_mutation_audit_refuse_unknown_suggests_only_a_close_spelling() -> None:
    """Mutation audit: a key far from every valid one ('kcx' to 'k_cand': 0.44) gets no "did
    you mean"; a close one ('k_cnad') does."""
    from stereovision._validate import refuse_unknown

    with pytest.raises(ValueError) as exc:
        refuse_unknown("MCGM parameter", {"kcx": 1}, ["k_cand", "zeta"])
    assert str(exc.value) == "unknown MCGM parameter(s) ['kcx']: expected one of k_cand, zeta"
    with pytest.raises(ValueError, match=r"\(did you mean 'k_cand'\?\)"):
        refuse_unknown("MCGM parameter", {"k_cnad": 1}, ["k_cand", "zeta"])


def test_mutation_audit_not_a_result_names_the_array_to_pass() -> None:
    """Mutation audit: a whole DepthResult where one of its arrays goes is a TypeError naming
    the argument and the field; an array passes."""
    import stereovision as sv
    from stereovision._validate import not_a_result

    res = sv.DepthResult(
        disparity=np.ones((2, 2), np.float32),
        confidence=np.ones((2, 2), np.float32),
        depth=None,
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
        method="fused",
        max_disparity=16,
        calibration=None,
        depth_sigma=None,
    )
    with pytest.raises(
        TypeError, match=r"^depth: got a DepthResult; pass its array, result\.depth$"
    ):
        not_a_result(res, "depth", "depth")
    not_a_result(res.disparity, "disparity", "disparity")


def test_mutation_audit_advice_for_carries_numbers_of_several_digits() -> None:
    """Mutation audit: a size of 640x480 in the API's advice is carried whole into the CLI's."""
    from stereovision._validate import advice_for

    got = advice_for("depth_map: images resized, not cropped: calib.scaled_to((640, 480))", "cli")
    assert got == (
        "depth_map: images resized, not cropped: resize them back to the calibration's size, or "
        "save it scaled to them once in Python with "
        "Calibration.from_file(path).scaled_to((640, 480)).save('rig.yaml') and give rig.yaml"
    )


def test_mutation_audit_negative_levels_are_not_called_8_bit_data() -> None:
    """Mutation audit: a float image reaching -0.25 and 200 is no 8-bit data to divide by 255
    (nor clipped overshoot): the advice is to scale both images alike."""
    from stereovision._validate import _unit_range_error

    assert _unit_range_error(-0.25, 200.0, "left") == (
        "left: float image values must lie in [0, 1], got range [-0.25, 200] "
        "(scale both images of the pair to [0, 1] alike)"
    )


def test_mutation_audit_positive_finite_says_a_bool_is_a_bool() -> None:
    """Mutation audit: True is refused as a bool ("got bool True"), not as the number it is."""
    with pytest.raises(ValueError) as exc:
        positive_finite(True, "blur")
    assert str(exc.value) == "blur: expected a positive finite number, got bool True"


def test_mutation_audit_real_scalar_refuses_a_bool_as_documented() -> None:
    """_real_scalar, documented to raise TypeError for a bool, read True as 1.0 (its callers
    each refused bools before it, so no public result changed); np.bool_ was refused."""
    from stereovision._validate import _real_scalar

    for bad in (True, False, np.True_, np.array([True])):
        with pytest.raises(TypeError):
            _real_scalar(bad)
    assert [_real_scalar(v) for v in (2, np.float32(0.5), np.array([3]), 2**70)] == [
        2.0,
        0.5,
        3.0,
        2.0**70,
    ]


def test_mutation_audit_pair_shape_error_says_which_image_has_alpha() -> None:
    """Mutation audit: a colour image beside one with alpha is said as such (not "both are
    grey"); a pair of two sizes gets the shapes alone, no hint of channels."""
    from stereovision._validate import pair_shape_error

    assert str(pair_shape_error((4, 5, 3), (4, 5, 4))) == (
        "left and right images must have the same shape, got left (4, 5, 3) and right (4, 5, 4): "
        "left is colour, right is colour with alpha; read both alike (cv2.imread(path) reads "
        "both in colour)"
    )
    assert str(pair_shape_error((4, 5, 3), (4, 6))) == (
        "left and right images must have the same shape, got left (4, 5, 3) and right (4, 6)"
    )


def test_mutation_audit_xy_points_keeps_float64() -> None:
    """Mutation audit: points are float64 as given (0.1 and 1e300 are not float32's)."""
    from stereovision._validate import xy_points

    got = xy_points([[0.1, 1e300], [2, 3]])
    assert got.dtype == np.float64
    assert got[0, 0] == 0.1 and got[0, 1] == 1e300


def test_mutation_audit_float_range_shows_nine_figures_of_a_float64_level() -> None:
    """Mutation audit: a float64 level that neither ``:g`` nor float32 reads back is shown with
    9 figures (1.00001235), not 6 (1.00001, which reads as within the tolerance's reach)."""
    from stereovision._validate import _unit_range_error

    assert _unit_range_error(0.0, 1.0000123456789, "left") == (
        "left: float image values must lie in [0, 1], got range [0, 1.00001235] "
        "(clip an overshoot of resampling with numpy.clip(img, 0, 1))"
    )


def test_mutation_audit_a_pathlib_path_is_said_to_be_a_path() -> None:
    """Mutation audit: a pathlib.Path where an image goes is named as the path it is (NumPy
    made it an object array: "converting to dtype object" said nothing of reading it)."""
    with pytest.raises(ValueError) as exc:
        as_gray_float(Path("scene/left.png"), "left")
    assert str(exc.value) == (
        "left: got the path 'scene/left.png', not an image: read it first "
        "(cv2.imread(path) or stereovision.io.imread(path))"
    )


def test_mutation_audit_refuse_not_numbers_names_the_first_and_spares_switches() -> None:
    """Mutation audit: the first numeric parameter given a bool or a timedelta is named; a
    switch's True (its default a bool) is its own."""
    from stereovision._validate import refuse_not_numbers

    defaults = {"flag": False, "A": 1.0, "k_cand": 3}
    with pytest.raises(ValueError) as exc:
        refuse_not_numbers({"flag": True, "A": True, "k_cand": np.timedelta64(3)}, defaults)
    assert str(exc.value) == "A: expected a number, got True"
    refuse_not_numbers({"flag": True, "A": 2.0, "k_cand": 3}, defaults)


@pytest.mark.skipif(os.sep != "/", reason="a backslash is a path separator on this system")
def test_first_line_doubles_the_backslashes_of_a_path_it_escapes() -> None:
    """A name holding a backslash and a control character (``x\\ny<TAB>z.png``, a literal
    backslash-n) was split at the backslash, so its backslash was not doubled and it read as
    ``x``, newline, ``y``: the escape was ambiguous. A path with no control character (a
    Windows-style name) is shown as it is."""
    from stereovision._validate import first_line

    name = "scans/x\\ny\tz.png"
    assert first_line(ValueError(f"image file not found: {name}"), [name]) == (
        "image file not found: scans/x\\\\ny\\tz.png"
    )
    win = "C:\\new\\test.png"
    assert first_line(ValueError(f"{win} not found\nmore"), [win]) == f"{win} not found"


def test_first_line_keeps_the_message_own_line_breaks_beside_an_escaped_path() -> None:
    """A path part ending (or starting) with a control character, ``a\\n`` of a pasted
    ``scans/a\\n``, was replaced wherever its text was: ``data\\nhint`` holds ``a\\n``, so the
    message's own line break was escaped and its second line shown on the first."""
    from stereovision._validate import first_line

    assert first_line(ValueError("cannot read data\nhint: give another"), ["scans/a\n"]) == (
        "cannot read data"
    )
    assert first_line(ValueError("cannot read x\n\nmore"), ["d/\n/e.png"]) == "cannot read x"
    assert first_line(ValueError("no\tway\nmore"), ["\tway"]) == "no\\tway"
    # where the path is, it is still escaped
    assert first_line(ValueError("not found: scans/a\n\nhint"), ["scans/a\n"]) == (
        "not found: scans/a\\n"
    )
    assert first_line(ValueError("not found: d/\n/e.png"), ["d/\n/e.png"]) == (
        "not found: d/\\n/e.png"
    )
    assert first_line(ValueError("not found: /abs/a\nb_depth.png"), ["a\nb"]) == (
        "not found: /abs/a\\nb_depth.png"
    )


@pytest.mark.parametrize(
    ("value", "shown"),
    [
        (np.arange(16.0).reshape(4, 4), "array of shape (4, 4) dtype float64"),
        (np.zeros((2, 2), np.uint8), "array of shape (2, 2) dtype uint8"),
        ("7" * 500, "'777777777777...7777777777777'"),
        ([1.0] * 50, "[1.0, 1.0, 1.0, 1.0, 1.0, 1.0, ...]"),
    ],
)
def test_a_number_check_shows_an_array_or_a_long_value_in_one_short_line(
    value: object, shown: str
) -> None:
    # the repr of a (4, 4) array is 4 lines: the message was cut by the CLI's first line, and
    # a camera frame given as a count filled the screen
    for check, words in [
        (lambda v: finite_number(v, "blur"), "blur: expected a finite number, got "),
        (lambda v: int_in_range(v, "blur", 0, 9), "blur: expected an integer from 0 to 9, got "),
        (lambda v: positive_whole(v, "blur"), "blur: expected a positive integer, got "),
    ]:
        with pytest.raises(ValueError) as err:
            check(value)
        assert str(err.value) == words + shown
    with pytest.raises(ValueError) as err:
        positive_finite(value, "blur")
    kind = "" if isinstance(value, np.ndarray) else type(value).__name__ + " "
    assert str(err.value) == "blur: expected a positive finite number, got " + kind + shown
    # a short value is shown as it is, on one line
    with pytest.raises(ValueError, match=r"got array\(\[1, 2\]\)$"):
        finite_number(np.array([1, 2]), "blur")


def test_an_encoded_files_bytes_are_no_path_and_are_said_in_one_short_line() -> None:
    # a PNG's bytes (requests.get(url).content) were "got the path '\udc89PNG\r\n...'": every
    # byte escaped, a message of 3.5 times the file's size; a NUL is in no file name
    from stereovision._validate import path_given, require

    png = cv2.imencode(".png", np.zeros((40, 60), np.uint8))[1].tobytes()
    assert path_given(png) is None and path_given(np.bytes_(png)) is None
    assert path_given("a\x00b.png") is None and path_given(b"left.png") == "left.png"
    with pytest.raises(ValueError) as err:
        as_gray_float(png, "left")
    assert str(err.value) == (
        f"left: got {len(png)} bytes, not an image: decode an encoded file first "
        "(cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED))"
    )
    with pytest.raises(TypeError) as terr:
        require(png, "Calibration", "calib")
    assert str(terr.value) == "calib: expected a stereovision.Calibration, got bytes"
    # a file name is said as before
    with pytest.raises(ValueError, match=r"^left: got the path 'left\.png', not an image"):
        as_gray_float(b"left.png", "left")


def test_the_low_uint16_warning_reads_the_colours_of_a_bgra_image_not_its_alpha() -> None:
    # an opaque 16-bit alpha is 65535: 12-bit colours beside it were scaled to 1/16 of the
    # range (grey 0.0625 at most) without the warning their BGR image gets
    img = np.full((4, 5, 4), 4095, np.uint16)
    img[:, :, 3] = 65535
    for convert in (as_gray_float, as_bgr_uint8, as_gray_uint8):
        with pytest.warns(UserWarning, match=r"^left: uint16 image whose largest value is 4095 "):
            convert(img, "left")
    img[:, :, 0] = 4096  # a colour at 4096 or above: no 12-bit data, no warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert float(as_gray_float(img, "left").max()) == pytest.approx(
            (0.114 * 4096 + 0.886 * 4095) / 65535, rel=1e-6
        )


@pytest.mark.parametrize(
    ("points", "says"),
    [
        ([["1", "2"]], r"^points: expected \(x, y\) pixels as numbers, got dtype <U1$"),
        ([[None, 1]], r"^points: expected \(x, y\) pixels as numbers, got dtype object$"),
        ([[True, False]], r"^points: expected \(x, y\) pixels as numbers, got dtype bool$"),
        (
            [[np.timedelta64(3), 1]],
            r"^points: expected \(x, y\) pixels as numbers, got dtype timedelta64$",
        ),
        ([[1 + 2j, 3]], r"^points: expected \(x, y\) pixels as numbers, got dtype complex128$"),
        ([[1, 2], [3]], r"^points: expected an \(N, 2\) array of \(x, y\), got list that NumPy"),
    ],
)
def test_xy_points_refuses_what_holds_no_numbers_naming_the_points(
    points: object, says: str
) -> None:
    # the float64 cast read '1' as 1, None as NaN, True as 1 and 3 ns as 3; a complex or a
    # ragged list was NumPy's TypeError or ValueError, naming no argument
    from stereovision._validate import xy_points

    with pytest.raises(ValueError, match=says):
        xy_points(points)


def test_xy_points_reads_every_real_number_as_before() -> None:
    from stereovision._validate import xy_points

    want = [[1.5, 2.0], [3.0, 4.0]]
    for points in (
        want,
        np.array(want, np.float32),
        [[Fraction(3, 2), 2], [3, np.int8(4)]],
        [[Decimal("1.5"), 2], [3, 4]],
        np.array([[1.5, 2], [3, 4]], dtype=object),
    ):
        got = xy_points(points)
        assert got.dtype == np.float64 and got.tolist() == want


def test_xy_points_names_the_points_for_an_int_past_a_floats_range() -> None:
    # the float64 cast's bare OverflowError ("int too large to convert to float") named no
    # argument, before and after c218122
    from stereovision._validate import xy_points

    with pytest.raises(ValueError, match=r"^points: .* integer too large for a float$"):
        xy_points([[10**400, 1], [2, 3]])


def test_xy_points_takes_a_float64_array_as_given_not_a_copy() -> None:
    # the real-number check cast every input with astype, which copies: a (1e6, 2) float64
    # array of points was copied once more (16 MB, +0.5 ms) where np.asarray had passed it
    from stereovision._validate import xy_points

    pts = np.arange(8.0).reshape(4, 2)
    got = xy_points(pts)
    assert np.shares_memory(got, pts) and got.tolist() == pts.tolist()
    # another dtype is still read into a new float64 array, its values as given
    small = pts.astype(np.float32)
    assert not np.shares_memory(xy_points(small), small)
    assert xy_points(small).tolist() == pts.tolist()


def test_xy_points_says_how_to_pass_one_point() -> None:
    """One pixel given as its (x, y), rectify_points((320, 240)), was "points: expected shape
    (N, 2) of (x, y), got (2,)", not what to pass; triangulate's points say it (4e0c5628), and
    Calibration.rectify_points and UncalibratedRectification.rectify_points read them here."""
    from stereovision._validate import xy_points

    with pytest.raises(ValueError) as err:
        xy_points((320, 240))
    assert str(err.value) == (
        "points: expected shape (N, 2) of (x, y), got (2,) (one point: [[x, y]])"
    )
    with pytest.raises(ValueError) as err:
        xy_points(np.zeros(3), "pixels")  # neither one point nor (N, 2): the shape alone
    assert str(err.value) == "pixels: expected shape (N, 2) of (x, y), got (3,)"
    assert xy_points([[320, 240]]).tolist() == [[320.0, 240.0]]


@pytest.mark.parametrize(
    "exc", [KeyError(10**5000), ValueError(10**5000), RuntimeError(-(10**4400))]
)
def test_an_error_whose_message_has_no_str_is_said_by_its_type(exc: BaseException) -> None:
    # str() of an error holding an int of over 4300 digits raises ValueError itself: the one
    # line the CLI prints of any error (first_line, internal_error) was a traceback instead
    from stereovision._validate import first_line, internal_error

    name = type(exc).__name__
    assert first_line(exc) == name
    assert internal_error(exc) == f"stereovision: error: internal {name} (please report this)"


@pytest.mark.parametrize("given", [Decimal("1e400"), Decimal("-1e400"), Fraction(10**400)])
def test_a_finite_real_past_a_floats_range_is_named_as_given_not_as_inf(given: object) -> None:
    # float(Decimal('1e400')) is inf, not the OverflowError of a Fraction's: the fusion's
    # options refused a finite number as "got inf"
    from stereovision._validate import _plain_option, _plain_real
    from stereovision.matching.fusion import fused_dense

    assert _plain_real(given) is given and _plain_option(given) is given
    d = np.full((6, 8), np.nan, np.float32)
    with pytest.raises(ValueError) as err:
        fused_dense(d, d, d, fill_confidence=given)  # type: ignore[arg-type]
    assert str(err.value).startswith("fill_confidence: expected a finite number, got ")
    assert "inf" not in str(err.value)
    # a Decimal infinity is one, and a Decimal within the range its float, as before
    assert _plain_real(Decimal("-Infinity")) == -np.inf and _plain_real(Decimal("1e300")) == 1e300


def test_first_line_matches_a_part_with_a_control_character_at_an_end_as_a_whole_name() -> None:
    """A part ending with a control character was bounded only after it, one opening with one
    only before it: ``a\\n`` of ``scans/a\\n`` still matched in ``data\\n\\nhint`` (a blank line)
    and ``\\nb`` of ``scans/\\nb`` in ``cannot read:\\nbad format``, so the message's own break
    was shown escaped and its next line on the first."""
    from stereovision._validate import first_line

    assert first_line(ValueError("cannot read data\n\nhint"), ["scans/a\n"]) == "cannot read data"
    assert first_line(ValueError("cannot read:\nbad format"), ["scans/\nb"]) == "cannot read:"
    # where the name is whole, it is still escaped
    assert first_line(ValueError("not found: scans/a\n\nhint"), ["scans/a\n"]) == (
        "not found: scans/a\\n"
    )
    assert first_line(ValueError("not found: 'scans/\nb':\nhint"), ["scans/\nb"]) == (
        "not found: 'scans/\\nb':"
    )


def test_a_name_byte_that_is_not_utf8_is_shown_escaped_and_prints_in_strict_utf8() -> None:
    """A file name's byte that is not UTF-8 (0xE9 of a Latin-1 ``café``) is a lone surrogate
    once os.fsdecode'd; escaped() left it as it was, so a line naming it raised
    UnicodeEncodeError on a UTF-8 standard output outside the C locale (``depth -o café``: the
    files written, then 'stereovision: error: 'utf-8' codec can't encode character '\\udce9''
    and exit 2). It is shown as Python names it, ``\\udce9``."""
    import os

    from stereovision._validate import escaped, first_line

    name = os.fsdecode(b"scans/caf\xe9.png")
    assert escaped(name) == "scans/caf\\udce9.png"
    assert escaped(name).encode("utf-8") == b"scans/caf\\udce9.png"
    assert first_line(FileNotFoundError(f"image file not found: {name}"), [name]) == (
        "image file not found: scans/caf\\udce9.png"
    )
