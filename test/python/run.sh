#!/bin/bash
# test/python/run.sh: the Python package's tests (test_towstab.py,
# test_progress.py, test_install.py) and its
# example (examples/python/), with Debian's python3-pytest and numpy.
#   run.sh PYTHON BUILD_DIR TOWSTAB LIBRARY SANITIZE
# Run from the project root. Skipped (77) without pytest or numpy; the
# example is run when matplotlib is there (tools/setup.sh installs it).
# With an instrumented library (SANITIZE not "none") the sanitizer's
# runtime is preloaded into the interpreter, leaks not checked (the
# interpreter's own are many).
set -u
if [ $# -ne 5 ]; then
    echo "usage: run.sh PYTHON BUILD_DIR TOWSTAB LIBRARY SANITIZE" >&2
    exit 2
fi
PY=$1 BUILD=$2 TOWSTAB=$3 LIBRARY=$4 SANITIZE=$5
if ! "$PY" -c 'import pytest, numpy' 2>/dev/null; then
    echo "SKIP: $PY lacks pytest or numpy (apt-get install python3-pytest python3-numpy)"
    exit 77
fi
export PYTHONPATH=$BUILD/python TOWSTAB_LIBRARY=$LIBRARY TOWSTAB_EXE=$TOWSTAB
export TOWSTAB_SOURCE=$PWD PYTHONDONTWRITEBYTECODE=1
# One BLAS thread, as the command line runs by default: with numpy's
# (one per core) the BLAS sums in another order and the last digits of a
# simulation differ from the command line's (doc/python.md, Tests).
export OPENBLAS_NUM_THREADS=1
if [ "$SANITIZE" != none ]; then
    pre=""
    for rt in libasan.so libubsan.so; do
        f=$(gcc -print-file-name=$rt 2>/dev/null)
        [ -f "$f" ] && pre="$pre $f"
    done
    export LD_PRELOAD=${pre# } ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0
fi
"$PY" -m pytest -q -p no:cacheprovider test/python
