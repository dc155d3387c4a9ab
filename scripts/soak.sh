#!/usr/bin/env bash
# Soak and cycle benchmark: runs `boxd serve` on the simulated station (CONFIG, default
# config/sim.yaml), makes N measurements over HTTP one after the other and prints each one's
# cycle (POST /v1/measure?wait=1 to its answer), the poses it took and why it stopped, its capture
# and processing (last frame to result) times and the daemon's resident memory after it.
# Usage: scripts/soak.sh [N=30] [PORT=18555]   (after a build: build/daemon/boxd)
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-30}
PORT=${2:-18555}
BOXD=${BOXD:-build/daemon/boxd}
CONFIG=${CONFIG:-config/sim.yaml}
DATA=$(mktemp -d)
"$BOXD" serve --config "$CONFIG" --listen "127.0.0.1:$PORT" --data-dir "$DATA/data" \
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
    code=$(curl -s -X POST "localhost:$PORT/v1/measure?wait=1" -o "$DATA/m.json" \
        -w '%{http_code} %{time_total}')
    times=$(python3 -c 'import json, sys
m = json.load(open(sys.argv[1]))
t, q = m.get("timing_ms", {}), m.get("quality", {})
print("%s poses, %s; capture %.2f s, processing %.3f s" % (q.get("poses"), q.get("stop_reason"),
      t.get("capture", 0) / 1e3, t.get("processing", 0) / 1e3))' \
        "$DATA/m.json" 2>/dev/null || echo "no timing")
    echo "measurement $i: HTTP ${code% *}, cycle ${code#* } s ($times), RSS $(rss) MB"
done
