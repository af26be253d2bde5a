"""Ids that become file and folder names: always one safe path component.

A photo's or skull's id is its folder's name (or its file's stem); the case writes each photo's
results to ``OUT/<photo id>/``. A name taken from the command line can be anything (``..``,
``.``, ``/``, ``javascript:alert(1)``, a name with a slash from a JSON field), so every id goes
through :func:`safe_id` before it names a folder: the result is a single path component that
stays inside its parent on every common file system and reads as a relative link in HTML.
"""

import os
import re
from contextlib import contextmanager
from pathlib import Path

#: Characters replaced by ``_``: path separators, characters Windows forbids, and ``%``/``#``
#: (which would change the meaning of a relative link); control characters too, and the lone
#: surrogates by which Python holds a file name's bytes that are not UTF-8 (they cannot be
#: written into a UTF-8 report or JSON file).
_UNSAFE = re.compile(r'[\x00-\x1f\x7f/\\:*?"<>|%#\ud800-\udfff]')

#: Names Windows reserves whatever the extension.
_RESERVED = {"con", "prn", "aux", "nul"} | {f"{p}{i}" for p in ("com", "lpt") for i in range(10)}

#: Longest id, in characters and in UTF-8 bytes; longer names are cut. File systems allow 255
#: bytes per name, and an id is written with a prefix and suffixes (``overlay_<id>.png``).
MAX_ID_CHARS = 100
MAX_ID_BYTES = 200


def safe_id(name, default="photo"):
    """``name`` as a safe folder name: one path component, never ``.``/``..``, not hidden.

    Parameters
    ----------
    name : str
    default : str
        Used when nothing is left of ``name`` (empty, only dots or spaces).

    Returns
    -------
    str
        ``name`` unchanged when it is already safe (letters, digits, spaces, ``-_.+()`` ...).

    Examples
    --------
    >>> safe_id("front_view")
    'front_view'
    >>> safe_id("..")
    'photo'
    >>> safe_id("javascript:alert(1)")
    'javascript_alert(1)'
    >>> safe_id("a/b\\\\c")
    'a_b_c'
    >>> len(safe_id("\N{GRINNING FACE}" * 70).encode())
    200
    """
    text = _UNSAFE.sub("_", str(name)).strip(" .")
    text = text[:MAX_ID_CHARS].encode("utf-8")[:MAX_ID_BYTES].decode("utf-8", "ignore")
    text = text.rstrip(" .")
    if not text:
        return default
    if text.split(".")[0].lower() in _RESERVED:
        text = "_" + text
    return text


def same_file(a, b):
    """Whether the paths ``a`` and ``b`` name one file: the same path once links are resolved,
    or a hard link (False when either cannot be looked at, e.g. does not exist)."""
    a, b = Path(a), Path(b)
    try:
        return a.resolve() == b.resolve() or (a.exists() and a.samefile(b))
    except OSError:
        return False


def printable(text):
    """``text`` for a terminal line: every character that is not printable (control
    characters, a newline, the bidirectional overrides that would reverse the rest of the
    line) written as its escape (``\\u202e``).

    >>> printable("A\\u202eB\\nC")
    'A\\\\u202eB\\\\u000aC'
    """
    return "".join(c if c.isprintable() else f"\\u{ord(c):04x}" for c in str(text))


def path_id(path, default="photo"):
    """The id of a folder or file given on the command line: its name as written, made safe.

    ``some/dir/..`` is ``some`` (the path is normalised first, without following links), and
    ``.`` is the current folder's name.
    """
    name = Path(os.path.normpath(os.path.abspath(path))).name
    return safe_id(name, default)


def check_no_links(folder):
    """Refuse an output folder that holds a symbolic link (anywhere below it).

    A command writes only inside its output folder, and it writes files by name: a link left
    there (``out/report.html -> ../notes.txt``, a dangling ``overlay.png``, a photo folder
    pointing elsewhere) would make it write through the link, outside the folder. The folder
    itself may be reached through links. Nothing to check when it does not exist yet.

    Raises
    ------
    ValueError
        Naming the first link found.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return
    for parent, dirs, files in os.walk(folder):  # does not descend into linked folders
        for name in sorted(dirs) + sorted(files):
            path = Path(parent) / name
            if path.is_symlink():
                raise ValueError(
                    f"{path} is a symbolic link inside the output folder, and Lilium writes "
                    "only inside it; remove the link or give another output folder"
                )


@contextmanager
def naming_errors(path):
    """Give an ``OSError`` raised inside without a file name the name ``path``.

    A full disk or a file-size limit met inside a write (Python's, OpenCV's, trimesh's or
    Pillow's: "File too large") names no file; the command's one-line error must.
    """
    try:
        yield
    except OSError as exc:
        if exc.filename is not None:
            raise
        raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from exc
