#!/bin/bash
# library.sh: the installed library is one others can build on.
#   library.sh MESON BUILD_DIR VERSION CHECK_JSON SANITIZE CC [CC_ARGS...]
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
#     the same computation, read back from 17 significant digits).
# SANITIZE is the build's b_sanitize ("none" or e.g. "address,undefined"):
# an instrumented library needs the same flags at link time.
# Run from the project root.
set -u
if [ $# -lt 6 ]; then
    echo "usage: library.sh MESON BUILD_DIR VERSION CHECK_JSON SANITIZE CC [CC_ARGS...]" >&2
    exit 2
fi
MESON=$1 BUILD=$2 VERSION=$3 CHECK_JSON=$4 SANITIZE=$5
shift 5
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
exit $fail
