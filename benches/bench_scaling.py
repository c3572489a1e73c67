"""How our default pipeline's time grows with image size and with max_disparity, beside SGBM-3WAY.

evaluation.md "Speed": same pair, same process, interleaved (ours, SGBM, ours, SGBM ...), median of
``--runs`` after a warm-up, both on every core. The pair is a real 640x480 scene
(tartanair/oldtown, see its SOURCE) resized to each size (cubic); the disparity range does not
change with the resize, so every size searches the same ``max_disparity``. Two sweeps:

* size: VGA (640x480), 720p (1280x720), 1080p (1920x1080) at ``max_disparity`` 64;
* range: ``max_disparity`` 32, 64, 128, 192 at VGA.

"Ours" is :func:`stereovision.depth_map` with ``--method`` (default: its default method) and no
calibration (the matcher, input checks and conversion); SGBM is
:func:`stereovision.baselines.opencv_sgbm`.
Prints a table, the growth factors (largest / smallest case, ours and SGBM's) and one JSON line
per case, and draws ``docs/images/scaling.png`` (``--plot PATH`` to change; matplotlib, the
``bench`` extra).

Usage: ``python benches/bench_scaling.py [--runs 5] [--method M] [--plot docs/images/scaling.png]``
"""

from __future__ import annotations

import argparse
import inspect
import json
from pathlib import Path

import cv2
from _common import interleaved_ms, timed_runs

from stereovision import baselines, depth_map
from stereovision.depth import METHODS

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT.parent / "shared" / "data" / "tartanair" / "oldtown_easy_p000_001116"
SIZES = {"VGA": (640, 480), "720p": (1280, 720), "1080p": (1920, 1080)}
SIZE_SWEEP_D = 64
D_SWEEP = (32, 64, 128, 192)
DEFAULT_METHOD = inspect.signature(depth_map).parameters["method"].default


def _plot(rows: list[dict], path: Path, method: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, sweep, xkey, xlabel in (
        (axes[0], "size", "megapixels", f"image size, megapixels (max_disparity {SIZE_SWEEP_D})"),
        (axes[1], "max_disparity", "max_disparity", "max_disparity, px (640x480)"),
    ):
        sel = [r for r in rows if r["sweep"] == sweep]
        xs = [r[xkey] for r in sel]
        ax.plot(xs, [r["ours_ms"] for r in sel], "o-", label=f"stereovision ({method})")
        ax.plot(xs, [r["sgbm_ms"] for r in sel], "s--", label="OpenCV SGBM-3WAY")
        if sweep == "size":
            for r in sel:
                ax.annotate(
                    r["label"],
                    (r[xkey], r["ours_ms"]),
                    textcoords="offset points",
                    xytext=(0, 8),
                    ha="center",
                    fontsize=8,
                )
        ax.set_xlabel(xlabel)
        ax.set_ylabel("median time, ms (2 cores)")
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.legend()
    fig.suptitle("Time vs image size and disparity range (same pair, same run, interleaved)")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=timed_runs, default=5, help="timed runs per case (median)")
    ap.add_argument(
        "--method", default=DEFAULT_METHOD, choices=METHODS, help=f"ours (default {DEFAULT_METHOD})"
    )
    ap.add_argument("--plot", type=Path, default=ROOT / "docs" / "images" / "scaling.png")
    args = ap.parse_args()
    left0, right0 = cv2.imread(str(SCENE / "left.png")), cv2.imread(str(SCENE / "right.png"))
    if left0 is None or right0 is None:
        raise SystemExit(f"scene not found: {SCENE}")
    cases = [("size", name, wh, SIZE_SWEEP_D) for name, wh in SIZES.items()]
    cases += [("max_disparity", f"D {d}", SIZES["VGA"], d) for d in D_SWEEP]
    rows = []
    print(
        f"{'sweep':14s} {'case':6s} {'size':>9s} {'D':>4s} {'ours':>8s} {'SGBM':>8s} {'ratio':>6s}"
    )
    for sweep, label, (w, h), d in cases:
        left = cv2.resize(left0, (w, h), interpolation=cv2.INTER_CUBIC)
        right = cv2.resize(right0, (w, h), interpolation=cv2.INTER_CUBIC)
        ours, sgbm = interleaved_ms(
            (
                lambda left=left, right=right, d=d: depth_map(
                    left, right, None, method=args.method, max_disparity=d
                ),
                lambda left=left, right=right, d=d: baselines.opencv_sgbm(left, right, d),
            ),
            args.runs,
        )
        row = {
            "bench": "scaling",
            "sweep": sweep,
            "label": label,
            "method": args.method,
            "width": w,
            "height": h,
            "megapixels": round(w * h / 1e6, 4),
            "max_disparity": d,
            "runs": args.runs,
            "ours_ms": round(ours, 2),
            "sgbm_ms": round(sgbm, 2),
            "ratio": round(ours / sgbm, 3),
        }
        rows.append(row)
        size = f"{w}x{h}"
        print(
            f"{sweep:14s} {label:6s} {size:>9s} {d:4d} {ours:8.1f} {sgbm:8.1f} {ours / sgbm:6.2f}"
        )
    for sweep in ("size", "max_disparity"):
        sel = [r for r in rows if r["sweep"] == sweep]
        g_ours = sel[-1]["ours_ms"] / sel[0]["ours_ms"]
        g_sgbm = sel[-1]["sgbm_ms"] / sel[0]["sgbm_ms"]
        print(
            f"growth over {sweep} ({sel[0]['label']} -> {sel[-1]['label']}): "
            f"ours x{g_ours:.2f}, SGBM-3WAY x{g_sgbm:.2f}"
        )
        rows.append(
            {
                "bench": "scaling_growth",
                "sweep": sweep,
                "ours": round(g_ours, 3),
                "sgbm": round(g_sgbm, 3),
            }
        )
    for r in rows:
        print(json.dumps(r))
    _plot([r for r in rows if r["bench"] == "scaling"], args.plot, args.method)
    print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
