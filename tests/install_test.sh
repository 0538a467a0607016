#!/usr/bin/env bash
# rccx installed and used from outside the tree: `cmake --install` into a temporary prefix, then
#   1. an outside CMake project (tests/install/) with find_package(rccx): a C++ program over
#      rccx::rccl and a 1986 C program (examples/cell_handoff.c) over rccx::compat;
#   2. the thesis's washer.c, a manual-style guarded motion and a pumatask() program with no
#      main() built with plain cc and `pkg-config --cflags --libs rccx-compat`.
# Each program runs on the simulated robots and must do what it says.
# Usage: install_test.sh BUILD_DIR SOURCE_DIR "SANITIZER FLAGS (may be empty)"
set -euo pipefail
build=$1 source=$2 flags=${3:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
for f in lib/cmake/rccx/rccxConfig.cmake lib/pkgconfig/rccx-compat.pc include/rccx/compat/rccl.h \
         include/rccx/rccl/manipulator.hpp share/rccx/cells/cvarl.json bin/rccx; do
  [[ -e $prefix/$f ]] || { echo "not installed: $f"; exit 1; }
done

# 1. find_package(rccx)
cmake -S "$source/tests/install" -B "$work/outside" -DCMAKE_PREFIX_PATH="$prefix" \
  -DRCCX_C_PROGRAM="$source/examples/cell_handoff.c" -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" \
  > "$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/outside" -j2 > "$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
"$work/outside/outside_cpp"
out=$(RCCX_CELL= "$work/outside/outside_c")
echo "$out"
grep -q "ended: yes" <<< "$out" && grep -q "puma ended yes, microbo ended yes" <<< "$out"

# 2. pkg-config and plain cc, no CMake
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
# shellcheck disable=SC2046,SC2086  # word splitting of the flags is the point
cc -std=c11 -o "$work/washer" "$source/examples/washer.c" $flags \
  $(pkg-config --cflags --libs rccx-compat)
out=$(RCCX_ROBOT=microbo "$work/washer")
echo "$out" | tail -3
grep -q "velocity 110, 120" <<< "$out"
# A program in the manual's style (K&R functions, a functionally defined monitor, nextmove), as
# gnu89 with implicit declarations refused, its log written where RCCX_LOG says.
# shellcheck disable=SC2046,SC2086
cc -std=gnu89 -Werror=implicit-function-declaration -o "$work/guarded" \
  "$source/examples/c/guarded.c" $flags $(pkg-config --cflags --libs rccx-compat)
out=$(RCCX_LOG="$work/guarded.csv" "$work/guarded")
echo "$out" | tail -1
grep -q "touched at z = " <<< "$out" && test "$(wc -l < "$work/guarded.csv")" -gt 10
# As the manual prints them: rccl.h and manex.h, pumatask() and no main() (rccx_compat_main's).
# shellcheck disable=SC2046,SC2086
cc -std=gnu89 -w -Werror=implicit-function-declaration -o "$work/pumatask" \
  "$source/examples/c/pumatask.c" $flags $(pkg-config --cflags --libs rccx-compat)
out=$("$work/pumatask")
echo "$out" | tail -1
grep -q "square drawn" <<< "$out"
echo "install_test: the CMake package and rccx-compat.pc build and run programs from outside"
