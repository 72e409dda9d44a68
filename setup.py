"""`pip install .`: the package `quadlod` with its extension built by CMake (issue 36).

The package is addons/blender/quadlod/ (the same files as the Blender add-on, see docs/blender.md)
plus the extension `quadlod._core`, which CMake builds (target `quadlod_python`,
python/CMakeLists.txt) and build_ext copies into the wheel. Metadata is in pyproject.toml; the
version is CMakeLists.txt's project(quadlod VERSION ...).

The CMake tree:
  default                      a fresh Release tree in a temporary directory, removed afterwards;
                               only the module and the library it needs are built (no tests, CLI,
                               report assets, benchmarks or fuzz targets). Minutes on 2 cores.
  QUADLOD_CMAKE_BUILD_DIR=DIR  DIR configured by this checkout (e.g. build/ from scripts/build):
                               only `quadlod_python` is brought up to date there and copied — the
                               CTest test python_pip_install uses it. DIR without a CMakeCache.txt
                               is configured as the default tree would be, and kept.
  CMAKE_BUILD_PARALLEL_LEVEL   build jobs (default: all cores); CMAKE_GENERATOR: the generator
                               (default: Ninja when `ninja` is on PATH).

setuptools' own scratch (build/lib.*, build/bdist.*, quadlod.egg-info) goes to a temporary
directory too, so a pip build neither leaves files in the checkout nor writes into the
repository's build/ tree.
"""

import atexit
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))

# What the module needs and nothing else; the options are CMakeLists.txt's.
CMAKE_OPTIONS = [
    "-DCMAKE_BUILD_TYPE=Release",
    "-DQUADLOD_BUILD_PYTHON=ON",
    "-DQUADLOD_BUILD_TESTS=OFF",
    "-DQUADLOD_BUILD_BENCH=OFF",
    "-DQUADLOD_FUZZ=OFF",
    "-DQUADLOD_SANITIZE=OFF",
    "-DQUADLOD_HTML_REPORT=OFF",  # three.js (node_modules) is for the CLI's report only
]


def cmake_version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(\s*quadlod\s+VERSION\s+([0-9][0-9.]*)", f.read())
    if not match:
        sys.exit("setup.py: no `project(quadlod VERSION x.y.z)` in CMakeLists.txt")
    return match.group(1)


SCRATCH = tempfile.mkdtemp(prefix="quadlod-setup-")
atexit.register(shutil.rmtree, SCRATCH, ignore_errors=True)


def cache_value(tree, name):
    with open(os.path.join(tree, "CMakeCache.txt"), encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith(name + ":"):
                return line.split("=", 1)[1].strip()
    return None


def run(command):
    print("setup.py: " + " ".join(command), flush=True)
    subprocess.run(command, check=True)


class CMakeBuild(build_ext):
    """Builds quadlod._core with CMake instead of setuptools' compiler."""

    def build_extension(self, ext):
        tree = os.environ.get("QUADLOD_CMAKE_BUILD_DIR")
        tree = os.path.abspath(tree) if tree else os.path.join(SCRATCH, "cmake")
        if os.path.exists(os.path.join(tree, "CMakeCache.txt")):
            source = cache_value(tree, "CMAKE_HOME_DIRECTORY")
            if not source or os.path.realpath(source) != os.path.realpath(ROOT):
                sys.exit(f"setup.py: QUADLOD_CMAKE_BUILD_DIR={tree} was configured for {source}, not {ROOT}")
        else:
            configure = ["cmake", "-S", ROOT, "-B", tree, *CMAKE_OPTIONS,
                         # the interpreter pip runs (a virtual environment's python is fine)
                         f"-DPython_EXECUTABLE={sys.executable}"]
            if "CMAKE_GENERATOR" not in os.environ and shutil.which("ninja"):
                configure += ["-G", "Ninja"]
            try:  # pybind11 from the build environment (PyPI's under build isolation)
                import pybind11

                configure.append(f"-Dpybind11_DIR={pybind11.get_cmake_dir()}")
            except (ImportError, AttributeError):
                pass  # CMake looks for it (Debian: python3-pybind11, /usr/lib/cmake/pybind11)
            run(configure)
        build = ["cmake", "--build", tree, "--target", "quadlod_python", "--config", "Release"]
        if "CMAKE_BUILD_PARALLEL_LEVEL" not in os.environ:  # cmake --build reads it itself
            build += ["--parallel", str(self.parallel or os.cpu_count() or 1)]
        run(build)

        # CMake names the module from the same interpreter's SOABI, e.g. _core.cpython-311-x86_64-linux-gnu.so.
        name = "_core" + sysconfig.get_config_var("EXT_SUFFIX")
        built = os.path.join(tree, "python", "quadlod", name)
        if not os.path.exists(built):
            found = os.listdir(os.path.dirname(built)) if os.path.isdir(os.path.dirname(built)) else []
            sys.exit(f"setup.py: {built} was not built — {tree} builds for another Python? "
                     f"(its python/quadlod/ holds {found}; this is {sys.executable})")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built, target)


setup(
    version=cmake_version(),
    packages=["quadlod"],
    package_dir={"quadlod": "addons/blender/quadlod"},
    ext_modules=[Extension("quadlod._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    options={"build": {"build_base": os.path.join(SCRATCH, "build")},
             "egg_info": {"egg_base": SCRATCH}},
)
