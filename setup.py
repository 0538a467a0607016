"""The build behind `pip install --no-build-isolation .` (pyproject.toml, docs/PYTHON.md).

The compiled module rccx._rccx is built by the project's own CMake, as `cmake --build --target
rccx_python` builds it (same flags, same static libraries, ccache when installed), not by
setuptools' compiler: Debian 12 has no scikit-build-core, and a second description of the build
would drift from CMake's. Only the module's target and what it links are built.

Environment:
  RCCX_PIP_BUILD_DIR  the CMake build tree (default: build/pip in the source tree, kept, so a
                      second install rebuilds only what changed)
  CMAKE_BUILD_PARALLEL_LEVEL  parallel jobs (default 2)
  CMAKE_ARGS          more -D options for the configure step, split on spaces
"""

import glob
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, find_packages, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        m = re.search(r"project\(rccx\s+VERSION\s+([0-9.]+)", f.read())
    if not m:
        sys.exit("setup.py: no `project(rccx VERSION ...)` in CMakeLists.txt")
    return m.group(1)


class CMakeBuild(build_ext):
    """Builds each extension (only rccx._rccx) with CMake and copies the module where setuptools
    packs it."""

    def build_extension(self, ext):
        cmake = shutil.which("cmake")
        if cmake is None:
            sys.exit("setup.py: cmake not found (apt-get install cmake, or scripts/install-deps)")
        build_dir = os.environ.get("RCCX_PIP_BUILD_DIR", os.path.join(ROOT, "build", "pip"))
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        configure = [
            cmake, "-S", ROOT, "-B", build_dir,
            "-DCMAKE_BUILD_TYPE=Release",
            "-DRCCX_PYTHON=ON",  # missing pybind11 / NumPy / Python.h is an error naming them
            "-DRCCX_BUILD_TESTS=OFF",
            "-DRCCX_BUILD_BENCHMARKS=OFF",
            # The interpreter pip runs (a venv's, or Debian's): the module's ABI is its.
            f"-DPython3_EXECUTABLE={sys.executable}",
            *os.environ.get("CMAKE_ARGS", "").split(),
        ]
        self.announce(" ".join(configure), level=2)
        subprocess.run(configure, check=True)
        subprocess.run([cmake, "--build", build_dir, "--target", "rccx_python", "-j", jobs],
                       check=True)
        built = sorted(glob.glob(os.path.join(build_dir, "python", "rccx", "_rccx*.so")))
        if len(built) != 1:
            sys.exit(f"setup.py: expected one _rccx*.so in {build_dir}/python/rccx, found {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built[0], target)


setup(
    version=version(),
    # Every package under python/ (rccx and any subpackage others add), with its .py files; the
    # stubs and marker as data, whatever their names: python/rccx/*.pyi, py.typed.
    packages=find_packages("python", include=["rccx", "rccx.*"]),
    package_dir={"": "python"},
    package_data={"": ["*.pyi", "py.typed"]},
    ext_modules=[Extension("rccx._rccx", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
