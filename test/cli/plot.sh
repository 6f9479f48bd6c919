#!/bin/bash
# test/cli/plot.sh: `towstab equilibrium|modes|response|simulate|converge
# --plot DIR` as a user runs them.
#
#   plot.sh TOWSTAB yes|no     (yes: towstab was built with PLplot)
#
# Run from the project root (meson does, suite 'cli').
# yes: --plot DIR writes side.png, side.svg, top.png, top.svg (PNG
#   signature, 1000 x 700 px from the IHDR chunk, > 5 kB; SVG starting
#   with <?xml and carrying the title naming the scene); a missing DIR is
#   created; --units imperial works (legends show the speeds as written);
#   overlays of speeds, turn rates and
#   scenes add curves (one "overlay" line each); --plot into a path that
#   is a file, a bad --units, overlays without --plot, an
#   overlay with a bad unit or a missing scene are refused with exit
#   status 2 before anything is solved, and leave no picture. modes and
#   response write their pictures; simulate writes histories,
#   snapshots_side and snapshots_top (PNG and SVG, titled, six files),
#   with --snapshot-interval in the title; converge writes error_time;
#   simulate and converge refuse --plot into a file (exit 2, nothing run),
#   --snapshot-interval without --plot or giving too many snapshots;
#   --units without --plot sets the tables (test/cli/units.sh). A run
#   without --plot loads neither the drawing module nor PLplot (LD_DEBUG),
#   one with it both; a drawing module that is missing, not a shared
#   object, or another library (TOWSTAB_PLOT_MODULE) makes --plot fail
#   with exit status 2, the file and the reason named, before anything is
#   solved or written.
# no: --plot is refused with exit status 2 and the message naming the
#   packages to install, while the analysis without --plot still runs.
#
# Prints one PASS/FAIL line per check and "N passed, N failed"; the exit
# status is 0 only when nothing failed.
set -u

if [ $# -ne 2 ]; then
    echo "usage: plot.sh TOWSTAB yes|no" >&2
    exit 2
fi
TOWSTAB=$1
HAVE=$2
T=$(mktemp -d "${TMPDIR:-/tmp}/towstab-plot-XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT

npass=0
nfail=0
pass() { echo "PASS $*"; npass=$((npass + 1)); }
fail() { echo "FAIL $*"; nfail=$((nfail + 1)); }
check() { # check DESCRIPTION COMMAND...
    local what=$1
    shift
    if "$@"; then pass "$what"; else fail "$what"; fi
}

ts() {
    "$TOWSTAB" "$@" >"$T/out" 2>"$T/err"
    status=$?
}

EX1=examples/kamman_ex1_above.yaml
EX1S=examples/kamman_ex1_submerged.yaml
EX2=examples/kamman_ex2_branched_turn.yaml

# is_png FILE W H: signature, IHDR size, more than 5000 bytes.
is_png() {
    local sig size w h
    sig=$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')
    [ "$sig" = "89504e470d0a1a0a" ] || return 1
    w=$((16#$(od -An -tx1 -j16 -N4 "$1" | tr -d ' \n')))
    h=$((16#$(od -An -tx1 -j20 -N4 "$1" | tr -d ' \n')))
    [ "$w" -eq "$2" ] && [ "$h" -eq "$3" ] || return 1
    size=$(stat -c %s "$1")
    [ "$size" -gt 5000 ]
}

# is_svg FILE TITLE: XML, the title element, complete, more than 5000 bytes.
is_svg() {
    head -c 5 "$1" | grep -q '^<?xml' &&
        grep -qF "<title>$2</title>" "$1" &&
        grep -q '</svg>' "$1" &&
        [ "$(stat -c %s "$1")" -gt 5000 ]
}

four_pictures() { # four_pictures DIR TITLE_PREFIX
    is_png "$1/side.png" 1000 700 && is_png "$1/top.png" 1000 700 &&
        is_svg "$1/side.svg" "$2, side view" &&
        is_svg "$1/top.svg" "$2, top view"
}

empty_dir() { [ -z "$(ls -A "$1" 2>/dev/null)" ]; }

if [ "$HAVE" = no ]; then
    mkdir "$T/p"
    ts equilibrium "$EX1" --plot "$T/p"
    check "without PLplot: --plot exits 2 (got $status)" [ $status -eq 2 ]
    check "without PLplot: the message names the packages" \
        grep -q "built without PLplot; install libplplot-dev and plplot-driver-cairo" "$T/err"
    check "without PLplot: nothing solved, nothing written" \
        bash -c "! grep -q converged '$T/out' && [ -z \"\$(ls -A '$T/p')\" ]"
    ts equilibrium "$EX1" --quiet
    check "without PLplot: the analysis still runs (exit $status)" \
        bash -c "[ $status -eq 0 ] && grep -q '^converged' '$T/out'"
    echo "$npass passed, $nfail failed"
    [ $nfail -eq 0 ]
    exit
fi

# The four pictures, in a directory that does not exist yet.
ts equilibrium "$EX1" --quiet --plot "$T/p/new"
check "--plot: exit 0 (got $status; $(head -c 300 "$T/err"))" [ $status -eq 0 ]
check "--plot: side and top PNG and SVG, titled with the scene" \
    four_pictures "$T/p/new" "kamman_ex1_above: equilibrium"
check "--plot: says where the pictures went" grep -q "wrote $T/p/new/side.png" "$T/out"
check "--plot: no temporary file left" \
    bash -c "[ \$(ls -A '$T/p/new' | wc -l) -eq 4 ]"

# PLplot is loaded with the drawing module (towstab-plot.so, lib/plot.c)
# only by a run that draws: the dynamic loader's list of the files it
# opens (LD_DEBUG=files) names neither for a run without --plot, both for
# one with it (which shows the check can see them).
loaded() { # loaded ARGS...: the files the run opened, in $T/files
    LD_DEBUG=files "$TOWSTAB" "$@" >"$T/out" 2>"$T/files"
    status=$?
}
loaded equilibrium "$EX1S" --links 20 --quiet
check "no --plot: exit 0, and neither towstab-plot.so nor libplplot is loaded ($(grep -c 'file=' "$T/files") files opened)" \
    bash -c "[ $status -eq 0 ] && grep -q 'file=' '$T/files' &&
             ! grep -q 'file=[^ ]*\(towstab-plot\|libplplot\|libcairo\)' '$T/files'"
loaded equilibrium "$EX1S" --links 20 --quiet --plot "$T/p/loaded"
check "--plot: the run loads towstab-plot.so and libplplot" \
    bash -c "[ $status -eq 0 ] && grep -q 'file=[^ ]*towstab-plot\.so' '$T/files' &&
             grep -q 'file=[^ ]*libplplot' '$T/files'"

# A module that cannot be loaded: --plot fails before anything is solved,
# naming the file, the loader's reason and the repair; nothing is written.
# An installation fault, not bad input: exit status 1. The module's place
# is forced with TOWSTAB_PLOT_MODULE.
plot_with_module() { # plot_with_module FILE
    TOWSTAB_PLOT_MODULE=$1 "$TOWSTAB" equilibrium "$EX1" --plot "$T/p/nomod" \
        >"$T/out" 2>"$T/err"
    status=$?
}
plot_with_module "$T/missing/towstab-plot.so"
check "missing module: exit 1 (got $status)" [ $status -eq 1 ]
check "missing module: the message names the file and the reason ($(head -c 300 "$T/err"))" \
    grep -qF "cannot load the plotting module $T/missing/towstab-plot.so: $T/missing/towstab-plot.so: cannot open shared object file" "$T/err"
check "missing module: the message says how to repair it" \
    grep -qF "(TOWSTAB_PLOT_MODULE): unset TOWSTAB_PLOT_MODULE, or set it to the plotting module of this towstab" "$T/err"
check "missing module: nothing solved, no directory made" \
    bash -c "! grep -q converged '$T/out' && [ ! -e '$T/p/nomod' ]"
echo "not a shared object" >"$T/broken.so"
plot_with_module "$T/broken.so"
check "broken module: exit 1, the file named ($(head -c 300 "$T/err"))" \
    bash -c "[ $status -eq 1 ] && grep -qF 'cannot load the plotting module $T/broken.so: ' '$T/err' && [ ! -e '$T/p/nomod' ]"
libm=$(ldd "$TOWSTAB" | awk '$1 ~ /^libm\.so/ {print $3}')
if [ -n "$libm" ]; then
    plot_with_module "$libm"
    check "a library that is no plotting module: refused ($(head -c 300 "$T/err"))" \
        bash -c "[ $status -eq 1 ] && grep -qF '$libm is not a towstab plotting module' '$T/err' && [ ! -e '$T/p/nomod' ]"
fi

# Imperial units and an overlaid scene.
ts equilibrium "$EX1" --quiet --plot "$T/imp" --units imperial --overlay "$EX1S"
check "--units imperial --overlay SCENE: exit 0 (got $status)" [ $status -eq 0 ]
check "overlaid scenes: titles name both scenes" \
    four_pictures "$T/imp" "kamman_ex1_above and kamman_ex1_submerged: equilibrium"
check "overlaid scene: one overlay line" \
    bash -c "[ \$(grep -c '^overlay ' '$T/out') -eq 1 ]"
check "imperial pictures differ from SI ones" \
    bash -c "! cmp -s '$T/imp/side.png' '$T/p/new/side.png'"

# Overlays of speeds (unit of the last item) and turn rates.
ts equilibrium "$EX1" --quiet --plot "$T/spd" --overlay-speeds "3,4, 6 knot"
check "--overlay-speeds: exit 0 (got $status; $(head -c 300 "$T/err"))" [ $status -eq 0 ]
check "--overlay-speeds '3,4, 6 knot': three overlay lines, in knots" \
    bash -c "[ \$(grep -c \"^overlay --overlay-speeds '[346] knot'\" '$T/out') -eq 3 ]"
check "--overlay-speeds: four pictures" four_pictures "$T/spd" "kamman_ex1_above: equilibrium"
ts equilibrium "$EX2" --quiet --plot "$T/turn" --overlay-turn-rates "0.5 rad/s"
check "--overlay-turn-rates: exit 0 (got $status)" [ $status -eq 0 ]
check "--overlay-turn-rates: four pictures" four_pictures "$T/turn" "kamman_ex2_branched: equilibrium"
check "a steady turn: the earth-frame plan view over one revolution (plan_earth), none for a straight tow" \
    bash -c "$(declare -f is_png is_svg); is_png '$T/turn/plan_earth.png' 1000 700 && is_svg '$T/turn/plan_earth.svg' 'kamman_ex2_branched: steady turn over one revolution, earth frame' && grep -q 'wrote $T/turn/plan_earth.png' '$T/out' && [ ! -e '$T/p/new/plan_earth.png' ]"

# Refusals: exit 2, nothing solved, no picture.
touch "$T/afile"
refused() { # refused DESCRIPTION ARGS...
    local what=$1
    shift
    rm -rf "$T/r"
    ts equilibrium "$@"
    if [ $status -eq 2 ] && [ -s "$T/err" ] && ! grep -q converged "$T/out" &&
        empty_dir "$T/r"; then
        pass "$what: exit 2, $(head -n1 "$T/err")"
    else
        fail "$what: exit $status, stdout $(head -c 200 "$T/out"), stderr $(head -c 300 "$T/err")"
    fi
}
refused "--plot into a file" "$EX1" --plot "$T/afile"
check "--plot into a file: the message says so" grep -q "not a directory" "$T/err"
refused "--plot under a file" "$EX1" --plot "$T/afile/sub"
refused "--units furlong" "$EX1" --plot "$T/r" --units furlong
refused "--overlay-speeds without --plot" "$EX1" --overlay-speeds "2 knot"
refused "--overlay-speeds with a wrong unit" "$EX1" --plot "$T/r" --overlay-speeds "2,3 lbf"
refused "--overlay-speeds with an empty item" "$EX1" --plot "$T/r" --overlay-speeds "2,,3 knot"
refused "--overlay-turn-rates with garbage" "$EX1" --plot "$T/r" --overlay-turn-rates "fast"
refused "--overlay of a missing scene" "$EX1" --plot "$T/r" --overlay "$T/missing.yaml"
refused "--plot without a value" "$EX1" --plot

# modes and response draw their pictures too.
EX3=examples/kamman_ex3_turn.yaml
# (without the estimate the shapes are judged on their own: the four
# lowest oscillatory modes are not grid-scale)
ts modes "$EX3" --oscillatory --count 4 --no-discretisation-error --quiet --plot "$T/modes"
check "modes --plot: exit 0 (got $status; $(head -c 300 "$T/err"))" [ $status -eq 0 ]
check "modes --plot: eigenvalue plane 1000 x 700, titled" \
    bash -c "$(declare -f is_png is_svg); is_png '$T/modes/eigenvalues.png' 1000 700 && is_svg '$T/modes/eigenvalues.svg' 'kamman_ex3: eigenvalues'"
check "modes --plot: the four lowest resolved oscillatory mode shapes (95 + 220 x 4 + 50 px tall)" \
    bash -c "$(declare -f is_png is_svg); is_png '$T/modes/modes.png' 1000 1025 && is_svg '$T/modes/modes.svg' 'kamman_ex3: lowest resolved oscillatory modes'"
ts response "$EX1" --output sphere.z --quiet --plot "$T/bode" --units imperial
check "response --plot: exit 0 (got $status; $(head -c 300 "$T/err"))" [ $status -eq 0 ]
check "response --plot: Bode plot, PNG and SVG, titled" \
    bash -c "$(declare -f is_png is_svg); is_png '$T/bode/bode.png' 1000 700 && is_svg '$T/bode/bode.svg' 'kamman_ex1_above: frequency response'"
anim_ok=1
nanim=0
for f in "$T/modes"/mode*_animation.svg; do
    nanim=$((nanim + 1))
    { [ -f "$f" ] && grep -q '<animate ' "$f" && grep -q '<title>kamman_ex3: mode' "$f"; } || anim_ok=0
done
check "modes --plot: the four drawn modes as animated SVGs (got $nanim)" \
    bash -c "[ $anim_ok -eq 1 ] && [ $nanim -eq 4 ]"
ntop=$(ls "$T/modes"/mode*_animation_top.svg 2>/dev/null | wc -l)
check "modes --plot: and in plan view (modeK_animation_top.svg, got $ntop)" \
    bash -c "[ $ntop -eq 4 ] && grep -q '<title>kamman_ex3: mode [0-9]*, top view, one cycle</title>' $(ls "$T/modes"/mode*_animation_top.svg | head -1)"
ts modes "$EX3" --oscillatory --count 1 --no-discretisation-error --quiet --plot "$T/frames" --frames
nfr=$(ls "$T/frames"/mode*_side_0[0-9][0-9].png "$T/frames"/mode*_top_0[0-9][0-9].png 2>/dev/null | wc -l)
check "modes --plot --frames: 12 PNG frames of the drawn mode in each view (got $nfr)" \
    bash -c "[ $status -eq 0 ] && [ $nfr -eq 24 ] && $(declare -f is_png); is_png \"\$(ls '$T/frames'/mode*_top_011.png)\" 1000 700"
ts modes "$EX3" --frames --quiet
check "modes --frames without --plot: exit 2 naming --plot (got $status)" \
    bash -c "[ $status -eq 2 ] && grep -q -- '--frames.*--plot' '$T/err'"
ts modes "$EX3" --plot "$T/afile"
check "modes --plot into a file: exit 2 (got $status)" [ $status -eq 2 ]

# simulate and converge draw their pictures too.
EX4=examples/kamman_ex4.yaml
ts simulate "$EX4" --quiet --excite tow.heave:amplitude=0.1ft,frequency=1Hz \
    --compare --t-end 6 --transient 3 --plot "$T/sim" --units imperial
check "simulate --plot: exit 0 (got $status; $(head -c 300 "$T/err"))" [ $status -eq 0 ]
check "simulate --plot: histories 1000 x 700, titled linear and nonlinear" \
    bash -c "$(declare -f is_png is_svg); is_png '$T/sim/histories.png' 1000 700 && is_svg '$T/sim/histories.svg' 'kamman_ex4: time histories, linear and nonlinear'"
check "simulate --plot: snapshots side and top (every 0.6 s = t_end/10)" \
    bash -c "$(declare -f is_png is_svg); is_png '$T/sim/snapshots_side.png' 1000 700 && is_png '$T/sim/snapshots_top.png' 1000 700 && is_svg '$T/sim/snapshots_side.svg' 'kamman_ex4: cable every 0.6 s, side view' && is_svg '$T/sim/snapshots_top.svg' 'kamman_ex4: cable every 0.6 s, top view'"
check "simulate --plot: six files, nothing else" \
    bash -c "[ \$(ls -A '$T/sim' | wc -l) -eq 6 ]"
ts simulate examples/kamman_ex5_drop.yaml --quiet --plot "$T/drop" --snapshot-interval 5s
check "simulate --plot --snapshot-interval 5s (drop test): exit 0 (got $status)" [ $status -eq 0 ]
check "simulate --snapshot-interval 5s: snapshots every 5 s" \
    bash -c "$(declare -f is_png is_svg); is_svg '$T/drop/snapshots_side.svg' 'kamman_ex5_drop: cable every 5 s, side view'"
ts converge examples/kamman_ex1_submerged.yaml --links 5,10,20,40 --quiet --plot "$T/conv"
check "converge --plot: exit 0 (got $status; $(head -c 300 "$T/err"))" [ $status -eq 0 ]
check "converge --plot: error against run time, PNG and SVG, titled" \
    bash -c "$(declare -f is_png is_svg); is_png '$T/conv/error_time.png' 1000 700 && is_svg '$T/conv/error_time.svg' 'kamman_ex1_submerged: equilibrium, error against run time (links sweep)'"
for cmd in "simulate $EX4 --t-end 2" "converge examples/kamman_ex1_submerged.yaml --links 5,10"; do
    rm -f "$T/afile"; touch "$T/afile"
    eval ts $cmd --plot "$T/afile"
    if [ $status -eq 2 ] && grep -q "not a directory" "$T/err" && [ ! -s "$T/afile" ] &&
        ! grep -q "wrote" "$T/out"; then
        pass "${cmd%% *} --plot into a file: exit 2, nothing run"
    else
        fail "${cmd%% *} --plot into a file: exit $status; $(head -c 300 "$T/err")"
    fi
done
ts simulate "$EX4" --t-end 2 --snapshot-interval 1
check "simulate --snapshot-interval without --plot: exit 2 (got $status)" [ $status -eq 2 ]
ts simulate "$EX4" --t-end 2 --transient 1 --excite tow.heave:amplitude=0.1ft,frequency=1Hz --plot "$T/r2" --snapshot-interval 0.01
check "simulate --snapshot-interval 0.01 s on a 2 s run (too many): exit 2 (got $status)" \
    bash -c "[ $status -eq 2 ] && grep -q snapshot-interval '$T/err'"

# Pictures of issue 15: exaggerated snapshots, the Bode magnitude in dB,
# a cylinder towfish drawn, error-vs-time points labelled.
ts simulate "$EX4" --quiet --t-end 2 --transient 1 --excite tow.heave:amplitude=0.01ft,frequency=1Hz \
    --plot "$T/ex" --exaggerate 50
check "simulate --exaggerate 50: snapshots titled with the factor" \
    bash -c "$(declare -f is_png is_svg); [ $status -eq 0 ] && is_svg '$T/ex/snapshots_side.svg' 'kamman_ex4: cable every 0.2 s, displacements from t = 0 s x 50, side view'"
for k in 0.5 abc; do
    ts simulate "$EX4" --t-end 2 --transient 1 --excite tow.heave:amplitude=0.1ft,frequency=1Hz \
        --plot "$T/exbad" --exaggerate $k
    check "simulate --exaggerate $k: exit 2 naming it (got $status)" \
        bash -c "[ $status -eq 2 ] && grep -q -- --exaggerate '$T/err'"
done
ts simulate "$EX4" --t-end 2 --transient 1 --excite tow.heave:amplitude=0.1ft,frequency=1Hz --exaggerate 5
check "simulate --exaggerate without --plot: exit 2 (got $status)" [ $status -eq 2 ]
ts simulate examples/kamman_ex1_submerged.yaml --quiet --t-end 20 \
    --manoeuvre turn_rate:to=0.1rad/s,duration=5s --plot "$T/man"
check "simulate under a manoeuvre: the earth-frame plan view with the ship's and the sphere's tracks (exit $status)" \
    bash -c "$(declare -f is_png is_svg); [ $status -eq 0 ] && is_png '$T/man/plan_earth.png' 1000 700 && is_svg '$T/man/plan_earth.svg' \"kamman_ex1_submerged: manoeuvre in the earth frame, cable every 2 s and the tracks\""
check "simulate under a manoeuvre: the tracks in the earth frame and the depths against time" \
    bash -c "$(declare -f is_png is_svg); is_png '$T/man/tracks.png' 1000 700 && is_svg '$T/man/tracks.svg' 'kamman_ex1_submerged: tracks in the earth frame' && is_png '$T/man/depths.png' 1000 700 && is_svg '$T/man/depths.svg' 'kamman_ex1_submerged: depths against time'"
check "simulate without a manoeuvre draws no plan_earth, tracks or depths" \
    bash -c "[ ! -e '$T/sim/plan_earth.png' ] && [ ! -e '$T/sim/tracks.png' ] && [ ! -e '$T/sim/depths.png' ]"
# A towing vehicle with waypoints: the tracks (its tow point's and the
# fish's) and the depths are drawn; the waypoints are open diamonds labelled
# "WP n" with a legend entry, so the picture holds more glyphs (cairo's
# <use> elements) than the same run without the waypoints entry.
WPS=test/scenes/dolphin_waypoints.yaml
ts simulate "$WPS" --quiet --t-end 20 --sample 0.5 --plot "$T/wp"
sed '/^waypoints:/,/^cables:/{/^cables:/!d}' "$WPS" >"$T/nowp.yaml"
ts simulate "$T/nowp.yaml" --quiet --t-end 20 --sample 0.5 --plot "$T/nowp"
nuse_wp=$(grep -c '<use' "$T/wp/tracks.svg" 2>/dev/null)
nuse_no=$(grep -c '<use' "$T/nowp/tracks.svg" 2>/dev/null)
check "simulate with waypoints: tracks with the waypoints marked ($nuse_wp glyphs against $nuse_no without) and depths" \
    bash -c "$(declare -f is_png is_svg); is_png '$T/wp/tracks.png' 1000 700 && is_svg '$T/wp/tracks.svg' 'dolphin_waypoints: tracks in the earth frame' && is_png '$T/wp/depths.png' 1000 700 && [ \"${nuse_wp:-0}\" -ge \$(( ${nuse_no:-0} + 15 )) ]"
ts response "$EX1" --output sphere.z --quiet --plot "$T/db" --db
check "response --db: the Bode plot drawn (exit $status)" \
    bash -c "$(declare -f is_png is_svg); [ $status -eq 0 ] && is_png '$T/db/bode.png' 1000 700"
ts response "$EX1" --output sphere.z --quiet --db
check "response --db without --plot: exit 2 (got $status)" [ $status -eq 2 ]
ts equilibrium examples/two_part_tow.yaml --quiet --plot "$T/cyl"
check "equilibrium of the two-part tow (a cylinder towfish) --plot: exit 0 (got $status)" \
    bash -c "$(declare -f is_png is_svg); [ $status -eq 0 ] && is_png '$T/cyl/side.png' 1000 700"

# Vehicles with their attitude (the outline itself is test_plot's; the
# SVG draws the legend's text as glyphs, so only the title is text).
ts equilibrium examples/aurora_towfish.yaml --links 10 --quiet --plot "$T/veh"
check "vehicle: equilibrium side and top views (exit $status)" \
    [ $status -eq 0 -a -s "$T/veh/side.png" -a -s "$T/veh/top.png" ]
check "vehicle: side and top SVG, titled with the scene" \
    bash -c "$(declare -f is_svg); is_svg '$T/veh/side.svg' 'aurora_towfish: equilibrium, side view' && is_svg '$T/veh/top.svg' 'aurora_towfish: equilibrium, top view'"

echo "$npass passed, $nfail failed"
[ $nfail -eq 0 ]
