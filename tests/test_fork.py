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


#: Runs a kernel in this process, in a child forked after it and in that child's child; each
#: prints its result's checksum. A process waiting on a pool without threads hangs.
_GRANDCHILD = """
import os
import numpy as np
from stereovision import _core

a = np.random.default_rng(0).random((240, 320), dtype=np.float32)
b = np.roll(a, -3, axis=1)


def run(who):
    d = _core.sgm_disparity(a, b, 0, 16, 8, 96, 16.0, 5, 1, 4)
    print(who, float(np.nansum(d)), flush=True)


run("parent")
if os.fork() == 0:
    run("child")
    if os.fork() == 0:
        run("grandchild")
        os._exit(0)
    os.wait()
    os._exit(0)
os.wait()
"""


def test_a_child_of_a_forked_child_runs_the_kernels() -> None:
    """A grandchild makes a pool of its own too: a mutation audit handing it its parent's
    pool (whose threads ``fork()`` did not copy) left every test passing, and it hung."""
    import os
    import signal
    import subprocess

    # Its own session: a hang kills the whole family (the forked ones would outlive the run).
    proc = subprocess.Popen(
        [sys.executable, "-c", _GRANDCHILD],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        stdout, stderr = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        stdout, stderr = proc.communicate()
        pytest.fail(f"a forked process hung; it printed {stdout!r}")
    out = subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr)
    assert out.returncode == 0, out.stderr[-2000:]
    sums = dict(line.split() for line in out.stdout.splitlines())
    assert set(sums) == {"parent", "child", "grandchild"}, out.stdout
    assert len(set(sums.values())) == 1 and float(sums["parent"]) > 0, sums
