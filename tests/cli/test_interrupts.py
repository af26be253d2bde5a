"""Ctrl-C (tests/acceptance/hostile_scenarios.py): one line and exit status 130 whenever it comes,
never a traceback, and never lost inside a library's import."""

import subprocess
import sys
import textwrap

import lilium.cli.main as cli_main
from cli_helpers import _sfo

#: A child that sends itself SIGINT while Python looks for trimesh, then imports it.
_CHILD = textwrap.dedent(
    """
    import os, signal, sys

    class CtrlC:
        def find_spec(self, name, path=None, target=None):
            if name == "trimesh":
                os.kill(os.getpid(), signal.SIGINT)
            return None

    sys.meta_path.insert(0, CtrlC())
    from lilium.io.mesh import import_trimesh
    try:
        import_trimesh()
    except KeyboardInterrupt:
        print("interrupted; trimesh complete:", "trimesh.creation" in sys.modules)
    """
)


def test_ctrl_c_during_the_trimesh_import_is_raised_after_it():
    # trimesh imports its optional parts under ``except BaseException``: a KeyboardInterrupt
    # raised inside the import could be swallowed there. Held back, it comes after the import.
    done = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True)
    assert done.stdout.strip() == "interrupted; trimesh complete: True", done.stderr


def test_ctrl_c_while_the_commands_load_is_one_line(monkeypatch, capsys):
    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(cli_main, "build_parser", interrupted)
    assert cli_main.main(["sfo", "--help"]) == 130
    assert capsys.readouterr().err == "lilium sfo: interrupted\n"


def test_ctrl_c_inside_a_compiled_kernel_is_one_line(case, tmp_path, monkeypatch, capsys):
    # numba's dispatcher returns with the KeyboardInterrupt set: CPython raises a SystemError
    # caused by it, which must not read as a bug.
    import lilium.cli.sfo as sfo_cli

    def kernel_interrupted(*args, **kwargs):
        raise SystemError("CPUDispatcher(kernel) returned a result with an exception set") from (
            KeyboardInterrupt()
        )

    monkeypatch.setattr(sfo_cli, "single_sfo", kernel_interrupted)
    assert cli_main.main([str(a) for a in _sfo(case, tmp_path / "out")]) == 130
    assert capsys.readouterr().err == "lilium sfo: interrupted\n"


def test_a_pools_worker_ends_without_a_word_on_ctrl_c():
    """Ctrl-C reaches a pool's workers too: one that is waiting for work (or still starting)
    ends at once, with no traceback under the parent's one-line message (lilium.workers)."""
    code = (
        "import os, signal, time\n"
        "from concurrent.futures import ProcessPoolExecutor\n"
        "from multiprocessing import get_context\n"
        "from lilium.workers import quiet_interrupts, starting_workers\n"
        "if __name__ == '__main__':\n"
        "    pool = ProcessPoolExecutor(1, mp_context=get_context('spawn'),\n"
        "                               initializer=quiet_interrupts)\n"
        "    with starting_workers():\n"
        "        pid = pool.submit(os.getpid).result()\n"
        "    os.kill(pid, signal.SIGINT)\n"
        "    deadline = time.monotonic() + 30\n"
        "    while time.monotonic() < deadline:\n"
        "        try:\n"
        "            os.kill(pid, 0)\n"
        "        except ProcessLookupError:\n"
        "            break\n"
        "        time.sleep(0.05)\n"
        "    else:\n"
        "        raise SystemExit('the worker did not end')\n"
        "    pool.shutdown(wait=False)\n"
        "    print('ended')\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert "ended" in done.stdout, done.stderr
    assert "Traceback" not in done.stderr and "KeyboardInterrupt" not in done.stderr, done.stderr


def test_a_pools_worker_ignores_ctrl_c_where_its_parent_does():
    """A run started in the background ignores SIGINT: its workers inherit that, so a SIGINT
    sent to the process group leaves the run whole instead of breaking its pool."""
    code = (
        "import os, signal\n"
        "from concurrent.futures import ProcessPoolExecutor\n"
        "from multiprocessing import get_context\n"
        "from lilium.workers import quiet_interrupts, starting_workers\n"
        "if __name__ == '__main__':\n"
        "    signal.signal(signal.SIGINT, signal.SIG_IGN)\n"
        "    pool = ProcessPoolExecutor(1, mp_context=get_context('spawn'),\n"
        "                               initializer=quiet_interrupts)\n"
        "    with starting_workers():\n"
        "        pid = pool.submit(os.getpid).result()\n"
        "    os.kill(pid, signal.SIGINT)\n"
        "    handler = pool.submit(signal.getsignal, signal.SIGINT).result(timeout=60)\n"
        "    print(handler == signal.SIG_IGN)\n"
        "    pool.shutdown()\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.stdout.strip() == "True", done.stderr
