#!/usr/bin/env bash
# Memory soak benchmark: runs `boxd serve` on the simulated station (config/sim.yaml), makes N
# measurements over HTTP one after the other and prints the daemon's resident memory after each.
# Usage: scripts/soak.sh [N=30] [PORT=18555]   (after a build: build/daemon/boxd)
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-30}
PORT=${2:-18555}
BOXD=${BOXD:-build/daemon/boxd}
DATA=$(mktemp -d)
"$BOXD" serve --config config/sim.yaml --listen "127.0.0.1:$PORT" --data-dir "$DATA/data" \
    2>"$DATA/serve.log" &
PID=$!
trap 'kill $PID 2>/dev/null; wait $PID 2>/dev/null; rm -rf "$DATA"' EXIT
for _ in $(seq 1 150); do
    curl -sf "localhost:$PORT/v1/health" >/dev/null && break
    sleep 0.2
done
rss() { awk '/VmRSS/ {printf "%.1f", $2 / 1024}' "/proc/$PID/status"; }
echo "started: RSS $(rss) MB"
for i in $(seq 1 "$N"); do
    code=$(curl -s -X POST "localhost:$PORT/v1/measure?wait=1" -o /dev/null -w '%{http_code}')
    echo "measurement $i: HTTP $code, RSS $(rss) MB"
done
