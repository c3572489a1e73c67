"""Draw where the census check drops valid members, on one GT scene (docs/fusion.md picture).

Two panels over the left image (grey): the members before the census check
(``fuse_pair(census_members=False)``) and after it (the default), each member a dot: green
within 1 px of the GT, red beyond (members without GT are not drawn); in the second panel the
members the check dropped are blue. Precision@1 and counts in the titles. One run.

Usage: ``python benches/plot_members.py [--scene middlebury2003/teddy] [--out PATH]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from _common import DATA, gt_scene

from stereovision._validate import as_gray_float
from stereovision.io import load_scene
from stereovision.matching.fusion import census_clear, fuse_pair

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="middlebury2003/teddy", type=gt_scene)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "members_census.png")
    args = ap.parse_args()
    sc = load_scene(DATA / args.scene)
    assert sc.gt is not None
    gl, gr = as_gray_float(sc.left, "left"), as_gray_float(sc.right, "right")
    before = fuse_pair(
        gl, gr, max_disparity=int(sc.max_disparity), census_members=False, dense_sgm=True
    )
    after = census_clear(before, before.channel_outputs["sgm"])
    fig, axes = plt.subplots(1, 2, figsize=(14, 6.2), constrained_layout=True)
    kept = set(zip(after.matches.xl.tolist(), after.matches.yl.tolist(), strict=True))
    mb = before.matches
    gone = np.array([k not in kept for k in zip(mb.xl.tolist(), mb.yl.tolist(), strict=True)])
    for ax, res, title in ((axes[0], before, "before the census check"), (axes[1], after, "after")):
        m = res.matches
        x, y = m.xl.astype(int), m.yl.astype(int)
        g = sc.gt[y, x]
        has = np.isfinite(g)
        ok = has & (np.abs(m.xl - m.xr - g) <= 1.0)
        bad = has & ~ok
        ax.imshow(gl, cmap="gray", vmin=0, vmax=1)
        ax.scatter(x[ok], y[ok], s=1, c="#2ca02c", linewidths=0)
        if res is after:
            xb, yb = mb.xl[gone].astype(int), mb.yl[gone].astype(int)
            ax.scatter(xb, yb, s=3, c="#1f77b4", linewidths=0, label="dropped by the check")
            ax.legend(loc="lower right", markerscale=4)
        ax.scatter(x[bad], y[bad], s=6, c="#d62728", linewidths=0)
        ax.set_title(
            f"members {title}: {100 * ok.sum() / has.sum():.2f} % of {has.sum()} within 1 px "
            "(red: beyond)"
        )
        ax.set_axis_off()
    fig.suptitle(f"{sc.name}: the valid members (green) and the census check")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=90)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
