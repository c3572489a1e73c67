"""Draw the filled maps of ``depth_map``'s modes beside SGBM-3WAY + fill on one GT scene (README
picture, "Choosing a mode").

Panels: the left image; the ground truth; SGBM-3WAY + the reference row fill; then
``method="gabor", fill=True``, ``method="census"`` and the fused default, each with every pixel off
by more than 2 px from the GT painted red and its bad-2.0 (holes counted) in the title. One run,
same process. The default scene, ETH3D playground, is the one where the census mode and the fused
default differ most (a wall of vertical stripes the census map locks one period off).

Usage: ``python benches/plot_modes.py [--scene eth3d/playground] [--out PATH]``
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np
from _common import DATA, gt_scene, plot_bad2_panels

from stereovision.baselines import opencv_sgbm, row_fill
from stereovision.depth import depth_map
from stereovision.io import load_scene

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="eth3d/playground", type=gt_scene)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "modes.png")
    args = ap.parse_args()
    sc = load_scene(DATA / args.scene)
    gt = sc.gt
    assert gt is not None
    md = sc.max_disparity

    def mode(**kw: Any) -> np.ndarray:
        return depth_map(sc.left, sc.right, max_disparity=md, **kw).disparity

    maps = {
        "SGBM-3WAY + row fill": row_fill(opencv_sgbm(sc.left, sc.right, md)),
        'method="gabor", fill=True': mode(method="gabor", fill=True),
        'method="census"': mode(method="census"),
        "fused (default)": mode(),
    }
    plot_bad2_panels(args.scene, sc.left, gt, maps, args.out, (13, 5.6))
    print(args.out)


if __name__ == "__main__":
    main()
