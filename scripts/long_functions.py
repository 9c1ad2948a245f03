#!/usr/bin/env python3
"""Lists functions longer than a limit anywhere in the tree's Rust and Python source.

Usage: python3 scripts/long_functions.py [LIMIT]   (default 80 lines)

Scans every `.rs` and `.py` file under SCANNED (below): the Rust crates
under `crates/` (ballcage-core, ballcage-shapes, ballcage-py and the bench
crate ballcage-bench) with their `src/`, `tests/`, `benches/` and
`examples/`; the fuzz crate `fuzz/` (src, fuzz_targets, tests, examples); the
Python package `python/ballcage`; the pytest suite `tests/`; the peer
benchmarks `benchmarks/`; and these scripts, `scripts/`. Folders named in
SKIPPED (build output such as `target/`, libFuzzer's `artifacts/` and
`corpus/`, caches) are not source and are not scanned.

Rust: a `fn` item runs from its signature line to the line of its closing brace
(brace matching, ignoring braces in strings, chars and comments well enough for
this tree). Python: a `def` runs to the last line of its body (ast end_lineno).
Exit code 1 when any function is over the limit.
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# Folders scanned, from the repository root, and folder names skipped within them.
SCANNED = ("crates", "fuzz", "python/ballcage", "tests", "benchmarks", "scripts")
SKIPPED = {"target", "artifacts", "corpus", "coverage", "__pycache__", ".pytest_cache"}
FN = re.compile(r"^\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)")


def _strip(line: str) -> str:
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])'", "''", line)
    return line.split("//", 1)[0]


def rust_functions(path: Path):
    lines = path.read_text().splitlines()
    i = 0
    while i < len(lines):
        m = FN.match(lines[i])
        if not m:
            i += 1
            continue
        depth, started, j = 0, False, i
        while j < len(lines):
            code = _strip(lines[j])
            if not started and ";" in code and "{" not in code:
                break  # a declaration without a body
            for ch in code:
                if ch == "{":
                    depth += 1
                    started = True
                elif ch == "}":
                    depth -= 1
            if started and depth == 0:
                yield m.group(6), i + 1, j - i + 1
                break
            j += 1
        i += 1


def python_functions(path: Path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield node.name, node.lineno, node.end_lineno - node.lineno + 1


def sources(suffix: str) -> list[Path]:
    """Every file ending in `suffix` under SCANNED, outside SKIPPED folders."""
    found = []
    for folder in SCANNED:
        for path in (ROOT / folder).rglob(f"*{suffix}"):
            if not SKIPPED.intersection(path.relative_to(ROOT).parts):
                found.append(path)
    return sorted(found)


def main() -> int:
    limit = int(sys.argv[1]) if len(sys.argv) > 1 else 80
    found = []
    for path in sources(".rs"):
        found += [(n, path, line, length) for n, line, length in rust_functions(path)]
    for path in sources(".py"):
        found += [(n, path, line, length) for n, line, length in python_functions(path)]
    over = sorted((f for f in found if f[3] > limit), key=lambda f: -f[3])
    for name, path, line, length in over:
        print(f"{length:5d}  {path.relative_to(ROOT)}:{line}  {name}")
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
