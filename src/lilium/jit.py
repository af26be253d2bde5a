"""Compiled kernels: numba when it is there, the numpy reference path otherwise.

The hot loops of an SFO (the skull raster and P_skof's outside-pixel count, the curve detection and
pairing of P_pll, the batched Levenberg-Marquardt of the population (plain, and on the camera
priors for the joint SFO) and its reprojection errors, the cameras' checks and terms (MSE_pix,
P_cam), the decoding of the genes, the DE's trials, the pinhole projection) have two
implementations that give the same numbers: a compiled kernel (``_*_kernels.py`` modules, numba,
``cache=True``, so only the first run on a machine pays the compile time) and the plain numpy code
they replaced, kept as the reference the tests compare the kernels against and as the fallback. On
the same inputs integers agree exactly, floats to 1e-9 (most of them bit for bit); since the
projection itself is compiled, a pixel that rounds at exactly half a pixel may round the other way
on the two paths (a rare one-pixel difference in a curve or a count).

numba is a pinned dependency (``pyproject.toml``); should it fail to import (a platform without
its wheels), Lilium still runs, on the numpy path, only slower. ``LILIUM_KERNELS=numpy`` in the
environment forces the numpy path (the benchmarks' reference timings); :func:`kernels` switches
it inside a process (tests).
"""

import contextlib
import os

try:  # pragma: no cover - depends on the install
    import numba as _numba
except ImportError:  # pragma: no cover
    _numba = None

#: Whether numba imported.
NUMBA_AVAILABLE = _numba is not None

_state = {"backend": "numba" if NUMBA_AVAILABLE else "numpy"}
if os.environ.get("LILIUM_KERNELS", "").strip().lower() == "numpy":
    _state["backend"] = "numpy"


def njit(*args, **kwargs):
    """``numba.njit(cache=True, ...)``, or the plain Python function without numba.

    Used as ``@njit`` or ``@njit(...)``. No ``fastmath``: the kernels must round exactly as
    numpy does.
    """
    kwargs.setdefault("cache", True)
    if _numba is None:  # pragma: no cover
        if args and callable(args[0]):
            return args[0]
        return lambda f: f
    return _numba.njit(*args, **kwargs)


def compiled():
    """True when the compiled kernels are in use (numba imported and not switched off)."""
    return _state["backend"] == "numba"


def backend():
    """``"numba"`` or ``"numpy"``: the path the hot loops take now."""
    return _state["backend"]


@contextlib.contextmanager
def kernels(name):
    """Run a block on the ``"numba"`` or ``"numpy"`` path.

    Raises
    ------
    ValueError
        Unknown name, or ``"numba"`` when numba is not installed.
    """
    if name not in ("numba", "numpy"):
        raise ValueError(f"kernels must be 'numba' or 'numpy', got {name!r}")
    if name == "numba" and not NUMBA_AVAILABLE:
        raise ValueError("numba is not installed: pip install 'numba==0.68.1'")
    previous = _state["backend"]
    _state["backend"] = name
    try:
        yield
    finally:
        _state["backend"] = previous
