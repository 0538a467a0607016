#!/usr/bin/env bash
# The Python package rccx installed the ways README.md says, and imported from outside the tree:
#   pip-venv  `pip install --no-build-isolation .` into a venv with --system-site-packages, from a
#             clean copy of the checkout (its tracked and unignored files: what a clone holds);
#   pip-root  Debian's pip as root without a venv (--break-system-packages, PEP 668), into a
#             temporary root (PIP_ROOT) instead of /usr/local;
#   cmake     `cmake --install` of the build under test into a temporary prefix.
# The README blocks marked <!-- install_test: pip-venv / pip-root --> are run as written (~/venvs
# mapped to the temporary directory), so the test fails when the README drifts. Each install's
# rccx.kin.robot("puma560").forward is checked against the `rccx kin fk` command of the build
# under test. pip runs offline (PIP_NO_INDEX): everything comes from Debian's packages.
# Pieces missing (git, the venv module, pip, setuptools, wheel) skip the test saying which
# ("rccx-skip:"). The pip builds are Release builds of the module's target only, -j2, ccache.
# Usage: pip_install_test.sh BUILD_DIR SOURCE_DIR RCCX_CLI "LD_PRELOAD for the build's module"
set -euo pipefail
# shellcheck source=tests/readme_block.sh
source "$(dirname "$0")/readme_block.sh"
build=$1 source=$2 cli=$3 preload=${4:-}
python=/usr/bin/python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
readme=$source/README.md
# Debian's pip and python3 first (a pyenv or venv on PATH does not see Debian's packages).
export PATH=/usr/bin:/bin:$PATH PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1
export CMAKE_BUILD_PARALLEL_LEVEL=2
unset PYTHONPATH PIP_ROOT PIP_PREFIX PIP_TARGET PIP_USER VIRTUAL_ENV

skip() { echo "rccx-skip: $*"; exit 0; }
command -v git > /dev/null || skip "git not found (the test copies the checkout's files)"
git -C "$source" rev-parse --git-dir > /dev/null 2>&1 || skip "$source is not a git checkout"
$python -c "import ensurepip, venv" 2> /dev/null ||
  skip "no venv module (apt-get install python3-venv)"
for module in pip setuptools wheel numpy pybind11; do
  $python -c "import $module" 2> /dev/null ||
    skip "$python has no $module (scripts/install-deps installs python3-$module)"
done

# The fenced block after "<!-- install_test: NAME -->" in the README, ~/venvs mapped.
block() {
  local text
  text=$(readme_block "$readme" "$1") || exit 1
  echo "${text//\~\/venvs/$work/venvs}"
}
# Runs the block NAME in the clean copy; its output in $work/NAME.log, shown when it fails.
run_block() {
  local name=$1
  shift
  (cd "$work/clone" && env "$@" bash -euo pipefail <<< "$(block "$name")") \
    > "$work/$name.log" 2>&1 ||
    { tail -60 "$work/$name.log"; echo "README block $name failed" >&2; exit 1; }
  echo "$name: installed"
}
# Imports rccx with PYTHON (and env ...) from $work (outside both trees), checks that it comes
# from under WHERE, and checks forward against the rccx command on random joint values.
check() {
  local where=$1 py=$2
  shift 2
  if ! (cd "$work" && env "$@" RCCX_CLI="$cli" WHERE="$where" SOURCE="$source" "$py" -s -) <<'PY'

import json, os, pathlib, subprocess, sys
import numpy as np
import rccx
where = os.path.realpath(os.environ["WHERE"])
origin = os.path.realpath(rccx.__file__)
assert origin.startswith(where + os.sep), f"rccx imported from {origin}, not from under {where}"
# The package whole: every .py, .pyi and py.typed of python/rccx, and the compiled module.
package = pathlib.Path(origin).parent
source = pathlib.Path(os.environ["SOURCE"], "python", "rccx")
wanted = {p.relative_to(source) for p in source.rglob("*")
          if p.suffix in (".py", ".pyi") or p.name == "py.typed"}
missing = sorted(str(p) for p in wanted if not (package / p).is_file())
assert not missing, f"{package} lacks {missing}"
assert list(package.glob("_rccx*.so")), f"{package} has no _rccx*.so"
k = rccx.kin.robot("puma560")
rng = np.random.default_rng(27)
qs = rng.uniform(k.lower, k.upper, (8, k.dof))
batch = k.forward(qs)
for i, q in enumerate(qs):
    out = subprocess.run([os.environ["RCCX_CLI"], "kin", "fk", "--robot", "puma560",
                          *map(repr, map(float, q)), "--json"],
                         check=True, capture_output=True, text=True).stdout
    expected = np.array(json.loads(out)["T"])
    # Another build of the same C++ (Release here, the test's build there): equal within rounding.
    for got in (k.forward(q), batch[i]):
        assert got.shape == (4, 4) and got.dtype == np.float64
        assert np.max(np.abs(got - expected)) <= 1e-12, (q, got, expected)
print(f"rccx {origin}: forward == rccx kin fk on {len(qs)} PUMA 560 poses")
PY
  then
    echo "the rccx installed under $where fails its check" >&2
    exit 1
  fi
}

# A clean copy: the checkout's tracked files and new unignored ones (no build trees).
mkdir "$work/clone"
git -C "$source" ls-files -z --cached --others --exclude-standard |
  (cd "$source" && tar -cf - --null --no-recursion -T - 2> /dev/null) | tar -xf - -C "$work/clone"
[[ -f $work/clone/pyproject.toml && -f $work/clone/setup.py ]] ||
  { echo "the copy has no pyproject.toml / setup.py" >&2; exit 1; }

# 1. A venv seeing Debian's packages; the README's lines.
run_block pip-venv
venv_python=$(find "$work/venvs" -maxdepth 3 -path '*/bin/python3' | head -1)
[[ -x $venv_python ]] || { echo "the pip-venv block made no venv under ~/venvs" >&2; exit 1; }
check "$("$venv_python" -c 'import sysconfig; print(sysconfig.get_path("platlib"))')" "$venv_python"

# 2. Debian's pip without a venv, as root (PEP 668's flag), into a temporary root.
run_block pip-root PIP_ROOT="$work/root"
root_dir=$(find "$work/root" -type f -path '*/rccx/__init__.py' -printf '%h\n' | head -1)
[[ -n $root_dir ]] ||
  { echo "pip-root installed no rccx/__init__.py under $work/root" >&2; exit 1; }
check "$(dirname "$root_dir")" "$python" PYTHONPATH="$(dirname "$root_dir")"

# 3. cmake --install of the build under test: the package beside the libraries.
cmake --install "$build" --prefix "$work/prefix" > "$work/cmake-install.log" 2>&1 ||
  { tail -30 "$work/cmake-install.log"; exit 1; }
prefix_dir=$(find "$work/prefix" -type f -path '*/rccx/__init__.py' -printf '%h\n' | head -1)
[[ -n $prefix_dir ]] ||
  { echo "cmake --install put no rccx/__init__.py under the prefix" >&2; exit 1; }
ls "$prefix_dir"/_rccx*.so "$prefix_dir"/py.typed "$prefix_dir"/__init__.pyi > /dev/null
preload_env=()
[[ -n $preload ]] && preload_env=(LD_PRELOAD="$preload" ASAN_OPTIONS=detect_leaks=0)
check "$(dirname "$prefix_dir")" "$python" PYTHONPATH="$(dirname "$prefix_dir")" "${preload_env[@]}"
echo "pip_install_test: pip (venv and root) and cmake --install give an importable rccx"
