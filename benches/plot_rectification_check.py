"""Draw the rectification check on a rectified scene as given and with its right camera turned
(docs/images/rectification_check.jpg, the README's picture).

Top: Middlebury 2003 cones as given. Bottom: the same pair with the right image 1.5 px lower and
turned 0.3 degrees about its centre, what a bumped rig does to rows. Matches are green within the
tolerance (0.5 px), yellow up to 1.5 px, red beyond. One run.

Usage: ``python benches/plot_rectification_check.py [--scene middlebury2003/cones] [--out PATH]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np
from _common import DATA, picture_path, write_picture

from stereovision.io import imread
from stereovision.rectification_check import check_rectification, draw_rectification_check

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="middlebury2003/cones")
    ap.add_argument(
        "--out", type=picture_path, default=ROOT / "docs/images/rectification_check.jpg"
    )
    args = ap.parse_args()
    left = imread(DATA / args.scene / "left.png")
    right = imread(DATA / args.scene / "right.png")
    h, w = right.shape[:2]
    m = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), 0.3, 1.0)
    m[1, 2] += 1.5
    bumped = cv2.warpAffine(right, m, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)
    panels = []
    for r in (right, bumped):
        res = check_rectification(left, r)
        print(res.summary())
        panels.append(draw_rectification_check(left, r, res))
    gap = np.full((12, panels[0].shape[1], 3), 255, np.uint8)
    img = np.concatenate([panels[0], gap, panels[1]], axis=0)
    write_picture(args.out, img)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
