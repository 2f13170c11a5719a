//! Making a segment a chain by splitting the edges it crosses (Li's insertion): used when a
//! walked strip has no valid re-filling, and by the route fallback. Each split adds a vertex on
//! the chain and 2 faces (1 on a boundary edge); children of a split lie inside their parent, so
//! no face turns over.

use crate::geometry::{add, scale, sub};

use super::super::trimesh::TriMesh;
use super::cut::{crossing, Cut};
use super::route;

/// Splits the edges a walked strip crosses where the cutting plane crosses them, pushing the new
/// vertices onto `chain`; false, with nothing changed, when a crossing lies at an edge's end.
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
    // A crossing at an edge's end is the cutting plane passing through a vertex (one lying
    // exactly on the segment's line, e.g. a chain vertex of the collinear next segment): a split
    // there would make a second vertex at that place and two zero-area faces. Refused before
    // anything changes; the segment's fallback (a vertex path or a route kept off edge ends)
    // realises it instead.
    if crossings.iter().any(|c| at_an_end(c.lam)) {
        return false;
    }
    split_crossings(mesh, &crossings, on_curve, added, chain)
}

/// Edge fractions this close to 0 or 1 are the edge's end: a split there makes an edge of at
/// most this fraction of the crossed edge, zero at double precision (measured: exactly 0 when
/// the vertex lies on the cutting plane, 7e-15 when one round-off off it).
const AT_END: f64 = 1e-9;

fn at_an_end(lam: f64) -> bool {
    !(AT_END..=1.0 - AT_END).contains(&lam)
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
