"""The machinery of the hostile-input campaign (issue 28; the tests ``test_hostile_*.py`` of
this folder): :class:`Probe` (one hostile input and what must come of it), :class:`Workspace`
(its own folder, a copy of the stand-in case), :func:`run_probe` (runs the command as a user
does, in a ``lilium`` process of its own under a time limit, and gives its verdict),
:func:`check_probe` (a test's assertion) and the set-ups the probe modules share
(:func:`_then`, :func:`_write`).

Each command on any input must end in a result or a one-line error naming the file or option
and the fix; never a traceback; never a write outside its output folder. The verdicts:

- ``pass``: an expected error is one line naming the file or option (the probe's needles), an
  expected success exits 0 (with the expected warning, when one is expected);
- ``traceback``: an exception escaped, or the line says "internal error" (a bug);
- ``silently wrong``: an input that must be refused (or warned about) ran to exit 0 without it;
- ``hang``: over the time limit (the process is killed);
- ``write outside --out``: a file changed in the probe's folder outside its ``--out``;
- ``unclear message``: the error is not one line, or does not name what the probe expects;
- ``wrongly refused``: a valid input was refused;
- ``stray output``: a library's warning reached stderr.
"""

import contextlib
import json
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: Time limit of one probe's command (s): over it, the process is killed and the verdict is
#: ``hang``.
LIMIT_S = 60


@dataclass
class Probe:
    """One hostile input: ``argv(ws)`` the command line, ``expect`` ``"error"``, ``"ok"`` or
    ``"warn"``, ``needles`` what the error line (or warning) must contain, ``setup(ws)`` what
    to break in the probe's copy of the case, ``owner`` ``"rel"``, ``"photo"`` or ``"ct"``,
    ``check(ws)`` (an expected success) what is wrong with its outputs, or None, ``code`` the
    exit status of an expected success (``lilium photo`` exits 3 when it finds no face)."""

    name: str
    argv: object
    expect: str
    needles: tuple = ()
    setup: object = None
    owner: str = "rel"
    check: object = None
    code: int = 0


class Workspace:
    """A probe's folder: a fresh copy of the stand-in case under ``in/``, ``out/`` for --out."""

    def __init__(self, root, base):
        self.root = Path(root)
        self.base = Path(base)
        shutil.copytree(base, self.root / "in")
        self.skull = self.root / "in" / "subjects" / "standin"
        self.photo = self.root / "in" / "photos" / "standin_frontal"
        self.out = self.root / "out"
        self.console = None  # (stdout, stderr) of the probe's command, once it ran

    def sfo(self, *extra, method="posest-sfo"):
        return ["sfo", "--skull", self.skull, "--photo", self.photo, "--out", self.out]

    def edit(self, path, change):
        data = json.loads(Path(path).read_text())
        change(data)
        Path(path).write_text(json.dumps(data))

    def file(self, name, content):
        path = self.root / "in" / name
        path.write_bytes(content if isinstance(content, bytes) else content.encode())
        return path


def _snapshot(root, skip):
    out = {}
    for dirpath, _, files in os.walk(root):
        if Path(dirpath) == skip or skip in Path(dirpath).parents:
            continue
        for name in files:
            path = Path(dirpath) / name
            with contextlib.suppress(OSError):
                st = path.lstat()
                out[path] = (st.st_size, st.st_mtime_ns)
    return out


def _lilium_env():
    """The environment of a probe's ``lilium`` process: this tree's package first on the path,
    and the CLI's own last-resort handler on (``LILIUM_DEBUG`` unset), as users run it."""
    import lilium

    env = dict(os.environ)
    env.pop("LILIUM_DEBUG", None)
    src = str(Path(lilium.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [src, env.get("PYTHONPATH", "")]))
    return env


def run_probe(probe, ws, limit_s=LIMIT_S):
    """``(verdict, seconds, detail)`` of one probe: its set-up, then its command line run as
    ``python -m lilium ...`` in the probe's folder (a relative write lands there, where it is
    seen), killed after ``limit_s`` seconds, then its check."""
    if probe.setup is not None:
        probe.setup(ws)
    argv = [str(a) for a in probe.argv(ws)]
    before = _snapshot(ws.root, ws.out)
    start = time.monotonic()
    try:
        done = subprocess.run(
            [sys.executable, "-m", "lilium", *argv],
            cwd=ws.root,
            env=_lilium_env(),
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=limit_s,
        )
    except subprocess.TimeoutExpired:
        return "hang", time.monotonic() - start, f"over {limit_s} s"
    seconds = time.monotonic() - start
    ws.console = (done.stdout, done.stderr)  # for the checks that read what it printed
    code, text = done.returncode, done.stderr
    lines = [ln for ln in text.splitlines() if ln.strip()]
    last = lines[-1] if lines else ""
    if "Traceback" in text or "internal error" in text:
        return "traceback", seconds, last.strip()
    changed = {p for p, s in _snapshot(ws.root, ws.out).items() if before.get(p) != s}
    if changed:
        return "write outside --out", seconds, ", ".join(sorted(str(p) for p in changed))[:200]
    if any("Warning:" in ln and ".py:" in ln for ln in lines):
        return "stray output", seconds, next(ln for ln in lines if "Warning:" in ln)
    if probe.expect == "error":
        if code == 0:
            return "silently wrong", seconds, "exit 0"
        errors = [ln for ln in lines if ": error:" in ln]
        if len(errors) != 1 or not all(n in errors[0] for n in probe.needles):
            return "unclear message", seconds, last
        return "pass", seconds, last
    if code != probe.code:
        return "wrongly refused", seconds, f"exit {code}: {last}"
    if probe.expect == "warn" and not all(n in text for n in probe.needles):
        return "silently wrong", seconds, "no warning naming " + repr(probe.needles)
    problem = probe.check(ws) if probe.check is not None else None
    if problem:
        return "silently wrong", seconds, problem
    return "pass", seconds, last


# -- set-ups the probe modules share ----------------------------------------------------------


def _then(*setups):
    """A probe's set-up made of several set-ups, run in order."""

    def setup(ws):
        for s in setups:
            s(ws)

    return setup


def _write(where, name, content):
    def setup(ws):
        folder = ws.photo if where == "photo" else ws.skull if where == "skull" else ws.root / "in"
        path = folder / name
        if path.is_dir():
            shutil.rmtree(path)
        path.write_bytes(content if isinstance(content, bytes) else content.encode())

    return setup


def check_probe(probe, ws, limit_s=LIMIT_S):
    """Fail the calling test unless ``probe`` passes in ``ws``; the message is its verdict and
    what was seen (the error line, the files written outside ``--out``, the problem found)."""
    verdict, seconds, detail = run_probe(probe, ws, limit_s)
    assert verdict == "pass", f"[{verdict}] {probe.name} ({seconds:.1f} s): {detail}"


def probe_params(*groups, known_limits=None):
    """A ``pytest.param`` of each probe of ``groups`` (lists of :class:`Probe`), its name as
    its id (``-k`` selects by it); ``known_limits``: ``{probe name: reason}`` of the probes
    that fail on a limit the method's docs (docs/method/) document and that is not mended
    (expected to fail, not strictly: a run may land within the tolerance)."""
    import pytest

    known_limits = known_limits or {}
    params = []
    for group in groups:
        for p in group:
            marks = ()
            if p.name in known_limits:
                marks = pytest.mark.xfail(reason=known_limits[p.name], strict=False)
            params.append(pytest.param(p, id=p.name, marks=marks))
    unknown = set(known_limits) - {p.name for group in groups for p in group}
    assert not unknown, f"known limits of no probe: {sorted(unknown)}"
    return params
