#!/bin/bash
# test/cli/converge.sh: `towstab converge` and the health labels of
# `towstab modes`, as a user runs them (suite 'cli').
#
#   converge.sh TOWSTAB CHECK_JSON
#
# converge: Kamman ex. 1 over 5..320 links recommends 40 links at the
#   default target 1e-3 with observed order 2 (the JSON's order, within
#   0.05) and writes a CSV with one line per run; --json - is JSON alone;
#   the modes study of ex. 4 runs; a scene entry of type converge runs
#   under `towstab run` and its JSON has "type": "converge"; bad options
#   and bad entries exit 2 with a message naming the option and no
#   output file; a cable with link_lengths refuses a link sweep but takes
#   a tolerance sweep; a study in which every run fails exits 1 without a
#   file.
# converge --analysis simulate: the documented command (Kamman ex. 4, its
#   first simulate entry, tolerances 1e-3..1e-9) exits 0 with JSON rows,
#   order, recommended, work_precision and the three fitted values; two
#   integrators give two series; simulate settings from the command line
#   replace the scene's; a converge scene entry with analysis simulate
#   runs; a bad or repeated integrator, --integrators or --excite with
#   another analysis, a transient past the run, a step sweep, a released
#   initial state and a scene without a periodic excitation exit 2 with
#   the option named and no file.
# modes: the JSON carries "trustworthy", "reasons", "notes" and per-mode
#   health; a chain hanging in still water (the linearized drag at rest
#   is the step's artefact) is labelled not trustworthy in the table and
#   in the JSON.
set -u
if [ $# -ne 2 ]; then
    echo "usage: converge.sh TOWSTAB CHECK_JSON" >&2
    exit 2
fi
TOWSTAB=$1
CHECK_JSON=$2
T=$(mktemp -d "${TMPDIR:-/tmp}/towstab-converge-XXXXXX") || exit 2
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
fresh() {
    rm -rf "$T/o"
    mkdir "$T/o"
}
# json_number FILE KEY: the first number after "KEY":
json_number() {
    grep -o "\"$2\": *[-0-9.eE+]*" "$1" | head -1 | sed 's/.*: *//'
}

EX1=examples/kamman_ex1_submerged.yaml
EX4=examples/kamman_ex4.yaml

fresh
ts converge "$EX1" --links 5,10,20,40,80,160,320 --json "$T/o/c.json" \
    --csv "$T/o/c.csv"
order=$(grep -o '"sphere.z": *[0-9.]*' "$T/o/c.json" 2>/dev/null | head -1 |
        sed 's/.*: *//')
if [ "$status" -eq 0 ] && "$CHECK_JSON" parse "$T/o/c.json" >/dev/null &&
   has_keys "$T/o/c.json" analysis rows setting wall_s evaluations values \
       errors order recommended work_precision &&
   [ "$(json_number "$T/o/c.json" recommended)" = "40" ] &&
   awk -v p="$order" 'BEGIN { exit !(p > 1.95 && p < 2.05) }' &&
   [ "$(wc -l < "$T/o/c.csv")" -eq 8 ] &&
   grep -q 'recommended: 40 links' "$T/out"; then
    pass "converge ex. 1: 40 links recommended, order of sphere.z $order, JSON and CSV"
else
    fail "converge ex. 1: status $status, order '$order'; $(head -c 300 "$T/err")"
fi

ts converge "$EX1" --links 10,20,40 --json - --quiet
if [ "$status" -eq 0 ] && "$CHECK_JSON" parse "$T/out" >/dev/null &&
   grep -q 'recommended' "$T/err"; then
    pass "converge --json -: JSON alone on stdout, the report on stderr"
else
    fail "converge --json -: status $status"
fi

fresh
ts converge "$EX4" --analysis modes --links 10,20,40 --quiet \
    --json "$T/o/m.json"
if [ "$status" -eq 0 ] && has_keys "$T/o/m.json" mode1.freq_hz \
       mode1.damping_ratio trustworthy &&
   grep -q '"analysis": "modes"' "$T/o/m.json"; then
    pass "converge --analysis modes: mode frequencies and damping ratios"
else
    fail "converge --analysis modes: status $status; $(head -c 300 "$T/err")"
fi

ts converge "$EX1" --tolerances 1e-6,1e-9,1e-12 --quiet
if [ "$status" -eq 0 ] && grep -q 'equilibrium against tolerance' "$T/out"; then
    pass "converge --tolerances: the equilibrium's residual target swept"
else
    fail "converge --tolerances: status $status; $(head -c 300 "$T/err")"
fi

for bad in "--links 5,5" "--links 5,x" "--links 0" "--links 7.5" \
           "--target 0" "--target 2" "--analysis foo" "--tolerances 2" \
           "--steps 1e-3" "--links 5,10 --tolerances 1e-3" "--modes 3" \
           "--analysis modes --modes 0" "--analysis modes --steps 0.5" \
           "--equilibrium-method foo"; do
    fresh
    eval ts converge "$EX1" $bad --json "$T/o/c.json" --csv "$T/o/c.csv"
    opt=${bad%% *}
    [ "$opt" = "--analysis" ] && [ "$bad" != "--analysis foo" ] &&
        opt=$(echo "$bad" | awk '{print $3}')
    if [ "$status" -eq 2 ] && grep -q -- "${opt}" "$T/err" &&
       [ -z "$(ls -A "$T/o")" ]; then
        pass "converge $bad: exit 2 naming $opt, no file"
    else
        fail "converge $bad: status $status, files: $(ls "$T/o"); $(cat "$T/err")"
    fi
done

# A scene entry, and bad entries refused before anything runs.
cat > "$T/entry.yaml" <<'EOF'
name: entry
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
  - type: converge
    links: "5,10,20,40"
    target: 1e-3
EOF
fresh
ts run "$T/entry.yaml" --json "$T/o/r.json" --quiet
if [ "$status" -eq 0 ] && grep -q '"type": "converge"' "$T/o/r.json" &&
   has_keys "$T/o/r.json" rows recommended; then
    pass "run: a converge entry runs and its JSON has type converge"
else
    fail "run converge entry: status $status; $(head -c 300 "$T/err")"
fi
for badentry in 'target: x' 'links: "5,5"' 'analysis: simulated' \
                'steps: "1e-3"' 'modes: 3' 'wobble: 1'; do
    sed "s/    target: 1e-3/    ${badentry}/" "$T/entry.yaml" > "$T/bad.yaml"
    key=${badentry%%:*}
    fresh
    ts run "$T/bad.yaml" --json "$T/o/r.json"
    if [ "$status" -eq 2 ] && grep -q "analyses\[0\].*${key}" "$T/err" &&
       ! grep -q 'converge' "$T/out" && [ -z "$(ls -A "$T/o")" ]; then
        pass "run: entry '$badentry' refused before running (exit 2, names $key)"
    else
        fail "run: entry '$badentry': status $status; $(cat "$T/err")"
    fi
done

# Link lengths: a link sweep would change them; a tolerance sweep is fine.
sed 's/    links: 10/    link_lengths: [5, 5, 10]/' "$T/entry.yaml" |
    sed '/^analyses:/,$d' > "$T/ll.yaml"
fresh
ts converge "$T/ll.yaml" --links 5,10 --json "$T/o/c.json"
if [ "$status" -eq 2 ] && grep -q 'link_lengths' "$T/err" &&
   [ -z "$(ls -A "$T/o")" ]; then
    pass "converge: link_lengths refuse a link sweep (exit 2, no file)"
else
    fail "converge link_lengths: status $status; $(cat "$T/err")"
fi
ts converge "$T/ll.yaml" --tolerances 1e-6,1e-8,1e-10 --quiet
if [ "$status" -eq 0 ]; then
    pass "converge: link_lengths allow a tolerance sweep"
else
    fail "converge link_lengths tolerances: status $status; $(cat "$T/err")"
fi

fresh
ts converge "$EX1" --links 5,10 --tolerance 1e-300 --json "$T/o/c.json"
if [ "$status" -eq 1 ] && grep -q 'every run failed' "$T/err" &&
   [ -z "$(ls -A "$T/o")" ]; then
    pass "converge: every run failing exits 1 with no file"
else
    fail "converge all failed: status $status; $(cat "$T/err")"
fi

# Health labels of towstab modes.
fresh
ts modes examples/kamman_ex1_above.yaml --json "$T/o/m.json" --quiet
if [ "$status" -eq 0 ] &&
   has_keys "$T/o/m.json" trustworthy reasons notes margin_ratio \
       shape_trustworthy damping_error vector_error nearest_mode &&
   grep -q '^trustworthy: ' "$T/out"; then
    pass "modes: JSON and report carry the health verdict"
else
    fail "modes health keys: status $status; $(head -c 300 "$T/err")"
fi
sed 's/  speed: 2/  speed: 0/; /^analyses:/,$d' "$T/entry.yaml" > "$T/still.yaml"
fresh
ts modes "$T/still.yaml" --json "$T/o/m.json"
if [ "$status" -eq 0 ] && grep -q '"trustworthy": false' "$T/o/m.json" &&
   grep -q 'trustworthy: NO' "$T/out" &&
   grep -q 'NOT TRUSTWORTHY: damping' "$T/out" &&
   grep -q 'damping ratio not resolved' "$T/out"; then
    pass "modes: a chain hanging in still water is labelled not trustworthy"
else
    fail "modes still water: status $status; $(tail -5 "$T/out")"
fi

# The simulate analysis : the documented command.
fresh
ts converge "$EX4" --analysis simulate --tolerances 1e-3,1e-5,1e-7,1e-9 \
    --json "$T/o/s.json" --quiet
if [ "$status" -eq 0 ] && "$CHECK_JSON" parse "$T/o/s.json" >/dev/null &&
   has_keys "$T/o/s.json" rows order recommended work_precision \
       sphere.z.amplitude_ratio sphere.z.mean_offset sphere.z.phase_deg \
       simulation &&
   grep -q '"analysis": "simulate"' "$T/o/s.json" &&
   grep -q '"parameter": "tolerance"' "$T/o/s.json" &&
   [ "$(grep -c '"setting":' "$T/o/s.json")" -ge 8 ] &&
   grep -q 'simulate against tolerance: 4 runs' "$T/out"; then
    pass "converge --analysis simulate --tolerances 1e-3..1e-9: JSON rows, order, recommended, work_precision"
else
    fail "converge --analysis simulate: status $status; $(head -c 400 "$T/err")"
fi

# Two integrators on a shorter run at 1 Hz given on the command line.
fresh
ts converge "$EX4" --analysis simulate --integrators rk8pd,rkf45 \
    --tolerances 1e-4,1e-6,1e-8 --excite tow.heave:amplitude=0.1ft,frequency=1Hz \
    --t-end 12 --transient 6 --json "$T/o/w.json" --quiet
if [ "$status" -eq 0 ] && grep -q 'frequency 1 Hz' "$T/out" &&
   grep -q '"series": "rkf45"' "$T/o/w.json" &&
   grep -q '"series": "rk8pd"' "$T/o/w.json" &&
   grep -q '   1e-08 rkf45' "$T/out"; then
    pass "converge --integrators rk8pd,rkf45: one series each, settings from the command line"
else
    fail "converge --integrators: status $status; $(head -c 400 "$T/err")"
fi

# A scene entry of type converge with analysis simulate.
sed '/^analyses:/,$d' "$EX4" > "$T/ex4entry.yaml"
cat >> "$T/ex4entry.yaml" <<'EOF'
analyses:
  - type: simulate
    excite: "tow.heave:amplitude=0.1ft,frequency=1Hz"
    t_end: 8 s
    transient: 4 s
    output: sphere.z
  - type: converge
    analysis: simulate
    tolerances: "1e-4,1e-6,1e-8"
    integrators: "rk8pd"
EOF
fresh
ts run "$T/ex4entry.yaml" --json "$T/o/r.json" --quiet
if [ "$status" -eq 0 ] && grep -q '"type": "converge"' "$T/o/r.json" &&
   grep -q '"analysis": "simulate"' "$T/o/r.json"; then
    pass "run: a converge entry with analysis simulate runs"
else
    fail "run converge simulate entry: status $status; $(head -c 300 "$T/err")"
fi

for bad in "--analysis simulate --integrators rk9" \
           "--analysis simulate --integrators rk8pd,rk8pd" \
           "--integrators rk8pd" "--excite tow.heave:amplitude=1,frequency=1" \
           "--analysis simulate --transient 70" \
           "--analysis simulate --steps 1e-3"; do
    fresh
    eval ts converge "$EX4" $bad --json "$T/o/c.json"
    case "$bad" in
        *--integrators*) opt=--integrators ;;
        *--transient*) opt=transient ;;
        *--steps*) opt=--steps ;;
        *) opt=--excite ;;
    esac
    if [ "$status" -eq 2 ] && grep -q -- "$opt" "$T/err" &&
       [ -z "$(ls -A "$T/o")" ]; then
        pass "converge $bad: exit 2 naming $opt, no file"
    else
        fail "converge $bad: status $status; $(cat "$T/err")"
    fi
done
fresh
ts converge examples/kamman_ex5_drop.yaml --analysis simulate --json "$T/o/c.json"
if [ "$status" -eq 2 ] && grep -q 'initial' "$T/err" && [ -z "$(ls -A "$T/o")" ]; then
    pass "converge --analysis simulate of the drop test (released): exit 2 naming initial"
else
    fail "converge simulate drop test: status $status; $(cat "$T/err")"
fi
sed 's/    initial: released//' examples/kamman_ex5_drop.yaml > "$T/drop_eq.yaml"
fresh
ts converge "$T/drop_eq.yaml" --analysis simulate --json "$T/o/c.json"
if [ "$status" -eq 2 ] && grep -q 'periodic' "$T/err" && [ -z "$(ls -A "$T/o")" ]; then
    pass "converge --analysis simulate without a periodic excitation: exit 2"
else
    fail "converge simulate without excitation: status $status; $(cat "$T/err")"
fi

echo "$npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
