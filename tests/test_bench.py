"""``stereovision bench``: every method beside OpenCV on the same pair, same run (evaluation.md)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import synthetic_scene as syn

import stereovision.bench
from stereovision import baselines
from stereovision.bench import BenchCase, bench_scene, format_table, sparse_name
from stereovision.cli import main
from stereovision.depth import METHODS
from stereovision.evaluate import dense_metrics
from stereovision.io import load_scene
from stereovision.match import METHODS as SPARSE_METHODS

SCENE = "middlebury2001/tsukuba"  # the smallest GT scene: 384x288, max_disparity 16


@pytest.fixture(scope="module")
def tsukuba_cases(data_dir: Path) -> list[BenchCase]:
    """``bench_scene(tsukuba, runs=5)``, timed once for the two tests that read it (neither
    changes it)."""
    return bench_scene(load_scene(data_dir / SCENE), runs=5)


def test_bench_scene_cases_and_figures(data_dir: Path, tsukuba_cases: list[BenchCase]) -> None:
    scene = load_scene(data_dir / SCENE)
    cases = tsukuba_cases
    names = [c.case for c in cases]
    # gabor's Matches are its dense run's confident pixels: timed once, as a dense method
    sparse = [sparse_name(m) for m in SPARSE_METHODS if m != "gabor"]
    assert names == [*METHODS, "pipeline", *sparse, "StereoBM", "SGBM-3WAY"]
    assert "fused-sparse" in sparse and len(set(names)) == len(names)
    by = {c.case: c for c in cases}
    assert by["SGBM-3WAY"].ratio == pytest.approx(1.0)
    for c in cases:
        assert c.ms > 0 and c.ratio == pytest.approx(c.ms / by["SGBM-3WAY"].ms)
        assert (c.width, c.height, c.max_disparity) == (384, 288, 16)
    # The OpenCV figures are evaluation.md's (tsukuba: BM 12.7 %, SGBM-3WAY 5.3 % bad-2.0).
    assert by["StereoBM"].accuracy["bad_2.0"] == pytest.approx(12.7, abs=0.3)
    assert by["SGBM-3WAY"].accuracy["bad_2.0"] == pytest.approx(5.3, abs=0.3)
    # Ours is scored by the same metric code as a direct evaluation.
    sgbm = baselines.opencv_sgbm(scene.left, scene.right, 16)
    assert by["SGBM-3WAY"].accuracy["density"] == pytest.approx(
        dense_metrics(sgbm, scene.gt).density
    )
    for m in sparse:
        acc = by[m].accuracy
        assert acc["precision@1.0"] > 90 and acc["count"] > 100
    # issue 2's bar: ours after the reference row fill beats StereoBM (README: 8.2 vs 12.7 %).
    assert by["pipeline"].accuracy["bad_2.0_filled"] < by["StereoBM"].accuracy["bad_2.0"]
    table = format_table(cases)
    assert table.count("\n") == len(cases) and "SGBM-3WAY" in table


def test_bench_cli_json_lines(
    data_dir: Path,
    tsukuba_cases: list[BenchCase],
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    asked: list[tuple[tuple[int, ...], int]] = []

    def timed_once(scene: Any, runs: int) -> list[BenchCase]:
        # the same scene and runs as tsukuba_cases: its cases, not a second timing of them
        asked.append((scene.left.shape, runs))
        return tsukuba_cases

    monkeypatch.setattr(stereovision.bench, "bench_scene", timed_once)
    assert main(["bench", "--runs", "5", "--json", str(data_dir / SCENE)]) == 0
    assert asked == [((288, 384, 3), 5)]
    lines = [json.loads(ln) for ln in capsys.readouterr().out.splitlines() if ln.strip()]
    assert [ln["case"] for ln in lines][-2:] == ["StereoBM", "SGBM-3WAY"]
    assert all(ln["bench"] == "vs_opencv" and ln["scene"].endswith("tsukuba") for ln in lines)
    assert {"ms", "ratio_sgbm", "max_disparity"} <= set(lines[0])
    # a count of matches is an integer in the JSON (it was written as 1326.0)
    counts = [ln["count"] for ln in lines if ln["kind"] == "sparse"]
    assert counts and all(type(c) is int and c > 100 for c in counts)


_RUNS_ERROR = "stereovision bench: error: argument --runs: expected "


@pytest.mark.parametrize(
    ("argv", "start"),
    [
        # evaluation.md "Speed": the median of >= 5 runs (1..4 were accepted); refused by the
        # parser as eval --runs is, not as a bare 'stereovision: error: --runs: at least 5 ...'
        (
            ["bench", "--runs", "1"],
            _RUNS_ERROR + "at least 5 runs (evaluation.md: the median of >= 5 runs), got '1'",
        ),
        (["bench", "--runs", "0"], _RUNS_ERROR + "at least 5 runs"),
        (["bench", "--runs", "4.5"], _RUNS_ERROR + "a whole number, got '4.5'"),
        # eval's words for the same folder (it was 'scene root not found: /no/such/folder')
        (
            ["bench", "/no/such/folder"],
            "stereovision: error: scene folder not found: /no/such/folder",
        ),
        # any count was taken: 10**20 timed the cases until killed
        (["bench", "--runs", "1001", "/no/such"], _RUNS_ERROR + "at most 1000 runs, got '1001'"),
        (
            ["bench", "--runs", str(10**20), "/no/such"],
            _RUNS_ERROR + f"at most 1000 runs, got '{10**20}'",
        ),
    ],
)
def test_bench_cli_errors_one_line(
    argv: list[str], start: str, capsys: pytest.CaptureFixture[str]
) -> None:
    try:
        status = main(argv)
    except SystemExit as exc:  # the parser's refusals exit as argparse's do
        status = exc.code
    assert status == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith(start), err


@pytest.mark.parametrize("runs", [4, np.int64(4)])
def test_bench_scene_refuses_fewer_than_five_runs(data_dir: Path, runs: int) -> None:
    """A NumPy integer is said as the number it is ("got 4", not "got np.int64(4)")."""
    scene = load_scene(data_dir / SCENE)
    with pytest.raises(ValueError, match=r"^runs: at least 5 .*, got 4$"):
        bench_scene(scene, runs=runs)


def test_bench_cli_folder_without_scenes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "empty").mkdir()
    assert main(["bench", str(tmp_path / "empty")]) == 2
    assert "no scene" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["eval", "bench"])
def test_a_folder_of_middleburys_names_is_said_with_the_names_a_scene_takes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    """A scene as Middlebury's archives ship it (im0.png, im1.png, disp0.pfm, calib.txt) was
    "no scene (left.png + right.png) under X", its files unnamed: the line says the names to
    give them, of the folder given or of those under it; among scenes it is said skipped."""
    root = tmp_path / "root"
    fix = (
        "a scene's images are named left.png + right.png and its ground truth gt_disp.pfm "
        "(rename im0.png, im1.png and disp0.pfm or disp0GT.pfm; calib.txt is read as it is)"
    )
    for name in ("artroom", "bike"):
        for image in ("im0.png", "im1.png", "disp0.pfm", "calib.txt"):
            (root / name).mkdir(parents=True, exist_ok=True)
            (root / name / image).write_bytes(b"")
    assert main([command, str(root / "bike")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: error: {root / 'bike'}: has Middlebury's im0.png + im1.png: {fix}"
    ]
    assert main([command, str(root)]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: error: no scene (left.png + right.png) under {root}; {root / 'artroom'}, "
        f"{root / 'bike'} hold Middlebury's im0.png + im1.png: {fix}"
    ]
    from stereovision.io import scan_scenes

    (root / "half").mkdir()
    (root / "half" / "left.png").write_bytes(b"")
    (root / "bike" / "right.png").write_bytes(b"")  # half a scene: said as such
    assert scan_scenes(root) == (
        [],
        [
            (root / "artroom", f"has Middlebury's im0.png + im1.png: {fix}"),
            (root / "bike", "has right.png but no left.png (a scene folder holds both)"),
            (root / "half", "has left.png but no right.png (a scene folder holds both)"),
        ],
    )


@pytest.mark.parametrize("command", ["eval", "bench"])
def test_no_scene_line_names_the_half_scenes_it_skipped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    """'no scene (left.png + right.png) under ROOT' of a folder holding only half scenes
    (left.png without right.png) did not say that they were skipped, though among scenes
    each is named; bench did not say either that the folder given was itself half a scene."""
    root = tmp_path / "root"
    for name, image in (("a", "left.png"), ("b", "right.png")):
        (root / name).mkdir(parents=True)
        (root / name / image).write_bytes(b"")
    assert main([command, str(root)]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: error: no scene (left.png + right.png) under {root}; skipped 2 half "
        f"scenes (a scene folder holds both images): {root / 'a'} has left.png but no "
        f"right.png, {root / 'b'} has right.png but no left.png"
    ]
    for name in "cdef":  # a few named, the rest counted: still one line
        (root / name).mkdir()
        (root / name / "left.png").write_bytes(b"")
    assert main([command, str(root)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "skipped 6 half scenes" in err
    assert err.endswith(f"{root / 'c'} has left.png but no right.png, 3 more\n")
    # the folder given is half a scene: said of it, as eval did
    assert main([command, str(root / "a")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: error: {root / 'a'}: has left.png but no right.png (a scene folder "
        "holds both)"
    ]
    # its right.png a folder, or a broken link: said as scan_scenes says them, not as "no
    # right.png" and as a half scene skipped under the folder given
    (root / "a" / "right.png").mkdir()
    (root / "b" / "right.png").unlink()
    (root / "b" / "right.png").symlink_to(tmp_path / "nowhere.png")
    for name, said in (
        ("a", "has left.png but right.png is a folder"),
        ("b", "has right.png but no left.png"),
    ):
        assert main([command, str(root / name)]) == 2
        assert capsys.readouterr().err.splitlines() == [
            f"stereovision: error: {root / name}: {said} (a scene folder holds both)"
        ]


def _strict_json(line: str) -> dict[str, object]:
    def refuse(token: str) -> object:
        raise ValueError(f"not JSON: {token}")

    out = json.loads(line, parse_constant=refuse)
    assert isinstance(out, dict)
    return out


def test_bench_cli_json_is_strict_without_gt_pixels(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A scene whose GT is all +inf (no known pixel): every accuracy figure has nothing to
    # measure. bench --json wrote them as NaN, which no strict JSON parser reads; eval --json
    # already wrote null.
    import cv2

    from stereovision.io import write_pfm

    scene = tmp_path / "no_gt_pixels"
    scene.mkdir()
    for name in ("left.png", "right.png"):
        img = cv2.imread(str(data_dir / SCENE / name))
        assert cv2.imwrite(str(scene / name), img[100:164, 100:196])
    write_pfm(scene / "gt_disp.pfm", np.full((64, 96), np.inf, np.float32))
    assert main(["bench", "--runs", "5", "--json", str(scene)]) == 0
    lines = [_strict_json(ln) for ln in capsys.readouterr().out.splitlines() if ln.strip()]
    by = {ln["case"]: ln for ln in lines}
    assert by["SGBM-3WAY"]["bad_2.0"] is None and by["SGBM-3WAY"]["density"] is None
    assert by["pipeline"]["bad_2.0_filled"] is None
    sparse = [ln for ln in lines if ln["kind"] == "sparse"]
    assert sparse and all(ln["precision@1.0"] is None for ln in sparse)
    assert all(isinstance(ln["ms"], float) and ln["ms"] > 0 for ln in lines)


def test_bench_of_a_scene_narrower_than_its_range_names_the_width_needed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A scene 8 px wide: bench said "disparity range 16 is not smaller than the image width 8
    ...; give a max_disparity below 8", a range nobody gave and an option bench does not have,
    naming no scene; eval says it in the scene's words (evaluation.md's range), and so does
    bench now."""

    scene = syn.narrow_scene(tmp_path)
    assert main(["bench", str(scene)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err.splitlines() == [
        f"stereovision: error: {scene}: images 8 px wide, not wider than the scene's disparity "
        "range (16 px, evaluation.md's rule: 16 at least): a scene needs images at least 17 px "
        "wide"
    ]


def test_bench_names_two_scenes_of_one_name_by_their_parents(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """day1/cam/tiny and day2/cam/tiny were both 'cam/tiny' in bench's table and JSON lines
    (as in eval's): each is named by as many parents as tell it from the other."""
    for day in ("day1", "day2"):
        (tmp_path / day / "cam").mkdir(parents=True)
        syn.narrow_scene(tmp_path / day / "cam", 20, 40)

    def one_case(scene: Any, runs: int) -> list[BenchCase]:  # the names, not the timing
        return [BenchCase(scene.name, "fast", "method", 40, 20, 16, runs, 1.0, 1.0, {})]

    monkeypatch.setattr(stereovision.bench, "bench_scene", one_case)
    assert main(["bench", str(tmp_path), "--json"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [r["scene"] for r in rows] == ["day1/cam/tiny", "day2/cam/tiny"]


def test_bench_table_keeps_its_columns_under_a_long_scene_name() -> None:
    """The scene column was 34 characters whatever the names: a longer one
    (outdoor_session_2026_12_01/rectified_pair_000123, 48) pushed its rows' figures out from
    under their labels. The column is as wide as the longest name."""
    long = "outdoor_session_2026_12_01/rectified_pair_000123"
    cases = [
        BenchCase(scene, case, "opencv", 60, 40, 16, 5, 2.0, 1.0, {"bad_2.0": 3.0})
        for scene in (long, "middlebury2001/tsukuba")
        for case in ("StereoBM", "SGBM-3WAY")
    ]
    lines = format_table(cases).splitlines()
    assert lines[1].startswith(f"{long}   60x40 ")
    ends = {line.index(" 2.0 ") for line in lines[1:]}  # the ms column, in every row
    assert len(ends) == 1 and lines[0].index("      ms") + 4 == ends.pop(), lines


def test_bench_of_a_scene_no_higher_than_stereobms_block_times_the_others(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A crop of tsukuba 12 rows high: StereoBM's refusal ('needs images at least 16 px high')
    failed the whole scene. Every other case is now benched, StereoBM left out and said why."""
    import cv2

    from stereovision.io import read_pfm, write_pfm

    src = data_dir / SCENE
    scene = tmp_path / "low"
    scene.mkdir()
    for name in ("left.png", "right.png"):
        assert cv2.imwrite(str(scene / name), cv2.imread(str(src / name))[100:112])
    write_pfm(scene / "gt_disp.pfm", read_pfm(src / "gt_disp.pfm")[100:112].copy())
    note = (
        f"{scene}: no StereoBM figures: StereoBM's 15 px block needs images at least 16 px "
        "high, got 12"
    )
    sparse = [sparse_name(m) for m in SPARSE_METHODS if m != "gabor"]
    for json_flag in ([], ["--json"]):
        assert main(["bench", *json_flag, str(scene)]) == 0
        cap = capsys.readouterr()
        assert cap.err.splitlines() == [note]
        lines = [_strict_json(ln) for ln in cap.out.splitlines() if ln.startswith("{")]
        assert [ln["case"] for ln in lines] == [*METHODS, "pipeline", *sparse, "SGBM-3WAY"]
        by: dict[Any, dict[str, Any]] = {ln["case"]: ln for ln in lines}
        assert by["SGBM-3WAY"]["ratio_sgbm"] == 1.0 and by["SGBM-3WAY"]["bad_2.0"] > 0
        assert by["pipeline"]["density"] > 50


class _Clock:
    """A fake ``time.perf_counter``: only the fake matchers below move it."""

    def __init__(self) -> None:
        self.now = 0.0

    def perf_counter(self) -> float:
        return self.now


_PATTERN = (1.0, 3.0, 2.0, 50.0, 2.0, 1.0)


def _fake(
    clock: _Clock,
    base_s: float,
    out: object,
    calls: list[float],
    pattern: tuple[float, ...] = _PATTERN,
) -> object:
    """A matcher taking 1 s on its first call (the warm-up), then ``base_s`` times ``pattern``
    (by default 1, 3, 2, 50, 2, 1: median 2 ``base_s``, mean 59/6 of it), returning ``out``;
    ``calls`` gets the clock's time at the start of each call."""

    def run(*_a: object, **_k: object) -> object:
        start = clock.now
        clock.now += 1.0 if not calls else base_s * pattern[len(calls) - 1]
        calls.append(start)
        return out

    return run


def _fake_bench(
    monkeypatch: pytest.MonkeyPatch,
    gt: np.ndarray | None,
    pattern: tuple[float, ...] = _PATTERN,
    calib: object = None,
    seen: dict[str, Any] | None = None,
) -> tuple[list[object], dict[str, list[float]], np.ndarray]:
    """bench_scene(runs=6) on an 8x32 pair with every matcher faked (timed by the fake clock);
    ``seen`` gets the arguments the matchers were called with."""
    import sys
    import types

    import stereovision.bench as bench_mod
    import stereovision.depth as depth_mod

    match_mod = sys.modules["stereovision.match"]  # the package's `match` is the function

    clock = _Clock()
    monkeypatch.setattr(bench_mod, "time", types.SimpleNamespace(perf_counter=clock.perf_counter))
    disp = np.full((8, 32), 2.0, np.float32)
    disp[3, 10] = np.nan  # a hole: bad before the row fill, not after
    calls: dict[str, list[float]] = {k: [] for k in ("pipeline", "bm", "sgbm")}
    seen = {} if seen is None else seen
    pipe = types.SimpleNamespace(disparity=disp)
    # GT 2 px: errors 0 and 1.5 px (precision@1 50 %, @2 100 %), the third match off the image
    sparse = types.SimpleNamespace(
        xl=np.array([5.0, 6.0, 40.0]), yl=np.array([1.0, 1.0, 1.0]), xr=np.array([3.0, 2.5, 38.0])
    )
    pipeline = _fake(clock, 0.010, pipe, calls["pipeline"], pattern)

    def depth_map(*a: object, **k: object) -> object:
        seen["depth_map"] = (a, k)
        return pipeline(*a, **k)  # type: ignore[operator]

    def run_matcher(*a: object, **k: object) -> object:
        seen["_run_matcher"] = (a, k)
        return disp, None

    def match(*a: object, **k: object) -> object:
        seen["match"] = (a, k)
        return sparse

    monkeypatch.setattr(depth_mod, "_run_matcher", run_matcher)
    monkeypatch.setattr(depth_mod, "depth_map", depth_map)
    monkeypatch.setattr(match_mod, "match", match)
    monkeypatch.setattr(baselines, "opencv_bm", _fake(clock, 0.001, disp, calls["bm"], pattern))
    monkeypatch.setattr(baselines, "opencv_sgbm", _fake(clock, 0.002, disp, calls["sgbm"], pattern))
    # the fake StereoBM runs on any pair: the real one's block needs 16 rows, not these 8
    monkeypatch.setattr(baselines, "bm_reference_refusal", lambda *_a: None)
    rng = np.random.default_rng(0)
    img = (rng.random((8, 32, 3)) * 255).astype(np.uint8)
    scene = types.SimpleNamespace(
        name="fake", left=img, right=img, gt=gt, max_disparity=4, calib=calib
    )
    return bench_scene(scene, runs=6), calls, disp  # type: ignore[return-value]


def test_bench_reports_the_median_of_the_timed_runs_after_a_warm_up(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """evaluation.md "Speed": one untimed warm-up per case, then the median (not the mean) of
    the ``runs`` timed runs in milliseconds, and each case's ratio to SGBM-3WAY's median."""
    gt = np.full((8, 32), 2.0, np.float32)
    cases, calls, disp = _fake_bench(monkeypatch, gt)
    by = {c.case: c for c in cases}  # type: ignore[attr-defined]
    assert len(calls["sgbm"]) == len(calls["pipeline"]) == 7  # the warm-up and 6 timed runs
    # SGBM: 2, 6, 4, 100, 4, 2 ms (the warm-up's 1 s not among them): median 4 ms
    assert by["SGBM-3WAY"].ms == pytest.approx(4.0)
    assert by["pipeline"].ms == pytest.approx(20.0) and by["StereoBM"].ms == pytest.approx(2.0)
    assert by["pipeline"].ratio == pytest.approx(5.0)
    assert by["StereoBM"].ratio == pytest.approx(0.5)
    out = by["pipeline"].as_dict()
    assert (out["ms"], out["ratio_sgbm"], out["runs"]) == (20.0, 5.0, 6)
    assert (out["width"], out["height"], out["max_disparity"]) == (32, 8, 4)
    # the pipeline's map has one hole: bad before the row fill, none after
    raw = dense_metrics(disp, gt)
    assert out["bad_2.0"] == round(raw.bad[2.0], 3) and raw.bad[2.0] > 0  # rounded to 3
    assert out["bad_2.0_filled"] == 0.0 and out["density"] == round(raw.density, 3)
    sparse = [c for c in cases if c.kind == "sparse"]  # type: ignore[attr-defined]
    # precision@1 (not @2) over the 2 matches with GT (not the 3 given)
    assert sparse and all(c.accuracy["precision@1.0"] == 50.0 for c in sparse)
    assert all(c.accuracy["count"] == 2 for c in sparse)


def test_bench_reports_every_figure_of_evaluation_md_together(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """evaluation.md: the dense figures are reported together (bad-0.5 to bad-4.0, density,
    avgerr, rms) and sparse precision@1 with @0.5, @2 and the 4x4 coverage of the count. The
    bench gave bad-2.0 and density alone, and precision@1 and the count alone."""
    gt = np.full((8, 32), 2.0, np.float32)
    gt[0, :4] = 3.0  # errors of 1 px: bad-0.5 and bad-1.0 tell apart, avgerr and rms not 0
    cases, _, disp = _fake_bench(monkeypatch, gt)
    by = {c.case: c.as_dict() for c in cases}  # type: ignore[attr-defined]
    raw = dense_metrics(disp, gt)
    want = {
        "bad_0.5": 100 * 5 / 256,  # the hole and the 4 pixels 1 px off
        "bad_1.0": 100 * 1 / 256,  # the hole alone
        "bad_2.0": 100 * 1 / 256,
        "bad_4.0": 100 * 1 / 256,
        "density": 100 * 255 / 256,
        "avgerr": 4 / 255,
        "rms": (4 / 255) ** 0.5,
    }
    for name in ("pipeline", "StereoBM", "SGBM-3WAY", *METHODS):
        for key, value in want.items():
            assert by[name][key] == round(value, 3), (name, key)
        assert by[name]["avgerr"] == round(raw.avgerr, 3) and by[name]["bad_2.0_filled"] == 0.0
        assert "n_gt" not in by[name] and "n_both" not in by[name]
    sparse = [c.as_dict() for c in cases if c.kind == "sparse"]  # type: ignore[attr-defined]
    # errors 0 and 1.5 px on the 2 matches with GT, both in the grid's top-left cell
    assert sparse and all(
        (s["precision@0.5"], s["precision@1.0"], s["precision@2.0"], s["count"], s["coverage"])
        == (50.0, 50.0, 100.0, 2, 1)
        for s in sparse
    )


def test_bench_without_gt_reports_times_only(monkeypatch: pytest.MonkeyPatch) -> None:
    cases, _, _ = _fake_bench(monkeypatch, None)
    assert cases and all(c.accuracy == {} for c in cases)  # type: ignore[attr-defined]
    assert "bad_2.0" not in cases[0].as_dict()  # type: ignore[attr-defined]


def test_format_table_names_a_scene_once_and_shows_no_figure_as_a_dash() -> None:
    from stereovision.bench import BenchCase

    acc = {"bad_2.0": float("nan"), "bad_2.0_filled": 1.25, "density": 50.0}
    cases = [
        BenchCase("a", "census", "method", 32, 8, 4, 5, 2.0, 0.5, acc),
        BenchCase("a", "SGBM-3WAY", "opencv", 32, 8, 4, 5, 4.0, 1.0, {}),
        BenchCase("b", "SGBM-3WAY", "opencv", 16, 4, 2, 5, 3.0, 1.0, {}),
    ]
    lines = format_table(cases).splitlines()
    assert len(lines) == 4
    assert lines[1].split() == [
        "a",
        "32x8",
        "4",
        "census",
        "2.0",
        "0.50",
        "-",
        "1.2",
        "50.0",
        "-",
        "-",
    ]
    assert lines[2].startswith(" " * 49 + " SGBM-3WAY")  # the scene said on its first case only
    assert lines[3].split()[:3] == ["b", "16x4", "2"]
    assert "nan" not in "\n".join(lines)


def test_bench_cli_prints_the_table_then_the_json_lines(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import cv2

    scene = tmp_path / "crop"
    scene.mkdir()
    for name in ("left.png", "right.png"):
        img = cv2.imread(str(data_dir / SCENE / name))
        assert cv2.imwrite(str(scene / name), img[100:164, 100:196])
    assert main(["bench", str(scene)]) == 0
    cap = capsys.readouterr()
    lines = cap.out.splitlines()
    n = (len(lines) - 1) // 2
    assert lines[0].split()[:4] == ["scene", "size", "D", "case"]
    table, objects = lines[1 : 1 + n], [json.loads(ln) for ln in lines[1 + n :]]
    assert len(objects) == n and [o["case"] for o in objects][-1] == "SGBM-3WAY"
    assert [ln.split()[0] for ln in table[1:]] == [o["case"] for o in objects][1:]


def test_bench_times_a_scene_given_twice_once(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`bench middlebury2001 middlebury2001/tsukuba` timed tsukuba twice (eval dropped the
    second already), and the scene counted twice among the rows; it is benched once, said."""
    from stereovision.bench import _scene_dirs

    family = data_dir / "middlebury2001"
    dirs = _scene_dirs([str(family), str(family / "tsukuba"), str(family / "venus")])
    assert dirs == [family / "tsukuba", family / "venus"]
    assert capsys.readouterr().err == "".join(
        f"stereovision: {family / s} given more than once: benched once\n"
        for s in ("tsukuba", "venus")
    )


def test_bench_says_which_folders_it_skipped_and_skips_hidden_ones(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """bench dropped a folder with right.png and no left.png without a word, and timed a hidden
    copy of a scene (.git) as a scene of its own."""
    from stereovision.bench import _scene_dirs

    for name in ("s", ".git/s", "half"):
        (tmp_path / name).mkdir(parents=True)
        (tmp_path / name / "right.png").write_bytes(b"")
    for name in ("s", ".git/s"):
        (tmp_path / name / "left.png").write_bytes(b"")
    assert _scene_dirs([str(tmp_path)]) == [tmp_path / "s"]
    assert capsys.readouterr().err == (
        f"stereovision: skipped {tmp_path / 'half'}: has right.png but no left.png"
        " (a scene folder holds both)\n"
    )


def test_bench_median_of_an_even_count_interleaved_and_milliseconds_to_3_decimals(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """evaluation.md "Speed": the median of 6 runs is the mean of the middle two (neither the
    lower nor the upper one), the cases run interleaved (A, B, A, B ...) after every warm-up,
    and the JSON's ms keeps 3 decimals (mutants of bench.py that survived the tests above)."""
    gt = np.full((8, 32), 2.0, np.float32)
    # times 1, 3, 2, 50, 2.25, 1 base: sorted 1 1 2 2.25 3 50, median 2.125 (low 2, high 2.25)
    cases, calls, _ = _fake_bench(monkeypatch, gt, pattern=(1.0, 3.0, 2.0, 50.0, 2.25, 1.0))
    by = {c.case: c for c in cases}  # type: ignore[attr-defined]
    assert by["SGBM-3WAY"].ms == pytest.approx(4.25)
    assert by["pipeline"].ms == pytest.approx(21.25) and by["pipeline"].ratio == pytest.approx(5)
    assert by["StereoBM"].as_dict()["ms"] == 2.125
    pipe, sgbm = calls["pipeline"], calls["sgbm"]
    assert pipe[1] > sgbm[0]  # every warm-up before the first timed run
    # timed run k of SGBM falls between the pipeline's k-th and (k+1)-th, not after all of them
    assert all(pipe[k] < sgbm[k] < pipe[k + 1] for k in range(1, 6))


@pytest.mark.parametrize("rectified", [False, True])
def test_bench_searches_the_scene_range_and_uses_only_a_rectified_calibration(
    monkeypatch: pytest.MonkeyPatch, rectified: bool
) -> None:
    """Every case searches the scene's max_disparity (evaluation.md: the same range for all);
    the pipeline gets the scene's calibration only when it rectifies the pair as given."""
    import types

    calib = types.SimpleNamespace(rectified=rectified)
    seen: dict[str, Any] = {}
    _fake_bench(monkeypatch, None, calib=calib, seen=seen)
    a, k = seen["depth_map"]
    assert a[2] is (calib if rectified else None) and k["max_disparity"] == 4
    a, k = seen["_run_matcher"]
    assert a[3:5] == (0.0, 4.0)
    a, k = seen["match"]
    assert k["max_disparity"] == 4


def test_bench_without_a_scene_times_the_bundled_cones() -> None:
    # the CLI's help promises the bundled Middlebury Cones (no test ran bench without a scene)
    from stereovision.bench import _scene_dirs

    (d,) = _scene_dirs([])
    assert d.parts[-2:] == ("data", "cones") and (d / "left.png").is_file()


def test_format_table_shows_a_sparse_case_precision_at_1_and_its_count() -> None:
    from stereovision.bench import BenchCase

    acc = {"precision@1.0": 97.5, "count": 1326}
    case = BenchCase("a", "hopfield", "sparse", 32, 8, 4, 5, 3.0, 0.75, acc)
    row = format_table([case]).splitlines()[1].split()
    # no dense figure; precision@1 (not another key) to 1 decimal, the count as an integer
    assert row[4:] == ["3.0", "0.75", "-", "-", "-", "97.5", "1326"]


def test_bench_json_keeps_the_ratio_to_4_decimals() -> None:
    """The JSON's ``ratio_sgbm`` is rounded to 4 decimals (a ratio of 0.12346 is not 0.12),
    ``ms`` and the accuracy figures to 3 (a mutant rounding the ratio to 2 survived)."""
    from stereovision.bench import BenchCase

    acc = {"bad_2.0": 12.34567, "density": 87.65432}
    out = BenchCase("a", "census", "method", 32, 8, 4, 5, 1.234567, 0.1234567, acc).as_dict()
    assert (out["ms"], out["ratio_sgbm"]) == (1.235, 0.1235)
    assert (out["bad_2.0"], out["density"]) == (12.346, 87.654)


@pytest.mark.parametrize("runs", [5.5, 6.0, float("nan"), "6", None, True])
def test_bench_scene_refuses_runs_that_are_no_integer_before_any_work(runs: object) -> None:
    """``runs=5.5`` or NaN passed the ``runs < 5`` check, every case ran its warm-up, and only
    then ``range(runs)`` raised a TypeError naming no argument ("6" and None: a TypeError from
    the comparison); a ValueError names ``runs`` before the scene is touched."""
    import types

    with pytest.raises(ValueError, match=r"^runs: expected an integer, at least 5 .*got "):
        bench_scene(types.SimpleNamespace(), runs=runs)  # type: ignore[arg-type]


@pytest.mark.parametrize("folder", ["data/cones", Path("data/cones")])
def test_bench_scene_of_a_folder_says_to_load_it(folder: object) -> None:
    """bench_scene("data/cones") failed with "AttributeError: 'str' object has no attribute
    'left'", naming neither the argument nor what it takes."""
    with pytest.raises(TypeError) as info:
        bench_scene(folder, runs=5)  # type: ignore[arg-type]
    assert str(info.value) == (
        "scene: got the path 'data/cones', not a scene: load it first "
        "(stereovision.io.load_scene(path))"
    )


def test_bench_scene_of_none_is_a_type_error_naming_scene() -> None:
    """bench_scene(None) was "AttributeError: 'NoneType' object has no attribute 'left'"."""
    with pytest.raises(TypeError) as info:
        bench_scene(None, runs=5)  # type: ignore[arg-type]
    assert str(info.value) == "scene: expected a scene (stereovision.io.load_scene(path)), got None"


def test_bench_of_several_scenes_goes_on_past_a_damaged_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """One damaged scene of several stopped the whole run at it (exit 2): the scenes timed
    before it were never printed (without --json the table comes at the end), those after it
    never timed, where eval says the damaged one and goes on. bench now does as eval: each
    damaged scene on a 'failed' line, the others benched and printed, exit status 1."""
    import cv2

    import stereovision.bench as bench_mod

    good = ("a_good", "c_good")
    for name in good:
        (tmp_path / name).mkdir()
        for side in ("left.png", "right.png"):
            assert cv2.imwrite(str(tmp_path / name / side), np.zeros((40, 60, 3), np.uint8))
    bad = tmp_path / "b_bad"
    bad.mkdir()
    narrow = tmp_path / "d_narrow"  # too narrow for its range: its message names its folder
    narrow.mkdir()
    for side in ("left.png", "right.png"):
        (bad / side).write_bytes(b"not a png")
        assert cv2.imwrite(str(narrow / side), np.zeros((40, 12, 3), np.uint8))

    def fake(scene: Any, runs: int) -> list[Any]:  # the figures are not what is checked
        return [
            bench_mod.BenchCase(scene.name, "SGBM-3WAY", "opencv", 60, 40, 16, runs, 2.0, 1.0, {})
        ]

    monkeypatch.setattr(bench_mod, "bench_scene", fake)
    for json_flag in ([], ["--json"]):
        assert main(["bench", *json_flag, str(tmp_path)]) == 1
        cap = capsys.readouterr()
        objects = [json.loads(ln) for ln in cap.out.splitlines() if ln.startswith("{")]
        assert [o["scene"].split("/")[-1] for o in objects] == list(good)
        if not json_flag:  # the table of the two scenes benched, then their JSON lines
            assert cap.out.splitlines()[0].split()[:4] == ["scene", "size", "D", "case"]
        err = cap.err.strip().splitlines()
        assert len(err) == 3 and err[0].startswith(f"failed {bad}: ") and "left.png" in err[0]
        assert err[1].startswith(f"failed {narrow}: ") and err[1].count(str(narrow)) == 1
        assert err[2] == "stereovision: 2 of 4 scenes failed (above)"
    # a damaged scene alone is the one-line error it was (exit 2)
    assert main(["bench", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("stereovision: error:") and "left.png" in err


def test_bench_interrupted_prints_the_scenes_it_timed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without --json the table comes at the end: a Ctrl-C (or SIGTERM) during the second of
    several scenes lost the first one's timing, as a damaged scene did before bench went on
    past it. The scenes timed are now printed (table and JSON lines), then 'interrupted'."""
    import cv2

    import stereovision.bench as bench_mod

    for name in ("a_first", "b_second", "c_third"):
        (tmp_path / name).mkdir()
        for side in ("left.png", "right.png"):
            assert cv2.imwrite(str(tmp_path / name / side), np.zeros((40, 60, 3), np.uint8))

    def fake(scene: Any, runs: int) -> list[Any]:
        if scene.name.endswith("b_second"):
            raise KeyboardInterrupt
        return [
            bench_mod.BenchCase(scene.name, "SGBM-3WAY", "opencv", 60, 40, 16, runs, 2.5, 1.0, {})
        ]

    monkeypatch.setattr(bench_mod, "bench_scene", fake)
    assert main(["bench", str(tmp_path)]) == 130
    cap = capsys.readouterr()
    assert cap.out.splitlines()[0].split()[:4] == ["scene", "size", "D", "case"]
    objects = [json.loads(ln) for ln in cap.out.splitlines() if ln.startswith("{")]
    assert [(o["scene"].split("/")[-1], o["ms"]) for o in objects] == [("a_first", 2.5)]
    assert cap.err.strip().splitlines()[-1] == "stereovision: interrupted"
    assert main(["bench", "--json", str(tmp_path)]) == 130  # its lines went out as it went
    objects = [json.loads(ln) for ln in capsys.readouterr().out.splitlines()]
    assert [o["scene"].split("/")[-1] for o in objects] == ["a_first"]


def test_bench_of_one_scene_on_a_terminal_says_it_is_timing(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The progress bar counts scenes and is off for one, so `stereovision bench` on one scene
    (the bundled cones: 12 s) was silent until its table. On a terminal a line on stderr now
    says what runs first; --json (stdout read by a program) and a piped stderr get none."""
    import sys

    import stereovision.bench as bench

    monkeypatch.setattr(bench, "bench_scene", lambda scene, runs: [])
    scene = data_dir / SCENE
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    assert main(["bench", str(scene), "--runs", "7"]) == 0
    assert capsys.readouterr().err == (
        f"{scene}: timing every case, a warm-up and 7 rounds (the table follows) ...\n"
    )
    assert main(["bench", str(scene), "--json"]) == 0
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    assert main(["bench", str(scene)]) == 0
    assert capsys.readouterr().err == ""


def test_bench_table_names_a_scene_with_a_newline_escaped() -> None:
    # a scene named with a newline cut its table row in two
    from stereovision.bench import BenchCase, format_table

    case = BenchCase("fam/o\nk", "SGBM-3WAY", "opencv", 60, 40, 16, 5, 2.0, 1.0, {})
    lines = format_table([case]).splitlines()
    assert len(lines) == 2 and lines[1].startswith("fam/o\\nk ")


def test_bench_says_a_gt_with_known_pixels_at_0_px(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """As eval: a GT converted keeping KITTI's 0 = unknown was scored against its 0s silently."""
    from stereovision.io import write_pfm

    scene = syn.narrow_scene(tmp_path, 20, 60)
    gt = np.full((20, 60), 2.0, np.float32)
    gt[:, :6] = -1.0  # another converter's mark of unknown pixels
    write_pfm(scene / "gt_disp.pfm", gt)
    monkeypatch.setattr(stereovision.bench, "bench_scene", lambda scene, runs: [])
    assert main(["bench", str(scene), "--json"]) == 0
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: {scene}: gt_disp.pfm: 120 of its 1200 known pixels (10.0 %) are at 0 px "
        "or below, scored as known disparities; if they mark unknown pixels (as 0 does in "
        "KITTI's and Middlebury's PNGs), write them as +inf"
    ]


def test_bench_says_a_gt_without_a_known_pixel(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A gt_disp.pfm all +inf: eval skips the scene saying so; bench timed it with '-' for every
    figure and a sparse count of 0, without a word on the GT. Said now, the figures as before."""
    from stereovision.io import write_pfm

    scene = syn.narrow_scene(tmp_path, 20, 40)
    write_pfm(scene / "gt_disp.pfm", np.full((20, 40), np.inf, np.float32))
    monkeypatch.setattr(stereovision.bench, "bench_scene", lambda scene, runs: [])
    assert main(["bench", str(scene), "--json"]) == 0
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: {scene}: no ground truth: gt_disp.pfm has no known (finite) pixel, "
        "times only"
    ]


def test_bench_of_a_scene_whose_gt_kept_middleburys_name_says_to_rename_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """As eval: a scene whose GT kept Middlebury's name (disp0GT.pfm) was benched with '-' for
    every figure without a word on the GT beside its images; a scene without GT is not said."""
    scene = syn.narrow_scene(tmp_path, 20, 40)
    (scene / "gt_disp.pfm").rename(scene / "disp0GT.pfm")
    monkeypatch.setattr(stereovision.bench, "bench_scene", lambda scene, runs: [])
    assert main(["bench", str(scene), "--json"]) == 0
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: {scene}: no ground truth (gt_disp.pfm), times only; it holds "
        "Middlebury's disp0GT.pfm: rename it gt_disp.pfm"
    ]
    (scene / "disp0GT.pfm").unlink()
    assert main(["bench", str(scene), "--json"]) == 0
    assert capsys.readouterr().err == ""
