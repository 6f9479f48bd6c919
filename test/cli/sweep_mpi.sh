#!/bin/bash
# test/cli/sweep_mpi.sh: `mpirun -np 2 towstab sweep` (suite 'mpi').
#
#   sweep_mpi.sh TOWSTAB MPIRUN
#
# - A modes sweep of examples/kamman_ex1_above.yaml over speed and turn
#   rate, with its stability boundary, run serially and with mpirun -np 2
#   (each process one thread): the same CSV, byte for byte, and the same
#   crossings in the JSON.
# - A sweep begun serially with --resume and stopped after a few chains,
#   finished under mpirun -np 3: the CSV of one serial run.
# As root, mpirun needs OMPI_ALLOW_RUN_AS_ROOT(_CONFIRM); --oversubscribe
# lets it start more processes than the machine has cores.
set -u
if [ $# -ne 2 ]; then
    echo "usage: sweep_mpi.sh TOWSTAB MPIRUN" >&2
    exit 2
fi
TOWSTAB=$1
MPIRUN=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
. "$(dirname "$0")/common.sh"
mpi() { "$MPIRUN" --oversubscribe -np "$@"; }
# The crossings of a sweep's JSON, one line each.
crossings() {
    tr -d '\n ' <"$1" | grep -o '"boundary":\[.*\],"points_failed"' |
        grep -o '"value":[^,]*,"stable":[^,]*,"unstable":[^,]*'
}

A="examples/kamman_ex1_above.yaml --analysis modes --vary speed=4:10:7 --vary turn_rate=0:0.1:4 --quiet"
"$TOWSTAB" sweep $A --jobs 1 --csv "$T/serial.csv" --json "$T/serial.json" \
    >/dev/null 2>"$T/err1"
s1=$?
mpi 2 "$TOWSTAB" sweep $A --csv "$T/mpi.csv" --json "$T/mpi.json" \
    >"$T/out2" 2>"$T/err2"
s2=$?
if [ "$s1" -eq 0 ] && [ "$s2" -eq 0 ] && cmp -s "$T/serial.csv" "$T/mpi.csv"; then
    pass "mpirun -np 2: the serial CSV byte for byte ($(($(wc -l <"$T/serial.csv") - 1)) points)"
else
    fail "mpirun -np 2: status $s1 and $s2, $(head -c 300 "$T/err2")"
fi
c1=$(crossings "$T/serial.json")
c2=$(crossings "$T/mpi.json")
if [ -n "$c1" ] && [ "$c1" = "$c2" ]; then
    pass "the same $(echo "$c1" | wc -l) crossings of the stability boundary"
else
    fail "crossings differ: serial '$c1', mpi '$c2'"
fi
[ "$(grep -c 'sweep: modes' "$T/out2")" -eq 1 ] &&
    pass "only process 0 prints" || fail "more than one process printed"

B="examples/kamman_ex1_above.yaml --analysis modes --vary speed=2:10:9 --vary turn_rate=0:0.1:7 --chain 1 --no-boundary --quiet"
"$TOWSTAB" sweep $B --jobs 1 --csv "$T/full.csv" >/dev/null 2>&1
"$TOWSTAB" sweep $B --jobs 1 --resume "$T/j.txt" >/dev/null 2>&1 &
pid=$!
for i in $(seq 1 400); do
    [ -f "$T/j.txt" ] && [ "$(wc -l <"$T/j.txt")" -ge 6 ] && break
    sleep 0.02
done
kill -9 $pid 2>/dev/null
wait $pid 2>/dev/null
mpi 3 "$TOWSTAB" sweep $B --resume "$T/j.txt" --csv "$T/r.csv" >"$T/out3" 2>"$T/err3"
s3=$?
if [ "$s3" -eq 0 ] && grep -q "chains restored" "$T/out3" &&
   cmp -s "$T/full.csv" "$T/r.csv"; then
    pass "begun serially, killed, finished under mpirun -np 3: the serial CSV ($(grep -o '[0-9]* of [0-9]* chains restored' "$T/out3"))"
else
    fail "resume under mpirun: status $s3, $(head -c 300 "$T/err3")"
fi

finish
