"""The typed stub ``_core.pyi`` says what the extension really exports, with its parameters.

``mypy.stubtest`` imports the built module and compares every function's name, parameters
(PyO3 gives each one a text signature) and defaults with the stub's: a kernel added, renamed or
given a new parameter without its stub fails here, not in a user's type checker.
"""

from __future__ import annotations

import subprocess
import sys


def test_stub_matches_the_built_extension() -> None:
    run = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "stereovision._core"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
    assert "Success" in run.stdout


def test_public_signatures_resolve_at_run_time() -> None:
    """``typing.get_type_hints`` (beartype, pydantic, typer) raised NameError on 25 public
    functions whose annotations named classes imported only for type checkers. pyvista's
    ``pv.PolyData`` stays unresolved: importing pyvista takes most of a second."""
    import importlib
    import inspect
    import typing

    modules = ["stereovision", "stereovision.depth", "stereovision.ground",
               "stereovision.export", "stereovision.render", "stereovision.calibration",
               "stereovision.evaluate", "stereovision.calibrate"]  # fmt: skip
    unresolved = []
    for name in modules:
        mod = importlib.import_module(name)
        for attr in getattr(mod, "__all__", []):
            obj = getattr(mod, attr)
            fns = [obj] if inspect.isfunction(obj) else []
            if inspect.isclass(obj):
                fns = [f for k, f in vars(obj).items() if inspect.isfunction(f) and k[0] != "_"]
            for fn in fns:
                try:
                    typing.get_type_hints(fn)
                except NameError as exc:
                    if "'pv'" not in str(exc):
                        unresolved.append(f"{name}.{fn.__qualname__}: {exc}")
    assert unresolved == []


def test_stub_defaults_are_the_extensions_values() -> None:
    """``stubtest`` takes a default of ``...`` for any value: ``hopfield_interest``'s four
    defaults were ``...`` in the stub, so an editor showed no default at all. Every default the
    extension's text signature gives is written out in the stub, with its value."""
    import ast
    import inspect
    from pathlib import Path

    from stereovision import _core

    stub = ast.parse(Path(inspect.getfile(_core)).with_name("_core.pyi").read_text())
    written: dict[str, dict[str, object]] = {}
    for node in stub.body:
        if isinstance(node, ast.FunctionDef):
            args = node.args
            pos = args.posonlyargs + args.args
            pairs = list(zip(pos[len(pos) - len(args.defaults) :], args.defaults, strict=True))
            pairs += [
                (a, d)
                for a, d in zip(args.kwonlyargs, args.kw_defaults, strict=True)
                if d is not None
            ]
            written[node.name] = {a.arg: ast.literal_eval(d) for a, d in pairs}
    for name in _core.__all__ if hasattr(_core, "__all__") else dir(_core):
        fn = getattr(_core, name)
        if not callable(fn) or not fn.__text_signature__:
            continue
        sig = inspect.signature(fn)
        real = {p: v.default for p, v in sig.parameters.items() if v.default is not v.empty}
        assert written[name] == real, name
