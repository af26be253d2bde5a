"""Argument types of the ``lilium`` commands: a bad value is argparse's one-line error that
names the option (``lilium sfo: error: argument --seed: ...``), before anything runs.

Each factory returns a callable for ``add_argument(type=...)``; argparse turns its
``argparse.ArgumentTypeError`` into ``usage`` + the message, exit status 2.
"""

import argparse
import errno
import functools
import math
import os
from pathlib import Path

from ..io.paths import check_no_links

#: Largest seed: numpy takes any non-negative integer, SQLite and JSON readers an int64.
MAX_SEED = 2**63 - 1


def _number(text, kind):
    try:
        value = kind(text)
    except ValueError:
        noun = "an integer" if kind is int else "a number"
        raise argparse.ArgumentTypeError(f"{text!r} is not {noun}") from None
    if kind is float and math.isnan(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a number")
    return value


def int_in(lo, hi=None, why=""):
    """An integer ``lo <= n`` (``<= hi`` when given); ``why`` explains the bound."""

    def parse(text):
        value = _number(text, int)
        if value < lo or (hi is not None and value > hi):
            span = f"of at least {lo}" if hi is None else f"from {lo} to {hi}"
            raise argparse.ArgumentTypeError(f"must be an integer {span}{why}, got {value}")
        return value

    parse.__name__ = "integer"
    return parse


def positive_float(allow_inf=False, why=""):
    """A number ``> 0`` (finite unless ``allow_inf``)."""

    def parse(text):
        value = _number(text, float)
        if not value > 0 or (math.isinf(value) and not allow_inf):
            kind = "a positive number" if allow_inf else "a finite positive number"
            raise argparse.ArgumentTypeError(f"must be {kind}{why}, got {text}")
        return value

    parse.__name__ = "number"
    return parse


#: ``--seed``: 0 <= seed <= 2**63 - 1.
seed = int_in(0, MAX_SEED, " (numpy seeds are non-negative)")


#: What to do about the errors the system gives for a path (the rest: the general advice).
_OS_ADVICE = {
    errno.ENAMETOOLONG: "the name is too long; give a shorter path",
    errno.EISDIR: "a folder stands where a file is needed; give another path",
    errno.ENOTDIR: "a file stands where a folder is needed; give another path",
    errno.EACCES: "permission denied; fix its permissions or give another path",
    errno.ENOSPC: "the disk is full; free space or give a path on another disk",
}


def describe_os_error(exc):
    """One line for an ``OSError``: the file it names, and what to do."""
    reason = exc.strerror or " ".join(str(exc).split()) or type(exc).__name__
    advice = _OS_ADVICE.get(exc.errno)
    if exc.filename is None:
        advice = advice or "check the paths and the free disk space"
        return f"{reason} ({type(exc).__name__}); {advice}"
    advice = advice or f"{reason}; check the path, its permissions and the free disk space"
    return f"{exc.filename}: {advice}"


def _path_checked(parse):
    """``parse`` with a path the system refuses to look at (too long, ...) as its message."""

    @functools.wraps(parse)
    def checked(text):
        try:
            return parse(text)
        except OSError as exc:
            exc.filename = text if exc.filename is None else exc.filename
            raise argparse.ArgumentTypeError(describe_os_error(exc)) from None

    return checked


def existing_file(what):
    """A path to an existing file (``what`` names it in the message)."""

    def parse(text):
        path = Path(text)
        if not path.is_file():
            state = "is a folder, not a file" if path.is_dir() else "not found"
            raise argparse.ArgumentTypeError(f"{text}: {what} {state}; check the path")
        return path

    parse.__name__ = "file"
    return _path_checked(parse)


@_path_checked
def dataset_folder(text):
    """A folder ``lilium synth`` wrote (it holds ``dataset.json``)."""
    path = Path(text)
    if not (path / "dataset.json").is_file():
        state = "not found" if not path.exists() else "holds no dataset.json"
        raise argparse.ArgumentTypeError(
            f"{text}: {state}; give the dataset folder lilium synth wrote"
        )
    return path


dataset_folder.__name__ = "dataset folder"


@_path_checked
def output_folder(text):
    """An output folder that exists or can be made, and can be written to.

    Rejects a path that is a file, lies under a file, or whose nearest existing folder is not
    writable, so a command never fails after a long run because it cannot write; and a folder
    holding a symbolic link (:func:`lilium.io.paths.check_no_links`), through which it would
    write outside the folder.
    """
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a file, not a folder; give a folder path")
    parent = path
    while not parent.exists():
        if parent.is_symlink():  # a dangling link: it cannot be made a folder
            raise argparse.ArgumentTypeError(f"{parent} is a broken link; give another folder")
        parent = parent.parent
    if not parent.is_dir():
        raise argparse.ArgumentTypeError(
            f"{text} lies under the file {parent}, which cannot hold folders; give a folder path"
        )
    if not os.access(parent, os.W_OK | os.X_OK):
        raise argparse.ArgumentTypeError(
            f"{parent} is not writable; give a folder you can write to (or fix its permissions)"
        )
    try:
        check_no_links(path)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return path
