"""What ``stereovision depth -o DIR`` writes holds the returned DepthResult's values."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest

from stereovision import cli
from stereovision._interrupt import Terminated
from stereovision.calibration import Calibration
from stereovision.cli import depth_outputs, main
from stereovision.io import read_pfm, read_ply


@pytest.fixture(scope="module")
def terrace(crop_terrace: Callable[[slice, slice], Path]) -> Path:
    """A 300 x 200 crop of ETH3D terrace (conftest's crop_terrace): a real metric scene with
    its holes at a fifth of the pixels (the tests are not about the size)."""
    return crop_terrace(slice(200, 400), slice(300, 600))


def test_depth_files_hold_the_results_values(terrace: Path, tmp_path: Path) -> None:
    """On a real metric scene: disparity.pfm and depth.npy bit for bit (NaN where none),
    depth_mm.png to the millimetre (0 where none), cloud.ply the result's points and colours
    in its order, disparity.png black exactly where there is no disparity."""
    scene = terrace
    left, right = cv2.imread(str(scene / "left.png")), cv2.imread(str(scene / "right.png"))
    calib = Calibration.from_file(scene / "calib.txt")
    res, written = depth_outputs(left, right, calib, tmp_path, method="gabor", max_disparity=32)
    assert res.depth is not None and 0.5 < res.density < 1.0  # holes: NaN must round-trip
    disp = read_pfm(written["disparity.pfm"])
    np.testing.assert_array_equal(disp, res.disparity)  # NaN in the same places
    depth = np.load(written["depth.npy"])
    assert depth.dtype == np.float32
    np.testing.assert_array_equal(depth, res.depth)
    mm = cv2.imread(str(written["depth_mm.png"]), cv2.IMREAD_UNCHANGED)
    assert mm.dtype == np.uint16 and mm.shape == res.depth.shape
    known = np.isfinite(res.depth)
    np.testing.assert_array_equal(mm > 0, known)  # every depth of terrace is below 65.535 m
    assert np.abs(mm[known] / 1000.0 - res.depth[known]).max() <= 0.0005 + 1e-6
    pts, colors = read_ply(written["cloud.ply"])
    assert len(pts) == len(res.points) == known.sum()
    np.testing.assert_allclose(pts, res.points, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(colors, res.colors)
    # each point is its pixel's depth, along the optical axis
    x, y = res.pixels[:, 0], res.pixels[:, 1]
    np.testing.assert_allclose(pts[:, 2], res.depth[y, x], rtol=1e-5)
    png = cv2.imread(str(written["disparity.png"]))
    assert png.shape == left.shape
    np.testing.assert_array_equal(png.max(axis=2) == 0, ~np.isfinite(res.disparity))


@pytest.mark.parametrize("name", ["disparity.pfm", "depth.npy"])
def test_depth_files_are_the_filtered_results(terrace: Path, tmp_path: Path, name: str) -> None:
    """--max-depth: the written maps are the filtered result's, not the unfiltered one's."""
    scene = terrace
    left, right = cv2.imread(str(scene / "left.png")), cv2.imread(str(scene / "right.png"))
    calib = Calibration.from_file(scene / "calib.txt")
    res, written = depth_outputs(
        left, right, calib, tmp_path, method="fast", max_disparity=32, max_depth=4.0
    )
    assert res.depth is not None and np.nanmax(res.depth) <= 4.0
    got = read_pfm(written[name]) if name.endswith(".pfm") else np.load(written[name])
    want = res.disparity if name.endswith(".pfm") else res.depth
    np.testing.assert_array_equal(got, want)
    pts, _ = read_ply(written["cloud.ply"])
    assert len(pts) == len(res.points) and pts[:, 2].max() <= 4.0


def _files(folder: Path) -> dict[str, bytes]:
    """Every entry of ``folder`` (hidden ones too) by name: its bytes (a folder: b"<dir>")."""
    return {p.name: (b"<dir>" if p.is_dir() else p.read_bytes()) for p in sorted(folder.iterdir())}


def _terrace_argv(scene: Path, out: Path, calib: bool = True, max_disparity: int = 32) -> list[str]:
    argv = ["depth", str(scene / "left.png"), str(scene / "right.png")]
    argv += ["--max-disparity", str(max_disparity)]
    if calib:
        argv += ["--calib", str(scene / "calib.txt")]
    return [*argv, "-o", str(out)]


@pytest.mark.parametrize(
    ("exc", "status"),
    [(OSError("disk full"), 2), (KeyboardInterrupt(), 130), (Terminated("signal 15"), 143)],
)
def test_a_run_failing_midway_leaves_the_earlier_outputs_whole(
    terrace: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    exc: BaseException,
    status: int,
) -> None:
    """A run into a folder of an earlier run that fails (or is interrupted) in a later writer
    left its new disparity and depth files beside the earlier run's overview.png, render.png
    and cloud.ply, without a word. The files are written into a hidden folder first and moved in
    at the end: the earlier set stays byte for byte, manifest included, and no temporary
    folder is left."""
    out = tmp_path / "o"
    assert main(_terrace_argv(terrace, out)) == 0
    before = _files(out)
    assert "cloud.ply" in before and "overview.png" in before

    def fails(*args: object, **kwargs: object) -> None:
        raise exc

    monkeypatch.setattr(cli, "write_overview", fails)  # after the maps, the cloud, the render
    capsys.readouterr()
    # another run: no calibration, another range (other disparity bytes), a stale cloud.ply
    assert main(_terrace_argv(terrace, out, calib=False, max_disparity=48)) == status
    assert capsys.readouterr().err.startswith("stereovision: ")
    assert _files(out) == before


def test_a_new_folder_is_not_left_behind_by_a_failing_run(
    terrace: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The -o folder a failing run created is removed with its temporary folder (it was left,
    holding the files written before the error)."""
    out = tmp_path / "new" / "o"

    def fails(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "write_overview", fails)
    assert main(_terrace_argv(terrace, out)) == 130
    assert not out.exists()
    # the folders above it that the run made go too (new/ was left): tmp_path as it was
    assert not (tmp_path / "new").exists()
    # a path through ".." (mkdir -p makes new2/ and b/, not "new2/..")
    out = tmp_path / "new2" / ".." / "b"
    assert main(_terrace_argv(terrace, out)) == 130
    assert not (tmp_path / "new2").exists() and not (tmp_path / "b").exists()


def test_a_complete_run_replaces_the_whole_earlier_set(
    terrace: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A run that completes leaves exactly its own files, those a run into an empty folder
    writes, byte for byte: the earlier run's files it did not write removed (said), a file of
    the user's kept, no temporary folder."""
    out, fresh = tmp_path / "o", tmp_path / "fresh"
    assert main(_terrace_argv(terrace, out)) == 0
    (out / "notes.txt").write_text("mine")
    argv = _terrace_argv(terrace, out, calib=False)
    capsys.readouterr()
    assert main(argv) == 0
    said = capsys.readouterr().out
    assert main(_terrace_argv(terrace, fresh, calib=False)) == 0
    got = _files(out)
    assert got.pop("notes.txt") == b"mine"
    assert got == _files(fresh)
    assert sorted(got) == [
        ".stereovision-depth.json", "disparity.pfm", "disparity.png", "overview.png"
    ]  # fmt: skip
    for name in ("cloud.ply", "depth.npy", "depth.png", "depth_mm.png", "render.png"):
        assert f"  removed {name} of an earlier run (not written by this one)" in said


_SIGTERM_MIDWAY = """
import os, signal, sys
import stereovision.cli as cli
real = cli.write_overview
def write_overview(*args, **kwargs):
    os.kill(os.getpid(), signal.SIGTERM)  # the CLI's handler raises in here
    return real(*args, **kwargs)
cli.write_overview = write_overview
sys.exit(cli.main(sys.argv[1:]))
"""


def test_sigterm_while_writing_leaves_the_earlier_outputs_whole(
    terrace: Path, tmp_path: Path
) -> None:
    """SIGTERM (kill, a container's stop) arriving while the files are written (another
    range: other disparity bytes; no calibration: a stale cloud.ply): one line, exit 143, the
    earlier run's set as it was and no temporary folder."""
    out = tmp_path / "o"
    assert main(_terrace_argv(terrace, out)) == 0
    before = _files(out)
    proc = subprocess.run(
        [sys.executable, "-c", _SIGTERM_MIDWAY, *_terrace_argv(terrace, out, False, 48)],
        capture_output=True, text=True, check=False, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 143, proc.stderr
    assert proc.stderr == "stereovision: terminated (SIGTERM)\n"
    assert _files(out) == before


def test_a_folder_under_a_listed_output_name_is_refused_before_any_file_moves(
    terrace: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An earlier run's cloud.ply replaced by a folder of that name: the rerun wrote the new
    disparity and depth files, then failed at the cloud, leaving a mix. It is refused in one
    line naming the folder, before any file moves in."""
    out = tmp_path / "o"
    assert main(_terrace_argv(terrace, out)) == 0
    (out / "cloud.ply").unlink()
    (out / "cloud.ply").mkdir()
    before = _files(out)
    capsys.readouterr()
    assert main(_terrace_argv(terrace, out, max_disparity=48)) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {out / 'cloud.ply'} is a folder, where the run's cloud.ply goes: "
        "move it away (the earlier outputs are kept as they were)\n"
    )
    assert _files(out) == before


def test_a_folder_under_a_listed_output_name_is_refused_before_the_matching(
    terrace: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """An earlier run's depth.png replaced by a folder of that name (listed in the manifest, so
    not the user's file): the pair was matched and every file written into the hidden folder
    before the folder was found. Refused first, in the same line, with no matching done."""
    import stereovision.depth

    out = tmp_path / "o"
    assert main(_terrace_argv(terrace, out)) == 0
    (out / "depth.png").unlink()
    (out / "depth.png").mkdir()
    before = _files(out)
    capsys.readouterr()

    def matched(*args: object, **kwargs: object) -> None:
        raise AssertionError("the pair was matched before the outputs were checked")

    monkeypatch.setattr(stereovision.depth, "depth_map", matched)
    assert main(_terrace_argv(terrace, out, max_disparity=48)) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {out / 'depth.png'} is a folder, where the run's depth.png goes: "
        "move it away (the earlier outputs are kept as they were)\n"
    )
    assert _files(out) == before


@pytest.mark.skipif(sys.platform == "win32", reason="no flock: the folders are left there")
def test_a_killed_runs_hidden_folder_is_removed_by_the_next_run(
    terrace: Path, tmp_path: Path
) -> None:
    """A run killed outright (SIGKILL, power loss) left its .stereovision-partial-* folder,
    4 MB of half-written files, in -o for good: no later run removed it. The next run removes
    such a folder that no running process holds; one a run in progress holds stays."""
    import fcntl
    import os

    out = tmp_path / "o"
    orphan = out / f"{cli.STAGING_PREFIX}dead1234"
    orphan.mkdir(parents=True)
    (orphan / "disparity.png").write_bytes(b"half")
    busy = out / f"{cli.STAGING_PREFIX}busy1234"
    busy.mkdir()
    fd = os.open(busy, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # as a run in progress holds its own
        assert main(_terrace_argv(terrace, out)) == 0
        hidden = sorted(p.name for p in out.iterdir() if p.name.startswith(cli.STAGING_PREFIX))
        assert hidden == [busy.name]
    finally:
        os.close(fd)
