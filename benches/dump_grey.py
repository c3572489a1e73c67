"""Write a scene's rectified pair as raw float32 grey images for the Rust profiling examples.

``python benches/dump_grey.py SCENE PREFIX`` writes ``PREFIX_l.f32`` and ``PREFIX_r.f32``
(little-endian, row-major, :func:`stereovision._validate.as_gray_float`'s values) and prints
``W H MAX_DISPARITY``; ``SCENE`` is a folder of ``../shared/data`` (or a path).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from _common import DATA

from stereovision._validate import as_gray_float
from stereovision.io import load_scene


def main() -> int:
    if sys.argv[1:] in (["-h"], ["--help"]):
        print(f"usage: dump_grey.py SCENE PREFIX\n\n{__doc__}")
        return 0
    if len(sys.argv) != 3:
        print("usage: dump_grey.py SCENE PREFIX", file=sys.stderr)
        return 2
    folder = Path(sys.argv[1])
    sc = load_scene(folder if folder.is_dir() else DATA / folder)
    for side, img in (("l", sc.left), ("r", sc.right)):
        as_gray_float(img).astype("<f4").tofile(f"{sys.argv[2]}_{side}.f32")
    h, w = np.asarray(sc.left).shape[:2]
    print(w, h, int(sc.max_disparity))
    return 0


if __name__ == "__main__":
    sys.exit(main())
