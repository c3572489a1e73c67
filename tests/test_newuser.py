"""A new user's first runs: tables that line up, outputs that say what they are, and first
mistakes (a video for an image, a range of 0) named in the command line's words."""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterator
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import stereovision
from stereovision.cli import main

# The sample as installed with the package (what a new user has), not the source tree's copy.
CONES = Path(str(resources.files("stereovision") / "data" / "cones"))


def test_the_sample_is_the_installed_packages() -> None:
    """These runs read the sample the package ships (they read ``python/stereovision/data`` of
    the source tree, which a wheel missing the sample would not have shown)."""
    # both resolved: a package imported through a symlinked folder (macOS's /tmp, a venv on a
    # linked disk) gives resources.files() the link's path and __file__.resolve() the target's
    assert CONES.resolve().is_relative_to(Path(stereovision.__file__).resolve().parent)
    assert sorted(p.name for p in CONES.glob("*.png")) == ["left.png", "right.png"]
    assert (CONES / "calib.txt").is_file() and (CONES / "gt_disp.pfm").is_file()


def test_eval_table_labels_sit_over_their_numbers(capsys: pytest.CaptureFixture[str]) -> None:
    """`stereovision eval`: the header, the label row and the scene rows put their column bars
    at the same places, and each label ends where its number ends."""
    assert main(["eval", str(CONES), "--no-opencv"]) == 0
    lines = capsys.readouterr().out.splitlines()
    header, labels, row = lines[0], lines[1], lines[2]
    assert row.split()[0].endswith("cones")

    def bars(line: str) -> list[int]:
        return [i for i, c in enumerate(line) if c == "|"]

    assert bars(header) == bars(labels)[: len(bars(header))]
    assert bars(row) == bars(labels)[: len(bars(row))]
    for label in ("bad-2", "bad-1", "dens"):
        ends = [i + len(label) for i in range(len(labels)) if labels.startswith(label, i)]
        assert len(ends) == 2, labels  # --no-opencv: ours and ours + fill alone
        for end in ends[:2]:  # ours, ours + fill: numbers under each label (the last ends the line)
            assert row[end - 1].isdigit() and row[end : end + 1] in " |", (labels, row)


def test_depth_without_calib_says_disparity_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without --calib there is no depth: the summary says so instead of "0 points"."""
    argv = ["depth", str(CONES / "left.png"), str(CONES / "right.png"), "--method", "gabor"]
    assert main([*argv, "--max-disparity", "64", "-o", str(tmp_path / "a")]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert "disparity only (no depth or cloud without --calib)" in first
    assert "0 points" not in first
    calib = ["--calib", str(CONES / "calib.txt")]
    assert main([*argv, *calib, "--max-disparity", "64", "-o", str(tmp_path / "b")]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert " points, " in first and "disparity only" not in first


def test_a_max_depth_that_leaves_no_depth_names_the_nearest(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``depth --max-depth 2`` on the sample said "no depth, 0 points" without saying why: it
    now names the limit and the nearest depth there was (cones' nearest is 2.07 m)."""
    argv = ["depth", str(CONES / "left.png"), str(CONES / "right.png")]
    argv += ["--calib", str(CONES / "calib.txt")]
    assert main([*argv, "-o", str(tmp_path / "all")]) == 0
    nearest = float(np.nanmin(np.load(tmp_path / "all" / "depth.npy")))
    assert 2.0 < nearest < 2.1
    capsys.readouterr()
    assert main([*argv, "--max-depth", "2", "-o", str(tmp_path / "cut")]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    said = f", no depth within --max-depth 2 m (the nearest is {nearest:.3g} m), 0 points, "
    assert said in first, first
    assert not np.isfinite(np.load(tmp_path / "cut" / "depth.npy")).any()
    # a limit that keeps some depth: the depth range as before
    assert main([*argv, "--max-depth", "2.1", "-o", str(tmp_path / "some")]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert f", depth {nearest:.3g}-" in first and "within --max-depth" not in first


def test_a_max_sigma_that_leaves_no_depth_names_the_smallest_sigma(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``depth --max-sigma 0.0001`` on the sample wrote outputs with no depth and said nothing
    of why: one warning line on stderr names the option and the frame's smallest depth sigma
    (in metres: not sigma_d, the disparity's in pixels, which the summary names), and that value
    given as --max-sigma keeps some depth."""
    argv = ["depth", str(CONES / "left.png"), str(CONES / "right.png")]
    argv += ["--calib", str(CONES / "calib.txt")]
    assert main([*argv, "--max-sigma", "0.0001", "-o", str(tmp_path / "cut")]) == 0
    out, err = capsys.readouterr()
    assert not np.isfinite(np.load(tmp_path / "cut" / "depth.npy")).any()
    lines = [line for line in err.splitlines() if "--max-sigma" in line]
    assert len(lines) == 1, err
    said = re.fullmatch(
        r"stereovision: warning: --max-sigma 0\.0001 m left no depth: the smallest depth sigma "
        r"of this frame is (\S+) m \(give --max-sigma \1 or more to keep some\)",
        lines[0],
    )
    assert said is not None, lines[0]
    assert "no depth, 0 points" in out
    assert main([*argv, "--max-sigma", said[1], "-o", str(tmp_path / "some")]) == 0
    out, err = capsys.readouterr()
    assert np.isfinite(np.load(tmp_path / "some" / "depth.npy")).any()
    assert "--max-sigma" not in err and "no depth" not in out


def test_the_nearest_beyond_max_depth_is_shown_beyond_it() -> None:
    """A nearest depth that three digits round onto the limit gets the digits to read past it;
    depths kept, none to begin with, or ones --max-sigma took (within reach): nothing said."""
    from stereovision.cli import _beyond_max_depth

    nan = np.float32(np.nan)
    none = np.full((1, 2), nan, np.float32)
    before = np.array([[2.0004, nan]], np.float32)
    said = _beyond_max_depth(none, before, 2.0)
    assert said == f"no depth within --max-depth 2 m (the nearest is {float(before[0, 0]):.7g} m)"
    assert said.endswith("(the nearest is 2.0004 m)")
    assert _beyond_max_depth(none, np.array([[3.5, 9.0]], np.float32), 2.0) == (
        "no depth within --max-depth 2 m (the nearest is 3.5 m)"
    )
    assert _beyond_max_depth(before, before, 2.0) is None  # depth kept
    assert _beyond_max_depth(none, none, 2.0) is None  # no depth before the limit either
    assert _beyond_max_depth(none, np.array([[1.5, nan]], np.float32), 2.0) is None


def test_max_sigma_with_a_max_depth_past_float32_says_one_line_without_numpy_warnings() -> None:
    """``--max-depth 1e300 --max-sigma 0.0001`` also printed NumPy's "overflow encountered in
    cast" (the limit compared with the float32 depths unguarded) before the --max-sigma line;
    the limit reads as float32's infinity, as DepthResult.filtered reads it."""
    import types
    import warnings

    from stereovision.cli import _below_max_sigma

    nan = np.float32(np.nan)
    before = types.SimpleNamespace(
        depth=np.array([[2.0, 3.0]], np.float32), depth_sigma=np.array([[0.5, 0.25]], np.float32)
    )
    none = np.full((1, 2), nan, np.float32)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        said = _below_max_sigma(none, before, 0.0001, 1e300)
    assert said == (
        "--max-sigma 0.0001 m left no depth: the smallest depth sigma of this frame is 0.25 m "
        "(give --max-sigma 0.25 or more to keep some)"
    )


@pytest.mark.parametrize("value", ["0", "-5", "1.5", "abc"])
def test_max_disparity_refused_in_the_options_words(
    value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`depth --max-disparity 0`: one line naming the option (it used to name depth_map's
    `min_disparity`, which the command line has no option for), exit 2, nothing written."""
    argv = ["depth", str(CONES / "left.png"), str(CONES / "right.png")]
    with pytest.raises(SystemExit) as exc:
        main([*argv, f"--max-disparity={value}", "-o", str(tmp_path / "o")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "stereovision depth: error: argument --max-disparity: expected a whole number of pixels "
        f"above 0, got '{value}' (see stereovision depth --help)"
    ]
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("command", ["batch", "stream"])
def test_max_disparity_of_batch_and_stream_refused_alike(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """`batch`/`stream --max-disparity 0` were taken (a plain int) and failed later, per pair
    or per frame, in depth_map's words; they are refused up front as `depth` refuses them."""
    with pytest.raises(SystemExit) as exc:
        main([command, "--max-disparity=0"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"stereovision {command}: error: argument --max-disparity: expected a whole number of "
        f"pixels above 0, got '0' (see stereovision {command} --help)"
    ]


def _write_video(path: Path) -> None:
    import cv2

    frame = cv2.imread(str(CONES / "left.png"))
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 10, (450, 375))
    for _ in range(3):
        writer.write(frame)
    writer.release()


def test_a_video_given_as_an_image_is_named_a_video(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision depth left.avi right.avi`: one line saying it is a video and which
    commands read videos, exit 2 (it used to say only "cannot decode ... as an image")."""
    video = tmp_path / "left.avi"
    _write_video(video)
    assert video.stat().st_size > 0
    assert main(["depth", str(video), str(video), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"stereovision: error: cannot decode {video} as an image: it is a video; this command "
        "takes one image per camera (stream, capture and calibrate read videos: --left VIDEO "
        "--right VIDEO)"
    ]
    bag = tmp_path / "run.db3"
    bag.write_bytes(b"SQLite format 3\x00" + bytes(100))
    assert main(["check", str(bag), str(bag)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].endswith(
        "it is a ROS bag; this command takes one image per "
        "camera (stream, capture, calibrate and gui read "
        "bags: --from-bag BAG)"
    )
    # any other undecodable file: the message as before, no guess
    junk = tmp_path / "left.png"
    junk.write_bytes(b"not a png")
    assert main(["depth", str(junk), str(junk), "-o", str(tmp_path / "o")]) == 2
    assert (
        capsys.readouterr().err.strip() == f"stereovision: error: cannot decode {junk} as an image"
    )


def test_help_says_where_to_start_and_every_option_what_it_is() -> None:
    """`stereovision --help` is plain text that points at `demo`; every option and argument of
    every command has a help line, and the defaults the README states are in them."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    top = parser.format_help()
    assert "``" not in top  # the module docstring's reST markup is not the description
    assert "Start with `stereovision demo`" in top
    subs = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    missing = [
        f"{name} {action.option_strings or action.dest}"
        for name, sub in subs.choices.items()
        for action in sub._actions
        if not action.help and not isinstance(action, argparse._HelpAction)
    ]
    assert not missing, missing
    helps = {name: " ".join(sub.format_help().split()) for name, sub in subs.choices.items()}
    for name in ("demo", "depth", "eval"):
        assert "matcher (default fused, the most accurate;" in helps[name], name
    assert "timed runs per case, at least 5 (default 5)" in helps["bench"]  # README: "default 5"
    assert "view port (default 8765)" in helps["stream"]  # README: 127.0.0.1:8765


def test_check_names_two_sizes_as_the_other_commands_do(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision check` on a pair of two sizes: "450x375 px", as `rectify` says it, not
    a (W, H) tuple."""
    import cv2

    small = tmp_path / "small.png"
    cv2.imwrite(str(small), cv2.resize(cv2.imread(str(CONES / "right.png")), (300, 250)))
    assert main(["check", str(CONES / "left.png"), str(small)]) == 2
    assert capsys.readouterr().err.strip() == (
        "stereovision: error: left is 450x375 px, right is 300x250 px: the two images of a pair "
        "have one size"
    )


def test_depth_and_batch_name_two_sizes_as_check_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision depth` (and `batch`) on a pair of two sizes said "got left (375, 450, 3)
    and right (250, 300, 3)": NumPy's (height, width, channels), which reads as 375 wide; they
    say "450x375 px" as `check` and `rectify` do."""
    import json

    import cv2

    pair = tmp_path / "scenes" / "p1"
    pair.mkdir(parents=True)
    (pair / "left.png").write_bytes((CONES / "left.png").read_bytes())
    cv2.imwrite(
        str(pair / "right.png"), cv2.resize(cv2.imread(str(CONES / "right.png")), (300, 250))
    )
    says = "left is 450x375 px, right is 300x250 px: the two images of a pair have one size"
    argv = ["depth", str(pair / "left.png"), str(pair / "right.png"), "-o", str(tmp_path / "o")]
    for calib in ([], ["--calib", str(CONES / "calib.txt")]):
        assert main([*argv, *calib]) == 2
        assert capsys.readouterr().err.strip() == f"stereovision: error: {says}"
    assert not (tmp_path / "o").exists()
    assert main(["batch", str(tmp_path / "scenes"), "-o", str(tmp_path / "b")]) == 1
    summary = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert summary["pairs"]["p1"]["error"] == f"ValueError: {says}"


def test_a_foreign_calibration_is_named_not_asked_for_image_width(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A JSON file of another tool's (MATLAB's stereoParameters through jsonencode) said
    "lacks field 'image_width'", and a user who added it was asked for K1 next; a YAML one
    already said it has none of the fields. A JSON file says so too, MATLAB's export (JSON or
    a MAT-file, which was "not a text calibration file") is named, with the way to convert it."""
    import json

    other = tmp_path / "other.json"
    other.write_text(json.dumps({"frame_count": 3, "fps": 30.0}))
    assert main(["info", str(other)]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {other} is not a calibration: it has none of the fields "
        "image_width, K1, K2, R, T (it holds: frame_count, fps)\n"
    )
    matlab = (
        "is MATLAB's stereoParameters, which is not read here: MATLAB's "
        "stereoParametersToOpenCV gives its K1, D1, K2, D2, R and T in OpenCV's convention; "
        "save them with image_width, image_height and unit (T's unit: MATLAB's default is mm) "
        "as a YAML or JSON file\n"
    )
    params = {"IntrinsicMatrix": np.eye(3).tolist(), "RadialDistortion": [0.0, 0.0]}
    exported = {
        "CameraParameters1": params,
        "CameraParameters2": params,
        "RotationOfCamera2": np.eye(3).tolist(),
        "TranslationOfCamera2": [-120.0, 0.0, 0.0],
    }
    for name, text in [
        ("stereoParams.json", json.dumps(exported)),
        ("stereoParams.yaml", "%YAML:1.0\n---\nRotationOfCamera2: 1\n"),
        ("plain.yaml", "RotationOfCamera2: [1, 0, 0]\n"),  # no OpenCV header
    ]:
        path = tmp_path / name
        path.write_text(text)
        assert main(["info", str(path)]) == 2
        assert capsys.readouterr().err == f"stereovision: error: {path} {matlab}"
    mat = tmp_path / "stereoParams.mat"  # a MAT-file's 128-byte header, then binary data
    mat.write_bytes(b"MATLAB 5.0 MAT-file, Platform: GLNXA64".ljust(124) + b"\x00\x01IM\xff\xfe")
    assert main(["info", str(mat)]) == 2
    a_mat_file = matlab.replace("MATLAB's stereoParameters", "a MATLAB MAT-file", 1)
    assert capsys.readouterr().err == f"stereovision: error: {mat} {a_mat_file}"


def test_an_unrectified_pair_is_said_to_be_one(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two raw camera images given to `depth` (no calibration, or a rectified one) were matched
    along rows they do not share without a word: a map of noise, "density 98.9 %". The feature
    matches of the automatic range already show it (2 % of OpenCV's uncalibrated books pair
    within 2 rows, 45-95 % on the 18 rectified scenes): a warning says so and how to rectify."""
    import cv2

    import stereovision as sv

    books = data_dir / "opencv_uncalibrated" / "books"
    argv = ["depth", str(books / "left.jpg"), str(books / "right.jpg"), "--method", "fast"]
    assert main([*argv, "-o", str(tmp_path / "o")]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("stereovision: warning: the left and right images look unrectified: ")
    assert "of the feature matches lie within 2 rows" in err[0]
    # each in its own words: both were said everywhere ("calib=, --calib")
    assert err[0].endswith(
        "give the calibration of the rig that took them (--calib; one marked "
        "rectified is used as it is), or rectify the pair from its features "
        "(stereovision rectify LEFT RIGHT -o DIR)"
    )
    # with a calibration marked rectified (another rig's): it said "give the rig's calibration"
    rectified = sv.Calibration.from_file(data_dir / "eth3d" / "terrace" / "calib.txt")
    raw = cv2.imread(str(books / "left.jpg")), cv2.imread(str(books / "right.jpg"))
    size = raw[0].shape[1::-1]
    with pytest.warns(UserWarning, match=r"look unrectified") as seen:
        sv.depth_map(*raw, rectified.scaled_to(size), method="fast")
    said = [str(w.message) for w in seen if "look unrectified" in str(w.message)]
    assert said[0].endswith(
        "(calib=Calibration.from_file(...); one marked rectified is used as it is), or rectify "
        "the pair from its features (stereovision.uncalibrated.rectify_uncalibrated)"
    ), said
    assert "--calib" not in said[0] and "LEFT RIGHT" not in said[0], said
    # the rectified sample: no warning; the same with its right image 8 rows lower: one
    left, right = cv2.imread(str(CONES / "left.png")), cv2.imread(str(CONES / "right.png"))
    assert sv.estimate_max_disparity(left, right) == 64
    lower = cv2.warpAffine(right, np.float32([[1, 0, 0], [0, 1, 8]]), right.shape[1::-1])
    with pytest.warns(UserWarning, match=r"look unrectified: \d+% of the feature matches"):
        sv.estimate_max_disparity(left, lower)


def test_a_pair_halved_with_rounding_is_named_resized(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The sample halved (450x375 -> 225x188, the odd height rounded) was "another aspect
    ratio: another camera mode or camera, or cropped images" under its calibration: only an
    exact ratio counted as a resize, where `stream` and `gui` scale a calibration to frames
    within 1 % (fit_to_frames). The hint takes the same 1 %, in the CLI's words (cf572b2)."""
    import cv2

    for name in ("left", "right"):
        image = cv2.imread(str(CONES / f"{name}.png"))
        cv2.imwrite(str(tmp_path / f"{name}.png"), cv2.resize(image, (225, 188)))
    argv = ["depth", str(tmp_path / "left.png"), str(tmp_path / "right.png")]
    assert main([*argv, "--calib", str(CONES / "calib.txt"), "-o", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.strip() == (
        "stereovision: error: calibration is for 450x375 images, got 225x188 (images resized, "
        "not cropped: resize them back to the calibration's size, or save it scaled to them once "
        "in Python with Calibration.from_file(path).scaled_to((225, 188)).save('rig.yaml') and "
        "give rig.yaml)"
    )


def test_paths_given_for_images_or_calibration_say_read_them_first() -> None:
    """`sv.depth_map("left.png", "right.png", calib)`, the README's call with file names, said
    "expected a numeric image array, got str converting to dtype <U8"; a calib.txt path said
    only "got str". Each says it got a path and how to read it."""
    import cv2

    import stereovision as sv

    calib = sv.Calibration.from_file(CONES / "calib.txt")
    left = str(CONES / "left.png")
    image = cv2.imread(left)
    for call in (sv.depth_map, sv.match):
        with pytest.raises(ValueError) as exc:
            call(left, image, calib)
        assert str(exc.value) == (
            f"left: got the path {left!r}, not an image: read it first (cv2.imread(path) or "
            "stereovision.io.imread(path))"
        )
        with pytest.raises(ValueError) as exc:
            call(image, image, CONES / "calib.txt")
        assert str(exc.value) == (
            f"calib: got the path '{CONES / 'calib.txt'}', not a calibration: read it first "
            "(stereovision.Calibration.from_file(path))"
        )


def test_a_grey_and_a_colour_image_are_named_as_such() -> None:
    """`cv2.imread(left, 0)` beside `cv2.imread(right)`: depth_map and match said "must have
    the same shape, got left (375, 450) and right (375, 450, 3)", the same size; they say
    which is grey and how to read them alike."""
    import cv2

    import stereovision as sv

    grey = cv2.imread(str(CONES / "left.png"), cv2.IMREAD_GRAYSCALE)
    colour = cv2.imread(str(CONES / "right.png"))
    said = (
        "left and right images must have the same shape, got left (375, 450) and right "
        "(375, 450, 3): left is grey, right is colour; read both alike (cv2.imread(path) "
        "reads both in colour)"
    )
    for call in (sv.depth_map, sv.match):
        with pytest.raises(ValueError) as exc:
            call(grey, colour)
        assert str(exc.value) == said
    with pytest.raises(ValueError, match=r"left is colour, right is colour with alpha; read"):
        sv.match(colour, cv2.cvtColor(colour, cv2.COLOR_BGR2BGRA))


def test_a_grey_image_with_a_channel_axis_is_not_called_grey_and_grey() -> None:
    """A grey image beside the same one with a channel axis of 1 (``img[..., None]``) was
    refused with "left is grey, right is grey; read both alike": both are grey. The refusal
    says which has the axis and how to drop it."""
    import cv2

    import stereovision as sv

    grey = cv2.imread(str(CONES / "left.png"), cv2.IMREAD_GRAYSCALE)
    for call in (sv.depth_map, sv.match):
        with pytest.raises(ValueError) as exc:
            call(grey, grey[..., None])
        assert str(exc.value) == (
            "left and right images must have the same shape, got left (375, 450) and right "
            "(375, 450, 1): both are grey, right with a channel axis of 1; drop it "
            "(right[..., 0])"
        )
        with pytest.raises(ValueError, match=r": both are grey, left with a channel axis of 1;"):
            call(grey[..., None], grey)


def test_a_path_as_a_numpy_string_or_bytes_is_said_as_a_path() -> None:
    """A file name taken from a NumPy table (``np.str_``, a 0-d string array) or given as bytes
    was said as "got the path np.str_('...')" or "got ndarray converting to dtype <U..": each
    is said as the path it is, for the images and the calibration."""
    import cv2

    import stereovision as sv

    left = str(CONES / "left.png")
    image = cv2.imread(left)
    for given in (np.str_(left), np.array(left), os.fsencode(left)):
        for call in (sv.depth_map, sv.match):
            with pytest.raises(ValueError) as exc:
                call(given, image)
            assert str(exc.value).startswith(f"left: got the path {left!r}, not an image: ")
            with pytest.raises(ValueError) as exc:
                call(image, image, given)
            assert str(exc.value).startswith(f"calib: got the path {left!r}, not a calibrat")


def test_matches_score_says_what_each_method_scores() -> None:
    """Matches' score was documented as a 7x7 ZNCC in [-1, 1] whatever the method: MCGM's is
    its GHT score, Gabor's its confidence and the fused members' the share of channels that
    agree, so `m[m.score > 0.9]` read differently per method without a word."""
    import re

    from stereovision.match import METHODS

    doc = stereovision.Matches.__doc__ or ""
    score = doc.split("score :", 1)[1].split("image_shape :", 1)[0]
    unsaid = [m for m in METHODS if not re.search(rf'"{m}"', score)]
    assert not unsaid, f"Matches.score does not say what these methods score: {unsaid}"


def test_a_stereo_calibrate_dump_is_told_which_fields_to_add(tmp_path: Path) -> None:
    """cv2.stereoCalibrate's K1 D1 K2 D2 R T written as they are (OpenCV's tutorials do) were
    told "lacks field 'image_width'", then "lacks field 'unit'", with no word of what either is:
    each missing field says what to write, the unit that it is T's (the square size's)."""
    import cv2

    from stereovision.calibration import Calibration

    calib = Calibration.from_file(CONES / "calib.txt")
    path = tmp_path / "stereo.yaml"
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    for key in ("K1", "D1", "K2", "D2", "R", "T"):
        fs.write(key, getattr(calib, key))
    fs.release()
    with pytest.raises(ValueError, match="lacks field 'image_width'") as err:
        Calibration.from_file(path)
    assert "image_width and image_height" in str(err.value)
    assert "size in pixels of the images it was calibrated on" in str(err.value)
    text = path.read_text() + "image_width: 450\nimage_height: 375\n"
    path.write_text(text)
    with pytest.raises(ValueError, match="lacks field 'unit'") as err:
        Calibration.from_file(path)
    assert "length unit of T" in str(err.value) and "square" in str(err.value)
    path.write_text(text + "unit: mm\n")
    read = Calibration.from_file(path)
    assert read.baseline_m == calib.baseline_m and np.array_equal(read.K1, calib.K1)


def test_stream_help_says_a_recording_brings_its_own_calibration() -> None:
    """stream's --bag and --ground-every said "needs --calib", though with --from-bag the
    recording's camera_info is the calibration (README: `stream --from-bag run/ --bag out/`)."""
    import argparse

    from stereovision.cli import build_parser

    commands = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    helps = {a.dest: a.help or "" for a in commands.choices["stream"]._actions}
    for dest in ("bag", "ground_every"):
        assert "--from-bag" in helps[dest] and "camera_info" in helps[dest], helps[dest]


def test_homographies_given_as_a_calibration_in_python_say_how_to_load_them(
    tmp_path: Path,
) -> None:
    """Calibration.from_file('rect/rectification.json') told a Python user only to "give it as
    --rectification", a command-line option; it names the loader too."""
    import json

    from stereovision.calibration import Calibration

    path = tmp_path / "rectification.json"
    path.write_text(json.dumps({"H1": [[1.0]], "H2": [[1.0]], "F": [[1.0]]}))
    with pytest.raises(ValueError, match="--rectification") as err:
        Calibration.from_file(path)
    assert "UncalibratedRectification.load(" in str(err.value)


def test_a_board_square_given_in_mm_with_the_unit_left_at_metres_is_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`board --square 30` (30 mm meant, --unit left at m) was refused as "a 30000 mm square at
    300 dpi is 354331 px", and --square 1.5 printed a 1.5 m square: a square over 1 m is said
    to be one, with the unit to give (calibrate says it of the baseline it finds)."""
    assert main(["board", "-o", str(tmp_path / "b.png"), "--square", "30"]) == 2
    err = capsys.readouterr().err
    assert "--square 30 m is a 30 m board square" in err and "--unit mm" in err
    assert main(["board", "-o", str(tmp_path / "b.png"), "--square", "30", "--unit", "mm"]) == 0
    assert "board square" not in capsys.readouterr().err  # (it is said to outgrow A4, below)
    # --unit ft: 4 (1.22 m) was said "measured in mm or cm?", where 4 in is the likely square
    assert main(["board", "-o", str(tmp_path / "f.png"), "--square", "4", "--unit", "ft"]) == 2
    err = capsys.readouterr().err  # then refused: too large to print at 300 dpi
    assert err.splitlines()[0] == (
        "stereovision: warning: --square 4 ft is a 1.2192 m board square: measured in in, mm or "
        "cm? give its unit (--unit in: a 10.2 cm square)"
    ), err


@pytest.mark.parametrize(("call", "method"), [("depth_map", "census"), ("match", "mcgm")])
def test_a_method_given_in_the_calibrations_place_is_named_a_method(call: str, method: str) -> None:
    """`sv.match(left, right, "mcgm")` (method is keyword-only, the third argument the
    calibration) was told "got the path 'mcgm', not a calibration: read it first"."""
    image = np.zeros((32, 48), np.uint8)
    said = rf"calib: got '{method}', a method's name.*method='{method}'"
    with pytest.raises(ValueError, match=said):
        getattr(stereovision, call)(image, image, method)
    with pytest.raises(ValueError, match=r"got the path 'rig\.yaml'"):
        getattr(stereovision, call)(image, image, "rig.yaml")
    from stereovision.depth import _ALL_METHODS
    from stereovision.match import METHODS

    assert set(METHODS) <= _ALL_METHODS  # a method match gains is known here too


@pytest.mark.parametrize(
    ("call", "method", "other"),
    [
        ("depth_map", "mcgm", "match"),
        ("depth_map", "hopfield", "match"),
        ("match", "census", "depth_map"),
    ],
)
def test_the_other_functions_method_in_the_calibrations_place_is_not_sent_to_method(
    call: str, method: str, other: str
) -> None:
    """`sv.depth_map(left, right, "mcgm")` was told to give it as method='mcgm', which
    depth_map then refused as an unknown method: the function the method belongs to is said."""
    image = np.zeros((32, 48), np.uint8)
    with pytest.raises(
        ValueError, match=rf"got '{method}'.*it is a method of stereovision\.{other}, not of {call}"
    ) as err:
        getattr(stereovision, call)(image, image, method)
    assert "method=" not in str(err.value)


def test_the_result_helpers_name_what_to_pass_instead() -> None:
    """First mistakes past depth_map: a calibration's path to check_rectification (and the
    other functions taking a Calibration) was "expected a stereovision.Calibration, got str";
    obstacle_mask given res.points was "expected shape (H, W, 3), got (N, 3)"; reproject given
    the whole result was "expected a real (H, W) array, got shape () dtype object"."""
    import stereovision as sv

    calib = sv.Calibration.from_file(CONES / "calib.txt")
    image = np.zeros((375, 450), np.uint8)
    with pytest.raises(TypeError, match=r"calib: got the path 'calib\.txt'.*from_file"):
        sv.check_rectification(image, image, "calib.txt")
    disparity = np.full((375, 450), 20.0, np.float32)
    disparity[200:] += np.linspace(0, 30, 175, dtype=np.float32)[:, None]  # a floor
    res = sv.DepthResult(
        disparity=disparity,
        confidence=np.ones_like(disparity),
        depth=calib.depth_from_disparity(disparity),
        points=calib.reproject(disparity).reshape(-1, 3),
        colors=np.zeros((375 * 450, 3), np.uint8),
        pixels=np.zeros((375 * 450, 2), np.int32),
        method="gabor",
        max_disparity=64,
        calibration=calib,
    )
    plane = sv.fit_ground_plane(disparity, calib)
    assert plane is not None
    with pytest.raises(ValueError, match=r"got \(168750, 3\).*point_image\(filled=True\)"):
        sv.obstacle_mask(res.points, plane)
    with pytest.raises(TypeError, match=r"disparity: got a DepthResult; .*result\.disparity"):
        calib.reproject(res)


def _chessboard_pairs(n: int) -> tuple[list[Path], list[Path]]:
    from tests.conftest import DATA_DIR

    folder = DATA_DIR / "chessboard"
    if not folder.is_dir():
        pytest.skip(f"chessboard data not found at {folder}")
    ids = ("01", "02", "03", "04", "05", "06", "07", "08", "09", "11", "12", "13", "14")[:n]
    return [folder / f"left{i}.jpg" for i in ids], [folder / f"right{i}.jpg" for i in ids]


@pytest.fixture
def cached_corners() -> Iterator[None]:
    """``calibrate.find_corners`` memoised by image content and pattern (test_calibrate's cache)
    for the tests of progress: the same six pairs are searched once, not once per calibration
    (0.7 s a board; what these tests read is the progress, not the search). Its own
    MonkeyPatch: a test's ``monkeypatch.undo()`` (of its stderr) leaves it in place."""
    from stereovision import calibrate as calmod
    from tests.test_calibrate import _cached_find_corners

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(calmod, "find_corners", _cached_find_corners)
        yield


@pytest.mark.usefixtures("cached_corners")
def test_calibrate_reports_its_progress() -> None:
    """calibrate said nothing until it was done (30 StereoPi pairs: 22 s, 14 s of them finding
    the boards and 8 s choosing the distortion model); its ``progress`` callback now hears each
    pair's board search, then each leave-one-out fit, and the result is the same."""
    from stereovision.calibrate import PROGRESS_BOARDS, PROGRESS_MODELS, calibrate

    lefts, rights = _chessboard_pairs(6)  # 6: the fewest views the model is chosen over
    calls: list[tuple[str, int, int]] = []
    cal, _ = calibrate(lefts, rights, square_size=1.0, progress=lambda *a: calls.append(a))
    boards = [(PROGRESS_BOARDS, i, 6) for i in range(1, 7)]
    # two candidate models, each left out view by view, for each camera
    fits = [(PROGRESS_MODELS, i, 24) for i in range(1, 25)]
    assert calls == boards + fits
    plain, _ = calibrate(lefts, rights, square_size=1.0)
    np.testing.assert_array_equal(cal.K1, plain.K1)
    np.testing.assert_array_equal(cal.T, plain.T)


@pytest.mark.usefixtures("cached_corners")
def test_calibrate_progress_reaches_its_total_when_a_fit_ends_early(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A view whose pose is not found (solvePnP failing) ends that camera's leave-one-out
    early, its RMS inf: the fits it skipped were never counted, and the "distortion models"
    count stopped short of the total it announced (20 of 24 here). They are now counted: the
    count rises to its total."""
    import cv2

    from stereovision.calibrate import PROGRESS_MODELS, calibrate

    lefts, rights = _chessboard_pairs(6)
    real = cv2.solvePnP
    n = [0]

    def fails_once(*a: object, **kw: object) -> object:
        n[0] += 1
        return (False, None, None) if n[0] == 2 else real(*a, **kw)  # k1k2p1p2's left, view 2

    monkeypatch.setattr(cv2, "solvePnP", fails_once)
    calls: list[tuple[str, int, int]] = []
    _, rep = calibrate(lefts, rights, square_size=1.0, progress=lambda *a: calls.append(a))
    fits = [done for stage, done, total in calls if stage == PROGRESS_MODELS and total == 24]
    assert len(fits) == len([c for c in calls if c[0] == PROGRESS_MODELS])
    assert fits[-1] == 24 and fits == sorted(set(fits))
    assert fits[:3] == [1, 2, 6]  # the left camera's 4 fits skipped, counted at once
    assert rep.model_selection["k1k2p1p2"] == float("inf")


class _HeardEnough(Exception):
    """Raised by :func:`_until`'s callback: what the test reads has been heard."""


def _until(stage: str, calls: list[tuple[str, int, int]]) -> Callable[[str, int, int], None]:
    """A ``progress`` callback keeping every call in ``calls`` and stopping the work with
    :class:`_HeardEnough` at the first call of ``stage``: the rest of a calibration (fitting,
    choosing the distortion model) is not what a test of the frames' progress reads."""

    def heard(what: str, done: int, total: int) -> None:
        calls.append((what, done, total))
        if what == stage:
            raise _HeardEnough

    return heard


class _Terminal:
    """A stderr that says it is a terminal, keeping what is written to it."""

    def __init__(self) -> None:
        self.text = ""

    def write(self, s: str) -> int:
        self.text += s
        return len(s)

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return True


@pytest.mark.usefixtures("cached_corners")
def test_calibrate_draws_progress_bars_on_a_terminal_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision calibrate` on a terminal shows a bar while it finds the boards and one
    while it chooses the distortion model, and leaves neither on screen; in a log (stderr not a
    terminal) it writes no bar, only its summary lines."""
    lefts, rights = _chessboard_pairs(6)
    args = ["calibrate", "--left", *map(str, lefts), "--right", *map(str, rights)]
    args += ["--square", "1", "-o", str(tmp_path / "rig.yaml")]
    terminal = _Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    assert main(args) == 0
    assert "boards:   0%" in terminal.text and "/6 [" in terminal.text
    assert "distortion models:   0%" in terminal.text and "/24 [" in terminal.text
    assert terminal.text.rsplit("\r", 2)[-2].strip() == ""  # the bars cleared from the screen
    assert "6/6 pairs used" in capsys.readouterr().out
    monkeypatch.undo()
    assert main([*args[:-1], str(tmp_path / "rig2.yaml")]) == 0
    logged = capsys.readouterr()
    assert "boards" not in logged.err and "%" not in logged.err
    assert "6/6 pairs used" in logged.out


def test_a_scene_folder_given_as_the_images_names_its_pair(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision depth cones cones -o out` (a scene folder, as eval and batch take it) said
    only "image file is not a regular file: cones"; it now names the folder's two images, as
    the Python reader does (left.png + right.png, or Middlebury's im0.png + im1.png), and a
    folder without one pair says the names looked for."""
    from stereovision.io import imread

    assert main(["depth", str(CONES), str(CONES), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"stereovision: error: image file is not a regular file: {CONES} (a folder holding a "
        f"pair: give its two images, {CONES / 'left.png'} and {CONES / 'right.png'})"
    )
    assert not (tmp_path / "out").exists()
    scene = tmp_path / "scene"
    scene.mkdir()
    for name in ("im0.png", "im1.png", "disp0.pfm"):
        (scene / name).write_bytes(b"")
    with pytest.raises(ValueError, match=r"give its two images, .*im0\.png and .*im1\.png\)$"):
        imread(scene)
    (scene / "im1.png").unlink()
    with pytest.raises(ValueError, match=r"^image file is not a regular file: .*scene \(a folder "):
        imread(scene)


@pytest.mark.parametrize(
    "command",
    [
        ["capture", "--left", "0", "--right", "1", "-o", "{tmp}/pairs"],
        ["stream", "--left", "0", "--right", "1", "--no-display"],
        ["info", "--hfov", "90", "--baseline", "0.1"],
        ["info", str(CONES / "calib.txt")],
    ],
    ids=["capture", "stream", "info-paper", "info-calib"],
)
def test_a_bad_size_is_named_by_its_option(
    command: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--size 640*480` was refused as "size: expected WIDTHxHEIGHT ...", the parameter's
    name where every other option's message names the option (--hfov, --baseline)."""
    args = [a.replace("{tmp}", str(tmp_path)) for a in command]
    assert main([*args, "--size", "640*480"]) == 2
    assert capsys.readouterr().err.strip() == (
        "stereovision: error: --size: expected WIDTHxHEIGHT with positive integers, got '640*480'"
    )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("command", "says"),
    [
        (["depth", "l.png", "r.png", "-o", "out", "--max-depth", "5m"], "--max-depth: expected a "
         "number of metres above 0 without a unit (5 for 5 m), got '5m' (see stereovision "
         "depth --help)"),
        (["calibrate", "--left", "l", "--right", "r", "-o", "rig.yaml", "--square", "1/4"],
         "--square: expected a number, got '1/4' (see stereovision calibrate --help)"),
        (["batch", "in", "-o", "out", "--workers", "two"], "--workers: expected a whole number, "
         "got 'two' (see stereovision batch --help)"),
        # a value holding a ' is in double quotes in argparse's words: it kept them all
        (["depth", "l.png", "r.png", "-o", "out", "--max-depth=5'"], "--max-depth: expected a "
         "number of metres above 0 without a unit (5 ft is 1.524 m: give 1.524), got \"5'\" (see "
         "stereovision depth --help)"),
        (["batch", "in", "-o", "out", "--workers", "2'"], "--workers: expected a whole number "
         "without a unit, got \"2'\" (see stereovision batch --help)"),
    ],
    ids=["depth", "calibrate", "batch", "depth-quote", "batch-quote"],
)  # fmt: skip
def test_a_value_that_is_no_number_is_said_without_python_types(
    command: list[str], says: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """argparse refused `--max-depth 5m` as "invalid float value: '5m'" (`--workers two`:
    "invalid int value"), Python's type names; the line says what to type instead."""
    with pytest.raises(SystemExit) as exit_:
        main(command)
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"stereovision {command[0]}: error: argument ") and err.endswith(says)
    assert "float" not in err and "int value" not in err


def test_an_image_sequence_is_not_said_to_run_at_0_fps(tmp_path: Path) -> None:
    """`capture --left 'pairs/left_%02d.png' ...` ended with "left ...: 320x240 @ 0 fps", OpenCV's
    0 for a frame rate it does not know read as a source delivering nothing; a known rate is
    still given."""
    import cv2

    from stereovision.capture import StereoCamera

    image = np.random.default_rng(0).integers(0, 255, (48, 64, 3), np.uint8)
    for i in (1, 2):
        for side in ("left", "right"):
            assert cv2.imwrite(str(tmp_path / f"{side}_{i:02d}.png"), image)
    with StereoCamera(str(tmp_path / "left_%02d.png"), str(tmp_path / "right_%02d.png")) as cam:
        cam.read()
        said = cam.describe()
        assert "left_%02d.png': 64x48 (no frame rate given); right" in said
        assert "0 fps" not in said
        cam.delivered_fps["left"] = 30.0
        assert "64x48 @ 30 fps; right" in cam.describe()


@pytest.mark.parametrize("command", ["depth", "check", "rectify"])
def test_one_scene_folder_for_both_images_says_what_to_type(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision depth cones -o out` (one positional: the scene folder, as eval and batch
    take it) said argparse's "the following arguments are required: right"; it now names the
    folder's two images, as `depth cones cones` does. A folder without one pair names the files
    looked for; a file keeps the plain one line."""
    out = str(tmp_path / "out")
    pair = f"give its two images, {CONES / 'left.png'} and {CONES / 'right.png'}"
    options = {"depth": ["-o", out, "--max-disparity", "64"], "check": ["--tolerance", "1"]}
    options["rectify"] = ["-o", out]
    for args in ([str(CONES), *options[command]], [*options[command], str(CONES)]):
        with pytest.raises(SystemExit) as exit_:
            main([command, *args])
        assert exit_.value.code == 2
        err = capsys.readouterr().err
        assert err == (
            f"stereovision {command}: error: the right image is missing; {CONES} is a folder "
            f"holding a pair: {pair} (see stereovision {command} --help)\n"
        )
    if command == "depth":  # -o missing too: both said
        with pytest.raises(SystemExit):
            main([command, str(CONES)])
        assert capsys.readouterr().err.endswith(
            f"{pair} (also required: -o/--output) (see stereovision depth --help)\n"
        )
    calib_set = tmp_path / "boards"  # left01/left02...: no single pair, but pairs (batch's)
    calib_set.mkdir()
    for name in ("left01.png", "left02.png", "right01.png", "right02.png"):
        (calib_set / name).write_bytes(b"")
    for given, said in (
        (
            calib_set,
            f"the right image is missing; {calib_set} is a folder of 2 pairs (left01.png + "
            "right01.png, ...; stereovision batch takes such a folder)",
        ),
        (CONES / "left.png", "the following arguments are required: right"),
    ):
        with pytest.raises(SystemExit):
            main([command, str(given)])
        err = capsys.readouterr().err
        assert err.startswith(f"stereovision {command}: error: {said}")
        assert err.count("\n") == 1
    assert not (tmp_path / "out").exists()


@pytest.mark.usefixtures("cached_corners")
def test_reading_a_calibration_recording_reports_its_progress(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision calibrate --left left.mp4 --right right.mp4` read the recording's frames
    without a word before the boards' bar; calibrate_from_video's ``progress`` now hears each
    pair read (of the pairs the recording announces), and the CLI draws a bar for it on a
    terminal only, gone before the "frame pairs kept" line; nothing of it in a log."""
    import cv2

    from stereovision.calibrate import PROGRESS_BOARDS, PROGRESS_FRAMES, calibrate_from_video

    lefts, rights = _chessboard_pairs(6)
    for side, paths in (("left", lefts), ("right", rights)):
        for i, path in enumerate(paths):
            assert cv2.imwrite(str(tmp_path / f"{side}_{i:02d}.png"), cv2.imread(str(path)))
    left, right = str(tmp_path / "left_%02d.png"), str(tmp_path / "right_%02d.png")
    calls: list[tuple[str, int, int]] = []
    with pytest.raises(_HeardEnough):
        calibrate_from_video(
            left, right, square_size=1.0, min_distance=0.0, progress=_until(PROGRESS_BOARDS, calls)
        )
    assert calls[:7] == [(PROGRESS_FRAMES, i, 6) for i in range(1, 7)] + [(PROGRESS_BOARDS, 1, 6)]

    args = ["calibrate", "--left", left, "--right", right, "--square", "1"]
    terminal = _Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    assert main([*args, "-o", str(tmp_path / "rig.yaml")]) == 0
    assert "frames:   0%" in terminal.text and "/6 [" in terminal.text
    assert terminal.text.rsplit("\r", 2)[-2].strip() == ""  # the bars cleared from the screen
    out = capsys.readouterr().out
    assert "frames" not in out.replace("frame pairs kept", "")  # no bar on stdout
    monkeypatch.undo()
    assert main([*args, "-o", str(tmp_path / "rig2.yaml")]) == 0
    logged = capsys.readouterr()
    assert "frames:" not in logged.err and "%" not in logged.err
    assert "of 6 frame pairs kept" in logged.out


@pytest.mark.parametrize("workers", ["0", "-1"])
def test_batch_refuses_no_workers_in_the_options_words(
    workers: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`batch in -o out --workers -1` (or 0) was refused as "workers: expected a positive
    number", run_batch's parameter, where --count, --max-pairs and a --workers that is no
    number name the option; nothing is written."""
    out = tmp_path / "out"
    assert main(["batch", str(CONES.parent), "-o", str(out), "--workers", workers]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: --workers: expected a whole number above 0, got {workers}\n"
    )
    assert not out.exists()


def test_a_scene_folder_beside_an_abbreviated_option_still_says_what_to_type(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """argparse takes an option by a prefix (`--meth census` for --method): 5e96852's scan of
    the words typed did not, so `depth cones --meth census -o out` counted `census` as a second
    positional and said argparse's plain "required: right" instead of the folder's two images.
    After `--` every word is a positional, even one starting with -."""
    out = str(tmp_path / "out")
    hint = f"give its two images, {CONES / 'left.png'} and {CONES / 'right.png'}"
    for args in (
        [str(CONES), "--meth", "census", "-o", out],
        ["--meth", "census", "--max-disp", "64", str(CONES), "--out", out],
        ["-o", out, "--", str(CONES)],
    ):
        with pytest.raises(SystemExit) as exit_:
            main(["depth", *args])
        assert exit_.value.code == 2
        err = capsys.readouterr().err
        assert err == (
            f"stereovision depth: error: the right image is missing; {CONES} is a folder "
            f"holding a pair: {hint} (see stereovision depth --help)\n"
        )
    with pytest.raises(SystemExit):  # two words, one a prefix of no option: no hint
        main(["depth", str(CONES), "--zzz", "census", "-o", out])
    assert "folder holding a pair" not in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.usefixtures("cached_corners")
def test_a_recording_announcing_fewer_frames_than_it_holds_never_reports_past_its_total(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """CAP_PROP_FRAME_COUNT is a container's guess: a recording holding more frames than it
    announces had progress hear ('frames', 5, 3), done past total (a callback's 167 %); once
    the reading passes the count announced, the total is said unknown (0), as a camera's."""
    import cv2

    from stereovision.calibrate import PROGRESS_BOARDS, PROGRESS_FRAMES, calibrate_from_video
    from stereovision.capture import StereoCamera

    lefts, rights = _chessboard_pairs(6)
    for side, paths in (("left", lefts), ("right", rights)):
        for i, path in enumerate(paths):
            assert cv2.imwrite(str(tmp_path / f"{side}_{i:02d}.png"), cv2.imread(str(path)))
    left, right = str(tmp_path / "left_%02d.png"), str(tmp_path / "right_%02d.png")
    monkeypatch.setattr(StereoCamera, "_announced", lambda self, side: 3)
    calls: list[tuple[str, int, int]] = []
    with pytest.raises(_HeardEnough):
        calibrate_from_video(
            left, right, square_size=1.0, min_distance=0.0, progress=_until(PROGRESS_BOARDS, calls)
        )
    frames = [c for c in calls if c[0] == PROGRESS_FRAMES]
    assert frames == [(PROGRESS_FRAMES, i, 3) for i in (1, 2, 3)] + [
        (PROGRESS_FRAMES, i, 0) for i in (4, 5, 6)
    ]


def test_the_rectified_pair_given_with_its_rectification_is_named_as_such(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`rectify` without --calib writes left_rect.png, right_rect.png and rectification.json;
    `depth left_rect.png right_rect.png --rectification rectification.json` (the homographies
    beside the pair they wrote) was refused as "left image is 484x419 px; this rectification is
    for 612x459", naming no mix-up. The rectified pair's size is now said to be that, and what
    to run instead; another size keeps the plain message."""
    books = data_dir / "opencv_uncalibrated" / "books"
    out = tmp_path / "rect"
    assert main(["rectify", str(books / "left.jpg"), str(books / "right.jpg"), "-o", str(out)]) == 0
    capsys.readouterr()
    rect = ["--rectification", str(out / "rectification.json"), "-o", str(tmp_path / "d")]
    assert main(["depth", str(out / "left_rect.png"), str(out / "right_rect.png"), *rect]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        "stereovision: error: left image is 484x419 px, the rectified pair's size; this "
        "rectification is for 612x459, the raw pair: match the rectified pair as it is (depth "
        "without --rectification)"
    )
    assert not (tmp_path / "d").exists()
    left = str(CONES / "left.png")
    assert main(["depth", left, str(CONES / "right.png"), *rect]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "stereovision: error: left image is 450x375 px; this rectification is for 612x459"


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        # the README's and robotics.md's ChArUco board: 12 x 9 squares of 30 mm with its margins
        (
            ["--board", "charuco", "--pattern", "10x7", "--square", "0.03", "--marker", "0.022"],
            "360 x 270 mm, larger than A4 and US Letter paper",
        ),
        (["--square", "0.025"], "300 x 225 mm, larger than A4 and US Letter paper"),  # 9x6
        (["--pattern", "11x6", "--square", "0.02"], "280 x 180 mm, larger than US Letter paper"),
        (["--square", "0.02"], None),  # 240 x 180 mm
        (["--pattern", "5x10", "--square", "0.02"], None),  # 160 x 260 mm: upright
    ],
)
def test_a_board_larger_than_office_paper_is_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], said: str | None
) -> None:
    """`board` said "printed at 100 % scale it is 360.0 x 270.0 mm" of the README's ChArUco
    board and nothing more: on A4 or US Letter a printer crops it or its fit-to-page shrinks the
    squares below the --square that calibrate is then given. A page that outgrows a sheet is now
    said in a warning (the board is written all the same); one that fits either way round is not."""
    out = tmp_path / "b.png"
    assert main(["board", "-o", str(out), *argv]) == 0
    assert out.is_file()
    err = capsys.readouterr().err
    if said is None:
        assert err == ""
    else:
        assert err == (
            f"stereovision: warning: {out} is {said}: print it on a larger sheet (A3, tabloid) "
            "or give a smaller --square (a printer's fit-to-page shrinks the squares)\n"
        )
