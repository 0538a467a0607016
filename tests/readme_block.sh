# shellcheck shell=bash
# Sourced by the install tests: readme_block FILE NAME prints the fenced block that follows the
# line "<!-- install_test: NAME -->" in FILE (the README), as written; exits 1 saying so when
# there is none.
readme_block() {
  local text
  text=$(awk -v marker="<!-- install_test: $2 -->" '
    $0 == marker { found = 1; next }
    found && /^```/ { if (inside) exit; inside = 1; next }
    inside { print }' "$1")
  [[ -n $text ]] || { echo "$1 has no block marked <!-- install_test: $2 -->" >&2; exit 1; }
  printf '%s\n' "$text"
}
