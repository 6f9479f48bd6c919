#!/bin/bash
# accuracy_cost.sh TOWSTAB [RUNS]: the whole-process CPU time of the
# discretisation error estimate (doc/performance.md, "The cost of the
# discretisation error"). Each command runs RUNS times (default 9) with the
# estimate (A) and without it (B), alternating A and B; the table gives the
# median CPU seconds (user + system) of each and their ratio. Run from the
# project root: `meson test -C build --benchmark accuracy_cost`.
set -eu
TOWSTAB=$1
RUNS=${2:-9}
# shellcheck source=paired_cpu.sh
. "$(dirname "$0")/paired_cpu.sh"

echo "runs $RUNS each, $(uptime | sed 's/.*load/load/')"
echo "| command | A cpu s | B cpu s | A/B cpu |"
echo "|---|---|---|---|"
ex1=examples/kamman_ex1_submerged.yaml
row "modes, ex. 1, 20 links" "" "--no-discretisation-error" \
    modes $ex1 --quiet --links 20
row "modes, ex. 1, 80 links" "" "--no-discretisation-error" \
    modes $ex1 --quiet --links 80
row "equilibrium, ex. 1, 200 links" "" "--no-discretisation-error" \
    equilibrium $ex1 --quiet --links 200
row "response, ex. 1, 20 links, sphere.z (100 frequencies)" "" \
    "--no-discretisation-error" response $ex1 --quiet --links 20 --output sphere.z
row "simulate, ex. 4, heave 0.1 ft at 1 Hz, 20 s" "--discretisation-error" "" \
    simulate examples/kamman_ex4.yaml --quiet --no-compare \
    --excite tow.heave:amplitude=0.1ft,frequency=1Hz --t-end 20 --transient 10
