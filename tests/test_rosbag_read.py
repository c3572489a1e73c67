"""Recorded rigs read from ROS 1 and ROS 2 bags (``BagCamera``): topics, pairing, encodings,
calibration from ``camera_info``, and the ``stream`` / ``capture`` commands on a bag.

The bags are written here with rosbags' own writers from real images (Middlebury cones and
OpenCV's chessboard pairs), so every frame read back can be compared with its source.
"""

from __future__ import annotations

import dataclasses
import io
import json
import math
import re
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

import stereovision as sv
from stereovision.calibration import Calibration, parse_ros_camera_info
from stereovision.io import load_scene

rosbags = pytest.importorskip("rosbags")

from rosbags.typesys import Stores, get_typestore  # noqa: E402

from stereovision.capture import SourceError  # noqa: E402
from stereovision.rosbag import (  # noqa: E402
    BagCamera,
    decode_image,
    find_stereo_topics,
    to_8bit,
)

LEFT, RIGHT = "/stereo/left/image_raw", "/stereo/right/image_raw"
PERIOD_NS = 33_333_333  # 30 fps
#: Tests that run the pipelined stream (its grab thread), as test_stream marks its own: a
#: deadlock of the grab thread and the matcher fails them within these seconds, with every
#: thread's stack, not at the suite's 600 s. Each took at most 2 s on a loaded two-core
#: machine, the KITTI one 7 s.
PIPELINED = pytest.mark.timeout(30)
SLOW_PIPELINED = pytest.mark.timeout(45)
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
T0 = 1_700_000_000_000_000_000


@pytest.fixture(scope="module")
def cones(data_dir: Path) -> Any:
    return load_scene(data_dir / "middlebury2003" / "cones")


# ------------------------------------------------------------------------------- encoding


def _image_fields(img: np.ndarray, encoding: str, *, pad: int = 0, big: bool = False) -> dict:
    """``img`` (BGR uint8, or uint16 for 16-bit encodings) laid out as ROS ``encoding`` does,
    written independently of the reader (numpy slicing, no OpenCV conversion codes)."""
    h, w = img.shape[:2]
    if encoding in ("mono8", "mono16"):
        arr = img if img.ndim == 2 else img[..., 1]
    elif encoding == "rgb8":
        arr = img[..., ::-1]
    elif encoding in ("bgr8", "bgr16"):
        arr = img
    elif encoding == "bgra8":
        arr = np.dstack([img, np.full((h, w), 255, img.dtype)])
    elif encoding.startswith("bayer_"):
        pattern = encoding[6:10]  # e.g. rggb: (0,0) R, (0,1) G, (1,0) G, (1,1) B
        index = {"b": 0, "g": 1, "r": 2}
        arr = np.empty((h, w), img.dtype)
        for k, colour in enumerate(pattern):
            dy, dx = divmod(k, 2)
            arr[dy::2, dx::2] = img[dy::2, dx::2, index[colour]]
    elif encoding in ("yuv422", "yuv422_yuy2"):
        y = img if img.ndim == 2 else img[..., 1]
        arr = np.empty((h, w, 2), np.uint8)
        # a grey image: chroma 128; UYVY puts chroma first, YUY2 luma first
        luma, chroma = (1, 0) if encoding == "yuv422" else (0, 1)
        arr[..., luma] = y
        arr[..., chroma] = 128
    else:
        raise AssertionError(encoding)
    arr = np.ascontiguousarray(arr)
    if arr.dtype == np.uint16:
        arr = arr.astype(">u2" if big else "<u2")
    rows = arr.view(np.uint8).reshape(h, -1)
    step = rows.shape[1] + pad
    data = np.zeros((h, step), np.uint8)
    data[:, : rows.shape[1]] = rows
    return {"height": h, "width": w, "encoding": encoding, "is_bigendian": int(big),
            "step": step, "data": data.reshape(-1)}  # fmt: skip


class _Msg:
    def __init__(self, **kw: Any) -> None:
        self.__dict__.update(kw)


def test_encodings_decode_to_the_source_image(cones: Any) -> None:
    bgr = cones.left
    grey = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
    for enc in ("bgr8", "rgb8", "bgra8"):
        np.testing.assert_array_equal(decode_image(_Msg(**_image_fields(bgr, enc, pad=7))), bgr)
    out = decode_image(_Msg(**_image_fields(grey, "mono8", pad=3)))
    assert out.shape == (*grey.shape, 3)
    np.testing.assert_array_equal(out[..., 0], grey)
    # 12-bit data in 16-bit containers, both byte orders: one shift of 4 brings it back
    g12 = grey.astype(np.uint16) << 4
    for big in (False, True):
        raw = decode_image(_Msg(**_image_fields(g12, "mono16", pad=2, big=big)))
        assert raw.dtype == np.uint16
        (back,) = to_8bit(raw)
        np.testing.assert_array_equal(back[..., 2], grey)
    c16 = bgr.astype(np.uint16) << 8
    np.testing.assert_array_equal(to_8bit(decode_image(_Msg(**_image_fields(c16, "bgr16"))))[0],
                                  bgr)  # fmt: skip
    # UYVY and YUY2 of the same grey image agree, and give its grey levels back through
    # BT.601's video range (luma 16..235 is black..white)
    a = decode_image(_Msg(**_image_fields(grey, "yuv422")))
    b = decode_image(_Msg(**_image_fields(grey, "yuv422_yuy2")))
    np.testing.assert_array_equal(a, b)
    full = np.clip((grey.astype(float) - 16) * 255 / 219, 0, 255)
    assert np.abs(a[..., 1] - full).max() <= 1.0


@pytest.mark.parametrize("pattern", ["rggb", "bggr", "gbrg", "grbg"])
def test_bayer_patterns_keep_red_and_blue(cones: Any, pattern: str) -> None:
    smooth = cv2.GaussianBlur(cones.left, (0, 0), 2.0)
    out = decode_image(_Msg(**_image_fields(smooth, f"bayer_{pattern}8")))
    err = np.abs(out.astype(int) - smooth).mean()
    swapped = np.abs(out[..., ::-1].astype(int) - smooth).mean()
    assert err < 2.0, (pattern, err)  # demosaicing error on a smooth image
    assert swapped > 3 * err, (pattern, err, swapped)  # red and blue not exchanged


@pytest.mark.parametrize("encoding", ["bayer_rggb8", "bayer_gbrg8", "bayer_grbg16"])
def test_a_compressed_bayer_image_is_demosaiced(cones: Any, encoding: str) -> None:
    """image_transport compresses a Bayer image as its mosaic, in a grey PNG or JPEG, with
    the format ``"bayer_rggb8; png compressed "``: it came out grey with the mosaic's
    checkerboard. Now as the raw topic's message decodes (red and blue in place)."""
    smooth = cv2.GaussianBlur(cones.left, (0, 0), 2.0)
    if encoding.endswith("16"):
        smooth = smooth.astype(np.uint16) << 4  # 12-bit data in 16 bits
    raw = _image_fields(smooth, encoding)
    mosaic = raw["data"].view("<u2" if encoding.endswith("16") else np.uint8)
    _ok, png = cv2.imencode(".png", mosaic.reshape(raw["height"], raw["width"]))
    out = decode_image(_Msg(format=f"{encoding}; png compressed ", data=png.reshape(-1)))
    np.testing.assert_array_equal(out, decode_image(_Msg(**raw)))
    scale = 16 if encoding.endswith("16") else 1
    assert np.abs(out.astype(int) - smooth).mean() < 2.0 * scale  # demosaiced, not grey


def test_compressed_images(cones: Any) -> None:
    _, png = cv2.imencode(".png", cones.left)
    out = decode_image(_Msg(format="bgr8; png compressed bgr8", data=png.reshape(-1)))
    np.testing.assert_array_equal(out, cones.left)
    _ok, jpg = cv2.imencode(".jpg", cv2.cvtColor(cones.left, cv2.COLOR_BGR2GRAY))
    assert decode_image(_Msg(format="mono8; jpeg compressed mono8", data=jpg.reshape(-1))).shape \
        == cones.left.shape  # fmt: skip
    # only a one-channel encoding's conversion (a Bayer pattern's) is applied to a grey
    # picture: one a colour format names (rgb8, yuv422) is grey, not cv2.cvtColor's error
    grey = cv2.imdecode(jpg, cv2.IMREAD_GRAYSCALE)
    for fmt in ("rgb8; jpeg compressed bgr8", "yuv422; jpeg compressed bgr8"):
        out = decode_image(_Msg(format=fmt, data=jpg.reshape(-1)))
        np.testing.assert_array_equal(out, cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR))
    with pytest.raises(ValueError, match="depth image"):
        decode_image(_Msg(format="16UC1; compressedDepth png", data=png.reshape(-1)))
    with pytest.raises(ValueError, match="does not decode"):
        decode_image(_Msg(format="jpeg", data=np.zeros(50, np.uint8)))


def test_messages_holding_their_data_as_bytes_decode() -> None:
    # rospy's messages hold uint8[] as bytes: np.asarray read them as one number ("invalid
    # literal for int()", the whole image quoted)
    small = np.random.default_rng(3).integers(0, 256, (6, 8, 3), dtype=np.uint8)
    f = _image_fields(small, "bgr8", pad=3)
    out = decode_image(_Msg(**{**f, "data": f["data"].tobytes()}))
    np.testing.assert_array_equal(out, small)
    assert out.flags.writeable
    g16 = small[..., 1].astype(np.uint16) << 4
    f16 = _image_fields(g16, "mono16", big=True)
    out16 = decode_image(_Msg(**{**f16, "data": bytearray(f16["data"].tobytes())}))
    np.testing.assert_array_equal(out16[..., 0], g16)
    _ok, png = cv2.imencode(".png", small)
    out_png = decode_image(_Msg(format="bgr8; png compressed bgr8", data=png.tobytes()))
    np.testing.assert_array_equal(out_png, small)
    # rosbags' data is a read-only view of the message: a bgr8 frame (no conversion, no
    # padding) was that view, and cv2.putText on a bag's frame raised where a camera's is drawn
    f0 = _image_fields(small, "bgr8")
    held = np.frombuffer(f0["data"].tobytes(), np.uint8)
    out_view = decode_image(_Msg(**{**f0, "data": held}))
    np.testing.assert_array_equal(out_view, small)
    assert out_view.flags.writeable and not held.flags.writeable


def test_bad_image_messages(cones: Any) -> None:
    f = _image_fields(cones.left, "bgr8")
    with pytest.raises(ValueError, match="'32FC1' is not a camera image"):
        decode_image(_Msg(**{**f, "encoding": "32FC1"}))
    with pytest.raises(ValueError, match="step 100 and"):
        decode_image(_Msg(**{**f, "step": 100}))
    with pytest.raises(ValueError, match="data bytes do not hold it"):
        decode_image(_Msg(**{**f, "data": f["data"][:-1]}))
    # 4:2:2 of an odd width (two pixels share a chroma pair): OpenCV's cv2.error escaped
    odd = _image_fields(cones.left[:, :-1], "yuv422")
    assert odd["width"] % 2 == 1
    for enc in ("yuv422", "yuv422_yuy2"):
        with pytest.raises(
            ValueError, match=f"{enc} image of 449x375 px: 4:2:2 data needs an even"
        ):
            decode_image(_Msg(**{**odd, "encoding": enc}))


# --------------------------------------------------------------------------------- topics


def test_topic_discovery() -> None:
    assert find_stereo_topics(["/cam0/image_raw", "/cam1/image_raw", "/imu"]) == (
        "/cam0/image_raw", "/cam1/image_raw")  # fmt: skip
    assert find_stereo_topics(["/camera/infra2/image_rect_raw", "/camera/infra1/image_rect_raw",
                               "/camera/color/image_raw"]) == (
        "/camera/infra1/image_rect_raw", "/camera/infra2/image_rect_raw")  # fmt: skip
    both = [LEFT, RIGHT, "/stereo/left/image_rect", "/stereo/right/image_rect",
            LEFT + "/compressed", RIGHT + "/compressed"]  # fmt: skip
    assert find_stereo_topics(both) == (LEFT, RIGHT)  # raw and uncompressed preferred
    rect = ["/zed/Left/image_rect_color", "/zed/Right/image_rect_color"]
    assert find_stereo_topics(rect) == tuple(rect)
    with pytest.raises(ValueError, match=r"no left/right pair .*\(/a/image, /b/image\)"):
        find_stereo_topics(["/a/image", "/b/image"])
    with pytest.raises(ValueError, match="several stereo pairs"):
        find_stereo_topics(["/cam0/image_raw", "/cam1/image_raw", "/cam2/image_raw"])
    with pytest.raises(ValueError, match="none"):
        find_stereo_topics([])
    # names of another depth are no pair, whatever their one differing part
    with pytest.raises(ValueError, match="no left/right pair"):
        find_stereo_topics(["/stereo/left/image", "/stereo/right/image/theora"])


def test_holding_reads_only_the_topics_asked_until_each_shows_a_message() -> None:
    """``_holding`` (the check of an index's zero count on the messages) asks the reader for
    the topics asked alone, stops at the first message of the last of them (a topic with
    messages costs a few, not a pass over the bag) and closes the messages it opened."""
    from types import SimpleNamespace

    from stereovision.rosbag import _holding

    conns = [SimpleNamespace(topic=t) for t in ("/a", "/b", "/c")]

    class _Reader:
        connections = conns

        def __init__(self) -> None:
            self.asked: list[str] = []
            self.read = 0
            self.closed = False

        def messages(self, connections: list[Any]) -> Any:
            self.asked = [c.topic for c in connections]
            order = ["/a", "/a", "/b", "/c", "/a", "/b"]  # in time order, as the bag holds them
            reader = self

            class _Messages:  # rosbags' generator, whose close() ends its read of the bag
                def __init__(self) -> None:
                    self.left = [
                        c for t in order if t in reader.asked for c in conns if c.topic == t
                    ]

                def __iter__(self) -> Any:
                    return self

                def __next__(self) -> tuple[Any, int, bytes]:
                    if not self.left:
                        raise StopIteration
                    reader.read += 1
                    return self.left.pop(0), 0, b""

                def close(self) -> None:
                    reader.closed = True

            return _Messages()

    reader = _Reader()
    assert _holding(reader, {"/a", "/b"}) == {"/a", "/b"}
    assert reader.asked == ["/a", "/b"] and reader.read == 3 and reader.closed
    reader = _Reader()
    assert _holding(reader, {"/c", "/x"}) == {"/c"}  # /x: no connection, no message
    assert reader.asked == ["/c"] and reader.closed
    assert _holding(_Reader(), {"/x"}) == set()


# ------------------------------------------------------------------------------- the bags


def _info_fields(cam: dict, ros1: bool, binning: int | tuple[int, int] = 0) -> dict:
    names = ("D", "K", "R", "P") if ros1 else ("d", "k", "r", "p")
    bx, by = binning if isinstance(binning, tuple) else (binning, binning)
    return {
        "height": cam["image_size"][1], "width": cam["image_size"][0],
        "distortion_model": cam["distortion_model"],
        names[0]: cam["D"], names[1]: cam["K"].ravel(), names[2]: cam["R"].ravel(),
        names[3]: cam["P"].ravel(), "binning_x": bx, "binning_y": by,
    }  # fmt: skip


def write_bag(
    path: Path,
    frames: list[tuple[int | None, np.ndarray, int | None, np.ndarray]],
    *,
    flavour: str = "ros2",
    encoding: str = "bgr8",
    topics: tuple[str, str] = (LEFT, RIGHT),
    infos: tuple[dict, dict] | None = None,
    binning: int | tuple[int, int] | list[tuple[int, int]] = 0,
    roi: tuple[int, int, int, int] = (0, 0, 0, 0),
    empty: tuple[str, ...] = (),
) -> Path:
    """A bag of ``(stamp_left, left, stamp_right, right)`` frames (a None stamp: not recorded),
    each message recorded 2 ms after its stamp, in recording order; ``infos``: the two cameras'
    parsed camera_info, published beside the image topics once per left frame, with
    ``binning`` (both axes, or ``(x, y)``; a list: ``[left's, right's]``) and ``roi``
    ``(x_offset, y_offset, width, height)``; ``empty``: image topics recorded without a
    message (a publisher that never published)."""
    ros1 = flavour == "ros1"
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    t = ts.types
    msgs: list[tuple[int, str, str, Any]] = []
    for sl, left, sr, right in frames:
        for topic, stamp, img in ((topics[0], sl, left), (topics[1], sr, right)):
            if stamp is None:
                continue
            time = t["builtin_interfaces/msg/Time"](sec=stamp // 10**9, nanosec=stamp % 10**9)
            hdr = {"stamp": time, "frame_id": "cam"} | ({"seq": 0} if ros1 else {})
            header = t["std_msgs/msg/Header"](**hdr)
            if encoding == "png":
                _ok, buf = cv2.imencode(".png", img)
                msg = t["sensor_msgs/msg/CompressedImage"](header=header, format="bgr8; png",
                                                           data=buf.reshape(-1))  # fmt: skip
                msgs.append((stamp + 2_000_000, topic, "sensor_msgs/msg/CompressedImage", msg))
            else:
                msg = t["sensor_msgs/msg/Image"](header=header, **_image_fields(img, encoding))
                msgs.append((stamp + 2_000_000, topic, "sensor_msgs/msg/Image", msg))
            if infos is not None:
                cam = infos[0] if topic == topics[0] else infos[1]
                side = 0 if topic == topics[0] else 1
                bins = binning[side] if isinstance(binning, list) else binning
                box = t["sensor_msgs/msg/RegionOfInterest"](
                    x_offset=roi[0], y_offset=roi[1], width=roi[2], height=roi[3],
                    do_rectify=False)  # fmt: skip
                info = t["sensor_msgs/msg/CameraInfo"](
                    header=header, roi=box, **_info_fields(cam, ros1, bins))  # fmt: skip
                info_topic = topic.rsplit("/", 1)[0] + "/camera_info"
                msgs.append((stamp + 2_000_001, info_topic, "sensor_msgs/msg/CameraInfo", info))
    msgs.sort(key=lambda m: m[0])
    if ros1:
        from rosbags.rosbag1 import Writer as W1

        writer: Any = W1(path)
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        plugin = StoragePlugin.MCAP if flavour == "mcap" else StoragePlugin.SQLITE3
        writer = Writer(path, version=9, storage_plugin=plugin)
    conns: dict[str, Any] = {}
    with writer:
        for topic in empty:
            conns[topic] = writer.add_connection(topic, "sensor_msgs/msg/Image", typestore=ts)
        for recorded, topic, msgtype, msg in msgs:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=ts)
            data = ts.serialize_ros1(msg, msgtype) if ros1 else ts.serialize_cdr(msg, msgtype)
            writer.write(conns[topic], recorded, data)
    return path


def _jittered(cones: Any, n: int) -> tuple[list, list[int]]:
    """``n`` distinct frames (the cones pair rolled by k px), the right stamps off by -4..+4 ms;
    right frame 5 and left frame 9 not recorded."""
    jitter = [((k * 7) % 9 - 4) * 1_000_000 for k in range(n)]
    frames = []
    for k in range(n):
        sl = None if k == 9 else T0 + k * PERIOD_NS
        sr = None if k == 5 else T0 + k * PERIOD_NS + jitter[k]
        frames.append((sl, np.roll(cones.left, k, axis=1), sr, np.roll(cones.right, k, axis=1)))
    return frames, jitter


@pytest.mark.parametrize("flavour", ["ros2", "mcap", "ros1"])
def test_pairs_are_matched_on_their_stamps(cones: Any, tmp_path: Path, flavour: str) -> None:
    frames, jitter = _jittered(cones, 14)
    bag = write_bag(tmp_path / ("rig.bag" if flavour == "ros1" else "rig"), frames,
                    flavour=flavour)  # fmt: skip
    with BagCamera(bag) as cam:
        assert cam.topics == {"left": LEFT, "right": RIGHT}
        got = list(cam.frames())
        assert cam.max_skew_ms == pytest.approx(PERIOD_NS / 2e6, rel=0.1)  # half of 33 ms
        assert cam.dropped == {"left": 1, "right": 1}  # left 5 and right 9 had no partner
        assert "bag " in cam.describe() and f"{LEFT}: 450x375" in cam.describe()
    assert got[0].left.flags.writeable and got[0].right.flags.writeable  # as a camera's
    kept = [k for k in range(14) if k not in (5, 9)]
    assert [round((f.t_left * 1e9 - T0) / PERIOD_NS) for f in got] == kept
    for f, k in zip(got, kept, strict=True):
        np.testing.assert_array_equal(f.left, frames[k][1])
        np.testing.assert_array_equal(f.right, frames[k][3])
        assert f.skew_ms == pytest.approx(abs(jitter[k]) / 1e6, abs=1e-3)
    assert cam.stamps_ns == [T0 + k * PERIOD_NS for k in kept]
    with pytest.raises(SourceError, match="closed"):
        cam.read()


def test_a_bag_without_message_definitions(cones: Any, tmp_path: Path) -> None:
    """ROS 2 bags recorded before Iron (Humble's) hold no message definitions: read with
    Humble's."""
    import sqlite3

    bag = write_bag(tmp_path / "humble", [(T0, cones.left, T0, cones.right)])
    db = sqlite3.connect(next(bag.glob("*.db3")))
    db.execute("DELETE FROM message_definitions")
    db.commit()
    db.close()
    with BagCamera(bag) as cam:
        frame = cam.read()
    np.testing.assert_array_equal(frame.left, cones.left)


def test_a_ros1_recording_split_in_files(cones: Any, tmp_path: Path) -> None:
    """``rosbag record --split``: a folder of .bag files read as one recording, in order."""
    frames, _ = _jittered(cones, 14)
    (tmp_path / "run").mkdir()
    write_bag(tmp_path / "run" / "run_0.bag", frames[:7], flavour="ros1")
    write_bag(tmp_path / "run" / "run_1.bag", frames[7:], flavour="ros1")
    from stereovision.rosbag import is_bag

    assert is_bag(tmp_path / "run") and not is_bag(tmp_path)
    with BagCamera(tmp_path / "run") as cam:
        got = list(cam.frames())
    kept = [k for k in range(14) if k not in (5, 9)]
    assert cam.stamps_ns == [T0 + k * PERIOD_NS for k in kept]
    np.testing.assert_array_equal(got[-1].right, frames[13][3])


def test_max_skew_and_end_of_recording(cones: Any, tmp_path: Path) -> None:
    frames, jitter = _jittered(cones, 14)
    bag = write_bag(tmp_path / "rig", frames)
    with BagCamera(bag, max_skew_ms=2.5) as cam:
        got = list(cam.frames())
        with pytest.raises(SourceError, match=r"end of the recording after \d+ pairs"):
            cam.read()
    # only frames within 2.5 ms pair; the others are dropped on both sides
    want = [k for k in range(14) if k not in (5, 9) and abs(jitter[k]) <= 2_500_000]
    assert [f.index for f in got] == list(range(len(want)))
    # a Fraction is its number (it was "expected a number >= 0, got Fraction(5, 2)")
    from fractions import Fraction

    with BagCamera(bag, max_skew_ms=Fraction(5, 2)) as cam:
        assert [f.index for f in cam.frames()] == list(range(len(want)))
    assert cam.stamps_ns == [T0 + k * PERIOD_NS for k in want]
    assert cam.dropped == {"left": 13 - len(want), "right": 13 - len(want)}


def test_mono16_pairs_share_one_shift_and_resize(cones: Any, tmp_path: Path) -> None:
    # a dim 12-bit left image and a bright right one: one scale for both (the matchers compare them)
    gl = cv2.cvtColor(cones.left, cv2.COLOR_BGR2GRAY).astype(np.uint16) << 2
    gr = cv2.cvtColor(cones.right, cv2.COLOR_BGR2GRAY).astype(np.uint16) << 4
    bag = write_bag(tmp_path / "rig", [(T0, gl, T0, gr)], encoding="mono16")
    with BagCamera(bag) as cam:
        f = cam.read()
    np.testing.assert_array_equal(f.left[..., 0], (gl >> 4).astype(np.uint8))
    np.testing.assert_array_equal(f.right[..., 0], (gr >> 4).astype(np.uint8))
    with BagCamera(bag, image_size="225x188") as cam:
        assert cam.read().left.shape == (188, 225, 3)


def test_a_16_bit_glint_does_not_halve_the_grey_levels_of_its_pair(tmp_path: Path) -> None:
    """Each pair had its own shift to 8 bits: the same 11-bit scene read 172, 86, 172 at one
    pixel over three pairs, the middle one with a single glint at 4095. The shift is now the
    largest a pair has needed so far: 172, 86, 86."""
    g = np.random.default_rng(0).integers(100, 2000, (60, 80)).astype(np.uint16)
    glint = g.copy()
    glint[0, 0] = 4095
    frames = [
        (T0 + i * PERIOD_NS, im, T0 + i * PERIOD_NS, im) for i, im in enumerate([g, glint, g])
    ]
    with BagCamera(write_bag(tmp_path / "rig", frames, encoding="mono16")) as cam:
        lefts = [cam.read().left[..., 0] for _ in range(3)]
    np.testing.assert_array_equal(lefts[0], (g >> 3).astype(np.uint8))
    np.testing.assert_array_equal(lefts[1], (glint >> 4).astype(np.uint8))
    np.testing.assert_array_equal(lefts[2], (g >> 4).astype(np.uint8))


def test_calibration_from_camera_info(cones: Any, tmp_path: Path) -> None:
    raw = _raw_rig()
    texts = raw.to_ros()
    cams = tuple(parse_ros_camera_info(t) for t in texts)
    frames = [(T0, cones.left, T0, cones.right)]
    (tmp_path / "yaml").mkdir()
    for name, text in zip(("left.yaml", "right.yaml"), texts, strict=True):
        (tmp_path / "yaml" / name).write_text(text)
    want = Calibration.from_file(tmp_path / "yaml")
    for flavour in ("ros2", "ros1"):
        (tmp_path / flavour).mkdir()
        name = "rig.bag" if flavour == "ros1" else "rig"
        bag = write_bag(tmp_path / flavour / name, frames, flavour=flavour, infos=cams)
        if flavour == "ros2":  # a file of the bag folder names the bag too
            bag = bag / "metadata.yaml"
        with BagCamera(bag) as cam:
            assert cam.info_topics == {"left": "/stereo/left/camera_info",
                                       "right": "/stereo/right/camera_info"}  # fmt: skip
            got = cam.calibration()
        assert got == want and not got.rectified
        np.testing.assert_allclose(got.T, raw.T, atol=1e-9)  # the rig comes back
        np.testing.assert_allclose(got.R, raw.R, atol=1e-9)
        np.testing.assert_allclose(got.K1, raw.K1) and np.testing.assert_allclose(got.D2, raw.D2)
    # rectified topics: the rectified rig of the two P matrices
    rect = ("/stereo/left/image_rect", "/stereo/right/image_rect")
    bag = write_bag(tmp_path / "rect", frames, topics=rect, infos=cams)
    with BagCamera(bag) as cam:
        got = cam.calibration()
    assert got.rectified
    np.testing.assert_allclose(got.K1, cams[0]["P"][:, :3])
    assert got.baseline_m == pytest.approx(-cams[1]["P"][0, 3] / cams[1]["P"][0, 0])
    # binned 2x2: the calibration of the half-size images
    bag = write_bag(tmp_path / "binned", frames, infos=cams, binning=2)
    with BagCamera(bag) as cam:
        got = cam.calibration()
    assert got.image_size == (225, 187)
    np.testing.assert_allclose(got.K1[0, 0], raw.K1[0, 0] * 225 / 450)
    # no camera_info: None
    with BagCamera(write_bag(tmp_path / "bare", frames)) as cam:
        assert cam.info_topics == {"left": None, "right": None} and cam.calibration() is None


def test_bag_errors(cones: Any, tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="bag not found"):
        BagCamera(tmp_path / "missing")
    (tmp_path / "notabag").mkdir()
    with pytest.raises(ValueError, match="not a readable ROS 1 or ROS 2 bag"):
        BagCamera(tmp_path / "notabag")
    (tmp_path / "text.bag").write_text("hello")
    with pytest.raises(ValueError, match="not a readable"):
        BagCamera(tmp_path / "text.bag")
    bag = write_bag(tmp_path / "rig", [(T0, cones.left, T0, cones.right)], encoding="png")
    with pytest.raises(ValueError, match=r"left topic '/x' is not an image topic .* "
                                         r"\(its image topics: /stereo/left"):  # fmt: skip
        BagCamera(bag, left_topic="/x", right_topic=RIGHT)
    with pytest.raises(ValueError, match="both the left and the right topic"):
        BagCamera(bag, left_topic=LEFT)
    with pytest.raises(ValueError, match="max_skew_ms"):
        BagCamera(bag, max_skew_ms=-1.0)
    with pytest.raises(ValueError, match="the same"):
        BagCamera(bag, left_topic=LEFT, right_topic=LEFT)
    with BagCamera(bag) as cam:  # compressed frames read
        np.testing.assert_array_equal(cam.read().left, cones.left)
    bad = write_bag(tmp_path / "float", [(T0, cones.left, T0, cones.right)], encoding="bgr8")
    # a depth stream recorded under an image name: refused at read, topic named
    from rosbags.rosbag2 import Reader, Writer

    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(bad) as r, Writer(tmp_path / "f32", version=9) as w:
        conns = {}
        for conn, stamp, raw in r.messages():
            msg = ts.deserialize_cdr(raw, conn.msgtype)
            if conn.topic == RIGHT:
                msg.encoding = "32FC1"
            conns.setdefault(conn.topic, w.add_connection(conn.topic, conn.msgtype, typestore=ts))
            w.write(conns[conn.topic], stamp, ts.serialize_cdr(msg, conn.msgtype))
    with (
        BagCamera(tmp_path / "f32") as cam,
        pytest.raises(ValueError, match=rf"{RIGHT} at stamp {T0} ns: image encoding '32FC1'"),
    ):
        cam.read()


def test_a_topic_given_that_is_no_image_topic_is_said_with_the_nearest_or_its_type(
    tmp_path: Path,
) -> None:
    """A name without its leading '/' or mistyped was refused with the bag's image topics
    alone, to be compared by eye: the nearest is suggested; a topic of another type (the
    camera_info given for the image) says its type."""
    cam = {"image_size": (6, 4), "distortion_model": "plumb_bob", "D": np.zeros(5),
           "K": np.eye(3), "R": np.eye(3), "P": np.eye(3, 4)}  # fmt: skip
    tiny = np.zeros((4, 6, 3), np.uint8)
    bag = write_bag(tmp_path / "rig.bag", [(T0, tiny, T0, tiny)], flavour="ros1", infos=(cam, cam))
    with pytest.raises(ValueError) as err:
        BagCamera(bag, left_topic=LEFT[1:], right_topic=RIGHT)
    assert str(err.value) == (
        f"left topic {LEFT[1:]!r} is not an image topic of {bag}; did you mean {LEFT!r}? "
        f"(its image topics: {LEFT}, {RIGHT})"
    )
    with pytest.raises(ValueError) as err:
        BagCamera(bag, left_topic=LEFT, right_topic="/stereo/right/camera_info")
    assert str(err.value) == (
        f"right topic '/stereo/right/camera_info' is not an image topic of {bag}: it holds "
        f"sensor_msgs/msg/CameraInfo, not sensor_msgs/Image or CompressedImage (its image "
        f"topics: {LEFT}, {RIGHT})"
    )
    from stereovision.rosbag import _topic_hint

    images = [LEFT, RIGHT]
    assert _topic_hint("/stereo/left/imag_raw", images, {}) == f"; did you mean {LEFT!r}?"
    assert _topic_hint(RIGHT + "/compressed", images, {}) == f"; did you mean {RIGHT!r}?"
    assert _topic_hint("/x", images, {}) == ""  # nothing near: no guess


def test_a_bag_link_whose_target_moved_names_it(tmp_path: Path) -> None:
    """A bag linked in from a disk since unmounted (run.bag -> moved/run.bag) was "bag not
    found: run.bag", of a name ls lists (stream --from-bag said it alike), where the file
    readers name the link's target (b7feb4e7); a loop of links alike. A missing bag as before."""
    (tmp_path / "run.bag").symlink_to(tmp_path / "moved" / "run.bag")
    (tmp_path / "loop.bag").symlink_to(tmp_path / "loop.bag")
    with pytest.raises(FileNotFoundError) as err:
        BagCamera(tmp_path / "run.bag")
    assert str(err.value) == (
        f"bag not found: {tmp_path / 'run.bag'} (a link to {tmp_path / 'moved' / 'run.bag'}, "
        "which does not exist)"
    )
    with pytest.raises(FileNotFoundError, match=r"loop.bag \(a link to .*loop.bag, one of a loop"):
        BagCamera(tmp_path / "loop.bag")
    with pytest.raises(FileNotFoundError) as err:
        BagCamera(tmp_path / "missing.bag")
    assert str(err.value) == f"bag not found: {tmp_path / 'missing.bag'}"


def test_bag_topics_of_a_missing_bag_says_not_found(tmp_path: Path) -> None:
    """bag_topics of a missing bag was a ValueError in rosbags' words: "missing.bag is not a
    readable ROS 1 or ROS 2 bag: The following paths are missing: [PosixPath(...)]", and of
    a link whose target moved said nothing of it; both are BagCamera's FileNotFoundError."""
    from stereovision.rosbag import bag_topics

    (tmp_path / "run.bag").symlink_to(tmp_path / "moved" / "run.bag")
    with pytest.raises(FileNotFoundError) as err:
        bag_topics(tmp_path / "run.bag")
    assert str(err.value) == (
        f"bag not found: {tmp_path / 'run.bag'} (a link to {tmp_path / 'moved' / 'run.bag'}, "
        "which does not exist)"
    )
    with pytest.raises(FileNotFoundError) as err:
        bag_topics(tmp_path / "missing.bag")
    assert str(err.value) == f"bag not found: {tmp_path / 'missing.bag'}"


# ------------------------------------------------------------------------------------ CLI


@pytest.fixture()
def run(capsys: pytest.CaptureFixture[str]) -> Callable[..., tuple[int, str, str]]:
    from stereovision.cli import main

    def go(*argv: str) -> tuple[int, str, str]:
        code = main(list(argv))
        out = capsys.readouterr()
        return code, out.out, out.err

    return go


@PIPELINED
def test_cli_stream_from_bag_keeps_stamps_and_calibration(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    k = np.array([[430.0, 0, 224.5], [0, 430.0, 187.0], [0, 0, 1]])
    rect = Calibration(K1=k, D1=np.zeros(5), K2=k, D2=np.zeros(5), R=np.eye(3),
                       T=np.array([-0.16, 0, 0]), image_size=(450, 375), unit="m",
                       rectified=True)  # fmt: skip
    cams = tuple(parse_ros_camera_info(t) for t in rect.to_ros())
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + k * PERIOD_NS + 1_000_000, cones.right)
              for k in range(3)]  # fmt: skip
    bag = write_bag(tmp_path / "rig", frames, infos=cams)
    code, out, err = run("stream", "--from-bag", str(bag), "--no-display", "--json",
                         "--method", "gabor", "--max-disparity", "64", "--no-check",
                         "--bag", str(tmp_path / "out"))  # fmt: skip
    assert code == 0, err
    assert "calibration: the bag's /stereo/left/camera_info and /stereo/right/camera_info" in err
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["frames"] == 3 and summary["skew_ms"]["mean"] == pytest.approx(1.0)
    from rosbags.rosbag2 import Reader

    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(tmp_path / "out") as r:
        depth = [(s, ts.deserialize_cdr(raw, c.msgtype)) for c, s, raw in r.messages()
                 if c.topic == "/stereo/depth"]  # fmt: skip
    assert [s for s, _ in depth] == [T0 + k * PERIOD_NS for k in range(3)]  # the frames' stamps
    want = sv.depth_map(cones.left, cones.right, rect, method="gabor", max_disparity=64,
                        cloud=False, refine=False)  # stream's defaults  # fmt: skip
    d = np.frombuffer(depth[0][1].data.tobytes(), "<f4").reshape(want.depth.shape)
    np.testing.assert_array_equal(d, want.depth.astype(np.float32))


@SLOW_PIPELINED
def test_cli_stream_from_a_kitti_bag_with_floor_scans(
    data_dir: Path, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """``stream --from-bag ... --ground-every 1 --bag OUT``: each frame's obstacles as a
    LaserScan on the floor fitted to it, the same as ``laser_scan`` on that frame's map."""
    from stereovision.ground import fit_ground_plane, laser_scan

    sc = load_scene(data_dir / "kitti2015" / "000005_10")
    cams = tuple(parse_ros_camera_info(t) for t in sc.calib.to_ros())
    frames = [(T0 + k * PERIOD_NS, sc.left, T0 + k * PERIOD_NS, sc.right) for k in range(2)]
    bag = write_bag(tmp_path / "kitti", frames, infos=cams)
    code, _out, err = run("stream", "--from-bag", str(bag), "--no-display", "--method", "gabor",
                         "--max-disparity", "112", "--no-check", "--ground-every", "1",
                         "--bag", str(tmp_path / "out"))  # fmt: skip
    assert code == 0, err
    from rosbags.rosbag2 import Reader

    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(tmp_path / "out") as r:
        scans = [(s, ts.deserialize_cdr(raw, c.msgtype)) for c, s, raw in r.messages()
                 if c.topic == "/stereo/scan"]  # fmt: skip
    assert [s for s, _ in scans] == [T0, T0 + PERIOD_NS]
    with BagCamera(bag) as cam:
        rc = cam.calibration()
    assert rc.rectified and rc.baseline_m == pytest.approx(sc.calib.baseline_m)
    want = sv.depth_map(sc.left, sc.right, rc, method="gabor", max_disparity=112, cloud=False,
                        refine=False)  # fmt: skip
    plane = fit_ground_plane(want.disparity, rc)
    assert plane is not None
    # the stream scans the result's point image (its depth, as the cloud), not a reprojection of
    # the clipped disparity: one ulp apart, enough to move a point across the obstacle height
    expected = laser_scan(want.point_image(filled=True), plane, rc)
    msg = scans[0][1]
    assert msg.header.frame_id == "base_footprint"
    np.testing.assert_array_equal(msg.ranges, expected.ranges)
    assert np.isfinite(msg.ranges).sum() > 500


def _memo(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` (an OpenCV corner finder: a pure function of the image and its arguments) with its
    results kept by the image's bytes, handed out as copies (``cornerSubPix`` refines in place)."""
    kept: dict[bytes, Any] = {}

    def memo(image: np.ndarray, *args: Any, **kwargs: Any) -> Any:
        key = repr((image.shape, image.dtype.str, args, sorted(kwargs.items()))).encode()
        key += np.ascontiguousarray(image).tobytes()
        if key not in kept:
            kept[key] = fn(image, *args, **kwargs)
        ok, corners = kept[key]
        return ok, None if corners is None else corners.copy()

    return memo


def test_cli_capture_and_calibrate_from_bag(
    data_dir: Path,
    tmp_path: Path,
    run: Callable[..., tuple[int, str, str]],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """OpenCV's chessboard pairs recorded as a ROS 1 bag of mono8 frames on EuRoC-style topics;
    ``capture --chessboard`` takes the board poses out of it, ``calibrate --from-bag`` the rig.
    The three runs look for the board in the same images: OpenCV's corner finders keep their
    results by image (the same corners, found once)."""
    for name in ("findChessboardCornersSB", "findChessboardCorners"):
        monkeypatch.setattr(cv2, name, _memo(getattr(cv2, name)))
    cb = data_dir / "chessboard"
    names = sorted(p.name[4:] for p in cb.glob("left*.jpg"))
    frames = []
    for k, name in enumerate(names):
        left = cv2.imread(str(cb / f"left{name}"))
        right = cv2.imread(str(cb / f"right{name}"))
        frames.append((T0 + k * 10**9, left, T0 + k * 10**9, right))
    bag = write_bag(tmp_path / "board.bag", frames, flavour="ros1", encoding="mono8",
                    topics=("/cam0/image_raw", "/cam1/image_raw"))  # fmt: skip
    code, out, err = run("capture", "--from-bag", str(bag), "--chessboard", "9x6",
                         "-o", str(tmp_path / "pairs"))  # fmt: skip
    assert code == 0, err
    saved = sorted((tmp_path / "pairs").glob("left_*.png"))
    assert f"{len(saved)} pairs saved" in out and f"{len(names)} pairs read" in out
    assert len(saved) >= 6  # distinct poses only (ROS's rule)
    for (
        path
    ) in saved:  # every saved pair is a recorded pair, pixel for pixel (mono8 of a grey JPEG)
        left = cv2.imread(str(path))
        right = cv2.imread(str(path).replace("left_", "right_"))
        assert any(np.array_equal(left, f[1]) and np.array_equal(right, f[3]) for f in frames)
    # calibrate straight from the bag: the same poses kept, the rig of the JPEG pairs
    code, out, err = run("calibrate", "--from-bag", str(bag), "--pattern", "9x6",
                         "--square", "0.025", "-o", str(tmp_path / "bag.yaml"))  # fmt: skip
    assert code == 0, err
    assert f"{len(saved)} of {len(names)} frame pairs kept" in out
    code, out, err = run("calibrate", "--left", str(cb / "left*.jpg"), "--right",
                         str(cb / "right*.jpg"), "--pattern", "9x6", "--square", "0.025",
                         "-o", str(tmp_path / "jpg.yaml"))  # fmt: skip
    assert code == 0, err
    got = Calibration.from_file(tmp_path / "bag.yaml")
    want = Calibration.from_file(tmp_path / "jpg.yaml")
    assert got.baseline_m == pytest.approx(want.baseline_m, rel=0.005)  # 83.26 vs 83.18 mm
    assert got.focal_px == pytest.approx(want.focal_px, rel=0.005)
    for argv, msg in [
        (("--from-bag", str(bag), "--left", "x.png"), "replaces --left"),
        (("--left-topic", "/a", "--left", "x.png", "--right", "y.png"), "are for --from-bag"),
        ((), "give the board's pairs (--left and --right) or a recording"),
    ]:  # fmt: skip
        code, out, err = run("calibrate", *argv, "--square", "1", "-o", str(tmp_path / "x.yaml"))
        assert code != 0 and msg in err and "Traceback" not in err, err


class _Terminal(io.StringIO):
    """A stderr that says it is a terminal (the calibrate CLI draws its bars on one only)."""

    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("count_known", [True, False])
def test_calibrating_from_a_bag_gives_the_frames_bar_its_total(
    cones: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, count_known: bool
) -> None:
    """`calibrate --from-bag`'s bar over the frames read had no total (tqdm's total None: a
    count without an end) though the bag's index holds each topic's messages; its total is
    now the fewer of the two topics' messages (6 left, 5 right: at most 5 pairs). A bag whose
    index says no count (metadata.yaml's message_count 0) is still read, its bar without a
    total as before."""
    import re

    from stereovision.calibrate import PROGRESS_FRAMES, _ProgressBars, calibrate_from_bag

    frames = [
        (T0 + k * PERIOD_NS, np.roll(cones.left, k, axis=1),
         None if k == 3 else T0 + k * PERIOD_NS, np.roll(cones.right, k, axis=1))
        for k in range(6)
    ]  # fmt: skip
    bag = write_bag(tmp_path / "rig", frames)
    if not count_known:
        meta = bag / "metadata.yaml"
        meta.write_text(re.sub(r"message_count: \d+", "message_count: 0", meta.read_text()))
    monkeypatch.setattr("sys.stderr", _Terminal())
    bars = _ProgressBars()
    seen: list[tuple[int, float | None]] = []

    def progress(stage: str, done: int, total: int) -> None:
        bars(stage, done, total)
        if stage == PROGRESS_FRAMES:
            seen.append((bars.bar.n, bars.bar.total))

    # no board in the cones: every pair is read, then the calibration is refused
    with pytest.raises(ValueError, match="no frame pair of the 5 read shows the chessboard"):
        calibrate_from_bag(
            bag, left_topic=LEFT, right_topic=RIGHT, pattern=(9, 6), square_size=1.0,
            progress=progress,
        )  # fmt: skip
    bars.close()
    assert seen == [(n, 5 if count_known else None) for n in range(1, 6)]


def test_cli_source_errors(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    bag = write_bag(tmp_path / "rig", [(T0, cones.left, T0, cones.right)])
    # a recording without the board: said in those words (it was "no image pairs given")
    code, _, err = run("calibrate", "--from-bag", str(bag), "--pattern", "9x6", "--square",
                         "0.025", "-o", str(tmp_path / "c.yaml"))  # fmt: skip
    assert code == 2 and not (tmp_path / "c.yaml").exists()
    assert err.strip().endswith(
        "no frame pair of the 1 read shows the chessboard 9x6 inner corners in both views"
    )
    for argv, msg in [
        (("stream", "--from-bag", str(tmp_path / "nope"), "--no-display"), "bag not found"),
        (("stream", "--no-display"), "give the two cameras (--left and --right) or a recording"),
        (("stream", "--from-bag", str(bag), "--left", "0", "--no-display"), "replaces --left"),
        (("capture", "--left", "0", "--right", "1", "--left-topic", "/a", "-o", str(tmp_path)),
         "are for --from-bag"),
        (("capture", "--from-bag", str(bag), "--fps", "10", "-o", str(tmp_path / "x")),
         "a bag is read as recorded"),
        (("stream", "--from-bag", str(bag), "--no-display", "--bag", str(tmp_path / "o")),
         "--bag: a bag holds depth; give --calib"),
        (("stream", "--left", "0", "--right", "1", "--realtime", "--no-display"),
         "it goes with --from-bag"),
    ]:  # fmt: skip
        code, _out, err = run(*argv)
        assert code != 0 and msg in err, (argv, err)
        assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err


def test_gui_plays_a_bag(cones: Any, tmp_path: Path) -> None:
    """``gui --from-bag``: the pairs of the bag, again from the start at its end, with the
    bag's calibration and the topics on the page."""
    pytest.importorskip("trame")
    import argparse

    from stereovision.gui import add_arguments, build_app

    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    frames = [(T0 + k * PERIOD_NS, np.roll(cones.left, k, axis=1), T0 + k * PERIOD_NS,
               np.roll(cones.right, k, axis=1)) for k in range(2)]  # fmt: skip
    bag = write_bag(tmp_path / "rig", frames, infos=cams)
    p = argparse.ArgumentParser()
    add_arguments(p)
    app = build_app(p.parse_args(["--from-bag", str(bag), "--port", "0", "--no-browser"]))
    try:
        assert app.source_calib == Calibration.from_file(_ros_folder(tmp_path, cams))
        for k in (0, 1, 0):  # the third read starts the recording again
            app._grab()
            assert app.pair is not None
            np.testing.assert_array_equal(app.pair[0], frames[k][1])
            np.testing.assert_array_equal(app.pair[1], frames[k][3])
        assert app.state.source_label == f"bag rig: {LEFT} / {RIGHT}"
    finally:
        app.source.close()
    with pytest.raises(ValueError, match="replaces --left and --right"):
        build_app(p.parse_args(["--from-bag", str(bag), "--left", "0", "--right", "1"]))
    # --calib wins over the bag's camera_info
    mine = dataclasses.replace(_raw_rig(), T=np.array([-0.2, 0.0, 0.0]))
    rig = mine.save(tmp_path / "mine.yaml")
    app = build_app(p.parse_args(["--from-bag", str(bag), "--calib", str(rig), "--no-browser"]))
    try:
        assert app.source_calib == Calibration.load(rig)
        assert app.source_calib.baseline_m == pytest.approx(0.2)
    finally:
        app.source.close()


def _raw_rig() -> Calibration:
    return Calibration(
        K1=np.array([[420.0, 0, 221.3], [0, 421.0, 190.2], [0, 0, 1]]),
        D1=np.array([-0.21, 0.05, 0.001, -0.0005, 0.0]),
        K2=np.array([[418.0, 0, 228.9], [0, 419.5, 185.7], [0, 0, 1]]),
        D2=np.array([-0.19, 0.04, -0.0008, 0.0004, 0.0]),
        R=cv2.Rodrigues(np.array([0.004, -0.011, 0.002]))[0],
        T=np.array([-0.1203, 0.0011, -0.0007]),
        image_size=(450, 375),
        unit="m",
    )


def _ros_folder(tmp_path: Path, cams: tuple) -> Path:
    from stereovision.calibration import _ros_yaml

    d = tmp_path / "ros"
    d.mkdir(exist_ok=True)
    for name, c in zip(("left", "right"), cams, strict=True):
        text = _ros_yaml(name, c["image_size"], c["K"], c["D"], c["R"], c["P"],
                         c["distortion_model"])  # fmt: skip
        (d / f"{name}.yaml").write_text(text)
    return d


def test_cli_info_on_a_bag(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + k * PERIOD_NS, cones.right) for k in range(4)]
    for flavour, name in (("ros2", "rig"), ("ros1", "rig.bag")):
        (tmp_path / flavour).mkdir()
        bag = write_bag(tmp_path / flavour / name, frames, flavour=flavour, infos=cams)
        code, out, err = run("info", str(bag))
        assert code == 0, err
        kind = "ROS 2" if flavour == "ros2" else "ROS 1"
        assert f"({kind}, 0.1 s, 4 topics)" in out
        lines = {ln.split()[0]: ln for ln in out.splitlines() if ln.startswith("  /")}
        assert lines[LEFT].endswith("<- left") and " 4 msgs " in lines[LEFT]
        assert lines["/stereo/right/camera_info"].endswith("<- right camera_info")
        assert "the rig, from its camera_info:" in out and "baseline 12.0 cm" in out
    bare = write_bag(tmp_path / "bare", frames)
    code, out, err = run("info", str(bare))
    assert code == 0 and "no camera_info beside the image topics" in out
    code, out, err = run("info", str(tmp_path / "ros1" / "nothing.bag"))
    assert code != 0 and "not found" in err and "Traceback" not in err
    # topics no rule pairs: the error names the options, and info has them
    odd = write_bag(tmp_path / "odd", frames, topics=("/a/image", "/b/image"))
    code, out, err = run("info", str(odd))
    assert code == 2 and "give the topics (--left-topic, --right-topic)" in err
    code, out, err = run("info", str(odd), "--left-topic", "/a/image", "--right-topic", "/b/image")
    assert code == 0, err
    assert " 4 msgs " in out and "/a/image" in out and "<- left" in out
    code, out, err = run("info", str(tmp_path / "ros2" / "rig"), "--left-topic", "/x")
    assert code == 2 and "give both the left and the right topic" in err
    cal = _raw_rig().save(tmp_path / "rig.yaml")
    code, out, err = run("info", str(cal), "--left-topic", "/a/image")
    assert code == 2 and err.strip().endswith("--left-topic and --right-topic are for a bag")


def test_one_camera_stops(cones: Any, tmp_path: Path) -> None:
    """The left camera stops after 10 frames, the right one goes on for 100: 10 pairs, the
    right frames after them dropped (and not all held in memory: at most 64 wait)."""
    from stereovision import rosbag

    frames = [(T0 + k * PERIOD_NS if k < 10 else None, cones.left, T0 + k * PERIOD_NS,
               cones.right) for k in range(100)]  # fmt: skip
    bag = write_bag(tmp_path / "rig", frames, encoding="png")
    held: list[int] = []
    with BagCamera(bag) as cam:
        real = cam._match

        def spy(lefts: Any, rights: Any, final: bool) -> Any:
            yield from real(lefts, rights, final)
            held.append(len(rights))

        cam._match = spy  # type: ignore[method-assign]
        assert len(list(cam.frames())) == 10
    assert cam.dropped == {"left": 0, "right": 90}
    assert max(held) == rosbag.MAX_WAITING  # the newest 64 kept, not fewer


def test_realtime_playback_skips_what_a_slow_reader_misses(cones: Any, tmp_path: Path) -> None:
    """``realtime``: pairs 100 ms apart, a reader that takes 250 ms per pair gets pairs 0, 2, 5,
    7 and 9 (the newest whose time has come), 5 skipped; a fast reader (10 ms) gets all 10 and
    waits out the rest of each period."""
    frames = [(T0 + k * 100_000_000, cones.left, T0 + k * 100_000_000, cones.right)
              for k in range(10)]  # fmt: skip
    bag = write_bag(tmp_path / "rig", frames, encoding="png")
    for work_s, want, slept in ((0.25, [0, 2, 5, 7, 9], 0.0), (0.01, list(range(10)), 0.81)):
        now = [0.0]
        waits: list[float] = []

        def sleep(dt: float, now: list[float] = now, waits: list[float] = waits) -> None:
            waits.append(dt)
            now[0] += dt

        with BagCamera(bag, realtime=True) as cam:
            cam._clock, cam._sleep = (lambda now=now: now[0]), sleep
            got = []
            for f in cam.frames():
                got.append(round((f.t_left * 1e9 - T0) / 100_000_000))
                now[0] += work_s  # the matcher's time on this pair
        assert got == want and cam.skipped == 10 - len(want)
        assert sum(waits) == pytest.approx(slept, abs=1e-6)


def test_topics_of_another_shape_are_refused_not_stretched(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A right topic of another shape than the left one: an error naming both (its frames were
    resized to the left's size, stretched without a word); one of the same shape and half the
    size is resized, with one warning."""
    squashed = cv2.resize(cones.right, (450, 300), interpolation=cv2.INTER_AREA)
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + k * PERIOD_NS, squashed) for k in range(3)]
    bag = write_bag(tmp_path / "rig", frames, encoding="png")
    with BagCamera(bag) as cam, pytest.raises(SourceError) as info:
        cam.read()
    assert str(info.value) == (
        f"bag {bag}: {RIGHT} at stamp {T0} ns is 450x300, the {LEFT} frames 450x375: frames of "
        "another shape cannot be paired without stretching one (0 pairs read before)"
    )
    assert info.value.end is False
    out = tmp_path / "pairs"
    code, _, err = run("capture", "--from-bag", str(bag), "-o", str(out))
    assert code == 2 and "frames of another shape cannot be paired" in err
    assert len(err.strip().splitlines()) == 1 and not list(out.glob("*.png"))

    half = cv2.resize(cones.right, (225, 188), interpolation=cv2.INTER_AREA)
    bag = write_bag(tmp_path / "half", [(T0, cones.left, T0, half)], encoding="png")
    with BagCamera(bag) as cam, pytest.warns(UserWarning, match=r"is 225x188, not 450x375"):
        frame = cam.read()
    assert frame.right.shape == cones.left.shape


def test_a_pair_recorded_without_messages_is_passed_over(cones: Any, tmp_path: Path) -> None:
    """A ROS 2 bag whose raw topics were recorded but never published, its rectified ones with
    frames: the raw pair (preferred by name) was taken, a camera of no frames. A pair with
    messages on both topics comes first now; a bag with none says so, listing the counts."""
    rect = ("/stereo/left/image_rect", "/stereo/right/image_rect")
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + k * PERIOD_NS, cones.right) for k in range(3)]
    bag = write_bag(tmp_path / "rig", frames, topics=rect, empty=(LEFT, RIGHT))
    with BagCamera(bag) as cam:
        assert cam.topics == {"left": rect[0], "right": rect[1]}
        listed = {ln.split()[0]: ln.split()[2:] for ln in cam.summary().splitlines()[1:]}
        assert listed[LEFT] == ["0", "msgs", "0.00", "Hz"]  # truly none: not "?"
        assert len(list(cam.frames())) == 3
    counts = {LEFT: 4, RIGHT: 0, rect[0]: 2, rect[1]: 2}  # one side without messages
    assert find_stereo_topics([LEFT, RIGHT, *rect], counts) == rect
    with pytest.raises(ValueError, match=r"no stereo pair .*holds messages on both topics: "):
        find_stereo_topics([LEFT, RIGHT], {LEFT: 5, RIGHT: 0})
    empty = write_bag(tmp_path / "empty", [], empty=(LEFT, RIGHT))
    want = (
        "no stereo pair of the bag holds messages on both topics: "
        f"{LEFT} + {RIGHT} (0 and 0 messages)"
    )
    with pytest.raises(ValueError) as info:
        BagCamera(empty)
    assert str(info.value) == want
    # an index counting none (metadata.yaml's message_count 0), the right topic truly empty:
    # the left one's messages were said as 1 (the check's mark), not a count
    import re

    lone = [(T0 + k * PERIOD_NS, cones.left, None, cones.right) for k in range(2)]
    one = write_bag(tmp_path / "one", lone, empty=(RIGHT,))
    meta = one / "metadata.yaml"
    meta.write_text(re.sub(r"message_count: \d+", "message_count: 0", meta.read_text()))
    with pytest.raises(ValueError) as info:
        BagCamera(one)
    assert str(info.value) == (
        "no stereo pair of the bag holds messages on both topics: "
        f"{LEFT} + {RIGHT} (some and 0 messages)"
    )
    assert find_stereo_topics([LEFT, RIGHT], {LEFT: -1, RIGHT: -1}) == (LEFT, RIGHT)


@pytest.mark.parametrize("flavour", ["ros2", "ros1"])
def test_a_bag_of_one_instant_has_a_span_and_its_counts_announced(
    cones: Any, tmp_path: Path, flavour: str
) -> None:
    """A bag whose messages were all recorded at one instant (one pair) spans 0.0 s, not "?"
    (kept for an index that counts none); its topics announce their messages to the frames
    bar, none once the bag is closed (an index counting none: the test below)."""
    bag = write_bag(tmp_path / ("one.bag" if flavour == "ros1" else "one"),
                    [(T0, cones.left, T0, cones.right)], flavour=flavour)  # fmt: skip
    with BagCamera(bag) as cam:
        assert cam.summary().splitlines()[0].endswith(", 0.0 s, 2 topics)")
        assert [cam._announced(side) for side in ("left", "right")] == [1, 1]
    assert cam._announced("left") is None  # closed


def _zero_ros1_index_counts(bag: Path) -> None:
    """Zero every count of a ROS 1 bag's chunk infos (the index's per-topic message counts),
    keeping the messages and each chunk's own index of them."""
    import struct

    buf = bytearray(bag.read_bytes())

    def record(pos: int) -> tuple[dict[bytes, bytes], int, int]:
        (hlen,) = struct.unpack_from("<I", buf, pos)
        fields, i = {}, pos + 4
        while i < pos + 4 + hlen:
            (flen,) = struct.unpack_from("<I", buf, i)
            name, _, value = bytes(buf[i + 4 : i + 4 + flen]).partition(b"=")
            fields[name] = value
            i += 4 + flen
        (dlen,) = struct.unpack_from("<I", buf, i)
        return fields, i + 4, dlen

    header, _, _ = record(len(b"#ROSBAG V2.0\n"))
    (pos,) = struct.unpack("<Q", header[b"index_pos"])
    while pos < len(buf):
        fields, data, dlen = record(pos)
        if fields[b"op"] == b"\x06":  # a chunk info: (connection id, count) pairs
            for k in range(data + 4, data + dlen, 8):
                struct.pack_into("<I", buf, k, 0)
        pos = data + dlen
    bag.write_bytes(bytes(buf))


@pytest.mark.parametrize("flavour", ["ros2", "mcap", "ros1"])
def test_a_bag_whose_index_counts_no_messages_is_read_with_its_topics_found(
    cones: Any, tmp_path: Path, flavour: str
) -> None:
    """A bag whose index says 0 messages on its image topics, but holds them (metadata.yaml's
    message_count left 0 by some recorders, a ROS 1 index of zero counts): its topics found
    by name were refused ("no stereo pair of the bag holds messages on both topics: ... (0 and
    0 messages)") though it read fine with the topics given; given them, it was read without
    its calibration (its camera_info topics taken for empty ones). A zero count is now checked
    on the messages themselves; a pair or camera_info truly without any is still passed over
    (the test above, test_a_camera_info_topic_without_messages_is_no_calibration)."""
    import re

    from stereovision.rosbag import _open_reader

    frames = [
        (T0 + k * PERIOD_NS, np.roll(cones.left, k, axis=1),
         T0 + k * PERIOD_NS, np.roll(cones.right, k, axis=1))
        for k in range(3)
    ]  # fmt: skip
    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    bag = write_bag(tmp_path / ("rig.bag" if flavour == "ros1" else "rig"), frames,
                    flavour=flavour, infos=cams)  # fmt: skip
    with BagCamera(bag) as cam:
        want = cam.calibration()
        positions = [(f.pos_left_ms, f.pos_right_ms) for f in cam.frames()]
    assert want is not None and positions[0] == (-2.0, -2.0)  # recorded 2 ms after its stamp
    if flavour == "ros1":
        _zero_ros1_index_counts(bag)
    else:
        meta = bag / "metadata.yaml"
        meta.write_text(re.sub(r"message_count: \d+", "message_count: 0", meta.read_text()))
    reader = _open_reader(bag)
    try:  # the bag is what the test says: its index counts nothing
        assert {i.msgcount for i in reader.topics.values()} == {0} and len(reader.topics) == 4
    finally:
        reader.close()
    with BagCamera(bag) as cam:
        assert cam.topics == {"left": LEFT, "right": RIGHT}
        assert cam._announced("left") is None  # the frames bar has no total, not 0
        assert cam.info_topics == {"left": "/stereo/left/camera_info",
                                   "right": "/stereo/right/camera_info"}  # fmt: skip
        assert cam.calibration() == want
        # info's lines: the counts and rates unknown, not 0 (a ROS 2 index gives no span)
        lines = cam.summary().splitlines()
        span = "0.1 s" if flavour == "ros1" else "? s"
        assert (
            lines[0] == f"bag {bag} ({'ROS 1' if flavour == 'ros1' else 'ROS 2'}, {span}, 4 topics)"
        )
        assert len(lines) == 5 and all(" ? msgs       ? Hz" in line for line in lines[1:]), lines
        got = list(cam.frames())
    assert cam.stamps_ns == [T0 + k * PERIOD_NS for k in range(3)]
    # the time since the bag's start, as indexed (a ROS 2 bag's start was rosbags' 2**63 - 1)
    assert [(f.pos_left_ms, f.pos_right_ms) for f in got] == positions
    for f, (_, left, _, right) in zip(got, frames, strict=True):
        np.testing.assert_array_equal(f.left, left)
        np.testing.assert_array_equal(f.right, right)


@PIPELINED
def test_capture_of_a_bag_without_a_pair_is_an_error(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A bag whose right frames are all a second off the left ones: no pair, an error saying
    why, exit 2, as `stream` says it (capture said "0 pairs saved (end of stream)", exit 0)."""
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + 10**9 + k * PERIOD_NS, cones.right)
              for k in range(5)]  # fmt: skip
    bag = write_bag(tmp_path / "rig", frames, encoding="png")
    want = (
        f"stereovision: error: bag {bag}: end of the recording after 0 pairs (5 left and 5 right "
        "frames without a partner)"
    )
    for argv in (["capture", "-o", str(tmp_path / "pairs")], ["stream", "--no-display"]):
        code, _, err = run(argv[0], "--from-bag", str(bag), *argv[1:])
        # (stream says first that the bag has no camera_info: disparity only)
        err = "\n".join(x for x in err.splitlines() if not x.startswith("calibration: none;"))
        assert code == 2 and err.splitlines()[0].startswith(want), err
        assert len(err.strip().splitlines()) == 1
    from stereovision.capture import capture

    with BagCamera(bag) as cam, pytest.raises(SourceError, match="without a partner"):
        capture(cam, tmp_path / "more")


def test_a_bag_without_a_pair_says_how_far_apart_the_topics_stamps_are(
    cones: Any, tmp_path: Path
) -> None:
    """The right camera stamping with its own clock (seconds since boot): every frame without a
    partner, and the error said no why. It now gives the first stamps' difference."""
    small = cones.left[:48, :64], cones.right[:48, :64]
    boot = 500 * 10**9
    frames = [(T0 + k * PERIOD_NS, small[0], boot + k * PERIOD_NS, small[1]) for k in range(10)]
    bag = write_bag(tmp_path / "rig", frames)
    with BagCamera(bag) as cam, pytest.raises(SourceError) as caught:
        cam.read()
    assert str(caught.value) == (
        f"bag {bag}: end of the recording after 0 pairs (10 left and 10 right frames without a "
        "partner); no left and right stamps within 16.7 ms of each other: the first left stamp "
        f"is +{(T0 - boot) / 1e9:.3f} s from the first right one (cameras stamping with "
        "different clocks?)"
    )
    # a pair read: the end is said as before
    frames[3] = (frames[3][0], small[0], frames[3][0], small[1])
    bag = write_bag(tmp_path / "one", frames)
    with BagCamera(bag, max_skew_ms=1) as cam, pytest.raises(SourceError) as caught:
        while True:
            cam.read()
    assert str(caught.value).endswith("(9 left and 9 right frames without a partner)")
    # a gap under a second in ms: 0.3 ms to a 0.1 ms max skew was "-0.000 s"
    frames = [(T0 + k * PERIOD_NS, small[0], T0 + k * PERIOD_NS + 300_000, small[1])
              for k in range(10)]  # fmt: skip
    bag = write_bag(tmp_path / "near", frames)
    with BagCamera(bag, max_skew_ms=0.1) as cam, pytest.raises(SourceError) as caught:
        cam.read()
    assert str(caught.value).endswith(
        "no left and right stamps within 0.1 ms of each other: the first left stamp is -0.3 ms "
        "from the first right one (cameras stamping with different clocks?)"
    )
    # a gap of a second and more in seconds, from exactly 1 s (not "-1e+03 ms")
    frames = [(T0 + k * PERIOD_NS, small[0], T0 + k * PERIOD_NS + 10**9, small[1])
              for k in range(10)]  # fmt: skip
    bag = write_bag(tmp_path / "second", frames)
    with BagCamera(bag) as cam, pytest.raises(SourceError) as caught:
        cam.read()
    assert "the first left stamp is -1.000 s from the first right one" in str(caught.value)


def test_the_no_pair_gap_is_never_said_in_exponent_form(cones: Any, tmp_path: Path) -> None:
    """4c9f7bd said a gap under a second with ``.3g``: 999.7 ms read "+1e+03 ms" and 5 ns (a
    ``max_skew_ms`` of 0) "-5e-06 ms". They are "+1000 ms" and "-5 ns" now."""
    small = cones.left[:48, :64], cones.right[:48, :64]
    for gap, skew, said in ((999_700_000, None, "+1000 ms"), (-5, 0.0, "-5 ns")):
        frames = [(T0 + k * PERIOD_NS + gap, small[0], T0 + k * PERIOD_NS, small[1])
                  for k in range(10)]  # fmt: skip
        bag = write_bag(tmp_path / f"gap{gap}", frames)
        with BagCamera(bag, max_skew_ms=skew) as cam, pytest.raises(SourceError) as caught:
            cam.read()
        assert f": the first left stamp is {said} from the first right one (" in str(caught.value)


def test_the_max_skew_is_never_said_in_exponent_form(cones: Any, tmp_path: Path) -> None:
    """The no-pair error and ``describe`` said a max skew with ``.3g``: 1500 ms read "within
    1.5e+03 ms" and 5e-06 ms "5e-06 ms". They are said as the gap is (``_gap_text``)."""
    small = cones.left[:48, :64], cones.right[:48, :64]
    gap = 2 * 10**9
    frames = [(T0 + k * PERIOD_NS + gap, small[0], T0 + k * PERIOD_NS, small[1])
              for k in range(10)]  # fmt: skip
    bag = write_bag(tmp_path / "far", frames)
    for skew, said in ((1500, "1.500 s"), (5e-06, "5 ns"), (250, "250 ms")):
        with BagCamera(bag, max_skew_ms=skew) as cam:
            assert cam.describe().endswith(f"; max skew {said}")
            with pytest.raises(SourceError) as caught:
                cam.read()
        assert f"; no left and right stamps within {said} of each other: " in str(caught.value)


def test_a_ros1_recording_left_unfinished_is_said_with_its_remedy(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """rosbag record killed leaves NAME.bag.active without an index: ``info`` took it for a
    calibration file ("not a text calibration file"), ``stream --from-bag`` said rosbags'
    "Unrecognized storage format '.active'". Both now say what it is and how to index it."""
    small = cones.left[:48, :64], cones.right[:48, :64]
    bag = write_bag(tmp_path / "rig.bag", [(T0, small[0], T0, small[1])], flavour="ros1")
    data = bytearray(bag.read_bytes())
    at = data.index(b"index_pos=") + len(b"index_pos=")
    data[at : at + 8] = bytes(8)  # the header's index position, as the recorder opened it
    active = tmp_path / "rig.bag.active"
    active.write_bytes(bytes(data))
    bag.unlink()
    from stereovision.rosbag import bag_topics, is_bag

    assert is_bag(active)
    # said as it is, not wrapped as "not a readable ROS 1 or ROS 2 bag"
    with pytest.raises(ValueError, match=r"^\S*rig\.bag\.active is a ROS 1 recording left unf"):
        bag_topics(active)
    said = (
        f"stereovision: error: {active} is a ROS 1 recording left unfinished (its recorder "
        f"stopped before writing the index): `rosbag reindex {active}` indexes it; then rename "
        "it to .bag"
    )
    for argv in (["info", str(active)], ["stream", "--from-bag", str(active), "--no-display"]):
        code, _out, err = run(*argv)
        assert code == 2 and err.strip().splitlines() == [said], argv


def test_a_split_ros1_recording_whose_last_piece_is_unfinished_is_said(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """``rosbag record --split`` killed: a folder of finished pieces and the last one
    NAME_2.bag.active. The folder was read without that piece, its pairs lost without a word
    (10 of 15 pairs); a folder holding only the .bag.active was "not a readable ROS 1 or ROS 2
    bag: Expected metadata file". Both now name the unfinished piece and its remedy."""
    from stereovision.rosbag import is_bag

    small = cones.left[:48, :64], cones.right[:48, :64]
    split, alone = tmp_path / "split", tmp_path / "alone"
    split.mkdir()
    alone.mkdir()
    for i in range(3):
        stamps = [T0 + (5 * i + k) * PERIOD_NS for k in range(5)]
        write_bag(split / f"rig_{i}.bag", [(s, small[0], s, small[1]) for s in stamps],
                  flavour="ros1")  # fmt: skip
    active = split / "rig_2.bag.active"
    (split / "rig_2.bag").rename(active)
    (alone / active.name).write_bytes(active.read_bytes())
    for folder in (split, alone):
        assert is_bag(folder)
        piece = folder / active.name
        said = (
            f"stereovision: error: {piece} is a ROS 1 recording left unfinished (its recorder "
            f"stopped before writing the index): `rosbag reindex {piece}` indexes it; then "
            "rename it to .bag"
        )
        for argv in (["info", str(folder)], ["stream", "--from-bag", str(folder), "--no-display"]):
            code, _out, err = run(*argv)
            assert code == 2 and err.strip().splitlines() == [said], argv
    # the piece finished: all 15 pairs read, as before
    active.rename(split / "rig_2.bag")
    with BagCamera(split) as cam:
        assert len(list(cam.frames())) == 15
    # a ROS 2 bag folder is read by its metadata.yaml: a stray .bag.active in it is not its
    # recording (not refused as one)
    ros2 = write_bag(tmp_path / "ros2", [(T0, small[0], T0, small[1])])
    (ros2 / active.name).write_bytes((split / "rig_2.bag").read_bytes())
    with BagCamera(ros2) as cam:
        assert len(list(cam.frames())) == 1


def test_another_recordings_unfinished_bag_beside_a_split_one_is_left_out(
    cones: Any, tmp_path: Path
) -> None:
    """A folder of a finished split recording (rig_<time>_0.bag, rig_<time>_1.bag) beside the
    .bag.active of another recording still under way there: 98b0543 refused the folder,
    naming the other recording's file (10 pairs read before it). That file is no piece of
    this recording: its 10 pairs are read; the recording's own unfinished piece is still
    named."""
    small = cones.left[:48, :64], cones.right[:48, :64]
    folder = tmp_path / "bags"
    folder.mkdir()
    for i in range(2):
        stamps = [T0 + (5 * i + k) * PERIOD_NS for k in range(5)]
        write_bag(folder / f"rig_2026-12-06-06-00-00_{i}.bag",
                  [(s, small[0], s, small[1]) for s in stamps], flavour="ros1")  # fmt: skip
    other = write_bag(tmp_path / "other_2026-12-06-07-00-00_0.bag",
                      [(T0 + k * PERIOD_NS, small[0], T0 + k * PERIOD_NS, small[1])
                       for k in range(5)], flavour="ros1")  # fmt: skip
    other.rename(folder / f"{other.name}.active")
    with BagCamera(folder) as cam:
        assert len(list(cam.frames())) == 10 and cam.dropped == {"left": 0, "right": 0}
    # beside a ROS 2 bag's storage files without metadata.yaml (read from them) alike
    ros2 = write_bag(tmp_path / "ros2", [(T0 + k * PERIOD_NS, small[0], T0 + k * PERIOD_NS,
                                          small[1]) for k in range(7)])  # fmt: skip
    (ros2 / "metadata.yaml").unlink()
    (ros2 / f"{other.name}.active").write_bytes((folder / f"{other.name}.active").read_bytes())
    with BagCamera(ros2) as cam:
        assert len(list(cam.frames())) == 7
    # the recording's own last piece unfinished: named, not the other recording's file
    own = folder / "rig_2026-12-06-06-00-00_1.bag"
    own.rename(folder / f"{own.name}.active")
    with pytest.raises(ValueError, match=re.escape(f"{own}.active is a ROS 1 recording left")):
        BagCamera(folder)


def test_an_mcap_recording_left_unfinished_is_said_with_its_remedy(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A recorder killed before writing the MCAP summary and footer: rosbags' "File end magic
    is invalid." was all the error said. Now what it is and the tool that rebuilds it, for the
    bag folder, the file, and the file alone (no metadata.yaml)."""
    small = cones.left[:48, :64], cones.right[:48, :64]
    frames = [(T0 + k * PERIOD_NS, small[0], T0 + k * PERIOD_NS, small[1]) for k in range(4)]
    bag = write_bag(tmp_path / "rig", frames, flavour="mcap")
    (mcap,) = bag.glob("*.mcap")
    mcap.write_bytes(mcap.read_bytes()[: mcap.stat().st_size * 6 // 10])
    lone = tmp_path / "lone"
    lone.mkdir()
    (lone / mcap.name).write_bytes(mcap.read_bytes())
    # killed as it began: the leading magic alone ("ord() expected a character, but string of
    # length 0 found"), its tail its head
    begun = tmp_path / "begun.mcap"
    begun.write_bytes(mcap.read_bytes()[:8])
    for path, file in (
        (bag, mcap),
        (mcap, mcap),
        (lone / mcap.name, lone / mcap.name),
        (begun, begun),
    ):
        said = (
            f"stereovision: error: {file} is an MCAP recording left unfinished (its recorder "
            "stopped before writing its summary, or is still recording): `mcap recover "
            f"{file} -o FIXED.mcap` (the mcap CLI) rebuilds it"
        )
        for argv in (["info", str(path)], ["stream", "--from-bag", str(path), "--no-display"]):
            code, _out, err = run(*argv)
            assert code == 2 and err.strip().splitlines() == [said], argv


@pytest.mark.parametrize("flavour", ["ros2", "mcap"])
def test_a_ros2_bag_without_its_metadata_is_read(
    cones: Any, tmp_path: Path, flavour: str, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A recorder killed before writing metadata.yaml: the folder is read from its storage
    files (it was "not a readable ROS 1 or ROS 2 bag: Expected metadata file ...", and
    `ros2 bag reindex` needs ROS)."""
    from stereovision.rosbag import is_bag

    frames, _ = _jittered(cones, 14)
    bag = write_bag(tmp_path / "rig", frames, flavour=flavour)
    (bag / "metadata.yaml").unlink()
    assert is_bag(bag)
    with BagCamera(bag) as cam:
        got = list(cam.frames())
    kept = [k for k in range(14) if k not in (5, 9)]
    assert cam.stamps_ns == [T0 + k * PERIOD_NS for k in kept]
    np.testing.assert_array_equal(got[-1].right, frames[13][3])
    code, out, _ = run("capture", "--from-bag", str(bag), "-o", str(tmp_path / "pairs"))
    assert code == 0 and out.splitlines()[-1].startswith(f"{len(kept)} pairs saved in ")


def test_a_folder_holding_no_bag_is_said_so_not_as_its_metadata_file(
    tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A folder of images given as the bag (capture --from-bag pairs/): rosbags' "Expected
    metadata file 'pairs' does not exist." named the folder as the file. It says what a bag
    folder holds, in the library and on the command line."""
    from stereovision.rosbag import bag_topics

    pairs = tmp_path / "pairs"
    pairs.mkdir()
    (pairs / "left_0001.png").write_bytes(b"")
    said = (
        f"{pairs} is not a readable ROS 1 or ROS 2 bag: a folder without a ROS 2 bag's "
        "metadata.yaml (or its .db3 / .mcap files) nor a ROS 1 recording's .bag files"
    )
    for open_it in (BagCamera, bag_topics):
        with pytest.raises(ValueError) as err:
            open_it(pairs)
        assert str(err.value) == said
    code, out, err_text = run("capture", "--from-bag", str(pairs), "-o", str(tmp_path / "o"))
    assert (code, out, err_text) == (2, "", f"stereovision: error: {said}\n")
    assert not (tmp_path / "o").exists()


def test_a_size_of_another_shape_does_not_stretch_a_recording(cones: Any, tmp_path: Path) -> None:
    """--size 450x200 for 450x375 frames: kept at 450x375 with a warning, as for cameras
    (`capture --size`: "frames of the same shape are resized"); they were stretched."""
    bag = write_bag(tmp_path / "rig", [(T0, cones.left, T0, cones.right)], encoding="png")
    with (
        BagCamera(bag, image_size="450x200") as cam,
        pytest.warns(
            UserWarning,
            match=r"size 450x200 is another shape than the recording's "
            r"450x375: its frames are kept at 450x375",
        ),  # fmt: skip
    ):
        frame = cam.read()
    np.testing.assert_array_equal(frame.left, cones.left)
    np.testing.assert_array_equal(frame.right, cones.right)


def test_frames_resized_after_a_dropped_size_are_said(cones: Any, tmp_path: Path) -> None:
    """--size 450x200 of a 450x375 left topic is dropped (another shape); the half-size right
    topic is then resized to 450x375, which nobody asked: one warning says so (there was none,
    as if the size asked had been applied)."""
    half = cv2.resize(cones.right, (225, 188), interpolation=cv2.INTER_AREA)
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + k * PERIOD_NS, half) for k in range(3)]
    bag = write_bag(tmp_path / "rig", frames, encoding="png")
    with pytest.warns(UserWarning) as caught, BagCamera(bag, image_size="450x200") as cam:
        got = list(cam.frames())
    assert [str(w.message) for w in caught] == [
        "size 450x200 is another shape than the recording's 450x375: its frames are kept at "
        "450x375 (a resize would stretch them)",
        f"{RIGHT} is 225x188, not 450x375: its frames are resized",
    ]
    assert len(got) == 3 and got[2].right.shape == cones.left.shape


def test_temporal_averaging_of_rectified_topics_is_said(cones: Any, tmp_path: Path) -> None:
    """A still rig's noisy frames from image_rect topics: their interpolation spread the noise,
    the filter's motion test takes it for motion and restarts on every pair, and `capture
    --temporal` saved no pair without a word. One warning now says why; the raw topics of the
    same rig (no warning) give pairs."""
    from stereovision.capture import capture
    from stereovision.temporal import TemporalFilter

    rng = np.random.default_rng(3)
    h, w = cones.left.shape[:2]
    half_px = np.float32([[1, 0, 0.5], [0, 1, 0.5]])

    def noisy(img: np.ndarray) -> np.ndarray:
        return np.clip(img + rng.normal(0, 8, img.shape), 0, 255).astype(np.uint8)

    raw = [(noisy(cones.left), noisy(cones.right)) for _ in range(6)]
    rect = [tuple(cv2.warpAffine(i, half_px, (w, h)) for i in pair) for pair in raw]
    topics = ("/stereo/left/image_rect", "/stereo/right/image_rect")
    stamps = [T0 + k * PERIOD_NS for k in range(6)]
    frames = [(t, lft, t, rgt) for t, (lft, rgt) in zip(stamps, rect, strict=True)]
    bag = write_bag(tmp_path / "rect", frames, topics=topics)
    tf = TemporalFilter()
    for lft, rgt in rect:
        tf(lft, rgt)
    assert tf.restarts == 5  # the limit itself (temporal.py): every pair taken for a moving one
    with BagCamera(bag) as cam, pytest.warns(UserWarning) as caught:
        saved = capture(cam, tmp_path / "pairs", temporal=2)
    assert saved.saved == [] and saved.frames_read == 6
    assert [str(w.message) for w in caught] == [
        f"temporal averaging: the topics {topics[0]} and {topics[1]} are rectified, and "
        "interpolation spreads their noise, which the filter takes for motion (it may average "
        "nothing); give the raw image topics (--left-topic, --right-topic)"
    ]
    frames = [(t, lft, t, rgt) for t, (lft, rgt) in zip(stamps, raw, strict=True)]
    bag = write_bag(tmp_path / "raw", frames)
    with BagCamera(bag) as cam, warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(capture(cam, tmp_path / "raw_pairs", temporal=2).saved) == 3


def _bag_with_a_bad_third_pair(cones: Any, tmp_path: Path) -> list[int]:
    """``tmp_path / "rig"``: four 128x96 pairs, the right frame of the third recorded as a
    depth image (32FC1); returns the pairs' stamps."""
    from rosbags.rosbag2 import Reader, Writer

    left, right = cones.left[100:196, 100:228], cones.right[100:196, 100:228]
    stamps = [T0 + k * PERIOD_NS for k in range(4)]
    good = write_bag(tmp_path / "good", [(s, left, s, right) for s in stamps])
    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(good) as r, Writer(tmp_path / "rig", version=9) as w:
        conns: dict[str, Any] = {}
        for conn, recorded, raw in r.messages():
            msg = ts.deserialize_cdr(raw, conn.msgtype)
            if conn.topic == RIGHT and recorded == stamps[2] + 2_000_000:
                msg.encoding = "32FC1"
            if conn.topic not in conns:
                conns[conn.topic] = w.add_connection(conn.topic, conn.msgtype, typestore=ts)
            w.write(conns[conn.topic], recorded, ts.serialize_cdr(msg, conn.msgtype))
    return stamps


@PIPELINED
def test_cli_stream_keeps_its_summary_when_a_recorded_frame_does_not_decode(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """The right frame of pair 3 recorded as a depth image (32FC1): the stream stopped with the
    error alone, the figures of the two pairs done lost. Now it ends there with their summary
    ("source failed", the topic and stamp named) and exits 2, as for a video."""
    stamps = _bag_with_a_bad_third_pair(cones, tmp_path)
    code, out, err = run("stream", "--from-bag", str(tmp_path / "rig"), "--no-display",
                         "--json", "--method", "gabor", "--max-disparity", "16",
                         "--no-check")  # fmt: skip
    assert code == 2
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["frames"] == 2 and summary["ended"] == "source failed"
    said = f"{RIGHT} at stamp {stamps[2]} ns: image encoding '32FC1'"
    assert summary["error"].startswith(said)
    assert err.strip().splitlines()[-1].startswith(f"stereovision: error: {said}")


def test_cli_capture_says_its_pairs_are_kept_when_a_recorded_frame_does_not_decode(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """The same bag captured: the error named the frame but not the two pairs saved before it,
    as a video's failing frame has it said; now it says they are kept."""
    stamps = _bag_with_a_bad_third_pair(cones, tmp_path)
    out_dir = tmp_path / "pairs"
    code, _out, err = run("capture", "--from-bag", str(tmp_path / "rig"), "-o", str(out_dir))
    assert code == 2
    said = err.strip().splitlines()[-1]
    assert said.startswith(f"stereovision: error: {RIGHT} at stamp {stamps[2]} ns: image ")
    assert said.endswith(f"; 2 pairs were saved in {out_dir} and are kept")
    assert sorted(p.name for p in out_dir.iterdir()) == [
        "left_0001.png", "left_0002.png", "right_0001.png", "right_0002.png"]  # fmt: skip


def _damaged_ros1_bag(cones: Any, tmp_path: Path) -> Path:
    """``tmp_path / "rig.bag"``: forty 128x96 pairs in a ROS 1 bag (a 1 MB chunk holds 28
    images), the record header of the 61st message (left frame 30, in the third chunk)
    overwritten: a field longer than the header, as a disk or copy error leaves it."""
    left, right = cones.left[100:196, 100:228], cones.right[100:196, 100:228]
    stamps = [T0 + k * PERIOD_NS for k in range(40)]
    bag = write_bag(tmp_path / "rig.bag", [(s, left, s, right) for s in stamps], flavour="ros1")
    data = bytearray(bag.read_bytes())
    # a message record's header: its fields, each a 4-byte length and "name=value"; op 2
    records = [m.start() for m in re.finditer(re.escape(b"\x04\x00\x00\x00op=\x02"), data)]
    assert len(records) == 80
    data[records[60] : records[60] + 4] = b"\xff\xff\xff\x00"
    bag.write_bytes(bytes(data))
    return bag


def test_a_bag_damaged_part_way_is_a_failure_of_the_source(cones: Any, tmp_path: Path) -> None:
    """rosbags' ReaderError (apsw's CorruptError for a damaged .db3) came out of ``read`` as
    it was: no bag named, and the CLI called it an internal error. Now a SourceError (not an
    end) naming the bag and the pairs read before, as a frame that does not decode is."""
    bag = _damaged_ros1_bag(cones, tmp_path)
    with BagCamera(bag) as cam:
        with pytest.raises(SourceError) as caught:
            while True:
                cam.read()
        assert 0 < cam.count < 31
        exc = caught.value
        assert not exc.end and exc.frames == cam.count
        assert str(exc).startswith(
            f"bag {bag} cannot be read past {cam.count} pairs (damaged or cut short?): ReaderError"
        )


def _bag_damaged_at(cones: Any, tmp_path: Path, record: int, n: int = 12) -> Path:
    """A ROS 1 bag of ``n`` small pairs, left and right stamped alike (recorded left first),
    the header of its message ``record`` (in recording order) overwritten."""
    left, right = cones.left[:48, :64], cones.right[:48, :64]
    stamps = [T0 + k * 100_000_000 for k in range(n)]
    bag = write_bag(tmp_path / "rig.bag", [(s, left, s, right) for s in stamps], flavour="ros1")
    data = bytearray(bag.read_bytes())
    records = [m.start() for m in re.finditer(re.escape(b"\x04\x00\x00\x00op=\x02"), data)]
    data[records[record] : records[record] + 4] = b"\xff\xff\xff\x00"
    bag.write_bytes(bytes(data))
    return bag


def test_the_pairs_before_a_damage_are_all_delivered(cones: Any, tmp_path: Path) -> None:
    """The left frame of pair 5 damaged: pairs 0-4 are whole, but were still waiting (the
    tolerance is decided on the first PERIOD_SAMPLE frames of each side) when the error was
    raised, so none was read and the error said "past 0 pairs". They are read now, the error
    then, and again on a read after it (it said "end of the recording after 5 pairs")."""
    bag = _bag_damaged_at(cones, tmp_path, 10)
    with BagCamera(bag) as cam:
        got = []
        with pytest.raises(SourceError) as caught:
            while True:
                got.append(round((cam.read().t_left * 1e9 - T0) / 100_000_000))
        assert got == [0, 1, 2, 3, 4] and cam.count == 5
        said = f"bag {bag} cannot be read past 5 pairs (damaged or cut short?): ReaderError: "
        assert str(caught.value).startswith(said)
        assert not caught.value.end and caught.value.frames == 5
        with pytest.raises(SourceError) as again:
            cam.read()
        assert str(again.value) == str(caught.value) and not again.value.end


def test_realtime_playback_delivers_the_pair_due_before_a_damage(
    cones: Any, tmp_path: Path
) -> None:
    """``realtime`` with a slow reader (250 ms a pair, pairs 100 ms apart): looking for the
    newest pair due, it met the damage after pair 4 and raised, losing pair 4 it held."""
    bag = _bag_damaged_at(cones, tmp_path, 10)
    now = [0.0]
    with BagCamera(bag, realtime=True) as cam:
        cam._clock, cam._sleep = (lambda: now[0]), (lambda dt: None)
        got = []
        with pytest.raises(SourceError) as caught:
            while True:
                got.append(round((cam.read().t_left * 1e9 - T0) / 100_000_000))
                now[0] += 0.25
    assert got == [0, 2, 4] and cam.skipped == 2
    assert str(caught.value).startswith(f"bag {bag} cannot be read past 3 pairs (damaged")


@PIPELINED
def test_cli_stream_keeps_its_summary_when_a_bag_is_damaged_part_way(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """The pairs before the damage were streamed, then "internal ReaderError ... (please
    report this)" with no summary; now the summary of those pairs, "source failed", exit 2."""
    bag = _damaged_ros1_bag(cones, tmp_path)
    code, out, err = run("stream", "--from-bag", str(bag), "--no-display", "--json",
                         "--method", "gabor", "--max-disparity", "16", "--no-check")  # fmt: skip
    assert code == 2
    summary = json.loads(out.strip().splitlines()[-1])
    done = summary["frames"]
    assert 0 < done < 31 and summary["ended"] == "source failed"
    said = f"bag {bag} cannot be read past {done} pairs (damaged or cut short?): ReaderError"
    assert summary["error"].startswith(said)
    assert err.strip().splitlines()[-1].startswith(f"stereovision: error: {said}")


def test_a_damaged_camera_info_is_said_with_its_bag_and_topic(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """The record of the first left camera_info (the third message) overwritten: rosbags'
    ReaderError came out of ``calibration`` as it was, and ``info`` (as ``stream --from-bag``)
    said "internal ReaderError ... (please report this)". Now a ValueError naming the bag and
    the topic, one line from the CLI."""
    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + k * PERIOD_NS, cones.right) for k in range(2)]
    bag = write_bag(tmp_path / "rig.bag", frames, flavour="ros1", infos=cams)
    data = bytearray(bag.read_bytes())
    # recorded in order: the left and right images, then their camera_info (1 ns later)
    records = [m.start() for m in re.finditer(re.escape(b"\x04\x00\x00\x00op=\x02"), data)]
    data[records[2] : records[2] + 4] = b"\xff\xff\xff\x00"
    bag.write_bytes(bytes(data))
    said = (
        f"bag {bag}: its first /stereo/left/camera_info message cannot be read (damaged or cut "
        "short?): ReaderError: "
    )
    with BagCamera(bag) as cam, pytest.raises(ValueError) as caught:
        cam.calibration()
    assert str(caught.value).startswith(said)
    code, _out, err = run("info", str(bag))
    assert code == 2 and err.strip().splitlines()[-1].startswith(f"stereovision: error: {said}")


def test_rgba8_and_rgb16_decode_with_their_channel_order(cones: Any) -> None:
    """Mutation audit: ``rgba8`` and ``rgb16`` were not read in the tests (red and blue
    exchanged, or the alpha taken for a colour, went unseen)."""
    bgr = cones.left
    h, w = bgr.shape[:2]
    rgba = np.ascontiguousarray(np.dstack([bgr[..., ::-1], np.full((h, w), 255, np.uint8)]))
    msg = _Msg(height=h, width=w, encoding="rgba8", is_bigendian=0, step=4 * w,
               data=rgba.reshape(-1))  # fmt: skip
    np.testing.assert_array_equal(decode_image(msg), bgr)
    c16 = (bgr.astype(np.uint16) << 8) | 7
    rgb16 = np.ascontiguousarray(c16[..., ::-1]).astype("<u2")
    msg = _Msg(height=h, width=w, encoding="rgb16", is_bigendian=0, step=6 * w,
               data=rgb16.view(np.uint8).reshape(-1))  # fmt: skip
    np.testing.assert_array_equal(decode_image(msg), c16)


def test_stamps_rates_and_the_skew_limit_itself(cones: Any, tmp_path: Path) -> None:
    """Mutation audit: a header stamp left 0 by the driver is the recording time (one of 1 ns
    is not); n messages over a span are n - 1 periods; a pair exactly ``max_skew_ms`` apart
    (either way) is paired, and ``max_skew_ms=0`` (exact stamps only) is accepted."""
    from stereovision.rosbag import _rate, _stamp_ns

    def header(sec: int, nanosec: int) -> Any:
        return _Msg(header=_Msg(stamp=_Msg(sec=sec, nanosec=nanosec)))

    assert _stamp_ns(header(0, 0), 123) == 123
    assert _stamp_ns(header(0, 1), 123) == 1
    assert _stamp_ns(header(2, 5), 123) == 2_000_000_005
    assert _rate(31, _Msg(duration=1_000_000_000)) == pytest.approx(30.0)
    assert _rate(1, _Msg(duration=1_000_000_000)) == 0.0
    left, right = cones.left[:64, :96], cones.right[:64, :96]
    frames = [
        (T0, left, T0 + 2_000_000, right),  # right 2 ms late
        (T0 + PERIOD_NS, left, T0 + PERIOD_NS - 2_000_000, right),  # 2 ms early
        (T0 + 2 * PERIOD_NS, left, T0 + 2 * PERIOD_NS, right),  # exact
    ]
    bag = write_bag(tmp_path / "rig", frames)
    with BagCamera(bag, max_skew_ms=2.0) as cam:
        list(cam.frames())
    assert cam.stamps_ns == [T0, T0 + PERIOD_NS, T0 + 2 * PERIOD_NS]
    assert cam.dropped == {"left": 0, "right": 0}
    with BagCamera(bag, max_skew_ms=0) as cam:
        list(cam.frames())
    assert cam.stamps_ns == [T0 + 2 * PERIOD_NS]
    assert cam.dropped == {"left": 2, "right": 2}
    with pytest.raises(ValueError, match="max_skew_ms: expected a number >= 0"):
        BagCamera(bag, max_skew_ms=-1)
    # 1e308 ms: its whole nanoseconds overflowed (OverflowError: cannot convert float infinity)
    with pytest.raises(ValueError, match=r"^max_skew_ms: expected at most 1e\+06, got 1e\+308$"):
        BagCamera(bag, max_skew_ms=1e308)
    with BagCamera(bag, max_skew_ms=1e6) as cam:  # the limit itself pairs all three
        list(cam.frames())
    assert cam.stamps_ns == [T0, T0 + PERIOD_NS, T0 + 2 * PERIOD_NS]


def test_bgra16_transport_suffixes_and_positions(cones: Any, tmp_path: Path) -> None:
    """Mutation audit: ``bgra16`` keeps its channel order, every image_transport suffix
    (``zstd`` too) is taken off a topic, and a frame's ``pos_*_ms`` are milliseconds."""
    from stereovision.rosbag import _base_topic

    bgr = cones.left[:32, :48]
    h, w = bgr.shape[:2]
    c16 = (bgr.astype(np.uint16) << 8) | 3
    bgra = np.ascontiguousarray(np.dstack([c16, np.full((h, w), 65535, np.uint16)])).astype("<u2")
    msg = _Msg(height=h, width=w, encoding="bgra16", is_bigendian=0, step=8 * w,
               data=bgra.view(np.uint8).reshape(-1))  # fmt: skip
    np.testing.assert_array_equal(decode_image(msg), c16)
    for suffix in ("compressed", "theora", "ffmpeg", "zstd"):
        assert _base_topic(f"/cam/image_raw/{suffix}") == "/cam/image_raw"
    left, right = cones.left[:64, :96], cones.right[:64, :96]
    bag = write_bag(tmp_path / "rig", [(T0 + k * PERIOD_NS, left, T0 + k * PERIOD_NS, right)
                                       for k in range(3)])  # fmt: skip
    with BagCamera(bag) as cam:
        got = list(cam.frames())
    # the bag starts at the first message's recording time, 2 ms after its stamp
    assert [f.pos_left_ms for f in got] == pytest.approx(
        [-2 + k * PERIOD_NS / 1e6 for k in range(3)]
    )
    assert [f.pos_right_ms for f in got] == pytest.approx(
        [-2 + k * PERIOD_NS / 1e6 for k in range(3)]
    )


def test_a_pair_exactly_max_skew_ms_apart_is_paired_for_any_decimal_value(
    cones: Any, tmp_path: Path
) -> None:
    """``max_skew_ms * 1e6`` in floats is 4099999.9999999995 ns for 4.1 ms (and just under
    the value for 33.3, 2.01, 1.001, ... ms), so a pair exactly 4.1 ms apart was still refused;
    the tolerance is the whole nanoseconds of the value given."""
    left, right = cones.left[:64, :96], cones.right[:64, :96]
    frames = [
        (T0, left, T0 + 4_100_000, right),  # right 4.1 ms late
        (T0 + PERIOD_NS, left, T0 + PERIOD_NS - 4_100_000, right),  # 4.1 ms early
        (T0 + 2 * PERIOD_NS, left, T0 + 2 * PERIOD_NS + 4_100_001, right),  # 1 ns past it
    ]
    bag = write_bag(tmp_path / "rig", frames)
    with BagCamera(bag, max_skew_ms=4.1) as cam:
        list(cam.frames())
    assert cam.stamps_ns == [T0, T0 + PERIOD_NS]
    assert cam.dropped == {"left": 1, "right": 1}
    assert cam.max_skew_ms == 4.1


def test_binning_scales_each_axis_by_its_own_factor(cones: Any, tmp_path: Path) -> None:
    """binning_y alone (1 x 2) halves the rows only; a binned pixel is the centre of its b
    sensor pixels: f' = f / b, c' = (c + 0.5) / b - 0.5 on each axis. 375 rows binned by 2 are
    187, and the scale was taken as 187 / 375 (fy 419.8 -> 209.34, not 209.9; cy 0.25 px
    off) instead of 1 / 2."""
    raw = _raw_rig()
    cams = tuple(parse_ros_camera_info(t) for t in raw.to_ros())
    frames = [(T0, cones.left, T0, cones.right)]
    for name, binning, b in (("y2", (1, 2), (1, 2)), ("x3y2", (3, 2), (3, 2)), ("zero", 0, (1, 1))):
        bag = write_bag(tmp_path / name, frames, infos=cams, binning=binning)
        with BagCamera(bag) as cam:
            got = cam.calibration()
        assert got.image_size == (450 // b[0], 375 // b[1])
        for k_got, k_raw in ((got.K1, raw.K1), (got.K2, raw.K2)):
            np.testing.assert_allclose(k_got[0, 0], k_raw[0, 0] / b[0], rtol=1e-12)
            np.testing.assert_allclose(k_got[1, 1], k_raw[1, 1] / b[1], rtol=1e-12)
            np.testing.assert_allclose(k_got[0, 2], (k_raw[0, 2] + 0.5) / b[0] - 0.5, rtol=1e-12)
            np.testing.assert_allclose(k_got[1, 2], (k_raw[1, 2] + 0.5) / b[1] - 0.5, rtol=1e-12)
        np.testing.assert_allclose(got.T, raw.T, atol=1e-9)  # the rig is the same


def test_a_camera_info_with_a_region_of_interest_is_refused(cones: Any, tmp_path: Path) -> None:
    """A camera_info whose roi is a part of the image (a cropped camera) is refused, naming
    the topic and the region; a zero roi (unset) and one of the whole image are the camera's."""
    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    frames = [(T0, cones.left, T0, cones.right)]
    bag = write_bag(tmp_path / "crop", frames, infos=cams, roi=(10, 20, 200, 100))
    with BagCamera(bag) as cam, pytest.raises(ValueError) as err:
        cam.calibration()
    assert str(err.value) == (
        "/stereo/left/camera_info: camera_info has a region of interest (200x100 at 10,20); "
        "cropped cameras are not supported"
    )
    for name, roi in (("whole", (0, 0, 450, 375)), ("unset", (0, 0, 0, 0))):
        with BagCamera(write_bag(tmp_path / name, frames, infos=cams, roi=roi)) as cam:
            assert cam.calibration().image_size == (450, 375)


def test_a_camera_info_with_a_half_zero_region_of_interest_is_refused(
    cones: Any, tmp_path: Path
) -> None:
    """ROS reads a roi of all zeros as the full image; one with a width and no height (or the
    reverse) is malformed, and was taken for the full image without a word (the check needed
    both sizes). It is refused naming the topic and the roi."""
    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    frames = [(T0, cones.left, T0, cones.right)]
    for name, roi in (("no_height", (0, 0, 450, 0)), ("no_width", (10, 20, 0, 100))):
        bag = write_bag(tmp_path / name, frames, infos=cams, roi=roi)
        with BagCamera(bag) as cam, pytest.raises(ValueError) as err:
            cam.calibration()
        assert str(err.value) == (
            f"/stereo/left/camera_info: camera_info has a malformed region of interest "
            f"({roi[2]}x{roi[3]} at {roi[0]},{roi[1]}): a zero width or height alone describes "
            "no region (ROS's all-zero roi means the full image)"
        )


def test_the_default_tolerance_is_half_the_faster_topics_period(cones: Any, tmp_path: Path) -> None:
    """Left at 25 fps, right at 16.7 fps: max_skew_ms is half the left's 40 ms period (the
    median of the first PERIOD_SAMPLE steps: a frame 5 ms late and a missing one, an 80 ms
    step, do not move it); a right frame exactly 20 ms from its left one pairs, one 40 ms away
    does not."""
    left, right = cones.left[:64, :96], cones.right[:64, :96]
    ms = 1_000_000
    lefts = [T0 + k * 40 * ms for k in range(13) if k != 5]  # frame 5 (200 ms) lost
    lefts[3] += 5 * ms  # one late frame among the first eight
    rights = [T0 + k * 60 * ms for k in range(8)]
    frames = [(sl, left, None, right) for sl in lefts] + [(None, left, sr, right) for sr in rights]
    bag = write_bag(tmp_path / "rates", frames)
    with BagCamera(bag) as cam:
        list(cam.frames())
    assert cam.max_skew_ms == 20.0
    # lefts 0, 40, 80, 125, 160, 240, ... ms; rights 0, 60, 120, ...: 40-60 (20 ms) pairs, 80
    # has none within 20 ms (60 taken, 120 40 ms away), 125-120, 160-180, 240-240, 280-300,
    # 320 none, 360-360, 400-420, 440 and 480 none
    assert cam.stamps_ns == [lefts[k] for k in (0, 1, 3, 4, 5, 6, 8, 9)]
    assert cam.skews_ms == pytest.approx([0, 20, 5, 20, 0, 20, 0, 20], abs=1e-3)
    assert cam.dropped == {"left": 4, "right": 0}


def test_an_equal_distance_tie_takes_the_earlier_right_frame(cones: Any, tmp_path: Path) -> None:
    """A left frame 2 ms from two right frames pairs with the earlier: the later one stays for
    the next left frame (2 pairs); taking the later one would leave the earlier unpaired and
    the next left frame without a partner (1 pair)."""
    left, right = cones.left[:64, :96], cones.right[:64, :96]
    ms = 1_000_000
    frames = [(T0, left, T0 - 2 * ms, right), (T0 + 4 * ms, left, T0 + 2 * ms, right)]
    with BagCamera(write_bag(tmp_path / "tie", frames), max_skew_ms=2) as cam:
        got = list(cam.frames())
    assert [(f.t_left, f.t_right) for f in got] == [
        ((T0) / 1e9, (T0 - 2 * ms) / 1e9),
        ((T0 + 4 * ms) / 1e9, (T0 + 2 * ms) / 1e9),
    ]
    assert cam.dropped == {"left": 0, "right": 0}


def test_a_rig_whose_cameras_bin_differently_is_refused(cones: Any, tmp_path: Path) -> None:
    """Left binned 2 x 2, right not: both were scaled by the larger binning (the right camera's
    calibration at half its size, without a word). It is refused, naming both."""
    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    frames = [(T0, cones.left, T0, cones.right)]
    bag = write_bag(tmp_path / "mixed", frames, infos=cams, binning=[(2, 2), (1, 1)])
    with BagCamera(bag) as cam, pytest.raises(ValueError) as err:
        cam.calibration()
    assert str(err.value) == (
        "/stereo/left/camera_info and /stereo/right/camera_info bin differently (2x2 and 1x1): "
        "a stereo pair's cameras must run in one mode"
    )
    # binning 0 (unset) is 1
    bag = write_bag(tmp_path / "same", frames, infos=cams, binning=[(0, 0), (1, 1)])
    with BagCamera(bag) as cam:
        assert cam.calibration().image_size == (450, 375)


def test_ros_encoding_names_aliases_and_16_bit_bayer(cones: Any) -> None:
    """Second mutation audit: ROS spells the generic encodings in capitals (``16UC1``,
    ``8UC3``; read as ``mono16`` and ``bgr8``), ``uyvy`` and ``yuyv`` are ``yuv422`` and
    ``yuv422_yuy2``, the 16-bit Bayer patterns keep red and blue as the 8-bit ones, and an
    empty (0 x 0) image is refused as one the message does not hold."""
    bgr, grey = cones.left, cv2.cvtColor(cones.left, cv2.COLOR_BGR2GRAY)
    g12 = grey.astype(np.uint16) << 4
    mono16 = _image_fields(g12, "mono16", pad=2)
    np.testing.assert_array_equal(decode_image(_Msg(**{**mono16, "encoding": "16UC1"})),
                                  decode_image(_Msg(**mono16)))  # fmt: skip
    assert decode_image(_Msg(**{**mono16, "encoding": "16UC1"})).dtype == np.uint16
    bgr8 = _image_fields(bgr, "bgr8", pad=1)
    np.testing.assert_array_equal(decode_image(_Msg(**{**bgr8, "encoding": "8UC3"})), bgr)
    for alias, layout in (("uyvy", "yuv422"), ("yuyv", "yuv422_yuy2")):
        fields = _image_fields(grey, layout)
        np.testing.assert_array_equal(decode_image(_Msg(**{**fields, "encoding": alias})),
                                      decode_image(_Msg(**fields)))  # fmt: skip
    smooth = cv2.GaussianBlur(bgr, (0, 0), 2.0)
    for pattern in ("rggb", "bggr", "gbrg", "grbg"):
        raw = decode_image(_Msg(**_image_fields(smooth.astype(np.uint16) << 8,
                                                f"bayer_{pattern}16")))  # fmt: skip
        assert raw.dtype == np.uint16 and raw.shape == bgr.shape
        eight = decode_image(_Msg(**_image_fields(smooth, f"bayer_{pattern}8")))
        # OpenCV interpolates the 16-bit data before the shift: rounding, 1 level at most
        np.testing.assert_allclose(to_8bit(raw)[0], eight, atol=1)
    empty = {"height": 0, "width": 0, "encoding": "mono8", "is_bigendian": 0, "step": 0,
             "data": np.zeros(0, np.uint8)}  # fmt: skip
    with pytest.raises(ValueError, match=r"mono8 image of 0x0 px: .* do not hold it"):
        decode_image(_Msg(**empty))


def test_compressed_bgra_and_16_bit_png(cones: Any) -> None:
    """Second mutation audit: a PNG with alpha comes out BGR (3 channels), and a 16-bit PNG
    (12-bit data) stays 16-bit, so :func:`to_8bit` shifts it by 4 (read as 8 bits it was
    divided by 256: nearly black)."""
    bgr = cones.left
    bgra = np.dstack([bgr, np.full(bgr.shape[:2], 200, np.uint8)])
    _ok, png = cv2.imencode(".png", bgra)
    np.testing.assert_array_equal(decode_image(_Msg(format="bgra8; png", data=png.reshape(-1))),
                                  bgr)  # fmt: skip
    grey = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
    _ok, png16 = cv2.imencode(".png", grey.astype(np.uint16) << 4)
    out = decode_image(_Msg(format="mono16; png compressed mono16", data=png16.reshape(-1)))
    assert out.dtype == np.uint16 and out.shape == bgr.shape
    np.testing.assert_array_equal(to_8bit(out)[0][..., 0], grey)


def test_a_nearer_right_frame_drops_the_one_before_and_the_end_says_so(
    cones: Any, tmp_path: Path
) -> None:
    """Second mutation audit: a left frame with two right frames within ``max_skew_ms`` pairs
    with the nearer, and the one passed over is counted dropped; the end-of-recording error
    says how many of each side found no partner (the sides in their places)."""
    left, right = cones.left[:64, :96], cones.right[:64, :96]
    ms = 1_000_000
    frames = [(T0, left, T0 - 3 * ms // 2, right), (None, left, T0 + ms // 2, right)]
    with BagCamera(write_bag(tmp_path / "near", frames), max_skew_ms=2) as cam:
        got = list(cam.frames())
        with pytest.raises(SourceError) as err:
            cam.read()
    assert [(f.t_left, f.t_right) for f in got] == [(T0 / 1e9, (T0 + ms // 2) / 1e9)]
    assert cam.dropped == {"left": 0, "right": 1}
    assert str(err.value).endswith(
        "end of the recording after 1 pair (0 left and 1 right frames without a partner)"
    )
    # two lefts, one right: the left passed over is counted on its side
    frames = [(T0, left, T0, right), (T0 + 40 * ms, left, None, right)]
    with BagCamera(write_bag(tmp_path / "lone", frames), max_skew_ms=2) as cam:
        list(cam.frames())
        with pytest.raises(SourceError, match=r"\(1 left and 0 right frames without"):
            cam.read()


def test_the_default_tolerance_waits_for_both_topics_and_skips_repeated_stamps(
    cones: Any, tmp_path: Path
) -> None:
    """Second mutation audit of the default ``max_skew_ms`` (half the faster topic's period):
    a faster right topic that starts late is waited for (10 ms for 50 fps, not the 25 fps
    left's 20 ms, decided before the right's first frame); a stamp sent again (a step of 0)
    is no period (it made the tolerance 0: no pair); a bag of one frame a side has no period
    and pairs its two frames."""
    left, right = cones.left[:64, :96], cones.right[:64, :96]
    ms = 1_000_000
    frames = [(T0 + k * 40 * ms, left, None, right) for k in range(30)]
    frames += [(None, left, T0 + 400 * ms + k * 20 * ms, right) for k in range(20)]
    with BagCamera(write_bag(tmp_path / "late", frames)) as cam:
        list(cam.frames())
    assert cam.max_skew_ms == 10.0
    # left stamps 0, 0, 0, 40, 40, 40, 80, 80, ... ms (each frame sent three times)
    lefts = [T0 + (k // 3) * 40 * ms for k in range(24)]
    frames = [(sl, left, None, right) for sl in lefts]
    frames += [(None, left, T0 + k * 40 * ms + 3 * ms, right) for k in range(8)]
    with BagCamera(write_bag(tmp_path / "repeated", frames)) as cam:
        got = list(cam.frames())
    assert cam.max_skew_ms == 20.0
    assert [f.skew_ms for f in got] == pytest.approx([3.0] * 8, abs=1e-3)
    with BagCamera(write_bag(tmp_path / "one", [(T0, left, T0 + 3 * ms, right)])) as cam:
        got = list(cam.frames())
    assert len(got) == 1 and cam.max_skew_ms == math.inf and cam.dropped == {"left": 0, "right": 0}


def test_camera_info_beside_a_compressed_image_topic(cones: Any, tmp_path: Path) -> None:
    """Second mutation audit: the camera_info of ``.../image_raw/compressed`` is the one
    beside ``.../image_raw`` (image_transport's suffix is no part of the camera's name)."""
    from rosbags.rosbag2 import Reader, Writer

    raw = _raw_rig()
    cams = tuple(parse_ros_camera_info(t) for t in raw.to_ros())
    src = write_bag(tmp_path / "src", [(T0, cones.left, T0, cones.right)], encoding="png",
                    infos=cams)  # fmt: skip
    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(src) as r, Writer(tmp_path / "rig", version=9) as w:
        conns: dict[str, Any] = {}
        for conn, stamp, data in r.messages():
            topic = conn.topic + "/compressed" if conn.topic in (LEFT, RIGHT) else conn.topic
            if topic not in conns:
                conns[topic] = w.add_connection(topic, conn.msgtype, typestore=ts)
            w.write(conns[topic], stamp, data)
    with BagCamera(tmp_path / "rig") as cam:
        assert cam.topics == {"left": LEFT + "/compressed", "right": RIGHT + "/compressed"}
        assert cam.info_topics == {"left": "/stereo/left/camera_info",
                                   "right": "/stereo/right/camera_info"}  # fmt: skip
        got = cam.calibration()
        np.testing.assert_array_equal(cam.read().left, cones.left)
    np.testing.assert_allclose(got.K1, raw.K1)
    np.testing.assert_allclose(got.T, raw.T, atol=1e-9)


def test_a_camera_info_topic_without_messages_is_no_calibration(cones: Any, tmp_path: Path) -> None:
    """A bag whose camera_info topics were recorded but never published (ROS 2 keeps a topic
    subscribed to and never heard, 0 messages): ``calibration()`` raised StopIteration (past
    ``info``'s and ``stream``'s error handling); the topic is taken as absent, so there is
    no calibration (None) and the commands ask for one."""
    from rosbags.rosbag2 import Reader, Writer

    src = write_bag(tmp_path / "src", [(T0, cones.left, T0, cones.right)])
    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(src) as r, Writer(tmp_path / "rig", version=9) as w:
        conns: dict[str, Any] = {}
        for conn, stamp, data in r.messages():
            if conn.topic not in conns:
                conns[conn.topic] = w.add_connection(conn.topic, conn.msgtype, typestore=ts)
            w.write(conns[conn.topic], stamp, data)
        for side in ("left", "right"):
            w.add_connection(f"/stereo/{side}/camera_info", CAMERA_INFO, typestore=ts)
    with BagCamera(tmp_path / "rig") as cam:
        assert cam.info_topics == {"left": None, "right": None}
        assert cam.calibration() is None
        np.testing.assert_array_equal(cam.read().left, cones.left)


def test_image_topics_sharing_one_camera_info_topic_are_said_not_taken_for_monocular(
    tmp_path: Path,
) -> None:
    """``/cam/image_left`` and ``/cam/image_right`` have one ``/cam/camera_info`` beside them:
    its first message (the left camera's) was read for both, and the stereo rig refused as "two
    monocular calibrations" (no baseline). The shared topic is named, with the remedy."""
    cams = tuple(
        {"image_size": (6, 4), "distortion_model": "plumb_bob", "D": np.zeros(5),
         "K": np.eye(3), "R": np.eye(3), "P": np.hstack([np.eye(3), [[-tx], [0], [0]]])}
        for tx in (0.0, 0.12)
    )  # fmt: skip
    tiny = np.zeros((4, 6, 3), np.uint8)
    topics = ("/cam/image_left", "/cam/image_right")
    bag = write_bag(tmp_path / "rig.bag", [(T0, tiny, T0, tiny)], flavour="ros1", topics=topics,
                    infos=cams)  # fmt: skip
    with BagCamera(bag) as cam, pytest.raises(ValueError) as err:
        cam.calibration()
    assert str(err.value) == (
        f"bag {bag}: /cam/image_left and /cam/image_right share one camera_info topic "
        "(/cam/camera_info), so which camera a message describes is not known: give the rig's "
        "calibration (--calib RIG)"
    )


def test_the_camera_info_of_uncalibrated_cameras_is_no_calibration(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A driver without a calibration file (usb_cam, through camera_info_manager) publishes
    its camera_info all zeros but the size, which ROS takes as uncalibrated (``K[0] == 0``).
    ``calibration()`` refused it ("rectification_matrix does not hold a rotation"), so
    ``stream --from-bag`` and ``info`` failed (exit 2) on a bag that reads whole; it is no
    calibration now (None), as a bag without camera_info, and the commands say why."""
    zero = {"image_size": (450, 375), "distortion_model": "", "D": np.zeros(0),
            "K": np.zeros((3, 3)), "R": np.zeros((3, 3)), "P": np.zeros((3, 4))}  # fmt: skip
    calibrated = parse_ros_camera_info(_raw_rig().to_ros()[1])
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + k * PERIOD_NS, cones.right) for k in range(2)]
    for flavour, name, infos in (
        ("ros2", "rig", (zero, zero)),
        ("ros1", "rig.bag", (zero, zero)),
        ("ros2", "half", (zero, calibrated)),  # one camera uncalibrated: no rig either
        ("ros2", "rect", (zero, zero)),
    ):
        topics = ("/stereo/left/image_rect", "/stereo/right/image_rect") if name == "rect" else (
            LEFT, RIGHT)  # fmt: skip
        (tmp_path / flavour).mkdir(exist_ok=True)
        bag = write_bag(tmp_path / flavour / name, frames, flavour=flavour, infos=infos,
                        topics=topics)  # fmt: skip
        with BagCamera(bag) as cam:
            assert None not in cam.info_topics.values()
            assert cam.calibration() is None, (flavour, name)
    for bag in (tmp_path / "ros2" / "half", tmp_path / "ros2" / "rig"):
        code, out, err = run("info", str(bag))
        assert code == 0, err
        assert "camera_info say a camera is uncalibrated (K = 0)" in out
    code, out, err = run("stream", "--from-bag", str(bag), "--no-display", "--json",
                         "--method", "gabor", "--max-disparity", "64", "--no-check")  # fmt: skip
    assert code == 0, err
    assert json.loads(out.strip().splitlines()[-1])["frames"] == 2
    assert "say a camera is uncalibrated (K = 0): disparity only" in err


def test_a_bag_with_one_cameras_camera_info_says_which_is_missing(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A bag recorded with the left camera's camera_info but not the right's: ``info`` said
    "no camera_info beside the image topics" under its own listing of the left one ("<- left
    camera_info"), and ``stream`` gave disparity only without a word. Both name the topic
    without one now."""
    from rosbags.rosbag1 import Reader, Writer

    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    small = (cones.left[:60, :90], cones.right[:60, :90])  # quick
    src = write_bag(tmp_path / "src.bag", [(T0, *small[:1], T0, *small[1:])], flavour="ros1",
                    infos=cams)  # fmt: skip
    bag = tmp_path / "rig.bag"
    with Reader(src) as r, Writer(bag) as w:
        conns: dict[str, Any] = {}
        for conn, stamp, data in r.messages():
            if conn.topic == "/stereo/right/camera_info":
                continue
            if conn.topic not in conns:
                conns[conn.topic] = w.add_connection(
                    conn.topic, conn.msgtype, msgdef=conn.msgdef.data, md5sum=conn.digest
                )
            w.write(conns[conn.topic], stamp, data)
    code, out, err = run("info", str(bag))
    assert code == 0, err
    assert out.splitlines()[-1] == (
        f"no camera_info beside {RIGHT} (the bag's /stereo/left/camera_info is the other "
        "camera's alone): give the rig's calibration to the command that reads the bag "
        "(stream --from-bag BAG --calib RIG)"
    )
    code, out, err = run("stream", "--from-bag", str(bag), "--no-display", "--method", "fast",
                         "--max-disparity", "16", "--no-check")  # fmt: skip
    assert code == 0, err
    assert (
        "calibration: none; the bag holds /stereo/left/camera_info but no camera_info beside "
        f"{RIGHT}: disparity only (--calib RIG for depth)"
    ) in err.splitlines()


def test_a_bag_without_camera_info_says_the_stream_has_no_calibration(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A bag recorded without any camera_info: ``stream --from-bag`` gave disparity only
    without a word about the calibration (one camera's alone, or uncalibrated ones, are said).
    It says so now, naming both image topics."""
    small = (cones.left[:60, :90], cones.right[:60, :90])  # quick
    bag = write_bag(tmp_path / "bare", [(T0, small[0], T0, small[1])])
    code, _, err = run("stream", "--from-bag", str(bag), "--no-display", "--method", "fast",
                         "--max-disparity", "16", "--no-check")  # fmt: skip
    assert code == 0, err
    assert (
        f"calibration: none; the bag holds no camera_info beside {LEFT} and {RIGHT}: disparity "
        "only (--calib RIG for depth)"
    ) in err.splitlines()


def test_rectified_topics_whose_camera_info_fills_p_only_keep_their_calibration(
    cones: Any, tmp_path: Path
) -> None:
    """``image_rect`` topics are calibrated by their ``P`` matrices alone (K, D and R are
    replaced by P's, as ``stereo_image_proc`` reads them): a camera_info with ``K`` all zeros
    but a valid ``P`` gave that calibration, until c10a691 took ``K[0] == 0`` as an
    uncalibrated camera for rectified topics too (None: disparity only, without a word).
    For them the test is ``P[0] == 0``; raw topics, which need K, keep ``K[0] == 0``."""
    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    p_only = tuple(c | {"K": np.zeros((3, 3)), "R": np.zeros((3, 3)), "D": np.zeros(0),
                        "distortion_model": ""} for c in cams)  # fmt: skip
    frames = [(T0, cones.left, T0, cones.right)]
    rect = ("/stereo/left/image_rect", "/stereo/right/image_rect")
    with BagCamera(write_bag(tmp_path / "rect", frames, topics=rect, infos=p_only)) as cam:
        got = cam.calibration()
    assert got is not None and got.rectified
    np.testing.assert_allclose(got.K1, cams[0]["P"][:, :3])
    assert got.baseline_m == pytest.approx(-cams[1]["P"][0, 3] / cams[1]["P"][0, 0])
    # raw topics cannot be rectified without K: no calibration, as before
    with BagCamera(write_bag(tmp_path / "raw", frames, infos=p_only)) as cam:
        assert cam.calibration() is None
    # rectified topics with a P of zeros (an uncalibrated camera's, K valid) are none too
    no_p = (cams[0] | {"P": np.zeros((3, 4))}, cams[1])
    with BagCamera(write_bag(tmp_path / "rect0", frames, topics=rect, infos=no_p)) as cam:
        assert cam.calibration() is None


def test_a_topic_recorded_with_two_types_is_listed_with_both(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A ROS 1 bag whose ``/status`` was published with two types (two connections, as
    ``rosbag record -a`` keeps them): rosbags' summary gives that topic no type (None), and
    ``info`` of the whole bag (``BagCamera.summary``) was "internal TypeError: unsupported
    format string passed to NoneType.__format__". The topic is listed with both types."""
    from rosbags.rosbag1 import Writer

    ts = get_typestore(Stores.ROS1_NOETIC)
    t = ts.types
    bag = tmp_path / "mixed.bag"
    with Writer(bag) as w:
        images = {
            s: w.add_connection(s, "sensor_msgs/msg/Image", typestore=ts) for s in (LEFT, RIGHT)
        }
        status = [w.add_connection("/status", f"std_msgs/msg/{n}", typestore=ts)
                  for n in ("String", "Int32")]  # fmt: skip
        for k in range(2):
            st = T0 + k * PERIOD_NS
            stamp = t["builtin_interfaces/msg/Time"](sec=st // 10**9, nanosec=st % 10**9)
            header = t["std_msgs/msg/Header"](seq=k, stamp=stamp, frame_id="cam")
            for topic, img in ((LEFT, cones.left), (RIGHT, cones.right)):
                msg = t["sensor_msgs/msg/Image"](header=header, **_image_fields(img, "bgr8"))
                w.write(images[topic], st, ts.serialize_ros1(msg, "sensor_msgs/msg/Image"))
            said = (t["std_msgs/msg/String"](data="ok"), t["std_msgs/msg/Int32"](data=k))
            for conn, msg in zip(status, said, strict=True):
                w.write(conn, st, ts.serialize_ros1(msg, conn.msgtype))
    code, out, err = run("info", str(bag))
    assert code == 0, err
    line = next(ln for ln in out.splitlines() if ln.startswith("  /status"))
    assert "std_msgs/msg/Int32 or std_msgs/msg/String" in line and " 4 msgs " in line
    with BagCamera(bag) as cam:
        assert "<- left" in cam.summary()
        np.testing.assert_array_equal(cam.read().left, cones.left)


def test_small_reader_cases_a_third_mutation_round_found_untested(
    cones: Any, tmp_path: Path
) -> None:
    """Mutation audit: compressed data of 0 bytes is a ValueError (OpenCV raised its own
    error); names that differ past their number are no camera pair (``camera0`` /
    ``camera1_depth``); 16-bit images dimmer than 8 bits are not shifted (a negative shift);
    a camera_info beside one image topic only is no calibration (None); an empty
    ``distortion_model`` is ROS's default ``plumb_bob``."""
    with pytest.raises(ValueError, match=r"compressed image \('jpeg', 0 bytes\) does not decode"):
        decode_image(_Msg(format="jpeg", data=np.zeros(0, np.uint8)))
    with pytest.raises(ValueError, match="no left/right pair"):
        find_stereo_topics(["/camera0/image_raw", "/camera1_depth/image_raw"])
    dim = np.array([[0, 3], [100, 27]], np.uint16)  # 7 bits
    np.testing.assert_array_equal(to_8bit(dim)[0], dim.astype(np.uint8))
    raw = _raw_rig()
    cams = tuple(parse_ros_camera_info(t) for t in raw.to_ros())
    frames = [(T0, cones.left, T0, cones.right)]
    bag = write_bag(tmp_path / "one_info", frames, infos=cams)
    from rosbags.rosbag2 import Reader, Writer

    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(bag) as r, Writer(tmp_path / "left_info", version=9) as w:
        conns: dict[str, Any] = {}
        for conn, stamp, data in r.messages():
            if conn.topic == "/stereo/right/camera_info":
                continue
            if conn.topic not in conns:
                conns[conn.topic] = w.add_connection(conn.topic, conn.msgtype, typestore=ts)
            w.write(conns[conn.topic], stamp, data)
    with BagCamera(tmp_path / "left_info") as cam:
        assert cam.info_topics == {"left": "/stereo/left/camera_info", "right": None}
        assert cam.calibration() is None
    unset = tuple({**c, "distortion_model": ""} for c in cams)
    with BagCamera(write_bag(tmp_path / "unset", frames, infos=unset)) as cam:
        got = cam.calibration()
    with BagCamera(bag) as cam:
        assert got == cam.calibration()
    np.testing.assert_allclose(got.D1, raw.D1)


@pytest.mark.parametrize("flavour", ["ros2", "mcap"])
def test_the_storage_file_of_a_bag_without_metadata_is_a_bag(
    cones: Any, tmp_path: Path, flavour: str, run: Callable[..., tuple[int, str, str]]
) -> None:
    """BagCamera reads the ``.db3`` / ``.mcap`` file of a bag whose recorder left no
    metadata.yaml, but ``is_bag`` said no, so ``stereovision info`` took it for a calibration
    ("not a text calibration file"); such a file is a bag."""
    from stereovision.rosbag import is_bag

    bag = write_bag(tmp_path / "rig", [(T0, cones.left, T0, cones.right)], flavour=flavour)
    (bag / "metadata.yaml").unlink()
    (storage,) = bag.iterdir()
    assert is_bag(storage)
    with BagCamera(storage) as cam:
        np.testing.assert_array_equal(cam.read().left, cones.left)
    code, out, _ = run("info", str(storage))
    assert code == 0 and out.startswith(f"bag {storage} (ROS 2")
    assert "no camera_info beside the image topics" in out
    (tmp_path / "rig.yaml").write_text("x")
    assert not is_bag(tmp_path / "rig.yaml")


def test_a_resized_pair_keeps_the_recorded_frames_and_describe_says_the_tolerance(
    cones: Any, tmp_path: Path
) -> None:
    """Mutation audit: a pair resized to ``image_size`` carries the frames as recorded
    (``delivered``; None when nothing was resized), and ``describe`` says ``auto`` until the
    default tolerance is known, then its value."""
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + k * PERIOD_NS, cones.right) for k in range(3)]
    bag = write_bag(tmp_path / "rig", frames)
    with BagCamera(bag, image_size="225x188") as cam:
        assert cam.describe().endswith("; max skew: auto")
        f = cam.read()
        assert f.left.shape == (188, 225, 3) and f.delivered is not None
        np.testing.assert_array_equal(f.delivered[0], cones.left)
        np.testing.assert_array_equal(f.delivered[1], cones.right)
        assert cam.describe().endswith("; max skew 16.7 ms")
    with BagCamera(bag) as cam:
        assert cam.read().delivered is None


@pytest.mark.parametrize("encoding", ["bgr8", "png"])
def test_capture_from_bag_says_the_recorded_size_before_the_first_pair(
    encoding: str, cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """``capture --from-bag``'s header is said before the first read, and said the image size
    as "? @ 30 fps"; it is the first recorded frames' (a raw Image's fields, a compressed one
    decoded), as a camera's is read back once opened. A topic without a frame leaves it out."""
    small = cones.left[:48, :64], cones.right[:24, :32]
    frames = [(T0 + k * PERIOD_NS, small[0], T0 + k * PERIOD_NS, small[1]) for k in range(3)]
    bag = write_bag(tmp_path / "rig", frames, encoding=encoding)
    with BagCamera(bag) as cam:
        said = cam.describe()
        assert f"; left {LEFT}: 64x48 @ 30 fps; right {RIGHT}: 32x24 @ 30 fps; " in said
        assert cam.delivered_size == {}  # nothing delivered yet
    code, out, err = run("capture", "--from-bag", str(bag), "-o", str(tmp_path / "pairs"))
    assert code == 0, err
    assert out.splitlines()[0] == (
        f"bag {bag}; left {LEFT}: 64x48 @ 30 fps; right {RIGHT}: 32x24 @ 30 fps; max skew: auto"
    )
    with BagCamera(bag) as cam:
        cam.topics = {"left": LEFT, "right": "/no/such/topic"}
        assert "; right /no/such/topic: 30 fps; " in cam.describe()


@PIPELINED
def test_the_size_warnings_of_a_bag_point_at_the_callers_line(cones: Any, tmp_path: Path) -> None:
    """The dropped-size and resized-topic warnings had ``stacklevel=4``, right through
    ``frames()`` only: a ``read()`` of the user's was attributed to the line that called the
    user's function (pytest's), ``capture()``'s to capture.py. Each is the caller's line now;
    through ``frames()`` it is the user's ``for`` (the generator's caller)."""
    from stereovision.capture import capture

    half = cv2.resize(cones.right, (225, 188), interpolation=cv2.INTER_AREA)
    frames = [(T0 + k * PERIOD_NS, cones.left, T0 + k * PERIOD_NS, half) for k in range(2)]
    bag = write_bag(tmp_path / "rig", frames, encoding="png")
    want = ["size 450x200 is another shape", f"{RIGHT} is 225x188, not 450x375"]
    with (
        warnings.catch_warnings(record=True) as caught,
        BagCamera(bag, image_size="450x200") as cam,
    ):
        warnings.simplefilter("always")
        cam.read()
    said = [(str(w.message), w.filename) for w in caught]
    assert [(m[: len(t)], f) for (m, f), t in zip(said, want, strict=True)] == [
        (t, __file__) for t in want
    ]
    with (
        warnings.catch_warnings(record=True) as caught,
        BagCamera(bag, image_size="450x200") as cam,
    ):
        warnings.simplefilter("always")
        for _ in cam.frames():
            pass
    assert [w.filename for w in caught] == [__file__, __file__]
    with (
        warnings.catch_warnings(record=True) as caught,
        BagCamera(bag, image_size="450x200") as cam,
    ):
        warnings.simplefilter("always")
        capture(cam, tmp_path / "pairs")
    assert [w.filename for w in caught if "450x" in str(w.message)] == [__file__, __file__]
    from stereovision.stream import run_stream

    with (
        warnings.catch_warnings(record=True) as caught,
        BagCamera(bag, image_size="450x200") as cam,
    ):
        warnings.simplefilter("always")
        run_stream(cam, max_disparity=16, check=False)  # read in the stream's grabbing thread
    assert [w.filename for w in caught if "450x" in str(w.message)] == [__file__, __file__]


def test_generic_encodings_and_rgba16_read_as_their_named_layouts(cones: Any) -> None:
    """Fourth mutation audit: the generic names ``8UC1``, ``8UC4``, ``16UC3`` and ``16UC4``
    were read in no test (one taken as 16-bit, or as RGB(A), went unseen), nor ``rgba16``'s
    channel order: each decodes as its layout's source image."""
    bgr = cones.left[:40, :60]
    h, w = bgr.shape[:2]
    grey = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
    c16 = (bgr.astype(np.uint16) << 8) | 5

    def msg(arr: np.ndarray, encoding: str) -> _Msg:
        arr = np.ascontiguousarray(arr)
        arr = arr.astype("<u2") if arr.dtype == np.uint16 else arr
        rows = arr.view(np.uint8).reshape(h, -1)
        return _Msg(height=h, width=w, encoding=encoding, is_bigendian=0, step=rows.shape[1],
                    data=rows.reshape(-1))  # fmt: skip

    alpha8, alpha16 = np.full((h, w), 255, np.uint8), np.full((h, w), 65535, np.uint16)
    out = decode_image(msg(grey, "8UC1"))
    assert out.dtype == np.uint8
    np.testing.assert_array_equal(out, np.dstack([grey] * 3))
    np.testing.assert_array_equal(decode_image(msg(np.dstack([bgr, alpha8]), "8UC4")), bgr)
    np.testing.assert_array_equal(decode_image(msg(c16, "16UC3")), c16)
    np.testing.assert_array_equal(decode_image(msg(np.dstack([c16, alpha16]), "16UC4")), c16)
    rgba = np.dstack([c16[..., ::-1], alpha16])
    np.testing.assert_array_equal(decode_image(msg(rgba, "rgba16")), c16)


def test_raw_compressed_topics_are_preferred_to_rectified_uncompressed_ones() -> None:
    """Fourth mutation audit: raw before uncompressed, as documented (a rectified pair was
    never weighed against a compressed raw one): ``image_raw/compressed`` is taken over
    ``image_rect``, whose calibration is another rig's."""
    rect = ["/stereo/left/image_rect", "/stereo/right/image_rect"]
    raw = [LEFT + "/compressed", RIGHT + "/compressed"]
    assert find_stereo_topics(rect + raw) == tuple(raw)


def test_compressed_rectified_topics_give_the_rectified_rig(cones: Any, tmp_path: Path) -> None:
    """Fourth mutation audit: ``image_rect/compressed`` topics are rectified ones (the
    transport suffix is no part of the name): their calibration is the rectified rig of the
    two ``P`` matrices, not the raw rig of ``K`` and ``D``."""
    from rosbags.rosbag2 import Reader, Writer

    cams = tuple(parse_ros_camera_info(t) for t in _raw_rig().to_ros())
    rect = ("/stereo/left/image_rect", "/stereo/right/image_rect")
    src = write_bag(tmp_path / "src", [(T0, cones.left, T0, cones.right)], topics=rect,
                    encoding="png", infos=cams)  # fmt: skip
    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(src) as r, Writer(tmp_path / "rig", version=9) as w:
        conns: dict[str, Any] = {}
        for conn, stamp, data in r.messages():
            topic = conn.topic + "/compressed" if conn.topic in rect else conn.topic
            if topic not in conns:
                conns[topic] = w.add_connection(topic, conn.msgtype, typestore=ts)
            w.write(conns[topic], stamp, data)
    with BagCamera(tmp_path / "rig") as cam:
        assert cam.topics == {"left": rect[0] + "/compressed", "right": rect[1] + "/compressed"}
        got = cam.calibration()
    assert got.rectified
    np.testing.assert_allclose(got.K1, cams[0]["P"][:, :3])
    np.testing.assert_array_equal(got.D1, np.zeros(5))


def test_a_shape_a_few_percent_off_is_refused_and_a_size_asked_is_not_warned(
    cones: Any, tmp_path: Path
) -> None:
    """Fourth mutation audit: the shape checks allow 1 % (rounding of a half size), not more:
    a right topic 450x360 beside a 450x375 left one (4 % off) is refused as another shape,
    and a size 450x360 asked for a 450x375 recording is dropped with a warning; a size of the
    recording's shape that was asked resizes without a warning (it was only checked for a
    size that was not asked)."""
    left = cones.left
    squat = cv2.resize(cones.right, (450, 360), interpolation=cv2.INTER_AREA)
    bag = write_bag(tmp_path / "off", [(T0, left, T0, squat)], encoding="png")
    with BagCamera(bag) as cam, pytest.raises(SourceError, match=r"is 450x360, the .* 450x375"):
        cam.read()
    bag = write_bag(tmp_path / "rig", [(T0, left, T0, cones.right)], encoding="png")
    with (
        BagCamera(bag, image_size="450x360") as cam,
        pytest.warns(UserWarning, match="size 450x360 is another shape"),
    ):
        assert cam.read().left.shape == left.shape
    with BagCamera(bag, image_size="225x188") as cam, warnings.catch_warnings():
        warnings.simplefilter("error")
        assert cam.read().right.shape == (188, 225, 3)


def test_a_left_camera_that_stops_within_its_first_frames_holds_no_more_right_ones(
    cones: Any, tmp_path: Path
) -> None:
    """The left camera stops after 5 frames (fewer than PERIOD_SAMPLE), the right one goes on
    for 100: the default tolerance waited for 8 left stamps, and until then every right frame
    was held (a whole bag's right topic in memory, decoded messages); it is decided once 64
    right frames wait, as it is for 64 left ones, so at most 64 are held."""
    from stereovision import rosbag

    small_l, small_r = cones.left[:32, :48], cones.right[:32, :48]
    frames = [(T0 + k * PERIOD_NS if k < 5 else None, small_l, T0 + k * PERIOD_NS, small_r)
              for k in range(100)]  # fmt: skip
    bag = write_bag(tmp_path / "rig", frames, encoding="png")
    held: list[int] = []
    with BagCamera(bag) as cam:
        real = cam._match

        def spy(lefts: Any, rights: Any, final: bool) -> Any:
            yield from real(lefts, rights, final)
            held.append(len(rights))

        cam._match = spy  # type: ignore[method-assign]
        assert len(list(cam.frames())) == 5
    assert cam.stamps_ns == [T0 + k * PERIOD_NS for k in range(5)]
    assert cam.dropped == {"left": 0, "right": 95}
    assert max(held) <= rosbag.MAX_WAITING


def test_to_8bit_takes_an_empty_image_beside_a_16_bit_one() -> None:
    """Fourth mutation audit: an empty 16-bit image (a 0-pixel crop) sets no shift and is
    returned as an empty ``uint8`` one (numpy's max of nothing raised), the other shifted as
    alone."""
    img = np.array([[0, 1000], [4095, 16]], np.uint16)  # 12 bits: a shift of 4
    empty, out = to_8bit(np.zeros((0, 5), np.uint16), img)
    assert empty.shape == (0, 5) and empty.dtype == np.uint8
    np.testing.assert_array_equal(out, (img >> 4).astype(np.uint8))


def test_a_late_starting_faster_left_camera_keeps_the_default_tolerance(tmp_path: Path) -> None:
    """The right camera (15 fps) records 100 frames before the left one (30 fps) starts: the
    64 right frames waiting decided the default tolerance before any left stamp came, half the
    right period (33 ms) instead of half the shorter, left one (16.7 ms), and a left frame was
    paired with a right one 33 ms away. Right frames older than the first left one's nearest
    can pair with no left frame: they are dropped while the tolerance waits for its stamps."""
    img = np.zeros((16, 24, 3), np.uint8)
    start = T0 + 200 * PERIOD_NS
    frames = [(None, img, T0 + 2 * k * PERIOD_NS, img) for k in range(160)]
    frames += [(start + k * PERIOD_NS, img, None, img) for k in range(60)]
    bag = write_bag(tmp_path / "rig", frames)
    with BagCamera(bag) as cam:
        assert len(list(cam.frames())) == 30
    assert cam.max_skew_ms == pytest.approx(PERIOD_NS / 2e6)
    assert max(cam.skews_ms) == 0.0
    assert cam.dropped == {"left": 30, "right": 130}


def test_a_late_starting_faster_right_camera_keeps_the_default_tolerance(tmp_path: Path) -> None:
    """The mirror case: the left camera (15 fps) records 100 frames before the right one
    (30 fps) starts. The 64 left frames waiting decided the tolerance from the left period
    alone (33 ms), and a pair 33 ms apart came out; the oldest left frames are dropped while
    no right frame waits (as they were once the tolerance was decided), which waits for the
    right camera's stamps."""
    img = np.zeros((16, 24, 3), np.uint8)
    start = T0 + 200 * PERIOD_NS
    frames = [(T0 + 2 * k * PERIOD_NS, img, None, img) for k in range(160)]
    frames += [(None, img, start + k * PERIOD_NS, img) for k in range(60)]
    bag = write_bag(tmp_path / "rig", frames)
    with BagCamera(bag) as cam:
        assert len(list(cam.frames())) == 30
    assert cam.max_skew_ms == pytest.approx(PERIOD_NS / 2e6)
    assert max(cam.skews_ms) == 0.0
    assert cam.dropped == {"left": 130, "right": 30}


def test_of_two_right_frames_with_one_stamp_the_first_is_paired(tmp_path: Path) -> None:
    """Two right frames of one stamp (a driver that published a frame twice) before the first
    left one: the pairing takes the first, as it did before right frames older than the first
    left one were dropped while the tolerance waits for its stamps."""
    first, second = np.zeros((16, 24, 3), np.uint8), np.full((16, 24, 3), 200, np.uint8)
    frames = [(None, first, T0, first), (None, second, T0, second)]
    frames += [(T0 + 1_000_000 + k * PERIOD_NS, first, T0 + (k + 1) * PERIOD_NS, first)
               for k in range(20)]  # fmt: skip
    bag = write_bag(tmp_path / "rig", frames)
    with BagCamera(bag) as cam:
        pair = cam.read()
    assert pair.right.max() == 0


def test_a_ros1_bag_cut_short_or_unindexed_is_said_with_its_remedy(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A ROS 1 .bag cut short (an interrupted copy: its index, at its end, gone) was "not a
    readable ROS 1 or ROS 2 bag: Bag index looks damaged: ('Header could not be read from
    file.',)", one without an index (index_pos 0) "Bag is not indexed, reindex before
    reading.", neither naming the command that indexes it. Each now says what it is and the
    rosbag reindex that indexes its messages."""
    small = cones.left[:48, :64], cones.right[:48, :64]
    frames = [(T0 + i * 10**8, small[0], T0 + i * 10**8, small[1]) for i in range(4)]
    bag = write_bag(tmp_path / "whole.bag", frames, flavour="ros1")
    data = bag.read_bytes()
    at = data.index(b"index_pos=") + len(b"index_pos=")
    index_pos = int.from_bytes(data[at : at + 8], "little")
    cut = tmp_path / "cut.bag"
    cut.write_bytes(data[: len(data) // 2])
    inside = tmp_path / "inside.bag"  # cut inside its index
    inside.write_bytes(data[: index_pos + 20])
    unindexed = tmp_path / "unindexed.bag"
    unindexed.write_bytes(data[:at] + bytes(8) + data[at + 8 :])
    from stereovision.rosbag import bag_topics

    why = {
        cut: f"without its index (cut short: {len(data) // 2} bytes, the index due at byte "
        f"{index_pos}; an interrupted copy or download, a full disk?)",
        inside: "whose index is damaged (cut short?)",
        unindexed: "without its index (its recorder stopped before writing it)",
    }
    for path, words in why.items():
        said = (
            f"{path} is a ROS 1 bag {words}: `rosbag reindex {path}` indexes the messages it holds"
        )
        for call in (bag_topics, BagCamera):
            with pytest.raises(ValueError) as info:
                call(path)
            assert str(info.value) == said, (path, call)
        code, _out, err = run("stream", "--from-bag", str(path), "--no-display")
        assert code == 2 and err.strip().splitlines() == [f"stereovision: error: {said}"]
    with BagCamera(bag) as cam:  # the whole bag reads as before
        assert cam.read().left.shape == (48, 64, 3)


def test_a_bag_of_one_camera_or_none_is_not_told_to_give_two_topics(
    cones: Any, tmp_path: Path, run: Callable[..., tuple[int, str, str]]
) -> None:
    """A bag holding one camera's image topic (the other camera not recorded) or none was told
    "no left/right pair among the bag's image topics (/stereo/left/image_raw); give the
    topics (--left-topic, --right-topic)", two topics the bag does not hold. It now says why
    there is no pair; several topics without a pair keep the advice."""
    small = cones.left[:48, :64], cones.right[:48, :64]
    one = write_bag(tmp_path / "one", [(T0, small[0], None, small[1])])
    said = (
        f"no left/right pair among the bag's image topics ({LEFT}); a pair needs an image topic "
        "per camera, and the bag holds one (was the other camera recorded?)"
    )
    with pytest.raises(ValueError) as info:
        BagCamera(one)
    assert str(info.value) == said
    code, _out, err = run("stream", "--from-bag", str(one), "--no-display")
    assert code == 2 and err.strip().splitlines() == [f"stereovision: error: {said}"]
    with pytest.raises(ValueError) as info:
        find_stereo_topics([])
    assert str(info.value) == (
        "no left/right pair among the bag's image topics (none); the bag holds no "
        "sensor_msgs/Image or CompressedImage topic"
    )
    with pytest.raises(ValueError) as info:
        find_stereo_topics(["/a/image", "/b/image"])
    assert str(info.value).endswith(
        "(/a/image, /b/image); give the topics (--left-topic, --right-topic)"
    )


def test_the_bag_entry_points_refuse_a_bytes_or_no_path_naming_it(tmp_path: Path) -> None:
    """BagCamera, BagWriter, bag_topics and is_bag given a bytes name raised pathlib's
    "argument should be a str object or an os.PathLike object returning str, not <class
    'bytes'>" (None "expected str, bytes or os.PathLike object"), naming no argument; they
    now say it as io's readers and Calibration.from_file do."""
    from stereovision.rosbag import BagWriter, bag_topics, is_bag

    name = str(tmp_path / "rig.bag")
    for call in (BagCamera, BagWriter, bag_topics, is_bag):
        with pytest.raises(TypeError) as info:
            call(name.encode())
        assert str(info.value) == (
            f"path: expected a str or os.PathLike file name, got the bytes {name!r}: decode it "
            "first (os.fsdecode(path))"
        )
        with pytest.raises(TypeError) as info:
            call(None)
        assert str(info.value) == "path: expected a str or os.PathLike file name, got NoneType"
    assert not list(tmp_path.iterdir())  # no bag folder made


def test_an_empty_bag_name_is_refused_not_the_current_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """BagCamera(''), bag_topics(''), BagWriter('') took Path(''), the current folder, for the
    bag ("'.' is not a readable ROS 1 or ROS 2 bag", "bag folder already exists: ."; a bag
    folder run in was read) and is_bag('') said True in a ROS 2 bag folder: '' names none."""
    from stereovision.rosbag import BagWriter, bag_topics, is_bag

    (tmp_path / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    monkeypatch.chdir(tmp_path)
    assert is_bag(".") and not is_bag("")
    for call in (lambda: BagCamera(""), lambda: bag_topics(""), lambda: BagWriter("")):
        with pytest.raises(ValueError) as info:
            call()
        assert str(info.value) == "path: expected a bag file or folder name, got ''"
    assert [p.name for p in tmp_path.iterdir()] == ["metadata.yaml"]


def test_cli_info_of_a_missing_bag_says_bag_not_found(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`info run.bag` of a missing bag (or a link to one since moved) said "calibration file
    not found: run.bag", of a name a bag's; it is the bag reader's "bag not found"."""
    from stereovision import cli

    (tmp_path / "run.bag").symlink_to(Path("moved") / "run.bag")
    assert cli.main(["info", str(tmp_path / "run.bag")]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: bag not found: {tmp_path / 'run.bag'} (a link to moved/run.bag, "
        "which does not exist)\n"
    )
    assert cli.main(["info", str(tmp_path / "x.mcap")]) == 2
    assert capsys.readouterr().err == f"stereovision: error: bag not found: {tmp_path / 'x.mcap'}\n"
    assert cli.main(["info", str(tmp_path / "rig.yaml")]) == 2  # a calibration's as before
    assert "calibration file not found" in capsys.readouterr().err
