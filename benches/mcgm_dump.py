"""Dump the MCGM channel's outputs over a parameter grid, or compare two dumps bit for bit.

``python benches/mcgm_dump.py OUT.npz`` runs ``mcgm_match(..., debug=True)`` on crops of five
real scenes under 20 parameter sets (every channel's candidates, windows, network state, chosen
pairs, graph edges and raw matches; the final matches), B.8's filters on the finest channel's raw
matches, and every channel's curves, and saves all arrays. ``python benches/mcgm_dump.py
--compare A.npz B.npz`` prints how many arrays differ. Run the dump with two builds of the
extension (for example an older one put first on ``PYTHONPATH``) to check that a speed change
leaves the output bit-identical beyond the default parameters.
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np
from _common import DATA

from stereovision._validate import as_gray_float
from stereovision.io import load_scene
from stereovision.matching import mcgm

SCENES = [
    "middlebury2003/cones",
    "middlebury2005/art",
    "kitti2015/000005_10",
    "eth3d/terrace",
    "middlebury2001/tsukuba",
]
GRID: list[dict[str, Any]] = [
    {},
    {"min_disparity": 5},
    {"sides_width": 16, "sides_height": 3},
    {"sides_mean_free": False},
    {"sides_best_margin": 0.01},
    {"r_graph": 0.0},
    {"r_graph": 7.0, "knn": 2},
    {"ght_min_score": 0.0},
    {"ght_min_score": 0.9},
    {"n_theta_bins": 3, "vote_bin_tol": 1},
    {"n_theta_bins": 72, "vote_bin_tol": 5},
    {"dy_band": 0},
    {"dy_band": 3},
    {"prior_radius_sigmas": 0.0},
    {"prior_radius_sigmas": 9.0},
    {"sigmas": [8.0, 3.0, 1.5, 0.7]},
    {"sigmas": [1.0]},
    {"high_quantile": 0.0, "low_ratio": 1.0},
    {"high_quantile": 1.0},
    {"max_turn_deg": 170.0},
]


def dump(path: str) -> None:
    out: dict[str, np.ndarray] = {}
    for name in SCENES:
        sc = load_scene(DATA / name)
        left, right = as_gray_float(sc.left)[:220, :330], as_gray_float(sc.right)[:220, :330]
        for gi, grid in enumerate(GRID):
            md = int(sc.max_disparity)
            m = mcgm.mcgm_match(left, right, max_disparity=md, debug=True, **grid)
            out[f"{name}|{gi}|matches"] = np.stack([m.xl, m.yl, m.xr, m.yr, m.score])
            for ci, ch in enumerate(m.stats["channels"]):
                for key, val in ch.items():
                    out[f"{name}|{gi}|c{ci}|{key}"] = np.asarray(val)
            raw = m.stats["channels"][-1]["matches"][:, :4]
            fp = {k: v for k, v in grid.items() if k.startswith(("sides", "disc"))}
            keep = mcgm.edge_filters(left, right, raw, max_disparity=md, **fp)
            out[f"{name}|{gi}|filters"] = keep
        for ci, c in enumerate(mcgm.curves(left)):
            for key, val in vars(c).items():
                if isinstance(val, np.ndarray):
                    out[f"{name}|curves{ci}|{key}"] = val
    np.savez(path, **out)  # type: ignore[arg-type]
    print(f"{len(out)} arrays -> {path}")


def compare(a_path: str, b_path: str) -> int:
    a, b = np.load(a_path), np.load(b_path)
    if set(a.files) != set(b.files):
        print(f"different keys: {sorted(set(a.files) ^ set(b.files))[:10]}")
        return 1
    differ = [
        k
        for k in a.files
        if a[k].shape != b[k].shape
        or a[k].dtype != b[k].dtype
        or not np.array_equal(a[k], b[k], equal_nan=a[k].dtype.kind == "f")
    ]
    print(
        f"{len(a.files)} arrays compared, {len(differ)} differ{': ' if differ else ''}"
        + ", ".join(differ[:10])
    )
    return 1 if differ else 0


USAGE = "usage: mcgm_dump.py OUT.npz | mcgm_dump.py --compare A.npz B.npz"


def main() -> int:
    args = sys.argv[1:]
    if args in (["-h"], ["--help"]):
        print(f"{USAGE}\n\n{__doc__}")
        return 0
    if len(args) == 3 and args[0] == "--compare":
        return compare(args[1], args[2])
    if len(args) == 1 and not args[0].startswith("-"):
        dump(args[0])
        return 0
    print(USAGE, file=sys.stderr)
    return 2


if __name__ == "__main__":
    raise SystemExit(main())
