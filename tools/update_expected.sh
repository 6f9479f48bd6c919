#!/bin/sh
# update_expected.sh: rewrite one example's expected summary from the
# current build, so that a change of the model shows as a diff of
# examples/NAME.expected.json to review and commit.
#
#   tools/update_expected.sh NAME [TOWSTAB] [OUT]
#
# NAME: the example (examples/NAME.yaml); TOWSTAB: the towstab binary
# (default build/tools/towstab); OUT: where to write (default
# examples/NAME.expected.json itself). Run from the project root.
#
# What it does: `towstab run examples/NAME.yaml --json` (what the
# examples test runs, test/cli/run.sh), then the expected file's "expect"
# part is used as the template: every value it holds is replaced by the
# run's value at the same place (objects by key, arrays by index), a
# number written to 10 significant digits (the files' precision, beyond
# their rtol), a whole number left whole, one within the file's atol of
# zero as 0 (a value zero by symmetry, to rounding). Keys the template does not
# hold are not added and "note", "rtol" and "atol" are kept as they are:
# what is checked, and why at that tolerance, is a decision made by hand,
# and the note may quote figures to revise. Each value that changed is
# printed, `PATH: OLD -> NEW (relative change)`.
#
# It refuses (exit 1, nothing written) when the run fails or does not
# have the template's shape: a key missing or an array of another length
# (say, a waypoint not reached), which needs the file edited by hand.
set -eu
if [ $# -lt 1 ] || [ $# -gt 3 ]; then
    echo "usage: tools/update_expected.sh NAME [TOWSTAB] [OUT]" >&2
    exit 2
fi
NAME=$1
TOWSTAB=${2:-build/tools/towstab}
SCENE=examples/$NAME.yaml
EXP=examples/$NAME.expected.json
OUT=${3:-$EXP}
for f in "$SCENE" "$EXP"; do
    if [ ! -f "$f" ]; then
        echo "update_expected.sh: no $f (run from the project root)" >&2
        exit 1
    fi
done
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
if ! OPENBLAS_NUM_THREADS=1 "$TOWSTAB" run "$SCENE" --quiet \
        --json "$TMP/run.json" >"$TMP/out" 2>&1; then
    echo "update_expected.sh: towstab run $SCENE failed:" >&2
    tail -5 "$TMP/out" >&2
    exit 1
fi
python3 - "$TMP/run.json" "$EXP" "$TMP/new.json" <<'EOF'
import json, sys

run_path, exp_path, new_path = sys.argv[1:4]
with open(run_path) as f:
    run = json.load(f)
with open(exp_path) as f:
    exp = json.load(f)


class Shape(Exception):
    pass


ATOL = exp.get("atol", 0.0)


def rounded(v):
    """A number as the expected files write it: 10 significant digits;
    0 within the file's atol (a value zero by symmetry, to rounding)."""
    if isinstance(v, bool) or isinstance(v, int):
        return v
    if abs(v) <= ATOL:
        return 0.0
    return float("%.10g" % v)


def fill(want, got, path):
    """want with each value replaced by got's at the same place."""
    if isinstance(want, dict):
        if not isinstance(got, dict):
            raise Shape("%s: the run has no object here" % path)
        out = {}
        for k, w in want.items():
            if k not in got:
                raise Shape("%s.%s: not in the run's output" % (path, k))
            out[k] = fill(w, got[k], "%s.%s" % (path, k))
        return out
    if isinstance(want, list):
        if not isinstance(got, list) or len(got) != len(want):
            raise Shape("%s: %d entries expected, the run has %s" % (
                path, len(want),
                len(got) if isinstance(got, list) else "no array"))
        return [fill(w, g, "%s[%d]" % (path, i))
                for i, (w, g) in enumerate(zip(want, got))]
    new = rounded(got) if isinstance(got, (int, float)) and \
        not isinstance(got, bool) else got
    if new != want:
        if isinstance(new, (int, float)) and isinstance(want, (int, float)) \
                and not isinstance(new, bool) and want != 0:
            print("%s: %r -> %r (%.3g relative)" % (
                path, want, new, (new - want) / abs(want)))
        else:
            print("%s: %r -> %r" % (path, want, new))
    return new


try:
    exp["expect"] = fill(exp["expect"], run, "expect")
except Shape as e:
    sys.stderr.write("update_expected.sh: %s; edit %s by hand\n" %
                     (e, exp_path))
    sys.exit(1)
with open(new_path, "w") as f:
    f.write(json.dumps(exp, indent=2, ensure_ascii=False) + "\n")
EOF
cp "$TMP/new.json" "$OUT"
echo "wrote $OUT"
