"""Peers' side of the smoothing benchmark (run by bench/smooth.sh in the same session as ours).
usage: smooth_peers.py MESH.obj [MESH.obj ...]
Prints `mesh<TAB>V=n<TAB>operation<TAB>peer<TAB>ms` (best of a few runs; one run for the slow ones).
Meshes are the compacted OBJ files bench_smooth wrote, so every tool sees the same vertices.
"""
import sys, time
import numpy as np, scipy.sparse as sp, scipy.sparse.linalg as spla
import trimesh, igl, pymeshlab
try:
    import open3d as o3d
except Exception as e:  # Open3D needs Debian's libusb-1.0-0
    o3d = None
    print(f"# open3d unavailable: {e}", file=sys.stderr)
try:
    from sksparse.cholmod import cholesky
except Exception as e:
    cholesky = None
    print(f"# cholmod unavailable: {e}", file=sys.stderr)


def best(f, reps=3):
    t, r = 1e99, None
    for _ in range(reps):
        s = time.perf_counter(); r = f(); t = min(t, time.perf_counter() - s)
    return t, r


def bench(path):
    m = trimesh.load(path, process=False, force='mesh')
    V = np.ascontiguousarray(m.vertices, dtype=np.float64)
    F = np.ascontiguousarray(m.faces, dtype=np.int64)
    n = len(V)
    big = n > 200_000
    name = path.split('/')[-1]
    out = []
    dt, L = best(lambda: igl.cotmatrix(V, F)); out.append(("cotan_assembly", "libigl", dt))
    dt, M = best(lambda: igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)); out.append(("mass_voronoi", "libigl", dt))
    # The implicit system Meshwork solves: (M + h S) with S = -L and h = mean edge length squared.
    e = m.edges_unique_length.mean()
    A = (M - (e * e) * L).tocsc()
    b = M @ V
    if cholesky is not None:
        def chol():
            f = cholesky(A)          # analyze + factor (supernodal, OpenBLAS)
            return f(b)              # solve 3 right-hand sides
        dt, _ = best(chol, reps=1 if big else 3); out.append(("implicit_analyze+factor+solve3", "cholmod", dt))
    if not big:
        dt, _ = best(lambda: spla.splu(A).solve(b), reps=1); out.append(("implicit_factor+solve3", "scipy_superlu", dt))

    def tri_implicit():
        mm = trimesh.Trimesh(V.copy(), m.faces, process=False)
        trimesh.smoothing.filter_laplacian(mm, iterations=1, implicit_time_integration=True)
        return mm
    dt, _ = best(tri_implicit, reps=1 if big else 5); out.append(("implicit1", "trimesh", dt))

    def tri_taubin():
        mm = trimesh.Trimesh(V.copy(), m.faces, process=False)
        trimesh.smoothing.filter_taubin(mm, iterations=10)  # 10 alternating half-steps, operator built inside
        return mm
    dt, _ = best(tri_taubin, reps=3 if big else 10); out.append(("taubin10(10 half-steps)", "trimesh", dt))
    if o3d is not None:
        mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V), o3d.utility.Vector3iVector(F.astype(np.int32)))
        dt, _ = best(lambda: mesh.filter_smooth_taubin(number_of_iterations=10)); out.append(("taubin10", "open3d", dt))
    ms = pymeshlab.MeshSet(); ms.add_mesh(pymeshlab.Mesh(V, F.astype(np.int32)))
    dt, _ = best(lambda: ms.apply_coord_taubin_smoothing(stepsmoothnum=10)); out.append(("taubin10", "pymeshlab", dt))
    for op, peer, dt in out:
        print(f"{name}\tV={n}\t{op}\t{peer}\t{dt * 1000:.1f} ms", flush=True)


if __name__ == "__main__":
    for p in sys.argv[1:]:
        bench(p)
