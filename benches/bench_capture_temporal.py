"""Calibration from noisy captures: one frame per board pose against the mean of N still frames
(``stereovision capture --temporal N``).

The rendered rig of ``bench_calibration_targets.py`` (640x480, k1 about -0.3, 120 mm baseline)
sees a 9x6 chessboard in 20 random poses per seed. Each pose is taken as a low-light camera would
give it: grey noise of ``--sigma`` levels, fresh in every frame. ``single`` calibrates on the
first frame of each pose; ``mean N`` on the output of a
:class:`~stereovision.temporal.TemporalFilter` after N frames (what ``capture --temporal N``
saves). Both are scored against the true rig as in ``bench_calibration_targets.py``: points 2-6 m
away seen by the true cameras, rectified with the estimate, give the row offset (px) and the
range error.

Usage: ``python benches/bench_capture_temporal.py [--seeds 3] [--sigma 8 20] [--frames 8]``
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from bench_calibration_targets import SQUARE, chessboard_view, random_views, truth_columns

from stereovision.calibrate import calibrate
from stereovision.temporal import TemporalFilter

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tests.test_exposure import noisy


def poses(rng: np.random.Generator, views: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Clean left and right chessboard renders of ``views`` random poses (float64, 0-255)."""
    out = []
    for _ in range(views):
        left, right = (chessboard_view(*v).astype(np.float64) for v in random_views(rng))
        out.append((left, right))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--views", type=int, default=20)
    ap.add_argument("--sigma", type=float, nargs="+", default=[8.0, 20.0])
    ap.add_argument("--frames", type=int, default=8)
    args = ap.parse_args()
    print(
        "sigma  case     seed  pairs  RMS px  |T| err mm  rot err deg  rows p95 px  "
        "range err median/p95 %"
    )
    for sigma in args.sigma:
        for seed in range(args.seeds):
            rng = np.random.default_rng(100 + seed)
            clean = poses(rng, args.views)
            single: tuple[list[np.ndarray], list[np.ndarray]] = ([], [])
            mean: tuple[list[np.ndarray], list[np.ndarray]] = ([], [])
            for cl, cr in clean:
                tf = TemporalFilter(max_frames=args.frames)
                for i in range(args.frames):
                    fl, fr = noisy(cl, sigma, rng), noisy(cr, sigma, rng)
                    if i == 0:
                        single[0].append(fl)
                        single[1].append(fr)
                    al, ar = tf(fl, fr)
                mean[0].append(al)
                mean[1].append(ar)
            for name, (left, right) in (("single", single), (f"mean {args.frames}", mean)):
                try:
                    cal, rep = calibrate(left, right, square_size=SQUARE)
                except ValueError as exc:
                    print(f"{sigma:5.1f}  {name:<7} {seed:>4}  failed: {exc}")
                    continue
                print(
                    f"{sigma:5.1f}  {name:<7} {seed:>4}  {len(rep.used_pairs):>2}/{args.views}  "
                    f"{rep.rms:6.3f}  {truth_columns(cal, seed)}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
