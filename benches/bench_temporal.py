"""A still rig's frames averaged over time (``stereovision.temporal.TemporalFilter``, ``stream
--temporal``): what it gains on still noisy scenes, what it does when the rig moves, and what it
costs per pair (docs/robotics.md, "A still rig in low light"). One run.

1. Still: every GT scene with seeded Gaussian noise of 4 or 8 grey levels on each colour channel,
   8 frames with fresh noise each; and noise 8 under a light that flickers by up to 4 %.
   Bad-2.0 of the default depth map on the last frame alone and on the filter's output after 8
   frames, beside the scene as given.
2. Moving: teddyH, reindeer and wood2 drifting by 0.25 or 1 px a frame (a panning rig;
   sub-pixel shifts by bilinear warping, the GT shifted with them), clean or with noise 8. Mean
   bad-2.0 over frames 2-8 unfiltered and filtered, the worst frame's difference, restarts.
3. Time: the filter per pair at 640x480 and 1280x720 beside the Gabor channel's depth map (the
   stream's default) on the same pair, interleaved, median of 7.

Usage: ``python benches/bench_temporal.py [--scenes S ...] [--skip-moving]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import cv2
import numpy as np
from _common import DATA, gt_scene, gt_scenes

import stereovision as sv
from stereovision.evaluate import dense_metrics
from stereovision.io import load_scene
from stereovision.temporal import TemporalFilter

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tests.test_exposure import noisy

FRAMES = 8
MOVING = ("middeval3/teddyH", "middlebury2005/reindeer", "middlebury2006/wood2")


def _bad2(left: np.ndarray, right: np.ndarray, gt: np.ndarray, md: float) -> float:
    res = sv.depth_map(left, right, max_disparity=md, cloud=False)
    return dense_metrics(res.disparity, gt).bad[2.0]


#: The still cases: noise (grey levels) and whether the light flickers (the whole image's gain
#: ``1 + 0.04 sin(2.1 k)`` on frame ``k``).
STILL = {"noise 4": (4.0, False), "noise 8": (8.0, False), "noise 8, flickering light": (8.0, True)}


def still(scenes: list[str]) -> None:
    print(
        "| scene | as given | " + " | ".join(f"{c}: one frame / 8 averaged" for c in STILL) + " |"
    )
    print("|---" * (len(STILL) + 2) + "|")
    gains: dict[str, list[float]] = {c: [] for c in STILL}
    for name in scenes:
        sc = load_scene(DATA / name)
        cells = [f"{_bad2(sc.left, sc.right, sc.gt, sc.max_disparity):.2f}"]
        for case, (sigma, flicker) in STILL.items():
            rng = np.random.default_rng(1)
            tf = TemporalFilter()
            for k in range(FRAMES):
                gain = 1.0 + 0.04 * np.sin(2.1 * k) if flicker else 1.0
                left, right = (
                    noisy(np.clip(i * gain, 0, 255).astype(np.uint8), sigma, rng)
                    for i in (sc.left, sc.right)
                )
                avg = tf(left, right)
            one = _bad2(left, right, sc.gt, sc.max_disparity)
            many = _bad2(*avg, sc.gt, sc.max_disparity)
            gains[case].append(many - one)
            cells.append(
                f"{one:.2f} / {many:.2f}" + (f" ({tf.restarts} restarts)" if tf.restarts else "")
            )
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)
    for case, g in gains.items():
        print(
            f"{case}: better on {sum(x < 0 for x in g)} of {len(g)} scenes, change "
            f"{min(g):+.2f} to {max(g):+.2f} points (mean {statistics.fmean(g):+.2f})"
        )


def _shift(a: np.ndarray, dx: float, margin: int, interp: int = cv2.INTER_LINEAR) -> np.ndarray:
    """``a`` moved ``dx`` px to the left (bilinear for images, nearest for GT), less the
    ``margin`` right columns that the move fills from outside."""
    h, w = a.shape[:2]
    m = np.float32([[1, 0, -dx], [0, 1, 0]])
    out = cv2.warpAffine(a, m, (w, h), flags=interp, borderMode=cv2.BORDER_REPLICATE)
    return np.ascontiguousarray(out[:, : w - margin])


def moving() -> None:
    print("\n| scene | noise | drift px/frame | unfiltered | filtered | worst frame | restarts |")
    print("|---|---|---|---|---|---|---|")
    for name in MOVING:
        sc = load_scene(DATA / name)
        margin = FRAMES + 2  # columns the fastest drift brings in from outside
        gt0 = np.nan_to_num(sc.gt.astype(np.float32), nan=-1.0)
        for sigma in (0.0, 8.0):
            for speed in (0.25, 1.0):
                rng = np.random.default_rng(1)
                tf = TemporalFilter()
                raw, filt = [], []
                for k in range(FRAMES):
                    dx = speed * k

                    left = noisy(_shift(sc.left, dx, margin), sigma, rng)
                    right = noisy(_shift(sc.right, dx, margin), sigma, rng)
                    gt = _shift(gt0, dx, margin, cv2.INTER_NEAREST)
                    gt[gt < 0] = np.nan
                    out = tf(left, right)
                    if k == 0:
                        continue
                    raw.append(_bad2(left, right, gt, sc.max_disparity))
                    same = np.array_equal(out[0], left) and np.array_equal(out[1], right)
                    filt.append(raw[-1] if same else _bad2(*out, gt, sc.max_disparity))
                worst = max(np.subtract(filt, raw))
                cells = [f"{statistics.fmean(raw):.2f}", f"{statistics.fmean(filt):.2f}"]
                cells += [f"{worst:+.2f}", f"{tf.restarts} of {FRAMES - 1}"]
                print(f"| {name} | {sigma:g} | {speed:g} | " + " | ".join(cells) + " |", flush=True)


def timing() -> None:
    sc = load_scene(DATA / "tartanair/oldtown_easy_p000_001116")
    print("\n| size | filter ms | Gabor depth map ms | ratio |")
    print("|---|---|---|---|")
    for size in ((640, 480), (1280, 720)):
        left, right = (
            cv2.resize(i, size, interpolation=cv2.INTER_LINEAR) for i in (sc.left, sc.right)
        )
        rng = np.random.default_rng(0)
        frames = [(noisy(left, 4.0, rng), noisy(right, 4.0, rng)) for _ in range(8)]
        tf = TemporalFilter()
        for fr in frames:
            tf(*fr)
        md = sc.max_disparity * size[0] / sc.left.shape[1]
        sv.depth_map(left, right, method="gabor", max_disparity=md, cloud=False)
        t_f, t_g = [], []
        for k in range(7):
            t0 = time.perf_counter()
            tf(*frames[k % len(frames)])
            t1 = time.perf_counter()
            sv.depth_map(left, right, method="gabor", max_disparity=md, cloud=False, refine=False)
            t2 = time.perf_counter()
            t_f.append(t1 - t0)
            t_g.append(t2 - t1)
        f, g = 1e3 * statistics.median(t_f), 1e3 * statistics.median(t_g)
        print(f"| {size[0]}x{size[1]} | {f:.1f} | {g:.1f} | {f / g:.2f} |", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--scenes", nargs="*", type=gt_scene, help="family/scene names (default: every GT scene)"
    )
    ap.add_argument("--skip-moving", action="store_true", help="only the still scenes and time")
    args = ap.parse_args()
    still(args.scenes or gt_scenes())
    if not args.skip_moving:
        moving()
    timing()


if __name__ == "__main__":
    main()
