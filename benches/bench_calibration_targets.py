"""ChArUco against chessboard calibration on the same synthetic rig and the same board poses.

A rig with known geometry (640x480, barrel distortion k1 about -0.3, 120 mm baseline) sees a
board in 20 random poses per seed, 0.35-0.6 m away, centred anywhere over the image and so often
cut by its edges. The same poses are rendered with a 9x6 chessboard and with a 10x7-square
ChArUco board (the same 9x6 inner-corner grid), with grey noise (sigma 1) and, with
``--hard``, a Gaussian blur (sigma 0.8 px), a lighting gradient and JPEG compression (quality
85). Each set is calibrated with :func:`stereovision.calibrate.calibrate` and the estimate is
scored against the true rig: points 2-6 m away seen by the true cameras, rectified with the
estimate, give the row offset (px) and the range error. The two calibrations of a seed are timed
interleaved (ChArUco, chessboard, ...), median of ``--runs`` after a warm-up (evaluation.md
"Speed").

Usage: ``python benches/bench_calibration_targets.py [--seeds 3] [--hard] [--runs 5]``
"""

from __future__ import annotations

import argparse
import math
import sys
from functools import partial
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from _common import interleaved_runs, timed_runs

from stereovision.calibrate import calibrate, render_chessboard
from stereovision.charuco import render_charuco

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
# The rig of tests/test_charuco.py: 640x480, k1 about -0.3, 120 mm baseline; its 10x7 board.
from tests.test_charuco import BOARD, D1, D2, K1, K2, ROT, T

SIZE = (640, 480)
SQUARE = 0.03


def degrade(img: np.ndarray, rng: np.random.Generator, hard: bool) -> np.ndarray:
    f = img.astype(np.float64)
    if hard:
        f = cv2.GaussianBlur(f, (0, 0), 0.8)
        h, w = f.shape
        gx = np.linspace(0.75, 1.15, w)[None, :] * np.linspace(1.1, 0.85, h)[:, None]
        f = f * gx
    f = np.clip(f + rng.normal(0, 1.0, f.shape), 0, 255).astype(np.uint8)
    if hard:
        _, buf = cv2.imencode(".jpg", f, [cv2.IMWRITE_JPEG_QUALITY, 85])
        f = cv2.imdecode(buf, cv2.IMREAD_GRAYSCALE)
    return f


def truth_errors(cal: object, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    c = cal
    R1, R2, P1, P2, *_ = cv2.stereoRectify(
        c.K1, c.D1, c.K2, c.D2, SIZE, c.R, c.T.reshape(3, 1),  # type: ignore[attr-defined]
        flags=cv2.CALIB_ZERO_DISPARITY, alpha=0,
    )  # fmt: skip
    n = 6000
    pts = np.c_[rng.uniform(-1.5, 1.5, n), rng.uniform(-1, 1, n), rng.uniform(2, 6, n)]
    pl = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), K1, D1)[0].reshape(-1, 2)
    pr = cv2.projectPoints(pts, cv2.Rodrigues(ROT)[0], T, K2, D2)[0].reshape(-1, 2)
    w, h = SIZE
    ok = np.all((pl >= 0) & (pl < (w, h)) & (pr >= 0) & (pr < (w, h)), axis=1)
    ul = cv2.undistortPoints(pl[ok].reshape(-1, 1, 2), c.K1, c.D1, R=R1, P=P1).reshape(-1, 2)  # type: ignore[attr-defined]
    ur = cv2.undistortPoints(pr[ok].reshape(-1, 1, 2), c.K2, c.D2, R=R2, P=P2).reshape(-1, 2)  # type: ignore[attr-defined]
    X = cv2.triangulatePoints(P1, P2, ul.T, ur.T)
    est = np.linalg.norm((X[:3] / X[3]).T, axis=1)
    return np.abs(ul[:, 1] - ur[:, 1]), np.abs(est / np.linalg.norm(pts[ok], axis=1) - 1)


def truth_columns(cal: object, seed: int) -> str:
    """The columns both calibration benches print against the true rig: baseline error (mm),
    rotation error (deg), rectified rows' 95th percentile (px), range error median / p95 (%)."""
    dy, rel = truth_errors(cal, np.random.default_rng(seed))
    rot = math.degrees(float(np.linalg.norm(cv2.Rodrigues(cal.R @ ROT.T)[0])))  # type: ignore[attr-defined]
    return (
        f"{1000 * abs(np.linalg.norm(cal.T) - np.linalg.norm(T)):10.3f}  "  # type: ignore[attr-defined]
        f"{rot:11.4f}  {np.percentile(dy, 95):11.3f}  "
        f"{100 * np.median(rel):10.2f} / {100 * np.percentile(rel, 95):.2f}"
    )


def random_views(rng: np.random.Generator) -> tuple[tuple[np.ndarray, ...], ...]:
    """One random board pose as each camera of the rig sees it: ``((K, D, rvec, tvec), ...)``
    for the left and the right camera, the ChArUco board's outer corner as the origin (0.35-0.6
    m away, centred anywhere over the image)."""
    centre = np.array([5 * SQUARE, 3.5 * SQUARE, 0])
    rv = rng.normal(0, 0.25, 3)
    z = rng.uniform(0.35, 0.6)
    c = np.array([rng.uniform(-0.25, 0.25) * z, rng.uniform(-0.18, 0.18) * z, z])
    tv = c - cv2.Rodrigues(rv)[0] @ centre
    r2, t2 = cv2.composeRT(
        rv.reshape(3, 1), tv.reshape(3, 1), cv2.Rodrigues(ROT)[0], T.reshape(3, 1)
    )[:2]
    return (K1, D1, rv, tv), (K2, D2, r2, t2)


def chessboard_view(K: np.ndarray, D: np.ndarray, r: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The 9x6 chessboard at a :func:`random_views` pose: its corner (0, 0) is the ChArUco's
    corner 0, one square in from the outer corner."""
    Rb = cv2.Rodrigues(np.asarray(r, np.float64).reshape(3, 1))[0]
    t_c = np.asarray(t, np.float64).ravel() + Rb @ np.array([SQUARE, SQUARE, 0])
    img: np.ndarray = render_chessboard(
        K, D, r, t_c, pattern=(9, 6), square_size=SQUARE, image_size=SIZE
    )
    return img


def _calibrate_or_error(
    left: list[np.ndarray], right: list[np.ndarray], **kw: Any
) -> tuple[Any, Any] | ValueError:
    """:func:`calibrate`'s result, or the ValueError it refused the set with (timed alike)."""
    try:
        return calibrate(left, right, **kw)
    except ValueError as exc:
        return exc


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--views", type=int, default=20)
    ap.add_argument("--hard", action="store_true", help="blur, lighting gradient and JPEG")
    ap.add_argument("--runs", type=timed_runs, default=5, help="timed runs per target (median)")
    args = ap.parse_args()
    print(
        "target      seed  pairs  corners  RMS px  |T| err mm  rot err deg  rows p95 px  "
        "range err median/p95 %  time s"
    )
    for seed in range(args.seeds):
        rng = np.random.default_rng(100 + seed)
        sets: dict[str, tuple[list[np.ndarray], list[np.ndarray]]] = {
            "charuco": ([], []),
            "chessboard": ([], []),
        }
        for _ in range(args.views):
            for side, (K, D, r, t) in enumerate(random_views(rng)):
                img = render_charuco(BOARD, K, D, r, t, image_size=SIZE)
                sets["charuco"][side].append(degrade(img, rng, args.hard))
                img = chessboard_view(K, D, r, t)
                sets["chessboard"][side].append(degrade(img, rng, args.hard))
        kws: dict[str, dict[str, Any]] = {
            "charuco": {"board": BOARD},
            "chessboard": {"square_size": SQUARE},
        }
        times, outs = interleaved_runs(
            [partial(_calibrate_or_error, *sets[name], **kws[name]) for name in sets], args.runs
        )
        for name, ms, out in zip(sets, times, outs, strict=True):
            dt = ms / 1e3
            if isinstance(out, ValueError):
                print(f"{name:<11} {seed:>4}  failed: {out}")
                continue
            cal, rep = out
            print(
                f"{name:<11} {seed:>4}  {len(rep.used_pairs):>2}/{args.views}  "
                f"{rep.corners_used:>7}  {rep.rms:6.3f}  {truth_columns(cal, seed)}  {dt:10.1f}"
            )


if __name__ == "__main__":
    main()
