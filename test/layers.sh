#!/bin/bash
# test/layers.sh: the library's modules include only modules below them.
#
#   layers.sh            check the project (run from its root)
#   layers.sh --selftest the checker on planted faults
#
# The layer order is written once, in doc/architecture.md, in the fenced
# block marked `layers`: one layer per line, lowest first, modules of one
# layer separated by spaces; `kernel(forces)` says that lib/forces.h
# belongs to the module kernel. A module is its files lib/<m>.c,
# lib/<m>.h, lib/<m>_impl.h and include/towstab/<m>.h. Checked:
#   - every file of lib/ and include/towstab/ belongs to a listed module,
#     and every listed module has a file;
#   - every #include "..." of such a file names its own module or one of
#     a lower layer (an include within one layer is upward too);
#   - the module graph has no cycle (tsort);
#   - tools/ includes only public headers (towstab/*.h) and its own.
# Prints one PASS/FAIL line per check and "N passed, N failed".
set -u

npass=0
nfail=0
pass() { echo "PASS $*"; npass=$((npass + 1)); }
fail() { echo "FAIL $*"; nfail=$((nfail + 1)); }

# check ROOT: the checks on the tree at ROOT; prints the faults, one a
# line, and returns 1 when there is any.
check() {
    local root=$1 edges
    edges=$(mktemp "${TMPDIR:-/tmp}/towstab-layers-edges-XXXXXX") || return 2
    awk -v root="$root" -v edges="$edges" '
    function module_of(path,    b) {
        b = path
        sub(/.*\//, "", b)
        sub(/\.[ch]$/, "", b)
        if (b in owner) return owner[b]
        sub(/_impl$/, "", b)
        return b
    }
    BEGIN {
        doc = root "/doc/architecture.md"
        inblock = 0; layer = 0
        while ((getline line < doc) > 0) {
            if (line ~ /^```layers/) { inblock = 1; continue }
            if (inblock && line ~ /^```/) { inblock = 0; continue }
            if (!inblock || line ~ /^[ \t]*$/) continue
            layer++
            n = split(line, mods, /[ \t]+/)
            for (i = 1; i <= n; i++) {
                m = mods[i]
                if (m == "") continue
                extra = ""
                if (match(m, /\(.*\)$/)) {
                    extra = substr(m, RSTART + 1, RLENGTH - 2)
                    m = substr(m, 1, RSTART - 1)
                    k = split(extra, ex, /,/)
                    for (j = 1; j <= k; j++) owner[ex[j]] = m
                }
                if (m in rank) { print "module " m " is listed twice"; bad = 1 }
                rank[m] = layer
                used[m] = 0
            }
        }
        if (layer == 0) { print doc ": no ```layers block"; exit 1 }
        cmd = "cd \"" root "\" && ls lib/*.c lib/*.h include/towstab/*.h 2>/dev/null"
        while ((cmd | getline f) > 0) files[++nf] = f
        close(cmd)
        for (i = 1; i <= nf; i++) {
            f = files[i]
            m = module_of(f)
            if (!(m in rank)) {
                print f ": module " m " is not in the layer list of doc/architecture.md"
                bad = 1
                continue
            }
            used[m] = 1
            while ((getline line < (root "/" f)) > 0) {
                if (line !~ /^[ \t]*#[ \t]*include[ \t]*"/) continue
                inc = line
                sub(/^[^"]*"/, "", inc)
                sub(/".*/, "", inc)
                t = module_of(inc)
                if (t == m) continue
                if (!(t in rank)) {
                    print f ": includes " inc " of module " t ", which is not in the layer list"
                    bad = 1
                } else if (rank[t] >= rank[m]) {
                    print f " (" m ", layer " rank[m] ") includes " inc " (" t ", layer " rank[t] "): an upward include"
                    bad = 1
                }
                print m, t > edges
            }
            close(root "/" f)
        }
        for (m in used)
            if (!used[m]) { print "module " m " is listed but has no file"; bad = 1 }
        exit bad
    }' </dev/null
    local st=$?
    # A cycle in the module graph (tsort names it).
    if [ -s "$edges" ] && ! tsort "$edges" >/dev/null 2>"$edges.tsort"; then
        echo "a cycle of modules: $(grep -v 'input contains a loop' "$edges.tsort" | sed 's/^tsort: //' | tr '\n' ' ')"
        st=1
    fi
    rm -f "$edges" "$edges.tsort"
    # tools/ sees the library through its public headers only.
    local f inc
    for f in "$root"/tools/*.c "$root"/tools/*.h; do
        [ -e "$f" ] || continue
        while read -r inc; do
            case "$inc" in
            towstab/*.h) [ -e "$root/include/$inc" ] || { echo "${f#"$root"/}: includes $inc, not a public header"; st=1; } ;;
            *) [ -e "$root/tools/$inc" ] || { echo "${f#"$root"/}: includes $inc, a library-internal header"; st=1; } ;;
            esac
        done < <(sed -n 's/^[ \t]*#[ \t]*include[ \t]*"\([^"]*\)".*/\1/p' "$f")
    done
    return $st
}

# A small tree: a (layer 1) < b (layer 2) < c (layer 3).
plant() {
    local r=$1
    mkdir -p "$r/doc" "$r/lib" "$r/include/towstab" "$r/tools"
    printf '# x\n\n```layers\na\nb(bhelp)\nc\n```\n' >"$r/doc/architecture.md"
    printf '#include "towstab/a.h"\n' >"$r/include/towstab/a.h"
    printf '#include "towstab/a.h"\n' >"$r/include/towstab/b.h"
    printf '#include "towstab/b.h"\n#include "bhelp.h"\n' >"$r/lib/b.c"
    printf '#include "towstab/a.h"\n' >"$r/lib/bhelp.h"
    printf '#include "towstab/b.h"\n#include "towstab/a.h"\n' >"$r/lib/c.c"
    printf '#include "towstab/c.h"\n' >"$r/include/towstab/c.h"
    printf '#include "towstab/c.h"\n' >"$r/tools/main.c"
}

selftest() {
    local T r why
    T=$(mktemp -d "${TMPDIR:-/tmp}/towstab-layers-XXXXXX") || exit 2
    trap 'rm -rf "$T"' RETURN
    r=$T/good; plant "$r"
    check "$r" >"$T/msg" && pass "selftest: a layered tree passes" ||
        fail "selftest: a layered tree is refused: $(head -1 "$T/msg")"
    r=$T/up; plant "$r"
    printf '#include "towstab/c.h"\n' >>"$r/lib/b.c"
    check "$r" >"$T/msg" || true
    grep -q 'lib/b.c (b, layer 2) includes towstab/c.h (c, layer 3): an upward include' "$T/msg" &&
        pass "selftest: an upward include is refused" || fail "selftest: upward include: $(cat "$T/msg")"
    r=$T/cycle; plant "$r"
    # Within one layer, both ways: upward for the checker, and a cycle.
    printf '```layers\na\nb(bhelp) c\n```\n' >"$r/doc/architecture.md"
    printf '#include "towstab/c.h"\n' >>"$r/lib/b.c"
    check "$r" >"$T/msg" || true
    why=""
    grep -q 'an upward include' "$T/msg" || why="$why no upward include;"
    grep -q 'a cycle of modules' "$T/msg" || why="$why no cycle;"
    [ -z "$why" ] && pass "selftest: two modules of one layer including each other: upward and a cycle" ||
        fail "selftest: cycle:$why $(cat "$T/msg")"
    r=$T/unlisted; plant "$r"
    printf '\n' >"$r/lib/d.c"
    check "$r" >"$T/msg" || true
    grep -q 'lib/d.c: module d is not in the layer list' "$T/msg" &&
        pass "selftest: a file of no listed module is refused" || fail "selftest: unlisted: $(cat "$T/msg")"
    r=$T/tools; plant "$r"
    printf '#include "bhelp.h"\n' >>"$r/tools/main.c"
    check "$r" >"$T/msg" || true
    grep -q 'tools/main.c: includes bhelp.h, a library-internal header' "$T/msg" &&
        pass "selftest: tools including an internal header is refused" || fail "selftest: tools: $(cat "$T/msg")"
}

if [ "${1:-}" = --selftest ]; then
    selftest
else
    selftest
    if check . >"${TMPDIR:-/tmp}/towstab-layers.$$"; then
        pass "lib/ and include/towstab/: every include points down the layers of doc/architecture.md, no cycle; tools/ uses public headers only"
    else
        while read -r line; do fail "$line"; done <"${TMPDIR:-/tmp}/towstab-layers.$$"
    fi
    rm -f "${TMPDIR:-/tmp}/towstab-layers.$$"
fi
echo "$npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
