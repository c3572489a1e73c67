"""Tests of stereovision.evaluate on hand-made arrays with hand-computed answers, and on real
scenes against the reference figures of evaluation.md."""

from __future__ import annotations

import itertools
import json
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from stereovision.baselines import opencv_sgbm
from stereovision.calibration import Calibration
from stereovision.evaluate import (
    count_at_precision,
    dense_metrics,
    depth_metrics,
    gt_depth,
    saturated_gt_depth,
    sparse_metrics,
    table1_report,
)
from stereovision.io import load_scene

NAN = np.nan
INF = np.inf


# ---------------------------------------------------------------------------------------- dense


def test_dense_metrics_hand_computed() -> None:
    gt = np.array([[10.0, 10.0, 10.0, 10.0], [10.0, INF, NAN, 10.0]])
    disp = np.array([[10.2, 10.8, 11.5, 13.0], [NAN, 5.0, 5.0, 0.0]])
    # known GT: 6 pixels; estimates there: errors 0.2, 0.8, 1.5, 3.0, (hole), 10.0
    m = dense_metrics(disp, gt)
    assert m.n_gt == 6 and m.n_both == 5
    assert m.density == pytest.approx(100 * 5 / 6)
    # bad-t counts the hole: errors > t or missing
    assert m.bad[0.5] == pytest.approx(100 * 5 / 6)  # 0.8, 1.5, 3, 10, hole
    assert m.bad[1.0] == pytest.approx(100 * 4 / 6)  # 1.5, 3, 10, hole
    assert m.bad[2.0] == pytest.approx(100 * 3 / 6)  # 3, 10, hole
    assert m.bad[4.0] == pytest.approx(100 * 2 / 6)  # 10, hole
    errs = np.array([0.2, 0.8, 1.5, 3.0, 10.0])
    assert m.avgerr == pytest.approx(errs.mean())
    assert m.rms == pytest.approx(math.sqrt(np.mean(errs**2)))
    d = m.as_dict()
    assert d["bad_2.0"] == m.bad[2.0] and d["density"] == m.density and d["n_gt"] == 6
    assert set(d) == {"bad_0.5", "bad_1.0", "bad_2.0", "bad_4.0", "density", "avgerr", "rms"} | {
        "n_gt",
        "n_both",
    }


def test_dense_metrics_boundary_and_mask() -> None:
    gt = np.array([[4.0, 4.0]])
    # exactly t is not bad (bad means "more than t")
    assert dense_metrics(np.array([[6.0, 5.0]]), gt).bad[2.0] == 0.0
    m = dense_metrics(np.array([[6.0, NAN]]), gt, mask=np.array([[True, False]]))
    assert m.n_gt == 1 and m.density == 100.0 and m.bad[1.0] == 100.0


def test_dense_metrics_empty_and_errors() -> None:
    m = dense_metrics(np.full((2, 2), NAN), np.full((2, 2), NAN))
    assert m.n_gt == 0 and math.isnan(m.bad[2.0]) and math.isnan(m.avgerr)
    m = dense_metrics(np.full((2, 2), NAN), np.ones((2, 2)))
    assert m.bad[0.5] == 100.0 and m.density == 0.0 and math.isnan(m.rms)
    with pytest.raises(ValueError, match=r"same shape.*\(2, 2\).*\(2, 3\)"):
        dense_metrics(np.ones((2, 2)), np.ones((2, 3)))
    with pytest.raises(ValueError, match=r"^disparity: expected a real \(H, W\) array"):
        dense_metrics(np.ones(4), np.ones(4))
    with pytest.raises(ValueError, match="thresholds"):
        dense_metrics(np.ones((2, 2)), np.ones((2, 2)), thresholds=(0.0,))


# ---------------------------------------------------------------------------------------- depth


def test_depth_metrics_hand_computed() -> None:
    gt = np.array([[10.0, 10.0, 20.0, 20.0], [NAN, 5.0, -1.0, 0.0]])
    est = np.array([[10.1, 11.0, 19.0, 20.0], [3.0, NAN, 5.0, 5.0]])
    # both valid: (10.1|10) (11|10) (19|20) (20|20); rel errs 1 %, 10 %, 5 %, 0 %
    m = depth_metrics(est, gt)
    assert m.n == 4
    assert m.density == pytest.approx(50.0)
    assert m.median_rel == pytest.approx(3.0)  # median of 0, 1, 5, 10
    assert m.share_off_5 == pytest.approx(25.0)  # only 10 % (5 % is not "more than")
    diff = np.array([0.1, 1.0, -1.0, 0.0])
    rmse = math.sqrt(np.mean(diff**2))
    assert m.rmse == pytest.approx(rmse)
    assert m.rmse_pct == pytest.approx(100 * rmse / 15.0)
    assert m.as_dict()["n"] == 4


def test_depth_metrics_no_overlap() -> None:
    m = depth_metrics(np.full((2, 2), NAN), np.ones((2, 2)))
    assert m.n == 0 and math.isnan(m.median_rel)
    with pytest.raises(ValueError, match="depth and gt"):
        depth_metrics(np.ones((2, 2)), np.ones((3, 2)))


def test_figures_beyond_float64_are_inf_without_numpy_warnings() -> None:
    """float64 maps of 1e300 overflowed the squares (and 1e300 / 1e-10 the relative error):
    NumPy's "overflow encountered in square" RuntimeWarning out of dense_metrics,
    depth_metrics and table1_report (an error under -W error). The figures are inf, as before."""
    big, one = np.full((2, 2), 1e300), np.ones((2, 2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dense = dense_metrics(big, -big)
        depth = depth_metrics(big, np.full((2, 2), 1e-10))
        rep = table1_report(big, one, n_points=3)
    assert (dense.avgerr, dense.rms, dense.bad[2.0]) == (2e300, INF, 100.0)
    assert (depth.median_rel, depth.rmse, depth.rmse_pct, depth.n) == (INF, INF, INF, 4)
    assert (rep.rmse, rep.mean_error, rep.mean_distance) == (INF, 1e300 - 1, 1.0)


def _rect_calib(f: float = 500.0, b_mm: float = 100.0, doffs: float = 0.0) -> Calibration:
    K1 = np.array([[f, 0, 100.0], [0, f, 50.0], [0, 0, 1]])
    K2 = K1.copy()
    K2[0, 2] += doffs
    return Calibration(
        K1=K1,
        D1=np.zeros(5),
        K2=K2,
        D2=np.zeros(5),
        R=np.eye(3),
        T=np.array([-b_mm, 0, 0]),
        image_size=(200, 100),
        unit="mm",
        rectified=True,
        doffs=doffs,
    )


def test_gt_depth_metres() -> None:
    cal = _rect_calib(f=500.0, b_mm=100.0, doffs=10.0)
    z = gt_depth(np.array([[40.0, NAN, -10.0, -20.0, 90.0]]), cal)
    # Z = f B / (d + doffs) = 500 * 0.1 m / 50 = 1 m ; d <= -doffs -> NaN
    np.testing.assert_allclose(z[0, [0, 4]], [1.0, 0.5], rtol=1e-7)
    assert np.isnan(z[0, 1:4]).all()
    assert z.dtype == np.float32


def test_saturated_gt_depth_is_float16s_largest_value_through_the_disparity() -> None:
    """TartanAir's sky: GT depth 65504 m (float16's largest) stored as a disparity of
    f B / 65504 px reads back as 65503.996 m in float32; that is saturated, a depth a metre
    nearer (or 65 km in mm) and unknown pixels are not."""
    cal = _rect_calib(f=320.0, b_mm=250.0, doffs=0.0)
    d = np.float32(80.0 / 65504.0)  # 0.0012213 px, as the scene's gt_disp.pfm holds it
    z = gt_depth(np.array([[d, 80.0 / 65503.0, 80.0 / 65.504, NAN, INF, 8.0]]), cal)
    assert float(z[0, 0]) != 65504.0  # the round trip moved it
    assert saturated_gt_depth(z).tolist() == [[True, False, False, False, False, False]]


# -------------------------------------------------------------------------------------- Table 1


def test_table1_given_points_hand_computed() -> None:
    est = np.array([[2.0, 3.1, 9.0], [4.0, 5.0, NAN]])
    gt = np.array([[2.1, 3.0, 9.0], [4.0, 5.0, 1.0]])
    r = table1_report(est, gt, points=np.array([[0, 0], [1, 0], [0, 1]]))
    np.testing.assert_array_equal(r.x, [0, 1, 0])
    np.testing.assert_array_equal(r.y, [0, 0, 1])
    np.testing.assert_allclose(r.estimated, [2.0, 3.1, 4.0])
    err = np.array([-0.1, 0.1, 0.0])
    assert r.mean_error == pytest.approx(0.0, abs=1e-12)
    assert r.mean_abs_error == pytest.approx(0.2 / 3)
    assert r.rmse == pytest.approx(math.sqrt(np.mean(err**2)))
    assert r.mean_distance == pytest.approx(3.0333333333)
    assert r.rmse_pct == pytest.approx(100 * r.rmse / (9.1 / 3))
    d = r.as_dict()
    json.dumps(d)  # JSON-ready
    assert d["rmse_ft"] == pytest.approx(r.rmse / 0.3048)
    # every figure format() prints in feet is in the dict too
    assert d["mean_abs_error_ft"] == pytest.approx(r.mean_abs_error / 0.3048)
    assert d["points"][1]["error_ft"] == pytest.approx(0.1 / 0.3048)
    assert d["points"][1] == {
        "x": 1,
        "y": 0,
        "estimated_m": 3.1,
        "ground_truth_m": 3.0,
        "error_m": pytest.approx(0.1),
        "estimated_ft": pytest.approx(3.1 / 0.3048),
        "ground_truth_ft": pytest.approx(3.0 / 0.3048),
        "error_ft": pytest.approx(0.1 / 0.3048),
    }
    text = r.format()
    assert "RMSE: 0.082 m (0.268 ft)" in text  # sqrt(0.02/3) = 0.0816 m = 0.2679 ft
    assert "est ft" in text and len(text.splitlines()) == 3 + 3 + 4


def test_table1_units_and_random_draw() -> None:
    rng = np.random.default_rng(5)
    gt = rng.uniform(1000, 3000, (20, 30))  # millimetres
    est = gt * 1.02
    est[::2] = NAN
    r = table1_report(est, gt, n_points=7, seed=3, unit="mm")
    assert r.n_points == 7
    assert (r.y % 2 == 1).all()  # only pixels where both exist
    assert len(set(zip(r.x.tolist(), r.y.tolist(), strict=True))) == 7
    np.testing.assert_allclose(r.estimated, gt[r.y, r.x] * 1.02e-3)
    assert r.rmse_pct == pytest.approx(
        100 * math.sqrt(np.mean((0.02 * r.ground_truth) ** 2)) / r.ground_truth.mean()
    )
    again = table1_report(est, gt, n_points=7, seed=3, unit="mm")
    np.testing.assert_array_equal(again.x, r.x)  # seeded
    assert table1_report(est, gt, n_points=10_000, unit="mm").n_points == 300


def test_table1_errors() -> None:
    ones = np.ones((3, 3))
    with pytest.raises(ValueError, match="no pixel"):
        table1_report(np.full((3, 3), NAN), ones)
    with pytest.raises(ValueError, match="outside"):
        table1_report(ones, ones, points=np.array([[3, 0]]))
    with pytest.raises(ValueError, match="lack"):
        table1_report(np.where(np.eye(3) > 0, NAN, 1.0), ones, points=np.array([[1, 1]]))
    with pytest.raises(ValueError, match="unit"):
        table1_report(ones, ones, unit="parsec")
    with pytest.raises(ValueError, match="n_points"):
        table1_report(ones, ones, n_points=0)


# --------------------------------------------------------------------------------------- sparse


def test_sparse_metrics_hand_computed() -> None:
    gt = np.full((8, 8), NAN)
    gt[0, 0] = 3.0
    gt[0, 7] = 3.0
    gt[7, 7] = 3.0
    gt[4, 4] = 2.0
    xl = np.array([0.2, 6.6, 7.0, 4.0, 3.0, 20.0])
    yl = np.array([0.4, 0.0, 7.0, 4.0, 3.0, 1.0])
    xr = np.array([-2.6, 3.0, 2.0, 1.0, 0.0, 0.0])
    # match 0: rounds to (0,0), dx=2.8 -> err 0.2 ; match 1: (7,0) dx=3.6 -> err 0.6
    # match 2: (7,7) dx=5 -> err 2 ; match 3: (4,4) dx=3 -> err 1 ; 4: no GT ; 5: outside
    m = sparse_metrics(xl, yl, xr, gt)
    assert m.count == 4 and m.n_matches == 6
    assert m.precision[0.5] == pytest.approx(25.0)
    assert m.precision[1.0] == pytest.approx(75.0)
    assert m.precision[2.0] == pytest.approx(100.0)
    assert m.coverage == 4  # cells (0,0), (0,3), (3,3), (2,2) of the 4x4 grid
    assert m.as_dict()["precision@1.0"] == pytest.approx(75.0)


def test_sparse_metrics_errors_and_empty() -> None:
    m = sparse_metrics([], [], [], np.ones((4, 4)))
    assert m.count == 0 and math.isnan(m.precision[1.0]) and m.coverage == 0
    with pytest.raises(ValueError, match="equal length"):
        sparse_metrics([1.0], [1.0, 2.0], [0.0], np.ones((4, 4)))


# ---------------------------------------------------------------------------------- real scenes


def test_sgbm_tsukuba_dense_reference(data_dir: Path) -> None:
    """evaluation.md: SGBM-3WAY on tsukuba, bad-2 5.3 %, density 98 %."""
    s = load_scene(data_dir / "middlebury2001" / "tsukuba")
    assert s.gt is not None
    m = dense_metrics(opencv_sgbm(s.left, s.right, s.max_disparity), s.gt)
    assert m.bad[2.0] == pytest.approx(5.3, abs=0.5)
    assert m.density == pytest.approx(98.0, abs=0.5)
    assert m.n_gt == 288 * 384 - 22896


def test_sgbm_terrace_depth_reference(data_dir: Path) -> None:
    """evaluation.md "Metric depth": terrace 2.18 % / 17.5 % / 6.1 % / density 50 %."""
    s = load_scene(data_dir / "eth3d" / "terrace")
    assert s.gt is not None and s.calib is not None
    disp = opencv_sgbm(s.left, s.right, s.max_disparity)
    m = depth_metrics(s.calib.depth_from_disparity(disp), gt_depth(s.gt, s.calib))
    assert m.median_rel == pytest.approx(2.18, abs=0.05)
    assert m.share_off_5 == pytest.approx(17.5, abs=0.3)
    assert m.rmse_pct == pytest.approx(6.1, abs=0.3)
    assert m.density == pytest.approx(50.0, abs=1.0)
    # terrace: Z = 711.499 px * 0.0599432 m / d -> a few metres
    r = table1_report(s.calib.depth_from_disparity(disp), gt_depth(s.gt, s.calib), n_points=5)
    assert 1.0 < r.mean_distance < 20.0


def test_count_at_precision_hand_computed() -> None:
    gt = np.full((4, 6), np.nan)
    gt[1, :] = 5.0
    # Scores rank: a (right), b (wrong by 3), c (right), d (no GT), e (right).
    xl = np.array([1, 2, 3, 4, 5], float)
    yl = np.array([1, 1, 1, 3, 1], float)
    xr = xl - np.array([5.0, 8.0, 5.4, 5.0, 4.2])
    score = np.array([0.9, 0.8, 0.7, 0.95, 0.1])
    # Prefix precisions over matches with GT: a 100, a b 50, a b c 66.7, a b c e 75.
    assert count_at_precision(xl, yl, xr, score, gt, 100.0) == 1
    assert count_at_precision(xl, yl, xr, score, gt, 70.0) == 4
    assert count_at_precision(xl, yl, xr, score, gt, 60.0) == 4
    assert count_at_precision(xl, yl, xr, score, gt, 76.0) == 1
    # A looser tolerance counts b as right: all four at 100 %.
    assert count_at_precision(xl, yl, xr, score, gt, 100.0, tolerance=3.0) == 4
    assert count_at_precision(xl[:0], yl[:0], xr[:0], score[:0], gt, 50.0) == 0
    with pytest.raises(ValueError, match="equal length"):
        count_at_precision(xl, yl, xr, score[:2], gt, 50.0)


def test_dense_metrics_keys_keep_every_threshold() -> None:
    """as_dict named thresholds with one decimal: 0.25 came out as ``bad_0.2``, and with 0.2
    beside it one of the two figures was lost under the shared key."""
    m = dense_metrics(np.array([[1.0, 1.22]]), np.ones((1, 2)), thresholds=(0.2, 0.25, 2.0))
    d = m.as_dict()
    assert [k for k in d if k.startswith("bad_")] == ["bad_0.2", "bad_0.25", "bad_2.0"]
    assert (d["bad_0.2"], d["bad_0.25"], d["bad_2.0"]) == (50.0, 0.0, 0.0)
    # the default keys (tracked figures) are unchanged
    assert [k for k in dense_metrics(np.ones((1, 1)), np.ones((1, 1))).as_dict()][:4] == [
        "bad_0.5", "bad_1.0", "bad_2.0", "bad_4.0"
    ]  # fmt: skip


def test_dense_metrics_takes_disparity_and_still_disp() -> None:
    """Its estimate was ``disp`` where the rest of the API says ``disparity``: ``disparity=`` now,
    ``disp=`` still works with a DeprecationWarning at the caller's line."""
    import inspect
    import warnings

    est, gt = np.array([[1.0, NAN, 5.0]]), np.array([[1.5, 2.0, 2.0]])
    assert list(inspect.signature(dense_metrics).parameters)[:2] == ["disparity", "gt"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        new = dense_metrics(disparity=est, gt=gt)
    with pytest.warns(DeprecationWarning) as caught:
        old = dense_metrics(disp=est, gt=gt)
    assert old == new and new.bad[1.0] == pytest.approx(200 / 3)
    assert str(caught[0].message) == (
        "dense_metrics(): the keyword disp= is now disparity= (disp= will be removed)"
    )
    assert caught[0].filename == __file__


@pytest.mark.parametrize(
    ("key", "value", "says"),
    [
        ("n_points", float("nan"), "n_points must be an integer >= 1, got nan"),
        ("n_points", 2.5, "n_points must be an integer >= 1, got 2.5"),
        ("n_points", True, "n_points must be an integer >= 1, got True"),
        ("n_points", "3", "n_points must be an integer >= 1, got '3'"),
        ("seed", -5, "seed must be an integer >= 0 or None, got -5"),
        ("seed", -1, "seed must be an integer >= 0 or None, got -1"),
        ("seed", float("nan"), "seed must be an integer >= 0 or None, got nan"),
        ("seed", "0", "seed must be an integer >= 0 or None, got '0'"),
    ],
)
def test_table1_report_names_a_bad_count_or_seed(key: str, value: object, says: str) -> None:
    # NumPy's messages named neither ("negative dimensions are not allowed", "expected
    # non-negative integer"), and 2.5 or True points were drawn
    est = np.full((20, 30), 2.0, np.float32)
    gt = np.full((20, 30), 2.5, np.float32)
    assert table1_report(est, gt, n_points=4, seed=np.int64(1)).n_points == 4
    with pytest.raises(ValueError, match="^" + re.escape(says)):
        table1_report(est, gt, **{key: value})  # type: ignore[arg-type]


def test_table1_report_seed_none_is_a_fresh_draw() -> None:
    # numpy.random.default_rng(None), the draw's documented generator, takes None for fresh
    # entropy, and table1_report did until the seed check above refused it as not an integer
    est = np.full((20, 30), 2.0, np.float32)
    gt = np.full((20, 30), 2.5, np.float32)
    r = table1_report(est, gt, n_points=4, seed=None)
    assert r.n_points == 4 and np.all((r.x >= 0) & (r.x < 30)) and np.all((r.y >= 0) & (r.y < 20))


@pytest.mark.parametrize(
    ("key", "value", "says"),
    [
        ("target", float("nan"), "target: expected a precision in percent, 0 to 100, got nan"),
        ("target", 101.0, "target: expected a precision in percent, 0 to 100, got 101.0"),
        ("target", -1.0, "target: expected a precision in percent, 0 to 100, got -1.0"),
        ("target", True, "target: expected a precision in percent, 0 to 100, got True"),
        ("tolerance", 0.0, "tolerance: expected a positive finite number of pixels, got 0.0"),
        (
            "tolerance",
            float("nan"),
            "tolerance: expected a positive finite number of pixels, got nan",
        ),
        ("tolerance", "1", "tolerance: expected a positive finite number of pixels, got '1'"),
        (
            "tolerance",
            10**400,
            "tolerance: expected a positive finite number of pixels, got an integer of 401 digits",
        ),
    ],
)
def test_count_at_precision_names_a_bad_target_or_tolerance(
    key: str, value: object, says: str
) -> None:
    # NaN or 101 % counted 0 matches, -1 % all of them, a tolerance of 0 or NaN none, without a word
    gt = np.full((4, 6), 5.0)
    xl = np.array([1.0, 2.0, 3.0])
    yl = np.ones(3)
    xr = xl - np.array([5.0, 8.0, 5.0])
    score = np.array([0.9, 0.8, 0.7])
    assert count_at_precision(xl, yl, xr, score, gt, 50.0, np.float32(1.0)) == 3
    kw: dict[str, object] = {"target": 50.0, "tolerance": 1.0, key: value}
    with pytest.raises(ValueError, match="^" + re.escape(says)):
        count_at_precision(xl, yl, xr, score, gt, **kw)  # type: ignore[arg-type]


def test_dense_metrics_thresholds_may_be_any_collection_of_numbers() -> None:
    # a range and a set were read until the check above took only a tuple, list or array; a
    # generator was used up by the check and gave no bad-t figure at all
    disp = np.zeros((3, 4), np.float32)
    want = {1.0: 100.0, 2.0: 0.0}
    assert dense_metrics(disp, disp + 1.5, thresholds=range(1, 3)).bad == want
    assert dense_metrics(disp, disp + 1.5, thresholds={2.0, 1.0}).bad == want
    assert dense_metrics(disp, disp + 1.5, thresholds=(t for t in (1.0, 2.0))).bad == want
    with pytest.raises(ValueError, match=r"^thresholds must be positive and finite, got '12'"):
        dense_metrics(disp, disp, thresholds="12")  # type: ignore[arg-type]


@pytest.mark.parametrize("thresholds", [2.0, (True,), ("2",), (2.0, 10**400)])
def test_dense_metrics_thresholds_must_be_a_sequence_of_numbers(thresholds: object) -> None:
    # 2.0 was "'float' object is not iterable", True a 1 px threshold, "2" a TypeError
    disp = np.zeros((3, 4), np.float32)
    assert dense_metrics(disp, disp + 1.5, thresholds=[np.float32(1.0), 2]).bad[2.0] == 0.0
    with pytest.raises(ValueError, match=r"^thresholds must be positive and finite, got ") as err:
        dense_metrics(disp, disp, thresholds=thresholds)  # type: ignore[arg-type]
    if thresholds == (2.0, 10**400):  # its 401 digits were the error's one line
        assert str(err.value) == (
            "thresholds must be positive and finite, got (2.0, an integer of 401 digits "
            "(too large for a float))"
        )


# ------------------------------------------------------------- mutation audit (values the
# tests above did not pin: each of these failed on a one-line bug that every other test passed)


def test_dense_metrics_mask_leaves_out_the_estimates_it_masks() -> None:
    # the masked-out pixel has both a GT and a (wrong) estimate: it must not reach n_both,
    # density, avgerr or rms (an occlusion mask that only trimmed n_gt let it in)
    gt = np.array([[4.0, 4.0, 4.0]])
    disp = np.array([[4.5, 10.0, NAN]])
    m = dense_metrics(disp, gt, mask=np.array([[True, False, True]]))
    assert (m.n_gt, m.n_both) == (2, 1)
    assert m.density == 50.0 and m.avgerr == 0.5 and m.rms == 0.5
    assert m.bad == {0.5: 50.0, 1.0: 50.0, 2.0: 50.0, 4.0: 50.0}


def test_dense_metrics_takes_a_0_255_mask_image() -> None:
    # a mask read from a PNG (Middlebury's nonocc masks are 0/255 uint8) is a mask, as bool
    gt = np.array([[4.0, 4.0, 4.0]])
    disp = np.array([[4.5, 10.0, NAN]])
    want = dense_metrics(disp, gt, mask=np.array([[True, False, True]]))
    got = dense_metrics(disp, gt, mask=np.array([[255, 0, 255]], dtype=np.uint8))
    assert got == want


@pytest.mark.parametrize(
    ("unit", "metres"), [("cm", 2.5), ("in", 250 * 0.0254), ("mm", 0.25), ("ft", 250 * 0.3048)]
)
def test_table1_report_converts_every_unit_to_metres(unit: str, metres: float) -> None:
    est = np.full((2, 2), 250.0)
    gt = np.full((2, 2), 200.0)
    r = table1_report(est, gt, points=np.array([[1, 0]]), unit=unit)
    assert r.estimated[0] == pytest.approx(metres, rel=1e-12)
    assert r.ground_truth[0] == pytest.approx(metres * 0.8, rel=1e-12)
    assert r.as_dict()["rmse_ft"] == pytest.approx(metres * 0.2 / 0.3048, rel=1e-12)


def test_table1_random_points_are_ten_in_row_major_order() -> None:
    h, w = 20, 30
    est = np.full((h, w), 2.0)
    gt = np.full((h, w), 2.5)
    r = table1_report(est, gt, seed=1)
    assert r.n_points == 10  # the documented default
    r = table1_report(est, gt, n_points=50, seed=1)
    flat = r.y * w + r.x
    assert len(set(flat.tolist())) == 50 and np.all(np.diff(flat) > 0)


def test_table1_format_rows_give_feet_of_the_right_column() -> None:
    est = np.array([[3.048, 6.096]])
    gt = np.array([[3.3528, 6.096]])  # 11 ft and 20 ft
    r = table1_report(est, gt, points=np.array([[0, 0], [1, 0]]))
    rows = [line.split() for line in r.format().splitlines()[3:5]]
    # '#', x, y, est m, GT m, err m, est ft, GT ft, err ft
    assert rows[0] == ["1", "0", "0", "3.048", "3.353", "-0.305", "10.000", "11.000", "-1.000"]
    assert rows[1] == ["2", "1", "0", "6.096", "6.096", "+0.000", "20.000", "20.000", "+0.000"]


def test_sparse_coverage_of_a_wide_image_uses_columns_for_x() -> None:
    gt = np.ones((4, 40))
    xl = np.array([5.0, 15.0, 25.0, 35.0])
    m = sparse_metrics(xl, np.zeros(4), xl - 1.0, gt)
    assert m.coverage == 4 and m.count == 4 and m.precision[0.5] == 100.0
    m = sparse_metrics(np.array([5.0, 5.0]), np.array([0.0, 3.0]), np.array([4.0, 4.0]), gt)
    assert m.coverage == 2


def test_sparse_metrics_leaves_out_missing_and_off_image_matches() -> None:
    gt = np.ones((4, 6))
    # a match with no right column (NaN), and one whose row rounds to 4, past the last row
    xl = np.array([2.0, 3.0, 2.0])
    yl = np.array([1.0, 1.0, 3.6])
    xr = np.array([1.0, NAN, 1.0])
    m = sparse_metrics(xl, yl, xr, gt)
    assert (m.count, m.n_matches) == (1, 3)
    assert m.precision == {0.5: 100.0, 1.0: 100.0, 2.0: 100.0}
    # the same rule in count_at_precision
    assert count_at_precision(xl, yl, xr, np.ones(3), gt, 100.0) == 1


def test_count_at_precision_keeps_the_given_order_among_equal_scores() -> None:
    # quantised scores tie; the ranking is stable (the docstring's promise), so equal scores
    # stay in the caller's order: the first 300 of the best-scored group are right, the rest
    # wrong, and 100 % precision keeps exactly those 300 (an unstable sort mixed them)
    n = 2000
    score = np.random.default_rng(0).integers(0, 3, n).astype(np.float64)
    best = np.flatnonzero(score == 2.0)
    good = np.zeros(n, dtype=bool)
    good[best[:300]] = True
    xr = np.where(good, -1.0, -5.0)  # GT disparity 1 at (0, 0): error 0 or 4 px
    zeros = np.zeros(n)
    assert count_at_precision(zeros, zeros, xr, score, np.ones((1, 1)), 100.0) == 300
    # 75 %: by hand over the same order (best score first, then the given order)
    order = sorted(range(n), key=lambda i: (-score[i], i))
    hits = list(itertools.accumulate(int(good[i]) for i in order))
    want = max(k for k in range(1, n + 1) if 100.0 * hits[k - 1] / k >= 75.0)
    assert count_at_precision(zeros, zeros, xr, score, np.ones((1, 1)), 75.0) == want


# ------------------------------------------- mutation audit, second round (each failed on a
# one-line bug in evaluate.py that every test above passed)


def test_dense_metrics_counts_an_infinite_estimate_as_a_hole() -> None:
    # the module's rule: an estimate is missing when not finite; an inf read as an estimate
    # raised the density and made avgerr and rms inf
    gt = np.array([[4.0, 4.0, 4.0]])
    m = dense_metrics(np.array([[4.5, INF, -INF]]), gt)
    assert (m.n_gt, m.n_both) == (3, 1)
    assert m.density == pytest.approx(100 / 3)
    assert (m.avgerr, m.rms) == (0.5, 0.5)
    assert m.bad[2.0] == pytest.approx(200 / 3)


def test_dense_metrics_refuses_bytes_for_thresholds() -> None:
    # b"12" iterates as the integers 49 and 50: read, it gave bad-49 and bad-50 figures
    disp = np.zeros((2, 2))
    with pytest.raises(ValueError, match=r"^thresholds must be positive and finite, got b'12'$"):
        dense_metrics(disp, disp, thresholds=b"12")  # type: ignore[arg-type]


def test_depth_metrics_density_without_overlap_is_zero_percent() -> None:
    # no pixel with both depths: 0 % of the pixels, a figure, not an unknown (NaN)
    m = depth_metrics(np.full((2, 3), NAN), np.ones((2, 3)))
    assert m.n == 0 and m.density == 0.0
    assert all(math.isnan(v) for v in (m.median_rel, m.share_off_5, m.rmse_pct, m.rmse))


@pytest.mark.parametrize("point", [[0, -1], [-1, 0]])
def test_table1_report_refuses_a_negative_point(point: list[int]) -> None:
    # -1 indexed the last row or column: a point of the far edge measured without a word
    ones = np.ones((3, 3))
    with pytest.raises(ValueError, match=re.escape(f"points: [{point}] lie outside the 3x3")):
        table1_report(ones, ones, points=np.array([point]))


def test_table1_report_refuses_float_points() -> None:
    ones = np.ones((3, 3))
    with pytest.raises(ValueError, match=r"^points: expected a non-empty integer \(N, 2\)"):
        table1_report(ones, ones, points=np.array([[1.0, 0.0]]))


def test_table1_summary_in_metres_and_feet() -> None:
    # 10 ft and 20 ft measured, 11 ft and 18 ft true: errors -1 and +2 ft, so the average
    # error (+0.5 ft) differs from the mean |error| (1.5 ft); RMSE sqrt(2.5) = 1.581 ft
    ft = 0.3048
    r = table1_report(
        np.array([[10 * ft, 20 * ft]]),
        np.array([[11 * ft, 18 * ft]]),
        points=np.array([[0, 0], [1, 0]]),
    )
    d = r.as_dict()
    assert d["mean_error_m"] == pytest.approx(0.5 * ft)
    assert d["mean_error_ft"] == pytest.approx(0.5)
    assert d["mean_abs_error_ft"] == pytest.approx(1.5)
    assert d["mean_distance_m"] == pytest.approx(14.5 * ft)
    assert d["mean_distance_ft"] == pytest.approx(14.5)
    assert d["rmse_ft"] == pytest.approx(math.sqrt(2.5))
    assert d["rmse_pct"] == pytest.approx(100 * math.sqrt(2.5) / 14.5)
    assert r.format().splitlines()[-3:] == [
        "points: 2   mean distance: 4.420 m (14.500 ft)",
        "average error: +0.152 m (+0.500 ft)   mean |error|: 0.457 m (1.500 ft)",
        "RMSE: 0.482 m (1.581 ft) = 10.90 % of the mean distance",
    ]


def test_sparse_metrics_rounds_half_to_even() -> None:
    # the documented look-up: (2.5, 0.5) -> (2, 0), (3.5, 0) -> (4, 0); half up gave (3, 1)
    # and (4, 0), one match on unknown GT
    gt = np.full((2, 6), NAN)
    gt[0, 2] = gt[0, 4] = 1.0
    xl = np.array([2.5, 3.5])
    m = sparse_metrics(xl, np.array([0.5, 0.0]), xl - 1.0, gt)
    assert m.count == 2 and m.precision[0.5] == 100.0 and m.coverage == 2


def test_count_at_precision_edges_of_the_target() -> None:
    gt = np.full((2, 8), 5.0)
    xl = np.arange(6.0) + 1
    yl = np.ones(6)
    score = -np.arange(6.0)  # best first: the given order
    right = np.array([1, 1, 1, 1, 1, 0], bool)
    xr = xl - np.where(right, 5.0, 9.0)
    # prefix precisions 100 x 5, then 5/6; a target of 5/6*100 (83.33333333333334) is the
    # 6-prefix's 100*5/6 (83.33333333333333) up to rounding, and holds it
    assert count_at_precision(xl, yl, xr, score, gt, 5 / 6 * 100) == 6
    # target 0 keeps every match with GT; the range is 0 to 100
    assert count_at_precision(xl, yl, xr, score, gt, 0) == 6
    # no prefix qualifies (the best-scored match is wrong): 0, not all of them
    assert count_at_precision(xl, yl, xr, -score, gt, 100.0) == 0


def test_count_at_precision_leaves_out_a_match_without_a_right_column() -> None:
    # the best-scored match has no right column (NaN): it is no match, not a wrong one
    gt = np.full((2, 4), 5.0)
    xl = np.array([1.0, 2.0])
    xr = np.array([NAN, 2.0 - 5.0])
    assert count_at_precision(xl, np.ones(2), xr, np.array([0.9, 0.5]), gt, 100.0) == 1


def test_depth_metrics_refuses_a_bool_map() -> None:
    # a validity mask passed for a depth map was read as depths of 1 and 0
    with pytest.raises(ValueError, match=r"^depth maps must be real arrays, got bool and float64"):
        depth_metrics(np.ones((2, 2), bool), np.ones((2, 2)))


def test_depth_metrics_names_a_whole_result_passed_for_a_depth_map() -> None:
    # depth_metrics(res, zgt) said "depth maps must be real arrays, got object and float32",
    # where dense_metrics and table1_report name the result and the array meant
    import stereovision as sv

    res = sv.DepthResult(
        disparity=np.ones((2, 2), np.float32),
        confidence=np.ones((2, 2), np.float32),
        depth=np.ones((2, 2), np.float32),
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
        depth_metrics(res, np.ones((2, 2)))
    with pytest.raises(TypeError, match=r"^gt: got a DepthResult; pass its array, result\.depth$"):
        depth_metrics(np.ones((2, 2)), res)
    assert depth_metrics(res.depth, np.ones((2, 2))).n == 4


def test_sparse_metrics_names_an_argument_that_is_no_array_of_numbers() -> None:
    # NumPy's words named nothing: a Matches given for xl was "setting an array element with
    # a sequence. The requested array would exceed the maximum number of dimension of 64"
    from stereovision.matches import Matches

    gt = np.ones((4, 6))
    m = Matches(
        xl=np.array([1.0]),
        yl=np.array([1.0]),
        xr=np.array([0.0]),
        yr=np.array([1.0]),
        score=np.array([0.9]),
        image_shape=(4, 6),
    )
    with pytest.raises(
        ValueError,
        match=r"^xl: expected a 1-D array of numbers, got Matches: pass its arrays, m\.xl, m\.yl",
    ):
        sparse_metrics(m, m.yl, m.xr, gt)
    with pytest.raises(ValueError, match=r"^xr: expected a 1-D array of numbers, got list$"):
        sparse_metrics(m.xl, m.yl, ["a"], gt)
    with pytest.raises(ValueError, match=r"^score: expected a 1-D array of numbers, got list$"):
        count_at_precision(m.xl, m.yl, m.xr, ["high"], gt, 90.0)
    assert sparse_metrics(m.xl, m.yl, m.xr, gt).count == 1


def test_sparse_metrics_refuses_complex_positions_and_scores() -> None:
    """A complex array lost its imaginary part with NumPy's ComplexWarning alone: xl 1+4j was
    read as 1 (count 1), where dense_metrics refuses a complex map."""
    gt = np.ones((4, 6))
    x, y = np.array([1.0]), np.array([1.0])
    with pytest.raises(
        ValueError, match=r"^xl: expected a 1-D array of real numbers, got complex values$"
    ):
        sparse_metrics(np.array([1 + 4j]), y, x - 1, gt)
    with pytest.raises(ValueError, match=r"^score: expected a 1-D array of real numbers"):
        count_at_precision(x, y, x - 1, np.array([0.9 + 0j]), gt, 90.0)
    assert sparse_metrics(x, y, x - 1, gt).count == 1


def test_dense_metrics_refuses_a_mask_of_another_shape() -> None:
    # a one-row mask was broadcast over every row, without a word
    gt = np.ones((2, 3))
    with pytest.raises(ValueError, match=r"^mask and gt must have the same shape, got \(1, 3\)"):
        dense_metrics(gt, gt, mask=np.ones((1, 3), bool))


def test_dense_metrics_a_gt_of_zero_is_known() -> None:
    # evaluation.md: unknown GT is inf or NaN (KITTI's 0 is converted when the scene is made);
    # a 0 px GT (a far point) counts: a hole there is an error
    gt = np.array([[0.0, 0.0, 2.0]])
    m = dense_metrics(np.array([[0.0, NAN, 2.0]]), gt)
    assert (m.n_gt, m.n_both) == (3, 2)
    assert m.bad[0.5] == pytest.approx(100 / 3)


def test_metrics_dicts_carry_each_figure_under_its_own_name() -> None:
    gt = np.array([[10.0, 10.0, 10.0]])
    m = dense_metrics(np.array([[11.0, 13.0, NAN]]), gt)  # errors 1 and 3
    d = m.as_dict()
    assert (d["avgerr"], d["rms"]) == (2.0, math.sqrt(5.0))
    assert (d["n_gt"], d["n_both"]) == (3, 2)
    s = sparse_metrics([0.0, 1.0, 2.0], [0.0, 0.0, 0.0], [-9.0, 0.0, NAN], np.ones((1, 3)))
    assert {k: s.as_dict()[k] for k in ("count", "n_matches", "coverage")} == {
        "count": 2,
        "n_matches": 3,
        "coverage": 2,
    }


@pytest.mark.parametrize("shape", [(0, 3), (3, 0)])
def test_sparse_metrics_on_an_empty_gt_counts_no_match(shape: tuple[int, int]) -> None:
    # every match lies outside an empty map, as in count_at_precision and dense_metrics (no
    # figure, NaN precision); the look-up at (0, 0) put in for them was an IndexError
    gt = np.zeros(shape)
    m = sparse_metrics([1.0, 2.0], [1.0, 0.0], [0.0, 1.0], gt)
    assert (m.count, m.n_matches, m.coverage) == (0, 2, 0)
    assert all(math.isnan(v) for v in m.precision.values())
    assert count_at_precision([1.0], [1.0], [0.0], [1.0], gt, 50.0) == 0


def test_maps_must_be_real_arrays() -> None:
    # a bool mask passed for a disparity or GT distance map was read as 1 and 0 px (or m)
    ones = np.ones((2, 2))
    with pytest.raises(
        ValueError, match=r"^disparity: expected a real \(H, W\) array, got .* bool"
    ):
        dense_metrics(ones > 0, ones)
    with pytest.raises(ValueError, match=r"^gt: expected a real \(H, W\) array, got .* bool"):
        table1_report(ones, ones > 0)


def test_a_masked_map_is_refused_as_depth_from_disparity_refuses_it() -> None:
    """np.asarray read a numpy.ma map's data: a masked GT pixel was scored (n_gt 6 of a map
    with one of its 6 masked), a masked estimate's pixel compared. Refused, saying what to
    pass, as depth_from_disparity refuses a masked map."""
    gt = np.ma.masked_array(np.full((2, 3), 5.0), mask=[[True, False, False], [False] * 3])
    est = np.full((2, 3), 5.0)
    for call, args, name in (
        (dense_metrics, (est, gt), "gt"),
        (dense_metrics, (gt, est), "disparity"),
        (depth_metrics, (est, gt), "gt"),
        (depth_metrics, (gt, est), "depth"),
    ):
        with pytest.raises(ValueError) as err:
            call(*args)
        assert str(err.value) == (
            f"{name}: a masked array (numpy.ma) with 1 masked pixel, whose values would be read "
            f"as real ones; pass {name}.filled(np.nan)"
        )
    assert dense_metrics(est, gt.filled(np.nan)).n_gt == 5


def test_table1_report_refuses_a_bool_seed() -> None:
    ones = np.ones((3, 3))
    with pytest.raises(ValueError, match=r"^seed must be an integer >= 0 or None, got True"):
        table1_report(ones, ones, seed=True)


def test_match_coordinates_must_be_1d() -> None:
    # a (1, N) row of matches was read as N matches in sparse_metrics, count_at_precision
    row = np.array([[1.0, 2.0]])
    gt = np.ones((4, 4))
    with pytest.raises(ValueError, match=r"^xl, yl, xr: expected 1-D arrays of equal length"):
        sparse_metrics(row, row, row - 1, gt)
    with pytest.raises(ValueError, match=r"^xl, yl, xr, score: expected 1-D arrays of equal len"):
        count_at_precision(row, row, row - 1, row, gt, 50.0)


# -------------------------------------------- mutation audit, third round (each failed on a
# mutant of evaluate.py that survived the tests above)


def test_sparse_coverage_reaches_every_cell_of_the_4x4_grid() -> None:
    # one match per 2x2 block of an 8x8 map: 16 cells, the last row and column among them
    # (clamping a cell index to 2 merged the bottom row of cells into the one above: 12)
    ys, xs = np.mgrid[0:8:2, 0:8:2]
    xl, yl = xs.ravel().astype(float), ys.ravel().astype(float)
    m = sparse_metrics(xl, yl, xl - 1.0, np.ones((8, 8)))
    assert (m.count, m.coverage) == (16, 16)
    # the bottom-right corner alone is cell (3, 3), apart from the cell above it
    m = sparse_metrics(
        np.array([7.0, 7.0]), np.array([5.0, 7.0]), np.array([6.0, 6.0]), np.ones((8, 8))
    )
    assert m.coverage == 2


@pytest.mark.parametrize("point", [[3, 0], [0, 3], [3, 3]])
def test_table1_report_refuses_a_point_past_the_far_edge(point: list[int]) -> None:
    # x == width or y == height is one past the last pixel: refused by name, not an IndexError
    ones = np.ones((3, 3))
    with pytest.raises(ValueError, match=re.escape(f"points: [{point}] lie outside the 3x3")):
        table1_report(ones, ones, points=np.array([point]))


def test_sparse_matches_on_infinite_gt_are_not_counted() -> None:
    """evaluation.md: a GT of inf (either sign) is unknown, as NaN; a match on it is neither
    right nor wrong (taken as known it was a wrong match, its error infinite)."""
    gt = np.ones((1, 4))
    gt[0, 0], gt[0, 1] = INF, -INF
    xl = np.array([0.0, 1.0, 2.0])
    yl = np.zeros(3)
    xr = xl - 1.0  # disparity 1: right wherever the GT is known
    m = sparse_metrics(xl, yl, xr, gt)
    assert (m.count, m.n_matches, m.coverage) == (1, 3, 1)
    assert m.precision == {0.5: 100.0, 1.0: 100.0, 2.0: 100.0}
    # the matches on inf GT scored best: they are not in the ranking, so 100 % keeps the third
    assert count_at_precision(xl, yl, xr, np.array([3.0, 2.0, 1.0]), gt, 100.0) == 1


def test_depth_metrics_leaves_out_an_infinite_estimated_depth() -> None:
    # an inf depth (a disparity of -doffs) is missing, as NaN: taken as valid, the RMSE was inf
    est = np.array([[2.0, INF, 4.4]])
    gt = np.array([[2.0, 3.0, 4.0]])
    m = depth_metrics(est, gt)
    assert (m.n, m.density) == (2, pytest.approx(200 / 3))
    assert m.rmse == pytest.approx(math.sqrt(0.08)) and m.share_off_5 == pytest.approx(50.0)


def test_dense_metrics_mask_does_not_make_unknown_gt_known() -> None:
    # a mask restricts the GT pixels, it never adds one: a masked-in NaN GT pixel is not counted
    est = np.array([[1.0, 1.0, 1.0]])
    gt = np.array([[1.0, NAN, 5.0]])
    m = dense_metrics(est, gt, mask=np.array([[True, True, False]]))
    assert (m.n_gt, m.n_both) == (1, 1)
    assert m.bad[0.5] == 0.0 and m.density == 100.0 and m.avgerr == 0.0


def test_table1_report_refuses_an_empty_list_of_points() -> None:
    # no point gave NaN figures (mean of nothing) and a table without a row
    ones = np.ones((3, 3))
    with pytest.raises(ValueError, match=r"^points: expected a non-empty integer \(N, 2\)"):
        table1_report(ones, ones, points=np.zeros((0, 2), dtype=np.int64))


def test_table1_report_draws_by_its_seed() -> None:
    est = np.full((20, 30), 2.0)
    gt = np.full((20, 30), 2.5)
    a, b, c = (table1_report(est, gt, seed=s) for s in (1, 1, 2))
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)
    assert not (np.array_equal(a.x, c.x) and np.array_equal(a.y, c.y))
    pick = np.sort(np.random.default_rng(2).choice(600, size=10, replace=False))
    assert np.array_equal(c.y * 30 + c.x, pick)  # the documented draw


def test_dense_metrics_bad_keys_are_floats_for_integer_thresholds() -> None:
    """``bad`` is a dict of float: integer thresholds (``(1, 2)``, ``np.arange``) are keyed as
    ``1.0`` and ``2.0``, so that its JSON keys are ``"1.0"``, not ``"1"`` or a NumPy type's text
    (a mutant keying by the threshold as given survived every test)."""
    from stereovision._jsonout import json_line

    d, g = np.array([[1.0, 2.5, NAN, 9.0]]), np.array([[1.0, 1.0, 1.0, 1.0]])
    for ts in ((1, 2), np.arange(1, 3)):
        m = dense_metrics(d, g, thresholds=ts)  # errors 0, 1.5, hole, 8
        assert [(type(k), k) for k in m.bad] == [(float, 1.0), (float, 2.0)]
        assert (m.bad[1.0], m.bad[2.0]) == (75.0, 50.0)
        assert json.loads(json_line({"bad": m.bad})) == {"bad": {"1.0": 75.0, "2.0": 50.0}}


@pytest.mark.parametrize("unit", [["m"], {"m": 1.0}, {"mm"}])
def test_table1_report_names_a_unit_that_is_no_name(unit: object) -> None:
    """A list, dict or set for ``unit`` raised ``TypeError: unhashable type: 'list'`` from the
    unit table, naming neither ``unit`` nor the units it takes."""
    ones = np.ones((2, 2))
    with pytest.raises(ValueError, match=r"unit: expected one of \['cm', 'ft', 'in', 'm', 'mm'\]"):
        table1_report(ones, ones, unit=unit)  # type: ignore[arg-type]


def test_depth_metrics_refuses_a_bool_gt_map() -> None:
    # the GT side too: a validity mask for the GT depth was read as depths of 1 and 0 (a mutant
    # checking the estimate's dtype only survived)
    with pytest.raises(ValueError, match=r"^depth maps must be real arrays, got float64 and bool"):
        depth_metrics(np.ones((2, 2)), np.ones((2, 2), bool))


def test_table1_report_seed_none_draws_other_points_each_call() -> None:
    """``seed=None`` is fresh entropy (``default_rng(None)``): two draws of 10 of 600 pixels
    differ (a mutant drawing with seed 0 for None survived the test above)."""
    est = np.full((20, 30), 2.0, np.float32)
    gt = np.full((20, 30), 2.5, np.float32)
    draws = [table1_report(est, gt, n_points=10, seed=None) for _ in range(2)]
    assert (draws[0].x.tolist(), draws[0].y.tolist()) != (draws[1].x.tolist(), draws[1].y.tolist())


@pytest.mark.parametrize(
    ("mask", "dtype"),
    [
        (np.array([[1.0, NAN, 1.0]]), "float64"),  # astype(bool) took the NaN as inside
        (np.array([[0.5, 0.0, 1.0]]), "float64"),
        (np.array([["y", "", "y"]]), "<U1"),
        (np.array([[1, None, 1]], dtype=object), "object"),
    ],
)
def test_dense_metrics_refuses_a_mask_that_is_not_bool_or_integer(
    mask: np.ndarray, dtype: str
) -> None:
    """``astype(bool)`` took any dtype: a NaN in a float mask counted as inside, a string
    mask was read by emptiness. Only bool, integer and 0/1 float masks are masks."""
    gt = np.full((1, 3), 4.0)
    with pytest.raises(ValueError, match=rf"^mask: expected .*bool.*, got dtype {dtype}"):
        dense_metrics(gt, gt, mask=mask)


def test_dense_metrics_takes_int_and_0_1_float_masks_as_bool() -> None:
    gt = np.array([[4.0, 4.0, 4.0]])
    disp = np.array([[4.5, 10.0, NAN]])
    want = dense_metrics(disp, gt, mask=np.array([[True, False, True]]))
    for mask in (np.array([[1, 0, 1]]), np.array([[1.0, 0.0, 1.0]], np.float32), [[1, 0, 1]]):
        assert dense_metrics(disp, gt, mask=mask) == want


def test_table1_report_shows_a_numpy_string_unit_as_its_text() -> None:
    # a unit read from an array (np.str_) was shown by repr: "got np.str_('parsec')"
    ones = np.ones((2, 2))
    with pytest.raises(ValueError, match=r"got 'parsec'$"):
        table1_report(ones, ones, unit=np.str_("parsec"))  # type: ignore[arg-type]


def test_depth_metrics_rmse_pct_is_of_the_mean_gt_depth() -> None:
    # GT depths 1, 1, 10: mean 4, median 1 (the hand-computed test's 10, 10, 20, 20 has both 15,
    # so it could not tell them apart)
    gt = np.array([[1.0, 1.0, 10.0]])
    est = np.array([[1.1, 1.0, 10.0]])
    m = depth_metrics(est, gt)
    rmse = math.sqrt((0.1**2 + 0.0 + 0.0) / 3)  # 0.0577...
    assert m.rmse == pytest.approx(rmse)
    assert m.rmse_pct == pytest.approx(100 * rmse / 4.0)  # 1.443 %, not 5.77 % (median 1)


def test_sparse_metrics_measures_the_disparity_at_the_unrounded_column() -> None:
    # The GT is looked up at the rounded (xl, yl), but the match's disparity is xl - xr with
    # xl as given: 10.4 - 9.0 = 1.4 against GT 1.7 (err 0.3), 3.6 - 3.0 = 0.6 against GT 0.4
    # (err 0.2). With the rounded columns they would be 1.0 and 1.0: errors 0.7 and 0.6.
    gt = np.full((2, 12), NAN)
    gt[0, 10] = 1.7
    gt[1, 4] = 0.4
    m = sparse_metrics([10.4, 3.6], [0.0, 1.0], [9.0, 3.0], gt)
    assert m.count == 2
    assert m.precision[0.5] == pytest.approx(100.0)


def test_count_at_precision_measures_the_disparity_at_the_unrounded_column() -> None:
    # as sparse_metrics: 10.4 - 9.0 = 1.4 against GT 1.7 (err 0.3 <= 0.5 px); the rounded
    # column's 1.0 would be 0.7 off and no prefix would hold 100 %
    gt = np.full((1, 12), NAN)
    gt[0, 10] = 1.7
    assert count_at_precision([10.4], [0.0], [9.0], [1.0], gt, 100.0, tolerance=0.5) == 1


def test_sparse_metrics_dict_gives_the_coverage_not_the_count() -> None:
    # three matches with GT, two in cell (0, 0) of the 4x4 grid over an 8x8 map, one in (3, 3):
    # count 3, coverage 2
    gt = np.full((8, 8), 2.0)
    s = sparse_metrics([0.0, 1.0, 7.0], [0.0, 1.0, 7.0], [-2.0, -1.0, 5.0], gt).as_dict()
    assert (s["count"], s["coverage"], s["precision@1.0"]) == (3, 2, 100.0)


def test_table1_text_keeps_its_columns_for_a_far_point() -> None:
    """A validated member at ~0 px disparity triangulates to 3e38 m: its row was printed with
    39-digit numbers, the columns out of line, and the summary likewise; the exponent form is
    used from a million up (and where a column is too narrow), the usual rows unchanged."""
    est = np.full((2, 2), 10.0)
    est[0, 0], est[0, 1], est[1, 0] = 3e38, 426500.0, 12.5
    text = table1_report(est, np.full((2, 2), 10.0), n_points=4).format().splitlines()
    head = text[1]
    for row in text[3:7]:  # every row as wide as the heading, its columns under it
        assert len(row) == len(head), row
    assert text[3].split()[3:6] == ["3.000e+38", "10.000", "+3.0e+38"]
    assert text[4].split()[3:6] == ["4.265e+05", "10.000", "+4.3e+05"]
    assert text[5].split()[3:9] == ["12.500", "10.000", "+2.500", "41.010", "32.808", "+8.202"]
    assert text[-1] == "RMSE: 1.500e+38 m (4.921e+38 ft) = 1.50e+39 % of the mean distance"


def test_table1_reports_compare_and_hash_by_identity() -> None:
    """Two reports of the same points: ``a == b`` compared their arrays and raised NumPy's
    'truth value of an array ... is ambiguous', and a report was unhashable. Equal to itself
    only, and hashable (as TriangulationResult)."""
    est = np.array([[2.0, 3.1], [4.0, 5.0]])
    a, b = (table1_report(est, est, points=np.array([[0, 0], [1, 0]])) for _ in range(2))
    assert a == a and a != b and b not in [a]
    assert {a: 1, b: 2}[a] == 1 and len({a, b, a}) == 2


def test_gt_depths_warnings_are_at_the_callers_line() -> None:
    """A GT map of fixed-point values (KITTI's d * 256 read with cv2.imread) or of the pair
    resized was warned about at gt_depth's own line in evaluate.py, not the caller's."""
    cal = Calibration.ideal((64, 48), 60.0, 0.1)
    for gt, words in (
        (np.full((48, 64), 20.0 * 256), "disparity: values up to 5120 px"),
        (np.ones((96, 128)), "disparity map is 128x96 px"),
    ):
        with pytest.warns(UserWarning, match=words) as rec:
            gt_depth(gt, cal)
        assert [r.filename for r in rec] == [__file__]


def test_dense_metrics_warns_of_a_gt_that_reads_as_a_disparity_png() -> None:
    """KITTI's GT PNG read with cv2.imread (d * 256, 0 = unknown) was scored as pixels, its
    unknown pixels known: SGBM-3WAY on 000005 bad-2.0 99.9 % for 29.5 %, without a word. An
    integer GT as wide as the map or wider, or holding 0s, is warned about at the caller's
    line; the figures are as before, and a GT in pixels (float, NaN = unknown) gets none."""
    d = np.full((4, 8), 3.0)
    gt = np.zeros((4, 8), np.uint16)
    gt[:2] = 3 * 256  # KITTI's 16-bit PNG: 3 px, the lower half unknown (0)
    with pytest.warns(
        UserWarning,
        match=r"^gt: values up to 768 px, as wide as the map \(8 px\) "
        r"or wider: no match lies that far; a disparity PNG \(KITTI's d \* 256, 0 = "
        r"unknown\) reads as pixels with stereovision.export.read_disparity_png ",
    ) as rec:
        m = dense_metrics(d, gt)
    assert [r.filename for r in rec] == [__file__] and m.bad[2.0] == 100.0 and m.n_gt == 32
    with pytest.warns(UserWarning, match=r"^gt: an integer map with 16 pixels at 0, scored as "):
        m = dense_metrics(d, gt // 256)  # the scale taken off, its 0s still known
    assert m.bad[2.0] == 50.0 and m.n_gt == 32
    as_pixels = np.where(gt > 0, gt / 256, np.nan)  # read_disparity_png's map
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = dense_metrics(d, as_pixels)
        dense_metrics(d, np.full((4, 8), 7))  # integer, no 0, narrower than the map
        dense_metrics(d, np.full((4, 8), 9.0))  # float: pixels, as wide as it may be
    assert m.bad[2.0] == 0.0 and m.n_gt == 16


def test_dense_metrics_warns_not_of_the_0s_its_mask_leaves_out() -> None:
    """An integer GT in pixels whose 0s (unknown) a mask leaves out, as KITTI's devkit scores
    (valid = gt > 0), was warned of as 'an integer map with 16 pixels at 0, scored as known
    0 px disparities' where none of them was scored; the 0s the mask keeps are still said."""
    d = np.full((4, 8), 3.0)
    gt = np.zeros((4, 8), np.uint8)
    gt[:2] = 3  # 3 px, the lower half unknown (0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = dense_metrics(d, gt, mask=gt > 0)
    assert m.bad[2.0] == 0.0 and m.n_gt == 16
    keep = gt > 0
    keep[2, :3] = True  # three of the 0s scored
    with pytest.warns(UserWarning, match=r"^gt: an integer map with 3 pixels at 0, scored as "):
        m = dense_metrics(d, gt, mask=keep)
    assert m.n_gt == 19


def test_sparse_figures_warn_of_a_gt_that_reads_as_a_disparity_png() -> None:
    """As dense_metrics: matches scored against KITTI's GT PNG as read (d * 256, 0 = unknown)
    had a precision of about 0 without a word; sparse_metrics and count_at_precision warn at
    the caller's line, their figures as before."""
    gt = np.zeros((4, 8), np.uint16)
    gt[:2] = 3 * 256
    xl, yl, xr = np.array([5.0, 6.0]), np.array([0.0, 1.0]), np.array([2.0, 3.0])
    with pytest.warns(UserWarning, match=r"^gt: values up to 768 px, as wide as the map") as rec:
        assert sparse_metrics(xl, yl, xr, gt).count == 2
        assert count_at_precision(xl, yl, xr, np.ones(2), gt, 50.0) == 0
    assert [r.filename for r in rec] == [__file__] * 2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert sparse_metrics(xl, yl, xr, np.where(gt > 0, gt / 256, np.nan)).precision[0.5] == 100
