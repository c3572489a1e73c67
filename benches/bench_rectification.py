"""The rectification check and its correction on the GT scenes (the README's figures). One run.

1. ``check_rectification`` on every GT scene as given, and with the right image moved 1 px down:
   median |dy| and the change of the fitted offset.
2. ``refine_rectification``: rectified scenes seen through a rig calibration (f 700 px) that
   says the right camera is pitched by 0.2 / 0.5 degrees; the default ``depth_map``'s bad-2.0
   in the left image's frame as given, bumped and refined, and the rotation left after it.
3. ``refine_rectification`` on the metric scenes' own calibrations.

Usage: ``python benches/bench_rectification.py [--skip-depth]``
"""

from __future__ import annotations

import argparse
import dataclasses

import cv2
import numpy as np
from _common import DATA, gt_scenes

import stereovision as sv
from stereovision.calibration import Calibration
from stereovision.evaluate import dense_metrics
from stereovision.io import load_scene
from stereovision.rectification_check import check_rectification, refine_rectification

BUMPED = ("middlebury2003/cones", "middlebury2005/art", "eth3d/terrace", "kitti2015/000005_10")


def in_left_frame(c: Calibration, disp: np.ndarray) -> np.ndarray:
    """A rectified-frame disparity map sampled at the original left pixels (no distortion)."""
    if c.rectified:
        return disp
    r1, _, p1, _, _ = c._stereo_rectify(0.0)
    hom = p1[:, :3] @ r1 @ np.linalg.inv(c.K1)
    h, w = disp.shape
    flags = cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP
    return cv2.warpPerspective(disp, hom, (w, h), flags=flags, borderValue=np.nan)


def bad2(scene, calib: Calibration) -> float:
    r = sv.depth_map(scene.left, scene.right, calib, max_disparity=scene.max_disparity)
    return float(dense_metrics(in_left_frame(calib, r.disparity), scene.gt).bad[2.0])


def degrees(rot: np.ndarray) -> float:
    return float(np.degrees(np.linalg.norm(cv2.Rodrigues(rot)[0])))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--skip-depth", action="store_true", help="only part 1 (a few seconds)")
    args = ap.parse_args()
    moves = []
    for name in gt_scenes():
        s = load_scene(DATA / name)
        h, w = s.right.shape[:2]
        down = cv2.warpAffine(
            s.right, np.float32([[1, 0, 0], [0, 1, 1.0]]), (w, h), borderMode=cv2.BORDER_REFLECT
        )
        a, b = check_rectification(s.left, s.right), check_rectification(s.left, down)
        moves.append(b.offset - a.offset)
        print(
            f"{name:38s} as given {a.median_dy:.3f} px ok {a.ok}; 1 px down: offset "
            f"{b.offset - a.offset:+.3f} px ok {b.ok}"
        )
    print(f"offset change for 1 px: {min(moves):+.3f} to {max(moves):+.3f} px")
    if args.skip_depth:
        return
    for name in BUMPED:
        s = load_scene(DATA / name)
        h, w = s.left.shape[:2]
        k = np.array([[700.0, 0, (w - 1) / 2], [0, 700.0, (h - 1) / 2], [0, 0, 1]])
        good = Calibration(
            K1=k,
            D1=np.zeros(5),
            K2=k,
            D2=np.zeros(5),
            R=np.eye(3),
            T=np.array([-0.1, 0.0, 0.0]),
            image_size=(w, h),
            unit="m",
        )
        for deg in (0.2, 0.5):
            rot = cv2.Rodrigues(np.array([np.radians(deg), 0.0, 0.0]))[0]
            bumped = dataclasses.replace(good, R=rot)
            fixed, after = refine_rectification(s.left, s.right, bumped)
            print(
                f"{name:24s} pitch {deg} deg: bad-2.0 given {bad2(s, good):.1f} / bumped "
                f"{bad2(s, bumped):.1f} / refined {bad2(s, fixed):.1f} %; rows "
                f"{after.median_dy:.2f} px; rotation left {degrees(fixed.R):.3f} deg",
                flush=True,
            )
    for name in gt_scenes():
        s = load_scene(DATA / name)
        if s.calib is None:
            continue
        fixed, after = refine_rectification(s.left, s.right, s.calib)
        before = check_rectification(s.left, s.right, s.calib)
        print(
            f"{name:38s} own calibration: rows {before.median_dy:.2f} -> {after.median_dy:.2f}"
            f" px, turn {degrees(fixed.R):.3f} deg, bad-2.0 {bad2(s, s.calib):.2f} -> "
            f"{bad2(s, fixed):.2f} %",
            flush=True,
        )


if __name__ == "__main__":
    main()
