"""Valid members of the channels' agreement vs each sparse channel alone, on every GT scene.

For each scene: the channels and their valid members as ``match(..., method="fused")`` gives them
(:func:`fuse_pair`: the Gabor map re-measured, ``mcgm``, ``hopfield``; vote mode, algorithms.md D.3
defaults; then the both-sides, edge and census checks on the members). Printed per scene:
precision@1 (@2 on KITTI, whose LiDAR GT sits about 0.4 px off), count with GT and 4x4 coverage of
the members and of each channel, and each channel's *count at the members' precision*: the most
matches it keeps, taken in decreasing score, while its precision stays at or above the members'
(the issue's "more of them than either sparse channel alone would give at that precision"). MCGM is
counted twice: as it votes (:data:`~stereovision.matching.fusion.MEMBER_MCGM`, B.8's settings) and
alone with its own, looser defaults (``mcgm_defaults``, what ``match(..., method="mcgm")``
returns). One JSON line per scene.

Usage: ``python benches/bench_fusion.py [SCENE ...]`` (default: every GT scene of shared/data)
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from _common import DATA, count_at, gt_scene

from stereovision._validate import as_gray_float
from stereovision.evaluate import sparse_metrics
from stereovision.io import find_scenes, load_scene
from stereovision.match import METHODS
from stereovision.matching.fusion import CHANNEL_BITS, fuse_pair
from stereovision.matching.mcgm import mcgm_match

#: The sparse channels (match.METHODS also has "gabor" since it gives Matches; fuse_pair keeps
#: the Gabor channel as a GaborResult, the dense map, not Matches).
SPARSE = [m for m in METHODS if m in CHANNEL_BITS and m != "gabor"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "scenes",
        nargs="*",
        type=gt_scene,
        help="scene folders or family/scene names (default: every GT scene)",
    )
    args = ap.parse_args()
    dirs = [Path(s) if Path(s).is_dir() else DATA / s for s in args.scenes] or find_scenes(DATA)
    print(f"channels: gabor + {' + '.join(SPARSE)}")
    for d in dirs:
        sc = load_scene(d)
        if sc.gt is None:
            continue
        tol = 2.0 if "kitti" in str(d) else 1.0
        md = int(sc.max_disparity)
        gl, gr = as_gray_float(sc.left, "left"), as_gray_float(sc.right, "right")
        res = fuse_pair(gl, gr, max_disparity=md)
        chans = {m: res.channel_outputs[m] for m in SPARSE}
        chans["mcgm_defaults"] = mcgm_match(gl, gr, max_disparity=md)
        fm = sparse_metrics(res.matches.xl, res.matches.yl, res.matches.xr, sc.gt)
        row = {
            "bench": "fusion",
            "scene": sc.name,
            "tol": tol,
            "members": {
                "precision": round(fm.precision[tol], 2),
                "count": fm.count,
                "coverage": fm.coverage,
                "three_agree": int((res.count == 3).sum()),
            },
        }
        line = f"{sc.name:36s} @{tol:.0f} members {fm.precision[tol]:6.2f} % {fm.count:6d}"
        line += f" {fm.coverage:2d}/16"
        for name, m in chans.items():
            cm = sparse_metrics(m.xl, m.yl, m.xr, sc.gt)
            # None (null, "-") when the members have no match with GT (their precision is NaN)
            at = count_at(m, sc.gt, fm.precision[tol], tol)
            row[name] = {
                "precision": round(cm.precision[tol], 2),
                "count": cm.count,
                "coverage": cm.coverage,
                "count_at_members_precision": at,
            }
            shown = "-" if at is None else str(at)
            line += (
                f" | {name} {cm.precision[tol]:6.2f} % {cm.count:6d} (at members' p: {shown:>6})"
            )
        print(line, flush=True)
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
