#!/bin/bash
# startup_cost.sh TOWSTAB PLOT_MODULE SUNDIALS_MODULE [RUNS]: what loading
# PLplot, or SUNDIALS, costs a run that uses neither (doc/performance.md,
# "Start-up"). Each command runs RUNS times (default 31) as it is (A) and
# with a module preloaded (B: LD_PRELOAD=MODULE, which loads what the
# module links, as every run did when the library linked it: for the
# drawing module PLplot and its eleven libraries; for the SUNDIALS module
# ARKODE and CVODE), alternating A and B; the table gives
# the median CPU seconds (user + system) of each and their ratio. Both run
# through env(1), so that they differ only in the variable. A module given
# as "none" (a build without PLplot) is left out. Run from the project
# root: `meson test -C build --benchmark startup_cost`.
set -eu
TOWSTAB=$1
PLOT=$2
SUNDIALS=$3
RUNS=${4:-31}
# shellcheck source=paired_cpu.sh
. "$(dirname "$0")/paired_cpu.sh"

# row_preload LABEL MODULE ARGS...: A without, B with MODULE preloaded.
row_preload() {
    local label=$1 module=$2
    shift 2
    ta=() tb=()
    for ((i = 0; i < RUNS; i++)); do
        ta+=("$(cpu env "$TOWSTAB" "$@")")
        tb+=("$(cpu env LD_PRELOAD="$module" "$TOWSTAB" "$@")")
    done
    DIGITS=4 row_of "$label"
}

eq=(equilibrium examples/kamman_ex1_submerged.yaml --links 20 --quiet)
echo "runs $RUNS each, $(uptime | sed 's/.*load/load/')"
echo "| command, B preloading | A cpu s | B cpu s | A/B cpu |"
echo "|---|---|---|---|"
for m in "$PLOT" "$SUNDIALS"; do
    [ "$m" = none ] && continue
    name=$(basename "$m")
    row_preload "towstab --version, $name" "$m" --version
    row_preload "equilibrium, ex. 1, 20 links, $name" "$m" "${eq[@]}"
done
