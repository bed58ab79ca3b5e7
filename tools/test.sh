#!/usr/bin/env bash
# The whole test suite: every GPU test runs on the chosen Vulkan device
# (lavapipe on machines without a GPU) with VK_LAYER_KHRONOS_validation and
# synchronization validation, and fails on any warning or error message.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
export VKHAIR_VALIDATION=1
# Quiet loader noise about XDG_RUNTIME_DIR on headless machines.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
cargo test --workspace --locked "$@"
# The documentation builds without a warning (broken links, missing docs).
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked --quiet
echo "docs: cargo doc has no warnings"
