"""Write requirements.lock: the exact versions installed here of Lilium's dependency closure.

pyproject.toml gives compatible ranges (a library installed beside others); the lock file pins
what CI and the README's Quick start install (``pip install -c requirements.lock ...``), so that
results repeat across machines. Run from the repository root, in an environment where
``pip install -e ".[test,photo,ct,dask]"`` was run (Python 3.11, Linux)::

    python .ci/lock.py > requirements.lock

The closure: the core dependencies and those of the extras in ``EXTRAS`` (``bench``, pycolmap
for one benchmark, is left out), and theirs, markers evaluated for this interpreter.
"""

import sys
import tomllib
from importlib.metadata import PackageNotFoundError, distribution
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

EXTRAS = ("test", "photo", "ct", "dask")

#: The lock file's first lines.
HEADER = """\
# Exact versions for CI and the README's Quick start: pip install -c requirements.lock ...
# pyproject.toml gives compatible ranges; this file pins. Written by .ci/lock.py (Python 3.11,
# Linux); after a change of a dependency, regenerate it from a fresh virtual environment:
#   python -m pip install -e ".[test,photo,ct,dask]" && python .ci/lock.py > requirements.lock
"""


def closure(requirements):
    """``{canonical name: version}`` of the installed distributions ``requirements`` (strings)
    need, transitively, with the dependencies of every extra asked for on the way."""
    found, seen, todo = {}, set(), [Requirement(r) for r in requirements]
    while todo:
        requirement = todo.pop()
        name = canonicalize_name(requirement.name)
        extras = sorted(requirement.extras) or [""]
        if all((name, e) in seen for e in extras):
            continue
        seen.update((name, e) for e in extras)
        try:
            dist = distribution(requirement.name)
        except PackageNotFoundError:
            sys.exit(f"{requirement.name} is not installed: pip install -e '.[{','.join(EXTRAS)}]'")
        found[name] = dist.version
        for text in dist.requires or ():
            needed = Requirement(text)
            if needed.marker is None or any(needed.marker.evaluate({"extra": e}) for e in extras):
                todo.append(needed)
    return found


def main():
    project = tomllib.loads(Path("pyproject.toml").read_text())["project"]
    roots = list(project["dependencies"])
    for extra in EXTRAS:
        roots += project["optional-dependencies"][extra]
    pins = closure(roots)
    print(HEADER, end="")
    for name in sorted(pins):
        print(f"{name}=={pins[name]}")


if __name__ == "__main__":
    main()
