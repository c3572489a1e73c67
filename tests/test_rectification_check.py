"""check_rectification: the row alignment of real pairs, as given and with the rig disturbed."""

from __future__ import annotations

import dataclasses
import json
import re
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

import stereovision as sv
from stereovision.calibration import Calibration
from stereovision.io import imread
from stereovision.rectification_check import (
    MIN_MATCHES,
    RectificationCheck,
    _judge_rows,
    check_rectification,
    refine_rectification,
)
from tests.test_calibration import stereopi_calib

SV = [sys.executable, "-m", "stereovision.cli"]


def _pair(data_dir: Path, scene: str) -> tuple[np.ndarray, np.ndarray]:
    return imread(data_dir / scene / "left.png"), imread(data_dir / scene / "right.png")


def _warp(img: np.ndarray, m: np.ndarray) -> np.ndarray:
    h, w = img.shape[:2]
    return cv2.warpAffine(img, m, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


@pytest.mark.parametrize(
    "scene",
    [
        "middlebury2003/cones",
        "eth3d/terrace",
        "kitti2015/000005_10",
        "tartanair/oldtown_easy_p000_001116",
    ],
)
def test_rectified_scenes_pass_and_a_one_pixel_drift_fails(data_dir: Path, scene: str) -> None:
    """Measured on the 17 GT scenes of ../shared/data as given: median |dy| 0.06-0.24 px; with
    the right image 1 px lower, the offset moves by -0.95 to -1.02 px and every verdict is
    False."""
    left, right = _pair(data_dir, scene)
    res = check_rectification(left, right)
    assert res.ok is True and res.matches >= 200
    assert res.median_dy < 0.3 and abs(res.offset) < 0.3
    assert check_rectification(left, right) == res  # deterministic
    low = check_rectification(left, _warp(right, np.float32([[1, 0, 0], [0, 1, 1.0]])))
    assert low.ok is False and low.offset - res.offset == pytest.approx(-1.0, abs=0.15)
    assert low.median_dy > 0.8


def test_a_roll_is_measured_as_a_slope(data_dir: Path) -> None:
    """KITTI's right image turned 0.2 degrees: the row offset changes by tan(0.2 deg) = 3.49 px
    per 1000 px across the image (measured 3.11); 1242 px wide, the median |dy| exceeds 0.5."""
    left, right = _pair(data_dir, "kitti2015/000005_10")
    h, w = right.shape[:2]
    res = check_rectification(
        left, _warp(right, cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), 0.2, 1.0))
    )
    assert res.slope_x == pytest.approx(1000 * np.tan(np.radians(0.2)), abs=0.6)
    assert res.ok is False


def test_large_images_are_checked_on_a_smaller_copy(data_dir: Path) -> None:
    """At 2484x750 SIFT runs on a 1600 px copy; the offset is still found in full-size pixels."""
    left, right = _pair(data_dir, "kitti2015/000005_10")
    big = [cv2.resize(im, None, fx=2, fy=2, interpolation=cv2.INTER_CUBIC) for im in (left, right)]
    res = check_rectification(big[0], big[1])
    assert res.ok is True and res.median_dy < 0.5
    low = check_rectification(big[0], _warp(big[1], np.float32([[1, 0, 0], [0, 1, 2.0]])))
    # KITTI's own rows are 0.24 px apart (0.48 px at this size): the 2 px come on top
    assert low.offset - res.offset == pytest.approx(-2.0, abs=0.2) and low.ok is False


def test_a_raw_rig_with_its_calibration_and_with_a_bumped_one(data_dir: Path) -> None:
    """The StereoPi scene: raw 0.59 px median |dy| (not rectified), 0.30 px through its own
    calibration; the right camera pitched by 0.25 degrees more gives a 1.9 px offset."""
    cal = stereopi_calib(data_dir)
    left, right = _pair(data_dir, "stereopi_rig/scene_photo")
    assert check_rectification(left, right).ok is False
    good = check_rectification(left, right, cal)
    assert good.ok is True and good.median_dy < 0.4
    bump = cv2.Rodrigues(np.array([np.radians(0.25), 0.0, 0.0]))[0]
    bad = check_rectification(left, right, dataclasses.replace(cal, R=bump @ cal.R))
    assert bad.ok is False and bad.offset == pytest.approx(-1.9, abs=0.4)


def _opencv_mutual_matches(da: np.ndarray, db: np.ndarray) -> np.ndarray:
    """The check's matching as it was: BFMatcher's knnMatch both ways, ratio 0.75."""
    bf = cv2.BFMatcher(cv2.NORM_L2)
    back = {m[0].queryIdx: m[0].trainIdx for m in bf.knnMatch(db, da, k=1) if m}
    pairs = [
        (m[0].queryIdx, m[0].trainIdx)
        for m in bf.knnMatch(da, db, k=2)
        if m[0].distance < 0.75 * m[1].distance and back.get(m[0].trainIdx) == m[0].queryIdx
    ]
    return np.array(pairs, dtype=np.intp).reshape(-1, 2)


def test_mutual_matches_are_opencvs_without_its_matcher(monkeypatch: pytest.MonkeyPatch) -> None:
    """BFMatcher's two passes took 0.68 s CPU of KITTI's 1.25 s check; one matrix product of
    SIFT's whole-number descriptors gives its matches exactly (0.25 s; the same on the 19 data
    scenes). Here on descriptors made of a few repeated ones (exact ties, which OpenCV breaks to
    the first index), of 0 and 255 (distances whose float32 square roots collide) and over
    more rows than one block; descriptors that are not whole numbers still go through it."""
    from stereovision import rectification_check as rc

    rng = np.random.default_rng(0)
    cases = []
    for top, n in ((2, 1100), (255, 400)):
        base = rng.integers(0, 2, (150, 128)).astype(np.float32) * top
        # repeated rows on both sides: ties of the nearest one way and the other
        da, db = base[rng.integers(0, 150, n)], base[rng.integers(0, 150, 200)]
        i, j = rng.integers(0, n, n), rng.integers(0, 128, n)
        da[i, j] = np.abs(da[i, j] - 1)  # and near ties
        cases.append((da, db, _opencv_mutual_matches(da, db)))
    frac = rng.random((200, 128)).astype(np.float32)
    frac_want = _opencv_mutual_matches(frac, frac[::-1].copy())

    def no_matcher(*a: object) -> None:
        raise AssertionError("BFMatcher used")

    monkeypatch.setattr(cv2, "BFMatcher", no_matcher)
    for da, db, want in cases:
        assert len(want) > 5 and np.array_equal(rc._mutual_matches(da, db), want)
    monkeypatch.undo()
    assert np.array_equal(rc._mutual_matches(frac, frac[::-1].copy()), frac_want)


def test_swapped_flat_and_unaligned_pairs(data_dir: Path) -> None:
    left, right = _pair(data_dir, "middlebury2003/cones")
    swapped = check_rectification(right, left)
    assert swapped.swapped and swapped.ok is False and "swapped" in swapped.summary()
    flat = np.full((240, 320), 128, np.uint8)
    none = check_rectification(flat, flat)
    assert none.ok is None and none.matches < MIN_MATCHES and "cannot tell" in none.summary()
    upside = check_rectification(left, np.ascontiguousarray(left[::-1]))
    assert upside.ok is False and not upside.swapped and upside.median_dy > 50
    assert json.dumps(upside.as_dict())  # NaN fields become null
    res = check_rectification(left, right)
    assert res.points.shape == (res.matches, 4)
    dy = res.points[:, 1] - res.points[:, 3]
    assert float(np.median(np.abs(dy))) == pytest.approx(res.median_dy, abs=1e-5)
    with pytest.raises(ValueError, match="tolerance"):
        check_rectification(left, right, tolerance=0)
    with pytest.raises(ValueError, match="left is"):
        check_rectification(left, right[:-1])
    assert sv.check_rectification is check_rectification


def test_cli_check(data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from stereovision.cli import main  # in-process but for the refusal's exit 2 and one line

    cones = data_dir / "middlebury2003" / "cones"
    code = main(["check", str(cones / "left.png"), str(cones / "right.png")])
    out = capsys.readouterr().out
    assert code == 0 and out.startswith("rectification ok: median |dy| 0.")
    left = cv2.imread(str(cones / "right.png"))
    cv2.imwrite(str(tmp_path / "low.png"), _warp(left, np.float32([[1, 0, 0], [0, 1, 1.5]])))
    code = main(["check", str(cones / "left.png"), str(tmp_path / "low.png"), "--json"])
    assert code == 1
    out = json.loads(capsys.readouterr().out)
    assert out["ok"] is False and out["offset"] == pytest.approx(-1.5, abs=0.3)
    assert "points" not in out
    plot = tmp_path / "check.png"
    code = main(["check", str(cones / "left.png"), str(cones / "right.png"), "--plot", str(plot)])
    assert code == 0
    img = cv2.imread(str(plot))
    assert img.shape[1] == 900 and img.shape[0] > 375
    # the summary band on top, then the pair with green dots (matches within tolerance)
    pair = img[-375:]
    green = (pair[..., 1] > 150) & (pair[..., 0] < 80) & (pair[..., 2] < 80)
    assert green[:, :450].sum() > 500 and green[:, 450:].sum() > 500
    run = subprocess.run(
        [*SV, "check", str(cones / "left.png"), str(tmp_path / "none.png")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2 and run.stderr.count("\n") == 1 and "none.png" in run.stderr


def _rig(w: int, h: int, rvec_deg: tuple[float, float, float], f: float = 700.0) -> Calibration:
    """A raw-rig calibration for a rectified scene, its right camera turned by ``rvec_deg``."""
    k = np.array([[f, 0.0, (w - 1) / 2], [0.0, f, (h - 1) / 2], [0.0, 0.0, 1.0]])
    rot = cv2.Rodrigues(np.radians(np.array(rvec_deg, dtype=np.float64)))[0]
    return Calibration(
        K1=k,
        D1=np.zeros(5),
        K2=k,
        D2=np.zeros(5),
        R=rot,
        T=np.array([-0.1, 0.0, 0.0]),
        image_size=(w, h),
        unit="m",
    )


def _deg(rot: np.ndarray) -> float:
    return float(np.degrees(np.linalg.norm(cv2.Rodrigues(rot)[0])))


@pytest.mark.parametrize("scene", ["middlebury2003/cones", "eth3d/terrace"])
@pytest.mark.parametrize("turn", [(0.3, 0.0, 0.0), (0.0, 0.0, 0.3), (0.2, 0.0, -0.2)])
def test_refine_turns_the_rig_back(data_dir: Path, scene: str, turn: tuple) -> None:
    """A rectified scene seen through a calibration that says the right camera is pitched or
    rolled by 0.3 degrees: rows 0.49-3.9 px apart; refined, within 0.15 px, and the rig's
    rotation is back to the identity within 0.03 degrees (benches/bench_rectification.py)."""
    left, right = _pair(data_dir, scene)
    h, w = left.shape[:2]
    bumped = _rig(w, h, turn)
    before = check_rectification(left, right, bumped)
    fixed, after = refine_rectification(left, right, bumped)
    assert after.ok is True and after.median_dy < 0.15
    assert before.median_dy > 0.45 and before.median_dy > 4 * after.median_dy
    assert _deg(fixed.R) < 0.03
    assert np.linalg.norm(fixed.T) == pytest.approx(0.1, rel=1e-12)  # the baseline's length


def test_refine_cannot_see_a_yaw(data_dir: Path) -> None:
    """A turn about the vertical axis moves disparities, not rows: the check passes, and the
    correction leaves the yaw (0.5 degrees) as it was."""
    left, right = _pair(data_dir, "middlebury2003/cones")
    h, w = left.shape[:2]
    yawed = _rig(w, h, (0.0, 0.5, 0.0))
    assert check_rectification(left, right, yawed).ok is True
    fixed, after = refine_rectification(left, right, yawed)
    assert after.ok is True and _deg(fixed.R) == pytest.approx(0.5, abs=0.05)


def test_refine_a_raw_rig_beyond_its_own_calibration(data_dir: Path) -> None:
    """The StereoPi rig pitched 0.5 degrees more (3.24 px): refined to 0.23 px, below its own
    calibration's 0.30 px, and within 0.1 degrees of its rotation (measured 0.098)."""
    cal = stereopi_calib(data_dir)
    left, right = _pair(data_dir, "stereopi_rig/scene_photo")
    bump = cv2.Rodrigues(np.array([np.radians(0.5), 0.0, 0.0]))[0]
    fixed, after = refine_rectification(left, right, dataclasses.replace(cal, R=bump @ cal.R))
    assert after.ok is True and after.median_dy <= check_rectification(left, right, cal).median_dy
    assert _deg(fixed.R @ cal.R.T) < 0.12


def test_refine_refuses_what_is_not_a_drift(data_dir: Path) -> None:
    left, right = _pair(data_dir, "middlebury2003/cones")
    h, w = left.shape[:2]
    with pytest.raises(ValueError, match="more than a drift"):
        refine_rectification(left, right, _rig(w, h, (4.0, 0.0, 0.0), f=300.0))
    flat = np.full((h, w), 128, np.uint8)
    with pytest.raises(ValueError, match="cannot refine: rectification: cannot tell"):
        refine_rectification(flat, flat, _rig(w, h, (0.3, 0.0, 0.0)))
    with pytest.raises(ValueError, match="swapped"):
        refine_rectification(right, left, _rig(w, h, (0.3, 0.0, 0.0)))


def test_cli_check_fix(data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from stereovision.cli import main  # in process: main returns the exit status, 2 a refusal

    cones = data_dir / "middlebury2003" / "cones"
    img = cv2.imread(str(cones / "left.png"))
    bumped = _rig(img.shape[1], img.shape[0], (0.3, 0.0, 0.0)).save(tmp_path / "rig.yaml")
    pair = [str(cones / "left.png"), str(cones / "right.png")]
    fixed = tmp_path / "fixed.yaml"
    code = main(["check", *pair, "--calib", str(bumped), "--fix", str(fixed)])
    said = capsys.readouterr()
    assert code == 0, said.err
    lines = said.out.splitlines()
    assert lines[0].startswith("pair NOT rectified")
    assert lines[1].startswith("corrected (the right camera turned 0.29")
    assert "rectification ok" in lines[1] and lines[2].endswith(str(fixed))
    code = main(["check", *pair, "--calib", str(fixed)])
    assert code == 0 and capsys.readouterr().out.startswith("rectification ok")
    code = main(["check", *pair, "--fix", str(tmp_path / "x.yaml")])
    assert code == 2 and "--fix needs --calib" in capsys.readouterr().err
    # --fix naming the calibration it corrects replaced the original: refused, the file kept
    before = bumped.read_bytes()
    code = main(["check", *pair, "--calib", str(bumped), "--fix", str(bumped)])
    said = capsys.readouterr()
    assert code == 2 and said.out == ""
    assert said.err == (
        f"stereovision: error: --fix {bumped}: is the calibration ({bumped}); give another "
        "file name\n"
    )
    assert bumped.read_bytes() == before
    # a failed check says what to do, as the rig has a calibration or not
    code = main(["check", *pair, "--calib", str(bumped)])
    assert code == 1 and "recalibrate, or correct the right camera" in capsys.readouterr().out
    down = np.float32([[1, 0, 0], [0, 1, 2]])  # the right image 2 px lower
    right = cv2.warpAffine(cv2.imread(pair[1]), down, img.shape[1::-1])
    cv2.imwrite(str(tmp_path / "low.png"), right)
    code = main(["check", pair[0], str(tmp_path / "low.png")])
    out = capsys.readouterr().out
    assert code == 1 and out.startswith("pair NOT rectified:")
    assert "give the rig's calibration (--calib), or rectify them" in out
    assert "recalibrate" not in out


def test_cli_check_cannot_tell(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A pair too plain to judge: exit 3 (not 1, a verdict on the rig, nor 2, an error), with
    and without --fix; --fix says in one line that it wrote nothing, and writes nothing. In
    process (main returns the exit status), but for --help, which exits as argparse's does."""
    from stereovision.cli import main

    flat, flat_r = tmp_path / "flat.png", tmp_path / "flat_r.png"  # one file twice warns
    cv2.imwrite(str(flat), np.full((375, 450), 128, np.uint8))
    cv2.imwrite(str(flat_r), np.full((375, 450), 130, np.uint8))
    rig = _rig(450, 375, (0.3, 0.0, 0.0)).save(tmp_path / "rig.yaml")
    fixed = tmp_path / "fixed.yaml"
    for extra in ([], ["--fix", str(fixed)], ["--json", "--fix", str(fixed)]):
        code = main(["check", str(flat), str(flat_r), "--calib", str(rig), *extra])
        run = capsys.readouterr()
        assert code == 3, (extra, run.err)
        out = json.loads(run.out) if "--json" in extra else run.out
        if "--json" in extra:
            assert out["ok"] is None and out["matches"] == 0
        else:
            assert out.startswith("rectification: cannot tell, only 0 feature matches")
        if extra:
            assert run.err == (
                f"stereovision: not corrected, nothing written to {fixed}: too little texture "
                "to tell the rows (give a textured pair)\n"
            )
        else:
            assert run.err == ""
        assert not fixed.exists()
    run = subprocess.run([*SV, "check", "--help"], capture_output=True, text=True, timeout=120)
    assert "3 when the pair has too little texture to tell" in " ".join(run.stdout.split())


#: The end of check --fix's lines that write nothing, of cones (rectified) through a raw rig.
CONES_AS_GIVEN = (
    "; but the images as given have rows that agree already (rows median |dy| 0.09 px over 523 "
    "matches, tolerance 0.5): if they are rectified images (rectify's left_rect.png, a camera's "
    "image_rect), the raw rig's calibration rectifies them again: give the raw images"
)


def test_cli_check_fix_says_once_what_it_cannot_correct(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--fix on a pair that fails the check in a way no drift explains: exit 1 (a verdict), not
    2 (an error), and one line after the check's, not the check's line again as an error. Cones
    as given is rectified: the line says that the raw rig's calibration may rectify it twice
    (it said "calibrate the rig again" alone); not of a swapped pair. In process: main returns
    the exit status."""
    from stereovision.cli import main

    cones = data_dir / "middlebury2003" / "cones"
    pair = [str(cones / "left.png"), str(cones / "right.png")]
    fixed = tmp_path / "fixed.yaml"
    cases = (
        (pair[::-1], (0.3, 0.0, 0.0), 700.0, "rectification: the left and right images look "
         "swapped", "the left and right images look swapped: give them the other way round"),
        (pair, (4.0, 0.0, 0.0), 300.0, "pair NOT rectified: median |dy| 23.",
         "the rows need the right camera turned by 4.0 degrees, more than a drift (at most 3): "
         f"calibrate the rig again{CONES_AS_GIVEN}"),
    )  # fmt: skip
    for images, turn, f, said, why in cases:
        rig = _rig(450, 375, turn, f=f).save(tmp_path / "rig.yaml")
        code = main(["check", *images, "--calib", str(rig), "--fix", str(fixed)])
        run = capsys.readouterr()
        assert code == 1, run.err
        assert run.out.startswith(said) and run.out.count("\n") == 1
        assert run.err == f"stereovision: not corrected, nothing written to {fixed}: {why}\n"
        assert not fixed.exists()


def test_align_rows_undoes_a_row_offset(data_dir: Path) -> None:
    """Cones with the right image 1.5 px lower and turned 0.2 degrees: aligned, the rows are
    back within 0.15 px; the left image (the disparity's frame) is untouched."""
    from stereovision.rectification_check import align_rows

    left, right = _pair(data_dir, "middlebury2003/cones")
    h, w = right.shape[:2]
    m = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), 0.2, 1.0)
    m[1, 2] += 1.5
    moved = _warp(right, m)
    aligned, before = align_rows(left, moved)
    assert before.ok is False and aligned.shape == moved.shape and aligned.dtype == np.uint8
    after = check_rectification(left, aligned)
    assert after.ok is True and after.median_dy < 0.15 and abs(after.offset) < 0.15
    # a float16 image (OpenCV's remap refuses it) is aligned the same and stays float16
    half, _ = align_rows(left, (moved / 255).astype(np.float16), check=before)
    assert half.dtype == np.float16
    assert np.abs(half.astype(np.float32) * 255 - aligned).mean() < 0.6
    flat = np.full((h, w), 100, np.uint8)
    same, res = align_rows(flat, flat)
    assert res.ok is None and same is not None and np.array_equal(same, flat)


def test_align_rows_keeps_a_float_pair_in_its_range(data_dir: Path) -> None:
    """A float [0, 1] pair with saturated parts (cones, contrast doubled, the right image
    1.5 px lower): bicubic overshot the edges to -0.063 .. 1.120, and depth_map refused the
    aligned image it had been handed ("float image values must lie in [0, 1]"). It is clipped
    to the right image's own range; the rows are aligned as before."""
    from stereovision.rectification_check import align_rows

    left, right = _pair(data_dir, "middlebury2003/cones")
    m = np.float64([[1, 0, 0], [0, 1, 1.5]])
    grey = [cv2.cvtColor(im, cv2.COLOR_BGR2GRAY) if im.ndim == 3 else im for im in (left, right)]
    lf, rf = (np.clip(g.astype(np.float32) / 255 * 2 - 0.3, 0, 1) for g in grey)
    rf = _warp(rf, m)
    aligned, before = align_rows(lf, rf)
    assert before.ok is False and aligned.dtype == np.float32
    assert aligned.min() == 0.0 and aligned.max() == 1.0
    after = check_rectification(lf, aligned)
    assert after.ok is True and abs(after.offset) < 0.15
    res = sv.depth_map(lf, aligned, max_disparity=64)
    assert np.isfinite(res.disparity).mean() > 0.5


def test_align_rows_on_kitti(data_dir: Path) -> None:
    """KITTI's rectified pair has its rows 0.24 px apart (offset -0.24 px, slopes -0.34 and
    -0.51 px per 1000 px): aligned, the default depth map's bad-2.0 falls 13.18 -> 10.81 %."""
    from stereovision.evaluate import dense_metrics
    from stereovision.io import load_scene
    from stereovision.rectification_check import align_rows

    s = load_scene(data_dir / "kitti2015" / "000005_10")
    aligned, res = align_rows(s.left, s.right)
    assert res.offset == pytest.approx(-0.24, abs=0.05)
    assert check_rectification(s.left, aligned).median_dy < res.median_dy
    given = sv.depth_map(s.left, s.right, s.calib, max_disparity=s.max_disparity)
    fixed = sv.depth_map(s.left, aligned, s.calib, max_disparity=s.max_disparity)
    b0 = dense_metrics(given.disparity, s.gt).bad[2.0]
    b1 = dense_metrics(fixed.disparity, s.gt).bad[2.0]
    assert b0 == pytest.approx(13.18, abs=0.01) and b1 < b0 - 2.0


def test_align_rows_undoes_a_roll_at_the_right_images_own_columns(data_dir: Path) -> None:
    """Art with the right image turned 0.6 degrees (rows apart 11 px per 1000 px): the roll
    was undone at the left image's columns, a disparity (~46 px) right of the right image's
    pixels, which left the rows 0.5 px apart (offset +0.49 px), over the tolerance; fitted at
    the right image's columns, they are within 0.1 px."""
    from stereovision.rectification_check import align_rows

    left, right = _pair(data_dir, "middlebury2005/art")
    h, w = right.shape[:2]
    m = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), 0.6, 1.0)
    aligned, before = align_rows(left, _warp(right, m))
    assert before.ok is False and before.slope_x == pytest.approx(11.1, abs=0.5)
    after = check_rectification(left, aligned)
    assert after.ok is True and after.median_dy < 0.1 and abs(after.offset) < 0.05


def test_a_calibration_file_name_and_numpy_tolerances() -> None:
    """check_rectification(L, R, "pi.yaml") failed with AttributeError ('str' object has no
    attribute 'rectify'), where refine_rectification says TypeError; tolerance=np.float32(0.5)
    was refused as "not a positive number"."""
    flat = np.zeros((60, 80), np.uint8)
    with pytest.raises(TypeError, match=r"^calib: got the path 'pi\.yaml', not a calibration"):
        check_rectification(flat, flat, "pi.yaml")
    for tol in (np.float32(0.5), np.float64(0.5), np.int64(1)):
        assert check_rectification(flat, flat, tolerance=tol).tolerance == float(tol)
    for bad in (np.float32("nan"), np.float64(-1.0), np.bool_(True), "0.5", 0, float("inf")):
        with pytest.raises(ValueError, match="tolerance: expected a positive number of pixels"):
            check_rectification(flat, flat, tolerance=bad)  # type: ignore[arg-type]


def test_homographies_given_as_calib_are_told_where_their_check_is() -> None:
    """depth_map takes an UncalibratedRectification as calib, so it was passed to
    check_rectification and refine_rectification too: "calib: expected a
    stereovision.Calibration, got UncalibratedRectification", no word of its own check."""
    from stereovision.uncalibrated import UncalibratedRectification

    rect = UncalibratedRectification(
        np.eye(3), np.eye(3), (80, 60), (80, 60), np.eye(3), 40, 0.1, 0.2, (1.0, 8.0), 16,
        (0.0, 0.0), (1.0, 1.0),
    )  # fmt: skip
    flat = np.zeros((60, 80), np.uint8)
    head = (
        "calib: expected a stereovision.Calibration, got an UncalibratedRectification "
        "(homographies found without a calibration): "
    )
    with pytest.raises(TypeError) as exc:
        check_rectification(flat, flat, rect)  # type: ignore[arg-type]
    assert str(exc.value) == f"{head}its own check(left, right) checks a raw pair through them"
    with pytest.raises(TypeError) as exc:
        refine_rectification(flat, flat, rect)  # type: ignore[arg-type]
    assert str(exc.value) == (
        f"{head}they have no rig to correct; rectify_uncalibrated finds them anew from a pair"
    )


def test_an_unrectified_pair_is_not_called_swapped(data_dir: Path) -> None:
    """OpenCV's hand-held books pair (no calibration, rows 36 px apart): most of its matches lie
    within 10 % of the height of their rows at negative disparities, and the check said 'the
    left and right images look swapped', not that the pair is not rectified. Swapping them
    does not rectify it: only a pair whose negative-disparity matches share rows is swapped."""
    books = data_dir / "opencv_uncalibrated" / "books"
    left, right = imread(books / "left.jpg"), imread(books / "right.jpg")
    res = check_rectification(left, right)
    assert res.ok is False and not res.swapped
    assert res.median_dy == pytest.approx(36.0, abs=1.0)
    assert res.summary().startswith("pair NOT rectified: median |dy| 36.0 px")
    # a rectified pair given the other way round still is
    cones_l, cones_r = _pair(data_dir, "middlebury2003/cones")
    assert check_rectification(cones_r, cones_l).swapped


def test_cli_check_fix_keeps_the_calibration_it_replaces(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check --fix OUT`` onto an existing calibration replaced it without a word; the
    earlier file is now kept as OUT's ``.previous`` copy, and the line says so."""
    from stereovision.cli import main

    cones = data_dir / "middlebury2003" / "cones"
    img = cv2.imread(str(cones / "left.png"))
    bumped = _rig(img.shape[1], img.shape[0], (0.3, 0.0, 0.0)).save(tmp_path / "rig.yaml")
    earlier = _rig(img.shape[1], img.shape[0], (0.1, 0.0, 0.0)).save(tmp_path / "rig2.yaml")
    before = earlier.read_bytes()
    pair = [str(cones / "left.png"), str(cones / "right.png")]
    assert main(["check", *pair, "--calib", str(bumped), "--fix", str(earlier)]) == 0
    kept = tmp_path / "rig2.previous.yaml"
    out = capsys.readouterr().out.splitlines()
    assert (
        out[-1]
        == f"corrected calibration written to {earlier} (the one it replaced kept as {kept})"
    )
    assert kept.read_bytes() == before and earlier.read_bytes() != before
    fresh = tmp_path / "rig3.yaml"
    assert main(["check", *pair, "--calib", str(bumped), "--fix", str(fresh)]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == f"corrected calibration written to {fresh}"
    assert not (tmp_path / "rig3.previous.yaml").exists()


def test_cli_check_fix_keeps_no_copy_of_a_calibration_written_again_unchanged(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check --fix OUT`` run twice with the same result kept the first run's identical file
    as OUT's ``.previous`` copy: it is said unchanged and no copy is made; a changed one still
    is kept aside."""
    from stereovision.cli import main

    cones = data_dir / "middlebury2003" / "cones"
    img = cv2.imread(str(cones / "left.png"))
    bumped = _rig(img.shape[1], img.shape[0], (0.3, 0.0, 0.0)).save(tmp_path / "rig.yaml")
    other = _rig(img.shape[1], img.shape[0], (-0.3, 0.0, 0.0)).save(tmp_path / "other.yaml")
    fix = tmp_path / "rig2.yaml"
    pair = [str(cones / "left.png"), str(cones / "right.png")]
    assert main(["check", *pair, "--calib", str(bumped), "--fix", str(fix)]) == 0
    first = fix.read_bytes()
    capsys.readouterr()
    assert main(["check", *pair, "--calib", str(bumped), "--fix", str(fix)]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == (
        f"corrected calibration written to {fix} (unchanged: it held this calibration)"
    )
    assert fix.read_bytes() == first and not list(tmp_path.glob("*.previous*"))
    assert main(["check", *pair, "--calib", str(other), "--fix", str(fix)]) == 0
    kept = tmp_path / "rig2.previous.yaml"
    assert capsys.readouterr().out.splitlines()[-1] == (
        f"corrected calibration written to {fix} (the one it replaced kept as {kept})"
    )
    assert kept.read_bytes() == first and fix.read_bytes() != first


def test_cli_check_names_a_bad_tolerance_before_the_work(
    data_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check L R --tolerance -1`` read (and rectified) the pair, then said 'tolerance: ...',
    the Python argument's name; it is refused first, naming the option."""
    from stereovision.cli import main

    cones = data_dir / "middlebury2003" / "cones"
    pair = [str(cones / "left.png"), str(cones / "right.png")]
    for bad in ("-1", "0", "nan"):
        with pytest.raises(SystemExit) as exit_:  # by the parser, since 'got inf' for 1e400
            main(["check", *pair, "--tolerance", bad])
        assert exit_.value.code == 2
        out, err = capsys.readouterr()
        assert out == "" and err == (
            "stereovision check: error: argument --tolerance: expected a positive number of "
            f"pixels, got '{bad}' (see stereovision check --help)\n"
        )


def test_cli_check_and_rectify_of_homographies_as_calib_name_what_they_take(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """rectify's rectification.json given as ``check --calib`` or ``rectify --calib`` was told
    "give it as --rectification", an option neither command has (argparse then refused it).
    Each now says what it takes; depth, which has the option, still names it. check's words
    sent the user to check rectify's left_rect.png and right_rect.png, where check finds few
    features (OpenCV's books: 18, "cannot tell", exit 3): they name the check through them."""
    from stereovision.cli import main
    from stereovision.uncalibrated import UncalibratedRectification

    rect = UncalibratedRectification(
        np.eye(3), np.eye(3), (40, 30), (40, 30), np.eye(3), 40, 0.1, 0.2, (1.0, 8.0), 16,
        (0.0, 0.0), (1.0, 1.0),
    )  # fmt: skip
    js = str(rect.save(tmp_path / "rectification.json"))
    img = np.random.default_rng(0).integers(0, 256, (30, 40), np.uint8)
    cv2.imwrite(str(tmp_path / "l.png"), img)
    cv2.imwrite(str(tmp_path / "r.png"), np.roll(img, -2, axis=1))
    pair = [str(tmp_path / "l.png"), str(tmp_path / "r.png")]
    head = f"stereovision: error: {js} holds the homographies `stereovision rectify` found for "
    head += "a rig without a calibration (disparity only): "
    assert main(["check", *pair, "--calib", js]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == (
        f"{head}check takes no homographies: in Python, stereovision.uncalibrated."
        "UncalibratedRectification.load(path).check(left, right) checks the raw pair through "
        "them (rectify says that check of the ones it finds; check of its left_rect.png and "
        "right_rect.png finds features anew, few on a warped pair)\n"
    )
    assert main(["rectify", *pair, "--calib", js, "-o", str(tmp_path / "out")]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == (
        f"{head}rectify takes no homographies (without --calib it finds them anew); "
        "`stereovision depth LEFT RIGHT --rectification FILE` rectifies a raw pair with them\n"
    )
    assert not (tmp_path / "out").exists()
    assert main(["depth", *pair, "--calib", js, "-o", str(tmp_path / "d")]) == 2
    assert "give it as --rectification (in Python" in capsys.readouterr().err


def test_cli_info_and_batch_of_homographies_as_calib_name_what_they_take(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """info and batch, which have no --rectification either, told rectify's rectification.json
    given as their calibration to "give it as --rectification" (argparse then: 'unrecognized
    arguments'), as check and rectify did before (test above)."""
    from stereovision.cli import main
    from stereovision.uncalibrated import UncalibratedRectification

    rect = UncalibratedRectification(
        np.eye(3), np.eye(3), (40, 30), (40, 30), np.eye(3), 40, 0.1, 0.2, (1.0, 8.0), 16,
        (0.0, 0.0), (1.0, 1.0),
    )  # fmt: skip
    js = str(rect.save(tmp_path / "rectification.json"))
    img = np.random.default_rng(0).integers(0, 256, (30, 40), np.uint8)
    (tmp_path / "in").mkdir()
    cv2.imwrite(str(tmp_path / "in" / "left_0001.png"), img)
    cv2.imwrite(str(tmp_path / "in" / "right_0001.png"), np.roll(img, -2, axis=1))
    head = f"stereovision: error: {js} holds the homographies `stereovision rectify` found for "
    head += "a rig without a calibration (disparity only): "
    use = "`stereovision depth LEFT RIGHT --rectification FILE` rectifies a raw pair with them"
    assert main(["info", js]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == (
        f"{head}info takes no homographies (they measure no depth); {use} (in Python: "
        "stereovision.uncalibrated.UncalibratedRectification.load(path).describe() says what "
        "they hold)\n"
    )
    out_dir = tmp_path / "out"
    assert main(["batch", str(tmp_path / "in"), "-o", str(out_dir), "--calib", js]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == f"{head}batch takes no homographies; {use}\n"
    assert not out_dir.exists()


# ------------------------------------------------------------- mutation audit: the rule on
# matched points (_judge_rows, shared with stereovision.uncalibrated) against closed forms


def _quad(xl: np.ndarray, yl: np.ndarray, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Matches [x_left, y_left, x_right, y_right] with disparity dx and row offset dy."""
    return np.column_stack([xl, yl, xl - dx, yl - dy])


def test_row_model_figures_are_the_closed_form_fit() -> None:
    w, h = 640, 480
    i = np.arange(60, dtype=np.float64)
    xl = 10 + 10 * i
    yl = 10 + (37 * i) % 460
    # dy = 0.3 + 2.0 (x - cx) / 1000 - 1.0 (y - cy) / 1000, cx, cy the image centre
    dy = 0.3 + 2.0 * (xl - 319.5) / 1000 - 1.0 * (yl - 239.5) / 1000
    r = _judge_rows(_quad(xl, yl, np.full(60, 20.0), dy), w, h, 0.5)
    assert r.matches == 60 and r.ok is True and r.swapped is False
    assert r.offset == pytest.approx(0.3, abs=1e-9)
    assert r.slope_x == pytest.approx(2.0, abs=1e-9)
    assert r.slope_y == pytest.approx(-1.0, abs=1e-9)
    ady = np.sort(np.abs(dy))
    assert r.median_dy == pytest.approx((ady[29] + ady[30]) / 2, abs=1e-12)
    # 95th percentile, linear between order statistics: rank 0.95 * 59 = 56.05
    assert r.p95_dy == pytest.approx(ady[56] + 0.05 * (ady[57] - ady[56]), abs=1e-12)
    assert r.summary().startswith("rectification ok: median |dy| ")
    assert "offset +0.30 px, roll +2.00 px per 1000 px" in r.summary()


def test_row_rule_boundaries() -> None:
    w, h = 640, 480
    i = np.arange(60, dtype=np.float64)
    xl, yl = 20 + 10 * i, 10 + (37 * i) % 460  # not on one line: the model's plane is fixed
    dx = np.full(60, 20.0)
    # a median |dy| of exactly the tolerance passes
    r = _judge_rows(_quad(xl, yl, dx, np.full(60, 0.5)), w, h, 0.5)
    assert r.ok is True and r.median_dy == 0.5
    # 30 matches give a verdict, 29 cannot tell (and the unknown figures are None in as_dict)
    assert _judge_rows(_quad(xl, yl, dx, np.zeros(60))[:30], w, h, 0.5).ok is True
    few = _judge_rows(_quad(xl, yl, dx, np.zeros(60))[:29], w, h, 0.5)
    assert few.ok is None and few.matches == 29
    assert few.as_dict()["offset"] is None and few.as_dict()["median_dy"] is None
    # an inlier is within 1 px of the model: 10 matches 1.8 px off are not
    dy = np.where(np.arange(60) % 6 == 5, 1.8, 0.0)
    assert _judge_rows(_quad(xl, yl, dx, dy), w, h, 0.5).matches == 50
    # matches at a disparity well below zero (-20 px < -max(8, 2 % of 640)) are not fitted
    dx2 = np.where(np.arange(60) < 40, 20.0, -20.0)
    r = _judge_rows(_quad(xl, yl, dx2, np.zeros(60)), w, h, 0.5)
    assert (r.matches, r.ok, r.swapped) == (40, True, False)


def test_swapped_needs_more_than_half_on_common_rows() -> None:
    w, h = 640, 480
    i = np.arange(60, dtype=np.float64)
    xl, yl = 20 + 10 * i, 10 + (37 * i) % 460  # not on one line: the model's plane is fixed
    # exactly half at negative disparities: not swapped, the other half is the verdict
    dx = np.where(np.arange(60) < 30, 20.0, -20.0)
    r = _judge_rows(_quad(xl, yl, dx, np.zeros(60)), w, h, 0.5)
    assert (r.matches, r.ok, r.swapped) == (30, True, False)
    # most at negative disparities but scattered over +-8 rows: an unrectified pair, not swapped
    dx = np.where(np.arange(60) < 10, 20.0, -20.0)
    scatter = np.random.default_rng(0).uniform(-8.0, 8.0, 60)
    r = _judge_rows(_quad(xl, yl, dx, scatter), w, h, 0.5)
    assert (r.ok, r.swapped) == (False, False)
    # a wide, low image: "near a row" is 10 % of the height (10 px), not of the width, so 50
    # matches 30 rows apart at negative disparities do not make the pair look swapped
    w, h = 1000, 100
    i = np.arange(90, dtype=np.float64)
    xl, yl = 20 + 10 * i, 5 + (37 * i) % 90
    dx = np.where(np.arange(90) < 40, 10.0, -20.0)
    dy = np.where(np.arange(90) < 40, 0.0, 30.0)
    r = _judge_rows(_quad(xl, yl, dx, dy), w, h, 0.5)
    assert (r.matches, r.ok, r.swapped) == (40, True, False)


def test_default_tolerance_is_half_a_pixel() -> None:
    # a textured pair 0.7 px apart in rows (and 12 px in columns): the default tolerance,
    # 0.5 px, calls it not rectified, and the fit finds the 0.7 px offset
    rng = np.random.default_rng(3)
    left = cv2.GaussianBlur(rng.integers(0, 256, (240, 320), dtype=np.uint8), (0, 0), 1.5)
    left = cv2.normalize(left, None, 0, 255, cv2.NORM_MINMAX)
    shift = np.float32([[1, 0, -12], [0, 1, -0.7]])  # right(x, y) = left(x + 12, y + 0.7)
    right = cv2.warpAffine(left, shift, (320, 240), flags=cv2.INTER_CUBIC,
                           borderMode=cv2.BORDER_REFLECT)  # fmt: skip
    r = check_rectification(left, right)
    assert r.tolerance == 0.5 and r.ok is False and r.matches >= 100
    assert r.offset == pytest.approx(0.7, abs=0.05) and r.median_dy == pytest.approx(0.7, abs=0.05)


def test_rows_agree_and_a_pair_of_two_sizes_in_words() -> None:
    """The line ``rectify`` and the GUI print for a pair used as given, and the refusal of a
    pair of two sizes: width x height of each image."""
    r = _judge_rows(_quad(*_grid(60), np.full(60, 20.0), np.full(60, 0.25)), 640, 480, 0.5)
    assert r.rows_agree() == "rows median |dy| 0.25 px over 60 matches, tolerance 0.5"
    with pytest.raises(ValueError) as err:
        check_rectification(np.zeros((60, 80), np.uint8), np.zeros((60, 90), np.uint8))
    assert str(err.value) == (
        "left is 80x60 px, right is 90x60 px: the two images of a pair have one size"
    )
    flat = np.zeros((60, 80), np.uint8)
    with pytest.raises(ValueError, match="tolerance: expected a positive number of pixels"):
        check_rectification(flat, flat, tolerance=True)


def _grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    i = np.arange(n, dtype=np.float64)
    return 20 + 10 * i, 10 + (37 * i) % 460  # not on one line: the model's plane is fixed


def test_a_negative_disparity_is_a_wrong_match_beyond_2_percent_of_the_width() -> None:
    # 1000 px wide: matches down to -20 px (2 % of the width, not of the 480 px height) are
    # fitted, those below are not
    dx = np.where(np.arange(60) < 40, 20.0, -15.0)
    r = _judge_rows(_quad(*_grid(60), dx, np.zeros(60)), 1000, 480, 0.5)
    assert (r.matches, r.ok, r.swapped) == (60, True, False)
    dx = np.where(np.arange(60) < 40, 20.0, -21.0)
    assert _judge_rows(_quad(*_grid(60), dx, np.zeros(60)), 1000, 480, 0.5).matches == 40


def test_sift_runs_on_a_copy_at_most_1600_px(monkeypatch: pytest.MonkeyPatch) -> None:
    """The longer side, wide or tall, is brought to 1600 px; a smaller image is used as is."""
    import types

    import stereovision.rectification_check as rc

    seen: list[tuple[int, ...]] = []

    class Sift:
        def __init__(self, **kw: int) -> None:
            self.sift = cv2.SIFT.create(**kw)

        def detectAndCompute(self, img: np.ndarray, mask: None) -> tuple:
            seen.append(img.shape)
            return self.sift.detectAndCompute(img, mask)

    class Cv2:
        SIFT = types.SimpleNamespace(create=Sift)

        def __getattr__(self, name: str) -> object:
            return getattr(cv2, name)

    monkeypatch.setattr(rc, "cv2", Cv2())
    for h, w in ((750, 2484), (2000, 1000), (375, 450)):
        rc._features(np.zeros((h, w), np.uint8))
    assert seen == [(483, 1600), (1600, 800), (375, 450)]


def test_swapped_needs_most_negative_matches_on_common_rows() -> None:
    """80 matches at negative disparities, 36 on their rows and 44 scattered 2-8 rows off:
    30 or more on common rows is not enough, it takes more than half of them."""
    rng = np.random.default_rng(1)
    off = rng.uniform(2.0, 8.0, 80) * rng.choice([-1.0, 1.0], 80)
    dy = np.where(np.arange(80) < 36, 0.0, off)
    r = _judge_rows(_quad(*_grid(80), np.full(80, -30.0), dy), 1000, 480, 0.5)
    assert (r.ok, r.swapped, r.matches) == (False, False, 80)
    # 50 of 80 at negative disparities on common rows: swapped, though the other 30 would fit
    dx = np.where(np.arange(80) < 50, -30.0, 20.0)
    r = _judge_rows(_quad(*_grid(80), dx, np.zeros(80)), 1000, 480, 0.5)
    assert (r.ok, r.swapped, r.matches) == (False, True, 80)


def test_matches_off_any_row_model_count_in_the_verdict() -> None:
    """A pair whose matches fit no row model: ``matches`` and ``median_dy`` are over all of
    them, those far off their rows too."""
    rng = np.random.default_rng(2)
    dy = rng.uniform(3.0, 8.0, 70) * rng.choice([-1.0, 1.0], 70)
    dy[60:] = 100.0 + 10 * np.arange(10)  # beyond 10 % of the height of their rows
    r = _judge_rows(_quad(*_grid(70), np.full(70, 20.0), dy), 1000, 480, 0.5)
    assert (r.ok, r.swapped, r.matches) == (False, False, 70)
    assert r.median_dy == pytest.approx(float(np.median(np.abs(dy))), abs=1e-12)
    assert r.p95_dy == pytest.approx(float(np.percentile(np.abs(dy), 95)), abs=1e-12)


def test_already_rectified_only_for_a_passing_check() -> None:
    from stereovision.rectification_check import already_rectified

    flat = np.full((120, 160), 128, np.uint8)
    assert check_rectification(flat, flat).ok is None and already_rectified(flat, flat) is None


def test_the_plot_colours_each_match_by_its_row_error() -> None:
    """Green within the tolerance, yellow up to 3 times it, red beyond; the tick in the left
    image points to the right image's row, ten times magnified."""
    from stereovision.rectification_check import RectificationCheck, draw_rectification_check

    black = np.zeros((100, 200), np.uint8)
    pts = np.float32([[30, 40, 20, 40.25], [90, 40, 80, 41.25], [150, 40, 140, 42]])
    check = RectificationCheck(3, 1.25, 1.9, 1.2, 0.0, 0.0, False, 0.5, points=pts)
    img = draw_rectification_check(black, black, check)
    pair = img[-100:].astype(int)
    green, yellow, red = (0, 200, 0), (0, 220, 255), (0, 0, 255)
    for (xl, _, xr, _), colour in zip(pts, (green, yellow, red), strict=True):
        for x in (int(xl), 200 + int(xr)):
            assert np.abs(pair[40, x] - colour).max() <= 2, (x, pair[40, x])
    # the red match's right row is 2 px lower: its tick runs 20 px down, none up
    assert pair[52, 150, 2] > 200 and pair[52, 150, :2].max() == 0 and pair[28, 150].max() == 0


@pytest.mark.parametrize(("right_shape", "said"), [((100, 150), "150x100"), ((80, 200), "200x80")])
def test_the_plot_of_a_pair_of_two_sizes_names_both(right_shape: tuple, said: str) -> None:
    """A narrower or shorter right image was NumPy's concatenation error, naming neither image
    ("along dimension 1, the array at index 0 has size 400 and the array at index 1 has size
    350"); it is said as check_rectification says it."""
    from stereovision.rectification_check import RectificationCheck, draw_rectification_check

    nan = float("nan")
    check = RectificationCheck(0, nan, nan, nan, nan, nan, None, 0.5)
    with pytest.raises(ValueError) as err:
        draw_rectification_check(np.zeros((100, 200), np.uint8), np.zeros(right_shape), check)
    assert str(err.value) == (
        f"left is 200x100 px, right is {said} px: the two images of a pair have one size"
    )


def test_refine_fits_the_turn_to_the_matches_within_1_px() -> None:
    """Given the check: 40 matches 1 px above their rows in the right image (a pitch of
    atan(1 / 700) = 0.082 degrees) and 20 more 3 px off are corrected by the 40 alone; a
    check whose matches fit no row model is refused in its own words."""
    from stereovision.rectification_check import RectificationCheck

    w, h = 640, 480
    rig = dataclasses.replace(_rig(w, h, (0.0, 0.0, 0.0)), rectified=True)
    xl, yl = _grid(60)
    yr = yl + np.where(np.arange(60) % 3 == 2, 3.0, 1.0)
    pts = np.column_stack([xl, yl, xl - 20, yr]).astype(np.float32)
    check = RectificationCheck(60, 1.0, 3.0, -1.67, 0.0, 0.0, False, 0.5, points=pts)
    flat = np.full((h, w), 128, np.uint8)
    fixed, _ = refine_rectification(flat, flat, rig, check=check)
    assert _deg(fixed.R) == pytest.approx(np.degrees(np.arctan(1 / 700)), abs=0.005)
    nan = float("nan")
    lost = RectificationCheck(60, 5.0, 9.0, nan, nan, nan, False, 0.5, points=pts)
    with pytest.raises(ValueError, match=r"^cannot refine: .* which fit no common row offset$"):
        refine_rectification(flat, flat, rig, check=lost)


def test_refine_refuses_a_check_of_a_pair_of_another_size() -> None:
    """refine_rectification took a check made on another size of the pair (a half-size copy's)
    and turned the full-size rig by that copy's rows: cones 2 px apart, checked at 225x187,
    were still 1.07 px apart "fixed", without a word. It refuses, as align_rows does, naming
    both sizes."""
    from stereovision.rectification_check import RectificationCheck

    w, h = 640, 480
    rig = dataclasses.replace(_rig(w, h, (0.0, 0.0, 0.0)), rectified=True)
    xl, yl = _grid(60)
    pts = np.column_stack([xl, yl, xl - 20, yl + 1.0]).astype(np.float32)
    flat = np.full((h, w), 128, np.uint8)
    half = RectificationCheck(60, 1.0, 1.0, -1.0, 0.0, 0.0, False, 0.5, points=pts, size=(320, 240))
    with pytest.raises(
        ValueError,
        match=r"^check: made on a 320x240 px pair, the calibration's images are 640x480 px: "
        r"check the pair that is refined$",
    ):
        refine_rectification(flat, flat, rig, check=half)


def test_align_rows_leaves_a_pair_without_a_row_model_as_it_is() -> None:
    from stereovision.rectification_check import RectificationCheck, align_rows

    nan = float("nan")
    lost = RectificationCheck(80, 24.0, 60.0, nan, nan, nan, False, 0.5)
    right = np.arange(60 * 80, dtype=np.uint16).reshape(60, 80)
    out, res = align_rows(right, right, check=lost)
    assert res is lost and out.dtype == np.uint16 and np.array_equal(out, right)


def test_cli_check_fix_refuses_a_bad_destination_before_the_work(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check --fix`` to a file name no calibration is saved as, or into a missing folder, is
    one line and status 2, before the pair is checked: nothing printed on stdout, nothing
    written."""
    from stereovision.cli import main

    cones = data_dir / "middlebury2003" / "cones"
    bumped = _rig(450, 375, (0.3, 0.0, 0.0)).save(tmp_path / "rig.yaml")
    pair = [str(cones / "left.png"), str(cones / "right.png")]
    for dest, says in (
        (tmp_path / "fixed.txt", f"--fix {tmp_path / 'fixed.txt'}: use a .yaml, .yml, .xml or"),
        (
            tmp_path / "gone" / "fixed.yaml",
            f"--fix {tmp_path / 'gone' / 'fixed.yaml'}: directory {tmp_path / 'gone'} does not",
        ),
    ):
        assert main(["check", *pair, "--calib", str(bumped), "--fix", str(dest)]) == 2
        out, err = capsys.readouterr()
        assert out == "" and err.startswith(f"stereovision: error: {says}") and err.count("\n") == 1
        assert not dest.exists()


def test_cli_check_default_tolerance_is_half_a_pixel() -> None:
    """``check``'s --tolerance is 0.5 px unless given (as check_rectification's)."""
    from stereovision.cli import build_parser

    assert build_parser().parse_args(["check", "l.png", "r.png"]).tolerance == 0.5


def test_cli_check_fix_json_keeps_stdout_one_object(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check --json --fix OUT`` onto an existing file: stdout is one JSON object, the check's
    with the correction under ``"fixed"`` (it was two JSON lines, which one ``json.loads`` of
    the output refused); the line naming the earlier file's copy goes to stderr."""
    from stereovision.cli import main

    cones = data_dir / "middlebury2003" / "cones"
    bumped = _rig(450, 375, (0.3, 0.0, 0.0)).save(tmp_path / "rig.yaml")
    earlier = _rig(450, 375, (0.1, 0.0, 0.0)).save(tmp_path / "rig2.yaml")
    pair = [str(cones / "left.png"), str(cones / "right.png")]
    assert main(["check", *pair, "--calib", str(bumped), "--fix", str(earlier), "--json"]) == 0
    out, err = capsys.readouterr()
    assert out.count("\n") == 1
    said = json.loads(out)
    assert said["ok"] is False and said["median_dy"] > 0.5
    fixed = said["fixed"]
    assert fixed["check"]["ok"] is True and fixed["check"]["median_dy"] < 0.5
    assert fixed["turn_deg"] == pytest.approx(0.3, abs=0.05)
    assert fixed["written"] == str(earlier)
    kept = tmp_path / "rig2.previous.yaml"
    lines = err.splitlines()  # on stderr, as the warning that cones agrees as given (rectified)
    assert lines[0].startswith("stereovision: warning: the images as given have rows that agree")
    assert lines[1:] == [f"stereovision: {earlier} replaced; the earlier file is {kept}"]


def test_cli_check_fix_that_still_fails_writes_nothing_and_exits_1(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A correction whose own check still fails is not written, and the status is 1 (a
    verdict on the rig), as a pair that cannot correct it. Cones as given is rectified: the
    line says that the raw rig's calibration may rectify it twice (it said "still fails"
    alone)."""
    from stereovision import rectification_check
    from stereovision.cli import main

    cones = data_dir / "middlebury2003" / "cones"
    bumped = _rig(450, 375, (0.3, 0.0, 0.0))
    rig = bumped.save(tmp_path / "rig.yaml")

    def still_failing(left, right, calib, tolerance, check):  # type: ignore[no-untyped-def]
        return bumped, check  # the correction judged as the failing check

    monkeypatch.setattr(rectification_check, "refine_rectification", still_failing)
    pair = [str(cones / "left.png"), str(cones / "right.png")]
    fixed = tmp_path / "fixed.yaml"
    assert main(["check", *pair, "--calib", str(rig), "--fix", str(fixed)]) == 1
    out, err = capsys.readouterr()
    assert out.splitlines()[1].startswith("corrected (the right camera turned 0.000 degrees)")
    assert (
        err == f"stereovision: the corrected calibration still fails: not written{CONES_AS_GIVEN}\n"
    )
    assert not fixed.exists()
    # with --json: one object, the correction's check failing too, no file written
    assert main(["check", *pair, "--calib", str(rig), "--fix", str(fixed), "--json"]) == 1
    out, err = capsys.readouterr()
    said = json.loads(out)
    assert said["ok"] is False and said["fixed"]["check"]["ok"] is False
    assert said["fixed"]["written"] is None and said["fixed"]["turn_deg"] == 0.0
    assert (
        err == f"stereovision: the corrected calibration still fails: not written{CONES_AS_GIVEN}\n"
    )
    assert not fixed.exists()


def test_cli_check_fix_of_a_passing_pair_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """--fix on a pair whose rows agree already wrote a "correction" of the noise (tsukuba
    through its identity rig, 0.07 px: turned 0.006 degrees, written): nothing is corrected or
    written now, one line says so and the status is 0; with --json stdout is the check's
    object, without "fixed". A file already at OUT is kept as it was."""
    from stereovision import rectification_check

    w, h = 64, 48
    img = np.random.default_rng(0).integers(0, 256, (h, w), np.uint8)
    pair = [str(tmp_path / "l.png"), str(tmp_path / "r.png")]
    cv2.imwrite(pair[0], img)
    cv2.imwrite(pair[1], np.roll(img, -2, axis=1))
    rig = str(_rig(w, h, (0.0, 0.0, 0.0)).save(tmp_path / "rig.yaml"))
    passing = RectificationCheck(385, 0.07, 0.47, -0.05, -0.08, 0.0, True, 0.5, size=(w, h))
    monkeypatch.setattr(rectification_check, "check_rectification", lambda *a, **k: passing)
    monkeypatch.setattr(
        rectification_check,
        "refine_rectification",
        lambda *a, **k: (_rig(w, h, (0.1, 0, 0)), passing),
    )
    fixed = tmp_path / "fixed.yaml"
    said = (
        f"stereovision: not corrected, nothing written to {fixed}: the rows agree already (rows "
        "median |dy| 0.07 px over 385 matches, tolerance 0.5): the calibration still rectifies "
        "this rig (a smaller --tolerance corrects a pair within it)\n"
    )
    assert sv.cli.main(["check", *pair, "--calib", rig, "--fix", str(fixed)]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("rectification ok: median |dy| 0.07 px") and out.count("\n") == 1
    assert err == said and not fixed.exists()
    fixed.write_text("mine")
    assert sv.cli.main(["check", *pair, "--calib", rig, "--fix", str(fixed), "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out) == passing.as_dict() and err == said
    assert fixed.read_text() == "mine" and not list(tmp_path.glob("*.previous*"))


@pytest.mark.parametrize("alpha", [5.0, -1, "1"])
def test_alpha_out_of_range_is_refused_with_or_without_a_calibration(alpha: object) -> None:
    """check_rectification without a calibration took any alpha without a word, and
    refine_rectification given its check passed alpha=5 or -1 to OpenCV's rectification
    (rectified_calibration takes any finite scaling) before its own check refused it."""
    from tests.test_calibration import raw_calib

    img = np.zeros((240, 320), np.uint8)
    says = re.escape(f"alpha: expected a value in [0, 1], got {alpha!r}")
    with pytest.raises(ValueError, match=says):
        check_rectification(img, img, alpha=alpha)  # type: ignore[arg-type]
    checked = check_rectification(img, img)
    with pytest.raises(ValueError, match=says):
        refine_rectification(img, img, raw_calib(), alpha=alpha, check=checked)  # type: ignore[arg-type]


def test_row_rule_edges_second_audit() -> None:
    """The edges of the row rule: a disparity of exactly -2 % of the width is fitted, as is
    one down to -8 px on a narrow image; a match 10 % of the height off its row is near it;
    -1 px of disparity is not negative for 'swapped'; exactly 30 negative matches on common
    rows are swapped; far-off-row negative matches do not count against a swapped verdict."""
    xl, yl = _grid(60)
    # -20 px on a 1000 px image (2 %) and -7 px on a 320 px one (the 8 px floor) are fitted
    dx = np.where(np.arange(60) < 40, 20.0, -20.0)
    assert _judge_rows(_quad(xl, yl, dx, np.zeros(60)), 1000, 480, 0.5).matches == 60
    dx = np.where(np.arange(60) < 40, 20.0, -7.0)
    assert _judge_rows(_quad(xl, yl, dx, np.zeros(60)), 320, 480, 0.5).matches == 60
    # 31 matches exactly 48 px (10 % of 480) off their rows are near them: the 30 on common
    # rows at negative disparities are not most of the near ones, so not swapped
    dx = np.where(np.arange(61) < 31, 20.0, -30.0)
    dy = np.where(np.arange(61) < 31, 48.0, 0.0)
    r = _judge_rows(_quad(*_grid(61), dx, dy), 640, 480, 0.5)
    assert (r.matches, r.ok, r.swapped, r.median_dy) == (31, False, False, 48.0)
    # 40 of 65 at -0.5 px: a disparity just below zero is no sign of a swapped pair
    dx = np.where(np.arange(65) < 40, -0.5, 20.0)
    r = _judge_rows(_quad(*_grid(65), dx, np.zeros(65)), 640, 480, 0.5)
    assert (r.matches, r.ok, r.swapped) == (65, True, False)
    # exactly MIN_MATCHES (30) at negative disparities on common rows: swapped
    r = _judge_rows(_quad(*_grid(30), np.full(30, -30.0), np.zeros(30)), 640, 480, 0.5)
    assert (r.ok, r.swapped) == (False, True)
    # 40 on common rows at negative disparities and 45 more 60-300 px off their rows: swapped
    # (the far ones are wrong matches, not part of the rule)
    far = np.random.default_rng(4).uniform(60.0, 300.0, 85)
    dy = np.where(np.arange(85) < 40, 0.0, far)
    r = _judge_rows(_quad(*_grid(85), np.full(85, -30.0), dy), 1000, 480, 0.5)
    assert (r.ok, r.swapped) == (False, True)


def test_alpha_reaches_the_rectification_and_a_match_at_the_tolerance_is_green(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """check_rectification rectifies with the alpha given (it was dropped for 0 unnoticed by
    any value test); in the plot a row error of exactly the tolerance is within it (green)."""
    from stereovision.rectification_check import RectificationCheck, draw_rectification_check

    seen: list[float] = []
    real = Calibration.rectify

    def spy(self: Calibration, left: object, right: object, alpha: float = 0.0) -> tuple:
        seen.append(alpha)
        return real(self, left, right, alpha=alpha)  # type: ignore[arg-type]

    monkeypatch.setattr(Calibration, "rectify", spy)
    rig = Calibration.ideal((80, 60), 60.0, 0.1)
    flat = np.zeros((60, 80), np.uint8)
    check_rectification(flat, flat, rig, alpha=0.75)
    assert seen == [0.75]
    black = np.zeros((100, 200), np.uint8)
    pts = np.float32([[30, 40, 20, 40.5]])
    check = RectificationCheck(1, 0.5, 0.5, 0.5, 0.0, 0.0, True, 0.5, points=pts)
    pair = draw_rectification_check(black, black, check)[-100:].astype(int)
    assert np.abs(pair[40, 30] - (0, 200, 0)).max() <= 2


def test_refine_takes_the_rectified_geometry_of_its_alpha(monkeypatch: pytest.MonkeyPatch) -> None:
    """A raw rig refined with alpha=0.5 fits the turn on the rays of the alpha-0.5 rectified
    pair (its K2), not on those of alpha 0."""
    from stereovision.rectification_check import RectificationCheck

    seen: list[float] = []
    real = Calibration.rectified_calibration

    def spy(self: Calibration, alpha: float = 0.0) -> Calibration:
        seen.append(alpha)
        return real(self, alpha)

    monkeypatch.setattr(Calibration, "rectified_calibration", spy)
    w, h = 640, 480
    rig = _rig(w, h, (0.1, 0.0, 0.0))
    xl, yl = _grid(60)
    pts = np.column_stack([xl, yl, xl - 20, yl]).astype(np.float32)
    check = RectificationCheck(60, 0.0, 0.0, 0.0, 0.0, 0.0, True, 0.5, points=pts)
    flat = np.full((h, w), 128, np.uint8)
    refine_rectification(flat, flat, rig, alpha=0.5, check=check)
    assert 0.5 in seen and 0.0 not in seen


def test_refine_a_rectified_rig_with_doffs() -> None:
    """A rectified calibration that carries doffs (cx2 - cx1 = 5 px) is refined to a raw one
    without it (the constructor refuses doffs on an unrectified rig)."""
    from stereovision.rectification_check import RectificationCheck

    w, h = 640, 480
    raw = _rig(w, h, (0.0, 0.0, 0.0))
    k2 = raw.K2.copy()
    k2[0, 2] += 5.0
    rig = dataclasses.replace(raw, K2=k2, rectified=True, doffs=5.0)
    xl, yl = _grid(60)
    pts = np.column_stack([xl, yl, xl - 20, yl + 1.0]).astype(np.float32)
    check = RectificationCheck(60, 1.0, 1.0, -1.0, 0.0, 0.0, False, 0.5, points=pts)
    flat = np.full((h, w), 128, np.uint8)
    fixed, _ = refine_rectification(flat, flat, rig, check=check)
    assert fixed.doffs is None and fixed.rectified is False
    assert _deg(fixed.R) == pytest.approx(np.degrees(np.arctan(1 / 700)), abs=0.005)


def test_align_rows_takes_the_roll_about_the_image_centre() -> None:
    """The fitted slope is about the centre pixel (w - 1) / 2: with no offset, the centre
    column of a vertical ramp is unmoved and a column 20 px right moves by slope * 20 / 1000."""
    from stereovision.rectification_check import RectificationCheck, align_rows

    h, w = 60, 81
    ramp = np.repeat(np.arange(h, dtype=np.float32)[:, None], w, axis=1)
    check = RectificationCheck(60, 1.0, 2.0, 0.0, 200.0, 0.0, False, 0.5)
    out, _ = align_rows(ramp, ramp, check=check)
    rows = slice(10, 50)
    np.testing.assert_allclose(out[rows, 40], ramp[rows, 40], atol=1e-3)
    np.testing.assert_allclose(out[rows, 60], ramp[rows, 60] - 4.0, atol=1e-3)


def test_align_rows_gives_a_one_channel_image_back_in_its_shape() -> None:
    """An (H, W, 1) right image came back (H, W) once aligned (cv2.remap drops the axis) but
    (H, W, 1) when there was nothing to align: it is (H, W, 1) both ways, the same values as
    the (H, W) image's."""
    from stereovision.rectification_check import RectificationCheck, align_rows

    h, w = 60, 81
    ramp = np.repeat(np.arange(h, dtype=np.uint8)[:, None], w, axis=1)
    check = RectificationCheck(60, 1.0, 2.0, 1.5, 200.0, 0.0, False, 0.5)
    flat, _ = align_rows(ramp, ramp, check=check)
    out, _ = align_rows(ramp, ramp[:, :, None], check=check)
    assert out.shape == (h, w, 1) and out.dtype == np.uint8
    np.testing.assert_array_equal(out[:, :, 0], flat)
    assert not np.array_equal(flat, ramp)  # it was moved
    nan = float("nan")
    none = RectificationCheck(0, nan, nan, nan, nan, nan, None, 0.5)
    assert align_rows(ramp, ramp[:, :, None], check=none)[0].shape == (h, w, 1)


def test_refine_turns_the_right_camera_in_its_own_rectified_frame() -> None:
    """A toed-in rig (right camera turned 4 degrees about y): rows 1 px apart everywhere are a
    pitch about the rectified right camera's x axis (R2's frame), not about the left one's
    (R1's, 4 degrees away, which adds a roll of 6 % of the pitch)."""
    from stereovision.rectification_check import RectificationCheck

    w, h = 640, 480
    rig = _rig(w, h, (0.0, 4.0, 0.0))
    xl, yl = _grid(60)
    xl = xl - xl.mean() + (w - 1) / 2  # centred: a uniform offset is a pitch, no roll
    yl = yl - yl.mean() + (h - 1) / 2
    pts = np.column_stack([xl, yl, xl - 20, yl + 1.0]).astype(np.float32)
    check = RectificationCheck(60, 1.0, 1.0, -1.0, 0.0, 0.0, False, 0.5, points=pts)
    flat = np.full((h, w), 128, np.uint8)
    fixed, _ = refine_rectification(flat, flat, rig, check=check)
    r2 = rig._stereo_rectify(0.0)[1]
    turn = cv2.Rodrigues(r2 @ fixed.R @ rig.R.T @ r2.T)[0].ravel()
    # the fit's own roll is 1 % of the pitch; about R1's axis it was 6 %
    assert abs(turn[1]) < 1e-9 and abs(turn[2]) < 0.03 * abs(turn[0])


def test_cli_check_fix_json_of_a_pair_it_cannot_correct_is_one_object(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check --json --fix OUT`` of a swapped pair: exit 1, stdout the check's one JSON object
    (no "fixed"), the reason on stderr, nothing written. A mutation audit dropped the object."""
    from stereovision.cli import main

    cones = data_dir / "middlebury2003" / "cones"
    rig = _rig(450, 375, (0.3, 0.0, 0.0), f=700.0).save(tmp_path / "rig.yaml")
    fixed = tmp_path / "fixed.yaml"
    pair = [str(cones / "right.png"), str(cones / "left.png")]
    assert main(["check", *pair, "--calib", str(rig), "--fix", str(fixed), "--json"]) == 1
    out, err = capsys.readouterr()
    assert out.count("\n") == 1
    said = json.loads(out)
    assert said["swapped"] is True and said["ok"] is False and "fixed" not in said
    assert err == (
        f"stereovision: not corrected, nothing written to {fixed}: the left and right images "
        "look swapped: give them the other way round\n"
    )
    assert not fixed.exists()


def test_refine_turns_in_the_right_cameras_rectified_frame_when_that_is_not_its_own() -> None:
    """Toed in with the baseline along the left camera's x axis, the right camera's rectified
    frame (R2) is 4 degrees from its own: the turn is made in R2's frame (about its axis the
    fit's roll stays 1 % of the pitch; made in the camera's own frame it was 6 %)."""
    from stereovision.rectification_check import RectificationCheck

    w, h = 640, 480
    raw = _rig(w, h, (0.0, 4.0, 0.0))
    rig = dataclasses.replace(raw, T=raw.R @ np.array([-0.1, 0.0, 0.0]))
    r2 = rig._stereo_rectify(0.0)[1]
    assert _deg(r2) == pytest.approx(4.0, abs=0.01)
    xl, yl = _grid(60)
    xl = xl - xl.mean() + (w - 1) / 2
    yl = yl - yl.mean() + (h - 1) / 2
    pts = np.column_stack([xl, yl, xl - 20, yl + 1.0]).astype(np.float32)
    check = RectificationCheck(60, 1.0, 1.0, -1.0, 0.0, 0.0, False, 0.5, points=pts)
    flat = np.full((h, w), 128, np.uint8)
    fixed, _ = refine_rectification(flat, flat, rig, check=check)
    turn = cv2.Rodrigues(r2 @ fixed.R @ rig.R.T @ r2.T)[0].ravel()
    assert abs(turn[1]) < 1e-9 and abs(turn[2]) < 0.03 * abs(turn[0])


def test_align_rows_repeats_the_edge_rows_into_the_border() -> None:
    """The rows moved in from outside the image repeat its edge, not black (0) ones."""
    from stereovision.rectification_check import RectificationCheck, align_rows

    img = np.full((20, 30), 100, np.uint8)
    for offset in (2.5, -2.5):
        check = RectificationCheck(60, 2.5, 2.5, offset, 0.0, 0.0, False, 0.5)
        out, _ = align_rows(img, img, check=check)
        np.testing.assert_array_equal(out, img)


def test_rows_agree_shows_the_tolerance_as_given() -> None:
    from stereovision.rectification_check import RectificationCheck

    check = RectificationCheck(412, 0.08, 0.2, 0.0, 0.0, 0.0, True, 0.25)
    assert check.rows_agree() == "rows median |dy| 0.08 px over 412 matches, tolerance 0.25"


def test_features_of_a_large_image_are_at_its_pixel_centres() -> None:
    """SIFT on the half-size copy of an image of 2 x 2 blocks: a feature at x' of the copy is
    at 2 (x' + 0.5) - 0.5 of the image (pixel centres), not at 2 x'."""
    from stereovision.rectification_check import _features

    rng = np.random.default_rng(4)
    small = cv2.GaussianBlur(rng.integers(0, 256, (300, 1600), dtype=np.uint8), (5, 5), 0)
    large = np.repeat(np.repeat(small, 2, axis=0), 2, axis=1)
    ps, _ = _features(small)
    pl, _ = _features(large)
    assert len(ps) > 100
    np.testing.assert_allclose(pl, (ps + 0.5) * 2 - 0.5, atol=1e-9)


def test_a_12_bit_pair_in_16_bits_is_checked_on_its_features(data_dir: Path) -> None:
    """A 12-bit camera's pair in uint16 (0-4095) was cut to 8 bits as 16-bit data: 0-16 grey
    levels, no SIFT feature, and the check said "cannot tell, only 0 feature matches (...
    point the cameras at something textured)" of the textured cones. A dark pair is now
    stretched by one gain first, as depth_map's automatic range stretches it: the same
    verdict as the 8-bit pair, and the rows 1 px apart still found."""
    left, right = (
        cv2.cvtColor(im, cv2.COLOR_BGR2GRAY) for im in _pair(data_dir, "middlebury2003/cones")
    )
    eight = check_rectification(left, right)
    twelve = [((im.astype(np.int64) * 4095 + 127) // 255).astype(np.uint16) for im in (left, right)]
    res = check_rectification(*twelve)
    assert res.ok is True and res.matches >= 0.8 * eight.matches
    assert res.median_dy < 0.3 and res.offset == pytest.approx(eight.offset, abs=0.1)
    low = check_rectification(twelve[0], _warp(twelve[1], np.float32([[1, 0, 0], [0, 1, 1.0]])))
    assert low.ok is False and low.offset - res.offset == pytest.approx(-1.0, abs=0.15)


def test_the_plot_of_a_12_bit_pair_shows_its_images(data_dir: Path) -> None:
    """draw_rectification_check drew a 12-bit pair in uint16 as 16-bit data: grey levels 0-16
    dimmed to 0-11, a black picture under the check's dots. It is stretched by the check's
    gain (its brightest grey to white): the 8-bit pair's picture, as bright within a third."""
    from stereovision.rectification_check import draw_rectification_check

    left, right = (im[:120, :160] for im in _pair(data_dir, "middlebury2003/cones"))
    twelve = [((im.astype(np.int64) * 4095 + 127) // 255).astype(np.uint16) for im in (left, right)]
    empty = _judge_rows(np.zeros((0, 4)), 160, 120, 0.5)
    eight_plot = draw_rectification_check(left, right, empty).astype(int)
    plot = draw_rectification_check(*twelve, empty).astype(int)
    assert plot.shape == eight_plot.shape
    pair, eight_pair = plot[-120:], eight_plot[-120:]  # below the summary band
    assert abs(np.median(pair) - np.median(eight_pair)) < np.median(eight_pair) / 3
    assert np.corrcoef(pair.ravel(), eight_pair.ravel())[0, 1] > 0.99


def test_the_plot_dims_the_pair_without_a_float_copy_of_it() -> None:
    """draw_rectification_check dimmed the side-by-side pair by ``canvas * 0.7``: a float64
    copy of the whole picture (576 MB for a 12 MP pair), 8 times the picture's size at its
    peak. The same grey levels now come from a table, at a peak within 3 times it."""
    import tracemalloc

    from stereovision.rectification_check import draw_rectification_check

    rng = np.random.default_rng(3)
    left = rng.integers(0, 256, (600, 800, 3), dtype=np.uint8)
    right = rng.integers(0, 256, (600, 800, 3), dtype=np.uint8)
    empty = _judge_rows(np.zeros((0, 4)), 800, 600, 0.5)
    tracemalloc.start()
    try:
        plot = draw_rectification_check(left, right, empty)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 3 * plot.nbytes
    # the same dimmed grey levels as before, above the first row line (y = 20)
    pair = plot[plot.shape[0] - 600 :]
    expected = (np.concatenate([left, right], axis=1) * 0.7).astype(np.uint8)
    np.testing.assert_array_equal(pair[:16], expected[:16])


def test_align_rows_refuses_a_check_of_a_pair_of_another_size(data_dir: Path) -> None:
    """align_rows took a check made on another size of the pair (the full-size pair's, to
    align a half-size copy) and moved the rows by that pair's row model, about its centre:
    cones 2 px apart, checked at 450x375 and aligned at 225x188, were left 0.9 px apart
    without a word. The check keeps the size it was made on, and align_rows names both."""
    from stereovision.rectification_check import align_rows

    left, right = _pair(data_dir, "middlebury2003/cones")
    right = _warp(right, np.float32([[1, 0, 0], [0, 1, 2.0]]))
    check = check_rectification(left, right)
    assert check.size == (450, 375) and "size" not in check.as_dict()
    half = [cv2.resize(im, (225, 188), interpolation=cv2.INTER_AREA) for im in (left, right)]
    with pytest.raises(
        ValueError,
        match=r"^check: made on a 450x375 px pair, the right image is 225x188 px: check the "
        r"pair that is aligned$",
    ):
        align_rows(*half, check)
    # the pair it was made on is aligned as before
    aligned, used = align_rows(left, right, check)
    assert used is check and check_rectification(left, aligned).ok is True


def test_one_image_twice_cannot_be_told_not_rectification_ok(data_dir: Path) -> None:
    """check_rectification(L, L) matched every feature to itself on its own row and said
    "rectification ok: median |dy| 0.00 px ... over 1253 matches" (the library, the stream,
    the GUI; `check L L` exit 0, `rectify L L` wrote L as "already rectified"). Identical
    images cannot tell: ok None with its own line; a blank pair keeps its texture advice."""
    from stereovision.rectification_check import already_rectified

    left = imread(data_dir / "middlebury2003" / "cones" / "left.png")[:150, :200]
    res = check_rectification(left, left.copy())
    assert res.ok is None and res.identical and res.matches == 0
    assert res.summary() == (
        "rectification: cannot tell, the two images are identical (the same file, or one "
        "camera twice?)"
    )
    assert res.as_dict()["identical"] is True and res.as_dict()["ok"] is None
    assert already_rectified(left, left) is None
    # the pair itself, and a blank pair, as before
    right = imread(data_dir / "middlebury2003" / "cones" / "right.png")[:150, :200]
    assert check_rectification(left, right).identical is False
    blank = np.zeros((150, 200), np.uint8)
    assert "point the cameras at something textured" in check_rectification(blank, blank).summary()


def test_cli_check_of_one_file_twice_cannot_tell(data_dir: Path, tmp_path: Path) -> None:
    """`stereovision check L L` warned that the two are the same file, then printed
    "rectification ok" and exited 0; now the cannot-tell line and exit 3."""
    cones = data_dir / "middlebury2003" / "cones"
    crop = tmp_path / "crop.png"
    cv2.imwrite(str(crop), cv2.imread(str(cones / "left.png"))[:150, :200])
    run = subprocess.run(
        [*SV, "check", str(crop), str(crop), "--json"], capture_output=True, text=True, timeout=120
    )
    said = json.loads(run.stdout)
    assert run.returncode == 3 and said["ok"] is None and said["identical"] is True
    assert "are the same file" in run.stderr


def test_cli_check_help_names_one_image_twice_as_exit_3(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """check exits 3 for one image twice too (above), where its --help named too little
    texture alone: a script reading 3 as "point the cameras at texture" missed a camera
    opened twice."""
    with pytest.raises(SystemExit):
        sv.cli.main(["check", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert (
        "3 when the pair has too little texture to tell, or its two images are the same pixels "
        "(one file or camera twice; with --fix: nothing is written)." in text
    )


def test_draw_rectification_check_refuses_a_check_of_a_pair_of_another_size(
    data_dir: Path,
) -> None:
    """draw_rectification_check drew a full-size check over a half-size copy of the pair
    without a word: 327 of cones' 523 left dots past the left image. It refuses, as align_rows
    does, naming both sizes; the pair checked is drawn as before."""
    from stereovision.rectification_check import draw_rectification_check

    left, right = _pair(data_dir, "middlebury2003/cones")
    check = check_rectification(left, right)
    half = [cv2.resize(im, (225, 188), interpolation=cv2.INTER_AREA) for im in (left, right)]
    with pytest.raises(
        ValueError,
        match=r"^check: made on a 450x375 px pair, the pair is 225x188 px: draw the pair that "
        r"was checked$",
    ):
        draw_rectification_check(*half, check)
    assert draw_rectification_check(left, right, check).shape[1:] == (900, 3)


def test_cli_check_reads_a_16_bit_pair_at_16_bits(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A 12-bit camera's pair in 16-bit PNGs: check read it with imread, its top 8 bits (0-4095
    as 0-15 grey levels), and told the rows from those (cones: 409 matches, 95 % 0.64 px, roll
    -0.02 px per 1000 px; 533, 0.40 px and -0.27 at 16 bits, the 8-bit pair's -0.28). It reads
    them as depth does, all 16 bits: the check of the arrays themselves."""
    from stereovision.cli import main
    from stereovision.io import read_image

    cones = data_dir / "middlebury2003" / "cones"
    paths = [tmp_path / "left.png", tmp_path / "right.png"]
    for side, path in zip(("left", "right"), paths, strict=True):
        grey = cv2.imread(str(cones / f"{side}.png"), cv2.IMREAD_GRAYSCALE)[100:260, 100:340]
        cv2.imwrite(str(path), grey.astype(np.uint16) * 16 + 8)  # 12-bit values
    assert main(["check", *map(str, paths), "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    want = check_rectification(*(read_image(p) for p in paths)).as_dict()
    assert said == want and said["matches"] > 100


def test_cli_check_fix_of_rectified_images_with_the_raw_rig_says_they_may_be_rectified_twice(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The StereoPi pair rectified by its rig (as rectify writes left_rect.png), then checked
    with that raw rig's calibration: rectified twice, 0.71 px. --fix "corrected" the rig to fit
    the rectified images (0.403 degrees; through it the raw pair's rows went from 0.15 to
    0.46 px) without a word, and without --fix the line said only to recalibrate. A warning now
    says that the images as given have rows that agree (0.30 px) and may be rectified already
    (the line without --fix says it too); --fix still writes: a drift of a rig whose raw rows
    agree looks the same."""
    cal = stereopi_calib(data_dir)
    pair = [tmp_path / "left_rect.png", tmp_path / "right_rect.png"]
    rectified = cal.rectify(*_pair(data_dir, "stereopi_rig/scene_photo"))
    for path, img in zip(pair, rectified, strict=True):
        cv2.imwrite(str(path), img)
    rig = cal.save(tmp_path / "rig.yaml")
    # the correction itself is refine_rectification's (tested above): a passing one, cheaply
    passing = RectificationCheck(100, 0.2, 0.5, 0.0, 0.0, 0.0, True, 0.5)
    monkeypatch.setattr(
        "stereovision.rectification_check.refine_rectification", lambda *a, **k: (cal, passing)
    )
    fixed = tmp_path / "fixed.yaml"
    assert sv.cli.main(["check", *map(str, pair), "--calib", str(rig), "--fix", str(fixed)]) == 0
    err = capsys.readouterr().err
    assert err == (
        "stereovision: warning: the images as given have rows that agree already (rows median "
        "|dy| 0.30 px over 102 matches, tolerance 0.5): if they are rectified images (rectify's "
        "left_rect.png, a camera's image_rect), the corrected calibration fits them, not the "
        "rig's raw images: give the raw images\n"
    )
    assert fixed.is_file()


def test_cli_check_of_raw_images_with_a_rectified_calibration_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Raw images checked with a calibration of rectified images (rectify's calib_rect.yaml:
    R = I, no distortion, so nothing is rectified): the line said only to recalibrate or --fix,
    and --fix wrote a distortion-free "correction" of the raw images (StereoPi: 0.441 degrees)
    without a word. Both now name the calibration as one of rectified images; a raw rig's line
    is as before."""
    w, h = 64, 48
    rect_rig = dataclasses.replace(_rig(w, h, (0.0, 0.0, 0.0)), rectified=True)
    raw_rig = _rig(w, h, (0.0, 0.0, 0.0))
    img = np.random.default_rng(0).integers(0, 256, (h, w), np.uint8)
    pair = [str(tmp_path / "l.png"), str(tmp_path / "r.png")]
    cv2.imwrite(pair[0], img)
    cv2.imwrite(pair[1], np.roll(img, -2, axis=1))
    failing = RectificationCheck(100, 0.6, 1.5, 0.5, 0.0, 0.0, False, 0.5, size=(w, h))
    passing = RectificationCheck(100, 0.1, 0.5, 0.0, 0.0, 0.0, True, 0.5, size=(w, h))
    monkeypatch.setattr(
        "stereovision.rectification_check.check_rectification", lambda *a, **k: failing
    )
    monkeypatch.setattr(
        "stereovision.rectification_check.refine_rectification",
        lambda *a, **k: (raw_rig, passing),
    )
    said = (
        "--calib is a calibration of rectified images (R = I, no distortion: rectify's "
        "calib_rect.yaml, a dataset's): if these are the raw images, give the raw rig's "
        "calibration"
    )
    advice = (
        "  the calibration no longer rectifies this rig: recalibrate, or correct the right "
        "camera's pitch and roll with --fix OUT"
    )
    rectified = str(rect_rig.save(tmp_path / "calib_rect.yaml"))
    assert sv.cli.main(["check", *pair, "--calib", rectified]) == 1
    assert capsys.readouterr().out.splitlines()[1] == f"{advice}; but {said}"
    fixed = tmp_path / "fixed.yaml"
    assert sv.cli.main(["check", *pair, "--calib", rectified, "--fix", str(fixed)]) == 0
    assert capsys.readouterr().err == (
        f"stereovision: warning: {said} (the correction fits them as given)\n"
    )
    assert fixed.is_file()
    raw = str(raw_rig.save(tmp_path / "rig.yaml"))
    # a raw rig (its images as given failing too): the line as before
    assert sv.cli.main(["check", *pair, "--calib", raw]) == 1
    assert capsys.readouterr().out.splitlines()[1] == advice


def test_cli_check_json_without_fix_does_not_check_the_images_as_given(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A failing check --calib RIG --json, without --fix, checked the images as given too (a
    second matching of the pair, as long as the first) for a 'rectified twice' note that its
    JSON never holds. It checks them once now; without --json the note is still looked for."""
    from stereovision import rectification_check

    pair = [data_dir / "stereopi_rig/scene_photo" / f"{s}.png" for s in ("left", "right")]
    rig = stereopi_calib(data_dir).save(tmp_path / "rig.yaml")
    failing = RectificationCheck(100, 2.0, 3.0, 0.0, 0.0, 0.0, False, 0.5)
    calls: list[tuple[object, ...]] = []

    def check(*a: object, **k: object) -> RectificationCheck:
        calls.append(a)
        return failing

    monkeypatch.setattr(rectification_check, "check_rectification", check)
    args = ["check", *map(str, pair), "--calib", str(rig)]
    assert sv.cli.main([*args, "--json"]) == 1
    assert len(calls) == 1 and json.loads(capsys.readouterr().out)["ok"] is False
    calls.clear()
    assert sv.cli.main(args) == 1
    assert len(calls) == 2  # the line may say the images are rectified already


def test_a_rectified_pair_of_two_exposures_is_already_rectified(data_dir: Path) -> None:
    """A rectified pair whose right camera exposed two stops darker (cones, right // 4) was
    'cannot tell' (12 matches) to check_rectification, so already_rectified gave None and
    rectify warped it; its views are brought to one exposure for the features, as f9e666ed
    does for rectify_uncalibrated."""
    from stereovision.rectification_check import already_rectified

    left, right = _pair(data_dir, "middlebury2003/cones")
    left, right = left[:200, :250], right[:200, :250] // 4
    check = already_rectified(left, right)
    assert check is not None and check.matches > 100 and check.median_dy < 0.5


def test_a_right_image_turned_on_its_side_is_named_by_check_and_depth(tmp_path: Path) -> None:
    """A right image of the left's size turned (a camera mounted on its side: 40x30 beside
    30x40) was refused by check_rectification, rectify and depth as 'the two images of a pair
    have one size' alone, where rectify_uncalibrated names the turn (64638868): rectify's
    check runs first, so its hint was never reached."""
    from stereovision.cli import _check_pair

    said = (
        "left is 40x30 px, right is 30x40 px: the two images of a pair have one size (the right "
        "image is the left's size turned 90 degrees: a camera mounted on its side? turn it back "
        "first)"
    )
    left, right = np.zeros((30, 40), np.uint8), np.zeros((40, 30), np.uint8)
    with pytest.raises(ValueError) as err:
        check_rectification(left, right)
    assert str(err.value) == said
    with pytest.raises(ValueError) as err:
        _check_pair(left, right, None, None)
    assert str(err.value) == said
    with pytest.raises(ValueError) as err:  # other sizes as before
        check_rectification(left, np.zeros((40, 40), np.uint8))
    assert str(err.value).endswith("px: the two images of a pair have one size")
