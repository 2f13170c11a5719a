"""Peers' side of the validate/repair benchmark (bench/repair.sh runs it next to bench_repair).
usage: repair_peers.py FILE [FILE...]   prints `file<TAB>operation<TAB>peer<TAB>ms` (best of 3),
timed from in-memory arrays (file loading excluded, as in bench_repair).

- validate/trimesh: a fresh Trimesh(process=False) and the checks comparable to our report
  (watertight, winding consistency, Euler number, body count, degenerate/duplicate faces,
  unreferenced vertices, bounds).
- repair/trimesh: Trimesh(process=True) (merges coincident vertices), nondegenerate + unique faces,
  remove_unreferenced_vertices, fix_normals (consistent winding, outward), fill_holes.
- repair/pymeshlab: remove duplicate vertices, duplicate and null faces, unreferenced vertices,
  repair non-manifold edges (split) and vertices, close holes (max size 1000).
Needs networkx in the peers' venv for trimesh's fill_holes.
"""
import os, sys, time
import numpy as np
import trimesh


def best(f, reps=3):
    t, r = 1e99, None
    for _ in range(reps):
        s = time.perf_counter()
        r = f()
        t = min(t, time.perf_counter() - s)
    return t, r


def validate(v, f):
    m = trimesh.Trimesh(v, f, process=False)
    return (m.is_watertight, m.is_winding_consistent, m.euler_number, m.body_count,
            int((~m.nondegenerate_faces()).sum()),
            len(m.faces) - len(trimesh.grouping.unique_rows(np.sort(m.faces, axis=1))[0]),
            len(m.vertices) - len(np.unique(m.faces)), m.bounds)


def repair_trimesh(v, f):
    m = trimesh.Trimesh(v, f, process=True)
    m.update_faces(m.nondegenerate_faces())
    m.update_faces(m.unique_faces())
    m.remove_unreferenced_vertices()
    trimesh.repair.fix_normals(m)
    m.fill_holes()
    return m


def repair_meshlab(v, f):
    import pymeshlab
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f))
    ms.meshing_remove_duplicate_vertices()
    ms.meshing_remove_duplicate_faces()
    ms.meshing_remove_null_faces()
    ms.meshing_remove_unreferenced_vertices()
    ms.meshing_repair_non_manifold_edges(method=1)
    ms.meshing_repair_non_manifold_vertices()
    ms.meshing_close_holes(maxholesize=1000)
    # The mesh belongs to the MeshSet: read what we report before it goes away.
    c = ms.current_mesh()
    return c.vertex_number(), c.face_number(), ms.get_topological_measures()['boundary_edges']


for path in sys.argv[1:]:
    name = os.path.basename(path)
    m = trimesh.load(path, process=False, force='mesh')
    v, f = np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int32)
    dv, _ = best(lambda: validate(v, f))
    print(f"{name}\tvalidate\ttrimesh\t{dv*1e3:.1f}", flush=True)
    dr, r = best(lambda: repair_trimesh(v, f))
    print(f"{name}\trepair\ttrimesh\t{dr*1e3:.1f}\twatertight={r.is_watertight} V={len(r.vertices)} F={len(r.faces)}", flush=True)
    try:
        dm, r = best(lambda: repair_meshlab(v, f))
        print(f"{name}\trepair\tpymeshlab\t{dm*1e3:.1f}\tV={r[0]} F={r[1]} boundary_edges={r[2]}", flush=True)
    except Exception as e:  # noqa: BLE001 - report and go on
        print(f"{name}\trepair\tpymeshlab\tfailed: {e}", flush=True)
