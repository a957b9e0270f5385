#!/bin/sh
# Bit-identity guard for behaviour-neutral refactors (issue 20): makes a fixed set of
# simulations and analysis outputs and compares them with the same set made by the code
# before the refactor.
#
#   sh scripts/refactor_guard.sh make  REFDIR [BUILD]   reference outputs (run on the old code)
#   sh scripts/refactor_guard.sh check REFDIR [BUILD]   the same outputs afresh, compared
#
# The set: the built-in default model at full size, one reduced run of every boundary mode
# (the examples' quick settings or smaller; sedimentation, flexural slip and weak layers
# ride along), a run stopped early and resumed from its checkpoint, and a cdem2D import;
# from each run `cdem-strain info`, `series`, `compute` (CSV and HDF5) and `render` (PNG),
# plus `repose` and `export-biaxial` where they apply.
#
# HDF5 files are compared with h5diff (values) and `h5dump -H -p` (types, shapes, chunks,
# filters). Two runs of identical code differ only in the root attribute `created` (the
# wall-clock time of the run), so that attribute alone is ignored; every other file is
# compared with cmp. The XDMF sidecars name their .h5 file, so every output keeps its name
# and only the directory differs. Each run takes under a minute on one thread; the whole
# set about five minutes (OMP_NUM_THREADS=1, niced: other work keeps the cores).
set -eu

ACTION=${1:?usage: refactor_guard.sh make|check REFDIR [BUILD]}
REFDIR=${2:?usage: refactor_guard.sh make|check REFDIR [BUILD]}
BUILD=${3:-build}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
case $BUILD in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
RUN="nice -n 5 $BUILD/cdem-run"
STRAIN="nice -n 5 $BUILD/cdem-strain"
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive

case $ACTION in
make) OUT=$REFDIR ;;
check) OUT=$(mktemp -d "${TMPDIR:-/tmp}/cdem-guard.XXXXXX") ;;
*) echo "refactor_guard.sh: unknown action '$ACTION' (make or check)" >&2; exit 2 ;;
esac
mkdir -p "$OUT"
cd "$OUT"

EX=$ROOT/examples
QUICK="-s assembly.half_radii=off -s time.display_interval=50 -s time.equilibration=400"

# simulate NAME [cdem-run arguments...]
simulate() {
    name=$1
    shift
    $RUN -q --force -o "$name.h5" "$@"
}

# analyse NAME: the analysis outputs every run gets
analyse() {
    $STRAIN info "$1.h5" > "$1-info.txt"
    $STRAIN series "$1.h5" -o "$1-series.csv"
    $STRAIN compute "$1.h5" --increment last --quantity total-max-shear -o "$1-total-max-shear.csv"
    $STRAIN compute "$1.h5" --increment all --quantity incr-disp-mag -o "$1-incr-disp-mag.csv"
    $STRAIN compute "$1.h5" --increment last --quantity cum-max-shear --format h5 \
        -o "$1-cum-max-shear.h5"
    $STRAIN render "$1.h5" --increment last -o "$1-layers.png" > "$1-render.txt"
    $STRAIN render "$1.h5" --increment last --color total-max-shear -o "$1-total-max-shear.png" \
        >> "$1-render.txt"
}

simulate default
analyse default
simulate planar-reverse "$EX/planar/fig7b-reverse50.ini" $QUICK -s time.runtime=1000
analyse planar-reverse
simulate vertical "$EX/planar/fig7c-caldera.ini" $QUICK -s time.runtime=1000
analyse vertical
simulate detachment-growth "$EX/growth/fig12b-ftb-low-rise.ini" $QUICK -s assembly.width=12 \
    -s time.runtime=2000
analyse detachment-growth
simulate listric "$EX/nonplanar/fig9a-listric-ch.ini" $QUICK -s time.runtime=1000
analyse listric
simulate irregular "$EX/nonplanar/fig9cd-irregular-cd.ini" $QUICK -s time.runtime=1000 \
    -s boundary.fault_file="$EX/nonplanar/irregular-fault.txt"
analyse irregular
simulate weak-layers "$EX/heterogeneity/fig10b-weak-lower-half.ini" $QUICK -s time.runtime=1000
analyse weak-layers
simulate repose "$EX/calibration/repose.ini" -s time.equilibration=400 -s time.runtime=1200
analyse repose
$STRAIN repose repose.h5 -o repose-slope.png > repose-slope.txt
simulate biaxial "$EX/calibration/biaxial.ini" -s time.equilibration=400 -s time.runtime=600 \
    -s boundary.confining_pressure=5e6
analyse biaxial
$STRAIN export-biaxial biaxial.h5 -o biaxial-export.txt
# salt (issue 45: the process plug-in must leave these identical): a basal band under a
# detachment, an interval under a planar fault, and a salt run stopped and resumed
simulate salt-detachment "$EX/salt-detachment/extension.ini" -s assembly.width=6 \
    -s time.runtime=800 -s time.display_interval=50
analyse salt-detachment
simulate salt-planar "$EX/salt-extension/salt.ini" -s assembly.width=6 -s time.runtime=700 \
    -s salt.layer=interval -s salt.interval_bottom_percent=20 -s salt.interval_top_percent=40
analyse salt-planar
simulate salt-resumed "$EX/salt-extension/salt.ini" -s assembly.width=5 -s assembly.height=2 \
    -s time.equilibration=100 -s time.runtime=300 --max-steps 8000 || [ $? -eq 3 ]
$RUN -q --resume salt-resumed.h5
analyse salt-resumed
# stopped early (exit status 3 is not an error here), then resumed: the checkpoint codec
simulate resumed -s assembly.height=2.5 -s time.equilibration=100 -s time.runtime=150 \
    --max-steps 4000 || [ $? -eq 3 ]
$RUN -q --resume resumed.h5
analyse resumed
$STRAIN import-cdem2d "$EX/cdem2d-import/cdem2d-inversion" -o cdem2d.h5
analyse cdem2d

if [ "$ACTION" = make ]; then
    git -C "$ROOT" rev-parse HEAD > "$OUT/COMMIT"
    echo "refactor_guard: reference outputs of $(cat "$OUT/COMMIT") in $OUT"
    exit 0
fi

# compare_h5 REF NEW: no differences except the root attribute 'created'
compare_h5() {
    h5dump -H -p "$1" | sed 1d > "$OUT/.ref-header"
    h5dump -H -p "$2" | sed 1d > "$OUT/.new-header"
    if ! cmp -s "$OUT/.ref-header" "$OUT/.new-header"; then
        echo "  header (types, shapes, layout) differs"
        return 1
    fi
    # h5diff -v prints a header line per object and "N differences found" after it
    h5diff -v "$1" "$2" | awk '
        /^(attribute|dataset|group|datatype|link) *:/ { object = $0 }
        /Not comparable/ && !/is an empty dataset/ { print "  " $0; bad = 1 }
        /differences found/ && $1 != "0" {
            if (object !~ /^attribute: <created of <\/>>/) { print "  " object ": " $1 " differences"; bad = 1 }
        }
        END { exit bad }'
}

failed=0
for ref in "$REFDIR"/*; do
    name=$(basename "$ref")
    [ "$name" = COMMIT ] && continue
    new=$OUT/$name
    if [ ! -e "$new" ]; then
        echo "MISSING $name"
        failed=1
        continue
    fi
    case $name in
    *.h5)
        if compare_h5 "$ref" "$new"; then echo "same    $name"; else
            echo "DIFFERS $name"
            failed=1
        fi
        ;;
    *)
        if cmp -s "$ref" "$new"; then echo "same    $name"; else
            echo "DIFFERS $name"
            failed=1
        fi
        ;;
    esac
done
for new in "$OUT"/*; do
    [ -e "$REFDIR/$(basename "$new")" ] || { echo "NEW     $(basename "$new")"; failed=1; }
done
if [ $failed -eq 0 ]; then
    echo "refactor_guard: all outputs identical to the reference of $(cat "$REFDIR/COMMIT" 2>/dev/null || echo '?')"
    rm -rf "$OUT"
else
    echo "refactor_guard: DIFFERENCES (new outputs kept in $OUT)"
fi
exit $failed
