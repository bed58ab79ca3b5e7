#!/usr/bin/env bash
# vkhair on the machine's real GPU, in one report (out/gpu-bench/report.txt):
#
#   1. the README's goals, each a `vkhair` run with its per-pass JSON beside it
#      under goals/:
#        a. the thesis scene's full frame at 1920×1080 with its two shadowed
#           spot lights (thesis_frame.json);
#        b. the simulation of 100,000 guides × 32 points with FLIP on a 64³
#           grid (guides_step.json; the guides grown on a sphere first);
#        c. 1,001,000 drawn strands (the thesis' 1,750 key hairs × 572, level of
#           detail off) with transparency (the default exact mode) at
#           1920×1080 (strands_frame.json);
#   2. `vkhair bench --require-gpu` (bench.json, scaling.csv, scaling.png):
#      every stage beside its CPU reference, recorded work, the bound at the
#      memory bandwidth of named GPUs, scaling curves; extra `vkhair bench`
#      flags go after the script's name (e.g. --samples 50).
#
# vkhair picks a discrete GPU over an integrated, virtual or CPU one
# (VKHAIR_DEVICE picks another); the bench refuses a CPU device. VKHAIR_OUT
# moves the output folder; VKHAIR_BIN runs that vkhair program instead of
# building one. `--smoke` (first argument) runs the goals' commands at toy
# sizes on any device and skips the bench: it checks this script, not a GPU.
set -euo pipefail
cd "$(dirname "$0")/.."
smoke=0
if [ "${1:-}" = "--smoke" ]; then
  smoke=1
  shift
fi
if [ -n "${VKHAIR_BIN:-}" ]; then
  vkhair=$VKHAIR_BIN
else
  bash tools/setup-debian.sh
  cargo build --release -p vkhair-tools
  vkhair=target/release/vkhair
fi
out=${VKHAIR_OUT:-out/gpu-bench}
goals="$out/goals"
mkdir -p "$goals"
if [ "$smoke" = 1 ]; then
  width=160 height=120 frames=2 steps=3 guides=300 grid=16 per_key=4
else
  width=1920 height=1080 frames=120 steps=120 guides=100000 grid=64 per_key=572
fi
report="$out/report.txt"
log="$goals/log.txt"
: >"$log"

# Runs one goal: its name, then the vkhair command; keeps the command's output
# in the log and its device and mean GPU total per frame or step in the report.
run_goal() {
  local name=$1
  shift
  "$vkhair" "$@" >"$log.last" 2>&1 || {
    cat "$log.last" >&2
    echo "gpu-bench: $name failed: vkhair $*" >&2
    exit 1
  }
  cat "$log.last" >>"$log"
  {
    echo "$name"
    echo "  vkhair $*"
    # The header line names the device and the scene; the per-pass table ends
    # with the total.
    grep -m1 " key hairs × " "$log.last" | sed 's/^/  /' || true
    # The first table is the frame's (graphics queue) or the step's; a render
    # whose simulation ran on a queue of its own has a second one.
    grep "^total" "$log.last" | head -n 1 | sed 's/^total */  GPU ms per frame or step (timestamps, mean): /'
    grep "^total" "$log.last" | sed -n 2p | sed 's/^total */  the simulation, on its own queue alongside (timestamps, mean): /'
  } >>"$report"
}

{
  echo "vkhair gpu-bench, $(date -u +%Y-%m-%dT%H:%MZ)$([ "$smoke" = 1 ] && echo ', smoke sizes')"
  echo
} >"$report"
run_goal "a. thesis full frame, ${width}×${height}, two shadowed spot lights" \
  render --width "$width" --height "$height" --frames "$frames" --out "$goals/thesis" --json "$goals/thesis_frame.json"
"$vkhair" grow --scalp sphere --strands "$guides" --points 32 --out "$goals/guides.hair" >>"$log" 2>&1
run_goal "b. simulation of $guides guides × 32 points, FLIP on a ${grid}³ grid" \
  simulate --input "$goals/guides.hair" --guides all --points 32 --volume flip --grid "$grid" --steps "$steps" \
  --json "$goals/guides_step.json"
run_goal "c. $((1750 * per_key)) drawn strands with transparency, ${width}×${height}" \
  render --width "$width" --height "$height" --frames "$frames" --hairs-per-key "$per_key" --no-lod \
  --out "$goals/strands" --json "$goals/strands_frame.json"
rm -f "$log.last"
if [ "$smoke" = 0 ]; then
  "$vkhair" bench --require-gpu --out "$out" --json "$out/bench.json" "$@"
  echo "bench: $out/bench.json" >>"$report"
fi
cat "$report"
