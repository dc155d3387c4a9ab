#!/usr/bin/env bash
# Runs the test suite N times in a row (default 5) while one busy loop per core keeps every core
# loaded, stopping at the first failing run: the check that no test depends on an idle machine.
#   scripts/loaded_runs.sh [N]      (after scripts/dev.sh build; BUILD_DIR as there)
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-5}
BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-$(nproc)}

LOAD_PIDS=()
stop_load() { kill "${LOAD_PIDS[@]}" 2>/dev/null || true; }
trap stop_load EXIT
for _ in $(seq 1 "$(nproc)"); do
    ( while :; do :; done ) &
    LOAD_PIDS+=($!)
done
echo "loaded_runs: ${#LOAD_PIDS[@]} busy loops started"

for run in $(seq 1 "$RUNS"); do
    start=$(date +%s)
    if ! (cd "$BUILD_DIR" && ctest --output-on-failure -j "$JOBS" > "ctest-loaded-$run.log" 2>&1); then
        grep -E "tests passed|\*\*\*Failed|\*\*\*Timeout" "$BUILD_DIR/ctest-loaded-$run.log" >&2 || true
        echo "loaded_runs: run $run of $RUNS failed; its log is $BUILD_DIR/ctest-loaded-$run.log" >&2
        exit 1
    fi
    echo "loaded_runs: run $run of $RUNS: $(grep -E 'tests passed' "$BUILD_DIR/ctest-loaded-$run.log") ($(( $(date +%s) - start )) s)"
done
echo "loaded_runs: all $RUNS runs passed under load"
