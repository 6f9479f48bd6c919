#!/bin/bash
# test/cli/options.sh: one option table per analysis, read by the command
# line and by the scene's entries (doc/manual.md, "Options").
#
#   options.sh TOWSTAB CHECK_JSON PLPLOT(yes|no)
#
# Checked: every command takes what its command line does not give from
# the scene's first entry of its type (modes count, response output,
# converge links, equilibrium links), the command line winning; a boolean
# is switched off with --no-NAME; the documented simulate command whose
# scene transient the command line's run length contradicts runs (the
# transient yields, with a note); `towstab run --csv DIR --plot DIR`
# writes one file set per analysis; command-line values get the scene's
# checks (--speed -1, a manoeuvre to -5 m/s, an empty excitation) and are
# refused naming the option, as the same values in an entry are refused
# naming the key; the option reference in doc/manual.md is what
# `towstab options` prints.
#
# Prints one PASS/FAIL line per check and "N passed, N failed".
set -u

if [ $# -ne 3 ]; then
    echo "usage: options.sh TOWSTAB CHECK_JSON yes|no" >&2
    exit 2
fi
TOWSTAB=$1
CHECK_JSON=$2
PLPLOT=$3
. "$(dirname "$0")/common.sh"
# jget FILE KEY: the first number of "KEY": in FILE.
jget() { grep -o "\"$2\": *[-0-9.eE+]*" "$1" | head -1 | sed 's/.*: *//'; }

# A scene with one entry of every kind.
cat >"$T/s.yaml" <<'EOF'
name: entries
tow:
  speed: 2
cables:
  - name: cable
    from: tow
    to: ball
    length: 20
    diameter: 0.02
    mass_per_length: 1.2
    links: 10
bodies:
  - name: ball
    type: sphere
    diameter: 0.2
    mass: 15
analyses:
  - type: equilibrium
    links: 7
  - type: modes
    count: 2
  - type: response
    output: ball.x
    points: 7
  - type: converge
    links: "5,10,20"
  - type: simulate
    excite: "tow.heave:amplitude=0.05,frequency=0.5Hz"
    t_end: 4 s
    compare: true
EOF

# 1. The scene's entries are honoured by the commands.
ts equilibrium "$T/s.yaml" --quiet
why=""
[ "$status" -eq 0 ] || why="$why exit $status;"
grep -q ', 7 links,' "$T/out" || why="$why not 7 links: $(grep links "$T/out" | head -1);"
check "equilibrium: the entry's links: 7" "$why"

ts modes "$T/s.yaml" --quiet --json "$T/m.json"
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
[ "$(jget "$T/m.json" nmodes)" = 2 ] || why="$why nmodes $(jget "$T/m.json" nmodes);"
check "modes: the entry's count: 2" "$why"
ts modes "$T/s.yaml" --quiet --json "$T/m.json" --count 4
[ "$status" -eq 0 ] && [ "$(jget "$T/m.json" nmodes)" = 4 ] &&
    pass "modes: --count 4 over the entry's count: 2" ||
    fail "modes --count 4: exit $status, nmodes $(jget "$T/m.json" nmodes)"

ts response "$T/s.yaml" --quiet --json "$T/r.json"
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
grep -q '"output": "ball.x"' "$T/r.json" || why="$why output not ball.x;"
[ "$(grep -c '"freq_hz"' "$T/r.json")" -eq 7 ] || why="$why not 7 points;"
check "response: the entry's output ball.x and points 7" "$why"

ts converge "$T/s.yaml" --quiet --json "$T/c.json"
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
[ "$(grep -c '"status": "' "$T/c.json")" -eq 3 ] || why="$why not 3 runs;"
check "converge: the entry's links 5,10,20" "$why"

# 2. --no-compare switches the entry's compare: true off.
ts simulate "$T/s.yaml" --quiet --json "$T/n.json" --no-compare
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
grep -q '"compare"' "$T/n.json" && why="$why a comparison in the JSON;"
grep -q '"linear"' "$T/n.json" && why="$why a linear run;"
grep -q 'comparison of' "$T/out" && why="$why a comparison printed;"
check "simulate --no-compare over the entry's compare: true" "$why"

# 3. The documented command: its run length contradicts the scene's
#    transient (30 s of 60 s), which yields to t_end / 2.
P=()
[ "$PLPLOT" = yes ] && P=(--plot "$T/p")
ts simulate examples/kamman_ex4.yaml \
    --excite tow.heave:amplitude=0.1ft,frequency=1Hz --compare --t-end 20 \
    "${P[@]}" --quiet --json "$T/d.json"
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
grep -q 'note: .*transient.*default' "$T/out" || why="$why no note on the transient;"
grep -q '"from_s": 10' "$T/d.json" || why="$why the window does not start at 10 s;"
if [ "$PLPLOT" = yes ]; then
    [ -s "$T/p/histories.png" ] || why="$why no histories.png;"
fi
check "simulate kamman_ex4 --excite ...1Hz --compare --t-end 20 ${P[*]}: runs, transient 10 s" "$why"

# 4. run --csv DIR --plot DIR: one file set per analysis.
mkdir -p "$T/runs"
head -n 27 "$T/s.yaml" >"$T/three.yaml" # equilibrium, modes, response
P=()
[ "$PLPLOT" = yes ] && P=(--plot "$T/runs/pics")
ts run "$T/three.yaml" --quiet --csv "$T/runs/csv" "${P[@]}" --json "$T/runs/r.json"
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
for f in 1_equilibrium 2_modes 3_response; do
    [ -s "$T/runs/csv/$f.csv" ] || why="$why no $f.csv;"
done
if [ "$PLPLOT" = yes ]; then
    [ -s "$T/runs/pics/1_equilibrium/side.png" ] || why="$why no 1_equilibrium/side.png;"
    [ -s "$T/runs/pics/2_modes/eigenvalues.svg" ] || why="$why no 2_modes/eigenvalues.svg;"
    [ -s "$T/runs/pics/3_response/bode.png" ] || why="$why no 3_response/bode.png;"
fi
check "run --csv DIR ${P[*]}: DIR/<k>_<type>.csv (and pictures) per analysis" "$why"

# 5. Command-line values get the scene's checks (issue: --speed -1 ran).
refused() { # refused DESCRIPTION WORD ARGS...
    local desc=$1 word=$2
    shift 2
    fresh
    ts "$@" --json "$T/o/x.json"
    local why=""
    [ "$status" -eq 2 ] || why="$why exit $status, not 2;"
    grep -q -F -- "$word" "$T/err" || why="$why stderr does not name '$word';"
    [ "$(wc -l <"$T/err")" -eq 1 ] || why="$why $(wc -l <"$T/err") lines on stderr;"
    [ -z "$(ls -A "$T/o")" ] || why="$why wrote $(ls "$T/o");"
    grep -q -E 'converged|trustworthy' "$T/out" && why="$why it ran;"
    check "$desc: exit 2: $(head -1 "$T/err")" "$why"
}
EX=examples/kamman_ex1_submerged.yaml
refused "--speed -1" "--speed" equilibrium "$EX" --speed -1
refused "--speed nan" "--speed" equilibrium "$EX" --speed nan
refused "--turn-rate '1 m'" "--turn-rate" modes "$EX" --turn-rate "1 m"
refused "--links 0" "--links" response "$EX" --output sphere.z --links 0
refused "--links 100001" "--links" equilibrium "$EX" --links 100001
refused "--manoeuvre speed:to=-5,duration=1s" "--manoeuvre" simulate "$EX" --manoeuvre speed:to=-5,duration=1s
refused "--excite ''" "--excite" simulate "$EX" --excite ""
refused "--excite ' ; '" "--excite" simulate "$EX" --excite " ; "
refused "--no-compare given a value" "--no-compare" simulate "$EX" --no-compare=yes
for kv in "speed: -1" "manoeuvre: 'speed:to=-5,duration=1s'" "excite: ' ; '"; do
    key=${kv%%:*}
    sed '/^analyses:/,$d' "$T/s.yaml" >"$T/e.yaml"
    printf 'analyses:\n  - type: simulate\n    %s\n' "$kv" >>"$T/e.yaml"
    refused "scene entry $kv" "analyses[0].$key (line" run "$T/e.yaml"
done

# A towing vehicle solves its speed and turn rate (tow.speed and
# tow.turn_rate are the solve's start values): --speed and --turn-rate
# (without turn_by) would not be the run's, refused naming the key that
# sets each; a --set tow.speed runs from that start, with a warning, and
# ends at the same solved speed.
DA=examples/dolphin_aurora.yaml
refused "--speed on a towing vehicle" "set towing_vehicle.propulsion.thrust (its thrust" equilibrium "$DA" --speed 5
refused "--turn-rate on a towing vehicle" "turn_by: <rudder>" modes "$DA" --turn-rate 0.01
if [ "$PLPLOT" = yes ]; then
    refused "--overlay-speeds on a towing vehicle" "--overlay-speeds '4': speed: tow.speed" equilibrium "$DA" --overlay-speeds 4,5 --plot "$T/o/pics"
fi
sed '/^analyses:/,$d' "$DA" >"$T/da_entry.yaml"
printf 'analyses:\n  - type: equilibrium\n    speed: 4\n' >>"$T/da_entry.yaml"
refused "scene entry speed: 4 on a towing vehicle" "analyses[0].speed (line" run "$T/da_entry.yaml"
q="--links 10 --no-discretisation-error --quiet"
ts equilibrium "$DA" $q --json "$T/da.json"
v0=$(jget "$T/da.json" speed)
why="" vals=""
for set in tow.speed=4.2 "speed=9.5 knot" tow.turn_rate=0.01; do
    fresh
    ts equilibrium "$DA" $q --set "$set" --json "$T/o/w.json"
    v=$(jget "$T/o/w.json" speed) w=$(jget "$T/o/w.json" turn_rate)
    key=${set%%=*}
    [ "$key" = speed ] && key=tow.speed
    [ "$status" -eq 0 ] || why="$why --set $set: exit $status;"
    want="to change the speed, set towing_vehicle.propulsion.thrust ("
    [ "$key" = tow.turn_rate ] && want="turn_by: <rudder>"
    grep "^towstab: warning: set: $key: .*only the solve's start value" "$T/err" |
        grep -qF -- "$want" || why="$why --set $set: no warning naming $want;"
    # The solved speed whatever the start (4.2 m/s, 4.89 m/s, the scene's
    # 5 m/s): equal to 1e-8 relative (the solver's error is 6e-10 m/s of
    # 4.44); the symmetric vehicle, rudder amidships, goes straight.
    awk -v a="$v" -v b="$v0" -v w="$w" 'BEGIN { d = a - b; if (d < 0) d = -d
        if (w < 0) w = -w; exit !(a != "" && b > 0 && d <= 1e-8 * b && w < 1e-9) }' ||
        why="$why --set $set: speed $v (from the scene's start $v0), turn rate $w;"
    vals="$vals $set: $v m/s;"
done
check "--set tow.speed or tow.turn_rate on a towing vehicle: a warning, and the solved speed ($v0 m/s):$vals" "$why"
# With turn_by the turn rate is the run's: --turn-rate taken, no warning.
sed 's/^  name: dolphin$/  name: dolphin\n  turn_by: rudder_upper/' "$DA" >"$T/da_turn.yaml"
ts equilibrium "$T/da_turn.yaml" $q --turn-rate 0.01 --json "$T/dt.json"
w=$(jget "$T/dt.json" turn_rate)
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -c 200 "$T/err");"
[ -s "$T/err" ] && why="$why stderr: $(head -c 200 "$T/err");"
awk -v w="$w" 'BEGIN { exit !(w != "" && w - 0.01 < 1e-9 && 0.01 - w < 1e-9) }' || why="$why turn rate $w;"
check "--turn-rate 0.01 with turn_by: taken, turn rate $w rad/s" "$why"

# 6. Help and the reference come from the table.
for cmd in equilibrium modes response simulate converge; do
    ts "$cmd" --help
    why=""
    [ "$status" -eq 0 ] || why="$why exit $status;"
    for o in --speed --turn-rate --equilibrium-method --tolerance --json; do
        grep -q -- "$o" "$T/out" || why="$why no $o;"
    done
    check "$cmd --help lists the table's options" "$why"
done
ts options
sed -n '/^<!-- options: begin/,/^<!-- options: end/p' doc/manual.md | sed '1d;$d' >"$T/doc"
if [ "$status" -eq 0 ] && [ -s "$T/doc" ] && diff -q "$T/out" "$T/doc" >/dev/null; then
    pass "doc/manual.md's option reference is what 'towstab options' prints ($(grep -c '^| `--' "$T/out") options)"
else
    fail "doc/manual.md's option reference differs from 'towstab options' (run tools/update_option_docs.sh): $(diff "$T/out" "$T/doc" | head -3 | tr '\n' ' ')"
fi

finish
