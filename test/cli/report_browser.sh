#!/bin/bash
# test/cli/report_browser.sh: the page of `towstab report` in a real
# browser, Debian's chromium, headless (doc/manual.md, "towstab report").
#
#   report_browser.sh TOWSTAB yes|no   (yes: towstab was built with PLplot)
#
# Run from the project root (meson does, suite 'cli'). For each scene: the
# page is made, copied alone into a fresh folder (so that it can only
# show what it holds), test/cli/report_check.js is appended to the copy,
# and chromium --dump-dom loads it at 1280 and at 1000 px wide; the
# script's results come back in the DOM: every image loads (naturalWidth
# > 0, an SVG data URI), no cell, paragraph, heading or caption overflows
# its box, every table fits the page, nothing but data URIs is fetched;
# and the page has the number of pictures expected (none without PLplot).
# Without chromium the test is skipped (exit status 77): tools/setup.sh
# installs it (and so CI, .ci/run, which runs setup.sh).
set -u

if [ $# -ne 2 ]; then
    echo "usage: report_browser.sh TOWSTAB yes|no" >&2
    exit 2
fi
TOWSTAB=$1
HAVE=$2
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$CHROMIUM" ]; then
    echo "SKIP chromium is not installed (apt-get install chromium, or tools/setup.sh)"
    exit 77
fi
. test/cli/common.sh

# browse PAGE WIDTH: PAGE with the checks appended, loaded by chromium at
# WIDTH px; the checks' lines into $T/checks. 0, or 1 after a FAIL line
# saying why there are none.
browse() {
    local page=$1 width=$2 what=$3
    { echo "<script>"; cat test/cli/report_check.js; echo "</script>"; } \
        >>"$page"
    rm -rf "$T/profile"
    mkdir "$T/profile"
    timeout 120 "$CHROMIUM" --headless --no-sandbox --disable-gpu \
        --disable-quic --no-first-run --disable-background-networking \
        --disable-component-update --disable-sync \
        --user-data-dir="$T/profile" --window-size="$width,900" \
        --virtual-time-budget=20000 --dump-dom \
        "file://$page" >"$T/dom" 2>"$T/chromium.err"
    local st=$?
    # The results are the text of the element the checks add.
    sed -n '/^<pre id="towstab-checks">/,/^DONE/p' "$T/dom" |
        sed 's/^<pre id="towstab-checks">//; s/&gt;/>/g; s/&lt;/</g; s/&amp;/\&/g' \
            >"$T/checks"
    if [ "$st" -ne 0 ] || ! grep -q '^DONE' "$T/checks"; then
        fail "$what: chromium exits $st without the checks' results: $(tail -3 "$T/chromium.err" | tr '\n' ' ')"
        return 1
    fi
}

# The checks themselves, on a page with one fault of each kind: each
# must fail.
mkdir "$T/plant"
cat >"$T/plant/page.html" <<'HTML'
<!DOCTYPE html><html><head><meta charset="utf-8"></head><body><main>
<p style="width:100px;white-space:nowrap">averyveryverylongunbreakablewordthatdoesnotfit</p>
<div class="wide" style="width:200px;overflow-x:auto"><table><tr><td style="white-space:nowrap">aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa</td></tr></table></div>
<img alt="broken" src="data:image/svg+xml,notsvg">
<img alt="remote" src="http://127.0.0.1:9/x.svg">
<div style="width:3000px">wide</div>
</main></body></html>
HTML
if browse "$T/plant/page.html" 1000 "planted faults"; then
    for gist in "every image loads.*: not broken; remote" \
                "none overflows: p 'averyvery" \
                "tables fit the page without scrolling: tr 'aaaa" \
                "the page is no wider than the window" \
                "nothing fetched but data URIs.*127.0.0.1"; do
        grep -q "^FAIL .*$gist" "$T/checks" &&
            pass "the checks catch a planted fault: $gist" ||
            fail "the checks miss a planted fault: $gist ($(tr '\n' '|' <"$T/checks"))"
    done
fi

# page NAME SCENE PICTURES: make the page of SCENE, load it alone at two
# widths, expect PICTURES images (when built with PLplot).
page() {
    local name=$1 scene=$2 want=$3 width
    rm -rf "$T/$name"
    mkdir -p "$T/$name/alone"
    ts report "$scene" -o "$T/$name/out" --quiet
    if [ "$status" -ne 0 ] || [ ! -s "$T/$name/out/index.html" ]; then
        fail "$name: towstab report exits $status: $(head -c 300 "$T/err")"
        return
    fi
    [ "$HAVE" = yes ] || want=0
    for width in 1280 1000; do
        cp "$T/$name/out/index.html" "$T/$name/alone/page.html"
        browse "$T/$name/alone/page.html" "$width" "$name at $width px" ||
            continue
        while read -r word rest; do
            case "$word" in
            PASS) pass "$name at $width px: $rest" ;;
            FAIL) fail "$name at $width px: $rest" ;;
            IMAGES)
                [ "$rest" -eq "$want" ] &&
                    pass "$name at $width px: $rest pictures, as drawn" ||
                    fail "$name at $width px: $rest pictures, expected $want" ;;
            esac
        done <"$T/checks"
    done
}

# Every kind of analysis (pictures: side, top; eigenvalues, modes; bode;
# histories, snapshots_side, snapshots_top; error_time).
page all_kinds test/cli/report/all_kinds.yaml 15
# A response in a sea (the spectral tables of doc/seastate.md; no
# picture of a sea-state response) after an equilibrium (side, top).
page survey_tow_sea examples/survey_tow_sea.yaml 2
finish
