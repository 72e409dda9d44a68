"""CTest `python_pip_install` (issue 36): `pip install --no-build-isolation --no-index` of the
checkout into a fresh virtual environment (--system-site-packages, for Debian's NumPy, setuptools
and wheel), then the installed module, imported in isolated mode from outside the checkout,
reduces a quad grid.

The extension comes from the test's own build tree (QUADLOD_CMAKE_BUILD_DIR, see setup.py), so
the install takes seconds; a clean pip build is the same setup.py with a fresh CMake tree.
Not named test_*.py: the pytest run of tests/python (test `python_module`) must not collect it.

  /usr/bin/python3 tests/python/check_pip_install.py --source . --build-dir build
"""

import argparse
import glob
import json
import os
import re
import subprocess
import sys
import tempfile
import time

# Runs inside the virtual environment. A 16 × 16 quad grid over a bump z = 0.2 sin(πx) sin(πy),
# x, y in [0, 1], reduced to a quarter: 512 triangle equivalents in, target 128.
CHECK = r"""
import json, sys
import numpy as np
import quadlod

n = 16
i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
x, y = i / n, j / n
height = lambda x, y: 0.2 * np.sin(np.pi * x) * np.sin(np.pi * y)
vertices = np.stack([x, y, height(x, y)], axis=-1).reshape(-1, 3)
a = (i[:-1, :-1] * (n + 1) + j[:-1, :-1]).ravel()
quads = np.stack([a, a + n + 1, a + n + 2, a + 1], axis=-1)

# symmetry="off": the scenario as measured; the bump is mirror-symmetric, and mirrored pairs of
# chord collapses are coarser steps (with symmetry: 60 quads and 8 triangles; docs/symmetry.md).
r = quadlod.simplify(vertices, quads, ratio=0.25, symmetry="off")
rep, sizes, out = r["report"], r["face_sizes"], r["vertices"]
assert rep["input_tri_equivalent"] == 2 * n * n == 512, rep["input_tri_equivalent"]
assert rep["target"] == 128, rep["target"]
assert rep["achieved"] == int(np.sum(sizes - 2)), (rep["achieved"], sizes)
assert abs(rep["achieved"] - 128) <= 0.03 * 128, rep["achieved"]  # Eq. 2's band, epsilon_n = 3 %
# A grid halves in each direction by collapsing whole poly-chords: it stays quads (measured:
# 61 quads and 5 triangles).
assert np.mean(sizes == 4) >= 0.9 and rep["quads"] == int(np.sum(sizes == 4)), (rep["quads"], len(sizes))
assert sizes.sum() == len(r["faces"]) and r["faces"].min() >= 0 and r["faces"].max() < len(out)
# The footprint's corners survive and the vertices stay on the bump (measured: 0.0052 off;
# the input's own facets are 0.001 off it).
assert np.allclose(out[:, :2].min(axis=0), 0) and np.allclose(out[:, :2].max(axis=0), 1), out[:, :2]
off = float(np.abs(out[:, 2] - height(out[:, 0], out[:, 1])).max())
assert off < 0.02, off
print(json.dumps({"module": quadlod._core.__file__, "version": quadlod.__version__, "faces": len(sizes),
                  "quads": rep["quads"], "achieved": rep["achieved"], "target": rep["target"],
                  "max_height_error": round(off, 4)}))
"""


def cmake_version(source):
    with open(os.path.join(source, "CMakeLists.txt"), encoding="utf-8") as f:
        return re.search(r"project\(\s*quadlod\s+VERSION\s+([0-9][0-9.]*)", f.read()).group(1)


def setuptools_leftovers(source):
    """What setuptools would leave in a checkout by default: egg-info, build/{lib,temp,bdist}.*, dist/."""
    patterns = ["*.egg-info", "addons/blender/*.egg-info", "build/lib.*", "build/temp.*", "build/bdist.*", "dist"]
    return {p for pattern in patterns for p in glob.glob(os.path.join(source, pattern))}


def run(command, **kwargs):
    print("+ " + " ".join("'<the check above>'" if "\n" in c else c for c in command), flush=True)
    started = time.monotonic()
    result = subprocess.run(command, **kwargs)
    print(f"  ({time.monotonic() - started:.1f} s, exit {result.returncode})", flush=True)
    if result.returncode != 0:
        if kwargs.get("capture_output"):
            print(result.stdout + result.stderr, flush=True)
        sys.exit(f"check_pip_install: failed: {' '.join(command)}")
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", required=True, help="the checkout (holds pyproject.toml)")
    parser.add_argument("--build-dir", required=True, help="a CMake tree of that checkout with quadlod_python")
    parser.add_argument("--python", default=sys.executable, help="the interpreter the venv is made from")
    args = parser.parse_args()
    source, build_dir = os.path.abspath(args.source), os.path.abspath(args.build_dir)

    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "PYTHONUSERBASE") and not k.startswith("PIP_")}
    env.update(QUADLOD_CMAKE_BUILD_DIR=build_dir, PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_NO_INPUT="1")
    before = setuptools_leftovers(source)
    with tempfile.TemporaryDirectory(prefix="quadlod-pip-test-") as work:
        venv = os.path.join(work, "venv")
        python = os.path.join(venv, "bin", "python")
        # Debian: python3-venv (scripts/bootstrap installs it).
        run([args.python, "-m", "venv", "--system-site-packages", venv], env=env, cwd=work)
        run([python, "-m", "pip", "install", "--no-build-isolation", "--no-index", "--quiet", source],
            env=env, cwd=work)
        shown = run([python, "-m", "pip", "show", "quadlod"], env=env, cwd=work,
                    capture_output=True, text=True).stdout
        version = re.search(r"^Version: (\S+)", shown, re.M).group(1)
        if version != cmake_version(source):
            sys.exit(f"check_pip_install: installed version {version}, CMakeLists.txt says {cmake_version(source)}")
        # -I: no PYTHONPATH, no user site, not the current directory — the venv's quadlod or nothing.
        out = run([python, "-I", "-c", CHECK], env=env, cwd=work, capture_output=True, text=True)
        print(out.stdout.strip())
        found = json.loads(out.stdout)
        module = found["module"]
        if found["version"] != version:
            sys.exit(f"check_pip_install: quadlod.__version__ is {found['version']}, the wheel's {version}")
        if not os.path.realpath(module).startswith(os.path.realpath(venv) + os.sep):
            sys.exit(f"check_pip_install: quadlod was imported from {module}, not from {venv}")
    junk = setuptools_leftovers(source) - before
    if junk:
        sys.exit(f"check_pip_install: the pip build left {sorted(junk)} in the checkout")
    print("check_pip_install: ok")


if __name__ == "__main__":
    main()
