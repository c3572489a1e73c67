"""Hopfield channel bench (issue 4): accuracy on every scene with GT and speed vs SGBM-3WAY.

Accuracy: for every scene of ``../shared/data`` with ``gt_disp.pfm``, the network
(``method="hopfield"``) and the best-match reference without the network (``method="best"``: same
points, candidates and filters) in the same run, timed interleaved (network, reference, ...),
median of ``--repeats`` runs after a warm-up; evaluation.md's sparse metrics: precision@0.5/1/2,
count with GT, 4x4 coverage. ``ref_count_at_net_precision``: the reference's matches ranked by
ZNCC and cut to the longest prefix whose precision@1 reaches the network's (count at equal
precision). Speed: OpenCV SGBM-3WAY (evaluation.md configuration) and the network on
middlebury2006/cloth3 and middeval3/teddyH, interleaved (SGBM, network, SGBM, ...), median of
``--repeats`` runs after a warm-up, ratio printed. One JSON line per case.

Usage: ``python benches/bench_hopfield.py [--scenes a,b] [--repeats 7] [--no-speed]``
"""

from __future__ import annotations

import argparse
import json
from functools import partial

from _common import (
    DATA,
    count_at,
    gt_scene_list,
    gt_scenes,
    interleaved_ms,
    interleaved_runs,
    sparse_row,
    timed_runs,
)

from stereovision import io
from stereovision._validate import as_gray_float
from stereovision.baselines import opencv_sgbm
from stereovision.matching.hopfield import best_match, hopfield_match

SPEED_SCENES = ("middlebury2006/cloth3", "middeval3/teddyH")
#: Target of issue 4: the network takes under a third of SGBM-3WAY's time.
SPEED_TARGET = 1.0 / 3.0


def accuracy(scenes: list[str], repeats: int) -> None:
    for name in scenes:
        sc = io.load_scene(DATA / name)
        assert sc.gt is not None
        left, right = as_gray_float(sc.left), as_gray_float(sc.right)
        # evaluation.md "Speed": interleaved, median of >= 5 runs after a warm-up (one run of
        # each gave whichever side the machine's other load happened to hit the slower time)
        (ms_net, ms_ref), (net, ref) = interleaved_runs(
            [partial(run, left, right, max_disparity=sc.max_disparity)
             for run in (hopfield_match, best_match)],
            repeats,
        )  # fmt: skip
        mn, mr = sparse_row(net, sc.gt), sparse_row(ref, sc.gt)
        line = {
            "case": "accuracy",
            "scene": name,
            "network": {**mn, "ms": round(ms_net, 1)},
            "reference": {**mr, "ms": round(ms_ref, 1)},
            "repeats": repeats,
            # null when the network has no match with GT (its precision is NaN)
            "ref_count_at_net_precision": count_at(ref, sc.gt, float(mn["p1"])),
            "sweeps": net.stats["sweeps"],
            "converged": net.stats["converged"],
            "n_points": net.stats["n_points"],
            "n_neurons": net.stats["n_neurons"],
            "n_weights": net.stats["n_weights"],
        }
        print(json.dumps(line), flush=True)


def speed(repeats: int) -> None:
    for name in SPEED_SCENES:
        sc = io.load_scene(DATA / name)

        def run_sgbm(sc: io.Scene = sc) -> None:
            opencv_sgbm(sc.left, sc.right, sc.max_disparity)

        def run_net(sc: io.Scene = sc) -> None:
            hopfield_match(sc.left, sc.right, max_disparity=sc.max_disparity)

        ms_s, ms_n = interleaved_ms((run_sgbm, run_net), repeats)
        ratio = ms_n / ms_s
        print(
            json.dumps(
                {
                    "case": "speed",
                    "scene": name,
                    "sgbm3way_ms": round(ms_s, 1),
                    "hopfield_ms": round(ms_n, 1),
                    "ratio": round(ratio, 3),
                    "target": round(SPEED_TARGET, 3),
                    "met": ratio < SPEED_TARGET,
                    "repeats": repeats,
                }
            ),
            flush=True,
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--scenes",
        default="",
        type=gt_scene_list,
        help="comma-separated family/scene (default: all)",
    )
    ap.add_argument("--repeats", type=timed_runs, default=7)
    ap.add_argument("--no-speed", action="store_true")
    ap.add_argument("--no-accuracy", action="store_true")
    args = ap.parse_args()
    scenes = args.scenes or gt_scenes()
    if not args.no_accuracy:
        accuracy(scenes, args.repeats)
    if not args.no_speed:
        speed(args.repeats)


if __name__ == "__main__":
    main()
