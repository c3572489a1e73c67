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

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from _common import DATA

from stereovision.baselines import opencv_sgbm, row_fill
from stereovision.depth import depth_map
from stereovision.io import load_scene

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="eth3d/playground")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "modes.png")
    args = ap.parse_args()
    sc = load_scene(DATA / args.scene)
    gt = sc.gt
    assert gt is not None
    valid = np.isfinite(gt) & (gt > 0)
    md = sc.max_disparity

    def mode(**kw: Any) -> np.ndarray:
        return depth_map(sc.left, sc.right, max_disparity=md, **kw).disparity

    maps = {
        "SGBM-3WAY + row fill": row_fill(opencv_sgbm(sc.left, sc.right, md)),
        'method="gabor", fill=True': mode(method="gabor", fill=True),
        'method="census"': mode(method="census"),
        "fused (default)": mode(),
    }
    vmax = float(np.nanmax(gt[valid]))
    fig, axes = plt.subplots(2, 3, figsize=(13, 5.6))
    left = sc.left if sc.left.ndim == 2 else sc.left[..., ::-1]
    axes[0, 0].imshow(left, cmap="gray")
    axes[0, 0].set_title(f"{args.scene}: left")
    axes[0, 1].imshow(np.where(valid, gt, np.nan), cmap="turbo", vmin=0, vmax=vmax)
    axes[0, 1].set_title("ground truth")
    for ax, (name, d) in zip([axes[0, 2], *axes[1]], maps.items(), strict=True):
        bad = valid & ~(np.abs(d - gt) <= 2)
        rgb = plt.get_cmap("turbo")(np.clip(np.nan_to_num(d) / vmax, 0, 1))[..., :3]
        rgb[bad] = (1.0, 0.0, 0.0)
        ax.imshow(rgb)
        ax.set_title(f"{name}: bad-2.0 {100 * bad.sum() / valid.sum():.2f} %")
    for ax in axes.flat:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=80)
    print(args.out)


if __name__ == "__main__":
    main()
