"""The typed public API, as a user with ``mypy --strict`` meets it.

``typed_user_script.py`` does what the README's "Using it" and docs/robotics.md's pipeline do,
every value annotated with the type the README promises; mypy checks it against the package
that ``import stereovision`` finds (the installed one in CI), with no configuration of this
repository's (only pyvista, whose types no script here uses, is read as ``Any``).
"""

from __future__ import annotations

import importlib.util
import os
import site
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import stereovision as sv

SCRIPT = Path(__file__).with_name("typed_user_script.py")


@pytest.fixture(scope="session")
def mypy_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """This test session's own mypy cache, shared by its mypy runs only: mypy's cache is not
    safe for concurrent runs (one reads another's half-written data and crashes, or an SQLite
    cache is locked), and a fixed folder in the temporary directory was one for every run of
    every checkout on the machine at once (worktrees, ``pytest -n``)."""
    return tmp_path_factory.mktemp("mypy-cache")


def _mypy_strict(source: Path, cwd: Path, cache: Path) -> subprocess.CompletedProcess[str]:
    """``mypy --strict`` on ``source``, finding ``stereovision`` where Python does: through its
    ``py.typed`` in site-packages, or (a source checkout on PYTHONPATH) through MYPYPATH, which
    mypy refuses to point at site-packages. The package's own modules are checked, not reported:
    a user's mypy reports the user's code. ``cache``: :func:`mypy_cache`."""
    package_root = Path(sv.__file__).resolve().parents[1]
    # pyvista is read as Any: its 128 modules (reached through export's and render's
    # ``pv.PolyData`` annotations) took 24.5 s of the 54 s a cold run took, and no script here
    # uses a pyvista type.
    config = cwd / "mypy.ini"
    config.write_text("[mypy]\n\n[mypy-pyvista.*]\nfollow_imports = skip\n")
    env = dict(os.environ)
    sites = {Path(p).resolve() for p in [*site.getsitepackages(), site.getusersitepackages()]}
    if package_root not in sites:
        env["MYPYPATH"] = str(package_root)
    return subprocess.run(
        [sys.executable, "-m", "mypy", "--config-file", str(config), "--strict",
         "--follow-imports=silent", "--no-error-summary", "--cache-dir", str(cache), str(source)],
        capture_output=True, text=True, timeout=600, cwd=cwd, env=env,
    )  # fmt: skip


def test_mypy_runs_with_this_sessions_own_cache(
    tmp_path: Path,
    tmp_path_factory: pytest.TempPathFactory,
    mypy_cache: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The cache was ``$TMPDIR/stereovision-mypy-strict-UID``, one folder for every concurrent
    run on the machine (other checkouts' and ``pytest -n`` workers'), which mypy does not
    support; it is under this session's base temporary folder now."""
    seen: list[list[str]] = []

    def fake_run(argv: list[str], **kwargs: object) -> subprocess.CompletedProcess[str]:
        seen.append(argv)
        return subprocess.CompletedProcess(argv, 0, "", "")

    monkeypatch.setattr(subprocess, "run", fake_run)
    _mypy_strict(SCRIPT, tmp_path, mypy_cache)
    cache = Path(seen[0][seen[0].index("--cache-dir") + 1])
    assert cache == mypy_cache
    assert cache.is_relative_to(tmp_path_factory.getbasetemp())


def test_the_readme_script_passes_mypy_strict(tmp_path: Path, mypy_cache: Path) -> None:
    """It failed on ``res.depth`` and ``res.depth_sigma`` (``ndarray | None`` even with a
    calibration: now ``require_depth()`` / ``require_depth_sigma()``) and on
    ``calib.depth_step(5.0)`` (an array for one number: now a float)."""
    run = _mypy_strict(SCRIPT, tmp_path, mypy_cache)
    assert run.stdout + run.stderr == ""
    assert run.returncode == 0


def test_mypy_strict_refuses_what_fails_at_run_time(tmp_path: Path, mypy_cache: Path) -> None:
    """The check above would pass if mypy saw nothing of the package (``Any`` everywhere): a
    script that uses ``res.depth`` unguarded is refused, naming the None, and so is a file name
    where a Calibration is meant (a TypeError at run time; ``Matches.to_points``'s and
    ``check_rectification``'s ``calib`` were ``Any``)."""
    script = tmp_path / "wrong.py"
    script.write_text(
        "import numpy as np\nimport numpy.typing as npt\nimport stereovision as sv\n\n\n"
        "def depth(res: sv.DepthResult) -> npt.NDArray[np.float32]:\n    return res.depth\n\n\n"
        "def points(m: sv.Matches) -> npt.NDArray[np.float32]:\n"
        "    return m.to_points('rig.yaml')\n\n\n"
        "def check(a: npt.NDArray[np.uint8]) -> bool | None:\n"
        "    return sv.check_rectification(a, a, 'rig.yaml').ok\n"
    )
    run = _mypy_strict(script, tmp_path, mypy_cache)
    assert run.returncode == 1
    lines = run.stdout.splitlines()
    assert len(lines) == 3, run.stdout
    assert 'wrong.py:7: error: Incompatible return value type (got "ndarray[' in lines[0]
    assert '| None", expected "ndarray[' in lines[0]
    assert lines[1].endswith(
        'wrong.py:11: error: Argument 1 to "to_points" of "Matches" has incompatible type '
        '"str"; expected "Calibration"  [arg-type]'
    )
    assert lines[2].endswith(
        'wrong.py:15: error: Argument 3 to "check_rectification" has incompatible type "str"; '
        'expected "Calibration | None"  [arg-type]'
    )


def test_mypy_strict_refuses_a_name_the_package_does_not_have(
    tmp_path: Path, mypy_cache: Path
) -> None:
    """The package's lazy imports (a module ``__getattr__``) made every attribute of it
    ``Any`` to mypy: ``sv.depth_mapp(...)``, a typo that fails at run time, passed --strict."""
    script = tmp_path / "typo.py"
    script.write_text("import stereovision as sv\n\nsv.depth_mapp\nreveal_type(sv.io)\n")
    run = _mypy_strict(script, tmp_path, mypy_cache)
    assert run.returncode == 1
    lines = run.stdout.splitlines()
    assert lines[0].endswith(
        'typo.py:3: error: Module has no attribute "depth_mapp"; maybe "depth_map"?  [attr-defined]'
    ), run.stdout
    assert lines[1].endswith('typo.py:4: note: Revealed type is "types.ModuleType"'), run.stdout
    assert len(lines) == 2, run.stdout


def test_a_name_that_is_no_identifier_is_no_attribute() -> None:
    """``getattr(sv, "a.b")`` looked for the submodule ``stereovision.a`` and raised
    ModuleNotFoundError, so ``hasattr`` raised where it says False."""
    assert not hasattr(sv, "a.b")
    with pytest.raises(AttributeError, match=r"has no attribute 'depth\.x'"):
        getattr(sv, "depth.x")


def test_the_readme_script_runs(data_dir: Path, tmp_path: Path) -> None:
    spec = importlib.util.spec_from_file_location("typed_user_script", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    got = module.run(data_dir / "eth3d" / "terrace", tmp_path)
    calib = sv.Calibration.from_file(data_dir / "eth3d" / "terrace" / "calib.txt")
    assert isinstance(got["step_5m"], float)
    assert got["step_5m"] == pytest.approx(25.0 / (calib.focal_px * calib.baseline_m))
    assert got["steps"] == pytest.approx(5.0 / (calib.focal_px * calib.baseline_m))
    assert 0.5 < got["depth_m"] < 20.0 and 0 < got["sigma_m"] < 1.0
    assert got["points"] == got["colors"] == got["image_points"] > 10_000
    assert 0 < got["near_points"] < got["points"]
    assert got["files"] == 1.0 and got["released"] == 1.0
    assert got["matches"] == got["read_back"] > 100 and 0 < got["strong_xyz"] <= got["matches"]
    assert got["optional_same"] == 1.0 and got["described"] > 100
    assert got["depth_ft"] == pytest.approx(got["depth_m"] / 0.3048, rel=1e-5)
    assert got["sigma_ft"] == pytest.approx(got["sigma_m"] / 0.3048, rel=1e-5)
    assert got["points_ft"] > 0
    assert got["camera_points"] == got["points"] and got["camera_dtype_f32"] == 1.0
    assert got["image_filled_points"] >= got["image_points"]
    assert 0 < got["voxels"] == got["voxel_colors"] < got["points"]
    assert got["live_points"] == 0.0  # cloud=False
    assert got["dispx"] == got["dispy"] > 0


def test_the_robotics_pipeline_runs(data_dir: Path, tmp_path: Path) -> None:
    """docs/robotics.md's snippet, as typed_user_script.robot, on KITTI (a floor in view)."""
    spec = importlib.util.spec_from_file_location("typed_user_script", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    scene = data_dir / "kitti2015" / "000005_10"
    left, right = module._read(scene / "left.png"), module._read(scene / "right.png")
    got = module.robot(left, right, scene / "calib.txt", tmp_path)
    assert got["saved"] == 0.0 and not (tmp_path / "rig_fixed.yaml").exists()  # still rectified
    assert got["described"] > 100 and got["files"] == 1.0
    assert got["points"] > 10_000 and got["obstacles"] > 0
    assert 0 < got["voxels"] == got["voxel_colors"] < got["points"]


def test_require_depth_returns_depth_or_says_why_there_is_none() -> None:
    rng = np.random.default_rng(0)
    left = rng.random((64, 96), dtype=np.float32)
    right = np.roll(left, -4, axis=1)
    bare = sv.depth_map(left, right, max_disparity=16)
    for accessor, what in ((bare.require_depth, "depth"),
                           (bare.require_depth_sigma, "depth uncertainty")):  # fmt: skip
        with pytest.raises(ValueError) as err:
            accessor()
        assert str(err.value).startswith(f"no {what}: depth_map was called without a calibration")
        assert "calib=Calibration.from_file(...)" in str(err.value)
    calib = sv.Calibration.ideal((96, 64), 90.0, 0.1)
    res = sv.depth_map(left, right, calib, max_disparity=16)
    assert res.require_depth() is res.depth
    assert res.require_depth_sigma() is res.depth_sigma
    assert float(np.nanmedian(res.require_depth())) == pytest.approx(
        calib.focal_px * 0.1 / 4, rel=0.05
    )


def test_calibration_methods_take_disparity_like_the_functions() -> None:
    """``Calibration.depth_from_disparity`` / ``.reproject`` called it ``disp``, the functions of
    the same name ``disparity``: the methods say ``disparity`` now, ``disp=`` still works with a
    DeprecationWarning at the caller's line, and both at once is a TypeError."""
    import inspect
    import warnings

    from stereovision import triangulation

    calib = sv.Calibration.ideal((64, 48), 90.0, 0.1)
    d = np.full((48, 64), 8.0, dtype=np.float32)
    for method, function in ((sv.Calibration.depth_from_disparity, sv.depth_from_disparity),
                             (sv.Calibration.reproject, triangulation.reproject)):  # fmt: skip
        assert list(inspect.signature(method).parameters)[1:] == ["disparity", "unit"]
        assert list(inspect.signature(function).parameters)[:2] == ["disparity", "calib"]
        name = method.__name__
        bound = getattr(calib, name)
        want = function(d, calib)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            np.testing.assert_array_equal(bound(d), want)
            np.testing.assert_array_equal(bound(disparity=d, unit="m"), want)
        with pytest.warns(DeprecationWarning) as caught:
            old = bound(disp=d)
        np.testing.assert_array_equal(old, want)
        assert str(caught[0].message) == (
            f"Calibration.{name}(): the keyword disp= is now disparity= (disp= will be removed)"
        )
        assert caught[0].filename == __file__
        with pytest.raises(TypeError, match=f"^Calibration.{name}\\(\\) got disp= and disparity="):
            bound(d, disp=d)
        with pytest.raises(TypeError, match="disp= and disparity="):
            bound(disparity=d, disp=d)


def test_mypy_strict_types_ranges_channels_and_steps_as_they_are(
    tmp_path: Path, mypy_cache: Path
) -> None:
    """``match(max_disparity=res.max_disparity)`` (a float, as depth_map's) was refused
    (``int | None``), ``res.channels[...]`` was ``Any``, and ``depth_step(np.float32(5))`` an
    array: the first script passes, the second is refused where it is wrong."""
    right = tmp_path / "right.py"
    right.write_text(
        "import numpy as np\nimport numpy.typing as npt\nimport stereovision as sv\n"
        "from stereovision.depth import DepthChannels\n"
        "from stereovision.matching.fusion import FusionResult\n"
        "from stereovision.matching.gabor import GaborResult\n\n\n"
        "def rematch(a: npt.NDArray[np.uint8], res: sv.DepthResult) -> sv.Matches:\n"
        "    return sv.match(a, a, max_disparity=res.max_disparity)\n\n\n"
        "def members(res: sv.DepthResult) -> FusionResult | None:\n"
        "    ch = res.channels\n"
        "    return None if ch is None or 'members' not in ch else ch['members']\n\n\n"
        "def gabor(ch: DepthChannels) -> GaborResult:\n    return ch['gabor']\n\n\n"
        "def sgm(ch: DepthChannels) -> npt.NDArray[np.float32]:\n    return ch['sgm']\n\n\n"
        "def step(calib: sv.Calibration) -> float:\n"
        "    return calib.depth_step(np.float32(5.0)) + calib.depth_step(np.int64(5))\n"
    )
    run = _mypy_strict(right, tmp_path, mypy_cache)
    assert run.stdout + run.stderr == ""
    assert run.returncode == 0
    wrong = tmp_path / "wrong.py"
    wrong.write_text(
        "import numpy as np\nimport numpy.typing as npt\n"
        "from stereovision.depth import DepthChannels\n\n\n"
        "def sgm(ch: DepthChannels) -> npt.NDArray[np.float32]:\n    return ch['census']\n"
    )
    run = _mypy_strict(wrong, tmp_path, mypy_cache)
    assert run.returncode == 1
    lines = run.stdout.splitlines()
    assert all(ln.startswith("wrong.py:7: error: ") for ln in lines), run.stdout
    assert 'wrong.py:7: error: TypedDict "DepthChannels" has no key "census"  [typeddict-item]' in (
        lines
    )


def test_mypy_strict_types_channel_outputs(tmp_path: Path, mypy_cache: Path) -> None:
    """``FusionResult.channel_outputs`` was ``dict[str, Any]``: any key passed and every value
    was ``Any``. It is the TypedDict ``ChannelOutputs`` (whose keys ``DepthChannels`` shares):
    the right reads pass, a key it never holds is refused."""
    script = tmp_path / "outputs.py"
    script.write_text(
        "import numpy as np\nimport numpy.typing as npt\n"
        "from stereovision.depth import DepthChannels\n"
        "from stereovision.matches import Matches\n"
        "from stereovision.matching.fusion import ChannelOutputs, FusionResult\n"
        "from stereovision.matching.gabor import GaborResult\n\n\n"
        "def gabor(fr: FusionResult) -> GaborResult:\n    return fr.channel_outputs['gabor']\n\n\n"
        "def mcgm(out: ChannelOutputs) -> Matches | None:\n    return out.get('mcgm')\n\n\n"
        "def keep(fr: FusionResult, ch: DepthChannels) -> None:\n"
        "    ch.update({**fr.channel_outputs, 'members': fr})\n\n\n"
        "def sgm(fr: FusionResult) -> npt.NDArray[np.float32]:\n"
        "    return fr.channel_outputs['census']\n"
    )
    run = _mypy_strict(script, tmp_path, mypy_cache)
    assert run.returncode == 1
    lines = run.stdout.splitlines()
    assert all(ln.startswith("outputs.py:22: error: ") for ln in lines), run.stdout  # only sgm
    refused = 'TypedDict "ChannelOutputs" has no key "census"  [typeddict-item]'
    assert f"outputs.py:22: error: {refused}" in lines, run.stdout


def test_fuse_pair_channel_outputs_are_channel_outputs_keys() -> None:
    """What fuse_pair fills is what ChannelOutputs names, with those types."""
    import typing

    from stereovision.depth import DepthChannels
    from stereovision.matching.fusion import ChannelOutputs, fuse_pair

    hints = typing.get_type_hints(ChannelOutputs)
    assert set(hints) == {"gabor", "gabor_remeasured", "mcgm", "hopfield", "sgm"}
    assert DepthChannels.__optional_keys__ == set(hints) | {"members"}
    rng = np.random.default_rng(0)
    left = rng.random((64, 96), dtype=np.float32)
    fr = fuse_pair(left, np.roll(left, -4, axis=1), max_disparity=16, dense_sgm=True)
    assert set(fr.channel_outputs) == set(hints)
    for k, v in fr.channel_outputs.items():
        assert isinstance(v, typing.get_origin(hints[k]) or hints[k]), k


def test_channels_hold_the_keys_and_types_depth_channels_names() -> None:
    from stereovision.depth import DepthChannels
    from stereovision.matching.fusion import FusionResult
    from stereovision.matching.gabor import GaborResult

    rng = np.random.default_rng(0)
    left = rng.random((64, 96), dtype=np.float32)
    right = np.roll(left, -4, axis=1)
    want = {
        "fused": {"gabor", "gabor_remeasured", "mcgm", "hopfield", "members", "sgm"},
        "gabor": {"gabor"},
        "census": {"sgm"},
        "fast": {"sgm"},
    }
    assert set(want) == set(sv.depth.METHODS)
    assert DepthChannels.__optional_keys__ == want["fused"]
    kinds: dict[str, type] = {"gabor": GaborResult, "members": FusionResult}
    kinds |= {"mcgm": sv.Matches, "hopfield": sv.Matches}
    kinds |= {"gabor_remeasured": np.ndarray, "sgm": np.ndarray}
    for method, keys in want.items():
        ch = sv.depth_map(left, right, method=method, max_disparity=16, return_channels=True)
        assert ch.channels is not None and set(ch.channels) == keys, method
        for k, v in ch.channels.items():
            assert isinstance(v, kinds[k]), (method, k)
            if isinstance(v, np.ndarray):
                assert v.dtype == np.float32 and v.shape == (64, 96)


def test_match_takes_a_fractional_range_as_documented() -> None:
    """A true shift of 17 px with ``max_disparity=16.5``: the whole-pixel searchers search up to
    17 and the matches above 16.5 are dropped (counted); gabor searches up to 16.5."""
    rng = np.random.default_rng(1)
    left = rng.random((80, 128), dtype=np.float32)
    right = np.roll(left, -17, axis=1)
    for method in ("hopfield", "best", "mcgm"):
        whole = sv.match(left, right, method=method, max_disparity=17)
        assert len(whole) > 50 and np.median(whole.xl - whole.xr) == pytest.approx(17, abs=0.2)
        frac = sv.match(left, right, method=method, max_disparity=16.5)
        d = frac.xl - frac.xr
        assert np.all(d <= 16.5), method
        assert frac.stats["n_out_of_range"] >= int(np.count_nonzero(whole.xl - whole.xr > 16.5))
        assert len(frac) < len(whole) / 2, method
    for method in ("gabor", "fused"):
        frac = sv.match(left, right, method=method, max_disparity=16.5)
        assert np.all(frac.xl - frac.xr <= 16.5), method
    assert (
        sv.match(left, right, method="best", max_disparity=np.float64(16.5)).stats["n_out_of_range"]
        == sv.match(left, right, method="best", max_disparity=16.5).stats["n_out_of_range"]
    )


def test_mypy_strict_types_voxel_downsample_colors_by_what_was_given(
    tmp_path: Path, mypy_cache: Path
) -> None:
    """``pts, rgb = export.voxel_downsample(res.points, res.colors)`` (the README's) typed
    ``rgb`` as ``ndarray | None``, so a typed user's ``rgb[:, 0]`` was refused: colours given
    come back as an array, none given as None, an optional one as optional."""
    script = tmp_path / "voxels.py"
    script.write_text(
        "import numpy as np\nimport numpy.typing as npt\nimport stereovision as sv\n"
        "from stereovision import export\n\n\n"
        "def given(res: sv.DepthResult) -> npt.NDArray[np.uint8]:\n"
        "    return export.voxel_downsample(res.points, res.colors, voxel=0.05)[1]\n\n\n"
        "def none(res: sv.DepthResult) -> None:\n"
        "    return export.voxel_downsample(res.points)[1]\n\n\n"
        "def maybe(res: sv.DepthResult, c: npt.NDArray[np.uint8] | None) -> npt.NDArray[np.uint8]:"
        "\n    return export.voxel_downsample(res.points, c)[1]\n"
    )
    run = _mypy_strict(script, tmp_path, mypy_cache)
    assert run.returncode == 1
    lines = run.stdout.splitlines()
    assert len(lines) == 1, run.stdout  # only the optional colours stay optional
    assert lines[0].startswith("voxels.py:16: error: Incompatible return value type (got ")
    assert '| None", expected "ndarray[' in lines[0]
