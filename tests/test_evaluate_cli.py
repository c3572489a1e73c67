"""``stereovision eval``: timing runs, strict JSON, one-line refusals (evaluation.md)."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import synthetic_scene as syn

from stereovision.cli import main

TIME_KEYS = ("ours_ms", "bm_ms", "sgbm_ms", "runs")


@pytest.fixture(scope="module")
def terrace(crop_terrace: Callable[[slice, slice], Path]) -> Path:
    """A 300 x 200 crop of ETH3D terrace (conftest's crop_terrace): a real metric scene with
    its holes at a fifth of the pixels (the tests are not about the size)."""
    return crop_terrace(slice(200, 400), slice(300, 600))


def _rows(out: str) -> list[dict[str, Any]]:
    return [json.loads(line) for line in out.splitlines() if line.strip()]


def test_eval_runs_reports_the_count_and_keeps_accuracy(
    terrace: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--runs N` times every method N times (the median is reported, `runs` says N); every
    accuracy figure (dense, depth, Table-1, validated matches) is the same as with one run."""
    assert main(["eval", str(terrace), "--json"]) == 0
    (one,) = _rows(capsys.readouterr().out)
    assert main(["eval", str(terrace), "--json", "--runs", "3"]) == 0
    (three,) = _rows(capsys.readouterr().out)
    assert (one["runs"], three["runs"]) == (1, 3)
    for row in (one, three):
        assert all(row[k] > 0 for k in ("ours_ms", "bm_ms", "sgbm_ms"))
    strip = [{k: v for k, v in r.items() if k not in TIME_KEYS} for r in (one, three)]
    assert strip[0] == strip[1]
    # the figures are there, not two empty rows
    assert strip[0]["ours"]["n_gt"] == 29866  # the crop's GT pixels
    assert {"depth", "sgbm_depth", "table1", "members_depth"} <= set(strip[0])


def test_eval_runs_interleaves_ours_and_opencv(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The runs go A, B, C, A, B, C (evaluation.md "Speed"), not A, A, A, B, B, B, after one
    warm-up round whose times are not counted ("median of >= 5 runs after a warm-up": the
    first calls' start-up was one of the N times); one run is one round, as before."""
    from stereovision import baselines, depth
    from stereovision.cli import _eval_scene
    from stereovision.io import load_scene

    calls: list[str] = []

    def spy(name: str, fn: Any) -> Any:
        def wrapped(*a: Any, **k: Any) -> Any:
            calls.append(name)
            return fn(*a, **k)

        return wrapped

    monkeypatch.setattr(depth, "depth_map", spy("ours", depth.depth_map))
    monkeypatch.setattr(baselines, "opencv_bm", spy("bm", baselines.opencv_bm))
    monkeypatch.setattr(baselines, "opencv_sgbm", spy("sgbm", baselines.opencv_sgbm))
    scene = load_scene(data_dir / "middlebury2001" / "tsukuba")
    row = _eval_scene(scene, "fast", True, runs=3)
    assert calls == ["ours", "bm", "sgbm"] * 4
    assert row["runs"] == 3
    calls.clear()
    _eval_scene(scene, "fast", True, runs=1)
    assert calls == ["ours", "bm", "sgbm"]
    with pytest.raises(ValueError, match=r"^runs must be >= 1, got 0$"):
        _eval_scene(scene, "fast", True, runs=0)


@pytest.mark.parametrize("value", ["0", "-2", "two"])
def test_eval_refuses_a_bad_runs_in_one_line(
    data_dir: Path, value: str, capfd: pytest.CaptureFixture[str]
) -> None:
    tsukuba = str(data_dir / "middlebury2001" / "tsukuba")
    proc = _eval(capfd, tsukuba, f"--runs={value}")
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        "stereovision eval: error: argument --runs: expected a whole number above 0, "
        f"got {value!r} (see stereovision eval --help)"
    ]


@pytest.mark.parametrize("value", ["1001", "100000000000000000000"])
def test_eval_refuses_runs_beyond_its_limit_in_one_line(
    data_dir: Path, value: str, capfd: pytest.CaptureFixture[str]
) -> None:
    """Any count was taken: --runs 100000000000000000000 timed the scene until killed. Refused
    before any work: the missing folder is not reached."""
    proc = _eval(capfd, str(data_dir / "no_such_scene"), f"--runs={value}")
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"stereovision eval: error: argument --runs: expected at most 1000 runs, got {value!r} "
        "(see stereovision eval --help)"
    ]


def test_eval_help_says_runs_1_has_no_warm_up(capsys: pytest.CaptureFixture[str]) -> None:
    """``--runs``'s help said "time every method N times ... after a warm-up round": eval times
    only the --method chosen beside OpenCV's two, and ``--runs 1`` has no warm-up (README)."""
    with pytest.raises(SystemExit):
        main(["eval", "--help"])
    said = " ".join(capsys.readouterr().out.split())
    assert (
        "--runs N time ours (--method), StereoBM and SGBM-3WAY N times, interleaved, after a "
        "warm-up round when N > 1 (--runs 1: one run, no warm-up), and print the medians"
    ) in said


def test_run_count_takes_one_to_the_limit() -> None:
    from stereovision.cli import MAX_RUNS, run_count

    assert (run_count("1"), run_count("5"), run_count("1000")) == (1, 5, 1000) == (1, 5, MAX_RUNS)


def _eval(capfd: pytest.CaptureFixture[str], *argv: str) -> subprocess.CompletedProcess[str]:
    """``stereovision eval *argv`` run in this process (a process start each cost a second):
    its status (an argparse refusal's SystemExit code too) and all it wrote on file descriptors
    1 and 2 (capfd: native writes too)."""
    capfd.readouterr()
    try:
        status = main(["eval", *argv])
    except SystemExit as exit_:
        assert isinstance(exit_.code, int), exit_.code  # a status, not a message
        status = exit_.code
    out, err = capfd.readouterr()
    return subprocess.CompletedProcess(["eval", *argv], status, out, err)


def test_eval_of_a_scene_without_gt_prints_no_table_header(
    data_dir: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """The table's two header lines went to stdout before the one-line error of a lone scene
    without ground truth: a table of nothing above the error."""
    photo = data_dir / "stereopi_rig" / "scene_photo"
    proc = _eval(capfd, str(photo), "--method", "fast", "--no-opencv")
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"stereovision: error: {photo}: no ground truth (gt_disp.pfm) to evaluate against"
    ]


def test_eval_of_a_folder_without_a_scene_names_what_is_missing(
    data_dir: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """'no scene (left.png + right.png) under X' for a folder holding left.png alone, or a
    JPEG pair: it did not say which file was missing or that the pair was not PNG."""
    tsukuba = data_dir / "middlebury2001" / "tsukuba"
    half = tmp_path / "half"
    half.mkdir()
    (half / "left.png").write_bytes((tsukuba / "left.png").read_bytes())
    proc = _eval(capfd, str(half))
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"stereovision: error: {half}: has left.png but no right.png (a scene folder holds both)"
    ]
    books = data_dir / "opencv_uncalibrated" / "books"
    proc = _eval(capfd, str(books))
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"stereovision: error: no scene (left.png + right.png) under {books} "
        "(left.jpg, right.jpg found: a scene's images are PNG)"
    ]
    empty = tmp_path / "empty"
    empty.mkdir()
    assert _eval(capfd, str(empty)).stderr.splitlines() == [
        f"stereovision: error: no scene (left.png + right.png) under {empty}"
    ]


def test_eval_of_a_pair_named_in_another_case_says_the_names_are_lower_case(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """Left.png + Right.png (or left.PNG) were said to be 'found: a scene's images are PNG',
    which they are: the names are the trouble (Linux tells them from left.png)."""
    said = {}
    for folder, names in {
        "capital": ("Left.png", "Right.png"),
        "suffix": ("left.PNG", "right.PNG"),
        "both": ("Left.png", "right.jpg"),
        "half": ("left.png", "Right.png"),
    }.items():
        (tmp_path / folder).mkdir()
        for name in names:
            (tmp_path / folder / name).write_bytes(b"")  # only the names are looked at
        proc = _eval(capfd, str(tmp_path / folder))
        assert proc.returncode == 2 and proc.stdout == ""
        said[folder] = proc.stderr.removeprefix("stereovision: error: ").rstrip("\n")
    lower = "a scene's images are named left.png and right.png, in lower case"
    assert said == {
        "capital": f"no scene (left.png + right.png) under {tmp_path / 'capital'} "
        f"(Left.png, Right.png found: {lower})",
        "suffix": f"no scene (left.png + right.png) under {tmp_path / 'suffix'} "
        f"(left.PNG, right.PNG found: {lower})",
        "both": f"no scene (left.png + right.png) under {tmp_path / 'both'} (Left.png, "
        "right.jpg found: a scene's images are PNG, named left.png and right.png, in lower case)",
        "half": f"{tmp_path / 'half'}: has left.png but no right.png (a scene folder holds both)"
        f"; Right.png found: {lower}",
    }


def test_eval_names_two_scenes_of_one_name_by_their_parents(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """day1/cam/tiny and day2/cam/tiny were both 'cam/tiny' (load_scene's family/scene) in the
    table, the depth lines and the JSON lines: two rows no one could tell apart. Each is named
    by as many parents as tell it from the other; a scene of its own name is named as before."""
    for folder in ("day1/cam", "day2/cam", "day3/lab"):
        (tmp_path / folder).mkdir(parents=True)
        syn.narrow_scene(tmp_path / folder, 4, 24)
    proc = _eval(capfd, str(tmp_path), "--json", "--no-opencv", "--method", "fast")
    assert proc.returncode == 0, proc.stderr
    scenes = [row["scene"] for row in _rows(proc.stdout)]
    assert scenes == ["day1/cam/tiny", "day2/cam/tiny", "lab/tiny"]


@pytest.mark.parametrize("json_flag", [["--json"], []])
def test_eval_writes_each_scene_s_line_out_before_the_next_scene(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, json_flag: list[str]
) -> None:
    """In a pipe or a file (block-buffered) eval's lines waited in the buffer until the run's
    end: a kill during a later scene (the OOM killer, a CI timeout) lost the scenes done, 0
    bytes written, and a reader saw nothing meanwhile. Each scene's line is out before the
    next scene is matched (as bench's and stream's JSON lines)."""
    import io

    from stereovision import cli

    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        syn.narrow_scene(tmp_path / folder, 4, 24)
    raw = io.BytesIO()
    monkeypatch.setattr(sys, "stdout", io.TextIOWrapper(raw, encoding="utf-8"))
    written: list[str] = []
    dense = {"bad_2.0": 1.0, "bad_1.0": 2.0, "density": 100.0}

    def fake(scene: Any, method: str, with_opencv: bool, runs: int = 1) -> dict[str, Any]:
        written.append(raw.getvalue().decode())  # what a reader has when it is matched
        return {"scene": scene.name, "max_disparity": 16, "ours": dense, "ours+fill": dense}

    monkeypatch.setattr(cli, "_eval_scene", fake)
    assert main(["eval", str(tmp_path), "--no-opencv", *json_flag]) == 0
    assert written[0] == ""
    assert written[1].count("a/tiny") == 1 and "b/tiny" not in written[1]


def test_eval_table_keeps_its_columns_under_a_long_scene_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    """The scene column was 38 characters whatever the names: a longer one
    (outdoor_session_2026_12_01_rectified/tiny, 41) pushed its row's figures out from under
    their labels. The column is as wide as the longest name."""
    from stereovision import cli

    folder = tmp_path / "outdoor_session_2026_12_01_rectified"
    folder.mkdir()
    syn.narrow_scene(folder, 4, 24)
    dense = {"bad_2.0": 1.0, "bad_1.0": 2.0, "density": 100.0}

    def fake(scene: Any, method: str, with_opencv: bool, runs: int = 1) -> dict[str, Any]:
        return {"scene": scene.name, "max_disparity": 16, "ours": dense, "ours+fill": dense}

    monkeypatch.setattr(cli, "_eval_scene", fake)
    proc = _eval(capfd, str(folder / "tiny"), "--no-opencv")
    assert proc.returncode == 0, proc.stderr
    header, sub, row = proc.stdout.splitlines()[:3]
    assert row.startswith("outdoor_session_2026_12_01_rectified/tiny ")
    bars = [[i for i, c in enumerate(line) if c == "|"] for line in (header, sub, row)]
    assert bars[0] == bars[1] == bars[2], proc.stdout


def test_eval_no_opencv_table_has_no_opencv_columns(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    """`eval --no-opencv` printed the StereoBM, SGBM-3WAY and SGBM+fill column names over three
    blank columns on every row, as if OpenCV had failed on every scene; the table has ours and
    ours+fill alone (with OpenCV, the five columns as before)."""
    from stereovision import cli

    syn.narrow_scene(tmp_path, 4, 24)
    dense = {"bad_2.0": 1.0, "bad_1.0": 2.0, "density": 100.0}

    def fake(scene: Any, method: str, with_opencv: bool, runs: int = 1) -> dict[str, Any]:
        row = {"scene": scene.name, "max_disparity": 16, "ours": dense, "ours+fill": dense}
        if with_opencv:
            row.update({"bm": dense, "sgbm": dense, "sgbm+fill": dense})
        return row

    monkeypatch.setattr(cli, "_eval_scene", fake)
    proc = _eval(capfd, str(tmp_path / "tiny"), "--no-opencv")
    assert proc.returncode == 0, proc.stderr
    header, sub, row = proc.stdout.splitlines()[:3]
    assert header.split() == ["scene", "D", "|", "ours", "|", "ours+fill"]
    assert sub.split() == ["|", "bad-2", "bad-1", "dens", "|", "bad-2", "bad-1", "dens"]
    assert row.split()[1:] == ["16", "|", "1.0", "2.0", "100.0", "|", "1.0", "2.0", "100.0"]
    assert proc.stdout.splitlines()[3] == "mean bad-2.0: ours 1.0 %, ours+fill 1.0 %"
    proc = _eval(capfd, str(tmp_path / "tiny"))
    header, sub, row = proc.stdout.splitlines()[:3]
    assert [w for w in header.split() if w != "|"][2:] == [
        "ours", "ours+fill", "StereoBM", "SGBM-3WAY", "SGBM+fill"
    ]  # fmt: skip
    assert row.split().count("100.0") == 5


def test_eval_of_a_scene_where_ours_has_no_gt_depth(
    terrace: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A metric scene whose GT is known only where our depth map has holes: the Table-1 draw
    raised 'no pixel has both an estimated and a ground-truth distance' (without the scene's
    name) and the whole scene was refused, its valid dense figures with it."""
    import shutil

    from stereovision.depth import depth_map
    from stereovision.io import load_scene, read_pfm, write_pfm

    scene_dir = tmp_path / "terrace"
    shutil.copytree(terrace, scene_dir)
    gt_path = scene_dir / "gt_disp.pfm"
    scene_dir.chmod(0o755)
    gt_path.chmod(0o644)
    gt = np.full_like(read_pfm(gt_path), np.inf)
    gt[:, 0] = 10.0  # max_disparity 16 for the scene
    write_pfm(gt_path, gt)
    scene = load_scene(scene_dir)
    res = depth_map(scene.left, scene.right, scene.calib, method="fast", max_disparity=16)
    holes = ~np.isfinite(res.depth)
    assert 0 < holes.sum() < holes.size
    write_pfm(gt_path, np.where(holes, np.float32(10.0), np.float32(np.inf)))
    argv = [str(scene_dir), "--method", "fast", "--no-opencv"]
    proc = _eval(capfd, *argv, "--json")
    assert proc.returncode == 0, proc.stderr
    (row,) = _rows(proc.stdout)
    assert row["ours"]["n_gt"] == int(holes.sum()) and row["depth"]["n"] == 0
    assert row["depth"]["median_rel"] is None and "table1" not in row
    text = _eval(capfd, *argv)
    assert text.returncode == 0, text.stderr
    assert f"{row['scene']}: depth: none of our pixels has a GT depth" in text.stdout.splitlines()


def test_eval_text_says_when_sgbm_or_the_members_have_no_gt_depth(
    terrace: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """SGBM-3WAY without a pixel on GT (a textureless pair: all invalid) and validated matches
    none of which has a GT depth printed 'SGBM-3WAY over 0: nan %, nan %' and 'with GT depth:
    0, RMSE nan % ...; SGBM-3WAY's RMSE nan %'; each says it has none, as ours does (0d1ed26)."""

    from stereovision import baselines
    from stereovision.matching import fusion

    def no_sgbm(left: Any, right: Any, md: int) -> np.ndarray:
        return np.full(left.shape[:2], np.nan, np.float32)

    real_fuse = fusion.fuse_pair

    def no_members(*a: Any, **k: Any) -> Any:
        # a whole FusionResult with no member (eval filters the members by range since 538eadb)
        fused = real_fuse(*a, **k)
        return fusion._members_where(fused, np.zeros(len(fused.matches.xl), bool))

    monkeypatch.setattr(baselines, "opencv_sgbm", no_sgbm)
    monkeypatch.setattr(fusion, "fuse_pair", no_members)
    capsys.readouterr()
    assert main(["eval", str(terrace), "--method", "fast"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "nan" not in "\n".join(lines)
    depth = next(line for line in lines if line.startswith("eth3d/terrace: depth over our "))
    assert depth.endswith("; SGBM-3WAY: none of its pixels has a GT depth")
    members = "eth3d/terrace: validated matches (>= 2 of Gabor, MCGM, Hopfield agree)"
    assert f"{members}: none has a GT depth" in lines


def test_eval_runs_prints_the_times_it_measured(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`eval --runs N` without --json timed every method N times and printed none of it (the
    medians were in the --json line only); now a line per scene says them, and a run without
    --runs prints the table as before, with no time line."""
    tsukuba = str(data_dir / "middlebury2001" / "tsukuba")
    assert main(["eval", tsukuba, "--method", "fast", "--runs", "2"]) == 0
    out = capsys.readouterr().out
    timed = [line for line in out.splitlines() if ": time, " in line]
    assert len(timed) == 1
    assert re.fullmatch(
        r"middlebury2001/tsukuba: time, median of 2 runs after a warm-up: ours [0-9.]+ ms, "
        r"StereoBM [0-9.]+ ms, SGBM-3WAY [0-9.]+ ms \(ours [0-9.]+ x SGBM-3WAY\)",
        timed[0],
    ), timed[0]
    assert main(["eval", tsukuba, "--method", "fast", "--no-opencv", "--runs", "1"]) == 0
    (line,) = [x for x in capsys.readouterr().out.splitlines() if ": time, " in x]
    assert re.fullmatch(r"middlebury2001/tsukuba: time, one run, no warm-up: ours [0-9.]+ ms", line)
    assert main(["eval", tsukuba, "--method", "fast"]) == 0
    assert ": time, " not in capsys.readouterr().out


@pytest.mark.parametrize(("height", "width"), [(1, 1), (3, 8), (1, 16), (64, 2)])
def test_eval_of_a_scene_narrower_than_its_range_names_the_width_needed(
    tmp_path: Path, height: int, width: int, capfd: pytest.CaptureFixture[str]
) -> None:
    """A scene at most 16 px wide: its range (evaluation.md's, 16 at least) was named as if
    given ("disparity range 16 is not smaller than the image width 8"); the error names the
    images' width and the width a scene needs, one line, nothing on stdout."""

    scene = syn.narrow_scene(tmp_path, height, width)
    proc = _eval(capfd, str(scene), "--no-opencv", "--method", "fast")
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"stereovision: error: {scene}: images {width} px wide, not wider than the scene's "
        "disparity range (16 px, evaluation.md's rule: 16 at least): a scene needs images at "
        "least 17 px wide"
    ]


def test_the_members_line_says_those_under_a_pixel_of_disparity_apart() -> None:
    """ETH3D playground: one validated match at 0.74 px of disparity (43.9 m for a GT of
    8.6 m, a pixel's error being the whole distance there) took the members' RMSE from 6.30 %
    to 10.16 % of the mean depth, unsaid. The line counts such members and gives the RMSE
    without them (members_depth_1px); the members' own figures are unchanged, and a scene
    without such members is said as before."""
    from stereovision.cli import _members_line

    def figures(n: int, rmse: float) -> dict[str, float]:
        return {"n": n, "rmse_pct": rmse, "median_rel": 2.8}

    row = {"members_depth": figures(8116, 10.164), "members_depth_1px": figures(8115, 6.2956)}
    head = (
        "playground: validated matches (>= 2 of Gabor, MCGM, Hopfield agree) with GT depth: "
        "8116, RMSE 10.16 % of the mean depth, median |dZ|/Z 2.80 %"
    )
    assert _members_line("playground", row) == (
        f"{head} (1 under 1 px of disparity, where a pixel's error is the whole distance; RMSE "
        "without them: 6.30 %)"
    )
    row["members_depth_1px"] = row["members_depth"]
    row["sgbm_depth"] = figures(9000, 12.0)
    assert _members_line("playground", row) == f"{head}; SGBM-3WAY's RMSE 12.00 %"
    row = {"members_depth": figures(2, 50.0), "members_depth_1px": figures(0, math.nan)}
    assert _members_line("x", row).endswith("RMSE without them: none left)")


@pytest.fixture(scope="module")
def tartanair_sky(data_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 96 x 48 crop of TartanAir oldtown's top edge (rows 0-47, columns 200-295) named
    ``tartanair/sky``: 1097 of its 4608 GT pixels are sky, at a GT depth of 65504 m."""
    import cv2

    from stereovision.io import read_pfm, write_pfm

    src = data_dir / "tartanair" / "oldtown_easy_p000_001116"
    dst = tmp_path_factory.mktemp("sky") / "tartanair" / "sky"
    dst.mkdir(parents=True)
    rows, cols = slice(0, 48), slice(200, 296)
    for name in ("left.png", "right.png"):
        assert cv2.imwrite(str(dst / name), cv2.imread(str(src / name))[rows, cols])
    write_pfm(dst / "gt_disp.pfm", read_pfm(src / "gt_disp.pfm")[rows, cols])
    text = (src / "calib.txt").read_text()  # the principal point does not enter the depth
    (dst / "calib.txt").write_text(
        text.replace("width=640", "width=96").replace("height=480", "height=48")
    )
    return dst


def test_eval_leaves_the_gt_depth_at_float16s_largest_value_out_and_says_so(
    tartanair_sky: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """TartanAir's sky holds a GT depth of 65504 m (float16's largest value, GT disparity
    0.0012 px), where validated matches measure ~8 m: the members' RMSE was 2060.75 % of the
    mean depth on the scene, 398.85 % over 32 members on this crop. Those GT pixels are now
    counted in a line and left out of the depth figures (30 members, 2.79 %; our depth over
    2735 pixels, not 3105); the disparity figures keep them (13.9 / 21.0 as before)."""
    assert main(["eval", str(tartanair_sky), "--no-opencv", "--method", "fast"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[2].split() == "tartanair/sky 16 | 13.9 21.0 100.0 | 13.9 21.0 100.0".split()
    assert out[4] == (
        "tartanair/sky: GT depth: 1097 of 4608 known pixels (23.8 %) are at 65504 m, float16's "
        "largest value (sky: a clamp, not a distance); the depth figures and Table-1 tests "
        "leave them out, the disparity figures keep them"
    )
    assert out[5].startswith("tartanair/sky: depth over our 2735 pixels: median |dZ|/Z 3.70 %")
    members = [line for line in out if "validated matches" in line]
    assert members == [
        "tartanair/sky: validated matches (>= 2 of Gabor, MCGM, Hopfield agree) with GT depth: "
        "30, RMSE 2.79 % of the mean depth, median |dZ|/Z 1.20 %"
    ]


def test_eval_scene_figures_are_the_metrics_of_each_output(terrace: Path) -> None:
    """Each block of an ``eval`` row is evaluation.md's metric of its own output, reproducible
    from the public functions: ``ours+fill`` of the row-filled map, ``members_depth`` of the
    validated matches' depth against the GT depth (not the reverse), Table-1 drawn with seed 0,
    and every dense block with all four bad-t figures (mutants of _eval_scene that evaluated the
    raw map as filled, swapped the depth maps or dropped a threshold survived every test)."""
    from stereovision._jsonout import json_ready
    from stereovision._validate import as_gray_float
    from stereovision.baselines import opencv_sgbm, row_fill
    from stereovision.cli import _eval_scene
    from stereovision.depth import depth_map
    from stereovision.evaluate import dense_metrics, depth_metrics, gt_depth, table1_report
    from stereovision.io import load_scene
    from stereovision.matching.fusion import fuse_pair

    scene = load_scene(terrace)
    calib, md = scene.calib, scene.max_disparity
    row = json_ready(_eval_scene(scene, "gabor", with_opencv=True))  # gabor leaves holes
    keys = ["bad_0.5", "bad_1.0", "bad_2.0", "bad_4.0", "density", "avgerr", "rms"]
    for block in ("ours", "ours+fill", "bm", "sgbm", "sgbm+fill"):
        assert list(row[block])[:7] == keys, block
    res = depth_map(scene.left, scene.right, calib, method="gabor", max_disparity=md)
    filled = dense_metrics(row_fill(res.disparity), scene.gt)
    assert row["ours+fill"] == json_ready(filled.as_dict())
    assert row["ours+fill"]["density"] > row["ours"]["density"]  # the fill filled holes
    zgt = gt_depth(scene.gt, calib)
    assert row["table1"] == json_ready(table1_report(res.depth, zgt, n_points=10, seed=0).as_dict())
    # the headline depth figures: ours and SGBM-3WAY's depth against the GT depth, relative to
    # the GT (depth_metrics(zgt, res.depth) divided by our depth and survived)
    assert row["depth"] == json_ready(depth_metrics(res.depth, zgt).as_dict())
    sgbm_z = calib.depth_from_disparity(opencv_sgbm(scene.left, scene.right, md))
    assert row["sgbm_depth"] == json_ready(depth_metrics(sgbm_z, zgt).as_dict())
    gl, gr = as_gray_float(scene.left, "left"), as_gray_float(scene.right, "right")
    dispx = fuse_pair(gl, gr, max_disparity=md).dispx
    z_members = calib.depth_from_disparity(dispx)
    assert row["members_depth"] == json_ready(depth_metrics(z_members, zgt).as_dict())
    near = np.where(dispx >= 1, z_members, np.nan)
    assert row["members_depth_1px"] == json_ready(depth_metrics(near, zgt).as_dict())


def test_eval_scene_uses_only_a_rectified_calibration(
    terrace: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A scene whose calibration does not rectify the pair as given is matched without it (no
    depth figures), as bench does; its dense figures stand."""
    from types import SimpleNamespace

    from stereovision import depth
    from stereovision.cli import _eval_scene
    from stereovision.io import load_scene

    seen: list[object] = []
    real = depth.depth_map

    def spy(left: Any, right: Any, calib: Any, **k: Any) -> Any:
        seen.append(calib)
        return real(left, right, calib, **k)

    monkeypatch.setattr(depth, "depth_map", spy)
    scene = load_scene(terrace)
    fake = SimpleNamespace(**{**vars(scene), "calib": SimpleNamespace(rectified=False)})
    row = _eval_scene(fake, "fast", with_opencv=False)
    assert seen == [None] and "depth" not in row and row["ours"]["n_gt"] == 29866


def test_eval_of_a_scene_narrower_than_bms_range_plus_its_block(
    data_dir: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A 70 px crop of cones (range 64): StereoBM's 15 px block needs 78 px, so 4f17fb0's
    refusal in opencv_bm refused the whole scene (exit 2); the BM reference now runs on the
    widest range that fits (48) and the scene is evaluated, as opencv_bm(…, 48) gives it."""
    import cv2

    from stereovision import baselines
    from stereovision.evaluate import dense_metrics
    from stereovision.io import load_scene, read_pfm, write_pfm

    src = data_dir / "middlebury2003" / "cones"
    scene_dir = tmp_path / "narrow"
    scene_dir.mkdir()
    for side in ("left", "right"):
        cv2.imwrite(
            str(scene_dir / f"{side}.png"), cv2.imread(str(src / f"{side}.png"))[:, 300:370]
        )
    write_pfm(
        scene_dir / "gt_disp.pfm", np.ascontiguousarray(read_pfm(src / "gt_disp.pfm")[:, 300:370])
    )
    proc = _eval(capfd, str(scene_dir), "--json")
    assert proc.returncode == 0, proc.stderr
    (row,) = _rows(proc.stdout)
    scene = load_scene(scene_dir)
    assert row["max_disparity"] == scene.max_disparity == 64
    assert baselines.bm_reference_range(64, 70) == 48
    bm = dense_metrics(baselines.opencv_bm(scene.left, scene.right, 48), scene.gt).as_dict()
    assert row["bm"]["bad_2.0"] == pytest.approx(bm["bad_2.0"])
    assert row["bm"]["density"] == pytest.approx(bm["density"])


def test_eval_names_a_narrow_scene_among_several_once(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A scene too narrow for its range among several was said as 'failed <folder>:
    <folder>: images 8 px wide, ...' (its message names its folder, and the line named it
    again); the folder is said once, as for any other failing scene."""
    narrow = syn.narrow_scene(tmp_path)
    empty = tmp_path / "zz_no_gt"  # a second scene, skipped without GT: no matching runs
    empty.mkdir()
    for name in ("left.png", "right.png"):
        (empty / name).write_bytes((narrow / name).read_bytes())
    proc = _eval(capfd, str(tmp_path), "--no-opencv", "--method", "fast")
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr.splitlines()[0] == (
        f"failed {narrow}: images 8 px wide, not wider than the scene's disparity range "
        "(16 px, evaluation.md's rule: 16 at least): a scene needs images at least 17 px wide"
    )
    # load_scene's 'scene FOLDER: ...' was said 'failed FOLDER: scene FOLDER: ...'
    from stereovision.io import write_pfm

    write_pfm(narrow / "gt_disp.pfm", np.full((3, 7), 2.0, np.float32))
    proc = _eval(capfd, str(tmp_path), "--no-opencv", "--method", "fast")
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr.splitlines()[0] == f"failed {narrow}: gt_disp.pfm is 7x3, left.png 8x3"


def _low_scene(data_dir: Path, tmp_path: Path, rows: int = 12) -> Path:
    """A crop of tsukuba ``rows`` rows high (range 16), with its GT."""
    import cv2

    from stereovision.io import read_pfm, write_pfm

    src = data_dir / "middlebury2001" / "tsukuba"
    scene = tmp_path / "low"
    scene.mkdir()
    for name in ("left.png", "right.png"):
        assert cv2.imwrite(str(scene / name), cv2.imread(str(src / name))[100 : 100 + rows])
    write_pfm(scene / "gt_disp.pfm", read_pfm(src / "gt_disp.pfm")[100 : 100 + rows].copy())
    return scene


def test_eval_of_a_scene_no_higher_than_stereobms_block_scores_ours_and_sgbm(
    data_dir: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A scene 12 rows high: since 67b28cf StereoBM's refusal ('needs images at least 16 px
    high') failed the whole scene (exit 2, no figures). Ours and SGBM-3WAY are now scored as
    on any scene, the StereoBM column blank (no 'bm' keys in --json) and one line says why."""
    from stereovision import baselines
    from stereovision.evaluate import dense_metrics
    from stereovision.io import load_scene

    scene_dir = _low_scene(data_dir, tmp_path)
    scene = load_scene(scene_dir)
    note = (
        f"{scene_dir}: no StereoBM figures: StereoBM's 15 px block needs images at least 16 px "
        "high, got 12"
    )
    proc = _eval(capfd, str(scene_dir), "--json", "--method", "fast")
    assert proc.returncode == 0 and proc.stderr.splitlines() == [note]
    (row,) = _rows(proc.stdout)
    assert "bm" not in row and "bm_ms" not in row and row["sgbm_ms"] > 0
    sgbm = dense_metrics(baselines.opencv_sgbm(scene.left, scene.right, 16), scene.gt).as_dict()
    assert row["sgbm"]["bad_2.0"] == pytest.approx(sgbm["bad_2.0"])
    assert row["ours"]["n_gt"] == sgbm["n_gt"] > 0 and row["ours"]["density"] > 50
    proc = _eval(capfd, str(scene_dir), "--method", "fast", "--runs", "2")
    assert proc.returncode == 0 and proc.stderr.splitlines() == [note]
    lines = proc.stdout.splitlines()
    cells = lines[2].split("|")
    assert cells[3].strip() == "" and cells[4].split()[0] == f"{row['sgbm']['bad_2.0']:.1f}"
    assert lines[3].startswith("mean bad-2.0: ours ") and "StereoBM" not in lines[3]
    assert "StereoBM" not in lines[4] and "SGBM-3WAY" in lines[4]


def test_eval_mean_line_says_why_stereobm_has_no_mean(
    data_dir: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """With one scene StereoBM cannot run on beside one it ran on, the mean line left StereoBM
    out without a word (the other scene's figures dropped from the run's means); it now says
    so after the other columns' means."""
    low = _low_scene(data_dir, tmp_path)
    full = data_dir / "middlebury2001" / "venus"
    proc = _eval(capfd, str(full), str(low), "--method", "fast")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    venus, crop = (line.split("|") for line in lines[2:4])  # in the order given
    assert venus[0].startswith("middlebury2001/venus") and crop[0].split()[0].endswith("/low")
    assert crop[3].strip() == "" and venus[3].strip() != ""
    mean = lines[4]
    names = [
        part.rsplit(" ", 2)[0] for part in mean.split(";")[0][len("mean bad-2.0: ") :].split(", ")
    ]
    assert names == ["ours", "ours+fill", "SGBM-3WAY", "SGBM+fill"], mean
    assert mean.endswith("; StereoBM: no mean (no figures for 1 of 2 scenes)"), mean


def test_eval_table_shows_each_blocks_bad_2_bad_1_and_density(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The text row gives, under bad-2, bad-1 and dens, the --json line's figures of each block
    (a table that showed bad-2 under bad-1 too survived every test)."""
    import cv2

    from stereovision.io import read_pfm, write_pfm

    tsukuba = data_dir / "middlebury2001" / "tsukuba"
    scene = tmp_path / "crop"
    scene.mkdir()
    for name in ("left.png", "right.png"):
        img = cv2.imread(str(tsukuba / name))
        assert cv2.imwrite(str(scene / name), img[100:196, 100:228])
    write_pfm(scene / "gt_disp.pfm", read_pfm(tsukuba / "gt_disp.pfm")[100:196, 100:228])
    argv = ["eval", "--no-opencv", "--method", "census", str(scene)]
    assert main([*argv, "--json"]) == 0
    (row,) = _rows(capsys.readouterr().out)
    assert main(argv) == 0
    text = capsys.readouterr().out.splitlines()[2]
    cells = [c.split() for c in text.split(" | ")[1:3]]
    for block, cell in zip(("ours", "ours+fill"), cells, strict=True):
        want = [f"{row[block][k]:.1f}" for k in ("bad_2.0", "bad_1.0", "density")]
        assert want[0] != want[1]  # bad-2 and bad-1 differ here: the test tells them apart
        assert cell == want, (block, text)


def test_eval_interrupted_prints_the_summary_of_the_scenes_it_evaluated(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The mean line, the --runs time lines and the depth / Table-1 lines come after the loop:
    a Ctrl-C (or SIGTERM) during the second of several scenes lost the first one's medians
    (bench kept its scenes' timing since 6032009). They are now printed for the scenes
    evaluated, then 'interrupted' (exit 130)."""
    import shutil

    import stereovision.cli as cli

    for name in ("a_first", "b_second"):
        shutil.copytree(data_dir / "middlebury2001" / "tsukuba", tmp_path / name)
    real = cli._eval_scene

    def first_only(scene: Any, *args: Any) -> dict[str, Any]:
        if scene.name.endswith("b_second"):
            raise KeyboardInterrupt
        return real(scene, *args)

    monkeypatch.setattr(cli, "_eval_scene", first_only)
    assert main(["eval", "--method", "fast", "--no-opencv", "--runs", "1", str(tmp_path)]) == 130
    cap = capsys.readouterr()
    lines = cap.out.splitlines()
    assert lines[2].startswith(f"{tmp_path.name}/a_first ")
    assert lines[3] == f"mean bad-2.0: ours {float(lines[2].split()[3]):.1f} %, " + (
        f"ours+fill {float(lines[2].split()[7]):.1f} %"
    )
    assert re.fullmatch(
        rf"{tmp_path.name}/a_first: time, one run, no warm-up: ours [0-9.]+ ms", lines[4]
    ), lines
    assert len(lines) == 5
    assert cap.err.strip().splitlines()[-1] == "stereovision: interrupted"


def test_eval_lines_name_a_scene_folder_with_a_newline_escaped(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A scene folder named with a newline cut eval's per-scene lines in two: 'skipped a',
    then 'b: no ground truth (gt_disp.pfm)' (and the table row, the failed and time lines
    alike). Each names it escaped now, as batch's lines do (a\\nb), on one line."""
    import cv2

    from stereovision.io import read_pfm, write_pfm

    src = data_dir / "middlebury2001" / "tsukuba"
    nogt, good, bad = tmp_path / "a\nb", tmp_path / "o\nk", tmp_path / "x\ny"
    for scene in (nogt, good, bad):
        scene.mkdir()
        for name in ("left.png", "right.png"):
            assert cv2.imwrite(str(scene / name), cv2.imread(str(src / name))[100:140])
    write_pfm(good / "gt_disp.pfm", read_pfm(src / "gt_disp.pfm")[100:140].copy())
    write_pfm(bad / "gt_disp.pfm", read_pfm(src / "gt_disp.pfm")[100:140].copy())
    (bad / "left.png").write_bytes(b"not a png")
    args = ["eval", "--method", "fast", "--no-opencv", "--runs", "1", str(tmp_path)]
    assert main(args) == 1
    cap = capsys.readouterr()
    out, err = cap.out.splitlines(), cap.err.splitlines()
    root = tmp_path.name
    assert out[2].startswith(f"{root}/o\\nk ") and out[3].startswith("mean bad-2.0: ours ")
    assert out[4].startswith(f"{root}/o\\nk: time, one run, no warm-up: ours ")
    assert len(out) == 5, out
    assert err[0] == f"skipped {tmp_path}/a\\nb: no ground truth (gt_disp.pfm)"
    assert err[1].startswith(f"failed {tmp_path}/x\\ny: ") and "left.png" in err[1], err
    assert err[2] == "stereovision: 1 of 3 scenes failed (above)" and len(err) == 3


def test_eval_reads_a_16_bit_scene_at_its_16_bits(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """eval read a scene's 16-bit PNGs at their top 8 bits (load_scene's imread) where `depth`
    and `batch` keep 16: a 12-bit 300x200 crop of terrace scored bad-2.0 9.2 % (4.8 % at its
    16 bits; a 200x150 crop with --method fast: 51.7 %, 3.0 % at 16 bits). It reads them as
    `depth` does now; 8-bit scenes are read as before."""
    import cv2

    from stereovision.io import read_pfm, write_pfm

    src = data_dir / "eth3d" / "terrace"
    crop = np.s_[100:250, 200:400]
    for n in ("left.png", "right.png"):
        grey8 = cv2.imread(str(src / n), cv2.IMREAD_COLOR)[crop]
        cv2.imwrite(str(tmp_path / n), np.rint(grey8 * (4095 / 255)).astype(np.uint16))
    write_pfm(tmp_path / "gt_disp.pfm", np.ascontiguousarray(read_pfm(src / "gt_disp.pfm")[crop]))
    assert main(["eval", str(tmp_path), "--json", "--no-opencv", "--method", "fast"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["ours"]["bad_2.0"] < 10.0


def test_eval_says_a_gt_with_known_pixels_at_0_px(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A GT converted keeping KITTI's (and Middlebury's PNGs') 0 = unknown was scored against its
    0s without a word (a crop of KITTI 000005, half its pixels unknown: bad-2.0 55.1 % for
    7.6 % with them +inf). eval says so on stderr; the figures are as before (0 px is known)."""
    import stereovision.cli as cli
    from stereovision.evaluate import dense_metrics
    from stereovision.io import write_pfm

    def scored(scene: Any, *_a: Any) -> dict[str, Any]:  # the GT as scored, not the matcher
        return {"ours": dense_metrics(np.full(scene.gt.shape, 2.0), scene.gt).as_dict()}

    monkeypatch.setattr(cli, "_eval_scene", scored)
    scene = syn.narrow_scene(tmp_path, 20, 60)
    gt = np.full((20, 60), 2.0, np.float32)
    gt[:, :15] = 0.0
    write_pfm(scene / "gt_disp.pfm", gt)
    args = ["eval", str(scene), "--json", "--no-opencv"]
    assert main(args) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out)["ours"]["n_gt"] == 1200
    assert cap.err.splitlines() == [
        f"stereovision: {scene}: gt_disp.pfm: 300 of its 1200 known pixels (25.0 %) are at 0 px "
        "or below, scored as known disparities; if they mark unknown pixels (as 0 does in "
        "KITTI's and Middlebury's PNGs), write them as +inf"
    ]
    gt[:, :15] = np.inf  # unknown as a gt_disp.pfm marks it: nothing to say
    write_pfm(scene / "gt_disp.pfm", gt)
    assert main(args) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out)["ours"]["n_gt"] == 900 and cap.err == ""


def test_eval_of_a_scene_whose_gt_kept_middleburys_name_says_to_rename_it(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A scene of left.png + right.png whose GT kept Middlebury's (and ETH3D's) name, disp0GT.pfm
    or disp0.pfm, was 'no ground truth (gt_disp.pfm)' without a word on the file beside them;
    the line now says to rename it (alone: the one-line error; among scenes: its skipped
    line). A scene without either is said as before."""
    scene = syn.narrow_scene(tmp_path, 20, 40)
    (scene / "gt_disp.pfm").rename(scene / "disp0GT.pfm")
    proc = _eval(capfd, str(scene), "--no-opencv")
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"stereovision: error: {scene}: no ground truth (gt_disp.pfm) to evaluate against; it "
        "holds Middlebury's disp0GT.pfm: rename it gt_disp.pfm"
    ]
    (scene / "disp0GT.pfm").rename(scene / "disp0.pfm")
    other = tmp_path / "other"
    other.mkdir()
    syn.narrow_scene(other, 20, 40)
    (other / "tiny" / "gt_disp.pfm").unlink()
    proc = _eval(capfd, str(tmp_path), "--no-opencv")
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"skipped {other / 'tiny'}: no ground truth (gt_disp.pfm)",
        f"skipped {scene}: no ground truth (gt_disp.pfm); it holds Middlebury's disp0.pfm: "
        "rename it gt_disp.pfm",
        "stereovision: error: none of the 2 scenes has ground truth to evaluate against",
    ]
