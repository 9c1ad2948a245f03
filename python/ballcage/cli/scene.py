"""``ballcage scene show``: a scene as TOML, every default with its unit and each PROPOSAL's range (`Scene.to_toml`)."""

from __future__ import annotations

import argparse
import sys

from ballcage.cli._common import Commands, Parser, add_set_option, checked_override, load_cli_scene


def add(commands: Commands) -> None:
    scene = commands.add_parser(
        "scene",
        help="show a scene (by default the embedded one) with every default and unit",
        description="Work with scenes: the embedded default one (the paper's drill pipe) or a file.",
    )
    scene_commands = scene.add_subparsers(title="commands", required=True, metavar="COMMAND", parser_class=Parser)
    show = scene_commands.add_parser(
        "show",
        help="print a scene (default: the embedded one) as TOML, with units",
        description=(
            "Print a scene as TOML (without SCENE.toml, the embedded paper scene), every default written out "
            "and each number's unit as a comment at the end of its line (contact laws in their own units, "
            "e.g. N/mm^2.2); each value the paper does not give (a PROPOSAL) under a comment line with its "
            "plausible range and source, e.g. '# PROPOSAL, 17.5–21 mm: not in the paper' "
            "(ballcage.proposals() has the registry, docs/proposals.md): copy it, edit it, run it."
        ),
    )
    show.add_argument("scene", metavar="SCENE.toml", nargs="?", help="scene file (TOML); default: the embedded one")
    add_set_option(show)
    show.set_defaults(command=show_command)


def show_command(args: argparse.Namespace) -> int:
    overrides = [checked_override(o) for o in args.overrides]
    text = load_cli_scene(args.scene, overrides).to_toml(units=True)
    sys.stdout.write(text if text.endswith("\n") else text + "\n")
    return 0
