"""Where the default ``depth_map``'s time goes (issue 5, point 3), beside SGBM-3WAY in the same run.

For each scene: OpenCV SGBM-3WAY (evaluation.md configuration), the whole default ``depth_map``
(fused, filled), each channel run alone (the Gabor channel, its re-measure, MCGM, Hopfield, the
census semi-global map), then the stages after the channels on their cached outputs: the vote
(:func:`fuse`), the member checks ``fuse_pair`` runs (B.8's both-sides check on the members MCGM is
not part of, the edge check on the re-measured Gabor map), the dense map (:func:`fused_dense`) and
the fill (:func:`~stereovision.depth.fill_holes`: the planes, the colour side rule, the reference
row rule, the enclosed far regions).
Interleaved (SGBM, whole, channel, ..., SGBM, ...), median of ``--repeats`` after a warm-up;
each case's ms and its ratio to SGBM.
The channels run side by side in ``depth_map`` (their times do not add up to its own); the
stages after them run one after another. One JSON line per case, then a table.

Usage: ``python benches/bench_stages.py [--repeats 7] [SCENE ...]`` (default: cloth3 and teddyH)
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
from _common import DATA, interleaved_ms, scene_folder, timed_runs

from stereovision import depth_map
from stereovision._validate import as_gray_float
from stereovision.baselines import opencv_sgbm
from stereovision.depth import fill_holes
from stereovision.io import load_scene
from stereovision.matching import fusion
from stereovision.matching.gabor import gabor_disparity
from stereovision.matching.hopfield import hopfield_match
from stereovision.matching.mcgm import mcgm_match
from stereovision.matching.sgm import sgm_disparity

SCENES = ("middlebury2006/cloth3", "middeval3/teddyH")


def cases(scene: Path) -> dict[str, Callable[[], object]]:
    """The timed cases of one scene (the stages after the channels on cached outputs)."""
    sc = load_scene(scene)
    md = sc.max_disparity
    gl, gr = as_gray_float(sc.left), as_gray_float(sc.right)
    g = gabor_disparity(gl, gr, max_disparity=md)
    base = fusion.remeasure(gl, gr, g.disparity, g.confidence, max_disparity=md)
    sparse = {
        "mcgm": mcgm_match(gl, gr, max_disparity=md, **fusion.MEMBER_MCGM),
        "hopfield": hopfield_match(gl, gr, max_disparity=md),
    }
    sgm = sgm_disparity(gl, gr, max_disparity=md)
    res = fusion.fuse((base, g.confidence), sparse)
    test = (res.sources & fusion.CHANNEL_BITS["mcgm"]) == 0

    def checks() -> object:
        keep = np.ones(len(res), bool)
        keep[test] = fusion._sides_ok(gl, gr, res.matches, test, md, 0.0)
        fat = fusion._fattened(base, gl, *fusion._EDGE_MEMBERS)
        keep &= ~fat[res.matches.yl.astype(np.intp), res.matches.xl.astype(np.intp)]
        return fusion._members_where(res, keep)

    def dense() -> tuple[np.ndarray, np.ndarray]:
        return fusion.fused_dense(base, g.confidence, res.dispx, second=sgm, guide=gl)

    d, _ = dense()
    return {
        "SGBM-3WAY": lambda: opencv_sgbm(sc.left, sc.right, md),
        "depth_map (whole)": lambda: depth_map(sc.left, sc.right, max_disparity=md),
        "channel: gabor": lambda: gabor_disparity(gl, gr, max_disparity=md),
        "channel: gabor re-measure": lambda: fusion.remeasure(
            gl, gr, g.disparity, g.confidence, max_disparity=md
        ),
        "channel: mcgm": lambda: mcgm_match(gl, gr, max_disparity=md, **fusion.MEMBER_MCGM),
        "channel: hopfield": lambda: hopfield_match(gl, gr, max_disparity=md),
        "channel: census sgm": lambda: sgm_disparity(gl, gr, max_disparity=md),
        "after: vote": lambda: fusion.fuse((base, g.confidence), sparse),
        "after: member checks": checks,
        "after: dense map": dense,
        "after: fill": lambda: fill_holes(d, sc.left, fused=True, grey=gl),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=timed_runs, default=7, help="timed runs per case (>= 5)")
    ap.add_argument(
        "scenes",
        nargs="*",
        type=scene_folder,
        help="scene folders or family/scene names (default: cloth3 and teddyH)",
    )
    args = ap.parse_args()
    dirs = [Path(s) if Path(s).is_dir() else DATA / s for s in args.scenes or SCENES]
    rows = []
    for scene in dirs:
        named = cases(scene)
        ms = dict(zip(named, interleaved_ms(list(named.values()), args.repeats), strict=True))
        ref = ms["SGBM-3WAY"]
        for case, t in ms.items():
            line = {
                "scene": scene.name,
                "case": case,
                "ms": round(t, 1),
                "ratio_sgbm": round(t / ref, 3),
            }
            print(json.dumps(line), flush=True)
            rows.append(line)
    print(f"\n{'scene':10s} {'case':28s} {'ms':>8s} {'x SGBM':>7s}")
    for r in rows:
        print(f"{r['scene']:10s} {r['case']:28s} {r['ms']:8.1f} {r['ratio_sgbm']:7.2f}")


if __name__ == "__main__":
    main()
