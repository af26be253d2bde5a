"""The machinery of the hostile-input probes (``probe_hostile.py``): :class:`Probe`,
:class:`Workspace`, :func:`run_probe` (one probe's verdict), the set-ups the probe modules share
(:func:`_then`, :func:`_write`), the runner of a list of probes and of one group alone
(:func:`run_group`). The probe modules import it; ``probe_hostile.py`` gathers them all."""

import argparse
import collections
import contextlib
import io
import json
import os
import shutil
import signal
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the stand-in case and report rows of the tests

VERDICTS = (
    "pass",
    "traceback",
    "silently wrong",
    "hang",
    "write outside --out",
    "unclear message",
    "wrongly refused",
    "stray output",
)


class ProbeTimeout(BaseException):
    """Raised by the alarm; a BaseException, so the command's own handlers do not catch it."""


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


def _alarm(signum, frame):
    raise ProbeTimeout


def run_probe(probe, ws, limit_s):
    """``(verdict, seconds, last stderr line)`` of one probe."""
    from lilium.cli.main import main

    if probe.setup is not None:
        probe.setup(ws)
    argv = [str(a) for a in probe.argv(ws)]
    before = _snapshot(ws.root, ws.out)
    out, err = io.StringIO(), io.StringIO()
    start, code, crashed = time.monotonic(), None, None
    old = os.getcwd()
    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(limit_s)
    try:
        os.chdir(ws.root)  # a relative write lands in the probe's folder, where it is seen
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
    except ProbeTimeout:
        code = "hang"
    except BaseException:  # noqa: BLE001 - that is what the probe looks for
        crashed = traceback.format_exc()
    finally:
        signal.alarm(0)
        os.chdir(old)
    seconds = time.monotonic() - start
    text = err.getvalue()
    lines = [ln for ln in text.splitlines() if ln.strip()]
    last = lines[-1] if lines else ""
    if code == "hang":
        return "hang", seconds, f"over {limit_s} s"
    if crashed or "Traceback" in text or "internal error" in text:
        return "traceback", seconds, (crashed or last).strip().splitlines()[-1]
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


def _fresh_work(work, base=None):
    """Empty ``work`` and write the probes' shared inputs into ``work/base`` (``base(folder)``,
    default the stand-in case); returns that folder."""
    if work.exists():
        shutil.rmtree(work)
    shared = work / "base"
    if base is None:
        from standin_case import make_standin_case

        make_standin_case(shared, seed=0)
    else:
        base(shared)
    return shared


def _run_probes(probes, args, shared, note=None, owners=False):
    """Run each probe in its own workspace under ``args.work``; print a line for each that did
    not pass (each with ``args.verbose``, or with a ``note``); returns the verdicts counted by
    owner (``{owner: Counter}``); ``owners``: the lines name each probe's owner."""
    counts = collections.defaultdict(collections.Counter)
    for k, probe in enumerate(probes):
        ws = Workspace(args.work / f"p{k:03d}", shared)
        try:
            verdict, seconds, detail = run_probe(probe, ws, args.limit_s)
        except Exception as exc:  # noqa: BLE001 - a probe's own set-up or check failed
            verdict, seconds, detail = "traceback", 0.0, f"probe set-up/check: {exc!r}"
        counts[probe.owner][verdict] += 1
        extra = note(probe, ws, verdict, args.verbose) if note is not None else ""
        if verdict != "pass" or args.verbose or extra:
            who = f"{probe.owner}: " if owners else ""
            print(f"[{verdict}] {who}{probe.name} ({seconds:.1f} s): {detail}{extra}", flush=True)
        if not args.keep:
            shutil.rmtree(ws.root, ignore_errors=True)
    return counts


def run_group(probes, label, doc, argv=None, limit_s=60, base=None, note=None, hooks=None):
    """Run one group of probes alone, with the verdicts of :func:`main`, and print one line per
    probe that did not pass (every probe with ``--verbose``) and a summary; 0 when all passed.

    Parameters
    ----------
    probes : callable
        Returns the group's list of :class:`Probe`.
    label, doc : str
        The summary line's name; the module docstring (its first paragraph is the help).
    limit_s : int
        The default ``--limit-s``.
    base : callable, optional
        ``base(folder)`` writes the probes' shared inputs (default: the stand-in case).
    note : callable, optional
        ``note(probe, ws, verdict, verbose)``: text added to the probe's line ("" for none);
        a probe's line is printed whenever the note has text.
    hooks : dict, optional
        ``"arguments"``: ``f(parser)`` adds options; ``"before"``: ``f(args, base)`` runs
        before the probes and may return an exit status that ends the run there; ``"after"``:
        ``f()`` runs after them (e.g. to close a cluster).
    """
    hooks = hooks or {}
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--work", type=Path, required=True, help="scratch folder (emptied)")
    parser.add_argument("--only", help="run the probes whose name holds this text")
    parser.add_argument("--limit-s", type=int, default=limit_s, help="time limit per probe")
    parser.add_argument("--list", action="store_true", help="list the probes and stop")
    parser.add_argument("--verbose", action="store_true", help="a line for every probe")
    parser.add_argument("--keep", action="store_true", help="keep each probe's folder")
    if "arguments" in hooks:
        hooks["arguments"](parser)
    args = parser.parse_args(argv)
    args.work = args.work.resolve()
    os.environ.pop("LILIUM_DEBUG", None)  # as users run it: the CLI's own handlers on
    chosen = [p for p in probes() if not args.only or args.only in p.name]
    if args.list:
        for p in chosen:
            print(f"{p.expect:5} {p.name}")
        print(f"{len(chosen)} probes")
        return 0
    shared = _fresh_work(args.work, base)
    if "before" in hooks and (code := hooks["before"](args, shared)) is not None:
        return code
    start = time.monotonic()
    counts = _run_probes(chosen, args, shared, note)["rel"]
    if "after" in hooks:
        hooks["after"]()
    parts = ", ".join(f"{v} {counts[v]}" for v in VERDICTS)
    print(f"{label}: {len(chosen)} probes in {time.monotonic() - start:.0f} s: {parts}")
    return 0 if counts["pass"] == len(chosen) else 1
