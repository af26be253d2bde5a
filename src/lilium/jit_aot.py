"""Building the kernels ahead of time (numba's ``pycc``), and the list of signatures it builds.

Not imported by the package at run time (it imports numba); used by ``setup.py`` when the package
is installed, and by a developer after a change of a kernel's arguments::

    python -m lilium.jit_aot record    # rewrite lilium/jit_signatures.json from real runs
    python -m lilium.jit_aot build     # build lilium/_kernels_aot (as pip install -e . does)

``record`` runs what a user runs (the demo, ``lilium sfo`` of every Lilium variant and of
POSEST-SFO on a frontal and a lateral photo, a joint ``lilium case``, a case from a bare skull
mesh) on numba's JIT and writes down the argument types of every call of a kernel from Python
(a kernel called only by other kernels is compiled into its callers). ``build`` compiles one
export per signature, for this machine's CPU (``pip install`` builds where it runs), with the
sources' hash of :func:`lilium.jit.source_hash`, so that a later edit makes the module stale
instead of wrong. A call with other argument types goes to numba's JIT, so a missing signature
costs start-up time, never a wrong answer.

The list is data, not source: ``lilium/jit_signatures.json`` (the kernel modules, and per kernel
its signatures, one per line), written by ``record`` and read by :func:`lilium.jit.signature_table`
(``build``, and the package at run time to find each export). It was a 550-line generated Python
module that read like code. Deriving the signatures at build time from declarations beside the
kernels was the alternative, not taken: the types that count are those real calls produce (array
layouts, read-only flags, the shapes of tuples), which only a run shows, and 33 hand-written
declarations could drift from the calls where a recorded list cannot.
"""

import json
import os
import sys
import tempfile
import time
from pathlib import Path

MODULE_NAME = "_kernels_aot"


# --- numba types <-> the plain literals of lilium/jit_signatures.json ----------------------------


def type_to_spec(t):
    """A numba type as a plain literal: ``("array", dtype, ndim, layout, readonly)``,
    ``("tuple", [...])`` or a scalar's name."""
    from numba.core import types

    if isinstance(t, types.Array):
        return ("array", str(t.dtype), t.ndim, t.layout, not t.mutable)
    if isinstance(t, types.BaseTuple):
        return ("tuple", [type_to_spec(e) for e in t.types])
    if isinstance(t, (types.Float, types.Integer, types.Boolean, types.NoneType)):
        return str(t)
    raise TypeError(f"no literal for the numba type {t}")


def spec_to_type(spec):
    """The inverse of :func:`type_to_spec`."""
    import numpy as np
    from numba import from_dtype
    from numba.core import types

    if isinstance(spec, str):
        return types.none if spec == "none" else from_dtype(np.dtype(spec))
    if spec[0] == "array":
        _, dtype, ndim, layout, readonly = spec
        return types.Array(from_dtype(np.dtype(dtype)), ndim, layout, readonly=readonly)
    return types.Tuple([spec_to_type(s) for s in spec[1]])


# --- record -------------------------------------------------------------------------------------


def _workloads(folder):
    """Run what a user runs, in ``folder`` (short DE budgets: the types, not the answers)."""
    from .cli.main import main

    def run(*args):
        main([str(a) for a in args])

    folder = Path(folder)
    run("demo", "--out", folder / "demo")
    skull = folder / "demo" / "data" / "subjects" / "s01"
    photos = sorted((folder / "demo" / "data" / "photos" / "C").iterdir())
    short = ("--generations", 15, "--population", 20)
    for photo in photos:
        for variant in ("base", "pll", "skof", "skof+pll"):
            out = folder / f"sfo-{photo.name}-{variant}"
            run("sfo", "--skull", skull, "--photo", photo, "--method", "lilium",
                "--variant", variant, "--out", out, *short)  # fmt: skip
        run("sfo", "--skull", skull, "--photo", photo, "--out", folder / f"{photo.name}-posest")
    joint = ("--photo", photos[0], "--photo", photos[1], "--joint")
    run("case", "--skull", skull, *joint, "--out", folder / "joint", *short)
    run("case", "--skull", skull / "skull.ply", "--landmarks", skull / "cranial_landmarks.json",
        "--photo", photos[0], "--out", folder / "mesh", *short)  # fmt: skip


def record():
    """``(modules, signatures)``: the modules that define kernels, and ``{kernel key:
    [(argument specs, return spec), ...]}`` of every call from Python in :func:`_workloads`, on
    numba's JIT."""
    from . import jit

    seen = {}
    call = jit.Kernel.__call__

    def recording(kernel, *args):
        result = call(kernel, *args)
        import numba

        seen.setdefault(kernel.key, {})[tuple(numba.typeof(a) for a in args)] = kernel
        return result

    jit.Kernel.__call__ = recording
    try:
        with jit.kernels("jit"), tempfile.TemporaryDirectory() as folder:
            _workloads(folder)
    finally:
        jit.Kernel.__call__ = call
    signatures = {}
    for key, calls in sorted(seen.items()):
        for argtypes, kernel in calls.items():
            (sig,) = [s for s in kernel.dispatcher.nopython_signatures if s.args == argtypes]
            entry = ([type_to_spec(a) for a in sig.args], type_to_spec(sig.return_type))
            if entry not in signatures.setdefault(key, []):
                signatures[key].append(entry)
    modules = tuple(sorted({kernel.py_func.__module__ for kernel in jit._KERNELS}))
    return modules, signatures


#: The first member of ``lilium/jit_signatures.json``: what the file is (JSON has no comments).
ABOUT = (
    "The argument types the kernels are built for ahead of time (lilium.jit). Written by "
    "`python -m lilium.jit_aot record`; do not edit by hand. Each signature is [argument specs, "
    'return spec], a spec being ["array", dtype, ndim, layout, readonly], '
    '["tuple", [specs]] or a scalar\'s name.'
)


def write_signatures(modules, signatures, path=None):
    """Write ``lilium/jit_signatures.json`` (default: :data:`lilium.jit.SIGNATURES_FILE`): the
    kernel ``modules``, and ``signatures`` (``{kernel key: [(argument specs, return spec),
    ...]}``) sorted by key, one signature per line so that a change reads as a one-line diff."""
    from . import jit

    path = Path(path or jit.SIGNATURES_FILE)
    compact = {"separators": (", ", ": ")}
    lines = ["{", f'  "about": {json.dumps(ABOUT)},', '  "modules": [']
    lines += [f"    {json.dumps(m)}," for m in modules]
    lines[-1] = lines[-1].rstrip(",")
    lines += ["  ],", '  "signatures": {']
    for key, entries in sorted(signatures.items()):
        lines.append(f"    {json.dumps(key)}: [")
        lines += [f"      {json.dumps(entry, **compact)}," for entry in entries]
        lines[-1] = lines[-1].rstrip(",")
        lines.append("    ],")
    lines[-1] = lines[-1].rstrip(",")
    lines += ["  }", "}", ""]
    path.write_text("\n".join(lines))
    jit.signature_table.cache_clear()
    return path


# --- build --------------------------------------------------------------------------------------


def build(output_dir, output_file=None, verbose=False):
    """Compile every signature of ``lilium/jit_signatures.json`` into one extension module in
    ``output_dir`` (file name ``output_file``, default numba's for this Python); returns its
    path."""
    from numba.core import types
    from numba.pycc import CC

    from . import jit

    _import_kernels()
    kernels = {k.key: k for k in jit._KERNELS}
    cc = CC(MODULE_NAME)
    cc.output_dir = str(output_dir)
    if output_file:
        cc.output_file = output_file
    cc.target_cpu = "host"  # built where it runs, like numba's JIT
    cc.verbose = verbose
    cc.export("source_hash", types.int64())(_constant(jit.source_hash()))
    cc.export("cpu_hash", types.int64())(_constant(jit.cpu_fingerprint()))
    for index, (key, args, ret) in enumerate(jit.aot_signatures()):
        signature = spec_to_type(ret)(*[spec_to_type(a) for a in args])
        cc.export(jit.export_name(index), signature)(kernels[key].dispatcher.py_func)
    cc.compile()
    return Path(cc.output_dir) / cc.output_file


def _import_kernels():
    """Import the kernel modules without their packages' ``__init__`` (which import scipy,
    OpenCV, PoseLib...: the isolated build has only numpy and numba)."""
    import importlib
    import types

    from .jit import signature_table

    modules, _ = signature_table()
    root = Path(__file__).parent
    for name in modules:
        package = name.rsplit(".", 1)[0]
        if package not in sys.modules:
            stub = types.ModuleType(package)
            stub.__path__ = [str(root / package.split(".")[1])]
            sys.modules[package] = stub
    for name in modules:
        importlib.import_module(name)


def _constant(value):
    def source_hash():
        return value

    return source_hash


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv == ["record"]:
        os.environ.setdefault("LILIUM_KERNELS", "jit")
        path = write_signatures(*record())
        print(f"wrote {path}")
    elif argv == ["build"]:
        start = time.perf_counter()
        path = build(Path(__file__).parent)
        print(f"built {path} in {time.perf_counter() - start:.0f} s")
    else:
        print("usage: python -m lilium.jit_aot record | build", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
