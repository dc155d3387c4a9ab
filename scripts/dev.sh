#!/usr/bin/env bash
# boxd developer entry point, used by the README's quick start and by CI.
#   scripts/dev.sh demo   install packages, build, measure a box on the simulated station
#   scripts/dev.sh test   install packages, build, run the whole test suite, then under ASan +
#                         UBSan each test the plain run took at most SANITIZE_MAX_SECONDS over,
#                         the drivers' and the service's tests under TSan, and each fuzzer for
#                         FUZZ_SECONDS
#   scripts/dev.sh deps   install packages only
#   scripts/dev.sh build  build only (into ./build)
#   scripts/dev.sh sanitize  clang build with ASan + UBSan (./build-sanitize), whole suite
#   scripts/dev.sh fuzz   the libFuzzer targets, FUZZ_SECONDS (60) each, on tests/fuzz/corpus
#   scripts/dev.sh tsan   clang build with ThreadSanitizer (./build-tsan): the daemon and the
#                         tests of the drivers, the service and the simulated turntable
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
    build-essential cmake ninja-build pkg-config git ca-certificates
    libeigen3-dev libpcl-dev libopencv-dev libceres-dev
    libmodbus-dev libopenni2-dev libfreenect-dev libusb-1.0-0-dev
    libyaml-cpp-dev nlohmann-json3-dev libcpp-httplib-dev libcli11-dev libspdlog-dev
    libsqlite3-dev libssl-dev libsystemd-dev libgtest-dev libembree-dev libpng-dev libdeflate-dev libmosquitto-dev
    mosquitto mosquitto-clients
    libjs-three chromium socat curl clang libclang-rt-14-dev python3-jsonschema help2man lintian
)
BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-$(nproc)}

deps() {
    # Only talk to the package servers when something is missing: a re-run costs a second.
    local missing=()
    for p in "${PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" \
            || missing+=("$p")
    done
    if [ ${#missing[@]} -eq 0 ]; then
        echo "dev.sh: all ${#PACKAGES[@]} packages present"
        return
    fi
    echo "dev.sh: installing ${missing[*]}"
    local sudo=""
    [ "$(id -u)" -eq 0 ] || sudo=sudo
    $sudo apt-get update
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends "${PACKAGES[@]}"
}

# Ninja compiles a target's files while the libraries they link are still being archived, where
# make's recursive passes wait for each target whole (one core idle at the end of each library).
GENERATOR=${BOXD_GENERATOR:-Ninja}

# Configures `dir` with the given options unless it already is: configuring a configured tree
# again reorders PCL's include directories, which rebuilds everything. (cmake --build still
# reconfigures by itself when a CMakeLists.txt changes.) A tree another generator made is
# configured afresh: cmake will not switch one in place.
configure() {
    local dir=$1 stamp="$2 $GENERATOR"
    shift 2
    if [ -f "$dir/CMakeCache.txt" ] && [ "$(cat "$dir/.dev-configured" 2>/dev/null)" = "$stamp" ]; then
        return
    fi
    if [ -f "$dir/CMakeCache.txt" ] &&
        ! grep -qx "CMAKE_GENERATOR:INTERNAL=$GENERATOR" "$dir/CMakeCache.txt"; then
        rm -rf "$dir/CMakeCache.txt" "$dir/CMakeFiles"
    fi
    cmake -S . -B "$dir" -G "$GENERATOR" "$@"
    echo "$stamp" > "$dir/.dev-configured"
}

build() {
    local werror=OFF
    [ "${CI:-}" = "true" ] && werror=ON
    configure "$BUILD_DIR" "werror=$werror" -DCMAKE_BUILD_TYPE=Release -DBOXD_WERROR="$werror"
    # Targets as arguments (the demo needs only boxd); none builds everything, tests included.
    local targets=()
    for t in "$@"; do targets+=(--target "$t"); done
    cmake --build "$BUILD_DIR" -j "$JOBS" "${targets[@]}"
}

demo() {
    # The daemon on the simulated station (config/sim.yaml: a sim-turntable child process driven
    # over Modbus TCP, the simulated camera), then one measurement through the REST API.
    local out port
    out=$(mktemp -d /tmp/boxd-demo.XXXXXX)
    port=${BOXD_DEMO_PORT:-8080}
    echo "dev.sh: starting boxd serve on 127.0.0.1:$port (simulated station, data in $out)"
    "$BUILD_DIR/daemon/boxd" serve --config config/sim.yaml --listen "127.0.0.1:$port" \
        --data-dir "$out" 2> "$out/boxd.log" &
    DEMO_PID=$!
    trap 'kill -TERM "$DEMO_PID" 2>/dev/null; wait "$DEMO_PID" 2>/dev/null || true' EXIT
    for _ in $(seq 1 150); do
        curl -sf "http://127.0.0.1:$port/v1/health" > /dev/null && break
        kill -0 "$DEMO_PID" 2>/dev/null || { cat "$out/boxd.log" >&2; exit 1; }
        sleep 0.2
    done
    echo "dev.sh: POST /v1/measure?wait=1 (the simulated box is 0.455 x 0.330 x 0.460 m)"
    curl -sS -X POST "http://127.0.0.1:$port/v1/measure?wait=1"
    echo
    echo "dev.sh: the daemon's log is $out/boxd.log"
}

run_tests() {
    (cd "$BUILD_DIR" && ctest --output-on-failure -j "$JOBS")
}

# One clang build serves both: ASan + UBSan everywhere, libFuzzer coverage in the libraries.
SAN_DIR=${SAN_DIR:-build-sanitize}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:strict_string_checks=1:check_initialization_order=1:detect_stack_use_after_return=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0}

sanitize_build() {
    CC=clang CXX=clang++ configure "$SAN_DIR" sanitize -DCMAKE_BUILD_TYPE=Release \
        -DBOXD_SANITIZE=ON -DBOXD_FUZZ=ON
    local targets=()
    for t in "$@"; do targets+=(--target "$t"); done
    cmake --build "$SAN_DIR" -j "$JOBS" "${targets[@]}"
}

# Under the sanitizers a test runs 10-20 times slower (the calibration's Ceres problems about 20).
# `scripts/dev.sh test` (CI) runs under ASan + UBSan each test the plain run before it took at
# most SANITIZE_MAX_SECONDS (1) over, as its cost file (ctest's) says: 566 of 649 tests, a
# fifth of the time all of them took there. The tests left out repeat the same code over more
# seeds, larger clouds or a daemon's whole run (the calibration through the CLI, the accuracy
# suite, the sweeps of L shapes), whose code the quicker tests also pass through. The Debian
# package and the operator page in Chromium check packaging and a browser, not boxd's memory:
# they run in the plain suite only. `sanitize` runs all.
SANITIZE_MAX_SECONDS=${SANITIZE_MAX_SECONDS:-1}
SANITIZE_KINDS_LEFT_OUT='^(package|browser)$'

# The tests the plain run in $BUILD_DIR took longer than SANITIZE_MAX_SECONDS over, as a ctest
# regular expression (none where it has not run).
slow_in_plain_run() {
    local costs="$BUILD_DIR/Testing/Temporary/CTestCostData.txt"
    [ -f "$costs" ] || return 0
    awk -v max="$SANITIZE_MAX_SECONDS" '/^---/ { exit } NF == 3 && $3 > max { print $1 }' \
        "$costs" | sed -e 's/[][\.*^$+?(){}|]/\\&/g' -e 's/.*/^&$/' | paste -sd '|'
}

# The sanitizer build and its tests; arguments go to ctest (none: the whole suite).
sanitize() {
    sanitize_build
    (cd "$SAN_DIR" && ctest --output-on-failure -j "$JOBS" "$@")
}

# CI's sanitizer run: the whole suite but the kinds and the slow tests above, building only the
# test executables that hold a test to run (the plain build's ctest names them).
sanitize_quick() {
    local slow
    slow=$(slow_in_plain_run)
    local args=(-LE "$SANITIZE_KINDS_LEFT_OUT" -E "${slow:+$slow|}_NOT_BUILT\$")
    local exes targets=(boxd) exe
    exes=$(cd "$BUILD_DIR" && ctest --show-only=json-v1 "${args[@]}" | python3 -c 'import json, sys
print("\n".join(sorted({t["command"][0] for t in json.load(sys.stdin)["tests"] if t.get("command")})))')
    [ -n "$exes" ] || { echo "dev.sh: no test to run under the sanitizers" >&2; return 1; }
    for exe in $exes; do targets+=("$(basename "$exe")"); done
    sanitize_build "${targets[@]}"
    (cd "$SAN_DIR" && ctest --output-on-failure -j "$JOBS" "${args[@]}")
}

fuzz() {
    sanitize_build fuzz_session fuzz_config fuzz_http
    local seconds=${FUZZ_SECONDS:-60} status=0
    for target in session config http; do
        # New inputs go to a scratch corpus; the seeds in the repository stay as they are.
        local work="$SAN_DIR/fuzz/$target"
        mkdir -p "$work/corpus" "$work/findings"
        echo "dev.sh: fuzz_$target for ${seconds} s"
        "$SAN_DIR/tests/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout=20 \
            -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
            -artifact_prefix="$work/findings/" "$work/corpus" "tests/fuzz/corpus/$target" \
            > "$work/log" 2>&1 || status=1
        grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb|^(==|SUMMARY)" "$work/log" || true
        if [ $status -ne 0 ]; then
            tail -n 60 "$work/log" >&2
            echo "dev.sh: fuzz_$target found a failure; the input is in $work/findings" >&2
            return 1
        fi
    done
}

# ThreadSanitizer: every process (the tests, and the daemons and simulators they start) writes
# its reports to one folder; any report fails the run, whatever the process's exit code was.
TSAN_DIR=${TSAN_DIR:-build-tsan}
TSAN_LABELS='^(drivers|drivers/sim|daemon/service)$'
# The tests built: the drivers', the service's, and of the simulators only the turntable (a Modbus
# server's thread); the rest of the simulators is one thread's physics.
TSAN_TESTS=(tests/drivers/*_test.cpp tests/drivers/sim/simulated_turntable_test.cpp
            tests/daemon/service/*_test.cpp)
# Not threads: packaging and a browser (as in the sanitizer run above), and the executables not
# built. The OpenNI2 recording test exercises OpenNI2's own recorder (libOniFile, its threads and
# locks uninstrumented), whose reports change from run to run without a frame of boxd's; the other
# camera tests stay. Calibrations through the daemon and a dump's import through the CLI run the
# threads a measurement runs, for minutes under TSan: ServeSimStation, ServeStartup and the
# measurements of the others stand for them.
TSAN_SKIP='DebianPackage[.]|OperatorPage[.]|OpenNi2Camera[.]RecordingOfTheDummyDeviceReadsBack'
TSAN_SKIP+='|ServeCalibrationHistory[.]|ServeAudit[.]Counts|FreenectStation[.]ImportDump|_NOT_BUILT$'

tsan() {
    local reports="$PWD/$TSAN_DIR/tsan-reports" status=0
    rm -rf "$reports"
    mkdir -p "$reports"
    # Also for the build: listing a test executable's tests runs it.
    export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:log_path=$reports/report"
    TSAN_OPTIONS+=":suppressions=$PWD/tests/tsan.supp"
    CC=clang CXX=clang++ configure "$TSAN_DIR" tsan -DCMAKE_BUILD_TYPE=Release -DBOXD_TSAN=ON
    local targets=(--target boxd) f
    for f in "${TSAN_TESTS[@]}"; do
        local stem=${f#tests/}
        stem=${stem%.cpp}
        targets+=(--target "${stem//\//_}")
    done
    cmake --build "$TSAN_DIR" -j "$JOBS" "${targets[@]}" || status=1
    if [ $status -eq 0 ]; then
        (cd "$TSAN_DIR" && ctest --output-on-failure -j "$JOBS" -L "$TSAN_LABELS" -E "$TSAN_SKIP") \
            || status=1
    fi
    if compgen -G "$reports/report*" > /dev/null; then
        echo "dev.sh: ThreadSanitizer reports:" >&2
        head -n 80 "$reports"/report* >&2
        status=1
    fi
    return $status
}

case "${1:-}" in
    demo) deps; build boxd; demo ;;
    test) deps; build; run_tests; sanitize_quick; tsan; fuzz ;;
    deps) deps ;;
    build) build ;;
    sanitize) deps; sanitize ;;
    fuzz) deps; fuzz ;;
    tsan) deps; tsan ;;
    *) echo "usage: scripts/dev.sh demo|test|deps|build|sanitize|fuzz|tsan" >&2; exit 2 ;;
esac
