"""The kernels compiled ahead of time (``lilium._kernels_aot``, :mod:`lilium.jit`): a call uses
them only with exactly the argument types they were built for, they give numba's JIT's numbers,
a stale build is not used, and a ``lilium sfo`` process served by them never imports numba."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from lilium import jit

built = pytest.mark.skipif(
    not (jit.NUMBA_AVAILABLE and jit._aot_table()),
    reason="the kernels were not compiled ahead of time (no C compiler at install)",
)

SPECS = [
    ("array", "float64", 2, "C", False),
    "int64",
    ("tuple", [("array", "bool", 1, "A", True), "float64"]),
    "bool",
]


def test_a_call_fits_an_export_only_with_numbas_own_types():
    fits = jit._matcher(SPECS)
    a, b = np.zeros((2, 3)), np.zeros(3, bool)
    assert fits(a, 3, (b, 1.0), True)
    assert fits(a, np.int64(3), (b[::2], np.float64(1.0)), np.True_)  # any layout for "A"
    frozen = b.copy()
    frozen.setflags(write=False)
    assert fits(a, 3, (frozen, 1.0), False)  # a read-only slot takes a read-only array
    read_only = a.copy()
    read_only.setflags(write=False)
    wrong = [
        (a.T, 3, (b, 1.0), True),  # Fortran order for a C slot
        (a[:, ::2], 3, (b, 1.0), True),  # not contiguous
        (read_only, 3, (b, 1.0), True),  # the kernel may write it
        (a.astype(np.float32), 3, (b, 1.0), True),
        (a.astype(">f8"), 3, (b, 1.0), True),  # byte order
        (a[None], 3, (b, 1.0), True),  # ndim
        (a, 3.0, (b, 1.0), True),  # a float for an int
        (a, True, (b, 1.0), True),  # a bool for an int
        (a, 2**63, (b, 1.0), True),  # beyond int64
        (a, 3, (b, 1), True),  # an int for a float
        (a, 3, [b, 1.0], True),  # a list for a tuple
        (a, 3, (b, 1.0, 2.0), True),
        (a, 3, (b.astype(np.int8), 1.0), True),
        (a, 3, (b, 1.0), 1),
        (a.view(np.recarray), 3, (b, 1.0), True),  # a subclass
    ]
    for args in wrong:
        assert not fits(*args), args


def test_a_kernel_pickles_by_name():
    import pickle

    from lilium.geometry._projection_kernels import project_kernel

    assert pickle.loads(pickle.dumps(project_kernel)) is project_kernel


@built
@pytest.mark.parametrize("changed", ["source_hash", "cpu_fingerprint"])
def test_a_stale_build_is_not_used(monkeypatch, changed):
    """After an edit of a kernel (or of the signature list), or on another CPU, the module's
    hash differs: the kernels run on numba's JIT until the package is built again there."""
    monkeypatch.setattr(jit, changed, lambda: -1)
    jit._aot_table.cache_clear()
    try:
        assert jit._aot_table() == {}
    finally:
        monkeypatch.undo()
        jit._aot_table.cache_clear()
    assert jit._aot_table()


@built
def test_ahead_of_time_and_jit_give_the_same_sfo(case, monkeypatch):
    from lilium.casework.build import read_photo, read_skull
    from lilium.methods import SfoOptions, run_sfo
    from lilium.optimisation import DEOptions

    subject_dir, photo_dir = case
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    options = SfoOptions(variant="skof+pll", de=DEOptions(max_generations=40, population_size=16))
    results, missed = {}, []
    jitted = jit.Kernel.dispatcher
    for name in ("numba", "jit"):
        if name == "numba":  # every call of this SFO must find its export
            monkeypatch.setattr(
                jit.Kernel, "dispatcher", property(lambda k: missed.append(k.key) or jitted.fget(k))
            )
        with jit.kernels(name):
            results[name] = run_sfo("lilium", skull, photo, options, seed=3)
        monkeypatch.undo()
    assert not missed, sorted(set(missed))
    aot, just_in_time = results["numba"], results["jit"]
    assert aot.fitness == just_in_time.fitness
    assert aot.terms == just_in_time.terms
    np.testing.assert_array_equal(aot.camera.skull2cam, just_in_time.camera.skull2cam)


@built
@pytest.mark.parametrize("command", ["sfo", "case"])
def test_a_process_never_imports_numba(case, tmp_path, command):
    """Issue 26's start-up: numba's import and registries cost a process about 0.5 s; with the
    kernels built ahead of time ``lilium sfo`` (Lilium skof+pll) and ``lilium case`` (its
    overlay and report pictures too) need neither, nor scipy.sparse (the mesh's edge incidence
    is built without it). A kernel whose signature the list misses fails this test."""
    subject_dir, photo_dir = case
    code = (
        "import sys\n"
        "from lilium.cli.main import main\n"
        "code = main(sys.argv[1:])\n"
        "print('MODULES', [m for m in ('numba', 'scipy.sparse') if m in sys.modules])\n"
    )
    args = [command, "--skull", subject_dir, "--photo", photo_dir, "--method", "lilium"]
    args += ["--generations", "20", "--out", tmp_path / "out"]
    done = subprocess.run(
        [sys.executable, "-c", code, *map(str, args)], capture_output=True, text=True, check=True
    )
    results = list((tmp_path / "out").rglob("result.json"))
    assert len(results) == 1 and json.loads(results[0].read_text())["method"] == "lilium"
    assert "MODULES []" in done.stdout, done.stdout


def test_a_numba_that_fails_to_import_leaves_the_numpy_path(tmp_path):
    """numba installed but broken (built for another numpy): the call that finds out runs in
    Python, warns once, and the rest takes the numpy path; the answers are the numpy path's."""
    fake = tmp_path / "numba"
    fake.mkdir()
    (fake / "__init__.py").write_text("raise ImportError('Numba needs NumPy 2.3 or less')\n")
    code = (
        "import warnings, numpy as np\n"
        "from lilium import jit\n"
        "from lilium.imaging.raster import mesh_edge_topology\n"
        "faces = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    warnings.simplefilter('always')\n"
        "    got = mesh_edge_topology(faces)\n"
        "    again = mesh_edge_topology(faces)\n"
        "with jit.kernels('numpy'):\n"
        "    want = mesh_edge_topology(faces)\n"
        "assert jit.backend() == 'numpy', jit.backend()\n"
        "assert (got.edges == want.edges).all() and (again.edges == want.edges).all()\n"
        "assert (got.incidence.data == want.incidence.data).all()\n"
        "print(len(caught), caught[0].message)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "LILIUM_KERNELS": "jit"}
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    ).stdout
    assert out.startswith("1 numba failed to import (Numba needs NumPy 2.3 or less)"), out


def test_the_incidence_of_edges_without_sides_is_zero():
    """An edge no side runs along (possible through :func:`edge_incidence`'s arguments, not
    from a mesh) has an empty row, as in scipy's CSR."""
    from scipy import sparse

    from lilium.imaging.raster import edge_incidence

    edge_of, direction = np.array([0, 2, 2, 4, 0, 2]), np.array([1.0, 1, 1, -1, -1, 1])
    dense = np.arange(10.0).reshape(2, 5)
    want = sparse.csr_matrix((direction, (edge_of, np.arange(6) // 3)), shape=(5, 2))
    want.sum_duplicates()
    for name in ("numba", "numpy"):
        with jit.kernels(name if jit.NUMBA_AVAILABLE else "numpy"):
            got = edge_incidence(edge_of, direction, 5)
        np.testing.assert_array_equal(got.indptr, want.indptr)
        np.testing.assert_array_equal(got.indices, want.indices)
        np.testing.assert_array_equal(got.data, want.data)
        np.testing.assert_array_equal(got @ dense, want @ dense)
    with pytest.raises(ValueError, match="three sides per face"):
        edge_incidence(edge_of[:5], direction[:5], 5)
