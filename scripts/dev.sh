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
    libsqlite3-dev libsystemd-dev libgtest-dev
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
    cmake --build "$BUILD_DIR" -j "$JOBS"
}

demo() {
    local out
    out=$(mktemp -d /tmp/boxd-demo.XXXXXX)
    echo "dev.sh: rendering a 0.455 x 0.330 x 0.460 m box on the simulated station into $out"
    "$BUILD_DIR/daemon/boxd" synth --out "$out/session" --dims 0.455 0.33 0.46 --poses 18 --frames 4
    echo "dev.sh: measuring it"
    "$BUILD_DIR/daemon/boxd" measure --session "$out/session"
}

run_tests() {
    cd "$BUILD_DIR"
    ctest --output-on-failure -j "$JOBS"
}

case "${1:-}" in
    demo) deps; build; demo ;;
    test) deps; build; run_tests ;;
    deps) deps ;;
    build) build ;;
    *) echo "usage: scripts/dev.sh demo|test|deps|build" >&2; exit 2 ;;
esac
