"""The command line: outputs, exit codes, one-line errors, nothing lost on failure."""

from __future__ import annotations

import json
import re
import shlex
import shutil
import subprocess
import sys
from collections.abc import Callable
from importlib import resources
from pathlib import Path

import cv2
import numpy as np
import pytest

from stereovision.cli import main
from stereovision.io import read_pfm, read_ply

SV = [sys.executable, "-m", "stereovision.cli"]
CONES = Path(str(resources.files("stereovision") / "data" / "cones"))  # the bundled scene


def _in_process(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> subprocess.CompletedProcess[str]:
    """``stereovision *argv`` run by cli.main in this Python, as subprocess.run would report it
    (main returns the exit status): a new Python costs ~1.2 s CPU of imports."""
    capsys.readouterr()
    rc = main(argv)
    return subprocess.CompletedProcess(argv, rc, *capsys.readouterr())


def test_demo_writes_outputs_and_prints_figures(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "demo"
    rc = main(["demo", "-o", str(out)])  # in process: a new Python costs ~1.2 s CPU
    proc = subprocess.CompletedProcess([], rc, *capsys.readouterr())
    assert proc.returncode == 0, proc.stderr
    assert "bad-2.0" in proc.stdout and "density" in proc.stdout
    assert "  rectification ok: median |dy| 0.0" in proc.stdout  # 0.09 px
    # Ours (filled) against OpenCV's SGBM after the same row fill, both printed: ours is lower.
    ours = re.search(r"fused on cones .*?bad-2\.0 ([\d.]+) % \(filled\)", proc.stdout)
    sgbm = re.search(r"StereoSGBM 3-way .*?, ([\d.]+) % with the row fill", proc.stdout)
    assert ours and sgbm, proc.stdout
    assert float(ours.group(1)) < 0.8 * float(sgbm.group(1))
    names = ("disparity.png", "depth.png", "disparity.pfm", "depth.npy", "depth_mm.png")
    names += ("overview.png",)  # and in the manifest: a rerun replaces it
    for name in (*names, "cloud.ply"):
        assert (out / name).stat().st_size > 0, name
    disp = read_pfm(out / "disparity.pfm")
    assert disp.shape == (375, 450)
    assert np.isfinite(disp).mean() > 0.5
    img = cv2.imread(str(out / "disparity.png"))
    assert img is not None and img.shape == (375, 450, 3) and img.std() > 10
    pts, _ = read_ply(out / "cloud.ply")
    assert len(pts) > 10000
    assert "overview.png" in json.loads((out / ".stereovision-depth.json").read_text())
    # depth.npy's holes where disparity.pfm has values (16 %) were said nowhere: counted, with
    # their reason (all filled pixels, guesses that get no depth)
    said = re.search(
        r"\n  depth on ([\d.]+) % of the pixels \(disparity on 100\.0 %\): none on (\d+) "
        r"filled \([\d.]+ %, guesses, not measured\)\n",
        proc.stdout,
    )
    assert said, proc.stdout
    depth = np.load(out / "depth.npy")
    assert float(said.group(1)) == round(100 * np.isfinite(depth).mean(), 1)
    assert int(said.group(2)) == int((np.isfinite(disp) & ~np.isfinite(depth)).sum()) > 0


def test_closed_pipe_stops_quietly(tmp_path: Path) -> None:
    """`stereovision demo | head -1`: the reader goes away while the pipeline runs; the CLI
    stops with 141 (128 + SIGPIPE, as a shell reports) and prints no error."""
    codes = []
    # The pipe is closed a fraction of a second before the results are printed; on a loaded
    # machine the demo can finish first (exit 0, nothing to test), so up to three tries.
    for attempt in range(3):
        proc = subprocess.Popen(
            [*SV, "demo", "-o", str(tmp_path / f"demo{attempt}")],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert proc.stdout is not None and proc.stderr is not None
        assert proc.stdout.readline().startswith("demo scene:")
        proc.stdout.close()
        err = proc.stderr.read()
        codes.append(proc.wait(timeout=120))
        assert codes[-1] in (0, 141) and err == "", (codes, err)
        if codes[-1] == 141:
            break
    assert codes[-1] == 141, codes


def test_warnings_are_one_line(
    tmp_path: Path, data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A swapped pair runs, and the CLI says so in one line (not Python's file:line echo)."""
    scene = data_dir / "middlebury2003" / "cones"
    argv = ["depth", str(scene / "right.png"), str(scene / "left.png"), "-o", str(tmp_path)]
    proc = _in_process(argv, capsys)  # main sets the one-line warning format itself
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("stereovision: warning: the left and right images look swapped")


def test_depth_command_on_metric_scene(
    tmp_path: Path,
    crop_terrace: Callable[[slice, slice], Path],
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # a 300 x 200 crop of eth3d/terrace about its principal point (the whole: 3 s a run)
    scene = crop_terrace(slice(117, 317), slice(206, 506))
    out = tmp_path / "o"
    rc = main(
        [
            "depth",
            str(scene / "left.png"),
            str(scene / "right.png"),
            "--calib",
            str(scene / "calib.txt"),
            "--max-disparity",
            "32",
            "-o",
            str(out),
        ]
    )
    assert rc == 0
    depth = np.load(out / "depth.npy")
    assert depth.shape == (200, 300) and depth.dtype == np.float32
    assert 1.0 < float(np.nanmedian(depth)) < 30.0  # metres
    # the 16-bit PNG holds the same depths in millimetres, 0 where there are none
    mm = cv2.imread(str(out / "depth_mm.png"), cv2.IMREAD_UNCHANGED)
    assert mm.dtype == np.uint16 and mm.shape == depth.shape
    np.testing.assert_array_equal(mm == 0, ~np.isfinite(depth))
    assert np.abs(mm[mm > 0] / 1000.0 - depth[mm > 0]).max() <= 0.0005 + 1e-6
    # --max-depth keeps the near half: depth, its PNG and the cloud lose the rest
    med = float(np.nanmedian(depth))
    argv = ["depth", str(scene / "left.png"), str(scene / "right.png"), "--calib"]
    argv += [str(scene / "calib.txt"), "--max-disparity", "32", "-o", str(tmp_path / "near")]
    assert main([*argv, "--max-depth", f"{med:.3f}"]) == 0
    near = np.load(tmp_path / "near" / "depth.npy")
    # the pixels with a disparity but no depth are counted with their reason: the filled ones
    # (as many in both runs), and the measured ones past --max-depth (terrace: none within
    # sigma_d of infinite depth)
    full, cut = (ln for ln in capsys.readouterr().out.splitlines() if "  depth on " in ln)
    filled = re.search(r"none on (\d+) filled", full)
    assert filled and int(filled.group(1)) > 0 and f" {filled.group(0)} (" in cut
    assert full.startswith(f"  depth on {100 * np.isfinite(depth).mean():.1f} % of the pixels")
    assert full.endswith(", guesses, not measured)") and " nor on " not in full
    beyond = int((np.isfinite(depth) & ~np.isfinite(near)).sum())
    assert cut.startswith(f"  depth on {100 * np.isfinite(near).mean():.1f} % of the pixels")
    assert f" nor on {beyond} measured (" in cut and cut.endswith(
        ") outside the limits or within sigma_d of infinite depth"
    )
    with np.errstate(invalid="ignore"):
        np.testing.assert_array_equal(np.isfinite(near), depth <= round(med, 3))
    pts, _ = read_ply(tmp_path / "near" / "cloud.ply")
    assert len(pts) == np.isfinite(near).sum() and pts[:, 2].max() <= med + 1e-3
    with pytest.raises(SystemExit):  # refused by argparse, in the option's name
        main([*argv, "--max-depth", "0"])
    # --voxel: one point per 5 cm cube in cloud.ply, the depth maps whole
    capsys.readouterr()
    import stereovision.io

    def read_back(*_: object) -> None:
        raise AssertionError("cloud.ply read back to count its points")

    # the count is the writer's: the whole cloud.ply was read back just to count it
    with monkeypatch.context() as m:
        m.setattr(stereovision.io, "read_ply", read_back)
        assert main([*argv, "--voxel", "0.05"]) == 0
    vox, _ = read_ply(tmp_path / "near" / "cloud.ply")
    # the summary gave the result's point count only, read as cloud.ply's (8x too many)
    summary = capsys.readouterr().out.splitlines()[0]
    n = int(np.isfinite(depth).sum())
    assert summary.endswith(f" {n} points ({len(vox)} in cloud.ply, one per 0.05 m cube), "
                            + summary.rsplit(", ", 1)[1])  # fmt: skip
    assert 0 < len(vox) < 0.2 * np.isfinite(depth).sum()
    cells = np.floor(vox / 0.05)
    assert len(np.unique(cells, axis=0)) == len(vox)
    np.testing.assert_array_equal(np.load(tmp_path / "near" / "depth.npy"), depth)
    argv = ["depth", str(scene / "left.png"), str(scene / "right.png"), "--max-sigma", "0.1"]
    assert main([*argv, "-o", str(tmp_path / "x")]) == 2
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    ("filled", "dropped", "limits", "tail"),
    [
        (0, 0, {}, ": every pixel with a disparity has one"),
        (30, 0, {}, ": none on 30 filled (15.0 %, guesses, not measured)"),
        (0, 20, {}, ": none on 20 measured (10.0 %) within sigma_d of infinite depth"),
        (
            30,
            20,
            {"max_depth": 2.0},
            ": none on 30 filled (15.0 %, guesses, not measured) nor on 20 measured (10.0 %) "
            "outside the limits or within sigma_d of infinite depth",
        ),
    ],
)
def test_depth_coverage_leaves_out_the_reasons_with_no_pixel(
    filled: int, dropped: int, limits: dict[str, float], tail: str
) -> None:
    """demo --method gabor (nothing filled, nothing dropped) said "none on 0 filled (0.0 %,
    guesses, not measured) nor on 0 measured (0.0 %) ...": a reason is said only when it has
    pixels, and with neither the line says so in one clause."""
    from types import SimpleNamespace

    from stereovision.cli import _depth_coverage

    counts = {"pixels": 200, "disparity": 150, "filled": filled, "dropped": dropped}
    counts["depth"] = 150 - filled - dropped
    res = SimpleNamespace(depth_counts=lambda: counts, limits=limits)
    depth_pct = f"{100 * counts['depth'] / 200:.1f}"
    head = f"depth on {depth_pct} % of the pixels (disparity on 75.0 %)"
    assert _depth_coverage(res) == head + tail


def test_depth_coverage_of_a_map_without_any_disparity_says_so() -> None:
    """A pair with nothing to match (a blank wall: depth --method gabor of two grey images)
    was said 'depth on 0.0 % of the pixels (disparity on 0.0 %): every pixel with a disparity
    has one', true of no pixel; it now says that none has a disparity."""
    from types import SimpleNamespace

    from stereovision.cli import _depth_coverage

    counts = {"pixels": 200, "disparity": 0, "depth": 0, "filled": 0, "dropped": 0}
    res = SimpleNamespace(depth_counts=lambda: counts, limits={})
    assert _depth_coverage(res) == (
        "depth on 0.0 % of the pixels (disparity on 0.0 %): no pixel has a disparity to triangulate"
    )


def test_errors_are_one_line_and_keep_earlier_outputs(
    tmp_path: Path, data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "o"
    out.mkdir()
    keep = out / "disparity.png"
    keep.write_bytes(b"earlier result")
    scene = data_dir / "middlebury2001" / "tsukuba"
    cases = [
        ["depth", str(tmp_path / "missing.png"), str(scene / "right.png"), "-o", str(out)],
        [
            "depth",
            str(scene / "left.png"),
            str(data_dir / "eth3d" / "terrace" / "right.png"),
            "-o",
            str(out),
        ],
        [
            "depth",
            str(scene / "left.png"),
            str(scene / "right.png"),
            "--calib",
            str(scene / "SOURCE"),
            "-o",
            str(out),
        ],
        ["eval", str(tmp_path / "nowhere")],
    ]
    for argv in cases:  # in process (main returns the exit status): ~1.2 s CPU less a case
        proc = subprocess.CompletedProcess(argv, main(argv), *capsys.readouterr())
        assert proc.returncode == 2, (argv, proc.stdout, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("stereovision: error:"), proc.stderr
        assert "Traceback" not in proc.stderr
    assert keep.read_bytes() == b"earlier result"


def test_eval_json_one_object_per_scene(data_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import json

    proc = _in_process(["eval", str(data_dir / "middlebury2001" / "tsukuba"), "--json"], capsys)
    assert proc.returncode == 0, proc.stderr
    rows = [json.loads(line) for line in proc.stdout.splitlines() if line.strip()]
    assert len(rows) == 1
    row = rows[0]
    assert row["scene"].endswith("tsukuba") and row["max_disparity"] == 16
    # Gabor (+ reference fill) beats StereoBM on Tsukuba, same run.
    assert row["ours+fill"]["bad_2.0"] < row["bm"]["bad_2.0"]


def test_eval_mean_line_has_every_column(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The mean line left out SGBM-3WAY + fill, the reference a dense map must beat
    # (evaluation.md), and named the others bm / sgbm instead of the table's headers.
    assert main(["eval", str(data_dir / "middlebury2001" / "tsukuba")]) == 0
    mean = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("mean bad-2.0")]
    assert len(mean) == 1
    m = re.fullmatch(
        r"mean bad-2\.0: ours ([\d.]+) %, ours\+fill ([\d.]+) %, StereoBM ([\d.]+) %, "
        r"SGBM-3WAY ([\d.]+) %, SGBM\+fill ([\d.]+) %",
        mean[0],
    )
    assert m is not None, mean[0]
    # OpenCV's figures within test_baselines' tolerance (they move a little between versions)
    bm, sgbm, sgbm_fill = float(m[3]), float(m[4]), float(m[5])
    assert (bm, sgbm, sgbm_fill) == pytest.approx((12.7, 5.3, 4.2), abs=0.5)
    assert float(m[2]) < sgbm_fill  # ours after the fill beats SGBM-3WAY + fill on tsukuba (3.3)


def test_eval_goes_on_past_a_damaged_scene(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One undecodable scene among several is reported in one line and the rest evaluated;
    the exit status is 1 (as batch's for a failed pair). Alone it is the usual error."""
    import json
    import shutil

    good = tmp_path / "a_tsukuba"
    shutil.copytree(data_dir / "middlebury2001" / "tsukuba", good)
    bad = tmp_path / "b_broken"
    shutil.copytree(good, bad)
    (bad / "left.png").write_bytes(b"not a png")
    proc = _in_process(["eval", str(tmp_path), "--json", "--no-opencv"], capsys)
    assert proc.returncode == 1, proc.stderr
    rows = [json.loads(line) for line in proc.stdout.splitlines() if line.strip()]
    assert [Path(r["scene"]).name for r in rows] == ["a_tsukuba"]
    assert rows[0]["ours"]["bad_2.0"] < 10
    err = proc.stderr.strip().splitlines()
    assert len(err) == 2 and err[0].startswith(f"failed {bad}: ") and "left.png" in err[0]
    assert err[1] == "stereovision: 1 of 2 scenes failed (above)"
    alone = _in_process(["eval", str(bad)], capsys)
    assert alone.returncode == 2 and alone.stderr.count("\n") == 1 and "left.png" in alone.stderr


def test_depth_refuses_an_output_under_a_file_before_matching(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    img = str(data_dir / "middlebury2001" / "tsukuba" / "left.png")
    (tmp_path / "a.txt").write_text("x")
    argv = ["depth", img, img.replace("left", "right"), "-o", str(tmp_path / "a.txt" / "out")]
    proc = _in_process(argv, capsys)
    assert proc.returncode == 2 and proc.stdout == ""  # no matcher line: it never ran
    assert proc.stderr.strip().endswith("a.txt is a file, not a folder")


def test_depth_reads_16_bit_images_whole(tmp_path: Path, data_dir: Path) -> None:
    """16-bit PNGs (a dark 13-bit exposure of ETH3D terrace) were read as 8-bit, keeping their
    top 5 bits: bad-2.0 11.6 %, against 1.6 % for depth_map on the same arrays."""
    from stereovision.evaluate import dense_metrics
    from stereovision.io import load_scene

    scene = load_scene(data_dir / "eth3d" / "terrace")
    for name, img in (("left", scene.left), ("right", scene.right)):
        assert cv2.imwrite(str(tmp_path / f"{name}.png"), (img.astype(np.uint16) * 257) // 8)
    argv = ["depth", str(tmp_path / "left.png"), str(tmp_path / "right.png"), "--calib"]
    argv += [str(data_dir / "eth3d" / "terrace" / "calib.txt"), "--method", "fast"]
    assert main([*argv, "--max-disparity", "32", "-o", str(tmp_path / "o")]) == 0
    bad2 = dense_metrics(read_pfm(tmp_path / "o" / "disparity.pfm"), scene.gt).bad[2.0]
    assert bad2 < 2.5


def test_depth_warns_about_one_image_given_twice(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    img = str(data_dir / "middlebury2001" / "tsukuba" / "left.png")
    proc = _in_process(["depth", img, img, "--method", "fast", "-o", str(tmp_path)], capsys)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.splitlines()[0].startswith("stereovision: warning: ")
    assert "are the same image: every disparity comes out 0" in proc.stderr


def test_depth_of_one_blank_frame_twice_says_no_disparity_comes_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two identical blank frames warned "every disparity comes out 0" before the matching,
    yet none came out (density 0 %): the warning now says what the result holds."""
    assert cv2.imwrite(str(tmp_path / "blank.png"), np.full((40, 64), 128, np.uint8))
    img = str(tmp_path / "blank.png")
    assert main(["depth", img, img, "--method", "fast", "-o", str(tmp_path / "o")]) == 0
    out, err = capsys.readouterr()
    assert "density 0.0 %" in out
    assert err == (
        f"stereovision: warning: {img} and {img} are the same image: no disparity comes out "
        "(two views of the scene are needed)\n"
    )


def test_depth_on_a_pair_too_small_says_only_that(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A 1x1 px pair (both images alike, as such tiny images are) printed "... are the same
    image" before the size error: the size error is now the only line, and nothing is written."""
    img = np.full((1, 1, 3), 7, np.uint8)
    for name in ("l.png", "r.png"):
        assert cv2.imwrite(str(tmp_path / name), img)
    argv = ["depth", str(tmp_path / "l.png"), str(tmp_path / "r.png"), "-o", str(tmp_path / "o")]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: image too narrow for stereo matching: 1 px wide, and the automatic "
        "disparity range (at least 16 px) needs images at least 17 px wide; a --max-disparity "
        "of your own needs images at least 2 px wide\n"  # the option, not Python's keyword
    )
    assert main([*argv, "--max-disparity", "16"]) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: disparity range 16 is not smaller than the image width 1: it needs "
        "images at least 17 px wide (a range of a pixel or more needs 2 px)\n"
    )
    assert not (tmp_path / "o").exists()


def test_depth_same_image_with_a_calibration_for_another_size_says_only_that(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One image given twice with a calibration for another image size printed "... are the
    same image" before the calibration's size error: the error is now the only line (depth_map
    refuses the pair), and nothing is written."""
    img = str(data_dir / "middlebury2003" / "cones" / "left.png")
    calib = str(data_dir / "kitti2015" / "000005_10" / "calib.txt")
    argv = ["depth", img, img, "--calib", calib, "-o", str(tmp_path / "o")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [
        "stereovision: error: calibration is for 1242x375 images, got 450x375 (another aspect "
        "ratio: another camera mode or camera, or cropped images)"
    ]
    assert not (tmp_path / "o").exists()


@pytest.mark.usefixtures("in_process_dask")
def test_resized_pair_size_error_gives_cli_advice(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A pair resized from the calibration's images was refused by depth and batch with
    "calib.scaled_to((450, 375))", a Python call no one at the command line can make: said in
    the CLI's words (the ADVICE swap its warnings get); Python's message keeps the call."""
    from stereovision.depth import depth_map
    from stereovision.io import load_scene

    teddy = load_scene(data_dir / "middeval3" / "teddyH")
    half = [cv2.resize(img, None, fx=0.5, fy=0.5) for img in (teddy.left, teddy.right)]
    pairs = tmp_path / "pairs"
    pairs.mkdir()
    pair = [str(pairs / "left.png"), str(pairs / "right.png")]
    for path, img in zip(pair, half, strict=True):
        cv2.imwrite(path, img)
    rig = str(teddy.calib.save(tmp_path / "rig.yaml"))
    said = (
        "calibration is for 900x750 images, got 450x375 (images resized, not cropped: resize "
        "them back to the calibration's size, or save it scaled to them once in Python with "
        "Calibration.from_file(path).scaled_to((450, 375)).save('rig.yaml') and give rig.yaml)"
    )
    assert main(["depth", *pair, "--calib", rig, "-o", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err == f"stereovision: error: {said}\n"
    assert main(["batch", str(pairs), "--calib", rig, "-o", str(tmp_path / "b")]) == 1
    assert f"failed pairs: ValueError: {said}\n" in capsys.readouterr().err
    with pytest.raises(ValueError, match=r"not cropped: calib\.scaled_to\(\(450, 375\)\)\)$"):
        depth_map(*half, teddy.calib)


def test_a_resized_maps_depth_warning_gives_cli_advice(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Triangulation's warning for a map of a resized pair read with the full-size calibration
    ended "use calib.scaled_to((225, 188))" on the CLI's warning line too, a Python call: the
    line (cli's warning hook, also the error line's and batch's swap) says it with --calib and
    files; Python's warning keeps the call."""
    from stereovision import cli
    from stereovision.calibration import Calibration
    from stereovision.triangulation import depth_from_disparity

    calib = Calibration.from_file(cli._demo_scene_dir() / "calib.txt")  # 450x375
    with pytest.warns(UserWarning, match=r"225x188 px, the calibration's images 450x375") as w:
        depth_from_disparity(np.full((188, 225), 20.0), calib)
    (seen,) = w
    assert "x the true depths; use calib.scaled_to((225, 188)) (a map" in str(seen.message)
    cli._one_line_warning(seen.message, seen.category, seen.filename, seen.lineno)
    err = capsys.readouterr().err
    assert err == (
        "stereovision: warning: disparity map is 225x188 px, the calibration's images 450x375: "
        "read with it, a map of the pair resized by 0.5 gives about 2 x the true depths; give "
        "--calib a calibration scaled to 225x188 images (save it once in Python with "
        "Calibration.from_file(path).scaled_to((225, 188)).save('rig.yaml')), or resize the "
        "images back to the calibration's size (a map of the images' top-left 225x188 px is "
        "read right)\n"
    )


def test_depth_rectification_on_a_pair_too_small_says_only_that(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """With --rectification the early size check was skipped (rectifying may change the size),
    so a 1x1 px pair printed "... are the same image" before the size error: the rectified
    pair is now checked before that warning, and the error is the only line. An image not of
    the rectification's input size is likewise refused alone."""
    img = np.full((1, 1, 3), 7, np.uint8)
    for name in ("l.png", "r.png"):
        assert cv2.imwrite(str(tmp_path / name), img)
    eye = np.eye(3).tolist()
    rect = {"H1": eye, "H2": eye, "size": [1, 1], "input_size": [1, 1]}
    rect |= {"F": [[0, 0, 0], [0, 0, -1], [0, 1, 0]], "matches": 40, "median_dy": 0.1}
    rect |= {"p95_dy": 0.3, "disparity_range": [0, 1], "max_disparity": 16}
    rect |= {"skew_deg": [0, 0], "aspect": [1, 1], "model": "projective"}
    (tmp_path / "rect.json").write_text(json.dumps(rect))
    argv = ["depth", str(tmp_path / "l.png"), str(tmp_path / "r.png"), "-o", str(tmp_path / "o")]
    argv += ["--rectification", str(tmp_path / "rect.json")]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: disparity range 16 is not smaller than the image width 1: it needs "
        "images at least 17 px wide (a range of a pixel or more needs 2 px)\n"
    )
    rect["input_size"] = [640, 480]
    (tmp_path / "rect.json").write_text(json.dumps(rect))
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1, err
    assert err.startswith("stereovision: error: ") and "640x480" in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["depth"], "stereovision depth: error: the following arguments are required: left"),
        (["bogus"], "stereovision: error: argument command: invalid choice: 'bogus'"),
        ([], "stereovision: error: the following arguments are required: command"),
        (
            ["depth", "a", "b", "-o", "x", "--max-disparity", "abc"],
            "--max-disparity: expected a whole number of pixels above 0, got 'abc'",
        ),
        (["stream", "--method", "sgbm"], "stereovision stream: error: argument --method"),
        # named as the option, not as run_stream's parameter ("frames: expected ...")
        (["stream", "--frames", "0"], "argument --frames: expected a whole number above 0"),
        (["stream", "--check-every", "0"], "argument --check-every: expected a whole number"),
        (
            ["stream", "--serve", "70000"],
            "argument --serve: expected a port 1 to 65535, or 0 for a free one",
        ),
        (["capture", "-o", "x", "--every", "0"], "argument --every: expected a whole number"),
        (["capture", "-o", "x", "--fps", "0"], "argument --fps: expected a frame rate above 0"),
        (["stream", "--fps", "nan"], "argument --fps: expected a frame rate above 0, got 'nan'"),
        (
            ["capture", "-o", "x", "--read-timeout", "0"],
            "argument --read-timeout: expected seconds above 0 or 'none' (no limit), got '0'",
        ),
        (["stream", "--read-timeout", "inf"], "argument --read-timeout: expected seconds above 0"),
        (["gui", "--read-timeout", "-1"], "argument --read-timeout: expected seconds above 0"),
        # taken, then an internal OverflowError out of the wait (and an abort, exit 134)
        (
            ["capture", "-o", "x", "--read-timeout", "1e10"],
            "argument --read-timeout: expected at most 86400 seconds (a day), or 'none' for no "
            "limit, got '1e10'",
        ),
    ],
)
def test_usage_errors_are_one_line(argv: list[str], says: str) -> None:
    """argparse's errors too: one line naming the command and its --help, not the usage block."""
    proc = subprocess.run([*SV, *argv], capture_output=True, text=True, check=False)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and says in proc.stderr, proc.stderr
    assert proc.stderr.rstrip().endswith("--help)")


def test_eval_metric_scene_reports_validated_matches(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """ETH3D terrace: depth figures, Table-1 on the dense map and on the validated matches."""
    import json

    assert main(["eval", str(data_dir / "eth3d" / "terrace"), "--json"]) == 0
    row = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert row["table1"]["n_points"] == 10 and row["members_table1"]["n_points"] == 10
    # the tables' text is the text output's: not in the JSON object
    assert [k for k in row if k.startswith("_")] == []
    members, sgbm = row["members_depth"], row["sgbm_depth"]
    # Measured: 4642 members, RMSE 3.19 % of the mean depth vs SGBM-3WAY's 6.10 % (issue 5 asks
    # for at most half: 0.52 here; was 3872 members, 3.09 %, before this round's Hopfield rules).
    assert members["n"] > 3000
    assert members["rmse_pct"] <= 0.55 * sgbm["rmse_pct"]
    # Members' median 1.37 %, SGBM's 2.18 %; the refined dense map's is as low (1.35 %).
    assert members["median_rel"] < sgbm["median_rel"]
    assert row["depth"]["median_rel"] < sgbm["median_rel"]


def test_info_describes_the_rig(data_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["info", str(data_dir / "eth3d" / "terrace" / "calib.txt")]) == 0
    out = capsys.readouterr().out
    assert "baseline 6.0 cm (59.9432 mm), focal length 711.5 px" in out
    assert "farthest depth, at a disparity of 1 px: 42.65 m" in out
    assert main(["info", str(data_dir / "nowhere.txt")]) == 2


def test_info_on_paper_refuses_a_bad_value_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    """``info --size 1280x720 --hfov 180 --baseline 0.1`` printed the rig's heading on stdout,
    then 'hfov_deg: ...', the Python argument's name, on stderr; the error is now the one line,
    naming the option (refused by argparse now, with the range --hfov takes)."""
    with pytest.raises(SystemExit) as exit_:
        main(["info", "--size", "1280x720", "--hfov", "180", "--baseline", "0.1"])
    assert exit_.value.code == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.strip().splitlines() == [
        "stereovision info: error: argument --hfov: expected a horizontal field of view from "
        "0.1 to under 180 degrees, got '180' (see stereovision info --help)"
    ]
    assert main(["info", "--size", "1280x720", "--hfov", "90", "--baseline", "-1"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("stereovision: error: --baseline: expected a positive")


@pytest.mark.parametrize(
    ("given", "left_out"),
    [
        (["--size", "1280x720", "--hfov", "90"], " (--baseline missing)"),
        (["--size", "1280x720", "--baseline", "0.12"], " (--hfov missing)"),
        (["--baseline", "0.12"], " (--size and --hfov missing)"),
        ([], ""),
    ],
)
def test_info_on_paper_names_the_option_left_out(
    given: list[str], left_out: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``info --size 1280x720 --hfov 90`` (the baseline forgotten) was told to give a
    calibration, or --size, --hfov and --baseline, as if it had given none of them; the ones
    left out are named now. Nothing given: said as before."""
    assert main(["info", *given]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err == (
        "stereovision: error: give a calibration (or a bag), or a rig on paper: --size, --hfov "
        f"and --baseline{left_out}\n"
    )


@pytest.mark.parametrize("baseline", ["1e308", "1000001"])
def test_info_on_paper_refuses_a_baseline_past_1000_km(
    baseline: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``info --baseline 1e308`` printed NumPy's "overflow encountered" warnings, then "baseline
    inf m" and depths of inf, exit 0; a baseline past 1000 km is now refused in one line."""
    assert main(["info", "--size", "1280x720", "--hfov", "90", "--baseline", baseline]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.splitlines() == [
        "stereovision: error: --baseline: expected at most 1e+06 m (a rig on paper), "
        f"got {float(baseline):g}"
    ]
    assert main(["info", "--size", "1280x720", "--hfov", "90", "--baseline", "1e6"]) == 0
    assert "farthest depth, at a disparity of 1 px: 640000000.00 m" in capsys.readouterr().out


def test_info_on_paper_refuses_a_baseline_past_any_float_as_typed(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``info --baseline 1e400`` said "got inf" (the parsed float; 1e-400 "got 0.0"), a value
    not typed: the value as typed now, by the parser, as ``check --tolerance 1e400``."""
    for bad, expected in (
        ("1e400", "at most 1e+06 m (a rig on paper)"),
        ("-1e400", "a positive number of metres"),
        ("1e-400", "a positive number of metres"),  # was "got 0.0"
        ("nan", "a positive number of metres"),
    ):
        with pytest.raises(SystemExit) as exit_:
            main(["info", "--size", "1280x720", "--hfov", "90", f"--baseline={bad}"])
        assert exit_.value.code == 2
        assert capsys.readouterr().err == (
            f"stereovision info: error: argument --baseline: expected {expected}, got '{bad}' "
            "(see stereovision info --help)\n"
        )


def test_info_on_paper_names_baseline_for_one_too_small_to_compute_with(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``info --baseline 1e-300`` said the library's "T: zero baseline (T = [-1e-300, ...])",
    naming no option given: its square underflows, and it is now refused as --baseline."""
    assert main(["info", "--size", "1280x720", "--hfov", "90", "--baseline", "1e-300"]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.splitlines() == [
        "stereovision: error: --baseline: expected a positive number of metres, got 1e-300 "
        "(too small to compute with)"
    ]


@pytest.mark.parametrize("option", ["--forward", "--up", "--right"])
@pytest.mark.parametrize("value", ["1e308", "-1000001", "nan", "inf"])
def test_view_refuses_a_camera_move_past_its_limit_in_one_line(
    option: str, value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``view --forward 1e308`` printed NumPy's "overflow encountered in multiply" and wrote an
    empty screenshot, exit 0: refused by argparse now, naming the option, before any work."""
    shot = tmp_path / "v.png"
    with pytest.raises(SystemExit) as exc:
        main(["view", str(tmp_path / "missing.ply"), option, value, "-o", str(shot)])
    assert exc.value.code == 2 and not shot.exists()
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision view: error: argument {option}: expected metres from -1e+06 to 1e+06, "
        f"got {value!r} (see stereovision view --help)"
    ]


@pytest.mark.parametrize("option", ["--roll", "--pitch", "--yaw"])
@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e400"])
def test_view_refuses_a_turn_that_is_no_finite_number_in_the_option_s_name(
    option: str, value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``view --roll nan`` said "camera control roll must be a finite number, got nan": the
    library's words, no option named (the moves said theirs). Refused by argparse now."""
    shot = tmp_path / "v.png"
    with pytest.raises(SystemExit) as exc:
        main(["view", str(tmp_path / "missing.ply"), f"{option}={value}", "-o", str(shot)])
    assert exc.value.code == 2 and not shot.exists()
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision view: error: argument {option}: expected a finite number of degrees, "
        f"got {value!r} (see stereovision view --help)"
    ]


@pytest.mark.parametrize("command", ["capture", "stream", "calibrate"])
@pytest.mark.parametrize("value", ["nan", "-5", "inf", "1e308"])
def test_max_skew_ms_is_refused_in_the_option_s_name(
    command: str, value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--max-skew-ms nan`` (-5, inf) said the library's "max_skew_ms: expected a number >= 0"
    and 1e308 "internal OverflowError: cannot convert float infinity to integer (please report
    this)": refused by argparse now, naming the option and its range, before the bag is read."""
    argv = [command, "--from-bag", str(tmp_path / "rig"), f"--max-skew-ms={value}"]
    with pytest.raises(SystemExit) as exc:
        main(argv + (["--no-display"] if command == "stream" else ["-o", str(tmp_path / "o")]))
    assert exc.value.code == 2 and list(tmp_path.iterdir()) == []
    assert capsys.readouterr().err == (
        f"stereovision {command}: error: argument --max-skew-ms: expected milliseconds from 0 "
        f"to 1e+06, got {value!r} (see stereovision {command} --help)\n"
    )


def test_depth_voxel_too_small_for_the_cloud_is_said_as_the_option_and_keeps_the_last_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``depth --calib ... --voxel 1e-300`` said "voxel: 1e-300 is too small for points reaching
    ...": the library's parameter, no unit. The option now, in metres; the folder's earlier
    run is kept."""
    out = tmp_path / "out"
    argv = ["depth", str(CONES / "left.png"), str(CONES / "right.png"), "--calib"]
    argv += [str(CONES / "calib.txt"), "--method", "fast", "-o", str(out)]
    assert main(argv) == 0
    earlier = {p.name: p.read_bytes() for p in out.iterdir()}
    capsys.readouterr()
    assert main([*argv, "--voxel", "1e-300"]) == 2
    err = capsys.readouterr().err
    assert re.fullmatch(
        r"stereovision: error: --voxel: 1e-300 m is too small for points reaching [0-9.]+ m\n", err
    ), err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == earlier


@pytest.mark.parametrize(
    ("square", "unit", "metres"), [("1e12", "mm", "1e+09"), ("1e-300", "m", "1e-300")]
)
def test_calibrate_square_out_of_bounds_is_said_in_the_options(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    square: str,
    unit: str,
    metres: str,
) -> None:
    """``calibrate --square 1e12 --unit mm`` said "square_size: 1e+12 mm is 1e+09 m", the
    library's parameter; the options now, nothing written."""
    boards = data_dir / "chessboard"
    out = tmp_path / "c.yaml"
    argv = ["calibrate", "--left", str(boards / "left0*.jpg"), "--right"]
    argv += [str(boards / "right0*.jpg"), "--square", square, "--unit", unit, "-o", str(out)]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: --square {float(square):g} --unit {unit} is {metres} m; expected "
        "a board square between 1 nm and 100 m\n"
    )
    assert list(tmp_path.iterdir()) == []


def test_view_turns_take_any_finite_degrees() -> None:
    from stereovision.render import _camera_turn

    assert [_camera_turn(v) for v in ("-0", "720", "-1e308", " 5")] == [0.0, 720.0, -1e308, 5.0]


def test_view_camera_move_takes_its_limit() -> None:
    from stereovision.render import _camera_move

    assert [_camera_move(v) for v in ("1e6", "-1e6", "0.5", "-2")] == [1e6, -1e6, 0.5, -2.0]


def test_info_on_paper_says_the_baseline_is_in_metres(capsys: pytest.CaptureFixture[str]) -> None:
    """``info ... --baseline 120`` (meant as mm) was warned about in the library's words: 'are T
    (or the board's square size) in another unit than unit='m'? With unit='mm' it would be
    12.0 cm', none of which the command takes; the warning names --baseline and its metres."""
    argv = ["info", "--size", "1280x720", "--hfov", "90", "--baseline", "120"]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert err.splitlines() == [
        "stereovision: warning: --baseline 120: 120 m is longer than a robot's rig (5 m); "
        "--baseline is in metres (120 mm is --baseline 0.12, 120 cm is --baseline 1.2, "
        "120 in is --baseline 3.048)"
    ]
    assert "baseline 120.00 m (120 m)" in out
    # 12 may be mm, cm or inches: each is named, not the first unit alone (12 mm)
    assert main(["info", "--size", "1280x720", "--hfov", "90", "--baseline", "12"]) == 0
    assert capsys.readouterr().err.splitlines() == [
        "stereovision: warning: --baseline 12: 12 m is longer than a robot's rig (5 m); "
        "--baseline is in metres (12 mm is --baseline 0.012, 12 cm is --baseline 0.12, "
        "12 ft is --baseline 3.6576, 12 in is --baseline 0.3048)"
    ]
    # the hint's range is the warning's (1 mm .. 5 m): a 4 m rig given in mm is named (the
    # hint used 5 mm .. 2 m and named nothing for 4000, though 4 m is taken without a word)
    assert main(["info", "--size", "1280x720", "--hfov", "90", "--baseline", "4000"]) == 0
    assert capsys.readouterr().err.splitlines() == [
        "stereovision: warning: --baseline 4000: 4000 m is longer than a robot's rig (5 m); "
        "--baseline is in metres (4000 mm is --baseline 4)"
    ]


def test_version_and_python_m() -> None:
    """``stereovision --version`` names the package's version; ``python -m stereovision`` is
    the same command line."""
    proc = subprocess.run(
        [sys.executable, "-m", "stereovision", "--version"], capture_output=True, text=True
    )
    from stereovision import __version__

    assert proc.returncode == 0 and proc.stdout.strip() == f"stereovision {__version__}"
    proc = subprocess.run(
        [sys.executable, "-m", "stereovision", "info", "nowhere.yaml"],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1


def test_a_missing_optional_package_is_one_line_with_its_pip_line(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The wheel alone has no trame, rosbags or dask (extras): the command says which to
    install (the GUI and the bag reader gave an 'internal ImportError ... please report')."""
    for mod in ("trame", "trame.app", "rosbags", "rosbags.highlevel", "rosbags.rosbag2"):
        monkeypatch.setitem(sys.modules, mod, None)  # import raises ImportError
    cones = data_dir / "middlebury2003" / "cones"
    assert (
        main(["gui", "--left", str(cones / "left.png"), "--right", str(cones / "right.png")]) == 2
    )
    assert capsys.readouterr().err == (
        "stereovision: error: the GUI needs trame: pip install 'stereovision-rs[gui]'\n"
    )
    (tmp_path / "bag").mkdir()
    (tmp_path / "bag" / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    assert main(["stream", "--from-bag", str(tmp_path / "bag"), "--no-display"]) == 2
    assert capsys.readouterr().err == (  # the pip line of the extra, as for gui and batch
        "stereovision: error: reading ROS bags needs rosbags: pip install 'stereovision-rs[ros]'\n"
    )
    from stereovision.rosbag import BagWriter

    with pytest.raises(ImportError) as info:
        BagWriter(tmp_path / "new_bag")
    assert str(info.value) == "writing ROS 2 bags needs rosbags: pip install 'stereovision-rs[ros]'"


def test_check_plot_refuses_to_overwrite_an_input(
    tmp_path: Path, data_dir: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """``check L R --plot L`` wrote the plot over the left image: refused, one line, exit 2, the
    input unchanged (however the path is spelled); another name is written."""
    cones = data_dir / "middlebury2003" / "cones"
    left, right = tmp_path / "myleft.png", tmp_path / "myright.png"
    left.write_bytes((cones / "left.png").read_bytes())
    right.write_bytes((cones / "right.png").read_bytes())
    before = left.read_bytes(), right.read_bytes()
    (tmp_path / "sub").mkdir()

    def check(plot: Path) -> subprocess.CompletedProcess[str]:
        # in this process (a process start cost a second): its status, fds 1 and 2 (capfd)
        capfd.readouterr()
        status = main(["check", str(left), str(right), "--plot", str(plot)])
        return subprocess.CompletedProcess([], status, *capfd.readouterr())

    for plot, what in [
        (left, "the left image"),
        (tmp_path / "sub" / ".." / "myright.png", "the right image"),
    ]:
        run = check(plot)
        assert run.returncode == 2, run.stderr
        assert run.stderr.startswith(f"stereovision: error: --plot {plot}: is {what} (")
        assert run.stderr.count("\n") == 1 and "give another file name" in run.stderr
    assert (left.read_bytes(), right.read_bytes()) == before
    if hasattr(Path, "symlink_to"):
        (tmp_path / "link.png").symlink_to(left)
        run = check(tmp_path / "link.png")
        assert run.returncode == 2 and "is the left image" in run.stderr
    assert (left.read_bytes(), right.read_bytes()) == before
    run = check(tmp_path / "plot.png")
    assert run.returncode == 0, run.stderr
    assert cv2.imread(str(tmp_path / "plot.png")) is not None


def test_depth_removes_its_own_outputs_of_an_earlier_run(
    tmp_path: Path, crop_terrace: Callable[[slice, slice], Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """A run without a calibration into a folder of a run with one left the earlier cloud.ply,
    depth maps and render there (``stereovision view DIR`` showed the earlier scene): they go;
    the user's own files, and an output name that is a folder, stay."""
    scene = crop_terrace(slice(117, 317), slice(206, 506))  # of eth3d/terrace
    out = tmp_path / "o"
    argv = ["depth", str(scene / "left.png"), str(scene / "right.png"), "--max-disparity", "32"]
    assert main([*argv, "--calib", str(scene / "calib.txt"), "-o", str(out)]) == 0
    for name in ("cloud.ply", "depth.npy", "depth.png", "depth_mm.png", "render.png"):
        assert (out / name).is_file(), name
    (out / "notes.txt").write_text("mine")
    (out / "scan.json").mkdir()  # not a file this tool wrote
    capsys.readouterr()
    assert main([*argv, "-o", str(out)]) == 0
    said = capsys.readouterr().out
    assert sorted(p.name for p in out.iterdir()) == [
        ".stereovision-depth.json",  # what this run wrote: the next one removes only those
        "disparity.pfm",
        "disparity.png",
        "notes.txt",
        "overview.png",
        "scan.json",
    ]
    assert (out / "notes.txt").read_text() == "mine"
    for name in ("cloud.ply", "depth.npy", "depth.png", "depth_mm.png", "render.png"):
        assert f"removed {name} of an earlier run" in said


def test_depth_keeps_same_named_files_it_did_not_write(
    tmp_path: Path, crop_terrace: Callable[[slice, slice], Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """``-o`` naming a folder of the user's: a ``cloud.ply``, ``map.png`` or ``render.png``
    there that no depth run wrote stays (they were deleted as stale outputs by name)."""
    scene = crop_terrace(slice(117, 317), slice(206, 506))  # of eth3d/terrace
    out = tmp_path / "mine"
    out.mkdir()
    own = {"cloud.ply": "my scan", "map.png": "my map", "render.png": "my render"}
    for name, text in own.items():
        (out / name).write_text(text)
    argv = ["depth", str(scene / "left.png"), str(scene / "right.png"), "--max-disparity", "32"]
    assert main([*argv, "-o", str(out)]) == 0
    assert main([*argv, "-o", str(out)]) == 0  # a second run: still not its files
    assert "removed" not in capsys.readouterr().out
    for name, text in own.items():
        assert (out / name).read_text() == text, name


def test_depth_refuses_to_replace_a_file_it_did_not_write(
    tmp_path: Path, crop_terrace: Callable[[slice, slice], Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """``-o`` naming a folder holding the user's own ``cloud.ply`` (or ``disparity.png``): the
    run replaced it silently; it now refuses before the matching, in one line naming the file,
    and writes nothing. Its own earlier outputs (listed in its manifest) are replaced."""
    scene = crop_terrace(slice(117, 317), slice(206, 506))  # of eth3d/terrace
    out = tmp_path / "mine"
    out.mkdir()
    (out / "cloud.ply").write_text("my scan")
    argv = ["depth", str(scene / "left.png"), str(scene / "right.png"), "--max-disparity", "32"]
    argv += ["--calib", str(scene / "calib.txt"), "-o", str(out)]
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == _not_ours(out, "cloud.ply")
    assert (out / "cloud.ply").read_text() == "my scan"
    assert sorted(p.name for p in out.iterdir()) == ["cloud.ply"]  # refused before any work
    (out / "cloud.ply").unlink()
    assert main(argv) == 0
    first = (out / "cloud.ply").stat().st_mtime_ns
    assert main(argv) == 0  # its own folder again: its files are replaced
    assert (out / "cloud.ply").stat().st_mtime_ns >= first
    assert "cloud.ply" in json.loads((out / ".stereovision-depth.json").read_text())


def test_demo_keeps_a_file_it_did_not_write(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``demo -o DIR`` overwrote the user's disparity.png in DIR and wrote no manifest: the file
    is copied aside as disparity.previous.png (said), not refused, so ``make demo`` still runs
    into a demo_output of a version before the manifest; it records what it wrote, and a rerun
    into its own folder replaces its files without copies. A folder under an output name is
    refused up front."""
    out = tmp_path / "d"
    out.mkdir()
    (out / "disparity.png").write_text("my disparity")
    capsys.readouterr()
    assert main(["demo", "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    kept = out / "disparity.previous.png"
    assert (
        lines[-1]
        == f"  the disparity.png that was there (no earlier run's output) is kept as {kept}"
    )
    assert kept.read_text() == "my disparity"
    assert cv2.imread(str(out / "disparity.png")) is not None
    listed = json.loads((out / ".stereovision-depth.json").read_text())
    names = ["cloud.ply", "depth.npy", "depth.png", "depth_mm.png", "disparity.pfm"]
    assert listed == [*names, "disparity.png", "overview.png", "render.png"]
    assert main(["demo", "-o", str(out)]) == 0  # again: its own files, no copy
    assert "kept as" not in capsys.readouterr().out
    assert sorted(p.name for p in out.glob("*.previous*")) == ["disparity.previous.png"]
    other = tmp_path / "e"
    (other / "cloud.ply").mkdir(parents=True)
    assert main(["demo", "-o", str(other)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""  # before any work
    assert captured.err == _not_ours(other, "cloud.ply")


def test_demo_keeps_no_copy_of_a_file_holding_the_bytes_it_writes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A file demo did not list but that holds the very bytes it writes (the outputs of a demo
    before the manifest) was still copied aside as NAME.previous.EXT and said so: the rule is a
    copy unless the bytes are equal. One that differs in its line endings alone (LF -> CRLF) is
    another file: kept byte for byte, said."""
    first = tmp_path / "first"
    assert main(["demo", "--method", "fast", "-o", str(first)]) == 0
    out = tmp_path / "d"
    out.mkdir()
    shutil.copy(first / "disparity.png", out / "disparity.png")
    crlf = (first / "disparity.pfm").read_bytes().replace(b"\n", b"\r\n")
    (out / "disparity.pfm").write_bytes(crlf)
    capsys.readouterr()
    assert main(["demo", "--method", "fast", "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    kept = out / "disparity.previous.pfm"
    assert lines[-1] == (
        f"  the disparity.pfm that was there (no earlier run's output) is kept as {kept}"
    )
    assert not any("disparity.png that was there" in line for line in lines)
    assert sorted(p.name for p in out.glob("*.previous*")) == ["disparity.previous.pfm"]
    assert kept.read_bytes() == crlf
    for name in ("disparity.png", "disparity.pfm"):
        assert (out / name).read_bytes() == (first / name).read_bytes()


def test_demo_runs_on_when_a_file_it_would_keep_aside_went_meanwhile(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """demo compares a file under an output name that no run listed with its staged output
    after the matching: one removed meanwhile (moved away by its owner while the scene was
    matched) failed the whole run there, "[Errno 2] No such file or directory", every output
    lost. Nothing is left to keep: the run writes its outputs and keeps no copy."""
    import stereovision.depth as depth_mod

    out = tmp_path / "d"
    out.mkdir()
    (out / "disparity.pfm").write_bytes(b"mine")
    real = depth_mod.depth_map

    def moved_away_meanwhile(*args: object, **kwargs: object) -> object:
        (out / "disparity.pfm").rename(tmp_path / "moved.pfm")
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(depth_mod, "depth_map", moved_away_meanwhile)
    assert main(["demo", "--method", "fast", "-o", str(out)]) == 0
    said = capsys.readouterr()
    assert said.err == "" and "that was there" not in said.out
    assert (tmp_path / "moved.pfm").read_bytes() == b"mine"
    assert not list(out.glob("*.previous*"))
    assert read_pfm(out / "disparity.pfm").shape == (375, 450)


def test_demo_interrupted_midway_leaves_the_earlier_outputs_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C while ``demo -o DIR`` writes into the folder of an earlier demo (here: another
    method): its new disparity and depth files stood beside the earlier overview.png. The files
    are moved in together at the end: the earlier set stays byte for byte, and no temporary
    folder is left."""
    from stereovision import cli

    out = tmp_path / "d"
    assert main(["demo", "--method", "fast", "-o", str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "write_overview", interrupted)
    capsys.readouterr()
    assert main(["demo", "-o", str(out)]) == 130
    assert capsys.readouterr().err == "stereovision: interrupted\n"
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


@pytest.mark.parametrize("target", ["on_a_drive_not_mounted.ply", "mine.ply"])
def test_demo_refuses_a_link_under_an_output_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], target: str
) -> None:
    """A link under an output name is refused by demo as by depth, but a link whose target is
    gone (exists() False) was neither copied aside nor refused: the run replaced it silently.
    It is refused up front now, in depth's line; a link to a file of the user's too (not
    replaced by the run's file, its target copied aside)."""
    out = tmp_path / "d"
    out.mkdir()
    (tmp_path / "mine.ply").write_bytes(b"mine")
    (out / "cloud.ply").symlink_to(tmp_path / target)
    assert main(["demo", "-o", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""  # before any work
    assert captured.err == _not_ours(out, "cloud.ply")
    assert (out / "cloud.ply").is_symlink()
    assert sorted(p.name for p in out.iterdir()) == ["cloud.ply"]


def test_depth_refuses_a_link_put_under_an_output_name_an_earlier_run_wrote(
    tmp_path: Path, data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An earlier run's disparity.png that the user replaced by a link to a file of theirs: a
    rerun replaced the link with its own file, unsaid (a run that does not write the name keeps
    such a link: commit_outputs). Refused before any work, as a link the manifest does not list."""
    src = data_dir / "middlebury2001" / "tsukuba"
    for side in ("left", "right"):
        cv2.imwrite(
            str(tmp_path / f"{side}.png"), cv2.imread(str(src / f"{side}.png"))[100:164, 150:246]
        )
    out = tmp_path / "out"
    argv = ["depth", str(tmp_path / "left.png"), str(tmp_path / "right.png"), "-o", str(out),
            "--max-disparity", "16", "--method", "fast"]  # fmt: skip
    assert main(argv) == 0
    mine = tmp_path / "mine.png"
    mine.write_bytes(b"mine")
    (out / "disparity.png").unlink()
    (out / "disparity.png").symlink_to(mine)
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    capsys.readouterr()
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        f"stereovision: error: -o {out}: {out / 'disparity.png'} is a link, not the file an "
        "earlier run wrote there, and would be replaced: give another -o folder, or move or "
        "remove that file\n"
    )
    assert (out / "disparity.png").is_symlink() and mine.read_bytes() == b"mine"
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before


def test_a_12_bit_pair_gets_one_warning_line_per_image(
    tmp_path: Path, data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A 12-bit pair in 16-bit PNGs printed four warning lines, two per image (the 8-bit copy's
    and the grey image's conversions each warned)."""
    src = data_dir / "middlebury2001" / "tsukuba"
    for side in ("left", "right"):
        crop = cv2.imread(str(src / f"{side}.png"))[100:164, 150:246]
        cv2.imwrite(str(tmp_path / f"{side}.png"), crop.astype(np.uint16) * 16)
    argv = ["depth", str(tmp_path / "left.png"), str(tmp_path / "right.png")]
    argv += ["-o", str(tmp_path / "out"), "--max-disparity", "16", "--method", "fast"]
    proc = _in_process(argv, capsys)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert [line.split(":")[2] for line in lines] == [" left", " right"], proc.stderr
    # the advice fits the command line: it gave Python's (img << 4, img.astype(np.uint8))
    cli = "save it scaled to the full 16-bit range first (12-bit data shifted left by 4 bits)"
    assert all(cli in line for line in lines), lines
    assert "<<" not in proc.stderr and "astype" not in proc.stderr, proc.stderr


def test_eval_treats_a_gt_without_known_pixels_as_no_gt(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A gt_disp.pfm that is all +inf (unknown) was evaluated: every figure NaN, printed as
    ``NaN`` in the --json line (not JSON) and as ``nan`` in the table's mean; exit 0."""
    import json
    import shutil

    from stereovision.io import write_pfm

    good = tmp_path / "a_tsukuba"
    shutil.copytree(data_dir / "middlebury2001" / "tsukuba", good)
    blank = tmp_path / "b_blank"
    shutil.copytree(good, blank)
    gt = read_pfm(blank / "gt_disp.pfm")
    write_pfm(blank / "gt_disp.pfm", np.full_like(gt, np.inf))
    argv = ["eval", "--json", "--no-opencv", "--method", "fast"]
    # in process (main returns the exit status): a new Python each costs ~1.2 s CPU
    proc = subprocess.CompletedProcess(argv, main([*argv, str(tmp_path)]), *capsys.readouterr())
    assert proc.returncode == 0, proc.stderr
    rows = [json.loads(ln, parse_constant=_no_constant) for ln in proc.stdout.splitlines()]
    assert [Path(r["scene"]).name for r in rows] == ["a_tsukuba"]
    assert proc.stderr.strip() == (
        f"skipped {blank}: no ground truth: gt_disp.pfm has no known (finite) pixel"
    )
    alone = subprocess.CompletedProcess(argv, main([*argv, str(blank)]), *capsys.readouterr())
    assert alone.returncode == 2 and alone.stdout == "", alone.stdout
    assert alone.stderr.strip() == (
        f"stereovision: error: {blank}: no ground truth: gt_disp.pfm has no known (finite) "
        "pixel to evaluate against"
    )


def test_eval_json_lines_are_strict_json() -> None:
    """Figures with nothing to measure (no pixel with both depths) are NaN: null in JSON."""
    import json

    from stereovision._jsonout import json_line
    from stereovision.evaluate import depth_metrics

    row = {"depth": depth_metrics(np.full((2, 2), np.nan), np.ones((2, 2))).as_dict(), "x": [1.5]}
    back = json.loads(json_line(row))
    assert back == {"depth": {"median_rel": None, "share_off_5": None, "rmse_pct": None,
                              "rmse": None, "n": 0, "density": 0.0}, "x": [1.5]}  # fmt: skip


def test_json_line_converts_numpy_scalars_and_0d_arrays() -> None:
    """NumPy integers and bools (a count from ``np.count_nonzero``, a mask's ``.any()``) were
    passed through as they were and json.dumps raised TypeError; NumPy scalars and 0-d arrays
    are written as JSON numbers, booleans and null (a NaN)."""
    import json

    from stereovision._jsonout import json_line, json_ready

    row = {
        "i64": np.int64(7),
        "i32": np.int32(-3),
        "u8": np.uint8(255),
        "yes": np.bool_(True),
        "no": np.bool_(False),
        "f32": np.float32(0.5),
        "nan": np.float64("nan"),
        "inf": np.float32("inf"),
        "a0_int": np.array(4),
        "a0_float": np.array(2.25),
        "a0_nan": np.array(np.nan),
        "a0_bool": np.array(True),
        "nested": [(np.int64(1), np.bool_(False))],
    }
    assert json.loads(json_line(row)) == {
        "i64": 7, "i32": -3, "u8": 255, "yes": True, "no": False, "f32": 0.5, "nan": None,
        "inf": None, "a0_int": 4, "a0_float": 2.25, "a0_nan": None, "a0_bool": True,
        "nested": [[1, False]],
    }  # fmt: skip
    ready = json_ready(row)
    kinds = [type(ready[k]).__name__ for k in ("i64", "yes", "f32", "a0_int", "a0_bool")]
    assert kinds == ["int", "bool", "float", "int", "bool"]


def test_json_line_writes_arrays_paths_and_numpy_keys_nested() -> None:
    """A NumPy array of one or more dimensions (a point, a matrix, a histogram) or a path
    inside a row, at any depth, made json.dumps raise TypeError ("Object of type ndarray is
    not JSON serializable"); arrays are written as (nested) lists, their NaN and inf as null,
    paths as strings, NumPy dict keys as their values."""
    import json
    from pathlib import Path, PurePosixPath

    from stereovision._jsonout import json_line, json_ready

    row = {
        "point": np.array([1.5, np.nan, -np.inf], dtype=np.float32),
        "K": np.array([[500, 0, 320], [0, 500, 240], [0, 0, 1]], dtype=np.int64),
        "mask": np.array([True, False]),
        "empty": np.zeros((0, 3)),
        "nested": {
            "pairs": [(np.float64(2.0), np.array([np.int16(3), np.int16(4)]))],
            "deep": ({"h": np.array([[np.nan], [0.25]])},),
            "objs": np.array([Path("a/b.png"), np.float64("nan")], dtype=object),
        },
        "where": PurePosixPath("/data/scene/left.png"),
        np.int64(5): "numpy key",
        np.str_("s"): np.str_("text"),
    }
    back = json.loads(json_line(row))
    assert back == {
        "point": [1.5, None, None],
        "K": [[500, 0, 320], [0, 500, 240], [0, 0, 1]],
        "mask": [True, False],
        "empty": [],
        "nested": {
            "pairs": [[2.0, [3, 4]]],
            "deep": [{"h": [[None], [0.25]]}],
            "objs": ["a/b.png", None],
        },
        "where": "/data/scene/left.png",
        "5": "numpy key",
        "s": "text",
    }
    ready = json_ready(row)
    assert [type(v).__name__ for v in ready["K"][0]] == ["int", "int", "int"]
    assert type(ready["mask"][0]) is bool and type(ready["point"][0]) is float
    assert json_ready(np.array([[1, 2]]).T) == [[1], [2]]


def test_eval_with_no_scene_to_evaluate_fails(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two scenes without ground truth: both skipped, nothing evaluated, and the exit status
    was 0 (an empty table)."""
    for name in ("a", "b"):
        (tmp_path / name).mkdir()
        for side in ("left", "right"):
            src = data_dir / "stereopi_rig" / "scene_photo" / f"{side}.png"
            (tmp_path / name / f"{side}.png").write_bytes(src.read_bytes())
    proc = _in_process(["eval", str(tmp_path)], capsys)
    assert proc.returncode == 2, proc.stderr
    err = proc.stderr.strip().splitlines()
    assert err[:2] == [f"skipped {tmp_path / n}: no ground truth (gt_disp.pfm)" for n in "ab"]
    assert err[2:] == [
        "stereovision: error: none of the 2 scenes has ground truth to evaluate against"
    ]


def _not_ours(out: Path, name: str) -> str:
    """The CLI's line refusing to replace ``out / name``, which no earlier run listed."""
    return (
        f"stereovision: error: -o {out}: {out / name} is not listed as an earlier run's output "
        "there and would be replaced: give another -o folder, or move or remove that file\n"
    )


def _no_constant(name: str) -> float:
    raise ValueError(f"not JSON: {name}")


def test_rectify_with_calib_removes_an_earlier_runs_homographies(
    crop_terrace: Callable[[slice, slice], Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """rectify without --calib, then with it into the same folder: the first run's
    rectification.json stayed beside the new images, and `depth --rectification` would warp
    the calibrated pair by the earlier homographies. A file of that name not ours stays."""
    scene = crop_terrace(slice(117, 317), slice(206, 506))  # of eth3d/terrace
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    out = tmp_path / "rect"
    # terrace is rectified already: --force has its homographies found all the same
    assert main(["rectify", *pair, "--force", "-o", str(out)]) == 0
    assert (out / "rectification.json").is_file()
    capsys.readouterr()
    assert main(["rectify", *pair, "--calib", str(scene / "calib.txt"), "-o", str(out)]) == 0
    assert not (out / "rectification.json").exists()
    said = capsys.readouterr().out.splitlines()
    assert said[-1] == (
        "  removed rectification.json of an earlier run (its homographies do not fit the images "
        "written now: rectified by --calib)"
    )
    (out / "rectification.json").write_text('{"mine": 1}')
    assert main(["rectify", *pair, "--calib", str(scene / "calib.txt"), "-o", str(out)]) == 0
    assert (out / "rectification.json").read_text() == '{"mine": 1}'


@pytest.mark.parametrize("exc", [OSError("disk full"), KeyboardInterrupt()])
def test_rectify_failing_midway_leaves_the_earlier_outputs_whole(
    crop_terrace: Callable[[slice, slice], Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    exc: BaseException,
) -> None:
    """rectify --calib into the folder of a --force run, failing (or interrupted) at
    check.png: the new left_rect.png and right_rect.png stood beside the earlier check.png and
    rectification.json (whose homographies do not fit them). The files are moved in together
    at the end: the earlier set stays byte for byte, and no temporary folder is left."""
    from stereovision import cli

    scene = crop_terrace(slice(117, 317), slice(206, 506))  # of eth3d/terrace
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    out = tmp_path / "rect"
    assert main(["rectify", *pair, "--force", "-o", str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    assert "rectification.json" in before
    real = cli._atomic_write_bytes

    def fails_at_check(path: Path, data: bytes) -> None:
        if path.name == "check.png":
            raise exc
        real(path, data)

    monkeypatch.setattr(cli, "_atomic_write_bytes", fails_at_check)
    status = 2 if isinstance(exc, OSError) else 130
    assert main(["rectify", *pair, "--calib", str(scene / "calib.txt"), "-o", str(out)]) == status
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_rectify_with_calib_keeps_homographies_it_did_not_write(
    crop_terrace: Callable[[slice, slice], Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A rectification.json of the user's (homographies found elsewhere, copied in) in the -o
    folder of a run with --calib was deleted as an earlier run's, though the manifest did not
    list it: it is kept now, and the line says its homographies do not fit the images."""
    scene = crop_terrace(slice(117, 317), slice(206, 506))  # of eth3d/terrace
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    elsewhere = tmp_path / "elsewhere"
    assert main(["rectify", *pair, "--force", "-o", str(elsewhere)]) == 0
    mine = (elsewhere / "rectification.json").read_bytes()
    out = tmp_path / "rect"
    out.mkdir()
    (out / "rectification.json").write_bytes(mine)
    capsys.readouterr()
    assert main(["rectify", *pair, "--calib", str(scene / "calib.txt"), "-o", str(out)]) == 0
    assert (out / "rectification.json").read_bytes() == mine
    assert capsys.readouterr().out.splitlines()[-1] == (
        f"  kept {out / 'rectification.json'} (not listed as an earlier run's output there), "
        "but its homographies do not fit the images written now (rectified by --calib): do not "
        "give it to depth --rectification with them"
    )
    assert "rectification.json" not in json.loads((out / ".stereovision-rectify.json").read_text())


def test_rectify_refuses_to_replace_a_file_it_did_not_write(
    crop_terrace: Callable[[slice, slice], Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``rectify -o DIR`` replaced the user's own left_rect.png (or, without --calib, their
    rectification.json) silently: refused before any work, one line naming it; the command's
    own earlier outputs (its manifest's) are replaced by a rerun."""
    scene = crop_terrace(slice(117, 317), slice(206, 506))  # of eth3d/terrace
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    calib = ["--calib", str(scene / "calib.txt")]
    out = tmp_path / "rect"
    out.mkdir()
    for name, argv in (("left_rect.png", calib), ("rectification.json", ["--force"])):
        (out / name).write_text("mine")
        capsys.readouterr()
        assert main(["rectify", *pair, *argv, "-o", str(out)]) == 2
        assert capsys.readouterr().err == _not_ours(out, name)
        assert sorted(p.name for p in out.iterdir()) == [name]  # nothing written
        assert (out / name).read_text() == "mine"
        (out / name).unlink()
    assert main(["rectify", *pair, "--force", "-o", str(out)]) == 0
    assert json.loads((out / ".stereovision-rectify.json").read_text()) == [
        "check.png",
        "left_rect.png",
        "rectification.json",
        "right_rect.png",
    ]
    assert main(["rectify", *pair, *calib, "-o", str(out)]) == 0  # its own files: replaced
    assert not (out / "rectification.json").exists()
    assert main(["rectify", *pair, "--force", "-o", str(out)]) == 0
    assert (out / "rectification.json").is_file()


def test_rectify_writes_a_rectified_pair_as_given(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`rectify` without --calib of a pair already rectified (cones) warped it by homographies
    fitted to rows that already agreed: resampled, and 455x378 px instead of 450x375. It is
    now written as given, said in one line; --force rectifies it from its features anyway."""
    scene = data_dir / "middlebury2003" / "cones"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    out = tmp_path / "rect"
    assert main(["rectify", *pair, "-o", str(out)]) == 0
    said = capsys.readouterr().out.splitlines()
    assert said[0].startswith("already rectified (rows median |dy| 0.")
    assert said[0].endswith(
        "tolerance 0.5): written as given, not warped (--force rectifies it from its features "
        "anyway)"
    )
    assert [line.split()[0] for line in said[1:]] == ["left_rect.png", "right_rect.png",
                                                     "check.png"]  # fmt: skip
    for side in ("left", "right"):
        np.testing.assert_array_equal(
            cv2.imread(str(out / f"{side}_rect.png")), cv2.imread(str(scene / f"{side}.png"))
        )
    assert not (out / "rectification.json").exists()
    assert main(["rectify", *pair, "--force", "-o", str(out)]) == 0
    assert capsys.readouterr().out.startswith("rectified without a calibration")
    assert (out / "rectification.json").is_file()
    assert cv2.imread(str(out / "left_rect.png")).shape != cv2.imread(pair[0]).shape
    # the forced run's homographies were this pair's (the line said 'not this pair's'), but
    # they do not fit the pair written as given now: removed, and said so
    assert main(["rectify", *pair, "-o", str(out)]) == 0
    assert not (out / "rectification.json").exists()
    assert capsys.readouterr().out.splitlines()[-1] == (
        "  removed rectification.json of an earlier run (its homographies do not fit the images "
        "written now: the pair as given)"
    )
    # an explicit --model on a pair written as given was dropped without a word: now named
    assert main(["rectify", *pair, "--model", "projective", "-o", str(out)]) == 0
    assert (
        capsys.readouterr()
        .out.splitlines()[0]
        .endswith(
            "tolerance 0.5): written as given, not warped, --model projective not used (--force "
            "rectifies it from its features anyway)"
        )
    )
    terrace = data_dir / "eth3d" / "terrace"
    calib = ["--calib", str(terrace / "calib.txt")]
    tp = [str(terrace / "left.png"), str(terrace / "right.png")]
    assert main(["rectify", *tp, *calib, "--force", "-o", str(tmp_path / "c")]) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: --force is for rectifying without a calibration (no --calib)\n"
    )


def test_eval_counts_a_scene_given_twice_once(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`eval middlebury2001 middlebury2001/tsukuba` evaluated tsukuba twice, and the mean
    line counted it twice (2.5 % for fast instead of the two scenes' 2.0 %)."""
    import json

    both = [str(data_dir / "middlebury2001"), str(data_dir / "middlebury2001" / "tsukuba")]
    proc = _in_process(["eval", *both, "--json", "--no-opencv", "--method", "fast"], capsys)
    assert proc.returncode == 0, proc.stderr
    rows = [json.loads(line) for line in proc.stdout.splitlines()]
    assert [r["scene"] for r in rows] == ["middlebury2001/tsukuba", "middlebury2001/venus"]
    tsukuba = data_dir / "middlebury2001" / "tsukuba"
    assert proc.stderr == f"stereovision: {tsukuba} given more than once: evaluated once\n"


def test_eval_says_which_folders_it_skipped_and_skips_hidden_ones(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A folder with left.png and no right.png among scenes was dropped without a word, and a
    hidden copy of a scene (.Trash) was evaluated a second time."""
    import json

    tsukuba = data_dir / "middlebury2001" / "tsukuba"
    shutil.copytree(tsukuba, tmp_path / "tsukuba")
    shutil.copytree(tsukuba, tmp_path / ".Trash" / "tsukuba")
    (tmp_path / "half").mkdir()
    shutil.copy(tsukuba / "left.png", tmp_path / "half" / "left.png")
    assert main(["eval", str(tmp_path), "--json", "--no-opencv", "--method", "fast"]) == 0
    cap = capsys.readouterr()
    assert len([json.loads(line) for line in cap.out.splitlines()]) == 1
    assert cap.err == (
        f"stereovision: skipped {tmp_path / 'half'}: has left.png but no right.png"
        " (a scene folder holds both)\n"
    )


def test_rectify_refuses_to_overwrite_its_input_images(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`rectify rect/left_rect.png rect/right_rect.png -o rect` wrote its outputs over the
    images it was given, without a word."""
    scene = data_dir / "stereopi_rig" / "scene_photo"
    rect = tmp_path / "rect"
    rect.mkdir()
    for side in ("left", "right"):
        (rect / f"{side}_rect.png").write_bytes((scene / f"{side}.png").read_bytes())
    before = (rect / "left_rect.png").read_bytes()
    pair = [str(rect / "left_rect.png"), str(rect / "right_rect.png")]
    proc = _in_process(["rectify", *pair, "-o", str(rect)], capsys)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr == (
        f"stereovision: error: -o {rect / 'left_rect.png'}: is the left image "
        f"({rect / 'left_rect.png'}); give another file name\n"
    )
    assert (rect / "left_rect.png").read_bytes() == before
    assert sorted(p.name for p in rect.iterdir()) == ["left_rect.png", "right_rect.png"]


def test_eval_of_an_image_file_says_it_is_a_file(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`eval scene/left.png` said 'scene root not found' of a file that exists."""
    img = data_dir / "middlebury2001" / "tsukuba" / "left.png"
    proc = _in_process(["eval", str(img)], capsys)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr == (
        f"stereovision: error: {img}: is a file; give a scene folder (holding left.png, "
        "right.png)\n"
    )


@pytest.mark.parametrize("command", ["eval", "bench"])
def test_eval_and_bench_of_a_device_say_it_is_no_folder(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """`eval /dev/null` (or a pipe) said "is a file" of what is no file; load_scene's words
    (aae87eaf) say what it is."""
    assert main([command, "/dev/null"]) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: /dev/null: is not a folder (a device or a pipe); give a scene "
        "folder (holding left.png, right.png)\n"
    )


def test_info_on_a_scene_folder_reads_its_calibration(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A scene folder said "folder without left.yaml and right.yaml": its calib.txt (else its
    Q.dat, sized by its left.png) is the rig's calibration."""
    assert main(["info", str(data_dir / "eth3d" / "playground")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("941x490 px, rectified pair: baseline 6.0 cm (59.5549 mm)")
    assert main(["info", str(data_dir / "middeval3" / "teddyH")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("900x750 px, rectified pair: baseline 8.0 cm (0.08 m), focal length")
    assert main(["info", str(data_dir / "chessboard")]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: calibration path {data_dir / 'chessboard'} is a folder without "
        "left.yaml and right.yaml (ROS camera_info), intrinsics.yml and extrinsics.yml (OpenCV "
        "stereo_calib output), calib.txt or Q.dat; pass a calibration file\n"
    )


def test_info_says_the_size_it_gives_a_q_dat_sets_the_field_of_view(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``info Q.dat --size 100x100`` (a Q.dat of TartanAir's 640x480 rig, 90 degrees across)
    said "field of view 10.5 x 13.2 degrees" without a word: a Q.dat holds no size, the field
    of view is --size's. Now said, and a principal point outside the size given is named."""
    q = tmp_path / "Q.dat"
    q.write_text("1 0 0 -320\n0 1 0 -240\n0 0 0 320\n0 0 4 0\n")
    assert main(["info", str(q), "--size", "100x100"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == "field of view 10.5 x 13.2 degrees"
    assert lines[-1] == (
        "image size 100x100 from --size (the file holds none): the field of view is for it; the "
        "principal point (320.0, 240.0) px lies outside a 100x100 image: is it the rig's image "
        "size?"
    )
    assert main(["info", str(q), "--size", "640x480"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == "field of view 90.0 x 73.7 degrees"
    assert (
        lines[-1]
        == "image size 640x480 from --size (the file holds none): the field of view is for it"
    )


def test_info_says_the_size_it_gives_a_q_dat_sized_by_a_left_png(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The note above was left out for a Q.dat with its left.png beside it (a scene folder):
    ``info scene --size 100x100`` said "field of view 10.5 x 13.2 degrees" for the 640x480
    left.png's 90-degree cameras, --size taken over the image unsaid. Now said, the image
    named; without --size the left.png sizes it, as before."""
    (tmp_path / "Q.dat").write_text("1 0 0 -320\n0 1 0 -240\n0 0 0 320\n0 0 4 0\n")
    cv2.imwrite(str(tmp_path / "left.png"), np.zeros((480, 640), np.uint8))
    assert main(["info", str(tmp_path), "--size", "100x100"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == "field of view 10.5 x 13.2 degrees"
    assert lines[-1].startswith(
        "image size 100x100 from --size (the file holds none; left.png beside it not read): "
        "the field of view is for it; the principal point (320.0, 240.0) px lies outside"
    )
    assert main(["info", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == "field of view 90.0 x 73.7 degrees"
    assert not any(line.startswith("image size") for line in lines)


def test_info_on_an_image_list_says_it_is_not_a_calibration(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """OpenCV's stereo_calib.xml lists the chessboard pairs: info said it "lacks field
    'image_width'"; it now says what the file is and how to get a calibration from it."""
    xml = data_dir / "chessboard" / "stereo_calib.xml"
    assert main(["info", str(xml)]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {xml} is not a calibration but a list of images (26 file names "
        "under 'imagelist'): calibrate the rig from those images with `stereovision calibrate "
        "--left ... --right ... --square SIZE -o calib.yaml`\n"
    )
    other = tmp_path / "other.yaml"
    other.write_text("%YAML:1.0\n---\nframe_count: 3\nfps: 30.\n")
    assert main(["info", str(other)]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {other} is not a calibration: it has none of the fields "
        "image_width, K1, K2, R, T (it holds: frame_count, fps)\n"
    )


def test_check_warns_of_one_file_given_twice(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check LEFT LEFT`` said "rectification ok" without a word about the pair being one
    file. It warns, and the verdict cannot tell (exit 3), not "rectification ok" (exit 0). The
    warning said "every disparity comes out 0" of a command that finds none: said of the rows."""
    left = data_dir / "middlebury2003" / "cones" / "left.png"
    assert main(["check", str(left), str(left)]) == 3
    out, err = capsys.readouterr()
    assert out.startswith("rectification: cannot tell, the two images are identical")
    assert err == (
        f"stereovision: warning: {left} and {left} are the same file: their rows agree by "
        "themselves (two views of the scene are needed)\n"
    )


def test_depth_takes_a_q_dat_apart_from_its_scene_sized_by_the_pair(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--calib Q.dat (4951e4c) was sized only by a left.png beside it: a Q.dat kept elsewhere
    was refused ('does not give the image size and there is no left.png beside it') though
    the pair given with it has a size. It is sized by the pair; beside a left.png, by that."""
    from stereovision.calibration import Calibration
    from stereovision.depth import depth_map
    from stereovision.io import load_scene

    teddy = data_dir / "middeval3" / "teddyH"
    q = tmp_path / "rig" / "Q.dat"
    q.parent.mkdir()
    q.write_bytes((teddy / "Q.dat").read_bytes())
    pair = [str(teddy / "left.png"), str(teddy / "right.png")]
    out = tmp_path / "out"
    args = ["--calib", str(q), "--method", "fast", "--max-disparity", "64", "-o", str(out)]
    assert main(["depth", *pair, *args]) == 0
    scene = load_scene(teddy)
    ref = depth_map(scene.left, scene.right, scene.calib, method="fast", max_disparity=64)
    assert ref.depth is not None
    np.testing.assert_array_equal(np.load(out / "depth.npy"), ref.depth)
    # info has no pair: still refused, in one line, which names its --size (it named none,
    # where the same refusal of stereo_calib output and of a KITTI file did); Python's call
    # names image_size=
    assert main(["info", str(q)]) == 2
    refused = "Q.dat does not give the image size and there is no left.png beside it"
    assert capsys.readouterr().err.strip().endswith(f"{refused}: pass --size WxH")
    with pytest.raises(ValueError, match=r"beside it: pass image_size=\(width, height\)$"):
        Calibration.from_file(q)
    assert main(["info", str(q), "--size", "900x750"]) == 0
    assert "900x750 px, rectified pair" in capsys.readouterr().out
    # a left.png beside the Q.dat still sizes it (a half-size pair is refused with the hint)
    half = cv2.resize(cv2.imread(pair[0]), None, fx=0.5, fy=0.5)
    cv2.imwrite(str(q.parent / "left.png"), cv2.imread(pair[0]))
    assert Calibration.from_file(q).image_size == (900, 750)
    small = [str(tmp_path / "l.png"), str(tmp_path / "r.png")]
    cv2.imwrite(small[0], half)
    cv2.imwrite(small[1], half)
    assert main(["depth", *small, *args]) == 2
    assert "calibration is for 900x750 images, got 450x375" in capsys.readouterr().err


def test_ctrl_c_while_the_commands_load_is_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C in the first second of `stereovision stream ...`, while the parser imports the
    commands' modules (0.2 s), printed a traceback of that import (measured: a SIGINT 0.7 s
    after the start); it is one line and status 130, as during the command."""
    from stereovision import cli

    def interrupted() -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "build_parser", interrupted)
    assert cli.main(["stream", "--left", "0", "--right", "1"]) == 130
    assert capsys.readouterr().err == "stereovision: interrupted\n"


def test_demo_checks_its_output_folder_first(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`demo -o FILE` matched and evaluated the scene (its figures printed) before it found
    the file in the way; now one line first, nothing computed."""
    (tmp_path / "notes").write_text("mine")
    assert main(["demo", "-o", str(tmp_path / "notes")]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == f"stereovision: error: -o {tmp_path / 'notes'}: is a file, not a folder\n"
    assert (tmp_path / "notes").read_text() == "mine"


@pytest.mark.parametrize(
    ("extra", "says"),
    [
        (["--max-depth", "-1"], "--max-depth: expected a number of metres above 0, got '-1'"),
        (["--voxel", "0"], "--voxel: expected a number of metres above 0, got '0'"),
        (["--grid", "0.1"], "--grid needs --ground"),
        (["--ground", "--grid", "11"], "--grid: expected a cell side from 0.01 to 10 m, got 11.0"),
        # a range as wide as the image is refused too (terrace: 713 px)
        (["--max-disparity", "713"], "disparity range 713 is not smaller than the image width 713"),
        (["--max-disparity", "5000"], "disparity range 5000 is not smaller than the image width"),
        (["--right", "tsukuba"], "left is 713x434 px, right is 384x288 px: the two images of"),
        (["--calib", "tsukuba"], "calibration is for 713x434 images, got 384x288"),
        # --max-sigma alone was told "--max-depth and --max-sigma need --calib"
        (["--no-calib", "--max-sigma", "0.1"], "error: --max-sigma needs --calib (no depth"),
        # accepted with no effect (no depth, no cloud) before
        (["--no-calib", "--unit", "ft"], "--unit needs --calib (no depth to say in it without"),
        (["--no-calib", "--voxel", "0.1"], "--voxel needs --calib (no cloud.ply without one)"),
        (["--no-calib", "--ground"], "--ground needs --calib (the floor is found in metres)"),
    ],
)
def test_depth_says_a_usage_error_before_a_file_it_did_not_write(
    tmp_path: Path,
    data_dir: Path,
    capsys: pytest.CaptureFixture[str],
    extra: list[str],
    says: str,
) -> None:
    """A usage error that needs no work is said first (it was hidden behind the refusal of a
    user's file under an output name, and said only once that file was moved), then that
    file, then the work."""
    terrace, tsukuba = data_dir / "eth3d" / "terrace", data_dir / "middlebury2001" / "tsukuba"
    left, right, calib = terrace / "left.png", terrace / "right.png", terrace / "calib.txt"
    if extra[:2] == ["--right", "tsukuba"]:
        right, extra = tsukuba / "right.png", extra[2:]
    elif extra[:2] == ["--calib", "tsukuba"]:
        left, right, extra = tsukuba / "left.png", tsukuba / "right.png", extra[2:]
    argv = ["depth", str(left), str(right), "-o", str(tmp_path / "o"), *extra]
    if extra[:1] == ["--no-calib"]:
        argv.remove("--no-calib")
    else:
        argv += ["--calib", str(calib)]
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "disparity.png").write_bytes(b"mine")
    capsys.readouterr()
    try:
        status = main(argv)
    except SystemExit as exit_:  # an option's value refused by argparse, in the option's name
        status = exit_.code
    assert status == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("stereovision") and says in err, err
    assert (tmp_path / "o" / "disparity.png").read_bytes() == b"mine"


def test_calib_unit_reads_opencv_stereo_calib_output(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """OpenCV stereo_calib's intrinsics.yml + extrinsics.yml hold no unit of T and no image
    size: every command refused them with "pass image_size=(width, height) and unit='m'/'mm'/...",
    a Python call no option of the CLI could make. --calib-unit says the unit, the run's images
    the size (info: --size)."""
    from test_calibration import _opencv_stereo_calib

    rig = tmp_path / "rig"
    rig.mkdir()
    _opencv_stereo_calib(rig)  # T (-120, 1.5, 0.8) mm, 640x480
    assert main(["info", str(rig)]) == 2
    assert capsys.readouterr().err.endswith(
        "(the board's square size): pass --size WxH and --calib-unit (m, mm, cm, ft or in)\n"
    )
    assert main(["info", str(rig), "--calib-unit", "mm", "--size", "640x480"]) == 0
    assert capsys.readouterr().out.startswith(
        "640x480 px, raw rig, rectified with alpha 0: baseline 12.0 cm (120.012 mm)"
    )
    left, right = (str(data_dir / "chessboard" / f"{s}01.jpg") for s in ("left", "right"))
    out = tmp_path / "out"
    assert main(["rectify", left, right, "--calib", str(rig), "-o", str(out)]) == 2
    assert capsys.readouterr().err.endswith(
        "(the board's square size): pass --calib-unit (m, mm, cm, ft or in)\n"
    )
    assert not out.exists()
    assert (
        main(["rectify", left, right, "--calib", str(rig), "--calib-unit", "mm", "-o", str(out)])
        == 0
    )
    assert cv2.imread(str(out / "left_rect.png")).shape == (480, 640, 3)


def test_calib_unit_and_size_refuse_what_the_file_states_and_need_a_file(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    calib_txt = data_dir / "eth3d" / "playground" / "calib.txt"
    assert main(["info", str(calib_txt), "--calib-unit", "m"]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {calib_txt} states its lengths in 'mm', not in --calib-unit m: "
        "leave --calib-unit out (it is for files that do not state theirs: OpenCV stereo_calib "
        "output, an OpenCV YAML/XML or JSON file without a unit field, Q.dat)\n"
    )
    assert main(["info", str(calib_txt), "--calib-unit", "mm"]) == 0
    assert "baseline 6.0 cm (59.5549 mm)" in capsys.readouterr().out
    # --size for a calibration that states its size: a check, said in the CLI's words (it
    # read "not of the image_size (1280, 720) given: leave image_size out, or resize the
    # calibration with .scaled_to((1280, 720))")
    assert main(["info", str(calib_txt), "--size", "1280x720"]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {calib_txt} is a calibration of 941x490 images, not of --size "
        "1280x720: leave --size out (it sizes a calibration that holds no size)\n"
    )
    scene = calib_txt.parent
    left, right = str(scene / "left.png"), str(scene / "right.png")
    assert main(["check", left, right, "--calib-unit", "mm"]) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: --calib-unit is the unit of --calib's file: give --calib too\n"
    )


@pytest.mark.parametrize("command", ["depth", "check", "rectify", "info", "stream", "gui", "batch"])
def test_every_command_that_loads_a_calibration_takes_calib_unit(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    assert "--calib-unit {m,mm,cm,ft,in}" in capsys.readouterr().out


def test_kitti_object_calibration_is_sized_by_the_pair(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A KITTI object/odometry calib file (P0..P3, no S_rect_02) with no image beside it was
    refused by depth/check/rectify with "pass image_size=(width, height)", a Python argument,
    though the pair given is the images it belongs to (as a Q.dat alone is sized by it)."""
    scene = data_dir / "kitti2015" / "000005_10"
    raw = (scene / "calib_kitti.txt").read_text()
    p2, p3 = (" ".join(m.split()) for m in re.findall(r"P_rect_0[23]:([^A-Z]*)", raw))
    calib = tmp_path / "000005.txt"
    calib.write_text(f"P2: {p2}\nP3: {p3}\n")
    left, right = str(scene / "left.png"), str(scene / "right.png")
    assert main(["check", left, right, "--calib", str(calib), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ok"] is True
    assert main(["info", str(calib)]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: image_size: KITTI calibration {calib} has no S_rect_02 and no "
        "image next to it; pass --size WxH\n"
    )
    assert main(["info", str(calib), "--size", "1242x375"]) == 0
    assert capsys.readouterr().out.startswith("1242x375 px, rectified pair: baseline 53.3 cm")


def test_json_line_writes_a_non_finite_key_as_a_string() -> None:
    """A dict key that is a NaN or infinite float (a histogram keyed by its bins' edges) made
    json_line raise ValueError ("Out of range float values are not JSON compliant", the key
    unnamed), though its docstring says never for floats: a key is a string in JSON, so it is
    written as json.dumps writes it ("NaN", "Infinity", "-Infinity"), a strict JSON string."""
    import json

    from stereovision._jsonout import json_line

    row = {float("nan"): 1, np.float32(np.inf): 2, -float("inf"): 3, 0.5: np.nan}

    def refuse(word: str) -> None:
        raise ValueError(f"not strict JSON: {word}")

    line = json_line(row)
    assert line == '{"NaN": 1, "Infinity": 2, "-Infinity": 3, "0.5": null}'
    assert json.loads(line, parse_constant=refuse) == {
        "NaN": 1,
        "Infinity": 2,
        "-Infinity": 3,
        "0.5": None,
    }


def test_check_plot_keeps_a_file_it_replaces(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--plot`` over an existing file (the user's picture of the same name) replaced it
    without a word; it is copied aside as NAME.previous.png and stderr says so in one line."""
    scene = data_dir / "middlebury2001" / "tsukuba"
    plot = tmp_path / "plot.png"
    plot.write_bytes(b"my picture")
    argv = ["check", str(scene / "left.png"), str(scene / "right.png"), "--plot", str(plot)]
    run = _in_process(argv, capsys)
    assert run.returncode == 0, run.stderr
    kept = tmp_path / "plot.previous.png"
    assert kept.read_bytes() == b"my picture"
    assert run.stderr == f"stereovision: {plot} replaced; the earlier file is {kept}\n"
    assert cv2.imread(str(plot)) is not None


def test_json_line_refuses_keys_written_alike() -> None:
    """A dict holding a NaN key and the string "NaN" (or 1 and "1", True and "true", None and
    "null") lost one value without a word: json_ready wrote both as "NaN" (one dict entry) and
    json.dumps wrote the others twice under one name (a parser keeps the last). It is a
    ValueError naming both keys now; distinct keys are written as before."""
    from stereovision._jsonout import json_line, json_ready

    for a, b, text in (
        (float("nan"), "NaN", "NaN"),
        (np.float64("inf"), "Infinity", "Infinity"),
        (1, "1", "1"),
        (np.int64(7), "7", "7"),
        (True, "true", "true"),
        (None, "null", "null"),
        (0.5, "0.5", "0.5"),
    ):
        shown = {"Infinity": "inf", "7": "7"}.get(b, repr(a))  # NumPy keys as Python's
        for row, first, second in (
            ({a: 1, b: 2}, shown, repr(b)),
            ({"deep": [{b: 1, a: 2}]}, repr(b), shown),
        ):
            with pytest.raises(ValueError) as err:
                json_line(row)
            assert str(err.value) == (
                f"JSON object keys {first} and {second} are both written as {text!r}: one "
                "value would be lost"
            )
        with pytest.raises(ValueError):
            json_ready({a: 1, b: 2})
    two_nans = {float("nan"): 1, float("nan"): 2}
    with pytest.raises(ValueError, match="both written as 'NaN'"):
        json_line(two_nans)
    row = {1: "a", "2": "b", False: "c", None: "d", float("nan"): "e", "nan": "f", 2.5: "g"}
    assert json_line(row) == (
        '{"1": "a", "2": "b", "false": "c", "null": "d", "NaN": "e", "nan": "f", "2.5": "g"}'
    )


def test_json_ready_writes_a_path_key_as_its_string() -> None:
    """A path as a dict key (a scene's folder) is its string: json.dumps refused it."""
    import os

    from stereovision._jsonout import json_line, json_ready

    assert json_ready({Path("a") / "b": 1}) == {os.path.join("a", "b"): 1}
    assert json.loads(json_line({"per_scene": {Path("s"): float("nan")}})) == {
        "per_scene": {"s": None}
    }


@pytest.mark.parametrize(("text", "port"), [("0", 0), ("65535", 65535)])
def test_port_number_takes_0_to_65535(text: str, port: int) -> None:
    from stereovision.cli import port_number

    assert port_number(text) == port


@pytest.mark.parametrize("text", ["-1", "65536", "80.5"])
def test_port_number_refuses_what_is_no_port(text: str) -> None:
    import argparse

    from stereovision.cli import port_number

    with pytest.raises(
        argparse.ArgumentTypeError, match="expected a port 1 to 65535, or 0 for a free one"
    ):
        port_number(text)


@pytest.mark.parametrize("error", [RecursionError, NotImplementedError])
def test_a_recursion_or_not_implemented_error_is_said_as_a_bug_of_ours(
    error: type[Exception],
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """RecursionError and NotImplementedError are RuntimeErrors, but no command raises them on
    purpose: they were said as an expected error ("stereovision: error: maximum recursion
    depth exceeded"), not as the bug they are."""
    import stereovision.cli as cli

    def broken(args: object) -> int:
        raise error("deep")

    monkeypatch.setattr(cli, "cmd_info", broken)
    assert main(["info", "--size", "640x480", "--hfov", "60", "--baseline", "0.1"]) == 2
    cap = capsys.readouterr()
    assert cap.err == (
        f"stereovision: error: internal {error.__name__}: deep (please report this)\n"
    )


@pytest.mark.parametrize("command", ["eval", "bench"])
def test_a_recursion_error_in_one_scene_of_several_is_said_as_a_bug_of_ours(
    command: str,
    data_dir: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """181c822 left eval's and bench's per-scene catch of RuntimeError as it was: of several
    scenes, a RecursionError was said as one damaged scene ("failed DIR: deep") and the run
    went on, exit 1, not as the bug it is."""
    import stereovision.bench as bench
    import stereovision.cli as cli

    def broken(*args: object, **kwargs: object) -> object:
        raise RecursionError("deep")

    monkeypatch.setattr(cli, "_eval_scene", broken)
    monkeypatch.setattr(bench, "bench_scene", broken)
    scenes = [str(data_dir / "middlebury2001" / s) for s in ("tsukuba", "venus")]
    assert main([command, *scenes, "--json"]) == 2
    cap = capsys.readouterr()
    assert cap.err == "stereovision: error: internal RecursionError: deep (please report this)\n"
    assert cap.out == ""


def test_a_bug_of_ours_is_one_line_on_stderr_and_exit_2(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """An exception no command raises on purpose (an AttributeError) is a bug: one line on
    stderr naming it (its message's first line), exit 2, no traceback, nothing on stdout."""
    import stereovision.cli as cli

    def broken(args: object) -> int:
        raise AttributeError("boom\nsecond line")

    monkeypatch.setattr(cli, "cmd_info", broken)
    assert main(["info", "--size", "640x480", "--hfov", "60", "--baseline", "0.1"]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == "stereovision: error: internal AttributeError: boom (please report this)\n"


def test_depth_of_a_pair_16_px_wide_is_refused_without_a_range(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """16 px is the automatic range's least: a pair that wide has no room for it."""
    rng = np.random.default_rng(0)
    img = (rng.random((8, 16, 3)) * 255).astype(np.uint8)
    assert cv2.imwrite(str(tmp_path / "l.png"), img)
    assert cv2.imwrite(str(tmp_path / "r.png"), img[:, ::-1])
    argv = ["depth", str(tmp_path / "l.png"), str(tmp_path / "r.png"), "-o", str(tmp_path / "o")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("stereovision: error: image too narrow for stereo matching: 16 px wide")
    assert not (tmp_path / "o").exists()


def test_eval_time_line_says_ours_over_sgbm() -> None:
    from stereovision.cli import _eval_time_line

    row = {"scene": "s", "runs": 5, "ours_ms": 30.0, "bm_ms": 2.0, "sgbm_ms": 12.0}
    assert _eval_time_line(row) == (
        "s: time, median of 5 runs after a warm-up: ours 30.0 ms, StereoBM 2.0 ms, "
        "SGBM-3WAY 12.0 ms (ours 2.5 x SGBM-3WAY)"
    )
    assert _eval_time_line({"scene": "s", "runs": 1, "ours_ms": 30.0}) == (
        "s: time, one run, no warm-up: ours 30.0 ms"
    )


def test_eval_times_are_the_medians_of_the_timed_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    """_eval_scene: one untimed warm-up round, then the median (not the mean) of each
    method's ``runs`` times, in milliseconds; accuracy from the first round's outputs."""
    import types

    import stereovision.cli as cli
    import stereovision.depth as depth_mod
    from stereovision import baselines

    now = [0.0]
    monkeypatch.setattr(cli, "time", types.SimpleNamespace(perf_counter=lambda: now[0]))
    disp = np.full((8, 32), 2.0, np.float32)

    def fake(base_s: float, out: object) -> object:
        calls: list[int] = []

        def run(*_a: object, **_k: object) -> object:
            # 1 s warm-up, then base times 1, 3, 2, 50, 2: median 2 base, mean 11.6 base
            now[0] += 1.0 if not calls else base_s * [1, 3, 2, 50, 2][len(calls) - 1]
            calls.append(1)
            return out

        return run

    res = types.SimpleNamespace(disparity=disp, depth=None, channels=None)
    monkeypatch.setattr(depth_mod, "depth_map", fake(0.010, res))
    monkeypatch.setattr(baselines, "opencv_bm", fake(0.001, disp))
    monkeypatch.setattr(baselines, "opencv_sgbm", fake(0.002, disp))
    # the fake StereoBM runs on any pair: the real one's block needs 16 rows, not these 8
    monkeypatch.setattr(baselines, "bm_reference_refusal", lambda *_a: None)
    img = np.zeros((8, 32, 3), np.uint8)
    gt = np.full((8, 32), 2.0, np.float32)
    scene = types.SimpleNamespace(
        name="fake", left=img, right=img, gt=gt, max_disparity=4, calib=None
    )
    row = cli._eval_scene(scene, "census", True, runs=5)
    times = (row["ours_ms"], row["bm_ms"], row["sgbm_ms"])
    assert times == pytest.approx((20.0, 2.0, 4.0)) and row["runs"] == 5
    assert row["ours"]["bad_2.0"] == 0.0 and row["sgbm"]["density"] == 100.0


def test_eval_of_a_missing_folder_names_it(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", "/no/such/scene"]) == 2
    assert (
        capsys.readouterr().err == "stereovision: error: scene folder not found: /no/such/scene\n"
    )


def test_eval_and_bench_name_a_scene_link_whose_target_moved(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``eval data`` (and ``bench data``) with data -> /mnt/usb/data, the disk unmounted, said
    "scene folder not found: data", of a name ls lists, where the file readers name a link's
    target (b7feb4e7). Now named."""
    link = tmp_path / "data"
    link.symlink_to(tmp_path / "moved" / "data")
    said = (
        f"stereovision: error: scene folder not found: {link} (a link to "
        f"{tmp_path / 'moved' / 'data'}, which does not exist)\n"
    )
    for command in ("eval", "bench"):
        assert main([command, str(link)]) == 2
        assert capsys.readouterr().err == said


def test_depth_refuses_rectification_and_calib_together(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    terrace = data_dir / "eth3d" / "terrace"
    (tmp_path / "r.json").write_text("{}")
    argv = [
        "depth",
        str(terrace / "left.png"),
        str(terrace / "right.png"),
        "-o",
        str(tmp_path / "o"),
    ]
    argv += ["--calib", str(terrace / "calib.txt"), "--rectification", str(tmp_path / "r.json")]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: --rectification and --calib: give one way to rectify the pair\n"
    )
    assert not (tmp_path / "o").exists()


def test_sigterm_is_exit_143_and_its_handler_restored(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import signal

    import stereovision.cli as cli
    from stereovision._interrupt import Terminated

    def terminated(args: object) -> int:
        raise Terminated()

    def mine(signum: int, frame: object) -> None:  # the caller's own handler
        pass

    kept = signal.signal(signal.SIGTERM, mine)
    try:
        monkeypatch.setattr(cli, "cmd_info", terminated)
        assert main(["info"]) == 143
        assert capsys.readouterr().err == "stereovision: terminated (SIGTERM)\n"
        assert signal.getsignal(signal.SIGTERM) is mine  # main's own handler is gone again
    finally:
        signal.signal(signal.SIGTERM, kept)


def test_eval_of_three_scenes_one_header_and_the_mean_of_their_figures(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The table's two header lines over the first row only; the mean line the mean (not the
    median) of the scenes' bad-2.0."""
    from stereovision.io import read_pfm, write_pfm

    tsukuba = data_dir / "middlebury2001" / "tsukuba"
    gt = read_pfm(tsukuba / "gt_disp.pfm")
    for i, (y, x) in enumerate([(20, 30), (120, 150), (200, 260)]):
        scene = tmp_path / f"s{i}"
        scene.mkdir()
        for name in ("left.png", "right.png"):
            img = cv2.imread(str(tsukuba / name))
            assert cv2.imwrite(str(scene / name), img[y : y + 64, x : x + 96])
        write_pfm(scene / "gt_disp.pfm", gt[y : y + 64, x : x + 96])
    assert main(["eval", "--no-opencv", "--method", "census", "--json", str(tmp_path)]) == 0
    bad = [json.loads(ln)["ours"]["bad_2.0"] for ln in capsys.readouterr().out.splitlines()]
    assert len(bad) == 3 and abs(np.mean(bad) - np.median(bad)) > 0.1
    assert main(["eval", "--no-opencv", "--method", "census", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert sum(ln.startswith("scene ") for ln in lines) == 1 and len(lines) == 6
    mean = re.fullmatch(r"mean bad-2\.0: ours ([\d.]+) %, ours\+fill ([\d.]+) %", lines[5])
    assert mean is not None and float(mean[1]) == pytest.approx(np.mean(bad), abs=0.051)


def test_depth_with_a_folder_under_an_output_name_moves_nothing(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A folder where one of the run's files goes (overview.png, listed as an earlier run's)
    is refused before any file moves in: the earlier run's disparity.png stays as it was."""
    from stereovision.cli import DEPTH_MANIFEST

    tsukuba = data_dir / "middlebury2001" / "tsukuba"
    out = tmp_path / "o"
    (out / "overview.png").mkdir(parents=True)
    (out / "disparity.png").write_bytes(b"earlier")
    (out / DEPTH_MANIFEST).write_text('["disparity.png", "overview.png"]')
    argv = ["depth", str(tsukuba / "left.png"), str(tsukuba / "right.png"), "-o", str(out)]
    assert main([*argv, "--method", "fast", "--max-disparity", "16"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{out / 'overview.png'} is a folder" in err, err
    assert (out / "disparity.png").read_bytes() == b"earlier"
    assert not (out / "disparity.pfm").exists()


def _tsukuba_depth_argv(data_dir: Path, out: Path) -> list[str]:
    tsukuba = data_dir / "middlebury2001" / "tsukuba"
    argv = ["depth", str(tsukuba / "left.png"), str(tsukuba / "right.png"), "-o", str(out)]
    return [*argv, "--method", "fast", "--max-disparity", "16"]


def test_depth_failing_while_staging_removes_only_the_folders_it_made(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A writer failing inside the staging folder: the -o folders the run made (new/sub) are
    removed again, empty; an -o folder that was there before is kept, as it was (empty)."""
    from stereovision import cli

    def no_room(*_: object, **__: object) -> dict[str, Path]:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(cli, "write_overview", no_room)
    made = tmp_path / "new" / "sub"
    assert main(_tsukuba_depth_argv(data_dir, made)) == 2
    assert capsys.readouterr().err == "stereovision: error: [Errno 28] No space left on device\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    there = tmp_path / "there"
    there.mkdir()
    assert main(_tsukuba_depth_argv(data_dir, there)) == 2
    assert there.is_dir() and list(there.iterdir()) == []


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full (Linux)")
def test_depth_into_a_full_disk_names_the_output_file_not_the_staging_one(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """depth -o full/d on a full disk said "cannot write full/d/.stereovision-partial-wex201ov/
    disparity.png: ...", a hidden folder removed by then: the file is named where it goes."""
    import os

    import stereovision.io as svio

    def full_disk(dest: Path, suffix: str) -> tuple[int, str]:
        return os.open("/dev/full", os.O_WRONLY), str(dest.with_name(f".{dest.name}.tmp"))

    monkeypatch.setattr(svio, "_temp_beside", full_disk)
    out = tmp_path / "d"
    assert main(_tsukuba_depth_argv(data_dir, out)) == 2
    err = capsys.readouterr().err
    said = rf"^stereovision: error: cannot write {re.escape(str(out))}/\w+\.\w+: No space left "
    assert re.match(said + r"on device\n$", err), err


def test_depth_whose_move_into_o_fails_names_the_file_once(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A move from the staging folder into -o refused (the folder made read-only meanwhile)
    said "[Errno 13] Permission denied: 'o/disparity.png' -> 'o/disparity.png'", a file moved
    onto itself (the staging folder's name replaced by -o's): the file is named where it goes."""
    import errno
    import os

    from stereovision import cli

    real_replace = os.replace

    def replace(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> None:
        if Path(src).parent.name.startswith(cli.STAGING_PREFIX) and Path(dst).parent == out:
            raise PermissionError(errno.EACCES, "Permission denied", str(src), None, str(dst))
        real_replace(src, dst)

    out = tmp_path / "o"
    monkeypatch.setattr(os, "replace", replace)
    assert main(_tsukuba_depth_argv(data_dir, out)) == 2
    err = capsys.readouterr().err
    assert err == f"stereovision: error: cannot write {out}/disparity.png: Permission denied\n"


def test_depth_records_the_manifest_before_moving_a_file_in(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The manifest lists the earlier run's files and this run's before the first file moves in:
    a run that dies after moving disparity.png leaves it listed, and the rerun replaces it
    instead of refusing it as the user's; at the end the manifest lists what was written."""
    import os

    from stereovision import cli

    out = tmp_path / "o"
    out.mkdir()
    (out / "depth.npy").write_bytes(b"earlier")  # an earlier run's (with --calib), not rewritten
    (out / cli.DEPTH_MANIFEST).write_text('["depth.npy"]')
    real_replace = os.replace
    seen: list[tuple[str, list[str]]] = []

    def replace(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> None:
        if cli.STAGING_PREFIX in str(src) and Path(dst).parent == out:
            seen.append((Path(dst).name, json.loads((out / cli.DEPTH_MANIFEST).read_text())))
            if len(seen) == 2:
                raise OSError(5, "Input/output error")
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    assert main(_tsukuba_depth_argv(data_dir, out)) == 2
    said = f"stereovision: error: cannot write {out}/disparity.pfm: Input/output error\n"
    assert capsys.readouterr().err == said
    want = ["depth.npy", "disparity.pfm", "disparity.png", "overview.png"]
    assert seen == [("disparity.png", want), ("disparity.pfm", want)]
    assert json.loads((out / cli.DEPTH_MANIFEST).read_text()) == want
    assert sorted(p.name for p in out.iterdir()) == [
        cli.DEPTH_MANIFEST,
        "depth.npy",
        "disparity.png",
    ]
    monkeypatch.setattr(os, "replace", real_replace)
    assert main(_tsukuba_depth_argv(data_dir, out)) == 0
    capsys.readouterr()
    assert json.loads((out / cli.DEPTH_MANIFEST).read_text()) == want[1:]
    assert not (out / "depth.npy").exists()  # the earlier run's, removed at the end


def test_depth_rectification_takes_an_explicit_max_disparity(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--rectification's saved max_disparity (40) is the default; --max-disparity 24 overrides
    it (the line says 24), and without it the saved one is searched (40)."""
    rng = np.random.default_rng(0)
    tex = cv2.resize(rng.integers(0, 255, (24, 40), np.uint8), (160, 96))
    left, right = tex, np.roll(tex, -6, axis=1)
    for name, img in (("l.png", left), ("r.png", right)):
        assert cv2.imwrite(str(tmp_path / name), img)
    eye = np.eye(3).tolist()
    rect = {"H1": eye, "H2": eye, "size": [160, 96], "input_size": [160, 96]}
    rect |= {"F": [[0, 0, 0], [0, 0, -1], [0, 1, 0]], "matches": 40, "median_dy": 0.1}
    rect |= {"p95_dy": 0.3, "disparity_range": [0, 12], "max_disparity": 40}
    rect |= {"skew_deg": [0, 0], "aspect": [1, 1], "model": "projective"}
    (tmp_path / "rect.json").write_text(json.dumps(rect))
    argv = ["depth", str(tmp_path / "l.png"), str(tmp_path / "r.png"), "--method", "fast"]
    argv += ["--rectification", str(tmp_path / "rect.json")]
    assert main([*argv, "-o", str(tmp_path / "a"), "--max-disparity", "24"]) == 0
    assert "fast: max_disparity 24 px," in capsys.readouterr().out
    assert main([*argv, "-o", str(tmp_path / "b")]) == 0
    assert "fast: max_disparity 40 px," in capsys.readouterr().out
    # the file's range edited to the width: it was "give a --max-disparity below 160", an
    # option not given; the file is named, and nothing is written
    (tmp_path / "rect.json").write_text(json.dumps(rect | {"max_disparity": 160}))
    assert main([*argv, "-o", str(tmp_path / "c")]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {tmp_path / 'rect.json'}: its max_disparity 160 is not smaller "
        "than the rectified width 160: edit it below 160 there, or give a --max-disparity "
        "below 160\n"
    )
    assert not (tmp_path / "c").exists()


def test_depth_failing_before_its_first_move_leaves_no_folder_and_the_old_manifest(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The first move into -o failing: the manifest written just before it listed this run's
    files, none of which came in, and kept the folder the run made (new/sub, empty to `ls`)
    alive. Nothing moved in: a folder the run made is removed, and an earlier manifest is
    as it was, byte for byte."""
    import os

    from stereovision import cli

    real_replace = os.replace

    def replace(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> None:
        # a move out of the staging folder (not a write inside it)
        stage = Path(src).parent
        if stage.name.startswith(cli.STAGING_PREFIX) and Path(dst).parent != stage:
            raise OSError(5, "Input/output error")
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    made = tmp_path / "new" / "sub"
    assert main(_tsukuba_depth_argv(data_dir, made)) == 2
    said = f"stereovision: error: cannot write {made}/disparity.png: Input/output error\n"
    assert capsys.readouterr().err == said
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    out = tmp_path / "o"
    out.mkdir()
    (out / "depth.npy").write_bytes(b"earlier")
    (out / cli.DEPTH_MANIFEST).write_text('[ "depth.npy" ]')
    assert main(_tsukuba_depth_argv(data_dir, out)) == 2
    capsys.readouterr()
    assert (out / cli.DEPTH_MANIFEST).read_text() == '[ "depth.npy" ]'
    assert sorted(p.name for p in out.iterdir()) == [cli.DEPTH_MANIFEST, "depth.npy"]


def test_commit_outputs_interrupted_right_after_the_first_move_keeps_it_listed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A second Ctrl-C during the first rename is raised once it returns, before the file is
    counted as written: the earlier manifest was put back without the file that did move in,
    and the rerun refused it as the user's. The manifest keeps listing it."""
    import os

    from stereovision import cli

    out = tmp_path / "o"
    stage = tmp_path / "stage"
    stage.mkdir()
    out.mkdir()
    (out / cli.DEPTH_MANIFEST).write_text('["depth.npy"]')
    (out / "depth.npy").write_bytes(b"earlier")
    staged = {}
    for name in ("disparity.png", "disparity.pfm"):
        (stage / name).write_bytes(b"new")
        staged[name] = stage / name
    real_replace = os.replace

    def replace(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> None:
        real_replace(src, dst)
        if Path(src).parent == stage:
            raise KeyboardInterrupt  # the handler of a second signal, run as the rename returns

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(KeyboardInterrupt):
        cli.commit_outputs(out, staged, {"depth.npy"})
    monkeypatch.setattr(os, "replace", real_replace)
    assert (out / "disparity.png").read_bytes() == b"new"
    listed = json.loads((out / cli.DEPTH_MANIFEST).read_text())
    assert "disparity.png" in listed and "depth.npy" in listed
    # the rerun replaces it, not refuses it as a file of the user's
    assert cli.refuse_foreign_outputs(out, list(cli.DEPTH_OUTPUTS)) == set(listed)


def test_depth_says_its_depths_in_metres_unless_unit_is_given(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The summary's depths are in metres by default and in --unit's unit when given (a wall
    about 8 px apart, 150 px focal, 0.1 m baseline: near 1.9 m); depth.npy stays in metres.
    A depth of 1000 or more in the unit was said in exponent form (``--unit mm``: "depth
    1.87e+03-1.93e+03 mm"); now in whole units. ``--unit mm --max-depth 1000`` kept every
    depth without a word (1000 m, the limits stay in metres): it is warned of, naming the
    --max-depth that 1000 mm is; with --unit m (or ft, where it cuts nothing either way) not."""
    from tests import synthetic_scene as syn

    rng = np.random.default_rng(0)
    left = (rng.random((syn.H, syn.W + 8)) * 255).astype(np.uint8)
    left = cv2.GaussianBlur(left, (3, 3), 0)
    pair = left[:, 8:], left[:, :-8]  # the right view's wall 8 px to the left
    for name, img in zip(("l.png", "r.png"), pair, strict=True):
        assert cv2.imwrite(str(tmp_path / name), img)
    rig = syn.calibration().save(tmp_path / "rig.yaml")
    argv = ["depth", str(tmp_path / "l.png"), str(tmp_path / "r.png"), "--calib", str(rig)]
    argv += ["--max-disparity", "16"]
    medians = {}
    for unit in ("m", "ft", "mm"):
        extra = [] if unit == "m" else ["--unit", unit]
        assert main([*argv, *extra, "--max-depth", "1000", "-o", str(tmp_path / unit)]) == 0
        out, err = capsys.readouterr()
        line = out.splitlines()[0]
        if unit == "mm":
            assert re.fullmatch(
                r"stereovision: warning: --max-depth 1000 is in metres, whatever --unit: 1000 m "
                r"keeps every depth \(the largest [\d.]+ m\); for 1000 mm give --max-depth 1\n",
                err,
            ), err
        else:
            assert err == ""
        found = re.search(rf"depth [\d.]+-[\d.]+ {unit} \(median ([\d.]+) {unit}\)", line)
        assert found, line
        medians[unit] = float(found.group(1))
        metres = float(np.nanmedian(np.load(tmp_path / unit / "depth.npy")))
        assert 1.8 < metres < 2.0  # the wall, in metres whatever --unit says
    assert medians["m"] == pytest.approx(metres, abs=0.005)
    assert medians["ft"] == pytest.approx(metres / 0.3048, abs=0.005)
    assert medians["mm"] == pytest.approx(1000 * metres, abs=0.5)


def test_depth_of_a_pair_16_px_wide_says_so_before_a_file_in_the_output_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A pair too narrow for the automatic range is refused as such, before (not behind) a
    file of the user's under an output name in -o, which stays."""
    rng = np.random.default_rng(0)
    img = (rng.random((8, 16, 3)) * 255).astype(np.uint8)
    assert cv2.imwrite(str(tmp_path / "l.png"), img)
    assert cv2.imwrite(str(tmp_path / "r.png"), img[:, ::-1])
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "disparity.png").write_bytes(b"mine")
    argv = ["depth", str(tmp_path / "l.png"), str(tmp_path / "r.png"), "-o", str(tmp_path / "o")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("stereovision: error: image too narrow for stereo matching: 16 px wide")
    assert (tmp_path / "o" / "disparity.png").read_bytes() == b"mine"


def test_positive_rate_refuses_an_infinite_rate() -> None:
    """``--fps inf`` is no frame rate (a zero frame period): refused in the option's words."""
    import argparse

    from stereovision.cli import positive_rate

    assert positive_rate("2.5") == 2.5
    for bad in ("inf", "-inf", "nan", "0", "x"):
        with pytest.raises(argparse.ArgumentTypeError, match="expected a frame rate above 0"):
            positive_rate(bad)


def test_whole_number_options_take_a_whole_number_written_with_a_point(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``--max-disparity 64.0`` (and ``--frames 5.0``, ``--runs 5.0``, the ``type=int`` options'
    ``--workers 2.0``) was refused as "expected a whole number", which it is, while the library
    takes 64.0: every whole-number option now takes it; a fraction, NaN, an exponent or a word
    is still refused, as typed."""
    import argparse

    from stereovision.bench import _run_count
    from stereovision.cli import _Parser, port_number, positive_count, positive_pixels, run_count

    assert [positive_pixels(t) for t in ("64", "64.0", " 64. ", "1_000")] == [64, 64, 64, 1000]
    assert (positive_count("5.0"), run_count("5.0"), _run_count("5.0")) == (5, 5, 5)
    for bad in ("64.5", "nan", "inf", "0.0", "-64.0", "abc", "6.4e1", "1e400"):
        with pytest.raises(argparse.ArgumentTypeError) as info:
            positive_pixels(bad)
        assert str(info.value) == f"expected a whole number of pixels above 0, got {bad!r}"
    refused = argparse.ArgumentTypeError
    with pytest.raises(refused, match=r"^expected a whole number, got '5\.5'$"):
        _run_count("5.5")
    with pytest.raises(refused, match=r"^expected at most 1000 runs, got '1001\.0'$"):
        run_count("1001.0")
    parser = _Parser(prog="stereovision batch")
    parser.add_argument("--workers", type=int)
    assert parser.parse_args(["--workers", "2.0"]).workers == 2
    assert (port_number("8080.0"), port_number("8080")) == (8080, 8080)  # as gui --port
    from stereovision.capture import _temporal_frames
    from stereovision.render import _point_count
    from stereovision.stream import temporal_pairs

    assert (_temporal_frames("8.0"), temporal_pairs("8.0"), _point_count("1000.0")) == (8, 8, 1000)
    with pytest.raises(refused, match=r"^expected 2-255 pairs to average, got '8\.5'$"):
        temporal_pairs("8.5")
    with pytest.raises(SystemExit):
        parser.parse_args(["--workers", "2.5"])
    assert capsys.readouterr().err == (
        "stereovision batch: error: argument --workers: expected a whole number, got '2.5' "
        "(see stereovision batch --help)\n"
    )


def test_check_tolerance_is_refused_as_typed(capsys: pytest.CaptureFixture[str]) -> None:
    """``check --tolerance 1e400`` said "got inf" (the parsed float): the value as typed now,
    by the parser, before the pair is read."""
    for bad in ("1e400", "-1e400"):  # nan, -1 and 0: test_rectification_check
        with pytest.raises(SystemExit) as exit_:
            main(["check", "no_l.png", "no_r.png", "--tolerance", bad])
        assert exit_.value.code == 2
        assert capsys.readouterr().err == (
            "stereovision check: error: argument --tolerance: expected a positive number of "
            f"pixels, got '{bad}' (see stereovision check --help)\n"
        )


def test_commit_outputs_keeps_a_link_the_user_put_under_an_earlier_output_name(
    tmp_path: Path,
) -> None:
    """An earlier run's depth.npy that the user replaced by a link (to a file of theirs) is
    not the tool's file any more: a run that does not write depth.npy leaves the link."""
    from stereovision.cli import DEPTH_MANIFEST, commit_outputs

    out = tmp_path / "o"
    out.mkdir()
    (tmp_path / "mine.npy").write_bytes(b"mine")
    (out / "depth.npy").symlink_to(tmp_path / "mine.npy")
    (out / "cloud.ply").write_bytes(b"earlier run's")
    stage = tmp_path / "stage"
    stage.mkdir()
    (stage / "disparity.png").write_bytes(b"new")
    written, removed = commit_outputs(
        out, {"disparity.png": stage / "disparity.png"}, {"depth.npy", "cloud.ply"}
    )
    assert written == {"disparity.png": out / "disparity.png"}
    assert removed == [out / "cloud.ply"]
    assert (out / "depth.npy").is_symlink() and (out / "depth.npy").read_bytes() == b"mine"
    assert json.loads((out / DEPTH_MANIFEST).read_text()) == ["disparity.png"]


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["rectify", "L", "R", "-o", "FILE"], "-o FILE: is a file; give a folder"),
        (
            ["rectify", "L", "R", "--calib", "RIG", "--model", "projective", "-o", "OUT"],
            "--model is for rectifying without a calibration (no --calib)",
        ),
        (
            ["info", "--calib-unit", "mm"],
            "--calib-unit is the unit of a calibration file: give one, or none",
        ),
        (
            ["info", "RIG", "--hfov", "60", "--baseline", "0.1"],
            "--hfov and --baseline describe a rig on paper: give no calibration",
        ),
        # --baseline alone was told "--hfov and --baseline describe ..."
        (
            ["info", "RIG", "--baseline", "0.1"],
            "--baseline describes a rig on paper: give no calibration",
        ),
        (
            ["info", "BAG", "--size", "640x480"],
            "--size and --calib-unit are for a calibration file, not a bag",
        ),
        # a rig on paper printed its figures, the topic dropped without a word
        (
            "info --size 640x480 --hfov 60 --baseline 0.1 --left-topic /l".split(),
            "--left-topic and --right-topic are for a bag",
        ),
    ],
)
def test_rectify_and_info_refuse_options_that_do_not_fit_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], says: str
) -> None:
    """Options the run would drop or trip over are one line and status 2 before any work:
    nothing on stdout, nothing written (the file given as -o stays as it was)."""
    from tests import synthetic_scene as syn

    rng = np.random.default_rng(0)
    img = (rng.random((syn.H, syn.W)) * 255).astype(np.uint8)
    names = {"L": tmp_path / "l.png", "R": tmp_path / "r.png", "FILE": tmp_path / "notes"}
    names |= {"RIG": tmp_path / "rig.yaml", "OUT": tmp_path / "out"}
    assert cv2.imwrite(str(names["L"]), img) and cv2.imwrite(str(names["R"]), img[:, ::-1])
    names["FILE"].write_text("mine")
    names["BAG"] = tmp_path / "rec.bag"  # not opened: the option is refused first
    names["BAG"].write_bytes(b"not read")
    syn.calibration().save(names["RIG"])
    capsys.readouterr()
    assert main([str(names.get(a, a)) for a in argv]) == 2
    out, err = capsys.readouterr()
    for key, path in names.items():
        says = says.replace(f" {key}:", f" {path}:")
    assert out == "" and err == f"stereovision: error: {says}\n"
    assert names["FILE"].read_text() == "mine" and not names["OUT"].exists()


def test_demo_writes_into_demo_output_unless_told() -> None:
    """`stereovision demo` writes into ./demo_output (README's Quick start, `make demo`)."""
    from stereovision.cli import build_parser

    assert build_parser().parse_args(["demo"]).output == "demo_output"


def test_a_warning_with_an_empty_message_is_one_line_not_an_error(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A warning with no message (a library's ``warnings.warn(SomeWarning())``) made the
    one-line printer index an empty list: the IndexError stopped the command as an internal
    error (status 2). It is said by its category's name, and the command goes on."""
    import warnings

    from stereovision import cli

    def warns(args: object) -> int:
        warnings.warn(UserWarning(), stacklevel=1)
        print("done")
        return 0

    monkeypatch.setattr(cli, "cmd_info", warns)
    assert cli.main(["info"]) == 0
    assert capsys.readouterr() == ("done\n", "stereovision: warning: UserWarning\n")


def test_a_warning_whose_message_opens_with_a_blank_line_says_its_text(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A message opening with a line break (``"\\nThe array is ..."``, as some libraries write
    them) was printed as 'stereovision: warning: ' and nothing else: its first line, empty, was
    taken. Its first line with text is said; one of blanks only is named by its category."""
    import warnings

    from stereovision import cli

    def warns(args: object) -> int:
        warnings.warn("\n  \nthe text\nmore", RuntimeWarning, stacklevel=1)
        warnings.warn(" \n ", UserWarning, stacklevel=1)
        return 0

    monkeypatch.setattr(cli, "cmd_info", warns)
    assert cli.main(["info"]) == 0
    assert capsys.readouterr().err == (
        "stereovision: warning: the text\nstereovision: warning: UserWarning\n"
    )


def test_a_resource_warning_is_not_said(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A SIGTERM caught between a file's open() and its ``with`` leaves the file to the
    collector, whose "unclosed file" ResourceWarning became a second line after the
    interrupt's (test_batch_interrupt_is_one_line failed so once). Python hides these by
    default; the command's warnings do too, and show the others."""
    import warnings

    from stereovision import cli

    def warns(args: object) -> int:
        warnings.warn("unclosed file <_io.BufferedReader>", ResourceWarning, stacklevel=1)
        warnings.warn("a real one", UserWarning, stacklevel=1)
        return 0

    monkeypatch.setattr(cli, "cmd_info", warns)
    assert cli.main(["info"]) == 0
    assert capsys.readouterr().err == "stereovision: warning: a real one\n"


# ------------------------------------------------------------- third mutation audit of the CLI


@pytest.mark.parametrize(
    ("grid", "reached"),
    [("0.01", True), ("10", True), ("0.005", False), ("10.5", False), ("nan", False)],
)
def test_depth_grid_takes_0_01_to_10_m_ends_included(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    grid: str,
    reached: bool,
) -> None:
    """--grid's range, as its message says it, 0.01 to 10 m with both ends taken: an end refused
    or a cell side beyond them taken survived a mutation audit. (The matching stands in for
    the work: reached, it stops the run.)"""
    import stereovision.depth

    def matched(*args: object, **kwargs: object) -> None:
        raise RuntimeError("matched")

    monkeypatch.setattr(stereovision.depth, "depth_map", matched)
    terrace = data_dir / "eth3d" / "terrace"
    pair = [str(terrace / "left.png"), str(terrace / "right.png")]
    argv = ["depth", *pair, "--calib", str(terrace / "calib.txt"), "--ground", "--grid", grid]
    argv += ["-o", str(tmp_path / "o")]
    assert main(argv) == 2
    said = (
        "matched"
        if reached
        else f"--grid: expected a cell side from 0.01 to 10 m, got {float(grid)}"
    )
    assert capsys.readouterr().err == f"stereovision: error: {said}\n"
    assert not (tmp_path / "o").exists()


def test_running_out_of_memory_is_the_users_one_line_not_a_bug(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A MemoryError (a pair too large for the machine) is said as the error it is, exit 2,
    not as 'internal MemoryError ... (please report this)'."""
    import stereovision.cli as cli

    def too_big(args: object) -> int:
        raise MemoryError("Unable to allocate 12.0 GiB for an array")

    monkeypatch.setattr(cli, "cmd_info", too_big)
    assert main(["info", "--size", "640x480", "--hfov", "60", "--baseline", "0.1"]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == "stereovision: error: Unable to allocate 12.0 GiB for an array\n"


def test_eval_json_leaves_out_the_text_only_keys(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """eval --json writes a row's figures, not its keys for the text output ('_table1_text',
    pre-formatted tables): a mutation audit wrote them into the JSON unseen."""
    import stereovision.cli as cli
    from stereovision.io import write_pfm

    scene = tmp_path / "fam" / "s"
    scene.mkdir(parents=True)
    rng = np.random.default_rng(0)
    img = (rng.random((24, 64, 3)) * 255).astype(np.uint8)
    assert cv2.imwrite(str(scene / "left.png"), img)
    assert cv2.imwrite(str(scene / "right.png"), img[:, ::-1])
    write_pfm(scene / "gt_disp.pfm", np.full((24, 64), 3.0, np.float32))
    row = {"scene": "fam/s", "max_disparity": 16, "table1": {"n": 1}, "_table1_text": "T"}
    monkeypatch.setattr(cli, "_eval_scene", lambda *args, **kwargs: dict(row))
    assert main(["eval", str(scene), "--json"]) == 0
    (line,) = capsys.readouterr().out.splitlines()
    assert json.loads(line) == {"scene": "fam/s", "max_disparity": 16, "table1": {"n": 1}}


@pytest.mark.parametrize(
    ("left", "name"),
    [("data/terrace/left.png", "terrace/left.png"), ("left.png", "left.png"),
     ("/tmp/l.png", "tmp/l.png")],
)  # fmt: skip
def test_pair_name_is_the_left_images_folder_and_file(left: str, name: str) -> None:
    """overview.png's title names the pair by its left image's folder and file name (the
    file alone when it has no folder)."""
    from stereovision.cli import _pair_name

    assert _pair_name(left) == name


def test_depth_pictures_colour_near_warm_and_the_disparity_from_0(tmp_path: Path) -> None:
    """disparity.png is coloured from 0 px (a disparity of 10..20 does not start at the
    colour map's end), depth.png by inverse depth (near warm, far cold, as the disparity):
    neither was asserted by value before a mutation audit."""
    from types import SimpleNamespace

    from stereovision.cli import colorize, write_depth_outputs

    disparity = np.tile(np.linspace(10.0, 20.0, 8, dtype=np.float32), (4, 1))
    depth = (40.0 / disparity).astype(np.float32)  # near where the disparity is large
    res = SimpleNamespace(
        disparity=disparity,
        depth=depth,
        points=np.ones((3, 3), np.float32),
        colors=np.zeros((3, 3), np.uint8),
    )
    written = write_depth_outputs(res, tmp_path / "o")
    disp_png = cv2.imread(str(written["disparity.png"]))
    assert np.array_equal(disp_png, colorize(disparity, lo=0.0))
    assert not np.array_equal(disp_png, colorize(disparity))
    depth_png = cv2.imread(str(written["depth.png"])).astype(int)
    near, far = depth_png[0, -1], depth_png[0, 0]  # BGR
    assert near[2] > near[0] and far[0] > far[2]  # near red, far blue
    assert np.array_equal(depth_png, colorize(1.0 / depth))


def test_a_manifest_that_is_no_list_names_no_earlier_output(tmp_path: Path) -> None:
    """A manifest holding a JSON object (or a string) is no list of an earlier run's files:
    the user's cloud.ply beside it is refused, not taken for the run's (its keys, or the
    string's letters, were never outputs)."""
    from stereovision.cli import DEPTH_MANIFEST, refuse_foreign_outputs

    (tmp_path / "cloud.ply").write_bytes(b"mine")
    for text in ('{"cloud.ply": true}', '"cloud.ply"'):
        (tmp_path / DEPTH_MANIFEST).write_text(text)
        with pytest.raises(FileExistsError, match=r"cloud\.ply is not listed"):
            refuse_foreign_outputs(tmp_path, ["disparity.png", "cloud.ply"])
    (tmp_path / DEPTH_MANIFEST).write_text('["cloud.ply"]')
    assert refuse_foreign_outputs(tmp_path, ["cloud.ply"]) == {"cloud.ply"}


def test_commit_outputs_keeps_an_earlier_file_stale_says_to_keep(tmp_path: Path) -> None:
    """commit_outputs' ``stale``: an earlier run's file this run did not write goes only when
    stale(path) says so (rectify keeps a rectification.json that holds no homographies)."""
    from stereovision.cli import RECTIFY_MANIFEST, RECTIFY_OUTPUTS, commit_outputs

    out, stage = tmp_path / "o", tmp_path / "stage"
    out.mkdir()
    stage.mkdir()
    for name in ("check.png", "rectification.json"):
        (out / name).write_text("earlier")
    (stage / "left_rect.png").write_bytes(b"new")
    earlier = {"check.png", "rectification.json"}
    written, removed = commit_outputs(
        out, {"left_rect.png": stage / "left_rect.png"}, earlier, RECTIFY_MANIFEST,
        RECTIFY_OUTPUTS, stale=lambda p: p.name == "check.png",
    )  # fmt: skip
    assert written == {"left_rect.png": out / "left_rect.png"}
    assert removed == [out / "check.png"]
    assert (out / "rectification.json").read_text() == "earlier"
    assert json.loads((out / RECTIFY_MANIFEST).read_text()) == ["left_rect.png"]


def test_lengths_are_said_in_the_unit_asked_for() -> None:
    """_length (the scan's and the floor's lines with --unit): metres said in the unit."""
    from stereovision.cli import _length

    assert _length(0.3048, "ft", 2) == "1.00 ft"
    assert _length(1.5, "mm", 0) == "1500 mm"
    assert _length(1.5, "m", 1) == "1.5 m"


def test_check_plot_of_the_same_plot_again_keeps_no_copy(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--plot written again with the same picture (the same pair checked twice) replaces
    nothing: no plot.previous.png, no line about it."""
    scene = data_dir / "middlebury2001" / "tsukuba"
    plot = tmp_path / "plot.png"
    argv = ["check", str(scene / "left.png"), str(scene / "right.png"), "--plot", str(plot)]
    assert main(argv) == 0
    first = plot.read_bytes()
    capsys.readouterr()
    assert main(argv) == 0
    assert capsys.readouterr().err == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plot.png"]
    assert plot.read_bytes() == first


def test_check_plot_names_the_picture_it_wrote(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check L R --plot PNG`` wrote the picture without a word (``view -o`` and ``--fix`` name
    the file they write): its last line now says where it is; with --json stdout stays the one
    JSON object."""
    scene = data_dir / "middlebury2001" / "tsukuba"
    plot = tmp_path / "plot.png"
    argv = ["check", str(scene / "left.png"), str(scene / "right.png"), "--plot", str(plot)]
    assert main(argv) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("rectification ok: ") and out[-1] == f"plot written to {plot}"
    assert len(out) == 2 and cv2.imread(str(plot)) is not None
    assert main([*argv, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ok"] is True


@pytest.mark.parametrize("blocked", ["file above", "read-only above"])
def test_rectify_checks_its_output_folder_before_the_work(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    blocked: str,
) -> None:
    """rectify -o notes/rect (notes a file), or into a folder that cannot be written, found out
    after the pair's features were matched and its homographies fitted (depth and demo check
    their -o first); now one line first, no work done."""
    import tempfile

    import stereovision.rectification_check

    def worked(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the pair was matched first")

    monkeypatch.setattr(stereovision.rectification_check, "already_rectified", worked)
    scene = data_dir / "middlebury2001" / "tsukuba"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    if blocked == "file above":
        (tmp_path / "notes").write_text("mine")
        out = tmp_path / "notes" / "rect"
        says = f"-o {out}: {tmp_path / 'notes'} is a file, not a folder"
    else:
        (tmp_path / "ro").mkdir()
        out = tmp_path / "ro" / "rect"
        real = tempfile.mkstemp

        def mkstemp(*args: object, dir: object = None, **kwargs: object) -> object:
            if dir is not None and Path(str(dir)) == tmp_path / "ro":  # root writes anywhere
                raise PermissionError(13, "Permission denied")
            return real(*args, dir=dir, **kwargs)  # type: ignore[call-overload]

        monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
        says = f"-o {out}: cannot write in {tmp_path / 'ro'} (Permission denied)"
    assert main(["rectify", *pair, "-o", str(out)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == f"stereovision: error: {says}\n"
    assert not out.exists()


@pytest.mark.parametrize("blocked", ["file above", "folder"])
def test_check_plot_that_cannot_be_written_is_said_before_the_check(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    blocked: str,
) -> None:
    """check --plot notes/plot.png (notes a file), or --plot naming a folder, was found out
    after the pair's features were matched and the verdict printed; now one line first, exit
    2, nothing checked."""
    import stereovision.rectification_check

    def worked(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the pair was checked first")

    monkeypatch.setattr(stereovision.rectification_check, "check_rectification", worked)
    scene = data_dir / "middlebury2001" / "tsukuba"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    if blocked == "file above":
        (tmp_path / "notes").write_text("mine")
        plot = tmp_path / "notes" / "plot.png"
        says = f"--plot {plot}: its folder {tmp_path / 'notes'}: is a file, not a folder"
    else:
        plot = tmp_path / "plot.png"
        plot.mkdir()
        says = f"--plot {plot}: is a folder; give a file name"
    assert main(["check", *pair, "--plot", str(plot)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == f"stereovision: error: {says}\n"
    assert (tmp_path / "notes").is_file() if blocked == "file above" else plot.is_dir()


def test_check_fix_naming_a_folder_is_said_before_the_check(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """check --fix rig.yaml where rig.yaml is a folder failed only when the corrected rig was
    saved, after the check and the correction; now one line first, exit 2."""
    import stereovision.rectification_check

    def worked(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the pair was checked first")

    monkeypatch.setattr(stereovision.rectification_check, "check_rectification", worked)
    scene = data_dir / "eth3d" / "terrace"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    rig = Path(tmp_path / "fixed.yaml")
    rig.mkdir()
    calib = scene / "calib.txt"
    assert main(["check", *pair, "--calib", str(calib), "--fix", str(rig)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == f"stereovision: error: --fix {rig}: is a folder; give a file name\n"
    assert rig.is_dir() and not any(rig.iterdir())


def test_check_fix_in_a_folder_that_cannot_be_written_is_said_before_the_check(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """check --fix ro/fixed.yaml (ro not writable) checked the pair and corrected the rig, then
    failed to save it; now one line first, exit 2, as --plot's folder."""
    import tempfile

    import stereovision.rectification_check

    def worked(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the pair was checked first")

    monkeypatch.setattr(stereovision.rectification_check, "check_rectification", worked)
    (tmp_path / "ro").mkdir()
    real = tempfile.mkstemp

    def mkstemp(*args: object, dir: object = None, **kwargs: object) -> object:
        if dir is not None and Path(str(dir)) == tmp_path / "ro":  # root writes anywhere
            raise PermissionError(13, "Permission denied")
        return real(*args, dir=dir, **kwargs)  # type: ignore[call-overload]

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    scene = data_dir / "eth3d" / "terrace"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    rig = tmp_path / "ro" / "fixed.yaml"
    calib = scene / "calib.txt"
    assert main(["check", *pair, "--calib", str(calib), "--fix", str(rig)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == (
        f"stereovision: error: --fix {rig}: its folder {tmp_path / 'ro'}: cannot write in "
        f"{tmp_path / 'ro'} (Permission denied)\n"
    )
    assert not any((tmp_path / "ro").iterdir())


def test_check_fix_in_a_folder_that_is_a_file_says_so(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """check --fix notes/fixed.yaml, notes a file, said "directory notes does not exist" (it
    does); now it is named a file, as --plot's folder is, before the check, exit 2."""
    import stereovision.rectification_check

    def worked(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the pair was checked first")

    monkeypatch.setattr(stereovision.rectification_check, "check_rectification", worked)
    scene = data_dir / "eth3d" / "terrace"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    (tmp_path / "notes").write_text("kept")
    rig = tmp_path / "notes" / "fixed.yaml"
    calib = scene / "calib.txt"
    assert main(["check", *pair, "--calib", str(calib), "--fix", str(rig)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == (
        f"stereovision: error: --fix {rig}: its folder {tmp_path / 'notes'}: is a file, "
        "not a folder\n"
    )
    assert (tmp_path / "notes").read_text() == "kept"


def test_check_fix_through_a_link_into_a_missing_folder_is_said_before_the_check(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """check --fix rig.yaml, rig.yaml a link into a folder that is gone: 3094d44 checked the
    link's own folder only, so the pair was checked and the rig corrected before the save
    failed; now one line first, exit 2, naming the link and its target's folder."""
    import stereovision.rectification_check

    def worked(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the pair was checked first")

    monkeypatch.setattr(stereovision.rectification_check, "check_rectification", worked)
    scene = data_dir / "eth3d" / "terrace"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    rig = tmp_path / "rig.yaml"
    target = tmp_path / "gone" / "rig.yaml"
    rig.symlink_to(target)
    calib = scene / "calib.txt"
    assert main(["check", *pair, "--calib", str(calib), "--fix", str(rig)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == (
        f"stereovision: error: --fix {rig}: its folder {tmp_path}: rig.yaml is a link to "
        f"{target}; cannot write {target}: directory {tmp_path / 'gone'} does not exist\n"
    )
    assert rig.is_symlink() and not (tmp_path / "gone").exists()


def test_check_plot_through_a_link_into_a_missing_folder_is_said_before_the_check(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """check --plot p.png, p.png a link into a folder that is gone: the pair was checked and
    drawn, then the save failed and the verdict was never printed; now one line first, exit 2."""
    import stereovision.rectification_check

    def worked(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the pair was checked first")

    monkeypatch.setattr(stereovision.rectification_check, "check_rectification", worked)
    scene = data_dir / "eth3d" / "terrace"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    plot = tmp_path / "p.png"
    target = tmp_path / "gone" / "p.png"
    plot.symlink_to(target)
    assert main(["check", *pair, "--plot", str(plot)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == (
        f"stereovision: error: --plot {plot}: its folder {tmp_path}: p.png is a link to "
        f"{target}; cannot write {target}: directory {tmp_path / 'gone'} does not exist\n"
    )
    assert plot.is_symlink() and not (tmp_path / "gone").exists()


def test_rectify_refuses_a_folder_under_a_listed_output_before_the_work(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """An earlier rectify's right_rect.png (listed in its manifest) replaced by a folder: the
    rerun matched the pair and staged its images before finding it. Refused first, in the
    line commit_outputs gives, with the pair not matched and the folder as it was."""
    import stereovision.rectification_check

    scene = data_dir / "middlebury2001" / "tsukuba"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    out = tmp_path / "rect"
    assert main(["rectify", *pair, "-o", str(out)]) == 0
    (out / "right_rect.png").unlink()
    (out / "right_rect.png").mkdir()
    before = sorted(p.name for p in out.iterdir())
    capsys.readouterr()

    def worked(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the pair was matched first")

    monkeypatch.setattr(stereovision.rectification_check, "already_rectified", worked)
    assert main(["rectify", *pair, "-o", str(out)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == (
        f"stereovision: error: {out / 'right_rect.png'} is a folder, where the run's "
        "right_rect.png goes: move it away (the earlier outputs are kept as they were)\n"
    )
    assert sorted(p.name for p in out.iterdir()) == before


def test_demo_refuses_a_folder_under_a_listed_output_before_the_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """An earlier demo's cloud.ply (listed in its manifest) replaced by a folder: the rerun
    checked the scene's rows and matched it before finding it. Refused first, in the line
    commit_outputs gives, with no work done and the folder as it was."""
    import stereovision.rectification_check

    out = tmp_path / "demo"
    assert main(["demo", "--method", "fast", "-o", str(out)]) == 0
    (out / "cloud.ply").unlink()
    (out / "cloud.ply").mkdir()
    before = sorted(p.name for p in out.iterdir())
    capsys.readouterr()

    def worked(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the scene was checked first")

    monkeypatch.setattr(stereovision.rectification_check, "check_rectification", worked)
    assert main(["demo", "--method", "fast", "-o", str(out)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == (
        f"stereovision: error: {out / 'cloud.ply'} is a folder, where the run's cloud.ply goes: "
        "move it away (the earlier outputs are kept as they were)\n"
    )
    assert sorted(p.name for p in out.iterdir()) == before


def test_calib_help_lists_the_same_formats_for_every_command() -> None:
    """``--calib`` of stream, batch and gui listed fewer formats than depth's (no stereo_calib
    output, no Q.dat, no XML) though all read it with Calibration.from_file; ``calibrate -o``
    said .yaml/.json where .yml and .xml are written too."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    commands = sub.choices

    def option_help(command: str, option: str) -> str:
        return str(commands[command]._option_string_actions[option].help)

    formats = ("YAML/XML", "JSON", "calib.txt", "KITTI", "Kalibr", "camera_info", "stereo_calib")
    for command in ("depth", "stream", "batch", "gui"):
        said = option_help(command, "--calib")
        assert all(f in said for f in (*formats, "Q.dat", "calibrationdata.tar.gz")), said
    assert ".yaml, .yml, .xml or .json" in option_help("calibrate", "-o")
    # depth --rectification searches the range rectify stored (rect.max_disparity), which
    # --max-disparity's help said was estimated from the images
    assert option_help("depth", "--max-disparity").endswith(
        "(default: estimated from the images; with --rectification, the search range it holds)"
    )
    # so did stream's, its default estimated once "from the first pair" (run_stream: the
    # homographies' max_disparity)
    assert option_help("stream", "--max-disparity").endswith(
        "(default: estimated once, from the first pair; with --rectification, the search "
        "range it holds)"
    )


@pytest.mark.parametrize(
    ("given", "said"),
    [
        # argparse's own "expected one argument": a value starting with - is taken for an option
        (["--max-depth", "-5m"], "--max-depth: expected a number of metres above 0 without a unit"),
        (["--max-depth", "-5"], "--max-depth: expected a number of metres above 0, got '-5'"),
        (["--max-depth", "5m"], "--max-depth: expected a number of metres above 0 without a unit"),
        (["--max-depth=nan"], "--max-depth: expected a number of metres above 0, got 'nan'"),
        (["--max-sigma", "-0.1"], "--max-sigma: expected a number of metres above 0, got '-0.1'"),
        (["--voxel", "-1cm"], "--voxel: expected a number of metres above 0 without a unit"),
        (["--voxel", "1e400"], "--voxel: expected a number of metres above 0, got '1e400'"),
        (["--ground", "--grid", "5m"], "--grid: expected a number of metres without a unit"),
        (["--ground", "--grid", "-5m"], "--grid: expected a number of metres without a unit"),
        (["--max-disparity", "-64px"], "--max-disparity: expected a whole number of pixels"),
        (["-o", "-x"], "-o/--output: '-x' starts with '-' and was taken for an option; give it "),
    ],
)
def test_a_negative_or_unit_suffixed_metre_option_names_what_it_takes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], given: list[str], said: str
) -> None:
    """`depth L R --max-depth -5m` printed argparse's "expected one argument" and `5m` "expected
    a number": neither said the option takes a positive number of metres, without a unit. Each
    is one line naming the option, before any image is read; the output folder is untouched."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("kept")
    args = ["depth", str(CONES / "left.png"), str(CONES / "right.png"), "--calib", str(CONES)]
    if "-o" not in given:
        args += ["-o", str(out)]
    with pytest.raises(SystemExit) as exit_:
        main([*args, *given])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"stereovision depth: error: argument {said}"), err
    assert err.count("\n") == 1
    assert [p.name for p in out.iterdir()] == ["mine.txt"]


def test_a_negative_number_for_a_plain_float_option_says_how_to_give_it(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """`info --hfov -1e1` (no plain negative number to argparse) said "expected one argument".
    A negative --hfov is out of its range, said so (no use giving it as --hfov=-1e1); a turn
    of the view may be negative: how to give it."""
    with pytest.raises(SystemExit):
        main(["info", "--size", "640x480", "--baseline", "0.1", "--hfov", "-1e1"])
    assert capsys.readouterr().err == (
        "stereovision info: error: argument --hfov: expected a horizontal field of view from 0.1 "
        "to under 180 degrees, got '-1e1' (see stereovision info --help)\n"
    )
    with pytest.raises(SystemExit):
        main(["view", "cloud.ply", "--roll", "-1e1"])
    assert capsys.readouterr().err == (
        "stereovision view: error: argument --roll: '-1e1' starts with '-' and was taken for an "
        "option; give it as --roll=-1e1 (see stereovision view --help)\n"
    )


@pytest.mark.parametrize(
    ("given", "names"),
    [
        (["-o", "--calib", "rig.yaml"], "-o/--output"),
        (["--max-depth", "--voxel", "0.05"], "--max-depth"),
        (["--max-depth", "--calib=rig.yaml"], "--max-depth"),
        (["--max-depth", "--vox", "0.05"], "--max-depth"),
        (["--voxel", "-oout"], "--voxel"),
    ],
)
def test_an_option_whose_value_was_left_out_before_another_option_says_so(
    capsys: pytest.CaptureFixture[str], given: list[str], names: str
) -> None:
    """`depth L R -o --calib rig.yaml` (the folder left out) was told "'--calib' starts with '-'
    and was taken for an option; give it as --output=--calib", and `--max-depth --voxel 0.05`
    "expected a number of metres above 0, got '--voxel'": the next option was taken for a value
    typed with a '-'. The value is missing, as argparse says."""
    with pytest.raises(SystemExit) as exit_:
        main(["depth", str(CONES / "left.png"), str(CONES / "right.png"), *given])
    assert exit_.value.code == 2
    assert capsys.readouterr().err == (
        f"stereovision depth: error: argument {names}: expected one argument "
        "(see stereovision depth --help)\n"
    )


def test_a_folder_without_a_pair_given_as_the_images_says_what_was_looked_for(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`depth somefolder` said only "the following arguments are required: right", and
    `depth somefolder somefolder` "image file is not a regular file": neither said what was
    expected of the folder. Both name the files looked for."""
    folder = tmp_path / "shots"
    folder.mkdir()
    cv2.imwrite(str(folder / "a.png"), np.zeros((4, 4, 3), np.uint8))
    out = tmp_path / "out"
    looked = "looked for left.png + right.png or im0.png + im1.png, any image suffix"
    with pytest.raises(SystemExit):
        main(["depth", str(folder), "-o", str(out)])
    assert capsys.readouterr().err == (
        f"stereovision depth: error: the right image is missing; {folder} is a folder with no "
        f"pair in it ({looked}): give two image files, left and right (see stereovision depth "
        "--help)\n"
    )
    assert main(["depth", str(folder), str(folder), "-o", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: image file is not a regular file: {folder} (a folder with no pair "
        f"in it: {looked}; give two image files)\n"
    )
    assert not out.exists()


def test_a_folder_of_pairs_named_otherwise_given_as_the_images_is_no_folder_without_a_pair(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A folder holding one pair as capture saves it (left_0001.jpg + right_0001.jpg), or a
    calibration set (left01.jpg + right01.jpg, ...), was said to be "a folder with no pair in
    it": the pair is named as left.png + right.png are; the set is said to be pairs, for batch."""
    one, many = tmp_path / "one", tmp_path / "many"
    for folder, names in ((one, ["left_0001", "right_0001"]), (many, ["l01", "r01"])):
        folder.mkdir()
        for name in names:
            cv2.imwrite(str(folder / f"{name}.jpg"), np.zeros((4, 4, 3), np.uint8))
    for i in (1, 2, 3):  # right04 missing: 3 pairs, left04 alone
        for side in ("left", "right"):
            cv2.imwrite(str(many / f"{side}{i:02}.jpg"), np.zeros((4, 4, 3), np.uint8))
    cv2.imwrite(str(many / "left04.jpg"), np.zeros((4, 4, 3), np.uint8))
    out = tmp_path / "out"
    with pytest.raises(SystemExit):
        main(["depth", str(one), "-o", str(out)])
    assert capsys.readouterr().err == (
        f"stereovision depth: error: the right image is missing; {one} is a folder holding a "
        f"pair: give its two images, {one / 'left_0001.jpg'} and {one / 'right_0001.jpg'} (see "
        "stereovision depth --help)\n"
    )
    assert main(["depth", str(one), str(one), "-o", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: image file is not a regular file: {one} (a folder holding a pair: "
        f"give its two images, {one / 'left_0001.jpg'} and {one / 'right_0001.jpg'})\n"
    )
    many_said = "3 pairs: left01.jpg + right01.jpg, ...; stereovision batch takes such a folder"
    with pytest.raises(SystemExit):
        main(["depth", str(many), "-o", str(out)])
    assert capsys.readouterr().err == (
        f"stereovision depth: error: the right image is missing; {many} is a folder of "
        f"{many_said.replace(': ', ' (', 1)}): give two image files, left and right (see "
        "stereovision depth --help)\n"
    )
    assert main(["depth", str(many), str(many), "-o", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: image file is not a regular file: {many} (a folder of "
        f"{many_said}; give two image files)\n"
    )
    assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        # calibrate said its parameters' names (square_size:, unit:)
        (
            ["calibrate", "--left", "l*.png", "--right", "r*.png", "--square", "0", "-o", "c.yaml"],
            "stereovision: error: --square: expected a positive finite number, got 0.0",
        ),
        (
            ["calibrate", "--left", "l*.png", "--right", "r*.png", "--square", "1", "--unit",
             "parsec", "-o", "c.yaml"],
            "stereovision: error: --unit: expected one of ['m', 'mm', 'cm', 'ft', 'in'], got "
            "'parsec'",
        ),
        # "expected a number" did not say where the unit goes
        (
            ["board", "-o", "b.png", "--square", "25mm"],
            "stereovision board: error: argument --square: expected a number, its unit given by "
            "--unit (25 --unit mm), got '25mm' (see stereovision board --help)",
        ),
        (
            ["info", "--size", "640x480", "--hfov", "60", "--baseline", "10cm"],
            "stereovision info: error: argument --baseline: expected a number of metres without "
            "a unit (10 cm is 0.1 m: give 0.1), got '10cm' (see stereovision info --help)",
        ),
        # told to write --tolerance=-1px, which is no number either (then: no word of the unit)
        (
            ["check", "l.png", "r.png", "--tolerance", "-1px"],
            "stereovision check: error: argument --tolerance: expected a positive number of "
            "pixels without a unit (5 for 5 px), got '-1px' (see stereovision check --help)",
        ),
        # board --square 1e400: "got inf", after the parsing
        (
            ["board", "-o", "b.png", "--square", "1e400"],
            "stereovision board: error: argument --square: expected a positive finite number, "
            "got '1e400' (see stereovision board --help)",
        ),
        # capture --square 25mm: "expected a number"; nan: the library's "square_size:"
        (
            ["capture", "--left", "l.avi", "--right", "r.avi", "--charuco", "5x7", "--square",
             "25mm", "--marker", "18", "-o", "out"],
            "stereovision capture: error: argument --square: expected a side above 0 without a "
            "unit (25 for 25 mm; --square and --marker in one unit, any), got '25mm' (see "
            "stereovision capture --help)",
        ),
        (
            ["capture", "--left", "l.avi", "--right", "r.avi", "--charuco", "5x7", "--square",
             "25", "--marker", "nan", "-o", "out"],
            "stereovision capture: error: argument --marker: expected a side above 0 (--square "
            "and --marker in one unit, any), got 'nan' (see stereovision capture --help)",
        ),
        # a field of view of 1e-300 degrees was taken: a focal length of 7e305 px said, exit 0
        (
            ["info", "--size", "640x480", "--hfov", "1e-300", "--baseline", "0.1"],
            "stereovision info: error: argument --hfov: expected a horizontal field of view from "
            "0.1 to under 180 degrees, got '1e-300' (see stereovision info --help)",
        ),
        (
            ["info", "--size", "640x480", "--hfov", "90deg", "--baseline", "0.1"],
            "stereovision info: error: argument --hfov: expected a horizontal field of view from "
            "0.1 to under 180 degrees without a unit (5 for 5 degrees), got '90deg' (see "
            "stereovision info --help)",
        ),
        # "scene root not found" of a file that is there
        (
            ["bench", "{tmp}/notes.txt"],
            "stereovision: error: {tmp}/notes.txt: is a file; give a scene folder (holding "
            "left.png, right.png)",
        ),
        # run_batch's words: "grid: the occupancy grid lies on the floor; it needs ground=True"
        (
            ["batch", "{tmp}", "-o", "{tmp}/out", "--grid", "0.1"],
            "stereovision: error: --grid needs --ground (the grid lies on the floor)",
        ),
        (
            ["batch", "{tmp}", "-o", "{tmp}/out", "--ground", "--grid", "nan"],
            "stereovision: error: --grid: expected a cell side from 0.01 to 10 m, got nan",
        ),
        # --grid 1e400 was said as "got inf", 1e-400 as "got 0.0": as typed, by the parser
        (
            ["depth", "l.png", "r.png", "-o", "out", "--ground", "--grid", "1e400"],
            "stereovision depth: error: argument --grid: expected a cell side from 0.01 to 10 m, "
            "got '1e400' (see stereovision depth --help)",
        ),
        (
            ["depth", "l.png", "r.png", "-o", "out", "--ground", "--grid", "1e-400"],
            "stereovision depth: error: argument --grid: expected a cell side from 0.01 to 10 m, "
            "got '1e-400' (see stereovision depth --help)",
        ),
        # a ChArUco board's refusal named CharucoBoard's parameters (marker_size, square_size,
        # squares, dictionary) after "--board charuco:" (board, calibrate) / "--charuco:"
        (
            ["board", "-o", "b.png", "--board", "charuco", "--pattern", "10x7", "--square",
             "0.03", "--marker", "0.05"],
            "stereovision: error: --marker: 0.05 must be smaller than --square 0.03 (the marker "
            "sits inside a white square)",
        ),
        (
            ["board", "-o", "b.png", "--board", "charuco", "--pattern", "2x7", "--square",
             "0.03", "--marker", "0.02"],
            "stereovision: error: --pattern: expected a ChArUco board's squares as COLSxROWS, "
            "each at least 3 (e.g. 7x5), got '2x7'",
        ),
        (
            ["board", "-o", "b.png", "--board", "charuco", "--pattern", "20x20", "--square",
             "0.03", "--marker", "0.02", "--dictionary", "DICT_4X4_50"],
            "stereovision: error: --dictionary: DICT_4X4_50 has 50 markers, but a 20x20 board "
            "needs 200",
        ),
        (
            ["capture", "--left", "l.avi", "--right", "r.avi", "--charuco", "2x7", "--square",
             "30", "--marker", "20", "-o", "out"],
            "stereovision: error: --charuco: expected a ChArUco board's squares as COLSxROWS, "
            "each at least 3 (e.g. 7x5), got '2x7'",
        ),
        (
            ["capture", "--left", "l.avi", "--right", "r.avi", "--charuco", "10x7", "--square",
             "20", "--marker", "30", "-o", "out"],
            "stereovision: error: --marker: 30 must be smaller than --square 20 (the marker sits "
            "inside a white square)",
        ),
    ],
    ids=["calibrate-square", "calibrate-unit", "board-square", "info-baseline", "check-tolerance",
         "board-square-overflow",
         "capture-square-unit", "capture-marker-nan", "info-hfov-tiny", "info-hfov-unit",
         "bench-file", "batch-grid-ground", "batch-grid-range", "depth-grid-overflow",
         "depth-grid-underflow", "board-charuco-marker",
         "board-charuco-squares", "board-charuco-dictionary", "capture-charuco-squares",
         "capture-charuco-marker"],
)  # fmt: skip
def test_a_bad_option_value_is_said_in_the_option_s_name(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    argv: list[str],
    said: str,
) -> None:
    """The sweep of bad values at every command: each is one line naming the option as typed
    (not a library parameter) and what it takes, exit 2, nothing written."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "notes.txt").write_text("mine")
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    try:
        status = main(argv)
    except SystemExit as exit_:  # refused by argparse
        status = exit_.code
    assert status == 2
    assert capsys.readouterr().err == said.replace("{tmp}", str(tmp_path)) + "\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


@pytest.mark.parametrize(
    ("text", "hint"),
    [
        ("5M", "5 for 5 m"),
        ("2FT", "2 ft is 0.6096 m: give 0.6096"),
        (".5m", "5 for 5 m"),
        ("1e3mm", "1000 mm is 1 m: give 1"),
        ("+5m", "5 for 5 m"),
        ("5 cm", "5 cm is 0.05 m: give 0.05"),
        ('5"', "5 in is 0.127 m: give 0.127"),
        ("5'", "5 ft is 1.524 m: give 1.524"),
        ("-.5 in", "5 for 5 m"),
        ("5km", "5 for 5 m"),
    ],
)
def test_every_way_of_typing_a_unit_after_a_metre_value_is_told_to_leave_it_out(
    text: str, hint: str
) -> None:
    """A mutation audit found the unit pattern's cases untested: an upper-case unit, a value
    without its leading 0, an exponent, a '+' sign and inches (a ") each lost the "without a
    unit" hint, which said only "expected a number of metres". A length in feet, inches, cm or
    mm was told "(5 for 5 m)": --max-depth 5ft read as "type 5", 5 m for 1.5; such a length is
    now said in metres (the unit of every metre option, whatever depth --unit prints in)."""
    import argparse

    from stereovision.cli import metres, positive_metres

    for kind, above in ((positive_metres, " above 0"), (metres, "")):
        with pytest.raises(argparse.ArgumentTypeError) as err:
            kind(text)
        assert str(err.value) == (
            f"expected a number of metres{above} without a unit ({hint}), got {text!r}"
        )
    with pytest.raises(argparse.ArgumentTypeError) as err:  # a word is no unit-suffixed number
        positive_metres("far")
    assert str(err.value) == "expected a number of metres above 0, got 'far'"


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (
            ["depth", "l.png", "r.png", "--grid", "50ft"],
            "--grid: expected a number of metres "
            "without a unit (50 ft is 15.24 m, outside 0.01 to 10 m), got '50ft'",
        ),
        (
            ["depth", "l.png", "r.png", "--grid", "0.1in"],
            "--grid: expected a number of metres "
            "without a unit (0.1 in is 0.00254 m, outside 0.01 to 10 m), got '0.1in'",
        ),
        (
            ["depth", "l.png", "r.png", "--grid", "2ft"],
            "--grid: expected a number of metres "
            "without a unit (2 ft is 0.6096 m: give 0.6096), got '2ft'",
        ),
        (
            ["batch", "in", "out", "--grid", "50ft"],
            "--grid: expected a number of metres "
            "without a unit (50 ft is 15.24 m, outside 0.01 to 10 m), got '50ft'",
        ),
        (
            ["info", "--baseline", "4e6ft"],
            "--baseline: expected a number of metres without a "
            "unit (4e+06 ft is 1.2192e+06 m, outside 0 to 1e+06 m), got '4e6ft'",
        ),
        (
            ["view", "c.ply", "--up=-4e6ft", "-o", "s.png"],
            "--up: expected metres from -1e+06 "
            "to 1e+06 without a unit (-4e+06 ft is -1.2192e+06 m, outside -1e+06 to 1e+06 m), "
            "got '-4e6ft'",
        ),
    ],
)
def test_a_length_typed_in_feet_is_never_said_as_a_value_the_option_refuses(
    argv: list[str], said: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--grid 50ft`` was told "give 15.24", which --grid then refused (0.01 to 10 m): a length
    outside the option's range is said with the range, not as a value to give."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert capsys.readouterr().err == (
        f"stereovision {argv[0]}: error: argument {said} (see stereovision {argv[0]} --help)\n"
    )


@pytest.mark.parametrize(
    ("value", "hint"),
    [
        ("2ft", "2 ft is 0.6096 m: give 0.6096"),
        ("-2ft", "-2 ft is -0.6096 m: give -0.6096"),
        ("50cm", "50 cm is 0.5 m: give 0.5"),
        ("2m", "5 for 5 m"),
    ],
)
def test_a_view_move_typed_in_feet_is_said_in_metres(
    value: str, hint: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``view --forward 2ft`` was told "without a unit (5 for 5 m)", 2 m for 0.61; a move
    either way in another length unit is said in metres, as the metre options say it."""
    with pytest.raises(SystemExit) as exc:
        main(["view", "cloud.ply", f"--forward={value}", "-o", "shot.png"])
    assert exc.value.code == 2
    assert capsys.readouterr().err == (
        "stereovision view: error: argument --forward: expected metres from -1e+06 to 1e+06 "
        f"without a unit ({hint}), got '{value}' (see stereovision view --help)\n"
    )


def _number_options() -> list[tuple[str, str]]:
    """Every (command, option) of the CLI whose value is converted to a number."""
    import argparse

    from stereovision.capture import fourcc_code
    from stereovision.cli import build_parser, listen_address

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return [
        (name, action.option_strings[-1])
        for name, parser in sub.choices.items()
        for action in parser._actions
        # --fourcc's type checks four characters, not a number ('25mm' is a fourcc); --host's
        # that an address is given ('25mm' may be a host name)
        if action.option_strings
        and action.type not in (None, str, fourcc_code, listen_address)
        and action.nargs != 0
    ]


@pytest.mark.parametrize(("command", "option"), _number_options())
def test_every_number_option_tells_a_value_typed_with_a_unit_to_leave_it_out(
    capsys: pytest.CaptureFixture[str], command: str, option: str
) -> None:
    """``capture --square 25mm``, ``--fps 30fps``, ``--max-skew-ms 5ms``: only the metre
    options and ``board --square`` said where a unit goes; the others "expected a number". Each
    says it now in one line naming the option, exit 2."""
    assert len(_number_options()) >= 40  # the sweep holds the CLI's number options
    with pytest.raises(SystemExit) as exit_:
        main([command, f"{option}=25mm"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"error: argument {option}: expected " in err
    assert "without a unit" in err or "its unit given by --unit (25 --unit mm)" in err
    assert err.endswith(f", got '25mm' (see stereovision {command} --help)\n")


@pytest.mark.parametrize(
    ("hfov", "taken"),
    [("0.1", True), ("1", True), ("170", True), ("179.9", True), ("0.09", False),
     ("180", False), ("nan", False), ("-0", False), ("inf", False)],
)  # fmt: skip
def test_info_takes_every_real_lens_s_field_of_view_and_nothing_past_it(
    capsys: pytest.CaptureFixture[str], hfov: str, taken: bool
) -> None:
    """A 1-degree telephoto and a 170-degree wide lens are rigs on paper; 0.09 (focal length
    running away) and 180 (no pinhole's) are refused in one line with the range."""
    try:
        status = main(["info", "--size", "1280x720", "--hfov", hfov, "--baseline", "0.1"])
    except SystemExit as exit_:
        status = exit_.code
    out, err = capsys.readouterr()
    if taken:
        assert status == 0 and err == ""
        assert f"field of view {float(hfov):.1f} x " in out
    else:
        assert status == 2 and out == ""
        assert err == (
            "stereovision info: error: argument --hfov: expected a horizontal field of view "
            f"from 0.1 to under 180 degrees, got {hfov!r} (see stereovision info --help)\n"
        )


def test_a_value_starting_with_a_dash_is_told_in_the_options_long_form(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A mutation audit: the hint's `--output=-x` (the long name, which takes the `=` form
    whatever the value) was asserted only up to "give it"."""
    with pytest.raises(SystemExit):
        main(["depth", str(CONES / "left.png"), str(CONES / "right.png"), "-o", "-x"])
    assert capsys.readouterr().err == (
        "stereovision depth: error: argument -o/--output: '-x' starts with '-' and was taken "
        "for an option; give it as --output=-x (see stereovision depth --help)\n"
    )


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (
            ["info", "--size", "64x48", "--hfov", "60", "--baseline", "0.1",
             "--max-disparity=64"],
            "stereovision info: error: unrecognized arguments: --max-disparity=64 (see "
            "stereovision info --help)",
        ),
        (
            ["depth", "l.png", "r.png", "--maxdisparity=64", "-o", "out"],
            "stereovision depth: error: unrecognized arguments: --maxdisparity=64; did you mean "
            "--max-disparity? (see stereovision depth --help)",
        ),
        (
            ["depth", "l.png", "r.png", "extra.png", "-o", "out"],
            "stereovision depth: error: unrecognized arguments: extra.png (see stereovision "
            "depth --help)",
        ),
    ],
)  # fmt: skip
def test_a_word_no_option_took_is_refused_by_its_command_with_the_option_meant(
    capsys: pytest.CaptureFixture[str], argv: list[str], said: str
) -> None:
    """An option a command has not was "stereovision: error: unrecognized arguments: ... (see
    stereovision --help)", the command list's help, and a mistyped one was not named: the
    command refuses it, with the option that is close to it."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert capsys.readouterr().err == said + "\n"


def test_an_option_given_twice_the_last_without_its_value_says_expected_one_argument(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A mutation audit: only a value typed after the option with a '-' is the one argparse
    took for an option; the earlier `--max-depth 25` (a value without a '-') is no such value."""
    args = ["depth", str(CONES / "left.png"), str(CONES / "right.png")]
    with pytest.raises(SystemExit):
        main([*args, "--max-depth", "25", "--max-depth"])
    assert capsys.readouterr().err == (
        "stereovision depth: error: argument --max-depth: expected one argument "
        "(see stereovision depth --help)\n"
    )


def test_a_scene_folder_after_a_switch_is_still_said_to_be_a_folder_holding_a_pair(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A mutation audit: a switch (no value) before the folder, `depth --ground cones`, was not
    asserted; taken as an option with a value it hides the folder, and argparse's bare
    "required: right" is said."""
    with pytest.raises(SystemExit):
        main(["depth", "--ground", str(CONES)])
    err = capsys.readouterr().err
    assert err.startswith(
        f"stereovision depth: error: the right image is missing; {CONES} is a folder holding a "
        f"pair: give its two images, {CONES / 'left.png'} and {CONES / 'right.png'}"
    ), err


def test_mutation_audit_5_number_options_at_their_limits() -> None:
    """The limits of today's number options, at their edges: --hfov takes 0.1 and refuses 180,
    --max-skew-ms takes 0 and MAX_SKEW_MS, --read-timeout takes a day (86400 s) and refuses
    more. The mutation audit found the skew and timeout edges movable without a test failing
    (the hfov edges were pinned through info; here too, beside the others)."""
    import argparse

    from stereovision.cli import field_of_view, read_timeout_seconds, skew_ms
    from stereovision.rosbag import MAX_SKEW_MS

    assert field_of_view("0.1") == 0.1 and field_of_view("179.99") == 179.99
    assert skew_ms("0") == 0.0 and skew_ms(f"{MAX_SKEW_MS!r}") == MAX_SKEW_MS
    assert read_timeout_seconds("86400") == 86400.0
    for parse, text in (
        (field_of_view, "180"),
        (field_of_view, "0.0999"),
        (skew_ms, "-1e-9"),
        (skew_ms, f"{MAX_SKEW_MS * (1 + 1e-12)!r}"),
        (read_timeout_seconds, "86400.001"),
    ):
        with pytest.raises(argparse.ArgumentTypeError, match=re.escape(f"got {text!r}")):
            parse(text)


def test_mutation_audit_5_the_unit_hint_names_each_options_unit_and_none_for_a_count() -> None:
    """_with_unit_hint's example is the option's own unit (--dpi's dpi) and a count (--count)
    gets none: the sweep asserted only "without a unit", so a wrong unit or a "(5 for 5 None)"
    passed it."""
    from stereovision.cli import _with_unit_hint

    assert _with_unit_hint("argument --dpi: expected a number, got '300dpi'") == (
        "argument --dpi: expected a number without a unit (5 for 5 dpi), got '300dpi'"
    )
    assert _with_unit_hint("argument --count: expected an integer, got '10x'") == (
        "argument --count: expected an integer without a unit, got '10x'"
    )


@pytest.mark.parametrize("name", ["plot.jpg", "plot.GIF", "plot.pdf"])
def test_check_plot_refuses_a_name_of_another_format(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    """``check L R --plot plot.jpg`` wrote PNG bytes under a .jpg name (exit 0): now refused
    before the pair is read, one line, exit 2, nothing written. A .png name (any case) or one
    without a suffix still gets its PNG."""
    scene = data_dir / "middlebury2001" / "tsukuba"
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    plot = tmp_path / name
    assert main(["check", *pair, "--plot", str(plot)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        f"stereovision: error: --plot {plot}: the plot is written as PNG; give a .png file name\n"
    )
    assert list(tmp_path.iterdir()) == []
    for ok in ("plot.PNG", "plot"):
        assert main(["check", *pair, "--plot", str(tmp_path / ok)]) == 0
        assert (tmp_path / ok).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("command", ["capture", "stream", "gui"])
@pytest.mark.parametrize("code", ["MJPEG", "", "é123"])
def test_a_bad_fourcc_is_refused_in_the_options_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, code: str
) -> None:
    """``--fourcc MJPEG`` was said as the library's parameter (``fourcc: expected four
    characters ...``), after the parsing; argparse now refuses it as ``--fps`` and ``--size``
    are refused: ``argument --fourcc: ...``, one line, exit 2, nothing written."""
    argv = [command, "--left", "0", "--right", "1", "--fourcc", code]
    if command == "capture":
        argv += ["-o", str(tmp_path / "out")]
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    out, err = capsys.readouterr()
    assert out == "" and list(tmp_path.iterdir()) == []
    assert err == (
        f"stereovision {command}: error: argument --fourcc: expected four characters such as "
        f"'MJPG' or 'YUYV', got {code!r} (see stereovision {command} --help)\n"
    )


@pytest.mark.parametrize(
    "host",
    [
        "",
        " ",
        "127.0.0.1\n",
        "local host",
        "127.0.0.1\t",
        "[::1",
        "::1]",
        "[]",
        "[127.0.0.1]",
        "[[::1]]",
        "[::1]:8080",
        "[localhost]",
        "[fe80::1%]]",
        "[fe80::1%[lo]",
    ],
)
@pytest.mark.parametrize("command", ["stream", "gui"])
def test_an_empty_host_is_refused_in_the_options_name(
    capsys: pytest.CaptureFixture[str], command: str, host: str
) -> None:
    """``--host ""`` (an unset shell variable: ``--host "$HOST"``) served the view on every
    interface (0.0.0.0, the empty address of a bind), where the default serves this machine
    alone, and said it as ``http://:8765/``; it is refused by argparse now, before any camera
    opens: one line, exit 2. So is an address holding a space or a control character
    (``127.0.0.1\\n`` read from a file): it reached the bind, after the cameras opened, and
    the error was cut at its newline ('cannot serve the view on 127.0.0.1'). So is a bracket
    around no IPv6 address ('[::1', '[]', '[127.0.0.1]', '[::1]:8080'): no name holds one,
    and each was bound after the cameras opened ('Name or service not known'); nor does an
    IPv6 address's scope (ipaddress took '[fe80::1%]]' as fe80::1 scoped ']')."""
    with pytest.raises(SystemExit) as exit_:
        main([command, "--left", "0", "--right", "1", "--host", host])
    assert exit_.value.code == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err == (
        f"stereovision {command}: error: argument --host: expected an address to listen on "
        f"(127.0.0.1: this machine alone; 0.0.0.0: every interface), got {host!r} "
        f"(see stereovision {command} --help)\n"
    )


@pytest.mark.parametrize("command", ["stream", "gui"])
def test_a_bracketed_ipv6_host_is_the_address_inside(command: str) -> None:
    """``--host [::1]``, an IPv6 address as a URL writes it, was bound as a host name (not
    found: 'cannot serve the view on [[::1]]:8765: Name or service not known') and the gui
    said it 'http://[[::1]]:8080/'; the address inside is taken. An IPv4 address, a host
    name and an unbracketed IPv6 address are kept as given."""
    from stereovision.cli import build_parser

    base = [command, "--left", "0", "--right", "1", "--host"]
    for given, taken in [
        ("[::1]", "::1"),
        ("[::]", "::"),
        ("[fe80::1%lo]", "fe80::1%lo"),
        ("[::ffff:127.0.0.1]", "::ffff:127.0.0.1"),
        ("::1", "::1"),
        ("::ffff:127.0.0.1", "::ffff:127.0.0.1"),
        ("0.0.0.0", "0.0.0.0"),
        ("localhost", "localhost"),
    ]:
        assert build_parser().parse_args([*base, given]).host == taken


@pytest.mark.parametrize("command", ["depth", "batch", "stream"])
def test_fill_and_no_fill_together_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    """``depth L R -o OUT --fill --no-fill`` ran with the last one, the other ignored without
    a word (the README's usage has them as one or the other, ``[--fill|--no-fill]``); refused
    now by argparse in one line naming both, exit 2, nothing written. Either alone is taken."""
    argv = {
        "depth": ["depth", "l.png", "r.png", "-o", str(tmp_path / "out")],
        "batch": ["batch", str(tmp_path), "-o", str(tmp_path / "out")],
        "stream": ["stream", "--left", "0", "--right", "1"],
    }[command]
    with pytest.raises(SystemExit) as exit_:
        main([*argv, "--fill", "--no-fill"])
    assert exit_.value.code == 2
    out, err = capsys.readouterr()
    assert out == "" and list(tmp_path.iterdir()) == []
    assert err == (
        f"stereovision {command}: error: argument --no-fill: not allowed with argument --fill "
        f"(see stereovision {command} --help)\n"
    )
    from stereovision.cli import build_parser

    for flag, fill in (("--fill", True), ("--no-fill", False)):
        assert build_parser().parse_args([*argv, flag]).fill is fill


@pytest.mark.parametrize("command", ["depth", "rectify", "batch"])
def test_output_folder_dash_is_refused_not_made(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    command: str,
) -> None:
    """``-o -`` (standard output, to many tools) made a folder named "-" and exited 0; the
    outputs are a folder of files, so it is refused in one line before any work."""
    monkeypatch.chdir(tmp_path)
    scene = data_dir / "middlebury2001" / "tsukuba"
    inputs = (
        [str(scene)] if command == "batch" else [str(scene / n) for n in ("left.png", "right.png")]
    )
    assert main([command, *inputs, "-o", "-"]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err == (
        "stereovision: error: -o -: the outputs are files in a folder, not a stream for "
        "standard output: name a folder\n"
    )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("name", "shown"),
    [
        ("a\nb.png", "a\\nb.png"),  # was cut at the newline: "image file not found: a"
        ("a\tb.png", "a\\tb.png"),
        ("a\x1b[2Jb.png", "a\\x1b[2Jb.png"),  # an ESC sequence that would clear the terminal
        ("my scans/é 1.png", "my scans/é 1.png"),  # an ordinary path: as it is
    ],
)
def test_a_path_with_a_control_character_is_shown_escaped_on_one_line(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    name: str,
    shown: str,
) -> None:
    right = CONES / "right.png"
    monkeypatch.chdir(tmp_path)
    proc = _in_process(["depth", name, str(right), "-o", str(tmp_path / "d.png")], capsys)
    assert proc.returncode == 2
    assert proc.stderr == f"stereovision: error: image file not found: {shown}\n"


def test_a_path_with_a_newline_is_shown_escaped_in_a_warning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The warning line cut its message at the first newline: ``check a\\nb.png c\\nd.png``
    of one image twice warned ``stereovision: warning: a``, another file's name. The command
    line's paths are shown escaped, as in an error line, and the line is whole."""
    for name in ("a\nb.png", "c\nd.png"):
        (tmp_path / name).write_bytes((CONES / "left.png").read_bytes())
    monkeypatch.chdir(tmp_path)
    # one image twice cannot be told rectified or not (17c4983): exit 3, the warning still said
    assert main(["check", "a\nb.png", "c\nd.png"]) == 3
    assert capsys.readouterr().err == (
        "stereovision: warning: a\\nb.png and c\\nd.png are the same image: their rows agree "
        "by themselves (two views of the scene are needed)\n"
    )


def test_a_folder_with_a_newline_is_shown_escaped_in_an_argparse_error(tmp_path: Path) -> None:
    (tmp_path / "d\nx").mkdir()
    proc = subprocess.run(
        [*SV, "depth", "d\nx", "-o", str(tmp_path / "d.png")],
        capture_output=True,
        text=True,
        check=False,
        cwd=tmp_path,
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "; d\\nx is a folder with no pair" in proc.stderr


@pytest.mark.parametrize("command", ["depth", "batch", "rectify"])
@pytest.mark.usefixtures("in_process_dask")
def test_output_folder_dot_slash_dash_is_a_folder(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    command: str,
) -> None:
    """``-o ./-`` names a folder "-" as a path; the check took Path("./-"), which is
    Path("-"), for ``-o -`` and refused it (depth, rectify; batch's run its own way)."""
    monkeypatch.chdir(tmp_path)
    scene = data_dir / "middlebury2001" / "tsukuba"
    inputs = (
        [str(scene)] if command == "batch" else [str(scene / n) for n in ("left.png", "right.png")]
    )
    options = {"depth": ["--method", "fast"], "batch": ["--method", "fast", "--workers", "1"]}
    code = main([command, *inputs, "-o", "./-", *options.get(command, [])])
    err = capsys.readouterr().err
    assert "standard output" not in err
    assert code == 0, err
    made = tmp_path / "-" / ("tsukuba" if command == "batch" else "")
    assert (made / ("left_rect.png" if command == "rectify" else "disparity.png")).is_file()


def test_a_file_in_a_folder_named_dash_is_no_standard_output(
    data_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``check --plot=-/plot.png``'s folder is Path("-"), which the ``-o -`` check refused:
    "--plot -/plot.png: its folder -: ... not a stream for standard output"."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "-").mkdir()
    scene = data_dir / "middlebury2001" / "tsukuba"
    main(["check", str(scene / "left.png"), str(scene / "right.png"), "--plot=-/plot.png"])
    assert (tmp_path / "-" / "plot.png").is_file()


def test_eval_reports_the_same_members_whatever_the_method(data_dir: Path) -> None:
    """The members' depth report (algorithms.md D) of a run of another method came from a
    fusion run of its own that kept the members whose sub-pixel average left the range
    searched, which the fused run's (``depth_map``'s, ``match``'s) drop since c91b80d:
    playground at 17 px, 21 members more above 17 px for ``--method census``. The same
    members now, whatever the method."""
    import dataclasses

    from stereovision import cli
    from stereovision.io import load_scene

    scene = dataclasses.replace(load_scene(data_dir / "eth3d" / "playground"), max_disparity=17)
    fused = cli._eval_scene(scene, "fused", False)
    census = cli._eval_scene(scene, "census", False)
    assert fused["members_depth"]["n"] > 1000
    assert census["members_depth"] == fused["members_depth"]
    assert census["members_table1"] == fused["members_table1"]


def test_gui_port_and_stream_serve_refuse_a_port_in_the_same_words(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``gui --port 70000`` said "must be 1 to 65535, or 0 for a free one" and ``stream --serve
    70000`` "expected a port 0 to 65535 (0: any free one)": one wording for both now."""
    from stereovision import gui

    words = "expected a port 1 to 65535, or 0 for a free one, got 70000\n"
    assert gui.main(["--port", "70000"]) == 2
    assert capsys.readouterr().err == f"stereovision: error: --port: {words}"
    with pytest.raises(SystemExit):
        main(["stream", "--serve", "70000"])
    err = capsys.readouterr().err
    assert f"argument --serve: {words.rstrip()}" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize(
    ("argv", "name"),
    [
        (["depth", "left.png", "right.png", "-o", ""], "-o/--output"),
        (["depth", "left.png", "right.png", "--calib", "", "-o", "out"], "--calib"),
        (["batch", "", "-o", "out"], "input"),
        (["batch", ".", "-o", ""], "-o/--output"),
        (["eval", ".", ""], "scenes"),
        (["bench", ""], "scenes"),
        (["info", ""], "calib"),
        (["view", ""], "source"),
        (["calibrate", "--left", "", "--right", "r", "--square", "1", "-o", "r.yaml"], "--left"),
        (["gui", "--data", ""], "--data"),
    ],
)
def test_an_empty_path_is_refused_not_taken_as_the_current_folder(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    argv: list[str],
    name: str,
) -> None:
    """An empty value (``batch "$DATA" -o "$OUT"`` with a variable unset) was the current
    folder: ``batch ''`` processed the pair there, ``depth ... -o ''`` wrote its outputs there,
    ``--calib ''`` loaded the Q.dat found there, ``info ''`` described it. argparse refuses it
    now naming the argument, exit 2, before any work."""
    monkeypatch.chdir(tmp_path)
    img = np.zeros((20, 40), np.uint8)  # a scene in the current folder, which '' named
    for side in ("left", "right"):
        cv2.imwrite(str(tmp_path / f"{side}.png"), img)
    (tmp_path / "Q.dat").write_text("1 0 0 -5\n0 1 0 -4\n0 0 0 100\n0 0 10 0\n")
    before = sorted(tmp_path.iterdir())
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    out, err = capsys.readouterr()
    assert out == "" and sorted(tmp_path.iterdir()) == before
    assert err == (
        f"stereovision {argv[0]}: error: argument {name}: expected a value, got '' (an unset "
        f"variable?) (see stereovision {argv[0]} --help)\n"
    )


def test_rectify_keeps_a_16_bit_pair_at_16_bits(data_dir: Path, tmp_path: Path) -> None:
    """A 12-bit camera's pair in 16-bit PNGs: rectify read it with imread, its top 8 bits, and
    wrote those (0-4095 as 0-15 grey levels: the rest of the pair lost). It reads it as depth
    does and writes the rectified pair at 16 bits (here, a rectified crop, as given)."""
    cones = data_dir / "middlebury2003" / "cones"
    pair = [tmp_path / "left.png", tmp_path / "right.png"]
    for side, path in zip(("left", "right"), pair, strict=True):
        grey = cv2.imread(str(cones / f"{side}.png"), cv2.IMREAD_GRAYSCALE)[100:260, 100:340]
        cv2.imwrite(str(path), grey.astype(np.uint16) * 16 + 8)  # 12-bit values
    out = tmp_path / "rect"
    assert main(["rectify", *map(str, pair), "-o", str(out)]) == 0
    for name, given in zip(("left_rect.png", "right_rect.png"), pair, strict=True):
        written = cv2.imread(str(out / name), cv2.IMREAD_UNCHANGED)
        assert written.dtype == np.uint16
        grey = cv2.imread(str(given), cv2.IMREAD_ANYDEPTH)
        # one channel, as the file given (it was three equal ones, read_image's BGR)
        np.testing.assert_array_equal(written, grey)


def test_rectify_with_calib_writes_a_grey_pair_grey(tmp_path: Path) -> None:
    """A grey pair rectified by a calibration was written as 3-channel PNGs (read_image's BGR,
    three equal channels): each is now written with its file's one channel, the same values."""
    from stereovision.calibration import Calibration

    rng = np.random.default_rng(3)
    pair = [tmp_path / "left.png", tmp_path / "right.png"]
    for path in pair:
        assert cv2.imwrite(str(path), rng.integers(0, 256, (48, 64), dtype=np.uint8))
    k = np.array([[60.0, 0.0, 31.5], [0.0, 60.0, 23.5], [0.0, 0.0, 1.0]])
    tilt = cv2.Rodrigues(np.array([0.0, 0.05, 0.02]))[0]
    rig = Calibration(k, np.zeros(5), k.copy(), np.zeros(5), tilt, np.array([-0.1, 0.0, 0.0]),
                      image_size=(64, 48), unit="m")  # fmt: skip
    rig.save(tmp_path / "rig.yaml")
    argv = ["rectify", *map(str, pair), "--calib", str(tmp_path / "rig.yaml")]
    assert main([*argv, "-o", str(tmp_path / "rect")]) == 0
    bgr = [cv2.imread(str(path)) for path in pair]
    for name, want in zip(("left_rect.png", "right_rect.png"), rig.rectify(*bgr), strict=True):
        written = cv2.imread(str(tmp_path / "rect" / name), cv2.IMREAD_UNCHANGED)
        assert written.shape == (48, 64) and written.dtype == np.uint8
        np.testing.assert_array_equal(written, want[..., 0])


def test_rectify_suggests_a_depth_command_the_shell_reads_for_a_folder_with_a_space(
    crop_terrace: Callable[[slice, slice], Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """rectify prints the depth command to run on its rectified pair; its paths were printed
    as they are: `-o "my rect"` gave `stereovision depth my rect/left_rect.png ...`, which the
    shell splits into other words (a file `my` not found). They are quoted for the shell (the
    line without --calib, `Next: stereovision depth ...`, through the same helper)."""
    scene = crop_terrace(slice(117, 217), slice(206, 356))  # of eth3d/terrace, 150x100
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    out = tmp_path / "my rect"
    assert main(["rectify", *pair, "--calib", str(scene / "calib.txt"), "-o", str(out)]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if "stereovision depth " in s)
    words = shlex.split(line.split("stereovision depth ", 1)[1].split(" -o OUT")[0])
    names = ("left_rect.png", "right_rect.png", "--calib", "calib_rect.yaml")
    assert words == [n if n.startswith("-") else str(out / n) for n in names]
    assert all(Path(w).is_file() for w in words[:2] + words[3:])


def test_depth_lists_its_files_in_a_folder_named_with_a_newline_one_per_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """depth's list of the files written printed their paths as they are: -o 'o\\nut' cut each
    line in two ('  disparity.png  .../o' then 'ut/disparity.png'), where its errors and
    warnings show such a path escaped. Each file is now one line, the newline escaped."""
    rng = np.random.default_rng(0)
    left = (rng.random((32, 64)) * 255).astype(np.uint8)
    pair = [tmp_path / "left.png", tmp_path / "right.png"]
    cv2.imwrite(str(pair[0]), left)
    cv2.imwrite(str(pair[1]), np.roll(left, -3, axis=1))
    out = tmp_path / "o\nut"
    argv = ["depth", *map(str, pair), "--method", "fast", "--max-disparity", "8"]
    assert main([*argv, "-o", str(out)]) == 0
    listed = capsys.readouterr().out.splitlines()[1:]
    shown = str(out).replace("\n", "\\n")
    assert listed == [
        f"  {name:14s} {shown}/{name}"
        for name in ("disparity.png", "disparity.pfm", "overview.png")
    ]
    assert (out / "disparity.pfm").is_file()


def test_board_names_a_folder_with_a_newline_escaped_on_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """board's line of the file written (and of the one kept aside) printed its path as it is,
    as depth's list did before: -o 'o\\nut/board.png' cut the line in two ('.../o' then
    'ut/board.png: chessboard ...'), where its warnings show it escaped. One line now, the
    newline escaped; calibrate's and check --fix's "(the one it replaced kept as ...)" alike
    (io.replaced_words)."""
    from stereovision.io import replaced_words

    folder = tmp_path / "o\nut"
    folder.mkdir()
    shown = str(folder).replace("\n", "\\n")
    board = folder / "board.png"
    board.write_bytes(b"a picture of the user's")
    argv = ["board", "-o", str(board), "--pattern", "3x3", "--square", "0.01", "--dpi", "50"]
    assert main(argv) == 0
    assert capsys.readouterr().out.splitlines()[0] == (
        f"{shown}/board.png: chessboard 3x3 inner corners, square 0.01 m (the one it replaced "
        f"kept as {shown}/board.previous.png)"
    )
    assert replaced_words(folder / "rig.previous.yaml", True) == (
        f" (the one it replaced kept as {shown}/rig.previous.yaml)"
    )


def test_rectify_suggests_a_depth_command_on_one_line_for_a_folder_with_a_newline(
    crop_terrace: Callable[[slice, slice], Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """rectify's suggested depth command quoted its paths for the shell as they are: -o
    'o\\nut' cut it into four lines ("stereovision depth '.../o", "ut/left_rect.png' '.../o",
    ...), under a list of the files naming them escaped. Such a path is ANSI-C quoted now
    ($'.../o\\nut/left_rect.png'): one line, which bash reads as the files written."""
    scene = crop_terrace(slice(117, 217), slice(206, 356))  # of eth3d/terrace, 150x100
    pair = [str(scene / "left.png"), str(scene / "right.png")]
    out = tmp_path / "o\nut"
    assert main(["rectify", *pair, "--calib", str(scene / "calib.txt"), "-o", str(out)]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if "stereovision depth " in s)
    command = line.split("stereovision depth ", 1)[1].split(" -o OUT")[0]
    assert command.startswith(f"$'{str(out).replace(chr(10), chr(92) + 'n')}/left_rect.png' ")
    bash = shutil.which("bash")
    if bash is None:  # the line is checked above; bash reads it back
        return
    said = subprocess.run(
        [bash, "-c", f"printf '%s\\0' {command}"], capture_output=True, text=True, check=True
    )
    names = ("left_rect.png", "right_rect.png", "--calib", "calib_rect.yaml")
    assert said.stdout.split("\0")[:-1] == [n if n[0] == "-" else str(out / n) for n in names]


def test_a_suggested_command_names_a_path_past_ascii_as_its_utf8_bytes() -> None:
    """_shell_path ANSI-C quoted a C1 control (U+0085) as $'...\\x85...', which bash reads as
    the byte 0x85, not the character (UTF-8 c2 85): another file; and U+2028 as \\u2028, the
    character in a UTF-8 locale only. Both are their UTF-8 bytes now, read alike in any locale;
    a name's own backslash before "x85" stays the name's."""
    import os

    from stereovision.cli import _shell_path

    names = ["x\x85y", "a\u2028b", "c\\x85\nd"]
    quoted = [_shell_path(Path(n)) for n in names]
    assert quoted == ["$'x\\xc2\\x85y'", "$'a\\xe2\\x80\\xa8b'", "$'c\\\\x85\\nd'"]
    bash = shutil.which("bash")
    if bash is None:  # the quoting is checked above; bash reads it back
        return
    said = subprocess.run(
        [bash, "-c", f"printf '%s\\0' {' '.join(quoted)}"],
        capture_output=True,
        check=True,
        env={**os.environ, "LC_ALL": "C"},
    )
    assert said.stdout.split(b"\0")[:-1] == [n.encode("utf-8") for n in names]


def test_a_suggested_command_names_a_name_byte_that_is_not_utf8_as_that_byte() -> None:
    """escaped() shows a name's byte that is not UTF-8 (os.fsdecode's lone surrogate) as
    "\\udce9" (22cb4006); _shell_path then encoded that character as UTF-8, which cannot be:
    `rectify l.png r.png --calib q.dat -o $'r\\xe9'` wrote its files, then "stereovision: error:
    'utf-8' codec can't encode character '\\udce9'", exit 2, even in the C locale where it had
    printed. The $'...' word holds that byte, as bash reads back the name."""
    import os

    from stereovision.cli import _shell_path

    name = os.fsdecode(b"r\xe9/left_rect.png")
    assert _shell_path(Path(name)) == "$'r\\xe9/left_rect.png'"
    assert _shell_path(Path(os.fsdecode(b"-\xff a"))) == "$'./-\\xff a'"
