#!/usr/bin/env bash
# Formats benchmark, meshwork and trimesh on the same files in the same run; prints ratios.
# usage: bench/io.sh [MESH.obj] [SUBDIVISION_LEVELS]     (from the project root)
# Needs the peers' venv (../shared/tools/peers/setup.sh → ~/.cache/meshwork-peers).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-/tmp/meshwork-bench-io}
TARGET=${CARGO_TARGET_DIR:-/work/target-release}
PY=${PEERS_PYTHON:-$HOME/.cache/meshwork-peers/bin/python}
mkdir -p "$OUT"
CARGO_TARGET_DIR=$TARGET cargo build --release --example bench_io -p meshwork-core >&2
"$TARGET/release/examples/bench_io" "${1:-../shared/meshes/stanford-bunny.obj}" --levels "${2:-3}" --out "$OUT" \
    | tee "$OUT/meshwork.tsv"
"$PY" bench/io_peers.py "$OUT"/big.obj "$OUT"/big.glb "$OUT"/big.ply "$OUT"/big.stl | tee "$OUT/trimesh.tsv"
python3 - "$OUT/meshwork.tsv" "$OUT/trimesh.tsv" <<'PY'
import sys
def rows(p):
    return {(f, op): float(ms) for f, op, _, ms in (l.rstrip("\n").split("\t") for l in open(p) if "\t" in l)}
mw, tm = rows(sys.argv[1]), rows(sys.argv[2])
print(f"\n| file | operation | meshwork ms | trimesh ms | trimesh / meshwork |\n|---|---|---|---|---|")
for key in sorted(set(mw) & set(tm)):
    print(f"| {key[0]} | {key[1]} | {mw[key]:.0f} | {tm[key]:.0f} | {tm[key] / mw[key]:.1f}x |")
PY
