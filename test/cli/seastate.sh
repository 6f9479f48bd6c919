#!/bin/bash
# test/cli/seastate.sh: the sea state on the command line and its example
# files (suite cli).
#
#   seastate.sh TOWSTAB RAO_BOX CHECK_JSON
#
# Run from the project root (meson does). Checks:
#  - examples/ship_rao.csv is what test/bench/rao_box.c writes (the
#    example's values come from the model documented there and in
#    doc/seastate.md, section 2, not from hand edits);
#  - `towstab response --sea` on the example: exit 0, the statistics in
#    the JSON (sigma's error the sum of its grid, band and discretisation
#    parts), a CSV row per grid point; the same numbers from the scene's
#    entry and from the command line;
#  - `towstab simulate --sea`: exit 0, the records' statistics; the same
#    seed gives the same record, another seed another;
#  - refusals with exit 2 and a message naming the option: --input with
#    --sea, a bad sea, an unreadable or malformed RAO file, a heading the
#    RAO table lacks, a turning tow, intervals not a multiple of 8, a
#    reference point of two numbers, a sea from a released shape, --plot
#    with --sea (no picture of it yet).
# Prints one PASS/FAIL line per check and "N passed, N failed".
set -u
if [ $# -ne 3 ]; then
    echo "usage: seastate.sh TOWSTAB RAO_BOX CHECK_JSON" >&2
    exit 2
fi
TOWSTAB=$1 RAO_BOX=$2 CHECK_JSON=$3
. "$(dirname "$0")/common.sh"

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

EX=examples/survey_tow_sea.yaml
SEA=(--sea Hs=4m,Tp=8s,gamma=3.3,heading=180deg --rao examples/ship_rao.csv
     --rao-reference "30 m, 0 m, 0 m")

fresh
ts response "$EX" --output fish.z "${SEA[@]}" --json "$T/o/r.json" \
    --csv "$T/o/r.csv" --quiet
why=""
[ "$status" -eq 0 ] || why="exit $status: $(head -c 200 "$T/err")"
grep -q "standard deviation sigma" "$T/out" || why="$why; no sigma printed"
rows=$(wc -l <"$T/o/r.csv" 2>/dev/null || echo 0)
[ "$rows" -eq 514 ] || why="$why; CSV has $rows lines, not 1 + 513"
check "response --sea: exit 0, sigma printed, CSV of 513 grid points" "$why"

# The statistics: sigma's error is the sum of its parts.
error_is_sum() { # VALUE ERROR GRID BAND DISCRETISATION
    awk -v s="$1" -v e="$2" -v g="$3" -v b="$4" -v d="$5" 'BEGIN {
        t = g + b + d; r = (e - t) / e; if (r < 0) r = -r
        exit !(s > 0 && r < 1e-12) }'
}
sig=$(tr -d '\n ' <"$T/o/r.json" | grep -o '"sigma":{"value":[^}]*}}' | head -1)
val=$(echo "$sig" | grep -o '"value":[-0-9.eE+]*' | cut -d: -f2)
err=$(echo "$sig" | grep -o '"error":[-0-9.eE+]*' | cut -d: -f2)
gri=$(echo "$sig" | grep -o '"grid":[-0-9.eE+]*' | cut -d: -f2)
ban=$(echo "$sig" | grep -o '"band":[-0-9.eE+]*' | cut -d: -f2)
dis=$(echo "$sig" | grep -o '"discretisation":[-0-9.eE+]*' | cut -d: -f2)
if [ -n "$val" ] && error_is_sum "$val" "$err" "$gri" "$ban" "$dis"; then
    pass "JSON: sigma $val m, its error $err the sum of grid, band and discretisation"
else
    fail "JSON: sigma's error is not the sum of its parts: $sig"
fi

# The scene's entry gives the same statistics as the command line.
ts run "$EX" --quiet --json "$T/o/run.json"
why=""
[ "$status" -eq 0 ] || why="exit $status: $(head -c 200 "$T/err")"
s1=$(tr -d '\n ' <"$T/o/run.json" | grep -o '"name":"fish.z.sigma","unit":"m","value":[-0-9.eE+]*' | cut -d: -f4)
s2=$(tr -d '\n ' <"$T/o/r.json" | grep -o '"name":"fish.z.sigma","unit":"m","value":[-0-9.eE+]*' | cut -d: -f4)
[ -n "$s1" ] && [ "$s1" = "$s2" ] || why="$why; sigma $s1 from the scene, $s2 from the command line"
check "the scene's response entry with a sea equals the command line" "$why"

# A simulation in the sea: short, few links and components.
SIM=(--output fish.z --links 5 --t-end 120 --transient 60 --sample 0.5
     --components 32 --quiet)
ts simulate "$EX" "${SIM[@]}" "${SEA[@]}" --compare --json "$T/o/s1.json"
why=""
[ "$status" -eq 0 ] || why="exit $status: $(head -c 200 "$T/err")"
grep -q "records of fish.z" "$T/out" || why="$why; no records printed"
grep -q '"records"' "$T/o/s1.json" 2>/dev/null || why="$why; no records in the JSON"
check "simulate --sea: exit 0, the records' statistics" "$why"
ts simulate "$EX" "${SIM[@]}" "${SEA[@]}" --compare --seed 1 --json "$T/o/s2.json"
ts simulate "$EX" "${SIM[@]}" "${SEA[@]}" --compare --seed 2 --json "$T/o/s3.json"
r1=$(tr -d '\n ' <"$T/o/s1.json" | grep -o '"fish.z.sigma","unit":"m","value":[-0-9.eE+]*' | cut -d: -f3)
r2=$(tr -d '\n ' <"$T/o/s2.json" | grep -o '"fish.z.sigma","unit":"m","value":[-0-9.eE+]*' | cut -d: -f3)
r3=$(tr -d '\n ' <"$T/o/s3.json" | grep -o '"fish.z.sigma","unit":"m","value":[-0-9.eE+]*' | cut -d: -f3)
if [ -n "$r1" ] && [ "$r1" = "$r2" ] && [ "$r1" != "$r3" ]; then
    pass "seed 1 (the default) reproduces its record (sigma $r1 m), seed 2 gives another ($r3 m)"
else
    fail "seeds: '$r1', '$r2' (seed 1), '$r3' (seed 2)"
fi

# Refusals: exit 2, one line naming the option.
printf 'axes: z-down\nphase: lead\nomega [rad/s], heave amp [m/m], heave phase [deg]\n0.5, 1\n' >"$T/bad_rao.csv"
refuse() { # EXPECT ARGS...: exit 2 and EXPECT in the message
    local expect=$1
    shift
    ts "$@"
    if [ "$status" -eq 2 ] && grep -q -- "$expect" "$T/err" &&
        [ "$(wc -l <"$T/err")" -eq 1 ]; then
        pass "refused ($expect): $(head -c 150 "$T/err")"
    else
        fail "not refused as expected ($expect): exit $status: $(head -c 300 "$T/err")"
    fi
}
refuse "input, from, to and points do not apply" response "$EX" \
    --output fish.z "${SEA[@]}" --input tow.surge
refuse "\-\-sea: unknown key 'wind'" response "$EX" --output fish.z \
    --sea Hs=4m,Tp=8s,wind=3
refuse "\-\-rao: cannot read" response "$EX" --output fish.z \
    --sea Hs=4m,Tp=8s --rao "$T/none.csv"
refuse "line 4: expected 3 numbers" response "$EX" --output fish.z \
    --sea Hs=4m,Tp=8s --rao "$T/bad_rao.csv"
refuse "heading 90 deg is not covered by the RAO table" response "$EX" \
    --output fish.z --sea Hs=4m,Tp=8s,heading=90deg \
    --rao examples/ship_rao.csv
refuse "the tow turns" response "$EX" --output fish.z --sea Hs=4m,Tp=8s \
    --turn-rate 0.01
refuse "\-\-intervals: expected a multiple of 8" response "$EX" \
    --output fish.z --sea Hs=4m,Tp=8s --intervals 100
refuse "\-\-rao-reference: expected three lengths" response "$EX" \
    --output fish.z --sea Hs=4m,Tp=8s --rao-reference 1,2
refuse "a sea state starts from the equilibrium" simulate "$EX" \
    --sea Hs=4m,Tp=8s --initial released
refuse "which a sea-state response has not" response "$EX" --output fish.z \
    --sea Hs=4m,Tp=8s --plot "$T/pictures"

# A towing ship's RAO rotations are its rotation inputs: the CSV carries
# tow.roll ... tow.yaw beside the translations (test_surface checks the
# gains they give).
"$TOWSTAB" response test/scenes/survey_ship.yaml --links 8 \
    --output depressor.z --sea Hs=2m,Tp=6s --rao examples/ship_rao.csv \
    --rao-reference "12 m,0,0" --no-discretisation-error --quiet \
    --csv "$T/ship.csv" --json "$T/ship.json" >"$T/ship.out" 2>"$T/ship.err"
st=$?
if [ "$st" -eq 0 ] && head -1 "$T/ship.csv" | grep -q 'tow.pitch_re,tow.pitch_im' &&
    grep -q 'standard deviation sigma' "$T/ship.out"; then
    pass "towing ship with RAOs: its rotations are inputs (tow.pitch_re in the CSV)"
else
    fail "towing ship with RAOs: exit $st, $(head -1 "$T/ship.err"), CSV header $(head -c 200 "$T/ship.csv" 2>/dev/null)"
fi
# Its JSON lever is the one the translation is taken at: the ship's
# origin O less the reference point. O is the tow point (0, 0, -3) m less
# the ship's tow_point (-12, 0, -3) m in a straight tow at zero yaw: (12,
# 0, 0) m, the reference point itself, so the lever is 0 (the tow point's
# would be (-12, 0, -3) m).
if python3 - "$T/ship.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
def find(o):
    if isinstance(o, dict):
        if "lever" in o:
            return o["lever"]
        for v in o.values():
            r = find(v)
            if r is not None:
                return r
    elif isinstance(o, list):
        for v in o:
            r = find(v)
            if r is not None:
                return r
    return None
lev = find(d)
print(lev)
sys.exit(0 if lev is not None and max(abs(x) for x in lev) < 1e-6 else 1)
PY
then
    pass "towing ship: the JSON lever is the ship's origin less the reference point (0 within 1e-6 m)"
else
    fail "towing ship: the JSON lever is not the origin's less the reference point"
fi

finish
