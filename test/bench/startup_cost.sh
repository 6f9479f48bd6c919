#!/bin/bash
# startup_cost.sh TOWSTAB PLOT_MODULE SUNDIALS_MODULE PAIRS EMPTY
#     EMPTY_ARPACK EMPTY_UDUNITS [RUNS]:
# what start-up costs a run, to the microsecond (doc/performance.md,
# "Start-up"). Every row is PAIRS (test/bench/startup_pairs.c) running A
# and B alternately RUNS times each (default 101) and giving the median
# CPU (user + system, wait4's accounting of each finished process) of
# each and the median and quartiles of the pair-by-pair ratio A/B:
#  - the same command as A and B: the scatter of the bench itself;
#  - towstab as it is (A) and with a module preloaded (B: LD_PRELOAD,
#    which loads what the module links, as every run did when the library
#    linked it): what PLplot, or SUNDIALS, would cost a run that uses
#    neither; both run through env(1), so that they differ only in the
#    variable. A module given as "none" (a build without PLplot) is left
#    out;
#  - EMPTY, a program doing nothing linked to LAPACK and BLAS, against
#    EMPTY_ARPACK, the same linked to ARPACK as well; EMPTY_UDUNITS, linked
#    to udunits2 too, reading its XML database and not reading it
#    (startup_empty.c); and EMPTY against /bin/true (a process and the C
#    library).
# Run from the project root: `meson test -C build --benchmark startup_cost`.
set -eu
TOWSTAB=$1
PLOT=$2
SUNDIALS=$3
PAIRS=$4
EMPTY=$5
EMPTY_ARPACK=$6
EMPTY_UDUNITS=$7
RUNS=${8:-101}
# towstab runs OpenBLAS on one thread unless told otherwise (doc/manual.md,
# "Threads"); the empty programs are told so, for a like comparison.
export OPENBLAS_NUM_THREADS=1

eq=(equilibrium examples/kamman_ex1_submerged.yaml --links 20 --quiet
    --no-discretisation-error)
echo "runs $RUNS pairs each, $(date -u '+%Y-%m-%d %H:%M UTC'), $(uptime | sed 's/.*load/load/')"
echo "| A / B | A cpu ms | B cpu ms | A/B cpu, median (quartiles) |"
echo "|---|---:|---:|---:|"
"$PAIRS" "$RUNS" "towstab --version / itself (the bench's scatter)" \
    "$TOWSTAB" --version -- "$TOWSTAB" --version
"$PAIRS" "$RUNS" "equilibrium, ex. 1, 20 links / towstab --version" \
    "$TOWSTAB" "${eq[@]}" -- "$TOWSTAB" --version
for m in "$PLOT" "$SUNDIALS"; do
    [ "$m" = none ] && continue
    name=$(basename "$m")
    "$PAIRS" "$RUNS" "towstab --version / the same preloading $name" \
        env "$TOWSTAB" --version -- env LD_PRELOAD="$m" "$TOWSTAB" --version
    "$PAIRS" "$RUNS" "equilibrium / the same preloading $name" \
        env "$TOWSTAB" "${eq[@]}" -- env LD_PRELOAD="$m" "$TOWSTAB" "${eq[@]}"
done
"$PAIRS" "$RUNS" "empty program with LAPACK, BLAS / the same with ARPACK" \
    "$EMPTY" -- "$EMPTY_ARPACK"
"$PAIRS" "$RUNS" "empty program with udunits2 reading its XML database / not reading it" \
    "$EMPTY_UDUNITS" read -- "$EMPTY_UDUNITS"
"$PAIRS" "$RUNS" "empty program with LAPACK, BLAS / /bin/true" \
    "$EMPTY" -- /bin/true
