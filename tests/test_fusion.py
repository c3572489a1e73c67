"""Triple-channel agreement (algorithms.md D): valid members, radius, modes, bits, bad input."""

from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from stereovision._validate import as_gray_float, check_pair
from stereovision.baselines import opencv_sgbm, row_fill
from stereovision.depth import depth_map as sv_depth_map
from stereovision.evaluate import count_at_precision, dense_metrics, sparse_metrics
from stereovision.io import load_scene
from stereovision.match import match as sv_match
from stereovision.matches import Matches
from stereovision.matching.fusion import (
    CHANNEL_BITS,
    FusionResult,
    _nearest_within_at,
    _radius_offsets,
    census_clear,
    fill_enclosed_far,
    fuse,
    fuse_pair,
    fused_dense,
    remeasure,
)
from stereovision.matching.gabor import GaborResult, gabor_disparity
from stereovision.matching.hopfield import hopfield_match
from tests.reference import edges_ref

H, W = 20, 30


def _m(points: list[tuple[float, float, float]], dy: float = 0.0) -> Matches:
    """Matches at (x, y) with x-disparity d (and a constant y-disparity)."""
    a = np.array(points, np.float32).reshape(-1, 3)
    x, y, d = a[:, 0], a[:, 1], a[:, 2]
    return Matches(x, y, x - d, y - dy, np.ones_like(x), (H, W))


def _dense(value: float, conf: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    return np.full((H, W), value, np.float32), np.full((H, W), conf, np.float32)


def test_vote_keeps_agreeing_pairs_and_averages() -> None:
    # Gabor says 10 everywhere (confidence 0.5); Hopfield points at 10.4, 10.6 (agree) and 14 (no).
    hop = _m([(5, 5, 10.4), (8, 5, 10.6), (12, 7, 14.0)])
    res = fuse(_dense(10.0, 0.5), {"hopfield": hop})
    assert len(res) == 2
    np.testing.assert_array_equal(res.matches.xl, [5, 8])
    # Weighted mean: (0.5 * 10 + 1 * d) / 1.5.
    np.testing.assert_allclose(
        res.matches.xl - res.matches.xr, [(5 + 10.4) / 1.5, (5 + 10.6) / 1.5]
    )
    np.testing.assert_array_equal(res.count, [2, 2])
    np.testing.assert_array_equal(res.sources, [1 | 4, 1 | 4])
    assert res.sources_map[5, 5] == 5 and res.count_map[7, 12] == 0
    assert np.isnan(res.dispx[7, 12]) and res.dispx[5, 8] == pytest.approx((5 + 10.6) / 1.5)


def test_fuse_takes_a_gabor_result_and_names_what_is_no_channel() -> None:
    """gabor_disparity's own result is the dense channel (it was "'GaborResult' object is not
    subscriptable"); the disparity map alone, or a sparse channel's to_array(), is a TypeError
    naming the argument (they failed on a row of the map, on a missing attribute)."""
    hop = _m([(5, 5, 10.4), (8, 5, 10.6), (12, 7, 14.0)])
    d, c = _dense(10.0, 0.5)
    want = fuse((d, c), {"hopfield": hop})
    got = fuse(GaborResult(disparity=d, confidence=c), {"hopfield": hop})
    np.testing.assert_array_equal(got.matches.to_array(), want.matches.to_array())
    np.testing.assert_array_equal(got.sources, want.sources)
    assert len(fuse(np.stack([d, c]), {"hopfield": hop})) == len(want)  # a stacked pair, as before
    with pytest.raises(TypeError, match=r"gabor: expected the \(dispx, conf\) maps or a Gabor"):
        fuse(d, {"hopfield": hop})  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"sparse\['hopfield'\]: expected a stereovision.Matches"):
        fuse(None, {"hopfield": hop.to_array()})  # type: ignore[dict-item]
    # a list of the channels' Matches was "unknown sparse channel Matches(3 matches ...)"
    with pytest.raises(TypeError) as err:
        fuse((d, c), [hop])  # type: ignore[arg-type]
    assert str(err.value) == (
        "sparse: expected the sparse channels by name, {'mcgm': ..., 'hopfield': ...}, got list"
    )


def test_sparse_channels_meet_within_radius() -> None:
    # A corner one pixel (diagonally) off a curve pixel still meets it at r = 1.5, not at 1.0.
    mcgm = _m([(10, 10, 7.0)])
    hop = _m([(11, 11, 7.5)])
    res = fuse(None, {"mcgm": mcgm, "hopfield": hop})
    # Both candidates (10, 10) and (11, 11) see the other channel within 1.5 px.
    assert len(res) == 2
    np.testing.assert_allclose(res.matches.xl - res.matches.xr, [7.25, 7.25])
    np.testing.assert_array_equal(res.sources, [2 | 4, 2 | 4])
    assert len(fuse(None, {"mcgm": mcgm, "hopfield": hop}, r_spatial=1.0)) == 0


@pytest.mark.parametrize("r", [1.0, 1.5, 2.5])
def test_nearest_within_takes_the_first_measured_offset(r: float) -> None:
    rng = np.random.default_rng(int(r * 10))
    h, w = 23, 31
    dx = np.where(rng.random((h, w)) < 0.15, rng.random((h, w)) * 40, np.nan).astype(np.float32)
    dy = np.where(rng.random((h, w)) < 0.9, rng.random((h, w)), np.nan).astype(np.float32)
    ys, xs = np.nonzero(np.ones((h, w), bool))
    got_x, got_y = (v.reshape(h, w) for v in _nearest_within_at(dx, dy, r, ys, xs))
    want_x = np.full((h, w), np.nan, np.float32)
    want_y = np.full((h, w), np.nan, np.float32)
    for y in range(h):
        for x in range(w):
            for oy, ox in _radius_offsets(r):
                sy, sx = y + oy, x + ox
                if 0 <= sy < h and 0 <= sx < w and np.isfinite(dx[sy, sx]):
                    want_x[y, x], want_y[y, x] = dx[sy, sx], dy[sy, sx]
                    break
    assert np.array_equal(got_x, want_x, equal_nan=True)
    assert np.array_equal(got_y, want_y, equal_nan=True)
    assert np.isfinite(got_x).sum() > np.isfinite(dx).sum()  # it did spread


def test_vote_prefers_larger_subset_then_smaller_spread() -> None:
    mcgm = _m([(3, 3, 20.0), (6, 3, 20.0)])
    hop = _m([(3, 3, 20.8), (6, 3, 19.4)])
    # At (3, 3): gabor 20.5 agrees with both (0.5, 0.3) and they agree (0.8): all three.
    # At (6, 3): mcgm-hop differ by 0.6 and gabor 20.5 differs from hop by 1.1: pair mcgm+gabor
    # (spread 0.5) or mcgm+hop (0.6) -> the smaller spread wins.
    res = fuse(_dense(20.5), {"mcgm": mcgm, "hopfield": hop})
    assert list(res.count) == [3, 2]
    assert list(res.sources) == [7, 1 | 2]
    np.testing.assert_allclose(res.matches.xl - res.matches.xr, [(20.5 + 20 + 20.8) / 3, 20.25])


def test_intersection_needs_every_channel() -> None:
    mcgm = _m([(3, 3, 5.0), (9, 9, 5.0)])
    hop = _m([(3, 3, 5.2)])
    inter = fuse(_dense(5.1), {"mcgm": mcgm, "hopfield": hop}, mode="intersection")
    assert len(inter) == 1 and inter.count[0] == 3
    vote = fuse(_dense(5.1), {"mcgm": mcgm, "hopfield": hop})
    assert len(vote) == 2  # (9, 9): mcgm + gabor


def test_low_confidence_gabor_and_dy_disagreement_do_not_count() -> None:
    hop = _m([(4, 4, 9.0)])
    assert len(fuse(_dense(9.0, conf=0.1), {"hopfield": hop})) == 0  # below a_conf_min
    # Sparse channels that agree on x but not on y (2 px apart vertically): no member.
    res = fuse(None, {"mcgm": _m([(4, 4, 9.0)], dy=0.0), "hopfield": _m([(4, 4, 9.0)], dy=2.0)})
    assert len(res) == 0


def test_bits_follow_the_spec() -> None:
    assert CHANNEL_BITS == {"gabor": 1, "mcgm": 2, "hopfield": 4}


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"sparse": {}}, "at least one sparse channel"),
        ({"sparse": {"sgbm": None}}, "unknown sparse channel"),
        ({"sparse": {"gabor": None}}, "unknown sparse channel"),  # the dense one
        ({"mode": "all"}, "mode"),
        ({"tau_dx": 0.0}, "tau_dx"),
        ({"r_spatial": float("nan")}, "r_spatial"),
        ({"min_agree": 1}, "min_agree"),
    ],
)
def test_bad_arguments(kwargs: dict, needle: str) -> None:
    args = {"gabor": _dense(1.0), "sparse": {"hopfield": _m([(1, 1, 1.0)])}} | kwargs
    with pytest.raises(ValueError, match=needle):
        fuse(args.pop("gabor"), args.pop("sparse"), **args)


def test_a_map_that_is_not_real_numbers_is_named() -> None:
    """A complex disparity map lost its imaginary part with NumPy's ComplexWarning only, and a
    map of text raised NumPy's "could not convert string to float"; both name the map."""
    conf = np.ones((H, W), np.float32)
    members = np.full((H, W), 3, np.uint8)
    for bad in (np.ones((H, W), np.complex64), np.full((H, W), "1")):
        with pytest.raises(
            ValueError, match=r"^disparity: expected a real \(H, W\) map, got dtype"
        ):
            fused_dense(bad, conf, members)
        with pytest.raises(ValueError, match=r"^guide: expected a real \(H, W\) map, got dtype"):
            fill_enclosed_far(np.ones((H, W), np.float32), bad)
    # bool, integer and float maps are numbers: read as before
    d = np.full((H, W), 4.0, np.float32)
    np.testing.assert_array_equal(
        fused_dense(d.astype(np.int16), conf.astype(bool), members)[0],
        fused_dense(d, conf, members)[0],
    )


def test_an_object_map_of_numbers_is_read_as_before() -> None:
    """A map of Python numbers in an object array (``np.array(values, dtype=object)``, a
    pandas object column) was read as its numbers until today's dtype check refused it as
    "got dtype object"; one holding None or text is still refused."""
    conf = np.ones((H, W), np.float32)
    members = np.full((H, W), 3, np.uint8)
    d = np.random.default_rng(0).uniform(2, 9, (H, W)).astype(np.float32)
    want = fused_dense(d, conf, members)
    got = fused_dense(d.astype(object), conf.astype(int).astype(object), members.astype(object))
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)
    bad = d.astype(object)
    bad[1, 2] = None
    with pytest.raises(ValueError, match=r"^disparity: expected a real \(H, W\) map, got dtype"):
        fused_dense(bad, conf, members)


def test_mismatched_sizes() -> None:
    small = Matches(*(np.zeros(1, np.float32),) * 5, (H - 1, W))
    with pytest.raises(ValueError, match="differs"):
        fuse(_dense(1.0), {"hopfield": small})
    with pytest.raises(ValueError, match="differs"):
        fuse((np.zeros((H, W)), np.zeros((H, W + 1))), {"hopfield": _m([(1, 1, 1.0)])})


def test_agreement_raises_precision_on_a_real_scene(data_dir: Path) -> None:
    """On Middlebury art the Gabor + Hopfield members are more precise than Hopfield alone."""
    scene = load_scene(data_dir / "middlebury2005" / "art")
    gl, gr = as_gray_float(scene.left, "left"), as_gray_float(scene.right, "right")
    g = gabor_disparity(gl, gr, max_disparity=96)
    hop = hopfield_match(gl, gr, max_disparity=96)
    res = fuse((g.disparity, g.confidence), {"hopfield": hop})
    m_hop = sparse_metrics(hop.xl, hop.yl, hop.xr, scene.gt)
    m_fused = sparse_metrics(res.matches.xl, res.matches.yl, res.matches.xr, scene.gt)
    # Measured: Hopfield 97.2 % of 1853, members 97.9 % of 1464.
    assert m_fused.precision[1.0] > m_hop.precision[1.0] + 0.4
    assert 0.6 * m_hop.count < m_fused.count < m_hop.count
    assert m_fused.coverage == 16


def test_match_fused_on_cones(data_dir: Path) -> None:
    """The three channels' valid members: more than either sparse channel, and more precise."""
    scene = load_scene(data_dir / "middlebury2003" / "cones")
    m = sv_match(scene.left, scene.right, method="fused", max_disparity=64)
    fm = sparse_metrics(m.xl, m.yl, m.xr, scene.gt)
    st = m.stats
    assert len(st["count"]) == len(st["sources"]) == len(m)
    assert set(np.unique(st["sources"])) <= {3, 5, 6, 7} and st["count"].min() >= 2
    assert st["channels"] == ["gabor", "mcgm", "hopfield"]
    # Measured: 99.97 % of 7842 members within 1 px (16/16); MCGM (vote settings) 6584 matches,
    # Hopfield 3026.
    assert fm.precision[1.0] > 99.8 and fm.coverage == 16
    assert fm.count > max(st["channel_matches"].values())
    # Each channel alone gives far fewer at the members' precision (its best-scored matches
    # while its precision stays there): MCGM with its own defaults 1109 of 7542, Hopfield 172.
    for name, most in (("mcgm", 1500), ("hopfield", 400)):
        alone = sv_match(scene.left, scene.right, method=name, max_disparity=64)
        at = count_at_precision(
            alone.xl, alone.yl, alone.xr, alone.score, scene.gt, fm.precision[1.0], 1.0
        )
        assert at < most < fm.count, name


def test_fuse_pair_rejects_unknown_options() -> None:
    img = np.random.default_rng(0).random((40, 60), dtype=np.float32)
    with pytest.raises(ValueError, match="unknown fusion option"):
        fuse_pair(img, img, max_disparity=8, tau=1.0)
    with pytest.raises(ValueError, match="unknown channel"):
        fuse_pair(img, img, max_disparity=8, channels=("gabor", "sgbm"))
    # A misspelt keyword of fuse_pair itself was refused with a list that lacked it.
    with pytest.raises(ValueError, match=r"did you mean 'check_members'\?.*census_members"):
        sv_match(img, img, method="fused", max_disparity=8, check_member=False)


def test_fused_dense_veto_replace_and_fill() -> None:
    d = np.full((H, W), 10.0, np.float32)
    d[:, 20:] = 30.0  # a region locked to a wrong value next to a member at 12
    d[0, :] = np.nan  # a hole row
    c = np.full((H, W), 0.5, np.float32)
    members = np.full((H, W), np.nan, np.float32)
    members[1, 24] = 12.0
    members[10, 5] = 10.5
    out, conf = fused_dense(d, c, members, radius=5.0, tau=2.0, fill_radius=1.5)
    # Members replace Gabor at their pixels, with confidence 1.
    assert out[1, 24] == 12.0 and conf[1, 24] == 1.0 and out[10, 5] == 10.5
    # Gabor pixels within 5 px of the member at 12 that differ by > 2 are dropped ...
    assert np.isnan(out[4, 24]) and conf[4, 24] == 0.0
    # ... farther ones stay, and agreeing ones (10 vs 10.5) stay.
    assert out[15, 25] == 30.0 and out[10, 7] == 10.0 and conf[10, 7] == 0.5
    # Holes within 1.5 px of a member take its value at the fill confidence.
    assert out[0, 24] == 12.0 and conf[0, 24] == pytest.approx(0.25)
    assert np.isnan(out[0, 10])
    # The fill's confidence is the one given.
    _, conf2 = fused_dense(d, c, members, radius=5.0, tau=2.0, fill_radius=1.5, fill_confidence=0.4)
    assert conf2[0, 24] == pytest.approx(0.4) and conf2[1, 24] == 1.0
    for bad in ({"fill_confidence": 1.5}, {"second_confidence": -0.1}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            fused_dense(d, c, members, **bad)
    # Without members the Gabor map is returned unchanged.
    same, _ = fused_dense(d, c, np.full((H, W), np.nan, np.float32))
    np.testing.assert_array_equal(same, d)


def test_second_confidence_zero_is_refused() -> None:
    """Confidence 0 marks a filled disparity (depth_counts' "filled", point_image(filled=True)):
    second_confidence=0 gave every census-only pixel that mark (on eth3d/terrace, method="census":
    278214 pixels with a depth and confidence 0, none at 0.5), so it is refused; 1 is allowed."""
    import re

    d = np.full((H, W), np.nan, np.float32)
    none = np.full((H, W), np.nan, np.float32)
    second = np.full((H, W), 7.0, np.float32)
    for bad in (0.0, -0.5, 1.5):
        says = re.escape(f"second_confidence: expected a value in (0, 1], got {bad}")
        with pytest.raises(ValueError, match=f"^{says}$"):
            fused_dense(d, d, none, second=second, second_confidence=bad)
    out, conf = fused_dense(d, d, none, second=second, second_confidence=1.0, speckle_area=0.0)
    np.testing.assert_array_equal(out, second)
    np.testing.assert_array_equal(conf, np.ones((H, W), np.float32))


def test_fill_confidence_zero_is_refused() -> None:
    """Anchor-filled pixels get a depth in depth_map (their value is a member's): confidence 0,
    the filled mark of depth_counts and point_image(filled=True), made them guesses there (on
    eth3d/playground, method="fused": 4887 pixels with a depth and confidence 0, and 17 dropped
    ones counted as filled). fill_confidence=0 is refused as second_confidence=0 is; 1 is allowed.
    """
    import re

    d = np.full((H, W), np.nan, np.float32)
    members = np.full((H, W), np.nan, np.float32)
    members[5, 5] = 12.0
    for bad in (0.0, 0, -0.5, 1.5):
        says = re.escape(f"fill_confidence: expected a value in (0, 1], got {bad}")
        with pytest.raises(ValueError, match=f"^{says}$"):
            fused_dense(d, d, members, fill_confidence=bad)
    out, conf = fused_dense(d, d, members, fill_radius=1.0, fill_confidence=1.0, speckle_area=0.0)
    assert out[5, 4] == 12.0 and conf[5, 4] == 1.0 and np.isnan(out[0, 0])


def test_nearest_member_labels_are_row_major() -> None:
    """The nearest-member map agrees with a brute-force search (OpenCV's label order)."""
    from stereovision.matching.fusion import _nearest_member

    rng = np.random.default_rng(1)
    a = np.full((50, 70), np.nan, np.float32)
    a.flat[rng.choice(a.size, 60, replace=False)] = rng.random(60, dtype=np.float32) + 1
    near, dist = _nearest_member(a)
    ys, xs = np.nonzero(np.isfinite(a))
    yy, xx = np.mgrid[:50, :70]
    d2 = (yy[..., None] - ys) ** 2 + (xx[..., None] - xs) ** 2
    brute = a[ys, xs][d2.argmin(-1)]
    # DIST_MASK_5 approximates the Euclidean distance: ties and near-ties may pick another
    # member at (almost) the same distance.
    assert np.mean(near == brute) > 0.97
    assert np.abs(dist - np.sqrt(d2.min(-1))).max() < 0.25


def test_depth_map_fused_beats_gabor_on_a_scene(data_dir: Path) -> None:
    """Middlebury 2006 wood2: the anchors fix Gabor's wrongly locked regions."""
    scene = load_scene(data_dir / "middlebury2006" / "wood2")
    gabor = sv_depth_map(scene.left, scene.right, max_disparity=128, method="gabor")
    fused = sv_depth_map(
        scene.left, scene.right, max_disparity=128, method="fused", return_channels=True
    )
    bg = dense_metrics(row_fill(gabor.disparity), scene.gt).bad[2.0]
    bf = dense_metrics(row_fill(fused.disparity), scene.gt).bad[2.0]
    assert bf < 0.5 * bg  # measured 7.8 -> 1.1 % (filled)
    # "fused" is depth_map's default.
    default = sv_depth_map(scene.left, scene.right, max_disparity=128)
    np.testing.assert_array_equal(default.disparity, fused.disparity)
    ch = fused.channels
    assert ch is not None
    assert set(ch) == {"gabor", "gabor_remeasured", "mcgm", "hopfield", "sgm", "members"}
    members = ch["members"]
    m = np.isfinite(members.dispx)
    np.testing.assert_array_equal(fused.disparity[m], members.dispx[m])
    assert np.all(fused.confidence[m] == 1.0)
    assert gabor.channels is None


@pytest.mark.parametrize(
    ("scene", "bar"), [("middlebury2003/teddy", 0.6), ("middlebury2005/reindeer", 0.55)]
)
def test_semi_global_completion_beats_filled_sgbm(data_dir: Path, scene: str, bar: float) -> None:
    """The census semi-global map fills Gabor's holes and vetoes its disagreeing values: bad-2.0
    (holes counted) against SGBM-3WAY + the same row fill, OpenCV in the same run. Measured:
    teddy 12.0 -> 6.9 % (SGBM + fill 15.0), reindeer 21.4 -> 6.0 % (14.4)."""
    sc = load_scene(data_dir / scene)
    kw = {"max_disparity": sc.max_disparity, "method": "fused"}
    on = sv_depth_map(sc.left, sc.right, **kw)
    off = sv_depth_map(sc.left, sc.right, semi_global=False, **kw)
    sgbm = row_fill(opencv_sgbm(sc.left, sc.right, sc.max_disparity))
    b_on, b_off, b_cv = (
        dense_metrics(d, sc.gt).bad[2.0] for d in (on.disparity, off.disparity, sgbm)
    )
    assert b_on < bar * b_cv, (b_on, b_cv)
    assert b_on < 0.8 * b_off, (b_on, b_off)
    # Pixels the census map alone measured carry its confidence; they get a depth like others.
    assert np.any(on.confidence == 0.5)


def test_remeasure_keeps_the_holes_and_sharpens_gabor(data_dir: Path) -> None:
    """ETH3D terrace: the re-measured Gabor map has Gabor's holes and a third of its error."""
    scene = load_scene(data_dir / "eth3d" / "terrace")
    gl, gr = as_gray_float(scene.left, "left"), as_gray_float(scene.right, "right")
    g = gabor_disparity(gl, gr, max_disparity=32)
    r = remeasure(gl, gr, g.disparity, g.confidence, max_disparity=32)
    np.testing.assert_array_equal(np.isnan(r), np.isnan(g.disparity))
    m = np.isfinite(g.disparity) & np.isfinite(scene.gt)
    e_raw, e_re = np.abs(g.disparity - scene.gt)[m], np.abs(r - scene.gt)[m]
    # Measured: median 0.356 -> 0.135 px, off by > 0.5 px 37.2 -> 11.8 %, > 2 px 1.75 -> 1.0 %.
    assert np.median(e_re) < 0.5 * np.median(e_raw)
    assert np.mean(e_re > 0.5) < 0.5 * np.mean(e_raw > 0.5)
    assert np.mean(e_re > 2.0) <= np.mean(e_raw > 2.0)


def test_remeasured_vote_gives_more_and_more_precise_members(data_dir: Path) -> None:
    """ETH3D terrace: voting with the re-measured Gabor map (the default) beats the raw one."""
    scene = load_scene(data_dir / "eth3d" / "terrace")
    gl, gr = as_gray_float(scene.left, "left"), as_gray_float(scene.right, "right")
    got = {}
    for check in (False, True):
        for flag in (False, True):
            fr = fuse_pair(gl, gr, max_disparity=32, remeasure_gabor=flag, check_members=check)
            m = fr.matches
            got[check, flag] = sparse_metrics(m.xl, m.yl, m.xr, scene.gt)
            assert ("gabor_remeasured" in fr.channel_outputs) == flag
    # Measured, the vote alone: 98.76 % of 4525 within 1 px -> 99.00 % of 4696 (within 0.5 px:
    # 92.6 -> 94.9 %). With the member check (the default) both reach 99.4 % within 1 px; the
    # re-measured map still gives more members, closer: 3949 -> 4139, 94.4 -> 96.5 % in 0.5 px.
    raw, new = got[False, False], got[False, True]
    assert new.precision[1.0] > raw.precision[1.0] + 0.1
    assert new.precision[0.5] > raw.precision[0.5] + 1.5
    assert new.count > raw.count
    raw, new = got[True, False], got[True, True]
    assert new.precision[1.0] > raw.precision[1.0] - 0.1
    assert new.precision[0.5] > raw.precision[0.5] + 1.5
    assert new.count > raw.count + 100


@pytest.mark.parametrize("refine", [True, False])
def test_fused_depth_sigma_follows_its_map(data_dir: Path, refine: bool) -> None:
    """The fused map on the re-measured Gabor map gets the refined sigma line (it fits it: error
    in sigmas median 0.65 pooled over the 17 scenes), on the raw map the raw one; the pixels only
    the census semi-global map measured (confidence 0.5) get the filled pixels' 0.63 px."""
    from stereovision.depth import disparity_sigma

    scene = load_scene(data_dir / "eth3d" / "terrace")
    r = sv_depth_map(
        scene.left, scene.right, scene.calib, method="fused", max_disparity=32, refine=refine
    )
    assert r.depth is not None and r.depth_sigma is not None and scene.calib is not None
    m = np.isfinite(r.depth)
    assert m.mean() > 0.4
    d = r.disparity[m].astype(np.float64)
    sigma_d = r.depth_sigma[m] * (d + scene.calib.doffs_px) / r.depth[m]
    census = r.confidence[m] == np.float32(0.5)
    assert 0.03 < census.mean() < 0.5  # measured on terrace: 15.7 %
    want = disparity_sigma(r.confidence[m], refined=refine, filled=census)
    np.testing.assert_allclose(sigma_d, want, rtol=1e-3)


def test_fused_is_bit_identical_across_thread_counts(data_dir: Path) -> None:
    """Issue 5: same inputs, same bits, with 1, 2 or 3 rayon threads (dense map and members;
    the census mode's map too), and with the kernels' waiting workers (``parallel::run_hot``)
    on or off."""
    import os
    import subprocess
    import sys

    script = (
        "import hashlib, stereovision as sv\n"
        "from stereovision.io import load_scene\n"
        f"sc = load_scene({str(data_dir / 'middlebury2001' / 'tsukuba')!r})\n"
        "r = sv.depth_map(sc.left, sc.right, method='fused', max_disparity=16)\n"
        "m = sv.match(sc.left, sc.right, method='fused', max_disparity=16)\n"
        "c = sv.depth_map(sc.left, sc.right, method='census', max_disparity=16)\n"
        "h = hashlib.sha1(r.disparity.tobytes() + r.confidence.tobytes())\n"
        "h.update(c.disparity.tobytes())\n"
        "h.update(m.to_array().tobytes())\n"
        "print(h.hexdigest(), len(m))\n"
    )
    outs = []
    for threads, spin in (("1", "1"), ("2", "1"), ("2", "0"), ("3", "1")):
        env = dict(os.environ, RAYON_NUM_THREADS=threads, STEREOVISION_SPIN_WAIT=spin)
        proc = subprocess.run(
            [sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True
        )
        outs.append(proc.stdout.split())
    assert all(o == outs[0] for o in outs) and int(outs[0][1]) > 1000


def test_member_check_drops_members_the_sides_check_rejects(data_dir: Path) -> None:
    """Middlebury laundry: members Gabor and Hopfield agree on must pass the both-sides check."""
    scene = load_scene(data_dir / "middlebury2005" / "laundry")
    gl, gr = as_gray_float(scene.left, "left"), as_gray_float(scene.right, "right")
    kw = {"max_disparity": 96, "edge_members": False, "census_members": False}
    on = fuse_pair(gl, gr, **kw)
    off = fuse_pair(gl, gr, check_members=False, **kw)
    p_on = sparse_metrics(on.matches.xl, on.matches.yl, on.matches.xr, scene.gt)
    p_off = sparse_metrics(off.matches.xl, off.matches.yl, off.matches.xr, scene.gt)
    # Measured: 98.91 % of 3309 -> 99.21 % of 3166 within 1 px.
    assert p_on.precision[1.0] > p_off.precision[1.0] + 0.2
    assert 0.9 * p_off.count < p_on.count < p_off.count

    # The kept members are a subset, unchanged; MCGM's are all kept; the rasters follow.
    def rows(r: FusionResult) -> set[tuple[float, ...]]:
        m = r.matches
        return set(map(tuple, np.stack([m.xl, m.yl, m.xr], axis=1).tolist()))

    assert rows(on) < rows(off)
    mcgm_bit = CHANNEL_BITS["mcgm"]
    assert np.count_nonzero(on.sources & mcgm_bit) == np.count_nonzero(off.sources & mcgm_bit)
    assert np.count_nonzero(np.isfinite(on.dispx)) == len(on) == np.count_nonzero(on.count_map)
    assert on.matches.stats["members_before_check"] == len(off)


def test_edge_check_drops_members_on_fattened_edges(data_dir: Path) -> None:
    """Middlebury reindeer: members on the Gabor map's foreground edges carried past the
    image's edges are dropped (fuse_pair's edge_members, on by default)."""
    scene = load_scene(data_dir / "middlebury2005" / "reindeer")
    gl, gr = as_gray_float(scene.left, "left"), as_gray_float(scene.right, "right")
    on = fuse_pair(gl, gr, max_disparity=80, census_members=False)
    off = fuse_pair(gl, gr, max_disparity=80, edge_members=False, census_members=False)
    p_on = sparse_metrics(on.matches.xl, on.matches.yl, on.matches.xr, scene.gt)
    p_off = sparse_metrics(off.matches.xl, off.matches.yl, off.matches.xr, scene.gt)
    # Measured: 99.28 % of 4879 -> 99.46 % of 4813 within 1 px.
    assert p_on.precision[1.0] > p_off.precision[1.0] + 0.1
    assert 0.97 * p_off.count < p_on.count < p_off.count
    keys = [set(zip(r.matches.xl.tolist(), r.matches.yl.tolist(), strict=True)) for r in (on, off)]
    assert keys[0] < keys[1]
    # Exactly the members on step 7's pixels of the re-measured Gabor map (_EDGE_MEMBERS: 7 px,
    # an edge 1.5 x the step, jumps over 2 px) go, with or without the both-sides check.
    from stereovision import _core

    fat = _core.fattened(off.channel_outputs["gabor_remeasured"], gl, 7, 1.5, 2.0)
    assert keys[0] == {(x, y) for x, y in keys[1] if not fat[int(y), int(x)]}
    kw = {"max_disparity": 80, "census_members": False, "check_members": False}
    alone = [fuse_pair(gl, gr, edge_members=e, **kw) for e in (True, False)]
    kept, all_ = (
        {(x, y) for x, y in zip(r.matches.xl.tolist(), r.matches.yl.tolist(), strict=True)}
        for r in alone
    )
    assert kept == {(x, y) for x, y in all_ if not fat[int(y), int(x)]} != all_


def test_channel_results_repr_is_a_summary_not_their_arrays() -> None:
    """The dataclass reprs printed every array: 3.4 kB for a 150x100 pair's FusionResult
    (its channel outputs' maps, 1.2 kB of them the GaborResult's), 9 kB of InterestPoints."""
    from stereovision.matching.hopfield import InterestPoints

    nan = np.nan
    disp = np.array([[1.0, nan, 2.5], [nan, nan, 2.0]], np.float32)
    g = GaborResult(disparity=disp, confidence=np.isfinite(disp).astype(np.float32))
    assert repr(g) == "GaborResult(3x2; disparity 1.00-2.50 px on 50.0 % of pixels)"
    assert repr(GaborResult(disp * nan, disp * 0)) == "GaborResult(3x2; no disparity)"
    ip = InterestPoints(np.zeros((4, 2), np.float32), np.zeros(4, np.float32), np.zeros((5, 6)))
    assert repr(ip) == "InterestPoints(4 points in 6x5)"
    m = Matches([0, 2, 2], [0, 0, 1], [-1, -0.5, 0], [0, 0, 1], [1, 1, 2 / 3], image_shape=(2, 3))
    fr = FusionResult(
        matches=m,
        count=np.array([3, 3, 2], np.uint8),
        sources=np.array([7, 7, 3], np.uint8),
        dispx=disp,
        dispy=disp * 0,
        count_map=np.zeros((2, 3), np.uint8),
        sources_map=np.zeros((2, 3), np.uint8),
        channels=("gabor", "mcgm", "hopfield"),
        channel_outputs={"gabor": g},
    )
    assert repr(fr) == (
        "FusionResult(3 members in 3x2 of gabor, mcgm, hopfield; count 2: 1, 3: 2; channel "
        "outputs: gabor)"
    )


def test_census_clear_drops_members_near_a_lower_census_region() -> None:
    """A member is dropped where the census map has a value more than ``jump`` below it within
    ``radius`` px; NaN census pixels do not count."""
    census = np.full((H, W), 20.0, np.float32)
    census[:, :8] = 10.0  # background left of a foreground edge at x = 8
    census[15:, 20:] = np.nan  # unmeasured
    census[2, 27] = 18.4  # 1.6 below the foreground
    pts = [(9.0, 5.0, 20.0), (14.0, 5.0, 20.0), (15.0, 5.0, 20.0), (25.0, 17.0, 20.0)]
    pts += [(25.0, 8.0, 19.0), (22.0, 2.0, 20.0), (3.0, 10.0, 10.0)]
    m = _m(pts)
    dispx = np.full((H, W), np.nan, np.float32)
    dispx[m.yl.astype(int), m.xl.astype(int)] = m.xl - m.xr
    on = np.isfinite(dispx)
    fr = FusionResult(
        matches=m,
        count=np.full(len(m), 2, np.uint8),
        sources=np.full(len(m), 6, np.uint8),
        dispx=dispx,
        dispy=np.where(on, 0.0, np.nan).astype(np.float32),
        count_map=(on * 2).astype(np.uint8),
        sources_map=(on * 6).astype(np.uint8),
        channels=("gabor", "mcgm", "hopfield"),
    )
    out = census_clear(fr, census, radius=7, jump=1.5)
    kept = {(float(x), float(y)) for x, y in zip(out.matches.xl, out.matches.yl, strict=True)}
    # x = 9 and 14 reach the background (7 px); x = 15 does not. (22, 2) at 20 reaches the
    # 18.4 speck, 1.6 below; (25, 8) at 19 reaches it too, but only 0.6 below. (25, 17) reaches
    # NaN pixels, which do not count. The background member (3, 10) has nothing lower.
    assert kept == {(15.0, 5.0), (25.0, 17.0), (25.0, 8.0), (3.0, 10.0)}
    assert np.count_nonzero(np.isfinite(out.dispx)) == len(out) == np.count_nonzero(out.count_map)
    # Every raster forgets the dropped members: dispy and sources_map too.
    np.testing.assert_array_equal(np.isfinite(out.dispy), np.isfinite(out.dispx))
    np.testing.assert_array_equal(out.sources_map != 0, np.isfinite(out.dispx))
    assert out.sources_map[5, 15] == 6 and out.sources_map[5, 9] == 0 and np.isnan(out.dispy[5, 9])
    assert out.matches.stats["members_before_census"] == len(pts)
    assert out.matches.stats["members"] == len(out) == 4  # those kept, not those checked
    assert len(census_clear(fr, census, radius=0)) == len(pts)  # its own pixel only
    assert len(census_clear(fr, census, radius=7, jump=20.0)) == len(pts)
    with pytest.raises(ValueError, match="census: shape"):
        census_clear(fr, census[:, :-1])
    with pytest.raises(ValueError, match="radius"):
        census_clear(fr, census, radius=-1)
    with pytest.raises(ValueError, match="radius"):
        census_clear(fr, census, radius=2.5)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="radius"):
        census_clear(fr, census, radius=True)
    # "More than jump below": a census value exactly jump below keeps the member.
    exact = census.copy()
    exact[2, 27] = 18.5
    kept = census_clear(fr, exact, radius=7, jump=1.5).matches
    assert (22.0, 2.0) in set(zip(kept.xl.tolist(), kept.yl.tolist(), strict=True))
    # After fuse_pair's member check the count before it stays what it was.
    from stereovision.matching.fusion import _members_where

    checked = _members_where(fr, np.arange(len(pts)) != 6)
    assert checked.matches.stats["members_before_check"] == len(pts)
    after = census_clear(checked, census, radius=7, jump=1.5)
    assert after.matches.stats["members_before_check"] == len(pts)
    assert after.matches.stats["members_before_census"] == len(pts) - 1
    with pytest.raises(ValueError, match="jump"):
        census_clear(fr, census, jump=float("nan"))


@pytest.mark.parametrize(
    ("scene", "before", "after"),
    [("middlebury2003/teddy", 98.5, 99.3), ("tartanair/oldtown_easy_p000_001116", 98.0, 99.0)],
)
def test_census_check_lifts_member_precision(
    data_dir: Path, scene: str, before: float, after: float
) -> None:
    """Issue 5, point 2: the members near a census depth edge go (fuse_pair's census_members, on
    by default); the wrong members sat there, on the foreground's disparity."""
    sc = load_scene(data_dir / scene)
    gl, gr = as_gray_float(sc.left, "left"), as_gray_float(sc.right, "right")
    md = int(sc.max_disparity)
    on = fuse_pair(gl, gr, max_disparity=md)
    off = fuse_pair(gl, gr, max_disparity=md, census_members=False)
    p_on = sparse_metrics(on.matches.xl, on.matches.yl, on.matches.xr, sc.gt)
    p_off = sparse_metrics(off.matches.xl, off.matches.yl, off.matches.xr, sc.gt)
    # Measured: teddy 97.89 % of 7784 -> 99.47 % of 6767 within 1 px; TartanAir 97.53 % of
    # 9213 -> 99.03 % of 6983.
    assert p_off.precision[1.0] < before and p_on.precision[1.0] > after
    assert 0.7 * p_off.count < p_on.count < p_off.count
    assert on.matches.stats["members_before_census"] == len(off)
    assert "sgm" not in on.channel_outputs  # it checked the members, the dense map did not ask


@pytest.mark.parametrize("scene", ["middlebury2003/cones", "kitti2015/000005_10"])
@pytest.mark.parametrize(("radius", "ratio", "jump"), [(3, 2.0, 2.0), (7, 1.5, 2.0)])
def test_fattened_kernel_equals_numpy_reference(
    data_dir: Path, scene: str, radius: int, ratio: float, jump: float
) -> None:
    """The edge kernel (``_core.fattened``, fused_dense's step 7 and fuse_pair's member check)
    against tests/reference/edges_ref.py on SGBM-3WAY's real maps, holes included, with the
    settings both callers use."""
    from stereovision import _core

    s = load_scene(data_dir / scene)
    d = opencv_sgbm(s.left, s.right, s.max_disparity)
    g = as_gray_float(s.left, "left")
    got = _core.fattened(d, g, radius, ratio, jump)
    want = edges_ref.fattened(d, g, radius, ratio, jump)
    assert got.dtype == np.bool_ and got.shape == d.shape
    np.testing.assert_array_equal(got, want)
    assert 100 < int(got.sum()) < 0.2 * got.size  # a real test: edges found, not everything


def test_fattened_kernel_small_and_bad_input() -> None:
    """Maps under 3 pixels along one axis are checked along the other only; shapes that differ
    and negative thresholds are ValueErrors."""
    from stereovision import _core

    col = np.array([[1.0], [1.0], [1.0], [9.0], [9.0], [9.0], [9.0], [9.0]], np.float32)
    g = np.array([[0.2]] * 6 + [[0.8]] * 2, np.float32)
    got = _core.fattened(col, g, 3, 2.0, 2.0)
    np.testing.assert_array_equal(got, edges_ref.fattened(col, g, 3, 2.0, 2.0))
    assert got[:, 0].tolist() == [False] * 3 + [True] * 3 + [False] * 2
    with pytest.raises(ValueError, match="guide"):
        _core.fattened(col, g[:4], 3, 2.0, 2.0)
    with pytest.raises(ValueError, match="ratio"):
        _core.fattened(col, g, 3, -1.0, 2.0)
    with pytest.raises(ValueError, match="jump"):
        _core.fattened(col, g, 3, 2.0, float("nan"))


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_fattened_kernel_refuses_a_guide_that_is_not_finite(bad: float) -> None:
    """A NaN step (a NaN or inf guide) never beat another in the kernel's search for the image's
    edge, where NumPy's argmax (tests/reference/edges_ref.py) stops at it: on this row the
    kernel marked 3 pixels and the reference none (on real crops with 5 % NaN: 23-55 pixels
    apart); an inf makes NaN steps beside it. The guide is an image: a ValueError naming it
    now."""
    from stereovision import _core

    d = np.array([[1, 1, 1, 9, 9, 9, 9, 9, 9, 9]], np.float32)
    g = np.array([[0.2, 0.2, 0.2, 0.2, bad, 0.2, 0.8, 0.8, 0.8, 0.8]], np.float32)
    if np.isnan(bad):
        assert not edges_ref.fattened(d, g, 3, 2.0, 2.0).any()
    with pytest.raises(ValueError, match=r"guide: expected finite values \(an image\), got 1 "):
        _core.fattened(d, g, 3, 2.0, 2.0)


@pytest.mark.parametrize(
    ("bad", "said"),
    [
        (np.nan, "got 1 NaN or inf$"),
        (-np.inf, "got 1 NaN or inf$"),
        (1e39, r"got 1 value\(s\) past float32's range \(3\.40282e\+38\)$"),
    ],
)
def test_fused_dense_refuses_a_guide_step_7_cannot_read_before_the_steps_run(
    monkeypatch: pytest.MonkeyPatch, bad: float, said: str
) -> None:
    """The kernel refuses a guide with NaN or inf, but fused_dense reached it only after steps
    1-6 had run, and a float64 guide of finite values past float32's range (the guide is "any
    scale") was cast to inf with NumPy's overflow warning and called "NaN or inf". Now the
    guide is checked first, and its message says which; unused (edge_radius 0) it is not."""
    import warnings

    from stereovision.matching import fusion

    d = np.full((20, 30), 10.0, np.float32)
    d[5:15, 10:20] = 20.0
    conf = np.full(d.shape, 0.8, np.float32)
    none = np.full(d.shape, np.nan, np.float32)
    guide = np.full(d.shape, 0.2)
    guide[5:15, 12:18] = 0.8
    guide[3, 4] = bad
    ran: list[str] = []
    real = fusion._drop_speckles
    monkeypatch.setattr(fusion, "_drop_speckles", lambda *a: ran.append("6") or real(*a))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no "overflow encountered in cast"
        with pytest.raises(ValueError, match=f"^guide: expected a finite grey image, {said}"):
            fused_dense(d, conf, none, guide=guide)
    assert ran == []  # refused before step 6
    out, _ = fused_dense(d, conf, none, guide=guide, edge_radius=0)
    np.testing.assert_array_equal(out, d)
    assert ran == ["6"]


def test_fused_dense_drops_speckles() -> None:
    """Step 6: a 3x3 island off its surroundings (9 px, fewer than 5e-5 of 400x500 = 10) becomes
    a hole; a 5x50 strip (250 px) and the slanted background stay."""
    h, w = 400, 500
    # A slanted background: 0.5 px from row to row (one region at speckle_diff = 1).
    bg = np.tile(20.0 + 0.5 * np.arange(h, dtype=np.float32)[:, None], (1, w))
    d = bg.copy()
    d[100:103, 100:103] = 35.0
    d[200:205, 300:350] = 5.0
    conf = np.full(d.shape, 0.8, np.float32)
    none = np.full(d.shape, np.nan, np.float32)
    assert 9 < 5e-5 * h * w < 250
    out, c = fused_dense(d, conf, none)
    assert np.isnan(out[100:103, 100:103]).all() and (c[100:103, 100:103] == 0).all()
    gone = np.isnan(out)
    assert gone.sum() == 9
    np.testing.assert_array_equal(out[~gone], d[~gone])
    kept, _ = fused_dense(d, conf, none, speckle_area=0.0)
    np.testing.assert_array_equal(kept, d)
    # "Smaller than": an area of exactly 9 px keeps the 9 px island, 10 px does not.
    assert np.isfinite(fused_dense(d, conf, none, speckle_area=9 / (h * w))[0]).all()
    assert np.isnan(fused_dense(d, conf, none, speckle_area=10 / (h * w))[0]).sum() == 9
    # An island 1 px off its surroundings is part of them (speckle_diff = 1).
    d2 = bg.copy()
    d2[100:103, 100:103] += 1.0
    out2, _ = fused_dense(d2, conf, none)
    assert np.isfinite(out2).all()
    with pytest.raises(ValueError, match="speckle_area"):
        fused_dense(d, conf, none, speckle_area=-1.0)


def test_fused_dense_snaps_jumps_to_image_edges() -> None:
    """Step 7: a foreground square (disparity 20 on 10) whose outline the matcher drew 3 px too
    wide on every side (not at the corners, which neither a row nor a column through them
    can tell); the image's edges are where the square really ends."""
    h, w = 60, 80
    guide = np.full((h, w), 0.2, np.float32)
    guide[20:40, 30:50] = 0.8  # the square in the image: rows 20-39, columns 30-49
    guide += np.random.default_rng(1).normal(0, 0.01, (h, w)).astype(np.float32)  # weak texture
    d = np.full((h, w), 10.0, np.float32)
    d[20:40, 27:53] = 20.0  # fattened by 3 px left and right ...
    d[17:43, 30:50] = 20.0  # ... and above and below
    conf = np.full(d.shape, 0.8, np.float32)
    none = np.full(d.shape, np.nan, np.float32)
    out, c = fused_dense(d, conf, none, guide=guide, speckle_area=0.0)
    truth = np.full((h, w), 10.0, np.float32)
    truth[20:40, 30:50] = 20.0
    fat = d != truth
    assert np.isnan(out[fat]).all() and (c[fat] == 0).all()  # the fattened ring became holes
    np.testing.assert_array_equal(out[~fat], d[~fat])  # nothing else moved
    np.testing.assert_array_equal(row_fill(out), truth)  # and the row fill gives the background
    # Without a guide, or with edge_radius 0, the step does not run; members stay.
    np.testing.assert_array_equal(fused_dense(d, conf, none, speckle_area=0.0)[0], d)
    np.testing.assert_array_equal(
        fused_dense(d, conf, none, guide=guide, speckle_area=0.0, edge_radius=0)[0], d
    )
    members = none.copy()
    members[25, 28] = 20.0
    kept, _ = fused_dense(d, conf, members, guide=guide, speckle_area=0.0, radius=0, fill_radius=0)
    assert kept[25, 28] == 20.0 and np.isnan(kept[25, 27])
    with pytest.raises(ValueError, match="guide"):
        fused_dense(d, conf, none, guide=guide[:, :10])


def test_enclosed_far_fills_dark_locked_regions_only() -> None:
    h, w = 60, 80
    d = np.full((h, w), 6.0, np.float32)
    d[:, 40:] += np.linspace(0, 2, w - 40, dtype=np.float32)  # a slanted part: the median is taken
    g = np.full((h, w), 0.6, np.float32)
    d[20:30, 10:25], g[20:30, 10:25] = 0.2, 0.1  # dark, at the floor, enclosed: filled
    d[35:45, 10:25], g[35:45, 10:25] = 0.0, 0.9  # bright (sky through a gap): kept
    d[0:8, 50:60], g[0:8, 50:60] = 0.0, 0.1  # touches the border: kept
    d[40:44, 50:54], g[40:44, 50:54] = 2.0, 0.1  # not at the floor: kept
    out, filled = fill_enclosed_far(d, g)
    assert filled.sum() == 150 and filled[20:30, 10:25].all()
    assert np.all(out[20:30, 10:25] == 6.0)
    keep = ~filled
    np.testing.assert_array_equal(out[keep], d[keep])
    # The floor is the range's: with a floor of -1, 0 is 1 px above it and nothing is filled.
    assert not fill_enclosed_far(d, g, floor=-1.0)[1].any()
    # A surround less than `jump` above the floor: kept.
    assert not fill_enclosed_far(d, g, jump=9.0)[1].any()
    # ... above the floor, not above 0: the scene 4 px further, floor 4 (surround 6 above it).
    assert fill_enclosed_far(d + 4.0, g, floor=4.0, jump=5.0)[1].sum() == 150
    assert not fill_enclosed_far(d + 4.0, g, floor=4.0, jump=7.0)[1].any()
    # A surround partly NaN: the median of its measured pixels.
    dp = d.copy()
    dp[17:20, 7:28] = np.nan  # the ring's top rows
    out_p, filled_p = fill_enclosed_far(dp, g)
    assert filled_p.sum() == 150 and np.all(out_p[20:30, 10:25] == 6.0)
    # NaN pixels belong to no region and to no surround.
    dn = d.copy()
    dn[16:34, 6:29] = np.nan  # wider than the ring
    dn[20:30, 10:25] = 0.2
    out_n, filled_n = fill_enclosed_far(dn, g)
    assert not filled_n.any() and np.array_equal(np.isnan(out_n), np.isnan(dn))
    bad = ({"far": -1.0}, {"ring": 0}, {"ring": 1.5}, {"jump": np.nan}, {"floor": np.inf})
    for kw in bad:
        needle = next(iter(kw))
        with pytest.raises(ValueError, match=needle):
            fill_enclosed_far(d, g, **kw)
    with pytest.raises(ValueError, match="guide"):
        fill_enclosed_far(d, g[:, :-1])


def test_enclosed_far_on_tartanair(data_dir: Path) -> None:
    """TartanAir's dark shop window is matched at disparity 0 (GT 5-6 px): depth_map fills it
    from its surround and gives it no depth. Measured: bad-2.0 8.96 -> 7.55 %, SGBM-3WAY + fill
    10.17 % (ratio 0.74; issue 5 asks for 0.8)."""
    sc = load_scene(data_dir / "tartanair" / "oldtown_easy_p000_001116")
    r = sv_depth_map(sc.left, sc.right, max_disparity=sc.max_disparity, calib=sc.calib)
    sgbm = row_fill(opencv_sgbm(sc.left, sc.right, sc.max_disparity))
    b, b_cv = (dense_metrics(x, sc.gt).bad[2.0] for x in (r.disparity, sgbm))
    assert b < 0.78 * b_cv, (b, b_cv)
    win = (slice(240, 285), slice(320, 380))
    assert np.median(r.disparity[win]) > 4.0  # the glass, not the locked 0
    assert r.depth is not None and np.isnan(r.depth[win]).mean() > 0.9
    assert np.all(np.isnan(r.depth[win][r.confidence[win] == 0]))  # the filled ones: no depth


def test_depth_map_reports_the_census_checked_members(data_dir: Path) -> None:
    """The fused ``depth_map`` anchors its dense map on all members but reports the checked
    ones, the same as ``match(method="fused")``."""
    sc = load_scene(data_dir / "middlebury2001" / "tsukuba")
    r = sv_depth_map(sc.left, sc.right, method="fused", max_disparity=16, return_channels=True)
    assert r.channels is not None
    members = r.channels["members"]
    m = sv_match(sc.left, sc.right, method="fused", max_disparity=16)
    np.testing.assert_array_equal(members.matches.to_array(), m.to_array())
    assert m.stats["members_before_census"] > len(m)


def test_depth_map_reports_only_the_members_in_the_range(data_dir: Path) -> None:
    """A member's sub-pixel average can leave the range searched (cones at 37 px: 84 members
    up to 37.79 px); ``match(method="fused")`` drops them, and so does ``depth_map``'s report,
    its rasters with them."""
    sc = load_scene(data_dir / "middlebury2003" / "cones")
    r = sv_depth_map(sc.left, sc.right, method="fused", max_disparity=37, return_channels=True)
    assert r.channels is not None
    members = r.channels["members"]
    m = sv_match(sc.left, sc.right, method="fused", max_disparity=37)
    assert m.stats["n_out_of_range"] > 50
    np.testing.assert_array_equal(members.matches.to_array(), m.to_array())
    np.testing.assert_array_equal(members.count, m.stats["count"])
    np.testing.assert_array_equal(members.sources, m.stats["sources"])
    assert m.stats["members"] == members.matches.stats["members"] == len(m)
    assert np.nanmax(members.dispx) <= 37
    assert np.count_nonzero(np.isfinite(members.dispx)) == len(m)
    assert np.count_nonzero(members.count_map) == len(m)


@pytest.fixture(scope="module")
def terrace_fused_match(data_dir: Path) -> Matches:
    """The default ``match(method="fused")`` on ETH3D terrace at 32 px, found once for the
    cases that compare against it (read only)."""
    sc = load_scene(data_dir / "eth3d" / "terrace")
    return sv_match(sc.left, sc.right, method="fused", max_disparity=32)


@pytest.mark.parametrize(
    ("depth_kw", "match_kw"),
    [
        ({"semi_global": False}, {"census_members": False}),
        ({"refine": False}, {"remeasure_gabor": False}),
    ],
)
def test_depth_map_members_without_census_or_remeasure_are_matchs_same(
    data_dir: Path,
    depth_kw: dict[str, bool],
    match_kw: dict[str, bool],
    terrace_fused_match: Matches,
) -> None:
    """DepthChannels' members with ``semi_global=False`` / ``refine=False`` are not the default
    ``match(method="fused")``'s (9927 / 7450 members against 7737 on terrace) but those of
    ``match`` with the census check / the re-measure off, as its docstring says."""
    sc = load_scene(data_dir / "eth3d" / "terrace")
    r = sv_depth_map(sc.left, sc.right, max_disparity=32, return_channels=True, **depth_kw)
    assert r.channels is not None
    got = r.channels["members"].matches
    m = sv_match(sc.left, sc.right, method="fused", max_disparity=32, **match_kw)
    default = terrace_fused_match
    assert len(got) != len(default)
    np.testing.assert_array_equal(got.to_array(), m.to_array())


def test_no_depth_within_its_sigma_on_playground(data_dir: Path) -> None:
    """ETH3D playground's sky and far gaps, matched at 0-1 px: such a depth's one-sigma interval
    reaches infinity, so the fused depth_map reports no depth there (the disparity stays)."""
    from stereovision.depth import disparity_sigma
    from stereovision.evaluate import depth_metrics, gt_depth

    sc = load_scene(data_dir / "eth3d" / "playground")
    assert sc.calib is not None
    r = sv_depth_map(sc.left, sc.right, sc.calib, method="fused", max_disparity=sc.max_disparity)
    assert r.depth is not None
    census = r.confidence == np.float32(0.5)
    sigma_d = disparity_sigma(r.confidence, refined=True, filled=census)
    d = r.disparity + sc.calib.doffs_px
    within = np.isfinite(r.disparity) & (r.confidence > 0) & (d <= sigma_d)
    # Measured: 4880 such pixels (82 with GT, whose depths reached 56 km for GT of 2-12 m).
    assert within.sum() > 1000
    assert np.isnan(r.depth[within]).all()
    assert np.isfinite(r.depth[np.isfinite(r.disparity) & (r.confidence > 0) & ~within]).all()
    # The dense map's depth RMSE: 31.5 % of the mean depth (4066 % with those pixels).
    m = depth_metrics(r.depth, gt_depth(sc.gt, sc.calib))
    assert m.rmse_pct < 60


def test_match_fused_drops_count_and_sources_with_out_of_range_members(data_dir: Path) -> None:
    """match(method='fused') drops members outside [min, max] disparity; their ``count`` and
    ``sources`` went on in ``stats`` (cones at 32 px: 4022 matches, 4124 counts)."""
    scene = load_scene(data_dir / "middlebury2003" / "cones")
    gl, gr = check_pair(scene.left, scene.right)
    res = fuse_pair(gl, gr, max_disparity=32)
    m = sv_match(scene.left, scene.right, method="fused", max_disparity=32)
    d = res.matches.xl - res.matches.xr
    keep = (d >= 0) & (d <= 32)
    assert m.stats["n_out_of_range"] == np.count_nonzero(~keep) > 0
    assert len(m.stats["count"]) == len(m.stats["sources"]) == len(m) == np.count_nonzero(keep)
    np.testing.assert_array_equal(m.stats["count"], res.count[keep])
    np.testing.assert_array_equal(m.stats["sources"], res.sources[keep])


def test_vote_bounds_are_inclusive() -> None:
    """algorithms.md D.4: Gabor takes part where ``A_conf >= a_conf_min``; two values agree
    where ``|ddx| <= tau_dx`` and ``|ddy| <= tau_dy`` (values exact in binary: no rounding)."""
    hop = _m([(5, 5, 11.0)])
    res = fuse(_dense(10.0, 0.25), {"hopfield": hop}, a_conf_min=0.25)
    assert len(res) == 1 and res.sources[0] == 1 | 4
    # Weighted mean (0.25 * 10 + 1 * 11) / 1.25.
    assert res.dispx[5, 5] == pytest.approx(10.8)
    assert len(fuse(_dense(10.0, 0.25), {"hopfield": hop}, a_conf_min=0.5)) == 0
    res = fuse(None, {"mcgm": _m([(4, 4, 9.0)], dy=0.0), "hopfield": _m([(4, 4, 9.0)], dy=1.0)})
    assert len(res) == 1 and res.dispy[4, 4] == pytest.approx(0.5)


@pytest.mark.parametrize("bad", [float("nan"), "0.2", None, -0.1, 1.5, True])
def test_a_conf_min_that_is_no_confidence_is_named(bad: object) -> None:
    """``a_conf_min`` NaN took no Gabor value at all without a word (``conf >= nan`` is False:
    match(method="fused", a_conf_min=nan) fused the sparse channels alone), a string or None
    failed in NumPy's comparison naming no parameter. 0 and 1 are its edges."""
    hop = _m([(5, 5, 10.0)])
    with pytest.raises(ValueError, match=r"^a_conf_min: expected a"):
        fuse(_dense(10.0, 0.5), {"hopfield": hop}, a_conf_min=bad)  # type: ignore[arg-type]
    assert fuse(_dense(10.0, 0.0), {"hopfield": hop}, a_conf_min=0).sources[0] == 1 | 4
    assert fuse(_dense(10.0, 1.0), {"hopfield": hop}, a_conf_min=1.0).sources[0] == 1 | 4


@pytest.mark.parametrize("bad", [float("nan"), 2.5, "2", None, True])
def test_min_agree_that_is_no_count_is_named(bad: object) -> None:
    """``min_agree`` NaN or 2.5 failed in range() ("'float' object cannot be interpreted as an
    integer"), a string or None in a comparison, naming no parameter; a NumPy int is a count."""
    hop = _m([(5, 5, 10.0)])
    with pytest.raises(ValueError, match=r"^min_agree: expected a whole number of channels"):
        fuse(_dense(10.0), {"hopfield": hop}, min_agree=bad)  # type: ignore[arg-type]
    assert len(fuse(_dense(10.0), {"hopfield": hop}, min_agree=np.int64(2))) == 1


@pytest.mark.parametrize("mode", ["vote", "intersection"])
@pytest.mark.parametrize("given", [np.array(3), np.array([3]), 3.0, np.float32(3.0)])
def test_min_agree_given_as_a_whole_number_is_its_count(mode: str, given: object) -> None:
    """The check of a count refused what it had taken: np.array(3) (a value read from an array;
    range() reads it) and 3.0 in intersection mode (where min_agree is not used), with "expected
    a whole number of channels, got 3.0". Each is the count 3: with two agreeing channels out of
    three, no member in vote mode (two make one: np.array([2])); intersection mode wants all."""
    mcgm, hop = _m([(4, 4, 10.0)]), _m([(4, 4, 10.2)])
    sparse = {"mcgm": mcgm, "hopfield": hop}
    want = fuse(_dense(14.0), sparse, mode=mode, min_agree=3)
    got = fuse(_dense(14.0), sparse, mode=mode, min_agree=given)  # type: ignore[arg-type]
    assert len(got) == len(want) == 0
    assert len(fuse(_dense(14.0), sparse, min_agree=np.array([2]))) == 1  # type: ignore[arg-type]


@pytest.mark.parametrize("kind", ["Fraction", "Decimal"])
def test_a_fraction_is_the_confidence_it_stands_for(kind: str) -> None:
    """a_conf_min, fill_confidence and second_confidence given a Fraction or a Decimal were
    compared as the number it is; the checks made it "expected a finite number, got
    Fraction(1, 4)". Each gives the plain float's result (as gabor_disparity reads them)."""
    from decimal import Decimal
    from fractions import Fraction

    def num(a: int, b: int) -> Any:
        return Fraction(a, b) if kind == "Fraction" else Decimal(a) / Decimal(b)

    hop = _m([(5, 5, 10.0)])
    # Gabor at confidence 0.25 and Hopfield agree: a member while Gabor takes part
    for cut, members in ((num(1, 4), 1), (num(3, 10), 0)):
        res = fuse(_dense(10.0, 0.25), {"hopfield": hop}, a_conf_min=cut)
        assert len(res) == members
    d = np.full((H, W), np.nan, np.float32)
    members = np.full((H, W), np.nan, np.float32)
    members[5, 5] = 12.0
    second = np.full((H, W), 7.0, np.float32)
    second[4:7, 3:8] = np.nan  # around the member: its anchor fill shows there
    kw: dict[str, Any] = {"fill_radius": 1.0, "speckle_area": 0.0, "second": second}
    out, conf = fused_dense(
        d, d, members, fill_confidence=num(1, 4), second_confidence=num(3, 4), **kw
    )
    want = fused_dense(d, d, members, fill_confidence=0.25, second_confidence=0.75, **kw)
    np.testing.assert_array_equal(out, want[0])
    np.testing.assert_array_equal(conf, want[1])
    assert out[5, 4] == 12.0 and conf[5, 4] == 0.25 and out[0, 0] == 7.0 and conf[0, 0] == 0.75


@pytest.mark.parametrize("kind", ["Fraction", "Decimal", "array"])
def test_every_fusion_option_reads_a_number_as_the_confidences_do(kind: str) -> None:
    """08d6931/15d043b read a Fraction or a Decimal as its float for the confidences only:
    r_spatial, tau_dx, radius, edge_jump, ... refused them ("expected a finite number, got
    Decimal('1.5')"), so a config read with parse_float=Decimal passed half its keys; and a
    size-1 array passed the checks but was used raw afterwards, NumPy's bare "only
    0-dimensional arrays can be converted" for r_spatial, speckle_area and the edge options
    (in depth_map after every matcher had run). Each option now gives its plain value's
    result."""
    from decimal import Decimal
    from fractions import Fraction

    from stereovision.matching.fusion import DEFAULTS, DENSE_DEFAULTS

    def given(v: float) -> Any:
        if kind == "array":
            return np.array([v])
        return Fraction(v) if kind == "Fraction" else Decimal(repr(v))

    sparse = {
        "hopfield": _m([(5, 5, 10.4), (8, 5, 10.6), (12, 7, 14.0)]),
        "mcgm": _m([(8, 6, 10.5)]),
    }
    want = fuse(_dense(10.0, 0.5), sparse)
    assert len(want) == 3
    for name, v in DEFAULTS.items():
        if name == "mode":
            continue
        got = fuse(_dense(10.0, 0.5), sparse, **{name: given(v)})
        np.testing.assert_array_equal(got.dispx, want.dispx, err_msg=name)
        np.testing.assert_array_equal(got.count, want.count, err_msg=name)
    d, c = _dense(5.0, 0.5)
    d[2:6, 3:9] = np.nan
    members = np.full((H, W), np.nan, np.float32)
    members[4, 4] = 12.0
    second = np.full((H, W), 7.0, np.float32)
    guide = np.random.default_rng(0).random((H, W)).astype(np.float32)
    kw: dict[str, Any] = {"second": second, "guide": guide}
    want_d, want_c = fused_dense(d, c, members, **kw)
    for name, v in DENSE_DEFAULTS.items():
        got_d, got_c = fused_dense(d, c, members, **kw, **{name: given(float(v))})
        np.testing.assert_array_equal(got_d, want_d, err_msg=name)
        np.testing.assert_array_equal(got_c, want_c, err_msg=name)


def test_a_fusion_option_of_a_small_integer_dtype_gives_the_plain_numbers_maps() -> None:
    """0bcf785 kept a size-1 array as the NumPy scalar of its dtype: np.array([16], np.uint8)
    as r_spatial squared to 0 in uint8 (only the pixel itself searched: MCGM's (8, 6) missed
    Hopfield's (8, 5)), np.array([1], np.uint8) as speckle_area was NumPy's "Python integer
    600 out of bounds for uint8". Each now gives the plain number's result."""
    sparse = {"hopfield": _m([(8, 5, 10.4), (12, 7, 14.0)]), "mcgm": _m([(8, 6, 10.5)])}
    want = fuse(None, sparse, r_spatial=16)
    assert len(want) == 2  # (8, 5) and (8, 6), each finding the other
    for r in (np.array([16], np.uint8), np.uint8(16), np.float64(16.0)):
        got = fuse(None, sparse, r_spatial=r)
        np.testing.assert_array_equal(got.dispx, want.dispx, err_msg=repr(r))
        np.testing.assert_array_equal(got.count, want.count, err_msg=repr(r))
    d, c = _dense(5.0, 0.5)
    d[2:4, 3:5] = 9.0  # a 4-pixel region: under 1 x 600 pixels, so dropped
    members = np.full((H, W), np.nan, np.float32)
    want_d, want_c = fused_dense(d, c, members, speckle_area=1)
    assert np.isnan(want_d).all()
    for a in (np.array([1], np.uint8), np.int8(1)):
        got_d, got_c = fused_dense(d, c, members, speckle_area=a)
        np.testing.assert_array_equal(got_d, want_d, err_msg=repr(a))
        np.testing.assert_array_equal(got_c, want_c, err_msg=repr(a))


def test_a_fraction_or_decimal_no_float_holds_is_refused_by_its_name() -> None:
    """A Fraction past a float's range (or a signalling Decimal NaN, which float() refuses) is
    left as given for the check, which names the parameter: it is not read as some other
    value and fused with."""
    from decimal import Decimal
    from fractions import Fraction

    hop = {"hopfield": _m([(5, 5, 10.0)])}
    for bad in (Fraction(10**400), -Fraction(10**400), Decimal("sNaN")):
        with pytest.raises(ValueError, match=r"^a_conf_min: expected a finite number"):
            fuse(_dense(10.0, 0.25), hop, a_conf_min=bad)  # type: ignore[arg-type]
    d = np.full((H, W), np.nan, np.float32)
    for name in ("fill_confidence", "second_confidence"):
        with pytest.raises(ValueError, match=f"^{name}: expected a finite number"):
            fused_dense(d, d, d, **{name: Fraction(10**400)})


@pytest.mark.parametrize("given", [np.timedelta64(16), np.timedelta64(16, "ns")])
def test_a_fusion_option_given_as_a_timedelta_is_refused(given: Any) -> None:
    """db08e0d read every np.integer with item(), and np.timedelta64 is one: 16 ns (or a
    timedelta without unit) became the int 16 and was taken as r_spatial=16 (or speckle_area),
    where it was refused as no number before. It is refused again, the value named as given."""
    sparse = {"hopfield": _m([(8, 5, 10.4)]), "mcgm": _m([(8, 6, 10.5)])}
    with pytest.raises(ValueError, match=r"^r_spatial: expected a finite number, got ") as info:
        fuse(None, sparse, r_spatial=given)
    assert repr(given) in str(info.value)
    d, c = _dense(5.0, 0.5)
    members = np.full((H, W), np.nan, np.float32)
    with pytest.raises(ValueError, match=r"^speckle_area: expected a finite number, got "):
        fused_dense(d, c, members, speckle_area=given)


@pytest.mark.parametrize("name", ["fill_confidence", "second_confidence"])
@pytest.mark.parametrize("bad", ["0.5", None])
def test_dense_confidence_that_is_no_number_is_named(name: str, bad: object) -> None:
    """fused_dense's confidences given a string or None failed in the range check's comparison
    ("'<' not supported between instances of 'int' and 'str'"), naming no parameter
    (depth_map(..., second_confidence="0.5") too)."""
    d = np.full((H, W), np.nan, np.float32)
    with pytest.raises(ValueError, match=f"^{name}: expected a finite number"):
        fused_dense(d, d, d, **{name: bad})


def test_tau_dy_alone_bounds_the_y_disparity() -> None:
    """``tau_dy`` (not ``tau_dx``) decides on y: 1.5 px apart vertically, same x-disparity."""
    sparse = {"mcgm": _m([(4, 4, 9.0)], dy=0.0), "hopfield": _m([(4, 4, 9.0)], dy=1.5)}
    assert len(fuse(None, sparse, tau_dx=1.0, tau_dy=2.0)) == 1
    assert len(fuse(None, sparse, tau_dx=3.0, tau_dy=1.0)) == 0


def test_members_carry_the_weighted_mean_y_disparity() -> None:
    """dispy is the agreeing subset's weighted mean with Gabor's vertical disparity taken as 0,
    and ``yr = yl - dispy`` (the Matches convention)."""
    mcgm = _m([(6, 8, 12.0)], dy=0.5)
    hop = _m([(6, 8, 12.0)], dy=1.0)
    res = fuse(_dense(12.0, 1.0), {"mcgm": mcgm, "hopfield": hop})
    assert len(res) == 1 and res.count[0] == 3
    # (1 * 0 + 1 * 0.5 + 1 * 1.0) / 3 = 0.5
    assert res.dispy[8, 6] == pytest.approx(0.5)
    assert res.matches.yr[0] == pytest.approx(8.0 - 0.5)
    assert np.isnan(res.dispy[0, 0])


def test_score_is_the_share_of_the_available_channels() -> None:
    """``score`` = agreeing / available: where Gabor has no value, two sparse channels that
    agree score 1; where all three are there and two agree, 2/3."""
    d, c = _dense(20.0)
    d[3, 3] = np.nan
    mcgm = _m([(3, 3, 10.0), (9, 3, 10.0)])
    hop = _m([(3, 3, 10.5), (9, 3, 10.5)])
    res = fuse((d, c), {"mcgm": mcgm, "hopfield": hop})
    np.testing.assert_array_equal(res.matches.xl, [3, 9])
    np.testing.assert_allclose(res.matches.score, [1.0, 2 / 3])
    np.testing.assert_array_equal(res.count, [2, 2])


def test_a_channel_measured_at_the_candidate_gives_its_own_value() -> None:
    """D.2's nearest value: a sparse channel measured at the candidate pixel itself takes part
    with that value, not with a neighbour's within ``r_spatial`` (here one row above)."""
    mcgm = _m([(10, 10, 7.0), (10, 9, 9.0)])
    hop = _m([(10, 10, 7.2)])
    res = fuse(None, {"mcgm": mcgm, "hopfield": hop})
    # (10, 9): MCGM's 9.0 against Hopfield's 7.2 one pixel down: no member there.
    np.testing.assert_array_equal(res.matches.xl, [10])
    np.testing.assert_array_equal(res.matches.yl, [10])
    assert res.dispx[10, 10] == pytest.approx(7.1)


def test_fused_dense_veto_radius_is_inclusive() -> None:
    """Step 2: a Gabor pixel exactly ``radius`` px from a member (5 px along a row: the
    distance transform's straight steps are exact) that differs by more than ``tau`` is
    dropped; one pixel farther it stays."""
    d = np.full((H, W), 10.0, np.float32)
    c = np.full((H, W), 0.5, np.float32)
    members = np.full((H, W), np.nan, np.float32)
    members[10, 10] = 20.0
    out, conf = fused_dense(d, c, members, radius=5.0, tau=2.0, fill_radius=0.0)
    assert np.isnan(out[10, 15]) and np.isnan(out[10, 5]) and conf[10, 15] == 0.0
    assert out[10, 16] == 10.0 and out[10, 4] == 10.0 and conf[10, 16] == 0.5
    # "More than tau": a value exactly tau from the member stays.
    d[10, 13] = 18.0
    out, _ = fused_dense(d, c, members, radius=5.0, tau=2.0, fill_radius=0.0)
    assert out[10, 13] == 18.0


def test_fused_dense_keeps_anchor_fills_where_second_is_silent() -> None:
    """Step 5 drops a lone Gabor value above the row fill, but not a hole an anchor filled
    (step 3): here the fill at column 3 (the member's 12) stands 7 px above its row fill (5)."""
    nan = np.float32(np.nan)
    d = np.array([[5, 5, 5, nan, 5, 5, 5, 5]], np.float32)
    members = np.array([[nan, nan, 12, nan, nan, nan, nan, nan]], np.float32)
    second = np.array([[5, 5, nan, nan, 5, 5, 5, 5]], np.float32)
    conf = np.full(d.shape, 0.8, np.float32)
    out, c = fused_dense(d, conf, members, radius=0.0, fill_radius=1.0, second=second)
    np.testing.assert_array_equal(out, np.array([[5, 5, 12, 12, 5, 5, 5, 5]], np.float32))
    np.testing.assert_allclose(c, [[0.8, 0.8, 1.0, 0.25, 0.8, 0.8, 0.8, 0.8]])


def test_enclosed_far_leaves_a_region_touching_any_border() -> None:
    """A dark floor region that touches the right border is open (kept); the same region one
    pixel from that border is enclosed (filled)."""
    d = np.full((40, 50), 6.0, np.float32)
    g = np.full((40, 50), 0.6, np.float32)
    d[10:20, 40:50], g[10:20, 40:50] = 0.0, 0.1
    assert not fill_enclosed_far(d, g)[1].any()
    d[10:20, 49], g[10:20, 49] = 6.0, 0.6
    out, filled = fill_enclosed_far(d, g)
    assert filled.sum() == 90 and np.all(out[10:20, 40:49] == 6.0)


def test_enclosed_far_takes_the_surround_median() -> None:
    """The filled region takes its surround's median: a strip of 30 in the ring (a nearer
    post beside the window) does not pull it up as a mean would (to about 10)."""
    d = np.full((60, 80), 6.0, np.float32)
    g = np.full((60, 80), 0.6, np.float32)
    d[20:30, 10:25], g[20:30, 10:25] = 0.2, 0.1  # dark, at the floor, enclosed
    d[20:30, 25:27] = 30.0  # part of the 3 px surround, on its right
    out, filled = fill_enclosed_far(d, g)
    assert filled.sum() == 150
    assert np.all(out[20:30, 10:25] == 6.0)


def test_fuse_result_dtypes_follow_the_docs() -> None:
    """dispx / dispy float32, count / sources and their rasters uint8 (FusionResult's docs)."""
    res = fuse(_dense(10.0, 0.5), {"hopfield": _m([(5, 5, 10.4)])})
    assert res.dispx.dtype == res.dispy.dtype == np.float32
    assert res.count.dtype == res.sources.dtype == np.uint8
    assert res.count_map.dtype == res.sources_map.dtype == np.uint8
    assert res.matches.xl.dtype == res.matches.xr.dtype == np.float32


def test_fused_dense_gives_holes_no_confidence() -> None:
    """A Gabor hole that nothing fills keeps confidence 0, whatever the confidence map says."""
    d = np.full((H, W), 10.0, np.float32)
    d[4, 4] = np.nan
    c = np.full((H, W), 0.5, np.float32)
    out, conf = fused_dense(d, c, np.full((H, W), np.nan, np.float32))
    assert np.isnan(out[4, 4]) and conf[4, 4] == 0.0 and conf[5, 5] == 0.5


def test_fused_dense_second_opinion_drops_disagreement_and_fills_holes() -> None:
    """Step 4: a Gabor value more than ``second_tol`` from the second map becomes a hole (not
    the second map's value); exactly ``second_tol`` apart it stays; a hole takes the second
    map's value at ``second_confidence``, also when there is no map of its own at all. Step 5's
    bound is strict too."""
    nan = np.float32(np.nan)
    d = np.array([[10, 10, 10, 10, nan, 10, 10, 10]], np.float32)
    second = np.array([[10.5, 11, 14, 10, 7, 10, 10, 10]], np.float32)
    conf = np.full(d.shape, 0.8, np.float32)
    none = np.full(d.shape, nan, np.float32)
    out, c = fused_dense(d, conf, none, second=second, second_tol=1.0, second_confidence=0.7)
    np.testing.assert_array_equal(out, np.array([[10, 10, nan, 10, 7, 10, 10, 10]], np.float32))
    np.testing.assert_allclose(c, [[0.8, 0.8, 0.0, 0.8, 0.7, 0.8, 0.8, 0.8]])
    out, c = fused_dense(none, conf, none, second=second, second_confidence=0.7)
    np.testing.assert_array_equal(out, second)
    np.testing.assert_allclose(c, np.full(d.shape, 0.7))
    # Step 5: a lone Gabor value (no second value there) more than occlusion_tau above the row
    # fill of the others goes; exactly occlusion_tau above it stays.
    lone = np.array([[5, 5, 7, 5, 5, 7.5, 5, 5]], np.float32)
    quiet = np.array([[5, 5, nan, 5, 5, nan, 5, 5]], np.float32)
    out, c = fused_dense(lone, conf, none, second=quiet, occlusion_tau=2.0)
    np.testing.assert_array_equal(out, np.array([[5, 5, 7, 5, 5, nan, 5, 5]], np.float32))
    assert c[0, 5] == 0.0 and c[0, 2] == np.float32(0.8)  # the hole has no confidence left


def test_fuse_pair_passes_its_range_to_the_remeasure_and_the_member_check(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A range that starts above 0 reaches the re-measure and the members' both-sides check
    too, not 0 to ``max_disparity``."""
    import stereovision.matching.mcgm as mcgm
    import stereovision.refine as refine

    seen: dict[str, list[tuple[float, float]]] = {"refine": [], "sides": []}

    def spy(name: str, fn: Any) -> Any:
        def call(*args: Any, **kw: Any) -> Any:
            seen[name].append((kw["min_disparity"], kw["max_disparity"]))
            return fn(*args, **kw)

        return call

    monkeypatch.setattr(refine, "_refine", spy("refine", refine._refine))
    monkeypatch.setattr(mcgm, "edge_filters", spy("sides", mcgm.edge_filters))
    sc = load_scene(data_dir / "middlebury2001" / "tsukuba")
    gl, gr = as_gray_float(sc.left, "left"), as_gray_float(sc.right, "right")
    res = fuse_pair(gl, gr, max_disparity=16, min_disparity=3, census_members=False)
    assert len(res) > 100
    assert seen == {"refine": [(3, 16)], "sides": [(3, 16)]}


def test_min_agree_three_needs_every_channel_to_agree() -> None:
    """Vote mode with ``min_agree=3``: a pixel where only two of the three channels agree is no
    member; one where all three agree is."""
    mcgm = _m([(3, 3, 10.0), (9, 3, 10.0)])
    hop = _m([(3, 3, 10.4), (9, 3, 14.0)])  # (9, 3): Hopfield disagrees, Gabor and MCGM agree
    assert len(fuse(_dense(10.2), {"mcgm": mcgm, "hopfield": hop})) == 2
    res = fuse(_dense(10.2), {"mcgm": mcgm, "hopfield": hop}, min_agree=3)
    np.testing.assert_array_equal(res.matches.xl, [3])
    np.testing.assert_array_equal(res.count, [3])


def test_channels_are_named_in_bit_order_and_candidates_counted() -> None:
    """``channels`` (and ``stats["channels"]``) follow the bits whatever the mapping's order;
    ``stats["candidates"]`` counts every pixel a sparse channel measured, ``"members"`` those
    kept."""
    hop = _m([(5, 5, 10.4), (8, 5, 10.6), (12, 7, 14.0)])
    mcgm = _m([(5, 5, 10.2)])
    res = fuse(_dense(10.0, 0.5), {"hopfield": hop, "mcgm": mcgm})
    assert res.channels == ("gabor", "mcgm", "hopfield")
    assert res.matches.stats["channels"] == ["gabor", "mcgm", "hopfield"]
    assert res.matches.stats["candidates"] == 3 and res.matches.stats["members"] == 2
    assert fuse(None, {"hopfield": hop, "mcgm": mcgm}).channels == ("mcgm", "hopfield")


def test_members_y_disparity_is_weighted_by_gabor_confidence() -> None:
    """Gabor's vertical disparity 0 weighs its confidence (0.5) in the mean, as on x:
    (0.5 * 0 + 1 * 0.6 + 1 * 0) / 2.5 = 0.24, not the plain mean 0.2."""
    mcgm = _m([(6, 8, 12.0)], dy=0.6)
    hop = _m([(6, 8, 12.0)], dy=0.0)
    res = fuse(_dense(12.0, 0.5), {"mcgm": mcgm, "hopfield": hop})
    assert len(res) == 1 and res.count[0] == 3
    assert res.dispy[8, 6] == pytest.approx(0.24)
    assert res.matches.yr[0] == pytest.approx(8.0 - 0.24)


def test_fuse_pair_runs_only_the_channels_asked_for() -> None:
    """``channels`` without MCGM: MCGM neither runs nor votes, and the per-channel match counts
    name exactly the sparse channels that ran (with their lengths)."""
    rng = np.random.default_rng(5)
    right = rng.random((48, 80)).astype(np.float32)
    left = np.roll(right, 4, axis=1)  # disparity 4
    kw: dict[str, Any] = {"max_disparity": 8, "census_members": False}
    both = fuse_pair(left, right, **kw)
    outs = both.channel_outputs
    assert both.matches.stats["channel_matches"] == {
        "mcgm": len(outs["mcgm"]),
        "hopfield": len(outs["hopfield"]),
    }
    res = fuse_pair(left, right, channels=("gabor", "hopfield"), **kw)
    assert len(res) > 0 and res.channels == ("gabor", "hopfield")
    assert "mcgm" not in res.channel_outputs
    assert res.matches.stats["channel_matches"] == {
        "hopfield": len(res.channel_outputs["hopfield"])
    }
    assert not np.any(res.sources & CHANNEL_BITS["mcgm"])


def test_enclosed_far_bounds_jump_inclusive_and_darker_strict() -> None:
    """A surround exactly ``jump`` above the floor is enough ("jump px or more"); a region as
    bright as its surround (not darker) is left alone."""
    d = np.full((60, 80), 3.0, np.float32)  # floor 0 + jump 3, exactly
    g = np.full((60, 80), 0.6, np.float32)
    d[20:30, 10:25], g[20:30, 10:25] = 0.2, 0.1
    out, filled = fill_enclosed_far(d, g, floor=0.0, jump=3.0)
    assert filled.sum() == 150 and np.all(out[20:30, 10:25] == 3.0)
    g[20:30, 10:25] = 0.6  # as bright as the surround
    out, filled = fill_enclosed_far(d, g, floor=0.0, jump=3.0)
    assert not filled.any() and np.all(out[20:30, 10:25] == np.float32(0.2))


def test_enclosed_far_region_is_strictly_below_floor_plus_far() -> None:
    """The region is ``d < floor + far`` strictly (docs/fusion.md): a dark pane at exactly
    0.5 px is not locked to the floor; ``far`` and ``jump`` 0 are valid (non-negative)."""
    d = np.full((60, 80), 6.0, np.float32)
    g = np.full((60, 80), 0.6, np.float32)
    d[20:30, 10:25], g[20:30, 10:25] = 0.5, 0.1
    assert not fill_enclosed_far(d, g, floor=0.0, far=0.5)[1].any()
    assert fill_enclosed_far(d, g, floor=0.0, far=0.75)[1].sum() == 150
    assert not fill_enclosed_far(d, g, far=0.0)[1].any()
    assert fill_enclosed_far(d, g, far=0.75, jump=0.0)[1].sum() == 150


def test_fused_dense_marks_the_pixels_only_second_measured() -> None:
    """``_only_second`` (depth_map's census-only marks) is set where the value came from
    ``second`` alone, also without a map of its own, and cleared where step 6 drops it."""
    none = np.full((H, W), np.nan, np.float32)
    conf = np.ones((H, W), np.float32)
    second = none.copy()
    second[2:6, 3:9] = 7.0
    flag = np.zeros((H, W), bool)
    fused_dense(none, conf, none, second=second, _only_second=flag)
    np.testing.assert_array_equal(flag, np.isfinite(second))
    d = np.full((H, W), 5.0, np.float32)
    d[10, 10] = np.nan
    island = none.copy()
    island[10, 10] = 20.0  # a one-pixel island the speckle step drops
    flag = np.zeros((H, W), bool)
    out, c = fused_dense(d, conf, none, second=island, speckle_area=2 / (H * W), _only_second=flag)
    assert np.isnan(out[10, 10]) and c[10, 10] == 0.0
    assert not flag.any()


def test_fused_dense_clears_census_only_marks_the_edge_step_drops() -> None:
    """Step 7 on a map ``second`` alone gave: the fattened ring it turns into holes loses its
    census-only mark (depth_map would count a hole as census-measured)."""
    h, w = 60, 80
    guide = np.full((h, w), 0.2, np.float32)
    guide[20:40, 30:50] = 0.8
    guide += np.random.default_rng(1).normal(0, 0.01, (h, w)).astype(np.float32)
    d = np.full((h, w), 10.0, np.float32)
    d[20:40, 27:53] = 20.0
    d[17:43, 30:50] = 20.0
    none = np.full(d.shape, np.nan, np.float32)
    flag = np.zeros((h, w), bool)
    out, _ = fused_dense(
        none, np.ones_like(d), none, second=d, guide=guide, speckle_area=0.0, _only_second=flag
    )
    assert np.isnan(out).sum() > 0
    np.testing.assert_array_equal(flag, np.isfinite(out))


@pytest.mark.parametrize(
    "name",
    [
        "radius",
        "tau",
        "fill_radius",
        "second_tol",
        "occlusion_tau",
        "speckle_area",
        "speckle_diff",  # the speckle kernel's f32, cast in Rust: no warning before either
        "edge_radius",
        "edge_ratio",
        "edge_jump",
    ],
)
def test_fused_dense_refuses_each_negative_setting(name: str) -> None:
    """Every length and tolerance of fused_dense is refused below 0, naming it."""
    d, c = _dense(5.0)
    with pytest.raises(ValueError, match=f"^{name}: expected a non-negative number"):
        fused_dense(d, c, np.full((H, W), np.nan, np.float32), **{name: -1})


@pytest.mark.parametrize(
    ("method", "bad"),
    [
        ("fused", {"a_conf_min": float("nan")}),
        ("fused", {"min_agree": 1}),
        ("fused", {"mode": "majority"}),
        ("fused", {"fill_confidence": 0}),
        ("fused", {"radius": -1.0}),
        ("census", {"second_confidence": 0}),
        ("fast", {"edge_jump": "2"}),
    ],
)
def test_a_bad_fusion_value_is_said_before_the_matching(
    method: str, bad: dict[str, Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    """fuse's and fused_dense's values were checked in them, after every matcher had run
    (0.4 s on cones, seconds on a large pair: depth_map reached its "rectify" and "prepare"
    stages and ran the channels): depth_map now refuses them before it rectifies, and
    fuse_pair (match(method="fused")) before its channels run."""
    import stereovision.matching.gabor as gabor_mod
    import stereovision.matching.sgm as sgm_mod
    from stereovision.matching.fusion import DEFAULTS

    def no_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("a matcher ran")

    monkeypatch.setattr(sgm_mod, "sgm_disparity", no_run)
    monkeypatch.setattr(gabor_mod, "gabor_disparity", no_run)
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    stages: list[str] = []
    name = next(iter(bad))
    with pytest.raises(ValueError, match=f"^{name}: expected "):
        sv_depth_map(img, img, max_disparity=8, method=method, progress=stages.append, **bad)
    assert stages == []
    if name in DEFAULTS:
        with pytest.raises(ValueError, match=f"^{name}: expected "):
            fuse_pair(img, img, max_disparity=8, **bad)


@pytest.mark.parametrize("channels", [("gabor",), (), "gabor,mcgm"])
@pytest.mark.parametrize("census_members", [True, False])
def test_fuse_pair_without_a_sparse_channel_is_refused_before_the_matching(
    channels: Any, census_members: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """425ec60 refused these before the matching in depth_map only: match(method="fused") and
    fuse_pair ran every channel (the census map too) before fuse's "at least one sparse
    channel", () without the census map was ThreadPoolExecutor's "max_workers must be greater
    than 0", and "gabor,mcgm" was read letter by letter ("unknown channel(s) [',', 'a', ...")."""
    import stereovision.matching.gabor as gabor_mod
    import stereovision.matching.sgm as sgm_mod

    def no_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("a matcher ran")

    monkeypatch.setattr(sgm_mod, "sgm_disparity", no_run)
    monkeypatch.setattr(gabor_mod, "gabor_disparity", no_run)
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    with pytest.raises(ValueError, match=r"^channels: expected a"):
        fuse_pair(img, img, max_disparity=8, channels=channels, census_members=census_members)
    with pytest.raises(ValueError, match=r"^channels: expected a"):
        sv_match(img, img, method="fused", max_disparity=8, channels=channels)


@pytest.mark.parametrize(
    ("channels", "says"),
    [
        (("gabor", "mcgm", "hopfield"), "the mcgm and hopfield channels search from 0 px"),
        (("gabor", "hopfield"), "the hopfield channel searches from 0 px"),
    ],
)
def test_fuse_pair_refuses_a_negative_range_before_the_matching(
    channels: tuple[str, ...], says: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The sparse channels' own refusal of min_disparity=-2 came after the Gabor channel and
    the census map, which take a negative range, had run on the whole pair (0.46 s on cones)."""
    import stereovision.matching.gabor as gabor_mod
    import stereovision.matching.sgm as sgm_mod

    def no_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("a matcher ran")

    monkeypatch.setattr(sgm_mod, "sgm_disparity", no_run)
    monkeypatch.setattr(gabor_mod, "gabor_disparity", no_run)
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    said = r"^min_disparity must be a non-negative number of pixels, got -2: " + says
    with pytest.raises(ValueError, match=said):
        fuse_pair(img, img, max_disparity=8, min_disparity=-2, channels=channels)


@pytest.mark.parametrize(
    ("kw", "says"),
    [
        ({"max_disparity": np.array([8])}, "max_disparity: expected a number of pixels, got "),
        ({"min_disparity": np.array([2])}, "min_disparity: expected a number of pixels, got "),
        ({"min_disparity": "2"}, "min_disparity: expected a number of pixels, got '2'"),
    ],
)
def test_fuse_pair_refuses_a_range_of_no_number_before_the_matching(
    kw: dict[str, object], says: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A bound that is no number (np.array([60]) read from a config) was refused by the sparse
    channels only after the Gabor channel and the census map had run (0.44 s on cones), as
    'max_disparity must be a non-negative number of pixels, got array([60])', of a value that
    is one. It is match()'s and depth_map's TypeError now, before any channel runs."""
    import stereovision.matching.gabor as gabor_mod
    import stereovision.matching.sgm as sgm_mod

    def no_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("a matcher ran")

    monkeypatch.setattr(sgm_mod, "sgm_disparity", no_run)
    monkeypatch.setattr(gabor_mod, "gabor_disparity", no_run)
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    with pytest.raises(TypeError, match="^" + re.escape(says)):
        fuse_pair(img, img, **{"max_disparity": 8, **kw})  # type: ignore[arg-type]


def test_fuse_pair_reads_channels_given_as_a_generator() -> None:
    """886da87 read channels three times: a generator was used up by the unknown-name check
    and then said to hold "no sparse channel" (before it, it ran the census map alone and
    failed in fuse). It now gives the tuple's result; a channels that is no collection of
    names is a ValueError naming it."""
    rng = np.random.default_rng(1)
    left = rng.random((40, 60)).astype(np.float32)
    right = np.roll(left, -3, axis=1)
    kw: dict[str, Any] = {"max_disparity": 8, "census_members": False, "check_members": False}
    want = fuse_pair(left, right, channels=("mcgm", "hopfield"), **kw)
    assert len(want) > 0
    got = fuse_pair(left, right, channels=(c for c in ("mcgm", "hopfield")), **kw)
    np.testing.assert_array_equal(got.dispx, want.dispx)
    np.testing.assert_array_equal(got.sources, want.sources)
    with pytest.raises(ValueError, match=r"^channels: expected a tuple of channel names"):
        fuse_pair(left, right, channels=None, **kw)


@pytest.mark.parametrize("channels", [(["mcgm"],), ("gabor", 1, "x")])
def test_fuse_pair_names_channels_that_are_no_names(
    channels: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """fuse_pair checked the names with sorted(set(channels)): a list among them was Python's
    bare "unhashable type: 'list'", a number beside a name "'<' not supported between
    instances of 'str' and 'int'" (from match(method="fused") too). Each is now the unknown
    channel ValueError, before any matcher runs."""
    import stereovision.matching.sgm as sgm_mod

    def no_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("a matcher ran")

    monkeypatch.setattr(sgm_mod, "sgm_disparity", no_run)
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    with pytest.raises(ValueError, match=r"^unknown channel\(s\) \[") as info:
        fuse_pair(img, img, max_disparity=8, channels=channels)
    assert "'gabor'" not in str(info.value).split(":")[0]
    with pytest.raises(ValueError, match=r"^unknown channel\(s\) \["):
        sv_match(img, img, method="fused", max_disparity=8, channels=channels)


@pytest.mark.parametrize(
    ("channels", "arrays"),
    [
        ((np.array(["mcgm", "gabor"]), "x"), 1),
        (np.array([["mcgm", "gabor"], ["hopfield", "gabor"]]), 2),
        ((np.array([1, 2]), np.array([3, 4])), 2),
    ],
)
def test_fuse_pair_names_channels_that_are_arrays(
    channels: Any, arrays: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """482acc9's name check compared each entry with those already found (``c not in bad``):
    an array entry beside another non-name was NumPy's "The truth value of an array with more
    than one element is ambiguous", naming nothing. Each is now the unknown channel error,
    before any matcher runs."""
    import stereovision.matching.sgm as sgm_mod

    def no_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("a matcher ran")

    monkeypatch.setattr(sgm_mod, "sgm_disparity", no_run)
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    with pytest.raises(ValueError, match=r"^unknown channel\(s\) \[") as info:
        fuse_pair(img, img, max_disparity=8, channels=channels)
    assert str(info.value).count("array(") == arrays  # each entry said once


@pytest.mark.parametrize(
    "switch", ["remeasure_gabor", "check_members", "edge_members", "census_members", "dense_sgm"]
)
@pytest.mark.parametrize("bad", ["no", None, 1])
def test_a_fuse_pair_switch_that_is_no_bool_is_named(
    switch: str, bad: object, monkeypatch: pytest.MonkeyPatch
) -> None:
    """c71ed42 refused depth_map(semi_global="no") (it ran the census map, None skipped it),
    but fuse_pair's switches, two of which depth_map and match(method="fused") pass on, went
    unchecked: check_members="no" ran the check and None skipped it without a word. Each is a
    TypeError naming it now, before any channel runs (depth_map's before the rectification)."""
    import stereovision.matching.gabor as gabor_mod
    import stereovision.matching.sgm as sgm_mod

    def no_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("a matcher ran")

    monkeypatch.setattr(sgm_mod, "sgm_disparity", no_run)
    monkeypatch.setattr(gabor_mod, "gabor_disparity", no_run)
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    want = f"^{switch}: expected True or False, got {bad!r}$"
    with pytest.raises(TypeError, match=want):
        fuse_pair(img, img, max_disparity=8, **{switch: bad})  # type: ignore[arg-type]
    if switch in ("check_members", "edge_members"):
        with pytest.raises(TypeError, match=want):
            sv_match(img, img, method="fused", max_disparity=8, **{switch: bad})
        stages: list[str] = []
        with pytest.raises(TypeError, match=want):
            sv_depth_map(img, img, max_disparity=8, progress=stages.append, **{switch: bad})
        assert stages == []


@pytest.mark.parametrize(
    ("channels", "min_agree"),
    [(("gabor", "mcgm", "hopfield"), 4), (("gabor", "mcgm"), 3), (("mcgm",), 2)],
)
def test_a_vote_no_pixel_can_win_is_refused(
    channels: tuple[str, ...], min_agree: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """min_agree above the channels taking part left range(n, min_agree - 1, -1) empty: fuse
    returned no member without a word, match(method="fused", channels=("mcgm",)) zero matches
    at the default min_agree after every channel had run, and depth_map(min_agree=4) a dense
    map with no member. Each is refused, before any matcher runs; intersection mode (which
    does not read min_agree) still takes it."""
    import stereovision.matching.gabor as gabor_mod
    import stereovision.matching.sgm as sgm_mod

    sparse = {n: _m([(4, 4, 10.0)]) for n in channels if n != "gabor"}
    dense = _dense(10.0) if "gabor" in channels else None
    want = rf"^min_agree: {min_agree} channels must agree but {len(channels)} take part"
    with pytest.raises(ValueError, match=want):
        fuse(dense, sparse, min_agree=min_agree)
    assert len(fuse(dense, sparse, min_agree=min_agree, mode="intersection")) == 1

    def no_run(*args: object, **kwargs: object) -> None:
        raise AssertionError("a matcher ran")

    monkeypatch.setattr(sgm_mod, "sgm_disparity", no_run)
    monkeypatch.setattr(gabor_mod, "gabor_disparity", no_run)
    img = np.random.default_rng(0).random((40, 60)).astype(np.float32)
    kw: dict[str, Any] = {"channels": channels, "min_agree": min_agree}
    with pytest.raises(ValueError, match=want):
        fuse_pair(img, img, max_disparity=8, **kw)
    with pytest.raises(ValueError, match=want):
        sv_match(img, img, method="fused", max_disparity=8, **kw)
    if "gabor" in channels:
        stages: list[str] = []
        with pytest.raises(ValueError, match=want):
            sv_depth_map(img, img, max_disparity=8, progress=stages.append, **kw)
        assert stages == []


@pytest.mark.parametrize("given", [10**5000, Fraction(10**5000)], ids=["int", "Fraction"])
def test_a_min_agree_with_no_str_is_named(given: object) -> None:
    """A min_agree of 10**5000 (or its Fraction, a count to whole_value since b87b5fa) above
    the channels was said by its str: Python's own "Exceeds the limit (4300 digits) for
    integer string conversion", naming no parameter."""
    sparse = {"hopfield": _m([(4, 4, 10.0)]), "mcgm": _m([(4, 4, 10.0)])}
    want = r"^min_agree: an integer of 5001 digits channels must agree but 2 take part"
    with pytest.raises(ValueError, match=want):
        fuse(None, sparse, min_agree=given)


def test_an_r_spatial_past_its_bound_is_refused_at_once() -> None:
    """fuse visits every offset within r_spatial: 1e6 px (or np.uint64's maximum, which
    _plain_option reads as a huge int) ran for ever instead of failing. Past MAX_R_SPATIAL it is
    refused before any search; the bound itself is taken."""
    from stereovision.matching.fusion import MAX_R_SPATIAL

    sparse = {"hopfield": _m([(8, 5, 10.4)]), "mcgm": _m([(8, 6, 10.5)])}
    for bad in (1e6, np.uint64(2**64 - 1), MAX_R_SPATIAL + 0.5):
        with pytest.raises(ValueError, match=r"^r_spatial: expected at most 64.0 px"):
            fuse(None, sparse, r_spatial=bad)
    assert len(fuse(None, sparse, r_spatial=MAX_R_SPATIAL)) == len(fuse(None, sparse, r_spatial=16))


@pytest.mark.parametrize("given", [np.timedelta64(2), np.timedelta64(2, "ns")])
def test_a_min_agree_given_as_a_timedelta_is_refused(given: Any) -> None:
    """2ff768b refused a timedelta64 as r_spatial or speckle_area, but min_agree reads its
    count by np.integer, which np.timedelta64 is: 2 ns was taken as 2 channels (an array of
    them refused). It is refused, named as given, by fuse and before depth_map matches."""
    sparse = {"hopfield": _m([(8, 5, 10.4)]), "mcgm": _m([(8, 6, 10.5)])}
    with pytest.raises(ValueError, match=r"^min_agree: expected a whole number") as info:
        fuse(None, sparse, min_agree=given)
    assert repr(given) in str(info.value)
    img = np.zeros((20, 30), np.float32)
    stages: list[str] = []
    with pytest.raises(ValueError, match=r"^min_agree: expected a whole number"):
        sv_depth_map(img, img, max_disparity=8, progress=stages.append, min_agree=given)
    assert stages == []


def test_a_speckle_area_too_large_for_the_map_drops_every_region() -> None:
    """speckle_area is a share of H * W, capped at the map's size before the kernel; 1e308
    of the map is inf, and int(inf) was Python's bare OverflowError (after every matcher had
    run, through depth_map). It now gives the capped area's map: every region is smaller."""
    d, c = _dense(5.0, 0.5)
    members = np.full((H, W), np.nan, np.float32)
    want, want_c = fused_dense(d, c, members, speckle_area=2.0)
    assert np.isnan(want).all()
    for big in (1e308, 2**70, np.uint64(2**64 - 1)):
        got, got_c = fused_dense(d, c, members, speckle_area=big)
        np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(got_c, want_c)


@pytest.mark.parametrize("name", ["edge_ratio", "edge_jump"])
def test_an_edge_option_past_float32_is_named(name: str) -> None:
    """The edge kernel takes edge_ratio and edge_jump as float32: 1e308 became inf there and
    was refused after every matcher had run as "ratio: expected a non-negative number, got
    inf", naming neither the option nor the value given. It is refused by its name before
    depth_map matches; float32's largest value is taken."""
    d, c = _dense(5.0, 0.5)
    members = np.full((H, W), np.nan, np.float32)
    guide = np.random.default_rng(0).random((H, W)).astype(np.float32)
    f32_max = float(np.finfo(np.float32).max)
    want = f"^{name}: expected at most 3.40282e\\+38 \\(float32\\), got 1e\\+308$"
    with pytest.raises(ValueError, match=want):
        fused_dense(d, c, members, guide=guide, **{name: 1e308})
    img = np.zeros((20, 30), np.float32)
    stages: list[str] = []
    with pytest.raises(ValueError, match=want):
        sv_depth_map(img, img, max_disparity=8, progress=stages.append, **{name: 1e308})
    assert stages == []
    got, _ = fused_dense(d, c, members, guide=guide, **{name: f32_max})
    assert np.isfinite(got).any()


@pytest.mark.parametrize(
    "key",
    [
        "tau_dx",
        "tau_dy",
        "radius",
        "tau",
        "fill_radius",
        "second_tol",
        "occlusion_tau",
        "speckle_diff",  # the speckle kernel's f32, cast in Rust: no warning before either
    ],
)
def test_a_tolerance_past_float32_is_its_infinity_without_numpy_warnings(
    data_dir: Path, key: str
) -> None:
    """``tau=1e308`` (and the other tolerances and radii compared with float32 maps) printed
    NumPy's "RuntimeWarning: overflow encountered in cast" after every matcher had run: it is
    float32's infinity, as the cast read it, without a word, and gives the map of float32's
    largest value (every difference within it)."""
    import warnings

    scene = load_scene(data_dir / "middlebury2003" / "cones")
    left, right = scene.left[:96, :160], scene.right[:96, :160]
    top = float(np.finfo(np.float32).max)
    want = sv_depth_map(left, right, max_disparity=32, **{key: top})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for huge in (1e308, 10**300):
            got = sv_depth_map(left, right, max_disparity=32, **{key: huge})
            np.testing.assert_array_equal(got.disparity, want.disparity)
            np.testing.assert_array_equal(got.confidence, want.confidence)


def test_radius_offsets_are_nearest_first_in_a_fixed_order() -> None:
    """D.2's "nearest": equal distances are visited up before down, left before right
    (``(dy, dx)`` ascending), so a candidate between two sparse values takes the one above."""
    assert _radius_offsets(1.5) == [
        (0, 0),
        (-1, 0),
        (0, -1),
        (0, 1),
        (1, 0),
        (-1, -1),
        (-1, 1),
        (1, -1),
        (1, 1),
    ]
    # MCGM measured above and below the Hopfield point, at the same distance: the one above
    # (7.5) is MCGM's value there, and the member the mean with Hopfield's 7.0.
    mcgm = _m([(10, 9, 7.5), (10, 11, 6.5)])
    hop = _m([(10, 10, 7.0)])
    res = fuse(None, {"mcgm": mcgm, "hopfield": hop}, tau_dx=0.6)
    assert res.dispx[10, 10] == pytest.approx(7.25)


def test_a_map_that_is_not_two_dimensional_is_named() -> None:
    """A Gabor map of shape (H, W, 1) (a colour axis left on) is refused by name, not read."""
    d, c = _dense(10.0)
    with pytest.raises(ValueError, match=r"^gabor dispx: expected an \(H, W\) map, got shape"):
        fuse((d[..., None], c), {"hopfield": _m([(5, 5, 10.0)])})
    with pytest.raises(ValueError, match=r"^members: expected an \(H, W\) map, got shape"):
        fused_dense(d, c, d[None])


def test_equal_spreads_keep_the_first_pair_in_bit_order() -> None:
    """Two agreeing pairs with the same x spread (Gabor 10 with MCGM 10.75 or Hopfield 9.25;
    MCGM and Hopfield 1.5 apart): the first in bit order (Gabor + MCGM) is the member."""
    res = fuse(_dense(10.0), {"mcgm": _m([(4, 4, 10.75)]), "hopfield": _m([(4, 4, 9.25)])})
    assert list(res.sources) == [1 | 2] and list(res.count) == [2]
    assert res.dispx[4, 4] == pytest.approx(10.375)


def test_count_map_holds_the_count_and_sources_map_the_bits() -> None:
    """The rasters carry each member's own values: 3 agreeing channels (bits 7) at (3, 3), 2
    (Gabor + MCGM, bits 3) at (9, 3), 0 off the members."""
    mcgm = _m([(3, 3, 10.0), (9, 3, 10.0)])
    hop = _m([(3, 3, 10.4), (9, 3, 14.0)])
    res = fuse(_dense(10.2), {"mcgm": mcgm, "hopfield": hop})
    assert res.count_map[3, 3] == 3 and res.count_map[3, 9] == 2
    assert res.sources_map[3, 3] == 7 and res.sources_map[3, 9] == 3
    assert np.count_nonzero(res.count_map) == np.count_nonzero(res.sources_map) == 2


def test_fuse_pair_times_each_channel_and_the_fusion() -> None:
    """``stats["seconds"]`` names every matcher that ran (the census one for the census check)
    and the fusion itself, each a positive time; the census map is kept only with
    ``dense_sgm``."""
    rng = np.random.default_rng(5)
    right = rng.random((48, 80)).astype(np.float32)
    left = np.roll(right, 4, axis=1)  # disparity 4
    res = fuse_pair(left, right, max_disparity=8)
    seconds = res.matches.stats["seconds"]
    assert set(seconds) == {"gabor", "mcgm", "hopfield", "sgm", "fuse"}
    assert all(isinstance(s, float) and s > 0 for s in seconds.values())
    assert "sgm" not in res.channel_outputs
    res = fuse_pair(left, right, max_disparity=8, channels=("gabor", "mcgm"), dense_sgm=True)
    assert set(res.matches.stats["seconds"]) == {"gabor", "mcgm", "sgm", "fuse"}
    assert res.channel_outputs["sgm"].shape == (48, 80)
    res = fuse_pair(left, right, max_disparity=8, census_members=False)
    assert set(res.matches.stats["seconds"]) == {"gabor", "mcgm", "hopfield", "fuse"}


def test_fuse_pair_runs_mcgm_and_the_member_check_with_member_mcgm(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """MCGM votes with MEMBER_MCGM's stricter settings (GHT score 0.5, 4 px half-windows, MAD
    0.04), not its own defaults, and the members' both-sides check uses the same sides."""
    import stereovision.matching.mcgm as mcgm

    seen: dict[str, dict[str, Any]] = {}

    def spy(name: str, fn: Any) -> Any:
        def call(*args: Any, **kw: Any) -> Any:
            seen[name] = kw
            return fn(*args, **kw)

        return call

    monkeypatch.setattr(mcgm, "mcgm_match", spy("mcgm", mcgm.mcgm_match))
    monkeypatch.setattr(mcgm, "edge_filters", spy("sides", mcgm.edge_filters))
    rng = np.random.default_rng(5)
    right = rng.random((48, 80)).astype(np.float32)
    fuse_pair(np.roll(right, 4, axis=1), right, max_disparity=8, census_members=False)
    assert {k: seen["mcgm"][k] for k in ("ght_min_score", "sides_mad", "sides_width")} == {
        "ght_min_score": 0.5,
        "sides_mad": 0.04,
        "sides_width": 4,
    }
    assert (seen["sides"]["sides_mad"], seen["sides"]["sides_width"]) == (0.04, 4)


@pytest.mark.parametrize("jump", [-0.5, -1e-3])
def test_census_clear_refuses_a_negative_jump(jump: float) -> None:
    """``jump`` is a distance below the member's disparity: a negative one is refused by name
    (it would drop members the census map agrees with)."""
    res = fuse(_dense(10.0), {"hopfield": _m([(5, 5, 10.0)])})
    with pytest.raises(ValueError, match=r"^jump must be >= 0, got -"):
        census_clear(res, np.full((H, W), 10.0, np.float32), jump=jump)
    assert len(census_clear(res, np.full((H, W), 10.0, np.float32), jump=0.0)) == 1


@pytest.mark.parametrize("jump", ["1.5", None, True, np.nan])
def test_census_clear_names_a_jump_that_is_no_number(jump: object) -> None:
    """A string or None failed in the comparison as Python's "'>=' not supported between
    instances of 'str' and 'int'", naming nothing; True was a jump of 1 px. A size-1 array is
    its number."""
    res = fuse(_dense(10.0), {"hopfield": _m([(5, 5, 10.0)])})
    census = np.full((H, W), 10.0, np.float32)
    with pytest.raises(ValueError, match=r"^jump must be >= 0, got "):
        census_clear(res, census, jump=jump)  # type: ignore[arg-type]
    assert len(census_clear(res, census, jump=np.array([1.5]))) == 1  # type: ignore[arg-type]


@pytest.mark.parametrize("radius", [np.array([7]), Fraction(7), np.float32(7.0)])
def test_census_clear_reads_a_whole_radius_as_its_count(radius: object) -> None:
    """radius was read by int(): np.array([7]) was NumPy's bare 'only 0-dimensional arrays can
    be converted to Python scalars' and Fraction(7) 'radius: expected a finite number', where
    jump (e43cafe1) and the library's counts take them. Each is the radius 7."""
    res = fuse(_dense(10.0), {"hopfield": _m([(5, 5, 10.0), (20, 5, 10.0)])})
    census = np.full((H, W), 10.0, np.float32)
    census[5, 12] = 5.0  # a lower census value 7 px from the first member, 8 from the second
    want = census_clear(res, census, radius=7)
    assert len(want) == 1
    got = census_clear(res, census, radius=radius)  # type: ignore[arg-type]
    np.testing.assert_array_equal(got.matches.xl, want.matches.xl)
    with pytest.raises(ValueError, match=r"^radius must be a non-negative integer, got 7.5"):
        census_clear(res, census, radius=7.5)  # type: ignore[arg-type]


def test_fused_dense_edge_step_runs_from_a_one_pixel_radius() -> None:
    """Step 7 runs from ``edge_radius`` 1 (only 0 turns it off): a square drawn 1 px too wide
    on every side loses that 1 px ring, which a 1 px look reaches."""
    h, w = 60, 80
    guide = np.full((h, w), 0.2, np.float32)
    guide[20:40, 30:50] = 0.8
    guide += np.random.default_rng(1).normal(0, 0.01, (h, w)).astype(np.float32)
    d = np.full((h, w), 10.0, np.float32)
    d[20:40, 29:51] = 20.0
    d[19:41, 30:50] = 20.0
    conf = np.full(d.shape, 0.8, np.float32)
    none = np.full(d.shape, np.nan, np.float32)
    out, c = fused_dense(d, conf, none, guide=guide, speckle_area=0.0, edge_radius=1)
    truth = np.full((h, w), 10.0, np.float32)
    truth[20:40, 30:50] = 20.0
    fat = d != truth
    assert np.count_nonzero(fat) == 80
    assert np.isnan(out[fat]).all() and (c[fat] == 0).all()
    np.testing.assert_array_equal(out[~fat], d[~fat])


@pytest.mark.parametrize("name", ["edge_ratio", "edge_jump"])
def test_an_edge_option_just_past_float32_is_named(name: str) -> None:
    """The bound is float32's largest value, not a larger one: 1e39 (finite in float64,
    infinite in float32) is refused by name as 1e308 is."""
    d, c = _dense(5.0, 0.5)
    members = np.full((H, W), np.nan, np.float32)
    guide = np.random.default_rng(0).random((H, W)).astype(np.float32)
    with pytest.raises(ValueError, match=f"^{name}: expected at most 3.40282e\\+38 \\(float32\\)"):
        fused_dense(d, c, members, guide=guide, **{name: 1e39})


def test_the_default_tables_are_the_functions_defaults() -> None:
    """DEFAULTS and DENSE_DEFAULTS (what depth_map checks and documents) are exactly the
    defaults fuse and fused_dense run with."""
    import inspect

    from stereovision.matching.fusion import DEFAULTS, DENSE_DEFAULTS

    for fn, table in ((fuse, DEFAULTS), (fused_dense, DENSE_DEFAULTS)):
        params = inspect.signature(fn).parameters
        assert {k: params[k].default for k in table} == table
    assert (DENSE_DEFAULTS["tau"], DENSE_DEFAULTS["fill_radius"]) == (2.0, 3.0)


@pytest.mark.parametrize("side", ["top", "bottom", "left", "right"])
def test_enclosed_far_leaves_a_region_open_to_each_border(side: str) -> None:
    """A dark floor region touching any one of the four borders is open (kept as it is); the
    same region moved 5 px inward is enclosed (filled with the surround's 6)."""
    h, w = 40, 50
    rows, cols = {
        "top": (slice(0, 10), slice(20, 30)),
        "bottom": (slice(30, 40), slice(20, 30)),
        "left": (slice(15, 25), slice(0, 10)),
        "right": (slice(15, 25), slice(40, 50)),
    }[side]
    d = np.full((h, w), 6.0, np.float32)
    g = np.full((h, w), 0.6, np.float32)
    d[rows, cols], g[rows, cols] = 0.0, 0.1
    out, filled = fill_enclosed_far(d, g)
    assert not filled.any() and np.array_equal(out, d)
    shift = {"top": (5, 0), "bottom": (-5, 0), "left": (0, 5), "right": (0, -5)}[side]
    d2 = np.roll(d, shift, axis=(0, 1))
    g2 = np.roll(g, shift, axis=(0, 1))
    out, filled = fill_enclosed_far(d2, g2)
    assert filled.sum() == 100 and np.all(out == 6.0)


def test_enclosed_far_joins_regions_touching_at_a_corner() -> None:
    """Regions are 8-connected: a dark floor block that meets a border-touching one only at a
    corner is part of it, so open to the border too (neither is filled)."""
    d = np.full((40, 50), 6.0, np.float32)
    g = np.full((40, 50), 0.6, np.float32)
    d[0:10, 10:20], g[0:10, 10:20] = 0.0, 0.1  # open to the top
    d[10:20, 20:30], g[10:20, 20:30] = 0.0, 0.1  # meets it at (9, 19) / (10, 20) only
    out, filled = fill_enclosed_far(d, g)
    assert not filled.any() and np.array_equal(out, d)


def test_enclosed_far_default_far_is_half_a_pixel() -> None:
    """By default a region is locked to the floor below 0.5 px: a dark pane at 0.45 is filled,
    one at 0.55 is not."""
    d = np.full((60, 80), 6.0, np.float32)
    g = np.full((60, 80), 0.6, np.float32)
    g[20:30, 10:25] = 0.1
    for value, fills in ((0.45, True), (0.55, False)):
        d[20:30, 10:25] = value
        out, filled = fill_enclosed_far(d, g)
        assert filled.any() == fills
        assert np.all(out[20:30, 10:25] == (6.0 if fills else np.float32(value)))


def test_census_clear_window_past_the_shorter_side_reaches_as_far_as_asked() -> None:
    """On a 20 x 30 map a 25 px window is wider than the map is tall but still ends 25 px
    along the row: a census value 23 px to the right, 10 below the member, drops it at radius
    25 and not at 22."""
    res = fuse(_dense(20.0), {"hopfield": _m([(2, 10, 20.0)])})
    census = np.full((H, W), 20.0, np.float32)
    census[10, 25] = 10.0
    assert len(census_clear(res, census, radius=25)) == 0
    assert len(census_clear(res, census, radius=22)) == 1


def test_fuse_pair_refuses_channels_given_as_bytes() -> None:
    """``b"gabor,mcgm"`` is one string of bytes, not channel names: refused as such before
    the channels run, not read byte by byte as the unknown channels 103, 97, ..."""
    img = np.zeros((20, 30), np.float32)
    with pytest.raises(ValueError, match=r"^channels: expected a tuple of channel names, got b"):
        fuse_pair(img, img, max_disparity=8, channels=b"gabor,mcgm")  # type: ignore[arg-type]
