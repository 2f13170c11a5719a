//! Texture coordinates of vertices the fit *moves* over the surface (vertices snapped onto a
//! curve segment by the re-triangulation, or pulled onto it by the Dijkstra fallback; vertices
//! moved by the untangling and by the smoothing).
//!
//! A moved vertex keeps its index but now sits somewhere else on the surface, so its old UV is
//! wrong there. Its new UV is interpolated, barycentrically, in the face that contains its new
//! position on the mesh *before* it moved (the mesh still carries the old parametrisation there).

use crate::mesh::Point3;

use super::insert::barycentric;
use super::trimesh::TriMesh;

/// One move: vertex `vertex` gets the UV `Σ w · uv[v]` over `weights` (evaluated in move order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UvMove {
    pub vertex: u32,
    pub weights: [(u32, f64); 3],
}

fn tri_pos(mesh: &TriMesh, f: u32) -> [Point3; 3] {
    let t = mesh.tris[f as usize];
    [mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize]]
}

/// The face containing `p` (projected onto face planes), searched from the star of `near` and
/// walked across the edge opposite the most negative coordinate; the coordinates are clamped to
/// the face (p slightly off the surface, or a walk cut short at the boundary).
pub fn locate(mesh: &TriMesh, near: u32, p: Point3) -> Option<(u32, [f64; 3])> {
    let mut best: Option<(u32, [f64; 3], f64)> = None;
    for &f in mesh.faces_of(near) {
        let l = barycentric(p, &tri_pos(mesh, f));
        let m = l[0].min(l[1]).min(l[2]);
        if best.is_none_or(|b| m > b.2) {
            best = Some((f, l, m));
        }
    }
    let (mut f, mut l, mut m) = best?;
    for _ in 0..64 {
        if m >= -1e-12 {
            break;
        }
        let t = mesh.tris[f as usize];
        let k = if l[0] <= l[1] && l[0] <= l[2] {
            0
        } else if l[1] <= l[2] {
            1
        } else {
            2
        };
        let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
        let Some(g) = mesh.across(f, a, b) else { break };
        let lg = barycentric(p, &tri_pos(mesh, g));
        let mg = lg[0].min(lg[1]).min(lg[2]);
        if mg <= m {
            break; // the walk does not get closer (curved surface): keep the best face so far
        }
        (f, l, m) = (g, lg, mg);
    }
    let c = [l[0].max(0.0), l[1].max(0.0), l[2].max(0.0)];
    let s = c[0] + c[1] + c[2];
    let c = if s > 0.0 { [c[0] / s, c[1] / s, c[2] / s] } else { [1.0 / 3.0; 3] };
    Some((f, c))
}

/// The move of `v` to `target`, located on the mesh as it is now (call before moving `v`).
pub fn record(mesh: &TriMesh, v: u32, target: Point3) -> Option<UvMove> {
    let (f, l) = locate(mesh, v, target)?;
    let t = mesh.tris[f as usize];
    Some(UvMove { vertex: v, weights: [(t[0], l[0]), (t[1], l[1]), (t[2], l[2])] })
}

/// Applies the moves in order to per-vertex UVs.
pub fn apply(uvs: &mut [[f64; 2]], moves: &[UvMove]) {
    for m in moves {
        let mut u = [0.0; 2];
        for &(v, w) in &m.weights {
            u[0] += w * uvs[v as usize][0];
            u[1] += w * uvs[v as usize][1];
        }
        uvs[m.vertex as usize] = u;
    }
}

/// Applies batches in order; the moves of one batch are simultaneous (each one's weights refer to
/// the UVs before the batch, as its positions were located on the mesh before the batch moved).
pub fn apply_batches(uvs: &mut [[f64; 2]], batches: &[Vec<UvMove>]) {
    for b in batches {
        let new: Vec<[f64; 2]> = b
            .iter()
            .map(|m| {
                m.weights.iter().fold([0.0; 2], |u, &(v, w)| {
                    [u[0] + w * uvs[v as usize][0], u[1] + w * uvs[v as usize][1]]
                })
            })
            .collect();
        for (m, u) in b.iter().zip(new) {
            uvs[m.vertex as usize] = u;
        }
    }
}

/// One batch for every vertex whose position differs between `mesh.pos` (before) and `after`
/// (e.g. smoothing): each new position located on `mesh` as it is.
pub fn relocate(mesh: &TriMesh, after: &[Point3]) -> Vec<UvMove> {
    use rayon::prelude::*;
    (0..mesh.pos.len().min(after.len()) as u32)
        .into_par_iter()
        .filter(|&v| mesh.pos[v as usize] != after[v as usize] && !mesh.faces_of(v).is_empty())
        .filter_map(|v| record(mesh, v, after[v as usize]))
        .collect()
}
