"""Gabor channel vs OpenCV StereoSGBM (3-way) on the same pairs, same process, interleaved.

evaluation.md "Speed": both use all cores (2 here, ``cv2.setNumThreads(2)``, rayon's default),
SGBM on the BGR pair with the reference configuration, our ``gabor_disparity`` on the grey
float32 pair (the grey conversion is done once, outside the timing, like OpenCV's BGR load).
After a warm-up the runs alternate A, B, A, B ...; the median of each and the ratio
``gabor / SGBM`` are printed, plus one JSON line per case.

Usage: ``python benches/bench_gabor_vs_sgbm.py [--runs 9] [--param key=value ...]``
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import cv2
import numpy as np
from _common import gabor_param, gabor_params, timed_runs

from stereovision.matching.gabor import gabor_disparity

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
CASES = (("middlebury2006/cloth3", 96), ("middeval3/teddyH", 128))


def sgbm_matcher(max_disparity: int) -> cv2.StereoSGBM:
    """The reference SGBM-3WAY configuration of evaluation.md."""
    d16 = (max_disparity + 15) // 16 * 16
    return cv2.StereoSGBM_create(
        minDisparity=0,
        numDisparities=d16,
        blockSize=5,
        P1=8 * 3 * 25,
        P2=32 * 3 * 25,
        disp12MaxDiff=1,
        uniquenessRatio=10,
        speckleWindowSize=100,
        speckleRange=2,
        mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY,
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=timed_runs, default=9)
    ap.add_argument(
        "--param", action="append", default=[], type=gabor_param, help="key=JSON (repeatable)"
    )
    args = ap.parse_args()
    params = gabor_params(ap, args.param)
    cv2.setNumThreads(2)
    print(f"{'scene':24s} {'size':>9s} {'D':>4s} {'gabor ms':>9s} {'SGBM ms':>8s} {'ratio':>6s}")
    for scene, dmax in CASES:
        d = DATA / scene
        lb, rb = cv2.imread(str(d / "left.png")), cv2.imread(str(d / "right.png"))
        lg = cv2.cvtColor(lb, cv2.COLOR_BGR2GRAY).astype(np.float32) / 255
        rg = cv2.cvtColor(rb, cv2.COLOR_BGR2GRAY).astype(np.float32) / 255
        sgbm = sgbm_matcher(dmax)

        def run_gabor(lg: np.ndarray = lg, rg: np.ndarray = rg, dmax: int = dmax) -> None:
            gabor_disparity(lg, rg, max_disparity=dmax, **params)

        def run_sgbm(sgbm: cv2.StereoSGBM = sgbm, lb: np.ndarray = lb, rb: np.ndarray = rb) -> None:
            sgbm.compute(lb, rb)

        run_gabor()
        run_sgbm()
        tg, ts = [], []
        for _ in range(args.runs):
            t = time.perf_counter()
            run_gabor()
            tg.append(time.perf_counter() - t)
            t = time.perf_counter()
            run_sgbm()
            ts.append(time.perf_counter() - t)
        mg, ms = 1e3 * statistics.median(tg), 1e3 * statistics.median(ts)
        h, w = lg.shape
        print(f"{scene:24s} {w:4d}x{h:<4d} {dmax:4d} {mg:9.1f} {ms:8.1f} {mg / ms:6.2f}")
        print(
            json.dumps(
                {
                    "bench": "gabor_vs_sgbm3way",
                    "scene": scene,
                    "width": w,
                    "height": h,
                    "max_disparity": dmax,
                    "runs": args.runs,
                    "gabor_ms": round(mg, 2),
                    "sgbm_ms": round(ms, 2),
                    "ratio": round(mg / ms, 3),
                    "params": params,
                }
            )
        )


if __name__ == "__main__":
    main()
