#!/usr/bin/env bash
# `rccx teach` in a real terminal: tmux types the keys an operator would (move a joint, jog it in
# pendant mode, examine, save, exit), the pane's text is read back, and `rccx db show` must
# print the saved position. Usage: teach_tmux_test.sh RCCX
set -euo pipefail
rccx="$1"
dir=$(mktemp -d)
session="rccx_teach_$$"
trap 'tmux kill-session -t "$session" 2>/dev/null || true; rm -rf "$dir"' EXIT
tmux new-session -d -s "$session" -x 200 -y 50 "$rccx teach --robot microbo --db $dir/cell.db; sleep 30"
send() { tmux send-keys -t "$session" "$1" Enter; sleep 0.5; }
sleep 1
send "m 1 20"
send "p"
send "1+"
send "q"
send "xd"
send "save TAUGHT"
send "e"
for _ in $(seq 1 40); do
  tmux capture-pane -p -t "$session" > "$dir/pane.txt"
  grep -q "taught T6" "$dir/pane.txt" && break
  sleep 0.25
done
cat "$dir/pane.txt"
grep -q "joints 2[45]\.[0-9]*deg" "$dir/pane.txt" || { echo "FAIL: xd did not show theta1 near 25 deg"; exit 1; }
grep -q "saved TAUGHT for microbo" "$dir/pane.txt" || { echo "FAIL: not saved"; exit 1; }
show=$("$rccx" db --db "$dir/cell.db" show --robot microbo TAUGHT)
echo "$show"
echo "$show" | grep -q "microbo TAUGHT: x " || { echo "FAIL: rccx db show"; exit 1; }
echo PASS
