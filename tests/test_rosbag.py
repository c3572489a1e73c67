"""ROS 2 bags of depth results, read back with rosbags' own reader: every topic's values."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import stereovision as sv
from stereovision.io import load_scene

rosbags = pytest.importorskip("rosbags")


@pytest.fixture(scope="module")
def kitti(data_dir: Path) -> tuple:
    sc = load_scene(data_dir / "kitti2015" / "000005_10")
    res = sv.depth_map(sc.left, sc.right, sc.calib, method="gabor", max_disparity=sc.max_disparity)
    lean = sv.depth_map(sc.left, sc.right, sc.calib, method="gabor",
                        max_disparity=sc.max_disparity, cloud=False)  # fmt: skip
    return res, lean


@pytest.fixture(scope="module")
def kitti_filled(data_dir: Path) -> sv.DepthResult:
    """KITTI's default (filled) map without a cloud, computed once for the tests that read it."""
    sc = load_scene(data_dir / "kitti2015" / "000005_10")
    return sv.depth_map(sc.left, sc.right, sc.calib, max_disparity=sc.max_disparity, cloud=False)


@pytest.fixture(scope="module")
def kitti_floor(kitti_filled: sv.DepthResult) -> tuple[Any, Any]:
    """``kitti_filled``'s floor (:func:`fit_ground_plane`, seeded: the same plane each time) and
    the :func:`laser_scan` of its filled point image over it, found once for the tests that
    only read them (1.2 s a test)."""
    from stereovision.ground import fit_ground_plane, laser_scan

    res = kitti_filled
    plane = fit_ground_plane(res.disparity, res.calibration)
    assert plane is not None
    return plane, laser_scan(res.point_image(filled=True), plane, res.calibration)


def _read(path: Path) -> dict[str, list]:
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    out: dict[str, list] = {}
    with Reader(path) as reader:
        for conn, stamp, raw in reader.messages():
            out.setdefault(conn.topic, []).append((stamp, ts.deserialize_cdr(raw, conn.msgtype)))
    return out


def test_bag_disparity_only_where_there_is_a_depth(
    kitti_filled: sv.DepthResult, tmp_path: Path
) -> None:
    """The default (filled) map: its filled pixels have no depth, and one at or below its
    uncertainty none either (d near 0). The disparity topic carried them all, some at d = 0
    (Z infinite for a reader computing f t / d)."""
    from stereovision.rosbag import BagWriter

    res = kitti_filled
    assert np.isfinite(res.disparity).all() and not np.isfinite(res.depth).all()
    with BagWriter(tmp_path / "run") as bag:
        bag.write(res, 1)
    disp = _read(tmp_path / "run")["/stereo/disparity"][0][1]
    dimg = np.frombuffer(disp.image.data.tobytes(), "<f4").reshape(disp.image.height, -1)
    valid = dimg >= disp.min_disparity
    np.testing.assert_array_equal(valid, np.isfinite(res.depth))
    assert dimg[valid].min() > 0
    np.testing.assert_allclose(disp.f * disp.t / dimg[valid], res.depth[valid], rtol=1e-5)


def test_bag_holds_the_results_values(kitti: tuple, tmp_path: Path) -> None:
    from stereovision.rosbag import BagWriter

    res, lean = kitti
    with BagWriter(tmp_path / "run") as bag:
        bag.write(res, 1_700_000_000_123_456_789)
        bag.write(lean, 1_700_000_000_223_456_789)
    assert (bag.messages, bag.frames) == (14, 2)
    topics = _read(tmp_path / "run")
    assert sorted(topics) == ["/stereo/camera_info", "/stereo/depth", "/stereo/disparity",
                              "/stereo/left/camera_info", "/stereo/left/image_rect_color",
                              "/stereo/points", "/stereo/right/camera_info"]  # fmt: skip
    # stereo_image_proc's disparity: Z = f t / d, -1 (below min_disparity) where none
    disp = topics["/stereo/disparity"][0][1]
    assert disp.f == pytest.approx(res.calibration.focal_px)
    assert disp.t == pytest.approx(res.calibration.baseline_m)
    dimg = np.frombuffer(disp.image.data.tobytes(), "<f4").reshape(disp.image.height,
                                                                   disp.image.width)  # fmt: skip
    valid = dimg >= disp.min_disparity
    np.testing.assert_array_equal(valid, np.isfinite(res.disparity))
    z = disp.f * disp.t / dimg[valid]
    np.testing.assert_allclose(z, res.depth[valid], rtol=1e-5)  # the depth image's values
    assert disp.max_disparity == res.max_disparity and disp.delta_d == 1 / 16
    stamp, depth = topics["/stereo/depth"][0]
    assert stamp == 1_700_000_000_123_456_789
    assert depth.header.stamp.sec == 1_700_000_000 and depth.header.stamp.nanosec == 123_456_789
    assert depth.header.frame_id == "stereo_left_optical" and depth.encoding == "32FC1"
    d = np.frombuffer(depth.data.tobytes(), "<f4").reshape(depth.height, depth.width)
    np.testing.assert_array_equal(d, res.depth.astype(np.float32))  # NaN where none, metres
    img = topics["/stereo/left/image_rect_color"][0][1]
    assert img.encoding == "bgr8" and img.step == 3 * img.width
    np.testing.assert_array_equal(
        np.frombuffer(img.data.tobytes(), np.uint8).reshape(img.height, img.width, 3),
        res.left_rectified,
    )
    info = topics["/stereo/left/camera_info"][0][1]
    np.testing.assert_allclose(info.k.reshape(3, 3), res.calibration.K1)
    assert info.p[3] == 0.0 and (info.width, info.height) == res.calibration.image_size
    cloud = topics["/stereo/points"][0][1]
    # PCL's PointXYZRGB: four FLOAT32 (7) fields, rgb the float holding the bits 0x00RRGGBB
    fields = [(f.name, f.offset, f.datatype, f.count) for f in cloud.fields]
    assert fields == [("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1), ("rgb", 12, 7, 1)]
    as_declared = np.frombuffer(cloud.data.tobytes(), dtype=[(n, "<f4") for n, *_ in fields])
    bits = as_declared["rgb"].view("<u4")  # what a PCL / RViz reader does with the float
    rgb = np.stack([(bits >> 16) & 255, (bits >> 8) & 255, bits & 255], axis=-1)
    np.testing.assert_array_equal(rgb, res.colors)
    xyz_rgb = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4")]
    rec = np.frombuffer(cloud.data.tobytes(), dtype=xyz_rgb)
    assert cloud.width == len(res.points) == len(rec) and cloud.point_step == 16
    np.testing.assert_array_equal(np.c_[rec["x"], rec["y"], rec["z"]], res.points)
    c = res.colors.astype(np.uint32)
    np.testing.assert_array_equal(rec["rgb"], (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2])
    # the result made without a cloud (stream's) gets its cloud from the depth map: the same
    lean_cloud = topics["/stereo/points"][1][1]
    rec2 = np.frombuffer(lean_cloud.data.tobytes(), dtype=rec.dtype)
    np.testing.assert_allclose(np.c_[rec2["x"], rec2["y"], rec2["z"]], res.points, rtol=1e-6)
    np.testing.assert_array_equal(rec2["rgb"], rec["rgb"])


def test_bag_camera_infos_of_the_depth_image_and_the_right_camera(
    kitti: tuple, tmp_path: Path
) -> None:
    """The depth image's ``camera_info`` beside it (``/stereo/camera_info``, where
    image_transport and depth_image_proc look: the bag had none), and the rectified right
    camera's, whose ``P`` carries ``-fx B``: ROS's stereo model of the two gives back the
    depth image (``Z = -Tx / (d + cx_r - cx_l)``) and this package's reading of them the rig."""
    from stereovision.calibration import Calibration, _ros_yaml
    from stereovision.rosbag import BagWriter

    res, _ = kitti
    cal = res.calibration
    with BagWriter(tmp_path / "run") as bag:
        bag.write(res, 5)
    topics = _read(tmp_path / "run")
    left = topics["/stereo/left/camera_info"][0][1]
    depth_info = topics["/stereo/camera_info"][0][1]
    right = topics["/stereo/right/camera_info"][0][1]
    for name in ("k", "d", "r", "p"):
        np.testing.assert_array_equal(getattr(depth_info, name), getattr(left, name))
    assert depth_info.header.frame_id == left.header.frame_id == "stereo_left_optical"
    assert (depth_info.width, depth_info.height) == cal.image_size
    pl, pr = left.p.reshape(3, 4), right.p.reshape(3, 4)
    np.testing.assert_allclose(pr[:, :3], cal.K2)
    assert pr[0, 3] == pytest.approx(-cal.focal_px * cal.baseline_m)
    assert pl[0, 3] == 0.0 and pr[1, 3] == pr[2, 3] == 0.0
    assert -pr[0, 3] / pr[0, 0] == pytest.approx(0.5327, abs=1e-4)  # KITTI's 0.54 m rig
    ok = np.isfinite(res.depth)
    z = -pr[0, 3] / (res.disparity[ok] + pr[0, 2] - pl[0, 2])
    np.testing.assert_allclose(z, res.depth[ok], rtol=1e-5)
    texts = [
        _ros_yaml(side, (m.width, m.height), m.p.reshape(3, 4)[:, :3], np.zeros(5), np.eye(3),
                  m.p.reshape(3, 4), "plumb_bob")
        for side, m in (("left", left), ("right", right))
    ]  # fmt: skip
    back = Calibration._from_ros_texts(texts[0], texts[1], "left", "right")
    assert back.focal_px == pytest.approx(cal.focal_px)
    assert back.baseline_m == pytest.approx(cal.baseline_m)
    assert back.doffs_px == pytest.approx(cal.doffs_px, abs=1e-9)


def test_bag_errors(kitti: tuple, tmp_path: Path, data_dir: Path) -> None:
    from stereovision.rosbag import BagWriter

    (tmp_path / "exists").mkdir()
    with pytest.raises(FileExistsError, match="bag folder already exists"):
        BagWriter(tmp_path / "exists")
    with pytest.raises(FileNotFoundError, match="parent does not exist"):
        BagWriter(tmp_path / "no" / "bag")
    sc = load_scene(data_dir / "middlebury2001" / "tsukuba")
    no_depth = sv.depth_map(sc.left, sc.right, method="gabor", max_disparity=16)
    with BagWriter(tmp_path / "b") as bag:
        with pytest.raises(ValueError, match="compute the result with a calibration"):
            bag.write(no_depth, 0)
        with pytest.raises(ValueError, match="stamp_ns"):
            bag.write(kitti[0], -5)
        # int() took True as 1 ns and time.time() (seconds) as a stamp in 1970; NaN, inf,
        # "abc" and a stamp past 2**31 s raised int()'s, OverflowError's or struct's messages
        with pytest.raises(ValueError, match=r"whole nanoseconds, got 1733000000\.5 \(seconds\?"):
            bag.write(kitti[0], 1733000000.5)
        for bad in (True, "abc", math.nan, math.inf, 2**70):
            with pytest.raises(ValueError, match="stamp_ns: expected"):
                bag.write(kitti[0], bad)
        assert bag.messages == 0  # nothing of the refused frames was written


def test_bag_scan_topic(kitti: tuple, tmp_path: Path, data_dir: Path) -> None:
    """A LaserScan given with the result is written as /stereo/scan, in the floor's frame."""
    from stereovision.ground import fit_ground_plane, laser_scan
    from stereovision.rosbag import BagWriter

    res = kitti[0]
    plane = fit_ground_plane(res.disparity, res.calibration)
    assert plane is not None
    scan = laser_scan(res.calibration.reproject(res.disparity), plane, res.calibration)
    with BagWriter(tmp_path / "run", points=False, scan_frame_id="robot_floor") as bag:
        bag.write(res, 42, scan=scan)
    msg = _read(tmp_path / "run")["/stereo/scan"][0][1]
    assert msg.header.frame_id == "robot_floor"
    assert msg.angle_min == pytest.approx(scan.angle_min, rel=1e-6)
    assert msg.angle_increment == pytest.approx(scan.angle_increment, rel=1e-6)
    np.testing.assert_array_equal(msg.ranges, scan.ranges)  # inf and NaN kept (REP 117)
    assert np.isinf(msg.ranges).any() and np.isfinite(msg.ranges).sum() > 500


def test_a_full_disk_is_named_and_committed_frames_stay(
    kitti: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The bag was one transaction until close: a full disk lost every frame, and sqlite's
    OperationalError reached the CLI as an "internal" error. Now it is an OSError naming the
    bag, and the frames committed before it (every second) stay."""
    import sqlite3

    from stereovision import rosbag

    res, _ = kitti
    monkeypatch.setattr(rosbag, "COMMIT_PERIOD_S", 0.0)  # commit after every frame
    bag = rosbag.BagWriter(tmp_path / "run")
    bag.write(res, 1)
    storage = bag._writer.storage

    def full(*_a: object) -> None:
        raise sqlite3.OperationalError("database or disk is full")

    monkeypatch.setattr(storage, "write", full)
    with pytest.raises(OSError, match=r"^bag .*run: database or disk is full$"):
        bag.write(res, 2)
    storage.conn.close()  # the process dies here; no metadata.yaml
    with sqlite3.connect(tmp_path / "run" / "run.db3") as db:
        assert db.execute("SELECT COUNT(*) FROM messages").fetchone()[0] == 7  # one frame


def test_a_bag_that_cannot_be_finished_keeps_the_error_of_its_block(
    kitti: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``with BagWriter(...)``: a block that failed, then a close that failed too (the disk
    still full at the last commit): the close's OSError replaced the block's error. The
    block's error is raised now, the close's message added to it as a note; a block that
    ended well still gets the close's error."""
    import sqlite3

    from stereovision import rosbag

    res, _ = kitti

    def full(*_a: object) -> None:
        raise sqlite3.OperationalError("database or disk is full")

    with pytest.raises(ValueError, match=r"^the block's own error") as err:
        with rosbag.BagWriter(tmp_path / "a") as bag:
            bag.write(res, 1)
            monkeypatch.setattr(bag._writer, "close", full)
            raise ValueError("the block's own error")
    assert str(err.value) == "the block's own error"
    (note,) = err.value.__notes__
    assert note.startswith(f"bag {tmp_path / 'a'} could not be finished (database or disk is full)")
    assert f"`ros2 bag reindex {tmp_path / 'a'}`" in note
    with pytest.raises(OSError, match=r"^bag .*b could not be finished \(database or disk"):
        with rosbag.BagWriter(tmp_path / "b") as bag:
            bag.write(res, 1)
            monkeypatch.setattr(bag._writer, "close", full)


def test_a_bag_where_it_cannot_go_is_said_as_such(tmp_path: Path) -> None:
    """--bag under a file said "bag folder's parent does not exist: FILE" (it does: it is a
    file), and under a folder that cannot be written (/proc, a read-only mount) rosbags' own
    "[Errno 2] No such file or directory: '/proc/bag'"; both say what is in the way now."""
    from stereovision.rosbag import BagWriter

    (tmp_path / "afile").write_text("mine")
    with pytest.raises(NotADirectoryError) as err:
        BagWriter(tmp_path / "afile" / "bag")
    assert str(err.value) == f"bag folder's parent is a file, not a folder: {tmp_path / 'afile'}"
    assert (tmp_path / "afile").read_text() == "mine"
    with pytest.raises(OSError) as err2:
        BagWriter("/proc/stereovision-bag")
    assert str(err2.value).startswith("cannot write the bag folder /proc/stereovision-bag: ")
    assert not Path("/proc/stereovision-bag").exists()


@pytest.mark.parametrize("fail_at", range(1, 8))
def test_a_frame_cut_by_a_full_disk_is_not_in_the_bag(
    kitti: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fail_at: int
) -> None:
    """A full disk while a frame was written kept that frame's messages written before it:
    the finished bag ended with a whole frame and part of the next (a depth image without its
    cloud), and metadata.yaml counted them. Now a frame is all or nothing: the bag holds the
    whole frames only, readable, with its metadata's counts those of its database; and the
    writer goes on when the disk has room again."""
    import errno
    import sqlite3

    from rosbags.highlevel import AnyReader

    from stereovision.rosbag import BagWriter

    res, _ = kitti
    bag = BagWriter(tmp_path / "run")
    bag.write(res, 1)
    storage = bag._writer.storage
    real_write = storage.write
    calls = [0]

    def full_at_k(*args: object) -> None:
        calls[0] += 1
        if calls[0] == fail_at:
            raise OSError(errno.ENOSPC, "No space left on device")
        real_write(*args)

    monkeypatch.setattr(storage, "write", full_at_k)
    with pytest.raises(OSError) as err:
        bag.write(res, 2)
    assert err.value.errno == errno.ENOSPC
    assert str(err.value) == f"bag {tmp_path / 'run'}: No space left on device"
    assert (bag.messages, bag.frames) == (7, 1)  # the first frame's
    monkeypatch.setattr(storage, "write", real_write)  # room again
    bag.write(res, 3)
    bag.close()
    assert (bag.messages, bag.frames) == (14, 2)
    with AnyReader([tmp_path / "run"]) as reader:
        stamps: dict[str, list[int]] = {}
        for conn, stamp, _raw in reader.messages():
            stamps.setdefault(conn.topic, []).append(stamp)
        meta = {t: info.msgcount for t, info in reader.topics.items()}
    assert len(stamps) == 7
    assert all(s == [1, 3] for s in stamps.values()), stamps
    assert meta == {t: 2 for t in stamps}
    with sqlite3.connect(tmp_path / "run" / "run.db3") as db:
        assert db.execute("SELECT COUNT(*) FROM messages").fetchone()[0] == 14


def test_a_database_that_fills_mid_frame_keeps_the_metadata_true(
    kitti: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """sqlite's own "database or disk is full" (here its page limit) part-way through a frame
    rolls back what it chooses; metadata.yaml counted every message handed to it, the ones
    rolled back too, so a reader was promised messages the database did not have."""
    from rosbags.highlevel import AnyReader

    from stereovision import rosbag

    res, _ = kitti
    monkeypatch.setattr(rosbag, "COMMIT_PERIOD_S", 0.0)  # the first frame committed
    bag = rosbag.BagWriter(tmp_path / "run")
    bag.write(res, 1)
    conn = bag._writer.storage.conn
    pages, size = (conn.execute(f"PRAGMA {p}").fetchone()[0] for p in ("page_count", "page_size"))
    conn.execute(f"PRAGMA max_page_count = {pages + 2_500_000 // size}")  # 1 or 2 messages
    with pytest.raises(OSError, match=r"^bag .*run: database or disk is full$"):
        bag.write(res, 2)
    bag.close()
    assert bag.messages == 7
    with AnyReader([tmp_path / "run"]) as reader:
        got = [(conn.topic, stamp) for conn, stamp, _ in reader.messages()]
        meta = {t: info.msgcount for t, info in reader.topics.items()}
        assert reader.message_count == 7
    assert len(got) == 7 and {s for _, s in got} == {1}
    assert meta == {t: 1 for t, _ in got}


@pytest.mark.parametrize("points", [True, False])
def test_the_frames_a_full_disk_rolled_back_are_counted_out(
    kitti: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, points: bool
) -> None:
    """A full disk lets sqlite undo its whole open transaction: every frame since the last
    commit. The writer counted messages only, so no one could say how many frames the bag
    still held; :attr:`BagWriter.frames` is the whole frames in its database (its depth
    images: a frame is 6 messages without the cloud, 7 with it)."""
    import sqlite3

    from stereovision import rosbag

    res, _ = kitti
    monkeypatch.setattr(rosbag, "COMMIT_PERIOD_S", 0.0)
    per_frame = 7 if points else 6
    bag = rosbag.BagWriter(tmp_path / "run", points=points)
    bag.write(res, 1)  # committed
    monkeypatch.setattr(rosbag, "COMMIT_PERIOD_S", 3600.0)
    bag.write(res, 2)
    bag.write(res, 3)  # both in the open transaction
    assert (bag.frames, bag.messages) == (3, 3 * per_frame)
    conn = bag._writer.storage.conn
    conn.execute(f"PRAGMA max_page_count = {conn.execute('PRAGMA page_count').fetchone()[0]}")
    with pytest.raises(OSError, match=r"^bag .*run: database or disk is full$"):
        bag.write(res, 4)
    # sqlite undid frames 2 and 3 with frame 4: the committed frame 1 is the bag's one frame
    stamps = conn.execute("SELECT DISTINCT timestamp FROM messages").fetchall()
    assert stamps == [(1,)]
    assert (bag.frames, bag.messages) == (1, per_frame)
    bag.close()
    with sqlite3.connect(tmp_path / "run" / "run.db3") as db:
        assert db.execute("SELECT COUNT(*) FROM messages").fetchone()[0] == per_frame


def _frame_cut_while_undone(
    res: object, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, commit_period_s: float
) -> Any:
    """A bag whose frame 1 is committed and whose frame 2 a second Ctrl-C cut (its third
    message) while a third one cut the undoing (``ROLLBACK TO frame``)."""
    import sqlite3

    from stereovision import rosbag

    class Interrupted(sqlite3.Connection):
        cut = True

        def execute(self, sql: str, *args: object) -> sqlite3.Cursor:  # type: ignore[override]
            if sql == "ROLLBACK TO frame" and self.cut:
                self.cut = False
                raise KeyboardInterrupt  # the third Ctrl-C
            return super().execute(sql, *args)

    monkeypatch.setattr(rosbag, "COMMIT_PERIOD_S", 0.0)
    bag = rosbag.BagWriter(tmp_path / "run")
    bag.write(res, 1)  # committed
    monkeypatch.setattr(rosbag, "COMMIT_PERIOD_S", commit_period_s)
    storage = bag._writer.storage
    storage.conn.close()
    storage.conn = sqlite3.connect(storage.path, factory=Interrupted)
    storage.cursor = storage.conn.cursor()
    real_write = storage.write
    calls = [0]

    def second_ctrl_c(*args: object) -> None:
        calls[0] += 1
        if calls[0] == 3:
            raise KeyboardInterrupt
        real_write(*args)

    monkeypatch.setattr(storage, "write", second_ctrl_c)
    with pytest.raises(KeyboardInterrupt):
        bag.write(res, 2)
    return bag


def test_an_interrupt_while_a_cut_frame_is_undone_leaves_no_part_of_it(
    kitti: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A second Ctrl-C cuts a frame (its messages are undone) and a third one, no longer held,
    cut the undoing: the frame's savepoint stayed open, the bag's close committed the part of
    the frame written (a depth image without its cloud) and metadata.yaml counted it. Now the
    writer undoes an unfinished frame before it writes the next one or closes."""
    import sqlite3

    from rosbags.highlevel import AnyReader

    res, _ = kitti
    bag = _frame_cut_while_undone(res, tmp_path, monkeypatch, 0.0)
    bag.close()  # as `with BagWriter(...)` does on the way out
    assert (bag.messages, bag.frames) == (7, 1)
    with AnyReader([tmp_path / "run"]) as reader:
        stamps = sorted({stamp for _, stamp, _ in reader.messages()})
        meta = {t: info.msgcount for t, info in reader.topics.items()}
    assert stamps == [1]
    assert meta == {t: 1 for t in meta} and len(meta) == 7
    with sqlite3.connect(tmp_path / "run" / "run.db3") as db:
        assert db.execute("SELECT COUNT(*) FROM messages").fetchone()[0] == 7


def test_an_interrupt_as_a_frame_is_released_keeps_the_frames(
    kitti: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A second Ctrl-C landing just as a frame's savepoint was released (the frame whole) was
    taken for a cut frame: undoing it found no savepoint and rolled the whole transaction back,
    the frames since the last commit with it (here frames 2 and 3 of 3). Now a frame released
    stays, and the counts are read back from the database."""
    import sqlite3

    from rosbags.highlevel import AnyReader

    from stereovision import rosbag

    class Interrupted(sqlite3.Connection):
        releases = 0

        def execute(self, sql: str, *args: object) -> sqlite3.Cursor:  # type: ignore[override]
            cur = super().execute(sql, *args)
            if sql == "RELEASE frame":
                self.releases += 1
                if self.releases == 2:
                    raise KeyboardInterrupt  # the frame is whole, its count not yet taken
            return cur

    res, _ = kitti
    monkeypatch.setattr(rosbag, "COMMIT_PERIOD_S", 0.0)
    bag = rosbag.BagWriter(tmp_path / "run")
    bag.write(res, 1)  # committed
    monkeypatch.setattr(rosbag, "COMMIT_PERIOD_S", 3600.0)
    storage = bag._writer.storage
    storage.conn.close()
    storage.conn = sqlite3.connect(storage.path, factory=Interrupted)
    storage.cursor = storage.conn.cursor()
    bag.write(res, 2)
    with pytest.raises(KeyboardInterrupt):
        bag.write(res, 3)
    bag.close()
    assert (bag.messages, bag.frames) == (21, 3)
    with AnyReader([tmp_path / "run"]) as reader:
        stamps = sorted({stamp for _, stamp, _ in reader.messages()})
        meta = {t: info.msgcount for t, info in reader.topics.items()}
    assert stamps == [1, 2, 3]
    assert meta == {t: 3 for t in meta} and len(meta) == 7


def test_bag_topics_flags_and_fields_a_reader_relies_on(kitti: tuple, tmp_path: Path) -> None:
    """Mutation audit: the prefix given is normalised (one leading slash, none trailing; an
    empty one puts the topics at the root), ``points=False`` writes no cloud, a mono left image
    is ``mono8``, the images are little-endian, the camera_info's model ``plumb_bob``, the
    cloud's ``row_step`` its whole row and the disparity's ``valid_window`` the box of the
    pixels with a depth; a stamp of 2**31 s (past ``sec``'s int32) is refused, one ns less is
    not."""
    import dataclasses

    import cv2

    from stereovision.rosbag import BagWriter

    res, _ = kitti
    grey = dataclasses.replace(res, left_rectified=cv2.cvtColor(res.left_rectified,
                                                                cv2.COLOR_BGR2GRAY))  # fmt: skip
    last = 2**31 * 1_000_000_000
    with BagWriter(tmp_path / "a", prefix="robot/stereo/") as bag:
        with pytest.raises(ValueError, match="2\\*\\*31 s"):
            bag.write(res, last)
        bag.write(res, last - 1)
    a = _read(tmp_path / "a")
    assert "/robot/stereo/depth" in a and len(a) == 7
    assert a["/robot/stereo/depth"][0][0] == last - 1
    depth = a["/robot/stereo/depth"][0][1]
    assert (
        depth.is_bigendian == 0 and a["/robot/stereo/left/image_rect_color"][0][1].is_bigendian == 0
    )
    assert a["/robot/stereo/left/camera_info"][0][1].distortion_model == "plumb_bob"
    cloud = a["/robot/stereo/points"][0][1]
    assert cloud.row_step == 16 * cloud.width == len(cloud.data)
    disp = a["/robot/stereo/disparity"][0][1]
    rows, cols = np.nonzero(np.isfinite(res.depth))
    win = disp.valid_window
    assert (win.x_offset, win.y_offset) == (cols.min(), rows.min())
    assert (win.width, win.height) == (cols.max() - cols.min() + 1, rows.max() - rows.min() + 1)
    with BagWriter(tmp_path / "b", prefix="/", points=False) as bag:
        bag.write(grey, 1)
    b = _read(tmp_path / "b")
    assert sorted(b) == ["/camera_info", "/depth", "/disparity", "/left/camera_info",
                         "/left/image_rect_color", "/right/camera_info"]  # fmt: skip
    img = b["/left/image_rect_color"][0][1]
    assert img.encoding == "mono8" and img.step == img.width
    np.testing.assert_array_equal(img.data.reshape(img.height, img.width), grey.left_rectified)


def test_a_closed_bag_refuses_frames(kitti: tuple, tmp_path: Path) -> None:
    """Mutation audit: a frame written after close is a ValueError naming the bag (not
    rosbags' own error, nor written), and closing again does nothing."""
    from stereovision.rosbag import BagWriter

    bag = BagWriter(tmp_path / "run")
    bag.write(kitti[0], 1)
    bag.close()
    bag.close()
    with pytest.raises(ValueError, match=r"^bag .*run is closed$"):
        bag.write(kitti[0], 2)
    assert (bag.messages, bag.frames) == (7, 1)
    assert {s for msgs in _read(tmp_path / "run").values() for s, _ in msgs} == {1}


def test_a_first_frame_cut_by_a_full_disk_leaves_a_readable_bag(
    kitti: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Mutation audit: a full disk in the very first frame rolls back the topics that frame
    made; the next frame makes them again and metadata.yaml's time span is its own (the
    rolled back frames' stamps are not the bag's start nor end)."""
    import errno

    from rosbags.highlevel import AnyReader

    from stereovision.rosbag import BagWriter

    res, _ = kitti
    bag = BagWriter(tmp_path / "run")
    storage = bag._writer.storage
    real_write = storage.write
    calls = [0]

    def full_at_3_and_20(*args: object) -> None:
        calls[0] += 1
        if calls[0] in (3, 20):  # in the first frame and in the fourth
            raise OSError(errno.ENOSPC, "No space left on device")
        real_write(*args)

    monkeypatch.setattr(storage, "write", full_at_3_and_20)
    with pytest.raises(OSError, match="No space left"):
        bag.write(res, 5_000)
    assert (bag.messages, bag.frames) == (0, 0)
    bag.write(res, 7_000)
    bag.write(res, 9_000)
    with pytest.raises(OSError, match="No space left"):
        bag.write(res, 11_000)
    bag.close()
    assert (bag.messages, bag.frames) == (14, 2)
    with AnyReader([tmp_path / "run"]) as reader:
        stamps = sorted({stamp for _, stamp, _ in reader.messages()})
        meta = {t: info.msgcount for t, info in reader.topics.items()}
        span = (reader.start_time, reader.end_time)
    assert stamps == [7_000, 9_000]
    assert meta == {t: 2 for t in meta} and len(meta) == 7
    assert span == (7_000, 9_001)


def test_the_frame_after_an_interrupted_undo_is_kept(
    kitti: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Mutation audit: a frame cut by a Ctrl-C whose undoing was cut too is undone before the
    next frame is written; written inside its open savepoint, that next frame was rolled back
    with it at the close."""
    from rosbags.highlevel import AnyReader

    res, _ = kitti
    bag = _frame_cut_while_undone(res, tmp_path, monkeypatch, 3600.0)
    bag.write(res, 3)
    bag.close()
    assert (bag.messages, bag.frames) == (14, 2)
    with AnyReader([tmp_path / "run"]) as reader:
        stamps = sorted({stamp for _, stamp, _ in reader.messages()})
    assert stamps == [1, 3]


def test_bag_of_a_rig_with_doffs_and_its_own_right_camera(data_dir: Path, tmp_path: Path) -> None:
    """KITTI's rig with the right principal point 20 px further right (``doffs`` 20, ``K2`` !=
    ``K1``; every scene in the data has 0 and ``K1 == K2``): the disparity topic carries ``d +
    doffs`` (so ``f t / d`` is the depth image), its range ``doffs + min`` to ``doffs + max``
    (measured 20 and 132 for 0-112), and the right ``camera_info`` carries ``K2``."""
    import dataclasses

    from stereovision.rosbag import BagWriter

    sc = load_scene(data_dir / "kitti2015" / "000005_10")
    k2 = sc.calib.K2.copy()
    k2[0, 2] += 20.0
    cal = dataclasses.replace(sc.calib, K2=k2, doffs=20.0)
    res = sv.depth_map(sc.left, sc.right, cal, max_disparity=sc.max_disparity, cloud=False)
    assert (res.min_disparity, res.max_disparity) == (0, 112)
    with BagWriter(tmp_path / "run") as bag:
        bag.write(res, 1)
    topics = _read(tmp_path / "run")
    disp = topics["/stereo/disparity"][0][1]
    dimg = np.frombuffer(disp.image.data.tobytes(), "<f4").reshape(disp.image.height, -1)
    ok = np.isfinite(res.depth)
    assert ok.mean() > 0.5
    np.testing.assert_array_equal(dimg >= disp.min_disparity, ok)
    np.testing.assert_array_equal(dimg[ok], res.disparity[ok] + np.float32(20.0))
    assert (dimg[~ok] == 19.0).all()  # below min_disparity: none
    assert (disp.min_disparity, disp.max_disparity) == (20.0, 132.0)
    np.testing.assert_allclose(disp.f * disp.t / dimg[ok], res.depth[ok], rtol=1e-5)
    left = topics["/stereo/left/camera_info"][0][1]
    right = topics["/stereo/right/camera_info"][0][1]
    np.testing.assert_array_equal(right.k.reshape(3, 3), k2)
    np.testing.assert_array_equal(right.p.reshape(3, 4)[:, :3], k2)
    np.testing.assert_array_equal(left.k.reshape(3, 3), sc.calib.K1)
    assert right.p[2] - left.p[2] == pytest.approx(20.0)


def test_bag_fields_of_a_filled_map_and_its_floor_scan(
    kitti_filled: sv.DepthResult, kitti_floor: tuple[Any, Any], tmp_path: Path
) -> None:
    """Second mutation audit, on the default (filled) map written with a ``ground`` as
    ``stream --bag`` does: the scan is stamped as the frame (to the ns) and carries the
    :func:`laser_scan` of the filled point image (its angles and range limits too); the cloud
    holds the pixels with a depth only, dense and little-endian; the camera_info is the
    rectified one (5 zero ``d``, identity ``r``); the disparity image is ``32FC1``; a result
    without its calibration is refused (not rosbags' or numpy's error part-way)."""
    import dataclasses

    from stereovision.ground import laser_scan
    from stereovision.rosbag import BagWriter

    res = kitti_filled
    plane, want = kitti_floor
    lean = laser_scan(res.point_image(filled=False), plane, res.calibration)
    assert not np.array_equal(want.ranges, lean.ranges)  # the filled pixels count
    stamp = 1_700_000_000_123_456_789
    with BagWriter(tmp_path / "run") as bag:
        with pytest.raises(ValueError, match="compute the result with a calibration"):
            bag.write(dataclasses.replace(res, calibration=None), stamp)
        bag.write(res, stamp, ground=plane)
        # a scan given: its own range limits (laser_scan's range_min is 0 by default)
        bag.write(res, stamp + 1, scan=dataclasses.replace(want, range_min=0.25, range_max=7.5))
    assert (bag.messages, bag.frames) == (17, 2)  # the first with its /tf
    topics = _read(tmp_path / "run")
    scan_stamp, scan = topics["/stereo/scan"][0]
    assert scan_stamp == stamp
    assert (scan.header.stamp.sec, scan.header.stamp.nanosec) == (1_700_000_000, 123_456_789)
    assert scan.header.frame_id == "base_footprint"
    for name in ("angle_min", "angle_max", "angle_increment", "range_min", "range_max"):
        assert getattr(scan, name) == pytest.approx(getattr(want, name), rel=1e-6), name
    assert scan.angle_max > scan.angle_min
    given = topics["/stereo/scan"][1][1]
    assert (given.range_min, given.range_max) == (0.25, 7.5)
    np.testing.assert_array_equal(scan.ranges, want.ranges)
    cloud = topics["/stereo/points"][0][1]
    assert cloud.width == np.isfinite(res.depth).sum() and cloud.height == 1
    assert cloud.is_dense and not cloud.is_bigendian
    xyz = np.frombuffer(cloud.data.tobytes(), "<f4").reshape(-1, 4)[:, :3]
    np.testing.assert_array_equal(xyz, res.point_image()[np.isfinite(res.depth)])
    for topic in ("left/camera_info", "right/camera_info", "camera_info"):
        info = topics[f"/stereo/{topic}"][0][1]
        np.testing.assert_array_equal(info.d, np.zeros(5))
        np.testing.assert_array_equal(info.r, np.eye(3).ravel())
    disp = topics["/stereo/disparity"][0][1].image
    assert disp.encoding == "32FC1" and disp.step == 4 * disp.width and not disp.is_bigendian


def test_every_header_carries_the_frames_stamp_and_the_frame_id_given(
    kitti: tuple, tmp_path: Path
) -> None:
    """Mutation audit: ``frame_id`` given is every header's (the default's was not checked
    against another), each message's header (the disparity's and its image's, the right
    camera_info's) carries the frame's stamp to the ns (tf and message_filters match on it),
    and a path that is a file is refused as existing (it was taken for a new folder)."""
    from stereovision.rosbag import BagWriter

    res, _ = kitti
    stamp = 1_700_000_005_000_000_007
    with BagWriter(tmp_path / "run", frame_id="cam_left_optical") as bag:
        bag.write(res, stamp)
    headers = []
    for topic, msgs in _read(tmp_path / "run").items():
        ((recorded, msg),) = msgs
        assert recorded == stamp, topic
        headers.append((topic, msg.header))
        if topic.endswith("disparity"):
            headers.append((topic + ".image", msg.image.header))
    assert len(headers) == 8
    for topic, header in headers:
        assert header.frame_id == "cam_left_optical", topic
        assert (header.stamp.sec, header.stamp.nanosec) == (1_700_000_005, 7), topic
    (tmp_path / "a_file").write_text("x")
    with pytest.raises(FileExistsError, match="bag folder already exists"):
        BagWriter(tmp_path / "a_file")
    assert (tmp_path / "a_file").read_text() == "x"


def test_a_stamp_of_zero_is_written(kitti: tuple, tmp_path: Path) -> None:
    """Fourth mutation audit: the stamps accepted start at 0 ns (a recording stamped by frame
    index times period starts there), as documented; only the upper end was checked."""
    from stereovision.rosbag import BagWriter

    with BagWriter(tmp_path / "run", points=False) as bag:
        bag.write(kitti[0], 0)
    ((recorded, depth),) = _read(tmp_path / "run")["/stereo/depth"]
    assert recorded == 0 and (depth.header.stamp.sec, depth.header.stamp.nanosec) == (0, 0)


def test_the_disparity_focal_length_is_fx_for_non_square_pixels(
    kitti: tuple, tmp_path: Path
) -> None:
    """Mutation audit: ``DisparityImage.f`` is the rectified ``fx`` (``Z = fx B / d``, as
    ``stereo_image_proc`` fills it), and the camera_infos' ``K`` keep ``fy``: a rig whose
    pixels are not square (fy 10 % above fx) tells the two apart (every rig of the tests had
    fx = fy, so ``f = fy`` survived)."""
    import dataclasses

    from stereovision.rosbag import BagWriter

    res, _ = kitti
    cal = res.calibration
    assert cal.rectified
    k1, k2 = cal.K1.copy(), cal.K2.copy()
    k1[1, 1] *= 1.1
    k2[1, 1] *= 1.1
    tall = dataclasses.replace(res, calibration=dataclasses.replace(cal, K1=k1, K2=k2))
    with BagWriter(tmp_path / "run", points=False) as bag:
        bag.write(tall, 1)
    topics = _read(tmp_path / "run")
    assert topics["/stereo/disparity"][0][1].f == pytest.approx(cal.K1[0, 0], rel=1e-7)  # f32
    info = topics["/stereo/left/camera_info"][0][1]
    np.testing.assert_allclose(info.k.reshape(3, 3), k1, rtol=1e-12)


def test_a_bag_with_a_floor_carries_the_camera_to_floor_transform(
    kitti_filled: sv.DepthResult, kitti_floor: tuple[Any, Any], tmp_path: Path
) -> None:
    """REP 105: the scan is in the floor frame (``base_footprint``), the images and cloud in the
    camera's optical frame; without a transform between the two (the bag had none), RViz and a
    Nav2 costmap cannot place the scan beside the cloud. With a ``ground``, each frame carries
    ``/tf``: the optical frame under the floor frame, stamped as the frame, whose rotation and
    translation take a camera point to REP 103's floor axes (x forward, y left, z up: a point
    on the optical axis is ahead, the cloud's heights are the plane's) and put each scan hit on
    an obstacle point at its beam's angle and range. A scan given without a floor has none."""
    from scipy.spatial.transform import Rotation

    from stereovision.rosbag import BagWriter

    res = kitti_filled
    plane, scan = kitti_floor
    stamp = 1_700_000_000_123_456_789
    with BagWriter(tmp_path / "run", points=False) as bag:
        bag.write(res, stamp, ground=plane)
        bag.write(res, stamp + 1, scan=scan)
    topics = _read(tmp_path / "run")
    ((recorded, tf),) = topics["/tf"]  # absolute (tf's topic), once: the frame with a floor
    assert recorded == stamp
    (tr,) = tf.transforms
    assert (tr.header.frame_id, tr.child_frame_id) == ("base_footprint", "stereo_left_optical")
    assert (tr.header.stamp.sec, tr.header.stamp.nanosec) == (1_700_000_000, 123_456_789)
    q = tr.transform.rotation
    rot = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix()
    v = tr.transform.translation
    shift = np.array([v.x, v.y, v.z])
    np.testing.assert_allclose(shift, [0.0, 0.0, plane.height], atol=1e-12)
    ahead = rot @ [0.0, 0.0, 1.0] + shift  # 1 m along the optical axis: forward, not sideways
    assert ahead[0] > 0.9 and abs(ahead[1]) < 0.1
    assert (rot @ [-1.0, 0.0, 0.0])[1] > 0.9  # the camera's left (-x) is the floor's +y
    pts = res.point_image(filled=True)
    ok = np.all(np.isfinite(pts), axis=-1)
    floor_pts = pts[ok] @ rot.T + shift
    np.testing.assert_allclose(floor_pts[:, 2], plane.height_of(pts[ok]), atol=1e-9)
    stood = floor_pts[(floor_pts[:, 2] > 0.15) & (floor_pts[:, 2] < 2.0)]
    dist = np.hypot(stood[:, 0], stood[:, 1])
    ang = np.arctan2(stood[:, 1], stood[:, 0])
    hits = np.nonzero(np.isfinite(scan.ranges))[0]
    assert hits.size > 10
    for i in hits[:: max(1, hits.size // 40)]:
        near = np.abs(ang - scan.angles[i]) <= scan.angle_increment / 2 + 1e-9
        assert np.min(np.abs(dist[near] - scan.ranges[i])) < 1e-4, i
    # a robot whose own tree places the camera: no second parent for the optical frame
    with BagWriter(tmp_path / "own_tree", points=False, tf=False) as bag:
        bag.write(res, stamp, ground=plane)
    assert "/tf" not in _read(tmp_path / "own_tree")


def test_keywords_that_make_a_bag_ros_cannot_use_are_refused(kitti: tuple, tmp_path: Path) -> None:
    """A prefix that gives no ROS 2 topic name (``my-rig``: rclcpp refuses it, so ``ros2 bag
    play`` could not publish the bag), a frame name tf2 refuses (ROS 1's leading ``/``, empty,
    None written as "None"), the optical frame named as the floor frame (tf2 ignores a frame's
    transform to itself), and flags or a result of another type were all taken, as were
    BagCamera's ``realtime="no"`` (played in real time) and ``max_skew_ms=True`` (1 ms). Each
    is refused by name now, before any folder is made."""
    from stereovision.rosbag import BagCamera, BagWriter

    run = tmp_path / "run"
    for kw, error, words in (
        ({"prefix": "my-rig"}, ValueError, "prefix: 'my-rig' gives no ROS 2 topic name"),
        ({"prefix": "stereo cam/x"}, ValueError, "'stereo cam': each part is letters"),
        ({"prefix": "/robot/2cams"}, ValueError, "'2cams': each part"),
        ({"prefix": "a//b"}, ValueError, "'': each part"),
        ({"prefix": None}, TypeError, "prefix: expected a topic namespace"),
        ({"frame_id": "/stereo_left_optical"}, ValueError, "frame_id: expected a tf frame name"),
        ({"frame_id": None}, ValueError, "got None"),
        ({"scan_frame_id": ""}, ValueError, "scan_frame_id: expected a tf frame name"),
        ({"scan_frame_id": "stereo_left_optical"}, ValueError, "are one frame"),
        ({"points": "no"}, TypeError, "points: expected True or False, got 'no'"),
        ({"tf": 0}, TypeError, "tf: expected True or False"),
    ):
        with pytest.raises(error, match=re.escape(words)):
            BagWriter(run, **kw)
        assert not run.exists(), kw
    with BagWriter(run, prefix="/robot_1/stereo/", frame_id="cam_1", points=False) as bag:
        for bad in (kitti[0].depth, None):
            with pytest.raises(TypeError, match="result: expected a DepthResult, got"):
                bag.write(bad, 1)
        bag.write(kitti[0], 1)
    assert "/robot_1/stereo/depth" in _read(run)
    # rmw takes topic names of at most 247 characters: a prefix of 225 gives that many at most,
    # one of 226 was taken and made a bag ros2 bag play cannot publish
    long = tmp_path / "long"
    with pytest.raises(ValueError, match="prefix: 226 characters make topic names longer than"):
        BagWriter(long, prefix="/" + "a" * 225)
    assert not long.exists()
    with BagWriter(long, prefix="/" + "a" * 224) as bag:
        bag.write(kitti[0], 1)
    assert max(len(topic) for topic in _read(long)) == 247
    with pytest.raises(TypeError, match="realtime: expected True or False, got 'no'"):
        BagCamera(run, realtime="no")
    for skew in (True, "5"):
        with pytest.raises(ValueError, match="max_skew_ms: expected a number >= 0"):
            BagCamera(run, max_skew_ms=skew)
    # a Fraction or Decimal is its number (it was "expected a number >= 0, got Fraction(5,
    # 1)"); an int beyond a float is too large, not math.isfinite's OverflowError
    from decimal import Decimal
    from fractions import Fraction

    for skew in (Fraction(5), Decimal("5")):  # taken: the bag's own words come next
        with pytest.raises(ValueError, match="no left/right pair among the bag's image topics"):
            BagCamera(run, max_skew_ms=skew)
    with pytest.raises(
        ValueError, match=r"max_skew_ms: expected at most \S+, got an integer of 401"
    ):
        BagCamera(run, max_skew_ms=10**400)
    with pytest.raises(ValueError, match="max_skew_ms: expected a number >= 0, got a negative"):
        BagCamera(run, max_skew_ms=-(10**400))
    with pytest.raises(
        ValueError, match=r"max_skew_ms: expected a number >= 0, got Decimal\('NaN'\)"
    ):
        BagCamera(run, max_skew_ms=Decimal("NaN"))
