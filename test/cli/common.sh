# test/cli/common.sh: what the command-line test scripts share (sourced).
# Sets T to a fresh folder (removed on exit) and defines:
#   pass TEXT, fail TEXT    one PASS/FAIL line, counted
#   check TEXT WHY          pass when WHY is empty, else fail with WHY
#   ts ARGS...              run $TOWSTAB: stdout in $T/out, stderr in
#                           $T/err, exit status in $status
#   fresh                   an empty output folder $T/o
#   finish                  the "N passed, N failed" line and exit status
T=$(mktemp -d "${TMPDIR:-/tmp}/towstab-cli-XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
npass=0
nfail=0
pass() { echo "PASS $*"; npass=$((npass + 1)); }
fail() { echo "FAIL $*"; nfail=$((nfail + 1)); }
check() {
    if [ -z "$2" ]; then pass "$1"; else fail "$1:$2"; fi
}
ts() {
    "$TOWSTAB" "$@" >"$T/out" 2>"$T/err"
    status=$?
}
fresh() {
    rm -rf "$T/o"
    mkdir "$T/o"
}
finish() {
    echo "$npass passed, $nfail failed"
    [ "$nfail" -eq 0 ]
    exit
}
