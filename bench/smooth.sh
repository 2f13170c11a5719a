#!/usr/bin/env bash
# Smoothing benchmark: Meshwork and the peers on the same files, in one session (report ratios).
# usage: bench/smooth.sh [--blender]   (Blender's modifier on the 556k mesh takes minutes to an hour)
# Needs the peers' venv (../shared/tools/peers/setup.sh) and, for --blender, Debian's blender 3.4.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${SMOOTH_BENCH_DIR:-/tmp/smooth-bench}
venv=${PEERS_VENV:-$HOME/.cache/meshwork-peers}
mkdir -p "$out"
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-/work/target-release}
cargo build --release -q -p meshwork-core --example bench_smooth --manifest-path "$root/Cargo.toml"
bin=$CARGO_TARGET_DIR/release/examples/bench_smooth
bunny=$root/../shared/meshes/stanford-bunny.obj
# Same vertices for everyone: unreferenced vertices dropped; the big mesh is the bunny subdivided twice.
"$bin" --write-subdivided "$out/bunny.obj" 0 "$bunny"
"$bin" --write-subdivided "$out/bunny-sub2.obj" 2 "$bunny"
cd "$out"
"$bin" bunny.obj bunny-sub2.obj
"$venv/bin/python" "$root/bench/smooth_peers.py" bunny.obj bunny-sub2.obj
if [[ "${1:-}" == "--blender" ]]; then
  for m in bunny.obj bunny-sub2.obj; do
    blender -b --factory-startup --python "$root/bench/smooth_blender.py" -- "$out/$m" 100 2>/dev/null | grep blender
  done
  blender -b --factory-startup --python "$root/bench/smooth_blender.py" -- "$out/bunny.obj" 1 2>/dev/null | grep blender
fi
