"""The examples in the package's docstrings run and print what they say (so they do not rot)."""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import stereovision

MODULES = sorted(
    m.name
    for m in pkgutil.walk_packages(stereovision.__path__, "stereovision.")
    if not m.name.endswith("__main__")
)


#: Examples that read the shared data: the module, and the name its example reads the folder
#: from (given here as the fixtures find the data, not as a path of one machine).
NEEDS_DATA = {"stereovision.calibrate": ("chessboard", "chessboard")}


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name: str, request: pytest.FixtureRequest) -> None:
    globs: dict[str, str] = {}
    if name in NEEDS_DATA:
        folder, glob_name = NEEDS_DATA[name]
        path = request.getfixturevalue("data_dir") / folder  # skips without the shared data
        if not path.is_dir():
            pytest.skip(f"{name}'s example reads {folder}/ of the shared data: {path} not found")
        globs[glob_name] = str(path)
    module = importlib.import_module(name)
    result = doctest.testmod(
        module, extraglobs=globs, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    )
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
    if name in NEEDS_DATA:
        assert result.attempted >= 4, result  # the data's example ran, not skipped


def test_examples_name_no_machine_path() -> None:
    """An example naming one machine's folder (calibrate's read /work/shared/data/chessboard)
    fails everywhere else."""
    for name in MODULES:
        finder = doctest.DocTestFinder()
        for t in finder.find(importlib.import_module(name)):
            for ex in t.examples:
                assert "/work/" not in ex.source and "/tmp/" not in ex.source, (t.name, ex.source)


def test_the_examples_are_there() -> None:
    """The public entry points carry examples (a renamed module would otherwise pass silently)."""
    names = ["stereovision.depth", "stereovision.matching.mcgm", "stereovision.matching.hopfield"]
    attempted = {
        name: doctest.testmod(importlib.import_module(name), report=False).attempted
        for name in names
    }
    assert all(n >= 3 for n in attempted.values()), attempted
