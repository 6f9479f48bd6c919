#!/bin/sh
# two_part_table.sh: the two-part tow's heave ratio against cable diameter,
# with and without bending stiffness (Lalu & Narayanan, Fig. 11;
# doc/two-part-tow.md).
#
#   tools/two_part_table.sh [TOWSTAB] [DIAMETERS_MM] [JOBS]
#
# TOWSTAB: the towstab binary (default build/tools/towstab); DIAMETERS_MM:
# space-separated diameters of the primary cable in mm (default
# "2 4 6 8 9.78 12 16"); JOBS: runs in parallel (default 2). Run from the
# project root. Prints a Markdown table on stdout; the scenes and JSON
# summaries are kept in a temporary directory (named on stderr).
#
# Scaling: the three cables of examples/two_part_tow.yaml have different
# diameters (primary d0 = 9.78 mm, depressor cable 5.46 mm, secondary
# 8.56 mm). For a primary diameter d every cable's diameter is multiplied
# by s = d / d0, so they keep their proportions and s = 1 is the example
# itself; each cable's mass per length, EA and internal damping are
# multiplied by s^2 (the same metallic fraction of the section; damping
# in proportion to EA and mass keeps the same fraction of critical on the
# axial modes, whose frequencies then do not depend on d); EI by s^4 (the
# example's EI are E_eff pi d_i^4 / 64 with an effective modulus E_eff =
# 2e10 Pa, so they stay that), or no bending. Every cable must have an EI
# line after its diameter. Lengths, links, depressor and towfish unchanged. Each run: the
# slider crank r = 0.1 m, rod 0.35 m, period 1.6 s, 40 s; integrator
# esdirk at rtol 1e-5, atol 1e-6 (on the example it gives rk8pd's heave
# ratios to 4 significant figures: doc/two-part-tow.md, "Integrator");
# heave ratios over t = 20..40 s.
set -eu
TOWSTAB=${1:-build/tools/towstab}
DIAMS=${2:-"2 4 6 8 9.78 12 16"}
JOBS=${3:-2}
SCENE=examples/two_part_tow.yaml
[ -x "$TOWSTAB" ] || { echo "two_part_table.sh: no towstab at $TOWSTAB" >&2; exit 2; }
[ -r "$SCENE" ] || { echo "two_part_table.sh: run from the project root ($SCENE)" >&2; exit 2; }
# d0: the primary (first) cable's diameter in mm.
D0=$(awk '/^cables:/ { c = 1; next }
          c && /^    diameter: "[0-9.]+ mm"$/ { gsub(/[^0-9.]/, "", $2); print $2; exit }' "$SCENE")
[ -n "$D0" ] || { echo "two_part_table.sh: $SCENE: no primary cable diameter in mm" >&2; exit 2; }
DIR=$(mktemp -d)
echo "two_part_table.sh: work in $DIR" >&2

# One scene per (d, bending|none), and d<d>_<b>.cables: the cables'
# diameters [mm] and EI [N m^2] (0: none), in the scene's order.
for d in $DIAMS; do
    for b in bending none; do
        awk -v d="$d" -v d0="$D0" -v b="$b" -v side="$DIR/d${d}_$b.cables" '
            function num(s) { gsub(/^"|"$/, "", s); return s + 0 }
            BEGIN { s = d / d0; s2 = s * s }
            /^[a-z]/ { incab = ($0 ~ /^cables:/) }
            incab && /^    diameter: / {
                if ($3 != "mm\"") { print "cable diameter not in mm: " $0 > "/dev/stderr"; exit 2 }
                dc = num($2) * s
                printf "    diameter: \"%.6g mm\"\n", dc; next }
            incab && /^    mass_per_length: / {
                printf "    mass_per_length: \"%.6g kg/m\"\n", num($2) * s2; next }
            incab && /^    EA: / { printf "    EA: \"%.6g N\"\n", num($2) * s2; next }
            incab && /^    damping: / { printf "    damping: \"%.6g N*s/m\"\n", num($2) * s2; next }
            incab && /^    EI: / {
                ei = (b == "bending") ? num($2) * s2 * s2 : 0
                printf "%.6g %.6g\n", dc, ei >> side
                if (b == "bending") printf "    EI: \"%.6g N*m^2\"\n", ei
                next }
            { print }' "$SCENE" > "$DIR/d${d}_$b.yaml"
        echo "$d $b"
    done
done | xargs -P "$JOBS" -n 2 sh -c '
    "$0" simulate "$1/d$2_$3.yaml" --excite "tow.heave:type=crank,amplitude=0.1m,rod=0.35m,period=1.6s" \
        --t-end 40 --transient 20 --output towfish.z --compare --quiet \
        --integrator esdirk --rtol 1e-5 --atol 1e-6 \
        --json "$1/d$2_$3.json" > "$1/d$2_$3.log" 2>&1 ||
        echo "two_part_table.sh: run d = $2 mm ($3) failed: see $1/d$2_$3.log" >&2
' "$TOWSTAB" "$DIR"

python3 - "$DIR" $DIAMS <<'EOF'
import json, sys
d = sys.argv[1]
print("| d [mm]: primary, depressor cable, secondary | EI [N m^2]: same | fundamental, with EI | p-p, with EI | fundamental, no EI | p-p, no EI | linear response, with EI | linear, no EI | (with - without) / without |")
print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
for dm in sys.argv[2:]:
    row = {}
    for b in ("bending", "none"):
        try:
            j = json.load(open(f"{d}/d{dm}_{b}.json"))
            c = j["compare"]
            row[b] = (c["nonlinear"]["amplitude_ratio"],
                      c["nonlinear"]["half_range"] / c["excitation"]["amplitude"],
                      c["response_prediction"]["amplitude_ratio"])
        except Exception:
            row[b] = (float("nan"),) * 3
    cables = [line.split() for line in open(f"{d}/d{dm}_bending.cables")]
    ds = ", ".join(f"{float(c[0]):.3g}" for c in cables)
    eis = ", ".join(f"{float(c[1]):.3g}" for c in cables)
    wb, nb = row["bending"], row["none"]
    print(f"| {ds} | {eis} | {wb[0]:.4f} | {wb[1]:.4f} | {nb[0]:.4f} | {nb[1]:.4f} | "
          f"{wb[2]:.4f} | {nb[2]:.4f} | {100 * (wb[0] - nb[0]) / nb[0]:+.1f} % |")
EOF
