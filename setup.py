"""Builds the kernels ahead of time into ``lilium/_kernels_aot`` (numba's pycc; see lilium.jit).

Everything else about the package is in pyproject.toml. The build is optional: without a C
compiler (or should it fail otherwise) the package installs without the module (``pip install
-v`` shows the reason), and its kernels are compiled by numba's JIT on first use, as before.
"""

import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

AOT_MODULE = "lilium._kernels_aot"


class BuildKernels(build_ext):
    def build_extension(self, ext):
        if ext.name != AOT_MODULE:
            return super().build_extension(ext)
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        sys.path.insert(0, str(Path(__file__).resolve().parent / "src"))
        try:
            from lilium.jit_aot import build

            print("lilium: compiling the kernels ahead of time (0.5-1 min)", file=sys.stderr)
            build(target.parent, target.name)
        except Exception as error:  # noqa: BLE001 - any failure leaves numba's JIT in charge
            print(
                f"lilium: the kernels were not compiled ahead of time ({error}); numba's JIT "
                "compiles them on first use instead",
                file=sys.stderr,
            )
        finally:
            sys.path.pop(0)


setup(
    ext_modules=[Extension(AOT_MODULE, sources=[], optional=True)],
    cmdclass={"build_ext": BuildKernels},
)
