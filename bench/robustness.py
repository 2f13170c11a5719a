#!/usr/bin/env python3
"""Broken files side by side: Meshwork vs trimesh, Open3D and PyMeshLab.

Every file of the broken-file corpus (core/tests/corpus: truncated, lying counts, NaN/Inf, indices out
of range, garbage, ...) is loaded by each library in its own subprocess (so a segfault or an abort is
seen as such, not as the end of this script), with a time limit. Each outcome is one of:

  error   - refused with an error/exception (Meshwork: non-zero exit and an `error[kind]` line)
  loaded  - accepted without any error: for these files that means the library silently dropped,
            repaired or invented data (vertex and face counts are printed so you can see what)
  crash   - the process died from a signal (segfault, abort) or an uncaught native error
  hang    - did not finish within the time limit

Run from the repository root, with the peers' venv (../shared/tools/peers/setup.sh):
  cargo build --release -p meshwork-service
  ~/.cache/meshwork-peers/bin/python bench/robustness.py [--meshwork target/release/meshwork] [--md]
"""
import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "..", "core", "tests", "corpus")
TIMEOUT = 30

# Each peer loader prints "V F" on success; an exception prints "ERR <message>" and exits 3.
PEERS = {
    "trimesh": """
import sys, trimesh
try:
    m = trimesh.load(sys.argv[1], force='mesh', process=False)
    print(len(m.vertices), len(m.faces))
except Exception as e:
    print('ERR', type(e).__name__, str(e)[:120]); sys.exit(3)
""",
    "open3d": """
import sys, open3d as o3d
o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
try:
    m = o3d.io.read_triangle_mesh(sys.argv[1])
    print(len(m.vertices), len(m.triangles))
except Exception as e:
    print('ERR', type(e).__name__, str(e)[:120]); sys.exit(3)
""",
    "pymeshlab": """
import sys, pymeshlab
try:
    ms = pymeshlab.MeshSet(); ms.load_new_mesh(sys.argv[1]); m = ms.current_mesh()
    print(m.vertex_number(), m.face_number())
except Exception as e:
    print('ERR', type(e).__name__, str(e)[:120]); sys.exit(3)
""",
}


def classify(cmd, env=None):
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT, env=env)
    except subprocess.TimeoutExpired:
        return "hang", ""
    out = (p.stdout.strip().splitlines() or [""])[-1]
    err = (p.stderr.strip().splitlines() or [""])[-1]
    if p.returncode < 0:
        return "crash", f"signal {-p.returncode}"
    if p.returncode == 0:
        return "loaded", out
    if p.returncode == 3 or out.startswith("ERR"):
        return "error", out[4:]
    return "crash", f"exit {p.returncode}: {err[:100]}"


def peer_file(path):
    """Peers pick the reader from the extension; `.bin` (unknown format) is offered as-is."""
    return path


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshwork", default=os.path.join(HERE, "..", "target", "release", "meshwork"))
    ap.add_argument("--md", action="store_true", help="print a markdown table")
    a = ap.parse_args()
    files = sorted(f for f in os.listdir(CORPUS) if not f.endswith(".py"))
    libs = ["meshwork"] + list(PEERS)
    tally = {lib: {} for lib in libs}
    rows = []
    for f in files:
        path = os.path.join(CORPUS, f)
        res = {}
        mw = classify([a.meshwork, "info", path])
        if mw[0] == "crash" and mw[1].startswith("exit 2"):
            # The CLI exits 2 with `error[kind]: message` on stderr for bad input: a clean refusal.
            p = subprocess.run([a.meshwork, "info", path], capture_output=True, text=True)
            mw = ("error", p.stderr.strip().splitlines()[-1][:120])
        res["meshwork"] = mw
        for lib, code in PEERS.items():
            res[lib] = classify([sys.executable, "-c", code, peer_file(path)])
        for lib in libs:
            tally[lib][res[lib][0]] = tally[lib].get(res[lib][0], 0) + 1
        rows.append((f, res))
        if not a.md:
            print(f, " | ".join(f"{lib}: {res[lib][0]} {res[lib][1][:60]}" for lib in libs), flush=True)
    if a.md:
        print("| file | " + " | ".join(libs) + " |")
        print("|---|" + "---|" * len(libs))
        for f, res in rows:
            cells = []
            for lib in libs:
                kind, detail = res[lib]
                cells.append(kind if kind != "loaded" else f"loaded ({detail.replace(' ', ' V / ', 1)} F)")
            print(f"| {f} | " + " | ".join(cells) + " |")
    print()
    print(f"{len(files)} broken files:")
    for lib in libs:
        t = tally[lib]
        print(f"  {lib:<10} " + ", ".join(f"{k} {t.get(k, 0)}" for k in ("error", "loaded", "crash", "hang")))


if __name__ == "__main__":
    main()
