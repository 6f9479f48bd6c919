#!/bin/bash
# test/cli/accuracy.sh: the discretisation error and the accuracy verdict
# on the command line (suite 'cli'; doc/accuracy.md).
#
#   accuracy.sh TOWSTAB CHECK_JSON
#
# - equilibrium: the header gives knots, deg/s and the turn radius; every
#   key value has a finite discretisation error in JSON; Kamman ex. 1 at
#   its 40 links meets the accuracy 1e-3 (trustworthy: yes); at 20 links
#   it misses it (trustworthy: NO, --links named) and --refine meets it; --accuracy 0.01 accepts it; --accuracy 2 and
#   accuracy: 0 in a scene entry are refused (exit 2, naming the option);
#   --no-discretisation-error says why there is no estimate;
# - modes: oscillatory modes first, --count 5 --near 0.1 lists five
#   oscillatory modes, --oscillatory only oscillatory ones; unresolved
#   modes labelled; the verdict quotes the resolved modes' margin; JSON
#   stability and per-mode resolved;
# - response: the magnitude's error per point and accurate_to_hz;
# - simulate: the window line; a window too short is not trustworthy and
#   names --transient; --discretisation-error estimates the key values.
set -u
if [ $# -ne 2 ]; then
    echo "usage: accuracy.sh TOWSTAB CHECK_JSON" >&2
    exit 2
fi
TOWSTAB=$1
CHECK_JSON=$2
. "$(dirname "$0")/common.sh"
EX1=examples/kamman_ex1_submerged.yaml
EX3=examples/kamman_ex3_turn.yaml
EX4=examples/kamman_ex4.yaml

# Equilibrium: header, errors, verdict.
ts equilibrium "$EX1" --quiet --json "$T/d.json"
if [ "$status" -eq 0 ] &&
   grep -q 'top tension 329.896452 N +- 0.13 (discretisation)' "$T/out" &&
   grep -q 'Richardson from 40, 20 and 10 links' "$T/out" &&
   grep -q 'trustworthy: yes' "$T/out" && grep -q '"met": true' "$T/d.json"; then
    pass "equilibrium ex. 1 as given (40 links): accuracy met, trustworthy"
else
    fail "equilibrium ex. 1 as given: status $status; $(tail -4 "$T/out")"
fi
ts equilibrium "$EX1" --quiet --links 20 --json "$T/e.json"
if [ "$status" -eq 0 ] && grep -q '(4.944 knots), turn rate 0 rad/s (straight)' "$T/out" &&
   grep -q '^  +- discretisation' "$T/out" &&
   grep -q 'top tension 329.582160 N +- 0.67 (discretisation)' "$T/out" &&
   grep -q 'trustworthy: NO' "$T/out" &&
   grep -q 'about 29 links per cable would meet it (--links 29, or --refine)' "$T/out" &&
   [ "$(grep -c '"discretisation": [0-9]' "$T/e.json")" -eq 4 ] &&
   grep -q '"links_needed": 29' "$T/e.json" &&
   grep -q '"met": false' "$T/e.json"; then
    pass "equilibrium ex. 1 at 20 links: errors beside the values, accuracy missed, --links 29 named"
else
    fail "equilibrium ex. 1: status $status; $(tail -4 "$T/out")"
fi
ts equilibrium "$EX1" --quiet --links 20 --refine --json "$T/r.json"
if [ "$status" -eq 0 ] && grep -q 'refined: 1 rerun from 20 to 29 links' "$T/out" &&
   grep -q 'trustworthy: yes' "$T/out" && grep -q '"refined_from": 20' "$T/r.json"; then
    pass "equilibrium --refine: 20 to 29 links, trustworthy"
else
    fail "equilibrium --refine: status $status; $(tail -4 "$T/out")"
fi
ts equilibrium "$EX1" --quiet --accuracy 0.01
if [ "$status" -eq 0 ] && grep -q 'against the accuracy 0.01: met' "$T/out" &&
   grep -q 'trustworthy: yes' "$T/out"; then
    pass "equilibrium --accuracy 0.01: met"
else
    fail "equilibrium --accuracy 0.01: status $status; $(tail -3 "$T/out")"
fi
ts equilibrium "$EX1" --quiet --no-discretisation-error --json "$T/n.json"
if [ "$status" -eq 0 ] &&
   grep -q 'discretisation error: not estimated: off (--no-discretisation-error)' "$T/out" &&
   grep -q '"discretisation": null' "$T/n.json" && grep -q 'trustworthy: yes' "$T/out"; then
    pass "--no-discretisation-error: not estimated, said so"
else
    fail "--no-discretisation-error: status $status; $(tail -3 "$T/out")"
fi
ts equilibrium "$EX1" --accuracy 2
if [ "$status" -eq 2 ] && grep -q -- '--accuracy' "$T/err"; then
    pass "--accuracy 2: exit 2 naming the option: $(cat "$T/err")"
else
    fail "--accuracy 2: status $status; $(cat "$T/err")"
fi
sed 's/^analyses:.*/analyses:\n  - {type: equilibrium, accuracy: 0}/' "$EX1" | sed '/^  - type: equilibrium$/,$d' >"$T/a.yaml"
ts run "$T/a.yaml"
if [ "$status" -eq 2 ] && grep -q 'accuracy' "$T/err" && grep -q 'line' "$T/err"; then
    pass "scene entry accuracy: 0: exit 2 naming the key and line"
else
    fail "scene accuracy 0: status $status; $(cat "$T/err")"
fi
ts equilibrium "$EX3" --quiet --turn-rate "0.5 rad/s"
if [ "$status" -eq 0 ] &&
   grep -q 'turn rate 0.5 rad/s (28.65 deg/s, turn radius 1.524 m, to starboard)' "$T/out"; then
    pass "header: turn rate in deg/s with the turn radius"
else
    fail "header: $(head -3 "$T/out")"
fi
ts equilibrium "$EX1" --quiet --turn-rate 1 --no-discretisation-error
if grep -q 'shorter than a tenth of the cable length' "$T/out" &&
   grep -q '57.3 deg/s' "$T/out"; then
    pass "a turn radius under a tenth of the cable: a note with deg/s"
else
    fail "turn radius note: status $status; $(tail -4 "$T/out")"
fi

# Modes.
ts modes "$EX3" --json "$T/m.json"
first=$(awk '/^mode +Re/{getline; print; exit}' "$T/out")
if [ "$status" -eq 0 ] && echo "$first" | awk '{exit !($3 > 0)}' &&
   grep -q '\[UNRESOLVED: ' "$T/out" &&
   grep -q '^verdict: stable: the 1 resolved mode is stable: max Re(lambda) = -0.523892 1/s (mode 1)' "$T/out" &&
   grep -q '^unresolved modes (44: ' "$T/out" &&
   "$CHECK_JSON" parse "$T/m.json" >/dev/null &&
   grep -q '"resolved": true' "$T/m.json" && grep -q '"resolved_modes": 1' "$T/m.json" &&
   grep -q '"unresolved_max_real": -0.2010' "$T/m.json"; then
    pass "modes ex. 3 turn: oscillatory first, unresolved labelled, the resolved modes' margin"
else
    fail "modes ex. 3: status $status; first row '$first'; $(grep -E '^verdict|^unresolved' "$T/out")"
fi
ts modes "$EX3" --count 5 --near 0.1 --quiet --json "$T/near.json"
# The modes' entries (indented 6; the rightmost eigenvalue's object, 4).
n=$(grep -c '^      "freq_hz": 0\.[0-9]*[1-9]' "$T/near.json")
if [ "$status" -eq 0 ] && [ "$(grep -c '^      "re":' "$T/near.json")" -eq 5 ] &&
   ! grep -q '^      "im": 0\.0,' "$T/near.json"; then
    pass "--count 5 --near 0.1: five oscillatory modes"
else
    fail "--near: status $status; $(grep -c '^      "re":' "$T/near.json") modes ($n)"
fi
ts modes "$EX3" --oscillatory --json "$T/osc.json"
if [ "$status" -eq 0 ] && ! grep -q 'real:' "$T/out" && grep -q '^listed: 35 of them' "$T/out"; then
    pass "--oscillatory: only the 35 oscillatory modes listed"
else
    fail "--oscillatory: status $status; $(grep -c 'real:' "$T/out") real rows"
fi

# Response.
ts response examples/kamman_ex1_above.yaml --output sphere.z --points 5 --json "$T/r.json"
if [ "$status" -eq 0 ] && grep -q '+- disc.' "$T/out" &&
   grep -q 'the magnitude meets the accuracy' "$T/out" &&
   grep -q '"magnitude_error"' "$T/r.json" && grep -q '"accurate_to_hz"' "$T/r.json" &&
   grep -q 'sphere.z.static_gain' "$T/r.json"; then
    pass "response: errors per point, accurate_to_hz, the static gain's error"
else
    fail "response: status $status; $(tail -3 "$T/out")"
fi
ts response examples/kamman_ex1_above.yaml --output cable.13.z --points 3
if [ "$status" -eq 0 ] && grep -q 'not estimated: the 10-link discretisation has no node at the place of cable.13.z' "$T/out"; then
    pass "response at cable.13 of 20 links: not estimated, said why"
else
    fail "response cable.13: status $status; $(grep discretisation "$T/out")"
fi

# Simulate: the window, and the estimate on request. The heave starts
# smoothly over two periods (the default), which sets the drift left.
ts simulate "$EX4" --excite tow.heave:amplitude=0.1ft,frequency=1Hz --t-end 8 --no-compare --quiet --json "$T/s.json"
if [ "$status" -eq 0 ] && grep -q '^window: t >= 4 s of 8 s; slowest time constant 1.588 s' "$T/out" &&
   grep -q 'NOT SETTLED, NOT PERIODIC' "$T/out" &&
   grep -q 'reason: not settled: .* --transient 8.55. --t-end 12.5. would do' "$T/out" &&
   grep -q 'discretisation error: not estimated: off: it costs the simulation again' "$T/out" &&
   grep -q '"settled": false' "$T/s.json"; then
    pass "simulate over 4..8 s: not settled, --transient named, no estimate by default"
else
    fail "simulate window: status $status; $(grep -E 'window|reason|discretisation' "$T/out")"
fi
ts simulate "$EX4" --excite tow.heave:amplitude=0.1ft,frequency=1Hz --t-end 15 --transient 11 --no-compare --quiet --discretisation-error --links 10
if [ "$status" -eq 0 ] && grep -q 'settled, periodic' "$T/out" &&
   grep -q 'sphere.z.amplitude_ratio .* +- 0.001[0-9] (discretisation)' "$T/out" &&
   grep -q 'Richardson from 10, 5 and 3 links' "$T/out"; then
    pass "simulate --discretisation-error at 10 links: estimated from 5 and 3 links; settled, periodic"
else
    fail "simulate estimate: status $status; $(grep -E 'window|amplitude|discretisation' "$T/out")"
fi

finish
