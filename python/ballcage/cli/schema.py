"""``ballcage schema``: each output table's columns with type, unit and description (`_native.table_schema`)."""

from __future__ import annotations

import argparse

from ballcage import _native
from ballcage.cli._common import TABLE_NAMES, Commands


def add(commands: Commands) -> None:
    schema = commands.add_parser(
        "schema",
        help="print the columns of the output tables",
        description="Print each output column with its type, unit and description.",
    )
    schema.add_argument("table", nargs="?", choices=TABLE_NAMES, metavar="TABLE", help=f"one of {', '.join(TABLE_NAMES)}")
    schema.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    tables = [args.table] if args.table else list(TABLE_NAMES)
    blocks = []
    for name in tables:
        schema = _native.table_schema(name)
        rows = []
        for field in schema:
            meta = field.metadata or {}
            unit = meta.get(b"unit", b"").decode()
            description = meta.get(b"description", b"").decode()
            rows.append((field.name, str(field.type), f"[{unit}]" if unit else "", description))
        widths = [max(len(r[i]) for r in rows) for i in range(3)] if rows else [0, 0, 0]
        lines = [name]
        lines += [
            f"  {n:<{widths[0]}}  {t:<{widths[1]}}  {u:<{widths[2]}}  {d}".rstrip() for n, t, u, d in rows
        ]
        blocks.append("\n".join(lines))
    print("\n\n".join(blocks))
    return 0
