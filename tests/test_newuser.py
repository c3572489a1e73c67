"""A new user's first runs: tables that line up, outputs that say what they are, and first
mistakes (a video for an image, a range of 0) named in the command line's words."""

from __future__ import annotations

from pathlib import Path

import pytest

from stereovision.cli import main

CONES = Path(__file__).resolve().parents[1] / "python" / "stereovision" / "data" / "cones"


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
        assert len(ends) == 5, labels
        for end in ends[:2]:  # ours, ours + fill: numbers printed under each label
            assert row[end - 1].isdigit() and row[end] in " |", (labels, row)


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
