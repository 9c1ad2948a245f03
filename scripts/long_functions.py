#!/usr/bin/env python3
"""Lists functions longer than a limit in the Rust core (with ballcage-shapes) and the Python package.

Usage: python3 scripts/long_functions.py [LIMIT]   (default 80 lines)

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


def main() -> int:
    limit = int(sys.argv[1]) if len(sys.argv) > 1 else 80
    found = []
    for crate in ("crates/ballcage-core/src", "crates/ballcage-shapes/src"):
        for path in sorted((ROOT / crate).rglob("*.rs")):
            found += [(n, path, line, length) for n, line, length in rust_functions(path)]
    for path in sorted((ROOT / "python/ballcage").rglob("*.py")):
        found += [(n, path, line, length) for n, line, length in python_functions(path)]
    over = sorted((f for f in found if f[3] > limit), key=lambda f: -f[3])
    for name, path, line, length in over:
        print(f"{length:5d}  {path.relative_to(ROOT)}:{line}  {name}")
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
