#!/bin/bash
# startup_cost.sh TOWSTAB PLOT_MODULE [RUNS]: what loading PLplot costs a
# run that draws nothing (doc/performance.md, "Start-up"). Each command
# runs RUNS times (default 31) as it is (A) and with the drawing module
# preloaded (B: LD_PRELOAD=PLOT_MODULE, which loads PLplot, cairo, pango,
# fontconfig and the rest, as every run did when the library linked
# PLplot), alternating A and B; the table gives the median CPU seconds
# (user + system) of each and their ratio. Both run through env(1), so
# that they differ only in the variable. Run from the project root:
# `meson test -C build --benchmark startup_cost`.
set -eu
TOWSTAB=$1
MODULE=$2
RUNS=${3:-31}
# shellcheck source=paired_cpu.sh
. "$(dirname "$0")/paired_cpu.sh"

# row LABEL ARGS...: A without, B with the module preloaded.
row_preload() {
    local label=$1
    shift
    ta=() tb=()
    for ((i = 0; i < RUNS; i++)); do
        ta+=("$(cpu env "$TOWSTAB" "$@")")
        tb+=("$(cpu env LD_PRELOAD="$MODULE" "$TOWSTAB" "$@")")
    done
    DIGITS=4 row_of "$label"
}

[ -f "$MODULE" ] || { echo "no drawing module $MODULE (a build without PLplot)"; exit 0; }
echo "runs $RUNS each, $(uptime | sed 's/.*load/load/')"
echo "| command | A cpu s | B cpu s (PLplot preloaded) | A/B cpu |"
echo "|---|---|---|---|"
row_preload "towstab --version" --version
row_preload "equilibrium, ex. 1, 20 links" \
    equilibrium examples/kamman_ex1_submerged.yaml --links 20 --quiet
