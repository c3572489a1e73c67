"""A fisheye rig end to end, rendered with exact geometry (docs/robotics.md's figures and
docs/images/fisheye_rig.jpg). One run.

1. Calibration: 40 ChArUco pairs rendered through a fisheye rig (480x360, about 130 x 100
   degrees, baseline 100 mm; the set-up of tests/test_fisheye.py), calibrated with
   ``distortion="fisheye"`` and with the pinhole models. Scored on the true rig's points 1-6 m
   away: rotation error, rows after rectification.
2. Depth: a textured wall 1.5 / 2.5 / 4 m away rendered through the true rig, then the default
   ``depth_map`` with the calibration found in 1: coverage of the rectified image and the depth
   error against the wall.

Usage: ``python benches/bench_fisheye.py [--picture PATH]``
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from _common import DATA, picture_path, write_picture

import stereovision as sv
from stereovision.calibrate import calibrate
from stereovision.calibration import Calibration

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests import test_fisheye as rig  # noqa: E402  (the rig and views of the tests)


def wall(calib: Calibration, z_wall: float) -> tuple[np.ndarray, np.ndarray, Any, np.ndarray]:
    tex = cv2.imread(str(DATA / "middlebury2003" / "cones" / "left.png"), cv2.IMREAD_COLOR)
    left, right = rig.render_wall(tex, z_wall)
    res = sv.depth_map(left, right, calib, max_disparity=32)
    return left, right, res, rig.wall_depth(calib, z_wall)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--picture", type=picture_path, default=ROOT / "docs/images/fisheye_rig.jpg")
    args = ap.parse_args()
    views = rig.render_views()
    found = {}
    for dist in ("fisheye", "auto", "rational"):
        cal, rep = calibrate(*views, board=rig.BOARD, distortion=dist)
        dy = rig._row_errors(cal)
        ang = math.degrees(float(np.linalg.norm(cv2.Rodrigues(cal.R @ rig.ROT.T)[0])))
        print(
            f"calibrate distortion={dist}: {len(rep.used_pairs)} pairs, {rep.corners_used} "
            f"corners, RMS {rep.rms:.3f} px, rotation off {ang:.3f} deg, baseline "
            f"{1000 * cal.baseline:.2f} mm (true 100.03), rows of the true points: median "
            f"{np.median(dy):.3f} px, 95th pct {np.percentile(dy, 95):.3f} px"
        )
        found[dist] = cal
    for z in (1.5, 2.5, 4.0):
        for name in ("true rig", "fisheye calibration"):
            cal = rig.TRUTH if name == "true rig" else found["fisheye"]
            left, right, res, z_true = wall(cal, z)
            ok = np.isfinite(res.depth)
            rel = np.abs(res.depth[ok] / z_true[ok] - 1)
            print(
                f"wall at {z} m, {name}: {100 * ok.mean():.1f} % of the rectified image, depth "
                f"error median {100 * np.median(rel):.2f} %, 95th pct "
                f"{100 * np.percentile(rel, 95):.2f} %"
            )
    left, right, res, _ = wall(found["fisheye"], 2.5)
    rl, _ = found["fisheye"].rectify(left, right)
    d = res.depth
    vis = np.zeros((*d.shape, 3), np.uint8)
    ok = np.isfinite(d)
    norm = np.clip((d - 1.5) / 3.0, 0, 1)
    vis[ok] = cv2.applyColorMap((255 * (1 - norm[ok])).astype(np.uint8).reshape(-1, 1),
                                cv2.COLORMAP_TURBO).reshape(-1, 3)  # fmt: skip
    panels = [left, rl, vis]
    for p, text in zip(
        panels, ("raw fisheye left", "rectified left", "depth 1.5-4.5 m"), strict=True
    ):
        cv2.rectangle(p, (0, 0), (8 + 9 * len(text), 22), (30, 30, 30), -1)
        cv2.putText(
            p, text, (4, 16), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1, cv2.LINE_AA
        )
    gap = np.full((left.shape[0], 6, 3), 255, np.uint8)
    write_picture(args.picture, np.hstack([panels[0], gap, panels[1], gap, panels[2]]))
    print(f"wrote {args.picture}")


if __name__ == "__main__":
    main()
