#!/bin/bash
# test/cli/run.sh: the towstab command line, run as a user would.
#
#   run.sh TOWSTAB CHECK_JSON cli        suite 'cli'
#   run.sh TOWSTAB CHECK_JSON examples   suite 'examples'
#
# Run from the project root (meson does). TOWSTAB is the built tool,
# CHECK_JSON the checker built from test/cli/check_json.c.
#
# cli: every test/scenes/bad_*.yaml and test/cli/bad/*.yaml is refused with
#   exit status 2, one line on standard error naming the key and its line,
#   nothing on standard output that looks like a result, and no output file
#   (--json/--csv go to a temporary folder that must stay empty); bad
#   options likewise; every example's `towstab equilibrium --json --csv`
#   output is valid JSON with the required keys and a CSV with one row per
#   node; `--json -` writes JSON alone to standard output; an analysis that
#   cannot converge exits 1 without a CSV.
# examples: `towstab run` on every examples/*.yaml succeeds and its JSON
#   matches examples/<name>.expected.json at the tolerance stated in that
#   file (rtol 1e-6, see the expected files).
#
# Prints one PASS/FAIL line per check and "N passed, N failed"; the exit
# status is 0 only when nothing failed.
set -u

if [ $# -ne 3 ]; then
    echo "usage: run.sh TOWSTAB CHECK_JSON cli|examples" >&2
    exit 2
fi
TOWSTAB=$1
CHECK_JSON=$2
MODE=$3
T=$(mktemp -d "${TMPDIR:-/tmp}/towstab-cli-XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT

npass=0
nfail=0
pass() { echo "PASS $*"; npass=$((npass + 1)); }
fail() { echo "FAIL $*"; nfail=$((nfail + 1)); }

# ts ARGS...: run towstab; stdout in $T/out, stderr in $T/err, status in
# $status.
ts() {
    "$TOWSTAB" "$@" >"$T/out" 2>"$T/err"
    status=$?
}

# no_outputs: nothing was written to the output folder $T/o.
no_outputs() {
    [ -z "$(ls -A "$T/o")" ]
}

fresh_outputs() {
    rm -rf "$T/o"
    mkdir "$T/o"
}

# looks_like_result FILE: the text a successful run prints.
looks_like_result() {
    grep -q -E 'converged|top tension|tension \[N\]|"nodes"' "$1"
}

# A scene key path: cables[0].length, tow.speed, analyses[1].method, ...
KEY_RE='^[A-Za-z_]+(\[[0-9]+\])?(\.[A-Za-z_0-9]+(\[[0-9]+\])?)*$'

# bad_scene FILE COMMAND: FILE must be refused by COMMAND (equilibrium or
# run) as bad input. The expected key is given by the fixture's
# "# expect: KEY" line when present, else it must look like a key path;
# "# expect-line: no" exempts a fixture from naming a line.
bad_scene() {
    local f=$1 cmd=$2 why=""
    fresh_outputs
    if [ "$cmd" = equilibrium ]; then
        ts equilibrium "$f" --json "$T/o/r.json" --csv "$T/o/r.csv"
    else
        ts run "$f" --json "$T/o/r.json"
    fi
    local msg
    msg=$(cat "$T/err")
    local want
    want=$(sed -n 's/^# expect: //p' "$f" | head -1)
    [ "$status" -eq 2 ] || why="$why exit status $status, not 2;"
    [ "$(wc -l <"$T/err")" -eq 1 ] || why="$why stderr has $(wc -l <"$T/err") lines, not 1;"
    # An empty file has no line to name.
    if ! grep -q '^# expect-line: no' "$f" && [ "$(basename "$f")" != bad_empty.yaml ]; then
        [[ $msg =~ line\ [0-9]+ ]] || why="$why no 'line N' in the message;"
    fi
    if [ -n "$want" ]; then
        # The key, followed by its line or a colon.
        case "$msg" in
        *"$want ("* | *"$want:"* | *"$want "*) ;;
        *) why="$why the message does not name '$want';" ;;
        esac
    else
        local rest=${msg#"towstab: error: $f: "}
        if [ "$rest" = "$msg" ]; then
            why="$why the message does not start with 'towstab: error: $f: ';"
        else
            local key=${rest%% (line*}
            key=${key%%:*}
            case "$(basename "$f")" in
            # Errors about the file as a whole, not one key.
            bad_empty.yaml) [[ $rest == *empty* ]] || why="$why not 'empty';" ;;
            bad_syntax.yaml) [[ $rest == *"YAML syntax error"* ]] || why="$why not a syntax error;" ;;
            bad_second_document.yaml) [[ $rest == *"second YAML document"* ]] || why="$why not 'second YAML document';" ;;
            *) [[ $key =~ $KEY_RE || $key == "top level" ]] || why="$why '$key' is not a key path;" ;;
            esac
        fi
    fi
    if looks_like_result "$T/out"; then
        why="$why a result on stdout;"
    fi
    no_outputs || why="$why left $(ls "$T/o" | tr '\n' ' ');"
    if [ -z "$why" ]; then
        pass "$cmd $f: exit 2, one line naming the key: $msg"
    else
        fail "$cmd $f:$why message: $msg"
    fi
}

# bad_option DESC WORD ARGS...: towstab ARGS must exit 2 with a message
# on stderr containing WORD (the option or value at fault), print no
# result and write no file. ARGS may name $T/o/r.json as an output.
bad_option() {
    local desc=$1 word=$2 why=""
    shift 2
    fresh_outputs
    ts "$@"
    [ "$status" -eq 2 ] || why="$why exit status $status, not 2;"
    [ -s "$T/err" ] || why="$why nothing on stderr;"
    grep -q -F -- "$word" "$T/err" || why="$why stderr does not name '$word';"
    if looks_like_result "$T/out"; then
        why="$why a result on stdout;"
    fi
    no_outputs || why="$why left $(ls "$T/o" | tr '\n' ' ');"
    local msg
    msg=$(head -1 "$T/err")
    if [ -z "$why" ]; then
        pass "$desc: exit 2: $msg"
    else
        fail "$desc:$why stderr: $msg"
    fi
}

# csv_rows FILE N: header and N rows of a name and four numbers, the tow
# point first.
csv_ok() {
    local f=$1 n=$2
    awk -F, -v n="$n" '
        NR == 1 { if ($0 != "node,x_m,y_m,z_m,tension_above_N") exit 1; next }
        NR == 2 && $1 != "tow" { exit 1 }
        NF != 5 { exit 1 }
        { for (i = 2; i <= 5; i++) if ($i !~ /^-?[0-9.]+([eE][-+]?[0-9]+)?$/) exit 1 }
        END { if (NR != n + 1) exit 1 }' "$f"
}

# The structure check must reject what it should.
structure_selftest() {
    local v='{"converged": true, "iterations": 3, "residual": 1e-12, "top_tension": 2.5, "nodes": [{"name": "tow", "x": 0, "y": 0, "z": 0}, {"name": "c.1", "x": -1, "y": 0, "z": 1}], "links": [{"cable": "c", "index": 1, "tension": 2.5, "theta1_deg": 45, "theta2_deg": 0}], "bodies": []}'
    local why="" m
    echo "$v" >"$T/v.json"
    "$CHECK_JSON" equilibrium "$T/v.json" >/dev/null || why="$why rejects a valid result;"
    for m in "${v/true/false}" "${v/1e-12/2e-10}" "${v/\"tow\"/\"c.0\"}" \
        "${v/\"iterations\": 3, /}" "${v/\"index\": 1/\"index\": 0}" \
        "${v/, \"theta2_deg\": 0/}" "${v/\"bodies\": []/\"bodies\": 0}" \
        "${v/\"top_tension\": 2.5, /}"; do
        echo "$m" >"$T/v.json"
        "$CHECK_JSON" equilibrium "$T/v.json" >/dev/null && why="$why accepts $m;"
    done
    if [ -z "$why" ]; then
        pass "check_json equilibrium: accepts a valid result; rejects converged false, residual 2e-10, no tow first, missing iterations, index 0, missing theta2_deg, bodies not a list, missing top_tension"
    else
        fail "check_json equilibrium:$why"
    fi
}

run_cli() {
    local f
    structure_selftest
    for f in test/scenes/bad_*.yaml; do
        bad_scene "$f" equilibrium
        bad_scene "$f" run
    done
    for f in test/cli/bad/*.yaml; do
        bad_scene "$f" run
    done

    local good=examples/kamman_ex3_turn.yaml
    bad_option "unknown option" "--frobnicate" equilibrium "$good" --frobnicate --json "$T/o/r.json"
    bad_option "--links 0" "--links" equilibrium "$good" --links 0 --json "$T/o/r.json"
    bad_option "--links abc" "--links" equilibrium "$good" --links abc --json "$T/o/r.json"
    bad_option "--tolerance -1" "--tolerance" equilibrium "$good" --tolerance -1 --json "$T/o/r.json"
    bad_option "--equilibrium-method foo" "--equilibrium-method" equilibrium "$good" --equilibrium-method foo --json "$T/o/r.json"
    bad_option "--speed '50 lb'" "--speed" equilibrium "$good" --speed "50 lb" --json "$T/o/r.json"
    bad_option "--turn-rate '1 Hz'" "--turn-rate" equilibrium "$good" --turn-rate "1 Hz" --json "$T/o/r.json"
    bad_option "--json without a value" "--json" equilibrium "$good" --json
    bad_option "missing scene file" "$T/no_such_scene.yaml" equilibrium "$T/no_such_scene.yaml" --json "$T/o/r.json"
    bad_option "two scene files" "one scene file" equilibrium "$good" "$good" --json "$T/o/r.json"
    bad_option "no scene file" "one scene file" equilibrium --json "$T/o/r.json"
    bad_option "run with an equilibrium option" "--links" run "$good" --links 3 --json "$T/o/r.json"
    bad_option "run: missing scene file" "$T/no_such_scene.yaml" run "$T/no_such_scene.yaml" --json "$T/o/r.json"
    bad_option "unknown command" "frobnicate" frobnicate "$good"
    bad_option "no command" "usage"

    ts --help
    if [ "$status" -eq 0 ] && grep -q equilibrium "$T/out"; then
        pass "towstab --help: exit 0, lists the commands"
    else
        fail "towstab --help: exit $status"
    fi
    ts equilibrium --help
    if [ "$status" -eq 0 ] && grep -q -- "--json" "$T/out"; then
        pass "towstab equilibrium --help: exit 0, lists the options"
    else
        fail "towstab equilibrium --help: exit $status"
    fi

    # Every example: JSON with the required keys and a CSV row per node.
    local x name n
    for x in examples/*.yaml; do
        name=$(basename "$x" .yaml)
        fresh_outputs
        ts equilibrium "$x" --quiet --json "$T/o/$name.json" --csv "$T/o/$name.csv"
        if [ "$status" -ne 0 ]; then
            fail "equilibrium $x: exit status $status: $(head -1 "$T/err")"
            continue
        fi
        [ -s "$T/err" ] && fail "equilibrium $x: stderr not empty: $(head -1 "$T/err")"
        if n=$("$CHECK_JSON" equilibrium "$T/o/$name.json" 2>&1); then
            n=${n#nodes }
            pass "equilibrium $x: JSON converged, residual <= 1e-10, nodes (tow first), links, bodies, top_tension ($n nodes)"
        else
            fail "equilibrium $x: JSON: $(echo "$n" | tr '\n' ' ')"
            continue
        fi
        if csv_ok "$T/o/$name.csv" "$n"; then
            pass "equilibrium $x: CSV header and $n rows, tow first, numbers"
        else
            fail "equilibrium $x: CSV is not a header and $n rows of a name and 4 numbers"
        fi
        if [ "$(ls "$T/o" | wc -l)" -eq 2 ]; then
            pass "equilibrium $x: exactly the two files requested, no temporaries"
        else
            fail "equilibrium $x: output folder holds $(ls "$T/o" | tr '\n' ' ')"
        fi
    done

    # '-' sends the JSON to standard output, alone, so that it parses.
    ts equilibrium "$good" --quiet --json -
    if [ "$status" -eq 0 ] && "$CHECK_JSON" parse "$T/out" >"$T/chk" 2>&1; then
        pass "equilibrium --json -: standard output is one JSON document"
    else
        fail "equilibrium --json -: exit $status, standard output is not JSON alone: $(head -1 "$T/chk")"
    fi
    ts run "$good" --quiet --json -
    if [ "$status" -eq 0 ] && "$CHECK_JSON" parse "$T/out" >"$T/chk" 2>&1; then
        pass "run --json -: standard output is one JSON document"
    else
        fail "run --json -: exit $status, standard output is not JSON alone: $(head -1 "$T/chk")"
    fi

    # An analysis that cannot reach its tolerance: exit 1, a message with
    # the residual, no CSV; a JSON, if any, says it did not converge.
    fresh_outputs
    ts equilibrium examples/kamman_ex1_submerged.yaml --quiet --tolerance 1e-300 \
        --json "$T/o/f.json" --csv "$T/o/f.csv"
    local why=""
    [ "$status" -eq 1 ] || why="$why exit status $status, not 1;"
    grep -q residual "$T/err" || why="$why no residual in the message;"
    [ -e "$T/o/f.csv" ] && why="$why a CSV of an unconverged shape;"
    if [ -e "$T/o/f.json" ] && ! grep -q '"converged": false' "$T/o/f.json"; then
        why="$why the JSON does not say converged false;"
    fi
    ls "$T/o" | grep -q partial && why="$why a temporary file left;"
    if [ -z "$why" ]; then
        pass "--tolerance 1e-300: exit 1, $(head -1 "$T/err")"
    else
        fail "--tolerance 1e-300:$why"
    fi
}

# The checker itself must reject what it should, or a match means nothing.
checker_selftest() {
    printf '{"a": 2.5, "b": [1, 0.0], "c": "x", "d": true, "e": {"f": 3}}\n' >"$T/r.json"
    local spec why=""
    spec() { printf '{"rtol": 1e-6, "atol": 1e-9, "expect": %s}\n' "$1" >"$T/s.json"; }
    spec '{"a": 2.5000015, "b": [1, 1e-10], "c": "x", "d": true, "e": {"f": 3}}'
    "$CHECK_JSON" compare "$T/r.json" "$T/s.json" >/dev/null || why="$why rejects a match within tolerance;"
    for bad in '{"a": 2.500003}' '{"b": [1, 2e-9]}' '{"b": [1]}' '{"c": "y"}' \
        '{"d": false}' '{"e": {"g": 3}}' '{"z": 1}' '{"a": "2.5"}'; do
        spec "$bad"
        "$CHECK_JSON" compare "$T/r.json" "$T/s.json" >/dev/null && why="$why accepts $bad;"
    done
    if [ -z "$why" ]; then
        pass "check_json compare: accepts rtol 1e-6 + atol 1e-9, rejects a number off by 1.2e-6, a missing key, a shorter array, another string, boolean or type"
    else
        fail "check_json compare:$why"
    fi
}

run_examples() {
    local x name exp n=0
    checker_selftest
    for x in examples/*.yaml; do
        n=$((n + 1))
        name=$(basename "$x" .yaml)
        exp=examples/$name.expected.json
        if [ ! -f "$exp" ]; then
            fail "$x: no expected summary $exp"
            continue
        fi
        fresh_outputs
        ts run "$x" --quiet --json "$T/o/$name.json"
        if [ "$status" -ne 0 ]; then
            fail "run $x: exit status $status: $(head -1 "$T/err")"
            continue
        fi
        pass "run $x: exit 0"
        if "$CHECK_JSON" equilibrium "$T/o/$name.json" >"$T/chk" 2>&1; then
            pass "run $x: every analysis converged, with the required keys"
        else
            fail "run $x: $(tr '\n' ' ' <"$T/chk")"
        fi
        if "$CHECK_JSON" compare "$T/o/$name.json" "$exp" >"$T/chk" 2>&1; then
            pass "run $x: matches $exp"
        else
            fail "run $x: differs from $exp: $(tr '\n' ' ' <"$T/chk")"
        fi
    done
    [ "$n" -gt 0 ] && pass "$n examples" || fail "no examples found (run from the project root)"
}

case "$MODE" in
cli) run_cli ;;
examples) run_examples ;;
*)
    echo "run.sh: unknown mode '$MODE' (cli or examples)" >&2
    exit 2
    ;;
esac
echo "$npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
