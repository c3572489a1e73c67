"""Speed and accuracy of every method beside OpenCV, on the same pairs in the same run.

``stereovision bench [SCENE_DIR...]`` (evaluation.md "Speed"): for each scene, every case runs once
as a warm-up, then all cases run in turn (A, B, C, ... A, B, C, ...) ``runs`` times and the median
time of each is reported with its ratio to OpenCV StereoSGBM 3-way's, beside its accuracy
(evaluation.md's metrics against the scene's ground truth when it has one). The cases:

* each dense method of :data:`stereovision.depth.METHODS`, the matcher alone on the grey float
  pair (converted once, outside the timing, as OpenCV's is loaded once);
* ``pipeline``: :func:`stereovision.depth_map` with the default method from the BGR pair and
  the scene's calibration: input checks, conversion, matching, triangulation and point cloud;
* each sparse method of :data:`stereovision.match.METHODS` (precision@0.5/1/2, count and 4x4
  coverage instead of the dense figures);
* ``StereoBM`` and ``SGBM-3WAY``: :mod:`stereovision.baselines`, evaluation.md's configuration.

All use every core (OpenCV's and rayon's default thread pools). A table is printed (bad-2.0,
filled, density; precision@1, count), then one JSON object per case with every figure of
:attr:`BenchCase.accuracy` (``--json``: only those); a figure with nothing to measure (a scene
without a known GT pixel, a sparse method without a match on GT) is ``null`` there, as in
``eval --json``.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from stereovision._jsonout import json_line
from stereovision._validate import BUG_ERRORS, NOT_NUMBERS, escaped

__all__ = ["BenchCase", "add_cli", "bench_scene", "cmd_bench", "format_table", "sparse_name"]

#: evaluation.md "Speed": the median of at least this many timed runs (fewer is noise on the
#: shared 2-core machines); also the default.
MIN_RUNS = 5
DEFAULT_RUNS = MIN_RUNS
REFERENCE = "SGBM-3WAY"


@dataclass
class BenchCase:
    """Figures of one case on one scene.

    Attributes
    ----------
    scene : str
    case : str
        Method name, ``pipeline``, ``StereoBM`` or ``SGBM-3WAY``.
    kind : str
        ``method`` (dense matcher alone), ``pipeline``, ``sparse`` or ``opencv``.
    ms : float
        Median time of the timed runs, milliseconds.
    ratio : float
        ``ms`` / SGBM-3WAY's ``ms`` in the same run (< 1 = faster than SGBM).
    accuracy : dict
        evaluation.md's figures, reported together. Dense: ``bad_0.5`` to ``bad_4.0`` (holes
        counted), ``bad_2.0_filled`` (after the reference row fill), ``density`` (percent),
        ``avgerr`` and ``rms`` (px). Sparse: ``precision@0.5``, ``precision@1.0``,
        ``precision@2.0``, ``count`` and ``coverage`` (cells of the 4 x 4 grid). Empty without
        GT.
    width, height : int
        The scene's image size, pixels.
    max_disparity : int
        The scene's disparity range.
    runs : int
        Timed runs the median ``ms`` is taken over.
    """

    scene: str
    case: str
    kind: str
    width: int
    height: int
    max_disparity: int
    runs: int
    ms: float
    ratio: float
    accuracy: dict[str, float]

    def as_dict(self) -> dict[str, Any]:
        """The JSON object of the case.

        Returns
        -------
        dict
            ``bench`` (``"vs_opencv"``), ``scene``, ``case``, ``kind``, ``width``, ``height``,
            ``max_disparity``, ``runs``, ``ms`` and ``ratio_sgbm`` (rounded), then the
            :attr:`accuracy` figures (rounded to 3 decimals; NaN where there is nothing to
            measure).
        """
        return {
            "bench": "vs_opencv",
            "scene": self.scene,
            "case": self.case,
            "kind": self.kind,
            "width": self.width,
            "height": self.height,
            "max_disparity": self.max_disparity,
            "runs": self.runs,
            "ms": round(self.ms, 3),
            "ratio_sgbm": round(self.ratio, 4),
            **{k: round(v, 3) for k, v in self.accuracy.items()},
        }


def _dense_accuracy(disp: np.ndarray, gt: np.ndarray | None) -> dict[str, float]:
    from stereovision.baselines import row_fill
    from stereovision.evaluate import dense_metrics

    if gt is None:
        return {}
    raw = dense_metrics(disp, gt)
    filled = dense_metrics(row_fill(disp), gt)
    # evaluation.md: "report all of them together": bad-2.0 and density alone left out bad-0.5,
    # -1.0 and -4.0, avgerr and rms, which eval reports of the same maps
    acc = {"bad_2.0": raw.bad[2.0], "bad_2.0_filled": filled.bad[2.0], "density": raw.density}
    others = raw.as_dict().items()  # its pixel counts n_gt, n_both are no figure of the case
    acc.update({k: float(v) for k, v in others if k not in acc and not k.startswith("n_")})
    return acc


def _sparse_accuracy(matches: Any, gt: np.ndarray | None) -> dict[str, float]:
    from stereovision.evaluate import sparse_metrics

    if gt is None:
        return {}
    sm = sparse_metrics(matches.xl, matches.yl, matches.xr, gt)
    # evaluation.md: precision@1 "also report @0.5 and @2", and the count's spread over a 4x4
    # grid: precision@1 and the count alone hid both
    acc: dict[str, float] = {f"precision@{t:.1f}": v for t, v in sm.precision.items()}
    acc.update(count=sm.count, coverage=sm.coverage)
    return acc


def sparse_name(method: str) -> str:
    """Case name of a sparse method.

    Parameters
    ----------
    method : str
        A method of :data:`stereovision.match.METHODS`.

    Returns
    -------
    str
        ``method``, or ``method + "-sparse"`` for one that is also a dense method of
        :data:`stereovision.depth.METHODS` (``fused-sparse``).
    """
    from stereovision.depth import METHODS

    return f"{method}-sparse" if method in METHODS else method


def _runs_rule(runs: object) -> str:
    # an integer as its number (NumPy 2's repr said np.int64(4)); anything else as Python shows it
    exact = isinstance(runs, (int, np.integer)) and not isinstance(runs, NOT_NUMBERS)
    shown = str(runs) if exact else repr(runs)
    return f"at least {MIN_RUNS} (evaluation.md: the median of >= {MIN_RUNS} runs), got {shown}"


def _check_runs(runs: object, name: str) -> None:
    """Refuse a ``runs`` that is no integer (5.5 and NaN passed ``runs < 5`` and failed in
    ``range`` after every warm-up) or below :data:`MIN_RUNS`, naming ``name``."""
    if not isinstance(runs, (int, np.integer)) or isinstance(runs, NOT_NUMBERS):  # 5 ns
        raise ValueError(f"{name}: expected an integer, {_runs_rule(runs)}")
    if runs < MIN_RUNS:
        raise ValueError(f"{name}: {_runs_rule(runs)}")


def _run_count(text: str) -> int:
    """argparse type of ``bench --runs``: a whole number from :data:`MIN_RUNS` to
    :data:`stereovision.cli.MAX_RUNS`, refused by the parser in the form ``eval --runs`` is
    ('stereovision bench: error: argument --runs: ...'), not as a bare 'stereovision: error:'."""
    import argparse

    from stereovision.cli import MAX_RUNS, whole_number

    value = whole_number(text)  # 5.0 too, as every whole-number option takes it
    if value is None:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}")
    if value < MIN_RUNS:
        raise argparse.ArgumentTypeError(
            f"expected at least {MIN_RUNS} runs (evaluation.md: the median of >= {MIN_RUNS} "
            f"runs), got {text!r}"
        )
    if value > MAX_RUNS:
        raise argparse.ArgumentTypeError(f"expected at most {MAX_RUNS} runs, got {text!r}")
    return value


def bench_scene(scene: Any, runs: int = DEFAULT_RUNS) -> list[BenchCase]:
    """Time and score every case on one scene (see the module doc).

    Parameters
    ----------
    scene : stereovision.io.Scene
        The pair, its GT (optional) and calibration (optional); ``max_disparity`` is the range
        every case searches (evaluation.md).
    runs : int
        Timed runs per case (>= :data:`MIN_RUNS`, evaluation.md's rule), after one warm-up.

    Returns
    -------
    list of BenchCase
        In the order: dense methods, pipeline, sparse methods, StereoBM, SGBM-3WAY; no
        StereoBM on a scene it cannot run on (:func:`~stereovision.baselines.bm_reference_refusal`).

    Raises
    ------
    ValueError
        If ``runs`` is not an integer or is < :data:`MIN_RUNS` (the median of fewer runs is not
        a figure to report).
    TypeError
        If ``scene`` is a path (a scene folder: :func:`stereovision.io.load_scene` reads it) or
        no scene (None).
    """
    from stereovision import baselines
    from stereovision._validate import as_gray_float
    from stereovision.depth import METHODS, _run_matcher, depth_map
    from stereovision.io import _refuse_no_scene
    from stereovision.match import METHODS as SPARSE_METHODS
    from stereovision.match import match

    _check_runs(runs, "runs")
    _refuse_no_scene(scene)  # a folder or None was an AttributeError naming no argument
    left, right, gt, md = scene.left, scene.right, scene.gt, int(scene.max_disparity)
    calib = scene.calib if scene.calib is not None and scene.calib.rectified else None
    gl, gr = as_gray_float(left, "left"), as_gray_float(right, "right")
    outputs: dict[str, Any] = {}

    def dense(m: str) -> Callable[[], Any]:
        return lambda: _run_matcher(m, gl, gr, 0.0, float(md), {})[0]

    def sparse(m: str) -> Callable[[], Any]:
        return lambda: match(left, right, method=m, max_disparity=md)

    def keep(name: str, fn: Callable[[], Any]) -> Callable[[], None]:
        def run() -> None:
            outputs[name] = fn()

        return run

    cases: list[tuple[str, str, Callable[[], None]]] = [
        (m, "method", keep(m, dense(m))) for m in METHODS
    ]
    pipeline = lambda: depth_map(left, right, calib, max_disparity=md).disparity  # noqa: E731
    cases.append(("pipeline", "pipeline", keep("pipeline", pipeline)))
    # gabor's Matches are its dense run's confident pixels: timed once, as a dense method
    sparse_only = [m for m in SPARSE_METHODS if m not in ("gabor",)]
    cases += [(sparse_name(m), "sparse", keep(sparse_name(m), sparse(m))) for m in sparse_only]
    # the widest range StereoBM's block has room for, on a scene narrower than md + 14 px
    bm_md = baselines.bm_reference_range(md, np.asarray(left).shape[1])
    bm = lambda: baselines.opencv_bm(left, right, bm_md)  # noqa: E731
    sgbm = lambda: baselines.opencv_sgbm(left, right, md)  # noqa: E731
    # none on a scene no higher than its block (or under 30 px wide): its refusal failed the
    # whole scene; cmd_bench says why the case is missing
    if baselines.bm_reference_refusal(md, np.asarray(left).shape) is None:
        cases += [("StereoBM", "opencv", keep("StereoBM", bm))]
    cases += [(REFERENCE, "opencv", keep(REFERENCE, sgbm))]
    for _, _, fn in cases:  # warm-up: first-call allocations, thread pools, caches
        fn()
    times: dict[str, list[float]] = {name: [] for name, _, _ in cases}
    for _ in range(runs):
        for name, _, fn in cases:
            t = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - t)
    med = {k: 1e3 * statistics.median(v) for k, v in times.items()}
    h, w = gl.shape
    result = []
    for name, kind, _ in cases:
        out = outputs[name]
        acc = _sparse_accuracy(out, gt) if kind == "sparse" else _dense_accuracy(out, gt)
        result.append(
            BenchCase(
                scene.name, name, kind, w, h, md, runs, med[name], med[name] / med[REFERENCE], acc
            )
        )
    return result


def _fmt(v: float | None, spec: str) -> str:
    return format(v, spec) if v is not None and math.isfinite(v) else "-"


def format_table(cases: Sequence[BenchCase]) -> str:
    """A text table of the cases.

    Parameters
    ----------
    cases : sequence of BenchCase
        As :func:`bench_scene` returns them (several scenes' in turn).

    Returns
    -------
    str
        A header line, then one line per case (the scene, size and range on its first case
        only; ``-`` for a figure without a value).
    """
    # the scene column as wide as the longest name (34 at least): a longer one pushed its rows'
    # figures out from under their labels
    col = max([34] + [len(escaped(c.scene)) for c in cases])
    lines = [
        f"{'scene':{col}s} {'size':>9s} {'D':>4s} {'case':12s} {'ms':>8s} {'x SGBM':>7s}"
        f" {'bad-2':>6s} {'+fill':>6s} {'dens':>6s} {'p@1':>6s} {'count':>6s}"
    ]
    last = None
    for c in cases:
        head = (
            f"{escaped(c.scene):{col}s} {c.width:4d}x{c.height:<4d} {c.max_disparity:4d}"
            if c.scene != last
            else " " * (col + 15)
        )
        last = c.scene
        a = c.accuracy
        lines.append(
            f"{head} {c.case:12s} {c.ms:8.1f} {c.ratio:7.2f}"
            f" {_fmt(a.get('bad_2.0'), '6.1f'):>6s} {_fmt(a.get('bad_2.0_filled'), '6.1f'):>6s}"
            f" {_fmt(a.get('density'), '6.1f'):>6s} {_fmt(a.get('precision@1.0'), '6.1f'):>6s}"
            f" {_fmt(a.get('count'), '6.0f'):>6s}"
        )
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------- CLI


def _scene_dirs(paths: Sequence[str]) -> list[Path]:
    from stereovision.io import _no_scene_under, distinct_scenes, scan_scenes

    if not paths:
        return [Path(str(resources.files("stereovision") / "data" / "cones"))]
    dirs: list[Path] = []
    for d in paths:
        if not Path(d).exists():  # as eval says it (scan_scenes: "scene root not found")
            from stereovision.io import _broken_link

            gone = f" ({_broken_link(Path(d))})" if Path(d).is_symlink() else ""
            raise FileNotFoundError(f"scene folder not found: {d}{gone}")
        if not Path(d).is_dir():  # find_scenes: "scene root not found"
            # /dev/null or a pipe is no file either (load_scene's words, aae87eaf)
            what = "is a file" if Path(d).is_file() else "is not a folder (a device or a pipe)"
            raise ValueError(f"{d}: {what}; give a scene folder (holding left.png, right.png)")
        found, half = scan_scenes(d)
        if not found:
            # eval's line: a half scene skipped, or a JPEG pair, was not named
            raise ValueError(_no_scene_under(Path(d), d, half))
        # as eval: half a scene among scenes was left out without a word
        for folder, reason in half:
            print(f"stereovision: skipped {escaped(str(folder))}: {reason}", file=sys.stderr)
        dirs.extend(found)
    # as eval: a scene named twice (its folder and one holding it) was timed twice
    dirs, dropped = distinct_scenes(dirs)
    for s in dropped:
        print(
            f"stereovision: {escaped(str(s))} given more than once: benched once", file=sys.stderr
        )
    return dirs


def cmd_bench(args: argparse.Namespace) -> int:
    """``stereovision bench [SCENE_DIR...]``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``scenes``, ``runs``, ``json``.

    Returns
    -------
    int
        The exit status: 0, or 1 when some of several scenes failed (each said on a
        ``failed`` line, the others benched); other errors are raised, for the CLI to print
        as one line. A Ctrl-C (or SIGTERM) prints the scenes timed so far, then is raised.

    Raises
    ------
    ValueError
        If ``runs`` < :data:`MIN_RUNS` or > :data:`stereovision.cli.MAX_RUNS`, a folder
        holds no scene, or the one scene given cannot be benched (damaged, too narrow).
    FileNotFoundError
        If a scene folder does not exist.
    """
    from tqdm import tqdm

    from stereovision import baselines
    from stereovision.cli import MAX_RUNS, middlebury_gt_hint, scene_failed_line
    from stereovision.evaluate import gt_at_zero_note
    from stereovision.io import load_scene, scene_names, scene_too_narrow

    _check_runs(args.runs, "--runs")
    if args.runs > MAX_RUNS:  # any count was taken: --runs 10**20 ran until killed
        raise ValueError(f"--runs: at most {MAX_RUNS}, got {args.runs}")
    dirs = _scene_dirs(args.scenes)
    # as eval: day1/cam/0001 and day2/cam/0001 were both cam/0001 in the table and the JSON
    names = dict(zip(dirs, scene_names(dirs), strict=True))
    all_cases: list[BenchCase] = []
    failed: list[str] = []
    quiet = args.json or len(dirs) < 2 or not sys.stderr.isatty()

    def print_table() -> None:
        if not args.json and all_cases:  # --json printed each scene's lines as it went
            print(format_table(all_cases))
            for c in all_cases:
                print(json_line(c.as_dict()))

    if len(dirs) == 1 and not args.json and sys.stderr.isatty():
        # the bar counts scenes, so one scene had none: 10-30 s of timing without a word
        print(
            f"{escaped(str(dirs[0]))}: timing every case, a warm-up and {args.runs} rounds "
            "(the table follows) ...",
            file=sys.stderr,
            flush=True,
        )
    try:
        for d in tqdm(dirs, desc="scenes", file=sys.stderr, disable=quiet):
            try:
                scene = load_scene(d, full_bits=True)  # as `depth` reads a 16-bit pair
                scene.name = names[d]
                # as eval: a GT left under Middlebury's name gave '-' for every figure, unsaid
                hint = middlebury_gt_hint(d) if scene.gt is None else ""
                if hint:
                    tqdm.write(
                        f"stereovision: {escaped(str(d))}: no ground truth (gt_disp.pfm), times "
                        f"only{hint}",
                        file=sys.stderr,
                    )
                elif scene.gt is not None and not np.isfinite(scene.gt).any():
                    # as eval's skip line: every figure '-' (null) and each sparse count 0, unsaid
                    tqdm.write(
                        f"stereovision: {escaped(str(d))}: no ground truth: gt_disp.pfm has no "
                        "known (finite) pixel, times only",
                        file=sys.stderr,
                    )
                # as eval: a GT converted keeping KITTI's 0 = unknown was scored against its 0s
                zero_note = gt_at_zero_note(scene.gt)
                if zero_note is not None:
                    tqdm.write(f"stereovision: {escaped(str(d))}: {zero_note}", file=sys.stderr)
                narrow = scene_too_narrow(scene)
                if narrow:
                    # as eval says it: "disparity range 16 is not smaller than the image width 8
                    # ...; give a max_disparity below 8" named a range and an option bench has not
                    raise ValueError(f"{d}: {narrow}")
                cases = bench_scene(scene, runs=args.runs)
            except BUG_ERRORS:  # RuntimeErrors, but a bug of ours: not one damaged scene of many
                raise
            except (ValueError, OSError, RuntimeError) as e:
                if len(dirs) == 1:
                    raise
                # one damaged scene of many, as eval: said, and the others benched (it stopped
                # the run, and without --json the table of the scenes timed before it was never
                # printed)
                failed.append(str(d))
                tqdm.write(scene_failed_line(d, e), file=sys.stderr)
                continue
            all_cases.extend(cases)
            # bench_scene left StereoBM out (too low for its block): say why
            no_bm = baselines.bm_reference_refusal(scene.max_disparity, scene.left.shape)
            if no_bm is not None:
                tqdm.write(f"{escaped(str(d))}: no StereoBM figures: {no_bm}", file=sys.stderr)
            if args.json:
                for c in cases:
                    print(json_line(c.as_dict()), flush=True)
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM (Terminated): the scenes timed are kept
        print_table()
        raise
    print_table()
    if failed:
        print(f"stereovision: {len(failed)} of {len(dirs)} scenes failed (above)", file=sys.stderr)
        return 1
    return 0


def add_cli(subparsers: Any) -> None:
    """Register ``stereovision bench`` on the CLI's sub-parsers."""
    from stereovision.cli import MAX_RUNS

    p = subparsers.add_parser(
        "bench",
        help="time and accuracy of every method beside OpenCV StereoBM / SGBM-3WAY",
        description="Each method, the whole pipeline and OpenCV's StereoBM and SGBM-3WAY on the "
        "same pairs in the same run (interleaved, median of --runs after a warm-up): a table, "
        "then one JSON line per case. Default scene: the bundled Middlebury Cones.",
    )
    p.add_argument("scenes", nargs="*", help="scene folders (or folders containing scenes)")
    p.add_argument(
        "--runs",
        type=_run_count,
        default=DEFAULT_RUNS,
        help=f"timed runs per case, at least {MIN_RUNS} (default {DEFAULT_RUNS}), "
        f"at most {MAX_RUNS}",
    )
    p.add_argument("--json", action="store_true", help="only the JSON lines")
    p.set_defaults(func=cmd_bench)
