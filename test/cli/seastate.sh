#!/bin/bash
# test/cli/seastate.sh: the sea-state example files (suite cli).
#
#   seastate.sh RAO_BOX
#
# Run from the project root (meson does). Checks:
#  - examples/ship_rao.csv is exactly what test/bench/rao_box.c writes (the
#    example's values come from the model documented there and in
#    doc/seastate.md, section 2, not from hand edits).
# Prints one PASS/FAIL line per check and "N passed, N failed".
set -u
if [ $# -ne 1 ]; then
    echo "usage: seastate.sh RAO_BOX" >&2
    exit 2
fi
RAO_BOX=$1
T=$(mktemp -d "${TMPDIR:-/tmp}/towstab-sea-XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
npass=0
nfail=0
pass() { echo "PASS $*"; npass=$((npass + 1)); }
fail() { echo "FAIL $*"; nfail=$((nfail + 1)); }

# Text lines must be equal; numbers may differ in their last printed digit
# (another compiler or CPU may round a product differently): 2e-6 in the
# amplitudes, 2e-3 deg in the phases (columns 4 and 6), taken modulo 360.
if "$RAO_BOX" >"$T/rao.csv" &&
    awk -F', *' 'NR == FNR { a[FNR] = $0; next }
        function wrap(d) { d = d % 360; if (d > 180) d -= 360; if (d < -180) d += 360; return d }
        {
            if (!(FNR in a)) { bad = "extra line " FNR; exit }
            if ($0 ~ /^[0-9]/) {
                n = split(a[FNR], b, /, */)
                if (n != NF) { bad = "line " FNR; exit }
                for (i = 1; i <= NF; i++) {
                    d = $i - b[i]
                    if (i == 4 || i == 6) d = wrap(d)
                    if (d < 0) d = -d
                    if (d > (i == 4 || i == 6 ? 2e-3 : 2e-6)) { bad = "line " FNR; exit }
                }
            } else if ($0 != a[FNR]) { bad = "line " FNR; exit }
            m = FNR
        }
        END { if (bad == "" && m != length(a)) bad = "length"; if (bad != "") { print bad; exit 1 } }' \
        "$T/rao.csv" examples/ship_rao.csv >"$T/why"; then
    pass "examples/ship_rao.csv is rao_box's output (to its printed digits)"
else
    fail "examples/ship_rao.csv differs from rao_box's output: $(cat "$T/why")"
fi

echo "$npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
