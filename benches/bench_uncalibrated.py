"""Rectification without a calibration (docs/robotics.md's table and
docs/images/uncalibrated_rectification.jpg). One run; the rectification's time against OpenCV
SGBM-3WAY's on the bumped pair (evaluation.md "Speed": interleaved, median of ``--runs`` after a
warm-up).

For every scene with GT: its right image turned 1.5 degrees, 1 % larger, 3 px lower and tilted
(``tests/test_uncalibrated.perturbation``: a bumped camera), then the default depth map's bad-2.0
on the pair as given, on the bumped pair as it is, and on the bumped pair rectified from its own
features, with the default model and with OpenCV's projective homographies of ``F`` alone (the GT
carried through the homographies; the pixels of the rectified left image with GT whose match the
bumped camera still sees); and the rectification's rows, search range and time. Then StereoPi's
raw pair and OpenCV's hand-held books pair, with the shape of OpenCV's own homographies beside
ours.

Usage: ``python benches/bench_uncalibrated.py [--scenes S ...] [--picture PATH] [--runs 5]``
"""

from __future__ import annotations

import argparse
import sys
from functools import partial
from pathlib import Path

import cv2
import numpy as np
from _common import (
    DATA,
    gt_scene,
    gt_scenes,
    interleaved_runs,
    picture_path,
    timed_runs,
    write_picture,
)

import stereovision as sv
from stereovision.baselines import opencv_sgbm
from stereovision.evaluate import dense_metrics
from stereovision.rectification_check import (
    _features,
    _mutual_matches,
    check_rectification,
    draw_rectification_check,
)
from stereovision.uncalibrated import _shape, rectify_uncalibrated

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests.test_uncalibrated import expected_disparity, perturbed_scene  # noqa: E402


def _opencv_shape(left: np.ndarray, right: np.ndarray, fm: np.ndarray) -> tuple:
    """Skew and aspect of OpenCV's own homographies for the same F, on F's matches."""
    gl, gr = (cv2.cvtColor(i, cv2.COLOR_BGR2GRAY) for i in (left, right))
    (pl, dl), (pr, dr) = _features(gl), _features(gr)
    pairs = _mutual_matches(dl, dr)
    p1, p2 = pl[pairs[:, 0]], pr[pairs[:, 1]]
    h1 = np.c_[p1, np.ones(len(p1))]
    lines = h1 @ fm.T
    dist = np.abs(np.sum(np.c_[p2, np.ones(len(p2))] * lines, axis=1)) / np.hypot(
        lines[:, 0], lines[:, 1]
    )
    fits = dist <= 1.0
    h, w = gl.shape
    _, a, b = cv2.stereoRectifyUncalibrated(p1[fits], p2[fits], fm, (w, h))
    return _shape(a, w, h), _shape(b, w, h)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--scenes", nargs="*", type=gt_scene, help="family/scene names (default: every GT scene)"
    )
    ap.add_argument("--runs", type=timed_runs, default=5, help="timed runs per side (median)")
    ap.add_argument(
        "--picture", type=picture_path, default=ROOT / "docs/images/uncalibrated_rectification.jpg"
    )
    args = ap.parse_args()
    print(
        "| scene | bad-2.0 as given | bumped, as it is | bumped, rectified from its features "
        "| the same, projective only | rows after, median / 95 % (px) | search range (scene's) "
        "| time (ms; x SGBM-3WAY's) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    ratios: dict[str, list[float]] = {"auto": [], "projective": []}
    for name in args.scenes or gt_scenes():
        sc, hp, right = perturbed_scene(DATA, name)
        md = sc.max_disparity
        given = dense_metrics(sv.depth_map(sc.left, sc.right, max_disparity=md).disparity, sc.gt)
        bumped = dense_metrics(sv.depth_map(sc.left, right, max_disparity=md).disparity, sc.gt)
        try:
            rect = rectify_uncalibrated(sc.left, right)
        except ValueError as exc:
            print(f"| {name} | {given.bad[2.0]:.2f} | {bumped.bad[2.0]:.2f} | refused: {exc} |")
            continue
        (rect_ms, sgbm_ms), _ = interleaved_runs(
            [
                partial(rectify_uncalibrated, sc.left, right),
                partial(opencv_sgbm, sc.left, right, md),
            ],
            args.runs,
        )
        bads = []
        projective = rectify_uncalibrated(sc.left, right, model="projective")
        for kind, r in (("auto", rect), ("projective", projective)):
            lr, rr = r.rectify(sc.left, right)
            want = expected_disparity(r, hp, sc.gt)
            got = sv.depth_map(lr, rr, max_disparity=r.max_disparity).disparity
            has = np.isfinite(want)
            bads.append(100 * float(np.mean(~(np.abs(got[has] - want[has]) <= 2.0))))
            ratios[kind].append(bads[-1] / given.bad[2.0])
        lr, rr = rect.rectify(sc.left, right)
        print(
            f"| {name} | {given.bad[2.0]:.2f} | {bumped.bad[2.0]:.2f} | {bads[0]:.2f} | "
            f"{bads[1]:.2f} | {rect.median_dy:.2f} / {rect.p95_dy:.2f} | {rect.max_disparity} "
            f"({md}) | {rect_ms:.0f} ({rect_ms / sgbm_ms:.2f} x SGBM-3WAY's {sgbm_ms:.0f}) |",
            flush=True,
        )
        if name == "middlebury2003/cones":
            before = draw_rectification_check(sc.left, right, check_rectification(sc.left, right))
            after = draw_rectification_check(lr, rr, check_rectification(lr, rr))
            width = max(before.shape[1], after.shape[1])
            pad = [
                cv2.copyMakeBorder(
                    i, 0, 6, 0, width - i.shape[1], cv2.BORDER_CONSTANT, value=(255, 255, 255)
                )
                for i in (before, after)
            ]
            write_picture(args.picture, np.vstack(pad))
            print(f"wrote {args.picture}")
    for kind, vals in ratios.items():
        if vals:
            print(
                f"{kind}: bad-2.0 over the pair as given's, mean {np.mean(vals):.3f}, worst "
                f"{np.max(vals):.3f}"
            )
    for label, folder, names in (
        ("StereoPi raw pair", DATA / "stereopi_rig" / "scene_photo", ("left.png", "right.png")),
        ("OpenCV books", DATA / "opencv_uncalibrated" / "books", ("left.jpg", "right.jpg")),
    ):
        left, right = (cv2.imread(str(folder / n)) for n in names)
        before = check_rectification(left, right)
        rect = rectify_uncalibrated(left, right)
        (s1, a1), (s2, a2) = _opencv_shape(left, right, rect.F)
        print(
            f"{label}: rows as taken median {before.median_dy:.2f} px; {rect.describe()}; "
            f"OpenCV's homographies alone: skew {s1:.2f} / {s2:.2f} deg, aspect {a1:.3f} / "
            f"{a2:.3f}"
        )


if __name__ == "__main__":
    main()
