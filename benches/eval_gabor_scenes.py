"""Scratch evaluation of the Gabor channel on the shared scenes (evaluation.md metrics).

Prints, per scene with GT under ../shared/data: bad-2.0 of our output after the reference row fill
and unfilled (holes count as errors), density, StereoBM and SGBM-3WAY bad-2.0 (unfilled), and
the times of the channel and of SGBM-3WAY (evaluation.md "Speed": interleaved, median of ``--runs``
after a warm-up; with ``--no-cv`` the channel's alone) with their ratio; then the means, and the
metric-depth comparison with SGBM-3WAY on the scenes with a metric calibration. Uses the
package's scene loader (max_disparity per evaluation.md), OpenCV references, reference fill and
metrics.

Usage: ``python benches/eval_gabor_scenes.py [--scenes a,b] [--param key=value ...] [--runs 5]
[--no-cv]``
"""

from __future__ import annotations

import argparse
from functools import partial

import cv2
import numpy as np
from _common import DATA, gabor_param, gabor_params, gt_scenes, interleaved_runs, timed_runs

from stereovision import baselines
from stereovision._validate import as_gray_float
from stereovision.evaluate import dense_metrics, depth_metrics, gt_depth, saturated_gt_depth
from stereovision.io import find_scenes, load_scene
from stereovision.matching.gabor import gabor_disparity


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="", help="comma-separated substrings of scene names")
    ap.add_argument(
        "--param", action="append", default=[], type=gabor_param, help="key=JSON (repeatable)"
    )
    ap.add_argument("--no-cv", action="store_true", help="skip the OpenCV references")
    ap.add_argument("--runs", type=timed_runs, default=5, help="timed runs per side (median)")
    args = ap.parse_args()
    params = gabor_params(ap, args.param)
    wanted = [p for p in args.scenes.split(",") if p]
    if wanted and not any(p in name for name in gt_scenes() for p in wanted):
        # none matched: the means were NaN (NumPy's "Mean of empty slice") and the exit status 0
        ap.error(f"argument --scenes: no scene with GT matches {args.scenes!r}")
    cv2.setNumThreads(2)
    rows = []
    hdr = f"{'scene':38s} {'fill':>6s} {'unf':>6s} {'dens':>5s} {'BM':>6s} {'SGBM':>6s} {'ms':>6s}"
    hdr += f" {'SGBMms':>6s} {'ratio':>5s}"
    print(hdr)
    for d in find_scenes(DATA):
        scene = load_scene(d)
        name = scene.name
        if scene.gt is None or (wanted and not any(p in name for p in wanted)):
            continue
        gt, dmax = scene.gt, scene.max_disparity
        lf, rf = as_gray_float(scene.left, "left"), as_gray_float(scene.right, "right")
        fns = [partial(gabor_disparity, lf, rf, max_disparity=dmax, **params)]
        if not args.no_cv:  # evaluation.md's reference, interleaved with ours
            fns.append(partial(baselines.opencv_sgbm, scene.left, scene.right, dmax))
        times, outs = interleaved_runs(fns, args.runs)
        ms = times[0]
        ours = outs[0].disparity
        unf = dense_metrics(ours, gt)
        row = {
            "scene": name,
            "fill": dense_metrics(baselines.row_fill(ours), gt).bad[2.0],
            "unf": unf.bad[2.0],
            "dens": unf.density,
            "ms": ms,
        }
        if not args.no_cv:
            row["bm"] = dense_metrics(baselines.opencv_bm(scene.left, scene.right, dmax), gt).bad[
                2.0
            ]
            sg = outs[1]
            row["sgbm"] = dense_metrics(sg, gt).bad[2.0]
            row["sgbm_ms"] = times[1]
            calib = scene.calib
            if calib is not None and calib.rectified:
                zgt = gt_depth(gt, calib)
                # float16's largest depth (TartanAir's sky, 65504 m) is a clamp, not a distance:
                # left out as `stereovision eval` leaves it (evaluate.saturated_gt_depth)
                zgt[saturated_gt_depth(zgt)] = np.nan
                mo = depth_metrics(calib.depth_from_disparity(ours), zgt)
                mg = depth_metrics(calib.depth_from_disparity(sg), zgt)
                row["depth_ours"] = (mo.median_rel, mo.share_off_5)
                row["depth_sgbm"] = (mg.median_rel, mg.share_off_5)
                row["cov_ratio"] = mo.n / max(1, mg.n)
        rows.append(row)
        verdict = ""
        if "bm" in row:
            verdict = "  BEATS-BM" if row["bm"] > row["fill"] else "  LOSES-TO-BM"
        print(
            f"{name:38s} {row['fill']:6.1f} {row['unf']:6.1f} {row['dens']:5.1f} "
            f"{row.get('bm', np.nan):6.1f} {row.get('sgbm', np.nan):6.1f} {ms:6.1f} "
            f"{row.get('sgbm_ms', np.nan):6.1f} {ms / row.get('sgbm_ms', np.nan):5.2f}{verdict}"
        )
    mean = {k: float(np.mean([r[k] for r in rows])) for k in ("fill", "unf", "dens", "ms")}
    line = f"{'MEAN':38s} {mean['fill']:6.1f} {mean['unf']:6.1f} {mean['dens']:5.1f}"
    if not args.no_cv:
        mb, ms_ = np.mean([r["bm"] for r in rows]), np.mean([r["sgbm"] for r in rows])
        line += f" {mb:6.1f} {ms_:6.1f}   fill/SGBM = {mean['fill'] / ms_:.3f}"
    print(line)
    for r in rows:
        if "depth_ours" in r:
            (mo, fo), (mg, fg) = r["depth_ours"], r["depth_sgbm"]
            print(
                f"depth {r['scene']:28s} ours med {mo:5.2f}% >5% {fo:5.1f}%   "
                f"SGBM med {mg:5.2f}% >5% {fg:5.1f}%   coverage ours/SGBM {r['cov_ratio']:.3f}"
            )


if __name__ == "__main__":
    main()
