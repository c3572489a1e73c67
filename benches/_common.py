"""Pieces the Python benches share: scene list, sparse figures, interleaved timing.

The benches run as scripts (``python benches/bench_x.py``), so this folder is on ``sys.path``.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeVar

import numpy as np

from stereovision.bench import MIN_RUNS, _run_count
from stereovision.evaluate import count_at_precision, sparse_metrics
from stereovision.matches import Matches

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"

#: argparse ``type`` of a bench's ``--runs`` / ``--repeats``: ``stereovision bench --runs``'s
#: rule, kept in one place (a copy here had no upper bound: ``--runs 1000000000`` ran on)
timed_runs = _run_count

T = TypeVar("T")


def picture_path(text: str) -> Path:
    """argparse ``type`` of a bench's ``--picture`` / ``--out`` written with OpenCV: the path,
    or argparse's one-line error when OpenCV has no writer for its extension (cv2.imwrite's
    traceback once the bench had run) or it is a folder."""
    import cv2

    path = Path(text)
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: is a folder; give a file such as {text}/x.jpg")
    if not cv2.haveImageWriter(text):
        raise argparse.ArgumentTypeError(
            f"{text}: OpenCV writes no image of that extension; give a .jpg or .png"
        )
    return path


def write_picture(path: Path, image: np.ndarray) -> None:
    """Write a bench's picture as JPEG quality 88 (the docs' pictures), its folder made first.

    cv2.imwrite returns False without a word where it cannot write (a missing folder): the
    benches printed "wrote PATH" of no file. That is an ``OSError`` naming ``path`` now."""
    import cv2

    path.parent.mkdir(parents=True, exist_ok=True)  # as plot_charuco and plot_bad2_panels do
    if not cv2.imwrite(str(path), image, [cv2.IMWRITE_JPEG_QUALITY, 88]):
        raise OSError(f"{path}: OpenCV could not write the picture")


def gabor_param(text: str) -> tuple[str, object]:
    """argparse ``type`` of a bench's ``--param key=JSON``: the pair, or argparse's one-line
    error (a missing ``=`` or a value that is not JSON was a traceback of the unpacking or of
    json.loads). Unknown keys: :func:`gabor_params`."""
    key, eq, value = text.partition("=")
    if not eq or not key:
        raise argparse.ArgumentTypeError(f"expected key=value (value in JSON), got {text!r}")
    try:
        return key, json.loads(value)
    except json.JSONDecodeError:
        # a bare word is most likely a string meant: say how the shell passes its quotes
        hint = f" (a string is quoted: {key}='\"{value}\"')" if value.isidentifier() else ""
        raise argparse.ArgumentTypeError(f"{key}: {value!r} is not a JSON value{hint}") from None


def gabor_params(
    ap: argparse.ArgumentParser, pairs: Sequence[tuple[str, object]]
) -> dict[str, object]:
    """The ``--param`` pairs as gabor_disparity's overrides; an unknown key is ``ap``'s one-line
    error before any scene is loaded (it was gabor_disparity's traceback on the first scene)."""
    from stereovision._validate import refuse_unknown
    from stereovision.matching.gabor import DEFAULTS

    params = dict(pairs)
    try:
        refuse_unknown("Gabor parameter", params, DEFAULTS, "stereovision.matching.gabor.DEFAULTS")
    except ValueError as e:
        ap.error(f"argument --param: {e}")
    return params


def gt_scenes() -> list[str]:
    """``family/scene`` of every scene of ``shared/data`` with a ``gt_disp.pfm``, sorted."""
    return sorted(str(p.parent.relative_to(DATA)) for p in DATA.glob("*/*/gt_disp.pfm"))


def gt_scene(name: str) -> str:
    """argparse ``type`` of a bench's ``--scenes`` name: a ``family/scene`` of ``shared/data``
    or a scene folder (as the benches load ``DATA / name``), either holding a ``gt_disp.pfm``;
    else argparse's one-line error listing :func:`gt_scenes` (a typo or a scene without GT was
    load_scene's FileNotFoundError traceback once the bench had started)."""
    if (DATA / name / "gt_disp.pfm").is_file():  # an absolute folder too: DATA / it is it
        return name
    if (Path(name) / "gt_disp.pfm").is_file():  # relative to the working directory
        return str(Path(name).resolve())
    raise argparse.ArgumentTypeError(
        f"{name!r} is no scene with a gt_disp.pfm: expected a scene folder or a family/scene "
        f"of {DATA}, one of {', '.join(gt_scenes())}"
    )


def scene_folder(name: str) -> str:
    """argparse ``type`` of a bench's scene that needs no GT (times only): ``name`` when it is a
    folder or a ``family/scene`` of ``shared/data``, else argparse's one-line error (a typo was
    load_scene's FileNotFoundError traceback)."""
    if (DATA / name).is_dir() or Path(name).is_dir():
        return name
    raise argparse.ArgumentTypeError(
        f"{name!r} is no folder: expected a scene folder or a family/scene of {DATA}, e.g. "
        f"{', '.join(gt_scenes()[:3])}"
    )


def gt_scene_list(text: str) -> list[str]:
    """argparse ``type`` of a comma-separated ``--scenes``: each name checked by
    :func:`gt_scene`; ``""`` (the default: every GT scene) is ``[]``."""
    return [gt_scene(name) for name in text.split(",")] if text else []


def sparse_row(m: Matches, gt: np.ndarray) -> dict[str, float | int]:
    """evaluation.md's sparse figures of ``m`` as a JSON-ready dict."""
    sm = sparse_metrics(m.xl, m.yl, m.xr, gt)
    return {
        "p05": round(sm.precision[0.5], 2),
        "p1": round(sm.precision[1.0], 2),
        "p2": round(sm.precision[2.0], 2),
        "count": sm.count,
        "coverage": sm.coverage,
    }


def count_at(m: Matches, gt: np.ndarray, target: float, tolerance: float = 1.0) -> int | None:
    """:func:`~stereovision.evaluate.count_at_precision` of ``m`` (ranked by its score) at the
    precision ``target`` of another matcher, or None (JSON null) when that precision is NaN:
    :func:`~stereovision.evaluate.sparse_metrics` gives NaN when no match has GT, and there is
    no count to hold at it (``count_at_precision`` refuses a NaN target, which crashed the bench
    on such a scene)."""
    if math.isnan(target):
        return None
    return count_at_precision(m.xl, m.yl, m.xr, m.score, gt, target, tolerance)


def interleaved_ms(fns: Sequence[Callable[[], object]], repeats: int) -> list[float]:
    """Median ms of each function: one warm-up each, then A, B, ... A, B, ... ``repeats`` times."""
    return interleaved_runs(fns, repeats)[0]


def interleaved_runs(fns: Sequence[Callable[[], T]], repeats: int) -> tuple[list[float], list[T]]:
    """:func:`interleaved_ms`, and what each function returned on its warm-up run (a bench that
    scores the output and times it runs each side ``repeats + 1`` times, not once more)."""
    if repeats < MIN_RUNS:
        raise ValueError(f"repeats: at least {MIN_RUNS} (evaluation.md), got {repeats}")
    results = [fn() for fn in fns]
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(repeats):
        for fn, acc in zip(fns, times, strict=True):
            t = time.perf_counter()
            fn()
            acc.append(time.perf_counter() - t)
    return [1e3 * statistics.median(t) for t in times], results


def plot_bad2_panels(
    title: str,
    left: np.ndarray,
    gt: np.ndarray,
    maps: dict[str, np.ndarray],
    out: Path,
    figsize: tuple[float, float],
) -> Path:
    """A 2 x 3 figure for the README: the left image, the GT, then each of the four ``maps``
    (disparity, NaN = hole) coloured like the GT with every pixel off by more than 2 px painted
    red and its bad-2.0 (holes counted) in the panel's title. Written to ``out`` (PNG, 80 dpi)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # evaluation.md's known GT (finite; a 0 px GT counts, as in dense_metrics): "& gt > 0" left
    # a hole on a 0 px pixel out of the title's bad-2.0
    valid = np.isfinite(gt)
    vmax = float(np.nanmax(gt[valid]))
    fig, axes = plt.subplots(2, 3, figsize=figsize)
    axes[0, 0].imshow(left if left.ndim == 2 else left[..., ::-1], cmap="gray")
    axes[0, 0].set_title(f"{title}: left")
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
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=80)
    plt.close(fig)
    return out
