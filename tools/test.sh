#!/usr/bin/env bash
# The whole test suite: every GPU test runs on the chosen Vulkan device
# (lavapipe on machines without a GPU) with VK_LAYER_KHRONOS_validation and
# synchronization validation, and fails on any warning or error message.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
export VKHAIR_VALIDATION=1
# A cold build (CI) gains nothing from incremental caches: writing them costs
# about a tenth of the build. CARGO_INCREMENTAL=1 keeps them.
export CARGO_INCREMENTAL=${CARGO_INCREMENTAL:-0}
# Quiet loader noise about XDG_RUNTIME_DIR on headless machines.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
cargo test --workspace --locked "$@"
# ASYNC COMPUTE on a real second queue: only where a device has one (lavapipe
# does not; the same code path runs on its graphics queue in the suite above).
# The program the tests just built (`cargo run -p vkhair-tools` would build the
# crate again with the tool's features alone: 41 s here).
devices=$("${CARGO_TARGET_DIR:-target}/debug/vkhair" devices 2>/dev/null || true)
if grep -q "async compute queue: yes" <<<"$devices"; then
  cargo test --locked --test suite "$@" -- --ignored schedule::async_compute_on_a_second_queue
else
  echo "skipped: async compute on a real second queue (no device here has one)"
fi
# The documentation builds without a warning (broken links, missing docs).
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked --quiet
echo "docs: cargo doc has no warnings"
# The asset readers under libFuzzer for a short while each, where a nightly
# toolchain and cargo-fuzz are installed (VKHAIR_FUZZ_SECONDS=0 skips).
seconds=${VKHAIR_FUZZ_SECONDS:-20}
if [ "$seconds" = 0 ]; then
  echo "fuzz: skipped (VKHAIR_FUZZ_SECONDS=0)"
elif cargo +nightly fuzz --version >/dev/null 2>&1; then
  for target in hair tfx obj abc usda usdc gltf; do
    (cd fuzz && cargo +nightly fuzz run "$target" -- -max_total_time="$seconds" -rss_limit_mb=2048)
  done
  echo "fuzz: hair, tfx, obj, abc, usda, usdc and gltf ran ${seconds} s each without a crash"
else
  echo "fuzz: skipped (needs a nightly toolchain and cargo-fuzz: rustup toolchain install nightly; cargo install cargo-fuzz)"
fi
