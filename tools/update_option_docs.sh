#!/bin/sh
# tools/update_option_docs.sh [TOWSTAB]: write the option reference of
# doc/manual.md (between "<!-- options: begin" and "<!-- options: end")
# from the option tables, as `towstab options` prints them. The cli test
# test/cli/options.sh fails when the two differ. Run from the project
# root; TOWSTAB defaults to build/tools/towstab.
set -eu
TOWSTAB=${1:-build/tools/towstab}
doc=doc/manual.md
tmp=$(mktemp)
trap 'rm -f "$tmp" "$tmp.ref"' EXIT
"$TOWSTAB" options >"$tmp.ref"
awk -v ref="$tmp.ref" '
    /^<!-- options: begin/ { print; while ((getline l < ref) > 0) print l; skip = 1; next }
    /^<!-- options: end/ { skip = 0 }
    !skip { print }' "$doc" >"$tmp"
grep -q '^<!-- options: begin' "$tmp" || { echo "$doc: no '<!-- options: begin' marker" >&2; exit 1; }
cat "$tmp" >"$doc"
