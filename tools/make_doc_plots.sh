#!/bin/bash
# tools/make_doc_plots.sh: regenerate the pictures of doc/plots.md into
# doc/img/ (PNG only, each under 150 kB).
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
T=$(mktemp -d "${TMPDIR:-/tmp}/towstab-docplots-XXXXXX")
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
