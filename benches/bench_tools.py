"""The default depth map against the matchers robotics users run as their tools ship them: ROS 2
``stereo_image_proc`` (BM and SGBM, the disparity node's defaults) and the ``StereoVision`` 1.0.4
package on PyPI (its BM and SGBM defaults), beside evaluation.md's SGBM-3WAY. Every matcher
searches the scene's range (``max_disparity`` rounded up to 16), the one setting a user fits to
the rig; everything else is the tool's default (``stereovision.baselines``).

Accuracy on every GT scene of ``shared/data``: bad-2.0 with holes counted (a hole is an error),
the same after evaluation.md's reference row fill (what a user can add to any of them), and the
density. Time on middlebury2006/cloth3 and middeval3/teddyH: every matcher interleaved in one run,
one warm-up, median of ``--repeats`` (>= 5), as a ratio to SGBM-3WAY's.

Usage: ``python benches/bench_tools.py [--repeats 5] [--no-accuracy] [--no-speed] [--json F]``
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np
from _common import DATA, gt_scenes, interleaved_ms, timed_runs

import stereovision as sv
from stereovision.baselines import (
    opencv_sgbm,
    ros_stereo_image_proc,
    row_fill,
    stereovision_1_0,
)
from stereovision.evaluate import dense_metrics
from stereovision.io import load_scene

Matcher = Callable[[np.ndarray, np.ndarray, int], np.ndarray]


def _ours(left: np.ndarray, right: np.ndarray, d: int, method: str = "fused") -> np.ndarray:
    return sv.depth_map(left, right, None, method=method, max_disparity=d).disparity


MATCHERS: dict[str, Matcher] = {
    "stereovision depth_map (fused, default)": _ours,
    'stereovision depth_map(method="fast")': partial(_ours, method="fast"),
    "OpenCV SGBM-3WAY (evaluation.md)": opencv_sgbm,
    "ROS stereo_image_proc, BM (default)": partial(ros_stereo_image_proc, algorithm="bm"),
    "ROS stereo_image_proc, SGBM (stereo_algorithm 1)": partial(
        ros_stereo_image_proc, algorithm="sgbm"
    ),
    "StereoVision 1.0.4 (PyPI), StereoBM": partial(stereovision_1_0, algorithm="bm"),
    "StereoVision 1.0.4 (PyPI), StereoSGBM": partial(stereovision_1_0, algorithm="sgbm"),
}
SPEED_SCENES = ("middlebury2006/cloth3", "middeval3/teddyH")


def accuracy() -> dict[str, dict[str, dict[str, float]]]:
    """``{matcher: {scene: {bad2, bad2_filled, density}}}`` over every GT scene."""
    out: dict[str, dict[str, dict[str, float]]] = {name: {} for name in MATCHERS}
    for rel in gt_scenes():
        scene = load_scene(DATA / rel)
        assert scene.gt is not None and scene.max_disparity is not None
        for name, fn in MATCHERS.items():
            disp = fn(scene.left, scene.right, scene.max_disparity)
            raw = dense_metrics(disp, scene.gt)
            filled = dense_metrics(row_fill(disp), scene.gt)
            out[name][rel] = {
                "bad2": round(raw.bad[2.0], 2),
                "bad2_filled": round(filled.bad[2.0], 2),
                "density": round(raw.density, 2),
            }
        print(f"  {rel}", file=sys.stderr, flush=True)
    return out


def speed(repeats: int) -> dict[str, dict[str, float]]:
    """``{scene: {matcher: median ms}}``, all matchers interleaved on each scene."""
    out: dict[str, dict[str, float]] = {}
    for rel in SPEED_SCENES:
        scene = load_scene(DATA / rel)
        d = scene.max_disparity
        assert d is not None
        fns = [partial(fn, scene.left, scene.right, d) for fn in MATCHERS.values()]
        out[rel] = dict(zip(MATCHERS, interleaved_ms(fns, repeats), strict=True))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=timed_runs, default=5, help="timed runs per matcher (>= 5)")
    ap.add_argument("--no-accuracy", action="store_true")
    ap.add_argument("--no-speed", action="store_true")
    ap.add_argument("--json", type=Path, help="also write the figures here")
    args = ap.parse_args(argv)
    if args.json is not None and args.json.is_dir():  # refused before the run, not after it
        ap.error(f"argument --json: {args.json}: is a folder; give a file such as figures.json")
    figures: dict[str, object] = {}
    if not args.no_accuracy:
        acc = accuracy()
        figures["accuracy"] = acc
        scenes = sorted(next(iter(acc.values())))
        print(
            f"\nbad-2.0 (%, holes counted) over the {len(scenes)} GT scenes: mean, worst, and "
            "scenes where the default is better"
        )
        print(
            "| matcher | bad-2.0 mean | worst | + row fill, mean | density, mean | default better |"
        )
        print("|---|---|---|---|---|---|")
        ours = acc[next(iter(MATCHERS))]
        for name, per in acc.items():
            bad = [per[s]["bad2"] for s in scenes]
            worst = max(scenes, key=lambda s: per[s]["bad2"])
            better = (
                "-"
                if per is ours
                else f"{sum(ours[s]['bad2'] < per[s]['bad2'] for s in scenes)} of {len(scenes)}"
            )
            print(
                f"| {name} | {statistics.mean(bad):.2f} | {per[worst]['bad2']:.2f} "
                f"({worst.split('/')[1]}) | "
                f"{statistics.mean(per[s]['bad2_filled'] for s in scenes):.2f} | "
                f"{statistics.mean(per[s]['density'] for s in scenes):.1f} | "
                f"{better} |"
            )
    if not args.no_speed:
        sp = speed(args.repeats)
        figures["speed_ms"] = sp
        ref = "OpenCV SGBM-3WAY (evaluation.md)"
        print(f"\ntime, median of {args.repeats} interleaved runs (ms; x SGBM-3WAY's)")
        print("| matcher | " + " | ".join(SPEED_SCENES) + " |")
        print("|---|" + "---|" * len(SPEED_SCENES))
        for name in MATCHERS:
            cells = [f"{sp[s][name]:.0f} ({sp[s][name] / sp[s][ref]:.2f} x)" for s in SPEED_SCENES]
            print(f"| {name} | " + " | ".join(cells) + " |")
    if args.json:
        # a new folder made, as the pictures' are: its write_text's FileNotFoundError came after
        # the whole run, the figures printed but not kept
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(figures, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
