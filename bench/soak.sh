#!/usr/bin/env bash
# A one-hour-equivalent soak: 18,000 frames (an hour of a 5 Hz LiDAR) on the simulated robot,
# as fast as it goes, sampling the process's resident memory every few seconds. Prints the
# samples, the growth from the first sample after warm-up to the last, and the run's deadline
# table. Not part of every CI run (minutes of CPU); run it by hand:
#
#   bench/soak.sh [FRAMES] [EXTRA UMBRA ARGS...]     e.g. bench/soak.sh 18000 --record /tmp/s.mcap
#
# Exit status 1 when resident memory grew by more than 1 MiB after warm-up.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-18000}; shift || true
cargo build --release -p umbra-firmware --bin umbra >&2
log=$(mktemp)
target/release/umbra run --frames "$frames" --speed max --quiet "$@" 2>"$log" &
pid=$!
samples=()
while kill -0 "$pid" 2>/dev/null; do
  rss=$(awk '/^VmRSS/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
  [ -n "$rss" ] && samples+=("$rss") && printf 't=%4ds  VmRSS %8d KiB\n' $(( ${#samples[@]} * 5 - 5 )) "$rss"
  sleep 5
done
wait "$pid"
grep -v '^\[INFO' "$log"; rm -f "$log"
n=${#samples[@]}
if [ "$n" -lt 3 ]; then echo "soak: too short to judge ($n samples)"; exit 0; fi
first=${samples[1]}; last=${samples[$((n - 1))]}; peak=$first
for s in "${samples[@]:1}"; do [ "$s" -gt "$peak" ] && peak=$s; done
echo "soak: $frames frames; VmRSS after warm-up ${first} KiB, at the end ${last} KiB, peak ${peak} KiB, growth $((last - first)) KiB"
[ $((last - first)) -le 1024 ]
