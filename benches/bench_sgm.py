"""Census semi-global matcher (the fused dense map's completion) beside OpenCV SGBM-3WAY.

Accuracy on every GT scene: bad-2.0 with holes counted after evaluation.md's reference row fill,
ours and SGBM-3WAY's, and their ratio. Speed on cloth3 and teddyH: both on all cores, interleaved
after a warm-up, median of ``--runs``, and the ratio ``ours / SGBM``.

Usage: ``python benches/bench_sgm.py [--runs 7] [--no-accuracy]``
"""

from __future__ import annotations

import argparse
import json
import statistics

import numpy as np
from _common import DATA, gt_scenes, interleaved_ms

from stereovision.baselines import opencv_sgbm, row_fill
from stereovision.evaluate import dense_metrics
from stereovision.io import load_scene
from stereovision.matching.sgm import sgm_disparity

SPEED = ("middlebury2006/cloth3", "middeval3/teddyH")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--no-accuracy", action="store_true")
    args = ap.parse_args()
    if not args.no_accuracy:
        ratios = []
        print(f"{'scene':40s} {'ours+fill':>9s} {'SGBM+fill':>9s} {'ratio':>6s} {'density':>7s}")
        for name in gt_scenes():
            sc = load_scene(DATA / name)
            assert sc.gt is not None
            d = sgm_disparity(sc.left, sc.right, max_disparity=sc.max_disparity)
            ours = dense_metrics(row_fill(d), sc.gt).bad[2.0]
            ref = dense_metrics(row_fill(opencv_sgbm(sc.left, sc.right, sc.max_disparity)), sc.gt)
            ref = ref.bad[2.0]
            ratios.append(ours / ref)
            dens = 100 * float(np.isfinite(d).mean())
            print(f"{name:40s} {ours:9.2f} {ref:9.2f} {ours / ref:6.3f} {dens:7.1f}")
            print(json.dumps({"scene": name, "ours_fill": ours, "sgbm_fill": ref, "density": dens}))
        print(f"mean ratio {statistics.mean(ratios):.3f}")
    for name in SPEED:
        sc = load_scene(DATA / name)
        dmax = sc.max_disparity
        left, right = sc.left, sc.right
        ours_ms, cv_ms = interleaved_ms(
            [
                lambda left=left, right=right, dmax=dmax: sgm_disparity(
                    left, right, max_disparity=dmax
                ),
                lambda left=left, right=right, dmax=dmax: opencv_sgbm(left, right, dmax),
            ],
            args.runs,
        )
        print(
            f"{name}: ours {ours_ms:.1f} ms, SGBM-3WAY {cv_ms:.1f} ms, ratio {ours_ms / cv_ms:.2f}"
        )
        print(json.dumps({"scene": name, "ours_ms": ours_ms, "sgbm_ms": cv_ms}))


if __name__ == "__main__":
    main()
