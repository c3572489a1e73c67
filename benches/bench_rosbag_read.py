"""How fast recorded rigs are read from bags (docs/robotics.md, "Recorded rigs"). One run.

KITTI's pair written 200 times (30 fps stamps) into a ROS 2 sqlite3 bag, a ROS 2 MCAP bag and a
ROS 1 bag of Bayer frames, and as PNG-compressed frames, with rosbags' own writers (the tests'
``write_bag``); then :class:`stereovision.rosbag.BagCamera` reads every pair: pairing on the
stamps, decoding to BGR. Median of 5 reads.

Usage: ``python benches/bench_rosbag_read.py [--pairs N]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

from _common import DATA

from stereovision.io import load_scene
from stereovision.rosbag import BagCamera

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests.test_rosbag_read import PERIOD_NS, T0, write_bag  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pairs", type=int, default=200)
    args = ap.parse_args()
    sc = load_scene(DATA / "kitti2015" / "000005_10")
    frames = [
        (T0 + k * PERIOD_NS, sc.left, T0 + k * PERIOD_NS + 1000, sc.right)
        for k in range(args.pairs)
    ]
    h, w = sc.left.shape[:2]
    with tempfile.TemporaryDirectory() as tmp:
        for flavour, encoding in (
            ("ros2", "bgr8"),
            ("mcap", "bgr8"),
            ("ros1", "bayer_rggb8"),
            ("ros2", "png"),
        ):
            name = f"{flavour}_{encoding}" + (".bag" if flavour == "ros1" else "")
            bag = write_bag(Path(tmp) / name, frames, flavour=flavour, encoding=encoding)
            times = []
            for _ in range(5):
                t0 = time.perf_counter()
                with BagCamera(bag) as cam:
                    n = sum(1 for _ in cam.frames())
                times.append(time.perf_counter() - t0)
            rate = n / statistics.median(times)
            print(f"{flavour:4s} {encoding:12s} {w}x{h}: {n} pairs, {rate:.0f} pairs/s")


if __name__ == "__main__":
    main()
