#!/usr/bin/env bash
# A full disk under every write rccx makes: `db export`, the sample logs (--log and RCCX_LOG), a
# database import, standard output. Each must exit 1 with a message, and leave a file it was
# replacing as it was, with no temporary file behind.
#   full_disk_test.sh RCCX ENOSPC_PRELOAD_LIB
# The full disk is a 64 KiB tmpfs in a private mount namespace when this machine lets us mount
# one (root, unshare), and in any case also the preload library (tests/enospc_preload.c), which
# fails writes under a directory with ENOSPC.
set -uo pipefail
rccx="$1"
preload="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
passed=0

fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok: $*"; passed=$((passed + 1)); }

# 600 transforms as an export file, to fill 64 KiB several times over.
python3 - "$work/big.json" <<'PY'
import json, sys
t = [{"robot": "puma560", "name": f"P{i}", "T_rows_m": [1,0,0,0.4,0,1,0,0.1,0,0,1,0.3],
      "configuration": "", "note": "x" * 40, "created_unix_s": 1, "changed_unix_s": 1}
     for i in range(600)]
json.dump({"rccx_position_database": 1, "units": "m, rad", "transforms": t},
          open(sys.argv[1], "w"))
PY
"$rccx" db --db "$work/cell.db" import "$work/big.json" 2>/dev/null || fail "setup: import into $work/cell.db"

# run NAME EXPECTED_EXIT FULL_DIR COMMAND...: runs it with the disk under FULL_DIR full.
expect() {
  local name="$1" want="$2" dir="$3" mode="$4"
  shift 4
  local err="$work/stderr"
  if [[ "$mode" == preload ]]; then
    ASAN_OPTIONS="${ASAN_OPTIONS:-}:verify_asan_link_order=0" LD_PRELOAD="$preload" \
      RCCX_ENOSPC_DIR="$dir" "$@" >/dev/null 2>"$err"
  else
    "$@" >/dev/null 2>"$err"
  fi
  local got=$?
  if [[ "$got" != "$want" ]]; then
    fail "$name ($mode): exit $got, expected $want; stderr: $(head -c 400 "$err")"
    return 1
  fi
  if [[ "$want" != 0 && ! -s "$err" ]]; then
    fail "$name ($mode): exit $got but nothing said on stderr"
    return 1
  fi
  return 0
}

intact() {  # FILE CONTENT NAME MODE
  if [[ "$(cat "$1")" != "$2" ]]; then fail "$3 ($4): $1 was changed"; return 1; fi
  if ls -A "$(dirname "$1")" | grep -q '\.tmp-'; then fail "$3 ($4): a temporary file was left"; return 1; fi
  return 0
}

cases() {  # FULL_DIR MODE
  local full="$1" mode="$2"
  rm -f "$full"/*  # each case on an empty disk, whatever the one before left
  echo "GOOD" >"$full/cell.json"
  expect "db export to a full disk" 1 "$full" "$mode" "$rccx" db --db "$work/cell.db" export "$full/cell.json" &&
    intact "$full/cell.json" "GOOD" "db export" "$mode" && pass "db export ($mode)"

  rm -f "$full"/*
  echo "OLD" >"$full/log.csv"
  expect "--log to a full disk" 1 "$full" "$mode" "$rccx" report --robot puma560 --seconds 20 --every 20 \
    --log "$full/log.csv" && intact "$full/log.csv" "OLD" "--log" "$mode" && pass "--log ($mode)"

  rm -f "$full"/*
  echo "OLD" >"$full/env.csv"
  expect "RCCX_LOG to a full disk" 1 "$full" "$mode" env RCCX_LOG="$full/env.csv" "$rccx" report --robot puma560 \
    --seconds 20 --every 20 && intact "$full/env.csv" "OLD" "RCCX_LOG" "$mode" && pass "RCCX_LOG ($mode)"

  rm -f "$full"/*
  expect "a cell's RCCX_LOG to a full disk" 1 "$full" "$mode" env RCCX_LOG="$full/cell.csv" "$rccx" \
    cell-load --robots 3 --seconds 0.3 && pass "a cell's RCCX_LOG, one file a robot ($mode)"

  rm -f "$full"/*
  expect "db import onto a full disk" 1 "$full" "$mode" "$rccx" db --db "$full/full.db" import "$work/big.json" &&
    pass "db import ($mode)"
  rm -f "$full"/*
}

# The tmpfs, when we may mount one.
if unshare -m true 2>/dev/null; then
  export -f cases expect intact fail pass
  export rccx preload work
  out=$(unshare -m --propagation private bash -c '
    mkdir -p "$work/tmpfs" && mount -t tmpfs -o size=64k tmpfs "$work/tmpfs" || exit 99
    failures=0; passed=0
    cases "$work/tmpfs" tmpfs
    echo "counts $passed $failures"')
  status=$?
  echo "$out" | grep -v '^counts '
  if [[ $status == 99 ]]; then
    echo "note: no tmpfs could be mounted; the preload library stands in"
  else
    read -r _ p f <<<"$(echo "$out" | grep '^counts ')"
    passed=$((passed + p)); failures=$((failures + f))
  fi
else
  echo "note: no private mount namespace here; the preload library stands in for a full disk"
fi

mkdir -p "$work/full"
cases "$work/full" preload

# Standard output on a full device.
if [[ -w /dev/full ]]; then
  "$rccx" kin robots >/dev/full 2>"$work/stderr"
  got=$?
  if [[ $got == 1 && -s "$work/stderr" ]]; then pass "stdout to /dev/full"; else fail "stdout to /dev/full: exit $got"; fi
  "$rccx" db --db "$work/cell.db" export >/dev/full 2>"$work/stderr"
  got=$?
  if [[ $got == 1 ]]; then pass "db export to a full stdout"; else fail "db export to a full stdout: exit $got"; fi
fi

echo "$passed passed, $failures failed"
((failures == 0))
