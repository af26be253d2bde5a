"""Running ``lilium`` commands in tests: the exit status and output of a command line, and
the one-line error a bad input must give (shared by the CLI test modules)."""

import json

from lilium.cli.main import main


def _run(argv, capsys):
    """``(exit status, stdout, stderr)`` of ``lilium`` with ``argv`` (paths allowed)."""
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _one_line_error(capsys, argv, *needles):
    """Run ``argv``, require exit status 2 and a one-line error holding every needle."""
    code, _, err = _run(argv, capsys)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for needle in needles:
        assert str(needle) in lines[0], lines[0]
    return lines[0]


def _sfo(case, out, *extra):
    """``lilium sfo`` arguments for a ``(subject folder, photo folder)`` case."""
    subject_dir, photo_dir = case
    return ["sfo", "--skull", subject_dir, "--photo", photo_dir, "--out", out, *extra]


def _edit_json(path, change):
    """Apply ``change(data)`` to a JSON file in place."""
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))
