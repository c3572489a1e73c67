"""Cameras that expose differently, noisy cameras, webcams' JPEG: on every GT scene
(docs/robotics.md, "Cameras that expose differently" and "Webcams: compressed or raw"). One run.

Two robot cameras with their own auto-exposure rarely agree. For each scene the right image is
made 0.6 times as bright, or given a gamma of 0.7 and a black level of +15 (of 255); or both
images get Gaussian noise of 8 grey levels (a camera in low light; seeded); or both go through
JPEG at quality 90 or 75 (a webcam's MJPG stream). The default depth map's bad-2.0 is measured
beside OpenCV SGBM-3WAY followed by evaluation.md's row fill, on the same pair.

Usage: ``python benches/bench_exposure.py [--scenes S ...]``
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np
from _common import DATA, gt_scene, gt_scenes

import stereovision as sv
from stereovision.baselines import opencv_sgbm, row_fill
from stereovision.evaluate import dense_metrics
from stereovision.io import load_scene

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tests.test_exposure import expose, jpeg, noisy

#: ``(gain, gamma, offset)`` of each case, applied as ``255 (gain x)^gamma + offset``.
CASES: dict[str, Any] = {
    "as given": None,
    "0.6 x darker": (0.6, 1.0, 0.0),
    "gamma 0.7, +15": (1.0, 0.7, 15.0),
    "noise 8": "noise",
    "JPEG 90": ("jpeg", 90),
    "JPEG 75": ("jpeg", 75),
}
#: Standard deviation (grey levels) of the noise case.
NOISE = 8.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--scenes", nargs="*", type=gt_scene, help="family/scene names (default: every GT scene)"
    )
    args = ap.parse_args()
    print("| scene | " + " | ".join(f"{c}: ours / SGBM-3WAY + fill" for c in CASES) + " |")
    print("|---" * (len(CASES) + 1) + "|")
    worst = {c: [0.0, 0.0] for c in CASES}
    for name in args.scenes or gt_scenes():
        sc = load_scene(DATA / name)
        cells = []
        for case, p in CASES.items():
            left, right = sc.left, sc.right
            if p == "noise":
                rng = np.random.default_rng(0)
                left, right = noisy(left, NOISE, rng), noisy(right, NOISE, rng)
            elif isinstance(p, tuple) and p[0] == "jpeg":
                left, right = jpeg(left, p[1]), jpeg(right, p[1])
            elif p is not None:
                right = expose(right, *p)
            res = sv.depth_map(left, right, max_disparity=sc.max_disparity)
            ours = dense_metrics(res.disparity, sc.gt).bad[2.0]
            theirs = dense_metrics(row_fill(opencv_sgbm(left, right, sc.max_disparity)),
                                   sc.gt).bad[2.0]  # fmt: skip
            cells.append(f"{ours:.2f} / {theirs:.2f}")
            worst[case] = [max(worst[case][0], ours), max(worst[case][1], theirs)]
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)
    for case, (a, b) in worst.items():
        print(f"{case}: worst scene ours {a:.2f} %, SGBM-3WAY + fill {b:.2f} %")


if __name__ == "__main__":
    main()
