#!/usr/bin/env bash
# The main job: list devices, grow the `thesis` reference scene, inspect it and
# simulate it on the GPU with the shaking-head motion (per-stage timing table,
# checked against the CPU reference). Later stages turn this into the renderer.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
cargo build --release -p vkhair-tools
vkhair=target/release/vkhair
out=${VKHAIR_OUT:-out}
mkdir -p "$out"
"$vkhair" devices
"$vkhair" grow --scalp thesis --out "$out/thesis.hair"
"$vkhair" inspect "$out/thesis.hair"
"$vkhair" simulate --steps 240 --check
