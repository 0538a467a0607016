#!/usr/bin/env bash
# rccx installed and used from outside the tree, exactly as README.md's "Using rccx from another
# project" says: its blocks marked <!-- install_test: NAME --> are taken from the README (so this
# test fails when the README drifts) and run with /opt/rccx read as a temporary prefix and
# build/release as the build under test:
#   install      the `cmake --install` line;
#   cpp          a C++ project that sets no standard (tests/install/outside.cpp as app.cpp);
#   c            a C-only project: washer.c with its main(), pumatask.c with none;
#   example10    examples/10_circuit_board.cpp built outside and run: it finds the cell;
#   pkg-config   the same programs with cc / c++ and pkg-config.
# Then a manual-style guarded motion as gnu89 (implicit declarations refused) with its log.
# The build's sanitizer flags reach the outside builds: CMake's flags, and cc / c++ wrappers first
# on PATH for the pkg-config lines (the instrumented libraries need them).
# Usage: install_test.sh BUILD_DIR SOURCE_DIR "SANITIZER FLAGS (may be empty)"
set -euo pipefail
# shellcheck source=tests/readme_block.sh
source "$(dirname "$0")/readme_block.sh"
build=$1 source=$2 flags=${3:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
readme=$source/README.md
unset RCCX_DATA_DIR RCCX_CELL RCCX_ROBOT RCCX_LOG RCCX_DB

# The fenced block after "<!-- install_test: NAME -->" in the README, the prefix and build mapped.
block() {
  local text
  text=$(readme_block "$readme" "$1") || exit 1
  sed -e "s|/opt/rccx|$prefix|g" -e "s|build/release|$build|g" <<< "$text"
}
# Runs PROGRAM (in the current directory), shows its last lines, and requires REGEX in its output.
expect() {
  local regex=$1 out
  shift
  out=$("$@" 2>&1) || { echo "$out"; echo "failed: $*" >&2; exit 1; }
  tail -2 <<< "$out"
  grep -Eq "$regex" <<< "$out" || { echo "$* did not print /$regex/" >&2; exit 1; }
}
# The sources the README's blocks name, in DIR.
sources() {
  cp "$source/examples/washer.c" "$source/examples/c/pumatask.c" \
     "$source/examples/10_circuit_board.cpp" "$1/"
  cp "$source/tests/install/outside.cpp" "$1/app.cpp"
}
# The README's CMake block NAME as DIR/CMakeLists.txt, configured against the prefix and built.
cmake_project() {
  local name=$1 dir=$work/$1
  mkdir -p "$dir"
  sources "$dir"
  block "$name" > "$dir/CMakeLists.txt"
  # Beside the README's lines: the package says where its data is (CMake's ${}, not the shell's).
  # shellcheck disable=SC2016
  echo 'if(NOT EXISTS "${rccx_DATA_DIR}/cells/cvarl.json")
  message(FATAL_ERROR "rccx_DATA_DIR (${rccx_DATA_DIR}) has no cells/cvarl.json")
endif()' >> "$dir/CMakeLists.txt"
  cmake -S "$dir" -B "$dir/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" \
    > "$dir/configure.log" 2>&1 || { cat "$dir/configure.log"; exit 1; }
  cmake --build "$dir/build" -j2 > "$dir/build.log" 2>&1 || { cat "$dir/build.log"; exit 1; }
}

(cd "$work" && bash -euo pipefail <<< "$(block install)") > "$work/install.log"
for f in lib/cmake/rccx/rccxConfig.cmake lib/pkgconfig/rccx-compat.pc lib/pkgconfig/rccx.pc \
         include/rccx/compat/rccl.h include/rccx/rccl/manipulator.hpp \
         include/rccx/io/installed_data_dir.hpp share/rccx/cells/cvarl.json \
         share/rccx/robots/puma560.json bin/rccx; do
  [[ -e $prefix/$f ]] || { echo "not installed: $f"; exit 1; }
done

# The programs each way builds, run: app finds the installed cell (not the source tree's), as
# example 10 does (run whole once, for CMake: 100 s of simulated time).
run_programs() (
  cd "$1"
  expect "outside: the cell is $prefix/share/rccx/cells/cvarl.json" ./app
  expect "velocity 110, 120" ./washer
  expect "square drawn" ./square
  if [[ $2 == whole ]]; then
    expect "8 pads probed" ./10_circuit_board
  fi
  # A misplaced RCCX_DATA_DIR is named, not silently passed over.
  if out=$(RCCX_DATA_DIR=$work/none ./10_circuit_board 2>&1); then
    echo "10_circuit_board ran with RCCX_DATA_DIR=$work/none" >&2; exit 1
  fi
  grep -q "not in $work/none: RCCX_DATA_DIR" <<< "$out" || { echo "$out"; exit 1; }
)
# 1. CMake: find_package(rccx), the README's three projects.
for name in cpp c example10; do cmake_project "$name"; done
mkdir "$work/cmake-programs"
cp "$work/cpp/build/app" "$work/c/build/washer" "$work/c/build/square" \
   "$work/example10/build/10_circuit_board" "$work/cmake-programs/"
run_programs "$work/cmake-programs" whole

# 2. pkg-config, plain cc and c++ (wrapped to add the build's flags).
mkdir -p "$work/bin" "$work/pc"
for compiler in cc c++; do
  printf '#!/bin/sh\nexec %s "$@" %s\n' "$(command -v $compiler)" "$flags" > "$work/bin/$compiler"
  chmod +x "$work/bin/$compiler"
done
sources "$work/pc"
(cd "$work/pc" && PATH=$work/bin:$PATH bash -euo pipefail <<< "$(block pkg-config)")
[[ $(pkg-config --variable=datadir "$prefix/lib/pkgconfig/rccx.pc") -ef $prefix/share/rccx ]] ||
  { echo "rccx.pc's datadir is not $prefix/share/rccx" >&2; exit 1; }
run_programs "$work/pc" quick

# 3. A program in the manual's style (K&R functions, a functionally defined monitor, nextmove),
# as gnu89 with implicit declarations refused, its log written where RCCX_LOG says.
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
# shellcheck disable=SC2046,SC2086  # word splitting of the flags is the point
cc -std=gnu89 -Werror=implicit-function-declaration -o "$work/guarded" \
  "$source/examples/c/guarded.c" $flags $(pkg-config --cflags --libs rccx-compat)
RCCX_LOG="$work/guarded.csv" expect "touched at z = " "$work/guarded"
test "$(wc -l < "$work/guarded.csv")" -gt 10
echo "install_test: the README's CMake projects and pkg-config lines build and run from outside"
