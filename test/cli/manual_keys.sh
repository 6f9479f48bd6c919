#!/bin/bash
# manual_keys.sh: every JSON key towstab writes is defined in doc/manual.md.
#   manual_keys.sh TOWSTAB CHECK_JSON
# Runs `towstab run` on every examples/*.yaml and each command once more
# with the options that add keys (modes with matrices and shapes, a
# response, a simulation with a comparison, a response and a simulation
# in a sea, the three kinds of
# convergence study), lists the keys of each result with
# `check_json keys` and looks for each key, written `key`, in the part of
# doc/manual.md of the command that wrote it ("## towstab COMMAND") or in
# its "## Output conventions" part (keys every command shares). Keys of a
# nested "equilibrium" object belong to `towstab equilibrium`, those of a
# run's analyses to their type. Run from the project root.
set -u
if [ $# -ne 2 ]; then
    echo "usage: manual_keys.sh TOWSTAB CHECK_JSON" >&2
    exit 2
fi
TOWSTAB=$1 CHECK_JSON=$2
manual=doc/manual.md
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
fail=0

# json COMMAND ARGS...: run `towstab COMMAND ARGS --json FILE --quiet` and
# add the keys of FILE to $T/pairs.
n=0
json() {
    local cmd=$1
    shift
    n=$((n + 1))
    "$TOWSTAB" "$cmd" "$@" --json "$T/$n.json" --quiet >"$T/out" 2>"$T/err"
    local status=$?
    if [ "$status" -ne 0 ]; then
        echo "FAIL: towstab $cmd $*: exit status $status: $(head -c 300 "$T/err")"
        fail=1
        return
    fi
    "$CHECK_JSON" keys "$cmd" "$T/$n.json" >>"$T/pairs" || fail=1
}

for f in examples/*.yaml; do
    json run "$f"
done
json equilibrium examples/kamman_ex1_above.yaml
json modes examples/kamman_ex3_turn.yaml --matrices --shapes "$T/shapes.json"
json modes test/scenes/towing_sphere.yaml --free-vehicle --links 4
"$CHECK_JSON" keys modes "$T/shapes.json" >>"$T/pairs" || fail=1
json response examples/kamman_ex1_above.yaml --output sphere.z --points 3
json response examples/aurora_towfish.yaml --open-loop --input aurora.wing \
    --output aurora.depth --points 3 --links 10
json simulate examples/kamman_ex4.yaml --compare --t-end 34 \
    --excite tow.heave:amplitude=0.1ft,frequency=0.25Hz
json response examples/survey_tow_sea.yaml --output fish.z \
    --sea Hs=2m,Tp=8s --rao examples/ship_rao.csv --rao-reference 30,0,0 \
    --intervals 64
json simulate examples/survey_tow_sea.yaml --output fish.z --links 5 \
    --sea Hs=2m,Tp=8s --rao examples/ship_rao.csv --rao-reference 30,0,0 \
    --t-end 120 --transient 60 --sample 0.5 --components 32 --compare
json simulate examples/kamman_ex3_turn.yaml --t-end 2 --sample 0.5 \
    --excite tow.heave:type=crank,amplitude=0.01,rod=0.05,period=1s \
    --excite tow.surge:type=step,amplitude=0.01,start=0.5s \
    --manoeuvre speed:by=0.1,start=0.2s,duration=0.5s
json converge examples/kamman_ex1_submerged.yaml --links 5,10,20
json converge examples/kamman_ex3_turn.yaml --analysis modes --links 5,10,20 \
    --modes 2
json sweep examples/kamman_ex1_above.yaml --analysis modes --vary speed=7:9:3
json sweep examples/kamman_ex1_submerged.yaml --vary speed=0:2:2 \
    --vary cables.cable.length=1e-3,30
json design examples/kamman_ex1_submerged.yaml --free cables.cable.length=10:60 \
    --target sphere.z=15m --constraint "top_tension<=600N"
json design examples/kamman_ex1_above.yaml --analysis modes --free speed=2:8.5 \
    --maximise speed --constraint "max_real<=0" --max-evals 60
json converge examples/kamman_ex4.yaml --analysis simulate \
    --tolerances 1e-3,1e-5 --integrators rk8pd,rkf45 --t-end 34

# The manual's parts: "## towstab COMMAND" -> COMMAND, "## Output
# conventions" -> common; one file each.
mkdir "$T/sections"
awk -v dir="$T/sections" '
    /^## / {
        name = ""
        if ($0 ~ /^## towstab [a-z]+/) { split($0, w, " "); name = w[3] }
        else if ($0 ~ /^## Output conventions/) name = "common"
    }
    name != "" { print > (dir "/" name) }
' "$manual"
[ -s "$T/sections/common" ] || { echo "FAIL: $manual has no '## Output conventions' part"; fail=1; }

npairs=0 missing=0
if [ -s "$T/pairs" ]; then
    while read -r section key; do
        npairs=$((npairs + 1))
        if ! grep -qF "\`$key\`" "$T/sections/$section" "$T/sections/common" 2>/dev/null; then
            echo "FAIL: JSON key '$key' of towstab $section is not defined in $manual (write \`$key\` in its part, or in 'Output conventions' when every command writes it)"
            missing=$((missing + 1))
        fi
    done < <(sort -u "$T/pairs")
fi
if [ "$npairs" -lt 100 ]; then
    echo "FAIL: only $npairs keys found: the runs did not produce their JSON"
    fail=1
elif [ "$missing" -eq 0 ]; then
    echo "PASS: all $npairs JSON keys written by $n runs are defined in $manual"
else
    fail=1
fi
exit $fail
