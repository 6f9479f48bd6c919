#!/bin/bash
# test/cli/outputs.sh: output targets are written where the user pointed,
# or the run fails loudly, and nothing else is damaged (doc/manual.md,
# "Output files").
#
#   outputs.sh TOWSTAB CHECK_JSON
#
# Special files are made in a temporary folder (a device node with mknod
# only when root), never in /dev; /dev/null and /dev/full are only written
# to, and must be the same character devices afterwards. Checked:
# devices, FIFOs and symbolic links as targets; /dev/full as --json and as
# standard output (exit 1 naming the target); two outputs naming one file
# (exit 2, nothing written); a failed run's JSON marked "completed": false
# with the message standard error gave, and no "trustworthy: yes".
#
# Prints one PASS/FAIL line per check and "N passed, N failed".
set -u

if [ $# -ne 2 ]; then
    echo "usage: outputs.sh TOWSTAB CHECK_JSON" >&2
    exit 2
fi
TOWSTAB=$1
CHECK_JSON=$2
. "$(dirname "$0")/common.sh"
EX=examples/kamman_ex3_turn.yaml
EX5=examples/kamman_ex5_drop.yaml
# device_id PATH: type, inode and device numbers, to compare before/after.
device_id() { stat -c '%F %i %t:%T' "$1"; }

# 1. /dev/null as --json: written, still the same device.
before=$(device_id /dev/null)
ts equilibrium "$EX" --quiet --json /dev/null
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
[ "$(device_id /dev/null)" = "$before" ] || why="$why /dev/null is now $(device_id /dev/null);"
check "--json /dev/null: exit 0, /dev/null still the character device ($before)" "$why"

# 2. /dev/full as --json: exit 1 naming it, still the device.
before=$(device_id /dev/full)
ts equilibrium "$EX" --quiet --json /dev/full
why=""
[ "$status" -eq 1 ] || why="$why exit $status, not 1;"
grep -q '/dev/full' "$T/err" || why="$why stderr does not name /dev/full;"
[ "$(device_id /dev/full)" = "$before" ] || why="$why /dev/full is now $(device_id /dev/full);"
check "--json /dev/full: exit 1: $(head -1 "$T/err")" "$why"

# 3. A full standard output: every command's table is checked.
for args in "equilibrium $EX" "modes $EX" \
    "response $EX --output sphere.z --points 5" \
    "simulate $EX5 --t-end 6" "converge $EX --links 5,10,20" "run $EX"; do
    # shellcheck disable=SC2086
    "$TOWSTAB" $args >/dev/full 2>"$T/err"
    status=$?
    why=""
    [ "$status" -eq 1 ] || why="$why exit $status, not 1;"
    grep -q 'standard output' "$T/err" || why="$why stderr does not name standard output: $(head -1 "$T/err");"
    check "${args%% *} > /dev/full: exit 1 naming standard output" "$why"
done

# 4. A device node made here (root only).
if mknod "$T/dev" c 1 3 2>/dev/null; then
    before=$(device_id "$T/dev")
    ts equilibrium "$EX" --quiet --json "$T/dev" --csv "$T/dev"
    why=""
    [ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
    [ "$(device_id "$T/dev")" = "$before" ] || why="$why now $(device_id "$T/dev");"
    ls "$T" | grep -q partial && why="$why a temporary file left;"
    check "a device node as --json and --csv: written in place, still the device" "$why"
else
    echo "SKIP a device node made with mknod (not permitted here)"
fi

# 5. A FIFO: its reader gets the JSON, the FIFO stays.
mkfifo "$T/fifo"
cat "$T/fifo" >"$T/from_fifo" &
reader=$!
ts equilibrium "$EX" --quiet --json "$T/fifo"
wait "$reader"
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
[ -p "$T/fifo" ] || why="$why the FIFO was replaced;"
"$CHECK_JSON" equilibrium "$T/from_fifo" >/dev/null 2>&1 || why="$why the reader did not get the JSON;"
check "--json FIFO: the reader gets the JSON, the FIFO stays" "$why"

# 6. A symbolic link: the file it names is replaced, the link kept.
fresh
echo old >"$T/o/target.json"
ln -s target.json "$T/o/link.json"
ts equilibrium "$EX" --quiet --json "$T/o/link.json"
why=""
[ "$status" -eq 0 ] || why="$why exit $status;"
[ -L "$T/o/link.json" ] || why="$why the link was replaced;"
"$CHECK_JSON" equilibrium "$T/o/target.json" >/dev/null 2>&1 || why="$why target.json does not hold the result;"
check "--json LINK: the link kept, its target holds the result" "$why"

# 7. /dev/stdout: the JSON goes to the descriptor, after the table.
ts equilibrium "$EX" --quiet --json /dev/stdout
why=""
[ "$status" -eq 0 ] || why="$why exit $status;"
grep -q '^converged' "$T/out" || why="$why the table is gone;"
grep -q '"top_tension"' "$T/out" || why="$why no JSON on standard output;"
check "--json /dev/stdout (a file): table and JSON both there" "$why"

# 8. Two outputs naming one file: refused up front, nothing written.
same() { # same DESCRIPTION ARGS...
    local desc=$1
    shift
    fresh
    ts "$@"
    local why=""
    [ "$status" -eq 2 ] || why="$why exit $status, not 2;"
    grep -q -E 'same file|standard output' "$T/err" || why="$why message: $(head -1 "$T/err");"
    [ -z "$(ls -A "$T/o")" ] || why="$why left $(ls "$T/o" | tr '\n' ' ');"
    grep -q -E 'converged|trustworthy' "$T/out" && why="$why it ran;"
    check "$desc: exit 2, nothing written: $(head -1 "$T/err")" "$why"
}
same "--json and --csv the same file" equilibrium "$EX" --json "$T/o/same.out" --csv "$T/o/same.out"
same "the same file spelt twice" equilibrium "$EX" --json "$T/o/a.json" --csv "$T/o/./a.json"
same "--json - and --csv -" equilibrium "$EX" --json - --csv -
same "modes --csv and --shapes" modes "$EX" --csv "$T/o/m.csv" --shapes "$T/o/m.csv"
same "response --json and --csv" response "$EX" --output sphere.z --json "$T/o/r" --csv "$T/o/r"
same "simulate --json and --csv" simulate "$EX5" --t-end 6 --json "$T/o/s" --csv "$T/o/s"
same "converge --json and --csv" converge "$EX" --links 5,10 --json "$T/o/c" --csv "$T/o/c"
same "--json into the --plot pictures" equilibrium "$EX" --plot "$T/o" --json "$T/o/side.svg"
# A link and its target (the target exists).
fresh
echo old >"$T/t.json"
ln -s "$T/t.json" "$T/l.json"
ts equilibrium "$EX" --json "$T/l.json" --csv "$T/t.json"
why=""
[ "$status" -eq 2 ] || why="$why exit $status, not 2;"
[ "$(cat "$T/t.json")" = old ] || why="$why the target was written;"
check "a link and its target: exit 2, untouched" "$why"

# 9. A failed equilibrium (a neutrally buoyant line towed from the surface:
# nothing restores its links): the JSON says so, with the message of
# stderr. (A weight of 1e300 is refused before the solve, exit 2.)
sed 's|weight: "1 lbf/ft"|wet_weight: 0|; s|weight: "50 lbf"|wet_weight: 0|' \
    examples/kamman_ex1_submerged.yaml >"$T/neutral.yaml"
fresh
ts equilibrium "$T/neutral.yaml" --json "$T/o/f.json"
msg=$(sed -n 's/^towstab: error: //p' "$T/err" | head -1)
why=""
[ "$status" -eq 1 ] || why="$why exit $status, not 1;"
grep -q '"completed": false' "$T/o/f.json" || why="$why not completed false;"
grep -q '"trustworthy": false' "$T/o/f.json" || why="$why not trustworthy false;"
grep -F -q "\"error\": \"$msg\"" "$T/o/f.json" || why="$why its error is not stderr's message;"
grep -q 'residual 0 of' "$T/o/f.json" && why="$why it blames a residual of 0;"
grep -q 'trustworthy: yes' "$T/out" && why="$why stdout says trustworthy: yes;"
check "failed equilibrium (neutral buoyancy): JSON completed false with stderr's reason" "$why"

# 10. A failed simulation: its summary and JSON are not trustworthy.
fresh
ts simulate "$EX5" --h-min 0.5 --json "$T/o/s.json" --quiet
why=""
[ "$status" -eq 1 ] || why="$why exit $status, not 1;"
grep -q 'trustworthy: yes' "$T/out" && why="$why stdout says trustworthy: yes;"
grep -q 'trustworthy: NO' "$T/out" || why="$why stdout has no verdict;"
grep -q '"trustworthy": false' "$T/o/s.json" || why="$why JSON trustworthy;"
grep -q '"completed": false' "$T/o/s.json" || why="$why JSON not completed false;"
check "failed simulation (--h-min 0.5): trustworthy NO, JSON incomplete" "$why"

# 11. run: a failed analysis leaves the results so far, marked.
cat "$T/neutral.yaml" >"$T/neutral_run.yaml"
fresh
ts run "$T/neutral_run.yaml" --json "$T/o/r.json"
why=""
[ "$status" -eq 1 ] || why="$why exit $status, not 1;"
"$CHECK_JSON" parse "$T/o/r.json" >/dev/null 2>&1 || why="$why no JSON;"
grep -q '"completed": false' "$T/o/r.json" || why="$why not completed false;"
grep -q '"error"' "$T/o/r.json" || why="$why no error;"
check "run with a failing analysis: JSON marked incomplete" "$why"

finish
