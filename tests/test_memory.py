"""The extension's block cache (rust/core/src/alloc.rs): bounded, releasable, output unchanged."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import stereovision as sv
from stereovision import _core
from stereovision.io import load_scene


def test_kept_blocks_are_bounded_released_and_reused_safely(data_dir: Path) -> None:
    scene = load_scene(data_dir / "middlebury2001" / "tsukuba")
    sv.release_memory()
    assert _core.kept_memory() == ((0, 0), 0)
    first = sv.depth_map(scene.left, scene.right, max_disparity=16, cloud=False)
    (blocks, kept), pooled = _core.kept_memory()
    # The call's image-sized buffers (384x288 float32 maps: 442 KB each) are kept for the next:
    # the refinement's by the allocator, the Gabor planes and the census matcher's cost volume
    # (384 x 288 x 17 levels) by their pools.
    assert blocks >= 4 and 4 * 384 * 288 * 4 <= kept <= 128 << 20
    assert 384 * 288 * 4 + 384 * 288 * 17 <= pooled <= 512 << 20
    # Reused blocks hold the previous call's data: the outputs must not depend on it.
    again = sv.depth_map(scene.left, scene.right, max_disparity=16, cloud=False)
    np.testing.assert_array_equal(first.disparity, again.disparity)
    np.testing.assert_array_equal(first.confidence, again.confidence)
    m = sv.match(scene.left, scene.right, method="fused", max_disparity=16)
    m2 = sv.match(scene.left, scene.right, method="fused", max_disparity=16)
    np.testing.assert_array_equal(m.to_array(), m2.to_array())
    (_, kept), pooled = _core.kept_memory()
    assert sv.release_memory() == kept + pooled > 0
    assert _core.kept_memory() == ((0, 0), 0)


def test_concurrent_calls_from_python_threads_match_sequential_ones(data_dir: Path) -> None:
    """A robot's nodes call the library from several threads at once (the GIL is released
    around every kernel): the kernels then share the rayon pool, the allocator's block cache and
    the Gabor and census pools under contention. Every output must equal the sequential one,
    bit for bit."""
    import threading

    # the top half of each scene (its whole width, so its whole range): 32 calls of 4 matchers
    scenes = []
    for n in ("middlebury2003/cones", "middlebury2001/tsukuba"):
        s = load_scene(data_dir / n)
        h = s.left.shape[0] // 2
        scenes.append((s.left[:h].copy(), s.right[:h].copy(), s.max_disparity))
    cases = [(i, m) for i in range(len(scenes)) for m in ("fused", "census", "gabor", "mcgm")]

    def run(i: int, method: str) -> np.ndarray:
        left, right, dmax = scenes[i]
        if method == "mcgm":
            return sv.match(left, right, method="mcgm", max_disparity=dmax).to_array()
        return sv.depth_map(left, right, method=method, max_disparity=dmax, cloud=False).disparity

    expected = {c: run(*c) for c in cases}
    got: list[tuple[tuple[int, str], np.ndarray]] = []
    errors: list[BaseException] = []

    def worker(k: int) -> None:
        try:
            for j in range(len(cases)):
                c = cases[(j + 3 * k) % len(cases)]  # each thread in another order
                got.append((c, run(*c)))
        except BaseException as exc:  # re-raised below, in the test's thread
            errors.append(exc)

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert len(got) == 3 * len(cases)
    for c, out in got:
        np.testing.assert_array_equal(out, expected[c], err_msg=str(c))


def _rss_mib() -> float:
    """The process's resident set (``VmRSS`` of /proc/self/status), MiB."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise AssertionError("no VmRSS line in /proc/self/status")


def _has_malloc_trim() -> bool:
    import ctypes

    try:
        ctypes.CDLL(None).malloc_trim  # noqa: B018 (the lookup is the test)
    except (OSError, TypeError, AttributeError):
        return False
    return True


@pytest.mark.skipif(
    not Path("/proc/self/status").exists() or not _has_malloc_trim(),
    reason="needs Linux's /proc and glibc's malloc_trim",
)
def test_release_memory_returns_the_freed_heap_to_the_system() -> None:
    """After a depth_map on a 3600 x 3000 pair the process stayed at 11-12 GB resident with
    0.6 GiB kept: the rest was free memory glibc held in its heap. release_memory now trims
    that heap as well (here a 900 x 750 pair: about 530 MiB at the peak; the old function left
    210-265 MiB of it resident, the new about 45)."""
    from stereovision.gui import bundled_data_dir

    scene = load_scene(bundled_data_dir() / "cones")
    left = np.repeat(np.repeat(scene.left, 2, axis=0), 2, axis=1)
    right = np.repeat(np.repeat(scene.right, 2, axis=0), 2, axis=1)
    sv.release_memory()
    base = _rss_mib()
    res = sv.depth_map(left, right, max_disparity=2 * scene.max_disparity, cloud=False)
    del res
    peak = _rss_mib()
    assert peak - base > 300, (base, peak)  # the call did grow the heap
    released = sv.release_memory()
    assert released > 0
    assert _core.kept_memory() == ((0, 0), 0)
    after = _rss_mib()
    assert after - base < 0.2 * (peak - base), (base, peak, after)
