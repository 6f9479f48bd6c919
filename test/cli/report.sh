#!/bin/bash
# test/cli/report.sh: `towstab report SCENE -o DIR` as a user runs it
# (doc/manual.md, "towstab report"); the page in a browser is
# test/cli/report_browser.sh.
#
#   report.sh TOWSTAB CHECK_JSON yes|no   (yes: built with PLplot)
#
# Run from the project root (meson does, suite 'cli'). Checked: on a scene
# with every kind of analysis the page and results.json are written, exit
# 0; results.json is what `towstab run --json` writes (every number equal,
# timings aside); the page holds the command that made it, the scene's
# text, every analysis with its verdict, its key values (equal to the
# JSON's to the digits shown) and its pictures as SVG data URIs, and
# nothing that fetches (no script, no external link or source); the
# standard output names only files written. Markup in the scene's names
# is escaped. A failing analysis: exit 1, the page of what ran marked
# incomplete, the rest "not run". Bad input (no -o, an empty -o, -o a
# file, --units bad, an unknown option, a scene without analyses, a
# missing scene) exits 2 and writes nothing.
set -u

if [ $# -ne 3 ]; then
    echo "usage: report.sh TOWSTAB CHECK_JSON yes|no" >&2
    exit 2
fi
TOWSTAB=$1
CHECK_JSON=$2
HAVE=$3
. test/cli/common.sh

ALL=test/cli/report/all_kinds.yaml
FAILS=test/cli/report/fails.yaml

# 1. Every kind of analysis.
fresh
ts report "$ALL" -o "$T/o/page" --quiet
P=$T/o/page/index.html
why=""
[ "$status" -eq 0 ] || why="$why exit $status: $(head -2 "$T/err");"
[ -s "$P" ] || why="$why no page;"
"$CHECK_JSON" parse "$T/o/page/results.json" >/dev/null 2>&1 || why="$why results.json is not JSON;"
check "report: exit 0, DIR/index.html and DIR/results.json written" "$why"

# results.json is towstab run --json: equal but for run times.
"$TOWSTAB" run "$ALL" --quiet --json "$T/o/run.json" >/dev/null 2>&1
strip() { # the JSON without the keys that hold times
    python3 -c '
import json, sys
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items()
                if not (k.startswith("wall_s") or k in ("simulated_per_wall", "prediction"))}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
print(json.dumps(strip(json.load(open(sys.argv[1]))), sort_keys=True))' "$1"
}
if command -v python3 >/dev/null 2>&1; then
    [ "$(strip "$T/o/page/results.json")" = "$(strip "$T/o/run.json")" ] &&
        pass "results.json equals towstab run --json, every number (run times aside)" ||
        fail "results.json differs from towstab run --json: $(diff <(strip "$T/o/page/results.json" | tr ',' '\n') <(strip "$T/o/run.json" | tr ',' '\n') | head -5)"
fi

why=""
grep -q '<title>towstab report: report_all_kinds</title>' "$P" || why="$why no title;"
grep -q "<pre>towstab report $ALL -o $T/o/page --quiet</pre>" "$P" || why="$why not the command that made it;"
grep -q 'speed: &quot;2.5 ft/s&quot;' "$P" || why="$why no scene text;"
for k in 1 2 3 4 5; do
    grep -q "<section id=\"a$k\">" "$P" || why="$why no section $k;"
done
# One verdict per analysis, the JSON's.
want=$(python3 -c 'import json,sys; print(" ".join("yes" if a["trustworthy"] else "NO" for a in json.load(open(sys.argv[1]))["analyses"]))' "$T/o/page/results.json" 2>/dev/null)
got=$(grep -o 'trustworthy: [a-zA-Z]*' "$P" | sed 's/trustworthy: //' | tr '\n' ' ' | sed 's/ $//')
[ -n "$want" ] && [ "$got" = "$want" ] || why="$why verdicts '$got', the JSON's '$want';"
for t in equilibrium modes response simulate converge; do
    grep -q "<h2>[0-9]. $t</h2>" "$P" || why="$why no $t;"
done
grep -q 'Key values and their error estimates' "$P" || why="$why no key values;"
grep -q '<td>water density</td><td class="num">1025.8615</td><td>kg/m^3</td>' "$P" || why="$why no inputs in SI;"
check "the page: title, the command that made it, the scene's text, inputs in SI, five analyses with verdicts and key values" "$why"

# The key values on the page are the JSON's, to the 10 digits shown.
if command -v python3 >/dev/null 2>&1; then
    msg=$(python3 - "$P" "$T/o/page/results.json" <<'PY'
import html, json, re, sys
page = open(sys.argv[1]).read()
doc = json.load(open(sys.argv[2]))
sections = re.split(r'<section id="a\d+">', page)[1:]
bad, n = [], 0
for sec, res in zip(sections, doc["analyses"]):
    for kv in res["key_values"]:
        if kv["value"] is None:
            continue
        m = re.search(r'<tr><td>%s</td><td class="num">([^<]*)</td>' % re.escape(html.escape(kv["name"])), sec)
        n += 1
        if not m or m.group(1) != "%.10g" % kv["value"]:
            bad.append("%s: page %s, JSON %.10g" % (kv["name"], m.group(1) if m else "none", kv["value"]))
print("%d key values%s" % (n, (": " + "; ".join(bad)) if bad else ""))
sys.exit(1 if bad or n == 0 else 0)
PY
)
    [ $? -eq 0 ] && pass "the page's key values are the JSON's ($msg)" || fail "key values: $msg"
fi

why=""
grep -q -i '<script' "$P" && why="$why a script;"
grep -E -q '(src|href)="(https?:|//|file:)' "$P" && why="$why an external reference;"
grep -E -q '<link|@import|url\(' "$P" && why="$why a stylesheet or url() to fetch;"
nimg=$(grep -o '<img ' "$P" | wc -l)
ndata=$(grep -o '<img alt="[^"]*" src="data:image/svg+xml,' "$P" | wc -l)
want=15  # with the modes' plan-view animations (modeK_animation_top)
[ "$HAVE" = yes ] || want=0
[ "$nimg" -eq "$want" ] && [ "$ndata" -eq "$want" ] || why="$why $nimg images ($ndata SVG data URIs), not $want;"
if [ "$HAVE" = yes ]; then
    nsvg=$(find "$T/o/page/pictures" -name '*.svg' | wc -l)
    npng=$(find "$T/o/page/pictures" -name '*.png' | wc -l)
    [ "$nsvg" -eq "$want" ] && [ "$npng" -eq 0 ] || why="$why $nsvg SVG and $npng PNG files, not $want and 0;"
else
    grep -q '<p>No pictures: ' "$P" || why="$why no word on the missing pictures;"
fi
check "self-contained: no script, no external reference, $want pictures inside as SVG data URIs (and as files)" "$why"

why=""
grep -q 'wrote .*\.png' "$T/out" && why="$why stdout names PNG files it did not write;"
grep -q "^wrote $T/o/page/index.html (5 analyses, $want pictures, [0-9]* bytes) and $T/o/page/results.json\$" "$T/out" || why="$why no closing line: $(tail -1 "$T/out");"
check "standard output names the files written, and only those" "$why"

# 2. A failing analysis: what ran, marked; the rest not run.
fresh
ts report "$FAILS" -o "$T/o/f" --quiet
P=$T/o/f/index.html
why=""
[ "$status" -eq 1 ] || why="$why exit $status, not 1;"
[ -s "$P" ] || why="$why no page;"
grep -q 'The run did not complete' "$P" || why="$why not marked incomplete;"
grep -q 'h_min 0.5 s' "$P" || why="$why not the reason;"
grep -q '<strong>not run</strong>' "$P" || why="$why the third analysis not marked not run;"
grep -q '"completed": false' "$T/o/f/results.json" || why="$why results.json not completed false;"
grep -q '<title>towstab report: report &lt;fails&gt; &amp; stops</title>' "$P" || why="$why the name's markup is not escaped;"
grep -q '<fails>' "$P" && why="$why raw markup from the scene;"
check "a failing analysis: exit 1, the page of what ran marked incomplete, the rest not run, names escaped" "$why"

# 3. Bad input: exit 2, nothing written.
bad() { # bad WHAT GIST ARGS...
    local what=$1 gist=$2
    shift 2
    fresh
    ts "$@"
    local why=""
    [ "$status" -eq 2 ] || why="$why exit $status, not 2;"
    grep -q -- "$gist" "$T/err" || why="$why message: $(head -1 "$T/err");"
    [ -z "$(find "$T/o" -name index.html)" ] || why="$why a page was written;"
    check "$what: exit 2 ($(head -1 "$T/err" | cut -c1-90))" "$why"
}
bad "no -o" "-o DIR: expected the directory" report "$ALL"
bad "an empty -o" "got an empty name" report "$ALL" -o ""
touch "$T/file"
bad "-o a file" "not a directory" report "$ALL" -o "$T/file"
bad "--units bad" "--units: 'cubits': expected si, imperial or QUANTITY=UNIT" report "$ALL" -o "$T/o/x" --units cubits
bad "an unknown option" "unknown option '--speed'" report "$ALL" -o "$T/o/x" --speed 3
printf 'name: none\ntow: {speed: 1}\ncables:\n  - {name: c, from: tow, length: 5, diameter: 0.01, mass_per_length: 0.1, links: 2}\n' >"$T/none.yaml"
bad "a scene without analyses" "lists no analyses" report "$T/none.yaml" -o "$T/o/x"
bad "a missing scene" "cannot open" report "$T/missing.yaml" -o "$T/o/x"
finish
