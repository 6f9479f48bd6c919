#!/bin/bash
# docrefs.sh: the project carries its own model (doc/model.md).
#  1. No file other than doc/model.md names the model by another file name
#     (an upper-case MODEL file) or points outside the project at the papers
#     or notes it was started from (paths of the shared folder or of the
#     working machine, the papers' file names).
#  2. Every "doc/model.md section N" (also "sections N-M", "N and M",
#     "N, M", across a line break or a comment marker) names a section that
#     doc/model.md has, as a heading "## N. ...".
# Files: those git tracks, or, outside a git checkout, every file below the
# source root except build directories. Run from the project root.
set -u
cd "${MESON_SOURCE_ROOT:-.}" || exit 2
model=doc/model.md
[ -f "$model" ] || { echo "FAIL: $model is missing"; exit 1; }

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    mapfile -t files < <(git ls-files)
else
    mapfile -t files < <(find . -type f ! -path './.git/*' ! -path './build*' \
                              ! -path './subprojects/*' | sed 's|^\./||')
fi
# Text files only (binary pictures cannot name a section), in one pass.
existing=()
for f in "${files[@]}"; do
    [ -f "$f" ] && existing+=("$f")
done
mapfile -t text < <(grep -lI . -- "${existing[@]}")

fail=0
# The patterns are written so that this file does not match them itself.
forbidden='MODEL[.]md|[.][.]/shared|/work[/](shared|notes)|shared[/]seeds|seeds[/]0[0-9]{2}_|seed 00[0-9]'
others=()
for f in "${text[@]}"; do
    [ "$f" = "$model" ] || others+=("$f")
done
hits=$(grep -nE "$forbidden" -- "${others[@]}")
if [ -n "$hits" ]; then
    echo "FAIL: references outside the project (cite doc/model.md and the papers by author and year):"
    echo "$hits"
    fail=1
else
    echo "PASS: no file but $model refers outside the project (${#others[@]} files)"
fi

# Sections doc/model.md has.
mapfile -t have < <(sed -n 's/^## \([0-9][0-9]*\)\. .*/\1/p' "$model")
declare -A exists=()
for n in "${have[@]}"; do exists[$n]=1; done
[ "${#have[@]}" -ge 9 ] || { echo "FAIL: $model has ${#have[@]} numbered sections, expected at least 9"; fail=1; }

# Every reference, with the file it is in. grep -z reads a file as one
# line, so a reference broken across lines (and comment markers) is seen.
sep='[[:space:]*#/"]*'
num='[0-9]+'
list="$num($sep(-|,|and|or)$sep$num)*"
refs=0 bad=0
while IFS= read -r -d '' hit; do
    f=${hit%%:*} m=${hit#*:}
    refs=$((refs + 1))
    nums=$(printf '%s' "$m" | sed -E 's/.*(section|sections|§)//' |
           tr -c '0-9-' ' ')
    # Expand ranges N-M.
    for tok in $nums; do
        if [[ $tok =~ ^([0-9]+)-([0-9]+)$ ]]; then
            seq_list=$(seq "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}")
        else
            seq_list=${tok//-/ }
        fi
        for n in $seq_list; do
            if [ -z "${exists[$n]:-}" ]; then
                echo "FAIL: $f: '$(printf '%s' "$m" | tr -s '[:space:]' ' ')' names section $n, which $model does not have"
                bad=$((bad + 1))
            fi
        done
    done
done < <(grep -HzoE "model[.]md,?$sep(sections?|§)$sep$list" -- "${text[@]}" |
         tr '\n' ' ')
if [ "$bad" -eq 0 ] && [ "$refs" -gt 0 ]; then
    echo "PASS: all $refs references to $model sections name one of its ${#have[@]} sections"
else
    [ "$refs" -gt 0 ] || echo "FAIL: no reference to a section of $model found (the search is broken)"
    fail=1
fi
exit $fail
