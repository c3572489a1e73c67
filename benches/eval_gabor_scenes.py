"""Scratch evaluation of the Gabor channel on the shared scenes (evaluation.md metrics).

Prints, per scene: bad-2.0 of our output after the reference row fill and unfilled (holes count as
errors), density, StereoBM and SGBM-3WAY bad-2.0 (unfilled), times; then the means, and the
metric-depth comparison with SGBM-3WAY on the three metric scenes. Self-contained (its own PFM
reader, baselines and fill) so it runs while the package's io/evaluate/baselines evolve.

Usage: ``python benches/eval_gabor_scenes.py [--scenes a,b] [--param key=value ...] [--no-cv]``
"""

from __future__ import annotations

import argparse
import json
import re
import time
from pathlib import Path

import cv2
import numpy as np

from stereovision.matching.gabor import gabor_disparity

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
SCENES = {
    "eth3d/playground": 32,
    "eth3d/terrace": 32,
    "kitti2015/000005_10": 112,
    "middeval3/teddyH": 128,
    "middlebury2001/tsukuba": 16,
    "middlebury2001/venus": 32,
    "middlebury2003/cones": 64,
    "middlebury2003/teddy": 64,
    "middlebury2005/art": 96,
    "middlebury2005/books": 96,
    "middlebury2005/dolls": 96,
    "middlebury2005/laundry": 96,
    "middlebury2005/moebius": 80,
    "middlebury2005/reindeer": 80,
    "middlebury2006/cloth3": 96,
    "middlebury2006/wood2": 128,
    "tartanair/oldtown_easy_p000_001116": 48,
}
METRIC = ("eth3d/terrace", "eth3d/playground", "kitti2015/000005_10")


def read_pfm(path: Path) -> np.ndarray:
    """Read a PFM (bottom-up rows, negative scale = little endian) as top-down float32."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    ch = 3 if kind == b"PF" else 1
    arr = data.reshape(h, w, ch)[..., 0] if ch == 3 else data.reshape(h, w)
    return np.ascontiguousarray(np.flipud(arr)).astype(np.float32)


def read_calib(path: Path) -> dict[str, float]:
    txt = path.read_text()
    out: dict[str, float] = {}
    m = re.search(r"cam0=\[\s*([0-9.eE+-]+)", txt)
    if m:
        out["f"] = float(m.group(1))
    for key in ("doffs", "baseline"):
        m = re.search(rf"{key}\s*=\s*([0-9.eE+-]+)", txt)
        if m:
            out[key] = float(m.group(1))
    return out


def row_fill(d: np.ndarray) -> np.ndarray:
    """Reference fill: a hole takes min(nearest valid left, nearest valid right) in its row."""
    out = d.copy()
    h, w = d.shape
    idx = np.arange(w)
    for y in range(h):
        row = d[y]
        v = np.isfinite(row)
        if not v.any() or v.all():
            continue
        left_i = np.maximum.accumulate(np.where(v, idx, -1))
        right_i = np.minimum.accumulate(np.where(v, idx, w)[::-1])[::-1]
        lv = np.where(left_i >= 0, row[np.clip(left_i, 0, w - 1)], np.inf)
        rv = np.where(right_i < w, row[np.clip(right_i, 0, w - 1)], np.inf)
        out[y] = np.where(v, row, np.minimum(lv, rv))
    return out


def bad(d: np.ndarray, gt: np.ndarray, t: float = 2.0) -> tuple[float, float]:
    known = np.isfinite(gt) & (gt > 0)
    have = np.isfinite(d) & (d >= 0) & known
    err = np.abs(np.where(have, d, 0) - np.where(known, gt, 0))
    ok = have & (err <= t)
    return 100.0 * (1 - ok.sum() / known.sum()), 100.0 * have.sum() / known.sum()


def cv_to_float(raw: np.ndarray) -> np.ndarray:
    d = raw.astype(np.float32) / 16.0
    d[d < 0] = np.nan
    return d


def sgbm(lb: np.ndarray, rb: np.ndarray, dmax: int) -> np.ndarray:
    d16 = (dmax + 15) // 16 * 16
    s = cv2.StereoSGBM_create(
        minDisparity=0,
        numDisparities=d16,
        blockSize=5,
        P1=8 * 3 * 25,
        P2=32 * 3 * 25,
        disp12MaxDiff=1,
        uniquenessRatio=10,
        speckleWindowSize=100,
        speckleRange=2,
        mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY,
    )
    return cv_to_float(s.compute(lb, rb))


def bm(lg: np.ndarray, rg: np.ndarray, dmax: int) -> np.ndarray:
    d16 = (dmax + 15) // 16 * 16
    return cv_to_float(cv2.StereoBM_create(d16, 15).compute(lg, rg))


def depth_metrics(d: np.ndarray, gt: np.ndarray, cal: dict[str, float]) -> tuple[float, float]:
    f, b, doffs = cal["f"], cal["baseline"], cal.get("doffs", 0.0)
    m = np.isfinite(d) & (d > 0) & np.isfinite(gt) & (gt > 0) & (d + doffs > 0)
    z = f * b / (d[m] + doffs)
    zg = f * b / (gt[m] + doffs)
    rel = np.abs(z - zg) / zg
    return 100 * float(np.median(rel)), 100 * float(np.mean(rel > 0.05))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default="")
    ap.add_argument("--param", action="append", default=[])
    ap.add_argument("--no-cv", action="store_true")
    args = ap.parse_args()
    params: dict[str, object] = {}
    for kv in args.param:
        k, v = kv.split("=", 1)
        params[k] = json.loads(v)
    cv2.setNumThreads(2)
    names = [s for s in SCENES if not args.scenes or any(p in s for p in args.scenes.split(","))]
    rows = []
    hdr = f"{'scene':38s} {'fill':>6s} {'unf':>6s} {'dens':>5s} {'BM':>6s} {'SGBM':>6s} {'ms':>6s}"
    print(hdr)
    for name in names:
        d = DATA / name
        lb, rb = cv2.imread(str(d / "left.png")), cv2.imread(str(d / "right.png"))
        lg, rg = cv2.cvtColor(lb, cv2.COLOR_BGR2GRAY), cv2.cvtColor(rb, cv2.COLOR_BGR2GRAY)
        gt = read_pfm(d / "gt_disp.pfm")
        dmax = SCENES[name]
        lf = lg.astype(np.float32) / 255
        rf = rg.astype(np.float32) / 255
        t = time.perf_counter()
        res = gabor_disparity(lf, rf, max_disparity=dmax, **params)
        ms = 1e3 * (time.perf_counter() - t)
        ours = res.disparity
        b_unf, dens = bad(ours, gt)
        b_fill, _ = bad(row_fill(ours), gt)
        row = {"scene": name, "fill": b_fill, "unf": b_unf, "dens": dens, "ms": ms}
        if not args.no_cv:
            row["bm"] = bad(bm(lg, rg, dmax), gt)[0]
            sg = sgbm(lb, rb, dmax)
            row["sgbm"], row["sgbm_dens"] = bad(sg, gt)
            if name in METRIC:
                cal = read_calib(d / "calib.txt")
                row["depth_ours"] = depth_metrics(ours, gt, cal)
                row["depth_sgbm"] = depth_metrics(sg, gt, cal)
                known = np.isfinite(gt) & (gt > 0)
                row["cov_ratio"] = (np.isfinite(ours) & known).sum() / max(
                    1, (np.isfinite(sg) & known).sum()
                )
        rows.append(row)
        print(
            f"{name:38s} {b_fill:6.1f} {b_unf:6.1f} {dens:5.1f} {row.get('bm', np.nan):6.1f} "
            f"{row.get('sgbm', np.nan):6.1f} {ms:6.0f}"
            + (
                "  BEATS-BM"
                if row.get("bm", 1e9) > b_fill
                else "  LOSES-TO-BM"
                if "bm" in row
                else ""
            )
        )
    mean = {k: float(np.mean([r[k] for r in rows])) for k in ("fill", "unf", "dens", "ms")}
    line = f"{'MEAN':38s} {mean['fill']:6.1f} {mean['unf']:6.1f} {mean['dens']:5.1f}"
    if not args.no_cv:
        mb, ms_ = np.mean([r["bm"] for r in rows]), np.mean([r["sgbm"] for r in rows])
        line += f" {mb:6.1f} {ms_:6.1f}   fill/SGBM = {mean['fill'] / ms_:.3f}"
    print(line)
    for r in rows:
        if "depth_ours" in r:
            (mo, fo), (mg, fg) = r["depth_ours"], r["depth_sgbm"]
            print(
                f"depth {r['scene']:28s} ours med {mo:5.2f}% >5% {fo:5.1f}%   "
                f"SGBM med {mg:5.2f}% >5% {fg:5.1f}%   coverage ours/SGBM {r['cov_ratio']:.3f}"
            )


if __name__ == "__main__":
    main()
