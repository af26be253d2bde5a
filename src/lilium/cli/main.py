"""``lilium`` command-line entry point: one sub-command module per job.

Each module in :data:`COMMANDS` has ``register(subparsers)`` that adds its parser and sets
``func(args) -> int``. ``main(argv)`` can be called from tests with a list of strings.

Every failure ends in one line on stderr, ``lilium <command>: error: ...``, and exit status 2:
an input error (``ValueError``, whose message names the file or option and the fix), a file
the system refuses (``OSError``: permissions, a full disk, a path under a file), memory running
out, or, as a last resort, any other exception (a bug: the line asks to report it). Set
:data:`DEBUG_ENV` (``LILIUM_DEBUG=1``) to get the traceback of anything but an input error
instead; the test suite does, so real bugs stay visible there. Python warnings of the libraries
(numpy, Pillow, matplotlib) are not shown unless :data:`DEBUG_ENV` is set: what a user needs to
know is said by Lilium's own warnings (docs/checks.md), not by a library's internals.
"""

import argparse
import importlib
import os
import sys
import warnings

from .. import __version__
from .argtypes import describe_os_error

#: Sub-command modules, in the order ``lilium --help`` lists them.
COMMANDS = [
    "lilium.cli.sfo",
    "lilium.cli.demo",
    "lilium.cli.case",
    "lilium.cli.synth",
    "lilium.cli.import_ct",
    "lilium.cli.experiment",
    "lilium.cli.report",
    "lilium.cli.calibrate",
    "lilium.cli.lineup",
    "lilium.cli.photo",
    "lilium.cli.skull",
]


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (the option, the problem, where to look)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {_one_line(message)} (see {self.prog} --help)\n")


def build_parser():
    parser = _Parser(
        prog="lilium", description="Automated skull-face overlay (Lilium and POSEST-SFO)."
    )
    parser.add_argument("--version", action="version", version=f"lilium {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True)
    for module in COMMANDS:
        importlib.import_module(module).register(subparsers)
    return parser


#: Environment variable that makes unexpected exceptions raise (with their traceback).
DEBUG_ENV = "LILIUM_DEBUG"


def _one_line(text):
    return " ".join(str(text).split())


def _describe(exc):
    """The one-line message of an exception that is not an input error."""
    if isinstance(exc, OSError):
        return describe_os_error(exc)
    if isinstance(exc, MemoryError):
        return "out of memory; downscale the photo (see docs/checks.md) or free memory"
    detail = _one_line(exc)
    return (
        f"internal error ({type(exc).__name__}{f': {detail}' if detail else ''}); this is a "
        f"bug: please report it with the command line and the traceback (run again with "
        f"{DEBUG_ENV}=1 to see it)"
    )


def _prog(argv):
    """``lilium <command>`` as far as ``argv`` names one (before it is parsed)."""
    words = sys.argv[1:] if argv is None else [str(a) for a in argv]
    names = [module.rsplit(".", 1)[-1].replace("_", "-") for module in COMMANDS]
    return next((f"lilium {w}" for w in words if w in names), "lilium")


def _interrupted(exc):
    """Whether ``exc`` arose from a ``KeyboardInterrupt`` (its cause or context)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def main(argv=None):
    """Run the command; returns the exit status (2 for any error, with one line on stderr)."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # --help, --version (0) or a bad argument (2, one line printed)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    except OSError as exc:  # an argument's type looked at a path the system refuses
        print(f"lilium: error: {describe_os_error(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # Ctrl-C while the commands' modules are imported
        print(f"{_prog(argv)}: interrupted", file=sys.stderr)
        return 130
    args.argv = [str(a) for a in (sys.argv[1:] if argv is None else argv)]  # the provenance
    debug = os.environ.get(DEBUG_ENV, "") not in ("", "0")
    try:
        with warnings.catch_warnings():
            if not debug:  # library chatter (numpy's "All-NaN slice", Pillow, matplotlib)
                warnings.simplefilter("ignore")
            return int(args.func(args) or 0)
    except ValueError as exc:
        print(f"lilium {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"lilium {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # the last resort: never a traceback for the user
        if _interrupted(exc):  # a compiled kernel reports Ctrl-C as a SystemError
            print(f"lilium {args.command}: interrupted", file=sys.stderr)
            return 130
        if debug:
            raise
        print(f"lilium {args.command}: error: {_describe(exc)}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
