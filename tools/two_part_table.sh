#!/bin/sh
# two_part_table.sh: the two-part tow's heave ratio against cable diameter,
# with and without bending stiffness (Lalu & Narayanan, Fig. 11;
# doc/two-part-tow.md).
#
#   tools/two_part_table.sh [TOWSTAB] [DIAMETERS_MM] [JOBS]
#
# TOWSTAB: the towstab binary (default build/tools/towstab); DIAMETERS_MM:
# space-separated cable diameters in mm (default "2 4 6 8 9.78 12 16");
# JOBS: runs in parallel (default 2). Run from the project root. Prints a
# Markdown table on stdout; the scenes and JSON summaries are kept in a
# temporary directory (named on stderr).
#
# Scaling with the diameter d (d0 = 9.78 mm, the example's): every cable's
# mass per length 0.181 (d/d0)^2 kg/m, EA 4.5e6 (d/d0)^2 N, internal
# damping 50 (d/d0)^2 N s/m (the same fraction of critical on the axial
# modes, whose frequencies then do not depend on d), EI = E_eff pi d^4/64
# with the example's effective modulus E_eff = 2e10 Pa (9.1 N m^2 at d0),
# or no bending. Depressor and towfish unchanged. Each run: the slider
# crank r = 0.1 m, rod 0.35 m, period 1.6 s, 40 s, rk8pd; heave ratios
# over t = 20..40 s.
set -eu
TOWSTAB=${1:-build/tools/towstab}
DIAMS=${2:-"2 4 6 8 9.78 12 16"}
JOBS=${3:-2}
SCENE=examples/two_part_tow.yaml
[ -x "$TOWSTAB" ] || { echo "two_part_table.sh: no towstab at $TOWSTAB" >&2; exit 2; }
[ -r "$SCENE" ] || { echo "two_part_table.sh: run from the project root ($SCENE)" >&2; exit 2; }
DIR=$(mktemp -d)
echo "two_part_table.sh: work in $DIR" >&2

for d in $DIAMS; do
    for b in bending none; do
        awk -v d="$d" -v b="$b" '
            BEGIN { s = d / 9.78; s2 = s * s
                    ei = 2e10 * 3.141592653589793 * (d * 1e-3)^4 / 64 }
            /^    diameter: "9.78 mm"/ { printf "    diameter: \"%s mm\"\n", d; next }
            /^    mass_per_length: "0.181 kg\/m"/ {
                printf "    mass_per_length: \"%.6g kg/m\"\n", 0.181 * s2; next }
            /^    EA: "4.5e6 N"/ { printf "    EA: \"%.6g N\"\n", 4.5e6 * s2; next }
            /^    damping: "50 N\*s\/m"/ { printf "    damping: \"%.6g N*s/m\"\n", 50 * s2; next }
            /^    EI: "9.1 N\*m\^2"/ { if (b == "bending") printf "    EI: \"%.6g N*m^2\"\n", ei; next }
            { print }' "$SCENE" > "$DIR/d${d}_$b.yaml"
        echo "$d $b"
    done
done | xargs -P "$JOBS" -n 2 sh -c '
    "$0" simulate "$1/d$2_$3.yaml" --excite "tow.heave:type=crank,amplitude=0.1m,rod=0.35m,period=1.6s" \
        --t-end 40 --transient 20 --output towfish.z --compare --quiet \
        --json "$1/d$2_$3.json" > "$1/d$2_$3.log" 2>&1 ||
        echo "two_part_table.sh: run d = $2 mm ($3) failed: see $1/d$2_$3.log" >&2
' "$TOWSTAB" "$DIR"

python3 - "$DIR" $DIAMS <<'EOF'
import json, sys
d = sys.argv[1]
print("| d [mm] | EI [N m^2] | fundamental, with EI | p-p, with EI | fundamental, no EI | p-p, no EI | linear response, with EI | no EI | (with - without) / without |")
print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
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
    ei = 2e10 * 3.141592653589793 * (float(dm) * 1e-3) ** 4 / 64
    wb, nb = row["bending"], row["none"]
    print(f"| {dm} | {ei:.3g} | {wb[0]:.4f} | {wb[1]:.4f} | {nb[0]:.4f} | {nb[1]:.4f} | "
          f"{wb[2]:.4f} | {nb[2]:.4f} | {100 * (wb[0] - nb[0]) / nb[0]:+.1f} % |")
EOF
