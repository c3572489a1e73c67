"""Census semi-global matcher (the fused dense map's completion) beside OpenCV SGBM-3WAY.

Accuracy on every GT scene: bad-2.0 with holes counted after evaluation.md's reference row fill,
ours (8 paths, and 3 paths in one pass: ``paths=3``, ``depth_map(method="fast")``'s) and
SGBM-3WAY's, the ratios, and the density of ours (8 paths, before the fill; evaluation.md's:
over the GT pixels). Speed on cloth3 and teddyH: all on all cores, interleaved after a
warm-up, median of ``--runs``, and the ratios ``ours / SGBM``.

Usage: ``python benches/bench_sgm.py [--runs 7] [--no-accuracy]``
"""

from __future__ import annotations

import argparse
import json
import statistics

from _common import DATA, gt_scenes, interleaved_ms, timed_runs

from stereovision.baselines import opencv_sgbm, row_fill
from stereovision.evaluate import dense_metrics
from stereovision.io import load_scene
from stereovision.matching.sgm import sgm_disparity

SPEED = ("middlebury2006/cloth3", "middeval3/teddyH")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=timed_runs, default=7)
    ap.add_argument("--no-accuracy", action="store_true")
    args = ap.parse_args()
    if not args.no_accuracy:
        ratios, ratios3 = [], []
        print(
            f"{'scene':40s} {'ours+fill':>9s} {'3 paths':>9s} {'SGBM+fill':>9s} {'ratio':>6s} "
            f"{'ratio3':>6s} {'density':>7s}"
        )
        for name in gt_scenes():
            sc = load_scene(DATA / name)
            assert sc.gt is not None
            d = sgm_disparity(sc.left, sc.right, max_disparity=sc.max_disparity)
            d3 = sgm_disparity(sc.left, sc.right, max_disparity=sc.max_disparity, paths=3)
            ours = dense_metrics(row_fill(d), sc.gt).bad[2.0]
            ours3 = dense_metrics(row_fill(d3), sc.gt).bad[2.0]
            ref = dense_metrics(row_fill(opencv_sgbm(sc.left, sc.right, sc.max_disparity)), sc.gt)
            ref = ref.bad[2.0]
            ratios.append(ours / ref)
            ratios3.append(ours3 / ref)
            # evaluation.md's density: over the GT pixels (it was over all of them: KITTI's
            # LiDAR GT covers a fifth of the image)
            dens = dense_metrics(d, sc.gt).density
            print(
                f"{name:40s} {ours:9.2f} {ours3:9.2f} {ref:9.2f} {ours / ref:6.3f} "
                f"{ours3 / ref:6.3f} {dens:7.1f}"
            )
            print(
                json.dumps(
                    {
                        "scene": name,
                        "ours_fill": ours,
                        "ours3_fill": ours3,
                        "sgbm_fill": ref,
                        "density": dens,
                    }
                )
            )
        print(f"mean ratio {statistics.mean(ratios):.3f} (3 paths: {statistics.mean(ratios3):.3f})")
    for name in SPEED:
        sc = load_scene(DATA / name)
        dmax = sc.max_disparity
        left, right = sc.left, sc.right
        ours_ms, ours3_ms, cv_ms = interleaved_ms(
            [
                lambda left=left, right=right, dmax=dmax: sgm_disparity(
                    left, right, max_disparity=dmax
                ),
                lambda left=left, right=right, dmax=dmax: sgm_disparity(
                    left, right, max_disparity=dmax, paths=3
                ),
                lambda left=left, right=right, dmax=dmax: opencv_sgbm(left, right, dmax),
            ],
            args.runs,
        )
        print(
            f"{name}: ours {ours_ms:.1f} ms, 3 paths {ours3_ms:.1f} ms, SGBM-3WAY {cv_ms:.1f} ms, "
            f"ratios {ours_ms / cv_ms:.2f} and {ours3_ms / cv_ms:.2f}"
        )
        print(
            json.dumps({"scene": name, "ours_ms": ours_ms, "ours3_ms": ours3_ms, "sgbm_ms": cv_ms})
        )


if __name__ == "__main__":
    main()
