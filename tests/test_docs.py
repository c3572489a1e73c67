"""The README and docs/ stay navigable: every relative link and picture points at a file that
exists, every in-page anchor names a heading, and the Quick start has its two commands."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK = re.compile(r"\]\(([^)\s]+)\)")


def _anchors(page: Path) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces to hyphens."""
    out = set()
    for line in page.read_text().splitlines():
        if line.startswith("#"):
            text = line.lstrip("#").strip().lower()
            out.add(re.sub(r"[^\w\- ]", "", text).replace(" ", "-"))
    return out


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_links_and_pictures_resolve(page: Path) -> None:
    broken = []
    for target in LINK.findall(page.read_text()):
        if target.startswith(("http://", "https://", "mailto:")):
            continue
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        if not dest.exists():
            broken.append(target)
        elif anchor and dest.suffix == ".md" and anchor not in _anchors(dest):
            broken.append(target)
    assert not broken, f"{page.name}: {broken}"


def test_quick_start_has_the_two_commands() -> None:
    text = (ROOT / "README.md").read_text()
    quick = text.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"```\n(.*?)```", quick, re.S)
    assert block is not None
    assert block.group(1).split("\n")[:-1] == ["make demo", "make test"]


ARCH = ROOT / "docs" / "architecture.md"
TREE_ROOTS = ("rust/core/src/", "rust/py/src/", "python/stereovision/", "tests/", "benches/")
SNAKE = re.compile(r"\b[a-z][a-z0-9]*(?:_[a-z0-9]+)+\b")


def _tree() -> list[tuple[str, str]]:
    """architecture.md's file tree as (path, description) entries: a top-level line names a file
    or, ending in ``/``, the folder of the indented entries below it; a line indented deeper is
    the description going on."""
    block = ARCH.read_text().split("```\n", 2)[1]
    entries: list[tuple[str, str]] = []
    folder = ""
    for line in block.splitlines():
        indent = len(line) - len(line.lstrip())
        if indent > 2:  # a description going on
            path, text = entries[-1]
            entries[-1] = (path, f"{text} {line.strip()}")
            continue
        name, _, text = line.strip().partition("  ")
        if indent == 0:
            folder = name if name.endswith("/") else ""
        for part in name.split(","):
            part = part.strip()
            if part:
                entries.append((part if indent == 0 else folder + part, text.strip()))
    return entries


def test_architecture_tree_names_only_what_exists() -> None:
    missing = [p for p, _ in _tree() if not list(ROOT.glob(p.rstrip("/")))]
    assert not missing, f"architecture.md names paths that do not exist: {missing}"


def test_architecture_tree_names_every_source_file() -> None:
    """Every Rust source (unit-test modules aside) and every Python module is in the tree, by
    its own line or named in its folder's line."""
    entries = _tree()
    named = {p for p, _ in entries}
    in_folder = {p: text for p, text in entries if p.endswith("/")}
    sources = [
        *ROOT.glob("rust/core/src/**/*.rs"),
        *ROOT.glob("rust/py/src/**/*.rs"),
        *ROOT.glob("python/stereovision/**/*.py"),
    ]
    unnamed = []
    for f in sources:
        rel = f.relative_to(ROOT).as_posix()
        if f.name == "tests.rs" or "/data/" in rel:
            continue
        parent = rel.rsplit("/", 1)[0] + "/"
        if rel not in named and not re.search(rf"\b{re.escape(f.name)}", in_folder.get(parent, "")):
            unnamed.append(rel)
    assert not unnamed, f"architecture.md does not name: {unnamed}"


def test_architecture_names_are_in_their_files() -> None:
    """A function, type or constant the tree names (snake_case or CamelCase) occurs in the file
    it is named under (or is the package's public API), so a renamed or moved one is caught."""
    camel = re.compile(r"\b[A-Z][a-z0-9]+[A-Z][a-z]\w*\b")
    public = (ROOT / "python/stereovision/__init__.py").read_text()  # named across files
    wrong = []
    for path, text in _tree():
        if not path.startswith(TREE_ROOTS[:3]) or path.endswith("/") or "*" in path:
            continue
        source = (ROOT / path).read_text()
        for name in {*SNAKE.findall(text), *camel.findall(text)}:
            if name not in source and name not in public:
                wrong.append(f"{path}: {name}")
    assert not wrong, f"architecture.md names what its file does not hold: {wrong}"


def test_architecture_lists_every_binding() -> None:
    """Every function the extension registers is named in the line of the file defining it
    (``hopfield_match (and _u8)`` names ``hopfield_match_u8``)."""
    lib = (ROOT / "rust/py/src/lib.rs").read_text()
    texts = dict(_tree())
    unnamed = []
    for module, name in re.findall(r"wrap_pyfunction!\((?:(\w+)::)?(\w+)", lib):
        path = f"rust/py/src/{module or 'lib'}.rs"
        words = set(re.findall(r"\w+", texts.get(path, "")))
        stem, _, tail = name.rpartition("_")
        if name not in words and not (stem in words and f"_{tail}" in words):
            unnamed.append(f"{path}: {name}")
    assert not unnamed, f"architecture.md does not list these bindings: {unnamed}"


def _resolves(dotted: str) -> bool:
    """Whether ``stereovision.a.b.c`` names a module, then attributes (or dataclass fields)."""
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj: object = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for name in parts[i:]:
            fields = {
                **getattr(obj, "__dataclass_fields__", {}),
                **getattr(obj, "__annotations__", {}),
            }
            if hasattr(obj, name):
                obj = getattr(obj, name)
            elif name in fields and name == parts[-1]:
                return True
            else:
                return False
        return True
    return False


def test_docstring_cross_references_resolve() -> None:
    """Every ``:func:`` / ``:class:`` / ... reference written with its full ``stereovision.``
    path, in the package's sources, names something that exists (a renamed function leaves
    none behind)."""
    import stereovision

    role = re.compile(r":(?:func|class|meth|mod|data|attr|exc):`~?(stereovision\.[\w.]+)`")
    broken = []
    for info in pkgutil.walk_packages(stereovision.__path__, "stereovision."):
        if info.name.endswith("__main__"):
            continue
        try:
            module = importlib.import_module(info.name)
            source = inspect.getsource(module)
        except (ImportError, OSError):  # an optional extra not installed; the compiled _core
            continue
        broken += [
            f"{info.name}: {n}" for n in sorted(set(role.findall(source))) if not _resolves(n)
        ]
    assert not broken, f"docstrings refer to names that do not exist: {broken}"


def test_help_texts_state_the_defaults() -> None:
    """An option with a default value (a folder, a number, a name) says it in its --help; a
    zero (no move, no offset) goes without saying."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    unsaid = []
    for command, sub in commands.choices.items():
        for action in sub._actions:
            default = action.default
            if isinstance(default, bool) or not isinstance(default, (str, int, float)):
                continue
            if default == argparse.SUPPRESS or (not isinstance(default, str) and default == 0):
                continue
            text = action.help or ""
            said = f"{default:g}" if isinstance(default, float) else str(default)
            if said not in text and not (default == "auto" and "default" in text):
                unsaid.append(f"{command} {action.option_strings[0]} (default {default!r})")
    assert not unsaid, f"--help does not say these defaults: {unsaid}"


def test_help_texts_say_what_the_option_is_beside_its_default() -> None:
    """`gui --port` said only "default 8080", `stream --max-disparity` only "default: estimated
    from the first pair" and `batch --max-disparity` "for every pair (default: per pair)": not
    what the option is, nor its unit. Each option's help says more than its default, and each
    --max-disparity that it is the range searched, in pixels."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    bare, no_unit = [], []
    for command, sub in commands.choices.items():
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            text = action.help or ""
            rest = re.sub(r"\(?\bdefault\b[^;)]*\)?", "", text).strip(" ;,.:")
            if len(rest.split()) < 2:
                bare.append(f"{command} {action.option_strings or action.dest}: {text!r}")
            if "--max-disparity" in action.option_strings and "in pixels" not in text:
                no_unit.append(f"{command}: {text!r}")
    assert not bare, f"--help gives only the default of: {bare}"
    assert not no_unit, f"--max-disparity without its unit: {no_unit}"


def test_every_default_a_help_text_names_is_the_parsers() -> None:
    """A second read of the help texts (f13e4d4, 89f2cb2) checked each by hand: every
    default an option's help names as a value ("(default 0.5)", "m (default)", "auto, the
    default") is the default argparse gives it. Held here, so that a default changed in
    add_argument without its help (or the reverse) is caught."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    said = re.compile(r"\bdefault:? ([^;),]+)|([\w.]+) \(default\)|\(([\w.]+), the default\)")
    checked, wrong = 0, []
    for command, sub in commands.choices.items():
        for action in sub._actions:
            if action.default in (None, argparse.SUPPRESS) or isinstance(action.default, bool):
                continue  # resolved later (the method's, found, estimated): said in words
            for m in said.finditer(action.help or ""):
                value = next(g for g in m.groups() if g)
                if action.default == "auto" and value != "auto":
                    continue  # a sentinel said by what it does ("found from the images")
                if isinstance(action.default, (int, float)):
                    same = float(value) == action.default
                else:
                    same = value == action.default
                checked += 1
                if not same:
                    wrong.append(f"{command} {action.option_strings}: {value!r}")
    assert not wrong, f"a help names another default than the parser's: {wrong}"
    # The options above, not a pattern that matches nothing (18 since 70673a2 and 9681991
    # made --serve, --host and --fill/--no-fill default to None, applied where used).
    assert checked >= 18, checked
    # stream --serve and --host are held to FrameServer's own defaults, applied where served.
    from stereovision.stream import FrameServer

    server = inspect.signature(FrameServer.__init__).parameters
    stream = commands.choices["stream"]
    for option, param in (("--serve", "port"), ("--host", "host")):
        action = next(a for a in stream._actions if option in a.option_strings)
        assert f"(default {server[param].default})" in (action.help or ""), (option, action.help)


def test_board_side_options_say_their_unit() -> None:
    """`capture --square` said "--charuco: square side", no unit, where calibrate's and board's
    say "in --unit" (capture has none: any unit does, only the ratio to --marker is used)."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    unsaid = [
        f"{command} {action.option_strings[0]}: {action.help!r}"
        for command, sub in commands.choices.items()
        for action in sub._actions
        if {"--square", "--marker"} & set(action.option_strings)
        and not re.search(r"\bunit\b", action.help or "")
    ]
    assert not unsaid, f"a board side without its unit: {unsaid}"


def test_batch_help_names_both_scene_calibrations() -> None:
    """batch reads a scene's calib.txt, else its Q.dat (batch.md); its --help says both."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    batch = commands.choices["batch"]
    calib = next(a for a in batch._actions if "--calib" in a.option_strings)
    assert "Q.dat" in (batch.description or "")
    assert "calib.txt or Q.dat" in (calib.help or "")


def test_readme_pipeline_table_matches_the_tree() -> None:
    """README's "pipeline, by folder" table names only files that exist, and every stage's
    source: every Python module and every Rust kernel file (the crate's plumbing aside)."""
    text = (ROOT / "README.md").read_text()
    table = text.split("## The pipeline, by folder", 1)[1].strip().split("\n\n", 1)[0]
    rust, python = set(), set()
    for row in table.splitlines()[2:]:
        cells = row.split("|")
        rust |= set(re.findall(r"`([^`]+)`", cells[2]))
        python |= set(re.findall(r"`([^`]+)`", cells[3]))
    core, pkg = ROOT / "rust/core/src", ROOT / "python/stereovision"
    missing = [n for n in rust if not (core / n).exists()]
    missing += [n for n in python if not (pkg / n).exists()]
    assert not missing, f"README's pipeline table names files that do not exist: {missing}"
    plumbing = {"lib.rs", "alloc.rs", "parallel.rs", "simd.rs", "matching/mod.rs"}
    unnamed = [
        f.relative_to(core).as_posix()
        for f in core.rglob("*.rs")
        if f.parent == core or f.parent.name == "matching"
    ]
    unnamed = [n for n in unnamed if n not in rust | plumbing]
    modules = [f.relative_to(pkg).as_posix() for f in pkg.rglob("*.py") if "gui" not in f.parts]
    unnamed += [m for m in modules if not m.rsplit("/", 1)[-1].startswith("__")]
    unnamed = [n for n in unnamed if n not in python | rust | plumbing | {"_interrupt.py"}]
    assert not unnamed, f"README's pipeline table leaves out: {unnamed}"


def test_depth_module_docstring_names_every_method() -> None:
    """The entry point's module docstring (the first thing `help(stereovision.depth)` shows) names
    each method and which is the default, as the signature has it."""
    from stereovision import depth

    signature = inspect.signature(depth.depth_map)
    default = signature.parameters["method"].default
    doc = depth.__doc__ or ""
    unnamed = [m for m in depth.METHODS if f'``"{m}"``' not in doc]
    assert not unnamed, f"stereovision.depth's docstring leaves out: {unnamed}"
    assert f'``"{default}"`` (the default' in doc


def test_commands_in_code_blocks_parse() -> None:
    """Every `stereovision ...` line of a code block in the README and docs/ (what a reader
    pastes) is accepted by the command line's parser: no renamed option or command left behind.
    Synopses (with ``[`` or ``|``) are skipped; a one-letter placeholder (N, M) stands for 64."""
    import shlex

    from stereovision.cli import build_parser

    parser = build_parser()
    rejected = []
    checked = 0
    for page in PAGES:
        for block in re.findall(r"```[a-z]*\n(.*?)```", page.read_text(), re.S):
            for line in block.replace("\\\n", " ").splitlines():
                m = re.match(r"\s*(?:\w+\$ )?stereovision (.*)", line)
                if not m:
                    continue
                command = re.split(r"\s+#", m.group(1))[0]
                if "[" in command or "|" in command:
                    continue
                words = ["64" if re.fullmatch(r"[A-Z]", w) else w for w in shlex.split(command)]
                checked += 1
                try:
                    parser.parse_args(words)
                except SystemExit:
                    rejected.append(f"{page.name}: stereovision {command}")
    assert not rejected, f"commands the parser refuses: {rejected}"
    # 36 lines on 2026-12-04: a code-block or prompt format the pattern no longer reads (a
    # "$ stereovision" prompt, ```shell-session fences) left nothing checked, and the test passed
    assert checked >= 30, f"only {checked} command lines found in the code blocks"


def test_unit_options_list_the_units_accepted() -> None:
    """calibrate's and board's --unit help names every unit a calibration takes (feet too)."""
    import argparse

    from stereovision.calibration import UNIT_TO_METRES
    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for command in ("calibrate", "board"):
        unit = next(a for a in commands.choices[command]._actions if "--unit" in a.option_strings)
        words = set(re.findall(r"\w+", unit.help or ""))
        assert set(UNIT_TO_METRES) <= words, f"{command} --unit: {unit.help}"


def test_architecture_lists_every_command() -> None:
    """The tree's cli.py line lists the command line's commands, no more, no fewer."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    text = dict(_tree())["python/stereovision/cli.py"]
    listed = re.search(r"`stereovision ([^`]+)`", text)
    assert listed is not None
    assert [c.strip() for c in listed.group(1).split("|")] == list(commands.choices)


def test_the_readme_names_the_opencv_the_package_requires() -> None:
    """The README said the baselines' parameters were 'set through OpenCV 4' after the floor
    became opencv-python-headless>=5.1: every version it gives for the OpenCV in use is the
    pyproject's floor."""
    floor = re.search(r'"opencv-python-headless>=([\d.]+)"', (ROOT / "pyproject.toml").read_text())
    assert floor is not None
    text = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    assert "set through OpenCV 4" not in text
    assert f"set through the current OpenCV API, {floor.group(1)} or later" in text


_SECTION = re.compile(r"^([A-Z][A-Za-z ]+)\n-{3,}$", re.M)


def _numpydoc_sections(doc: str) -> dict[str, str]:
    marks = list(_SECTION.finditer(doc))
    return {
        m.group(1): doc[m.end() : marks[i + 1].start() if i + 1 < len(marks) else len(doc)]
        for i, m in enumerate(marks)
    }


def _public_api() -> list[tuple[str, object]]:
    """The functions a script calls: ``stereovision``'s exports (and their classes' public
    methods) and the public functions of ``export``, ``io`` and ``evaluate``."""
    import stereovision as sv

    out: list[tuple[str, object]] = []
    for name in sv.__all__:
        obj = getattr(sv, name)
        if inspect.isfunction(obj):
            out.append((name, obj))
        elif inspect.isclass(obj):
            for attr, value in vars(obj).items():
                if isinstance(value, (classmethod, staticmethod)):
                    value = value.__func__
                if not attr.startswith("_") and inspect.isfunction(value):
                    out.append((f"{name}.{attr}", value))
    for mod_name in ("stereovision.export", "stereovision.io", "stereovision.evaluate"):
        mod = importlib.import_module(mod_name)
        for attr, value in vars(mod).items():
            if not attr.startswith("_") and inspect.isfunction(value):
                if value.__module__ == mod_name:
                    out.append((f"{mod_name}.{attr}", value))
    return out


def test_public_functions_document_their_parameters_and_returns() -> None:
    """numpydoc: a public function taking arguments has a Parameters section naming exactly
    its signature's parameters, and every public function annotated to return a value (one
    without parameters too: ``release_memory``, ``Matches.to_array``) a Returns (or Yields)
    section."""
    problems = []
    for name, func in _public_api():
        doc = inspect.getdoc(func) or ""
        sig = inspect.signature(func)  # type: ignore[arg-type]
        params = [p for p in sig.parameters if p not in ("self", "cls")]
        if not doc:
            problems.append(f"{name}: no docstring")
            continue
        sections = _numpydoc_sections(doc)
        if params and "Parameters" not in sections:
            problems.append(f"{name}: no Parameters section for {params}")
        elif params:
            documented = {
                part.strip().lstrip("*")
                for line in sections["Parameters"].splitlines()
                if line and not line[0].isspace()
                for part in line.split(" : ")[0].split(",")
            }
            if documented != set(params):
                problems.append(f"{name}: Parameters {sorted(documented)} != {params}")
        returns = sig.return_annotation
        if returns not in (None, "None", inspect.Signature.empty) and not (
            {"Returns", "Yields"} & set(sections)
        ):
            problems.append(f"{name}: no Returns section")
    assert len(_public_api()) > 60
    assert not problems, "\n".join(problems)


def _exported() -> dict[int, tuple[str, object]]:
    """What ``stereovision`` and each of its modules' ``__all__`` export, by identity."""
    import stereovision as sv

    exported = {id(getattr(sv, name)): (name, getattr(sv, name)) for name in sv.__all__}
    for info in pkgutil.walk_packages(sv.__path__, "stereovision."):
        if info.name.endswith("__main__"):
            continue
        try:
            module = importlib.import_module(info.name)
        except ImportError:  # an optional extra not installed
            continue
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name, None)
            exported.setdefault(id(obj), (name, obj))
    return exported


def test_public_dataclasses_document_their_fields() -> None:
    """Every public field of a dataclass ``stereovision`` or one of its modules exports is
    named in its docstring's Parameters or Attributes: ``DepthResult.min_disparity`` and
    ``left_rectified`` (the image the cloud takes its colours from) were in none, nor 14 fields
    of 5 classes the modules export (``CaptureResult.saved``, ``StreamReport.density``, ...)."""
    import dataclasses

    undocumented, checked = [], 0
    for name, cls in _exported().values():
        if not (inspect.isclass(cls) and dataclasses.is_dataclass(cls)):
            continue
        sections = _numpydoc_sections(inspect.getdoc(cls) or "")
        said = {
            part.strip()
            for section in ("Parameters", "Attributes")
            for line in sections.get(section, "").splitlines()
            if line and not line[0].isspace()
            for part in line.split(" : ")[0].split(",")
        }
        for f in dataclasses.fields(cls):
            if not f.name.startswith("_"):
                checked += 1
                if f.name not in said:
                    undocumented.append(f"{name}.{f.name}")
    assert not undocumented, f"fields no docstring names: {undocumented}"
    assert checked >= 240, checked  # 261 on 2026-12-06


def test_public_classes_take_the_parameters_their_docstring_lists() -> None:
    """An exported class whose docstring has a Parameters section is made with exactly those
    parameters: dataclasses' generated constructors took their state too, so
    ``TemporalFilter(8, 3.0, 5)`` started at ``frames=5`` and ``ChessboardCollector(pattern,
    0.2, board)``, the documented order, put the board into ``kept``."""
    wrong, checked = [], 0
    for name, cls in _exported().values():
        if not inspect.isclass(cls):
            continue
        sections = _numpydoc_sections(inspect.getdoc(cls) or "")
        if "Parameters" not in sections:
            continue
        documented = {
            part.strip().lstrip("*")
            for line in sections["Parameters"].splitlines()
            if line and not line[0].isspace()
            for part in line.split(" : ")[0].split(",")
        }
        params = set(inspect.signature(cls).parameters)
        checked += 1
        if params != documented:
            wrong.append(f"{name}{sorted(params)}: documents {sorted(documented)}")
    assert not wrong, "constructors and their Parameters differ:\n" + "\n".join(wrong)
    assert checked >= 12, checked  # 13 on 2026-12-07


#: The modules whose classes and functions a user's script meets beyond ``_public_api``'s:
#: what ``depth_map``, ``check_rectification``, ``rectify_uncalibrated``, ``occupancy_grid`` and
#: the evaluation return, and the 3-D view's camera; the capture, ChArUco, stream and bench
#: modules and the matchers (35 of their functions had no Returns section). Not gui, batch and
#: rosbag (yet).
RETURNS_MODULES = ("depth", "matches", "ground", "calibration", "triangulation", "evaluate",
                   "rectification_check", "uncalibrated", "refine", "temporal", "render",
                   "export", "io", "capture", "charuco", "stream", "bench", "matching",
                   "matching.gabor", "matching.mcgm", "matching.hopfield", "matching.fusion",
                   "matching.sgm", "matching.planes")  # fmt: skip


def test_every_returned_value_is_documented() -> None:
    """numpydoc's Returns (or Yields) section on every function and public method of those
    modules' ``__all__`` annotated to return a value (``as_dict``, ``describe``, ``summary``
    had none)."""
    missing = []
    for short in RETURNS_MODULES:
        module = importlib.import_module(f"stereovision.{short}")
        for attr in module.__all__:
            obj = getattr(module, attr)
            funcs = [(attr, obj)] if inspect.isfunction(obj) else []
            if inspect.isclass(obj):
                for name, value in vars(obj).items():
                    if isinstance(value, (classmethod, staticmethod)):
                        value = value.__func__
                    if not name.startswith("_") and inspect.isfunction(value):
                        funcs.append((f"{attr}.{name}", value))
            for name, func in funcs:
                returns = inspect.signature(func).return_annotation
                if returns in (None, "None", inspect.Signature.empty):
                    continue
                sections = _numpydoc_sections(inspect.getdoc(func) or "")
                if not {"Returns", "Yields"} & set(sections):
                    missing.append(f"stereovision.{short}.{name}")
    assert not missing, f"no Returns section: {missing}"


def test_calib_unit_commands_are_the_ones_the_docs_list() -> None:
    """README and robotics.md list the commands that take --calib-unit; the list is the CLI's."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    taking = {
        name
        for name, sub in commands.choices.items()
        if any("--calib-unit" in a.option_strings for a in sub._actions)
    }
    readme = (ROOT / "README.md").read_text()
    robotics = (ROOT / "docs" / "robotics.md").read_text()
    said = {
        "README.md": re.search(r"on every command that loads a calibration: ([^)]*)\)", readme),
        "robotics.md": re.search(r"every command that loads a calibration \(([^)]*)\)", robotics),
    }
    for page, found in said.items():
        assert found is not None, f"{page} no longer lists the commands taking --calib-unit"
        listed = set(re.findall(r"`([a-z]+)`", " ".join(found.group(1).split())))
        assert listed == taking, f"{page}: lists {sorted(listed)}, the CLI {sorted(taking)}"


def test_quick_start_names_the_files_make_demo_prints(tmp_path: Path) -> None:
    """The Quick start's `demo_output/{...}` is the folder `make demo` writes into and the list
    of files `stereovision demo` prints as written (overview.png among them), the same set."""
    import subprocess
    import sys

    text = (ROOT / "README.md").read_text()
    quick = text.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    said = re.search(r"`demo_output/\{([^}]*)\}`", quick)
    assert said is not None, "the Quick start no longer lists demo_output's files"
    listed = {name.strip() for name in said.group(1).split(",")}
    target = re.search(r"^demo:.*\n\t(.*)$", (ROOT / "Makefile").read_text(), re.M)
    assert target is not None and target.group(1).endswith("stereovision demo -o demo_output")
    out = tmp_path / "demo_output"
    proc = subprocess.run(
        [sys.executable, "-m", "stereovision", "demo", "-o", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    written = proc.stdout.split(f"outputs in {out}:\n", 1)[1].splitlines()
    printed = {line.split()[0] for line in written if line.startswith("  ")}
    assert "overview.png" in printed
    assert printed == listed, f"README {sorted(listed)}, printed {sorted(printed)}"


def test_readme_synopsis_names_every_option() -> None:
    """The README's command-line synopsis (demo, depth, eval, check) names every option each
    command's --help lists: `depth --rectification` and `demo --method` were left out."""
    import argparse

    from stereovision.cli import build_parser

    text = (ROOT / "README.md").read_text()
    block = re.search(r"```\n(stereovision demo .*?)```", text, re.S)
    assert block is not None, "the README's synopsis block is gone"
    usage: dict[str, str] = {}
    command = ""
    for line in block.group(1).splitlines():
        start = re.match(r"stereovision (\w+)", line)
        command = start.group(1) if start else command
        usage[command] = usage.get(command, "") + line.split("  #", 1)[0]
    assert set(usage) == {"demo", "depth", "eval", "check"}
    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    unnamed = [
        f"{command} {action.option_strings[-1]}"
        for command, said in usage.items()
        for action in commands.choices[command]._actions
        if action.option_strings and "--help" not in action.option_strings
        if not any(re.search(re.escape(o) + r"(?![\w-])", said) for o in action.option_strings)
    ]
    assert not unnamed, f"README's synopsis leaves out: {unnamed}"


def test_readme_says_how_each_command_sizes_stereo_calib_output() -> None:
    """README's --calib-unit paragraph said to save stereo_calib output once as YAML for batch,
    stream and gui, which all size it from their pairs (docs/robotics.md); it names how each
    command taking --calib-unit sizes it."""
    text = " ".join((ROOT / "README.md").read_text().split())
    said = re.search(r"`stereo_calib` output holds no image size either: (.*?)\(\[docs/", text)
    assert said is not None, "README no longer says how stereo_calib output is sized"
    sentence = said.group(1)
    assert "YAML" not in sentence, sentence
    for command in ("depth", "check", "rectify", "info", "batch", "stream", "gui"):
        assert f"`{command}`" in sentence, command


def test_robotics_quotes_kittis_floor_as_the_fit_finds_it(data_dir: Path) -> None:
    """robotics.md quotes KITTI 000005's floor under the default depth map (its pipeline's 3b,
    and describe(unit="ft")); the seed-robust fit (a705382) moved it from 1.618 m (5.309 ft)
    to 1.625 m (5.331 ft), which `stereovision depth --ground --unit ft` prints, and the page
    still said the old figures."""
    import cv2

    import stereovision as sv

    kitti = data_dir / "kitti2015" / "000005_10"
    calib = sv.Calibration.from_file(kitti / "calib.txt")
    left, right = cv2.imread(str(kitti / "left.png")), cv2.imread(str(kitti / "right.png"))
    plane = sv.fit_ground_plane(sv.depth_map(left, right, calib).disparity, calib)
    assert plane is not None
    page = (ROOT / "docs" / "robotics.md").read_text()
    metres = re.search(r"camera \S+ m above it", plane.describe())
    feet = re.search(r"camera \S+ ft above it", plane.describe("ft"))
    assert metres is not None and feet is not None
    assert f"# KITTI: {metres.group(0)}, pitch" in page
    assert f"`{feet.group(0)}` on KITTI" in page


def _python_blocks(page: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", page.read_text(), re.S)


def test_readme_python_example_runs_as_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The README's "Using it" block, pasted as it stands into a script beside the bundled cones
    (its ``calib.txt``, ``left.png`` and ``right.png``), runs; what its comments name is what the
    calls return (``depth_counts()``'s keys, the channels and their types) and every file it
    writes is there. typed_user_script.py is a copy of it, which the README can drift from."""
    import shutil

    import numpy as np

    import stereovision as sv

    (block,) = _python_blocks(ROOT / "README.md")
    cones = Path(sv.__file__).parent / "data" / "cones"
    given = ("calib.txt", "left.png", "right.png")
    for name in given:
        shutil.copy(cones / name, tmp_path)
    monkeypatch.chdir(tmp_path)
    scope: dict[str, object] = {}
    exec(compile(block, "README.md", "exec"), scope)  # the README's own code

    res, fused, m = scope["res"], scope["fused"], scope["m"]
    assert isinstance(res, sv.DepthResult) and isinstance(fused, sv.DepthResult)
    assert isinstance(m, sv.Matches)
    assert res.disparity.shape == (375, 450) and res.disparity.dtype == np.float32
    counts = re.search(r"res\.depth_counts\(\)\s+# \{([^}]*)\}", block)
    assert counts is not None
    assert set(re.findall(r'"(\w+)"', counts.group(1))) == set(res.depth_counts())
    channels = re.search(r"fused\.channels\s+# \{(.*)\}", block)
    assert channels is not None and fused.channels is not None
    said = dict(re.findall(r'"(\w+)": (\w+)', channels.group(1)))
    assert {k: type(v).__name__ for k, v in fused.channels.items()} == said
    assert m.to_array().shape == (len(m), 4)
    written = set(re.findall(r'"(\w+\.(?:ply|png|csv))"', block)) - set(given)
    assert {"cloud.ply", "depth_mm.png", "matches.csv"} <= written  # 4 on 2026-12-06
    assert all((tmp_path / name).stat().st_size > 0 for name in written)


def test_robotics_pipeline_runs_as_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, data_dir: Path
) -> None:
    """docs/robotics.md's two Python blocks (the pipeline from the calibration to a robot's
    inputs, and the fisheye field's ``alpha=1``) run as written on KITTI 000005, its calibration
    saved as the ROS ``camera_info`` folder ``ros/`` the pipeline reads; the obstacles are the
    ``(H, W) bool`` its comment says, within the 8 m the depth is filtered to."""
    import cv2
    import numpy as np

    import stereovision as sv

    kitti = data_dir / "kitti2015" / "000005_10"
    left, right = cv2.imread(str(kitti / "left.png")), cv2.imread(str(kitti / "right.png"))
    monkeypatch.chdir(tmp_path)
    calib = sv.Calibration.from_file(kitti / "calib.txt")
    calib.save_ros("ros/")
    pipeline, fisheye = _python_blocks(ROOT / "docs" / "robotics.md")
    scope: dict[str, object] = {"left": left, "right": right}
    exec(compile(pipeline, "robotics.md", "exec"), scope)  # the page's own code

    res, obstacles = scope["res"], scope["obstacles"]
    assert isinstance(res, sv.DepthResult) and isinstance(obstacles, np.ndarray)
    assert obstacles.shape == left.shape[:2] and obstacles.dtype == np.bool_
    assert 0 < obstacles.sum() and np.nanmax(res.point_image(filled=True)[obstacles][:, 2]) <= 8
    assert (tmp_path / "depth_mm.png").stat().st_size > 0
    pts = scope["pts"]
    assert isinstance(pts, np.ndarray) and pts.shape[1] == 3

    scope = {"sv": sv, "left": left, "right": right, "calib": calib}
    exec(compile(fisheye, "robotics.md", "exec"), scope)
    res = scope["res"]
    assert isinstance(res, sv.DepthResult) and res.disparity.shape == left.shape[:2]


def _commands() -> dict[str, set[str]]:
    """Each command of the command line and the option strings it takes."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {
        name: {o for a in sub._actions for o in a.option_strings}
        for name, sub in commands.choices.items()
    }


def test_commands_named_in_the_prose_take_their_options() -> None:
    """A ``cmd ... --option`` quoted in the prose (`capture --fourcc`, `depth --unit ft`, `board
    -o`) names an option that command takes: the code-block test sees whole lines only."""
    commands = _commands()
    wrong, checked = [], 0
    for page in PAGES:
        prose = re.sub(r"```.*?```", "", page.read_text(), flags=re.S)
        for span in " ".join(prose.split()).split("`")[1::2]:
            m = re.match(r"(?:stereovision )?(\w+) (.*)", span)
            if not m or m.group(1) not in commands:
                continue
            for option in re.findall(r"(?<![\w-])(--?[a-z][\w-]*)", m.group(2)):
                checked += 1
                if option not in commands[m.group(1)]:
                    wrong.append(f"{page.name}: `{span}`: {option}")
    assert not wrong, f"options the command does not take: {wrong}"
    assert checked >= 60, checked  # 81 on 2026-12-06


def test_every_option_is_documented_with_its_command() -> None:
    """Every option a command's --help lists is named (by one of its option strings) in a
    paragraph of the README or docs/ that names that command (`stream`, `stereovision gui`) or
    on a code block's line running it (continued lines too): `stream --serve`, `--no-check`,
    `--no-pipeline`, `gui --port`, `--no-browser` and `board --dpi` were named nowhere. A code
    block's line counts for the command it runs only: `board --unit` passed as `depth ...
    --unit ft` two lines below `stereovision board ...` in one block."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    block = re.compile(r"```[a-z]*\n.*?```", re.S)
    paragraphs, runs = [], []  # prose paragraphs; (command, line) of the code blocks
    for page in PAGES:
        text = page.read_text()
        paragraphs += re.split(r"\n\s*\n", block.sub("\n\n", text))
        for code in block.findall(text):
            command, previous = "", ""
            for line in code.splitlines():
                start = re.match(r"\s*(?:\S+\$ )?(?:python -m )?stereovision (\w+)", line)
                if start:
                    command = start.group(1)
                elif not previous.split("#")[0].rstrip().endswith("\\"):  # not continued
                    command = ""
                runs.append((command, line))
                previous = line
    unnamed, checked = [], 0
    for command, sub in commands.choices.items():
        names_command = re.compile(rf"(?:`|stereovision )(?:stereovision )?{command}\b")
        with_command = [p for p in paragraphs if names_command.search(p)]
        with_command += [line for c, line in runs if c == command]
        for action in sub._actions:
            if not action.option_strings or "--help" in action.option_strings:
                continue
            checked += 1
            named = re.compile("|".join(re.escape(o) + r"(?![\w-])" for o in action.option_strings))
            if not any(named.search(p) for p in with_command):
                unnamed.append(f"{command} {action.option_strings[-1]}")
    assert not unnamed, f"options no paragraph naming their command names: {unnamed}"
    assert checked >= 140, checked  # 151 on 2026-12-06


def test_synopsis_choices_are_the_parsers() -> None:
    """An option shown with its values (`--method fused|gabor|census|fast`, `--unit m|ft|...`)
    in a code block lists exactly the values the parser accepts."""
    import argparse

    from stereovision.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    wrong, checked = [], 0
    for page in PAGES:
        for block in re.findall(r"```[a-z]*\n(.*?)```", page.read_text(), re.S):
            command = ""
            for line in block.splitlines():
                start = re.match(r"\s*(?:\w+\$ )?stereovision (\w+)", line)
                command = start.group(1) if start else command
                sub = commands.choices.get(command)
                for option, values in re.findall(r"(--[\w-]+) (\w+(?:\|\w+)+)", line):
                    action = next(a for a in sub._actions if option in a.option_strings)
                    checked += 1
                    if set(values.split("|")) != set(action.choices or ()):
                        wrong.append(f"{page.name}: {command} {option} {values}")
    assert not wrong, f"values that are not the parser's: {wrong}"
    assert checked >= 2, checked


def _api_names() -> dict[str, list[object]]:
    """Every public function, class and method of the package, by name."""
    import stereovision

    names: dict[str, list[object]] = {}
    for info in pkgutil.walk_packages(stereovision.__path__, "stereovision."):
        if info.name.endswith("__main__"):
            continue
        try:
            module = importlib.import_module(info.name)
        except ImportError:  # an optional extra not installed
            continue
        for name, obj in vars(module).items():
            if name.startswith("_"):
                continue
            if inspect.isclass(obj):
                names.setdefault(name, []).append(obj)
                for attr, value in vars(obj).items():
                    if isinstance(value, (classmethod, staticmethod)):
                        value = value.__func__
                    if not attr.startswith("_") and inspect.isfunction(value):
                        names.setdefault(attr, []).append(value)
            elif inspect.isfunction(obj):
                names.setdefault(name, []).append(obj)
    return names


FILE_SUFFIX = re.compile(
    r"\.(?:py|pyi|rs|md|txt|csv|yaml|yml|json|png|jpg|dat|ply|pcd|npz|npy|pfm|html|bag|mp4|avi"
    r"|gz|db3|mcap)\b"
)


def test_names_the_docs_give_exist() -> None:
    """Every ``sv.name`` / ``stereovision.module.name`` / ``module.name`` (``fusion.remeasure``)
    and every ``Class.attribute`` of the package's classes (``Calibration.scaled_to``,
    ``GroundPlane.below_share``) that the README and docs/ name exists: a renamed function
    leaves no stale name in the prose."""
    import stereovision

    names = _api_names()
    classes = {n: objs for n, objs in names.items() if any(inspect.isclass(o) for o in objs)}
    modules: dict[str, list[str]] = {}  # `fusion.census_clear`, `capture.temporal_average`
    for info in pkgutil.walk_packages(stereovision.__path__, "stereovision."):
        modules.setdefault(info.name.rsplit(".", 1)[1], []).append(info.name)
    broken, checked = [], 0
    for page in PAGES:
        text = page.read_text()
        for dotted in re.findall(r"(?<![\w.])((?:sv|stereovision)(?:\.\w+)+)", text):
            full = "stereovision" + dotted[2:] if dotted.startswith("sv.") else dotted
            checked += 1
            if not _resolves(full):
                broken.append(f"{page.name}: {dotted}")
        for module, rest in re.findall(r"(?<![\w./])([a-z_]+)((?:\.[A-Za-z_]\w*)+)", text):
            if module not in modules or FILE_SUFFIX.match(rest):  # `io.py`, `depth.png`
                continue
            checked += 1
            if not any(_resolves(full + rest) for full in modules[module]):
                broken.append(f"{page.name}: {module}{rest}")
        for cls, attr in re.findall(r"(?<![\w.])([A-Z]\w+)\.([a-z_]\w*)\b(?!\.\w)", text):
            if cls not in classes:
                continue
            owners = [o for o in classes[cls] if inspect.isclass(o)]
            checked += 1
            fields = {
                f
                for o in owners
                for f in (
                    *getattr(o, "__dataclass_fields__", {}),
                    *getattr(o, "__annotations__", {}),
                )
            }
            if any(hasattr(o, attr) for o in owners) or attr in fields:
                continue
            if not any(f"self.{attr} =" in inspect.getsource(o) for o in owners):  # set in __init__
                broken.append(f"{page.name}: {cls}.{attr}")
    assert not broken, f"the docs name what does not exist: {broken}"
    assert checked >= 80, checked  # 103 on 2026-12-06


def test_keyword_arguments_in_the_docs_are_taken() -> None:
    """A call the README or docs/ write with keywords (``filtered(max_depth=...,
    max_relative_sigma=...)``, ``BagWriter(path, tf=False)``, ``run_stream(check_every=N)``)
    passes names the package's function of that name takes."""
    names = _api_names()
    call = re.compile(r"(?<![\w])(\w+)\(([^()]*(?:\([^()]*\)[^()]*)*)\)")
    wrong, checked = [], 0
    for page in PAGES:
        for name, args in call.findall(page.read_text()):
            if name not in names:
                continue
            own = re.sub(r"\([^()]*\)", "", args)  # a nested call's keywords are its own
            for keyword in re.findall(r"(?:^|[,\s])([a-z_]\w*)=(?!=)", own):
                checked += 1
                takes = False
                for func in names[name]:
                    try:
                        params = inspect.signature(func).parameters  # type: ignore[arg-type]
                    except (TypeError, ValueError):
                        takes = True
                        continue
                    takes |= keyword in params or any(
                        p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()
                    )
                if not takes:
                    wrong.append(f"{page.name}: {name}({keyword}=)")
    assert not wrong, f"keywords no function of that name takes: {wrong}"
    assert checked >= 50, checked  # 72 on 2026-12-06


def test_readme_set_up_is_the_build_files() -> None:
    """What the README and docs/ say about setting up (the Python and Rust floors, the
    `.[extra]` installs, `make` targets, the distribution name) is what pyproject.toml,
    Cargo.toml and the Makefile hold (read as text: tomllib is Python 3.11's)."""
    pyproject = (ROOT / "pyproject.toml").read_text()
    cargo = (ROOT / "Cargo.toml").read_text()
    makefile = (ROOT / "Makefile").read_text()
    readme = " ".join((ROOT / "README.md").read_text().split())
    python = re.search(r'^requires-python = ">=([\d.]+)"', pyproject, re.M)
    rust = re.search(r'^rust-version = "([\d.]+)"', cargo, re.M)
    name = re.search(r'^name = "([\w-]+)"', pyproject, re.M)
    assert python is not None and rust is not None and name is not None
    assert f"Python {python.group(1)} or newer" in readme
    assert f"Rust toolchain {rust.group(1)} or newer" in readme
    assert f"Distribution name `{name.group(1)}`" in readme
    section = pyproject.split("[project.optional-dependencies]", 1)[1].split("\n[", 1)[0]
    extras = set(re.findall(r"^(\w+) = \[", section, re.M))
    wrong = []
    for page in PAGES:
        text = page.read_text()
        said = re.findall(r"`\.\[(\w+)\]`", text)
        said += re.findall(rf"{re.escape(name.group(1))}\[(\w+)\]", text)
        wrong += [f"{page.name}: [{extra}]" for extra in said if extra not in extras]
        for target in re.findall(r"`make (\w[\w-]*)`", text):
            if not re.search(rf"^{re.escape(target)}:", makefile, re.M):
                wrong.append(f"{page.name}: make {target}")
    assert not wrong, f"set-up steps the build files do not have: {wrong}"


def test_readme_quotes_the_gui_captions_of_the_method_pictured() -> None:
    """The README gave the stereo panel's captions on the cones (red 52.3 px, blue 6.50 m) "as
    pictured below", without the method: gui-3d.png shows them (fused), gui-methods.png, the
    Gabor method, 51.6 px and 6.20 m. Each picture's are quoted now with its method, computed
    here as the page computes them (full size, range from the images)."""
    pytest.importorskip("trame")
    import stereovision as sv
    from stereovision.gui.app import compute_view
    from stereovision.io import load_scene

    scene = load_scene(Path(sv.__file__).parent / "data" / "cones")
    readme = " ".join((ROOT / "README.md").read_text().split())
    for method, said in (("fused", "on the cones with the fused default, as in the first"),
                         ("gabor", "the Gabor method, as in the second:")):  # fmt: skip
        view = compute_view(scene.left, scene.right, scene.calib, method)
        # the page's captions keep a number and its unit together (no-break spaces)
        quoted = " ".join(f"`{view.disparity_caption}`, `{view.depth_caption}`".split())
        assert f"{quoted} {said}" in readme or f"{said} {quoted}" in readme, (method, quoted)


def test_fused_dense_speckle_area_rounds_down_as_its_docstring_says() -> None:
    """fused_dense's docstring said a region "smaller than ``speckle_area`` of the image" is
    dropped, but the size is int(speckle_area * H * W): at 1.99 / 600 of a 20x30 map a
    one-pixel island stays (1 is not fewer than int(1.99)), at 2 / 600 it goes. The docstring
    and fusion.md now say "rounded down"; held here."""
    import numpy as np

    from stereovision.matching.fusion import fused_dense

    d = np.full((20, 30), 10.0, np.float32)
    d[5, 5] = 30.0  # a one-pixel island, 20 px off its neighbours
    conf, members = np.ones_like(d), np.full_like(d, np.nan)
    kept, _ = fused_dense(d, conf, members, speckle_area=1.99 / 600, edge_radius=0)
    dropped, _ = fused_dense(d, conf, members, speckle_area=2 / 600, edge_radius=0)
    assert kept[5, 5] == 30.0 and np.isnan(dropped[5, 5])
    assert np.isnan(dropped).sum() == 1 and not np.isnan(kept).any()
    assert "int(speckle_area * H * W)" in (fused_dense.__doc__ or "")


def test_the_docs_settings_are_the_codes_defaults() -> None:
    """The settings refine.md, fusion.md and the README state in prose (the audit of
    2026-12-06 checked each by hand against the code) are each held to the default they
    describe: a default changed without its page (or the reverse) fails here."""
    from stereovision import refine
    from stereovision.calibrate import DEFAULT_READ_TIMEOUT
    from stereovision.matching import planes, sgm
    from stereovision.matching.fusion import _EDGE_MEMBERS, DENSE_DEFAULTS, census_clear

    r, d, s = refine.DEFAULTS, DENSE_DEFAULTS, sgm.DEFAULTS
    (step1, min1), (step2, min2) = planes.DEFAULTS["passes"]
    [(fill_sigma, fill_zncc)] = r["fills"]
    assert r["step"] == 0.5  # refine.md: "half a pixel apart"
    clear = inspect.signature(census_clear).parameters
    words = {3: "three", 5: "five", 7: "seven", 9: "nine"}
    area = f"{d['speckle_area']:.0e}".replace("e-0", "e-")  # 5e-5, as the page writes it
    said = {
        "refine.md": [
            f"three box passes, sigma {r['base_sigma']:g} px",
            f"for {words[2 * r['search'] + 1]} shifts `s` half a pixel apart",
            f"(sigma {r['win_sigma']:g} px, {2 * r['win_radius'] + 1} x {2 * r['win_radius'] + 1})",
            f"sigma {fill_sigma:g} px: on KITTI's",
            f"within {r['fill_search']} px of it (whole-pixel shifts)",
            f"ZNCC is at least {fill_zncc:g}",
            f"get a depth, confidence {r['fill_confidence']:g}",
        ],
        "fusion.md": [
            f"a member within {d['radius']:g} px vetoes a Gabor value more than {d['tau']:g} px",
            f"holes within {d['fill_radius']:g} px of a member take its value",
            f"differ by more than {d['second_tol']:g} px the pixel becomes a hole",
            f"takes its value (confidence {d['second_confidence']:g}, with a depth)",
            f"stands more than {d['occlusion_tau']:g} px above the row fill",
            f"fewer pixels than {area} of the image rounded down: "
            f"{int(d['speckle_area'] * 450 * 375)} at 450x375",
            f"a disparity jump of more than {d['edge_jump']:g} px",
            f"looks {d['edge_radius']} px either side",
            f"(sigma {planes.DEFAULTS['blur']:g} px) and quantised in steps of {step1} grey",
            f"(median residual at most {planes.DEFAULTS['max_residual']:g} px, {min1} measured",
            f"(steps of {step2} levels, {min2} measured pixels or more",
            f"Its settings (P1 {s['p1']}, P2 {s['p2']} halved per {s['gamma']:g} grey levels",
            f"uniqueness {s['uniqueness']} %, left-right {s['lr_tol']} level)",
            f"more than {clear['jump'].default:g} px below the member's disparity within "
            f"{clear['radius'].default} px",
            f"{_EDGE_MEMBERS[0]} px either side, an intensity step {_EDGE_MEMBERS[1]:g} x",
        ],
        "README.md": [
            f"--read-timeout 30 # a camera slow to open or start (default "
            f"{DEFAULT_READ_TIMEOUT:g} s)"
        ],
    }
    unsaid = []
    for name, phrases in said.items():
        page = ROOT / ("README.md" if name == "README.md" else f"docs/{name}")
        text = " ".join(page.read_text().split())
        unsaid += [f"{name}: {p!r}" for p in phrases if p not in text]
    assert not unsaid, f"the docs do not say the code's defaults: {unsaid}"


def test_the_readme_shows_every_match_method() -> None:
    """README's sv.match lines left out method="best" (the Hopfield channel's reference, which
    sv.match accepts): every one of match.METHODS has its line."""
    from stereovision.match import METHODS

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    shown = set(re.findall(r'sv\.match\(left, right, method="(\w+)"\)', text))
    assert shown == set(METHODS)
