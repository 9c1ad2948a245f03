"""The Python package's modules form layers, as the engine's do (crates/ballcage-core/tests/layers.rs).

Each group (a top-level module or subpackage of ``python/ballcage``) imports
only the groups its row of `LAYERS` lists, every one of them below it, so the
groups have no import cycle: the library never imports the CLI, `studies`
never imports `paper`, and the measurements of a run (`measures`) know neither.
The test parses every module with `ast`: imports at module level, deferred
imports inside functions, ``if TYPE_CHECKING:`` imports and
``importlib.import_module("ballcage.…")`` all count. A failure names the file
and line of each offending import.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "ballcage"
#: The facade: ``ballcage/__init__.py`` (the public names) and ``ballcage/__main__.py`` (``python -m ballcage``).
FACADE = "ballcage"
#: The library, below the CLI: every group but the CLI and the facade.
_LIBRARY = (
    "_native", "_files", "_plot", "scene", "run", "_links", "duty", "sizing", "buckling", "measures",
    "view", "studies", "verify", "paper",
)  # fmt: skip

#: The groups, bottom first, each with the groups it may import. The native module (`_native`, Rust) is the
#: bottom; then the file writers and the plotting style; scenes and runs; the library's models of a run (tube
#: forces per link, duty, sizing, buckling, the measurements `ballcage.measures`); the studies and the 3D view;
#: a run's verification (`verify`: its error against a run ten times tighter, by the studies' quantities, called
#: by `run` through the hook `run.VERIFIER` the facade sets); the paper's report; the CLI, one module per command;
#: the facade on top. A group may only import groups above it in this table, and only those listed (tests below).
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("_native", ()),
    ("_files", ()),
    ("_plot", ()),
    ("scene", ("_native",)),
    ("run", ("_native", "_files", "scene")),
    ("_links", ("_native", "run")),
    ("duty", ("_native", "_files", "_plot")),
    ("sizing", ("_native", "_plot")),
    ("buckling", ("_native", "scene", "run")),
    ("measures", ("_native", "run", "_links")),
    ("view", ("_native", "_files", "_plot", "run")),
    ("studies", ("_native", "_files", "_plot", "scene", "run", "_links", "duty", "sizing", "measures")),
    ("verify", ("_native", "run", "studies")),
    ("paper", ("_native", "_files", "_plot", "scene", "run", "_links", "duty", "measures", "view", "studies")),
    ("cli", _LIBRARY),
    (FACADE, (*_LIBRARY, "cli")),
)


@dataclass(frozen=True)
class Import:
    """One import of a ``ballcage`` module: where it is, the importing group and the imported one."""

    file: Path
    line: int
    group: str
    target: str

    def __str__(self) -> str:
        return f"{self.file.relative_to(PACKAGE.parent)}:{self.line}: `{self.group}` imports `{self.target}`"


def group_of(path: Path) -> str:
    """The group of a module file: ``studies/sweep_run.py`` → ``studies``; the facade's files → `FACADE`."""
    first = path.relative_to(PACKAGE).parts[0].removesuffix(".py")
    return FACADE if first in ("__init__", "__main__") else first


def _submodules() -> set[str]:
    """The names directly under ``ballcage``: modules, subpackages and the native extension."""
    names = {p.stem for p in PACKAGE.glob("*.py")} | {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()}
    return (names | {"_native"}) - {"__init__", "__main__"}


def _target_group(dotted: str, submodules: set[str]) -> str | None:
    """The group a dotted module name lies in; ``None`` outside ``ballcage``; `FACADE` for the package's own names."""
    parts = dotted.split(".")
    if parts[0] != "ballcage":
        return None
    return parts[1] if len(parts) > 1 and parts[1] in submodules else FACADE


def imported_names(source: str, package: str) -> Iterator[tuple[int, str]]:
    """(line, dotted module name) of every import in `source`, anywhere in it, of a module in `package`.

    ``from ballcage import x`` yields ``ballcage.x`` (a submodule, or a name of the facade); relative imports
    are resolved against `package`, the importing module's package; ``importlib.import_module("…")``
    with a constant name counts.
    """
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*parent, *([node.module] if node.module else [])])
            if base == "ballcage":
                for alias in node.names:
                    yield node.lineno, f"ballcage.{alias.name}"
            else:
                yield node.lineno, base
        elif isinstance(node, ast.Call) and _is_import_module(node.func):
            if node.args and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str):
                yield node.lineno, node.args[0].value


def _is_import_module(func: ast.expr) -> bool:
    return (isinstance(func, ast.Attribute) and func.attr == "import_module") or (
        isinstance(func, ast.Name) and func.id == "import_module"
    )


def _package_of(path: Path) -> str:
    """The dotted package a module file is in (``ballcage.studies`` for ``studies/sweep_run.py``)."""
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts if path.name == "__init__.py" else parts[:-1])


def imports() -> list[Import]:
    """Every import from one group into another, over every module of the package."""
    submodules = _submodules()
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        group = group_of(path)
        for line, dotted in imported_names(path.read_text(encoding="utf-8"), _package_of(path)):
            target = _target_group(dotted, submodules)
            if target is not None and target != group:
                out.append(Import(path, line, group, target))
    return out


def violations(found: list[Import], layers: tuple[tuple[str, tuple[str, ...]], ...] = LAYERS) -> list[str]:
    """The imports `layers` does not allow, and the groups it does not list."""
    allowed = dict(layers)
    bad = []
    for imp in found:
        if imp.group not in allowed:
            bad.append(f"{imp.file.relative_to(PACKAGE.parent)}: group `{imp.group}` is not in LAYERS")
        elif imp.target not in allowed[imp.group]:
            bad.append(f"{imp} (not in its row of LAYERS)")
    return bad


def cycles(found: list[Import]) -> list[list[Import]]:
    """The import cycles between groups, each as the imports around it (one cycle per strongly connected set)."""
    edges: dict[str, dict[str, Import]] = {}
    for imp in found:
        edges.setdefault(imp.group, {}).setdefault(imp.target, imp)
    out, seen = [], set()
    for start in sorted(edges):
        path = _cycle_from(start, edges)
        if path and frozenset(i.group for i in path) not in seen:
            seen.add(frozenset(i.group for i in path))
            out.append(path)
    return out


def _cycle_from(start: str, edges: dict[str, dict[str, Import]]) -> list[Import]:
    """The imports of a shortest cycle through `start` (breadth first); empty when there is none."""
    frontier: list[tuple[str, list[Import]]] = [(start, [])]
    visited = {start}
    while frontier:
        nxt = []
        for node, path in frontier:
            for target, imp in sorted(edges.get(node, {}).items()):
                if target == start:
                    return [*path, imp]
                if target not in visited:
                    visited.add(target)
                    nxt.append((target, [*path, imp]))
        frontier = nxt
    return []


def test_every_group_imports_only_the_groups_its_row_lists() -> None:
    bad = violations(imports())
    assert not bad, "upward or unlisted imports:\n" + "\n".join(bad)


def test_the_groups_import_each_other_without_a_cycle() -> None:
    found = cycles(imports())
    text = "\n\n".join("\n".join(str(i) for i in cycle) for cycle in found)
    assert not found, f"import cycles between groups:\n{text}"


def test_the_table_is_ordered_so_there_is_no_cycle() -> None:
    names = [group for group, _ in LAYERS]
    assert len(names) == len(set(names)), "a group is listed twice"
    for i, (group, allowed) in enumerate(LAYERS):
        for target in allowed:
            assert target in names, f"`{group}` may import `{target}`, which is not in LAYERS"
            assert names.index(target) < i, f"`{group}` may import `{target}`, which is not below it"


def test_every_module_is_in_a_group_of_the_table() -> None:
    groups = {group for group, _ in LAYERS}
    missing = sorted({group_of(p) for p in PACKAGE.rglob("*.py")} - groups)
    assert not missing, f"groups not in LAYERS (add each with what it may import): {missing}"


def test_no_library_module_imports_the_cli_and_studies_never_import_the_paper() -> None:
    allowed = dict(LAYERS)
    for group in _LIBRARY:
        assert "cli" not in allowed[group], group
    assert "paper" not in allowed["studies"]
    assert [str(i) for i in imports() if i.target == "cli" and i.group != FACADE] == []
    assert [str(i) for i in imports() if i.group == "studies" and i.target == "paper"] == []


def test_the_scanner_sees_every_kind_of_import() -> None:
    # Module level, deferred in a function, under TYPE_CHECKING, relative, `from ballcage import x`,
    # import_module with a constant; other packages are not ballcage's.
    source = (
        "import numpy\n"
        "from ballcage.run import Run\n"
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n"
        "    from ballcage.paper.compare import comparison\n"
        "def f():\n"
        "    from ballcage import cli, Run\n"
        "    from ..view import write_view\n"
        "    from . import sweep_case\n"
        "    return importlib.import_module('ballcage.duty')\n"
    )
    submodules = {"run", "paper", "cli", "view", "duty", "studies", "_native"}
    found = [(line, _target_group(name, submodules)) for line, name in imported_names(source, "ballcage.studies")]
    assert sorted((line, g) for line, g in found if g is not None) == [
        (2, "run"),
        (5, "paper"),
        (7, FACADE),
        (7, "cli"),
        (8, "view"),
        (9, "studies"),
        (10, "duty"),
    ]


def test_the_checks_fail_on_an_upward_import_and_on_a_cycle() -> None:
    here = PACKAGE / "studies" / "sweep_case.py"
    upward = Import(here, 7, "studies", "paper")
    back = Import(PACKAGE / "paper" / "compare.py", 9, "paper", "studies")
    assert violations([upward]) == [f"{upward} (not in its row of LAYERS)"]
    assert "ballcage/studies/sweep_case.py:7" in violations([upward])[0]
    assert [sorted(str(i) for i in c) for c in cycles([upward, back])] == [sorted([str(upward), str(back)])]
    assert cycles([back]) == []


@pytest.mark.parametrize("group", [g for g, _ in LAYERS if g not in ("_native", FACADE)])
def test_each_listed_group_exists(group: str) -> None:
    assert (PACKAGE / f"{group}.py").is_file() or (PACKAGE / group / "__init__.py").is_file(), group
