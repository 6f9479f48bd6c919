#!/bin/bash
# test/cli/sweep.sh: `towstab sweep` as a user runs it (suite 'cli').
#
#   sweep.sh TOWSTAB PLOT(yes|no)
#
# - A point is the single run: every point of a cold-start sweep (--chain
#   1) of equilibria over cable length and speed has the sphere depth and
#   top tension of `towstab equilibrium --set cables.cable.length=L
#   --speed V`, to the last digit (17 significant digits of the CSV
#   against those of the JSON); the first point of a continued modes
#   sweep has the max Re(lambda) of `towstab modes --speed V`.
# - Threads: --jobs 1 and --jobs 3 write the same CSV, byte for byte.
# - Resume: a sweep with --resume killed (SIGKILL) after some chains,
#   run again, restores them, computes the rest and writes the CSV of an
#   uninterrupted run; SIGINT stops it with status 130, a JSON marked
#   "completed": false and "interrupted": "SIGINT"; a resume file of
#   another sweep is refused (2).
# - The stability boundary of examples/kamman_ex1_above.yaml is found
#   between 8 and 9 m/s; maps are drawn (with PLplot).
# - The towing vehicle's propulsion (thrust, and power on the same scene
#   with constant power) by path: each point is the single run with --set;
#   a key of another law is refused.
# - A unit on a range or list ("2:4 knot:3", "2,3,4 knot") applies to
#   the values written without one.
# - Bad input exits 2 naming the option: an unknown path, a malformed
#   --vary, a bare value beside values in different units, a column --output does not have, --no-boundary without modes,
#   --analysis converge, no --vary.
set -u
if [ $# -ne 2 ]; then
    echo "usage: sweep.sh TOWSTAB PLOT" >&2
    exit 2
fi
TOWSTAB=$1
PLOT=$2
. "$(dirname "$0")/common.sh"
# csv_value FILE INDEX COLUMN: the value of COLUMN in the row of point
# INDEX.
csv_value() {
    awk -F, -v idx="$2" -v col="$3" '
        NR == 1 { for (i = 1; i <= NF; i++) if ($i == col) c = i; next }
        $1 == idx { print $c }' "$1"
}
# json_key_value FILE NAME: the value of key value NAME.
json_key_value() {
    tr -d '\n ' <"$1" | grep -o "{\"name\":\"$2\",\"unit\":\"[^\"]*\",\"value\":[^,}]*" |
        head -1 | sed 's/.*"value"://'
}
# same NUMBER NUMBER: the same double.
same() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && a + 0 == b + 0) }'; }

EX1=examples/kamman_ex1_submerged.yaml
ABOVE=examples/kamman_ex1_above.yaml

# ---- a point is the single run ------------------------------------------
ts sweep "$EX1" --vary "cables.cable.length=20:40:3" --vary "speed=1.5:4.5:3" \
    --chain 1 --csv "$T/eq.csv" --quiet
if [ "$status" -eq 0 ]; then
    ok=1 n=0
    for p in 0 4 8; do
        L=$(csv_value "$T/eq.csv" $p cables.cable.length)
        V=$(csv_value "$T/eq.csv" $p tow.speed)
        "$TOWSTAB" equilibrium "$EX1" --set "cables.cable.length=$L" --speed "$V" \
            --json "$T/single.json" --quiet >/dev/null 2>&1 || ok=0
        for col in sphere.z top_tension; do
            a=$(csv_value "$T/eq.csv" $p $col)
            b=$(json_key_value "$T/single.json" $col)
            same "$a" "$b" || { ok=0; echo "     point $p $col: sweep $a, single $b"; }
            n=$((n + 1))
        done
    done
    [ $ok -eq 1 ] && pass "cold-start sweep: $n values of 3 points equal the single runs (equilibrium --set cables.cable.length --speed) to the last digit" ||
        fail "a sweep point differs from its single run"
else
    fail "sweep of equilibria exited $status: $(head -c 300 "$T/err")"
fi
ts sweep "$ABOVE" --analysis modes --vary "speed=2:10:9" --csv "$T/modes.csv" \
    --json "$T/modes.json" --quiet
if [ "$status" -eq 0 ]; then
    "$TOWSTAB" modes "$ABOVE" --speed 2 --json "$T/m1.json" --quiet >/dev/null 2>&1
    a=$(csv_value "$T/modes.csv" 0 max_real)
    b=$(tr -d '\n ' <"$T/m1.json" | grep -o '"stability":{[^}]*' | grep -o '"max_real":[^,}]*' | head -1 | sed 's/.*://')
    same "$a" "$b" && pass "modes sweep: its first point's max Re(lambda) of the resolved modes $a is that of towstab modes --speed 2" ||
        fail "modes sweep point 0: max_real $a against $b"
    if grep -q "stability boundary: tow.speed = 8\.[0-9]* m/s" "$T/out"; then
        pass "stability boundary between 8 and 9 m/s: $(grep -o 'tow.speed = [0-9.]* m/s' "$T/out" | head -1)"
    else
        fail "no stability boundary between 8 and 9 m/s: $(grep boundary "$T/out")"
    fi
    grep -q '"boundary": \[' "$T/modes.json" && grep -q '"max_real_unstable"' "$T/modes.json" &&
        pass "the JSON lists the boundary" || fail "the JSON has no boundary"
else
    fail "modes sweep exited $status: $(head -c 300 "$T/err")"
fi

# ---- threads ------------------------------------------------------------
TURN="examples/kamman_ex3_turn.yaml --vary cables.cable.length=1.6:1.9:2 --vary turn_rate=0:1.8:7 --chain 3 --quiet"
ts sweep $TURN --jobs 1 --csv "$T/j1.csv"
s1=$status
ts sweep $TURN --jobs 3 --csv "$T/j3.csv"
if [ "$s1" -eq 0 ] && [ "$status" -eq 0 ] && cmp -s "$T/j1.csv" "$T/j3.csv"; then
    pass "--jobs 1 and --jobs 3: the same CSV byte for byte ($(($(wc -l <"$T/j1.csv") - 1)) points)"
else
    fail "--jobs 1 ($s1) and --jobs 3 ($status) differ"
fi

# ---- resume ---------------------------------------------------------------
SLOW="$ABOVE --analysis modes --vary speed=2:10:9 --vary turn_rate=0:0.1:7 --jobs 1 --chain 1 --no-boundary --quiet"
"$TOWSTAB" sweep $SLOW --csv "$T/full.csv" >/dev/null 2>&1
"$TOWSTAB" sweep $SLOW --resume "$T/j.txt" --csv "$T/r.csv" >/dev/null 2>&1 &
pid=$!
for i in $(seq 1 400); do
    [ -f "$T/j.txt" ] && [ "$(wc -l <"$T/j.txt")" -ge 6 ] && break
    sleep 0.02
done
kill -9 $pid 2>/dev/null
wait $pid 2>/dev/null
kept=$(($(wc -l <"$T/j.txt") - 1))
ts sweep $SLOW --resume "$T/j.txt" --csv "$T/r.csv"
restored=$(grep -o 'resume file [^:]*: [0-9]* of' "$T/out" | grep -o '[0-9]* of' | grep -o '[0-9]*')
if [ "$status" -eq 0 ] && [ -n "$restored" ] && [ "$restored" -gt 0 ] &&
   [ "$restored" -lt 63 ] && cmp -s "$T/full.csv" "$T/r.csv"; then
    pass "killed after $kept chains, resumed ($restored of 63 restored): the CSV of one run, byte for byte"
else
    fail "resume after a kill: status $status, restored '$restored', $(head -c 200 "$T/err")"
fi
ts sweep $SLOW --resume "$T/j.txt" --chain 2
if [ "$status" -eq 2 ] && grep -q "records another sweep" "$T/err"; then
    pass "a resume file of another sweep refused: $(head -c 160 "$T/err")"
else
    fail "resume file of another sweep: status $status"
fi
rm -f "$T/j2.txt"
"$TOWSTAB" sweep $SLOW --resume "$T/j2.txt" --json "$T/int.json" >/dev/null 2>"$T/interr" &
pid=$!
for i in $(seq 1 400); do
    [ -f "$T/j2.txt" ] && [ "$(wc -l <"$T/j2.txt")" -ge 4 ] && break
    sleep 0.02
done
kill -INT $pid 2>/dev/null
wait $pid
st=$?
if [ "$st" -eq 130 ] && grep -q '"completed": false' "$T/int.json" &&
   grep -q '"interrupted": "SIGINT"' "$T/int.json"; then
    pass "SIGINT: exit 130, the points so far written, completed false, interrupted SIGINT"
else
    fail "SIGINT: exit $st, $(head -c 200 "$T/interr")"
fi

# ---- pictures -------------------------------------------------------------
if [ "$PLOT" = yes ]; then
    ts sweep "$ABOVE" --analysis modes --vary speed=6:10:5 --vary turn_rate=0:0.1:3 \
        --plot "$T/pic" --quiet
    if [ "$status" -eq 0 ] && [ -s "$T/pic/map_max_real.png" ] &&
       [ -s "$T/pic/map_sphere_z.svg" ] && [ -s "$T/pic/map_top_tension.png" ]; then
        pass "--plot with two --vary: maps of sphere.z, top_tension and max_real"
    else
        fail "--plot maps: status $status $(head -c 200 "$T/err")"
    fi
fi

# ---- the towing vehicle's propulsion by path --------------------------------
# examples/dolphin_aurora.yaml (thrust) over towing_vehicle.propulsion.thrust,
# and the same scene with constant power over towing_vehicle.propulsion.power:
# each point's solved speed and top tension are those of the single
# equilibrium with --set to the last digit, and more power is more speed.
DA=examples/dolphin_aurora.yaml
sed 's/^    thrust: "4500 N"$/    power: "22 kW"\n    max_thrust: "9000 N"/' "$DA" \
    >"$T/da_power.yaml"
for spec in "$DA towing_vehicle.propulsion.thrust 4000:5000:3" \
            "$T/da_power.yaml towing_vehicle.propulsion.power 20000:24000:3"; do
    set -- $spec
    scene=$1 path=$2 range=$3
    ts sweep "$scene" --vary "$path=$range" --links 10 --chain 1 --csv "$T/tv.csv" \
        --quiet
    if [ "$status" -ne 0 ]; then
        fail "sweep over $path: status $status $(head -c 200 "$T/err")"
        continue
    fi
    why=""
    prev=""
    for p in 0 1 2; do
        x=$(csv_value "$T/tv.csv" $p "$path")
        [ "$(csv_value "$T/tv.csv" $p status)" = ok ] || why="$why point $p not ok;"
        "$TOWSTAB" equilibrium "$scene" --links 10 --set "$path=$x" \
            --json "$T/single.json" --quiet >/dev/null 2>&1 || why="$why single run $p failed;"
        for col in dolphin.speed top_tension; do
            a=$(csv_value "$T/tv.csv" $p $col)
            b=$(json_key_value "$T/single.json" $col)
            same "$a" "$b" || why="$why point $p $col $a vs $b;"
        done
        v=$(csv_value "$T/tv.csv" $p dolphin.speed)
        [ -z "$prev" ] || awk -v a="$prev" -v b="$v" 'BEGIN { exit !(b > a) }' ||
            why="$why speed $v not above $prev;"
        prev=$v
    done
    check "sweep over $path: each point is the single run with --set, speed rising to $prev m/s" "$why"
done
ts sweep "$DA" --vary "towing_vehicle.propulsion.power=20000:24000:3"
if [ "$status" -eq 2 ] && grep -q "propulsion is thrust, which has no 'power'" "$T/err"; then
    pass "power on a thrust-propelled vehicle refused: $(head -c 160 "$T/err")"
else
    fail "power on a thrust-propelled vehicle: status $status $(head -c 200 "$T/err")"
fi

# ---- a unit on a range or a list applies to its bare values ---------------
# "2:4 knot:3" is 2 to 4 knots (1.0289 to 2.0578 m/s), the sweep of
# "2 knot:4 knot:3"; "2,3,4 knot" the list of each in knots; both CSVs
# byte for byte the one with every value's unit written. Before, FROM was
# read as 2 m/s.
for pair in "2:4 knot:3|2 knot:4 knot:3" "2,3,4 knot|2 knot,3 knot,4 knot"; do
    ts sweep "$EX1" --vary "speed=${pair%%|*}" --jobs 1 --quiet --csv "$T/u1.csv"
    s1=$status
    ts sweep "$EX1" --vary "speed=${pair#*|}" --jobs 1 --quiet --csv "$T/u2.csv"
    v0=$(csv_value "$T/u1.csv" 0 tow.speed)
    if [ "$s1" -eq 0 ] && [ "$status" -eq 0 ] && cmp -s "$T/u1.csv" "$T/u2.csv" &&
       awk -v v="$v0" 'BEGIN { exit !(v == 2 * 1852 / 3600) }'; then
        pass "--vary speed=${pair%%|*}: the unit applies to every value (first $v0 m/s = 2 knots)"
    else
        fail "--vary speed=${pair%%|*}: status $s1/$status, first value $v0 m/s, $(head -c 200 "$T/err")"
    fi
done

# tow.speed and tow.turn_rate on a towing vehicle: only the start values of
# the speed and turn rate its equilibrium solves, so every point would be
# the same. Refused (exit 2, no file written), naming the key that sets
# each: the propulsion's thrust, power or set speed, or turn_by.
sed 's/^    thrust: "4500 N"$/    speed: "4.5 m\/s"\n    gain: "2000 N*s\/m"/' "$DA" \
    >"$T/da_speed.yaml"
for spec in "$DA|speed=4:5:2|propulsion.thrust" \
            "$T/da_power.yaml|tow.speed=4:5:2|propulsion.power" \
            "$T/da_speed.yaml|speed=4,5|propulsion.speed (its speed controller's set speed" \
            "$DA|turn_rate=0:0.02:2|turn_by: <rudder>"; do
    IFS='|' read -r scene vary want <<<"$spec"
    rm -f "$T/tw.csv" "$T/tw.json"
    ts sweep "$scene" --vary "$vary" --csv "$T/tw.csv" --json "$T/tw.json"
    if [ "$status" -eq 2 ] && grep -qF -- "$want" "$T/err" &&
       [ ! -e "$T/tw.csv" ] && [ ! -e "$T/tw.json" ] && [ "$(wc -l <"$T/err")" -eq 1 ]; then
        pass "--vary $vary on a towing vehicle refused, naming $want: $(head -c 120 "$T/err")"
    else
        fail "--vary $vary on a towing vehicle: status $status, $(head -c 300 "$T/err")"
    fi
done
# The keys named do vary the motion: the set speed (more thrust at 5 m/s
# than at 4), and tow.turn_rate with turn_by (more rudder at 0.02 rad/s).
sed 's/^  name: dolphin$/  name: dolphin\n  turn_by: rudder_upper/' "$DA" >"$T/da_turn.yaml"
why="" vals=""
for spec in "$T/da_speed.yaml|towing_vehicle.propulsion.speed=4:5:2|dolphin.thrust" \
            "$T/da_turn.yaml|turn_rate=0.01:0.02:2|dolphin.rudder_upper.deflection"; do
    IFS='|' read -r scene vary col <<<"$spec"
    ts sweep "$scene" --vary "$vary" --links 10 --chain 1 --csv "$T/tw.csv" --quiet
    a=$(csv_value "$T/tw.csv" 0 "$col") b=$(csv_value "$T/tw.csv" 1 "$col")
    [ "$status" -eq 0 ] && awk -v a="$a" -v b="$b" 'BEGIN { if (a < 0) { a = -a; b = -b }
        exit !(a != "" && b > 1.2 * a) }' || why="$why $vary: status $status, $col $a, $b;"
    vals="$vals $col $a, $b;"
done
check "the keys named vary the towing vehicle's motion:$vals" "$why"

# ---- bad input --------------------------------------------------------------
bad() { # WHAT EXPECTED-TEXT ARGS...
    local what=$1 want=$2
    shift 2
    ts sweep "$@"
    if [ "$status" -eq 2 ] && grep -q -- "$want" "$T/err"; then
        pass "$what: exit 2: $(head -c 140 "$T/err")"
    else
        fail "$what: status $status, $(head -c 200 "$T/err")"
    fi
}
bad "unknown path" "no cable of that name" "$EX1" --vary cables.rope.length=1:2:2
bad "malformed --vary" "expected FROM:TO:N" "$EX1" --vary speed=1:2
bad "unknown --output" "no column 'fish.z'" "$EX1" --vary speed=1:2:2 --output fish.z
bad "--no-boundary without modes" "no-boundary" "$EX1" --vary speed=1:2:2 --no-boundary
bad "--analysis converge" "not an analysis to sweep" "$EX1" --analysis converge --vary speed=1:2:2
bad "no --vary" "at least one --vary" "$EX1"
bad "a value out of range" "must be >= 0 m/s" "$EX1" --vary speed=-1:2:3
bad "a bare value beside two units" "values in different units" "$EX1" --vary "speed=2 knot,3 m/s,4"

finish
