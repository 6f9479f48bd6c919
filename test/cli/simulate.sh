#!/bin/bash
# test/cli/simulate.sh: `towstab simulate` run as a user would (suite cli).
#
#   simulate.sh TOWSTAB
#
# Run from the project root (meson does). Checks:
#  - the three documented commands succeed: the example-4 comparison
#    (prints the comparison table, JSON with the summary keys), the turn
#    manoeuvre with --csv (one row per 0.5 s sample, the scene's
#    interval), the drop test every 3 s (11 rows, from the scene's
#    released shape);
#  - the turn run ends on the steady-turn equilibrium printed by
#    `towstab equilibrium --turn-rate 0.5rad/s` (to 1e-5 m in the printed
#    digits: the run settles to ~1e-6 m in 30 s);
#  - an integrator failure (step below --h-min) exits 1 and still writes
#    the history so far, with "completed": false in the JSON;
#  - bad options exit 2 with one line naming the option and write no file;
#  - `--json -` writes one JSON document alone to standard output.
# Prints one PASS/FAIL line per check and "N passed, N failed".
set -u
if [ $# -ne 1 ]; then
    echo "usage: simulate.sh TOWSTAB" >&2
    exit 2
fi
TOWSTAB=$1
T=$(mktemp -d "${TMPDIR:-/tmp}/towstab-sim-XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
npass=0
nfail=0
pass() { echo "PASS $*"; npass=$((npass + 1)); }
fail() { echo "FAIL $*"; nfail=$((nfail + 1)); }
ts() {
    "$TOWSTAB" "$@" >"$T/out" 2>"$T/err"
    status=$?
}
fresh() { rm -rf "$T/o"; mkdir "$T/o"; }

EX3=examples/kamman_ex3_into_turn.yaml
EX4=examples/kamman_ex4.yaml
EX5=examples/kamman_ex5_drop.yaml

# 1. Example 4, the first documented command.
fresh
ts simulate "$EX4" --excite tow.heave:amplitude=0.1ft,frequency=0.25Hz \
    --t-end 60 --compare --output sphere.z --json "$T/o/c.json" --quiet
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
grep -q "^amplitude ratio" "$T/out" || why="$why no amplitude ratio printed;"
for k in '"output": "sphere.z"' '"axis": "tow.heave"' '"frequency_hz": 0.25' \
    '"amplitude_ratio"' '"mean_offset"' '"response_prediction"' \
    '"amplitude_difference_pct"' '"mean_difference_pct"' '"completed": true'; do
    grep -q -F "$k" "$T/o/c.json" || why="$why JSON lacks $k;"
done
[ -z "$why" ] && pass "ex4 --compare: exit 0, table and JSON summary keys" ||
    fail "ex4 --compare:$why"

# 2. Example 3 into the turn, with a CSV history.
fresh
ts simulate "$EX3" --t-end 30 --csv "$T/o/history.csv"
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
rows=$(($(wc -l <"$T/o/history.csv") - 1))
[ "$rows" -eq 61 ] || why="$why $rows rows, not 61 (0..30 s every 0.5 s);"
head -1 "$T/o/history.csv" | grep -q '^t_s,tow.x_m,tow.y_m,tow.z_m,cable.1.x_m' ||
    why="$why header '$(head -1 "$T/o/history.csv" | cut -c1-60)';"
[ -z "$why" ] && pass "ex3 into the turn: exit 0, CSV of 61 samples" ||
    fail "ex3 into the turn:$why"
# Its last sphere row against the steady-turn equilibrium.
last=$(grep -E '^ +30\.0000 ' "$T/out" | awk '{print $2, $3, $4}')
"$TOWSTAB" equilibrium "$EX3" --turn-rate 0.5rad/s --quiet >"$T/eq" 2>&1
eq=$(awk '$1 == "sphere" {print $2, $3, $4}' "$T/eq" | tail -1)
if awk -v a="$last" -v b="$eq" 'BEGIN { split(a, x, " "); split(b, y, " ");
        for (i = 1; i <= 3; i++) { d = x[i] - y[i]; if (d < 0) d = -d;
        if (d > 1e-5 || x[i] == "") exit 1 } }'; then
    pass "ex3: the sphere at 30 s ($last) is at the steady-turn equilibrium ($eq) within 1e-5 m"
else
    fail "ex3: the sphere at 30 s ($last) is not at the steady-turn equilibrium ($eq)"
fi

# 3. The drop test every 3 s.
fresh
ts simulate "$EX5" --t-end 30 --sample 3
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
n=$(grep -c -E '^ +[0-9]+\.0000 ' "$T/out")
[ "$n" -eq 11 ] || why="$why $n table rows, not 11;"
grep -q "initial state: released" "$T/out" || why="$why not released;"
[ -z "$why" ] && pass "ex5 drop: exit 0, released shape, 11 rows 0..30 s" ||
    fail "ex5 drop:$why"

# 4. An integrator failure keeps the history.
fresh
ts simulate "$EX5" --h-min 0.5 --json "$T/o/f.json" --csv "$T/o/f.csv" --quiet
why=""
[ "$status" -eq 1 ] || why="$why exit $status, not 1;"
grep -q "h_min" "$T/err" || why="$why the message does not say h_min;"
[ -s "$T/o/f.csv" ] && [ "$(wc -l <"$T/o/f.csv")" -ge 2 ] ||
    why="$why no CSV history;"
grep -q '"completed": false' "$T/o/f.json" || why="$why JSON not completed false;"
ls "$T/o" | grep -q partial && why="$why a temporary file left;"
[ -z "$why" ] && pass "integrator failure: exit 1, history so far written: $(head -1 "$T/err")" ||
    fail "integrator failure:$why"

# 5. Bad options: exit 2, the option named, one line, no file.
bad() {
    local word=$1
    shift
    fresh
    ts simulate "$@" --json "$T/o/r.json" --csv "$T/o/r.csv"
    local why=""
    [ "$status" -eq 2 ] || why="$why exit $status;"
    grep -q -F -- "$word" "$T/err" || why="$why stderr does not name '$word';"
    [ "$(wc -l <"$T/err")" -eq 1 ] || why="$why $(wc -l <"$T/err") lines on stderr;"
    [ -z "$(ls -A "$T/o")" ] || why="$why left $(ls "$T/o" | tr '\n' ' ');"
    [ -z "$why" ] && pass "bad: $*: exit 2: $(head -1 "$T/err")" ||
        fail "bad: $*:$why $(head -1 "$T/err")"
}
bad "tow.roll" "$EX4" --excite tow.roll:amplitude=1,frequency=1
bad "amplitud" "$EX4" --excite tow.heave:amplitud=1,frequency=1
bad "frequency must be > 0" "$EX4" --excite tow.heave:amplitude=1,frequency=-1Hz
bad "start must be >= 0" "$EX5" --excite tow.heave:type=step,amplitude=1,start=-2
bad "--t-end" "$EX5" --t-end -5
bad "--sample" "$EX5" --t-end 10 --sample 20
bad "--integrator" "$EX5" --integrator euler
bad "--rtol" "$EX5" --rtol 0
bad "--output" "$EX5" --output sphere.w
bad "--initial" "$EX5" --initial upside_down
bad "manoeuvre" "$EX3" --compare
bad "--excite" "$EX5" --excite tow.heave:type=csv,file=$T/none.csv
bad "--sample" "$EX4" --sample 0.5 --excite tow.heave:amplitude=0.1ft,frequency=1Hz
bad "--frobnicate" "$EX5" --frobnicate

# Vehicles: a depth change (a step of the depth set point, a vehicle's
# input) with the controllers, linear against nonlinear; a turn with the
# controllers (nonlinear); the vehicles' outputs in the CSV and JSON.
A=examples/aurora_towfish.yaml
fresh
ts simulate $A --links 10 --excite aurora.depth.setpoint:amplitude=1m,start=1s,rise=2s \
    --t-end 20 --sample 0.5 --output aurora.z --compare --quiet \
    --csv "$T/o/dc.csv" --json "$T/o/dc.json"
if [ "$status" -eq 0 ] && [ "$(wc -l <"$T/o/dc.csv")" -eq 42 ] &&
   head -1 "$T/o/dc.csv" | grep -q 'nonlinear.aurora.depth_m' &&
   head -1 "$T/o/dc.csv" | grep -q 'linear.aurora.wing.deflection_rad' &&
   grep -q '"vehicle_outputs"' "$T/o/dc.json" &&
   grep -q '"input": "aurora.depth.setpoint"' "$T/o/dc.json" &&
   grep -q '^comparison of aurora.z' "$T/out"; then
    pass "depth change with --compare: 41 samples, depth and deflections in the CSV and JSON"
else
    fail "depth change: status $status; $(head -c 300 "$T/err")"
fi
fresh
ts simulate $A --links 10 --manoeuvre turn_rate:to=0.02rad/s,duration=5s \
    --t-end 10 --sample 1 --quiet --csv "$T/o/turn.csv"
if [ "$status" -eq 0 ] && head -1 "$T/o/turn.csv" | grep -q 'aurora.yaw_rad'; then
    pass "turn with the controllers: the vehicle's yaw in the CSV"
else
    fail "turn: status $status; $(head -c 300 "$T/err")"
fi
bad "aurora.bogus" $A --links 10 --excite aurora.bogus:amplitude=1m
bad "expected an angle" $A --links 10 --excite aurora.wing:amplitude=1m
bad "crank" $A --links 10 --excite aurora.wing:crank,amplitude=1deg,frequency=1Hz,rod=1m
bad "loops open" $A --links 10 --open-loop --excite aurora.depth.setpoint:amplitude=1m
bad "no vehicle" examples/kamman_ex1_vehicle.yaml --links 10 --excite fish.depth.setpoint:amplitude=1m

# 6. JSON on standard output, alone.
ts simulate "$EX5" --t-end 3 --sample 1 --quiet --json -
if [ "$status" -eq 0 ] && head -c 1 "$T/out" | grep -q '{' &&
    ! grep -q "^simulate" "$T/out"; then
    pass "--json -: standard output is the JSON document alone"
else
    fail "--json -: exit $status, standard output starts '$(head -c 40 "$T/out")'"
fi

# Every run says whether it is trustworthy, in the table and in JSON.
"$TOWSTAB" simulate examples/kamman_ex4.yaml \
    --excite tow.heave:amplitude=0.1ft,frequency=1Hz --t-end 60 --compare \
    --output sphere.z --quiet --json "$T/trust.json" >"$T/out" 2>"$T/err"
status=$?
if [ "$status" -eq 0 ] && grep -q '^trustworthy: yes' "$T/out" &&
   grep -q '"trustworthy": true' "$T/trust.json" &&
   grep -q 'tow point is at the water surface' "$T/trust.json"; then
    pass "health: trustworthy, with the waterline note, in the table and JSON"
else
    fail "health: status $status, $(grep trustworthy "$T/out")"
fi

echo "$npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
