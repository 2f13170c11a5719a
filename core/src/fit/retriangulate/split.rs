//! Making a segment a chain by splitting the edges it crosses (Li's insertion): used when a
//! walked strip has no valid re-filling, and by the route fallback. Each split adds a vertex on
//! the chain and 2 faces (1 on a boundary edge); children of a split lie inside their parent, so
//! no face turns over.

use crate::geometry::{add, scale, sub};
use crate::mesh::Point3;

use super::super::trimesh::TriMesh;
use super::cut::{crossing, Cut};
use super::route;

/// stays valid up to its last vertex).
pub(super) fn split_strip(
    mesh: &mut TriMesh,
    cut: &Cut,
    crossed: &[(u32, u32)],
    on_curve: &mut Vec<bool>,
    added: &mut Vec<[(u32, f64); 3]>,
    chain: &mut Vec<u32>,
) -> bool {
    // At the crossing itself (on the surface): moving it onto the straight segment would fold
    // the split faces where the strip is long and curved.
    let crossings: Vec<route::Crossing> =
        crossed.iter().map(|&(l, r)| route::Crossing { l, r, lam: crossing(mesh, cut, l, r).1 }).collect();
    split_crossings(mesh, &crossings, on_curve, added, chain)
}

/// Splits each crossed edge in order at its fraction, pushing the new vertices onto `chain`
/// (consecutive crossings of one face become an edge between their new vertices).
pub(super) fn split_crossings(
    mesh: &mut TriMesh,
    crossings: &[route::Crossing],
    on_curve: &mut Vec<bool>,
    added: &mut Vec<[(u32, f64); 3]>,
    chain: &mut Vec<u32>,
) -> bool {
    for c in crossings {
        let (pl, pr) = (mesh.pos[c.l as usize], mesh.pos[c.r as usize]);
        let x = add(pl, scale(sub(pr, pl), c.lam));
        let Some(m) = split_edge(mesh, c.l, c.r, x) else { return false };
        added.push([(c.l, 1.0 - c.lam), (c.r, c.lam), (c.l, 0.0)]);
        on_curve.push(true);
        chain.push(m);
    }
    true
}

/// Splits edge (a, b) at `x` and the one or two faces on it; the new vertex's id.
fn split_edge(mesh: &mut TriMesh, a: u32, b: u32, x: Point3) -> Option<u32> {
    let faces: Vec<u32> =
        [mesh.face_with_edge(a, b), mesh.face_with_edge(b, a)].into_iter().flatten().collect();
    if faces.is_empty() {
        return None;
    }
    let m = mesh.add_vertex(x);
    for f in faces {
        let t = mesh.tris[f as usize];
        let k = (0..3).find(|&k| (t[k] == a && t[(k + 1) % 3] == b) || (t[k] == b && t[(k + 1) % 3] == a))?;
        let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        mesh.remove_face(f);
        // The removed face freed its directed edges; p→m, m→q and the edges at m are new.
        mesh.add_face([p, m, r]).ok()?;
        mesh.add_face([m, q, r]).ok()?;
    }
    Some(m)
}
