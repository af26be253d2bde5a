"""Provenance of a result: fingerprints of the input files and the software that made it.

Reports and result files record these so a reader can check that a result came from exactly
these inputs (SHA-256 of each file) with these versions of Python and the packages.
"""

import hashlib
import platform
import sys
from dataclasses import dataclass
from pathlib import Path

#: Packages whose versions the provenance lists.
PACKAGES = ("lilium", "numpy", "scipy", "poselib", "opencv-python-headless", "trimesh", "pillow")

#: Bytes read at a time while hashing.
HASH_CHUNK_BYTES = 1 << 20


@dataclass(frozen=True)
class InputFile:
    """One labelled input file and its fingerprint.

    Attributes
    ----------
    label : str
        What the file is (``"skull mesh"``, ``"photo"``, ...).
    path : str
    size_bytes : int or None
        None when the file is missing.
    sha256 : str or None
        Hex digest; None when the file is missing.
    """

    label: str
    path: str
    size_bytes: int | None
    sha256: str | None


def sha256_of(path, chunk=HASH_CHUNK_BYTES):
    """Hex SHA-256 of a file.

    Parameters
    ----------
    path : str or Path
    chunk : int
        Bytes read at a time.

    Returns
    -------
    str
        64 hex digits.
    """
    digest = hashlib.sha256()
    with Path(path).open("rb") as fh:
        while block := fh.read(chunk):
            digest.update(block)
    return digest.hexdigest()


def input_files(inputs, cache=None):
    """Fingerprint labelled input files.

    Parameters
    ----------
    inputs : dict of str -> str or Path
        Label -> file (``{"skull mesh": path, ...}``).
    cache : dict of Path -> str, optional
        Digests already computed, keyed by resolved path; filled in (hash a file shared by
        several SFOs once).

    Returns
    -------
    tuple of InputFile
        In the order of ``inputs``; a missing file has ``size_bytes`` and ``sha256`` None.
    """
    cache = {} if cache is None else cache
    out = []
    for label, path in inputs.items():
        path = Path(path)
        if not path.is_file():
            out.append(InputFile(str(label), str(path), None, None))
            continue
        key = path.resolve()
        if key not in cache:
            cache[key] = sha256_of(path)
        out.append(InputFile(str(label), str(path), path.stat().st_size, cache[key]))
    return tuple(out)


def software_versions(packages=PACKAGES):
    """Versions of Python, the platform and the packages the results depend on.

    Parameters
    ----------
    packages : sequence of str
        Distribution names.

    Returns
    -------
    dict of str -> str
        ``python``, ``platform``, then one entry per package (``"not installed"`` where absent).
    """
    from importlib import metadata

    out = {"python": sys.version.split()[0], "platform": platform.platform()}
    for name in packages:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out
