//! Making a segment a chain by splitting the edges it crosses (Li's insertion): used when a
//! walked strip has no valid re-filling, and by the route fallback. Each split adds a vertex on
//! the chain and 2 faces (1 on a boundary edge); children of a split lie inside their parent, so
//! no face turns over.

use crate::geometry::{add, scale, sub};

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
        let Some(m) = mesh.split_edge(c.l, c.r, x) else { return false };
        added.push([(c.l, 1.0 - c.lam), (c.r, c.lam), (c.l, 0.0)]);
        on_curve.push(true);
        chain.push(m);
    }
    true
}
