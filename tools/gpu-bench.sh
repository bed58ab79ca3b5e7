#!/usr/bin/env bash
# `vkhair bench` on the machine's real GPU (lavapipe and other CPU devices are
# refused): every stage beside its CPU reference, recorded work, the bound at
# the memory bandwidth of named GPUs, scaling curves. Writes out/gpu-bench/
# bench.json, scaling.csv and scaling.png; pass extra `vkhair bench` flags
# after the script's name (e.g. --samples 50).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
cargo build --release -p vkhair-tools
vkhair=target/release/vkhair
out=${VKHAIR_OUT:-out/gpu-bench}
# vkhair chooses a discrete GPU over an integrated, virtual or CPU one (set
# VKHAIR_DEVICE to pick another); --require-gpu refuses a CPU device.
"$vkhair" bench --require-gpu --out "$out" --json "$out/bench.json" "$@"
