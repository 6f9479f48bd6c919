#!/bin/bash
# test/cli/units.sh: --units as a user runs it (suite 'cli').
#
#   units.sh TOWSTAB
#
# Run from the project root (meson does). Checks, against the exact
# definitions 1 ft = 0.3048 m and 1 lbf = 4.4482216152605 N:
#  - round trips: every number of `equilibrium --csv` with --units
#    imperial (x_ft, ..., tension_above_lbf) times its factor equals the SI
#    file's to 1e-14 relative (rounding of one multiplication); the same
#    for "force=kN,length=cm" (columns x_cm, tension_above_kN);
#  - the printed tables: the top tension line and the body table in lbf
#    and ft equal the SI ones converted (to their printed digits);
#  - simulate --csv --units imperial: columns t_s, sphere.z_ft,
#    tow.force_lbf, values round trip; response --csv on a tension:
#    magnitude_lbf_per_ft; converge --csv: sphere.z_ft;
#  - JSON stays SI whatever --units: the same numbers, and "units" names
#    them;
#  - `towstab run --units imperial` without --plot prints in lbf;
#  - bad specifications exit 2 naming --units and write nothing.
# Prints one PASS/FAIL line per check and "N passed, N failed".
set -u
if [ $# -ne 1 ]; then
    echo "usage: units.sh TOWSTAB" >&2
    exit 2
fi
TOWSTAB=$1
. "$(dirname "$0")/common.sh"
EX1=examples/kamman_ex1_submerged.yaml
EX4=examples/kamman_ex4.yaml
FT=0.3048
LBF=4.4482216152605

# csv_ratio A B F1 F2 ...: the largest relative difference between the
# numbers of CSV files A (SI) and B (shown), column k of B times Fk.
csv_ratio() {
    local a=$1 b=$2
    shift 2
    paste -d, "$a" "$b" | awk -F, -v f="$*" '
        BEGIN { nf = split(f, fac, " ") }
        NR > 1 { n = NF / 2
            for (k = 2; k <= n; k++) {
                want = $k; got = $(k + n) * fac[k - 1]
                d = got - want; if (d < 0) d = -d
                s = want; if (s < 0) s = -s
                if (s > 0 && d / s > m) m = d / s
                if (s == 0 && d > m) m = d } }
        END { printf "%.3g", m + 0 }'
}

# 1. Equilibrium CSV round trips.
"$TOWSTAB" equilibrium "$EX1" --quiet --csv "$T/si.csv" >"$T/si.out" 2>&1
ts equilibrium "$EX1" --quiet --csv "$T/imp.csv" --units imperial
cp "$T/out" "$T/imp.out"
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
[ "$(head -1 "$T/imp.csv")" = "node,x_ft,y_ft,z_ft,tension_above_lbf" ] ||
    why="$why header '$(head -1 "$T/imp.csv")';"
m=$(csv_ratio "$T/si.csv" "$T/imp.csv" $FT $FT $FT $LBF)
awk -v m="$m" 'BEGIN { exit !(m <= 1e-14) }' || why="$why deviation $m;"
[ -z "$why" ] && pass "equilibrium --csv --units imperial: ft and lbf, every number round trips to $m" ||
    fail "equilibrium --csv --units imperial:$why"
ts equilibrium "$EX1" --quiet --csv "$T/kn.csv" --units "force=kN,length=cm"
why=""
[ "$(head -1 "$T/kn.csv")" = "node,x_cm,y_cm,z_cm,tension_above_kN" ] ||
    why="$why header '$(head -1 "$T/kn.csv")';"
m=$(csv_ratio "$T/si.csv" "$T/kn.csv" 0.01 0.01 0.01 1000)
awk -v m="$m" 'BEGIN { exit !(m <= 1e-14) }' || why="$why deviation $m;"
[ -z "$why" ] && pass "--units force=kN,length=cm: cm and kN, round trip $m" ||
    fail "--units force=kN,length=cm:$why"

# 2. The printed tables.
t_si=$(awk '/^top tension/ {print $3}' "$T/si.out")
t_imp=$(awk '/^top tension/ {print $3, $4}' "$T/imp.out")
z_si=$(awk '$1 == "sphere" {print $4}' "$T/si.out")
z_imp=$(awk '$1 == "sphere" {print $4}' "$T/imp.out")
if awk -v a="$t_si" -v b="${t_imp% *}" -v u="${t_imp#* }" -v z="$z_si" -v w="$z_imp" -v l=$LBF -v f=$FT '
    BEGIN { d = b * l - a; if (d < 0) d = -d; e = w * f - z; if (e < 0) e = -e
            exit !(u == "lbf" && d <= 1e-6 * l && e <= 1e-6 * f) }'; then
    pass "printed: top tension $t_imp (SI $t_si N), sphere depth $z_imp ft (SI $z_si m)"
else
    fail "printed: top tension '$t_imp' against $t_si N, depth '$z_imp' against $z_si m"
fi

# 3. A simulation, a response and a study in imperial CSV.
"$TOWSTAB" simulate "$EX4" --no-compare --t-end 4 --csv "$T/s_si.csv" --quiet >/dev/null 2>&1
ts simulate "$EX4" --no-compare --t-end 4 --csv "$T/s_imp.csv" --quiet --units imperial
why=""
[ "$(head -1 "$T/s_imp.csv")" = "t_s,sphere.x_ft,sphere.y_ft,sphere.z_ft,tow.force_lbf" ] ||
    why="$why header '$(head -1 "$T/s_imp.csv")';"
m=$(csv_ratio "$T/s_si.csv" "$T/s_imp.csv" $FT $FT $FT $LBF)
awk -v m="$m" 'BEGIN { exit !(m <= 1e-14) }' || why="$why deviation $m;"
[ -z "$why" ] && pass "simulate --csv --units imperial: round trip $m" ||
    fail "simulate --csv --units imperial:$why"
ts response "$EX1" --output cable.1.tension --points 5 --csv "$T/r.csv" --quiet --units imperial
head -1 "$T/r.csv" | grep -q '^freq_hz,magnitude_lbf_per_ft,phase_deg,re_lbf_per_ft,im_lbf_per_ft$' &&
    grep -q 'static gain .*' "$T/out" && grep -q '(lbf/ft)' "$T/out" &&
    pass "response --units imperial: the gain in lbf/ft" ||
    fail "response --units imperial: header '$(head -1 "$T/r.csv")'"
ts converge "$EX1" --links 5,10 --csv "$T/c.csv" --quiet --units imperial
head -1 "$T/c.csv" | grep -q ',sphere.z_ft,sphere.z_ft_error,top_tension_lbf,' &&
    pass "converge --units imperial: sphere.z_ft, top_tension_lbf" ||
    fail "converge --units imperial: header '$(head -1 "$T/c.csv")'"

# 4. JSON stays SI, with its units named.
"$TOWSTAB" equilibrium "$EX1" --quiet --json "$T/a.json" >/dev/null 2>&1
"$TOWSTAB" equilibrium "$EX1" --quiet --json "$T/b.json" --units imperial >/dev/null 2>&1
a=$(grep -o '"top_tension": [-0-9.eE+]*' "$T/a.json")
b=$(grep -o '"top_tension": [-0-9.eE+]*' "$T/b.json")
if [ -n "$a" ] && [ "$a" = "$b" ] && grep -q '"length": "m"' "$T/b.json" &&
    grep -q '"force": "N"' "$T/b.json"; then
    pass "JSON with --units imperial: the same SI numbers ($a), units named"
else
    fail "JSON with --units imperial: '$a' against '$b'"
fi

# 5. towstab run prints in the units asked for, without --plot.
ts run "$EX1" --quiet --units imperial
grep -q '^top tension [0-9.]* lbf' "$T/out" && [ "$status" -eq 0 ] &&
    pass "run --units imperial without --plot: $(grep '^top tension' "$T/out" | cut -c1-40)" ||
    fail "run --units imperial: exit $status, $(grep '^top tension' "$T/out")"

# 6. Bad specifications.
for spec in furlong "weight=kg" "force=kg" "length=" "si,"; do
    fresh
    ts equilibrium "$EX1" --units "$spec" --csv "$T/o/x.csv" --plot "$T/o/p"
    if [ "$status" -eq 2 ] && grep -q -- "--units" "$T/err" && [ -z "$(ls -A "$T/o")" ]; then
        pass "--units '$spec': exit 2: $(head -1 "$T/err" | cut -c1-100)"
    else
        fail "--units '$spec': exit $status, left $(ls "$T/o"): $(head -1 "$T/err")"
    fi
done

finish
