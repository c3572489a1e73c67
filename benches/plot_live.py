"""Draw what a live view gets on one GT scene: the Gabor channel as ``stereovision stream`` runs it
by default (``refine=False``, holes left) beside ``method="fast", fill=False`` (README picture,
"Choosing a mode").

Panels: the left image; the ground truth; then each map coloured like the GT, its holes black and
every measured pixel off by more than 2 px from the GT red, with the share of GT pixels measured
and the share of those off by more than 2 px in the title. One run, same process.

Usage: ``python benches/plot_live.py [--scene middlebury2003/teddy] [--out PATH]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from _common import DATA, gt_scene

from stereovision.depth import depth_map
from stereovision.io import load_scene

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="middlebury2003/teddy", type=gt_scene)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "live_modes.png")
    args = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sc = load_scene(DATA / args.scene)
    gt = sc.gt
    assert gt is not None
    md = sc.max_disparity
    maps = {
        'stream default: method="gabor", refine=False': depth_map(
            sc.left, sc.right, max_disparity=md, method="gabor", refine=False
        ).disparity,
        'method="fast", fill=False': depth_map(
            sc.left, sc.right, max_disparity=md, method="fast", fill=False
        ).disparity,
    }
    # evaluation.md's known GT (finite; a 0 px GT counts, as in dense_metrics and
    # plot_bad2_panels): "& gt > 0" left a 0 px pixel out of the titles' shares
    valid = np.isfinite(gt)
    vmax = float(np.nanmax(gt[valid]))
    fig, axes = plt.subplots(2, 2, figsize=(10, 8.4))
    axes[0, 0].imshow(sc.left[..., ::-1] if sc.left.ndim == 3 else sc.left, cmap="gray")
    axes[0, 0].set_title(f"{args.scene}: left")
    axes[0, 1].imshow(np.where(valid, gt, np.nan), cmap="turbo", vmin=0, vmax=vmax)
    axes[0, 1].set_title("ground truth")
    for ax, (name, d) in zip(axes[1], maps.items(), strict=True):
        measured = valid & np.isfinite(d)
        wrong = measured & (np.abs(d - gt) > 2)
        rgb = plt.get_cmap("turbo")(np.clip(np.nan_to_num(d) / vmax, 0, 1))[..., :3]
        rgb[~np.isfinite(d)] = (0.0, 0.0, 0.0)
        rgb[wrong] = (1.0, 0.0, 0.0)
        ax.imshow(rgb)
        share = 100 * measured.sum() / valid.sum()
        ax.set_title(
            f"{name}\n{share:.1f} % measured, {100 * wrong.sum() / measured.sum():.2f} % of them"
            " off by > 2 px",
            fontsize=10,
        )
    for ax in axes.flat:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=80)
    plt.close(fig)
    print(args.out)


if __name__ == "__main__":
    main()
