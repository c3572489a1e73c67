"""Export a depth result: coloured PLY (cloud or mesh), organised PCD, ``.npz`` bundle.

Conventions shared with pyvista, Open3D, MeshLab and PCL:

- PLY: ``binary_little_endian 1.0``; vertex ``float x, y, z`` + ``uchar red, green, blue``; mesh
  faces as ``list uchar int vertex_indices``. Metres, left rectified camera frame (X right, Y down,
  Z forward).
- PCD (PCL 0.7): ``FIELDS x y z rgb``, ``rgb`` packed into a float (``255 << 24 | r << 16 |
  g << 8 | b``: opaque, as ``pcl::PointXYZRGB`` writes it); the cloud keeps the image layout
  (``WIDTH`` = image width, ``HEIGHT`` = image height, row-major), pixels without depth are NaN
  points (``is_dense`` false).
- NPZ: ``depth``, ``disparity`` (H, W float32, NaN = none), ``confidence`` (H, W float32,
  0-1, 0 = none), ``K`` (3x3), ``baseline`` (metres), ``doffs`` (pixels), ``image_size``
  (W, H), ``method``, ``max_disparity`` (int64; float64 for a fractional range),
  ``min_disparity`` (float64), ``depth_sigma`` (H, W float32, metres, NaN = none).
- 16-bit PNG: depth in millimetres (ROS ``16UC1``, TUM RGB-D, Open3D), disparity times 256
  (KITTI); 0 = none.

Every writer replaces its file atomically (:func:`stereovision.io.atomic_write`).
"""

from __future__ import annotations

import io as _io
import math
import numbers
import os
import warnings
import zipfile
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, overload

import numpy as np
import numpy.typing as npt

from stereovision import _core
from stereovision._validate import (
    NO_DEPTH,
    NOT_NUMBERS,
    as_path,
    check_index_range,
    not_a_result,
    number_shown,
    refuse_beyond_float32,
    renamed_keyword,
    text_shown,
)
from stereovision._validate import require as _require_type

# at run time too, so that typing.get_type_hints resolves the public signatures
from stereovision.depth import DepthResult
from stereovision.io import (
    _UTF8_BOM,
    _ascii_table,
    _broken_link,
    _float32_coordinates,
    _through_links,
    _writable_destination,
    atomic_write,
    make_folder,
    read_ply,
    write_ply,
)

if TYPE_CHECKING:
    import pyvista as pv

__all__ = [
    "DEPTH_PNG_SCALE",
    "DISPARITY_PNG_SCALE",
    "EXPORT_FORMATS",
    "encode_depth_png",
    "export_result",
    "load_cloud",
    "organised_points",
    "read_depth_png",
    "read_disparity_png",
    "read_npz",
    "read_pcd",
    "voxel_downsample",
    "write_cloud_ply",
    "write_depth_png",
    "write_disparity_png",
    "write_mesh_ply",
    "write_npz",
    "write_pcd",
]

PathLike = str | os.PathLike[str]

#: Formats :func:`export_result` writes, with their file names.
EXPORT_FORMATS = {
    "ply": "cloud.ply",
    "pcd": "cloud.pcd",
    "npz": "depth.npz",
    "depth16": "depth_mm.png",
    "disp16": "disparity_16.png",
}

#: The :data:`EXPORT_FORMATS` that need a metric depth (a calibration).
_METRIC_FORMATS = ("ply", "pcd", "depth16")

_PCD_MAGIC = (b"# .PCD", b"VERSION")
_PLY_MAGIC = b"ply"
_ZIP_MAGIC = b"PK\x03\x04"


def _cloud_file(path: PathLike, what: str) -> Path:
    """``path`` as a file to read, else refused: ``"WHAT not found: P"``, or ``"not a file:
    P"`` for a folder (it was "not found", as if the path were wrong) or a FIFO.

    A link whose target moved (a cloud linked in from a folder since moved) was "not found"
    alone, of a name ``ls`` lists: its target is named, as :mod:`stereovision.io`'s readers
    name it (``(a link to X, which does not exist)``).
    """
    p = as_path(path, file=True)
    if not p.exists():
        gone = f" ({_broken_link(p)})" if p.is_symlink() else ""
        raise FileNotFoundError(f"{what} not found: {p}{gone}")
    if not p.is_file():
        raise ValueError(f"not a file: {p}")
    return p


def _require_metric(result: DepthResult) -> None:
    if result.depth is None or result.calibration is None:
        raise ValueError(NO_DEPTH.format(what="point cloud"))


def _check_left_size(result: DepthResult) -> None:
    """Refuse a ``left_rectified`` of another size than the disparity map's, where its pixels
    colour the cloud: a hand-made result (``dataclasses.replace`` with the raw left image, a
    scaled one) failed in NumPy's words, "could not broadcast input array from shape (4800,)
    into shape (19200,)" (write_pcd) or "index 4800 is out of bounds" (a cloud=False result's
    PLY)."""
    left = result.left_rectified
    h, w = result.disparity.shape[:2]
    if left is not None and left.ndim == 3 and left.shape[:2] != (h, w):
        raise ValueError(
            f"result.left_rectified: {left.shape[1]}x{left.shape[0]} px, expected the disparity "
            f"map's {w}x{h} (the rectified left image colours the cloud)"
        )


def organised_points(
    result: DepthResult,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8]]:
    """Image-shaped points and colours of ``result`` (NaN points where there is no depth).

    Parameters
    ----------
    result : DepthResult
        A :func:`stereovision.depth_map` result computed with a calibration.

    Returns
    -------
    points : ndarray, float32 (H, W, 3)
        Metres, left rectified camera frame; NaN where the pixel has no 3-D point.
    colors : ndarray, uint8 (H, W, 3)
        RGB of the left rectified image (BGR or BGRA); without a colour one (none, or grey),
        the cloud's colours at their pixels, zeros elsewhere.

    Raises
    ------
    ValueError
        If the result has no calibration, or its colour ``left_rectified`` is not the
        disparity map's size.
    """
    _require_type(result, "DepthResult", "result")
    _require_metric(result)
    _check_left_size(result)
    h, w = result.disparity.shape[:2]
    if len(result.points) == 0:  # computed with cloud=False: from the depth map
        pts = result.point_image()
    else:
        pts = np.full((h, w, 3), np.nan, dtype=np.float32)
        pts[result.pixels[:, 1], result.pixels[:, 0]] = result.points
    xs, ys = result.pixels[:, 0], result.pixels[:, 1]
    # a grey (H, W) left image has no channels to reverse ([..., ::-1] mirrored its columns),
    # an (H, W, 1) one no colour, and BGRA's alpha is none (as render.surface_mesh's texture)
    left = result.left_rectified
    if left is not None and left.ndim == 3 and left.shape[2] >= 3:
        cols = np.ascontiguousarray(left[..., 2::-1], dtype=np.uint8)
    else:
        cols = np.zeros((h, w, 3), np.uint8)
        cols[ys, xs] = result.colors
    return pts, cols


# ----------------------------------------------------------------------------- PLY


def write_cloud_ply(path: PathLike, result: DepthResult) -> Path:
    """Coloured point cloud of ``result`` as binary PLY (see the module conventions).

    Parameters
    ----------
    path : path
        File to write (atomically: an existing file is replaced only once the new one is whole).
    result : DepthResult
        A :func:`stereovision.depth_map` result computed with a calibration; one computed with
        ``cloud=False`` (as :func:`stereovision.stream.run_stream` gives them) is written with the
        cloud its depth map gives, the same points as with ``cloud=True``.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        If the result has no calibration (no metric points), or has no cloud of its own and a
        colour ``left_rectified`` of another size than its disparity map.
    """
    dest = as_path(path, file=True)
    _require_type(result, "DepthResult", "result")
    _require_metric(result)
    if len(result.points) == 0:  # its colours are then the left image's, pixel for pixel
        _check_left_size(result)
    # A cloud=False result (stream's) has no points of its own: the cloud from its depth map.
    points, colors = result._cloud_points()
    write_ply(dest, points, colors)
    return dest


def _mesh_rgb(rgb: npt.NDArray[Any]) -> npt.NDArray[np.uint8]:
    """A mesh's point data ``RGB`` as uint8 0-255: floats are 0-1 (pyvista's and VTK's colour
    scalars), integers 0-255. A plain uint8 cast made 0-1 floats black (0.5 became 0), 300
    came out 44 and -1 255, without a word."""
    if rgb.ndim != 2 or rgb.shape[1] not in (3, 4):
        raise ValueError(f"mesh RGB: expected (N, 3) colours, got shape {rgb.shape}")
    rgb = rgb[:, :3]
    if rgb.dtype == np.uint8:
        return rgb
    if rgb.dtype.kind == "f":
        bad = ~(np.isfinite(rgb) & (rgb >= 0) & (rgb <= 1))
        if bad.any():
            raise ValueError(
                f"mesh RGB: float colours are 0-1, got {int(bad.any(axis=1).sum())} point(s) "
                "outside (or NaN); give 0-255 colours as uint8"
            )
        return np.rint(rgb * 255.0).astype(np.uint8)
    if rgb.dtype.kind in "iu" and rgb.size and (rgb.min() < 0 or rgb.max() > 255):
        raise ValueError(f"mesh RGB: expected colours 0-255, got values {rgb.min()} to {rgb.max()}")
    if rgb.dtype.kind not in "iu":
        raise ValueError(f"mesh RGB: expected uint8 or 0-1 float colours, got {rgb.dtype}")
    return rgb.astype(np.uint8)


def write_mesh_ply(path: PathLike, mesh: pv.PolyData) -> Path:
    """Triangle mesh with per-vertex colours as binary PLY (MeshLab / Open3D / pyvista readable).

    Parameters
    ----------
    path : path
    mesh : pyvista.PolyData
        E.g. :func:`stereovision.render.surface_mesh`; triangles only; colours from point data
        ``"RGB"`` when present (uint8 0-255, or floats 0-1 as pyvista takes them).

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    TypeError
        If ``mesh`` is not a mesh (no points, faces and point data), e.g. a DepthResult.
    ValueError
        If the mesh has non-triangle faces, colours outside 0-255 (0-1 for floats), or finite
        vertex coordinates beyond float32's range (they would become inf).
    """
    dest = as_path(path, file=True)
    if not all(hasattr(mesh, a) for a in ("points", "faces", "point_data")):
        # a DepthResult (which write_ply, write_pcd and write_npz take) failed with
        # "AttributeError: 'DepthResult' object has no attribute 'faces'"
        hint = (
            ": render.surface_mesh(res) makes its mesh, write_cloud_ply(path, res) writes its cloud"
            if isinstance(mesh, DepthResult)
            else ""
        )
        raise TypeError(
            f"mesh: expected a pyvista.PolyData triangle mesh, got {type(mesh).__name__}{hint}"
        )
    pts = np.asarray(mesh.points)
    # a float64 vertex past float32's range was written as inf, NumPy's overflow warning alone
    # (write_ply's check, 3581344)
    refuse_beyond_float32(pts, "mesh.points", "would be written as inf")
    pts = pts.astype(np.float32, copy=False)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    if faces.size % 4 or (faces.size and (faces.reshape(-1, 4)[:, 0] != 3).any()):
        raise ValueError("write_mesh_ply: only triangle meshes are supported")
    tris = faces.reshape(-1, 4)[:, 1:].astype("<i4")
    has_rgb = "RGB" in mesh.point_data
    vfields: list[tuple[str, str]] = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    header = [
        "ply",
        "format binary_little_endian 1.0",
        "comment stereovision surface mesh (metres, X right, Y down, Z forward)",
        f"element vertex {len(pts)}",
        "property float x",
        "property float y",
        "property float z",
    ]
    if has_rgb:
        vfields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
        header += ["property uchar red", "property uchar green", "property uchar blue"]
    header += [f"element face {len(tris)}", "property list uchar int vertex_indices", "end_header"]
    vert = np.empty(len(pts), dtype=np.dtype(vfields))
    vert["x"], vert["y"], vert["z"] = pts[:, 0], pts[:, 1], pts[:, 2]
    if has_rgb:
        rgb = _mesh_rgb(np.asarray(mesh.point_data["RGB"]))
        vert["red"], vert["green"], vert["blue"] = rgb[:, 0], rgb[:, 1], rgb[:, 2]
    face = np.empty(len(tris), dtype=np.dtype([("n", "u1"), ("i", "<i4", (3,))]))
    face["n"] = 3
    face["i"] = tris
    with atomic_write(dest) as fh:
        fh.write(("\n".join(header) + "\n").encode("ascii"))
        # the records' bytes, not a copy of them (tobytes): a big mesh held its records twice
        fh.write(vert.view(np.uint8))
        fh.write(face.view(np.uint8))
    return dest


# ----------------------------------------------------------------------------- PCD


def _pack_rgb(colors: npt.NDArray[np.uint8]) -> npt.NDArray[np.float32]:
    """RGB as PCL packs it, ``0xFFRRGGBB`` in the bits of a float32: pcl::PointXYZRGB's
    ``rgba`` with its alpha 255 (opaque; alpha 0 was written, which PCL never does)."""
    c = colors.reshape(-1, 3).astype(np.uint32)
    packed = np.uint32(0xFF000000) | (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]
    return packed.astype("<u4").view("<f4")


def _unpack_rgb(packed: npt.NDArray[Any]) -> npt.NDArray[np.uint8]:
    """RGB of PCL's packed colours, ``0xAARRGGBB`` in the bits of 4-byte values (alpha unread).

    The bits, whatever the type that holds them: PCL packs ``rgb`` into a float32 (``TYPE F``),
    ``rgba`` and some writers into a uint32 (``TYPE U``); a numeric conversion between the two
    would change the colour.
    """
    a = np.ascontiguousarray(packed)
    if a.dtype.itemsize != 4:
        raise ValueError(f"packed rgb: expected 4-byte values, got {a.dtype}")
    u = a.astype(a.dtype.newbyteorder("<"), copy=False).view("<u4")
    return np.stack([(u >> 16) & 255, (u >> 8) & 255, u & 255], axis=-1).astype(np.uint8)


def _ascii_rgb_bits(values: npt.NDArray[np.float64], kind: str) -> npt.NDArray[np.uint32]:
    """The 32 bits of an ASCII PCD's packed colour column (read as float64 numbers).

    ``TYPE U`` and ``I``: the integer is the bits. ``TYPE F``: PCL writes the float's bits as an
    integer (``16711680`` for red: a float would be NaN for every opaque colour), older writers
    the float itself (``2.3418052e-38``); an integer token is taken as the bits, any other as
    the float whose bits they are.
    """
    if kind in ("U", "I"):
        ints = np.where(np.isfinite(values), values, 0).astype(np.int64)
        return (ints & 0xFFFFFFFF).astype(np.uint32)
    with np.errstate(invalid="ignore"):
        integral = np.isfinite(values) & (values == np.floor(values))
        integral &= (values >= 0) & (values < 2.0**32)
    as_int = np.where(integral, values, 0).astype(np.uint32)
    as_float = values.astype("<f4").view("<u4")
    return np.where(integral, as_int, as_float).astype(np.uint32)


def write_pcd(path: PathLike, result: DepthResult) -> Path:
    """Organised binary PCD (``WIDTH`` x ``HEIGHT`` = image size, NaN where no depth).

    Parameters
    ----------
    path : path
        File to write (atomically).
    result : DepthResult
        A :func:`stereovision.depth_map` result computed with a calibration.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        If the result has no calibration, or a colour ``left_rectified`` of another size than
        its disparity map.
    """
    dest = as_path(path, file=True)
    _require_type(result, "DepthResult", "result")
    pts, cols = organised_points(result)
    h, w = pts.shape[:2]
    rec = np.empty(
        h * w, dtype=np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4")])
    )
    flat = pts.reshape(-1, 3)
    rec["x"], rec["y"], rec["z"] = flat[:, 0], flat[:, 1], flat[:, 2]
    # stored as the bits: with alpha 255 white is a NaN float, kept bit for bit as an integer
    rec["rgb"] = _pack_rgb(cols).view("<u4")
    header = (
        "# .PCD v0.7 - Point Cloud Data file format (stereovision, metres, X right Y down Z fwd)\n"
        "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
        f"WIDTH {w}\nHEIGHT {h}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {h * w}\nDATA binary\n"
    )
    with atomic_write(dest) as fh:
        fh.write(header.encode("ascii"))
        fh.write(rec.view(np.uint8))  # the records' bytes, not a copy of them (tobytes)
    return dest


def read_pcd(
    path: PathLike,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8] | None]:
    """Read a PCD file with ``x y z`` (float) and optional packed ``rgb`` (ascii, binary or
    PCL's LZF ``binary_compressed`` data).

    The colour is PCL's packed ``0xAARRGGBB`` (alpha unread) in a 4-byte ``rgb`` (or ``rgba``)
    field, read as bits whether the header types it ``F`` (``pcl::PointXYZRGB``), ``U`` or
    ``I``. In ASCII data an integer is the bits (as PCL writes ``rgb``) and, for ``TYPE F``, any
    other number the float holding them.

    Parameters
    ----------
    path : path
        The ``.pcd`` file.

    Returns
    -------
    points : ndarray, float32 (HEIGHT, WIDTH, 3)
        Organised layout as stored (``HEIGHT`` 1 for an unorganised cloud); NaN kept.
    colors : ndarray, uint8 (HEIGHT, WIDTH, 3) or None

    Raises
    ------
    FileNotFoundError
        Missing file.
    ValueError
        Not a PCD file, unsupported fields / compression, truncated data, ``WIDTH`` x
        ``HEIGHT`` other than ``POINTS``, or a folder.
    """
    p = _cloud_file(path, "PCD file")
    # an ASCII cloud saved by a Windows editor opens with a UTF-8 byte-order mark: it was "not a
    # PCD file"
    raw = p.read_bytes().removeprefix(_UTF8_BOM)
    if not raw.startswith(_PCD_MAGIC):
        raise ValueError(f"not a PCD file: {p}")
    meta: dict[str, list[str]] = {}
    pos = 0
    while True:
        nl = raw.find(b"\n", pos)
        if nl < 0:
            raise ValueError(f"not a PCD file (header not terminated): {p}")
        line = raw[pos:nl].decode("ascii", errors="replace").strip()
        pos = nl + 1
        if not line or line.startswith("#"):
            continue
        key, *vals = line.split()
        meta[key.upper()] = vals
        if key.upper() == "DATA":
            break
    try:
        names = meta["FIELDS"]
        sizes = [int(s) for s in meta["SIZE"]]
        types = meta["TYPE"]
        counts = [int(c) for c in meta.get("COUNT", ["1"] * len(names))]
        # PCL's reader: a file without HEIGHT (PCD before 0.7) is unorganised, HEIGHT 1, and
        # WIDTH is its POINTS when not given either ("incomplete header" refused such files)
        points = int(meta["POINTS"][0]) if "POINTS" in meta else None
        if "HEIGHT" in meta or points is None:
            width, height = int(meta["WIDTH"][0]), int(meta["HEIGHT"][0])
        else:
            width = int(meta["WIDTH"][0]) if "WIDTH" in meta else points
            height = 1
        mode = meta["DATA"][0]
    except (KeyError, IndexError, ValueError):
        raise ValueError(f"PCD file {p}: incomplete header") from None
    if len(counts) == len(names) == len(sizes) == len(types):
        # PCL's reader drops a field of COUNT 0 (or less): it has no values in the data (taken
        # as one value, it shifted every point after the first in binary data)
        keep = [i for i, c in enumerate(counts) if c > 0]
        names, types = [names[i] for i in keep], [types[i] for i in keep]
        sizes, counts = [sizes[i] for i in keep], [counts[i] for i in keep]
    if not {"x", "y", "z"} <= set(names):
        raise ValueError(f"PCD file {p}: fields {names}, expected x y z")
    kinds = {"F": "f", "U": "u", "I": "i"}
    # "_" is PCL's padding field and may appear more than once (Ouster's and PCL's binary
    # files: "x y z _ intensity _"); each gets its own name so that the record type can hold it.
    fields = [f"_pad{i}" if n == "_" else n for i, n in enumerate(names)]
    try:
        dtype = np.dtype(
            [
                (n, f"<{kinds[t]}{s}", (c,)) if c > 1 else (n, f"<{kinds[t]}{s}")
                for n, s, t, c in zip(fields, sizes, types, counts, strict=True)
            ]
        )
    except (KeyError, TypeError, ValueError):
        # A type letter other than F/U/I, a size numpy has no type for, fewer sizes than fields.
        raise ValueError(
            f"PCD file {p}: unsupported fields {names} (SIZE {sizes}, TYPE {types})"
        ) from None
    if width < 0 or height < 0:
        raise ValueError(f"PCD file {p}: negative WIDTH or HEIGHT ({width} x {height})")
    if points is not None and points != width * height:
        # as PCL's reader refuses it: a POINTS 2 file of WIDTH 3 (a cloud cropped, its WIDTH
        # left) read a third point from the bytes after the data (PCL pads a file to a page)
        raise ValueError(
            f"PCD file {p}: WIDTH x HEIGHT is {width} x {height} = {width * height} points, "
            f"POINTS says {points}"
        )
    # The packed colour: "rgb" (PCL's PointXYZRGB, TYPE F) or "rgba" (PointXYZRGBA, TYPE U).
    colour = next((c for c in ("rgb", "rgba") if c in names), None)
    if colour is not None and (dtype[colour].shape != () or dtype[colour].itemsize != 4):
        i = names.index(colour)
        raise ValueError(
            f"PCD file {p}: field {colour!r} of SIZE {sizes[i]} COUNT {counts[i]}, expected a "
            "packed colour (SIZE 4, COUNT 1)"
        )
    # x y z of COUNT 2 failed late, in np.stack: "all input arrays must have the same shape"
    axis = next((a for a in ("x", "y", "z") if dtype[a].shape != ()), None)
    if axis is not None:
        raise ValueError(
            f"PCD file {p}: field {axis!r} of COUNT {counts[names.index(axis)]}, expected a "
            "coordinate (COUNT 1)"
        )
    n = width * height
    if mode == "binary":
        if len(raw) - pos < n * dtype.itemsize:
            raise ValueError(f"truncated PCD file {p}: expected {n} points")
        rec = np.frombuffer(raw, dtype=dtype, count=n, offset=pos)
    elif mode == "ascii":
        table = _ascii_table(raw[pos:], p, "PCD", sum(counts))
        # A field of COUNT c takes c columns (PCL's FPFH histograms: 33, padding "_": 4).
        if table.shape[1] < sum(counts):
            raise ValueError(
                f"PCD file {p}: rows of {table.shape[1]} values, FIELDS has {sum(counts)}"
                + (" (with its COUNT)" if len(counts) != sum(counts) else "")
            )
        if table.shape[0] != n:
            raise ValueError(f"PCD file {p}: expected {n} points, got {table.shape[0]}")
        # x, y and z as their text's float64: a 1e39 was made inf in the cast to a float field,
        # said by nothing but NumPy's "overflow encountered in cast" (_float32_coordinates)
        rec = np.empty(
            n, dtype=[(f, "<f8") if f in ("x", "y", "z") else (f, dtype[f]) for f in fields]
        )
        start = 0
        for i, name in enumerate(fields):
            col = table[:, start] if counts[i] == 1 else table[:, start : start + counts[i]]
            start += counts[i]
            if name == colour:  # the bits, stored in the field's own type
                bits = _ascii_rgb_bits(col, types[i])
                rec[name] = bits.astype("<u4").view(dtype[name])
            else:
                rec[name] = col
    elif mode == "binary_compressed":
        rec = _compressed_pcd_records(raw[pos:], dtype, n, p)
    else:
        raise ValueError(
            f"PCD file {p}: unsupported DATA {mode!r} (ascii, binary or binary_compressed)"
        )
    pts = _float32_coordinates(np.stack([rec["x"], rec["y"], rec["z"]], axis=-1), p, "PCD")
    cols = None if colour is None else _unpack_rgb(np.asarray(rec[colour]))
    shape = (height, width)
    return pts.reshape(*shape, 3), None if cols is None else cols.reshape(*shape, 3)


def _lzf_decompress(data: bytes, size: int, path: Path) -> bytes:
    """LZF (liblzf's ``lzf_decompress``, which PCL's ``binary_compressed`` data is) of
    ``data`` into ``size`` bytes, in Rust; a damaged stream is a ValueError naming ``path``
    and what is wrong with it."""
    try:
        return _core.lzf_decompress(data, size)
    except ValueError as e:
        raise ValueError(
            f"damaged PCD file {path}: its compressed data does not decompress ({e})"
        ) from None


def _compressed_pcd_records(
    body: bytes, dtype: np.dtype[Any], n: int, path: Path
) -> npt.NDArray[Any]:
    """The ``n`` records of a PCD's ``binary_compressed`` data (``pcl::io::
    savePCDFileBinaryCompressed``): the compressed and the plain size (uint32), then LZF of
    each field's values for all points in turn (all x, then all y..., to aid the compression)."""
    if len(body) < 8:
        raise ValueError(f"truncated PCD file {path}: expected {n} points")
    packed, size = (int(v) for v in np.frombuffer(body, "<u4", count=2))
    if len(body) - 8 < packed:
        raise ValueError(f"truncated PCD file {path}: expected {n} points")
    if size != n * dtype.itemsize:
        raise ValueError(
            f"damaged PCD file {path}: {size} bytes of compressed points, expected "
            f"{n * dtype.itemsize} for {n} points"
        )
    plain = _lzf_decompress(body[8 : 8 + packed], size, path) if size else b""
    rec = np.empty(n, dtype=dtype)
    offset = 0
    for name in dtype.names or ():
        field = dtype[name]  # (COUNT,) values for a field of COUNT > 1
        count = n * field.itemsize // field.base.itemsize
        values = np.frombuffer(plain, field.base, count=count, offset=offset)
        rec[name] = values.reshape((n, *field.shape))
        offset += n * field.itemsize
    return rec


# ----------------------------------------------------------------------------- NPZ


def write_npz(path: PathLike, result: DepthResult) -> Path:
    """Bundle depth, its uncertainty, confidence, disparity, the intrinsics and the disparity
    range searched into a ``.npz``.

    Without calibration ``depth`` and ``depth_sigma`` are all NaN and ``K`` / ``baseline`` /
    ``doffs`` are NaN.

    Parameters
    ----------
    path : path
        File to write (atomically).
    result : DepthResult
        Any :func:`stereovision.depth_map` result.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    dest = as_path(path, file=True)
    _require_type(result, "DepthResult", "result")
    h, w = result.disparity.shape[:2]
    calib = result.calibration
    k = np.full((3, 3), np.nan)
    baseline = doffs = float("nan")
    if calib is not None:
        k = np.asarray(calib.K1, dtype=np.float64)
        baseline = float(calib.baseline_m)
        doffs = float(calib.doffs_px)
    nan_map = np.full((h, w), np.nan, np.float32)
    depth = result.depth if result.depth is not None else nan_map
    # The one-sigma depth uncertainty is what a consumer weighs the depths by; without it the
    # bundle could not be used for fusion or filtering downstream.
    sigma = result.depth_sigma if result.depth_sigma is not None else nan_map
    bio = _io.BytesIO()
    np.savez_compressed(
        bio,
        depth=depth.astype(np.float32),
        depth_sigma=sigma.astype(np.float32),
        confidence=result.confidence.astype(np.float32),
        disparity=result.disparity.astype(np.float32),
        K=k,
        baseline=np.float64(baseline),
        doffs=np.float64(doffs),
        image_size=np.array([w, h], dtype=np.int64),
        method=np.array(result.method),
        # int64 for a whole range, float64 for a fractional one (int64 truncated 37.5 to 37)
        max_disparity=np.asarray(result.max_disparity),
        # the range's lower end: without it a [8, 40] px search read back as [0, 40]
        min_disparity=np.float64(result.min_disparity),
    )
    with atomic_write(dest) as fh:
        fh.write(bio.getvalue())
    return dest


def read_npz(path: PathLike) -> dict[str, Any]:
    """Read a bundle written by :func:`write_npz` into a dict of arrays (scalars as Python values).

    Parameters
    ----------
    path : path
        The ``.npz`` file.

    Returns
    -------
    dict
        ``depth``, ``confidence``, ``disparity`` (H, W) float32, ``K`` (3, 3), ``baseline``,
        ``doffs``, ``image_size``, ``method``, ``max_disparity``, ``min_disparity`` (a float;
        absent from bundles written before it was stored: their search may have started above
        0), and ``depth_sigma`` (H, W) float32, the depth's one-sigma uncertainty in metres
        (absent from older bundles).

    Raises
    ------
    FileNotFoundError
        Missing file.
    ValueError
        If the file is not an ``.npz`` bundle with ``depth`` and ``K``, is a folder, or a
        member holds Python objects (``np.savez(..., meta={...})`` pickles them: not loaded,
        a pickle can run code).
    """
    p = _cloud_file(path, "npz file")
    try:
        loaded = np.load(p, allow_pickle=False)
        if not isinstance(loaded, np.lib.npyio.NpzFile):  # a .npy file: one array, no bundle
            raise ValueError
        data: dict[str, Any] = {}
        pickled: list[str] = []
        with loaded as z:
            for k in z.files:
                try:
                    data[k] = z[k]
                except ValueError as exc:
                    if "allow_pickle" not in str(exc):
                        raise
                    pickled.append(k)
    except (zipfile.BadZipFile, zlib.error, EOFError, ValueError, OSError):
        # zlib.error / EOFError: a bundle whose compressed members are damaged or cut.
        raise ValueError(f"not an .npz bundle (or a damaged one): {p}") from None
    if pickled:
        # a member of Python objects (np.savez(..., meta={...})) is a pickle, refused unloaded
        # (loading one can run code), as before, but the whole file was said to be "not an .npz
        # bundle (or a damaged one)", sending the user after a damaged download
        raise ValueError(
            f"{p}: its {pickled[0]!r} holds Python objects (a pickle, not loaded: loading one can "
            "run code); save the bundle with numeric arrays only"
        )
    if "depth" not in data or "K" not in data:
        raise ValueError(f"{p}: not a stereovision depth bundle (needs depth and K)")
    for key, value in list(data.items()):
        if value.ndim == 0:
            data[key] = value.item()
    return data


def _points_from_bundle(data: dict[str, Any], path: Path) -> npt.NDArray[np.float32]:
    # A bundle of another writer, or a hand-made one: its depth and K named, not an IndexError
    # ("too many indices"), an unpacking error, or "empty point cloud" for a K of zeros.
    raw_depth, raw_k = np.asarray(data["depth"]), np.asarray(data["K"])
    for name, arr in (("depth", raw_depth), ("K", raw_k)):
        if arr.dtype == np.bool_ or not (
            np.issubdtype(arr.dtype, np.integer) or np.issubdtype(arr.dtype, np.floating)
        ):
            raise ValueError(f"{path}: its {name} is not numbers ({arr.dtype})")
    if raw_depth.ndim != 2:
        raise ValueError(f"{path}: its depth has shape {raw_depth.shape}, expected (H, W)")
    if raw_k.shape != (3, 3):
        raise ValueError(f"{path}: its K has shape {raw_k.shape}, expected (3, 3)")
    depth = raw_depth.astype(np.float64)
    k = raw_k.astype(np.float64)
    if not np.isfinite(k).all():
        # write_npz of a result without calibration: K and depth all NaN ("empty point cloud"
        # named no cause)
        raise ValueError(
            f"{path}: a depth bundle without calibration (no intrinsics): no metric 3-D points"
        )
    if not (k[0, 0] > 0 and k[1, 1] > 0):
        raise ValueError(
            f"{path}: its K has focal lengths {k[0, 0]:g} and {k[1, 1]:g}, expected positive ones"
        )
    h, w = depth.shape
    ys, xs = np.mgrid[0:h, 0:w]
    x = (xs - k[0, 2]) * depth / k[0, 0]
    y = (ys - k[1, 2]) * depth / k[1, 1]
    return np.stack([x, y, depth], axis=-1).astype(np.float32)


# ----------------------------------------------------------------------------- any cloud


def load_cloud(
    path: PathLike,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8] | None]:
    """Read a point cloud from PLY, PCD or an ``.npz`` bundle (chosen by content, not by name).

    Parameters
    ----------
    path : path
        The file.

    Returns
    -------
    points : ndarray, float32 (N, 3)
        Finite points only.
    colors : ndarray, uint8 (N, 3) or None

    Raises
    ------
    FileNotFoundError
        Missing file.
    ValueError
        Not a PLY / PCD / NPZ file (``"not a PLY file: ..."`` for a ``.ply`` that is not one), or
        a cloud without any finite point (``"empty point cloud: ..."``).
    """
    p = _cloud_file(path, "point cloud file")
    with open(p, "rb") as fh:
        head = fh.read(len(_UTF8_BOM) + 8).removeprefix(_UTF8_BOM)  # a BOM: as read_ply's
    cols: npt.NDArray[np.uint8] | None
    if head.startswith(_PLY_MAGIC):
        pts, cols = read_ply(p)
    elif head.startswith(_PCD_MAGIC):
        pts, cols = read_pcd(p)
    elif head.startswith(_ZIP_MAGIC):
        pts, cols = _points_from_bundle(read_npz(p), p), None
    elif p.suffix.lower() == ".ply":
        raise ValueError(f"not a PLY file: {p}")
    else:
        raise ValueError(f"not a point cloud file (PLY, PCD or NPZ): {p}")
    pts = pts.reshape(-1, 3)
    keep = np.isfinite(pts).all(axis=1)
    if not keep.any():
        raise ValueError(f"empty point cloud: {p} has no finite 3-D point")
    cols = None if cols is None else cols.reshape(-1, 3)
    if keep.all():  # no filtered copy of a cloud without NaN (2 s of 5 for 15 M points)
        return np.ascontiguousarray(pts), None if cols is None else np.ascontiguousarray(cols)
    return np.ascontiguousarray(pts[keep]), None if cols is None else cols[keep]


# --------------------------------------------------------------------------- voxel grid


@overload
def voxel_downsample(
    points: npt.ArrayLike, colors: None = None, voxel: float = 0.05
) -> tuple[npt.NDArray[np.float32], None]: ...
@overload
def voxel_downsample(
    points: npt.ArrayLike, colors: npt.ArrayLike, voxel: float = 0.05
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8]]: ...
@overload
def voxel_downsample(
    points: npt.ArrayLike, colors: npt.ArrayLike | None = None, voxel: float = 0.05
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8] | None]: ...
def voxel_downsample(
    points: npt.ArrayLike, colors: npt.ArrayLike | None = None, voxel: float = 0.05
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8] | None]:
    """One point per occupied cube of side ``voxel``: the mean of its points (and colours).

    The usual first step before a robot's planner or ICP: a 900x750 depth map gives 600 k
    points, mostly redundant near the camera. Cubes are aligned to the origin (the camera),
    and the output is ordered by cube (z, then y, then x), so the same cloud always gives the
    same result.

    Parameters
    ----------
    points : array_like
        ``(N, 3)`` points (metres); non-finite rows are dropped.
    colors : array_like, optional
        ``(N, 3)`` colours of the points: ``uint8`` (or other integers) 0-255, or floats 0-1
        (Open3D's and pyvista's colours; taken as 0-255 when any is above 1, as
        :func:`stereovision.io.read_ply` takes them). Returned as ``uint8`` 0-255.
    voxel : float
        Cube side, in the points' unit.

    Returns
    -------
    tuple
        ``(points float32 (M, 3), colors uint8 (M, 3))``; the colours are None when
        ``colors`` is (typed so: given colours come back as an array, no None check needed).

    Raises
    ------
    ValueError
        If ``points`` is not ``(N, 3)`` or holds a finite coordinate beyond float32's range
        (``1e39``), ``colors`` is a bare number (a cube side given positionally), does not
        match ``points`` or holds values outside 0-255, or ``voxel`` is not a positive number.

    Warns
    -----
    UserWarning
        If ``voxel`` is larger than the cloud's extent (its largest 1-99 % span): a side in
        another unit (50 meaning mm for points in metres) left a handful of points silently.
    """
    not_a_result(points, "points", "points")
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points: expected shape (N, 3), got {pts.shape}")
    # a point at 1e39 came out as an inf point, NumPy's "overflow encountered in cast" alone
    refuse_beyond_float32(pts, "points", "would come out as inf (the points are float32)")
    # Not a real number (a string, None): numpy's isfinite failed naming no argument.
    # np.timedelta64 is a numbers.Real too: 3 ns was a cube side of 3
    if isinstance(voxel, NOT_NUMBERS) or not isinstance(voxel, numbers.Real):
        raise ValueError(f"voxel: expected a positive cube side, got {voxel!r}")
    try:  # as a float: a Fraction made numpy's isfinite fail
        side = float(voxel)
    except OverflowError:  # an int too large for a float
        side = math.inf
    if not (math.isfinite(side) and side > 0):
        raise ValueError(f"voxel: expected a positive cube side, got {number_shown(voxel)}")
    voxel = side
    # voxel_downsample(pts, 1.0): the cube side landed in colors, reported as a shape mismatch.
    if isinstance(colors, (numbers.Number, np.number, np.bool_)):
        shown = number_shown(colors.item() if isinstance(colors, np.generic) else colors)
        raise ValueError(
            f"colors: expected (N, 3) colours, got the number {shown}; give the cube side "
            f"by keyword: voxel_downsample(points, voxel={shown})"
        )
    cols = None
    if colors is not None:
        cols = np.asarray(colors)
        if cols.shape != pts.shape:
            raise ValueError(f"colors: expected shape {pts.shape}, got {cols.shape}")
        if cols.dtype != np.uint8:
            # cast to uint8 after the mean, 300 came out 44 and NaN 0 (with a cast warning)
            if cols.dtype == np.bool_ or not (
                np.issubdtype(cols.dtype, np.integer) or np.issubdtype(cols.dtype, np.floating)
            ):
                raise ValueError(f"colors: expected uint8 colours 0-255, got {cols.dtype}")
            bad = ~(np.isfinite(cols) & (cols >= 0) & (cols <= 255))
            if bad.any():
                raise ValueError(
                    f"colors: expected colours 0-255, got {int(bad.any(axis=1).sum())} point(s) "
                    "with values outside (or NaN)"
                )
            if cols.dtype.kind == "f" and cols.size and float(cols.max()) <= 1.0:
                # Open3D's colours (np.asarray(pcd.colors)) are 0-1 floats: taken as 0-255 they
                # averaged to 0 or 1, a black cloud, without a word
                cols = cols * 255.0
    keep = np.isfinite(pts).all(axis=1)
    pts = pts[keep]
    if cols is not None:
        cols = cols[keep]
    if len(pts) == 0:
        empty_c = None if cols is None else np.zeros((0, 3), np.uint8)
        return np.zeros((0, 3), np.float32), empty_c
    farthest = float(np.abs(pts).max())
    reach = farthest / voxel
    if not reach < 2.0**62:  # cube indices must fit an int64
        # the farthest coordinate itself: reach * voxel was inf once reach overflowed (points
        # at 1e300 with a side of 1e-300 were said to reach inf)
        raise ValueError(f"voxel: {voxel!r} is too small for points reaching {farthest:.3g}")
    cells = np.floor(pts / voxel).astype(np.int64)
    cells -= cells.min(axis=0)
    ext = cells.max(axis=0) + 1
    if float(ext[0]) * float(ext[1]) * float(ext[2]) < 2.0**62:
        # one int64 key per cube (x fastest): a 1-D unique is ~10x faster than rows
        key = (cells[:, 2] * ext[1] + cells[:, 1]) * ext[0] + cells[:, 0]
        _, inverse, counts = np.unique(key, return_inverse=True, return_counts=True)
    else:  # a cloud spanning more cubes than an int64 counts
        _, inverse, counts = np.unique(
            cells[:, ::-1], axis=0, return_inverse=True, return_counts=True
        )
    inverse = inverse.reshape(-1)

    def mean(values: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        sums = [np.bincount(inverse, weights=values[:, k], minlength=len(counts)) for k in range(3)]
        out: npt.NDArray[np.float64] = np.column_stack(sums) / counts[:, None]
        return out

    if len(pts) >= _VOXEL_WARN_MIN_POINTS and len(counts) < len(pts):  # a cloud, merged
        _warn_if_voxel_too_large(pts, voxel, len(counts))
    out_c = None if cols is None else np.rint(mean(cols.astype(np.float64))).astype(np.uint8)
    return mean(pts).astype(np.float32), out_c


#: Share of a cloud's points (by coordinate, each end) left out of its extent: a depth map's
#: cloud has a few far outliers (cones at 5 cm: 98 % within 4.4 m, the farthest 166 m away).
_EXTENT_TAIL = 0.01
#: Fewer points are no cloud whose resolution a cube side sets (a few picked points; their
#: 1-99 % span is their whole span): no warning of a side larger than it.
_VOXEL_WARN_MIN_POINTS = 100


def _warn_if_voxel_too_large(pts: npt.NDArray[np.float64], voxel: float, kept: int) -> None:
    """Warn when ``voxel`` exceeds the cloud's extent (the largest 1-99 % span of its axes): the
    bulk of the cloud then fits within one cube side, at most 8 cubes, whatever the scene, so
    the side is in another unit (mm for points in metres) rather than a resolution. A share
    of points kept (1 %) would also flag a planner's coarse grid (cones at 20 cm keeps 0.7 %),
    a count (< 10) any small cloud."""
    sample = pts[:: max(1, len(pts) // 10000)]  # a stride: the quantiles cost ~1 ms
    lo, hi = np.quantile(sample, [_EXTENT_TAIL, 1.0 - _EXTENT_TAIL], axis=0)
    extent = float(np.max(hi - lo))
    if voxel <= extent or extent == 0.0:  # one point repeated: merging them is no loss
        return
    hint = f"; {voxel / 1000:g} if {voxel:g} was in mm" if voxel / 1000 < extent else ""
    warnings.warn(
        f"voxel: a cube side of {voxel:g} is larger than the cloud's extent, {extent:.3g} "
        f"across 98 % of its points (in the points' unit: metres for depth_map's points): "
        f"it leaves {kept} of {len(pts)} points; give the side in the points' unit{hint}",
        UserWarning,
        stacklevel=3,
    )


# ------------------------------------------------------------------------- 16-bit PNG

#: Units per metre of the 16-bit depth PNG: millimetres, as ROS ``16UC1`` depth images, the TUM
#: RGB-D and Open3D (``depth_scale=1000``) store depth.
DEPTH_PNG_SCALE = 1000.0
#: KITTI's disparity PNG: ``disparity * 256`` as uint16, 0 = no disparity.
DISPARITY_PNG_SCALE = 256.0


def _png16_bytes(values: npt.NDArray[np.float64], what: str) -> bytes:
    import cv2

    ok, buf = cv2.imencode(".png", values.astype(np.uint16))
    if not ok:
        raise ValueError(f"could not encode the {what} as a 16-bit PNG")
    return bytes(buf.tobytes())


def _png16_dest(path: PathLike, what: str) -> Path:
    """The file a 16-bit PNG writer writes, checked before its map is: with the arguments
    swapped (``write_depth_png(res, "d.png")``) the file name was taken for the map, "could
    not convert string to float: 'd.png'", naming neither."""
    dest = as_path(path, file=True)
    if dest.suffix.lower() != ".png":
        raise ValueError(f"{path}: a 16-bit {what} image is written as .png (lossless)")
    return dest


def _png16(dest: Path, values: npt.NDArray[np.float64], what: str) -> Path:
    data = _png16_bytes(values, what)
    with atomic_write(dest) as fh:
        fh.write(data)
    return dest


def encode_depth_png(depth: npt.ArrayLike, scale: float = DEPTH_PNG_SCALE) -> bytes:
    """The bytes :func:`write_depth_png` writes, for a depth map in metres (NaN = none).

    Parameters
    ----------
    depth : array_like
        ``(H, W)`` depth in metres.
    scale : float
        Units per metre.

    Returns
    -------
    bytes
        A single-channel 16-bit PNG.

    Raises
    ------
    TypeError
        If ``scale`` is not a real number (a string, a bool), or ``depth`` is a whole
        :class:`~stereovision.DepthResult` (its ``depth`` is meant) or a file name.
    ValueError
        If ``scale`` is not positive and finite, or ``depth`` is not a non-empty 2-D map.
    """
    not_a_result(depth, "depth", "depth")  # else numpy's "float() argument must be ..."
    return _png16_bytes(_scaled_u16(depth, scale, "depth"), "depth")


def _check_scale(scale: float) -> float:
    """A 16-bit PNG's ``scale`` (units per metre), checked to be a positive finite number (else
    named), as a float: another real number (a ``fractions.Fraction``) made an object array in
    numpy ("loop of ufunc does not support argument 0 of type float"), and an int too large
    for a float failed in ``math.isfinite`` naming no argument."""
    if isinstance(scale, NOT_NUMBERS) or not isinstance(scale, numbers.Real):
        # 3 ns was 3 units per metre; a string (scale="1000") failed inside numpy with
        # "ufunc 'isfinite' not supported"
        raise TypeError(
            f"scale: expected a number (units per metre), got {type(scale).__name__} {scale!r}"
        )
    try:
        value = float(scale)
    except OverflowError:
        value = math.inf
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"scale: expected a positive finite number, got {number_shown(scale)}")
    return value


def _scaled_u16(arr: npt.ArrayLike, scale: float, name: str) -> npt.NDArray[np.float64]:
    scale = _check_scale(scale)
    if isinstance(arr, (str, bytes, os.PathLike)):
        # a file name for the map: NumPy's "could not convert string to float: 'depth.npy'"
        shown = str(os.fsdecode(arr))
        raise TypeError(
            f"{name}: expected an (H, W) array, got the file name {shown!r}: read the map first"
        )
    if isinstance(arr, np.ndarray) and arr.ndim == 2:  # before the float64 copy
        check_index_range(arr.shape, name, "map")
    a = np.asarray(arr, dtype=np.float64)
    if a.ndim != 2 or a.size == 0:
        raise ValueError(f"{name}: expected a non-empty (H, W) array, got shape {a.shape}")
    # over: a depth past a float's range once scaled (1e308 m) is inf, dropped below as too
    # far; NumPy's bare "overflow encountered in multiply" named neither map nor pixel
    with np.errstate(over="ignore"):
        s = np.rint(np.where(np.isfinite(a), a, 0.0) * scale)
    # 0 means "none": values that round to 0 or do not fit 16 bits are dropped, not clipped, so
    # no pixel is written at a wrong distance.
    kept = (s >= 1) & (s <= 65535)
    positive = np.isfinite(a) & (a > 0)
    known = int(np.count_nonzero(positive))
    if known and not kept.any():
        # what is true of the values said, not a guess: depths of 66 m and more in metres (a
        # far scene, a small --max-disparity) were "millimetres given?"
        far = int(np.count_nonzero(positive & (s > 65535)))
        why = []
        if far:
            unit = " m" if name == "depth" else ""
            why.append(
                f"{far} beyond {65535 / scale:g}{unit}, the most a 16-bit PNG holds at this scale"
                + (" (depths are in metres)" if name == "depth" else "")
            )
        if known - far:
            why.append(f"{known - far} rounding to 0 (under {0.5 / scale:g})")
        warnings.warn(
            f"{name}: none of its {known} values fits 1..65535 at scale {scale:g}: "
            + "; ".join(why)
            + ": the image is all 0",
            UserWarning,
            stacklevel=3,
        )
    return np.where(kept, s, 0.0)


def write_depth_png(
    path: PathLike, depth: DepthResult | npt.ArrayLike, scale: float = DEPTH_PNG_SCALE
) -> Path:
    """Depth as a single-channel 16-bit PNG: ``round(Z * scale)``, millimetres by default.

    The format of ROS ``16UC1`` depth images, the TUM RGB-D benchmark and Open3D's
    ``create_from_depth_image`` (``depth_scale=1000``). 0 marks pixels without depth; depths
    beyond ``65535 / scale`` (65.5 m in millimetres) are written as 0, not clipped.

    Parameters
    ----------
    path : path
        File to write (atomically).
    depth : DepthResult or array_like
        A :func:`stereovision.depth_map` result with a calibration, or an ``(H, W)`` depth
        map in metres (NaN = none).
    scale : float
        Units per metre.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        A result without calibration (no depth), a map that is not 2-D, or a ``scale`` that is
        not positive and finite.
    TypeError
        A ``scale`` that is not a real number (a string, a bool), a ``path`` that is no file
        name (a DepthResult: the arguments swapped), or a file name for ``depth``.
    """
    from stereovision.depth import DepthResult

    dest = _png16_dest(path, "depth")
    if isinstance(depth, DepthResult):
        if depth.depth is None:
            raise ValueError(NO_DEPTH.format(what="depth"))
        return _png16(dest, _scaled_u16(depth.depth, scale, "depth"), "depth")
    return _png16(dest, _scaled_u16(depth, scale, "depth"), "depth")


def write_disparity_png(path: PathLike, disparity: DepthResult | npt.ArrayLike) -> Path:
    """Disparity in KITTI's 16-bit PNG format: ``round(d * 256)``, 0 = no disparity.

    Disparities at or below 1/512 px and at or above 65535.5/256 = 255.998 px (which would round
    past 16 bits) are written as 0.

    Parameters
    ----------
    path : path
        File to write (atomically).
    disparity : DepthResult or array_like
        A :func:`stereovision.depth_map` result or an ``(H, W)`` disparity map (NaN = none).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        A map that is not 2-D.
    TypeError
        A ``path`` that is no file name (a DepthResult: the arguments swapped), or a file name
        for ``disparity``.
    """
    from stereovision.depth import DepthResult

    dest = _png16_dest(path, "disparity")
    d = disparity.disparity if isinstance(disparity, DepthResult) else disparity
    return _png16(dest, _scaled_u16(d, DISPARITY_PNG_SCALE, "disparity"), "disparity")


def _read_png16(path: PathLike, scale: float, what: str) -> npt.NDArray[np.float32]:
    import cv2

    from stereovision.io import _existing_file, _imdecode

    p = _existing_file(path, what)
    raw = np.fromfile(p, dtype=np.uint8)
    img = _imdecode(raw, cv2.IMREAD_UNCHANGED) if raw.size else None
    if img is None or img.ndim != 2 or img.dtype != np.uint16:
        got = "not a PNG" if img is None else f"{img.dtype} with shape {img.shape}"
        raise ValueError(f"{p}: expected a single-channel 16-bit PNG, got {got}")
    # a scale whose depths a float32 cannot hold: 1e-50 units per metre read every depth as
    # inf (1e39: as 0, on the camera), with NumPy's "divide by zero" warnings alone
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        out = img.astype(np.float32) / np.float32(scale)
    known = img > 0
    if known.any() and not (np.isfinite(out[known]).all() and (out[known] > 0).all()):
        lo, hi = int(img[known].min()), int(img.max())
        raise ValueError(
            f"scale: {number_shown(scale)} units per metre makes the values {lo} to {hi} of "
            f"{p} {lo / scale:.3g} to {hi / scale:.3g} m, past a float32's range"
        )
    out[img == 0] = np.nan
    return out


def read_depth_png(path: PathLike, scale: float = DEPTH_PNG_SCALE) -> npt.NDArray[np.float32]:
    """Read a 16-bit depth PNG (see :func:`write_depth_png`) as metres, NaN where 0.

    Parameters
    ----------
    path : path
        The PNG.
    scale : float
        Units per metre of the file (1000 for millimetres, 5000 for the TUM RGB-D benchmark).

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` float32 metres.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    TypeError
        If ``scale`` is not a number.
    ValueError
        If it is not a single-channel 16-bit PNG, or ``scale`` is not positive and finite or
        makes the file's depths past a float32's range (1e-50 units per metre).
    """
    return _read_png16(path, _check_scale(scale), "depth PNG")


def read_disparity_png(path: PathLike) -> npt.NDArray[np.float32]:
    """Read a KITTI 16-bit disparity PNG (``d * 256``) as pixels, NaN where 0.

    Parameters
    ----------
    path : path
        The PNG.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` float32 disparity in pixels.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        If it is not a single-channel 16-bit PNG.
    """
    return _read_png16(path, DISPARITY_PNG_SCALE, "disparity PNG")


@renamed_keyword("out_dir", "directory")
def export_result(
    result: DepthResult,
    directory: PathLike,
    formats: tuple[str, ...] = tuple(EXPORT_FORMATS),
) -> dict[str, Path]:
    """Write the result in the chosen formats into ``directory`` (:data:`EXPORT_FORMATS`).

    Parameters
    ----------
    result : DepthResult
        A :func:`stereovision.depth_map` result.
    directory : path
        Folder, created if missing; each file is written atomically.
        The keyword ``out_dir=``, its former name, still works, with a DeprecationWarning.
    formats : tuple of str
        Any of ``"ply"``, ``"pcd"``, ``"npz"``, ``"depth16"`` (millimetres, 16-bit PNG) and
        ``"disp16"`` (KITTI's 16-bit disparity PNG); default: all.

    Returns
    -------
    dict
        File name -> path written.

    Raises
    ------
    TypeError
        If ``formats`` is one string (``"ply"``) or bytes (``b"ply"``), not a tuple of
        names, or no collection of names at all (None). Any iterable of names is taken (a
        list, a generator).
    ValueError
        Unknown format, or PLY / PCD / depth PNG asked for a result without calibration.
    IsADirectoryError
        If a folder stands where one of the files goes.
    OSError
        If a link stands there that loops or leads into a missing folder
        (FileNotFoundError), or a FIFO or a device (or a link to one).

    Notes
    -----
    These are checked before any file is written: a call refused for them leaves the folder
    as it was.
    """
    if isinstance(formats, str):
        # set("ply") is its letters: "unknown export format(s) ['l', 'p', 'y']"
        raise TypeError(
            f"formats: expected a tuple of format names, got the string {formats!r} "
            f"(give ({formats!r},))"
        )
    if isinstance(formats, bytes | bytearray | memoryview):
        # iterated, b"ply" is its byte values: "unknown export format(s) [108, 112, 121]"
        name = bytes(formats).decode("ascii", "replace")
        hint = f"give ({name!r},)" if name in EXPORT_FORMATS else "e.g. ('ply', 'npz')"
        raise TypeError(
            f"formats: expected a tuple of format names, got the bytes {bytes(formats)!r} ({hint})"
        )
    try:
        # once, as a tuple: a generator was used up by the check of its names below, and
        # nothing was written ({} returned, without a word)
        formats = tuple(formats)
    except TypeError:  # None, a number: "'NoneType' object is not iterable" named no argument
        raise TypeError(
            f"formats: expected a tuple of format names, got {formats!r} (e.g. ('ply', 'npz'))"
        ) from None
    # each shown once, by its repr: a list among them failed in set() ("unhashable type"),
    # an int beside an unknown name in the sort of this list, naming no argument
    unknown = sorted(
        {text_shown(f) for f in formats if not (isinstance(f, str) and f in EXPORT_FORMATS)}
    )
    if unknown:
        raise ValueError(
            f"unknown export format(s) [{', '.join(unknown)}]: expected {list(EXPORT_FORMATS)}"
        )
    _require_type(result, "DepthResult", "result")
    # Refused before any file is written: found at its turn, after the formats before it were
    # written, it left a folder's good depth.npz replaced by an all-NaN one (and a new
    # disparity_16.png beside an earlier run's cloud.ply), then raised.
    metric = [f for f in formats if f in _METRIC_FORMATS]
    if metric and (result.depth is None or result.calibration is None):
        raise ValueError(
            NO_DEPTH.format(what="depth") + f"; formats {metric} need one (npz and disp16 "
            "do not); nothing was written"
        )
    if "pcd" in formats or ("ply" in formats and len(result.points) == 0):
        _check_left_size(result)  # found at the PCD's turn, after cloud.ply was replaced
    out = as_path(directory, "directory")
    for fmt in formats:  # a folder in the way, refused before the formats before it are written
        target = out / EXPORT_FORMATS[fmt]
        if target.is_dir():
            raise IsADirectoryError(
                f"cannot write {target}: it is a folder; move it away (nothing was written)"
            )
        if target.is_symlink() or (target.exists() and not target.is_file()):
            # what atomic_write refuses of a link (one that loops, one into a missing folder)
            # or of a FIFO was found at its format's turn, after depth.npz and cloud.ply were
            # replaced
            _writable_destination(_through_links(target), target)
    make_folder(out)
    writers: dict[str, Callable[[Path, DepthResult], Path]] = {
        "ply": write_cloud_ply,
        "pcd": write_pcd,
        "npz": write_npz,
        "depth16": write_depth_png,
        "disp16": write_disparity_png,
    }
    written: dict[str, Path] = {}
    for fmt in formats:
        name = EXPORT_FORMATS[fmt]
        written[name] = writers[fmt](out / name, result)
    return written
