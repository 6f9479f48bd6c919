#!/bin/bash
# library.sh: the installed library is one others can build on.
#   library.sh MESON BUILD_DIR VERSION CHECK_JSON SANITIZE PLOT CC [CC_ARGS...]
# Installs the build into a temporary folder (meson install --destdir),
# points pkg-config at it (PKG_CONFIG_PATH, PKG_CONFIG_SYSROOT_DIR) and
# checks:
#  1. towstab.pc is installed, its version is the project's, and the shared
#     library's soname is libtowstab.so.0;
#  2. examples/speed_sweep.c compiles and links with
#     `pkg-config --cflags --libs towstab` against the shared library, and
#     runs with LD_LIBRARY_PATH;
#  3. it links against the static archive with `pkg-config --static --libs`,
#     and needs no libtowstab at run time;
#  4. with every object of the archive forced in (--whole-archive), the
#     static link still resolves every symbol: Libs.private and
#     Requires.private list every dependency;
#  5. the sweep's depths and top tensions at three speeds equal those of
#     the installed `towstab equilibrium --speed V --json` (relative 1e-12:
#     the same computation, read back from 17 significant digits);
#  6. the installed `towstab simulate --integrator esdirk` loads the
#     installed SUNDIALS module (LIBDIR/towstab/towstab-sundials.so); with
#     PLOT yes (a build with PLplot): the installed drawing module
#     (LIBDIR/towstab/towstab-plot.so) is what the installed
#     `towstab equilibrium --plot DIR` loads (LD_DEBUG=files), and it draws
#     the side and top views; a run without --plot loads neither the
#     module nor libplplot; with the module moved away, --plot fails
#     (exit 2) naming the installed file, and writes nothing.
# SANITIZE is the build's b_sanitize ("none" or e.g. "address,undefined"):
# an instrumented library needs the same flags at link time.
# Run from the project root.
set -u
if [ $# -lt 7 ]; then
    echo "usage: library.sh MESON BUILD_DIR VERSION CHECK_JSON SANITIZE PLOT CC [CC_ARGS...]" >&2
    exit 2
fi
MESON=$1 BUILD=$2 VERSION=$3 CHECK_JSON=$4 SANITIZE=$5 PLOT=$6
shift 6
CC=("$@")
command -v pkg-config >/dev/null || { echo "SKIP: no pkg-config"; exit 77; }
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
fail=0
pass() { echo "PASS: $*"; }
bad() { echo "FAIL: $*"; fail=1; }

flags=(-std=c11)
[ "$SANITIZE" = none ] || flags+=("-fsanitize=$SANITIZE")

D=$T/root
if ! "$MESON" install -C "$BUILD" --destdir "$D" --no-rebuild --quiet >"$T/install.log" 2>&1; then
    cat "$T/install.log"
    echo "FAIL: meson install --destdir failed"
    exit 1
fi
pc=$(find "$D" -name towstab.pc | head -1)
so=$(find "$D" -name "libtowstab.so.$VERSION" | head -1)
tool=$(find "$D" -path '*/bin/towstab' | head -1)
if [ -z "$pc" ] || [ -z "$so" ] || [ -z "$tool" ]; then
    echo "FAIL: the install lacks towstab.pc, libtowstab.so.$VERSION or bin/towstab:"
    find "$D" -type f | sed "s|^$D||"
    exit 1
fi
libdir=$(dirname "$so")
export PKG_CONFIG_PATH=$(dirname "$pc") PKG_CONFIG_SYSROOT_DIR=$D

# 1. The package and the soname.
v=$(pkg-config --modversion towstab)
[ "$v" = "$VERSION" ] && pass "pkg-config finds towstab $v in the installed tree" ||
    bad "pkg-config --modversion towstab: '$v', expected $VERSION"
soname=$(readelf -d "$so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
[ "$soname" = libtowstab.so.0 ] && [ -L "$libdir/libtowstab.so.0" ] &&
    pass "soname libtowstab.so.0, file libtowstab.so.$VERSION" ||
    bad "soname '$soname' (expected libtowstab.so.0, with its link)"

# 2.-4. Shared, static, and static with every object of the archive.
read -r -a cflags <<<"$(pkg-config --cflags towstab)"
read -r -a libs <<<"$(pkg-config --libs towstab)"
read -r -a slibs <<<"$(pkg-config --static --libs towstab)"
static=()
whole=()
for a in "${slibs[@]}"; do
    if [ "$a" = -ltowstab ]; then
        # The archive in place of -ltowstab (GNU ld's -l:NAME).
        static+=(-l:libtowstab.a)
        whole+=(-Wl,--whole-archive -l:libtowstab.a -Wl,--no-whole-archive)
    else
        static+=("$a")
        whole+=("$a")
    fi
done
# link NAME LIBS...: build the example as $T/NAME; the compiler's messages
# in $T/NAME.log. Returns the compiler's status.
link() {
    local name=$1
    shift
    "${CC[@]}" "${flags[@]}" examples/speed_sweep.c "${cflags[@]}" "$@" \
        -o "$T/$name" 2>"$T/$name.log"
}
needs_towstab() { readelf -d "$T/$1" | grep -q 'NEEDED.*\[libtowstab\.so'; }

# The shared program needs libtowstab.so.0 at run time, the static one not.
for prog in shared static; do
    if [ "$prog" = shared ]; then
        args=("${libs[@]}") how="pkg-config --cflags --libs" want=yes
    else
        args=("${static[@]}") how="pkg-config --static --libs, libtowstab.a" want=no
    fi
    if ! link "$prog" "${args[@]}"; then
        bad "$prog: $(head -c 2000 "$T/$prog.log")"
        continue
    fi
    got=no
    needs_towstab "$prog" && got=yes
    if [ "$got" = "$want" ]; then
        pass "$prog: built with $how; needs libtowstab.so.0 at run time: $got"
    else
        bad "$prog: needs libtowstab.so.0 at run time: $got, expected $want"
    fi
done
if link whole "${whole[@]}"; then
    pass "static, whole archive: every symbol of libtowstab.a resolves with pkg-config --static --libs"
else
    bad "static, whole archive: $(grep -c 'undefined reference' "$T/whole.log") undefined references, e.g. $(grep -m 3 -o "undefined reference to \`[^']*'" "$T/whole.log" | tr '\n' ' ')"
fi

# 5. The numbers, against the installed command line.
scene=examples/kamman_ex1_submerged.yaml
speeds=("3 knot" "5 knot" "2.385 m/s")
for prog in shared static whole; do
    [ -x "$T/$prog" ] || continue
    # Only the shared program may look for libtowstab at run time.
    ldpath=${LD_LIBRARY_PATH:-}
    [ "$prog" = shared ] && ldpath=$libdir
    if ! LD_LIBRARY_PATH=$ldpath "$T/$prog" "$scene" "${speeds[@]}" >"$T/$prog.out" 2>"$T/err"; then
        bad "$prog: speed_sweep failed: $(cat "$T/err")"
        continue
    fi
    rows=$(grep -vc '^#' "$T/$prog.out")
    [ "$rows" -eq ${#speeds[@]} ] || { bad "$prog: $rows rows for ${#speeds[@]} speeds"; continue; }
    i=0 ok=1
    while read -r speed node depth top; do
        s=${speeds[$i]}
        i=$((i + 1))
        if ! LD_LIBRARY_PATH=$libdir "$tool" equilibrium "$scene" --speed "$s" \
                --json "$T/eq.json" --quiet >/dev/null 2>"$T/err"; then
            bad "towstab equilibrium --speed '$s': $(cat "$T/err")"
            ok=0
            continue
        fi
        printf '{"rtol": 1e-12, "atol": 0, "expect": {"speed": %s, "top_tension": %s, "bodies": [{"name": "%s", "z": %s}]}}\n' \
            "$speed" "$top" "$node" "$depth" >"$T/want.json"
        if ! "$CHECK_JSON" compare "$T/eq.json" "$T/want.json" >"$T/cmp" 2>&1; then
            bad "$prog at '$s': the sweep differs from towstab equilibrium: $(cat "$T/cmp")"
            ok=0
        fi
    done < <(grep -v '^#' "$T/$prog.out")
    [ "$ok" -eq 1 ] && pass "$prog: depth and top tension at ${speeds[*]} equal towstab equilibrium's (rtol 1e-12): $(grep -v '^#' "$T/$prog.out" | awk '{printf "%.6g m %.6g N; ", $3, $4}')"
done

# 6. The modules of the installed tree: SUNDIALS' steppers, pictures.
smodule=$libdir/towstab/towstab-sundials.so
LD_LIBRARY_PATH=$libdir LD_DEBUG=files "$tool" simulate examples/kamman_ex4.yaml \
    --quiet --no-compare --t-end 2 --no-discretisation-error --integrator esdirk \
    >"$T/out" 2>"$T/files"
st=$?
if [ $st -eq 0 ] && grep -qF "file=$smodule " "$T/files"; then
    pass "installed towstab simulate --integrator esdirk loads the installed LIBDIR/towstab/towstab-sundials.so"
else
    bad "installed simulate --integrator esdirk (exit $st): $(grep -v 'file=\|^ *[0-9]*: *$' "$T/files" | head -c 500); modules loaded: $(grep -o 'file=[^ ]*towstab-sundials[^ ]*' "$T/files")"
fi

if [ "$PLOT" = yes ]; then
    module=$libdir/towstab/towstab-plot.so
    [ -f "$module" ] && pass "the drawing module is installed as LIBDIR/towstab/towstab-plot.so" ||
        bad "no $module; installed: $(find "$D" -name '*.so' | sed "s|^$D||" | tr '\n' ' ')"
    LD_LIBRARY_PATH=$libdir LD_DEBUG=files "$tool" equilibrium "$scene" --quiet \
        --plot "$T/pics" >"$T/out" 2>"$T/files"
    st=$?
    if [ $st -eq 0 ] && grep -qF "file=$module " "$T/files" &&
        [ "$(head -c 4 "$T/pics/side.png" | tail -c 3)" = PNG ] &&
        grep -q '</svg>' "$T/pics/top.svg"; then
        pass "installed towstab --plot loads the installed module and draws side.png, top.svg"
    else
        bad "installed towstab --plot (exit $st): $(grep -v 'file=\|^ *[0-9]*: *$' "$T/files" | head -c 500); modules loaded: $(grep -o 'file=[^ ]*towstab-plot[^ ]*' "$T/files")"
    fi
    LD_LIBRARY_PATH=$libdir LD_DEBUG=files "$tool" equilibrium "$scene" --quiet \
        >"$T/out" 2>"$T/files"
    st=$?
    if [ $st -eq 0 ] && grep -q 'file=' "$T/files" &&
        ! grep -q 'file=[^ ]*\(towstab-plot\|libplplot\)' "$T/files"; then
        pass "installed towstab without --plot loads neither the module nor libplplot"
    else
        bad "installed towstab without --plot (exit $st) loaded: $(grep -o 'file=[^ ]*\(towstab-plot\|libplplot\)[^ ]*' "$T/files" | sort -u | tr '\n' ' ')"
    fi
    mv "$module" "$module.away"
    LD_LIBRARY_PATH=$libdir "$tool" equilibrium "$scene" --quiet \
        --plot "$T/pics2" >"$T/out" 2>"$T/err"
    st=$?
    if [ $st -eq 1 ] && grep -qF "towstab-plot.so" "$T/err" &&
        grep -q "cannot open shared object file" "$T/err" &&
        grep -qF "reinstall towstab, or rebuild it" "$T/err" && [ ! -e "$T/pics2" ]; then
        pass "module moved away: --plot exits 1 naming it and the repair, nothing written: $(head -c 400 "$T/err")"
    else
        bad "module moved away: exit $st, $(head -c 400 "$T/err")"
    fi
    mv "$module.away" "$module"
fi
exit $fail
