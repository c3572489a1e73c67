"""Shared fixtures: the real stereo scenes of ``../shared/data`` (evaluation.md)."""

from __future__ import annotations

import signal
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

DATA_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data"

# A suite started in the background by a non-interactive shell (`make test &`, nohup, some CI
# runners) inherits SIGINT ignored, and Python then installs no KeyboardInterrupt handler: the
# Ctrl-C tests (a signal raised in-process, or sent to a child, which inherits the ignore)
# failed with "DID NOT RAISE KeyboardInterrupt" and exit 0 for 130. Python's own handler, as an
# interactive run has it.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """``<repo>/../shared/data``; tests using it are skipped when the data is absent."""
    if not DATA_DIR.is_dir():
        pytest.skip(f"shared test data not found at {DATA_DIR}")
    return DATA_DIR


@pytest.fixture(scope="session")
def crop_terrace(
    data_dir: Path, tmp_path_factory: pytest.TempPathFactory
) -> Callable[[slice, slice], Path]:
    """``crop_terrace(rows, cols)``: a folder ``eth3d/terrace`` of that crop of the ETH3D scene
    (left.png, right.png, gt_disp.pfm), its calib.txt's principal point and size made the
    crop's. A real metric scene with its holes at a fraction of the pixels, made once per
    session for each crop; read only (copy it to change it)."""
    made: dict[tuple[int, int, int, int], Path] = {}

    def crop(rows: slice, cols: slice) -> Path:
        key = (rows.start, rows.stop, cols.start, cols.stop)
        if key in made:
            return made[key]
        import cv2

        from stereovision.io import read_pfm, write_pfm

        src = data_dir / "eth3d" / "terrace"
        dst = tmp_path_factory.mktemp("crop") / "eth3d" / "terrace"
        dst.mkdir(parents=True)
        for name in ("left.png", "right.png"):
            assert cv2.imwrite(str(dst / name), cv2.imread(str(src / name))[rows, cols])
        write_pfm(dst / "gt_disp.pfm", read_pfm(src / "gt_disp.pfm")[rows, cols])
        text = (src / "calib.txt").read_text()
        for old, new in [
            ("376.135", f"{376.135 - cols.start:.3f}"),
            ("227.447", f"{227.447 - rows.start:.3f}"),
            ("width=713", f"width={cols.stop - cols.start}"),
            ("height=434", f"height={rows.stop - rows.start}"),
        ]:
            assert old in text
            text = text.replace(old, new)
        (dst / "calib.txt").write_text(text)
        made[key] = dst
        return dst

    return crop


@pytest.fixture
def in_process_dask(monkeypatch: pytest.MonkeyPatch) -> None:
    """batch's LocalCluster with its worker a thread of this process, for the tests whose point
    is batch's bookkeeping (skips, redos, summary, errors) or the command line's words and
    paths, not Dask's processes: started and closed by each run as before, at a sixth of the
    CPU (a worker process starts Python, NumPy and OpenCV: about 2 s of CPU a run, ~0.3 s in
    process). Tests of the cluster itself (its
    workers, signals, memory, what reaches a worker) keep real worker processes."""
    import distributed

    real = distributed.LocalCluster

    def in_process(*args: Any, **kwargs: Any) -> Any:
        kwargs.pop("env", None)  # a worker process's environment: none to set in process
        return real(*args, **{**kwargs, "processes": False})

    monkeypatch.setattr(distributed, "LocalCluster", in_process)


@pytest.fixture
def sift_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The rows check's SIFT features and mutual matches (:mod:`stereovision.rectification_check`,
    used by :mod:`stereovision.uncalibrated` too) found once per image and pair of descriptor
    sets, by content: pure functions, copies handed out. Each check still fits and judges its
    pair's matches."""
    import hashlib

    from stereovision import rectification_check as rc
    from stereovision import uncalibrated

    def key(*arrays: Any) -> tuple:
        return tuple((a.shape, a.dtype.str, hashlib.sha1(a.tobytes()).digest()) for a in arrays)

    features, matches = rc._features, rc._mutual_matches
    found: dict[tuple, Any] = {}
    matched: dict[tuple, Any] = {}

    def features_once(gray: Any) -> Any:
        k = key(gray)
        if k not in found:
            found[k] = features(gray)
        pts, desc = found[k]
        return pts.copy(), None if desc is None else desc.copy()

    def matches_once(da: Any, db: Any) -> Any:
        k = key(da, db)
        if k not in matched:
            matched[k] = matches(da, db)
        return matched[k].copy()

    for module in (rc, uncalibrated):
        monkeypatch.setattr(module, "_features", features_once)
        monkeypatch.setattr(module, "_mutual_matches", matches_once)


@pytest.fixture
def unlistable(monkeypatch: pytest.MonkeyPatch) -> Callable[[Any], None]:
    """``unlistable(folder)``: ``os.scandir`` of that folder raises PermissionError from then
    on, as for a user without read permission (the tests run as root, whom chmod does not
    stop). A descriptor (an int, as os.fwalk passes) is listed as before."""
    import os

    listing = os.scandir
    locked: set[str] = set()

    def scandir(path: Any = ".") -> Any:
        if not isinstance(path, int) and os.fspath(path) in locked:
            raise PermissionError(13, "Permission denied", os.fspath(path))
        return listing(path)

    monkeypatch.setattr(os, "scandir", scandir)
    return lambda folder: locked.add(os.fspath(folder))
