#!/bin/bash
# test/cli/loops.sh: a vehicle's controller loops from the command line
# (suite 'cli'), on examples/aurora_towfish.yaml.
#
#   loops.sh TOWSTAB
#
# - --set with a unit on a loop's setpoint and gain ("130 ft", "2 deg",
#   "3 deg/m"), and the same from a scene entry's `set:`: exit 0 and the
#   JSON of the run with the plain SI numbers, every number the same
#   (the run times apart).
# - A unit the loop does not take ("400 m" on the pitch loop, "5 deg" on
#   the depth loop, "2 deg/m" on the pitch loop's kp), from the command
#   line and from an entry: exit 2, one error naming the source, the path,
#   what the loop measures and the unit expected; no JSON written.
# - An unreachable depth (400 m on the 150 m cable): exit 1, one error
#   naming both attempts, shooting's first (its stopping point, the depth
#   loop and its error), then Newton's; the JSON written is marked
#   "completed": false with that error. With the wing's limit at 0.05 rad
#   and --equilibrium-method shooting the error says the wing is at its
#   deflection limit, and names no Newton; with its stall at 2 +- 0.5 deg
#   as well, that the wing is stalling.
# Prints one PASS/FAIL line per check and "N passed, N failed".
set -u
if [ $# -ne 1 ]; then
    echo "usage: loops.sh TOWSTAB" >&2
    exit 2
fi
TOWSTAB=$1
. "$(dirname "$0")/common.sh"
export OPENBLAS_NUM_THREADS=1
EX=examples/aurora_towfish.yaml
D=bodies.aurora.loops.depth
P=bodies.aurora.loops.pitch

# numbers FILE: the JSON without its run times.
numbers() { grep -v '"wall_s"\|_per_wall\|"per_s"' "$1"; }

# 1. Units accepted, equal to the SI run. The SI numbers are what the
# conversion gives (a scale: value times factor, in double precision).
si_depth=$(awk 'BEGIN { printf "%.17g", 130 * 0.3048 }')
si_pitch=$(awk 'BEGIN { printf "%.17g", 2 * (3.14159265358979323846 / 180) }')
si_kp=$(awk 'BEGIN { printf "%.17g", 3 * (3.14159265358979323846 / 180) }')
fresh
ts equilibrium "$EX" --quiet --json "$T/o/si.json" \
    --set "$D.setpoint=$si_depth; $P.setpoint=$si_pitch; $D.kp=$si_kp"
st_si=$status
ts equilibrium "$EX" --quiet --json "$T/o/u.json" \
    --set "$D.setpoint=130 ft" --set "$P.setpoint=2 deg" \
    --set "$D.kp=3 deg/m"
why=""
[ "$st_si" -eq 0 ] || why="$why SI run exit $st_si;"
[ "$status" -eq 0 ] || why="$why exit $status ($(head -c 300 "$T/err"));"
if [ -s "$T/o/si.json" ] && [ -s "$T/o/u.json" ]; then
    numbers "$T/o/si.json" >"$T/a"
    numbers "$T/o/u.json" >"$T/b"
    cmp -s "$T/a" "$T/b" || why="$why JSON differs: $(diff "$T/a" "$T/b" | head -4 | tr '\n' ' ');"
    grep -q '"converged": true' "$T/o/u.json" || why="$why not converged;"
else
    why="$why no JSON;"
fi
check "--set 130 ft, 2 deg, 3 deg/m on the loops: the run of the SI numbers ($si_depth m, $si_pitch rad, $si_kp rad/m)" "$why"

# The same from a scene entry's set.
sed '/^analyses:/,$d' "$EX" >"$T/entry.yaml"
cat >>"$T/entry.yaml" <<EOF
analyses:
  - type: equilibrium
    set: "$D.setpoint=130 ft; $P.setpoint=2 deg; $D.kp=3 deg/m"
EOF
ts equilibrium "$T/entry.yaml" --quiet --json "$T/o/e.json"
why=""
[ "$status" -eq 0 ] || why="$why exit $status ($(head -c 300 "$T/err"));"
if [ -s "$T/o/e.json" ]; then
    numbers "$T/o/e.json" | grep -v '"scene"\|"name"\|"path"' >"$T/c"
    grep -v '"scene"\|"name"\|"path"' "$T/b" >"$T/d"
    cmp -s "$T/c" "$T/d" || why="$why JSON differs: $(diff "$T/c" "$T/d" | head -4 | tr '\n' ' ');"
else
    why="$why no JSON;"
fi
check "an entry's set: with the same units: the same run" "$why"

# 2. A unit the loop does not take: refused, naming the path, the
# loop's measure and the unit expected; nothing written.
# refused WHAT SET WANT...: --set SET refused so.
refused() {
    local what=$1 set=$2 w why=""
    shift 2
    fresh
    ts equilibrium "$EX" --json "$T/o/r.json" --set "$set"
    [ "$status" -eq 2 ] || why="$why exit $status;"
    [ "$(wc -l <"$T/err")" -eq 1 ] || why="$why $(wc -l <"$T/err") lines on stderr;"
    grep -q '^towstab: error: --set: ' "$T/err" || why="$why not named --set;"
    for w in "$@"; do
        grep -qF -- "$w" "$T/err" || why="$why no '$w' in: $(head -c 300 "$T/err");"
    done
    [ -z "$(ls -A "$T/o")" ] || why="$why wrote $(ls "$T/o");"
    check "$what: exit 2, nothing written" "$why"
}
refused "--set $P.setpoint=400 m" "$P.setpoint=400 m" \
    "$P.setpoint: '400 m' is in m" "loop 'pitch' of vehicle 'aurora' measures pitch" \
    "expected rad"
refused "--set $D.setpoint=5 deg" "$D.setpoint=5 deg" \
    "$D.setpoint: '5 deg' is in rad" "measures depth" "expected m"
refused "--set $P.kp=2 deg/m" "$P.kp=2 deg/m" "$P.kp" "measures pitch" \
    "expected a plain number"
refused "--set $D.setpoint=5 kg" "$D.setpoint=5 kg" "$D.setpoint" \
    "m for depth or rad for an angle"

sed '/^analyses:/,$d' "$EX" >"$T/bad.yaml"
cat >>"$T/bad.yaml" <<EOF
analyses:
  - type: equilibrium
    set: "$P.setpoint=400 m"
EOF
fresh
ts equilibrium "$T/bad.yaml" --json "$T/o/r.json"
why=""
[ "$status" -eq 2 ] || why="$why exit $status;"
grep -q "analyses\[0\]\.set (line [0-9]*): $P.setpoint: '400 m' is in m" "$T/err" ||
    why="$why not named: $(head -c 300 "$T/err");"
grep -qF "expected rad" "$T/err" || why="$why no unit expected;"
[ -z "$(ls -A "$T/o")" ] || why="$why wrote $(ls "$T/o");"
check "an entry's set: $P.setpoint=400 m: exit 2 naming the entry's line, nothing written" "$why"

# 3. An unreachable depth: both attempts in the message.
fresh
ts equilibrium "$EX" --json "$T/o/f.json" --set "$D.setpoint=400"
why=""
[ "$status" -eq 1 ] || why="$why exit $status;"
err=$(grep '^towstab: error: ' "$T/err")
for w in "equilibrium: shooting with vehicles did not converge (" \
         "of the way from where the loops idle to their set points" \
         "got no closer than outer mismatch" \
         "worst in loop 'depth' of vehicle 'aurora', its error" \
         "on the way to 400 m" \
         "; then Newton, the fallback, failed too: " \
         "Newton stopped after"; do
    case "$err" in *"$w"*) ;; *) why="$why no '$w';" ;; esac
done
case "$err" in
*"shooting with vehicles"*"then Newton"*) ;;
*) why="$why shooting's reason not first;" ;;
esac
if [ -s "$T/o/f.json" ]; then
    grep -q '"completed": false' "$T/o/f.json" || why="$why JSON not marked completed false;"
    grep -q '"error": ".*shooting with vehicles did not converge.*then Newton, the fallback, failed too' "$T/o/f.json" ||
        why="$why the JSON's error lacks both;"
    grep -q '"trustworthy": true' "$T/o/f.json" && why="$why JSON says trustworthy;"
else
    why="$why no JSON of the failed run (doc/manual.md: completed false);"
fi
check "$D.setpoint=400 (150 m of cable): exit 1, shooting's stop then Newton's, JSON completed false" "$why"

fresh
ts equilibrium "$EX" --json "$T/o/s.json" --equilibrium-method shooting \
    --set "bodies.aurora.components.wing.limit=0.05" --set "$D.setpoint=60"
why=""
[ "$status" -eq 1 ] || why="$why exit $status;"
err=$(grep '^towstab: error: ' "$T/err")
for w in "shooting with vehicles did not converge" \
         "worst in loop 'depth' of vehicle 'aurora'" \
         "with aurora.wing (2.865 deg) at its deflection limit"; do
    case "$err" in *"$w"*) ;; *) why="$why no '$w' in: $err;" ;; esac
done
case "$err" in *Newton*) why="$why names Newton;" ;; esac
grep -q '"completed": false' "$T/o/s.json" 2>/dev/null || why="$why JSON not marked completed false;"
check "method shooting, the wing's limit 0.05 rad, 60 m: the wing at its limit named" "$why"

fresh
ts equilibrium "$EX" --json "$T/o/st.json" --equilibrium-method shooting \
    --set "bodies.aurora.components.wing.limit=0.05" --set "$D.setpoint=60" \
    --set "bodies.aurora.components.wing.stall=2deg" \
    --set "bodies.aurora.components.wing.stall_width=0.5deg"
why=""
[ "$status" -eq 1 ] || why="$why exit $status;"
err=$(grep '^towstab: error: ' "$T/err")
case "$err" in
*"with aurora.wing (angle of attack "*" deg, its stall 2 +- 0.5 deg) stalling: more lift asked than it gives?"*) ;;
*) why="$why the wing not named stalling in: $err;" ;;
esac
check "method shooting, the wing's stall at 2 deg: the wing named stalling" "$why"

finish
