//! Untangling a folded region by moving all its free vertices at once (a convex-combination map).
//!
//! One-vertex moves cannot undo a fold where several neighbouring vertices are on the wrong side
//! of each other (each ring mean is itself folded). Here the connected group of folded faces, grown
//! by k rings, is treated as a disk:
//! 1. it is projected on the plane of its mean reference normal (the surface it came from);
//! 2. its boundary vertices, and every fixed vertex inside (curve, chain and mesh-boundary
//!    vertices), keep their positions; every other vertex is placed at the mean of its neighbours
//!    (Tutte's barycentric map, solved by conjugate gradients). By Tutte's theorem the planar map
//!    has no folded face when the projected boundary is convex and nothing inside is fixed; in
//!    general it is checked, and the patch grows by a ring when the check fails;
//! 3. the height over the plane is interpolated by the same weights (a membrane spanning the
//!    boundary), then each moved vertex is dropped onto the surface before the untangling (closest
//!    point on the patch's old faces) when that keeps every face unfolded.
//!
//! A solution is taken only when the patch has no folded face afterwards (or, at the largest
//! patch tried, strictly fewer) and its smallest angle is no worse than before; fixed vertices
//! never move.

use std::collections::HashMap;

use crate::error::Result;
use crate::geometry::{add, cross, dot, norm2, normalize, scale, sub, triangle_cross};
use crate::job::Progress;
use crate::mesh::Point3;

use super::super::smooth::min_angle_quality;
use super::super::trimesh::TriMesh;
use super::super::uvs::{self, UvMove};
use super::{energy, Ctx, MIN_COS};

/// Rings added around a group of folded faces, tried in order until one works.
const MAX_RINGS: usize = 8;
/// Largest patch (faces) solved.
const MAX_PATCH_FACES: usize = 4000;
/// Reference normals of a patch farther than this cosine from their mean: too curved for one plane.
const MIN_PLANE_COS: f64 = 0.2;

/// What one pass did.
#[derive(Debug, Default)]
pub(super) struct PatchPass {
    pub patches_solved: usize,
    pub vertices_moved: usize,
    /// One batch of simultaneous moves per solved patch (for the UVs).
    pub uv_batches: Vec<Vec<UvMove>>,
}

/// One pass over the groups of folded faces of `mesh` (`bad`: its folded faces, in id order).
pub(super) fn untangle_patches(
    mesh: &mut TriMesh,
    ctx: &Ctx,
    bad: &[u32],
    progress: &Progress,
) -> Result<PatchPass> {
    let mut out = PatchPass::default();
    let mut seen: HashMap<u32, ()> = HashMap::new();
    for (i, &f) in bad.iter().enumerate() {
        progress.check_every(i, super::POLL_FOLDED)?;
        if seen.contains_key(&f) || !mesh.alive[f as usize] || !ctx.folded(mesh, f) {
            continue;
        }
        let group = folded_group(mesh, ctx, f);
        for &g in &group {
            seen.insert(g, ());
        }
        let mut patch = group.clone();
        let mut in_patch: HashMap<u32, ()> = patch.iter().map(|&g| (g, ())).collect();
        let mut best: Option<(usize, Vec<(u32, Point3)>)> = None;
        let folded_before = group.len();
        for _ in 0..MAX_RINGS {
            // A ring's solve can take tens of ms on a patch of thousands of faces (one group's
            // rings were ~470 ms of CPU without a poll at load 9, session 10).
            progress.check()?;
            grow(mesh, &mut patch, &mut in_patch);
            if patch.len() > MAX_PATCH_FACES {
                break;
            }
            let got = solve(mesh, ctx, &patch, &in_patch);
            let Ok((left, moves)) = got else { continue };
            if left == 0 {
                best = Some((0, moves));
                break;
            }
            if best.as_ref().is_none_or(|b| left < b.0) {
                best = Some((left, moves));
            }
        }
        let Some((left, moves)) = best else { continue };
        if left >= folded_before {
            continue;
        }
        // UVs: each new position located on the mesh before any of the batch moved.
        let batch: Vec<UvMove> = moves.iter().filter_map(|&(v, p)| uvs::record(mesh, v, p)).collect();
        for &(v, p) in &moves {
            mesh.pos[v as usize] = p;
        }
        out.patches_solved += 1;
        out.vertices_moved += moves.len();
        out.uv_batches.push(batch);
    }
    Ok(out)
}

/// The folded faces connected to `f` through shared vertices.
fn folded_group(mesh: &TriMesh, ctx: &Ctx, f: u32) -> Vec<u32> {
    let mut group = vec![f];
    let mut mark: HashMap<u32, ()> = HashMap::from([(f, ())]);
    let mut i = 0;
    while i < group.len() {
        let t = mesh.tris[group[i] as usize];
        i += 1;
        for &v in &t {
            for &g in mesh.faces_of(v) {
                if !mark.contains_key(&g) && ctx.folded(mesh, g) {
                    mark.insert(g, ());
                    group.push(g);
                }
            }
        }
    }
    group
}

/// Adds every face sharing a vertex with the patch.
fn grow(mesh: &TriMesh, patch: &mut Vec<u32>, in_patch: &mut HashMap<u32, ()>) {
    let n = patch.len();
    for i in 0..n {
        let t = mesh.tris[patch[i] as usize];
        for &v in &t {
            for &g in mesh.faces_of(v) {
                if !in_patch.contains_key(&g) {
                    in_patch.insert(g, ());
                    patch.push(g);
                }
            }
        }
    }
}

/// Solves the patch: `Some((folded faces left in it, new positions of its free vertices))`, or
/// None when it is not a disk, too curved, has nothing free, or the map makes it no better.
fn solve(
    mesh: &TriMesh,
    ctx: &Ctx,
    patch: &[u32],
    in_patch: &HashMap<u32, ()>,
) -> Result<(usize, Vec<(u32, Point3)>), &'static str> {
    // Vertices and whether each is on the patch boundary (an edge whose twin is not in the patch).
    let mut index: HashMap<u32, usize> = HashMap::new();
    let mut verts: Vec<u32> = Vec::new();
    let mut on_border: Vec<bool> = Vec::new();
    let mut edges = 0usize;
    let mut border_edges = 0usize;
    for &f in patch {
        let t = mesh.tris[f as usize];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            for v in [a, b] {
                if !index.contains_key(&v) {
                    index.insert(v, verts.len());
                    verts.push(v);
                    on_border.push(false);
                }
            }
            let twin = mesh.face_with_edge(b, a).filter(|g| in_patch.contains_key(g));
            if twin.is_none() {
                border_edges += 1;
                edges += 1;
                on_border[index[&a]] = true;
                on_border[index[&b]] = true;
            } else if a < b {
                edges += 1;
            }
        }
    }
    // A disk: Euler characteristic 1 and one boundary loop (as many border vertices as edges).
    let border_vertices = on_border.iter().filter(|&&b| b).count();
    if verts.len() + patch.len() != edges + 1 || border_vertices != border_edges {
        return Err("not a disk");
    }
    let free: Vec<bool> = verts.iter().zip(&on_border).map(|(&v, &b)| !b && !ctx.fixed[v as usize]).collect();
    if !free.iter().any(|&f| f) {
        return Err("nothing free");
    }
    // The plane: mean reference normal of the patch.
    let normals: Vec<Point3> = verts.iter().map(|&v| ctx.normal_at(mesh, v)).collect();
    let n = normalize(normals.iter().fold([0.0; 3], |a, &r| add(a, r)));
    if n == [0.0; 3] || normals.iter().any(|&r| r != [0.0; 3] && dot(r, n) < MIN_PLANE_COS) {
        return Err("too curved");
    }
    let u = normalize(if n[0].abs() < 0.9 { cross(n, [1.0, 0.0, 0.0]) } else { cross(n, [0.0, 1.0, 0.0]) });
    let w = cross(n, u);
    let origin = mesh.pos[verts[0] as usize];
    let coords: Vec<[f64; 3]> = verts
        .iter()
        .map(|&v| {
            let d = sub(mesh.pos[v as usize], origin);
            [dot(d, u), dot(d, w), dot(d, n)]
        })
        .collect();
    // Neighbours of each patch vertex within the patch (uniform weights).
    let mut nbrs: Vec<Vec<usize>> = vec![Vec::new(); verts.len()];
    for &f in patch {
        let t = mesh.tris[f as usize];
        for k in 0..3 {
            let (a, b) = (index[&t[k]], index[&t[(k + 1) % 3]]);
            if !nbrs[a].contains(&b) {
                nbrs[a].push(b);
            }
            if !nbrs[b].contains(&a) {
                nbrs[b].push(a);
            }
        }
    }
    let solved = tutte(&coords, &free, &nbrs);
    let lift = |c: [f64; 3]| add(origin, add(add(scale(u, c[0]), scale(w, c[1])), scale(n, c[2])));
    let q_before =
        patch.iter().map(|&f| quality(mesh.tris[f as usize], |v| mesh.pos[v as usize])).fold(1.0, f64::min);
    let folded_before = patch.iter().filter(|&&f| ctx.folded(mesh, f)).count();
    let eval = |cand: &[Point3]| {
        let p = |v: u32| cand[index[&v]];
        let left = patch.iter().filter(|&&f| ctx.score_face(mesh, f, p) <= MIN_COS).count();
        let q = patch.iter().map(|&f| quality(mesh.tris[f as usize], p)).fold(1.0, f64::min);
        (left, q)
    };
    // A layout in the plane → 3D positions (heights of the membrane), then the better of those and
    // their drop onto the old surface: (folded left, quality, positions).
    let place = |layout: &[[f64; 2]]| -> (usize, f64, Vec<Point3>) {
        let mut cand: Vec<Point3> = verts.iter().map(|&v| mesh.pos[v as usize]).collect();
        for i in 0..verts.len() {
            if free[i] {
                cand[i] = lift([layout[i][0], layout[i][1], solved[i][2]]);
            }
        }
        let mut projected = cand.clone();
        for i in 0..verts.len() {
            if free[i] {
                projected[i] = closest_on_patch(mesh, patch, cand[i]);
            }
        }
        let (left_p, q_p) = eval(&projected);
        let (left_m, q_m) = eval(&cand);
        if left_p <= left_m && q_p >= q_before.min(q_m) {
            (left_p, q_p, projected)
        } else {
            (left_m, q_m, cand)
        }
    };
    // 1. Tutte's map.
    let tutte_layout: Vec<[f64; 2]> = solved.iter().map(|c| [c[0], c[1]]).collect();
    let mut best = place(&tutte_layout);
    // 2. Where it leaves folds or slivers: the barrier energy, from the layout as it is.
    if best.0 > 0 || best.1 < q_before {
        let mut layout: Vec<[f64; 2]> = coords.iter().map(|c| [c[0], c[1]]).collect();
        let areas: Vec<f64> = patch
            .iter()
            .map(|&f| {
                let t = mesh.tris[f as usize];
                0.5 * norm2(triangle_cross(
                    mesh.pos[t[0] as usize],
                    mesh.pos[t[1] as usize],
                    mesh.pos[t[2] as usize],
                ))
                .sqrt()
            })
            .collect();
        let mean_area = areas.iter().sum::<f64>() / areas.len().max(1) as f64;
        let refs: Vec<energy::RefTri> = patch
            .iter()
            .map(|&f| {
                let t = mesh.tris[f as usize];
                energy::RefTri::new(t.map(|v| index[&v]), t.map(|v| mesh.pos[v as usize]), 1e-2 * mean_area)
            })
            .collect();
        let mut tris_of: Vec<Vec<usize>> = vec![Vec::new(); verts.len()];
        for (k, r) in refs.iter().enumerate() {
            for &c in &r.c {
                tris_of[c].push(k);
            }
        }
        energy::untangle_2d(&mut layout, &free, &refs, &tris_of, mean_area.sqrt(), 40);
        let e = place(&layout);
        if e.0 < best.0 || (e.0 == best.0 && e.1 > best.1) {
            best = e;
        }
    }
    let (left, q, chosen) = best;
    // Never below the patch's own smallest angle (so the mesh's smallest angle cannot drop).
    if q < q_before {
        return Err("worse angles");
    }
    if left >= folded_before {
        return Err("no better");
    }
    let moves = (0..verts.len()).filter(|&i| free[i]).map(|i| (verts[i], chosen[i])).collect();
    Ok((left, moves))
}

fn quality(t: [u32; 3], p: impl Fn(u32) -> Point3) -> f64 {
    min_angle_quality(p(t[0]), p(t[1]), p(t[2]))
}

fn closest_on_patch(mesh: &TriMesh, patch: &[u32], q: Point3) -> Point3 {
    let mut best = (f64::INFINITY, q);
    for &f in patch {
        let t = mesh.tris[f as usize];
        let c = crate::spatial::closest_on_triangle(
            q,
            &[mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize]],
        );
        let d = norm2(sub(c, q));
        if d < best.0 {
            best = (d, c);
        }
    }
    best.1
}

/// Tutte's barycentric map: every free vertex at the mean of its neighbours, the others fixed;
/// the three coordinates solved at once by conjugate gradients (the Dirichlet graph Laplacian is
/// symmetric positive definite when every free component touches a fixed vertex, which a disk
/// patch with a boundary ensures).
pub(super) fn tutte(coords: &[[f64; 3]], free: &[bool], nbrs: &[Vec<usize>]) -> Vec<[f64; 3]> {
    let n = coords.len();
    let mut x = coords.to_vec();
    // Unknowns: free vertices; b = Σ fixed neighbours, A = deg·I − adjacency among free ones.
    let apply = |x: &[[f64; 3]], out: &mut [[f64; 3]]| {
        for i in 0..n {
            if !free[i] {
                out[i] = [0.0; 3];
                continue;
            }
            let mut s = scale(x[i], nbrs[i].len() as f64);
            for &j in &nbrs[i] {
                if free[j] {
                    s = sub(s, x[j]);
                }
            }
            out[i] = s;
        }
    };
    let mut b = vec![[0.0; 3]; n];
    for i in 0..n {
        if free[i] {
            for &j in &nbrs[i] {
                if !free[j] {
                    b[i] = add(b[i], coords[j]);
                }
            }
        }
    }
    let mut ax = vec![[0.0; 3]; n];
    apply(&x, &mut ax);
    let mut r: Vec<[f64; 3]> = (0..n).map(|i| if free[i] { sub(b[i], ax[i]) } else { [0.0; 3] }).collect();
    // Jacobi preconditioner: 1 / degree.
    let prec = |r: &[[f64; 3]]| -> Vec<[f64; 3]> {
        (0..n)
            .map(|i| if free[i] { scale(r[i], 1.0 / nbrs[i].len().max(1) as f64) } else { [0.0; 3] })
            .collect()
    };
    let mut z = prec(&r);
    let mut p = z.clone();
    let dot3 = |a: &[[f64; 3]], b: &[[f64; 3]]| -> [f64; 3] {
        let mut s = [0.0; 3];
        for i in 0..n {
            for k in 0..3 {
                s[k] += a[i][k] * b[i][k];
            }
        }
        s
    };
    let bnorm = dot3(&b, &b);
    let bmax = bnorm[0].max(bnorm[1]).max(bnorm[2]).max(1e-300);
    let mut rz = dot3(&r, &z);
    let mut ap = vec![[0.0; 3]; n];
    for _ in 0..(4 * n + 50) {
        let rr = dot3(&r, &r);
        if (0..3).all(|k| rr[k] <= 1e-28 * bmax) {
            break;
        }
        apply(&p, &mut ap);
        let pap = dot3(&p, &ap);
        let alpha: [f64; 3] = std::array::from_fn(|k| if pap[k] > 0.0 { rz[k] / pap[k] } else { 0.0 });
        for i in 0..n {
            for k in 0..3 {
                x[i][k] += alpha[k] * p[i][k];
                r[i][k] -= alpha[k] * ap[i][k];
            }
        }
        z = prec(&r);
        let rz_new = dot3(&r, &z);
        let beta: [f64; 3] = std::array::from_fn(|k| if rz[k] > 0.0 { rz_new[k] / rz[k] } else { 0.0 });
        for i in 0..n {
            for k in 0..3 {
                p[i][k] = z[i][k] + beta[k] * p[i][k];
            }
        }
        rz = rz_new;
    }
    x
}
