#!/bin/bash
# Runs every MoorDyn input deck under a directory (MoorDyn's tests/Mooring)
# through `cablesim run`, each from its own folder as MoorDyn's tests read
# their data files, and prints one line per deck: cablesim's exit code, the
# deck, and the first line of its message (0: ran; 2: refused, naming the
# deck's line; 3: a numerical failure). Data files beside the decks (current
# profiles, grids) are recognised by having no MoorDyn section header and are
# skipped. docs/moordyn-files.md gives the count this produced.
#
#   tests/tools/run_moordyn_decks.sh MOORDYN/tests/Mooring [build/bin/cablesim]
set -u
dir=${1:?usage: run_moordyn_decks.sh MOORDYN_TESTS_MOORING_DIR [CABLESIM]}
bin=$(realpath "${2:-build/bin/cablesim}")
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cd "$dir" || exit 2
find . \( -name '*.txt' -o -name '*.dat' \) | sort | while read -r f; do
  grep -q -E -- '^-+ *(LINE|ROD|POINT|CONNECTION|NODE|BODY|BODIES|RODS|LINES|OPTIONS|LINE TYPES|ROD TYPES)' "$f" || continue
  log="$out/run.log"
  (cd "$(dirname "$f")" && timeout 600 "$bin" run "$(basename "$f")" --out "$out/out.csv" >"$log" 2>&1)
  rc=$?
  msg=$(grep -m1 -E '^cablesim:|"status":"failed"' "$log" | cut -c1-160)
  echo "$rc $f $msg"
done
