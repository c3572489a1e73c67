"""A process forked after the kernels ran (``multiprocessing``'s "fork" start method, a
preforking server) runs them too, with the same results.

rayon's worker threads are not copied by ``fork()``: before the binding gave a forked process
a pool of its own (``rust/py/src/workers.rs``), such a child waited forever on its first kernel.
"""

from __future__ import annotations

import multiprocessing as mp
import sys
from pathlib import Path

import numpy as np
import pytest

import stereovision as sv
from stereovision.io import load_scene

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="fork start method")

_SCENE: dict[str, object] = {}


def _depth(method: str) -> np.ndarray:
    s = _SCENE["scene"]
    return sv.depth_map(s.left, s.right, method=method, max_disparity=64).disparity  # type: ignore[attr-defined]


def test_a_forked_child_runs_the_kernels(data_dir: Path) -> None:
    _SCENE["scene"] = load_scene(data_dir / "middlebury2003" / "cones")
    methods = ["fused", "fast"]
    here = [_depth(m) for m in methods]  # the parent's pool is started
    with mp.get_context("fork").Pool(2) as pool:
        # a hang fails the test instead of stopping the run
        there = pool.map_async(_depth, methods).get(timeout=120)
    for a, b in zip(here, there, strict=True):
        np.testing.assert_array_equal(a, b)  # bit-identical, as across thread counts
    assert np.isfinite(here[0]).mean() > 0.9
