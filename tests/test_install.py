"""What a user who only ran ``pip install stereovision-rs`` gets: the installed package, its
metadata and its bundled scene; an optional feature whose extra is missing names that extra."""

from __future__ import annotations

import shutil
import sys
from importlib import resources
from pathlib import Path

import pytest

from stereovision.cli import main


def _bundled_cones() -> Path:
    """The installed package's bundled scene (not the source tree's)."""
    return Path(str(resources.files("stereovision") / "data" / "cones"))


def test_batch_without_dask_names_the_extra(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision batch` where Dask is not installed (the `batch` extra is optional): one
    line naming the pip install of the extra, exit 2. It said "No module named 'distributed'"
    (the import of ``as_completed`` came before the one that names the extra)."""
    scene = tmp_path / "in" / "cones"
    scene.mkdir(parents=True)
    for name in ("left.png", "right.png", "calib.txt"):
        shutil.copy(_bundled_cones() / name, scene / name)
    # None in sys.modules: `import distributed` raises ImportError, as where it is not installed
    monkeypatch.setitem(sys.modules, "distributed", None)
    code = main(["batch", str(tmp_path / "in"), "-o", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert err == [
        "stereovision: error: batch needs Dask distributed: pip install 'stereovision-rs[batch]'"
    ]
