"""``lilium`` command-line entry point: one sub-command module per job.

Each module in :data:`COMMANDS` has ``register(subparsers)`` that adds its parser and sets
``func(args) -> int``. ``main(argv)`` can be called from tests with a list of strings.
"""

import argparse
import importlib
import sys

from .. import __version__

#: Sub-command modules, in the order ``lilium --help`` lists them.
COMMANDS = [
    "lilium.cli.sfo",
    "lilium.cli.demo",
    "lilium.cli.case",
    "lilium.cli.synth",
    "lilium.cli.import_ct",
    "lilium.cli.experiment",
    "lilium.cli.report",
    "lilium.cli.photo",
]


def build_parser():
    parser = argparse.ArgumentParser(
        prog="lilium", description="Automated skull-face overlay (Lilium and POSEST-SFO)."
    )
    parser.add_argument("--version", action="version", version=f"lilium {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True)
    for module in COMMANDS:
        importlib.import_module(module).register(subparsers)
    return parser


def main(argv=None):
    """Run the command; returns the exit status. Input errors print one line and return 2."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ValueError as exc:
        print(f"lilium {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
