"""Compiled kernels: ahead of time where built, numba's JIT otherwise, the numpy path without numba.

The hot loops of an SFO (the skull raster and P_skof's outside-pixel count, the curve detection and
pairing of P_pll, the batched Levenberg-Marquardt of the population (plain, and on the camera
priors for the joint SFO) and its reprojection errors, the cameras' checks and terms (MSE_pix,
P_cam), the decoding of the genes, the DE's trials, the pinhole projection) have two
implementations that give the same numbers: a compiled kernel (``_*_kernels.py`` modules, written
for numba) and the plain numpy code they replaced, kept as the reference the tests compare the
kernels against and as the fallback. On the same inputs integers agree exactly, floats to 1e-9
(most of them bit for bit); since the projection itself is compiled, a pixel that rounds at
exactly half a pixel may round the other way on the two paths (a rare one-pixel difference in a
curve or a count).

A kernel is compiled one of two ways, from the same source:

- **ahead of time**, when the package was installed: ``pip install`` builds the extension module
  ``lilium._kernels_aot`` with numba's ``pycc`` (``setup.py``, :mod:`lilium.jit_aot`) for the
  argument types listed in ``lilium/jit_signatures.json`` (recorded from the demo, ``lilium sfo``
  and ``lilium case``, whose SFOs ``lineup`` and ``experiment`` run too). A call whose arguments
  have exactly one of those types runs it, and a process that needs nothing else never imports
  numba (numba's import and its registries cost about 0.5 s per process; the module loads in
  about a millisecond). The module
  carries a hash of the kernels' sources and of that list; after an edit of either, it no longer
  matches and is not used (run ``pip install -e .`` again to rebuild it); nor on another CPU
  than the one it was built for (:func:`cpu_fingerprint`). Without a C compiler the build is
  skipped and everything runs on numba's JIT;
- **just in time**, for every other call: numba (``cache=True``, so only the first run on a
  machine pays the compile time, cached in the package's ``__pycache__`` folders).

numba is a dependency (``pyproject.toml``: the minor release the build uses; its exact version in
``requirements.lock``); should it be missing, or fail to import (a numba built against another
numpy), Lilium still runs, on the numpy path, only slower (a failed import warns once).
``LILIUM_KERNELS=numpy`` in the environment forces the numpy path (the benchmarks' reference
timings), ``LILIUM_KERNELS=jit`` numba's JIT without the ahead-of-time module; :func:`kernels`
switches them inside a process (tests).
"""

import contextlib
import functools
import hashlib
import importlib
import importlib.util
import json
import os
import platform
import warnings
from pathlib import Path

import numpy as np

#: Whether numba is installed (found, not imported: a process served by the ahead-of-time
#: module never imports it).
NUMBA_AVAILABLE = importlib.util.find_spec("numba") is not None

_BACKENDS = ("numba", "jit", "numpy")
_state = {"backend": "numba" if NUMBA_AVAILABLE else "numpy"}
_requested = os.environ.get("LILIUM_KERNELS", "").strip().lower()
if _requested == "numpy" or (_requested == "jit" and NUMBA_AVAILABLE):
    _state["backend"] = _requested

#: Every kernel defined so far, in definition order.
_KERNELS = []
_PACKAGE = Path(__file__).parent


class Kernel:
    """A compiled kernel: the ahead-of-time build for the argument types it was built for,
    numba's JIT for any other.

    Made by :func:`njit`; called like the Python function it wraps. ``py_func`` is that
    function; ``dispatcher`` numba's dispatcher of it (numba is imported on first use).
    """

    def __init__(self, py_func, options):
        self.py_func = py_func
        self.options = options
        self.key = f"{py_func.__module__}.{py_func.__qualname__}"
        self._dispatcher = None
        self._exports = None
        functools.update_wrapper(self, py_func)
        _KERNELS.append(self)

    def __call__(self, *args):
        if _state["backend"] == "numba":
            if self._exports is None:
                self._exports = _aot_exports(self.key)
            for n_args, fits, function in self._exports:
                if len(args) == n_args and fits(*args):
                    return function(*args)
        dispatcher = self.dispatcher
        if dispatcher is None:  # numba would not import: this call in Python, then numpy's path
            return self.py_func(*args)
        return dispatcher(*args)

    @property
    def dispatcher(self):
        """numba's dispatcher of ``py_func`` (compiled, or loaded from its cache, on a call);
        None when numba is installed but fails to import."""
        if self._dispatcher is None:
            numba = _import_numba()
            if numba is None:
                return None
            self._dispatcher = numba.njit(**self.options)(self.py_func)
        return self._dispatcher

    @property
    def targetoptions(self):
        """The options numba's inliner reads from a callee (``inline="always"``)."""
        return {k: v for k, v in self.options.items() if k != "cache"}

    def __repr__(self):
        return f"<lilium kernel {self.key}>"

    def __reduce__(self):  # pickled by name (a Dask task may carry one), like a function
        return _kernel_named, (self.py_func.__module__, self.py_func.__qualname__)


def _kernel_named(module, qualname):
    return getattr(importlib.import_module(module), qualname)


@functools.cache
def _import_numba():
    """numba, taught to compile a call of a :class:`Kernel` from another kernel (it types it as
    the kernel's dispatcher: the module's name holds the Kernel, so numba's cache pickles it by
    reference, and its inliner reads ``py_func`` and ``targetoptions`` from it); or None, with a
    warning and the numpy path from then on, when it is installed but fails to import."""
    try:
        import numba
        from numba.core import types
        from numba.extending import typeof_impl
    except Exception as error:  # noqa: BLE001 - e.g. a numba built for another numpy
        warnings.warn(
            f"numba failed to import ({error}); Lilium runs its numpy reference path (slower)",
            RuntimeWarning,
            stacklevel=3,
        )
        _state["backend"] = "numpy"
        return None

    @typeof_impl.register(Kernel)
    def _typeof_kernel(value, context):
        return types.Dispatcher(value.dispatcher)

    return numba


def njit(*args, **kwargs):
    """A :class:`Kernel` (numba ``njit(cache=True, ...)`` options), or the plain Python function
    without numba.

    Used as ``@njit`` or ``@njit(...)``. No ``fastmath``: the kernels must round exactly as
    numpy does.
    """
    kwargs.setdefault("cache", True)
    if not NUMBA_AVAILABLE:  # pragma: no cover
        if args and callable(args[0]):
            return args[0]
        return lambda f: f
    if args and callable(args[0]):
        return Kernel(args[0], kwargs)
    return lambda f: Kernel(f, kwargs)


def compiled():
    """True when the compiled kernels are in use (numba installed and not switched off)."""
    return _state["backend"] != "numpy"


def backend():
    """``"numba"`` (ahead of time where built, else JIT), ``"jit"`` or ``"numpy"``: the path
    the hot loops take now."""
    return _state["backend"]


@contextlib.contextmanager
def kernels(name):
    """Run a block on the ``"numba"``, ``"jit"`` (numba without the ahead-of-time module) or
    ``"numpy"`` path.

    Raises
    ------
    ValueError
        Unknown name, or a compiled path when numba is not installed.
    """
    if name not in _BACKENDS:
        raise ValueError(f"kernels must be one of {', '.join(_BACKENDS)}, got {name!r}")
    if name != "numpy" and not NUMBA_AVAILABLE:
        raise ValueError("numba is not installed: pip install 'numba==0.68.1'")
    previous = _state["backend"]
    _state["backend"] = name
    try:
        yield
    finally:
        _state["backend"] = previous


# --- the ahead-of-time module -------------------------------------------------------------------

#: The argument types the kernels are built for ahead of time, a data file written by
#: ``python -m lilium.jit_aot record`` (:mod:`lilium.jit_aot` says why it is data).
SIGNATURES_FILE = _PACKAGE / "jit_signatures.json"


@functools.cache
def signature_table():
    """``(modules, signatures)`` of :data:`SIGNATURES_FILE`: the modules that define kernels,
    and ``{kernel key: [[argument specs, return spec], ...]}``."""
    table = json.loads(SIGNATURES_FILE.read_text(encoding="utf-8"))
    return tuple(table["modules"]), table["signatures"]


def source_hash():
    """A 63-bit hash of the kernels' sources and of their signature list (what the ahead-of-time
    module was built from: a module whose hash differs is stale and not used)."""
    modules, _ = signature_table()
    digest = hashlib.sha256()
    for name in (*modules, "lilium.constants"):
        path = _PACKAGE.joinpath(*name.split(".")[1:]).with_suffix(".py")
        digest.update(name.encode() + b"\0" + path.read_bytes())
    digest.update(SIGNATURES_FILE.name.encode() + b"\0" + SIGNATURES_FILE.read_bytes())
    return int.from_bytes(digest.digest()[:8], "little") >> 1


def cpu_fingerprint():
    """A 63-bit hash of this machine's processor: its architecture and, on Linux, the first
    processor's model and instruction-set flags in ``/proc/cpuinfo``.

    The module is built for the CPU it was built on (like numba's JIT); on another one (a shared
    install on a cluster's mixed nodes) its instructions might not exist, so it is not used there.
    """
    text = platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as cpuinfo:
            for line in cpuinfo:
                if not line.strip():
                    break  # the first processor's block
                if line.startswith(("model name", "flags", "Features", "CPU part")):
                    text += line
    except OSError:
        pass
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:8], "little") >> 1


def export_name(index):
    """The ahead-of-time module's name of the ``index``-th signature of
    :func:`aot_signatures`."""
    return f"k{index}"


def aot_signatures():
    """``[(kernel key, argument slots, return slot), ...]`` in the module's export order."""
    _, signatures = signature_table()
    return [(key, args, ret) for key in sorted(signatures) for args, ret in signatures[key]]


@functools.cache
def _aot_table():
    """``{kernel key: [(argument specs, function), ...]}`` of the built module; empty when it
    is absent or stale."""
    try:
        from . import _kernels_aot as module
    except ImportError:
        return {}
    try:
        if module.source_hash() != source_hash() or module.cpu_hash() != cpu_fingerprint():
            return {}
    except (AttributeError, OSError):  # pragma: no cover - a broken build
        return {}
    table = {}
    for index, (key, args, _ret) in enumerate(aot_signatures()):
        function = getattr(module, export_name(index), None)
        if function is not None:
            table.setdefault(key, []).append((args, function))
    return table


def _aot_exports(key):
    """``[(number of arguments, fits, function), ...]`` of one kernel: ``fits(*args)`` is
    True when the arguments have exactly the types numba would give them for that export (or
    types it accepts: any layout for an ``"A"`` slot, a writeable array for a read-only one)."""
    return [(len(args), _matcher(args), function) for args, function in _aot_table().get(key, ())]


_SCALAR_TYPES = {
    "float64": "(float, _np.float64)",
    "int64": "(int, _np.int64)",
    "bool": "(bool, _np.bool_)",
}


def _matcher(specs):
    """A function of the arguments that checks them against ``specs`` in one expression (a
    kernel may be called thousands of times per SFO: about 0.2 us per argument)."""
    names = {"_np": np, "_ndarray": np.ndarray}

    def check(spec, value):
        if isinstance(spec, str):
            if spec not in _SCALAR_TYPES:
                return "False"
            test = f"type({value}) in {_SCALAR_TYPES[spec]}"
            if spec == "int64":
                test += f" and {-(2**63)} <= {value} < {2**63}"
            return test
        if spec[0] == "tuple":
            members = [check(s, f"{value}[{i}]") for i, s in enumerate(spec[1])]
            return " and ".join(
                [f"type({value}) is tuple", f"len({value}) == {len(spec[1])}", *members]
            )
        _, dtype, ndim, layout, readonly = spec
        dtype_name = f"_d{len(names)}"
        names[dtype_name] = np.dtype(dtype)
        tests = [
            f"type({value}) is _ndarray",
            f"((_t := {value}.dtype) is {dtype_name} or _t == {dtype_name})",
            f"{value}.ndim == {ndim}",
        ]
        flags = [f"(_f := {value}.flags).aligned"]
        if layout != "A":
            flags.append(f"_f.{'c' if layout == 'C' else 'f'}_contiguous")
        if not readonly:
            flags.append("_f.writeable")
        return " and ".join(tests + flags)

    arguments = [f"a{i}" for i in range(len(specs))]
    body = " and ".join(check(spec, a) for spec, a in zip(specs, arguments, strict=True)) or "True"
    source = f"def fits({', '.join(arguments)}):\n    return bool({body})\n"
    exec(compile(source, "<lilium.jit matcher>", "exec"), names)
    return names["fits"]
