"""trimesh's side of the IO benchmark: load, the checks comparable to `meshwork info`, GLB export.
usage: io_peers.py FILE [FILE...]   (prints `file<TAB>operation<TAB>trimesh<TAB>ms`, best of 3)
Run by bench/io.sh with the peers' venv (../shared/tools/peers/setup.sh), on the files bench_io wrote.
"""
import sys, time, tempfile, os
import trimesh


def best(f, reps=3):
    t = 1e99
    r = None
    for _ in range(reps):
        s = time.perf_counter()
        r = f()
        t = min(t, time.perf_counter() - s)
    return t, r


def validate(m):
    # What `meshwork info` reports, as far as trimesh computes it: edge manifoldness and
    # watertightness, winding consistency, Euler characteristic, connected components, degenerate
    # and duplicate faces, unreferenced vertices, bounding box.
    return (m.is_watertight, m.is_winding_consistent, m.euler_number, m.body_count,
            int((~m.nondegenerate_faces()).sum()) if hasattr(m, 'nondegenerate_faces') else 0,
            len(m.faces) - len(trimesh.grouping.unique_rows(m.faces)[0]),
            len(m.vertices) - len(set(m.faces.ravel().tolist())),
            m.bounds)


for path in sys.argv[1:]:
    name = os.path.basename(path)
    dt, m = best(lambda: trimesh.load(path, process=False, force='mesh'))
    print(f"{name}\tload\ttrimesh\t{dt*1e3:.1f}", flush=True)
    dv, _ = best(lambda: validate(trimesh.Trimesh(m.vertices, m.faces, process=False)))
    print(f"{name}\tvalidate\ttrimesh\t{dv*1e3:.1f}", flush=True)
    print(f"{name}\tload+validate\ttrimesh\t{(dt+dv)*1e3:.1f}", flush=True)
    out = os.path.join(tempfile.gettempdir(), '_trimesh_out.glb')
    dw, _ = best(lambda: m.export(out))
    print(f"{name}\twrite_glb\ttrimesh\t{dw*1e3:.1f}", flush=True)
    if name.endswith('.obj'):
        out = os.path.join(tempfile.gettempdir(), '_trimesh_out.obj')
        dw, _ = best(lambda: m.export(out))
        print(f"{name}\twrite_obj\ttrimesh\t{dw*1e3:.1f}", flush=True)
