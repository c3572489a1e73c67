"""Exports: coloured PLY (pyvista-readable), organised PCD, NPZ bundle, and their errors."""

from __future__ import annotations

import math
import os
import re
from dataclasses import replace
from fractions import Fraction

import cv2
import numpy as np
import pytest
import synthetic_scene as syn

from stereovision import _core, export
from tests.reference import lzf_ref


@pytest.fixture(scope="module")
def result():
    return syn.depth_result()


def test_cloud_ply_read_by_pyvista(result, tmp_path):
    pv = pytest.importorskip("pyvista")
    path = export.write_cloud_ply(tmp_path / "cloud.ply", result)
    cloud = pv.read(path)
    assert cloud.n_points == len(result.points) == syn.W * syn.H - 100
    np.testing.assert_array_equal(np.asarray(cloud.points), result.points)
    np.testing.assert_array_equal(np.asarray(cloud.point_data["RGB"]), result.colors)
    header = path.read_bytes()[:200]
    assert b"format binary_little_endian 1.0" in header
    assert b"property uchar red" in header
    assert b"comment stereovision point cloud (metres, X right, Y down, Z forward)\n" in header


def test_mesh_ply_read_by_pyvista(result, tmp_path):
    pv = pytest.importorskip("pyvista")
    from stereovision.render import surface_mesh

    mesh = surface_mesh(result, step=2)
    path = export.write_mesh_ply(tmp_path / "mesh.ply", mesh)
    back = pv.read(path)
    assert back.n_points == mesh.n_points
    assert back.n_cells == mesh.n_cells > 0
    np.testing.assert_array_equal(np.asarray(back.faces), np.asarray(mesh.faces))
    np.testing.assert_array_equal(np.asarray(back.point_data["RGB"]), mesh.point_data["RGB"])


def test_open3d_reads_ply_and_pcd(result, tmp_path):
    o3d = pytest.importorskip("open3d")
    ply = o3d.io.read_point_cloud(str(export.write_cloud_ply(tmp_path / "c.ply", result)))
    assert len(ply.points) == len(result.points)
    pcd = o3d.io.read_point_cloud(str(export.write_pcd(tmp_path / "c.pcd", result)))
    assert np.isfinite(np.asarray(pcd.points)).all(axis=1).sum() == len(result.points)


def test_pcd_keeps_image_layout(result, tmp_path):
    path = export.write_pcd(tmp_path / "cloud.pcd", result)
    head = path.read_bytes()[:400].decode("ascii", errors="replace")
    assert f"WIDTH {syn.W}\n" in head
    assert f"HEIGHT {syn.H}\n" in head
    assert f"POINTS {syn.W * syn.H}\n" in head
    pts, cols = export.read_pcd(path)
    assert pts.shape == (syn.H, syn.W, 3)
    assert np.isnan(pts[syn.HOLE]).all()  # missing points stay NaN at their pixel
    assert pts[60, 80, 2] == pytest.approx(syn.BOX_Z)  # box centre
    assert pts[5, 150, 2] == pytest.approx(syn.WALL_Z)
    x, y = result.pixels[:, 0], result.pixels[:, 1]
    np.testing.assert_array_equal(pts[y, x], result.points)
    np.testing.assert_array_equal(cols, result.left_rectified[..., ::-1])


def test_pcd_rgb_is_packed_like_pcl():
    """pcl::PointXYZRGB's rgba with alpha 255 (opaque), as PCL writes it: alpha was 0."""
    rgb = np.array([[255, 0, 0], [0, 128, 1], [255, 255, 255], [0, 0, 0]], np.uint8)
    packed = export._pack_rgb(rgb)
    assert packed.view("<u4").tolist() == [0xFFFF0000, 0xFF008001, 0xFFFFFFFF, 0xFF000000]
    np.testing.assert_array_equal(export._unpack_rgb(packed), rgb)


def test_pcd_written_colours_are_opaque_and_read_back(result, tmp_path):
    """The file's own bytes: alpha 255 in every point's rgb, white (a NaN float) kept bit for
    bit, and read_pcd gives the colours back."""
    left = result.left_rectified.copy()
    left[0, :4] = [[255, 255, 255], [0, 0, 0], [3, 2, 1], [255, 128, 0]]  # BGR
    path = export.write_pcd(tmp_path / "c.pcd", replace(result, left_rectified=left))
    raw = path.read_bytes()
    body = raw[raw.index(b"DATA binary\n") + len(b"DATA binary\n") :]
    bits = np.frombuffer(body, "<u4").reshape(-1, 4)[:, 3]
    assert bits[:4].tolist() == [0xFFFFFFFF, 0xFF000000, 0xFF010203, 0xFF0080FF]
    assert (bits >> 24 == 255).all()
    _, cols = export.read_pcd(path)
    np.testing.assert_array_equal(cols, left[..., ::-1])


def test_pcd_opaque_colours_that_are_nan_or_inf_floats_read_back(tmp_path):
    """With alpha 255 the packed float is NaN for red >= 0x80 (a signalling NaN for 0x80-0xBF,
    which a float conversion would quiet: red 0x80 read as 0xC0) and -inf for (128, 0, 0):
    every such colour comes back from binary and from ASCII PCD (PCL's integer tokens)."""
    rgb = np.array(
        [
            [0, 0, 0],
            [255, 255, 255],
            [255, 0, 0],
            [0, 255, 0],
            [0, 0, 255],
            [128, 0, 0],
            [128, 0, 1],
            [191, 255, 255],
            [192, 0, 0],
            [127, 255, 255],
            [160, 7, 9],
        ],
        np.uint8,
    )
    bits = export._pack_rgb(rgb).view("<u4")
    assert np.isnan(bits.view("<f4")).sum() == 6 and np.isneginf(bits.view("<f4")).sum() == 1
    n = len(rgb)
    xyz = np.arange(3 * n, dtype=np.float32).reshape(n, 3)
    head = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
        f"WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA "
    )
    rec = np.empty(n, [("xyz", "<f4", (3,)), ("rgb", "<u4")])
    rec["xyz"], rec["rgb"] = xyz, bits
    (tmp_path / "b.pcd").write_bytes((head + "binary\n").encode() + rec.tobytes())
    rows = "".join(
        f"{x:g} {y:g} {z:g} {b}\n" for (x, y, z), b in zip(xyz, bits.tolist(), strict=True)
    )
    (tmp_path / "a.pcd").write_text(head + "ascii\n" + rows)
    for name in ("b.pcd", "a.pcd"):
        pts, cols = export.read_pcd(tmp_path / name)
        np.testing.assert_array_equal(cols.reshape(-1, 3), rgb, err_msg=name)
        pts, cols = export.load_cloud(tmp_path / name)  # the GUI's and render's reader
        np.testing.assert_array_equal(pts, xyz, err_msg=name)
        np.testing.assert_array_equal(cols, rgb, err_msg=name)


_COLOURS = np.array([[255, 0, 0], [10, 20, 30], [0, 128, 1]], np.uint8)
_POINTS = np.array([[1, 2, 3], [4, 5, 6], [np.nan, np.nan, np.nan]], np.float32)


def _hand_written_pcd(path, kind, mode, field="rgb", alpha=0):
    """A 3-point PCD as another tool writes it: ``TYPE F F F <kind>``, DATA ``mode``."""
    c = _COLOURS.astype(np.uint32)
    bits = (np.uint32(alpha) << 24) | (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]
    head = (
        f"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z {field}\nSIZE 4 4 4 4\nTYPE F F F {kind}\n"
        "COUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n"
        f"DATA {mode}\n"
    )
    if mode == "binary":
        rec = np.empty(3, [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("c", "<u4")])
        rec["x"], rec["y"], rec["z"] = _POINTS.T
        rec["c"] = bits
        path.write_bytes(head.encode() + rec.tobytes())
    else:
        if kind == "F" and alpha == 0:  # an old writer: the float holding the bits
            tokens = [repr(float(v)) for v in bits.astype("<u4").view("<f4")]
        else:  # PCL's own writer, and TYPE U: the bits as an integer
            tokens = [str(int(v)) for v in bits]
        rows = [f"{x} {y} {z} {t}" for (x, y, z), t in zip(_POINTS.tolist(), tokens, strict=True)]
        path.write_text(head + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("mode", ["binary", "ascii"])
@pytest.mark.parametrize(
    ("kind", "field", "alpha"), [("F", "rgb", 0), ("U", "rgb", 0), ("U", "rgba", 255)]
)
def test_pcd_colours_are_read_as_bits(tmp_path, mode, kind, field, alpha):
    """The packed colour is bits: a ``TYPE U`` field was converted numerically (red read back
    as (127, 0, 0) in binary, black in ASCII), an old writer's ASCII float as black."""
    path = _hand_written_pcd(tmp_path / "c.pcd", kind, mode, field, alpha)
    pts, cols = export.read_pcd(path)
    np.testing.assert_array_equal(pts.reshape(-1, 3), _POINTS)
    np.testing.assert_array_equal(cols.reshape(-1, 3), _COLOURS)
    back, back_cols = export.load_cloud(path)
    np.testing.assert_array_equal(back, _POINTS[:2])
    np.testing.assert_array_equal(back_cols, _COLOURS[:2])


def test_pcd_ascii_float_colour_as_pcl_writes_it(tmp_path):
    """PCL writes a ``TYPE F`` rgb in ASCII as its bits' integer (``4294901760`` for opaque
    red, NaN as a float): read as those bits."""
    path = tmp_path / "pcl.pcd"
    path.write_text(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\n"
        "COUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n"
        f"1 2 3 {0xFFFF0000}\n4 5 6 {0x000A141E}\n"
    )
    _, cols = export.read_pcd(path)
    assert cols.reshape(-1, 3).tolist() == [[255, 0, 0], [10, 20, 30]]
    path.write_text(path.read_text().replace("SIZE 4 4 4 4", "SIZE 4 4 4 8"))
    with pytest.raises(ValueError, match="field 'rgb' of SIZE 8 COUNT 1, expected a packed"):
        export.read_pcd(path)


def test_pcd_padding_fields_are_skipped(tmp_path):
    """PCL's padding field ``_`` may appear several times (an Ouster scan as PCL saves it:
    ``x y z _ intensity _``): such a file was refused as "unsupported fields"."""
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("p", "u1", 4), ("rgb", "<u4")]
    fields += [("i", "<f4"), ("q", "u1", 12)]
    rec = np.zeros(2, dtype=fields)
    rec["x"], rec["y"], rec["z"] = [1.0, 4.0], [2.0, 5.0], [3.0, 6.0]
    rec["rgb"] = [0xFF0000, 0x0A141E]
    rec["p"], rec["q"] = 7, 9
    head = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z _ rgb intensity _\nSIZE 4 4 4 1 4 4 1\n"
        "TYPE F F F U U F U\nCOUNT 1 1 1 4 1 1 12\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary\n"
    )
    path = tmp_path / "pad.pcd"
    path.write_bytes(head.encode() + rec.tobytes())
    pts, cols = export.read_pcd(path)
    assert pts.reshape(-1, 3).tolist() == [[1, 2, 3], [4, 5, 6]]
    assert cols.reshape(-1, 3).tolist() == [[255, 0, 0], [10, 20, 30]]


def test_pcd_ascii_field_of_several_values(tmp_path):
    """An ASCII field of COUNT c takes c columns: the fields after a ``COUNT 2`` one were read
    from the wrong columns (z from the field before it)."""
    path = tmp_path / "count.pcd"
    path.write_text(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS uv x y z rgb\nSIZE 4 4 4 4 4\nTYPE F F F F U\n"
        "COUNT 2 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n"
        f"0.5 0.25 1 2 3 {0xFF0000}\n0.5 0.25 4 5 6 {0x0A141E}\n"
    )
    pts, cols = export.read_pcd(path)
    assert pts.reshape(-1, 3).tolist() == [[1, 2, 3], [4, 5, 6]]
    assert cols.reshape(-1, 3).tolist() == [[255, 0, 0], [10, 20, 30]]
    path.write_text(path.read_text().replace("1 2 3 ", "1 2 "))
    with pytest.raises(ValueError, match=r"count\.pcd"):
        export.read_pcd(path)


def test_empty_ascii_pcd_is_an_empty_cloud(tmp_path):
    """An ASCII PCD with ``POINTS 0`` (PCL saves an empty cloud so) was "rows of 1 values,
    FIELDS has 3" after NumPy's "input contained no data" warning; it is an empty cloud, as
    the binary one was, and ``load_cloud`` says so."""
    import warnings

    head = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
        "WIDTH 0\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 0\nDATA {}\n"
    )
    for mode in ("ascii", "binary"):
        path = tmp_path / f"empty_{mode}.pcd"
        path.write_text(head.format(mode))
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            pts, cols = export.read_pcd(path)
        assert pts.shape == (1, 0, 3) and cols is not None and cols.shape == (1, 0, 3)
        with pytest.raises(ValueError, match=rf"empty point cloud: .*empty_{mode}\.pcd has no"):
            export.load_cloud(path)
    # POINTS 3 and no rows: the count is named (it was "rows of 1 values, FIELDS has 4" after
    # NumPy's "input contained no data" warning; read_ply's and read_pcd's ASCII reading is one)
    path = tmp_path / "no_rows.pcd"
    path.write_text(
        head.replace("WIDTH 0", "WIDTH 3").replace("POINTS 0", "POINTS 3").format("ascii")
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=r"no_rows\.pcd: expected 3 points, got 0$"):
            export.read_pcd(path)


def test_bundle_without_calibration_says_so(result, tmp_path):
    """``load_cloud`` (and so ``view``) of a bundle written without calibration said "empty
    point cloud: ... has no finite 3-D point"; the cause is that it has no intrinsics."""
    path = export.write_npz(tmp_path / "u.npz", replace(result, calibration=None, depth=None))
    with pytest.raises(ValueError, match=r"u\.npz: a depth bundle without calibration \(no intr"):
        export.load_cloud(path)
    pts, _ = export.load_cloud(export.write_npz(tmp_path / "c.npz", result))
    assert len(pts) == len(result.points)


def test_npz_bundle(result, tmp_path):
    # sigma_Z = Z^2 sigma_d / (f B) with sigma_d = 0.5 px: the bundle keeps the uncertainty.
    sigma = (result.depth.astype(np.float64) ** 2 * 0.5 / (syn.F * syn.B)).astype(np.float32)
    result = replace(result, depth_sigma=sigma)
    data = export.read_npz(export.write_npz(tmp_path / "d.npz", result))
    np.testing.assert_array_equal(data["depth"], result.depth)
    np.testing.assert_array_equal(data["depth_sigma"], sigma)
    assert np.isfinite(data["depth_sigma"]).sum() > 1000
    np.testing.assert_array_equal(data["confidence"], result.confidence)
    np.testing.assert_array_equal(data["disparity"], result.disparity)
    np.testing.assert_allclose(data["K"], [[syn.F, 0, syn.CX], [0, syn.F, syn.CY], [0, 0, 1]])
    assert data["baseline"] == pytest.approx(syn.B)
    assert data["doffs"] == 0.0
    assert data["image_size"].tolist() == [syn.W, syn.H]
    assert data["method"] == "gabor"
    # The bundle alone rebuilds the cloud.
    pts, cols = export.load_cloud(tmp_path / "d.npz")
    assert cols is None
    np.testing.assert_allclose(pts, result.points, rtol=1e-6, atol=1e-6)


def test_npz_bundle_keeps_the_searched_range_and_older_bundles_load(result, tmp_path):
    """The bundle kept max_disparity but not min_disparity: a result searched over [8, 40] px
    read back as if searched from 0. It is kept now; a bundle written before has none (as
    depth_sigma): given 0.0, an older [8, 40] px bundle still read back as [0, 40]."""
    ranged = replace(result, min_disparity=8.0, max_disparity=40)
    data = export.read_npz(export.write_npz(tmp_path / "r.npz", ranged))
    assert (data["min_disparity"], data["max_disparity"]) == (8.0, 40)
    assert type(data["min_disparity"]) is float
    older = {k: v for k, v in np.load(tmp_path / "r.npz").items() if k != "min_disparity"}
    np.savez_compressed(tmp_path / "old.npz", **older)
    data = export.read_npz(tmp_path / "old.npz")
    assert "min_disparity" not in data and data["max_disparity"] == 40


def test_export_result_writes_all(result, tmp_path):
    written = export.export_result(result, tmp_path / "out")
    assert set(written) == {
        "cloud.ply",
        "cloud.pcd",
        "depth.npz",
        "depth_mm.png",
        "disparity_16.png",
    }
    assert all(p.is_file() and p.stat().st_size > 0 for p in written.values())
    for name in ("cloud.ply", "cloud.pcd"):
        pts, _ = export.load_cloud(written[name])
        assert len(pts) == len(result.points)
    with pytest.raises(ValueError, match="unknown export format"):
        export.export_result(result, tmp_path, ("obj",))


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs os.mkfifo")
def test_export_result_refuses_a_fifo_before_writing_anything(result, tmp_path):
    """cloud.ply a FIFO: atomic_write refuses it, but at its format's turn, after depth.npz
    was replaced. Refused before any file is written, the folder left as it was."""
    (tmp_path / "depth.npz").write_bytes(b"kept")
    os.mkfifo(tmp_path / "cloud.ply")
    said = f"cannot write {tmp_path / 'cloud.ply'}: it is not a regular file (a FIFO)"
    with pytest.raises(OSError, match=f"^{re.escape(said)}$"):
        export.export_result(result, tmp_path, ("npz", "ply"))
    assert (tmp_path / "depth.npz").read_bytes() == b"kept"
    assert sorted(os.listdir(tmp_path)) == ["cloud.ply", "depth.npz"]


def test_no_calibration_no_cloud(result, tmp_path):
    bare = replace(result, depth=None, depth_sigma=None, calibration=None)
    with pytest.raises(ValueError, match="without a calibration"):
        export.write_cloud_ply(tmp_path / "c.ply", bare)
    with pytest.raises(ValueError, match="without a calibration"):
        export.write_pcd(tmp_path / "c.pcd", bare)
    data = export.read_npz(export.write_npz(tmp_path / "d.npz", bare))
    assert np.isnan(data["depth"]).all() and np.isnan(data["K"]).all()
    assert np.isnan(data["depth_sigma"]).all()


def test_a_left_image_of_another_size_is_named_before_anything_is_written(result, tmp_path):
    """A result whose left_rectified is not the disparity map's size (made by hand: the raw
    left image, a scaled one) failed in NumPy's words where its pixels colour the cloud:
    write_pcd "could not broadcast input array from shape (4800,) into shape (19200,)" (after
    export_result had replaced cloud.ply), a cloud=False result's PLY "index 4800 is out of
    bounds". Named now, nothing written; a result with its own cloud writes its PLY as before."""
    small = replace(result, left_rectified=result.left_rectified[::2, ::2].copy())
    said = (
        "result.left_rectified: 80x60 px, expected the disparity map's 160x120 (the rectified "
        "left image colours the cloud)"
    )
    no_cloud = replace(
        small,
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
    )
    for call in (
        lambda: export.write_pcd(tmp_path / "c.pcd", small),
        lambda: export.write_cloud_ply(tmp_path / "c.ply", no_cloud),
        lambda: export.export_result(small, tmp_path / "out"),
    ):
        with pytest.raises(ValueError) as err:
            call()
        assert str(err.value) == said
    assert sorted(p.name for p in tmp_path.rglob("*")) == []
    export.write_cloud_ply(tmp_path / "c.ply", small)
    assert len(export.load_cloud(tmp_path / "c.ply")[0]) == len(result.points)


def test_every_writer_needing_a_calibration_says_to_pass_calib(result, tmp_path):
    """to_ply, points, filtered and export's writers said the result had no calibration but
    not what to do, where require_depth() says to pass calib=: all now give its hint."""
    bare = replace(result, depth=None, depth_sigma=None, calibration=None)
    hint = "; pass calib=Calibration.from_file(...)"
    calls = {
        "point cloud": (
            lambda: bare.to_ply(tmp_path / "c.ply"),
            lambda: export.write_cloud_ply(tmp_path / "c.ply", bare),
            lambda: export.write_pcd(tmp_path / "c.pcd", bare),
        ),
        "3-D points": (lambda: bare.point_image(),),
        "depth to filter": (lambda: bare.filtered(max_depth=2.0),),
        "depth": (lambda: export.write_depth_png(tmp_path / "d.png", bare),),
    }
    for what, funcs in calls.items():
        for func in funcs:
            with pytest.raises(ValueError) as err:
                func()
            said = str(err.value)
            assert said.startswith(f"no {what}: depth_map was called without a calibration")
            assert said.endswith(hint), said
    with pytest.raises(ValueError) as err:
        export.export_result(bare, tmp_path / "out", ("ply",))
    assert f"{hint}; formats ['ply'] need one" in str(err.value)
    assert not (tmp_path / "out").exists() and not list(tmp_path.iterdir())


def test_a_bytes_path_is_refused_naming_the_argument(result, tmp_path):
    """A bytes file name failed in pathlib with "argument should be a str object or an
    os.PathLike object returning str, not <class 'bytes'>", naming no argument, where
    Calibration.from_file said which: every reader and writer now says it in those words."""
    from stereovision import io
    from stereovision.matches import Matches
    from stereovision.uncalibrated import UncalibratedRectification

    base = str(tmp_path / "x")
    cal = result.calibration
    calls = {
        ".ply": [
            lambda p: result.to_ply(p),
            lambda p: export.write_cloud_ply(p, result),
            lambda p: export.load_cloud(p),
            lambda p: io.write_ply(p, np.zeros((2, 3), np.float32)),
            lambda p: io.read_ply(p),
        ],
        ".pcd": [lambda p: export.write_pcd(p, result)],
        ".npz": [lambda p: export.write_npz(p, result)],
        ".png": [
            lambda p: export.write_depth_png(p, result),
            lambda p: export.write_disparity_png(p, result),
            lambda p: io.imread(p),
            lambda p: io.read_image(p),
        ],
        ".pfm": [lambda p: io.write_pfm(p, np.zeros((2, 2), np.float32)), io.read_pfm],
        ".csv": [
            lambda p: Matches.from_csv(p, (4, 4)),
            lambda p: Matches(*(np.zeros(0, np.float32) for _ in range(5)), (4, 4)).save_csv(p),
        ],
        ".yaml": [cal.save, type(cal).load, type(cal).from_file],
        ".json": [UncalibratedRectification.load],
    }
    for suffix, funcs in calls.items():
        name = base + suffix
        want = (
            f"path: expected a str or os.PathLike file name, got the bytes {name!r}: "
            "decode it first (os.fsdecode(path))"
        )
        for func in funcs:
            with pytest.raises(TypeError) as err:
                func(name.encode())
            assert str(err.value) == want, (suffix, str(err.value))
    with pytest.raises(TypeError, match=r"^directory: expected a str or os.PathLike file name"):
        io.load_scene(base.encode())
    assert not list(tmp_path.iterdir())


def test_load_cloud_errors(tmp_path):
    fake = tmp_path / "fake.ply"
    fake.write_bytes(b"\x89PNG not a ply")
    with pytest.raises(ValueError, match="not a PLY file"):
        export.load_cloud(fake)
    other = tmp_path / "notes.txt"
    other.write_text("hello")
    with pytest.raises(ValueError, match=r"not a point cloud file \(PLY, PCD or NPZ\)"):
        export.load_cloud(other)
    with pytest.raises(FileNotFoundError, match="not found"):
        export.load_cloud(tmp_path / "missing.ply")
    from stereovision.io import write_ply

    write_ply(tmp_path / "nan.ply", np.full((4, 3), np.nan, np.float32), drop_invalid=False)
    with pytest.raises(ValueError, match="empty point cloud"):
        export.load_cloud(tmp_path / "nan.ply")
    trunc = tmp_path / "t.pcd"
    trunc.write_bytes(
        b"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
        b"WIDTH 10\nHEIGHT 1\nPOINTS 10\nDATA binary\n" + b"\0" * 12
    )
    with pytest.raises(ValueError, match="truncated PCD"):
        export.load_cloud(trunc)
    bad_npz = tmp_path / "b.npz"
    np.savez(bad_npz, foo=np.zeros(3))
    with pytest.raises(ValueError, match="not a stereovision depth bundle"):
        export.load_cloud(bad_npz)


@pytest.mark.parametrize(
    ("depth", "k", "message"),
    [
        (np.ones(4), np.eye(3), r"its depth has shape \(4,\), expected \(H, W\)"),
        (np.ones((4, 4)), np.ones(3), r"its K has shape \(3,\), expected \(3, 3\)"),
        (np.ones((4, 4)), np.zeros((3, 3)), "its K has focal lengths 0 and 0, expected positive"),
        (np.array(["a", "b"]), np.eye(3), "its depth is not numbers"),
        (np.ones((4, 4), bool), np.eye(3), r"its depth is not numbers \(bool\)"),
    ],
)
def test_a_foreign_npz_bundle_is_named(tmp_path, depth, k, message):
    """A bundle of another writer: a 1-D depth or K raised an unpacking error or an IndexError
    ("too many indices"), a K of zeros said "empty point cloud" (after divide-by-zero
    warnings). The file and what is wrong with it are named."""
    path = tmp_path / "other.npz"
    np.savez(path, depth=depth, K=k)
    with pytest.raises(ValueError, match=f"other.npz: {message}"):
        export.load_cloud(path)


def test_damaged_pcd_and_npz_are_value_errors(result, tmp_path):
    """A garbled PCD type letter (a KeyError before) and a bundle whose compressed data is
    damaged (zlib.error before) are ValueErrors naming the file."""
    bad_type = tmp_path / "t.pcd"
    bad_type.write_bytes(
        b"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F Q F\nCOUNT 1 1 1\n"
        b"WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary\n" + b"\0" * 12
    )
    with pytest.raises(ValueError, match=r"t\.pcd: unsupported fields"):
        export.load_cloud(bad_type)
    good = export.write_npz(tmp_path / "a.npz", result)
    data = bytearray(good.read_bytes())
    # Flip bytes inside the first member's deflate stream (past its 30-byte local header and
    # name), where the zip directory still reads fine.
    name_len = int.from_bytes(data[26:28], "little")
    start = 30 + name_len + int.from_bytes(data[28:30], "little")
    for i in range(start + 4, start + 40):
        data[i] ^= 0x5A
    damaged = tmp_path / "d.npz"
    damaged.write_bytes(bytes(data))
    for fn in (export.read_npz, export.load_cloud):
        with pytest.raises(ValueError, match=r"d\.npz"):
            fn(damaged)
    # an ASCII PCD with a short row (NumPy's message alone before) or too few columns
    head = b"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
    for name, rows, says in (
        ("short.pcd", b"1 2 3\n4 5\n", r"damaged PCD file .*short\.pcd: "),
        ("narrow.pcd", b"1 2\n4 5\n", r"narrow\.pcd: rows of 2 values, FIELDS has 3"),
    ):
        (tmp_path / name).write_bytes(head + b"WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n" + rows)
        with pytest.raises(ValueError, match=says):
            export.read_pcd(tmp_path / name)


def test_depth_png_in_millimetres(result, tmp_path):
    """16-bit depth as ROS 16UC1 / TUM / Open3D read it: round(Z * 1000), 0 = none; depths
    that do not fit 16 bits are dropped, not clipped to 65.535 m."""
    import cv2

    path = export.write_depth_png(tmp_path / "d.png", result)
    raw = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    assert raw.dtype == np.uint16 and raw.shape == (syn.H, syn.W)
    assert raw[60, 80] == round(syn.BOX_Z * 1000) and raw[5, 150] == round(syn.WALL_Z * 1000)
    assert (raw[syn.HOLE] == 0).all()
    back = export.read_depth_png(path)
    np.testing.assert_allclose(back, result.depth, atol=0.0005 + 1e-7)
    np.testing.assert_array_equal(np.isnan(back), np.isnan(result.depth))
    z = np.array([[0.0004, 0.0006, 1.2344, 65.535, 65.5356, np.inf, np.nan, -2.0]])
    raw = cv2.imread(str(export.write_depth_png(tmp_path / "z.png", z)), cv2.IMREAD_UNCHANGED)
    assert raw.tolist() == [[0, 1, 1234, 65535, 0, 0, 0, 0]]
    tum = export.read_depth_png(export.write_depth_png(tmp_path / "t.png", z, scale=5000), 5000)
    assert tum[0, 2] == pytest.approx(1.2344, abs=1e-4) and np.isnan(tum[0, 3])
    bare = replace(result, depth=None, depth_sigma=None, calibration=None)
    with pytest.raises(ValueError, match="no depth"):
        export.write_depth_png(tmp_path / "n.png", bare)
    with pytest.raises(ValueError, match="scale"):
        export.write_depth_png(tmp_path / "n.png", z, scale=0)
    with pytest.raises(ValueError, match=r"\(H, W\) array"):
        export.write_depth_png(tmp_path / "n.png", np.zeros(5))
    assert not (tmp_path / "n.png").exists()


@pytest.mark.parametrize(
    ("scale", "error", "message"),
    [
        ("1000", TypeError, "scale: expected a number (units per metre), got str '1000'"),
        (True, TypeError, "scale: expected a number (units per metre), got bool True"),
        (None, TypeError, "scale: expected a number (units per metre), got NoneType None"),
        (0, ValueError, "scale: expected a positive finite number, got 0"),
        (-1000.0, ValueError, "scale: expected a positive finite number, got -1000.0"),
        (math.nan, ValueError, "scale: expected a positive finite number, got nan"),
        (math.inf, ValueError, "scale: expected a positive finite number, got inf"),
    ],
)
def test_encode_depth_png_refuses_a_bad_scale(scale, error, message, tmp_path):
    """A bad scale is an error naming ``scale`` (a string failed inside numpy's isfinite), for
    the writer and the reader alike (read_depth_png's check had the same numpy failure)."""
    with pytest.raises(error) as info:
        export.encode_depth_png(np.ones((2, 2)), scale=scale)
    assert str(info.value) == message
    png = export.write_depth_png(tmp_path / "d.png", np.ones((2, 2)))
    with pytest.raises(error) as info:
        export.read_depth_png(png, scale=scale)
    assert str(info.value) == message


def test_encode_depth_png_takes_any_real_scale():
    """Ints, numpy scalars and fractions are numbers (a Fraction made numpy's rint fail on an
    object array): 1.2344 m at 5000 units per metre is 6172."""
    z = np.array([[1.2344, np.nan]])
    for scale in (5000, 5000.0, np.float32(5000), np.int64(5000), Fraction(5000)):
        png = export.encode_depth_png(z, scale=scale)
        raw = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_UNCHANGED)
        assert raw.tolist() == [[6172, 0]]


def test_a_scale_too_large_for_a_float_is_named():
    """An int of 10**400 units per metre failed inside math.isfinite ('int too large to convert
    to float', no argument named); it is not a finite number."""
    for call in (
        lambda: export.encode_depth_png(np.ones((2, 2)), scale=10**400),
        lambda: export.read_depth_png("unused.png", scale=10**400),
    ):
        with pytest.raises(
            ValueError,
            match=r"^scale: expected a positive finite number, got an integer of 401 digits",
        ):
            call()


def test_disparity_png_kitti_format(data_dir, result, tmp_path):
    """KITTI's disparity PNG (d * 256): ours round-trips within 1/512 px, and KITTI's own GT
    file reads as the PFM it was converted to."""
    back = export.read_disparity_png(export.write_disparity_png(tmp_path / "d.png", result))
    finite = np.isfinite(result.disparity) & (result.disparity > 0)
    np.testing.assert_array_equal(np.isfinite(back), finite)
    np.testing.assert_allclose(back[finite], result.disparity[finite], atol=1 / 512 + 1e-6)
    from stereovision.io import read_pfm

    gt = read_pfm(data_dir / "kitti2015" / "000005_10" / "gt_disp.pfm")
    path = export.write_disparity_png(tmp_path / "gt.png", np.where(np.isinf(gt), np.nan, gt))
    again = export.read_disparity_png(path)
    ok = np.isfinite(gt)
    np.testing.assert_array_equal(np.isfinite(again), ok)
    np.testing.assert_allclose(again[ok], gt[ok], atol=1 / 512 + 1e-6)
    (tmp_path / "rgb.png").write_bytes((tmp_path / "gt.png").read_bytes()[:40])
    with pytest.raises(ValueError, match="16-bit PNG"):
        export.read_disparity_png(tmp_path / "rgb.png")
    with pytest.raises(FileNotFoundError):
        export.read_depth_png(tmp_path / "none.png")


def _voxel_reference(points, colors, voxel):
    """Plain Python: group by cube, mean per cube, sorted by (z, y, x) cube index."""
    groups: dict[tuple[int, int, int], list[int]] = {}
    for i, p in enumerate(points):
        if np.isfinite(p).all():
            groups.setdefault(tuple(int(v) for v in np.floor(p / voxel))[::-1], []).append(i)
    keys = sorted(groups)
    pts = np.array([points[groups[k]].mean(axis=0) for k in keys])
    cols = np.array([np.rint(colors[groups[k]].astype(float).mean(axis=0)) for k in keys])
    return pts, cols


def test_voxel_downsample_against_a_plain_reference(result):
    rng = np.random.default_rng(3)
    pts = result.points[rng.choice(len(result.points), 3000, replace=False)].astype(np.float64)
    pts[5] = np.nan
    cols = rng.integers(0, 256, size=pts.shape).astype(np.uint8)
    for voxel in (0.05, 0.2):
        down, dc = export.voxel_downsample(pts, cols, voxel=voxel)
        ref_p, ref_c = _voxel_reference(pts, cols, voxel)
        assert len(down) == len(ref_p) < len(pts)
        np.testing.assert_allclose(down, ref_p, rtol=1e-6, atol=1e-6)
        np.testing.assert_array_equal(dc, ref_c)
    # coordinates whose cube indices do not fit one int64 key take the row-wise path
    far = pts[:50].copy()
    far[::2, 0] += 1e12
    down, _ = export.voxel_downsample(far, cols[:50], voxel=1e-4)
    ref_p, _ = _voxel_reference(far, cols[:50], 1e-4)
    np.testing.assert_allclose(down, ref_p, rtol=1e-6)
    assert export.voxel_downsample(np.zeros((0, 3)))[0].shape == (0, 3)
    with pytest.raises(ValueError, match="voxel"):
        export.voxel_downsample(pts, voxel=0)
    with pytest.raises(ValueError, match="too small"):
        export.voxel_downsample(pts, voxel=1e-300)
    with pytest.raises(ValueError, match="colors"):
        export.voxel_downsample(pts, cols[:10])
    with pytest.raises(ValueError, match="points"):
        export.voxel_downsample(pts[:, :2])


@pytest.mark.parametrize("side", [1.0, 2, np.float32(0.5), np.int64(3)])
def test_voxel_downsample_a_positional_cube_side_is_named(side: object) -> None:
    """voxel_downsample(pts, 1.0): the side lands in ``colors``; the error said
    "colors: expected shape (3, 3), got ()" and now says a number came and where it goes."""
    pts = np.zeros((3, 3))
    want = f"got the number {side}; give the cube side by keyword: .*voxel={side}\\)"
    with pytest.raises(ValueError, match=want):
        export.voxel_downsample(pts, side)  # type: ignore[call-overload]


def test_voxel_downsample_refuses_colours_it_would_wrap() -> None:
    """Colours are averaged and cast to uint8: 300 came out 44 and NaN 0 (a cast warning),
    silently. Colours 0-255 of any numeric type are averaged as before; others are refused."""
    pts = np.zeros((3, 3))
    _down, dc = export.voxel_downsample(pts, np.array([[10.0, 20, 30], [20, 30, 40], [30, 40, 50]]))
    assert dc is not None and dc.tolist() == [[20, 30, 40]]
    for bad in (np.full((3, 3), 300.0), np.full((3, 3), np.nan), np.full((3, 3), -1)):
        with pytest.raises(ValueError, match=r"colors: expected colours 0-255, got 3 point\(s\)"):
            export.voxel_downsample(pts, bad)
    with pytest.raises(ValueError, match="expected uint8 colours 0-255, got bool"):
        export.voxel_downsample(pts, np.ones((3, 3), bool))


def test_point_image_without_the_cloud(result, tmp_path):
    """``cloud=False`` results (the live rate) still give their image-shaped points and an
    organised PCD: from the depth map, as the cloud would have them."""
    pts = result.point_image()
    assert pts.shape == (syn.H, syn.W, 3) and pts.dtype == np.float32
    x, y = result.pixels[:, 0], result.pixels[:, 1]
    np.testing.assert_allclose(pts[y, x], result.points, atol=1e-5)
    assert np.isnan(pts[~np.isfinite(result.depth)]).all()
    assert np.isnan(pts[syn.HOLE]).all()
    bare = replace(
        result,
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
    )
    back, cols = export.read_pcd(export.write_pcd(tmp_path / "live.pcd", bare))
    np.testing.assert_allclose(back[y, x], result.points, atol=1e-5)
    assert np.isfinite(back[..., 2]).sum() == len(result.points)
    np.testing.assert_array_equal(cols, result.left_rectified[..., ::-1])
    # a filtered result loses its far points in the image too
    near = result.filtered(max_depth=float(syn.BOX_Z) + 0.01)
    far = near.point_image()[5, 150]
    assert np.isnan(far).all() and near.point_image()[60, 80, 2] == pytest.approx(syn.BOX_Z)
    with pytest.raises(ValueError, match="without a calibration"):
        replace(result, depth=None, calibration=None).point_image()


def test_point_image_filled_keeps_the_guesses_within_the_working_range(result):
    """Filled pixels have a disparity and no depth: ``filled=True`` gives them their point
    within :meth:`filtered`'s depth range, and none under an uncertainty limit."""
    z = np.where(np.isfinite(result.disparity), result.depth, np.nan)
    guess = np.zeros(result.disparity.shape, bool)
    guess[70:90, 20:100] = True  # pretend these were filled: no depth, a disparity (box and wall)
    # and these dropped: measured (confidence > 0), no depth (within sigma_d of infinity)
    dropped = np.zeros_like(guess)
    dropped[30:40, 20:100] = True
    assert (result.confidence[dropped] > 0).all() and np.isfinite(result.depth[dropped]).all()
    filled = replace(
        result,
        depth=np.where(guess | dropped, np.nan, z).astype(np.float32),
        confidence=np.where(guess, 0, result.confidence).astype(np.float32),
    )
    assert np.isnan(filled.point_image()[guess]).all()
    both = filled.point_image(filled=True)
    np.testing.assert_allclose(both[guess], result.point_image()[guess], atol=1e-5)
    np.testing.assert_array_equal(both[~guess], filled.point_image()[~guess])
    # a dropped pixel is not a guess: it stayed out ("also the filled pixels", not every one
    # without a depth; a far point's depth interval reaches infinity)
    assert np.isnan(both[dropped]).all()
    box, wall = float(syn.BOX_Z), float(syn.WALL_Z)
    assert box < wall
    assert filled.limits == {}
    near = filled.filtered(max_depth=0.5 * (box + wall)).filtered(max_depth=wall * 2)
    assert near.limits == {"max_depth": 0.5 * (box + wall)}  # the tighter of the two
    pts = near.point_image(filled=True)
    far_guess = guess & (result.depth > near.limits["max_depth"])
    near_guess = guess & (result.depth <= near.limits["max_depth"])
    assert far_guess.sum() > 0 and near_guess.sum() > 0
    assert np.isnan(pts[far_guess]).all() and np.isfinite(pts[near_guess]).all()
    sigma = np.where(np.isfinite(filled.depth), 0.01, np.nan).astype(np.float32)
    trusted = replace(filled, depth_sigma=sigma).filtered(max_sigma=1e3)
    assert trusted.limits == {"max_sigma": 1e3}
    assert np.isnan(trusted.point_image(filled=True)[guess]).all()


def test_cloud_false_result_writes_the_same_cloud(data_dir, tmp_path):
    """A ``cloud=False`` result (what ``stream`` hands ``on_result``) has no points of its own:
    ``write_cloud_ply`` and ``export_result`` write the cloud its depth map gives, the same
    points and colours as the ``cloud=True`` result (they wrote a PLY with 0 vertices)."""
    import stereovision as sv
    from stereovision.io import load_scene, read_ply

    scene = load_scene(data_dir / "eth3d" / "terrace")
    kw = {"method": "census", "max_disparity": scene.max_disparity}
    full = sv.depth_map(scene.left, scene.right, scene.calib, **kw)
    live = sv.depth_map(scene.left, scene.right, scene.calib, cloud=False, **kw)
    assert len(live.points) == 0 and len(full.points) > 10_000
    pts, cols = read_ply(export.write_cloud_ply(tmp_path / "live.ply", live))
    np.testing.assert_array_equal(pts, full.points)
    np.testing.assert_array_equal(cols, full.colors)
    written = export.export_result(live, tmp_path / "out", ("ply", "pcd"))
    for name in ("cloud.ply", "cloud.pcd"):
        back, _ = export.load_cloud(written[name])
        assert len(back) == len(full.points)
        np.testing.assert_allclose(back, full.points, atol=1e-6)
    # a result without its left image: the same points, black
    bare = replace(live, left_rectified=None)
    pts, cols = read_ply(export.write_cloud_ply(tmp_path / "bare.ply", bare))
    np.testing.assert_array_equal(pts, full.points)
    assert not cols.any()


def _grid_mesh(n):
    """A triangulated height field of about ``n`` vertices with per-vertex colours."""
    pv = pytest.importorskip("pyvista")
    side = int(n**0.5)
    ys, xs = np.mgrid[0:side, 0:side]
    pts = np.stack([xs, ys, np.sin(xs * 0.1 + ys * 0.07)], -1).reshape(-1, 3).astype(np.float32)
    i = (ys[:-1, :-1] * side + xs[:-1, :-1]).ravel()
    tri = np.concatenate(
        [np.stack([i, i + 1, i + side], 1), np.stack([i + 1, i + side + 1, i + side], 1)]
    )
    faces = np.hstack([np.full((len(tri), 1), 3), tri]).astype(np.int64).ravel()
    mesh = pv.PolyData(pts, faces)
    mesh.point_data["RGB"] = (np.arange(len(pts) * 3) % 251).astype(np.uint8).reshape(-1, 3)
    return mesh


class _Recorder:
    """A file that keeps what each write() was given (its type and size), and the bytes."""

    def __init__(self):
        self.calls = []
        self.data = bytearray()

    def write(self, b):
        self.calls.append((type(b).__name__, memoryview(b).nbytes))
        self.data += memoryview(b).cast("B")
        return memoryview(b).nbytes


def test_pcd_and_mesh_writers_write_the_records_without_copying_them(result, tmp_path, monkeypatch):
    """write_pcd and write_mesh_ply copied their whole record arrays into bytes (tobytes) before
    writing them, as write_ply did: the records go to the file as they are now, and the files
    are byte for byte what they were (SHA-256 of the earlier writer's files)."""
    import contextlib
    import hashlib
    import tracemalloc

    mesh = _grid_mesh(100)
    # The mesh is synthetic, so its file's digest is pinned (the earlier writer's). The PCD's
    # would pin a real depth_map result to the last bit (any matcher change, another CPU): its
    # bytes are checked against a read-back instead.
    ply_digest = "2fdbd6a72a99e021e33042c1223ba8347e821cb35a624a6a613064c663158081"
    path = export.write_mesh_ply(tmp_path / "m.ply", mesh)
    assert hashlib.sha256(path.read_bytes()).hexdigest() == ply_digest
    pcd_path = export.write_pcd(tmp_path / "c.pcd", result)
    raw = pcd_path.read_bytes()
    body = raw[raw.index(b"DATA binary\n") + len(b"DATA binary\n") :]
    pts, cols = export.organised_points(result)
    h, w = pts.shape[:2]
    assert raw.startswith(b"# .PCD v0.7") and f"WIDTH {w}\nHEIGHT {h}\n".encode() in raw
    assert b"FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\n" in raw
    rec = np.frombuffer(body, np.float32).reshape(-1, 4)
    assert len(rec) == h * w
    np.testing.assert_array_equal(rec[:, :3], pts.reshape(-1, 3))
    rgb = rec[:, 3].view(np.uint32)  # PCL's packed 0xFFRRGGBB (alpha 255)
    flat = cols.reshape(-1, 3).astype(np.uint32)
    packed = (flat[:, 0] << 16) | (flat[:, 1] << 8) | flat[:, 2]
    np.testing.assert_array_equal(rgb, np.uint32(0xFF000000) | packed)
    files = []

    @contextlib.contextmanager
    def recording(path, mode="wb"):
        files.append(_Recorder())
        yield files[-1]

    monkeypatch.setattr(export, "atomic_write", recording)
    export.write_pcd(tmp_path / "c.pcd", result)
    export.write_mesh_ply(tmp_path / "m.ply", mesh)
    pcd, ply = files
    assert bytes(pcd.data) == (tmp_path / "c.pcd").read_bytes()
    assert bytes(ply.data) == (tmp_path / "m.ply").read_bytes()
    # the header as bytes, then the records themselves (an array view, no bytes copy)
    assert [t for t, _ in pcd.calls] == ["bytes", "ndarray"]
    assert pcd.calls[1][1] == 16 * result.depth.size
    assert [t for t, _ in ply.calls] == ["bytes", "ndarray", "ndarray"]
    monkeypatch.undo()
    big = _grid_mesh(200_000)
    tracemalloc.start()
    try:
        export.write_mesh_ply(tmp_path / "big.ply", big)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    records = 15 * big.n_points + 13 * big.n_cells  # vertex and face records
    assert peak < 1.9 * records  # 2.2 with the copies; the int32 indices are the rest


# ------------------------------------------------------------------ mutation audit (value tests)


def test_pcd_header_has_every_pcl_line_in_order(result, tmp_path):
    """PCL's reader wants VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS,
    DATA in that order (parsed back by hand)."""
    raw = export.write_pcd(tmp_path / "c.pcd", result).read_bytes()
    head = raw[: raw.index(b"DATA binary\n") + len(b"DATA binary\n")].decode("ascii")
    lines = [ln.split() for ln in head.splitlines() if not ln.startswith("#")]
    assert [ln[0] for ln in lines] == [
        "VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT", "POINTS",
        "DATA",
    ]  # fmt: skip
    meta = {ln[0]: ln[1:] for ln in lines}
    assert meta["COUNT"] == ["1"] * 4 and meta["VIEWPOINT"] == ["0", "0", "0", "1", "0", "0", "0"]
    assert meta["POINTS"] == [str(syn.W * syn.H)]


def test_npz_bundle_of_a_millimetre_rig_with_doffs(result, tmp_path):
    """The bundle's baseline is in metres and its doffs the calibration's, whatever the unit the
    rig was calibrated in; its maps are float32 and its scalars Python values."""
    c = syn.calibration()
    K2 = c.K2.copy()
    K2[0, 2] += 4.5  # the right camera's principal point 4.5 px further right
    mm = replace(c, K2=K2, T=c.T * 1000.0, unit="mm", doffs=4.5)
    data = export.read_npz(export.write_npz(tmp_path / "mm.npz", replace(result, calibration=mm)))
    assert data["baseline"] == pytest.approx(syn.B) and isinstance(data["baseline"], float)
    assert data["doffs"] == 4.5 and isinstance(data["doffs"], float)
    assert isinstance(data["method"], str) and data["method"] == "gabor"
    for key in ("depth", "depth_sigma", "confidence", "disparity"):
        assert data[key].dtype == np.float32, key


def test_bundle_cloud_uses_fy_for_y(tmp_path):
    """``Y = (y - cy) Z / fy`` for a bundle whose K has fx != fy (closed form)."""
    depth = np.full((4, 6), 2.0)
    k = np.array([[100.0, 0.0, 2.5], [0.0, 80.0, 1.5], [0.0, 0.0, 1.0]])
    np.savez(tmp_path / "k.npz", depth=depth, K=k)
    pts, _ = export.load_cloud(tmp_path / "k.npz")
    ys, xs = np.mgrid[0:4, 0:6]
    want = np.stack([(xs - 2.5) * 2 / 100, (ys - 1.5) * 2 / 80, depth], -1).reshape(-1, 3)
    np.testing.assert_allclose(pts, want, rtol=1e-6)
    np.savez(tmp_path / "f.npz", depth=depth, K=np.diag([100.0, 0.0, 1.0]))
    with pytest.raises(ValueError, match="focal lengths 100 and 0, expected positive"):
        export.load_cloud(tmp_path / "f.npz")


def test_load_cloud_drops_partly_nan_points_and_pcd_refuses_a_negative_height(tmp_path):
    path = tmp_path / "p.pcd"
    head = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
        "WIDTH 3\nHEIGHT {}\nPOINTS 3\nDATA ascii\n"
    )
    path.write_text(head.format(1) + "1 2 3\n4 nan 6\n7 8 9\n")
    pts, _ = export.load_cloud(path)
    assert pts.tolist() == [[1, 2, 3], [7, 8, 9]]
    path.write_text(head.format(-1) + "1 2 3\n")
    with pytest.raises(ValueError, match=r"negative WIDTH or HEIGHT \(3 x -1\)"):
        export.read_pcd(path)


def test_export_result_pngs_hold_depth_and_disparity(result, tmp_path):
    """depth_mm.png holds the depth in millimetres and disparity_16.png KITTI's disparity."""
    written = export.export_result(result, tmp_path / "out", ("depth16", "disp16"))
    z = export.read_depth_png(written["depth_mm.png"])
    np.testing.assert_allclose(z, result.depth, atol=0.0005 + 1e-7)
    d = export.read_disparity_png(written["disparity_16.png"])
    ok = np.isfinite(result.disparity) & (result.disparity > 0)
    np.testing.assert_allclose(d[ok], result.disparity[ok], atol=1 / 512 + 1e-6)


def test_organised_points_colours_without_the_left_image(result):
    """Without the left image the colours are the cloud's, each at its own pixel (x, y)."""
    _, cols = export.organised_points(replace(result, left_rectified=None))
    x, y = result.pixels[:, 0], result.pixels[:, 1]
    np.testing.assert_array_equal(cols[y, x], result.colors)


def test_voxel_of_true_is_refused():
    with pytest.raises(ValueError, match="voxel: expected a positive cube side, got True"):
        export.voxel_downsample(np.zeros((3, 3)), voxel=True)


def test_depth_png_refuses_what_it_cannot_read_or_write(tmp_path) -> None:
    """An 8-bit or a 3-channel 16-bit PNG is not a depth image; an empty map is named; ".PNG"
    is a PNG; a map with no positive depth (all 0, no value at all) is not warned about."""
    import warnings

    cv2.imwrite(str(tmp_path / "u8.png"), np.full((2, 3), 7, np.uint8))
    cv2.imwrite(str(tmp_path / "c16.png"), np.full((2, 3, 3), 700, np.uint16))
    for name, got in (
        ("u8.png", r"uint8 with shape \(2, 3\)"),
        ("c16.png", r"uint16 with shape \(2, 3, 3\)"),
    ):
        with pytest.raises(ValueError, match=rf"expected a single-channel 16-bit PNG, got {got}"):
            export.read_depth_png(tmp_path / name)
    with pytest.raises(ValueError, match=r"depth: expected a non-empty \(H, W\) array"):
        export.write_depth_png(tmp_path / "e.png", np.zeros((0, 4)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        export.write_depth_png(tmp_path / "z.PNG", np.zeros((2, 3)))
    assert export.read_depth_png(tmp_path / "z.PNG").shape == (2, 3)
    assert np.isnan(export.read_depth_png(tmp_path / "z.PNG")).all()


# -------------------------------------------------------- mutation audit 2 (value tests)


def _fake_mesh(points, faces):
    """What write_mesh_ply reads of a mesh: points, the flat VTK face list, point data."""
    from types import SimpleNamespace

    return SimpleNamespace(
        points=np.asarray(points, np.float32), faces=np.asarray(faces), point_data={}
    )


def test_mesh_ply_refuses_quads(tmp_path):
    """Quads are refused by name, also when the face list's length is a multiple of 4 and
    every 4th entry (read as a triangle's count) is at least 3."""
    pts = np.zeros((8, 3))
    for faces in ([4, 3, 4, 5, 6], [4, 3, 4, 5, 6] * 4):
        with pytest.raises(ValueError, match="only triangle meshes are supported"):
            export.write_mesh_ply(tmp_path / "q.ply", _fake_mesh(pts, faces))
    assert not (tmp_path / "q.ply").exists()


def test_mesh_ply_refuses_float64_vertices_beyond_float32(tmp_path):
    """A float64 vertex of 1e39 m was written as inf by the float32 cast (NumPy's overflow
    warning alone); refused now in write_ply's words (3581344), nothing written."""
    from types import SimpleNamespace

    pts = np.array([[0.0, 0.0, 1.0], [1e39, 0.0, 1.0], [0.0, 1.0, 1.0]])
    mesh = SimpleNamespace(points=pts, faces=np.array([3, 0, 1, 2]), point_data={})
    with pytest.raises(ValueError) as exc:
        export.write_mesh_ply(tmp_path / "m.ply", mesh)
    assert str(exc.value) == (
        "mesh.points: 1 finite value(s) beyond float32's range (e.g. 1e+39) would be written as inf"
    )
    assert list(tmp_path.iterdir()) == []


def test_unpack_rgb_refuses_values_that_are_not_4_bytes():
    with pytest.raises(ValueError, match="packed rgb: expected 4-byte values, got float64"):
        export._unpack_rgb(np.array([1.0, 2.0]))


_XYZ_HEAD = (
    "# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE {sizes}\nTYPE {types}\nCOUNT {counts}\n"
    "WIDTH {w}\nHEIGHT 1\nPOINTS {w}\nDATA {mode}\n"
)


def _xyz_pcd(path, rows="1 2 3\n4 5 6\n", w=2, mode="ascii", fields="x y z", counts="1 1 1"):
    n = len(fields.split())
    head = _XYZ_HEAD.format(
        fields=fields, sizes=" ".join(["4"] * n), types=" ".join(["F"] * n), counts=counts,
        w=w, mode=mode,
    )  # fmt: skip
    path.write_text(head + rows)
    return path


def test_read_pcd_names_what_is_wrong(tmp_path):
    """read_pcd called directly (not through load_cloud, which checks the magic first)."""
    with pytest.raises(FileNotFoundError, match=r"PCD file not found: .*none\.pcd"):
        export.read_pcd(tmp_path / "none.pcd")
    (tmp_path / "a.ply").write_text("ply\nformat ascii 1.0\nend_header\n")
    with pytest.raises(ValueError, match=r"not a PCD file: .*a\.ply"):
        export.read_pcd(tmp_path / "a.ply")
    xy = _xyz_pcd(tmp_path / "xy.pcd", "1 2\n3 4\n", fields="x y", counts="1 1")
    with pytest.raises(ValueError, match=r"fields \['x', 'y'\], expected x y z"):
        export.read_pcd(xy)
    neg = _xyz_pcd(tmp_path / "neg.pcd", w=-1)
    with pytest.raises(ValueError, match=r"negative WIDTH or HEIGHT \(-1 x 1\)"):
        export.read_pcd(neg)
    more = _xyz_pcd(tmp_path / "more.pcd", "1 2 3\n4 5 6\n7 8 9\n")
    with pytest.raises(ValueError, match=r"more\.pcd: expected 2 points, got 3$"):
        export.read_pcd(more)
    # PCL's binary_compressed (LZF, fields one after the other) is not read as binary records
    packed = _xyz_pcd(tmp_path / "lzf.pcd", "", mode="binary_compressed")
    packed.write_bytes(packed.read_bytes() + b"\0" * 64)
    with pytest.raises(ValueError, match=r"lzf\.pcd: 0 bytes of compressed points, expected 24"):
        export.read_pcd(packed)
    other = _xyz_pcd(tmp_path / "lzf.pcd", "", mode="binary_zstd")
    with pytest.raises(ValueError, match=r"unsupported DATA 'binary_zstd' \(ascii, binary or b"):
        export.read_pcd(other)
    quad = tmp_path / "u1.pcd"
    quad.write_text(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 1\nTYPE F F F U\n"
        "COUNT 1 1 1 4\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3 255 0 0 0\n"
    )
    with pytest.raises(ValueError, match=r"field 'rgb' of SIZE 1 COUNT 4, expected a packed"):
        export.read_pcd(quad)


def test_read_pcd_coordinate_of_count_2_is_named(tmp_path):
    """x, y or z of COUNT 2 failed in np.stack, 'all input arrays must have the same shape'
    (read_pcd, so load_cloud and view); it names the field, in any DATA."""
    two = _xyz_pcd(tmp_path / "x2.pcd", "1 2 3 4\n5 6 7 8\n", counts="2 1 1")
    with pytest.raises(ValueError, match=r"x2\.pcd: field 'x' of COUNT 2, expected a coordin"):
        export.read_pcd(two)
    z3 = _xyz_pcd(tmp_path / "z3.pcd", "", counts="1 1 3", mode="binary")
    z3.write_bytes(z3.read_bytes() + np.zeros(10, "<f4").tobytes())
    with pytest.raises(ValueError, match=r"z3\.pcd: field 'z' of COUNT 3, expected a coordin"):
        export.load_cloud(z3)


def test_read_pcd_field_of_count_0_has_no_values_as_pcl_reads_it(tmp_path):
    """A field of COUNT 0 has no values (PCL's reader drops it): binary data was read as if it
    had one, the second point [5, 6, 0] for [4, 5, 6]; ASCII failed, 'could not broadcast'."""
    rows = _xyz_pcd(tmp_path / "a.pcd", "1 2 3\n4 5 6\n", fields="x y z n", counts="1 1 1 0")
    assert export.read_pcd(rows)[0].tolist() == [[[1, 2, 3], [4, 5, 6]]]
    flat = _xyz_pcd(tmp_path / "b.pcd", "", fields="x y z n", counts="1 1 1 0", mode="binary")
    flat.write_bytes(flat.read_bytes() + np.arange(1, 7, dtype="<f4").tobytes() + bytes(64))
    assert export.read_pcd(flat)[0].tolist() == [[[1, 2, 3], [4, 5, 6]]]


def test_read_pcd_without_count_and_in_lower_case(tmp_path):
    """COUNT is optional (1 per field) and the header's keywords are read in any case."""
    path = tmp_path / "c.pcd"
    path.write_text(
        "# .PCD v0.7\nversion 0.7\nfields x y z rgb\nsize 4 4 4 4\ntype F F F U\nwidth 2\n"
        f"height 1\npoints 2\ndata ascii\n1 2 3 {0xFF0000}\n4 5 6 {0x0A141E}\n"
    )
    pts, cols = export.read_pcd(path)
    assert pts.reshape(-1, 3).tolist() == [[1, 2, 3], [4, 5, 6]]
    assert cols.reshape(-1, 3).tolist() == [[255, 0, 0], [10, 20, 30]]


def test_npz_bundle_keeps_the_left_camera_and_the_range(result, tmp_path):
    """K is the left camera's (the frame of the points), not the right one's; a fractional
    range stays fractional; without calibration baseline and doffs are NaN, not 0."""
    c = syn.calibration()
    K2 = c.K2.copy()
    K2[0, 2] += 4.5
    right_moved = replace(result, calibration=replace(c, K2=K2), max_disparity=37.5)
    data = export.read_npz(export.write_npz(tmp_path / "k.npz", right_moved))
    np.testing.assert_array_equal(data["K"], c.K1)
    assert data["max_disparity"] == 37.5
    data = export.read_npz(export.write_npz(tmp_path / "w.npz", result))
    assert data["max_disparity"] == 16 and isinstance(data["max_disparity"], int)
    bare = replace(result, depth=None, depth_sigma=None, calibration=None)
    data = export.read_npz(export.write_npz(tmp_path / "b.npz", bare))
    assert math.isnan(data["baseline"]) and math.isnan(data["doffs"])


def test_foreign_bundle_without_k_or_with_a_nan_in_k(tmp_path):
    np.savez(tmp_path / "d.npz", depth=np.ones((2, 2)))
    with pytest.raises(ValueError, match=r"d\.npz: not a stereovision depth bundle \(needs"):
        export.read_npz(tmp_path / "d.npz")
    k = np.array([[100.0, 0, np.nan], [0, 100, 1], [0, 0, 1]])
    np.savez(tmp_path / "n.npz", depth=np.ones((2, 2)), K=k)
    with pytest.raises(ValueError, match=r"n\.npz: a depth bundle without calibration"):
        export.load_cloud(tmp_path / "n.npz")


def test_load_cloud_of_a_folder_and_an_upper_case_ply(tmp_path):
    # read_pcd and read_npz said "file not found" of a folder, as if the path were wrong
    for read in (export.load_cloud, export.read_pcd, export.read_npz):
        with pytest.raises(ValueError, match=r"^not a file: "):
            read(tmp_path)
    (tmp_path / "SCAN.PLY").write_bytes(b"\x89PNG not a ply")
    with pytest.raises(ValueError, match=r"not a PLY file: .*SCAN\.PLY"):
        export.load_cloud(tmp_path / "SCAN.PLY")


def test_cloud_readers_name_a_link_whose_target_moved_or_loops(tmp_path):
    """read_pcd, read_npz and load_cloud said only "PCD file not found: cloud.pcd" of a link
    whose target moved (a cloud linked in from a folder since moved), a name ls lists; they
    name its target now, as io's readers do, and a loop of links as one."""
    (tmp_path / "cloud.pcd").symlink_to(tmp_path / "moved" / "cloud.pcd")
    (tmp_path / "a.ply").symlink_to("b.ply")
    (tmp_path / "b.ply").symlink_to("a.ply")
    for read, what in (
        (export.read_pcd, "PCD file"),
        (export.read_npz, "npz file"),
        (export.load_cloud, "point cloud file"),
    ):
        with pytest.raises(FileNotFoundError) as exc:
            read(tmp_path / "cloud.pcd")
        assert str(exc.value) == (
            f"{what} not found: {tmp_path}/cloud.pcd (a link to {tmp_path}/moved/cloud.pcd, "
            "which does not exist)"
        )
        with pytest.raises(FileNotFoundError, match=r"a\.ply \(a link to b\.ply, one of a loop"):
            read(tmp_path / "a.ply")


def test_voxel_downsample_keeps_white_and_drops_partly_nan_points():
    pts = np.array([[0.01, 0.01, 0.01], [0.02, 0.02, 0.02], [np.nan, 0.01, 0.01]])
    cols = np.array([[255.0, 255, 255], [255, 253, 0], [0, 0, 0]])
    down, dc = export.voxel_downsample(pts, cols, voxel=0.1)
    np.testing.assert_allclose(down, [[0.015, 0.015, 0.015]], rtol=1e-6)
    assert dc.tolist() == [[255, 254, 128]]  # 127.5 rounds to even


def test_depth_png_warning_and_suffix(tmp_path):
    """The all-0 warning points at the caller's line and only comes when nothing fits; a
    16-bit image is refused under another suffix than .png."""
    import warnings

    with pytest.warns(UserWarning, match=r"4 beyond 65.535 m, .* \(depths are in metres\)") as rec:
        export.write_depth_png(tmp_path / "mm.png", np.full((2, 2), 1500.0))
    assert rec[0].filename == __file__
    with pytest.warns(UserWarning, match="none of its 4 values") as rec:
        export.encode_depth_png(np.full((2, 2), 1500.0))
    assert rec[0].filename == __file__
    with pytest.warns(UserWarning, match="disparity: none of its 4 values") as rec:
        export.write_disparity_png(tmp_path / "wide.png", np.full((2, 2), 300.0))
    assert rec[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        export.write_depth_png(tmp_path / "far.png", np.array([[1.0, 70.0]]))
    assert export.read_depth_png(tmp_path / "far.png")[0, 0] == 1.0
    for name in ("d.tiff", "d.jpg", "d"):
        with pytest.raises(ValueError, match=r"a 16-bit depth image is written as \.png"):
            export.write_depth_png(tmp_path / name, np.ones((2, 2)))
        assert not (tmp_path / name).exists()


def test_export_result_formats_as_one_string_is_named(result, tmp_path):
    """``formats="ply"`` was split into letters: "unknown export format(s) ['l', 'p', 'y']"
    (and nothing written); the string is named, with the tuple to give instead."""
    with pytest.raises(TypeError) as info:
        export.export_result(result, tmp_path / "out", "ply")
    assert str(info.value) == (
        "formats: expected a tuple of format names, got the string 'ply' (give ('ply',))"
    )
    assert not (tmp_path / "out").exists()


def test_export_result_formats_as_bytes_are_named(result, tmp_path):
    """``formats=b"ply"`` was taken byte by byte: "unknown export format(s) [108, 112, 121]".
    Bytes are refused as one string is, named, with the tuple to give when they spell a
    format; nothing is written."""
    for bad, hint in (
        (b"ply", "give ('ply',)"),
        (bytearray(b"npz"), "give ('npz',)"),
        (b"xyz", "e.g. ('ply', 'npz')"),
        (b"\xff", "e.g. ('ply', 'npz')"),
    ):
        with pytest.raises(TypeError) as info:
            export.export_result(result, tmp_path / "out", bad)
        assert str(info.value) == (
            f"formats: expected a tuple of format names, got the bytes {bytes(bad)!r} ({hint})"
        )
    assert not (tmp_path / "out").exists()


def test_export_result_formats_given_once_through_are_all_written(result, tmp_path):
    """Formats given as a generator (or any iterator) were used up by the check of their names,
    so nothing was written and ``{}`` returned, the folder made empty, without a word; they
    are written as a tuple of them is. Formats that are no collection of names are named."""
    wanted = ("npz", "disp16")
    written = export.export_result(result, tmp_path / "gen", (f for f in wanted))
    assert sorted(written) == ["depth.npz", "disparity_16.png"]
    assert sorted(p.name for p in (tmp_path / "gen").iterdir()) == sorted(written)
    assert written == export.export_result(result, tmp_path / "gen", wanted)
    for bad in (None, 3):
        with pytest.raises(TypeError) as info:
            export.export_result(result, tmp_path / "bad", bad)
        assert str(info.value) == (
            f"formats: expected a tuple of format names, got {bad!r} (e.g. ('ply', 'npz'))"
        )
    assert not (tmp_path / "bad").exists()


def test_export_result_names_formats_that_are_no_names(result, tmp_path):
    """A format that is no name was Python's own error, naming no argument: a list among them
    (``[["ply"]]``) "unhashable type: 'list'", two unknown ones of different types
    (``("x", 3)``) "'<' not supported between instances of 'int' and 'str'" from the sort of
    the error's own list. Each is an unknown format, named, and nothing is written."""
    expected = f"expected {list(export.EXPORT_FORMATS)}"
    for bad, shown in (([["ply"]], "[['ply']]"), (("ply", "x", 3, "x"), "['x', 3]")):
        with pytest.raises(ValueError) as info:
            export.export_result(result, tmp_path / "bad", bad)
        assert str(info.value) == f"unknown export format(s) {shown}: {expected}"
    with pytest.raises(ValueError) as info:  # as before for names alone
        export.export_result(result, tmp_path / "bad", ("PLY", "npz", "Ply"))
    assert str(info.value) == f"unknown export format(s) ['PLY', 'Ply']: {expected}"
    assert not (tmp_path / "bad").exists()


def test_pcd_without_the_comment_line_and_with_signed_colours(tmp_path):
    """A PCD may start at VERSION (the comment line is optional); a ``TYPE I`` colour holds
    the bits as a signed integer (opaque red 0xFFFF0000 is -65536)."""
    path = tmp_path / "i.pcd"
    path.write_text(
        "VERSION 0.7\nFIELDS x y z rgba\nSIZE 4 4 4 4\nTYPE F F F I\nCOUNT 1 1 1 1\n"
        "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3 -65536\n4 5 6 -16116706\n"
    )
    pts, cols = export.load_cloud(path)
    assert pts.tolist() == [[1, 2, 3], [4, 5, 6]]
    assert cols.tolist() == [[255, 0, 0], [10, 20, 30]]  # -16116706 = 0xFF0A141E


def test_binary_pcd_with_bytes_after_its_points(tmp_path):
    """Bytes after the WIDTH x HEIGHT records (a closing newline) are not points."""
    path = _xyz_pcd(tmp_path / "b.pcd", "", mode="binary")
    path.write_bytes(path.read_bytes() + np.arange(6, dtype="<f4").tobytes() + b"\n")
    pts, cols = export.read_pcd(path)
    assert pts.tolist() == [[[0, 1, 2], [3, 4, 5]]] and cols is None


def test_ascii_pcd_rows_short_of_a_count_field(tmp_path):
    path = tmp_path / "c.pcd"
    path.write_text(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS uv x y z rgb\nSIZE 4 4 4 4 4\nTYPE F F F F U\n"
        "COUNT 2 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n0.5 1 2 3 0\n0.5 4 5 6 0\n"
    )
    with pytest.raises(ValueError, match=r"rows of 5 values, FIELDS has 6 \(with its COUNT\)$"):
        export.read_pcd(path)


def test_load_cloud_keeps_the_colours_of_a_cloud_without_nan(tmp_path):
    from stereovision.io import write_ply

    pts = np.array([[1, 2, 3], [4, 5, 6]], np.float32)
    cols = np.array([[255, 0, 0], [10, 20, 30]], np.uint8)
    back, back_cols = export.load_cloud(write_ply(tmp_path / "c.ply", pts, cols))
    np.testing.assert_array_equal(back, pts)
    np.testing.assert_array_equal(back_cols, cols)


def test_voxel_downsample_colour_shape_and_an_all_nan_cloud():
    pts = np.zeros((2, 3))
    with pytest.raises(ValueError, match=r"colors: expected shape \(2, 3\), got \(2, 4\)"):
        export.voxel_downsample(pts, np.zeros((2, 4), np.uint8))
    down, dc = export.voxel_downsample(np.full((2, 3), np.nan), np.zeros((2, 3), np.uint8))
    assert down.shape == (0, 3) and dc is not None and dc.shape == (0, 3)
    assert dc.dtype == np.uint8


def test_empty_png_is_not_a_png(tmp_path):
    (tmp_path / "e.png").write_bytes(b"")
    with pytest.raises(ValueError, match=r"e\.png: expected a single-channel 16-bit PNG, got not"):
        export.read_depth_png(tmp_path / "e.png")


def test_writers_make_nested_folders_and_return_paths(result, tmp_path):
    """export_result creates missing parent folders; every writer returns a Path for a str."""
    written = export.export_result(result, tmp_path / "a" / "b", ("npz",))
    assert written["depth.npz"] == tmp_path / "a" / "b" / "depth.npz"
    for write, name in (
        (export.write_cloud_ply, "c.ply"),
        (export.write_pcd, "c.pcd"),
        (export.write_npz, "d.npz"),
        (export.write_depth_png, "d.png"),
        (export.write_disparity_png, "p.png"),
    ):
        out = write(str(tmp_path / name), result)
        assert isinstance(out, type(tmp_path)) and out == tmp_path / name


def test_mesh_without_colours(tmp_path):
    """A mesh without point data ``RGB`` is written with x y z vertices only."""
    from stereovision.io import read_ply

    mesh = _fake_mesh([[0, 0, 1], [1, 0, 1], [0, 1, 2]], [3, 0, 1, 2])
    path = export.write_mesh_ply(tmp_path / "m.ply", mesh)
    assert b"property uchar red" not in path.read_bytes()[:400]
    pts, cols = read_ply(path)
    assert pts.tolist() == [[0, 0, 1], [1, 0, 1], [0, 1, 2]] and cols is None


def test_npz_bundle_types_and_refuses_pickles(result, tmp_path):
    """Maps are float32 whatever the result holds; an object array (a pickle, which could run
    code on load) is refused; a missing bundle is FileNotFoundError."""
    wide = replace(result, confidence=result.confidence.astype(np.float64))
    data = export.read_npz(export.write_npz(tmp_path / "w.npz", wide))
    assert data["confidence"].dtype == np.float32
    np.savez(tmp_path / "o.npz", depth=np.ones((2, 2)), K=np.eye(3), extra=np.array([{}]))
    with pytest.raises(ValueError, match=r"o\.npz: its 'extra' holds Python objects \(a pickle"):
        export.read_npz(tmp_path / "o.npz")
    with pytest.raises(FileNotFoundError, match=r"npz file not found: .*none\.npz"):
        export.read_npz(tmp_path / "none.npz")


@pytest.mark.parametrize(
    ("voxel", "shown"),
    [("0.05", "'0.05'"), (None, "None"), ([0.05], r"\[0.05\]"), (10**400, "an integer of 401 d")],
    ids=["str", "None", "list", "10**400"],
)
def test_voxel_that_is_not_a_number_is_named(voxel, shown):
    """A string, None or a list failed inside numpy ("ufunc 'isfinite' not supported for the
    input types", naming no argument), as did an int too large for a float."""
    with pytest.raises(ValueError, match=rf"^voxel: expected a positive cube side, got {shown}"):
        export.voxel_downsample(np.zeros((3, 3)), voxel=voxel)


def test_voxel_takes_any_real_number():
    """A Fraction failed in numpy's isfinite; ints and numpy scalars work as floats do."""
    pts = np.array([[0.01, 0.0, 0.0], [0.04, 0.0, 0.0], [0.06, 0.0, 0.0]])
    for voxel in (Fraction(1, 20), 0.05, np.float32(0.05)):
        down, _ = export.voxel_downsample(pts, voxel=voxel)
        np.testing.assert_allclose(down, [[0.025, 0, 0], [0.06, 0, 0]], rtol=1e-6)
    assert len(export.voxel_downsample(pts, voxel=1)[0]) == 1


def test_pcd_of_a_result_with_a_grey_left_image(result, tmp_path):
    """A grey (H, W) left image: organised_points gave it mirrored (``[..., ::-1]`` reversed
    its columns) as (H, W) colours and write_pcd failed with NumPy's "could not broadcast";
    as write_cloud_ply (and the ROS bag writer) do, the cloud's own colours are used."""
    from stereovision.io import read_ply

    grey = replace(result, left_rectified=result.left_rectified[..., 1].copy())
    pts, cols = export.read_pcd(export.write_pcd(tmp_path / "g.pcd", grey))
    x, y = result.pixels[:, 0], result.pixels[:, 1]
    np.testing.assert_array_equal(pts[y, x], result.points)
    np.testing.assert_array_equal(cols[y, x], result.colors)
    _, ply_cols = read_ply(export.write_cloud_ply(tmp_path / "g.ply", grey))
    np.testing.assert_array_equal(ply_cols, result.colors)


def test_depth_png_scale_and_its_smallest_value(result, tmp_path):
    """encode_depth_png writes millimetres by default (the bytes write_depth_png writes); a
    result is written at the scale given; 1 mm (the value 1) reads back, only 0 is none."""
    z = np.array([[1.2344, 0.001, np.nan]])
    png = export.encode_depth_png(z)
    assert png == export.write_depth_png(tmp_path / "z.png", z).read_bytes()
    raw = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_UNCHANGED)
    assert raw.tolist() == [[1234, 1, 0]]
    back = export.read_depth_png(tmp_path / "z.png")
    assert back[0, 1] == np.float32(0.001) and np.isnan(back[0, 2])
    tum = export.write_depth_png(tmp_path / "tum.png", result, scale=5000)
    raw = cv2.imread(str(tum), cv2.IMREAD_UNCHANGED)
    assert raw[60, 80] == round(syn.BOX_Z * 5000) and raw[5, 150] == round(syn.WALL_Z * 5000)


@pytest.mark.parametrize(("scale", "metres"), [(1e-50, "1e+50 to 3e+50"), (1e39, "1e-39 to 3e-39")])
def test_a_depth_png_scale_past_float32_is_refused(tmp_path, scale, metres):
    """read_depth_png divides in float32: a scale of 1e-50 read every depth as inf, 1e39 as 0
    (on the camera), with NumPy's "divide by zero encountered" alone. Refused by name."""
    path = export.write_depth_png(tmp_path / "z.png", np.array([[0.001, 0.003], [np.nan, 0.002]]))
    with pytest.raises(ValueError) as err:
        export.read_depth_png(path, scale=scale)
    assert str(err.value) == (
        f"scale: {scale:g} units per metre makes the values 1 to 3 of {path} {metres} m, past "
        "a float32's range"
    )


def test_disparity_png_warning_does_not_speak_of_millimetres(tmp_path):
    with pytest.warns(UserWarning) as rec:
        export.write_disparity_png(tmp_path / "d.png", np.full((2, 2), 300.0))
    assert str(rec[0].message) == (
        "disparity: none of its 4 values fits 1..65535 at scale 256: 4 beyond 255.996, the most "
        "a 16-bit PNG holds at this scale: the image is all 0"
    )


def test_depths_too_far_for_the_png_are_not_said_to_be_millimetres(tmp_path):
    """Depths in metres past 65.535 m (a far scene, depth --max-disparity 1) were warned as
    '(a depth in metres is expected; millimetres given?)': what the values are is said now."""
    with pytest.warns(UserWarning) as rec:
        export.encode_depth_png(np.array([[100.0, 70.0], [np.nan, -1.0]]))
    assert str(rec[0].message) == (
        "depth: none of its 2 values fits 1..65535 at scale 1000: 2 beyond 65.535 m, the most "
        "a 16-bit PNG holds at this scale (depths are in metres): the image is all 0"
    )
    with pytest.warns(UserWarning) as rec:
        export.write_depth_png(tmp_path / "z.png", np.array([[0.0001, 100.0]]))
    assert str(rec[0].message) == (
        "depth: none of its 2 values fits 1..65535 at scale 1000: 1 beyond 65.535 m, the most "
        "a 16-bit PNG holds at this scale (depths are in metres); 1 rounding to 0 (under "
        "0.0005): the image is all 0"
    )


def test_a_depth_past_a_float_once_scaled_is_dropped_without_numpy_warning():
    """A float64 depth of 1e308 m (a disparity of 1e-306 px) times 1000 overflowed: NumPy's
    bare 'overflow encountered in multiply' came with the PNG; it is dropped (0) as any depth
    too far for 16 bits, the others written."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        data = export.encode_depth_png(np.array([[1e308, 2.0]]))
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    assert img.tolist() == [[0, 2000]]


def test_pcd_header_incomplete_or_not_terminated(tmp_path):
    path = _xyz_pcd(tmp_path / "h.pcd")
    path.write_text(path.read_text().replace("WIDTH 2\n", ""))
    with pytest.raises(ValueError, match=r"^PCD file .*h\.pcd: incomplete header$"):
        export.read_pcd(path)
    path.write_text("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4")
    with pytest.raises(ValueError, match=r"^not a PCD file \(header not terminated\): "):
        export.read_pcd(path)


def test_pcd_without_height_is_unorganised_as_pcl_reads_it(tmp_path):
    """PCL's reader takes a file without HEIGHT (PCD before 0.7) as unorganised, HEIGHT 1, and
    WIDTH as its POINTS when not given either: both were refused as an incomplete header."""
    path = _xyz_pcd(tmp_path / "h.pcd")
    path.write_text(path.read_text().replace("HEIGHT 1\n", ""))
    assert export.read_pcd(path)[0].tolist() == [[[1, 2, 3], [4, 5, 6]]]
    path.write_text(path.read_text().replace("WIDTH 2\n", ""))
    assert export.read_pcd(path)[0].tolist() == [[[1, 2, 3], [4, 5, 6]]]
    # nor WIDTH, HEIGHT nor POINTS: incomplete still
    path.write_text(path.read_text().replace("POINTS 2\n", ""))
    with pytest.raises(ValueError, match=r"^PCD file .*h\.pcd: incomplete header$"):
        export.read_pcd(path)


def test_pcd_whose_points_are_not_width_by_height_is_refused(tmp_path):
    """POINTS 2 with WIDTH 3 (a cloud cropped, its WIDTH left): the third point was read from
    the bytes after the data (PCL pads its files to a page), a point (0, 0, 0) at the camera;
    PCL's reader refuses such a file, and so does read_pcd now, naming both counts."""
    path = _xyz_pcd(tmp_path / "m.pcd", "", w=3, mode="binary")
    path.write_bytes(
        path.read_bytes().replace(b"POINTS 3", b"POINTS 2")
        + np.array([[1, 2, 3], [4, 5, 6]], "<f4").tobytes()
        + bytes(4096)
    )
    with pytest.raises(
        ValueError, match=r"m\.pcd: WIDTH x HEIGHT is 3 x 1 = 3 points, POINTS says 2$"
    ):
        export.read_pcd(path)


def _lzf(data):
    """LZF as liblzf's lzf_compress writes it (greedy, for the tests' few bytes): literal runs
    of 1-32 bytes (control 0-31), back references of 3-264 bytes (LZF's reach: 8192 back)."""
    out, lit, i = bytearray(), bytearray(), 0

    def flush():
        while lit:
            out.append(len(lit[:32]) - 1)
            out.extend(lit[:32])
            del lit[:32]

    while i < len(data):
        best, back = 0, 0
        for start in range(max(0, i - 300), i):  # 300, not 8192 back: a fast test
            k = 0
            while i + k < len(data) and k < 264 and data[start + k] == data[i + k]:
                k += 1
            if k > best:
                best, back = k, i - start - 1
        if best < 3:
            lit.append(data[i])
            i += 1
            continue
        flush()
        n = best - 2
        out += bytes([7 << 5 | back >> 8, n - 7]) if n >= 7 else bytes([n << 5 | back >> 8])
        out.append(back & 0xFF)
        i += best
    flush()
    return bytes(out)


def test_pcd_binary_compressed_as_pcl_writes_it(tmp_path):
    """PCL's savePCDFileBinaryCompressed (DATA binary_compressed: sizes, then LZF of each
    field's values in turn) was refused, 'unsupported DATA'; it reads as the binary file."""
    n = 120  # repeated values: back references, long and overlapping ones
    pts = np.zeros((n, 3), np.float32)
    pts[:, 0] = np.arange(n) % 7
    pts[::5, 1] = np.nan
    pts[:, 2] = 2.5
    rgb = np.full(n, 0xFF0A141E, np.uint32)
    rgb[1::2] = 0xFFFF0000
    head = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z _ rgb\nSIZE 4 4 4 1 4\nTYPE F F F U U\n"
        f"COUNT 1 1 1 3 1\nWIDTH {n // 2}\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\n"
    )
    planes = b"".join(
        [pts[:, 0].tobytes(), pts[:, 1].tobytes(), pts[:, 2].tobytes(), bytes(3 * n), rgb.tobytes()]
    )
    lzf = _lzf(planes)
    assert len(lzf) < len(planes) // 4  # it did compress
    path = tmp_path / "c.pcd"
    body = np.array([len(lzf), len(planes)], "<u4").tobytes() + lzf
    path.write_bytes((head + "DATA binary_compressed\n").encode() + body)
    got, cols = export.read_pcd(path)
    np.testing.assert_array_equal(got, pts.reshape(2, n // 2, 3))
    assert cols.reshape(-1, 3)[:2].tolist() == [[10, 20, 30], [255, 0, 0]]
    assert export.load_cloud(path)[0].shape == (n - n // 5, 3)
    # a literal 'A' and 12 more from one byte back (the overlapping copy of liblzf)
    assert export._lzf_decompress(b"\x00A\xe0\x03\x00", 13, path) == b"A" * 13
    assert lzf_ref.lzf_decompress(b"\x00A\xe0\x03\x00", 13) == b"A" * 13
    sizes = np.array([2, len(planes)], "<u4").tobytes()
    for cut, word in (
        (body[:-1], "truncated"),
        (sizes + b"\x20\x05", "damaged"),  # a reference before the start
        (sizes + b"\x00A", "damaged"),  # 1 byte of 2280
    ):
        path.write_bytes((head + "DATA binary_compressed\n").encode() + cut)
        with pytest.raises(ValueError, match=rf"^{word} PCD file .*c\.pcd"):
            export.read_pcd(path)


def _terrace_planes(data_dir, rows, cols):
    """A real organised cloud as PCL's binary_compressed stores it before LZF: the x, y, z and
    packed rgb values of ETH3D terrace's ground-truth points (NaN in its holes), field by field."""
    from stereovision.io import read_pfm

    src = data_dir / "eth3d" / "terrace"
    d = read_pfm(src / "gt_disp.pfm")[rows, cols].astype(np.float32)
    bgr = cv2.imread(str(src / "left.png"))[rows, cols].astype(np.uint32)
    f, cx, cy, baseline = 711.499, 376.135, 227.447, 0.0599432
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(np.isfinite(d) & (d > 0), f * baseline / d, np.nan).astype(np.float32)
    ys, xs = np.mgrid[rows, cols]
    x, y = ((xs - cx) * z / f).astype(np.float32), ((ys - cy) * z / f).astype(np.float32)
    rgb = 0xFF000000 | bgr[..., 2] << 16 | bgr[..., 1] << 8 | bgr[..., 0]
    return b"".join(a.astype("<f4").tobytes() for a in (x, y, z)) + rgb.astype("<u4").tobytes()


def test_lzf_rust_decoder_matches_the_reference_on_a_real_cloud(data_dir, tmp_path):
    """read_pcd's LZF decoder (Rust, _core.lzf_decompress) gives the bytes of the Python
    reference (the decoder it replaced) on a real scene's cloud, and read_pcd its points."""
    rows, cols = slice(200, 240), slice(80, 160)  # a quarter of its points without depth
    planes = _terrace_planes(data_dir, rows, cols)
    lzf = lzf_ref.lzf_compress(planes)
    assert len(lzf) < len(planes) * 9 // 10  # back references, overlapping ones among them
    assert _core.lzf_decompress(lzf, len(planes)) == planes
    assert lzf_ref.lzf_decompress(lzf, len(planes)) == planes
    h, w = 40, 80
    head = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
        f"WIDTH {w}\nHEIGHT {h}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {w * h}\nDATA binary_compressed\n"
    )
    path = tmp_path / "terrace.pcd"
    path.write_bytes(head.encode() + np.array([len(lzf), len(planes)], "<u4").tobytes() + lzf)
    pts, cols_ = export.read_pcd(path)
    want = np.frombuffer(planes, "<f4", count=3 * h * w).reshape(3, h, w).transpose(1, 2, 0)
    np.testing.assert_array_equal(pts, want)
    assert np.isnan(pts[..., 2]).any() and np.isfinite(pts[..., 2]).any()
    bgr = cv2.imread(str(data_dir / "eth3d" / "terrace" / "left.png"))[rows, cols]
    np.testing.assert_array_equal(cols_, bgr[..., ::-1])


def test_lzf_damaged_streams_refused_as_the_reference_does(tmp_path):
    """Every damaged or cut stream the reference refuses is a ValueError of the Rust decoder
    too, and read_pcd's message names the file and what is wrong; a valid one decodes the same."""
    plain = bytes(range(40)) * 3 + bytes(60)
    good = lzf_ref.lzf_compress(plain)
    path = tmp_path / "bad.pcd"
    cases = [
        (b"\x20\x05", 3, "a back reference (control byte at 0) reaches 6 bytes back, 0 bytes"),
        (b"\x02abc", 2, "decompress to more than 2 bytes (control byte at 0)"),
        (b"\x05abc", 6, "end inside a literal run of 6 bytes (control byte at 0)"),
        (b"\x00A\xe0", 13, "end inside a back reference (control byte at 2)"),
        (b"\x00A\xe0\x03", 13, "end inside a back reference (control byte at 2)"),
        (b"\x00A", 3, "decompress to 1 bytes, expected 3"),
        (good[:-1], len(plain), "end inside a back reference (control byte at 47)"),
        (good, len(plain) + 1, "expected 181"),
        (b"\x00A", 2**32 - 1, "2 bytes cannot decompress to 4294967295 bytes (at most 88 times"),
    ]
    for data, size, words in cases:
        with pytest.raises(ValueError):
            lzf_ref.lzf_decompress(data, size)
        with pytest.raises(ValueError, match=re.escape(words)):
            _core.lzf_decompress(data, size)
        with pytest.raises(
            ValueError,
            match=rf"^damaged PCD file .*bad\.pcd: its compressed data does not decompress "
            rf"\(corrupt LZF data: .*{re.escape(words)}",
        ):
            export._lzf_decompress(data, size, path)
    # every cut of a valid stream: refused by both, or (cut between chunks) too short
    for end in range(len(good)):
        with pytest.raises(ValueError):
            lzf_ref.lzf_decompress(good[:end], len(plain))
        with pytest.raises(ValueError, match="corrupt LZF data"):
            _core.lzf_decompress(good[:end], len(plain))
    assert _core.lzf_decompress(good, len(plain)) == plain


def test_read_npz_of_a_npy_file_is_named(tmp_path):
    """np.load gives a .npy file's array, not a bundle: read_npz failed with "'numpy.ndarray'
    object does not support the context manager protocol"."""
    np.save(tmp_path / "d.npy", np.ones((2, 2)))
    with pytest.raises(ValueError, match=r"^not an \.npz bundle \(or a damaged one\): .*d\.npy$"):
        export.read_npz(tmp_path / "d.npy")


def test_encode_depth_png_of_a_whole_result_is_named(result):
    """write_depth_png takes a result; encode_depth_png (its bytes, for a map) failed with
    "float() argument must be a string or a real number, not 'DepthResult'"."""
    with pytest.raises(TypeError, match=r"^depth: got a DepthResult; pass its array, result\.dep"):
        export.encode_depth_png(result)
    assert export.encode_depth_png(result.depth) == export.encode_depth_png(
        np.asarray(result.depth, np.float64)
    )


@pytest.mark.parametrize("channels", [4, 1])
def test_pcd_of_a_result_with_a_bgra_or_one_channel_left_image(result, tmp_path, channels):
    """A BGRA left image (surface_mesh takes one, its alpha dropped) gave organised_points
    (H, W, 4) colours, alpha first (``[..., ::-1]``), and an (H, W, 1) one (H, W, 1) colours:
    write_pcd failed with NumPy's "could not broadcast" on both. BGRA's colours are its BGR in
    RGB; a one-channel image is grey, the cloud's own colours are used (as a (H, W) one)."""
    bgr = result.left_rectified
    left = np.dstack([bgr, np.full(bgr.shape[:2], 7, np.uint8)]) if channels == 4 else bgr[..., 1:2]
    other = replace(result, left_rectified=left.copy())
    _, cols = export.organised_points(other)
    assert cols.shape == (*bgr.shape[:2], 3)
    pts, cols = export.read_pcd(export.write_pcd(tmp_path / "c.pcd", other))
    x, y = result.pixels[:, 0], result.pixels[:, 1]
    np.testing.assert_array_equal(pts[y, x], result.points)
    np.testing.assert_array_equal(cols[y, x], result.colors)


def test_mutation_audit_3_export_survivors(result, tmp_path):
    """A further mutation audit found unasserted: depths that all round to 0 mm (a map in
    kilometres) warned about like ones past 65535 (a 0 counted as fitting passed), an
    uncalibrated result's disparity PNG and its export (a writer reading the result only with a
    calibration passed), and voxel_downsample's cube key (y's extent taken as x's, or z's left
    out of the int64 check, merged distinct cubes)."""
    with pytest.warns(UserWarning, match="none of its 2 values fits 1..65535 at scale 1000"):
        export.encode_depth_png(np.array([[0.0001, 0.0004]]))
    bare = replace(result, depth=None, depth_sigma=None, calibration=None)
    written = export.export_result(bare, tmp_path / "bare", formats=("disp16", "npz"))
    disp = export.read_disparity_png(written["disparity_16.png"])
    expect = np.where((bare.disparity > 1 / 512) & (bare.disparity < 255.99), bare.disparity, 0)
    np.testing.assert_allclose(np.nan_to_num(disp), np.rint(expect * 256) / 256)
    # x all in one cube: y's extent 2, z's 2 (x's extent 1 for y merged (0, 1, 0) and (0, 0, 1))
    pts = np.array([[0.5, 0.5, 0.5], [0.5, 1.5, 0.5], [0.5, 0.5, 1.5]])
    assert len(export.voxel_downsample(pts, voxel=1.0)[0]) == 3
    # 2**22 x 2**22 x (2**20 + 1) cubes: a key without z's extent wrapped (0, 0, 2**20) to 0
    far = np.array([[0.5, 0.5, 0.5], [2**22 - 0.5, 2**22 - 0.5, 0.5], [0.5, 0.5, 2**20 + 0.5]])
    assert len(export.voxel_downsample(far, voxel=1.0)[0]) == 3


def test_mutation_audit_3_export_survivors_bis(result, tmp_path):
    """More unasserted behaviour: a result with depths but no calibration (as replace() makes
    one) refused as a cloud, points reaching past 2**62 voxels refused (a bound of 2**63 let the
    int64 cube indices overflow), and a file opening with 'PK' but not a zip's 'PK\\x03\\x04'
    named as no point cloud (not as a damaged bundle)."""
    no_calib = replace(result, calibration=None)
    assert no_calib.depth is not None
    for write in (export.write_cloud_ply, export.write_pcd):
        with pytest.raises(ValueError, match="depth_map was called without a calibration"):
            write(tmp_path / "c.out", no_calib)
    with pytest.raises(
        ValueError, match=re.escape("voxel: 1.0 is too small for points reaching 5e+18")
    ):
        export.voxel_downsample(np.array([[-5e18, 0.0, 0.0], [5e18, 0.0, 0.0]]), voxel=1.0)
    # points / side past a float's range: the farthest point named, not 'reaching inf'
    with pytest.raises(
        ValueError, match=re.escape("voxel: 1e-300 is too small for points reaching 1e+30")
    ):
        export.voxel_downsample(np.array([[1e30, 0.0, 0.0], [0.0, 0.0, 0.0]]), voxel=1e-300)
    # a coordinate past float32 came out as an inf point, NumPy's overflow warning alone
    with pytest.raises(ValueError) as err:
        export.voxel_downsample(np.array([[1e39, 0.0, 0.0], [1.0, 1.0, 1.0]]), voxel=1e30)
    assert str(err.value) == (
        "points: 1 finite value(s) beyond float32's range (e.g. 1e+39) would come out as inf "
        "(the points are float32)"
    )
    pk = tmp_path / "cloud.bin"
    pk.write_bytes(b"PKnot a zip at all")
    with pytest.raises(ValueError, match=re.escape("not a point cloud file (PLY, PCD or NPZ)")):
        export.load_cloud(pk)


def test_voxel_downsample_warns_of_a_side_larger_than_the_cloud(result):
    """A cube side in mm (50 for 5 cm) against points in metres left the cloud a few points
    without a word; now it warns naming the side, the cloud's extent and the unit. A coarse
    but plausible grid (50 cm: under 1 % of the points) and a small cloud stay quiet."""
    import warnings

    pts = result.points[np.isfinite(result.points).all(axis=1)]
    with pytest.warns(UserWarning) as seen:
        down, _ = export.voxel_downsample(pts, voxel=50)
    said = str(seen[0].message)
    assert said.startswith("voxel: a cube side of 50 is larger than the cloud's extent, "), said
    assert "(in the points' unit: metres for depth_map's points)" in said
    assert said.endswith(
        f"it leaves {len(down)} of {len(pts)} points; give the side in the "
        "points' unit; 0.05 if 50 was in mm"
    ), said
    extent = float(said.split("extent, ")[1].split(" ")[0])
    assert 3 < extent < 5, said  # the scene is about 4 m across
    assert seen[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(export.voxel_downsample(pts, voxel=0.5)[0]) < 0.01 * len(pts)
        export.voxel_downsample(pts[:99], voxel=50)
        export.voxel_downsample(np.zeros((5, 3)), voxel=1.0)  # only duplicates merged


def test_mutation_audit_4_pcd_edges_and_the_16_bit_limit(tmp_path):
    """A mutation audit of the exporters found unasserted: a binary PCD one byte short of its
    records (read by numpy's "buffer is smaller than requested size" when the length check was
    off by one), an ASCII ``TYPE F`` colour written as the float itself whose value is an
    integer of 2**32 or more (taken as the integer's bits, it wrapped to black), and a depth
    that rounds to 65536 mm (kept as fitting 16 bits, it wrapped to 0 without the warning)."""
    head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
    short = tmp_path / "short.pcd"
    short.write_bytes(
        (head + "POINTS 2\nDATA binary\n").encode() + np.arange(6, dtype="<f4").tobytes()[:-1]
    )
    with pytest.raises(ValueError, match=r"truncated PCD file .*: expected 2 points$"):
        export.read_pcd(short)
    # 0x4F800000 (alpha 0x4F, red 0x80) is the float 2**32: an integer, but not the bits
    big = tmp_path / "big.pcd"
    big.write_text(
        "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
        "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3 4294967296\n4 5 6 4.2949673e+09\n"
    )
    pts, cols = export.read_pcd(big)
    assert pts.tolist() == [[[1, 2, 3], [4, 5, 6]]]
    assert cols.tolist() == [[[128, 0, 0], [128, 0, 0]]]
    with pytest.warns(UserWarning, match="none of its 1 values fits 1..65535 at scale 1000"):
        png = export.encode_depth_png(np.array([[65.5355]]))  # 65535.5 mm rounds to 65536
    assert cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_UNCHANGED).tolist() == [[0]]


@pytest.mark.parametrize("writer", ["ply", "mesh", "pcd", "npz", "depth16", "disp16"])
def test_a_disk_full_half_way_keeps_the_previous_file(result, tmp_path, writer):
    """Every writer replaces its file atomically: when the disk fills half-way (here a file
    size limit of half the file, so the write itself fails with EFBIG), the previous file is
    left byte for byte and no temporary file stays. A mutation audit found write_npz and the
    16-bit PNG writers' atomicity unasserted (opening the file itself, they emptied the
    previous one)."""
    import signal

    resource = pytest.importorskip("resource")  # POSIX: file size limits
    mesh = _grid_mesh(400) if writer == "mesh" else None
    writers = {
        "ply": lambda p: export.write_cloud_ply(p, result),
        "mesh": lambda p: export.write_mesh_ply(p, mesh),
        "pcd": lambda p: export.write_pcd(p, result),
        "npz": lambda p: export.write_npz(p, result),
        "depth16": lambda p: export.write_depth_png(p, result),
        "disp16": lambda p: export.write_disparity_png(p, result),
    }
    path = tmp_path / ("out.png" if writer.endswith("16") else "out.bin")
    writers[writer](path)
    before = path.read_bytes()
    path.write_bytes(before[::-1])  # a previous file that the new one would differ from
    previous = path.read_bytes()
    old_limit = resource.getrlimit(resource.RLIMIT_FSIZE)
    old_handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG, not a killed process
    try:
        resource.setrlimit(resource.RLIMIT_FSIZE, (len(before) // 2, old_limit[1]))
        with pytest.raises(OSError, match="File too large"):
            writers[writer](path)
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, old_limit)
        signal.signal(signal.SIGXFSZ, old_handler)
    assert path.read_bytes() == previous
    assert [p.name for p in tmp_path.iterdir()] == [path.name]
    writers[writer](path)  # and a write that fits replaces it
    assert path.read_bytes() == before


def test_the_voxel_warning_starts_at_the_clouds_extent():
    """The warning is for a cube side past the cloud's 1-99 % extent (0.98 for points spread
    over a unit cube), not only for one past twice it (a mutation audit found the threshold
    unasserted between the two): 1.5 warns, 0.9 does not."""
    import warnings

    pts = np.random.default_rng(0).random((1000, 3))
    with pytest.warns(UserWarning, match=r"a cube side of 1\.5 is larger than the cloud's extent"):
        out, _ = export.voxel_downsample(pts, voxel=1.5)
    assert len(out) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out, _ = export.voxel_downsample(pts, voxel=0.9)
    assert len(out) == len(np.unique(np.floor(pts / 0.9), axis=0))  # 7 of 2 x 2 x 2 cubes


def test_export_result_refused_writes_nothing(result, tmp_path):
    """A result without calibration asked for ("npz", "ply") replaced the folder's good
    depth.npz by an all-NaN bundle, then raised at "ply"; a folder where cloud.pcd goes was
    found after cloud.ply had been replaced. Both are refused before any file is written."""
    out = tmp_path / "out"
    export.export_result(result, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    bare = replace(result, depth=None, depth_sigma=None, calibration=None)
    with pytest.raises(ValueError, match="without a calibration") as err:
        export.export_result(bare, out, ("npz", "disp16", "ply"))
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert np.isfinite(export.read_npz(out / "depth.npz")["depth"]).any()
    assert "formats ['ply'] need one" in str(err.value)
    # nor is a folder made for a refused call
    with pytest.raises(ValueError, match=r"formats \['depth16'\]"):
        export.export_result(bare, tmp_path / "new", ("disp16", "depth16"))
    assert not (tmp_path / "new").exists()
    # a folder in the way of a later format: the earlier ones are not replaced either
    (out / "cloud.pcd").unlink()
    (out / "cloud.pcd").mkdir()
    stale = out / "cloud.ply"
    stale.write_bytes(b"earlier")
    with pytest.raises(IsADirectoryError, match=r"cloud\.pcd: it is a folder"):
        export.export_result(result, out, ("ply", "pcd"))
    assert stale.read_bytes() == b"earlier"
    # the formats that need no calibration are still written for such a result
    written = export.export_result(bare, tmp_path / "bare", ("npz", "disp16"))
    assert sorted(written) == ["depth.npz", "disparity_16.png"]


@pytest.mark.parametrize(
    ("target", "error", "words"),
    [
        ("cloud.pcd", OSError, r"cloud\.pcd: it is a link that loops"),
        ("/nonexistent_sv/x/cloud.pcd", FileNotFoundError, r"directory /nonexistent_sv/x does not"),
    ],
)
def test_export_result_link_in_the_way_writes_nothing(result, tmp_path, target, error, words):
    """A link where a later format goes (one that loops, one into a missing folder) was found
    at that format's turn, after depth.npz and cloud.ply had been replaced: it is now refused
    before any file is written, as a folder in the way is."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "depth.npz").write_bytes(b"earlier npz")
    (out / "cloud.ply").write_bytes(b"earlier ply")
    link = out / "cloud.pcd"
    link.symlink_to(out / target if target == "cloud.pcd" else target)
    with pytest.raises(error, match=words):
        export.export_result(result, out, ("npz", "ply", "pcd"))
    assert (out / "depth.npz").read_bytes() == b"earlier npz"
    assert (out / "cloud.ply").read_bytes() == b"earlier ply"
    assert sorted(p.name for p in out.iterdir()) == ["cloud.pcd", "cloud.ply", "depth.npz"]


def test_mesh_ply_colours_float_0_1_and_out_of_range(tmp_path):
    """A uint8 cast made a mesh's 0-1 float colours (pyvista's) black, 0.5 grey became 0, and
    wrapped integers (300 came out 44, -1 255): floats are scaled from 0-1, and colours that do
    not fit are refused before anything is written."""
    from stereovision.io import read_ply

    pts = np.array([[0, 0, 1], [1, 0, 1], [0, 1, 1]], np.float32)
    mesh = _fake_mesh(pts, [3, 0, 1, 2])
    mesh.point_data["RGB"] = np.array([[1.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.2, 0.2, 1.0]])
    _, cols = read_ply(export.write_mesh_ply(tmp_path / "f.ply", mesh))
    np.testing.assert_array_equal(cols, [[255, 0, 0], [0, 128, 0], [51, 51, 255]])
    # integers 0-255 of a wider type, and RGBA, keep their values
    mesh.point_data["RGB"] = np.array([[255, 0, 7, 9], [0, 128, 0, 9], [1, 2, 3, 9]], np.int64)
    _, cols = read_ply(export.write_mesh_ply(tmp_path / "i.ply", mesh))
    np.testing.assert_array_equal(cols, [[255, 0, 7], [0, 128, 0], [1, 2, 3]])
    for bad, match in (
        (np.array([[300, 0, 0], [0, 0, 0], [-1, 0, 0]]), "colours 0-255, got values -1 to 300"),
        (np.array([[255.0, 0, 0], [0, 0, 0], [np.nan, 0, 0]]), "float colours are 0-1, got 2"),
    ):
        mesh.point_data["RGB"] = bad
        with pytest.raises(ValueError, match=match):
            export.write_mesh_ply(tmp_path / "bad.ply", mesh)
    assert not (tmp_path / "bad.ply").exists()


def test_mutation_audit_5_mesh_colours_and_export_pre_checks(result, tmp_path):
    """What the mutation audit of today's export changes found untested: a mesh RGB that is not
    (N, 3/4), negative integer colours alone, the point count of a point with two bad channels,
    pcd as the one metric format of a result without calibration, and an object that is no
    DepthResult: each refused before anything is written (nor a folder made)."""
    pts = np.array([[0, 0, 1], [1, 0, 1], [0, 1, 1]], np.float32)
    mesh = _fake_mesh(pts, [3, 0, 1, 2])
    for bad, match in (
        (np.zeros((3, 2), np.uint8), r"expected \(N, 3\) colours, got shape \(3, 2\)"),
        (np.array([[0, 0, 0], [0, -1, 0], [1, 2, 3]]), "colours 0-255, got values -1 to 3$"),
        (np.array([[2.0, 2.0, 0], [0, 0, 0], [0, 0, 0]]), "float colours are 0-1, got 1 point"),
    ):
        mesh.point_data["RGB"] = bad
        with pytest.raises(ValueError, match=match):
            export.write_mesh_ply(tmp_path / "bad.ply", mesh)
    assert not (tmp_path / "bad.ply").exists()
    bare = replace(result, depth=None, depth_sigma=None, calibration=None)
    with pytest.raises(ValueError, match=r"formats \['pcd'\] need one"):
        export.export_result(bare, tmp_path / "pcd", ("npz", "pcd"))
    assert not (tmp_path / "pcd").exists()
    with pytest.raises(TypeError, match=r"^result: expected a stereovision\.DepthResult, got str$"):
        export.export_result("depth.npz", tmp_path / "str", ("npz",))  # type: ignore[arg-type]
    assert not (tmp_path / "str").exists()


def test_export_entry_points_refuse_a_bytes_or_no_path_naming_the_argument(result, tmp_path):
    """read_pcd, load_cloud, write_pcd, write_depth_png, export_result ... given a bytes name (or
    None) raised pathlib's "argument should be a str object or an os.PathLike object returning
    str, not <class 'bytes'>", naming no argument: they now say it as io's readers do, before
    anything is written."""
    name = str(tmp_path / "a.ply")
    depth = np.ones((4, 4), np.float32)
    cases = [
        (lambda p: export.read_pcd(p), "path"),
        (lambda p: export.read_npz(p), "path"),
        (lambda p: export.load_cloud(p), "path"),
        (lambda p: export.write_cloud_ply(p, result), "path"),
        (lambda p: export.write_mesh_ply(p, None), "path"),
        (lambda p: export.write_pcd(p, result), "path"),
        (lambda p: export.write_npz(p, result), "path"),
        (lambda p: export.write_depth_png(p, depth), "path"),
        (lambda p: export.write_disparity_png(p, depth), "path"),
        (lambda p: export.export_result(result, p, ("npz",)), "directory"),
    ]
    for call, arg in cases:
        with pytest.raises(TypeError) as info:
            call(name.encode())
        assert str(info.value) == (
            f"{arg}: expected a str or os.PathLike file name, got the bytes {name!r}: decode "
            f"it first (os.fsdecode({arg}))"
        )
        with pytest.raises(TypeError) as info:
            call(None)
        assert str(info.value) == f"{arg}: expected a str or os.PathLike file name, got NoneType"
    assert not list(tmp_path.iterdir())  # nothing written


def test_mesh_ply_refuses_what_is_not_a_mesh(tmp_path):
    """A DepthResult, which the cloud writers take, failed in write_mesh_ply with
    "AttributeError: 'DepthResult' object has no attribute 'faces'"; it is a TypeError that
    says how to make the mesh, and nothing is written."""
    res = syn.depth_result()
    with pytest.raises(
        TypeError,
        match=r"mesh: expected a pyvista.PolyData triangle mesh, got "
        r"DepthResult: render.surface_mesh\(res\) makes its mesh",
    ):
        export.write_mesh_ply(tmp_path / "m.ply", res)
    with pytest.raises(
        TypeError,
        match=r"^mesh: expected a pyvista.PolyData triangle mesh, got "
        r"ndarray$",
    ):
        export.write_mesh_ply(tmp_path / "m.ply", np.zeros((3, 3)))
    assert not (tmp_path / "m.ply").exists()


def test_png_writers_name_swapped_arguments_and_a_file_name_for_the_map(result, tmp_path):
    """``write_depth_png(res, "d.png")`` (the arguments swapped) took the file name for the map:
    "could not convert string to float: 'd.png'", naming neither; the path is checked first, as
    the other writers do, and a file name given for the map is named. Nothing is written."""
    import warnings

    for writer in (export.write_depth_png, export.write_disparity_png):
        with pytest.raises(
            TypeError, match=r"^path: expected a str or os.PathLike file name, got DepthResult$"
        ):
            writer(result, str(tmp_path / "d.png"))
    for writer, name in (
        (export.write_depth_png, "depth"),
        (export.write_disparity_png, "disparity"),
    ):
        with pytest.raises(
            TypeError,
            match=rf"^{name}: expected an \(H, W\) array, got the file name 'm\.npy': read the "
            "map first$",
        ):
            writer(tmp_path / "d.png", "m.npy")
    with pytest.raises(TypeError, match=r"^depth: expected an \(H, W\) array, got the file name"):
        export.encode_depth_png(tmp_path / "m.npy")
    # the suffix is refused before the map is looked at: no all-0 warning first
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=r"a 16-bit depth image is written as \.png"):
            export.write_depth_png(tmp_path / "d.jpg", np.full((2, 2), 1500.0))
    assert list(tmp_path.iterdir()) == []


def test_read_pcd_says_a_coordinate_beyond_float32_in_words(tmp_path):
    """A PCD coordinate beyond float32's range (ASCII 1e39, a SIZE 8 double's) became inf with
    only NumPy's "overflow encountered in cast", naming no file; it is still inf (no point),
    said once naming the file."""
    import warnings

    head = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE {s} {s} {s}\nTYPE F F F\nCOUNT 1 1 1\n"
        "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA {mode}\n"
    )
    (tmp_path / "a.pcd").write_text(head.format(s=4, mode="ascii") + "1e39 0 1\n1.5 2 3\n")
    (tmp_path / "b.pcd").write_bytes(
        head.format(s=8, mode="binary").encode()
        + np.array([(1e39, 0, 1), (1.5, 2, 3)], "<f8").tobytes()
    )
    for name in ("a.pcd", "b.pcd"):
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            pts, _ = export.read_pcd(tmp_path / name)
        assert [str(w.message) for w in said] == [
            f"PCD file {tmp_path / name}: 1 point(s) with a coordinate beyond float32's range "
            "(e.g. 1e+39) read as inf (no point)"
        ]
        assert np.isinf(pts[0, 0, 0]) and pts[0, 1].tolist() == [1.5, 2, 3]


def test_read_npz_names_a_pickled_member_not_a_damaged_file(tmp_path):
    """A bundle with a member of Python objects (np.savez(..., meta={...}): a pickle, which
    allow_pickle=False does not load) is refused, as before, but was said to be 'not an .npz
    bundle (or a damaged one)' as a whole, in read_npz and load_cloud (view): the member is
    named, and what to do."""
    np.savez(tmp_path / "m.npz", depth=np.ones((2, 2)), K=np.eye(3), meta={"robot": "r1"})
    for read in (export.read_npz, export.load_cloud):
        with pytest.raises(ValueError) as exc:
            read(tmp_path / "m.npz")
        assert str(exc.value) == (
            f"{tmp_path / 'm.npz'}: its 'meta' holds Python objects (a pickle, not loaded: "
            "loading one can run code); save the bundle with numeric arrays only"
        )


def test_voxel_downsample_takes_float_colours_0_to_1_as_open3d_gives_them():
    """Open3D's colours (np.asarray(pcd.colors)) are floats 0-1: taken as 0-255 they averaged to
    0 or 1, a black cloud ([[1, 0, 0]] for orange), without a word. Floats all within 0-1 are
    scaled to 0-255 (as read_ply and write_mesh_ply take them); any above 1, 0-255 as before."""
    pts = np.array([[0.01, 0.01, 0.01], [0.02, 0.02, 0.02], [1.0, 1.0, 1.0]])
    rgb = np.array([[1.0, 0.5, 0.0], [1.0, 0.5, 0.0], [0.2, 0.4, 0.6]])
    for cols in (rgb, rgb.astype(np.float32), rgb * 255):
        _down, dc = export.voxel_downsample(pts, cols, voxel=0.1)
        assert dc is not None and dc.tolist() == [[255, 128, 0], [51, 102, 153]]


def test_an_ascii_pcd_or_ply_with_a_byte_order_mark_is_read(tmp_path):
    """An ASCII cloud saved by a Windows editor opens with a UTF-8 byte-order mark: read_pcd
    said 'not a PCD file', load_cloud 'not a point cloud file (PLY, PCD or NPZ)' (and of a
    .ply 'not a PLY file'); both read it as without the mark."""
    pcd = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
        "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3 4294901760\n4 5 6 4278255360\n"
    )
    ply = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
    ply += "property float z\nend_header\n7 8 9\n"
    (tmp_path / "c.pcd").write_bytes(b"\xef\xbb\xbf" + pcd.encode())
    (tmp_path / "c.ply").write_bytes(b"\xef\xbb\xbf" + ply.encode())
    pts, cols = export.read_pcd(tmp_path / "c.pcd")
    assert pts.tolist() == [[[1, 2, 3], [4, 5, 6]]] and cols.tolist() == [
        [[255, 0, 0], [0, 255, 0]]
    ]
    pts, cols = export.load_cloud(tmp_path / "c.pcd")
    assert pts.tolist() == [[1, 2, 3], [4, 5, 6]] and cols.tolist() == [[255, 0, 0], [0, 255, 0]]
    pts, cols = export.load_cloud(tmp_path / "c.ply")
    assert pts.tolist() == [[7, 8, 9]] and cols is None
