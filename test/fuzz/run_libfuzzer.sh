#!/bin/sh
# run_libfuzzer.sh FUZZER SEED_CORPUS DICT WORKDIR SECONDS [LIBFUZZER_ARGS...]
#
# A bounded libFuzzer run for the test suite (suite 'fuzz', meson
# -Dfuzz=true): copies the seed corpus into WORKDIR/corpus (in the build
# directory, so the source tree is never written to), fuzzes for SECONDS,
# and keeps any crashing input in WORKDIR/artifacts/. Exit status: the
# fuzzer's (0 when nothing was found).
set -eu
if [ $# -lt 5 ]; then
  echo "usage: run_libfuzzer.sh FUZZER SEED_CORPUS DICT WORKDIR SECONDS" \
    "[ARGS...]" >&2
  exit 2
fi
fuzzer=$1 seeds=$2 dict=$3 work=$4 secs=$5
shift 5
rm -rf "$work"
mkdir -p "$work/corpus" "$work/artifacts"
cp "$seeds"/* "$work/corpus/"
status=0
"$fuzzer" -max_total_time="$secs" -dict="$dict" -timeout=10 \
  -rss_limit_mb=2048 -max_len=8192 -print_final_stats=1 \
  -artifact_prefix="$work/artifacts/" "$@" "$work/corpus" || status=$?
if [ "$status" -ne 0 ]; then
  echo "run_libfuzzer: $fuzzer failed (status $status);" \
    "inputs kept in $work/artifacts:" >&2
  ls -l "$work/artifacts" >&2
  echo "run_libfuzzer: replay one with: $fuzzer $work/artifacts/<file>" >&2
fi
exit "$status"
