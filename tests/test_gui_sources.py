"""The GUI's sources without a browser: allowed folders, camera pairs, image folders, scaling.

The first tests of path escapes and video files are at the end; the others pin down what a
mutation audit of ``stereovision.gui.sources`` found unasserted.
"""

from __future__ import annotations

import re
import subprocess
import sys
import time
import types
from pathlib import Path
from typing import Any, ClassVar

import cv2
import numpy as np
import pytest
import synthetic_scene as syn
from gui_helpers import VIDEO_FRAMES
from gui_helpers import write_video as _write_video

from stereovision.gui import sources
from stereovision.gui.sources import AllowedFolders, FolderPairs, VideoPair, display_path

# ----------------------------------------------------------------------------- display_path


def test_display_path_relative_home_and_absolute() -> None:
    cwd, home = Path("/srv/work"), Path("/home/me")
    assert display_path("/srv/work/a/b.png", cwd=cwd, home=home) == "a/b.png"
    assert display_path("a/../c", cwd=cwd, home=home) == "c"  # relative: from cwd
    assert display_path("/home/me", cwd=cwd, home=home) == "~"
    assert display_path("/home/me/x/y", cwd=cwd, home=home) == "~/x/y"
    assert display_path("/home/meow", cwd=cwd, home=home) == "/home/meow"
    # From "/" (or a home of "/") every path is under it: absolute, not "tmp/..." or "~/tmp".
    assert display_path("/tmp/x", cwd=Path("/"), home=home) == "/tmp/x"
    assert display_path("/tmp/x", cwd=cwd, home=Path("/")) == "/tmp/x"


def test_display_path_defaults_to_the_current_and_home_folders(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "w").mkdir()
    monkeypatch.chdir(tmp_path / "w")
    monkeypatch.setenv("HOME", str(tmp_path))
    assert display_path(tmp_path / "w" / "a.png") == "a.png"
    assert display_path(tmp_path / "b.png") == "~/b.png"


def test_display_path_without_a_home_folder(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_home() -> Path:
        raise RuntimeError("no home")

    monkeypatch.setattr(Path, "home", staticmethod(no_home))
    assert display_path("/mnt/x", cwd=Path("/srv")) == "/mnt/x"
    assert display_path("/srv/y", cwd=Path("/srv")) == "y"


def test_display_path_in_a_removed_current_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``stereovision gui --data ~/scenes`` run from a folder since removed (a shell left in a
    build folder made again) stopped at start-up with 'error: [Errno 2] No such file or
    directory', naming nothing: the save field's path was shown relative to the current
    folder, which has none. It is shown ``~``-abbreviated or whole."""
    gone = tmp_path / "build"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert display_path(tmp_path / "home" / "scenes" / "saved") == "~/scenes/saved"
    assert display_path(tmp_path / "data" / ".." / "saved") == str(tmp_path / "saved")
    folders = AllowedFolders([tmp_path])
    assert folders.roots == (tmp_path.resolve(),)


# ----------------------------------------------------------------------------- AllowedFolders


@pytest.fixture
def data(tmp_path: Path) -> Path:
    """data/ with a scene, a hidden folder, files of several kinds and a link out."""
    d = tmp_path / "data"
    (d / "scene").mkdir(parents=True)
    for n in ("left.png", "right.png"):
        (d / "scene" / n).write_bytes(b"png")
    (d / ".hidden").mkdir()
    (d / ".hidden" / "h.ply").write_text("x")
    (d / "b.PLY").write_text("x")
    (d / "a.ply").write_text("x")
    (d / "notes.txt").write_text("x")
    out = tmp_path / "outside"
    out.mkdir()
    (out / "o.ply").write_text("x")
    (d / "out.ply").symlink_to(out / "o.ply")
    (d / "outdir").symlink_to(out)
    return d


def test_roots_are_resolved_deduplicated_and_checked(data: Path, tmp_path: Path) -> None:
    (tmp_path / "alias").symlink_to(data)
    folders = AllowedFolders([data, tmp_path / "alias", data / "scene" / ".."])
    assert folders.roots == (data.resolve(),)
    with pytest.raises(FileNotFoundError, match=r"^data folder not found: .*a\.ply is a file, "):
        AllowedFolders([data / "a.ply"])  # a file, not a folder: said so (it was "not found")
    with pytest.raises(FileNotFoundError, match=r"^data folder not found: .*nothing$"):
        AllowedFolders([data / "nothing"])


@pytest.mark.parametrize("given", ["", " "])
def test_an_empty_data_folder_is_refused_not_taken_for_the_current_one(
    given: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``gui --data ""`` (an unset shell variable: ``--data "$SCENES"``) allowed the current
    folder: the page listed and opened its files and saved into it. It is refused, one line
    before anything is opened or served."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match=rf"^data folder: expected a folder, got {given!r}$"):
        AllowedFolders([given])
    from stereovision.gui import main

    if not given:  # refused by the CLI's parser first, as any empty argument (46356f4)
        with pytest.raises(SystemExit) as exit_:
            main(["--data", given, "--no-browser", "--port", "0"])
        assert exit_.value.code == 2
        assert capsys.readouterr() == (
            "",
            "stereovision gui: error: argument --data: expected a value, got '' (an unset "
            "variable?) (see stereovision gui --help)\n",
        )
        return
    assert main(["--data", given, "--no-browser", "--port", "0"]) == 2
    assert capsys.readouterr() == (
        "",
        f"stereovision: error: data folder: expected a folder, got {given!r}\n",
    )


def test_a_data_folder_named_with_spaces_is_taken(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A folder named " " (a legal name, which the CLI's parser takes) was refused as "data
    folder: expected a folder, got ' '" though it is one; blank text naming no folder still is
    (test_an_empty_data_folder_is_refused_not_taken_for_the_current_one)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / " ").mkdir()
    (tmp_path / " " / "left.png").write_bytes(b"")
    (tmp_path / "other.png").write_bytes(b"")
    allowed = AllowedFolders([" "])
    assert allowed.roots == ((tmp_path / " ").resolve(),)
    assert allowed.contains(tmp_path / " " / "left.png")
    assert not allowed.contains(tmp_path / "other.png")


def test_a_data_folder_under_an_unknown_users_home_is_said_as_such() -> None:
    """``gui --data ~nobody-such/scenes`` (the shell leaves an unknown user's ``~`` as typed)
    said Python's 'Could not determine home directory.', naming neither the folder nor why."""
    with pytest.raises(
        ValueError,
        match=r"^no home folder is known for ~nobody-such/scenes \(no user nobody-such is known\)",
    ):
        AllowedFolders(["~nobody-such/scenes"])


def test_resolve_accepts_the_root_and_refuses_nul_and_rootless(data: Path) -> None:
    folders = AllowedFolders([data])
    assert folders.resolve(data) == data.resolve()
    assert folders.resolve("scene") == (data / "scene").resolve()
    two = AllowedFolders([data / "scene", data])
    assert two.resolve("left.png") == (data / "scene" / "left.png").resolve()  # the first root
    assert two.resolve("a.ply") == (data / "a.ply").resolve()  # in the second root only
    with pytest.raises(ValueError, match="empty or invalid path"):
        folders.resolve("a\x00.ply")
    with pytest.raises(ValueError, match=r"^path outside the allowed folders: a\.ply$"):
        AllowedFolders([]).resolve("a.ply")
    with pytest.raises(ValueError, match=r"^path outside the allowed folders: /"):
        AllowedFolders([]).resolve(str(data / "a.ply"))
    with pytest.raises(FileNotFoundError, match=r"^no such file: nope\.ply$"):
        folders.resolve("nope.ply")
    assert folders.contains("a.ply") and not folders.contains("out.ply")
    assert not folders.contains("nope.ply") and not folders.contains("")


def test_resolve_output(data: Path, tmp_path: Path) -> None:
    folders = AllowedFolders([data, tmp_path / "outside"])
    # Relative to the first root, stripped, need not exist.
    assert folders.resolve_output("  new/sub ") == data.resolve() / "new" / "sub"
    assert folders.resolve_output(data) == data.resolve()
    assert folders.resolve_output(tmp_path / "outside" / "x") == (tmp_path / "outside" / "x")
    for bad in ("", "   ", None, "a\x00b"):
        with pytest.raises(ValueError, match=r"^empty or invalid folder$"):
            folders.resolve_output(bad)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^folder outside the --data folders: \.\./elsewhere$"):
        folders.resolve_output("../elsewhere")
    with pytest.raises(ValueError, match=r"^folder outside the --data folders: outdir/x$"):
        folders.resolve_output("outdir/x", roots=[data.resolve()])  # a link out of the roots
    # roots=: only those; relative to the first of them.
    only = [(tmp_path / "outside").resolve()]
    assert folders.resolve_output("y", roots=only) == only[0] / "y"
    with pytest.raises(ValueError, match="folder outside"):
        folders.resolve_output(data / "z", roots=only)
    with pytest.raises(ValueError, match=r"^no folder to write into: start the GUI with --data"):
        folders.resolve_output("x", roots=[])
    # a sibling whose name begins with a root's ("data2" beside "data") is no folder in it
    (tmp_path / "outside2").mkdir()
    with pytest.raises(ValueError, match=r"^folder outside the --data folders: .*outside2/x$"):
        folders.resolve_output(tmp_path / "outside2" / "x")
    with pytest.raises(ValueError, match=r"^no folder to write into"):
        AllowedFolders([]).resolve_output("x")


def test_files_are_sorted_case_blind_inside_and_visible(data: Path) -> None:
    folders = AllowedFolders([data])
    assert folders.files(sources.CLOUD_SUFFIXES) == [data / "a.ply", data / "b.PLY"]
    assert folders.files(sources.IMAGE_SUFFIXES) == [
        data / "scene" / "left.png",
        data / "scene" / "right.png",
    ]


@pytest.mark.parametrize("limit", [2, 3])
def test_files_stop_at_max_listed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, limit: int
) -> None:
    monkeypatch.setattr(sources, "MAX_LISTED", limit)
    for k in range(4):
        (tmp_path / f"{k}.ply").write_text("x")
    listed = AllowedFolders([tmp_path]).files(sources.CLOUD_SUFFIXES)
    assert listed == [tmp_path / f"{k}.ply" for k in range(limit)]


def test_files_stop_at_max_listed_across_folders(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sources, "MAX_LISTED", 2)
    (tmp_path / "sub").mkdir()
    for name in ("a.ply", "b.ply", "sub/c.ply"):
        (tmp_path / name).write_text("x")
    assert AllowedFolders([tmp_path]).files(sources.CLOUD_SUFFIXES) == [
        tmp_path / "a.ply",
        tmp_path / "b.ply",
    ]


def test_home_relative_paths_are_expanded(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("HOME", str(tmp_path))
    folders = AllowedFolders(["~/data"])
    assert folders.roots == (data.resolve(),)
    assert folders.resolve("~/data/a.ply") == (data / "a.ply").resolve()
    assert folders.resolve_output(" ~/data/new") == data.resolve() / "new"


def _no_home(monkeypatch: pytest.MonkeyPatch) -> None:
    """No home folder known: HOME unset and no password entry (a service's user)."""
    import pwd

    def no_entry(uid: int) -> Any:
        raise KeyError(uid)

    monkeypatch.delenv("HOME", raising=False)
    monkeypatch.setattr(pwd, "getpwuid", no_entry)


def test_a_home_relative_path_without_a_home_folder_is_refused_in_words(
    data: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With no home folder known, a typed ``~/...`` raised Path.expanduser's RuntimeError
    ("Could not determine home directory."), which the page's handlers (ValueError, OSError)
    let through: the page said nothing. It is a ValueError naming the path and the cause."""
    _no_home(monkeypatch)
    folders = AllowedFolders([data])
    said = "no home folder is known for ~/data/a.ply (HOME is not set): give the whole path"
    with pytest.raises(ValueError, match=re.escape(said)):
        folders.resolve("~/data/a.ply")
    with pytest.raises(ValueError, match="no home folder is known for ~/new "):
        folders.resolve_output("~/new")
    assert not folders.contains("~/data/a.ply")
    assert folders.resolve(data / "a.ply") == (data / "a.ply").resolve()  # the rest as before


def test_a_path_under_an_unknown_users_home_is_not_said_to_lack_home(
    data: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """HOME set, a typed ``~bob/...`` of a user the system does not know: Path.expanduser's
    RuntimeError was said "(HOME is not set)", the cure offered the wrong one. It names the
    user; ``~/...`` with HOME set still expands."""
    import pwd

    def no_user(name: str) -> Any:
        raise KeyError(name)

    monkeypatch.setenv("HOME", str(data))
    monkeypatch.setattr(pwd, "getpwnam", no_user)
    folders = AllowedFolders([data])
    said = "no home folder is known for ~bob/a.ply (no user bob is known): give the whole path"
    with pytest.raises(ValueError, match=re.escape(said)):
        folders.resolve("~bob/a.ply")
    with pytest.raises(ValueError, match=re.escape("~bob (no user bob is known)")):
        folders.resolve_output("~bob")
    assert folders.resolve("~/a.ply") == (data / "a.ply").resolve()


def test_files_and_scenes_of_two_roots(tmp_path: Path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    for d in (a, b):
        (d / "s").mkdir(parents=True)
        for n in ("left.png", "right.png"):
            (d / "s" / n).write_bytes(b"png")
        (d / "c.ply").write_text("x")
    folders = AllowedFolders([b, a])
    assert folders.files(sources.CLOUD_SUFFIXES) == [b / "c.ply", a / "c.ply"]  # root order
    assert folders.scenes() == [a / "s", b / "s"]  # sorted


def test_the_lists_read_an_unchanged_folder_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The page's lists (scenes, clouds, images) walked the whole ``--data`` tree each, at
    every refresh, in the page's loop: 1.4 s on a 45k-file folder. A folder is read once while
    its mtime stays; one that changes is read again (a Save's new cloud is listed)."""
    import os

    (tmp_path / "s").mkdir()
    for n in ("left.png", "right.png", "c.ply"):
        (tmp_path / "s" / n).write_bytes(b"x")
    old = time.time() - 60  # past the 2 s in which an mtime may not yet tell a change
    for d in (tmp_path / "s", tmp_path):
        os.utime(d, (old, old))
    read: list[str] = []
    scandir = os.scandir
    monkeypatch.setattr(os, "scandir", lambda d: read.append(str(d)) or scandir(d))
    folders = AllowedFolders([tmp_path])
    for _ in range(2):  # two refreshes
        assert folders.scenes() == [tmp_path / "s"]
        assert folders.files(sources.CLOUD_SUFFIXES) == [tmp_path / "s" / "c.ply"]
        assert folders.files(sources.IMAGE_SUFFIXES) == [
            tmp_path / "s" / n for n in ("left.png", "right.png")
        ]
    assert sorted(read) == [str(tmp_path), str(tmp_path / "s")]
    (tmp_path / "s" / "d.ply").write_bytes(b"x")
    assert folders.files(sources.CLOUD_SUFFIXES) == [tmp_path / "s" / n for n in ("c.ply", "d.ply")]
    # past MAX_KEPT_NAMES names a folder is read each time (not held in memory)
    os.utime(tmp_path / "s", (old, old))
    monkeypatch.setattr(sources, "MAX_KEPT_NAMES", 1)
    read.clear()
    few = AllowedFolders([tmp_path / "s"])
    for _ in range(2):
        assert few.files(sources.CLOUD_SUFFIXES) == [
            tmp_path / "s" / "c.ply",
            tmp_path / "s" / "d.ply",
        ]
    assert read == [str(tmp_path / "s")] * 2 and few._kept_names == 0


def test_scenes_skip_hidden_links_out_and_stop_at_max_listed(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for name in (".h", "z"):
        (data / name).mkdir()
        for n in ("left.png", "right.png"):
            (data / name / n).write_bytes(b"png")
    (tmp_path / "outside" / "right.png").write_bytes(b"png")
    (data / "half").mkdir()
    (data / "half" / "left.png").write_bytes(b"png")
    (data / "half" / "right.png").symlink_to(tmp_path / "outside" / "right.png")
    folders = AllowedFolders([data])
    assert folders.scenes() == [data / "scene", data / "z"]
    monkeypatch.setattr(sources, "MAX_LISTED", 1)
    assert folders.scenes() == [data / "scene"]


def test_folders_lists_roots_and_their_visible_subfolders(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (data / "b").mkdir()
    (data / "scene" / "deeper").mkdir()
    gone = tmp_path / "gone"
    gone.mkdir()
    folders = AllowedFolders([data, gone])
    gone.rmdir()  # a root removed while the GUI runs is skipped, not an error
    assert folders.folders() == [data.resolve(), data / "b", data / "scene", gone]
    monkeypatch.setattr(sources, "MAX_LISTED", 2)
    assert folders.folders() == [data.resolve(), data / "b"]


def test_label(data: Path, tmp_path: Path) -> None:
    folders = AllowedFolders([data])
    assert folders.label(data.resolve()) == "data"
    assert folders.label(data.resolve() / "scene" / "left.png") == "data/scene/left.png"
    assert folders.label(tmp_path / "outside" / "o.ply") == "o.ply"
    # Three roots of one name, two of them alike one level up as well.
    roots = [tmp_path / p / "x" / "data" for p in ("p", "q")] + [tmp_path / "r" / "data"]
    for r in roots:
        r.mkdir(parents=True)
    three = AllowedFolders(roots)
    assert [three.label(r) for r in roots] == ["p/x/data", "q/x/data", "r/data"]


# ----------------------------------------------------------------------------- parse_source


def test_parse_source() -> None:
    assert sources.parse_source(3) == 3
    assert sources.parse_source(np.int64(3)) == 3 and type(sources.parse_source(np.int64(3))) is int
    assert sources.parse_source(" 12 ") == 12
    assert sources.parse_source(" cam.avi ") == "cam.avi"
    assert sources.parse_source("img_%03d.png") == "img_%03d.png"
    with pytest.raises(ValueError, match=r"^empty camera source$"):
        sources.parse_source("")
    # a digit to str.isdigit but no number to int(): "invalid literal for int()" on the page;
    # a file name, as stereovision.capture.parse_source takes it
    assert sources.parse_source(" ² ") == "²"


def test_parse_source_refuses_what_capture_refuses() -> None:
    # -1 passed on to cv2.VideoCapture (a crash where no camera is present), True opened camera
    # 1, a NumPy -1 was taken for a file "-1": refused as stereovision.capture refuses them
    negative = r"^camera index -1 is negative: cameras are numbered from 0 \(\./-1 for a file\)$"
    for bad in (-1, np.int64(-1), "-1", " -1 "):
        with pytest.raises(ValueError, match=negative):
            sources.parse_source(bad)
    for flag in (True, np.bool_(False)):
        with pytest.raises(ValueError, match=r"expected a device index or a path"):
            sources.parse_source(flag)
    assert sources.parse_source("-0") == "-0"  # no negative index: a file, as capture takes it


def test_video_pair_refuses_a_negative_index_before_opencv_sees_it() -> None:
    # In a subprocess: cv2.VideoCapture(-1) ended the process (SIGSEGV) with no camera present.
    code = (
        "from stereovision.gui.sources import VideoPair\n"
        "for bad in (-1, True):\n"
        "    try:\n"
        "        VideoPair(bad, 0)\n"
        "    except ValueError as e:\n"
        "        print(e)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr[-500:]
    assert done.stdout.splitlines() == [
        "camera index -1 is negative: cameras are numbered from 0 (./-1 for a file)",
        "camera source: expected a device index or a path, got True",
    ]


# ----------------------------------------------------------------------------- VideoPair


class FakeCap:
    """A cv2.VideoCapture stand-in: ``frames`` in order, then no frame (until rewound)."""

    made: ClassVar[list[FakeCap]] = []
    calls: ClassVar[list[str]] = []
    opened = True
    frames: ClassVar[list[np.ndarray]] = []

    def __init__(self, src: Any) -> None:
        self.src = src
        self.pos = 0
        self.released = False
        self.props: dict[int, float] = {}
        self.own = list(type(self).frames)
        FakeCap.made.append(self)

    def isOpened(self) -> bool:
        return type(self).opened

    def set(self, prop: int, value: float) -> bool:
        self.props[prop] = value
        if prop == cv2.CAP_PROP_POS_FRAMES:
            self.pos = int(value)
        return True

    def read(self) -> tuple[bool, np.ndarray | None]:
        self.calls.append(f"read {self.src}")
        if self.pos >= len(self.own):
            return False, None
        self.pos += 1
        return True, self.own[self.pos - 1]

    def grab(self) -> bool:
        self.calls.append(f"grab {self.src}")
        if self.pos >= len(self.own):
            return False
        self.pos += 1
        return True

    def retrieve(self) -> tuple[bool, np.ndarray | None]:
        self.calls.append(f"retrieve {self.src}")
        return (True, self.own[self.pos - 1]) if self.pos else (False, None)

    def release(self) -> None:
        self.released = True


@pytest.fixture
def fake_cap(monkeypatch: pytest.MonkeyPatch) -> type[FakeCap]:
    FakeCap.made = []
    FakeCap.calls = []
    FakeCap.opened = True
    FakeCap.frames = [np.full((4, 6, 3), k, np.uint8) for k in (10, 20)]
    monkeypatch.setattr(cv2, "VideoCapture", FakeCap)
    return FakeCap


def test_video_pair_asks_devices_not_files_for_the_size(
    fake_cap: type[FakeCap], tmp_path: Path
) -> None:
    f = tmp_path / "r.avi"
    f.write_bytes(b"")
    pair = VideoPair("0", str(f), size=(640, 480))
    dev, file = fake_cap.made
    assert dev.src == 0 and file.src == str(f)
    assert dev.props == {cv2.CAP_PROP_FRAME_WIDTH: 640, cv2.CAP_PROP_FRAME_HEIGHT: 480}
    assert file.props == {}
    assert pair.sources == ("0", str(f))
    # The file starts again at its end (the device is read on, not rewound); the device
    # that ends says so.
    dev.own = [np.full((4, 6, 3), k, np.uint8) for k in range(1, 6)]
    reads = [tuple(int(x[0, 0, 0]) for x in pair.read()) for _ in range(3)]
    assert reads == [(1, 10), (2, 20), (4, 10)]  # 3 went with the file's end
    assert cv2.CAP_PROP_POS_FRAMES not in dev.props and file.pos == 1
    dev.pos = 5
    with pytest.raises(OSError, match=r"^camera '0' gave no frame$"):
        pair.read()
    pair.close()
    assert dev.released and file.released
    with pytest.raises(OSError, match=r"^camera pair is closed$"):
        pair.read()


def test_video_pair_without_size_sets_nothing(fake_cap: type[FakeCap]) -> None:
    pair = VideoPair(0, 1)
    assert [c.props for c in fake_cap.made] == [{}, {}]
    left, right = pair.read()
    assert left[0, 0, 0] == right[0, 0, 0] == 10
    pair.close()


def test_video_pair_grey_frames_become_bgr(fake_cap: type[FakeCap]) -> None:
    fake_cap.frames = [np.arange(24, dtype=np.uint8).reshape(4, 6)]
    pair = VideoPair(0, 1)
    left, _ = pair.read()
    assert left.shape == (4, 6, 3) and left.dtype == np.uint8 and left.flags.c_contiguous
    np.testing.assert_array_equal(left[..., 2], fake_cap.frames[0])
    pair.close()


def test_video_pair_that_cannot_open_releases_what_it_opened(
    fake_cap: type[FakeCap], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    f = tmp_path / "l.avi"
    f.write_bytes(b"")
    with pytest.raises(FileNotFoundError, match=r"^right camera source not found: .*none\.avi$"):
        VideoPair(str(f), str(tmp_path / "none.avi"))
    assert len(fake_cap.made) == 1 and fake_cap.made[0].released
    fake_cap.opened = False
    with pytest.raises(OSError, match=r"^cannot open camera 'x%d\.png' \(left\)$"):
        VideoPair("x%d.png", 0)  # a pattern is not looked for as a file
    assert fake_cap.made[-1].released


def test_video_pair_plays_an_image_sequence_again_after_the_last(tmp_path: Path) -> None:
    for k in range(2):
        img = np.full((8, 10), 50 + 100 * k, np.uint8)
        cv2.imwrite(str(tmp_path / f"img_{k:03d}.png"), img)
    pattern = str(tmp_path / "img_%03d.png")
    pair = VideoPair(pattern, pattern)
    try:
        got = [pair.read()[0][0, 0, 0] for _ in range(3)]
    finally:
        pair.close()
    assert got == [50, 150, 50]


@pytest.mark.parametrize(
    ("folder", "fmt", "first"),
    [("seq", "%03d", 5), ("seq", "%010d", 0), ("run 100%", "%03d", 0)],
    ids=["starts-at-5", "10-wide", "percent-folder"],
)
def test_video_pair_opens_the_sequences_capture_opens(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], folder: str, fmt: str, first: int
) -> None:
    """VideoPair opened an image sequence with cv2.VideoCapture alone: one whose first
    number is 5 or more (FFmpeg's image2 looks at 0-4), one 10 digits wide or in a folder
    whose name holds a ``%`` did not open ("cannot open camera"), while ``stereovision
    capture`` and ``stream`` open them (:class:`stereovision.capture._ImageSequence`). It
    opens them as they do, plays them again after the last pair, and OpenCV's warning of the
    file after the last is not printed."""
    seq = tmp_path / folder
    seq.mkdir()
    for k in range(first, first + 3):
        cv2.imwrite(str(seq / f"l_{fmt % k}.png"), np.full((6, 8), 10 + k, np.uint8))
        cv2.imwrite(str(seq / f"r_{fmt % k}.png"), np.full((6, 8), 100 + k, np.uint8))
    capfd.readouterr()
    left, right = str(seq / f"l_{fmt}.png"), str(seq / f"r_{fmt}.png")
    pair = VideoPair(left, right)
    try:
        got = [tuple(int(x[0, 0, 0]) for x in pair.read()) for _ in range(5)]
    finally:
        pair.close()
    assert got == [(10 + first + k, 100 + first + k) for k in (0, 1, 2, 0, 1)]
    source = sources.open_stereo_source(left, right)  # what the page opens, as capture does
    try:
        assert [tuple(int(x[0, 0, 0]) for x in source.read()) for _ in range(5)] == got
    finally:
        source.close()
    assert "WARN" not in capfd.readouterr().err


def test_video_pair_quiets_only_the_sequences_grab(tmp_path: Path) -> None:
    """A video paired with an image sequence: both grabs ran with OpenCV's process-wide log
    silenced, so the video's (or a camera's) own warnings were lost, and every other
    thread's meanwhile. Only the sequence's grab is quiet now; the level is put back."""
    log = cv2.utils.logging
    video = tmp_path / "l.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 5, (8, 6))
    for k in range(3):
        writer.write(np.full((6, 8, 3), 10 * k, np.uint8))
    writer.release()
    for k in range(5, 8):  # from 5: read by _ImageSequence
        cv2.imwrite(str(tmp_path / f"r_{k:03d}.png"), np.full((6, 8), 100 + k, np.uint8))

    class Recorder:
        """A capture that records OpenCV's log level at each grab."""

        def __init__(self, cap: Any, levels: list[int]) -> None:
            self.cap, self.levels = cap, levels

        def grab(self) -> bool:
            self.levels.append(log.getLogLevel())
            return bool(self.cap.grab())

        def __getattr__(self, name: str) -> Any:
            return getattr(self.cap, name)

    before = log.getLogLevel()
    log.setLogLevel(log.LOG_LEVEL_WARNING)
    try:
        pair = VideoPair(str(video), str(tmp_path / "r_%03d.png"))
        seen: tuple[list[int], list[int]] = ([], [])
        pair._caps = [Recorder(c, s) for c, s in zip(pair._caps, seen, strict=True)]
        try:
            got = [int(pair.read()[1][0, 0, 0]) for _ in range(4)]
        finally:
            pair.close()
        assert got == [105, 106, 107, 105]  # played again after the last
        assert set(seen[0]) == {log.LOG_LEVEL_WARNING}  # the video's warnings are said
        assert set(seen[1]) == {log.LOG_LEVEL_SILENT}
        assert log.getLogLevel() == log.LOG_LEVEL_WARNING
    finally:
        log.setLogLevel(before)


# ----------------------------------------------------------------------------- _CaptureAdapter


class FakeCamera:
    """Gives ``results`` in order (an exception is raised; the list is shared by the cameras
    a factory makes, as a file reopened goes on from its start); logs closes."""

    def __init__(self, results: list[Any], log: list[str]) -> None:
        self.results = results
        self.log = log

    def read(self) -> Any:
        got = self.results.pop(0)
        if isinstance(got, BaseException):
            raise got
        return got

    def close(self) -> None:
        self.log.append("close")

    def release(self) -> None:
        self.log.append("release")


def _frame(v: int) -> np.ndarray:
    return np.full((2, 3, 3), v, np.uint8)


def test_capture_adapter_reads_every_shape_of_pair() -> None:
    frame = types.SimpleNamespace(left=_frame(5), right=_frame(6))
    results = [(_frame(1), _frame(2)), (True, _frame(3), _frame(4)), frame]
    ad = sources._CaptureAdapter(lambda: FakeCamera(results, []), files=False)
    assert [tuple(int(x[0, 0, 0]) for x in ad.read()) for _ in range(3)] == [(1, 2), (3, 4), (5, 6)]


def test_capture_adapter_reopens_files_not_cameras() -> None:
    from stereovision import capture

    log: list[str] = []
    made: list[FakeCamera] = []

    def factory(results: list[Any]) -> Any:
        def make() -> FakeCamera:
            made.append(FakeCamera(results, log))
            return made[-1]

        return make

    cams = sources._CaptureAdapter(factory([(False, None, None)]), files=False)
    with pytest.raises(OSError, match=r"^camera pair gave no frame$"):
        cams.read()
    assert len(made) == 1 and log == []
    made.clear()
    files = sources._CaptureAdapter(factory([OSError("end"), (_frame(7), _frame(8))]), files=True)
    left, _ = files.read()
    assert left[0, 0, 0] == 7 and len(made) == 2 and log == ["close"]  # close, not also release
    assert files.restarted is None  # both ended together: nothing to say
    # one that ended early (a gap in its numbers): said by the read that started them again
    early = capture.SourceError("left source ended after 2 images: left03.png is missing", gap="x")
    files = sources._CaptureAdapter(factory([early, (_frame(1),) * 2, (_frame(2),) * 2]), True)
    assert files.read()[0][0, 0, 0] == 1 and files.restarted == str(early)
    assert files.read()[0][0, 0, 0] == 2 and files.restarted is None
    with pytest.raises(ValueError):  # only an ended source is reopened
        sources._CaptureAdapter(factory([ValueError("bad")]), files=True).read()

    class ReleaseOnly:
        def __init__(self) -> None:
            self.released = False

        def release(self) -> None:
            self.released = True

    cam = ReleaseOnly()
    sources._CaptureAdapter(lambda: cam, files=False).close()
    assert cam.released


# ----------------------------------------------------------------------------- open_stereo_source


def test_open_stereo_source_hands_size_fourcc_and_file_flag(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import stereovision.capture as capture

    made: list[tuple[Any, ...]] = []

    def fake_camera(
        left: Any, right: Any, *, image_size: Any, fourcc: Any, open_timeout: Any
    ) -> FakeCamera:
        made.append((left, right, image_size, fourcc, open_timeout))
        return FakeCamera([], [])

    monkeypatch.setattr(capture, "StereoCamera", fake_camera)
    src = sources.open_stereo_source(" 1", "2 ", size=(320, 240), fourcc="YUYV", read_timeout=3)
    assert made == [(1, 2, (320, 240), "YUYV", 3)]  # the read's bound bounds the open too
    assert isinstance(src, sources._CaptureAdapter) and src._files is False
    assert sources.open_stereo_source("a.avi", "b.avi")._files is True  # type: ignore[attr-defined]
    assert made[-1] == ("a.avi", "b.avi", None, None, capture.DEFAULT_READ_TIMEOUT)
    assert sources.open_stereo_source("a.avi", 0)._files is False  # type: ignore[attr-defined]
    with pytest.raises(ValueError, match=r"^fourcc: expected four characters"):
        sources.open_stereo_source(0, 1, fourcc="MJPEG")  # checked before a camera opens
    assert len(made) == 3
    # bound_open=False: the caller bounds the first open (the page, which waits for it in a
    # thread); a file opened again at its end, in a read, is bounded as the read is
    files = sources.open_stereo_source("a.avi", "b.avi", read_timeout=3, bound_open=False)
    assert made[-1][-1] is None
    files._factory()  # type: ignore[attr-defined]
    assert made[-1][-1] == 3 and len(made) == 5


class _SlowStart:
    """A VideoCapture stand-in whose first grab takes ``delay`` s (a camera slow to start)."""

    def __init__(self, delay: float) -> None:
        self.delay, self.grabs = delay, 0

    def isOpened(self) -> bool:
        return True

    def grab(self) -> bool:
        self.grabs += 1
        if self.grabs == 1:
            time.sleep(self.delay)
        return True

    def retrieve(self) -> tuple[bool, np.ndarray]:
        return True, _frame(self.grabs)

    def get(self, prop: int) -> float:
        return {cv2.CAP_PROP_FRAME_WIDTH: 3.0, cv2.CAP_PROP_FRAME_HEIGHT: 2.0}.get(prop, 0.0)

    def set(self, prop: int, value: float) -> bool:
        return False

    def release(self) -> None:
        pass


def test_open_stereo_source_gives_a_hung_read_up(monkeypatch: pytest.MonkeyPatch) -> None:
    """The GUI read its cameras without a time limit (capture's and stream's reads have one):
    a hung camera froze the page for good. A read now takes at most ``read_timeout`` s
    (capture's default): 0.2 s gives a 0.5 s first grab up, as capture says it; 2 s and None
    (no limit) wait for it."""
    import stereovision.capture as capture

    real = capture.StereoCamera
    monkeypatch.setattr(
        capture, "StereoCamera", lambda *a, **kw: real(_SlowStart(0.5), _SlowStart(0.0))
    )
    src = sources.open_stereo_source(0, 1, read_timeout=0.2)
    t0 = time.perf_counter()
    with pytest.raises(capture.SourceError, match=r" delivered no frame in 0\.2 s \(its read did"):
        src.read()
    assert time.perf_counter() - t0 < 0.45
    src.close()
    for timeout in (2.0, None):
        src = sources.open_stereo_source(0, 1, read_timeout=timeout)
        left, right = src.read()
        assert (int(left[0, 0, 0]), int(right[0, 0, 0])) == (1, 1)
        src.close()
    src = sources.open_stereo_source(0, 1)
    assert src._read_timeout == capture.DEFAULT_READ_TIMEOUT == 10.0  # type: ignore[attr-defined]
    src.close()


@pytest.mark.parametrize("fallback", [False, True])
def test_a_camera_whose_open_hangs_is_given_up(
    fake_cap: type[FakeCap], monkeypatch: pytest.MonkeyPatch, fallback: bool
) -> None:
    """The page's cameras were opened with no time limit (their reads had one): a wedged
    device froze the page for good in ``cv2.VideoCapture``. The open is now given up after
    ``read_timeout`` s, with capture's error naming the camera (OpenCV's fallback too)."""
    import threading

    unplug = threading.Event()

    class Wedged(FakeCap):
        def __init__(self, src: Any) -> None:
            if src == 1:
                unplug.wait(3.0)  # at most: the old code's test ends
            super().__init__(src)

        def get(self, prop: int) -> float:
            return 0.0

    monkeypatch.setattr(cv2, "VideoCapture", Wedged)
    if fallback:
        monkeypatch.setitem(sys.modules, "stereovision.capture", None)  # import fails
    t0 = time.perf_counter()
    try:
        with pytest.raises(OSError) as err:
            sources.open_stereo_source(0, 1, read_timeout=0.2)
        assert time.perf_counter() - t0 < 1.0
    finally:
        unplug.set()
    assert str(err.value) == (
        "right source camera 1 did not open within 0.2 s (its open did not return: a wedged "
        "camera or driver); unplug and replug it, or give it a longer timeout"
    )
    assert fake_cap.made[0].src == 0 and fake_cap.made[0].released  # the left one, opened
    deadline = time.monotonic() + 2.0  # the wedged open returns: its capture is released
    while not (len(fake_cap.made) == 2 and fake_cap.made[1].released):
        assert time.monotonic() < deadline, "the late capture was kept"
        time.sleep(0.01)


@pytest.mark.parametrize("fallback", [False, True])
def test_a_camera_whose_size_setting_hangs_is_given_up(
    fake_cap: type[FakeCap], monkeypatch: pytest.MonkeyPatch, fallback: bool
) -> None:
    """The open was bounded, but the size asked of a camera after it (``cap.set``) was not: a
    wedged device froze the page there. Open and size together are given up after
    ``read_timeout`` s, naming the camera and the setting (OpenCV's fallback too); the capture
    is released once its set returns."""
    import threading

    unplug = threading.Event()

    class Wedged(FakeCap):
        def set(self, prop: int, value: float) -> bool:
            if self.src == 1 and prop == cv2.CAP_PROP_FRAME_WIDTH:
                unplug.wait(3.0)  # at most: the old code's test ends
            return super().set(prop, value)

        def get(self, prop: int) -> float:
            return 0.0

    monkeypatch.setattr(cv2, "VideoCapture", Wedged)
    if fallback:
        monkeypatch.setitem(sys.modules, "stereovision.capture", None)  # import fails
    t0 = time.perf_counter()
    try:
        with pytest.raises(OSError) as err:
            sources.open_stereo_source(0, 1, size=(640, 480), read_timeout=0.2)
        assert time.perf_counter() - t0 < 1.0
    finally:
        unplug.set()
    assert str(err.value) == (
        "right source camera 1 did not open within 0.2 s (setting its frame width to 640 did "
        "not return: a wedged camera or driver); unplug and replug it, or give it a longer "
        "timeout"
    )
    deadline = time.monotonic() + 2.0  # its set returns: both captures are released
    while not (len(fake_cap.made) == 2 and all(c.released for c in fake_cap.made)):
        assert time.monotonic() < deadline, "a capture was kept"
        time.sleep(0.01)


@pytest.mark.parametrize(
    ("left", "right", "files"), [("rtsp://a/1", "rtsp://a/2", False), ("a.avi", "b.avi", True)]
)
def test_a_stream_given_by_name_is_not_reopened_when_its_read_hangs(
    monkeypatch: pytest.MonkeyPatch, left: str, right: str, files: bool
) -> None:
    """Sources given by name (``rtsp://...``, ``/dev/video0``: "files", opened again at their
    end) were opened again when their read was given up as hung (a SourceError is an OSError):
    a second open of the hung device and a second full wait, the page frozen twice as long. The
    read says the time-out after one wait; a file's end still starts it again.

    A stream is no file since test_open_stereo_source_takes_streams_and_device_nodes_as_live
    (it pinned ``_files is True`` for rtsp://): a pair of files given up as hung is not opened
    again either."""
    import stereovision.capture as capture

    real = capture.StereoCamera
    opened: list[int] = []

    def slow(*a: Any, **kw: Any) -> Any:
        opened.append(1)
        return real(_SlowStart(0.5), _SlowStart(0.0))

    monkeypatch.setattr(capture, "StereoCamera", slow)
    src = sources.open_stereo_source(left, right, read_timeout=0.2)
    assert src._files is files  # type: ignore[attr-defined]
    t0 = time.perf_counter()
    with pytest.raises(capture.SourceError, match=r" delivered no frame in 0\.2 s"):
        src.read()
    assert time.perf_counter() - t0 < 0.35 and len(opened) == 1
    src.close()


def test_open_stereo_source_takes_streams_and_device_nodes_as_live(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """With the capture module (the page's path), any text source was a file: a stream
    (rtsp://, http://) or a camera by its device node (/dev/video7, a /dev/v4l/by-id link) that
    stopped was opened again as a file's end is, its end said as nothing (73cb4e7 fixed only
    VideoPair). Their end is now the error StereoCamera says; files still start again."""
    import stereovision.capture as capture

    link = tmp_path / "usb-cam-video-index0"
    link.symlink_to("/dev/video7")  # a by-id link: resolved to the node, existing or not
    ended = "left source /dev/video7 stopped delivering frames after 2 (disconnected?)"
    made: list[tuple[Any, Any]] = []
    results: list[Any] = []  # shared: a camera opened again goes on from where the last ended

    def fake_camera(left: Any, right: Any, **kw: Any) -> FakeCamera:
        made.append((left, right))
        return FakeCamera(results, [])

    monkeypatch.setattr(capture, "StereoCamera", fake_camera)
    for left, right in (
        ("rtsp://cam/0", "rtsp://cam/1"),
        ("http://cam/l.mjpg", "http://cam/r.mjpg"),
        ("/dev/video7", "/dev/video8"),
        (str(link), "/dev/video8"),
        ("rtsp://cam/0", "a.avi"),
    ):
        made.clear()
        results[:] = [capture.SourceError(ended, side="left"), (_frame(1), _frame(2))]
        src = sources.open_stereo_source(left, right)
        with pytest.raises(capture.SourceError, match=rf"^{re.escape(ended)}$"):
            src.read()
        assert made == [(left, right)], (left, right)  # not opened again
    # a pair of files (a video, a sequence) still starts again at its end
    made.clear()
    results[:] = [capture.SourceError(ended, side="left"), (_frame(1), _frame(2))]
    src = sources.open_stereo_source("a.avi", "r_%03d.png")
    assert [int(x[0, 0, 0]) for x in src.read()] == [1, 2] and len(made) == 2


def test_open_stereo_source_falls_back_to_opencv(
    fake_cap: type[FakeCap], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "stereovision.capture", None)  # import fails
    src = sources.open_stereo_source("0", 1, size=(8, 6), fourcc="MJPG")
    assert isinstance(src, VideoPair) and [c.src for c in fake_cap.made] == [0, 1]
    assert fake_cap.made[0].props[cv2.CAP_PROP_FRAME_WIDTH] == 8
    src.close()


# ----------------------------------------------------------------------------- FolderPairs


def _pairs_folder(root: Path, n: int) -> Path:
    seq = root / "seq"
    seq.mkdir(parents=True)
    for k in range(1, n + 1):
        for side, v in (("left", k), ("right", 100 + k)):
            cv2.imwrite(str(seq / f"{side}_{k:04d}.png"), np.full((4, 5, 3), v, np.uint8))
    return seq


def test_folder_pairs_play_in_order_and_again(tmp_path: Path) -> None:
    seq = _pairs_folder(tmp_path, 3)
    fp = FolderPairs(seq, "data/seq")
    assert fp.current is None and fp.describe() == "folder data/seq"
    got = [tuple(int(x[0, 0, 0]) for x in fp.read()) for _ in range(4)]
    assert got == [(1, 101), (2, 102), (3, 103), (1, 101)]
    assert fp.current is not None and fp.current.left.name == "left_0001.png"
    assert fp.describe() == "folder data/seq: pair 0001 (1 of 3)"
    fp.read()
    assert fp.describe() == "folder data/seq: pair 0002 (2 of 3)"
    fp.close()  # nothing to release; reading goes on
    assert fp.read()[0][0, 0, 0] == 3


def test_folder_pairs_say_a_file_gone_since_with_its_pair(tmp_path: Path) -> None:
    """A pair's file removed (or spoilt) while the folder played was said by its whole path
    alone ("image file not found: /tmp/.../seq/right_0002.png") under the label of the pair
    before, the next Capture going on to pair 0003: which pair was skipped went unsaid. It is
    said with the pair, the path from the folder's name, and the next read goes on; so is a
    played scene's calib.txt spoilt or removed."""
    seq = _pairs_folder(tmp_path, 3)
    fp = FolderPairs(seq, "data/seq")
    fp.read()
    (seq / "right_0002.png").unlink()
    (seq / "left_0003.png").write_bytes(b"not an image")
    with pytest.raises(FileNotFoundError) as gone:
        fp.read()
    assert str(gone.value) == (
        "folder data/seq: pair 0002 (2 of 3): image file not found: data/seq/right_0002.png"
    )
    with pytest.raises(ValueError, match=r"^folder data/seq: pair 0003 \(3 of 3\): cannot decode "):
        fp.read()
    assert fp.read()[0][0, 0, 0] == 1  # the first again
    # a played scene's calibration too (the page's _read_pair reads it)
    from stereovision.gui.app import _read_pair

    for name in ("a", "b"):
        scene = tmp_path / "sc" / name
        scene.mkdir(parents=True)
        for side in ("left", "right"):
            cv2.imwrite(str(scene / f"{side}.png"), np.zeros((4, 5, 3), np.uint8))
        (scene / "calib.txt").write_text("not a calibration\n")
    scenes = FolderPairs(tmp_path / "sc", "data/sc")
    with pytest.raises(ValueError, match=r"^folder data/sc: pair a \(1 of 2\): unrecognised "):
        _read_pair(scenes, False)
    (tmp_path / "sc" / "b" / "calib.txt").unlink()
    with pytest.raises(FileNotFoundError) as gone:
        _read_pair(scenes, False)
    assert str(gone.value) == (
        "folder data/sc: pair b (2 of 2): calibration file not found: data/sc/b/calib.txt"
    )


def test_folder_pairs_keep_and_no_pairs(tmp_path: Path) -> None:
    seq = _pairs_folder(tmp_path, 2)
    fp = FolderPairs(seq, "s", keep=lambda p: "0002" not in p.name)
    assert [j.name for j in fp.jobs] == ["0001"]
    one_side = FolderPairs(seq, "s", keep=lambda p: p.name != "right_0002.png")
    assert [j.name for j in one_side.jobs] == ["0001"]  # a pair is kept only whole
    with pytest.raises(ValueError, match=r"^no image pairs in s \(left_0001\.png"):
        FolderPairs(seq, "s", keep=lambda p: False)
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match=r"^no image pairs in e "):
        FolderPairs(tmp_path / "empty", "e")


def test_folder_pairs_read_is_annotated_with_the_uint16_it_returns(tmp_path: Path) -> None:
    """FolderPairs.read returns a 16-bit pair at its 16 bits (uint16) but was annotated as
    uint8 arrays (a type: ignore hid it), as the page's StereoSource.read was: both say uint16."""
    import typing

    from stereovision.gui.sources import StereoSource

    scene = tmp_path / "sc"
    scene.mkdir()
    for name in ("left.png", "right.png"):
        cv2.imwrite(str(scene / name), np.full((4, 5, 3), 4095, np.uint16))
    left, right = FolderPairs(scene, "sc").read()
    assert left.dtype == right.dtype == np.uint16 and int(left.max()) == 4095
    for read in (FolderPairs.read, StereoSource.read):
        said = str(typing.get_type_hints(read)["return"])
        assert "uint16" in said and "uint8" in said, said


def test_folder_pairs_keep_checks_a_scenes_calibration_too(tmp_path: Path) -> None:
    # a scene whose calib.txt is a link out of the allowed folders is dropped whole: its
    # calibration would be read from outside them
    img = np.full((4, 5, 3), 9, np.uint8)
    for name in ("a", "b"):
        d = tmp_path / "scenes" / name
        d.mkdir(parents=True)
        cv2.imwrite(str(d / "left.png"), img)
        cv2.imwrite(str(d / "right.png"), img)
    (tmp_path / "secret.txt").write_text("cam0=[1 0 2; 0 1 2; 0 0 1]\n")
    (tmp_path / "scenes" / "b" / "calib.txt").symlink_to(tmp_path / "secret.txt")
    folders = AllowedFolders([tmp_path / "scenes"])
    fp = FolderPairs(tmp_path / "scenes", "scenes", keep=folders.contains)
    assert [j.left.parent.name for j in fp.jobs] == ["a"]


# ----------------------------------------------------------------------------- scaling


def test_scale_pair_never_enlarges_and_rounds_the_height() -> None:
    left = np.zeros((7, 10, 3), np.uint8)
    right = np.ones((7, 10, 3), np.uint8)
    for width in (None, 10, 11):
        l2, r2, s = sources.scale_pair(left, right, width)
        assert l2 is left and r2 is right and s == 1.0
    l2, r2, s = sources.scale_pair(left, right, 5)
    assert l2.shape == r2.shape == (4, 5, 3) and s == 0.5  # 3.5 rounds to 4
    assert r2[0, 0, 0] == 1 and l2.dtype == np.uint8
    l2, _, s = sources.scale_pair(left, right, 1)
    assert l2.shape == (1, 1, 3) and s == pytest.approx(0.1)
    wide = np.zeros((1, 40, 3), np.uint8)
    assert sources.scale_pair(wide, wide, 4)[0].shape == (1, 4, 3)  # height 0.1: one row


def test_scale_pair_averages_the_pixels_it_merges() -> None:
    """INTER_AREA: a fine checkerboard halved is its mean grey (nearest-neighbour would keep
    one colour of it, and alias)."""
    board = np.indices((8, 8)).sum(axis=0) % 2 * 200
    img = np.repeat(board[..., None], 3, axis=2).astype(np.uint8)
    small, small_r, _ = sources.scale_pair(img, img, 4)
    np.testing.assert_array_equal(small, np.full((4, 4, 3), 100, np.uint8))
    np.testing.assert_array_equal(small_r, small)


def test_scale_pair_keeps_a_16_bit_pair_16_bit() -> None:
    """A 16-bit pair (a 16-bit PNG sequence) at 640 or 320 px was cast to uint8, its levels
    wrapped modulo 256: matched as noise (cones at 200 px: disparities 0-112 px, 'look
    unrectified', where its 8-bit copy gives 0-32 px)."""
    from stereovision.gui.app import compute_view
    from stereovision.io import imread

    cones = Path(sources.__file__).resolve().parents[1] / "data" / "cones"
    left8, right8 = imread(cones / "left.png"), imread(cones / "right.png")
    left, right = (im.astype(np.uint16) * 257 for im in (left8, right8))
    small, small_r, s = sources.scale_pair(left, right, 200)
    small8, _, s8 = sources.scale_pair(left8, right8, 200)
    assert small.dtype == small_r.dtype == np.uint16 and s == s8
    assert np.abs(small.astype(np.int64) - small8.astype(np.int64) * 257).max() <= 257
    view16 = compute_view(left, right, None, "fast", width=200)
    view8 = compute_view(left8, right8, None, "fast", width=200)
    assert view16.result.max_disparity == view8.result.max_disparity == 32
    assert "unrectified" not in view16.stats


def test_video_pair_keeps_a_16_bit_sequence_16_bit(tmp_path: Path) -> None:
    """VideoPair (the fallback without stereovision.capture) cast a 16-bit sequence's frame to
    uint8, its levels wrapped modulo 256 (300 read as 44); the capture path keeps it uint16,
    and so does it now (grey made BGR as before)."""
    grey = (np.arange(12 * 16).reshape(12, 16) * 300).astype(np.uint16)
    for i in range(5, 7):  # from 5: read by capture's _ImageSequence, IMREAD_UNCHANGED
        for side in ("l", "r"):
            assert cv2.imwrite(str(tmp_path / f"{side}_{i:03d}.png"), grey)
    pair = VideoPair(str(tmp_path / "l_%03d.png"), str(tmp_path / "r_%03d.png"))
    try:
        left, right = pair.read()
    finally:
        pair.close()
    assert left.dtype == right.dtype == np.uint16 and left.shape == (12, 16, 3)
    np.testing.assert_array_equal(left[..., 0], grey)
    np.testing.assert_array_equal(right[..., 2], grey)


def test_scaled_calibration_passes_none_and_unscaled_through() -> None:
    asked: list[Any] = []

    class Calib:
        def scaled_to(self, size: Any) -> str:
            asked.append(size)
            return "scaled"

    c = Calib()
    assert sources.scaled_calibration(None, 0.5, (1, 1)) is None
    assert sources.scaled_calibration(c, 1.0, (9, 9)) is c
    assert sources.scaled_calibration(c, 0.5, (np.int64(80), 60.0)) == "scaled"  # type: ignore[arg-type]
    assert asked == [(80, 60)] and all(type(v) is int for v in asked[0])


# ----------------------------------------------------------------------------- bags


def test_open_bag_source_probes_then_plays_from_the_start(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    rosbag = pytest.importorskip("stereovision.rosbag")
    made: list[Any] = []

    class FakeBag:
        def __init__(self, path: Any, left_topic: Any = None, right_topic: Any = None) -> None:
            self.args = (path, left_topic, right_topic)
            self.topics = {"left": "/l/image", "right": "/r/image"}
            self.closed = False
            made.append(self)

        def __enter__(self) -> FakeBag:
            return self

        def __exit__(self, *exc: object) -> None:
            self.closed = True

        def calibration(self) -> str:
            return "calib"

        def read(self) -> Any:
            return (_frame(1), _frame(2))

        def close(self) -> None:
            self.closed = True

    monkeypatch.setattr(rosbag, "BagCamera", FakeBag)
    src, calib, names = sources.open_bag_source(tmp_path / "b.bag", "/l", "/r")
    assert calib == "calib" and names == ("/l/image", "/r/image")
    assert len(made) == 2 and made[0].closed and not made[1].closed  # the probe is closed
    assert made[1].args == (tmp_path / "b.bag", "/l", "/r")
    assert src._files is True  # type: ignore[attr-defined]


def test_a_data_folder_at_the_top_of_the_disk_is_labelled_with_one_slash(tmp_path: Path) -> None:
    """``--data /data`` beside the bundled ``.../stereovision/data``: the root's name took the
    anchor as a part of its own and joined it with "/" again, so the page listed "//data/...";
    a ``--data /`` listed "//etc/...". Both now read as the path they are."""
    top = Path("/tmp").resolve()
    if len(top.parts) != 2:
        pytest.skip("/tmp is not a folder directly under /")
    (tmp_path / top.name).mkdir()
    both = AllowedFolders([tmp_path / top.name, top])
    assert both.label(top) == "/tmp"
    assert both.label(top / "x.png") == "/tmp/x.png"
    assert both.label(tmp_path / top.name / "y") == f"{tmp_path.name}/tmp/y"
    root = AllowedFolders(["/"])
    assert root.label(Path("/")) == "/"
    assert root.label(Path("/etc/hosts")) == "/etc/hosts"


def test_video_pair_of_unequal_lengths_starts_both_again_together(tmp_path: Path) -> None:
    """Each file started again on its own: a 2-frame left and a 3-frame right gave left 0 with
    right 2 on the third read, and every pair after it out of step (StereoCamera, the usual
    path, opens the pair again as one). Both files now start again when either ends."""
    for side, n in (("l", 2), ("r", 3)):
        for k in range(n):
            img = np.full((8, 10), 50 + 50 * k, np.uint8)
            cv2.imwrite(str(tmp_path / f"{side}_{k:03d}.png"), img)
    pair = VideoPair(str(tmp_path / "l_%03d.png"), str(tmp_path / "r_%03d.png"))
    try:
        got = [tuple(int(x[0, 0, 0]) for x in pair.read()) for _ in range(5)]
    finally:
        pair.close()
    assert got == [(50, 50), (100, 100), (50, 50), (100, 100), (50, 50)]


def test_video_pair_of_a_file_without_frames_names_it(
    fake_cap: type[FakeCap], tmp_path: Path
) -> None:
    f = tmp_path / "empty.avi"
    f.write_bytes(b"")
    pair = VideoPair(0, str(f))
    fake_cap.made[1].own = []  # no frame, even from the start
    with pytest.raises(OSError, match=r"^camera '.*empty\.avi' gave no frame$"):
        pair.read()
    fake_cap.made[1].own = list(fake_cap.frames)
    fake_cap.made[1].props.clear()
    fake_cap.made[0].pos = 2  # a device that gives no frame fails at once
    with pytest.raises(OSError, match=r"^camera 0 gave no frame$"):
        pair.read()
    assert fake_cap.made[1].props == {}  # the file was not started again for it
    pair.close()


def test_video_pair_names_the_left_file_when_it_has_no_frame(
    fake_cap: type[FakeCap], tmp_path: Path
) -> None:
    """The left file's own name, not the right camera's (the check after both files started
    again names each side: naming sources[1] for the left passed the other tests)."""
    f = tmp_path / "empty.avi"
    f.write_bytes(b"")
    pair = VideoPair(str(f), 1)
    fake_cap.made[0].own = []
    with pytest.raises(OSError, match=r"^camera '.*empty\.avi' gave no frame$"):
        pair.read()
    assert fake_cap.made[0].props == {cv2.CAP_PROP_POS_FRAMES: 0}  # it was started again first
    pair.close()


def test_video_pair_grabs_both_before_it_decodes_either(fake_cap: type[FakeCap]) -> None:
    """read() said "grab both, then decode both" and read (grabbed and decoded) one camera
    after the other: the right camera's frame was taken a whole decode later than the left's.
    Both are now grabbed first, as StereoCamera does."""
    pair = VideoPair(0, 1)
    left, right = pair.read()
    assert fake_cap.calls == ["grab 0", "grab 1", "retrieve 0", "retrieve 1"]
    assert left[0, 0, 0] == right[0, 0, 0] == 10
    pair.close()


def test_a_data_folder_inside_another_is_listed_once(data: Path) -> None:
    """``--data`` naming a folder that holds another allowed folder (the bundled data inside
    a checkout given as ``--data .``): each file below both was offered twice in the page's
    lists, and the inner folder twice among the folders to play."""
    folders = AllowedFolders([data / "scene", data])
    assert folders.files(sources.IMAGE_SUFFIXES) == [
        data / "scene" / "left.png",
        data / "scene" / "right.png",
    ]
    assert folders.folders() == [data / "scene", data.resolve()]
    assert folders.scenes() == [data / "scene"]


# ----------------------------------------------------------------------------- allowed folders


def test_a_relative_path_is_taken_in_the_data_folder_it_is_in(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A relative path was taken under the first root alone, which with ``--data`` is the
    bundled demo data: a pattern typed in a camera field (``seq/left%02d.png``) or a file
    named as the page's lists name it (``scenes/data/seq/left01.png``) was "no such file"
    of a file in the --data folder. It is now taken under the first root it is in (as
    labelled, relative to a root or to the current folder), the first root first."""
    bundled, data = tmp_path / "stereovision" / "data", tmp_path / "scenes" / "data"
    for root in (bundled, data):
        (root / "cones").mkdir(parents=True)
        (root / "cones" / "left.png").write_bytes(b"x")
    (data / "seq").mkdir()
    (data / "seq" / "left01.png").write_bytes(b"x")
    (tmp_path / "secret.png").write_bytes(b"x")
    folders = AllowedFolders([bundled, data])
    seq = (data / "seq" / "left01.png").resolve()
    assert folders.label(seq) == "scenes/data/seq/left01.png"
    assert folders.resolve("seq/left01.png") == seq
    assert folders.resolve("scenes/data/seq/left01.png") == seq
    assert folders.resolve("seq") == seq.parent  # a camera field's pattern, by its folder
    assert folders.resolve("cones/left.png") == (bundled / "cones" / "left.png").resolve()
    monkeypatch.chdir(tmp_path / "scenes")
    assert folders.resolve("data/seq/left01.png") == seq  # as the page's messages show it
    with pytest.raises(FileNotFoundError, match=r"^no such file: seq/left02\.png$"):
        folders.resolve("seq/left02.png")
    with pytest.raises(ValueError, match=r"^path outside the allowed folders: \.\./secret"):
        folders.resolve("../secret.png")  # under the current folder's parent: still refused


@pytest.fixture
def tree(tmp_path):
    """data/ (allowed) with a file, a sub-folder and a symlink out; secret/ beside it."""
    data = tmp_path / "data"
    (data / "sub").mkdir(parents=True)
    (data / "sub" / "a.ply").write_text("x")
    (data / "img.png").write_bytes(b"png")
    secret = tmp_path / "secret"
    secret.mkdir()
    (secret / "key.ply").write_text("secret")
    (data / "link.ply").symlink_to(secret / "key.ply")
    (data / "linkdir").symlink_to(secret)
    (tmp_path / "data2").mkdir()
    (tmp_path / "data2" / "b.ply").write_text("y")
    return data, secret


def test_allowed_folders_accept_inside(tree):
    data, _ = tree
    folders = AllowedFolders([data])
    assert folders.resolve(data / "sub" / "a.ply") == (data / "sub" / "a.ply").resolve()
    assert folders.resolve("sub/a.ply") == (data / "sub" / "a.ply").resolve()  # relative to root
    assert folders.resolve(data / "sub" / ".." / "img.png") == (data / "img.png").resolve()


@pytest.mark.parametrize(
    "path",
    [
        "../secret/key.ply",
        "sub/../../secret/key.ply",
        "link.ply",  # symlink to a file outside
        "linkdir/key.ply",  # symlinked folder outside
        "/etc/passwd",
        "../data2/b.ply",  # a sibling whose name starts like the root
        "",
    ],
)
def test_allowed_folders_reject_escapes(tree, path):
    data, _ = tree
    with pytest.raises(ValueError, match=r"outside the allowed folders|empty"):
        AllowedFolders([data]).resolve(path)


def test_allowed_folders_listing_and_errors(tree):
    data, _ = tree
    folders = AllowedFolders([data])
    listed = folders.files(sources.CLOUD_SUFFIXES)
    assert listed == [(data / "sub" / "a.ply").resolve()] or listed == [data / "sub" / "a.ply"]
    with pytest.raises(FileNotFoundError, match="no such file"):
        folders.resolve("sub/missing.ply")
    with pytest.raises(FileNotFoundError, match="data folder not found"):
        AllowedFolders([data / "nope"])


def test_two_data_folders_of_one_name_are_told_apart(tmp_path):
    # the bundled ".../stereovision/data" and "--data .../shared/data" both read "data/..."
    a, b = tmp_path / "pkg" / "data", tmp_path / "shared" / "data"
    for d in (a, b):
        (d / "cones").mkdir(parents=True)
    both = AllowedFolders([a, b])
    assert [both.label(d / "cones") for d in (a, b)] == ["pkg/data/cones", "shared/data/cones"]
    assert AllowedFolders([a]).label(a / "cones") == "data/cones"  # alone: as before


def test_scene_list_is_not_cut_short_by_other_images(tmp_path, monkeypatch):
    """The listing's limit counted PNG files: a folder of calibration pairs before the scenes
    (in walking order) filled it, and the scenes after it were not offered."""
    monkeypatch.setattr(sources, "MAX_LISTED", 5)
    (tmp_path / "a_calib").mkdir()
    for k in range(6):
        (tmp_path / "a_calib" / f"left_{k:02d}.png").write_bytes(b"png")
    for name in ("b_scene", "c_scene"):
        (tmp_path / name).mkdir()
        for side in ("left.png", "right.png"):
            (tmp_path / name / side).write_bytes(b"png")
    (tmp_path / "d_half").mkdir()
    (tmp_path / "d_half" / "left.png").write_bytes(b"png")  # no right.png: not a scene
    folders = AllowedFolders([tmp_path])
    assert [folders.label(p) for p in folders.scenes()] == [
        f"{tmp_path.name}/b_scene",
        f"{tmp_path.name}/c_scene",
    ]


# -------------------------------------------------------------------------------------- video files


def test_video_pair_reads_frames_and_rewinds(tmp_path):
    img = syn.left_image()
    lv = _write_video(tmp_path / "l.avi", img)
    rv = _write_video(tmp_path / "r.avi", img[:, ::-1].copy())
    pair = sources.VideoPair(str(lv), str(rv))
    try:
        frames = [pair.read() for _ in range(VIDEO_FRAMES + 1)]
    finally:
        pair.close()
    assert frames[0][0].shape == img.shape
    # Consecutive frames differ (rolled), and after the last frame the video starts again.
    assert np.abs(frames[0][0].astype(int) - frames[1][0]).mean() > 10
    assert np.abs(frames[0][0].astype(int) - frames[VIDEO_FRAMES][0]).mean() < 3


def test_missing_cameras_clear_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="left camera source not found"):
        sources.VideoPair(str(tmp_path / "none.avi"), str(tmp_path / "none2.avi"))
    with pytest.raises(OSError, match="cannot open camera 9"):
        sources.VideoPair(9, 10)
    with pytest.raises(ValueError, match="empty camera source"):
        sources.parse_source(" ")


def test_open_stereo_source_loops_video_files(tmp_path):
    img = syn.left_image()
    lv = _write_video(tmp_path / "l.avi", img)
    rv = _write_video(tmp_path / "r.avi", img)
    src = sources.open_stereo_source(str(lv), str(rv))
    try:
        frames = [src.read()[0] for _ in range(2 * VIDEO_FRAMES + 1)]
    finally:
        src.close()
    assert all(f.shape == img.shape for f in frames)
    assert np.abs(frames[0].astype(int) - frames[VIDEO_FRAMES]).mean() < 3  # started again
    with pytest.raises(OSError, match="7"):
        sources.open_stereo_source(7, 8)


def test_video_pair_says_a_stream_that_gives_no_frame_without_its_password(
    fake_cap: type[FakeCap],
) -> None:
    """A URL with a percent-encoded password ("%" in it: not looked for as a file) that opens
    and gives no frame was said whole, 'camera 'rtsp://admin:p%40ss@cam/0' gave no frame',
    where its "cannot open" is masked."""
    fake_cap.frames = []
    url = "rtsp://admin:p%40ss@cam/0"
    pair = VideoPair(url, url)
    with pytest.raises(OSError, match=r"^camera 'rtsp://admin:\*\*\*@cam/0' gave no frame$"):
        pair.read()
    pair.close()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="V4L2 device nodes are Linux's")
def test_video_pair_takes_a_stream_or_device_node_for_no_file(fake_cap: type[FakeCap]) -> None:
    """Any text source was a file: a stream's URL without a "%" was refused as "left camera
    source not found: rtsp://cam/0", and a camera given by its device node was not asked the
    size, its missing frame taken for a file's end (rewound, not said)."""
    pair = VideoPair("rtsp://cam/0", "/dev/video7", size=(640, 480))
    stream, dev = fake_cap.made
    assert (stream.src, dev.src) == ("rtsp://cam/0", "/dev/video7")
    assert stream.props == {}  # a stream is asked no size
    assert dev.props == {cv2.CAP_PROP_FRAME_WIDTH: 640, cv2.CAP_PROP_FRAME_HEIGHT: 480}
    assert [tuple(int(x[0, 0, 0]) for x in pair.read()) for _ in range(2)] == [(10, 10), (20, 20)]
    # Neither is rewound when it gives no frame: said, as a camera by its index is.
    with pytest.raises(OSError, match=r"^camera 'rtsp://cam/0' gave no frame$"):
        pair.read()
    assert cv2.CAP_PROP_POS_FRAMES not in stream.props | dev.props
    pair.close()
    # A local path that does not exist is still refused as a file.
    with pytest.raises(FileNotFoundError, match=r"^left camera source not found: nope\.avi$"):
        VideoPair("nope.avi", "/dev/video7")


def test_a_loop_of_links_in_a_data_folder_is_no_file_and_stops_nothing(tmp_path: Path) -> None:
    """A loop of symbolic links in a --data folder (a.png -> b.png -> a.png) stopped the GUI at
    start-up: listing the folder's images raised Python 3.11's RuntimeError "Symlink loop from
    '.../a.png'" ('stereovision: error: Symlink loop from ...', exit 2), and one typed on the
    page (a file, a Save folder) went past the handlers. The loop is now no file: left out of
    the lists, said as one where a file is asked for, a Save folder checked as any other."""
    (tmp_path / "a.png").symlink_to("b.png")
    (tmp_path / "b.png").symlink_to("a.png")
    (tmp_path / "loop").symlink_to("loop")
    cv2.imwrite(str(tmp_path / "ok.png"), np.zeros((4, 4, 3), np.uint8))
    folders = AllowedFolders([tmp_path])
    assert folders.files(frozenset({".png"})) == [tmp_path.resolve() / "ok.png"]
    loop = "one of a loop of links that never reaches a file"
    with pytest.raises(
        FileNotFoundError, match=rf"^no such file: a\.png \(a link to b\.png, {loop}\)$"
    ):
        folders.resolve("a.png")
    with pytest.raises(FileNotFoundError, match=r"^no such file: loop/x\.png$"):
        folders.resolve("loop/x.png")
    assert not folders.contains("loop")
    assert folders.resolve_output("loop/x") == tmp_path.resolve() / "loop" / "x"


def test_a_link_to_a_missing_file_typed_on_the_page_names_its_target(tmp_path: Path) -> None:
    """_loop_note looked for "loop" in _broken_link's words: a link to a missing file was
    "no such file: y.png" of a name ls lists, unless its target's name held "loop"
    (x.png -> loops/none.png). Every link that reaches no file names its target, as --data's
    words do (e55e27d1)."""
    (tmp_path / "loops").mkdir()
    (tmp_path / "x.png").symlink_to(Path("loops") / "none.png")
    (tmp_path / "y.png").symlink_to("none.png")
    folders = AllowedFolders([tmp_path])
    for name, target in (("x.png", "loops/none.png"), ("y.png", "none.png")):
        with pytest.raises(FileNotFoundError) as err:
            folders.resolve(name)
        assert str(err.value) == f"no such file: {name} (a link to {target}, which does not exist)"


def test_a_file_typed_on_the_page_out_of_reach_is_said_unreadable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A file (or a link to one) behind a folder the user may not enter was "[Errno 13]
    Permission denied: '/data/secret/x.png'", the link's target alone: what was typed is said,
    and the link."""
    import errno
    import os

    (tmp_path / "secret").mkdir()
    (tmp_path / "secret" / "x.png").write_bytes(b"png")
    (tmp_path / "link.png").symlink_to(Path("secret") / "x.png")
    stat = os.stat

    def denied(p: Any, *args: Any, **kwargs: Any) -> Any:  # as for a user other than root
        if "secret" in os.fspath(p) and kwargs.get("follow_symlinks", True):
            raise PermissionError(errno.EACCES, "Permission denied", os.fspath(p))
        return stat(p, *args, **kwargs)

    monkeypatch.setattr(os, "stat", denied)
    folders = AllowedFolders([tmp_path])
    for name, said in (
        ("link.png", "link.png (a link to secret/x.png)"),
        ("secret/x.png", "secret/x.png"),
    ):
        with pytest.raises(PermissionError) as err:
            folders.resolve(name)
        assert str(err.value) == f"cannot read {said}: Permission denied"


def test_a_data_folder_out_of_reach_is_said_unreadable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """--data behind a folder the user may not enter, or a link to one: "[Errno 13] Permission
    denied: '/mnt/secret/data'", a link's target alone, not the folder given."""
    import errno
    import os

    (tmp_path / "secret" / "data").mkdir(parents=True)
    (tmp_path / "data").symlink_to(Path("secret") / "data")
    stat = os.stat

    def denied(p: Any, *args: Any, **kwargs: Any) -> Any:  # as for a user other than root
        if os.fspath(p) == str(tmp_path / "data") or "secret" in os.fspath(p):
            if kwargs.get("follow_symlinks", True):
                raise PermissionError(errno.EACCES, "Permission denied", os.fspath(p))
        return stat(p, *args, **kwargs)

    monkeypatch.setattr(os, "stat", denied)
    for given, said in (
        (tmp_path / "data", f"{tmp_path / 'data'} (a link to secret/data)"),
        (tmp_path / "secret" / "data", str(tmp_path / "secret" / "data")),
    ):
        with pytest.raises(PermissionError) as err:
            AllowedFolders([given])
        assert str(err.value) == f"data folder cannot be read: {said}: Permission denied"


def test_a_data_folder_or_video_link_whose_target_moved_names_it(tmp_path: Path) -> None:
    # --data data -> moved/data (a disk since unmounted), VideoPair("v.avi") -> moved/v.avi:
    # "not found" alone, of a name ls lists, where load_scene and StereoCamera name the target
    (tmp_path / "data").symlink_to(Path("moved") / "data")
    (tmp_path / "v.avi").symlink_to(Path("moved") / "v.avi")
    with pytest.raises(FileNotFoundError) as err:
        AllowedFolders([tmp_path / "data"])
    assert str(err.value) == (
        f"data folder not found: {tmp_path / 'data'} (a link to moved/data, which does not exist)"
    )
    with pytest.raises(FileNotFoundError) as err:
        VideoPair(str(tmp_path / "v.avi"), str(tmp_path / "v.avi"))
    assert str(err.value) == (
        f"left camera source not found: {tmp_path / 'v.avi'} (a link to moved/v.avi, which "
        "does not exist)"
    )
