#!/usr/bin/env bash
# One long continuation of Method B's training on a lent GPU machine (the `device` tool), in one
# command: a fresh simulator dataset made there, training from continue.pt for a fixed wall time,
# and the weights and log copied to $OUT. Offline: Ultralytics travels as wheels in .whl/ and
# the simulator as a prebuilt binary in .gpu/ (both git-ignored, carried by the call).
#
#   run(command="bash training/gpu_run.sh", carry=[".whl", ".gpu"], timeout_s=600)
#
# Before the call, here (both folders listed in .git/info/exclude):
#   python3 -m pip download --no-deps --only-binary=:all: --python-version 3.12 \
#       --implementation cp --platform manylinux_2_28_x86_64 -d .whl \
#       ultralytics==8.4.190 ultralytics-thop
#   cargo build --release -p umbra-sim && mkdir -p .gpu && cp target/release/umbra-sim .gpu/
# The machine's own torch (2.11) and numpy, opencv, polars-free Ultralytics paths are used.
#
# Knobs (environment): SCENARIOS (16000), SEED (35; never an eval or test seed), HOURS (0.11),
# BATCH (128), LR0 (0.0005), WORKERS (14), DEVICE (0), PY (python3), NAME (gpu19), LIMIT (560:
# seconds from the start after which training is interrupted, so the weights saved at the last
# epoch still come back inside the call's 600 s), INIT (checkpoints/continue.pt, relative to
# training/), and the data's mix: VARIED (0), ROUND (0), OFFICE (0), PEOPLE (0), CLUTTER (6),
# WORN (0), the `umbra-sim dataset` options of the same names (`--round-tables`,
# `--office-chairs`, `--worn`: the share of scenarios seen by a worn LiDAR, `sim::wear`),
# KINDS (rect,tworooms), FRAMES (4), and how the images are drawn: SEAM (fixed; quiet) and
# DESKEW (0; 1: swept labels). The set's dataset.json comes back with the weights: export with
# `training/export.py --seam S --deskew true|false` as it says, so the files declare it.
# Run locally on CPU with e.g. `SCENARIOS=40 HOURS=0.005 DEVICE=cpu PY=.venv/bin/python
# OUT=/tmp/gpu-out bash training/gpu_run.sh` to check it before spending device time.
set -euo pipefail
SCENARIOS=${SCENARIOS:-16000}
SEED=${SEED:-35}
HOURS=${HOURS:-0.11}
BATCH=${BATCH:-128}
LR0=${LR0:-0.0005}
WORKERS=${WORKERS:-14}
DEVICE=${DEVICE:-0}
PY=${PY:-python3}
NAME=${NAME:-gpu19}
INIT=${INIT:-checkpoints/continue.pt}
VARIED=${VARIED:-0}
ROUND=${ROUND:-0}
OFFICE=${OFFICE:-0}
PEOPLE=${PEOPLE:-0}
CLUTTER=${CLUTTER:-6}
WORN=${WORN:-0}
KINDS=${KINDS:-rect,tworooms}
FRAMES=${FRAMES:-4}
SEAM=${SEAM:-fixed}
DESKEW=${DESKEW:-0}
DRAW=(--seam "$SEAM")
[ "$DESKEW" = 1 ] && DRAW+=(--deskew)
DATA=${DATA:-/tmp/umbra-gpu-data}
: "${OUT:?OUT must name a folder for the results}"
mkdir -p "$OUT"

if [ -d .whl ]; then
    "$PY" -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/site .whl/*.whl
    export PYTHONPATH=/tmp/site
fi
command -v nvidia-smi >/dev/null && nvidia-smi -L
echo "cpus $(nproc); shm: $(df -h /dev/shm | tail -1)"
# DataLoader workers pass batches through /dev/shm: few workers where it is small.
shm_kb=$(df -k --output=avail /dev/shm | tail -1)
[ "$shm_kb" -lt 2000000 ] && WORKERS=2 && echo "small /dev/shm: $WORKERS workers"

LIMIT=${LIMIT:-560}
t0=$(date +%s)
rm -rf "$DATA"
.gpu/umbra-sim dataset --out "$DATA" --scenarios "$SCENARIOS" --frames "$FRAMES" \
    --seed "$SEED" --kinds "$KINDS" --clutter "$CLUTTER" --varied "$VARIED" \
    --round-tables "$ROUND" --office-chairs "$OFFICE" --people "$PEOPLE" --worn "$WORN" "${DRAW[@]}" \
    --no-method-a --no-recordings --pictures 0 >"$OUT/dataset.log"
cp "$DATA/dataset.json" "$OUT/dataset.json"
echo "dataset: $(ls "$DATA/images/train" | wc -l) train images in $(( $(date +%s) - t0 )) s"

cd training
rm -rf "runs/$NAME"
set +e
PYTHONUNBUFFERED=1 timeout --signal=INT --kill-after=15 $(( LIMIT - ($(date +%s) - t0) )) \
    "$PY" train.py --data "$DATA/data.yaml" --device "$DEVICE" --workers "$WORKERS" \
    --batch "$BATCH" --epochs 100 --hours "$HOURS" --name "$NAME" \
    --init "$INIT" --lr0 "$LR0" --seed "$SEED" 2>&1 | tee "$OUT/train.log" | \
    tr '\r' '\n' | grep -a -v "it/s" | tail -n 80
rc=${PIPESTATUS[0]}
set -e
for f in best.pt last.pt; do
    [ -f "runs/$NAME/weights/$f" ] && cp "runs/$NAME/weights/$f" "$OUT/$NAME-$f"
done
[ -f "runs/$NAME/results.csv" ] && cp "runs/$NAME/results.csv" "$OUT/$NAME-results.csv"
echo "train.py exit $rc after $(( $(date +%s) - t0 )) s"
exit "$rc"
