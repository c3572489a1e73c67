"""The Python bench scripts of ``benches/``: their command lines, not their figures.

Speed is measured by the scripts themselves (evaluation.md "Speed"); these tests only check that
a script refuses a median of fewer than 5 runs, that ``--help`` helps instead of running, and that
every ``benches/*.py`` command the README and docs cite takes the options it is cited with.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from stereovision.matches import Matches

ROOT = Path(__file__).resolve().parents[1]
BENCHES = ROOT / "benches"
TIMING = {
    "bench_calibration_targets.py": "--runs",
    "bench_gabor_vs_sgbm.py": "--runs",
    "bench_ground.py": "--runs",
    "bench_hopfield.py": "--repeats",
    "bench_mcgm.py": "--repeats",
    "bench_scaling.py": "--runs",
    "bench_sgm.py": "--runs",
    "bench_stages.py": "--repeats",
    "bench_tools.py": "--repeats",
    "bench_uncalibrated.py": "--runs",
    "eval_gabor_scenes.py": "--runs",
}


def _run(script: str, *args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    # the installed package, as `make` installs it (python/ holds no built extension)
    return subprocess.run(
        [sys.executable, str(BENCHES / script), *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
    )


def _main(script: str, *args: str) -> subprocess.CompletedProcess[str]:
    """``python benches/<script> *args`` run in this process (a process start cost about a
    second of CPU: Python, NumPy, OpenCV): the script's ``main()`` with that ``sys.argv``, its
    exit status (a SystemExit's, as Python gives it) and what it wrote to stdout and stderr.
    Help wrapped at ``$COLUMNS`` or 80, as in a pipe. Only for scripts that leave the process
    as they found it (eval_gabor_scenes sets OpenCV's threads: a subprocess, ``_run``)."""
    import contextlib
    import importlib
    import io
    import os
    from unittest import mock

    out, err = io.StringIO(), io.StringIO()
    columns = {"COLUMNS": os.environ.get("COLUMNS", "80")}
    with (
        mock.patch.object(sys, "path", [str(BENCHES), *sys.path]),
        mock.patch.object(sys, "argv", [script, *args]),
        mock.patch.dict(os.environ, columns),
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
    ):
        try:
            status = importlib.import_module(script.removesuffix(".py")).main() or 0
        except SystemExit as exit_:
            code = exit_.code
            if code is not None and not isinstance(code, int):
                print(code, file=sys.stderr)  # as Python prints a message's SystemExit
            status = code if isinstance(code, int) else (0 if code is None else 1)
    return subprocess.CompletedProcess([script, *args], status, out.getvalue(), err.getvalue())


@cache
def _help(script: str) -> str:
    done = _main(script, "--help")
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.parametrize(("script", "option"), sorted(TIMING.items()))
def test_timing_scripts_refuse_fewer_than_five_runs(script: str, option: str) -> None:
    done = _main(script, option, "4")
    assert done.returncode == 2
    assert f"{option}: " in done.stderr and "at least 5" in done.stderr and "got '4'" in done.stderr


@pytest.mark.parametrize("script", ["mcgm_dump.py", "dump_grey.py"])
def test_help_prints_usage_and_writes_nothing(
    script: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # where a script's relative output paths land
    done = _main(script, "--help")
    assert done.returncode == 0 and done.stdout.startswith(f"usage: {script} ")
    assert list(tmp_path.iterdir()) == []  # mcgm_dump.py wrote a 40 MB "--help.npz"


def test_help_description_is_the_whole_first_paragraph() -> None:
    # argparse re-wraps it; the first line alone stopped mid-sentence ("... against the plane of")
    for script in ("bench_ground.py", "bench_tools.py", "bench_gabor_vs_sgbm.py"):
        doc = (BENCHES / script).read_text().split('"""')[1].split("\n\n")[0]
        assert " ".join(doc.split()) in " ".join(_help(script).split()), script


def _cited_commands() -> list[tuple[str, str, list[str]]]:
    """``(where, script, options)`` of each ``benches/X.py ...`` in backticks of the docs."""
    found = []
    for doc in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for m in re.finditer(r"`(?:[.\w/]*python )?benches/(\w+\.py)([^`]*)`", doc.read_text()):
            options = re.findall(r"(?<![\w-])--[a-z][\w-]*", m.group(2))
            if options:
                found.append((doc.name, m.group(1), options))
    return found


def test_docs_cite_bench_options_that_exist() -> None:
    cited = _cited_commands()
    assert ("README.md", "bench_scaling.py", ["--method", "--runs"]) in cited
    for where, script, options in cited:
        assert (BENCHES / script).is_file(), f"{where}: benches/{script}"
        text = _help(script) if script != "mcgm_dump.py" else (BENCHES / script).read_text()
        for opt in options:
            assert re.search(rf"(?<![\w-]){re.escape(opt)}\b", text), f"{where}: {script} {opt}"


def test_bench_fusion_compares_the_sparse_channels(data_dir: Path) -> None:
    # match() took method="gabor" (its confident pixels as Matches), which made the bench take
    # fuse_pair's dense GaborResult for a sparse channel: AttributeError 'xl' on every scene.
    assert (data_dir / "middlebury2001" / "tsukuba").is_dir()
    # a family/scene name, as bench_exposure / bench_temporal take them (it took folders only)
    done = _main("bench_fusion.py", "middlebury2001/tsukuba")
    assert done.returncode == 0, done.stderr
    out = done.stdout.splitlines()
    assert out[0] == "channels: gabor + hopfield + mcgm"
    row = json.loads(out[-1])
    assert row["scene"].endswith("tsukuba") and row["tol"] == 1.0
    assert set(row) == {"bench", "scene", "tol", "members", "hopfield", "mcgm", "mcgm_defaults"}
    assert row["members"]["count"] > 3500 and row["members"]["coverage"] == 16
    assert row["members"]["precision"] > 99 and row["hopfield"]["count"] > 1000


@pytest.mark.parametrize(
    ("script", "ours"), [("bench_hopfield.py", "network"), ("bench_mcgm.py", "mcgm")]
)
def test_accuracy_times_are_medians_of_the_repeats(data_dir: Path, script: str, ours: str) -> None:
    # the accuracy lines' times were of one run of each side, one after the other
    assert (data_dir / "middlebury2001" / "tsukuba").is_dir()
    done = _main(script, "--scenes", "middlebury2001/tsukuba", "--no-speed", "--repeats", "5")
    assert done.returncode == 0, done.stderr
    row = json.loads(done.stdout.splitlines()[-1])
    assert row["case"] == "accuracy" and row["repeats"] == 5
    assert row[ours]["ms"] > 0 and row["reference"]["ms"] > 0
    assert row[ours]["count"] > 1000 and row[ours]["p1"] > 97


def test_accuracy_times_come_from_as_many_timed_runs(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The test above reads ``repeats: 5`` off the line, which a script can print after one
    run; here the functions bench_hopfield hands to ``_common.interleaved_runs`` are counted:
    a warm-up and 5 timed runs of each side (network, reference)."""
    import runpy

    assert (data_dir / "middlebury2001" / "tsukuba").is_dir()
    monkeypatch.syspath_prepend(str(BENCHES))
    import _common

    real = _common.interleaved_runs
    counts: list[list[int]] = []

    def counting(fns: Any, repeats: int) -> Any:
        ran = [0] * len(fns)

        def counted(i: int) -> Any:
            def run() -> Any:
                ran[i] += 1
                return fns[i]()

            return run

        counts.append(ran)
        return real([counted(i) for i in range(len(fns))], repeats)

    monkeypatch.setattr(_common, "interleaved_runs", counting)
    argv = ["bench_hopfield.py", "--scenes", "middlebury2001/tsukuba", "--no-speed"]
    monkeypatch.setattr(sys, "argv", [*argv, "--repeats", "5"])
    runpy.run_path(str(BENCHES / "bench_hopfield.py"), run_name="__main__")
    row = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert row["repeats"] == 5
    assert counts == [[6, 6]]  # one scene: 1 warm-up + 5 timed runs, network and reference


def test_a_matcher_without_matches_is_a_null_count_not_a_crash(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A scene where the network keeps no match with GT: its precision is NaN, and the bench
    handed it to count_at_precision, which refuses a NaN target (ValueError, the bench ended
    there); the reference's count at that precision is now null."""
    import runpy

    import stereovision.matching.hopfield as hopfield

    monkeypatch.syspath_prepend(str(BENCHES))
    import _common

    gt = np.full((4, 6), 5.0)
    none = Matches(*(np.zeros(0, np.float32) for _ in range(5)), image_shape=(4, 6))
    assert _common.count_at(none, gt, float("nan")) is None
    one = np.ones(2, np.float32)
    xl = np.array([1.0, 2.0], np.float32)
    some = Matches(
        xl, one, xl - np.array([5.0, 8.0], np.float32), one, np.array([0.9, 0.8]), (4, 6)
    )
    assert _common.count_at(some, gt, 100.0) == 1  # the first (5 px) is right, the second not

    real = hopfield.hopfield_match
    monkeypatch.setattr(hopfield, "hopfield_match", lambda *a, **k: real(*a, **k)[:0])
    argv = ["bench_hopfield.py", "--scenes", "middlebury2001/tsukuba", "--no-speed"]
    monkeypatch.setattr(sys, "argv", [*argv, "--repeats", "5"])
    runpy.run_path(str(BENCHES / "bench_hopfield.py"), run_name="__main__")
    row = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert row["network"]["count"] == 0 and row["ref_count_at_net_precision"] is None
    assert row["reference"]["count"] > 0


def test_bench_sgm_density_is_over_the_gt_pixels(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """bench_sgm's density column is evaluation.md's: the share of the GT pixels with a value.
    It was the share of all pixels (tsukuba's GT leaves a border unknown: 79 % of the image;
    KITTI's LiDAR a fifth of it)."""
    import runpy

    from stereovision.evaluate import dense_metrics
    from stereovision.io import load_scene
    from stereovision.matching.sgm import sgm_disparity

    name = "middlebury2001/tsukuba"
    monkeypatch.syspath_prepend(str(BENCHES))
    import _common

    monkeypatch.setattr(_common, "gt_scenes", lambda: [name])
    # the timing section after the density rows is not this test's: each side runs once (its
    # warm-up), not 1 + 5 times on two large scenes
    monkeypatch.setattr(_common, "interleaved_ms", lambda fns, runs: [(f(), 1.0)[1] for f in fns])
    monkeypatch.setattr(sys, "argv", ["bench_sgm.py", "--runs", "5"])
    runpy.run_path(str(BENCHES / "bench_sgm.py"), run_name="__main__")
    row = next(json.loads(ln) for ln in capsys.readouterr().out.splitlines() if '"scene"' in ln)
    sc = load_scene(data_dir / name)
    assert sc.gt is not None
    d = sgm_disparity(sc.left, sc.right, max_disparity=sc.max_disparity)
    want = dense_metrics(d, sc.gt).density
    assert row["scene"] == name and row["density"] == pytest.approx(want)
    assert abs(want - 100 * float(np.isfinite(d).mean())) > 1  # the two differ here


def test_eval_gabor_scenes_times_ours_beside_sgbm(data_dir: Path) -> None:
    # our time was of one run, beside no timed reference
    assert (data_dir / "middlebury2001" / "tsukuba").is_dir()
    done = _run("eval_gabor_scenes.py", "--scenes", "tsukuba", "--runs", "5")
    assert done.returncode == 0, done.stderr
    head, row = done.stdout.splitlines()[:2]
    assert head.split()[-3:] == ["ms", "SGBMms", "ratio"]
    cells = row.split()
    assert cells[0] == "middlebury2001/tsukuba" and cells[1:3] == ["7.3", "17.7"]
    ms, sgbm_ms, ratio = (float(c) for c in cells[6:9])
    # the times are printed to 0.1 ms: the ratio of the printed times is within their rounding
    assert ratio == pytest.approx(ms / sgbm_ms, abs=0.006 + 0.05 * (1 + ratio) / sgbm_ms)


def _sky_scene() -> tuple[Any, np.ndarray]:
    """A two-pixel TartanAir-like scene (f B = 80 m px): GT disparity 80 / 65504 px (the sky,
    GT depth float16's largest value) then 8 px (10 m); and a disparity map measuring 8 px (10 m)
    at both."""
    import types

    from stereovision.calibration import Calibration

    K = np.array([[320.0, 0, 1], [0, 320.0, 0], [0, 0, 1]])
    calib = Calibration(
        K1=K,
        D1=np.zeros(5),
        K2=K.copy(),
        D2=np.zeros(5),
        R=np.eye(3),
        T=np.array([-250.0, 0, 0]),
        image_size=(64, 48),
        unit="mm",
        rectified=True,
    )
    gt = np.array([[80.0 / 65504.0, 8.0]], np.float32)
    scene = types.SimpleNamespace(
        name="tartanair/sky", left=np.zeros((1, 2, 3), np.uint8), gt=gt, calib=calib
    )
    scene.right, scene.max_disparity = scene.left, 16
    return scene, np.full((1, 2), 8.0, np.float32)


def test_eval_gabor_scenes_leaves_the_gt_depth_at_float16s_largest_value_out(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The depth lines scored TartanAir's sky (GT depth 65504 m, float16's clamp) as a distance,
    as eval did before 621b5d1b (its SGBM median 2.73 % where eval says 2.68 %). A stubbed
    two-pixel scene, f B = 80 m px: a sky pixel and one at 10 m, both measured at 10 m: the
    median was 49.99 % over both pixels, it is 0 % over the one with a GT depth (_sky_scene)."""
    import types

    monkeypatch.syspath_prepend(str(BENCHES))
    import eval_gabor_scenes as egs

    scene, d = _sky_scene()
    monkeypatch.setattr(egs, "find_scenes", lambda root: ["tartanair/sky"])
    monkeypatch.setattr(egs, "load_scene", lambda path: scene)
    monkeypatch.setattr(egs, "gabor_disparity", lambda *a, **k: types.SimpleNamespace(disparity=d))
    monkeypatch.setattr(egs.baselines, "opencv_sgbm", lambda *a, **k: d)
    monkeypatch.setattr(egs.baselines, "opencv_bm", lambda *a, **k: d)
    monkeypatch.setattr(sys, "argv", ["eval_gabor_scenes.py", "--runs", "5"])
    egs.main()
    last = capsys.readouterr().out.splitlines()[-1]
    assert last.split() == [
        "depth", "tartanair/sky", "ours", "med", "0.00%", ">5%", "0.0%",
        "SGBM", "med", "0.00%", ">5%", "0.0%", "coverage", "ours/SGBM", "1.000",
    ]  # fmt: skip


@pytest.mark.parametrize(
    ("script", "param", "message"),
    [
        ("eval_gabor_scenes.py", "freq", "expected key=value (value in JSON), got 'freq'"),
        ("eval_gabor_scenes.py", "freq=[1", "freq: '[1' is not a JSON value"),
        (
            "eval_gabor_scenes.py",
            "speckle_size=big",
            "speckle_size: 'big' is not a JSON value (a string is quoted: speckle_size='\"big\"')",
        ),
        ("bench_gabor_vs_sgbm.py", "frq=0.2", "unknown Gabor parameter(s) ['frq'] (did you mean"),
    ],
)
def test_gabor_benches_refuse_a_bad_param_in_one_line(
    script: str,
    param: str,
    message: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """--param without '=', with a value that is not JSON, or with a key gabor_disparity does not
    take was a traceback (of the unpacking, json.loads, or gabor_disparity on the first scene);
    now argparse's one-line error, exit status 2, before any scene is loaded."""
    import importlib

    monkeypatch.syspath_prepend(str(BENCHES))
    bench = importlib.import_module(script.removesuffix(".py"))
    monkeypatch.setattr(sys, "argv", [script, "--param", param, "--runs", "5"])
    with pytest.raises(SystemExit) as exc:
        bench.main()
    assert exc.value.code == 2
    err = capsys.readouterr().err.splitlines()
    assert err[-1].startswith(f"{script}: error: argument --param: {message}"), err


@pytest.mark.parametrize(
    ("script", "scenes", "message"),
    [
        (
            "bench_hopfield.py",
            "middlebury2001/tsukuba,middlebury2001/tsukba",
            "'middlebury2001/tsukba'",
        ),
        ("bench_mcgm.py", "nope", "'nope'"),
        ("bench_exposure.py", "opencv_uncalibrated/books", "'opencv_uncalibrated/books'"),
        ("bench_temporal.py", "tsukuba", "'tsukuba'"),
        ("bench_uncalibrated.py", "chessboard", "'chessboard'"),
    ],
)
def test_benches_refuse_a_scene_without_gt_in_one_line(
    script: str,
    scenes: str,
    message: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """--scenes naming no scene (a typo, a bare scene name) or one without a gt_disp.pfm was
    load_scene's FileNotFoundError traceback once the bench had started; now argparse's one-line
    error (exit status 2) naming it and the scenes there are. A folder or family/scene with GT
    is taken as before."""
    import importlib

    monkeypatch.syspath_prepend(str(BENCHES))
    bench = importlib.import_module(script.removesuffix(".py"))
    import _common

    monkeypatch.setattr(sys, "argv", [script, "--scenes", scenes])
    with pytest.raises(SystemExit) as exc:
        bench.main()
    assert exc.value.code == 2
    err = capsys.readouterr().err.splitlines()[-1]
    head = f"{script}: error: argument --scenes: {message} is no scene with a gt_disp.pfm: "
    assert err.startswith(head + "expected a scene folder or a family/scene of "), err
    assert err.endswith(", tartanair/oldtown_easy_p000_001116"), err
    # a folder, or a name with a trailing slash, is taken as before
    assert _common.gt_scene("middlebury2001/tsukuba/") == "middlebury2001/tsukuba/"
    folder = _common.DATA / "middlebury2001" / "tsukuba"
    assert _common.gt_scene(str(folder)) == str(folder)


@pytest.mark.parametrize(
    ("script", "args", "where"),
    [
        ("plot_fused.py", ["--scene", "middlebury2005/bookz"], "argument --scene"),
        ("plot_live.py", ["--scene", "middlebury2005/bookz"], "argument --scene"),
        ("plot_members.py", ["--scene", "middlebury2005/bookz"], "argument --scene"),
        ("plot_modes.py", ["--scene", "middlebury2005/bookz"], "argument --scene"),
        ("bench_fusion.py", ["middlebury2005/bookz"], "argument scenes"),
    ],
)
def test_plots_refuse_a_scene_without_gt_in_one_line(
    script: str,
    args: list[str],
    where: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """As the benches' --scenes (test_benches_refuse_a_scene_without_gt_in_one_line): the
    plots' --scene and bench_fusion's scenes were load_scene's FileNotFoundError traceback."""
    import importlib

    monkeypatch.syspath_prepend(str(BENCHES))
    bench = importlib.import_module(script.removesuffix(".py"))
    monkeypatch.setattr(sys, "argv", [script, *args])
    with pytest.raises(SystemExit) as exc:
        bench.main()
    assert exc.value.code == 2
    err = capsys.readouterr().err.splitlines()[-1]
    assert err.startswith(
        f"{script}: error: {where}: 'middlebury2005/bookz' is no scene with a gt_disp.pfm: "
    ), err


def test_bench_stages_refuses_a_missing_scene_in_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """bench_stages' scenes (times only: no GT needed) naming no folder was load_scene's
    FileNotFoundError traceback; now argparse's one-line error, exit status 2."""
    monkeypatch.syspath_prepend(str(BENCHES))
    import bench_stages

    monkeypatch.setattr(sys, "argv", ["bench_stages.py", "middlebury2006/clot3"])
    with pytest.raises(SystemExit) as exc:
        bench_stages.main()
    assert exc.value.code == 2
    err = capsys.readouterr().err.splitlines()[-1]
    assert err.startswith(
        "bench_stages.py: error: argument scenes: 'middlebury2006/clot3' is no folder: expected "
        "a scene folder or a family/scene of "
    ), err
    assert err.endswith(", e.g. eth3d/playground, eth3d/terrace, kitti2015/000005_10"), err


def test_eval_gabor_scenes_refuses_scenes_matching_nothing(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """--scenes matching no GT scene printed NaN means (NumPy's "Mean of empty slice"
    warnings) and exited 0; now argparse's one-line error, exit status 2."""
    monkeypatch.syspath_prepend(str(BENCHES))
    import eval_gabor_scenes as egs

    monkeypatch.setattr(sys, "argv", ["eval_gabor_scenes.py", "--scenes", "tsukba,vnus"])
    with pytest.raises(SystemExit) as exc:
        egs.main()
    assert exc.value.code == 2
    err = capsys.readouterr().err.splitlines()[-1]
    assert (
        err
        == "eval_gabor_scenes.py: error: argument --scenes: no scene with GT matches 'tsukba,vnus'"
    )


def test_docs_pictures_script_redraws_the_demo_pictures(tmp_path: Path) -> None:
    """docs/images' demo pictures had no script that redrew them (they were copied by hand from
    ``make demo``'s output). ``plot_docs_pictures.py --only demo`` writes them, the overview
    (the README's picture of the outputs) too, at the demo's size and as optimised PNGs under
    300 KB."""
    import cv2

    done = _run("plot_docs_pictures.py", "--only", "demo", "--out-dir", str(tmp_path))
    assert done.returncode == 0, done.stderr
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["demo_disparity.png", "demo_overview.png", "demo_render.png"]
    shapes = {"demo_overview.png": (848, 1106, 3)}
    for name in names:
        img = cv2.imread(str(tmp_path / name))
        assert img is not None and img.shape == shapes.get(name, (375, 450, 3)), name
        assert (tmp_path / name).stat().st_size < 300_000, name


def test_docs_pictures_refine_leaves_the_gt_depth_at_float16s_largest_value_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The refine picture's titles and error panels scored a GT depth of 65504 m (TartanAir's
    sky, float16's clamp) as a distance, where eval leaves it out (621b5d1b): on _sky_scene a
    49.99 % median over 2 px; 0.00 % over the 1 px with a GT depth now. Scene, matchers and
    the PNG stubbed (the picture not looked at)."""
    import types

    import matplotlib.figure
    import matplotlib.pyplot as plt

    import stereovision.baselines
    import stereovision.depth
    import stereovision.io

    monkeypatch.syspath_prepend(str(BENCHES))
    import plot_docs_pictures as pdp

    scene, d = _sky_scene()
    depth = types.SimpleNamespace(depth=np.full((1, 2), 10.0, np.float32))
    monkeypatch.setattr(pdp, "REFINE_SCENES", ("tartanair/sky",))
    monkeypatch.setattr(stereovision.io, "load_scene", lambda path: scene)
    monkeypatch.setattr(stereovision.depth, "depth_map", lambda *a, **k: depth)
    monkeypatch.setattr(stereovision.baselines, "opencv_sgbm", lambda *a, **k: d)
    monkeypatch.setattr(pdp, "save_png", lambda image, out: out)
    monkeypatch.setattr(pdp.io, "BytesIO", lambda: None)
    titles: list[str] = []
    close = plt.close

    def keep_titles(fig: Any) -> None:
        titles.extend(ax.get_title(loc="left") for ax in fig.axes)
        close(fig)

    monkeypatch.setattr(plt, "close", keep_titles)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda self, *a, **k: None)
    monkeypatch.setattr("PIL.Image.open", lambda buf: None)
    pdp.draw_refine(tmp_path)
    assert titles[:3] == [
        f"tartanair {label}: median 0.00 %, >5 %: 0.0 %, 1 px"
        for label in ("gabor, refine=False", "gabor (refined, its default)", "OpenCV SGBM-3WAY")
    ], titles


def test_docs_pictures_gui_offers_a_save_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The README's GUI pictures showed the Save field empty, "start the GUI with --data DIR":
    the script started the GUI without ``--data``. It starts it as the README tells users to,
    ``--data scenes`` on a copy of the cones in its working folder: the page offers
    ``scenes/saved``."""
    pytest.importorskip("trame")
    import argparse

    from stereovision.gui import add_arguments, build_app, bundled_data_dir
    from stereovision.gui.app import SAVE_HINT

    monkeypatch.syspath_prepend(str(BENCHES))
    import plot_docs_pictures

    cmd = plot_docs_pictures.gui_command(tmp_path, 8123)
    assert cmd[1:3] == ["-m", "stereovision.gui"]
    assert cmd[cmd.index("--data") + 1] == "scenes"
    cones = bundled_data_dir() / "cones"
    for name in ("left.png", "right.png", "calib.txt"):
        assert (tmp_path / "scenes" / "cones" / name).read_bytes() == (cones / name).read_bytes()
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    monkeypatch.chdir(tmp_path)  # the server's working folder
    app = build_app(parser.parse_args(cmd[3:]))
    assert app.state.save_dir == "scenes/saved"  # as the README tells it, not /tmp/sv-...
    assert app.state.save_dir_title.startswith(str(tmp_path.resolve() / "scenes" / "saved"))
    assert app.state.save_hint == SAVE_HINT


def test_picture_benches_write_into_a_new_folder_and_refuse_an_unknown_extension(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """cv2.imwrite returns False into a missing folder: plot_rectification_check (and
    bench_fisheye, bench_ground, bench_uncalibrated) printed "wrote PATH" of no file; an
    extension OpenCV has no writer for was cv2.error's traceback after the run. Now the folder
    is made (as plot_charuco did) and the extension refused by argparse in one line. The pair
    and the check are stubbed (the picture not looked at)."""
    import types

    import cv2

    monkeypatch.syspath_prepend(str(BENCHES))
    import plot_rectification_check as prc

    monkeypatch.setattr(prc, "imread", lambda path: np.zeros((8, 8, 3), np.uint8))
    check = types.SimpleNamespace(summary=lambda: "rows ok")
    monkeypatch.setattr(prc, "check_rectification", lambda left, right: check)
    monkeypatch.setattr(prc, "draw_rectification_check", lambda *a: np.zeros((4, 6, 3), np.uint8))
    out = tmp_path / "new" / "check.jpg"
    monkeypatch.setattr(sys, "argv", ["plot_rectification_check.py", "--out", str(out)])
    prc.main()
    assert capsys.readouterr().out.splitlines()[-1] == f"wrote {out}"
    img = cv2.imread(str(out))
    assert img is not None and img.shape == (20, 6, 3)
    bad = str(tmp_path / "check.jgp")
    monkeypatch.setattr(sys, "argv", ["plot_rectification_check.py", "--out", bad])
    with pytest.raises(SystemExit) as exc:
        prc.main()
    assert exc.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1] == (
        f"plot_rectification_check.py: error: argument --out: {bad}: OpenCV writes no image of "
        "that extension; give a .jpg or .png"
    )


def test_bench_tools_json_goes_into_a_new_folder_and_refuses_a_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """bench_tools --json in a missing folder was write_text's FileNotFoundError after the
    whole run (the figures not kept), and a folder its IsADirectoryError; now the folder is
    made, and a folder refused by argparse in one line before anything runs."""
    monkeypatch.syspath_prepend(str(BENCHES))
    import bench_tools

    monkeypatch.setattr(sys, "argv", ["bench_tools.py"])  # argparse's program name
    out = tmp_path / "new" / "figures.json"
    assert bench_tools.main(["--no-accuracy", "--no-speed", "--json", str(out)]) == 0
    assert json.loads(out.read_text()) == {}
    with pytest.raises(SystemExit) as exc:
        bench_tools.main(["--no-accuracy", "--no-speed", "--json", str(tmp_path)])
    assert exc.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1] == (
        f"bench_tools.py: error: argument --json: {tmp_path}: is a folder; give a file such as "
        "figures.json"
    )


def test_the_benches_runs_option_is_stereovision_benchs(monkeypatch: pytest.MonkeyPatch) -> None:
    """benches/_common.timed_runs copied bench's --runs rule without its upper bound: a bench's
    ``--runs 1000000000`` was taken (and ran on for days). It is that rule itself now."""
    import argparse

    from stereovision.bench import _run_count
    from stereovision.cli import MAX_RUNS

    monkeypatch.syspath_prepend(str(BENCHES))
    import _common

    assert _common.timed_runs is _run_count
    assert _common.timed_runs("5") == 5
    with pytest.raises(argparse.ArgumentTypeError, match=f"^expected at most {MAX_RUNS} runs"):
        _common.timed_runs("1000000000")
    with pytest.raises(argparse.ArgumentTypeError, match=r"^expected at least 5 runs"):
        _common.timed_runs("4")


def test_plot_bad2_panels_counts_a_gt_of_zero_as_known(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The README panels' bad-2.0 left out GT pixels of 0 px (known: evaluation.md's unknown
    is inf or NaN, and dense_metrics counts them), so a hole there was no error in the
    panel's title: 0.00 % where dense_metrics says 50.00 %."""
    import matplotlib.figure
    import matplotlib.pyplot as plt

    from stereovision.evaluate import dense_metrics

    monkeypatch.syspath_prepend(str(BENCHES))
    import _common

    titles: list[str] = []
    close = plt.close

    def keep_titles(fig: Any) -> None:
        titles.extend(ax.get_title() for ax in fig.axes)
        close(fig)

    monkeypatch.setattr(plt, "close", keep_titles)
    # the picture itself is not looked at: its layout and PNG were most of the test's time
    monkeypatch.setattr(matplotlib.figure.Figure, "tight_layout", lambda self: None)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda self, *a, **k: None)
    gt = np.array([[0.0, 0.0, 3.0, 4.0]], np.float32)
    d = np.array([[np.nan, 0.5, 3.0, 4.0]], np.float32)
    maps = {name: d for name in ("a", "b", "c", "d")}
    _common.plot_bad2_panels("t", np.zeros((1, 4), np.uint8), gt, maps, tmp_path / "p.png", (4, 3))
    assert dense_metrics(d, gt).bad[2.0] == 25.0
    assert titles[2] == "a: bad-2.0 25.00 %", titles


def test_plot_live_counts_a_gt_of_zero_as_known(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """plot_live's titles left out GT pixels of 0 px, as plot_bad2_panels did (18c16d41): a hole
    on a known 0 px GT was not in the share measured (100.0 % where 75.0 % is), a 0.5 px
    answer there no error. The scene and its two maps are stubbed (the picture not looked at)."""
    import types

    import matplotlib.figure
    import matplotlib.pyplot as plt

    monkeypatch.syspath_prepend(str(BENCHES))
    import plot_live

    gt = np.array([[0.0, 0.0, 3.0, 4.0]], np.float32)
    d = np.array([[np.nan, 3.0, 3.0, 4.0]], np.float32)
    scene = types.SimpleNamespace(left=np.zeros((1, 4), np.uint8), right=None, gt=gt)
    scene.max_disparity = 4
    monkeypatch.setattr(plot_live, "load_scene", lambda path: scene)
    monkeypatch.setattr(plot_live, "depth_map", lambda *a, **k: types.SimpleNamespace(disparity=d))
    titles: list[str] = []
    close = plt.close

    def keep_titles(fig: Any) -> None:
        titles.extend(ax.get_title() for ax in fig.axes)
        close(fig)

    monkeypatch.setattr(plt, "close", keep_titles)
    monkeypatch.setattr(matplotlib.figure.Figure, "tight_layout", lambda self: None)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda self, *a, **k: None)
    monkeypatch.setattr(sys, "argv", ["plot_live.py", "--out", str(tmp_path / "p.png")])
    plot_live.main()
    assert titles[2].endswith("\n75.0 % measured, 33.33 % of them off by > 2 px"), titles
