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
#  - the mode tables (printed, --csv, --shapes) in deg/s, mHz, min and
#    rad, the sea-state statistics and spectra CSV in ft, the vehicle
#    tables in rad, ft, lbf and lbf ft, and the excitation's input line in
#    ft, mHz and ms equal the SI output converted (to 1e-14 in CSV, to
#    the printed digits in tables);
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

# 3b. The mode tables, the sea state, the vehicles and the input line
# (issue 15): every number round trips against the SI run (CSV to 1e-14;
# printed tables to half a unit of their last digit: the pitch printed
# to 4 decimals in rad is within 2.9e-3 deg).
EX3=examples/kamman_ex3_turn.yaml
"$TOWSTAB" modes "$EX3" --csv "$T/m_si.csv" --shapes "$T/sh_si.csv" >"$T/m_si.out" 2>&1
ts modes "$EX3" --csv "$T/m_u.csv" --shapes "$T/sh_u.csv" --units "turn_rate=deg/s,frequency=mHz,time=min,angle=rad"
cp "$T/out" "$T/m_u.out"
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
[ "$(head -1 "$T/m_u.csv")" = "mode,re_per_s,im_deg_per_s,freq_mHz,period_min,damping_ratio,time_constant_min,condition,error_bound,description" ] ||
    why="$why header '$(head -1 "$T/m_u.csv")';"
# Columns 2..8 (re, im, freq, period, damping, time constant, condition).
m=$(cut -d, -f1-8 "$T/m_si.csv" >"$T/a.csv"; cut -d, -f1-8 "$T/m_u.csv" >"$T/b.csv"
    csv_ratio "$T/a.csv" "$T/b.csv" 1 0.017453292519943295 0.001 60 1 60 1)
awk -v m="$m" 'BEGIN { exit !(m <= 1e-14) }' || why="$why deviation $m;"
[ -z "$why" ] && pass "modes --csv --units deg/s, mHz, min: every number round trips to $m" ||
    fail "modes --csv with display units:$why"
why=""
[ "$(head -1 "$T/sh_u.csv")" = "mode,freq_mHz,node,x_amp,x_phase_rad,y_amp,y_phase_rad,z_amp,z_phase_rad" ] ||
    why="$why header '$(head -1 "$T/sh_u.csv")';"
# Columns freq (mHz), then the phases (rad, printed to 6 decimals: 1e-6).
m=$(paste -d, "$T/sh_si.csv" "$T/sh_u.csv" | awk -F, 'NR > 1 {
        d = $11 * 0.001 - $2; if (d < 0) d = -d; if ($2 != 0 && d / $2 > m) m = d / $2
        for (k = 5; k <= 9; k += 2) { e = $(k + 9) * 57.29577951308232 - $k
            if (e < 0) e = -e; if (e > p) p = e } }
        END { printf "%.3g %.3g", m + 0, p + 0 }')
awk -v m="${m% *}" -v p="${m#* }" 'BEGIN { exit !(m <= 1e-14 && p <= 1e-4) }' ||
    why="$why deviation $m;"
[ -z "$why" ] && pass "modes --shapes --units: frequency in mHz, phases in rad (deviation $m)" ||
    fail "modes --shapes with display units:$why"
# The printed table: mode 1's Im, frequency and period.
if awk 'NR == FNR { if ($1 == "1" && NF > 7) { im = $3; f = $4; p = $5 } next }
        $1 == "1" && NF > 7 { d1 = $3 - im * 57.29577951308232; d2 = $4 - 1000 * f; d3 = $5 * 60 - p
            ok = (d1 < 0 ? -d1 : d1) <= 1e-5 * (im < 0 ? -im : im) * 57.3 &&
                 (d2 < 0 ? -d2 : d2) <= 1e-5 * 1000 * f && (d3 < 0 ? -d3 : d3) <= 1e-5 * p }
        END { exit !ok }' "$T/m_si.out" "$T/m_u.out" &&
    grep -q 'Im \[deg/s\]' "$T/m_u.out" && grep -q 'freq \[mHz\]' "$T/m_u.out" &&
    grep -q 'period \[min\]' "$T/m_u.out"; then
    pass "modes printed: Im [deg/s], freq [mHz], period [min] equal the SI table converted"
else
    fail "modes printed in display units: $(grep -m1 '^ *1 ' "$T/m_u.out")"
fi

SEX=examples/survey_tow_sea.yaml
SEA=(--sea Hs=4m,Tp=8s,gamma=3.3,heading=180deg --intervals 64)
"$TOWSTAB" response "$SEX" --output fish.z "${SEA[@]}" --csv "$T/sea_si.csv" >"$T/sea_si.out" 2>&1
ts response "$SEX" --output fish.z "${SEA[@]}" --csv "$T/sea_u.csv" --units imperial
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -1 "$T/err");"
head -1 "$T/sea_u.csv" | grep -q '^omega_rad_s,omega_e_rad_s,wave_ft2_s_rad,.*,gain_re_ft_per_ft,gain_im_ft_per_ft,gain_abs_ft_per_ft,density_ft2_s_rad$' ||
    why="$why header '$(head -1 "$T/sea_u.csv")';"
# omega, omega_e, wave (ft^2), 6 RAO columns, 3 gains (ft/ft), density (ft^2).
F2=$(awk -v f=$FT 'BEGIN { printf "%.17g", f * f }')
m=$(csv_ratio "$T/sea_si.csv" "$T/sea_u.csv" 1 $F2 1 1 1 1 1 1 1 1 1 $F2)
awk -v m="$m" 'BEGIN { exit !(m <= 1e-14) }' || why="$why deviation $m;"
s_si=$(awk '/standard deviation sigma/ {print $4}' "$T/sea_si.out")
s_u=$(awk '/standard deviation sigma/ {print $4, $5}' "$T/out")
awk -v a="$s_si" -v b="${s_u% *}" -v u="${s_u#* }" -v f=$FT 'BEGIN {
    d = b * f - a; if (d < 0) d = -d; exit !(u == "ft" && d <= 1e-5 * a) }' ||
    why="$why sigma '$s_u' against $s_si m;"
[ -z "$why" ] && pass "response --sea --units imperial: sigma $s_u (SI $s_si m), the spectra CSV round trips to $m" ||
    fail "response --sea with display units:$why"

ts simulate "$EX4" --no-compare --t-end 1 --quiet --units "imperial,time=ms,frequency=mHz"
grep -q '^input: tow.heave sine amplitude 0.1 ft, frequency 250 mHz, phase 0 deg, smooth start over 8000 ms' "$T/out" &&
    pass "simulate: the input line in ft, mHz and ms: $(grep -m1 '^input:' "$T/out" | cut -c1-90)" ||
    fail "simulate: the input line: $(grep -m1 '^input:' "$T/out")"

AUR=examples/aurora_towfish.yaml
"$TOWSTAB" equilibrium "$AUR" >"$T/v_si.out" 2>&1
ts equilibrium "$AUR" --units "imperial,angle=rad"
if awk 'NR == FNR { if (v == "" && $1 == "vehicle") { v = 1; next } if (v == 1) { p = $2; z = $7; v = 2 } next }
        $1 == "vehicle" { w = 1; next } w == 1 { q = $2; y = $7; w = 2 }
        END { d = q * 57.29577951308232 - p; e = y * 0.3048 - z
              exit !((d < 0 ? -d : d) <= 3e-3 && (e < 0 ? -e : e) <= 1e-5 * (z < 0 ? -z : z) + 1e-6) }' \
        "$T/v_si.out" "$T/out" && grep -q 'pitch\[rad\]' "$T/out" && grep -q 'depth \[ft\]' "$T/out" &&
    grep -q 'Fx \[lbf\]' "$T/out" && grep -q 'Mx \[lbf ft\]' "$T/out"; then
    pass "vehicle tables: pitch in rad, depth in ft, loads in lbf and lbf ft, equal to SI converted"
else
    fail "vehicle tables in display units: $(grep -A1 '^vehicle' "$T/out" | tr '\n' '|')"
fi

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
