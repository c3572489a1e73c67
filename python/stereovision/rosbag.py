"""Depth results as a ROS 2 bag: replay a run in RViz or feed it to a ROS pipeline, without ROS.

:class:`BagWriter` writes, for every result, the topics ``stereo_image_proc`` and
``depth_image_proc`` publish (REP 118 for depth images), stamped with the frame's time and in the
left rectified camera's optical frame (X right, Y down, Z forward: this package's frame):

================================  ===========================  ==================================
topic (``prefix`` = ``/stereo``)  type                         content
================================  ===========================  ==================================
``left/image_rect_color``         ``sensor_msgs/Image``        the rectified left image, ``bgr8``
``left/camera_info``              ``sensor_msgs/CameraInfo``   the rectified left camera (``P``)
``depth``                         ``sensor_msgs/Image``        ``32FC1`` metres, NaN where none
``points``                        ``sensor_msgs/PointCloud2``  ``x y z`` (float32) and ``rgb``
================================  ===========================  ==================================

The bag is written with the pure-Python ``rosbags`` library (``pip install rosbags``, or the
``ros`` extra), as a ROS 2 bag (sqlite3, CDR) that ``ros2 bag play`` reads.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["DEFAULT_FRAME_ID", "DEFAULT_PREFIX", "BagWriter"]

#: The frame the messages are stamped with (the left rectified camera's optical frame).
DEFAULT_FRAME_ID = "stereo_left_optical"
#: Topic namespace.
DEFAULT_PREFIX = "/stereo"


def _rosbags() -> tuple[Any, Any]:
    try:
        from rosbags.rosbag2 import Writer
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise ImportError(
            "writing ROS 2 bags needs the rosbags package: pip install rosbags (or the package's "
            "'ros' extra)"
        ) from None
    return Writer, get_typestore(Stores.ROS2_HUMBLE)


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

    Raises
    ------
    FileExistsError
        If ``path`` exists.
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
    ) -> None:
        self.path = Path(path)
        if self.path.exists():
            raise FileExistsError(f"bag folder already exists: {self.path} (choose a new one)")
        if not self.path.parent.is_dir():
            raise FileNotFoundError(f"bag folder's parent does not exist: {self.path.parent}")
        writer_cls, self._types = _rosbags()
        self.prefix = "/" + prefix.strip("/") if prefix.strip("/") else ""
        self.frame_id = str(frame_id)
        self.points = bool(points)
        self.messages = 0
        self._writer = writer_cls(self.path, version=9)
        self._writer.open()
        self._conns: dict[str, Any] = {}

    # ------------------------------------------------------------------------------ helpers

    def _conn(self, topic: str, msgtype: str) -> Any:
        if topic not in self._conns:
            self._conns[topic] = self._writer.add_connection(
                f"{self.prefix}/{topic}", msgtype, typestore=self._types
            )
        return self._conns[topic]

    def _header(self, stamp_ns: int) -> Any:
        t = self._types.types
        stamp = t["builtin_interfaces/msg/Time"](
            sec=int(stamp_ns // 1_000_000_000), nanosec=int(stamp_ns % 1_000_000_000)
        )
        return t["std_msgs/msg/Header"](stamp=stamp, frame_id=self.frame_id)

    def _put(self, topic: str, msgtype: str, msg: Any, stamp_ns: int) -> None:
        data = self._types.serialize_cdr(msg, msgtype)
        self._writer.write(self._conn(topic, msgtype), stamp_ns, data)
        self.messages += 1

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

    def _camera_info(self, header: Any, result: Any) -> Any:
        t = self._types.types
        cal = result.calibration
        k = np.asarray(cal.K1, np.float64)
        p = np.hstack([k, np.zeros((3, 1))])
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

    def _cloud(self, header: Any, result: Any) -> Any:
        t = self._types.types
        pts = np.asarray(result.points, np.float32).reshape(-1, 3)
        colors = np.asarray(result.colors, np.uint8).reshape(-1, 3)
        if len(pts) == 0:  # computed with cloud=False (stream): the cloud from the depth map
            grid = result.calibration.reproject(result.disparity)
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
            field(name="rgb", offset=12, datatype=6, count=1),  # UINT32, as PCL packs it
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

    # --------------------------------------------------------------------------------- API

    def write(self, result: Any, stamp_ns: int) -> None:
        """Write one depth result (:class:`~stereovision.depth.DepthResult` with a calibration)
        stamped ``stamp_ns`` nanoseconds (the frame's time).

        Raises
        ------
        ValueError
            For a result without depth (computed without a calibration), or a negative stamp.
        """
        if result.depth is None or result.calibration is None:
            raise ValueError("a bag holds depth: compute the result with a calibration")
        stamp = int(stamp_ns)
        if stamp < 0:
            raise ValueError(f"stamp_ns: expected a time in nanoseconds >= 0, got {stamp_ns!r}")
        header = self._header(stamp)
        if result.left_rectified is not None:
            left = np.asarray(result.left_rectified, np.uint8)
            enc = "bgr8" if left.ndim == 3 else "mono8"
            self._put(
                "left/image_rect_color",
                "sensor_msgs/msg/Image",
                self._image(header, left, enc),
                stamp,
            )
        self._put(
            "left/camera_info",
            "sensor_msgs/msg/CameraInfo",
            self._camera_info(header, result),
            stamp,
        )
        depth = np.asarray(result.depth, np.float32)
        self._put("depth", "sensor_msgs/msg/Image", self._image(header, depth, "32FC1"), stamp)
        if self.points:
            self._put("points", "sensor_msgs/msg/PointCloud2", self._cloud(header, result), stamp)

    def close(self) -> None:
        """Finish the bag (its metadata.yaml); the writer cannot be used afterwards."""
        if self._writer is not None:
            self._writer.close()
            self._writer = None

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
