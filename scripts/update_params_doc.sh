#!/bin/sh
# Regenerates the generated tables of the docs from the program: docs/parameters.md (the
# parameter table, the whole file) and, in docs/solver.md, the tables of the granular laws and
# of the boundary modes (each from its header row to the blank line after it).
# tests/test_params.c fails while any of them is stale. Usage: sh scripts/update_params_doc.sh [BUILD]
set -eu
BUILD=${1:-build}
"$BUILD/cdem-run" --params-markdown > docs/parameters.md.tmp
mv docs/parameters.md.tmp docs/parameters.md
for what in laws modes; do
    "$BUILD/cdem-run" --$what-markdown > "docs/$what.table.tmp"
    head=$(head -n 1 "docs/$what.table.tmp")
    awk -v table="docs/$what.table.tmp" -v head="$head" '
        $0 == head { while ((getline line < table) > 0) print line; skip = 1; next }
        skip && /^$/ { skip = 0 }
        !skip { print }
    ' docs/solver.md > docs/solver.md.tmp
    mv docs/solver.md.tmp docs/solver.md
    rm -f "docs/$what.table.tmp"
done
