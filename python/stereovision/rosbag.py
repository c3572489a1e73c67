"""ROS bags without ROS: depth results written as ROS 2 bags, recorded rigs read from bags.

:class:`BagWriter` writes, for every result, the topics ``stereo_image_proc`` and
``depth_image_proc`` publish (REP 118 for depth images), stamped with the frame's time and in the
left rectified camera's optical frame (X right, Y down, Z forward: this package's frame):

================================  ================================  ===============================
topic (``prefix`` = ``/stereo``)  type                              content
================================  ================================  ===============================
``left/image_rect_color``         ``sensor_msgs/Image``             the rectified left image,
                                                                    ``bgr8``
``left/camera_info``              ``sensor_msgs/CameraInfo``        the rectified left camera
                                                                    (``P = [K | 0]``)
``right/camera_info``             ``sensor_msgs/CameraInfo``        the rectified right camera:
                                                                    ``P = [K | (-fx B, 0, 0)]``,
                                                                    left frame (no right image)
``depth``                         ``sensor_msgs/Image``             ``32FC1`` metres, NaN where
                                                                    none
``camera_info``                   ``sensor_msgs/CameraInfo``        the depth image's camera
                                                                    (the left one), where
                                                                    ``image_transport`` and
                                                                    ``depth_image_proc`` look
``disparity``                     ``stereo_msgs/DisparityImage``    as ``stereo_image_proc``:
                                                                    ``Z = f t / d``, below
                                                                    ``min_disparity`` where none
``points``                        ``sensor_msgs/PointCloud2``       ``x y z`` (float32), ``rgb``
                                                                    (PCL's packed ``0x00RRGGBB``
                                                                    in a float32)
``scan`` (when given)             ``sensor_msgs/LaserScan``         the obstacles on the floor,
                                                                    in ``scan_frame_id``
``/tf`` (with a ``ground``)       ``tf2_msgs/TFMessage``            the optical frame under
                                                                    ``scan_frame_id`` (REP 105)
================================  ================================  ===============================

The bag is written with the pure-Python ``rosbags`` library (the ``ros`` extra:
``pip install 'stereovision-rs[ros]'``), as a ROS 2 bag (sqlite3, CDR) that ``ros2 bag play``
reads.

:class:`BagCamera` goes the other way: it reads a recorded rig -- a ROS 1 bag (or a folder of
them, split), or a ROS 2 bag (sqlite3 or MCAP) -- as synchronised pairs, with the same interface
as :class:`~stereovision.capture.StereoCamera`, so ``stream``, ``capture``, ``calibrate`` and
``gui`` run on a recording as on live cameras (``--from-bag``):

- **Topics.** The left and right image topics (``sensor_msgs/Image`` or ``CompressedImage``) are
  given, or found: two image topics whose names differ in one part, ``left``/``right`` or a
  number (``/cam0/image_raw`` and ``/cam1/image_raw``); raw ones are preferred when a bag also
  holds rectified ones. Anything else is a clear error that lists the bag's image topics.
- **Pairs** are matched on the messages' header stamps (the time of exposure, not of
  recording), each left frame with the nearest right frame within ``max_skew_ms`` (default:
  half the faster topic's frame period, so no frame can be used twice); a frame without a
  partner is skipped and counted (:attr:`BagCamera.dropped`).
- **Images** of every ROS encoding a camera driver publishes (``mono8/16``, ``bgr8``, ``rgb8``,
  ``bgra8``, ``rgba8`` and their 16-bit forms, the four Bayer patterns, ``yuv422``/``uyvy`` and
  ``yuyv``; row padding and big-endian data) and compressed ones (JPEG, PNG; a Bayer mosaic,
  as image_transport compresses it, demosaiced) come out as BGR
  ``uint8``, like a camera's. 16-bit pairs are brought to 8 bits by one power-of-two shift for
  both images, the smallest that keeps their brightest pixel (a 12-bit sensor in a 16-bit
  container is shifted by 4, not left nearly black), and never less than a pair read before
  needed: a frame's grey levels do not halve for one glint.
- **Calibration.** When the bag holds each camera's ``camera_info`` (beside its image topic),
  :meth:`BagCamera.calibration` makes the rig's :class:`~stereovision.calibration.Calibration`
  from them, as :meth:`~stereovision.calibration.Calibration.from_ros` does from the YAML files;
  for rectified topics (``image_rect...``), the rectified rig of the two ``P`` matrices.
"""

from __future__ import annotations

import difflib
import itertools
import math
import os
import re
import sqlite3
import statistics
import time
import warnings
from collections import deque
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from stereovision._interrupt import HeldInterrupts
from stereovision._validate import (
    _plain_real,
    as_path,
    number_shown,
    real_number,
    renamed_keyword,
    source_warning,
    too_large_for_float,
)
from stereovision.capture import PairSource, SourceError, StereoFrame, _pairs, resize_frame

__all__ = [
    "DEFAULT_FRAME_ID",
    "DEFAULT_PREFIX",
    "ENCODINGS",
    "BagCamera",
    "BagWriter",
    "decode_image",
    "find_stereo_topics",
    "is_bag",
    "to_8bit",
]

#: The frame the messages are stamped with (the left rectified camera's optical frame).
DEFAULT_FRAME_ID = "stereo_left_optical"
#: Topic namespace.
DEFAULT_PREFIX = "/stereo"
#: Seconds between commits of the bag's database: a process killed (SIGKILL, power) keeps the
#: frames committed before in its ``.db3``, which ``ros2 bag reindex`` gives a metadata.yaml.
COMMIT_PERIOD_S = 1.0


def _rosbags() -> tuple[Any, Any]:
    try:
        from rosbags.rosbag2 import Writer
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise ImportError(
            "writing ROS 2 bags needs rosbags: pip install 'stereovision-rs[ros]'"
        ) from None
    return Writer, get_typestore(Stores.ROS2_HUMBLE)


def _stamp(stamp_ns: Any) -> int:
    """``stamp_ns`` as whole nanoseconds in ROS 2's range, or a ValueError naming it.

    ``int()`` alone took ``True`` as 1 ns and ``time.time()`` (seconds, with a fraction) as a
    stamp in January 1970, and gave ``int()``'s or OverflowError's message for ``"abc"``, NaN
    or infinity, and ``struct.error`` for a stamp past 2038 (``sec`` is an int32).
    """
    if not real_number(stamp_ns):
        raise ValueError(f"stamp_ns: expected a time in nanoseconds, got {stamp_ns!r}")
    value = float(stamp_ns)
    if not math.isfinite(value) or value != math.floor(value):
        raise ValueError(
            f"stamp_ns: expected whole nanoseconds, got {stamp_ns!r}"
            + (" (seconds? multiply by 1e9)" if math.isfinite(value) and value < 1e12 else "")
        )
    stamp = int(stamp_ns)
    if not 0 <= stamp < 2**31 * 1_000_000_000:
        raise ValueError(
            f"stamp_ns: expected a time in nanoseconds from 0 to 2**31 s (ROS 2's int32 "
            f"seconds), got {stamp_ns!r}"
        )
    return stamp


#: A part of a ROS 2 topic name (rcl's rule): letters, digits and underscores, no digit first.
_TOPIC_PART = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
#: The longest topic name ROS 2 takes (rmw's RMW_TOPIC_MAX_NAME_LENGTH: 255 less 8 for DDS's
#: prefixes); :class:`BagWriter`'s longest topic under its prefix.
_MAX_TOPIC_NAME = 247
_LONGEST_TOPIC = "left/image_rect_color"


def _flag(value: object, name: str) -> bool:
    """``value`` if it is True or False, else a TypeError naming it: ``bool("no")`` is True."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {value!r}")
    return bool(value)


def _frame_name(value: object, name: str) -> str:
    """``value`` as a tf frame name, or a ValueError naming it: tf2 refuses an empty name and
    one with a leading ``/`` (ROS 1's habit), so RViz could place none of the bag's messages;
    ``str(None)`` made a frame named "None"."""
    if not isinstance(value, str) or not value or value.startswith("/"):
        raise ValueError(
            f"{name}: expected a tf frame name (not empty, no leading '/', which tf2 refuses), "
            f"got {value!r}"
        )
    return value


def _bag_path(path: str | os.PathLike[str]) -> Path:
    """``path`` as a Path (:func:`stereovision._validate.as_path`), an empty name refused: Path('')
    is the current folder, which was taken for the bag (read if it was one, else "'.' is not a
    readable ROS 1 or ROS 2 bag")."""
    p = as_path(path)
    if not os.fspath(path):
        raise ValueError("path: expected a bag file or folder name, got ''")
    return p


def _topic_prefix(prefix: object) -> str:
    """``prefix`` as the bag's topic namespace (``"/stereo"``, ``""`` for none), or an error
    naming it: a part ROS 2 does not take in a topic name (``my-rig``, ``stereo cam``,
    ``2cams``) made a bag ``ros2 bag play`` cannot publish (rclcpp refuses the name)."""
    if not isinstance(prefix, str):
        raise TypeError(f"prefix: expected a topic namespace such as '/stereo', got {prefix!r}")
    parts = prefix.strip("/").split("/") if prefix.strip("/") else []
    bad = [part for part in parts if not _TOPIC_PART.fullmatch(part)]
    if bad:
        raise ValueError(
            f"prefix: {prefix!r} gives no ROS 2 topic name ({bad[0]!r}: each part is letters, "
            "digits and underscores, not starting with a digit)"
        )
    out = "/" + "/".join(parts) if parts else ""
    if len(f"{out}/{_LONGEST_TOPIC}") > _MAX_TOPIC_NAME:
        # rmw refuses the name as too long: a bag ros2 bag play cannot publish, as above
        raise ValueError(
            f"prefix: {len(out)} characters make topic names longer than ROS 2's "
            f"{_MAX_TOPIC_NAME} (.../{_LONGEST_TOPIC}): at most "
            f"{_MAX_TOPIC_NAME - len(_LONGEST_TOPIC) - 1}"
        )
    return out


def _sqlite(writer: Any) -> sqlite3.Connection | None:
    """A rosbags writer's database connection (its sqlite storage), None for another storage."""
    conn = getattr(getattr(writer, "storage", None), "conn", None)
    return conn if isinstance(conn, sqlite3.Connection) else None


def _os_error(what: str, exc: OSError) -> OSError:
    """``exc`` said of ``what`` (the bag), keeping its errno: rosbags' own words named no bag."""
    err = OSError(f"{what}: {exc.strerror or exc}")
    err.errno = exc.errno
    return err


class BagWriter:
    """Write depth results into a new ROS 2 bag folder.

    Parameters
    ----------
    path : str or os.PathLike
        The bag's folder; it must not exist yet (a bag is never appended to or overwritten).
    prefix : str
        Topic namespace.
    frame_id : str
        ``header.frame_id`` of every message.
    points : bool
        Also write the point cloud (the largest topic).
    scan_frame_id : str
        ``header.frame_id`` of the scans: the floor frame under the camera, the parent frame of
        :meth:`GroundPlane.ros2_static_transform <stereovision.ground.GroundPlane.\
ros2_static_transform>`.
    tf : bool
        With a ``ground`` given to :meth:`write`, also write ``/tf``: ``frame_id`` under
        ``scan_frame_id``. False for a robot whose own transforms (``robot_state_publisher``)
        already place the camera: a frame has one parent in tf.

    Raises
    ------
    ValueError
        If ``prefix`` gives no ROS 2 topic name (a part other than letters, digits and
        underscores, or starting with a digit; over 225 characters, so that a topic name is
        over ROS 2's 247), ``frame_id`` or ``scan_frame_id`` is no tf
        frame name (empty, or a leading ``/``), or the two are one frame.
    TypeError
        If ``points`` or ``tf`` is not True or False, or ``prefix`` is not a string.
    FileExistsError
        If ``path`` exists.
    FileNotFoundError, NotADirectoryError
        If its parent folder does not exist or is a file.
    OSError
        If the folder cannot be made there (a read-only mount), naming it.
    ImportError
        Without the ``rosbags`` package.

    Examples
    --------
    >>> with BagWriter("run1") as bag:                       # doctest: +SKIP
    ...     bag.write(sv.depth_map(left, right, calib), stamp_ns=t)
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        prefix: str = DEFAULT_PREFIX,
        frame_id: str = DEFAULT_FRAME_ID,
        points: bool = True,
        scan_frame_id: str = "base_footprint",
        tf: bool = True,
    ) -> None:
        self.path = _bag_path(path)
        # checked before the folder is made: a bad keyword left an empty bag folder behind
        self.prefix = _topic_prefix(prefix)
        self.frame_id = _frame_name(frame_id, "frame_id")
        self.scan_frame_id = _frame_name(scan_frame_id, "scan_frame_id")
        if self.scan_frame_id == self.frame_id:
            # the optical frame is placed under the floor frame (/tf), and the scan is in the
            # floor's axes: as one frame, tf2 ignores the transform and the scan is misplaced
            raise ValueError(
                f"frame_id and scan_frame_id are one frame ({frame_id!r}): the camera's optical "
                "frame stands in the floor frame, so they need two names"
            )
        self.points = _flag(points, "points")
        self.tf = _flag(tf, "tf")
        if self.path.exists():
            raise FileExistsError(f"bag folder already exists: {self.path} (choose a new one)")
        if self.path.parent.exists() and not self.path.parent.is_dir():
            # it said "does not exist" of the user's file
            raise NotADirectoryError(
                f"bag folder's parent is a file, not a folder: {self.path.parent}"
            )
        if not self.path.parent.is_dir():
            raise FileNotFoundError(f"bag folder's parent does not exist: {self.path.parent}")
        writer_cls, self._types = _rosbags()
        self.messages = 0
        #: Whole frames the bag holds (as :attr:`messages`, read back after a rollback).
        self.frames = 0
        self._writer = writer_cls(self.path, version=9)
        try:
            self._writer.open()
        except OSError as exc:
            # a folder that cannot be written (a read-only mount): rosbags' "[Errno 2] No such
            # file or directory: 'PATH'" named no cause
            raise _os_error(f"cannot write the bag folder {self.path}", exc) from None
        self._conns: dict[str, Any] = {}
        self._pending: list[tuple[str, str, Any, int]] = []  # the frame being made, serialised
        # a frame's savepoint taken and the frame not yet released or undone and counted: an
        # interrupt (a Ctrl-C no longer held) cut it, see :meth:`_settle`
        self._unsettled = False
        self._committed = time.monotonic()

    # ------------------------------------------------------------------------------ helpers

    def _conn(self, topic: str, msgtype: str) -> Any:
        if topic not in self._conns:
            # an absolute topic ("/tf") stays out of the namespace: tf listens there only
            name = topic if topic.startswith("/") else f"{self.prefix}/{topic}"
            self._conns[topic] = self._writer.add_connection(name, msgtype, typestore=self._types)
        return self._conns[topic]

    def _header(self, stamp_ns: int, frame_id: str | None = None) -> Any:
        t = self._types.types
        stamp = t["builtin_interfaces/msg/Time"](
            sec=int(stamp_ns // 1_000_000_000), nanosec=int(stamp_ns % 1_000_000_000)
        )
        return t["std_msgs/msg/Header"](
            stamp=stamp, frame_id=self.frame_id if frame_id is None else frame_id
        )

    def _put(self, topic: str, msgtype: str, msg: Any, stamp_ns: int) -> None:
        """Serialise one message of the frame being made; :meth:`_flush` writes them."""
        self._pending.append((topic, msgtype, self._types.serialize_cdr(msg, msgtype), stamp_ns))

    def _flush(self) -> None:
        """Write the frame's messages as one: a failure part-way (a full disk, a second Ctrl-C)
        rolls back those written, so the bag never holds part of a frame; the writer's counts
        (its metadata.yaml) and :attr:`messages` are then read back from the database."""
        pending, self._pending = self._pending, []
        conn = _sqlite(self._writer)
        if conn is None:  # another storage: no rollback
            for topic, msgtype, data, stamp in pending:
                self._writer.write(self._conn(topic, msgtype), stamp, data)
                self.messages += 1
            self.frames += 1
            return
        if not conn.in_transaction:
            conn.execute("BEGIN")  # else the savepoint's release would commit at every frame
        self._unsettled = True
        conn.execute("SAVEPOINT frame")
        try:
            for topic, msgtype, data, stamp in pending:
                self._writer.write(self._conn(topic, msgtype), stamp, data)
        except BaseException:
            try:
                conn.execute("ROLLBACK TO frame")
                conn.execute("RELEASE frame")
            except sqlite3.Error:  # sqlite rolled the transaction back itself (or cannot undo)
                try:
                    conn.rollback()
                except sqlite3.Error:
                    pass
            self._resync(conn)
            self._unsettled = False
            raise
        # Out of the try: an interrupt landing as the frame is released (whole) was taken for a
        # cut frame, and the undoing, finding no savepoint, rolled back every frame since the
        # last commit. Cut here, the frame stays unsettled: :meth:`_settle` keeps and counts it.
        conn.execute("RELEASE frame")
        self.messages += len(pending)
        self.frames += 1
        self._unsettled = False

    def _settle(self) -> None:
        """Undo a frame an interrupt left unfinished, before the next frame or the close.

        A Ctrl-C that is no longer held (the third) can cut :meth:`_flush` anywhere, the undoing
        of a cut frame too: its savepoint then stayed open and the close's commit kept the part
        of the frame written. The savepoint is rolled back when it is still open (a frame
        released already is whole and stays), and the counts are read back from the database.
        """
        conn = _sqlite(self._writer)
        if not self._unsettled or conn is None:
            return
        try:
            conn.execute("ROLLBACK TO frame")
            conn.execute("RELEASE frame")
        except sqlite3.Error:  # "no such savepoint": released (whole) or undone by sqlite
            pass
        self._resync(conn)
        self._unsettled = False

    def _resync(self, conn: sqlite3.Connection) -> None:
        """The writer's connections, message counts and time span as the database holds them
        after a rollback (metadata.yaml is written from them), and :attr:`frames`: the depth
        images it holds (one a frame, and a frame is all or nothing)."""
        w = self._writer
        topics = {row[0] for row in conn.execute("SELECT id FROM topics")}
        w.connections = [c for c in w.connections if c.id in topics]
        self._conns = {k: c for k, c in self._conns.items() if c.id in topics}
        w.added_types = {
            row[0] for row in conn.execute("SELECT topic_type FROM message_definitions")
        }
        counts = dict.fromkeys(topics, 0)
        counts |= dict(conn.execute("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id"))
        w.counts = counts
        lo, hi = conn.execute("SELECT MIN(timestamp), MAX(timestamp) FROM messages").fetchone()
        w.min_timestamp = 2**63 - 1 if lo is None else lo
        w.max_timestamp = 0 if hi is None else hi
        self.messages = sum(counts.values())
        depth = self._conns.get("depth")
        self.frames = 0 if depth is None else counts.get(depth.id, 0)

    def _image(self, header: Any, img: np.ndarray, encoding: str) -> Any:
        arr = np.ascontiguousarray(img)
        h, w = arr.shape[:2]
        return self._types.types["sensor_msgs/msg/Image"](
            header=header,
            height=h,
            width=w,
            encoding=encoding,
            is_bigendian=0,
            step=arr.strides[0],
            data=arr.view(np.uint8).reshape(-1),
        )

    def _camera_info(self, header: Any, result: Any, side: str = "left") -> Any:
        """The rectified ``side`` camera as ROS's ``CameraInfo``: ``K``, no distortion, and
        ``P = [K | t]`` projecting points of the left rectified frame, ``t = 0`` for the left
        camera and ``(-fx B, 0, 0)`` for the right one (ROS's stereo convention: a reader's
        baseline is ``-P[0, 3] / P[0, 0]``)."""
        t = self._types.types
        cal = result.calibration
        cal = cal if cal.rectified else cal.rectified_calibration()
        k = np.asarray(cal.K1 if side == "left" else cal.K2, np.float64)
        shift = np.zeros((3, 1))
        if side == "right":
            shift[0, 0] = -k[0, 0] * cal.baseline_m
        p = np.hstack([k, shift])
        w, h = cal.image_size
        roi = t["sensor_msgs/msg/RegionOfInterest"](
            x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
        )
        return t["sensor_msgs/msg/CameraInfo"](
            header=header,
            height=h,
            width=w,
            distortion_model="plumb_bob",
            d=np.zeros(5),
            k=k.reshape(-1),
            r=np.eye(3).reshape(-1),
            p=p.reshape(-1),
            binning_x=0,
            binning_y=0,
            roi=roi,
        )

    def _cloud(self, header: Any, result: Any, grid: Any) -> Any:
        t = self._types.types
        pts = np.asarray(result.points, np.float32).reshape(-1, 3)
        colors = np.asarray(result.colors, np.uint8).reshape(-1, 3)
        if len(pts) == 0:  # computed with cloud=False (stream): the cloud from the depth map
            grid = grid()
            keep = np.isfinite(result.depth)
            pts = np.asarray(grid[keep], np.float32)
            colors = np.zeros((len(pts), 3), np.uint8)
            if result.left_rectified is not None and result.left_rectified.ndim == 3:
                colors = result.left_rectified[keep][:, ::-1]  # BGR -> RGB
        n = len(pts)
        rec = np.zeros(n, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4")])
        rec["x"], rec["y"], rec["z"] = pts[:, 0], pts[:, 1], pts[:, 2]
        if len(colors) == n:
            c = colors.astype(np.uint32)  # RGB packed as PCL does: 0x00RRGGBB
            rec["rgb"] = (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]
        field = t["sensor_msgs/msg/PointField"]
        fields = [
            field(name="x", offset=0, datatype=7, count=1),  # FLOAT32
            field(name="y", offset=4, datatype=7, count=1),
            field(name="z", offset=8, datatype=7, count=1),
            # FLOAT32 (7) holding the bits 0x00RRGGBB: the type pcl::PointXYZRGB gives its rgb
            # field (pcl_conversions, RViz's RGB8); the bytes are the same as a UINT32's
            field(name="rgb", offset=12, datatype=7, count=1),
        ]
        return t["sensor_msgs/msg/PointCloud2"](
            header=header,
            height=1,
            width=n,
            fields=fields,
            is_bigendian=False,
            point_step=16,
            row_step=16 * n,
            data=rec.view(np.uint8).reshape(-1),
            is_dense=True,
        )

    def _disparity(self, header: Any, result: Any) -> Any:
        """``stereo_msgs/DisparityImage`` as ``stereo_image_proc`` publishes it: ``Z = f t / d``,
        so ``d`` is the disparity plus the rig's ``doffs`` (0 for a rig rectified by OpenCV);
        a pixel without one is below ``min_disparity`` (-1: ROS's readers test ``d <
        min_disparity``, which NaN would pass). Only the pixels with a depth carry one: a
        filled pixel (no depth) or one at or below its uncertainty (``d`` near 0, ``Z`` near
        infinity) would give a reader a point the depth image does not have."""
        t = self._types.types
        cal = result.calibration
        d = np.asarray(result.disparity, np.float32) + np.float32(cal.doffs_px)
        known = np.isfinite(np.asarray(result.depth)) & np.isfinite(d)
        lo = float(cal.doffs_px + result.min_disparity)
        d = np.where(known, d, np.float32(lo - 1.0)).astype(np.float32)
        rows, cols = np.nonzero(known)
        roi = t["sensor_msgs/msg/RegionOfInterest"](
            x_offset=int(cols.min()) if cols.size else 0,
            y_offset=int(rows.min()) if rows.size else 0,
            height=int(rows.max() - rows.min() + 1) if rows.size else 0,
            width=int(cols.max() - cols.min() + 1) if cols.size else 0,
            do_rectify=False,
        )
        return t["stereo_msgs/msg/DisparityImage"](
            header=header,
            image=self._image(header, d, "32FC1"),
            f=float(cal.focal_px),
            t=float(cal.baseline_m),
            valid_window=roi,
            min_disparity=lo,
            max_disparity=float(cal.doffs_px + result.max_disparity),
            delta_d=1.0 / 16,  # the floating map is finer; stereo_image_proc's SGBM step
        )

    def _transform(self, stamp_ns: int, ground: Any) -> Any:
        """``/tf``'s message: the optical frame under :attr:`scan_frame_id`, the pose of
        :meth:`GroundPlane.camera_in_floor <stereovision.ground.GroundPlane.camera_in_floor>`
        (REP 105: without it the scan, in the floor frame, and the images and cloud, in the
        optical frame, could not be shown or used together). Stamped as the frame, on ``/tf``
        rather than ``/tf_static``: a floor fitted again moves it."""
        from stereovision.ground import _quaternion, floor_frame

        t = self._types.types
        qx, qy, qz, qw = _quaternion(floor_frame(ground))
        moved = t["geometry_msgs/msg/Transform"](
            translation=t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=float(ground.height)),
            rotation=t["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
        )
        pose = t["geometry_msgs/msg/TransformStamped"](
            header=self._header(stamp_ns, self.scan_frame_id),
            child_frame_id=self.frame_id,
            transform=moved,
        )
        return t["tf2_msgs/msg/TFMessage"](transforms=[pose])

    def _scan(self, stamp_ns: int, scan: Any) -> Any:
        t = self._types.types
        return t["sensor_msgs/msg/LaserScan"](
            header=self._header(stamp_ns, self.scan_frame_id),
            angle_min=float(scan.angle_min),
            angle_max=float(scan.angle_max),
            angle_increment=float(scan.angle_increment),
            time_increment=0.0,
            scan_time=0.0,
            range_min=float(scan.range_min),
            range_max=float(scan.range_max),
            ranges=np.asarray(scan.ranges, np.float32),
            intensities=np.zeros(0, np.float32),
        )

    # --------------------------------------------------------------------------------- API

    def write(self, result: Any, stamp_ns: int, *, scan: Any = None, ground: Any = None) -> None:
        """Write one depth result (:class:`~stereovision.depth.DepthResult` with a calibration)
        stamped ``stamp_ns`` nanoseconds (the frame's time), and its
        :class:`~stereovision.ground.LaserScan`: ``scan`` when given, else the scan of the
        obstacles on ``ground`` (a :class:`~stereovision.ground.GroundPlane`), from the same
        reprojection of the depth map as the cloud. With ``ground`` (and ``tf``), also
        ``/tf``: the optical frame ``frame_id`` under the floor frame ``scan_frame_id``, the
        camera's pose on the floor (:meth:`~stereovision.ground.GroundPlane.camera_in_floor`).

        Raises
        ------
        ValueError
            For a result without depth (computed without a calibration), a stamp that is not
            whole nanoseconds from 0 to ROS 2's last second (2**31 s: ``sec`` is an int32), or
            a closed bag.
        OSError
            When the bag's database cannot be written (a full disk), naming the bag. None of
            the frame's messages is then in the bag (a frame is all or nothing), nor the frames
            since the last commit when sqlite rolls its transaction back; the writer's counts
            (and so metadata.yaml, :attr:`messages` and :attr:`frames`) are those the database
            holds.
        TypeError
            If ``result`` is not a depth result.
        """
        if not (hasattr(result, "depth") and hasattr(result, "calibration")):
            # an image or None gave "'numpy.ndarray' object has no attribute 'depth'"
            raise TypeError(f"result: expected a DepthResult, got {type(result).__name__}")
        if result.depth is None or result.calibration is None:
            raise ValueError("a bag holds depth: compute the result with a calibration")
        stamp = _stamp(stamp_ns)
        if self._writer is None:
            raise ValueError(f"bag {self.path} is closed")
        try:
            with HeldInterrupts():
                self._settle()
                self._pending = []
                self._write_frame(result, stamp, scan, ground)  # serialised, not written
                self._flush()
                if time.monotonic() - self._committed >= COMMIT_PERIOD_S:
                    self._commit()
        except sqlite3.Error as exc:  # e.g. "database or disk is full"
            raise OSError(f"bag {self.path}: {exc}") from exc
        except OSError as exc:
            raise _os_error(f"bag {self.path}", exc) from exc

    def _commit(self) -> None:
        """Commit the frames written so far (rosbags keeps one transaction until close)."""
        conn = _sqlite(self._writer)
        if conn is not None:
            try:
                conn.commit()
            except sqlite3.Error:
                self._resync(conn)  # sqlite may have rolled the frames since the last one back
                raise
        self._committed = time.monotonic()

    def _write_frame(self, result: Any, stamp: int, scan: Any, ground: Any) -> None:
        header = self._header(stamp)
        if result.left_rectified is not None:
            left = np.asarray(result.left_rectified, np.uint8)
            enc = "bgr8" if left.ndim == 3 else "mono8"
            self._put(
                _LONGEST_TOPIC,
                "sensor_msgs/msg/Image",
                self._image(header, left, enc),
                stamp,
            )
        left_info = self._camera_info(header, result)
        for topic, info in (
            ("left/camera_info", left_info),
            ("right/camera_info", self._camera_info(header, result, "right")),
            # the depth image's camera, where image_transport looks for it: beside ``depth``
            # (depth_image_proc's point_cloud_xyz subscribes to the two as one camera)
            ("camera_info", left_info),
        ):
            self._put(topic, "sensor_msgs/msg/CameraInfo", info, stamp)
        depth = np.asarray(result.depth, np.float32)
        self._put("depth", "sensor_msgs/msg/Image", self._image(header, depth, "32FC1"), stamp)
        self._put(
            "disparity",
            "stereo_msgs/msg/DisparityImage",
            self._disparity(header, result),
            stamp,
        )
        memo: list[Any] = []

        def grid() -> Any:  # the depth map's points, reprojected once for the cloud and scan
            if not memo:
                memo.append(result.point_image(filled=True))
            return memo[0]

        if self.points:
            cloud = self._cloud(header, result, grid)
            self._put("points", "sensor_msgs/msg/PointCloud2", cloud, stamp)
        if scan is None and ground is not None:
            from stereovision.ground import laser_scan

            scan = laser_scan(grid(), ground, result.calibration)
        if scan is not None:
            self._put("scan", "sensor_msgs/msg/LaserScan", self._scan(stamp, scan), stamp)
        if ground is not None and self.tf:
            self._put("/tf", "tf2_msgs/msg/TFMessage", self._transform(stamp, ground), stamp)

    def close(self) -> None:
        """Finish the bag (its metadata.yaml); the writer cannot be used afterwards.

        Raises
        ------
        OSError
            When the bag cannot be finished (a full disk): the frames committed before are in
            its ``.db3`` and ``ros2 bag reindex`` rebuilds its metadata.
        """
        writer = self._writer
        if writer is None:
            return
        try:
            with HeldInterrupts():
                try:
                    self._settle()  # not to commit part of a frame
                finally:
                    self._writer = None
                writer.close()
        except sqlite3.Error as exc:
            conn = _sqlite(writer)
            if conn is not None:
                conn.close()
            raise OSError(
                f"bag {self.path} could not be finished ({exc}): the frames committed before "
                f"(every {COMMIT_PERIOD_S:g} s) are in its .db3; `ros2 bag reindex {self.path}` "
                "rebuilds its metadata.yaml"
            ) from exc

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, exc_type: object, exc: BaseException | None, tb: object) -> None:
        """Close the bag; an error that ended the ``with`` block stays the one raised.

        A bag that cannot be finished on the way out of a failing block (the disk still full)
        replaced that block's error with its own; its message is added to the block's error
        now (a note, in Python 3.11+; a :class:`RuntimeWarning` before), and raised alone when
        the block ended well.
        """
        try:
            self.close()
        except OSError as close_exc:
            if exc is None:
                raise
            if hasattr(exc, "add_note"):
                exc.add_note(str(close_exc))
            else:  # Python 3.10
                warnings.warn(str(close_exc), RuntimeWarning, stacklevel=2)


# ==================================================================================== reading

IMAGE_TYPE = "sensor_msgs/msg/Image"
COMPRESSED_TYPE = "sensor_msgs/msg/CompressedImage"
CAMERA_INFO_TYPE = "sensor_msgs/msg/CameraInfo"
#: Stamps of this many first frames of each side set the default pairing tolerance.
PERIOD_SAMPLE = 8
#: Left frames held back while waiting for a right one; beyond, the oldest is decided as if the
#: recording had ended (a right topic that stopped must not make the reader hold the whole bag).
#: Right frames beyond this many without a left one are dropped, oldest first (and the default
#: tolerance is decided then, for a left topic that stopped before its PERIOD_SAMPLE frames).
MAX_WAITING = 64

# ROS encoding -> (channels, bytes per channel, OpenCV conversion to BGR or None). ROS names a
# Bayer pattern by its first two pixels (rggb: R G / G B), OpenCV by the second row's second and
# third, so ROS's rggb is OpenCV's BayerBG: cv_bridge's table, checked in the tests.
_ENCODINGS: dict[str, tuple[int, int, int | None]] = {
    "mono8": (1, 1, cv2.COLOR_GRAY2BGR),
    "8uc1": (1, 1, cv2.COLOR_GRAY2BGR),
    "mono16": (1, 2, cv2.COLOR_GRAY2BGR),
    "16uc1": (1, 2, cv2.COLOR_GRAY2BGR),
    "bgr8": (3, 1, None),
    "8uc3": (3, 1, None),
    "rgb8": (3, 1, cv2.COLOR_RGB2BGR),
    "bgr16": (3, 2, None),
    "16uc3": (3, 2, None),
    "rgb16": (3, 2, cv2.COLOR_RGB2BGR),
    "bgra8": (4, 1, cv2.COLOR_BGRA2BGR),
    "8uc4": (4, 1, cv2.COLOR_BGRA2BGR),
    "rgba8": (4, 1, cv2.COLOR_RGBA2BGR),
    "bgra16": (4, 2, cv2.COLOR_BGRA2BGR),
    "16uc4": (4, 2, cv2.COLOR_BGRA2BGR),
    "rgba16": (4, 2, cv2.COLOR_RGBA2BGR),
    "bayer_rggb8": (1, 1, cv2.COLOR_BayerBG2BGR),
    "bayer_bggr8": (1, 1, cv2.COLOR_BayerRG2BGR),
    "bayer_gbrg8": (1, 1, cv2.COLOR_BayerGR2BGR),
    "bayer_grbg8": (1, 1, cv2.COLOR_BayerGB2BGR),
    "bayer_rggb16": (1, 2, cv2.COLOR_BayerBG2BGR),
    "bayer_bggr16": (1, 2, cv2.COLOR_BayerRG2BGR),
    "bayer_gbrg16": (1, 2, cv2.COLOR_BayerGR2BGR),
    "bayer_grbg16": (1, 2, cv2.COLOR_BayerGB2BGR),
    "yuv422": (2, 1, cv2.COLOR_YUV2BGR_UYVY),
    "uyvy": (2, 1, cv2.COLOR_YUV2BGR_UYVY),
    "yuv422_yuy2": (2, 1, cv2.COLOR_YUV2BGR_YUY2),
    "yuyv": (2, 1, cv2.COLOR_YUV2BGR_YUY2),
}
#: The ROS image encodings :func:`decode_image` reads.
ENCODINGS = tuple(sorted(_ENCODINGS))


def _bag_paths(path: Path) -> list[Path]:
    """The files rosbags opens for ``path``: a ROS 2 bag folder as it is; a folder of ROS 1
    ``.bag`` files (a recording split by ``rosbag record --split``) as all of them, in name
    order; a ROS 2 bag folder without its ``metadata.yaml`` (a recorder killed before writing
    it) as its ``.db3`` or ``.mcap`` files (it was "not a readable bag": ``ros2 bag reindex``
    needs ROS); a ``.bag`` file alone. A folder holding none of them is a ValueError saying what
    a bag folder holds."""
    if path.is_dir() and not (path / "metadata.yaml").is_file():
        parts = sorted(path.glob("*.bag"))
        if parts:
            return parts
        parts = sorted(path.glob("*.db3")) or sorted(path.glob("*.mcap"))
        if parts:
            return parts
        # rosbags said "Expected metadata file 'DIR' does not exist.", the folder named as
        # the file (a folder of images, a mistyped run folder)
        raise ValueError(
            "a folder without a ROS 2 bag's metadata.yaml (or its .db3 / .mcap files) nor a "
            "ROS 1 recording's .bag files"
        )
    return [path]


class _UnfinishedBagError(ValueError):
    """A recording its recorder left unfinished (a ROS 1 ``.bag.active``, an MCAP file without
    its summary): said as it is, with its remedy, not wrapped in "not a readable bag"."""


_MCAP_MAGIC = b"\x89MCAP0\r\n"


def _unfinished_mcap(path: Path) -> Path | None:
    """The MCAP file of ``path`` (the file, or a ROS 2 bag folder's) that starts as MCAP and
    does not end as one: its recorder stopped (killed, power lost) before writing the summary
    and footer, or is still writing it. rosbags said "File end magic is invalid."."""
    files = [path] if path.is_file() else sorted(path.glob("*.mcap")) if path.is_dir() else []
    for f in files:
        if f.suffix != ".mcap":
            continue
        try:
            with f.open("rb") as fh:
                head = fh.read(len(_MCAP_MAGIC))
                size = f.stat().st_size
                fh.seek(max(0, size - len(_MCAP_MAGIC)))
                tail = fh.read(len(_MCAP_MAGIC))
        except OSError:
            continue  # rosbags says what it can of an unreadable file
        # a file of the leading magic alone (the recorder killed as it began) ends as it
        # starts: its tail is its head, and rosbags said "ord() expected a character"
        if head == _MCAP_MAGIC and (tail != _MCAP_MAGIC or size < 2 * len(_MCAP_MAGIC)):
            return f
    return None


_ROS1_MAGIC = b"#ROSBAG V2.0\n"


def _unindexed_ros1(path: Path) -> tuple[Path, int, int] | None:
    """The ROS 1 bag file of ``path`` (the file, or a split recording's pieces) whose bag
    header places its index nowhere in the file, with that position and the file's size: 0
    when its recorder never wrote one, past the end when the file was cut short (an
    interrupted copy or download, a full disk). rosbags said "Bag index looks damaged:
    ('Header could not be read from file.',)" of a cut file, no remedy named."""
    for f in _bag_paths(path):
        try:
            with f.open("rb") as fh:
                head = fh.read(4096)
                size = os.fstat(fh.fileno()).st_size
        except OSError:
            continue  # rosbags says what it can of an unreadable file
        if not head.startswith(_ROS1_MAGIC):
            continue
        # the bag header record: its header's length, then fields of (length, name=value)
        pos = len(_ROS1_MAGIC) + 4
        end = min(len(head), pos + int.from_bytes(head[pos - 4 : pos], "little"))
        while pos + 4 <= end:
            n = int.from_bytes(head[pos : pos + 4], "little")
            field = head[pos + 4 : pos + 4 + n]
            pos += 4 + n
            if field.startswith(b"index_pos=") and len(field) == 18:
                index_pos = int.from_bytes(field[10:], "little")
                if index_pos == 0 or index_pos >= size:
                    return f, index_pos, size
                break
    return None


_SPLIT_PIECE = re.compile(r"^(.*)_\d+\.bag(\.active)?$")


def _active_pieces(folder: Path) -> list[Path]:
    """The ``.bag.active`` files of ``folder`` that are pieces of the recording its ``.bag``
    files hold (``NAME_N.bag`` beside ``NAME_M.bag.active``, ``rosbag record --split``), or all
    of them when it holds no bag files. Another recording's ``.bag.active`` (one still being
    recorded into the same folder, beside ``.bag`` pieces or a ROS 2 bag's ``.db3`` / ``.mcap``
    files) is no piece of it: the finished recording was refused for it, though it reads
    whole."""
    active = sorted(folder.glob("*.bag.active"))
    finished = sorted(folder.glob("*.bag"))
    if not finished:
        ros2 = any(folder.glob("*.db3")) or any(folder.glob("*.mcap"))
        return [] if ros2 else active

    def name(p: Path) -> str:
        m = _SPLIT_PIECE.match(p.name)
        return m.group(1) if m else p.name.removesuffix(".active").removesuffix(".bag")

    names = {name(p) for p in finished}
    return [p for p in active if name(p) in names]


def _open_reader(path: Path) -> Any:
    """rosbags' reader of a ROS 1 or ROS 2 bag, opened. A ROS 2 bag recorded before Iron holds
    no message definitions: ``sensor_msgs`` are then read with Humble's (the same since)."""
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise ImportError(
            "reading ROS bags needs rosbags: pip install 'stereovision-rs[ros]'"
        ) from None
    # rosbag record's file until it is closed: killed, it holds no index (rosbags said
    # "Unrecognized storage format '.active'", info "not a text calibration file"). In a folder
    # of a split recording it is the last piece, which was left out without a word
    active = (
        [path]
        if path.name.endswith(".bag.active")
        else _active_pieces(path)
        if path.is_dir() and not (path / "metadata.yaml").is_file()
        else []
    )
    if active:
        raise _UnfinishedBagError(
            f"{active[0]} is a ROS 1 recording left unfinished (its recorder stopped before "
            f"writing the index): `rosbag reindex {active[0]}` indexes it; then rename it to .bag"
        )
    unindexed = _unindexed_ros1(path)
    if unindexed is not None:
        bag, index_pos, size = unindexed
        why = (
            "its recorder stopped before writing it"
            if index_pos == 0
            else f"cut short: {size} bytes, the index due at byte {index_pos}; an interrupted "
            "copy or download, a full disk?"
        )
        raise _UnfinishedBagError(
            f"{bag} is a ROS 1 bag without its index ({why}): `rosbag reindex {bag}` "
            "indexes the messages it holds"
        )
    cut = _unfinished_mcap(path)
    if cut is not None:
        raise _UnfinishedBagError(
            f"{cut} is an MCAP recording left unfinished (its recorder stopped before writing "
            f"its summary, or is still recording): `mcap recover {cut} -o FIXED.mcap` (the mcap "
            "CLI) rebuilds it"
        )
    paths = _bag_paths(path)
    reader = AnyReader(paths, default_typestore=get_typestore(Stores.ROS2_HUMBLE))
    try:
        reader.open()
    except Exception as exc:  # rosbags' errors name no common base class
        if "Bag index looks damaged" not in str(exc):
            raise
        # an index cut part-way (its start inside the file): the same remedy
        named = paths[0] if len(paths) == 1 else path / "*.bag"
        raise _UnfinishedBagError(
            f"{named} is a ROS 1 bag whose index is damaged (cut short?): `rosbag reindex "
            f"{named}` indexes the messages it holds"
        ) from None
    return reader


def _topic_lines(path: Path, reader: Any, roles: dict[str, str]) -> str:
    """``BagCamera.summary``'s lines: the bag, then each topic's type, messages and rate,
    with its role (``roles``: topic -> suffix)."""
    # an index's count of 0 is checked on the messages, as BagCamera's topics are: a bag whose
    # metadata.yaml counts none listed the topics it reads as "0 msgs 0.00 Hz" (and a ROS 2
    # one's span as 0.0 s); their count and rate are unknown ("?"), a topic without any is 0
    zero = {t for t, i in reader.topics.items() if i.msgcount <= 0}
    unknown = _holding(reader, zero) if zero else set()
    span = "?" if reader.start_time > reader.end_time else f"{max(reader.duration, 1) / 1e9:.1f}"
    kind = "ROS 2" if getattr(reader, "is2", True) else "ROS 1"
    lines = [f"bag {path} ({kind}, {span} s, {len(reader.topics)} topics)"]
    width = max((len(t) for t in reader.topics), default=0)
    for topic, info in sorted(reader.topics.items()):
        count, rate = (
            (f"{'?':>7}", f"{'?':>7}")
            if topic in unknown
            else (f"{info.msgcount:7d}", f"{_rate(info.msgcount, reader):7.2f}")
        )
        # a topic recorded with two types (a ROS 1 bag's connections, or split pieces) has none
        # in rosbags' summary: None's format failed ("internal TypeError", info of a whole bag)
        msgtype = info.msgtype or " or ".join(sorted({c.msgtype for c in info.connections}))
        lines.append(
            f"  {topic:<{width}}  {msgtype:<31} {count} msgs {rate} Hz{roles.get(topic, '')}"
        )
    return "\n".join(lines)


def bag_topics(path: str | os.PathLike[str]) -> str:
    """The topics of any bag, as :meth:`BagCamera.summary` lists them, without looking for a
    stereo pair: for a bag in which none is found (the depth bag ``stream --bag`` writes holds
    one image topic and the depth image), so that ``info`` still shows what it holds.

    Parameters
    ----------
    path : str or os.PathLike
        A ROS 1 ``.bag`` file or a folder of them, or a ROS 2 bag folder (or one of its files).

    Returns
    -------
    str
        A few lines for a terminal.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist (a link whose target moved named so).
    ValueError
        If ``path`` is not a readable bag.
    ImportError
        Without the ``rosbags`` package.
    """
    p = _bag_path(path)
    if not p.exists():
        # as BagCamera says it: a missing bag was "not a readable ROS 1 or ROS 2 bag: The
        # following paths are missing: [PosixPath('run.bag')]", a ValueError
        from stereovision.io import _broken_link

        gone = f" ({_broken_link(p)})" if p.is_symlink() else ""
        raise FileNotFoundError(f"bag not found: {p}{gone}")
    if p.is_file() and (p.parent / "metadata.yaml").is_file():
        p = p.parent  # a file of a ROS 2 bag, as BagCamera takes it
    try:
        reader = _open_reader(p)
    except (ImportError, _UnfinishedBagError):
        raise
    except Exception as exc:  # rosbags' errors name no common base class
        raise ValueError(f"{p} is not a readable ROS 1 or ROS 2 bag: {exc}") from None
    try:
        return _topic_lines(p, reader, {})
    finally:
        reader.close()


def _message_bytes(data: Any) -> np.ndarray:
    """A message's ``data`` as a flat ``uint8`` array: rosbags' arrays, and the ``bytes`` of
    rospy's messages (np.asarray read those as one number: "invalid literal for int()", the
    whole image quoted)."""
    if isinstance(data, (bytes, bytearray, memoryview)):
        return np.frombuffer(data, np.uint8).copy()  # a copy: the image comes out writable
    return np.asarray(data, np.uint8).reshape(-1)


def decode_image(msg: Any) -> np.ndarray:
    """A ``sensor_msgs/Image`` or ``CompressedImage`` message as a BGR image.

    Parameters
    ----------
    msg : object
        The deserialised message (``rosbags``' classes, or anything with the same fields:
        rospy's and rclpy's messages, ``data`` as ``bytes`` or an array of bytes).

    Returns
    -------
    numpy.ndarray
        ``(H, W, 3)`` BGR, ``uint8`` or, for 16-bit encodings, ``uint16`` (see :func:`to_8bit`);
        writable, whatever the message's buffer.
        A compressed grey image whose format names a Bayer encoding (``"bayer_rggb8; png
        compressed "``: image_transport compresses the mosaic as it is) is demosaiced.

    Raises
    ------
    ValueError
        For an encoding that is not one of :data:`ENCODINGS` (named), a ``compressedDepth``
        image, data that does not decode, a size, ``step`` and data length that disagree, or a
        4:2:2 (``yuv422``, ``uyvy``, ``yuyv``) image of an odd width.
    """
    if hasattr(msg, "format"):  # CompressedImage
        fmt = str(msg.format)
        if "compresseddepth" in fmt.lower():
            raise ValueError(f"compressed image format {fmt!r} is a depth image, not a camera's")
        from stereovision.io import _imdecode  # cv2.error for a header of an impossible size

        buf = _message_bytes(msg.data)
        img = _imdecode(buf, cv2.IMREAD_UNCHANGED) if buf.size else None
        if img is None:
            raise ValueError(f"compressed image ({fmt!r}, {buf.size} bytes) does not decode")
        # image_transport compresses a Bayer image as it is, the mosaic in a grey JPEG or PNG,
        # and says so in the format ("bayer_rggb8; png compressed "): it came out grey, the
        # mosaic's checkerboard kept. Demosaiced now, as the raw topic is.
        source = _ENCODINGS.get(fmt.split(";", 1)[0].strip().lower())
        if img.ndim == 2 and source is not None and source[0] == 1 and source[2] is not None:
            return np.asarray(cv2.cvtColor(img, source[2]))
        if img.ndim == 2:
            return np.asarray(cv2.cvtColor(img, cv2.COLOR_GRAY2BGR))
        if img.shape[2] == 4:
            return np.asarray(cv2.cvtColor(img, cv2.COLOR_BGRA2BGR))
        return np.asarray(img)
    enc = str(msg.encoding)
    spec = _ENCODINGS.get(enc.lower())
    if spec is None:
        raise ValueError(
            f"image encoding {enc!r} is not a camera image this reader knows; expected one of "
            f"{', '.join(ENCODINGS)}"
        )
    ch, nbytes, code = spec
    h, w, step = int(msg.height), int(msg.width), int(msg.step)
    data = _message_bytes(msg.data)
    row = w * ch * nbytes
    if h <= 0 or w <= 0 or step < row or data.size < step * h:
        raise ValueError(
            f"{enc} image of {w}x{h} px: step {step} and {data.size} data bytes do not hold it "
            f"({row} bytes per row needed)"
        )
    if code in (cv2.COLOR_YUV2BGR_UYVY, cv2.COLOR_YUV2BGR_YUY2) and w % 2:
        # two pixels share one chroma pair: OpenCV's assertion (cv2.error) escaped BagCamera
        raise ValueError(f"{enc} image of {w}x{h} px: 4:2:2 data needs an even width")
    rows = np.ascontiguousarray(data[: step * h].reshape(h, step)[:, :row])
    arr: np.ndarray = rows
    if nbytes == 2:
        arr = rows.view(">u2" if msg.is_bigendian else "<u2").astype(np.uint16)
    arr = arr.reshape((h, w) if ch == 1 else (h, w, ch))
    if code is not None:
        return np.asarray(cv2.cvtColor(arr, code))
    # unpadded 8-bit BGR is a view of the message's buffer, which rosbags gives read-only: a
    # bag's bgr8 frames were not writable where a camera's are (cv2.putText on one raised)
    return arr if arr.flags.writeable else arr.copy()


def to_8bit(*images: np.ndarray) -> tuple[np.ndarray, ...]:
    """Bring 16-bit images to ``uint8`` with one power-of-two shift for all of them.

    The shift is the smallest that keeps the brightest pixel of the images, so a pair keeps one
    scale (the matchers compare the two images) and a 10- or 12-bit sensor's data in a 16-bit
    container is not left nearly black. ``uint8`` images are returned as they are.
    """
    return _shifted_to_8bit(images, _needed_shift(images))


def _needed_shift(images: tuple[np.ndarray, ...]) -> int:
    """The smallest right shift that brings the brightest 16-bit pixel of ``images`` to 8 bits."""
    peak = max((int(im.max()) for im in images if im.dtype == np.uint16 and im.size), default=0)
    return max(0, peak.bit_length() - 8)


def _shifted_to_8bit(images: tuple[np.ndarray, ...], shift: int) -> tuple[np.ndarray, ...]:
    """``images`` as ``uint8``, the 16-bit ones shifted right by ``shift``."""
    return tuple(
        (im >> shift).astype(np.uint8) if im.dtype == np.uint16 else np.asarray(im, np.uint8)
        for im in images
    )


def is_bag(path: str | os.PathLike[str]) -> bool:
    """Does ``path`` name a ROS bag: a ``.bag`` file (or a ``.bag.active`` one, a recording
    left unfinished, which the reader refuses with its remedy), a folder of them (a split
    recording, whose last piece may be left unfinished), a ROS 2 bag folder
    (``metadata.yaml``; or its ``.db3`` / ``.mcap`` files without it), one of its files, or a
    ``.db3`` / ``.mcap`` file alone (a recorder that left no metadata.yaml)?"""
    p = as_path(path)
    if not os.fspath(path):
        return False  # '' is no name: the current folder was asked about
    # a bag's storage file alone is read (its recorder left no metadata.yaml): `info` took
    # it for a calibration file
    if p.is_file() and (p.suffix in (".bag", ".db3", ".mcap") or p.name.endswith(".bag.active")):
        return True
    folder = p if p.is_dir() else p.parent
    if (folder / "metadata.yaml").is_file():
        return True
    exts = (".bag", ".db3", ".mcap", ".bag.active")
    return p.is_dir() and any(any(p.glob(f"*{ext}")) for ext in exts)


def _gap_text(gap_ns: int) -> str:
    """A stamp difference as the no-pair error says it: seconds to 3 decimals from a second,
    3 significant digits of ms below (a 0.3 ms gap was "-0.000 s"), whole ns under a
    microsecond. Never in exponent form: ``.3g`` said 999.7 ms as "+1e+03 ms" and 5 ns (a
    ``max_skew_ms`` of 0) as "+5e-06 ms"."""
    if abs(gap_ns) >= 10**9:
        return f"{gap_ns / 1e9:+.3f} s"
    if abs(gap_ns) < 1000:
        return f"{gap_ns:+d} ns"
    ms = gap_ns / 1e6
    text = f"{ms:+.{max(0, 2 - math.floor(math.log10(abs(ms))))}f}"
    return (text.rstrip("0").rstrip(".") if "." in text else text) + " ms"


def _skew_text(tol_ns: float) -> str:
    """The pairing tolerance as :func:`_gap_text` says a gap, without its sign: ``.3g`` said
    a max skew of 1500 ms as "1.5e+03 ms" (now "1.500 s") and 5 ns as "5e-06 ms" (now "5 ns")."""
    if not math.isfinite(tol_ns):  # the default of a bag without two stamps on a side
        return f"{tol_ns} ms"
    return _gap_text(round(tol_ns)).removeprefix("+")


def _rate(count: int, reader: Any) -> float:
    """Messages per second of a topic over the bag's span (n messages span n - 1 periods)."""
    span_s = reader.duration / 1e9
    return (count - 1) / span_s if count > 1 and span_s > 0 else 0.0


def _stamp_ns(msg: Any, recorded_ns: int) -> int:
    """The header's stamp in nanoseconds; the recording time when the driver left it 0."""
    stamp = msg.header.stamp
    ns = int(stamp.sec) * 1_000_000_000 + int(getattr(stamp, "nanosec", 0))
    return ns if ns > 0 else int(recorded_ns)


def _is_left_right(a: str, b: str) -> bool:
    """Is ``a``/``b`` one topic-name part of a left/right pair (``left``/``right``, ``cam0``/
    ``cam1``, ``infra1``/``infra2``)?"""
    if "left" in a.lower() and a.lower().replace("left", "right") == b.lower():
        return True
    ma, mb = re.fullmatch(r"(\D*)(\d+)(\D*)", a), re.fullmatch(r"(\D*)(\d+)(\D*)", b)
    return bool(ma and mb and ma[1] == mb[1] and ma[3] == mb[3] and int(ma[2]) < int(mb[2]))


def _base_topic(topic: str) -> str:
    """The image topic without an image_transport suffix (``.../image_raw/compressed``)."""
    return re.sub(r"/(compressed|theora|ffmpeg|zstd)$", "", topic)


def _topic_hint(topic: str, images: list[str], topics: dict[str, Any]) -> str:
    """What a topic given that is no image topic of the bag is: one of another type (its type
    named: a ``camera_info`` given for the image), or the image topic nearest its name (a
    name without its leading ``/``, a typo); ``""`` when none is near. The error listed the
    bag's image topics alone, to be compared by eye with the name typed."""
    info = topics.get(topic)
    if info is not None:
        msgtype = info.msgtype or " or ".join(sorted({c.msgtype for c in info.connections}))
        return f": it holds {msgtype}, not sensor_msgs/Image or CompressedImage"
    near = difflib.get_close_matches(topic, images, n=1, cutoff=0.8)
    return f"; did you mean {near[0]!r}?" if near else ""


def _stereo_pairs(image_topics: list[str]) -> list[tuple[str, str]]:
    """The ``(left, right)`` pairs among ``image_topics``, as :func:`find_stereo_topics` forms
    them: names that differ in one ``/``-separated part, a left/right one."""
    pairs = []
    for a in image_topics:
        pa = a.split("/")
        for b in image_topics:
            pb = b.split("/")
            if a == b or len(pa) != len(pb):
                continue
            diff = [i for i in range(len(pa)) if pa[i] != pb[i]]
            if len(diff) == 1 and _is_left_right(pa[diff[0]], pb[diff[0]]):
                pairs.append((a, b))
    return pairs


def _holding(reader: Any, topics: set[str]) -> set[str]:
    """Those of ``topics`` that hold a message, from the messages themselves, not the index.

    Read in time order until each topic has shown one message: a topic with messages costs
    a few of them (the first message of a 528 MB bag's topic came in 1-7 ms, sqlite3 or MCAP),
    only a topic without any costs a pass over the bag."""
    found: set[str] = set()
    conns = [c for c in reader.connections if c.topic in topics]
    if not conns:
        return found
    messages = reader.messages(connections=conns)
    try:
        for conn, _recorded, _raw in messages:
            found.add(conn.topic)
            if found == topics:
                break
    finally:
        messages.close()
    return found


def find_stereo_topics(
    image_topics: list[str], counts: dict[str, int] | None = None
) -> tuple[str, str]:
    """Pick the left and right image topics among a bag's image topics.

    Two topics form a pair when their names differ in one ``/``-separated part, ``left`` against
    ``right`` or a lower against a higher number (``cam0``/``cam1``). Among several pairs, those
    whose two topics hold messages are preferred, then raw (``image_raw``) and uncompressed ones.

    Parameters
    ----------
    image_topics : list of str
        The bag's image topics.
    counts : dict of str to int, optional
        Each topic's message count (-1: holds messages, how many unknown). Default: every
        topic taken to hold messages.

    Raises
    ------
    ValueError
        When no pair, more than one equally good pair, or only pairs without messages on both
        topics are found (the topics are listed).
    """
    pairs = _stereo_pairs(image_topics)
    listing = ", ".join(sorted(image_topics)) or "none"
    if not pairs:
        # two topics to give where the bag holds one or none was advice none could follow
        advice = (
            "give the topics (--left-topic, --right-topic)"
            if len(image_topics) > 1
            else "a pair needs an image topic per camera, and the bag holds one (was the other "
            "camera recorded?)"
            if image_topics
            else "the bag holds no sensor_msgs/Image or CompressedImage topic"
        )
        raise ValueError(f"no left/right pair among the bag's image topics ({listing}); {advice}")

    def held(topic: str) -> int:
        return 1 if counts is None else counts.get(topic, 0)

    # a topic recorded but never published (0 messages) gave a camera of no frames: a raw pair
    # without messages was taken over a rectified one with them
    def rank(pair: tuple[str, str]) -> tuple[bool, bool, bool]:
        full = held(pair[0]) != 0 and held(pair[1]) != 0
        return (full, "raw" in pair[0], _base_topic(pair[0]) == pair[0])

    best = max(rank(p) for p in pairs)
    if not best[0]:
        # a count unknown is not said as a number (a zero-count index's topic held 4, said 1)
        said = {t: "some" if held(t) < 0 else str(held(t)) for p in pairs for t in p}
        names = "; ".join(f"{a} + {b} ({said[a]} and {said[b]} messages)" for a, b in pairs)
        raise ValueError(f"no stereo pair of the bag holds messages on both topics: {names}")
    top = [p for p in pairs if rank(p) == best]
    if len(top) > 1:
        names = "; ".join(f"{a} + {b}" for a, b in top)
        raise ValueError(
            f"the bag holds several stereo pairs ({names}); give the topics (--left-topic, "
            "--right-topic)"
        )
    return top[0]


#: Largest ``max_skew_ms`` :class:`BagCamera` takes: 1000 s, far past any pair (two frames
#: that far apart are no pair); 1e308 overflowed its whole nanoseconds, an OverflowError.
MAX_SKEW_MS = 1e6


class BagCamera(PairSource):
    """A stereo rig recorded in a ROS 1 or ROS 2 bag, read as synchronised pairs.

    It has :class:`~stereovision.capture.StereoCamera`'s interface (``read``, ``frames``,
    ``skew_report``, ``describe``, ``close``, ``size``, ``count``, ``skews_ms``), so it is
    accepted wherever a camera is; see the module doc for how topics, pairs and images are
    read. The frames' ``t_left`` / ``t_right`` are the header stamps (seconds), their skew the
    stamps' difference, and ``pos_*_ms`` the time since the bag's start.

    Parameters
    ----------
    path : str or os.PathLike
        A ROS 1 ``.bag`` file or a folder of them (a recording split by ``rosbag record
        --split``, read in name order), or a ROS 2 bag folder (sqlite3 or MCAP).
    left_topic, right_topic : str, optional
        The image topics; found when not given (both or neither).
    max_skew_ms : float, optional
        Largest stamp difference of a pair. Default: half the frame period of the faster topic
        (from the first :data:`PERIOD_SAMPLE` frames' stamps), so a frame pairs at most once.
        At most :data:`MAX_SKEW_MS`.
    image_size : tuple of int or str, optional
        Resize the frames to ``(width, height)`` (or ``"WxH"``); a size of another shape than the
        recording's is not applied (a resize would stretch the frames), with a warning. Default:
        as recorded. The keyword ``size=``, its former name, still works, with a
        DeprecationWarning (the attribute stays :attr:`size`).
    realtime : bool
        Play the recording at its own pace, as a live camera would deliver it: each read waits
        for the next pair's time, and gives the newest pair whose time has come, skipping those
        a slow reader missed (counted in :attr:`skipped`). Default: every pair, at once.

    Attributes
    ----------
    topics : dict of str to str
        ``{"left": topic, "right": topic}``.
    info_topics : dict of str to str or None
        Each side's ``camera_info`` topic, None when the bag has none beside the image topic
        (or only one without messages).
    dropped : dict of str to int
        Frames of each side that found no partner within ``max_skew_ms`` (so far).
    stamps_ns : list of int
        The left header stamp of every pair read, in order.
    skipped : int
        Pairs passed over by ``realtime`` playback because the reader was late for them.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        If it is not a bag, a given topic is not an image topic of the bag, or the topics
        cannot be found (the bag's image topics are listed); a ``max_skew_ms`` that is not a
        number from 0 to :data:`MAX_SKEW_MS`.
    TypeError
        If ``realtime`` is not True or False.
    ImportError
        Without the ``rosbags`` package.
    """

    @renamed_keyword("size", "image_size")
    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        left_topic: str | None = None,
        right_topic: str | None = None,
        max_skew_ms: float | None = None,
        image_size: tuple[int, int] | str | None = None,
        realtime: bool = False,
    ) -> None:
        from stereovision.capture import parse_size

        self.path = _bag_path(path)
        if not self.path.exists():
            # a link whose target moved (a bag linked in from a disk since unmounted) was "not
            # found" alone, of a name ls lists: its target is named, as io's readers name it
            from stereovision.io import _broken_link

            gone = f" ({_broken_link(self.path)})" if self.path.is_symlink() else ""
            raise FileNotFoundError(f"bag not found: {self.path}{gone}")
        if self.path.is_file() and (self.path.parent / "metadata.yaml").is_file():
            self.path = self.path.parent  # a file of a ROS 2 bag (its .db3, .mcap or metadata)
        if (left_topic is None) != (right_topic is None):
            raise ValueError("give both the left and the right topic, or neither")
        # a Fraction or Decimal as its float (refused as "expected a number"), as the
        # library's other numbers; 10**400 is a number, too large (math.isfinite's
        # OverflowError)
        skew_in = _plain_real(max_skew_ms)
        if max_skew_ms is not None and not (
            real_number(skew_in)
            and (too_large_for_float(skew_in) or math.isfinite(skew_in))
            and skew_in >= 0
        ):  # "5" was TypeError's "must be real number, not str", True taken as 1 ms
            raise ValueError(
                f"max_skew_ms: expected a number >= 0, got {number_shown(max_skew_ms)}"
            )
        if max_skew_ms is not None and skew_in > MAX_SKEW_MS:
            raise ValueError(
                f"max_skew_ms: expected at most {MAX_SKEW_MS:g}, got {number_shown(max_skew_ms)}"
            )
        skew = None if max_skew_ms is None else float(skew_in)
        self.requested_size = parse_size(image_size, "image_size")
        realtime = _flag(realtime, "realtime")  # bool("no") played the bag in real time
        try:
            reader = _open_reader(self.path)
        except (ImportError, _UnfinishedBagError):
            raise
        except Exception as exc:  # rosbags' errors name no common base class
            raise ValueError(f"{self.path} is not a readable ROS 1 or ROS 2 bag: {exc}") from None
        self._reader: Any = reader
        self.realtime = realtime
        self.skipped = 0
        self._clock: Any = time.monotonic  # the wall clock and the wait (tests replace them)
        self._sleep: Any = time.sleep
        self._start: tuple[float, int] | None = None  # (wall time, stamp) of the first pair
        self._peeked: deque[tuple[int, Any, int, Any]] = deque()
        self._origin: int | None = None  # the bag's start (_start_ns)
        try:
            self._setup(left_topic, right_topic, skew)
        except BaseException:
            self.close()
            raise

    def _setup(self, left: str | None, right: str | None, max_skew_ms: float | None) -> None:
        topics = self._reader.topics
        images = sorted(t for t, i in topics.items() if i.msgtype in (IMAGE_TYPE, COMPRESSED_TYPE))
        if left is None or right is None:
            counts = {t: topics[t].msgcount for t in images}
            # an index's count of 0 is not trusted alone: some recorders leave metadata.yaml's
            # message_count 0 (or a bag cut short has none), and such a bag was refused as one
            # without messages though it read fine with its topics given. Only then are the
            # pairs' zero-count topics looked at, so a bag whose index counts its messages
            # costs nothing more.
            unsure = {t for pair in _stereo_pairs(images) for t in pair if counts[t] <= 0}
            if unsure:
                counts |= dict.fromkeys(_holding(self._reader, unsure), -1)  # how many unknown
            left, right = find_stereo_topics(images, counts)
        for side, topic in (("left", left), ("right", right)):
            if topic not in images:
                raise ValueError(
                    f"{side} topic {topic!r} is not an image topic of {self.path}"
                    f"{_topic_hint(topic, images, topics)} (its image topics: "
                    f"{', '.join(images) or 'none'})"
                )
        if left == right:
            raise ValueError(f"the left and right topics are the same: {left!r}")
        self.topics = {"left": left, "right": right}
        self.sources = {"left": f"{self.path}:{left}", "right": f"{self.path}:{right}"}
        infos = {
            side: info
            for side, topic in self.topics.items()
            if (info := _base_topic(topic).rsplit("/", 1)[0] + "/camera_info") in topics
            and topics[info].msgtype == CAMERA_INFO_TYPE
        }
        # a topic recorded and never published (0 messages) is none: calibration()'s first
        # message raised StopIteration. An index's 0 is checked on the messages, as the image
        # topics' are (a bag whose index counts none read without its calibration)
        unsure = {info for info in infos.values() if topics[info].msgcount <= 0}
        held = _holding(self._reader, unsure) if unsure else set()
        empty = unsure - held
        self.info_topics: dict[str, str | None] = {
            side: None if infos.get(side) in empty else infos.get(side) for side in self.topics
        }
        self.rectified_topics = all(
            "rect" in _base_topic(t).rsplit("/", 1)[-1] for t in (left, right)
        )
        self._conns = [c for c in self._reader.connections if c.topic in (left, right)]
        self.delivered_fps = {
            s: _rate(topics[t].msgcount, self._reader) for s, t in self.topics.items()
        }
        self.size = self.requested_size
        self._shape: tuple[int, int] | None = None  # the first left frame's size
        self._shift = 0  # the 16-bit frames' shift to 8 bits, the largest needed so far
        self._warned: set[str] = set()
        self.delivered_size: dict[str, tuple[int, int]] = {}
        self.skews_ms: list[float] = []
        self.stamps_ns: list[int] = []
        self.count = 0
        self.dropped = {"left": 0, "right": 0}
        self.max_skew_ms = max_skew_ms
        # whole nanoseconds of the value given (stamps are ints): 4.1 * 1e6 is 4099999.9999999995
        # in floats, which refused a pair exactly 4.1 ms apart (33.3 ms, 2.01 ms, ... alike)
        self._tol_ns: float | None = (
            None if max_skew_ms is None else math.floor(round(max_skew_ms * 1e6, 6))
        )
        self._first: dict[str, list[int]] = {"left": [], "right": []}
        self._damage: Exception | None = None  # what stopped the reading of a damaged bag
        self._failed = False  # the damage met: its error is raised by every read after it
        self._pairs = self._pair_iter()

    # ------------------------------------------------------------------------------ pairing

    def _default_tolerance(self) -> float:
        periods = []
        for stamps in self._first.values():
            steps = [b - a for a, b in itertools.pairwise(stamps) if b > a]
            if steps:
                periods.append(statistics.median(steps))
        return 0.5 * min(periods) if periods else math.inf

    def _match(
        self, lefts: deque[tuple[int, Any]], rights: deque[tuple[int, Any]], final: bool
    ) -> Iterator[tuple[int, Any, int, Any]]:
        if self._tol_ns is None:
            # right frames no left frame can take (left stamps rise): those before the first
            # waiting left's nearest at or before it, or beyond the newest MAX_WAITING with no
            # left yet; counted as crowding, they decided the tolerance before a late left
            # camera's stamps came (half the right period, not the shorter left one's). Left
            # frames beyond MAX_WAITING with no right yet are dropped (as once decided), so a
            # late right camera's stamps are waited for too.
            if lefts:
                # (strictly older: of equal stamps the pairing takes the first)
                while len(rights) > 1 and rights[0][0] < rights[1][0] <= lefts[0][0]:
                    rights.popleft()
                    self.dropped["right"] += 1
            else:
                while len(rights) > MAX_WAITING:
                    rights.popleft()
                    self.dropped["right"] += 1
            while not rights and len(lefts) > MAX_WAITING:
                lefts.popleft()
                self.dropped["left"] += 1
            sampled = all(len(s) >= PERIOD_SAMPLE for s in self._first.values())
            # a left side that stopped before PERIOD_SAMPLE frames: decided once either side
            # has MAX_WAITING waiting (it held the other's every frame, decoded, to the end)
            crowded = len(lefts) > MAX_WAITING or (bool(lefts) and len(rights) > MAX_WAITING)
            if not (final or sampled or crowded):
                return
            self._tol_ns = self._default_tolerance()
            self.max_skew_ms = self._tol_ns / 1e6
        tol = self._tol_ns
        while lefts:
            sl = lefts[0][0]
            # differences of int stamps: sl +- tol in floats (stamps near 1.7e18 ns, a 256 ns
            # step) refused a pair exactly max_skew_ms apart
            while rights and sl - rights[0][0] > tol:
                rights.popleft()
                self.dropped["right"] += 1
            waiting = not rights or rights[-1][0] < sl
            if waiting and not final and len(lefts) <= MAX_WAITING:
                return  # a nearer right frame may still come
            best = None
            for i, (sr, _) in enumerate(rights):
                if sr - sl > tol:
                    break
                if best is None or abs(sr - sl) < abs(rights[best][0] - sl):
                    best = i
            _, ml = lefts.popleft()
            if best is None:
                self.dropped["left"] += 1
                continue
            for _ in range(best):
                rights.popleft()
                self.dropped["right"] += 1
            sr, mr = rights.popleft()
            yield sl, ml, sr, mr
        while len(rights) > MAX_WAITING:  # a left topic that stopped: keep the newest only
            rights.popleft()
            self.dropped["right"] += 1

    def _messages(self) -> Iterator[tuple[Any, int, Any]]:
        """The two image topics' messages, deserialised, in recording order.

        A bag damaged part-way (a ROS 1 chunk, a ``.db3`` page or an MCAP record overwritten)
        raised rosbags', apsw's or sqlite's own error out of :meth:`read`: ``stream`` lost the
        summary of the pairs done and the CLI called it an internal error ("please report
        this"), ``capture`` did not say its pairs were kept. It is a failure of the source now
        (:class:`~stereovision.capture.SourceError`, not an end), naming the bag and the pairs
        read before. The messages end at the damage, which is kept in ``self._damage`` for
        :meth:`_pair_iter` to raise once the pairs read before it are delivered.
        """
        messages = self._reader.messages(connections=self._conns)
        try:
            while True:
                try:
                    item = next(messages, None)
                    if item is None:
                        return
                    conn, recorded, raw = item
                    msg = self._reader.deserialize(raw, conn.msgtype)
                except Exception as exc:  # rosbags' errors name no common base class
                    self._damage = exc
                    return
                yield conn, recorded, msg
        finally:
            messages.close()

    def _pair_iter(self) -> Iterator[tuple[int, Any, int, Any]]:
        lefts: deque[tuple[int, Any]] = deque()
        rights: deque[tuple[int, Any]] = deque()
        left_topic = self.topics["left"]
        for conn, recorded, msg in self._messages():
            side = "left" if conn.topic == left_topic else "right"
            stamp = _stamp_ns(msg, recorded)
            if len(self._first[side]) < PERIOD_SAMPLE:
                self._first[side].append(stamp)
            (lefts if side == "left" else rights).append((stamp, msg))
            yield from self._match(lefts, rights, final=False)
        # the frames read before a damage are paired as at the end of a recording: raised at
        # once, it lost the pairs still waiting (the first PERIOD_SAMPLE frames, a left frame
        # waiting for a nearer right one), and said fewer pairs than the bag holds
        yield from self._match(lefts, rights, final=True)
        self.dropped["right"] += len(rights)
        if self._damage is not None:
            raise self._damage_error()

    def _damage_error(self) -> SourceError:
        """The error of a bag that cannot be read past :attr:`count` pairs (``_damage``)."""
        exc = self._damage
        error = SourceError(
            f"bag {self.path} cannot be read past {_pairs(self.count)} (damaged or cut short?): "
            f"{type(exc).__name__}: {exc}",
            end=False,
            frames=self.count,
        )
        error.__cause__ = exc
        return error

    # ------------------------------------------------------------------------------ reading

    def _fit(self, side: str, img: np.ndarray, stamp: int) -> np.ndarray:
        """``img`` at the output size. A frame of another shape than the first left frame is
        refused, as :class:`~stereovision.capture.StereoCamera` refuses it (a resize stretched
        it silently: a 450x300 right topic came out as 450x375 beside a 450x375 left one, and
        every depth or calibration made of it was wrong); one of the same shape and another
        size is resized with one warning per side, unless ``size`` asked for it. A ``size`` of
        another shape than the first frame's is dropped, with a warning (and the frames then
        resized to the first one's are said, as without a ``size``)."""
        h, w = img.shape[:2]
        self.delivered_size[side] = (w, h)
        if self._shape is None:
            self._shape = (w, h)
            rw, rh = self.size or (w, h)
            if abs((w / h) / (rw / rh) - 1) > 0.01:
                # as StereoCamera (and `capture --size`'s help) has it: a size of another
                # shape would stretch the frames, so they keep theirs (they were stretched)
                source_warning(
                    f"size {rw}x{rh} is another shape than the recording's {w}x{h}: its frames "
                    f"are kept at {w}x{h} (a resize would stretch them)",
                )
                self.size = (w, h)
        if self.size is None:
            self.size = (w, h)
        sw, sh = self._shape
        if abs((w / h) / (sw / sh) - 1) > 0.01:
            raise SourceError(
                f"bag {self.path}: {self.topics[side]} at stamp {stamp} ns is {w}x{h}, the "
                f"{self.topics['left']} frames {sw}x{sh}: frames of another shape cannot be "
                f"paired without stretching one ({self.count} pairs read before)",
                side=side,
                end=False,
                frames=self.count,
            )
        if (w, h) == self.size:
            return img
        # said unless the size is the one asked (not when a size asked was dropped above)
        if self.size != self.requested_size and side not in self._warned:
            self._warned.add(side)
            source_warning(
                f"{self.topics[side]} is {w}x{h}, not {self.size[0]}x{self.size[1]}: its frames "
                "are resized",
            )
        return resize_frame(img, self.size)

    def read(self) -> StereoFrame:
        """The next pair, as a :class:`~stereovision.capture.StereoFrame`.

        Raises
        ------
        SourceError
            At the end of the recording, or when the bag is closed; for a frame whose shape
            differs from the first left frame's, or a bag that cannot be read on (damaged,
            cut short), the bag and the pairs read before named (``end`` False).
        ValueError
            If a frame does not decode (its topic and stamp named).
        """
        if self._reader is None:
            raise SourceError("the bag is closed")
        nxt = self._next_pair()
        if nxt is None:
            firsts = self._first["left"][:1] + self._first["right"][:1]
            hint = ""
            if self.count == 0 and len(firsts) == 2:
                tol = self._tol_ns if self._tol_ns is not None else math.inf
                # frames on both sides and no pair said no why: two cameras stamping with two
                # clocks (one its own, since boot) are seconds or years apart, which this shows.
                # Under a second in ms: a 0.3 ms gap to a 0.1 ms max skew was "-0.000 s"
                said = _gap_text(firsts[0] - firsts[1])
                hint = (
                    f"; no left and right stamps within {_skew_text(tol)} of each other: "
                    f"the first left stamp is {said} from the first right one (cameras stamping "
                    "with different clocks?)"
                )
            raise SourceError(
                f"bag {self.path}: end of the recording after {_pairs(self.count)} "
                f"({self.dropped['left']} left and {self.dropped['right']} right frames without "
                f"a partner){hint}"
            )
        sl, ml, sr, mr = nxt
        imgs = []
        for side, msg, stamp in (("left", ml, sl), ("right", mr, sr)):
            try:
                imgs.append(decode_image(msg))
            except ValueError as exc:
                raise ValueError(f"{self.topics[side]} at stamp {stamp} ns: {exc}") from None
        # One shift for the whole recording so far, the largest a pair has needed: a shift of
        # each pair's own halved a frame's grey levels for a single glint past the others'
        # peak (the same 11-bit scene read 172, 86, 172 over three pairs, the middle one with
        # one pixel at 4095), a flicker that capture --temporal took for a change of light.
        self._shift = max(self._shift, _needed_shift((imgs[0], imgs[1])))
        left, right = _shifted_to_8bit((imgs[0], imgs[1]), self._shift)
        start = self._start_ns()
        fitted = (self._fit("left", left, sl), self._fit("right", right, sr))
        frame = StereoFrame(
            left=fitted[0],
            right=fitted[1],
            delivered=None if fitted[0] is left and fitted[1] is right else (left, right),
            t_left=sl / 1e9,
            t_right=sr / 1e9,
            index=self.count,
            pos_left_ms=(sl - start) / 1e6,
            pos_right_ms=(sr - start) / 1e6,
        )
        self.count += 1
        self.skews_ms.append(frame.skew_ms)
        self.stamps_ns.append(sl)
        return frame

    def _start_ns(self) -> int:
        """The bag's start (its first message's recording time), the origin of the frames'
        ``pos_*_ms``. rosbags takes it from the index: a ROS 2 bag whose metadata.yaml counts
        no message (read since its topics are checked on the messages) gave 2**63 - 1, and
        every position near -7.5e12 ms; its first message is read for it then (once)."""
        if self._origin is None:
            reader = self._reader
            start = int(reader.start_time)
            if start > reader.end_time:  # no message counted: no span known
                messages = reader.messages()
                try:
                    first = next(messages, None)
                finally:
                    messages.close()
                start = int(first[1]) if first is not None else 0
            self._origin = start
        return self._origin

    def _next_pair(self) -> tuple[int, Any, int, Any] | None:
        """The next pair; with ``realtime``, the newest whose time has come (waiting for it).
        A damaged bag's error (:meth:`_pair_iter`) is raised again on every read after it: the
        pairs' generator ended, and a read said "end of the recording" instead."""
        if self._failed:
            raise self._damage_error()
        try:
            nxt = self._peeked.popleft() if self._peeked else next(self._pairs, None)
        except SourceError:
            self._failed = True
            raise
        if not self.realtime or nxt is None:
            return nxt
        if self._start is None:
            self._start = (self._clock(), nxt[0])
            return nxt
        wall0, stamp0 = self._start
        due = stamp0 + (self._clock() - wall0) * 1e9  # the recording's time now
        while nxt[0] <= due:
            try:
                later = next(self._pairs, None)
            except SourceError:
                self._failed = True  # said on the next read: the pair due is delivered first
                break
            if later is None or later[0] > due:
                if later is not None:
                    self._peeked.append(later)
                break
            nxt = later  # the camera would have overwritten it: a late reader misses it
            self.skipped += 1
        if nxt[0] > due:
            self._sleep((nxt[0] - due) / 1e9)
        return nxt

    def _announced(self, side: str) -> int | None:
        """The messages the bag's index holds on ``side``'s topic, as
        :class:`~stereovision.capture.StereoCamera`'s ``_announced`` gives a video's frame count
        (a progress bar's total: each frame pairs at most once); None when the bag says none,
        or it is closed."""
        if self._reader is None:
            return None
        info = self._reader.topics.get(self.topics[side])
        count = int(getattr(info, "msgcount", 0) or 0)
        return count if count > 0 else None

    def describe(self) -> str:
        """One line: the bag, its two topics with their size and rate, the pairing tolerance."""
        tol = self._tol_ns
        skew = "max skew: auto" if tol is None else f"max skew {_skew_text(tol)}"
        # before the first read (capture's header) the sizes are the first recorded frames':
        # they were said "?", though a camera's or a file's are known once opened
        sizes = dict(self.delivered_size)
        for side in ("left", "right"):
            if side not in sizes and (size := self._first_size(side)) is not None:
                sizes[side] = size
        return f"bag {self.path}; " + self._delivered(self.topics, sizes) + f"; {skew}"

    def _first_size(self, side: str) -> tuple[int, int] | None:
        """``(width, height)`` of the first frame of ``side``'s topic as recorded; None when
        the bag is closed, the topic holds none or its first message cannot be read (the
        reading then says why)."""
        if self._reader is None:
            return None
        conns = [c for c in self._reader.connections if c.topic == self.topics[side]]
        if not conns:  # (no connections would read every topic's messages)
            return None
        messages = self._reader.messages(connections=conns)
        try:
            conn, _, raw = next(messages)
            msg = self._reader.deserialize(raw, conn.msgtype)
            if not hasattr(msg, "format"):  # a raw Image says its size, no decoding needed
                return (int(msg.width), int(msg.height)) if msg.width and msg.height else None
            h, w = decode_image(msg).shape[:2]
            return (w, h)
        except Exception:  # rosbags' errors name no common base class; read() says them
            return None
        finally:
            messages.close()

    def summary(self) -> str:
        """The bag's topics (type, messages, rate), which are the left and right images and
        their ``camera_info``: a few lines for a terminal."""
        reader = self._reader
        if reader is None:
            return f"bag {self.path} (closed)"
        roles = {t: f"  <- {side}" for side, t in self.topics.items()}
        roles |= {t: f"  <- {side} camera_info" for side, t in self.info_topics.items() if t}
        return _topic_lines(self.path, reader, roles)

    # ---------------------------------------------------------------------------- calibration

    def calibration(self) -> Any:
        """The rig's calibration from the bag's ``camera_info`` messages (the first of each
        side), in metres; None when the bag has no ``camera_info`` beside both image topics,
        or one of them is an uncalibrated camera's (``K[0] = 0``: ROS's own test,
        ``camera_info_manager``'s ``isCalibrated``; a driver without a calibration file, such as
        ``usb_cam``, publishes all zeros). For rectified topics, which use ``P`` alone, the
        test is ``P[0] = 0``.

        For raw topics it is the rig of :meth:`Calibration.from_ros
        <stereovision.calibration.Calibration.from_ros>`; for rectified topics (``image_rect``)
        the rectified rig of the two ``P`` matrices. Binned images (``binning_x/y`` > 1) get
        the calibration scaled by ``1 / binning`` on each axis (a binned pixel is the centre of
        its sensor pixels), at their size ``(width // binning_x, height // binning_y)``.

        Raises
        ------
        ValueError
            If a ``camera_info`` is not a stereo camera's (no baseline), its model is not
            supported, it describes a region of interest (named) or a malformed one (a zero
            width or height alone), or the two bin differently; if the first ``camera_info``
            message cannot be read (a damaged bag, named); if the two image topics share one
            ``camera_info`` topic (one namespace).
        """
        from stereovision.calibration import Calibration, _ros_yaml

        if self._reader is None or None in self.info_topics.values():
            return None
        if self.info_topics["left"] == self.info_topics["right"]:
            # two image topics of one namespace have one camera_info beside them: its first
            # message, one camera's, was read for both, and a stereo rig's calibration was
            # refused as "two monocular calibrations" (no baseline)
            raise ValueError(
                f"bag {self.path}: {self.topics['left']} and {self.topics['right']} share one "
                f"camera_info topic ({self.info_topics['left']}), so which camera a message "
                "describes is not known: give the rig's calibration (--calib RIG)"
            )
        texts: list[str] = []
        binning: list[tuple[int, int]] = []
        for side in ("left", "right"):
            topic = self.info_topics[side]
            conns = [c for c in self._reader.connections if c.topic == topic]
            messages = self._reader.messages(connections=conns)
            try:
                conn, _, raw = next(messages)
                msg = self._reader.deserialize(raw, conn.msgtype)
            except Exception as exc:  # rosbags' errors name no common base class
                # a damaged bag's ReaderError was "internal ReaderError (please report this)"
                raise ValueError(
                    f"bag {self.path}: its first {topic} message cannot be read (damaged or "
                    f"cut short?): {type(exc).__name__}: {exc}"
                ) from exc
            finally:
                messages.close()

            # ROS 2 spells the matrices k, d, r, p; ROS 1 K, D, R, P
            K, D, R, P = (
                np.asarray(getattr(msg, n) if hasattr(msg, n) else getattr(msg, n.upper()), float)
                for n in "kdrp"
            )
            K, R, P = K.reshape(3, 3), R.reshape(3, 3), P.reshape(3, 4)
            # an uncalibrated camera, as ROS tells it (K[0] == 0): its zeros were refused ("does
            # not hold a rotation"), so stream, info and gui failed on a bag that reads whole.
            # Rectified topics need P alone (K, D, R are replaced below): K's zeros beside a
            # valid P (a driver that fills P only) are a calibration there, P's zeros are none
            if (P[0, 0] if self.rectified_topics else K[0, 0]) == 0:
                return None
            roi = msg.roi
            size = (int(msg.width), int(msg.height))
            # ROS: a roi of all zeros is the full image; a zero width or height alone is none
            if bool(roi.width) != bool(roi.height):
                raise ValueError(
                    f"{topic}: camera_info has a malformed region of interest ({roi.width}x"
                    f"{roi.height} at {roi.x_offset},{roi.y_offset}): a zero width or height "
                    "alone describes no region (ROS's all-zero roi means the full image)"
                )
            if roi.width and roi.height and (roi.width, roi.height) != size:
                raise ValueError(
                    f"{topic}: camera_info has a region of interest ({roi.width}x{roi.height} at "
                    f"{roi.x_offset},{roi.y_offset}); cropped cameras are not supported"
                )
            model = str(msg.distortion_model) or "plumb_bob"
            if self.rectified_topics:
                K, D, R, model = P[:, :3], np.zeros(5), np.eye(3), "plumb_bob"
            texts.append(_ros_yaml(side, size, K, D, R, P, model))
            binning.append((max(int(msg.binning_x), 1), max(int(msg.binning_y), 1)))
        calib = Calibration._from_ros_texts(
            texts[0], texts[1], str(self.info_topics["left"]), str(self.info_topics["right"])
        )
        if binning[0] != binning[1]:
            # the larger was taken for both: one camera's calibration at another size than its
            # images', without a word
            (lx, ly), (rx, ry) = binning
            raise ValueError(
                f"{self.info_topics['left']} and {self.info_topics['right']} bin differently "
                f"({lx}x{ly} and {rx}x{ry}): a stereo pair's cameras must run in one mode"
            )
        bx, by = binning[0]
        if (bx, by) != (1, 1):
            w, h = calib.image_size
            # each axis by exactly 1 / b: scaled_to((w // bx, h // by)) took 187 / 375 for 375
            # rows binned by 2 (fy 0.27 % low, cy 0.25 px off)
            calib = calib._scaled((w // bx, h // by), 1 / bx, 1 / by)
        return calib

    def close(self) -> None:
        """Close the bag (idempotent)."""
        if self._reader is not None:
            try:
                self._reader.close()
            finally:
                self._reader = None

    def __enter__(self) -> BagCamera:
        return self
