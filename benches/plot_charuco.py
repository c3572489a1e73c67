"""Draw why a ChArUco board helps near the image edge (docs/images/charuco_cut_board.jpg).

One rendered pose (640x480, barrel distortion k1 = -0.3) whose board's last corner column is out of
view. Left: a 10x7-square ChArUco board; the corners found (green, with their ids) are used.
Right: a 9x6 chessboard in the same pose; OpenCV's exhaustive detector reports a board (red) one
square off, its first column being the border squares' outer corners (true corners in green);
``find_corners`` refuses it, and the view gives a chessboard calibration nothing.

Usage: ``python benches/plot_charuco.py [--out PATH]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np
from _common import picture_path, write_picture

from stereovision.calibrate import (
    SB_FLAG_SETS,
    board_object_points,
    find_corners,
    render_chessboard,
)
from stereovision.charuco import CharucoBoard, find_charuco_corners, render_charuco

ROOT = Path(__file__).resolve().parents[1]
K = np.array([[600.0, 0, 330], [0, 602, 238], [0, 0, 1]])
D = np.array([-0.30, 0.12, 0.0008, -0.0004, 0])
SQUARE = 0.03


def label(img: np.ndarray, text: str, y: int = 24) -> None:
    (w, h), _ = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, 0.55, 1)
    cv2.rectangle(img, (4, y - h - 6), (16 + w, y + 6), (30, 30, 30), -1)
    cv2.putText(img, text, (10, y), cv2.FONT_HERSHEY_SIMPLEX, 0.55, (255, 255, 255), 1, cv2.LINE_AA)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=picture_path, default=ROOT / "docs/images/charuco_cut_board.jpg")
    args = ap.parse_args()
    rv, tv = np.array([-0.289, 0.072, 0.195]), np.array([-0.0169, -0.0796, 0.3933])
    board = CharucoBoard("10x7", SQUARE, 0.022, "DICT_5X5_100")
    t0 = tv - cv2.Rodrigues(rv)[0] @ np.array([SQUARE, SQUARE, 0.0])
    ch = render_charuco(board, K, D, rv, t0)
    found = find_charuco_corners(ch, board)
    assert found is not None
    left = cv2.cvtColor(ch, cv2.COLOR_GRAY2BGR)
    for i, (x, y) in zip(found[0], found[1], strict=True):
        cv2.circle(left, (round(x), round(y)), 4, (0, 200, 0), 2, cv2.LINE_AA)
        cv2.putText(left, str(i), (round(x) + 4, round(y) - 4), cv2.FONT_HERSHEY_SIMPLEX, 0.35,
                    (0, 140, 0), 1, cv2.LINE_AA)  # fmt: skip
    label(left, f"ChArUco: {len(found[0])} of {board.n_corners} corners, each with its id: used")

    cb = render_chessboard(K, D, rv, tv, pattern=(9, 6), square_size=SQUARE, image_size=(640, 480))
    right = cv2.cvtColor(cb, cv2.COLOR_GRAY2BGR)
    truth = cv2.projectPoints(board_object_points((9, 6), SQUARE).astype(np.float64), rv, tv, K, D)
    for x, y in truth[0].reshape(-1, 2):
        if 0 <= x < 640 and 0 <= y < 480:
            cv2.circle(right, (round(x), round(y)), 4, (0, 200, 0), 2, cv2.LINE_AA)
    ok, wrong = cv2.findChessboardCornersSB(cb, (9, 6), flags=SB_FLAG_SETS[-1])
    if ok:
        for x, y in np.asarray(wrong).reshape(-1, 2):
            cv2.drawMarker(right, (round(x), round(y)), (0, 0, 230), cv2.MARKER_TILTED_CROSS, 9, 2)
    refused = find_corners(cb, (9, 6)) is None
    label(right, "chessboard: OpenCV finds it one square off (red)")
    label(right, "find_corners: " + ("refused, view unused" if refused else "accepted"), 50)
    out = np.hstack([left, np.full((480, 8, 3), 255, np.uint8), right])
    write_picture(args.out, out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
