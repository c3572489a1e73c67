"""The ground plane and obstacles on the scenes with a metric calibration, against the plane of
their own GT (docs/robotics.md's table and docs/images/ground_kitti.jpg), and KITTI's laser
scan beside OpenCV SGBM-3WAY's. One run; the fit's time against SGBM-3WAY's on the same pair
(evaluation.md "Speed": interleaved, median of ``--runs`` after a warm-up).

For each scene: the floor found in the GT disparity and in the default ``depth_map``'s (RANSAC
in disparity space, :func:`stereovision.fit_ground_plane`), the angle between them, the
camera's height, pitch and roll from each, the share of the points measurably below each
(``GroundPlane.below_share``), and the obstacle pixels (0.15-2 m above the floor,
within 30 m) of our map against those of the GT, on the pixels with GT. Then the rendered floor
of tests/test_ground.py (camera 1.1 m up, pitched 12 degrees down, rolled 3).

Usage: ``python benches/bench_ground.py [--picture PATH] [--runs 5]``
"""

from __future__ import annotations

import argparse
import math
import sys
from functools import partial
from pathlib import Path

import cv2
import numpy as np
from _common import DATA, interleaved_runs, picture_path, timed_runs, write_picture
from scipy.ndimage import binary_dilation

import stereovision as sv
from stereovision.ground import fit_ground_plane, laser_scan, obstacle_mask, occupancy_grid
from stereovision.io import load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENES = (
    "kitti2015/000005_10",
    "eth3d/playground",
    "eth3d/terrace",
    "tartanair/oldtown_easy_p000_001116",
)


def _scan_table(
    sc: object, gt: object, fused: np.ndarray, pts_gt: np.ndarray, has: np.ndarray
) -> None:
    """The laser scan of each map against the GT's, on the GT's floor and pixels."""
    from stereovision.baselines import opencv_sgbm, row_fill

    sgbm = opencv_sgbm(sc.left, sc.right, sc.max_disparity)  # type: ignore[attr-defined]
    maps = {"fused (default)": fused, "SGBM-3WAY": sgbm, "SGBM-3WAY + fill": row_fill(sgbm)}
    calib = sc.calib  # type: ignore[attr-defined]
    for far in (15.0, 30.0):
        inside = has & (pts_gt[..., 2] < far + 5)
        truth = laser_scan(pts_gt[inside], gt, calib, range_max=far)  # type: ignore[arg-type]
        hit = np.isfinite(truth.ranges)
        for name, d in maps.items():
            s = laser_scan(calib.reproject(d)[inside], gt, calib, range_max=far)  # type: ignore[arg-type]
            both = hit & np.isfinite(s.ranges)
            rel = np.abs(s.ranges[both] / truth.ranges[both] - 1)
            false = int((np.isinf(truth.ranges) & np.isfinite(s.ranges)).sum())
            print(
                f"  scan within {far:g} m, pixels with GT, GT floor: {name}: {int(both.sum())} of "
                f"{int(hit.sum())} beams hit, median |error| {100 * np.median(rel):.2f} %, "
                f"{100 * np.mean(rel < 0.05):.1f} % within 5 %, {false} hits where the GT "
                "sees free floor"
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--picture", type=picture_path, default=ROOT / "docs/images/ground_kitti.jpg")
    ap.add_argument("--runs", type=timed_runs, default=5, help="timed runs per side (median)")
    args = ap.parse_args()
    for name in SCENES:
        sc = load_scene(DATA / name)
        assert sc.calib is not None and sc.gt is not None
        gt = fit_ground_plane(sc.gt, sc.calib)
        res = sv.depth_map(sc.left, sc.right, sc.calib, max_disparity=sc.max_disparity)
        from stereovision.baselines import opencv_sgbm

        (fit_ms, sgbm_ms), (ours, _) = interleaved_runs(
            [partial(fit_ground_plane, res.disparity, sc.calib),
             partial(opencv_sgbm, sc.left, sc.right, sc.max_disparity)],
            args.runs,
        )  # fmt: skip
        if gt is None or ours is None:
            print(f"{name}: GT plane {gt is not None}, ours {ours is not None}")
            continue
        angle = math.degrees(math.acos(min(1.0, float(gt.normal @ ours.normal))))
        pts_gt = sc.calib.reproject(sc.gt)
        has = np.all(np.isfinite(pts_gt), axis=-1) & (pts_gt[..., 2] < 30)
        truth = obstacle_mask(pts_gt, gt, max_range=30) & has
        pts = sc.calib.reproject(res.disparity)
        found = obstacle_mask(pts, ours, max_range=30) & has
        tp = int((found & truth).sum())
        # what `depth --ground` marks: the pixels with a depth only (no filled guesses)
        kept = obstacle_mask(res.point_image(), ours, max_range=30) & has
        tp_kept = int((kept & truth).sum())
        dh = 100 * (ours.height / gt.height - 1)
        print(
            f"{name}: GT height {gt.height:.3f} m, pitch {gt.pitch_deg:+.2f}, roll "
            f"{gt.roll_deg:+.2f}; ours {ours.height:.3f} m ({dh:+.1f} %), pitch "
            f"{ours.pitch_deg:+.2f}, roll {ours.roll_deg:+.2f}; {angle:.2f} deg apart; "
            f"{100 * ours.inlier_share:.0f} % on it, {100 * ours.below_share:.1f} % below it "
            f"(GT's: {100 * gt.below_share:.1f} % below its own); "
            f"fit {fit_ms:.0f} ms ({fit_ms / sgbm_ms:.2f} x SGBM-3WAY's {sgbm_ms:.0f} ms); "
            f"obstacles precision "
            f"{tp / max(int(found.sum()), 1):.3f} recall {tp / max(int(truth.sum()), 1):.3f}; "
            f"on the pixels with a depth ({100 * np.isfinite(res.depth).mean():.0f} %): "
            f"precision {tp_kept / max(int(kept.sum()), 1):.3f} recall "
            f"{tp_kept / max(int(truth.sum()), 1):.3f}"
        )
        if name.startswith("kitti"):
            img = sc.left.copy()
            on = ours.inliers
            img[on] = (0.5 * img[on] + 0.5 * np.array([60, 200, 60])).astype(np.uint8)
            ob = obstacle_mask(pts, ours, max_range=30)
            img[ob] = (0.5 * img[ob] + 0.5 * np.array([40, 40, 230])).astype(np.uint8)
            text = ours.describe().split(" (")[0]
            cv2.rectangle(img, (0, 0), (12 + 8 * len(text), 24), (30, 30, 30), -1)
            cv2.putText(img, text, (6, 17), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1,
                        cv2.LINE_AA)  # fmt: skip
            grid = occupancy_grid(pts, ours, resolution=0.1, forward=(0, 30), lateral=(-15, 15))
            bev = cv2.cvtColor(grid.image(), cv2.COLOR_GRAY2BGR)
            bev = cv2.rotate(bev, cv2.ROTATE_90_COUNTERCLOCKWISE)  # forward up, left to the left
            side = img.shape[0]
            bev = cv2.resize(bev, (side, side), interpolation=cv2.INTER_NEAREST)
            # the laser scan's hits: x forward (up), y left (to the left), 30 m over the side
            scan = laser_scan(pts, ours, sc.calib, range_max=30.0)
            for x, y in scan.endpoints():
                u, v = side / 2 - y * side / 30, side - x * side / 30
                cv2.circle(bev, (int(u), int(v)), 1, (200, 120, 0), -1)
            cv2.putText(bev, "grid 0.1 m, 30 m ahead", (6, 17), cv2.FONT_HERSHEY_SIMPLEX, 0.5,
                        (40, 40, 230), 1, cv2.LINE_AA)  # fmt: skip
            cv2.putText(bev, "laser scan", (6, 35), cv2.FONT_HERSHEY_SIMPLEX, 0.5,
                        (200, 120, 0), 1, cv2.LINE_AA)  # fmt: skip
            gap = np.full((img.shape[0], 6, 3), 255, np.uint8)
            write_picture(args.picture, np.hstack([img, gap, bev]))
            print(f"wrote {args.picture}")
            for far in (15.0, 30.0):
                kw = {"resolution": 0.2, "forward": (0.0, far), "lateral": (-far / 2, far / 2)}
                occ_gt = occupancy_grid(pts_gt[has], gt, **kw).data == 100
                occ = occupancy_grid(pts[has], ours, **kw).data == 100
                prec = (occ & binary_dilation(occ_gt)).sum() / max(int(occ.sum()), 1)
                rec = (occ_gt & binary_dilation(occ)).sum() / max(int(occ_gt.sum()), 1)
                print(
                    f"  grid within {far:g} m, 0.2 m cells, pixels with GT: occupied cells "
                    f"precision {prec:.3f} recall {rec:.3f} within one cell"
                )
            _scan_table(sc, gt, res.disparity, pts_gt, has)
    sys.path.insert(0, str(ROOT))
    from tests import test_ground as tg

    scene = tg.scene.__wrapped__(DATA)  # the pytest fixture's own function
    res = sv.depth_map(scene["left"], scene["right"], tg.RIG, max_disparity=64)
    plane = fit_ground_plane(res.disparity, tg.RIG)
    assert plane is not None
    print(
        f"rendered floor (true: 1.100 m, pitch +12.00, roll +3.00): {plane.describe()}; "
        f"{100 * plane.below_share:.1f} % below it"
    )


if __name__ == "__main__":
    main()
