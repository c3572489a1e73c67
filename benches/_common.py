"""Pieces the Python benches share: scene list, sparse figures, interleaved timing.

The benches run as scripts (``python benches/bench_x.py``), so this folder is on ``sys.path``.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from stereovision.evaluate import sparse_metrics
from stereovision.matches import Matches

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def gt_scenes() -> list[str]:
    """``family/scene`` of every scene of ``shared/data`` with a ``gt_disp.pfm``, sorted."""
    return sorted(str(p.parent.relative_to(DATA)) for p in DATA.glob("*/*/gt_disp.pfm"))


def sparse_row(m: Matches, gt: np.ndarray) -> dict[str, float | int]:
    """evaluation.md's sparse figures of ``m`` as a JSON-ready dict."""
    sm = sparse_metrics(m.xl, m.yl, m.xr, gt)
    return {
        "p05": round(sm.precision[0.5], 2),
        "p1": round(sm.precision[1.0], 2),
        "p2": round(sm.precision[2.0], 2),
        "count": sm.count,
        "coverage": sm.coverage,
    }


def interleaved_ms(fns: Sequence[Callable[[], object]], repeats: int) -> list[float]:
    """Median ms of each function: one warm-up each, then A, B, ... A, B, ... ``repeats`` times."""
    for fn in fns:
        fn()
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(repeats):
        for fn, acc in zip(fns, times, strict=True):
            t = time.perf_counter()
            fn()
            acc.append(time.perf_counter() - t)
    return [1e3 * statistics.median(t) for t in times]
