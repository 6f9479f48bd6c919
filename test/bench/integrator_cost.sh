#!/bin/bash
# integrator_cost.sh TOWSTAB [RUNS]: the whole-process CPU time of the
# elastic heave with esdirk (A) against bdf (B) at 100 and 500 links
# (doc/performance.md, "bdf"). Each command runs RUNS times (default 5),
# alternating A and B; the table gives the median CPU seconds of each and
# their ratio. Run from the project root:
# `meson test -C build --benchmark integrator_cost`.
set -eu
TOWSTAB=$1
RUNS=${2:-5}
# shellcheck source=paired_cpu.sh
. "$(dirname "$0")/paired_cpu.sh"

echo "runs $RUNS each, $(uptime | sed 's/.*load/load/')"
echo "| command | esdirk cpu s | bdf cpu s | esdirk/bdf cpu |"
echo "|---|---|---|---|"
for n in 100 500; do
    row "heave 0.1 ft at 0.25 Hz, 2 s, $n links" \
        "--integrator esdirk" "--integrator bdf" \
        simulate examples/kamman_ex1_elastic.yaml \
        --excite tow.heave:amplitude=0.1ft,frequency=0.25Hz --t-end 2 \
        --sample 0.1 --rtol 1e-6 --atol 1e-9 --no-discretisation-error \
        --no-compare --quiet --links $n
done
