#!/usr/bin/env bash
# The main job: list devices, simulate and render the `thesis` scene headless
# (1750 key hairs → 28,000 hairs, shaking-head motion, three lights, two of them
# casting self-shadows through deep opacity maps): PNG frames, a contact sheet,
# a per-pass GPU timing table, and in out/ the same profile as a Chrome trace
# (trace.json: open it in Perfetto or chrome://tracing) and a JSON summary
# (run.json); then the simulation alone, with the FLIP volume stage on a 32³
# grid, checked against its CPU reference (simulate_trace.json).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
cargo build --release -p vkhair-tools
vkhair=target/release/vkhair
out=${VKHAIR_OUT:-out}
mkdir -p "$out"
"$vkhair" devices
"$vkhair" render --out "$out" --trace "$out/trace.json" --json "$out/run.json"
"$vkhair" simulate --steps 120 --check --trace "$out/simulate_trace.json" --json "$out/simulate.json"
