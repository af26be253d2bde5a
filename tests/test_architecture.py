"""The layer picture of docs/architecture.md, checked: imports only run down the layers, and
modules stay readable in one sitting."""

import ast
import subprocess
import sys
from pathlib import Path

import lilium

#: Layer of each top-level module or subpackage (docs/architecture.md); a module may import
#: from its own layer or below, never above.
LAYERS = {
    "constants": 0,
    "validation": 0,
    "jit": 0,
    "workers": 0,
    "geometry": 1,
    "optimisation": 1,
    "softtissue": 2,
    "pose": 2,
    "fitness": 3,
    "imaging": 3,
    "inputs": 4,
    "methods": 5,
    "evaluation": 5,
    "identification": 5,
    "io": 6,
    "synthetic": 7,
    "ct": 7,
    "casework": 8,
    "report": 8,
    "photo": 8,
    "experiments": 9,
    "demo": 9,
    "cli": 10,
    "jit_aot": 10,
    "skull": 8,
}

#: Longest module (lines) that still reads in one sitting.
MAX_MODULE_LINES = 650

ROOT = Path(lilium.__file__).parent


def _top(path):
    return path.relative_to(ROOT).parts[0].removesuffix(".py")


def _imports(path):
    """Top-level lilium packages a module imports (relative and absolute imports)."""
    rel = path.relative_to(ROOT).parts[:-1]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = list(rel[: len(rel) - node.level + 1])
            target = base + (node.module.split(".") if node.module else [])
            if target:
                yield target[0]
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("lilium."):
            yield node.module.split(".")[1]
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("lilium."):
                    yield alias.name.split(".")[1]


def _modules():
    return [p for p in ROOT.rglob("*.py") if _top(p) not in ("__init__", "__main__")]


def test_every_package_has_a_layer():
    assert {_top(p) for p in _modules()} <= set(LAYERS)


def test_imports_run_down_the_layers():
    upward = [
        f"{p.relative_to(ROOT)} imports lilium.{target}"
        for p in _modules()
        for target in _imports(p)
        if target in LAYERS and LAYERS[target] > LAYERS[_top(p)]
    ]
    assert not upward, "\n".join(upward)


def test_modules_read_in_one_sitting():
    long = {
        str(p.relative_to(ROOT)): n
        for p in _modules()
        if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES
    }
    assert not long, long


#: Libraries a ``lilium sfo`` process must not import before its SFO starts (issue 26: each
#: costs 0.07-0.15 s of start-up; they are imported where first needed).
LAZY_LIBRARIES = (
    "trimesh",
    "networkx",
    "scipy.optimize",
    "scipy.ndimage",
    "scipy.sparse",
    "matplotlib",
    "dask",
    "lilium.synthetic",
    "lilium.experiments.runner",
)


def test_sfo_command_imports_stay_light():
    code = (
        "import sys\n"
        "import lilium.cli.main, lilium.cli.sfo, lilium.casework.folders\n"
        "from lilium.cli.main import build_parser\n"
        "build_parser()\n"
        f"print([m for m in {LAZY_LIBRARIES!r} if m in sys.modules])\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == "[]", out



def test_the_compiled_curve_index_does_not_import_scipy_spatial():
    """P_pll's nearest-point table is a compiled bucket search: building it (once per SFO with
    P_pll) loads no k-d tree (scipy.spatial, about 0.1 s of a process's start)."""
    from lilium import jit

    if not jit.compiled():
        return  # the numpy reference path builds the table with a k-d tree
    code = (
        "import sys\n"
        "import numpy as np\n"
        "from lilium.fitness.pll import face_curve_index\n"
        "u = np.arange(200.0)\n"
        "index = face_curve_index(np.column_stack([u, np.round(300 + (u - 100) ** 2 / 80)]))\n"
        "assert index.table.size > 0\n"
        "print('scipy.spatial' in sys.modules)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == "False", out


#: Test folders that are not a subpackage of lilium: the benchmark cases' tests, the slow
#: acceptance campaign of every command (and its snapshot data).
OTHER_TEST_FOLDERS = {"benchmarks", "acceptance"}


def test_tests_mirror_the_package():
    """Each test folder is named after the subpackage it tests (tests of the top-level modules
    sit in tests/ itself), and no two test modules share a name: without ``__init__.py`` files
    pytest imports each by its base name."""
    tests = Path(__file__).resolve().parent
    subpackages = {p.parent.name for p in ROOT.glob("*/__init__.py")}
    folders = {p.name for p in tests.iterdir() if p.is_dir() and not p.name.startswith((".", "__"))}
    assert folders - subpackages - OTHER_TEST_FOLDERS == set()
    names = [p.name for p in tests.rglob("test_*.py")]
    assert sorted({n for n in names if names.count(n) > 1}) == []
    for path in tests.glob("test_*.py"):
        assert path.stem.removeprefix("test_").split("_")[0] not in subpackages, path.name
