#!/usr/bin/env bash
# boxd developer entry point, used by the README's quick start and by CI.
#   scripts/dev.sh demo   install packages, build, measure a box on the simulated station
#   scripts/dev.sh test   install packages, build, run the whole test suite
#   scripts/dev.sh deps   install packages only
#   scripts/dev.sh build  build only (into ./build)
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
    build-essential cmake pkg-config git ca-certificates
    libeigen3-dev libpcl-dev libopencv-dev libceres-dev
    libmodbus-dev libopenni2-dev libusb-1.0-0-dev
    libyaml-cpp-dev nlohmann-json3-dev libcpp-httplib-dev libcli11-dev libspdlog-dev
    libsqlite3-dev libsystemd-dev libgtest-dev libembree-dev libpng-dev
    socat curl
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

build() {
    local werror=OFF
    [ "${CI:-}" = "true" ] && werror=ON
    cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DBOXD_WERROR="$werror"
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
    cd "$BUILD_DIR"
    ctest --output-on-failure -j "$JOBS"
}

case "${1:-}" in
    demo) deps; build boxd; demo ;;
    test) deps; build; run_tests ;;
    deps) deps ;;
    build) build ;;
    *) echo "usage: scripts/dev.sh demo|test|deps|build" >&2; exit 2 ;;
esac
