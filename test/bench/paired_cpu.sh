# paired_cpu.sh: sourced by the whole-process benchmarks (accuracy_cost.sh,
# integrator_cost.sh). Needs TOWSTAB and RUNS set; `row` prints one table
# row of the median CPU seconds of two variants of a command, run
# alternately (A, B, A, B, ...) so that a change of load hits both alike.
TIMEFORMAT='%U %S'

# cpu CMD...: CPU seconds (user + system) of one run of CMD.
cpu() {
    local t
    t=$( { time "$@" >/dev/null 2>&1; } 2>&1 ) || true
    awk '{ printf "%.4f\n", $1 + $2 }' <<<"$t"
}

median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

# row LABEL "A options" "B options" COMMAND ARGS...
row() {
    local label=$1 a=$2 b=$3
    shift 3
    ta=() tb=()
    for ((i = 0; i < RUNS; i++)); do
        # shellcheck disable=SC2086
        ta+=("$(cpu "$TOWSTAB" "$@" $a)")
        # shellcheck disable=SC2086
        tb+=("$(cpu "$TOWSTAB" "$@" $b)")
    done
    row_of "$label"
}

# row_of LABEL: the row of the CPU seconds in the arrays ta and tb, with
# DIGITS decimals (default 3).
row_of() {
    local ma mb
    ma=$(printf '%s\n' "${ta[@]}" | median)
    mb=$(printf '%s\n' "${tb[@]}" | median)
    awk -v l="$1" -v a="$ma" -v b="$mb" -v d="${DIGITS:-3}" \
        'BEGIN { printf "| %s | %.*f | %.*f | %.2f |\n", l, d, a, d, b, a / b }'
}

