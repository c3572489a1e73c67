"""What a user who only ran ``pip install stereovision-rs`` gets: the installed package, its
metadata and its bundled scene; an optional feature whose extra is missing names that extra."""

from __future__ import annotations

import re
import shutil
import sys
from importlib import metadata, resources
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


def _distribution() -> metadata.Distribution:
    try:
        return metadata.distribution("stereovision-rs")
    except metadata.PackageNotFoundError:
        pytest.skip("stereovision-rs is not installed (the tests run from a source tree)")


def test_wheel_carries_its_licence() -> None:
    """The MIT licence is declared as an SPDX expression and its text ships in the wheel (the
    MIT licence asks for its notice in every copy). There was no licence file at all, in the
    repository, the sdist or the wheel: only ``License: MIT``."""
    dist = _distribution()
    assert dist.metadata["License-Expression"] == "MIT"
    licences = [f for f in dist.files or [] if f.name == "LICENSE"]
    assert len(licences) == 1, dist.files
    assert licences[0].read_text().startswith("MIT License\n")


def test_metadata_says_what_the_wheel_supports() -> None:
    """Requires-Python is the abi3 minimum of the wheel's tag, and the classifiers list that
    Python and the typed package. There were no classifiers."""
    dist = _distribution()
    minimum = dist.metadata["Requires-Python"]
    assert minimum == ">=3.10"
    tags = [
        line.split(": ", 1)[1]
        for line in (dist.read_text("WHEEL") or "").splitlines()
        if line.startswith("Tag: ")
    ]
    assert tags and all(t.startswith("cp310-abi3-") for t in tags), tags
    classifiers = dist.metadata.get_all("Classifier") or []
    assert "Programming Language :: Python :: 3.10" in classifiers
    assert "Typing :: Typed" in classifiers
    assert dist.metadata["Description-Content-Type"].startswith("text/markdown")


def test_installed_package_holds_its_stub_and_sample_attribution() -> None:
    """The typed stub, the py.typed marker and the bundled scene with its SOURCE and licence
    note are in the installed package, not only in the source tree."""
    pkg = resources.files("stereovision")
    assert (pkg / "py.typed").is_file()
    assert "def gabor_disparity(" in (pkg / "_core.pyi").read_text()
    cones = _bundled_cones()
    for name in ("left.png", "right.png", "calib.txt", "gt_disp.pfm"):
        assert (cones / name).is_file(), name
    assert "Scharstein" in (cones / "README.md").read_text()
    assert "licence=" in (cones / "SOURCE").read_text()


def _minimum(dist: metadata.Distribution, name: str) -> tuple[int, ...]:
    """The ``>=`` lower bound of requirement ``name`` (an extra's too), as a version tuple."""
    for req in dist.requires or []:
        m = re.fullmatch(rf"{name}(\[[^]]*\])?\s*>=\s*([0-9.]+)\s*(;.*)?", req.strip())
        if m:
            return tuple(int(p) for p in m.group(2).split("."))
    raise AssertionError(f"no {name}>=... among {dist.requires}")


def test_declared_minimums_are_versions_the_package_runs_on() -> None:
    """Measured in a venv holding each lower bound (``stereovision demo`` and ``view``, no
    display; tests/test_io.py, test_rosbag.py, test_rosbag_read.py): pyvista 0.44 (the old
    minimum) comes with VTK 9.3, whose render aborted the demo (exit 134, at render.png);
    pyvista 0.46 and 0.47 raise AttributeError on ``PolyData.n_faces``, which render.py reads;
    OpenCV 4.8 (the old minimum) to 4.14 have no ``criteria`` in ``cv2.undistortPoints``
    (calibrate) and 4.8-4.12 no ``cv2.utils.logging`` (every image decode); with OpenCV 5.0
    ``import stereovision`` fails (no ``cv2.fisheye.CALIB_RECOMPUTE_EXTRINSIC``). OpenCV 5.1,
    numpy 2.0, pyvista 0.48 and VTK 9.4 run them. The floor said VTK 9.4, but pyvista (0.48
    on) excludes 9.4.0 and 9.4.1: pip found no vtk==9.4.0 beside pyvista==0.48.0, and 9.4.2
    is the oldest VTK the package was tested on."""
    dist = _distribution()
    assert _minimum(dist, "pyvista") >= (0, 48)
    assert _minimum(dist, "vtk") >= (9, 4, 2)
    assert _minimum(dist, "opencv-python-headless") >= (5, 1)
    assert _minimum(dist, "numpy") >= (2, 0)  # OpenCV 5 needs it


def test_pyyaml_floor_installs_on_every_python_it_claims() -> None:
    """The floor was pyyaml>=6: PyYAML 6.0 has no wheel for Python 3.12 or 3.13 (classifiers
    here) and its sdist fails to build with Cython 3 ("'build_ext' object has no attribute
    'cython_sources'"). 6.0.1 has a 3.12 wheel and an sdist that builds (it pins Cython < 3);
    tests/test_calibration.py, test_calibrate.py, test_calibration_ros.py and test_io.py pass
    with it."""
    assert _minimum(_distribution(), "pyyaml") >= (6, 0, 1)


def test_gui_extra_floors_install_beside_its_trame_pyvista() -> None:
    """The ``gui`` extra asked for trame>=3, trame-vtk>=2.8 and trame-vuetify>=2.7 beside
    trame-pyvista>=0.2, but trame-pyvista 0.2.0 requires trame>=3.9.1, trame-vtk>=2.11.16 and
    trame-vuetify>=3.2.5: pip found no install of the floors together. tests/test_gui_app.py
    passes with exactly those (trame 3.9.1, trame-vtk 2.11.16, trame-vuetify 3.2.5,
    trame-pyvista 0.2.0)."""
    dist = _distribution()
    assert _minimum(dist, "trame-pyvista") >= (0, 2)
    assert _minimum(dist, "trame") >= (3, 9, 1)
    assert _minimum(dist, "trame-vtk") >= (2, 11, 16)
    assert _minimum(dist, "trame-vuetify") >= (3, 2, 5)


def test_ros_extra_asks_for_a_rosbags_that_reads_bags_in_a_thread() -> None:
    """The ``ros`` extra asked for rosbags>=0.10: with 0.10.11 and 0.11.0, ``stream
    --from-bag`` and ``capture --from-bag`` of a ROS 2 bag stopped with "internal
    ProgrammingError: SQLite objects created in a thread can only be used in that same
    thread" (the bag is read on a prefetch thread), and 0.10 read no ROS 2 bag without its
    metadata.yaml; tests/test_rosbag_read.py passes from 0.11.1."""
    assert _minimum(_distribution(), "rosbags") >= (0, 11, 1)
