"""MCGM channel bench (issue 3): accuracy on every scene with GT beside the ZNCC reference, and
speed vs SGBM-3WAY.

Accuracy: for every scene of ``../shared/data`` with ``gt_disp.pfm``, the channel
(``stereovision.match(..., method="mcgm")``) and, in the same run, the plain reference
(:func:`stereovision.matching.mcgm.zncc_reference`: best 7x7 ZNCC along the row on the same
zero-crossing pixels, left-right check, the same B.8 filters); evaluation.md's sparse metrics:
precision@0.5/1/2, count with GT, 4x4 coverage. ``ref_count_at_mcgm_precision``: the reference's
matches ranked by ZNCC, cut to the longest prefix whose precision@1 reaches the channel's.
Speed: OpenCV SGBM-3WAY (evaluation.md configuration) and the channel on middlebury2006/cloth3
and middeval3/teddyH at the scene's max_disparity, interleaved (SGBM, MCGM, SGBM, ...), median
of ``--repeats`` runs after a warm-up, ratio printed. One JSON line per case.

Usage: ``python benches/bench_mcgm.py [--scenes a,b] [--repeats 7] [--no-speed]``
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np

import stereovision as sv
from stereovision import io
from stereovision._validate import as_gray_float
from stereovision.baselines import opencv_sgbm
from stereovision.evaluate import sparse_metrics
from stereovision.matches import Matches
from stereovision.matching.mcgm import zncc_reference

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
SPEED_SCENES = ("middlebury2006/cloth3", "middeval3/teddyH")
#: Target of issue 3: the channel takes under a third of SGBM-3WAY's time.
SPEED_TARGET = 1.0 / 3.0


def _metrics(m: Matches, gt: np.ndarray) -> dict[str, float | int]:
    sm = sparse_metrics(m.xl, m.yl, m.xr, gt)
    return {
        "p05": round(sm.precision[0.5], 2),
        "p1": round(sm.precision[1.0], 2),
        "p2": round(sm.precision[2.0], 2),
        "count": sm.count,
        "coverage": sm.coverage,
    }


def _count_at_precision(m: Matches, gt: np.ndarray, target_p1: float) -> int:
    """Largest count with GT among score-ranked prefixes of ``m`` whose precision@1 >= target."""
    order = np.argsort(-m.score, kind="stable")
    xl, yl, xr = m.xl[order], m.yl[order], m.xr[order]
    h, w = gt.shape
    xi = np.clip(np.rint(xl).astype(int), 0, w - 1)
    yi = np.clip(np.rint(yl).astype(int), 0, h - 1)
    g = gt[yi, xi]
    has = np.isfinite(g)
    ok = np.abs((xl - xr) - g) <= 1.0
    n = np.cumsum(has)
    good = np.cumsum(has & ok)
    prec = np.where(n > 0, 100.0 * good / np.maximum(n, 1), 0.0)
    valid = np.nonzero(prec >= target_p1 - 1e-9)[0]
    return int(n[valid[-1]]) if valid.size else 0


def accuracy(scenes: list[str]) -> None:
    for name in scenes:
        sc = io.load_scene(DATA / name)
        assert sc.gt is not None
        left, right = as_gray_float(sc.left), as_gray_float(sc.right)
        t0 = time.perf_counter()
        m = sv.match(left, right, method="mcgm", max_disparity=sc.max_disparity)
        t1 = time.perf_counter()
        z = zncc_reference(left, right, max_disparity=sc.max_disparity)
        t2 = time.perf_counter()
        mm, mz = _metrics(m, sc.gt), _metrics(z, sc.gt)
        line = {
            "case": "accuracy",
            "scene": name,
            "max_disparity": sc.max_disparity,
            "mcgm": {**mm, "ms": round(1e3 * (t1 - t0), 1)},
            "reference": {**mz, "ms": round(1e3 * (t2 - t1), 1)},
            "ref_count_at_mcgm_precision": _count_at_precision(z, sc.gt, float(mm["p1"])),
            "as_precise_as_reference": mm["p1"] >= mz["p1"],
            "n_candidates": m.stats["n_candidates"],
            "n_pairs": m.stats["n_pairs"],
            "n_combined": m.stats["n_combined"],
            "n_sides": m.stats["n_sides"],
        }
        print(json.dumps(line), flush=True)


def speed(repeats: int) -> None:
    for name in SPEED_SCENES:
        sc = io.load_scene(DATA / name)

        def run_sgbm(sc: io.Scene = sc) -> None:
            opencv_sgbm(sc.left, sc.right, sc.max_disparity)

        def run_mcgm(sc: io.Scene = sc) -> None:
            sv.match(sc.left, sc.right, method="mcgm", max_disparity=sc.max_disparity)

        run_sgbm()
        run_mcgm()  # warm-up
        ts: list[float] = []
        tm: list[float] = []
        for _ in range(repeats):
            for fn, acc in ((run_sgbm, ts), (run_mcgm, tm)):
                t = time.perf_counter()
                fn()
                acc.append(time.perf_counter() - t)
        ms_s, ms_m = 1e3 * statistics.median(ts), 1e3 * statistics.median(tm)
        ratio = ms_m / ms_s
        print(
            json.dumps(
                {
                    "case": "speed",
                    "scene": name,
                    "max_disparity": sc.max_disparity,
                    "sgbm3way_ms": round(ms_s, 1),
                    "mcgm_ms": round(ms_m, 1),
                    "ratio": round(ratio, 3),
                    "target": round(SPEED_TARGET, 3),
                    "met": ratio < SPEED_TARGET,
                    "repeats": repeats,
                }
            ),
            flush=True,
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="", help="comma-separated family/scene (default: all)")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--no-speed", action="store_true")
    ap.add_argument("--no-accuracy", action="store_true")
    args = ap.parse_args()
    scenes = (
        args.scenes.split(",")
        if args.scenes
        else sorted(str(p.parent.relative_to(DATA)) for p in DATA.glob("*/*/gt_disp.pfm"))
    )
    if not args.no_accuracy:
        accuracy(scenes)
    if not args.no_speed:
        speed(args.repeats)


if __name__ == "__main__":
    main()
