"""The examples in the package's docstrings run and print what they say (so they do not rot)."""

from __future__ import annotations

import doctest
import importlib
import pkgutil
from pathlib import Path

import pytest

import stereovision

MODULES = sorted(
    m.name
    for m in pkgutil.walk_packages(stereovision.__path__, "stereovision.")
    if not m.name.endswith("__main__")
)


# calibrate's example reads OpenCV's chessboard pairs from the shared data folder.
NEEDS_DATA = {"stereovision.calibrate": Path("/work/shared/data/chessboard")}


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name: str) -> None:
    if name in NEEDS_DATA and not NEEDS_DATA[name].is_dir():
        pytest.skip(f"{NEEDS_DATA[name]} not found")
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"


def test_the_examples_are_there() -> None:
    """The public entry points carry examples (a renamed module would otherwise pass silently)."""
    names = ["stereovision.depth", "stereovision.matching.mcgm", "stereovision.matching.hopfield"]
    attempted = {
        name: doctest.testmod(importlib.import_module(name), report=False).attempted
        for name in names
    }
    assert all(n >= 3 for n in attempted.values()), attempted
