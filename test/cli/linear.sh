#!/bin/bash
# test/cli/linear.sh: `towstab modes` and `towstab response` as a user runs
# them (suite 'cli').
#
#   linear.sh TOWSTAB CHECK_JSON
#
# modes: every example with water in straight tow is stable; the JSON has
#   stable, max_real and modes with re, im, freq_hz, damping_ratio; --json -
#   is JSON alone; --shapes writes the mode shapes; bad options exit 2 with
#   a message and no file.
# response: the JSON has input, output and points with freq_hz, magnitude,
#   phase_deg; unknown input or output names exit 2 listing the valid ones;
#   an empty or negative frequency range exits 2; an equilibrium that does
#   not converge is not linearized (exit 1, no file).
# start-up: LAPACK, BLAS, ARPACK, KLU and NLopt are loaded only by a run
#   that uses them (LD_DEBUG=files).
set -u
if [ $# -ne 2 ]; then
    echo "usage: linear.sh TOWSTAB CHECK_JSON" >&2
    exit 2
fi
TOWSTAB=$1
CHECK_JSON=$2
T=$(mktemp -d "${TMPDIR:-/tmp}/towstab-linear-XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
npass=0
nfail=0
pass() { echo "PASS $*"; npass=$((npass + 1)); }
fail() { echo "FAIL $*"; nfail=$((nfail + 1)); }
ts() {
    "$TOWSTAB" "$@" >"$T/out" 2>"$T/err"
    status=$?
}
has_keys() { # FILE KEY...: every "KEY": appears in FILE
    local f=$1
    shift
    for k in "$@"; do
        grep -q "\"$k\":" "$f" || return 1
    done
}

# Straight tows with water are stable (drag damps every mode).
for scene in examples/kamman_ex1_submerged.yaml examples/kamman_ex1_above.yaml \
             examples/kamman_ex3_turn.yaml; do
    rm -f "$T/m.json"
    ts modes "$scene" --turn-rate 0 --json "$T/m.json" --quiet
    if [ "$status" -eq 0 ] && "$CHECK_JSON" parse "$T/m.json" >/dev/null &&
       has_keys "$T/m.json" stable max_real modes re im freq_hz damping_ratio &&
       grep -q '"stable": true' "$T/m.json" &&
       grep -q 'verdict: stable' "$T/out"; then
        pass "modes $scene straight: stable, JSON complete"
    else
        fail "modes $scene straight: status $status; $(head -c 300 "$T/err")"
    fi
done

ts modes examples/kamman_ex3_turn.yaml --count 3 --json - --quiet
if [ "$status" -eq 0 ] && "$CHECK_JSON" parse "$T/out" >/dev/null &&
   grep -q 'verdict' "$T/err"; then
    pass "modes --json -: JSON alone on stdout, the report on stderr"
else
    fail "modes --json -: status $status"
fi

# A large system: the sparse model and ARPACK, with the rightmost search.
# Example 1 at 400 links: the rightmost eigenvalue is the top of the
# transverse band, -0.0166107 1/s at 53.103 Hz (LAPACK on the same model,
# test/test_eigen_search.c), not among the 20 modes nearest 0 Hz (whose
# largest real part is -0.16).
rm -f "$T/big.json"
ts modes examples/kamman_ex1_submerged.yaml --links 400 --json "$T/big.json" \
    --quiet
cat > "$T/big.expected.json" <<'EOF'
{"rtol": 1e-4, "atol": 0,
 "expect": {"complete": false, "rightmost": {"re": -0.0166107, "freq_hz": 53.1029},
            "linearization": {"model": "sparse"}}}
EOF
if [ "$status" -eq 0 ] && has_keys "$T/big.json" rightmost search top_hz &&
   "$CHECK_JSON" compare "$T/big.json" "$T/big.expected.json" &&
   grep -q 'rightmost search' "$T/out"; then
    pass "modes at 400 links: sparse model, the rightmost search finds the band top"
else
    fail "modes at 400 links: status $status; $(head -c 300 "$T/err")"
fi

rm -f "$T/shapes.csv"
ts modes examples/kamman_ex3_turn.yaml --count 2 --shapes "$T/shapes.csv" --quiet
if [ "$status" -eq 0 ] && [ "$(wc -l < "$T/shapes.csv")" -gt 20 ]; then
    pass "modes --shapes writes a table of node displacements"
else
    fail "modes --shapes: status $status"
fi

for bad in "--count 0" "--count x" "--near -1" "--near '5 m'" "--eigen-method foo" \
           "--equilibrium-method foo"; do
    rm -rf "$T/o"
    mkdir "$T/o"
    eval ts modes examples/kamman_ex3_turn.yaml $bad --json "$T/o/m.json"
    if [ "$status" -eq 2 ] && [ -s "$T/err" ] && [ -z "$(ls -A "$T/o")" ]; then
        pass "modes $bad: exit 2, message, no file"
    else
        fail "modes $bad: status $status, files: $(ls "$T/o")"
    fi
done

rm -f "$T/r.json" "$T/r.csv"
ts response examples/kamman_ex1_above.yaml --output sphere.z --points 20 \
    --json "$T/r.json" --csv "$T/r.csv" --quiet
if [ "$status" -eq 0 ] && "$CHECK_JSON" parse "$T/r.json" >/dev/null &&
   has_keys "$T/r.json" input output points freq_hz magnitude phase_deg \
            trustworthy reasons notes &&
   [ "$(wc -l < "$T/r.csv")" -eq 21 ]; then
    pass "response: JSON (with its trust verdict) and CSV with 20 points"
else
    fail "response: status $status; $(head -c 300 "$T/err")"
fi

for bad in "--output nowhere.z" "--output sphere.w" "--input tow.spin --output sphere.z" \
           "--output sphere.z --from 1 --to 1" "--output sphere.z --from -1" \
           "--output sphere.z --from 5 --to 1" "--output sphere.z --points 1"; do
    rm -rf "$T/o"
    mkdir "$T/o"
    eval ts response examples/kamman_ex1_above.yaml $bad --json "$T/o/r.json"
    if [ "$status" -eq 2 ] && [ -s "$T/err" ] && [ -z "$(ls -A "$T/o")" ]; then
        pass "response $bad: exit 2, message, no file"
    else
        fail "response $bad: status $status, files: $(ls "$T/o")"
    fi
done
ts response examples/kamman_ex1_above.yaml --output nowhere.z
if grep -q "sphere" "$T/err"; then
    pass "response: an unknown output lists the valid ones"
else
    fail "response: unknown output message: $(cat "$T/err")"
fi

# A rigid link's tension: the note that inextensible links overstate it
# at high frequency, in the table and in the JSON; none for a position.
rm -rf "$T/o"
mkdir "$T/o"
ts response examples/kamman_ex1_submerged.yaml --output cable.1.tension \
    --to 1 --quiet --json "$T/o/t.json"
if [ "$status" -eq 0 ] && grep -q "note: inextensible links overstate" "$T/out" &&
   grep -q "inextensible links overstate.*elastic cable" "$T/o/t.json"; then
    pass "response on a rigid link's tension: $(grep -o 'note: inextensible.*(.*)' "$T/out" | cut -c1-150)"
else
    fail "response on a rigid link's tension: status $status, no note"
fi
ts response examples/kamman_ex1_submerged.yaml --output sphere.z --to 1 --quiet
if [ "$status" -eq 0 ] && ! grep -q "inextensible" "$T/out"; then
    pass "response on a position: no note on tensions"
else
    fail "response on a position: status $status or a tension note"
fi
ts response examples/kamman_ex1_submerged.yaml --output tow.force
if [ "$status" -eq 2 ] && grep -q "output of simulate" "$T/err"; then
    pass "response --output tow.force: exit 2, points to simulate"
else
    fail "response --output tow.force: status $status: $(cat "$T/err")"
fi

rm -rf "$T/o"
mkdir "$T/o"
ts modes examples/kamman_ex3_turn.yaml --tolerance 1e-300 --json "$T/o/m.json"
if [ "$status" -eq 1 ] && grep -q -i "converge" "$T/err" &&
   [ -z "$(ls -A "$T/o")" ]; then
    pass "modes: an unconverged equilibrium is not linearized (exit 1, no file)"
else
    fail "modes --tolerance 1e-300: status $status; $(cat "$T/err")"
fi

# Vehicles: control inputs and vehicle outputs, the open loop, margins.
A=examples/aurora_towfish.yaml
ts response $A --input aurora.depth.setpoint --output aurora.depth \
    --points 2 --links 10 --json "$T/v.json" --quiet
if [ "$status" -eq 0 ] && grep -q '"unit": "m/m"' "$T/v.json" &&
   grep -q 'response of aurora.depth to aurora.depth.setpoint (m/m): static gain 0.99999' "$T/out"; then
    pass "response to a set point: closed-loop static gain 1 (integral action)"
else
    fail "response set point: status $status; $(head -c 300 "$T/err")"
fi
ts response $A --open-loop --input aurora.wing --output aurora.depth \
    --points 2 --links 10 --json "$T/v.json" --quiet
if [ "$status" -eq 0 ] && grep -q '"open_loop": true' "$T/v.json" &&
   grep -q '"unit": "m/rad"' "$T/v.json" && grep -q '^open loop:' "$T/out"; then
    pass "response --open-loop: fin to depth in m/rad, open_loop in the JSON"
else
    fail "response --open-loop: status $status; $(head -c 300 "$T/err")"
fi
ts modes $A --links 10 --json "$T/v.json" --quiet
if [ "$status" -eq 0 ] && has_keys "$T/v.json" margins phase_margin_deg &&
   grep -q '^aurora.depth .* deg' "$T/out"; then
    pass "modes with controllers: the loops' margins"
else
    fail "modes margins: status $status; $(head -c 300 "$T/err")"
fi
ts modes $A --links 10 --no-margins --json "$T/v.json" --quiet
if [ "$status" -eq 0 ] && ! grep -q '"margins"' "$T/v.json"; then
    pass "modes --no-margins: none"
else
    fail "modes --no-margins: status $status"
fi
for bad in "response $A --open-loop --input aurora.depth.setpoint --output aurora.depth" \
           "response $A --input aurora.bogus --output aurora.depth" \
           "response $A --output aurora.bogus" \
           "modes examples/kamman_ex1_vehicle.yaml --open-loop" \
           "simulate $A --open-loop --initial released"; do
    eval ts $bad --links 10
    if [ "$status" -eq 2 ] && [ -s "$T/err" ]; then
        pass "$bad: exit 2 ($(head -c 120 "$T/err"))"
    else
        fail "$bad: status $status, $(head -c 300 "$T/err")"
    fi
done

# A towing vehicle (examples/dolphin_aurora.yaml, straight): the
# equilibrium's JSON speed is the solved speed (the vehicle's, printed as
# "towing at V m/s"), not the scene's 5 m/s; modes sets the three neutral
# modes by symmetry apart and is stable on the rest; response has no
# static gain and says why, printing no nan.
D=examples/dolphin_aurora.yaml
ts equilibrium "$D" --quiet --json "$T/d.json"
v=$(sed -n 's/^dolphin: towing at \([0-9.]*\) m\/s.*/\1/p' "$T/out")
printf '{"rtol": 1e-5, "atol": 0, "expect": {"speed": %s}}\n' "${v:-0}" \
    >"$T/d.expected.json"
if [ "$status" -eq 0 ] && [ -n "$v" ] &&
   [ "$(printf '%s\n' "$v" | cut -c1-4)" != "5" ] &&
   "$CHECK_JSON" compare "$T/d.json" "$T/d.expected.json" >"$T/chk" 2>&1; then
    pass "towing vehicle: the JSON speed is the solved $v m/s, not the scene's 5 m/s"
else
    fail "towing vehicle: JSON speed (printed $v): status $status, $(head -c 300 "$T/chk")"
fi
ts modes "$D" --json "$T/dm.json"
if [ "$status" -eq 0 ] &&
   grep -q '^neutral by symmetry, not counted in the verdict (3): mode [0-9]*, along-track position' "$T/out" &&
   grep -q '^verdict: stable' "$T/out" && grep -q '"neutral_modes": 3' "$T/dm.json" &&
   grep -q '"neutral": "heading"' "$T/dm.json"; then
    pass "modes $D: 3 neutral modes by symmetry apart, $(grep -m1 '^verdict' "$T/out" | cut -c1-60)"
else
    fail "modes $D: status $status, $(grep -m1 '^verdict' "$T/out")"
fi
ts response "$D" --input dolphin.thrust --output aurora.y --quiet --json "$T/dr.json"
if [ "$status" -eq 0 ] && grep -q 'static gain undefined: the output drifts with the towing vehicle.s neutral modes by symmetry (cross-track position, heading)' "$T/out" &&
   ! grep -qiw 'nan' "$T/out" && grep -q '"static_gain": null' "$T/dr.json" &&
   grep -q '"static_gain_note": "undefined' "$T/dr.json"; then
    pass "response $D: the cross-track position's static gain undefined with its reason, no nan printed"
else
    fail "response $D: status $status, $(grep -m1 'static gain' "$T/out")"
fi
ts response "$D" --input dolphin.thrust --output aurora.z --quiet --json "$T/dz.json"
if [ "$status" -eq 0 ] && grep -q 'static gain -2.62[0-9]*e-06 +- ' "$T/out" &&
   ! grep -q '"static_gain_note"' "$T/dz.json"; then
    pass "response $D: the depth's static gain is finite through the neutral modes: $(grep -o 'static gain [^ ]*' "$T/out" | head -1)"
else
    fail "response $D: depth: status $status, $(grep -m1 'static gain' "$T/out")"
fi

# The headers of a towing-vehicle run state the solved steady motion, not
# the scene's tow.speed (3 m/s, where the solve starts): modes, response
# and simulate on test/scenes/towing_sphere.yaml print the speed the
# vehicle's own line gives ("tug: towing at V m/s"), straight; with the
# rudder at 3 deg the solved turn rate, and the turn radius V / |Omega|
# from the solved values (164.3 m, doc/towing-vehicle.md section 5).
W=test/scenes/towing_sphere.yaml
for run in "modes $W --links 4" \
           "response $W --links 4 --input tug.thrust --output sphere.z --points 3" \
           "simulate $W --links 4 --t-end 0.5" \
           "modes $W --links 4 --set towing_vehicle.components.rudder.deflection=3deg"; do
    eval ts $run --no-discretisation-error
    v=$(sed -n 's/^tug: towing at \([0-9.]*\) m\/s.*/\1/p' "$T/out")
    w=$(sed -n 's/^tug: towing at .*turn rate \([-0-9.e]*\) rad\/s.*/\1/p' "$T/out")
    case $run in
    simulate*) # its vehicle line is the equilibrium's, in the JSON
        ts equilibrium $W --links 4 --no-discretisation-error --quiet
        v=$(sed -n 's/^tug: towing at \([0-9.]*\) m\/s.*/\1/p' "$T/out")
        eval ts $run --no-discretisation-error
        h=$(sed -n 1p "$T/out") ;;
    *) h=$(sed -n 2p "$T/out") ;;
    esac
    case $run in
    *deflection*) turn="turn rate $(printf '%.6g' "$w") rad/s (.*turn radius 164.3 m, to port)" ;;
    *) turn="turn rate 0 rad/s (straight)" ;;
    esac
    if [ "$status" -eq 0 ] && [ -n "$v" ] && [ "$v" != 3 ] &&
       printf '%s\n' "$h" | grep -q "towing vehicle, solved speed $(printf '%.6g' "$v") m/s ([0-9.]* knots; scene 3 m/s), $turn"; then
        pass "${run%% *}: the header states the solved speed $v m/s${w:+, turn rate $w rad/s}"
    else
        fail "${run%% *} ($run): status $status, vehicle line $v m/s, header: $h"
    fi
done

# The numerical libraries are opened when a run first uses them
# (lib/lazylib.h): the dynamic loader's list of the files it opens
# (LD_DEBUG=files) names none of LAPACK, BLAS, ARPACK, KLU and NLopt for
# --version, --help, a refused scene or a 20-link equilibrium solved by
# shooting; modes with LAPACK loads LAPACK; modes with ARPACK loads ARPACK
# and KLU (its shifts factor the sparse model).
lazy_loaded() { grep -o 'file=[^ ]*\(liblapack\|libblas\|libopenblas\|libarpack\|libklu\|libnlopt\)[^ ]*' "$T/files" | sort -u | tr '\n' ' '; }
for run in "--version" "--help" "equilibrium $T/absent.yaml" \
           "equilibrium examples/kamman_ex1_submerged.yaml --links 20 --quiet"; do
    # shellcheck disable=SC2086
    LD_DEBUG=files "$TOWSTAB" $run >"$T/out" 2>"$T/files"
    status=$?
    want=0
    [ "${run#equilibrium $T}" != "$run" ] && want=2
    [ $status -eq $want ] && grep -q 'file=' "$T/files" && [ -z "$(lazy_loaded)" ] &&
        pass "towstab $run (exit $status): none of LAPACK, BLAS, ARPACK, KLU, NLopt loaded" ||
        fail "towstab $run (exit $status, want $want) loaded: $(lazy_loaded)"
done
LD_DEBUG=files "$TOWSTAB" modes examples/kamman_ex1_submerged.yaml --links 20 --eigen-method lapack --quiet >"$T/out" 2>"$T/files"
status=$?
[ $status -eq 0 ] && grep -q 'file=[^ ]*liblapack\.so\.3' "$T/files" &&
    pass "modes --eigen-method lapack loads LAPACK: $(lazy_loaded)" ||
    fail "modes --eigen-method lapack (exit $status) loaded: $(lazy_loaded)"
LD_DEBUG=files "$TOWSTAB" modes examples/kamman_ex1_submerged.yaml --links 20 --eigen-method arpack --quiet >"$T/out" 2>"$T/files"
status=$?
[ $status -eq 0 ] && grep -q 'file=[^ ]*libarpack\.so\.2' "$T/files" &&
    grep -q 'file=[^ ]*libklu\.so\.1' "$T/files" &&
    pass "modes --eigen-method arpack loads ARPACK and KLU: $(lazy_loaded)" ||
    fail "modes --eigen-method arpack (exit $status) loaded: $(lazy_loaded)"

echo "$npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
