#!/bin/sh
# Regenerates the parameter table of docs/parameters.md (between its BEGIN GENERATED and
# END GENERATED markers) from build/cdem-run --params-markdown. Usage: sh scripts/update_params_doc.sh [BUILD]
set -eu
BUILD=${1:-build}
doc=docs/parameters.md
tmp=$(mktemp)
"$BUILD/cdem-run" --params-markdown > "$tmp.table"
awk -v table="$tmp.table" '
    /^<!-- BEGIN GENERATED/ { print; while ((getline line < table) > 0) print line; skip = 1; next }
    /^<!-- END GENERATED/ { skip = 0 }
    !skip { print }
' "$doc" > "$tmp"
mv "$tmp" "$doc"
rm -f "$tmp.table"
