#!/bin/sh
# Validate/repair benchmark: ours (bench_repair, release) and the peers (trimesh, pymeshlab) on the
# same shared meshes, one after the other in the same run. Usage: bench/repair.sh [MESH_DIR]
set -e
cd "$(dirname "$0")/.."
MESHES=${1:-../shared/meshes}
PY=${PEERS_PY:-$HOME/.cache/meshwork-peers/bin/python}
CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-/work/target-release} cargo build --release -q -p meshwork-core --example bench_repair
echo "== meshwork (best of 7; validate and repair from memory, read excluded)"
"${CARGO_TARGET_DIR:-/work/target-release}/release/examples/bench_repair" "$MESHES"
echo "== peers (best of 3, from memory)"
"$PY" bench/repair_peers.py "$MESHES"/*.obj 2>/dev/null
