"""Tests of stereovision.io: images, PFM, PLY, scenes (values asserted)."""

from __future__ import annotations

import errno
import os
import re
import shutil
import struct
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from stereovision.calibration import Calibration
from stereovision.io import (
    atomic_write,
    find_scenes,
    imread,
    load_scene,
    make_folder,
    read_image,
    read_pfm,
    read_ply,
    scan_scenes,
    scene_max_disparity,
    write_pfm,
    write_ply,
    write_together,
)

# evaluation.md "Reference figures": max_disparity per scene.
TABLE_MAX_DISPARITY = {
    "eth3d/playground": 32,
    "eth3d/terrace": 32,
    "kitti2015/000005_10": 112,
    "middeval3/teddyH": 128,
    "middlebury2001/tsukuba": 16,
    "middlebury2001/venus": 32,
    "middlebury2003/cones": 64,
    "middlebury2003/teddy": 64,
    "middlebury2005/art": 96,
    "middlebury2005/books": 96,
    "middlebury2005/dolls": 96,
    "middlebury2005/laundry": 96,
    "middlebury2005/moebius": 80,
    "middlebury2005/reindeer": 80,
    "middlebury2006/cloth3": 96,
    "middlebury2006/wood2": 128,
    "tartanair/oldtown_easy_p000_001116": 48,
}


# ------------------------------------------------------------------------------------- imread


def test_imread_colour_and_gray(tmp_path: Path) -> None:
    img = np.zeros((4, 5, 3), np.uint8)
    img[1, 2] = (10, 20, 30)  # B, G, R
    path = tmp_path / "a.png"
    assert cv2.imwrite(str(path), img)
    got = imread(path)
    assert got.dtype == np.uint8 and got.shape == (4, 5, 3)
    np.testing.assert_array_equal(got, img)
    gray = imread(path, gray=True)
    assert gray.shape == (4, 5)
    # BT.601: 0.114 B + 0.587 G + 0.299 R = 1.14 + 11.74 + 8.97 = 21.85 -> 22
    assert gray[1, 2] == 22


def test_read_image_keeps_16_bits(tmp_path: Path) -> None:
    """``stereovision depth``'s reader: a 16-bit file's values as they are (imread keeps the
    top 8 bits: 4095 -> 15), grey replicated to BGR; an 8-bit file as imread reads it."""
    grey16 = np.array([[0, 4095, 65535], [256, 1, 300]], np.uint16)
    assert cv2.imwrite(str(tmp_path / "g16.png"), grey16)
    got = read_image(tmp_path / "g16.png")
    assert got.dtype == np.uint16 and got.shape == (2, 3, 3)
    for c in range(3):
        np.testing.assert_array_equal(got[..., c], grey16)
    assert int(imread(tmp_path / "g16.png")[0, 1, 0]) == 15
    bgr16 = np.stack([grey16, grey16 // 2, grey16 // 3], axis=2)
    assert cv2.imwrite(str(tmp_path / "c16.png"), bgr16)
    np.testing.assert_array_equal(read_image(tmp_path / "c16.png"), bgr16)
    img8 = np.arange(24, dtype=np.uint8).reshape(2, 4, 3)
    assert cv2.imwrite(str(tmp_path / "c8.png"), img8)
    got8 = read_image(tmp_path / "c8.png")
    assert got8.dtype == np.uint8
    np.testing.assert_array_equal(got8, img8)
    with pytest.raises(FileNotFoundError, match=r"nope\.png"):
        read_image(tmp_path / "nope.png")
    (tmp_path / "bad.png").write_bytes(b"not an image")
    with pytest.raises(ValueError, match="cannot decode"):
        read_image(tmp_path / "bad.png")


def test_read_image_decodes_an_8_bit_file_once(tmp_path: Path, monkeypatch) -> None:
    """An 8-bit JPEG (EXIF-turned) and PNG read by one decode, imread's very pixels: the
    16-bit try and then imread decoded every 8-bit file twice (a board search reads each)."""
    import struct

    from stereovision import io as svio

    rng = np.random.default_rng(3)
    img = rng.integers(0, 256, (40, 30, 3), np.uint8)
    jpg = cv2.imencode(".jpg", img)[1].tobytes()
    # an APP1 Exif block with Orientation 6 (turn 90 degrees clockwise)
    tiff = b"MM\x00\x2a\x00\x00\x00\x08" + struct.pack(">HHHII", 1, 0x0112, 3, 1, 6 << 16)
    app1 = b"Exif\x00\x00" + tiff + b"\x00" * 4
    (tmp_path / "t.jpg").write_bytes(
        jpg[:2] + b"\xff\xe1" + struct.pack(">H", len(app1) + 2) + app1 + jpg[2:]
    )
    assert cv2.imwrite(str(tmp_path / "c.png"), img)
    calls: list[int] = []
    decode = svio._imdecode

    def counted(buf: np.ndarray, flags: int) -> np.ndarray | None:
        calls.append(flags)
        return decode(buf, flags)

    for name, shape in (("t.jpg", (30, 40, 3)), ("c.png", (40, 30, 3))):
        want = imread(tmp_path / name)
        calls.clear()
        monkeypatch.setattr(svio, "_imdecode", counted)
        got = read_image(tmp_path / name)
        monkeypatch.setattr(svio, "_imdecode", decode)
        assert len(calls) == 1, name
        assert got.dtype == np.uint8 and got.shape == shape
        np.testing.assert_array_equal(got, want)


def test_imread_missing(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"nope\.png"):
        imread(tmp_path / "nope.png")


def test_imread_garbage(tmp_path: Path) -> None:
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"this is not an image")
    with pytest.raises(ValueError, match="cannot decode"):
        imread(bad)
    empty = tmp_path / "empty.png"
    empty.write_bytes(b"")
    with pytest.raises(ValueError, match="cannot decode"):
        imread(empty)


def test_imread_truncated_says_it_once(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    """A cut file gives our one error; OpenCV's own ``[ERROR] imdecode_`` log line (printed on
    the C stderr for a truncated PGM header) stays silent, and its log level is put back."""
    import cv2

    ok, png = cv2.imencode(".png", np.arange(64 * 48 * 3, dtype=np.uint8).reshape(48, 64, 3))
    assert ok
    cut = tmp_path / "cut.png"
    cut.write_bytes(png.tobytes()[: png.size // 3])
    pgm = tmp_path / "cut.pgm"
    pgm.write_bytes(b"P5\n")
    level = cv2.utils.logging.getLogLevel()  # type: ignore[attr-defined]
    for path in (cut, pgm):
        with pytest.raises(ValueError, match="cannot decode"):
            imread(path)
    assert capfd.readouterr().err == ""
    assert cv2.utils.logging.getLogLevel() == level  # type: ignore[attr-defined]


@pytest.mark.parametrize("deep", [False, True], ids=["8-bit", "16-bit"])
def test_a_png_cut_short_prints_no_libpng_line(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], deep: bool
) -> None:
    """A PNG cut anywhere in its data (an interrupted copy) printed libpng's own "libpng error:
    PNG input buffer is incomplete" on the C stderr, once per decode (twice for read_image and
    `stereovision depth`), before our one error line; OpenCV's log level does not reach it.
    Cut files are still refused, silently, saying they are cut short (it was "cannot decode F
    as an image" alone, a damaged file's or an unknown format's words); the whole file, junk
    after its end too, still reads.
    """
    from stereovision.io import decode_image, read_image

    rng = np.random.default_rng(0)
    img = cv2.GaussianBlur(rng.integers(0, 256, (120, 160, 3), dtype=np.uint8), (5, 5), 2)
    pixels = img.astype(np.uint16) * 257 if deep else img
    ok, png = cv2.imencode(".png", pixels)
    assert ok
    data = png.tobytes()
    for keep in (len(data) // 10, len(data) // 2, len(data) - 13, len(data) - 1):
        cut = tmp_path / f"cut{keep}.png"
        cut.write_bytes(data[:keep])
        for read in (imread, read_image):
            with pytest.raises(ValueError) as info:
                read(cut)
            assert str(info.value) == (
                f"cannot decode {cut} as an image: the PNG file ends before its last chunk "
                f"({keep} bytes: cut short by an interrupted copy?)"
            )
        assert decode_image(data[:keep]) is None
        assert capfd.readouterr().err == ""
    whole = tmp_path / "whole.png"
    whole.write_bytes(data + b"junk after IEND")
    np.testing.assert_array_equal(read_image(whole), pixels)
    np.testing.assert_array_equal(imread(whole), img)


def test_concurrent_decodes_put_the_log_level_back() -> None:
    """Threads decoding at once (good and bad files): OpenCV's process-wide log level ends as it
    was, and each call's result is its own."""
    import threading

    import cv2

    from stereovision.io import decode_image

    ok, png = cv2.imencode(".png", np.full((32, 48, 3), 7, np.uint8))
    assert ok
    good, bad = png.tobytes(), png.tobytes()[: png.size // 3]
    log = cv2.utils.logging  # type: ignore[attr-defined]
    before = log.getLogLevel()
    results: list[bool] = []

    def work(k: int) -> None:
        for i in range(200):
            img = decode_image(good if (i + k) % 2 else bad)
            results.append(
                img is not None and img.shape == (32, 48, 3) if (i + k) % 2 else img is None
            )

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(results) == 800 and all(results)
    assert log.getLogLevel() == before


# ---------------------------------------------------------------------------------------- PFM


def _pfm_bytes(arr: np.ndarray, little: bool) -> bytes:
    """Independent PFM encoder (bottom-up rows) used as the oracle."""
    magic = b"PF" if arr.ndim == 3 else b"Pf"
    h, w = arr.shape[:2]
    dt = "<f4" if little else ">f4"
    scale = b"-1.0" if little else b"1.0"
    return magic + f"\n{w} {h}\n".encode() + scale + b"\n" + arr[::-1].astype(dt).tobytes()


def test_read_pfm_orientation_and_endianness(tmp_path: Path) -> None:
    arr = np.arange(6, dtype=np.float32).reshape(2, 3)  # row 0 = top = [0, 1, 2]
    for little in (True, False):
        p = tmp_path / f"x{little}.pfm"
        p.write_bytes(_pfm_bytes(arr, little))
        got = read_pfm(p)
        assert got.dtype == np.float32 and got.dtype.isnative
        np.testing.assert_array_equal(got, arr)
    # the first stored row is the bottom one
    raw = (tmp_path / "xTrue.pfm").read_bytes()
    assert struct.unpack("<f", raw[-12:-8])[0] == 0.0  # last stored row = top row [0, 1, 2]


def test_pfm_colour_round_trip(tmp_path: Path) -> None:
    arr = np.random.default_rng(1).standard_normal((3, 4, 3)).astype(np.float32)
    assert write_pfm(tmp_path / "c.pfm", arr, little_endian=False) == tmp_path / "c.pfm"
    assert (tmp_path / "c.pfm").read_bytes().startswith(b"PF\n4 3\n1.0\n")
    np.testing.assert_array_equal(read_pfm(tmp_path / "c.pfm"), arr)


# any float32 bits: values mostly of extreme magnitudes (1e-40, 1e38) are warned of as maybe
# read in the wrong byte order, as read_pfm warns of such a file
@pytest.mark.filterwarnings("ignore:PFM file")
@settings(max_examples=30, deadline=None)
@given(
    arr=hnp.arrays(
        np.float32,
        hnp.array_shapes(min_dims=2, max_dims=2, min_side=1, max_side=7),
        elements=st.floats(width=32, allow_nan=True, allow_infinity=True),
    ),
    little=st.booleans(),
)
def test_pfm_round_trip_bit_exact(tmp_path_factory: pytest.TempPathFactory, arr, little) -> None:
    p = tmp_path_factory.mktemp("pfm") / "r.pfm"
    write_pfm(p, arr, little_endian=little)
    got = read_pfm(p)
    assert got.shape == arr.shape
    assert got.tobytes() == arr.astype(np.float32).tobytes()  # NaN/inf bits included


def test_pfm_errors(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        read_pfm(tmp_path / "none.pfm")
    (tmp_path / "bad.pfm").write_bytes(b"P5\n2 2\n255\n....")
    with pytest.raises(ValueError, match="not a PFM"):
        read_pfm(tmp_path / "bad.pfm")
    (tmp_path / "short.pfm").write_bytes(b"Pf\n4 4\n-1.0\n" + b"\0" * 12)
    with pytest.raises(ValueError, match="truncated"):
        read_pfm(tmp_path / "short.pfm")
    with pytest.raises(ValueError, match=r"\(H, W\)"):
        write_pfm(tmp_path / "w.pfm", np.zeros((2, 2, 2), np.float32))


@pytest.mark.parametrize(
    "eol", [b"\r\n", b" \n", b"  \t\r\n"], ids=["crlf", "space", "spaces-crlf"]
)
@pytest.mark.parametrize("little", [True, False])
def test_read_pfm_header_lines_of_windows_tools(tmp_path: Path, eol: bytes, little: bool) -> None:
    """A header written with CRLF line endings (Windows tools) or trailing spaces: its scale
    line's \\r or space was taken as the whole line ending, so the data began one byte early
    (every value shifted by a byte, silently) or the file was said to be truncated."""
    arr = np.array([[1.5, -2.0, 3.25], [0.0, 7.0, -0.5]], np.float32)
    body = _pfm_bytes(arr, little)
    magic, sizes, scale, data = body.split(b"\n", 3)
    p = tmp_path / "w.pfm"
    p.write_bytes(magic + eol + sizes + eol + scale + eol + data)
    got = read_pfm(p)
    assert got.dtype == np.float32
    np.testing.assert_array_equal(got, arr)
    # one line, ended by one space (no line feed): the data right after it, as before
    p.write_bytes(b"Pf 3 2 " + scale + b" " + data)
    np.testing.assert_array_equal(read_pfm(p), arr)


@pytest.mark.parametrize("first", [b"\n", b" \n", b"\r\n", b"\t\t\n"])
def test_read_pfm_one_space_header_keeps_data_that_begins_like_a_line_end(
    tmp_path: Path, first: bytes
) -> None:
    """A header ended by one space and no line feed, its data's first bytes 0x0A (or spaces,
    \r, then 0x0A): those bytes were taken as the scale line's end, the data read from a byte
    or more late (said truncated). The data is the file's last bytes when they fit there."""
    raw = first + bytes(range(24 - len(first)))
    arr = np.frombuffer(raw, "<f4").reshape(2, 3)[::-1]
    p = tmp_path / "w.pfm"
    p.write_bytes(b"Pf\n3 2\n-1.0 " + raw)
    np.testing.assert_array_equal(read_pfm(p), arr)
    p.write_bytes(b"Pf\n3 2\n-1.0\r\n" + raw[:-1])  # the line's own end still ends it
    with pytest.raises(ValueError, match=r"truncated PFM file .*got 23"):
        read_pfm(p)


def test_read_pfm_bad_scale_and_truncation_name_the_file(tmp_path: Path) -> None:
    """A scale that is no number ("1.0.0", "."), zero (no byte order) or a file cut short is a
    ValueError naming the file (a malformed scale raised float()'s own message, no file)."""
    data = np.zeros(6, "<f4").tobytes()
    for scale in (b"1.0.0", b".", b"-."):
        p = tmp_path / "s.pfm"
        p.write_bytes(b"Pf\n3 2\n" + scale + b"\n" + data)
        with pytest.raises(ValueError, match=rf"PFM.*{re.escape(str(p))}"):
            read_pfm(p)
    for scale in (b"0", b"-0.0", b"+0e5"):
        p.write_bytes(b"Pf\n3 2\n" + scale + b"\n" + data)
        with pytest.raises(ValueError, match=rf"bad PFM header in {re.escape(str(p))}.*scale"):
            read_pfm(p)
    p.write_bytes(b"Pf\r\n3 2\r\n-1.0\r\n" + data[:-1])
    with pytest.raises(ValueError, match=rf"truncated PFM file {re.escape(str(p))}: .*got 23"):
        read_pfm(p)


def test_read_shared_gt(data_dir: Path) -> None:
    gt = read_pfm(data_dir / "middlebury2001" / "tsukuba" / "gt_disp.pfm")
    assert gt.shape == (288, 384)
    finite = gt[np.isfinite(gt)]
    assert finite.max() == 14.0
    assert np.count_nonzero(np.isinf(gt)) == 22896


# ------------------------------------------------------------------------------------- atomic


def test_atomic_write_leaves_old_file_on_error(tmp_path: Path) -> None:
    dest = tmp_path / "f.bin"
    dest.write_bytes(b"old")
    with pytest.raises(RuntimeError), atomic_write(dest) as fh:
        fh.write(b"new")
        raise RuntimeError("boom")
    assert dest.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["f.bin"]  # no temporary file left behind
    with atomic_write(dest) as fh:
        fh.write(b"new")
    assert dest.read_bytes() == b"new"
    umask = os.umask(0)
    os.umask(umask)
    assert dest.stat().st_mode & 0o777 == 0o666 & ~umask  # not mkstemp's private 0o600
    with pytest.raises(FileNotFoundError, match="does not exist"):
        write_pfm(tmp_path / "missing_dir" / "x.pfm", np.zeros((1, 1), np.float32))


def test_writing_into_a_folder_link_to_nothing_names_the_link(tmp_path: Path) -> None:
    """A folder given as a link whose target moved (out -> a disk since unmounted), or one of a
    loop of links: "cannot write out/d.pfm: directory out does not exist" of a name ls lists.
    It says what the link reaches, as the readers' "not found" does; nothing is written."""
    out, loop = tmp_path / "out", tmp_path / "loop"
    out.symlink_to(tmp_path / "moved")
    loop.symlink_to(loop)
    for folder, said in (
        (out, f"a link to {tmp_path / 'moved'}, which does not exist"),
        (loop, f"a link to {loop}, one of a loop of links that never reaches a file"),
    ):
        with pytest.raises(FileNotFoundError) as info:
            write_pfm(folder / "d.pfm", np.zeros((1, 1), np.float32))
        assert str(info.value) == f"cannot write {folder / 'd.pfm'}: directory {folder} is {said}"
    assert sorted(os.listdir(tmp_path)) == ["loop", "out"]


def test_writing_onto_a_folder_or_under_a_file_names_it(tmp_path: Path) -> None:
    """A folder where a file goes, or a file where a folder goes: the error says which (it
    showed the temporary file's name, or mkdir's bare "[Errno 17] File exists")."""
    (tmp_path / "out").mkdir()
    with pytest.raises(IsADirectoryError, match=r"cannot write .*out: it is a folder"):
        write_pfm(tmp_path / "out", np.zeros((1, 1), np.float32))
    afile = tmp_path / "a.txt"
    afile.write_text("x")
    with pytest.raises(NotADirectoryError, match=r"a\.txt is a file, not a folder"):
        write_pfm(afile / "x.pfm", np.zeros((1, 1), np.float32))
    with pytest.raises(NotADirectoryError, match=r"cannot make the folder .*: .*a\.txt is a file"):
        make_folder(afile / "sub" / "deeper")
    assert make_folder(tmp_path / "new" / "deeper").is_dir()
    assert sorted(os.listdir(tmp_path)) == ["a.txt", "new", "out"]  # nothing else left


# ---------------------------------------------------------------------------------------- PLY


def test_ply_round_trip_with_colours(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    pts = rng.standard_normal((50, 3)).astype(np.float32)
    cols = rng.integers(0, 256, (50, 3), dtype=np.uint8)
    pts[7] = np.nan
    assert write_ply(tmp_path / "c.ply", pts, cols) == tmp_path / "c.ply"
    raw = (tmp_path / "c.ply").read_bytes()
    header, body = raw.split(b"end_header\n")
    assert b"format binary_little_endian 1.0" in header
    assert b"element vertex 49" in header
    assert b"property uchar red" in header
    assert len(body) == 49 * (3 * 4 + 3)
    got_p, got_c = read_ply(tmp_path / "c.ply")
    keep = np.arange(50) != 7
    np.testing.assert_array_equal(got_p, pts[keep])
    assert got_c is not None
    np.testing.assert_array_equal(got_c, cols[keep])
    # first vertex, decoded by hand
    x, y, z, r, g, b = struct.unpack("<fffBBB", body[:15])
    assert (x, y, z) == tuple(pts[0].tolist()) and (r, g, b) == tuple(cols[0].tolist())


def test_ply_header_gives_units_and_frame(tmp_path: Path) -> None:
    """The header said "stereovision point cloud" only: metres or millimetres, which frame?"""
    pts = np.array([[0.5, -0.25, 2.0]], np.float32)
    write_ply(tmp_path / "c.ply", pts)
    header = (tmp_path / "c.ply").read_bytes().split(b"end_header\n")[0].decode("ascii")
    assert "comment stereovision point cloud (metres, X right, Y down, Z forward)\n" in header
    write_ply(tmp_path / "mm.ply", pts * 1000, comment="robot map (millimetres, ROS base_link)")
    header = (tmp_path / "mm.ply").read_bytes().split(b"end_header\n")[0].decode("ascii")
    assert "\ncomment robot map (millimetres, ROS base_link)\n" in header
    np.testing.assert_array_equal(read_ply(tmp_path / "mm.ply")[0], pts * 1000)
    for bad in ("two\nlines", "m\u00e8tres"):  # would break the header
        with pytest.raises(ValueError, match="comment: expected one line of printable ASCII"):
            write_ply(tmp_path / "bad.ply", pts, comment=bad)
    assert not (tmp_path / "bad.ply").exists()


def test_ply_writer_holds_no_extra_copies_of_a_big_cloud(tmp_path: Path) -> None:
    """A map of millions of points: the writer held the cloud four times over (a float32 copy,
    the finite points, the records and their bytes), 46 bytes a point for a 15-byte record."""
    import tracemalloc

    n = 200_000
    rng = np.random.default_rng(0)
    pts = rng.uniform(-5, 5, (n, 3)).astype(np.float32)
    cols = rng.integers(0, 256, (n, 3), dtype=np.uint8)
    tracemalloc.start()
    try:
        write_ply(tmp_path / "big.ply", pts, cols)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2 * 15 * n  # the records (15 bytes a point) and a mask, not four copies
    got_p, got_c = read_ply(tmp_path / "big.ply")
    np.testing.assert_array_equal(got_p, pts)
    np.testing.assert_array_equal(got_c, cols)


def test_ply_without_colours_and_image_shaped(tmp_path: Path) -> None:
    pts = np.arange(2 * 3 * 3, dtype=np.float64).reshape(2, 3, 3)
    write_ply(tmp_path / "p.ply", pts)
    got, cols = read_ply(tmp_path / "p.ply")
    assert cols is None
    np.testing.assert_array_equal(got, pts.reshape(-1, 3).astype(np.float32))
    write_ply(tmp_path / "k.ply", np.full((2, 3), np.nan), drop_invalid=False)
    kept, _ = read_ply(tmp_path / "k.ply")
    assert kept.shape == (2, 3) and np.isnan(kept).all()


def test_ascii_ply_and_float_colours(tmp_path: Path) -> None:
    """ASCII PLY (MeshLab's, CloudCompare's, Open3D's ``write_ascii=True``) was refused as
    "binary only"; float colours of 0-1 were cast to uint8 (every colour 0 or 1: black)."""
    head = (
        "ply\nformat ascii 1.0\ncomment made elsewhere\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nproperty float nx\nproperty float ny\n"
        "property float nz\nproperty {t} red\nproperty {t} green\nproperty {t} blue\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
    )
    body = "1 2 3 0 0 1 {}\n-0.5 0.25 4.5 0 0 1 {}\nnan 0 1 0 0 1 {}\n3 0 1 2\n"
    (tmp_path / "u8.ply").write_text(
        head.format(t="uchar") + body.format("255 0 10", "1 2 3", "0 0 0")
    )
    pts, cols = read_ply(tmp_path / "u8.ply")
    np.testing.assert_array_equal(pts[:2], [[1, 2, 3], [-0.5, 0.25, 4.5]])
    assert pts.dtype == np.float32 and np.isnan(pts[2, 0])
    assert cols is not None and cols.tolist() == [[255, 0, 10], [1, 2, 3], [0, 0, 0]]
    (tmp_path / "f.ply").write_text(
        head.format(t="float") + body.format("1 0 0.5", "0.2 1 -1", "0 0 0")
    )
    _, cols = read_ply(tmp_path / "f.ply")
    assert cols is not None and cols.tolist() == [[255, 0, 128], [51, 255, 0], [0, 0, 0]]
    # float colours of 0-255 (Open3D reads every float colour so): as 0-1 they were all white
    (tmp_path / "f255.ply").write_text(
        head.format(t="float") + body.format("255 128 0.4", "12 300 -1", "0 0 0")
    )
    _, cols = read_ply(tmp_path / "f255.ply")
    assert cols is not None and cols.tolist() == [[255, 128, 0], [12, 255, 0], [0, 0, 0]]
    # binary with float colours, and MeshLab's diffuse_ names
    rec = np.zeros(
        1, [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("r", "<f4"), ("g", "<f4"), ("b", "<f4")]
    )
    rec[0] = (1, 2, 3, 1.0, 0.5, 0.0)
    raw = (
        head.format(t="float")
        .replace("ascii", "binary_little_endian")
        .replace("element vertex 3", "element vertex 1")
    )
    raw = raw.replace("property float nx\nproperty float ny\nproperty float nz\n", "")
    (tmp_path / "fb.ply").write_bytes(
        raw.replace(" red", " diffuse_red")
        .replace(" green", " diffuse_green")
        .replace(" blue", " diffuse_blue")
        .encode()
        + rec.tobytes()
    )
    pts, cols = read_ply(tmp_path / "fb.ply")
    assert pts.tolist() == [[1, 2, 3]] and cols is not None and cols.tolist() == [[255, 128, 0]]
    # a short file and a damaged row say so, with the file's name
    (tmp_path / "short.ply").write_text(head.format(t="uchar") + "1 2 3 0 0 1 4 5 6\n")
    with pytest.raises(ValueError, match=r"truncated PLY file .*short\.ply: expected 3 vert"):
        read_ply(tmp_path / "short.ply")
    (tmp_path / "bad.ply").write_text(
        head.format(t="uchar") + body.format("1 2 x", "1 2 3", "0 0 0")
    )
    with pytest.raises(ValueError, match=r"damaged PLY file .*bad\.ply"):
        read_ply(tmp_path / "bad.ply")
    (tmp_path / "e.ply").write_text(head.format(t="uchar").replace("vertex 3", "vertex 0"))
    pts, cols = read_ply(tmp_path / "e.ply")
    assert pts.shape == (0, 3) and cols is not None and cols.shape == (0, 3)


def test_ply_errors(tmp_path: Path) -> None:
    (tmp_path / "g.ply").write_bytes(b"\x00\x01garbage")
    with pytest.raises(ValueError, match="not a PLY file"):
        read_ply(tmp_path / "g.ply")
    with pytest.raises(FileNotFoundError):
        read_ply(tmp_path / "none.ply")
    with pytest.raises(ValueError, match="points"):
        write_ply(tmp_path / "x.ply", np.zeros((4, 2)))
    with pytest.raises(ValueError, match="colors"):
        write_ply(tmp_path / "x.ply", np.zeros((4, 3)), np.zeros((4, 3), np.float32))
    with pytest.raises(ValueError, match="colors"):
        write_ply(tmp_path / "x.ply", np.zeros((4, 3)), np.zeros((3, 3), np.uint8))
    assert not (tmp_path / "x.ply").exists()


# ------------------------------------------------------------------------------------- scenes


def test_scene_max_disparity_rule() -> None:
    gt = np.array([[np.nan, 14.0], [np.inf, 3.0]], np.float32)
    gt[1, 0] = np.nan
    assert scene_max_disparity(gt, width=100) == 16  # 1.1 * 14 = 15.4 -> 16
    assert scene_max_disparity(np.array([[14.6]]), width=100) == 32  # 16.06 -> 32
    assert scene_max_disparity(None, width=100, ndisp=70) == 80
    assert scene_max_disparity(None, width=100) == 32  # 100 // 4 = 25 -> 32
    assert scene_max_disparity(np.full((2, 2), np.nan), width=320) == 80


def test_scene_max_disparity_is_exactly_1_1_times_the_gt_max() -> None:
    """evaluation.md's range is 1.1 x the largest GT disparity rounded up to a multiple of 16: a
    GT reaching 800 px searches 880, not 896 (1.1 * 800 is 880.0000000000001 in floats)."""
    for top, want in ((800.0, 880), (1440.0, 1584), (1600.0, 1760), (160.0, 176), (800.5, 896)):
        gt = np.array([[3.0, top]], np.float32)
        assert scene_max_disparity(gt, width=4000) == want, top


def test_scene_max_disparity_refuses_a_bad_width_or_ndisp(data_dir: Path, tmp_path: Path) -> None:
    """A width of 0 gave 16, an ndisp of NaN or -5 (from calib.txt too) the width's range,
    without a word: each is a ValueError naming the argument, or the file and the key."""
    for width in (0, -4, 2.5, True):
        with pytest.raises(ValueError, match=r"^width: expected the image width in pixels"):
            scene_max_disparity(None, width=width)  # type: ignore[arg-type]
    for ndisp in (float("nan"), -5.0, 0.0, float("inf")):
        with pytest.raises(ValueError, match=r"^ndisp: expected a positive finite number"):
            scene_max_disparity(None, width=100, ndisp=ndisp)
    scene = tmp_path / "terrace"
    shutil.copytree(data_dir / "eth3d" / "terrace", scene)
    assert load_scene(scene).max_disparity == 32  # from its GT
    calib = scene / "calib.txt"
    good = calib.read_text()
    assert "ndisp=713\n" in good
    for bad in ("nan", "-5", "0"):
        calib.write_text(good.replace("ndisp=713\n", f"ndisp={bad}\n"))
        with pytest.raises(ValueError) as info:
            load_scene(scene)
        assert str(info.value) == (
            f"{calib}: ndisp={float(bad):g}: expected the disparity range in pixels, a positive "
            "finite number"
        )


def test_find_scenes(data_dir: Path) -> None:
    scenes = find_scenes(data_dir)
    names = [f"{p.parent.name}/{p.name}" for p in scenes]
    assert names == sorted(names)
    assert set(TABLE_MAX_DISPARITY) <= set(names)
    assert all((p / "left.png").is_file() and (p / "right.png").is_file() for p in scenes)
    assert "opencv_uncalibrated/books" not in names  # .jpg pair, not a scene
    with pytest.raises(FileNotFoundError):
        find_scenes(data_dir / "nope")


def test_load_scene_tsukuba(data_dir: Path) -> None:
    s = load_scene(data_dir / "middlebury2001" / "tsukuba")
    assert s.name == "middlebury2001/tsukuba"
    assert s.left.shape == (288, 384, 3) and s.left.dtype == np.uint8
    assert s.gt is not None and s.gt.dtype == np.float32
    assert not np.isinf(s.gt).any()
    assert np.isnan(s.gt).sum() == 22896  # the file's +inf became NaN
    assert s.calib is None
    assert s.max_disparity == 16


def test_load_scene_with_calib(data_dir: Path) -> None:
    s = load_scene(data_dir / "eth3d" / "terrace")
    assert isinstance(s.calib, Calibration)
    assert s.calib.unit == "mm" and s.calib.baseline == pytest.approx(59.9432)
    assert s.calib.image_size == (713, 434)


def test_max_disparity_matches_evaluation_table(data_dir: Path) -> None:
    for name, expected in TABLE_MAX_DISPARITY.items():
        assert load_scene(data_dir / name).max_disparity == expected, name


def test_load_scene_errors(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        load_scene(tmp_path / "none")
    with pytest.raises(FileNotFoundError, match=r"left\.png"):
        load_scene(tmp_path)
    img = np.zeros((4, 6, 3), np.uint8)
    cv2.imwrite(str(tmp_path / "left.png"), img)
    cv2.imwrite(str(tmp_path / "right.png"), img[:, :5])
    with pytest.raises(
        ValueError, match=r"right\.png is .*: the two images of a pair have one size"
    ):
        load_scene(tmp_path)
    cv2.imwrite(str(tmp_path / "right.png"), img)
    write_pfm(tmp_path / "gt_disp.pfm", np.zeros((3, 6), np.float32))
    with pytest.raises(ValueError, match=r"gt_disp\.pfm"):
        load_scene(tmp_path)
    (tmp_path / "gt_disp.pfm").unlink()
    s = load_scene(tmp_path)
    assert s.gt is None and s.max_disparity == 16


def test_load_scene_of_middleburys_names_says_the_names_a_scene_takes(tmp_path: Path) -> None:
    """A folder as Middlebury ships a scene (im0.png, im1.png) said only "image file not
    found: .../left.png": it says what eval and bench say of it (0f66e302), the files to rename.
    With one of left.png / right.png there, the missing one is named as before."""
    img = np.zeros((4, 6), np.uint8)
    for name in ("im0.png", "im1.png"):
        cv2.imwrite(str(tmp_path / name), img)
    with pytest.raises(FileNotFoundError) as err:
        load_scene(tmp_path)
    assert str(err.value) == (
        f"image file not found: {tmp_path / 'left.png'}; {tmp_path} has Middlebury's im0.png + "
        "im1.png: a scene's images are named left.png + right.png and its ground truth "
        "gt_disp.pfm (rename im0.png, im1.png and disp0.pfm or disp0GT.pfm; calib.txt is read "
        "as it is)"
    )
    cv2.imwrite(str(tmp_path / "left.png"), img)
    with pytest.raises(FileNotFoundError) as err:
        load_scene(tmp_path)
    assert str(err.value) == f"image file not found: {tmp_path / 'right.png'}"


def test_a_missing_image_names_the_one_file_of_its_stem_beside_it(tmp_path: Path) -> None:
    """``image file not found: left.png`` beside a ``left.jpg`` said nothing of it: the one
    image of the same stem and another suffix is offered; none for two such files or for a
    file that is no image (nor for a folder named as an image)."""
    (tmp_path / "left.txt").write_bytes(b"")
    (tmp_path / "left.webp").mkdir()  # a folder of an image's name is no image to offer
    with pytest.raises(FileNotFoundError) as err:
        read_image(tmp_path / "left.png")
    assert str(err.value) == f"image file not found: {tmp_path / 'left.png'}"
    (tmp_path / "left.JPG").write_bytes(b"")
    for typed in ("left.png", "left"):
        with pytest.raises(FileNotFoundError) as err:
            read_image(tmp_path / typed)
        assert str(err.value) == (
            f"image file not found: {tmp_path / typed} (did you mean {tmp_path / 'left.JPG'}?)"
        )
    (tmp_path / "left.tif").write_bytes(b"")
    with pytest.raises(FileNotFoundError) as err:
        read_image(tmp_path / "left.png")
    assert str(err.value) == f"image file not found: {tmp_path / 'left.png'}"


def test_load_scene_and_view_of_a_pair_named_in_another_case_say_the_names(
    tmp_path: Path,
) -> None:
    """A folder of Left.png + Right.png was 'image file not found: .../left.png' to load_scene
    and 'no cloud.ply and no scene (left.png + right.png) in this folder' to view, beside the
    pair: each says what eval says of it (87b6bed3), that the names are lower case."""
    from stereovision import render

    for name in ("Left.png", "Right.png"):
        (tmp_path / name).write_bytes(b"")
    why = (
        f"{tmp_path} holds Left.png, Right.png: a scene's images are named left.png and "
        "right.png, in lower case"
    )
    with pytest.raises(FileNotFoundError) as err:
        load_scene(tmp_path)
    assert str(err.value) == f"image file not found: {tmp_path / 'left.png'}; {why}"
    with pytest.raises(FileNotFoundError) as err:
        render.load_view_source(tmp_path)
    assert str(err.value) == (
        f"{tmp_path}: no cloud.ply and no scene (left.png + right.png) in this folder; it "
        + why.removeprefix(f"{tmp_path} ")
    )


def test_view_of_a_middlebury_folder_says_the_names(tmp_path: Path) -> None:
    """A folder of Middlebury's im0.png + im1.png was 'no cloud.ply and no scene (left.png +
    right.png) in this folder' to view alone, where load_scene, eval and bench name the files
    to rename (1c96a879 added only Left.png + Right.png's words to view)."""
    from stereovision import render
    from stereovision.io import _MIDDLEBURY_NAMES

    for name in ("im0.png", "im1.png"):
        (tmp_path / name).write_bytes(b"")
    with pytest.raises(FileNotFoundError) as err:
        render.load_view_source(tmp_path)
    assert str(err.value) == (
        f"{tmp_path}: no cloud.ply and no scene (left.png + right.png) in this folder; it "
        f"{_MIDDLEBURY_NAMES}"
    )
    assert "rename im0.png, im1.png" in str(err.value)


@pytest.mark.parametrize("name", ["gt_disp.pfm", "calib.txt", "Q.dat"])
def test_load_scene_refuses_a_link_to_nothing(tmp_path: Path, name: str) -> None:
    """A scene's GT or calibration that is a link whose target moved (exists() is False) was
    taken as absent: the scene loaded without it, and `eval` said "no ground truth
    (gt_disp.pfm)" of a folder listing one. It is a FileNotFoundError naming link and target."""
    img = np.zeros((4, 6, 3), np.uint8)
    for side in ("left.png", "right.png"):
        cv2.imwrite(str(tmp_path / side), img)
    assert load_scene(tmp_path).gt is None  # no such file at all: still loaded without it
    (tmp_path / name).symlink_to(tmp_path / "moved" / name)
    with pytest.raises(FileNotFoundError) as err:
        load_scene(tmp_path)
    assert str(err.value) == (
        f"{tmp_path / name} is a link to {tmp_path / 'moved' / name}, which does not exist "
        "(moved or deleted?)"
    )


def test_a_scene_image_linked_to_nothing_is_found_and_named(tmp_path: Path) -> None:
    """A scene whose right.png is a link to a moved file was left out of find_scenes without a
    word (eval skipped it), where one whose left.png is was listed; both are listed now, and
    load_scene (and imread) say the link is broken, not only "not found". A folder named
    right.png still makes no scene."""
    img = np.zeros((4, 6, 3), np.uint8)
    for scene in ("a", "b", "c", "d"):
        (tmp_path / scene).mkdir()
        for side in ("left.png", "right.png"):
            cv2.imwrite(str(tmp_path / scene / side), img)
    for scene, side in (("b", "right.png"), ("c", "left.png")):
        (tmp_path / scene / side).unlink()
        (tmp_path / scene / side).symlink_to(tmp_path / "moved" / side)
    (tmp_path / "d" / "right.png").unlink()
    (tmp_path / "d" / "right.png").mkdir()
    assert find_scenes(tmp_path) == [tmp_path / "a", tmp_path / "b", tmp_path / "c"]
    for scene, side in (("b", "right.png"), ("c", "left.png")):
        with pytest.raises(FileNotFoundError) as err:
            load_scene(tmp_path / scene)
        assert str(err.value) == (
            f"image file not found: {tmp_path / scene / side} (a link to "
            f"{tmp_path / 'moved' / side}, which does not exist)"
        )


def test_a_link_loop_is_said_to_be_one(tmp_path: Path) -> None:
    """A link that leads back to itself (gt_disp.pfm -> gt.pfm -> gt_disp.pfm) was said to be "a
    link to gt.pfm, which does not exist (moved or deleted?)", of a gt.pfm that is there (a link
    too): the user looked for a moved file. Both readers now say it is a loop of links."""
    img = np.zeros((4, 6, 3), np.uint8)
    for side in ("left.png", "right.png"):
        cv2.imwrite(str(tmp_path / side), img)
    (tmp_path / "gt_disp.pfm").symlink_to("gt.pfm")
    (tmp_path / "gt.pfm").symlink_to("gt_disp.pfm")
    with pytest.raises(FileNotFoundError) as err:
        load_scene(tmp_path)
    assert str(err.value) == (
        f"{tmp_path / 'gt_disp.pfm'} is a link to gt.pfm, one of a loop of links that never "
        "reaches a file"
    )
    (tmp_path / "gt_disp.pfm").unlink()
    (tmp_path / "right.png").unlink()
    (tmp_path / "right.png").symlink_to("right.png")
    assert find_scenes(tmp_path) == [tmp_path]
    for read in (load_scene, lambda d: imread(d / "right.png")):
        with pytest.raises(FileNotFoundError) as err:
            read(tmp_path)
        assert str(err.value) == (
            f"image file not found: {tmp_path / 'right.png'} (a link to right.png, one of a "
            "loop of links that never reaches a file)"
        )


def test_load_scene_reads_q_dat_when_there_is_no_calib_txt(data_dir: Path) -> None:
    """middeval3/teddyH ships only OpenCV's Q (f 3000 px, 1/B 12.5 per metre, cx 398, cy 375):
    it was loaded without a calibration, so no depth, no 3-D and no metric figures."""
    scene = load_scene(data_dir / "middeval3/teddyH")
    assert scene.calib is not None
    assert scene.calib.unit == "m"
    assert scene.calib.focal_px == 3000.0
    assert scene.calib.baseline_m == pytest.approx(0.08)
    assert scene.calib.doffs_px == 0.0
    assert scene.calib.K1[0, 2] == 398.0 and scene.calib.K1[1, 2] == 375.0
    assert scene.calib.image_size == (900, 750)
    q_file = np.loadtxt(data_dir / "middeval3/teddyH/Q.dat")
    np.testing.assert_allclose(scene.calib.Q, q_file, rtol=1e-12)
    # Z = f B / d: a GT disparity of 60 px lies at 3000 * 0.08 / 60 = 4 m
    z = scene.calib.depth_from_disparity(np.array([[60.0]], dtype=np.float32))
    assert float(z[0, 0]) == pytest.approx(4.0, rel=1e-6)


def test_load_scene_prefers_calib_txt_over_q_dat(data_dir: Path) -> None:
    """TartanAir has both; its calib.txt (mm) wins, and the two describe the same rig."""
    d = data_dir / "tartanair/oldtown_easy_p000_001116"
    scene = load_scene(d)
    assert scene.calib is not None and scene.calib.unit == "mm"
    from_q = Calibration.from_q(d / "Q.dat", scene.calib.image_size)
    assert from_q.baseline_m == pytest.approx(scene.calib.baseline_m)
    assert from_q.focal_px == scene.calib.focal_px


def test_load_scene_refuses_a_q_dat_that_is_not_a_q_matrix(tmp_path: Path) -> None:
    img = np.full((8, 10, 3), 100, np.uint8)
    cv2.imwrite(str(tmp_path / "left.png"), img)
    cv2.imwrite(str(tmp_path / "right.png"), img)
    (tmp_path / "Q.dat").write_text("1 0 0 -5\n0 1 0 -4\n0 0 0 100\n0 0 -4 0\n")
    with pytest.raises(ValueError, match=r"Q\[3,2\] \(1/baseline -4\) must be positive"):
        load_scene(tmp_path)
    (tmp_path / "Q.dat").write_text("1 2 3\n")
    with pytest.raises(ValueError, match="16 finite numbers expected, got 3"):
        load_scene(tmp_path)
    (tmp_path / "Q.dat").write_text("1 0 0 -5\n0 1 0 -4\n0 0 1 100\n0 0 4 0\n")
    with pytest.raises(ValueError, match=r"Q\[2,2\] = 1, expected 0"):
        load_scene(tmp_path)


def test_pair_size_messages_give_sizes_not_numpy_shapes(tmp_path: Path) -> None:
    """A size mismatch said "left.png (375, 450, 3) and right.png (288, 384, 3) differ in
    size": numpy shapes, height first. It now says 450x375 (colour) as the rest of the
    project; one file (or one image) given twice is a warning."""
    from stereovision.io import check_pair_files, image_size_text

    assert image_size_text(np.zeros((375, 450, 3), np.uint8)) == "450x375 (colour)"
    assert image_size_text(np.zeros((375, 450), np.uint8)) == "450x375 (grey)"
    assert image_size_text(np.zeros((2, 3, 4), np.uint8)) == "3x2 (4 channels)"
    a, b = np.zeros((375, 450, 3), np.uint8), np.full((288, 384, 3), 9, np.uint8)
    with pytest.raises(ValueError) as err:
        check_pair_files(a, b, "l.png", "r.png")
    assert str(err.value) == (
        "l.png is 450x375 (colour), r.png is 384x288 (colour): the two images of a pair have "
        "one size"
    )
    cv2.imwrite(str(tmp_path / "left.png"), a)
    cv2.imwrite(str(tmp_path / "right.png"), b)
    with pytest.raises(ValueError) as err:
        load_scene(tmp_path)
    assert str(err.value) == (
        f"scene {tmp_path}: left.png is 450x375 (colour), right.png is 384x288 (colour): the "
        "two images of a pair have one size"
    )
    f = tmp_path / "left.png"
    assert check_pair_files(a, a.copy(), f, f, names=("L", "R")) == (
        "L and R are the same file: every disparity comes out 0 (two views of the scene are needed)"
    )
    assert check_pair_files(a, a.copy(), f, tmp_path / "right.png") == (
        f"{f} and {tmp_path / 'right.png'} are the same image: every disparity comes out 0 "
        "(two views of the scene are needed)"
    )
    assert check_pair_files(a, a + 1, f, tmp_path / "right.png") is None


def test_from_q_reads_a_multiple_of_q_as_q(data_dir: Path, tmp_path: Path) -> None:
    """Q acts on homogeneous coordinates: ROS image_geometry's StereoCameraModel writes it
    times -f B (Q[0,0] = f Tx, Q[3,2] = -f). Such a Q was refused as 'Q[0,0] = -240, expected
    1'; it is now the same calibration as OpenCV's Q."""
    q = np.loadtxt(data_dir / "middeval3/teddyH/Q.dat")
    plain = Calibration.from_q(data_dir / "middeval3/teddyH/Q.dat", (900, 750))
    (tmp_path / "Q.dat").write_text(
        "\n".join(" ".join(repr(float(v)) for v in r) for r in q * -240.0)
    )
    scaled = Calibration.from_q(tmp_path / "Q.dat", (900, 750))
    assert scaled.focal_px == 3000.0 and scaled.baseline_m == pytest.approx(0.08)
    np.testing.assert_allclose(scaled.Q, plain.Q, rtol=1e-12)
    np.testing.assert_allclose(scaled.K2, plain.K2, rtol=1e-12)
    # an entry out of place is named as read after the division, which is said
    (tmp_path / "Q.dat").write_text("2 0 0 -5\n0 2 0 -4\n0 0 2 100\n0 0 4 0\n")
    with pytest.raises(
        ValueError, match=r"Q\[2,2\] = 1, expected 0 \(the matrix divided by its Q\[0,0\] = 2\)$"
    ):
        Calibration.from_q(tmp_path / "Q.dat", (10, 8))
    # Q[0,0] = 0 is the one value refused there: 'expected 1' alone was wrong since c6850a6
    (tmp_path / "Q.dat").write_text("0 0 0 -5\n0 1 0 -4\n0 0 0 100\n0 0 4 0\n")
    with pytest.raises(
        ValueError,
        match=r"Q\[0,0\] = 0, expected 1 \(or any value but 0: a multiple of Q is read as Q\)$",
    ):
        Calibration.from_q(tmp_path / "Q.dat", (10, 8))


def test_a_q_dat_file_is_a_calibration_file(data_dir: Path, tmp_path: Path) -> None:
    """--calib Q.dat (the file, not its scene folder) said 'unrecognised calibration format'.
    It is read as OpenCV's Q, sized by image_size or the left.png beside it."""
    q = data_dir / "middeval3/teddyH/Q.dat"
    assert Calibration.from_file(q).image_size == (900, 750)
    alone = tmp_path / "rig_q.txt"
    shutil.copy(q, alone)
    assert Calibration.from_file(alone, image_size=(640, 480)).focal_px == 3000.0
    with pytest.raises(
        ValueError, match=r"rig_q\.txt does not give the image size and there is no"
    ):
        Calibration.from_file(alone)


def test_keep_previous_never_replaces_an_earlier_copy(tmp_path):
    """``calibrate -o rig.yaml`` run three times (a good rig, then two worse ones): the third
    run's copy replaced ``rig.previous.yaml``, the good rig, so no file held it any more. An
    earlier copy is kept now: the next one goes to ``rig.previous.2.yaml``, and a file already
    kept byte for byte is not copied twice."""
    from stereovision.io import keep_previous

    rig = tmp_path / "rig.yaml"
    assert keep_previous(rig) is None  # nothing to keep
    rig.write_bytes(b"good")
    assert keep_previous(rig) == tmp_path / "rig.previous.yaml"
    rig.write_bytes(b"worse")
    assert keep_previous(rig) == tmp_path / "rig.previous.2.yaml"
    assert (tmp_path / "rig.previous.yaml").read_bytes() == b"good"
    assert (tmp_path / "rig.previous.2.yaml").read_bytes() == b"worse"
    # the same bytes again (a run that changed nothing): no third copy
    assert keep_previous(rig) == tmp_path / "rig.previous.2.yaml"
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "rig.previous.2.yaml",
        "rig.previous.yaml",
        "rig.yaml",
    ]


@pytest.mark.parametrize("kind", ["dangling", "to a folder", "to the file", "loop", "same bytes"])
def test_keep_previous_leaves_a_link_under_its_name_untouched(tmp_path: Path, kind: str) -> None:
    """``rig.previous.yaml`` already a link of the user's: a dangling one had the copy written
    through it (a file made elsewhere, at its target); one to ``rig.yaml`` itself passed for
    the copy, so the rig about to be replaced was kept nowhere; a looping one failed (after
    calibrate's work). A link is a taken name now, left as it is: the copy goes to
    ``rig.previous.2.yaml``, as for a folder or a file of other bytes."""
    from stereovision.io import keep_previous

    rig = tmp_path / "rig.yaml"
    rig.write_bytes(b"good")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    link = tmp_path / "rig.previous.yaml"
    target = {
        "dangling": elsewhere / "victim.yaml",
        "to a folder": elsewhere,
        "to the file": rig,
        "loop": link,
        "same bytes": elsewhere / "same.yaml",
    }[kind]
    if kind == "same bytes":
        target.write_bytes(b"good")
    link.symlink_to(target)
    assert keep_previous(rig) == tmp_path / "rig.previous.2.yaml"
    assert (tmp_path / "rig.previous.2.yaml").read_bytes() == b"good"
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert sorted(p.name for p in elsewhere.iterdir()) == (
        ["same.yaml"] if kind == "same bytes" else []
    )


def test_keep_previous_copies_a_large_file_in_chunks(tmp_path):
    """``demo`` keeps a cloud.ply that no earlier run listed aside with keep_previous, which
    read the whole file into memory (and each earlier copy again to compare): a 2 GB cloud
    took 4 GB. It is compared and copied in chunks now: a 48 MB file, under 8 MB at the peak,
    and the copy holds its bytes."""
    import tracemalloc

    from stereovision.io import keep_previous

    cloud = tmp_path / "cloud.ply"
    data = np.random.default_rng(0).integers(0, 256, 48 << 20, dtype=np.uint8).tobytes()
    cloud.write_bytes(data)
    (tmp_path / "cloud.previous.ply").write_bytes(data[:-1] + b"x")  # same size, other bytes
    tracemalloc.start()
    try:
        kept = keep_previous(cloud)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert kept == tmp_path / "cloud.previous.2.ply"
    assert peak < 8 << 20, peak
    assert kept.read_bytes() == data
    assert keep_previous(cloud) == kept  # the same bytes: not copied again


@pytest.mark.parametrize(
    ("data", "says"),
    [
        (None, "got NoneType"),
        ("abc", "got str"),
        ([1, 2, 3], "got list"),
        (np.zeros((2, 2), np.uint8), "got array of shape (2, 2) dtype uint8"),
        (np.zeros(4, np.float32), "got array of shape (4,) dtype float32"),
    ],
)
def test_decode_image_names_what_is_not_bytes(data: object, says: str) -> None:
    # None, a str and a list were an AttributeError ("has no attribute 'size'"), a 2-D array
    # OpenCV's "(-215:Assertion failed) buf.checkVector(1, CV_8U) > 0"
    from stereovision.io import decode_image

    ok, png = cv2.imencode(".png", np.full((4, 6, 3), 7, np.uint8))
    assert ok
    for good in (png, png.tobytes(), bytearray(png.tobytes())):
        img = decode_image(good)  # type: ignore[arg-type]
        assert img is not None and img.shape == (4, 6, 3) and int(img.max()) == 7
    with pytest.raises(TypeError, match=r"^data: expected the file's bytes or a 1-D uint8 array, "):
        decode_image(data)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=re.escape(says)):
        decode_image(data)  # type: ignore[arg-type]


def test_decode_image_takes_a_column_or_row_of_bytes() -> None:
    # OpenCV 4's cv2.imencode gives its bytes as an (N, 1) array; decode_image read it (and a
    # (1, N) row) until the check above refused any 2-D array: now a vector is taken, flattened
    from stereovision.io import decode_image

    ok, png = cv2.imencode(".png", np.full((4, 6, 3), 7, np.uint8))
    assert ok
    for good in (png.reshape(-1, 1), png.reshape(1, -1)):
        img = decode_image(good)
        assert img is not None and img.shape == (4, 6, 3) and int(img.max()) == 7


def _png_of_size(width: int, height: int) -> bytes:
    """A 4 x 4 PNG whose header (its CRC made right) says ``width`` x ``height``."""
    import zlib

    png = cv2.imencode(".png", np.zeros((4, 4, 3), np.uint8))[1].tobytes()
    body = b"IHDR" + struct.pack(">II", width, height) + png[24:29]
    return png[:8] + struct.pack(">I", 13) + body + struct.pack(">I", zlib.crc32(body)) + png[33:]


@pytest.mark.parametrize(
    "data",
    [_png_of_size(100_000, 100_000), b"Pf\n-3 2\n-1\n" + bytes(24)],
    ids=["png-over-the-pixel-limit", "pfm-of-width-minus-3"],
)
def test_an_image_header_of_an_impossible_size_is_unreadable(tmp_path: Path, data: bytes) -> None:
    """A header saying 10^10 pixels (a corrupt or hostile PNG) or a negative width raised
    OpenCV's cv2.error from its size check, where other bytes it cannot decode are None: from
    decode_image, read_image, imread, read_depth_png and a bag's compressed image alike. They
    are unreadable now, each caller's own error naming the file."""
    from stereovision.export import read_depth_png, read_disparity_png
    from stereovision.io import decode_image, imread, read_image
    from stereovision.rosbag import decode_image as decode_message

    path = tmp_path / "frame.png"
    path.write_bytes(data)
    assert decode_image(data) is None
    for read in (read_image, imread):
        with pytest.raises(ValueError, match=r"cannot decode .*frame\.png as an image"):
            read(path)
    for read_png in (read_depth_png, read_disparity_png):
        with pytest.raises(ValueError, match=r"frame\.png: expected a single-channel 16-bit PNG"):
            read_png(path)

    class Msg:
        format = "png"

    Msg.data = np.frombuffer(data, np.uint8)  # type: ignore[attr-defined]
    with pytest.raises(ValueError, match=r"compressed image \('png', \d+ bytes\) does not decode"):
        decode_message(Msg())


def test_an_image_out_of_memory_is_a_memory_error_not_unreadable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """OpenCV's cv2.error of a failed allocation (a valid 16000 x 16000 PNG under ulimit -v)
    was swallowed with the impossible headers' errors: a good file read as "cannot decode
    frame.png as an image". It is a MemoryError saying so."""
    from stereovision.export import read_depth_png
    from stereovision.io import decode_image, read_image

    def no_memory(buf: object, flags: int) -> None:
        exc = cv2.error("Failed to allocate 768000000 bytes")
        exc.code, exc.err = cv2.Error.StsNoMem, "Failed to allocate 768000000 bytes"
        raise exc

    path = tmp_path / "frame.png"
    path.write_bytes(cv2.imencode(".png", np.zeros((4, 4), np.uint16))[1].tobytes())
    monkeypatch.setattr(cv2, "imdecode", no_memory)
    for read in (lambda: decode_image(path.read_bytes()), lambda: read_image(path)):
        with pytest.raises(MemoryError, match="not enough memory to decode the image: Failed"):
            read()
    with pytest.raises(MemoryError, match="768000000 bytes"):
        read_depth_png(path)


def test_write_pfm_refuses_what_it_would_change(tmp_path: Path) -> None:
    # a finite 1e300 was written as inf, and little_endian="no" (true) a little-endian file
    arr = np.array([[1.0, np.nan], [np.inf, -3.5e38]])  # -3.5e38 is beyond float32 too
    with pytest.raises(
        ValueError,
        match=re.escape(
            "arr: 1 finite value(s) beyond float32's range (e.g. -3.5e+38) would be written as inf"
        ),
    ):
        write_pfm(tmp_path / "a.pfm", arr)
    with pytest.raises(
        TypeError, match=re.escape("little_endian: expected True or False, got 'no'")
    ):
        write_pfm(tmp_path / "b.pfm", arr[:1], little_endian="no")  # type: ignore[arg-type]
    assert not (tmp_path / "a.pfm").exists() and not (tmp_path / "b.pfm").exists()
    big = np.array([[1e30, -2.0], [np.inf, np.nan]])  # within float32, and non-finite: kept
    write_pfm(tmp_path / "c.pfm", big, little_endian=np.bool_(False))
    np.testing.assert_array_equal(read_pfm(tmp_path / "c.pfm"), big.astype(np.float32))


@pytest.mark.parametrize("flag", ["no", None, 0])
def test_write_ply_drop_invalid_must_be_a_switch(tmp_path: Path, flag: object) -> None:
    # "no" (true) dropped the NaN points the caller meant to keep, without a word
    pts = np.array([[0.0, 0.0, 1.0], [np.nan, 0.0, 1.0]], np.float32)
    write_ply(tmp_path / "keep.ply", pts, drop_invalid=np.bool_(False))
    assert len(read_ply(tmp_path / "keep.ply")[0]) == 2
    with pytest.raises(
        TypeError, match=re.escape(f"drop_invalid: expected True or False, got {flag!r}")
    ):
        write_ply(tmp_path / "x.ply", pts, drop_invalid=flag)  # type: ignore[arg-type]
    assert not (tmp_path / "x.ply").exists()


@pytest.mark.parametrize("shape", [(1, 1), (1, 17), (1, 64), (3, 1), (2, 2)])
def test_read_pfm_of_a_single_row_is_writable(tmp_path: Path, shape: tuple[int, int]) -> None:
    """A single-row PFM came back as a read-only view of the file's bytes (its rows reversed
    were already contiguous, so nothing was copied): ``load_scene`` then failed with
    "assignment destination is read-only", ``eval`` of a 1 px tall scene said only that."""
    arr = np.arange(shape[0] * shape[1], dtype=np.float32).reshape(shape)
    arr.flat[0] = np.inf
    write_pfm(tmp_path / "gt_disp.pfm", arr)
    got = read_pfm(tmp_path / "gt_disp.pfm")
    assert got.flags.writeable and got.flags.c_contiguous and got.dtype == np.float32
    np.testing.assert_array_equal(got, arr)
    left = np.full((*shape, 3), 128, np.uint8)
    cv2.imwrite(str(tmp_path / "left.png"), left)
    cv2.imwrite(str(tmp_path / "right.png"), left)
    scene = load_scene(tmp_path)
    assert scene.gt is not None and np.isnan(scene.gt.flat[0])
    np.testing.assert_array_equal(scene.gt.flat[1:], arr.flat[1:])


# ------------------------------------------------------------- mutation audit (values the
# tests above did not pin: each of these failed on a one-line bug that every other test passed)


def test_read_pfm_refuses_a_zero_scale(tmp_path: Path) -> None:
    # the scale's sign is the byte order: 0 has none (it was read as big-endian data)
    (tmp_path / "zero.pfm").write_bytes(b"Pf\n1 1\n0\n" + struct.pack("<f", 1.0))
    with pytest.raises(ValueError, match=r"scale 0\.0 \(expected positive sizes and a non-zero"):
        read_pfm(tmp_path / "zero.pfm")


def test_read_pfm_scale_sets_the_byte_order_not_the_values(tmp_path: Path) -> None:
    # evaluation.md: the scale's sign is the byte order; a GT disparity of 1.5 px stored under
    # a scale of -2.5 (or 4.0, big-endian) is 1.5 px, not scaled by it (every shared GT has a
    # scale of -1.0, so a reader multiplying by |scale| passed every other test)
    vals = [1.5, 0.25]
    (tmp_path / "le.pfm").write_bytes(b"Pf\n2 1\n-2.5\n" + struct.pack("<2f", *vals))
    (tmp_path / "be.pfm").write_bytes(b"Pf\n2 1\n4.0\n" + struct.pack(">2f", *vals))
    for name in ("le.pfm", "be.pfm"):
        np.testing.assert_array_equal(read_pfm(tmp_path / name), [vals])


def test_find_scenes_needs_both_images(tmp_path: Path) -> None:
    for name in ("a/pair", "a/left_only"):
        (tmp_path / name).mkdir(parents=True)
        (tmp_path / name / "left.png").write_bytes(b"")
    (tmp_path / "a/pair/right.png").write_bytes(b"")
    (tmp_path / "a/left_only/right.png").mkdir()  # a folder is not an image
    assert find_scenes(tmp_path) == [tmp_path / "a/pair"]


def test_scan_scenes_names_half_scenes_and_skips_hidden_folders(tmp_path: Path) -> None:
    """eval and bench dropped a folder with left.png and no right.png without a word, and
    searched hidden folders batch skips (a scene's copy in .Trash was evaluated twice)."""
    for name in ("a", "b_left", "c_right", "d_dir", ".Trash/a", "e/.git/x"):
        (tmp_path / name).mkdir(parents=True)
    for name in ("a", "b_left", "d_dir", ".Trash/a", "e/.git/x"):
        (tmp_path / name / "left.png").write_bytes(b"")
    for name in ("a", "c_right", ".Trash/a", "e/.git/x"):
        (tmp_path / name / "right.png").write_bytes(b"")
    (tmp_path / "d_dir/right.png").mkdir()
    both = "(a scene folder holds both)"
    assert scan_scenes(tmp_path) == (
        [tmp_path / "a"],
        [
            (tmp_path / "b_left", f"has left.png but no right.png {both}"),
            (tmp_path / "c_right", f"has right.png but no left.png {both}"),
            (tmp_path / "d_dir", f"has left.png but right.png is a folder {both}"),
        ],
    )
    assert find_scenes(tmp_path) == [tmp_path / "a"]
    # a hidden root given is searched, as given
    assert find_scenes(tmp_path / ".Trash") == [tmp_path / ".Trash/a"]
    assert scan_scenes(tmp_path / "e/.git") == ([tmp_path / "e/.git/x"], [])


def test_scan_scenes_says_a_left_png_that_is_a_folder_is_one(tmp_path: Path) -> None:
    """A left.png that is a folder beside a right.png was 'has right.png but no left.png'
    (eval's and bench's line), where a right.png folder is said to be one."""
    from stereovision.io import _no_scene_under

    (tmp_path / "s" / "left.png").mkdir(parents=True)
    (tmp_path / "s" / "right.png").write_bytes(b"")
    why = "has right.png but left.png is a folder (a scene folder holds both)"
    assert scan_scenes(tmp_path) == ([], [(tmp_path / "s", why)])
    given = str(tmp_path / "s")
    half = scan_scenes(given)[1]
    assert _no_scene_under(tmp_path / "s", given, half) == f"{given}: {why}"


def test_scan_scenes_names_a_pair_named_in_another_case(tmp_path: Path) -> None:
    """A scene folder of Left.png + Right.png under the root given was left out without a word
    (eval's mean over one scene fewer), and a tree of only such folders was 'no scene under
    ROOT' alone (87b6bed's hint was for the folder given only). Each is skipped saying the
    names are lower case; the folder given itself is said as 87b6bed says it."""
    from stereovision.io import _no_scene_under

    for name in ("good", "cased"):
        (tmp_path / name).mkdir()
    for name in ("good/left.png", "good/right.png", "cased/Left.png", "cased/Right.png"):
        (tmp_path / name).write_bytes(b"")
    lower = "a scene's images are named left.png and right.png, in lower case"
    why = f"holds Left.png, Right.png: {lower}"
    assert scan_scenes(tmp_path) == ([tmp_path / "good"], [(tmp_path / "cased", why)])
    (tmp_path / "good/left.png").unlink()
    (tmp_path / "good/right.png").unlink()
    root, given = str(tmp_path), str(tmp_path / "cased")
    assert _no_scene_under(tmp_path, root, scan_scenes(root)[1]) == (
        f"no scene (left.png + right.png) under {root}; {given} holds Left.png, Right.png: {lower}"
    )
    assert _no_scene_under(tmp_path / "cased", given, scan_scenes(given)[1]) == (
        f"no scene (left.png + right.png) under {given} (Left.png, Right.png found: {lower})"
    )


def test_scan_scenes_finds_a_scene_linked_by_a_hidden_and_a_visible_name(tmp_path: Path) -> None:
    """434f57a's skip of hidden folders dropped a scene linked as ``.cache`` and as ``s``: the
    walk took the hidden link (first in name order) as the folder's one entry, so the visible
    one was an alias, and the hidden one was then skipped; eval found no scene at all."""
    from stereovision.batch import find_pairs

    ext, root = tmp_path / "ext", tmp_path / "root"
    ext.mkdir()
    root.mkdir()
    for side in ("left.png", "right.png"):
        (ext / side).write_bytes(b"")
    for link in (".cache", "s"):
        (root / link).symlink_to(ext, target_is_directory=True)
    assert scan_scenes(root) == ([root / "s"], [])
    # batch walks the same way (its pairs from the visible link)
    assert [j.name for j in find_pairs(root)] == ["s"]


def test_scene_max_disparity_ignores_a_gt_without_positive_disparity() -> None:
    # an all-zero (or negative) GT gives no range: the calibration's ndisp, else the width's
    zero = np.zeros((2, 2), np.float32)
    assert scene_max_disparity(zero, width=200, ndisp=100) == 112
    assert scene_max_disparity(-zero - 3.0, width=200) == 64  # 200 // 4 = 50 -> 64


# ------------------------------------------------------------- mutation audit: writers, readers


def test_atomic_write_cleans_up_after_an_interrupt_and_writes_text_as_utf8(tmp_path: Path) -> None:
    """A Ctrl-C in the body (not an Exception) must also leave the old file and no temporary
    one; text mode is UTF-8 whatever the locale."""
    dest = tmp_path / "f.txt"
    dest.write_bytes(b"old")
    with pytest.raises(KeyboardInterrupt), atomic_write(dest, "w") as fh:
        fh.write("new")
        raise KeyboardInterrupt
    assert dest.read_bytes() == b"old" and os.listdir(tmp_path) == ["f.txt"]
    with atomic_write(dest, "w") as fh:
        fh.write("z = 2.5 \u00b5m")
    assert dest.read_bytes() == "z = 2.5 \u00b5m".encode()


@pytest.mark.parametrize("code", [errno.ENOSPC, errno.EXDEV, errno.EACCES])
def test_atomic_write_failing_to_put_the_file_in_place_names_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, code: int
) -> None:
    """The rename failing (a full disk, another device, a folder that refuses it) was
    os.replace's "[Errno 28] No space left on device: '.../.x.pfm.k2j3abcd.tmp' -> '.../x.pfm'",
    the temporary file named first; a full disk in the body or the sync was "[Errno 28] No space
    left on device", naming no file. The file the caller gave is named, in the error's class and
    errno, and no temporary file stays (write_together alike)."""
    dest = tmp_path / "x.pfm"
    dest.write_bytes(b"old")
    said = os.strerror(code)

    def refused(src: object, dst: object) -> None:
        raise OSError(code, said, str(src), None, str(dst))

    monkeypatch.setattr(os, "replace", refused)
    with pytest.raises(OSError) as info:
        write_pfm(dest, np.ones((2, 2), np.float32))
    assert str(info.value) == f"cannot write {dest}: {said}" and info.value.errno == code
    assert isinstance(info.value, PermissionError) == (code == errno.EACCES)
    with pytest.raises(OSError, match=rf"^cannot write {re.escape(str(dest))}: {said}$"):
        write_together([(dest, b"new")])
    monkeypatch.undo()
    full = OSError(errno.ENOSPC, "No space left on device")
    with pytest.raises(OSError, match=r"^cannot write .*x\.pfm: No space left on device$"):
        with atomic_write(dest) as fh:
            raise full

    def sync_fails(fd: int) -> None:
        raise full

    monkeypatch.setattr(os, "fsync", sync_fails)
    with pytest.raises(OSError, match=r"^cannot write .*x\.pfm: No space left on device$"):
        with atomic_write(dest, "w") as fh:
            fh.write("new")
    assert os.listdir(tmp_path) == ["x.pfm"] and dest.read_bytes() == b"old"


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (Linux)")
def test_atomic_write_into_a_full_disk_names_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A real full disk fails the buffered write at the flush, and the file's close flushed
    it again: that second, bare "[Errno 28] No space left on device" replaced the error naming
    the file (write_pfm of a 4x4 or a 300x300 array into a full 64 KiB tmpfs), and replaced a
    body's own error too. /dev/full fails every write with ENOSPC, as such a disk does."""
    import stereovision.io as svio

    def full_disk(dest: Path, suffix: str) -> tuple[int, str]:
        return os.open("/dev/full", os.O_WRONLY), str(tmp_path / f".{dest.name}.tmp")

    monkeypatch.setattr(svio, "_temp_beside", full_disk)
    dest = tmp_path / "x.pfm"
    said = rf"^cannot write {re.escape(str(dest))}: No space left on device$"
    for n in (4, 300):
        with pytest.raises(OSError, match=said) as info:
            write_pfm(dest, np.zeros((n, n), np.float32))
        assert info.value.errno == errno.ENOSPC
    with pytest.raises(OSError, match=said):
        with atomic_write(dest, "w") as fh:
            fh.write("z = 2.5")
    with pytest.raises(ValueError, match=r"^the body's own$"):
        with atomic_write(dest) as fh:
            fh.write(b"abc")
            raise ValueError("the body's own")
    assert not dest.exists()


def test_pfm_sizes_and_range_limits(tmp_path: Path) -> None:
    """A PFM of width 0 or an infinite scale is refused; an empty array is not written; a
    float64 holding exactly float32's largest value is written as that value, not refused."""
    (tmp_path / "w0.pfm").write_bytes(b"Pf\n0 2\n-1.0\n")
    with pytest.raises(ValueError, match="bad PFM header"):
        read_pfm(tmp_path / "w0.pfm")
    (tmp_path / "inf.pfm").write_bytes(b"Pf\n1 1\n-1e999\n" + b"\0" * 4)
    with pytest.raises(ValueError, match="bad PFM header"):
        read_pfm(tmp_path / "inf.pfm")
    with pytest.raises(ValueError, match="non-empty"):
        write_pfm(tmp_path / "e.pfm", np.zeros((0, 3), np.float32))
    assert not (tmp_path / "e.pfm").exists()
    top = float(np.finfo(np.float32).max)
    write_pfm(tmp_path / "top.pfm", np.array([[top, -top]], np.float64))
    assert read_pfm(tmp_path / "top.pfm").tolist() == [[top, -top]]


def test_write_pfm_and_write_ply_refuse_masked_values(tmp_path: Path) -> None:
    """A numpy.ma map or cloud: asarray read its data, so write_pfm wrote a masked pixel's
    value (2.0) as a real one and write_ply kept a masked point, nothing said. Both refuse it
    as depth_from_disparity does, nothing written; a mask of nothing writes as before."""
    disparity = np.ma.masked_array([[1.0, 2.0], [3.0, 4.0]], mask=[[0, 1], [0, 0]])
    points = np.ma.masked_array(np.arange(6.0).reshape(2, 3), mask=[[0, 0, 0], [1, 1, 1]])
    for write, name, value, says in (
        (write_pfm, "d.pfm", disparity, "arr: a masked array (numpy.ma) with 1 masked pixel"),
        (write_ply, "c.ply", points, "points: a masked array (numpy.ma) with 3 masked pixels"),
    ):
        with pytest.raises(ValueError) as info:
            write(tmp_path / name, value)
        arg = says.split(":")[0]
        assert str(info.value) == (
            f"{says}, whose values would be read as real ones; pass {arg}.filled(np.nan)"
        )
        assert not (tmp_path / name).exists()
    disparity.mask = False
    np.testing.assert_array_equal(read_pfm(write_pfm(tmp_path / "d.pfm", disparity)), disparity)
    points.mask = False
    np.testing.assert_array_equal(read_ply(write_ply(tmp_path / "c.ply", points))[0], points)


def test_write_ply_drops_a_point_with_one_nan_coordinate(tmp_path: Path) -> None:
    pts = np.array([[1, 2, 3], [1, np.nan, 2], [np.inf, 0, 1], [4, 5, 6]], np.float32)
    cols = np.array([[1, 1, 1], [2, 2, 2], [3, 3, 3], [4, 4, 4]], np.uint8)
    write_ply(tmp_path / "c.ply", pts, cols)
    got, got_c = read_ply(tmp_path / "c.ply")
    assert got.tolist() == [[1, 2, 3], [4, 5, 6]]
    assert got_c is not None and got_c.tolist() == [[1, 1, 1], [4, 4, 4]]


def test_write_ply_refuses_float64_points_beyond_float32(tmp_path: Path) -> None:
    """A float64 point of 1e39 m became inf in the float32 cast: dropped without a word
    (NumPy's overflow warning alone), or written as inf with drop_invalid=False. Refused now,
    nothing written; a NaN point is still dropped."""
    pts = np.array([[1.0, 2.0, 3.0], [1e39, 0.0, 1.0]])
    for drop, fate in ((True, "would become inf (the point dropped)"),
                       (False, "would be written as inf")):  # fmt: skip
        with pytest.raises(ValueError) as exc:
            write_ply(tmp_path / "c.ply", pts, drop_invalid=drop)
        assert str(exc.value) == (
            f"points: 1 finite value(s) beyond float32's range (e.g. 1e+39) {fate}"
        )
    assert list(tmp_path.iterdir()) == []
    write_ply(tmp_path / "c.ply", np.array([[1.0, 2.0, 3.0], [np.nan, 0.0, 1.0]]))
    assert read_ply(tmp_path / "c.ply")[0].tolist() == [[1, 2, 3]]


def _ply(fmt: str, props: str, count: int) -> bytes:
    return f"ply\nformat {fmt} 1.0\nelement vertex {count}\n{props}end_header\n".encode("ascii")


def test_read_ply_big_endian_and_every_scalar_type(tmp_path: Path) -> None:
    """Big-endian data was read as little-endian; each type name maps to its own width and
    signedness (char -1 is not 255, ushort 40000 is not -25536, double is 8 bytes)."""
    props = "property char x\nproperty ushort y\nproperty double z\nproperty uint red\n"
    props += "property uchar green\nproperty uchar blue\n"
    fields = [("x", "i1"), ("y", "u2"), ("z", "f8"), ("r", "u4"), ("g", "u1"), ("b", "u1")]
    for fmt, order in (("binary_big_endian", ">"), ("binary_little_endian", "<")):
        rec = np.array(
            [(-1, 40000, 0.1, 200, 7, 9), (5, 3, -2.5, 1, 2, 3)],
            [(n, order + t) for n, t in fields],
        )
        (tmp_path / "t.ply").write_bytes(_ply(fmt, props, 2) + rec.tobytes())
        pts, cols = read_ply(tmp_path / "t.ply")
        assert pts.tolist() == [[-1, 40000, np.float32(0.1)], [5, 3, -2.5]], fmt
        assert cols is not None and cols.tolist() == [[200, 7, 9], [1, 2, 3]], fmt


def test_read_ply_header_and_truncation_errors(tmp_path: Path) -> None:
    """A file not starting with "ply", one vertex short (binary or ASCII), no vertex element
    or a vertex element without a count: each a ValueError saying so."""
    xyz = "property float x\nproperty float y\nproperty float z\n"
    good = _ply("ascii", xyz, 1) + b"1 2 3\n"
    (tmp_path / "n.ply").write_bytes(b"xyz" + good[3:])
    with pytest.raises(ValueError, match="not a PLY file"):
        read_ply(tmp_path / "n.ply")
    (tmp_path / "b.ply").write_bytes(_ply("binary_little_endian", xyz, 3) + b"\0" * 24)
    with pytest.raises(ValueError, match=r"truncated PLY file .*expected 3 vertices of 12"):
        read_ply(tmp_path / "b.ply")
    (tmp_path / "a.ply").write_bytes(_ply("ascii", xyz, 3) + b"1 2 3\n4 5 6\n")
    with pytest.raises(ValueError, match=r"truncated PLY file .*expected 3 vertices"):
        read_ply(tmp_path / "a.ply")
    (tmp_path / "nv.ply").write_bytes(b"ply\nformat ascii 1.0\nend_header\n")
    with pytest.raises(ValueError, match="no format or vertex element"):
        read_ply(tmp_path / "nv.ply")
    (tmp_path / "nc.ply").write_bytes(b"ply\nformat ascii 1.0\nelement vertex\n" + xyz.encode())
    (tmp_path / "nc.ply").write_bytes((tmp_path / "nc.ply").read_bytes() + b"end_header\n")
    with pytest.raises(ValueError, match="element vertex has no count"):
        read_ply(tmp_path / "nc.ply")


def test_read_ply_float_colours_with_nan_and_none(tmp_path: Path) -> None:
    """A NaN float colour is 0 and does not make the others 0-255; an empty cloud with float
    colours is read (the maximum of no colour was asked for)."""
    props = "property float x\nproperty float y\nproperty float z\n"
    props += "property float red\nproperty float green\nproperty float blue\n"
    (tmp_path / "f.ply").write_bytes(_ply("ascii", props, 1) + b"0 0 1 0.5 nan 1\n")
    _, cols = read_ply(tmp_path / "f.ply")
    assert cols is not None and cols.tolist() == [[128, 0, 255]]
    (tmp_path / "e.ply").write_bytes(_ply("binary_little_endian", props, 0))
    pts, cols = read_ply(tmp_path / "e.ply")
    assert pts.shape == (0, 3) and cols is not None and cols.shape == (0, 3)
    # plain names win over MeshLab's diffuse_ ones when a file has both
    both = props + "property uchar diffuse_red\nproperty uchar diffuse_green\n"
    both += "property uchar diffuse_blue\n"
    (tmp_path / "d.ply").write_bytes(_ply("ascii", both, 1) + b"0 0 1 1 1 1 5 6 7\n")
    _, cols = read_ply(tmp_path / "d.ply")
    assert cols is not None and cols.tolist() == [[255, 255, 255]]


def test_read_ply_bad_count_or_twice_named_property_names_the_file(tmp_path: Path) -> None:
    """'element vertex abc' was int()'s "invalid literal for int() with base 10", a property
    named twice NumPy's "field 'x' occurs more than once", -3 "no format or vertex element":
    none named the file or what was wrong in it."""
    xyz = "property float x\nproperty float y\nproperty float z\n"
    path = tmp_path / "bad cloud.ply"
    for count in ("abc", "-3", "2.5"):
        path.write_bytes(_ply("ascii", xyz, 1).replace(b"vertex 1", f"vertex {count}".encode()))
        with pytest.raises(ValueError) as err:
            read_ply(path)
        assert str(err.value) == (
            f"PLY file {path}: vertex count '{count}' is not a whole number (>= 0)"
        )
    path.write_bytes(_ply("ascii", xyz + "property float x\n", 1) + b"1 2 3 4\n")
    with pytest.raises(ValueError) as err:
        read_ply(path)
    assert str(err.value) == f"PLY file {path}: vertex property 'x' given twice"


def test_read_ply_vertex_element_without_a_count_or_with_two_says_so(tmp_path: Path) -> None:
    """'element vertex' with no count (or '1 2', two) was told off as "first element is
    ['vertex'], expected vertex": the element it names is the one it expects."""
    xyz = "property float x\nproperty float y\nproperty float z\n"
    path = tmp_path / "cloud.ply"
    for line, said in (
        ("vertex", "element vertex has no count"),
        ("vertex 1 2", "vertex count '1 2' is not a whole number (>= 0)"),
    ):
        path.write_bytes(_ply("ascii", xyz, 1).replace(b"vertex 1", line.encode()) + b"1 2 3\n")
        with pytest.raises(ValueError) as err:
            read_ply(path)
        assert str(err.value) == f"PLY file {path}: {said}"
    # a file of elements, none of them vertex, names those it holds
    path.write_bytes(_ply("ascii", xyz, 1).replace(b"vertex 1", b"face 1") + b"1 2 3\n")
    with pytest.raises(ValueError) as err:
        read_ply(path)
    assert str(err.value) == f"PLY file {path}: no vertex element (elements: face)"
    # a bare element line, no name: it said "first element is [], expected vertex"
    path.write_bytes(_ply("ascii", xyz, 1).replace(b"element vertex 1", b"element") + b"1 2 3\n")
    with pytest.raises(ValueError) as err:
        read_ply(path)
    assert str(err.value) == f"PLY file {path}: an element line names no element (expected vertex)"


def test_read_ply_16_bit_and_signed_colours_do_not_wrap(tmp_path: Path) -> None:
    """ushort colours (PDAL's PLY of a LAS cloud, 0-65535) wrapped in the uint8 cast: 32768
    was 0, 65280 was 0, 257 was 1; a short -5 was 251. 16-bit ones are scaled to 0-255, those
    all within 0-255 kept, negative ones 0."""
    cases = {
        ("ushort", "<u2"): (
            [[65535, 32768, 0], [65280, 257, 12850]],
            [[255, 128, 0], [254, 1, 50]],
        ),
        ("uint", "<u4"): ([[65535, 32768, 0], [65280, 257, 12850]], [[255, 128, 0], [254, 1, 50]]),
        ("short", "<i2"): ([[-5, 200, 255], [0, 7, 255]], [[0, 200, 255], [0, 7, 255]]),
    }
    for (kind, code), (stored, want) in cases.items():
        props = "property float x\nproperty float y\nproperty float z\n"
        props += "".join(f"property {kind} {c}\n" for c in ("red", "green", "blue"))
        fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")] + [(c, code) for c in "rgb"]
        rec = np.array([(i, 0, 1, *rgb) for i, rgb in enumerate(stored)], fields)
        (tmp_path / "c.ply").write_bytes(_ply("binary_little_endian", props, 2) + rec.tobytes())
        _, cols = read_ply(tmp_path / "c.ply")
        assert cols is not None and cols.tolist() == want, kind


def test_write_ply_refuses_a_transposed_colour_image(tmp_path: Path) -> None:
    """(W, H, 3) colours of (H, W, 3) points have the same size: each point got another
    pixel's colour. Two images must have one shape; a flat (N, 3) side pairs by count."""
    pts = np.arange(2 * 3 * 3, dtype=np.float32).reshape(2, 3, 3)
    img = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
    with pytest.raises(ValueError, match=r"colors: expected shape \(2, 3, 3\).*got \(3, 2, 3\)"):
        write_ply(tmp_path / "t.ply", pts, img.transpose(1, 0, 2))
    for p, c in ((pts, img), (pts.reshape(-1, 3), img), (pts, img.reshape(-1, 3))):
        back, cols = read_ply(write_ply(tmp_path / "ok.ply", p, c))
        np.testing.assert_array_equal(back, pts.reshape(-1, 3))
        assert cols is not None
        np.testing.assert_array_equal(cols, img.reshape(-1, 3))


def test_read_ply_header_ends_at_the_end_header_line(tmp_path: Path) -> None:
    """A comment holding the words "end_header" cut the header there: the vertex element
    after it was never read ("no vertex element")."""
    pts = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], np.float32)
    path = write_ply(tmp_path / "c.ply", pts, comment="written before end_header")
    back, _ = read_ply(path)
    np.testing.assert_array_equal(back, pts)
    (tmp_path / "n.ply").write_bytes(b"ply\nformat ascii 1.0\ncomment end_header\n")
    with pytest.raises(ValueError, match="not a PLY file"):
        read_ply(tmp_path / "n.ply")


def test_read_ply_skips_the_elements_before_the_vertices(tmp_path: Path) -> None:
    """A legal PLY whose first element is not vertex (MeshLab writes a camera element first)
    was refused ("first element is 'camera', expected vertex"): the rows of the elements before
    the vertices are skipped, ASCII or binary; a binary list among them cannot be, and says so."""
    camera = "element camera 1\nproperty float view_px\nproperty uchar flag\n"
    xyz = "property float x\nproperty float y\nproperty float z\n"
    pts = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], np.float32)
    path = tmp_path / "c.ply"
    ascii_head = _ply("ascii", xyz, 2).replace(
        b"element vertex", camera.encode() + b"element vertex"
    )
    path.write_bytes(ascii_head + b"7.5 1\n1 2 3\n4 5 6\n")
    np.testing.assert_array_equal(read_ply(path)[0], pts)
    head = _ply("binary_little_endian", xyz, 2)
    path.write_bytes(
        head.replace(b"element vertex", camera.encode() + b"element vertex")
        + np.array([7.5], "<f4").tobytes()
        + b"\x01"
        + pts.astype("<f4").tobytes()
    )
    np.testing.assert_array_equal(read_ply(path)[0], pts)
    # a camera row and no vertex rows: truncated
    path.write_bytes(ascii_head + b"7.5 1\n")
    with pytest.raises(ValueError) as err:
        read_ply(path)
    assert str(err.value) == f"truncated PLY file {path}: expected 2 vertices"
    listed = "element face 1\nproperty list uchar int vertex_indices\n"
    path.write_bytes(head.replace(b"element vertex", listed.encode() + b"element vertex"))
    with pytest.raises(ValueError) as err:
        read_ply(path)
    assert str(err.value) == (
        f"PLY file {path}: element 'face' before vertex holds a list property (its binary rows "
        "are not skipped)"
    )


def test_read_ply_first_line_is_ply_alone(tmp_path: Path) -> None:
    """A file whose first line merely began with "ply" ('plyfoo', 'ply 2') was read as a PLY
    file; the magic line is "ply" (a CR or trailing blanks allowed)."""
    xyz = "property float x\nproperty float y\nproperty float z\n"
    path = tmp_path / "c.ply"
    for magic in (b"plyfoo", b"ply 2", b"ply_cloud"):
        path.write_bytes(_ply("ascii", xyz, 1).replace(b"ply", magic, 1) + b"1 2 3\n")
        with pytest.raises(ValueError) as err:
            read_ply(path)
        assert str(err.value) == f"not a PLY file: {path}"
    for magic in (b"ply\r", b"ply "):
        path.write_bytes(_ply("ascii", xyz, 1).replace(b"ply", magic, 1) + b"1 2 3\n")
        np.testing.assert_array_equal(read_ply(path)[0], [[1.0, 2.0, 3.0]])
    # 0 bytes (an interrupted copy) was "not a PLY file" alone, another format's words
    path.write_bytes(b"")
    with pytest.raises(ValueError) as err:
        read_ply(path)
    assert str(err.value) == f"not a PLY file (the file is empty, 0 bytes): {path}"
    path.write_bytes(b"\xef\xbb\xbf")  # a byte-order mark alone is no empty file
    with pytest.raises(ValueError) as err:
        read_ply(path)
    assert str(err.value) == f"not a PLY file: {path}"


# ------------------------------------------------- mutation audit 2: scenes, images, path helpers


def test_load_scene_names_a_relative_folder_by_its_own_names(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``stereovision eval .`` inside a scene's folder listed it as "/", and ``eval tsukuba``
    beside it as "/tsukuba", ``eval ../tsukuba`` as "../tsukuba": the name is
    ``<family>/<scene>`` of the folder itself, however it is spelt."""
    monkeypatch.chdir(data_dir / "middlebury2001" / "tsukuba")
    for spelt in (".", "../tsukuba", Path("..") / "tsukuba" / "."):
        assert load_scene(spelt).name == "middlebury2001/tsukuba", spelt
    monkeypatch.chdir(data_dir / "middlebury2001")
    assert load_scene("tsukuba").name == "middlebury2001/tsukuba"


def test_load_scene_names_the_folder_a_dotdot_after_a_link_reads(
    data_dir: Path, tmp_path: Path
) -> None:
    """``home/tsu/../venus`` with ``tsu`` a link to ``/data/middlebury2001/tsukuba``: the OS
    reads ``/data/middlebury2001/venus`` but the name folded '..' as text, 'home/venus' (a
    folder that is not there). A '..' after a link goes up from the link's target now; other
    '..' and the links' own names are kept as spelt."""
    (tmp_path / "home").mkdir()
    (tmp_path / "home" / "tsu").symlink_to(data_dir / "middlebury2001" / "tsukuba")
    s = load_scene(tmp_path / "home" / "tsu" / ".." / "venus")
    assert s.name == "middlebury2001/venus"
    np.testing.assert_array_equal(
        s.left, imread(data_dir / "middlebury2001" / "venus" / "left.png")
    )
    assert load_scene(tmp_path / "home" / ".." / "home" / "tsu").name == "home/tsu"


def _jpeg_with_orientation(image: np.ndarray, orientation: int) -> bytes:
    """A JPEG of ``image`` with an EXIF APP1 segment holding only the Orientation tag."""
    ok, jpg = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 100])
    assert ok
    tiff = b"II*\x00" + struct.pack("<I", 8)  # little-endian TIFF header, IFD at offset 8
    tiff += struct.pack("<H", 1) + struct.pack("<HHIHH", 0x0112, 3, 1, orientation, 0)
    tiff += struct.pack("<I", 0)  # no next IFD
    app1 = b"Exif\x00\x00" + tiff
    data = jpg.tobytes()
    return data[:2] + b"\xff\xe1" + struct.pack(">H", len(app1) + 2) + app1 + data[2:]


def test_images_are_read_upright_as_their_exif_orientation_says(tmp_path: Path) -> None:
    """A camera's JPEG tagged "rotate 90 clockwise" (EXIF Orientation 6) is read turned, as
    cv2.imread and image viewers show it, by imread and read_image alike."""
    img = np.zeros((16, 24, 3), np.uint8)
    img[:8, :8] = 255  # a white top-left block
    path = tmp_path / "portrait.jpg"
    path.write_bytes(_jpeg_with_orientation(img, 6))
    for got in (imread(path), read_image(path), imread(path, gray=True)):
        assert got.shape[:2] == (24, 16)
        assert got[:8, 8:].min() > 200 and got[:8, :8].max() < 50  # now top right
    np.testing.assert_array_equal(imread(path), cv2.imread(str(path)))


def test_a_folder_or_a_float_file_is_no_image(tmp_path: Path) -> None:
    """A folder given as an image is 'not a regular file' (ValueError, as for any other input),
    not 'not found' nor NumPy's IsADirectoryError; a float32 TIFF is refused, not read
    as uint16 by a cast (0.5 -> 0), saying why (it was "cannot decode" alone)."""
    (tmp_path / "left.png").mkdir()
    for read in (imread, read_image):
        with pytest.raises(ValueError, match=r"^image file is not a regular file: .*left\.png \("):
            read(tmp_path / "left.png")
    colour = np.dstack([np.array([[0.5, 300.0]], np.float32)] * 3)  # decodes as float32 BGR
    assert cv2.imwrite(str(tmp_path / "f.tiff"), colour)
    # it decodes, as float32: said so, not only "cannot decode" as of a damaged file
    says = r": its pixels are float32 values, not 8- or 16-bit ones \(save it as an 8- or 16-bit"
    for read in (imread, read_image):
        with pytest.raises(ValueError, match=rf"^cannot decode .*f\.tiff as an image{says}"):
            read(tmp_path / "f.tiff")
    assert cv2.imwrite(str(tmp_path / "i.tiff"), np.zeros((2, 3), np.int32))
    with pytest.raises(ValueError, match=r"i\.tiff as an image: its pixels are int32 values"):
        read_image(tmp_path / "i.tiff")
    cut = tmp_path / "cut.tiff"  # a TIFF that does not decode at all: no such words
    cut.write_bytes((tmp_path / "f.tiff").read_bytes()[:40])
    with pytest.raises(ValueError, match=r"^cannot decode .*cut\.tiff as an image$"):
        read_image(cut)


def test_a_signed_16_bit_tiff_is_read_by_its_values_or_refused(tmp_path: Path) -> None:
    """A TIFF of int16 pixels: OpenCV's IMREAD_COLOR keeps the top 8 of the bits taken as
    unsigned, so -5 read as 255 (white) and -32768 as 128, without a word; read_image (depth's)
    kept those 8 bits of one of values >= 0 too (1000 -> 3), where the same frame unsigned
    keeps 16. Negative pixels are refused, saying so (imread, read_image, decode_image, batch's
    worker); values >= 0 read as the unsigned file reads."""
    from stereovision.batch import _decode
    from stereovision.io import decode_image

    signed = np.array([[-5, 0, 1000], [32767, -32768, 256]], np.int16)
    path = tmp_path / "s.tiff"
    assert cv2.imwrite(str(path), signed)
    for read in (imread, read_image):
        with pytest.raises(ValueError) as info:
            read(path)
        assert str(info.value) == (
            f"cannot decode {path} as an image: its pixels are signed 16-bit values, some "
            "negative, not unsigned 8- or 16-bit ones (save it as an unsigned 8- or 16-bit PNG "
            "or TIFF)"
        )
    assert decode_image(path.read_bytes()) is None
    with pytest.raises(ValueError, match=r"^cannot decode s\.tiff as an image: its pixels are si"):
        _decode("s.tiff", path.read_bytes())
    frame = np.array([[5, 0, 1000], [32767, 4095, 256]], np.int16)  # none negative
    unsigned = tmp_path / "u.tiff"
    assert cv2.imwrite(str(unsigned), frame.astype(np.uint16))
    assert cv2.imwrite(str(path), frame)
    got = read_image(path)
    assert got.dtype == np.uint16 and got[..., 0].tolist() == frame.tolist()
    np.testing.assert_array_equal(got, read_image(unsigned))
    np.testing.assert_array_equal(imread(path), imread(unsigned))  # top 8 bits, as before


@pytest.mark.parametrize("channels", [1, 3], ids=["Pf", "PF"])
def test_a_pfm_is_no_image(tmp_path: Path, channels: int) -> None:
    """OpenCV decodes a PFM under IMREAD_COLOR, its floats rounded and clipped to 0-255: a
    disparity map given as an image was read as [[0, 1, 4], [100, 255, 0]] (a Pf file as a
    2-D array, not the documented (H, W, 3)), `depth gt_disp.pfm gt_disp.pfm` matched it, and
    imread(gray=True) was OpenCV's "Bad number of channels". It is refused, saying what it is."""
    from stereovision.io import decode_image, read_image

    values = np.array([[0.4, 0.6, 3.7], [100.2, 300.0, -5.0]], np.float32)
    path = write_pfm(tmp_path / "disp.pfm", np.dstack([values] * 3) if channels == 3 else values)
    says = (
        r"^cannot decode .*disp\.pfm as an image: it is a PFM file of floating-point values "
        r"\(a disparity map\?\), not an 8- or 16-bit image$"
    )
    for read in (imread, read_image, lambda p: imread(p, gray=True)):
        with pytest.raises(ValueError, match=says):
            read(path)
    assert decode_image(path.read_bytes()) is None
    np.testing.assert_array_equal(
        read_pfm(path)[..., 0] if channels == 3 else read_pfm(path), values
    )


def test_a_file_starting_pf_without_a_separator_is_not_called_a_pfm(tmp_path: Path) -> None:
    """A PFM header is ``Pf`` or ``PF`` and a whitespace character: a text file that merely
    starts with the letters (``PFX notes``) is not said to be a disparity map."""
    for text in (b"PFX notes\n", b"Pf"):
        path = tmp_path / "notes.png"
        path.write_bytes(text)
        with pytest.raises(ValueError, match=r"^cannot decode .*notes\.png as an image") as info:
            imread(path)
        assert "PFM" not in str(info.value)


def test_a_video_is_named_whatever_the_case_of_its_suffix(tmp_path: Path) -> None:
    for name, says in (("CLIP.AVI", "it is a video"), ("run.Bag", "it is a ROS bag")):
        (tmp_path / name).write_bytes(b"\x00" * 64)
        with pytest.raises(ValueError, match=rf"as an image: {says}; this command"):
            imread(tmp_path / name)


def _scene(folder: Path, width: int, height: int) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(0)
    for name in ("left.png", "right.png"):
        cv2.imwrite(str(folder / name), rng.integers(0, 255, (height, width, 3), np.uint8))
    return folder


def test_load_scene_right_image_gt_width_and_range_without_gt(tmp_path: Path) -> None:
    """The right image is right.png's pixels; a GT one column narrower than the images is
    refused as one a row shorter is; without GT or calibration the range is a quarter of the
    width (200 // 4 = 50 -> 64), not of the height (40 // 4 -> 16)."""
    d = _scene(tmp_path / "fam" / "wide", 200, 40)
    s = load_scene(d)
    np.testing.assert_array_equal(s.right, cv2.imread(str(d / "right.png")))
    assert not np.array_equal(s.left, s.right)
    assert s.gt is None and s.calib is None and s.max_disparity == 64
    write_pfm(d / "gt_disp.pfm", np.full((40, 199), 5.0, np.float32))
    with pytest.raises(ValueError) as info:
        load_scene(d)
    assert str(info.value) == f"scene {d}: gt_disp.pfm is 199x40, left.png 200x40"
    # a file is no scene folder: it was "scene directory not found" (a deliberate change)
    with pytest.raises(NotADirectoryError, match=r"left\.png is a file, not a scene directory"):
        load_scene(d / "left.png")


def test_scene_range_ignores_infinite_gt_and_calib_ndisp_inf_names_the_file(
    tmp_path: Path,
) -> None:
    """+inf (the files' unknown) is no disparity of the range: [inf, 30] gives
    round_up16(33) = 48, not an overflow; an ndisp=inf in calib.txt is refused naming the
    file and the key, as NaN, 0 and -5 are."""
    gt = np.array([[np.inf, 30.0], [-np.inf, np.nan]], np.float32)
    assert scene_max_disparity(gt, width=100) == 48
    d = _scene(tmp_path / "fam" / "s", 64, 8)
    calib = d / "calib.txt"
    calib.write_text(
        "cam0=[100 0 32; 0 100 4; 0 0 1]\ncam1=[100 0 32; 0 100 4; 0 0 1]\ndoffs=0\n"
        "baseline=120\nwidth=64\nheight=8\nndisp=inf\n"
    )
    with pytest.raises(ValueError) as info:
        load_scene(d)
    assert str(info.value) == (
        f"{calib}: ndisp=inf: expected the disparity range in pixels, a positive finite number"
    )
    calib.write_text(calib.read_text().replace("ndisp=inf", "ndisp=20"))
    assert load_scene(d).max_disparity == 32  # no GT: the calibration's ndisp, rounded up
    calib.write_text(calib.read_text().replace("0 0 1]\ncam1", "0 0 1; 1 2 3]\ncam1"))
    with pytest.raises(
        ValueError, match=r"calib\.txt:1: cannot parse cam0=.*, got rows of 3, 3, 3, 3 numbers\)$"
    ):
        load_scene(d)


def test_scene_range_of_an_ndisp_the_images_have_no_room_for(tmp_path: Path) -> None:
    """ETH3D's calib.txt gives ndisp = the width (941 on playground): a scene without GT took
    round_up16(941) = 944 px, wider than its images, and bench and view refused it as too
    narrow for its own range. Such an ndisp bounds nothing (the width's quarter); one the
    images have room for is the range, as before."""
    from stereovision.io import scene_too_narrow

    assert scene_max_disparity(None, width=941, ndisp=941) == 240  # 941 // 4 = 235 -> 240
    assert scene_max_disparity(None, width=941, ndisp=930) == 240  # 944 px: no room either
    assert scene_max_disparity(None, width=941, ndisp=920) == 928
    d = _scene(tmp_path / "eth3d" / "s", 70, 8)
    (d / "calib.txt").write_text(
        "cam0=[100 0 35; 0 100 4; 0 0 1]\ncam1=[100 0 35; 0 100 4; 0 0 1]\ndoffs=0\n"
        "baseline=60\nwidth=70\nheight=8\nndisp=70\n"
    )
    s = load_scene(d)
    assert (s.max_disparity, scene_too_narrow(s)) == (32, None)  # 70 // 4 = 17 -> 32


def test_load_scene_refuses_a_calib_txt_of_another_image_size(tmp_path: Path) -> None:
    """A calib.txt whose width and height are not the images' (a scene cropped or resized,
    its calib.txt copied as it was) was loaded, and eval and view failed at the first depth
    with depth_map's "calibration is for 80x8 images, got 70x8", naming neither scene nor
    file. load_scene refuses it, naming both; a calib.txt of the images' size loads."""
    d = _scene(tmp_path / "fam" / "s", 70, 8)
    text = (
        "cam0=[100 0 35; 0 100 4; 0 0 1]\ncam1=[100 0 35; 0 100 4; 0 0 1]\ndoffs=0\n"
        "baseline=60\nwidth={}\nheight={}\nndisp=16\n"
    )
    for size in ((80, 8), (70, 20)):
        (d / "calib.txt").write_text(text.format(*size))
        with pytest.raises(ValueError) as info:
            load_scene(d)
        assert str(info.value) == (
            f"scene {d}: calib.txt is for {size[0]}x{size[1]} images (its width and height), "
            "left.png is 70x8"
        )
    (d / "calib.txt").write_text(text.format(70, 8))
    calib = load_scene(d).calib
    assert calib is not None and tuple(calib.image_size) == (70, 8)


def test_find_scenes_of_a_file_says_it_is_a_file(tmp_path: Path) -> None:
    """find_scenes / scan_scenes of a file (a scene's left.png) or a device said "scene root
    not found" of a path that is there (eval and bench say it in their own words first); it is
    a NotADirectoryError saying what it is, as load_scene's; a missing path is not found."""
    from stereovision.io import scan_scenes

    (tmp_path / "left.png").write_bytes(b"")
    for path, kind in (
        (tmp_path / "left.png", "a file"),
        (Path("/dev/null"), "not a folder (a device or a pipe)"),
    ):
        for find in (find_scenes, scan_scenes):
            with pytest.raises(NotADirectoryError) as info:
                find(path)
            assert str(info.value) == (
                f"{path} is {kind}, not a scene root: give the folder holding the scene folders "
                "(or one scene folder, holding left.png and right.png)"
            )
    with pytest.raises(FileNotFoundError, match=r"^scene root not found: .*none$"):
        find_scenes(tmp_path / "none")


def test_scan_scenes_of_a_root_that_cannot_be_listed_is_an_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, unlistable: Callable[[Any], None]
) -> None:
    """A scene root that cannot be listed (no permission) was the walk's warning 'cannot
    search folder in: ...; the pairs in it, if any, are left out' and then eval's 'no scene
    (left.png + right.png) under in', as if it held none: an error naming it now, as batch's
    input folder (564d04ae); eval and bench say it in one line, exit 2."""
    from stereovision.io import scan_scenes

    root = tmp_path / "in"
    (root / "a").mkdir(parents=True)
    unlistable(str(root))
    said = f"cannot search scene root {root}: Permission denied"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the error alone, no warning before it
        with pytest.raises(PermissionError) as err:
            scan_scenes(root)
    assert str(err.value) == said


def test_path_helpers_of_the_cli(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """missing_folders lists absolute folders, skips '..' and stops at a (dangling) link;
    check_output_folder refuses a folder it cannot write in; refuse_an_input looks past an
    input not given; lock_folder tells a held lock (busy) from its own."""
    from stereovision.io import (
        check_output_folder,
        lock_folder,
        missing_folders,
        refuse_an_input,
    )

    monkeypatch.chdir(tmp_path)
    assert missing_folders("new/../out") == [tmp_path / "new/../out", tmp_path / "new"]
    assert missing_folders("a/b") == [tmp_path / "a/b", tmp_path / "a"]
    (tmp_path / "link").symlink_to(tmp_path / "gone")
    assert missing_folders("link/sub") == [tmp_path / "link/sub"]  # not the link itself
    with pytest.raises(PermissionError, match=r"^-o /proc/x/out: cannot write in /proc \("):
        check_output_folder("/proc/x/out", "-o")
    (tmp_path / "l.png").write_bytes(b"x")
    with pytest.raises(ValueError, match=r"^--plot l\.png: is the left image \(l\.png\)"):
        refuse_an_input("--plot", Path("l.png"), {"the mask": None, "the left image": "l.png"})
    fd, busy = lock_folder(tmp_path)
    assert isinstance(fd, int) and busy is False
    try:
        assert lock_folder(tmp_path) == (None, True)  # another descriptor: the lock is held
    finally:
        os.close(fd)
    fd, busy = lock_folder(tmp_path)
    assert fd is not None and busy is False
    os.close(fd)


def test_load_scene_refuses_a_colour_pfm_as_gt_saying_so(tmp_path: Path) -> None:
    """A colour PFM (PF, 3 channels) of the images' size as gt_disp.pfm was refused as
    'gt_disp.pfm is 6x4, left.png 6x4', a size mismatch between two equal sizes."""
    d = _scene(tmp_path / "fam" / "s", 6, 4)
    write_pfm(d / "gt_disp.pfm", np.ones((4, 6, 3), np.float32))
    with pytest.raises(ValueError) as info:
        load_scene(d)
    assert str(info.value) == (
        f"scene {d}: gt_disp.pfm holds 3 channels (a colour PF file): a GT disparity map has "
        "one value per pixel (Pf)"
    )


def test_pair_check_keep_previous_and_quiet_decodes_edge_cases(tmp_path: Path) -> None:
    """Paths that do not exist (the GUI's, a bag's) are not 'the same file'; keep_previous of
    a folder copies nothing; an empty file is 'cannot decode' for read_image too (not
    OpenCV's assertion); a decode inside another keeps OpenCV silent until the outer ends."""
    from stereovision.io import _opencv_quiet, check_pair_files, keep_previous

    a, b = np.zeros((2, 3, 3), np.uint8), np.ones((2, 3, 3), np.uint8)
    assert check_pair_files(a, b, tmp_path / "l.png", tmp_path / "r.png") is None
    (tmp_path / "shot.png").mkdir()
    assert keep_previous(tmp_path / "shot.png") is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shot.png"]
    (tmp_path / "empty.png").write_bytes(b"")
    with pytest.raises(
        ValueError, match=r"^cannot decode .*empty\.png as an image: the file is empty \(0 bytes\)$"
    ):
        read_image(tmp_path / "empty.png")
    log = cv2.utils.logging  # type: ignore[attr-defined]
    before = log.getLogLevel()
    with _opencv_quiet():
        with _opencv_quiet():
            pass
        assert log.getLogLevel() == log.LOG_LEVEL_SILENT
    assert log.getLogLevel() == before


def test_scene_calibrations_are_the_calib_txt_values(data_dir: Path, tmp_path: Path) -> None:
    """Each calib.txt layout read by hand: K of cam0, baseline in mm, the image size, doffs;
    depth Z = f B / (d + doffs) in metres."""
    kitti = load_scene(data_dir / "kitti2015/000005_10").calib
    assert kitti is not None and kitti.unit == "mm" and kitti.image_size == (1242, 375)
    np.testing.assert_array_equal(
        kitti.K1, [[721.5377, 0, 609.5593], [0, 721.5377, 172.854], [0, 0, 1]]
    )
    assert kitti.baseline_m == pytest.approx(0.532725, rel=1e-12)
    z = kitti.depth_from_disparity(np.array([[50.0]], np.float32))
    assert float(z[0, 0]) == pytest.approx(721.5377 * 0.532725 / 50, rel=1e-6)  # 7.688 m
    tartan = load_scene(data_dir / "tartanair/oldtown_easy_p000_001116").calib
    assert tartan is not None and tartan.focal_px == 320.0 and tartan.doffs_px == 0.0
    assert float(tartan.depth_from_disparity(np.array([[8.0]], np.float32))[0, 0]) == 10.0
    play = load_scene(data_dir / "eth3d/playground").calib
    assert play is not None and play.image_size == (941, 490)
    assert (play.K1[0, 2], play.K1[1, 2], play.baseline) == (541.836, 255.198, 59.5549)
    # Middlebury 2014's layout: cam1's cx is cam0's + doffs
    d = _scene(tmp_path / "fam" / "mb2014", 64, 8)
    (d / "calib.txt").write_text(
        "cam0=[100 0 30; 0 100 4; 0 0 1]\ncam1=[100 0 40; 0 100 4; 0 0 1]\ndoffs=10\n"
        "baseline=120\nwidth=64\nheight=8\nndisp=20\nisint=0\nvmin=2\nvmax=18\n"
    )
    mb = load_scene(d).calib
    assert mb is not None and mb.doffs_px == 10.0 and mb.K1[0, 2] == 30.0 and mb.K2[0, 2] == 40.0
    z = mb.depth_from_disparity(np.array([[20.0, -10.0]], np.float32))
    assert float(z[0, 0]) == pytest.approx(0.4, rel=1e-6)  # 120 mm * 100 / (20 + 10)
    assert np.isnan(z[0, 1])  # d + doffs = 0: no depth


def test_scene_range_fallbacks_and_16_bit_scene_images(tmp_path: Path) -> None:
    """ndisp is the range as given (16 -> 16; not 1.1 x, which gives 32); the width's quarter
    rounds down (65 // 4 = 16 -> 16); a scene's 16-bit PNGs are read as evaluation.md says,
    8-bit as cv2.imread reads them (the top 8 bits), both images alike."""
    assert scene_max_disparity(None, width=100, ndisp=16) == 16
    assert scene_max_disparity(None, width=65) == 16
    d = tmp_path / "fam" / "deep"
    d.mkdir(parents=True)
    deep = np.full((4, 6, 3), 0x1234, np.uint16)
    for name in ("left.png", "right.png"):
        assert cv2.imwrite(str(d / name), deep)
        deep = deep + 0x0100
    s = load_scene(d)
    assert s.left.dtype == np.uint8 and s.right.dtype == np.uint8
    assert (int(s.left[0, 0, 0]), int(s.right[0, 0, 0])) == (0x12, 0x13)


def test_find_scenes_follows_linked_folders_once(data_dir: Path, tmp_path: Path) -> None:
    """Scenes linked into a folder (``ln -s /data/middlebury2001 mine/mb``) were not found:
    Path.rglob does not enter a link to a folder, so ``eval mine`` said there was no scene.
    Links are followed, a link back up the tree (a loop) once."""
    (tmp_path / "fam").mkdir()
    (tmp_path / "mb").symlink_to(data_dir / "middlebury2001")
    (tmp_path / "fam" / "terrace").symlink_to(data_dir / "eth3d" / "terrace")
    (tmp_path / "fam" / "loop").symlink_to(tmp_path)
    assert find_scenes(tmp_path) == [
        tmp_path / "fam" / "terrace",
        tmp_path / "mb" / "tsukuba",
        tmp_path / "mb" / "venus",
    ]
    assert load_scene(tmp_path / "mb" / "venus").name == "mb/venus"  # the link's own name


@pytest.mark.parametrize("folder", ["data/cones", Path("data/cones")])
def test_scene_too_narrow_of_a_folder_says_to_load_it(folder: object) -> None:
    """scene_too_narrow("data/cones") was "AttributeError: 'str' object has no attribute
    'max_disparity'", as bench_scene's was (d6b69581): it says it in bench_scene's words."""
    from stereovision.io import scene_too_narrow

    with pytest.raises(TypeError) as info:
        scene_too_narrow(folder)  # type: ignore[arg-type]
    assert str(info.value) == (
        "scene: got the path 'data/cones', not a scene: load it first "
        "(stereovision.io.load_scene(path))"
    )


def test_scene_too_narrow_of_none_is_a_type_error_naming_scene() -> None:
    """scene_too_narrow(None) was "AttributeError: 'NoneType' object has no attribute
    'max_disparity'", naming no argument."""
    from stereovision.io import scene_too_narrow

    with pytest.raises(TypeError) as info:
        scene_too_narrow(None)  # type: ignore[arg-type]
    assert str(info.value) == "scene: expected a scene (stereovision.io.load_scene(path)), got None"


def test_load_scene_refuses_a_gt_of_the_other_sign(tmp_path: Path) -> None:
    """A GT whose known disparities are all negative (the other sign convention, x_right -
    x_left) was evaluated as it was: a tsukuba crop's every method 100 % bad on every
    threshold, without a word. It is refused, saying so; a GT with positive values beside
    negative ones, all 0 or all unknown loads as before."""
    d = _scene(tmp_path / "fam" / "s", 3, 2)
    for gt in ([[-5.0, -14.0, np.inf], [np.nan, -7.5, -5.0]], [[-2.5, 0.0, 0.0]] * 2):
        write_pfm(d / "gt_disp.pfm", np.array(gt, np.float32))
        with pytest.raises(ValueError) as info:
            load_scene(d)
        low, high = ("-14", "-5") if gt[0][0] == -5.0 else ("-2.5", "0")
        assert str(info.value) == (
            f"scene {d}: gt_disp.pfm's disparities are all negative ({high} to {low} px), where "
            "a left image's are >= 0 (x_left - x_right): a GT of the other sign (negate it), or "
            "the right image's?"
        )
    for gt in ([[-0.5, 3.0, 2.0]] * 2, [[0.0] * 3] * 2, [[np.inf] * 3] * 2):
        write_pfm(d / "gt_disp.pfm", np.array(gt, np.float32))
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert load_scene(d).gt is not None


def test_load_scene_keeps_gt_zero_and_large_values_as_disparities(tmp_path: Path) -> None:
    """evaluation.md: only inf or NaN is unknown. A GT of 0 (a point at infinity, TartanAir's
    sky) is a known disparity, not KITTI's raw 'no LiDAR' 0 (its SOURCE conversion made those
    +inf); 65504 (float16's largest) is a value too, and then the range says the scene is
    too narrow for it."""
    from stereovision.io import scene_too_narrow

    d = _scene(tmp_path / "fam" / "s", 4, 2)
    gt = np.array([[0.0, 65504.0, np.inf, -np.inf], [np.nan, 1.5, 0.0, 2.0]], np.float32)
    write_pfm(d / "gt_disp.pfm", gt)
    s = load_scene(d)
    assert s.gt is not None
    np.testing.assert_array_equal(
        s.gt, np.array([[0.0, 65504.0, np.nan, np.nan], [np.nan, 1.5, 0.0, 2.0]], np.float32)
    )
    assert s.max_disparity == 72064  # round_up16(1.1 * 65504 = 72054.4)
    # the range its GT sets is said so, with that GT's largest value: a GT left in KITTI's
    # 256 x scale was said only to need images 72065 px wide
    assert scene_too_narrow(s) == (
        "images 4 px wide, not wider than the scene's disparity range (72064 px: 1.1 x its "
        "largest GT disparity, 65504 px, rounded up to a multiple of 16): a scene needs images "
        "at least 72065 px wide, or its gt_disp.pfm is not in pixels (KITTI's PNGs hold 256 x "
        "the disparity)"
    )
    # a range at evaluation.md's 16 px floor (a GT of 2 px) is said as before
    write_pfm(d / "gt_disp.pfm", np.full((2, 4), 2.0, np.float32))
    assert scene_too_narrow(load_scene(d)) == (
        "images 4 px wide, not wider than the scene's disparity range (16 px, evaluation.md's "
        "rule: 16 at least): a scene needs images at least 17 px wide"
    )


def test_find_scenes_lists_a_scene_behind_an_alias_link_once(tmp_path: Path) -> None:
    """A link inside the root to a folder of it (``latest -> run3``) listed its scenes twice,
    so ``bench`` counted them twice in its mean; rglob did not enter it. As batch's walk, a link
    inside the root (or to a folder entered already) is an alias, also when the root is a link."""
    scene = tmp_path / "data" / "run3" / "s1"
    scene.mkdir(parents=True)
    for name in ("left.png", "right.png"):
        (scene / name).write_bytes(b"")
    (tmp_path / "data" / "latest").symlink_to(tmp_path / "data" / "run3")
    (tmp_path / "data" / "x1").symlink_to(tmp_path / "outside")
    (tmp_path / "data" / "x2").symlink_to(tmp_path / "outside")
    (tmp_path / "outside" / "s2").mkdir(parents=True)
    for name in ("left.png", "right.png"):
        (tmp_path / "outside" / "s2" / name).write_bytes(b"")
    assert find_scenes(tmp_path / "data") == [
        tmp_path / "data" / "run3" / "s1",
        tmp_path / "data" / "x1" / "s2",
    ]
    (tmp_path / "root").symlink_to(tmp_path / "data")
    assert find_scenes(tmp_path / "root") == [
        tmp_path / "root" / "run3" / "s1",
        tmp_path / "root" / "x1" / "s2",
    ]


def test_write_together_refuses_a_folder_or_missing_folder_naming_the_destination(
    tmp_path: Path,
) -> None:
    """save_ros's right.yaml being a folder was atomic_write's 'cannot write .../right.yaml: it
    is a folder'; write_together said '[Errno 21] Is a directory: .../.right.yaml.x1y2.tmp ->
    ...', naming its temporary file. Each destination is checked first, nothing written."""
    (tmp_path / "b.yaml").mkdir()
    with pytest.raises(IsADirectoryError) as info:
        write_together([(tmp_path / "a.yaml", b"1"), (tmp_path / "b.yaml", b"2")])
    folder = tmp_path / "b.yaml"
    assert str(info.value) == f"cannot write {folder}: it is a folder; give a file name"
    with pytest.raises(FileNotFoundError) as missing:
        write_together([(tmp_path / "a.yaml", b"1"), (tmp_path / "no" / "c.yaml", b"2")])
    assert str(missing.value) == (
        f"cannot write {tmp_path / 'no' / 'c.yaml'}: directory {tmp_path / 'no'} does not exist"
    )
    assert sorted(os.listdir(tmp_path)) == ["b.yaml"]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs as on POSIX")
def test_a_fifo_destination_is_refused_not_replaced_by_a_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``-o pipe.png`` where ``pipe.png`` is a FIFO (a reader waiting on it), or a link to
    one, was replaced by a regular file without a word (``stereovision board -o`` exit 0), the
    reader getting nothing. It is refused, the FIFO left in place; a regular file is still
    replaced."""
    from stereovision.cli import main

    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    (tmp_path / "link.png").symlink_to("pipe.png")
    said = f"cannot write {fifo}: it is not a regular file (a FIFO)"
    link = tmp_path / "link.png"
    # the link is named, the name the user gave (not its target alone)
    said_link = f"cannot write {link}: it is a link to {fifo}, not a regular file (a FIFO)"
    for dest, words in ((fifo, said), (link, said_link)):
        with pytest.raises(OSError) as refused, atomic_write(dest) as fh:
            fh.write(b"x")
        assert str(refused.value) == words
        with pytest.raises(OSError) as together:
            write_together([(tmp_path / "a.yaml", b"1"), (dest, b"2")])
        assert str(together.value) == words
    assert main(["board", "-o", str(fifo), "--square", "20", "--unit", "mm"]) == 2
    assert capsys.readouterr().err == f"stereovision: error: {said}\n"
    assert sorted(os.listdir(tmp_path)) == ["link.png", "pipe.png"]  # nothing written
    assert not fifo.is_file() and fifo.exists()
    (tmp_path / "plain.png").write_bytes(b"old")
    with atomic_write(tmp_path / "plain.png") as fh:
        fh.write(b"new")
    assert (tmp_path / "plain.png").read_bytes() == b"new"


def test_load_scene_of_a_folder_at_the_filesystem_root_has_no_leading_slash(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A scene folder directly under '/' (a container's /tsukuba) was still named '/tsukuba',
    the name a10afcb called wrong for 'tsukuba': a folder with no family is named alone."""
    monkeypatch.chdir(data_dir / "middlebury2001")
    monkeypatch.setattr(os, "getcwd", lambda: "/")  # abspath("tsukuba") is then "/tsukuba"
    assert load_scene("tsukuba").name == "tsukuba"


def test_writers_write_through_a_link_to_a_file_as_open_does(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A destination that is a link to a file (rig.yaml -> rigs/2026.yaml) was replaced by a
    regular file: the link was lost and its target kept the old contents. Like open(path, "w"),
    atomic_write and write_together write the target now, still all or nothing; a dangling
    link's target is created, a link loop is refused naming the link."""
    elsewhere = tmp_path / "rigs"
    elsewhere.mkdir()
    for name in ("a.yaml", "b.yaml", "c.yaml"):
        (elsewhere / name).write_text("old")
        (tmp_path / name).symlink_to(Path("rigs") / name)  # relative, as ln -s makes them
    with atomic_write(tmp_path / "a.yaml", "w") as fh:
        fh.write("new")
    write_together([(tmp_path / "b.yaml", b"new"), (tmp_path / "plain.yaml", b"new")])
    for name in ("a.yaml", "b.yaml"):
        assert (tmp_path / name).is_symlink() and (elsewhere / name).read_text() == "new"
    assert sorted(os.listdir(elsewhere)) == ["a.yaml", "b.yaml", "c.yaml"]  # no temporaries
    # all or nothing through the link: the second replacement fails, the first is undone
    real_replace = os.replace

    def fail_second(src: str, dst: str) -> None:
        if str(dst).endswith("d.yaml"):
            raise OSError(28, "No space left on device")
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", fail_second)
    with pytest.raises(OSError, match="No space left"):
        write_together([(tmp_path / "c.yaml", b"new"), (tmp_path / "d.yaml", b"new")])
    monkeypatch.undo()
    assert (tmp_path / "c.yaml").is_symlink() and (elsewhere / "c.yaml").read_text() == "old"
    assert sorted(os.listdir(elsewhere)) == ["a.yaml", "b.yaml", "c.yaml"]
    (tmp_path / "dangling.yaml").symlink_to(elsewhere / "new.yaml")
    with atomic_write(tmp_path / "dangling.yaml", "w") as fh:
        fh.write("created")
    assert (elsewhere / "new.yaml").read_text() == "created"
    assert (tmp_path / "dangling.yaml").is_symlink()
    (tmp_path / "loop.yaml").symlink_to(tmp_path / "loop.yaml")
    with pytest.raises(OSError, match=r"^cannot write .*loop\.yaml: it is a link that loops"):
        write_together([(tmp_path / "loop.yaml", b"x")])
    with pytest.raises(OSError, match=r"^cannot write .*loop\.yaml: it is a link that loops"):
        with atomic_write(tmp_path / "loop.yaml") as fh:
            fh.write(b"x")
    assert (tmp_path / "loop.yaml").is_symlink()


def test_a_link_that_cannot_be_followed_is_not_called_a_loop(tmp_path: Path) -> None:
    """A link through a file (out.yaml -> notes.txt/out.yaml) was refused as 'it is a link that
    loops': every error of the strict resolution was taken for ELOOP. It is refused as open()
    refuses it, a file where a folder should be; a link to a folder names the link."""
    (tmp_path / "notes.txt").write_text("mine")
    (tmp_path / "out.yaml").symlink_to(Path("notes.txt") / "out.yaml")
    with pytest.raises(NotADirectoryError) as info:
        with atomic_write(tmp_path / "out.yaml") as fh:
            fh.write(b"x")
    assert str(info.value) == (
        f"cannot write {tmp_path / 'notes.txt' / 'out.yaml'}: {tmp_path / 'notes.txt'} is a "
        "file, not a folder"
    )
    with pytest.raises(NotADirectoryError):
        write_together([(tmp_path / "out.yaml", b"x")])
    (tmp_path / "rigs").mkdir()
    (tmp_path / "dir.yaml").symlink_to("rigs")
    with pytest.raises(IsADirectoryError) as folder:
        write_together([(tmp_path / "dir.yaml", b"x")])
    assert str(folder.value) == (
        f"cannot write {tmp_path / 'dir.yaml'}: it is a link to the folder "
        f"{tmp_path / 'rigs'}; give a file name"
    )
    assert sorted(os.listdir(tmp_path)) == ["dir.yaml", "notes.txt", "out.yaml", "rigs"]
    assert (tmp_path / "notes.txt").read_text() == "mine" and not os.listdir(tmp_path / "rigs")


def test_write_together_refuses_two_destinations_that_are_one_file(tmp_path: Path) -> None:
    """Written through links, right.yaml -> left.yaml made save_ros write the right camera over
    the left one: a rig of one camera, said nowhere. Two destinations that are one file (a
    link, a linked folder, a hard link, or the same name twice) are refused before anything
    is written."""
    (tmp_path / "left.yaml").write_text("old")
    (tmp_path / "right.yaml").symlink_to("left.yaml")
    (tmp_path / "same").symlink_to(".")
    os.link(tmp_path / "left.yaml", tmp_path / "hard.yaml")
    for other in ("right.yaml", "same/left.yaml", "hard.yaml", "left.yaml"):
        with pytest.raises(ValueError) as info:
            write_together([(tmp_path / "left.yaml", b"L"), (tmp_path / other, b"R")])
        assert str(info.value) == (
            f"cannot write {tmp_path / 'left.yaml'} and {tmp_path / other} together: they are "
            "one file (the second would replace the first)"
        )
    assert (tmp_path / "left.yaml").read_text() == "old"
    assert sorted(os.listdir(tmp_path)) == ["hard.yaml", "left.yaml", "right.yaml", "same"]


def test_writers_keep_the_permissions_of_the_file_they_replace(tmp_path: Path) -> None:
    """A private file (0600) replaced by atomic_write or write_together came back 0644 (a new
    file's mode), readable by every user; through a link, a private target elsewhere was
    opened up so. open(path, "w") keeps a file's mode: so do they. A new file still gets a
    plain open()'s (0666 less the umask)."""
    (tmp_path / "rigs").mkdir()
    private = tmp_path / "rigs" / "rig.yaml"
    private.write_text("old")
    private.chmod(0o600)
    (tmp_path / "rig.yaml").symlink_to(Path("rigs") / "rig.yaml")
    shared = tmp_path / "map.yaml"
    shared.write_text("old")
    shared.chmod(0o640)
    with atomic_write(tmp_path / "rig.yaml", "w") as fh:
        fh.write("new")
    assert private.read_text() == "new" and private.stat().st_mode & 0o777 == 0o600
    private.chmod(0o400)  # read-only to its owner: replaced all the same, as before
    write_together([(tmp_path / "rig.yaml", b"newer"), (shared, b"new"), (tmp_path / "n", b"")])
    assert private.read_bytes() == b"newer" and private.stat().st_mode & 0o777 == 0o400
    assert shared.read_bytes() == b"new" and shared.stat().st_mode & 0o777 == 0o640
    umask = os.umask(0)
    os.umask(umask)
    assert (tmp_path / "n").stat().st_mode & 0o777 == 0o666 & ~umask


def test_a_folder_without_write_permission_is_named_not_the_temporary_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The new contents are made beside the file (through a link: beside its target) and put in
    place; in a folder the user may not write, the error was '[Errno 13] Permission denied:
    '.../.rig.yaml.k2j3abcd.tmp'', a file the user never named. The file and its folder are
    named. (mkstemp refusing stands for the folder's mode: the tests may run as root.)"""
    import tempfile

    (tmp_path / "ro").mkdir()
    (tmp_path / "ro" / "rig.yaml").write_text("old")
    (tmp_path / "rig.yaml").symlink_to(Path("ro") / "rig.yaml")

    def refused(prefix: str = "", suffix: str = "", dir: object = None) -> tuple[int, str]:
        raise PermissionError(13, "Permission denied", f"{dir}/{prefix}k2j3abcd{suffix}")

    monkeypatch.setattr(tempfile, "mkstemp", refused)
    want = (
        f"cannot write {tmp_path / 'ro' / 'rig.yaml'}: its folder {tmp_path / 'ro'} is not "
        "writable (the new contents are made there, then put in place)"
    )
    with pytest.raises(PermissionError) as info:
        with atomic_write(tmp_path / "rig.yaml") as fh:
            fh.write(b"x")
    assert str(info.value) == want
    with pytest.raises(PermissionError) as together:
        write_together([(tmp_path / "rig.yaml", b"x")])
    assert str(together.value) == want
    assert (tmp_path / "ro" / "rig.yaml").read_text() == "old"


def test_a_folder_refusing_new_files_for_another_reason_is_named_not_the_temporary_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Only PermissionError was said of the file and its folder: board -o /proc/x.png (mkstemp:
    ENOENT) printed '[Errno 2] No such file or directory: '/proc/.x.png.58m0qpf3.tmp''. Any
    refusal names the file and its folder, keeping its class and errno."""
    import tempfile

    def refused(prefix: str = "", suffix: str = "", dir: object = None) -> tuple[int, str]:
        raise FileNotFoundError(2, "No such file or directory", f"{dir}/{prefix}58m0qpf3{suffix}")

    monkeypatch.setattr(tempfile, "mkstemp", refused)
    want = (
        f"cannot write {tmp_path / 'x.png'}: no file can be made in its folder {tmp_path} "
        "(No such file or directory)"
    )
    with pytest.raises(FileNotFoundError) as info:
        with atomic_write(tmp_path / "x.png") as fh:
            fh.write(b"x")
    assert str(info.value) == want and info.value.errno == 2
    with pytest.raises(FileNotFoundError) as together:
        write_together([(tmp_path / "x.png", b"x")])
    assert str(together.value) == want
    assert not (tmp_path / "x.png").exists()


# ------------------------------------------------------- third mutation audit of the safe writes


def test_a_replaced_files_set_user_id_bit_is_not_carried(tmp_path: Path) -> None:
    """A third mutation audit: the replaced file's permission bits are kept, but not its
    set-user-ID, set-group-ID or sticky bits (new contents are not the program it held)."""
    rig = tmp_path / "tool"
    rig.write_bytes(b"old")
    rig.chmod(0o6755)
    with atomic_write(rig) as fh:
        fh.write(b"new")
    assert rig.stat().st_mode & 0o7777 == 0o755
    rig.chmod(0o4711)
    write_together([(rig, b"newer")])
    assert rig.stat().st_mode & 0o7777 == 0o711


def test_lock_folder_where_nothing_can_be_locked_is_not_busy(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A filesystem that cannot lock (flock: EOPNOTSUPP, ENOLCK) is no lock held by another
    run: (None, False); only a held lock (BlockingIOError) is busy. A mutation audit made every
    failure 'busy' unseen."""
    import errno
    import fcntl

    from stereovision.io import lock_folder

    def cannot(fd: int, op: int) -> None:
        raise OSError(errno.EOPNOTSUPP, "Operation not supported")

    monkeypatch.setattr(fcntl, "flock", cannot)
    assert lock_folder(tmp_path) == (None, False)

    def held(fd: int, op: int) -> None:
        raise BlockingIOError(errno.EWOULDBLOCK, "Resource temporarily unavailable")

    monkeypatch.setattr(fcntl, "flock", held)
    assert lock_folder(tmp_path) == (None, True)


def test_refuse_an_input_through_a_folder_not_made_yet(tmp_path: Path) -> None:
    """``--plot new/../left.png`` names the left image through a folder that does not exist
    yet (os.path.samefile fails): the spelled-out paths are compared, and it is refused;
    ``make_folder`` would have made ``new`` and the plot replaced the image."""
    from stereovision.io import refuse_an_input

    left = tmp_path / "left.png"
    left.write_bytes(b"img")
    inputs = {"the left image": str(left), "the calibration": None}
    with pytest.raises(ValueError, match=r"--plot .*: is the left image \(.*left\.png\); give"):
        refuse_an_input("--plot", tmp_path / "new" / ".." / "left.png", inputs)
    refuse_an_input("--plot", tmp_path / "new" / "left.png", inputs)  # another file: accepted


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="links and FIFOs as on POSIX")
def test_an_output_folder_through_a_link_to_nothing_is_refused_naming_the_link(
    tmp_path: Path,
) -> None:
    """``-o out`` where ``out`` is a link to a moved folder passed check_output_folder (made
    to refuse before the matching), so the run did its work and then make_folder said
    "out is a file, not a folder"; of ``out/sub``, "out/sub is a file" (no file at all), and
    of a folder under a FIFO the same. Both now name the link (or the FIFO) and what it is."""
    from stereovision.io import check_output_folder

    (tmp_path / "gone").symlink_to(tmp_path / "moved")
    (tmp_path / "loop1").symlink_to("loop2")
    (tmp_path / "loop2").symlink_to("loop1")
    os.mkfifo(tmp_path / "fifo")
    moved = f"is a link to {tmp_path / 'moved'}, which does not exist"
    loop = "is a link to loop2, one of a loop of links that never reaches a file"
    for out, blocker, what in (
        (tmp_path / "gone", tmp_path / "gone", moved),
        (tmp_path / "gone" / "sub", tmp_path / "gone", moved),
        (tmp_path / "loop1" / "sub", tmp_path / "loop1", loop),
    ):
        with pytest.raises(ValueError) as refused:
            check_output_folder(out, "-o")
        where = "" if out == blocker else f"{blocker} "
        assert str(refused.value) == f"-o {out}: {where}{what}"
        with pytest.raises(NotADirectoryError) as err:
            make_folder(out)
        assert str(err.value) == f"cannot make the folder {out}: {blocker} {what}"
    with pytest.raises(NotADirectoryError) as err:
        make_folder(tmp_path / "fifo" / "sub")
    assert str(err.value) == (
        f"cannot make the folder {tmp_path / 'fifo' / 'sub'}: {tmp_path / 'fifo'} is not a folder"
    )
    assert sorted(os.listdir(tmp_path)) == ["fifo", "gone", "loop1", "loop2"]  # nothing made


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs as on POSIX")
def test_an_output_folder_at_or_under_a_fifo_is_refused_as_no_folder_not_as_a_file(
    tmp_path: Path,
) -> None:
    """3dc4258 had make_folder call a FIFO in the way "not a folder" (it was "a file"), but
    check_output_folder, which the CLI runs first, still said "-o fifo/sub: fifo is a file,
    not a folder" of it (and "-o fifo: is a file"): the words the commit took back."""
    from stereovision.io import check_output_folder

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    (tmp_path / "plain").write_bytes(b"")
    for out, said in (
        (fifo, f"-o {fifo}: is not a folder"),
        (fifo / "sub", f"-o {fifo / 'sub'}: {fifo} is not a folder"),
        # a regular file is still named one
        (tmp_path / "plain", f"-o {tmp_path / 'plain'}: is a file, not a folder"),
        (
            tmp_path / "plain" / "sub",
            f"-o {tmp_path / 'plain' / 'sub'}: {tmp_path / 'plain'} is a file, not a folder",
        ),
    ):
        with pytest.raises(ValueError) as refused:
            check_output_folder(out, "-o")
        assert str(refused.value) == said


def test_check_output_folder_error_classes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A file above the folder is a ValueError naming that file ('is a file, not a folder');
    a folder above it that cannot be written is a PermissionError naming it."""
    import tempfile

    from stereovision.io import check_output_folder

    (tmp_path / "notes").write_text("mine")
    with pytest.raises(ValueError) as info:
        check_output_folder(tmp_path / "notes" / "out", "-o")
    assert str(info.value) == (
        f"-o {tmp_path / 'notes' / 'out'}: {tmp_path / 'notes'} is a file, not a folder"
    )

    def refused(*args: object, **kwargs: object) -> tuple[int, str]:
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", refused)
    with pytest.raises(PermissionError) as denied:
        check_output_folder(tmp_path / "new" / "out", "-o")
    assert str(denied.value) == (
        f"-o {tmp_path / 'new' / 'out'}: cannot write in {tmp_path} (Permission denied)"
    )


def test_a_tilde_the_shell_left_as_typed_is_not_made_a_folder_named_tilde(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--output=~/out`` (bash expands no ~ after '=') made a folder named "~" in the current
    one and wrote there; an image typed ``"~/l.png"`` was "not found" alone. The folder is
    refused, the image's message offers the home's file; ./~/out, or a ~ folder that is
    there, is taken as typed."""
    from stereovision.io import check_output_folder

    home, cwd = tmp_path / "home", tmp_path / "cwd"
    home.mkdir()
    cwd.mkdir()
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir(cwd)
    with pytest.raises(ValueError) as err:
        check_output_folder("~/out", "-o")
    assert str(err.value) == (
        "-o ~/out: ~ is not expanded here (the shell leaves it as typed after '=' or in "
        f"quotes): give {home / 'out'}, or ./~/out for a folder named ~"
    )
    check_output_folder("./~/out", "-o")
    cv2.imwrite(str(home / "l.png"), np.zeros((2, 2), np.uint8))
    with pytest.raises(FileNotFoundError) as missing:
        read_image("~/l.png")
    assert str(missing.value) == (
        f"image file not found: ~/l.png (~ is not expanded here: did you mean {home / 'l.png'}?)"
    )
    # --calib=~/rig.yaml: depth's and batch's calibration readers offer the home's file too
    from stereovision.batch import find_pairs
    from stereovision.calibration import Calibration

    (home / "rig.yaml").write_text("not read\n")
    (cwd / "in").mkdir()
    said = (
        "calibration file not found: ~/rig.yaml (~ is not expanded here: did you mean "
        f"{home / 'rig.yaml'}?)"
    )
    for load in (Calibration.load, lambda c: find_pairs(cwd / "in", calib=c)):
        with pytest.raises(FileNotFoundError) as no_calib:
            load("~/rig.yaml")
        assert str(no_calib.value) == said
    (cwd / "~").mkdir()  # a folder of that name, made on purpose: taken
    check_output_folder("~/out", "-o")
    assert not (cwd / "~" / "out").exists()


def test_check_destinations_a_loop_and_a_hard_link(tmp_path: Path) -> None:
    """A looping link is said as a loop alone (not 'is a link to itself; ...'), its errno
    kept (ELOOP); right.yaml a hard link of left.yaml is one file, as a symbolic one is."""
    import errno

    from stereovision.io import check_destinations

    ros = tmp_path / "ros"
    ros.mkdir()
    (ros / "left.yaml").symlink_to(ros / "left.yaml")
    with pytest.raises(OSError) as info:
        check_destinations(ros, ["left.yaml", "right.yaml"], "--ros")
    assert (
        str(info.value) == f"--ros {ros}: cannot write {ros / 'left.yaml'}: it is a link that loops"
    )
    assert info.value.errno == errno.ELOOP
    (ros / "left.yaml").unlink()
    (ros / "left.yaml").write_text("left\n")
    os.link(ros / "left.yaml", ros / "right.yaml")
    with pytest.raises(ValueError, match=r"right\.yaml and .*left\.yaml are one file"):
        check_destinations(ros, ["left.yaml", "right.yaml"], "--ros")
    (ros / "right.yaml").unlink()
    (ros / "right.yaml").write_text("right\n")
    check_destinations(ros, ["left.yaml", "right.yaml"], "--ros")  # two files: accepted


def test_keep_previous_with_the_new_bytes(tmp_path: Path) -> None:
    """keep_previous(path, new): the same bytes again replace nothing (no copy, None); other
    bytes of the same length do, so the file is copied aside."""
    from stereovision.io import keep_previous

    plot = tmp_path / "plot.png"
    plot.write_bytes(b"abcd")
    assert keep_previous(plot, b"abcd") is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plot.png"]
    assert keep_previous(plot, b"abce") == tmp_path / "plot.previous.png"
    assert (tmp_path / "plot.previous.png").read_bytes() == b"abcd"


def test_write_together_failing_removes_a_new_file_it_put_in_place(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The second file failing to go in place: the first, which did not exist before, is
    removed again (all or nothing), the second's earlier contents untouched, no temporary
    file left."""
    real = os.replace
    calls = []

    def second_fails(src: object, dst: object) -> None:
        calls.append(dst)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        real(src, dst)

    (tmp_path / "b.yaml").write_bytes(b"old")
    monkeypatch.setattr(os, "replace", second_fails)
    with pytest.raises(OSError, match="No space left"):
        write_together([(tmp_path / "a.yaml", b"new"), (tmp_path / "b.yaml", b"new")])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.yaml"]
    assert (tmp_path / "b.yaml").read_bytes() == b"old"


def test_write_together_names_previous_contents_it_could_not_put_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The second file failing, and the first's previous contents failing to be put back: the
    copy holding them is kept and the error's note names it and its destination."""
    real = os.replace
    calls = []

    def fails_after_the_first(src: object, dst: object) -> None:
        calls.append(dst)
        if len(calls) >= 2:
            raise OSError(5, "Input/output error")
        real(src, dst)

    (tmp_path / "a.yaml").write_bytes(b"old a")
    monkeypatch.setattr(os, "replace", fails_after_the_first)
    with pytest.raises(OSError) as info:
        write_together([(tmp_path / "a.yaml", b"new a"), (tmp_path / "b.yaml", b"new b")])
    (copy,) = [p for p in tmp_path.iterdir() if p.name.endswith(".old")]
    assert copy.read_bytes() == b"old a"
    assert info.value.__notes__ == [
        f"{tmp_path / 'a.yaml'} could not be restored: its previous contents are in {copy}"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["a.yaml", copy.name])


def test_read_pfm_one_value_short_is_truncated(tmp_path: Path) -> None:
    """A PFM four bytes (one value) short is said to be truncated, with the counts."""
    path = write_pfm(tmp_path / "d.pfm", np.ones((2, 3), np.float32))
    path.write_bytes(path.read_bytes()[:-4])
    with pytest.raises(ValueError) as info:
        read_pfm(path)
    assert str(info.value) == (
        f"truncated PFM file {path}: expected 24 data bytes for 3x2x1, got 20"
    )


def test_read_pfm_cut_right_after_its_scale_is_truncated(tmp_path: Path) -> None:
    """A PFM cut right after its scale (its line feed gone with the data) was "not a PFM file
    (bad header)"; it is truncated, as one cut after the line feed is."""
    path = write_pfm(tmp_path / "d.pfm", np.ones((2, 3), np.float32))
    for cut, got in ((b"Pf\n3 2\n-1.0", 0), (b"Pf\n3 2\n-1.0 ", 0), (b"Pf\n3 2\n-1.0\n", 0)):
        path.write_bytes(cut)
        with pytest.raises(ValueError) as info:
            read_pfm(path)
        assert str(info.value) == (
            f"truncated PFM file {path}: expected 24 data bytes for 3x2x1, got {got}"
        )
    path.write_bytes(b"Pf\n3 2\n-1.")  # a scale cut short is read as far as it goes: "-1."
    with pytest.raises(ValueError, match=r"^truncated PFM file"):
        read_pfm(path)


def test_scene_too_narrow_at_a_range_as_wide_as_the_images(tmp_path: Path) -> None:
    """Images exactly as wide as the scene's range cannot be matched over it (the range must be
    below the width); one pixel wider can."""
    from stereovision.io import Scene, scene_too_narrow

    def scene(width: int) -> Scene:
        img = np.zeros((4, width, 3), np.uint8)
        return Scene("f/s", img, img, None, None, 32, tmp_path)

    assert scene_too_narrow(scene(32)) == (
        "images 32 px wide, not wider than the scene's disparity range (32 px, evaluation.md's "
        "rule: 16 at least): a scene needs images at least 33 px wide"
    )
    assert scene_too_narrow(scene(33)) is None


def test_distinct_scenes_through_a_link(tmp_path: Path) -> None:
    """A scene given by its folder and through a link to it (or a '..' spelling) is one scene:
    kept once, the later spellings dropped, in order."""
    from stereovision.io import distinct_scenes

    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "a")
    given = [tmp_path / "a", tmp_path / "b", tmp_path / "link", tmp_path / "b" / ".." / "a"]
    assert distinct_scenes(given) == (
        [tmp_path / "a", tmp_path / "b"],
        [tmp_path / "link", tmp_path / "b" / ".." / "a"],
    )


def test_keep_previous_steps_over_a_folder_under_its_name(tmp_path: Path) -> None:
    """A folder named plot.previous.png is not a copy (nor compared as one): the copy is
    plot.previous.2.png, the folder untouched."""
    from stereovision.io import keep_previous

    (tmp_path / "plot.previous.png").mkdir()
    # as many bytes as the folder's size: compared by size alone, it was opened as a file
    mine = b"m" * (tmp_path / "plot.previous.png").stat().st_size
    plot = tmp_path / "plot.png"
    plot.write_bytes(mine)
    assert keep_previous(plot) == tmp_path / "plot.previous.2.png"
    assert (tmp_path / "plot.previous.2.png").read_bytes() == mine
    assert (tmp_path / "plot.previous.png").is_dir()


def test_load_scene_refuses_a_folder_named_gt_disp_pfm(tmp_path: Path) -> None:
    """A folder under gt_disp.pfm is no scene without ground truth: refused, naming it."""
    img = np.zeros((8, 32, 3), np.uint8)
    assert cv2.imwrite(str(tmp_path / "left.png"), img)
    assert cv2.imwrite(str(tmp_path / "right.png"), img)
    (tmp_path / "gt_disp.pfm").mkdir()
    with pytest.raises(ValueError, match=r"^PFM file is not a regular file: .*gt_disp\.pfm$"):
        load_scene(tmp_path)


def test_io_entry_points_refuse_a_bytes_or_no_path_naming_the_argument(tmp_path: Path) -> None:
    """imread, read_pfm, write_ply, load_scene, find_scenes, Calibration.load ... given a bytes
    name (or None) raised pathlib's "argument should be a str object or an os.PathLike object
    returning str, not <class 'bytes'>", naming no argument; Calibration.from_file already said
    which argument and to decode it (028e86f): each entry point now says so in those words."""
    name = str(tmp_path / "a.png")
    raw = os.fsencode(name)
    cloud = np.zeros((2, 3), np.float32)
    cases = [
        (lambda p: imread(p), "path"),
        (lambda p: read_image(p), "path"),
        (lambda p: read_pfm(p), "path"),
        (lambda p: write_pfm(p, np.zeros((2, 2), np.float32)), "path"),
        (lambda p: write_ply(p, cloud), "path"),
        (lambda p: read_ply(p), "path"),
        (lambda p: load_scene(p), "directory"),
        (lambda p: find_scenes(p), "root"),
        (lambda p: scan_scenes(p), "root"),
        (lambda p: Calibration.load(p), "path"),
        (lambda p: Calibration.from_middlebury(p), "path"),
        (lambda p: Calibration.from_ros(p, name), "left"),
        (
            lambda p: Calibration(
                np.eye(3),
                np.zeros(5),
                np.eye(3),
                np.zeros(5),
                np.eye(3),
                np.array([-0.1, 0.0, 0.0]),
                (4, 4),
            ).save(p),
            "path",
        ),
    ]
    for call, arg in cases:
        with pytest.raises(TypeError) as info:
            call(raw)
        assert str(info.value) == (
            f"{arg}: expected a str or os.PathLike file name, got the bytes {name!r}: decode "
            f"it first (os.fsdecode({arg}))"
        )
        with pytest.raises(TypeError) as info:
            call(None)
        assert str(info.value) == f"{arg}: expected a str or os.PathLike file name, got NoneType"
    assert not list(tmp_path.iterdir())  # nothing written


def test_an_empty_file_name_is_refused_not_taken_for_the_current_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """write_ply('', pts) said "cannot write .: it is a folder; give a file name", read_ply('')
    "PLY file is not a regular file: .": Path('') is the current folder, no name the caller gave.
    The file readers and writers of io, export and Calibration now say the name is empty."""
    from stereovision import export

    monkeypatch.chdir(tmp_path)
    cloud = np.zeros((2, 3), np.float32)
    depth = np.ones((2, 2), np.float32)
    calib = Calibration(
        np.eye(3), np.zeros(5), np.eye(3), np.zeros(5), np.eye(3), np.array([-0.1, 0, 0]), (4, 4)
    )
    for call in (
        lambda: write_ply("", cloud),
        lambda: read_ply(""),
        lambda: write_pfm("", depth),
        lambda: read_pfm(""),
        lambda: imread(""),
        lambda: export.read_pcd(""),
        lambda: export.load_cloud(""),
        lambda: export.write_depth_png("", depth),
        lambda: export.read_depth_png(""),
        lambda: calib.save(""),
        lambda: Calibration.load(""),
    ):
        with pytest.raises(ValueError) as info:
            call()
        assert str(info.value) == "path: expected a file name, got ''"
    assert not list(tmp_path.iterdir())  # nothing written


@pytest.mark.parametrize("flag", [0, 1, cv2.IMREAD_GRAYSCALE, "no", None])
def test_imread_gray_is_true_or_false_not_cv2_s_flags(tmp_path: Path, flag: object) -> None:
    """imread(p, 0), as cv2.imread(p, 0) (IMREAD_GRAYSCALE) is written, returned the colour
    image, and imread(p, 1) or gray="no" the grey one, without a word."""
    path = tmp_path / "a.png"
    assert cv2.imwrite(str(path), np.zeros((2, 3, 3), np.uint8))
    with pytest.raises(
        TypeError,
        match=rf"^gray: expected True or False, got {re.escape(repr(flag))} \(not "
        r"cv2\.imread's flags: gray=True for a grey image\)$",
    ):
        imread(path, flag)  # type: ignore[arg-type]
    assert imread(path, np.bool_(True)).shape == (2, 3) and imread(path, False).shape == (2, 3, 3)


def test_read_ply_ascii_blank_lines_are_skipped_without_numpy_s_warning(tmp_path: Path) -> None:
    """A blank line in an ASCII PLY's body was skipped (the cloud right), but NumPy's
    loadtxt warned 'Input line 1 contained no data and will not be counted towards
    `max_rows=2` ...' in four lines, shown before the CLI's output."""
    import warnings

    header = (
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n"
    )
    (tmp_path / "c.ply").write_text(header + "\n1 2 3\n\n4 5 6\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        points, colours = read_ply(tmp_path / "c.ply")
    assert points.tolist() == [[1, 2, 3], [4, 5, 6]] and colours is None


def test_read_ply_ascii_damaged_count_or_out_of_type_value_is_said(tmp_path: Path) -> None:
    """An ASCII PLY whose vertex count is damaged (99999999999 of one row) was a MemoryError of
    terabytes (the table and records allocated for the count), not "truncated"; a uchar colour
    of 300 or -1 (a value its type cannot hold) came back 44 and 255, wrapped by the cast."""
    head = "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n"
    head += "property float z\n{}end_header\n"
    f = tmp_path / "c.ply"
    f.write_text(head.format(99999999999, "") + "1 2 3\n")
    with pytest.raises(ValueError, match=r"^truncated PLY file .*: expected 99999999999 vertices$"):
        read_ply(f)
    rgb = "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    for row, said in (("1 2 3 300 0 2", "300"), ("1 2 3 7 -1 2", "-1"), ("1 2 3 7 1 2.5", "2.5")):
        f.write_text(head.format(1, rgb) + row + "\n")
        with pytest.raises(ValueError) as info:
            read_ply(f)
        assert str(info.value).endswith(f"holds {said}, not a whole number 0 to 255 as its type")
    f.write_text(head.format(2, rgb) + "1 2 3 255 0 2\n4 5 6 0.0 128 1\n")
    pts, cols = read_ply(f)
    assert pts.tolist() == [[1, 2, 3], [4, 5, 6]]
    assert cols is not None and cols.tolist() == [[255, 0, 2], [0, 128, 1]]


def test_an_empty_image_file_is_said_to_be_empty(tmp_path: Path) -> None:
    """A 0-byte image (an interrupted copy or save) was "cannot decode F as an image" alone, the
    words of a damaged file or an unknown format; it now says the file is empty."""
    empty = tmp_path / "left.png"
    empty.write_bytes(b"")
    for read in (imread, read_image):
        with pytest.raises(ValueError) as info:
            read(empty)
        assert str(info.value) == f"cannot decode {empty} as an image: the file is empty (0 bytes)"
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"this is not an image")
    with pytest.raises(ValueError) as info:
        imread(bad)
    assert str(info.value) == f"cannot decode {bad} as an image"


def test_read_ply_takes_a_comment_in_utf8(tmp_path: Path) -> None:
    """A header comment in UTF-8 ('comment créé par Jürgen') made the whole file "not a PLY file
    (non-ASCII header)"; a comment's text is free, the other lines still ASCII."""
    body = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
    f = tmp_path / "c.ply"
    head = "ply\nformat ascii 1.0\ncomment créé par Jürgen à Åre\n"  # Å: C3 85, 85 a NEL
    f.write_bytes((head + body + "1 2 3\n").encode())
    pts, cols = read_ply(f)
    assert pts.tolist() == [[1, 2, 3]] and cols is None
    f.write_bytes(("ply\nformat ascii 1.0\n" + body.replace(" x", " é") + "1 2 3\n").encode())
    with pytest.raises(ValueError, match=r"^not a PLY file \(non-ASCII header\): "):
        read_ply(f)


def test_make_folder_refuses_a_bytes_name_naming_it(tmp_path: Path) -> None:
    """make_folder(b'/x/new') gave pathlib's TypeError ("argument should be a str object or an
    os.PathLike object returning str, not <class 'bytes'>"), naming no argument."""
    new = tmp_path / "new"
    with pytest.raises(TypeError) as info:
        make_folder(os.fsencode(new))
    assert str(info.value) == (
        f"path: expected a str or os.PathLike file name, got the bytes {str(new)!r}: "
        "decode it first (os.fsdecode(path))"
    )
    assert not new.exists()


def test_read_ply_reads_past_an_empty_list_element_before_the_vertices(tmp_path: Path) -> None:
    """A binary PLY with "element face 0" (a list property) before its vertices was refused
    ("element 'face' before vertex holds a list property (its binary rows are not skipped)"),
    though an element of no rows has no bytes to skip; one with rows still says so."""
    head = (
        "ply\nformat binary_little_endian 1.0\nelement face {}\n"
        "property list uchar int vertex_indices\nelement vertex 1\nproperty float x\n"
        "property float y\nproperty float z\nend_header\n"
    )
    empty = tmp_path / "empty.ply"
    empty.write_bytes(head.format(0).encode() + np.array([1, 2, 3], "<f4").tobytes())
    pts, cols = read_ply(empty)
    assert pts.tolist() == [[1.0, 2.0, 3.0]] and cols is None
    one = tmp_path / "one.ply"
    one.write_bytes(head.format(1).encode() + b"\x00" + np.array([1, 2, 3], "<f4").tobytes())
    with pytest.raises(ValueError) as info:
        read_ply(one)
    assert str(info.value) == (
        f"PLY file {one}: element 'face' before vertex holds a list property (its binary rows "
        "are not skipped)"
    )


def test_atomic_write_and_keep_previous_take_a_long_legal_name(tmp_path: Path) -> None:
    """A 250-byte name (NAME_MAX is 255) is written: the temporary '.NAME.xxxxxxxx.tmp' and the
    kept 'NAME.previous.EXT' are cut to fit, where both failed with 'File name too long'."""
    from stereovision.io import atomic_write, keep_previous

    dest = tmp_path / ("é" * 60 + "a" * 125 + ".yaml")  # 250 bytes in UTF-8
    assert len(os.fsencode(dest.name)) == 250
    with atomic_write(dest) as fh:
        fh.write(b"old")
    assert dest.read_bytes() == b"old"
    kept = keep_previous(dest, b"new")
    assert kept is not None and kept.read_bytes() == b"old"
    assert kept.name.endswith(".previous.yaml") and len(os.fsencode(kept.name)) <= 255
    assert keep_previous(dest, b"newer") == kept  # already kept byte for byte: not copied again
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([dest.name, kept.name])


def test_keep_previous_and_save_csv_refuse_a_bytes_or_empty_name_in_as_paths_words(
    tmp_path: Path,
) -> None:
    """keep_previous(b'/x') said pathlib's 'argument should be a str object ...', naming no
    argument, and keep_previous('') / Matches.save_csv('') took '' for the current folder
    ('cannot write .: it is a folder'): both in as_path's words now."""
    from stereovision.io import keep_previous
    from stereovision.matches import Matches

    with pytest.raises(TypeError, match=r"^path: expected a str or os\.PathLike file name, got"):
        keep_previous(b"/x")
    with pytest.raises(ValueError, match=r"^path: expected a file name, got ''$"):
        keep_previous("")
    z = np.zeros(2, np.float32)
    with pytest.raises(ValueError, match=r"^path: expected a file name, got ''$"):
        Matches(z, z, z, z, z, (8, 10)).save_csv("")


@pytest.mark.skipif(os.name != "posix", reason="Unix sockets")
def test_a_socket_destination_is_refused_as_a_socket(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Unix socket (a ROS node's, a daemon's) under the output name was called "a FIFO or a
    device"; it is said to be a socket, and /dev/null a character device."""
    import socket

    from stereovision.io import atomic_write

    monkeypatch.chdir(tmp_path)  # a relative name: a socket's path is limited to ~108 bytes
    with socket.socket(socket.AF_UNIX) as sock:
        sock.bind("out.png")
        with pytest.raises(OSError) as refused, atomic_write("out.png") as fh:
            fh.write(b"x")
    assert str(refused.value) == "cannot write out.png: it is not a regular file (a socket)"
    if Path("/dev/null").exists():
        with pytest.raises(OSError, match=r"\(a character device\)$"), atomic_write("/dev/null"):
            pass


def test_keep_previous_takes_a_legal_name_whose_suffix_is_long(tmp_path: Path) -> None:
    """'x.' + 250 letters (252 bytes, legal) hung keep_previous: '.previous' + its 251-byte
    suffix left the stem no room, and cutting it to '' never fitted. The whole name is cut
    now, the copy made."""
    from stereovision.io import keep_previous

    dest = tmp_path / ("x." + "b" * 250)
    dest.write_bytes(b"old")
    kept = keep_previous(dest, b"new")
    assert kept is not None and kept.read_bytes() == b"old"
    assert kept.name == "x." + "b" * 244 + ".previous"  # 255 bytes
    assert keep_previous(dest, b"newer") == kept  # already kept byte for byte
    dest.write_bytes(b"other")
    second = keep_previous(dest, b"new")
    assert second is not None and second.name == "x." + "b" * 242 + ".previous.2"


@pytest.mark.parametrize("mode", ["a", "ab", "x", "xb", "r+", "rb", None, "wbt", "ww", "w+b+"])
def test_atomic_write_refuses_a_mode_that_keeps_the_old_contents(
    tmp_path: Path, mode: str | None
) -> None:
    """atomic_write(p, "a") replaced a log with the body's lines alone, its old lines lost,
    and "x" replaced the existing file it is there to keep, without a word: only a mode that
    writes a whole new file is taken now, the file left as it was. "wbt" got fdopen's "can't
    have text and binary mode at once" after the temporary file was made, its descriptor left
    open: it is refused before anything is made."""
    dest = tmp_path / "log.txt"
    dest.write_bytes(b"line1\n")
    open_fds = len(os.listdir("/proc/self/fd"))
    with pytest.raises(
        ValueError,
        match=r"^mode: expected 'wb' or 'w' \(atomic_write replaces the whole file\), got "
        + re.escape(repr(mode))
        + "$",
    ):
        with atomic_write(dest, mode) as fh:  # type: ignore[arg-type]
            fh.write(b"line2\n")
    assert dest.read_bytes() == b"line1\n" and os.listdir(tmp_path) == ["log.txt"]
    assert len(os.listdir("/proc/self/fd")) == open_fds
    for ok in ("w", "wt", "wb", "w+b"):
        with atomic_write(dest, ok) as fh:
            fh.write("new" if "b" not in ok else b"new")
        assert dest.read_bytes() == b"new"


def test_atomic_write_refuses_a_name_ending_in_a_slash(tmp_path: Path) -> None:
    """'new/' (no such folder) was written as a file named 'new': Path() drops the slash,
    where open('new/', 'w') refuses it. It is refused now, nothing made."""
    from stereovision.io import atomic_write

    given = f"{tmp_path}/new/"
    with pytest.raises(
        IsADirectoryError,
        match=r"^cannot write .*/new/: a name ending in '/' is a folder's; give a file name$",
    ):
        with atomic_write(given) as fh:
            fh.write(b"x")
    assert list(tmp_path.iterdir()) == []
    # an existing folder is refused as before
    with pytest.raises(IsADirectoryError, match=r": it is a folder; give a file name$"):
        with atomic_write(f"{tmp_path}/"):
            pass


def test_load_scene_full_bits_keeps_a_16_bit_pair_and_reads_8_bits_alike(tmp_path: Path) -> None:
    """eval and bench load scenes with full_bits (a 16-bit pair was read at its top 8 bits, 0-4095
    as 0-15, where `depth` keeps 16); the default and an 8-bit pair are read as before."""
    import cv2

    from stereovision.io import load_scene

    deep = (np.arange(24 * 32 * 3).reshape(24, 32, 3) % 4096).astype(np.uint16)
    for name, img in (("s16", deep), ("s8", (deep // 16).astype(np.uint8))):
        (tmp_path / name).mkdir()
        for n in ("left.png", "right.png"):
            cv2.imwrite(str(tmp_path / name / n), img)
    full = load_scene(tmp_path / "s16", full_bits=True)
    assert full.left.dtype == np.uint16 and np.array_equal(full.right, deep)
    assert load_scene(tmp_path / "s16").left.max() == deep.max() >> 8  # default: the top 8 bits
    eight = load_scene(tmp_path / "s8")
    assert np.array_equal(load_scene(tmp_path / "s8", full_bits=True).left, eight.left)


def test_read_ply_says_a_coordinate_beyond_float32_in_words(tmp_path: Path) -> None:
    """A coordinate beyond float32's range (an ASCII float's or a double's 1e39) became inf
    (no point) with only NumPy's "overflow encountered in cast", naming no file (twice for an
    ASCII file; the CLI's view printed it as its warning). It is still inf, said once, naming
    the file and the points; other coordinates read as before."""
    import warnings

    props = "property {t} x\nproperty {t} y\nproperty {t} z\n"
    (tmp_path / "a.ply").write_bytes(
        _ply("ascii", props.format(t="float"), 2) + b"1e39 0 1\n1.1 2 3\n"
    )
    rec = np.array([(-1e300, 0, 1), (1.1, 2, 3)], "<f8")
    (tmp_path / "b.ply").write_bytes(
        _ply("binary_little_endian", props.format(t="double"), 2) + rec.tobytes()
    )
    for name, big in (("a.ply", "1e+39"), ("b.ply", "-1e+300")):
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            pts, _ = read_ply(tmp_path / name)
        assert [str(w.message) for w in said] == [
            f"PLY file {tmp_path / name}: 1 point(s) with a coordinate beyond float32's range "
            f"(e.g. {big}) read as inf (no point)"
        ]
        assert said[0].filename == __file__
        assert np.isinf(pts[0, 0]) and pts[1].tolist() == [np.float32(1.1), 2, 3]


def test_read_ply_of_an_ascii_cloud_with_a_byte_order_mark(tmp_path: Path) -> None:
    """An ASCII PLY saved by a Windows editor opens with a UTF-8 byte-order mark (and CRLF):
    it was 'not a PLY file'; it reads as without the mark."""
    body = _ply("ascii", "property float x\nproperty float y\nproperty float z\n", 2)
    body += b"1 2 3\n4 5 6.5\n"
    (tmp_path / "b.ply").write_bytes(b"\xef\xbb\xbf" + body.replace(b"\n", b"\r\n"))
    pts, cols = read_ply(tmp_path / "b.ply")
    assert pts.tolist() == [[1, 2, 3], [4, 5, 6.5]] and cols is None


def test_load_scene_of_a_file_says_its_folder_is_the_scene(tmp_path: Path) -> None:
    """``load_scene('cones/left.png')`` said "scene directory not found: .../left.png" of a
    file that is there; it says it is a file and names its folder; a missing path is still
    "not found"."""
    d = _scene(tmp_path / "cones", 8, 6)
    with pytest.raises(NotADirectoryError) as info:
        load_scene(d / "left.png")
    assert str(info.value) == (
        f"{d / 'left.png'} is a file, not a scene directory: a scene is the folder holding "
        f"left.png and right.png ({d}?)"
    )
    with pytest.raises(FileNotFoundError, match=r"^scene directory not found: .*nothing$"):
        load_scene(tmp_path / "nothing")


def test_load_scene_of_a_device_says_it_is_no_folder(tmp_path: Path) -> None:
    """``load_scene('/dev/null')`` (or a pipe: there, neither a file nor a folder) said "scene
    directory not found" of a path that is there; it says it is not a folder."""
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    for path in (Path("/dev/null"), pipe):
        with pytest.raises(NotADirectoryError) as info:
            load_scene(path)
        assert str(info.value) == (
            f"{path} is not a folder (a device or a pipe), not a scene directory: a scene is "
            "the folder holding left.png and right.png"
        )


def test_a_scene_link_whose_target_moved_names_it(tmp_path: Path) -> None:
    """A scene folder (or scene root) given as a link whose target moved (a dataset on a disk
    since unmounted) was "scene directory not found: data" / "scene root not found: data", of
    a name ls lists; the link's target is named, as eval's and bench's words name it; a
    missing folder as before."""
    link = tmp_path / "data"
    link.symlink_to("moved/data")
    gone = f"{link} (a link to moved/data, which does not exist)"
    with pytest.raises(FileNotFoundError) as info:
        load_scene(link)
    assert str(info.value) == f"scene directory not found: {gone}"
    with pytest.raises(FileNotFoundError) as info:
        scan_scenes(link)
    assert str(info.value) == f"scene root not found: {gone}"
    with pytest.raises(FileNotFoundError) as info:
        scan_scenes(tmp_path / "nothing")
    assert str(info.value) == f"scene root not found: {tmp_path / 'nothing'}"


def test_a_link_target_holding_a_newline_is_escaped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A link whose target moved and holds a newline (data -> 'moved\\nx') was said with it
    raw: the CLI's one-line error was cut there ("image file not found: data (a link to
    moved"), the rest lost. The target is escaped as paths are ('moved\\\\nx')."""
    from stereovision import cli

    link = tmp_path / "data"
    link.symlink_to("moved\nx")
    said = f"image file not found: {link} (a link to moved\\nx, which does not exist)"
    with pytest.raises(FileNotFoundError) as info:
        read_image(link)
    assert str(info.value) == said
    assert cli.main(["depth", str(link), str(link), "-o", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err == f"stereovision: error: {said}\n"


def test_a_link_to_a_link_whose_target_moved_names_each_link(tmp_path: Path) -> None:
    """data -> current -> moved/data (a disk since unmounted) was "a link to current, which
    does not exist", of a name ls lists: each link is named, to the missing one."""
    (tmp_path / "current").symlink_to(Path("moved") / "data")
    link = tmp_path / "data"
    link.symlink_to("current")
    with pytest.raises(FileNotFoundError) as info:
        read_image(link)
    assert str(info.value) == (
        f"image file not found: {link} (a link to current, a link to moved/data, which does "
        "not exist)"
    )
    with pytest.raises(FileNotFoundError) as info:
        load_scene(link)
    assert str(info.value).endswith(
        "(a link to current, a link to moved/data, which does not exist)"
    )


def test_a_path_holding_a_null_byte_is_refused_in_the_arguments_name(tmp_path: Path) -> None:
    """10c9107a named a null byte in OccupancyGrid.save's arguments only: write_pfm,
    Matches.save_csv, read_pfm (every as_path caller) still raised the OS's bare "ValueError:
    embedded null byte" (a read: "PFM file not found" of a garbled name). as_path refuses it
    in the argument's name, and nothing is written."""
    from stereovision.io import read_pfm, write_pfm
    from stereovision.matches import Matches

    bad = str(tmp_path / "a\x00b.pfm")
    said = r"^path: expected a path without a null byte, got '.*a\\x00b\.pfm'$"
    with pytest.raises(ValueError, match=said):
        write_pfm(bad, np.ones((2, 3), np.float32))
    with pytest.raises(ValueError, match=said):
        read_pfm(bad)
    z = np.zeros(2, np.float32)
    with pytest.raises(ValueError, match=said.replace("pfm", "csv")):
        Matches(z, z, z, z, z, (8, 10)).save_csv(bad[:-3] + "csv")
    assert list(tmp_path.iterdir()) == []


def test_read_pfm_cut_within_its_header_is_truncated(tmp_path: Path) -> None:
    """A PFM cut within its header (an interrupted save; 0 bytes when cut at once) was "not a
    PFM file (bad header)", the words of another format's file; it is truncated, as one cut in
    its data is. Another format's header is still "bad header"."""
    path = tmp_path / "d.pfm"
    path.write_bytes(b"")
    with pytest.raises(ValueError) as info:
        read_pfm(path)
    assert str(info.value) == f"truncated PFM file {path}: the file is empty (0 bytes)"
    for cut in (b"Pf", b"PF\n", b"Pf\n3", b"Pf\n3 2", b"Pf\r\n3 2\r\n-"):
        path.write_bytes(cut)
        with pytest.raises(ValueError) as info:
            read_pfm(path)
        assert str(info.value) == (
            f"truncated PFM file {path}: it ends within its header ({len(cut)} bytes: "
            f"{cut.decode()!r})"
        )
    for other in (b"P5\n2 2", b"Pf\n3 2\nabc", b"Pfx", b"P"):
        path.write_bytes(other)
        with pytest.raises(ValueError) as info:
            read_pfm(path)
        assert str(info.value) == f"not a PFM file (bad header): {path}"


@pytest.mark.parametrize("little", [True, False], ids=["little-data", "big-data"])
def test_read_pfm_warns_of_a_scale_of_the_wrong_sign(tmp_path: Path, little: bool) -> None:
    """A PFM whose writer gave the scale the wrong sign (1.0 before little-endian data) was
    read as garbage without a word (a GT's 14 px as 3.4e-41, inf as 4.6e-41). It warns, naming
    the file; the values are still read in the order the scale says (not guessed). Files of
    the right sign, NaN as unknown included, read without a warning."""
    gt = np.array([[14.0, np.inf, 3.5], [0.0, 7.25, np.nan]], np.float32)
    path = tmp_path / "gt_disp.pfm"
    magic, sizes, _, data = _pfm_bytes(gt, little).split(b"\n", 3)
    path.write_bytes(b"\n".join([magic, sizes, b"1.0" if little else b"-1.0", data]))
    with pytest.warns(UserWarning) as record:
        got = read_pfm(path)
    said, other = ("big", "little") if little else ("little", "big")
    assert [str(w.message) for w in record] == [
        f"PFM file {path}: its scale {1 if little else -1} says {said}-endian, but 83% of its "
        f"finite values read so are below 1e-30 or beyond 1e30, where read {other}-endian they "
        "are plausible: its writer may have given the scale the wrong sign (negative: "
        "little-endian)"
    ]
    assert got.tobytes() == gt.byteswap().tobytes()  # as the scale says, as before
    path.write_bytes(_pfm_bytes(gt, little))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(read_pfm(path), gt)


def test_read_pfm_says_a_magic_of_the_other_kind(tmp_path: Path) -> None:
    """A writer's PF (colour) before a grey map was "truncated PFM file: expected 72 data bytes
    ..., got 24" of a whole file; Pf before colour data read its first third as a grey map of
    interleaved R, G, B values without a word. Both are a bad header, saying which magic the
    data takes; a magic that fits its data reads as before."""
    grey = np.arange(6, dtype=np.float32).reshape(2, 3)
    colour = np.arange(18, dtype=np.float32).reshape(2, 3, 3)
    path = tmp_path / "d.pfm"
    for data, magic, says in (
        (
            grey,
            b"PF",
            "PF says a colour map (3 values a pixel), but its 24 data bytes hold 3x2 "
            "grey values: a grey map's is Pf",
        ),
        (
            colour,
            b"Pf",
            "Pf says a grey map (1 value a pixel), but its 72 data bytes hold 3x2x3 "
            "values: a colour map's is PF",
        ),
    ):
        path.write_bytes(magic + _pfm_bytes(data, True)[2:])
        with pytest.raises(ValueError) as info:
            read_pfm(path)
        assert str(info.value) == f"bad PFM header in {path}: {says}"
        path.write_bytes(_pfm_bytes(data, True))
        np.testing.assert_array_equal(read_pfm(path), data)
