"""Draw the fused dense map beside OpenCV SGBM-3WAY + fill on one GT scene (README picture).

Panels: the left image; the ground truth; then, for the fused map with the row fill alone (no
planes: ``fill=False``, then the reference row fill), SGBM-3WAY + the reference row fill, the fused
map without the census semi-global map (``semi_global=False``) and the default fused map, the
disparity with every pixel off by more than 2 px from the GT painted red, and its bad-2.0 (holes
counted) in the title. One run, same process.

Usage: ``python benches/plot_fused.py [--scene middlebury2005/books] [--out PATH]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

from _common import DATA, gt_scene, plot_bad2_panels

from stereovision.baselines import opencv_sgbm, row_fill
from stereovision.depth import depth_map
from stereovision.io import load_scene

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="middlebury2005/books", type=gt_scene)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "fused_vs_sgbm.png")
    args = ap.parse_args()
    sc = load_scene(DATA / args.scene)
    gt = sc.gt
    assert gt is not None
    md = sc.max_disparity
    maps = {
        "fused, row fill only": row_fill(
            depth_map(sc.left, sc.right, max_disparity=md, method="fused", fill=False).disparity
        ),
        "SGBM-3WAY + row fill": row_fill(opencv_sgbm(sc.left, sc.right, md)),
        "fused, no census map": depth_map(
            sc.left, sc.right, max_disparity=md, method="fused", semi_global=False
        ).disparity,
        "fused (default)": depth_map(sc.left, sc.right, max_disparity=md, method="fused").disparity,
    }
    plot_bad2_panels(args.scene, sc.left, gt, maps, args.out, (13, 7.2))
    print(args.out)


if __name__ == "__main__":
    main()
