#!/bin/bash
# tools/make_doc_plots.sh: regenerate the pictures of doc/plots.md and
# doc/sweep.md and doc/design.md into doc/img/ (PNG only, each under
# 150 kB).
#
#   tools/make_doc_plots.sh [TOWSTAB]
#
# TOWSTAB is the built tool (default: build/tools/towstab), built with
# PLplot (meson option plot, on by default when libplplot-dev and
# plplot-driver-cairo are installed). Runs from any directory; the scenes
# are the repository's examples/.
set -eu

ROOT=$(cd "$(dirname "$0")/.." && pwd)
TOWSTAB=${1:-$ROOT/build/tools/towstab}
if [ ! -x "$TOWSTAB" ]; then
    echo "make_doc_plots.sh: no towstab at '$TOWSTAB' (build it, or pass its path)" >&2
    exit 2
fi
OUT=$ROOT/doc/img
MAX_BYTES=153600
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
mkdir -p "$OUT"
cd "$ROOT"

# run NAME ARGS...: towstab equilibrium ARGS --plot $T/NAME, then copy the
# side and top PNGs to doc/img/NAME_side.png and NAME_top.png.
run() {
    local name=$1
    shift
    "$TOWSTAB" equilibrium "$@" --quiet --plot "$T/$name" >"$T/$name.log"
    for view in side top; do
        install -m 0644 "$T/$name/$view.png" "$OUT/${name}_$view.png"
        local size
        size=$(stat -c %s "$OUT/${name}_$view.png")
        if [ "$size" -gt $MAX_BYTES ]; then
            echo "make_doc_plots.sh: $OUT/${name}_$view.png is $size bytes (> $MAX_BYTES)" >&2
            exit 1
        fi
        echo "doc/img/${name}_$view.png ($size bytes)"
    done
}

# Memo Figs. 7-8: example 1, tow point 35 ft above the water and at the
# surface, overlaid (the memo's units: ft, knot).
run equilibrium_ex1 examples/kamman_ex1_above.yaml \
    --overlay examples/kamman_ex1_submerged.yaml --units imperial
# Example 2: the branched cable in straight tow and in the 0.5 rad/s turn.
run equilibrium_ex2 examples/kamman_ex2_branched_turn.yaml \
    --overlay-turn-rates "0.5 rad/s" --units imperial
# Example 1 at several speeds, SI units.
run equilibrium_speeds examples/kamman_ex1_above.yaml \
    --speed "3 knot" --overlay-speeds "5,8 knot"

# pic NAME PICTURE COMMAND ARGS...: towstab COMMAND ARGS --plot $T/NAME,
# then copy $T/NAME/PICTURE.png to doc/img/NAME.png.
pic() {
    local name=$1 picture=$2
    shift 2
    "$TOWSTAB" "$@" --quiet --plot "$T/$name" >"$T/$name.log"
    install -m 0644 "$T/$name/$picture.png" "$OUT/$name.png"
    local size
    size=$(stat -c %s "$OUT/$name.png")
    if [ "$size" -gt $MAX_BYTES ]; then
        echo "make_doc_plots.sh: $OUT/$name.png is $size bytes (> $MAX_BYTES)" >&2
        exit 1
    fi
    echo "doc/img/$name.png ($size bytes)"
}

# Modes of example 3 in its 0.5 rad/s turn: the eigenvalue plane, resolved
# and unresolved modes apart, and the shapes of the lowest resolved
# oscillatory modes (three resolved to 1 %; four would exceed 150 kB).
pic modes_ex3_eigenvalues eigenvalues modes examples/kamman_ex3_turn.yaml
pic modes_ex3_shapes modes modes examples/kamman_ex3_turn.yaml --accuracy 0.01 --oscillatory --count 3
# Frequency response of example 1's sphere depth to tow-point heave (ft/ft).
pic response_ex1_bode bode response examples/kamman_ex1_above.yaml \
    --output sphere.z --units imperial
# Example 4, tow point heaved 0.1 ft at 1 Hz: linear (dashed) against
# nonlinear (solid) over 20 s.
pic simulate_ex4_histories histories simulate examples/kamman_ex4.yaml \
    --excite tow.heave:amplitude=0.1ft,frequency=1Hz --compare \
    --t-end 20 --transient 10 --units imperial
# Example 5, the drop test: the cable every 3 s (memo Fig. 11).
pic simulate_ex5_snapshots snapshots_side simulate \
    examples/kamman_ex5_drop.yaml --snapshot-interval 3s --units imperial
# Example 1 (submerged tow point), 5 to 320 links: error against run time
# (memo Fig. 12).
pic converge_ex1_error_time error_time converge \
    examples/kamman_ex1_submerged.yaml --links 5,10,20,40,80,160,320
# Operating envelope of example 1 with the tow point 35 ft above the water
# (doc/sweep.md): modes over speed and turn rate, the sphere's depth and
# the stability margin with the bisected boundary; and speed alone.
pic sweep_ex1_max_real map_max_real sweep examples/kamman_ex1_above.yaml \
    --analysis modes --vary speed=2:10:17 --vary "turn_rate=0:6 deg/s:7"
pic sweep_ex1_depth map_sphere_z sweep examples/kamman_ex1_above.yaml \
    --analysis modes --vary speed=2:10:17 --vary "turn_rate=0:6 deg/s:7"
pic sweep_ex1_speed sweep sweep examples/kamman_ex1_above.yaml \
    --analysis modes --vary speed=2:10:17
# The sphere's depth and the top tension of example 1 against the cable
# length (doc/design.md: the design for 15 m lands on this curve).
pic design_ex1_length sweep sweep examples/kamman_ex1_submerged.yaml \
    --vary cables.cable.length=10:60:26 --output sphere.z,top_tension
# The two-part tow: depressor sphere and cylinder towfish.
pic equilibrium_two_part_side side equilibrium examples/two_part_tow.yaml
# A 0.1 rad/s turn begun over 5 s, in the earth frame.
pic simulate_manoeuvre_plan plan_earth simulate \
    examples/kamman_ex1_submerged.yaml \
    --manoeuvre turn_rate:to=0.1rad/s,duration=5s --t-end 40
