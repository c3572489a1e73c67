"""Numerical and shape edge cases of the entry points that reach the Rust kernels: tiny and
constant images, non-finite and huge values, memory layouts, and integer arguments beyond their
type. Each gives a correct result or a ValueError / TypeError naming the problem: never a panic,
a hang, an ``OverflowError`` naming nothing, or a map spoilt without a word.

Parameters out of range through the Python wrappers are tests/test_bad_params.py's; wrong
array types and allocation failures given to the extension, tests/test_bindings_input.py's.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import stereovision as sv
from stereovision import _core, refine
from stereovision.matching import fusion, gabor

RNG = np.random.default_rng(0)
LEFT = RNG.random((40, 60), dtype=np.float32)
RIGHT = np.roll(LEFT, -3, axis=1)  # every pixel 3 px closer on the right image

DEPTH_METHODS = ["fused", "gabor", "census", "fast"]
MATCH_METHODS = ["hopfield", "best", "mcgm", "fused", "gabor"]


# --- images ------------------------------------------------------------------------------------


@pytest.mark.parametrize("shape", [(1, 40), (5, 5), (9, 9), (12, 12)])
@pytest.mark.parametrize("method", DEPTH_METHODS)
def test_depth_map_of_tiny_images_has_their_shape(shape: tuple[int, int], method: str) -> None:
    left = RNG.random(shape, dtype=np.float32)
    res = sv.depth_map(left, np.roll(left, -1, axis=1), method=method, max_disparity=4)
    assert res.disparity.shape == res.confidence.shape == shape
    d = res.disparity[np.isfinite(res.disparity)]
    assert ((d >= 0) & (d <= 4)).all()


@pytest.mark.parametrize("shape", [(40, 1), (2, 2), (3, 3)])
@pytest.mark.parametrize("method", DEPTH_METHODS)
def test_depth_map_narrower_than_the_range_is_refused(shape: tuple[int, int], method: str) -> None:
    left = RNG.random(shape, dtype=np.float32)
    with pytest.raises(ValueError, match="disparity range 4 is not smaller than the image width"):
        sv.depth_map(left, left, method=method, max_disparity=4)


@pytest.mark.parametrize("shape", [(1, 40), (5, 5)])
@pytest.mark.parametrize("method", MATCH_METHODS)
def test_matches_of_tiny_images_are_none(shape: tuple[int, int], method: str) -> None:
    left = RNG.random(shape, dtype=np.float32)
    assert len(sv.match(left, left, method=method, max_disparity=4)) == 0


@pytest.mark.parametrize("matcher", ["gabor", "sgm", "hopfield", "mcgm"])
def test_the_matchers_search_a_range_past_the_image_to_its_edge(matcher: str) -> None:
    """What stereovision.matching's docstring says: the functions there search a range past
    the image to its edge (max_disparity 200 on LEFT, 60 px wide: the result of 60), where
    match refuses it; a range wholly past the image is refused by both, in the same words."""
    from stereovision.matching import hopfield, mcgm, sgm

    run = {
        "gabor": lambda md, lo=0: (
            gabor.gabor_disparity(LEFT, RIGHT, max_disparity=md, min_disparity=lo).disparity
        ),
        "sgm": lambda md, lo=0: sgm.sgm_disparity(LEFT, RIGHT, max_disparity=md, min_disparity=lo),
        "hopfield": lambda md, lo=0: (
            hopfield.hopfield_match(LEFT, RIGHT, max_disparity=md, min_disparity=lo).dispx
        ),
        "mcgm": lambda md, lo=0: (
            mcgm.mcgm_match(LEFT, RIGHT, max_disparity=md, min_disparity=lo).dispx
        ),
    }[matcher]
    np.testing.assert_array_equal(run(200), run(60))
    with pytest.raises(
        ValueError, match="disparity range 200 is not smaller than the image width 60"
    ):
        sv.match(LEFT, RIGHT, method="gabor", max_disparity=200)
    words = r"^min_disparity \(70\) is not below the image width 60"
    with pytest.raises(ValueError, match=words):
        run(200, 70)
    with pytest.raises(ValueError, match=words):
        sv.match(LEFT, RIGHT, method="gabor", max_disparity=200, min_disparity=70)


@pytest.mark.parametrize(
    ("shape", "max_disparity"),
    [((40, 1), 4), ((1, 1), 4), ((3, 3), 4), ((24, 30), 30), ((24, 30), 40), ((24, 30), 1e300)],
)
@pytest.mark.parametrize("method", MATCH_METHODS)
def test_match_narrower_than_the_range_is_refused_as_depth_map_refuses_it(
    shape: tuple[int, int], max_disparity: float, method: str
) -> None:
    """A range not below the width (max_disparity 40 on a 30 px wide uncalibrated pair):
    depth_map refused it, match searched it (clipped to the image) without a word. Both refuse
    it now, in the same words."""
    left = RNG.random(shape, dtype=np.float32)
    with pytest.raises(ValueError) as want:
        sv.depth_map(left, left, max_disparity=max_disparity)
    assert str(want.value).startswith("disparity range ")
    with pytest.raises(ValueError) as got:
        sv.match(left, left, None, method=method, max_disparity=max_disparity)
    assert str(got.value) == str(want.value)


@pytest.mark.parametrize("width", [1, 2, 16])
@pytest.mark.parametrize("method", MATCH_METHODS)
def test_match_of_a_pair_too_narrow_for_the_automatic_range_is_refused(
    width: int, method: str
) -> None:
    """With no max_disparity, a pair 16 px wide or narrower (the estimate is at least 16 px)
    was matched without a word by match and refused by depth_map: match says depth_map's
    words."""
    left = np.random.default_rng(0).integers(0, 256, (24, width), dtype=np.uint8)
    right = np.roll(left, -1, axis=1)
    with pytest.raises(ValueError) as want:
        sv.depth_map(left, right)
    assert str(want.value).startswith(f"image too narrow for stereo matching: {width} px wide")
    with pytest.raises(ValueError) as got:
        sv.match(left, right, method=method)
    assert str(got.value) == str(want.value)


def test_constant_images_give_no_measurement() -> None:
    flat = np.full((40, 60), 0.5, np.float32)
    for method in DEPTH_METHODS:
        res = sv.depth_map(flat, flat, method=method, max_disparity=8)
        assert np.isnan(res.disparity).all(), method
    for method in MATCH_METHODS:
        assert len(sv.match(flat, flat, method=method, max_disparity=8)) == 0, method


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_one_non_finite_pixel_is_named(value: float) -> None:
    left = LEFT.copy()
    left[20, 30] = value
    says = "left: float image contains 1 NaN/inf value"
    with pytest.raises(ValueError, match=says):
        sv.depth_map(left, RIGHT, method="gabor", max_disparity=8)
    with pytest.raises(ValueError, match=says):
        sv.match(left, RIGHT, max_disparity=8)
    kernel = "left: image contains non-finite values (NaN or inf) at 1 pixels"
    for call in (
        lambda: _core.gabor_disparity(left, RIGHT, 0.0, 8.0),
        lambda: _core.sgm_disparity(left, RIGHT, 0, 8, 8, 96, 16.0, 5, 1, 4),
        lambda: _core.hopfield_match(left, RIGHT, {"max_disparity": 8}),
        lambda: _core.mcgm_match(left, RIGHT, {"max_disparity": 8}),
    ):
        with pytest.raises(ValueError, match=re.escape(kernel)):
            call()


#: The wrappers that hand a float grey image to a kernel as it is (no scaling).
UNSCALED: dict[str, Callable[[np.ndarray], object]] = {
    "gabor_disparity": lambda a: gabor.gabor_disparity(a, RIGHT, max_disparity=8),
    "gabor_responses": lambda a: gabor.gabor_responses(a),
    "refine_disparity": lambda a: refine.refine_disparity(
        a, RIGHT, np.full(a.shape, 3.0, np.float32), max_disparity=8
    ),
    "remeasure": lambda a: fusion.remeasure(
        a, RIGHT, np.full(a.shape, 3.0, np.float32), np.ones(a.shape, np.float32), max_disparity=8
    ),
}


@pytest.mark.parametrize("what", list(UNSCALED))
@pytest.mark.parametrize("value", [1e30, 255.0, -0.5])
def test_float_grey_levels_outside_0_1_are_refused(what: str, value: float) -> None:
    """One pixel of 1e30 (its square is infinite in float32) made the whole refined map NaN and a
    quarter of the Gabor map, without a word; an 8-bit image passed as float was read as is."""
    UNSCALED[what](LEFT)
    left = LEFT.copy()
    left[20, 30] = value
    with pytest.raises(ValueError, match=r"left|image") as exc:
        UNSCALED[what](left)
    assert "float image values must lie in [0, 1], got range" in str(exc.value)


def test_the_refinement_keeps_its_map_for_grey_levels_in_range() -> None:
    d = np.full(LEFT.shape, 3.0, np.float32)
    r = refine.refine_disparity(LEFT, RIGHT, d, max_disparity=8)
    assert np.nanmedian(np.abs(r.disparity - 3.0)) < 0.05
    assert np.isfinite(r.disparity).mean() > 0.8


@pytest.mark.parametrize(
    "layout",
    [
        np.copy,
        lambda a: np.ascontiguousarray(a[::-1, ::-1])[::-1, ::-1],  # negative strides
        np.asfortranarray,
        lambda a: np.pad(a, ((0, 0), (0, 7)))[:, :60],  # a view with a row stride
    ],
)
def test_any_memory_layout_gives_the_same_result(layout: Callable[[np.ndarray], Any]) -> None:
    left, right = layout(LEFT), layout(RIGHT)
    for a in (left, right):
        a.flags.writeable = False  # read-only buffers are read only
    np.testing.assert_array_equal(left, LEFT)
    want = _core.gabor_disparity(LEFT, RIGHT, 0.0, 8.0)
    got = _core.gabor_disparity(left, right, 0.0, 8.0)
    for g, w in zip(got, want, strict=True):
        np.testing.assert_array_equal(g, w)
    np.testing.assert_array_equal(
        _core.sgm_disparity(left, right, 0, 8, 8, 96, 16.0, 5, 1, 4),
        _core.sgm_disparity(LEFT, RIGHT, 0, 8, 8, 96, 16.0, 5, 1, 4),
    )
    m, _, _ = _core.mcgm_match(left, right, {"max_disparity": 8})
    np.testing.assert_array_equal(m, _core.mcgm_match(LEFT, RIGHT, {"max_disparity": 8})[0])
    got_m = sv.match(left, right, max_disparity=8)
    want_m = sv.match(LEFT, RIGHT, max_disparity=8)
    assert len(want_m) > 50
    np.testing.assert_array_equal(got_m.xl, want_m.xl)
    np.testing.assert_array_equal(got_m.xr, want_m.xr)


# --- ranges ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("max_disparity", "says"),
    [
        (0, r"max_disparity \(0\) must be larger than min_disparity"),
        (-1, r"max_disparity \(-1\) must be larger than min_disparity"),
        (60, "disparity range 60 is not smaller than the image width 60"),
        (float("nan"), "max_disparity: expected a finite number, got nan"),
        (True, "max_disparity: expected a number of pixels, got True"),
    ],
)
@pytest.mark.parametrize("method", DEPTH_METHODS)
def test_depth_map_range_edges(max_disparity: object, says: str, method: str) -> None:
    with pytest.raises((ValueError, TypeError), match=says):
        sv.depth_map(LEFT, RIGHT, method=method, max_disparity=max_disparity)


@pytest.mark.parametrize("method", DEPTH_METHODS)
def test_depth_map_min_above_max_is_refused(method: str) -> None:
    with pytest.raises(ValueError, match=r"max_disparity \(8\) must be larger than min_disparity"):
        sv.depth_map(LEFT, RIGHT, method=method, max_disparity=8, min_disparity=10)


@pytest.mark.parametrize("method", DEPTH_METHODS)
def test_depth_map_over_a_fractional_range(method: str) -> None:
    res = sv.depth_map(LEFT, RIGHT, method=method, max_disparity=4.5)
    d = res.disparity[np.isfinite(res.disparity)]
    assert d.size > 0.5 * LEFT.size and abs(float(np.median(d)) - 3.0) < 0.1


# --- the extension's integer arguments ---------------------------------------------------------

D = LEFT * 5
U8 = (RNG.random((20, 30, 3)) * 255).astype(np.uint8)


def _refine(**kw: Any) -> object:
    args: dict[str, Any] = {
        "d_min": 0.0,
        "d_max": 8.0,
        "base_sigma": 1.0,
        "win_sigma": 1.5,
        "win_radius": 3,
        "search": 2,
        "step": 0.25,
        "fill_search": 2,
        "fill_step": 0.5,
        "var_floor": 1e-4,
        "fills": [(1.0, 0.5)],
        "fill_confidence": 0.1,
        "fill_plane": True,
        "fill_max_residual": 1.0,
    }
    args.update(kw)
    return _core.refine_disparity(LEFT, RIGHT, D, np.full_like(D, 0.5), *args.values())


def _sgm(**kw: Any) -> object:
    args: dict[str, Any] = {"d_min": 0, "d_max": 8, "p1": 8, "p2": 96, "gamma": 16.0}
    args.update({"uniqueness": 5, "lr_tol": 1, "edge_margin": 4, "paths": 8})
    args.update(kw)
    return _core.sgm_disparity(LEFT, RIGHT, *args.values())


#: (name, lowest, highest, call with that argument): an integer outside the range was a bare
#: OverflowError ("can't convert negative int to unsigned", "out of range integral type
#: conversion attempted", "int too big to convert") that named nothing.
U64 = 2**64 - 1
INTS: list[tuple[str, int, int, Callable[[Any], object]]] = [
    ("radius", 0, U64, lambda v: _core.fattened(D, LEFT, v, 2.0, 2.0)),
    ("min_size", 0, U64, lambda v: _core.gabor_remove_speckles(D, v, 1.0)),
    ("min_pixels", 0, U64, lambda v: _core.plane_fill(D, np.zeros(D.shape, np.uint32), v, 1, 0, 5)),
    ("min_size", 0, U64, lambda v: _core.graph_segments(U8.astype(np.float32), 1.0, v)),
    ("step", 0, 2**32 - 1, lambda v: _core.quantised_regions(U8, v, 0)),
    ("offset", 0, 2**32 - 1, lambda v: _core.quantised_regions(U8, 16, v)),
    ("nms_half", 0, U64, lambda v: _core.hopfield_interest(LEFT, nms_half=v)),
    ("tile", 0, U64, lambda v: _core.hopfield_interest(LEFT, tile=v)),
    ("n_levels", 0, U64, lambda v: _core.gabor_disparity(LEFT, RIGHT, 0.0, 8.0, n_levels=v)),
    ("speckle_size", 0, U64, lambda v: _core.gabor_disparity(LEFT, RIGHT, 0, 8, speckle_size=v)),
    ("fine_levels", 0, U64, lambda v: _core.gabor_disparity(LEFT, RIGHT, 0, 8, fine_levels=v)),
    ("win_radius", 0, U64, lambda v: _refine(win_radius=v)),
    ("fill_search", 0, U64, lambda v: _refine(fill_search=v)),
    ("d_max", -(2**31), 2**31 - 1, lambda v: _sgm(d_max=v)),
    ("p2", 0, 2**16 - 1, lambda v: _sgm(p2=v)),
    ("edge_margin", 0, 2**32 - 1, lambda v: _sgm(edge_margin=v)),
    (
        "max_frames",
        0,
        255,
        lambda v: _core.temporal_running_mean(
            U8, np.zeros(U8.shape, np.float32), np.zeros((20, 30), np.uint8), D[:20, :30], 2, v
        ),
    ),
]


@pytest.mark.parametrize("case", range(len(INTS)), ids=[f"{c[0]}-{i}" for i, c in enumerate(INTS)])
def test_an_integer_beyond_its_type_names_the_argument(case: int) -> None:
    name, lo, hi, call = INTS[case]
    says = f"invalid parameter `{name}`: expected " + ("None or " if name == "n_levels" else "")
    says += f"an integer from {lo} to {hi}, got "
    for value in (lo - 1, hi + 1, 2**70):
        with pytest.raises(ValueError, match=re.escape(says + str(value))):
            call(value)
    with pytest.raises(TypeError, match=f"invalid parameter `{name}`: .*float"):
        call(2.5)


def test_fill_planes_passes_name_the_bad_element() -> None:
    """A bad element of ``passes`` was named by the whole list ("expected a list of (step,
    min_pixels) pairs, ...") or by its step alone ("every step must be in 1-255, got 0"); the
    error names the element's index and value and what is wrong with it."""
    says = "invalid parameter `passes`: element "
    with pytest.raises(
        ValueError,
        match=re.escape(says + f"0 ((16, -1)): min_pixels must be an integer from 0 to {U64}"),
    ):
        _core.fill_planes(D, U8, [(16, -1)], 1.0)
    for bad in (0, 256, -1, 2**70):
        with pytest.raises(
            ValueError, match=re.escape(says + f"1 (({bad}, 5)): step must be an integer in 1-255")
        ):
            _core.fill_planes(D, U8, [(16, 5), (bad, 5)], 1.0)
    for bad in (7, (3,), (1, 2, 3), "ab"):
        with pytest.raises(
            ValueError, match=re.escape(says + f"1 ({bad!r}): expected a (step, min_pixels) pair")
        ):
            _core.fill_planes(D, U8, [(16, 5), bad], 1.0)
    with pytest.raises(TypeError, match=r"`passes`: expected a sequence of .*, got 'ab'"):
        _core.fill_planes(D, U8, "ab", 1.0)


def test_sgm_paths_names_what_the_kernel_takes() -> None:
    """``paths`` outside a byte said "expected an integer from 0 to 255", though the kernel
    takes 8 or 3 only; every other integer is answered with what it takes."""
    for bad in (-1, 0, 4, 255, 256, 2**70):
        with pytest.raises(
            ValueError, match=re.escape(f"invalid parameter `paths`: expected 8 or 3, got {bad}")
        ):
            _sgm(paths=bad)
    with pytest.raises(TypeError, match=r"invalid parameter `paths`: .*float"):
        _sgm(paths=2.5)
    assert _sgm(paths=3).shape == _sgm(paths=8).shape == LEFT.shape


def test_matcher_parameter_dicts_name_an_integer_range() -> None:
    """A negative ``min_disparity`` in the MCGM or Hopfield dict was "parameter `min_disparity`:
    OverflowError: can't convert negative int to unsigned"; it names the range now, and
    ``mcgm_filter`` refuses a range that ``mcgm_match`` refuses (it returned flags)."""
    none = np.zeros((0, 4), np.float32)
    for call in (
        lambda p: _core.mcgm_filter(LEFT, LEFT, none, p),
        lambda p: _core.mcgm_match(LEFT, LEFT, p),
        lambda p: _core.hopfield_match(LEFT, LEFT, p),
    ):
        for key in ("min_disparity", "max_disparity"):
            for bad in (-1, 2**64):
                says = f"invalid parameter `{key}`: expected an integer from 0 to {U64}, got {bad}"
                with pytest.raises(ValueError, match=re.escape(says)):
                    call({key: bad})
    with pytest.raises(
        ValueError, match=re.escape("invalid parameter `seed`: expected an integer from 0 to")
    ):
        _core.mcgm_filter(LEFT, LEFT, none, {"seed": -1})
    wrong = {"min_disparity": 9, "max_disparity": 4}
    says = "invalid parameter `max_disparity`: must be >= min_disparity (9), got 4"
    with pytest.raises(ValueError, match=re.escape(says)):
        _core.mcgm_filter(LEFT, LEFT, none, wrong)
    with pytest.raises(ValueError, match=re.escape("max_disparity")):
        _core.mcgm_match(LEFT, LEFT, wrong)


def test_a_fattening_radius_beyond_the_map_is_the_whole_map() -> None:
    """A radius of 2**31 px looped over every offset (minutes on a 40 x 60 map), and one of
    2**63 or more wrapped to a negative radius in the kernel: other pixels marked."""
    d = np.where(np.arange(60) < 30, 2.0, 9.0).astype(np.float32)[None].repeat(40, 0)
    g = np.where(np.arange(60) < 36, 0.2, 0.8).astype(np.float32)[None].repeat(40, 0)
    whole = _core.fattened(d, g, 60, 2.0, 2.0)
    assert whole.sum() == 40 * 6  # columns 30-35: the foreground carried to the colour edge
    for radius in (61, 2**64 - 1, 2**63, 2**31):
        np.testing.assert_array_equal(_core.fattened(d, g, radius, 2.0, 2.0), whole)


def test_an_infinite_disparity_has_no_depth() -> None:
    """+inf gave depth 0 and sigma 0 (a point on the camera); ``depth_from_disparity`` gives NaN."""
    d = np.array([[np.inf, -np.inf, 8.0]], np.float32)
    z, s = _core.depth_rectified(d, np.full_like(d, 0.5), 50.0, 2.0, 0.74, -0.52, 0.2, 0.9)
    assert np.isnan(z[0, :2]).all() and np.isnan(s[0, :2]).all()
    assert z[0, 2] == 5.0


@pytest.mark.parametrize("method", MATCH_METHODS)
@pytest.mark.parametrize(
    ("min_disparity", "max_disparity", "shown"),
    # 48 to 48: a one-level range at the width gave hopfield/best/mcgm 0 matches without a word
    [(48, 64, "48"), (100, 116, "100"), (3e10, 3e10 + 16, "30000000000"), (48, 48, "48")],
)
def test_match_refuses_a_min_disparity_not_below_the_width(
    method: str, min_disparity: float, max_disparity: float, shown: str
) -> None:
    """No pixel of a 48 px wide pair has a match 48 px or more to its left: match() returned 0
    matches without a word (or for 3e10, which float32 does not tell from 3e10 + 16, the kernel's
    "invalid parameter `d_max`"); it says what depth_map says."""
    left = np.random.default_rng(0).integers(0, 256, (24, 48), dtype=np.uint8)
    with pytest.raises(ValueError) as err:
        sv.match(
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
    assert "d_max" not in str(err.value)


@pytest.mark.parametrize("method", MATCH_METHODS)
@pytest.mark.parametrize(
    ("name", "value", "shown"),
    [
        ("max_disparity", np.array(48), "array(48)"),
        ("max_disparity", True, "True"),
        ("max_disparity", "32", "'32'"),
        ("min_disparity", None, "None"),
        ("min_disparity", np.array(0), "array(0)"),
    ],
)
def test_match_refuses_a_range_of_another_type_as_depth_map_does(
    method: str, name: str, value: object, shown: str
) -> None:
    """A 0-d array passed "gabor" and was refused by the others as "must be a non-negative
    number of pixels"; True or None was a ValueError in two wordings: depth_map's TypeError."""
    left = np.random.default_rng(0).integers(0, 256, (24, 48), dtype=np.uint8)
    words = f"{name}: expected a number of pixels, got {shown}"
    with pytest.raises(TypeError) as err:
        sv.match(left, left.copy(), method=method, **{name: value})
    assert str(err.value) == words
    with pytest.raises(TypeError) as err:
        sv.depth_map(left, left.copy(), **{name: value})
    assert str(err.value) == words


@pytest.mark.parametrize("method", MATCH_METHODS)
def test_match_names_a_max_disparity_below_min_disparity_first(method: str) -> None:
    """A max_disparity the caller gave below min_disparity is the mistake named, even when the
    min_disparity is past the width too (match()'s docstring: left to the matchers' checks)."""
    left = np.random.default_rng(0).integers(0, 256, (24, 48), dtype=np.uint8)
    with pytest.raises(ValueError, match=r"max_disparity \(10\) must be .*min_disparity \(60\)"):
        sv.match(left, left.copy(), method=method, min_disparity=60, max_disparity=10)


@pytest.mark.parametrize("method", MATCH_METHODS)
def test_match_of_a_flat_pair_in_a_reachable_range_is_still_empty(method: str) -> None:
    """The refusal is of the range, not of the pair: a pair with no edges, in a range it can
    match in (up to the width minus one), has zero matches, not an error."""
    flat = np.full((24, 48), 0.5, np.float32)
    assert len(sv.match(flat, flat, method=method, min_disparity=47, max_disparity=63)) == 0


_PAIR = np.random.default_rng(1).random((24, 48), dtype=np.float32)
_DISP = np.full((24, 48), 10.0, np.float32)
_CONF = np.full((24, 48), 0.9, np.float32)


@pytest.mark.parametrize(
    "run",
    [
        lambda lo, hi: gabor.gabor_disparity(_PAIR, _PAIR, min_disparity=lo, max_disparity=hi),
        lambda lo, hi: refine.refine_disparity(
            _PAIR, _PAIR, _DISP, _CONF, min_disparity=lo, max_disparity=hi
        ),
        lambda lo, hi: fusion.fuse_pair(_PAIR, _PAIR, min_disparity=lo, max_disparity=hi),
        lambda lo, hi: fusion.remeasure(
            _PAIR, _PAIR, _DISP, _CONF, min_disparity=lo, max_disparity=hi
        ),
        lambda lo, hi: sv.depth_map(
            _PAIR, _PAIR, method="gabor", min_disparity=lo, max_disparity=hi
        ),
        lambda lo, hi: sv.depth_map(
            _PAIR, _PAIR, method="fused", min_disparity=lo, max_disparity=hi
        ),
        lambda lo, hi: sv.match(_PAIR, _PAIR, method="gabor", min_disparity=lo, max_disparity=hi),
        lambda lo, hi: sv.match(_PAIR, _PAIR, method="fused", min_disparity=lo, max_disparity=hi),
    ],
)
def test_a_range_float32_cannot_tell_apart_is_named_in_the_callers_words(
    run: Callable[[float, float], object],
) -> None:
    """10 to 10.0000001 is one float32 number: the kernels said "invalid parameter `d_max`: must
    be > d_min (10), got 10" (or "`range`: need finite d_min < d_max"), words the caller never
    used; the error names max_disparity and min_disparity."""
    with pytest.raises(ValueError) as err:
        run(10, 10.0000001)
    assert str(err.value) == (
        "empty disparity range in float32, the matchers' precision: max_disparity (10.0000001) "
        "and min_disparity (10) are the same float32 number (10); give a wider range"
    )


@pytest.mark.parametrize("method", MATCH_METHODS)
def test_match_with_the_automatic_range_refuses_a_min_disparity_not_below_the_width(
    method: str,
) -> None:
    """With no max_disparity, min_disparity 100 on a 48 px wide pair was told the estimate (24)
    "must be >= min_disparity (100)"; a larger max_disparity only led to the refusal of a
    min_disparity no pixel reaches: the error says that at once."""
    left = np.random.default_rng(0).integers(0, 256, (24, 48), dtype=np.uint8)
    with pytest.raises(ValueError) as err:
        sv.match(left, left.copy(), method=method, min_disparity=100)
    assert str(err.value).startswith("min_disparity (100) is not below the image width 48")


@pytest.mark.parametrize("method", MATCH_METHODS)
@pytest.mark.parametrize("max_disparity", [10**401, None], ids=["10**401", "automatic"])
def test_match_refuses_a_min_disparity_too_large_for_a_float(
    method: str, max_disparity: int | None
) -> None:
    """min_disparity 10**400 (to 10**401) returned 0 matches without a word from hopfield, best
    and mcgm: the check of an unreachable range skipped a value beyond a float. It is refused
    as any min_disparity not below the width, its size shown, not its 401 digits."""
    left = np.random.default_rng(0).integers(0, 256, (24, 48), dtype=np.uint8)
    with pytest.raises(ValueError) as err:
        sv.match(
            left, left.copy(), method=method, min_disparity=10**400, max_disparity=max_disparity
        )
    assert str(err.value).startswith(
        "min_disparity (an integer of 401 digits) is not below the image width 48: "
    )


@pytest.mark.parametrize("method", MATCH_METHODS)
def test_match_with_a_max_disparity_beyond_a_float_is_named_as_depth_map_names_it(
    method: str,
) -> None:
    """10**400 was an OverflowError in match's final range cut (837713f6 then searched the
    whole width with it, where depth_map refuses it); the range check's own subtraction
    overflowed too. It is refused as depth_map refuses it, as are 1e300 and 2**70 (ranges not
    below the width)."""
    from tests.test_mcgm import _blurred_pair

    left, right = _blurred_pair()
    for big in (10**400, 1e300, 2**70):
        with pytest.raises(ValueError) as want:
            sv.depth_map(left, right, max_disparity=big)
        with pytest.raises(ValueError) as got:
            sv.match(left, right, method=method, max_disparity=big)
        assert str(got.value) == str(want.value)
    assert str(got.value).startswith("disparity range 1.18059162072e+21 is not smaller than")
    with pytest.raises(ValueError, match=r"^max_disparity: expected a finite number, got an int"):
        sv.match(left, right, method=method, max_disparity=10**400)


@pytest.mark.parametrize("method", ["hopfield", "best", "mcgm"])
def test_match_drops_the_integer_searchs_matches_above_a_fractional_max(method: str) -> None:
    """max_disparity 2.5 is searched up to level 3: a pair shifted 3 px has its matches there,
    and every one is dropped (counted in n_out_of_range), none kept up to the ceiling."""
    from tests.test_mcgm import _blurred_pair

    left, right = _blurred_pair(3)
    whole = sv.match(left, right, method=method, max_disparity=3)
    assert np.count_nonzero(whole.xl - whole.xr > 2.5) > 20
    cut = sv.match(left, right, method=method, max_disparity=2.5)
    assert (cut.xl - cut.xr <= 2.5).all()
    assert cut.stats["n_out_of_range"] >= np.count_nonzero(whole.xl - whole.xr > 2.5)


def test_match_range_cut_drops_and_counts_a_single_match() -> None:
    """One match out of range is dropped and counted like any number of them."""
    from stereovision.match import _in_range, _keep
    from stereovision.matches import Matches

    x = np.array([10.0, 20.0, 30.0], np.float32)
    m = Matches(
        x, x * 0, x - np.array([2.0, 5.0, 9.0], np.float32), x * 0, np.ones_like(x), (8, 40)
    )
    out = _keep(m, _in_range(m, 0, 8))
    np.testing.assert_array_equal(out.xl, [10.0, 20.0])
    assert out.stats["n_out_of_range"] == 1


@pytest.mark.parametrize("method", ["sgm", "census", "fast", "Hopfield", ""])
def test_match_refuses_a_method_it_does_not_have(method: str) -> None:
    """match()'s methods are exactly its documented five; depth_map's dense names (or a
    misspelt one) are refused by name, not run as another matcher."""
    from stereovision.match import METHODS

    assert METHODS == ("hopfield", "best", "mcgm", "fused", "gabor")
    with pytest.raises(ValueError, match=f"unknown method '{method}'"):
        sv.match(LEFT, RIGHT, method=method, max_disparity=8)


# --- images too large for the kernels: refused from their shape, before any copy ----------------

#: Each entry point given shape-only (broadcast) arrays past the kernels' 32-bit pixel indices (the
#: images, and maps of their size that triangulation, evaluation, export and ground read), in
#: a child under ``ulimit -v`` 3 GB: the grey, BGR, float32 or byte-order copies made before any
#: check needed 4.6-37 GiB, so the user got a MemoryError instead of the limit. segments of a
#: 1 x 5e9 row went to OpenCV's blur, which wrapped the width: a (1, 705032704) label map came
#: back under ``ulimit -v`` 8 GB, a SIGSEGV under 3 GB (cv2.error for 70000 x 70000). Each
#: outcome is printed as it comes: a crash leaves the rest unsaid.
_TOO_LARGE_SCRIPT = """
import resource, sys
import numpy as np
resource.setrlimit(resource.RLIMIT_AS, (3_000_000 * 1024, 3_000_000 * 1024))
import stereovision as sv
import pathlib, tempfile
from stereovision import evaluate, export, io, refine, temporal, triangulation
from stereovision.matching import gabor, hopfield, mcgm, planes, sgm

CALIB = sv.Calibration.from_file(pathlib.Path(sv.__file__).parent / "data/cones/calib.txt")
OUT = tempfile.mkdtemp()

SQ, ROW = (70000, 70000), (1, 5_000_000_000)
def u8(shape): return np.broadcast_to(np.uint8(0), shape)
def f32(shape): return np.broadcast_to(np.float32(0), shape)
kw = {"max_disparity": 64}
CASES = {
    "depth_map": lambda: sv.depth_map(u8(SQ), u8(SQ), **kw),
    "depth_map_bgr_row": lambda: sv.depth_map(u8(ROW + (3,)), u8(ROW + (3,)), **kw),
    "depth_map_big_endian": lambda: sv.depth_map(
        np.broadcast_to(np.zeros((), ">u2"), SQ), np.broadcast_to(np.zeros((), ">u2"), SQ), **kw
    ),
    "match_hopfield_row": lambda: sv.match(u8(ROW), u8(ROW), **kw),
    "match_mcgm": lambda: sv.match(u8(SQ), u8(SQ), method="mcgm", **kw),
    "match_gabor": lambda: sv.match(f32(SQ), f32(SQ), method="gabor", **kw),
    "estimate_max_disparity": lambda: sv.estimate_max_disparity(u8(SQ), u8(SQ)),
    "check_rectification": lambda: sv.check_rectification(u8(SQ), u8(SQ)),
    "mcgm_curves": lambda: mcgm.curves(u8(SQ)),
    "sgm_disparity": lambda: sgm.sgm_disparity(u8(SQ), u8(SQ), **kw),
    "hopfield_match": lambda: hopfield.hopfield_match(u8(SQ), u8(SQ), **kw),
    "interest_points_row": lambda: hopfield.interest_points(u8(ROW)),
    "gabor_disparity": lambda: gabor.gabor_disparity(f32(SQ), f32(SQ), **kw),
    "gabor_responses_row": lambda: gabor.gabor_responses(f32(ROW)),
    "refine_disparity": lambda: refine.refine_disparity(u8(SQ), u8(SQ), f32(SQ), **kw),
    "segments_row": lambda: planes.segments(u8(ROW)),
    "fill_planes": lambda: planes.fill_planes(f32(SQ), u8(SQ)),
    "plane_fill": lambda: planes.plane_fill(f32(SQ), np.broadcast_to(np.uint32(0), SQ)),
    "depth_from_disparity": lambda: sv.depth_from_disparity(f32(SQ), CALIB),
    "reproject_row": lambda: triangulation.reproject(f32(ROW), CALIB),
    "gt_depth": lambda: evaluate.gt_depth(f32(SQ), CALIB),
    "fit_ground_plane": lambda: sv.fit_ground_plane(f32(SQ), CALIB),
    "dense_metrics": lambda: evaluate.dense_metrics(f32(SQ), f32(SQ)),
    "depth_metrics_row": lambda: evaluate.depth_metrics(f32(ROW), f32(ROW)),
    "encode_depth_png": lambda: export.encode_depth_png(f32(SQ)),
    "write_depth_png": lambda: export.write_depth_png(OUT + "/d.png", f32(SQ)),
    "write_disparity_png_row": lambda: export.write_disparity_png(OUT + "/p.png", f32(ROW)),
    "write_pfm": lambda: io.write_pfm(OUT + "/d.pfm", f32(SQ)),
    "noise_sigma": lambda: temporal.noise_sigma(u8(SQ)),
    "TemporalFilter": lambda: sv.TemporalFilter()(u8(SQ), u8(SQ)),
    # last: before its check, OpenCV's blur of it crashed the child (SIGSEGV under 3 GB)
    "segments_graph": lambda: planes.segments(u8((2, 1_500_000_000)), k=1.0),
}
for name, call in CASES.items():
    try:
        call()
        print(name, "returned", flush=True)
    except Exception as exc:
        print(name, type(exc).__name__ + ":", str(exc).splitlines()[0][:300], flush=True)
"""

_TOO_LARGE = {
    "depth_map": "left: image of 70000x70000",
    "depth_map_bgr_row": "left: image of 5000000000x1",
    "depth_map_big_endian": "left: image of 70000x70000",
    "match_hopfield_row": "left: image of 5000000000x1",
    "match_mcgm": "left: image of 70000x70000",
    "match_gabor": "left: image of 70000x70000",
    "estimate_max_disparity": "left: image of 70000x70000",
    "check_rectification": "left: image of 70000x70000",
    "mcgm_curves": "image: image of 70000x70000",
    "sgm_disparity": "left: image of 70000x70000",
    "hopfield_match": "left: image of 70000x70000",
    "interest_points_row": "image: image of 5000000000x1",
    "gabor_disparity": "left: image of 70000x70000",
    "gabor_responses_row": "image: image of 5000000000x1",
    "refine_disparity": "left: image of 70000x70000",
    "segments_row": "image: image of 5000000000x1",
    "fill_planes": "disparity: map of 70000x70000",
    "plane_fill": "disparity: map of 70000x70000",
    "depth_from_disparity": "disparity: map of 70000x70000",
    "reproject_row": "disparity: map of 5000000000x1",
    "gt_depth": "disparity: map of 70000x70000",
    "fit_ground_plane": "disparity: map of 70000x70000",
    "dense_metrics": "disparity: map of 70000x70000",
    "depth_metrics_row": "depth: map of 5000000000x1",
    "encode_depth_png": "depth: map of 70000x70000",
    "write_depth_png": "depth: map of 70000x70000",
    "write_disparity_png_row": "disparity: map of 5000000000x1",
    "write_pfm": "arr: map of 70000x70000",
    "noise_sigma": "image: image of 70000x70000",
    "TemporalFilter": "left: image of 70000x70000",
}


@pytest.fixture(scope="module")
def too_large_outcomes() -> dict[str, str]:
    import subprocess
    import sys

    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    out = subprocess.run(
        [sys.executable, "-c", _TOO_LARGE_SCRIPT],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    said = dict(line.split(" ", 1) for line in out.stdout.splitlines())
    if out.returncode != 0:  # a crash: the cases after the last one said have no outcome
        gone = f"no outcome: the child exited {out.returncode} ({out.stderr[-300:]!r})"
        said = {case: said.get(case, gone) for case in _TOO_LARGE}
    return said


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS is Linux's")
@pytest.mark.parametrize("case", list(_TOO_LARGE))
def test_an_image_past_32_bit_indices_is_refused_before_any_copy(
    case: str, too_large_outcomes: dict[str, str]
) -> None:
    """Refused from the shape alone, naming the argument and the limit: no MemoryError for a
    copy of a broadcast image that takes no memory as given (the child has 3 GB)."""
    want = (
        f"ValueError: {_TOO_LARGE[case]} pixels is too large: the kernels index pixels with "
        "32-bit integers (at most 4294967295 pixels, 2147483647 per side)"
    )
    assert too_large_outcomes[case] == want


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS is Linux's")
def test_an_image_past_the_graph_segmentations_limit_is_refused_before_any_copy(
    too_large_outcomes: dict[str, str],
) -> None:
    """segments' graph path (k > 0, min_size > 1, a float image) takes at most 2**31 pixels:
    a 2 x 1.5e9 image (3e9 pixels, within the other kernels' 32-bit indices) was blurred and
    copied as float32 keys (a MemoryError for 11.2 GiB) before graph_segments refused it."""
    assert too_large_outcomes.get("segments_graph") == (
        "ValueError: image: image of 1500000000x2 pixels is too large: the kernels index pixels "
        "with 32-bit integers (at most 2147483648 pixels, 2147483647 per side)"
    )
    from stereovision._validate import check_index_range

    check_index_range((2, 2**30), "image", max_pixels=2**31)
    with pytest.raises(ValueError, match=r"^image: image of 1073741825x2 pixels .* 2147483648 "):
        check_index_range((2, 2**30 + 1), "image", max_pixels=2**31)


def test_check_index_range_at_the_kernels_limits() -> None:
    """The same limits as ``image::check_index_range`` in Rust, on the shape alone."""
    from stereovision._validate import MAX_PIXELS, MAX_SIDE, check_index_range, u8_pair

    fit = [
        (1, 1),
        (MAX_PIXELS // 3, 3),
        (2, MAX_SIDE),
        (MAX_SIDE, 2),
        (65537, 65535),
        (1, MAX_SIDE, 3),
    ]
    for shape in fit:
        check_index_range(shape, "left")
    for shape in [(65536, 65536), (1, MAX_SIDE + 1), (MAX_SIDE + 1, 1), (2, MAX_PIXELS // 2 + 1)]:
        with pytest.raises(ValueError, match=rf"^left: image of {shape[1]}x{shape[0]} pixels"):
            check_index_range(shape, "left")
    # u8_pair leaves a pair too large to check_pair's refusal, without copying it first
    big = np.broadcast_to(np.uint8(0), (65536, 65536))
    assert u8_pair(big, big) is None
    fits = np.broadcast_to(np.uint8(7), (3, 4, 3))
    pair = u8_pair(fits, fits)
    assert pair is not None
    np.testing.assert_array_equal(pair[0], np.full((3, 4, 3), 7, np.uint8))


@pytest.mark.parametrize("make", [np.broadcast_to, "read-only"])
def test_a_broadcast_or_read_only_pair_gives_the_contiguous_result(make: object) -> None:
    """A real pair as a broadcast view (strides of 0 nowhere, but not writeable) or a read-only
    copy: depth_map and match give the contiguous pair's results, bit for bit."""
    from pathlib import Path

    import cv2

    cones = Path(sv.__file__).parent / "data" / "cones"
    left = cv2.imread(str(cones / "left.png"))
    right = cv2.imread(str(cones / "right.png"))
    assert left.shape == (375, 450, 3)
    if make == "read-only":
        views = [left.copy(), right.copy()]
        for v in views:
            v.flags.writeable = False
    else:
        views = [np.broadcast_to(left, left.shape), np.broadcast_to(right, right.shape)]
        assert not views[0].flags.writeable
    want = sv.depth_map(left, right, max_disparity=64)
    got = sv.depth_map(*views, max_disparity=64)
    np.testing.assert_array_equal(got.disparity, want.disparity)
    np.testing.assert_array_equal(got.confidence, want.confidence)
    for method in ("hopfield", "mcgm"):
        mw = sv.match(left, right, method=method, max_disparity=64)
        mg = sv.match(*views, method=method, max_disparity=64)
        assert len(mw) > 100
        np.testing.assert_array_equal(mg.xl, mw.xl)
        np.testing.assert_array_equal(mg.xr, mw.xr)
