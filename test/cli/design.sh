#!/bin/bash
# test/cli/design.sh: `towstab design` as a user runs it (suite 'cli').
#
#   design.sh TOWSTAB
#
# - A target in other units (the cable between 30 and 200 ft, the sphere
#   at 15 m): exit 0, "reached"; the optimum the JSON gives, run again
#   with `towstab equilibrium --set`, gives the design's sphere depth to
#   the last digit (the final run is the single run) and 15 m within the
#   target's tolerance.
# - An unreachable target exits 1 with NOT REACHED, the closest point and
#   a JSON with "success": false.
# - Constraints in kN and m with a value to maximise: both met.
# - Controller gains by the scene's key path (bodies.aurora.controllers.
#   depth.kp): the control_damping reported is a mode's damping ratio of
#   a separate `towstab modes --set` run at the gains, to the last digit.
# - Settings from the scene's design section: the same optimum as on the
#   command line; the command line overrides them one by one (the goals
#   as one group); the section's analysis; its errors name the key and
#   line.
# - Bad input exits 2 naming the option.
set -u
if [ $# -ne 1 ]; then
    echo "usage: design.sh TOWSTAB" >&2
    exit 2
fi
TOWSTAB=$1
. "$(dirname "$0")/common.sh"
# json_num FILE KEY: the first number after "KEY": in FILE.
json_num() {
    tr -d '\n ' <"$1" | grep -o "\"$2\":[-0-9.eE+]*" | head -1 | sed 's/.*://'
}
json_key_value() {
    tr -d '\n ' <"$1" | grep -o "{\"name\":\"$2\",\"unit\":\"[^\"]*\",\"value\":[^,}]*" |
        head -1 | sed 's/.*"value"://'
}
EX1=examples/kamman_ex1_submerged.yaml

ts design "$EX1" --free "cables.cable.length=30ft:200ft" --target "sphere.z=15m" \
    --json "$T/d.json" --quiet
if [ "$status" -eq 0 ] && grep -q "wanted 15 m: reached" "$T/out"; then
    pass "target sphere.z = 15 m reached: $(grep -o 'cables.cable.length *[0-9.]*' "$T/out")"
    L=$(json_num "$T/d.json" optimum)
    z=$(tr -d '\n ' <"$T/d.json" | grep -o '"goal":{.*' | grep -o '"value":[-0-9.eE+][-0-9.eE+]*' | head -1 | sed 's/.*://')
    "$TOWSTAB" equilibrium "$EX1" --set "cables.cable.length=$L" --json "$T/s.json" --quiet >/dev/null 2>&1
    zs=$(json_key_value "$T/s.json" sphere.z)
    if awk -v a="$z" -v b="$zs" 'BEGIN { exit !(a != "" && a + 0 == b + 0 && (b - 15 < 1.5e-5 && 15 - b < 1.5e-5)) }'; then
        pass "towstab equilibrium --set cables.cable.length=$L gives sphere.z $zs m, the design's $z to the last digit, 15 m within 1.5e-5 m"
    else
        fail "the single run at the optimum: sphere.z $zs against the design's $z"
    fi
else
    fail "target 15 m: status $status $(head -c 300 "$T/err") $(grep wanted "$T/out")"
fi

# A unit on one bound applies to the bare one: "30:200 ft" is the study
# of "30ft:200ft": lower bound 9.144 m, the same optimum to the last digit.
ts design "$EX1" --free "cables.cable.length=30:200 ft" --target "sphere.z=15m" \
    --json "$T/du.json" --quiet
if [ "$status" -eq 0 ] && grep -q '"lower": 9.144' "$T/du.json" &&
   awk -v a="$(json_num "$T/du.json" optimum)" -v b="$(json_num "$T/d.json" optimum)" \
       'BEGIN { exit !(a != "" && a + 0 == b + 0) }'; then
    pass "--free cables.cable.length=30:200 ft: both bounds in feet, the optimum of 30ft:200ft ($(json_num "$T/du.json" optimum) m)"
else
    fail "--free 30:200 ft: status $status, $(grep -m1 '"lower"' "$T/du.json" 2>/dev/null) $(head -c 200 "$T/err")"
fi

ts design "$EX1" --free "cables.cable.length=10:60" --target "sphere.z=20m" \
    --json "$T/u.json" --quiet
if [ "$status" -eq 1 ] && grep -q "NOT REACHED" "$T/out" &&
   grep -q "AT THE UPPER BOUND" "$T/out" && grep -q '"success": false' "$T/u.json"; then
    pass "unreachable target: exit 1, $(grep -o 'NOT REACHED, misfit [0-9.e-]* m' "$T/out"), the cable at its upper bound"
else
    fail "unreachable target: status $status $(head -c 300 "$T/err")"
fi

ts design "$EX1" --free "bodies.sphere.mass=1kg:1000kg" --free "speed=1:5" \
    --maximise speed --constraint "top_tension<=0.6kN" --constraint "layback<=25m" --quiet
if [ "$status" -eq 0 ] && [ "$(grep -c 'wanted <= .*: met' "$T/out")" -eq 2 ]; then
    pass "maximise speed under top_tension <= 0.6 kN and layback <= 25 m: $(grep -o 'tow.speed *[0-9.]*' "$T/out") m/s, both met"
else
    fail "constraints: status $status $(head -c 300 "$T/err") $(grep wanted "$T/out")"
fi

# Controller gains (the AURORA towfish's depth loop, by the scene's
# `controllers` key), a few runs: the damping the design reports is that
# of a mode of a separate `towstab modes --set` run at its gains, to the
# last digit.
AUR=examples/aurora_towfish.yaml
ts design "$AUR" --analysis modes --no-discretisation-error \
    --free "bodies.aurora.controllers.depth.kp=0.01:0.3" \
    --free "bodies.aurora.controllers.depth.kd=0:0.5" --maximise control_damping \
    --constraint "fin_use<=1" --fin-step 2m --max-evals 8 --json "$T/a.json" --quiet
if [ "$status" -eq 0 ] || [ "$status" -eq 1 ]; then
    opt=$(tr -d '\n ' <"$T/a.json" | grep -o '"optimum":[-0-9.eE+]*' | sed 's/.*://')
    kp=$(echo "$opt" | sed -n 1p)
    kd=$(echo "$opt" | sed -n 2p)
    g=$(tr -d '\n ' <"$T/a.json" | grep -o '"goal":{.*' | grep -o '"value":[-0-9.eE+][-0-9.eE+]*' | head -1 | sed 's/.*://')
    "$TOWSTAB" modes "$AUR" --no-discretisation-error \
        --set "bodies.aurora.controllers.depth.kp=$kp;bodies.aurora.controllers.depth.kd=$kd" \
        --json "$T/am.json" --quiet >/dev/null 2>&1
    if [ -n "$g" ] && tr -d '\n ' <"$T/am.json" | grep -q "\"damping_ratio\":$g[,}]"; then
        pass "maximise control_damping over the depth gains: $g at kp $kp, kd $kd; towstab modes --set at those gains has a mode of that damping ratio"
    else
        fail "control_damping '$g' at kp '$kp', kd '$kd' not among the modes of the single run"
    fi
else
    fail "controller gains: status $status $(head -c 300 "$T/err")"
fi

# Settings in the scene's design section; the command line's override
# them setting by setting (the goals as one group).
{ cat "$EX1"; cat <<'EOF'
design:
  free: ["cables.cable.length=30ft:200ft"]
  target: "sphere.z=15m"
  method: bobyqa
  target_tol: 1e-7
EOF
} >"$T/ds.yaml"
ts design "$T/ds.yaml" --json "$T/ds.json" --quiet
ts_status=$status
ts_out=$(cat "$T/out")
"$TOWSTAB" design "$EX1" --free "cables.cable.length=30ft:200ft" --target "sphere.z=15m" \
    --method bobyqa --target-tol 1e-7 --json "$T/dc.json" --quiet >/dev/null 2>&1
if [ "$ts_status" -eq 0 ] && echo "$ts_out" | grep -q "design: bobyqa" &&
   echo "$ts_out" | grep -q "wanted 15 m: reached.*tolerance 1.5e-06 m" &&
   [ "$(json_num "$T/ds.json" optimum)" = "$(json_num "$T/dc.json" optimum)" ]; then
    pass "the scene's design section alone (free, target, method, target_tol): the optimum $(json_num "$T/ds.json" optimum) m of the same settings on the command line, to the last digit"
else
    fail "design section: status $ts_status $(head -c 300 "$T/err") $(echo "$ts_out" | head -3)"
fi
ts design "$T/ds.yaml" --target "sphere.z=12m" --quiet
if [ "$status" -eq 0 ] && grep -q "design: bobyqa" "$T/out" &&
   grep -q "wanted 12 m: reached.*tolerance 1.2e-06 m" "$T/out"; then
    pass "--target sphere.z=12m overrides the scene's target; its method and target_tol stay"
else
    fail "override: status $status $(head -c 300 "$T/err") $(grep wanted "$T/out")"
fi
ts design "$T/ds.yaml" --maximise layback --constraint "top_tension<=0.5kN" --method cobyla --quiet
if [ "$status" -eq 0 ] && grep -q "design: cobyla" "$T/out" && grep -q "maximise layback" "$T/out" &&
   ! grep -q "target sphere.z" "$T/out"; then
    pass "--maximise replaces the scene's target (one group of goals), --method cobyla its bobyqa"
else
    fail "goal group override: status $status $(head -c 300 "$T/err") $(grep -E 'maximise|target' "$T/out")"
fi
{ cat "$AUR"; cat <<'EOF'
design:
  analysis: modes
  free:
    - "bodies.aurora.controllers.depth.kp=0.01:0.3"
    - "bodies.aurora.controllers.depth.kd=0:0.5"
  maximise: control_damping
  constraint: "fin_use<=1"
  fin_step: 2 m
  max_evals: 3
EOF
} >"$T/as.yaml"
ts design "$T/as.yaml" --no-discretisation-error --quiet
if { [ "$status" -eq 0 ] || [ "$status" -eq 1 ]; } && grep -q "modes at every evaluation" "$T/out" &&
   grep -q "iterations: 3 analysis runs" "$T/out"; then
    pass "the scene's design.analysis modes, a list of free values, max_evals 3: $(grep -o 'maximise control_damping *[0-9.]*' "$T/out")"
else
    fail "aurora design section: status $status $(head -c 300 "$T/err")"
fi
{ cat "$T/as.yaml"; printf '  steps: 4\n'; } >"$T/as_bad.yaml"
ts design "$T/as_bad.yaml"
if [ "$status" -eq 2 ] && grep -q "design.steps (line [0-9]*): unknown setting" "$T/err"; then
    pass "an unknown setting in the section: exit 2: $(head -c 140 "$T/err")"
else
    fail "unknown design setting: status $status $(head -c 200 "$T/err")"
fi
sed 's/"cables.cable.length=30ft:200ft"/"cables.cable.length=30ft"/' "$T/ds.yaml" >"$T/ds_bad.yaml"
ts design "$T/ds_bad.yaml"
if [ "$status" -eq 2 ] && grep -q "design.free (line [0-9]*) cables.cable.length: expected LOWER:UPPER" "$T/err"; then
    pass "a malformed free value in the section: exit 2 naming it and its line: $(head -c 160 "$T/err")"
else
    fail "malformed design.free: status $status $(head -c 200 "$T/err")"
fi

bad() { # WHAT EXPECTED-TEXT ARGS...
    local what=$1 want=$2
    shift 2
    ts design "$@"
    if [ "$status" -eq 2 ] && grep -q -- "$want" "$T/err"; then
        pass "$what: exit 2: $(head -c 140 "$T/err")"
    else
        fail "$what: status $status, $(head -c 200 "$T/err")"
    fi
}
F="--free cables.cable.length=10:60"
bad "no --free" "at least one --free" "$EX1" --target sphere.z=15
bad "malformed --free" "expected LOWER:UPPER" "$EX1" --free cables.cable.length=10 --target sphere.z=15
bad "unknown path" "no cable of that name" "$EX1" --free cables.rope.length=10:60 --target sphere.z=15
bad "unknown value" "no value 'fish.z'" "$EX1" $F --target fish.z=15
bad "max_real without modes" "no value 'max_real'" "$EX1" $F --minimise max_real
bad "two goals" "one of --target" "$EX1" $F --target sphere.z=15 --maximise top_tension
bad "a target in the wrong unit" "--target sphere.z.*expected a length" "$EX1" $F --target sphere.z=15kg
bad "a constraint without its operator" "NAME<=Q" "$EX1" $F --constraint top_tension=5
bad "bobyqa with a constraint" "bobyqa takes bounds only" "$EX1" $F --target sphere.z=15 --method bobyqa --constraint "top_tension<=600"
bad "--method" "expected cobyla, bobyqa or slsqp" "$EX1" $F --target sphere.z=15 --method newton
bad "--analysis simulate" "not an analysis to design with" "$EX1" --analysis simulate $F --target sphere.z=15
bad "no goal" "expected a target" "$EX1" $F
bad "control_damping without modes" "no value 'control_damping'" "$EX1" $F --maximise control_damping
bad "--fin-step in the wrong unit" "fin-step" "$EX1" $F --target sphere.z=15 --fin-step 2kg

# A towing vehicle solves its speed (and turn rate): freeing tow.speed
# would move nothing. Refused before any run, naming the key to free;
# the key named does move it (a thrust that brings the pull to 2000 N,
# within the target tolerance: 1e-6 of it, 0.002 N).
DA=examples/dolphin_aurora.yaml
rm -f "$T/tv.json"
bad "tow.speed free on a towing vehicle" "free: tow.speed: .*free towing_vehicle.propulsion.thrust (" \
    "$DA" --free tow.speed=3:6 --maximise top_tension --json "$T/tv.json"
[ -e "$T/tv.json" ] && fail "tow.speed free on a towing vehicle wrote its JSON"
bad "tow.turn_rate free on a towing vehicle" "free: tow.turn_rate: .*turn_by: <rudder>" \
    "$DA" --free turn_rate=0:0.02 --maximise top_tension
ts design "$DA" --free towing_vehicle.propulsion.thrust=4000:5000 --target "top_tension=2000 N" \
    --links 6 --no-discretisation-error --json "$T/tv.json" --quiet
t=$(json_num "$T/tv.json" top_tension)
if [ "$status" -eq 0 ] && awk -v t="$t" 'BEGIN { d = t - 2000; exit !(t != "" && d <= 0.002 && d >= -0.002) }'; then
    pass "the thrust named does set the pull: top_tension $t N at the target 2000 N"
else
    fail "design of the thrust: status $status, top_tension '$t', $(head -c 200 "$T/err")"
fi

finish
